"""Clearance (issue 21): safety margins, the min clearance of every path, exact paths with a
margin, objectives and CSV export, against independent shapely computations.

How path_clearance measures a path (its pruning bounds, the closest position, the SE(2) lower
bound): tests/translation/test_path_clearance.py."""
import heapq
import json
import math

import numpy as np
import pytest
import shapely

from cspace.translation.cspace import CSpace
from cspace.kernel.polygons.disk import disk_polygon, disk_sides
from cspace.kernel.minkowski.margin import MARGIN_PHASE
from cspace.io.load import ScenarioError, scenario_from_dict
from oracles import swept_clearance

TOL = 0.05  # disk_tolerance of the random scenes: an 11-gon margin (few vertices for the oracle)


# ------------------------------------------------------------------ independent oracles
# (and swept_clearance, tests/helpers/oracles.py: the robot swept along a path, by shapely)

def oracle_cobstacles(obstacles, robot, margin) -> list:
    """obstacle ⊕ −robot ⊕ −margin for convex operands: the hull of all vertex sums (numpy + shapely)."""
    out = []
    for o in obstacles:
        pts = o
        for op in ([robot] if robot is not None else []) + [margin]:
            pts = (pts[:, None, :] - op[None, :, :]).reshape(-1, 2)
        out.append(np.asarray(shapely.MultiPoint(pts).convex_hull.exterior.coords)[:-1])
    return out


def oracle_shortest(pieces, bounds, s, g) -> float:
    """Dijkstra over the pieces' vertices, start and goal; an edge is valid iff it stays in the
    box and meets no piece's interior (DE-9IM T********)."""
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    box = shapely.box(bounds[0], bounds[2], bounds[1], bounds[3])
    pts = [tuple(s), tuple(g)] + [tuple(v) for p in pieces for v in p.tolist()]
    pts = [p for i, p in enumerate(pts)
           if i < 2 or (box.covers(shapely.Point(p)) and not union.relate_pattern(shapely.Point(p), "T********"))]

    def ok(a, b):
        seg = shapely.LineString([a, b])
        return box.covers(seg) and not union.relate_pattern(seg, "T********")

    dist = {0: 0.0}
    heap, done = [(0.0, 0)], set()
    while heap:
        d, u = heapq.heappop(heap)
        if u in done:
            continue
        done.add(u)
        if u == 1:
            return d
        for w in range(len(pts)):
            if w not in done:
                nd = d + math.dist(pts[u], pts[w])
                if nd < dist.get(w, math.inf) and ok(pts[u], pts[w]):
                    dist[w] = nd
                    heapq.heappush(heap, (nd, w))
    return math.inf


# ------------------------------------------------------------------ random scenes

def random_scene(seed: int, point: bool = False) -> dict:
    rng = np.random.default_rng(seed)
    obstacles = []
    for _ in range(4):
        c = rng.uniform(2, 8, 2)
        pts = c + rng.normal(0, 0.8, (int(rng.integers(3, 7)), 2))
        hull = shapely.MultiPoint(pts).convex_hull
        if hull.area > 0.05:
            obstacles.append([list(map(float, v)) for v in np.asarray(hull.exterior.coords)[:-1]])
    d = float(rng.uniform(0.05, 0.4))
    data = {"bounds": {"xmin": 0.0, "xmax": 10.0, "ymin": 0.0, "ymax": 10.0}, "clearance": d,
            "disk_tolerance": TOL, "obstacles": [{"polygon": o} for o in obstacles],
            "start": {"x": 0.5, "y": 0.5}, "goal": {"x": 9.5, "y": 9.5}}
    if not point:
        w, h = rng.uniform(0.1, 0.4, 2)
        data["robot"] = {"polygon": [[-w, -h], [w, -h], [0.0, h]]}
    union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
    robot = shapely.Polygon(data["robot"]["polygon"]) if not point else shapely.Point(0, 0)
    free = []
    while len(free) < 2:  # start and goal with the margin kept (shapely)
        p = rng.uniform(0.6, 9.4, 2)
        if shapely.affinity.translate(robot, *p).distance(union) > 1.1 * d:
            free.append(p)
    data["start"] = {"x": float(free[0][0]), "y": float(free[0][1])}
    data["goal"] = {"x": float(free[1][0]), "y": float(free[1][1])}
    return data


