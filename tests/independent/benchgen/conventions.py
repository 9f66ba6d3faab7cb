"""Angles, units and frame transforms (docs/ARCHITECTURE.md §3), written down once.

theta_m   mechanical angle [rad]
theta     resolver electrical angle = p_r * theta_m [rad]
theta_e   motor electrical angle   = p * theta_m [rad]
eps       position error = theta_true - theta_measured (Hanselman's sign) [rad, resolver electrical]
Clarke (amplitude invariant): i_alpha = i_a, i_beta = (i_b - i_c) / sqrt(3)
Park:  i_d =  i_alpha cos(theta_e) + i_beta sin(theta_e)
       i_q = -i_alpha sin(theta_e) + i_beta cos(theta_e)
"""
import numpy as np

TWO_PI = 2.0 * np.pi
SQRT3 = np.sqrt(3.0)
RPM_TO_RAD_S = TWO_PI / 60.0  # 1 r/min = 2 pi / 60 rad/s


def wrap_pm_pi(angle):
    """Wraps [rad] into [-pi, pi)."""
    return np.mod(np.asarray(angle) + np.pi, TWO_PI) - np.pi


def wrap_2pi(angle):
    """Wraps [rad] into [0, 2 pi)."""
    return np.mod(angle, TWO_PI)


def clarke(i_a, i_b, i_c):
    """Amplitude-invariant Clarke transform: (i_alpha, i_beta) [A]."""
    return np.asarray(i_a, dtype=float), (np.asarray(i_b) - np.asarray(i_c)) / SQRT3


def park(i_alpha, i_beta, theta_e):
    """Park transform into the frame at theta_e [rad]: (i_d, i_q) [A]."""
    c, s = np.cos(theta_e), np.sin(theta_e)
    return i_alpha * c + i_beta * s, -i_alpha * s + i_beta * c


def inverse_park(i_d, i_q, theta_e):
    """Inverse of park(): (i_alpha, i_beta) [A]."""
    c, s = np.cos(theta_e), np.sin(theta_e)
    return i_d * c - i_q * s, i_d * s + i_q * c


def inverse_clarke(i_alpha, i_beta):
    """Inverse of clarke() for a balanced (zero-sum) set: (i_a, i_b, i_c) [A]."""
    i_b = -0.5 * i_alpha + 0.5 * SQRT3 * i_beta
    i_c = -0.5 * i_alpha - 0.5 * SQRT3 * i_beta
    return i_alpha, i_b, i_c
