#!/usr/bin/env python3
"""Issue 16 ("Trust") through the real programs: every row of the issue's table
that this branch owns becomes a test here, asserting the new behaviour and the
message, each with a control where one makes sense.

  row                                      test
  sin = cos = 0 for the whole log           DeadExcitation
  a DBC whose cos overlaps sin              OverlappingDbc
  motor stopped (the health half)           StoppedMotor
  resolverd --replay /dev/zero, FIFO, line  SignalsEndIt
  replay without --once (loop)              LoopingReplay
  --fast replay into file://                LcmLogsOtherToolsCanUse.test_file_log_*
  --fast replay on udpm with lcm-logger     LcmLogsOtherToolsCanUse.test_udpm_*
  SIGHUP during --replay                    SighupInReplay (issue 25: it keeps the record)
  30000 r/min                               Overspeed
  exit codes                                ExitCodes

Issue 25 ("Trust"): the persisted calibration (--state-dir) and SIGHUP.

  a calibration saved from an unhealthy run   CalibrationOnlyFromAHealthyRun
  provenance; a file from another layout      CalibrationProvenance
  two resolverd on one state dir              StateDirLock
  a failed save, a read-only state dir        CalibrationSaveFails
  a FIFO in place of calibration.txt          CalibrationFifo

Timing: the liveness tests (SignalsEndIt) assert that a signal ends resolverd
within LIVENESS_BOUND_S. The design bound is far smaller (the reader looks at the
stop flag at least every CandumpReader::kStopPollMs = 100 ms, a paced sleep every
50 ms, and the end-of-run report is a few ms); the bound is generous because this
is a liveness check on a shared, loaded machine, not a timing benchmark. Before
the fix these runs never ended (only SIGKILL did).

Python 3 standard library only; lcm-logger and lcm-logplayer (liblcm-bin) where
installed (the udpm test also needs a multicast route; it skips without one).

  test_trust.py --bin build/bin --work build/integration/trust --cases tests/bad_input/cases
"""
import argparse
import json
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest

ARGS = None
LIVENESS_BOUND_S = 5.0  # [s] see the module docstring
# A port of its own: other programs on this host (a demo, another test run) publish
# RESOLVER_* on LCM's default group and port, and their messages must not count here.
UDPM = "udpm://239.255.76.67:%d?ttl=0" % (17000 + os.getpid() % 2000)


