"""ring_hulls (many nearly convex rings at once) equals convex_hull, ring for ring.

Oracle: the exact monotone chain (cspace.kernel.polygons.hull.convex_hull), on rings that are
convex up to rounding (rounded sums of disks and of random convex pieces, the case the
batched pair sums repair), and on rings that are not convex at all (random points,
repeated and collinear points, rings of fewer than three distinct points), where the
peeling must notice and fall back.
"""
import numpy as np
from hypothesis import given, settings, strategies as st

from cspace.kernel.polygons.disk import disk_polygon
from cspace.kernel.polygons.hull import convex_hull, ring_hulls
from cspace.kernel.minkowski.merge import minkowski_sum


def check(rings):
    got = ring_hulls(np.concatenate(rings) if rings else np.zeros((0, 2)), [len(r) for r in rings])
    assert len(got) == len(rings)
    for r, h in zip(rings, got):
        assert np.array_equal(h, convex_hull(r)), (r, h)


def rounded_sum_ring(rng):
    """The vertices of a disk ⊕ disk ⊕ convex piece sum, each rounded once more by a
    random shift and back (so nearly collinear, sometimes not strictly convex)."""
    a = disk_polygon(tuple(rng.uniform(-50, 50, 2)), float(rng.uniform(0.1, 5)), max_error=float(rng.choice([1e-3, 1e-4])))
    b = disk_polygon((0.0, 0.0), float(rng.uniform(0.01, 1)), max_error=1e-3)
    s = minkowski_sum(a, b)
    shift = rng.uniform(-1e3, 1e3, 2)
    return (s + shift) - shift


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_nearly_convex_rings(seed):
    rng = np.random.default_rng(seed)
    check([rounded_sum_ring(rng) for _ in range(int(rng.integers(1, 6)))])


def test_nearly_convex_rings_are_peeled_not_handed_back(monkeypatch):
    # The point of ring_hulls: rounded sums are peeled in numpy, convex_hull is the
    # rare fallback. Some rings really lose vertices (non-left rounded turns).
    import cspace.kernel.polygons.hull as hull

    rng = np.random.default_rng(11)
    rings = [rounded_sum_ring(rng) for _ in range(40)]
    calls = []
    monkeypatch.setattr(hull, "convex_hull", lambda r: calls.append(1) or convex_hull(r))
    got = hull.ring_hulls(np.concatenate(rings), [len(r) for r in rings])
    monkeypatch.undo()
    assert not calls
    assert sum(len(r) - len(h) for r, h in zip(rings, got)) > 0
    assert all(np.array_equal(h, convex_hull(r)) for r, h in zip(rings, got))


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_arbitrary_rings_fall_back(seed):
    rng = np.random.default_rng(seed)
    rings = []
    for _ in range(int(rng.integers(1, 6))):
        kind = rng.integers(0, 4)
        n = int(rng.integers(1, 12))
        if kind == 0:  # random points in random order
            rings.append(rng.integers(-5, 5, (n, 2)).astype(float))
        elif kind == 1:  # a convex ring with repeats and collinear midpoints
            c = convex_hull(rng.integers(-9, 9, (n + 3, 2)).astype(float))
            if len(c) < 3:
                c = np.array([[0.0, 0], [1, 0], [0, 1]])
            mids = (c + np.roll(c, -1, axis=0)) / 2
            ring = np.empty((2 * len(c), 2))
            ring[0::2], ring[1::2] = c, mids
            rings.append(np.repeat(ring, rng.integers(1, 3, len(ring)), axis=0))
        elif kind == 2:  # a star-shaped but reflex ring
            ang = np.sort(rng.uniform(0, 2 * np.pi, n + 3))
            rad = rng.uniform(0.2, 1.0, n + 3)
            rings.append(np.column_stack([rad * np.cos(ang), rad * np.sin(ang)]))
        else:  # a convex ring listed clockwise
            c = convex_hull(rng.uniform(-1, 1, (n + 3, 2)))
            rings.append(c[::-1].copy())
    check(rings)
