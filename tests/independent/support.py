"""Test helpers: run the bench in-process, write its log, read the bytes back, and measure.

Every measurement here comes from the written candump bytes (decoded by readers.py), never
from the simulator's internal arrays, so the tests check what a user's tool would read.
"""
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from benchgen import layouts, readers, writers  # noqa: E402
from benchgen.bench import BenchConfig, simulate  # noqa: E402
from benchgen.conventions import TWO_PI, clarke, park  # noqa: E402
from benchgen.effects import EffectSet  # noqa: E402
from benchgen.impair import impair_records  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
BENCH_DBC = layouts.BENCH_DBC
START_US = 1_700_000_000_000_000

# Quantization floors of the default layout [rad]:
RD16_HALF_LSB = np.pi / 2**16  # R/D angle rounded to the nearest of 2^16 codes: |error| <= LSB/2
REF_HALF_LSB = np.pi / 2**32  # reference u32 rounded likewise [mech rad]


def wrap(angle):
    return np.mod(np.asarray(angle) + np.pi, TWO_PI) - np.pi


class Decoded:
    """A default-layout log read back from its candump bytes, joined by sample order."""

    def __init__(self, path, p_r, p):
        stamps, ids, data, _ = readers.read_candump(path)
        frames = readers.decode_default(ids, data)
        self.frames = frames
        self.stamps, self.ids, self.data = stamps, ids, data
        res, ref = frames[0x100], frames[0x102]
        self.sin = res["sin"].astype(float)
        self.cos = res["cos"].astype(float)
        self.rd = res["rd_angle"] * (TWO_PI / 65536.0)  # [rad] resolver electrical
        self.ref = ref["ref_angle"] * (TWO_PI / 2.0**32)  # [rad] mechanical
        self.t = (stamps[ids == 0x100] - stamps[ids == 0x100][0]) / 1e6
        cur = frames[0x101]
        self.i_a, self.i_b, self.i_c = (cur[k] / 1000.0 for k in ("i_a", "i_b", "i_c"))
        self.p_r, self.p = p_r, p

    def eps(self):
        """Position error from the log: p_r theta_ref - theta_rd [resolver electrical rad]."""
        return wrap(self.p_r * self.ref - self.rd)

    def eps_sincos(self):
        """Position error of the DSP's sampled envelopes: p_r theta_ref - atan2(sin, cos)."""
        return wrap(self.p_r * self.ref - np.arctan2(self.sin, self.cos))

    def theta(self):
        """True resolver electrical angle from the reference [rad]."""
        return self.p_r * self.ref

    def dq_reference(self):
        """i_d, i_q [A] with the reference angle (theta_e = p theta_ref)."""
        return park(*clarke(self.i_a, self.i_b, self.i_c), self.p * self.ref)


def run(effects=(), **overrides):
    """Simulates, writes a default-layout candump log to a temporary file and reads it back.

    Returns (Decoded, samples, config)."""
    config = BenchConfig(effects=EffectSet(list(effects)), **overrides)
    samples = simulate(config)
    frames = layouts.encode(samples, config)
    index, times, _ = impair_records(frames.t, config.effects, config.seed)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "bench.log")
        writers.write_candump(path, frames, index, times, START_US)
        decoded = Decoded(path, config.p_r, config.p)
    return decoded, samples, config


def fit_harmonics(angle, values, orders):
    """Least squares values ~ c0 + sum_n (a_n sin(n angle) + b_n cos(n angle)); returns
    (c0, {n: (a_n, b_n)}, residual)."""
    columns = [np.ones_like(angle)]
    for n in orders:
        columns += [np.sin(n * angle), np.cos(n * angle)]
    design = np.column_stack(columns)
    coef, *_ = np.linalg.lstsq(design, values, rcond=None)
    residual = values - design @ coef
    return coef[0], {n: (coef[1 + 2 * k], coef[2 + 2 * k]) for k, n in enumerate(orders)}, residual
