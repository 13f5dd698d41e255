"""Scenario validation: a parsed TOML document (a dict) into a :class:`cspace.io.scenario.schema.Scenario`.

The document's sections in order, the rules across fields (space, slabs, turning radius, a
translating robot's one angle), then every start and goal placed in bounds and free of obstacles.
Fields are checked by :mod:`cspace.io.scenario.fields` and :mod:`cspace.io.scenario.shapes`.
"""
from __future__ import annotations

import math
import os

from ...kernel.polygons.disk import DEFAULT_RELATIVE_ERROR
from ...kernel.polygons.rotation import wrap_angle
from .messages import ScenarioError, control_character, printable, short
from .probe import CollisionProbe
from .schema import (CAR_SPACES, MAX_ROTATING_VERTICES, MAX_SLABS, MIN_EXTENT, ROTATING_SPACES, SPACES,
                     TURNING_RADIUS_RANGE, Scenario)
from .shapes import ShapeChecks

# The keys a scenario may have at its top level (a new section adds its key here).
TOP_LEVEL_KEYS = frozenset({"name", "expect", "disk_tolerance", "bounds", "robot", "obstacles", "start", "goal",
                            "planner", "queries", "space", "slabs", "turning_radius",
                            "clearance", "margin"})


def scenario_from_dict(data: dict, path: str = "<scenario>", space: str | None = None,
                       turning_radius: float | None = None) -> Scenario:
    """Validate a parsed scenario (the TOML document as a dict) into a :class:`Scenario`.
    ``space`` and ``turning_radius``, if given, override the document's."""
    v = _Validator(path)
    v.no_extra(data, "", TOP_LEVEL_KEYS)
    name = data.get("name")
    if name is None:  # the file's name: shown as it is spelt, its control characters escaped
        name = printable(os.path.splitext(os.path.basename(path))[0])
    elif not isinstance(name, str):
        raise v.err("name", "must be a string")
    elif control_character(name) is not None:  # it would act on a terminal and break a log's lines
        raise v.err("name", f"contains the control character {control_character(name)} (names are printed "
                            "on terminals and written in logs)")
    expect = data.get("expect", "solvable")
    if expect not in ("solvable", "unsolvable"):
        raise v.err("expect", 'must be "solvable" or "unsolvable"')
    tol = v.number(data.get("disk_tolerance", DEFAULT_RELATIVE_ERROR), "disk_tolerance", positive=True)

    if "bounds" not in data and set(data) <= {"robot", "name"}:  # a robot file (--robot), given as a scene
        raise v.err("bounds", "missing: this file holds a robot only; give it as --robot FILE with a scenario "
                              "or a map to plan in")
    b = v.table(data, "bounds", required=True)
    v.no_extra(b, "bounds", {"xmin", "xmax", "ymin", "ymax"})  # first: a misspelt key explains a missing one
    xmin, xmax = v.number(b.get("xmin"), "bounds.xmin"), v.number(b.get("xmax"), "bounds.xmax")
    ymin, ymax = v.number(b.get("ymin"), "bounds.ymin"), v.number(b.get("ymax"), "bounds.ymax")
    if not xmin < xmax:
        raise v.err("bounds", f"xmin ({xmin}) must be less than xmax ({xmax})")
    if not ymin < ymax:
        raise v.err("bounds", f"ymin ({ymin}) must be less than ymax ({ymax})")
    if max(xmax - xmin, ymax - ymin) < MIN_EXTENT:
        raise v.err("bounds", f"the scene's extent {max(xmax - xmin, ymax - ymin):.3g} is below the supported "
                              f"2^-400 (about {MIN_EXTENT:.2g})")
    bounds = (xmin, xmax, ymin, ymax)

    if space is not None and space not in SPACES:
        raise ScenarioError("--space", "space", f"must be one of {', '.join(SPACES)}, got {short(space)}")
    overridden = space is not None and space != data.get("space", "translation")
    space = space or data.get("space", "translation")
    if space not in SPACES:
        raise v.err("space", f"must be one of {', '.join(repr(s) for s in SPACES)}, got {short(space)}")
    se2 = space in ROTATING_SPACES
    slabs = data.get("slabs")
    if slabs is not None:
        if not se2:
            raise v.err("slabs", 'applies to a rotating robot only (space = "se2", "dubins" or "reeds-shepp")')
        if isinstance(slabs, bool) or not isinstance(slabs, int) or not 4 <= slabs <= MAX_SLABS:
            raise v.err("slabs", f"must be an integer from 4 to {MAX_SLABS} (a slab spans at most a quarter "
                                 f"turn), got {short(slabs)}")
    radius = data.get("turning_radius")
    if turning_radius is not None:
        if space not in CAR_SPACES:
            raise ScenarioError("--turning-radius", "turning_radius", 'applies to space = "dubins" or "reeds-shepp" only')
        if isinstance(turning_radius, bool) or not isinstance(turning_radius, (int, float)) \
                or not 0.0 < float(turning_radius) < math.inf:
            raise ScenarioError("--turning-radius", "turning_radius", f"must be a positive number, got {short(turning_radius)}")
        radius = float(turning_radius)
    if space in CAR_SPACES:
        if radius is None:
            raise v.err("turning_radius", f'is required for space = "{space}" (the car\'s minimum turning radius)')
        radius = v.number(radius, "turning_radius", positive=True)
        lo, hi = (f * max(xmax - xmin, ymax - ymin) for f in TURNING_RADIUS_RANGE)
        if not lo <= radius <= hi:
            where = ("--turning-radius", "turning_radius") if turning_radius is not None else (path, "turning_radius")
            raise ScenarioError(*where, f"{radius!r} is outside [{lo:.3g}, {hi:.3g}] (1e-9 to 1e9 times the "
                                        "scene's extent)")
    elif radius is not None and overridden and data.get("space") in CAR_SPACES:
        radius = None  # a car's file planned as another space (--space se2): its turning radius does not apply
    elif radius is not None:
        raise v.err("turning_radius", 'applies to space = "dubins" or "reeds-shepp" only')

    start_t = v.table(data, "start", required=True)
    goal_t = v.table(data, "goal", required=True)
    start, theta = v.pose(start_t, "start")
    goal, goal_theta = v.pose(goal_t, "goal")
    if se2:  # angles as OMPL's SO(2) holds them: in [-pi, pi) (pi itself is -pi)
        start, goal = (*start, wrap_angle(theta or 0.0)), (*goal, wrap_angle(goal_theta or 0.0))
        theta = 0.0  # the robot stays in its body frame; poses carry the angle
    else:
        if goal_theta is not None and theta is not None and goal_theta != theta:
            raise v.err("goal.theta", f"{goal_theta} differs from start.theta ({theta}), but the robot only "
                                      'translates here: add space = "se2" to let it rotate')
        theta = theta if theta is not None else (goal_theta or 0.0)

    robot, kind = v.robot(data.get("robot"), theta, tol)
    clearance = v.number(data.get("clearance", 0.0), "clearance")
    if clearance < 0:
        raise v.err("clearance", f"must be a distance >= 0, got {data.get('clearance')}")
    margin = v.margin(data.get("margin"), theta, tol)
    if se2:
        _rotating_size(v, robot, margin, clearance, tol)
    obstacles = v.obstacles(data.get("obstacles", []), tol)
    planner = v.planner(data.get("planner", {}))
    queries = v.queries(data.get("queries", []), se2)

    sc = Scenario(
        name=name, bounds=bounds, robot=robot, obstacles=obstacles, start=start, goal=goal,
        theta=theta, planner=planner, queries=queries, expect=expect, path=path,
        robot_kind=kind, disk_tolerance=tol, space=space, slabs=slabs,
        turning_radius=radius, clearance=clearance, margin=margin,
    )
    labelled = [(start, "start"), (goal, "goal")]
    for i, q in enumerate(queries):
        labelled += [(q.start, f"queries[{i}].start"), (q.goal, f"queries[{i}].goal")]
    hits = CollisionProbe(sc).first_hits([pt for pt, _ in labelled])  # one query for every pose
    for (pt, fld), hit in zip(labelled, hits):
        v.placement(sc, pt, hit, fld)
    return sc


