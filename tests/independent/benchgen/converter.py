"""The R/D converter: ideal (atan2) or a type-II tracking loop (Hanselman II.A, Hwang Fig. 2).

The loop, on the converter's own analog inputs s(t), c(t) (unit amplitude, noise-free,
not skewed by the DSP's sampling):
    e       = s cos(phi) - c sin(phi)          (= sin(theta - phi) for ideal signals, eq. 3)
    dphi/dt = w + 2 zeta omega_n e
    dw/dt   = omega_n^2 e
Linearised (e ~ theta - phi) this is H(s) = (2 zeta omega_n s + omega_n^2) /
(s^2 + 2 zeta omega_n s + omega_n^2) from theta to phi, but it is integrated here as the
nonlinear system, with classic fixed-step RK4 and omega_n h <= MAX_OMEGA_H, so large errors,
dead channels and acquisition behave as a real converter does.
"""
import math

import numpy as np

MAX_OMEGA_H = 0.05  # omega_n * h per RK4 step: local error ~ (omega_n h)^5, far below 16-bit LSB
SETTLE_TIME_CONSTANTS = 12.0  # pre-roll of 12 / (zeta omega_n): exp(-12) ~ 6e-6 of a start error
MAX_PREROLL_S = 2.0
CHUNK_SAMPLES = 2048  # output samples per vectorised block of input signals


def ideal(analog, times):
    """Converter angle [rad] of an infinitely fast converter: atan2(s, c), wrapped to (-pi, pi]."""
    s, c = analog(times)
    return np.arctan2(s, c)


def substeps_per_sample(omega_n, period):
    """RK4 steps per output sample so that omega_n h <= MAX_OMEGA_H."""
    return max(1, math.ceil(omega_n * period / MAX_OMEGA_H))


def preroll_samples(omega_n, zeta, period):
    """Whole samples the loop runs before the first output so it has settled."""
    settle = min(MAX_PREROLL_S, SETTLE_TIME_CONSTANTS / (zeta * omega_n))
    return math.ceil(settle / period)


def tracking_loop(analog, first_time, period, count, omega_n, zeta, initial_speed):
    """Loop angle phi [rad, unwrapped] at first_time + k period, k = 0..count-1.

    analog(t) -> (s, c) vectorised; initial_speed(t) [rad/s] starts the loop's velocity
    state at the pre-roll's start (the residual start error decays during the pre-roll).
    Returns (phi, substeps)."""
    steps = substeps_per_sample(omega_n, period)
    h = period / steps
    pre = preroll_samples(omega_n, zeta, period)
    start = first_time - pre * period
    s0, c0 = analog(np.array([start]))
    phi = math.atan2(float(s0[0]), float(c0[0]))
    w = float(initial_speed(start))
    g1, g2 = 2.0 * zeta * omega_n, omega_n * omega_n
    half, sixth = 0.5 * h, h / 6.0
    sin, cos = math.sin, math.cos
    out = np.empty(count)
    total = pre + count  # output k of the extended run is at start + k period
    k_done = 0  # extended samples already integrated up to
    written = 0
    if pre == 0:
        out[0] = phi
        written = 1
    while k_done < total - 1:
        block = min(CHUNK_SAMPLES, total - 1 - k_done)
        n_steps = block * steps
        # Half-step grid of this block: 2 n_steps + 1 points from sample k_done.
        grid = start + (k_done * steps + 0.5 * np.arange(2 * n_steps + 1)) * h
        s_arr, c_arr = analog(grid)
        s_list, c_list = s_arr.tolist(), c_arr.tolist()
        s_a, s_m, s_b = s_list[0:-1:2], s_list[1::2], s_list[2::2]
        c_a, c_m, c_b = c_list[0:-1:2], c_list[1::2], c_list[2::2]
        step = 0
        for sa, ca, sm, cm, sb, cb in zip(s_a, c_a, s_m, c_m, s_b, c_b):
            e1 = sa * cos(phi) - ca * sin(phi)
            p1, w1 = w + g1 * e1, g2 * e1
            q = phi + half * p1
            e2 = sm * cos(q) - cm * sin(q)
            p2, w2 = w + half * w1 + g1 * e2, g2 * e2
            q = phi + half * p2
            e3 = sm * cos(q) - cm * sin(q)
            p3, w3 = w + half * w2 + g1 * e3, g2 * e3
            q = phi + h * p3
            e4 = sb * cos(q) - cb * sin(q)
            p4, w4 = w + h * w3 + g1 * e4, g2 * e4
            phi += sixth * (p1 + 2.0 * p2 + 2.0 * p3 + p4)
            w += sixth * (w1 + 2.0 * w2 + 2.0 * w3 + w4)
            step += 1
            if step == steps:
                step = 0
                k_done += 1
                if k_done >= pre:
                    out[written] = phi
                    written += 1
    return out, steps


def quantize(angle, bits):
    """R/D output code [0, 2^bits) for an angle [rad], rounded to the nearest LSB."""
    scale = (1 << bits) / (2.0 * np.pi)
    return np.mod(np.rint(np.asarray(angle) * scale).astype(np.int64), 1 << bits)
