"""All pairwise Minkowski sums A_i ⊕ B_j of two lists of small convex polygons, batched.

This module owns the batched angular merge. Each piece is CCW from its lowest
(then leftmost) vertex, so its edges are already in angular order; the merge of a
pair is then fixed by edge-versus-edge comparisons alone, and all of them are one
vectorised pass over every edge of A against every edge of B: half-plane first,
then the exact sign of the cross product (:func:`cspace.kernel.polygons.predicates.cross_diff_cols`).
An edge a of A_i that has k predecessors in A_i and l edges of B_j strictly before
it starts at the sum vertex A_i[k] + B_j[l]; an edge of B_j likewise, unless an
edge of A_i has its exact direction (then the two are fused, one vertex). So every
output vertex is one vertex of A_i plus one of B_j, rounded once, exactly as
:func:`cspace.kernel.minkowski.merge.minkowski_sum` computes it.

A pair is accepted when its vertex sums were exact (Fast2Sum test) or its rounded
output turns strictly left at every vertex (exact test); otherwise its rounded
vertices are replaced by their exact convex hull, the repair ``minkowski_sum``
makes. A piece that is not strictly convex and canonical goes, with all its pairs,
to :func:`cspace.kernel.minkowski.merge.minkowski_sum`. The result equals ``minkowski_sum(a, b)``
for every pair, array for array.
"""
from __future__ import annotations

import numpy as np

from ..polygons.hull import ring_hulls
from .merge import minkowski_sum
from ..polygons.polygon import PackedPieces, ring_neighbours
from ..polygons.predicates import cross_diff_cols, orient2d_many


def pairwise_sums(pa: list, pb: list) -> list[np.ndarray]:
    """``[minkowski_sum(a, b) for a in pa for b in pb]``, computed in one batch.

    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> tri = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    >>> [s.tolist() for s in pairwise_sums([sq], [tri])]
    [[[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [1.0, 3.0], [0.0, 3.0]]]
    """
    pa = [np.asarray(p, dtype=np.float64) for p in pa]
    pb = [np.asarray(p, dtype=np.float64) for p in pb]
    if any(p.ndim != 2 or p.shape[1:] != (2,) or len(p) == 0 for p in pa + pb):
        raise ValueError("pairwise_sums: every piece must be a non-empty (N, 2) array of vertices")
    if not pa or not pb:
        return []
    A, B = PackedPieces(pa), PackedPieces(pb)
    out: list = [None] * (len(pa) * len(pb))
    if A.ok.any() and B.ok.any():
        _batch(A, B, out)
    for p in range(len(out)):
        if out[p] is None:
            out[p] = minkowski_sum(pa[p // len(pb)], pb[p % len(pb)])
    return out


def _batch(A: PackedPieces, B: PackedPieces, out: list) -> None:
    nb = len(B.sizes)
    a0, a1, b0, b1 = A.pts, A.pts[A.nxt], B.pts, B.pts[B.nxt]
    # cross[a, b] = sign of edge_a x edge_b (exact); > 0: b turns CCW from a (a first).
    cross = cross_diff_cols(a0[:, None, 0], a0[:, None, 1], a1[:, None, 0], a1[:, None, 1],
                            b0[None, :, 0], b0[None, :, 1], b1[None, :, 0], b1[None, :, 1])
    ha, hb = A.half[:, None], B.half[None, :]
    b_first = (hb < ha) | ((hb == ha) & (cross < 0))
    a_first = (ha < hb) | ((ha == hb) & (cross > 0))
    same = (ha == hb) & (cross == 0)
    lt_a = np.add.reduceat(b_first.view(np.int8).astype(np.intp), B.starts, axis=1)  # (edges of A, pieces of B)
    lt_b = np.add.reduceat(a_first.view(np.int8).astype(np.intp), A.starts, axis=0)  # (pieces of A, edges of B)
    fused = np.add.reduceat(same.view(np.int8).astype(np.intp), A.starts, axis=0) > 0
    # Events of A's edges: every (edge a, piece j); of B's edges: (piece i, edge b) unless fused.
    ea_i = np.repeat(A.piece, nb)
    ea_j = np.tile(np.arange(nb), len(A.pts))
    ea_k = np.repeat(A.local, nb)
    ea_l = lt_a.ravel()
    keep = ~fused.ravel()
    eb_i = np.repeat(np.arange(len(A.sizes)), len(B.pts))[keep]
    eb_j = np.tile(B.piece, len(A.sizes))[keep]
    eb_l = np.tile(B.local, len(A.sizes))[keep]
    eb_k = lt_b.ravel()[keep]
    i = np.concatenate([ea_i, eb_i])
    j = np.concatenate([ea_j, eb_j])
    k = np.concatenate([ea_k, eb_k])
    l = np.concatenate([ea_l, eb_l])
    pair = i * nb + j
    order = np.lexsort((k + l, pair))  # along each pair's lattice path k + l strictly grows
    pair, i, j, k, l = pair[order], i[order], j[order], k[order], l[order]
    va = A.pts[A.starts[i] + k % A.sizes[i]]
    vb = B.pts[B.starts[j] + l % B.sizes[j]]
    s = va + vb
    with np.errstate(invalid="ignore", over="ignore"):
        inexact = ((s - va != vb) | (s - vb != va)).any(axis=1)
    counts = np.bincount(pair, minlength=len(A.sizes) * nb)
    ends = np.cumsum(counts)
    starts = ends - counts
    doubt = np.bincount(pair[inexact], minlength=len(counts)) > 0
    if doubt.any():  # rounded pairs: accept those whose output turns strictly left everywhere
        prv, nxt = ring_neighbours(counts)
        sel = np.flatnonzero(doubt[pair])
        turn = orient2d_many(s[prv[sel]], s[sel], s[nxt[sel]])
        doubt[:] = np.bincount(pair[sel[turn <= 0]], minlength=len(counts)) > 0
    good = np.repeat(A.ok, nb) & np.tile(B.ok, len(A.ok))
    for p in np.flatnonzero(good & ~doubt).tolist():
        out[p] = s[starts[p]:ends[p]]
    bad = np.flatnonzero(good & doubt)
    if bad.size:  # a rounded turn that is not strictly left: minkowski_sum's repair, the exact hull
        rings = np.concatenate([s[starts[p]:ends[p]] for p in bad.tolist()])
        for p, h in zip(bad.tolist(), ring_hulls(rings, counts[bad])):
            out[p] = h
