#!/usr/bin/env python3
"""The R/D converter's loop at real gain errors, through the real programs (loop_correction.h).

The converter's detector s cos(phi) - c sin(phi) has the envelopes' radius as its gain: with a
15 % gain error and a 2 % quadrature the radius swings by +-7 % at 2 theta around a 7 % mean.
Before the fit modelled it, resolver-sim's loop (omega_n = 3000 rad/s, zeta 0.7) came out
64-75 rad/s fast (53-325 standard errors) and the tracking error times the radius ripple was
proposed as a harmonic that is not there. One log that starts at a standstill and ramps to
1513 r/min (not a round speed: at a whole number of samples per turn the R/D angle's
quantization error repeats with the angle and biases harmonics by several standard errors),
10 kHz:

  named     the user's loop from the seed model (explain, add the first candidate; at most
            3 steps) ends `explained` with exactly amplitude_imbalance, quadrature and
            tracking_loop; the seed model's explain names the two as its missing pair;
  floor     that model leaves every signal <= 1.2x its floor (the magnitude sweep's limit),
            in-sample and held back;
  values    omega_n, alpha and beta within 4 standard errors of the truth (1 in 16,000 by
            chance);
  control   the same sensor read through an ideal converter (tracking_loop:omega_n=0): the
            loop ends explained without tracking_loop (the correction invents no loop);
  slow      a slow loop (omega_n 800 rad/s, zeta 0.5, a software observer's) whose
            resonance the 2 theta ripple crosses at 1213.7 r/min, alpha 0.12: the true model
            with zeta fitted reaches <= 1.2x its floor, omega_n and zeta within 0.1 % (the
            ramp's second-order remainder, loop_correction_test: measured 0.01 %). Before the
            start at 1000 rad/s (least_squares.cpp other_starts) it ended at 286 rad/s, 738x.
            Not checked: the user's loop from the seed model, which names a mechanical
            harmonic first here (a linearised step from an ideal converter cannot show a
            resonant loop) and keeps it at 6.8 se (docs/ACCURACY.md).
  rd only   alpha 0.10 on the same profile read with a signal map of only the R/D and
            reference angles (a scope export's layout): the true model reaches <= 1.2x its
            floor with omega_n within 4 standard errors, and the seed model's candidates
            are each listed once (the R/D angle cannot separate a pair at 2 theta; a pair and
            a family both reduced to harmonics(k3_q) and to mechanical_harmonics(b6), and
            the duplicates took the exact refits' places).
"""
import argparse
import json
import os
import subprocess
import sys

LIMIT = 1.2
Z_LIMIT = 4.0
PROFILE = "0:0.5,0-1513.3:1.5,1513.3:3"
SENSOR = ["-e", "amplitude_imbalance:alpha=0.15", "-e", "quadrature:beta=0.02"]
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tests", "hidden_effect"))
from run_hidden_effect import angle_only_config  # noqa: E402  (the scope export's signal map)
TRUTH = {"amplitude_imbalance.alpha": 0.15, "quadrature.beta": 0.02, "tracking_loop.omega_n": 3000.0}


def run(cmd):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {proc.returncode}\n{proc.stderr[-2000:]}")
    return proc.stdout


def explain(args, log, refs, extra=()):
    return json.loads(run([os.path.join(args.bin, "resolver-model"), "explain", log, "--json",
                           "--effects", ",".join(refs)] + list(extra)))


def user_loop(args, log, first=None):
    """The user's loop from the seed model; `first` (a list) gets the seed model's explain."""
    refs = ["amplitude_imbalance"]
    ex = explain(args, log, refs)
    if first is not None:
        first.append(ex)
    for _ in range(3):
        if ex["verdict"] == "explained" or not ex["candidates"]:
            break
        refs.append(ex["candidates"][0]["effect"])
        ex = explain(args, log, refs)
    return refs, ex


