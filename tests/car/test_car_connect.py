"""The compiled Reeds–Shepp RRT-Connect (cspace/car/connect.py, cspace/compiled/_carrrt.c) and
``auto``'s slice that runs it (planners/core/car_sampling.py): its paths pass the independent
sweep (scripts/sweep_oracle.py, along the curves), every motion is at most one step long (the
interpolation along a curve), the same seed gives the same path, its budgets (samples, deadline)
stop it; without the extension the same search runs in Python (``search_python``: the compiled
search's oracle, the same path for the same arguments)."""
from __future__ import annotations

import math
import os
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

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
        assert res.solved and res.answered_by == "sampling" and "own RRT-Connect" in res.message, res.message
        assert swept_free(sc, np.asarray(res.path))
        again = planners.plan(sc, seed=1, time=10.0, simplify=simplify)
        assert np.array_equal(res.path, again.path)


@compiled
@pytest.mark.parametrize("name", RS_SCENES + ["u_turn_cusps.toml", "parallel_tight.toml"])
def test_the_python_search_is_the_compiled_one(name):
    # The oracle: the same samples, trees, motions asked and path, double for double, on every
    # bundled Reeds-Shepp scene (parallel_tight: no path in 300 samples, the same count of motions).
    from cspace.car.connect import search_python
    from cspace.compiled import motions

    sc, ad, q, pair = setup_of(name)
    for seed in (0, 3):
        ad.forget()
        c = motions.car_connect(*pair, ad.radius, sc.bounds, step_length(ad), seed, 300, ad.motion_free)
        ad.forget()
        p = search_python(*pair, ad.radius, sc.bounds, step_length(ad), seed, 300, ad.motion_free)
        assert c[1:] == p[1:] and (c[0] is None) == (p[0] is None), (name, seed, c[1:], p[1:])
        assert c[0] is None or c[0] == p[0], (name, seed)


@compiled
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 2**64 - 1), st.floats(0.3, 3.0), st.floats(0.5, 6.0),
       st.lists(st.tuples(st.floats(1, 9), st.floats(1, 9)), min_size=0, max_size=4))
def test_the_python_search_is_the_compiled_one_on_random_scenes(seed, radius, step, centres):
    # Random boxes, radii and steps; the motion test is the certified one of that scene.
    from cspace.car.connect import search_python
    from cspace.car.motion import CarCSpace
    from cspace.compiled import motions

    box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    obstacles = [np.array([[x - 0.5, y - 0.5], [x + 0.5, y - 0.5], [x + 0.5, y + 0.5], [x - 0.5, y + 0.5]])
                 for x, y in centres if not (abs(x - 0.5) < 1.2 and abs(y - 0.5) < 1.2) and
                 not (abs(x - 9.5) < 1.2 and abs(y - 9.5) < 1.2)]
    cs = CarCSpace((0, 10, 0, 10), obstacles, [box], slabs=16)
    test = cs.car_motion_test("reeds-shepp", radius)
    a, b = (0.5, 0.5, 0.3), (9.5, 9.5, -2.0)
    c = motions.car_connect(a, b, radius, (0, 10, 0, 10), step, seed, 60, test)
    p = search_python(a, b, radius, (0, 10, 0, 10), step, seed, 60, test)
    assert c == p


def test_without_the_extension_auto_runs_the_same_search_in_python(monkeypatch):
    import cspace.car.connect as connect_module

    sc = load_scenario(os.path.join(SCENARIOS, "car", "u_turn.toml"))
    first = planners.plan(sc, seed=1, time=10.0, simplify=False)
    monkeypatch.setattr(connect_module.motions, "car_connect", lambda *a, **k: None)
    res = planners.plan(sc, seed=1, time=10.0, simplify=False)
    assert res.solved and res.answered_by == "sampling" and "own RRT-Connect" in res.message, res.message
    assert swept_free(sc, np.asarray(res.path))
    assert np.array_equal(res.path, first.path)  # the same path as the compiled search's


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
