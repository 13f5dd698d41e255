"""A car's lattice of short certified moves (cspace.car.lattice): every pose it returns is truly
reachable (a chain of moves from the seed that the independent sweep, scripts/sweep_oracle.py,
passes), it is breadth first and bounded by its cap, and it tells a boxed-in end from an open one
on scenes whose answer is known by geometry (a car facing a wall it cannot turn away from)."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from car_scenes import FACING, RADIUS, wall_scene
from conftest import load_script
from cspace.car.curves import advance
from cspace.car.lattice import STEP, boxed_in, lattice_reach
from cspace.car.motion import as_car
from planners.core.plan import build_cspace

oracle = load_script("sweep_oracle")


def chains_pass_the_sweep(sc, poses, backward: bool) -> int:
    """Each pose after the seed is one move from an earlier one (the same doubles), and that move
    passes the independent sweep; the number of moves checked."""
    length = (-STEP if backward else STEP) * RADIUS
    made = {}
    for p in poses:
        for kind in "LSR":
            made.setdefault(advance(p, kind, length, RADIUS), (p, kind))
    for q in poses[1:]:
        p, kind = made[q]
        assert poses.index(p) < poses.index(q)  # breadth first: the parent came first
        judged = oracle.car_sweep_check(sc, [p, q], lambda a, b: [(kind, length)], RADIUS)
        assert not judged["collides"] and not judged["out_of_bounds"], (p, kind, judged)
    return len(poses) - 1


@pytest.mark.parametrize("d, backward", [(1.5, False), (1.7, False), (1.7, True)])
def test_every_pose_is_reached_by_moves_the_independent_sweep_passes(d, backward):
    sc = wall_scene(d)
    car = as_car(build_cspace(sc))
    poses = lattice_reach(car, FACING, RADIUS, backward=backward, cap=80)
    assert poses[0] == FACING and len(set(poses)) == len(poses)
    assert chains_pass_the_sweep(sc, poses, backward) == len(poses) - 1 > 0


@pytest.mark.parametrize("d, boxed", [(1.5, True), (1.58, True), (1.75, False)])
def test_a_car_facing_a_wall_is_boxed_in_only_where_it_cannot_turn_away(d, boxed):
    car = as_car(build_cspace(wall_scene(d)))
    assert boxed_in(car, FACING, RADIUS, cap=300) is boxed
    assert not boxed_in(car, FACING, RADIUS, backward=True, cap=300)  # behind it: the open room


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.floats(1.3, 2.5), st.integers(1, 120), st.booleans())
def test_the_cap_bounds_the_poses_and_a_smaller_cap_returns_a_prefix(d, cap, backward):
    car = as_car(build_cspace(wall_scene(d)))
    full = lattice_reach(car, FACING, RADIUS, backward=backward, cap=cap)
    assert 1 <= len(full) <= cap
    assert lattice_reach(car, FACING, RADIUS, backward=backward, cap=max(1, cap // 2)) == full[:max(1, cap // 2)]
