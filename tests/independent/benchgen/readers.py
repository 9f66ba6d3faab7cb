"""Readers for what benchgen writes, used by the tests (and handy for a user's checks):
a candump -l parser, the docs/ARCHITECTURE.md §4 byte-level decoder with CRC check, a DBC decoder, the
scope CSV parser. Independent of the writers: they parse text, they do not share state.
"""
import csv
import re

import numpy as np

from .crc8 import frame_crc
from .dbc import read_dbc

_LINE = re.compile(r"^\((\d+)\.(\d{6})\)\s+(\S+)\s+([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#([0-9A-Fa-f]*)\s*$")


def read_candump(path):
    """(time_us int64, ids, data (n, 8) uint8, dlc) of a candump -l file; raises naming file:line."""
    stamps, ids, rows, dlcs = [], [], [], []
    with open(path, encoding="ascii") as handle:
        for number, line in enumerate(handle, start=1):
            match = _LINE.match(line)
            if not match:
                raise ValueError(f"{path}:{number}: not a candump -l line: {line.strip()!r}")
            payload = bytes.fromhex(match.group(5))
            stamps.append(int(match.group(1)) * 1_000_000 + int(match.group(2)))
            ids.append(int(match.group(4), 16))
            rows.append(payload.ljust(8, b"\0"))
            dlcs.append(len(payload))
    data = np.frombuffer(b"".join(rows), dtype=np.uint8).reshape(-1, 8)
    return np.array(stamps, dtype=np.int64), np.array(ids), data, np.array(dlcs)


def decode_default(ids, data):
    """docs/ARCHITECTURE.md §4 frames by ID: dict id -> dict of fields (byte-level, little endian), crc_ok."""
    out = {}
    for can_id in (0x100, 0x101, 0x102, 0x1F0):
        rows = data[ids == can_id]
        fields = {"crc_ok": rows[:, 7] == frame_crc(rows[:, :7], can_id)}
        raw = np.ascontiguousarray(rows)
        if can_id == 0x1F0:
            fields.update(version=rows[:, 0], p_r=rows[:, 1], p=rows[:, 2], rd_bits=rows[:, 3],
                          sample_rate=raw[:, 4:6].copy().view("<u2").ravel())
        else:
            fields["counter"] = rows[:, 0]
        if can_id == 0x100:
            fields.update(sin=raw[:, 1:3].copy().view("<i2").ravel(), cos=raw[:, 3:5].copy().view("<i2").ravel(),
                          rd_angle=raw[:, 5:7].copy().view("<u2").ravel())
        elif can_id == 0x101:
            fields.update(i_a=raw[:, 1:3].copy().view("<i2").ravel(), i_b=raw[:, 3:5].copy().view("<i2").ravel(),
                          i_c=raw[:, 5:7].copy().view("<i2").ravel())
        elif can_id == 0x102:
            fields.update(ref_angle=raw[:, 1:5].copy().view("<u4").ravel(), reserved=raw[:, 5:7])
        out[can_id] = fields
    return out


def decode_with_dbc(ids, data, dbc_path):
    """Every message of a DBC found in the frames: dict name -> dict signal -> physical values."""
    out = {}
    for message in read_dbc(dbc_path).values():
        rows = data[ids == message.frame_id]
        out[message.name] = {name: signal.decode(rows) for name, signal in message.signals.items()}
    return out


def read_scope_csv(path, header_lines=4):
    """(FILETIME ticks, column names, values (n, k) float) of a benchgen scope CSV."""
    with open(path, encoding="utf-8", newline="") as handle:
        for _ in range(header_lines):
            next(handle)
        reader = csv.reader(handle, delimiter=";")
        names = next(reader)
        rows = [row for row in reader]
    ticks = np.array([int(r[0]) for r in rows], dtype=np.int64)
    values = np.array([[float(v.replace(",", ".")) for v in r[1:]] for r in rows])
    return ticks, names, values.reshape(len(rows), len(names) - 1)
