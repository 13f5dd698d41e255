"""Minkowski sums of convex polygons by the angular merge, and reflection.

The sum of convex polygons P_1 ⊕ ... ⊕ P_k is the convex polygon whose edge
sequence is the merge of the operands' edge sequences by polar angle (foundations
note, section on the merge). Start at the sum of the operands' lowest-then-leftmost
vertices, which is the sum's lowest-then-leftmost vertex; then walk the edges in
angle order. Each vertex of the sum is the sum of one vertex per operand.

Angles are compared exactly: first by half-plane (the upper half [0, pi) versus the
lower half [pi, 2 pi), decided by the signs of the edge's coordinates, which float
subtraction preserves), then by the exact sign of the cross product of the two
edge vectors (:func:`cspace.kernel.predicates.cross_diff_sign`). Parallel edges of equal
direction are fused, so the sum has no collinear vertex and at most sum(n_i)
vertices. Integer input (|x| < 2^52) gives the exact integer sum. Float input gives
each vertex as a sum of input vertices rounded once per addition; if that rounding
makes a turn non-convex, the exact hull of the rounded vertices is returned, so the
output is always strictly convex by the exact test.

Two code paths, one semantics: a scalar merge for the small polygons of C-space
pieces, and a vectorised one for large inputs (a stable sort of pseudo-angle keys,
whose order is then certified pair by pair with the exact comparison; any doubt
falls back to the scalar merge).
"""
from __future__ import annotations

import numpy as np

from .polygon import as_array, drop_collinear, drop_repeats, lowest_first
from .predicates import (CCW_ERRBOUND_A, NonFiniteError, cross_diff_cols, cross_diff_sign, error_free_cross_sign,
                         lower_half, orient2d_xy, sum_error)

# Up to this many vertices in total the scalar merge is faster than numpy's overhead.
_SCALAR_MAX = 96


def reflect(polygon) -> np.ndarray:
    """The reflection −P = {−p : p ∈ P}, CCW and lowest-first like its input.

    Reflection through the origin is a rotation by pi, so orientation is kept.

    >>> reflect([[0, 0], [2, 0], [0, 1]]).tolist()
    [[0.0, -1.0], [0.0, 0.0], [-2.0, 0.0]]
    """
    p = as_array(polygon, nonempty=True)
    return lowest_first(-p + 0.0)  # + 0.0 turns -0.0 into 0.0


def minkowski_sum(P, Q, *more) -> np.ndarray:
    """P ⊕ Q (⊕ more...) of convex polygons, by one angular merge of all their edges.

    Operands may be in either orientation and may be degenerate (a point, a segment);
    they may carry repeated or collinear vertices. A non-convex operand raises
    ``ValueError``. The result is CCW from its lowest-then-leftmost vertex, with no
    collinear vertices.

    >>> minkowski_sum([[0, 0], [2, 0], [0, 2]], [[0, 0], [1, 0], [1, 1], [0, 1]]).tolist()
    [[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [1.0, 3.0], [0.0, 3.0]]
    """
    ops = [as_array(x, copy=False, nonempty=True) for x in (P, Q) + more]  # only read
    try:
        return _minkowski_sum(ops)
    except (OverflowError, NonFiniteError):  # an exact step met a NaN or an infinity
        if not all(np.isfinite(o).all() for o in ops):
            raise ValueError("minkowski_sum: coordinates must be finite") from None
        raise ValueError("minkowski_sum: the sum's coordinates overflow the double range") from None


def _minkowski_sum(ops: list) -> np.ndarray:
    """:func:`minkowski_sum` of operands already converted to arrays."""
    if sum(len(o) for o in ops) <= _SCALAR_MAX:
        if len(ops) == 2:
            (P, EP), (Q, EQ) = _clean_edges_small(ops[0].tolist()), _clean_edges_small(ops[1].tolist())
            flat, exact = _merge2_small(P, Q, EP, EQ)
            if exact:  # the exact sum, strictly convex by the exact merge
                return np.array(flat, dtype=np.float64).reshape(-1, 2)
            out = list(zip(flat[::2], flat[1::2]))
        else:
            out = _merge_small([_clean_small(o.tolist()) for o in ops])
        return np.array(_certify_small(out), dtype=np.float64)
    out = None
    if all(len(o) >= 3 for o in ops):  # the common case: certify while merging
        fast = [_prep_fast(o) for o in ops]
        if all(f is not None for f in fast):
            out = _merge_vectorised([f[0] for f in fast], [f[1] for f in fast])
    if out is None:  # repeats, collinear or degenerate operands: clean them first
        polys = [_clean_convex(o) for o in ops]
        out = _merge_vectorised(polys)
    if out is None:  # the float pre-sort could not be certified: exact scalar merge
        out = np.array(_certify_small(_merge_small([_clean_small(p.tolist()) for p in polys])))
    return out


