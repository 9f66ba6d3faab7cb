#!/usr/bin/env python3
"""End-to-end: resolver-sim -> candump log -> resolverd --replay --once -> LCM log -> resolver-echo.

Checks, on Hwang et al.'s operating point (alpha = 0.003, 200 r/min, 16-bit R/D,
p_r = p = 3), that the daemon's alpha is within 5 % of the truth and that the
2x dq ripple with the compensated angle is at least 10x smaller than with the
raw angle, and that nothing was lost on the way (every sample published).

Where the tolerances come from (see also docs in README):
  * alpha: the estimator's per-revolution spread from 16-bit quantization is
    pi*LSB/sqrt(12 N) ~ 6e-6 (N = 200 samples per revolution), 0.2 % of alpha;
    the small-angle approximation (Hwang eq. 10) biases it by alpha/2 = 0.15 %;
    sin/cos noise filtered by the tracking loop adds less. With the sample grid
    locked to the revolution (exactly 200 samples per revolution) the 16-bit
    quantization error repeats every revolution and does not average out: it
    biases alpha by up to ~0.8 % depending on the start phase. 5 % (the issue's
    requirement) is therefore met with a wide margin; a broken estimator
    (wrong sign, factor 2, missing normalisation) misses it by far.
  * ripple: raw 2x ripple is I_m alpha/2 = 15 mA at I_q = 10 A. After
    compensation what remains is I_m |alpha - alpha_hat| / 2 (~0.1 mA) plus
    the noise floor of the ripple measurement, 2 sigma_i / sqrt(N K) for the
    simulator's sigma_i = 20 mA, N = 200 samples per electrical revolution and
    K coherently averaged revolutions: 2.5 mA for K = 1, 0.6 mA for K = 16.
    The test asks for K = 16 so that the floor is 25x below the raw ripple
    and the required 10x is decided by the compensation, not by the noise.
"""
import argparse
import json
import math
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "magnitude"))
from run_magnitude_sweep import spikes_in_log  # noqa: E402  (the log's own spike count)

ARGS = None


def run(cmd, **kw):
    proc = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return proc


def bench_log(name, effects, args=()):
    """A resolver-sim log of 8 s at 601.7 r/min (seed 3) with these --effect specs and options."""
    log = os.path.join(ARGS.work, f"{name}.log")
    cmd = [f"{ARGS.bin}/resolver-sim", "--out", log, "--rpm", "601.7", "--duration", "8", "--seed", "3", *args]
    for e in effects:
        cmd += ["--effect", e]
    run(cmd)
    return log


def replay_report(log, name, config=None):
    """resolverd --replay LOG --once --fast's run report (JSON)."""
    rep = os.path.join(ARGS.work, f"{name}.json")
    run([f"{ARGS.bin}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", "--report", rep] +
        (["--config", config] if config else []))
    with open(rep) as f:
        return json.load(f)


