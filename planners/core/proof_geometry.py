"""The geometry of the independent proof checker (:mod:`planners.core.proof_check`), with none of
the project's geometry code: an exact orientation predicate of its own, exact "inside the true
disk", the fast core containment test, and POSSIBLE re-derived with shapely.

Tolerance model (shared with the planner, issue 49): one unit u = 2^-40·S, S = the largest
coordinate magnitude of the bounds and the obstacles as the checker sees them + r·√2 (r the
largest distance of a proof robot-piece vertex from the reference point): :func:`scene_unit`.
The planner (:mod:`cspace.se2.slab_graph`) derives its proof-side numbers from the same S:

========================================  ==========  ================
what                                      planner     checker
========================================  ==========  ================
core edges pulled in beyond the rounding  4 u         must keep ≥ u (:func:`core_inside`)
POSSIBLE grown (cores / obstacle union)   64 u        16 u (the checker's regions lie in the planner's)
components linked / end nodes within      1024 u      512 u (so the proof lists all the checker wants)
proof component = recomputed one          --          area diff ≤ 1e-9·bounds + 256 u·perimeters
========================================  ==========  ================

Float error of every quantity compared with u is a few 2^-53·S, 2^-10 u or less.
"""
from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import shapely

TWO_PI = 2.0 * math.pi
UNIT_REL = 2.0**-40
SHRINK_UNITS = 16.0
TOUCH_UNITS = 512.0
MATCH_UNITS = 256.0
PEAK_SLACK = 1e-9
ANGLE_SLACK = 1e-9  # a slab holds the start's or goal's angle within this
ERRBOUND = 3.3306690738754716e-16  # Shewchuk's ccwerrboundA


def orient(a, b, c) -> int:
    """The exact sign of the turn a -> b -> c (1 left, -1 right, 0 collinear) of float points.

    >>> orient((0, 0), (1, 0), (0, 1)), orient((0.1, 0.1), (0.2, 0.2), (0.3, 0.3))
    (1, 0)
    """
    dl = (b[0] - a[0]) * (c[1] - a[1])
    dr = (b[1] - a[1]) * (c[0] - a[0])
    det, total = dl - dr, abs(dl) + abs(dr)
    if math.isfinite(total) and total > 1e-250 and abs(det) > ERRBOUND * total:
        return 1 if det > 0 else -1
    f = [Fraction(v) for v in (*a, *b, *c)]
    d = (f[2] - f[0]) * (f[5] - f[1]) - (f[3] - f[1]) * (f[4] - f[0])
    return (d > 0) - (d < 0)


