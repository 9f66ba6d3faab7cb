#!/usr/bin/env python3
"""Integration test of the Python path (ctest python_lcmlog_example):

  resolver-sim (demo bench, 3 s) -> resolverd --replay --lcm file://...lcmlog
  -> examples/lcmlog_to_arrays.py --json       (pure-Python reader + lcm-gen --python types)
  == the same summary computed from resolver-echo --log   (the C++ reader, types parsed from .lcm)

Per channel: the type and message count; per field: the first and last value
(arrays and strings included) and, for numeric scalars, min, max and the number
of non-finite values. Equality is exact: resolver-echo prints doubles with
round-trip precision and JSON carries them unchanged. Checked with numpy
arrays and with plain lists (--no-numpy), and the fingerprints of the Python
classes against resolver-echo --list-types.

Controls, so the comparison can fail: the summary of a log with its last event
cut off differs; a log with a corrupted sync word is refused by both readers at
the same byte offset.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

LOG_TIME_COLUMN = "log_time_us"  # resolver_lcm's event-time column; resolver-echo has none


def run(cmd, env=None, check=True):
    result = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if check and result.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {result.returncode}:\n{result.stderr}")
    return result


def load_example_module(path):
    """The example's own summarise_column, so both sides are summarised by one function."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("lcmlog_to_arrays", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def summary_from_echo(echo_lines, summarise_column):
    channels = {}
    for line in echo_lines:
        msg = json.loads(line)
        if msg.get("type") is None:
            sys.exit(f"FAIL: resolver-echo could not decode a message: {line}")
        ch = channels.setdefault(msg["channel"], {"type": msg["type"], "rows": []})
        ch["rows"].append({k: v for k, v in msg.items() if k not in ("channel", "type")})
    out = {}
    for name, ch in sorted(channels.items()):
        fields = list(ch["rows"][0])
        out[name] = {"type": ch["type"], "count": len(ch["rows"]),
                     "fields": {f: summarise_column([r[f] for r in ch["rows"]]) for f in fields}}
    return out


