"""Doors just wider (or narrower) than the robot (issue 49, point 5): zero-width slabs at the
critical angles decide them; paths are judged by the independent sweep, proofs by check-proof."""
from __future__ import annotations

import math
import random

import pytest

from conftest import load_script
from cspace.io.load import scenario_from_dict
from cspace.se2.critical import critical_angles, with_zero_slabs  # noqa: F401
from cspace.se2.exact import from_scenario
from planners.core.proof_check import check_proof

oracle = load_script("sweep_oracle")


def door(seed: int, spare: float):
    rng = random.Random(seed)
    L, W = rng.uniform(1.2, 2.5), rng.uniform(0.3, 0.7)
    d, y0 = (1 + spare) * W, rng.uniform(-1.5, 1.5)
    return scenario_from_dict({
        "space": "se2", "bounds": {"xmin": -4, "xmax": 4, "ymin": -3, "ymax": 3},
        "robot": {"polygon": [[-L / 2, -W / 2], [L / 2, -W / 2], [L / 2, W / 2], [-L / 2, W / 2]]},
        "start": {"x": -2.5, "y": rng.uniform(-1, 1), "theta": rng.uniform(-math.pi, math.pi)},
        "goal": {"x": 2.5, "y": rng.uniform(-1, 1), "theta": rng.uniform(-math.pi, math.pi)},
        "obstacles": [{"polygon": [[-0.1, -5], [0.1, -5], [0.1, y0 - d / 2], [-0.1, y0 - d / 2]]},
                      {"polygon": [[-0.1, y0 + d / 2], [0.1, y0 + d / 2], [0.1, 5], [-0.1, 5]]}]}, "door.toml")


@pytest.mark.parametrize("seed, spare", [(0, 0.003), (1, 0.003), (2, 0.001), (3, 0.001)])
def test_a_door_just_wider_than_the_robot_is_solved_with_a_clean_path(seed, spare):
    sc = door(seed, spare)
    r = from_scenario(sc)  # no time limit: the result does not depend on the machine
    assert r.status == "solved", r.stats.get("statement")
    j = oracle.sweep_check(sc, r.path)
    assert not j["collides"] and not j["out_of_bounds"]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_door_just_narrower_is_proven_and_the_proof_checks(seed):
    sc = door(seed, -0.004)
    r = from_scenario(sc)
    assert r.status == "unsolvable"
    v = check_proof(sc, r.proof)
    assert v.valid, v


@pytest.mark.parametrize("gap", [0.3, 0.7])
def test_proofs_with_zero_width_slabs_check(gap):
    """A bar shut in a room (the door in its ceiling too narrow to turn through) is proven after a
    refinement, with the critical angles' zero-width slabs in the partition; check-proof accepts
    them (a single angle: a path crossing it lies in it and in both neighbours)."""
    import sys
    import os

    sys.path.insert(0, os.path.dirname(__file__))
    from test_proof_scales import closed_room

    sc = closed_room((0.0, 0.0), 1.0, 3.0, gap)
    r = from_scenario(sc)
    assert r.status == "unsolvable" and any(s["a"] == s["b"] for s in r.proof["slabs"])
    v = check_proof(sc, r.proof)
    assert v.valid, v


def test_a_corridor_across_the_seam_is_solved():
    """A bar in a corridor 0.5 % wider than it, pointing just below π at the start and just above −π
    at the goal: the one way is to turn through ±π and slide; the zero-width slab at π holds it."""
    L, W, spare, eps = 2.0, 0.4, 0.005, 2e-4
    d = W * (1 + spare)
    sc = scenario_from_dict({
        "space": "se2", "bounds": {"xmin": 1.5, "xmax": 8.5, "ymin": 0.0, "ymax": 0.0 + 1e-3},
        "robot": {"polygon": [[-L / 2, -W / 2], [L / 2, -W / 2], [L / 2, W / 2], [-L / 2, W / 2]]},
        "start": {"x": 2.0, "y": 0.0, "theta": math.pi - eps}, "goal": {"x": 8.0, "y": 0.0, "theta": -math.pi + eps},
        "obstacles": [{"polygon": [[0, -3], [10, -3], [10, -d / 2], [0, -d / 2]]},
                      {"polygon": [[0, d / 2], [10, d / 2], [10, 3], [0, 3]]}]}, "seam.toml")
    r = from_scenario(sc)
    assert r.status == "solved", r.stats.get("statement")
    assert r.rotation < 0.01  # through the seam, not the long way round
    j = oracle.sweep_check(sc, r.path)
    assert not j["collides"] and not j["out_of_bounds"]
