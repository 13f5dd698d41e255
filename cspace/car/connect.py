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
Compiled only (cspace/compiled/_carrrt.c): :func:`connect` returns None on the pure path and
the caller plans with OMPL instead.
"""
from __future__ import annotations

import time

import numpy as np

from ..compiled import motions


class _Late(Exception):
    """The deadline passed: raised through the compiled search from the motion test."""


def connect(motion_free, start, goal, radius: float, bounds, step: float, seed: int, iterations: int,
            deadline: float | None = None):
    """Search for a path of Reeds–Shepp curves from ``start`` to ``goal`` (poses (x, y, theta))
    within ``bounds`` (xmin, xmax, ymin, ymax) for ``iterations`` samples at most, extending by at
    most ``step`` (a length along the curve), stopping at ``deadline`` (a ``time.perf_counter``
    value) if given. Returns ``(path or None, {"iterations": n, "motions": m})``, the path an
    (N, 3) array from start to goal whose motions ``motion_free`` accepted each; or None on the
    pure path (no compiled search).

    >>> from cspace.car.motion import CarCSpace
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> cs = CarCSpace((0, 10, 0, 10), [np.array([[4., 3], [6, 3], [6, 7], [4, 7]])], [box], slabs=16)
    >>> test = cs.car_motion_test("reeds-shepp", 1.0)
    >>> got = connect(test, (1.0, 5.0, 0.0), (9.0, 5.0, 0.0), 1.0, (0, 10, 0, 10), 3.0, 7, 2000)
    >>> got is None or (got[0][0].tolist(), got[0][-1].tolist()) == ([1.0, 5.0, 0.0], [9.0, 5.0, 0.0])
    True
    >>> got is None or all(test(tuple(a), tuple(b)) for a, b in zip(got[0][:-1].tolist(), got[0][1:].tolist()))
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
    except _Late:
        return None, {"iterations": None, "motions": None, "late": True}
    if got is None:
        return None
    path, n, m = got
    stats = {"iterations": n, "motions": m}
    return (None if path is None else np.array(path, dtype=np.float64).reshape(-1, 3)), stats
