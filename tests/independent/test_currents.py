"""Current side, measured from the log: Park with the reference angle (theta_e = p theta_ref).

Floor: each phase is sent rounded to 1 mA (+-0.5 mA); Clarke gives |d i_alpha| <= 0.5 mA,
|d i_beta| <= (0.5 + 0.5)/sqrt3 mA, so |d(i_d, i_q)| <= hypot(0.5, 1/sqrt3) mA = 0.76 mA.
Expected ripples are derived here with space vectors (i_alpha + j i_beta), independently
of benchgen/currents.py: a sequence x_k = cos(W - k 2pi/3) is the vector e^{jW} (positive),
x_k = cos(W + k 2pi/3) is e^{-jW} (negative); Park multiplies by e^{-j theta_e}.
"""
import unittest

import numpy as np

from support import fit_harmonics, run

DQ_FLOOR = np.hypot(0.5e-3, 1e-3 / np.sqrt(3))  # [A]
I_Q = 10.0


class CurrentsTest(unittest.TestCase):
    def dq(self, effects, **kw):
        log, _, _ = run(effects, profile="300:2", p=4, **kw)
        i_d, i_q = log.dq_reference()
        return log, i_d, i_q

    def test_no_effect_is_pure_iq(self):
        _, i_d, i_q = self.dq([])
        np.testing.assert_allclose(i_d, 0.0, atol=DQ_FLOOR)
        np.testing.assert_allclose(i_q, I_Q, atol=DQ_FLOOR)

    def test_mounting_offset_shows_steady_id(self):
        # The drive's frame is theta_e + theta_0: the current vector sits at theta_0 + pi/2 in
        # the true frame: i_d = -i_q sin(theta_0), i_q cos(theta_0).
        theta_0 = 0.2
        _, i_d, i_q = self.dq([f"mounting_offset:theta_0={theta_0}"])
        np.testing.assert_allclose(i_d, -I_Q * np.sin(theta_0), atol=DQ_FLOOR)
        np.testing.assert_allclose(i_q, I_Q * np.cos(theta_0), atol=DQ_FLOOR)

    def test_offsets_ripple_at_1x(self):
        # A constant stationary vector (off_a, off_b/sqrt3) (c is an ideal third sensor) seen
        # from the rotating frame: i_d + j i_q = j I_Q + (off_a + j off_b/sqrt3) e^{-j theta_e}.
        off_a, off_b = 0.05, -0.03
        log, i_d, i_q = self.dq([f"current_offsets:off_a={off_a},off_b={off_b}"])
        theta_e = log.p * log.ref
        want = 1j * I_Q + (off_a + 1j * off_b / np.sqrt(3)) * np.exp(-1j * theta_e)
        np.testing.assert_allclose(i_d, want.real, atol=DQ_FLOOR)
        np.testing.assert_allclose(i_q, want.imag, atol=DQ_FLOOR)

    def test_gain_mismatch_ripple_at_2x(self):
        # i_a = I cos psi, i_b = I cos(psi - 2pi/3), psi = theta_e + pi/2. The errors
        # g_a i_a and g_b i_b give the vector g_a I cos psi + j (g_b/sqrt3) I cos(psi - 2pi/3),
        # whose negative-sequence part N e^{-j psi} has
        # N = I/2 [(g_a - g_b/2) - j g_b/(2 sqrt3)]; in dq: N e^{-j pi/2} e^{-j 2 theta_e}.
        g_a, g_b = 0.02, -0.01
        log, i_d, i_q = self.dq([f"current_gain_mismatch:gain_a={g_a},gain_b={g_b}"])
        theta_e = log.p * log.ref
        n = I_Q / 2 * ((g_a - g_b / 2) - 1j * g_b / (2 * np.sqrt(3)))
        z = i_d + 1j * i_q
        design = np.column_stack([np.ones_like(theta_e), np.exp(-2j * theta_e), np.exp(2j * theta_e)])
        coef, *_ = np.linalg.lstsq(design, z, rcond=None)
        # Rounding to 1 mA moves a fitted coefficient by at most the floor.
        self.assertLess(abs(coef[1] - n * (-1j)), DQ_FLOOR)
        self.assertLess(abs(coef[2]), DQ_FLOOR)
        self.assertGreater(abs(n), 20 * DQ_FLOOR)

    def test_dead_time_6x_perpendicular(self):
        # Each phase + k I (sin 7 psi_x - sin 5 psi_x): the 7th is a positive sequence
        # (vector -j e^{j7psi}), the 5th negative (vector -j e^{-j5psi}). In dq with
        # psi = theta_e + pi/2: k I (-j)(e^{j6theta_e} e^{j7pi/2} + e^{-j6theta_e} e^{-j5pi/2})
        # = -2 k I cos(6 theta_e) on i_d, nothing on i_q.
        t_d = 2e-6
        k = t_d / 100e-6
        log, i_d, i_q = self.dq([f"dead_time:t_d={t_d}"])
        theta_e = log.p * log.ref
        np.testing.assert_allclose(i_d, -2 * k * I_Q * np.cos(6 * theta_e), atol=DQ_FLOOR)
        np.testing.assert_allclose(i_q, I_Q, atol=DQ_FLOOR)

    def test_current_noise(self):
        sigma = 0.02
        log, i_d, i_q = self.dq([f"noise:sigma_i={sigma}"])
        # i_a = Re[j I_Q e^{j theta_e}] = -I_Q sin(theta_e) plus the phase noise sigma and the
        # 1 mA rounding (variance 1e-6/12 A^2).
        residual = log.i_a + I_Q * np.sin(log.p * log.ref)
        want = np.sqrt(sigma**2 + 1e-6 / 12)
        self.assertLess(abs(np.std(residual) / want - 1), 5 / np.sqrt(2 * len(residual)))

    def test_drive_follows_rd_angle(self):
        # --drive-angle rd: the drive commutates with its own R/D angle, so Park with that angle
        # gives the command exactly while the reference frame sees the resolver's error:
        # the drive's frame is theta_e - eps_e (p = p_r here, so eps_e = eps), the current vector
        # sits at pi/2 - eps_e in the true frame: i_d = I_Q sin(eps_e) ~ I_Q (alpha/2) sin 2theta.
        alpha = 0.01
        log, _, _ = run([f"amplitude_imbalance:alpha={alpha}"], profile="300:2", p=3, drive_angle="rd")
        from benchgen.conventions import clarke, park
        i_d_rd, i_q_rd = park(*clarke(log.i_a, log.i_b, log.i_c), log.rd)
        np.testing.assert_allclose(i_d_rd, 0.0, atol=DQ_FLOOR + I_Q * np.pi / 2**16)
        i_d, _ = log.dq_reference()
        _, coef, _ = fit_harmonics(log.p * log.ref, i_d, [2])
        # a_2 = +I_Q alpha/2 to O(alpha^2) (the atan2 remainder (B1) and sin eps ~ eps).
        self.assertLess(abs(coef[2][0] - I_Q * alpha / 2), I_Q * alpha**2 / 2 + DQ_FLOOR)


if __name__ == "__main__":
    unittest.main()
