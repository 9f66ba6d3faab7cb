#!/usr/bin/python3
"""Scale (issue 15): resolver-model explain against log length, the default replay
(live model fit on) against can-utils' log2asc, side by side in one run.

Prints two tables (medians of --repeats runs, each under /usr/bin/time -v):

  1. explain: peak RSS, wall and CPU time and bytes per sample for logs of a 10 kHz bench
     (resolver-sim --sample-rate 10000, 200 r/min, alpha = 0.003) of each --minutes
     length, or the --logs given, per --threads count, each beside resolverd --replay
     --fast with the model fit off on the same log (the issue's ratio); a length whose
     projected RSS (from the shortest log's bytes per sample) exceeds --max-rss-gb is not
     run and is printed as projected.
  2. replay: resolverd --replay LOG --once --fast with the default config (the live
     model fit on, every window fitted), the same with --baseline-bin (an older build,
     to measure a change side by side), and log2asc on the same log; ratios are the
     median of the per-repetition ratios, so a noisy neighbour slows both sides alike.

  3. with --stats-chunk S (issue 23): resolver-model stats LOG --chunk S (one run per chunk,
     the samples of two chunks in memory) against the same log's resolverd --replay --fast
     with the model fit off, per --minutes length: peak RSS, wall and their ratio, and
     merge of the file's runs.

Examples:
  /usr/bin/python3 tests/bench/scale_benchmark.py --bin build/bin
  /usr/bin/python3 tests/bench/scale_benchmark.py --bin build/bin --skip-replay --skip-explain --stats-chunk 30 --minutes 1 5 60
  /usr/bin/python3 tests/bench/scale_benchmark.py --bin build/bin --minutes 1 10 --baseline-bin ../old/build/bin
  # explain on 1 and 2 threads on a log the seed model does not explain, beside the replay
  /usr/bin/python3 tests/bench/scale_benchmark.py --bin build/bin --skip-replay --logs b30.log --threads 1 2
"""
import argparse
import pathlib
import statistics
import subprocess
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import replay_benchmark as rb  # noqa: E402  (its timed(), resolverd and log2asc runners)

SAMPLE_RATE = 10000.0  # [Hz] the bench
FRAMES_PER_SECOND = 3 * SAMPLE_RATE + 10  # RESOLVER_SAMPLE, PHASE_CURRENTS, REFERENCE_ANGLE + BENCH_INFO at 10 Hz


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", type=pathlib.Path, required=True)
    p.add_argument("--baseline-bin", type=pathlib.Path, help="an older build's bin folder for the replay table")
    p.add_argument("--minutes", type=float, nargs="+", default=[1.0, 10.0, 60.0], help="log lengths [min]")
    p.add_argument("--replay-minutes", type=float, default=1.0, help="log length for the replay table [min]")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--max-rss-gb", type=float, default=16.0, help="do not run explain beyond this projected RSS")
    p.add_argument("--work", type=pathlib.Path, default=pathlib.Path("/tmp/resolver-scale-bench"))
    p.add_argument("--skip-replay", action="store_true", help="no replay table")
    p.add_argument("--skip-explain", action="store_true", help="no explain table")
    p.add_argument("--stats-chunk", type=float, default=0.0,
                   help="[s] also the table of resolver-model stats --chunk S against the replay with the fit off")
    p.add_argument("--effects", default="amplitude_imbalance", help="the model for stats (default the seed's)")
    p.add_argument("--threads", type=int, nargs="+", default=[],
                   help="explain table: one row per thread count (resolver-model --threads N; none: its default), "
                        "each beside resolverd --replay --fast with the model fit off on the same log")
    p.add_argument("--logs", type=pathlib.Path, nargs="+", default=[],
                   help="explain table: these logs instead of generated ones of --minutes (e.g. one with an effect "
                        "the seed model lacks)")
    return p.parse_args()


