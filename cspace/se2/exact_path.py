"""Path assembly for the slab graph (:mod:`cspace.se2.exact`): a FREE walk to poses.

A walk S, n_1, ..., n_{m-1}, G (S and G: the start's and goal's components of FREE at their
own angles; n_i = (slab k_i, component c_i)) with a link point p_i between consecutive nodes
becomes, in order:

- a translation at θs inside S's component from the start to p_0 (FREE at θs is the exact
  translation C-space of the turned robot, shrunk by the slab pad δ, so a shortest path
  along its boundary keeps the robot off the obstacles);
- for each slab node n_i: a turn in place at p_{i-1} to its angle α_i (θs for the first
  node, the slab's middle otherwise), a translation at α_i inside c_i from p_{i-1} to p_i
  (the straight segment, else the shortest path within a triangle channel of that slab's FREE
  (:func:`cspace.paths.shortest.shortest_path`, method "channel"), checked by it against the FREE
  pieces with exact predicates), a turn at p_i to β_i
  (θg for the last node, the middle otherwise), and, when the next node is a slab node, a
  turn to the boundary angle the two slabs share;
- a translation at θg inside G's component from p_{m-1} to the goal.

Every turn stays inside one slab (at most π/4 wide), so between consecutive poses, wrapped to
[−π, π), "the shorter way" is the way inside the slab: across ±π too. Each turn point is
checked exactly (:func:`cspace.se2.slab_graph.point_free`) against the FREE pieces of every
slab the turn passes through; a failed check raises :class:`AssemblyError` (never a silent
uncertified path).
"""
from __future__ import annotations

import math

import numpy as np

from ..kernel.polygons.rotation import wrap_angle
from ..paths.pathcheck import path_violations
from ..paths.shortest import shortest_path
from .slab_graph import point_free


class AssemblyError(RuntimeError):
    """A walk of the FREE graph whose exact re-check failed (a translation or a turn point).
    ``index``: the walk's node where it failed (0 the start's, the last the goal's), set by
    :func:`assemble`, so that the search can route round it or refine its slab."""

    index: int = -1


def in_slab(theta: float, a: float, b: float) -> float | None:
    """θ (wrapped to [−π, π)) as an angle of the slab [a, b] ⊆ [−π, π + 1 ulp], or None: −π is
    also π (the same angle; in the last slab, which ends one ulp above the float π).

    >>> in_slab(-math.pi, 3.0, math.pi) == math.pi, in_slab(0.5, 0.0, 1.0), in_slab(2.0, 0.0, 1.0)
    (True, 0.5, None)
    """
    if a <= theta <= b:
        return theta
    if theta == -math.pi and a <= math.pi <= b:
        return math.pi
    return None


def holding(part: list, theta: float, slack: float = 0.0) -> list[int]:
    """Indices of the slabs of the partition ``part`` (list of (a, b)) that hold θ; with ``slack``,
    also those within ``slack`` of it (round the circle): a proof's start and goal belong to
    every slab that a checker, unsure of an angle's last bits, may count (toward more nodes).

    >>> holding([(-math.pi, 0.0), (0.0, math.pi)], 0.0), holding([(-math.pi, 0.0), (0.0, math.pi)], -math.pi)
    ([0, 1], [0, 1])
    >>> holding([(-math.pi, 0.0), (0.0, math.pi)], 1e-10), holding([(-math.pi, 0.0), (0.0, math.pi)], 1e-10, 1e-8)
    ([1], [0, 1])
    """
    out = []
    for k, (a, b) in enumerate(part):
        if in_slab(theta, a, b) is not None or any(a - slack <= t <= b + slack for t in
                                                   (theta, theta - 2 * math.pi, theta + 2 * math.pi)):
            out.append(k)
    return out


def assemble(walk: list, part: list, freg: list, regions, start, goal, near: bool = False) -> np.ndarray:
    """The poses of a FREE walk ``[(node, link point to the next node), ..., (G, None)]``.

    ``part``: the slabs (a, b); ``freg``: their FREE regions; ``regions``: the
    :class:`cspace.se2.slab_graph.SlabRegions` (for the FREE of the start's and goal's angles).
    ``near``: the link points moved where the path is first (:func:`near_links`), the walk's own
    where that path fails its checks; its short translations searched in a window round them.

    >>> from cspace.se2.slab_graph import SlabRegions
    >>> sr = SlabRegions([], [np.array([[0., 0], [1, 0], [0, 1]])], (0, 10, 0, 10))
    >>> walk = [((-1, 0), None), ((-2, 0), None)]
    >>> assemble(walk, [], [], sr, (1, 1, 0.0), (5, 1, 0.0)).tolist()
    [[1.0, 1.0, 0.0], [5.0, 1.0, 0.0]]
    """
    if near:
        try:
            return _assemble(near_links(walk, part, freg, regions, start, goal), part, freg, regions, start, goal,
                             [0], local=True)
        except AssemblyError:
            pass
    at = [0]
    try:
        return _assemble(walk, part, freg, regions, start, goal, at, local=near)
    except AssemblyError as exc:
        exc.index = at[0]
        raise


