"""CAN layouts: samples -> frames (relative time [s], CAN ID, 8 data bytes).

default     docs/ARCHITECTURE.md §4, encoded here byte by byte (struct layout from the table, own
            CRC), NOT through a DBC, so tests can check it against proto/resolver_bench.dbc.
angle_only  dbc/angle_only.dbc: R/D and reference angle in degrees in one message, no counter,
            no CRC (a scope-style 1X bench, typically 100 Hz and p_r = 1).
be_counter  dbc/be_counter.dbc: big-endian signals with a counter, no CRC, other units.
Frames of one sample are spread over the sample period (FRAME_SPACING_S apart, as on a
1 Mbit/s bus where an 8-byte frame takes about 110 us).
"""
import os
from dataclasses import dataclass

import numpy as np

from .conventions import TWO_PI
from .crc8 import frame_crc
from .dbc import read_dbc

_INDEPENDENT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # tests/independent
REPO_ROOT = os.path.dirname(os.path.dirname(_INDEPENDENT))
DBC_DIR = os.path.join(_INDEPENDENT, "dbc")
BENCH_DBC = os.path.join(REPO_ROOT, "proto", "resolver_bench.dbc")  # docs/ARCHITECTURE.md §4, the default layout
FRAME_SPACING_S = 130e-6  # one 8-byte classic frame at 1 Mbit/s with stuffing ~ 110-130 us
BENCH_INFO_PERIOD_S = 0.1  # 10 Hz (docs/ARCHITECTURE.md §4)
LAYOUT_VERSION = 1

ID_RESOLVER_SAMPLE, ID_PHASE_CURRENTS, ID_REFERENCE_ANGLE, ID_BENCH_INFO = 0x100, 0x101, 0x102, 0x1F0


@dataclass
class Frames:
    t: np.ndarray  # [s] relative to the log start
    can_id: np.ndarray  # int
    data: np.ndarray  # (n, 8) uint8
    sample: np.ndarray  # sample index a frame belongs to (-1: BENCH_INFO)

    def __len__(self):
        return len(self.t)


def _spacing(period, per_sample):
    return min(FRAME_SPACING_S, period / (per_sample + 1))


def _merge(parts):
    """Concatenates frame groups and orders them by time (stable: a sample's order kept)."""
    t = np.concatenate([p[0] for p in parts])
    order = np.argsort(t, kind="stable")
    return Frames(t[order], np.concatenate([p[1] for p in parts])[order],
                  np.vstack([p[2] for p in parts])[order], np.concatenate([p[3] for p in parts])[order])


def _le_bytes(values, dtype):
    """Little-endian bytes of each value: (n, itemsize) uint8."""
    values = np.ascontiguousarray(np.asarray(values).astype(dtype))
    return values.view(np.uint8).reshape(len(values), -1)


def _with_crc(rows, can_id):
    rows[:, 7] = frame_crc(rows[:, :7], can_id)
    return rows


def saturate(values, low, high):
    return np.clip(values, low, high)


def encode_default(samples, config, reference=True, currents=True):
    """docs/ARCHITECTURE.md §4 frames: 0x100, 0x101, 0x102 per sample; 0x1F0 at 10 Hz."""
    n = len(samples)
    period = 1.0 / config.sample_rate
    per_sample = 1 + int(currents) + int(reference)
    gap = _spacing(period, per_sample)
    counter = (np.arange(n) % 256).astype(np.uint8)
    index = np.arange(n)
    parts = []

    rows = np.zeros((n, 8), dtype=np.uint8)
    rows[:, 0] = counter
    rows[:, 1:3] = _le_bytes(samples.sin, "<i2")
    rows[:, 3:5] = _le_bytes(samples.cos, "<i2")
    # rd_angle u16: the converter's rd_bits in the top bits, the low bits zero (docs/ARCHITECTURE.md §4).
    rows[:, 5:7] = _le_bytes(samples.rd_code << (16 - samples.rd_bits), "<u2")
    parts.append((samples.t.copy(), np.full(n, ID_RESOLVER_SAMPLE), _with_crc(rows, ID_RESOLVER_SAMPLE), index))
    slot = 1
    if currents:
        rows = np.zeros((n, 8), dtype=np.uint8)
        rows[:, 0] = counter
        for k, phase in enumerate((samples.i_a, samples.i_b, samples.i_c)):
            milliamps = saturate(np.rint(np.asarray(phase) * 1000.0), -32768, 32767)  # 1 mA/bit
            rows[:, 1 + 2 * k:3 + 2 * k] = _le_bytes(milliamps, "<i2")
        parts.append((samples.t + slot * gap, np.full(n, ID_PHASE_CURRENTS), _with_crc(rows, ID_PHASE_CURRENTS), index))
        slot += 1
    if reference:
        rows = np.zeros((n, 8), dtype=np.uint8)
        rows[:, 0] = counter
        turns = np.asarray(samples.ref_angle) / TWO_PI  # [0, 1) mechanical turn
        rows[:, 1:5] = _le_bytes(np.mod(np.rint(turns * 2.0**32).astype(np.int64), 1 << 32), "<u4")
        parts.append((samples.t + slot * gap, np.full(n, ID_REFERENCE_ANGLE), _with_crc(rows, ID_REFERENCE_ANGLE), index))
        slot += 1
    # BENCH_INFO at 10 Hz, after the frames of the sample it follows.
    duration = n * period
    info_t = np.arange(0.0, duration, BENCH_INFO_PERIOD_S) + slot * gap
    rows = np.zeros((len(info_t), 8), dtype=np.uint8)
    rows[:, 0] = LAYOUT_VERSION
    rows[:, 1] = config.p_r
    rows[:, 2] = config.p
    rows[:, 3] = samples.rd_bits
    rows[:, 4:6] = _le_bytes(np.full(len(info_t), int(round(config.sample_rate))), "<u2")
    parts.append((info_t, np.full(len(info_t), ID_BENCH_INFO), _with_crc(rows, ID_BENCH_INFO),
                  np.full(len(info_t), -1)))
    return _merge(parts)


