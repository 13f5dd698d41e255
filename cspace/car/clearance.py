"""The clearance of a car's path, driven along its Dubins / Reeds–Shepp curves: a certified lower bound.

Along one segment of a curve (kind, signed length L) parametrised by the distance s the
reference point has driven, a robot point at body offset v (|v| ≤ ρ, the robot's radius
about its reference point) is at x(s) + R(θ(s)) v. The reference point moves at unit
speed and the heading turns at 1/r on an arc (0 on a straight), so the point moves at
most ``lip`` = 1 + ρ/r (1 on a straight) per unit of s. The distance d(s) from the
robot at s to the obstacles therefore changes by at most ``lip · |s − s'|`` between two
places on the segment (each point of the robot moves that little), so over an interval
[s0, s1] of the segment with exact distances d0, d1 at its ends,

    d(s) ≥ max(d0 − lip (s − s0), d1 − lip (s1 − s)) ≥ (d0 + d1 − lip (s1 − s0)) / 2.

That is an arc's interval's lower bound. A straight's is exact at once: each convex robot
piece translates at one heading, so over [s0, s1] it sweeps exactly the hull of its two
placements, whose GJK distance is the interval's least (slack 0). On an arc every robot point
turns about the turning centre by the same angle, so the robot stays in the slab hulls of its
pieces turned about that centre (:func:`arc_bound`); their distance is a second lower bound,
taken where its slack (quadratic in the turn) is below the Lipschitz one, and asked only of an
interval that comes to the top of the best-first heap below (most never do). The path's bound is the least over intervals covering every
segment of every motion (and over the joins from a curve's end to its target pose, which a
Dubins curve may miss by a few 1e-6 radii: the distance at the curve's end less the most a
robot point moves over the join). Intervals are split best-first (the one of smallest bound first,
its middle measured) until the smallest bound belongs to an interval of slack
``lip (s1 − s0) / 2`` at most ``tol``, or is within ``tol`` of a distance actually met
(then it is within ``tol`` of the true clearance), or ``max_samples`` distances have been
measured (the bound found so far is kept: still a lower bound). The distance at a pose is
GJK's between each turned convex robot piece and the nearest obstacle piece (float, error
about 2^-50 of the coordinates' scale), as in :mod:`cspace.translation.clearance`.
"""
from __future__ import annotations

import heapq
import math
from typing import Callable

import numpy as np

from .curves import advance, knots
from ..translation.clearance import Nearest, PathClearance
from ..kernel.polygons.rotation import rotate, wrap_angle

TOL = 1e-3  # slack of the bound, relative to max(turning radius, robot radius)
MAX_SAMPLES = 20000  # poses measured at most per path
INITIAL = 1024.0  # first samples about INITIAL x tol / lip apart (1 to 64 intervals per segment)


def robot_radius(robot_pieces: list) -> float:
    """The largest distance from the reference point (the body frame's origin) to a robot vertex.

    >>> robot_radius([np.array([[-1., 0], [3, 0], [0, 4]])])
    4.0
    """
    return max((float(np.hypot(p[:, 0], p[:, 1]).max()) for p in robot_pieces if len(p)), default=0.0)


