"""Batched pairwise sums against the scalar merge, array for array."""
import numpy as np
from hypothesis import given, settings, strategies as st

from cspace.kernel.hull import convex_hull
from cspace.kernel.minkowski import minkowski_sum
from cspace.kernel.pairsums import pairwise_sums


def convex_piece(draw, integer):
    k = draw(st.integers(3, 9))
    if integer:  # small integer grid: many parallel and collinear edges
        pts = draw(st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), min_size=k, max_size=k))
        p = convex_hull(np.array(pts, dtype=np.float64))
    else:
        seed = draw(st.integers(0, 2**31))
        rng = np.random.default_rng(seed)
        a = np.sort(rng.uniform(0, 2 * np.pi, k))
        p = np.c_[np.cos(a), np.sin(a)] * rng.uniform(0.1, 10) + rng.uniform(-5, 5, 2)
        if draw(st.booleans()):  # a rotated rectangle: exactly parallel pairs after rounding are rare, near ones common
            t = rng.uniform(0, np.pi)
            u, v = np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])
            p = np.array([0 * u, 3 * u, 3 * u + v, v])
        p = convex_hull(p)
    return p


@st.composite
def piece_lists(draw):
    integer = draw(st.booleans())
    n, m = draw(st.integers(1, 4)), draw(st.integers(1, 4))
    return [convex_piece(draw, integer) for _ in range(n)], [convex_piece(draw, integer) for _ in range(m)]


@settings(max_examples=300, deadline=None)
@given(piece_lists())
def test_batch_equals_scalar_sums(lists):
    pa, pb = lists
    got = pairwise_sums(pa, pb)
    ref = [minkowski_sum(a, b) for a in pa for b in pb]
    assert len(got) == len(ref)
    for g, r in zip(got, ref):
        assert np.array_equal(g, r), (g, r)


def test_degenerate_and_non_canonical_pieces_fall_back():
    seg = np.array([[0.0, 0.0], [1.0, 1.0]])
    cw_square = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]])
    tri = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    pa, pb = [seg, cw_square, tri], [tri, cw_square]
    for g, r in zip(pairwise_sums(pa, pb), [minkowski_sum(a, b) for a in pa for b in pb]):
        assert np.array_equal(g, r)


def test_comb_pieces_match():
    from cspace.kernel.decompose import convex_decompose
    from test_decompose import comb

    th = np.radians(30)
    R = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
    pa, pb = convex_decompose(comb(8)), convex_decompose(comb(5, 0.5, 1.0, 3.0, 0.5) @ R)
    for g, r in zip(pairwise_sums(pa, pb), [minkowski_sum(a, b) for a in pa for b in pb]):
        assert np.array_equal(g, r)
