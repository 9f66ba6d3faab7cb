#!/usr/bin/env python3
"""resolver-model report, in headless Chromium (driven over the DevTools protocol
through a pipe: chromium_cdp.py). resolver-sim hides quadrature next to amplitude
imbalance (alpha = 0.003, beta = 0.002 rad, with phase currents and the reference
encoder); the page of `resolver-model report` must:

  Screenshot   render: a full-page screenshot that is not blank and shows the step
               colours (red: the starting model, blue: the final one), and every angle
               plot drawn continuously: shown alone, each solid line reaches at least
               90 % of the plot's pixel columns, and each band has its dot drawn in at
               least 90 % of the angle bins.
  AngleBins    carry data that covers the angle: in every angle plot at least 90 % of
               the 2 deg bins hold samples, a bin's mean is there exactly where its
               count is not zero, and the individual samples (discovery's series, the
               overlay) fall in 90 % of the bins too.
  Interaction  zoom and pan: a drag across the plot zooms to the dragged range and the
               plots of the same angle follow, the mouse wheel zooms about the pointer,
               shift-drag pans, a double-click and the reset button restore 0-360 deg, a
               legend click shows the samples, and the CSV button downloads the plot's
               data (read back with the csv module and compared with the page's data).

Controls: a log that turns through half an electrical revolution only must fail the
90 % checks of Screenshot and AngleBins (the checks can fail).

Skips (exit 77) only when chromium is not installed (Debian package chromium;
tools/install-deps.sh installs it); RESOLVER_REQUIRE_CHROMIUM=1 turns that skip into
a failure.

  test_report_browser.py --bin BUILD/bin --work DIR [Screenshot|AngleBins|Interaction]
"""
import argparse
import base64
import csv
import json
import os
import subprocess
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from chromium_cdp import Chromium, find_chromium  # noqa: E402
from png_image import png_size, read_png  # noqa: E402

ARGS = None
PAGES = {}  # name -> html path
# Step colours of the page (tools/model/discovery_run.cpp step_color): start and final model.
RED, BLUE = (0xC0, 0x39, 0x2B), (0x1F, 0x5F, 0xA8)
COLOUR_TOLERANCE = 48      # per channel: anti-aliasing blends a 2 px line's edge into the white
MIN_COVERED = 0.90         # the "90 % of the angle bins", in bins and in pixel columns
MIN_STEP_PIXELS = 3000     # pixels of each step colour in the page (its lines, dots and swatches)


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


def make_pages():
    os.makedirs(ARGS.work, exist_ok=True)
    sim, model = os.path.join(ARGS.bin, "resolver-sim"), os.path.join(ARGS.bin, "resolver-model")
    log = os.path.join(ARGS.work, "hidden_quadrature.log")
    run([sim, "-o", log, "-e", "amplitude_imbalance:alpha=0.003", "-e", "quadrature:beta=0.002", "--seed", "5"])
    PAGES["full"] = os.path.join(ARGS.work, "hidden_quadrature.html")
    run([model, "report", log, "--html", PAGES["full"]])
    # Control: 5 r/min for 2 s with p_r = 3 is half an electrical turn (0-180 deg of theta).
    part = os.path.join(ARGS.work, "half_turn.log")
    run([sim, "-o", part, "--rpm", "5", "--duration", "2", "-e", "amplitude_imbalance:alpha=0.003"])
    PAGES["half_turn"] = os.path.join(ARGS.work, "half_turn.html")
    # (resolver-sim's reference zero is on the d axis: --reference-aligned makes mounting_offset fittable)
    run([model, "report", part, "--effects", "mounting_offset", "--reference-aligned", "--html", PAGES["half_turn"]])
    # Without the reference encoder: no dq plots, the self-calibrated angle.
    noref = os.path.join(ARGS.work, "no_reference.log")
    run([sim, "-o", noref, "--no-reference", "-e", "amplitude_imbalance:alpha=0.003", "--duration", "3"])
    PAGES["no_reference"] = os.path.join(ARGS.work, "no_reference.html")
    run([model, "report", noref, "--html", PAGES["no_reference"]])