def make_log(args, minutes):
    log = args.work / f"bench10k_{minutes:g}min.log"
    if not log.exists():
        cmd = [str(args.bin / "resolver-sim"), "--out", str(log), "--rpm", "200", "--duration", f"{minutes * 60:g}",
               "--sample-rate", f"{SAMPLE_RATE:g}", "--effect", "amplitude_imbalance:alpha=0.003"]
        print("generating: " + " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return log


def explain_table(args):
    """explain per log (and per --threads count), each repetition beside the replay with the fit off."""
    per_sample = None
    threads = args.threads or [None]
    print("\nresolver-model explain, 10 kHz bench, beside resolverd --replay --fast with the model fit off on the same "
          "log (median of %d; ratios: median of the per-repetition ratios)" % args.repeats)
    print("| log | samples | threads | wall [s] | CPU [s] | peak RSS [MB] | bytes/sample | x replay (fit off) |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    logs = [(log, None) for log in args.logs] or [(None, m) for m in sorted(args.minutes)]
    for given, minutes in logs:
        log = given or make_log(args, minutes)
        frames = rb.count_lines(log)
        samples = (frames - frames // 3001) / 3 if given else SAMPLE_RATE * minutes * 60
        name = log.name if given else f"{minutes:g} min"
        # Projected from the largest log run so far, with 20 % margin (bytes per sample fall with length).
        if per_sample is not None and 1.2 * per_sample * samples > args.max_rss_gb * 1e9:
            print(f"| {name} | {samples:.3g} | | not run | | {per_sample * samples / 1e6:.0f} projected | "
                  f"{per_sample:.0f} | |", flush=True)
            continue
        rb.warm_cache(log)
        runs = {t: [] for t in threads}
        replay = []
        for _ in range(args.repeats):
            replay.append(rb.run_resolverd_pipeline(argparse.Namespace(bin=args.bin, work=args.work), log, frames))
            for t in threads:
                cmd = [str(args.bin / "resolver-model"), "explain", str(log)] + ([] if t is None else ["--threads", str(t)])
                runs[t].append(rb.timed(cmd))
        for t in threads:
            wall = statistics.median(r[0] for r in runs[t])
            rss_mb = statistics.median(r[1] for r in runs[t]) / 1024
            per_sample = rss_mb * 1e6 / samples
            ratio = statistics.median(r[0] / p["wall"] for r, p in zip(runs[t], replay))
            print(f"| {name} | {samples:.3g} | {'default' if t is None else t} | {wall:.2f} | "
                  f"{statistics.median(r[2] for r in runs[t]):.2f} | {rss_mb:.0f} | {per_sample:.0f} | {ratio:.1f} |",
                  flush=True)


def stats_table(args):
    print(f"\nresolver-model stats --chunk {args.stats_chunk:g} --effects {args.effects} against resolverd --replay "
          f"--fast with the model fit off, 10 kHz bench (median of {args.repeats})")
    print("| log | samples | stats wall [s] | stats peak RSS [MB] | replay (fit off) wall [s] | stats / replay | "
          "merge wall [s] | merge peak RSS [MB] |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    out = args.work / "chunked.stats"
    for minutes in sorted(args.minutes):
        log = make_log(args, minutes)
        frames = rb.count_lines(log)
        rb.warm_cache(log)
        stats, replay, merge = [], [], []
        for _ in range(args.repeats):
            stats.append(rb.timed([str(args.bin / "resolver-model"), "stats", str(log), "--chunk", f"{args.stats_chunk:g}",
                                   "--effects", args.effects, "--out", str(out)]))
            replay.append(rb.run_resolverd_pipeline(argparse.Namespace(bin=args.bin, work=args.work), log, frames))
            merge.append(rb.timed([str(args.bin / "resolver-model"), "merge", str(out)]))
        ratio = statistics.median(s[0] / r["wall"] for s, r in zip(stats, replay))
        print(f"| {minutes:g} min | {SAMPLE_RATE * minutes * 60:.3g} | {statistics.median(s[0] for s in stats):.1f} | "
              f"{statistics.median(s[1] for s in stats) / 1024:.0f} | {statistics.median(r['wall'] for r in replay):.1f} | "
              f"{ratio:.2f} | {statistics.median(m[0] for m in merge):.2f} | "
              f"{statistics.median(m[1] for m in merge) / 1024:.0f} |", flush=True)


def replay_table(args):
    log = make_log(args, args.replay_minutes)
    frames = rb.count_lines(log)
    rb.warm_cache(log)
    tools = {"resolverd (live fit on)": args.bin}
    if args.baseline_bin:
        tools["baseline resolverd (live fit on)"] = args.baseline_bin
    res = {name: [] for name in list(tools) + ["log2asc"]}
    for _ in range(args.repeats):
        for name, b in tools.items():
            res[name].append(rb.run_resolverd(argparse.Namespace(bin=b, work=args.work), log, frames))
        res["log2asc"].append(rb.run_log2asc(args, log, frames))
    print(f"\nreplay of a {args.replay_minutes:g} min 10 kHz log ({frames} frames), median of {args.repeats}")
    print("| program | frames/s | wall [s] | CPU [s] | peak RSS [MB] | x log2asc |")
    print("|---|---|---|---|---|---|")
    for name, runs in res.items():
        ratio = statistics.median(l2["wall"] / r["wall"] for r, l2 in zip(runs, res["log2asc"]))
        wall = statistics.median(r["wall"] for r in runs)
        print(f"| {name} | {frames / wall / 1e6:.2f} M | {wall:.2f} | {statistics.median(r['cpu'] for r in runs):.2f} "
              f"| {statistics.median(r['rss_kb'] for r in runs) / 1024:.0f} | {ratio:.2f} |")
    if args.baseline_bin:
        name = "baseline resolverd (live fit on)"
        r = statistics.median(b["wall"] / a["wall"] for a, b in zip(res["resolverd (live fit on)"], res[name]))
        print(f"\nresolverd vs baseline: {r:.2f}x faster (median of the per-repetition ratios)")


def main():
    args = parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    if not args.skip_replay:
        replay_table(args)
    if not args.skip_explain:
        explain_table(args)
    if args.stats_chunk > 0:
        stats_table(args)


if __name__ == "__main__":
    main()
