"""Bench-MR's results format: written from our plans (``cspace plan --bench-mr-json``), read back and
re-checked exactly (``cspace recheck``), whoever planned the paths.

The format, as Bench-MR's ``Log`` writes it and its ``python/plot_stats.py`` reads it::

    {"settings": {"env": {"collision": {"collision_model": 1, "robot_shape": [[x, y], ...]}, ...},
                  "steer": {"car_turning_radius": r, ...}, ...},
     "runs": [{"environment": {"type": "polygon", "obstacles": [[[x, y], ...], ...],
                               "start": [x, y, theta], "goal": [...], "min_x": ..., ...},
               "plans": {PLANNER: {"path": [[x, y, theta], ...], "trajectory": [...],
                                   "stats": {"path_found": ..., "path_collides": ..., ...}}}}]}

with the steer function in ``settings.steering`` (``"reeds_shepp"``, ``"dubins"``, ``"linear"``,
...). What we add is ignored by its readers: ``holes`` beside an environment's obstacles,
``robot_parts`` beside the robot shape (several convex or non-convex parts).

:func:`recheck` puts the run's robot (its ``robot_shape``, turned about the origin as Bench-MR turns
it) along every path of every plan that found one, motion by motion between the path's
waypoints along the steer function's curve (Reeds–Shepp, Dubins: the certified curve check of
:class:`cspace.car.motion.CarCSpace`; ``linear``: the certified SE(2) motion), and reports per
planner how many paths it called collision-free collide, with the first colliding pose.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

STEERING = {"reeds-shepp": "reeds_shepp", "dubins": "dubins", "se2": "linear", "translation": "linear"}
CURVES = {"reeds_shepp": "reeds-shepp", "dubins": "dubins"}


def results_document(res, planner_label: str | None = None) -> dict:
    """A plan (and its queries: one run each) in Bench-MR's results format."""
    from .benchmr import interpolated, result_metrics

    sc = res.scenario_data
    steering = STEERING.get(sc.space, "linear")
    robot = [np.asarray(r.polygon, float).tolist() for r in sc.robot] or [[[0.0, 0.0]]]
    settings = {"env": {"collision": {"collision_model": 1 if sc.robot else 0, "robot_shape": robot[0],
                                      "robot_parts": robot},
                        "type": "polygon"},
                "steer": {"car_turning_radius": sc.turning_radius}, "steering": steering,
                "exact_goal_radius": 1e-2, "interpolation_limit": 500}
    xmin, xmax, ymin, ymax = sc.bounds
    env = {"type": "polygon", "name": sc.name,
           "obstacles": [np.asarray(o.polygon, float).tolist() for o in sc.obstacles],
           "holes": [[np.asarray(h, float).tolist() for h in o.holes] for o in sc.obstacles],
           "min_x": xmin, "max_x": xmax, "min_y": ymin, "max_y": ymax, "width": xmax - xmin, "height": ymax - ymin}
    runs = []
    name = planner_label or f"cspace_{res.planner}"
    for r in (res.queries or [res]):
        m = result_metrics(r, sc) if r.solved else None
        path = np.asarray(r.path, float) if r.solved else np.zeros((0, 3))
        traj = interpolated(path, sc.space, sc.turning_radius, sc.bounds) if r.solved else path
        if path.shape[1] == 2:  # a translating robot: its shape is written turned, its heading 0 throughout
            path, traj = (np.column_stack((a, np.zeros(len(a)))) for a in (path, traj))
        stats = {"path_found": bool(r.solved), "path_collides": False if r.solved else None,
                 "exact_goal_path": bool(m and m["exact_goal_path"]), "planner": name,
                 "planning_time": r.timings.get("solve", 0.0)}
        if m:
            stats.update({k: m[k] for k in ("path_length", "max_curvature", "normalized_curvature", "aol")})
            stats["cusps"] = m["cusp_points"]
            stats["certified"], stats["min_clearance"] = True, m["min_clearance"]
        else:
            stats.update(path_length=None, max_curvature=None, normalized_curvature=None, aol=None, cusps=[])
        runs.append({"environment": dict(env, start=list(r.start), goal=list(r.goal)),
                     "plans": {name: {"path": path.tolist(), "trajectory": traj.tolist(), "stats": stats}}})
    return {"globals": {"writer": "cspace"}, "settings": settings, "runs": runs}