def run(cmd, expect_rc=0, **kw):
    proc = subprocess.run(cmd, capture_output=True, text=True, errors="replace", **kw)
    if expect_rc is not None and proc.returncode != expect_rc:
        raise AssertionError(f"{' '.join(cmd)} exited {proc.returncode}, expected {expect_rc}:\n"
                             f"{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


def work(name):
    return os.path.join(ARGS.work, name)


def resolverd(*args):
    return [os.path.join(ARGS.bin, "resolverd"), *args]


def echo_messages(lcmlog, *filters):
    out = run([os.path.join(ARGS.bin, "resolver-echo"), "--log", lcmlog, *filters]).stdout
    return [json.loads(line) for line in out.splitlines() if line.strip()]


def sim_log(name, *args):
    """A resolver-sim log in the work folder (made once per run)."""
    path = work(name)
    if not os.path.exists(path):
        run([os.path.join(ARGS.bin, "resolver-sim"), "--out", path, *args])
    return path


def case(name):
    return os.path.join(ARGS.cases, name)


def replay_fast(log, name, *extra):
    """resolverd --replay LOG --once --fast into a file:// LCM log; returns (proc, report, lcmlog)."""
    lcmlog, report = work(name + ".lcmlog"), work(name + ".report.json")
    for f in (lcmlog, report):
        if os.path.exists(f):
            os.remove(f)
    proc = run(resolverd("--replay", log, "--once", "--fast", "--quiet", "--lcm", f"file://{lcmlog}?mode=w",
                         "--report", report, *extra))
    with open(report) as f:
        return proc, json.load(f), lcmlog


def spawn(cmd, **kw):
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace", **kw)


def signal_and_time(proc, sig):
    """Sends `sig`, waits (at most 30 s), returns (seconds it took, stdout, stderr)."""
    t0 = time.monotonic()
    proc.send_signal(sig)
    try:
        out, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        return math.inf, out, err
    return time.monotonic() - t0, out, err


class DeadExcitation(unittest.TestCase):
    """sin = cos = 0 for the whole log: loss_of_signal in health_t and the report, theta_sincos NaN."""

    @classmethod
    def setUpClass(cls):
        cls.proc, cls.rep, lcmlog = replay_fast(case("dead_excitation.log"), "dead")
        cls.msgs = echo_messages(lcmlog)

    def test_health_t_says_loss_of_signal_with_no_amplitude(self):
        health = [m for m in self.msgs if m["channel"] == "RESOLVER_HEALTH"]
        self.assertTrue(health)
        last = health[-1]
        faults = dict(zip(last["fault_name"], zip(last["fault_count"], last["fault_active"])))
        self.assertEqual(last["num_faults"], 7)
        count, active = faults["loss_of_signal"]
        self.assertEqual(count, 1000, "every sample of the log")
        self.assertTrue(active)
        for name in ("degradation_of_signal", "loss_of_tracking", "clipping", "stopped", "overspeed", "outliers"):
            self.assertEqual(faults[name][0], 0, name)
        self.assertEqual(last["sincos_amplitude"], 0.0)
        self.assertEqual(last["sincos_amplitude_max"], 0.0)

    def test_theta_sincos_is_nan_not_zero(self):
        angles = [m for m in self.msgs if m["channel"] == "RESOLVER_ANGLE"]
        self.assertEqual(len(angles), 1000)
        self.assertTrue(all(m["theta_sincos"] is None for m in angles), "NaN is printed as null")

    def test_report_and_stderr_say_so(self):
        self.assertIn("fault      loss_of_signal         100.0 % of the samples", self.proc.stdout)
        self.assertIn("no usable sin/cos", self.proc.stdout)
        self.assertIn("resolverd: signal fault loss_of_signal started 0.000 s into the input (sample 0)",
                      self.proc.stderr)
        los = self.rep["signal_health"]["faults"]["loss_of_signal"]
        self.assertEqual(los["share"], 1.0)
        self.assertTrue(los["active_at_end"])

    def test_control_clean_log_has_angles_and_no_fault(self):
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        proc, rep, lcmlog = replay_fast(log, "clean")
        angles = echo_messages(lcmlog, "--channel", "RESOLVER_ANGLE")
        self.assertTrue(all(m["theta_sincos"] is not None for m in angles))
        self.assertEqual({n: f["samples"] for n, f in rep["signal_health"]["faults"].items() if f["samples"]}, {})
        self.assertAlmostEqual(rep["signal_health"]["sincos_amplitude"], 26000, delta=5)  # the simulator's envelope
        self.assertIn("fault      none", proc.stdout)


class ExplainOnFaultySignals(unittest.TestCase):
    """resolver-model judges signal health as resolverd does: a fault over a tenth of the
    log forbids "explained" and any proposed effect (issue 16, part 2)."""

    def explain(self, log):
        p = run([os.path.join(ARGS.bin, "resolver-model"), "explain", log, "--json"])
        return json.loads(p.stdout)

    def test_dead_excitation_is_unexplained_with_the_fault(self):
        ex = self.explain(case("dead_excitation.log"))
        self.assertEqual(ex["verdict"], "unexplained")
        self.assertFalse([c for c in ex["candidates"] if c["proposed"]])
        self.assertIn("signal health: loss_of_signal for 1000 of 1000 samples", ex["where_it_fails"][0])

    def test_overspeed_at_the_floor_is_still_not_explained(self):
        # 30000 r/min aliases: the residual can sit at the floor while the angle is wrong.
        ex = self.explain(case("overspeed_30000rpm.log"))
        self.assertEqual(ex["verdict"], "unexplained")
        self.assertIn("overspeed", ex["summary"])

    def test_garbage_on_many_samples_is_never_explained(self):
        # Issue 25: impulsive garbage on a large share of the samples (here ~40 %, with a
        # valid CRC) sets the noise floor itself; the fit then "explained" it at 0.82x.
        # Outliers over a tenth of the samples now forbid "explained" and any proposal.
        ex = self.explain(sim_log("garbage_half.log", "--seed", "2", "-e", "outliers:rate=1000,size=3000"))
        self.assertEqual(ex["verdict"], "unexplained")
        self.assertFalse([c for c in ex["candidates"] if c["proposed"]])
        self.assertTrue([w for w in ex["where_it_fails"] if "signal health: outliers for" in w], ex["where_it_fails"])
        # Control: a few spikes a second are the fit's own business (kept out of it).
        few = self.explain(sim_log("spikes_5hz.log", "--seed", "2", "-e", "outliers:rate=5,size=3000"))
        self.assertFalse([w for w in few["where_it_fails"] if "signal health: outliers for" in w])

    def test_control_clean_log_is_explained(self):
        ex = self.explain(sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2"))
        self.assertEqual(ex["verdict"], "explained")
        self.assertFalse([w for w in ex["where_it_fails"] if "signal health" in w])


class StopOnASlowLoop(unittest.TestCase):
    """A stop's first samples are the bench settling, not its noise: a software tracking
    observer of omega_n = 30 rad/s rings for ~0.3 s after an abrupt stop from 60 r/min
    (p_r = 1), longer than the fixed 0.1 s the floor waits. That ringing made the position
    error's standstill floor 1.95e-3 rad against the moving samples' 3.7e-5 (53x), and any
    model within 50x of it "at the floor". The floor now waits until the stop has settled
    (noise_floor.cpp settled_start)."""

    def test_the_standstill_floor_is_the_moving_samples_noise(self):
        log = sim_log("slow_loop_stop.log", "--profile", "60:3,0:3,60:3", "--p-r", "1", "--sample-rate", "10000",
                      "-e", "tracking_loop:omega_n=30,zeta=0.7", "-e", "quadrature:beta=0.002")
        p = run([os.path.join(ARGS.bin, "resolver-model"), "explain", log, "--effects", "tracking_loop", "--json"])
        ex = json.loads(p.stdout)
        for signal in ("position_error", "sin_cos"):
            f = ex["floors"][signal]
            self.assertGreater(f["standstill_samples"], 20000)  # most of the 3 s stop is kept
            # The two estimates of one noise (second differences of the moving samples,
            # spread of the still ones, the quantization in both) agree within 1.5x: a
            # 16-bit R/D code is 2.8e-5 rad by either.
            self.assertLess(f["standstill"], 1.5 * f["second_differences"], (signal, f))
        # The ringing at the steps and the quadrature are both above the floor.
        self.assertNotEqual(ex["verdict"], "explained")


class OverlappingDbc(unittest.TestCase):
    def test_refused_naming_both_signals_message_and_bits(self):
        cfg = os.path.join(work("overlap.toml"))
        with open(cfg, "w") as f:
            f.write('[layout]\ndbc = "%s"\n' % case("dbc_overlapping_signals.dbc"))
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        proc = run(resolverd("--config", cfg, "--replay", log, "--once", "--fast", "--lcm", "memq://"), expect_rc=2)
        self.assertIn("message 'RESOLVER_SAMPLE': signals 'sin' (bits 8..23) and 'cos' (bits 16..31) overlap in bits "
                      "16..23", proc.stderr)


class StoppedMotor(unittest.TestCase):
    def test_stopped_fault_and_control(self):
        log = sim_log("stopped.log", "--rpm", "0", "--duration", "1")
        proc, rep, _ = replay_fast(log, "stopped")
        self.assertEqual(rep["signal_health"]["faults"]["stopped"]["share"], 1.0)
        self.assertIn("signal fault stopped started", proc.stderr)
        clean = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        _, rep, _ = replay_fast(clean, "clean_for_stop")
        self.assertEqual(rep["signal_health"]["faults"]["stopped"]["samples"], 0)


class SignalsEndIt(unittest.TestCase):
    """SIGTERM/SIGINT end resolverd on any input (see LIVENESS_BOUND_S)."""

    def assert_ends(self, cmd, sig=signal.SIGTERM, settle_s=0.7, **kw):
        proc = spawn(cmd, **kw)
        time.sleep(settle_s)  # let it get into its read loop
        if proc.poll() is not None:
            self.fail("ended before the signal: %s" % (proc.communicate(),))
        took, out, err = signal_and_time(proc, sig)
        self.assertLess(took, LIVENESS_BOUND_S, f"{' '.join(cmd)} took {took:.2f} s to end on {sig.name}\n{err[-2000:]}")
        self.assertGreaterEqual(proc.returncode, 0, "died by a signal instead of exiting: %s" % err[-2000:])
        self.assertIn("resolverd report:", out, "the report is printed at a stop")
        return proc.returncode, err

    def test_dev_zero(self):
        for sig in (signal.SIGTERM, signal.SIGINT):
            rc, err = self.assert_ends(resolverd("--replay", "/dev/zero", "--lcm", "memq://", "--quiet"), sig)
            self.assertEqual(rc, 1, "nothing decoded: exit 1")
            self.assertIn("no sample decoded", err)

    def test_fifo_with_no_writer(self):
        fifo = work("no_writer.fifo")
        if os.path.exists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        rc, _ = self.assert_ends(resolverd("--replay", fifo, "--lcm", "memq://", "--quiet"))
        self.assertEqual(rc, 1)

    def test_fifo_writer_sending_an_endless_line(self):
        fifo = work("endless.fifo")
        if os.path.exists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        stop = threading.Event()

        def writer():
            with open(fifo, "wb") as f:
                try:
                    while not stop.is_set():
                        f.write(b"A" * 65536)  # never a newline
                except BrokenPipeError:
                    pass

        t = threading.Thread(target=writer, daemon=True)
        t.start()
        try:
            self.assert_ends(resolverd("--replay", fifo, "--lcm", "memq://", "--quiet"))
        finally:
            stop.set()

    def test_fifo_writer_idle_mid_line(self):
        fifo = work("idle.fifo")
        if os.path.exists(fifo):
            os.remove(fifo)
        os.mkfifo(fifo)
        holder = {}

        def writer():
            f = open(fifo, "wb", buffering=0)
            f.write(b"(1700000000.000000) can0 100#00")  # a line that never ends
            holder["f"] = f

        t = threading.Thread(target=writer, daemon=True)
        t.start()
        try:
            self.assert_ends(resolverd("--replay", fifo, "--lcm", "memq://", "--quiet"))
        finally:
            t.join(5)
            if "f" in holder:
                holder["f"].close()

    def test_paced_replay_of_a_good_log(self):
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        rc, _ = self.assert_ends(resolverd("--replay", log, "--lcm", "memq://", "--quiet"), settle_s=1.0)
        self.assertEqual(rc, 0)

    def test_a_day_long_pause_in_the_log(self):
        # Two frames a day apart: paced replay sleeps, in slices, and a signal ends the sleep.
        log = work("day_gap.log")
        with open(case("clean.log")) as src, open(log, "w") as dst:
            lines = src.read().splitlines()
            dst.write("\n".join(lines[:10]) + "\n")
            head, rest = lines[10].split(")", 1)
            sec = int(head[1:].split(".")[0]) + 86400
            dst.write("(%d.%s)%s\n" % (sec, head.split(".")[1], rest))
        self.assert_ends(resolverd("--replay", log, "--lcm", "memq://", "--quiet"))


class LoopingReplay(unittest.TestCase):
    def test_health_keeps_coming_and_utime_stays_monotonic(self):
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        _, _, one_pass = replay_fast(log, "one_pass")
        pass_bytes = os.path.getsize(one_pass)
        lcmlog = work("loop.lcmlog")
        if os.path.exists(lcmlog):
            os.remove(lcmlog)
        # 2 s of log at 10x: a pass every 0.2 s; let it loop until the log holds more than
        # three passes (the writer flushes at every health_t), however slow the machine.
        proc = spawn(resolverd("--replay", log, "--rate", "10", "--quiet", "--lcm", f"file://{lcmlog}?mode=w"))
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            if os.path.exists(lcmlog) and os.path.getsize(lcmlog) > 3.2 * pass_bytes:
                break
            time.sleep(0.2)
        took, out, err = signal_and_time(proc, signal.SIGTERM)
        self.assertLess(took, LIVENESS_BOUND_S)
        self.assertEqual(proc.returncode, 0, err)
        msgs = echo_messages(lcmlog)
        health = [m["utime"] for m in msgs if m["channel"] == "RESOLVER_HEALTH"]
        angle = [m["utime"] for m in msgs if m["channel"] == "RESOLVER_ANGLE"]
        passes = len(angle) / 4000.0
        self.assertGreater(passes, 3.0, "looped more than three times (%.1f passes)" % passes)
        # One health_t per second of (shifted) frame time, in every pass: ~2 per pass.
        self.assertGreaterEqual(len(health), int(2 * passes) - 1, health)
        self.assertTrue(all(b > a for a, b in zip(health, health[1:])), "health utime monotonic")
        self.assertTrue(all(b >= a for a, b in zip(angle, angle[1:])), "angle utime monotonic across passes")
        span = (angle[-1] - angle[0]) / 1e6
        self.assertAlmostEqual(span, passes * 2.0, delta=0.1, msg="utime advances by the log's span per pass")


class LcmLogsOtherToolsCanUse(unittest.TestCase):
    def test_file_log_of_fast_replay_is_stamped_with_bench_time(self):
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        _, _, lcmlog = replay_fast(log, "fast_file")
        # Event times (lcm::LogFile's timestamp) as resolver-echo cannot show them: read the headers.
        stamps = []
        with open(lcmlog, "rb") as f:
            data = f.read()
        pos = 0
        while pos + 28 <= len(data):
            sync, _, ts, clen, dlen = (int.from_bytes(data[pos:pos + 4], "big"), 0,
                                       int.from_bytes(data[pos + 12:pos + 20], "big", signed=True),
                                       int.from_bytes(data[pos + 20:pos + 24], "big"),
                                       int.from_bytes(data[pos + 24:pos + 28], "big"))
            self.assertEqual(sync, 0xEDA1DA01)
            stamps.append(ts)
            pos += 28 + clen + dlen
        self.assertEqual(pos, len(data))
        span = (stamps[-1] - stamps[0]) / 1e6
        self.assertAlmostEqual(span, 2.0, delta=0.01, msg="event times span the bench's 2 s, not the replay's wall time")
        self.assertTrue(all(b >= a for a, b in zip(stamps, stamps[1:])), "event times never go back")

    def test_file_log_plays_at_bench_speed_in_lcm_logplayer(self):
        player = shutil.which("lcm-logplayer")
        if player is None:
            self.skipTest("lcm-logplayer not installed (apt-get install liblcm-bin)")
        log = sim_log("clean_200rpm.log", "--rpm", "200", "--duration", "2")
        _, _, lcmlog = replay_fast(log, "fast_file_play")
        t0 = time.monotonic()
        run([player, "-l", "memq://", "-s", "2", lcmlog], timeout=60)
        took = time.monotonic() - t0
        # 2 s of bench time at 2x: 1 s. Playing cannot be faster than the stamps
        # allow (the lower bound is the property; before the fix: ~0.02 s).
        self.assertGreater(took, 0.8, "lcm-logplayer played 2 s of bench time at 2x in %.3f s" % took)

    def udpm_or_skip(self):
        if shutil.which("lcm-logger") is None:
            self.skipTest("lcm-logger not installed (apt-get install liblcm-bin)")
        try:
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            s.connect(("239.255.76.67", 7667))
            s.close()
        except OSError as e:
            self.skipTest("no multicast route (%s): ip route add 224.0.0.0/4 dev lo" % e)

    def logger_keeps(self, replay_args, name):
        """Messages lcm-logger recorded of one replay, and resolverd's stderr."""
        lcmlog = work(name + ".udpm.lcmlog")
        if os.path.exists(lcmlog):
            os.remove(lcmlog)
        logger = spawn(["lcm-logger", "--lcm-url=" + UDPM, "-c", "RESOLVER_.*", lcmlog])
        time.sleep(0.5)  # subscribed before the first message
        try:
            proc = run(resolverd("--once", "--quiet", "--lcm", UDPM, *replay_args), timeout=120)
            time.sleep(0.5)
        finally:
            logger.send_signal(signal.SIGINT)
            logger.communicate(timeout=10)
        return len(echo_messages(lcmlog)), proc.stderr

    def test_udpm_fast_says_listeners_may_drop_and_rate_paces(self):
        self.udpm_or_skip()
        log = sim_log("clean_1s.log", "--rpm", "200", "--duration", "1")
        _, _, reference = replay_fast(log, "udpm_reference")
        total = len(echo_messages(reference))
        _, err = self.logger_keeps(["--replay", log, "--fast"], "fast")
        self.assertIn("--fast on udpm publishes as fast as the CPU allows", err)
        self.assertIn("--rate X", err)
        kept, err = self.logger_keeps(["--replay", log, "--rate", "1"], "rate1")
        self.assertNotIn("--fast on udpm", err)
        # Paced at real time lcm-logger keeps (nearly) every message. Not "every": on a
        # loaded shared machine the logger may be descheduled for longer than its socket
        # buffer (~200 datagrams at the kernel's default rmem) lasts at 4000 messages/s;
        # --fast kept 14 % in the same place. Measured 98.8 % paced while ctest ran two
        # fits beside it on this 2-core machine: 90 % still tells pacing from --fast.
        self.assertLessEqual(kept, total)
        self.assertGreaterEqual(kept, 0.9 * total, "paced at real time, lcm-logger keeps the messages")


class SighupInReplay(unittest.TestCase):
    def replay_and_reload(self, name, before, after, lcm, *extra, log=None, after_s=1.0):
        """Paced replay of a 4 s log with config text `before`; 1 s in, the file becomes
        `after` and resolverd gets SIGHUP. Returns stderr once it ran to the end (exit 0)."""
        log = log or sim_log("clean_4s.log", "--rpm", "200", "--duration", "4")
        cfg = work(name + ".toml")
        with open(cfg, "w") as f:
            f.write(before)
        proc = spawn(resolverd("--replay", log, "--once", "--config", cfg, "--quiet", "--lcm", lcm, *extra))
        time.sleep(after_s)
        with open(cfg, "w") as f:
            f.write(after)
        proc.send_signal(signal.SIGHUP)
        _, err = proc.communicate(timeout=60)
        self.assertEqual(proc.returncode, 0, err)
        return err

    def test_reload_switches_the_estimator(self):
        lcmlog = work("sighup.lcmlog")
        err = self.replay_and_reload("sighup", '[estimator]\nmethod = "hwang_integral"\n',
                                     '[estimator]\nmethod = "sincos_least_squares"\n', f"file://{lcmlog}?mode=w")
        self.assertIn("resolverd: config reloaded from " + work("sighup.toml"), err)
        methods = [m["method"] for m in echo_messages(lcmlog, "--channel", "RESOLVER_ESTIMATE")]
        self.assertIn("hwang_integral", methods)
        self.assertEqual(methods[-1], "sincos_least_squares", "the reloaded config runs to the end")

    def test_reload_keeps_the_record(self):
        # Issue 25: one valid SIGHUP reset the run's counters, rejects, health, the learned
        # estimate and angle_t's sample_index (7395 back to 228); the final report covered
        # 6043 of 23992 frames. The reload changes a threshold and keeps the model.
        log = sim_log("clean_4s.log", "--rpm", "200", "--duration", "4")
        with open(log) as f:
            frames = sum(1 for line in f if line.strip())
        lcmlog, report = work("sighup_keep.lcmlog"), work("sighup_keep.report.json")
        for f in (lcmlog, report):
            if os.path.exists(f):
                os.remove(f)
        # Windows of 4 revolutions (0.4 s here): estimates come before the reload, 1.5 s in.
        model = "[model]\nwindow_revolutions = 4\n"
        err = self.replay_and_reload("sighup_keep", model + "[health]\noutlier_sigmas = 8.0\n",
                                     model + "[health]\noutlier_sigmas = 9.0\n", f"file://{lcmlog}?mode=w",
                                     "--report", report, after_s=1.5)
        with open(report) as f:
            rep = json.load(f)
        self.assertEqual(rep["frames_seen"], frames, "the final report covers the whole log")
        self.assertEqual(rep["samples_complete"], 8000)
        self.assertEqual(rep["signal_health"]["samples"], 8000, "health counts the whole log")
        self.assertEqual(rep["reload_count"], 1)
        reload = rep["reloads"][0]
        self.assertGreater(reload["t_s"], 0.0)
        self.assertLess(reload["t_s"], 4.0)
        self.assertTrue(reload["estimate_kept"])
        self.assertRegex(err, r"resolverd: config reloaded from \S+ at \d+\.\d{3} s into the input \(sample \d+\): "
                              r"the learned estimate is kept")
        msgs = echo_messages(lcmlog)
        index = [m["sample_index"] for m in msgs if m["channel"] == "RESOLVER_ANGLE"]
        self.assertEqual(len(index), 8000)
        self.assertTrue(all(b > a for a, b in zip(index, index[1:])), "angle_t's sample_index never steps back")
        health = [m for m in msgs if m["channel"] == "RESOLVER_HEALTH"]
        seen = [h["frames_seen"] for h in health]
        self.assertTrue(all(b >= a for a, b in zip(seen, seen[1:])), "health_t's frame count never steps back")
        self.assertEqual(seen[-1], frames)
        # The learned model carries on: the estimates after the reload build on the ones before.
        est = [m for m in msgs if m["channel"] == "RESOLVER_ESTIMATE"]
        after = [m for m in est if m["sample_index"] > reload["sample_index"]]
        before = [m for m in est if m["sample_index"] <= reload["sample_index"]]
        self.assertTrue(before and after, "estimates on both sides of the reload")
        self.assertTrue(before[-1]["converged"])
        self.assertTrue(after[0]["converged"], "no restart: still converged right after the reload")
        # A replay hands a window's model over where the next window completes (live_model_fit.h),
        # so the first estimate after the reload may be the same window's, summed again (equal to
        # rounding: 1e-9 of a revolution is far below any restart, which would drop to 0).
        self.assertGreaterEqual(after[0]["revolutions_used"] + 1e-9, before[-1]["revolutions_used"])

    def test_reload_of_a_clean_log_with_rejects_keeps_them(self):
        # The rejects before a reload stay in the report: a log with a CRC error early on.
        log = work("sighup_crc.log")
        with open(sim_log("clean_4s.log", "--rpm", "200", "--duration", "4")) as src:
            lines = src.read().splitlines()
        head, payload = lines[30].rsplit("#", 1)
        lines[30] = head + "#" + payload[:-2] + ("00" if payload[-2:] != "00" else "01")  # the CRC byte
        with open(log, "w") as dst:
            dst.write("\n".join(lines) + "\n")
        report = work("sighup_crc.report.json")
        self.replay_and_reload("sighup_crc", "[health]\noutlier_sigmas = 8.0\n", "[health]\noutlier_sigmas = 9.0\n",
                               "memq://", "--report", report, log=log)
        with open(report) as f:
            rep = json.load(f)
        self.assertEqual(rep["rejects"].get("crc"), 1, rep["rejects"])
        self.assertEqual(rep["frames_seen"], len(lines))

    def test_bad_config_on_reload_keeps_the_running_one(self):
        err = self.replay_and_reload("sighup_bad", "[bench]\np_r = 3\n", "[bench]\npole_pairs = 3\n", "memq://")
        self.assertIn("reload failed, keeping the running config", err)
        self.assertIn("unknown key 'pole_pairs' in [bench]", err)


class Overspeed(unittest.TestCase):
    def test_sim_refuses_naming_the_limit_and_the_options(self):
        proc = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", work("never.log"), "--rpm", "30000"], expect_rc=2)
        self.assertIn("--rpm 30000 r/min is more than --sample-rate 2000 Hz can represent", proc.stderr)
        self.assertIn("The limit is 20000 r/min here", proc.stderr)
        self.assertFalse(os.path.exists(work("never.log")))
        # Control: the limit is the limit, not a blanket refusal (a warning above resolverd's line).
        ok = run([os.path.join(ARGS.bin, "resolver-sim"), "--out", work("fast_ok.log"), "--rpm", "19000",
                  "--duration", "0.2"])
        self.assertIn("resolverd will report overspeed", ok.stderr)

    def test_resolverd_says_overspeed(self):
        proc, rep, _ = replay_fast(case("overspeed_30000rpm.log"), "overspeed")
        self.assertEqual(rep["signal_health"]["faults"]["overspeed"]["share"], 1.0)
        self.assertIn("signal fault overspeed started", proc.stderr)
        self.assertIn("30000 r/min at 2000 Hz, p_r = 3", proc.stderr)

    def test_live_model_fit_is_not_explained_once_the_fault_is_known(self):
        # The aliased angle fits at the floor; the live fit must not call it explained.
        # Health judges blocks of 0.1 s (200 samples here): windows that end before the
        # first block is judged cannot know yet (a stated limit); every later one does.
        _, _, lcmlog = replay_fast(case("overspeed_30000rpm.log"), "overspeed_fit")
        fits = echo_messages(lcmlog, "--channel", "RESOLVER_MODEL_FIT")
        judged = [m for m in fits if m["sample_index"] >= 200 and m["verdict"] != "insufficient_data"]
        self.assertTrue(judged)
        self.assertEqual({m["verdict"] for m in judged}, {"unexplained"})
        self.assertIn("overspeed", judged[0]["reason"])


def state_dir(name):
    """An empty state directory in the work folder."""
    d = work(name + ".state")
    if os.path.exists(d):
        os.chmod(d, 0o755)
        shutil.rmtree(d)
    os.makedirs(d)
    return d


def replay_with_state(log, state, name, *extra, expect_rc=0, timeout=300):
    """resolverd --replay LOG --once --fast --state-dir STATE; returns (proc, report or None)."""
    report = work(name + ".report.json")
    if os.path.exists(report):
        os.remove(report)
    proc = run(resolverd("--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", "--state-dir", state,
                         "--report", report, *extra), expect_rc=expect_rc, timeout=timeout)
    rep = None
    if os.path.exists(report):
        with open(report) as f:
            rep = json.load(f)
    return proc, rep


def lot_log():
    """2000 r/min with the DSP's cos sample 1 ms late: the R/D angle and atan2(sin, cos)
    disagree by up to 36 degrees: loss_of_tracking (and degradation_of_signal) on every block
    of the log, the live model fit unexplained, yet the estimate converges."""
    return sim_log("lot_2000rpm.log", "--rpm", "2000", "--duration", "4", "-e", "sampling_skew:tau=0.001")


def clean_log():
    return sim_log("clean_4s.log", "--rpm", "200", "--duration", "4")


def read_calibration(state):
    with open(os.path.join(state, "calibration.txt")) as f:
        return f.read()


class CalibrationOnlyFromAHealthyRun(unittest.TestCase):
    """Issue 25: a run with loss_of_tracking on every sample used to save its calibration,
    and the next start compensated with it (367 arcmin off)."""

    def test_loss_of_tracking_run_saves_nothing_and_says_why(self):
        state = state_dir("lot")
        proc, rep = replay_with_state(lot_log(), state, "lot")
        lot = rep["signal_health"]["faults"]["loss_of_tracking"]
        self.assertGreater(lot["share"], 0.9, "the log is what the test needs: loss of tracking throughout")
        self.assertTrue(rep["converged"], "the estimate converged: only the gate keeps it from being saved")
        self.assertFalse(os.path.exists(os.path.join(state, "calibration.txt")), proc.stderr[-2000:])
        path = os.path.join(state, "calibration.txt")
        self.assertIn("resolverd: calibration not saved to %s: " % path, proc.stderr)
        self.assertIn("signal fault loss_of_tracking for", proc.stderr)
        cal = rep["calibration"]
        self.assertEqual(cal["path"], path)
        self.assertFalse(cal["saved"])
        self.assertIn("loss_of_tracking", cal["reason"])
        self.assertIn("calibration not saved to " + path, proc.stdout)

    def test_an_unhealthy_run_leaves_the_good_calibration_as_it_was(self):
        state = state_dir("lot_after_clean")
        _, rep = replay_with_state(clean_log(), state, "clean_first")
        self.assertTrue(rep["calibration"]["saved"], rep["calibration"])
        good = read_calibration(state)
        proc, rep = replay_with_state(lot_log(), state, "lot_second")
        self.assertFalse(rep["calibration"]["saved"])
        self.assertEqual(read_calibration(state), good, "the healthy run's calibration is kept")
        self.assertIn("the file there, if any, is unchanged", proc.stderr)

    def test_control_a_healthy_run_saves(self):
        state = state_dir("healthy")
        proc, rep = replay_with_state(clean_log(), state, "healthy")
        self.assertEqual(rep["calibration"], {"path": os.path.join(state, "calibration.txt"), "saved": True,
                                              "reason": None})
        self.assertIn("resolverd: calibration saved to " + os.path.join(state, "calibration.txt"), proc.stderr)
        self.assertIn("param amplitude_imbalance.alpha", read_calibration(state))

    def test_without_state_dir_the_report_says_so(self):
        _, rep, _ = replay_fast(clean_log(), "no_state")
        self.assertEqual(rep["calibration"], {"path": "", "saved": False, "reason": "no --state-dir given"})


class CalibrationProvenance(unittest.TestCase):
    def test_the_file_says_where_it_came_from(self):
        state = state_dir("provenance")
        cfg = work("provenance.toml")
        with open(cfg, "w") as f:
            f.write("[bench]\np_r = 3\n")
        replay_with_state(clean_log(), state, "provenance", "--config", cfg)
        text = read_calibration(state)
        lines = dict(line.split(" ", 1) for line in text.splitlines() if " " in line)
        self.assertEqual(lines["format"], "3")
        self.assertEqual(lines["config"], cfg)
        self.assertRegex(lines["config_crc32"], r"^[0-9a-f]{8}$")
        self.assertRegex(lines["layout"], r"^[0-9a-f]{8} the layout of .*RESOLVER_SAMPLE 0x100")
        self.assertEqual(lines["source"], clean_log())
        self.assertRegex(lines["saved_at"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        version = run(resolverd("--version")).stdout.strip()
        self.assertEqual(lines["program"], version)

    def test_a_calibration_from_another_layout_is_refused_and_kept_aside(self):
        state = state_dir("layout")
        replay_with_state(clean_log(), state, "layout_learn")
        learned = read_calibration(state)
        # The same log through a config that swaps two phase currents: another wiring.
        cfg = work("swapped_phases.toml")
        with open(cfg, "w") as f:
            f.write('[layout.signals]\nsin = "RESOLVER_SAMPLE.sin"\ncos = "RESOLVER_SAMPLE.cos"\n'
                    'rd_angle = "RESOLVER_SAMPLE.rd_angle"\nref_angle = "REFERENCE_ANGLE.ref_angle"\n'
                    'i_a = "PHASE_CURRENTS.i_b"\ni_b = "PHASE_CURRENTS.i_a"\ni_c = "PHASE_CURRENTS.i_c"\n')
        proc, _ = replay_with_state(clean_log(), state, "layout_other", "--config", cfg)
        self.assertIn("resolverd: the saved calibration %s was learned on another layout" %
                      os.path.join(state, "calibration.txt"), proc.stderr)
        self.assertIn("it is NOT applied, kept aside as " + os.path.join(state, "calibration.txt.refused-"), proc.stderr)
        self.assertNotIn("compensating with the saved", proc.stderr)
        aside = [n for n in os.listdir(state) if n.startswith("calibration.txt.refused-")]
        self.assertEqual(len(aside), 1, os.listdir(state))
        with open(os.path.join(state, aside[0])) as f:
            self.assertEqual(f.read(), learned, "the refused file is kept as it was")

    def test_control_the_same_layout_from_a_copied_dbc_is_applied(self):
        state = state_dir("layout_same")
        replay_with_state(clean_log(), state, "layout_same_learn")
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
        dbc = work("bench_copy.dbc")
        with open(os.path.join(root, "proto", "resolver_bench.dbc")) as src, open(dbc, "w") as dst:
            dst.write(src.read() + '\nCM_ "a comment does not make another layout";\n')
        cfg = work("copied_dbc.toml")
        with open(cfg, "w") as f:
            f.write('[layout]\ndbc = "%s"\n' % dbc)
        proc, _ = replay_with_state(clean_log(), state, "layout_same_apply", "--config", cfg)
        self.assertIn("compensating with the saved", proc.stderr)
        self.assertNotIn("another layout", proc.stderr)


class StateDirLock(unittest.TestCase):
    def test_a_second_resolverd_on_the_same_state_dir_refuses_naming_the_first(self):
        state = state_dir("lock")
        first = spawn(resolverd("--replay", clean_log(), "--lcm", "memq://", "--quiet", "--state-dir", state))
        try:
            lock = os.path.join(state, "resolverd.lock")
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                if os.path.exists(lock):
                    with open(lock) as f:
                        if f.read().strip() == str(first.pid):
                            break
                time.sleep(0.05)
            proc = run(resolverd("--replay", clean_log(), "--once", "--fast", "--lcm", "memq://", "--quiet",
                                 "--state-dir", state), expect_rc=3)
            self.assertIn("resolverd: cannot use --state-dir %s: it is in use by another resolverd, pid %d (it holds "
                          "the lock %s)" % (state, first.pid, lock), proc.stderr)
        finally:
            took, _, err = signal_and_time(first, signal.SIGTERM)
        # A clean exit on SIGTERM: 0, or on a loaded machine (CI, 2026-11-27) 1 with its own
        # message when the signal came before its first frame was decoded; never a crash.
        if first.returncode == 1:
            self.assertIn("no sample decoded", err)
        else:
            self.assertEqual(first.returncode, 0, err)
        # Control: the lock goes with its process; the next one starts.
        run(resolverd("--replay", case("clean.log"), "--once", "--fast", "--lcm", "memq://", "--quiet",
                      "--state-dir", state))


class CalibrationSaveFails(unittest.TestCase):
    def test_a_failed_save_exits_3_naming_the_path(self):
        # The save's temp file cannot be created (a directory in its place): the same
        # path through the code as a full disk or a read-only directory at exit, and it
        # works as root, whom permissions do not stop.
        state = state_dir("save_fails")
        os.mkdir(os.path.join(state, "calibration.txt.tmp"))
        proc, rep = replay_with_state(clean_log(), state, "save_fails", expect_rc=3)
        tmp = os.path.join(state, "calibration.txt.tmp")
        self.assertIn("cannot save the calibration: creating '%s' failed: Is a directory" % tmp, proc.stderr)
        self.assertIn("(exit code 3)", proc.stderr)
        self.assertFalse(rep["calibration"]["saved"])
        self.assertIn(tmp, rep["calibration"]["reason"])
        self.assertIn("resolverd report:", proc.stdout, "the report is still printed")

    def test_a_read_only_state_dir_is_refused_at_start(self):
        state = state_dir("read_only")
        if os.geteuid() == 0:
            self.skipTest("running as root: a mode-0555 directory is writable for root (the failed save "
                          "itself is tested by test_a_failed_save_exits_3_naming_the_path)")
        os.chmod(state, 0o555)
        try:
            proc = run(resolverd("--replay", clean_log(), "--once", "--fast", "--lcm", "memq://", "--quiet",
                                 "--state-dir", state), expect_rc=3)
        finally:
            os.chmod(state, 0o755)
        self.assertIn("cannot use --state-dir %s: opening the lock file %s failed: Permission denied" %
                      (state, os.path.join(state, "resolverd.lock")), proc.stderr)

    def test_a_missing_state_dir_is_refused_at_start(self):
        missing = work("no-such-state-dir")
        proc = run(resolverd("--replay", case("clean.log"), "--once", "--fast", "--lcm", "memq://", "--quiet",
                             "--state-dir", missing), expect_rc=3)
        self.assertIn("cannot use --state-dir %s: opening the lock file %s/resolverd.lock failed: No such file or "
                      "directory" % (missing, missing), proc.stderr)


class CalibrationFifo(unittest.TestCase):
    def test_a_fifo_in_place_of_the_calibration_does_not_block_the_start(self):
        state = state_dir("fifo")
        fifo = os.path.join(state, "calibration.txt")
        os.mkfifo(fifo)
        try:
            proc, rep = replay_with_state(clean_log(), state, "fifo", timeout=60)
        except subprocess.TimeoutExpired:
            self.fail("resolverd blocked opening the FIFO %s" % fifo)
        self.assertIn("%s: not a regular file (a FIFO)" % fifo, proc.stderr)
        self.assertTrue(rep["calibration"]["saved"])
        self.assertTrue(os.path.isfile(fifo) and not os.path.islink(fifo), "the save put a file in its place")


class ExitCodes(unittest.TestCase):
    PROGRAMS = ["resolverd", "resolver-sim", "resolver-model", "resolver-echo", "resolver-accuracy"]

    def bin(self, name):
        return os.path.join(ARGS.bin, name)

    def test_help_documents_them_everywhere(self):
        for prog in self.PROGRAMS:
            args = [self.bin(prog), "--help"]
            out = run(args).stdout
            self.assertRegex(out, r"(?i)exit (codes|status)", prog)
            self.assertRegex(out, r"3 I/O error", prog)

    def test_missing_file_is_3_naming_it(self):
        missing = work("does-not-exist.log")
        for cmd in ([self.bin("resolverd"), "--replay", missing, "--once"],
                    [self.bin("resolverd"), "--replay", case("clean.log"), "--config", missing],
                    [self.bin("resolver-sim"), "--out", work("x.log"), "--config", missing],
                    [self.bin("resolver-model"), "fit", missing],
                    [self.bin("resolver-model"), "fit", case("clean.log"), "--config", missing],
                    [self.bin("resolver-echo"), "--log", missing]):
            proc = run(cmd, expect_rc=3)
            self.assertIn(missing + ": No such file or directory", proc.stderr, cmd)

    def test_usage_and_config_errors_are_2(self):
        bad_cfg = work("bad.toml")
        with open(bad_cfg, "w") as f:
            f.write("[bench]\npole_pairs = 3\n")
        for cmd in ([self.bin("resolverd")],
                    [self.bin("resolverd"), "--bogus"],
                    [self.bin("resolverd"), "--replay", case("clean.log"), "--config", bad_cfg, "--once"],
                    [self.bin("resolverd"), "--replay", case("clean.log"), "--fast", "--rate", "2"],
                    [self.bin("resolver-sim"), "--bogus"],
                    [self.bin("resolver-model")],
                    [self.bin("resolver-model"), "fit", case("clean.log"), "--config", bad_cfg],
                    [self.bin("resolver-echo")],
                    [self.bin("resolver-accuracy"), "--seeds", "1"]):
            run(cmd, expect_rc=2)

    def test_no_usable_data_is_1(self):
        empty = work("empty.log")
        open(empty, "w").close()
        proc = run([self.bin("resolverd"), "--replay", empty, "--once", "--fast", "--lcm", "memq://"], expect_rc=1)
        self.assertIn("no sample decoded", proc.stderr)
        run([self.bin("resolver-model"), "fit", case("clean.log")], expect_rc=1)  # 24 samples: too few to fit
        run([self.bin("resolverd"), "--replay", case("clean.log"), "--once", "--fast", "--lcm", "memq://"],
            expect_rc=0)  # control: 24 samples decode

    def test_unwritable_output_is_3(self):
        bad = "/nonexistent-dir/out"
        run([self.bin("resolverd"), "--replay", case("clean.log"), "--once", "--fast", "--lcm",
             f"file://{bad}.lcmlog?mode=w"], expect_rc=3)
        run([self.bin("resolverd"), "--replay", case("clean.log"), "--once", "--fast", "--lcm", "memq://",
             "--report", bad + ".json"], expect_rc=3)
        run([self.bin("resolver-sim"), "--out", bad + ".log", "--duration", "0.1"], expect_rc=3)

    def test_spy_wrapper(self):
        spy = self.bin("resolver-spy")
        if not os.path.exists(spy) or shutil.which("java") is None:
            self.skipTest("resolver-spy not built or no java")
        env = dict(os.environ, LCM_JAR=work("no-lcm.jar"))
        proc = run([spy], expect_rc=3, env=env)
        self.assertIn("no-lcm.jar does not exist", proc.stderr)
        run([spy, "--bogus"], expect_rc=2)


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--cases", required=True, help="tests/bad_input/cases")
    ARGS, rest = ap.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
