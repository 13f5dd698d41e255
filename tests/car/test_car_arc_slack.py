"""The car clearance's arc bound (cspace/car/clearance.py ``arc_bound``): its distance is at most the
least distance of the robot driven along the arc, and at most ``slack`` below it. The swept set is
not convex: a long edge's two end placements cross, and the slab hull fills the notches beside the
crossing; an obstacle corner in such a notch is nearer the hull than the robot ever comes (a
loading-dock path: 0.0063 below, where the slack claimed 0.0003 and the bound stopped refining)."""
from __future__ import annotations

import math

import numpy as np
import shapely

from cspace.car.clearance import arc_bound
from cspace.car.curves import advance
from cspace.translation.clearance import Nearest


def dense_least(pose, kind, length, r, piece, obstacle, n=801) -> float:
    best = math.inf
    for f in np.linspace(0.0, 1.0, n):
        x, y, th = advance(pose, kind, f * length, r)
        c, s = math.cos(th), math.sin(th)
        best = min(best, shapely.Polygon(piece @ np.array([[c, s], [-s, c]]) + (x, y)).distance(obstacle))
    return best


def test_the_arc_bound_is_below_the_sweep_and_within_its_slack():
    rng = np.random.default_rng(5)
    piece = np.array([[-0.3, -0.35], [1.1, -0.35], [1.1, 0.35], [-0.3, 0.35]])  # a car, its rear axle at 0
    r = 1.2
    worst = 0.0
    for _ in range(60):
        kind, length = ("L", "R")[int(rng.integers(2))], float(rng.uniform(-0.6, 0.6))
        pose = (0.0, 0.0, float(rng.uniform(-math.pi, math.pi)))
        # an obstacle corner beside the sweep: a small triangle near a placed vertex at the middle turn
        x, y, th = advance(pose, kind, 0.5 * length, r)
        c, s = math.cos(th), math.sin(th)
        v = piece[int(rng.integers(4))] * rng.uniform(0.3, 1.0, 2)
        px, py = x + c * v[0] - s * v[1], y + s * v[0] + c * v[1]
        ang = rng.uniform(0, 2 * math.pi)
        tip = np.array([px, py]) + rng.uniform(0.0, 0.08) * np.array([math.cos(ang), math.sin(ang)])
        tri = np.array([tip, tip + (0.5 * math.cos(ang + 0.3), 0.5 * math.sin(ang + 0.3)),
                        tip + (0.5 * math.cos(ang - 0.3), 0.5 * math.sin(ang - 0.3))])
        if shapely.Polygon(tri).area <= 0:
            continue
        tri = tri if shapely.Polygon(tri).exterior.is_ccw else tri[::-1]
        obstacle = shapely.Polygon(tri)
        d, slack = arc_bound(pose, kind, length, r, [piece], Nearest([tri]))
        true = dense_least(pose, kind, length, r, piece, obstacle)
        if true == 0.0 or not math.isfinite(d):
            continue
        spacing = (1 + 1.25 / r) * abs(length) / 800  # the dense placements' own error
        assert d <= true + 1e-9, (kind, length, pose, d, true)
        assert true - d <= slack + spacing + 1e-9, (kind, length, pose, d, true, slack)
        worst = max(worst, (true - d) / slack)
    assert worst > 0.01  # the cases reach into the slack (an obstacle in the notches), not all far away


def test_an_obstacle_in_the_notch_of_the_sweep_is_within_the_slack():
    # The loading dock's path at seed 0: a reverse right arc of 0.031 beside the dock's wall, where
    # the hull came 0.0063 nearer the wall than the car does and claimed a slack of 0.0003.
    import os

    from conftest import SCENARIOS
    from cspace.io.load import load_scenario
    from planners.core.plan import build_cspace

    sc = load_scenario(os.path.join(SCENARIOS, "car", "loading_dock.toml"))
    cs = build_cspace(sc)
    pose, length, r = (4.239551997093077, 2.219411408672043, -2.4139129628927547), -0.03148979979231398, sc.turning_radius
    d, slack = arc_bound(pose, "R", length, r, cs.body_pieces, Nearest(cs.obstacle_pieces))
    obstacles = shapely.union_all([shapely.Polygon(o.polygon, o.holes) for o in sc.obstacles])
    true = min(dense_least(pose, "R", length, r, p, obstacles) for p in cs.body_pieces)
    assert d <= true + 1e-9
    assert true - d > 1e-3  # the notch: well below (this case is the one the slack must cover)
    assert true - d <= slack + 1e-9, (d, true, slack)


def test_a_path_s_clearance_is_a_lower_bound_within_its_tolerance_of_the_dense_sweep():
    """car_path_clearance along Reeds–Shepp curves (its arcs' turned-hull bounds asked only of the
    intervals that come to the top of its heap) against the robot placed densely along the same
    curves and measured by shapely: never above that least, and at most its tolerance (plus the
    dense placements' own spacing error) below it."""
    from cspace.car.clearance import TOL, car_path_clearance
    from cspace.car.curves import knots, reeds_shepp_segments

    rng = np.random.default_rng(11)
    piece = np.array([[-0.3, -0.35], [1.1, -0.35], [1.1, 0.35], [-0.3, 0.35]])
    r = 1.0
    rho = float(np.hypot(*piece.T).max())
    checked = 0
    for _ in range(14):
        poses = [(float(rng.uniform(0, 6)), float(rng.uniform(0, 6)), float(rng.uniform(-math.pi, math.pi)))
                 for _ in range(3)]
        obstacles = []
        for _ in range(3):
            c = rng.uniform(-2, 8, 2)
            pts = c + rng.uniform(-0.8, 0.8, (6, 2))
            hull = shapely.MultiPoint([tuple(p) for p in pts]).convex_hull
            if hull.geom_type == "Polygon" and hull.area > 1e-3:
                obstacles.append(np.asarray(hull.exterior.coords)[:-1])
        if not obstacles:
            continue
        seg = lambda a, b: reeds_shepp_segments(a, b, r)  # noqa: E731
        got = car_path_clearance(np.array(poses), seg, r, [piece], obstacles)
        union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
        least, spacing = math.inf, 0.0
        for a, b in zip(poses[:-1], poses[1:]):
            segs = [s for s in seg(a, b) if s[1] != 0.0]
            for (kind, length), k0 in zip(segs, knots(a, segs, r)):
                n = max(2, int(abs(length) / 0.003))
                spacing = max(spacing, (1 + (rho / r if kind != "S" else 0.0)) * abs(length) / n)
                for f in np.linspace(0.0, 1.0, n + 1):
                    x, y, th = advance(k0, kind, f * length, r)
                    c, s = math.cos(th), math.sin(th)
                    least = min(least, shapely.Polygon(piece @ np.array([[c, s], [-s, c]]) + (x, y)).distance(union))
        if least == 0.0:
            assert got.distance == 0.0
            continue
        checked += 1
        assert got.distance <= least + 1e-9, (poses, got.distance, least)
        assert least - got.distance <= TOL * max(r, rho) + 0.5 * spacing + 1e-9, (poses, got.distance, least)
    assert checked >= 5
