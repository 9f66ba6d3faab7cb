#!/usr/bin/env python3
"""Pooled fits (issue 24): resolver-model fit|explain A.log B.log ... through the real programs.

One sensor (alpha = 0.03, beta = 0.01, the simulator's 3000 rad/s R/D loop) recorded in runs
that differ in what a bench changes between runs: speed (600 and 900 r/min), the reference's
zero against the resolver's (the mounting offset theta_0, any value) and the noise seed.

  1. pooled with the right model: the shared parameters match the truth, each log gets its own
     reference zero and operating point, no log disagrees, pooling shrinks the standard error,
     --jobs 2 prints the same bytes as --jobs 1;
  2. a third run whose alpha changed (0.033): it alone is named, on alpha;
  3. control: the model without the R/D loop (an effect that differs with speed): the two runs
     disagree on alpha, which is what a missing speed-dependent effect looks like;
  4. report on two runs: the discovery loop adds the loop and ends explained, with a pooled section;
  5. bad input: a run without the reference beside runs with one (exit 1, naming the log and
     the signal), a missing log (exit 3, naming it); a single log prints no "pool".
Standard library only.
"""
import argparse
import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_test_kit import (Checks, run, simulate_run, RUN_MODEL, RUN_ALPHA, RUN_BETA, RUN_TOL,  # noqa: E402
                            RUN_TOL_ZERO)

MODEL, ALPHA, BETA, TOL, TOL_ZERO = RUN_MODEL, RUN_ALPHA, RUN_BETA, RUN_TOL, RUN_TOL_ZERO  # bench_test_kit.py

checks = Checks()
check = checks.check


def simulate(sim, out, rpm, seed, alpha, theta_0, extra=()):
    simulate_run(sim, out, rpm, seed, alpha, BETA, theta_0, extra)


def fit_json(model, logs, effects=MODEL, jobs=1):
    r = run([model, "fit", *logs, "--effects", effects, "--json", "--jobs", jobs])
    if r.returncode != 0:
        sys.exit(f"resolver-model fit {logs} failed ({r.returncode}): {r.stderr}")
    return json.loads(r.stdout), r.stdout


def value_and_se(d, name):
    p = d["params"][name]
    return p["value"], p["stderr"]


def disagreeing(d):
    return {(c["log"], c["parameter"]) for c in d["pool"]["comparisons"] if c["disagrees"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True, type=Path)
    ap.add_argument("--work", required=True, type=Path)
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    sim, model = args.bin / "resolver-sim", args.bin / "resolver-model"
    a, b, c, n = (args.work / x for x in ("a.log", "b.log", "c.log", "noref.log"))
    simulate(sim, a, 600, 1, ALPHA, 0.3)
    simulate(sim, b, 900, 2, ALPHA, -1.2)
    simulate(sim, c, 600, 3, 0.033, 2.0)
    simulate(sim, n, 600, 4, ALPHA, 0.3, ["--no-reference"])

    # 1. the right model, two runs
    pooled, text1 = fit_json(model, [a, b])
    _, text2 = fit_json(model, [a, b], jobs=2)
    check(text1 == text2, "--jobs 2 prints the same bytes as --jobs 1")
    alpha, se_alpha = value_and_se(pooled, "amplitude_imbalance.alpha")
    beta, _ = value_and_se(pooled, "quadrature.beta")
    check(abs(alpha - ALPHA) < TOL, f"pooled alpha {alpha:.7g} is the truth {ALPHA} within {TOL}")
    check(abs(beta - BETA) < TOL, f"pooled beta {beta:.7g} is the truth {BETA} within {TOL}")
    logs = {l["log"]: l for l in pooled["pool"]["logs"]}
    check(set(logs) == {str(a), str(b)}, "the pool lists both logs")
    for log, theta_0 in ((a, 0.3), (b, -1.2)):
        l = logs[str(log)]
        # eps = -(p_r / p) theta_0 (mounting_offset.h) with p_r = p = 3: each run's own zero.
        zero = l["nuisance"]["nuisance.rd_constant"]
        check(abs(zero + theta_0) < TOL_ZERO, f"{log.name}: its own reference zero {zero:.6g} = -theta_0 = {-theta_0}")
        # The operating point in the reference frame: i_d = -i_q sin theta_0 at i_q = 10 A.
        i_d = l["nuisance"]["nuisance.i_d"]
        check(abs(i_d + 10.0 * math.sin(theta_0)) < 0.05,
              f"{log.name}: its own operating point i_d {i_d:.4g} = -10 sin(theta_0) A (the dq floor is 0.018 A)")
        alone_se = next(p["stderr"] for p in l["alone"]["params"] if p["name"] == "amplitude_imbalance.alpha")
        check(se_alpha < alone_se, f"{log.name}: pooling shrinks alpha's standard error ({se_alpha:.2g} < {alone_se:.2g})")
    check(not disagreeing(pooled), f"no log disagrees with the right model: {sorted(disagreeing(pooled))}")

    # 2. a run whose alpha changed is named alone, on alpha
    three, _ = fit_json(model, [a, b, c], jobs=2)
    flagged = disagreeing(three)
    check((str(c), "amplitude_imbalance.alpha") in flagged, "the run whose alpha changed disagrees on alpha")
    check(not any(log != str(c) for log, _ in flagged), f"only that run is named: {sorted(flagged)}")
    check(any(str(c) in n and "amplitude_imbalance.alpha" in n for n in three["notes"]), "a note names it")

    # 3. control: without the R/D loop the runs at two speeds disagree on alpha
    no_loop, _ = fit_json(model, [a, b], effects="amplitude_imbalance,quadrature")
    check({(str(a), "amplitude_imbalance.alpha"), (str(b), "amplitude_imbalance.alpha")} <= disagreeing(no_loop),
          "control: a model without the speed-dependent loop leaves the runs disagreeing on alpha")

    # The discovery loop on the pooled runs (report): from alpha + beta it adds the R/D loop
    # and ends explained; the page has the pooled section with both runs.
    page = args.work / "pooled.html"
    r = run([model, "report", a, b, "--effects", "amplitude_imbalance,quadrature", "--html", page])
    check(r.returncode == 0 and r.stdout.startswith("explained") and "tracking_loop" in r.stdout,
          f"report on two runs: the loop adds tracking_loop and explains them ({r.returncode}: {r.stdout.strip()})")
    text = page.read_text(encoding="utf-8") if page.exists() else ""
    check("The pooled logs" in text and a.name in text and b.name in text,
          "the page has the pooled section naming both runs")

    # 4. bad input
    r = run([model, "fit", a, n, "--effects", MODEL])
    check(r.returncode == 1 and str(n) in r.stderr and "reference" in r.stderr,
          f"a run without the reference beside one with it: exit 1 naming the log ({r.returncode}: {r.stderr.strip()})")
    r = run([model, "fit", a, args.work / "missing.log", "--effects", MODEL])
    check(r.returncode == 3 and "missing.log" in r.stderr,
          f"a missing log: exit 3 naming it ({r.returncode}: {r.stderr.strip()})")
    single, _ = fit_json(model, [a])
    check("pool" not in single, "one log: no pool in the JSON")

    return checks.finish("all pooled-fit checks passed")


if __name__ == "__main__":
    sys.exit(main())
