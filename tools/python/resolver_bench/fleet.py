"""A production line's calibrations on Dask: one task per unit.

  python3 -m resolver_bench.fleet MANIFEST --out DIR (--scheduler tcp://HOST:8786 | --local N)
                                  [--resolver-model PATH] [--effects a,b] [--config F]

MANIFEST is resolver-model fleet's: a CSV with the header "unit,log", one row per log,
relative paths relative to the manifest's folder. Each unit is one Dask task (retries=2)
that runs `resolver-model fleet` on a manifest of that unit alone into a folder of its
own (DIR/.tasks/UNIT.ATTEMPT); the client moves the unit's folder to DIR/UNIT and, once
every unit has ended, runs `resolver-model fleet --summarize DIR`: fleet.json is computed
by the same code from the same unit.json files as a single-process
`resolver-model fleet MANIFEST --out DIR`, so the two are identical.

A unit whose task failed for good (the worker lost three times, resolver-model crashed)
gets a unit.json saying so, and is counted and named in fleet.json: never dropped.

On several machines: `dask scheduler` on one, `dask worker tcp://HOST:8786` on each,
the logs, DIR and resolver-model on a path every worker sees under the same name.

Exit codes (resolver-model's): 0 every unit done; 1 some unit failed (fleet.json says
which and why); 2 usage (a bad option, a malformed manifest); 3 the manifest or DIR
cannot be read or written.
"""
import argparse
import csv
import os
import re
import shutil
import subprocess
import sys
import uuid

EXIT_DONE, EXIT_UNIT_FAILED, EXIT_USAGE, EXIT_IO = 0, 1, 2, 3
_UNIT_NAME = re.compile(r"^[A-Za-z0-9_-][A-Za-z0-9_.-]{0,127}$")  # resolver-model's rule: a folder name


class UsageError(Exception):
    pass


def read_manifest(path):
    """{unit: [absolute log path, ...]} in manifest order; UsageError on a malformed manifest."""
    base = os.path.dirname(os.path.abspath(path))
    units = {}
    header = False
    with open(path, newline="") as f:
        for n, row in enumerate(csv.reader(f), 1):
            if not row or not "".join(row).strip() or row[0].strip().startswith("#"):
                continue
            if len(row) != 2:
                raise UsageError(f"{path}:{n}: a manifest row is \"unit,log\" (two fields): {','.join(row)}")
            unit, log = row[0].strip(), row[1].strip()
            if not header:
                if (unit, log) != ("unit", "log"):
                    raise UsageError(f"{path}:{n}: the manifest's first line is the header \"unit,log\"")
                header = True
                continue
            if not _UNIT_NAME.match(unit) or not log:
                raise UsageError(f"{path}:{n}: unit '{unit}': a unit is a folder name of letters, digits, "
                                 "'_', '-', '.' (not first), and every row names a log")
            # Joined, not normalised: resolver-model sees two spellings of one log and says so.
            units.setdefault(unit, []).append(log if os.path.isabs(log) else os.path.join(base, log))
    if not header:
        raise UsageError(f"{path}: empty manifest: expected the header \"unit,log\"")
    return units


def run_unit(resolver_model, unit, logs, tasks_dir, extra):
    """The Dask task: resolver-model fleet on UNIT alone, in a folder of this attempt's own
    (a retry never shares one with an attempt still running on a lost worker).
    Returns (unit, folder of DIR/UNIT's content, exit code, stderr); raises on anything but
    exit 0 or 1 so that Dask retries it."""
    attempt = os.path.join(tasks_dir, f"{unit}.{uuid.uuid4().hex[:12]}")
    os.makedirs(attempt)
    manifest = os.path.join(attempt, "manifest.csv")
    with open(manifest, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["unit", "log"])
        for log in logs:
            w.writerow([unit, log])
    out = os.path.join(attempt, "out")
    proc = subprocess.run([resolver_model, "fleet", manifest, "--out", out, *extra],
                          capture_output=True, text=True, errors="replace")
    if proc.returncode not in (EXIT_DONE, EXIT_UNIT_FAILED) or not os.path.exists(os.path.join(out, unit, "unit.json")):
        raise RuntimeError(f"unit {unit}: resolver-model fleet exited {proc.returncode}: {proc.stderr.strip()[-2000:]}")
    return unit, os.path.join(out, unit), proc.returncode, proc.stderr


