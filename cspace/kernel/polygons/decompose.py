"""Convex decomposition of simple polygons, holes included.

Hertel–Mehlhorn over a constrained Delaunay triangulation: triangulate (GEOS, via
``shapely.constrained_delaunay_triangles``; it adds no Steiner points, so every
triangle corner is an input vertex), then remove diagonals while both polygons
they separate merge into a convex one. Every diagonal left is *essential* (its
removal would create a reflex corner), each reflex vertex holds at most two of
them, so a polygon without holes with r reflex vertices gets at most 2r + 1
pieces, within 4x of the optimum. Convexity of a merge is decided exactly
(:func:`cspace.kernel.polygons.predicates.orient2d_xy`).

Which diagonals survive depends on the order they are tried in. A diagonal that
*resolves* a reflex vertex (splits its angle into two angles of at most pi) is
worth keeping, and one resolving both its ends (a comb's tooth base) does the work
of two cuts. So diagonals are tried in ranks: between two convex vertices first,
then those touching a reflex vertex, then those resolving one, then two; longest
first within a rank (removing them merges big triangles early). One pass is enough: a merge refused once stays refused, since
pieces only grow. A convex input without holes is returned as it is, never
triangulated.
"""
from __future__ import annotations

import numpy as np

from .polygon import as_array, collinear_extent, drop_collinear, is_convex, normalize, ring_neighbours
from .predicates import CCW_ERRBOUND_A, orient2d_many, orient2d_xy
from .scaling import scaled_copies


def convex_decompose(polygon, holes=None) -> list[np.ndarray]:
    """Split a simple polygon (with optional holes) into convex CCW pieces.

    The pieces' union is the polygon, their interiors are disjoint, and every
    piece vertex is an input vertex. Each piece is strictly convex (no collinear
    vertex) and starts at its lowest (then leftmost) vertex. ``polygon`` may also
    be a shapely Polygon (its interiors are then the holes). Collinear vertices (no
    area) give the one point or segment they span; a polygon with no area that is
    not such a set raises ``ValueError``.

    >>> pieces = convex_decompose([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])
    >>> len(pieces), sorted(len(p) for p in pieces)
    (2, [4, 4])
    >>> len(convex_decompose([[0, 0], [1, 0], [0, 1]]))
    1
    """
    if hasattr(polygon, "geom_type") and polygon.geom_type == "Polygon" and holes is None:
        holes = [as_array(r) for r in polygon.interiors]
    shell = normalize(polygon if hasattr(polygon, "geom_type") else as_array(polygon, nonempty=True))
    if len(shell) < 3:  # no area: the point or segment it spans, a convex piece itself
        return [collinear_extent(as_array(polygon))]
    hole_list = []
    for i, h in enumerate(holes or []):
        try:
            hole_list.append(normalize(h, ccw=False))
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"convex_decompose: hole {i}: {exc}") from None
        if len(hole_list[-1]) < 3:  # GEOS crashes (SIGSEGV) on such a ring: refuse it first
            raise ValueError(f"convex_decompose: hole {i} has no area (empty, one point or collinear)")
    if not hole_list and is_convex(shell):
        return [shell]
    if hole_list:
        _check_simple(shell, hole_list)
    return decompose_normalized(shell, hole_list)


def _check_simple(shell: np.ndarray, holes: list) -> None:
    """ValueError unless the shell and its holes make a valid polygon (simple rings,
    holes inside the shell, disjoint but for touching points): triangulating anything
    else has no meaning, and can crash GEOS."""
    import shapely

    rings = [shell] + holes
    rescaled = scaled_copies(rings, max(float(np.abs(r).max()) for r in rings))  # as _triangulate does
    if rescaled:
        rings = rescaled[1]
    poly = shapely.Polygon(rings[0], rings[1:])
    if not poly.is_valid:
        raise ValueError(f"convex_decompose: not a simple polygon with holes ({shapely.is_valid_reason(poly)})")


def decompose_normalized(shell: np.ndarray, hole_list: list) -> list[np.ndarray]:
    """:func:`convex_decompose` of a shell already normalised CCW, not convex or with
    holes, and holes normalised CW (callers that checked this themselves).

    >>> len(decompose_normalized(normalize([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]), []))
    2
    """
    rings = [shell] + hole_list
    pts = np.concatenate(rings) if hole_list else shell
    tris = _triangulate(rings, pts)
    diagonals = _diagonals(tris)
    if not len(diagonals):
        return _finish(pts, tris.tolist())
    rank = _diagonal_ranks(rings, pts, diagonals)
    vec = pts[diagonals[:, 0]] - pts[diagonals[:, 1]]
    order = np.lexsort((-np.hypot(vec[:, 0], vec[:, 1]), rank))
    return _finish(pts, _hertel_mehlhorn(tris, pts, diagonals[order].tolist()))


def _diagonals(tris: np.ndarray) -> np.ndarray:
    """The triangulation's inner edges (u, v), u < v, once each."""
    e = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    e = np.sort(e, axis=1)
    e = e[np.lexsort((e[:, 1], e[:, 0]))]
    twice = np.flatnonzero((e[1:] == e[:-1]).all(axis=1))
    return e[twice]


