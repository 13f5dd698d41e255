"""Pictures read without the guide: legends, axis labels, failed queries, the zoom on a narrow gap.

The figures are inspected as matplotlib objects before they are saved; the narrowest
gap is checked against corridors whose width is known.
"""
from __future__ import annotations

import os

import matplotlib
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from cspace.paths.gap import narrowest_gap  # noqa: E402
from planners.pictures import plot  # noqa: E402
from planners import plan  # noqa: E402

from conftest import ROOT

SCEN = os.path.join(ROOT, "scenarios")


def _legend(fig) -> list[str]:
    ax = fig.axes[0]
    leg = ax.get_legend()
    assert leg is not None, "no legend"
    return [t.get_text() for t in leg.get_texts()]


def _labels_ok(fig) -> None:
    ax = fig.axes[0]
    assert ax.get_xlabel() == "x" and ax.get_ylabel() == "y"


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_plan_picture_has_a_legend_for_everything_drawn():
    res = plan(os.path.join(SCEN, "basic.toml"), planner="exact")
    fig = plot.figure_result(res)
    _labels_ok(fig)
    labels = _legend(fig)
    for want in ("bounds", "obstacle", "C-obstacle (reference point there: collision)", "robot at start",
                 "robot at goal", "robot along the path", f"path (length {res.length:.4g})"):
        assert want in labels, (want, labels)
    assert not any("no path" in s for s in labels)
    assert not fig.axes[0].child_axes  # wide passages: no zoom


def test_scene_picture_has_a_legend_and_labels():
    from cspace.translation.cspace import CSpace
    from cspace.io.load import load_scenario

    sc = load_scenario(os.path.join(SCEN, "basic.toml"))
    fig = plot.figure_scene(sc, CSpace.from_scenario(sc))
    _labels_ok(fig)
    assert _legend(fig) == ["bounds", "obstacle", "C-obstacle, convex pieces outlined", "robot at start",
                            "robot at goal"]


def test_point_robot_scene_names_its_pieces():
    from cspace.translation.cspace import CSpace
    from cspace.io.load import load_scenario

    sc = load_scenario(os.path.join(SCEN, "ompl", "circles.toml"))
    labels = _legend(plot.figure_scene(sc, CSpace.from_scenario(sc)))
    assert "convex pieces (point robot: C-obstacle = obstacle)" in labels
    assert not any(s.startswith("C-obstacle") for s in labels)


TWO_QUERIES = """
name = "two-queries"
[bounds]
xmin = 0.0
xmax = 10.0
ymin = 0.0
ymax = 10.0
[robot]
polygon = [[-0.2, -0.2], [0.2, -0.2], [0.2, 0.2], [-0.2, 0.2]]
[[obstacles]]
polygon = [[6.0, 6.0], [9.0, 6.0], [9.0, 9.0], [6.0, 9.0]]
holes = [[[7.0, 7.0], [7.0, 8.0], [8.0, 8.0], [8.0, 7.0]]]
[start]
x = 1.0
y = 1.0
[goal]
x = 4.0
y = 2.0
[[queries]]
start = [1.0, 1.0]
goal = [4.0, 2.0]
[[queries]]
start = [2.0, 4.0]
goal = [7.5, 7.5]
[planner]
name = "exact"
"""


def test_multi_query_picture_marks_the_failed_query(write_toml):
    res = plan(write_toml(TWO_QUERIES), all_queries=True)
    assert [q.solved for q in res.queries] == [True, False]  # the second goal is walled in
    fig = plot.figure_result(res)
    _labels_ok(fig)
    labels = _legend(fig)
    assert "no path found (1 query, start to goal)" in labels and "paths (1 query)" in labels
    assert "query start" in labels and "query goal" in labels
    ax = fig.axes[0]
    marks = [ln for ln in ax.get_lines() if ln.get_color() == plot.FAILED and ln.get_marker() == "x"]
    assert len(marks) == 1
    assert np.allclose(marks[0].get_xydata(), [[2.0, 4.0], [7.5, 7.5]])  # at the failed query's ends
    assert any(t.get_text() == "query 1" for t in ax.texts)
    assert "1/2 queries solved" in ax.get_title()


def test_single_unsolved_plan_is_marked(write_toml):
    text = TWO_QUERIES.replace("x = 4.0\ny = 2.0", "x = 7.5\ny = 7.5")
    res = plan(write_toml(text))
    assert not res.solved
    labels = _legend(plot.figure_result(res))
    assert "no path found (start to goal)" in labels and not any(s.startswith("path") for s in labels)


