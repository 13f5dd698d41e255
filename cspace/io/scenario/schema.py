"""The scenario schema: what a scenario *is* (:class:`Scenario`, :class:`Shape`, :class:`Query`)
and the limits of the scenes it describes.

A TOML file becomes a :class:`Scenario` through :func:`cspace.io.load.load_scenario`
(validation: :mod:`cspace.io.scenario.validate`).

Schema (all lengths in one unit, angles in radians)::

    name = "..."                       # optional, defaults to the file stem
    expect = "solvable"                # optional: "solvable" (default) or "unsolvable"
    disk_tolerance = 1e-3              # optional: largest disk-to-polygon error, relative to r
    [bounds]   xmin, xmax, ymin, ymax  # bounds of the robot's reference point (the state)
    [robot]    polygon = [[x, y], ...] # body frame, reference point = body origin
               | [[robot.parts]] polygon = ...   (several parts)
               | radius = r            # a disk centred on the reference point
               (no [robot]: a point robot)
    [[obstacles]] polygon = [[x, y], ...], holes = [[[x, y], ...], ...]  (holes optional)
                | center = [x, y], radius = r
    [start]    x, y, theta (optional; the fixed orientation while translating)
    [goal]     x, y, theta (optional; must equal the start's unless space = "se2")
    [planner]  name, time, seed        # optional defaults
    [[queries]] start = [x, y], goal = [x, y]   # optional extra queries ([x, y, theta] in SE(2))
    space = "translation" | "se2" | "dubins" | "reeds-shepp"
                                       # optional: "se2" lets the robot rotate (theta is free;
                                       # pose angles are taken into [-pi, pi), as OMPL's SO(2))
    slabs = K                          # optional, SE(2) only: angle slabs of the sliced C-space
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...kernel.polygons.disk import DEFAULT_RELATIVE_ERROR

# The state spaces a scenario can ask for, and the largest number of angle slabs.
SPACES = ("translation", "se2", "dubins", "reeds-shepp")
ROTATING_SPACES = ("se2", "dubins", "reeds-shepp")
CAR_SPACES = ("dubins", "reeds-shepp")
MAX_SLABS = 4096
# A rotating robot's convex pieces (a part, grown by its margin) have at most this many
# vertices: the slab build is quadratic in them (256: about a second for 32 slabs; a
# 7 025-gon took minutes and gigabytes). A finer disk needs a larger disk_tolerance.
MAX_ROTATING_VERTICES = 256
# A car's turning radius lies within these factors of the scene's extent (outside, the
# curves' lengths in radii overflow or lose every digit of the scene).
TURNING_RADIUS_RANGE = (1e-9, 1e9)
# Seeds: OMPL's are 32-bit and never 0 (planners.adapters.glue.SEED_LIMIT); a seed s is used as s + 1.
MAX_SEED = 2**32 - 2

# The scenes the C-space supports: products of two coordinates (or of two extents)
# stay far inside the double range. Within it, plans are the same at every scale: a
# scene scaled by a power of two gives the same path, scaled (tested from 2^-300 to
# 2^300). The geometry functions themselves take any finite doubles.
MAX_MAGNITUDE = 2.0**400
MIN_EXTENT = 2.0**-400


@dataclass
class Shape:
    """One robot part or obstacle: a simple polygon (CCW exterior, CW holes).

    ``disk`` is ``(cx, cy, r)`` when the shape stands for a disk (then ``polygon``
    is the circumscribed regular polygon).
    """

    polygon: np.ndarray
    holes: list[np.ndarray] = field(default_factory=list)
    disk: tuple[float, float, float] | None = None
    convex: bool = False

    def inner_polygon(self) -> np.ndarray:
        """A polygon inside the shape as written: the polygon itself, or for a disk the regular
        polygon of as many sides inscribed in it (:func:`cspace.kernel.polygons.disk.disk_inner_polygon`;
        (0, 2) when the disk is too small to hold one). What a proof that no path exists reasons
        about (``polygon``, around the disk, is what a certified path keeps clear of).

        >>> from cspace.kernel.polygons.disk import disk_polygon
        >>> sh = Shape(disk_polygon((0, 0), 1.0, sides=8), disk=(0.0, 0.0, 1.0), convex=True)
        >>> bool(np.hypot(*sh.inner_polygon().T).max() < 1.0 < np.hypot(*sh.polygon.T).min())
        True
        """
        if self.disk is None:
            return self.polygon
        from ...kernel.polygons.disk import disk_inner_polygon

        cx, cy, r = self.disk
        inner = disk_inner_polygon((cx, cy), r, len(self.polygon))
        return inner

    def to_shapely(self):
        """The shape as a shapely Polygon (imported lazily)."""
        import shapely

        return shapely.Polygon(self.polygon, [h for h in self.holes])


@dataclass
class Query:
    """A start and goal: (x, y) of the reference point, or poses (x, y, theta) in SE(2)."""

    start: tuple
    goal: tuple


@dataclass
class Scenario:
    """A planning problem: a robot, obstacles, bounds and queries.

    ``space`` is ``"translation"`` (the robot translates at the fixed orientation
    ``theta``; ``robot`` holds the parts already rotated by it, relative to the
    reference point) or ``"se2"`` (the robot also rotates; ``robot`` holds the parts
    in the body frame, ``theta`` is 0, and start, goal and queries are poses
    ``(x, y, theta)``). An empty ``robot`` is a point robot.
    """

    name: str
    bounds: tuple[float, float, float, float]
    robot: list[Shape]
    obstacles: list[Shape]
    start: tuple[float, float]
    goal: tuple[float, float]
    theta: float = 0.0
    planner: dict = field(default_factory=dict)
    queries: list[Query] = field(default_factory=list)
    expect: str = "solvable"
    path: str | None = None
    robot_kind: str = "point"  # "point", "polygon", "parts" or "disk"
    disk_tolerance: float = DEFAULT_RELATIVE_ERROR
    space: str = "translation"  # or "se2", "dubins", "reeds-shepp"
    slabs: int | None = None  # SE(2): angle slabs of the sliced C-space (None: derived)
    clearance: float = 0.0  # safety margin D: paths keep the robot at least D from obstacles
    margin: np.ndarray | None = None  # anisotropic convex margin (at theta in translation; body frame in SE(2))
    turning_radius: float | None = None  # car-like spaces: the minimum turning radius

    @property
    def rotates(self) -> bool:
        """Whether poses carry an angle: SE(2) and the car-like spaces (a car is a rotating robot
        whose motions are Dubins or Reeds–Shepp curves)."""
        return self.space in ROTATING_SPACES

    @property
    def has_disks(self) -> bool:
        """Whether a robot part or an obstacle is a disk (its polygon then only circumscribes it)."""
        return any(s.disk is not None for s in self.robot) or any(s.disk is not None for s in self.obstacles)

    def margins(self, inner: bool = False) -> list[np.ndarray]:
        """The margin operands the robot is inflated by (:func:`cspace.kernel.minkowski.margin.margin_shapes`);
        empty without a clearance or a margin polygon. ``inner``: the clearance's disk by its
        inscribed polygon (what a proof that no path keeps the clearance is made of)."""
        from ...kernel.minkowski.margin import margin_shapes

        return margin_shapes(self.clearance, self.margin, self.disk_tolerance, inner=inner)

    @property
    def dim(self) -> int:
        """Numbers in a state: 2 for translation, 3 for SE(2) and the car-like spaces."""
        return 3 if self.rotates else 2

    @property
    def is_point_robot(self) -> bool:
        return not self.robot

    def all_queries(self) -> list[Query]:
        """The main query first, then the ``[[queries]]`` (the main one not repeated)."""
        main = Query(self.start, self.goal)
        rest = [q for q in self.queries if (q.start, q.goal) != (main.start, main.goal)]
        return [main] + rest

    def robot_at(self, x: float, y: float, theta: float = 0.0) -> list[np.ndarray]:
        """The robot's part polygons with the reference point at (x, y), turned by theta
        (in SE(2); a translating robot is already at its fixed orientation)."""
        if theta:
            from ...kernel.polygons.rotation import rotate

            return [rotate(s.polygon, theta) + np.array([x, y]) for s in self.robot]
        return [s.polygon + np.array([x, y]) for s in self.robot]