def differences(expected, got):
    """Human-readable differences between two channel summaries ([] = equal)."""
    diffs = []
    for name in sorted(set(expected) | set(got)):
        if name not in got or name not in expected:
            diffs.append(f"{name}: only in {'resolver-echo' if name in expected else 'the example'}")
            continue
        e, g = expected[name], got[name]
        if (e["type"], e["count"]) != (g["type"], g["count"]):
            diffs.append(f"{name}: resolver-echo {e['type']} x{e['count']}, example {g['type']} x{g['count']}")
        g_fields = {k: v for k, v in g["fields"].items() if k != LOG_TIME_COLUMN}
        if set(e["fields"]) != set(g_fields):
            diffs.append(f"{name}: fields differ: {sorted(set(e['fields']) ^ set(g_fields))}")
        for f in e["fields"]:
            if f in g_fields and e["fields"][f] != g_fields[f]:
                diffs.append(f"{name}.{f}: resolver-echo {e['fields'][f]} != example {g_fields[f]}")
    return diffs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--python-path", required=True, help="folder holding resolver_lcm")
    ap.add_argument("--example", required=True)
    ap.add_argument("--demo-config", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--duration", default="3", help="[s] of simulated demo bench")
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=args.python_path, PYTHONDONTWRITEBYTECODE="1")
    sys.path.insert(0, args.python_path)
    from resolver_lcm import TYPES_BY_FINGERPRINT
    from resolver_lcm.eventlog import write_events, read_events
    example = load_example_module(args.example)
    failures = []

    candump = os.path.join(args.work, "demo.log")
    lcmlog = os.path.join(args.work, "demo.lcmlog")
    run([f"{args.bin}/resolver-sim", "--config", args.demo_config, "--duration", args.duration, "--out", candump])
    run([f"{args.bin}/resolverd", "--replay", candump, "--once", "--fast", "--quiet",
         "--lcm", f"file://{lcmlog}?mode=w"])

    echo = run([f"{args.bin}/resolver-echo", "--log", lcmlog]).stdout.splitlines()
    expected = summary_from_echo(echo, example.summarise_column)
    counts = {name: ch["count"] for name, ch in expected.items()}
    print(f"resolver-echo: {len(echo)} messages: {counts}")
    for channel in ("RESOLVER_ANGLE", "RESOLVER_DQ", "RESOLVER_ESTIMATE", "RESOLVER_MODEL_FIT", "RESOLVER_HEALTH"):
        if counts.get(channel, 0) == 0:
            failures.append(f"the replay wrote no {channel} message: the comparison would prove little")

    # 1. The example against resolver-echo, with numpy arrays and with lists.
    for mode in ([], ["--no-numpy"]):
        out = run([sys.executable, args.example, lcmlog, "--json"] + mode, env=env)
        got = json.loads(out.stdout)
        diffs = differences(expected, got["channels"])
        if got["undecoded"]:
            diffs.append(f"undecoded messages: {got['undecoded']}")
        label = "lists" if mode else "numpy (if installed)"
        if diffs:
            failures.append(f"example ({label}) differs from resolver-echo:\n  " + "\n  ".join(diffs[:20]))
        else:
            print(f"ok: example ({label}) == resolver-echo on {len(expected)} channels, "
                  f"{sum(len(c['fields']) for c in expected.values())} fields")

    # 2. The same fingerprints as the C++ side's types.
    listed = run([f"{args.bin}/resolver-echo", "--list-types"]).stdout
    cpp = {m.group(2): int(m.group(1), 16) for m in re.finditer(r"0x([0-9a-fA-F]{16})\s+(\S+)", listed)}
    py = {"resolver." + cls.__name__: int.from_bytes(fp, "big") for fp, cls in TYPES_BY_FINGERPRINT.items()}
    if not py or any(cpp.get(name) != fp for name, fp in py.items()):
        failures.append(f"fingerprints differ: python {py}, resolver-echo {cpp}")
    else:
        print(f"ok: {len(py)} Python types have resolver-echo's fingerprints")

    # 3. numpy's .npz export holds the columns.
    try:
        import numpy
    except ImportError:
        numpy = None
        print("note: python3-numpy not installed; --npz not checked")
    if numpy is not None:
        npz = os.path.join(args.work, "demo.npz")
        run([sys.executable, args.example, lcmlog, "--json", "--npz", npz], env=env)
        with numpy.load(npz) as data:
            theta = data["RESOLVER_ANGLE/theta_comp"]
            if theta.shape != (counts["RESOLVER_ANGLE"],):
                failures.append(f"npz RESOLVER_ANGLE/theta_comp shape {theta.shape}")
            else:
                print(f"ok: npz RESOLVER_ANGLE/theta_comp has {theta.shape[0]} values")

    # Controls. a) one event fewer: the comparison must see it.
    events = list(read_events(lcmlog))
    with tempfile.TemporaryDirectory() as tmp:
        shorter = os.path.join(tmp, "shorter.lcmlog")
        write_events(shorter, [(e.channel, e.data, e.timestamp_us) for e in events[:-1]])
        got = json.loads(run([sys.executable, args.example, shorter, "--json"], env=env).stdout)
        if not differences(expected, got["channels"]):
            failures.append("control: a log without its last event compared equal; the comparison cannot fail")
        else:
            print("ok: control: a log without its last event differs")
        # b) a corrupt sync word: both readers refuse it at the same offset.
        broken = os.path.join(tmp, "broken.lcmlog")
        with open(lcmlog, "rb") as f:
            raw = bytearray(f.read())
        raw[events[3].offset] ^= 0x5A
        with open(broken, "wb") as f:
            f.write(raw)
        py_run = run([sys.executable, args.example, broken], env=env, check=False)
        cpp_run = run([f"{args.bin}/resolver-echo", "--log", broken], check=False)
        where = f"byte offset {events[3].offset} (event #4 in the file)"
        if py_run.returncode != 1 or where not in py_run.stderr:
            failures.append(f"control: corrupt log: example exit {py_run.returncode}, stderr {py_run.stderr!r}")
        elif cpp_run.returncode == 0 or where not in cpp_run.stderr:
            failures.append(f"control: corrupt log: resolver-echo exit {cpp_run.returncode}, {cpp_run.stderr!r}")
        else:
            print(f"ok: control: both readers refuse the corrupt log at {where}")

    if failures:
        print("FAIL:\n" + "\n".join(failures))
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