# ---------------------------------------------------------------- exact turn of two edge vectors


def _turn(ux: float, uy: float, vx: float, vy: float, a, b, c, d) -> int:
    """Sign of (b - a) x (d - c), given the float edges u = b - a and v = d - c.

    The stage-A filter on the already-rounded differences; the exact product of the
    endpoints' rationals when it cannot decide.
    """
    left = ux * vy
    right = uy * vx
    det = left - right
    bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
    if det > bound and bound > 1e-280:
        return 1
    if -det > bound and bound > 1e-280:
        return -1
    return cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])


# ---------------------------------------------------------------- operands


def _clean_small(pts: list) -> list:
    """CCW, lowest-first, no repeated or collinear vertex; checks convexity (scalar)."""
    return _clean_edges_small(pts)[0]


def _clean_edges_small(pts: list) -> tuple[list, list]:
    """:func:`_clean_small`, and the cleaned operand's edges from :func:`_edges_small`.

    One pass computes each vertex's turn as the cross product of its two edges (the
    stage-A filter inline, rationals only in doubt) and the lowest vertex.
    """
    out = [(p[0], p[1]) for i, p in enumerate(pts) if p != pts[i - 1]] or [tuple(pts[0])]
    n = len(out)
    if n <= 2:
        out = _extremes(out)
        return out, _edges_small(out)
    pos = neg = 0
    px, py = out[-1]
    qx, qy = out[0]
    ux, uy = qx - px, qy - py
    low = 0
    for i in range(n):
        rx, ry = out[i + 1] if i + 1 < n else out[0]
        vx, vy = rx - qx, ry - qy
        left, right = ux * vy, uy * vx
        det = left - right
        bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
        if bound > 1e-280 and det > bound:
            pos += 1
        elif bound > 1e-280 and -det > bound:
            neg += 1
        else:
            t = cross_diff_sign(px, py, qx, qy, qx, qy, rx, ry)
            if t == 0:  # a collinear vertex: drop it exactly (rare), then start again
                p = drop_collinear(np.array(out, dtype=np.float64))
                if len(p) >= 3:
                    return _clean_edges_small(p.tolist())
                out = _extremes(out)
                return out, _edges_small(out)
            pos += t > 0
            neg += t < 0
        if qy < out[low][1] or (qy == out[low][1] and qx < out[low][0]):
            low = i
        px, py, qx, qy, ux, uy = qx, qy, rx, ry, vx, vy
    if pos and neg:
        raise ValueError("minkowski_sum: operand is not convex")
    if neg:
        out.reverse()
        low = n - 1 - low
    out = out[low:] + out[:low]
    return out, _edges_small(out)  # raises unless the edges sweep the angle once


def _extremes(pts: list) -> list:
    """A point or a segment, as its one or two extreme points, lowest (then leftmost) first."""
    lo = min(pts, key=lambda v: (v[1], v[0]))
    hi = max(pts, key=lambda v: (v[1], v[0]))
    return [lo] if lo == hi else [lo, hi]


