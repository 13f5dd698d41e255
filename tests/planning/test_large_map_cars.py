"""A car on a large map (issue 47, the warehouse's Reeds–Shepp queries): the slab graph's path
turns where it is, not at the one link point kept per pair of components (on a large map a
hundred metres away); a search asking for room shares the body's POSSIBLE regions; the
preparation of a C-space for many queries changes no answer. Every path is judged by the
independent sweep (scripts/sweep_oracle.py, shapely), not by the C-space that certified it.
"""
from __future__ import annotations

import dataclasses
import math
import os

import numpy as np
import pytest

import planners
from conftest import SCENARIOS, load_script
from cspace.io.load import load_scenario, scenario_from_dict
from cspace.se2.exact import exact_se2_search
from cspace.se2.slab_graph import SlabRegions

oracle = load_script("sweep_oracle")
BAR = [[-0.6, -0.15], [0.6, -0.15], [0.6, 0.15], [-0.6, 0.15]]
POSTS = [[[20.0, 20.0], [22.0, 20.0], [22.0, 22.0], [20.0, 22.0]], [[70.0, 60.0], [73.0, 60.0], [73.0, 64.0], [70.0, 64.0]],
         [[6.2, 3.5], [6.8, 3.5], [6.8, 6.5], [6.2, 6.5]]]  # (the last between the test's start and goal)


def _open_map(start, goal) -> object:
    """A 100 m square with two posts, a bar robot: the overlap of two neighbouring slabs' FREE is
    most of the map, so the link point kept for the pair is near its middle."""
    return scenario_from_dict({"name": "open", "space": "se2", "bounds": {"xmin": 0, "xmax": 100, "ymin": 0, "ymax": 100},
                               "robot": {"polygon": BAR}, "obstacles": [{"polygon": p} for p in POSTS],
                               "start": dict(zip(("x", "y", "theta"), start)),
                               "goal": dict(zip(("x", "y", "theta"), goal))})


def _length(path) -> float:
    return float(np.hypot(*np.diff(np.asarray(path)[:, :2], axis=0).T).sum())


def test_a_walk_turns_where_it_is_not_at_the_far_link_point():
    """... and its short translation round the post between start and goal is searched in a
    window round them: the path still passes the independent sweep."""
    start, goal = (5.0, 5.0, 0.0), (8.0, 5.0, 2.5)  # 3 m apart, a turn through three slabs, a post between
    sc = _open_map(start, goal)
    pieces = [np.array(p, dtype=float) for p in POSTS]
    far = exact_se2_search(pieces, [np.array(BAR)], (0, 100, 0, 100), start, goal)
    near = exact_se2_search(pieces, [np.array(BAR)], (0, 100, 0, 100), start, goal, near=True)
    assert far.status == near.status == "solved"
    for r in (far, near):
        j = oracle.sweep_check(sc, r.path)
        assert not j["collides"] and not j["out_of_bounds"]
        assert tuple(r.path[0]) == start and tuple(r.path[-1][:2]) == goal[:2]
    assert _length(far.path) > 50.0  # (the test is not blind: the kept points are mid-map)
    assert _length(near.path) < 4 * math.dist(start[:2], goal[:2])
    assert not (near.path[:, 1] == 5.0).all()  # (it went round the post)


def test_the_kept_point_stays_where_no_overlap_is_near():
    wall = np.array([[4.0, 0.0], [5.0, 0.0], [5.0, 10.0], [4.0, 10.0]])
    sr = SlabRegions([wall], [np.array([[0.0, 0.0], [0.2, 0.0], [0.0, 0.2]])], (0, 10, 0, 10))
    f1, f2 = sr.free(0.0, 0.5), sr.free(0.5, 1.0)
    right = [i for i, c in enumerate(f1.components) if c.bounds[0] > 4.5]
    left = [j for j, c in enumerate(f2.components) if c.bounds[2] < 4.5]
    assert right and left and sr.link_near(f1, right[0], f2, left[0], 4.5, 5.0) is None  # they do not overlap
    x, y = sr.link_near(f1, right[0], f2, [j for j in range(len(f2.components)) if j not in left][0], 9.0, 9.0)
    assert (x, y) == (9.0, 9.0) and sr.pose_free(x, y, 0.0) and sr.pose_free(x, y, 1.0)


def test_a_search_with_room_reads_the_body_s_possible_regions():
    from planners.core.exact_se2 import slab_regions_of
    from planners.core.plan import build_cspace

    sc = load_scenario(os.path.join(SCENARIOS, "car", "parallel_tight.toml"))
    cs = build_cspace(sc)
    body, roomy = slab_regions_of(cs), slab_regions_of(cs, 0.01)
    assert roomy.possible(0.0, 0.5) is body.possible(0.0, 0.5)
    assert roomy.free(0.0, 0.5) is not body.free(0.0, 0.5)
    other = SlabRegions(body.obstacles, [p * 0.5 for p in body.robot], body.bounds)
    assert not other.share_possible(body)  # another body: POSSIBLE differs, nothing shared


