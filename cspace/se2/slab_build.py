"""Many SE(2) slabs built at once: the slab hulls, inner sets, pair sums and C-spaces of a run of slabs.

This module owns the batched build of :class:`cspace.se2.cspace.SE2CSpace`'s slabs. Slab k is a
translational C-space of the robot pieces' slab hulls (:func:`cspace.kernel.slabs.slab.slab_hull`) and
a grid of certified-blocked cells over the obstacles summed with the pieces' inner sets
(:func:`cspace.kernel.slabs.slab.slab_inner`). Built one by one, each slab pays the same Python
work again: the decomposition stages, the packing of the obstacles, the hull of each
rotated piece, the clipping of each inner set, one pair-sum call per set. Here a run of
slabs shares all of it:

- the rotations of every robot piece to every slab's angles are one numpy product each
  (the same IEEE operations, in the same order, as :func:`cspace.kernel.slabs.slab.rotate`,
  with ``math.cos``/``math.sin`` of the same angles), their hulls one
  :func:`cspace.kernel.polygons.hull.ring_hulls` call (its answer is ``convex_hull``'s, array for
  array), the pads one :func:`cspace.translation.build.pair_sums` call per pad value;
- the inner sets' half-plane clipping runs on every slab at once, vertex for vertex the
  scalar loop's arithmetic (:func:`slab_inners`);
- one :func:`cspace.translation.build.pair_sums` call sums the obstacle pieces with the
  hulls and inner sets of every slab of the run (compiled: one C call);
- each slab's C-space is then :meth:`cspace.translation.cspace.CSpace.from_sums` (the prune and
  the grid of ``CSpace``, without its decomposition and sum stages).

Every array is the one the slab-by-slab route computes (tests/compiled/test_slab_builds.py checks
pieces, grids and answers against it and against the pure path), so this is a faster
route to the same slabs, not another approximation.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..compiled import fastpath
from ..translation.broadphase import GridIndex
from ..translation.cspace import CSpace
from ..translation.build import check_range, pair_sums
from ..kernel.polygons.hull import convex_hull, ring_hulls
from ..kernel.minkowski.merge import reflect
from ..kernel.polygons.pieces import PieceSet
from ..kernel.polygons.polygon import ring_neighbours
from ..kernel.polygons.predicates import orient2d_many
from ..kernel.slabs.slab import ANGLE_SLACK, edge_planes, slab_hull, slab_inner, slab_pad  # noqa: F401 (slab_inner: the doctests)

# A run of slabs is built together up to about this many (obstacle piece, robot set) pairs
# (hulls and inner sets of all its slabs): a scene of a few hundred pieces gets all its
# slabs at once, a big one smaller runs (the slabs stay lazy at the run's granularity).
SLAB_BATCH_PAIRS = 1 << 14


def slab_run(k: int, K: int, pairs_per_slab: int) -> range:
    """The run of slabs built with slab k: K / 2^i consecutive slabs (the largest run within
    :data:`SLAB_BATCH_PAIRS`), aligned, holding k.

    >>> slab_run(5, 64, 100), slab_run(5, 64, 1 << 13), slab_run(5, 64, 1 << 20), slab_run(9, 10, 1)
    (range(0, 64), range(4, 6), range(5, 6), range(0, 10))
    """
    n = K
    while n > 1 and n * max(pairs_per_slab, 1) > SLAB_BATCH_PAIRS:
        n = (n + 1) // 2
    start = (k // n) * n
    return range(start, min(start + n, K))


def _rotations(angles: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """``math.cos`` and ``math.sin`` of each angle (the doubles :func:`rotate` uses), as columns."""
    return (np.array([math.cos(t) for t in angles])[:, None], np.array([math.sin(t) for t in angles])[:, None])


def _rotated(p: np.ndarray, c: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rotate` of ``p`` by each row's angle: (K, n) x and y, the same doubles."""
    x, y = p[:, 0][None, :], p[:, 1][None, :]
    return x * c - y * s + 0.0, x * s + y * c + 0.0


