#!/usr/bin/env python3
"""Exact models at real-sensor magnitudes (issue 21), through the real programs.

Real sensors carry gain errors of 3-13 %, degrees of quadrature, offsets and winding
harmonics of a few percent with their own phases. For each hidden set (singly and in
pairs) at each magnitude (1, 5, 10, 15 %), on logs of resolver-sim and of the independent
tests/independent/benchgen.py (its own parameterisation: K sin(n theta + phase)):

  named     the user's loop from the seed model (explain, add the first candidate, explain
            again; at most 3 steps) ends `explained` with exactly the hidden effects (the
            alpha-only case: the seed model is `explained` and proposes nothing);
  floor     `fit --effects <the hidden set>` is `explained` with every signal's residual
            <= 1.2x its noise floor, in-sample and held back (with current spikes, case part
            ispike, spike: `unexplained` for the outliers, every spike in the log counted,
            the rest at the floor);
  coverage  the 95 % intervals (value +- 1.96 standard errors) cover the truth; over
            --seeds N seeds per case the share must lie in the binomial band of 95 %
            (two-sided 99.9 %: 0.95 +- 3.3 sqrt(0.95 0.05 / (N x params))).

  run_magnitude_sweep.py --bin BUILD/bin --work DIR [--cases a,b] [--magnitudes 0.05,0.15]
                         [--generators sim,benchgen] [--seeds N] [--profile bench|SPEC]
  run_magnitude_sweep.py --bin BUILD/bin --work DIR --reference-zero | --geometry

Prints one row per case and magnitude (named, residual / floor, coverage) and exits 1 when
a check fails. The ctest subset runs one seed of a few cases; the whole table is the
script's (docs/ACCURACY.md).
"""
import argparse
import json
import math
import os
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCHGEN = os.path.join(REPO, "tests", "independent", "benchgen.py")
SYSTEM_PYTHON = "/usr/bin/python3"
LIMIT = 1.2  # issue 21: the right model reaches 1.2x its floor at every magnitude
Z95 = 1.959964
MAGNITUDES = (0.01, 0.05, 0.10, 0.15)
NOISE = "noise:sigma_sc=2,sigma_i=0.02"  # resolver-sim's default noise, given to both generators
# [counts] below the generators' 26000: a 15 % gain with a 15 % harmonic peaks at 1.3x.
AMPLITUDE = 20000
SPIKE_RATE, SPIKE_SIZE = 50.0, 10.0  # [1/s], [A]: the ispike case part
SC_SPIKE_SIZE = 3000  # [counts] the spike case part: 15 % of AMPLITUDE, at SPIKE_RATE, random sign
BASE_ALPHA = 0.003  # every log but the alpha cases keeps the demo's small imbalance
PHASE2, PHASE3 = 0.7, -1.1  # [rad] the harmonics' own phases
# A bench's run: standstills at both ends, a slow reversal through zero speed, a speed step.
# Not round speeds (see --rpm): at 300, 400 and 600 r/min the R/D quantization repeats and
# biases alpha by 15 standard errors in resolver-sim's logs.
BENCH_PROFILE = "0:0.5,301.37:2,301.37--403.1:1.5,-403.1:2,0:0.5,601.7:2"


def _harmonic(n, m, phase):
    """(sim spec, benchgen spec, truth) of a same-sequence K_n of size m with a phase."""
    kc, ks = m * math.cos(phase), m * math.sin(phase)
    return (f"harmonics:k{n}={kc:.10g},k{n}_q={ks:.10g}", f"harmonics:k{n}={m:.10g},k{n}_phase={phase:.10g}",
            {f"harmonics.k{n}": kc, f"harmonics.k{n}_q": ks}, f"harmonics(k{n},k{n}_q)")


