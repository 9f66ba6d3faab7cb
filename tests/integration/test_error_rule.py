#!/usr/bin/python3
"""The one error rule (issue 22 item 3, docs/ARCHITECTURE.md §9): each library error
that used to come back as a value (a variant, an optional message, an out-parameter)
is now a typed exception, and the program's one mapping gives it its documented exit
code and one line "PROGRAM: WHERE: WHAT" (README: exit codes). Each case runs the
real program:

  BadDbc        a [layout] dbc with a syntax error: resolverd exits 2 naming the DBC
                file and line (was parse_dbc's variant, mapped by hand in pipeline.cpp)
  LockedStateDir  a --state-dir another process holds the lock of: resolverd exits 3
                naming the directory and the holder's pid (was StateDirLock::acquire's
                out-parameter, printed and mapped by hand in main)
  Unreadable    a [layout] dbc that is not there: resolverd exits 3 naming the config
                and the DBC (was exit_code::unreadable's optional message, mapped by
                hand in every main)
  CsvColumns    a CSV export without a column [input.csv.columns] names: resolverd and
                resolver-model exit 2 naming the file, its column-name line and the
                option (was RowDecoder::bind's optional message)
  CsvTime       a time column coarser than the rows: exit 2 naming the file and the
                lines checked (was RowDecoder::check_time_resolution's optional message)
  Unloggable    resolver-sim --iface with a blank: exit 2 naming the log and the line the
                first frame would have taken (was check_loggable's optional message,
                wrapped by hand in a std::invalid_argument)
  BadProfile    resolver-sim --profile with a bad segment: exit 2 naming the option and
                the segment (was parse_speed_profile's optional message)
  LcmUrl        resolver-echo --lcm with a URL LCM cannot open: exit 3 naming the option
                and the URL (was LiveEchoResult::error, printed by hand in main)
  EchoMapping   resolver-echo's errors its main caught and mapped by hand: a bad .lcm
                in --types (exit 2, file and line), a bad --channel regex (exit 2),
                --csv into a folder that cannot be made (exit 3, "--csv: cannot write")
  ArgumentChecks  the programs' own argument checks (were printed and returned by hand
                in each main): resolverd and resolver-model --to before --from,
                resolverd with nothing to read, resolver-echo without --log or --lcm
                and with an unknown --type, resolver-model export-data without --csv or
                --mat, fleet's MANIFEST / --out / --summarize: exit 2 (a --summarize
                that is not a folder 3) and one line "PROGRAM: [OPTION: ]MESSAGE"

  test_error_rule.py --bin BUILD/bin --work DIR [unittest arguments]
"""
import argparse
import fcntl
import os
import subprocess
import sys
import unittest

ARGS = None
USAGE, IO = 2, 3  # README: 2 usage or configuration error, 3 I/O error


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)


def work(name):
    return os.path.join(ARGS.work, name)


def write(name, text):
    path = work(name)
    with open(path, "w") as f:
        f.write(text)
    return path


_LOG = None


def sim_log():
    """A short resolver-sim candump log, made once."""
    global _LOG
    if _LOG is None:
        _LOG = work("rule.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", _LOG, "--duration", "0.5", "--seed", "5"])
        if p.returncode != 0:
            raise AssertionError(f"resolver-sim failed ({p.returncode}): {p.stderr}")
    return _LOG


def resolverd(*extra):
    return run([f"{ARGS.bin}/resolverd", "--replay", sim_log(), "--once", "--fast", "--quiet", "--lcm", "memq://",
                *extra])


class BadDbc(unittest.TestCase):
    def test_syntax_error_names_file_and_line(self):
        dbc = write("broken.dbc", 'VERSION ""\n\nBO_ 256 RESOLVER_SAMPLE 8 RD\n')  # no ':' after the name
        cfg = write("broken_dbc.toml", f'[layout]\ndbc = "{dbc}"\n')
        p = resolverd("--config", cfg)
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertEqual(p.stderr.count("\n"), 1, p.stderr)
        self.assertRegex(p.stderr, rf"^resolverd: {dbc}:3: expected ':'")

    def test_control_the_bundled_dbc_copied_is_read(self):
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        with open(os.path.join(root, "proto", "resolver_bench.dbc")) as f:
            dbc = write("copy.dbc", f.read())
        cfg = write("copy_dbc.toml", f'[layout]\ndbc = "{dbc}"\n')
        p = resolverd("--config", cfg)
        self.assertEqual(p.returncode, 0, p.stderr)


