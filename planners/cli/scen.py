"""``cspace plan MAP.map --scen FILE.scen``: the rows of a MovingAI scenario file as the queries of
one C-space, with headings where the robot turns, and each row's octile optimum kept beside its
result (the grid optimum MovingAI computed: a reference for a translating robot).

Headings (``--scen-headings``): a ``.scen`` row gives cells, not angles. ``estimate`` (the
default) does what Bench-MR's ``Environment::estimateStartGoalOrientations`` does: plan a
point from start to goal (Bench-MR: Theta*, an any-angle grid search; here the exact shortest
path among the imported obstacles, the path Theta* approximates) and take the direction of its
first segment as the start's heading and of its last as the goal's. ``zero`` gives every pose
heading 0, what Bench-MR's benchmark runs use (its code never calls the estimate).
"""
from __future__ import annotations

import math
import sys

from ..errors import InputError


def add_scen_options(p) -> None:
    """``--scen``, ``--scen-rows``, ``--scen-headings`` (plan only)."""
    g = p.add_argument_group("MovingAI scenario files (.scen, with a .map)")
    g.add_argument("--scen", metavar="FILE.scen", help="plan these rows of a MovingAI scenario file as queries "
                                                       "on the .map's one C-space (start and goal cells; the row's "
                                                       "octile optimum is printed beside its result)")
    g.add_argument("--scen-rows", metavar="A:B", help="the rows to plan, Python-style: 0:10, -10: (the last ten), "
                                                      "5 (one row); default: all")
    g.add_argument("--scen-headings", choices=("estimate", "zero"), default=None,
                   help="the poses' headings where the robot turns: estimate (default; the first and last "
                        "segments of a point's shortest path, as Bench-MR estimates them) or zero")


def scen_rows(args, src: str) -> list | None:
    """The selected rows of ``--scen`` (None without it); the options checked against each other."""
    if args.scen is None:
        for flag in ("scen_rows", "scen_headings"):
            if getattr(args, flag) is not None:
                raise InputError(src, f"--{flag.replace('_', '-')}", "applies with --scen only")
        return None
    if args.queries is not None:
        raise InputError(src, "--scen", "--scen and --queries exclude each other (one list of queries)")
    if not src.lower().endswith(".map"):
        raise InputError(src, "--scen", "a MovingAI scenario file goes with its MovingAI map (.map)")
    for flag in ("start", "goal"):
        if getattr(args, flag) is not None:
            raise InputError(src, f"--{flag}", "--scen gives the starts and goals")
    from cspace.io.importers.movingai import read_scen
    from cspace.io.scenario.files import check_input

    check_input(args.scen)
    return read_scen(args.scen, args.scen_rows)


def first_points(rows: list, height: int, reading: str) -> tuple:
    """The first row's start and goal as points of the plane (the import's start and goal)."""
    from cspace.io.importers.movingai import scen_point

    r = rows[0]
    return scen_point(*r.start, height, reading), scen_point(*r.goal, height, reading)


def scen_scenario(args, src: str, options, rows: list, outputs: list):
    """Import the map, give every row its points (and headings where the robot turns), and
    return the Scenario with the rows as its queries, and the indices of the rows kept (a row
    whose start or goal puts the robot on an obstacle is left out, with a warning)."""
    from cspace.io.importers.imported import import_file
    from cspace.io.importers.movingai import read_map, scen_point
    from cspace.io.scenario.validate import with_queries

    from ..output import check_output

    reading = options.grid_reading or "movingai"
    blocked, _, _ = read_map(src)
    h, w = blocked.shape
    for r in rows:
        if (r.width, r.height) != (w, h):
            raise InputError(args.scen, f"row {r.index}", f"made for a {r.width} x {r.height} map, {src} is {w} x {h}")
    points = [(scen_point(*r.start, h, reading), scen_point(*r.goal, h, reading)) for r in rows]
    options.start, options.goal = points[0]
    imp = import_file(src, options)
    for out, opt in outputs:
        if out is not None:
            check_output(out, opt, inputs=imp.inputs + [args.scen])
    for warning in imp.warnings:
        sys.stderr.write(f"warning: {warning}\n")
    space = args.space or imp.data.get("space", "translation")
    turns = space in ("se2", "dubins", "reeds-shepp")
    headings = [(0.0, 0.0)] * len(rows)
    if turns and (args.scen_headings or "estimate") == "estimate":
        headings = estimate_headings(imp.data, points)
    queries = [({"start": [*st, th[0]] if turns else list(st), "goal": [*gl, th[1]] if turns else list(gl)})
               for (st, gl), th in zip(points, headings)]
    sc, kept = _placed(imp.data, src, args, queries)
    left = [i for i in range(len(rows)) if i not in kept]
    for i in left:
        sys.stderr.write(f"warning: {args.scen}: row {rows[i].index}: the robot at its start or goal touches an "
                         "obstacle: left out (counted not solved)\n")
    out = with_queries(sc, {"queries": [queries[i] for i in kept]}, args.scen)
    return out, kept


