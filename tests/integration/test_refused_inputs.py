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
  OutOfMemory      resolver-model under an address-space limit (prlimit --as) too small
                   for the log: exit 4, "resolver-model: out of memory: ..." on one line
                   (was: a bare "std::bad_alloc", exit 1)
  NotAFile         a FIFO as resolver-echo --log: exit 2 at once, naming it (was: it
                   waited for a writer)
  BinaryLogs       a Vector BLF log (.blf, or the magic "LOGG") and a gzip file (.gz,
                   or the magic 1f 8b) given to resolverd --replay or resolver-model:
                   exit 2 naming the file and the conversion command (was: read as
                   candump text, "182 bad lines"); the BLF command, run, gives an ASC
                   log both programs read (made with python-can's BLFWriter from a
                   resolver-sim log), and so does the zcat command

  test_refused_inputs.py --bin BUILD/bin --work DIR [unittest arguments]
"""
import argparse
import gzip
import json
import os
import shlex
import shutil
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


def have_pycan():
    return subprocess.run([PY, "-c", "import can"], capture_output=True).returncode == 0


def refused_by_both(test, path, *extra):
    """resolverd --replay and resolver-model fit on `path`: exit 2 naming it; resolverd's stderr."""
    p = run([f"{ARGS.bin}/resolverd", "--replay", path, "--once", "--fast", "--quiet", "--lcm", "memq://", *extra])
    test.assertEqual(p.returncode, USAGE, p.stderr)
    test.assertIn(path, p.stderr)
    test.assertNotIn("bad line", p.stderr)  # refused before any line is read
    m = run([f"{ARGS.bin}/resolver-model", "fit", path, *extra])
    test.assertEqual(m.returncode, USAGE, m.stderr)
    test.assertIn(path, m.stderr)
    return p.stderr


def decoded_samples(log):
    """resolverd --replay LOG --report: the complete samples it decoded (asserts exit 0)."""
    rep = work(os.path.basename(log) + ".report.json")
    p = run([f"{ARGS.bin}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://",
             "--report", rep])
    if p.returncode != 0:
        raise AssertionError(f"resolverd --replay {log} exited {p.returncode}: {p.stderr}")
    with open(rep) as f:
        n = json.load(f)["samples_complete"]
    if n < 1000:  # resolver-sim's 1 s at 2 kHz: a log that decodes nothing proves nothing
        raise AssertionError(f"resolverd --replay {log} decoded only {n} samples")
    return n


