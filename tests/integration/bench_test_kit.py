"""What every integration script of tests/integration needs: run a program, check and count.

    from bench_test_kit import Checks, run
    c = Checks()
    r = run([model, "fit", log])
    c.check(r.returncode == 0, "fit runs")
    return c.finish("all fit checks passed")

Standard library only.
"""
import subprocess
import sys


# One sensor recorded in several runs (test_pooled_fit.py, test_stats_merge.py): a 3 % gain
# error, a 1 % quadrature and the simulator's 3000 rad/s R/D loop, fitted with this model.
RUN_MODEL = "amplitude_imbalance,quadrature,tracking_loop"
RUN_ALPHA, RUN_BETA = 0.03, 0.01
# Tolerance on alpha and beta: their position error at 2 theta is x/2; 1e-5 leaves 5e-6 rad,
# a sixth of this 16-bit bench's noise floor (2.9e-5 rad, measured by the fit).
RUN_TOL = 1e-5
# [rad] a run's reference-zero constant: the fit finds it to a few standard errors of the
# position error's mean (floor / sqrt(12000 samples) ~ 3e-7); 1e-4 is far above that and far
# below the 1.5 rad the runs' zeros differ by.
RUN_TOL_ZERO = 1e-4


def run(cmd, timeout=300, **kwargs):
    """Runs cmd (any path-like items), returns the CompletedProcess with text output."""
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout, **kwargs)


class Checks:
    """Prints "ok   what" / "FAIL what" per check and counts the failures."""

    def __init__(self):
        self.failures = []

    def check(self, ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            self.failures.append(what)
        return ok

    def finish(self, passed_message):
        """The script's exit code: 1 with a count of the failures, else 0 with `passed_message`."""
        if self.failures:
            print(f"{len(self.failures)} check(s) failed")
            return 1
        print(passed_message)
        return 0


def simulate_run(sim, out, rpm, seed, alpha, beta, theta_0, extra=(), duration=6):
    """One run of one sensor with resolver-sim: amplitude imbalance alpha, quadrature beta and the
    reference's zero theta_0 (mounting_offset), at rpm with the noise seed; exits on failure."""
    r = run([sim, "--out", out, "--rpm", rpm, "--duration", duration, "--seed", seed, "--effect",
             f"amplitude_imbalance:alpha={alpha}", "--effect", f"quadrature:beta={beta}", "--effect",
             f"mounting_offset:theta_0={theta_0}", *extra])
    if r.returncode != 0:
        sys.exit(f"resolver-sim failed: {r.stderr}")