def test_narrow_passage_gets_a_zoom_on_its_gap():
    res = plan(os.path.join(SCEN, "narrow_passage.toml"))
    fig = plot.figure_result(res)
    ax = fig.axes[0]
    assert len(ax.child_axes) == 1
    ins = ax.child_axes[0]
    x0, x1 = ins.get_xlim()
    xmin, xmax, ymin, ymax = res.cspace.bounds
    size = max(xmax - xmin, ymax - ymin)
    assert 0 < x1 - x0 < 0.01 * size  # really zoomed in
    gap = plot.narrow_gap(res.scenario_data, res.cspace, [res])
    # The passage of narrow_passage.toml: obstacles 5.524143 - 4.523143 apart, robot 1 wide.
    assert gap.width == pytest.approx(5.524143 - 4.523143 - 1.0, rel=1e-6)
    assert x0 < gap.center[0] < x1
    assert any(s.startswith("narrowest gap") for s in _legend(fig))
    assert "gap 0.001" in ins.get_title()


def test_saved_picture_is_a_png(tmp_path):
    res = plan(os.path.join(SCEN, "narrow_passage.toml"))
    out = tmp_path / "p.png"
    plot.plot_result(res, str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- the gap, against known corridors


def _corridor(y: float, w: float):
    """Two blocks leaving a horizontal corridor [y, y + w] for x in [4, 6] in a 10 x 10 box."""
    return [np.array([[4.0, 0.0], [6.0, 0.0], [6.0, y], [4.0, y]]),
            np.array([[4.0, y + w], [6.0, y + w], [6.0, 10.0], [4.0, 10.0]])]


@settings(max_examples=30, deadline=None)
@given(y=st.floats(1.0, 8.0), w=st.floats(1e-6, 0.9), t=st.floats(0.0, 1.0))
def test_gap_is_the_corridor_width_wherever_the_path_crosses_it(y, w, t):
    py = y + t * w  # anywhere across the corridor, walls included
    g = narrowest_gap(_corridor(y, w), (0, 10, 0, 10), np.array([[1.0, py], [9.0, py]]))
    assert g.width == pytest.approx(w, rel=1e-9, abs=1e-12)
    assert 4.0 <= g.point[0] <= 6.0 and g.ends[0][0] == pytest.approx(g.point[0])
    # Looking only for gaps below 1 (only the edges near the path): the same gap.
    fast = narrowest_gap(_corridor(y, w), (0, 10, 0, 10), np.array([[1.0, py], [9.0, py]]), below=1.0)
    assert fast.width == pytest.approx(w, rel=1e-9, abs=1e-12)


def test_gap_in_open_space_is_the_extent_across_the_path():
    g = narrowest_gap([], (0, 10, 0, 4), np.array([[1.0, 1.0], [9.0, 1.0]]))
    assert g.width == pytest.approx(4.0)
    assert narrowest_gap([], (0, 10, 0, 4), np.array([[1.0, 1.0], [1.0, 1.0]])) is None
    assert narrowest_gap([], (0, 10, 0, 4), np.array([[1.0, 1.0], [9.0, 1.0]]), below=3.9) is None


def test_gap_ignores_theta_of_poses():
    walls = _corridor(4.0, 0.3)
    xy = np.array([[1.0, 4.1], [9.0, 4.2]])
    poses = np.column_stack([xy, [0.3, 1.2]])
    a = narrowest_gap(walls, (0, 10, 0, 10), xy)
    b = narrowest_gap(walls, (0, 10, 0, 10), poses)
    assert a == b
    # Across a path of slope 0.1 / 8 the perpendicular meets the walls at that angle, longer than the
    # corridor is wide; the gap reported is the corridor's width, wall to wall.
    assert a.width == pytest.approx(0.3, rel=1e-9)


def test_titles_say_proven_unsolvable_and_give_no_seed_to_the_exact_planner():
    # the picture's title, the page's and the command line say the same (issue 51): a query with
    # a proof is "proven unsolvable", not "not solved"; the seedless exact planner shows no seed
    from planners.pictures.view.figure import scene_layout

    impossible = plan(os.path.join(SCEN, "se2", "wide_square.toml"), planner="RRTConnect", time=5)
    exact = plan(os.path.join(SCEN, "basic.toml"), planner="exact")
    sampled = plan(os.path.join(SCEN, "basic.toml"), planner="RRTConnect", seed=4, time=5)
    for res, want, unwanted in ((impossible, "proven unsolvable", "not solved"), (exact, "exact, length", "seed"),
                                (sampled, "RRTConnect, seed 4, length", "not solved")):
        png = plot.figure_result(res).axes[0].get_title()
        page = scene_layout(res.scenario_data, res, [], [])["title"]["text"]
        assert png == page and want in png and unwanted not in png, (png, page)