class BinaryLogs(unittest.TestCase):
    def make_blf(self, name):
        """The resolver-sim log written as BLF by python-can (no code of this project)."""
        if not have_pycan():
            if os.environ.get("RESOLVER_REQUIRE_PYCAN") == "1":
                self.fail(f"{PY} cannot 'import can' but RESOLVER_REQUIRE_PYCAN=1; install python3-can")
            self.skipTest(f"{PY} cannot 'import can' (install python3-can)")
        blf = work(name)
        script = ("import can, sys\n"
                  "w = can.BLFWriter(sys.argv[2])\n"
                  "for m in can.CanutilsLogReader(sys.argv[1]): w.on_message_received(m)\n"
                  "w.stop()\n")
        p = run([PY, "-c", script, sim_log(), blf])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(blf, "rb") as f:
            self.assertEqual(f.read(4), b"LOGG")
        return blf

    def test_blf_refused_and_its_command_converts_it(self):
        blf = self.make_blf("refused.blf")
        err = refused_by_both(self, blf)
        self.assertIn("Vector BLF", err)
        self.assertIn("can.BLFReader", err)
        command = err.split("give that: ", 1)[1].strip()
        argv = shlex.split(command)
        self.assertEqual(argv[:2], ["python3", "-c"], command)
        asc = work("refused.asc")
        if os.path.exists(asc):
            os.remove(asc)
        p = run([PY, *argv[1:]])  # Debian's python3, the one with python3-can
        self.assertEqual(p.returncode, 0, f"{command}\n{p.stderr}")
        self.assertTrue(os.path.exists(asc), f"the command writes {asc}")
        self.assertEqual(decoded_samples(asc), decoded_samples(sim_log()), "the ASC holds every sample of the log")
        m = run([f"{ARGS.bin}/resolver-model", "fit", asc])
        self.assertEqual(m.returncode, 0, m.stderr)

    def test_blf_by_content(self):
        blf = self.make_blf("blf_named.log")
        self.assertIn("starts with 'LOGG'", refused_by_both(self, blf))
        self.assertIn("starts with 'LOGG'", refused_by_both(self, blf, "--format", "candump"))

    def test_gzip_refused_and_its_command_decompresses_it(self):
        gz = work("refused.log.gz")
        with open(sim_log(), "rb") as src, gzip.open(gz, "wb") as dst:
            shutil.copyfileobj(src, dst)
        err = refused_by_both(self, gz)
        self.assertIn("gzip", err)
        command = err.split("give that: ", 1)[1].strip()
        self.assertEqual(command, f"zcat '{gz}' > '{work('refused.log')}'")
        plain = work("unzipped.log")
        p = subprocess.run(["sh", "-c", command.replace(work("refused.log'"), plain + "'")], capture_output=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(decoded_samples(plain), decoded_samples(sim_log()))

    def test_gzip_by_content(self):
        gz = work("gzip_named.log")
        with open(sim_log(), "rb") as src, gzip.open(gz, "wb") as dst:
            shutil.copyfileobj(src, dst)
        err = refused_by_both(self, gz)
        self.assertIn("starts with the bytes 1f 8b", err)
        self.assertIn(f"zcat '{gz}' > '{work('gzip_named.unzipped.log')}'", err)

    def test_control_text_starting_like_blf_is_read(self):
        # "LOGG" followed by text is no BLF header: the file is read (as candump, bad lines counted).
        text = work("logg_text.log")
        with open(text, "w") as f:
            f.write("LOGGED BY BENCH 3\n")
            with open(sim_log()) as src:
                f.write(src.read())
        decoded_samples(text)


class OutOfMemory(unittest.TestCase):
    """A log larger than the memory resolver-model may use (an address-space limit set
    with prlimit --as, as ulimit -v does): exit 4 and one line that says so, not a bare
    std::bad_alloc with exit 1 or 70."""

    def test_model_out_of_memory(self):
        prlimit = shutil.which("prlimit")
        if prlimit is None:
            self.skipTest("no prlimit (util-linux)")
        model = f"{ARGS.bin}/resolver-model"
        if "asan" in run(["ldd", model]).stdout:
            self.skipTest("AddressSanitizer reserves terabytes of address space: no --as limit fits")
        big = work("oom_60s.log")  # 60 s at 2 kHz: ~40 MiB more than the 1 s log once read
        p = run([f"{ARGS.bin}/resolver-sim", "--out", big, "--duration", "60", "--seed", "5"])
        self.assertEqual(p.returncode, 0, p.stderr)
        # The smallest limit (8 MiB steps) under which the 1 s log is still fitted.
        for mib in range(16, 1024, 8):
            if run([prlimit, f"--as={mib << 20}", model, "fit", sim_log()]).returncode == 0:
                break
        else:
            self.fail("resolver-model fit of a 1 s log fails under any address-space limit up to 1 GiB")
        p = run([prlimit, f"--as={mib << 20}", model, "fit", big])
        self.assertEqual(p.returncode, 4, f"--as={mib} MiB: {p.stderr}")
        self.assertRegex(p.stderr, r"^resolver-model: out of memory: ")
        self.assertNotIn("std::bad_alloc", p.stderr)
        self.assertEqual(p.stderr.count("\n"), 1, "one line: " + p.stderr)
        self.assertIn("--chunk", p.stderr, "the message names the way to read a long log")
        # The way out it names: 16 MiB more than the 1 s log needs does not hold the 60 s log
        # (~40 MiB more), but read in 1 s chunks it is fitted (two chunks and the statistics).
        roomy = f"--as={(mib + 16) << 20}"
        self.assertEqual(run([prlimit, roomy, model, "fit", big]).returncode, 4, "control: whole, it does not fit")
        p = run([prlimit, roomy, model, "fit", big, "--chunk", "1"])
        self.assertEqual(p.returncode, 0, f"{roomy}: fit --chunk 1: {p.stderr}")
        self.assertIn("merged 60 runs", p.stdout)


class NotAFile(unittest.TestCase):
    def test_echo_refuses_a_fifo_without_waiting_for_a_writer(self):
        fifo = work("echo.fifo")
        if os.path.exists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        p = run([f"{ARGS.bin}/resolver-echo", "--log", fifo], timeout=30)
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn(f"{fifo}: not a regular file", p.stderr)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
