#!/usr/bin/python3
"""Issue 25 ("Trust": no verdict from garbage, nothing lost silently) through the
real programs: inputs that used to be read as wrong numbers, hang or crash, and
now are refused or counted with a message naming the file, line, column or option.

  DecimalCommas   a European export (decimal commas) read with a ',' delimiter:
                  "0,0010,359,9451,0,00000" was read as 0 s, 10 deg, 359 deg with
                  nothing rejected; now refused up front (exit 2, file:line:column)
                  when the first row does not line up with the column names, and a
                  later row that does not is counted as extra_fields
  AbsurdValues    1e300 deg in a CSV angle column was wrapped into a "valid" angle;
                  now counted as absurd_value naming file:line:column
  CoarseTime      a 1 kHz export whose time column is rounded to 0.01 s: ten rows
                  per time, "0 moving, 5500 at standstill"; now refused (exit 2)
                  naming the column, its resolution and the row rate, and the fix
                  it suggests (row_rate_hz) gives the unrounded export's fit
  ConfigRanges    [estimator] max_order = 2000 replayed for minutes, 2147483647 ended
                  in "std::bad_alloc"; now exit 2 naming the file, line, option and
                  its range; likewise [bench] sample_rate_hz = 1e-300 (was taken:
                  "0 moving over 3.2e+303 s"), 0.001, 1e300, -5, inf; and [bench]
                  p_r = 2147483647 (was: "converged over 2856153251 revolutions")
  CoarseTable     resolver-model export --points 8 of a 10 % imbalance: a table with
                  0.065 rad interpolation error (2160x the noise floor) written with
                  no warning; now a stderr warning with the error, the floor and the
                  --points that reaches it (the export still succeeds)
  CustomTerms     a [[model.custom]] term 1/(theta-theta) was reported as "not
                  separable"; now refused at load (exit 2) naming the file, block and
                  term and that it is inf everywhere; a term non-finite on this log's
                  motion only (sqrt(-omega) turning forward) is named at the fit
  LoopJoints      resolverd --replay without --once loops the log; a clean 200 -> 1000
                  r/min ramp raised "signal fault outliers started ... 7 impulsive
                  sample(s)" and "... ended 0.000 s (sample 0)" at every pass's joint;
                  the joint is no fault now (the log's own faults still show per pass)
  MixedInterfaces a candump log of two benches (can0, and can1 whose counter runs 100
                  periods ahead) was joined into one stream: "the rotor hardly moves"
                  over 501 s of a 2 s log; now can0 (the first interface with a bench
                  frame) is read, can1's frames are counted per interface
                  (other_interface) and the message says how to read can1 (grep)
  ShuffledFrames  frames delayed by up to 3 ms (a USB-CAN adapter's buffering): "13077
                  frames lost" of 12020 in the log, 601 s; now reordered, nothing lost,
                  and with frames deleted the count lost is the count deleted
  LateFrame       one frame after the next period's: angle_t's sample_index jumped
                  11 -> 268 with no gap counted; now it steps by one
  SwappedRows     two neighbouring CSV rows in the wrong time order: "samples_lost=2"
                  (and a step back); now rows_reordered = 1 naming both lines

Every bad input is made from tools/examples/scope_sweep.csv (a real-looking scope
export, semicolons and decimal commas), so each case has its clean control.

  test_garbage_inputs.py --bin BUILD/bin --repo SOURCE --work DIR [unittest arguments]
"""
import argparse
import json
import os
import random
import signal
import time
import subprocess
import sys
import unittest

ARGS = None
USAGE = 2  # README: 2 usage or configuration error

SWEEP_TOML = """[bench]
p_r = 1
p = 4
reference_aligned = true
[input.csv]
%s
time_column = "Time [s]"
time_unit = "s"
[input.csv.columns]
rd_angle = { column = "R/D angle [deg]", unit = "deg" }
ref_angle = { column = "Encoder [deg]", unit = "deg" }
"""


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)


def work(name):
    return os.path.join(ARGS.work, name)


def write(name, text):
    path = work(name)
    with open(path, "w") as f:
        f.write(text)
    return path


def sweep_rows():
    """The example export's column-name line and data rows (semicolons, decimal commas)."""
    with open(os.path.join(ARGS.repo, "tools", "examples", "scope_sweep.csv")) as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Time [s]"))
    return lines[start], [line for line in lines[start + 1:] if line.strip()]


