"""A Reeds–Shepp car's RRT-Connect with its nearest-neighbour search compiled.

OMPL's RRTConnect, on OMPL's Reeds–Shepp space, spends most of a small car scene's time in
its nearest-neighbour search: every step of either tree measures the Reeds–Shepp length from
the target pose to the tree's nodes (GNAT over the metric: a scan of whole leaves). Here the
two trees grow as OMPL's do -- a uniform sample (x, y, theta) in the bounds; the start and the
goal tree in turn extend towards it by at most ``step`` along the shortest curve from their
nearest node, then the other tree connects to the new node, step after step, until it reaches
it (a path) or is trapped -- but the nearest node is found over lower bounds first: the
straight-line distance between two poses, and the turning radius times the turn between
their headings, are each at most the length of any curve joining them, so a node whose bound
is not below the best length so far is passed over without computing its word.

Nothing is certified here: each motion a tree takes is asked of ``motion_free(q0, q1)`` (the
car's certified motion test), in the direction the path drives it, and the caller re-checks
the path. The samples come from splitmix64 seeded with ``seed``: the same seed, the same path.
Compiled (cspace/compiled/_carrrt.c); on the pure path the same search in Python
(:func:`search_python`: the same samples, trees and motions asked, so the same path, double for
double), which is also the compiled search's oracle (tests/car/test_car_connect.py).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..compiled import motions
from ..kernel.polygons.rotation import wrap_angle
from .curves import curve_length, reeds_shepp_segments


class _Late(Exception):
    """The deadline passed: raised through the compiled search from the motion test."""


def connect(motion_free, start, goal, radius: float, bounds, step: float, seed: int, iterations: int,
            deadline: float | None = None):
    """Search for a path of Reeds–Shepp curves from ``start`` to ``goal`` (poses (x, y, theta))
    within ``bounds`` (xmin, xmax, ymin, ymax) for ``iterations`` samples at most, extending by at
    most ``step`` (a length along the curve), stopping at ``deadline`` (a ``time.perf_counter``
    value) if given. Returns ``(path or None, {"iterations": n, "motions": m})``, the path an
    (N, 3) array from start to goal whose motions ``motion_free`` accepted each (compiled, or
    :func:`search_python` on the pure path: the same result).

    >>> from cspace.car.motion import CarCSpace
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> cs = CarCSpace((0, 10, 0, 10), [np.array([[4., 3], [6, 3], [6, 7], [4, 7]])], [box], slabs=16)
    >>> test = cs.car_motion_test("reeds-shepp", 1.0)
    >>> got = connect(test, (1.0, 5.0, 0.0), (9.0, 5.0, 0.0), 1.0, (0, 10, 0, 10), 3.0, 7, 2000)
    >>> (got[0][0].tolist(), got[0][-1].tolist()) == ([1.0, 5.0, 0.0], [9.0, 5.0, 0.0])
    True
    >>> all(test(tuple(a), tuple(b)) for a, b in zip(got[0][:-1].tolist(), got[0][1:].tolist()))
    True
    """
    clock = time.perf_counter

    def in_time(q0, q1) -> bool:
        if clock() > deadline:
            raise _Late
        return motion_free(q0, q1)

    free = motion_free if deadline is None else in_time

    try:
        got = motions.car_connect(start, goal, radius, bounds, step, seed, iterations, free)
        if got is None:  # the pure path
            got = search_python(start, goal, radius, bounds, step, seed, iterations, free)
    except _Late:
        return None, {"iterations": None, "motions": None, "late": True}
    path, n, m = got
    stats = {"iterations": n, "motions": m}
    return (None if path is None else np.array(path, dtype=np.float64).reshape(-1, 3)), stats


# ---------------------------------------------------------------- the same search in Python
# The pure path, and the compiled search's oracle: the same samples (splitmix64), the same
# trees, nearest nodes, steps and motions asked, so the same path, as _carrrt.c's, double for
# double (the compiled and the Python Reeds–Shepp word give the same lengths).

_MASK = (1 << 64) - 1
_MAX_CONNECT = 100000  # steps of one connection, at most (a guard: each is ``step`` closer)
_TRAPPED, _ADVANCED, _REACHED = 0, 1, 2


class _Samples:
    """Uniform doubles in [0, 1) from splitmix64 seeded with ``seed``, as the compiled search draws them."""

    def __init__(self, seed: int):
        self.state = int(seed) & _MASK

    def unit(self) -> float:
        self.state = s = (self.state + 0x9E3779B97F4A7C15) & _MASK
        s = ((s ^ (s >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
        s = ((s ^ (s >> 27)) * 0x94D049BB133111EB) & _MASK
        return float((s ^ (s >> 31)) >> 11) * (1.0 / 9007199254740992.0)


def _nearest(nodes: list, q, r: float) -> tuple[int, float]:
    # A node's straight-line distance to q, and r times the turn between their headings, are each
    # at most the length of any curve joining them: a node whose bound is not below the best
    # length so far is passed over without its word.
    best, at = math.inf, -1
    for i, p in enumerate(nodes):
        dx, dy = q[0] - p[0], q[1] - p[1]
        bound = max(math.sqrt(dx * dx + dy * dy), r * abs(wrap_angle(q[2] - p[2])))
        if bound >= best:
            continue
        d = curve_length(reeds_shepp_segments(p, q, r))
        if d < best:
            best, at = d, i
    return at, best


def _along(p, segments, r: float, s: float) -> tuple:
    # The pose ``s`` along the curve from p: each arc turns the point about its centre, one
    # radius to the left (L) or right (R) of the heading; a reversed segment has a negative length.
    x, y, th = p
    for kind, length in segments:
        if not s > 0.0:
            break
        ln = length if abs(length) <= s else math.copysign(s, length)
        v = ln / r
        s -= abs(ln)
        if kind == "L":
            x += r * (math.sin(th + v) - math.sin(th))
            y += r * (math.cos(th) - math.cos(th + v))
            th += v
        elif kind == "R":
            x += r * (math.sin(th) - math.sin(th - v))
            y += r * (math.cos(th - v) - math.cos(th))
            th -= v
        else:
            x += ln * math.cos(th)
            y += ln * math.sin(th)
    return (x, y, wrap_angle(th))


def _grow(tree, start: bool, q, r: float, step: float, free, asked: list) -> int:
    # One step of ``tree`` towards q, from its nearest node, at most ``step`` along the curve; the
    # start tree drives from its node, the goal tree to it (each motion asked as the path drives it).
    nodes, up = tree
    i, d = _nearest(nodes, q, r)
    if i < 0:
        return _TRAPPED
    p = nodes[i]
    reach = d <= step
    nq = q if reach else _along(p, reeds_shepp_segments(p, q, r), r, step)
    if not reach and nq == p:
        return _TRAPPED
    asked[0] += 1
    if not free(*((p, nq) if start else (nq, p))):
        return _TRAPPED
    nodes.append(nq)
    up.append(i)
    return _REACHED if reach else _ADVANCED


def _branch(tree, i: int) -> list:
    nodes, up = tree
    out = []
    while i >= 0:
        out.append(nodes[i])
        i = up[i]
    return out


def search_python(start, goal, radius: float, bounds, step: float, seed: int, iterations: int, motion_free):
    """The compiled search (:func:`cspace.compiled.motions.car_connect`) in Python: ``(path or
    None, iterations, motions asked)``, the path a list of (x, y, theta) tuples; the same for the
    same arguments.

    >>> free = lambda q0, q1: True  # an empty scene
    >>> path, n, asked = search_python((1.0, 1.0, 0.0), (3.0, 1.0, 0.0), 1.0, (0, 4, 0, 2), 5.0, 0, 10, free)
    >>> path[0], path[-1], len(path), n, asked  # one sample: the start tree reached it, the goal tree too
    ((1.0, 1.0, 0.0), (3.0, 1.0, 0.0), 3, 1, 2)
    """
    xmin, xmax, ymin, ymax = map(float, bounds)
    r, step = float(radius), float(step)
    trees = (([tuple(map(float, start))], [-1]), ([tuple(map(float, goal))], [-1]))
    samples, asked, n, from_start, path = _Samples(seed), [0], 0, True, None
    while n < iterations and path is None:
        x = xmin + samples.unit() * (xmax - xmin)
        y = ymin + samples.unit() * (ymax - ymin)
        q = (x, y, -math.pi + samples.unit() * (2.0 * math.pi))
        grown, other = (trees[0], trees[1]) if from_start else (trees[1], trees[0])
        if _grow(grown, from_start, q, r, step, motion_free, asked) != _TRAPPED:
            target, c, k = grown[0][-1], _ADVANCED, 0  # the other tree connects to the new node
            while c == _ADVANCED and k < _MAX_CONNECT:
                c, k = _grow(other, not from_start, target, r, step, motion_free, asked), k + 1
            if c == _REACHED:
                s, g = (grown, other) if from_start else (other, grown)
                path = _branch(s, len(s[0]) - 1)[::-1] + _branch(g, g[1][-1])
        n, from_start = n + 1, not from_start
    return path, n, asked[0]