def with_queries(sc: Scenario, data: dict, path: str) -> Scenario:
    """``sc`` with the queries of a queries file (``data``: its parsed TOML, whose one key is
    ``queries``, an array of ``{start, goal}`` tables as in a scenario) instead of its own,
    the first becoming its start and goal; every pose is checked as a scenario's (in the
    bounds, the robot touching nothing). Faults name ``path``, the queries file.

    >>> import numpy as np
    >>> from .schema import Shape
    >>> sc = Scenario(name="s", bounds=(0.0, 4.0, 0.0, 4.0), robot=[], obstacles=[], start=(1.0, 1.0), goal=(2.0, 2.0))
    >>> q = with_queries(sc, {"queries": [{"start": [0.5, 0.5], "goal": [3, 3]}, {"start": [1, 3], "goal": [3, 1]}]}, "q.toml")
    >>> q.start, q.goal, len(q.all_queries())
    ((0.5, 0.5), (3.0, 3.0), 2)
    """
    import dataclasses

    v = _Validator(path)
    if not isinstance(data, dict):
        raise v.err("queries", "must be a TOML document with [[queries]] tables")
    v.no_extra(data, "", {"queries"})
    queries = v.queries(data.get("queries", []), sc.rotates)
    if not queries:
        raise v.err("queries", "none given: add [[queries]] tables with start and goal")
    out = dataclasses.replace(sc, start=queries[0].start, goal=queries[0].goal, queries=queries)
    labelled = [(pt, f"queries[{i}].{k}") for i, q in enumerate(queries) for pt, k in ((q.start, "start"), (q.goal, "goal"))]
    hits = CollisionProbe(out).first_hits([pt for pt, _ in labelled])
    for (pt, fld), hit in zip(labelled, hits):
        v.placement(out, pt, hit, fld)
    return out


