"""Tiny and huge coordinates: every answer at scale 2^k is the scale-1 answer times 2^k.

Multiplying all coordinates by a power of two is exact, so this is an oracle for
every function: exact ones must agree bit for bit, float ones to their own
tolerance. Before the rescaling of :mod:`cspace.kernel.polygons.scaling` and the exact orientation
of :func:`cspace.kernel.polygons.polygon.orientation`, GJK and EPA answered wrongly from 2^-400 and
2^700 on, GEOS's triangulation raised from 2^±700, and normalize turned a CCW
polygon clockwise at 2^-600 (its shoelace area underflowed to 0).
"""
import warnings

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

import cspace as C
from cspace.kernel.polygons.polygon import normalize, orientation

SCALES = [-1000, -700, -400, 400, 700, 1000]


def _convex(rng, n, offset=(0.0, 0.0)):
    a = np.sort(rng.uniform(0, 2 * np.pi, n))
    return np.c_[rng.uniform(0.3, 1.0) * np.cos(a), np.sin(a)] + offset


def _star(rng, n):
    a = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = rng.uniform(0.3, 1.0, n)
    return np.c_[r * np.cos(a), r * np.sin(a)]


@pytest.fixture(autouse=True)
def _no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an overflow warning leaking out is a failure too
        yield


@pytest.mark.parametrize("k", SCALES + [-1070])
def test_normalize_keeps_orientation_at_every_scale(k):
    T = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    want = np.ldexp(normalize(T), k)
    assert np.array_equal(normalize(np.ldexp(T, k)), want)
    assert np.array_equal(normalize(np.ldexp(T[::-1], k)), want)
    assert orientation(np.ldexp(T, k)) == 1 and C.is_simple(np.ldexp(T, k))


def test_orientation_of_a_sliver_is_exact():
    # Nearly collinear (the last y one ulp up): the shoelace sum rounds to 0.0 here.
    p = np.array([[0.1, 0.3], [589.3624923188806, 196.72083077296023], [941.6651814089914, 314.15506046966385]])
    assert C.signed_area(p) == 0.0
    assert orientation(p) == 1 and orientation(p[::-1]) == -1
    assert np.array_equal(normalize(p), p)  # CCW already, lowest first: kept as it is


@pytest.mark.parametrize("seed", range(6))
def test_gjk_and_epa_scale_exactly(seed):
    rng = np.random.default_rng(seed)
    P = _convex(rng, int(rng.integers(3, 10)))
    Q = _convex(rng, int(rng.integers(3, 10)), rng.uniform(-2.5, 2.5, 2))
    d0, p0 = C.gjk_distance(P, Q), C.epa_penetration(P, Q)
    for k in SCALES:
        d = C.gjk_distance(np.ldexp(P, k), np.ldexp(Q, k))
        assert d.status == d0.status
        assert np.ldexp(d.distance, -k) == pytest.approx(d0.distance, rel=1e-12, abs=1e-15)
        assert np.allclose(np.ldexp(d.point_a, -k), d0.point_a, rtol=0, atol=1e-12)
        p = C.epa_penetration(np.ldexp(P, k), np.ldexp(Q, k))
        assert p.status == p0.status
        assert np.ldexp(p.depth, -k) == pytest.approx(p0.depth, rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("seed", range(4))
def test_decompose_erode_and_sums_scale_exactly(seed):
    rng = np.random.default_rng(100 + seed)
    S, L = _star(rng, int(rng.integers(6, 25))), _star(rng, int(rng.integers(5, 12)))
    P, Q = _convex(rng, 8) * 3, _convex(rng, 5) * 0.2
    pieces0, eroded0 = C.convex_decompose(S), C.erode(P, Q)
    region0 = C.minkowski_sum_nonconvex(S, L)
    for k in SCALES:
        pieces = C.convex_decompose(np.ldexp(S, k))
        assert len(pieces) == len(pieces0)
        assert all(np.array_equal(a, np.ldexp(b, k)) for a, b in zip(pieces, pieces0))
        assert np.array_equal(C.erode(np.ldexp(P, k), np.ldexp(Q, k)), np.ldexp(eroded0, k))
        assert np.array_equal(C.minkowski_sum(np.ldexp(P, k), np.ldexp(Q, k)), np.ldexp(C.minkowski_sum(P, Q), k))
        region = shapely.transform(C.minkowski_sum_nonconvex(np.ldexp(S, k), np.ldexp(L, k)),
                                   lambda c: np.ldexp(c, -k))
        assert region.symmetric_difference(region0).area <= 1e-12 * region0.area


def test_sums_beyond_the_double_range_raise_value_error():
    P = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]) * 1.5e308
    with pytest.raises(ValueError, match="overflow the double range"):
        C.minkowski_sum(P, P)
    L = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]]) * 5e307
    with pytest.raises(ValueError, match="overflow the double range"):
        C.minkowski_sum_nonconvex(L, L)


