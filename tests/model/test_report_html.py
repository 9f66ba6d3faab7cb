#!/usr/bin/env python3
"""resolver-model report --html, end to end: resolver-sim hides quadrature next to
amplitude imbalance (Hanselman eq. 5 and 7: alpha = 0.003, beta = 0.002 rad);
`resolver-model report LOG --html OUT` must walk the discovery from the default
model to `explained` by adding quadrature, and write one self-contained page.

The page is checked with Python's html.parser (no browser): every element closed
in order, at least 4 inline <svg> plots, every axis labelled with a unit in
brackets, no external reference (src, href other than #anchors, url() other than
url(#...), @import, script), a title and the log name, the verdict in words,
the step table showing quadrature added and why, and a notes section.

  test_report_html.py --bin BUILD/bin --work DIR
"""
import argparse
import os
import re
import subprocess
import sys
import unittest
from collections import Counter
from html.parser import HTMLParser

ARGS = None
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
EXTERNAL_TAGS = {"script", "link", "img", "iframe", "object", "embed", "image", "use", "audio", "video"}


def run(cmd, expect_rc=0):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if expect_rc is not None and p.returncode != expect_rc:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode} (expected {expect_rc}):\n{p.stdout}\n{p.stderr}")
    return p


class Page(HTMLParser):
    """Collects what the tests look at, and nesting errors."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.stack, self.errors, self.refs = [], [], []
        self.tags = Counter()
        self.title = ""
        self.axis_labels = []      # text of every <text class="axis"> (x and y labels)
        self.steps = []            # rows of <table class="steps">, each a list of cell texts
        self.verdict_class, self.verdict_text = None, ""
        self.h2 = []
        self._in = Counter()       # open elements of interest
        self._cell = None

    def _open(self, tag, attrs):
        self.tags[tag] += 1
        a = dict(attrs)
        for k, v in attrs:
            if k in ("src", "href", "xlink:href", "srcset", "action", "data", "poster"):
                self.refs.append((tag, k, v))
        cls = (a.get("class") or "").split()
        if tag == "text" and "axis" in cls:
            self.axis_labels.append("")
            return "axis"
        if tag == "table" and "steps" in cls:
            return "steps"
        if tag == "tr" and self._in["steps"]:
            self.steps.append([])
        if tag in ("td", "th") and self._in["steps"]:
            self.steps[-1].append("")
            return "cell"
        if tag == "div" and "verdict" in cls:
            self.verdict_class = next((c for c in cls if c.startswith("v-")), None)
            return "verdict"
        if tag in ("title", "h2"):
            if tag == "h2":
                self.h2.append("")
            return tag
        return None

    def handle_starttag(self, tag, attrs):
        mark = self._open(tag, attrs)
        if tag in VOID:
            return
        self.stack.append((tag, mark, self.getpos()))
        if mark:
            self._in[mark] += 1

    def handle_startendtag(self, tag, attrs):  # <circle .../>: opened and closed at once
        self._open(tag, attrs)

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1][0] != tag:
            open_tag = self.stack[-1] if self.stack else None
            self.errors.append(f"</{tag}> at line {self.getpos()[0]} closes {open_tag}")
            return
        _, mark, _ = self.stack.pop()
        if mark:
            self._in[mark] -= 1

    def handle_data(self, data):
        if self._in["axis"]:
            self.axis_labels[-1] += data
        if self._in["cell"]:
            self.steps[-1][-1] += data
        if self._in["verdict"]:
            self.verdict_text += data
        if self._in["title"]:
            self.title += data
        if self._in["h2"]:
            self.h2[-1] += data


class ReportHtml(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        os.makedirs(ARGS.work, exist_ok=True)
        cls.log = os.path.join(ARGS.work, "hidden_quadrature.log")
        cls.out = os.path.join(ARGS.work, "hidden_quadrature.html")
        if os.path.exists(cls.out):
            os.remove(cls.out)
        cls.model = os.path.join(ARGS.bin, "resolver-model")
        run([os.path.join(ARGS.bin, "resolver-sim"), "-o", cls.log, "-e", "amplitude_imbalance:alpha=0.003",
             "-e", "quadrature:beta=0.002", "--seed", "5"])
        cls.proc = run([cls.model, "report", cls.log, "--html", cls.out])
        with open(cls.out, encoding="utf-8") as f:
            cls.html = f.read()
        cls.page = Page()
        cls.page.feed(cls.html)
        cls.page.close()

    def test_stdout_is_a_summary_and_where_it_went(self):
        lines = self.proc.stdout.strip().splitlines()
        self.assertEqual(len(lines), 2, self.proc.stdout)
        self.assertTrue(lines[0].startswith("explained after 2 steps: amplitude_imbalance + quadrature"), lines[0])
        self.assertTrue(lines[1].startswith(f"wrote {self.out}"), lines[1])

    def test_well_formed(self):
        self.assertTrue(self.html.startswith("<!DOCTYPE html>"))
        self.assertEqual(self.page.errors, [])
        self.assertEqual([t for t, _, _ in self.page.stack], [], "elements left open")
        self.assertEqual(self.page.tags["html"], 1)
        self.assertEqual(self.page.tags["body"], 1)

    def test_self_contained(self):
        self.assertEqual([r for r in self.page.refs if not (r[1] == "href" and r[2].startswith("#"))], [])
        self.assertEqual({t for t in self.page.tags if t in EXTERNAL_TAGS}, set())
        self.assertIsNone(re.search(r"url\(\s*['\"]?(?!#)", self.html), "url() to something other than an #id")
        self.assertNotIn("@import", self.html)

    def test_plots_with_units_on_every_axis(self):
        svgs = self.page.tags["svg"]
        self.assertGreaterEqual(svgs, 4)
        self.assertEqual(len(self.page.axis_labels), 2 * svgs, "an x and a y label per plot")
        for label in self.page.axis_labels:
            self.assertRegex(label, r"\[[^\]]+\]", f"axis label without a unit: {label!r}")
        self.assertNotIn("no data", self.html)

    def test_title_log_name_verdict_in_words(self):
        name = os.path.basename(self.log)
        self.assertIn(name, self.page.title)
        self.assertIn(self.log, self.html)
        self.assertEqual(self.page.verdict_class, "v-explained")
        self.assertTrue(self.page.verdict_text.strip().startswith("Explained: the model amplitude_imbalance + quadrature"),
                        self.page.verdict_text)
        self.assertIn("after adding quadrature", self.page.verdict_text)

    def test_step_table_shows_quadrature_added_and_why(self):
        header, *rows = self.page.steps
        self.assertIn("added next, and why", header[-1])
        self.assertEqual(len(rows), 2, rows)
        col = {h.strip(): i for i, h in enumerate(header)}
        first, last = rows
        self.assertEqual(first[col["model"]].strip(), "amplitude_imbalance")
        self.assertEqual(first[col["verdict"]].strip(), "missing_effect")
        why = first[col["added next, and why"]]
        self.assertTrue(why.startswith("+ quadrature"), why)
        self.assertIn("cos winding", why)  # the candidate's physics sentence
        self.assertIn("quadrature", last[col["model"]])
        self.assertEqual(last[col["verdict"]].strip(), "explained")
        for row in rows:  # residual in rad and arcmin and against the floor
            self.assertRegex(row[col["position-error residual"]], r"rad = \S+ arcmin.*x floor")

    def test_notes_section(self):
        self.assertTrue(any(h.startswith("Notes") for h in self.page.h2), self.page.h2)

    def test_unwritable_output_names_the_file(self):
        bad = os.path.join(ARGS.work, "no-such-dir", "x.html")
        p = run([self.model, "report", self.log, "--html", bad], expect_rc=3)  # an I/O error
        self.assertIn(f"cannot write {bad}: No such file or directory", p.stderr)

    def test_starting_model_with_the_effect_needs_one_step(self):
        out = os.path.join(ARGS.work, "one_step.html")
        p = run([self.model, "report", self.log, "--effects", "amplitude_imbalance,quadrature", "--html", out])
        self.assertTrue(p.stdout.startswith("explained after 1 step: amplitude_imbalance + quadrature"), p.stdout)


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
