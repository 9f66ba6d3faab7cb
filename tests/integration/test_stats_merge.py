#!/usr/bin/env python3
"""Statistics that merge (issue 24): resolver-model stats LOG --out F.stats, merge A.stats B.stats ...

One sensor (alpha = 0.03, beta = 0.01, the simulator's 3000 rad/s R/D loop) recorded in runs
that differ as a bench's runs do: speed (600 and 900 r/min), the reference's zero (theta_0, any
value) and the noise seed. Through the real programs:

  1. merge of two runs' statistics = the pooled fit of the logs (fit A.log B.log): every shared
     parameter within 0.05 of its standard error, the truth within the tolerance below, each
     run's own reference zero; the order of the files does not matter; the file describes itself;
  2. a third run whose alpha changed (0.033) is named alone, on alpha;
  3. the model without the tracking loop: the merged residual stays far above the floor and
     the runs disagree on alpha (control: a missing speed-dependent effect);
  4. statistics of a model without quadrature: merge ranks the candidates from the files and
     names quadrature;
  5. two halves of one log (--to / --from) merged against the whole log's fit (measured, see
     the check's comment);
  6. bad input: another file version, a log given as statistics, a truncated file, another
     layout (exit 2); a run of another p_r (exit 1); a missing file (exit 3); each names the file.
Standard library only.
"""
import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_test_kit import (Checks, run, simulate_run, RUN_MODEL, RUN_ALPHA, RUN_BETA, RUN_TOL,  # noqa: E402
                            RUN_TOL_ZERO)

MODEL, ALPHA, BETA, TOL, TOL_ZERO = RUN_MODEL, RUN_ALPHA, RUN_BETA, RUN_TOL, RUN_TOL_ZERO  # bench_test_kit.py
# Merge against the pooled fit: the pooled fit iterates to convergence, the merge takes one
# pooled Gauss-Newton step from each run's own solution: second order in how far those lie
# apart. Measured 0.01 standard errors and less (run_statistics_test.cpp); 0.05 is a decision-free margin.
TOL_SE = 0.05

c = Checks()


def simulate(sim, out, rpm, seed, alpha, theta_0, extra=()):
    simulate_run(sim, out, rpm, seed, alpha, BETA, theta_0, extra)


def stats(model, log, out, effects=MODEL, extra=()):
    r = run([model, "stats", log, "--effects", effects, "--out", out, *extra])
    if r.returncode != 0:
        sys.exit(f"resolver-model stats {log} failed ({r.returncode}): {r.stderr}")
    return out


def merge(model, files, extra=()):
    r = run([model, "merge", *files, "--json", *extra])
    if r.returncode != 0:
        sys.exit(f"resolver-model merge {files} failed ({r.returncode}): {r.stderr}")
    return json.loads(r.stdout)


def fit(model, logs, effects=MODEL):
    r = run([model, "fit", *logs, "--effects", effects, "--json"])
    if r.returncode != 0:
        sys.exit(f"resolver-model fit {logs} failed ({r.returncode}): {r.stderr}")
    return json.loads(r.stdout)


def disagreeing(merged):
    return {(d["run"], d["parameter"]) for d in merged["comparisons"] if d["disagrees"]}


def refused(model, files, code, words, what):
    r = run([model, "merge", *files])
    c.check(r.returncode == code and all(w in r.stderr for w in words),
            f"{what}: exit {code} naming {words} ({r.returncode}: {r.stderr.strip()[:300]})")


