"""A screenshot of Planner Arena showing a cspace benchmark database, taken by a real browser.

    python scripts/make_arena_screenshot.py            # docs/figures/planner_arena.png

Runs a small ``cspace bench ... --db`` sweep (bug_trap, RRTConnect, RRTstar and PRM, budgets 0.2
and 0.5 s, 10 runs each) into a temporary database, starts Planner Arena on it (the installed
``plannerarena`` package's Shiny app, ``DATABASE=...``, on a free port of 127.0.0.1), opens it in
headless Chromium (the DevTools driver of scripts/make_view_screenshots.py), picks the
``length error`` attribute on "Overall performance", waits for the plot the server draws, and saves
the viewport. The server and the browser are stopped at the end. Needs chromium and plannerarena
(``pip install -e ".[bench]"``); Google Analytics, which the app's page loads, is blocked.
"""
from __future__ import annotations

import importlib.util
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "docs", "figures", "planner_arena.png")
BENCH_ARGS = ["scenarios/bug_trap.toml", "--planners", "RRTConnect,RRTstar,PRM", "--times", "0.2,0.5",
              "--runs", "10", "--workers", "2", "--quiet", "--no-plot"]
ATTRIBUTE = "length error"  # the run column shown (one of this project's, see the guide)
PROBLEM = "bug-trap_t0.5"  # the experiment shown


def _browser_module():
    spec = importlib.util.spec_from_file_location("make_view_screenshots",
                                                  os.path.join(ROOT, "scripts", "make_view_screenshots.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def make_database(db: str, work: str) -> None:
    """The sweep of :data:`BENCH_ARGS` stored in ``db``."""
    cmd = [sys.executable, "-c", "from planners.cli import console; console()", "bench", *BENCH_ARGS,
           "--out", work, "--db", db]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=1800)
    if proc.returncode != 0 or not os.path.exists(db):
        raise RuntimeError(f"cspace bench failed (exit {proc.returncode}): {proc.stderr.strip()[-500:]}")


def start_arena(db: str, port: int, log) -> subprocess.Popen:
    """Planner Arena serving ``db`` on http://127.0.0.1:PORT/ (the app ``plannerarena`` runs, on our port)."""
    env = dict(os.environ, DATABASE=db)
    proc = subprocess.Popen([sys.executable, "-m", "shiny", "run", "--host", "127.0.0.1", "--port", str(port),
                             "plannerarena.app:app"], env=env, stdout=log, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"plannerarena exited with {proc.returncode}")
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as r:
                if r.status == 200:
                    return proc
        except OSError:
            time.sleep(0.3)
    proc.terminate()
    raise TimeoutError("plannerarena did not answer in 60 s")


def wait_for(b, expression: str, what: str, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            if b.eval(expression):
                return
        except RuntimeError:
            pass
        b.pump(0.2)
    raise TimeoutError(f"Planner Arena: {what} did not appear in {timeout:.0f} s")


PLOT_IMG = "document.querySelector('#performance-plot img')"


def arena_screenshot(out: str = OUT, db: str | None = None) -> str:
    """Save Planner Arena's "Overall performance" page for a cspace database (made here unless
    ``db`` is given) as ``out``; returns a one-line summary. ``out`` is checked before any work (a
    PNG, not a folder, not ``db`` nor the scenario the sweep reads, writable: one line, exit 2) and
    written atomically."""
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from benchutil import check_out

    check_out(out, [p for p in (db, os.path.join(ROOT, BENCH_ARGS[0])) if p], "--out", {".png": "png"})
    mod = _browser_module()
    work = tempfile.mkdtemp(prefix="cspace-arena-")
    log_path = os.path.join(work, "plannerarena.log")
    server = None
    try:
        if db is None:
            db = os.path.join(work, "results.db")
            make_database(db, os.path.join(work, "bench"))
        port = free_port()
        with open(log_path, "wb") as log:
            server = start_arena(os.path.abspath(db), port, log)
            with mod.Browser(width=1400, height=1000, timeout=60) as b:
                # The driver starts offline; Planner Arena needs its own server (HTTP and websocket).
                b.call("Network.emulateNetworkConditions", {"offline": False, "latency": 0,
                                                            "downloadThroughput": -1, "uploadThroughput": -1},
                       session=True)
                b.call("Network.setBlockedURLs", {"urls": ["*google-analytics.com*", "*googletagmanager.com*"]},
                       session=True)
                b.call("Page.navigate", {"url": f"http://127.0.0.1:{port}/"}, session=True)
                wait_for(b, "!!document.querySelector('#performance-attribute option')", "the attribute list")
                wait_for(b, f"!!document.querySelector('#performance-problem option[value=\"{PROBLEM}\"]')",
                         "the problem list")
                wait_for(b, f"{PLOT_IMG} && {PLOT_IMG}.complete", "the first plot")
                b.eval(f"""(() => {{
                    window.cspaceOldPlot = {PLOT_IMG}.src;
                    for (const [id, v] of [['performance-problem', '{PROBLEM}'], ['performance-attribute', '{ATTRIBUTE}']]) {{
                        const s = document.getElementById(id);
                        s.value = v; s.dispatchEvent(new Event('change', {{bubbles: true}}));
                    }}
                    const close = document.querySelector('.alert .btn-close'); if (close) close.click();
                    return true; }})()""")
                # The server redraws the plot: wait until its picture is there and the app idle.
                wait_for(b, f"{PLOT_IMG} && {PLOT_IMG}.src !== window.cspaceOldPlot && {PLOT_IMG}.complete && "
                            f"{PLOT_IMG}.naturalWidth > 0 && "
                            "!document.documentElement.classList.contains('shiny-busy') && "
                            "!document.querySelector('#performance-plot.recalculating')", "the plot")
                b.pump(1.0)
                wait_for(b, f"{PLOT_IMG}.complete && !document.querySelector('#performance-plot.recalculating')", "the plot")
                shown = b.eval(f"[document.getElementById('performance-problem').value, "
                               f"document.getElementById('performance-attribute').value, "
                               f"[...document.querySelectorAll('#performance-planners input:checked')]"
                               f".map(e => e.value).join(', ')]")
                b.screenshot(out)  # (written atomically)
        return f"Planner Arena: {shown[0]}, {shown[1]}, planners {shown[2]}"
    except Exception:
        if os.path.exists(log_path):
            sys.stderr.write(open(log_path, errors="replace").read()[-2000:])
        raise
    finally:
        if server is not None:
            server.terminate()
            try:
                server.wait(timeout=10)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--db", help="an existing benchmark database (default: run the small sweep)")
    ap.add_argument("--out", default=OUT, help="the PNG to write")
    args = ap.parse_args()
    print(arena_screenshot(args.out, args.db))
