"""Each resolver effect's position error, measured from the written log (reference angle vs
R/D angle, and atan2 of the sampled sin/cos), against its small-parameter signature.

Bounds are derived, not tuned:
  * Quantization floor F = pi/2^16 (R/D, rounded to the nearest 16-bit code) + p_r pi/2^32
    (reference u32).
  * Winding effects (ideal converter): phi = atan2(s, c) = theta + arg(1 + w) with
    w = e^{-j theta} (dc + j ds) the envelope perturbation, |w| <= m. The signature is the
    first-order term Im(w); the rest of the series Im(log(1 + w)) is bounded by
    sum_{k>=2} m^k / k <= m^2 / (2 (1 - m))                                        (B1)
    Where the catalog's signature also linearises the parameter itself (quadrature:
    cos(theta + beta) - cos(theta) = -beta sin(theta) - (1 - cos beta) cos(theta) - ...),
    that remainder is added: (1 - cos beta)/2 + |beta - sin beta| <= beta^2/2 + |beta|^3/6.
  * Mechanical effects, mounting offset and delay at constant speed are exact: bound F.
Every check also runs its control: the signature with the opposite sign must NOT fit, so a
sign slip cannot pass.
"""
import unittest

import numpy as np

from support import RD16_HALF_LSB, REF_HALF_LSB, fit_harmonics, run

P_R = 3
FLOOR = RD16_HALF_LSB + P_R * REF_HALF_LSB
RPM = 2 * np.pi / 60


def b1(m):
    """(B1): second-and-higher-order remainder of arg(1 + w), |w| <= m."""
    return m * m / (2.0 * (1.0 - m))


def sincos_floor(amplitude, m=0.0):
    """atan2 of envelopes rounded to whole counts: each channel +-0.5 count, so the
    perturbation grows by at most sqrt(2) 0.5 / (amplitude (1 - m)) [rad]."""
    return np.sqrt(2.0) * 0.5 / (amplitude * (1.0 - m))


class SignatureCase(unittest.TestCase):
    def assertSignature(self, measured, predicted, bound, what):
        error = np.max(np.abs(measured - predicted))
        self.assertLessEqual(error, bound, f"{what}: max |eps - signature| = {error:.3g} > bound {bound:.3g}")
        # Control: the signature must be large against the bound, and its sign must matter.
        flipped = np.max(np.abs(measured + predicted))
        self.assertGreater(flipped, 5 * bound, f"{what}: the test cannot tell the sign ({flipped:.3g})")


class FloorTest(SignatureCase):
    def test_zero_effects_every_preset(self):
        for preset in ("out_and_back", "speed_steps", "reversals", "ramps"):
            log, _, _ = run(profile=preset, sample_rate=1000.0)
            eps = log.eps()
            self.assertLessEqual(np.max(np.abs(eps)), FLOOR, preset)
            self.assertLessEqual(np.max(np.abs(log.eps_sincos())), FLOOR + sincos_floor(26000.0), preset)

    def test_zero_effects_tracking_loop(self):
        # With ideal signals the loop's exact solution phi = theta is kept by RK4 at every
        # stage (constant speed), so the converter adds nothing to the floor.
        log, samples, _ = run(["tracking_loop:omega_n=2000,zeta=0.7"], profile="300:2")
        self.assertGreater(samples.substeps, 1)
        self.assertLessEqual(np.max(np.abs(log.eps())), FLOOR)

    def test_noise_floor_of_the_envelopes(self):
        # White noise sigma on s and c moves the atan2 angle by (n_s cos - n_c sin)/A: std
        # sigma/A; whole-count rounding adds variance 1/12 count^2. The R/D is noise-free.
        sigma, amplitude = 3.0, 26000.0
        log, _, _ = run(["noise:sigma_sc=3"], profile="200:5", amplitude=amplitude)
        self.assertLessEqual(np.max(np.abs(log.eps())), FLOOR)
        std = np.std(log.eps_sincos())
        want = np.sqrt(sigma**2 + 1.0 / 12.0) / amplitude
        n = len(log.rd)
        self.assertLess(abs(std / want - 1.0), 5.0 / np.sqrt(2 * n))  # 5 standard errors of a std

    def test_quantization_bits(self):
        log, _, _ = run(["quantization:rd_bits=10"], profile="200:5")
        lsb = 2 * np.pi / 2**10
        eps = log.eps()
        self.assertLessEqual(np.max(np.abs(eps)), lsb / 2 + P_R * REF_HALF_LSB)
        # Uniform over the LSB (200 r/min moves 5.12 LSB per sample: 25 evenly spread phases).
        self.assertLess(abs(np.std(eps) / (lsb / np.sqrt(12.0)) - 1.0), 0.05)