def _ring_order(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Per row, the points' order by angle about their mean (a ring for ring_hulls to peel;
    any order gives convex_hull's answer, this one makes its first peel the usual last)."""
    ang = np.arctan2(y - y.mean(axis=1, keepdims=True), x - x.mean(axis=1, keepdims=True))
    return np.argsort(ang, axis=1, kind="stable")


def slab_hulls(pieces: list[np.ndarray], lo: list[float], hi: list[float], scale: float) -> list[list[np.ndarray]]:
    """``[[slab_hull(p, lo[k], hi[k], scale=scale) for p in pieces] for k in range(len(lo))]``,
    equal array for array, for all the slabs at once.

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> lo, hi = [0.0, 0.5, 1.0], [0.5, 1.0, 1.0 + math.pi / 2]
    >>> all(np.array_equal(h, slab_hull(sq, a, b, scale=3.0)) for hs, a, b in zip(slab_hulls([sq], lo, hi, 3.0), lo, hi)
    ...     for h in hs)
    True
    """
    K = len(lo)
    out: list[list] = [[None] * len(pieces) for _ in range(K)]
    rows = [k for k in range(K) if hi[k] > lo[k] and hi[k] - lo[k] <= 0.5 * math.pi + 4 * ANGLE_SLACK]
    for k in set(range(K)) - set(rows):  # a zero-width slab, or an error: slab_hull's own answer
        out[k] = [slab_hull(p, lo[k], hi[k], scale=scale) for p in pieces]
    if not rows or not pieces:
        return out
    a = [float(lo[k]) for k in rows]
    half = [0.5 * (float(hi[k]) - t) for k, t in zip(rows, a)]
    m = [t + h for t, h in zip(a, half)]
    ca, sa = _rotations(a)
    cb, sb = _rotations([float(hi[k]) for k in rows])
    cm, sm = _rotations(m)
    ch = np.array([math.cos(h) for h in half])[:, None]
    rings_x, rings_y, sizes, pads = [], [], [], []
    for p in pieces:
        p = np.asarray(p, dtype=np.float64)
        ax, ay = _rotated(p, ca, sa)
        bx, by = _rotated(p, cb, sb)
        mx, my = _rotated(p, cm, sm)
        mx, my = mx / ch, my / ch  # the apexes: the end tangents meet at R_m v / cos(Δ/2)
        r = np.maximum(np.abs(mx).max(axis=1), np.abs(my).max(axis=1)) * math.sqrt(2.0)
        pads.append([slab_pad(max(float(v), float(scale))) for v in r.tolist()])
        x, y = np.concatenate([ax, bx, mx], axis=1), np.concatenate([ay, by, my], axis=1)
        order = _ring_order(x, y)
        rings_x.append(np.take_along_axis(x, order, axis=1))
        rings_y.append(np.take_along_axis(y, order, axis=1))
        sizes.append(x.shape[1])
    # rings row-major: slab (row) r, piece j
    pts = np.stack([np.concatenate([rx[r] for rx in rings_x]) for r in range(len(rows))])
    pts = np.column_stack([pts.ravel(), np.stack([np.concatenate([ry[r] for ry in rings_y])
                                                  for r in range(len(rows))]).ravel()])
    hulls = ring_hulls(pts, np.tile(sizes, len(rows)))
    by_pad: dict[float, list[int]] = {}
    for t in range(len(hulls)):
        by_pad.setdefault(pads[t % len(pieces)][t // len(pieces)], []).append(t)
    for d, ts in by_pad.items():
        square = np.array([[-d, -d], [d, -d], [d, d], [-d, d]])
        for t, h in zip(ts, pair_sums([hulls[t] for t in ts], [square])):
            out[rows[t // len(pieces)]][t % len(pieces)] = h
    return out


def _clip_all(X: np.ndarray, Y: np.ndarray, n: np.ndarray, ux: np.ndarray, uy: np.ndarray, off: np.ndarray):
    """:func:`cspace.kernel.slabs.slab._clip_halfplane` of every row's polygon (its first n[r] vertices
    of X, Y) by its own half-plane ux x + uy y <= off, the same points in the same order."""
    R, M = X.shape
    t = np.arange(M)[None, :]
    valid = t < n[:, None]
    prv = np.where(t == 0, np.maximum(n[:, None] - 1, 0), t - 1)
    PX, PY = np.take_along_axis(X, prv, axis=1), np.take_along_axis(Y, prv, axis=1)
    fq = ux[:, None] * X + uy[:, None] * Y - off[:, None]
    fp = ux[:, None] * PX + uy[:, None] * PY - off[:, None]
    q_in = fq <= 0.0
    cut = valid & ((q_in & (fp > 0.0)) | (~q_in & (fp <= 0.0)))
    keep = valid & q_in
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        s = fp / (fp - fq)
        IX = PX + (X - PX) * s
        IY = PY + (Y - PY) * s
    count = cut.astype(np.int64) + keep
    new_n = count.sum(axis=1)
    W = max(int(new_n.max()) if R else 0, 1)
    start = np.cumsum(count, axis=1) - count
    NX, NY = np.zeros((R, W)), np.zeros((R, W))
    r, c = np.nonzero(cut)
    NX[r, start[r, c]], NY[r, start[r, c]] = IX[r, c], IY[r, c]
    r, c = np.nonzero(keep)
    pos = start[r, c] + cut[r, c]
    NX[r, pos], NY[r, pos] = X[r, c], Y[r, c]
    return NX, NY, new_n


def slab_inners(pieces: list[np.ndarray], lo: list[float], hi: list[float], pad: float) -> list[list[np.ndarray]]:
    """``[[slab_inner(p, lo[k], hi[k], pad) for p in pieces] for k in range(len(lo))]``, equal
    array for array, for all the slabs at once: the clipping of every slab's polygon by its
    turned half-planes in one numpy pass per half-plane (each point the scalar loop's
    doubles, kept or dropped by the same comparisons), the hulls by one
    :func:`cspace.kernel.polygons.hull.ring_hulls` call, the final turn by the same rotation and
    exact turn test as :func:`cspace.kernel.slabs.slab.rotate_piece`.

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> lo, hi = [0.0, 0.5, -3.0], [0.5, 1.0, -2.9]
    >>> all(np.array_equal(j, slab_inner(sq, a, b, 1e-12)) for js, a, b in zip(slab_inners([sq], lo, hi, 1e-12), lo, hi)
    ...     for j in js)
    True
    """
    K = len(lo)
    out: list[list] = [[np.zeros((0, 2))] * len(pieces) for _ in range(K)]
    if not K or not pieces:
        return out
    half = [0.5 * (float(b) - float(a)) for a, b in zip(lo, hi)]
    m = [float(a) + h for a, h in zip(lo, half)]
    ch = np.array([math.cos(h) for h in half])
    sh = np.array([math.sin(h) for h in half])
    found = []  # (slab, piece, X row, Y row, n)
    for j, p in enumerate(pieces):
        p = np.asarray(p, dtype=np.float64)
        box = 2.0 * float(np.hypot(p[:, 0], p[:, 1]).max())
        X = np.tile(np.array([-box, box, box, -box]), (K, 1))
        Y = np.tile(np.array([-box, -box, box, box]), (K, 1))
        n = np.full(K, 4, dtype=np.int64)
        alive = np.ones(K, dtype=bool)
        for nx, ny, c, ln in edge_planes(p):
            low = 4.0 * pad * ln
            for ux, uy, off in ((nx * ch - ny * sh, nx * sh + ny * ch, np.full(K, c - low)),
                                (nx * ch + ny * sh, -nx * sh + ny * ch, np.full(K, c - low)),
                                (np.full(K, nx), np.full(K, ny), c * ch - low)):
                X, Y, n = _clip_all(X, Y, n, ux, uy, off)
            alive &= n >= 3
            n = np.where(alive, n, 0)  # slab_inner returns the empty piece there
        for k in np.flatnonzero(alive).tolist():
            found.append((k, j, X[k, :n[k]], Y[k, :n[k]]))
    if not found:
        return out
    sizes = [len(f[2]) for f in found]
    hulls = ring_hulls(np.column_stack([np.concatenate([f[2] for f in found]), np.concatenate([f[3] for f in found])]),
                       sizes)
    keep = [t for t, h in enumerate(hulls) if len(h) >= 3]
    if not keep:
        return out
    # rotate_piece(J, m): the rotation, then the exact turns (all strictly left: kept as is)
    cm = np.array([math.cos(m[found[t][0]]) for t in keep])
    sm = np.array([math.sin(m[found[t][0]]) for t in keep])
    hs = [hulls[t] for t in keep]
    size = np.array([len(h) for h in hs])
    J = np.concatenate(hs)
    c, s = np.repeat(cm, size), np.repeat(sm, size)
    R = np.empty_like(J)
    R[:, 0] = J[:, 0] * c - J[:, 1] * s
    R[:, 1] = J[:, 0] * s + J[:, 1] * c
    R = R + 0.0
    prv, nxt = ring_neighbours(size)
    turn = orient2d_many(R[prv], R, R[nxt])
    bent = np.bincount(np.repeat(np.arange(len(hs)), size)[turn <= 0], minlength=len(hs)) > 0
    ends = np.cumsum(size)
    for i, t in enumerate(keep):
        r = R[ends[i] - size[i]:ends[i]]
        k, j = found[t][0], found[t][1]
        out[k][j] = convex_hull(r) if bent[i] else r
    return out


def _packed(pieces: list[np.ndarray]) -> PieceSet | None:
    """The pieces' :class:`PieceSet` from one compiled packing pass (None on the pure path)."""
    got = fastpath.pack_boxes(pieces)
    if got is None:
        return None
    pts, off, lo, hi, _ = got
    return PieceSet(pieces, (lo, hi), (pts, np.diff(off)))


def _operand_sums(sums: list, nb: int, no: int, at: int, n: int) -> list:
    """Of the pair sums of ``no`` obstacle pieces with ``nb`` operands (obstacle-major, as
    :func:`pair_sums` gives them), those with operands ``at .. at + n - 1``, obstacle-major:
    ``[sums[i * nb + at + j] for i in range(no) for j in range(n)]`` (one operand: a slice).

    >>> _operand_sums(list("abcdefgh"), 4, 2, 1, 2), _operand_sums(list("abcdefgh"), 4, 2, 3, 1)
    (['b', 'c', 'f', 'g'], ['d', 'h'])
    """
    if n == 1:
        return sums[at::nb][:no]
    return [sums[i * nb + at + j] for i in range(no) for j in range(n)]


def build_slabs(bounds, obstacle_pieces: list[np.ndarray], robot_pieces: list[np.ndarray], lo: list[float],
                hi: list[float], *, scale: float, pad: float, grid_cells: int, obstacles_checked: bool = False,
                nested: bool = True) -> list[tuple]:
    """Slabs ``[lo[k], hi[k]]`` at once: per slab ``(outer, inner, inner_pieces, seconds,
    outer_seconds)``, outer its :class:`CSpace` of the slab hulls, inner the BLOCKED cells
    (:meth:`GridIndex.blocked_cells`) of the obstacles summed with the inner sets on the
    outer grid's cells (False if there is none), as :meth:`cspace.se2.cspace.SE2CSpace` builds them one
    by one; the seconds are each slab's share of the run's time. ``obstacles_checked``: the caller
    ran :func:`check_range` on the obstacles (pieces of convex decompositions lie within them), so
    only the bounds and the hulls are checked here (a map's thousands of pieces, once, not per run).
    ``nested``: passed to each slab's :meth:`CSpace.from_sums` (False: no containment prune).
    """
    t0 = time.perf_counter()
    K, nr = len(lo), len(robot_pieces)
    hulls = slab_hulls(robot_pieces, lo, hi, scale)
    inners = [[j for j in js if len(j) >= 3] for js in slab_inners(robot_pieces, lo, hi, pad)]
    t_sets = time.perf_counter() - t0
    negs = [reflect(h) for hs in hulls for h in hs]
    inner_at = []  # where each slab's inner sets start among the robot operands
    for js in inners:
        inner_at.append(len(negs))
        negs += [reflect(j) for j in js] if obstacle_pieces else []
    t = time.perf_counter()
    sums = pair_sums(obstacle_pieces, negs) if obstacle_pieces and negs else []
    t_sums = time.perf_counter() - t
    nb, no = len(negs), len(obstacle_pieces)
    check_range(tuple(float(v) for v in bounds), ([] if obstacles_checked else list(obstacle_pieces))
                + [h for hs in hulls for h in hs])  # once, not per slab
    out = []
    for k in range(K):
        t = time.perf_counter()
        outer = CSpace.from_sums(bounds, obstacle_pieces, hulls[k], _operand_sums(sums, nb, no, k * nr, nr),
                                 grid_cells=grid_cells, seconds=t_sums / K, checked=True, nested=nested)
        t_outer = time.perf_counter() - t
        inner = False
        ni = len(inners[k])
        if ni and obstacle_pieces:
            g = outer.index
            pieces = _operand_sums(sums, nb, no, inner_at[k], ni)
            inner = GridIndex.blocked_cells(pieces, bounds, (g.nx, g.ny), packed=_packed(pieces))
        out.append((outer, inner, ni, time.perf_counter() - t + (t_sets + t_sums) / K, t_outer + t_sets / K))
    return out