def _triangulate(rings: list, pts: np.ndarray) -> np.ndarray:
    """CCW index triangles ``(T, 3)`` of the polygon, over the array of its vertices."""
    import shapely

    # GEOS's in-circle tests multiply four coordinates: far from 1 in magnitude, a
    # power-of-two copy (exact) is triangulated and its corners looked up instead.
    rescaled = scaled_copies(rings, float(np.abs(pts).max()))
    if rescaled:
        rings = rescaled[1]
        pts = np.concatenate(rings) if len(rings) > 1 else rings[0]
    geom = shapely.Polygon(rings[0], rings[1:])
    try:
        tri = shapely.constrained_delaunay_triangles(geom)
    except shapely.errors.GEOSException as e:
        # Say what is wrong with the input, in the loader's words, rather than GEOS's exception.
        reason = "" if shapely.is_valid(geom) else f"not a simple polygon ({shapely.is_valid_reason(geom)}); "
        raise ValueError(f"convex_decompose: {reason}GEOS could not triangulate it ({type(e).__name__})") from None
    corners = shapely.get_coordinates(tri).reshape(-1, 4, 2)[:, :3].reshape(-1, 2)
    # Each corner's vertex index: look the (x, y) pairs up as complex numbers, which
    # numpy sorts by x, then y.
    keys = np.ascontiguousarray(pts, dtype=np.float64).view(np.complex128).ravel()
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    wanted = np.ascontiguousarray(corners).view(np.complex128).ravel()
    at = np.minimum(np.searchsorted(sorted_keys, wanted), len(keys) - 1)
    if not (sorted_keys[at] == wanted).all():  # never expected: GEOS's CDT uses the input vertices only
        raise ValueError("convex_decompose: triangulation introduced a new vertex")
    ids = order[at].reshape(-1, 3)
    turn = orient2d_many(pts[ids[:, 0]], pts[ids[:, 1]], pts[ids[:, 2]])
    ids[turn < 0] = ids[turn < 0][:, ::-1]
    return ids[turn != 0]  # a zero-area sliver covers nothing


def _diagonal_ranks(rings: list, pts: np.ndarray, d: np.ndarray) -> np.ndarray:
    """How worth keeping each diagonal (u, v) of ``d`` is: 0 between two convex
    vertices, else 1 plus the number of reflex endpoints it *resolves*.

    The polygon's interior lies left of every ring (CCW shell, CW holes). A reflex
    vertex v (right turn prev -> v -> next) is resolved by a diagonal v -> w when w
    lies in the cone where both parts of the angle are at most pi: left of or on
    v -> next and right of or on v -> prev, exactly. One cut that resolves both its
    ends does the work of two (a comb's tooth bases).
    """
    prev, nxt = ring_neighbours([len(r) for r in rings])
    # All the turns in one exact call: every corner, then for each diagonal end v
    # (both ends) the two cone tests v -> next -> w and v -> w -> prev.
    v = np.concatenate([d[:, 0], d[:, 1]])
    w = np.concatenate([d[:, 1], d[:, 0]])
    a = np.concatenate([prev, v, v])
    b = np.concatenate([np.arange(len(pts)), nxt[v], w])
    c = np.concatenate([nxt, w, prev[v]])
    turn = orient2d_many(pts[a], pts[b], pts[c])
    reflex = turn[:len(pts)] < 0
    cone = turn[len(pts):].reshape(2, -1) >= 0
    resolves = (reflex[v] & cone[0] & cone[1]).reshape(2, -1)
    rank = (reflex[d[:, 0]] | reflex[d[:, 1]]).astype(np.int8)
    return rank + resolves.sum(axis=0, dtype=np.int8)