class WindingTest(SignatureCase):
    def check(self, spec, signature, m, extra=0.0):
        log, _, _ = run([spec], profile="200:3")
        theta = log.theta()
        self.assertSignature(log.eps(), signature(theta), b1(m) + extra + FLOOR, f"{spec} (R/D)")
        # The DSP's envelopes carry the same error.
        self.assertSignature(log.eps_sincos(), signature(theta),
                             b1(m) + extra + P_R * REF_HALF_LSB + sincos_floor(26000.0, m), f"{spec} (sin/cos)")

    def test_amplitude_imbalance(self):
        for alpha in (0.01, -0.02):
            self.check(f"amplitude_imbalance:alpha={alpha}", lambda th: alpha / 2 * np.sin(2 * th), abs(alpha))

    def test_quadrature(self):
        for beta in (0.01, -0.015):
            self.check(f"quadrature:beta={beta}", lambda th: -beta / 2 * (1 - np.cos(2 * th)), abs(beta),
                       beta**2 / 2 + abs(beta) ** 3 / 6)

    def test_offsets(self):
        o_s, o_c = 0.004, -0.006
        self.check(f"offsets:o_s={o_s},o_c={o_c}", lambda th: o_c * np.sin(th) - o_s * np.cos(th), np.hypot(o_s, o_c))

    def test_k0(self):
        k0 = 0.003
        self.check(f"harmonics:k0={k0}", lambda th: -np.sqrt(2) * k0 * np.cos(th + np.pi / 4), np.sqrt(2) * k0)

    def test_harmonics_same_sign(self):
        # Hanselman eq. 9: K_n lands on (n - 1) theta.
        for n in (2, 3, 5, 9, 20):
            k = 0.004
            self.check(f"harmonics:k{n}={k}", lambda th: -k * np.sin((n - 1) * th), k)

    def test_harmonics_opposite_sign(self):
        # s += K sin(n theta), c -= K cos(n theta): Im(w) = K sin((n + 1) theta).
        for n in (2, 3, 7):
            k = -0.003
            self.check(f"harmonics:k{n}_opp={k}", lambda th: -k * np.sin((n + 1) * th), abs(k))

    def test_envelope_drift(self):
        # Both windings x (1 + g t): atan2 ignores a common positive factor, so neither
        # angle moves (eps = 0 to the floor), and the radius grows by g t: whole counts
        # move it by at most sqrt(2) 0.5 count, 2.7e-5 of the amplitude.
        for g in (0.004, -0.004):
            log, _, _ = run([f"envelope_drift:g={g}"], profile="200:3")
            self.assertLessEqual(np.max(np.abs(log.eps())), FLOOR, f"g={g} (R/D)")
            self.assertLessEqual(np.max(np.abs(log.eps_sincos())), FLOOR + sincos_floor(26000.0 * (1 - 3 * abs(g))),
                                 f"g={g} (sin/cos)")
            radius = np.hypot(log.sin, log.cos) / 26000.0 - 1.0
            self.assertSignature(radius, g * log.t, np.sqrt(2.0) * 0.5 / 26000.0, f"envelope_drift:g={g} (radius)")


class MechanicalTest(SignatureCase):
    def test_eccentricity(self):
        e, phase = 1e-3, 0.7
        log, _, _ = run([f"eccentricity:e={e},phase={phase}"], profile="200:3")
        self.assertSignature(log.eps(), -P_R * e * np.sin(log.ref + phase), FLOOR, "eccentricity")

    def test_mechanical_harmonics(self):
        a2, b2, a5 = 5e-4, -3e-4, 2e-4
        log, _, _ = run([f"mechanical_harmonics:a2={a2},b2={b2},a5={a5}"], profile="200:3")
        want = -P_R * (a2 * np.sin(2 * log.ref) + b2 * np.cos(2 * log.ref) + a5 * np.sin(5 * log.ref))
        self.assertSignature(log.eps(), want, FLOOR, "mechanical_harmonics")

    def test_mounting_offset(self):
        theta_0 = 0.3  # motor electrical rad, p = p_r = 3
        log, _, _ = run([f"mounting_offset:theta_0={theta_0}"], profile="200:1")
        self.assertSignature(log.eps(), np.full(len(log.rd), -P_R / 3 * theta_0), FLOOR, "mounting_offset")


