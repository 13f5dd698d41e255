"""What every import shares: its options (:class:`ImportOptions`), its record (:class:`Imported`:
the scenario dict, report lines, warnings, files read), and the robot, start and goal that the
options put over a file's own. The formats (:mod:`cspace.io.importers.occupancy` maps through
:mod:`cspace.io.importers.imported`, :mod:`cspace.io.importers.omplapp`) build on it."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..scenario.messages import ScenarioError


@dataclass
class ImportOptions:
    """What an import needs beyond the file.

    ``robot`` is a ``[robot]`` table as in a scenario (``{"radius": r}``,
    ``{"polygon": [[x, y], ...]}`` or ``{"parts": [...]}``), None for a point robot
    (a ``.cfg`` names its own robot). ``start`` and ``goal`` are ``(x, y)`` or
    ``(x, y, theta)`` (a ``.cfg`` gives its own, which these override).
    ``unknown`` is ``"obstacle"`` or ``"free"``; ``tolerance`` is the largest
    simplification error in world units (None: two cells of a map; 0: the exact
    staircase of cells). ``flatten_curves`` is the largest distance of a chord from an SVG
    curve (None: curves refused); ``convex_hulls`` replaces each SVG path by its convex hull.
    ``grid_reading`` (``"movingai"`` or ``"bench-mr"``) and ``border`` place a MovingAI map
    (:mod:`cspace.io.importers.movingai`).
    """

    robot: dict | None = None
    start: tuple | None = None
    goal: tuple | None = None
    unknown: str = "obstacle"
    tolerance: float | None = None
    flatten_curves: float | None = None
    convex_hulls: bool = False
    grid_reading: str | None = None
    border: bool = False


@dataclass
class Imported:
    """An import's scenario dict, its report lines and one-line warnings."""

    data: dict
    report: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    comments: list[str] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)  # every file read (an output must be none of them)


def robot_and_queries(imp: Imported, options: ImportOptions, path: str) -> None:
    """The robot, start and goal from the options (over the file's own, for a cfg)."""
    data = imp.data
    if options.robot is not None:
        data["robot"] = options.robot
    for key, value in (("start", options.start), ("goal", options.goal)):
        if value is not None:
            pose = {"x": float(value[0]), "y": float(value[1])}
            if len(value) > 2:
                pose["theta"] = float(value[2])
            data[key] = pose
        elif key not in data:
            raise ScenarioError(path, key, f"missing: a map has no {key}; give --{key} x,y")
    st, gt = data["start"].get("theta"), data["goal"].get("theta")
    if st is not None and gt is not None and st != gt and "space" not in data:
        data["space"] = "se2"  # different angles at the ends: the robot must rotate
