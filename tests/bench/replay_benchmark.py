#!/usr/bin/python3
"""Offline replay throughput: resolverd against python-can and can-utils.

For each log size (default 1 M and 10 M frames) this script

  1. writes a simulated candump -l log with resolver-sim (default bench,
     200 r/min, amplitude imbalance alpha = 0.003) or reuses the one already
     in the work directory;
  2. runs, side by side and interleaved, R times each (default 3):
       resolverd   --replay LOG --once --fast --quiet --lcm file://OUT.lcmlog
                   with [model] enabled = false (the full pipeline: parse,
                   decode, join, estimate, compensate, dq, publish every
                   angle_t / dq_t into an LCM log)
       resolverd + model fit: the same with the default config, which also fits
                   the effect model every 16 revolutions (model_fit_t; on a
                   second thread that replay waits for, so every window is fitted)
       python-can  can.CanutilsLogReader(LOG), iterating every message
       log2asc     can-utils' converter, log2asc -I LOG -O /dev/null can0
     each under /usr/bin/time -v for the peak RSS, wall time from the parent;
  3. prints medians: frames/s, wall seconds, peak RSS, and how many times
     faster resolverd is than each tool (median of the per-repetition ratios,
     so a noisy neighbour slows both sides of a pair alike).

The page cache is warmed before every run, so all tools read from memory.
Only the Python standard library is used; python-can must be importable by
/usr/bin/python3 (Debian's python3-can).

Examples:
  /usr/bin/python3 tests/bench/replay_benchmark.py --bin build/bin
  /usr/bin/python3 tests/bench/replay_benchmark.py --bin build/bin --frames 200000 --small-frames 0 --repeats 1
"""

import argparse
import json
import os
import pathlib
import re
import shutil
import statistics
import subprocess
import sys
import time

# resolver-sim's default bench: 2000 control periods/s, 3 frames each
# (RESOLVER_SAMPLE, PHASE_CURRENTS, REFERENCE_ANGLE), BENCH_INFO at 10 Hz.
FRAMES_PER_BENCH_SECOND = 3 * 2000 + 10

PYTHON_CAN_CHILD = r"""
import sys, can
n = 0
for _msg in can.CanutilsLogReader(sys.argv[1]):
    n += 1
print(n)
"""

TIME_BIN = "/usr/bin/time"
SYSTEM_PYTHON = "/usr/bin/python3"


def parse_args():
    here = pathlib.Path(__file__).resolve()
    repo = here.parents[2]
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", type=pathlib.Path, default=repo / "build" / "bin",
                   help="directory holding resolverd and resolver-sim (default: %(default)s)")
    p.add_argument("--frames", type=int, default=10_000_000,
                   help="frames in the large log (default: %(default)s)")
    p.add_argument("--small-frames", type=int, default=None,
                   help="frames in the second, smaller log for the RSS comparison "
                        "(default: frames/10; 0 = only one size)")
    p.add_argument("--repeats", type=int, default=3, help="runs per tool and size (default: %(default)s)")
    p.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/resolver-replay-bench"),
                   help="directory for the logs (reused when present) and LCM output (default: %(default)s)")
    p.add_argument("--skip-python-can", action="store_true", help="do not run python-can (slowest tool)")
    p.add_argument("--skip-log2asc", action="store_true", help="do not run log2asc")
    p.add_argument("--variants", action="store_true",
                   help="also run resolverd with --lcm memq:// (messages built and published, nothing "
                        "written) and with angle/dq decimation 10 into the LCM file, to split the cost")
    p.add_argument("--json", type=pathlib.Path, help="also write every measurement as JSON here")
    args = p.parse_args()
    if args.small_frames is None:
        args.small_frames = args.frames // 10
    if args.frames <= 0 or args.repeats <= 0 or args.small_frames < 0:
        p.error("--frames and --repeats must be positive, --small-frames >= 0")
    return args


def die(message):
    print(f"replay_benchmark: {message}", file=sys.stderr)
    sys.exit(2)


def count_lines(path):
    n = 0
    with open(path, "rb") as f:
        while True:
            chunk = f.read(1 << 24)
            if not chunk:
                return n
            n += chunk.count(b"\n")


def warm_cache(path):
    """Reads the file once so every timed run starts from the page cache."""
    with open(path, "rb") as f:
        while f.read(1 << 24):
            pass