@pytest.mark.parametrize("seed", range(8))
def test_exact_with_margin_matches_an_independent_visibility_graph(seed):
    from planners import plan

    data = random_scene(seed, point=seed % 4 == 3)
    sc = scenario_from_dict(data)
    res = plan(sc, planner="exact")
    d = data["clearance"]
    margin = disk_polygon((0.0, 0.0), d, sides=disk_sides(d, TOL * d), phase=MARGIN_PHASE)
    robot = np.array(data["robot"]["polygon"], dtype=np.float64) if "robot" in data else None
    obstacles = [np.array(o["polygon"], dtype=np.float64) for o in data["obstacles"]]
    ref = oracle_shortest(oracle_cobstacles(obstacles, robot, margin), sc.bounds, sc.start, sc.goal)
    if math.isinf(ref):
        assert not res.solved
        return
    assert res.solved
    assert res.length == pytest.approx(ref, rel=1e-9)
    # The path keeps the margin: the robot swept along it stays >= D from the obstacles
    # (rounding of the sums: 1e-12 of the scene), and the result says how close it comes.
    truth = swept_clearance(res.path, [robot] if robot is not None else [], obstacles)
    assert truth >= d - 1e-12
    if len(res.path) > 2:  # it bends: there it touches the inflated C-obstacles
        assert truth <= d * (1 + TOL) + 1e-12
    assert res.min_clearance == pytest.approx(truth, rel=1e-9, abs=1e-12)
    assert not res.touches


@pytest.mark.parametrize("seed", range(4))
def test_sampled_paths_keep_the_margin(seed):
    from planners import plan

    data = random_scene(100 + seed)
    sc = scenario_from_dict(data)
    res = plan(sc, planner="RRTConnect", time=0.5, seed=seed)
    if not res.solved:
        pytest.skip("not solved within the budget")
    robot = [np.array(data["robot"]["polygon"], dtype=np.float64)]
    obstacles = [np.array(o["polygon"], dtype=np.float64) for o in data["obstacles"]]
    truth = swept_clearance(res.path, robot, obstacles)
    assert truth > data["clearance"] - 1e-12
    assert res.min_clearance == pytest.approx(truth, rel=1e-9, abs=1e-12)
    # The reported closest point is on an obstacle, at that distance from the robot at the pose.
    x, y = res.min_clearance_at
    robot_there = shapely.Polygon(robot[0] + (x, y))
    assert robot_there.distance(shapely.Point(res.min_clearance_obstacle)) == pytest.approx(truth, rel=1e-6, abs=1e-9)


def test_min_clearance_of_plain_plans_matches_shapely():
    """Without a margin, on a bundled scene with a non-convex robot (pieces)."""
    import os

    from conftest import SCENARIOS
    from planners import plan

    for name in ("basic.toml", "u_robot.toml"):
        res = plan(os.path.join(SCENARIOS, name), planner="RRTConnect", seed=2)
        assert res.solved
        sc = res.scenario_data
        parts = []
        for s in sc.robot:  # shapely's own triangulation of each part: convex pieces
            tris = shapely.constrained_delaunay_triangles(shapely.Polygon(s.polygon))
            parts += [np.asarray(t.exterior.coords)[:-1] for t in tris.geoms]
        obstacles = []
        for o in sc.obstacles:
            tris = shapely.constrained_delaunay_triangles(shapely.Polygon(o.polygon, o.holes))
            obstacles += [np.asarray(t.exterior.coords)[:-1] for t in tris.geoms]
        truth = swept_clearance(res.path, parts, obstacles)
        assert res.min_clearance == pytest.approx(truth, rel=1e-9, abs=1e-12)
        assert res.min_clearance_bound == "exact"


