"""Scenarios imported from other formats: ROS occupancy-grid maps (``.yaml``),
OMPL.app problem files (``.cfg``), SVG drawings (``.svg``, :mod:`cspace.io.importers.svg`) and
MovingAI grid maps (``.map``, :mod:`cspace.io.importers.movingai`).

An import builds the same dict a scenario TOML parses to, so one validator
(:func:`cspace.io.scenario.validate.scenario_from_dict`) checks both, and :func:`to_toml` writes
it out as a scenario file. What the map does not say (the robot, the start and goal
of a map) comes from :class:`ImportOptions`; what the import changed (cells filled,
vertices simplified, the largest error, anything dropped) is in the report.
"""
from __future__ import annotations

import math
import os
import time

import numpy as np

from ..scenario.messages import ScenarioError
from ..scenario.schema import MAX_MAGNITUDE
from .import_record import Imported, ImportOptions, robot_and_queries  # noqa: F401  (the imports' API)
from ..scenario.validate import scenario_from_dict

MAP_SUFFIXES = (".yaml", ".yml")
CFG_SUFFIXES = (".cfg",)
SVG_SUFFIXES = (".svg",)
GRID_SUFFIXES = (".map",)
SUFFIXES = MAP_SUFFIXES + CFG_SUFFIXES + SVG_SUFFIXES + GRID_SUFFIXES
# A map's default simplification tolerance, in cells: 2 lets Douglas-Peucker (within 0.8 cell)
# straighten a diagonal staircase (its corners are 0.71 cell off the diagonal); 1 would not.
DEFAULT_TOLERANCE_CELLS = 2.0


def is_import(path) -> bool:
    """Whether a file is read by an import (by its suffix) rather than as a scenario TOML.

    >>> is_import("maps/office.yaml"), is_import("basic.toml")
    (True, False)
    """
    return os.fspath(path).lower().endswith(SUFFIXES)


def import_file(path, options: ImportOptions | None = None) -> Imported:
    """Import a map YAML or an OMPL.app cfg into a scenario dict and a report.

    >>> import os
    >>> root = os.path.join(os.path.dirname(__file__), "..", "..", "..", "scenarios", "maps")
    >>> imp = import_file(os.path.join(root, "office.yaml"), ImportOptions(start=(0.5, 0.5), goal=(9.5, 6.5)))
    >>> len(imp.data["obstacles"]), imp.data["bounds"]["xmax"]
    (54, 11.0)
    """
    path = os.fspath(path)
    options = options or ImportOptions()
    if options.unknown not in ("obstacle", "free"):
        raise ScenarioError("--unknown", "unknown", f"must be obstacle or free, got {options.unknown!r}")
    if options.tolerance is not None and not (math.isfinite(options.tolerance) and options.tolerance >= 0):
        raise ScenarioError("--tolerance", "tolerance", f"must be a finite number >= 0, got {options.tolerance}")
    if options.flatten_curves is not None and not (math.isfinite(options.flatten_curves)
                                                   and options.flatten_curves > 0):
        raise ScenarioError("--flatten-curves", "flatten_curves", f"must be a positive finite distance, got "
                                                                  f"{options.flatten_curves}")
    if path.lower().endswith(CFG_SUFFIXES):
        from .omplapp import import_cfg

        return import_cfg(path, options)
    if path.lower().endswith(SVG_SUFFIXES):
        from .svg import import_svg

        return import_svg(path, options)
    if path.lower().endswith(GRID_SUFFIXES):
        from .movingai import import_movingai

        return import_movingai(path, options)
    return import_map(path, options)


def load_imported(path, space: str | None = None, options: ImportOptions | None = None,
                  turning_radius: float | None = None):
    """:func:`import_file`, then validated into a :class:`cspace.io.scenario.schema.Scenario`.

    >>> import os
    >>> root = os.path.join(os.path.dirname(__file__), "..", "..", "..", "scenarios", "maps")
    >>> sc = load_imported(os.path.join(root, "office.yaml"),
    ...                    options=ImportOptions(robot={"radius": 0.2}, start=(0.5, 0.5), goal=(9.5, 6.5)))
    >>> sc.robot_kind, sc.start, sc.space
    ('disk', (0.5, 0.5), 'translation')
    """
    imp = import_file(path, options)
    return scenario_from_dict(imp.data, os.fspath(path), space=space, turning_radius=turning_radius)


