#!/usr/bin/python3
"""Inputs every program must refuse up front, with the documented exit code and a
message that names the option or file and says what to do (README: exit codes).

  UnknownEffect    a misspelt effect in resolver-model --effects or resolverd's
                   [model] effects: exit 2 (usage/config), naming the option or key,
                   the bad name and "did you mean 'amplitude_imbalance'?"
                   (was: resolver-model read the log and exited 1, "no usable data")
  ConfigDirectory  --config naming a directory, in resolverd, resolver-model and
                   resolver-sim: exit 3 (I/O), naming the path and saying it is a
                   directory (was: read as an empty file, all defaults, exit 0);
                   likewise a directory as resolverd --replay, resolver-model's LOG
                   or resolver-echo --log

  test_refused_inputs.py --bin BUILD/bin --work DIR [unittest arguments]
"""
import argparse
import os
import subprocess
import sys
import unittest

ARGS = None
PY = "/usr/bin/python3"  # Debian's interpreter: the one python3-can is installed for
USAGE, IO = 2, 3         # README: 2 usage or configuration error, 3 I/O error


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)


def work(name):
    return os.path.join(ARGS.work, name)


def write(name, text):
    path = work(name)
    with open(path, "w") as f:
        f.write(text)
    return path


_LOG = None


def sim_log():
    """A short resolver-sim candump log, made once."""
    global _LOG
    if _LOG is None:
        _LOG = work("refused.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", _LOG, "--duration", "1", "--seed", "5"])
        if p.returncode != 0:
            raise AssertionError(f"resolver-sim failed ({p.returncode}): {p.stderr}")
    return _LOG


class UnknownEffect(unittest.TestCase):
    def test_model_effects_option(self):
        for sub in ("fit", "explain", "export"):
            with self.subTest(sub=sub):
                p = run([f"{ARGS.bin}/resolver-model", sub, sim_log(), "--effects", "amplitude_imbalanse"])
                self.assertEqual(p.returncode, USAGE, p.stderr)
                self.assertIn("--effects", p.stderr)
                self.assertIn("'amplitude_imbalanse'", p.stderr)
                self.assertIn("did you mean 'amplitude_imbalance'?", p.stderr)

    def test_model_effects_in_a_list(self):
        p = run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--effects", "amplitude_imbalance,dead_tme"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn("'dead_tme'", p.stderr)
        self.assertIn("did you mean 'dead_time'?", p.stderr)

    def test_model_far_name_gets_no_guess(self):
        p = run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--effects", "nope"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn("'nope' is not a fittable catalog effect", p.stderr)
        self.assertNotIn("did you mean", p.stderr)

    def test_model_unknown_parameter(self):
        p = run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--effects", "harmonics(k55)"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn("no parameter 'k55' (did you mean 'k5'?)", p.stderr)

    def test_daemon_config_key(self):
        cfg = write("typo_effect.toml", '[model]\neffects = ["amplitude_imbalanse"]\n')
        p = run([f"{ARGS.bin}/resolverd", "--replay", sim_log(), "--once", "--fast", "--quiet", "--lcm", "memq://",
                 "--config", cfg])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn("typo_effect.toml:2", p.stderr)
        self.assertIn("[model] effects", p.stderr)
        self.assertIn("did you mean 'amplitude_imbalance'?", p.stderr)

    def test_control_right_name_is_accepted(self):
        p = run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--effects", "amplitude_imbalance"])
        self.assertEqual(p.returncode, 0, p.stderr)


class ConfigDirectory(unittest.TestCase):
    def setUp(self):
        self.dir = work("config_dir.toml")  # a directory with a config's name
        os.makedirs(self.dir, exist_ok=True)

    def assert_directory_refused(self, p, option, path):
        self.assertEqual(p.returncode, IO, p.stderr)
        self.assertIn(f"{option} {path}", p.stderr)
        self.assertIn("is a directory", p.stderr)

    def test_resolverd(self):
        p = run([f"{ARGS.bin}/resolverd", "--replay", sim_log(), "--once", "--fast", "--quiet", "--lcm", "memq://",
                 "--config", self.dir])
        self.assert_directory_refused(p, "--config", self.dir)

    def test_resolver_model(self):
        for sub in ("fit", "explain"):
            with self.subTest(sub=sub):
                p = run([f"{ARGS.bin}/resolver-model", sub, sim_log(), "--config", self.dir])
                self.assert_directory_refused(p, "--config", self.dir)

    def test_resolver_sim(self):
        out = work("config_dir_sim.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", out, "--duration", "0.2", "--config", self.dir])
        self.assert_directory_refused(p, "--config", self.dir)
        self.assertFalse(os.path.exists(out), "nothing is simulated with a directory for a config")

    def test_directory_as_the_log(self):
        p = run([f"{ARGS.bin}/resolverd", "--replay", self.dir, "--once", "--fast", "--quiet", "--lcm", "memq://"])
        self.assert_directory_refused(p, "--replay", self.dir)
        p = run([f"{ARGS.bin}/resolver-model", "fit", self.dir])
        self.assert_directory_refused(p, "LOG", self.dir)
        p = run([f"{ARGS.bin}/resolver-echo", "--log", self.dir])
        self.assert_directory_refused(p, "--log", self.dir)

    def test_control_a_config_file_is_read(self):
        cfg = write("config_file.toml", "[model]\nwindow_revolutions = 16\n")
        p = run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--config", cfg])
        self.assertEqual(p.returncode, 0, p.stderr)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