class ReplayPipeline(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        work = ARGS.work
        os.makedirs(work, exist_ok=True)
        cls.log = os.path.join(work, "hwang_200rpm.log")
        cls.truth = os.path.join(work, "hwang_200rpm.truth.json")
        cls.lcmlog = os.path.join(work, "hwang_200rpm.lcmlog")
        cls.report = os.path.join(work, "hwang_200rpm.report.json")
        for f in (cls.lcmlog, cls.report):
            if os.path.exists(f):
                os.remove(f)
        b = ARGS.bin
        run([f"{b}/resolver-sim", "--out", cls.log, "--rpm", "200", "--duration", "8", "--p-r", "3", "--p", "3",
             "--rd-bits", "16", "--iq", "10", "--effect", "amplitude_imbalance:alpha=0.003", "--seed", "7",
             "--truth", cls.truth])
        cls.config = os.path.join(work, "ripple16.toml")
        with open(cls.config, "w") as f:
            f.write("[output]\nripple_revolutions = 16\n")
        cls.daemon = run([f"{b}/resolverd", "--replay", cls.log, "--once", "--fast", "--quiet", "--config", cls.config,
                          "--lcm", f"file://{cls.lcmlog}?mode=w", "--report", cls.report])
        echo = run([f"{b}/resolver-echo", "--log", cls.lcmlog])
        cls.msgs = [json.loads(line) for line in echo.stdout.splitlines() if line.strip()]
        with open(cls.report) as f:
            cls.rep = json.load(f)
        with open(cls.log) as f:
            cls.log_frames = sum(1 for line in f if line.strip())

    def of_type(self, name):
        return [m for m in self.msgs if m["type"] == f"resolver.{name}"]

    def test_alpha_within_5_percent(self):
        est = [m for m in self.of_type("estimate_t") if m["converged"]]
        self.assertTrue(est, "no converged estimate_t published")
        last = est[-1]
        self.assertEqual(last["param_name"], ["amplitude_imbalance.alpha"])
        alpha = last["value"][0]
        self.assertLess(abs(alpha - 0.003) / 0.003, 0.05, f"alpha = {alpha}")
        self.assertAlmostEqual(self.rep["alpha"], alpha, places=12)

    def test_dq_ripple_falls_10x(self):
        dq = [m for m in self.of_type("dq_t") if m["ripple_valid"]]
        self.assertTrue(dq)
        last = dq[-1]
        self.assertEqual(last["ripple_order"], [1, 2, 6])
        raw, comp = last["i_d_ripple_raw"][1], last["i_d_ripple_comp"][1]
        self.assertGreater(raw, 0.010, "raw 2x i_d ripple should be ~I_m alpha/2 = 15 mA")
        self.assertGreaterEqual(raw / comp, 10.0, f"raw {raw} comp {comp}")
        # i_q = I_m cos(eps): no first-order 2x ripple from an angle error (second order, I_m eps^2/2).
        self.assertLess(last["i_q_ripple_raw"][1], 10.0 * 0.003 ** 2 * 10 + 0.002)

    def test_nothing_lost(self):
        health = self.of_type("health_t")
        self.assertTrue(health)
        last = health[-1]
        self.assertEqual(last["frames_seen"], self.log_frames)
        self.assertEqual(last["frames_decoded"], self.log_frames)
        self.assertEqual(last["num_reasons"], 0, last)
        self.assertEqual(last["samples_incomplete"], 0)
        angles = self.of_type("angle_t")
        self.assertEqual(len(angles), last["samples_complete"])
        idx = [a["sample_index"] for a in angles]
        self.assertEqual(idx, sorted(idx))
        self.assertEqual(idx[-1] - idx[0] + 1, len(idx), "sample indices must be consecutive")

    def test_report_printed(self):
        self.assertIn("alpha", self.daemon.stdout)
        self.assertIn("dq ripple", self.daemon.stdout)


class CurrentSpikes(unittest.TestCase):
    """One-sided 10 A spikes on phase current a at 50/s (resolver-sim's current_outliers, an
    inverter's switching edges on a current ADC) must not show in the dq ripple: taken in,
    they read as 170 mA at 1x theta_e and 105 mA at 6x where the currents carry 1-4 mA (a
    current sensor offset and a dead time that are not there; current_spike_gate.h). The
    control is the same bench without the spikes (same seed; the spikes' draws re-deal the
    noise, so the two differ by the ripple's noise floor, ~2 sigma / sqrt(N K) = 2 mA per
    order here: 20 mA noise, N = 67 samples per electrical turn at 600 r/min, K = 8)."""

    ORDERS = (0, 2)  # 1x and 6x in the report's ripple arrays
    TOLERANCE = 0.006  # [A] three noise floors

    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.rep = {}
        for name, extra in (("clean", []), ("spikes", ["current_outliers:rate=50,size=10,positive=1"])):
            log = bench_log(f"current_spikes_{name}",
                            ["amplitude_imbalance:alpha=0.003", "current_gain_mismatch:gain_a=0.1"] + extra)
            cls.rep[name] = replay_report(log, f"current_spikes_{name}")
            if name == "spikes":
                cls.in_log = spikes_in_log(log)  # the log's own count (run_magnitude_sweep.py)

    def test_the_ripple_is_the_clean_benchs(self):
        clean, spikes = self.rep["clean"], self.rep["spikes"]
        for key in ("i_d_ripple_raw", "i_q_ripple_raw", "i_d_ripple_comp"):
            for k in self.ORDERS:
                self.assertLess(abs(spikes[key][k] - clean[key][k]), self.TOLERANCE, f"{key}[{k}]: {spikes[key]} "
                                f"against {clean[key]} without spikes")
        # The gain error's 2x ripple (~0.5 A) is still there.
        self.assertLess(abs(spikes["i_d_ripple_raw"][1] - clean["i_d_ripple_raw"][1]), self.TOLERANCE)

    def test_every_spike_is_counted_and_nothing_else(self):
        self.assertEqual(self.rep["clean"]["ripple_current_spikes"], 0)
        self.assertGreater(self.in_log, 300)
        # All but those in the first window (64 samples) and at a restart may be judged.
        self.assertGreaterEqual(self.rep["spikes"]["ripple_current_spikes"], self.in_log - 3)
        self.assertLessEqual(self.rep["spikes"]["ripple_current_spikes"], self.in_log)


class SinSpikes(unittest.TestCase):
    """Spikes on the sin ADC (EMI on the resolver's cable: 3000 counts, 15 % of the amplitude,
    50/s, random sign) on a sensor whose offsets (15 %, -9 %) swing the radius by 35 %. Before:
    the signal health called the channels degraded (the radius' range took in spikes its running
    test missed: 11 % of the log), and the live windows counted every sample of an outlier
    episode as faulty ("outliers for 1065 of 1065 samples" where 2.5 % are impulses) and said the
    signals were faulty, naming nothing, where the same bench without spikes names offsets."""

    TRUTH = {"amplitude_imbalance.alpha": 0.003, "offsets.o_s": 0.15, "offsets.o_c": -0.09}

    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.rep = {}
        for name, extra in (("clean", []), ("spikes", ["outliers:rate=50,size=3000"])):
            log = bench_log(f"sin_spikes_{name}", ["amplitude_imbalance:alpha=0.003", "offsets:o_s=0.15,o_c=-0.09",
                                                   "tracking_loop:omega_n=0"] + extra,
                            ("--amplitude", "20000"))  # 15 % offsets and a 15 % spike stay below full scale
            for model, effects in (("seed", '["amplitude_imbalance"]'), ("true", '["amplitude_imbalance", "offsets"]')):
                cfg = os.path.join(ARGS.work, f"sin_spikes_{model}.toml")
                with open(cfg, "w") as f:
                    f.write(f"[model]\neffects = {effects}\n")
                cls.rep[(name, model)] = replay_report(log, f"sin_spikes_{name}_{model}", cfg)

    def test_the_live_windows_name_the_missing_effect_as_without_spikes(self):
        for name in ("clean", "spikes"):  # the clean bench is the control: the answer is its
            fit = self.rep[(name, "seed")]["model_fit"]
            self.assertEqual((fit["last_verdict"], fit["last_best_candidate"]), ("missing_effect", "offsets"),
                             f"{name}: {fit}")

    def test_no_degradation_and_the_true_model_at_its_floor(self):
        rep = self.rep[("spikes", "true")]
        faults = rep["signal_health"]["faults"]
        self.assertEqual(faults["degradation_of_signal"]["samples"], 0, faults["degradation_of_signal"])
        self.assertGreater(faults["outliers"]["samples"], 100)  # the spikes are seen, as spikes
        fit = rep["model_fit"]
        # 1.2x: the exact model's bound at real magnitudes (run_magnitude_sweep.py LIMIT).
        self.assertLess(fit["last_residual_rms_rad"], 1.2 * fit["last_noise_floor_rad"], fit)
        for name, truth in self.TRUTH.items():
            p = rep["params"][name]
            # 4 standard errors: 1 in 16000 by chance for one parameter.
            self.assertLess(abs(p["value"] - truth), 4.0 * p["stderr"], f"{name}: {p}")


class ReceiveJitter(unittest.TestCase):
    """Frames that arrive in 1 ms bursts (canplayer, USB adapters) must not
    distort the estimate: the DSP samples on its own clock and numbers the
    samples, so resolverd times samples by counter / sample rate. At 200 r/min
    a 0.5 ms timing error is omega * 0.5 ms = 31 mrad of apparent angle error,
    20x the 1.5 mrad alpha/2 signal, so frame timestamps alone fail badly."""

    @classmethod
    def setUpClass(cls):
        work = ARGS.work
        os.makedirs(work, exist_ok=True)
        b = ARGS.bin
        cls.log = os.path.join(work, "jitter_src.log")
        cls.bursty = os.path.join(work, "jitter_bursts.log")
        run([f"{b}/resolver-sim", "--out", cls.log, "--rpm", "200", "--duration", "6",
             "--effect", "amplitude_imbalance:alpha=0.003", "--seed", "11"])
        with open(cls.log) as src, open(cls.bursty, "w") as dst:
            for line in src:
                ts, rest = line.split(")", 1)
                us = round(float(ts[1:]) * 1e6)
                us -= us % 1000  # delivered at the end of each 1 ms burst, in order
                dst.write(f"({us // 1000000}.{us % 1000000:06d}){rest}")

    def alpha(self, time_source):
        cfg = os.path.join(ARGS.work, f"time_{time_source}.toml")
        with open(cfg, "w") as f:
            # Hwang's integral is the estimator that integrates over time, so its
            # result shows the jitter; the default model fit reads angles only.
            f.write(f'[bench]\ntime_source = "{time_source}"\n[estimator]\nmethod = "hwang_integral"\n')
        rep = os.path.join(ARGS.work, f"jitter_{time_source}.json")
        run([f"{ARGS.bin}/resolverd", "--replay", self.bursty, "--once", "--fast", "--quiet",
             "--lcm", "memq://", "--config", cfg, "--report", rep])
        with open(rep) as f:
            r = json.load(f)
        return r["alpha"], r["converged"]

    def test_counter_time_survives_bursts(self):
        alpha, converged = self.alpha("counter")
        self.assertTrue(converged)
        self.assertLess(abs(alpha - 0.003) / 0.003, 0.05, f"alpha = {alpha}")

    def test_frame_time_alone_would_fail(self):
        alpha, converged = self.alpha("frame")
        self.assertFalse(converged and abs(alpha - 0.003) / 0.003 < 0.05,
                         f"frame timestamps gave alpha = {alpha}: the jitter test no longer tests anything")


class EstimatorSelection(unittest.TestCase):
    """[estimator] method selects the estimator; estimate_t carries every
    parameter with its standard error. On a log with alpha, beta and offsets:
    the sin/cos least squares and the Fourier fit recover all four and bring
    the position error to the R/D quantization floor, LSB/sqrt(12) =
    (2 pi / 65536)/sqrt(12) = 2.77e-5 rad, while the seed's alpha-only model
    cannot (quadrature and offsets stay in the residual)."""

    TRUTH = {"amplitude_imbalance.alpha": 0.003, "quadrature.beta": 0.004,
             "offsets.o_s": 0.002, "offsets.o_c": -0.001}
    FLOOR = 2 * math.pi / 65536 / math.sqrt(12)

    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.log = os.path.join(ARGS.work, "abo.log")
        run([f"{ARGS.bin}/resolver-sim", "--out", cls.log, "--rpm", "200", "--duration", "4", "--seed", "5",
             "--effect", "amplitude_imbalance:alpha=0.003", "--effect", "quadrature:beta=0.004",
             "--effect", "offsets:o_s=0.002,o_c=-0.001"])

    def replay(self, method):
        cfg = os.path.join(ARGS.work, f"method_{method}.toml")
        with open(cfg, "w") as f:
            f.write(f'[estimator]\nmethod = "{method}"\n')
        rep = os.path.join(ARGS.work, f"method_{method}.json")
        lcmlog = os.path.join(ARGS.work, f"method_{method}.lcmlog")
        if os.path.exists(lcmlog):
            os.remove(lcmlog)
        run([f"{ARGS.bin}/resolverd", "--replay", self.log, "--once", "--fast", "--quiet", "--config", cfg,
             "--lcm", f"file://{lcmlog}?mode=w", "--report", rep])
        with open(rep) as f:
            report = json.load(f)
        echo = run([f"{ARGS.bin}/resolver-echo", "--log", lcmlog, "--type", "estimate_t"])
        estimates = [json.loads(l) for l in echo.stdout.splitlines() if l.strip()]
        return report, estimates

    def check_full_model(self, method):
        report, estimates = self.replay(method)
        self.assertTrue(report["converged"])
        last = estimates[-1]
        self.assertEqual(last["method"], method)
        params = dict(zip(last["param_name"], zip(last["value"], last["std_error"])))
        for name, truth in self.TRUTH.items():
            value, se = params[name]
            # Second-order model terms (alpha*beta, beta^2 ~ 1e-5) and the 16-bit
            # quantization of the R/D angle bound the bias; 3 % of the smallest
            # parameter is 3e-5.
            self.assertAlmostEqual(value, truth, delta=3e-5, msg=f"{method} {name}")
            self.assertTrue(se > 0 and se < 1e-4, f"{method} {name} stderr {se}")
        self.assertLess(report["eps_rms_comp_rad"], 1.5 * self.FLOOR, report["eps_rms_comp_rad"])

    def test_sincos_least_squares(self):
        self.check_full_model("sincos_least_squares")

    def test_fourier_reference(self):
        self.check_full_model("fourier_reference")

    def test_seed_model_leaves_the_other_effects(self):
        report, _ = self.replay("hwang_integral")
        self.assertGreater(report["eps_rms_comp_rad"], 20 * self.FLOOR)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
