"""Bench-MR's path metrics, computed as its code computes them, for a solved path.

Bench-MR (``src/utils/PathEvaluation.hpp``) first interpolates a solution with OMPL's
``PathGeometric::interpolate(500)`` in the planning state space (``interpolation_limit``; a
path of more than 500 states or longer than 10 000 is left as it is), then measures the
interpolated states' (x, y) points:

- ``path_length``: the sum of the straight distances between consecutive points
  (``PathLengthMetric``: ``PlannerUtils::totalLength``);
- ``max_curvature``: walking the points, three at a time, each at least 0.3 from the one before
  (``MaxCurvatureMetric``), the largest inverse radius of the circle through them;
- ``normalized_curvature``: the same circles' curvatures, each times the two distances between
  its points, summed (``NormalizedCurvatureMetric``);
- ``aol``: the total absolute heading change between consecutive distinct segments divided by the
  path length (``AOLMetric``);
- ``cusps``: the points where that heading change exceeds 60 degrees (``computeCusps``);
- ``exact_goal_path``: the last state within 0.01 of the goal (``exact_goal_radius``).

Beside them, ours: the path is ``certified`` (every motion checked exactly, the footprint swept),
and its ``min_clearance`` (exact in translation, a certified lower bound when the robot turns).
"""
from __future__ import annotations

import math

import numpy as np

INTERPOLATION_LIMIT = 500
MAX_PATH_LENGTH = 10_000.0
CUSP_ANGLE = math.radians(60.0)
EXACT_GOAL_RADIUS = 1e-2
CURVATURE_STEP = 0.3


def interpolated(path: np.ndarray, space: str, turning_radius: float | None, bounds) -> np.ndarray:
    """The path's states after OMPL's ``interpolate(500)`` in its state space (SE(2), Dubins,
    Reeds–Shepp or the plane), as Bench-MR interpolates before measuring; (M, 2) or (M, 3)."""
    from ..adapters.glue import ompl

    ob, og, _ = ompl()
    path = np.asarray(path, dtype=float)
    if len(path) < 2:
        return path
    xmin, xmax, ymin, ymax = bounds
    b = ob.RealVectorBounds(2)
    b.setLow(0, xmin), b.setHigh(0, xmax), b.setLow(1, ymin), b.setHigh(1, ymax)
    if path.shape[1] == 2:
        s = ob.RealVectorStateSpace(2)
    elif space == "dubins":
        s = ob.DubinsStateSpace(float(turning_radius), False)
    elif space == "reeds-shepp":
        s = ob.ReedsSheppStateSpace(float(turning_radius))
    else:
        s = ob.SE2StateSpace()
    s.setBounds(b)
    si = ob.SpaceInformation(s)
    si.setStateValidityChecker(lambda _state: True)
    si.setup()
    p = og.PathGeometric(si)
    for row in path:
        st = s.allocState()
        if path.shape[1] == 2:
            st[0], st[1] = float(row[0]), float(row[1])
        else:
            st.setX(float(row[0])), st.setY(float(row[1])), st.setYaw(float(row[2]))
        p.append(st)
    if p.getStateCount() <= INTERPOLATION_LIMIT and p.length() <= MAX_PATH_LENGTH:
        p.interpolate(INTERPOLATION_LIMIT)
    out = []
    for i in range(p.getStateCount()):
        st = p.getState(i)
        out.append((st[0], st[1]) if path.shape[1] == 2 else (st.getX(), st.getY(), st.getYaw()))
    return np.array(out, dtype=float)


def total_length(pts: np.ndarray) -> float:
    """The sum of the straight distances between consecutive points (``PlannerUtils::totalLength``).

    >>> total_length(np.array([[0, 0], [3, 4], [3, 5]], float))
    6.0
    """
    return float(np.hypot(*np.diff(pts[:, :2], axis=0).T).sum()) if len(pts) > 1 else 0.0


def _next_far(pts: np.ndarray, i: int, x: float, y: float) -> int | None:
    """The first index after ``i`` whose point lies CURVATURE_STEP or more from (x, y) (Bench-MR's
    curvature walk skips the points closer than that); None past the end."""
    while True:
        i += 1
        if i >= len(pts):
            return None
        if math.hypot(pts[i, 0] - x, pts[i, 1] - y) >= CURVATURE_STEP:
            return i


