"""The collision probe: which obstacle the robot at a pose touches, by an independent shapely route.

Validation places starts and goals with it (:mod:`cspace.io.validate`); tests use it as an oracle.
"""
from __future__ import annotations

import numpy as np

from ..kernel.union import union
from .schema import Scenario


class CollisionProbe:
    """Which obstacle does the robot at (x, y) touch? An independent shapely route.

    Closed sets: touching counts, the same convention as the C-space. Used to
    validate starts and goals, and as a test oracle.
    """

    def __init__(self, sc: Scenario):
        import shapely

        self._shapely = shapely
        self._sc = sc
        self._geoms = _shapely_obstacles(sc.obstacles)
        self._tree = shapely.STRtree(self._geoms) if self._geoms else None

    def first_hit(self, x: float, y: float, theta: float = 0.0) -> int | None:
        shapely = self._shapely
        if self._tree is None:
            return None
        if self._sc.robot:
            body = union([shapely.Polygon(p) for p in self._sc.robot_at(x, y, theta)])
        else:
            body = shapely.Point(x, y)
        hits = self._tree.query(body, predicate="intersects")
        return int(hits.min()) if len(hits) else None



def _shapely_obstacles(obstacles: list) -> list:
    """``[ob.to_shapely() for ob in obstacles]``, polygons without holes made in batches of
    one vertex count (one shapely call each instead of one per obstacle)."""
    import shapely

    out = [None] * len(obstacles)
    groups: dict = {}
    for i, ob in enumerate(obstacles):
        if ob.holes:
            out[i] = ob.to_shapely()
        else:
            groups.setdefault(len(ob.polygon), []).append(i)
    for idx in groups.values():
        for i, g in zip(idx, shapely.polygons(np.stack([obstacles[i].polygon for i in idx])).tolist()):
            out[i] = g
    return out


def first_collision(sc: Scenario, x: float, y: float) -> int | None:
    """Index of the first obstacle the robot at (x, y) touches (closed sets), or None."""
    return CollisionProbe(sc).first_hit(x, y)