def _lowest_index_convex(p: np.ndarray) -> int:
    """:func:`cspace.kernel.polygon.lowest_index` of a convex polygon, in one pass.

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


def _clean_convex(p: np.ndarray) -> np.ndarray:
    """Vectorised :func:`_clean_small` for large operands."""
    if len(p) >= 2:
        nxt = np.roll(p, -1, axis=0)
        if ((nxt[:, 0] == p[:, 0]) & (nxt[:, 1] == p[:, 1])).any():
            p = drop_repeats(p)
            nxt = np.roll(p, -1, axis=0)
    if len(p) < 3:
        return np.array(_extremes([tuple(v) for v in p.tolist()]), dtype=np.float64)
    e = nxt - p
    ep = np.roll(e, 1, axis=0)
    turn = _turns_cols(ep[:, 0], ep[:, 1], e[:, 0], e[:, 1], np.roll(p, 1, axis=0), p, p, nxt)
    if not turn.all():
        q = drop_collinear(p)
        if len(q) < 3:
            return np.array(_extremes([tuple(v) for v in p.tolist()]), dtype=np.float64)
        return _clean_convex(q)
    pos = turn[0] > 0
    if (turn < 0).any() if pos else (turn > 0).any():
        raise ValueError("minkowski_sum: operand is not convex")
    if not pos:
        p = p[::-1]
    return np.ascontiguousarray(lowest_first(p))


def _turns_cols(ux, uy, vx, vy, a, b, c, d) -> np.ndarray:
    """Vectorised :func:`_turn`: exact signs of u x v for float edges u = b - a, v = d - c."""
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        # Three fresh arrays, the rest in place: at 10^4 vertices and more, each fresh
        # array costs more in page faults than its arithmetic.
        left = np.multiply(ux, vy)
        right = np.multiply(uy, vx)
        det = np.subtract(left, right)
        bound = np.abs(left, out=left)
        bound += np.abs(right, out=right)
        bound *= CCW_ERRBOUND_A
        ok = (bound > 1e-280) & (bound < np.inf)
        sign = (ok & (det > bound)).astype(np.int8) - (ok & (np.negative(det, out=right) > bound)).astype(np.int8)
    doubt = np.flatnonzero(sign == 0)
    if len(doubt):
        sign[doubt] = cross_diff_cols(a[doubt, 0], a[doubt, 1], b[doubt, 0], b[doubt, 1],
                                      c[doubt, 0], c[doubt, 1], d[doubt, 0], d[doubt, 1])
    return sign


def _half(dx: float, dy: float) -> int:
    """0 for directions in [0, pi) (upper half-plane), 1 for [pi, 2 pi)."""
    return 0 if dy > 0.0 or (dy == 0.0 and dx > 0.0) else 1


# ---------------------------------------------------------------- merges


def _merge2_small(P: list, Q: list, EP: list | None = None, EQ: list | None = None) -> tuple[list, bool]:
    """The two-operand merge: two pointers, exact comparison, parallel edges fused.

    Returns the vertices as a flat list [x0, y0, x1, y1, ...] (cheap to hand to numpy)
    and whether every vertex sum was exact (the test of Fast2Sum: fl(s - a) == c
    and fl(s - c) == a hold together only for an exact sum).
    """
    n, m = len(P), len(Q)
    EP = _edges_small(P) if EP is None else EP
    EQ = _edges_small(Q) if EQ is None else EQ
    ne, me = len(EP), len(EQ)
    i = j = 0
    (ax, ay), (cx, cy) = P[0], Q[0]
    sx, sy = ax + cx, ay + cy
    exact = sx - ax == cx and sx - cx == ax and sy - ay == cy and sy - cy == ay
    out = [sx, sy]
    while True:
        if i < ne and j < me:
            ux, uy, hu = EP[i]
            vx, vy, hv = EQ[j]
            if hu != hv:
                s = hv - hu  # the edge in the upper half comes first
            else:  # exact sign of u x v: the stage-A filter, rationals in doubt
                left, right = ux * vy, uy * vx
                det = left - right
                bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
                if bound > 1e-280 and abs(det) > bound:
                    s = 1 if det > 0 else -1
                else:
                    a, b, c, d = P[i], P[(i + 1) % n], Q[j], Q[(j + 1) % m]
                    s = cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])
            # s > 0: P's edge comes first; s < 0: Q's; 0: parallel, fused.
            if s >= 0:
                i += 1
            if s <= 0:
                j += 1
        elif i < ne:
            i += 1
        elif j < me:
            j += 1
        if i == ne and j == me:
            return out, exact
        (ax, ay), (cx, cy) = P[i % n], Q[j % m]
        sx, sy = ax + cx, ay + cy
        if exact:
            exact = sx - ax == cx and sx - cx == ax and sy - ay == cy and sy - cy == ay
        out += (sx, sy)


def _edges_small(P: list) -> list:
    """Edge vectors of a cleaned operand with their half-plane (0 upper, 1 lower).

    From the lowest vertex of a convex polygon, the edges read upper...upper then
    lower...lower; a polygon with all turns left that returns to the upper half
    (a pentagram) winds more than once and is not convex. A point has no edge.
    """
    if len(P) < 2:
        return []
    edges = [(bx - ax, by - ay, 0 if by > ay or (by == ay and bx > ax) else 1)
             for (ax, ay), (bx, by) in zip(P, P[1:] + P[:1])]
    seen_lower = 0
    for e in edges:
        if e[2] < seen_lower:
            raise ValueError("minkowski_sum: operand is not convex (winds more than once)")
        seen_lower = e[2]
    return edges


def _merge_small(polys: list) -> list:
    """The k-way angular merge, one vertex of the sum per distinct edge direction.

    ``idx[i]`` is the current vertex of operand i; the current vertex of the sum is
    the sum of those. At each step the operands whose next edge has the smallest
    angle (exactly equal angles tie) all advance together, which fuses parallel edges.
    """
    k = len(polys)
    sizes = [len(p) for p in polys]
    idx = [0] * k
    out = [(sum(p[0][0] for p in polys), sum(p[0][1] for p in polys))]
    total = sum(s if s > 1 else 0 for s in sizes)
    taken = 0
    while taken < total:
        best: list = []
        bh = 2
        for i in range(k):
            n = sizes[i]
            if n < 2 or idx[i] == n:
                continue
            p = polys[i]
            a, b = p[idx[i]], p[(idx[i] + 1) % n]
            h = _half(b[0] - a[0], b[1] - a[1])
            if h < bh:
                bh, best = h, [(i, a, b)]
            elif h == bh:
                _, c, d = best[0]
                s = cross_diff_sign(c[0], c[1], d[0], d[1], a[0], a[1], b[0], b[1])
                if s < 0:      # edge a->b is clockwise of the current best: smaller angle
                    best = [(i, a, b)]
                elif s == 0:   # parallel, same half: the same direction
                    best.append((i, a, b))
        for i, _, _ in best:
            idx[i] += 1
            taken += 1
        if taken < total:
            out.append((sum(polys[i][idx[i] % sizes[i]][0] for i in range(k)),
                        sum(polys[i][idx[i] % sizes[i]][1] for i in range(k))))
    return out


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


def _prep_fast(p: np.ndarray) -> tuple[np.ndarray, int] | None:
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


def _merge_vectorised(polys: list, rot: list | None = None) -> np.ndarray | None:
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
        fused = _parallel_pairs(ux, uy, half, integral, order, edged, rot, sizes, ex, ey)  # ex, ey: spent
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
        return _certify_cols(out, exact=False)
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
    return _certify_cols(out, exact=False)


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
        if not _max_abs(p) < lim:
            return False
    for p in polys:
        if not np.array_equal(np.floor(p, out=scratch[:len(p)]), p):
            return False
    return True


def _parallel_pairs(ux, uy, half, integral, order, edged, rot, sizes, w1, w2) -> np.ndarray | None:
    """Which consecutive merged edges are parallel (to be fused); None if out of order.

    Within a half-plane, edge t+1 must not turn clockwise of edge t: u x v >= 0,
    decided exactly. For integer input, products below 2^53 are exact; for floats the
    stage-A filter decides; in doubt, Dekker's error-free products, rationals last.
    """
    same = half[:-1] == half[1:]
    left = np.multiply(ux[:-1], uy[1:], out=w1[:-1])  # w1, w2: scratch
    right = np.multiply(uy[:-1], ux[1:], out=w2[:-1])
    if integral and max(_max_abs(left), _max_abs(right)) < 2.0**53:
        # Integer products below 2^53 are exact (a true product of 2^53 or more cannot
        # round below 2^53) and so is their difference's sign: all are sure at once.
        det = np.subtract(left, right, out=left)
        if (same & (det < 0)).any():
            return None
        return same & (det == 0)
    if integral:
        # Integer products below 2^53 are exact (a true product of 2^53 + 1 or more
        # cannot round below 2^53), and the one rounding of their difference keeps
        # its sign; pairs with a larger product go to the exact tests below.
        big = 2.0**53
        sure = (left < big) & (left > -big) & (right < big) & (right > -big)
        det = np.subtract(left, right, out=left)
    else:  # the stage-A bound, computed in place over the products (one fresh array)
        det = np.subtract(left, right)
        bound = np.abs(left, out=left)
        bound += np.abs(right, out=right)
        bound *= CCW_ERRBOUND_A
        sure = (bound > 1e-280) & (bound < np.inf) & (np.abs(det, out=right) > bound)
    if (same & sure & (det < 0)).any():
        return None
    fused = same & (~sure | (det == 0))  # parallel, or in doubt: decided exactly below
    doubt = np.flatnonzero(same & ~sure)
    if len(doubt):
        sign = _error_free_signs(ux, uy, doubt)
        ends = np.cumsum(sizes)
        first = ends - sizes
        edged = [np.roll(p, -k, axis=0) for p, k in zip(edged, rot)]  # lowest first
        X = np.concatenate([p[:, 0] for p in edged])
        Y = np.concatenate([p[:, 1] for p in edged])
        exact_edge = _diff_is_exact_cols(X, first, ends) & _diff_is_exact_cols(Y, first, ends)
        sign[~(exact_edge[order[doubt]] & exact_edge[order[doubt + 1]])] = 2
        rest = np.flatnonzero(sign == 2)
        if len(rest):
            sign[rest] = [_exact_pair(edged, first, order[doubt[r]], order[doubt[r] + 1])
                          for r in rest]
        if (sign < 0).any():
            return None
        fused[doubt] = sign == 0  # parallel, same direction: no vertex between them
    return fused


def _max_abs(u: np.ndarray) -> float:
    # The ufunc reductions themselves: ndarray.max() adds a Python-level wrapper.
    return max(float(np.maximum.reduce(u, axis=None)), -float(np.minimum.reduce(u, axis=None)))


def _error_free_signs(ux: np.ndarray, uy: np.ndarray, doubt: np.ndarray) -> np.ndarray:
    """Exact signs of ux[t]*uy[t+1] - uy[t]*ux[t+1] where floats get them without error, else 2.

    :func:`cspace.kernel.predicates.error_free_cross_sign` on the edge vectors (as differences
    from the origin, which are exact). The edges themselves must be exact differences
    of the input vertices, which the caller checks.
    """
    z = np.zeros(len(doubt))
    return error_free_cross_sign(z, z, ux[doubt], uy[doubt], z, z, ux[doubt + 1], uy[doubt + 1])


def _diff_is_exact_cols(x: np.ndarray, first: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Whether each cyclic difference fl(x[i+1] - x[i]) within each operand is exact.

    Knuth's TwoSum: the rounding error of b + (-a) is computed exactly; zero means exact.
    """
    b = np.empty_like(x)
    b[:-1] = x[1:]
    b[ends - 1] = x[first]
    na = -x
    return sum_error(b, na, b + na) == 0.0


