"""The proof before sampling on a C-space that serves many queries (issue 47, point 3): what
depends on the map alone (POSSIBLE regions, their graph's labelled components) is built once and
kept; a query only looks up its start and goal, and answers exactly as the uncached search does.
The clearance measures ask only the obstacle pieces near the path, with the same bound."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings, strategies as st

from cspace.car.clearance import car_path_clearance
from cspace.car.curves import reeds_shepp_segments
from cspace.io.load import load_scenario
from cspace.io.scenario.schema import Query
from cspace.se2 import clearance as se2_clearance
from cspace.se2.exact import ANGLE_NEAR, NO_PROOF_FOUND, exact_se2_search, initial_partition
from cspace.se2.possible_joins import PossibleJoins, proof_partitions
from cspace.se2.slab_graph import SlabRegions
from cspace.translation.clearance import Nearest
from planners.core import exact_se2
from planners.core.plan import build_cspace

ROOT = os.path.join(os.path.dirname(__file__), "..", "..", "scenarios")


def rect(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def uncached(obstacles, robot, bounds, start, goal) -> str:
    """The proof-only search of the proof before sampling, on fresh regions: "proof" or "none"."""
    r = exact_se2_search(obstacles, robot, bounds, start, goal, possible_only=True, min_width=exact_se2.QUICK_WIDTH)
    assert r.status == "unsolvable" or r.stats.get("reason") == NO_PROOF_FOUND
    return "proof" if r.status == "unsolvable" else "none"


def joined(obstacles, robot, bounds, start, goal) -> bool:
    regions = SlabRegions(obstacles, robot, bounds)
    parts = proof_partitions(initial_partition(), exact_se2.QUICK_WIDTH)
    return all(PossibleJoins(regions, p, ANGLE_NEAR).joined(start, goal) for p in parts)


def test_partitions_are_the_searchs():
    """The partitions labelled are the ones the proof-only search tries, to its last."""
    wall = [rect(4, 0, 5, 10)]
    bar = [rect(-0.5, -0.1, 0.5, 0.1)]
    r = exact_se2_search(wall, bar, (0, 10, 0, 10), (1, 1, 0.0), (2, 8, 1.0), possible_only=True,
                         min_width=exact_se2.QUICK_WIDTH)
    parts = proof_partitions(initial_partition(), exact_se2.QUICK_WIDTH)
    assert [list(map(list, p)) for p in parts[-1:]] == [r.stats["partition"]]
    assert len(parts) == r.stats["refinements"] + 1


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(length=st.floats(0.4, 2.6), width=st.floats(0.15, 0.7), gap_y=st.floats(1.0, 5.0), gap=st.floats(0.2, 1.8),
       thick=st.floats(0.1, 1.0), box=st.tuples(st.floats(0.5, 5.0), st.floats(0.5, 5.0), st.floats(0.2, 1.2)),
       ts=st.floats(-math.pi, math.pi), tg=st.floats(-math.pi, math.pi), gy=st.floats(0.5, 5.5))
def test_lookup_agrees_with_the_uncached_search(length, width, gap_y, gap, thick, box, ts, tg, gy):
    """Random walls with a door, a box and a bar: "joined at every partition" exactly where the
    uncached search ends without a proof (and so a proof exactly where it separates them)."""
    bounds = (0.0, 6.0, 0.0, 6.0)
    robot = [rect(-length / 2, -width / 2, length / 2, width / 2)]
    x0, x1 = 3.0 - thick / 2, 3.0 + thick / 2
    bx, by, bs = box
    obstacles = [rect(x0, -1.0, x1, gap_y), rect(x0, gap_y + gap, x1, 7.0), rect(bx, by, bx + bs, by + bs)]
    start, goal = (1.0, 3.0, ts), (5.0, gy, tg)
    shp = [shapely.Polygon(o) for o in obstacles]
    for x, y, t in (start, goal):
        c, s = math.cos(t), math.sin(t)
        placed = shapely.Polygon(robot[0] @ np.array([[c, s], [-s, c]]) + (x, y))
        assume(not any(placed.intersects(o) for o in shp))
    expect = uncached(obstacles, robot, bounds, start, goal)
    assert joined(obstacles, robot, bounds, start, goal) == (expect == "none")


def test_scene_queries_agree_and_a_proof_is_still_the_searchs():
    """Bundled scenes, both answers: the lookup agrees with the uncached search, and quick_proof on a
    prepared C-space returns the search's proof where it separates start and goal."""
    seen = set()
    for name in ("door_tight.toml", "bug_trap.toml", "plank_corner_tight.toml", "wide_square.toml"):
        sc = load_scenario(os.path.join(ROOT, "se2", name))
        cs = build_cspace(sc)
        exact_se2.prepare(cs)
        q = sc.all_queries()[0]
        want = uncached(cs.obstacle_pieces, cs.body_pieces, cs.bounds, q.start, q.goal)
        got = exact_se2.quick_proof(sc, cs, q, 10.0)
        assert (got is not None) == (want == "proof")
        if got is not None:
            assert got.proof["format"] == "cspace-se2-proof/1"
        seen.add(want)
    assert seen == {"proof", "none"}  # both kinds of answer were tried