def _hertel_mehlhorn(tris: np.ndarray, pts: np.ndarray, diagonals: list) -> list[list[int]]:
    """Merge triangles across the diagonals, tried in the given order, while the
    merge stays convex; return the pieces as index cycles.

    A piece is a cycle of vertex indices held as successor and predecessor maps, so a
    merge splices the smaller piece into the larger one (O(smaller), never a copy of a
    growing piece: a star of 10^5 spikes merges into one centre in O(n log n), not
    O(n^2)). Pieces are named by union-find: an edge keeps the name it was created
    with, ``find`` gives its current piece. The result is the list-based merge's:
    the same pieces in the same order, each cycle read from the same vertex.
    """
    succ: list = []
    pred: list = []
    for a, b, c in tris.tolist():
        succ.append({a: b, b: c, c: a})
        pred.append({b: a, c: b, a: c})
    parent = list(range(len(succ)))
    slot = list(range(len(succ)))  # the position a piece is listed at: its first triangle's
    start = [t[0] for t in tris.tolist()]  # where its cycle is read from

    def find(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    owner: dict = {}  # directed edge (u, v) -> a name of the piece holding it
    for k, sp in enumerate(succ):
        for u, v in sp.items():
            owner[(u, v)] = k
    xy = pts.tolist()
    for u, v in diagonals:
        a, b = owner.get((u, v)), owner.get((v, u))
        if a is None or b is None:
            continue
        a, b = find(a), find(b)
        if a == b:
            continue
        _merge(a, b, u, v, succ, pred, parent, slot, start, xy, owner)
    reps = sorted((slot[k], k) for k in range(len(succ)) if parent[k] == k)
    out = []
    for _, k in reps:
        sp = succ[k]
        first = start[k]
        cycle, w = [first], sp[first]
        while w != first:
            cycle.append(w)
            w = sp[w]
        out.append(cycle)
    return out


def _merge(a: int, b: int, u: int, v: int, succ: list, pred: list, parent: list, slot: list, start: list,
           xy: list, owner: dict) -> bool:
    """Piece a holds edge u->v, piece b holds v->u; merge them if the union is convex at
    u and at v (the cycle runs v, a's path to u, u, b's path to v). Returns whether it did.

    A corner the merge makes straight is dropped at once: it stays straight (pieces
    only grow, so no later merge can be convex there), and the edges through it can
    no longer be merged across, so they leave ``owner``.
    """
    sa, pa, sb, pb = succ[a], pred[a], succ[b], pred[b]
    small_map, other = (sb, sa) if len(sb) <= len(sa) else (sa, sb)
    if any(w in other for w in small_map if w != u and w != v):
        return False  # a third shared vertex (a degenerate sliver): the cycle would repeat it
    straight = []
    # the corner at u: pred_a(u), u, succ_b(u); at v: pred_b(v), v, succ_a(v)
    for w, (p0, p2) in ((u, (pa[u], sb[u])), (v, (pb[v], sa[v]))):
        (ax, ay), (bx, by), (cx, cy) = xy[p0], xy[w], xy[p2]
        # orient2d's stage-A filter inline (most corners are decided here), else exact.
        left = (ax - cx) * (by - cy)
        right = (ay - cy) * (bx - cx)
        bound = CCW_ERRBOUND_A * (abs(left) + abs(right))
        if left - right > bound > 1e-280:
            continue
        turn = -1 if right - left > bound > 1e-280 else orient2d_xy(ax, ay, bx, by, cx, cy)
        if turn < 0:
            return False
        if turn == 0:
            straight.append(w)
    # Splice: the merged successor map is a's and b's, except u -> succ_b(u) and
    # v -> succ_a(v); the predecessor map likewise, u <- pred_a(u) and v <- pred_b(v).
    # The smaller piece's entries are copied into the larger one's maps.
    big, small = (a, b) if len(sa) >= len(sb) else (b, a)
    S, P = succ[big], pred[big]
    skip_s, skip_p = (v, u) if big == a else (u, v)
    for w, x in succ[small].items():
        if w != skip_s:
            S[w] = x
    for x, w in pred[small].items():
        if x != skip_p:
            P[x] = w
    succ[small], pred[small] = {}, {}
    parent[small] = big
    slot[big] = slot[a]  # the merged piece is listed where a was
    start[big] = v  # the cycle as the list-based merge wrote it: from v
    owner.pop((u, v), None)
    owner.pop((v, u), None)
    for w in straight:  # u first, then v, as before: the two are never neighbours
        p0, p2 = P[w], S[w]
        owner.pop((p0, w), None)
        owner.pop((w, p2), None)
        S[p0] = p2
        P[p2] = p0
        del S[w], P[w]
        if start[big] == w:
            start[big] = p2
    return True


def _finish(pts: np.ndarray, cycles: list) -> list[np.ndarray]:
    """The pieces as CCW arrays from their lowest (then leftmost) vertex.

    An exact check of every corner in one vectorised pass guards the invariant that
    no straight corner survived the merges (a zero-area sliver skipped by the
    triangulation could leave one); such a piece is cleaned the slow way.
    """
    sizes = np.array([len(c) for c in cycles])
    flat = np.array([i for c in cycles for i in c], dtype=np.intp)
    ends = np.cumsum(sizes)
    starts = ends - sizes
    owner = np.repeat(np.arange(len(cycles)), sizes)
    prev, nxt = ring_neighbours(sizes)
    V = pts[flat]
    turn = orient2d_many(V[prev], V, V[nxt])
    bad = np.zeros(len(cycles), dtype=bool)
    bad[owner[turn <= 0]] = True
    # lowest-then-leftmost vertex of each cycle: lexsort by (piece, y, x), first of each piece
    first = np.lexsort((V[:, 0], V[:, 1], owner))[starts]
    # Rotate every cycle to its first vertex with one gather, then cut.
    shift = np.repeat(first - starts, sizes)
    local = np.arange(len(V)) - np.repeat(starts, sizes)
    V = V[np.repeat(starts, sizes) + (local + shift) % np.repeat(sizes, sizes)]
    out = [V[s:e] for s, e in zip(starts.tolist(), ends.tolist())]
    for c in np.flatnonzero(bad).tolist():
        out[c] = normalize(drop_collinear(out[c]))
    return out
