"""A small DBC reader and a vectorised signal codec (BO_ / SG_ lines; no multiplexing).

Bit numbering as Vector's DBC: Intel (@1) start = LSB, counted from bit 0 of byte 0 upward;
Motorola (@0) start = MSB, numbered byte * 8 + bit-in-byte (7 = a byte's MSB), the signal
continuing into the following bytes toward their LSB.
"""
import re
from dataclasses import dataclass, field

import numpy as np

_BO = re.compile(r"^BO_\s+(\d+)\s+(\w+)\s*:\s*(\d+)\s+(\w+)")
_SG = re.compile(r"^\s*SG_\s+(\w+)\s*:\s*(\d+)\|(\d+)@([01])([+-])\s*\(\s*([^,]+),\s*([^)]+)\)\s*"
                 r"\[\s*([^|]+)\|\s*([^\]]+)\]\s*\"([^\"]*)\"")


class DbcError(ValueError):
    """A DBC line that cannot be read; the message names file:line."""


@dataclass
class Signal:
    name: str
    start: int
    length: int
    little_endian: bool
    signed: bool
    factor: float
    offset: float
    minimum: float
    maximum: float
    unit: str

    def _shift(self):
        if self.little_endian:
            return self.start
        msb = (7 - self.start // 8) * 8 + self.start % 8  # position in the big-endian 64-bit word
        return msb - self.length + 1

    def raw(self, data):
        """Raw integers of this signal in every row of a (n, 8) uint8 array."""
        data = np.ascontiguousarray(np.asarray(data, dtype=np.uint8))
        word = data.view("<u8" if self.little_endian else ">u8").reshape(-1).astype(np.uint64)
        mask = np.uint64((1 << self.length) - 1)
        value = ((word >> np.uint64(self._shift())) & mask).astype(np.int64)
        if self.signed:
            value = np.where(value >= (1 << (self.length - 1)), value - (1 << self.length), value)
        return value

    def decode(self, data):
        """Physical values [unit] in every row."""
        return self.raw(data) * self.factor + self.offset

    def insert(self, data, raw):
        """Writes raw integers (two's complement for signed) into the rows of `data` in place."""
        data = np.asarray(data)
        mask = (1 << self.length) - 1
        bits = (np.asarray(raw, dtype=np.int64) & mask).astype(np.uint64) << np.uint64(self._shift())
        keep = np.uint64(0xFFFFFFFFFFFFFFFF ^ (mask << self._shift()))
        dtype = "<u8" if self.little_endian else ">u8"
        word = np.ascontiguousarray(data).view(dtype).reshape(-1).astype(np.uint64)
        word = (word & keep) | bits
        data[:] = word.astype(dtype).view(np.uint8).reshape(-1, 8)

    def to_raw(self, physical, wrap=False):
        """Physical -> raw integers, rounded; wrap=True folds modulo 2^length (angles)."""
        raw = np.rint((np.asarray(physical, dtype=float) - self.offset) / self.factor).astype(np.int64)
        if wrap:
            raw = np.mod(raw, 1 << self.length)
            if self.signed:
                raw = np.where(raw >= (1 << (self.length - 1)), raw - (1 << self.length), raw)
            return raw
        low = -(1 << (self.length - 1)) if self.signed else 0
        high = (1 << (self.length - 1)) - 1 if self.signed else (1 << self.length) - 1
        return np.clip(raw, low, high)


@dataclass
class Message:
    frame_id: int
    name: str
    dlc: int
    extended: bool
    signals: dict = field(default_factory=dict)


def read_dbc(path):
    """Messages by name from a DBC file."""
    messages = {}
    current = None
    with open(path, encoding="utf-8", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            if line.startswith("BO_ "):
                match = _BO.match(line)
                if not match:
                    raise DbcError(f"{path}:{number}: unreadable BO_ line")
                raw_id = int(match.group(1))
                current = Message(raw_id & 0x1FFFFFFF, match.group(2), int(match.group(3)),
                                  bool(raw_id & 0x80000000))
                messages[current.name] = current
            elif line.strip().startswith("SG_"):
                match = _SG.match(line)
                if not match or current is None:
                    raise DbcError(f"{path}:{number}: unreadable SG_ line (or SG_ before any BO_)")
                g = match.groups()
                current.signals[g[0]] = Signal(g[0], int(g[1]), int(g[2]), g[3] == "1", g[4] == "-",
                                               float(g[5]), float(g[6]), float(g[7]), float(g[8]), g[9])
            elif not line.strip():
                current = None
    return messages
