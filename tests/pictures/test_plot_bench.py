"""The bench figure: every planner in the legend, tick labels that do not overlap, plain numbers."""
from __future__ import annotations

import itertools

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from planners.pictures import bench_figure as pb  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _rows(scenarios, planners, budgets, runs, error_of, solved_of=lambda *a: True):
    """Synthetic bench rows: error_of(scenario, planner, budget, seed) for solved runs."""
    rows = []
    for sc, p, t, s in itertools.product(scenarios, planners, budgets, range(runs)):
        ok = solved_of(sc, p, t, s)
        rows.append({"scenario": sc, "planner": p, "time_budget": t, "seed": s, "status": "ok", "solved": ok,
                     "error": error_of(sc, p, t, s) if ok else None})
    return rows


def _labels(axis) -> list:
    return [t for t in axis.get_ticklabels(which="both") if t.get_visible() and t.get_text()]


def _overlaps(fig, axis) -> list:
    """Pairs of tick labels of one axis whose boxes on the canvas intersect."""
    r = fig.canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(r)) for t in _labels(axis)]
    return [(a, b) for (a, ba), (b, bb) in itertools.combinations(boxes, 2) if ba.overlaps(bb)]


def _check_ticks(fig) -> None:
    fig.canvas.draw()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            assert not _overlaps(fig, axis), _overlaps(fig, axis)
            for t in _labels(axis):
                txt = t.get_text().replace(" %", "")
                assert "$" not in txt and "times" not in txt, txt  # plain numbers, no 6x10^-2
                float(txt)


def test_overlap_detector_can_fail():
    fig, ax = plt.subplots(figsize=(2, 2))
    ax.set_yscale("log")
    ax.set_ylim(0.01, 1)
    pb._set_log_ticks(ax.yaxis, list(np.geomspace(0.011, 0.99, 40)))
    fig.canvas.draw()
    assert _overlaps(fig, ax.yaxis)


@pytest.mark.parametrize("lo,hi", [(0.03, 0.07), (0.0101, 0.0109), (1e-6, 5.0), (0.2, 3.0), (1e-4, 1e-3)])
def test_error_ticks_are_readable_for_any_range(lo, hi):
    rng = np.random.default_rng(0)
    budgets = [0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0]  # more than fit: thinned
    rows = _rows(["a", "b"], ["RRTConnect", "RRTstar"], budgets, 4,
                 lambda *a: float(np.exp(rng.uniform(np.log(lo), np.log(hi)))))
    fig = pb.figure_error_vs_time(rows)
    _check_ticks(fig)
    top = fig.axes[0]
    assert len(_labels(top.yaxis)) >= 2  # a scale can be read
    assert 2 <= len(_labels(fig.axes[2].xaxis)) <= pb.MAX_TICKS


def test_legend_names_every_planner_solved_or_not():
    planners = ["RRTConnect", "RRTstar", "PRMstar", "BITstar"]
    rows = _rows(["basic", "maze"], planners, [0.01, 0.1, 1.0], 3, lambda *a: 0.05,
                 solved_of=lambda sc, p, t, s: p in ("RRTConnect", "BITstar") and (sc == "basic" or p == "BITstar"))
    fig = pb.figure_error_vs_time(rows)
    texts = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert texts == ["RRTConnect", "RRTstar (no run solved)", "PRMstar (no run solved)", "BITstar"]
    _check_ticks(fig)
    # Axis labels name what is plotted.
    assert "optimum" in fig.axes[0].get_ylabel() and fig.axes[len(fig.axes) // 2].get_xlabel() == "time budget (s)"


def test_a_scenario_nobody_solved_says_so_and_one_budget_works():
    rows = _rows(["shut"], ["RRTConnect"], [0.5], 2, lambda *a: 0.1, solved_of=lambda *a: False)
    fig = pb.figure_error_vs_time(rows)
    assert any(t.get_text() == "no run solved" for t in fig.axes[0].texts)
    _check_ticks(fig)


def test_curves_agree_with_the_bench():

    rng = np.random.default_rng(1)
    rows = _rows(["a"], ["P", "Q"], [0.1, 1.0], 5, lambda *a: float(rng.uniform(0, 1)),
                 solved_of=lambda sc, p, t, s: s != 2)
    assert pb.curves(rows) == pb.curves(rows)


def test_written_png(tmp_path):
    rows = _rows(["a"], ["P"], [0.1, 1.0], 2, lambda *a: 0.1)
    out = tmp_path / "e.png"
    pb.plot_error_vs_time(rows, str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_clearance_row_when_measured_readable_and_marked():
    """A middle row of median min clearance when the runs measured it; a car's column says it has none;
    an SE(2) column says its numbers are lower bounds; without clearances the figure is as before."""
    rng = np.random.default_rng(2)
    rows = _rows(["plain", "se2", "car"], ["RRTConnect", "RRTstar"], [0.01, 0.1, 1.0], 3,
                 lambda *a: float(rng.uniform(0.01, 0.2)))
    for r in rows:
        measured = r["solved"] and r["scenario"] != "car"
        r["min_clearance"] = float(rng.uniform(0.3, 0.31)) if measured else None
        r["min_clearance_bound"] = ("lower" if r["scenario"] == "se2" else "exact") if measured else None
    fig = pb.figure_error_vs_time(rows)
    _check_ticks(fig)
    assert len(fig.axes) == 9
    mid = fig.axes[3:6]
    assert "clearance" in mid[0].get_ylabel()
    assert [t.get_text() for t in mid[2].texts] == ["no clearance measured"]
    assert [t.get_text() for t in mid[1].texts] == ["certified lower bound"]
    assert len(_labels(mid[0].yaxis)) >= 2
    med = pb.curves(rows, "min_clearance")[("plain", "RRTstar")]["median"]
    line = mid[0].get_lines()[1]  # RRTstar's
    assert list(line.get_ydata()) == med
    plt.close(fig)
    for r in rows:
        r["min_clearance"] = None
    assert len(pb.figure_error_vs_time(rows).axes) == 6
