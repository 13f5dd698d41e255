"""Issue 39: pictures and clearance reports that were wrong.

1. ``--plot`` with a clearance and a non-convex robot: the margin outline summed the whole
   robot with the margin (the kernel's sum takes convex operands only) and the plan exited 3.
2. The narrowest-gap inset zoomed on a gap that was not there (its width the search radius),
   and measured a passage across the path, not wall to wall.
3. A car's path reported no clearance: it is now a certified lower bound along its curves.

Oracles: shapely (Minkowski sums of a triangulation, distances between C-obstacles, the
posed robot's distance to the obstacles at densely sampled poses).
"""
from __future__ import annotations

import glob
import json
import math
import os

import numpy as np
import pytest
import shapely

from conftest import SCENARIOS
from cspace.io.load import load_scenario
from cspace.paths.gap import narrowest_gap
from planners import plan
from planners.cli import main

PNG = b"\x89PNG\r\n\x1a\n"


# ---------------------------------------------------------------- 1. margin of a non-convex robot

@pytest.mark.parametrize("scene", ["u_robot.toml", os.path.join("se2", "tee_slot.toml")])
def test_plot_with_clearance_and_a_non_convex_robot_exits_0(scene, tmp_path, capsys):
    out = tmp_path / "p.png"
    code = main(["plan", os.path.join(SCENARIOS, scene), "--clearance", "0.05", "--plot", str(out)])
    text = capsys.readouterr()
    assert code == 0, text.out + text.err
    assert "internal error" not in text.out + text.err
    assert out.read_bytes()[:8] == PNG


def _minkowski_oracle(polygon: np.ndarray, margin: np.ndarray):
    """R ⊕ M by shapely alone: the union over R's triangles (shapely's triangulation, not the
    project's decomposition) of the hull of all vertex sums (the sum of two convex sets)."""
    tris = shapely.constrained_delaunay_triangles(shapely.Polygon(polygon))
    out = []
    for t in shapely.get_parts(tris):
        tv = np.asarray(t.exterior.coords)[:-1]
        out.append(shapely.MultiPoint((tv[:, None, :] + margin[None, :, :]).reshape(-1, 2)).convex_hull)
    return shapely.union_all(out)


@pytest.mark.parametrize("scene,theta", [("u_robot.toml", 0.0), (os.path.join("se2", "tee_slot.toml"), 0.7)])
def test_the_drawn_margin_is_the_robot_grown_by_it(scene, theta):
    from planners.pictures.grown import grown_robot

    sc = load_scenario(os.path.join(SCENARIOS, scene))
    sc.clearance = 0.3
    (margin,) = sc.margins()
    drawn = shapely.union_all([shapely.Polygon(s, h) for s, h in grown_robot(sc, 2.0, -1.0, theta)])
    c, s = math.cos(theta), math.sin(theta)
    turn = np.array([[c, s], [-s, c]])  # row vectors times this: turned by theta
    want = _minkowski_oracle(sc.robot[0].polygon @ turn, margin @ turn)
    want = shapely.affinity.translate(want, 2.0, -1.0)
    assert drawn.is_valid and drawn.area > shapely.Polygon(sc.robot[0].polygon).area
    assert drawn.symmetric_difference(want).area < 1e-9 * want.area


# ---------------------------------------------------------------- 2. the narrowest gap

def test_no_gap_inset_in_open_space():
    from planners.pictures import plot

    res = plan(os.path.join(SCENARIOS, "clearance.toml"))
    assert res.solved
    assert plot.narrow_gap(res.scenario_data, res.cspace, [res]) is None
    fig = plot.figure_result(res)
    try:
        assert fig.axes[0].child_axes == []
        labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert not any(s.startswith("narrowest gap") for s in labels)
    finally:
        plot.mpl()[0].close(fig)


def _components_near(pieces: list, point) -> shapely.Geometry:
    """The connected component of the union of the C-obstacle pieces nearest to ``point``."""
    comps = list(shapely.get_parts(shapely.union_all([shapely.Polygon(p) for p in pieces])))
    return min(comps, key=lambda g: g.distance(shapely.Point(point)))


def test_real_passage_gap_is_the_distance_between_its_c_obstacles():
    from planners.pictures import plot

    res = plan(os.path.join(SCENARIOS, "narrow_passage.toml"))
    gap = plot.narrow_gap(res.scenario_data, res.cspace, [res])
    assert gap is not None
    lo = _components_near(res.cspace.pieces, gap.ends[0])
    hi = _components_near(res.cspace.pieces, gap.ends[1])
    assert not lo.equals(hi)
    assert gap.width == pytest.approx(lo.distance(hi), rel=1e-6)
    # the path crosses it: the gap's point is on the path, between its two walls
    assert shapely.LineString(res.path).distance(shapely.Point(gap.point)) < 1e-9
    assert shapely.LineString(gap.ends).distance(shapely.Point(gap.point)) < 1e-6


