"""Where the robot is along a path: poses spaced evenly along it, moving between waypoints
exactly as the planner's motions do (straight in x, y; theta along the shorter arc, OMPL's
SE(2) interpolation), so the pictures show the motions that were certified; and the
robot's parts at a pose."""
from __future__ import annotations

import math

import numpy as np


def poses_along(path: np.ndarray, count: int, weight: float = 0.5) -> np.ndarray:
    """``count`` poses from the first to the last waypoint (both included), spaced evenly
    by the path's length in the metric of the planner (``|dxy| + weight * |dtheta|`` for
    (N, 3) poses, ``|dxy|`` for (N, 2) positions).

    >>> poses_along(np.array([[0., 0], [2, 0]]), 3).tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]
    >>> p = poses_along(np.array([[0., 0, 3.0], [0, 0, -3.0]]), 3)   # the shorter arc, through pi
    >>> round(float(p[1, 2]), 6)
    3.141593
    """
    from cspace.se2.cspace import interpolate

    path = np.asarray(path, dtype=np.float64)
    if len(path) == 1 or count < 2:
        return path[:1].repeat(max(count, 1), axis=0)
    se2 = path.shape[1] == 3
    step = np.hypot(*np.diff(path[:, :2], axis=0).T)
    if se2:
        step = step + weight * np.array([abs(_arc(a, b)) for a, b in zip(path[:-1, 2], path[1:, 2])])
    s = np.concatenate([[0.0], np.cumsum(step)])
    if s[-1] == 0.0:
        return path[:1].repeat(count, axis=0)
    out = []
    for target in np.linspace(0.0, s[-1], count):
        k = min(int(np.searchsorted(s, target, side="right")) - 1, len(path) - 2)
        t = 0.0 if step[k] == 0.0 else min(max((target - s[k]) / step[k], 0.0), 1.0)
        a, b = path[k], path[k + 1]
        out.append(interpolate(tuple(a), tuple(b), t) if se2 else tuple(a + t * (b - a)))
    return np.array(out, dtype=np.float64)


def _arc(a: float, b: float) -> float:
    """Signed shorter-arc angle from a to b, in [-pi, pi]."""
    d = math.remainder(b - a, 2.0 * math.pi)
    return d


def robot_polygons(scenario, pose) -> list[np.ndarray]:
    """The robot's parts at a pose ((x, y) or (x, y, theta)), in world coordinates."""
    theta = float(pose[2]) if len(pose) > 2 else 0.0
    return scenario.robot_at(float(pose[0]), float(pose[1]), theta)
