#!/usr/bin/env python3
"""resolver-model export --table-format c-header: the header compiles as C99 and as
C++17 with -Wall -Werror for models whose table has exact zeros.

A table entry that is exactly zero used to be written "0f," (an integer constant
with a float suffix: "invalid suffix "f" on integer constant"). Models checked:
  delay                        speed term only: every table entry is 0, the delay a scalar
  dead_time, current_offsets   current-side effects: every table entry is 0
  amplitude_imbalance          the seed model: the entry at theta = 0 is exactly 0
  amplitude_imbalance,delay    a table plus a non-zero scalar
  amplitude_imbalance,harmonics(k5),eccentricity   the model test_export.py uses
on a log with a speed ramp (a delay is told from the reference's zero by a change of speed).
Each header is included by a .c and a .cpp that read the table and the scalars.

  test_export_c_header.py --bin BUILD/bin --work DIR
"""
import argparse
import os
import re
import shutil
import subprocess
import sys

MODELS = [
    ("delay", True),
    ("dead_time", True),
    ("current_offsets", True),
    ("amplitude_imbalance", False),
    ("amplitude_imbalance,delay", False),
    ("amplitude_imbalance,harmonics(k5),eccentricity", False),
]

# An integer constant with the float suffix, e.g. "0f", "-0f", "12f" (not "0.0f", "1e-05f").
INTEGER_WITH_SUFFIX = re.compile(r"(?<![\w.+-])-?[0-9]+f\b")

USE = """#include "{header}"
int use_table(void);
int use_table(void) {{
  float sum = 0.0f;
  int i;
  for (i = 0; i < RESOLVER_CAL_POINTS; ++i) sum += resolver_cal_correction_rad[i];
  return sum > 1.0f || resolver_cal_delay_s > 1.0 || resolver_cal_backlash_rad > 1.0;
}}
"""


def run(cmd, ok=True):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if ok and p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {p.returncode}\n{p.stderr}")
    return p


def table_values(header):
    body = header.split("resolver_cal_correction_rad[RESOLVER_CAL_POINTS] = {", 1)[1].split("};", 1)[0]
    return [float(v.strip().rstrip("f")) for v in body.split(",") if v.strip()]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    b, w = args.bin, args.work
    compilers = [c for c in (("gcc", "-std=c99", "c"), ("g++", "-std=c++17", "cpp")) if shutil.which(c[0])]
    if len(compilers) < 2:
        print("SKIP: gcc and g++ are both needed")
        return 77
    failures = []

    def check(cond, what):
        print(("ok   " if cond else "FAIL ") + what)
        if not cond:
            failures.append(what)

    log = os.path.join(w, "c_header.log")
    run([f"{b}/resolver-sim", "--out", log, "--profile", "200:1,200-1200:1.5", "-e", "amplitude_imbalance:alpha=0.003",
         "-e", "harmonics:k5=3e-4", "-e", "eccentricity:e=3e-4,phase=0.5", "-e", "delay:d=2e-5"])
    for i, (effects, all_zero) in enumerate(MODELS):
        name = f"cal{i}.h"
        hdr = os.path.join(w, name)
        run([f"{b}/resolver-model", "export", log, "--effects", effects, "--table-format", "c-header",
             "--points", "64", "--out", hdr])
        with open(hdr) as f:
            text = f.read()
        values = table_values(text)
        zeros = sum(1 for v in values if v == 0.0)
        check(len(values) == 64, f"{effects}: 64 table entries (got {len(values)})")
        # The point of the test: it must really exercise exact zeros.
        if all_zero:
            check(zeros == 64, f"{effects}: the table is all zeros ({zeros} of 64)")
        else:
            check(any(v != 0.0 for v in values), f"{effects}: the table is not all zeros")
        bad = INTEGER_WITH_SUFFIX.findall(text.split("*/", 1)[1])
        check(not bad, f"{effects}: no integer constant with an 'f' suffix ({bad[:3]})")
        for cc, std, ext in compilers:
            src = os.path.join(w, f"use{i}.{ext}")
            with open(src, "w") as f:
                f.write(USE.format(header=name))
            p = run([cc, std, "-Wall", "-Werror", "-c", src, "-o", os.path.join(w, f"use{i}_{ext}.o"), "-I", w],
                    ok=False)
            check(p.returncode == 0, f"{effects}: the header compiles with {cc} {std} -Wall -Werror"
                  + (f"\n{p.stderr}" if p.returncode else ""))
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
