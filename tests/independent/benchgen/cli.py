"""benchgen command line: one simulation, any number of outputs of it."""
import argparse
import os
import sys

import numpy as np

from . import layouts, writers
from .bench import BenchConfig, simulate
from .conventions import TWO_PI
from .effects import EffectError, EffectSet, catalog_text
from .impair import impair_records
from .profile import PRESETS, MotionProfile, ProfileError, parse_profile

FORMAT_VERSION = 1

EXAMPLES = """examples:
  # default bench (docs/ARCHITECTURE.md §4 layout), 200 r/min for 5 s, 0.3 % amplitude imbalance, truth file
  benchgen.py --out imb.log --truth imb.json -e amplitude_imbalance:alpha=0.003 -e noise:sigma_sc=2,sigma_i=0.01
  # a 1X resolver turned one revolution out and back with standstills, as a scope would record it
  benchgen.py --profile out_and_back --p-r 1 --p 4 --sample-rate 100 --layout angle_only \\
      --out sweep.log --csv sweep.csv -e delay:d=0.004 -e backlash:h=0.002
  # the same bench as a Vector ASC log of the default layout
  benchgen.py --asc bench.asc --profile speed_steps -e channel_delay:tau=2e-6 -e tracking_loop:omega_n=3000,zeta=0.7
"""


def build_parser():
    ap = argparse.ArgumentParser(
        prog="benchgen.py", formatter_class=argparse.RawDescriptionHelpFormatter, epilog=EXAMPLES,
        description="Independent resolver-bench log generator (physics from docs/ARCHITECTURE.md and the papers, "
                    "not from resolver-sim). Writes candump -l, Vector ASC, scope CSV and truth files.")
    out = ap.add_argument_group("outputs (at least one)")
    out.add_argument("--out", metavar="LOG", help="candump -l log of the chosen layout")
    out.add_argument("--asc", metavar="FILE", help="Vector ASC log of the chosen layout (python-can ASCWriter)")
    out.add_argument("--csv", metavar="FILE",
                     help="scope-style CSV: FILETIME time, ';' separator, decimal comma, angles in degrees")
    out.add_argument("--csv-columns", default="rd_angle,ref_angle",
                     help=f"CSV columns, comma separated, from {','.join(writers.CSV_COLUMNS)} (default rd_angle,ref_angle)")
    out.add_argument("--truth", metavar="FILE.json", help="every effect and parameter, profile, layout, rate, seed, events")
    out.add_argument("--truth-samples", metavar="FILE.csv", help="per-sample truth: true theta_m, speed, converter angle, eps")
    out.add_argument("--write-dbc", metavar="FILE", help="copy the chosen layout's DBC here")
    motion = ap.add_argument_group("motion")
    motion.add_argument("--profile", help="rpm:seconds items, 'a-b:s' ramps, negative speeds, 0 = hold "
                                          f"(e.g. '0:1,30:2,0:1,-30:2,0:1'), or a preset: {', '.join(PRESETS)}")
    motion.add_argument("--rpm", type=float, default=200.0, help="constant speed without --profile [r/min] (200)")
    motion.add_argument("--duration", type=float, default=5.0, help="run length with --rpm [s] (5)")
    motion.add_argument("--start-angle", type=float, default=0.0, help="theta_m at t = 0 [mech deg] (0)")
    bench = ap.add_argument_group("bench")
    bench.add_argument("--sample-rate", type=float, default=2000.0, help="samples per second [Hz] (2000)")
    bench.add_argument("--p-r", type=int, default=3, help="resolver pole pairs (3)")
    bench.add_argument("--p", type=int, default=3, help="motor pole pairs (3)")
    bench.add_argument("--rd-bits", type=int, default=16, help="R/D resolution [bits] without a quantization effect (16)")
    bench.add_argument("--amplitude", type=float, default=26000.0, help="sin/cos envelope amplitude [counts] (26000)")
    bench.add_argument("--iq", type=float, default=10.0, help="commanded q current [A] (10)")
    bench.add_argument("--id", type=float, default=0.0, help="commanded d current [A] (0)")
    bench.add_argument("--drive-angle", choices=("reference", "rd"), default="reference",
                       help="drive frame: p theta_m + theta_0 (reference, default) or from the R/D angle (rd)")
    bench.add_argument("--ref-zero", type=float, default=0.0,
                       help="the reference encoder's zero against the rotor's [mech deg] (0): ref = theta_m - zero")
    bench.add_argument("--two-current-sensors", action="store_true", help="report i_c = -(i_a + i_b)")
    bench.add_argument("-e", "--effect", action="append", default=[], metavar="SPEC",
                       help="name:param=value,... (repeatable; --list-effects)")
    bench.add_argument("--seed", type=int, default=1, help="random seed (1): same seed, same files")
    log = ap.add_argument_group("log")
    log.add_argument("--layout", choices=layouts.LAYOUTS, default="default",
                     help="default (docs/ARCHITECTURE.md §4), angle_only (degrees, no counter/CRC), be_counter (big endian)")
    log.add_argument("--no-reference", action="store_true", help="no reference angle frames")
    log.add_argument("--no-currents", action="store_true", help="no phase current frames")
    log.add_argument("--iface", default="can0", help="interface name in candump lines (can0)")
    log.add_argument("--start-time", type=float, default=1700000000.0, help="Unix time of the first sample [s]")
    info = ap.add_argument_group("information")
    info.add_argument("--list-effects", action="store_true", help="print the effects and exit")
    info.add_argument("--list-presets", action="store_true", help="print the profile presets and exit")
    return ap


