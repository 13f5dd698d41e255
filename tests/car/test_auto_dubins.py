"""``auto``'s stages for a Dubins car after its slice (planners/core/auto_dubins.py): restarts of
sampling at a shorter range, counted in iterations that double, each with samples of its own;
the reach proof and the SE(2) proof between them, run even when the caller's iterations run out.
Paths pass the independent sweep (scripts/sweep_oracle.py); proofs pass check-proof's checker."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest

import planners
from car_scenes import wall_scene
from conftest import SCENARIOS, load_script
from cspace.car.curves import dubins_segments
from cspace.io.load import load_scenario, scenario_from_dict
from planners.core import auto, auto_dubins
from planners.core.dubins_check import check_dubins_proof
from planners.core.plan import build_cspace, make_adapter

oracle = load_script("sweep_oracle")
MAZE = os.path.join(SCENARIOS, "car", "maze.toml")  # a Dubins car through a serpentine maze


def _hall(side: float = 100.0, radius: float = 0.5):
    """An empty square hall ``side`` wide, a small Dubins car: a scene of 200 turning radii."""
    return scenario_from_dict({
        "space": "dubins", "turning_radius": radius,
        "bounds": {"xmin": 0, "xmax": side, "ymin": 0, "ymax": side},
        "robot": {"polygon": [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]},
        "obstacles": [{"polygon": [[40, 40], [60, 40], [60, 60], [40, 60]]}],
        "start": {"x": 10, "y": 10, "theta": 0}, "goal": {"x": 90, "y": 90, "theta": 0}}, "hall")


def _range(adapter) -> float:
    """The range RRTConnect is given on this adapter (OMPL's units)."""
    from planners.adapters.glue import make_setup

    ss = make_setup(adapter, "RRTConnect", 0)[0]
    return ss.getPlanner().getRange()


def _own(adapter) -> float:
    """OMPL's own range on this adapter's space (a fifth of its extent)."""
    from planners.adapters.glue import RANGE_SHARE, make_setup

    return RANGE_SHARE * make_setup(adapter, "RRTConnect", 0)[0].getSpaceInformation().getMaximumExtent()


def test_with_range_sets_the_restart_range_below_the_usual_floor_and_restores_it():
    from planners.adapters.glue import RANGE_FLOOR

    sc = _hall()
    adapter = make_adapter(sc, build_cspace(sc))
    usual, cap, own = _range(adapter), adapter.max_range, _own(adapter)
    short = max(math.ldexp(auto_dubins.RESTART_RADII * adapter.radius, adapter.k), auto_dubins.RESTART_FLOOR * own)
    assert short < 0.6 * RANGE_FLOOR * own < usual  # the usual floor (a quarter of OMPL's range) would not allow it
    assert auto_dubins.with_range(adapter, auto_dubins.RESTART_RADII, lambda: _range(adapter)) == pytest.approx(short)
    assert adapter.max_range == cap and not hasattr(adapter, "range_floor") and _range(adapter) == usual
    with pytest.raises(RuntimeError):  # restored when the call fails too
        auto_dubins.with_range(adapter, 3.0, lambda: (_ for _ in ()).throw(RuntimeError("boom")))
    assert adapter.max_range == cap and not hasattr(adapter, "range_floor")


def _record(monkeypatch) -> list:
    """(seed, iterations, range) of every sampling run ``auto`` asks for, in order."""
    import planners.core.routine as routine

    seen = []
    real = routine.run_planner

    def spy(adapter, *a, **k):
        seen.append((a[3], k.get("iterations"), adapter.max_range))
        return real(adapter, *a, **k)

    monkeypatch.setattr(routine, "run_planner", spy)
    return seen


def _restarted(monkeypatch, runs: int):
    """The maze planned ``runs`` times (seed 5) with a slice made to fail (2 iterations) and short
    restarts (50 iterations at first), the proofs put off: (scenario, results, runs' records)."""
    seen = _record(monkeypatch)
    monkeypatch.setattr(auto, "SLICE_ITERATIONS", 2)
    monkeypatch.setattr(auto_dubins, "FIRST_RESTART", 50)  # short restarts: several of them run
    monkeypatch.setattr(auto_dubins, "REACH_AFTER", 98)  # (the proofs: the last test)
    monkeypatch.setattr(auto_dubins, "QUICK_AFTER", 99)
    sc = load_scenario(MAZE)
    cs = build_cspace(sc)
    out, records = [], []
    for _ in range(runs):
        seen.clear()
        out.append(planners.plan(sc, cspace=cs, seed=5, time=1000.0))
        records.append(list(seen))
    return sc, out, records


def test_after_a_failed_slice_a_dubins_car_restarts_at_a_shorter_range_with_doubling_counts(monkeypatch):
    # The restarts after the slice each draw their own samples (turn seeds 3, 4, ...), count 50,
    # 100, ... iterations (not time: the same answer on every machine) at 7 turning radii, not the
    # slice's 20; the same seed gives the same path.
    _, results, records = _restarted(monkeypatch, 2)
    for res, seen in zip(results, records):
        assert res.solved and res.answered_by == "sampling" and res.seed == 5, res.message
        first, rest = seen[0], seen[1:]
        assert first[:2] == (5, 2) and len(rest) >= 2, seen
        assert [s for s, _, _ in rest] == [auto.turn_seed(5, t) for t in range(3, 3 + len(rest))]
        assert [n for _, n, _ in rest] == [50 * 2 ** i for i in range(len(rest))]
        short = [m for _, _, m in rest]
        assert all(m == short[0] < first[2] for m in short), seen
    assert np.array_equal(results[0].path, results[1].path)


@pytest.mark.slow
def test_a_restart_s_path_passes_the_independent_sweep(monkeypatch):
    sc, (res,), _ = _restarted(monkeypatch, 1)
    assert res.solved
    curves = lambda a, b: dubins_segments(a, b, sc.turning_radius)  # noqa: E731
    judged = oracle.car_sweep_check(sc, np.asarray(res.path), curves, sc.turning_radius)
    assert not judged["collides"] and not judged["out_of_bounds"]


def test_the_reach_proof_runs_after_the_restarts_even_when_the_caller_s_iterations_run_out(tmp_path):
    # The dead-end alley, Dubins: no forward path. With 30 iterations in all, the restarts stop
    # early, and the proofs still run: the reach proof answers, and check-proof's checker accepts it.
    text = open(os.path.join(SCENARIOS, "car", "dead_end_alley.toml")).read()
    path = tmp_path / "alley.toml"
    path.write_text(text.replace('space = "reeds-shepp"', 'space = "dubins"'))
    sc = load_scenario(str(path))
    assert sc.space == "dubins"
    res = planners.plan(sc, seed=0, iterations=30, time=60.0)
    assert res.proven_unsolvable and res.answered_by == "proof", res.message
    assert "forward-only car cannot" in res.message
    assert check_dubins_proof(sc, res.proof).valid


def test_a_tiny_turning_radius_keeps_a_restart_range_of_an_eighth_of_ompl_s(monkeypatch):
    # A car of radius 1e-6 in the maze: 7 radii would be 7e-6; the restarts' range stops at an
    # eighth of OMPL's own (at 1/64 the maze was not solved in 30 000 iterations, 7 s; at 1/8 in 6 000).
    import dataclasses

    sc = dataclasses.replace(load_scenario(MAZE), turning_radius=1e-6)
    cs = build_cspace(sc)
    adapter = make_adapter(sc, cs)
    own = _own(adapter)
    assert auto_dubins.with_range(adapter, auto_dubins.RESTART_RADII, lambda: _range(adapter)) == \
        pytest.approx(auto_dubins.RESTART_FLOOR * own)
    monkeypatch.setattr(auto, "SLICE_ITERATIONS", 2)  # a slice that cannot answer: the restarts do
    res = planners.plan(sc, cspace=cs, seed=0, iterations=6000, time=1000.0)
    assert res.solved and res.answered_by == "sampling", res.message


def test_a_boxed_in_start_is_proven_before_any_restart(monkeypatch):
    # A car facing a wall it cannot turn away from (tests/helpers/car_scenes.py): its lattice stops
    # at a few dozen poses, so its reach proof runs right after the slice, not after 14 000
    # iterations of restarts that cannot answer; check-proof's checker accepts it.
    seen = _record(monkeypatch)
    sc = wall_scene(1.5)
    res = planners.plan(sc, seed=0, time=60.0)
    assert res.proven_unsolvable and res.answered_by == "proof", res.message
    assert len(seen) == 1 and seen[0][1] == auto.SLICE_ITERATIONS, seen  # the slice alone sampled
    assert check_dubins_proof(sc, res.proof).valid


def test_ends_in_the_open_are_never_given_a_reach_proof(monkeypatch):
    # The hall: start and goal in the open. The slice made to fail and the reach stage moved to
    # the first restart: their lattices run to the cap, so no reach proof is tried (one would fail
    # after 0.1-0.2 s on a large map); the restarts answer.
    from planners.core import dubins_proof

    calls = []
    real = dubins_proof.reach_result
    monkeypatch.setattr(dubins_proof, "reach_result", lambda *a, **k: calls.append(k) or real(*a, **k))
    monkeypatch.setattr(auto, "SLICE_ITERATIONS", 2)
    monkeypatch.setattr(auto_dubins, "FIRST_RESTART", 20)
    monkeypatch.setattr(auto_dubins, "REACH_AFTER", 1)
    monkeypatch.setattr(auto_dubins, "QUICK_AFTER", 99)
    monkeypatch.setattr(auto_dubins, "LATE_CAP", 200)
    asked = []
    boxed = auto_dubins.boxed_ends
    monkeypatch.setattr(auto_dubins, "boxed_ends", lambda *a, **k: asked.append(a[-1] if len(a) > 3 else k) or boxed(*a, **k))
    res = planners.plan(_hall(), seed=3, time=60.0)
    assert res.solved and res.answered_by == "sampling", res.message
    assert len(asked) == 2 and calls == [], (asked, calls)  # early (BOXED_CAP) and at the first restart (LATE_CAP)
