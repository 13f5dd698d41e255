"""Geometry as plotly traces: polygons joined into one filled trace (rings separated by gaps),
the robot's footprint at a pose, a path's lines, the closest approach. Plain dicts, so that
the figure is built and validated by plotly once (:mod:`.figure`)."""
from __future__ import annotations

import math

import numpy as np

from ..plot import BOUNDS, CLOSEST, COBSTACLE, GOAL, OBSTACLE, PATH, PIECE_EDGE, REVERSE, ROBOT
from ..plot import GAP as GAP_COLOUR

GAP = np.full((1, 2), np.nan)  # between two rings of one trace
PROOF = "#4c9f70"  # the free components a proof lists (slab_pair.py's FREE colour)


def example_scene():
    """A small translation scene (a triangle robot, one wall), for the examples.

    >>> example_scene().bounds
    (0.0, 10.0, 0.0, 10.0)
    """
    from cspace.io.load import scenario_from_dict

    return scenario_from_dict({"name": "example", "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
                               "robot": {"polygon": [[-0.4, -0.3], [0.4, -0.3], [0.0, 0.5]]},
                               "obstacles": [{"polygon": [[3, 0], [4, 0], [4, 6], [3, 6]]}],
                               "start": {"x": 1, "y": 1}, "goal": {"x": 9, "y": 9}}, "example")


def digits(bounds) -> int:
    """Decimals kept in the page: a millionth of the scene's size (coordinates are for the eye).

    >>> digits((0, 10, 0, 10)), digits((0, 1200, 0, 100))
    (5, 3)
    """
    xmin, xmax, ymin, ymax = bounds
    extent = max(xmax - xmin, ymax - ymin, 1e-300)
    return max(0, 6 - math.floor(math.log10(extent)))


def rings_xy(rings, nd: int = 6) -> tuple[list, list]:
    """x and y lists of closed rings separated by ``None`` (plotly's gap): one trace for many polygons.

    >>> rings_xy([[[0, 0], [1, 0], [0, 1]]])
    ([0.0, 1.0, 0.0, 0.0, None], [0.0, 0.0, 1.0, 0.0, None])
    """
    parts = []
    for ring in rings:
        r = np.asarray(ring, dtype=np.float64).reshape(-1, 2)
        if len(r):
            parts += [r, r[:1], GAP]
    if not parts:
        return [], []
    p = np.round(np.concatenate(parts), nd)
    return ([None if v != v else v for v in p[:, 0].tolist()],  # NaN (the gap) as JSON null
            [None if v != v else v for v in p[:, 1].tolist()])


def line_xy(points, nd: int = 6) -> tuple[list, list]:
    """x and y lists of a polyline (rounded to ``nd`` decimals).

    >>> line_xy([[0, 0.1234567], [1, 2]], nd=3)
    ([0.0, 1.0], [0.123, 2.0])
    """
    p = np.round(np.asarray(points, dtype=np.float64).reshape(-1, 2), nd)
    return p[:, 0].tolist(), p[:, 1].tolist()


def filled(name: str, rings, color: str, nd: int, *, line: str | None = None, opacity: float = 1.0,
           legend: bool = True, dash: str | None = None, fill: bool = True) -> dict:
    """A scatter trace filling (or outlining) polygons; rings wound oppositely cut holes
    (the scenario stores shells counter-clockwise, holes clockwise).

    >>> t = filled("obstacle", [[[0, 0], [1, 0], [0, 1]]], "#333333", 3)
    >>> t["fill"], t["x"][:3], t["name"]
    ('toself', [0.0, 1.0, 0.0], 'obstacle')
    """
    x, y = rings_xy(rings, nd)
    edge = line or color
    return {"type": "scatter", "mode": "lines", "name": name, "x": x, "y": y,
            "fill": "toself" if fill else "none", "fillcolor": color if fill else None,
            "line": {"color": edge, "width": 0.8 if line or not fill else 0, **({"dash": dash} if dash else {})},
            "opacity": opacity, "hoverinfo": "name", "showlegend": legend}


def bounds_trace(bounds) -> dict:
    """The bounds of the reference point, dashed.

    >>> bounds_trace((0, 2, 0, 1))["x"]
    [0, 2, 2, 0, 0]
    """
    xmin, xmax, ymin, ymax = bounds
    return {"type": "scatter", "mode": "lines", "name": "bounds", "x": [xmin, xmax, xmax, xmin, xmin],
            "y": [ymin, ymin, ymax, ymax, ymin], "line": {"color": BOUNDS, "width": 1, "dash": "dash"},
            "hoverinfo": "skip"}