# Physical value of each role [the DBC signal's unit], from samples. Angles wrap.
_ROLE_VALUE = {
    "rd_angle": lambda s: s.rd_angle,  # [rad]
    "ref_angle": lambda s: s.ref_angle,  # [rad mech]
    "sin": lambda s: s.sin,
    "cos": lambda s: s.cos,
    "i_a": lambda s: s.i_a,
    "i_b": lambda s: s.i_b,
    "i_c": lambda s: s.i_c,
}
_UNIT_FROM_RAD = {"rad": 1.0, "deg": 360.0 / TWO_PI, "rev": 1.0 / TWO_PI}
_ANGLE_ROLES = ("rd_angle", "ref_angle")


@dataclass(frozen=True)
class DbcLayout:
    name: str
    dbc_file: str
    messages: tuple  # message names, sent in this order every sample
    has_counter: bool
    description: str

    @property
    def dbc_path(self):
        return os.path.join(DBC_DIR, self.dbc_file)


DBC_LAYOUTS = {
    "angle_only": DbcLayout("angle_only", "angle_only.dbc", ("ANGLES",), False,
                            "R/D and reference angle [deg] in one message, no counter, no CRC"),
    "be_counter": DbcLayout("be_counter", "be_counter.dbc", ("RES_FB", "CUR_FB", "REF_FB"), True,
                            "big-endian signals, u8 counter, no CRC; angles in rad and rev, 10 mA/bit"),
}
LAYOUTS = ("default",) + tuple(DBC_LAYOUTS)


def dbc_path(layout):
    """The DBC describing a layout (the project's own for the default layout)."""
    return BENCH_DBC if layout == "default" else DBC_LAYOUTS[layout].dbc_path


def encode_dbc_layout(samples, config, layout, reference=True, currents=True):
    """Frames of a DBC-described layout; every signal named after its role (or `counter`)."""
    messages = read_dbc(layout.dbc_path)
    n = len(samples)
    period = 1.0 / config.sample_rate

    def wanted(message):
        roles = set(message.signals) - {"counter"}
        if not currents and roles <= {"i_a", "i_b", "i_c"}:
            return False
        return reference or roles != {"ref_angle"}  # a shared message sends ref_angle = 0

    sent = [name for name in layout.messages if wanted(messages[name])]
    gap = _spacing(period, len(sent))
    parts = []
    for slot, name in enumerate(sent):
        message = messages[name]
        rows = np.zeros((n, 8), dtype=np.uint8)
        for signal in message.signals.values():
            if signal.name == "counter":
                raw = np.arange(n) % (1 << signal.length)
            else:
                value = np.asarray(_ROLE_VALUE[signal.name](samples), dtype=float)
                if signal.name in _ANGLE_ROLES:
                    value = value * _UNIT_FROM_RAD[signal.unit]
                if signal.name == "ref_angle" and not reference:
                    value = np.zeros(n)
                raw = signal.to_raw(value, wrap=signal.name in _ANGLE_ROLES)
            signal.insert(rows, raw)
        parts.append((samples.t + slot * gap, np.full(n, message.frame_id), rows, np.arange(n)))
    return _merge(parts)


def encode(samples, config, layout="default", reference=True, currents=True):
    """Frames of the named layout (LAYOUTS)."""
    if layout == "default":
        return encode_default(samples, config, reference, currents)
    if layout not in DBC_LAYOUTS:
        raise ValueError(f"layout '{layout}': not one of {', '.join(LAYOUTS)}")
    return encode_dbc_layout(samples, config, DBC_LAYOUTS[layout], reference, currents)
