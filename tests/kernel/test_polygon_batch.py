"""The loader's batched route (cspace.kernel.polygons.polygon_batch) gives the scalar route's answers:
the same normalised arrays and convexity flags wherever it decides, None (the scalar
route then decides and words the error) for everything it does not certify, and the
loader reports the first faulty obstacle in file order either way."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cspace import ScenarioError, is_convex, normalize, scenario_from_dict
from cspace.kernel.polygons.polygon import invalid_reason
from cspace.kernel.polygons.polygon_batch import normalize_many


def scalar(p: np.ndarray):
    if len(np.unique(p, axis=0)) < 3 or invalid_reason(p):
        return None
    q = normalize(p, ccw=True)
    return None if len(q) < 3 else (q, is_convex(q))


def check(polys):
    for p, got in zip(polys, normalize_many(polys)):
        want = scalar(p)
        if got is None:
            continue  # the scalar route decides: nothing to compare
        assert want is not None, p
        assert np.array_equal(got[0], want[0]) and got[1] == want[1], p


coords = st.integers(-6, 6).map(float) | st.floats(-1e3, 1e3, allow_nan=False, width=32)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.lists(st.lists(st.tuples(coords, coords), min_size=3, max_size=7), min_size=1, max_size=6))
def test_random_polygons_match_the_scalar_route(raw):
    check([np.array(p, dtype=np.float64) for p in raw])


def test_named_cases():
    sq = np.array([[0., 0], [2, 0], [2, 2], [0, 2]])
    cases = [sq, sq[::-1].copy(), np.roll(sq, 2, axis=0),                       # CCW, CW, rotated
             np.array([[0., 0], [2, 0], [1, 1], [2, 2], [0, 2]]),               # non-convex
             np.array([[0., 0], [2, 2], [2, 0], [0, 2]]),                       # bowtie: invalid
             np.array([[0., 0], [1, 0], [2, 0], [0, 1]]),                       # collinear vertex
             np.array([[0., 0], [0, 0], [1, 0], [0, 1]]),                       # repeat
             np.array([[0., 0], [1, 0], [0, 1]]) * 1e-300,                      # extreme scale
             np.array([[math.cos(a), math.sin(a)] for a in np.arange(5) * 4 * math.pi / 5]),  # pentagram
             np.array([[0., 0], [1, 1e-17], [2, 0], [1, 1]])]                   # sliver turn
    got = normalize_many(cases)
    assert [g is None for g in got] == [False, False, False, False, True, True, True, True, True, False]
    assert got[0][1] and got[1][1] and not got[3][1]
    check(cases)


def scene(obstacles):
    return {"bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10}, "start": {"x": 0.5, "y": 0.5},
            "goal": {"x": 9.5, "y": 9.5}, "obstacles": obstacles}


def test_loader_reports_the_first_fault_in_file_order():
    tri = {"polygon": [[2, 2], [3, 2], [2.5, 3]]}
    bowtie = {"polygon": [[4, 4], [6, 6], [6, 4], [4, 6]]}
    bad_hole = {"polygon": [[7, 7], [8, 7], [8, 8], [7, 8]], "holes": [[[1, 1], [2, 1], [1, 2]]]}
    bad_number = {"polygon": [[1, 1], [2, "x"], [1, 2]]}
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.polygon: not a simple polygon"):
        scenario_from_dict(scene([tri, bowtie, bad_hole]))
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.polygon: not a simple polygon"):
        scenario_from_dict(scene([tri, bowtie, bad_number]))
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.holes"):
        scenario_from_dict(scene([tri, bad_hole, bowtie]))
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]\.polygon\[1\]\[1\]"):
        scenario_from_dict(scene([bad_number, bowtie]))
    huge = {"polygon": [[1, 1], [2, 1e300], [1, 2]]}  # beyond 2^400: found after the batch conversion
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.polygon\[1\]\[1\]: .* beyond"):
        scenario_from_dict(scene([tri, huge, bowtie]))
    with pytest.raises(ScenarioError, match=r"obstacles\[1\]\.polygon: not a simple polygon"):
        scenario_from_dict(scene([tri, bowtie, huge, bad_hole]))
    with pytest.raises(ScenarioError, match=r"obstacles\[0\]\.polygon\[0\]\[0\]: .* too large"):
        scenario_from_dict(scene([{"polygon": [[2**1100, 1], [2, 1], [1, 2]]}, bowtie]))


def test_loaded_obstacles_are_the_scalar_normalisation():
    rng = np.random.default_rng(5)
    obs = []
    for k in range(60):
        n = int(rng.integers(3, 7))
        a = (np.arange(n) + rng.uniform(0, 0.5, n)) * 2 * math.pi / n  # star-shaped: simple
        r = rng.uniform(0.2, 0.6, n)
        p = np.column_stack([5 + r * np.cos(a), 5 + r * np.sin(a)])
        obs.append({"polygon": (p if k % 2 else p[::-1]).tolist()})
    sc = scenario_from_dict(scene(obs))
    for o, raw in zip(sc.obstacles, obs):
        want = normalize(np.array(raw["polygon"]), ccw=True)
        assert np.array_equal(o.polygon, want) and o.convex == is_convex(want) and o.holes == []


def test_stars_are_simple_without_geos_and_match_the_scalar_route():
    a = np.arange(2000) * 2 * math.pi / 2000
    r = np.where(np.arange(2000) % 2 == 0, 10.0, 4.0)
    star = np.column_stack([50 + r * np.cos(a), 50 + r * np.sin(a)])
    from cspace.kernel.polygons.polygon_batch import _star_shaped

    assert _star_shaped(star[None], np.ones((1, 2000))).tolist() == [True]
    twice = np.vstack([star[::2], star[::2]])[::1]  # the same vertices wound twice: not simple
    assert _star_shaped(twice[None], np.ones((1, 2000))).tolist() == [False]
    check([star, star[::-1].copy(), twice])
