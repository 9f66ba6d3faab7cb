#!/usr/bin/python3
"""Long offline runs and inputs that are not a plain, settled file (issues 22, 23).

  Progress       resolver-model fit/explain --progress with stderr in a file: progress
                 lines (bytes of the total, samples, rate, ETA; then the fit), at most
                 ~4 a second, and stdout byte for byte as without --progress; without
                 --progress and with stderr not a terminal: no progress at all
  ChangingFile   a log that grows while resolver-model reads it: exit 0, a warning and
                 a note saying so; one truncated while it is read: exit 3 naming it
  Threads        explain (and --chunk) on --threads 1, 3 and the default: the same JSON
                 byte for byte; --threads 0 refused naming it
  ReadOnce       a FIFO or a pipe read where a loop would read it twice: resolverd
                 --replay without --once stops after one pass saying why (exit 0, it
                 used to wait for another writer or say "no frames to loop over");
                 resolver-model reads a pipe (/dev/stdin) once, as a file

  test_long_runs.py --bin BUILD/bin --work DIR [unittest arguments]
"""
import argparse
import os
import re
import subprocess
import sys
import threading
import time
import unittest

ARGS = None


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)


def work(name):
    return os.path.join(ARGS.work, name)


_LOGS = {}


def sim_log(seconds):
    """A resolver-sim candump log of `seconds` at 2 kHz, made once."""
    if seconds not in _LOGS:
        path = work(f"long_{seconds}s.log")
        p = run([f"{ARGS.bin}/resolver-sim", "--out", path, "--duration", str(seconds), "--seed", "7"])
        if p.returncode != 0:
            raise AssertionError(f"resolver-sim failed ({p.returncode}): {p.stderr}")
        _LOGS[seconds] = path
    return _LOGS[seconds]


def copy(src, name):
    dst = work(name)
    with open(src, "rb") as f, open(dst, "wb") as g:
        g.write(f.read())
    return dst


def wait_until_reading(proc, path, settle_s=0.01, timeout_s=20.0):
    """Waits until `proc` has `path` open (and still open `settle_s` later: the
    reader, not the quick look at the first bytes). False if it never does."""
    real = os.path.realpath(path)
    fd_dir = f"/proc/{proc.pid}/fd"

    def has_open():
        try:
            for fd in os.listdir(fd_dir):
                try:
                    if os.readlink(os.path.join(fd_dir, fd)) == real:
                        return True
                except OSError:
                    pass
        except OSError:
            pass
        return False

    end = time.monotonic() + timeout_s
    while time.monotonic() < end and proc.poll() is None:
        if has_open():
            time.sleep(settle_s)
            if has_open():
                return True
        time.sleep(0.001)
    return False


class Progress(unittest.TestCase):
    def test_forced_into_a_file_and_output_unchanged(self):
        log = sim_log(60)
        model = f"{ARGS.bin}/resolver-model"
        for sub in ("fit", "explain"):
            with self.subTest(sub=sub):
                quiet = run([model, sub, log])
                self.assertEqual(quiet.returncode, 0, quiet.stderr)
                self.assertEqual(quiet.stderr, "", "stderr not a terminal, no --progress: no progress")
                t0 = time.monotonic()
                shown = run([model, sub, log, "--progress"])
                took = time.monotonic() - t0
                self.assertEqual(shown.returncode, 0, shown.stderr)
                self.assertEqual(shown.stdout, quiet.stdout, "--progress changes stderr only")
                lines = shown.stderr.splitlines()
                reading = [line for line in lines if line.startswith(f"reading {log}: ")]
                self.assertTrue(reading, shown.stderr)
                self.assertNotIn("\r", shown.stderr, "a file gets whole lines, no carriage returns")
                self.assertRegex(reading[0], r": [0-9.]+ of [0-9.]+ MB \(\d+%\), \d+ samples, [0-9.]+ MB/s, ETA ")
                self.assertRegex(reading[-1], r"of ([0-9.]+) MB \(100%\), 120000 samples, .* done in ")
                self.assertTrue(any(re.match(r"fitting \[#* *\] +100% done in ", line) for line in lines), shown.stderr)
                # At most ~4 draws a second (and the first and last ones).
                self.assertLessEqual(len(reading), 4 * took + 3, shown.stderr)

    def test_environment_still_forces_it(self):
        env = dict(os.environ, RESOLVER_PROGRESS="1", RESOLVER_PROGRESS_AFTER_MS="0")
        p = run([f"{ARGS.bin}/resolver-model", "explain", sim_log(2)], env=env)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertRegex(p.stderr, r"fitting .*100%")


