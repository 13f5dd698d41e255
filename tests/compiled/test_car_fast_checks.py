"""The fast lanes of a car's motion check: the argument checks' fast paths answer as the full
checks do, and the proof before sampling is remembered only when its search ran to its end."""
import math

import numpy as np
import pytest

from cspace.car import curves as car_curves
from cspace.se2.pose_checks import curve_radius, curve_segments


@pytest.mark.parametrize("segs", [
    [("L", 1.0), ("S", -2.0), ("R", 0.5)],
    [("S", 3.0)],
    [],
])
def test_usual_segments_pass_unchanged(segs):
    assert curve_segments(segs, 1.0, 10.0) == segs


@pytest.mark.parametrize("segs, err", [
    ([("L", math.nan)], ValueError),
    ([("S", math.inf)], ValueError),
    ([("S", 1e8)], ValueError),                       # beyond MAX_SEGMENT_EXTENTS x extent
    ([("L", 65 * 2 * math.pi)], ValueError),          # more than MAX_ARC_TURNS turns
    ([("X", 1.0)], ValueError),
    ([("S", "1")], TypeError),
    ([("S", 1.0, 2.0)], TypeError),
    ([["S"]], TypeError),
])
def test_junk_segments_are_refused_as_before(segs, err):
    with pytest.raises(err):
        curve_segments(segs, 1.0, 10.0)


def test_other_numbers_take_the_full_check():
    # NumPy scalars, ints and list pairs: the full check converts them, as it did
    assert curve_segments([["L", np.float64(1.5)], ("S", 2)], 1.0, 10.0) == [("L", 1.5), ("S", 2.0)]
    assert curve_segments((("S", 1.0),), 1.0, 10.0) == [("S", 1.0)]


def test_radius_fast_path_and_refusals():
    assert curve_radius(1.0, 10.0) == 1.0
    assert curve_radius(np.float64(2.0), 10.0) == 2.0
    for bad, err in ((math.nan, ValueError), (1e20, ValueError), (True, TypeError), ("1", TypeError)):
        with pytest.raises(err):
            curve_radius(bad, 10.0)


def test_pose_fast_path_matches_the_full_one():
    a, b = (0.5, 0.25, 0.1), (np.float64(3.0), 1, np.float32(0.5))
    assert car_curves.reeds_shepp_segments(a, (3.0, 1.0, float(np.float32(0.5))), 1.0) == \
        car_curves.reeds_shepp_segments(list(a), b, 1.0)
    for bad in ((0.0, math.nan, 0.0), (math.inf, 0.0, 0.0)):
        with pytest.raises(ValueError):
            car_curves.reeds_shepp_segments(bad, (1.0, 1.0, 0.0), 1.0)


def test_quick_proof_remembers_only_a_finished_search(monkeypatch):
    import os

    from conftest import SCENARIOS
    from cspace.io.load import load_scenario
    from planners.core import exact_se2
    from planners.core.plan import build_cspace

    sc = load_scenario(os.path.join(SCENARIOS, "car", "loading_dock.toml"))
    cs = build_cspace(sc)
    q = sc.all_queries()[0]
    calls = []
    real = exact_se2.search

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(exact_se2, "search", counted)
    assert exact_se2.quick_proof(sc, cs, q, 10.0) is None
    assert exact_se2.quick_proof(sc, cs, q, 10.0) is None
    assert len(calls) == 1  # the second answer is the remembered one
    # a search cut by its budget (time limit 0) is not remembered
    cs2 = build_cspace(sc)
    assert exact_se2.quick_proof(sc, cs2, q, 0.0) is None
    assert exact_se2.quick_proof(sc, cs2, q, 0.0) is None
    assert len(calls) == 3