def car_path_clearance(path, segments_of: Callable, radius: float, robot_pieces: list, obstacle_pieces: list,
                       tol: float | None = None, max_samples: int = MAX_SAMPLES,
                       nearest: Nearest | None = None) -> PathClearance:
    """A certified lower bound of a car's clearance along ``path`` (module docstring).

    ``path`` is (N, 3) poses joined by the curves ``segments_of(q0, q1)`` returns
    ((kind, signed length) segments, :mod:`cspace.car.curves`) for the turning
    ``radius``; ``robot_pieces`` are convex, in the body frame. ``tol``: the slack aimed at
    (default :data:`TOL` x max(radius, robot radius)). ``nearest``: a :class:`Nearest` of
    ``obstacle_pieces`` kept by the caller; only the pieces near the curves are searched
    (:func:`near_curves`).

    >>> from cspace.car.curves import dubins_segments
    >>> box = [np.array([[-0.5, -0.25], [0.5, -0.25], [0.5, 0.25], [-0.5, 0.25]])]
    >>> wall = [np.array([[0., 2], [6, 2], [6, 3], [0, 3]])]
    >>> c = car_path_clearance(np.array([[1., 0, 0], [5, 0, 0]]), lambda a, b: dubins_segments(a, b, 1.0),
    ...                        1.0, box, wall)
    >>> c.bound, 1.75 - 1e-3 <= c.distance <= 1.75  # along the wall, 1.75 from it: within tol below
    ('lower', True)
    """
    poses = np.asarray(path, dtype=np.float64).reshape(-1, 3)
    obs = nearest if nearest is not None else Nearest(obstacle_pieces)
    cap = [math.inf]  # every distance measured is capped there (near_curves)
    rob = [np.asarray(p, dtype=np.float64) for p in robot_pieces] or [np.zeros((1, 2))]
    r = float(radius)
    rho = robot_radius(rob)
    tol = TOL * max(r, rho) if tol is None else float(tol)
    if not len(poses) or not len(obstacle_pieces):
        return PathClearance(math.inf, (), (), -1, "lower")

    def at(pose, j: int | None = None) -> tuple[float, object]:
        """(distance, obstacle point) of the robot at a pose (of segment ``j``: its pieces nearby)."""
        x, y, th = pose
        best, w = math.inf, None
        near = obs if j is None else local[j]
        for p in rob:
            d, k, wk = near.nearest(rotate(p, th) + (x, y), best)
            if k >= 0 and (d < best or w is None):
                best, w = d, wk
        return min(best, cap[0]), w

    # The curve's segments: (motion index, pose at the segment's start, kind, signed length).
    parts = []
    joins = {}  # last segment of a motion -> how far a robot point is from its curve's end to q1
    for i, (a, b) in enumerate(zip(poses[:-1], poses[1:])):
        segs = [sg for sg in segments_of(tuple(a), tuple(b)) if sg[1] != 0.0]
        ks = knots(tuple(a), segs, r)
        for (kind, length), k0 in zip(segs, ks):
            parts.append((i, k0, kind, float(length)))
        if segs:  # a Dubins curve may end a few 1e-6 radii short of q1 (cspace.car.curves): the join to it
            x, y, th = ks[-1]
            joins[len(parts) - 1] = math.hypot(b[0] - x, b[1] - y) + rho * abs(wrap_angle(b[2] - th))
    if not parts:  # one pose, or poses all equal: the robot stands still
        d, w = at(tuple(poses[0]))
        return PathClearance(float(d), tuple(float(v) for v in poses[0]), _point(w), 0, "lower")

    first = at(tuple(poses[0]))[0]  # the robot at the first pose: the clearance is at most that
    local = [obs] * len(parts)  # each segment's obstacle pieces
    if math.isfinite(first):
        local, cap[0] = near_curves(obs, parts, r, rho + max(joins.values(), default=0.0), first), first

    def pose(j: int, s: float) -> tuple:
        _, k0, kind, length = parts[j]
        return advance(k0, kind, math.copysign(s, length), r)

    heap: list = []
    count = 0
    upper = math.inf  # the least distance measured: the true clearance is at most that

    def straight(j: int, s0: float, s1: float) -> float:
        """The least distance over [s0, s1] of a straight segment, exactly (up to GJK's rounding):
        each robot piece translates at one heading, so it sweeps the hull of its two placements."""
        (x0, y0, th), (x1, y1, _) = pose(j, s0), pose(j, s1)
        best = math.inf
        for p in rob:
            q = rotate(p, th)
            best = min(best, local[j].nearest(np.vstack([q + (x0, y0), q + (x1, y1)]), best)[0])
        return min(best, cap[0])

    def push(j: int, s0: float, s1: float, e0: tuple, e1: tuple, turned: bool = False) -> None:
        """An interval into the heap with its bound. An arc's enters with the Lipschitz bound; its
        turned hulls' (:func:`arc_bound`, dearer) is asked when it comes to the top (``turned``),
        so an interval that never does (most, where the least is elsewhere) never pays for it."""
        nonlocal count
        count += 1
        if parts[j][2] == "S":  # the swept hull's distance: the interval's exact least, no slack
            heapq.heappush(heap, (max(0.0, straight(j, s0, s1)), count, j, s0, s1, 0.0, e0, e1, True))
            return
        lip = 1.0 + rho / r
        lb = max(0.0, min(e0[0], e1[0], 0.5 * (e0[0] + e1[0] - lip * (s1 - s0))))
        slack = 0.5 * lip * (s1 - s0)
        if turned:
            hull, hull_slack = arc_bound(pose(j, s0), parts[j][2], math.copysign(s1 - s0, parts[j][3]), r, rob,
                                         local[j])
            if hull_slack < slack:  # the turned hull's bound, where it is the tighter claim
                lb, slack = max(0.0, min(hull, cap[0])), hull_slack
        heapq.heappush(heap, (lb, count, j, s0, s1, slack, e0, e1, turned))

    for j, (_, k0, kind, length) in enumerate(parts):
        lip = 1.0 if kind == "S" else 1.0 + rho / r
        n = max(1, math.ceil(abs(length) * lip / (INITIAL * tol)))  # coarse first, refined where it matters
        # (a straight's bound is exact at once; an arc's pieces turn by at most π/4 for arc_bound)
        n = 1 if kind == "S" else max(min(n, 64), math.ceil(abs(length) / r / (0.25 * math.pi)))
        cuts = [abs(length) * m / n for m in range(n + 1)]
        ends = [at(pose(j, s), j) for s in cuts]
        upper = min([upper] + [e[0] for e in ends])
        for m in range(n):
            push(j, cuts[m], cuts[m + 1], ends[m], ends[m + 1])
        if joins.get(j):  # over the join, within that of the curve's end (measured: the last cut)
            heapq.heappush(heap, (max(0.0, ends[-1][0] - joins[j]), -j - 1, j, cuts[-1], cuts[-1], 0.0,
                                  ends[-1], ends[-1], True))
    samples = count + len(parts)
    while True:
        lb, _, j, s0, s1, slack, e0, e1, turned = heap[0]
        if slack <= tol or lb >= upper - tol or samples >= max_samples or not math.isfinite(lb):
            break
        heapq.heappop(heap)
        if not turned:  # an arc's interval at the top: its turned hulls' bound before any split
            push(j, s0, s1, e0, e1, turned=True)
            samples += 1
            continue
        sm = 0.5 * (s0 + s1)
        em = at(pose(j, sm), j)
        samples += 1
        upper = min(upper, em[0])
        push(j, s0, sm, e0, em)
        push(j, sm, s1, em, e1)
    if not math.isfinite(lb):
        return PathClearance(math.inf, (), (), -1, "lower")
    x, y, th = pose(j, s0 if e0[0] <= e1[0] else s1)
    where = (x, y, wrap_angle(th))
    w = e0[1] if e0[0] <= e1[0] else e1[1]
    return PathClearance(float(lb), tuple(float(v) for v in where), _point(w), parts[j][0], "lower")


