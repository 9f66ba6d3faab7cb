#!/usr/bin/env python3
"""Hidden-effect matrix through the real programs (issues 4, 13, 14).

For one hidden effect (or control) and one generator (resolver-sim, or the independent
tests/independent/benchgen.py, written from the physics only), on each of the effect's
motion profiles (profiles.py): the generator writes a candump log with 0.3 % amplitude
imbalance, noise and the hidden effect; then

  1. `resolver-model explain LOG --json` (default model: amplitude_imbalance) says what its
     statistics cover (reversals, revolutions travelled, standstill samples: issue 13),
     says `missing_effect` and names the hidden effect first -- or, where the physics makes
     two effects indistinguishable on that profile (matrix.py derives why), names one of
     the pair with the other in its `fits_as_well`;
  2. `explain --effects amplitude_imbalance,<first candidate>` says `explained` with every
     signal's residual, fitted and held back, <= 1.5x its noise floor (issue 4's limit).

Rows with `truth` check the refit's parameter against the hidden value; rows with
`quiet_in_control` check on the alpha-only control that the effect's BIC drop would not
propose it.

Controls: alpha alone is `explained` with nothing proposed on every profile; spikes on
top of a fitted model are never `explained`; drifting alpha stays `unexplained`, and its
`suggested_custom` block, appended to a config, brings the residual to the floor.

With --streaming, each profile instead checks issue 23's streaming path: `explain --chunk`
(half the log per chunk, merged from the statistics) against `explain` holding the log:
the same verdict, the same effect named, its parameters within STREAM_SE standard errors.

Checks known to fail are listed with their reason in matrix.XFAIL; they are printed at the
end and do not fail the test, but an entry whose checks all pass (XPASS) does, so it goes.

  run_hidden_effect.py --bin BUILD/bin --work DIR --generator sim|benchgen CASE [--profile P] [--streaming]
  run_hidden_effect.py --list
"""
import argparse
import fnmatch
import json
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from matrix import ALPHA, CONTROLS, HIDDEN, NOISE, XFAIL  # noqa: E402
from profiles import PROFILES  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BENCHGEN = os.path.join(REPO, "tests", "independent", "benchgen.py")
SYSTEM_PYTHON = "/usr/bin/python3"  # benchgen needs Debian's numpy and python-can
LIMIT = 1.5  # issue 4: "explained" means every residual <= 1.5x its noise floor
SEED = "7"
# resolver-model proposes a candidate whose BIC drop exceeds this (DiscoveryOptions::proposal_bic_drop).
PROPOSAL_BIC_DROP = 10.0
SAMPLE_RATE_HZ = 2000.0  # both generators' default
# Standstill detection: a hold's first and last samples may be taken as moving (the speed
# is estimated from differences across a few samples). At the 2 kHz sample rate 10
# samples = 5 ms per hold edge; a real misclassification (noise counted as motion, issue
# 13's "323 revolutions") is thousands of samples.
STANDSTILL_EDGE_SAMPLES = 10
# Travelled angle: the reference is a u32 (1.5e-9 rad) and holds are excluded, so the
# travelled revolutions are exact up to the hysteresis that keeps noise from counting;
# 1 % of the travel (3.6 deg per revolution) is far above it and far below issue 13's
# failure (net angle 0 for out-and-back, 161x for noise counted as revolutions).
TRAVEL_TOLERANCE = 0.01
# --streaming: a candidate's parameters from two chunks merged against the whole log.
# Each chunk is a run with its own operating point and noise floor (the weights; the log's
# reference zero, envelope gain and clock are shared, and a chunk goes on from the rotor's
# state where the last one ended); a nonlinear merge is relinearised over passes and every
# proposed candidate refitted, so the two fits are of the same rows at the same point:
# measured 0.00 standard errors on 195 of the 196 profiles and 0.06 on one (sim k5 steps,
# the chunks' own floors) by tests/hidden_effect/streaming_table.py on 2026-11-27.
STREAM_SE = 0.1


