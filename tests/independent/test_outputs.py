"""The command line and its files: determinism, the scope CSV read back with Python's csv
module, the truth JSON, record-level impairments, errors that name the bad spec."""
import csv
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import support
from benchgen import readers

CLI = os.path.join(support.HERE, "benchgen.py")
FILETIME_UNIX_EPOCH = 116444736000000000  # 100 ns ticks 1601-01-01 -> 1970-01-01


def cli(*args, cwd):
    return subprocess.run([sys.executable, CLI, *args], cwd=cwd, capture_output=True, text=True)


class DeterminismTest(unittest.TestCase):
    def test_same_seed_same_files(self):
        args = ["--out", "x.log", "--asc", "x.asc", "--csv", "x.csv", "--truth", "x.json",
                "--truth-samples", "x_s.csv", "--profile", "reversals", "--seed", "5",
                "-e", "noise:sigma_sc=2,sigma_i=0.01", "-e", "outliers:rate=2,size=500,channel=cos",
                "-e", "timestamp_jitter:sigma=20e-6", "-e", "tracking_loop:omega_n=800,zeta=0.7"]
        contents = []
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            for where in (a, b):
                result = cli(*args, cwd=where)
                self.assertEqual(result.returncode, 0, result.stderr)
                contents.append({f: open(os.path.join(where, f), "rb").read()
                                 for f in ("x.log", "x.asc", "x.csv", "x.json", "x_s.csv")})
            self.assertEqual(contents[0], contents[1])
            result = cli(*[a if a != "5" else "6" for a in args], cwd=a)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertNotEqual(open(os.path.join(a, "x.log"), "rb").read(), contents[1]["x.log"])


class ScopeCsvTest(unittest.TestCase):
    def test_csv_parses_back_to_the_samples(self):
        with tempfile.TemporaryDirectory() as tmp:
            result = cli("--csv", "s.csv", "--truth-samples", "t.csv", "--truth", "t.json",
                         "--profile", "out_and_back", "--p-r", "1", "--p", "4", "--sample-rate", "100",
                         "--layout", "angle_only", "--csv-columns", "rd_angle,ref_angle,sin,i_a",
                         "-e", "delay:d=0.004", "-e", "backlash:h=0.002", cwd=tmp)
            self.assertEqual(result.returncode, 0, result.stderr)
            with open(os.path.join(tmp, "s.csv"), encoding="utf-8", newline="") as handle:
                lines = list(csv.reader(handle, delimiter=";"))
            with open(os.path.join(tmp, "t.csv"), encoding="ascii", newline="") as handle:
                truth = list(csv.DictReader(handle))
            meta = json.load(open(os.path.join(tmp, "t.json")))
        self.assertEqual(meta["outputs"]["csv"]["header_lines"], 4)
        header, rows = lines[4], lines[5:]
        self.assertEqual(header, ["Time [FILETIME]", "RD angle [deg]", "Reference angle [deg]",
                                  "Sin [counts]", "Ia [A]"])
        self.assertEqual(lines[2], ["Sample interval [s]", "0,01"])
        self.assertEqual(len(rows), 700)  # 7 s at 100 Hz
        self.assertEqual(len(rows), len(truth))
        for row in rows:
            self.assertTrue(all("." not in cell for cell in row), row)  # decimal comma only
        ticks = np.array([int(r[0]) for r in rows], dtype=np.int64)  # exact integers: 100 ns
        start = 1_700_000_000 * 10_000_000 + FILETIME_UNIX_EPOCH
        np.testing.assert_array_equal(ticks - start, np.arange(700) * 100_000)
        value = lambda k: np.array([float(r[k].replace(",", ".")) for r in rows])
        rd_truth = np.array([float(r["rd_angle_rad"]) for r in truth])
        theta_m = np.array([float(r["theta_m_rad"]) for r in truth])
        # 6 decimals: the printed degrees are within 5e-7 deg of the sent angle.
        np.testing.assert_allclose(value(1), np.degrees(rd_truth), atol=5e-7 + 1e-9)
        np.testing.assert_allclose(value(2), np.degrees(np.mod(theta_m, 2 * np.pi)), atol=5e-7 + 1e-6)


