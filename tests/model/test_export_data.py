#!/usr/bin/env python3
"""resolver-model export-data, end to end: resolver-sim hides quadrature next to
amplitude imbalance (alpha = 0.003, beta = 0.002 rad; phase currents and the reference
encoder). `export-data LOG --effects amplitude_imbalance,quadrature --csv OUT --mat OUT`
is read back with independent readers, Python's csv module and scipy.io.loadmat
(Debian python3-scipy), and compared with `resolver-model fit --json` on the same log:

  - one header line of identifiers (MATLAB readtable / pandas names), units as
    suffixes, one row per sample with an angle, as many as the fit's "covers.rows";
    the fitted flags count covers.fitted
  - the parameters file: the fit's names, values, standard errors and units
  - measured - model = residual in every row, and the residual's rms over the fitted
    rows is the fit's residual rms of each signal
  - the model column is the physics: amplitude imbalance and quadrature move the
    sin/cos angle by (alpha/2) sin 2theta - (beta/2)(1 - cos 2theta) (Hanselman eq. 5
    and 7), plus the fitted constant
  - the raw signals beside them (sin_raw, cos_raw, theta_rd_rad, theta_ref_m_rad,
    i_a_a, i_b_a, i_c_a): recomputing the fit's columns from them by the textbook
    formulas gives the fit's columns (eps_rd = theta - theta_rd, eps_sc = theta -
    atan2(sin, cos), the radius over its median, Clarke + Park at theta_e for i_d, i_q;
    the reference angle is theta_m); the simulated currents are balanced
  - the .mat holds the same columns, units, descriptions, parameters and info, the
    info's numbers (p_r, p, residual and floor) as numbers
  - control: without --csv or --mat it refuses (exit 2); an unwritable path names it

  test_export_data.py --bin BUILD/bin --work DIR
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import unittest

ARGS = None
IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
EFFECTS = "amplitude_imbalance,quadrature"
# The CSV keeps 12 significant digits: a value read back is within 1e-11 of it, relative.
CSV_RELATIVE = 1e-11


def run(cmd, expect_rc=0):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if expect_rc is not None and p.returncode != expect_rc:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode} (expected {expect_rc}):\n{p.stdout}\n{p.stderr}")
    return p


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


class ExportData(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.model = os.path.join(ARGS.bin, "resolver-model")
        cls.log = os.path.join(ARGS.work, "hidden_quadrature.log")
        run([os.path.join(ARGS.bin, "resolver-sim"), "-o", cls.log, "-e", "amplitude_imbalance:alpha=0.003",
             "-e", "quadrature:beta=0.002", "--seed", "5"])
        cls.csv_path = os.path.join(ARGS.work, "export.csv")
        cls.params_path = os.path.join(ARGS.work, "export.params.csv")
        cls.mat_path = os.path.join(ARGS.work, "export.mat")
        for f in (cls.csv_path, cls.params_path, cls.mat_path):
            if os.path.exists(f):
                os.remove(f)
        cls.proc = run([cls.model, "export-data", cls.log, "--effects", EFFECTS, "--csv", cls.csv_path,
                        "--mat", cls.mat_path])
        cls.fit = json.loads(run([cls.model, "fit", cls.log, "--effects", EFFECTS, "--json"]).stdout)
        with open(cls.csv_path, newline="") as f:
            reader = csv.reader(f)
            cls.header = next(reader)
            cls.rows = [[float(v) for v in row] for row in reader]  # float() reads NaN as MATLAB writes it
        cls.col = {name: [r[i] for r in cls.rows] for i, name in enumerate(cls.header)}
        with open(cls.params_path, newline="") as f:
            cls.params = list(csv.DictReader(f))
        cls.fitted = [i for i, v in enumerate(cls.col["fitted"]) if v == 1.0]

    def test_stdout_says_what_was_written(self):
        self.assertIn(f"wrote {self.csv_path} (10000 samples x {len(self.header)} columns, 2 parameters",
                      self.proc.stdout)
        self.assertIn(f"and {self.params_path}", self.proc.stdout)
        self.assertIn(f"wrote {self.mat_path}", self.proc.stdout)

    def test_one_header_of_identifiers_and_one_row_per_sample(self):
        for name in self.header:
            self.assertRegex(name, IDENTIFIER)
        self.assertEqual(len(set(self.header)), len(self.header))
        for name in ("t_s", "theta_rad", "theta_m_rad", "theta_e_rad", "speed_rpm", "fitted", "eps_rd_rad",
                     "eps_rd_model_rad", "eps_rd_residual_rad", "eps_sc_rad", "radius_dev", "i_d_a",
                     "i_q_model_a", "i_q_residual_a"):
            self.assertIn(name, self.header)
        self.assertTrue(all(len(r) == len(self.header) for r in self.rows))
        self.assertEqual(len(self.rows), self.fit["covers"]["rows"])
        self.assertEqual(len(self.fitted), self.fit["covers"]["fitted"])
        t = self.col["t_s"]
        self.assertTrue(all(b > a for a, b in zip(t, t[1:])), "time increases")
        for name in ("theta_rad", "theta_m_rad", "theta_e_rad"):
            self.assertTrue(all(0.0 <= a < 2 * math.pi for a in self.col[name]), name)
        # p = p_r = 3 here: theta_e = 3 theta_m = theta (wrapped).
        for a, b in zip(self.col["theta_e_rad"], self.col["theta_rad"]):
            self.assertAlmostEqual(math.remainder(a - b, 2 * math.pi), 0.0, delta=1e-9)
        self.assertAlmostEqual(sum(self.col["speed_rpm"]) / len(self.rows), 200.0, delta=0.5)

    def test_parameters_are_the_fits(self):
        fit = self.fit["params"]
        self.assertEqual([p["name"] for p in self.params], list(fit))
        for p in self.params:
            f = fit[p["name"]]
            # fit --json prints 9 significant digits.
            self.assertAlmostEqual(float(p["value"]) / f["value"], 1.0, delta=1e-8, msg=p["name"])
            self.assertAlmostEqual(float(p["std_error"]) / f["stderr"], 1.0, delta=1e-8, msg=p["name"])
            self.assertEqual(p["unit"], f["unit"].strip("[]"))
        alpha = float(self.params[0]["value"])
        self.assertAlmostEqual(alpha, 0.003, delta=5e-5)  # the simulated value, within the noise

    def test_residual_is_measured_minus_model_and_its_rms_the_fits(self):
        pairs = {"position_error": [("eps_rd_rad", "eps_rd_model_rad", "eps_rd_residual_rad")],
                 "sin_cos": [("eps_sc_rad", "eps_sc_model_rad", "eps_sc_residual_rad"),
                             ("radius_dev", "radius_dev_model", "radius_dev_residual")],
                 "i_dq": [("i_d_a", "i_d_model_a", "i_d_residual_a"), ("i_q_a", "i_q_model_a", "i_q_residual_a")]}
        signals = {s["signal"]: s for s in self.fit["signals"]}
        for signal, columns in pairs.items():
            residuals = []
            for measured, model, residual in columns:
                for i in range(len(self.rows)):
                    m, p, r = self.col[measured][i], self.col[model][i], self.col[residual][i]
                    self.assertLessEqual(abs(m - p - r), CSV_RELATIVE * (abs(m) + abs(p)) + 1e-300, residual)
                residuals += [self.col[residual][i] for i in self.fitted]
            got, want = rms(residuals), signals[signal]["rms"]
            self.assertEqual(len(residuals), signals[signal]["rows"], signal)
            # position and sin/cos: the fit is linear, its RSS is the residual's at the fitted
            # values (fit --json prints 9 digits). i_dq: the fit reports the linearised RSS
            # of its last step, measured 7e-4 above the residual at the fitted values here
            # (told to the discovery's owner); 1e-2 keeps that known gap out of this test.
            tolerance = 1e-2 if signal == "i_dq" else 1e-6
            self.assertAlmostEqual(got / want, 1.0, delta=tolerance, msg=f"{signal}: {got} vs fit {want}")

    def test_model_column_is_hanselmans_sin_cos_error(self):
        alpha = float(self.params[0]["value"])
        beta = float(self.params[1]["value"])
        theta, model = self.col["theta_rad"], self.col["eps_sc_model_rad"]
        expected = [alpha / 2 * math.sin(2 * a) - beta / 2 * (1 - math.cos(2 * a)) for a in theta]
        constant = sum(m - e for m, e in zip(model, expected)) / len(model)
        worst = max(abs(m - e - constant) for m, e in zip(model, expected))
        # First order in alpha and beta (signature.h): the neglected terms are ~alpha^2 = 1e-5 rad.
        self.assertLess(worst, 2e-5)
        self.assertGreater(max(abs(e) for e in expected), 1e-3)  # the check has something to see

    def test_raw_signals_give_the_fits_columns(self):
        c = self.col
        for name in ("sin_raw", "cos_raw", "theta_rd_rad", "theta_ref_m_rad", "i_a_a", "i_b_a", "i_c_a",
                     "i_d_a", "i_q_a"):
            self.assertIn(name, self.header)
            self.assertFalse(any(math.isnan(v) for v in c[name]), f"{name}: every sample of this log has it")
        two_pi = 2 * math.pi
        # CSV: 12 significant digits of values up to 2 pi (angles) and ~26000 counts.
        angle_tol = 1e-9
        for i in range(len(self.rows)):
            theta = c["theta_rad"][i]
            self.assertAlmostEqual(math.remainder(theta - c["theta_rd_rad"][i] - c["eps_rd_rad"][i], two_pi), 0.0,
                                   delta=angle_tol, msg=f"eps_rd row {i}")
            seen = math.atan2(c["sin_raw"][i], c["cos_raw"][i])
            self.assertAlmostEqual(math.remainder(theta - seen - c["eps_sc_rad"][i], two_pi), 0.0,
                                   delta=angle_tol, msg=f"eps_sc row {i}")
            self.assertAlmostEqual(math.remainder(c["theta_ref_m_rad"][i] - c["theta_m_rad"][i], two_pi), 0.0,
                                   delta=angle_tol, msg=f"reference row {i}")
        # radius_dev = radius / amplitude - 1 with one amplitude for the log (the median radius).
        amplitudes = [math.hypot(a, b) / (1.0 + r) for a, b, r in zip(c["sin_raw"], c["cos_raw"], c["radius_dev"])]
        self.assertLess((max(amplitudes) - min(amplitudes)) / amplitudes[0], 1e-9)
        self.assertAlmostEqual(amplitudes[0], sorted(math.hypot(a, b) for a, b in zip(c["sin_raw"], c["cos_raw"]))[
            len(amplitudes) // 2], delta=1.0)
        # Clarke (amplitude invariant) and Park at the motor electrical angle.
        worst = 0.0
        for i in range(len(self.rows)):
            ia, ib, ic = c["i_a_a"][i], c["i_b_a"][i], c["i_c_a"][i]
            alpha, beta = ia, (ib - ic) / math.sqrt(3.0)
            th = c["theta_e_rad"][i]
            d = alpha * math.cos(th) + beta * math.sin(th)
            q = -alpha * math.sin(th) + beta * math.cos(th)
            worst = max(worst, abs(d - c["i_d_a"][i]), abs(q - c["i_q_a"][i]))
            self.assertLess(abs(ia + ib + ic), 0.5, f"row {i}: the simulated phases are balanced up to noise")
        self.assertLess(worst, 1e-8)
        self.assertAlmostEqual(sum(c["i_q_a"]) / len(self.rows), 10.0, delta=0.1)  # resolver-sim's default i_q

    def test_mat_holds_the_same_table(self):
        try:
            import scipy.io
        except ImportError:
            self.fail("python3-scipy is needed to read the .mat independently (tools/install-deps.sh installs it)")
        mat = scipy.io.loadmat(self.mat_path)
        self.assertEqual(sorted(k for k in mat if not k.startswith("__")),
                         ["descriptions", "info", "params", "samples", "units"])
        samples = mat["samples"][0, 0]
        self.assertEqual(list(samples.dtype.names), self.header)
        for name in self.header:
            values = samples[name].ravel()
            self.assertEqual(values.shape, (len(self.rows),), name)
            for a, b in zip(values[::97], self.col[name][::97]):
                if math.isnan(b):
                    self.assertTrue(math.isnan(a), name)
                else:
                    self.assertLessEqual(abs(a - b), CSV_RELATIVE * abs(a) + 1e-300, name)
        units = mat["units"][0, 0]
        self.assertEqual(str(units["theta_rad"][0]), "rad")
        self.assertEqual(str(units["i_d_a"][0]), "A")
        self.assertTrue(str(mat["descriptions"][0, 0]["eps_rd_rad"][0]).startswith("measured position error"))
        params = mat["params"][0, 0]
        names = [str(c[0][0]) for c in params["name"]]
        self.assertEqual(names, [p["name"] for p in self.params])
        for a, p in zip(params["value"].ravel(), self.params):
            self.assertAlmostEqual(a / float(p["value"]), 1.0, delta=CSV_RELATIVE, msg=p["name"])
        self.assertEqual([str(c[0][0]) for c in params["unit"]], [p["unit"] for p in self.params])
        info = mat["info"][0, 0]
        self.assertEqual(str(info["model"][0]), EFFECTS)
        for key, want in (("p_r", 3.0), ("p", 3.0), ("residual_rms_rad", self.fit["residual_rms_rad"])):
            value = info[key]
            self.assertEqual(value.dtype.kind, "f", f"info.{key} is a number, not {value.dtype}")
            self.assertEqual(value.shape, (1, 1), key)
            self.assertAlmostEqual(float(value[0, 0]) / want, 1.0, delta=1e-8, msg=key)
        self.assertGreater(float(info["noise_floor_rad"][0, 0]), 0.0)
        self.assertEqual(str(mat["units"][0, 0]["i_a_a"][0]), "A")
        self.assertEqual(str(info["log"][0]), self.log)

    def test_needs_an_output_and_names_an_unwritable_one(self):
        p = run([self.model, "export-data", self.log], expect_rc=2)
        self.assertIn("give --csv OUT, --mat OUT or both", p.stderr)
        for option in ("--csv", "--mat"):
            bad = os.path.join(ARGS.work, "no-such-dir", "x" + option.replace("--", "."))
            p = run([self.model, "export-data", self.log, option, bad], expect_rc=3)  # a failed write: I/O
            self.assertIn(f"cannot write {bad}: No such file or directory", p.stderr)


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
