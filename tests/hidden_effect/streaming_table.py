#!/usr/bin/env python3
"""Issue 23's "same answers" over the whole hidden-effect matrix: every case and profile of
both generators through `run_hidden_effect.py --streaming` (explain --chunk, half the log per
chunk, against explain holding the log), as a table: profiles that give the same answer, the
expected failures (matrix.XFAIL, with their reasons) and the failures. ctest runs a subset
(hidden_effect_stream_*); this is the sweep, a few minutes on 2 cores.

  streaming_table.py --bin BUILD/bin --work DIR [--generator sim|benchgen ...]
"""
import argparse
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
RUNNER = os.path.join(HERE, "run_hidden_effect.py")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--generator", action="append", choices=["sim", "benchgen"])
    a = ap.parse_args()
    listing = subprocess.run([sys.executable, RUNNER, "--list"], capture_output=True, text=True, check=True).stdout
    cases = [line.split()[0] for line in listing.splitlines() if line.strip()]
    totals = {"same": 0, "xfail": 0, "fail": 0}
    print(f"{'generator':9} {'case':24} {'profiles':>8} {'same':>5} {'xfail':>5} {'fail':>5}")
    for generator in a.generator or ["sim", "benchgen"]:
        for case in cases:
            out = subprocess.run([sys.executable, RUNNER, "--bin", a.bin, "--work", a.work, "--generator", generator,
                                  "--streaming", case], capture_output=True, text=True).stdout
            row = {"same": 0, "xfail": 0, "fail": 0}
            for block in re.split(r"^== ", out, flags=re.M)[1:]:
                if "(not with" in block:
                    continue
                kind = "fail" if re.search(r"^  FAIL ", block, re.M) else \
                       "xfail" if re.search(r"^  XFAIL ", block, re.M) else "same"
                row[kind] += 1
            n = sum(row.values())
            if n == 0:
                continue
            for k in totals:
                totals[k] += row[k]
            print(f"{generator:9} {case:24} {n:8} {row['same']:5} {row['xfail']:5} {row['fail']:5}", flush=True)
    n = sum(totals.values())
    print(f"{'total':34} {n:8} {totals['same']:5} {totals['xfail']:5} {totals['fail']:5}")
    return 1 if totals["fail"] else 0


if __name__ == "__main__":
    sys.exit(main())