def _placed(data: dict, src: str, args, queries: list):
    """The scenario, its start and goal the first query whose robot touches nothing, and the
    indices of the queries whose start and goal are both free (the shapely probe's answer)."""
    from cspace.io.scenario.messages import ScenarioError
    from cspace.io.scenario.probe import CollisionProbe
    from cspace.io.scenario.validate import scenario_from_dict

    for q in queries:
        data["start"], data["goal"] = (_pose(q["start"]), _pose(q["goal"]))
        try:
            sc = scenario_from_dict(data, src, space=args.space, turning_radius=args.turning_radius)
        except ScenarioError as exc:
            if exc.field.split(".")[0] in ("start", "goal") and "collision" in exc.message:
                continue
            raise
        hits = CollisionProbe(sc).first_hits([tuple(p) for q2 in queries for p in (q2["start"], q2["goal"])])
        return sc, [i for i in range(len(queries)) if hits[2 * i] is None and hits[2 * i + 1] is None]
    raise InputError(args.scen, "rows", f"the robot touches an obstacle at the start or goal of every selected row "
                                        f"({len(queries)})")


def _pose(p: list) -> dict:
    d = {"x": float(p[0]), "y": float(p[1])}
    if len(p) > 2:
        d["theta"] = float(p[2])
    return d


def estimate_headings(data: dict, points: list, time_limit: float = 10.0) -> list[tuple[float, float]]:
    """Each (start, goal)'s headings: the directions of the first and last segments of a point's
    exact shortest path among the scenario dict's obstacles (0 where there is none).

    >>> data = {"bounds": {"xmin": 0, "xmax": 4, "ymin": 0, "ymax": 4},
    ...         "obstacles": [{"polygon": [[1, 0], [2, 0], [2, 3], [1, 3]]}]}
    >>> # around the wall's top corners (1, 3) and (2, 3): atan2(2.5, 0.5) and atan2(-2.5, 1.5)
    >>> [tuple(round(math.degrees(a)) for a in h) for h in estimate_headings(data, [((0.5, 0.5), (3.5, 0.5))])]
    [(79, -59)]
    """
    import numpy as np

    from cspace.paths.shortest import shortest_path
    from cspace.translation.cspace import CSpace

    b = data["bounds"]
    obs = data.get("obstacles", [])
    cs = CSpace((b["xmin"], b["xmax"], b["ymin"], b["ymax"]), [np.asarray(o["polygon"], float) for o in obs],
                None, obstacle_holes=[[np.asarray(h, float) for h in o.get("holes", [])] for o in obs])
    out = []
    for s, g in points:
        sp = shortest_path(cs.pieces, cs.bounds, s, g, time_limit=time_limit)
        if not sp.solved or len(sp.path) < 2:
            sys.stderr.write(f"warning: no point path from {s} to {g} for its headings: 0 taken (as Bench-MR "
                             "leaves them when its estimate fails)\n")
            out.append((0.0, 0.0))
            continue
        p = np.asarray(sp.path, float)
        out.append((math.atan2(p[1, 1] - p[0, 1], p[1, 0] - p[0, 0]),
                    math.atan2(p[-1, 1] - p[-2, 1], p[-1, 0] - p[-2, 0])))
    return out


def annotate(d: dict, rows: list, kept: list, results: list) -> list[str]:
    """Each row beside its result: the JSON's ``movingai`` list (in ``d``) and summary lines."""
    d["movingai"] = [{"row": r.index, "start_cell": list(r.start), "goal_cell": list(r.goal),
                      "octile_optimum": r.optimum, "query": kept.index(i) if i in kept else None,
                      "length": (results[kept.index(i)].length if results[kept.index(i)].solved else None)
                      if i in kept else None} for i, r in enumerate(rows)]
    lines = []
    left = [rows[i].index for i in range(len(rows)) if i not in kept]
    if left:
        lines.append(f"{len(left)} of {len(rows)} .scen rows left out (the robot touches an obstacle at their start "
                     f"or goal): rows {', '.join(map(str, left))}")
    for i, (r, res) in enumerate(zip([rows[k] for k in kept], results)):
        tail = f", length / octile {res.length / r.optimum:.4f}" if res.solved and r.optimum > 0 else ""
        lines.append(f"query {i}: .scen row {r.index}, cells {r.start} -> {r.goal}, octile optimum "
                     f"{r.optimum:.6g}{tail}")
    return lines
