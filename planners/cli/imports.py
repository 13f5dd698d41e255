"""``cspace import``: a ROS occupancy-grid map (``.yaml``), an OMPL.app problem (``.cfg``), an
SVG drawing (``.svg``: Bench-MR's polygon worlds) or a MovingAI map (``.map``) as a scenario TOML, with a report of what was read and what the import changed.

The options that say what such a file does not (the robot, the start and goal)
are shared with ``cspace plan``, which plans these files directly.
"""
from __future__ import annotations

import os
import sys

from ..errors import InputError


def register(sub) -> None:
    p = sub.add_parser("import", help="convert a ROS map (.yaml), an OMPL.app problem (.cfg), an SVG drawing "
                                      "(.svg) or a MovingAI map (.map) to a scenario",
                       description="Import a ROS map_server map (YAML + image), an OMPL.app .cfg problem "
                                   "(COLLADA meshes, needs pip install -e \".[io]\") or an SVG drawing (every "
                                   "path an obstacle, y up as Bench-MR reads it) and write it as a scenario "
                                   "TOML, or a MovingAI grid map (.map); exit 0 written, 2 bad input.")
    p.add_argument("file", help="map YAML (.yaml), OMPL.app problem (.cfg), SVG drawing (.svg) or MovingAI map (.map)")
    p.add_argument("--out", required=True, help="scenario TOML to write (never one of the inputs)")
    add_import_options(p)
    p.add_argument("--verbose", "-v", action="store_true",
                   help="on an internal error, print its traceback; let numpy and matplotlib warnings through")
    p.set_defaults(run=run)


def add_import_options(p) -> None:
    """The robot, start, goal and tracing options (import and plan share them)."""
    g = p.add_argument_group("imported files (.yaml maps, .cfg problems, .svg drawings)")
    g.add_argument("--robot", metavar="ROBOT.toml", help="the robot: a TOML file with a [robot] table "
                                                          "(polygon, parts or radius, as in a scenario), or an "
                                                          "SVG file whose first path is the robot, centred on the "
                                                          "mean of its points as Bench-MR centres it")
    g.add_argument("--radius", type=float, help="the robot: a disk of this radius")
    g.add_argument("--polygon", metavar="X,Y;X,Y;...", help="the robot: a polygon about its reference point")
    g.add_argument("--start", metavar="X,Y[,THETA]", help="start pose (a map has none; a .cfg's is overridden)")
    g.add_argument("--goal", metavar="X,Y[,THETA]", help="goal pose")
    g.add_argument("--unknown", choices=("obstacle", "free"), default=None,
                   help="a map's unknown cells: obstacle (default) or free")
    g.add_argument("--tolerance", type=float, help="largest simplification error of a map's obstacles, in map "
                                                   "units (default: two cells; 0: the exact staircase of cells)")
    g.add_argument("--flatten-curves", type=float, metavar="TOL",
                   help="an SVG's curves as chords within TOL of them, each such obstacle grown by TOL so that it "
                        "contains the curve (default: a curve is refused)")
    g.add_argument("--convex-hulls", action="store_true", default=None,
                   help="replace each SVG path (and an SVG robot) by its convex hull, as Bench-MR does "
                        "(default: the true shapes)")
    g.add_argument("--grid-reading", choices=("movingai", "bench-mr"), default=None,
                   help="a MovingAI map's frame: movingai (default: row 0 at the top, as MovingAI draws it) or "
                        "bench-mr (rows upwards, cells centred on integer points, only '.' passable, as "
                        "Bench-MR reads it)")
    g.add_argument("--border", action="store_true", default=None,
                   help="a MovingAI map's outermost cells blocked (Bench-MR's create_border)")


IMPORT_FLAGS = ("robot", "radius", "polygon", "start", "goal", "unknown", "tolerance", "flatten_curves",
                "convex_hulls", "grid_reading", "border")


def import_options(args, src: str):
    """The :class:`cspace.io.importers.imported.ImportOptions` of the parsed options; for a file that
    is not imported (a scenario TOML) any of them is an error."""
    from cspace.io.importers.imported import ImportOptions, is_import

    given = [f for f in IMPORT_FLAGS if getattr(args, f, None) is not None]
    if not is_import(src):
        if given:
            raise InputError(src, f"--{given[0].replace('_', '-')}", "applies to imported files (.yaml maps, .cfg "
                                                                     "problems, .svg drawings, .map grids) only; a "
                                                                     "scenario TOML names its own")
        return None
    robots = [f for f in ("robot", "radius", "polygon") if getattr(args, f) is not None]
    if len(robots) > 1:
        raise InputError(src, f"--{robots[1]}", f"--{robots[0]} and --{robots[1]} exclude each other (one robot)")
    robot = None
    flatten = getattr(args, "flatten_curves", None)
    if flatten is not None and not (flatten > 0 and flatten < float("inf")):
        raise InputError(src, "--flatten-curves", f"must be a positive finite distance, got {flatten}")
    hulls = bool(getattr(args, "convex_hulls", None))
    if args.robot is not None:
        robot = read_robot(args.robot, convex_hull=hulls, flatten=flatten)
    elif args.radius is not None:
        if not (args.radius > 0 and args.radius < float("inf")):
            raise InputError(src, "--radius", f"must be a positive number, got {args.radius}")
        robot = {"radius": args.radius}
    elif args.polygon is not None:
        robot = {"polygon": [list(_numbers(v, "--polygon", 2, 2)) for v in args.polygon.split(";") if v.strip()]}
    return ImportOptions(robot=robot,
                         start=_numbers(args.start, "--start", 2, 3) if args.start is not None else None,
                         goal=_numbers(args.goal, "--goal", 2, 3) if args.goal is not None else None,
                         unknown=args.unknown or "obstacle", tolerance=args.tolerance,
                         flatten_curves=flatten, convex_hulls=hulls, grid_reading=getattr(args, "grid_reading", None),
                         border=bool(getattr(args, "border", None)))