def _fail(message):
    print(f"benchgen: {message}", file=sys.stderr)
    return 2


def _validate(args):
    if not 1 <= args.p_r <= 255 or not 1 <= args.p <= 255:
        return "--p-r and --p must be in 1..255 (u8 in BENCH_INFO)"
    if not 1 <= args.rd_bits <= 16:
        return "--rd-bits must be in 1..16"
    if not args.sample_rate > 0:
        return "--sample-rate must be > 0"
    if args.layout == "default" and (args.sample_rate != round(args.sample_rate) or args.sample_rate > 65535):
        return "--sample-rate must be a whole number of Hz <= 65535 for the default layout (u16 in BENCH_INFO)"
    if not (args.out or args.asc or args.csv or args.truth or args.truth_samples or args.write_dbc):
        return "no output: give --out, --asc, --csv, --truth, --truth-samples or --write-dbc"
    bad = [c for c in args.csv_columns.split(",") if c not in writers.CSV_COLUMNS]
    if bad:
        return f"--csv-columns: unknown {', '.join(bad)}; known: {', '.join(writers.CSV_COLUMNS)}"
    return None


def _truth(args, config, profile, samples, outputs, frames):
    direction = profile.direction_runs()
    loop = config.effects.get("tracking_loop")
    travel = np.abs(np.diff(samples.theta_m)).sum() / TWO_PI
    layout = os.path.relpath(layouts.dbc_path(args.layout), layouts.REPO_ROOT)  # from the repository root
    ids, counts = np.unique(frames.can_id, return_counts=True) if frames is not None else ([], [])
    return {
        "generator": "benchgen (tests/independent)", "format_version": FORMAT_VERSION,
        "command": sys.argv,
        "seed": config.seed,
        "sample_rate_hz": config.sample_rate, "samples": len(samples),
        "p_r": config.p_r, "p": config.p, "rd_bits": samples.rd_bits,
        "amplitude_counts": config.amplitude, "i_d_A": config.i_d, "i_q_A": config.i_q,
        "drive_angle": config.drive_angle, "two_current_sensors": config.two_sensors,
        "start_time_unix_s": args.start_time, "start_angle_rad": config.start_angle,
        "profile": {"text": config.profile, "expanded": PRESETS.get(config.profile, config.profile),
                    "duration_s": profile.total, "segments": profile.describe(),
                    "reversal_times_s": [float(b) for b in direction[0]],
                    "mechanical_travel_rev": float(travel)},
        "converter": ({"kind": "tracking_loop", "omega_n_rad_s": loop["omega_n"], "zeta": loop["zeta"],
                       "rk4_substeps_per_sample": samples.substeps}
                      if samples.substeps else {"kind": "ideal (atan2)"}),
        "layout": {"name": args.layout, "dbc": layout, "reference": not args.no_reference,
                   "currents": not args.no_currents, "iface": args.iface,
                   "frames_per_id": {f"0x{int(i):03X}": int(c) for i, c in zip(ids, counts)}},
        "effects": config.effects.describe(),
        "events": samples.events,
        "outputs": outputs,
        "conventions": "eps = theta_true - theta_measured [resolver electrical rad]; theta = p_r theta_m; "
                       "theta_e = p theta_m; Clarke amplitude-invariant; Park i_d = i_alpha cos + i_beta sin",
    }


