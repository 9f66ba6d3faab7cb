#!/usr/bin/python3
"""The fleet at scale (issue 24): resolver-model fleet single process against the Dask
client (python3 -m resolver_bench.fleet: one `resolver-model stats` task per log on the
workers, `fleet --merge-only` on the client) with --local 1 and --local 2, on N unit logs.

Makes N logs of --seconds each with resolver-sim (default bench, 2 kHz; seed, alpha and
beta varied per unit, unit 7 with alpha = 0.03 and unit 11 with beta = 0.01 as outliers)
and WORK/manifest.csv, once (reused while the manifest exists). Then runs each command
under /usr/bin/time -v and prints, per command, the wall time, CPU time, time -v's peak
RSS (the largest single process of the tree), the peak of the RSS summed over the
whole process tree (sampled every 0.2 s: Dask's scheduler, nannies and workers count
together) and, sampled the same way, the peaks of the client (the command's own
process), of the largest other Python process (a Dask worker or nanny) and of the
largest resolver-model process; with --repeat R each command runs R times (in turn) and
the medians are printed. Checks that the three fleet.json are identical. Not run by ctest.

  /usr/bin/python3 tests/bench/fleet_scale.py --bin build/bin --work /tmp/fleet_scale --units 200 --seconds 30
"""
import argparse
import os
import random
import re
import subprocess
import sys
import time

EFFECTS = "amplitude_imbalance,quadrature"


def make_fleet(bin_dir, work, units, seconds):
    manifest = os.path.join(work, "manifest.csv")
    if os.path.exists(manifest):
        return manifest
    logs = os.path.join(work, "logs")
    os.makedirs(logs, exist_ok=True)
    rng = random.Random(24)
    rows = []
    t0 = time.monotonic()
    for i in range(1, units + 1):
        alpha = 0.003 + rng.gauss(0, 0.0004)
        beta = 0.001 + rng.gauss(0, 0.0002)
        if i == 7:
            alpha = 0.03  # a far-off gain
        if i == 11:
            beta = 0.01  # a large quadrature
        name = f"unit{i:03d}.log"
        subprocess.run([os.path.join(bin_dir, "resolver-sim"), "--out", os.path.join(logs, name), "--duration",
                        str(seconds), "--seed", str(1000 + i), "-e", f"amplitude_imbalance:alpha={alpha:.6f}",
                        "-e", f"quadrature:beta={beta:.6f}"], check=True, capture_output=True)
        rows.append((f"unit{i:03d}", os.path.join("logs", name)))
    with open(manifest + ".tmp", "w") as f:
        f.write("unit,log\n" + "".join(f"{u},{l}\n" for u, l in rows))
    os.replace(manifest + ".tmp", manifest)
    print(f"made {units} logs of {seconds} s in {time.monotonic() - t0:.0f} s", file=sys.stderr)
    return manifest


def process_tree(root):
    children = {}
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            with open(f"/proc/{pid}/stat") as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            children.setdefault(ppid, []).append(int(pid))
        except (OSError, IndexError, ValueError):
            pass
    out, todo = [], [root]
    while todo:
        p = todo.pop()
        out.append(p)
        todo += children.get(p, [])
    return out


def rss_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            m = re.search(r"VmRSS:\s+(\d+)", f.read())
        return int(m.group(1)) if m else 0
    except OSError:
        return 0