def test_nonconvex_sum_with_a_segment_or_a_point():
    # A segment operand sweeps the polygon: the union of its two end copies and of the
    # parallelograms its edges sweep (an independent construction).
    L = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0], [1.0, 2.0], [0.0, 2.0]])
    seg = np.array([[0.0, 0.0], [1.0, 0.5], [3.0, 1.5], [1.0, 0.5]])  # collinear, folded back
    v = np.array([3.0, 1.5])
    swept = [shapely.Polygon(L), shapely.Polygon(L + v)] + [
        shapely.Polygon([L[i], L[i - 1], L[i - 1] + v, L[i] + v]).buffer(0) for i in range(len(L))]
    want = shapely.union_all(swept)
    got = C.minkowski_sum_nonconvex(L, seg)
    assert got.symmetric_difference(want).area <= 1e-12 * want.area
    assert [p.tolist() for p in C.convex_decompose(seg)] == [[[0.0, 0.0], [3.0, 1.5]]]
    assert C.minkowski_sum_nonconvex(L, [[5.0, 5.0]]).equals(shapely.Polygon(L + 5.0))
    with pytest.raises(ValueError, match="not collinear"):
        C.convex_decompose([[0, 0], [1, 0], [0, 0], [0, 1]])  # two arms: no area, not a segment


def _scaled_doc(doc, k):
    """A scenario document with every length multiplied by 2^k (exact)."""
    keep = {"time", "seed", "theta", "disk_tolerance", "name", "expect", "simplify"}

    def sc(v, key=None):
        if key in keep:
            return v
        if isinstance(v, dict):
            return {kk: sc(vv, kk) for kk, vv in v.items()}
        if isinstance(v, list):
            return [sc(x) for x in v]
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return np.ldexp(float(v), k).item()
        return v
    return sc(doc)


@pytest.mark.parametrize("name", ["basic", "u_robot"])
def test_plans_are_the_same_path_at_every_supported_scale(name):
    # Scaling a scene by 2^k changes no exact decision, so the path must be the same,
    # scaled. At 2^-60 the scene is ~1e-17 across: OMPL's absolute thresholds refused
    # it ("longest valid segment must be positive") until it planned in a 2^k frame.
    import pathlib
    import tomllib

    from conftest import SCENARIOS
    from cspace import scenario_from_dict
    from planners import plan

    doc = tomllib.loads((pathlib.Path(SCENARIOS) / f"{name}.toml").read_text())
    base = plan(scenario_from_dict(doc, name), planner="RRTConnect", time=5.0, seed=3)
    assert base.solved
    for k in (-300, -60, 60, 300):
        r = plan(scenario_from_dict(_scaled_doc(doc, k), name), planner="RRTConnect", time=5.0, seed=3)
        assert r.solved and np.array_equal(np.ldexp(r.path, -k), base.path), k


