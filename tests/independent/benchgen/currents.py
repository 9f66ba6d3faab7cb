"""Phase currents: the machine carries the commanded (i_d, i_q) in the drive's frame.

The drive's frame angle theta_drive is either
  "reference": p theta_m + theta_0 (the drive is commutated by the resolver, so its frame
               carries the mounting offset theta_0; other resolver errors are not fed back,
               as in Hwang's analysis, eq. 11-16), or
  "rd":        (p / p_r) x the R/D angle as delivered (a closed-loop drive that follows its
               own converter, every resolver error included).
With a pure i_q command and the "reference" frame, Park with the reference angle gives
i_d = -i_q sin(theta_0), i_q cos(theta_0) (docs/ARCHITECTURE.md §7, mounting_offset).

Dead time (signature model, docs/ARCHITECTURE.md §7): each phase x gains k |I| (sin 7 psi_x - sin 5 psi_x),
k = t_d / 100 us, psi_x the phase's fundamental angle (i_x = |I| cos psi_x). The 7th is a
positive and the 5th a negative sequence, so in the frame of the current vector they add to
-j 2 k |I| cos(6 psi_a): a 6x ripple perpendicular to the current.

Sensors: a and b have offset and gain errors (current_offsets, current_gain_mismatch); c is
a third, ideal sensor (set `two_sensors` to report c = -(a + b) from the measured a, b).
"""
import numpy as np

from .conventions import inverse_clarke, inverse_park

DEAD_TIME_REFERENCE_S = 100e-6  # k = t_d / 100 us (the catalog's signature model)


def machine_currents(theta_drive, i_d, i_q, t_d):
    """True phase currents (i_a, i_b, i_c) [A] for the commanded currents in the drive frame."""
    i_alpha, i_beta = inverse_park(i_d, i_q, theta_drive)
    i_a, i_b, i_c = inverse_clarke(i_alpha, i_beta)
    if t_d:
        k = t_d / DEAD_TIME_REFERENCE_S
        magnitude = np.hypot(i_d, i_q)
        psi_a = theta_drive + np.arctan2(i_q, i_d)  # i_a = |I| cos(psi_a)
        out = []
        for phase, shift in ((i_a, 0.0), (i_b, -2.0 * np.pi / 3.0), (i_c, 2.0 * np.pi / 3.0)):
            psi = psi_a + shift
            out.append(phase + k * magnitude * (np.sin(7.0 * psi) - np.sin(5.0 * psi)))
        i_a, i_b, i_c = out
    return i_a, i_b, i_c


def sensed_currents(i_a, i_b, i_c, effects, two_sensors=False):
    """What the current sensors report [A] (before noise and 1 mA quantization)."""
    off_a = effects.param("current_offsets", "off_a")
    off_b = effects.param("current_offsets", "off_b")
    gain_a = effects.param("current_gain_mismatch", "gain_a")
    gain_b = effects.param("current_gain_mismatch", "gain_b")
    m_a = (1.0 + gain_a) * i_a + off_a
    m_b = (1.0 + gain_b) * i_b + off_b
    m_c = -(m_a + m_b) if two_sensors else np.array(i_c, dtype=float, copy=True)
    return m_a, m_b, m_c