def check_merge_is_pooled_fit(model, work, a, b):
    sa, sb = stats(model, a, work / "a.stats"), stats(model, b, work / "b.stats")
    merged, pooled = merge(model, [sa, sb]), fit(model, [a, b])
    for name, p in pooled["params"].items():
        m = merged["params"][name]
        c.check(abs(m["value"] - p["value"]) <= TOL_SE * p["stderr"],
                f"merge = pooled fit on {name}: {m['value']:.9g} against {p['value']:.9g} +- {p['stderr']:.2g} "
                f"({abs(m['value'] - p['value']) / p['stderr']:.3f} se)")
    for name, truth in (("amplitude_imbalance.alpha", ALPHA), ("quadrature.beta", BETA)):
        v = merged["params"][name]["value"]
        c.check(abs(v - truth) < TOL, f"merged {name} {v:.7g} is the truth {truth} within {TOL}")
    for f, theta_0 in ((sa, 0.3), (sb, -1.2)):
        zero = merged["nuisance"][f"nuisance.rd_constant[{f}]"]["value"]
        c.check(abs(zero + theta_0) < TOL_ZERO, f"{f.name}: its own reference zero {zero:.6g} = -theta_0 = {-theta_0}")
    c.check(merged["verdict"] == "explained", f"the right model merged: explained ({merged['summary']})")
    c.check(not disagreeing(merged), f"no run disagrees with the right model: {sorted(disagreeing(merged))}")
    swapped = merge(model, [sb, sa])
    c.check(all(abs(swapped["params"][n]["value"] - v["value"]) <= 2e-8 * abs(v["value"])
                for n, v in merged["params"].items()),
            "merge b a gives merge a b's parameters (to the 9 digits printed)")
    head = json.loads(sa.read_text())
    c.check(head["format"] == "resolver-model stats" and head["version"] == 3 and head["tool"].startswith("resolver-model")
            and len(head["runs"]) == 1 and head["runs"][0]["bench"] == {"p_r": 3, "p": 3} and head["layout"]["id"]
            and head["log"] == str(a), "the statistics file says what it is: format, version, tool, layout, log, bench")
    return sa, sb


def cut_gap_and_swap(src, dst, gap_from, gap_to, swap_at):
    """A logging gap (frames from gap_from to gap_to [s] lost) and two frames out of order at swap_at."""
    lines = src.read_text().splitlines()
    t0 = float(lines[0][1:lines[0].index(")")])
    at = lambda l: float(l[1:l.index(")")]) - t0  # noqa: E731
    kept = [l for l in lines if not gap_from <= at(l) < gap_to]
    i = next(k for k, l in enumerate(kept) if at(l) >= swap_at)
    kept[i], kept[i + 1] = kept[i + 1], kept[i]
    dst.write_text("\n".join(kept) + "\n")