def test_exact_without_clearance_says_it_touches(tmp_path):
    import os

    from conftest import SCENARIOS
    from planners.cli import main

    out = tmp_path / "r.json"
    assert main(["plan", os.path.join(SCENARIOS, "basic.toml"), "--planner", "exact", "--json", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["touches"] is True and d["min_clearance"] == 0.0 and d["clearance"] == 0.0


def test_clearance_zero_reproduces_the_plain_plan():
    import os

    from conftest import SCENARIOS
    from planners import plan

    f = os.path.join(SCENARIOS, "basic.toml")
    for planner in ("exact", "RRTConnect"):
        a, b = plan(f, planner=planner, seed=4), plan(f, planner=planner, seed=4, clearance=0.0)
        assert np.array_equal(a.path, b.path) and a.length == b.length
    plain = CSpace.from_scenario(f)
    sc = plain.scenario
    assert sc.margins() == []
    again = CSpace(sc.bounds, [o.polygon for o in sc.obstacles], [r.polygon for r in sc.robot],
                   normalized=True, margin=[])
    assert len(plain.pieces) == len(again.pieces)
    assert all(np.array_equal(p, q) for p, q in zip(plain.pieces, again.pieces))


def test_margin_cspace_is_the_inflated_robot():
    """Points: free with the margin iff the robot there is farther than the margin polygon
    reaches (shapely: robot ⊕ margin, as a hull of vertex sums, against the obstacles)."""
    rng = np.random.default_rng(5)
    obstacles = [np.array([[3., 3], [6, 3], [6, 5], [3, 5]]), np.array([[7., 6], [9, 8], [7, 9]])]
    robot = np.array([[-0.5, -0.2], [0.5, -0.2], [0.0, 0.4]])
    aniso = np.array([[-0.1, -0.2], [0.6, -0.2], [0.6, 0.2], [-0.1, 0.2]])
    margin = [disk_polygon((0, 0), 0.3, sides=12), aniso]
    cs = CSpace((0, 10, 0, 10), obstacles, [robot], margin=margin)
    inflated = shapely.MultiPoint((robot[:, None, None, :] + margin[0][None, :, None, :]
                                   + aniso[None, None, :, :]).reshape(-1, 2)).convex_hull
    union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
    for p in rng.uniform(0, 10, (400, 2)):
        d = shapely.affinity.translate(inflated, *p).distance(union)
        if d > 1e-9:
            assert cs.is_free(tuple(p))
        elif not shapely.affinity.translate(inflated, *p).touches(union):
            assert not cs.is_free(tuple(p))


def test_point_robot_with_margin():
    obstacles = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])]
    cs = CSpace((0, 10, 0, 10), obstacles, [], margin=[disk_polygon((0, 0), 1.0, sides=64)])
    assert cs.is_free((2.9, 5.0)) and not cs.is_free((3.1, 5.0))


def test_se2_plan_keeps_the_margin(write_toml):
    from planners import plan
    from cspace.se2.motion import interpolate
    from cspace.kernel.polygons.rotation import rotate

    f = write_toml("""
        space = "se2"
        clearance = 0.2
        disk_tolerance = 0.05
        [bounds]
        xmin = 0
        xmax = 10
        ymin = 0
        ymax = 10
        [robot]
        polygon = [[-0.8, -0.15], [0.8, -0.15], [0.8, 0.15], [-0.8, 0.15]]
        [margin]
        polygon = [[-0.1, -0.1], [0.3, -0.1], [0.3, 0.1], [-0.1, 0.1]]
        [[obstacles]]
        polygon = [[4, 0], [5, 0], [5, 6], [4, 6]]
        [start]
        x = 2
        y = 2
        theta = 0
        [goal]
        x = 8
        y = 2
        theta = 1.5
        """)
    res = plan(f, planner="RRTConnect", time=5.0, seed=1)
    assert res.solved and res.min_clearance_bound == "lower"
    bar = np.array([[-0.8, -0.15], [0.8, -0.15], [0.8, 0.15], [-0.8, 0.15]])
    wall = shapely.Polygon([[4, 0], [5, 0], [5, 6], [4, 6]])
    sampled = min(shapely.Polygon(rotate(bar, q[2]) + q[:2]).distance(wall)
                  for a, b in zip(res.path[:-1], res.path[1:]) for t in np.linspace(0, 1, 200)
                  for q in [np.array(interpolate(a, b, t))])
    assert sampled >= 0.2 - 1e-9
    assert res.min_clearance <= sampled + 1e-12