def _rotating_size(v, robot, margin, clearance: float, tol: float) -> None:
    """A rotating robot's parts, each grown by its margin, within MAX_ROTATING_VERTICES (an
    upper bound on its convex pieces' vertices: a convex sum has at most n + m)."""
    from ...kernel.minkowski.margin import margin_shapes

    extra = sum(len(m) for m in margin_shapes(clearance, margin, tol))
    for i, sh in enumerate(robot):
        n = len(sh.polygon) + extra
        if n > MAX_ROTATING_VERTICES:
            fld = "robot" if len(robot) == 1 else f"robot.parts[{i}]"
            hint = " (raise disk_tolerance)" if sh.disk is not None or extra else ""
            raise v.err(fld, f"{n} vertices{' with its margin' if extra else ''}: a rotating robot part has at "
                             f"most {MAX_ROTATING_VERTICES}{hint}")


class _Validator(ShapeChecks):
    """The field and shape checks, and where starts and goals may be."""

    def placement(self, sc: Scenario, pt: tuple, hit: int | None, field: str) -> None:
        """The reference point must be in bounds and the robot there (turned by the
        pose's theta in SE(2)) must touch no obstacle (``hit``: the first it touches,
        :meth:`CollisionProbe.first_hits`)."""
        xmin, xmax, ymin, ymax = sc.bounds
        x, y = pt[0], pt[1]
        theta = pt[2] if len(pt) > 2 else 0.0
        where = f"({x}, {y})" if len(pt) == 2 else f"({x}, {y}, theta {theta})"
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            raise self.err(field, f"{where} is outside the bounds [{xmin}, {xmax}] x [{ymin}, {ymax}]")
        if hit is not None:  # named by its index and its box: an imported map's obstacles have no table to count
            poly = sc.obstacles[hit].polygon
            (x0, y0), (x1, y1) = poly.min(axis=0), poly.max(axis=0)
            raise self.err(field, f"{where} puts the robot in collision with obstacles[{hit}] (the one within "
                                  f"x {x0:.6g} to {x1:.6g}, y {y0:.6g} to {y1:.6g})")