def hex_colour(c):
    return tuple(int(c[i:i + 2], 16) for i in (1, 3, 5))


def near(px, colour):
    return all(abs(a - b) <= COLOUR_TOLERANCE for a, b in zip(px, colour))


def angle_plots(browser):
    return [p for p in browser.evaluate("resolverReport.plots") if p["angle_bins"] > 0]


def rect_of(browser, expression, scroll=True):
    """[left, top, width, height] of the element, in viewport CSS px (scrolled into view first)."""
    return browser.evaluate(f"""(() => {{ const e = {expression};
        {'e.scrollIntoView({block: "center"});' if scroll else ''}
        const r = e.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; }})()""")


def drawn_share(browser, plot_id, series_index, colour):
    """How much of a series is on screen, shown alone: for a line, the share of the plot area's
    pixel columns that hold its colour; for a band's dots, the share of the plot's angle bins
    whose dot is there (a column within 1 px of the bin's x holds the colour)."""
    spec = browser.evaluate(f"resolverReport.plots.find(p => p.id === '{plot_id}')")
    was = [browser.evaluate(f"resolverReport.shown('{plot_id}', {k})") for k in range(len(spec["series"]))]
    for k in range(len(spec["series"])):
        browser.evaluate(f"resolverReport.setShown('{plot_id}', {k}, {'true' if k == series_index else 'false'})")
    left, top, width, height = rect_of(browser, f"resolverReport.chart('{plot_id}').over", scroll=False)
    # Two animation frames are not always enough on a loaded machine (CI with ctest -j2:
    # once a series read 9 % drawn, 50 % alone): capture until two captures agree.
    inked, img = None, None
    for _ in range(6):
        browser.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        png = browser.call("Page.captureScreenshot", {
            "format": "png", "captureBeyondViewport": True,
            "clip": {"x": left, "y": top, "width": width, "height": height, "scale": 1}})["data"]
        img = read_png(base64.b64decode(png))
        now = [any(near(img.pixel(x, y), colour) for y in range(img.height)) for x in range(img.width)]
        if now == inked:
            break
        inked = now
    series = spec["series"][series_index]
    if series["mark"] == "band":
        xs = browser.evaluate(f"resolverReport.plots.find(p => p.id === '{plot_id}').series[{series_index}].x"
                              f".map(x => resolverReport.chart('{plot_id}').valToPos(x, 'x'))")
        hit = [any(inked[c] for c in range(max(0, round(x) - 1), min(img.width, round(x) + 2))) for x in xs]
        share = sum(hit) / spec["angle_bins"]
    else:
        share = sum(inked) / img.width
    for k, on in enumerate(was):
        browser.evaluate(f"resolverReport.setShown('{plot_id}', {k}, {'true' if on else 'false'})")
    return share


def continuity(page):
    """{(plot, series label): covered share} of every solid line and band of every angle plot."""
    out = {}
    with Chromium(ARGS.work, width=1200, height=900) as b:
        b.open("file://" + page)
        height = int(b.evaluate("document.documentElement.scrollHeight"))
        b.call("Emulation.setDeviceMetricsOverride", {"width": 1200, "height": height, "deviceScaleFactor": 1,
                                                       "mobile": False})
        b.evaluate("window.scrollTo(0, 0)")
        for p in angle_plots(b):
            for k, s in enumerate(p["series"]):
                if s["mark"] in ("line", "band") and not s["dashed"]:
                    out[(p["id"], s["label"])] = drawn_share(b, p["id"], k, hex_colour(s["color"]))
    return out


