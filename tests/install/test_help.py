#!/usr/bin/env python3
"""Every program's --help and man page (issue 26).

- each C++ program's usage line names the program, not the path it was run by
  (CLI11 prints argv[0] unless the program names itself);
- every resolver-model subcommand's --help has examples of that subcommand, and
  ends with the exit codes;
- resolverd's description is true to its defaults: [estimator] method = "model"
  fits the [model] effects; Hwang's integral method is an option, not the default;
- with --man DIR: every page with examples in its --help has an EXAMPLES section
  (help2man makes one from an "Examples:" paragraph) set one command a line, as
  --help shows them; resolver-model's page has every subcommand's examples.

Usage: tests/install/test_help.py --bin BUILD/bin [--man BUILD/man/man1]
"""
import argparse
import gzip
import os
import re
import subprocess
import sys
import unittest

ARGS = None
PROGRAMS = ["resolverd", "resolver-sim", "resolver-echo", "resolver-model", "resolver-accuracy"]
SUBCOMMANDS = ["fit", "explain", "report", "export-data", "export", "fleet"]


def run_help(*argv):
    path = os.path.join(ARGS.bin, argv[0])
    proc = subprocess.run([path, *argv[1:], "--help"], capture_output=True, text=True, timeout=60)
    if proc.returncode != 0:
        raise AssertionError(f"{' '.join(argv)} --help exited {proc.returncode}: {proc.stderr}")
    return proc.stdout


def example_commands(help_text, program):
    """The command lines of the "Examples:" paragraph (comments and prose left out)."""
    lines = help_text.splitlines()
    try:
        start = next(i for i, l in enumerate(lines) if l.strip().lower() in ("examples:", "examples"))
    except StopIteration:
        return []
    out = []
    for line in lines[start + 1:]:
        if not line.strip():
            break
        if line.strip() == program or line.strip().startswith(program + " "):
            out.append(line.strip())
    return out


def man_text(name):
    """The page's roff source with the escapes that matter here undone."""
    with gzip.open(os.path.join(ARGS.man, name + ".1.gz"), "rt") as f:
        roff = f.read()
    roff = re.sub(r"\\f[BIRP]|\\f\(..|\\/|\\,", "", roff)
    return roff.replace("\\-", "-").replace("\\e", "\\").replace("\\&", "")


def man_section(roff, title):
    m = re.search(r"^\.SH " + title + r"\n(.*?)(?=^\.SH |\Z)", roff, re.S | re.M)
    return m.group(1) if m else None


class UsageLine(unittest.TestCase):
    def test_programs_name_themselves(self):
        for program in PROGRAMS:
            with self.subTest(program=program):
                usage = [l for l in run_help(program).splitlines() if l.startswith("Usage:")]
                self.assertTrue(usage, f"{program} --help has no usage line")
                self.assertTrue(usage[0].startswith(f"Usage: {program} "), usage[0])

    def test_subcommands_name_the_program(self):
        for sub in SUBCOMMANDS:
            with self.subTest(sub=sub):
                usage = [l for l in run_help("resolver-model", sub).splitlines() if l.startswith("Usage:")]
                self.assertTrue(usage and usage[0].startswith(f"Usage: resolver-model {sub} "), usage)


class SubcommandExamples(unittest.TestCase):
    def test_every_subcommand_has_examples_of_itself(self):
        for sub in SUBCOMMANDS:
            with self.subTest(sub=sub):
                text = run_help("resolver-model", sub)
                commands = example_commands(text, "resolver-model")
                own = [c for c in commands if c.startswith(f"resolver-model {sub} ")]
                self.assertGreaterEqual(len(own), 2, f"resolver-model {sub} --help examples: {commands}")
                self.assertIn("Exit codes: 0 done", text)

    def test_top_level_examples_cover_every_subcommand(self):
        commands = example_commands(run_help("resolver-model"), "resolver-model")
        for sub in SUBCOMMANDS:
            self.assertTrue(any(c.startswith(f"resolver-model {sub} ") for c in commands), (sub, commands))


class ResolverdDescription(unittest.TestCase):
    def test_description_names_the_default_estimator(self):
        text = run_help("resolverd")
        description = text.split("Examples:")[0]
        self.assertIn('[estimator] method = "model"', description)
        self.assertIn("hwang_integral", description)
        # The seed's method is named as the option it is, not as what resolverd does.
        self.assertNotIn("amplitude imbalance (Hwang et al. 2009 integral method)", " ".join(description.split()))


class ManPages(unittest.TestCase):
    def setUp(self):
        if not ARGS.man:
            self.skipTest("no --man: the build makes no man pages (RESOLVER_MAN_PAGES off or no help2man)")

    def check_examples_verbatim(self, page, commands):
        roff = man_text(page)
        section = man_section(roff, "EXAMPLES")
        self.assertIsNotNone(section, f"{page}.1 has no EXAMPLES section")
        self.assertTrue(section.lstrip().startswith(".nf"), f"{page}.1 EXAMPLES is filled: {section[:200]}")
        lines = [l.strip() for l in section.splitlines()]
        for c in commands:
            self.assertIn(c, lines, f"{page}.1 EXAMPLES: '{c}' is not a line of its own")

    def test_examples_section_per_program(self):
        for program in ["resolverd", "resolver-sim", "resolver-echo", "resolver-model", "resolver-accuracy"]:
            with self.subTest(program=program):
                commands = example_commands(run_help(program), program)
                self.assertTrue(commands, f"{program} --help has no examples")
                self.check_examples_verbatim(program, commands)

    def test_resolver_model_page_has_each_subcommands_examples(self):
        roff = man_text("resolver-model")
        subs = man_section(roff, "SUBCOMMANDS")
        self.assertIsNotNone(subs)
        lines = [l.strip() for l in subs.splitlines()]
        for sub in SUBCOMMANDS:
            for c in example_commands(run_help("resolver-model", sub), "resolver-model"):
                with self.subTest(sub=sub, command=c):
                    self.assertIn(c, lines)
        self.assertNotIn(ARGS.bin, roff, "the page names the build path")


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--man", default="")
    ARGS, rest = parser.parse_known_args()
    unittest.main(argv=[sys.argv[0], "-v", *rest])


if __name__ == "__main__":
    main()
