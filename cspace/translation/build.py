"""The C-space's build stages, shared by :class:`cspace.translation.cspace.CSpace` and the SE(2)
C-space: the supported range, convex decomposition of obstacles and robot, the batched
pairwise Minkowski sums (obstacle piece ⊕ reflected robot piece), the exact containment
test that prunes pieces, and the :class:`Stage` record each stage leaves in the report.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kernel.polygons.polygon import piece_boxes
from ..kernel.polygons.predicates import orient2d_many
from ..io.scenario.schema import MAX_MAGNITUDE, MIN_EXTENT


@dataclass
class Stage:
    """One build stage: whether it ran, what it counted and what it cost."""

    name: str
    ran: bool
    seconds: float = 0.0
    counts: dict = field(default_factory=dict)
    note: str = ""

    def as_dict(self) -> dict:
        return {"stage": self.name, "ran": self.ran, "seconds": self.seconds, **self.counts, "note": self.note}


# Minkowski sums of pieces of at most PAIR_BATCH_EDGES vertices are batched, about
# PAIR_BATCH_CELLS (obstacle edge, robot edge) comparisons per batch.
PAIR_BATCH_EDGES = 128  # a robot piece with a margin's rounded corners (~75 edges) is still batched
PAIR_BATCH_CELLS = 1 << 20


def check_range(bounds: tuple, shapes: list) -> None:
    """ValueError unless the scene lies in the range the C-space supports (its
    classification multiplies two coordinates): see :data:`cspace.io.scenario.schema.MAX_MAGNITUDE`."""
    xmin, xmax, ymin, ymax = bounds
    if not (xmin < xmax and ymin < ymax):
        raise ValueError(f"CSpace: bounds {bounds} are empty (need xmin < xmax and ymin < ymax)")
    pts = [p for p in shapes if len(p)]
    big = max([abs(v) for v in bounds] + ([float(np.abs(np.concatenate(pts)).max())] if pts else []))
    if not big <= MAX_MAGNITUDE:
        raise ValueError(f"CSpace: a coordinate of magnitude {big:.3g} is beyond the supported 2^400")
    if max(xmax - xmin, ymax - ymin) < MIN_EXTENT:
        raise ValueError(f"CSpace: the bounds' extent {max(xmax - xmin, ymax - ymin):.3g} is below the supported 2^-400")


def decompose_obstacles(obstacles: list[np.ndarray], holes: list[list[np.ndarray]] | None = None,
                        of: list[int] | None = None,
                        convex: list[bool] | None = None) -> tuple[list[np.ndarray], np.ndarray, int]:
    """Convex pieces of the obstacles: (pieces, owning obstacle of each piece, obstacles split).

    Convex obstacles without holes are kept as they are; the others go through
    :func:`cspace.kernel.polygons.decompose.convex_decompose`. ``of[k]``, if given, is the input obstacle
    shell k came from (a MultiPolygon gives several shells); ``convex[k]``, if given, is
    the loader's exact :func:`cspace.kernel.polygons.polygon.is_convex` of shell k (not computed again).
    Shared by :class:`CSpace` and the SE(2) C-space, which decomposes once for all its slabs.

    >>> p, owner, split = decompose_obstacles([np.array([[0., 0], [2, 0], [2, 2], [0, 2]])])
    >>> len(p), owner.tolist(), split
    (1, [0], 0)
    """
    from ..kernel.polygons.polygon import is_convex

    holes = holes or [[] for _ in obstacles]
    pieces, owner, split = [], [], 0
    for k, (poly, hs) in enumerate(zip(obstacles, holes)):
        i = k if of is None else of[k]
        if not hs and (convex[k] if convex is not None else is_convex(poly)):
            parts = [np.asarray(poly, dtype=np.float64)]
        else:
            from ..kernel.polygons.decompose import convex_decompose

            parts = convex_decompose(poly, hs)
            split += 1
        pieces += parts
        owner += [i] * len(parts)
    return pieces, np.array(owner, dtype=np.int64), split


def decompose_robot(robot: list[np.ndarray], is_disk: bool = False) -> tuple[list[np.ndarray], int]:
    """Convex pieces of the robot parts: (pieces, parts split). A disk's polygon is convex.

    >>> p, split = decompose_robot([np.array([[0., 0], [2, 0], [2, 2], [1, 1], [0, 2]])])
    >>> len(p) > 1, split
    (True, 1)
    """
    from ..kernel.polygons.polygon import is_convex

    pieces, split = [], 0
    for part in robot:
        if is_disk or is_convex(part):
            pieces.append(np.asarray(part, dtype=np.float64))
        else:
            from ..kernel.polygons.decompose import convex_decompose

            pieces += convex_decompose(part)
            split += 1
    return pieces, split


# From this many pieces on, the containment prune proposes each piece by its far vertex.
FAR_VERTEX_PIECES = 4096
# Up to this many pieces, it proposes pairs by boxes alone (no polygons built).
BOX_PROPOSALS = 256


def contained_pieces(pieces: list[np.ndarray], boxes: tuple[np.ndarray, np.ndarray] | None = None,
                     packed: tuple[np.ndarray, np.ndarray] | None = None) -> dict[int, int]:
    """Convex pieces lying inside another piece (exact containment test): removed -> container.

    Candidate pairs come from bounding-box containment; a convex piece P lies in a
    convex piece Q iff every vertex of P is on or left of every edge of Q. Of two
    identical pieces only the later one is removed. ``boxes``: the pieces' (lo, hi)
    (:func:`cspace.kernel.polygons.polygon.piece_boxes`), ``packed``: their vertices end to end
    and their sizes (:func:`cspace.kernel.polygons.polygon.pack`), when the caller has them.
    """
    n = len(pieces)
    if n < 2:
        return {}
    lo, hi = boxes if boxes is not None else piece_boxes(pieces)
    removed: dict[int, int] = {}
    # Pairs (q, p), p != q, whose box lies inside q's box (closed), each q's in the order of
    # ``order``. A piece inside q has every vertex in q, so one vertex stands for it: an
    # STRtree of those points proposes the pieces holding each (near-linear, where boxes of
    # long thin pieces overlap by the thousand), the exact box comparisons and the exact
    # vertex test below decide. The vertex: the first, or among many pieces the one
    # farthest from the middle of the pieces' boxes (pieces fanning out from one place, a
    # star's spikes, share their inner vertices with many others, while their far ends lie
    # in few; choosing it costs more than it saves on small scenes). (Pieces of fewer than 3
    # vertices: boxes covering boxes.)
    import shapely

    if n <= BOX_PROPOSALS:
        # Few pieces: every pair whose boxes nest, by one comparison of all the boxes (at
        # most n^2 pairs for the exact test; building the trees and polygons for the
        # point-in-polygon filter below costs more than the exact test of what it drops).
        nest = (lo[None, :, 0] >= lo[:, None, 0]) & (hi[None, :, 0] <= hi[:, None, 0]) & \
            (lo[None, :, 1] >= lo[:, None, 1]) & (hi[None, :, 1] <= hi[:, None, 1])
        np.fill_diagonal(nest, False)
        qs, ps = np.nonzero(nest)  # exactly the pairs the filter below keeps
    elif (sizes := packed[1] if packed is not None else np.fromiter((len(p) for p in pieces), np.int64, n)).min() >= 3:
        flat = packed[0] if packed is not None else np.concatenate(pieces)
        owner = np.repeat(np.arange(n), sizes)
        rings = shapely.linearrings(flat, indices=owner)
        rep = np.cumsum(sizes) - sizes  # each piece's first vertex
        if n >= FAR_VERTEX_PIECES:
            mid = 0.5 * (lo.min(axis=0) + hi.max(axis=0))
            d = flat - mid
            far = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
            pick = np.flatnonzero(far == np.maximum.reduceat(far, rep)[owner])
            rep = pick[np.r_[True, owner[pick[1:]] != owner[pick[:-1]]]]  # the first of ties: one per piece
        reps = shapely.points(flat[rep])
        # The pieces are the (prepared) query geometries, the points the tree: a piece of
        # 10^5 vertices is indexed once, not walked once per point near it.
        qs, ps = shapely.STRtree(reps).query(shapely.polygons(rings), predicate="intersects")
    else:
        boxes = shapely.box(lo[:, 0], lo[:, 1], hi[:, 0], hi[:, 1])
        qs, ps = shapely.STRtree(boxes).query(boxes, predicate="covers")
    if n > BOX_PROPOSALS:
        inside = (ps != qs) & (lo[ps, 0] >= lo[qs, 0]) & (hi[ps, 0] <= hi[qs, 0]) & (lo[ps, 1] >= lo[qs, 1]) & \
            (hi[ps, 1] <= hi[qs, 1])
        qs, ps = qs[inside], ps[inside]
    if not len(qs):  # no box inside another (the common case): nothing to test
        return removed
    from ..compiled import fastpath

    # Compiled: every candidate's answer at once (-1 where not certified: the exact test below).
    # A "no" removes nothing whatever the order (identical pieces answer "yes"): only the
    # others go on, so a large map's thousands of nested boxes cost one C call, not a loop.
    known = fastpath.contained(pieces, qs, ps, packed)
    if known is not None:
        go = known != 0
        qs, ps, known = qs[go], ps[go], known[go]
        if not len(qs):
            return removed
    order = np.argsort(lo[:, 0], kind="stable")
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    by = np.lexsort((rank[ps], qs))
    qs, ps = qs[by], ps[by]
    known = known[by].tolist() if known is not None else [-1] * len(qs)
    cut = np.flatnonzero(np.diff(qs)) + 1
    t = 0
    for q, cand in zip(qs[np.r_[0, cut]].tolist(), np.split(ps, cut)):
        t0, t = t, t + len(cand)
        if q in removed:
            continue
        Q = pieces[q]
        e = None  # Q's edges' ends, made for the first candidate the compiled test left open
        for p, answer in zip(cand.tolist(), known[t0:t]):
            if p in removed:
                continue
            P = pieces[p]
            if P.shape == Q.shape and p < q and np.array_equal(P, Q):
                continue  # identical: keep the earlier one, drop q when it is visited as p
            if answer < 0:
                e = np.roll(Q, -1, axis=0) if e is None else e
                answer = (orient2d_many(Q[None, :, :], e[None, :, :], P[:, None, :]) >= 0).all()
            if answer:
                removed[p] = q
    return removed


def pair_sums(obstacle_pieces: list[np.ndarray], robot_pieces: list[np.ndarray]) -> list[np.ndarray]:
    """``[minkowski_sum(p, r) for p in obstacle_pieces for r in robot_pieces]``, equal array
    for array. Compiled: one certified merge per pair in C (:func:`cspace.compiled.fastpath.pair_sums`),
    the pairs it cannot certify by ``minkowski_sum``. Pure: pairs of small pieces in batches
    (:func:`cspace.kernel.minkowski.pairsums.pairwise_sums`), large ones one by one (a batch compares
    every edge with every edge).

    >>> sq = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
    >>> [s.tolist() for s in pair_sums([sq], [sq - 1])]
    [[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]]
    """
    from ..kernel.minkowski.merge import minkowski_sum
    from ..kernel.minkowski.pairsums import pairwise_sums
    from ..compiled import fastpath

    nr = len(robot_pieces)
    out = fastpath.pair_sums(obstacle_pieces, robot_pieces)  # compiled: None where not certified
    if out is not None:
        for k in (k for k, s in enumerate(out) if s is None):
            out[k] = minkowski_sum(obstacle_pieces[k // nr], robot_pieces[k % nr])
        return out
    out = [None] * (len(obstacle_pieces) * nr)
    small_r = [j for j, r in enumerate(robot_pieces) if len(r) <= PAIR_BATCH_EDGES]
    small_o = [i for i, p in enumerate(obstacle_pieces) if len(p) <= PAIR_BATCH_EDGES]
    if small_r and small_o:
        rb = [robot_pieces[j] for j in small_r]
        redges = sum(len(r) for r in rb)
        start = 0
        while start < len(small_o):  # chunks of about PAIR_BATCH_CELLS edge comparisons
            stop, used = start, 0
            while stop < len(small_o) and (stop == start or (used + len(obstacle_pieces[small_o[stop]])) * redges
                                           <= PAIR_BATCH_CELLS):
                used += len(obstacle_pieces[small_o[stop]])
                stop += 1
            chunk = small_o[start:stop]
            sums = pairwise_sums([obstacle_pieces[c] for c in chunk], rb)
            for a, c in enumerate(chunk):
                for b, j in enumerate(small_r):
                    out[c * nr + j] = sums[a * len(rb) + b]
            start = stop
    for k in range(len(out)):
        if out[k] is None:
            out[k] = minkowski_sum(obstacle_pieces[k // nr], robot_pieces[k % nr])
    return out


def inflated(robot_pieces: list[np.ndarray], margin: list[np.ndarray]) -> list[np.ndarray]:
    """:func:`cspace.kernel.minkowski.margin.inflated_pieces`, equal array for array: with one margin
    operand (a clearance's disk polygon, or a ``[margin]`` polygon alone) each robot piece's
    sum is a pair sum, so :func:`pair_sums` computes them (in C on the compiled path).

    >>> sq = np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])
    >>> inflated([sq], [sq])[0].tolist()
    [[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]]
    """
    from ..kernel.minkowski.margin import inflated_pieces

    if len(margin) == 1 and robot_pieces:
        return pair_sums([np.asarray(r, dtype=np.float64) for r in robot_pieces], [np.asarray(margin[0], dtype=np.float64)])
    return inflated_pieces(robot_pieces, margin)


def inner_pieces(sc) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Convex pieces (obstacles, robot) INSIDE a scenario's shapes as written: its polygons, and
    for each disk the polygon inscribed in it (:meth:`cspace.io.scenario.schema.Shape.inner_polygon`)
    instead of the circumscribed one the C-space is built of. A proof that no path exists made
    of these holds for the disks themselves (less obstacle, a smaller robot); a disk too small
    to hold a polygon drops out (a point robot then).

    >>> from cspace.io.scenario.schema import Scenario, Shape
    >>> from cspace.kernel.polygons.disk import disk_polygon
    >>> sc = Scenario("d", (0, 4, 0, 4), [], [Shape(disk_polygon((2, 2), 1.0, sides=8), disk=(2.0, 2.0, 1.0),
    ...               convex=True)], (0, 0), (4, 4))
    >>> obs, rob = inner_pieces(sc)
    >>> len(obs), bool(np.hypot(obs[0][:, 0] - 2, obs[0][:, 1] - 2).max() < 1.0), rob
    (1, True, [])
    """
    obstacles, holes, convex = [], [], []
    for o in sc.obstacles:
        p = o.inner_polygon()
        if len(p) >= 3:
            obstacles.append(p)
            holes.append(o.holes)
            convex.append(o.convex)
    pieces, _, _ = decompose_obstacles(obstacles, holes, convex=convex)
    robot = [r.inner_polygon() for r in sc.robot]
    rpieces, _ = decompose_robot([p for p in robot if len(p) >= 3], sc.robot_kind == "disk")
    return pieces, rpieces
