#!/usr/bin/python3
"""Writes the bad-input cases of tests/bad_input/cases/ (run once; the output is checked in).

Every log case starts from the same clean log of the default bench layout
(docs/ARCHITECTURE.md §4, proto/resolver_bench.dbc): one BENCH_INFO frame, then N_SAMPLES
control periods of RESOLVER_SAMPLE (0x100), PHASE_CURRENTS (0x101) and
REFERENCE_ANGLE (0x102), 500 us apart (2 kHz). Each case then makes exactly one
kind of damage, and where possible *adds* the bad line/frame rather than
replacing a good one, so the damage shows up in one counter only and the
manifest can insist that no other reject appears.

Frames carry real CRCs, computed here independently of the C++ code:
CRC-8 SAE J1850 (poly 0x1D, init 0xFF, no reflection, xorout 0xFF) over data
bytes 0..6 followed by the low byte of the CAN ID (check value of
b"123456789" = 0x4B, asserted below).

    /usr/bin/python3 tests/bad_input/make_cases.py     # rewrites cases/ and cases.json
"""
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = os.path.join(HERE, "cases")

ID_SAMPLE, ID_CURRENTS, ID_REF, ID_INFO = 0x100, 0x101, 0x102, 0x1F0
N_SAMPLES = 24
T0_US = 1_700_000_000_000_000  # [us] first frame
PERIOD_US = 500  # [us] 2 kHz control period


