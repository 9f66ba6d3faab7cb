#!/usr/bin/env python3
"""Load resolverd's LCM log into arrays, one per field and channel, and summarise them.

    resolverd --replay demo.log --once --fast --lcm 'file:///tmp/demo.lcmlog?mode=w'
    python3 lcmlog_to_arrays.py /tmp/demo.lcmlog                     # a table per channel
    python3 lcmlog_to_arrays.py /tmp/demo.lcmlog --channel RESOLVER_DQ --json
    python3 lcmlog_to_arrays.py /tmp/demo.lcmlog --npz /tmp/demo.npz  # numpy.load() it later

In your own code the whole job is two lines:

    from resolver_lcm import load_log
    dq = load_log("/tmp/demo.lcmlog")["RESOLVER_DQ"]; i_d = dq["i_d_comp"]   # [A]

Needs the resolver_lcm package on the Python path: installed by the .deb (or
cmake --install) into dist-packages, or build/python in a build tree
(PYTHONPATH=build/python). numpy is optional (python3-numpy): without it the
columns are lists; --npz needs it. Exit status: 0 ok, 1 unreadable or corrupt
log, 2 bad command line.
"""

import argparse
import json
import math
import sys

try:
    from resolver_lcm import LOG_TIME_COLUMN, EventLogError, load_log
except ImportError as e:
    sys.exit(f"lcmlog_to_arrays: cannot import resolver_lcm ({e}); set PYTHONPATH to the folder that "
             "holds it: <prefix>/lib/python3/dist-packages when installed, build/python in a build tree")


def _plain(value):
    """A JSON-able copy: numpy values to Python ones, NaN and +-inf to None (as resolver-echo prints them)."""
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def summarise_column(values):
    """first/last value of any column; min/max/non-finite count of a numeric 1-D one."""
    values = _plain(values)
    out = {"first": values[0], "last": values[-1]}
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) or v is None for v in values):
        finite = [v for v in values if v is not None]
        out["non_finite"] = len(values) - len(finite)
        if finite:
            out["min"], out["max"] = min(finite), max(finite)
    return out


def summarise(log):
    summary = {"channels": {}, "undecoded": dict(log.undecoded)}
    for name, channel in sorted(log.channels.items()):
        summary["channels"][name] = {
            "type": channel.type_name,
            "count": channel.count,
            "fields": {f: summarise_column(channel[f]) for f in channel.field_names()},
        }
    return summary


def _number(v):
    return f"{v:d}" if isinstance(v, int) else f"{v:.12g}"


def print_table(summary):
    for name, channel in summary["channels"].items():
        t = channel["fields"][LOG_TIME_COLUMN]
        span_s = (t["last"] - t["first"]) * 1e-6
        print(f"{name} ({channel['type']}): {channel['count']} messages over {span_s:.3f} s of log time")
        for field, s in channel["fields"].items():
            if "min" in s:
                print(f"  {field:28s} min {_number(s['min']):<24} max {_number(s['max']):<24} "
                      f"non-finite {s['non_finite']}")
            else:
                print(f"  {field:28s} last {json.dumps(s['last'])[:70]}")
    for name, n in summary["undecoded"].items():
        print(f"{name}: {n} messages of an unknown type (not a resolver_lcm type)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("log", help="LCM event log (resolverd --lcm file://...?mode=w, lcm-logger)")
    parser.add_argument("--channel", action="append", help="only this channel (repeatable)")
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    parser.add_argument("--npz", metavar="OUT", help="save every column as OUT (numpy .npz, keys CHANNEL/field)")
    parser.add_argument("--no-numpy", action="store_true", help="plain Python lists even if numpy is installed")
    args = parser.parse_args(argv)

    try:
        log = load_log(args.log, channels=args.channel, use_numpy=False if args.no_numpy else None)
    except (OSError, EventLogError, ValueError) as e:
        print(f"lcmlog_to_arrays: {e}", file=sys.stderr)
        return 1
    summary = summarise(log)
    if args.json:
        print(json.dumps(summary, allow_nan=False))
    else:
        print_table(summary)
    if args.npz:
        try:
            import numpy
        except ImportError:
            print("lcmlog_to_arrays: --npz needs numpy (Debian: apt-get install python3-numpy)", file=sys.stderr)
            return 2
        arrays, ragged = {}, []
        for c, ch in log.channels.items():
            for f in ch.field_names():
                try:
                    a = numpy.asarray(ch[f])
                except ValueError:  # numpy >= 1.24 refuses ragged lists
                    a = None
                if a is None or a.dtype == object:
                    ragged.append(f"{c}/{f}")  # variable-length arrays: one length per message
                else:
                    arrays[f"{c}/{f}"] = a
        numpy.savez(args.npz, **arrays)
        if ragged:
            print(f"lcmlog_to_arrays: not in {args.npz} (variable length per message): {', '.join(ragged)}",
                  file=sys.stderr)
        print(f"wrote {len(arrays)} arrays to {args.npz}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
