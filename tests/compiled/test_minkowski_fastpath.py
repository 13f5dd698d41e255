"""The public minkowski_sum takes the compiled pair sum for two small convex polygons
(cspace.compiled.fastpath registers it in cspace.kernel.minkowski.merge's hook) and gives the very
arrays of the pure route: exact integer sums, rounded float sums, either orientation, any start."""
from __future__ import annotations

import numpy as np
import pytest

from cspace.kernel.minkowski import merge as mk
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.compiled import fastpath

needs_c = pytest.mark.skipif(not fastpath.compiled(), reason="compiled fast path not built (or CSPACE_PURE=1)")


def random_convex(n, rng, span=2**20):
    """n integer vertices, CCW: n random edge vectors sorted by angle, summed (Valtr)."""
    while True:
        v = rng.integers(-span, span, size=(n, 2))
        v[-1] = -v[:-1].sum(axis=0)
        ang = np.arctan2(v[:, 1], v[:, 0])
        if len(np.unique(ang)) == n:
            p = np.cumsum(v[np.argsort(ang)], axis=0).astype(np.float64)
            return p - p.min(axis=0)


def cases(seed=0, count=300):
    rng = np.random.default_rng(seed)
    for k in range(count):
        P, Q = random_convex(int(rng.integers(3, 12)), rng), random_convex(int(rng.integers(3, 12)), rng)
        if k % 3 == 1:  # floats: rounded sums, the certified repair
            P, Q = P * 0.1 + 0.05, Q * 1e-3 - 7.3
        P, Q = np.roll(P, int(rng.integers(len(P))), axis=0), np.roll(Q, int(rng.integers(len(Q))), axis=0)
        if k % 5 == 2:
            P = P[::-1]  # clockwise: the pure route's business
        if k % 7 == 3:  # a horizontal bottom edge
            Q = np.array([[0.0, 0.0], [3.0, 0.0], [2.0, 1.0]])
        yield P, Q


def pure(P, Q):
    with fastpath.disabled():
        saved = mk.use_pair_sum(None)
        try:
            return minkowski_sum(P, Q)
        finally:
            mk.use_pair_sum(saved)


@needs_c
def test_registered_when_compiled():
    assert mk._pair_sum is fastpath.pair_sums


@needs_c
def test_fast_route_equals_pure_route():
    served = []

    def counting(pa, pb):
        out = fastpath.pair_sums(pa, pb)
        served.append(out is not None and out[0] is not None)
        return out

    saved = mk.use_pair_sum(counting)
    try:
        for P, Q in cases():
            fast = minkowski_sum(P, Q)
            ref = pure(P, Q)
            assert fast.dtype == ref.dtype == np.float64
            assert np.array_equal(fast, ref), (P.tolist(), Q.tolist())
            assert np.signbit(fast).tolist() == np.signbit(ref).tolist()  # no -0.0 where the pure route has 0.0
            fast[0, 0] = np.nan  # the caller owns its array (not a view of a shared buffer)
    finally:
        mk.use_pair_sum(saved)
    assert sum(served) >= len(served) // 2, "the compiled merge served too few of the pairs"


def test_disabled_is_the_pure_route():
    P, Q = next(cases(1, 1))
    with fastpath.disabled():
        a = minkowski_sum(P, Q)
    assert np.array_equal(a, pure(P, Q))
    assert np.array_equal(minkowski_sum(P, Q), a)


def test_faulty_operands_still_refused():
    # All left turns but winding twice (a pentagram), and a dent: the pure route's ValueError.
    import math

    star = np.array([[math.cos(a), math.sin(a)] for a in (math.pi / 2 + 4 * math.pi * k / 5 for k in range(5))])
    dent = np.array([[0.0, 0.0], [4.0, 0.0], [2.0, 1.0], [4.0, 4.0], [0.0, 4.0]])
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    for bad in (star, dent):
        with pytest.raises(ValueError):
            minkowski_sum(bad, sq)
        with pytest.raises(ValueError):
            pure(bad, sq)
