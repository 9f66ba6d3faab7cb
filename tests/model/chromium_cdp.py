"""Headless Chromium driven over the DevTools protocol through a pipe, Python standard
library only (no websocket client, no playwright: its browser download is not
possible here, and the pipe needs no port).

Chromium started with --remote-debugging-pipe reads protocol messages from fd 3 and
writes to fd 4, each a JSON object ended by a NUL byte. One page is opened and
attached in flat mode; `call` sends a command to it and returns the result,
keeping the events seen meanwhile for `wait_event`.

    with Chromium(work_dir) as b:
        b.open("file:///.../page.html")
        b.evaluate("document.title")
        png = b.screenshot()

Errors raise CdpError with the method and the protocol's message; a browser that
does not answer within the timeout raises too (no test hangs).
"""
import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import time

CHROMIUM_FLAGS = [
    # As root in a container: no sandbox. The rest keep Chromium off the network
    # (this machine refuses outside connections) and its first-run chores off.
    "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-default-apps", "--mute-audio", "--remote-debugging-pipe",
]


class CdpError(RuntimeError):
    pass


def find_chromium():
    return shutil.which("chromium") or "/usr/bin/chromium"


class Chromium:
    def __init__(self, work_dir, chromium=None, width=1200, height=900, timeout=60.0):
        self.work_dir = work_dir
        self.chromium = chromium or find_chromium()
        self.width, self.height, self.timeout = width, height, timeout
        self.proc = None
        self.session = None
        self.events = []
        self._buf = b""
        self._next_id = 0

    # -- process and pipe ------------------------------------------------------------------
    def __enter__(self):
        to_browser_r, to_browser_w = os.pipe()
        from_browser_r, from_browser_w = os.pipe()

        def child_fds():
            # Move the pipe ends out of the way first, then onto 3 and 4 (they may be 3 or 4 already).
            a = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        profile = os.path.join(self.work_dir, "chromium-profile")
        shutil.rmtree(profile, ignore_errors=True)
        self.stderr = open(os.path.join(self.work_dir, "chromium.stderr"), "wb")
        self.proc = subprocess.Popen(
            [self.chromium, *CHROMIUM_FLAGS, f"--user-data-dir={profile}",
             f"--window-size={self.width},{self.height}", "about:blank"],
            pass_fds=(3, 4), preexec_fn=child_fds, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
            stderr=self.stderr)
        os.close(to_browser_r)
        os.close(from_browser_w)
        self._out, self._in = to_browser_w, from_browser_r
        return self

    def __exit__(self, *exc):
        try:
            if self.proc and self.proc.poll() is None:
                try:
                    self._send("Browser.close", {}, None)
                    self.proc.wait(timeout=10)
                except Exception:  # noqa: BLE001 -- closing politely failed: end it
                    self.proc.kill()
                    self.proc.wait(timeout=10)
        finally:
            for fd in (self._out, self._in):
                try:
                    os.close(fd)
                except OSError:
                    pass
            self.stderr.close()
        return False

    def _send(self, method, params, session):
        self._next_id += 1
        msg = {"id": self._next_id, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        data = json.dumps(msg).encode() + b"\0"
        while data:
            data = data[os.write(self._out, data):]
        return self._next_id

    def _read_message(self, deadline):
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise CdpError(f"Chromium did not answer in {self.timeout:.0f} s")
            ready, _, _ = select.select([self._in], [], [], left)
            if not ready:
                continue
            chunk = os.read(self._in, 1 << 20)
            if not chunk:
                raise CdpError(f"Chromium closed the pipe (exit code {self.proc.poll()})")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method, params=None, session="page"):
        """Sends a command (to the page's session unless session=None) and returns its result."""
        sid = self.session if session == "page" else session
        mid = self._send(method, params or {}, sid)
        deadline = time.monotonic() + self.timeout
        while True:
            msg = self._read_message(deadline)
            if msg.get("id") == mid:
                if "error" in msg:
                    raise CdpError(f"{method}: {msg['error'].get('message')} {msg['error'].get('data', '')}")
                return msg.get("result", {})
            if "method" in msg:
                self.events.append(msg)

    def wait_event(self, method, predicate=lambda params: True, timeout=None):
        """The first event `method` (seen already or arriving) whose params satisfy predicate."""
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            for i, ev in enumerate(self.events):
                if ev["method"] == method and predicate(ev.get("params", {})):
                    return self.events.pop(i).get("params", {})
            msg = self._read_message(deadline)
            if "method" in msg:
                self.events.append(msg)

    # -- page ------------------------------------------------------------------------------
    def open(self, url, ready_expression="window.resolverReport && window.resolverReport.ready"):
        """Opens url in a new page and waits for the load event and for ready_expression to be true."""
        target = self.call("Target.createTarget", {"url": "about:blank"}, session=None)["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True},
                                 session=None)["sessionId"]
        self.call("Page.enable")
        self.call("Runtime.enable")
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": self.width, "height": self.height, "deviceScaleFactor": 1, "mobile": False})
        self.call("Page.navigate", {"url": url})
        self.wait_event("Page.loadEventFired")
        if ready_expression:
            self.wait_for(ready_expression)

    def evaluate(self, expression):
        """The value of a JavaScript expression in the page (JSON-serializable), or CdpError on an exception."""
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True})
        if "exceptionDetails" in r:
            d = r["exceptionDetails"]
            raise CdpError(f"{expression[:80]}: {d.get('exception', {}).get('description') or d.get('text')}")
        return r["result"].get("value")

    def wait_for(self, expression, timeout=None):
        deadline = time.monotonic() + (timeout or self.timeout)
        while not self.evaluate(f"!!({expression})"):
            if time.monotonic() > deadline:
                raise CdpError(f"page: {expression} is still false after {timeout or self.timeout:.0f} s")
            time.sleep(0.05)

    def screenshot(self, full_page=True):
        """PNG bytes of the page (the whole page: the viewport is grown to its height)."""
        params = {"format": "png"}
        if full_page:
            height = int(self.evaluate("Math.ceil(document.documentElement.scrollHeight)"))
            self.call("Emulation.setDeviceMetricsOverride",
                      {"width": self.width, "height": height, "deviceScaleFactor": 1, "mobile": False})
            self.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        data = self.call("Page.captureScreenshot", params)["data"]
        return base64.b64decode(data)

    # -- input -----------------------------------------------------------------------------
    def mouse(self, kind, x, y, button="left", buttons=0, modifiers=0, click_count=0, delta_y=0):
        self.call("Input.dispatchMouseEvent", {
            "type": kind, "x": x, "y": y, "button": button, "buttons": buttons, "modifiers": modifiers,
            "clickCount": click_count, "deltaX": 0, "deltaY": delta_y})

    def drag(self, x0, y0, x1, y1, modifiers=0, steps=8):
        self.mouse("mouseMoved", x0, y0, button="none", modifiers=modifiers)
        self.mouse("mousePressed", x0, y0, buttons=1, modifiers=modifiers, click_count=1)
        for k in range(1, steps + 1):
            self.mouse("mouseMoved", x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps, buttons=1,
                       modifiers=modifiers)
        self.mouse("mouseReleased", x1, y1, modifiers=modifiers, click_count=1)

    def click(self, x, y, count=1):
        self.mouse("mouseMoved", x, y, button="none")
        for k in range(1, count + 1):
            self.mouse("mousePressed", x, y, buttons=1, click_count=k)
            self.mouse("mouseReleased", x, y, click_count=k)

    def wheel(self, x, y, delta_y):
        self.mouse("mouseMoved", x, y, button="none")
        self.mouse("mouseWheel", x, y, button="none", delta_y=delta_y)