@pytest.mark.slow  # (several seconds: the sweep along the curves)
def test_a_car_s_slab_graph_path_with_room_passes_the_sweep():
    """FREE with room is built without the union's check and the walk's links are moved: the
    path is still certified curve by curve, and the independent sweep along the curves agrees."""
    from cspace.car.curves import reeds_shepp_segments

    sc = load_scenario(os.path.join(SCENARIOS, "car", "parallel_tight.toml"))
    r = planners.plan(sc, seed=0, time=20.0)
    assert r.solved and r.answered_by == "slab graph", r.message
    assert tuple(r.path[0]) == tuple(r.start) and tuple(r.path[-1]) == tuple(r.goal)
    j = oracle.car_sweep_check(sc, r.path, lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius),
                               sc.turning_radius)
    assert not j["collides"] and not j["out_of_bounds"]


@pytest.mark.slow  # (about 1 s: the scene planned twice)
def test_preparing_a_c_space_changes_no_answer():
    from planners.core.auto import prepare
    from planners.core.plan import build_cspace

    sc = load_scenario(os.path.join(SCENARIOS, "car", "parallel_tight.toml"))
    plain, ready = build_cspace(sc), build_cspace(sc)
    assert prepare(sc, ready) > 0.0
    a = planners.plan(sc, seed=3, time=20.0, cspace=plain)
    b = planners.plan(dataclasses.replace(sc), seed=3, time=20.0, cspace=ready)
    assert a.solved and b.solved and a.answered_by == b.answered_by == "slab graph"
    assert np.array_equal(a.path, b.path)


def _door_car():
    """A Reeds–Shepp car (a 1 x 0.5 box) at heading 0.3 either side of a wall's 0.6 door: no 45°
    slab passes it, the heading 0, a slab boundary, does."""
    wall = [[[-0.1, 0.3], [0.1, 0.3], [0.1, 3], [-0.1, 3]], [[-0.1, -3], [0.1, -3], [0.1, -0.3], [-0.1, -0.3]]]
    return scenario_from_dict({"space": "reeds-shepp", "turning_radius": 0.5,
                               "bounds": {"xmin": -4, "xmax": 4, "ymin": -3, "ymax": 3},
                               "robot": {"polygon": [[-0.5, -0.25], [0.5, -0.25], [0.5, 0.25], [-0.5, 0.25]]},
                               "start": {"x": -2.5, "y": 0.0, "theta": 0.3}, "goal": {"x": 2.5, "y": 0.0, "theta": 0.3},
                               "obstacles": [{"polygon": p} for p in wall]}, "door.toml")


def test_preparing_builds_the_halves_a_first_refinement_reads(monkeypatch):
    """A Reeds–Shepp car's preparation builds FREE (with the first room) at the first 8 slabs and
    at their halves: a door that no 45° slab passes makes the search bisect every slab once, and
    each half it then reads was built by the preparation (the same floats: one bisection,
    :func:`cspace.se2.critical.bisected`), none anew but the start's and goal's own angle."""
    from cspace.se2 import exact
    from planners.core.auto import ROOMS, prepare
    from planners.core.exact_se2 import search, slab_regions_of
    from planners.core.plan import build_cspace

    sc = _door_car()
    cs = build_cspace(sc)
    prepare(sc, cs)
    room = ROOMS[0] * max(float(np.hypot(*p.T).max()) for p in cs.body_pieces)
    regions = slab_regions_of(cs, room)
    prepared, built = set(regions._free), regions.counts["free_built"]
    split, halves = exact._Search._split, []

    def split_once(self, which):  # every slab halved once, then no more
        if self.refinements:
            return False
        done = split(self, set(range(len(self.part))))
        halves.extend(self.part)
        return done

    monkeypatch.setattr(exact._Search, "_split", split_once)
    search(cs, sc.all_queries()[0], 30.0, refine=True, room=room, near=True)
    assert len(halves) == 16 and set(halves) <= prepared
    assert regions.counts["free_built"] - built == 1  # FREE at θ = 0.3, the start's and goal's


def test_a_reeds_shepp_car_on_a_large_map_goes_from_its_slice_to_the_refinement(monkeypatch):
    """Where the car's own RRT-Connect does not run (a large map) and OMPL's slice failed, no second
    turn of sampling comes before the refinement (on the warehouse map it cost the queries through
    a door 50 ms and answered few): the refinement answers, its path passes the sweep."""
    import planners.core.auto as auto
    import planners.core.routine as routine
    from cspace.car.curves import reeds_shepp_segments

    sc = _door_car()
    seeds = []
    real = routine.run_planner
    monkeypatch.setattr(routine, "run_planner", lambda *a, **k: seeds.append(a[4]) or real(*a, **k))
    monkeypatch.setattr(auto, "direct_curve", lambda *a, **k: None)  # (here the one curve is free)
    monkeypatch.setattr(auto, "connect_slice", lambda *a, **k: None)  # as on a large map
    monkeypatch.setattr(auto, "SLICE_ITERATIONS", 2)  # a slice that cannot answer
    res = planners.plan(sc, seed=3, time=60.0)
    assert res.solved and res.answered_by == "refinement", res.message
    assert seeds == [3], seeds  # the slice alone: no turn (its seed would be auto.turn_seed(3, 1))
    j = oracle.car_sweep_check(sc, res.path, lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius),
                               sc.turning_radius)
    assert not j["collides"] and not j["out_of_bounds"]