class Checks:
    """Named checks of one case. A check under an XFAIL entry (matrix.XFAIL: case and
    check patterns with a reason) may fail without failing the test; an entry none of
    whose checks failed is stale (XPASS) and fails the test, so it goes once fixed."""

    def __init__(self, case_id, ledger):
        self.case_id = case_id
        self.ledger = ledger  # XFAIL entry index -> [checks matched, checks failed]
        self.failures = []
        self.xfails = []

    def __call__(self, key, cond, what):
        full = f"{self.case_id}:{key}"
        entry = next((i for i, (pats, _) in enumerate(XFAIL) if any(fnmatch.fnmatch(full, p) for p in pats)), None)
        if entry is None:
            print(("  ok    " if cond else "  FAIL  ") + what)
            if not cond:
                self.failures.append(f"{full}: {what}")
            return cond
        tally = self.ledger.setdefault(entry, [0, 0])
        tally[0] += 1
        if cond:
            print("  ok    " + what + "  (under XFAIL)")
        else:
            tally[1] += 1
            print("  XFAIL " + what)
            self.xfails.append(f"{full}: {what}\n        reason: {XFAIL[entry][1]}")
        return cond


def run(cmd, allow_fail=False):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0 and not allow_fail:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}\n{p.stderr}")
    return p


def generate(generator, bin_dir, log, profile, args):
    common = ["--out", log, "--seed", SEED, "--profile", profile.text, "--p-r", str(profile.p_r),
              "-e", ALPHA, "-e", NOISE] + args
    if generator == "sim":
        cmd = [os.path.join(bin_dir, "resolver-sim")] + common
        # resolver-sim's chain has an R/D loop (omega_n = 3000 rad/s) unless told otherwise;
        # benchgen's converter is ideal unless given one. Only the tracking_loop case hides
        # a loop: a speed step kicks it into a transient of ~delta omega / omega_n (1.3e-2 rad
        # for 0 -> 120 r/min at p_r = 3), a second hidden effect.
        if not any(a.startswith("tracking_loop") for a in args):
            cmd += ["-e", "tracking_loop:omega_n=0"]
    else:
        cmd = [SYSTEM_PYTHON, BENCHGEN] + common
    run(cmd)