class Screenshot(unittest.TestCase):
    def test_pages_run_without_script_errors(self):
        for name, page in PAGES.items():
            with Chromium(ARGS.work) as b:
                b.open("file://" + page)
                plots = b.evaluate("resolverReport.plots.map(p => p.id)")
                drawn = b.evaluate("resolverReport.plots.filter(p => resolverReport.chart(p.id)).length")
                errors = [e["params"] for e in b.events if e["method"] == "Runtime.exceptionThrown" or (
                    e["method"] == "Runtime.consoleAPICalled" and e["params"].get("type") in ("error", "assert"))]
            self.assertEqual(errors, [], name)
            self.assertEqual(drawn, len(plots), f"{name}: every plot has its chart")
            # A one-speed log draws no residual-vs-speed plot (one dot; the page says so instead).
            self.assertGreaterEqual(len(plots), 4, name)

    def test_page_renders_with_the_step_colours(self):
        with Chromium(ARGS.work, width=1200, height=900) as b:
            b.open("file://" + PAGES["full"])
            png = b.screenshot(full_page=True)
            with open(os.path.join(ARGS.work, "hidden_quadrature.png"), "wb") as f:
                f.write(png)  # for a person to look at
            # Decoding 1200 x ~9000 px in pure Python is slow: check a quarter-scale copy.
            small = read_png(base64.b64decode(b.call("Page.captureScreenshot", {
                "format": "png", "captureBeyondViewport": True,
                "clip": {"x": 0, "y": 0, "width": 1200, "height": b.evaluate("document.documentElement.scrollHeight"),
                         "scale": 0.25}})["data"]))
        width, height = png_size(png)
        self.assertEqual(width, 1200)
        self.assertGreater(height, 3000, "the page is shorter than its tables and plots")
        ink = red = blue = 0
        for y in range(small.height):
            for x in range(small.width):
                px = small.pixel(x, y)
                if min(px) < 235:
                    ink += 1
                red += near(px, RED)
                blue += near(px, BLUE)
        share = ink / (small.width * small.height)
        print(f"screenshot {width} x {height}: non-white {share:.1%}, red {red * 16} px, blue {blue * 16} px")
        self.assertGreater(share, 0.04, "the page looks blank")
        self.assertGreater(red * 16, MIN_STEP_PIXELS, "the starting model's colour is missing: plots not drawn?")
        self.assertGreater(blue * 16, MIN_STEP_PIXELS, "the final model's colour is missing: plots not drawn?")

    def test_every_angle_plot_is_continuous(self):
        cov = continuity(PAGES["full"])
        for key, share in sorted(cov.items()):
            print(f"  {key[0]:6} {share:6.1%}  {key[1]}")
        self.assertGreaterEqual(len({k[0] for k in cov}), 6, "angle plots missing (pe, res1, res2, dqd, dqq, dqerr)")
        self.assertEqual({k: v for k, v in cov.items() if v < MIN_COVERED}, {})

    def test_control_half_a_turn_is_not_continuous(self):
        cov = continuity(PAGES["half_turn"])
        self.assertTrue(cov)
        # Half a turn: the lines reach about half the columns.
        self.assertEqual({k: v for k, v in cov.items() if not 0.3 < v < 0.7}, {})


def bin_shares(page):
    """{plot: (filled share by the page's counts, share of the samples overlay)} and the problems found."""
    with Chromium(ARGS.work) as b:
        b.open("file://" + page)
        plots = angle_plots(b)
    shares, problems = {}, []
    for p in plots:
        nbins = p["angle_bins"]
        counted = [s for s in p["series"] if s["mark"] == "band" or s.get("count")]
        lines = [s for s in p["series"] if s["mark"] in ("line", "band") and len(s["x"]) == nbins]
        if not lines:
            problems.append(f"{p['id']}: no binned series")
            continue
        for s in lines:
            if s.get("count"):
                for i, (y, n) in enumerate(zip(s["y"], s["count"])):
                    if (y is None) != (n == 0):
                        problems.append(f"{p['id']} {s['label']}: bin {i} has {n} samples and mean {y}")
        filled = sum(1 for y in lines[0]["y"] if y is not None)
        if counted:
            filled_by_count = sum(1 for n in counted[0]["count"] if n > 0)
            if filled_by_count != p["filled_bins"]:
                problems.append(f"{p['id']}: filled_bins {p['filled_bins']} but {filled_by_count} bins counted")
        samples = [s for s in p["series"] if s["mark"] == "points"]
        overlay = len({int(x / (360.0 / nbins)) % nbins for x in samples[0]["x"]}) / nbins if samples else None
        shares[p["id"]] = (filled / nbins, overlay)
    return shares, problems