def worst_ratio(ex):
    return max(max(s["rms"] / s["floor"], s["held_back_rms"] / s["floor"]) for s in ex["signals"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    failures = []
    sim = [os.path.join(args.bin, "resolver-sim"), "--profile", PROFILE, "--sample-rate", "10000", "--seed", "5"]

    log = os.path.join(args.work, "loop_alpha15.log")
    run(sim + SENSOR + ["--out", log])
    seed = []
    refs, ex = user_loop(args, log, seed)
    print(f"loop from the seed model: {refs}, {ex['verdict']}, worst {worst_ratio(ex):.2f}x the floor")
    # The seed model lacks two effects; quadrature alone leaves 70x the floor (the loop's
    # ripple), the two together reach it: named as the pair (before: quadrature alone).
    pair = seed[0].get("missing_pair", [])
    print(f"  seed model: {seed[0]['verdict']}, pair {pair}")
    if sorted(pair) != ["quadrature", "tracking_loop"]:
        failures.append(f"the seed model's explain named {pair or 'no pair'}: {seed[0]['summary'][:200]}")
    if ex["verdict"] != "explained" or sorted(refs) != sorted(["amplitude_imbalance", "quadrature", "tracking_loop"]):
        failures.append(f"the user's loop ended at {refs} ({ex['verdict']})")
    fit = explain(args, log, ["amplitude_imbalance", "quadrature", "tracking_loop"])
    if worst_ratio(fit) > LIMIT:
        failures.append(f"the true model leaves {worst_ratio(fit):.2f}x its floor (limit {LIMIT})")
    for name, truth in TRUTH.items():
        p = fit["params"][name]
        z = abs(p["value"] - truth) / p["stderr"]
        print(f"  {name} = {p['value']:.7g} +- {p['stderr']:.2g} (truth {truth:g}, {z:.1f} se)")
        if z > Z_LIMIT:
            failures.append(f"{name} = {p['value']:.7g} is {z:.1f} standard errors from {truth:g}")

    ideal = os.path.join(args.work, "ideal_alpha15.log")
    run(sim + SENSOR + ["-e", "tracking_loop:omega_n=0", "--out", ideal])
    refs, ex = user_loop(args, ideal)
    print(f"control, ideal converter: {refs}, {ex['verdict']}")
    if ex["verdict"] != "explained" or "tracking_loop" in refs:
        failures.append(f"control: the ideal converter's loop ended at {refs} ({ex['verdict']})")

    slow = os.path.join(args.work, "slow_loop.log")
    run([os.path.join(args.bin, "resolver-sim"), "--profile", "0:0.3,0-1213.7:1,1213.7:3", "--sample-rate", "10000",
         "--seed", "5", "-e", "amplitude_imbalance:alpha=0.12", "-e", "tracking_loop:omega_n=800,zeta=0.5",
         "--out", slow])
    fit = explain(args, slow, ["amplitude_imbalance", "tracking_loop(omega_n,zeta)"])
    wn, zeta = fit["params"]["tracking_loop.omega_n"]["value"], fit["params"]["tracking_loop.zeta"]["value"]
    print(f"slow loop: omega_n {wn:.6g}, zeta {zeta:.6g}, worst {worst_ratio(fit):.2f}x the floor")
    if worst_ratio(fit) > LIMIT or abs(wn / 800.0 - 1.0) > 1e-3 or abs(zeta / 0.5 - 1.0) > 1e-3:
        failures.append(f"slow loop: omega_n {wn:.6g}, zeta {zeta:.6g}, {worst_ratio(fit):.2f}x its floor")

    rd_log = os.path.join(args.work, "rd_only_alpha10.log")
    run(sim + ["-e", "amplitude_imbalance:alpha=0.1", "--out", rd_log])
    cfg = ["--config", angle_only_config(args.work, 3)]
    seed = explain(args, rd_log, ["amplitude_imbalance"], cfg)
    listed = [c["effect"] for c in seed["candidates"]]
    twice = sorted({e for e in listed if listed.count(e) > 1})
    print(f"rd only, seed model: {seed['verdict']}, first candidates {listed[:5]}")
    if seed["signals"][0]["signal"] != "position_error" or any(s["signal"] != "position_error" for s in seed["signals"]):
        failures.append(f"rd only: signals fitted {[s['signal'] for s in seed['signals']]}")
    if twice:
        failures.append(f"rd only: candidates listed twice: {twice}")
    fit = explain(args, rd_log, ["amplitude_imbalance", "tracking_loop"], cfg)
    p = fit["params"]["tracking_loop.omega_n"]
    z = abs(p["value"] - 3000.0) / p["stderr"]
    print(f"rd only, true model: worst {worst_ratio(fit):.2f}x the floor, omega_n {p['value']:.7g} ({z:.1f} se)")
    if worst_ratio(fit) > LIMIT or z > Z_LIMIT:
        failures.append(f"rd only: {worst_ratio(fit):.2f}x its floor, omega_n {z:.1f} se from 3000")

    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