def crc8_j1850(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


assert crc8_j1850(b"123456789") == 0x4B, "CRC-8 J1850 check value"


def seal(can_id, payload7):
    """8 data bytes: the 7 given plus the bench CRC over them and the ID's low byte."""
    assert len(payload7) == 7
    return payload7 + bytes([crc8_j1850(payload7 + bytes([can_id & 0xFF]))])


def line(t_us, can_id, data, iface="can0"):
    return "(%d.%06d) %s %03X#%s" % (t_us // 1_000_000, t_us % 1_000_000, iface, can_id, data.hex().upper())


def sample_lines(k, samples_per_rev=40.0, amplitude=20000, rd_follows=True):
    """The three frames of control period k (counter k & 0xFF). Default: 40 samples per
    resolver electrical revolution (1000 r/min with p_r = 3 at 2 kHz), envelopes of
    20000 counts, the R/D angle on the true angle. amplitude=0 is a dead excitation
    (sin = cos = 0); rd_follows=False holds the R/D angle at 0 (a converter without input)."""
    t = T0_US + PERIOD_US * (k + 1)
    theta = 2 * math.pi * k / samples_per_rev  # resolver electrical angle [rad]
    sin_c, cos_c = int(amplitude * math.sin(theta)), int(amplitude * math.cos(theta))
    rd = int(wrap(theta) / (2 * math.pi) * 65536) & 0xFFFF if rd_follows else 0
    counter = k & 0xFF
    res = seal(ID_SAMPLE, struct.pack("<BhhH", counter, sin_c, cos_c, rd))
    i_a = int(1000 * math.cos(theta))
    i_b = int(1000 * math.cos(theta - 2 * math.pi / 3))
    i_c = -i_a - i_b
    cur = seal(ID_CURRENTS, struct.pack("<Bhhh", counter, i_a, i_b, i_c))
    ref = seal(ID_REF, struct.pack("<BIH", counter, int(wrap(theta / 3) / (2 * math.pi) * 2**32) & 0xFFFFFFFF, 0))
    return [line(t, ID_SAMPLE, res), line(t + 1, ID_CURRENTS, cur), line(t + 2, ID_REF, ref)]


def wrap(angle):
    """[rad] into [0, 2pi)."""
    return angle % (2 * math.pi)


def clean_log(n_samples=N_SAMPLES, **kwargs):
    """List of lines: BENCH_INFO then n_samples periods (3 lines each); kwargs go to sample_lines."""
    info = seal(ID_INFO, struct.pack("<BBBBHB", 1, 3, 4, 16, 2000, 0))
    lines = [line(T0_US, ID_INFO, info)]
    for k in range(n_samples):
        lines.extend(sample_lines(k, **kwargs))
    return lines


def index_of(k, slot):
    """Line index (0-based) of control period k's frame in slot 0/1/2."""
    return 1 + 3 * k + slot


def time_of(text):
    return text[: text.index(")") + 1]


def replace_data(text, new_frame):
    """Same timestamp and interface, another '<id>#<data>'."""
    head, _, _ = text.rpartition(" ")
    return head + " " + new_frame


def data_of(text):
    return bytes.fromhex(text.rpartition("#")[2])


def asc_of(lines):
    """The candump lines as a Vector ASC file (absolute times from the first frame)."""
    t0 = None
    out = ["date Tue Nov 14 10:13:20.000 PM 2023", "base hex  timestamps absolute", "internal events logged",
           "Begin Triggerblock Tue Nov 14 10:13:20.000 PM 2023"]
    for l in lines:
        t, rest = l[1:].split(")", 1)
        us = round(float(t) * 1e6)
        t0 = us if t0 is None else t0
        frame = rest.split()[1]
        can_id, data = frame.split("#")
        b = bytes.fromhex(data)
        out.append("   %d.%06d 1  %-15s Rx   d %d %s" % ((us - t0) // 1_000_000, (us - t0) % 1_000_000, can_id.lstrip("0") or "0",
                                                      len(b), " ".join("%02X" % x for x in b)))
    out.append("End TriggerBlock")
    return out


SCOPE_TOML = """[bench]
p_r = 1
p = 1
[input.csv]
delimiter = ";"
decimal = ","
header_lines = 5
time_column = "Time"
time_unit = "filetime"
[input.csv.columns]
rd_angle = { column = "Resolver", unit = "deg" }
ref_angle = { column = "Encoder", unit = "deg" }
"""
# 2024-01-01 00:00:00 UTC as a Windows FILETIME (100 ns ticks since 1601-01-01).
FILETIME_2024 = 133_485_408_000_000_000


def scope_rows():
    """A scope export: 5 header lines, a name line, N_SAMPLES rows at 2 kHz (FILETIME, degrees, decimal comma)."""
    out = ["Scope export", "Model;XY-123", "Channels;2", "Sample rate;2000 Hz", "Unit;deg",
           "Time;Resolver;Encoder"]
    for k in range(N_SAMPLES):
        deg = 360.0 * k / 40.0
        out.append("%d;%s;%s" % (FILETIME_2024 + 5000 * k, ("%.4f" % deg).replace(".", ","),
                                 ("%.4f" % (deg + 0.01)).replace(".", ",")))
    return out


cases = []


def log_case(name, lines, reason, count, message, also=None, note="", samples=None, ext=".log", config=None):
    path = os.path.join(CASES, name + ext)
    with open(path, "w", encoding="latin-1", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    case = {"file": "cases/" + name + ext, "kind": "log", "expected_reason": reason,
            "expected_count": count, "expected_message_substring": message}
    if also:
        case["also_expected"] = also
    if samples is not None:
        case["expected_samples"] = samples
    if config:
        case["config"] = "cases/" + config
    if note:
        case["note"] = note
    cases.append(case)


def health_case(name, lines, faults, message, note=""):
    """A log that decodes cleanly but whose signals are faulty: resolverd must report
    `faults` ({name: least share of the samples}) in the report's signal_health, no
    other fault, no reject, and print `message`."""
    path = os.path.join(CASES, name + ".log")
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    case = {"file": "cases/" + name + ".log", "kind": "health", "expected_reason": None, "expected_count": 0,
            "expected_message_substring": message, "expected_faults": faults}
    if note:
        case["note"] = note
    cases.append(case)


def text_case(name, ext, kind, text, message, note="", dbc=None):
    path = os.path.join(CASES, name + ext)
    with open(path, "w", encoding="latin-1", newline="\n") as f:
        f.write(text)
    case = {"file": "cases/" + name + ext, "kind": kind, "expected_reason": None, "expected_count": 0,
            "expected_message_substring": message}
    if dbc:
        case["dbc"] = "cases/" + dbc
    if note:
        case["note"] = note
    cases.append(case)


def inserted(at, new_line):
    lines = clean_log()
    lines.insert(at, new_line)
    return lines


def main():
    os.makedirs(CASES, exist_ok=True)
    for old in os.listdir(CASES):
        os.remove(os.path.join(CASES, old))
    base = clean_log()
    # Line numbers below are 1-based file lines: an inserted line at index i is line i + 1.
    after = index_of(5, 2) + 1  # right after period 5's last frame
    t5 = time_of(base[index_of(5, 2)])

    log_case("clean", base, None, 0, "", note="the unmodified base log: no rejects at all")

    # ---- malformed lines (candump_line.h LogLineError); added lines, so nothing else is touched
    log_case("bad_hex", inserted(after, t5 + " can0 101#0A3200CEFF4G01E8"), "bad_hex", 1,
             "bad_hex.log:%d:41: expected a hex digit 0-9/A-F in the data, found 'G'" % (after + 1))
    log_case("odd_nibbles", inserted(after, t5 + " can0 101#0A3200CEFF4C01E"), "odd_nibbles", 1,
             "odd_nibbles.log:%d:" % (after + 1))
    log_case("dlc_too_long_classic", inserted(after, t5 + " can0 101#0A3200CEFF4C01E8AA"), "dlc_too_long", 1,
             "classic CAN frame has 9 data bytes, at most 8 are allowed")
    log_case("missing_timestamp", inserted(after, "can0 101#0A3200CEFF4C01E8"), "missing_timestamp", 1,
             "missing_timestamp.log:%d:1: expected '(' opening the timestamp" % (after + 1))
    # ---- odd time (issue 16.3): counted and re-anchored, every sample still used
    def shifted(lines, from_period, dt_us):
        out = list(lines)
        for i in range(index_of(from_period, 0), len(out)):
            t, rest = out[i][1:].split(")", 1)
            us = round(float(t) * 1e6) + dt_us
            out[i] = "(%d.%06d)%s" % (us // 1_000_000, us % 1_000_000, rest)
        return out
    log_case("timestamp_step_back", shifted(base, 12, -1_000_000), "timestamp_step_back", 1,
             "line %d: sample 12 at (1699999999.006500): the timestamp goes back 0.999500 s from the previous "
             "sample's; time continues from the counter" % (index_of(12, 2) + 1),
             samples=N_SAMPLES,
             note="every frame from period 12 on is 1 s earlier; the counter goes on: all samples used")
    log_case("timestamp_jump", shifted(base, 12, 86_400_000_000), "timestamp_jump", 1,
             "the timestamp jumps forward 86400.000500 s while the counter advanced by 1; read as a clock jump, "
             "time continues from the counter", samples=N_SAMPLES,
             note="every frame from period 12 on is a day later; the counter goes on: all samples used")
    log_case("logs_appended", base + base[1:], "timestamp_step_back", 1,
             "time continues one sample period after the previous sample (logs appended?)",
             also={"counter_wrong_sequence": 1}, samples=2 * N_SAMPLES,
             note="the clean log twice: time and counter both restart (one new sequence); the second copy joins "
                  "one period on")
    log_case("bad_fd_flags", inserted(after, t5 + " can0 101##80A3200CEFF4C01E8"), "bad_fd_flags", 1,
             "expected the CAN FD flags nibble 0-7")
    log_case("bad_fd_length", inserted(after, t5 + " can0 101##10A3200CEFF4C01E8AA"), "dlc_too_long", 1,
             "not a valid FD length")
    log_case("bad_id_digits", inserted(after, t5 + " can0 1010#0A3200CEFF4C01E8"), "bad_id", 1,
             "CAN id '1010' has 4 hex digits")
    log_case("bad_id_range", inserted(after, t5 + " can0 800#0A3200CEFF4C01E8"), "bad_id", 1,
             "standard CAN id 0x800 is above 0x7FF")
    log_case("bad_timestamp", inserted(after, "(17000000x0.000000) can0 101#00"), "bad_timestamp", 1,
             "bad_timestamp.log:%d:10:" % (after + 1))
    log_case("missing_frame", inserted(after, t5 + " can0"), "missing_frame", 1,
             "missing_frame.log:%d:25: expected the frame '<id>#<data>' after interface 'can0'" % (after + 1))
    log_case("missing_frame_trailing_blanks", inserted(after, t5 + " can0 \t \r"), "missing_frame", 1,
             "missing_frame_trailing_blanks.log:%d:25: expected the frame" % (after + 1),
             note="trailing blanks and CR are trimmed before parsing")
    log_case("missing_interface", inserted(after, t5), "missing_interface", 1,
             "missing_interface.log:%d:20: expected the interface name (e.g. can0) after the timestamp" % (after + 1))
    log_case("bad_separator", inserted(after, t5 + " can0 101#0A3200CEFF4C01E8 junk"), "bad_separator", 1,
             "unexpected text after the frame, found 'j'")
    log_case("line_too_long", inserted(after, t5 + " can0 101#" + "A" * 5000), "line_too_long", 1,
             "line_too_long.log:%d:4097: line is" % (after + 1))
    flood = clean_log()
    for n in range(12):
        flood.insert(after + n, t5 + " can0 101#ZZ")
    log_case("bad_hex_flood", flood, "bad_hex", 12,
             "further 'bad_hex' problems are counted (health_t, final report), not printed",
             note="only the first ten of a kind are printed; all twelve are counted")

    # ---- frames that parse but fail the bench layout (frame_decoder.h FrameReject)
    bad = bytearray(data_of(base[index_of(5, 1)]))
    bad[2] ^= 0x10  # one bit flipped, CRC byte kept: a CRC mismatch
    log_case("crc_mismatch", inserted(index_of(5, 1) + 1, replace_data(base[index_of(5, 1)], "101#" + bad.hex().upper())),
             "crc", 1, "line %d: frame 101 at (1700000000.003001): CRC-8 J1850 mismatch" % (index_of(5, 1) + 2), note="corrupted copy added next to the good frame, so counters stay clean")
    last5 = base[index_of(5, 2)]  # added frames take the previous frame's time (equal times are fine)
    log_case("unknown_id", inserted(after, replace_data(last5, "321#" + data_of(base[index_of(5, 1)]).hex().upper())),
             "unknown_id", 1, "line %d: frame 321 at (1700000000.003002): unknown CAN ID" % (after + 1))
    log_case("wrong_dlc", inserted(after, replace_data(last5, "101#" + data_of(base[index_of(5, 1)])[:6].hex().upper())),
             "wrong_dlc", 1, "line %d: frame 101 at (1700000000.003002): length 6 differs from the DBC's DLC" % (after + 1))
    log_case("remote_frame", inserted(after, replace_data(last5, "101#R")),
             "remote_frame", 1, "line %d: frame 101 at (1700000000.003002): remote (RTR) frame" % (after + 1))

    # ---- counter supervision and joining (sample_joiner.h)
    dup = clean_log()
    dup.insert(index_of(6, 1) + 1, dup[index_of(6, 1)])  # exact copy right after the original
    log_case("counter_repeated", dup, "counter_repeated", 1,
             "line %d: frame 101 at (1700000000.003501): PHASE_CURRENTS counter 6 repeated" % (index_of(6, 1) + 2))
    gap = clean_log()
    del gap[index_of(7, 0): index_of(8, 2) + 1]  # periods 7 and 8 lost entirely
    log_case("counter_gap", gap, "counter_gap", 3, "RESOLVER_SAMPLE counter jumped to 9, 2 frame(s) lost",
             also={"frames_lost": 6},
             note="each of the three sample messages sees its counter jump 6 -> 9 once; frames_lost = 6")
    jump = clean_log()
    del jump[index_of(7, 0): index_of(18, 2) + 1]  # 12 periods lost: more than max_counter_delta = 8
    log_case("counter_wrong_sequence", jump, "counter_wrong_sequence", 1,
             "RESOLVER_SAMPLE counter jumped to 19 from 6: 12 periods missing as the 8-bit counter counts, more than "
             "[layout] max_counter_delta = 8, or a new sequence (a restart, logs appended): resynchronised, the "
             "sample index advances by 13",
             note="12 periods lost, more than max_counter_delta = 8: one new sequence, its index step named")
    missing = clean_log()
    del missing[index_of(10, 1)]  # period 10 without its PHASE_CURRENTS frame
    log_case("sample_missing_frame", missing, "sample_incomplete", 1, "sample counter 10 (index 10) is missing PHASE_CURRENTS",
             also={"counter_gap": 1, "frames_lost": 1},
             note="PHASE_CURRENTS' counter also jumps 9 -> 11 (one frame lost)")

    # ---- issue 25 ("Trust"): frames out of order as a USB-CAN adapter's buffering delivers them
    # (reordered within [layout] max_counter_delta periods: joined, not lost), and a second interface
    shuffled = clean_log()
    shuffled.insert(index_of(6, 1), shuffled.pop(index_of(7, 0)))  # period 7's first frame before 6's other two
    log_case("frames_reordered", shuffled, "frames_reordered", 2,
             "line %d: frame 101 at %s: PHASE_CURRENTS counter 6 came after a frame of counter 7: reordered, joined "
             "into its own sample (not lost)" % (index_of(6, 1) + 2, time_of(base[index_of(6, 1)])),
             samples=N_SAMPLES,
             note="period 7's RESOLVER_SAMPLE arrives before period 6's PHASE_CURRENTS and REFERENCE_ANGLE: before, "
                  "counter_gap, frames_lost, counter_wrong_sequence and two incomplete samples")
    late = clean_log()
    late.insert(index_of(11, 2), late.pop(index_of(10, 2)))  # period 10's REFERENCE_ANGLE after period 11's frames
    log_case("frame_late_by_one_period", late, "frames_reordered", 1,
             "REFERENCE_ANGLE counter 10 came after a frame of counter 11: reordered, joined into its own sample",
             samples=N_SAMPLES,
             note="before, the sample index jumped by 257 (10, 266, 268: the counter read as wrapped) with no gap "
                  "counted, and 2 frames were counted lost")
    too_late = clean_log()
    too_late.insert(index_of(15, 2), too_late.pop(index_of(5, 1)))  # period 5's PHASE_CURRENTS after period 15's frames
    log_case("frame_later_than_the_window", too_late, "frames_late", 1,
             "PHASE_CURRENTS counter 5 is 10 periods behind the newest (15), more than [layout] max_counter_delta = "
             "8: it came after its sample was used, dropped (not lost",
             also={"sample_incomplete": 1}, samples=N_SAMPLES,
             note="10 periods late, more than the window: its sample went out without it (incomplete); it is counted "
                  "late, not lost, and the index does not move")
    second = []
    for k in range(N_SAMPLES):  # a second bench on can1, its counter 100 further, 130 us after can0's frames
        for l in sample_lines(k + 100):
            t, rest = l[1:].split(")", 1)
            us = round(float(t) * 1e6) - PERIOD_US * 100 + 130
            second.append("(%d.%06d)%s" % (us // 1_000_000, us % 1_000_000, rest.replace(" can0 ", " can1 ")))
    mixed = sorted(base + second, key=lambda l: float(l[1:l.index(")")]))
    log_case("other_interface", mixed, "other_interface", 3 * N_SAMPLES,
             "on can1: the log holds frames of more than one CAN interface; only can0's are read (the first "
             "interface with a frame of the layout), can1's are counted as other_interface and left out",
             samples=N_SAMPLES,
             note="a second bench on can1 interleaved: before, its counters were joined with can0's (hundreds of "
                  "seconds of a standing rotor in a 12 ms log)")

    # ---- signal faults (issue 16): the frames are fine, the signals are not
    health_case("dead_excitation", clean_log(1000, amplitude=0, rd_follows=False), {"loss_of_signal": 1.0},
                "signal fault loss_of_signal started 0.000 s into the input (sample 0): sin/cos amplitude 0.0",
                note="sin = cos = 0 for the whole log (a dead excitation or a broken connector), the R/D angle "
                     "held at 0, the motor turning (reference and currents): loss of signal and nothing else; "
                     "theta_sincos must be NaN")
    # 30000 r/min with p_r = 3 at 2 kHz: 0.75 resolver electrical revolutions per sample, beyond what the
    # sample rate can represent (resolver-sim refuses to write it); the mechanical reference still resolves it.
    health_case("overspeed_30000rpm", clean_log(1000, samples_per_rev=1 / 0.75), {"overspeed": 1.0},
                "signal fault overspeed started 0.000 s into the input (sample 0): resolver electrical travel 4.712 "
                "rad per sample (from the reference angle)",
                note="30000 r/min: more than pi rad of resolver travel per sample")

    # ---- Vector ASC (drivers/asc): the clean log as CANoe writes it, then one bad line each
    asc = asc_of(base)
    log_case("asc_clean", asc, None, 0, "", samples=N_SAMPLES, ext=".asc",
             note="the clean log as a Vector ASC file (header, trigger block, classic lines)")
    at = 5 + 3 * 6  # after period 5 (4 header lines, BENCH_INFO, 3 lines per period)
    asc_t5 = asc[at - 1].split()[0]
    for name, line, reason, message in [
        ("asc_unknown_line", "hello", "asc_unknown_line", "asc_unknown_line.asc:%d:1: not a Vector ASC line" % (at + 1)),
        ("asc_unsupported_event", "   %s 1 Statistic: D 0 R 0 XD 0 XR 0" % asc_t5, "asc_unsupported_event",
         "asc_unsupported_event.asc:%d:15: event '1 Statistic: D 0 R 0 XD 0 XR 0' carries no CAN frame" % (at + 1)),
        ("asc_bad_data_byte", "   %s 1  101             Rx   d 2 0A 0G" % asc_t5, "bad_data_byte",
         "asc_bad_data_byte.asc:%d:44: expected a data byte (hex 00..FF), found '0G'" % (at + 1)),
        ("asc_missing_data", "   %s 1  101             Rx   d 8 0A" % asc_t5, "missing_data",
         "the DLC announces 8 data bytes, the line has 1"),
    ]:
        bad_asc = list(asc)
        bad_asc.insert(at, line)
        log_case(name, bad_asc, reason, 1, message, samples=N_SAMPLES, ext=".asc")

    # ---- CSV / scope exports (drivers/csv, daemon/decode/row_decoder.h) through a column map
    with open(os.path.join(CASES, "scope.toml"), "w", encoding="ascii") as f:
        f.write(SCOPE_TOML)
    rows = scope_rows()
    log_case("csv_clean", rows, None, 0, "", samples=N_SAMPLES, ext=".csv", config="scope.toml",
             note="FILETIME, ';', decimal comma, degrees, 5 header lines: every row a sample")
    row_at = 6 + 15  # header lines, names line, then row 15 (the clock has learned the period by then)
    bad = list(rows)
    bad[row_at] = bad[row_at].replace(";", ";x", 1)
    log_case("csv_bad_number", bad, "bad_number", 1,
             "csv_bad_number.csv:%d:20: column 'Resolver' (rd_angle): expected a number with ',' as decimal mark" % (row_at + 1),
             samples=N_SAMPLES - 1, ext=".csv", config="scope.toml", also={"sample_gap": 1, "samples_lost": 1},
             note="the bad row is lost; the sample clock finds the gap it leaves")
    short = list(rows)
    short[row_at] = short[row_at].rsplit(";", 1)[0]
    log_case("csv_missing_column", short, "missing_column", 1,
             "csv_missing_column.csv:%d:" % (row_at + 1), samples=N_SAMPLES - 1, ext=".csv", config="scope.toml",
             also={"sample_gap": 1, "samples_lost": 1})
    back = list(rows)
    for i in range(row_at, len(back)):
        ft, rest = back[i].split(";", 1)
        back[i] = "%d;%s" % (int(ft) - 10_000_000, rest)  # 1 s earlier from row 15 on
    log_case("csv_time_step_back", back, "timestamp_step_back", 1,
             "line %d: sample 15 at (1704067199.007500): the timestamp goes back 0.999500 s" % (row_at + 1),
             samples=N_SAMPLES, ext=".csv", config="scope.toml",
             note="rows from 15 on are 1 s earlier: counted, re-anchored, every row used")
    swapped = list(rows)
    swapped[row_at], swapped[row_at + 1] = swapped[row_at + 1], swapped[row_at]
    log_case("csv_rows_swapped", swapped, "rows_reordered", 1,
             "line %d: row at (1704067200.007500) comes before line %d's (1704067200.008000) in time: rows out of "
             "order, used in time order (not lost)" % (row_at + 2, row_at + 1),
             samples=N_SAMPLES, ext=".csv", config="scope.toml",
             note="rows 15 and 16 swapped: before, a step back and two gaps (samples_lost = 2) of nothing missing")
    text_case("csv_unknown_column", ".toml", "config", SCOPE_TOML.replace('"Encoder"', '"Encoder2"'),
              "no column named 'Encoder2' (the columns are 'Time', 'Resolver', 'Encoder')")
    cases[-1]["replay"] = "cases/csv_clean.csv"
    text_case("csv_unknown_unit", ".toml", "config", SCOPE_TOML.replace('unit = "deg" }\nref', 'unit = "grad" }\nref'),
              "rd_angle: unit \"grad\" is not an angle unit")
    cases[-1]["replay"] = "cases/csv_clean.csv"
    text_case("csv_without_columns", ".toml", "config", "[bench]\np_r = 1\n",
              "is read as a CSV / scope export (by its extension), but ")
    cases[-1]["replay"] = "cases/csv_clean.csv"

    # ---- a DBC angle in an unknown unit (signal_units.h): refused, naming the signal
    with open(os.path.join(HERE, "..", "..", "proto", "resolver_bench.dbc"), encoding="ascii") as f:
        grad = f.read().replace('"rad" RESOLVERD', '"grad" RESOLVERD', 1)
    text_case("dbc_angle_unit_unknown", ".dbc", "dbc", grad,
              "role 'rd_angle' (RESOLVER_SAMPLE.rd_angle): unit \"grad\" is unknown")
    with open(os.path.join(CASES, "dbc_angle_unit_unknown.toml"), "w", encoding="ascii") as f:
        f.write("[layout]\ndbc = \"dbc_angle_unit_unknown.dbc\"\n")
    cases[-1]["config"] = "cases/dbc_angle_unit_unknown.toml"

    # ---- configuration and DBC: resolverd must refuse to start, exit 2, say where and why
    text_case("bad_toml", ".toml", "config", "[bench]\np_r = = 3\n",
              "bad_toml.toml:2:7: TOML syntax error")
    text_case("unknown_config_key", ".toml", "config", "[bench]\np_r = 3\npole_pairs = 4\n",
              "unknown key 'pole_pairs' in [bench]")
    text_case("bad_config_value", ".toml", "config", "[output]\nangle_decimation = 0\n",
              "[output] angle_decimation must be >= 1, got 0")
    text_case("bad_signal_map", ".toml", "config",
              "[layout.signals]\nsin = \"RESOLVER_SAMPLE.sine\"\ncos = \"RESOLVER_SAMPLE.cos\"\n",
              "message 'RESOLVER_SAMPLE' has no signal 'sine'")
    with open(os.path.join(HERE, "..", "..", "proto", "resolver_bench.dbc"), encoding="ascii") as f:
        bench_dbc = f.read()
    broken = bench_dbc.replace("BO_ 257 PHASE_CURRENTS: 8 INVERTER", "BO_ 257 PHASE_CURRENTS 8 INVERTER")
    assert broken != bench_dbc
    broken_line = broken[: broken.index("BO_ 257 PHASE_CURRENTS 8")].count("\n") + 1
    text_case("dbc_syntax_error", ".dbc", "dbc", broken, "dbc_syntax_error.dbc:%d:" % broken_line,
              note="the bench DBC with the ':' after PHASE_CURRENTS removed; loaded through a config")
    with open(os.path.join(CASES, "dbc_syntax_error.toml"), "w", encoding="ascii") as f:
        f.write("[layout]\ndbc = \"dbc_syntax_error.dbc\"\n")
    cases[-1]["config"] = "cases/dbc_syntax_error.toml"
    signal_past = bench_dbc.replace("SG_ crc : 56|8@1+", "SG_ crc : 60|8@1+", 1)
    assert signal_past != bench_dbc
    text_case("dbc_signal_past_dlc", ".dbc", "dbc", signal_past, "dbc_signal_past_dlc.dbc:",
              note="RESOLVER_SAMPLE.crc moved to bits 60..67 of an 8-byte message")
    with open(os.path.join(CASES, "dbc_signal_past_dlc.toml"), "w", encoding="ascii") as f:
        f.write("[layout]\ndbc = \"dbc_signal_past_dlc.dbc\"\n")
    cases[-1]["config"] = "cases/dbc_signal_past_dlc.toml"

    overlap = bench_dbc.replace("SG_ cos : 24|16@1-", "SG_ cos : 16|16@1-", 1)
    assert overlap != bench_dbc
    text_case("dbc_overlapping_signals", ".dbc", "dbc", overlap,
              "message 'RESOLVER_SAMPLE': signals 'sin' (bits 8..23) and 'cos' (bits 16..31) overlap in bits 16..23",
              note="RESOLVER_SAMPLE.cos moved onto the upper byte of sin: two quantities from the same bits")
    with open(os.path.join(CASES, "dbc_overlapping_signals.toml"), "w", encoding="ascii") as f:
        f.write("[layout]\ndbc = \"dbc_overlapping_signals.dbc\"\n")
    cases[-1]["config"] = "cases/dbc_overlapping_signals.toml"

    with open(os.path.join(HERE, "cases.json"), "w", encoding="ascii") as f:
        json.dump({"comment": "Written by make_cases.py; read by run_bad_inputs.py. Paths are relative to "
                              "tests/bad_input/, where resolverd runs.", "cases": cases}, f, indent=2)
        f.write("\n")
    print("wrote %d cases to %s" % (len(cases), CASES))


if __name__ == "__main__":
    main()