class TruthJsonTest(unittest.TestCase):
    def test_truth_lists_everything(self):
        with tempfile.TemporaryDirectory() as tmp:
            result = cli("--out", "x.log", "--truth", "x.json", "--profile", "speed_steps", "--seed", "3",
                         "-e", "harmonics:k3=0.001,k4_opp=2e-4", "-e", "outliers:rate=3,size=800,channel=sin",
                         "-e", "tracking_loop:omega_n=1500", cwd=tmp)
            self.assertEqual(result.returncode, 0, result.stderr)
            truth = json.load(open(os.path.join(tmp, "x.json")))
            stamps, ids, data, _ = readers.read_candump(os.path.join(tmp, "x.log"))
        self.assertEqual(truth["seed"], 3)
        self.assertEqual(truth["sample_rate_hz"], 2000.0)
        self.assertEqual(truth["profile"]["expanded"], "100:2,300:2,600:2,1000:2")
        self.assertEqual(truth["layout"]["name"], "default")
        harmonics = next(e for e in truth["effects"] if e["name"] == "harmonics")
        self.assertEqual(harmonics["params"]["k3"], 0.001)
        self.assertEqual(harmonics["params"]["k4_opp"], 2e-4)
        self.assertEqual(len(harmonics["params"]), 1 + 4 * 19)  # k0, k2..k20, k2_opp..k20_opp and their phases
        loop = next(e for e in truth["effects"] if e["name"] == "tracking_loop")
        self.assertEqual(loop["params"]["zeta"], 0.7)  # defaults are written out
        self.assertEqual(truth["converter"]["kind"], "tracking_loop")
        self.assertLessEqual(1500 / 2000 / truth["converter"]["rk4_substeps_per_sample"], 0.05)
        self.assertEqual(truth["layout"]["frames_per_id"]["0x100"], 16000)
        self.assertEqual(truth["outputs"]["candump"]["records_out"], len(ids))
        # Outliers: each listed spike is in the sent sin channel, about `size` off its neighbours.
        spikes = [e for e in truth["events"] if e["kind"] == "outlier"]
        self.assertGreater(len(spikes), 5)  # Poisson mean 24
        sin = readers.decode_default(ids, data)[0x100]["sin"].astype(float)
        # Without a spike, s_k - (s_k-1 + s_k+1)/2 = A (1 - cos(n dtheta)) sin(n theta) per
        # harmonic n: at most A (1 - cos dtheta) + A k3 (1 - cos 3dtheta) + ..., dtheta =
        # 3 x 1000 r/min / 2000 Hz = 0.157 rad; whole-count rounding adds 1.
        dtheta = 3 * 1000 * 2 * np.pi / 60 / 2000
        bound = 26000 * ((1 - np.cos(dtheta)) + 0.001 * (1 - np.cos(3 * dtheta))
                         + 2e-4 * (1 - np.cos(4 * dtheta))) + 1.0
        isolated = [e for e in spikes if 0 < e["index"] < len(sin) - 1
                    and not any(abs(o["index"] - e["index"]) == 1 for o in spikes)]
        self.assertTrue(isolated)
        for spike in isolated:
            k = spike["index"]
            jump = sin[k] - 0.5 * (sin[k - 1] + sin[k + 1])
            self.assertLess(abs(jump - spike["added"]), bound, spike)


class RecordImpairmentTest(unittest.TestCase):
    def _log(self, *effects):
        with tempfile.TemporaryDirectory() as tmp:
            args = ["--out", "x.log", "--truth", "x.json", "--profile", "200:2"]
            for e in effects:
                args += ["-e", e]
            result = cli(*args, cwd=tmp)
            self.assertEqual(result.returncode, 0, result.stderr)
            return readers.read_candump(os.path.join(tmp, "x.log")), json.load(open(os.path.join(tmp, "x.json")))

    def test_dropped_and_duplicated(self):
        (stamps, ids, data, _), truth = self._log("dropped_frames:rate=0.01", "duplicated_frames:rate=0.005")
        stats = truth["outputs"]["candump"]
        self.assertEqual(stats["records_in"], 3 * 4000 + 20)
        self.assertEqual(len(ids), stats["records_in"] - stats["dropped"] + stats["duplicated"])
        self.assertGreater(stats["dropped"], 0)
        self.assertGreater(stats["duplicated"], 0)
        counters = data[ids == 0x100][:, 0].astype(int)
        steps = np.diff(counters) % 256
        self.assertTrue((steps == 0).any(), "a duplicated frame repeats its counter")
        self.assertTrue((steps >= 2).any(), "a dropped frame leaves a counter gap")

    def test_timestamp_steps_and_jitter(self):
        (stamps, ids, _, _), truth = self._log("timestamp_step:at=0.5,by=-0.2", "timestamp_step:at=1.5,by=3",
                                               "timestamp_jitter:sigma=1e-6")
        back = np.flatnonzero(np.diff(stamps) < -100_000)
        ahead = np.flatnonzero(np.diff(stamps) > 2_000_000)
        self.assertEqual(len(back), 1)
        self.assertEqual(len(ahead), 1)
        self.assertAlmostEqual(stamps[back[0] + 1] / 1e6 - 1.7e9, 0.3, delta=0.001)
        self.assertEqual(len(truth["outputs"]["candump"]["timestamp_steps"]), 2)


class ErrorsTest(unittest.TestCase):
    def test_bad_specs_are_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            for args, fragment in (
                    (["-e", "amplitude_imbalanse:alpha=0.1"], "unknown effect 'amplitude_imbalanse'"),
                    (["-e", "quadrature:gamma=0.1"], "unknown parameter 'gamma' of quadrature"),
                    (["-e", "quadrature:beta=2"], "beta=2 [rad] is outside"),
                    (["-e", "delay"], "parameter 'd' [s] of delay is required"),
                    (["-e", "outliers:rate=1,size=2,channel=tacho"], "channel='tacho' is not one of"),
                    (["-e", "delay:d=1e-3", "-e", "delay:d=2e-3"], "delay given twice"),
                    (["--profile", "30:2,x"], "profile item 2 'x'"),
                    (["--csv-columns", "rd_angle,speed", "--csv", "a.csv"], "--csv-columns: unknown speed"),
                    (["--sample-rate", "100.5"], "whole number of Hz")):
                result = cli("--out", "x.log", *args, cwd=tmp)
                self.assertEqual(result.returncode, 2, args)
                self.assertIn(fragment, result.stderr, args)

    def test_listings(self):
        with tempfile.TemporaryDirectory() as tmp:
            listing = cli("--list-effects", cwd=tmp).stdout
            for name in ("amplitude_imbalance", "quadrature", "offsets", "harmonics", "eccentricity",
                         "mechanical_harmonics", "mounting_offset", "backlash", "delay", "channel_delay",
                         "sampling_skew", "tracking_loop", "quantization", "current_offsets",
                         "current_gain_mismatch", "dead_time", "noise"):
                self.assertIn(f"  {name} ", listing)
            result = cli("--layout", "angle_only", "--write-dbc", "a.dbc", cwd=tmp)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn('"deg"', open(os.path.join(tmp, "a.dbc")).read())


if __name__ == "__main__":
    unittest.main()
