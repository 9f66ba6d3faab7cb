#!/usr/bin/env python3
"""The user's loop on benches whose winding terms have mechanical aliases (docs/ACCURACY.md "Aliases").

Two benches at real magnitudes, 10 kHz resolver-sim logs with a standstill, a ramp, a hold and
a reversal through zero (not round speeds):

  A  p_r 3: alpha 0.11, beta 0.03, offsets 2 % / -1.5 %, k3 0.02 with k3_q 0.01, a 1500 rad/s
     loop at zeta 0.35, the reference's zero 2.1 rad off the d axis. A mechanical pair of
     order 6 is the alias of the 2 theta winding terms.
  B  p_r 1 (p 4): alpha -0.08, beta -0.02, offsets -1 % / 2.5 %, k3 -0.012 with k3_q 0.015, a
     2500 rad/s loop at zeta 0.5, an eccentricity of 3 mrad at 2.2 rad. Every mechanical
     order is an electrical one.
  C  bench B with the reference's zero 1.3 rad off the rotor's d axis.

For each: the true model (explained, values within Z_LIMIT standard errors), then the user's
loop from amplitude_imbalance: explain, take the first candidate (in place of the term it
replaces, when it names one), explain again, at most STEPS times. It passes when the loop
ends explained with only the sensor's own effects in its model (the loop's zeta may stay at
the catalog's 0.7 where the log explains without it). Prints each step and a table; ~15 min
on two cores. Not a ctest test (too long): the in-process tests
ModelDiscovery.AnAliasOfTheModelIsOfferedInPlaceOfIt and
ModelDiscovery.AtPr1TheModelsWindingAliasOfAnEccentricityIsSwapped hold the key steps.

  /usr/bin/python3 tests/magnitude/alias_loops.py --bin build/bin --work /tmp/alias_loops
"""
import argparse
import json
import os
import subprocess
import sys
import time

Z_LIMIT = 4.0
STEPS = 9
BENCHES = {
    "A (p_r 3)": {
        "sim": ["--profile", "0:0.5,0-813.7:1.5,813.7:2,813.7--613.7:2,-613.7:2",
                "-e", "amplitude_imbalance:alpha=0.11", "-e", "quadrature:beta=0.03",
                "-e", "offsets:o_s=0.02,o_c=-0.015", "-e", "harmonics:k3=0.02,k3_q=0.01",
                "-e", "tracking_loop:omega_n=1500,zeta=0.35", "-e", "mounting_offset:theta_0=2.1"],
        "true": ["amplitude_imbalance", "quadrature", "offsets", "harmonics(k3,k3_q)", "tracking_loop(omega_n,zeta)"],
        "truth": {"amplitude_imbalance.alpha": 0.11, "quadrature.beta": 0.03, "offsets.o_s": 0.02,
                  "offsets.o_c": -0.015, "harmonics.k3": 0.02, "harmonics.k3_q": 0.01,
                  "tracking_loop.omega_n": 1500, "tracking_loop.zeta": 0.35},
    },
    "B (p_r 1)": {
        "sim": ["--p-r", "1", "--p", "4",
                "--profile", "0:0.5,0-1413.7:1.5,1413.7:2,1413.7--913.7:2,-913.7:1.5,-913.7-0:1,0:0.5",
                "-e", "amplitude_imbalance:alpha=-0.08", "-e", "quadrature:beta=-0.02",
                "-e", "offsets:o_s=-0.01,o_c=0.025", "-e", "harmonics:k3=-0.012,k3_q=0.015",
                "-e", "tracking_loop:omega_n=2500,zeta=0.5", "-e", "eccentricity:e=0.003,phase=2.2"],
        "true": ["amplitude_imbalance", "quadrature", "offsets", "harmonics(k3,k3_q)", "tracking_loop(omega_n,zeta)",
                 "eccentricity"],
        "truth": {"amplitude_imbalance.alpha": -0.08, "quadrature.beta": -0.02, "offsets.o_s": -0.01,
                  "offsets.o_c": 0.025, "harmonics.k3": -0.012, "harmonics.k3_q": 0.015,
                  "tracking_loop.omega_n": 2500, "tracking_loop.zeta": 0.5, "eccentricity.e": 0.003,
                  "eccentricity.phase": 2.2},
    },
}
# C: bench B with the reference's zero 1.3 rad off the rotor's d axis (as a bench's encoder
# is mounted), the eccentricity's phase then against that zero.
BENCHES["C (p_r 1, reference zero off)"] = {
    "sim": BENCHES["B (p_r 1)"]["sim"] + ["-e", "mounting_offset:theta_0=1.3"],
    "true": BENCHES["B (p_r 1)"]["true"],
    "truth": {k: v for k, v in BENCHES["B (p_r 1)"]["truth"].items() if k != "eccentricity.phase"},
}


