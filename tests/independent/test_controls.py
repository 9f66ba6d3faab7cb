"""Controls outside the catalog and sample-level impairments do what their docs say.

Same bounds as test_signatures: F = 16-bit R/D rounding + reference rounding; (B1) the atan2
remainder m^2 / (2 (1 - m)) for an envelope perturbation of size m.
"""
import unittest

import numpy as np

from support import RD16_HALF_LSB, REF_HALF_LSB, fit_harmonics, run, wrap
from test_signatures import b1

P_R = 3
FLOOR = RD16_HALF_LSB + P_R * REF_HALF_LSB
RPM = 2 * np.pi / 60


class ControlsTest(unittest.TestCase):
    def test_alpha_drift_is_not_a_constant_alpha(self):
        alpha, rate = 0.002, 0.004  # alpha(t) from 0.002 to 0.022 over 5 s
        log, _, _ = run([f"amplitude_imbalance:alpha={alpha}", f"alpha_drift:rate={rate}"], profile="200:5")
        theta, eps = log.theta(), log.eps()
        a_t = alpha + rate * log.t
        np.testing.assert_allclose(eps, a_t / 2 * np.sin(2 * theta), atol=b1(a_t.max()) + FLOOR)
        # The best constant alpha leaves (rate (t - mean t) / 2) sin 2theta: std
        # rate T / (2 sqrt(12)) / sqrt(2) for a uniform t over T = 5 s.
        _, _, residual = fit_harmonics(theta, eps, [2])
        left = rate * 5.0 / (2 * np.sqrt(24))
        self.assertGreater(left, 10 * FLOOR)
        self.assertGreater(np.std(residual), 0.9 * left)

    def test_angle_drift(self):
        rate, amp, period = 2e-4, 3e-4, 2.0
        log, _, _ = run([f"angle_drift:rate={rate},amp={amp},period={period}"], profile="200:4")
        want = -(rate * log.t + amp * np.sin(2 * np.pi * log.t / period))
        np.testing.assert_allclose(log.eps(), want, atol=FLOOR)

    def test_mixed_order(self):
        # 5 theta_m + 3 theta with p_r = 3: order 14 in theta_m (an angle error, exact).
        amp = 5e-4
        log, _, _ = run([f"mixed_order:amp={amp},m=5,n=3,phase=0.4"], profile="200:3")
        np.testing.assert_allclose(log.eps(), -amp * np.sin(14 * log.ref + 0.4), atol=FLOOR)

    def test_speed_gain(self):
        # cos gain 1 + k |omega_e|: amplitude imbalance alpha = k |omega_e| at each speed.
        k = 2e-5
        log, _, _ = run([f"speed_gain:k={k}"], profile="100:1,400:1")
        for rpm, window in ((100, log.t < 1.0), (400, log.t >= 1.0)):
            alpha = k * P_R * rpm * RPM
            np.testing.assert_allclose(log.eps()[window], alpha / 2 * np.sin(2 * log.theta()[window]),
                                       atol=b1(alpha) + FLOOR)

    def test_temperature_step(self):
        alpha, gain, step = 0.005, 0.03, 0.004
        log, _, _ = run([f"amplitude_imbalance:alpha={alpha}", f"temperature_step:at=1,gain={gain},alpha={step}"],
                        profile="200:2")
        after = log.t >= 1.0
        a_after = (1 + alpha) * (1 + step) - 1
        a_t = np.where(after, a_after, alpha)
        np.testing.assert_allclose(log.eps(), a_t / 2 * np.sin(2 * log.theta()), atol=b1(a_after) + FLOOR)
        # Both windings gain 3 %: the sin envelope's peak follows (whole counts: +-1).
        self.assertAlmostEqual(np.max(np.abs(log.sin[after])), 26000 * (1 + gain), delta=1.5)
        self.assertAlmostEqual(np.max(np.abs(log.sin[~after])), 26000, delta=1.5)


class SampleImpairmentTest(unittest.TestCase):
    def test_outliers_on_the_rd_angle(self):
        log, samples, _ = run(["outliers:rate=5,size=0.05,channel=rd"], profile="200:4")
        spikes = [e for e in samples.events if e["kind"] == "outlier"]
        self.assertGreater(len(spikes), 5)
        eps = log.eps()
        index = np.array([e["index"] for e in spikes])
        added = np.array([e["added"] for e in spikes])
        np.testing.assert_allclose(eps[index], -added, atol=FLOOR)  # eps = theta - (theta + spike)
        clean = np.setdiff1d(np.arange(len(eps)), index)
        self.assertLessEqual(np.max(np.abs(eps[clean])), FLOOR)

    def test_clipping_hits_only_the_dsp(self):
        log, _, _ = run(["clipping:level=20000"], profile="200:2")
        self.assertEqual(np.max(np.abs(log.sin)), 20000)
        self.assertEqual(np.max(np.abs(log.cos)), 20000)
        self.assertLessEqual(np.max(np.abs(log.eps())), FLOOR)  # the R/D front end is not clipped

    def test_dead_channel(self):
        log, _, _ = run(["dead_channel:start=0.5,end=0.7"], profile="200:1")
        dead = (log.t >= 0.5) & (log.t < 0.7)
        self.assertTrue((log.sin[dead] == 0).all() and (log.cos[dead] == 0).all())
        self.assertTrue((log.rd[dead] == 0).all())  # ideal converter: atan2(0, 0) = 0
        self.assertLessEqual(np.max(np.abs(log.eps()[~dead])), FLOOR)

    def test_dead_channel_tracking_loop_coasts(self):
        # With e = 0 the loop keeps its velocity: at constant speed it coasts on the true angle,
        # then reacquires. Coasting error: w was omega to the loop's floor, so eps stays tiny.
        log, _, _ = run(["dead_channel:start=0.5,end=0.6", "tracking_loop:omega_n=500,zeta=0.7"], profile="200:1")
        dead = (log.t >= 0.5) & (log.t < 0.6)
        self.assertTrue((log.sin[dead] == 0).all())
        self.assertLessEqual(np.max(np.abs(log.eps())), 2 * FLOOR)

    def test_stuck_reference(self):
        log, samples, _ = run(["stuck:channel=ref,start=1,end=1.5"], profile="200:2")
        stuck = (log.t >= 1.0) & (log.t < 1.5)
        self.assertEqual(len(np.unique(log.ref[stuck])), 1)
        self.assertGreater(np.ptp(np.unwrap(log.ref[~stuck & (log.t < 1.0)])), 1.0)
        self.assertEqual([e["kind"] for e in samples.events], ["stuck"])
        self.assertLessEqual(np.max(np.abs(wrap(log.eps()[~stuck]))), FLOOR)


if __name__ == "__main__":
    unittest.main()