class AngleBins(unittest.TestCase):
    def test_ninety_percent_of_the_angle_bins_hold_data(self):
        shares, problems = bin_shares(PAGES["full"])
        for pid, (filled, overlay) in shares.items():
            print(f"  {pid:6} bins filled {filled:6.1%}, samples overlay {overlay if overlay is None else f'{overlay:.1%}'}")
        self.assertEqual(problems, [])
        self.assertGreaterEqual(set(shares), {"pe", "res1", "res2", "dqd", "dqq", "dqerr"})
        for pid, (filled, overlay) in shares.items():
            self.assertGreaterEqual(filled, MIN_COVERED, pid)
            if overlay is not None:
                self.assertGreaterEqual(overlay, MIN_COVERED, f"{pid}: the individual samples (ModelFit::series)")

    def test_control_half_a_turn_fills_half_the_bins(self):
        shares, problems = bin_shares(PAGES["half_turn"])
        self.assertEqual(problems, [])
        self.assertTrue(shares)
        for pid, (filled, _) in shares.items():
            self.assertLess(filled, MIN_COVERED, pid)
            self.assertAlmostEqual(filled, 0.5, delta=0.05, msg=pid)


class Interaction(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.b = Chromium(ARGS.work, width=1200, height=900).__enter__()
        cls.b.open("file://" + PAGES["full"])

    @classmethod
    def tearDownClass(cls):
        cls.b.__exit__(None, None, None)

    def xrange(self, pid):
        return self.b.evaluate(f"resolverReport.xRange('{pid}')")

    def assertRange(self, got, lo, hi, tol, what):
        self.assertAlmostEqual(got[0], lo, delta=tol, msg=f"{what}: {got}")
        self.assertAlmostEqual(got[1], hi, delta=tol, msg=f"{what}: {got}")

    def test_1_drag_zooms_and_the_angle_plots_follow(self):
        left, top, width, height = rect_of(self.b, "resolverReport.chart('pe').over")
        deg_per_px = 360.0 / width
        self.b.drag(left + 0.25 * width, top + 0.5 * height, left + 0.5 * width, top + 0.5 * height)
        self.assertRange(self.xrange("pe"), 90, 180, 2 * deg_per_px, "after dragging over 25-50 % of the plot")
        for pid in ("res1", "res2", "dqerr"):
            self.assertEqual(self.xrange(pid), self.xrange("pe"), f"{pid} follows pe's zoom")
        self.assertEqual(self.xrange("dqd"), [0, 360], "θ_e plots are another group")

    def test_2_wheel_zooms_about_the_pointer(self):
        self.b.evaluate("resolverReport.setX('pe', 90, 180)")
        left, top, width, height = rect_of(self.b, "resolverReport.chart('pe').over")
        self.b.wheel(left + 0.5 * width, top + 0.5 * height, -100)  # wheel up: in
        # The page zooms by 0.75 about the pointer (135 deg).
        self.assertRange(self.xrange("pe"), 135 - 45 * 0.75, 135 + 45 * 0.75, 0.5, "after one wheel step in")

    def test_3_shift_drag_pans(self):
        self.b.evaluate("resolverReport.setX('pe', 90, 180)")
        left, top, width, height = rect_of(self.b, "resolverReport.chart('pe').over")
        shift = 8  # CDP modifier bit for Shift
        self.b.drag(left + 0.6 * width, top + 0.5 * height, left + 0.4 * width, top + 0.5 * height, modifiers=shift)
        # Dragging the data 20 % of the width to the left shows 20 % of the range (18 deg) further right.
        self.assertRange(self.xrange("pe"), 108, 198, 1.0, "after shift-dragging 20 % to the left")

    def test_4_double_click_and_button_reset(self):
        self.b.evaluate("resolverReport.setX('pe', 100, 120)")
        left, top, width, height = rect_of(self.b, "resolverReport.chart('pe').over")
        self.b.click(left + 0.5 * width, top + 0.5 * height, count=2)
        self.assertEqual(self.xrange("pe"), [0, 360])
        self.b.evaluate("resolverReport.setX('pe', 100, 120)")
        bl, bt, bw, bh = rect_of(self.b, "document.querySelector('[data-reset=\"pe\"]')")
        self.b.click(bl + bw / 2, bt + bh / 2)
        self.assertEqual(self.xrange("pe"), [0, 360])

    def test_5_legend_shows_the_samples(self):
        spec = self.b.evaluate("resolverReport.plots.find(p => p.id === 'pe')")
        k = next(i for i, s in enumerate(spec["series"]) if s["mark"] == "points")
        self.assertFalse(self.b.evaluate(f"resolverReport.shown('pe', {k})"), "samples start hidden")
        left, top, width, height = rect_of(self.b, f"document.querySelector('[data-legend=\"pe\"] [data-series=\"{k}\"]')")
        self.b.click(left + width / 2, top + height / 2)
        self.assertTrue(self.b.evaluate(f"resolverReport.shown('pe', {k})"), "a legend click shows them")

    def test_6_csv_button_downloads_the_plots_data(self):
        downloads = os.path.join(ARGS.work, "downloads")
        os.makedirs(downloads, exist_ok=True)
        target = os.path.join(downloads, "hidden_quadrature-pe.csv")
        if os.path.exists(target):
            os.remove(target)
        self.b.call("Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": downloads,
                                                    "eventsEnabled": True}, session=None)
        left, top, width, height = rect_of(self.b, "document.querySelector('[data-csv=\"pe\"]')")
        self.b.click(left + width / 2, top + height / 2)
        begun = self.b.wait_event("Browser.downloadWillBegin")
        self.assertEqual(begun["suggestedFilename"], "hidden_quadrature-pe.csv")
        self.b.wait_event("Browser.downloadProgress", lambda p: p.get("state") == "completed")
        with open(target, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows[0], ["series", "theta_deg", "eps_arcmin", "eps_arcmin_sd", "samples"])
        spec = self.b.evaluate("resolverReport.plots.find(p => p.id === 'pe')")
        expected = [(s["label"], x, y) for s in spec["series"] for x, y in zip(s["x"], s["y"])]
        self.assertEqual(len(rows) - 1, len(expected))
        for row, (label, x, y) in zip(rows[1:], expected):
            self.assertEqual(row[0], label)
            self.assertEqual(float(row[1]), x)
            if y is None:
                self.assertEqual(row[2], "NaN")
            else:
                self.assertEqual(float(row[2]), y)


def main():
    global ARGS
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    chromium = find_chromium()
    if not (os.path.isfile(chromium) and os.access(chromium, os.X_OK)):
        msg = f"chromium not found ({chromium}): apt-get install chromium (tools/install-deps.sh does)"
        if os.environ.get("RESOLVER_REQUIRE_CHROMIUM") == "1":
            sys.exit(f"FAIL: {msg}; RESOLVER_REQUIRE_CHROMIUM=1 says it must be there")
        print(f"SKIP: {msg}")
        sys.exit(77)
    make_pages()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