def replay(csv, config, name, expect_rc=0):
    report = work(name + ".json")
    if os.path.exists(report):
        os.remove(report)
    proc = run([os.path.join(ARGS.bin, "resolverd"), "--replay", csv, "--config", config, "--once", "--fast",
                "--lcm", "file://" + work(name + ".lcmlog") + "?mode=w", "--report", report])
    if proc.returncode != expect_rc:
        raise AssertionError(f"resolverd exited {proc.returncode}, expected {expect_rc}:\n{proc.stderr[-3000:]}")
    if expect_rc != 0:
        return None, proc.stderr
    with open(report) as f:
        return json.load(f), proc.stderr


def model(*args):
    return run([os.path.join(ARGS.bin, "resolver-model"), *args])


class DecimalCommas(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        names, rows = sweep_rows()
        cls.rows = len(rows)
        # The same export written with ',' as the delimiter, decimal commas kept.
        cls.comma = write("eu_comma.csv", "\n".join([names.replace(";", ",")] + [r.replace(";", ",") for r in rows]) + "\n")
        # Its first rows happen to have whole numbers (3 fields): the rest do not.
        whole = ["%d,359,0" % k for k in range(3)]
        cls.late = write("eu_late.csv",
                         "\n".join([names.replace(";", ",")] + whole + [r.replace(";", ",") for r in rows[3:]]) + "\n")
        cls.auto = write("auto.toml", SWEEP_TOML % "")
        cls.right = write("semicolon.toml", SWEEP_TOML % 'delimiter = ";"\ndecimal = ","')
        cls.semicolon = write("eu_semicolon.csv", "\n".join([names] + rows) + "\n")

    def test_refused_up_front_naming_file_line_and_the_fix(self):
        for prog in ([os.path.join(ARGS.bin, "resolverd"), "--replay", self.comma, "--once", "--fast"],
                     [os.path.join(ARGS.bin, "resolver-model"), "explain", self.comma]):
            proc = run(prog + ["--config", self.auto])
            self.assertEqual(proc.returncode, USAGE, proc.stderr)
            self.assertIn("eu_comma.csv:2:12: the first data row does not match [input.csv]", proc.stderr)
            self.assertIn("the row has 6 fields, the column-name line has 3", proc.stderr)
            self.assertIn('decimal = ","', proc.stderr)

    def test_later_rows_that_do_not_line_up_are_counted_not_misread(self):
        report, err = replay(self.late, self.auto, "late")
        self.assertEqual(report["rejects"], {"extra_fields": self.rows - 3})
        self.assertEqual(report["samples_complete"], 3)
        self.assertIn("eu_late.csv:5:12: the row has 6 fields", err)

    def test_a_point_expected_where_the_export_has_commas_says_so(self):
        _, err = replay(self.semicolon, self.auto, "semicolon_point", expect_rc=1)  # 1: no sample decoded
        self.assertIn("eu_semicolon.csv:2:1: column 'Time [s]' (time): expected a number with '.' as decimal mark, "
                      "found '0,0000' (a ',' decimal mark: set [input.csv] decimal = \",\")", err)

    def test_control_the_right_config_reads_every_row(self):
        report, _ = replay(self.semicolon, self.right, "semicolon_right")
        self.assertEqual(report["rejects"], {})
        self.assertEqual(report["samples_complete"], self.rows)


class AbsurdValues(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        names, rows = sweep_rows()
        cls.rows = len(rows)
        cls.config = write("absurd.toml", SWEEP_TOML % 'delimiter = ";"\ndecimal = ","')
        bad = list(rows)
        for k in (100, 200):  # data rows 100 and 200: lines 102 and 202
            t, _, enc = bad[k].split(";")
            bad[k] = ";".join([t, "1e300", enc])
        t, rd, _ = bad[300].split(";")
        bad[300] = ";".join([t, rd, "-1,5e40"])
        cls.csv = write("absurd.csv", "\n".join([names] + bad) + "\n")

    def test_counted_naming_file_line_column(self):
        report, err = replay(self.csv, self.config, "absurd")
        self.assertEqual(report["rejects"].get("absurd_value"), 3, report["rejects"])
        self.assertEqual(report["samples_complete"], self.rows - 3)
        self.assertIn("absurd.csv:102:8: column 'R/D angle [deg]' (rd_angle): '1e300'", err)
        self.assertIn("absurd.csv:302:", err)
        self.assertIn("(ref_angle): '-1,5e40'", err)

    def test_resolver_model_skips_them(self):
        proc = model("fit", self.csv, "--config", self.config)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("3 malformed log lines skipped", proc.stdout)
        # By reason, with the first line, as resolverd prints them.
        self.assertIn("note: absurd_value: 3 line(s) not read, the first: " + work("absurd.csv") +
                      ":102:8: column 'R/D angle [deg]' (rd_angle): '1e300'", proc.stdout)


class CoarseTime(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        names, rows = sweep_rows()
        rounded = []
        for r in rows:
            t, rd, enc = r.split(";")
            rounded.append(";".join([("%.2f" % float(t.replace(",", "."))).replace(".", ","), rd, enc]))
        cls.csv = write("rounded.csv", "\n".join([names] + rounded) + "\n")
        cls.exact = write("exact.csv", "\n".join([names] + rows) + "\n")
        cls.config = write("coarse.toml", SWEEP_TOML % 'delimiter = ";"\ndecimal = ","')
        cls.by_rate = write("by_rate.toml", (SWEEP_TOML % 'delimiter = ";"\ndecimal = ","\nrow_rate_hz = 1000')
                            .replace('time_column = "Time [s]"\ntime_unit = "s"\n', ""))

    def test_refused_naming_the_column_its_resolution_and_the_rate(self):
        for prog in ([os.path.join(ARGS.bin, "resolverd"), "--replay", self.csv, "--once", "--fast"],
                     [os.path.join(ARGS.bin, "resolver-model"), "explain", self.csv]):
            proc = run(prog + ["--config", self.config])
            self.assertEqual(proc.returncode, USAGE, proc.stderr)
            self.assertIn("rounded.csv:2-202: column 'Time [s]' (time): 180 of the first 201 rows repeat the previous "
                          "row's time: the column resolves only 0.01 s", proc.stderr)
            self.assertIn("about 1000 Hz", proc.stderr)
            self.assertIn("row_rate_hz", proc.stderr)
            self.assertNotIn("0 moving", proc.stderr)

    def test_the_suggested_row_rate_fits_like_the_exact_times(self):
        by_rate = model("fit", self.csv, "--config", self.by_rate, "--json")
        exact = model("fit", self.exact, "--config", self.config, "--json")
        self.assertEqual(by_rate.returncode, 0, by_rate.stderr)
        self.assertEqual(exact.returncode, 0, exact.stderr)
        a, b = json.loads(by_rate.stdout), json.loads(exact.stdout)
        self.assertEqual(a["verdict"], b["verdict"])
        self.assertEqual(a["params"], b["params"])


_SIM = None


def sim_log():
    """A 2 s resolver-sim log of the default bench, made once."""
    global _SIM
    if _SIM is None:
        _SIM = work("sim.log")
        proc = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", _SIM, "--duration", "2"])
        if proc.returncode != 0:
            raise AssertionError(proc.stderr)
    return _SIM


def refused(test, config_text, name, *fragments):
    """resolverd and resolver-model refuse `config_text` with exit 2 within 30 s, saying every fragment."""
    config = write(name + ".toml", config_text)
    for prog in ([os.path.join(ARGS.bin, "resolverd"), "--replay", sim_log(), "--once", "--fast",
                  "--lcm", "file://" + work(name + ".lcmlog") + "?mode=w"],
                 [os.path.join(ARGS.bin, "resolver-model"), "fit", sim_log()]):
        try:
            proc = run(prog + ["--config", config], timeout=30)
        except subprocess.TimeoutExpired:
            test.fail(f"{os.path.basename(prog[0])} still running after 30 s with {config_text!r}")
        test.assertEqual(proc.returncode, USAGE, f"{prog[0]}: {proc.stderr[-2000:]}")
        for fragment in fragments:
            test.assertIn(fragment, proc.stderr)


class ConfigRanges(unittest.TestCase):
    def test_max_order_beyond_its_range(self):
        for v in ("2000", "2147483647", "0"):
            refused(self, '[estimator]\nmethod = "fourier_reference"\nmax_order = %s\n' % v, "max_order_" + v,
                    ":3: [estimator] max_order must be 1..19", "got " + v)

    def test_absurd_sample_rates(self):
        for v in ("1e-300", "0.001", "1e300", "-5", "inf"):
            refused(self, "[bench]\np_r = 3\nsample_rate_hz = %s\n" % v, "rate_" + v,
                    ":3: [bench] sample_rate_hz must be 1 .. 1e6 Hz (0 = take it from BENCH_INFO), got ")

    def test_absurd_pole_pairs(self):
        refused(self, "[bench]\np_r = 2147483647\n", "p_r_huge",
                ":2: [bench] p_r must be 1..255 (resolver pole pairs, as BENCH_INFO carries them), got 2147483647")
        refused(self, "[bench]\np = 1000\n", "p_huge", ":2: [bench] p must be 1..255 (motor pole pairs")

    def test_control_max_order_at_its_limit_runs(self):
        config = write("max_order_19.toml", '[estimator]\nmethod = "fourier_reference"\nmax_order = 19\n')
        proc = run([os.path.join(ARGS.bin, "resolverd"), "--replay", sim_log(), "--once", "--fast", "--config", config,
                    "--lcm", "file://" + work("max_order_19.lcmlog") + "?mode=w"], timeout=60)
        self.assertEqual(proc.returncode, 0, proc.stderr[-2000:])


class CoarseTable(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.log = work("alpha10.log")
        proc = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", cls.log, "--duration", "3",
                    "-e", "amplitude_imbalance:alpha=0.1"])
        if proc.returncode != 0:
            raise AssertionError(proc.stderr)

    def export(self, points):
        out = work("table_%d.csv" % points)
        proc = model("export", self.log, "--points", str(points), "--out", out)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertTrue(os.path.getsize(out) > 0)
        return proc.stderr

    def test_warns_with_the_error_the_floor_and_the_points_that_reach_it(self):
        err = self.export(8)
        self.assertIn("resolver-model: warning: --points 8: the table's interpolation error 0.065 rad is ", err)
        self.assertIn("the model's noise floor", err)
        suggested = int(err.split("; --points ")[1].split()[0])
        self.assertNotIn("warning", self.export(suggested))

    def test_control_the_default_points_do_not_warn(self):
        self.assertNotIn("warning", self.export(1024))


CUSTOM = """[model]
effects = ["amplitude_imbalance", "broken"]
[[model.custom]]
name = "broken"
signal = "position_error"
terms = ["%s"]
"""


class CustomTerms(unittest.TestCase):
    def test_a_term_infinite_everywhere_is_refused_at_load(self):
        refused(self, CUSTOM % "1/(theta-theta)", "div0",
                "div0.toml:3 [[model.custom]] #1 custom effect 'broken', term 1 \"1/(theta-theta)\": evaluates to inf "
                "at every angle, speed and time tried", "division by zero")

    def test_a_term_not_finite_on_this_motion_is_named_at_the_fit(self):
        config = write("sqrt.toml", CUSTOM % "sqrt(-omega)")
        proc = model("fit", sim_log(), "--config", config)
        self.assertEqual(proc.returncode, 1, proc.stderr)  # 1: nothing in this log to fit it with
        self.assertIn("sqrt.toml:3 [[model.custom]] #1 custom effect 'broken', term 1 \"sqrt(-omega)\" is not finite "
                      "on 4000 of this log's 4000 rows (e.g. nan at theta = ", proc.stderr)
        self.assertNotIn("not separable", proc.stderr)

    def test_control_a_finite_term_fits(self):
        config = write("finite.toml", CUSTOM % "t*cos(theta)")
        proc = model("fit", sim_log(), "--config", config)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("broken.c1", proc.stdout)


class LoopJoints(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.log = work("ramp.log")
        proc = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", cls.log, "--profile", "200-1000:2"])
        if proc.returncode != 0:
            raise AssertionError(proc.stderr)

    def replay(self, name, *extra):
        report = work(name + ".json")
        if os.path.exists(report):
            os.remove(report)
        cmd = [os.path.join(ARGS.bin, "resolverd"), "--replay", self.log, "--fast", "--report", report,
               "--lcm", "file://" + work(name + ".lcmlog") + "?mode=w", *extra]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace")
        if "--once" not in extra:
            time.sleep(1.5)
            proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 0, err[-2000:])
        with open(report) as f:
            return json.load(f), err

    def test_the_joint_between_passes_is_no_fault(self):
        once, _ = self.replay("ramp_once", "--once")
        looped, err = self.replay("ramp_loop")
        passes = looped["samples_complete"] / once["samples_complete"]
        self.assertGreater(passes, 3.0)
        faults = {k: v["samples"] for k, v in looped["signal_health"]["faults"].items() if v["samples"]}
        self.assertEqual(faults, {}, "%.1f passes" % passes)
        self.assertNotIn("signal fault", err)

    def test_control_one_pass_is_clean(self):
        once, err = self.replay("ramp_once", "--once")
        self.assertEqual({k: v["samples"] for k, v in once["signal_health"]["faults"].items() if v["samples"]}, {})
        self.assertNotIn("signal fault", err)


def candump_frames(path):
    """(time [us], interface, frame) of every line of a candump -l log."""
    out = []
    with open(path) as f:
        for line in f:
            t, iface, frame = line.split()
            out.append((round(float(t[1:-1]) * 1e6), iface, frame))
    return out


def write_candump(name, frames):
    return write(name, "".join("(%d.%06d) %s %s\n" % (t // 1_000_000, t % 1_000_000, i, fr) for t, i, fr in frames))


def simulate(name, *args):
    path = work(name)
    proc = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", path, *args])
    if proc.returncode != 0:
        raise AssertionError(proc.stderr)
    return path


def replay_log(log, name, *extra):
    """resolverd --replay LOG into NAME.lcmlog: the --report JSON and stderr."""
    report = work(name + ".json")
    if os.path.exists(report):
        os.remove(report)
    proc = run([os.path.join(ARGS.bin, "resolverd"), "--replay", log, "--once", "--fast", "--report", report,
                "--lcm", "file://" + work(name + ".lcmlog") + "?mode=w", *extra])
    if proc.returncode != 0:
        raise AssertionError(f"resolverd exited {proc.returncode}:\n{proc.stderr[-3000:]}")
    with open(report) as f:
        return json.load(f), proc.stderr


def fit_params(log, *extra):
    proc = model("fit", log, "--json", *extra)
    if proc.returncode != 0:
        raise AssertionError(proc.stderr)
    return json.loads(proc.stdout)["params"]


class MixedInterfaces(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.can0 = candump_frames(sim_log())
        # A second bench on can1 (600 r/min), started 100 periods (50 ms) earlier: its counter runs 100 ahead.
        other = candump_frames(simulate("bench_can1.log", "--duration", "2", "--rpm", "600", "--seed", "7",
                                        "--iface", "can1"))
        t0 = other[0][0]
        cls.can1 = [(t - 50_000 + 130, i, fr) for t, i, fr in other if t >= t0 + 50_000]
        cls.log = write_candump("two_benches.log", sorted(cls.can0 + cls.can1, key=lambda f: f[0]))
        # The same frames seen on two interfaces.
        twice = []
        for t, _, fr in cls.can0:
            twice += [(t, "can0", fr), (t + 10, "can1", fr)]
        cls.twice = write_candump("same_frames_twice.log", twice)

    def test_only_the_first_interface_is_read_and_the_other_counted(self):
        report, err = replay_log(self.log, "two_benches")
        n1 = len(self.can1)
        self.assertEqual(report["rejects"], {"other_interface": n1})
        self.assertEqual(report["samples_complete"], 4000)
        self.assertLess(report["span_s"], 2.01)  # was 501.2 s, "the rotor hardly moves"
        self.assertEqual(report["interfaces"], [
            {"name": "can0", "frames": len(self.can0), "left_out": 0, "read": True},
            {"name": "can1", "frames": n1, "left_out": n1, "read": False}])
        self.assertIn("on can1: the log holds frames of more than one CAN interface; only can0's are read (the first "
                      "interface with a frame of the layout), can1's are counted as other_interface and left out", err)
        self.assertIn("To read can1 instead, replay a log of its lines only (candump -l: grep ' can1 ' LOG > can1.log",
                      err)
        self.assertNotIn("hardly moves", err)

    def test_resolver_model_names_the_interfaces(self):
        proc = model("explain", self.log)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("covers: 4000 of 4000 samples fitted", proc.stdout)
        self.assertIn("note: the log holds frames of 2 CAN interfaces: can0 %d frames (read), can1 %d frames (%d left "
                      "out: other_interface)" % (len(self.can0), len(self.can1), len(self.can1)), proc.stdout)

    def test_the_grep_it_suggests_reads_the_other_bench(self):
        with open(self.log) as f:
            only = write("can1.log", "".join(line for line in f if " can1 " in line))
        report, err = replay_log(only, "can1_only")
        self.assertEqual(report["rejects"], {})
        self.assertEqual(report["samples_complete"], sum(not f[2].startswith("1F0") for f in self.can1) // 3)
        self.assertNotIn("interface", err)
        proc = model("explain", only)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        self.assertIn("600 r/min", proc.stdout)

    def test_the_same_frames_on_two_interfaces(self):
        report, _ = replay_log(self.twice, "twice")
        self.assertEqual(report["rejects"], {"other_interface": len(self.can0)})  # was counter_repeated
        self.assertEqual(report["samples_complete"], 4000)


class ShuffledFrames(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.clean = sim_log()
        frames = candump_frames(cls.clean)
        rng = random.Random(25)
        # Each frame arrives up to 3 ms (6 periods) late; the log holds the arrival order and time.
        cls.log = write_candump("shuffled.log", sorted(((t + rng.randrange(3000), i, fr) for t, i, fr in frames),
                                                       key=lambda f: f[0]))
        kept = []
        cls.deleted = 0
        for n, f in enumerate(frames):
            if not f[2].startswith("1F0") and 100 < n < len(frames) - 100 and rng.random() < 0.01:
                cls.deleted += 1  # lost on the bus
            else:
                kept.append((f[0] + rng.randrange(3000), f[1], f[2]))
        cls.lossy = write_candump("shuffled_lossy.log", sorted(kept, key=lambda f: f[0]))

    def test_reordered_frames_are_not_lost(self):
        report, err = replay_log(self.log, "shuffled")
        self.assertEqual(set(report["rejects"]), {"frames_reordered"})  # was frames_lost 13077 of 12020 frames
        self.assertGreater(report["rejects"]["frames_reordered"], 1000)
        self.assertEqual(report["samples_complete"], 4000)
        self.assertEqual(report["samples_incomplete"], 0)
        self.assertLess(report["span_s"], 2.01)  # was 602 s
        self.assertIn("came after a frame of counter", err)
        self.assertIn("reordered, joined into its own sample (not lost)", err)

    def test_lost_is_what_is_missing(self):
        report, _ = replay_log(self.lossy, "shuffled_lossy")
        self.assertGreater(self.deleted, 50)
        self.assertEqual(report["rejects"]["frames_lost"], self.deleted)
        self.assertEqual(report["rejects"]["sample_incomplete"], report["samples_incomplete"])
        self.assertNotIn("counter_wrong_sequence", report["rejects"])
        self.assertLess(report["span_s"], 2.01)

    def test_resolver_model_fits_what_the_clean_log_gives(self):
        self.assertEqual(fit_params(self.log), fit_params(self.clean))


class LateFrame(unittest.TestCase):
    def test_the_sample_index_steps_by_one(self):
        frames = candump_frames(sim_log())
        late = next(n for n, f in enumerate(frames) if f[2].startswith("102#0A"))  # period 10's REFERENCE_ANGLE
        frame = frames.pop(late)
        frames.insert(next(n for n, f in enumerate(frames) if f[2].startswith("102#0B")) + 1, frame)
        report, _ = replay_log(write_candump("late_frame.log", frames), "late_frame")
        proc = run([os.path.join(ARGS.bin, "resolver-echo"), "--log", work("late_frame.lcmlog"), "--channel",
                    "RESOLVER_ANGLE"])
        index = [json.loads(line)["sample_index"] for line in proc.stdout.splitlines() if line.strip()]
        jumps = [(a, b) for a, b in zip(index, index[1:]) if b - a != 1]
        self.assertEqual(jumps, [], "was [(11, 268)] with no gap counted")
        self.assertEqual(len(index), 4000)
        self.assertEqual(report["rejects"], {"frames_reordered": 1})


class SwappedRows(unittest.TestCase):
    def test_counted_as_reordered_with_both_lines(self):
        names, rows = sweep_rows()
        rows[999], rows[1000] = rows[1000], rows[999]  # data rows 999 and 1000: lines 1001 and 1002
        csv = write("swapped.csv", "\n".join([names] + rows) + "\n")
        clean = write("unswapped.csv", "\n".join([names] + sweep_rows()[1]) + "\n")
        config = write("swapped.toml", SWEEP_TOML % 'delimiter = ";"\ndecimal = ","')
        report, err = replay(csv, config, "swapped")
        self.assertEqual(report["rejects"], {"rows_reordered": 1})  # was sample_gap 2, samples_lost 2, step back 1
        self.assertEqual(report["samples_complete"], len(rows))
        self.assertIn("line 1002: row at (0.999000) comes before line 1001's (1.000000) in time: rows out of order, "
                      "used in time order (not lost) [rows_reordered]", err)
        self.assertEqual(fit_params(csv, "--config", config), fit_params(clean, "--config", config))


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--repo", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