def strictly_convex_ccw(pts) -> bool:
    """Whether the ring ``pts`` (not closed) is a strictly convex CCW polygon, decided exactly:
    every turn strictly left (a float filter over all turns at once, :func:`orient` where it is
    unsure) and the edge directions going round exactly once.

    >>> strictly_convex_ccw([(0, 0), (1, 0), (0, 1)]), strictly_convex_ccw([(0, 0), (0, 1), (1, 0)])
    (True, False)
    """
    n = len(pts)
    if n < 3:
        return False
    p = np.asarray(pts, dtype=np.float64)
    a, b, c = p, np.roll(p, -1, axis=0), np.roll(p, -2, axis=0)
    with np.errstate(all="ignore"):
        dl = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1])
        dr = (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        det, total = dl - dr, np.abs(dl) + np.abs(dr)
    sure = np.isfinite(total) & (total > 1e-250) & (np.abs(det) > ERRBOUND * total)
    if np.any(sure & (det <= 0)):
        return False
    for i in np.flatnonzero(~sure).tolist():
        if orient(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) <= 0:
            return False
    d = b - a  # the sign of a float difference is exact
    half = np.where((d[:, 1] > 0) | ((d[:, 1] == 0) & (d[:, 0] > 0)), 0, 1)
    return int(np.sum((half == 1) & (np.roll(half, -1) == 0))) == 1


def in_arc(t: float, a: float, b: float, slack: float) -> bool:
    """Whether the angle t (modulo 2 pi) lies in [a - slack, b + slack]."""
    d = math.fmod(t - a, TWO_PI)
    d = d + TWO_PI if d < 0 else d
    return d <= (b - a) + slack or d >= TWO_PI - slack


def scene_unit(bounds, obstacle_parts, pieces) -> float:
    """u = 2^-40·S (see the module docstring).

    >>> scene_unit((0, 4, 0, 2), [np.array([[1., 1], [2, 1], [2, 2]])], [[(3.0, 4.0)]]) == 2.0**-40 * (4 + 5 * 2**0.5)
    True
    """
    s = max([abs(float(v)) for v in bounds] + [float(np.abs(o).max()) for o in obstacle_parts if len(o)])
    r = max((math.hypot(x, y) for p in pieces for x, y in p), default=0.0)
    return UNIT_REL * (s + r * math.sqrt(2.0))


def in_disk(points, disk) -> bool:
    """Whether every point lies strictly inside the true disk (cx, cy, r), decided exactly (a float
    filter with a bound on its error, then ``Fraction`` on the stored floats where it is unsure).

    >>> in_disk([(0.6, 0.8)], (0.0, 0.0, 1.0)), in_disk([(0.6, 0.79)], (0.0, 0.0, 1.0))
    (False, True)
    """
    cx, cy, r = (float(v) for v in disk)
    fr = Fraction(r) ** 2
    for x, y in points:
        err = 4.0 * (math.ulp(max(abs(x), abs(cx))) + math.ulp(max(abs(y), abs(cy))))
        d = math.hypot(x - cx, y - cy)
        if math.isfinite(d) and d + err < r * (1.0 - 1e-12):
            continue
        if (Fraction(x) - Fraction(cx)) ** 2 + (Fraction(y) - Fraction(cy)) ** 2 >= fr:
            return False
    return True


def inner_disk(disk, sides: int) -> np.ndarray:
    """A convex polygon strictly inside the true disk (cx, cy, r): the regular ``sides``-gon on a
    circle a little smaller (the planner's inscribed polygon, re-derived), every vertex checked
    exactly by :func:`in_disk` (one that is not is dropped: a smaller obstacle); (0, 2) if none holds.

    >>> p = inner_disk((1.0, 2.0, 0.5), 12)
    >>> len(p), in_disk(p.tolist(), (1.0, 2.0, 0.5))
    (12, True)
    """
    cx, cy, r = (float(v) for v in disk)
    inner = r - (2.0**-46 * r + 16.0 * math.ulp(max(abs(cx), abs(cy)) + r))
    ang = -math.pi / 2 + math.pi / sides + 2.0 * math.pi * np.arange(sides) / sides
    pts = [p for p in zip((cx + inner * np.cos(ang)).tolist(), (cy + inner * np.sin(ang)).tolist())
           if in_disk([p], disk)]
    hull = shapely.convex_hull(shapely.multipoints(pts)) if len(pts) >= 3 else None
    if hull is None or hull.geom_type != "Polygon" or not hull.area > 0:
        return np.zeros((0, 2))
    return np.asarray(hull.exterior.coords)[:-1]


def convex_obstacles(scenario) -> list:
    """The obstacles as convex parts (vertex arrays) inside the obstacles as written: convex ones
    as they are, others triangulated, a disk by a polygon inside it (:func:`inner_disk`; its
    circumscribed polygon would be more obstacle than the scenario has)."""
    parts = []
    for ob in scenario.obstacles:
        if ob.disk is not None:
            inner = inner_disk(ob.disk, len(ob.polygon))
            if len(inner):
                parts.append(inner)
            continue
        pts = [(float(x), float(y)) for x, y in np.asarray(ob.polygon, dtype=float)]
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts.pop()
        if not len(ob.holes) and (strictly_convex_ccw(pts) or strictly_convex_ccw(pts[::-1])):
            parts.append(np.array(pts))
            continue
        poly = shapely.Polygon(ob.polygon, [h for h in ob.holes])
        tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
        for t in tris[shapely.covers(poly, tris) & (shapely.area(tris) > 0)]:
            parts.append(np.asarray(t.exterior.coords)[:-1])
    return parts


def _lowest_ccw(p: np.ndarray) -> np.ndarray:
    """The convex polygon's vertices CCW from its lowest (then leftmost) one."""
    q = p - p[0]  # the shoelace about a vertex: no cancellation far from the origin
    if q[:, 0] @ np.roll(q[:, 1], -1) - q[:, 1] @ np.roll(q[:, 0], -1) < 0:
        p = p[::-1]
    return np.roll(p, -int(np.lexsort((p[:, 0], p[:, 1]))[0]), axis=0)


def convex_sum(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Vertices of a ⊕ b for convex a, b (either orientation) in O(n + m): the two edge sequences
    merged by angle, each vertex a_i + b_j computed directly (one rounding: a point of the true
    sum, so the hull of the result lies in it however close edges were ordered).

    >>> convex_sum(np.array([[0., 0], [1, 0], [0, 1]]), np.array([[0., 0], [2, 0], [2, 2], [0, 2]])).tolist()
    [[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [3.0, 2.0], [2.0, 3.0], [0.0, 3.0], [0.0, 2.0]]
    """
    a, b = _lowest_ccw(a), _lowest_ccw(b)
    ea, eb = np.roll(a, -1, axis=0) - a, np.roll(b, -1, axis=0) - b
    ta = np.mod(np.arctan2(ea[:, 1], ea[:, 0]), TWO_PI)
    tb = np.mod(np.arctan2(eb[:, 1], eb[:, 0]), TWO_PI)
    order = np.argsort(np.concatenate([ta, tb]), kind="stable")
    from_a = order < len(a)
    i = np.concatenate([[0], np.cumsum(from_a)[:-1]]) % len(a)
    j = np.concatenate([[0], np.cumsum(~from_a)[:-1]]) % len(b)
    return a[i] + b[j]


class Obstacles:
    """The obstacles' convex parts prepared once for every slab's sums: each CCW from its lowest
    vertex, with its edge angles (increasing in [0, 2π)), all parts side by side."""

    def __init__(self, parts):
        parts = [_lowest_ccw(np.asarray(o, dtype=np.float64)) for o in parts if len(o) >= 3]
        self.count = len(parts)
        self.sizes = np.array([len(o) for o in parts], dtype=np.int64)
        self.starts = np.concatenate([[0], np.cumsum(self.sizes)[:-1]]).astype(np.int64)
        self.v = np.concatenate(parts) if parts else np.zeros((0, 2))
        e = np.concatenate([np.roll(o, -1, axis=0) - o for o in parts]) if parts else np.zeros((0, 2))
        self.t = np.mod(np.arctan2(e[:, 1], e[:, 0]), TWO_PI)
        self.part = np.repeat(np.arange(self.count), self.sizes)

    def sums(self, core) -> np.ndarray:
        """The convex sums O_p ⊕ (−core) of every part at once, as shapely polygons: the merge of
        :func:`convex_sum` vectorised over the parts (8 × 2π separates the parts' angle ranges)."""
        b = _lowest_ccw(-np.asarray(core, dtype=np.float64))
        eb = np.roll(b, -1, axis=0) - b
        tb = np.mod(np.arctan2(eb[:, 1], eb[:, 0]), TWO_PI)
        m, P = len(b), self.count
        shift = 8.0 * TWO_PI * self.part
        # a-edge i starts at A_i + B_j, j = the b-edges strictly before it; b-edge j at A_i + B_j,
        # i = the part's a-edges at or before it (ties: a first, as a stable merge)
        jb = np.searchsorted(tb, self.t, side="left") % m
        qa = (tb[None, :] + 8.0 * TWO_PI * np.arange(P)[:, None]).ravel()
        ia = np.searchsorted(self.t + shift, qa, side="right") - np.repeat(self.starts, m)
        ia = (ia % np.repeat(self.sizes, m)) + np.repeat(self.starts, m)
        pts = np.concatenate([self.v + b[jb], self.v[ia] + np.tile(b, (P, 1))])
        key = np.concatenate([self.t, np.tile(tb, P)])
        owner = np.concatenate([self.part, np.repeat(np.arange(P), m)])
        tie = np.concatenate([np.zeros(len(self.t)), np.ones(P * m)])
        order = np.lexsort((tie, key, owner))
        sizes = self.sizes + m
        # the merged ring is the convex sum up to one rounding per vertex (no hull needed: every
        # vertex is a point of the sum, so the polygon lies in it)
        return shapely.polygons(shapely.linearrings(pts[order], indices=owner[order])) if len(sizes) else np.array([])


def possible_components(cores, parts, box, shrink) -> list:
    """The components of POSSIBLE for a slab's ``cores``: the box minus the union of the convex
    sums O ⊕ (−C) (:meth:`Obstacles.sums`, their hulls: each vertex a point of the true sum up to
    one rounding), that union eroded by ``shrink`` (a smaller obstacle: rounding never closes a
    passage). Eroding the union, not each sum, opens no crack between the sums of one obstacle's
    triangles where a core is thinner than 2 ``shrink``. ``parts``: an :class:`Obstacles`."""
    parts = parts if isinstance(parts, Obstacles) else Obstacles(parts)
    sums = [parts.sums(core) for core in cores if core and parts.count]
    if not sums:
        return [box]
    blocked = shapely.buffer(shapely.union_all(np.concatenate(sums)), -shrink, join_style="mitre")
    rest = shapely.difference(box, blocked)
    return [g for g in shapely.get_parts(rest) if g.geom_type == "Polygon" and g.area > 0]


# -- the core containment test ---------------------------------------------------------------


class Piece:
    """A robot piece (strictly convex, CCW) prepared for :func:`core_inside`: its vertices, the
    angles of its outward edge normals (increasing, unwrapped twice round), and a sparse table of
    the signed distances d_j of the reference point inside each edge's line, for range minima."""

    def __init__(self, pts):
        self.v = np.asarray(pts, dtype=np.float64)
        n = len(self.v)
        e = np.roll(self.v, -1, axis=0) - self.v
        le = np.hypot(e[:, 0], e[:, 1])
        self.e, self.le = e, le
        # d_j = cross(p_j, ê_j): the reference point lies d_j inside edge j's line (error ≤ ε|p_j|)
        self.d = (self.v[:, 0] * e[:, 1] - self.v[:, 1] * e[:, 0]) / le
        phi = np.arctan2(-e[:, 0], e[:, 1])  # outward normal (ey, -ex)
        k = int(np.argmin(phi))
        order = (np.arange(n) + k) % n
        ang = np.unwrap(phi[order])
        self.order = np.concatenate([order, order])
        self.ang = np.concatenate([ang, ang + TWO_PI])
        table = [np.concatenate([self.d[order], self.d[order]])]
        while (1 << len(table)) <= 2 * n:
            prev, step = table[-1], 1 << (len(table) - 1)
            table.append(np.minimum(prev[:-step], prev[step:]))
        self.table = table
        self.o = self.v.mean(axis=0)  # inside: a strictly convex polygon's vertex average

    def range_min(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """min d over positions [lo, hi) of the doubled order (inf where empty)."""
        out = np.full(len(lo), np.inf)
        ok = hi > lo
        if ok.any():
            ln = (hi[ok] - lo[ok]).astype(np.int64)
            lev = np.floor(np.log2(ln)).astype(np.int64)
            vals = np.full(len(ln), np.inf)
            for L in np.unique(lev).tolist():
                sel = lev == L
                t = self.table[L]
                vals[sel] = np.minimum(t[lo[ok][sel]], t[hi[ok][sel] - (1 << L)])
            out[ok] = vals
        return out

    def inside(self, q: np.ndarray, margin: float) -> np.ndarray:
        """For each point of q (k, 2): is it inside the piece, at least ``margin`` inside the edges
        around it? A binary search (the angle about an inner point o) finds the candidate edge;
        the point passes when it is ``margin`` inside it and its two neighbours and, by a margin
        above the float error, in the cone from o over those three edges (narrower than π): the
        union of their triangles with o, inside the piece. Points the cone test cannot settle are
        checked against every edge (``margin`` inside each). Time O(k log n) but for those."""
        v, n = self.v, len(self.v)
        if n <= 8:
            return self._all_edges(q, margin)
        rel = v - self.o
        a0 = np.arctan2(rel[:, 1], rel[:, 0])
        k0 = int(np.argmin(a0))
        va = np.unwrap(np.roll(a0, -k0))
        qa = np.arctan2(q[:, 1] - self.o[1], q[:, 0] - self.o[0])
        qa = np.where(qa < va[0], qa + TWO_PI, qa)
        i = (np.searchsorted(va, qa, side="right") - 1 + k0) % n  # candidate edge i -> i+1
        ok = np.ones(len(q), dtype=bool)
        for s in (-1, 0, 1):
            j = (i + s) % n
            ok &= self._edge_dist(q, j) >= margin
        lo, hi = v[(i - 1) % n], v[(i + 2) % n]
        o = self.o
        c_lo = (lo[:, 0] - o[0]) * (q[:, 1] - o[1]) - (lo[:, 1] - o[1]) * (q[:, 0] - o[0])
        c_hi = (hi[:, 0] - o[0]) * (q[:, 1] - o[1]) - (hi[:, 1] - o[1]) * (q[:, 0] - o[0])
        narrow = (lo[:, 0] - o[0]) * (hi[:, 1] - o[1]) - (lo[:, 1] - o[1]) * (hi[:, 0] - o[0])
        # the three cross products' float error, with the point moved by a few ε|q| (its rounding)
        band = 16.0 * ERRBOUND * (np.hypot(*(lo - o).T) + np.hypot(*(hi - o).T) + 1e-300) * (
            np.hypot(*(q - o).T) + np.abs(q).max(axis=1) + float(np.abs(o).max()))
        settled = (c_lo > band) & (c_hi < -band) & (narrow > band)
        out = ok & settled
        rest = np.flatnonzero(~settled)
        if len(rest):
            out[rest] = self._all_edges(q[rest], margin)
        return out

    def _edge_dist(self, q, j) -> np.ndarray:
        # cross(ê_j, q - p_j): the distance of q inside edge j's line (error ≤ 4ε·(|q| + |p|))
        p, e, le = self.v[j], self.e[j], self.le[j]
        return (e[:, 0] * (q[:, 1] - p[:, 1]) - e[:, 1] * (q[:, 0] - p[:, 0])) / le

    def _all_edges(self, q, margin) -> np.ndarray:
        out = np.ones(len(q), dtype=bool)
        for j in range(len(self.v)):  # n steps over all points at once
            out &= self._edge_dist(q, np.full(len(q), j)) >= margin
        return out


def core_inside(core, piece: Piece, a: float, b: float, unit: float):
    """None if every vertex c of ``core`` stays at least ``unit`` inside ``piece`` turned by every
    θ in [a, b] (R_(-θ) c in the piece: the arc of c's positions); else the index of a vertex
    that does not. The arc lies inside a convex piece when its two ends do (each found ``unit``
    inside the edges around it by :meth:`Piece.inside`: the true turned point, within 4ε|c| of the
    computed one, is then inside) and, for every edge whose outward normal
    points into the arc's range of directions (a contiguous run of the sorted normals, found by
    binary search, with 1e-9 rad slack), the arc's farthest point along it, |c|, stays unit inside:
    d_j − |c| ≥ unit, the run's minimum of d_j from a sparse table. Time O((n + m) log(n + m)).

    >>> sq = Piece([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])
    >>> core_inside([(0.5, 0.0), (0.0, 0.5), (-0.5, 0.0)], sq, 0.0, 0.5, 1e-12) is None
    True
    >>> core_inside([(0.0, 0.5), (0.95, 0.9), (-0.5, 0.0)], sq, 0.0, 1.0, 1e-12)  # turned to 0°: x = 1.31
    1
    """
    c = np.asarray(core, dtype=np.float64).reshape(-1, 2)
    if not np.isfinite(c).all():
        return 0
    rho = np.hypot(c[:, 0], c[:, 1])
    ok = np.ones(len(c), dtype=bool)
    for t in (a, b):  # w = R_(-t) c, within 4ε|c| of the true turned point
        co, si = math.cos(t), math.sin(t)
        w = np.column_stack([c[:, 0] * co + c[:, 1] * si, -c[:, 0] * si + c[:, 1] * co])
        ok &= piece.inside(w, unit)
    # directions of w over the arc: ψ - b .. ψ - a; normals in that range (slack both sides)
    psi = np.arctan2(c[:, 1], c[:, 0])
    lo_ang = psi - b - PEAK_SLACK
    base = piece.ang[0]
    lo_ang = base + np.mod(lo_ang - base, TWO_PI)
    hi_ang = lo_ang + (b - a) + 2 * PEAK_SLACK
    lo = np.searchsorted(piece.ang, lo_ang, side="left")
    hi = np.searchsorted(piece.ang, hi_ang, side="right")
    trough = piece.range_min(lo, hi)
    ok &= ~(trough - rho < unit)
    bad = np.flatnonzero(~ok)
    return int(bad[0]) if len(bad) else None

class Graph:
    """The checker's graph, built slab by slab as the regions are matched (two slabs' regions
    kept at a time, and the first for the wrap-around): the proof's nodes, the checker's own for
    unlisted slivers, the links it finds and the proof's edges; the first missing end node or edge."""

    def __init__(self, p, q, touch):
        self.p, self.q, self.touch = p, q, touch
        self.ends = {"start": set(), "goal": set()}
        self.extra, self.faults = [], {}  # step -> the first fault of that step
        self.given = set(p["edges"])

    def slab(self, k, comps, owners):
        s = self.p["slabs"][k]
        node = (lambda r: (k, owners[r]) if owners[r] is not None else ("own", k, r))
        for key, pose in (("start", self.q.start), ("goal", self.q.goal)):
            if in_arc(pose[2], s["a"], s["b"], ANGLE_SLACK):
                point = shapely.Point(pose[0], pose[1])
                found = {node(r) for r, g in enumerate(comps) if shapely.dwithin(g, point, self.touch)}
                listed = set(self.p[f"{key}_nodes"])
                missing = sorted(n for n in found if n[0] != "own" and n not in listed)
                if missing:
                    self.faults.setdefault("nodes", f"{key}_nodes lacks {list(missing[0])}, a component holding "
                                                    f"the {key}")
                self.ends[key] |= found
        return node

    def link(self, k, comps, node, k2, comps2, node2):
        """Pairs of components of slab k and k2 (k2 = k: the same slab) whose closures touch."""
        if not comps or not comps2:
            return
        left, right = shapely.STRtree(comps2).query(comps, predicate="dwithin", distance=self.touch)
        for u, v in ((node(r), node2(r2)) for r, r2 in zip(left.tolist(), right.tolist())):
            if k2 == k or "own" in (u[0], v[0]):
                self.extra.append((u, v))
            elif (*u, *v) not in self.given:
                self.faults.setdefault("edges", f"edges lacks {[*u, *v]}: the components touch")
