"""Our results in Bench-MR's format read by Bench-MR's own plotting module (issue 50, point 3):
`python/plot_stats.py` of a checkout (``$BENCH_MR``; skipped without one, or without its
dependencies click and matplotlib) draws the statistics of a `cspace plan --bench-mr-json` file
in a child process, with the checkout's python/ folder on its path (it is not an installable
package). Nothing of Bench-MR is copied here."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

import pytest

from conftest import ROOT
from planners.cli import main

BENCH_MR = os.environ.get("BENCH_MR", "")
PLOT_STATS = os.path.join(BENCH_MR, "python", "plot_stats.py")


@pytest.mark.skipif(not (BENCH_MR and os.path.isfile(PLOT_STATS)), reason="no Bench-MR checkout ($BENCH_MR)")
@pytest.mark.skipif(importlib.util.find_spec("click") is None, reason="Bench-MR's plotting needs click")
def test_bench_mr_plots_our_results(tmp_path, capsys):
    pytest.importorskip("ompl")
    out = tmp_path / "bm.json"
    assert main(["plan", os.path.join(ROOT, "scenarios", "basic.toml"), "--bench-mr-json", str(out)]) == 0
    png = tmp_path / "stats.png"
    code = ("import sys; sys.argv = ['plot_stats']\n"
            "from plot_stats import plot_planner_stats\n"
            f"plot_planner_stats({str(out)!r}, save_file={str(png)!r}, headless=True,\n"
            "                   metrics='path_length, curvature, planning_time, cusps')\n")
    proc = subprocess.run([sys.executable, "-c", code], cwd=os.path.dirname(PLOT_STATS), capture_output=True,
                          text=True, timeout=300, env=dict(os.environ, MPLBACKEND="Agg"))
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "Saved" in proc.stdout and png.stat().st_size > 10_000
