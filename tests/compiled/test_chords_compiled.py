"""The compiled chord polygons (cspace/compiled/_chords.c) against the numpy route, value for value.

Both feed the grid's classification; equal chord polygons and sagittas mean equal grids
on the compiled and pure paths (tests/compiled/test_fastpath.py compares those too)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from cspace.kernel.polygons.chords import chord_polygons
from cspace.kernel.polygons.disk import disk_polygon
from cspace.kernel.polygons.hull import convex_hull
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.compiled import fastpath

pytestmark = pytest.mark.skipif(not fastpath.compiled(), reason="compiled fast path not built")


def padded(pieces):
    sizes = np.array([len(p) for p in pieces], dtype=np.int64)
    Q = np.zeros((len(pieces), int(sizes.max()), 2))
    for r, p in enumerate(pieces):
        Q[r, : len(p)] = p
    return Q, sizes


def same(pieces, long_edge, tolerance):
    Q, sizes = padded(pieces)
    R0, n0, s0 = chord_polygons(Q.copy(), sizes, long_edge, tolerance)
    R1, n1, s1 = fastpath.chord_polygons(Q.copy(), sizes, long_edge, tolerance)
    assert n0.tolist() == n1.tolist() and R0.shape == R1.shape and s0.shape == s1.shape
    for k, n in enumerate(n0.tolist()):
        assert np.array_equal(R0[k, :n], R1[k, :n])
        assert np.array_equal(s0[k, :n], s1[k, :n], equal_nan=True)
    return n0


@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 6), st.sampled_from([1e-6, 1.0, 1e4]),
       st.floats(0.01, 5.0), st.floats(0.001, 1.0))
def test_rounded_pieces(seed, k, scale, long_edge, tolerance):
    rng = np.random.default_rng(seed)
    pieces = []
    for _ in range(k):
        core = convex_hull(rng.normal(0, 3, (int(rng.integers(1, 8)), 2)))
        disk = disk_polygon((0.0, 0.0), float(rng.uniform(0.05, 3)), max_error=float(rng.choice([1e-2, 1e-3, 1e-4])))
        pieces.append((minkowski_sum(core, disk) + rng.uniform(-50, 50, 2)) * scale)
    same(pieces, long_edge * scale, tolerance * scale)


def test_degenerate_pieces_give_the_same_nans():
    point = np.zeros((70, 2)) + 5.0  # a disk that rounded to a point: zero-length chords, NaN sagittas
    tiny = disk_polygon((1e-300, 0.0), 1e-300, max_error=1e-303)
    huge = disk_polygon((0.0, 0.0), 1e307, sides=80)
    n = same([point, tiny, huge, disk_polygon((3.0, 4.0), 2.0, max_error=1e-4)], 0.5, 0.01)
    assert n[-1] < len(disk_polygon((3.0, 4.0), 2.0, max_error=1e-4))  # really approximated