def effects_of(case, m):
    """(sim specs, benchgen specs, truth {param: value}, model references) of a case."""
    parts = case.split("+")
    sim, bg, truth, refs = [], [], {}, ["amplitude_imbalance"]
    alpha = m if "alpha" in parts else BASE_ALPHA
    sim.append(f"amplitude_imbalance:alpha={alpha:.10g}")
    truth["amplitude_imbalance.alpha"] = alpha
    for p in parts:
        if p == "alpha":
            continue
        if p == "beta":
            spec = f"quadrature:beta={m:.10g}"
            sim.append(spec)
            bg.append(spec)
            truth["quadrature.beta"] = m
            refs.append("quadrature")
        elif p == "offsets":
            spec = f"offsets:o_s={m:.10g},o_c={-0.6 * m:.10g}"
            sim.append(spec)
            bg.append(spec)
            truth["offsets.o_s"] = m
            truth["offsets.o_c"] = -0.6 * m
            refs.append("offsets")
        elif p == "igain":
            # The phase current sensors' gains (resolver-sim only: benchgen has no currents).
            # Their ripple is predicted exactly from the currents' operating point, the
            # constant of a ripple fit (current_operating_point.h), not the plain mean the
            # gains shift on an uneven run.
            sim.append(f"current_gain_mismatch:gain_a={m:.10g},gain_b={-0.6 * m:.10g}")
            truth["current_gain_mismatch.gain_a"] = m
            truth["current_gain_mismatch.gain_b"] = -0.6 * m
            refs.append("current_gain_mismatch")
        elif p == "ioff":
            # The phase current sensors' offsets, 2 m A and -1.2 m A at 10 A (0.1-0.3 A at 5-15 %).
            sim.append(f"current_offsets:off_a={2 * m:.10g},off_b={-1.2 * m:.10g}")
            truth["current_offsets.off_a"] = 2 * m
            truth["current_offsets.off_b"] = -1.2 * m
            refs.append("current_offsets")
        elif p == "ispike":
            # One-sided spikes on phase current a (a current ADC that glitches high with the
            # inverter's switching, 50/s, 10 A, some a sample or two apart): never part of a
            # model; found (outliers.h) and kept out of the floors, the currents' operating
            # point and the fit. resolver-sim only. Before, the spikes a sample or two apart and
            # at a run's end were missed: i_dq at 9x its floor, its standstill floor at 24x.
            sim.append(f"current_outliers:rate={SPIKE_RATE:g},size={SPIKE_SIZE:g},positive=1")
        elif p == "spike":
            # Spikes on the sin channel's ADC (EMI on the resolver's cable: 15 % of the
            # amplitude, 50/s, random sign, some side by side or a sample apart): found by the
            # burst test (outliers.h) and kept out of the fit. resolver-sim only. Before, sin/cos
            # took the single pass: one of a pair stayed in (sin_cos at 19.7x its floor, three
            # effects proposed that are not there) or the floor took them (0.45x).
            sim.append(f"outliers:rate={SPIKE_RATE:g},size={SC_SPIKE_SIZE}")
        elif p == "zero":
            # The reference's zero 2 rad (electrical) off the rotor's d axis, as a bench's encoder
            # is mounted anywhere: resolver-sim's mounting offset, fitted without
            # --reference-aligned, so the fit's frame shift takes the zero (no parameter of its own;
            # it turns the frame the currents' ripple is predicted in). resolver-sim only.
            sim.append("mounting_offset:theta_0=-2.0")
        elif p in ("k2", "k3"):
            n = int(p[1])
            s, b, t, r = _harmonic(n, m, PHASE2 if n == 2 else PHASE3)
            sim.append(s)
            bg.append(b)
            truth.update(t)
            refs.append(r)
        else:
            sys.exit(f"unknown case part {p}")
    bg.insert(0, sim[0])
    return sim, bg, truth, refs


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode not in (0,):
        raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}\n{p.stderr[-2000:]}")
    return p.stdout


