"""The vectorised angular merge of large convex polygons: a stable sort of pseudo-angle keys.

Each operand's edges (from its lowest vertex, no rotated copy) get a monotone stand-in
for their polar angle (:func:`_pseudo_angle`); one stable sort merges them
(:func:`_sort_keys`); the sorted order is then certified exactly and parallel edges fused
(:mod:`cspace.kernel.minkowski.certify`), and the sum's vertices are formed: exact int64
running sums on integer input, else one input vertex per operand, rounded once per
addition and certified strictly convex. :func:`merge_vectorised` returns None whenever it
cannot certify; :func:`cspace.kernel.minkowski.merge.minkowski_sum` then takes a slower exact route.
"""
from __future__ import annotations

import numpy as np

from .certify import certify_cols, max_abs, parallel_pairs, turns_cols
from .scalar import extremes
from ..polygons.polygon import drop_collinear, drop_repeats, lowest_first
from ..polygons.predicates import lower_half, orient2d_xy


def _lowest_index_convex(p: np.ndarray) -> int:
    """:func:`cspace.kernel.polygons.polygon.lowest_index` of a convex polygon, in one pass.

    A convex polygon's lowest vertices are consecutive (one vertex, or the run along
    its bottom edge), so the leftmost of them is found next to the first one. On a
    non-convex polygon the answer may be another vertex; callers certify convexity.
    """
    y = p[:, 1]
    n = len(p)
    k = int(np.argmin(y))
    ymin = y[k]
    if y[k - 1] != ymin and y[(k + 1) % n] != ymin:
        return k
    run = [k]
    for step in (-1, 1):
        j = (k + step) % n
        while y[j] == ymin and j != k and len(run) < n:
            run.append(j)
            j = (j + step) % n
    return min(run, key=lambda j: p[j, 0])


def clean_convex(p: np.ndarray) -> np.ndarray:
    """Vectorised :func:`cspace.kernel.minkowski.scalar._clean_small` for large operands."""
    if len(p) >= 2:
        nxt = np.roll(p, -1, axis=0)
        if ((nxt[:, 0] == p[:, 0]) & (nxt[:, 1] == p[:, 1])).any():
            p = drop_repeats(p)
            nxt = np.roll(p, -1, axis=0)
    if len(p) < 3:
        return np.array(extremes([tuple(v) for v in p.tolist()]), dtype=np.float64)
    e = nxt - p
    ep = np.roll(e, 1, axis=0)
    turn = turns_cols(ep[:, 0], ep[:, 1], e[:, 0], e[:, 1], np.roll(p, 1, axis=0), p, p, nxt)
    if not turn.all():
        q = drop_collinear(p)
        if len(q) < 3:
            return np.array(extremes([tuple(v) for v in p.tolist()]), dtype=np.float64)
        return clean_convex(q)
    pos = turn[0] > 0
    if (turn < 0).any() if pos else (turn > 0).any():
        raise ValueError("minkowski_sum: operand is not convex")
    if not pos:
        p = p[::-1]
    return np.ascontiguousarray(lowest_first(p))



def _pseudo_angle(dx: np.ndarray, dy: np.ndarray, key: np.ndarray, scratch: np.ndarray) -> np.ndarray:
    """A monotone stand-in for the polar angle in [0, 4), no trigonometry.

    t = dx / (|dx| + |dy|) falls from 1 to -1 over the upper half and rises back over
    the lower half, so the key is 1 - t there and 3 + t here: 2 - copysign(1 + t, dy)
    (dy must carry no -0.0). A zero vector gives NaN. The key is only a pre-sort,
    certified afterwards exactly. Written into ``key``; ``scratch`` is overwritten.
    """
    with np.errstate(invalid="ignore", over="ignore"):  # NaN and inf are read by the caller
        np.abs(dx, out=key)
        key += np.abs(dy, out=scratch)
        np.divide(dx, key, out=key)  # t
    key += 1.0
    np.copysign(key, dy, out=key)
    np.subtract(2.0, key, out=key)
    return key


def prep_fast(p: np.ndarray) -> tuple[np.ndarray, int] | None:
    """A large operand CCW (a reversed view if needed) and the index of its lowest
    vertex, without the full clean; or None.

    The lowest-then-leftmost vertex is a strict extreme point, so the exact turn
    there gives the orientation of a convex polygon. Nothing else is checked here:
    convexity, repeats and collinear vertices are certified by the merge itself
    (an operand whose edges do not sweep the angle once in order fails there, and
    the caller then takes the full clean, which raises for non-convex input).
    """
    n = len(p)
    k = _lowest_index_convex(p)
    (ax, ay), (bx, by), (cx, cy) = p[k - 1].tolist(), p[k].tolist(), p[(k + 1) % n].tolist()
    t = orient2d_xy(ax, ay, bx, by, cx, cy)
    if t == 0:
        return None
    if t < 0:
        p, k = p[::-1], n - 1 - k
    return p, k