def angle_only_config(work, p_r):
    """A resolverd config whose signal map holds only rd_angle and ref_angle (no sin/cos,
    no currents): issue 13's scope export, on the default layout's frames."""
    path = os.path.join(work, f"angle_only_p{p_r}.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(f"""[bench]
p_r = {p_r}
[layout]
dbc = "{os.path.join(REPO, 'proto', 'resolver_bench.dbc')}"
[layout.signals]
rd_angle = "RESOLVER_SAMPLE.rd_angle"
ref_angle = "REFERENCE_ANGLE.ref_angle"
""")
    return path


def explain(bin_dir, log, effects=None, config=None, allow_fail=False, aligned=True, chunk=None):
    cmd = [os.path.join(bin_dir, "resolver-model"), "explain", log, "--json"]
    if chunk:
        cmd += ["--chunk", f"{chunk:g}"]
    if aligned:
        # Both generators write the true rotor angle as the reference: its zero is on the
        # d axis, so a constant error is the mounting offset, not the reference's zero.
        cmd.append("--reference-aligned")
    if effects:
        cmd += ["--effects", ",".join(effects)]
    if config:
        cmd += ["--config", config]
    p = run(cmd, allow_fail)
    if p.returncode != 0:
        return None, p.stderr.strip()
    return json.loads(p.stdout), ""


def first_candidate(ex):
    return ex["candidates"][0] if ex["candidates"] else None


def describe(c):
    if c is None:
        return "no candidate"
    twins = f", fits as well: {', '.join(c['fits_as_well'])}" if c["fits_as_well"] else ""
    return f"{c['effect']} ({c['residual_after_rad']:.3g} rad{twins})"


def check_covers(check, ex, profile, rate_hz):
    """Issue 13: the statistics say what they cover, and it is what the profile holds."""
    cov = ex["covers"]
    check("covers_reversals", cov["reversals"] == profile.reversals(),
          f"covers: {cov['reversals']} reversals (profile: {profile.reversals()})")
    travel = profile.travelled_revolutions()
    got = cov["revolutions_mechanical"]
    check("covers_travel", abs(got - travel) <= TRAVEL_TOLERANCE * travel,
          f"covers: {got:.4g} mechanical revolutions travelled (profile: {travel:.4g}, +-{TRAVEL_TOLERANCE:.0%})")
    hold = profile.hold_seconds() * rate_hz
    # Each hold has two edges; a pass through zero speed (ramp or step reversal) is a
    # momentary standstill of a few samples, like two edges.
    edges = 2 * (profile.holds() + profile.zero_crossings()) * STANDSTILL_EDGE_SAMPLES
    check("covers_standstill", abs(cov["standstill"] - hold) <= edges,
          f"covers: {cov['standstill']} standstill samples (profile holds: {hold:.0f} +-{edges})")


def check_floor(check, ex, key, label):
    for s in ex["signals"]:
        ratio = s["rms"] / s["floor"]
        held = s["held_back_rms"] / s["floor"]
        check(f"{key}_{s['signal']}", ratio <= LIMIT, f"{label}: {s['signal']} residual {ratio:.2f}x floor <= {LIMIT}")
        check(f"{key}_held_back_{s['signal']}", held <= LIMIT,
              f"{label}: {s['signal']} held back {held:.2f}x floor <= {LIMIT}")


def hidden_case(check, bin_dir, log, hidden, profile, config):
    first, _ = explain(bin_dir, log, config=config)
    best = first_candidate(first)
    print(f"  default model: verdict {first['verdict']}, first {describe(best)}")
    check_covers(check, first, profile, SAMPLE_RATE_HZ)
    twins, why = hidden.twins.get(profile.name, ((), ""))
    if why:
        print(f"  twins: {hidden.refs[0]} ~ {', '.join(twins)}: {why}")
    if twins == ("amplitude_imbalance",):
        absorbed_case(check, first, hidden)
        return
    check("verdict", first["verdict"] == "missing_effect", f"verdict missing_effect (got {first['verdict']})")
    name = best["effect"] if best else None
    others = best["fits_as_well"] if best else []
    is_hidden = name in hidden.refs and frozenset(best["params"]) == hidden.params
    if profile.name in hidden.part:
        part_ref, part_params, part_why = hidden.part[profile.name]
        print(f"  part: {part_ref}: {part_why}")
        is_hidden = name == part_ref and frozenset(best["params"]) == frozenset(part_params)
    if not twins:
        check("named", is_hidden, f"{hidden.refs[0]} named first (got {name})")
    else:
        # Twins the log cannot tell apart: the tool must not name a twin alone. Naming the
        # hidden effect itself is right (transients such as the take-up after a reversal
        # or a speed step can tell them apart); naming a twin is right only with the
        # hidden effect in its fits_as_well.
        named_refs = set(hidden.refs) | ({hidden.part[profile.name][0]} if profile.name in hidden.part else set())
        # Or the hidden effect is listed as not identifiable on this motion (issue 21: a
        # delay or play at one speed in one direction is a constant: never proposed).
        unidentifiable = any(n.startswith(f"{r}:") and "not identifiable here" in n
                             for n in first["not_evaluated"] for r in hidden.refs)
        ok = is_hidden or (name in twins and (any(o in named_refs for o in others) or unidentifiable))
        check("twins", ok, f"first candidate is {hidden.refs[0]}, or one of {', '.join(twins)} with "
                           f"{hidden.refs[0]} in fits_as_well (got {describe(best)})")
    for ref in hidden.apart.get(profile.name, ()):
        check("apart", ref not in others, f"{ref} is told apart: not in fits_as_well (got {describe(best)})")
    check("first_reaches_floor", bool(best) and best["reaches_floor"],
          f"the first candidate reaches the floor ({describe(best)})")
    # The user's next step: add the effect the tool named (as printed) and refit.
    ref = name if is_hidden else hidden.refs[0]
    if profile.name in hidden.part:
        ref = hidden.part[profile.name][0]
    after, err = explain(bin_dir, log, ["amplitude_imbalance", ref], config, allow_fail=True)
    if not check("refit_runs", after is not None, f"explain --effects amplitude_imbalance,{ref} runs ({err})"):
        return
    check("refit_verdict", after["verdict"] == "explained", f"{ref} added: verdict explained (got {after['verdict']})")
    check_floor(check, after, "refit", f"{ref} added")
    for param, (value, tol, why) in hidden.truth.items():
        got = after["params"].get(param)
        if not check("refit_value", got is not None, f"{ref} added: {param} is fitted"):
            continue
        bound = 5 * (got["stderr"] or 0.0) + tol
        check("refit_value", abs(got["value"] - value) <= bound,
              f"{ref} added: {param} = {got['value']:.6g} +- {got['stderr']:.2g}, hidden {value:.6g} "
              f"(+- 5 standard errors + {tol:.2g}: {why})")
    if hidden.key == "mounting_offset" and profile.name == "const":
        # Control: told that the reference's zero is unknown (a real bench's encoder), the
        # tool must not name a mounting offset: a constant is then the reference's zero.
        free, err = explain(bin_dir, log, config=config, allow_fail=True, aligned=False)
        if check("unaligned_runs", free is not None, f"explain without --reference-aligned runs ({err})"):
            named = [c["effect"] for c in free["candidates"] if c["proposed"]]
            reason = [n for n in free["not_evaluated"] if n.startswith("mounting_offset:")]
            check("unaligned_not_named", "mounting_offset" not in named and bool(reason),
                  f"unaligned reference: mounting_offset not evaluated ({reason}), proposed {named}")
    if ref != hidden.refs[0] and profile.name == "const":
        # The explicit reference (README: "harmonics(k3,k5_opp)", "mechanical_harmonics(a2,b2)")
        # names the same model: once per effect, on the default bench.
        explicit, err = explain(bin_dir, log, ["amplitude_imbalance", hidden.refs[0]], config, allow_fail=True)
        if check("explicit_runs", explicit is not None,
                 f"explain --effects amplitude_imbalance,{hidden.refs[0]} runs ({err})"):
            # The same model on the same log is the same deterministic fit: equal to
            # rounding (1e-9 rad is 4 orders below the floor).
            check("explicit_same", abs(explicit["residual_rms_rad"] - after["residual_rms_rad"]) <= 1e-9,
                  f"{hidden.refs[0]} and {ref} give the same fit ({explicit['residual_rms_rad']:.4g} vs "
                  f"{after['residual_rms_rad']:.4g} rad)")


def streaming_case(check, bin_dir, log, profile, config):
    """Issue 23: the streaming path gives explain's answer. `explain --chunk` on half the
    log (two chunks, each a run of its own; the candidates ranked from the merged
    statistics, a nonlinear one refitted by a further pass) against explain holding the
    whole log: the same verdict, the same effect named (or one the in-memory explain
    says fits as well), its parameters within STREAM_SE standard errors."""
    chunk = sum(seconds for _, _, seconds in profile.segments()) / 2
    whole, _ = explain(bin_dir, log, config=config)
    streamed, err = explain(bin_dir, log, config=config, allow_fail=True, chunk=chunk)
    if not check("stream_runs", streamed is not None, f"explain --chunk {chunk:g} runs ({err[-300:]})"):
        return
    check("stream_verdict", streamed["verdict"] == whole["verdict"],
          f"--chunk {chunk:g}: verdict {streamed['verdict']}, in memory {whole['verdict']}")
    if whole["verdict"] != "missing_effect" or streamed["verdict"] != "missing_effect":
        return
    best, got = first_candidate(whole), first_candidate(streamed)
    same = got is not None and got["effect"] == best["effect"]
    check("stream_named", same or (got is not None and got["effect"] in best["fits_as_well"]),
          f"--chunk {chunk:g} names {got['effect'] if got else None} first, in memory {describe(best)}")
    if not same:
        return
    for name, p in best["params"].items():
        q = got["params"].get(name)
        if not check("stream_value", q is not None, f"--chunk {chunk:g}: {name} fitted"):
            continue
        apart = abs(q["value"] - p["value"]) / p["stderr"] if p["stderr"] else float("inf")
        check("stream_value", apart <= STREAM_SE,
              f"--chunk {chunk:g}: {name} = {q['value']:.6g}, in memory {p['value']:.6g} +- {p['stderr']:.2g} "
              f"({apart:.2f} se apart)")


def absorbed_case(check, first, hidden):
    """The default model's amplitude imbalance absorbs the hidden effect: explained, with
    alpha moved by hidden.absorbs x size."""
    check("verdict", first["verdict"] == "explained", f"absorbed by alpha: verdict explained (got {first['verdict']})")
    check_floor(check, first, "default", "default model")
    alpha = first["params"]["amplitude_imbalance.alpha"]
    expect = float(ALPHA.split("=")[1]) + hidden.absorbs * hidden.size
    # Neglected second-order terms of the chain: alpha x size on eps, i.e. 2 alpha size on
    # alpha; plus 5 standard errors of the fit.
    tol = 2 * float(ALPHA.split("=")[1]) * hidden.size + 5 * (alpha["stderr"] or 0.0)
    check("absorbed_alpha", abs(alpha["value"] - expect) <= tol,
          f"absorbed by alpha: alpha {alpha['value']:.6g} = {expect:.6g} +- {tol:.2g}")


def control_case(check, bin_dir, log, case, config, work):
    first, _ = explain(bin_dir, log, config=config)
    best = first_candidate(first)
    print(f"  default model: verdict {first['verdict']}, first {describe(best)}")
    if case == "control_alpha_only":
        check("verdict", first["verdict"] == "explained", f"alpha only: explained (got {first['verdict']})")
        proposed = [c["effect"] for c in first["candidates"] if c["proposed"]]
        check("nothing_proposed", not proposed, f"alpha only: nothing proposed (got {proposed})")
        check_floor(check, first, "default", "alpha only")
        # An explained log proposes nothing by rule; the rows that ask for it are checked on
        # their own merit too: their BIC drop would not propose them either.
        for hidden in (h for h in HIDDEN.values() if h.quiet_in_control):
            ranked = [c for c in first["candidates"] if c["effect"] in hidden.refs]
            skipped = [n for n in first["not_evaluated"] for r in hidden.refs if n.startswith(f"{r}:")]
            for c in ranked:
                values = ", ".join(f"{k} = {v['value']:.3g} +- {v['stderr']:.2g}" for k, v in c["params"].items())
                check("quiet", c["bic_drop"] <= PROPOSAL_BIC_DROP,
                      f"alpha only: {c['effect']} would not be proposed (BIC drop {c['bic_drop']:.1f} <= "
                      f"{PROPOSAL_BIC_DROP:g}; {values})")
            if not ranked:
                check("quiet", bool(skipped), f"alpha only: {hidden.refs[0]} ranked or not evaluated ({skipped})")
        return
    if case.startswith("control_outliers"):
        check("verdict", first["verdict"] != "explained", f"spikes: not explained (got {first['verdict']})")
        n = sum(o["count"] for o in first["outliers"])
        check("outliers_reported", n > 0, f"spikes: outliers reported ({n})")
        return
    # control_alpha_drift
    check("verdict", first["verdict"] == "unexplained", f"drifting alpha: unexplained (got {first['verdict']})")
    check("time", any("time" in w for w in first["where_it_fails"]), "drifting alpha: the residual changes over time")
    block = first.get("suggested_custom")
    check("suggested_custom", bool(block), "drifting alpha: a [[model.custom]] block is suggested")
    if not block:
        # Still try the config step, with the block the physics gives: alpha(t) = alpha_0 +
        # r t puts (r t / 2) sin 2theta on eps; its cos part covers a phase error.
        block = ('[[model.custom]]\nname = "alpha_drift"\nsignal = "position_error"\n'
                 'terms = ["t*sin(2*theta)", "t*cos(2*theta)"]\n')
        print("  (no suggestion: trying the config step with the physics' block t sin 2theta, t cos 2theta)")
    names = re.findall(r'name\s*=\s*"([^"]+)"', block) or ["residual"]
    cfg = os.path.join(work, os.path.basename(log) + ".custom.toml")
    with open(cfg, "w", encoding="utf-8") as f:
        if config:
            with open(config, encoding="utf-8") as base:
                f.write(base.read())
        f.write("\n" + block + "\n")
    after, err = explain(bin_dir, log, ["amplitude_imbalance"] + names, cfg, allow_fail=True)
    if not check("custom_config", after is not None, f"--config reads the [[model.custom]] block ({err})"):
        return
    # alpha(t) linear in t is exactly c t sin 2 theta: a block that describes it removes it
    # down to the floor.
    pe = next(s for s in after["signals"] if s["signal"] == "position_error")
    before = next(s for s in first["signals"] if s["signal"] == "position_error")
    check("custom_refit", pe["rms"] <= LIMIT * pe["floor"],
          f"custom refit: position error {before['rms'] / before['floor']:.2f}x -> "
          f"{pe['rms'] / pe['floor']:.2f}x floor <= {LIMIT}")


def cases_of(case):
    if case in HIDDEN:
        return HIDDEN[case].profiles
    return CONTROLS[case][1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin")
    ap.add_argument("--work")
    ap.add_argument("--generator", choices=["sim", "benchgen"])
    ap.add_argument("--profile", action="append", help="only these profiles (repeatable)")
    ap.add_argument("--list", action="store_true", help="print the matrix and exit")
    ap.add_argument("--streaming", action="store_true",
                    help="instead of the checks above, check that explain --chunk (half the log per chunk, "
                         "issue 23's streaming path) gives explain's in-memory answer")
    ap.add_argument("case", nargs="?", choices=sorted(list(HIDDEN) + list(CONTROLS)))
    a = ap.parse_args()
    if a.list:
        for c in sorted(list(HIDDEN) + list(CONTROLS)):
            print(f"{c:24} {' '.join(cases_of(c))}")
        return
    if not (a.bin and a.work and a.generator and a.case):
        ap.error("--bin, --work, --generator and CASE are required")
    work = os.path.join(a.work, a.generator)
    os.makedirs(work, exist_ok=True)
    failures, xfails, ledger = [], [], {}
    for pname in cases_of(a.case):
        if a.profile and pname not in a.profile:
            continue
        profile = PROFILES[pname]
        case_id = f"{a.generator}/{a.case}/{pname}"
        print(f"== {case_id}: {profile.why} ({profile.text}, p_r = {profile.p_r})")
        t0 = time.monotonic()
        log = os.path.join(work, f"{a.case}.{pname}.log")
        config = angle_only_config(work, profile.p_r) if profile.angle_only else None
        check = Checks(case_id, ledger)
        if a.case in HIDDEN:
            hidden = HIDDEN[a.case]
            generate(a.generator, a.bin, log, profile, ["-e", hidden.spec])
            if a.streaming:
                streaming_case(check, a.bin, log, profile, config)
            else:
                hidden_case(check, a.bin, log, hidden, profile, config)
        elif a.generator not in CONTROLS[a.case][0]:
            print(f"  (not with {a.generator}: {CONTROLS[a.case][2]})")
            continue
        else:
            generate(a.generator, a.bin, log, profile, CONTROLS[a.case][0][a.generator])
            if a.streaming:
                streaming_case(check, a.bin, log, profile, config)
            else:
                control_case(check, a.bin, log, a.case, config, work)
        print(f"  ({time.monotonic() - t0:.1f} s)")
        failures += check.failures
        xfails += check.xfails
    xpasses = [f"{', '.join(XFAIL[i][0])}: {XFAIL[i][1]}" for i, (_, bad) in sorted(ledger.items()) if bad == 0]
    if xfails:
        print(f"\nXFAIL ({len(xfails)}: expected failures, each with its reason):")
        for x in xfails:
            print("  " + x)
    if xpasses:
        print(f"\nXPASS ({len(xpasses)}: every check of these XFAIL entries passed; remove them from "
              "matrix.XFAIL):")
        for x in xpasses:
            print("  " + x)
    if failures:
        print(f"\nFAILED ({len(failures)}):")
        for f in failures:
            print("  " + f)
    if failures or xpasses:
        sys.exit(1)
    print("PASS")


if __name__ == "__main__":
    main()
