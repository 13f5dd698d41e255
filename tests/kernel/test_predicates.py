"""The predicate's stages against rationals: the filter, the error-free stage, the fallback."""
from fractions import Fraction

import numpy as np
from hypothesis import given, settings, strategies as st

from cspace.kernel.polygons.predicates import cross_diff_cols, cross_diff_exact, cross_diff_sign, error_free_cross_sign, orient2d_xy


def exact(ax, ay, bx, by, cx, cy, dx, dy):
    F = Fraction
    det = (F(bx) - F(ax)) * (F(dy) - F(cy)) - (F(by) - F(ay)) * (F(dx) - F(cx))
    return (det > 0) - (det < 0)


ints = st.integers(-2**30, 2**30).map(float)
dyadic = st.builds(lambda m, e: m * 2.0**e, st.integers(-2**20, 2**20), st.integers(-40, 40))
anyf = st.floats(-1e12, 1e12, allow_nan=False, allow_infinity=False)
coords = st.one_of(ints, dyadic, anyf)


@settings(max_examples=400, deadline=None)
@given(st.lists(coords, min_size=8, max_size=8))
def test_error_free_stage_never_wrong(v):
    got = int(error_free_cross_sign(*(np.array([x]) for x in v))[0])
    assert got == 2 or got == exact(*v)
    assert cross_diff_sign(*v) == exact(*v)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.one_of(ints, dyadic), min_size=6, max_size=6), st.integers(-50, 50), st.integers(-50, 50))
def test_collinear_points_are_zero(v, s, t):
    # c = a + s/64 (b - a) and d = a + t/64 (b - a): all exactly collinear when representable
    ax, ay, bx, by = v[:4]
    cx, cy = ax + s / 64 * (bx - ax), ay + s / 64 * (by - ay)
    ref = exact(ax, ay, bx, by, ax, ay, cx, cy)
    assert orient2d_xy(ax, ay, bx, by, cx, cy) == exact(cx, cy, ax, ay, cx, cy, bx, by)
    assert cross_diff_sign(ax, ay, bx, by, ax, ay, cx, cy) == ref


def test_columns_match_scalar_on_touching_grid():
    # many exact zeros (lattice points on lattice lines): the stage the filter cannot settle
    rng = np.random.default_rng(5)
    p = rng.integers(-4, 5, size=(4000, 6)).astype(float) * 2.0**rng.integers(-30, 30, size=(4000, 1))
    a, b, c = p[:, 0:2], p[:, 2:4], p[:, 4:6]
    cols = cross_diff_cols(c[:, 0], c[:, 1], a[:, 0], a[:, 1], c[:, 0], c[:, 1], b[:, 0], b[:, 1])
    ref = [cross_diff_exact(*map(float, (c[i, 0], c[i, 1], a[i, 0], a[i, 1], c[i, 0], c[i, 1], b[i, 0], b[i, 1])))
           for i in range(len(p))]
    assert cols.tolist() == ref
    assert (cols == 0).sum() > 100  # the corpus really exercises the zeros


def test_underflowing_products_are_not_taken_as_exact():
    # (1e-200, 0) x (0, 1e-200) = 1e-400 > 0: both float products underflow to zero, and
    # TwoProduct's error terms underflow with them; the sign must still come out +1.
    v = (0.0, 0.0, 1e-200, 0.0, 0.0, 0.0, 0.0, 1e-200)
    cols = [np.array([x]) for x in v]
    assert exact(*v) == 1
    assert int(error_free_cross_sign(*cols)[0]) == 2  # undecided: left to rationals
    assert cross_diff_cols(*cols).tolist() == [1]
    assert cross_diff_sign(*v) == 1


def test_column_predicates_take_plain_scalars_in_doubt():
    # Scalars whose sign the filter cannot decide (a collinear triple, and the note's
    # near-parallel pair) reach the exact stage as 0-d arrays.
    from cspace.kernel.polygons.predicates import cross_diff_cols, orient2d_cols

    assert int(orient2d_cols(0.0, 0.0, 1.0, 1.0, 3.0, 3.0)) == 0
    assert int(orient2d_cols(0.1, 0.1, 0.3, 0.3, 0.7, 0.7)) == orient2d_xy(0.1, 0.1, 0.3, 0.3, 0.7, 0.7)
    d = 2.0**-30
    assert int(cross_diff_cols(0.0, 0.0, 1e6, 1.0, 0.0, 0.0, 2e6, 2.0 + d)) == 1


# The whole double range: subnormals, huge magnitudes, signed zeros, exact ties.
wide = st.one_of(st.floats(allow_nan=False, allow_infinity=False, width=64),
                 st.sampled_from([0.0, -0.0, 5e-324, -5e-324, 2.0**-1022, 2.0**1023, -2.0**1023]))


@settings(max_examples=600, deadline=None)
@given(st.lists(st.one_of(wide, coords), min_size=8, max_size=8))
def test_exact_fallback_equals_rationals(v):
    # The fallback scales every double to one power-of-two denominator and works in
    # Python ints: the same sign as Fractions, on any finite doubles.
    assert cross_diff_exact(*v) == exact(*v)


def test_exact_fallback_refuses_non_finite():
    import pytest

    from cspace.kernel.polygons.predicates import NonFiniteError

    for bad in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(NonFiniteError):
            cross_diff_exact(0.0, 0.0, 1.0, bad, 0.0, 0.0, 1.0, 1.0)