def imported_scenario(args, src: str, options, outputs: list):
    """Import the map or OMPL.app problem ``src`` with ``options`` (:func:`import_options`), check
    each ``(path, option)`` output against every file the import read (never written over one),
    print the import's warnings, and return its Scenario with ``--space`` and
    ``--turning-radius`` applied (plan and view share this)."""
    from cspace.io.importers.imported import import_file
    from cspace.io.load import scenario_from_dict

    from ..output import check_output

    imp = import_file(src, options)
    for out, opt in outputs:
        if out is not None:
            check_output(out, opt, inputs=imp.inputs)
    for w in imp.warnings:
        sys.stderr.write(f"warning: {w}\n")
    return scenario_from_dict(imp.data, src, space=args.space, turning_radius=args.turning_radius)


def count_as_load(res, seconds: float) -> None:
    """Add the seconds spent loading here (an import, a queries file: not by ``plan()``) to the
    result's ``load`` and ``total`` times (plan and view share this)."""
    res.timings["load"] = res.timings.get("load", 0.0) + seconds
    res.timings["total"] = res.timings.get("total", 0.0) + seconds


def _numbers(text: str, option: str, lo: int, hi: int) -> tuple:
    import math

    parts = [t for t in text.replace(" ", ",").split(",") if t]
    try:
        vals = tuple(float(t) for t in parts)
    except ValueError:
        vals = ()
    if not lo <= len(vals) <= hi or not all(math.isfinite(v) for v in vals):
        want = "x,y" if hi == 2 else "x,y or x,y,theta"
        raise InputError(text, option, f"expected {want} (finite numbers), got {text!r}")
    return vals


def input_files(src: str, robot: str | None = None, queries: str | None = None, scen: str | None = None) -> list[str]:
    """Every file a command reads, which no output may be: the scenario (or the map YAML and
    the image it names, or the cfg and its meshes, resolved as the import resolves them),
    the ``--robot`` file and the ``--queries`` file. Listed without importing; a file that
    cannot be listed (a broken YAML or cfg) is reported by the import itself."""
    from cspace.io.importers.imported import CFG_SUFFIXES, is_import
    from cspace.io.scenario.messages import ScenarioError

    files = [src]
    if is_import(src):
        try:
            if src.lower().endswith(CFG_SUFFIXES):
                from cspace.io.importers.omplapp import mesh_files

                files += mesh_files(src)
            elif src.lower().endswith((".svg", ".map")):
                pass  # one file
            else:
                from cspace.io.importers.occupancy import read_map_yaml

                files.append(read_map_yaml(src).image)
        except (ScenarioError, OSError, ValueError):
            pass
    return files + [f for f in (robot, queries, scen) if f is not None]


def read_robot(path: str, convex_hull: bool = False, flatten: float | None = None) -> dict:
    """The ``[robot]`` table of a TOML file (a robot file, or any scenario), or the robot of an
    SVG file (its first path, centred as Bench-MR centres it: :func:`cspace.io.importers.svg.svg_robot`)."""
    from cspace.io.scenario.files import read_input, toml_reader

    if path.lower().endswith(".svg"):
        from cspace.io.importers.svg import svg_robot
        from cspace.io.scenario.files import check_input

        check_input(path)
        robot, _, warnings = svg_robot(path, convex_hull=convex_hull, flatten=flatten)
        for w in warnings:
            sys.stderr.write(f"warning: {w}\n")
        return robot

    tomllib = toml_reader()
    raw = read_input(path)
    try:
        data = tomllib.loads(raw.decode("utf-8-sig"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError, ValueError, RecursionError) as exc:
        raise InputError(path, "--robot", f"not a TOML file ({str(exc)[:120]})") from None
    robot = data.get("robot")
    if not isinstance(robot, dict):
        raise InputError(path, "robot", "missing: a robot file needs a [robot] table (polygon, parts or radius)")
    return robot


def run(args) -> int:
    from cspace.io.scenario.files import check_input
    from cspace.io.importers.imported import import_file, is_import, to_toml
    from cspace.io.scenario.validate import scenario_from_dict

    from ..output import check_output, write_text

    src = args.file
    if not is_import(src):
        raise InputError(src, "file", "expected a map YAML (.yaml, .yml), an OMPL.app problem (.cfg), an SVG "
                                      "drawing (.svg) or a MovingAI map (.map)")
    check_input(src)
    check_output(args.out, "--out", {".toml": "toml"}, inputs=input_files(src, args.robot))
    options = import_options(args, src)
    imp = import_file(src, options)
    check_output(args.out, "--out", {".toml": "toml"}, inputs=imp.inputs)  # nor the image or a mesh
    text = to_toml(imp)
    scenario_from_dict(imp.data, src)  # what is written loads: start and goal free, polygons valid
    write_text(args.out, text, "--out")
    for line in imp.report:
        print(line)
    for w in imp.warnings:
        sys.stderr.write(f"warning: {w}\n")
    print(f"wrote {args.out}: {len(imp.data.get('obstacles', []))} obstacles, "
          f"{os.path.getsize(args.out) if os.path.isfile(args.out) else 0} bytes")
    return 0