def generate(generator, bin_dir, log, specs, seed, args):
    motion = ["--profile", args.profile] if args.profile else ["--rpm", str(args.rpm), "--duration", str(args.duration)]
    common = ["--out", log, "--seed", str(seed)] + motion + ["--p-r", "3", "--amplitude", str(AMPLITUDE), "-e", NOISE]
    for s in specs:
        common += ["-e", s]
    if generator == "sim":
        # resolver-sim's R/D loop (omega_n = 3000 rad/s) is a hidden effect of its own here.
        run([os.path.join(bin_dir, "resolver-sim")] + common + ["-e", "tracking_loop:omega_n=0"])
    else:
        run([SYSTEM_PYTHON, BENCHGEN] + common)


def explain(bin_dir, log, refs, aligned=True):
    out = run([os.path.join(bin_dir, "resolver-model"), "explain", log, "--json"] +
              (["--reference-aligned"] if aligned else []) + ["--effects", ",".join(refs)])
    return json.loads(out)


def worst_ratio(ex):
    worst = 0.0
    for s in ex["signals"]:
        worst = max(worst, s["rms"] / s["floor"], s["held_back_rms"] / s["floor"])
    return worst


def spikes_in_log(log):
    """Samples whose phase currents do not sum to zero by more than half a spike, read from
    the candump log itself (PHASE_CURRENTS 0x101: i_a, i_b, i_c int16 LE at 1 mA/bit): the
    spikes the generator put in, counted without the programs under test. The sensors'
    gain errors leave the sum within 0.15 x 10 A of zero."""
    count = 0
    with open(log) as f:
        for line in f:
            parts = line.split()
            if len(parts) != 3 or not parts[2].startswith("101#"):
                continue
            data = bytes.fromhex(parts[2][4:])
            a, b, c = (int.from_bytes(data[k:k + 2], "little", signed=True) for k in (1, 3, 5))
            count += abs(a + b + c) > 500 * SPIKE_SIZE
    return count


def sin_spikes_in_log(log, p_r=3, orders=8):
    """Samples whose sin is off a least-squares fit in the reference angle (REFERENCE_ANGLE
    0x102, u32 mechanical, x p_r) by more than half a spike: the spikes the generator put in,
    counted without the programs under test. The fit's harmonics up to `orders` take the
    hidden effects (an angle error of 15 % leaves < 60 counts above the 8th); what is left
    is the noise (2 counts) and the reference's quantization."""
    import numpy as np
    sin, ref = [], []
    with open(log) as f:
        for line in f:
            parts = line.split()
            if len(parts) != 3:
                continue
            if parts[2].startswith("100#"):
                sin.append(int.from_bytes(bytes.fromhex(parts[2][4:])[1:3], "little", signed=True))
            elif parts[2].startswith("102#"):
                ref.append(int.from_bytes(bytes.fromhex(parts[2][4:])[1:5], "little"))
    n = min(len(sin), len(ref))
    y = np.array(sin[:n], float)
    theta = p_r * np.array(ref[:n], float) * 2.0 * math.pi / 2.0**32
    cols = [np.ones(n)]
    for k in range(1, orders + 1):
        cols += [np.sin(k * theta), np.cos(k * theta)]
    a = np.column_stack(cols)
    clean = np.ones(n, bool)
    for _ in range(3):
        x = np.linalg.lstsq(a[clean], y[clean], rcond=None)[0]
        clean = np.abs(y - a @ x) < SC_SPIKE_SIZE / 2
    return int(n - clean.sum())


def done(ex):
    """Where a bench engineer stops adding effects: explained, or at the floor once the
    outliers the summary names are left out (the verdict says "unexplained" for them)."""
    if ex["verdict"] == "explained":
        return True
    return ex["verdict"] == "unexplained" and bool(ex["outliers"]) and worst_ratio(ex) <= LIMIT


def loop(bin_dir, log, aligned):
    """The user's loop from the seed model: returns (model references, final explain)."""
    refs = ["amplitude_imbalance"]
    ex = explain(bin_dir, log, refs, aligned)
    for _ in range(3):
        if done(ex) or not ex["candidates"]:
            break
        refs.append(ex["candidates"][0]["effect"])
        ex = explain(bin_dir, log, refs, aligned)
    return refs, ex