def cmdline(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def sample(root, peaks):
    """One sample of the tree's RSS: the sum, the root (the client), the largest other
    Python process (a Dask worker or nanny) and the largest resolver-model process."""
    tree = process_tree(root)
    rss = {p: rss_kib(p) for p in tree}
    peaks["sum"] = max(peaks["sum"], sum(rss.values()))
    for p in tree[1:]:  # tree[0] is /usr/bin/time
        line = cmdline(p)
        role = ("resolver_model" if line.split(" ")[0].endswith("resolver-model")
                else "client" if "resolver_bench.fleet" in line else "worker" if "python" in line else None)
        if role:
            peaks[role] = max(peaks[role], rss[p])


def measured(label, cmd, work, env):
    timefile = os.path.join(work, f"time_{label}.txt")
    peaks = {"sum": 0, "client": 0, "worker": 0, "resolver_model": 0}
    with open(os.path.join(work, f"out_{label}.txt"), "w") as log:
        t0 = time.monotonic()
        proc = subprocess.Popen(["/usr/bin/time", "-v", "-o", timefile] + cmd, stdout=log, stderr=subprocess.STDOUT,
                                env=env)
        while proc.poll() is None:
            sample(proc.pid, peaks)
            time.sleep(0.2)
        wall = time.monotonic() - t0
    with open(timefile) as f:
        tv = f.read()
    cpu = float(re.search(r"User time \(seconds\): (\S+)", tv).group(1)) + \
        float(re.search(r"System time \(seconds\): (\S+)", tv).group(1))
    peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", tv).group(1))
    with open("/proc/loadavg") as f:
        load = f.read().split()[0]
    return {"label": label, "rc": proc.returncode, "wall": wall, "cpu": cpu, "peak": peak / 1024,
            "peak_sum": peaks["sum"] / 1024, "client": peaks["client"] / 1024, "worker": peaks["worker"] / 1024,
            "resolver_model": peaks["resolver_model"] / 1024, "load": load}


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if len(v) % 2 else (v[len(v) // 2 - 1] + v[len(v) // 2]) / 2


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="build/bin: resolver-sim and resolver-model")
    ap.add_argument("--work", required=True, help="logs, manifest and the runs' folders")
    ap.add_argument("--units", type=int, default=200)
    ap.add_argument("--seconds", type=float, default=30.0, help="length of each unit's log [s]")
    ap.add_argument("--python-path", default=os.path.join(os.path.dirname(__file__), "..", "..", "tools", "python"),
                    help="where resolver_bench is (default: the source tree's tools/python)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each command (medians printed)")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    manifest = make_fleet(args.bin, args.work, args.units, args.seconds)
    model = os.path.abspath(os.path.join(args.bin, "resolver-model"))
    env = dict(os.environ, PYTHONPATH=os.path.abspath(args.python_path), PYTHONDONTWRITEBYTECODE="1")
    runs = [("single", [model, "fleet", manifest, "--effects", EFFECTS])]
    for workers in (1, 2):
        runs.append((f"dask_local{workers}", ["/usr/bin/python3", "-m", "resolver_bench.fleet", manifest, "--local",
                                              str(workers), "--effects", EFFECTS, "--resolver-model", model]))
    results = {label: [] for label, _ in runs}
    for _ in range(args.repeat):
        for label, cmd in runs:
            out = os.path.join(args.work, f"out_{label}")
            subprocess.run(["rm", "-rf", out], check=True)
            results[label].append(measured(label, cmd + ["--out", out], args.work, env))
            print(results[label][-1], file=sys.stderr)
    print(f"{args.units} units, {args.seconds:g} s logs, --effects {EFFECTS}, median of {args.repeat} run(s)")
    print("| run | wall [s] | CPU [s] | peak RSS, largest process [MiB] | whole tree [MiB] | client [MiB] "
          "| largest Dask worker/nanny [MiB] | largest resolver-model [MiB] | exit | load after |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, rs in results.items():
        m = {k: median([r[k] for r in rs]) for k in ("wall", "cpu", "peak", "peak_sum", "client", "worker",
                                                     "resolver_model")}
        print(f"| {label} | {m['wall']:.0f} | {m['cpu']:.0f} | {m['peak']:.0f} | {m['peak_sum']:.0f} | "
              f"{m['client']:.0f} | {m['worker']:.0f} | {m['resolver_model']:.0f} | "
              f"{','.join(str(r['rc']) for r in rs)} | {rs[-1]['load']} |")
    same = all(same_results(args.work, label, runs[0][0]) for label, _ in runs[1:])
    print("fleet.json and every unit.json identical in the three runs" if same else "results DIFFER between the runs")
    return 0 if same and all(r["rc"] == 0 for rs in results.values() for r in rs) else 1


def same_results(work, label, reference):
    """fleet.json and every unit.json of run `label` byte-identical to those of `reference`."""
    a, b = os.path.join(work, f"out_{label}"), os.path.join(work, f"out_{reference}")
    files = ["fleet.json"] + [os.path.join(u, "unit.json") for u in sorted(os.listdir(b))
                              if os.path.exists(os.path.join(b, u, "unit.json"))]
    for name in files:
        with open(os.path.join(a, name), "rb") as x, open(os.path.join(b, name), "rb") as y:
            if x.read() != y.read():
                print(f"{label}: {name} differs from {reference}'s", file=sys.stderr)
                return False
    return True


if __name__ == "__main__":
    sys.exit(main())