def _exact_pair(edged: list, ends: np.ndarray, s: int, t: int) -> int:
    """Exact sign of edge s x edge t, edges numbered across the concatenated operands."""
    def ends_of(g):
        i = int(np.searchsorted(ends, g, side="right")) - 1
        p = edged[i]
        j = g - ends[i]
        return p[j], p[(j + 1) % len(p)]
    a, b = ends_of(int(s))
    c, d = ends_of(int(t))
    return cross_diff_sign(a[0], a[1], b[0], b[1], c[0], c[1], d[0], d[1])


# ---------------------------------------------------------------- certification


def _certify_small(out: list) -> list:
    """Exact strict-convexity check of the rounded sum; repair by exact hull if needed."""
    n = len(out)
    if n < 3:  # a point or a segment, already lowest first
        return out
    for i in range(n):
        a, b, c = out[i - 1], out[i], out[(i + 1) % n]
        if _turn(b[0] - a[0], b[1] - a[1], c[0] - b[0], c[1] - b[1], a, b, b, c) <= 0:
            from .hull import convex_hull

            return convex_hull(out).tolist()
    return out


class _Cyclic:
    """``p`` shifted cyclically by ``k`` rows, read only at the indices asked for
    (the exact fallback of :func:`_turns_cols` reads a few): no shifted copy is made."""

    def __init__(self, p: np.ndarray, k: int):
        self.p, self.k = p, k

    def __getitem__(self, key):
        rows, col = key
        return self.p[(rows + self.k) % len(self.p), col]


