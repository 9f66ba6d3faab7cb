#!/usr/bin/python3
"""Real bench data in (issues 13, 16): logs and exports nobody wrote for us, through the real programs.

Every case starts from a resolver-sim log (the truth) and turns it into what a
bench engineer brings, with tools that share no code with this project
(python-can for CAN files, struct for payloads):

  * a Vector ASC log written by python-can's ASCWriter,
  * a scope export: ';' separated, decimal comma, 5 header lines, Windows
    FILETIME time stamps, angles in degrees,
  * an angle-only CAN layout: p_r = 1, no counter, no CRC, angles in degrees
    (one of them with the Latin-1 degree sign a Windows DBC carries),
  * logs whose timestamps step back 1 s, jump forward a day, or that are two
    recordings appended,
  * a config whose DBC gives the angle in a unit nobody knows, a log without a
    reference encoder, an export with bad rows.

Both resolverd --replay (--report JSON, and angle_t per sample on an LCM log)
and resolver-model fit --json must read them. Where a case holds exactly the
samples of the candump original (ASC; odd time with a counter) the results
must be identical, because both programs time samples by the counter
(index / sample rate) and the values are the same bits. Where it changes the
values (degrees printed with 9 decimals: 1.7e-11 rad, six orders below the
16-bit R/D LSB of 9.6e-5 rad) they must agree to well inside that LSB.
"""
import argparse
import json
import math
import os
import struct
import subprocess
import sys
import unittest

ARGS = None
PY = "/usr/bin/python3"  # Debian's interpreter: the one python3-can is installed for
FILETIME_UNIX_EPOCH = 116_444_736_000_000_000  # 100 ns ticks from 1601-01-01 to 1970-01-01
SAMPLE_RATE = 2000.0  # [Hz] resolver-sim's default
DURATION = 4.0        # [s]
SAMPLES = int(SAMPLE_RATE * DURATION)


def run(cmd, ok=True, **kw):
    proc = subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)
    if ok and proc.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    return proc


def work(name):
    return os.path.join(ARGS.work, name)


def have_pycan():
    return subprocess.run([PY, "-c", "import can"], capture_output=True).returncode == 0


def skip_or_fail_without_pycan(test):
    if not have_pycan():
        if os.environ.get("RESOLVER_REQUIRE_PYCAN") == "1":
            test.fail(f"{PY} cannot 'import can' but RESOLVER_REQUIRE_PYCAN=1; install python3-can")
        test.skipTest(f"{PY} cannot 'import can' (install python3-can)")


def sim(out, *extra):
    run([f"{ARGS.bin}/resolver-sim", "--out", out, "--rpm", "200", "--duration", str(DURATION),
         "--effect", "amplitude_imbalance:alpha=0.003", "--seed", "3", *extra])


def replay(log, name, *extra, lcm=False):
    """resolverd --replay: (report dict, stderr, angle_t messages or None)."""
    rep = work(name + ".report.json")
    lcmlog = work(name + ".lcmlog")
    for f in (rep, lcmlog):
        if os.path.exists(f):
            os.remove(f)
    proc = run([f"{ARGS.bin}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--report", rep,
                "--lcm", f"file://{lcmlog}?mode=w" if lcm else "memq://", *extra])
    with open(rep) as f:
        report = json.load(f)
    angles = None
    if lcm:
        echo = run([f"{ARGS.bin}/resolver-echo", "--log", lcmlog, "--type", "angle_t"])
        angles = [json.loads(l) for l in echo.stdout.splitlines() if l.strip()]
    return report, proc.stderr, angles


def fit(log, *extra):
    proc = run([f"{ARGS.bin}/resolver-model", "fit", log, "--json", *extra])
    return json.loads(proc.stdout)


def without_notes(fit_json):
    return {k: v for k, v in fit_json.items() if k != "notes"}


def signal_rows(fit_json, name):
    for s in fit_json.get("signals", []):
        if s["signal"] == name:
            return s["rows"]
    return None


def read_candump(path):
    """[(t_us, id, data bytes)] with python-can's own reader."""
    import can  # noqa: imported here so the module loads without python-can
    out = []
    for msg in can.CanutilsLogReader(path):
        out.append((round(msg.timestamp * 1e6), msg.arbitration_id, bytes(msg.data)))
    return out