def run(cmd):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    if proc.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {proc.returncode}\n{proc.stderr[-2000:]}")
    return proc.stdout


def explain(args, log, refs):
    return json.loads(run([os.path.join(args.bin, "resolver-model"), "explain", log, "--json",
                           "--effects", ",".join(refs)]))


def worst_ratio(ex):
    return max(max(s["rms"], s["held_back_rms"] or 0.0) / s["floor"] for s in ex["signals"])


def effect_of(reference):
    return reference.split("(")[0]


def off_truth(ex, truth):
    """The largest distance of a fitted value from the truth, in its standard errors."""
    worst = 0.0
    for name, value in truth.items():
        p = ex["params"].get(name)
        if p and p["stderr"] > 0:
            worst = max(worst, abs(p["value"] - value) / p["stderr"])
    return worst


def user_loop(args, log):
    refs = ["amplitude_imbalance"]
    ex = explain(args, log, refs)
    for _ in range(STEPS):
        if ex["verdict"] == "explained" or not ex["candidates"] or not ex["candidates"][0]["proposed"]:
            break
        c = ex["candidates"][0]
        if c.get("replaces"):
            refs.remove(c["replaces"])
        refs.append(c["effect"])
        print(f"    -> {', '.join(refs)}" + (f"  ({c['effect']} in place of {c['replaces']})" if c.get("replaces") else ""),
              flush=True)
        ex = explain(args, log, refs)
    return refs, ex


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="folder of resolver-sim and resolver-model")
    ap.add_argument("--work", default="/tmp/alias_loops", help="where the logs are made (reused)")
    ap.add_argument("--only", help="the benches whose names start with these letters, e.g. BC")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    rows, failed = [], False
    for name, bench in BENCHES.items():
        if args.only and name[0] not in args.only:
            continue
        log = os.path.join(args.work, name.split()[0] + ".log")
        if not os.path.exists(log):
            run([os.path.join(args.bin, "resolver-sim"), "--sample-rate", "10000", "--seed", "7", "--out", log]
                + bench["sim"])
        t = time.time()
        true = explain(args, log, bench["true"])
        ok_true = true["verdict"] == "explained" and off_truth(true, bench["truth"]) <= Z_LIMIT
        print(f"{name}: true model {true['verdict']} {worst_ratio(true):.2f}x, "
              f"{off_truth(true, bench['truth']):.1f} se from the truth at most", flush=True)
        refs, ex = user_loop(args, log)
        own = {effect_of(r) for r in bench["true"]}
        ok_loop = ex["verdict"] == "explained" and all(effect_of(r) in own for r in refs)
        failed = failed or not ok_true or not ok_loop
        rows.append((name, true["verdict"], worst_ratio(true), ", ".join(refs), ex["verdict"], worst_ratio(ex),
                     "ok" if ok_true and ok_loop else "FAIL", time.time() - t))
    print("\n| bench | true model | x floor | the user's loop ends at | verdict | x floor | status | wall [s] |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]} | {r[4]} | {r[5]:.2f} | {r[6]} | {r[7]:.0f} |")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