def read_results(path: str) -> dict:
    """A results file, parsed (one-line :class:`InputError` naming the file and the field)."""
    import json

    from cspace.io.scenario.files import read_input

    raw = read_input(path)
    try:
        doc = json.loads(raw.decode("utf-8-sig"))
    except (UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise InputError(path, "file", f"not a JSON results file ({str(exc)[:100]})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("runs"), list):
        raise InputError(path, "runs", "missing: a Bench-MR results file has a list of runs")
    return doc


def _polygon(value, path: str, field: str, least: int = 3) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = np.zeros((0, 0))
    if a.ndim != 2 or a.shape[1] != 2 or len(a) < least or not np.isfinite(a).all() or np.abs(a).max() > 1e12:
        raise InputError(path, field, f"expected a list of at least {least} finite points [x, y]")
    return a


def _poses(value, path: str, field: str) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = np.zeros((0, 0))
    if a.ndim != 2 or a.shape[1] < 3 or not np.isfinite(a[:, :3]).all() or (len(a) and np.abs(a).max() > 1e12):
        raise InputError(path, field, "expected a list of states [x, y, theta]")
    return a[:, :3]


def recheck(doc: dict, path: str, steering: str | None = None) -> list[dict]:
    """Per run and planner: ``{run, planner, paths, called_free, colliding, first_colliding}``;
    ``first_colliding`` is the pose a colliding path's first failing motion starts from."""
    settings = doc.get("settings") if isinstance(doc.get("settings"), dict) else {}
    coll = (settings.get("env") or {}).get("collision") or {}
    parts = coll.get("robot_parts") or [coll.get("robot_shape")]
    steer = steering or settings.get("steering") or "linear"
    radius = (settings.get("steer") or {}).get("car_turning_radius")
    kind = CURVES.get(steer)
    if kind is not None and not (isinstance(radius, (int, float)) and 0 < radius < 1e12):
        raise InputError(path, "settings.steer.car_turning_radius", f"a positive radius for {steer}, got {radius!r}")
    robot = [_polygon(p, path, "settings.env.collision.robot_shape") for p in parts] \
        if coll.get("collision_model", 1) else []
    runs = []
    for i, run in enumerate(doc["runs"]):
        if not isinstance(run, dict) or not isinstance(run.get("plans"), dict):
            raise InputError(path, f"runs[{i}]", "a run has an environment and plans")
        runs.append(_read_run(run, i, path))
    # One C-space per distinct environment (a results file repeats its world in every run), its
    # bounds holding every run's obstacles and paths, grown by the robot's reach and two radii.
    reach = max((float(np.hypot(*r.T).max()) for r in robot), default=0.0) + 2 * float(radius or 0.0) + 1.0
    boxes: dict = {}
    for obstacles, holes, plans, key in runs:
        pts = np.concatenate([o for o in obstacles] + [p[:, :2] for p, _ in plans.values()] or [np.zeros((0, 2))])
        if len(pts):
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            old = boxes.get(key)
            boxes[key] = (lo, hi) if old is None else (np.minimum(old[0], lo), np.maximum(old[1], hi))
    spaces: dict = {}
    out = []
    for i, (obstacles, holes, plans, key) in enumerate(runs):
        if key not in boxes:
            continue
        if key not in spaces:
            spaces[key] = _cspace(obstacles, holes, robot, boxes[key], reach, path, i)
        out += _check_plans(spaces[key], plans, i, kind, radius)
    return out


def _read_run(run: dict, i: int, path: str):
    """A run's obstacles, holes and solved plans ``{name: (poses, stats)}``, and its environment's
    identity (its obstacles' and holes' floats: runs of one world share a C-space)."""
    env = run.get("environment") or {}
    if env.get("type", "polygon") != "polygon":
        raise InputError(path, f"runs[{i}].environment.type", f"{env.get('type')!r}: only polygon environments "
                                                              "are re-checked (a grid's cells are not stored)")
    obstacles = [_polygon(o, path, f"runs[{i}].environment.obstacles[{j}]") for j, o in
                 enumerate(env.get("obstacles") or [])]
    holes = env.get("holes") or [[] for _ in obstacles]
    if not isinstance(holes, list) or len(holes) != len(obstacles):
        raise InputError(path, f"runs[{i}].environment.holes", "one list of holes per obstacle")
    holes = [[_polygon(h, path, f"runs[{i}].environment.holes[{j}]") for h in hs] for j, hs in enumerate(holes)]
    plans = {}
    for name, plan in run["plans"].items():
        stats = plan.get("stats") or {}
        if stats.get("path_found") and plan.get("path"):
            plans[name] = (_poses(plan["path"], path, f"runs[{i}].plans.{name}.path"), stats)
    key = (tuple(o.tobytes() + b"|" + str(o.shape).encode() for o in obstacles),
           tuple(tuple(h.tobytes() + b"|" + str(h.shape).encode() for h in hs) for hs in holes))
    return obstacles, holes, plans, key


def _cspace(obstacles, holes, robot, box, reach: float, path: str, i: int):
    from cspace.car.motion import CarCSpace

    lo, hi = box[0] - reach, box[1] + reach
    try:
        return CarCSpace((lo[0], hi[0], lo[1], hi[1]), obstacles, robot or None, obstacle_holes=holes)
    except (ValueError, TypeError) as exc:
        raise InputError(path, f"runs[{i}].environment", f"not a polygon scene cspace reads ({str(exc)[:100]})"
                         ) from None


def _check_plans(cs, plans: dict, i: int, kind: str | None, radius) -> list[dict]:
    """Each plan's path along its curves: the first colliding pose, or None."""
    out = []
    for name, (poses, stats) in plans.items():
        first = None
        for a, b in zip(poses[:-1], poses[1:]):
            a, b = tuple(map(float, a)), tuple(map(float, b))
            ok = cs.car_motion_free(a, b, kind, float(radius)) if kind else cs.motion_free(a, b)
            if not ok:
                first = list(a)
                break
        if len(poses) == 1 and not cs.is_free(tuple(map(float, poses[0]))):
            first = poses[0].tolist()
        out.append({"run": i, "planner": name, "paths": 1, "called_free": int(stats.get("path_collides") is False),
                    "colliding": int(first is not None), "first_colliding": first})
    return out


def per_planner(rows: list[dict]) -> dict:
    """The recheck rows summed per planner.

    >>> per_planner([{"planner": "a", "paths": 1, "called_free": 1, "colliding": 1, "first_colliding": [1, 2, 0],
    ...               "run": 0}])["a"]["called_free_colliding"]
    1
    """
    out: dict[str, dict] = {}
    for r in rows:
        d = out.setdefault(r["planner"], {"paths": 0, "called_free": 0, "colliding": 0, "called_free_colliding": 0,
                                          "first": None})
        d["paths"] += r["paths"]
        d["called_free"] += r["called_free"]
        d["colliding"] += r["colliding"]
        d["called_free_colliding"] += r["colliding"] and r["called_free"]
        if r["colliding"] and d["first"] is None:
            d["first"] = {"run": r["run"], "pose": r["first_colliding"]}
    return out