def main(argv=None):
    args = build_parser().parse_args(argv)
    if args.list_effects:
        print(catalog_text())
        return 0
    if args.list_presets:
        for name, text in PRESETS.items():
            print(f"{name:<14} {text}")
        return 0
    problem = _validate(args)
    if problem:
        return _fail(problem)
    profile_text = args.profile if args.profile else f"{args.rpm:g}:{args.duration:g}"
    try:
        effects = EffectSet(args.effect)
        profile = MotionProfile(parse_profile(profile_text), np.deg2rad(args.start_angle))
    except (EffectError, ProfileError) as error:
        return _fail(str(error))
    config = BenchConfig(profile=profile_text, sample_rate=args.sample_rate, p_r=args.p_r, p=args.p,
                         amplitude=args.amplitude, i_d=args.id, i_q=args.iq, seed=args.seed, effects=effects,
                         drive_angle=args.drive_angle, start_angle=np.deg2rad(args.start_angle),
                         rd_bits=args.rd_bits, two_sensors=args.two_current_sensors,
                         ref_zero=np.deg2rad(args.ref_zero))
    samples = simulate(config)
    start_us = int(round(args.start_time * 1e6))
    outputs = {}
    frames = None
    if args.out or args.asc or args.truth:
        frames = layouts.encode(samples, config, args.layout, not args.no_reference, not args.no_currents)
    if args.out or args.asc:
        index, times, stats = impair_records(frames.t, effects, args.seed)
        if args.out:
            writers.write_candump(args.out, frames, index, times, start_us, args.iface)
            outputs["candump"] = {"path": args.out, **stats}
        if args.asc:
            writers.write_asc(args.asc, frames, index, times, start_us)
            outputs["asc"] = {"path": args.asc, **stats}
    if args.csv:
        columns = args.csv_columns.split(",")
        index, times, stats = impair_records(samples.t, effects, args.seed)
        writers.write_scope_csv(args.csv, samples, index, times, start_us, columns, args.sample_rate)
        outputs["csv"] = {"path": args.csv, "columns": columns, "header_lines": writers.CSV_HEADER_LINES,
                          "separator": ";", "decimal": ",", "time": "FILETIME 100 ns ticks", **stats}
    if args.write_dbc:
        with open(layouts.dbc_path(args.layout), encoding="utf-8") as src, \
                open(args.write_dbc, "w", encoding="utf-8") as dst:
            dst.write(src.read())
        outputs["dbc"] = {"path": args.write_dbc}
    if args.truth_samples:
        writers.write_truth_samples(args.truth_samples, samples, config.p_r)
        outputs["truth_samples"] = {"path": args.truth_samples}
    if args.truth:
        writers.write_truth_json(args.truth, _truth(args, config, profile, samples, outputs, frames))
    return 0