def test_second_query_reuses_the_maps_structures():
    """Prepared once: later queries build no region, no link and no labelling (counted, not timed)."""
    sc = load_scenario(os.path.join(ROOT, "se2", "wide_square.toml"))
    cs = build_cspace(sc)
    exact_se2.prepare(cs)
    regions = exact_se2._regions_of(cs)
    joins = exact_se2.proof_joins(cs, build=False)
    assert joins and all(j.builds == 1 for j in joins)
    before = dict(regions.counts)
    rng = np.random.default_rng(5)
    xmin, xmax, ymin, ymax = sc.bounds
    asked = 0
    while asked < 6:
        s = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        g = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if not (cs.is_free(s) and cs.is_free(g)):
            continue
        res = exact_se2.quick_proof(sc, cs, Query(start=s, goal=g), 10.0)
        asked += 1
        if res is None:  # answered by the lookups: nothing of the map built again
            assert regions.counts == before
    assert exact_se2.proof_joins(cs, build=False) is joins


def test_an_unprepared_cspace_labels_after_its_first_complete_search():
    sc = load_scenario(os.path.join(ROOT, "se2", "wide_square.toml"))
    cs = build_cspace(sc)
    q = sc.all_queries()[0]
    assert exact_se2.proof_joins(cs, build=False) == []
    if exact_se2.quick_proof(sc, cs, q, 10.0) is None:
        assert exact_se2.proof_joins(cs, build=False)


# ---------------------------------------------------------------- clearance near the path

def far_map(rng, n=60):
    """Small boxes scattered over a 100 m square, the path's neighbourhood among them."""
    out = []
    for _ in range(n):
        x, y = rng.uniform(0, 95, size=2)
        w, h = rng.uniform(0.2, 2.0, size=2)
        out.append(rect(x, y, x + w, y + h))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_se2_clearance_near_the_path_is_the_same_bound(seed, monkeypatch):
    """Only the pieces near the path are asked: the bound is the one over every piece, to the bit."""
    rng = np.random.default_rng(seed)
    obstacles = far_map(rng)
    robot = [rect(-0.3, -0.25, 0.3, 0.25)]
    path = np.array([[50.0, 50.0, 0.0], [53.0, 51.0, 1.0], [55.0, 49.0, -2.0]])
    path[:, :2] += rng.uniform(-20, 20, size=2)
    near = se2_clearance.se2_path_clearance(path, robot, obstacles, nearest=Nearest(obstacles))
    monkeypatch.setattr(se2_clearance, "near_path", lambda obs, poses, rob: [obs] * max(1, len(poses) - 1))
    every = se2_clearance.se2_path_clearance(path, robot, obstacles)
    assert near == every