def import_map(path: str, options: ImportOptions) -> Imported:
    """A ROS map (YAML + image) as a scenario dict: obstacles traced conservatively.

    >>> import os
    >>> root = os.path.join(os.path.dirname(__file__), "..", "..", "..", "scenarios", "maps")
    >>> imp = import_map(os.path.join(root, "office.yaml"), ImportOptions(start=(0.5, 0.5), goal=(9.5, 6.5),
    ...                                                                   tolerance=0.0))
    >>> imp.report[2]
    'obstacles: 58 traced (482 vertices, 1 holes) -> 58 after simplification (482 vertices, 1 holes)'
    """
    import shapely

    from .occupancy import (check_vertices, classify, fill_corner_touches, polygons_of, read_image, read_map_yaml,
                            simplify_conservative, staircase)

    t0 = time.perf_counter()
    info = read_map_yaml(path)
    values, alpha = read_image(info, path)
    cells = classify(values, alpha, info)
    h, w = cells.shape
    res, (ox, oy, _) = info.resolution, info.origin
    if not max(abs(ox), abs(oy)) + (max(w, h) + 1) * res <= MAX_MAGNITUDE:  # before any geometry (issue 36)
        raise ScenarioError(path, "resolution", f"{res!r} per cell over {w} x {h} cells from the origin ({ox!r}, "
                                                f"{oy!r}) reaches beyond the supported magnitude 2^400")
    unknown_blocks = options.unknown == "obstacle"
    blocked = (cells == 1) | ((cells == -1) if unknown_blocks else False)
    # Rows bottom-up, and a ring of unknown cells around the map: with unknown cells as
    # obstacles the robot cannot leave the map (the reference point stays in its bounds).
    grid = np.pad(blocked[::-1], 1, constant_values=unknown_blocks)
    filled = fill_corner_touches(grid)
    check_vertices(grid, info.image)  # before any polygon is made (issue 36)
    t_read = time.perf_counter() - t0
    exact = staircase(grid)
    exact = shapely.transform(exact, lambda c: c - 1.0)  # padded units to cell units (exact on integers)
    tol = DEFAULT_TOLERANCE_CELLS * res if options.tolerance is None else options.tolerance
    # World coordinates round once (x = origin + X * resolution): a simplified vertex moves by
    # about an ulp of the largest coordinate, which the growth covers (64 of them, in cells).
    rounding = 64 * np.finfo(float).eps * (max(abs(ox), abs(oy)) + max(w, h) * res + res) / res
    result = simplify_conservative(exact, tol / res, margin=rounding)
    t_trace = time.perf_counter() - t0 - t_read
    error = _largest_error(result, exact, tol / res + 1.0) * res

    def world(c):
        return np.column_stack((ox + c[:, 0] * res, oy + c[:, 1] * res))

    result_w = shapely.transform(result, world)
    before, after = polygons_of(exact), polygons_of(result_w)
    obstacles = []
    for p in after:
        ob = {"polygon": _ring(p.exterior)}
        if p.interiors:
            ob["holes"] = [_ring(r) for r in p.interiors]
        obstacles.append(ob)
    bounds = {"xmin": ox, "xmax": ox + w * res, "ymin": oy, "ymax": oy + h * res}
    data = {"name": os.path.splitext(os.path.basename(path))[0], "bounds": bounds, "obstacles": obstacles}
    imp = Imported(data, warnings=list(info.warnings), inputs=[path, info.image])
    robot_and_queries(imp, options, path)
    n_occ, n_unk = int((cells == 1).sum()), int((cells == -1).sum())
    holes_before = sum(len(p.interiors) for p in before)
    holes_after = sum(len(p.interiors) for p in after)
    imp.report += [
        f"read {path}: image {os.path.basename(info.image)} {w} x {h} cells of {res:g}, origin ({ox:g}, {oy:g}), "
        f"mode {info.mode}{', negated' if info.negate else ''}, thresholds free < {info.free_thresh:g}, "
        f"occupied > {info.occupied_thresh:g}",
        f"cells: {n_occ} occupied, {w * h - n_occ - n_unk} free, {n_unk} unknown (unknown counted "
        f"{'as obstacles, and a ring of them around the map' if unknown_blocks else 'free'})",
        f"obstacles: {len(before)} traced ({_count(before)} vertices, {holes_before} holes) -> {len(after)} "
        f"after simplification ({_count(after)} vertices, {holes_after} holes)",
        f"simplification: tolerance {tol:g}, largest error {error:.3g} (every blocked cell inside the polygons)",
        f"time: read {t_read:.2f} s, trace and simplify {t_trace:.2f} s",
    ]
    if filled:
        imp.warnings.append(f"{path}: {filled} free cells counted blocked where blocked cells touched only at "
                            "a corner")
    if holes_after < holes_before:
        imp.warnings.append(f"{path}: {holes_before - holes_after} free pockets narrower than the tolerance closed")
    imp.comments += [f"imported from {os.path.basename(path)} (ROS map, {w} x {h} cells of {res:g})",
                     f"obstacles contain every {'occupied or unknown' if unknown_blocks else 'occupied'} cell; "
                     f"simplified within {tol:g}"]
    return imp


