"""Batched pairwise sums against the scalar merge, array for array."""
import numpy as np
from hypothesis import given, settings

from convex_pieces import piece_lists
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.kernel.minkowski.pairsums import pairwise_sums


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
    from cspace.kernel.polygons.decompose import convex_decompose
    from test_decompose import comb

    th = np.radians(30)
    R = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
    pa, pb = convex_decompose(comb(8)), convex_decompose(comb(5, 0.5, 1.0, 3.0, 0.5) @ R)
    for g, r in zip(pairwise_sums(pa, pb), [minkowski_sum(a, b) for a in pa for b in pb]):
        assert np.array_equal(g, r)