def _assemble(walk, part, freg, regions, start, goal, at: list, local: bool = False) -> np.ndarray:
    bounds = regions.bounds
    xs, ys, ts = (float(v) for v in start)
    xg, yg, tg = (float(v) for v in goal)
    nodes = [n for n, _ in walk]
    pts = [p for _, p in walk[:-1]]
    poses = [(xs, ys, wrap_angle(ts))]
    if len(nodes) == 2:  # the start's and goal's components at one common angle: one translation
        _translate(poses, regions.free_at(ts), bounds, (xs, ys), (xg, yg), ts, local)
        return np.array(poses, dtype=np.float64)
    K = len(part)
    m = len(nodes) - 1
    if tuple(pts[0]) != (xs, ys):  # (an end joined its slab directly: nothing to translate at its angle)
        _translate(poses, regions.free_at(ts), bounds, (xs, ys), pts[0], ts, local)
    for i in range(1, m):
        at[0] = i
        k = nodes[i][0]
        a, b = part[k]
        pieces = freg[k].pieces
        alpha = in_slab(ts, a, b) if i == 1 else 0.5 * (a + b)
        beta = in_slab(tg, a, b) if i == m - 1 else 0.5 * (a + b)
        if alpha is None or beta is None:
            raise AssemblyError(f"slab {k} [{a!r}, {b!r}] does not hold the start's or goal's angle")
        p_in, p_out = pts[i - 1], pts[i]
        for p in (p_in, p_out):  # turn points: free at every angle of the slab, exactly
            if not point_free(pieces, bounds, p[0], p[1], freg[k].piece_boxes):
                raise AssemblyError(f"turn point {p} is not free in slab {k} [{a!r}, {b!r}]")
        _turn(poses, p_in, alpha)
        _translate(poses, freg[k], bounds, p_in, p_out, alpha, local)
        _turn(poses, p_out, beta)
        nxt = nodes[i + 1][0]
        if nxt >= 0:  # into the next slab through the boundary the two share
            if nxt == (k + 1) % K:
                _turn(poses, p_out, b)
            elif k == (nxt + 1) % K:
                _turn(poses, p_out, a)
            else:
                raise AssemblyError(f"slabs {k} and {nxt} are not adjacent")
    at[0] = m
    if tuple(pts[-1]) != (xg, yg):
        _translate(poses, regions.free_at(tg), bounds, pts[-1], (xg, yg), tg, local)
    return np.array(poses, dtype=np.float64)


def near_links(walk: list, part: list, freg: list, regions, start, goal) -> list:
    """The walk with its link points moved where the path is (per query): the translation that
    crosses the scene is made at one slab of the walk, the first that carried such a translation
    for an earlier query on these regions (``regions.carriers``: its mesh is kept), else the first
    of the widest, the links before it each into the overlap of its two
    components near the point before it (the start for the first), those after it near the
    point after it (the goal for the last): :meth:`cspace.se2.slab_graph.SlabRegions.link_near`.
    A point joining an end to its slab directly, or with no overlap near, stays. The same
    nodes: a walk of the same FREE graph, assembled and checked as any other.

    >>> from cspace.se2.slab_graph import SlabRegions
    >>> sr = SlabRegions([], [np.array([[0., 0], [.2, 0], [0, .2]])], (0, 10, 0, 10))
    >>> part = [(0.0, 0.5), (0.5, 1.0)]
    >>> walk = [((-1, 0), (1.0, 1.0)), ((0, 0), (9.0, 9.0)), ((1, 0), (8.0, 8.0)), ((-2, 0), None)]
    >>> [p for _, p in near_links(walk, part, [sr.free(a, b) for a, b in part], sr, (1, 1, 0.2), (2, 1, 0.7))]
    [(1.0, 1.0), (2.0, 1.0), (2.0, 1.0), None]
    """
    nodes, pts = [n for n, _ in walk], [p for _, p in walk[:-1]]
    m = len(nodes) - 1
    if m < 2:
        return walk
    ends = [(float(start[0]), float(start[1]), float(start[2])), (float(goal[0]), float(goal[1]), float(goal[2]))]
    # (a slab that carried one before first: its mesh is kept, a search in it costs milliseconds,
    # a new one ~0.1 s on a large map)
    rank = [(part[n[0]] in regions.carriers, part[n[0]][1] - part[n[0]][0]) for n in nodes[1:m]]
    carrier = 1 + rank.index(max(rank))
    regions.carriers.add(part[nodes[carrier][0]])

    def region_of(i: int):  # node i's region and component (an end's: FREE at its own angle)
        if nodes[i][0] >= 0:
            return freg[nodes[i][0]], nodes[i][1]
        x, y, th = ends[0] if i == 0 else ends[1]
        zero = regions.free_at(th)
        return zero, regions.containing(zero, x, y)

    out = list(pts)
    for order, ref in ((range(carrier), ends[0][:2]), (range(m - 1, carrier - 1, -1), ends[1][:2])):
        for i in order:
            p = (float(pts[i][0]), float(pts[i][1]))
            if p not in (ends[0][:2], ends[1][:2]):
                (r1, c1), (r2, c2) = region_of(i), region_of(i + 1)
                q = None if c1 is None or c2 is None else regions.link_near(r1, c1, r2, c2, *ref)
                out[i] = p if q is None else q
            ref = out[i]
    return [(n, out[i] if i < m else None) for i, n in enumerate(nodes)]


