"""The Hertel-Mehlhorn merge on successor maps (O(n log n)) returns the list-based
merge's cycles exactly: the same pieces, in the same order, each read from the same
vertex. The list-based merge (O(n^2) on a star) is kept here as the oracle."""
import math

import numpy as np
import pytest

from cspace.kernel.polygons import decompose as dc
from cspace.kernel.polygons.polygon import normalize
from cspace.kernel.polygons.predicates import CCW_ERRBOUND_A, orient2d_xy


def reference(tris, pts, diagonals):
    pieces = {k: t for k, t in enumerate(tris.tolist())}
    owner = {}
    for k, (a, b, c) in pieces.items():
        owner[(a, b)] = owner[(b, c)] = owner[(c, a)] = k
    xy = pts.tolist()
    for u, v in diagonals:
        a, b = owner.get((u, v)), owner.get((v, u))
        if a is None or b is None or a == b:
            continue
        q = pieces[b]
        merged = merge_reference(pieces[a], q, u, v, xy, owner)
        if merged is None:
            continue
        del pieces[b]
        pieces[a] = merged
        for e in zip(q, q[1:] + q[:1]):
            if owner.get(e) == b:
                owner[e] = a
        owner.pop((u, v), None)
        owner.pop((v, u), None)
    return list(pieces.values())


def merge_reference(p, q, u, v, xy, owner):
    i, j = p.index(u), q.index(v)
    merged = p[i + 1:] + p[:i] + q[j + 1:] + q[:j]
    n = len(merged)
    straight = []
    for k in (n - len(q) + 1, 0):
        (ax, ay), (bx, by), (cx, cy) = xy[merged[k - 1]], xy[merged[k]], xy[merged[(k + 1) % n]]
        left, right = (ax - cx) * (by - cy), (ay - cy) * (bx - cx)
        bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
        if left - right > bound > 1e-280:
            continue
        turn = -1 if right - left > bound > 1e-280 else orient2d_xy(ax, ay, bx, by, cx, cy)
        if turn < 0:
            return None
        if turn == 0:
            straight.append(k)
    for k in sorted(straight, reverse=True):
        owner.pop((merged[k - 1], merged[k]), None)
        owner.pop((merged[k], merged[(k + 1) % len(merged)]), None)
        del merged[k]
    return merged


def inputs(shell, holes=()):
    shell = normalize(shell)
    holes = [normalize(h, ccw=False) for h in holes]
    rings = [shell] + holes
    pts = np.concatenate(rings) if holes else shell
    tris = dc._triangulate(rings, pts)
    diagonals = dc._diagonals(tris)
    rank = dc._diagonal_ranks(rings, pts, diagonals)
    vec = pts[diagonals[:, 0]] - pts[diagonals[:, 1]]
    order = np.lexsort((-np.hypot(vec[:, 0], vec[:, 1]), rank))
    return tris, pts, diagonals[order].tolist()


def star(n, r0=10.0, r1=4.0):
    a = np.arange(n) * 2 * math.pi / n
    r = np.where(np.arange(n) % 2 == 0, r0, r1)
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


CASES = {
    "star": (star(200), []),
    "integer star": (np.round(star(60) * 4), []),
    "square with holes": (np.array([[0., 0], [20, 0], [20, 20], [0, 20]]),
                          [np.array([[2., 2], [4, 2], [3, 5]]), np.array([[10., 10], [14, 10], [14, 12], [10, 12]])]),
    "collinear runs": (np.array([[0., 0], [1, 0], [2, 0], [3, 0], [3, 1], [2, 1], [2, 2], [1, 2], [1, 1], [0, 1]]), []),
}


@pytest.mark.parametrize("name", list(CASES))
def test_merge_equals_the_list_based_one(name):
    shell, holes = CASES[name]
    tris, pts, diags = inputs(shell, holes)
    assert dc._hertel_mehlhorn(tris, pts, diags) == reference(tris, pts, diags)


@pytest.mark.parametrize("seed", range(8))
def test_random_simple_polygons(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 60))
    a = (np.arange(n) + rng.uniform(0, 0.6, n)) * 2 * math.pi / n
    r = rng.uniform(1, 10, n)
    shell = np.column_stack([r * np.cos(a), r * np.sin(a)])
    if seed % 2:
        shell = np.round(shell)  # integer coordinates: collinear and straight corners happen
        shell = shell[np.r_[True, (np.diff(shell, axis=0) != 0).any(axis=1)]]
    try:
        tris, pts, diags = inputs(shell)
    except ValueError:
        pytest.skip("rounding made the ring invalid")
    assert dc._hertel_mehlhorn(tris, pts, diags) == reference(tris, pts, diags)
