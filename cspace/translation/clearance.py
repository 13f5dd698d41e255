"""The clearance of a path: how close the robot, swept along it, comes to any obstacle.

Translation (exact per segment). A convex robot piece R translated from p0 to p1
sweeps conv((R + p0) ∪ (R + p1)): every intermediate position p(t) + R lies in it, and
every point of the hull is a point of some p(t) + R (the hull of two translates of a
convex set is their union over the segment). So the distance between the swept robot
and a convex obstacle piece O is the GJK distance between the point set
(R + p0) ∪ (R + p1) (GJK only reads its support function, which is the hull's) and O.
The smallest over segments, robot pieces and obstacle pieces is the path's clearance.
A broad phase skips pairs: pieces are visited in order of their bounding boxes'
distance (a lower bound), and the search stops once that bound reaches the best
distance found so far, over the whole path. Where the minimum occurs: the reference
point on the segment closest to O ⊕ (−R), by GJK of the segment against that sum.

The SE(2) lower bound built on :class:`Nearest` is :mod:`cspace.se2.clearance`.

With the compiled fast path, the walk over the pairs runs in C (cspace/compiled/_nearest.c),
each pair decided as the Python loop below decides it (tests/compiled/test_gjk_fast.py: the same
answers, to the bit); contacts and the exact band return to that loop.

Distances are GJK's, float (error about 2^-50 of the coordinates' scale); the search
skips pairs that cannot be nearer than the best found by more than 2^-44 of that scale
(their bounds: the float distance from the segment to O ⊕ (−R)), so the result is within
that of the least GJK distance; contact is decided exactly (0.0 means the swept robot
touches an obstacle).
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..kernel.distance.gjk import EXACT_BAND, MAX_ITERATIONS, gjk_distance, gjk_distance_below, witness_weights
from ..kernel.polygons.scaling import SAFE_MAX, SAFE_MIN
from ..kernel.polygons.polygon import piece_boxes
from ..compiled import fastpath

# Translation: the search stops at pairs whose lower bound is within TIE x the coordinate scale
# of the best distance found (see path_clearance).
TIE = 2.0**-44
GJK_FIRST = 32  # pairs measured on box bounds before the rest get tight ones
FEW_PAIRS = 1 << 10  # (sweep, obstacle piece) pairs up to which the broad phase keeps them all


class PathClearance(NamedTuple):
    """The smallest distance between the robot swept along a path and the obstacles.

    ``distance`` (inf without obstacles), ``where``: the reference pose on the path
    where it occurs, ``obstacle_point``: the closest point of the obstacle, ``segment``:
    the path segment's index, ``bound``: ``"exact"`` (translation) or ``"lower"`` (SE(2):
    never more than the true clearance); ``cut``: the measure stopped at its deadline before its
    precision (still a lower bound, a looser one).
    """

    distance: float
    where: tuple
    obstacle_point: tuple
    segment: int
    bound: str
    cut: bool = False


class Nearest:
    """Convex pieces behind their bounding boxes: the distance from a convex set (the hull
    of a point set) to the nearest piece, boxes first (a lower bound), GJK for the rest.

    >>> near = Nearest([np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
    >>> near.distance(np.array([[1., 5]])), near.distance(np.array([[1., 1], [3, 3]]))
    (3.0, 1.4142135623730951)
    """

    def __init__(self, pieces: list[np.ndarray]):
        self.loop = fastpath.gjk_loop()  # the compiled GJK loop, or None (pure): fixed at construction
        packed = fastpath.pack_boxes(pieces)  # compiled: packed points and boxes in one pass
        if packed is not None:  # (every piece a finite float64 (n, 2) array, used as it is)
            self.pieces = list(pieces)
            self.xy, self.off, self.lo, self.hi, self.scale = packed
        else:
            self.pieces = [np.ascontiguousarray(p, dtype=np.float64) for p in pieces]
            self.lo, self.hi = piece_boxes(self.pieces)  # all boxes in two reductions
            self.xy = self.off = None
            # the largest |coordinate| of the pieces is one of their boxes', max(hi, -lo)
            self.scale = max(float(self.hi.max()), -float(self.lo.min())) if len(self.pieces) else -math.inf
        # the compiled pass over losing pairs of path_clearance (with the packed points), or None
        self.scan = fastpath.clearance_scan() if self.xy is not None else None

    def nearest(self, pts: np.ndarray, cap: float = math.inf):
        """(distance, piece, point on the piece) of the closest piece to conv(pts), or
        (cap, -1, None) when every piece is at least ``cap`` away (boxes first)."""
        if not len(self.pieces):
            return cap, -1, None
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        gap = np.maximum(np.maximum(self.lo - hi, lo - self.hi), 0.0)
        lb = np.hypot(gap[:, 0], gap[:, 1])
        cand = np.flatnonzero(lb < cap)
        best, k_best, w_best = cap, -1, None
        for k in cand[np.argsort(lb[cand], kind="stable")].tolist():
            if lb[k] >= best:
                break
            d = gjk_distance_below(pts, self.pieces[k], best if k_best >= 0 else math.nextafter(best, math.inf),
                                   loop=self.loop)
            if d is not None and (d.distance < best or k_best < 0 and d.distance <= best):
                best, k_best, w_best = d.distance, k, d.point_b
                if best == 0.0:
                    break
        return best, k_best, w_best

    def distance(self, pts: np.ndarray) -> float:
        """The distance from conv(pts) to the nearest piece (inf without pieces)."""
        return float(self.nearest(pts)[0])

    def within(self, lo, hi, reach: float) -> "Nearest":
        """The pieces whose boxes come within ``reach`` of the box [lo, hi], as a Nearest: every
        other piece is farther than ``reach`` from any set inside that box (a box gap is a lower
        bound of the distance), so a path's measure asks only its neighbourhood.

        >>> near = Nearest([np.array([[4., 4], [6, 4], [6, 6], [4, 6]]), np.array([[40., 0], [41, 0], [41, 1]])])
        >>> len(near.within((0.0, 0.0), (1.0, 1.0), 5.0).pieces), len(near.within((0.0, 0.0), (1.0, 1.0), 1.0).pieces)
        (1, 0)
        """
        if not len(self.pieces):
            return self
        gap = np.maximum(np.maximum(self.lo - np.asarray(hi, dtype=np.float64),
                                    np.asarray(lo, dtype=np.float64) - self.hi), 0.0)
        # (the slack covers hypot's rounding: a piece on the edge of the reach is kept)
        keep = np.flatnonzero(np.hypot(gap[:, 0], gap[:, 1]) <= reach * (1.0 + 2.0**-40))
        return Nearest([self.pieces[k] for k in keep.tolist()])


class EdgeDistance:
    """Float distance from a point or a segment to the nearest edge of convex pieces, all
    edges at once (numpy): the clearance of a FREE state or motion (one that meets no piece;
    a segment inside a piece would read its distance to the edges, not 0). It feeds the
    planners' objectives, where a float value is enough; reported clearances use GJK.

    >>> ed = EdgeDistance([np.array([[4., 4], [6, 4], [6, 6], [4, 6]])])
    >>> ed.point(1.0, 5.0), ed.segment(1.0, 1.0, 3.0, 3.0)
    (3.0, 1.4142135623730951)
    """

    def __init__(self, pieces: list[np.ndarray]):
        ps = [np.asarray(p, dtype=np.float64) for p in pieces if len(p)]
        self.a = np.concatenate(ps) if ps else np.zeros((0, 2))
        self.b = np.concatenate([np.roll(p, -1, axis=0) for p in ps]) if ps else np.zeros((0, 2))
        self.d = self.b - self.a
        self.dd = np.maximum(np.einsum("ij,ij->i", self.d, self.d), np.finfo(float).tiny)
        self.ab = np.concatenate([self.a, self.b])

    def _point_to_edges(self, x: float, y: float) -> np.ndarray:
        px, py = x - self.a[:, 0], y - self.a[:, 1]
        t = np.minimum(np.maximum((px * self.d[:, 0] + py * self.d[:, 1]) / self.dd, 0.0), 1.0)
        return np.hypot(px - t * self.d[:, 0], py - t * self.d[:, 1])

    def point(self, x: float, y: float) -> float:
        """Distance from (x, y) to the nearest edge (inf without pieces)."""
        return float(self._point_to_edges(x, y).min()) if len(self.a) else math.inf

    def segment(self, x0: float, y0: float, x1: float, y1: float) -> float:
        """Distance from the segment to the nearest edge: 0 where they cross, else the least
        of the four endpoint-to-segment distances (inf without pieces)."""
        if not len(self.a):
            return math.inf
        ux, uy = x1 - x0, y1 - y0
        uu = ux * ux + uy * uy
        d = min(self._point_to_edges(x0, y0).min(), self._point_to_edges(x1, y1).min())
        if uu > 0.0:  # the edges' endpoints against the segment, both ends in one array
            q = self.ab - (x0, y0)
            qx, qy = q[:, 0], q[:, 1]
            t = np.minimum(np.maximum((qx * ux + qy * uy) * (1.0 / uu), 0.0), 1.0)
            d = min(d, np.hypot(qx - t * ux, qy - t * uy).min())
            # proper crossings: each edge's ends on both sides of the segment's line, and back
            side = ux * qy - uy * qx
            n = len(self.a)
            s3 = self.d[:, 0] * (y0 - self.a[:, 1]) - self.d[:, 1] * (x0 - self.a[:, 0])
            s4 = self.d[:, 0] * (y1 - self.a[:, 1]) - self.d[:, 1] * (x1 - self.a[:, 0])
            if ((side[:n] * side[n:] < 0) & (s3 * s4 < 0)).any():
                return 0.0
        return float(d)


def path_clearance(path, robot_pieces: list, obstacle_pieces: list) -> PathClearance:
    """Exact clearance of a translating robot's path (see the module docstring).

    ``path`` is (N, 2) reference positions; ``robot_pieces`` the convex robot pieces
    relative to the reference point ([] for a point robot); ``obstacle_pieces`` convex.

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> rob = [np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])]
    >>> c = path_clearance(np.array([[1., 1], [9, 1]]), rob, [sq])
    >>> c.distance, c.bound, c.obstacle_point[1]
    (2.0, 'exact', 4.0)
    """
    pts = np.asarray(path, dtype=np.float64).reshape(-1, 2)
    obs = Nearest(obstacle_pieces)
    rob = [np.asarray(r, dtype=np.float64) for r in robot_pieces] or [np.zeros((1, 2))]
    if not len(pts):
        return PathClearance(math.inf, (), (), -1, "exact")
    best, arg = math.inf, None
    if not len(obs.pieces):
        return PathClearance(math.inf, (), (), -1, "exact")
    # The broad phase over the whole path at once: the box of every (segment, robot piece)
    # sweep against every obstacle box, the pairs then visited by increasing box distance
    # (a lower bound) until it reaches the best distance found.
    a, b = (pts[:-1], pts[1:]) if len(pts) > 1 else (pts, pts)  # the segments' ends, as rows
    rlo, rhi = _boxes(rob)
    lo = (np.minimum(a, b)[:, None, :] + rlo[None, :, :]).reshape(-1, 2)  # (segment, piece) rows
    hi = (np.maximum(a, b)[:, None, :] + rhi[None, :, :]).reshape(-1, 2)
    nr, no = len(rob), len(obs.pieces)

    def box_bounds(s0: int, s1: int) -> np.ndarray:  # sweeps s0..s1 against every obstacle box
        if (gaps := fastpath.box_gaps(lo[s0:s1], hi[s0:s1], obs.lo, obs.hi)) is not None:  # compiled: the same doubles
            return gaps
        gap = np.maximum(np.maximum(obs.lo[None, :, :] - hi[s0:s1, None, :], lo[s0:s1, None, :] - obs.hi[None, :, :]), 0.0)
        return np.hypot(gap[..., 0], gap[..., 1])

    # Candidate pairs as row * no + k (row: sweep, k: obstacle piece); pairs=None: all of them.
    if len(lo) * no <= FEW_PAIRS:  # few: every pair, in one block (the search's stop rule
        lbs, pairs = box_bounds(0, len(lo)).ravel(), None  # drops what the filter below would)
    else:
        step = max(1, (1 << 20) // no)  # bound the (sweeps, obstacles) block
        cand_lb, cand = [], []
        for s0 in range(0, len(lo), step):
            lb = box_bounds(s0, s0 + step)
            # Keep, per sweep, the pieces no farther than the nearest piece's far corner could be.
            keep = np.flatnonzero(lb <= lb.min(axis=1, keepdims=True) + _reach(lo[s0:s0 + step], hi[s0:s0 + step],
                                                                                obs)[:, None])
            cand_lb.append(lb.ravel()[keep])
            cand.append(keep + s0 * no)
        lbs, pairs = np.concatenate(cand_lb), np.concatenate(cand)
    # Pairs whose lower bound is within TIE x the scene's coordinate scale of the best
    # distance found are not measured (GJK's own error is about 2^-50 x that scale). A path
    # with a margin runs at one distance, to rounding, along many segments, where box
    # bounds leave GJK hundreds of pairs: after GJK_FIRST pairs, the rest get tight bounds.
    slack = TIE * max(float(pts.max()), -float(pts.min()), obs.scale)
    queue, pos, measured = np.argsort(lbs, kind="stable"), 0, 0
    still = (a == b).all(axis=1)  # a segment of one point sweeps the piece itself
    # Each robot piece placed at every path point: a segment's swept point set is two
    # consecutive placements, one contiguous block (a view, no copy).
    placed = [(r[None, :, :] + pts[:, None, :]).reshape(-1, 2) for r in rob]

    def swept(i: int, j: int) -> np.ndarray:  # segment i's placements of robot piece j
        nv = len(rob[j])
        return placed[j][i * nv:(i + 1 if still[i] else i + 2) * nv]

    def tighten(queue, pos, lbs):  # the pairs left, on tight bounds, in their order
        rest = queue[pos:]
        rest = rest[lbs[rest] < best - slack]
        lbs = lbs.copy()
        rows, ks = np.divmod(rest if pairs is None else pairs[rest], no)
        lbs[rest] = _tighter_bounds(lbs[rest], rows, ks, a, b, rob, obs)
        return rest[np.argsort(lbs[rest], kind="stable")], 0, lbs

    while pos < len(queue):
        if obs.scan is not None:  # compiled: the pairs whose answer is GJK's float one
            pos, n, won = obs.scan(placed, len(pts), still, obs.xy, obs.off, queue, pairs, lbs, no, pos, best, slack,
                                   GJK_FIRST - measured if measured < GJK_FIRST else -1, MAX_ITERATIONS, SAFE_MIN,
                                   SAFE_MAX, EXACT_BAND, math.hypot)
            if won is not None:
                best, t, bx, by = won
                row, k = divmod(t, no)
                arg = (*divmod(row, nr), k, np.array((bx, by)))
            measured += n
            if n and measured == GJK_FIRST:
                queue, pos, lbs = tighten(queue, pos, lbs)
                continue
            if pos == len(queue):
                break
        t = int(queue[pos])
        pos += 1
        if lbs[t] >= best - slack:
            break
        row, k = divmod(t if pairs is None else int(pairs[t]), no)
        i, j = divmod(row, nr)
        d = gjk_distance_below(swept(i, j), obs.pieces[k], best if arg is not None else math.inf, loop=obs.loop)
        if d is not None and (d.distance < best or arg is None):
            best, arg = d.distance, (i, j, k, d.point_b)
            if best == 0.0:
                break
        measured += 1
        if measured == GJK_FIRST:
            queue, pos, lbs = tighten(queue, pos, lbs)
    if arg is None:
        return PathClearance(math.inf, (), (), -1, "exact")
    i, j, k, w = arg
    # Where: GJK's closest point on the swept set is a weighted sum of placed vertices r + p
    # (p the segment's start or end); the same weights on the p's give a reference position
    # whose placed piece holds that point, so lies at the distance found (no C-obstacle built).
    weights = witness_weights(swept(i, j), obs.pieces[k], loop=obs.loop)
    if weights is not None:  # vertex v of the swept block is at path point i + v // (piece's vertices)
        ends = pts[i:i + 2].tolist()  # in floats: the same sums (from 0, in order) as on numpy scalars
        x = y = 0
        for v, t in weights:
            px, py = ends[v // len(rob[j])]
            x, y = x + t * px, y + t * py
        where = (float(x), float(y))
    else:  # touching, or decided exactly: the segment's point nearest the C-obstacle,
        # and the obstacle's point nearest the piece placed there (where the sweep touches
        # along a stretch, the sweep's own witness may lie elsewhere on it)
        where = _closest_position((pts[i], pts[min(i + 1, len(pts) - 1)]), rob[j], obs.pieces[k], obs.loop)
        w = gjk_distance(rob[j] + np.array(where), obs.pieces[k], loop=obs.loop).point_b
    return PathClearance(float(best), where, tuple(float(v) for v in w), i, "exact")


def _boxes(pieces: list) -> tuple[np.ndarray, np.ndarray]:
    """The pieces' boxes (:func:`cspace.kernel.polygons.polygon.piece_boxes`), compiled where built."""
    packed = fastpath.pack_boxes(pieces)
    return piece_boxes(pieces) if packed is None else packed[2:4]