def _circle_curvatures(pts: np.ndarray):
    """Bench-MR's walk for the curvature metrics: (curvature, |p1 p2| + |p2 p3|) per circle,
    its indices advanced exactly as its loops advance them."""
    n = len(pts)
    out = []
    if n < 3:
        return out
    i = 0
    while i < n - 2:
        x1, y1 = pts[i, 0], pts[i, 1]
        i = _next_far(pts, i, x1, y1)
        if i is None:
            return out
        x2, y2 = pts[i, 0], pts[i, 1]
        i = _next_far(pts, i, x2, y2)
        if i is None:
            return out
        x3, y3 = pts[i, 0], pts[i, 1]
        i += 1  # the for loop's own step
        if (x1 == x2 and y1 == y2) or (x2 == x3 and y2 == y3) or (x1 == x3 and y1 == y3):
            continue
        den_x = 2.0 * (x3 * (-y1 + y2) + x2 * (y1 - y3) + x1 * (-y2 + y3))
        den_y = 2.0 * (x3 * (y1 - y2) + x1 * (y2 - y3) + x2 * (-y1 + y3))
        with np.errstate(divide="ignore", invalid="ignore"):
            cx = (x3 ** 2 * (-y1 + y2) + x2 ** 2 * (y1 - y3) - (x1 ** 2 + (y1 - y2) * (y1 - y3)) * (y2 - y3)) / den_x \
                if den_x else math.inf
            cy = (-(x2 ** 2 * x3) + x1 ** 2 * (-x2 + x3) + x3 * (y1 ** 2 - y2 ** 2)
                  + x1 * (x2 ** 2 - x3 ** 2 + y2 ** 2 - y3 ** 2) + x2 * (x3 ** 2 - y1 ** 2 + y3 ** 2)) / den_y \
                if den_y else math.inf
        radius = math.hypot(x1 - cx, y1 - cy)
        k = 1.0 / radius if radius > 0 else math.inf
        out.append((k, math.hypot(x2 - x1, y2 - y1) + math.hypot(x3 - x2, y3 - y2)))
    return out


def _heading_changes(pts: np.ndarray):
    """(point, |heading change|) at each interior point between distinct segments, duplicates
    skipped as Bench-MR's ``computeCusps`` and ``AOLMetric`` skip them."""
    out = []
    n = len(pts)
    prev = cur = nxt = 0
    while nxt < n:
        if math.dist(pts[prev, :2], pts[cur, :2]) <= 0:
            cur += 1
            nxt += 1
        elif math.dist(pts[cur, :2], pts[nxt, :2]) <= 0:
            nxt += 1
        else:
            a = math.atan2(pts[cur, 1] - pts[prev, 1], pts[cur, 0] - pts[prev, 0])
            b = math.atan2(pts[nxt, 1] - pts[cur, 1], pts[nxt, 0] - pts[cur, 0])
            d = (b - a + math.pi) % (2 * math.pi) - math.pi
            out.append((cur, abs(d)))
            prev, cur = cur, nxt
            nxt += 1
    return out


def metrics(points: np.ndarray, goal) -> dict:
    """Bench-MR's metrics of interpolated states (:func:`interpolated`).

    >>> sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    >>> m = metrics(sq, (0, 1)); m["path_length"], m["cusps"], m["exact_goal_path"], round(m["aol"], 6)
    (3.0, 2, True, 1.047198)
    >>> round(m["max_curvature"], 6), round(m["normalized_curvature"], 6)  # one circle, radius sqrt(2)/2
    (1.414214, 2.828427)
    """
    pts = np.asarray(points, dtype=float)
    length = total_length(pts)
    circles = _circle_curvatures(pts)
    turns = _heading_changes(pts)
    cusps = [pts[i, :2].tolist() for i, d in turns if d > CUSP_ANGLE]
    return {
        "path_length": length,
        "max_curvature": max([k for k, _ in circles], default=0.0) if len(pts) else math.inf,
        "normalized_curvature": float(sum(k * s for k, s in circles)),
        "aol": float(sum(d for _, d in turns) / length) if length > 0 else 0.0,
        "cusps": len(cusps),
        "cusp_points": cusps,
        "exact_goal_path": bool(len(pts) and math.dist(pts[-1, :2], goal[:2]) <= EXACT_GOAL_RADIUS),
        "states": len(pts),
    }


def result_metrics(res, sc=None) -> dict | None:
    """Bench-MR's metrics of a solved :class:`planners.core.result.PlanResult`, with ours beside
    them (None when unsolved); ``sc``: its scenario (a query's result has none of its own)."""
    if not res.solved or res.path is None or len(res.path) == 0:
        return None
    sc = sc if sc is not None else res.scenario_data
    space = getattr(sc, "space", "translation")
    pts = interpolated(res.path, space, getattr(sc, "turning_radius", None), sc.bounds)
    m = metrics(pts, res.goal)
    m["planning_time"] = res.timings.get("solve", 0.0)
    m["certified"] = True  # every motion of a returned path is checked exactly (the footprint swept)
    m["path_collides"] = False
    m["min_clearance"] = res.min_clearance if res.min_clearance is None or math.isfinite(res.min_clearance) else "inf"
    m["min_clearance_bound"] = res.min_clearance_bound
    return m
