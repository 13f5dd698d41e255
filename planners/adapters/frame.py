"""What every state-space adapter shares: the scaled frame OMPL's states live in, OMPL's
bounds in that frame, the exact verification loop over a path's steps, and a path's length.

Plain functions over numpy arrays; nothing here imports OMPL (``scaled_bounds`` takes
OMPL's base module as an argument).
"""
from __future__ import annotations

import math
import weakref

import numpy as np

_NEAREST: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # C-space -> its obstacles' Nearest


def frame_exponent(bounds) -> int:
    """The power of two k OMPL's states are scaled by: 0 for scenes of ordinary size.

    OMPL has absolute thresholds (a longest valid segment must exceed machine epsilon,
    the goal is reached within ``GOAL_THRESHOLD``), so a scene 1e-17 across cannot be
    planned as it is. Scenes whose extent leaves [2^-20, 2^100] are planned in a frame
    scaled by 2^k to an extent near 1: exact, so the C-space's answers, and so the
    path (scaled back), are the same. The hot path pays nothing when k is 0.

    >>> frame_exponent((0.0, 10.0, 0.0, 10.0)), frame_exponent((0.0, 1e-17, 0.0, 1e-17))
    (0, 56)
    """
    xmin, xmax, ymin, ymax = map(float, bounds)
    extent = max(xmax - xmin, ymax - ymin)
    if not (0.0 < extent < math.inf) or 2.0**-20 <= extent <= 2.0**100:
        return 0
    return -math.frexp(extent)[1]


def scaled_bounds(ob, bounds, k: int):
    """The C-space's bounds (xmin, xmax, ymin, ymax) as OMPL's ``RealVectorBounds(2)`` of
    x and y, in the frame scaled by 2^k (``ob``: OMPL's base module)."""
    xmin, xmax, ymin, ymax = (math.ldexp(float(v), k) for v in bounds)
    b = ob.RealVectorBounds(2)
    b.setLow(0, xmin)
    b.setHigh(0, xmax)
    b.setLow(1, ymin)
    b.setHigh(1, ymax)
    return b


def verify_path(path: np.ndarray, start: tuple, goal: tuple, step_free, *, step: str = "segment",
                test: str = "exact", ends: str = "start to goal") -> tuple[bool, str]:
    """The adapters' verification: the path runs from ``start`` exactly to ``goal`` exactly
    and ``step_free(a, b)`` accepts each of its steps (one point: start equals goal).

    >>> verify_path(np.array([[0., 0], [1, 0]]), (0.0, 0.0), (1.0, 0.0), lambda a, b: True)
    (True, 'exact solution')
    >>> verify_path(np.array([[0., 0], [1, 0]]), (0.0, 0.0), (2.0, 0.0), lambda a, b: True)
    (False, 'path does not run exactly from start to goal')
    """
    # Rows as tuples of Python floats (not NumPy scalars): the checks' fast paths take them as they are.
    rows = [tuple(r) for r in np.asarray(path).tolist()]
    if len(rows) < 2:
        same = len(rows) == 1 and rows[0] == start == goal
        return same, "start equals goal" if same else "empty path"
    if rows[0] != start or rows[-1] != goal:
        return False, f"path does not run exactly from {ends}"
    for i in range(len(rows) - 1):
        if not step_free(rows[i], rows[i + 1]):
            return False, f"{step} {i} failed the {test} test"
    return True, f"{test} solution"


def path_length(path: np.ndarray) -> float:
    """Euclidean length of the polyline of reference points: the (x, y) columns (poses
    (x, y, theta) of a rotating robot count their x, y).

    >>> path_length(np.array([[0., 0], [3, 4], [3, 5]]))
    6.0
    >>> path_length(np.array([[0., 0, 0], [3, 4, 1], [3, 5, -1]]))
    6.0
    """
    if len(path) < 2:
        return 0.0
    return float(np.hypot(*np.diff(path[:, :2], axis=0).T).sum())


def obstacle_nearest(cspace):
    """The :class:`cspace.translation.clearance.Nearest` of a C-space's obstacle pieces, made on
    first use and kept with the C-space: the clearance measures of its many paths share it.

    >>> from cspace.se2.cspace import SE2CSpace
    >>> cs = SE2CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])], [np.array([[0., 0], [1, 0], [0, 1]])])
    >>> obstacle_nearest(cs) is obstacle_nearest(cs), len(obstacle_nearest(cs).pieces)
    (True, 1)
    """
    from cspace.translation.clearance import Nearest

    near = _NEAREST.get(cspace)
    if near is None:
        near = _NEAREST[cspace] = Nearest(cspace.obstacle_pieces)
    return near