@pytest.mark.parametrize("seed", range(4))
def test_car_clearance_near_the_curves_is_a_lower_bound_within_tol(seed, monkeypatch):
    """A car's bound near its curves: never above the distance at dense placements, and within the
    measure's tolerance of the bound over every piece."""
    import cspace.car.clearance as car_clearance

    rng = np.random.default_rng(seed)
    obstacles = far_map(rng, 80)
    robot = [rect(-0.3, -0.25, 0.3, 0.25)]
    r = 0.4
    path = np.array([[50.0, 50.0, 0.0], [52.0, 51.0, 1.5], [53.0, 49.0, -2.5]])
    path[:, :2] += rng.uniform(-20, 20, size=2)

    def segs(a, b):
        return reeds_shepp_segments(a, b, r)

    near = car_path_clearance(path, segs, r, robot, obstacles, nearest=Nearest(obstacles))
    monkeypatch.setattr(car_clearance, "near_curves", lambda obs, parts, *a: [obs] * len(parts))
    every = car_path_clearance(path, segs, r, robot, obstacles)
    tol = car_clearance.TOL * max(r, 0.4)
    assert abs(near.distance - every.distance) <= tol
    # the true clearance at dense placements along the curves is never below the bound
    from cspace.car.curves import advance, knots

    union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
    for a, b in zip(path[:-1], path[1:]):
        sg = [s for s in segs(tuple(a), tuple(b)) if s[1] != 0.0]
        for (kind, length), k0 in zip(sg, knots(tuple(a), sg, r)):
            for f in np.linspace(0.0, 1.0, 40):
                x, y, th = advance(k0, kind, f * length, r)
                c, s = math.cos(th), math.sin(th)
                placed = shapely.Polygon(robot[0] @ np.array([[c, s], [-s, c]]) + (x, y))
                assert near.distance <= placed.distance(union) + 1e-9


@pytest.mark.parametrize("kind,length,wall_y", [("L", 1.2, 1.3), ("R", -0.9, -1.1), ("L", -2.0, 1.1), ("R", 2.5, 0.3)])
def test_car_arc_bound_is_sound_and_tight(kind, length, wall_y):
    """One arc beside a wall: the bound is never above the distance at 2000 placements along it,
    and within the tolerance (plus the placements' spacing) of their least."""
    from cspace.car.curves import advance
    import cspace.car.clearance as car_clearance

    r = 0.8
    robot = [rect(-0.3, -0.25, 0.3, 0.25)]
    wall = [rect(-3, wall_y, 3, wall_y + 0.5)] if wall_y > 0 else [rect(-3, wall_y - 0.5, 3, wall_y)]
    start = (0.0, 0.0, 0.3)
    end = advance(start, kind, length, r)
    path = np.array([start, end])

    def segs(a, b):
        return [(kind, length)] if tuple(a) == start else []

    c = car_path_clearance(path, segs, r, robot, wall)
    union = shapely.Polygon(wall[0])
    dense = math.inf
    for f in np.linspace(0.0, 1.0, 2001):
        x, y, th = advance(start, kind, f * length, r)
        cs, sn = math.cos(th), math.sin(th)
        dense = min(dense, shapely.Polygon(robot[0] @ np.array([[cs, sn], [-sn, cs]]) + (x, y)).distance(union))
    lip = 1.0 + 0.4 / r
    assert c.distance <= dense + 1e-9
    assert dense - c.distance <= car_clearance.TOL * r + lip * abs(length) / 2000


def test_the_bench_warms_the_proof_for_its_forked_runs():
    """cspace bench forks its runs from one held C-space: the proof before sampling's structures are
    built there once (their work in a child would be lost when it exits)."""
    from planners.bench.reference import warmed

    for name in ("se2/wide_square.toml", "car/" + sorted(os.listdir(os.path.join(ROOT, "car")))[0]):
        sc = load_scenario(os.path.join(ROOT, name))
        cs, _ = warmed(sc)
        assert exact_se2.proof_joins(cs, build=False)
