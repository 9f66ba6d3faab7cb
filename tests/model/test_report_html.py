#!/usr/bin/env python3
"""resolver-model report --html, end to end: resolver-sim hides quadrature next to
amplitude imbalance (Hanselman eq. 5 and 7: alpha = 0.003, beta = 0.002 rad);
`resolver-model report LOG --html OUT` must walk the discovery from the default
model to `explained` by adding quadrature, and write one self-contained page.

The page is checked with Python's html.parser (no browser; test_report_browser.py
renders it): every element closed in order; no external reference (src, href other
than #anchors, url() other than url(#...), @import; scripts inline only); the plots'
data (one inline JSON element) with a unit and a CSV column name on every axis, one
residual panel per step, i_d and i_q against θ_e; every table with its units (the
parameters' unit column filled); what the statistics cover, the floors and where
they come from, held-back validation; a title and the log name, the verdict in
words, the step table showing quadrature added and why, and a notes section.

  test_report_html.py --bin BUILD/bin --work DIR
"""
import argparse
import json
import os
import re
import subprocess
import sys
import unittest
from collections import Counter
from html.parser import HTMLParser

ARGS = None
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
EXTERNAL_TAGS = {"link", "img", "iframe", "object", "embed", "image", "use", "audio", "video"}
IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")  # a MATLAB variable / pandas column name


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
        self.tables = []           # every table: rows of cell texts
        self.data_json = ""        # the plots' data (<script type="application/json" id="report-data">)
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
        if tag == "table":
            self.tables.append([])
            if "steps" in cls:
                self.steps = self.tables[-1]
            return "table"
        if tag == "tr" and self._in["table"]:
            self.tables[-1].append([])
        if tag in ("td", "th") and self._in["table"]:
            self.tables[-1][-1].append("")
            return "cell"
        if tag == "script" and a.get("id") == "report-data":
            return "data"
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
            self.tables[-1][-1][-1] += data
        if self._in["data"]:
            self.data_json += data
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
        self.assertNotIn("import(", self.html, "a dynamic import")
        # uPlot, its licence notice and the page's script are inline.
        self.assertGreaterEqual(self.page.tags["script"], 3)
        self.assertIn("Permission is hereby granted, free of charge", self.html)
        self.assertIn("var uPlot=", self.html)

    def test_plots_data_with_units_on_every_axis(self):
        plots = json.loads(self.page.data_json)["plots"]
        ids = [p["id"] for p in plots]
        self.assertEqual(len(ids), len(set(ids)), "plot ids are unique")
        self.assertGreaterEqual(len(plots), 8)
        for p in plots:
            for axis in (p["x"], p["y"]):
                self.assertTrue(axis["unit"], f"{p['id']}: axis {axis['label']!r} without a unit")
                self.assertRegex(axis["column"], IDENTIFIER, p["id"])
            self.assertTrue(p["series"], p["id"])
            for s in p["series"]:
                self.assertEqual(len(s["x"]), len(s["y"]), f"{p['id']} {s['label']}")
                self.assertTrue(s["label"], p["id"])
            # Every plot has a figure with a chart, a legend and a CSV button.
            for attr in ("data-plot", "data-legend", "data-csv"):
                self.assertIn(f'{attr}="{p["id"]}"', self.html)
        # One residual panel per discovery step, measured drawn over the model.
        self.assertIn("res1", ids)
        self.assertIn("res2", ids)
        self.assertNotIn("res3", ids)
        pe = next(p for p in plots if p["id"] == "pe")
        marks = [s["mark"] for s in pe["series"]]
        self.assertLess(marks.index("line"), marks.index("band"), "the model line first, the measured band on top")
        # The dq currents against the motor electrical angle.
        for pid in ("dqd", "dqq"):
            self.assertEqual(next(p for p in plots if p["id"] == pid)["x"]["column"], "theta_e_deg")

    def test_tables_carry_units(self):
        params = next(t for t in self.page.tables if t[0][:4] == ["parameter", "value", "standard error", "unit"])
        self.assertGreaterEqual(len(params), 3, "alpha and beta")
        for row in params[1:]:
            self.assertTrue(row[3].strip(), f"{row[0]} has no unit")
        # Every bare number in every table has its unit: a "unit" column, a unit in brackets in
        # its header, or it is a count (samples, rows, steps, parameters k) or a BIC.
        counts = {"step", "k", "BIC", "BIC drop", "samples", "rows"}
        for table in self.page.tables:
            header = [h.strip() for h in table[0]]
            if "unit" in header:
                continue
            for row in table[1:]:
                for h, cell in zip(header, row):
                    if re.fullmatch(r"\s*-?[0-9.]+(e[-+]?[0-9]+)?\s*", cell):
                        self.assertTrue("[" in h or h in counts, f"{cell!r} under {h!r} has no unit")

    def test_coverage_floors_and_held_back_validation(self):
        self.assertTrue(any(h.startswith("What the statistics cover") for h in self.page.h2), self.page.h2)
        cover = next(t for t in self.page.tables if t[0] == ["what", "count", "unit"])
        fitted = next(r for r in cover if r[0].startswith("fitted"))
        self.assertEqual(fitted[1].strip(), "10000")  # 5 s at 2 kHz, all moving
        floors = next(t for t in self.page.tables if "floor used" in t[0])
        self.assertEqual([r[0] for r in floors[1:]], ["position_error", "sin_cos", "i_dq"])
        col = floors[0].index("from")
        for r in floors[1:]:
            self.assertIn(r[col].strip(), ("standstill", "second_differences"))
        signals = next(t for t in self.page.tables if "held back / floor" in t[0])
        self.assertEqual(len(signals), 4)
        self.assertIn("Held-back validation", self.html)
        self.assertIn("Whiteness", self.html)

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

    def test_unexplained_log_gets_the_suggested_custom_block(self):
        # Alpha drifting in time is outside the catalog (resolver-sim --alpha-drift): unexplained,
        # and the page carries the [[model.custom]] block that describes the residual.
        log = os.path.join(ARGS.work, "alpha_drift.log")
        out = os.path.join(ARGS.work, "alpha_drift.html")
        run([os.path.join(ARGS.bin, "resolver-sim"), "-o", log, "--alpha-drift", "0.002", "-e",
             "amplitude_imbalance:alpha=0.003", "--seed", "5"])
        p = run([self.model, "report", log, "--html", out])
        self.assertTrue(p.stdout.startswith("unexplained after 1 step"), p.stdout)
        page = Page()
        with open(out, encoding="utf-8") as f:
            html = f.read()
        page.feed(html)
        self.assertEqual(page.verdict_class, "v-unexplained")
        self.assertIn("Suggested custom effect", page.h2)
        block = re.search(r'<pre class="custom">(.*?)</pre>', html, re.S)
        self.assertIsNotNone(block)
        self.assertTrue(block.group(1).startswith("[[model.custom]]\nname = &quot;"), block.group(1)[:80])
        self.assertIn("t*sin(2*theta)", block.group(1))  # the residual changes with time at 2 theta

    def plot_ids_and_page(self, name, sim_args, report_args=()):
        log = os.path.join(ARGS.work, name + ".log")
        out = os.path.join(ARGS.work, name + ".html")
        run([os.path.join(ARGS.bin, "resolver-sim"), "-o", log, "--seed", "5"] + list(sim_args))
        p = run([self.model, "report", log, "--html", out] + list(report_args))
        page = Page()
        with open(out, encoding="utf-8") as f:
            html = f.read()
        page.feed(html)
        return p, json.loads(page.data_json)["plots"], html

    def test_failing_signal_leads_the_plots(self):
        # Dead time (6 theta_e in i_d, i_q) left out of a one-step run: i_dq is 16x its floor,
        # the position error at it; the page opens with the dq residual by harmonic, saying why.
        p, plots, html = self.plot_ids_and_page("dead_time_one_step", ["-e", "dead_time:t_d=3e-6"],
                                                ["--max-steps", "1"])
        self.assertTrue(p.stdout.startswith("missing_effect after 1 step"), p.stdout)
        self.assertEqual(plots[0]["id"], "specdq")
        self.assertFalse(plots[0]["half"])
        self.assertEqual(plots[1]["id"], "pe")
        first = re.search(r'<figure class="plot" id="fig-([a-z0-9]+)">.*?<figcaption>(.*?)</figcaption>', html)
        self.assertEqual(first.group(1), "specdq")
        self.assertTrue(first.group(2).startswith("Shown first: i_dq is the signal furthest above its floor ("),
                        first.group(2)[:120])
        # Explained: the position error leads as always, with no such sentence.
        plots = json.loads(self.page.data_json)["plots"]
        self.assertEqual(plots[0]["id"], "pe")
        self.assertNotIn("Shown first", self.html)

    def test_single_speed_and_direction_say_so(self):
        # The setUpClass log runs at one speed, forward only: no one-dot speed plot, no one-row table.
        ids = [p["id"] for p in json.loads(self.page.data_json)["plots"]]
        self.assertNotIn("speed", ids)
        self.assertIn("One speed: the speed breakdown has one bin (200 r/min", self.html)
        self.assertIn("One direction: every fitted sample turned forward", self.html)
        self.assertFalse(any(t[0][:1] == ["direction"] for t in self.page.tables), "no one-row direction table")
        # Control: a ramp and an out-and-back have the speed plot and the direction table.
        _, plots, html = self.plot_ids_and_page("ramp_out_and_back",
                                                ["--profile", "200:1.5,200-600:1.5,-200:2", "-e",
                                                 "amplitude_imbalance:alpha=0.003"])
        speed = next(p for p in plots if p["id"] == "speed")
        self.assertGreater(len(speed["series"][0]["x"]), 1)
        self.assertNotIn("One speed", html)
        self.assertNotIn("One direction", html)
        self.assertIn("<th>direction</th>", html)

    def test_standard_errors_name_their_basis_alike_in_text_json_and_html(self):
        # One story of uncertainty (issue 26): the text header, the JSON and the page's note
        # say the same basis; the 5 s, 200 r/min log has enough revolutions for the spread.
        text = run([self.model, "explain", self.log]).stdout
        basis = json.loads(run([self.model, "explain", self.log, "--json"]).stdout)["standard_errors"]
        self.assertRegex(basis, r"^robust: revolution-to-revolution spread of \d+ revolutions$")
        self.assertIn(f"parameters (value +- standard error, {basis}):", text)
        self.assertIn("Standard errors, robust: revolution-to-revolution spread of ", self.html)
        # Too few revolutions: formal, saying so the same way.
        short = os.path.join(ARGS.work, "short.log")
        run([os.path.join(ARGS.bin, "resolver-sim"), "-o", short, "--duration", "0.4", "--seed", "5"])
        basis = json.loads(run([self.model, "explain", short, "--json"]).stdout)["standard_errors"]
        self.assertRegex(basis, r"^formal: residual variance \(\d revolutions, the spread needs 8\)$")
        self.assertIn(f"parameters (value +- standard error, {basis}):", run([self.model, "explain", short]).stdout)

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