def estimates_of(report):
    keys = ("samples_complete", "samples_incomplete", "alpha", "params", "eps_rms_raw_rad", "eps_rms_comp_rad",
            "i_d_ripple_raw", "i_d_ripple_comp", "converged", "revolutions")
    return {k: report.get(k) for k in keys}


class CleanLog:
    """One resolver-sim log and its results through both programs, shared by the cases."""
    log = None
    report = None
    angles = None
    fit = None

    @classmethod
    def get(cls):
        if cls.log is None:
            os.makedirs(ARGS.work, exist_ok=True)
            cls.log = work("clean.log")
            sim(cls.log)
            cls.report, _, cls.angles = replay(cls.log, "clean", lcm=True)
            cls.fit = fit(cls.log)
        return cls


class VectorAsc(unittest.TestCase):
    """python-can's ASCWriter converts the candump log; resolverd and resolver-model read the ASC
    sample for sample like the original (the same frames, the same counter time)."""

    def test_asc_equals_candump(self):
        skip_or_fail_without_pycan(self)
        clean = CleanLog.get()
        asc = work("clean.asc")
        script = ("import can,sys\n"
                  "w = can.ASCWriter(sys.argv[2])\n"
                  "for m in can.CanutilsLogReader(sys.argv[1]): w.on_message_received(m)\n"
                  "w.stop()\n")
        run([PY, "-c", script, clean.log, asc])
        report, _, angles = replay(asc, "asc", lcm=True)
        self.assertEqual(report["rejects"], {}, "python-can's ASC must read without a single problem")
        self.assertEqual(report["frames_decoded"], clean.report["frames_decoded"])
        self.assertEqual(estimates_of(report), estimates_of(clean.report))
        # Sample for sample: every angle_t but its utime (python-can's block date keeps milliseconds only).
        self.assertEqual(len(angles), SAMPLES)
        strip = lambda msgs: [{k: v for k, v in m.items() if k not in ("utime", "timestamp")} for m in msgs]
        self.assertEqual(strip(angles), strip(clean.angles))
        self.assertEqual(without_notes(fit(asc)), without_notes(clean.fit))


SCOPE_TOML = """# A scope export: time as Windows FILETIME, angles in degrees, German locale.
[bench]
p_r = 3
p = 3
[input.csv]
delimiter = ";"
decimal = ","
header_lines = 5
time_column = "Time"
time_unit = "filetime"
[input.csv.columns]
rd_angle = {{ column = "R/D angle", unit = "deg" }}
ref_angle = {{ column = "Encoder", unit = "deg" }}
{extra}"""


def write_scope_csv(frames, path, bad_rows=()):
    """RESOLVER_SAMPLE's rd_angle and REFERENCE_ANGLE's ref_angle (docs/ARCHITECTURE.md §4 payloads, decoded with struct)
    as a scope export: 5 header lines, a name line, one row per sample (a sample starts with its
    RESOLVER_SAMPLE frame; the resolver-sim log holds no gaps). Returns the number of rows."""
    rows = []  # [t_us, rd_deg, ref_deg]
    for t_us, can_id, data in frames:
        if can_id == 0x100:
            # bytes 5-6: u16, 65536 counts = 360 deg electrical
            rows.append([t_us, struct.unpack_from("<H", data, 5)[0] * 360.0 / 65536.0, None])
        elif can_id == 0x102 and rows:
            # bytes 1-4: u32, 2^32 counts = 360 deg mechanical
            rows[-1][2] = struct.unpack_from("<I", data, 1)[0] * 360.0 / 4294967296.0
    lines = ["Oscilloscope export", "Instrument;DS-1234", "Channels;2", "Sample interval;500 us", "Units;deg",
             "Time;R/D angle;Encoder"]
    for k, (t_us, rd, ref) in enumerate(rows):
        ft = FILETIME_UNIX_EPOCH + t_us * 10
        a = "n/a" if k in bad_rows else ("%.9f" % rd).replace(".", ",")
        b = ("%.9f" % ref).replace(".", ",")
        lines.append(f"{ft};{a};{b}")
    with open(path, "w", encoding="ascii") as f:
        f.write("\r\n".join(lines) + "\r\n")  # written on Windows
    return len(rows)


