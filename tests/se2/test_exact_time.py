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