def obstacle_rings(scenario) -> list:
    """Every obstacle's shell and holes, as rings.

    >>> len(obstacle_rings(example_scene()))
    1
    """
    rings = []
    for ob in scenario.obstacles:
        rings.append(ob.polygon)
        rings += list(ob.holes)
    return rings


def footprint(scenario, pose, nd: int, limit: int | None = None) -> tuple[list, list]:
    """x, y lists of the robot's parts at ``pose`` ((x, y) or (x, y, theta)); a point robot: one point.
    ``limit``: at most about that many vertices in all (:func:`decimate`), for a footprint drawn
    once per frame.

    >>> x, y = footprint(example_scene(), (1.0, 1.0), 3)
    >>> x
    [0.6, 1.4, 1.0, 0.6, None]
    """
    if scenario.is_point_robot:
        return [round(float(pose[0]), nd)], [round(float(pose[1]), nd)]
    th = float(pose[2]) if len(pose) > 2 else 0.0
    parts = scenario.robot_at(float(pose[0]), float(pose[1]), th)
    return rings_xy(parts if limit is None else decimate(parts, limit), nd)


def decimate(rings, limit: int) -> list:
    """Rings with every k-th vertex kept, k the least that brings the total to ``limit`` or below
    (at least 3 vertices a ring): a 22 000-gon disk drawn in a frame as a 250-gon, which the eye
    cannot tell apart. For the picture only: no check uses it.

    >>> [len(r) for r in decimate([np.zeros((1000, 2)), np.zeros((4, 2))], 100)]
    [91, 4]
    """
    rings = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rings]
    total = sum(len(r) for r in rings)
    if total <= limit:
        return rings
    k = -(-total // max(limit, 1))
    return [r if len(r) <= 3 * k else r[::k] for r in rings]


def robot_trace(name: str, scenario, pose, color: str, nd: int, *, fill: bool = True, dash: str | None = None,
                opacity: float = 0.6, limit: int | None = None) -> dict:
    """The robot's footprint at a pose as one trace (a marker for a point robot).

    >>> robot_trace("start", example_scene(), (1, 1), "#2a9d4b", 3)["fill"]
    'toself'
    """
    x, y = footprint(scenario, pose, nd, limit)
    if scenario.is_point_robot:
        return {"type": "scatter", "mode": "markers", "name": name, "x": x, "y": y,
                "marker": {"color": color, "size": 9}, "hoverinfo": "name+x+y"}
    return {"type": "scatter", "mode": "lines", "name": name, "x": x, "y": y, "fill": "toself" if fill else "none",
            "fillcolor": color if fill else None, "opacity": opacity, "hoverinfo": "name",
            "line": {"color": color, "width": 1.2, **({"dash": dash} if dash else {})}}


def path_traces(scenario, res, nd: int) -> tuple[list[dict], np.ndarray]:
    """The path's traces (a car's along its curves: forward solid, reverse dashed) and the
    dense poses the robot moves through (the footprint's frames pick from them).

    >>> import numpy as np
    >>> class R: path = np.array([[0., 0], [1, 0]])
    >>> traces, poses = path_traces(example_scene(), R(), 3)
    >>> traces[0]["name"], len(poses)
    ('path', 2)
    """
    path = np.asarray(res.path, dtype=np.float64)
    if scenario.turning_radius is None:
        x, y = line_xy(path[:, :2], nd)
        return [{"type": "scatter", "mode": "lines+markers", "name": "path", "x": x, "y": y,
                 "line": {"color": PATH, "width": 2}, "marker": {"size": 4}, "hoverinfo": "name+x+y"}], path
    from ...adapters.car import dense_curve

    xmin, xmax, ymin, ymax = scenario.bounds
    dense, rev = dense_curve(path, scenario.space, scenario.turning_radius, step=max(xmax - xmin, ymax - ymin) / 600)
    runs = {False: ([], []), True: ([], [])}
    cuts = [0] + [i for i in range(1, len(rev)) if rev[i] != rev[i - 1]] + [len(rev)]
    for a, b in zip(cuts[:-1], cuts[1:]):
        x, y = line_xy(dense[a:min(b + 1, len(dense)), :2], nd)
        xs, ys = runs[bool(rev[a])]
        xs += x + [None]
        ys += y + [None]
    out = [{"type": "scatter", "mode": "lines", "name": "path (forward)", "x": runs[False][0], "y": runs[False][1],
            "line": {"color": PATH, "width": 2}, "hoverinfo": "name+x+y"}]
    if runs[True][0]:
        out.append({"type": "scatter", "mode": "lines", "name": "path (reverse)", "x": runs[True][0],
                    "y": runs[True][1], "line": {"color": REVERSE, "width": 2, "dash": "dash"},
                    "hoverinfo": "name+x+y"})
    return out, dense


def closest_traces(scenario, res, nd: int) -> list[dict]:
    """The closest approach of a solved path: the robot there (outlined), a star on the obstacle's
    closest point, a dotted line to the robot's; no traces without a measured clearance.

    >>> class R: solved, min_clearance_obstacle = False, None
    >>> closest_traces(None, R(), 3)
    []
    """
    if not res.solved or not res.min_clearance_obstacle or not res.min_clearance_at:
        return []
    from cspace.kernel.distance.gjk import gjk_distance

    pose = tuple(res.min_clearance_at) + (0.0,) * (3 - len(res.min_clearance_at))
    ob = np.array(res.min_clearance_obstacle, dtype=np.float64)
    parts = scenario.robot_at(*pose[:3]) if not scenario.is_point_robot else [np.array(pose[:2])[None, :]]
    near = min((gjk_distance(p, ob[None, :]) for p in parts), key=lambda d: d.distance).point_a
    word = "≥" if res.min_clearance_bound == "lower" else "="
    label = f"closest approach: clearance {word} {res.min_clearance:.4g}"
    robot = robot_trace("robot at the closest approach", scenario, pose, CLOSEST, nd, fill=False, dash="dot",
                        opacity=1.0)
    x, y = line_xy([near, ob], nd)
    mark = {"type": "scatter", "mode": "lines+markers", "name": label, "x": x, "y": y,
            "line": {"color": CLOSEST, "width": 1.5, "dash": "dot"},
            "marker": {"symbol": ["circle", "star"], "size": [6, 16], "color": CLOSEST,
                       "line": {"color": "black", "width": 0.5}}, "hovertext": [label, label], "hoverinfo": "text"}
    return [robot, mark]


def start_goal_traces(scenario, res, nd: int) -> list[dict]:
    """The robot at the start (green) and at the goal (red).

    >>> class R: start, goal = (1.0, 1.0), (9.0, 9.0)
    >>> [t["name"] for t in start_goal_traces(example_scene(), R(), 3)]
    ['robot at start', 'robot at goal']
    """
    return [robot_trace("robot at start", scenario, res.start, ROBOT, nd),
            robot_trace("robot at goal", scenario, res.goal, GOAL, nd)]


def cobstacle_trace(pieces, nd: int, name: str = "C-obstacle (reference point there: collision)") -> dict:
    """C-obstacle pieces, shaded light beneath the obstacles, their convex pieces outlined.

    >>> cobstacle_trace([[[0, 0], [1, 0], [0, 1]]], 3)["fillcolor"]
    '#f2b8a0'
    """
    return filled(name, pieces, COBSTACLE, nd, line=PIECE_EDGE, opacity=0.9)


def obstacle_trace(scenario, nd: int) -> dict:
    """The workspace obstacles, dark.

    >>> obstacle_trace(example_scene(), 3)["name"]
    'obstacle'
    """
    return filled("obstacle", obstacle_rings(scenario), OBSTACLE, nd, opacity=0.85)


def proof_rings(slab: dict) -> list:
    """A proof slab's components (``{"shell", "holes"}``) as rings.

    >>> proof_rings({"components": [{"shell": [[0, 0], [1, 0], [0, 1]], "holes": []}]})
    [[[0, 0], [1, 0], [0, 1]]]
    """
    rings = []
    for comp in slab.get("components", []):
        rings.append(comp["shell"])
        rings += comp.get("holes", [])
    return rings


def proof_trace(rings, nd: int) -> dict:
    """A proof slab's POSSIBLE components (where the reference point may be free at some angle of it), green.

    >>> proof_trace([], 3)["x"]
    []
    """
    return filled("proof: the slab's POSSIBLE components (free at some angle, perhaps)", rings, PROOF, nd,
                  opacity=0.4, line="#1d4d33")


def gap_traces(gap, nd: int) -> list[dict]:
    """The narrowest gap the path crosses (:func:`cspace.paths.gap.narrowest_gap_of_paths`), as a
    segment from wall to wall, its width in the legend; none without such a gap.

    >>> gap_traces(None, 3)
    []
    """
    if gap is None:
        return []
    label = f"narrowest gap, {gap.width:.3g} wide"
    x, y = line_xy([np.asarray(gap.ends[0], dtype=np.float64), np.asarray(gap.ends[1], dtype=np.float64)], nd)
    return [{"type": "scatter", "mode": "lines+markers", "name": label, "x": x, "y": y,
             "line": {"color": GAP_COLOUR, "width": 2},
             "marker": {"symbol": "line-ns-open", "size": 10, "color": GAP_COLOUR},
             "hovertext": [label, label], "hoverinfo": "text"}]