@pytest.mark.parametrize("field,value,fault", [
    ("clearance", -1.0, "clearance: must be a distance >= 0"),
    ("clearance", "a", "clearance: must be a number"),
    ("margin", {"polygon": [[1, 1], [2, 1], [2, 2], [1, 2]]}, "margin.polygon: must contain the origin"),
    ("margin", {"polygon": [[-1, -1], [1, -1], [0, 0], [1, 1], [-1, 1]]}, "margin.polygon: must be convex"),
    ("margin", {"radius": 1}, "margin.radius: unknown field"),
])
def test_bad_margins_are_named(field, value, fault):
    data = {"bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10}, "start": {"x": 1, "y": 1},
            "goal": {"x": 9, "y": 9}, field: value}
    with pytest.raises(ScenarioError, match=fault.replace("(", r"\(")):
        scenario_from_dict(data, "s.toml")


def test_start_closer_than_the_clearance_is_refused(write_toml):
    from planners import plan

    f = write_toml("""
        [bounds]
        xmin = 0
        xmax = 10
        ymin = 0
        ymax = 10
        [[obstacles]]
        polygon = [[2, 0], [3, 0], [3, 3], [2, 3]]
        [start]
        x = 1.5
        y = 1
        [goal]
        x = 9
        y = 9
        """)
    with pytest.raises(ScenarioError, match="start: .*with clearance 1"):
        plan(f, planner="exact", clearance=1.0)
    with pytest.raises(ScenarioError, match="clearance: must be a finite distance"):
        plan(f, planner="exact", clearance=-0.5)


def test_cli_clearance_csv_and_objective(tmp_path):
    import os

    from conftest import SCENARIOS
    from planners.cli import main

    f = os.path.join(SCENARIOS, "basic.toml")
    csv, js = tmp_path / "p.csv", tmp_path / "p.json"
    assert main(["plan", f, "--planner", "exact", "--clearance", "0.25", "--csv", str(csv), "--json", str(js)]) == 0
    d = json.loads(js.read_text())
    lines = csv.read_text().splitlines()
    assert lines[0] == "x,y" and len(lines) == len(d["path"]) + 1
    assert [list(map(float, ln.split(","))) for ln in lines[1:]] == d["path"]  # the same doubles
    assert d["clearance"] == 0.25 and d["min_clearance"] >= 0.25 - 1e-12 and d["touches"] is False
    assert main(["plan", f, "--objective", "clearance", "--planner", "PRMstar"]) == 2
    assert main(["plan", f, "--clearance", "-1"]) == 2


def test_clearance_objective_runs_and_is_recorded():
    import os

    from conftest import SCENARIOS
    from planners import plan

    f = os.path.join(SCENARIOS, "basic.toml")
    for objective in ("clearance", "balanced"):
        res = plan(f, planner="RRTstar", time=30.0, seed=1, objective=objective, iterations=250)
        assert res.solved and res.objective == objective
        assert res.min_clearance > 0.0


def test_csv_of_se2_path_has_theta():
    from planners.output import path_csv

    text = path_csv(np.array([[1.0, 2.0, 0.5]]), 3)
    assert text.splitlines() == ["x,y,theta", "1.0,2.0,0.5"]


def test_plot_marks_the_closest_approach():
    import os

    from conftest import SCENARIOS
    from planners import plan
    from planners.pictures.plot import figure_result

    res = plan(os.path.join(SCENARIOS, "clearance.toml"))
    fig = figure_result(res)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert f"closest approach (clearance {res.min_clearance:.3g})" in labels
    assert "robot with its safety margin 0.3" in labels
    notes = [t.get_text() for t in fig.axes[0].texts]
    assert any(n.startswith("clearance = 0.3") for n in notes)
    import matplotlib.pyplot as plt

    plt.close(fig)


