#!/usr/bin/env python3
"""resolver-model export (issue 12 part 5) through the real programs: fit a log,
export the correction table, replay the same log through resolverd --calibration
TABLE, and check that the compensated position error reaches the model's own
residual within the table's stated interpolation error.

Bound: the compensated RMS over the moving samples and the fit's residual RMS are
both the noise floor plus what the model leaves; they differ by the table's
interpolation error (stated in its header, max over the turn) and by which samples
each covers (the fit leaves out the 5 % of samples at the ends of stretches and the
outliers): 5 % of the residual covers that.
Also: every format parses (CSV rows = --points, JSON loads, the C header compiles
with the C compiler), and a bad table is refused with its file and line.

  test_export.py --bin BUILD/bin --work DIR
"""
import argparse
import json
import os
import subprocess
import sys

ARGS = None


def run(cmd, ok=True):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if ok and p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}\n{p.stderr}")
    return p


def main():
    global ARGS
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS = ap.parse_args()
    os.makedirs(ARGS.work, exist_ok=True)
    b, w = ARGS.bin, ARGS.work
    failures = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            failures.append(what)

    log = os.path.join(w, "export.log")
    # A resolver-side model with harmonics and a mechanical order: the table must carry both.
    effects = "amplitude_imbalance,harmonics(k5),eccentricity"
    run([f"{b}/resolver-sim", "--out", log, "--duration", "4", "-e", "amplitude_imbalance:alpha=0.003",
         "-e", "harmonics:k5=3e-4", "-e", "eccentricity:e=3e-4,phase=0.5"])
    fit = json.loads(run([f"{b}/resolver-model", "fit", log, "--effects", effects, "--json"]).stdout)
    model_rms = fit["residual_rms_rad"]
    table = os.path.join(w, "table.csv")
    run([f"{b}/resolver-model", "export", log, "--effects", effects, "--points", "1024", "--out", table])
    with open(table) as f:
        lines = f.read().splitlines()
    head = {ln[2:].split(": ", 1)[0]: ln[2:].split(": ", 1)[1] for ln in lines if ln.startswith("# ") and ": " in ln}
    rows = [ln for ln in lines if ln and not ln.startswith("#")][1:]
    check(len(rows) == 1024, f"CSV has 1024 table rows (got {len(rows)})")
    check(head.get("model") == "amplitude_imbalance, harmonics(k5), eccentricity", f"header names the model ({head.get('model')})")
    interp = float(head["interpolation"].split("max error ")[1].split(" rad")[0])
    report = os.path.join(w, "report.json")
    run([f"{b}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", "--calibration", table,
         "--report", report])
    with open(report) as f:
        rep = json.load(f)
    comp = rep["position_error"]["compensated_moving"]["rms_rad"]
    raw = rep["position_error"]["raw_same_samples"]["rms_rad"]
    bound = 1.05 * model_rms + interp
    check(comp <= bound, f"compensated {comp:.3g} rad <= model residual {model_rms:.3g} x 1.05 + interpolation {interp:.3g}")
    check(raw > 10 * comp, f"the table does the work: raw {raw:.3g} rad > 10 x compensated")
    # Control: a table of the seed model alone leaves the harmonic and the eccentricity.
    seed_table = os.path.join(w, "seed.csv")
    run([f"{b}/resolver-model", "export", log, "--effects", "amplitude_imbalance", "--out", seed_table])
    run([f"{b}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", "--calibration",
         seed_table, "--report", report])
    with open(report) as f:
        seed_comp = json.load(f)["position_error"]["compensated_moving"]["rms_rad"]
    check(seed_comp > 3 * bound, f"control: the seed model's table leaves {seed_comp:.3g} rad > 3 x the bound")
    # Other formats.
    js = json.loads(run([f"{b}/resolver-model", "export", log, "--effects", effects, "--table-format", "json",
                         "--points", "256"]).stdout)
    check(len(js["correction_rad"]) == 256 and js["p_r"] == 3, "JSON export loads with 256 points and p_r")
    hdr = os.path.join(w, "cal.h")
    run([f"{b}/resolver-model", "export", log, "--effects", effects, "--table-format", "c-header", "--points", "64",
         "--out", hdr])
    src = os.path.join(w, "use.c")
    with open(src, "w") as f:
        f.write('#include "cal.h"\nint main(void) { return resolver_cal_correction_rad[RESOLVER_CAL_POINTS - 1] > 1.0f; }\n')
    cc = run(["cc", "-Wall", "-Werror", "-c", src, "-o", os.path.join(w, "use.o"), "-I", w], ok=False)
    check(cc.returncode == 0, "the C header compiles with -Wall -Werror" + (f": {cc.stderr}" if cc.returncode else ""))
    # A bad table: refused before anything runs, naming the file and line.
    bad = os.path.join(w, "bad.csv")
    with open(bad, "w") as f:
        f.write("\n".join(lines[:lines.index("index,theta_m_rad,correction_rad") + 3]) + "\n5,0.1,zz\n")
    p = run([f"{b}/resolverd", "--replay", log, "--once", "--fast", "--quiet", "--lcm", "memq://", "--calibration", bad],
            ok=False)
    check(p.returncode == 2 and "bad.csv:" in p.stderr and ("not a number" in p.stderr or "out of order" in p.stderr),
          f"a bad table is refused with file:line (exit {p.returncode}: {p.stderr.strip()[:120]})")
    if failures:
        sys.exit(f"{len(failures)} check(s) failed")


if __name__ == "__main__":
    main()
