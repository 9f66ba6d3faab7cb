#!/usr/bin/python3
"""Makes tools/examples/scope_sweep.csv: a 1X resolver (p_r = 1) turned one way and back at
60 r/min with standstills before, between and after, as a digital scope exports it: the R/D
converter's angle and the reference encoder, in degrees, ';' separated with decimal commas,
four header lines and a name line, time in seconds from the trigger.

The bench behind it is resolver-sim's, with what real out-and-back benches have: amplitude
imbalance (the default model), play in the coupling (backlash) and a 3rd winding harmonic.
resolver-model is told none of this; the README's walk-through finds it.

  /usr/bin/python3 tools/examples/make_scope_sweep.py build/bin/resolver-sim tools/examples/scope_sweep.csv
"""
import os
import subprocess
import sys
import tempfile

PROFILE = "0:0.5,60:2,0:0.5,-60:2,0:0.5"  # [r/min:s]: hold, 2 turns forward, hold, 2 back, hold
EFFECTS = ["amplitude_imbalance:alpha=0.004", "backlash:h=0.002", "harmonics:k3=0.0006"]
RATE = 1000  # [Hz] the scope's sample rate


def main():
    sim, out = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "sweep.log")
        cmd = [sim, "--out", log, "--p-r", "1", "--p", "4", "--profile", PROFILE, "--sample-rate", str(RATE),
               "--seed", "11"]
        for e in EFFECTS:
            cmd += ["-e", e]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        rows, t0 = [], None
        with open(log, encoding="ascii") as f:
            for line in f:  # "(1700000000.000500) can0 100#<hex>" (docs/ARCHITECTURE.md §4 payloads)
                stamp, _, frame = line.split()
                can_id, data = frame.split("#")
                data = bytes.fromhex(data)
                t = float(stamp.strip("()"))
                if can_id == "100":  # RESOLVER_SAMPLE: bytes 5-6 u16 R/D angle, 65536 = 360 deg electrical
                    t0 = t if t0 is None else t0
                    rows.append([t - t0, int.from_bytes(data[5:7], "little") * 360.0 / 65536.0, None])
                elif can_id == "102" and rows:  # REFERENCE_ANGLE: bytes 1-4 u32, 2^32 = 360 deg mechanical
                    rows[-1][2] = int.from_bytes(data[1:5], "little") * 360.0 / 4294967296.0
    lines = ["Scope export", "Model;DSO-4024", "Sample rate;1 kHz", "Probe;CH1 R/D angle, CH2 encoder (deg)",
             "Time [s];R/D angle [deg];Encoder [deg]"]
    for t, rd, ref in rows:
        lines.append(";".join(("%.4f" % t, "%.4f" % rd, "%.5f" % ref)).replace(".", ","))
    with open(out, "w", encoding="ascii") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