def one(generator, bin_dir, work, case, m, seed, args, named_too):
    sim, bg, truth, refs = effects_of(case, m)
    aligned = "zero" not in case.split("+")
    log = os.path.join(work, f"{generator}_{case}_{m:g}_{seed}.log")
    generate(generator, bin_dir, log, sim if generator == "sim" else bg, seed, args)
    result = {}
    if named_too:
        found, ex = loop(bin_dir, log, aligned)
        result["named"] = done(ex) and sorted(found) == sorted(refs)
        result["loop"] = found
    if not aligned and named_too:
        # The control: the zero is in the log, so the same model taken as aligned misses it.
        result["control"] = explain(bin_dir, log, refs, aligned=True)["verdict"]
    fit = explain(bin_dir, log, refs, aligned)
    # The true model's verdict: `explained`; with spikes in the log the verdict says the
    # outliers carry the residual (`unexplained`), and every spike the log holds must be
    # counted on i_dq, nothing else flagged, the rest at the floor.
    result["accepted"] = fit["verdict"] == "explained"
    injected = {}
    if "ispike" in case.split("+"):
        injected["i_dq"] = spikes_in_log(log)
    if "spike" in case.split("+"):
        injected["sin_cos"] = sin_spikes_in_log(log)
    if injected:
        counted = {o["signal"]: o["count"] for o in fit["outliers"]}
        result["spikes"] = (injected, counted)
        result["accepted"] = counted == injected and min(injected.values()) > 0 and done(fit)
    result["ratio"] = worst_ratio(fit)
    covered, total, worst_z = 0, 0, 0.0
    for name, value in truth.items():
        p = fit["params"].get(name)
        if p is None or p["stderr"] is None or not p["stderr"] > 0:
            total += 1
            continue
        z = abs(p["value"] - value) / p["stderr"]
        worst_z = max(worst_z, z)
        covered += z <= Z95
        total += 1
    result["covered"], result["total"], result["worst_z"] = covered, total, worst_z
    return result


def reference_zero(bin_dir, work):
    """Issue 21: the parameters do not depend on the reference's zero. benchgen's reference
    reads theta_m - zero; at 0, 0.1, 0.325 and 0.5 turn (electrical 0, 108, 351, 540 degrees at
    p_r = 3) the fit without --reference-aligned must give the same parameters: equal to
    1e-3 of a standard error (the fits see the same samples, turned; what is left is
    rounding and the frame shift's convergence tolerance, 1e-10 rad)."""
    refs = ["amplitude_imbalance", "quadrature", "harmonics(k2,k2_q)"]
    effects = ["amplitude_imbalance:alpha=-0.112", "quadrature:beta=0.02", "harmonics:k2=0.03,k2_phase=0.9"]
    failures, first = [], None
    print(f"{'reference zero [turn]':>22} {'verdict':>10} {'res/floor':>9}  parameters")
    for turn in (0.0, 0.1, 0.325, 0.5):
        log = os.path.join(work, f"zero_{turn:g}.log")
        cmd = [SYSTEM_PYTHON, BENCHGEN, "--out", log, "--seed", "3", "--rpm", "301.37", "--duration", "2", "--p-r", "3",
               "--amplitude", str(AMPLITUDE), "--ref-zero", f"{360.0 * turn:g}", "-e", NOISE]
        for e in effects:
            cmd += ["-e", e]
        run(cmd)
        fit = json.loads(run([os.path.join(bin_dir, "resolver-model"), "explain", log, "--json",
                              "--effects", ",".join(refs)]))
        params = {k: (v["value"], v["stderr"]) for k, v in fit["params"].items()}
        print(f"{turn:22.3f} {fit['verdict']:>10} {worst_ratio(fit):9.2f}  " +
              " ".join(f"{k.split('.')[1]}={v:.6g}" for k, (v, _) in params.items()), flush=True)
        if fit["verdict"] != "explained" or worst_ratio(fit) > LIMIT:
            failures.append(f"reference zero {turn} turn: {fit['verdict']} at {worst_ratio(fit):.2f}x its floor")
        if first is None:
            first = params
            continue
        for k, (v, se) in params.items():
            if abs(v - first[k][0]) > 1e-3 * first[k][1]:
                failures.append(f"reference zero {turn} turn: {k} = {v:.9g}, at zero {first[k][0]:.9g}")
    return failures


