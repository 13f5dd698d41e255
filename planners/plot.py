"""Pictures of scenes and paths (matplotlib, imported only when a plot is asked for).

This module owns drawing: the workspace obstacles, the C-obstacles shaded lighter
beneath them, the path, and the robot at the start, the goal and a few poses along
the path. Files are written atomically (temporary file, then rename).
"""
from __future__ import annotations

import numpy as np

from .output import atomic_path

OBSTACLE = "#3b3b3b"
COBSTACLE = "#f2b8a0"
PIECE_EDGE = "#c97c5d"
PATH = "#1f5fbf"
ROBOT = "#2a9d4b"


def _mpl():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    return plt, PathPatch, Path


def _poly_patch(poly, holes=(), **kw):
    """A matplotlib patch for a polygon with holes (even-odd fill)."""
    _, PathPatch, Path = _mpl()
    verts, codes = [], []
    for ring in [poly, *holes]:
        ring = np.asarray(ring, dtype=float)
        verts += ring.tolist() + [ring[0].tolist()]
        codes += [Path.MOVETO] + [Path.LINETO] * (len(ring) - 1) + [Path.CLOSEPOLY]
    return PathPatch(Path(verts, codes), **kw)


def draw_scene(ax, scenario, cspace=None, pieces_edges: bool = False) -> None:
    """Bounds, C-obstacles (lighter, beneath) and obstacles on a matplotlib axis."""
    xmin, xmax, ymin, ymax = scenario.bounds
    ax.add_patch(_poly_patch([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]],
                             fill=False, edgecolor="#888888", linewidth=0.8, linestyle="--"))
    if cspace is not None and not scenario.is_point_robot:
        for p in cspace.pieces:
            ax.add_patch(_poly_patch(p, facecolor=COBSTACLE, edgecolor=PIECE_EDGE if pieces_edges else "none",
                                     linewidth=0.3, alpha=0.9))
    elif cspace is not None and pieces_edges:
        for p in cspace.pieces:
            ax.add_patch(_poly_patch(p, fill=False, edgecolor=PIECE_EDGE, linewidth=0.3))
    for ob in scenario.obstacles:
        ax.add_patch(_poly_patch(ob.polygon, ob.holes, facecolor=OBSTACLE, edgecolor="none", alpha=0.85))


def draw_robot(ax, scenario, x: float, y: float, theta: float = 0.0, color=ROBOT, alpha=0.5, fill=True) -> None:
    """The robot's parts with the reference point at (x, y), turned by theta (SE(2))."""
    if scenario.is_point_robot:
        ax.plot([x], [y], "o", color=color, markersize=5)
        return
    for part in scenario.robot_at(x, y, theta):
        ax.add_patch(_poly_patch(part, facecolor=color if fill else "none", edgecolor=color,
                                 alpha=alpha, linewidth=0.8))
    ax.plot([x], [y], ".", color=color, markersize=3)


def _poses(path: np.ndarray, k: int) -> np.ndarray:
    """k poses spaced evenly by arc length along a polyline (ends excluded)."""
    seg = np.hypot(*np.diff(path, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] == 0.0:
        return np.zeros((0, 2))
    targets = s[-1] * np.arange(1, k + 1) / (k + 1)
    return np.column_stack([np.interp(targets, s, path[:, 0]), np.interp(targets, s, path[:, 1])])


def plot_result(res, out: str, fmt: str | None = None, scenario=None, cspace=None, poses: int = 4) -> None:
    """Save a picture of a plan result (PNG, SVG or PDF by ``fmt`` or extension)."""
    from cspace.cspace import CSpace

    plt = _mpl()[0]
    sc = scenario or res.scenario_data
    if sc is None:
        raise ValueError("plot_result needs the scenario (pass scenario=...)")
    se2 = sc.space == "se2"
    # In SE(2) the C-obstacles depend on the angle: the picture shows the workspace and
    # the robot's footprint along the path instead.
    cs = None if se2 else (cspace or res.cspace or CSpace.from_scenario(sc))
    fig, ax = plt.subplots(figsize=(7, 7 * (sc.bounds[3] - sc.bounds[2]) / (sc.bounds[1] - sc.bounds[0]) + 0.6))
    draw_scene(ax, sc, cs)
    results = res.queries or [res]
    for r in results:
        if r.solved and len(r.path) and se2:
            from .animate import poses_along

            for q in poses_along(r.path, 14 if len(results) == 1 else 0)[1:-1]:
                draw_robot(ax, sc, *q, color=PATH, alpha=0.35, fill=False)
            ax.plot(r.path[:, 0], r.path[:, 1], "-", color=PATH, linewidth=1.4)
        elif r.solved and len(r.path):
            for q in _poses(r.path, poses if len(results) == 1 else 0):
                draw_robot(ax, sc, q[0], q[1], color=PATH, alpha=0.25, fill=False)
            ax.plot(r.path[:, 0], r.path[:, 1], "-", color=PATH, linewidth=1.4)
        draw_robot(ax, sc, *r.start, color=ROBOT, alpha=0.6)
        draw_robot(ax, sc, *r.goal, color="#c0392b", alpha=0.6)
    _frame(ax, sc.bounds)
    if len(results) == 1:
        status = f"length {res.length:.4g}" if res.solved else "not solved"
        ax.set_title(f"{sc.name}: {res.planner}, seed {res.seed}, {status}")  # no wall time: same plan, same picture
    else:
        n = sum(r.solved for r in results)
        ax.set_title(f"{sc.name}: {res.planner}, {n}/{len(results)} queries solved")
    _save(fig, out, fmt)


def _frame(ax, bounds) -> None:
    """Axes on the bounds, with a 2 % margin, at equal scale."""
    xmin, xmax, ymin, ymax = bounds
    pad = 0.02 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")


def plot_scene(scenario, cspace, out: str, fmt: str | None = None, theta: float | None = None,
               title: str | None = None) -> None:
    """Save a picture of the workspace, the C-obstacles and their convex pieces.

    In SE(2) ``cspace`` is one angle slab's C-space and ``theta`` the angle at which the
    robot is drawn at the start and the goal."""
    plt = _mpl()[0]
    sc = scenario
    fig, ax = plt.subplots(figsize=(7, 7 * (sc.bounds[3] - sc.bounds[2]) / (sc.bounds[1] - sc.bounds[0]) + 0.6))
    draw_scene(ax, sc, cspace, pieces_edges=True)
    if theta is None:
        draw_robot(ax, sc, *sc.start, color=ROBOT, alpha=0.6)
        draw_robot(ax, sc, *sc.goal, color="#c0392b", alpha=0.6)
    else:
        draw_robot(ax, sc, sc.start[0], sc.start[1], theta, color=ROBOT, alpha=0.6)
        draw_robot(ax, sc, sc.goal[0], sc.goal[1], theta, color="#c0392b", alpha=0.6)
    _frame(ax, sc.bounds)
    ax.set_title(title or f"{sc.name}: {len(sc.obstacles)} obstacles, {len(cspace.pieces)} C-obstacle pieces")
    _save(fig, out, fmt)


def _save(fig, out: str, fmt: str | None) -> None:
    import os

    plt = _mpl()[0]
    fmt = fmt or os.path.splitext(out)[1].lstrip(".").lower() or "png"
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format=fmt, dpi=130)
    plt.close(fig)