def _largest_error(result, exact, bound: float | None = None) -> float:
    """The largest distance from a vertex of ``result`` to ``exact`` (0 when equal)."""
    from .trace import largest_error

    return largest_error(result, exact, bound)  # O(n log n): a tree of exact's segments (issue 36)


def polygons_of_any(geom) -> list:
    """Polygons of a geometry (a Polygon is a list of one).

    >>> import shapely; len(polygons_of_any(shapely.box(0, 0, 1, 1)))
    1
    """
    return list(geom.geoms) if hasattr(geom, "geoms") else [geom]


def _ring(ring) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in np.asarray(ring.coords)[:-1]]


def _count(polys) -> int:
    return sum(len(p.exterior.coords) - 1 + sum(len(r.coords) - 1 for r in p.interiors) for p in polys)


def to_toml(imp: Imported) -> str:
    """The imported scenario as a TOML scenario file (comments first).

    >>> imp = Imported({"name": "m", "bounds": {"xmin": 0.0, "xmax": 1.0, "ymin": 0.0, "ymax": 1.0},
    ...                 "start": {"x": 0.1, "y": 0.1}, "goal": {"x": 0.9, "y": 0.9}}, comments=["hi"])
    >>> print(to_toml(imp).splitlines()[0])
    # hi
    """
    out = [f"# {c}" for c in imp.comments]
    d = imp.data
    for key in ("name", "space", "slabs", "expect"):
        if key in d:
            out.append(f"{key} = {_value(d[key])}")
    for key in ("bounds", "start", "goal", "planner"):
        if key in d:
            out += ["", f"[{key}]"] + [f"{k} = {_value(v)}" for k, v in d[key].items()]
    if "robot" in d:
        robot = d["robot"]
        out += ["", "[robot]"] + [f"{k} = {_value(v)}" for k, v in robot.items() if k != "parts"]
        for part in robot.get("parts", []):
            out += ["", "[[robot.parts]]"] + [f"{k} = {_value(v)}" for k, v in part.items()]
    for ob in d.get("obstacles", []):
        out += ["", "[[obstacles]]"] + [f"{k} = {_value(v)}" for k, v in ob.items()]
    return "\n".join(out) + "\n"


def _value(v) -> str:
    """A TOML value: strings quoted, floats exactly (repr round-trips), lists nested.

    >>> _value([[0.1, 2.0], [3, "a"]])
    '[[0.1, 2.0], [3, "a"]]'
    """
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if v != v else ("inf" if v > 0 else "-inf"))
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return str(v)
