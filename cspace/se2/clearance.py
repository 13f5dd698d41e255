"""The clearance of a rotating robot's path: a certified lower bound.

Between two poses OMPL moves x, y linearly and θ
along the shorter arc. Over a piece of that motion whose angles lie in [a, b], the
turned robot piece stays inside its slab hull H = :func:`cspace.kernel.slabs.slab.slab_hull` over
[a, b], so the robot is inside conv((H + p(t0)) ∪ (H + p(t1))): the distance from
that to the obstacles is a lower bound for the piece of motion. Pieces are split
best-first (the one of smallest bound first) until the smallest bound belongs to a
piece turning by at most ``angle_step`` (or not turning, which is exact), or reaches
the distance of the robot at some pose met on the way (an upper bound: then it cannot
rise further, as when the path touches): the bound is then within about
r · angle_step of the true clearance (r the robot's radius), and never above it.

The distances are :class:`cspace.translation.clearance.Nearest`'s (boxes, then GJK).
"""
from __future__ import annotations

import heapq
import math
import time

import numpy as np

from ..kernel.polygons.rotation import rotate_piece
from ..kernel.slabs.slab import slab_hull
from ..translation.clearance import Nearest, PathClearance
from .motion import interpolate, turn_arc

ANGLE_STEP = 1e-3  # radians of turn below which a sub-motion is not split further
MAX_SPLITS = 20000  # sub-motions evaluated at most (then the bound found so far is kept)


def se2_path_clearance(path, robot_pieces: list, obstacle_pieces: list, angle_step: float = ANGLE_STEP,
                       max_splits: int = MAX_SPLITS, nearest: Nearest | None = None,
                       deadline: float | None = None) -> PathClearance:
    """A certified lower bound of a rotating robot's path clearance (module docstring).

    ``path`` is (N, 3) poses (x, y, θ) joined by OMPL's SE(2) interpolation;
    ``robot_pieces`` are convex, in the body frame. ``nearest``: a :class:`Nearest` of
    ``obstacle_pieces`` kept by the caller (a C-space's, for many paths); only the pieces
    near the path are searched (:func:`near_path`: the same answer, to the bit). ``deadline``
    (a ``time.perf_counter()`` value): past it no piece is split further, and the least bound so
    far is returned (``cut``: still a lower bound, a looser one); the first pass, one bound per
    quarter turn of each motion, always runs (linear in the path).

    >>> sq = np.array([[4., 4], [6, 4], [6, 6], [4, 6]])
    >>> bar = [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])]
    >>> c = se2_path_clearance(np.array([[2., 1, 0], [2, 1, 1.5]]), bar, [sq])
    >>> c.bound, round(c.distance, 6)  # the true clearance is 2.6005637...
    ('lower', 2.600564)
    """
    poses = np.asarray(path, dtype=np.float64).reshape(-1, 3)
    rob = [np.asarray(r, dtype=np.float64) for r in robot_pieces] or [np.zeros((1, 2))]
    if not len(poses):
        return PathClearance(math.inf, (), (), -1, "lower")
    local = near_path(nearest if nearest is not None else Nearest(obstacle_pieces), poses, rob)
    if len(poses) == 1:
        poses = np.vstack([poses, poses])
        local = local * 2

    heap: list = []
    count = 0
    upper = math.inf  # the least distance of the robot at a pose met so far

    def push(i: int, t0: float, t1: float) -> None:
        nonlocal count
        q0, q1 = poses[i], poses[i + 1]
        arc = turn_arc(float(q0[2]), float(q1[2]))
        a, b = sorted((float(q0[2]) + arc * t0, float(q0[2]) + arc * t1))
        pa = q0[:2] + (q1[:2] - q0[:2]) * t0
        pb = q0[:2] + (q1[:2] - q0[:2]) * t1
        best, w = math.inf, None
        for r in rob:
            H = _hull(r, a, b)
            swept = np.concatenate([H + pa, H + pb])
            d, k, wk = local[i].nearest(swept, best)
            if k >= 0 and d < best or w is None and k >= 0:
                best, w = d, wk
        count += 1
        heapq.heappush(heap, (best, count, i, t0, t1, b - a, w))
        # An upper bound: the robot itself at the middle pose (GJK, the turned pieces).
        nonlocal upper
        x, y, th = interpolate(q0, q1, 0.5 * (t0 + t1))
        for r in rob:
            upper = min(upper, local[i].nearest(rotate_piece(r, th) + (x, y) if len(r) > 2 else r + (x, y), upper)[0])

    for i in range(len(poses) - 1):
        arc = abs(turn_arc(float(poses[i][2]), float(poses[i + 1][2])))
        n = max(1, math.ceil(arc / (0.25 * math.pi)))  # slab hulls span at most a quarter turn
        for s in range(n):
            push(i, s / n, (s + 1) / n)
    cut = False
    while True:
        d, _, i, t0, t1, width, w = heap[0]
        if width <= angle_step or not math.isfinite(d) or count >= max_splits or d >= upper * (1.0 - 1e-9):
            break  # (the bound meets a distance actually reached: it cannot rise further)
        if deadline is not None and time.perf_counter() >= deadline:
            cut = True
            break
        heapq.heappop(heap)
        tm = 0.5 * (t0 + t1)
        push(i, t0, tm)
        push(i, tm, t1)
    if w is None:
        return PathClearance(math.inf, (), (), -1, "lower")
    where = interpolate(poses[i], poses[i + 1], 0.5 * (t0 + t1))
    return PathClearance(float(d), tuple(float(v) for v in where), tuple(float(v) for v in w), i, "lower", cut)


def near_path(obs: Nearest, poses: np.ndarray, rob: list) -> list[Nearest]:
    """For each motion of ``poses``' path, the obstacle pieces that can matter to its measure: those
    within U of the box of its two poses grown by 1.25 ρ (ρ the robot's radius), U the robot's
    distance at the first pose. Every set the measure asks about on that motion lies in that box
    (a slab hull over at most a quarter turn lies within ρ / cos(π/8) < 1.09 ρ of its pose, up to
    its pad), and the least bound is at most U (the clearance is), so a piece farther than U from
    all of them never decides a bound that the search reads: the answer is the same as over every
    piece. (One pose: one entry.)

    >>> far = [np.array([[4., 4], [6, 4], [6, 6], [4, 6]]), np.array([[90., 0], [91, 0], [91, 1]])]
    >>> bar = [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])]
    >>> [len(n.pieces) for n in near_path(Nearest(far), np.array([[2., 1, 0], [2, 1, 1.5]]), bar)]
    [1]
    """
    n = max(1, len(poses) - 1)
    if not len(obs.pieces):
        return [obs] * n
    x, y, th = poses[0]
    first = min(obs.nearest(rotate_piece(r, th) + (x, y) if len(r) > 2 else r + (x, y))[0] for r in rob)
    if not math.isfinite(first):
        return [obs] * n
    rho = max(float(np.hypot(r[:, 0], r[:, 1]).max()) for r in rob)
    grow = 1.25 * rho + 2.0**-30 * (rho + float(np.abs(poses[:, :2]).max()))
    ends = [poses[i:i + 2, :2] for i in range(n)]
    return [obs.within(e.min(axis=0) - grow, e.max(axis=0) + grow, first) for e in ends]


def _hull(piece: np.ndarray, a: float, b: float) -> np.ndarray:
    """The piece turned through every angle of [a, b]: a convex superset (its slab hull)."""
    return slab_hull(piece, a, b)