def arc_bound(pose, kind: str, length: float, r: float, rob: list, obs: Nearest) -> tuple[float, float]:
    """(lower bound, slack) of the robot's distance to the obstacles while it drives ``length`` (signed)
    along an arc of radius ``r`` from ``pose``: every robot point turns about the turning centre c
    by the same angle, between 0 and Δ = ± length / r, so each piece stays in c + the slab hull of
    (the piece at ``pose`` − c) over [min(0, Δ), max(0, Δ)] (:func:`cspace.kernel.slabs.slab.slab_hull`,
    padded for the rounding of the poses); the distance from those hulls bounds the interval's from
    below. ``slack``: how far above the true least it can be, R the farthest robot vertex from c:
    the hull is the convex hull of each vertex's two end placements and the apex where their
    tangents meet (at most R (1 / cos(Δ/2) − 1) beyond the middle placement); a point of the
    convex hull of the swept set is a convex combination of placed vertices, each within
    2 R sin(Δ/4) of its placement at the middle turn, so it lies within 2 R sin(Δ/4) of the middle
    placement (a convex piece): the swept set is not convex (an edge's two end placements cross,
    and the hull fills the notches beside the crossing), which only the second term covers. So
    2 R (1 / cos(Δ/2) − 1) + 2 R sin(Δ/4) plus the pads. (inf, inf) for a turn above π/2 (no slab
    hull).

    >>> box = [np.array([[-0.5, -0.25], [0.5, -0.25], [0.5, 0.25], [-0.5, 0.25]])]
    >>> d, slack = arc_bound((0.0, 0.0, 0.0), "L", 0.1, 1.0, box, Nearest([np.array([[-1., 3], [1, 3], [0, 4]])]))
    >>> bool(0.0 < d <= 3.0 - 0.25 - 0.5 * 0.1), slack < 0.08  # R = 1.35, Δ = 0.1: mostly 2 R sin(Δ/4)
    (True, True)
    """
    from ..kernel.slabs.slab import slab_pad, slab_points

    x, y, th = pose
    side = 1.0 if kind == "L" else -1.0
    cx, cy = x - side * r * math.sin(th), y + side * r * math.cos(th)
    turn = side * length / r  # counter-clockwise about the centre
    if abs(turn) > 0.5 * math.pi or min(len(p) for p in rob) < 3:
        return math.inf, math.inf
    lo, hi = min(0.0, turn), max(0.0, turn)
    scale = abs(cx) + abs(cy) + r
    best, far = math.inf, 0.0
    for p in rob:
        q = rotate(p, th) + (x - cx, y - cy)
        far = max(far, float(np.hypot(q[:, 0], q[:, 1]).max()))
        pts, d = slab_points(q, lo, hi, scale=scale)  # the slab hull: conv(pts) grown by [-d, d]^2
        grow = d * math.sqrt(2.0)  # (GJK reads conv(pts): no hull, no sum, the pad taken off its distance)
        best = min(best, obs.nearest(pts + (cx, cy), best + grow)[0] - grow)
    pad = slab_pad(scale + far)
    return best, 2.0 * far * (1.0 / math.cos(0.5 * (hi - lo)) - 1.0) + 2.0 * far * math.sin(0.25 * (hi - lo)) + 8.0 * pad