def _tighter_bounds(lbs, rows, ks, a, b, rob, obs) -> np.ndarray:
    """The box bounds ``lbs`` of the candidate (sweep, obstacle piece) pairs raised to the
    float distance from the sweep's segment to O ⊕ (−R) (the translating piece R meets O
    where its reference point meets that sum), less a tolerance of 2^-46 x the coordinate
    scale (some 30 times that distance's rounding): still lower bounds, tight enough that
    GJK runs on few pairs. Scenes far from unit scale (products could underflow or
    overflow) keep the box bounds."""
    from ..kernel.minkowski.merge import reflect
    from .build import pair_sums  # compiled when built; equal to pairwise_sums

    if not len(rows):
        return lbs
    nr = len(rob)
    i, j = rows // nr, rows % nr
    key = ks * nr + j
    uniq, inv = np.unique(key, return_inverse=True)
    polys: list = [None] * len(uniq)
    for jj in range(nr):  # the C-obstacles the candidates need, batched per robot piece
        sel = np.flatnonzero(uniq % nr == jj)
        if not len(sel):
            continue
        obst = [obs.pieces[k] for k in (uniq[sel] // nr).tolist()]
        r = rob[jj]
        sums = obst if len(r) == 1 and not r.any() else pair_sums(obst, [reflect(r)])
        for t, poly in zip(sel.tolist(), sums):
            polys[t] = poly
    sizes = np.array([len(p) for p in polys])
    E = int(sizes.max())
    P = np.zeros((len(polys), E, 2))
    for t, poly in enumerate(polys):
        P[t, : len(poly)] = poly
        P[t, len(poly):] = poly[0]  # padding repeats a vertex: zero-length edges change nothing
    scale = max(float(np.abs(P).max()), float(np.abs(a).max()), float(np.abs(b).max()))
    if not (1e-100 < scale < 1e100):
        return lbs
    d = _segment_polygon_distance(a[i], b[i], P[inv])
    tol = 2.0**-46 * (scale + np.where(np.isfinite(d), d, 0.0))
    return np.where(np.isfinite(d), np.fmax(lbs, d - tol), lbs)


def _segment_polygon_distance(a, b, P) -> np.ndarray:
    """Float distance from each segment a[t]-b[t] to the closed convex CCW polygon P[t]
    (padded to a common length by repeating its first vertex: zero-length edges):
    0 when an end lies inside or the segment crosses an edge, else the least of the
    ends' distances to the edges and the vertices' distances to the segment."""
    Q = np.roll(P, -1, axis=1)
    ex, ey = Q[..., 0] - P[..., 0], Q[..., 1] - P[..., 1]

    def side(px, py):  # edge e x (p - P_e), per edge
        return ex * (py[:, None] - P[..., 1]) - ey * (px[:, None] - P[..., 0])

    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sa, sb = side(a[:, 0], a[:, 1]), side(b[:, 0], b[:, 1])
        inside = (sa >= 0).all(axis=1) | (sb >= 0).all(axis=1)
        ux, uy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
        o1 = ux[:, None] * (P[..., 1] - a[:, 1, None]) - uy[:, None] * (P[..., 0] - a[:, 0, None])
        o2 = ux[:, None] * (Q[..., 1] - a[:, 1, None]) - uy[:, None] * (Q[..., 0] - a[:, 0, None])
        cross = ((o1 * o2 <= 0) & (sa * sb <= 0) & ((ex != 0) | (ey != 0))).any(axis=1)
        d = np.minimum(_point_segment(a[:, None, :], P, Q), _point_segment(b[:, None, :], P, Q)).min(axis=1)
        d = np.minimum(d, _point_segment(P, a[:, None, :], b[:, None, :]).min(axis=1))
    return np.where(inside | cross, 0.0, d)


def _point_segment(p, s0, s1) -> np.ndarray:
    """Distances from points p to segments s0-s1 (broadcast over the leading axes)."""
    dx, dy = s1[..., 0] - s0[..., 0], s1[..., 1] - s0[..., 1]
    px, py = p[..., 0] - s0[..., 0], p[..., 1] - s0[..., 1]
    ll = dx * dx + dy * dy
    t = np.clip(np.where(ll > 0, (px * dx + py * dy) / np.where(ll > 0, ll, 1.0), 0.0), 0.0, 1.0)
    return np.hypot(px - t * dx, py - t * dy)


def _reach(lo: np.ndarray, hi: np.ndarray, obs: Nearest) -> np.ndarray:
    """Per box, an upper bound of the distance from it to the nearest obstacle piece beyond its
    box distance: the box's diagonal plus the largest obstacle box's diagonal (any point of a
    box is that close to any other point of it), so no piece that could be nearest is dropped."""
    own = np.hypot(*(hi - lo).T)
    other = float(np.hypot(*(obs.hi - obs.lo).T).max())
    return own + other


def _closest_position(seg, robot_piece: np.ndarray, obstacle: np.ndarray, loop=None) -> tuple:
    """The reference position on the segment where the robot piece is closest to the
    obstacle: the segment's point nearest to obstacle ⊕ (−piece) (GJK)."""
    from ..kernel.minkowski.merge import reflect
    from .build import pair_sums  # minkowski_sum's arrays; compiled when built

    p0, p1 = seg
    cobs = pair_sums([obstacle], [reflect(robot_piece)])[0] if len(robot_piece) > 1 or robot_piece.any() else obstacle
    d = gjk_distance(np.array([p0, p1]), cobs, loop=loop)
    return float(d.point_a[0]), float(d.point_a[1])