def _json_str(s):
    import json
    return json.dumps(s)


def write_failed_unit(out_dir, unit, logs, reason):
    """What resolver-model writes for a failed unit, for a task that never got that far."""
    folder = os.path.join(out_dir, unit)
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    with open(os.path.join(folder, "unit.json"), "w") as f:
        f.write('{"unit":%s,"status":"failed","reason":%s,"log_rows":%d,"logs":[]}\n'
                % (_json_str(unit), _json_str(reason), len(logs)))


def install_unit(out_dir, unit, folder):
    target = os.path.join(out_dir, unit)
    shutil.rmtree(target, ignore_errors=True)
    shutil.move(folder, target)


def default_resolver_model():
    return os.environ.get("RESOLVER_MODEL") or shutil.which("resolver-model") or "resolver-model"


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m resolver_bench.fleet", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("manifest", metavar="MANIFEST", help="CSV with the header unit,log")
    ap.add_argument("--out", required=True, metavar="DIR", help="DIR/UNIT/ per unit and DIR/fleet.json")
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", metavar="tcp://HOST:8786", help="a running Dask scheduler")
    where.add_argument("--local", type=int, metavar="N", help="a local cluster of N worker processes")
    ap.add_argument("--resolver-model", default=default_resolver_model(), metavar="PATH",
                    help="resolver-model on the workers (default: $RESOLVER_MODEL, else on PATH)")
    ap.add_argument("--effects", help="the model every log is fitted with (resolver-model fleet --effects)")
    ap.add_argument("--config", help="resolverd config (resolver-model fleet --config), on a path the workers see")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return EXIT_USAGE if e.code not in (0, None) else EXIT_DONE
    if args.local is not None and args.local < 1:
        print("resolver_bench.fleet: --local N needs N >= 1", file=sys.stderr)
        return EXIT_USAGE
    try:
        units = read_manifest(args.manifest)
    except UsageError as e:
        print(f"resolver_bench.fleet: {e}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as e:
        print(f"resolver_bench.fleet: cannot read manifest {args.manifest}: {e.strerror}", file=sys.stderr)
        return EXIT_IO
    try:
        import distributed
    except ImportError:
        print("resolver_bench.fleet: Dask is not installed (apt-get install python3-distributed)", file=sys.stderr)
        return EXIT_USAGE
    out_dir = os.path.abspath(args.out)
    tasks_dir = os.path.join(out_dir, ".tasks")
    os.makedirs(tasks_dir, exist_ok=True)
    extra = []
    if args.effects:
        extra += ["--effects", args.effects]
    if args.config:
        extra += ["--config", os.path.abspath(args.config)]
    resolver_model = os.path.abspath(args.resolver_model) if os.path.sep in args.resolver_model else args.resolver_model

    cluster = None
    if args.local is not None:
        cluster = distributed.LocalCluster(n_workers=args.local, threads_per_worker=1, processes=True,
                                           dashboard_address=None)
        client = distributed.Client(cluster)
    else:
        client = distributed.Client(args.scheduler)
    try:
        futures = {client.submit(run_unit, resolver_model, unit, logs, tasks_dir, extra, key=f"unit-{unit}",
                                 retries=2, pure=False): unit for unit, logs in units.items()}
        for future in distributed.as_completed(futures):
            unit = futures[future]
            try:
                _, folder, code, err = future.result()
            except Exception as e:  # the task failed for good: said per unit, and in fleet.json
                reason = f"the Dask task failed after its retries: {e}"
                print(f"resolver_bench.fleet: unit {unit}: {reason}", file=sys.stderr)
                write_failed_unit(out_dir, unit, units[unit], reason)
                continue
            install_unit(out_dir, unit, folder)
            if err.strip():
                sys.stderr.write(err if err.endswith("\n") else err + "\n")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    shutil.rmtree(tasks_dir, ignore_errors=True)
    proc = subprocess.run([resolver_model, "fleet", "--summarize", out_dir], text=True, errors="replace")
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
