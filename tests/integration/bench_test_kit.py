"""What every integration script of tests/integration needs: run a program, check and count.

    from bench_test_kit import Checks, run
    c = Checks()
    r = run([model, "fit", log])
    c.check(r.returncode == 0, "fit runs")
    return c.finish("all fit checks passed")

Standard library only.
"""
import subprocess


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