class SpeedDependentTest(SignatureCase):
    def test_delay_grows_with_speed(self):
        # Constant speed: the R/D angle of t - d is exactly theta - omega d: eps = p_r omega_m d.
        d = 1e-3
        log, samples, _ = run([f"delay:d={d}"], profile="speed_steps", sample_rate=1000.0)
        means = []
        for rpm, start in ((100, 0.0), (300, 2.0), (600, 4.0), (1000, 6.0)):
            inside = (log.t > start + 2 * d) & (log.t < start + 2.0)  # skip the step's first d
            self.assertSignature(log.eps()[inside], np.full(inside.sum(), P_R * rpm * RPM * d), FLOOR,
                                 f"delay at {rpm} r/min")
            means.append(np.mean(log.eps()[inside]))
        self.assertTrue(np.all(np.diff(means) > 0), f"eps must grow with speed: {means}")

    def test_delay_shifts_other_errors(self):
        # eps = omega d + every other error at theta - omega d (docs/ARCHITECTURE.md §7).
        d, alpha, rpm = 2e-3, 0.01, 200
        log, _, _ = run([f"delay:d={d}", f"amplitude_imbalance:alpha={alpha}"], profile=f"{rpm}:3")
        lag = P_R * rpm * RPM * d
        want = lag + alpha / 2 * np.sin(2 * (log.theta() - lag))
        self.assertSignature(log.eps(), want, b1(alpha) + FLOOR, "delay + amplitude_imbalance")

    def test_channel_delay_is_quadrature_for_both(self):
        # c(t) = C(theta(t - tau)) = cos(theta - omega tau): quadrature with beta = -omega tau,
        # seen by the R/D converter AND by the DSP's samples.
        tau, rpm = 20e-6, 1000
        beta = -P_R * rpm * RPM * tau
        log, _, _ = run([f"channel_delay:tau={tau}"], profile=f"{rpm}:1")
        want = -beta / 2 * (1 - np.cos(2 * log.theta()))
        bound = b1(abs(beta)) + beta**2 / 2 + abs(beta) ** 3 / 6
        self.assertSignature(log.eps(), want, bound + FLOOR, "channel_delay (R/D)")
        self.assertSignature(log.eps_sincos(), want,
                             bound + P_R * REF_HALF_LSB + sincos_floor(26000.0, abs(beta)), "channel_delay (sin/cos)")

    def test_sampling_skew_only_in_the_samples(self):
        # The DSP samples cos tau later: beta = +omega tau in atan2(sin, cos); the R/D is clean.
        tau, rpm = 20e-6, 1000
        beta = P_R * rpm * RPM * tau
        log, _, _ = run([f"sampling_skew:tau={tau}"], profile=f"{rpm}:1")
        self.assertLessEqual(np.max(np.abs(log.eps())), FLOOR)
        want = -beta / 2 * (1 - np.cos(2 * log.theta()))
        bound = b1(beta) + beta**2 / 2 + beta**3 / 6 + P_R * REF_HALF_LSB + sincos_floor(26000.0, beta)
        self.assertSignature(log.eps_sincos(), want, bound, "sampling_skew (sin/cos)")


class BacklashTest(unittest.TestCase):
    def test_deadband_at_reversals(self):
        # p_r = 1 bench, out and back: steady motion lags h/2 in the direction of motion; after
        # a reversal the resolver holds (R/D code constant) until the reference has moved h back.
        h = 0.02
        log, _, _ = run([f"backlash:h={h}"], profile="out_and_back", p_r=1, p=4, sample_rate=1000.0)
        floor = RD16_HALF_LSB + REF_HALF_LSB
        ref = np.unwrap(log.ref)
        step = np.diff(ref, prepend=ref[0])
        direction = np.sign(np.where(np.abs(step) > 1e-9, step, 0.0))
        eps = log.eps()
        moving = np.flatnonzero(direction != 0)
        # Travel since the last reversal, from the reference.
        travelled = np.zeros(len(ref))
        last_dir, anchor = 0, ref[0]
        for k in moving:
            if direction[k] != last_dir:
                last_dir, anchor = direction[k], ref[k - 1]
            travelled[k] = abs(ref[k] - anchor)
        forward = moving[(direction[moving] > 0) & (travelled[moving] > h)]
        backward = moving[(direction[moving] < 0) & (travelled[moving] > h)]
        takeup = moving[(direction[moving] < 0) & (travelled[moving] < h)]
        self.assertGreater(len(forward), 100)
        self.assertGreater(len(backward), 100)
        self.assertGreater(len(takeup), 3)
        np.testing.assert_allclose(eps[forward], h / 2, atol=floor)
        np.testing.assert_allclose(eps[backward], -h / 2, atol=floor)
        # During the take-up the R/D angle does not move while the reference does.
        self.assertEqual(len(np.unique(log.rd[takeup])), 1)
        self.assertGreater(np.ptp(ref[takeup]), 0.5 * h)
        # A standstill keeps the lag of the motion before it.
        hold_after_forward = (log.t > 3.2) & (log.t < 3.9)
        np.testing.assert_allclose(eps[hold_after_forward], h / 2, atol=floor)