def ensure_log(args, frames):
    """Returns (path, frame count) of a simulated log with ~`frames` frames."""
    log = args.work / f"sim_{frames}.log"
    meta = args.work / f"sim_{frames}.frames"
    if log.exists() and meta.exists():
        count = int(meta.read_text().strip())
        print(f"reusing {log} ({count} frames)", flush=True)
        return log, count
    duration = frames / FRAMES_PER_BENCH_SECOND
    cmd = [str(args.bin / "resolver-sim"), "--out", str(log), "--rpm", "200", "--duration", f"{duration:.6f}",
           "--effect", "amplitude_imbalance:alpha=0.003"]
    print("generating: " + " ".join(cmd), flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    count = count_lines(log)
    meta.write_text(f"{count}\n")
    return log, count


def timed(cmd, stdout=subprocess.DEVNULL):
    """Runs cmd under /usr/bin/time -v. Returns (wall s, peak RSS kB, CPU s, stdout text)."""
    full = [TIME_BIN, "-v"] + cmd
    t0 = time.perf_counter()
    proc = subprocess.run(full, stdout=stdout, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        die(f"{' '.join(cmd)} failed with exit code {proc.returncode}:\n{proc.stderr[-2000:]}")
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr)
    if not m:
        die(f"no 'Maximum resident set size' in /usr/bin/time -v output of {cmd[0]}")
    cpu = sum(float(x) for x in re.findall(r"(?:User|System) time \(seconds\): ([0-9.]+)", proc.stderr))
    return wall, int(m.group(1)), cpu, proc.stdout if stdout == subprocess.PIPE else ""


def run_resolverd(args, log, frames, lcm="file", config=None):
    out = args.work / "resolverd_out.lcmlog"
    report = args.work / "resolverd_report.json"
    if out.exists():
        out.unlink()  # truncating a GB-sized file inside the timed run would cost more than the replay
    cmd = [str(args.bin / "resolverd"), "--replay", str(log), "--once", "--fast", "--quiet",
           "--lcm", f"file://{out}?mode=w" if lcm == "file" else lcm, "--report", str(report)]
    if config is not None:
        cmd += ["--config", str(config)]
    wall, rss, cpu, _ = timed(cmd)
    rep = json.loads(report.read_text())
    if rep.get("frames_seen") != frames:
        die(f"resolverd saw {rep.get('frames_seen')} frames, the log has {frames}")
    lcm_bytes = 0
    if out.exists():
        lcm_bytes = out.stat().st_size
        out.unlink()
    return {"wall": wall, "rss_kb": rss, "cpu": cpu, "internal_wall": rep.get("wall_seconds"),
            "lcm_bytes": lcm_bytes}


def no_model_config(args, extra=""):
    config = args.work / ("no_model_fit.toml" if not extra else "no_model_fit_decimation10.toml")
    config.write_text("# replay_benchmark.py: the pipeline without the live model fit\n"
                      "[model]\nenabled = false\n" + extra)
    return config


def run_resolverd_pipeline(args, log, frames):
    return run_resolverd(args, log, frames, config=no_model_config(args))


def run_resolverd_model(args, log, frames):
    return run_resolverd(args, log, frames)  # default config: model fit on


def run_resolverd_memq(args, log, frames):
    return run_resolverd(args, log, frames, lcm="memq://", config=no_model_config(args))


def run_resolverd_decimated(args, log, frames):
    config = no_model_config(args, "[output]\nangle_decimation = 10\ndq_decimation = 10\n")
    return run_resolverd(args, log, frames, config=config)


def run_python_can(args, log, frames):
    wall, rss, cpu, text = timed([SYSTEM_PYTHON, "-c", PYTHON_CAN_CHILD, str(log)], stdout=subprocess.PIPE)
    if int(text.strip()) != frames:
        die(f"python-can read {text.strip()} messages, the log has {frames}")
    return {"wall": wall, "rss_kb": rss, "cpu": cpu}


def run_log2asc(args, log, frames):
    # log2asc needs the interface names to convert; resolver-sim writes can0.
    wall, rss, cpu, _ = timed(["log2asc", "-I", str(log), "-O", "/dev/null", "can0"])
    return {"wall": wall, "rss_kb": rss, "cpu": cpu}


def check_tools(args):
    for name in ("resolverd", "resolver-sim"):
        if not (args.bin / name).is_file():
            die(f"{args.bin / name} not found; build first (cmake --build build) or pass --bin")
    if not os.access(TIME_BIN, os.X_OK):
        die(f"{TIME_BIN} not found; install it: apt-get install time")
    if not args.skip_log2asc and shutil.which("log2asc") is None:
        die("log2asc not found; install can-utils or pass --skip-log2asc")
    if not args.skip_python_can:
        r = subprocess.run([SYSTEM_PYTHON, "-c", "import can"], capture_output=True)
        if r.returncode != 0:
            die("python-can is not importable by /usr/bin/python3; apt-get install python3-can or --skip-python-can")


def fmt_rate(x):
    return f"{x / 1e6:.3f} M" if x >= 1e6 else f"{x / 1e3:.1f} k"


def main():
    args = parse_args()
    check_tools(args)
    args.work.mkdir(parents=True, exist_ok=True)
    tools = [("resolverd", run_resolverd_pipeline), ("resolverd + model fit", run_resolverd_model)]
    if not args.skip_python_can:
        tools.append(("python-can", run_python_can))
    if not args.skip_log2asc:
        tools.append(("log2asc", run_log2asc))
    if args.variants:
        tools.append(("resolverd memq://", run_resolverd_memq))
        tools.append(("resolverd decim. 10", run_resolverd_decimated))

    sizes = [args.frames] + ([args.small_frames] if args.small_frames > 0 else [])
    sizes = sorted(set(sizes))
    results = []
    for size in sizes:
        log, frames = ensure_log(args, size)
        runs = {name: [] for name, _ in tools}
        for rep in range(args.repeats):
            for name, fn in tools:
                warm_cache(log)
                r = fn(args, log, frames)
                r["fps"] = frames / r["wall"]
                runs[name].append(r)
                print(f"  [{frames} frames, run {rep + 1}/{args.repeats}] {name:20s} {r['wall']:8.3f} s  "
                      f"{fmt_rate(r['fps'])}frames/s  {r['rss_kb'] / 1024:7.1f} MB  cpu {r['cpu']:.3f} s",
                      flush=True)
        base = runs["resolverd"]
        for name, _ in tools:
            rs = runs[name]
            speedups = [b["fps"] / r["fps"] for b, r in zip(base, rs)]
            results.append({
                "tool": name, "frames": frames, "log": str(log), "runs": rs,
                "fps_median": statistics.median(r["fps"] for r in rs),
                "wall_median": statistics.median(r["wall"] for r in rs),
                # /usr/bin/time reports CPU time in 10 ms steps: meaningless for tiny logs.
                "cpu_fps_median": (statistics.median(frames / r["cpu"] for r in rs)
                                   if all(r["cpu"] >= 0.1 for r in rs) else None),
                "rss_kb_median": statistics.median(r["rss_kb"] for r in rs),
                "rss_kb_max": max(r["rss_kb"] for r in rs),
                "resolverd_speedup_median": statistics.median(speedups),
                "internal_fps_median": (statistics.median(frames / r["internal_wall"] for r in rs)
                                        if name == "resolverd" else None),
            })

    print()
    print(f"median of {args.repeats} interleaved runs; page cache warm; resolverd writes every "
          "angle_t/dq_t to an LCM log file; frames/s from wall time (process start to exit), "
          "frames/CPU-s from user+sys time")
    header = f"| {'tool':20s} | {'frames':>10s} | {'frames/s':>11s} | {'wall [s]':>8s} | " \
             f"{'frames/CPU-s':>12s} | {'peak RSS [MB]':>13s} | {'resolverd is x times faster':>27s} |"
    print(header)
    print("|" + "|".join("-" * (len(c)) for c in header.split("|")[1:-1]) + "|")
    for r in results:
        print(f"| {r['tool']:20s} | {r['frames']:>10d} | {fmt_rate(r['fps_median']):>11s} | "
              f"{r['wall_median']:8.2f} | {fmt_rate(r['cpu_fps_median']) if r['cpu_fps_median'] else 'n/a':>12s} | "
              f"{r['rss_kb_median'] / 1024:13.1f} | {r['resolverd_speedup_median']:26.2f}x |")
    for r in results:
        if r["tool"] == "resolverd":
            print(f"resolverd, {r['frames']} frames: {fmt_rate(r['internal_fps_median'])}frames/s by its own "
                  f"report (replay loop only, without process start and DBC load)")

    big = [r for r in results if r["frames"] == max(x["frames"] for x in results)]
    by_tool = {r["tool"]: r for r in big}
    print()
    print("targets:")
    rd = by_tool["resolverd"]
    print(f"  full pipeline >= 2 M frames/s: {fmt_rate(rd['fps_median'])}frames/s -> "
          f"{'met' if rd['fps_median'] >= 2e6 else 'NOT met'}")
    if "python-can" in by_tool:
        s = by_tool["python-can"]["resolverd_speedup_median"]
        print(f"  >= 20x python-can: {s:.1f}x -> {'met' if s >= 20 else 'NOT met'}")
    if "log2asc" in by_tool:
        s = by_tool["log2asc"]["resolverd_speedup_median"]
        print(f"  >= 1x log2asc: {s:.2f}x -> {'met' if s >= 1 else 'NOT met'}")
    rss = {r["frames"]: r["rss_kb_max"] for r in results if r["tool"] == "resolverd"}
    if len(rss) > 1:
        lo, hi = min(rss), max(rss)
        growth = rss[hi] / rss[lo]
        print(f"  resolverd RSS flat in log length: {rss[lo] / 1024:.1f} MB at {lo} frames, "
              f"{rss[hi] / 1024:.1f} MB at {hi} frames ({growth:.2f}x for {hi / lo:.0f}x the frames) -> "
              f"{'met' if growth < 1.25 else 'NOT met'}")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1) + "\n")
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