def check_faulty_log_through_passes(args, w):
    """A bench log at real magnitudes with its faults, in memory and through --chunk's passes.

    8 % gain error, 20 mrad quadrature, 1-1.5 % offsets; out and back through zero and a
    speed step; spikes five times a second, a 0.4 s logging gap and two frames out of order.
    The model lacks the R/D loop, so candidates are ranked and the best are refitted: explain
    --chunk 3 must give the in-memory verdict, the model's values (passes stop at a step
    under 0.05 se: 0.1 se as the streaming table's STREAM_SE), the same candidates refitted
    (the first ones as listed, "one_step" false) with their values within 0.5 se (a pass
    whose step goes uphill keeps the last good merge: steps of ~0.1 se measured), and the
    faults counted by both. Before the refits were chosen from the listed order in memory
    too, the k3 harmonic was refitted by one path and stepped by the other: 6.7 se apart.
    """
    model = args.bin / "resolver-model"
    clean, odd = w / "faults_clean.log", w / "faults.log"
    r = run([args.bin / "resolver-sim", "--profile", "600:3,600--600:1,-600:3,-600-300:1,300:4", "--sample-rate", 4000,
             "-e", "amplitude_imbalance:alpha=0.08", "-e", "quadrature:beta=0.02", "-e", "offsets:o_s=0.01,o_c=-0.015",
             "-e", "outliers:rate=5,size=3000", "-o", clean])
    if r.returncode != 0:
        sys.exit(f"resolver-sim failed: {r.stderr}")
    cut_gap_and_swap(clean, odd, 5.0, 5.4, 8.0)
    effects = "amplitude_imbalance,quadrature,offsets"
    mem_r = run([model, "explain", odd, "--effects", effects, "--json"])
    chk_r = run([model, "explain", odd, "--effects", effects, "--chunk", 3, "--json"])
    if not c.check(mem_r.returncode == 0 and chk_r.returncode == 0,
                   f"a faulty log: explain with and without --chunk 3 run ({mem_r.returncode}, {chk_r.returncode}: "
                   f"{chk_r.stderr.strip()[-200:]})"):
        return
    mem, chk = json.loads(mem_r.stdout), json.loads(chk_r.stdout)
    c.check(mem["verdict"] == chk["verdict"] == "missing_effect",
            f"a faulty log: explain --chunk 3 says {chk['verdict']}, in memory {mem['verdict']}")
    for name, p in mem["params"].items():
        d = abs(chk["params"][name]["value"] - p["value"]) / p["stderr"]
        c.check(d < 0.1, f"a faulty log through the passes: {name} {d:.3f} se from explain in memory")
    refitted = lambda j: [x["effect"] for x in j["candidates"] if not x["one_step"]][:3]  # noqa: E731
    c.check(refitted(mem) == refitted(chk) and len(refitted(mem)) == 3,
            f"a faulty log: the same candidates refitted, in order ({refitted(mem)} in memory, {refitted(chk)} chunked)")
    by_effect = {x["effect"]: x for x in chk["candidates"]}
    for x in mem["candidates"]:
        if x["effect"] not in refitted(mem) or x["effect"] not in by_effect:
            continue
        for name, p in x["params"].items():
            d = abs(by_effect[x["effect"]]["params"][name]["value"] - p["value"]) / p["stderr"]
            c.check(d < 0.5, f"a faulty log: candidate {x['effect']} {name} {d:.3f} se from explain in memory")
    stepped = [x["effect"] for x in mem["candidates"] if x["one_step"]]
    c.check(bool(stepped) and all(by_effect[e]["one_step"] for e in stepped if e in by_effect),
            f"a faulty log: the candidates left at one linearised step are said so by both ({stepped[:4]})")
    for what, j in (("in memory", mem), ("chunked", chk)):
        said = all(("(one linearised step: " in x["reason"]) == x["one_step"] and ("(fit: " in x["reason"]) != x["one_step"]
                   for x in j["candidates"] if x["params"])
        c.check(said, f"a faulty log {what}: each candidate's reason calls its values a fit or one step as they are")
    for what, notes in (("in memory", mem["notes"]), ("chunked", chk["notes"])):
        c.check(any("outliers for" in n for n in notes) and any("input problems counted" in n for n in notes),
                f"a faulty log {what}: the spikes and the reader's problems are counted in the notes")
    # The same frames as Vector ASC (can-utils' log2asc, an independent writer) through the
    # same chunks and passes: the reader is another, the samples and so every value the same.
    # fit --chunk 3 on both (~12 s each), not explain: the ASC reader only makes the samples,
    # and explain --chunk's candidate refits cost ~200 s a file here (a tracking loop refitted
    # over passes) for nothing more about the reader.
    asc = w / "faults.asc"
    r = run(["log2asc", "-I", odd, "-O", asc, "can0"])
    fits = [run([model, "fit", f, "--effects", effects, "--chunk", 3, "--json"]) if r.returncode == 0 else r
            for f in (odd, asc)]
    if c.check(all(f.returncode == 0 for f in fits),
               f"the faulty log as candump and as ASC through fit --chunk 3 ({[f.returncode for f in fits]}: "
               f"{fits[-1].stderr.strip()[-200:]})"):
        by_log, by_asc = (json.loads(f.stdout) for f in fits)
        same = all(abs(by_asc["params"][n]["value"] - p["value"]) <= 1e-9 * abs(p["value"])
                   for n, p in by_log["params"].items())
        runs = lambda j: [(x["fitted_samples"], x["span_s"]) for x in j["runs"]]  # noqa: E731
        ranked = lambda j: [x["effect"] for x in j["candidates"]]  # noqa: E731
        c.check(same and runs(by_asc) == runs(by_log) and ranked(by_asc) == ranked(by_log),
                "the faulty log as ASC through fit --chunk 3: the candump's values, chunks and ranked candidates")

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True, type=Path)
    ap.add_argument("--work", required=True, type=Path)
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    sim, model, w = args.bin / "resolver-sim", args.bin / "resolver-model", args.work
    a, b, changed, other_p_r = (w / x for x in ("a.log", "b.log", "changed.log", "p_r2.log"))
    simulate(sim, a, 600, 1, ALPHA, 0.3)
    simulate(sim, b, 900, 2, ALPHA, -1.2)
    simulate(sim, changed, 600, 3, 0.033, 2.0)
    simulate(sim, other_p_r, 600, 4, ALPHA, 0.3, ["--p-r", 2])

    # 1. merge = pooled fit
    sa, sb = check_merge_is_pooled_fit(model, w, a, b)

    # 2. a run whose alpha changed is named alone
    sc = stats(model, changed, w / "changed.stats")
    three = merge(model, [sa, sb, sc])
    flagged = disagreeing(three)
    c.check((str(sc), "amplitude_imbalance.alpha") in flagged and all(f == str(sc) for f, _ in flagged),
            f"only the run whose alpha changed disagrees, on alpha: {sorted(flagged)}")

    # 3. control: the model without the R/D loop
    effects = "amplitude_imbalance,quadrature"
    no_loop = merge(model, [stats(model, a, w / "a_noloop.stats", effects), stats(model, b, w / "b_noloop.stats", effects)])
    pos = next(s for s in no_loop["signals"] if s["signal"] == "position_error")
    c.check(no_loop["verdict"] != "explained" and pos["rms"] > 3 * pos["floor"],
            f"control: without the loop the merged residual is {pos['rms'] / pos['floor']:.1f}x the floor, not explained")
    c.check({(str(w / "a_noloop.stats"), "amplitude_imbalance.alpha"),
             (str(w / "b_noloop.stats"), "amplitude_imbalance.alpha")} <= disagreeing(no_loop),
            "control: the runs at two speeds disagree on alpha without the speed-dependent loop")

    # 4. a missing effect ranked from the statistics alone
    effects = "amplitude_imbalance,tracking_loop"
    no_beta = merge(model, [stats(model, a, w / "a_nobeta.stats", effects), stats(model, b, w / "b_nobeta.stats", effects)])
    first = no_beta["candidates"][0] if no_beta["candidates"] else {}
    c.check(no_beta["verdict"] == "missing_effect" and first.get("effect") == "quadrature" and first.get("proposed"),
            f"statistics without quadrature: merge names it first ({no_beta['verdict']}: {no_beta['summary'][:160]})")
    # The same files with quadrature fitted (a candidate's columns, one step from zero):
    # the value is right to first order (beta^2 terms ~ 1e-4 left).
    with_beta = merge(model, [w / "a_nobeta.stats", w / "b_nobeta.stats"], ["--effects", MODEL])
    c.check(abs(with_beta["params"]["quadrature.beta"]["value"] - BETA) < 3e-4,
            f"--effects adds a candidate from the same files: beta {with_beta['params']['quadrature.beta']['value']:.5g}")
    # Its residual is linearised, not evaluated at that beta: never "explained" from it.
    c.check(with_beta["verdict"] != "explained" and any("linearised step from zero" in n for n in with_beta["notes"]),
            f"a candidate fitted from the files is not called explained ({with_beta['verdict']})")

    # explain on the statistics of a chunked log ranks as explain does in memory, and
    # refits a candidate whose linearised step is not its fit (here a 3 % quadrature
    # beside a 10 % gain error, real magnitudes: the step leaves beta^2 ~ 1e-3 rad) by a
    # further pass over the log with it in the model: the same verdict, the same effect
    # named, the same beta (one step from each chunk's converged fit against the whole
    # log iterated: second order, measured 0.01 standard errors).
    big = w / "big_beta.log"
    simulate_run(args.bin / "resolver-sim", big, 600, 5, 0.1, 0.03, 2.5)
    for log, what in ((a, "1 % quadrature"), (big, "3 % quadrature, 10 % gain")):
        in_memory = run([model, "explain", log, "--effects", effects, "--json"])
        streamed = run([model, "explain", log, "--effects", effects, "--chunk", 2, "--json"])
        if not c.check(in_memory.returncode == 0 and streamed.returncode == 0,
                       f"{what}: explain with and without --chunk run ({in_memory.returncode}, {streamed.returncode})"):
            continue
        mem, chk = json.loads(in_memory.stdout), json.loads(streamed.stdout)
        mem_first, chk_first = mem["candidates"][0], chk["candidates"][0]
        c.check(chk["verdict"] == mem["verdict"] == "missing_effect" and chk_first["effect"] == mem_first["effect"],
                f"{what}: explain --chunk 2 says {chk['verdict']}, {chk_first['effect']} first; in memory "
                f"{mem['verdict']}, {mem_first['effect']}")
        mb, cb = mem_first["params"]["quadrature.beta"], chk_first["params"]["quadrature.beta"]
        c.check(abs(cb["value"] - mb["value"]) < 0.1 * mb["stderr"],
                f"{what}: explain --chunk 2 gives beta {cb['value']:.9g} against {mb['value']:.9g} +- {mb['stderr']:.2g} "
                f"in memory")
        if log == big:
            c.check("Fitted to convergence" in chk["summary"] and abs(cb["value"] - 0.03) < 1e-4,
                    f"{what}: refitted to convergence by a second pass (beta {cb['value']:.6g}, truth 0.03): "
                    f"{chk['summary'][-110:]}")

    # 5. halves of one log against the whole: each half is its own run (its own reference
    # zero, amplitude, operating point, folds, floor), so this is not a rounding-level
    # identity; it is a check that nothing is lost when a long log is cut: within 1 se.
    h1 = stats(model, a, w / "a1.stats", extra=["--to", 3])
    h2 = stats(model, a, w / "a2.stats", extra=["--from", 3])
    halves, whole = merge(model, [h1, h2]), fit(model, [a])
    for name, p in whole["params"].items():
        d = abs(halves["params"][name]["value"] - p["value"]) / p["stderr"]
        c.check(d < 1.0, f"two halves merged against the whole log on {name}: {d:.3f} se apart")

    # Chunks (--chunk, a long log in bounded memory): each chunk a run; merged, the same
    # fit as the whole log. Chunks of 2 s of a 6 s log: three runs.
    chunked = stats(model, a, w / "a_chunks.stats", extra=["--chunk", 2])
    runs = json.loads(chunked.read_text())["runs"]
    merged_chunks = merge(model, [chunked])
    samples = sum(r["counts"]["samples"] for r in runs)
    fitted = sum(r["counts"]["fitted_rows"] for r in runs)
    # Every sample is in a chunk; a chunk's first and last samples may not count as
    # moving (the speed estimate needs neighbours), so the fitted ones may differ by a few.
    c.check(len(runs) == 3 and samples == whole["covers"]["samples_in"]
            and abs(fitted - whole["covers"]["fitted"]) <= 0.001 * fitted,
            f"--chunk 2 on 6 s: 3 runs, {samples} samples (the log's {whole['covers']['samples_in']}), {fitted} fitted "
            f"(the whole log's {whole['covers']['fitted']})")
    for name, p in whole["params"].items():
        d = abs(merged_chunks["params"][name]["value"] - p["value"]) / p["stderr"]
        c.check(d < 1.0, f"chunks of 2 s merged against the whole log on {name}: {d:.3f} se apart")

    # fit|explain --chunk: the same in one command, for every log given.
    r = run([model, "fit", a, b, "--chunk", 2, "--effects", MODEL, "--json"])
    both = json.loads(r.stdout) if r.returncode == 0 else {"runs": []}
    c.check(len(both["runs"]) == 6 and {x["file"].split(":")[0] for x in both["runs"]} == {str(a), str(b)},
            f"fit a.log b.log --chunk 2: 6 runs, 3 of each log ({r.returncode}: {r.stderr.strip()[:200]})")
    # The same merge; the model is nonlinear, so explain --chunk says how far the chunks'
    # own fits lie from it: close enough (here ~1e-3 floors) that one step is exact to
    # < 0.05 se and no further pass is made, the merge is the files' merge to rounding;
    # otherwise Gauss-Newton over passes of the log moves it (second order, < 0.01 se).
    r = run([model, "explain", a, "--chunk", 2, "--effects", MODEL, "--json"])
    one = json.loads(r.stdout) if r.returncode == 0 else {"params": {}, "notes": []}
    one_step = any("its merge is one step from each run's own fit" in n for n in one["notes"])
    passes = any("made again at the merged fit over" in n for n in one["notes"])
    c.check(one_step != passes, f"explain --chunk 2 says whether it relinearised the nonlinear model: "
                                f"{[n[:90] for n in one['notes']]}")
    c.check(all(abs(one["params"].get(n, {"value": 1e9})["value"] - v["value"])
                <= (1e-12 + 1e-8 * abs(v["value"]) if one_step else 0.01 * v["stderr"])
                for n, v in merged_chunks["params"].items()),
            f"explain --chunk 2 = stats --chunk 2 then merge, in one command ({'one step' if one_step else 'passes'})")

    # Real recordings (tests/data/corpus): the chunked verdict is the whole log's, and a
    # chunk too short for the motion a fit needs is refused with the reason, never fitted.
    repo = Path(__file__).resolve().parents[2]
    servo = [repo / "tests/data/corpus/servoproject/optical_encoder_ab.txt", "--config",
             repo / "tools/examples/servoproject_ab.toml"]
    whole_servo = json.loads(run([model, "explain", *servo, "--json"]).stdout)
    r = run([model, "explain", *servo, "--chunk", 5, "--json"])
    chunked_servo = json.loads(r.stdout) if r.returncode == 0 else {"verdict": "?", "params": {}}
    a_whole = whole_servo["params"]["amplitude_imbalance.alpha"]["value"]
    a_chunk = chunked_servo["params"].get("amplitude_imbalance.alpha", {"value": float("nan")})["value"]
    c.check(chunked_servo["verdict"] == whole_servo["verdict"] == "unexplained" and abs(a_chunk - a_whole) < 0.01 * abs(a_whole),
            f"optical encoder recording in 5 s chunks: {chunked_servo['verdict']} as whole, alpha {a_chunk:.4g} against "
            f"{a_whole:.4g}")
    moteus = [repo / "tests/data/corpus/moteus/encoder_calibration_sweep.csv", "--config",
              repo / "tools/examples/moteus_sweep.toml"]
    r = run([model, "explain", *moteus, "--chunk", 5])
    c.check(r.returncode == 1 and "no chunk of the log could be fitted" in r.stderr and "4 bins" in r.stderr,
            f"a one-turn sweep in 5 s chunks: exit 1, each chunk's missing angle range named ({r.returncode})")

    # What the reader counted travels with the statistics: a log with a 0.5 s gap (frames
    # cut out) says so in its file and in the merge's notes, as explain says it.
    lines = a.read_text().splitlines()
    t0 = float(lines[0][1:lines[0].index(")")])
    gap = w / "gap.log"
    gap.write_text("\n".join(l for l in lines if not 2.8 <= float(l[1:l.index(")")]) - t0 < 3.3) + "\n")
    counted = [n for n in json.loads(stats(model, gap, w / "gap.stats").read_text())["input"] if "input problems" in n]
    merged_gap = merge(model, [w / "gap.stats"])
    c.check(bool(counted) and any(counted[0] in n for n in merged_gap["notes"]),
            f"a log with a gap: its counted input problems are in the statistics file and the merge's notes ({counted})")

    check_faulty_log_through_passes(args, w)

    # 6. bad input
    text = sa.read_text()
    bad = {"v1.stats": text.replace('"version":3', '"version":2', 1), "cut.stats": text[: len(text) // 2],
           "layout.stats": json.dumps(dict(json.loads(text), layout={"id": "other", "description": "a CSV layout"}))}
    for name, body in bad.items():
        (w / name).write_text(body)
    refused(model, [sa, w / "v1.stats"], 2, ["v1.stats", "version 2"], "a file of another version")
    refused(model, [sa, w / "cut.stats"], 2, ["cut.stats", "not a statistics file"], "a truncated file")
    refused(model, [sa, a], 2, [str(a), "not a statistics file"], "a log given as statistics")
    refused(model, [sa, w / "layout.stats"], 2, ["layout.stats", "another layout"], "statistics of another layout")
    refused(model, [sa, stats(model, other_p_r, w / "p_r2.stats")], 1, ["p_r2.stats", "pole pairs"],
            "a run of another p_r")
    refused(model, [sa, w / "missing.stats"], 3, ["missing.stats"], "a missing file")
    return c.finish("all stats/merge checks passed")


if __name__ == "__main__":
    sys.exit(main())
