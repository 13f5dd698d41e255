"""Every stage of ``exact`` in SE(2) inside the time limit (issue 49, point 7): the shortening stops
when time is up and keeps the certified path; messages say why a stage was skipped."""
from __future__ import annotations

import os

import numpy as np
import pytest

import planners
from conftest import SCENARIOS
from cspace.io.load import load_scenario
from planners.adapters.glue import ompl_available
from planners.core import exact_se2
from planners.core.plan import build_cspace, make_adapter

DOOR = os.path.join(SCENARIOS, "se2", "bar_door.toml")
needs_ompl = pytest.mark.skipif(not ompl_available(), reason="OMPL not installed")


def solved_raw():
    sc = load_scenario(DOOR)
    cs = build_cspace(sc)
    ad = make_adapter(sc, cs)
    q = sc.all_queries()[0]
    res = exact_se2.search(cs, q, 30.0)
    assert res.status == "solved" and len(res.path) >= 3
    return ad, np.asarray(res.path), q


def test_no_simplify_does_not_say_ompl_is_missing():
    r = planners.plan(DOOR, planner="exact", time=30.0, simplify=False)
    assert r.solved and "OMPL not installed" not in r.message and "--no-simplify" in r.message


@needs_ompl
def test_no_time_left_keeps_the_certified_path():
    ad, raw, q = solved_raw()
    path, note = exact_se2.shorten(ad, raw, q, time_limit=0.0)
    assert path is raw and "no time left" in note


@needs_ompl
def test_the_shortening_stops_at_its_time_and_keeps_the_certified_path(monkeypatch):
    """A clock that jumps past the limit at the first motion check: that check and every later one
    answer "not free" without being computed, and the certified path is returned as it was."""
    ad, raw, q = solved_raw()
    asked = []
    real = ad.motion_free
    monkeypatch.setattr(ad, "motion_free", lambda a, b: asked.append(1) or real(a, b))
    clock = iter([0.0, 0.0] + [1e9] * 10**6)
    monkeypatch.setattr(exact_se2.time, "perf_counter", lambda: next(clock))
    path, note = exact_se2.shorten(ad, raw, q, time_limit=5.0)
    assert path is raw and "time limit stopped the shortening" in note
    assert asked == []  # no motion check computed after the deadline


@needs_ompl
def test_with_time_the_shortening_runs_as_before():
    ad, raw, q = solved_raw()
    timed, note = exact_se2.shorten(ad, raw, q, time_limit=1e6)
    free, _ = exact_se2.shorten(ad, raw, q)
    assert "shortened" in note and ad.verify(timed, q.start, q.goal)[0]
    assert ad.length(timed) <= ad.length(raw) and ad.length(free) <= ad.length(raw)


def test_the_raw_recheck_stops_at_the_time_limit_and_says_so(monkeypatch):
    """A clock past the limit once the search is done: the second opinion (the certified re-check)
    stops before its first motion, the slab graph's path is kept (each of its motions was checked
    exactly when it was built), the message says how far the re-check got, and the shortening is
    skipped for lack of time (no wall-clock assertion: the clock is the test's)."""
    sc = load_scenario(DOOR)
    cs = build_cspace(sc)
    ad = make_adapter(sc, cs)
    q = sc.all_queries()[0]
    asked = []
    real = ad.motion_free
    monkeypatch.setattr(ad, "motion_free", lambda a, b: asked.append(1) or real(a, b))
    res = exact_se2.search(cs, q, None)
    monkeypatch.setattr(exact_se2, "search", lambda *a, **k: res)
    late = iter([0.0] + [1e9] * 10**6)
    monkeypatch.setattr(exact_se2.time, "perf_counter", lambda: next(late))
    r = exact_se2.exact_se2(sc, cs, ad, q, "door.toml", time_limit=5.0)
    assert r.solved and np.array_equal(r.path, res.path) and asked == []
    assert f"0 of {len(res.path) - 1} motions re-checked before the time limit" in r.message
    assert "not shortened: no time left" in r.message


def test_with_time_the_recheck_runs_to_its_end():
    ad, raw, q = solved_raw()
    ok, why, cut = ad.verify_until(raw, q.start, q.goal, None)
    assert ok and cut is None and (ok, why) == ad.verify(raw, q.start, q.goal)
    bad = raw.copy()
    bad[1:-1, :2] = 5.0  # through the wall: the re-check refutes it when it runs
    assert not ad.verify_until(bad, q.start, q.goal, None)[0]


def test_the_clearance_measure_stops_at_its_deadline_with_a_lower_bound():
    """A deadline already past: the first pass only (one bound per quarter turn of each motion),
    marked ``cut``; never above the full measure's bound (both lower bounds of the true clearance)."""
    from cspace.se2.clearance import se2_path_clearance

    sq = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])]
    bar = [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])]
    turn = np.array([[2., 1, 0], [2, 1, 1.5]])  # a turn in place: its bound is refined (true clearance 2.6006)
    full = se2_path_clearance(turn, bar, sq)
    cut = se2_path_clearance(turn, bar, sq, deadline=0.0)
    assert not full.cut and cut.cut and cut.bound == "lower"
    assert 0.0 <= cut.distance < full.distance


def test_plan_says_when_the_clearance_measure_was_cut():
    """plan()'s measure of a solved SE(2) path with its deadline already past (a turn in place near
    an obstacle, whose bound the measure would refine): a lower bound, and the message says so."""
    from types import SimpleNamespace

    from cspace.io.load import scenario_from_dict
    from planners.core.plan import _measure_clearance

    sc = scenario_from_dict({"space": "se2", "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
                             "robot": {"polygon": [[-1, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]]},
                             "start": {"x": 2, "y": 1, "theta": 0}, "goal": {"x": 2, "y": 1, "theta": 1.5},
                             "obstacles": [{"polygon": [[4, 4], [6, 4], [6, 6], [4, 6]]}]}, "turn.toml")
    ad = make_adapter(sc, build_cspace(sc))
    r = SimpleNamespace(solved=True, path=np.array([[2., 1, 0], [2, 1, 1.5]]), message="solved", timings={},
                        clearance=0.0)
    _measure_clearance(r, ad, deadline=0.0)
    assert "the clearance measure stopped at the time limit" in r.message
    assert r.min_clearance_bound == "lower" and 0.0 <= r.min_clearance < 2.6005  # the true clearance: 2.60056...
    r.message = "solved"
    _measure_clearance(r, ad, deadline=None)
    assert r.message == "solved" and 2.59 < r.min_clearance <= 2.6006
