"""Log writers: candump -l, Vector ASC (python-can's ASCWriter), scope-style CSV, truth files.

Absolute time = start [us since the Unix epoch] + relative time, kept in integer
microseconds so a 1.7e9 s epoch loses nothing to float rounding.
"""
import csv
import json
import time

import numpy as np

from .conventions import TWO_PI

FILETIME_UNIX_EPOCH = 116444736000000000  # 100 ns ticks from 1601-01-01 to 1970-01-01 UTC


def absolute_us(start_us, times):
    return int(start_us) + np.rint(np.asarray(times) * 1e6).astype(np.int64)


def _hex_rows(data):
    text = np.ascontiguousarray(data).tobytes().hex().upper()
    width = 2 * data.shape[1]
    return [text[k:k + width] for k in range(0, len(text), width)]


def write_candump(path, frames, index, times, start_us, iface="can0"):
    """candump -l lines "(sec.usec) iface ID#DATA" for frames[index] at times [s]."""
    us = absolute_us(start_us, times)
    sec, usec = np.divmod(us, 1_000_000)
    ids = frames.can_id[index]
    data = _hex_rows(frames.data[index])
    with open(path, "w", encoding="ascii") as out:
        out.writelines(f"({s}.{u:06d}) {iface} {i:03X}#{d}\n" if i <= 0x7FF else
                       f"({s}.{u:06d}) {iface} {i:08X}#{d}\n"
                       for s, u, i, d in zip(sec.tolist(), usec.tolist(), ids.tolist(), data))


def write_asc(path, frames, index, times, start_us):
    """Vector ASC through python-can's ASCWriter; its wall-clock header lines are replaced by
    the log's start time (UTC) so the same seed gives the same file."""
    import can  # Debian python3-can

    us = absolute_us(start_us, times)
    writer = can.ASCWriter(path)
    for stamp, can_id, row in zip(us.tolist(), frames.can_id[index].tolist(), frames.data[index]):
        writer.on_message_received(can.Message(timestamp=stamp / 1e6, arbitration_id=can_id,
                                               is_extended_id=can_id > 0x7FF, data=bytes(row),
                                               channel=0, is_rx=True))
    writer.stop()
    start = time.gmtime(int(start_us) // 1_000_000)
    millis = (int(start_us) // 1000) % 1000
    stamp = time.strftime(f"%a %b %d %I:%M:%S.{millis:03d} %p %Y", start)
    with open(path, encoding="ascii") as handle:
        lines = handle.readlines()
    for k, line in enumerate(lines[:6]):
        if line.startswith("date "):
            lines[k] = f"date {stamp}\n"
        elif line.startswith("Begin Triggerblock"):
            lines[k] = f"Begin Triggerblock {stamp}\n"
    with open(path, "w", encoding="ascii") as handle:
        handle.writelines(lines)


# Scope CSV columns: header text and value [column unit] of a sample.
CSV_COLUMNS = {
    "rd_angle": ("RD angle [deg]", lambda s: s.rd_angle * (360.0 / TWO_PI), "%.6f"),
    "ref_angle": ("Reference angle [deg]", lambda s: s.ref_angle * (360.0 / TWO_PI), "%.6f"),
    "sin": ("Sin [counts]", lambda s: s.sin, "%d"),
    "cos": ("Cos [counts]", lambda s: s.cos, "%d"),
    "i_a": ("Ia [A]", lambda s: s.i_a, "%.4f"),
    "i_b": ("Ib [A]", lambda s: s.i_b, "%.4f"),
    "i_c": ("Ic [A]", lambda s: s.i_c, "%.4f"),
}
CSV_HEADER_LINES = 4  # lines before the column-name line


def write_scope_csv(path, samples, index, times, start_us, columns, sample_rate):
    """A scope-style export: 4 header lines, a column-name line, then rows of
    Windows FILETIME (100 ns ticks since 1601-01-01 UTC); values with a decimal comma, ';'."""
    ticks = int(start_us) * 10 + np.rint(np.asarray(times) * 1e7).astype(np.int64) + FILETIME_UNIX_EPOCH
    cells = [ticks.astype(str)]
    for name in columns:
        _, value, fmt = CSV_COLUMNS[name]
        column = np.char.mod(fmt, np.asarray(value(samples))[index])
        cells.append(np.char.replace(column, ".", ","))
    interval = f"{1.0 / sample_rate:.6g}".replace(".", ",")
    with open(path, "w", encoding="utf-8", newline="") as out:
        out.write("Scope export;benchgen\n")
        out.write(f"Channels;{len(columns)}\n")
        out.write(f"Sample interval [s];{interval}\n")
        out.write("Time base;Windows FILETIME (100 ns ticks since 1601-01-01 UTC)\n")
        out.write(";".join(["Time [FILETIME]"] + [CSV_COLUMNS[c][0] for c in columns]) + "\n")
        out.writelines(";".join(row) + "\n" for row in zip(*[c.tolist() for c in cells]))


def write_truth_json(path, truth):
    with open(path, "w", encoding="utf-8") as out:
        json.dump(truth, out, indent=2, sort_keys=False)
        out.write("\n")


def write_truth_samples(path, samples, p_r):
    """Per-sample truth, plain CSV ('.' decimals, ',' separator), one row per sample."""
    eps = np.mod(p_r * samples.theta_m - samples.rd_angle + np.pi, TWO_PI) - np.pi
    columns = {
        "index": np.arange(len(samples)),
        "t_s": samples.t,
        "theta_m_rad": samples.theta_m,  # true mechanical angle, unwrapped
        "omega_m_rad_s": samples.omega_m,
        "theta_resolver_shaft_rad": samples.theta_b,  # after the backlash play
        "phi_converter_rad": samples.phi,  # R/D before quantization, read at t - delay
        "rd_angle_rad": samples.rd_angle,  # as sent
        "eps_rad": eps,  # p_r theta_m - rd_angle, wrapped [resolver electrical rad]
    }
    with open(path, "w", encoding="ascii", newline="") as out:
        writer = csv.writer(out)
        writer.writerow(columns)
        formatted = [np.char.mod("%d" if k == "index" else "%.12g", v).tolist() for k, v in columns.items()]
        writer.writerows(zip(*formatted))