class LockedStateDir(unittest.TestCase):
    def test_a_held_lock_is_exit_3_naming_the_holder(self):
        state = work("locked_state")
        os.makedirs(state, exist_ok=True)
        with open(os.path.join(state, "resolverd.lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)  # flock(2), as resolverd takes it
            lock.write("4242\n")
            lock.flush()
            p = resolverd("--state-dir", state)
        self.assertEqual(p.returncode, IO, p.stderr)
        self.assertEqual(p.stderr.count("\n"), 1, p.stderr)
        self.assertRegex(p.stderr, rf"^resolverd: cannot use --state-dir {state}: it is in use by another resolverd, "
                                   r"pid 4242 ")

    def test_control_the_released_lock_is_taken(self):
        state = work("free_state")
        os.makedirs(state, exist_ok=True)
        p = resolverd("--state-dir", state)
        self.assertEqual(p.returncode, 0, p.stderr)


class Unreadable(unittest.TestCase):
    def test_missing_dbc_names_the_config_and_the_file(self):
        dbc = work("absent.dbc")
        cfg = write("absent_dbc.toml", f'[layout]\ndbc = "{dbc}"\n')
        p = resolverd("--config", cfg)
        self.assertEqual(p.returncode, IO, p.stderr)
        self.assertEqual(p.stderr, f"resolverd: {cfg}: cannot read [layout] dbc {dbc}: No such file or directory\n")


CSV_TOML = """[bench]
p_r = 1
p = 4
[input.csv]
delimiter = ","
time_column = "t"
time_unit = "s"
[input.csv.columns]
rd_angle = { column = "%s", unit = "deg" }
"""


def csv_export(name, time_format, rows=300, rate_hz=1000.0):
    """A CSV export "t,rd" of a turning rotor, one row every 1/rate_hz s."""
    lines = ["t,rd"] + [(time_format + ",%.3f") % (k / rate_hz, (k * 3.6) % 360) for k in range(rows)]
    return write(name, "\n".join(lines) + "\n")


def both_programs(log, cfg):
    """resolverd --replay and resolver-model fit on `log` with `cfg`: their results."""
    return (resolverd_on(log, "--config", cfg),
            run([f"{ARGS.bin}/resolver-model", "fit", log, "--config", cfg]))


def resolverd_on(log, *extra):
    return run([f"{ARGS.bin}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", *extra])


class CsvColumns(unittest.TestCase):
    def test_missing_column_names_file_line_and_option(self):
        log = csv_export("columns.csv", "%.6f")
        cfg = write("columns.toml", CSV_TOML % "Resolver")
        for p in both_programs(log, cfg):
            self.assertEqual(p.returncode, USAGE, p.stderr)
            self.assertIn(f"{log}:1: [input.csv.columns]: rd_angle: no column named 'Resolver' "
                          "(the columns are 't', 'rd')", p.stderr)

    def test_control_the_right_name_is_read(self):
        log = csv_export("columns_ok.csv", "%.6f")
        cfg = write("columns_ok.toml", CSV_TOML % "rd")
        p = resolverd_on(log, "--config", cfg)
        self.assertEqual(p.returncode, 0, p.stderr)


class CsvTime(unittest.TestCase):
    def test_coarse_time_column_names_file_and_lines(self):
        log = csv_export("coarse.csv", "%.2f")  # 0.01 s at 1 kHz: nine rows in ten repeat a time
        cfg = write("coarse.toml", CSV_TOML % "rd")
        for p in both_programs(log, cfg):
            self.assertEqual(p.returncode, USAGE, p.stderr)
            self.assertRegex(p.stderr, rf"{log}:2-\d+: column 't' \(time\): \d+ of the first \d+ rows repeat")


class Unloggable(unittest.TestCase):
    def test_interface_with_a_blank_names_the_log_and_line(self):
        out = work("iface.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", out, "--duration", "0.1", "--iface", "can 0"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertEqual(p.stderr, f"resolver-sim: {out}:1: cannot log this frame: interface name 'can 0' contains a "
                                   "blank or control character\n")

    def test_control_a_plain_interface_is_logged(self):
        out = work("iface_ok.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", out, "--duration", "0.1", "--iface", "vcan1"])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out) as f:
            self.assertIn(" vcan1 ", f.readline())


class BadProfile(unittest.TestCase):
    def test_bad_segment_names_option_and_segment(self):
        out = work("profile.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", out, "--profile", "200:0.1,abc:0.1"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertEqual(p.stderr.count("\n"), 1, p.stderr)
        self.assertRegex(p.stderr, r"^resolver-sim: --profile: '200:0.1,abc:0.1': segment 'abc:0.1' has a bad start "
                                   r"speed \[r/min\]; write rpm")
        self.assertFalse(os.path.exists(out), "nothing is simulated with a bad profile")

    def test_control_a_good_profile_is_simulated(self):
        out = work("profile_ok.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", out, "--profile", "200:0.1,200-400:0.1"])
        self.assertEqual(p.returncode, 0, p.stderr)


class LcmUrl(unittest.TestCase):
    def test_unknown_provider_is_exit_3_naming_the_url(self):
        p = run([f"{ARGS.bin}/resolver-echo", "--lcm", "nosuch://x", "--count", "1", "--timeout", "1"], timeout=60)
        self.assertEqual(p.returncode, IO, p.stderr)
        self.assertIn("resolver-echo: --lcm nosuch://x: the LCM instance failed to initialize", p.stderr)

    def test_control_memq_times_out_with_no_message(self):
        p = run([f"{ARGS.bin}/resolver-echo", "--lcm", "memq://", "--count", "1", "--timeout", "0.2"], timeout=60)
        self.assertEqual(p.returncode, 1, p.stderr)  # README: 1, the input had no usable data
        self.assertIn("--timeout 0.2 s expired after 0 of --count 1 messages", p.stderr)


_LCMLOG = None


def lcm_log():
    """resolverd's LCM log of the short candump log (file:// URL), made once."""
    global _LCMLOG
    if _LCMLOG is None:
        _LCMLOG = work("rule.lcmlog")
        p = run([f"{ARGS.bin}/resolverd", "--replay", sim_log(), "--once", "--fast", "--quiet",
                 "--lcm", f"file://{_LCMLOG}?mode=w"])
        if p.returncode != 0:
            raise AssertionError(f"resolverd writing {_LCMLOG} failed ({p.returncode}): {p.stderr}")
    return _LCMLOG


class EchoMapping(unittest.TestCase):
    def test_bad_lcm_type_file_is_exit_2_naming_it(self):
        types = work("types")
        os.makedirs(types, exist_ok=True)
        bad = write(os.path.join("types", "bad.lcm"), "package x;\nstruct broken {\n  int32_t ;\n}\n")
        p = run([f"{ARGS.bin}/resolver-echo", "--log", lcm_log(), "--types", types, "--limit", "1"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertIn(f"resolver-echo: {bad}:3", p.stderr)

    def test_bad_channel_regex_is_exit_2(self):
        p = run([f"{ARGS.bin}/resolver-echo", "--log", lcm_log(), "--channel", "RESOLVER_(", "--limit", "1"])
        self.assertEqual(p.returncode, USAGE, p.stderr)
        self.assertEqual(p.stderr.count("\n"), 1, p.stderr)
        self.assertIn("RESOLVER_(", p.stderr)

    def test_csv_into_a_folder_that_cannot_be_made_is_exit_3(self):
        blocker = write("csv_blocker", "a file where the folder's parent should be\n")
        out = os.path.join(blocker, "tables")
        p = run([f"{ARGS.bin}/resolver-echo", "--log", lcm_log(), "--csv", out])
        self.assertEqual(p.returncode, IO, p.stderr)
        self.assertRegex(p.stderr, rf"^resolver-echo: --csv: cannot write {out}: ")

    def test_control_csv_tables_are_written(self):
        out = work("tables")
        p = run([f"{ARGS.bin}/resolver-echo", "--log", lcm_log(), "--csv", out])
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("wrote ", p.stdout)


class ArgumentChecks(unittest.TestCase):
    def assert_one_line(self, p, code, line):
        self.assertEqual(p.returncode, code, p.stderr)
        self.assertEqual(p.stderr, line + "\n")

    def test_to_before_from_is_exit_2_naming_the_option(self):
        self.assert_one_line(resolverd("--from", "0.4", "--to", "0.2"), USAGE,
                             "resolverd: --to: 0.2 s is before --from 0.4 s")
        self.assert_one_line(run([f"{ARGS.bin}/resolver-model", "fit", sim_log(), "--from", "0.4", "--to", "0.2"]),
                             USAGE, "resolver-model: --to: 0.2 s is before --from 0.4 s")

    def test_control_to_after_from_is_read(self):
        p = resolverd("--from", "0.1", "--to", "0.4")
        self.assertEqual(p.returncode, 0, p.stderr)

    def test_resolverd_with_nothing_to_read_is_exit_2(self):
        p = run([f"{ARGS.bin}/resolverd", "--quiet", "--lcm", "memq://"], timeout=60)
        self.assert_one_line(p, USAGE, "resolverd: nothing to read: give --replay LOG or --can IFACE (see --help)")

    def test_echo_without_log_or_lcm_is_exit_2(self):
        p = run([f"{ARGS.bin}/resolver-echo"], timeout=60)
        self.assert_one_line(p, USAGE, "resolver-echo: give --log FILE or --lcm URL (or --list-types); see --help")

    def test_echo_unknown_type_is_exit_2_naming_the_option(self):
        p = run([f"{ARGS.bin}/resolver-echo", "--log", lcm_log(), "--type", "nosuch_t"])
        self.assert_one_line(p, USAGE, "resolver-echo: --type nosuch_t: no such type; see --list-types or add it "
                                       "with --types")

    def test_export_data_without_an_output_is_exit_2(self):
        p = run([f"{ARGS.bin}/resolver-model", "export-data", sim_log()])
        self.assert_one_line(p, USAGE, "resolver-model: export-data: give --csv OUT, --mat OUT or both")

    def test_fleet_argument_checks(self):
        model = f"{ARGS.bin}/resolver-model"
        manifest = write("fleet.csv", f"unit,log\nu1,{sim_log()}\n")
        self.assert_one_line(run([model, "fleet", "--summarize", ARGS.work, "--out", work("fleet_out")]), USAGE,
                             "resolver-model: fleet: --summarize DIR takes no MANIFEST or --out")
        self.assert_one_line(run([model, "fleet", manifest]), USAGE,
                             "resolver-model: fleet: give MANIFEST --out DIR, or --summarize DIR")
        self.assert_one_line(run([model, "fleet", "--summarize", manifest]), IO,
                             f"resolver-model: fleet: --summarize {manifest}: not a folder")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