class Threads(unittest.TestCase):
    """Each pass over a log's rows runs on --threads N (row_blocks.h): the answer is the
    same to the last bit on any number."""

    def test_the_same_report_on_one_thread_and_on_three(self):
        log = sim_log(60)  # 120,000 samples: four blocks of 32,768 rows, so the passes are split
        model = f"{ARGS.bin}/resolver-model"
        for extra in ([], ["--chunk", "20"]):
            with self.subTest(extra=extra):
                one = run([model, "explain", log, "--json", "--threads", "1", *extra])
                three = run([model, "explain", log, "--json", "--threads", "3", *extra])
                default = run([model, "explain", log, "--json", *extra])
                self.assertEqual(one.returncode, 0, one.stderr)
                self.assertIn('"verdict"', one.stdout)
                self.assertEqual(three.stdout, one.stdout)
                self.assertEqual(default.stdout, one.stdout)

    def test_a_thread_count_out_of_range_is_refused_naming_the_option(self):
        p = run([f"{ARGS.bin}/resolver-model", "explain", sim_log(60), "--threads", "0"])
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("--threads", p.stderr)


class ChangingFile(unittest.TestCase):
    def test_a_log_growing_while_it_is_read(self):
        log = copy(sim_log(120), "growing.log")  # 33 MB: read in ~0.25 s here, acted on ~10 ms after opening
        with open(sim_log(2)) as f:
            more = f.read()
        proc = subprocess.Popen([f"{ARGS.bin}/resolver-model", "fit", log], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        if not wait_until_reading(proc, log):
            proc.kill()
            self.skipTest("resolver-model read the log before it could be made to grow")
        with open(log, "a") as f:
            f.write(more)
        out, err = proc.communicate(timeout=120)
        self.assertEqual(proc.returncode, 0, err)
        self.assertIn(f"resolver-model: warning: {log} grew while it was read", err)
        self.assertRegex(out, rf"note: {re.escape(log)} grew while it was read \((\d+) bytes when opened, (\d+) read")

    def test_a_log_truncated_while_it_is_read(self):
        log = copy(sim_log(120), "truncated.log")
        proc = subprocess.Popen([f"{ARGS.bin}/resolver-model", "fit", log], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        if not wait_until_reading(proc, log):
            proc.kill()
            self.skipTest("resolver-model read the log before it could be truncated")
        os.truncate(log, os.path.getsize(log) // 4)
        _, err = proc.communicate(timeout=120)
        self.assertEqual(proc.returncode, 3, err)
        self.assertRegex(err, rf"^resolver-model: {re.escape(log)}: the file shrank while it was read")


class ReadOnce(unittest.TestCase):
    def test_resolverd_replay_loop_of_a_fifo_stops_after_one_pass(self):
        fifo = work("loop.fifo")
        if os.path.exists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        log = sim_log(2)

        def feed():
            with open(log, "rb") as src, open(fifo, "wb") as dst:
                dst.write(src.read())

        writer = threading.Thread(target=feed)
        writer.start()
        try:
            p = run([f"{ARGS.bin}/resolverd", "--replay", fifo, "--fast", "--quiet", "--lcm", "memq://"], timeout=60)
        finally:
            writer.join(timeout=10)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn(f"resolverd: {fifo} is not a regular file (a FIFO, pipe or device): it is read once", p.stderr)
        self.assertNotIn("no frames to loop over", p.stderr)
        self.assertIn("resolverd report:", p.stdout)

    def test_resolverd_replay_loop_of_stdin_pipe(self):
        with open(sim_log(2), "rb") as f:
            data = f.read()
        p = subprocess.run([f"{ARGS.bin}/resolverd", "--replay", "/dev/stdin", "--fast", "--quiet", "--lcm", "memq://"],
                           input=data, capture_output=True, timeout=60)
        err = p.stderr.decode(errors="replace")
        self.assertEqual(p.returncode, 0, err)
        self.assertIn("is not a regular file (a FIFO, pipe or device): it is read once", err)

    def test_resolver_model_reads_a_pipe_once(self):
        log = sim_log(2)
        from_file = run([f"{ARGS.bin}/resolver-model", "fit", log])
        self.assertEqual(from_file.returncode, 0, from_file.stderr)
        # cat | ...: stdin a pipe, not the file itself
        p = run(["sh", "-c", 'cat "$1" | "$0" fit /dev/stdin', f"{ARGS.bin}/resolver-model", log], timeout=60)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(p.stdout.replace("/dev/stdin", log), from_file.stdout)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--work", required=True)
    ARGS, rest = parser.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
