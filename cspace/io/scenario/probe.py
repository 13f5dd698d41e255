"""The collision probe: which obstacle the robot at a pose touches, by an independent shapely route.

Validation places starts and goals with it (:mod:`cspace.io.scenario.validate`); tests use it as an oracle.
"""
from __future__ import annotations

import numpy as np

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
        """The first obstacle (lowest index) the robot at (x, y, theta) touches, or None."""
        return self.first_hits([(x, y, theta)])[0]

    def first_hits(self, poses) -> list[int | None]:
        """:meth:`first_hit` of each pose ``(x, y)`` or ``(x, y, theta)``, in one tree query:
        the robot's parts placed at every pose (a part meets an obstacle iff the robot does).

        >>> import os, tempfile
        >>> from cspace.io.load import load_scenario
        >>> f = os.path.join(tempfile.mkdtemp(), "s.toml")
        >>> _ = open(f, "w").write("[bounds]\\nxmin=0\\nxmax=4\\nymin=0\\nymax=4\\n[start]\\nx=0.5\\ny=0.5\\n"
        ...     "[goal]\\nx=3.5\\ny=3.5\\n[[obstacles]]\\npolygon=[[1,1],[3,1],[3,3],[1,3]]\\n")
        >>> CollisionProbe(load_scenario(f)).first_hits([(0.5, 0.5), (2.0, 2.0), (3.0, 1.0)])
        [None, 0, 0]
        """
        shapely = self._shapely
        if self._tree is None or not len(poses):
            return [None] * len(poses)
        if self._sc.robot:
            bodies, owner = [], []
            for k, q in enumerate(poses):
                for part in self._sc.robot_at(q[0], q[1], q[2] if len(q) > 2 else 0.0):
                    bodies.append(part)
                    owner.append(k)
            geoms = [shapely.Polygon(b) for b in bodies]
        else:
            geoms = shapely.points(np.array([(q[0], q[1]) for q in poses], dtype=np.float64))
            owner = range(len(poses))
        inp, obs = self._tree.query(geoms, predicate="intersects")
        first = np.full(len(poses), len(self._geoms))
        np.minimum.at(first, np.asarray(owner, dtype=np.int64)[inp], obs)
        return [int(h) if h < len(self._geoms) else None for h in first.tolist()]


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