def _sort_keys(key: np.ndarray, runs: int, packed: np.ndarray) -> np.ndarray:
    """Stable permutation sorting ``key`` (pseudo-angles in [0, 4)), made of ``runs`` sorted runs.

    ``key`` is overwritten; the permutation is written into the int64 ``packed``.
    Below 2^21 keys, each key is quantised to 40 bits and packed with its index
    into one int64, so an integer sort moves no index array beside it; equal quanta
    keep index order, which the exact certification that follows checks anyway.
    A merge sort (timsort finds the runs) costs O(N log runs), so it serves few
    runs; the SIMD quicksort is faster from a handful of runs on.
    """
    n = len(key)
    if n >= 1 << 21:
        return np.argsort(key, kind="stable")
    np.copyto(packed, np.multiply(key, 2.0**40, out=key), casting="unsafe")  # key is spent
    packed <<= 21
    packed |= _iota(n)
    packed.sort(kind="stable" if runs <= 4 else None)
    packed &= (1 << 21) - 1
    return packed


_IOTA = np.arange(0, dtype=np.int64)


def _iota(n: int) -> np.ndarray:
    """0, 1, ..., n - 1 as a read-only view of one cached array (grown as needed)."""
    global _IOTA
    if len(_IOTA) < n:
        _IOTA = np.arange(max(n, 2 * len(_IOTA)), dtype=np.int64)
        _IOTA.flags.writeable = False
    return _IOTA[:n]


def _edge_vectors(edged: list, rot: list, ex: np.ndarray, ey: np.ndarray) -> None:
    """The operands' edge vectors, concatenated, each operand's from its vertex ``rot``
    on: the edge from vertex j to j + 1 (cyclically) is written at j - rot. No copy
    of the operand is rotated. Written into ``ex``, ``ey``."""
    o = 0
    for p, k in zip(edged, rot):
        n = len(p)
        for e, c in ((ex, 0), (ey, 1)):
            blk = e[o:o + n]
            np.subtract(p[k + 1:, c], p[k:-1, c], out=blk[:n - k - 1])
            blk[n - k - 1] = p[0, c] - p[n - 1, c]
            np.subtract(p[1:k + 1, c], p[:k, c], out=blk[n - k:])
        o += n
    ey += 0.0  # -0.0 (from -0.0 - 0.0) becomes 0.0: the key reads the half-plane from its sign


