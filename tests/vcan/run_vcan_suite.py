#!/usr/bin/python3
"""vcan suite: resolverd on real SocketCAN, checked from the outside.

    run_vcan_suite.py --bin BUILD/bin --work BUILD/vcan [--guest-dir BUILD/vcan-guest]
                      [--soak-seconds 30] [--latency-seconds 5 --latency-runs 1 --latency-lcm memq://]
                      [--scenarios replay,errors,...] [--timeout 420] [--qemu | --native]

Where it runs:
  * natively when /sys/class/net/vcan0 exists (a bench PC with vcan; scenarios
    that change interfaces need root and are skipped without it), else
  * in a QEMU guest (Debian's stock kernel, busybox initramfs; make_guest.sh builds
    it) whose /init creates vcan0/vcan1 and runs the scenario scripts; results
    come back over a 9p shared folder (WORK/share/out/NAME), markers on the serial
    console (WORK/console.txt).

The scenario scripts (scenarios/*.sh) only act and record (LCM log, daemon output,
key=value facts); every check is made here, on the host, with resolver-echo
reading the LCM log each run of resolverd wrote.

Exit status: 0 all checks passed; 1 a check failed, or the guest could not run
while RESOLVER_REQUIRE_VCAN=1; 77 skipped (no vcan here and no way to boot a
guest) - ctest reports that as skipped (SKIP_RETURN_CODE 77).
"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ALL_SCENARIOS = ["replay", "errors", "linkflap", "recreate", "sighup", "split", "wakechange", "model", "fd", "fullspeed",
                 "latency", "soak"]
NEEDS_ROOT_NATIVELY = {"linkflap", "recreate", "soak"}  # they take vcan0 down / delete it
# Scenarios that run the live benchmark's programs (tests/bench/live_latency_*).
LIVE_BENCH_PROGS = {"latency": "live_latency_bench", "soak": "live_latency_sender"}
RSS_GROWTH_KB = 1024  # soak: VmRSS may end at most this much above its warmed-up sample
# soak: resolverd's working set grows for its first ~40 s (estimator and model-fit windows,
# ripple trackers, malloc arenas; docs/PERFORMANCE.md "Soak"); flatness is judged from there.
RSS_WARM_S = 40
# soak: a run too short to judge flatness still bounds the working set: the 600 s soak's
# largest VmRSS is 11.4 MB; holding the frames of 30 s at 8000 frames/s would take ~24 MB more.
RSS_BOUND_KB = 32 * 1024
IFACE_DROPS = "vcan0 rx_dropped"
ALPHA_TRUE = 0.003
ALPHA_TOL = 0.05  # the 5 %; the estimator's own spread is ~0.2 % (tests/integration)
SKIP = 77


class CannotRun(Exception):
    """The environment cannot run the suite (not a failure of the code under test)."""


def require_vcan():
    return os.environ.get("RESOLVER_REQUIRE_VCAN") == "1"


def cannot_run(msg):
    if require_vcan():
        print(f"vcan suite: FAILED: RESOLVER_REQUIRE_VCAN=1 but {msg}", file=sys.stderr)
        sys.exit(1)
    print(f"vcan suite: SKIPPED: {msg} (set RESOLVER_REQUIRE_VCAN=1 to make this a failure)")
    sys.exit(SKIP)


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} -> {p.returncode}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    return p


# ---- inputs -----------------------------------------------------------------

def split_in_halves(path, first, second):
    """Writes the log's two halves next to it, split at a sample boundary (before a
    RESOLVER_SAMPLE frame, ID 0x100). Returns (lines, index of the cut)."""
    with open(path) as f:
        lines = [ln for ln in f if ln.strip()]
    cut = len(lines) // 2
    while " 100#" not in lines[cut]:
        cut += 1
    for name, part in ((first, lines[:cut]), (second, lines[cut:])):
        with open(os.path.join(os.path.dirname(path), name), "w") as f:
            f.writelines(part)
    return lines, cut


def make_inputs(bin_dir, in_dir):
    """demo.log (5 s, Hwang's bench, alpha = 0.003) and its two halves, split at a
    sample boundary (before a RESOLVER_SAMPLE frame, ID 0x100)."""
    os.makedirs(in_dir, exist_ok=True)
    demo = os.path.join(in_dir, "demo.log")
    run([os.path.join(bin_dir, "resolver-sim"), "--out", demo, "--rpm", "200", "--duration", "5",
         "--p-r", "3", "--p", "3", "--rd-bits", "16", "--iq", "10", "--seed", "1",
         "--effect", f"amplitude_imbalance:alpha={ALPHA_TRUE}"])
    lines, cut = split_in_halves(demo, "half1.log", "half2.log")

    # model: 6 s with quadrature hidden next to alpha, in two halves (seed model, then
    # the model with quadrature added by SIGHUP).
    model = os.path.join(in_dir, "model.log")
    run([os.path.join(bin_dir, "resolver-sim"), "--out", model, "--rpm", "200", "--duration", "6", "--seed", "3",
         "--effect", f"amplitude_imbalance:alpha={ALPHA_TRUE}", "--effect", "quadrature:beta=0.002"])
    split_in_halves(model, "model1.log", "model2.log")

    def samples(ls):
        return sum(1 for ln in ls if " 100#" in ln)
    return {"frames": len(lines), "samples": samples(lines),
            "half1_frames": cut, "half2_frames": len(lines) - cut,
            "half1_samples": samples(lines[:cut]), "half2_samples": samples(lines[cut:])}


# ---- running the scenarios ----------------------------------------------------

def scenario_params(args):
    """Parameters of the latency and soak scenarios: environment variables
    natively, kernel command-line words in the guest (URLs have no spaces)."""
    return {"resolver_vcan_latency_s": str(args.latency_seconds),
            "resolver_vcan_latency_runs": str(args.latency_runs),
            "resolver_vcan_latency_lcm": args.latency_lcm,
            "resolver_vcan_soak_s": str(args.soak_seconds),
            "resolver_vcan_soak_flap_s": str(args.soak_flap_seconds),
            "resolver_vcan_burst": str(args.live_burst),
            "resolver_vcan_wake_ids": args.wake_ids or "none"}


def run_native(args, scenarios, share):
    env = dict(os.environ, PATH=f"{os.path.abspath(args.bin)}:{os.environ.get('PATH', '')}",
               CANPLAYER_GAP_MS=str(args.canplayer_gap_ms),
               IN=os.path.join(share, "in"), IFACE="vcan0", FD_IFACE="vcan1", **scenario_params(args))
    ran = []
    for s in scenarios:
        if s in NEEDS_ROOT_NATIVELY and os.geteuid() != 0:
            print(f"vcan suite: scenario {s} skipped natively: it changes vcan0 and needs root")
            continue
        out = os.path.join(share, "out", s)
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "scenario.txt"), "w") as log:
            rc = subprocess.call(["sh", os.path.join(HERE, "scenarios", f"{s}.sh")],
                                 env=dict(env, OUT=out), stdout=log, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL, timeout=args.timeout)
        with open(os.path.join(out, "rc"), "w") as f:
            f.write(f"{rc}\n")
        ran.append(s)
    return ran, {"mode": "native"}


def run_qemu(args, scenarios, share):
    qemu = shutil.which("qemu-system-x86_64")
    if not qemu:
        raise CannotRun("qemu-system-x86_64 not found (apt-get install qemu-system-x86, or tests/vcan/install-deps.sh)")
    guest = os.path.abspath(args.guest_dir)
    bins = [os.path.join(args.bin, b) for b in ("resolverd", "resolver-echo")]
    bins += [os.path.join(args.bin, LIVE_BENCH_PROGS[s]) for s in scenarios if s in LIVE_BENCH_PROGS]
    t0 = time.monotonic()
    # resolverd opens the bundled DBC by its compiled-in absolute path (the source
    # tree's proto/resolver_bench.dbc): put it at the same path in the guest.
    dbc = os.path.normpath(os.path.join(HERE, "..", "..", "proto", "resolver_bench.dbc"))
    mk = subprocess.run(["bash", os.path.join(HERE, "make_guest.sh"), "--out", guest,
                         "--file", f"{dbc}:{dbc}"] + bins,
                        capture_output=True, text=True)
    if mk.returncode != 0:
        raise CannotRun(f"make_guest.sh failed:\n{mk.stderr.strip()}")
    build_s = time.monotonic() - t0
    with open(os.path.join(guest, "guest.env")) as f:
        kernel = re.search(r"KERNEL_VERSION=(\S+)", f.read()).group(1)

    # no_timer_check (kernel command line): a starved TCG guest fails the boot-time
    # IO-APIC timer check and panics ("IO-APIC + timer doesn't work"), seen with the
    # host's two cores busy.
    # TCG (software emulation) by default: it works everywhere. On this project's
    # machines /dev/kvm exists but is unusable (nested KVM: "-cpu host" aborts on an
    # MSR, other CPU models hang in the BIOS), so KVM is opt-in.
    if os.environ.get("RESOLVER_VCAN_ACCEL") == "kvm":
        accel = ["-accel", "kvm", "-cpu", "host"]
    else:
        accel = ["-accel", "tcg", "-cpu", "max"]
    cmd = [qemu, "-nographic", "-m", "512", "-smp", os.environ.get("RESOLVER_VCAN_SMP", "1"), "-no-reboot", "-nic", "none"] + accel + [
        "-kernel", os.path.join(guest, "vmlinuz"), "-initrd", os.path.join(guest, "initramfs.cpio.gz"),
        "-append", f"console=ttyS0 quiet panic=-1 no_timer_check resolver_vcan={','.join(scenarios)} "
                   f"resolver_vcan_gap={args.canplayer_gap_ms} "
                   + " ".join(f"{k}={v}" for k, v in scenario_params(args).items()),
        "-virtfs", f"local,path={share},mount_tag=vcanshare,security_model=none,id=vcanshare"]
    console_path = os.path.join(args.work, "console.txt")
    print("vcan suite: booting " + " ".join(cmd))
    t0 = time.monotonic()
    ready_s = None
    markers = {}
    with open(console_path, "w") as console:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True, errors="replace")
        try:
            deadline = t0 + args.timeout
            for line in proc.stdout:  # the guest powers off at the end, which closes stdout
                console.write(line)
                if "@@VCAN" in line:
                    line = line[line.index("@@VCAN"):]  # after any terminal escapes
                    print("  guest: " + line.rstrip())
                    if line.startswith("@@VCAN READY"):
                        ready_s = time.monotonic() - t0
                    word = line.split()[1]
                    markers.setdefault(word, []).append(line.strip())
                if time.monotonic() > deadline:
                    raise subprocess.TimeoutExpired(cmd, args.timeout)
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
            raise RuntimeError(f"guest did not finish within {args.timeout} s; console in {console_path}")
    total_s = time.monotonic() - t0
    if "SETUP-FAILED" in markers:
        raise CannotRun(f"guest setup failed: {markers['SETUP-FAILED'][0]} (console: {console_path})")
    if "READY" not in markers:
        raise CannotRun(f"guest never became ready (qemu exit {proc.returncode}); console: {console_path}")
    if "DONE" not in markers:
        raise RuntimeError(f"guest stopped before finishing its scenarios; console: {console_path}")
    ready = markers["READY"][0]
    uptime = float(re.search(r"uptime=([\d.]+)", ready).group(1))
    info = {"mode": "qemu", "kernel": kernel, "accel": accel[1], "guest_build_s": round(build_s, 1),
            "boot_to_ready_s": round(ready_s, 1), "guest_uptime_at_ready_s": uptime,
            "qemu_total_s": round(total_s, 1)}
    return scenarios, info


# ---- checks -------------------------------------------------------------------

class Checks:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, scenario, ok, text):
        print(f"  {'PASS' if ok else 'FAIL'} {scenario}: {text}")
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        return ok


def read_facts(out):
    facts = {}
    path = os.path.join(out, "facts")
    if os.path.exists(path):
        with open(path) as f:
            for ln in f:
                if "=" in ln:
                    k, v = ln.strip().split("=", 1)
                    facts[k] = v
    return facts


def lcm_messages(bin_dir, lcmlog):
    if not os.path.exists(lcmlog):
        return []
    p = run([os.path.join(bin_dir, "resolver-echo"), "--log", lcmlog])
    return [json.loads(ln) for ln in p.stdout.splitlines() if ln.strip()]


def reasons(health):
    return dict(zip(health.get("reject_reason", []), health.get("reject_count", [])))


def receive_jitter(candump_log):
    """Spread of the kernel receive timestamps of the RESOLVER_SAMPLE frames
    (0x100; one per 500 us control period) as candump recorded them."""
    if not os.path.exists(candump_log):
        return {}
    with open(candump_log) as f:
        ts = [float(ln.split()[0].strip("()")) for ln in f if " 100#" in ln]
    if len(ts) < 402:
        return {}
    d = sorted((b - a) * 1e6 for a, b in zip(ts, ts[1:]))
    revs = [(ts[i + 200] - ts[i]) * 1e3 for i in range(0, len(ts) - 200, 200)]
    n = len(d)
    return {"interval_us_p1": round(d[n // 100]), "interval_us_p50": round(d[n // 2]),
            "interval_us_p99": round(d[99 * n // 100]), "rev_ms_min": round(min(revs), 1),
            "rev_ms_max": round(max(revs), 1)}


def check_scenario(c, s, out, msgs, facts, inputs, summary):
    def fact_int(k):
        return int(facts[k]) if k in facts else None

    rc = open(os.path.join(out, "rc")).read().strip() if os.path.exists(os.path.join(out, "rc")) else "missing"
    c.check(s, rc == "0", f"scenario script exit status {rc} (log: {out}/scenario.txt)")
    if s == "latency":  # no resolverd process: the benchmark is the daemon side
        check_latency(c, s, out, facts, summary)
        return
    c.check(s, facts.get("resolverd_rc") == "0", f"resolverd exited {facts.get('resolverd_rc')} after SIGTERM")
    for k in sorted(k for k in facts if k.startswith("canplayer")):
        c.check(s, facts[k] == "0", f"{k} = {facts[k]}")
    angles = [m for m in msgs if m["type"] == "resolver.angle_t"]
    health = [m for m in msgs if m["type"] == "resolver.health_t"]
    est = [m for m in msgs if m["type"] == "resolver.estimate_t" and m.get("converged")]
    last = health[-1] if health else {}
    if not c.check(s, bool(health), f"{len(msgs)} LCM messages, {len(health)} health_t"):
        return
    summary.update({"frames_seen": last["frames_seen"], "frames_decoded": last["frames_decoded"],
                    "angle_t": len(angles), "bus_errors": last["bus_errors"],
                    "kernel_drops": last["kernel_drops"], "reject": reasons(last)})
    if est:
        summary["alpha"] = est[-1]["value"][0]
    stderr_path = os.path.join(out, "resolverd.stderr")
    stderr = open(stderr_path).read() if os.path.exists(stderr_path) else ""

    if s == "replay":
        sent = fact_int("frames_sent")
        c.check(s, sent == inputs["frames"], f"canplayer sent {sent} frames (log has {inputs['frames']})")
        c.check(s, fact_int("frames_on_bus") == sent, f"candump saw {facts.get('frames_on_bus')} frames on {sent} sent")
        c.check(s, last["frames_seen"] == sent, f"health frames_seen {last['frames_seen']} == frames sent {sent}")
        c.check(s, last["frames_decoded"] == sent, f"health frames_decoded {last['frames_decoded']} == {sent}")
        c.check(s, last["kernel_drops"] == 0 and last["num_reasons"] == 0,
                f"kernel_drops {last['kernel_drops']}, rejects {reasons(last)}")
        c.check(s, len(angles) == inputs["samples"], f"angle_t published {len(angles)} == samples sent {inputs['samples']}")
        # The default [can] wake_ids = "auto": after 256 samples resolverd
        # re-opens vcan0 as two sockets mid-stream; the counts above show that
        # no frame was lost or seen twice in the hand-over.
        c.check(s, "samples are completed by 0x102; only it wakes the reader now" in stderr,
                "resolverd learnt that 0x102 completes the samples and switched to two sockets mid-stream")
        jitter = receive_jitter(os.path.join(out, "candump.log"))
        summary["receive_timing"] = jitter
        if c.check(s, bool(est), f"{len(est)} converged estimate_t"):
            alpha = est[-1]["value"][0]
            c.check(s, abs(alpha - ALPHA_TRUE) / ALPHA_TRUE < ALPHA_TOL,
                    f"alpha {alpha:.6f} within 5 % of {ALPHA_TRUE} ({100 * (alpha - ALPHA_TRUE) / ALPHA_TRUE:+.2f} %)")
        else:
            last_est = [m for m in msgs if m["type"] == "resolver.estimate_t"]
            print(f"  NOTE {s}: last (unconverged) alpha "
                  f"{last_est[-1]['value'][0] if last_est else 'none'}; resolverd's report: "
                  + " ".join(ln.strip() for ln in open(os.path.join(out, "resolverd.stdout")) if "rejected:" in ln))
        if jitter:
            print(f"  NOTE {s}: kernel receive times of RESOLVER_SAMPLE (candump): interval p1/p50/p99 "
                  f"{jitter['interval_us_p1']}/{jitter['interval_us_p50']}/{jitter['interval_us_p99']} us "
                  f"(nominal 500), 200-sample spans {jitter['rev_ms_min']}..{jitter['rev_ms_max']} ms (nominal 100); "
                  "resolverd times samples by counter / sample rate, not by these timestamps")
    elif s == "errors":
        sent = fact_int("frames_sent")
        err_sent = fact_int("error_frames_sent")
        err_bus = fact_int("error_frames_seen_by_candump")
        summary.update({"error_frames_sent": err_sent, "error_frames_seen_by_candump": err_bus})
        c.check(s, last["frames_decoded"] == sent, f"data frames decoded {last['frames_decoded']} == sent {sent} (error frames in between)")
        c.check(s, last["frames_seen"] == sent + err_bus, f"frames_seen {last['frames_seen']} == {sent} data + {err_bus} error frames")
        # resolverd must count exactly the error frames a reader can get from the
        # kernel: candump (with an error mask) is the independent witness.
        c.check(s, last["bus_errors"] == err_bus,
                f"health bus_errors {last['bus_errors']} == error frames candump received {err_bus} "
                f"(of {err_sent} written with cansend)")
        if err_bus == 0:
            print(f"  NOTE {s}: the kernel delivered none of the {err_sent} error-flagged frames written by cansend "
                  "to error-filter readers: vcan cannot inject bus errors this way")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']}")
    elif s == "linkflap":
        sent = fact_int("frames_sent")
        r = reasons(last)
        c.check(s, facts.get("link_down_rc") == "0" and facts.get("link_up_rc") == "0", "ip link set down/up succeeded")
        c.check(s, r.get("network_down", 0) >= 1, f"network_down counted in health ({r})")
        c.check(s, last["frames_seen"] == sent, f"frames_seen {last['frames_seen']} == sent {sent} across the flap")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']}")
    elif s == "split":
        sent = fact_int("frames_sent")
        err_bus = fact_int("error_frames_seen_by_candump")
        r = reasons(last)
        c.check(s, "two sockets" in stderr, "resolverd read vcan0 through two sockets ([can] wake_ids = [0x102])")
        c.check(s, facts.get("link_down_rc") == "0" and facts.get("link_up_rc") == "0", "ip link set down/up succeeded")
        c.check(s, last["frames_decoded"] == sent, f"frames_decoded {last['frames_decoded']} == sent {sent} (both sockets)")
        c.check(s, last["frames_seen"] == sent + err_bus,
                f"frames_seen {last['frames_seen']} == {sent} data + {err_bus} error frames")
        c.check(s, last["bus_errors"] == err_bus, f"bus_errors {last['bus_errors']} == error frames candump received {err_bus}")
        c.check(s, r.get("network_down", 0) >= 1, f"network_down counted across the split sockets ({r})")
        # The 1.5 s pause of the flap, as in linkflap: the sender stops and its counter goes on
        # where it stopped, so the sample clock reads a timestamp_jump (time continues from the
        # counter); sample_clock_reanchored if frames were lost across it too.
        c.check(s, set(r) <= {"network_down", "sample_clock_reanchored", "timestamp_jump"},
                f"no other rejects: frames in order, none completed a sample from the quiet socket ({r})")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']}")
    elif s == "wakechange":
        sent = fact_int("frames_sent")
        c.check(s, "samples are completed by 0x102; only it wakes the reader now" in stderr,
                "first half: resolverd learnt 0x102 and split its socket")
        c.check(s, "0x102 no longer completes the samples; every frame wakes the reader again" in stderr,
                "second half (no 0x102): back to waking for every frame")
        c.check(s, last["frames_seen"] == sent and last["frames_decoded"] == sent,
                f"frames_seen {last['frames_seen']}, decoded {last['frames_decoded']} == sent {sent} across both switches")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']}")
    elif s == "recreate":
        sent = fact_int("frames_sent")
        r = reasons(last)
        c.check(s, facts.get("link_del_rc") == "0" and facts.get("link_add_rc") == "0", "ip link del/add succeeded")
        c.check(s, facts.get("reopened_rc") == "0", f"resolverd re-opened vcan0 by itself ({stderr.count('reading vcan0')}x 'reading vcan0')")
        c.check(s, r.get("device_gone", 0) >= 1, f"device_gone counted in health ({r})")
        c.check(s, last["frames_seen"] == sent, f"frames_seen {last['frames_seen']} == sent {sent} across delete/re-create")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']}")
    elif s == "sighup":
        c.check(s, facts.get("reload_ok_rc") == "0", "SIGHUP with a valid config: 'config reloaded'")
        c.check(s, facts.get("reload_bad_rc") == "0", "SIGHUP with a broken config: 'reload failed', old config kept")
        # A reload keeps the run's record (issue 25): the last health_t counts both halves.
        both = inputs["half1_frames"] + inputs["half2_frames"]
        c.check(s, last["frames_seen"] == both,
                f"after the reload frames_seen {last['frames_seen']} == both halves {both} (the record is kept)")
        c.check(s, len(angles) == inputs["samples"], f"angle_t {len(angles)} == samples {inputs['samples']} across reloads")
    elif s == "fullspeed":
        sent = fact_int("frames_sent")
        drops = last["kernel_drops"]
        summary.update({"frames_sent": sent})
        c.check(s, facts.get("txqueuelen_rc") == "0", "ip link set txqueuelen 10000 succeeded")
        # Nothing lost that is not counted: the socket either delivered a frame
        # or the kernel's SO_RXQ_OVFL counter counted it.
        c.check(s, last["frames_seen"] + drops == sent,
                f"frames_seen {last['frames_seen']} + kernel_drops {drops} == frames sent {sent}")
        c.check(s, drops == 0 or reasons(last).get("kernel_drop", 0) >= 1,
                f"kernel drops reported as a reject reason too ({reasons(last)})")
        print(f"  NOTE {s}: canplayer -t with a 4 KiB receive buffer: {drops} of {sent} frames dropped by the kernel")
    elif s == "soak":
        check_soak(c, s, out, facts, last, summary, msgs)
    elif s == "model":
        check_model(c, s, facts, msgs, summary)
    elif s == "fd":
        sent = fact_int("frames_sent")
        fd = fact_int("fd_frames_sent")
        c.check(s, facts.get("mtu") == "72", f"{facts.get('mtu')} is the CAN FD MTU 72")
        c.check(s, all(facts.get(f"cansend_fd{i}_rc") == "0" for i in range(fd or 0)), f"cansend wrote {fd} FD frames")
        c.check(s, last["frames_seen"] == sent + fd, f"frames_seen {last['frames_seen']} == {sent} classic + {fd} FD")
        c.check(s, last["frames_decoded"] == sent, f"frames_decoded {last['frames_decoded']} == classic {sent}; "
                f"FD frames rejected as {reasons(last)}")
        c.check(s, len(angles) == inputs["half1_samples"], f"angle_t {len(angles)} == samples {inputs['half1_samples']}")


def check_latency(c, s, out, facts, summary):
    """live_latency_bench in the guest: it must run and account for every frame;
    the timings are printed (emulated, so no target is asserted)."""
    c.check(s, facts.get("latency_rc") == "0",
            f"live_latency_bench exit {facts.get('latency_rc')}: every frame sent was read or counted as a kernel drop")
    path = os.path.join(out, "latency.json")
    if not c.check(s, os.path.exists(path), "latency.json written"):
        return
    with open(path) as f:
        res = json.load(f)
    m = res["median"]
    summary["latency"] = res
    print(f"  NOTE {s}: {res['source']}, LCM {res['lcm']}, {res['rate']:.0f} frames/s, {len(res['runs'])} run(s) of "
          f"{res['seconds']} s (emulated: QEMU guest): arrival->publish p50/p99/max {m['pub_p50_us']:.0f}/"
          f"{m['pub_p99_us']:.0f}/{m['pub_max_us']:.0f} us, recvmsg->publish p50/p99 {m['read_p50_us']:.0f}/"
          f"{m['read_p99_us']:.0f} us, CPU {m['cpu_percent']:.1f} % of the vCPU; table in {out}/latency.txt")


def read_rss(path):
    """rss.txt rows 'SECONDS KB' (the last row 'end KB'); returns [(label, kB)]."""
    rows = []
    if os.path.exists(path):
        with open(path) as f:
            for ln in f:
                parts = ln.split()
                if len(parts) == 2 and parts[1].isdigit():
                    rows.append((parts[0], int(parts[1])))
    return rows


def check_model(c, s, facts, msgs, summary):
    """Live model discovery: model_fit_t per 8-revolution window; the seed model
    names the hidden quadrature, the reloaded model explains the log."""
    c.check(s, facts.get("reload_ok_rc") == "0", "SIGHUP with quadrature added: 'config reloaded'")
    c.check(s, facts.get("reload_bad_rc") == "0", "SIGHUP with an unknown effect: 'reload failed', model kept")
    fits = [m for m in msgs if m["type"] == "resolver.model_fit_t"]
    fitted = [m for m in fits if m["verdict"] != "insufficient_data"]
    seed = [m for m in fitted if m["effects"] == ["amplitude_imbalance"]]
    added = [m for m in fitted if m["effects"] == ["amplitude_imbalance", "quadrature"]]
    summary["model_fit_t"] = {"published": len(fits), "seed_model": [m["verdict"] for m in seed],
                              "with_quadrature": [m["verdict"] for m in added]}
    c.check(s, len(seed) >= 2 and all(m["verdict"] == "missing_effect" and m["candidate_effect"][:1] == ["quadrature"]
                                      for m in seed),
            f"seed model: {len(seed)} windows, all missing_effect with quadrature first "
            f"({[(m['verdict'], m['candidate_effect'][:1]) for m in seed]})")
    c.check(s, len(added) >= 2 and all(m["verdict"] == "explained" for m in added),
            f"after SIGHUP: {len(added)} windows, all explained ({[m['verdict'] for m in added]})")
    c.check(s, all(m["effects"] != ["flux_capacitor"] for m in fits), "the refused config never ran")
    if added:
        r = [m["residual_rms_rad"] / m["noise_floor_rad"] for m in added]
        c.check(s, max(r) <= 1.5, f"residual after adding quadrature {min(r):.2f}..{max(r):.2f}x floor (<= 1.5)")


def check_soak(c, s, out, facts, last, summary, msgs):
    def n(k):
        return int(facts.get(k, "-1"))
    attempted, sent, down, other = n("sender_attempted"), n("sender_sent"), n("sender_failed_down"), n("sender_failed_other")
    seen, drops = last["frames_seen"], last["kernel_drops"]
    flaps = n("flaps")
    c.check(s, facts.get("sender_rc") == "0", f"live_latency_sender exit {facts.get('sender_rc')}")
    c.check(s, flaps >= 1 and facts.get("link_down_rc") == "0" and facts.get("link_up_rc") == "0",
            f"{flaps} link flaps (ip link set down/up) every {facts.get('flap_every_s')} s")
    c.check(s, other == 0, f"sender: no send failed other than while the link was down ({other})")
    # Nothing lost that is not counted, by the daemon's health_t and the sender.
    c.check(s, seen + drops + n("iface_rx_dropped") == sent,
            f"frames_seen {seen} + kernel_drops {drops} + {IFACE_DROPS} {n('iface_rx_dropped')} == frames the link "
            f"accepted {sent}")
    # Frames the kernel drops before any socket (the netif_rx backlog full, or
    # a frame sent in the instant the link went down) appear only in the
    # interface's rx_dropped: counted by the kernel, not by health_t.
    netif = n("iface_rx_dropped")
    c.check(s, attempted == seen + drops + down + netif,
            f"frames attempted {attempted} == frames_seen {seen} + kernel_drops {drops} + refused while down {down}"
            f" + {IFACE_DROPS} {netif}")
    # An error frame can be among the kernel drops like any other frame.
    err_sent = n("sender_error_sent")
    c.check(s, last["bus_errors"] == err_sent or err_sent - drops <= last["bus_errors"] < err_sent,
            f"bus_errors {last['bus_errors']} == error frames sent {err_sent} (less only by kernel drops, {drops})")
    if netif or n("softnet_dropped"):
        print(f"  NOTE {s}: {netif} frames ({IFACE_DROPS}; softnet_stat dropped {n('softnet_dropped')}) were dropped by "
              "the kernel before any socket: not in health_t, which counts only socket queue overflows")
    nd = reasons(last).get("network_down", 0)
    c.check(s, nd == flaps, f"network_down counted once per flap ({nd} for {flaps})")
    rss = read_rss(os.path.join(out, "rss.txt"))
    # The reference is the sample after the working set's warm-up (RSS_WARM_S, or half
    # the run if that is later, at most 60 s): it must be flat from then on. The CI's 30 s
    # run ends inside the warm-up (it grew 20 -> 30 s by 1.1 and 1.3 MB in two runs, and
    # the flatness check failed on it): there only the bound is checked, and flatness is the
    # 600 s soak's (vcan_soak).
    warm = min(60, max(RSS_WARM_S, n("soak_seconds") // 2))
    ref = next((kb for t, kb in rss if t.isdigit() and int(t) >= warm), None)
    if c.check(s, len(rss) >= 3, f"{len(rss)} VmRSS samples"):
        kb = [k for _, k in rss]
        summary["rss_kb"] = {"first": kb[0], "reference": ref, "reference_s": warm, "last": kb[-1], "max": max(kb),
                             "samples": len(kb), "series": rss}
        c.check(s, max(kb) <= RSS_BOUND_KB, f"VmRSS bounded: max {max(kb)} kB <= {RSS_BOUND_KB} kB")
        if ref is None or n("soak_seconds") < warm + 20:
            print(f"  NOTE {s}: VmRSS {kb[0]} kB at start, {kb[-1]} kB at the end: a {n('soak_seconds')} s run ends "
                  f"within the ~{RSS_WARM_S} s warm-up, so flatness is not judged here (the 600 s soak does)")
        else:
            c.check(s, kb[-1] - ref <= RSS_GROWTH_KB,
                    f"VmRSS flat: {kb[0]} kB at start, {ref} kB at {warm} s, {kb[-1]} kB at the end, max {max(kb)} kB "
                    f"(growth after {warm} s <= {RSS_GROWTH_KB} kB)")
    # The estimate must survive the flaps and drops: the sender's alpha is 0.003.
    ests = [m for m in msgs if m["type"] == "resolver.estimate_t" and m.get("converged")]

    def good(m):
        return math.isfinite(m["value"][0]) and abs(m["value"][0] - ALPHA_TRUE) / ALPHA_TRUE < ALPHA_TOL
    if c.check(s, bool(ests), f"{len(ests)} converged estimate_t"):
        a = ests[-1]["value"][0]
        summary["alpha"] = a
        c.check(s, good(ests[-1]), f"final alpha {a:.6g} (std. error {ests[-1]['std_error'][0]:.3g}) within 5 % of "
                f"{ALPHA_TRUE}")
        bad = next((m for m in ests if not good(m)), None)
        if bad is not None:
            t = (bad["utime"] - ests[0]["utime"]) * 1e-6
            summary["first_bad_estimate"] = {"after_s": round(t, 1), "alpha": bad["value"][0],
                                             "sample_index": bad["sample_index"]}
            print(f"  NOTE {s}: first converged estimate off by more than 5 %: alpha {bad['value'][0]:.6g} "
                  f"(std. error {bad['std_error'][0]:.3g}, {bad['revolutions_used']} revolutions) at sample "
                  f"{bad['sample_index']}, ~{t:.0f} s of sample time after the first estimate")
    summary.update({"frames_attempted": attempted, "frames_sent": sent, "refused_while_down": down, "flaps": flaps,
                    "iface_rx_dropped": netif, "softnet_dropped": n("softnet_dropped"),
                    "soak_seconds": n("soak_seconds"), "sender_late_wakeups": n("sender_late_wakeups"),
                    "sender_max_late_us": n("sender_max_late_us")})
    print(f"  NOTE {s}: {n('soak_seconds')} s at 8000 frames/s: attempted {attempted}, accepted {sent}, refused while "
          f"down {down}; frames_seen {seen}, kernel_drops {drops}, bus_errors {last['bus_errors']}, rejects {reasons(last)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="folder with resolverd, resolver-sim, resolver-echo")
    ap.add_argument("--work", required=True, help="scratch folder (inputs, share, console log)")
    ap.add_argument("--guest-dir", help="guest build + download cache (default: WORK/../vcan-guest)")
    ap.add_argument("--scenarios", default=",".join(ALL_SCENARIOS), help=f"comma list of {ALL_SCENARIOS}")
    ap.add_argument("--timeout", type=float, default=420, help="seconds for the whole guest run")
    ap.add_argument("--latency-seconds", type=float, default=5, help="latency scenario: seconds per run")
    ap.add_argument("--latency-runs", type=int, default=1, help="latency scenario: runs (median reported)")
    ap.add_argument("--latency-lcm", default="memq://", help="latency scenario: LCM URL of the output")
    ap.add_argument("--soak-seconds", type=int, default=30,
                    help="soak scenario: seconds at full bus rate (30 in the suite; 600 = the full soak)")
    ap.add_argument("--soak-flap-seconds", type=int, default=30, help="soak scenario: link flap period")
    ap.add_argument("--live-burst", type=int, default=8,
                    help="latency and soak scenarios: frames per sender wake-up (8 = a burst per ms at 8000 frames/s)")
    ap.add_argument("--wake-ids", default="",
                    help="latency and soak scenarios: [can] wake_ids, comma-separated (e.g. 0x102): read through two "
                         "sockets, woken only by these frames; default: soak = resolverd's default (\"auto\": learnt), "
                         "latency = every frame wakes (the benchmark does not learn)")
    ap.add_argument("--canplayer-gap-ms", type=int, default=int(os.environ.get("RESOLVER_VCAN_CANPLAYER_GAP_MS", "1")),
                    help="canplayer -g: its sleep between clock checks [ms]; 1 is canplayer's default, "
                         "0 busy-loops for the log's exact timing")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--qemu", action="store_true", help="use the QEMU guest even if vcan0 exists here")
    mode.add_argument("--native", action="store_true", help="use this machine's vcan0 (fail if missing)")
    args = ap.parse_args()
    args.work = os.path.abspath(args.work)
    args.bin = os.path.abspath(args.bin)
    args.guest_dir = args.guest_dir or os.path.join(os.path.dirname(args.work), "vcan-guest")
    scenarios = [s for s in args.scenarios.split(",") if s]
    unknown = set(scenarios) - set(ALL_SCENARIOS)
    if unknown:
        ap.error(f"unknown scenarios {sorted(unknown)}")
    if "soak" in scenarios:
        args.timeout += args.soak_seconds * 1.5  # emulation runs the soak's own work slower than real time
    if "latency" in scenarios:
        args.timeout += args.latency_seconds * args.latency_runs * 2
    for b in ["resolverd", "resolver-sim", "resolver-echo"] + [LIVE_BENCH_PROGS[s] for s in scenarios if s in LIVE_BENCH_PROGS]:
        if not os.access(os.path.join(args.bin, b), os.X_OK):
            print(f"vcan suite: FAILED: {args.bin}/{b} missing; build it first (or leave out the latency/soak "
                  "scenarios, which need live_latency_bench/live_latency_sender)", file=sys.stderr)
            return 1

    native = args.native or (not args.qemu and os.path.exists("/sys/class/net/vcan0"))
    if args.native and not os.path.exists("/sys/class/net/vcan0"):
        cannot_run("--native but this machine has no vcan0 (modprobe vcan; ip link add dev vcan0 type vcan; ip link set vcan0 up)")
    share = os.path.join(args.work, "share")
    shutil.rmtree(share, ignore_errors=True)
    os.makedirs(os.path.join(share, "out"))
    inputs = make_inputs(args.bin, os.path.join(share, "in"))
    print(f"vcan suite: inputs: {inputs['frames']} frames, {inputs['samples']} samples "
          f"(halves {inputs['half1_frames']} + {inputs['half2_frames']} frames)")
    try:
        if native:
            for tool in ("canplayer", "candump", "cansend", "ip"):
                if not shutil.which(tool):
                    cannot_run(f"vcan0 exists but '{tool}' is missing (apt-get install can-utils iproute2)")
            ran, info = run_native(args, scenarios, share)
        else:
            ran, info = run_qemu(args, scenarios, share)
    except CannotRun as e:
        cannot_run(str(e))
    except RuntimeError as e:
        print(f"vcan suite: FAILED: {e}", file=sys.stderr)
        return 1
    print("vcan suite: " + ", ".join(f"{k} {v}" for k, v in info.items()))

    c = Checks()
    results = {"run": info, "inputs": inputs, "scenarios": {}}
    for s in ran:
        out = os.path.join(share, "out", s)
        summary = {}
        try:
            check_scenario(c, s, out, lcm_messages(args.bin, os.path.join(out, "out.lcmlog")),
                           read_facts(out), inputs, summary)
        except (RuntimeError, KeyError, ValueError, OSError) as e:
            c.check(s, False, f"could not check: {e!r}")
        summary["facts"] = read_facts(out)
        results["scenarios"][s] = summary
    with open(os.path.join(args.work, "summary.json"), "w") as f:
        json.dump(results, f, indent=2)
    print(f"vcan suite: details in {args.work}/summary.json and {share}/out/*/")
    print(f"vcan: {c.passed} passed, {c.failed} failed")
    return 0 if c.failed == 0 and c.passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
