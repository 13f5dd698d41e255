"""The benches' independent judge of SE(2) paths (scripts/sweep_oracle.py, ``sweep_check``): it
ends on every path with work bounded by the path (a path that slides along an obstacle closer
than a step's pad once made it halve that step some 2^31 times), it never calls a colliding path
free, and where it cannot decide it says so (``undecided``) rather than "free".

Oracles: scenes built so that the answer is known (a gap of 1e-14 or 1e-9, a needle crossed
between two grid poses), and brute force (poses sampled densely along random motions, each
tested with shapely)."""
from __future__ import annotations

import math

import numpy as np
import shapely

from conftest import load_script

oracle = load_script("sweep_oracle")


def scene(obstacles, robot, bounds=(0.0, 100.0, 0.0, 100.0)):
    from cspace.io.scenario.validate import scenario_from_dict

    xmin, xmax, ymin, ymax = bounds
    data = {"bounds": {"xmin": xmin, "xmax": xmax, "ymin": ymin, "ymax": ymax}, "robot": {"polygon": robot},
            "obstacles": [{"polygon": p} for p in obstacles], "space": "se2",
            "start": {"x": 1.0, "y": 1.0, "theta": 0.0}, "goal": {"x": 2.0, "y": 1.0, "theta": 0.0}}
    return scenario_from_dict(data, "oracle")


def grid_steps(path, dtheta=2e-3, dxy=0.2):
    return sum(max(1, math.ceil(abs(oracle._shortest(a[2], b[2])) / dtheta),
                   math.ceil(math.hypot(b[0] - a[0], b[1] - a[1]) / dxy)) for a, b in zip(path[:-1], path[1:]))


def test_a_square_sliding_along_a_wall_closer_than_rounding_is_undecided_in_bounded_work():
    # The unit square's top edge 1e-14 below a wall (the extent is 100: the pad of a step that does
    # not turn is 1e-13), slid 30 units along it. The old judge halved each step until it was
    # 1e-10 long: 2^31 halvings a step.
    sc = scene([[[0, 50], [100, 50], [100, 60], [0, 60]]], [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    y = 49.5 - 1e-14
    assert y + 0.5 < 50.0
    path = np.array([[10.0, y, 0.0], [40.0, y, 0.0]])
    j = oracle.sweep_check(sc, path)
    assert not j["collides"] and j["undecided"] >= 1, j  # neither free nor a collision: said so
    assert j["steps"] <= 4 * grid_steps(path), j  # a hull test or two a step, not a halving chain
    free = oracle.sweep_check(sc, np.array([[10.0, 49.0, 0.0], [40.0, 49.0, 0.0]]))  # 0.5 below: free
    assert not free["collides"] and free["undecided"] == 0, free


def test_a_bar_turning_and_moving_past_a_point_closer_than_its_steps_resolve_is_bounded():
    # A bar (half-length 1, half-width 0.1) turning by 2e-3 rad about its middle while it moves
    # 0.01 along itself, a triangle's apex 1e-9 above its middle (the closest any pose comes): the
    # hull of the bar's two ends is 1e-3 too tall there, and halving shrinks that only linearly.
    # The old judge made 60 000 hull tests of this one step (and 100 times as many at 1e-11).
    apex = 0.1 + 1e-9
    sc = scene([[[50, 50 + apex], [50.5, 51], [49.5, 51]]], [[-1, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    path = np.array([[49.995, 50.0, -1e-3], [50.005, 50.0, 1e-3]])
    j = oracle.sweep_check(sc, path)
    assert not j["collides"], j  # no pose meets it (1e-9 is the least distance, sampled densely)
    assert j["undecided"] == 1, j
    assert j["steps"] <= 2 * 4096 + 10, j  # the step's own cap of halves
    capped = oracle.sweep_check(sc, np.array([path[0], path[1]] * 20), total_cap=1000)
    assert capped["undecided"] == 39 and capped["steps"] <= 1000 + 2 * 39 * 5, capped  # the path's cap


def test_a_needle_crossed_between_two_poses_collides_with_a_pose_found():
    # A square translating 20 units in one grid step (dxy = 50) across a needle 1e-3 wide: neither
    # end meets it, the sweep (the hull of the ends, exactly) does.
    sc = scene([[[30, 0], [30.001, 0], [30.0005, 49.8]]], [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    j = oracle.sweep_check(sc, np.array([[20.0, 49.5, 0.0], [40.0, 49.5, 0.0]]), dxy=50.0)
    assert j["collides"] and j["certain"], j
    above = oracle.sweep_check(sc, np.array([[20.0, 50.4, 0.0], [40.0, 50.4, 0.0]]), dxy=50.0)
    assert not above["collides"] and above["undecided"] == 0, above


def test_its_verdicts_agree_with_poses_sampled_densely():
    """Free means no sampled pose meets an obstacle; a sampled pose in collision means "collides"."""
    sc = scene([[[20, 20], [40, 22], [30, 45]], [[60, 60], [80, 60], [80, 62], [60, 62]],
                [[50, 10], [52, 10], [52, 40], [50, 40]]],
               [[-3, -0.5], [3, -0.5], [3, 0.5], [-3, 0.5]])
    obstacles = shapely.union_all([o.to_shapely() for o in sc.obstacles])
    body = shapely.Polygon(sc.robot[0].polygon)
    rng = np.random.default_rng(3)
    seen = {"free": 0, "collides": 0}
    for _ in range(40):
        a = np.array([*rng.uniform(5, 95, 2), rng.uniform(-math.pi, math.pi)])
        b = np.array([*np.clip(a[:2] + rng.normal(0, 12, 2), 5, 95), rng.uniform(-math.pi, math.pi)])
        j = oracle.sweep_check(sc, np.array([a, b]))
        hit = any(obstacles.intersects(oracle.at(body, oracle._interp(a, b, t))) for t in np.linspace(0, 1, 801))
        if hit:
            assert j["collides"], (a, b, j)
        if not j["collides"] and not j["undecided"]:
            assert not hit, (a, b)
        seen["collides" if j["collides"] else "free"] += 1
    assert min(seen.values()) >= 5, seen  # both verdicts were put to the test
