"""Independent oracles that tests of several folders share (numpy and shapely only).

``swept_clearance``: the clearance of a translation path, checked by the clearance tests
(tests/translation/test_clearance.py, tests/translation/test_path_clearance.py) and by the
bench's (tests/bench/test_bench_clearance.py).
"""
import math

import numpy as np
import shapely


def swept_clearance(path, robot_parts, obstacles) -> float:
    """Shapely: the distance between the robot (convex parts) swept along a translation path
    (per segment, the hull of the part at both ends) and the union of the obstacles."""
    union = shapely.union_all([shapely.Polygon(o) for o in obstacles])
    parts = robot_parts or [np.zeros((1, 2))]
    best = math.inf
    pts = list(path) if len(path) > 1 else [path[0], path[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        for r in parts:
            hull = shapely.MultiPoint(np.vstack([r + a, r + b])).convex_hull
            best = min(best, hull.distance(union))
    return best