class ScopeCsv(unittest.TestCase):
    """A scope export of the R/D angle and the reference encoder, made from the sim log by
    python-can + struct; both programs read every row as one sample, on the same clock."""

    @classmethod
    def setUpClass(cls):
        cls.skip = not have_pycan()
        if cls.skip:
            return
        cls.clean = CleanLog.get()
        cls.frames = read_candump(cls.clean.log)
        cls.csv = work("scope.csv")
        cls.rows = write_scope_csv(cls.frames, cls.csv)
        cls.config = work("scope.toml")
        with open(cls.config, "w") as f:
            f.write(SCOPE_TOML.format(extra=""))

    def setUp(self):
        if self.skip:
            skip_or_fail_without_pycan(self)

    def test_every_row_is_a_sample_in_both_programs(self):
        self.assertEqual(self.rows, SAMPLES)
        report, _, angles = replay(self.csv, "scope", "--config", self.config, lcm=True)
        self.assertEqual(report["rejects"], {})
        self.assertEqual(report["frames_seen"], SAMPLES, "health counts rows as frames")
        self.assertEqual(report["samples_complete"], SAMPLES)
        model = fit(self.csv, "--config", self.config)
        self.assertEqual(signal_rows(model, "position_error"), SAMPLES)
        # The same angles as the candump original, to far inside the R/D LSB (2 pi / 65536 = 9.6e-5 rad):
        # degrees printed with 9 decimals carry 1.7e-11 rad.
        self.assertEqual(len(angles), len(self.clean.angles))
        worst = max(abs(math.remainder(a["theta_rd"] - b["theta_rd"], 2 * math.pi))
                    for a, b in zip(angles, self.clean.angles))
        self.assertLess(worst, 1e-9)
        worst_ref = max(abs(math.remainder(a["theta_ref"] - b["theta_ref"], 2 * math.pi))
                        for a, b in zip(angles, self.clean.angles))
        self.assertLess(worst_ref, 1e-9)
        # FILETIME keeps the microseconds: utime is the candump frame time exactly.
        self.assertEqual([a["utime"] for a in angles], [b["utime"] for b in self.clean.angles])

    def test_estimates_match_the_candump_original(self):
        # Hwang's integral reads the R/D angle only (the default estimator fits every signal a log has,
        # and the export holds fewer), and time from the stamps: the FILETIME stamps are exact multiples
        # of the period, so t is the same; only the 1.7e-11 rad printing error differs.
        hwang = work("scope_hwang.toml")
        with open(hwang, "w") as f:
            f.write(SCOPE_TOML.format(extra="") + '[estimator]\nmethod = "hwang_integral"\n')
        hwang_bench = work("hwang.toml")
        with open(hwang_bench, "w") as f:
            f.write('[estimator]\nmethod = "hwang_integral"\n')
        report, _, _ = replay(self.csv, "scope_est", "--config", hwang)
        clean, _, _ = replay(self.clean.log, "clean_hwang", "--config", hwang_bench)
        self.assertTrue(report["converged"])
        self.assertAlmostEqual(report["alpha"], clean["alpha"], delta=1e-9)
        # The error statistics start when the estimate converges, at a revolution boundary; an R/D angle
        # exactly on the boundary (0 counts) read 1e-11 rad apart may put one sample on the other side.
        # One sample of N = 7200 moves an RMS by at most about 1/N of itself.
        n = SAMPLES - SAMPLE_RATE * 0.4  # the Hwang estimate converges after 0.4 s (min_revolutions = 3 at 200 r/min)
        for key in ("eps_rms_raw_rad", "eps_rms_comp_rad"):
            self.assertAlmostEqual(report[key], clean[key], delta=clean[key] / n)
        model = fit(self.csv, "--config", self.config)
        pos = [s for s in model["signals"] if s["signal"] == "position_error"][0]
        pos_clean = [s for s in self.clean.fit["signals"] if s["signal"] == "position_error"][0]
        # resolver-model fits alpha to every signal a log has: here the position error alone, in the
        # original also sin/cos and the dq currents. With the sample grid locked to the revolution the
        # 16-bit R/D quantization error repeats every revolution and biases an alpha taken from the
        # position error by up to ~0.8 % (test_replay_pipeline.py), which no std. error shows: the two
        # alphas agree within 1 %, and the position residual within 1 % of its floor (LSB / sqrt(12)).
        a = model["params"]["amplitude_imbalance.alpha"]
        b = self.clean.fit["params"]["amplitude_imbalance.alpha"]
        self.assertAlmostEqual(a["value"], b["value"], delta=0.01 * abs(b["value"]))
        self.assertAlmostEqual(pos["rms"], pos_clean["rms"], delta=0.01 * pos_clean["floor"])

    def test_bad_rows_are_counted_with_file_line_column(self):
        bad = work("scope_bad.csv")
        write_scope_csv(self.frames, bad, bad_rows=(100, 101, 5000))
        report, stderr, _ = replay(bad, "scope_bad", "--config", self.config)
        self.assertEqual(report["rejects"].get("bad_number"), 3)
        self.assertEqual(report["samples_complete"], SAMPLES - 3)
        # Line of row 100: 6 lines before the data. Column: after the 18-digit FILETIME and ';'.
        self.assertIn(f"scope_bad.csv:{6 + 100 + 1}:20: column 'R/D angle' (rd_angle): expected a number", stderr)
        self.assertEqual(report["rejects"].get("sample_gap"), 2, "two gaps found from time (rows 100-101, 5000)")
        self.assertEqual(report["rejects"].get("samples_lost"), 3)
        proc = run([f"{ARGS.bin}/resolver-model", "fit", bad, "--config", self.config])
        self.assertIn("3 malformed log lines skipped", proc.stdout)

    def test_slice_from_to(self):
        report, _, angles = replay(self.csv, "scope_slice", "--config", self.config, "--from", "1", "--to", "2.5",
                                   lcm=True)
        # [1, 2.5] s at 2 kHz: samples 2000 .. 5000. Rows before the slice are read (and counted in
        # health) to keep the clock; reading stops at the first row after it, with the 8 rows read
        # behind it ([layout] max_counter_delta: timed rows wait that long for a row out of order).
        self.assertEqual([a["sample_index"] for a in angles], list(range(2000, 5001)))
        self.assertEqual(report["samples_complete"], 5002 + 8)
        self.assertEqual(report["samples_used"], 3001)
        self.assertEqual(report["samples_outside_slice"], 2001 + 8)
        model = fit(self.csv, "--config", self.config, "--from", "1", "--to", "2.5")
        self.assertEqual(signal_rows(model, "position_error"), 3001)