@pytest.mark.parametrize("value, fault", [
    ("1e308", "--clearance: 1e+308 is beyond the supported magnitude 2^400"),
    ("-1", "--clearance: must be a finite distance >= 0"),
    ("nan", "--clearance: must be a finite distance >= 0"),
])
@pytest.mark.parametrize("command", ["plan", "show"])
def test_bad_clearance_options_are_one_line_exit_2(command, value, fault, tmp_path):
    # --clearance 1e308 built a margin beyond the supported coordinates and ended as an
    # internal error (exit 3); every bad value is one line naming the option, exit 2.
    import os
    import subprocess
    import sys

    from conftest import SCENARIOS

    out = subprocess.run([sys.executable, "-m", "planners", command, os.path.join(SCENARIOS, "basic.toml"),
                          f"--clearance={value}"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and fault in lines[0] and "Traceback" not in out.stderr


def test_plan_api_refuses_a_huge_clearance():
    import os

    from conftest import SCENARIOS
    from planners import plan

    with pytest.raises(ScenarioError, match=r"clearance: 1e\+308 is beyond the supported magnitude"):
        plan(os.path.join(SCENARIOS, "basic.toml"), clearance=1e308)


@pytest.mark.parametrize("d, tol", [(0.3, 1e-3), (1.0, 1e-2), (2.5, 1e-4), (1e-3, 1e-3)])
def test_margin_polygon_contains_the_disk_within_its_error(d, tol):
    """The turned margin polygon is still the circumscribed regular polygon: every edge's line
    at least D from the centre (exact: the line's signed distance, computed in Fractions,
    squared), every vertex within the documented error of the disk (shapely)."""
    from fractions import Fraction

    from cspace.kernel.minkowski.margin import margin_error, margin_shapes

    (m,) = margin_shapes(d, disk_tolerance=tol)
    n = len(m)
    assert n == disk_sides(d, tol * d)
    for k in range(n):
        (ax, ay), (bx, by) = map(lambda v: map(Fraction, v), (m[k], m[(k + 1) % n]))
        cross = ax * by - ay * bx  # twice the triangle (0, a, b): the line's distance times |b - a|
        assert cross > 0 and cross * cross >= Fraction(d) ** 2 * ((bx - ax) ** 2 + (by - ay) ** 2)
    assert shapely.Polygon(m).hausdorff_distance(shapely.Point(0, 0).buffer(d, 4096)) <= margin_error(d, tol) + 1e-6 * d


@pytest.mark.parametrize("sides", [8, 31, 64, 71, 72, 200])
def test_margin_edges_are_parallel_to_no_axis_and_no_disk_edge(sides):
    """Why the margin is turned: its edges meet neither the axis-parallel edges of boxes nor the
    edges of a disk of the same side count at a near-tie (each such tie is an exact comparison,
    and its rounded sum vertex a hull repair, in every pair sum)."""
    from cspace.kernel.minkowski.margin import margin_shapes

    d = 0.7
    ang = lambda p: np.arctan2(*(np.roll(p, -1, axis=0) - p)[:, ::-1].T)
    (m,) = margin_shapes(d, disk_tolerance=1.0 / math.cos(math.pi / sides) - 1.0 + 1e-12)
    assert len(m) == sides
    # Without the turn, the same-count disk's edges are parallel to the margin's (to rounding).
    assert np.abs(np.sort(ang(m)) - np.sort(ang(disk_polygon((0.0, 0.0), d, sides=sides)))).max() > 1e-3 / sides
    disk = disk_polygon((3.0, -2.0), 1.3, sides=len(m))
    step = 2 * math.pi / len(m)
    for other in (ang(disk), np.array([0.0, math.pi / 2, math.pi, -math.pi / 2])):
        gap = np.abs((ang(m)[:, None] - other[None, :] + math.pi) % (2 * math.pi) - math.pi)
        assert gap.min() > 1e-3 * step  # a tie would be within rounding, some 1e-15