def _certify_cols(out: np.ndarray, exact: bool) -> np.ndarray:
    """Vectorised :func:`_certify_small`; skipped when the sums were exact integers.

    Rounded sums of a strictly convex polygon are still in angular order around its
    interior, so a vertex whose exact turn is not left lies inside its neighbours'
    chord and is removed (never two neighbours in one round, so each removal is
    decided on vertices that stay); rounds repeat until every turn is left, which is
    the hull of the rounded vertices (as a Graham scan of angularly sorted points).
    """
    if exact or len(out) < 3:
        return out
    for _ in range(len(out)):
        n = len(out)
        e = np.empty((n + 1, 2))  # e[i]: the edge into vertex i; e[i + 1]: the edge out of it
        np.subtract(out[1:], out[:-1], out=e[1:n])
        e[0] = e[n] = out[0] - out[-1]
        turn = _turns_cols(e[:-1, 0], e[:-1, 1], e[1:, 0], e[1:, 1], _Cyclic(out, -1), out, out, _Cyclic(out, 1))
        bad = turn <= 0
        if not bad.any():
            # Every turn is left, so the edge directions sweep 2 pi once per winding and
            # cross from the lower half-plane into the upper one once per winding.
            h = lower_half(e[1:, 0], e[1:, 1])
            if np.count_nonzero(h[:-1] & ~h[1:]) + bool(h[-1] and not h[0]) == 1:
                return lowest_first(out)
            break  # it winds more than once: the hull of its vertices
        drop = bad.copy()
        drop[1:] &= ~bad[:-1]  # keep a bad vertex whose predecessor is being removed
        if drop[0] and drop[-1]:
            drop[-1] = False
        out = out[~drop]
        if len(out) < 3:
            break
    from .hull import convex_hull

    return convex_hull(out)