GEOMETRY_CONFIG = """[bench]
p_r = {p_r}
[input.csv]
delimiter = ";"
decimal = ","
header_lines = 4
column_names = true
time_column = "Time [FILETIME]"
time_unit = "filetime"
[input.csv.columns]
sin = {{ column = "Sin [counts]", scale = {sin_scale}, full_scale = 32767 }}
cos = {{ column = "Cos [counts]", full_scale = 32767 }}
ref_angle = {{ column = "Reference angle [deg]", unit = "deg", scale = {ref_scale} }}
rd_angle = {{ column = "RD angle [deg]", unit = "deg" }}
"""


def geometry(bin_dir, work):
    """Issue 21: a channel wired the other way, a reference counting the other way, or a
    reference at another ratio than p_r is named with its fix, never fitted into nonsense.
    One scope export of benchgen (p_r = 3, alpha 0.05), read through four column maps."""
    csv = os.path.join(work, "geometry.csv")
    run([SYSTEM_PYTHON, BENCHGEN, "--csv", csv, "--csv-columns", "sin,cos,ref_angle,rd_angle", "--seed", "1",
         "--rpm", "301.37", "--duration", "2", "--p-r", "3", "-e", NOISE, "-e", "amplitude_imbalance:alpha=0.05"])
    cases = [  # (name, p_r, sin scale, reference scale, words the message must hold; None = fits)
        ("as wired", 3, 1, 1, None),
        ("sin reversed", 3, -1, 1, ["sin/cos angle", "turns the other way", "scale = -1"]),
        ("reference reversed", 3, 1, -1, ["R/D angle", "turns the other way", "negate one"]),
        ("p_r = 2 configured", 2, 1, 1, ["1.5 times", "p_r = 3?"]),
    ]
    failures = []
    for name, p_r, sin_scale, ref_scale, words in cases:
        config = os.path.join(work, f"geometry_{name.replace(' ', '_')}.toml")
        with open(config, "w", encoding="utf-8") as f:
            f.write(GEOMETRY_CONFIG.format(p_r=p_r, sin_scale=sin_scale, ref_scale=ref_scale))
        p = subprocess.run([os.path.join(bin_dir, "resolver-model"), "explain", csv, "--config", config,
                            "--reference-aligned", "--json"], capture_output=True, text=True)
        if words is None:
            ok = p.returncode == 0 and json.loads(p.stdout)["verdict"] == "explained"
            print(f"{name:20} exit {p.returncode}, {json.loads(p.stdout)['verdict'] if p.returncode == 0 else ''}")
        else:
            ok = p.returncode != 0 and all(w in p.stderr for w in words)
            print(f"{name:20} exit {p.returncode}: {p.stderr.strip()[:200]}")
        if not ok:
            failures.append(f"{name}: exit {p.returncode}, expected {words or 'explained'}: {p.stderr.strip()[:300]}")
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--cases", default="alpha,beta,offsets,k2,k3,alpha+beta,alpha+offsets,alpha+k3,igain,beta+igain")
    ap.add_argument("--magnitudes", default=",".join(f"{m:g}" for m in MAGNITUDES))
    ap.add_argument("--generators", default="sim,benchgen")
    ap.add_argument("--seeds", type=int, default=1, help="seeds per case for the coverage (1)")
    # Not a round 300 r/min: there 2 kHz gives exactly 400/3 samples per electrical turn, the
    # 16-bit R/D quantization error repeats every 3 turns, is no longer noise and biases the
    # harmonics by ~5 standard errors in every seed alike (measured: alpha, k2 at +4.9..+7.0
    # sigma over 3 seeds at 300 r/min, -0.6..+0.1 sigma at 301.37). A real bench's speed
    # ripple dithers it.
    ap.add_argument("--rpm", type=float, default=301.37)
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--profile", default="",
                    help="instead of --rpm and --duration: a speed profile (resolver-sim's --profile); 'bench': a bench's "
                         "standstills, reversal and speed step, " + BENCH_PROFILE)
    ap.add_argument("--reference-zero", action="store_true",
                    help="instead: the same fit with the reference's zero at 0, 0.1, 0.325 and 0.5 turn")
    ap.add_argument("--geometry", action="store_true",
                    help="instead: a reversed channel, a reversed reference and a wrong p_r are named with the fix")
    args = ap.parse_args()
    if args.profile == "bench":
        args.profile = BENCH_PROFILE
    os.makedirs(args.work, exist_ok=True)
    if args.reference_zero or args.geometry:
        failures = reference_zero(args.bin, args.work) if args.reference_zero else geometry(args.bin, args.work)
        print("\nFAILED:\n  " + "\n  ".join(failures) if failures else "\nall checks passed")
        return 1 if failures else 0
    failures = []
    print(f"{'generator':9} {'case':14} {'size':>5} {'named':>6} {'verdict':>10} {'res/floor':>9} "
          f"{'coverage':>9} {'max |z|':>7}  loop")
    for generator in args.generators.split(","):
        if generator == "benchgen" and args.profile:
            print("benchgen: skipped, it has no speed profile (--profile is resolver-sim's)")
            continue
        for case in args.cases.split(","):
            if generator == "benchgen" and {"igain", "ioff", "zero", "ispike", "spike"} & set(case.split("+")):
                continue  # benchgen simulates no phase currents or spikes (its zero is --reference-zero's)
            for m in (float(x) for x in args.magnitudes.split(",")):
                rows = []
                for seed in range(1, args.seeds + 1):
                    try:
                        rows.append(one(generator, args.bin, args.work, case, m, seed, args, seed == 1))
                    except RuntimeError as e:
                        failures.append(f"{generator} {case} {m:g} seed {seed}: {e}")
                        break
                if not rows:
                    continue
                first = rows[0]
                covered = sum(r["covered"] for r in rows)
                total = sum(r["total"] for r in rows)
                ratio = max(r["ratio"] for r in rows)
                explained = all(r["accepted"] for r in rows)
                print(f"{generator:9} {case:14} {m:5.2f} {str(first['named']):>6} "
                      f"{'explained' if explained else 'NO':>10} {ratio:9.2f} {covered:4d}/{total:<4d} "
                      f"{max(r['worst_z'] for r in rows):7.2f}  {','.join(first['loop'])}", flush=True)
                tag = f"{generator} {case} {m:g}"
                if first.get("control") == "explained":
                    failures.append(f"{tag}: the control taken as --reference-aligned is explained too: the "
                                    "log's reference zero did not reach the fit")
                if not first["named"]:
                    failures.append(f"{tag}: the loop from the seed model ended at {first['loop']}")
                for r in rows:
                    if "spikes" in r and r["spikes"][1] != r["spikes"][0]:
                        failures.append(f"{tag}: {r['spikes'][0]} spikes in the log, outliers counted {r['spikes'][1]}")
                if not explained or ratio > LIMIT:
                    failures.append(f"{tag}: the true model is not explained at <= {LIMIT}x its floor ({ratio:.2f}x)")
                if args.seeds == 1:
                    # One seed: every parameter within 4 standard errors (1 in 16000 by chance).
                    if max(r["worst_z"] for r in rows) > 4.0:
                        failures.append(f"{tag}: a parameter {first['worst_z']:.1f} standard errors from the truth")
                elif total > 0:
                    share = covered / total
                    band = 3.29 * math.sqrt(0.95 * 0.05 / total)
                    if abs(share - 0.95) > band:
                        failures.append(f"{tag}: coverage {share:.3f} outside 0.95 +- {band:.3f}")
    if failures:
        print("\nFAILED:\n  " + "\n  ".join(failures))
        return 1
    print("\nall checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