def merge_vectorised(polys: list, rot: list | None = None) -> np.ndarray | None:
    """Merge by a sort of pseudo-angle keys, then certify the order exactly.

    Each operand is CCW; ``rot`` gives each one's lowest vertex (default: the first).
    Returns None when the result cannot be
    certified: a repeated vertex (a zero edge), an operand whose keys do not increase
    along it, or some adjacent pair of the merged sequence out of exact angular order
    (a pre-sort misled by rounding, or a non-convex operand); the caller then takes a
    slower exact route.
    """
    rot = rot or [0] * len(polys)
    start = polys[0][rot[0]].copy()
    for p, k in zip(polys[1:], rot[1:]):
        start += p[k]
    rot = [k for p, k in zip(polys, rot) if len(p) >= 2]
    edged = [p for p in polys if len(p) >= 2]
    if not edged:
        return start.reshape(1, 2)
    sizes = np.array([len(p) for p in edged])
    ends = np.cumsum(sizes)
    total = int(ends[-1])
    # One workspace block for every large temporary: a single allocation that the C
    # allocator keeps between calls, where a dozen fresh arrays would each be paged
    # in again (about 2 us a page here, half the run time at 16384 vertices).
    ws = np.empty(8 * total)
    ex, ey, key, scratch = (ws[i * total:(i + 1) * total] for i in range(4))
    ints = ws[4 * total:].view(np.int64)
    order, g, cp, cq = (ints[i * total:(i + 1) * total] for i in range(4))
    _edge_vectors(edged, rot, ex, ey)
    _pseudo_angle(ex, ey, key, scratch)
    if not np.isfinite(key.sum()):  # 0 / 0: a zero edge (or an overflowing one)
        return None
    down = np.flatnonzero(key[1:] < key[:-1])  # allowed only where one operand ends
    if len(down) and not set(down.tolist()) <= set((ends[:-1] - 1).tolist()):
        return None
    order = _sort_keys(key, len(edged), order)
    ux, uy = np.take(ex, order, out=key), np.take(ey, order, out=scratch)
    half = lower_half(ux, uy)  # exact, from the signs of the sorted edges
    if (half[:-1] > half[1:]).any():
        return None
    # At most one output vertex per edge: the output's buffer is scratch until then.
    buf = np.empty((total, 2))
    integral = _integral(edged, len(polys), buf)
    with np.errstate(over="ignore", invalid="ignore"):  # inf and NaN products go to the exact tests
        fused = parallel_pairs(ux, uy, half, integral, order, edged, rot, sizes, ex, ey)  # ex, ey: spent
    if fused is None:
        return None
    # The vertex after merged edge t, t < last, unless t and t + 1 fuse.
    keep = np.flatnonzero(~fused) if fused.any() else _iota(len(fused))
    out = buf[:len(keep) + 1]  # all of buf unless edges fused
    out[0] = start
    if integral:  # exact: vertex after edge t = start + the sum of the edges up to t
        return _running_sums(ux, uy, start, keep, ints[:2 * total], ws[:2 * total], out)  # order, g, ex, ey: spent
    if len(edged) == 2 and len(polys) == 2:
        # Two operands: after merged edge t, taken from operand P (size n) as its
        # local edge l, P has given l + 1 edges and Q the other t - l, and vice versa.
        P, Q = edged
        n, k = len(P), len(keep)
        g = np.take(order, keep, out=g[:k]) if k < len(fused) else order[:-1]
        # P's edges taken so far: g + 1 after P's edge g, keep - (g - n) after Q's
        # edge g - n; as arithmetic, since np.where mispredicts on a random mask.
        cp = np.add(keep, n - 1, out=cp[:k])
        cp -= g
        cp -= g
        cp *= g >= n
        cp += g
        cp += 1
        cq = np.subtract(keep, cp, out=cq[:k])  # Q's: the rest
        cq += 1
        cp += rot[0]  # counted from each operand's lowest vertex
        cq += rot[1]
        # Whole rows gathered ('wrap' takes index n as vertex 0) into spent blocks.
        a = ints[:2 * k].view(np.float64).reshape(k, 2)  # order and g: spent
        b = ws[:2 * k].reshape(k, 2)  # ex and ey: spent
        np.take(P, cp, axis=0, out=a, mode="wrap")
        np.take(Q, cq, axis=0, out=b, mode="wrap")
        np.add(a, b, out=out[1:])
        return certify_cols(out, exact=False)
    # Float input: each vertex is the sum of one input vertex per operand, rounded
    # once per addition; the count of an operand's edges taken so far is its index.
    vx = np.zeros(len(keep))
    vy = np.zeros(len(keep))
    for p in polys:
        if len(p) == 1:  # an operand that is one point (no edges): it translates every vertex
            vx += p[0, 0]
            vy += p[0, 1]
    owner = np.repeat(np.arange(len(edged)), sizes)[order]
    for i, p in enumerate(edged):
        cnt = (np.cumsum(owner == i)[keep] + rot[i]) % sizes[i]
        vx += p[cnt, 0]
        vy += p[cnt, 1]
    out[1:, 0] = vx
    out[1:, 1] = vy
    return certify_cols(out, exact=False)


def _running_sums(ux, uy, start, keep, acc, spare, out) -> np.ndarray:
    """``out[1:]``: start + the running sums of the merged edges (ux, uy), at ``keep``.

    For integer input. Every partial sum is a vertex of the sum, an integer below 2^51
    in magnitude, so int64 sums are exact and so is their conversion back. One
    accumulate of (x, y) rows costs less than two of columns. ``acc`` and ``spare``
    are scratch blocks of 2 * len(ux) int64 and float64.
    """
    n = len(ux)
    acc = acc.reshape(n, 2)
    np.copyto(acc[:, 0], ux, casting="unsafe")
    np.copyto(acc[:, 1], uy, casting="unsafe")
    acc[0] += start.astype(np.int64)
    np.cumsum(acc, axis=0, out=acc)
    k = len(keep)
    if k < n - 1:  # fused edges leave no vertex: gather the rest
        acc = np.take(acc, keep, axis=0, out=spare[:2 * k].view(np.int64).reshape(k, 2))
    out[1:] = acc[:k]
    return out


def _integral(polys: list, k: int, scratch: np.ndarray) -> bool:
    """Every coordinate an integer small enough that all sums of k of them are exact.

    ``scratch`` is an (M, 2) float array, M at least the largest operand's size.
    """
    lim = 2.0**51 / max(k, 1)
    for p in polys:
        if not max_abs(p) < lim:
            return False
    for p in polys:
        if not np.array_equal(np.floor(p, out=scratch[:len(p)]), p):
            return False
    return True