def near_curves(obs: Nearest, parts: list, r: float, rho: float, first: float) -> list[Nearest]:
    """For each segment of ``parts`` ((motion, start pose, kind, signed length)), the obstacle pieces
    within ``first`` of the box that holds the robot driven along it: the box of its start and end
    grown by ``rho`` (the robot about its reference point), and by 2 r more on an arc (which stays
    within 2 r of its start). A piece left out is farther than ``first`` from the robot everywhere
    on the segment, so a distance measured without it is exact where it is at most ``first`` and
    above ``first`` otherwise: capped at ``first`` (the measure does), it is a lower bound of the
    true one everywhere, which is all the bounds need (the first pose's distance, ``first``, is at
    least the clearance).

    >>> far = Nearest([np.array([[0., 2], [6, 2], [6, 3], [0, 3]]), np.array([[90., 0], [91, 0], [91, 1]])])
    >>> [len(n.pieces) for n in near_curves(far, [(0, (1.0, 0.0, 0.0), "S", 4.0)], 1.0, 0.5, 1.75)]
    [1]
    """
    out = []
    for _, k0, kind, length in parts:
        x1, y1, _ = advance(k0, kind, length, r)
        lo, hi = (min(k0[0], x1), min(k0[1], y1)), (max(k0[0], x1), max(k0[1], y1))
        grow = (0.0 if kind == "S" else 2.0 * r) + rho + 2.0**-30 * (r + rho + max(map(abs, lo + hi)))
        out.append(obs.within((lo[0] - grow, lo[1] - grow), (hi[0] + grow, hi[1] + grow), first))
    return out


def _point(w) -> tuple:
    return () if w is None else tuple(float(v) for v in w)
