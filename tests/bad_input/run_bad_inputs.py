#!/usr/bin/python3
"""Runs resolverd on every bad-input case of cases.json and checks what it says.

For a log case (kind "log"; a candump, Vector ASC or CSV file, with its config if named):
  resolverd --replay FILE [--config CONFIG] --once --fast --quiet --lcm memq:// --report R.json
  must exit 0 (bad input is counted, never fatal), count expected_count problems
  under expected_reason in R.json "rejects", count nothing else except the
  reasons listed in also_expected (with exactly those counts), print a line
  "resolverd: ... <expected_message_substring> ... [<reason>]" on stderr, and,
  where expected_samples is given, decode exactly that many samples (nothing lost).
For a signal-fault case (kind "health"): the same run must exit 0 with no reject,
  report every fault of expected_faults in R.json "signal_health" for at least the
  given share of the samples, report no other fault, and print the message.
For a config or DBC case (kind "config" / "dbc"):
  resolverd --config CONFIG --replay cases/clean.log (or the case's "replay") ... must
  refuse to start: exit 2 with "resolverd: ...<expected_message_substring>..." on stderr.
Any death by a signal, a sanitizer report or a timeout fails the case.

Paths in cases.json are relative to this folder, where resolverd runs.
Python 3 standard library only.

  run_bad_inputs.py --resolverd build/bin/resolverd [--only NAME ...] [-v]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CLEAN_LOG = "cases/clean.log"
TIMEOUT_S = 120


def run(resolverd, args, work):
    report = os.path.join(work, "report.json")
    if os.path.exists(report):
        os.remove(report)
    cmd = [resolverd] + args + ["--once", "--fast", "--quiet", "--lcm", "memq://", "--report", report]
    try:
        proc = subprocess.run(cmd, cwd=HERE, capture_output=True, text=True, errors="replace", timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return None, "", None, cmd
    data = None
    if os.path.exists(report):
        with open(report, encoding="utf-8") as f:
            data = json.load(f)
    return proc.returncode, proc.stderr, data, cmd


def check_case(case, resolverd, work):
    """Returns a list of failure strings (empty = pass)."""
    kind = case["kind"]
    want = case["expected_message_substring"]
    if kind in ("log", "health"):
        args = ["--replay", case["file"]] + (["--config", case["config"]] if "config" in case else [])
        want_rc = 0
    elif kind == "config":
        args = ["--config", case["file"], "--replay", case.get("replay", CLEAN_LOG)]
        want_rc = 2
    elif kind == "dbc":
        args = ["--config", case["config"], "--replay", case.get("replay", CLEAN_LOG)]
        want_rc = 2
    else:
        return ["unknown kind '%s' in cases.json" % kind]

    rc, stderr, report, cmd = run(resolverd, args, work)
    failures = []
    where = "command: " + " ".join(cmd)
    if rc is None:
        return ["timed out after %d s (%s)" % (TIMEOUT_S, where)]
    if rc < 0:
        failures.append("resolverd died by signal %d (%s)" % (-rc, where))
    if "Sanitizer" in stderr or "runtime error:" in stderr:
        failures.append("sanitizer report on stderr")
    if rc != want_rc:
        failures.append("exit code %d, expected %d (%s)" % (rc, want_rc, where))

    lines = [l for l in stderr.splitlines() if l.startswith("resolverd: ")]
    if kind not in ("log", "health"):
        # Config/DBC errors may list several problems on indented lines below the "resolverd: " one.
        if not lines:
            failures.append("no 'resolverd: ' line on stderr")
        elif want not in stderr:
            failures.append("stderr does not contain %r" % want)
    elif want:
        hits = [l for l in lines if want in l]
        if not hits:
            failures.append("no 'resolverd: ' stderr line contains %r" % want)
        elif kind == "log" and case["expected_reason"]:
            tag = "[%s]" % case["expected_reason"]
            if not any(l.endswith(tag) or "'%s'" % case["expected_reason"] in l for l in hits):
                failures.append("the line with %r does not name the reason %s: %s" % (want, tag, hits[0]))

    if kind in ("log", "health"):
        if report is None:
            failures.append("no report written")
        else:
            rejects = report.get("rejects", {})
            expected = dict(case.get("also_expected", {}))
            if case["expected_reason"]:
                expected[case["expected_reason"]] = case["expected_count"]
            for reason, count in sorted(expected.items()):
                if rejects.get(reason, 0) != count:
                    failures.append("rejects[%s] = %s, expected %d" % (reason, rejects.get(reason, 0), count))
            extra = {r: n for r, n in rejects.items() if r not in expected and n}
            if extra:
                failures.append("unexpected rejects %s (the damage leaked into other counters)" % extra)
            faults = report.get("signal_health", {}).get("faults", {})
            wanted = case.get("expected_faults", {})
            for name, share in sorted(wanted.items()):
                got = faults.get(name, {}).get("share", 0)
                if got < share:
                    failures.append("signal fault %s held for %.3f of the samples, expected at least %.3f"
                                    % (name, got, share))
            others = {n: f["samples"] for n, f in faults.items() if n not in wanted and f["samples"]}
            if others:
                failures.append("unexpected signal faults %s" % others)
            if "expected_samples" in case:
                got = report.get("samples_complete", 0) + report.get("samples_incomplete", 0)
                if got != case["expected_samples"]:
                    failures.append("%d samples decoded, expected %d" % (got, case["expected_samples"]))
    if failures:
        tail = "\n".join("      | " + l for l in stderr.splitlines()[-15:])
        failures.append("stderr (last lines):\n" + tail)
    return failures


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--resolverd", required=True, help="path to the resolverd binary")
    ap.add_argument("--cases", default=os.path.join(HERE, "cases.json"))
    ap.add_argument("--only", action="append", default=[], help="run only this case (file stem); repeatable")
    ap.add_argument("-v", "--verbose", action="store_true", help="print resolverd's stderr for every case")
    opts = ap.parse_args()
    resolverd = os.path.abspath(opts.resolverd)
    if not os.access(resolverd, os.X_OK):
        print("run_bad_inputs: %s is not an executable; build resolverd first" % resolverd, file=sys.stderr)
        return 2
    with open(opts.cases, encoding="utf-8") as f:
        cases = json.load(f)["cases"]
    if opts.only:
        cases = [c for c in cases if os.path.splitext(os.path.basename(c["file"]))[0] in opts.only]
        if not cases:
            print("run_bad_inputs: no case matches %s" % opts.only, file=sys.stderr)
            return 2

    failed = 0
    with tempfile.TemporaryDirectory(prefix="bad_input_") as work:
        for case in cases:
            name = os.path.basename(case["file"])
            failures = check_case(case, resolverd, work)
            if failures:
                failed += 1
                print("FAIL %s" % name)
                for fl in failures:
                    print("    " + fl)
            else:
                if case["kind"] == "health":
                    summary = " ".join(sorted(case["expected_faults"]))
                elif case["kind"] != "log":
                    summary = "refused to start (exit 2)"
                elif case["expected_reason"]:
                    summary = "%s=%d" % (case["expected_reason"], case["expected_count"])
                else:
                    summary = "no rejects"
                print("ok   %-34s %s" % (name, summary))
            if opts.verbose:
                _, stderr, _, _ = run(resolverd, ["--replay", case["file"]] + (["--config", case["config"]] if "config" in case else [])
                                      if case["kind"] in ("log", "health") else
                                      ["--config", case.get("config", case["file"]), "--replay",
                                       case.get("replay", CLEAN_LOG)], work)
                print("\n".join("      | " + l for l in stderr.splitlines()))
    print("%d of %d bad-input cases passed" % (len(cases) - failed, len(cases)))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