def test_cspace_outside_its_range_is_a_value_error():
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    assert not C.CSpace((0, 10, 0, 10), [sq]).is_free((5, 5))
    for bounds, shapes, fault in (((0, 10, 0, 10), [sq * 1e121], "beyond"), ((0, 1e-300, 0, 1e-300), [], "below"),
                                  ((0, 0, 0, 1), [], "empty")):
        with pytest.raises(ValueError, match=fault):
            C.CSpace(bounds, shapes)


def test_disk_sides_with_a_tolerance_too_small_to_show():
    # radius 5e-324: its relative tolerance underflows to 0, and 1 - 1e-300 rounds to 1;
    # both divided by acos(1) = 0 before. The finest polygon is the answer.
    from cspace.kernel.polygons.disk import MAX_SIDES, disk_sides

    assert disk_sides(5e-324) == MAX_SIDES
    assert disk_sides(1.0, 1e-300) == MAX_SIDES
    assert disk_sides(1.0, 1e-3) == 71  # ordinary radii unchanged


_TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
_CALLS = {
    "convex_hull": lambda q: C.convex_hull(q),
    "minkowski_sum": lambda q: C.minkowski_sum(q, _TRI),
    "minkowski_sum (vectorised)": lambda q: C.minkowski_sum(np.tile(q, (40, 1)), _TRI),
    "erode A": lambda q: C.erode(q, _TRI * 0.1),
    "erode B": lambda q: C.erode(_TRI, q * 0.1),
    "gjk_distance": lambda q: C.gjk_distance(q, _TRI),
    "epa_penetration": lambda q: C.epa_penetration(q, _TRI),
    "convex_decompose": lambda q: C.convex_decompose(q),
    "minkowski_sum_nonconvex": lambda q: C.minkowski_sum_nonconvex(q, _TRI),
    "normalize": lambda q: C.normalize(q),
    "is_convex": lambda q: C.is_convex(q),
    "halfplanes": lambda q: C.halfplanes(q),
    "CSpace": lambda q: C.CSpace((0, 10, 0, 10), [q + 3.0]),
}


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("name", sorted(_CALLS))
def test_non_finite_coordinates_are_a_clear_value_error(name, bad):
    # Before: "cannot convert NaN to integer ratio", an OverflowError for inf, or (for
    # minkowski_sum) a claim that the sum overflowed.
    q = _TRI.copy()
    q[1, 0] = bad
    with pytest.raises(ValueError, match="finite|beyond the supported") as exc:
        _CALLS[name](q)
    assert "integer ratio" not in str(exc.value)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.integers(-50, 50), st.integers(-50, 50)), min_size=3, max_size=12, unique=True),
       st.sampled_from([1.0, 2.0**-600, 2.0**600, 1e-7]), st.floats(-1e8, 1e8))
@example(pts=[(0, 1), (1, 2), (-1, 0)], scale=2.0**600, offset=2.2250738585e-313)  # GEOS's reason overflowed
def test_orientation_is_the_sign_of_the_exact_area(pts, scale, offset):
    # Oracle: the shoelace sum in Fractions. Star-shaped (sorted by angle about the
    # centroid), so the polygon is simple; scaled and offset in floats, so the area is
    # tiny, huge or rounded next to the coordinates.
    from fractions import Fraction

    p = np.array(pts, dtype=np.float64)
    c = p.mean(axis=0)
    p = p[np.argsort(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]), kind="stable")] * scale + offset * scale
    if not C.is_simple(p):
        return
    F = [(Fraction(x), Fraction(y)) for x, y in p.tolist()]
    area2 = sum(F[i][0] * F[i - 1][1] - F[i - 1][0] * F[i][1] for i in range(len(F)))
    want = (area2 < 0) - (area2 > 0)  # (x_i y_{i-1} - x_{i-1} y_i) sums to -2 area
    assert orientation(p) == want and orientation(p[::-1]) == -want