@pytest.mark.parametrize("angle,width,slant", [(0.0, 0.05, 0.6), (0.4, 0.02, -0.9), (1.2, 0.08, 0.3)])
def test_a_slanted_crossing_reports_the_wall_to_wall_width(angle, width, slant):
    """Two blocks leaving a corridor of ``width`` at ``angle``, crossed by a path at ``slant`` to
    its normal: the gap is the blocks' shapely distance, not the (longer) cut across the path."""
    c, s = math.cos(angle), math.sin(angle)
    R = np.array([[c, s], [-s, c]])
    half = 0.5 * width
    blocks = [np.array([[-1.0, -3.0], [1.0, -3.0], [1.0, -half], [-1.0, -half]]),
              np.array([[-1.0, half], [1.0, half], [1.0, 3.0], [-1.0, 3.0]])]
    blocks = [b @ R + 5.0 for b in blocks]
    d = np.array([math.cos(slant), math.sin(slant)]) @ R  # the corridor runs along x before turning
    path = np.array([5.0 - 3.0 * d, 5.0 + 3.0 * d])
    g = narrowest_gap(blocks, (0, 10, 0, 10), path, below=0.5)
    truth = shapely.Polygon(blocks[0]).distance(shapely.Polygon(blocks[1]))
    assert g is not None and g.width == pytest.approx(truth, rel=1e-9)
    a, b = (shapely.Point(e) for e in g.ends)
    assert shapely.Polygon(blocks[0]).distance(a) < 1e-9 and shapely.Polygon(blocks[1]).distance(b) < 1e-9


def test_a_path_along_one_wall_has_no_gap():
    """Hugging a single wall in open space: no wall on the other side within the search radius."""
    wall = [np.array([[2.0, 0.0], [8.0, 0.0], [8.0, 3.0], [2.0, 3.0]])]
    path = np.array([[1.0, 3.0], [9.0, 3.0]])  # along the wall's top edge
    assert narrowest_gap(wall, (0, 10, 0, 10), path, below=0.1) is None
    path = np.array([[1.0, 3.02], [9.0, 3.02]])  # just above it
    assert narrowest_gap(wall, (0, 10, 0, 10), path, below=0.1) is None


# ---------------------------------------------------------------- 3. a car's clearance

CARS = sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))


def _dense_oracle(res, step: float) -> float:
    """The least shapely distance from the posed robot to the obstacles at poses about ``step``
    apart along the car's curves (the project's own interpolation: what plots draw)."""
    from planners.adapters.car import dense_curve

    sc = res.scenario_data
    poses, _ = dense_curve(res.path, sc.space, sc.turning_radius, step=step)
    obstacles = shapely.union_all([shapely.Polygon(o.polygon, o.holes) for o in sc.obstacles])
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    best = math.inf
    for part in sc.robot:
        v = part.polygon
        x = poses[:, None, 0] + c[:, None] * v[None, :, 0] - s[:, None] * v[None, :, 1]
        y = poses[:, None, 1] + s[:, None] * v[None, :, 0] + c[:, None] * v[None, :, 1]
        best = min(best, float(shapely.distance(shapely.polygons(np.stack([x, y], axis=-1)), obstacles).min()))
    return best


@pytest.mark.parametrize("path", [p for p in CARS if load_scenario(p).expect == "solvable"],
                         ids=os.path.basename)
def test_car_clearance_is_a_tight_lower_bound_of_the_curves(path):
    from cspace.car.clearance import TOL, robot_radius

    res = plan(path, seed=0)
    assert res.solved
    sc = res.scenario_data
    assert res.min_clearance_bound == "lower"
    step = 2e-3
    oracle = _dense_oracle(res, step)
    r = sc.turning_radius
    rho = robot_radius([p.polygon for p in sc.robot])
    lip = 1.0 + rho / r  # the most a robot point moves per unit driven
    slack = TOL * max(r, rho) + step * lip  # the bound's aim, and the oracle's own sampling error
    assert res.min_clearance > 0 or oracle <= slack  # 0 only where the curves come within the bound's aim
    assert res.min_clearance <= oracle + 1e-9
    assert res.min_clearance >= oracle - slack - 1e-9
    # where it says: the robot there is that far (or a little farther) from the obstacles
    at = shapely.Polygon(sc.robot_at(*res.min_clearance_at)[0])
    obstacles = shapely.union_all([shapely.Polygon(o.polygon, o.holes) for o in sc.obstacles])
    assert res.min_clearance <= at.distance(obstacles) + 1e-9


def test_car_clearance_is_a_lower_bound_even_unrefined():
    """Cut off after the first samples, the bound is looser but still below the curves' clearance."""
    from cspace.car.clearance import car_path_clearance
    from cspace.car.curves import reeds_shepp_segments

    res = plan(os.path.join(SCENARIOS, "car", "u_turn.toml"), seed=0)
    r = res.scenario_data.turning_radius
    coarse = car_path_clearance(res.path, lambda a, b: reeds_shepp_segments(a, b, r), r, res.cspace.body_pieces,
                                res.cspace.obstacle_pieces, max_samples=1)
    assert coarse.bound == "lower" and 0 <= coarse.distance <= res.min_clearance
    assert coarse.distance <= _dense_oracle(res, 2e-3) + 1e-9


def test_car_clearance_in_cli_and_json(tmp_path, capsys):
    out = tmp_path / "r.json"
    code = main(["plan", os.path.join(SCENARIOS, "car", "u_turn.toml"), "--json", str(out)])
    text = capsys.readouterr().out
    assert code == 0
    assert "not measured" not in text and "(a certified lower bound)" in text
    data = json.loads(out.read_text())
    assert data["min_clearance_bound"] == "lower" and data["min_clearance"] > 0
    assert len(data["min_clearance_at"]) == 3
    assert f"min clearance {data['min_clearance']:.6g}" in text
