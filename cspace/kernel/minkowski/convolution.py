"""Minkowski sums of convex pieces with a simple polygon, through the convolution cycle.

This module owns the convolution route of
:func:`cspace.kernel.minkowski.nonconvex.minkowski_sum_nonconvex`. For a convex polygon P and a
simple polygon Q (no holes), both CCW, the convolution cycle P * Q walks Q's
boundary. Each edge of Q is translated by the vertex of P that is extreme along
the edge's outer normal. At each vertex of Q, the walk turns from one edge
direction to the next, and the edges of P whose directions lie in that turn are
inserted, translated by the vertex: forward at a convex vertex, backward at a
reflex one.

Guibas, Ramshaw and Stolfi (1983) showed that the winding number of the cycle
around a point x (not on it) is the Euler characteristic of (x − P) ∩ Q. In the
plane, every component of that intersection is simply connected when Q has no
holes, so the winding number counts the components. P ⊕ Q is therefore exactly
the set of points of positive winding number. CGAL's convolution method rests on
the same theorem. For a non-convex A = ∪ A_i, A ⊕ Q = ∪ (A_i ⊕ Q), one cycle per
piece.

The cycle is built exactly. Each edge direction is placed among P's edge
directions by half-plane, then by the exact sign of the cross product
(:func:`cspace.kernel.polygons.predicates.cross_diff_cols`). Each turn of Q is classified by the
exact orientation test. Only the vertex sums Q[j] + P[k] are rounded, once each,
as in the convex merge. GEOS then extracts the positive-winding region. Its
buffer builder at distance 0 nodes the cycle and keeps the faces of depth ≥ 1.
All pieces go to GEOS in one vectorised call.
"""
from __future__ import annotations

import os
import threading

import numpy as np

from ..polygons.polygon import PackedPieces, orientation
from ..polygons.predicates import cross_diff_cols, lower_half, orient2d_many

# Most (Q edge, piece edge) comparisons in one vectorised block.
_BLOCK = 1 << 20


