"""A production line's calibrations on Dask: one task per log, the merge on the client.

  python3 -m resolver_bench.fleet MANIFEST --out DIR (--scheduler tcp://HOST:8786 | --local N)
                                  [--resolver-model PATH] [--effects a,b] [--config F]

Example (a local cluster of 2 worker processes; units.csv as for resolver-model fleet):

  python3 -m resolver_bench.fleet units.csv --out fleet/ --local 2 --effects amplitude_imbalance,quadrature

MANIFEST is resolver-model fleet's: a CSV with the header "unit,log", one row per log,
relative paths relative to the manifest's folder. Each row is one Dask task (retries=2)
that runs `resolver-model stats LOG --out DIR/UNIT/stats/LINE.stats` (LINE: the row's
line in the manifest) into a temporary file of that attempt's own, renamed into place
when it is complete: a lost worker's retry never shares a file with an attempt still
running, and a half-written file is never merged. A log resolver-model refuses (exit 1,
2 or 3: unreadable, no usable data) gets DIR/UNIT/stats/LINE.error with the reason; so
does a task that failed for good (its worker lost three times, resolver-model crashed).
The client then runs `resolver-model fleet MANIFEST --out DIR --merge-only`: each unit is
the merge of its rows' statistics (unit.json, calibration.{csv,json,h}) and fleet.json
their summary, the same code and the same files as a single-process
`resolver-model fleet MANIFEST --out DIR`, so the two give the same results. A row
without statistics fails its unit, named with its manifest line and reason in unit.json
and fleet.json: never dropped.

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


class Row:
    """One manifest row: its unit, its log (resolved as resolver-model resolves it) and line."""

    def __init__(self, unit, log, line):
        self.unit, self.log, self.line = unit, log, line

    def stats_path(self, out_dir):
        return os.path.join(out_dir, self.unit, "stats", f"{self.line}.stats")

    def error_path(self, out_dir):
        return os.path.join(out_dir, self.unit, "stats", f"{self.line}.error")


def read_manifest(path):
    """The rows in manifest order; UsageError on a malformed manifest. A relative log is
    joined to the manifest's folder and normalised, as resolver-model does (the merge
    checks each statistics file was made from its row's log)."""
    base = os.path.dirname(os.path.abspath(path))
    rows = []
    header = False
    with open(path, newline="") as f:
        reader = csv.reader(f)
        for row in reader:
            n = reader.line_num  # the physical line: resolver-model's LINE
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
            rows.append(Row(unit, log if os.path.isabs(log) else os.path.normpath(os.path.join(base, log)), n))
    if not header:
        raise UsageError(f"{path}: empty manifest: expected the header \"unit,log\"")
    return rows


def _write_atomically(path, text):
    tmp = os.path.join(os.path.dirname(path), f".tmp-{uuid.uuid4().hex}")
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def _remove(path):
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


def run_stats(resolver_model, log, stats_path, error_path, extra):
    """The Dask task: resolver-model stats on one log, into a temporary file of this
    attempt's own in the same folder, renamed to stats_path when complete (atomic).
    A log resolver-model refuses (exit 1, 2, 3) leaves error_path with its reason and
    returns ("failed", reason); anything else (killed, crashed) raises so Dask retries."""
    tmp = os.path.join(os.path.dirname(stats_path), f".tmp-{uuid.uuid4().hex}.stats")
    # One thread per task: the cluster's workers are the parallelism (a process each
    # using every core would oversubscribe a machine running several).
    proc = subprocess.run([resolver_model, "stats", log, "--out", tmp, "--threads", "1", *extra],
                          capture_output=True, text=True, errors="replace")
    if proc.returncode == EXIT_DONE and os.path.exists(tmp):
        _remove(error_path)
        os.replace(tmp, stats_path)
        return "done", ""
    _remove(tmp)
    lines = [l for l in proc.stderr.splitlines() if l.strip()]
    said = " ".join(lines[-3:])[-2000:]
    if proc.returncode in (EXIT_UNIT_FAILED, EXIT_USAGE, EXIT_IO):
        reason = f"resolver-model stats exited {proc.returncode}: {said}"
        _remove(stats_path)
        _write_atomically(error_path, reason + "\n")
        return "failed", reason
    raise RuntimeError(f"resolver-model stats {log} exited {proc.returncode}: {said}")


def run_rows(client, distributed, resolver_model, rows, out_dir, extra):
    """Every row's statistics on the cluster; a task that failed for good leaves its
    .error file here. Returns the number of rows without statistics."""
    for row in rows:  # a stale file of an earlier run is never merged
        os.makedirs(os.path.dirname(row.stats_path(out_dir)), exist_ok=True)
        _remove(row.stats_path(out_dir))
        _remove(row.error_path(out_dir))
    futures = {client.submit(run_stats, resolver_model, row.log, row.stats_path(out_dir), row.error_path(out_dir),
                             extra, key=f"stats-{row.unit}-{row.line}", retries=2, pure=False): row for row in rows}
    failed = 0
    for future in distributed.as_completed(futures):
        row = futures[future]
        try:
            status, reason = future.result()
        except Exception as e:  # lost or crashed three times: said per row, and in unit.json
            status, reason = "failed", f"the Dask task failed after its retries: {e}"
            _remove(row.stats_path(out_dir))
            _write_atomically(row.error_path(out_dir), reason + "\n")
        if status != "done":
            failed += 1
            print(f"resolver_bench.fleet: unit {row.unit}: {row.log} (manifest line {row.line}): {reason}",
                  file=sys.stderr)
    return failed


def remove_leftovers(rows, out_dir):
    """Temporary files of attempts whose worker was lost (never renamed into place)."""
    for folder in {os.path.dirname(row.stats_path(out_dir)) for row in rows}:
        for name in os.listdir(folder):
            if name.startswith(".tmp-"):
                _remove(os.path.join(folder, name))


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
    ap.add_argument("--effects", help="the model every log is fitted with (resolver-model stats/fleet --effects)")
    ap.add_argument("--config", help="resolverd config (resolver-model stats/fleet --config), on a path the workers see")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:
        return EXIT_USAGE if e.code not in (0, None) else EXIT_DONE
    if args.local is not None and args.local < 1:
        print("resolver_bench.fleet: --local N needs N >= 1", file=sys.stderr)
        return EXIT_USAGE
    try:
        rows = read_manifest(args.manifest)
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
        run_rows(client, distributed, resolver_model, rows, out_dir, extra)
        remove_leftovers(rows, out_dir)
    except OSError as e:
        print(f"resolver_bench.fleet: cannot write in {out_dir}: {e}", file=sys.stderr)
        return EXIT_IO
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    # The merge and the summary, here: the manifest by its absolute path, so that its
    # relative logs resolve to the paths the workers were given.
    try:
        proc = subprocess.run([resolver_model, "fleet", os.path.abspath(args.manifest), "--out", out_dir,
                               "--merge-only", *extra], text=True, errors="replace")
    except OSError as e:  # resolver-model not found here: the statistics stay for a later --merge-only
        print(f"resolver_bench.fleet: cannot run {resolver_model} fleet --merge-only: {e}", file=sys.stderr)
        return EXIT_IO
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main())
