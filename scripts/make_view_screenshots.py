"""Screenshots of ``cspace view`` pages taken by a real browser (headless Chromium), and the
small browser driver the tests use too.

    python scripts/make_view_screenshots.py            # docs/figures/view_bar_door.png

:class:`Browser` talks Chrome's DevTools protocol over a pipe (``--remote-debugging-pipe``:
JSON messages separated by NUL bytes on file descriptors 3 and 4), so no websocket library
and no network port is needed. The network is switched off (``Network.emulateNetworkConditions``
offline) and every request the page makes is recorded, so a caller can check that nothing but
the file itself was loaded. Clicks and drags are real mouse events (``Input.dispatchMouseEvent``).
"""
from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--no-default-browser-check",
         "--disable-extensions", "--mute-audio", "--remote-debugging-pipe"]


def chromium() -> str | None:
    """The Chromium executable on PATH (``chromium``, else ``chromium-browser``), or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class Browser:
    """One headless Chromium with one page, driven over the DevTools pipe. Use as a context manager.

    >>> # with Browser() as b: b.open("file:///tmp/v.html"); png = b.screenshot()
    """

    def __init__(self, width: int = 1200, height: int = 1000, exe: str | None = None, timeout: float = 30.0):
        exe = exe or chromium()
        if exe is None:
            raise RuntimeError("chromium is not installed")
        self.timeout = timeout
        self.profile = tempfile.mkdtemp(prefix="cspace-chromium-")
        cmd_r, self._cmd_w = os.pipe()  # our commands: the browser reads them on fd 3
        self._out_r, out_w = os.pipe()  # its answers and events: written on fd 4

        def pipes_on_3_and_4():  # in the child: the pipe ends on the fds Chromium reads and writes
            a, b = os.dup(cmd_r), os.dup(out_w)  # above 4, wherever the originals are
            os.dup2(a, 3)  # dup2 makes them inheritable; every other fd of ours closes on exec
            os.dup2(b, 4)

        self.proc = subprocess.Popen([exe, *FLAGS, f"--user-data-dir={self.profile}", f"--window-size={width},{height}",
                                      "about:blank"], preexec_fn=pipes_on_3_and_4, close_fds=False,
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(cmd_r)
        os.close(out_w)
        self._buf = b""
        self._next = 0
        self.events: list[dict] = []
        self.requests: list[str] = []
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for method, params in (("Page.enable", {}), ("Runtime.enable", {}), ("Network.enable", {}),
                               ("Network.emulateNetworkConditions", {"offline": True, "latency": 0,
                                                                     "downloadThroughput": -1,
                                                                     "uploadThroughput": -1}),
                               ("Emulation.setDeviceMetricsOverride", {"width": width, "height": height,
                                                                       "deviceScaleFactor": 1, "mobile": False})):
            self.call(method, params, session=True)

    # -- the protocol ----------------------------------------------------------------

    def _send(self, msg: dict) -> None:
        data = json.dumps(msg).encode() + b"\0"
        while data:
            data = data[os.write(self._cmd_w, data):]

    def _read(self, deadline: float) -> dict:
        while b"\0" not in self._buf:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._out_r], [], [], left)[0]:
                raise TimeoutError("chromium did not answer in time")
            chunk = os.read(self._out_r, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed the DevTools pipe")
            self._buf += chunk
        raw, self._buf = self._buf.split(b"\0", 1)
        msg = json.loads(raw)
        if msg.get("method") == "Network.requestWillBeSent":
            self.requests.append(msg["params"]["request"]["url"])
        elif "method" in msg:
            self.events.append(msg)
        return msg

    def call(self, method: str, params: dict | None = None, session: bool = False) -> dict:
        """Send one command and return its result (an error answer raises RuntimeError)."""
        self._next += 1
        msg = {"id": self._next, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = self.session
        self._send(msg)
        deadline = time.monotonic() + self.timeout
        while True:
            ans = self._read(deadline)
            if ans.get("id") == self._next:
                if "error" in ans:
                    raise RuntimeError(f"{method}: {ans['error']}")
                return ans.get("result", {})

    def pump(self, seconds: float) -> None:
        """Let ``seconds`` of real time pass, reading events meanwhile."""
        deadline = time.monotonic() + seconds
        try:
            while True:
                self._read(deadline)
        except TimeoutError:
            pass

    # -- what a test does --------------------------------------------------------------

    def eval(self, expression: str):
        """The value of a JavaScript expression in the page (promises awaited)."""
        res = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                        session=True)
        if "exceptionDetails" in res:
            raise RuntimeError(f"{expression}: {res['exceptionDetails'].get('text')}")
        return res["result"].get("value")

    def open(self, url: str, wait: float | None = None) -> float:
        """Load ``url`` and wait until the page's title is ``ok`` (or ``error``); the seconds it took."""
        t0 = time.monotonic()
        self.call("Page.navigate", {"url": url}, session=True)
        deadline = t0 + (wait or self.timeout)
        while time.monotonic() < deadline:
            if self.eval("document.title") in ("ok", "error"):
                return time.monotonic() - t0
            self.pump(0.02)
        raise TimeoutError(f"{url}: the page did not finish drawing (title {self.eval('document.title')!r})")

    def screenshot(self, out: str | None = None) -> bytes:
        """A PNG of the viewport (also written to ``out`` if given)."""
        png = base64.b64decode(self.call("Page.captureScreenshot", {"format": "png"}, session=True)["data"])
        if out:
            from planners.output import atomic_path

            with atomic_path(out, "screenshot") as tmp:  # never half a picture
                with open(tmp, "wb") as fh:
                    fh.write(png)
        return png

    def click(self, x: float, y: float) -> None:
        """A left click at (x, y) CSS pixels of the viewport."""
        self.press(x, y)
        self.release(x, y)

    def press(self, x: float, y: float) -> None:
        self.call("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x, "y": y}, session=True)
        self.call("Input.dispatchMouseEvent", {"type": "mousePressed", "x": x, "y": y, "button": "left",
                                               "clickCount": 1}, session=True)

    def release(self, x: float, y: float) -> None:
        self.call("Input.dispatchMouseEvent", {"type": "mouseReleased", "x": x, "y": y, "button": "left",
                                               "clickCount": 1}, session=True)

    def box(self, selector: str, index: int = 0) -> dict:
        """The viewport box (left, top, width, height) of the index-th element matching ``selector``."""
        return self.eval(f"(() => {{ const r = document.querySelectorAll({json.dumps(selector)})[{index}]"
                         ".getBoundingClientRect(); return {left: r.left, top: r.top, width: r.width, "
                         "height: r.height}; })()")

    def state(self) -> dict:
        """The page's ``#state``: the current frame and each slider's step."""
        self.pump(0.15)  # the page refreshes it every 100 ms
        return json.loads(self.eval("document.getElementById('state').textContent") or "{}")

    def close(self) -> None:
        try:
            self.call("Browser.close")
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        for fd in (self._cmd_w, self._out_r):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def slider_point(b: Browser, index: int, fraction: float) -> tuple[float, float]:
    """Where on the index-th slider's rail (in page order) a fraction of its length lies."""
    r = b.box(".slider-container .slider-rail-touch-rect", index)
    return r["left"] + fraction * r["width"], r["top"] + r["height"] / 2


def bar_door_screenshot(out: str = os.path.join(ROOT, "docs", "figures", "view_bar_door.png")) -> str:
    """Plan scenarios/se2/bar_door.toml, write its page, and save the browser's screenshot of it
    with the bar half way through the door and the angle slider at 0 degrees. ``out`` is checked
    before any work (never the scenario, a folder or an unwritable place: one line, exit 2) and
    written atomically."""
    sys.path.insert(0, ROOT)
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import planners
    from benchutil import check_out
    from planners.output import PLOT_FORMATS
    from planners.pictures.view import write_view

    scene = os.path.join(ROOT, "scenarios", "se2", "bar_door.toml")
    check_out(out, [scene], "out", {".png": PLOT_FORMATS[".png"]})
    with tempfile.TemporaryDirectory() as tmp:
        page = os.path.join(tmp, "view.html")
        write_view(planners.plan(scene), page)
        with Browser(width=1200, height=900) as b:
            b.open("file://" + page + "#pose=55&angle=16")
            b.pump(0.3)
            b.screenshot(out)
    return out


if __name__ == "__main__":
    print(bar_door_screenshot())