def convolution_cycles(pieces: list, Q) -> tuple[np.ndarray, np.ndarray]:
    """The convolution cycles P_i * Q of convex pieces with one simple polygon.

    ``pieces`` are strictly convex CCW arrays, each from its lowest (then
    leftmost) vertex, as :func:`cspace.kernel.polygons.decompose.convex_decompose` returns them.
    ``Q`` is a simple CCW polygon without repeated vertices. Returns the cycles'
    vertices, one cycle after another, and each cycle's vertex count.

    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> L = np.array([[0.0, 0.0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> pts, sizes = convolution_cycles([sq], L)
    >>> pts.tolist()  # at the reflex corner (1, 1): back down the square's edge
    [[3.0, 0.0], [3.0, 2.0], [2.0, 2.0], [2.0, 1.0], [2.0, 3.0], [0.0, 3.0], [0.0, 0.0]]
    >>> sizes.tolist()
    [7]
    """
    Q = np.asarray(Q, dtype=np.float64)
    packed = PackedPieces([np.asarray(p, dtype=np.float64) for p in pieces])
    if not packed.ok.all():
        bad = int(np.flatnonzero(~packed.ok)[0])
        raise ValueError(f"convolution_cycles: piece {bad} is not strictly convex, CCW from its lowest vertex")
    pts, sizes, starts, nxt = packed.pts, packed.sizes, packed.starts, packed.nxt
    Q1 = np.concatenate((Q[1:], Q[:1]))  # each edge's head
    if len(Q) < 3 or ((Q1[:, 0] == Q[:, 0]) & (Q1[:, 1] == Q[:, 1])).any() or orientation(Q) <= 0:
        raise ValueError("convolution_cycles: Q must be a CCW polygon without repeated vertices")
    # pos[t, i]: how many edges of piece i come strictly before edge t of Q in angle,
    # counted from the +x direction. Piece i's edges are in that order already, so
    # its vertex pos % n_i is the one extreme along edge t's outer normal.
    pos = np.empty((len(Q), len(pieces)), dtype=np.intp)
    fused = np.empty((len(Q), len(pieces)), dtype=bool)
    qlow = lower_half(Q1[:, 0] - Q[:, 0], Q1[:, 1] - Q[:, 1])[:, None]
    step = max(1, _BLOCK // max(len(pts), 1))
    plow = packed.half[None, :]
    for t0 in range(0, len(Q), step):
        t = slice(t0, t0 + step)
        cross = cross_diff_cols(pts[:, 0], pts[:, 1], pts[nxt, 0], pts[nxt, 1],
                                Q[t, 0, None], Q[t, 1, None], Q1[t, 0, None], Q1[t, 1, None])
        same_half = plow == qlow[t]
        before = (plow < qlow[t]) | (same_half & (cross > 0))
        pos[t] = np.add.reduceat(before, starts, axis=1)
        # Does the piece's first edge after Q's edge t run the same way (exactly)?
        first_edge = starts + pos[t] % sizes
        rows = np.arange(pos[t].shape[0])[:, None]
        fused[t] = same_half[rows, first_edge] & (cross[rows, first_edge] == 0)
    # At Q's vertex t + 1 the walk turns from edge t to edge t + 1: left (convex)
    # through the piece's edges pos_t .. pos_{t+1} - 1, right (reflex) back through
    # them, straight through none.
    turn = orient2d_many(Q, Q1, np.concatenate((Q1[1:], Q1[:1])))[:, None]
    n = sizes[None, :]
    later = np.concatenate((pos[1:], pos[:1]))
    steps = np.where(turn > 0, (later - pos) % n, -((pos - later) % n))
    # Cycle i, piece-major: at each vertex of Q, the chain of piece vertices from
    # the one serving edge t to the one serving edge t + 1 (|steps| + 1 of them).
    # When the chain starts along an edge parallel to Q's edge t (a left turn), its
    # first vertex lies inside one straight edge of the sum: it is left out, as the
    # convex merge fuses parallel edges, rather than rounded into a kink.
    skip = ((steps > 0) & fused).T.ravel()
    steps = steps.T.ravel()
    first = (pos % n).T.ravel() + np.sign(steps) * skip
    run = np.abs(steps) + 1 - skip
    total = int(run.sum())
    offset = np.arange(total) - np.repeat(np.cumsum(run) - run, run)
    ring = np.repeat(np.repeat(sizes, len(Q)), run)
    vertex = (np.repeat(first, run) + np.repeat(np.sign(steps), run) * offset) % ring
    vertex += np.repeat(np.repeat(starts, len(Q)), run)
    corner = np.repeat(np.tile((np.arange(len(Q)) + 1) % len(Q), len(pieces)), run)
    out = Q[corner] + pts[vertex]
    return out, run.reshape(len(pieces), len(Q)).sum(axis=1)


def convex_sums_with(pieces: list, Q) -> np.ndarray:
    """Each P_i ⊕ Q as a shapely polygon, for convex pieces and a simple polygon Q.

    ``pieces`` and ``Q`` as for :func:`convolution_cycles`.

    >>> L = np.array([[0.0, 0.0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> float(convex_sums_with([sq], L)[0].area)
    8.0
    """
    import shapely

    pts, sizes = convolution_cycles(pieces, Q)
    rings = shapely.linearrings(pts, indices=np.repeat(np.arange(len(sizes)), sizes))
    # Depth >= 1 of the (self-overlapping) ring: the points of positive winding number.
    return _buffer_zero(shapely.polygons(rings), sizes)


# Cycles with fewer vertices in all than this are buffered on one thread: below it,
# starting a thread (about 50 us) costs more than half the work saves.
_THREAD_MIN_VERTICES = 256


def _buffer_zero(polys: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """``shapely.buffer(polys, 0)``, split over threads when it pays.

    GEOS releases the GIL, and each cycle is buffered on its own, so chunks of about
    equal vertex counts run in parallel with the same results. ``CSPACE_THREADS``
    caps the threads (1: none); the default is the machine's cores, at most 4. A
    thread is started per call, never kept, so a process forked later finds no pool.
    """
    import shapely

    workers = min(_threads(), len(polys))
    if workers < 2 or int(sizes.sum()) < _THREAD_MIN_VERTICES:
        return shapely.buffer(polys, 0.0)
    # Chunk boundaries at equal shares of the vertices.
    cuts = np.searchsorted(np.cumsum(sizes), np.arange(1, workers) * (sizes.sum() / workers))
    chunks = np.split(polys, np.unique(np.clip(cuts + 1, 1, len(polys) - 1)))
    out: list = [None] * len(chunks)
    errors: list = []

    def run(i: int) -> None:
        try:
            out[i] = shapely.buffer(chunks[i], 0.0)
        except BaseException as exc:  # re-raised in the caller's thread
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(i,), daemon=True) for i in range(1, len(chunks))]
    for t in threads:
        t.start()
    run(0)
    for t in threads:
        t.join()
    if errors:
        raise errors[0]
    return np.concatenate(out)


def _threads() -> int:
    """Threads for GEOS work: ``CSPACE_THREADS`` if set, else the cores, at most 4."""
    env = os.environ.get("CSPACE_THREADS", "")
    if env.strip().isdigit() and int(env) >= 1:
        return int(env)
    return max(1, min(4, os.cpu_count() or 1))