ANGLE_DBC = """VERSION ""
BU_: SCOPE
BO_ 291 ANGLES: 8 SCOPE
 SG_ RdAngle : 0|32@1+ (1e-06,0) [0|360] "deg" Vector__XXX
 SG_ RefAngle : 32|32@1+ (1e-06,0) [0|360] "\xb0" Vector__XXX
CM_ SG_ 291 RefAngle "Reference encoder, mechanical; the unit is the Latin-1 degree sign.";
"""

ANGLE_TOML = """[bench]
p_r = 1
p = 4
sample_rate_hz = 2000
[layout]
dbc = "{dbc}"
counter_signal = ""
crc = "none"
bench_info_message = ""
[layout.signals]
rd_angle = "ANGLES.RdAngle"
ref_angle = "ANGLES.RefAngle"
"""


def angle_only_log(src, name):
    """`src` (a resolver-sim candump log) as the angle-only layout: (log, config)."""
    dbc = work("angles.dbc")
    with open(dbc, "w", encoding="latin-1") as f:
        f.write(ANGLE_DBC)
    cfg = work("angles.toml")
    with open(cfg, "w") as f:
        f.write(ANGLE_TOML.format(dbc=dbc))
    out = work(name)
    lines = []
    rd = None
    for t_us, can_id, data in read_candump(src):
        if can_id == 0x100:
            rd = struct.unpack_from("<H", data, 5)[0] * 360.0 / 65536.0
        elif can_id == 0x102 and rd is not None:
            ref = struct.unpack_from("<I", data, 1)[0] * 360.0 / 4294967296.0
            payload = struct.pack("<II", round(rd * 1e6) % 360_000_000, round(ref * 1e6) % 360_000_000)
            lines.append("(%d.%06d) can0 123#%s" % (t_us // 1_000_000, t_us % 1_000_000, payload.hex().upper()))
            rd = None
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")
    return out, cfg, len(lines)


class AngleOnlyLayout(unittest.TestCase):
    """A 1X resolver (p_r = 1) logged as one CAN message of two angles in degrees: no counter, no CRC,
    no BENCH_INFO. Both programs accept the layout and decode every sample the simulator made."""

    def test_angle_only_degrees_without_counter(self):
        skip_or_fail_without_pycan(self)
        os.makedirs(ARGS.work, exist_ok=True)
        src = work("p_r1.log")
        sim(src, "--p-r", "1", "--p", "4")
        out, cfg, samples = angle_only_log(src, "angles.log")
        self.assertEqual(samples, SAMPLES)
        report, stderr, _ = replay(out, "angles", "--config", cfg)
        self.assertEqual(report["rejects"], {}, stderr)
        self.assertEqual(report["samples_complete"], SAMPLES)
        self.assertEqual(report["p_r"], 1)
        model = fit(out, "--config", cfg)
        self.assertEqual(signal_rows(model, "position_error"), SAMPLES)

    def test_a_missing_pair_is_named_with_what_the_log_cannot_tell_it_from(self):
        """At p_r = 1 without sin/cos, offsets, eccentricity and K_2 all land on 1 theta and
        quadrature, K_3_q and a mechanical 2x on 2 theta: each ranks alike with the others, and the
        three best candidates are one such class. The two missing effects must still be found (a
        pair across the classes), and said with what this log cannot tell them from, never as the
        one answer. Before, the search paired only the best three (aliases of one another) and
        said "unexplained"."""
        skip_or_fail_without_pycan(self)
        os.makedirs(ARGS.work, exist_ok=True)
        src = work("pair_src.log")
        # An ideal converter (tracking_loop omega_n = 0): the sim's default loop would be a third
        # missing effect. Magnitudes of a real sensor: 8 % gain, 20 mrad, offsets of 1 %.
        run([f"{ARGS.bin}/resolver-sim", "--out", src, "--p-r", "1", "--p", "4", "--seed", "8",
             "--profile", "311.7:4,311.7-893.4:1,893.4:4",
             "--effect", "amplitude_imbalance:alpha=0.08", "--effect", "quadrature:beta=0.02",
             "--effect", "offsets:o_s=0.01,o_c=-0.006", "--effect", "tracking_loop:omega_n=0"])
        log, cfg, _ = angle_only_log(src, "pair.log")
        # Control: the true model explains this log (so the search has a pair to find).
        truth = fit(log, "--config", cfg, "--effects", "amplitude_imbalance,quadrature,offsets")
        rms = [s for s in truth["signals"] if s["signal"] == "position_error"][0]
        self.assertLessEqual(rms["rms"], 1.5 * rms["floor"], truth)
        ex = json.loads(run([f"{ARGS.bin}/resolver-model", "explain", log, "--json", "--config", cfg]).stdout)
        self.assertEqual(ex["verdict"], "missing_effect", ex["summary"])
        pair = ex["missing_pair"]
        self.assertEqual(len(pair), 2, ex["summary"])
        on_2theta = {"quadrature", "harmonics(k3_q)", "mechanical_harmonics(b2)"}
        on_1theta = {"offsets", "eccentricity", "harmonics(k2,k2_q)"}
        self.assertEqual(len(on_2theta & set(pair)), 1, ex["summary"])
        self.assertEqual(len(on_1theta & set(pair)), 1, ex["summary"])
        self.assertIn("This log cannot tell", ex["summary"])
        self.assertIn("sin/cos envelopes would tell them apart", ex["summary"])

    def test_unknown_angle_unit_is_an_error_naming_the_signal(self):
        os.makedirs(ARGS.work, exist_ok=True)
        dbc = work("angles_grad.dbc")
        with open(dbc, "w", encoding="latin-1") as f:
            f.write(ANGLE_DBC.replace('"deg"', '"grad"'))
        cfg = work("angles_grad.toml")
        with open(cfg, "w") as f:
            f.write(ANGLE_TOML.format(dbc=dbc))
        log = CleanLog.get().log
        d = run([f"{ARGS.bin}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://",
                 "--config", cfg], ok=False)
        self.assertEqual(d.returncode, 2, d.stderr)
        self.assertIn("role 'rd_angle' (ANGLES.RdAngle): unit \"grad\" is unknown", d.stderr)
        self.assertIn("rad, deg", d.stderr)
        m = run([f"{ARGS.bin}/resolver-model", "fit", log, "--config", cfg], ok=False)
        self.assertNotEqual(m.returncode, 0)
        self.assertIn("ANGLES.RdAngle", m.stderr)


def shifted_log(src, dst, from_fraction, dt_us):
    """The log with every line from `from_fraction` of it on moved by dt_us."""
    with open(src) as f:
        lines = f.read().splitlines()
    start = int(len(lines) * from_fraction)
    out = []
    for i, line in enumerate(lines):
        if i >= start:
            t, rest = line[1:].split(")", 1)
            us = round(float(t) * 1e6) + dt_us
            line = "(%d.%06d)%s" % (us // 1_000_000, us % 1_000_000, rest)
        out.append(line)
    with open(dst, "w") as f:
        f.write("\n".join(out) + "\n")


class OddTime(unittest.TestCase):
    """Issue 16.3: a step back, a jump forward, two logs appended: counted, re-anchored, every sample
    used, and the estimates of the clean log (identical where the samples are the same)."""

    def check_same_as_clean(self, log, name, reason):
        clean = CleanLog.get()
        report, stderr, _ = replay(log, name)
        self.assertEqual(report["rejects"], {reason: 1}, stderr)
        self.assertEqual(estimates_of(report), estimates_of(clean.report))
        model = fit(log)
        self.assertEqual(without_notes(model), without_notes(clean.fit))
        self.assertTrue(any(reason in n for n in model["notes"]), model["notes"])

    def test_step_back(self):
        log = work("step_back.log")
        shifted_log(CleanLog.get().log, log, 0.4, -1_000_000)
        self.check_same_as_clean(log, "step_back", "timestamp_step_back")

    def test_jump_forward_a_day(self):
        log = work("jump.log")
        shifted_log(CleanLog.get().log, log, 0.6, 86_400_000_000)
        self.check_same_as_clean(log, "jump", "timestamp_jump")

    def test_two_logs_appended(self):
        clean = CleanLog.get()
        log = work("appended.log")
        with open(clean.log) as f:
            text = f.read()
        with open(log, "w") as f:
            f.write(text + text)  # the second recording starts at the same time, counter 0 again
        report, stderr, _ = replay(log, "appended")
        self.assertEqual(report["samples_complete"], 2 * SAMPLES, stderr)
        self.assertEqual(report["rejects"].get("timestamp_step_back"), 1)
        self.assertEqual(set(report["rejects"]) - {"timestamp_step_back", "counter_wrong_sequence"}, set())
        # Twice the same revolutions: Hwang's integral averages the same per-revolution values, except the one
        # revolution across the join, which the speed check rejects or which adds one value of the same size.
        # Its alpha is within the clean log's own spread (the estimator's std. error, 1e-6 here at most).
        self.assertTrue(report["converged"])
        self.assertAlmostEqual(report["alpha"], clean.report["alpha"], delta=max(1e-6, 10 * clean.report["alpha_spread"]))
        model = fit(log)
        self.assertEqual(signal_rows(model, "position_error"), 2 * SAMPLES)
        a = model["params"]["amplitude_imbalance.alpha"]
        b = clean.fit["params"]["amplitude_imbalance.alpha"]
        # Twice the data: the std. error falls by sqrt(2); the value stays within the clean one's std. error.
        self.assertAlmostEqual(a["value"], b["value"], delta=3 * b["stderr"])


class MissingSignals(unittest.TestCase):
    """A log without the reference encoder: both programs run on what is there and say what is not."""

    def test_no_reference(self):
        os.makedirs(ARGS.work, exist_ok=True)
        log = work("no_ref.log")
        sim(log, "--no-reference")
        report, _, _ = replay(log, "no_ref")
        self.assertEqual(report["samples_complete"], SAMPLES)
        self.assertEqual(report["rejects"], {})
        model = fit(log)
        self.assertFalse(model["reference"])


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
