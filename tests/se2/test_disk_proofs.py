"""Proofs that no path exists are true for disks as written (issue 49, point 1).

A disk (obstacle, robot, robot part, clearance) is a circumscribed polygon in the C-space: right
for a certified path (more obstacle, a bigger robot), wrong for a proof (the polygon may close a
door the disk leaves open). The proof side (SE(2) POSSIBLE, the checker's regions, the translation
planner's separated components) is built of polygons inscribed in the disks.

Oracles: the true circles (a shapely distance to the centre minus the radius; exact ``Fraction``
arithmetic for "inside the disk"); each scene of the families has a witness path (a straight
translation) whose clearance to the true disks is measured so, and it is never "proven
unsolvable", by the slab graph, its proof before sampling, or the translation planner.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings, strategies as st

from cspace.io.load import scenario_from_dict
from cspace.kernel.polygons.disk import disk_inner_polygon, disk_polygon
from cspace.se2.exact import exact_se2_search, from_scenario
from planners.core.exact import exact_plan, separated_proof
from planners.core.exact_se2 import quick_proof
from planners.core.plan import build_cspace
from planners.core.proof_check import check_proof, in_disk


def inside_exactly(p, c, r) -> bool:
    return all((Fraction(x) - Fraction(c[0])) ** 2 + (Fraction(y) - Fraction(c[1])) ** 2 < Fraction(r) ** 2
               for x, y in p.tolist())


@pytest.mark.slow
@settings(max_examples=200, deadline=None)
@given(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6), st.floats(1e-3, 1e3), st.integers(8, 400))
@example(1e6, -1e6, 1e-3, 71)
def test_inscribed_polygon_lies_inside_the_true_disk(cx, cy, r, n):
    p = disk_inner_polygon((cx, cy), r, n)
    assert len(p) >= 3 and inside_exactly(p, (cx, cy), r) and in_disk(p.tolist(), (cx, cy, r))
    # ... and close to it: every vertex within the rounding shrink of the circle, edges within the sagitta
    d = np.hypot(p[:, 0] - cx, p[:, 1] - cy)
    assert d.min() > r - (2.0**-40 * r + 64 * math.ulp(max(abs(cx), abs(cy)) + r))
    out = disk_polygon((cx, cy), r, sides=n)  # the circumscribed one: every vertex outside
    assert not any(inside_exactly(v[None], (cx, cy), r) for v in out)


def door_scene(space, R, half, spare, offset, tol=1e-3, robot_disk=False):
    """A robot crossing between two round pillars of radius R (true gap = robot height + 2 spare)
    along y = offset[1]; robot: a box 2 half[0] x 2 half[1], or a disk of radius half[1]."""
    ox, oy = offset
    L = 2.0 * R + 4.0 * max(half)
    c = R + half[1] + spare
    robot = {"radius": half[1]} if robot_disk else {
        "polygon": [[-half[0], -half[1]], [half[0], -half[1]], [half[0], half[1]], [-half[0], half[1]]]}
    data = {"space": space, "disk_tolerance": tol,
            "bounds": {"xmin": ox - L, "xmax": ox + L, "ymin": oy - R / 2, "ymax": oy + R / 2},
            "robot": robot, "start": {"x": ox - L + 2 * max(half), "y": oy, "theta": 0.0},
            "goal": {"x": ox + L - 2 * max(half), "y": oy, "theta": 0.0},
            "obstacles": [{"center": [ox, oy + c], "radius": R}, {"center": [ox, oy - c], "radius": R}]}
    return scenario_from_dict(data, "door.toml")


def witness_clearance(sc, half, robot_disk) -> float:
    """Clearance of the straight translation at angle 0 from start to goal to the TRUE disks."""
    (x0, y0), (x1, _) = sc.start[:2], sc.goal[:2]
    line = shapely.LineString([(x0, y0), (x1, y0)])
    swept = line.buffer(half[1], cap_style="round") if robot_disk else \
        shapely.box(x0 - half[0], y0 - half[1], x1 + half[0], y0 + half[1])
    return min(shapely.distance(swept, shapely.Point(o.disk[:2])) - o.disk[2] for o in sc.obstacles)


DOORS = dict(R=st.floats(0.5, 30.0), w=st.floats(0.3, 2.0), h=st.floats(0.05, 0.5), spare=st.floats(1e-4, 0.02),
             exp=st.sampled_from([0.0, 1e3, 3e5, 1e6]), tol=st.sampled_from([1e-3, 1e-2]), disk=st.booleans())


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(**DOORS)
@example(R=10.0, w=0.8, h=0.3, spare=0.003, exp=0.0, tol=1e-3, disk=False)  # the issue's pillars
@example(R=10.0, w=0.3, h=0.3, spare=0.003, exp=0.0, tol=1e-3, disk=True)
def test_a_door_between_disks_with_a_witness_is_never_proven_unsolvable(R, w, h, spare, exp, tol, disk):
    half = (max(w, h), h)
    for space in ("se2", "translation"):
        sc = door_scene(space, R, half, spare * h, (exp, -exp), tol, disk)
        if witness_clearance(sc, half, disk) <= 0:  # rounding at the offset ate the spare: no witness
            return
        cs = build_cspace(sc)
        q = sc.all_queries()[0]
        if space == "se2":
            r = from_scenario(sc, possible_only=True, min_width=2 * math.pi / 32)
            assert r.status != "unsolvable"
            assert quick_proof(sc, cs, q, 10.0) is None
        else:
            assert separated_proof(sc, cs, q) is None
            assert not exact_plan(sc, cs, q, time_limit=10.0, progress=False).message.startswith("proven")


def test_the_circumscribed_proof_of_the_issue_is_refused_by_the_checker():
    """The issue's scene (a box between round pillars, 1 % to spare): the old proof, made of the
    circumscribed polygons, still comes out of a search given them as its inner pieces, and the
    checker, reasoning about the disks as written, refuses it."""
    sc = door_scene("se2", 10.0, (0.8, 0.3), 0.003, (0.0, 0.0))
    assert witness_clearance(sc, (0.8, 0.3), False) > 0.002
    cs = build_cspace(sc)
    q = sc.all_queries()[0]
    old = exact_se2_search(cs.obstacle_pieces, cs.body_pieces, sc.bounds, q.start, q.goal, possible_only=True)
    assert old.status == "unsolvable"
    verdict = check_proof(sc, old.proof)
    assert not verdict.valid and verdict.step == "regions"
    assert from_scenario(sc, possible_only=True, min_width=2 * math.pi / 32).status != "unsolvable"


@pytest.mark.parametrize("robot_disk", [False, True])
def test_a_closed_door_between_disks_is_proven_and_the_proof_checks(robot_disk):
    """Negative spare (the disks overlap the robot's way by more than their polygons' error): a proof,
    which the checker accepts; a disk robot's proof stores pieces inside the true disk."""
    half = (0.8, 0.3) if not robot_disk else (0.3, 0.3)
    sc = door_scene("se2", 10.0, half, -0.05, (0.0, 0.0), robot_disk=robot_disk)
    r = from_scenario(sc, time_limit=30.0)
    assert r.status == "unsolvable"
    if robot_disk:
        assert all(in_disk(p, (0.0, 0.0, 0.3)) for p in r.proof["robot_pieces"])
    v = check_proof(sc, r.proof)
    assert v.valid, v
    t = door_scene("translation", 10.0, half, -0.05, (0.0, 0.0), robot_disk=robot_disk)
    assert separated_proof(t, build_cspace(t), t.all_queries()[0]) is not None


def test_a_proof_with_the_circumscribed_disk_robot_is_refused():
    """The checker's robot step: a piece must lie inside the TRUE disk, not its polygon."""
    sc = door_scene("se2", 10.0, (0.3, 0.3), -0.05, (0.0, 0.0), robot_disk=True)
    r = from_scenario(sc, time_limit=30.0)
    bad = dict(r.proof, robot_pieces=[sc.robot[0].polygon.tolist()])
    v = check_proof(sc, bad)
    assert not v.valid and v.step == "robot"
