#!/usr/bin/env python3
"""resolver-model report --html, rendered: headless Chromium screenshots the page
of a log with quadrature hidden next to amplitude imbalance, and the PNG must have
the window's size (1200 x 3000), not be blank, and show the plots (pixels in the
step colours: red for the starting model, blue for the final one; the bars of the
harmonic spectrum alone are thousands of pixels of each).

Skips (exit 77) only when chromium is not installed (Debian package chromium;
tools/install-deps.sh installs it); RESOLVER_REQUIRE_CHROMIUM=1 turns that skip
into a failure. Any other problem (chromium fails, no PNG) fails.
The PNG is decoded with zlib (standard library), no PIL.

  test_report_screenshot.py --bin BUILD/bin --work DIR [--chromium PATH]
"""
import argparse
import os
import shutil
import struct
import subprocess
import sys
import zlib

WIDTH, HEIGHT = 1200, 3000
# The page's step colours (tools/model/html_report.cpp step_color): start and final model.
RED, BLUE = (0xC0, 0x39, 0x2B), (0x1F, 0x5F, 0xA8)
COLOUR_TOLERANCE = 40       # per channel: anti-aliasing and the dots' opacity shift colours a little
MIN_COLOUR_PIXELS = 5000    # the 2θ and constant bars of each step alone are ~60 x 150 px
MIN_INK = 0.04              # non-white share of the page and of its lower half (the plots)


def fail(msg):
    sys.exit(f"FAIL: {msg}")


def run(cmd, timeout=120):
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        fail(f"{' '.join(cmd)} did not finish in {timeout} s")
    if p.returncode != 0:
        fail(f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout}\n{p.stderr[-3000:]}")
    return p


def read_png(path):
    """(width, height, rows of RGB(A) bytes, bytes per pixel) of an 8-bit, non-interlaced RGB or RGBA PNG."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{path} is not a PNG")
    pos, idat, hdr = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    w, h, depth, ctype, _, _, interlace = hdr
    if depth != 8 or ctype not in (2, 6) or interlace:
        fail(f"{path}: unsupported PNG (bit depth {depth}, colour type {ctype}, interlace {interlace})")
    bpp = 3 if ctype == 2 else 4
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(h):
        ftype, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        if ftype == 1:
            for x in range(bpp, stride):
                line[x] = (line[x] + line[x - bpp]) & 255
        elif ftype == 2:
            for x in range(stride):
                line[x] = (line[x] + prev[x]) & 255
        elif ftype == 3:
            for x in range(stride):
                line[x] = (line[x] + ((line[x - bpp] if x >= bpp else 0) + prev[x]) // 2) & 255
        elif ftype == 4:
            for x in range(stride):
                a = line[x - bpp] if x >= bpp else 0
                b, c = prev[x], (prev[x - bpp] if x >= bpp else 0)
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return w, h, rows, bpp


def near(px, colour):
    return all(abs(a - b) <= COLOUR_TOLERANCE for a, b in zip(px, colour))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    a = ap.parse_args()
    if not (os.path.isfile(a.chromium) and os.access(a.chromium, os.X_OK)):
        msg = f"chromium not found ({a.chromium}): apt-get install chromium (tools/install-deps.sh does)"
        if os.environ.get("RESOLVER_REQUIRE_CHROMIUM") == "1":
            fail(msg + "; RESOLVER_REQUIRE_CHROMIUM=1 says it must be there")
        print(f"SKIP: {msg}")
        return 77

    os.makedirs(a.work, exist_ok=True)
    log, html, png = (os.path.join(a.work, "hidden_quadrature" + ext) for ext in (".log", ".html", ".png"))
    for f in (html, png):
        if os.path.exists(f):
            os.remove(f)
    run([os.path.join(a.bin, "resolver-sim"), "-o", log, "-e", "amplitude_imbalance:alpha=0.003",
         "-e", "quadrature:beta=0.002", "--seed", "5"])
    run([os.path.join(a.bin, "resolver-model"), "report", log, "--html", html])
    # Own profile directory: parallel runs (ctest -j) and the user's profile stay apart.
    run([a.chromium, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         f"--user-data-dir={os.path.join(a.work, 'chromium-profile')}", f"--screenshot={png}",
         f"--window-size={WIDTH},{HEIGHT}", "file://" + os.path.abspath(html)])
    if not os.path.isfile(png):
        fail(f"chromium wrote no screenshot {png}")

    w, h, rows, bpp = read_png(png)
    if (w, h) != (WIDTH, HEIGHT):
        fail(f"{png} is {w} x {h}, expected {WIDTH} x {HEIGHT}")
    ink = [0] * h
    red = blue = 0
    for y, row in enumerate(rows):
        for x in range(0, len(row), bpp):
            px = row[x:x + 3]
            if min(px) < 235:
                ink[y] += 1
                if near(px, RED):
                    red += 1
                elif near(px, BLUE):
                    blue += 1
    page_ink = sum(ink) / (w * h)
    lower_ink = sum(ink[h // 2:]) / (w * (h - h // 2))
    print(f"{png}: {w} x {h}, non-white {page_ink:.1%} (lower half {lower_ink:.1%}), "
          f"start-model red {red} px, final-model blue {blue} px")
    if page_ink < MIN_INK or lower_ink < MIN_INK:
        fail(f"the screenshot looks blank: non-white {page_ink:.1%} of the page, {lower_ink:.1%} of its lower half "
             f"(need {MIN_INK:.0%})")
    if red < MIN_COLOUR_PIXELS or blue < MIN_COLOUR_PIXELS:
        fail(f"the plots did not render: {red} red and {blue} blue pixels (need {MIN_COLOUR_PIXELS} of each)")
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