def _turn(poses: list, p, theta: float) -> None:
    """Turn in place at p (the last pose's position) to θ."""
    x, y, t = poses[-1]
    if (x, y) != (float(p[0]), float(p[1])):
        raise AssemblyError(f"turn at {p} but the path is at {(x, y)}")
    th = wrap_angle(float(theta))
    if th != t:
        poses.append((x, y, th))


def _translate(poses: list, region, bounds, p, q, theta: float, local: bool = False) -> None:
    """Translate at θ from p (the last pose's position) to q inside the FREE ``region`` (a
    :class:`cspace.se2.slab_graph.Region`): the straight segment if the exact segment test
    (:func:`path_violations`) finds it free against the region's pieces, else a short path through
    their free space (the shortest within a triangle channel, checked exactly against the pieces:
    :func:`cspace.paths.shortest.shortest_path`'s "channel"; OMPL's simplifier shortens it later).
    ``local`` (a moved walk's, whose translations are mostly short): first through a small window
    round p and q (:func:`_window_path`), not the whole region's mesh."""
    pieces = region.pieces
    x, y, t = poses[-1]
    th = wrap_angle(float(theta))
    if (x, y) != (float(p[0]), float(p[1])) or th != t:
        raise AssemblyError(f"translation from {p} at {th!r} but the path is at {(x, y, t)}")
    q = (float(q[0]), float(q[1]))
    if q == (x, y):
        return
    if not path_violations([(x, y), q], pieces, bounds):  # the straight segment is free: it is the shortest
        poses.append((q[0], q[1], th))
        return
    sp = _window_path(pieces, region.piece_boxes, bounds, (x, y), q) if local else None
    if sp is None:
        sp = shortest_path(pieces, bounds, (x, y), q, method="channel", free=region.components)
    if not sp.solved:
        raise AssemblyError(f"no certified translation from {p} to {q} at {th!r}: {sp.stats.get('reason')}")
    for px, py in sp.path[1:].tolist():
        poses.append((float(px), float(py), th))


def _window_path(pieces: list, boxes, bounds, p, q):
    """The channel path p -> q through the free space of a small window round them (the box of
    p and q grown by their distance, at most 1/16 of the bounds), with the pieces whose boxes
    meet it: a path inside the window missing those misses every piece (the others' boxes lie
    outside it), certified as one through the whole region is, for a fraction of the whole
    region's triangulation on a large map. None where the window is larger, or cuts p from q."""
    g = math.hypot(q[0] - p[0], q[1] - p[1])
    w = (max(bounds[0], min(p[0], q[0]) - g), min(bounds[1], max(p[0], q[0]) + g),
         max(bounds[2], min(p[1], q[1]) - g), min(bounds[3], max(p[1], q[1]) + g))
    if (w[1] - w[0]) * (w[3] - w[2]) > (bounds[1] - bounds[0]) * (bounds[3] - bounds[2]) / 16:
        return None
    b = np.asarray(boxes).reshape(-1, 4)
    meet = np.flatnonzero((b[:, 0] <= w[1]) & (b[:, 2] >= w[0]) & (b[:, 1] <= w[3]) & (b[:, 3] >= w[2]))
    sp = shortest_path([pieces[k] for k in meet.tolist()], w, p, q, method="channel")
    return sp if sp.solved else None
