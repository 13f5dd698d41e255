"""The compiled Reeds–Shepp RRT-Connect (cspace/car/connect.py, cspace/compiled/_carrrt.c) and
``auto``'s slice that runs it (planners/core/car_sampling.py): its paths pass the independent
sweep (scripts/sweep_oracle.py, along the curves), every motion is at most one step long (the
interpolation along a curve), the same seed gives the same path, its budgets (samples, deadline)
stop it, and without the extension ``auto`` samples with OMPL as before."""
from __future__ import annotations

import math
import os
import time

import numpy as np
import pytest

import planners
from conftest import SCENARIOS, load_script
from cspace.car.connect import connect
from cspace.car.curves import curve_length, reeds_shepp_segments
from cspace.compiled import fastpath
from cspace.io.load import load_scenario
from planners.core.car_sampling import step_length
from planners.core.plan import build_cspace, make_adapter

oracle = load_script("sweep_oracle")
compiled = pytest.mark.skipif(not fastpath.compiled(), reason="the compiled fast path is not built")
RS_SCENES = ["parking.toml", "u_turn.toml", "loading_dock.toml", "dead_end_alley.toml", "garage_reverse.toml"]


def setup_of(name):
    sc = load_scenario(os.path.join(SCENARIOS, "car", name))
    cs = build_cspace(sc)
    adapter = make_adapter(sc, cs)
    q = sc.all_queries()[0]
    return sc, adapter, q, (adapter.pose(q.start), adapter.pose(q.goal))


def swept_free(sc, path) -> bool:
    j = oracle.car_sweep_check(sc, path, lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius), sc.turning_radius)
    return not j["collides"] and not j["out_of_bounds"]


@compiled
@pytest.mark.parametrize("name", RS_SCENES)
def test_its_paths_pass_the_sweep_and_step_at_most_one_step(name):
    sc, ad, q, pair = setup_of(name)
    step = step_length(ad)
    for seed in range(2):
        ad.forget()
        path, stats = connect(ad.motion_free, pair[0], pair[1], ad.radius, sc.bounds, step, seed, 3000)
        assert path is not None, (name, seed, stats)
        assert tuple(path[0]) == pair[0] and tuple(path[-1]) == pair[1]
        assert 0 < stats["iterations"] <= 3000 and stats["motions"] >= len(path) - 1
        rows = [tuple(r) for r in path.tolist()]
        lengths = [curve_length(reeds_shepp_segments(a, b, ad.radius)) for a, b in zip(rows[:-1], rows[1:])]
        # every tree step is at most the step along its curve (a wrong interpolation overshoots)
        assert max(lengths) <= step * (1 + 1e-9) + 1e-12, (max(lengths), step)
        assert all(-math.pi <= r[2] < math.pi for r in rows[1:-1])  # the nodes' headings wrapped as OMPL's
        assert ad.verify(path, q.start, q.goal)[0]
        assert swept_free(sc, path), (name, seed)


@compiled
def test_the_interpolated_steps_are_whole_steps_along_their_curves():
    # A long open drive: the trees advance a whole step at a time (a node at a step's end is
    # exactly one step from its parent along the shortest curve), except where they reach.
    from cspace.car.motion import CarCSpace

    box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    cs = CarCSpace((0, 40, 0, 10), [np.array([[19., 0], [21, 0], [21, 2], [19, 2]])], [box], slabs=16)
    test = cs.car_motion_test("reeds-shepp", 1.0)
    path, _ = connect(test, (2.0, 5.0, 0.5), (38.0, 5.0, -0.5), 1.0, (0, 40, 0, 10), 2.0, 1, 2000)
    rows = [tuple(r) for r in path.tolist()]
    lengths = [curve_length(reeds_shepp_segments(a, b, 1.0)) for a, b in zip(rows[:-1], rows[1:])]
    assert sum(abs(x - 2.0) < 1e-9 for x in lengths) >= len(lengths) // 2, lengths


@compiled
def test_same_seed_same_path_and_seeds_differ():
    sc, ad, q, pair = setup_of("parking.toml")
    runs = [connect(ad.motion_free, *pair, ad.radius, sc.bounds, step_length(ad), s, 3000)[0] for s in (4, 4, 5)]
    assert np.array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])


@compiled
def test_its_budgets_stop_it():
    sc, ad, q, pair = setup_of("parallel_tight.toml")  # sampling does not find this one in a few samples
    path, stats = connect(ad.motion_free, *pair, ad.radius, sc.bounds, step_length(ad), 0, 5)
    assert path is None and stats["iterations"] == 5
    path, stats = connect(ad.motion_free, *pair, ad.radius, sc.bounds, step_length(ad), 0, 10**9,
                          deadline=time.perf_counter() - 1.0)
    assert path is None and stats["late"]
    with pytest.raises(ValueError):
        connect(ad.motion_free, (math.nan, 1.0, 0.0), pair[1], ad.radius, sc.bounds, 1.0, 0, 10)
    with pytest.raises(ZeroDivisionError):  # an error in the motion test comes through, nothing swallowed
        connect(lambda a, b: 1 / 0, *pair, ad.radius, sc.bounds, 1.0, 0, 10)


@compiled
@pytest.mark.parametrize("name", ["u_turn.toml", "garage_reverse.toml"])
def test_auto_answers_a_small_car_scene_by_the_compiled_slice(name):
    sc = load_scenario(os.path.join(SCENARIOS, "car", name))
    for simplify in (False, True):
        res = planners.plan(sc, seed=1, time=10.0, simplify=simplify)
        assert res.solved and res.answered_by == "sampling" and "compiled RRT-Connect" in res.message, res.message
        assert swept_free(sc, np.asarray(res.path))
        again = planners.plan(sc, seed=1, time=10.0, simplify=simplify)
        assert np.array_equal(res.path, again.path)


def test_without_the_extension_auto_samples_with_ompl(monkeypatch):
    import cspace.car.connect as connect_module

    monkeypatch.setattr(connect_module.motions, "car_connect", lambda *a, **k: None)
    sc = load_scenario(os.path.join(SCENARIOS, "car", "u_turn.toml"))
    res = planners.plan(sc, seed=1, time=10.0, simplify=False)
    assert res.solved and res.answered_by == "sampling" and "compiled" not in res.message, res.message
    assert swept_free(sc, np.asarray(res.path))


def test_a_map_of_hundreds_of_radii_keeps_ompl_s_slice():
    # (a building's map: its first queries build slabs inside the slice; OMPL's slice re-runs there)
    from planners.adapters.car import CarSpace
    from planners.core.car_sampling import connect_slice, small_car_scene

    sc, ad, q, pair = setup_of("parking.toml")
    assert small_car_scene(ad)
    tiny = CarSpace(ad.cspace, "reeds-shepp", ad.radius / 20)  # the same scene, 20x as many radii across
    assert not small_car_scene(tiny)
    clock = type("Clock", (), {"t0": time.perf_counter(), "limit": 1.0, "left": lambda self: 1.0})()
    assert connect_slice(sc, tiny, q, pair, 0, clock, 1.0, None, False) is None
    assert connect_slice(sc, ad, q, pair, 0, clock, 1.0, None, False).solved  # the scene's own radius: small