class TrackingLoopTest(unittest.TestCase):
    def test_integrator_against_linear_response(self):
        # The loop on ideal envelopes of psi(t) = eps0 sin(Omega t) (standstill dither):
        # e = sin(psi - phi), linear to eps0^3/6 ~ 2e-10 for eps0 = 1e-3, so phi must be the
        # exact steady state eps0 Im[H(j Omega) e^{j Omega t}]. Other terms: the start
        # transient after the pre-roll, <= 2 eps0 exp(-12) ~ 1.2e-8; RK4 global error
        # ~ (omega_n h)^4 eps0 ~ 6e-9. Bound 5e-8; a wrong RK4 stage gives up to ~1e-5.
        from benchgen import converter
        eps0, big_omega, wn, zeta, rate = 1e-3, 150.0, 200.0, 0.7, 2000.0

        def analog(t):
            psi = eps0 * np.sin(big_omega * t)
            return np.sin(psi), np.cos(psi)

        phi, steps = converter.tracking_loop(analog, 0.0, 1.0 / rate, 4000, wn, zeta,
                                             lambda t: eps0 * big_omega * np.cos(big_omega * t))
        self.assertLessEqual(wn / (rate * steps), converter.MAX_OMEGA_H)
        t = np.arange(4000) / rate
        s = 1j * big_omega
        h = (2 * zeta * wn * s + wn**2) / (s**2 + 2 * zeta * wn * s + wn**2)
        want = eps0 * np.imag(h * np.exp(1j * big_omega * t))
        self.assertLess(np.max(np.abs(phi - want)), 5e-8)
        # From 0.1 s on the start transient has decayed by another exp(-14): only the RK4
        # error is left, ~ (omega_n h)^4 / 120 eps0 ~ 5e-11 per unit loop gain; bound 1e-9.
        self.assertLess(np.max(np.abs(phi - want)[t > 0.1]), 1e-9)

    def test_ripple_filtered_by_closed_loop(self):
        # Linearised loop from the envelopes' angle psi = theta - (alpha/2) sin 2theta to phi:
        # H(s) = (2 zeta wn s + wn^2)/(s^2 + 2 zeta wn s + wn^2); a ramp passes exactly (type II),
        # so eps = Im[(alpha/2) H(j 2 omega_e) e^{j 2 theta}]. Bound: the atan2 remainder (B1)
        # through |H|, plus the largest shift 16-bit rounding can give a fitted coefficient
        # (2/N sum |q_k| <= LSB).
        alpha, wn, zeta, rpm = 0.01, 200.0, 0.7, 200
        log, _, _ = run([f"amplitude_imbalance:alpha={alpha}", f"tracking_loop:omega_n={wn},zeta={zeta}"],
                        profile=f"{rpm}:4")
        big_omega = 2 * P_R * rpm * RPM
        s = 1j * big_omega
        h = (2 * zeta * wn * s + wn**2) / (s**2 + 2 * zeta * wn * s + wn**2)
        want = alpha / 2 * h
        _, coef, _ = fit_harmonics(log.theta(), log.eps(), [2])
        got = coef[2][0] + 1j * coef[2][1]  # a sin + b cos = Im[(a + j b) e^{j 2 theta}]
        bound = b1(alpha) * abs(h) + 2 * RD16_HALF_LSB
        self.assertLess(abs(got - want), bound, f"ripple {got:.4g} vs H-predicted {want:.4g}")
        # Control: the loop's gain and phase matter here (an ideal converter would be alpha/2).
        self.assertGreater(abs(want - alpha / 2), 5 * bound)

    def test_lag_under_acceleration(self):
        # Type-II loop, constant angular acceleration a: steady lag eps = a / wn^2.
        wn = 200.0
        log, _, _ = run([f"tracking_loop:omega_n={wn},zeta=0.7"], profile="0:0.2,0-600:2,600:1")
        accel = P_R * 600 * RPM / 2.0
        ramp = (log.t > 0.7) & (log.t < 2.2)  # 0.5 s = 70 time constants after the ramp starts
        self.assertLess(abs(np.mean(log.eps()[ramp]) - accel / wn**2), RD16_HALF_LSB)
        self.assertGreater(accel / wn**2, 20 * RD16_HALF_LSB)
        steady = log.t > 2.8
        self.assertLessEqual(np.max(np.abs(log.eps()[steady])), FLOOR)


if __name__ == "__main__":
    unittest.main()
