"""What a large map pays on first use rather than up front (issue 47, point 3): slabs whose
containment prune is skipped answer as pruned ones do; ``auto``'s first slice of sampling is
decided by its iterations, not by the slabs it builds; a Dubins car's ``auto`` samples before
it proves.
"""
from __future__ import annotations

import math
import time

import numpy as np
from hypothesis import given, settings, strategies as st

import planners
from cspace.io.load import scenario_from_dict
from cspace.se2.cspace import SE2CSpace
from cspace.translation.cspace import CSpace
from planners.core.auto import SLICE_ITERATIONS, sampling_slice

BAR = np.array([[-0.6, -0.15], [0.6, -0.15], [0.6, 0.15], [-0.6, 0.15]])


def _prune(cs) -> dict:
    return next(s for s in cs.report()["stages"] if s["stage"] == "prune")


@settings(max_examples=10, deadline=None)
@given(st.lists(st.tuples(st.floats(0.5, 8.5), st.floats(0.5, 8.5), st.floats(0.05, 1.5), st.floats(0.05, 1.5)),
                min_size=1, max_size=8), st.integers(0, 7))
def test_a_slab_without_the_containment_prune_answers_as_the_pruned_one(boxes, k):
    """Boxes (overlapping or not, some inside others) and one bar: wherever the obstacle pieces
    nest the slabs prune, elsewhere they skip it; either way every point of a grid, and every
    vertex of the slab's pieces, gets the answer of the slab's C-space built with the prune."""
    obstacles = [np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]]) for x, y, w, h in boxes]
    cs = SE2CSpace((0, 10, 0, 10), obstacles, [BAR], slabs=8)
    slab = cs.slab(k)
    pruned = CSpace(cs.bounds, cs.obstacle_pieces, slab.robot_pieces, normalized=True)
    pts = [(x, y) for x in np.linspace(0, 10, 41) for y in np.linspace(0, 10, 41)]
    pts += [tuple(v) for p in pruned.pieces for v in p if 0 <= v[0] <= 10 and 0 <= v[1] <= 10]
    assert [slab.is_free(p) for p in pts] == [pruned.is_free(p) for p in pts]
    if _prune(pruned)["inside_another"]:  # sums that nest: the slab found them too
        assert _prune(slab)["inside_another"] == _prune(pruned)["inside_another"]


def test_nested_obstacle_pieces_keep_the_prune_and_apart_ones_skip_it():
    big, small = np.array([[2., 2], [6, 2], [6, 6], [2, 6]]), np.array([[3., 3], [4, 3], [4, 4], [3, 4]])
    nested = SE2CSpace((0, 10, 0, 10), [big, small], [BAR], slabs=8)
    assert _prune(nested.slab(0))["inside_another"] == 1
    apart = SE2CSpace((0, 10, 0, 10), [big, small + 5], [BAR], slabs=8)
    assert _prune(apart.slab(0))["inside_another"] == 0 and len(apart.slab(0).pieces) == 2


class _Built:
    """A C-space whose slabs the fake sampler builds."""

    def __init__(self):
        self.n = 0

    def slabs_built(self):
        return self.n, 0.0


class _Clock:
    def left(self) -> float:
        return 10.0


class _Unsolved:
    solved = False


def test_a_slice_out_of_time_while_it_built_slabs_runs_again_until_none_is_built():
    cs, calls = _Built(), []

    def sample(budget, iterations):
        calls.append(iterations)
        time.sleep(budget)  # its whole time ...
        if len(calls) <= 2:
            cs.n += 3  # ... spent building slabs on the first two turns
        return _Unsolved()

    sampling_slice(sample, cs, _Clock(), 0.1)
    assert calls == [SLICE_ITERATIONS] * 3


def test_a_slice_that_ends_on_its_iterations_is_not_run_again():
    cs, calls = _Built(), []

    def sample(budget, iterations):
        calls.append(iterations)
        cs.n += 3  # builds slabs, but returns at once: its iterations ended it
        return _Unsolved()

    sampling_slice(sample, cs, _Clock(), 100.0)
    assert calls == [SLICE_ITERATIONS]


def test_a_dubins_car_on_an_open_scene_is_answered_by_the_slice_before_any_proof():
    """(Before, a Dubins car's auto began with the proof: on a large map, seconds of regions per query.)"""
    sc = scenario_from_dict({"name": "open", "space": "dubins", "turning_radius": 0.5,
                             "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
                             "robot": {"polygon": BAR.tolist()},
                             "start": {"x": 2.0, "y": 2.0, "theta": 0.0}, "goal": {"x": 8.0, "y": 8.0, "theta": 1.0},
                             "obstacles": [{"polygon": [[4.5, 4.5], [5.5, 4.5], [5.5, 5.5], [4.5, 5.5]]}]})
    res = planners.plan(sc, seed=1)
    assert res.planner == "auto" and res.solved and res.answered_by == "sampling", res.message
    assert res.stages[-1] == "sampling" and "proof" not in res.stages and math.isfinite(res.timings["sampling"])
