#!/usr/bin/python3
"""Issue 26: resolverd --replay of a CSV with only sin/cos columns (no R/D angle,
no reference), through the real program.

  Short    9 revolutions, fewer than the default [model] window_revolutions (16):
           the default method "model" gets its first fit only at the end of the
           input, when no sample is left to compensate. It used to say nothing
           (no reference: no position lines) or "no model fitted yet (or
           compensation disabled)"; now the report, text and JSON, says why and
           which key changes it, and each suggestion does compensate.
  Long     control: 90 revolutions, compensated by default from the first window,
           and the report says from when.

  test_sincos_only.py --bin BUILD/bin --work DIR [unittest arguments]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import unittest

ARGS = None

CONFIG = """[bench]
p_r = 1
p = 1
[input.csv]
delimiter = ","
column_names = true
time_column = "t"
time_unit = "s"
[input.csv.columns]
sin = { column = "sin" }
cos = { column = "cos" }
"""


def write_csv(path, rev_per_s, seconds=3.0, rate=10000.0):
    """A 1X resolver at constant speed with a 1 % amplitude imbalance, sin/cos in counts."""
    with open(path, "w") as f:
        f.write("t,sin,cos\n")
        for i in range(int(seconds * rate)):
            t = i / rate
            th = 2 * math.pi * rev_per_s * t
            f.write(f"{t:.6f},{10100 * math.sin(th):.3f},{9900 * math.cos(th):.3f}\n")


def replay(csv, extra_config=""):
    config = csv + ".toml"
    with open(config, "w") as f:
        f.write(CONFIG + extra_config)
    report = csv + ".json"
    r = subprocess.run([os.path.join(ARGS.bin, "resolverd"), "--replay", csv, "--config", config, "--once",
                        "--fast", "--quiet", "--lcm", "memq://", "--report", report],
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise AssertionError(f"resolverd exit {r.returncode}: {r.stderr}")
    with open(report) as f:
        return r.stdout, json.load(f)


class SinCosOnly(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.short = os.path.join(ARGS.work, "sincos_short.csv")
        cls.long = os.path.join(ARGS.work, "sincos_long.csv")
        write_csv(cls.short, 3.0)    # 9 revolutions
        write_csv(cls.long, 30.0)    # 90 revolutions

    def test_short_log_says_why_it_is_not_compensated(self):
        out, rep = replay(self.short)
        self.assertEqual(rep["compensation"]["samples"], 0)
        self.assertIsNone(rep["compensation"]["started_s"])
        reason = rep["compensation"]["reason"]
        self.assertIn("window_revolutions = 16 resolver revolutions, the input turned 9", reason)
        self.assertIn('method = "sincos_least_squares"', reason)
        self.assertIn("not compensated: " + reason, out)

    def test_each_suggested_key_compensates_the_short_log(self):
        for extra in ('[model]\nwindow_revolutions = 3\n', '[estimator]\nmethod = "sincos_least_squares"\n'):
            with self.subTest(extra=extra):
                out, rep = replay(self.short, extra)
                self.assertGreater(rep["compensation"]["samples"], 5000)
                self.assertIsNone(rep["compensation"]["reason"])
                self.assertRegex(out, r"compensated from \d\.\d{3} s: \d+ of 30000 samples published compensated")

    def test_standard_errors_name_their_basis(self):
        # The final estimate is the whole run's (every window's model combined, issue 26):
        # said once, in the text and the JSON alike.
        out, rep = replay(self.long)
        basis = rep["std_error_basis"]
        self.assertRegex(basis, r"^the whole run: \d+ windows \(\d+ revolutions\) combined, inverse-variance weighted; "
                                r"(robust: window-to-window spread of \d+ windows|formal: from the windows' own errors)")
        self.assertIn("             +- standard error: " + basis + "\n", out)
        _, rep = replay(self.long, '[estimator]\nmethod = "hwang_integral"\n')
        self.assertRegex(rep["std_error_basis"], r"^robust: revolution-to-revolution spread of \d+ revolutions \(the whole run\)$")

    def test_long_log_is_compensated_by_default(self):
        out, rep = replay(self.long)
        self.assertEqual(rep["method"], "model")
        self.assertGreater(rep["compensation"]["samples"], 15000)
        self.assertLess(rep["compensation"]["started_s"], 1.5)
        self.assertIn("compensated from", out)
        self.assertNotIn("not compensated", out)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
