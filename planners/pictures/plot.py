"""Pictures of scenes and paths (matplotlib, imported only when a plot is asked for).

This module owns drawing: the workspace obstacles, the C-obstacles shaded lighter
beneath them, the path, and the robot at the start, the goal and a few poses along
the path. Every picture says what it shows without the guide: axis labels, a legend
built from :data:`LEGEND` (one entry per kind of thing drawn, in the same style as
the drawing), failed queries marked, and an inset zoom on a narrow passage.

Each picture has a ``figure_*`` function returning the matplotlib Figure (tests
inspect it) and a ``plot_*`` function that saves it atomically (temporary file,
then rename).
"""
from __future__ import annotations

import numpy as np

from ..output import atomic_path
from .titles import plan_title

OBSTACLE = "#3b3b3b"
COBSTACLE = "#f2b8a0"
PIECE_EDGE = "#c97c5d"
PATH = "#1f5fbf"
REVERSE = "#e07b00"  # orange, dashed: a car driving backwards
ROBOT = "#2a9d4b"
GOAL = "#c0392b"
FAILED = "#d6007a"  # magenta: apart from the goal's red and the path's blue
BOUNDS = "#888888"
GAP = "#7b2cbf"
CLOSEST = "#e67e00"  # the closest approach: orange, apart from every other colour

# A passage narrower than this fraction of the scene's size gets an inset zoom.
from cspace.paths.gap import GAP_FRACTION  # noqa: E402  (the pictures' threshold)


def mpl():
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["text.parse_math"] = False  # a scene's name is text, never mathtext ($...$)
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    return plt, PathPatch, Path


def poly_patch(poly, holes=(), **kw):
    """A matplotlib patch for a polygon with holes (even-odd fill)."""
    _, PathPatch, Path = mpl()
    verts, codes = [], []
    for ring in [poly, *holes]:
        ring = np.asarray(ring, dtype=float)
        verts += ring.tolist() + [ring[0].tolist()]
        codes += [Path.MOVETO] + [Path.LINETO] * (len(ring) - 1) + [Path.CLOSEPOLY]
    return PathPatch(Path(verts, codes), **kw)


# ---------------------------------------------------------------- legend

def _patch(**kw):
    from matplotlib.patches import Patch

    return Patch(**kw)


def _line(**kw):
    from matplotlib.lines import Line2D

    return Line2D([], [], **kw)


# Legend entries by key: (label, proxy artist factory). The factories take the robot
# kind, since a point robot is drawn as a dot and a polygon robot as its outline.
LEGEND = {
    "bounds": ("bounds", lambda point: _line(color=BOUNDS, lw=0.8, ls="--")),
    "obstacle": ("obstacle", lambda point: _patch(facecolor=OBSTACLE, alpha=0.85)),
    "cobstacle": ("C-obstacle (reference point there: collision)",
                  lambda point: _patch(facecolor=COBSTACLE, alpha=0.9)),
    "pieces": ("C-obstacle, convex pieces outlined",
               lambda point: _patch(facecolor=COBSTACLE, edgecolor=PIECE_EDGE, lw=0.6, alpha=0.9)),
    "outlines": ("convex pieces (point robot: C-obstacle = obstacle)",
                 lambda point: _patch(facecolor="none", edgecolor=PIECE_EDGE, lw=0.8)),
    "start": ("robot at start", lambda point: _robot_proxy(point, ROBOT)),
    "goal": ("robot at goal", lambda point: _robot_proxy(point, GOAL)),
    "query_start": ("query start", lambda point: _robot_proxy(point, ROBOT)),
    "query_goal": ("query goal", lambda point: _robot_proxy(point, GOAL)),
    "along": ("robot along the path", lambda point: _robot_proxy(point, PATH, fill=False, alpha=0.4)),
    "path": ("path", lambda point: _line(color=PATH, lw=1.4)),
    "reverse": ("path driven in reverse", lambda point: _line(color=REVERSE, lw=1.6, ls="--")),
    "failed": ("no path found (start to goal)",
               lambda point: _line(color=FAILED, lw=2.0, ls="--", marker="x", ms=8, mew=2.0)),
    "gap": ("narrowest gap (zoomed)", lambda point: _line(color=GAP, lw=1.5, marker="|", ms=6)),
    "closest": ("closest approach (min clearance)",
                lambda point: _line(color=CLOSEST, lw=1.2, ls=":", marker="*", ms=9)),
    "margin": ("robot with its safety margin", lambda point: _line(color=CLOSEST, lw=0.9, ls="--")),
}


def _robot_proxy(point: bool, color: str, fill: bool = True, alpha: float = 0.6):
    if point:
        return _line(color=color, marker="o", ls="none", ms=5)
    return _patch(facecolor=color if fill else "none", edgecolor=color, alpha=alpha, lw=0.8)


def legend_handles(keys, point_robot: bool = False, labels: dict | None = None) -> list:
    """Proxy artists for the legend entries ``keys`` (of :data:`LEGEND`), in that order.

    ``labels`` overrides a label (``{"path": "path (length 3.2)"}``).

    >>> [h.get_label() for h in legend_handles(["obstacle", "path"], labels={"path": "path, length 2"})]
    ['obstacle', 'path, length 2']
    """
    out = []
    for k in keys:
        label, make = LEGEND[k]
        h = make(point_robot)
        h.set_label((labels or {}).get(k, label))
        out.append(h)
    return out


def add_legend(ax, handles: list, ncol: int = 3) -> None:
    """The legend below the axis, outside the scene, so that it never hides a path."""
    # Anchored a fixed distance (in font sizes) below the axis: clear of the tick labels and
    # the x label whatever the scene's aspect.
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), borderaxespad=4.0, ncol=ncol,
              fontsize=8, frameon=False, handlelength=2.2, columnspacing=1.2)


# ---------------------------------------------------------------- drawing

def draw_scene(ax, scenario, cspace=None, pieces_edges: bool = False) -> list[str]:
    """Bounds, C-obstacles (lighter, beneath) and obstacles on a matplotlib axis.

    Returns the legend keys of what was drawn.
    """
    xmin, xmax, ymin, ymax = scenario.bounds
    ax.add_patch(poly_patch([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]],
                             fill=False, edgecolor=BOUNDS, linewidth=0.8, linestyle="--"))
    keys = ["bounds", "obstacle"]
    if cspace is not None and not scenario.is_point_robot:
        for p in cspace.pieces:
            ax.add_patch(poly_patch(p, facecolor=COBSTACLE, edgecolor=PIECE_EDGE if pieces_edges else "none",
                                     linewidth=0.3, alpha=0.9))
        keys.append("pieces" if pieces_edges else "cobstacle")
    elif cspace is not None and pieces_edges:
        for p in cspace.pieces:
            ax.add_patch(poly_patch(p, fill=False, edgecolor=PIECE_EDGE, linewidth=0.3))
        keys.append("outlines")
    for ob in scenario.obstacles:
        ax.add_patch(poly_patch(ob.polygon, ob.holes, facecolor=OBSTACLE, edgecolor="none", alpha=0.85))
    return keys


def draw_robot(ax, scenario, x: float, y: float, theta: float = 0.0, color=ROBOT, alpha=0.5, fill=True) -> None:
    """The robot's parts with the reference point at (x, y), turned by theta (SE(2))."""
    if scenario.is_point_robot:
        ax.plot([x], [y], "o", color=color, markersize=5)
        return
    for part in scenario.robot_at(x, y, theta):
        ax.add_patch(poly_patch(part, facecolor=color if fill else "none", edgecolor=color,
                                 alpha=alpha, linewidth=0.8))
    ax.plot([x], [y], ".", color=color, markersize=3)


def draw_closest(ax, scenario, res) -> list[str]:
    """The closest approach of a solved path: the robot there (with its margin, dashed, if
    the plan kept one), a star on the obstacle's closest point, a dotted line to the
    robot's, and the clearance written beside it. Returns the legend keys drawn."""
    if not res.solved or not res.min_clearance_obstacle or not res.min_clearance_at:
        return []
    from cspace.kernel.distance.gjk import gjk_distance

    pose = tuple(res.min_clearance_at) + (0.0,) * (3 - len(res.min_clearance_at))
    x, y, th = pose[:3]
    ob = np.array(res.min_clearance_obstacle, dtype=np.float64)
    parts = scenario.robot_at(x, y, th) if not scenario.is_point_robot else [np.array([[x, y]])]
    near = min((gjk_distance(p, ob[None, :]) for p in parts), key=lambda d: d.distance).point_a
    keys = ["closest"]
    draw_robot(ax, scenario, x, y, th, color=CLOSEST, alpha=0.8, fill=False)
    from .grown import grown_robot

    grown = grown_robot(scenario, x, y, th)  # non-convex robots too: the union of the pieces' sums
    for shell, holes in grown:
        ax.add_patch(poly_patch(shell, holes, facecolor="none", edgecolor=CLOSEST, linewidth=0.9, ls="--"))
    keys += ["margin"] if grown else []
    ax.plot([near[0], ob[0]], [near[1], ob[1]], ":", color=CLOSEST, linewidth=1.2)
    ax.plot([ob[0]], [ob[1]], "*", color=CLOSEST, markersize=11, markeredgecolor="black", markeredgewidth=0.4)
    word = "≥" if res.min_clearance_bound == "lower" else "="
    ax.annotate(f"clearance {word} {res.min_clearance:.3g}", ob, xytext=(6, 6), textcoords="offset points",
                fontsize=8, color="black", bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": CLOSEST,
                                                 "alpha": 0.9})
    return keys


def _poses(path: np.ndarray, k: int) -> np.ndarray:
    """k poses spaced evenly by arc length along a polyline (ends excluded)."""
    seg = np.hypot(*np.diff(path, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] == 0.0:
        return np.zeros((0, 2))
    targets = s[-1] * np.arange(1, k + 1) / (k + 1)
    return np.column_stack([np.interp(targets, s, path[:, 0]), np.interp(targets, s, path[:, 1])])


def draw_failed(ax, start, goal, label: str | None = None) -> None:
    """A query without a path: a dashed line from start to goal, crosses at both ends, drawn
    on top of everything with a white halo so that it stands out among many paths."""
    from matplotlib import patheffects

    halo = [patheffects.withStroke(linewidth=4, foreground="white")]
    xs, ys = [start[0], goal[0]], [start[1], goal[1]]
    ax.plot(xs, ys, "--", color=FAILED, lw=2.0, zorder=7, path_effects=halo)
    ax.plot(xs, ys, "x", color=FAILED, ms=10, mew=2.5, zorder=8, path_effects=halo)
    if label:
        ax.annotate(label, (start[0], start[1]), xytext=(6, 6), textcoords="offset points", color=FAILED,
                    fontsize=8, fontweight="bold", zorder=8,
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": FAILED, "lw": 0.8})


def _draw_queries(ax, sc, results: list, poses: int) -> list[str]:
    """Paths, robots at start and goal, failed queries; returns the legend keys drawn."""
    single = len(results) == 1
    keys: list[str] = []
    se2 = sc.rotates
    for i, r in enumerate(results):
        if r.solved and len(r.path) and sc.turning_radius is not None:
            keys += _draw_car_path(ax, sc, r.path, 3 * poses + 2 if single else 0)
        elif r.solved and len(r.path) and se2:
            # A rotating robot: its footprint at poses spaced along the path, moved as
            # the planner's motions move it (OMPL's SE(2) interpolation), so it is seen to turn.
            from .poses import poses_along

            along = poses_along(r.path, 3 * poses + 2 if single else 0)[1:-1]
            for q in along:
                draw_robot(ax, sc, q[0], q[1], q[2], color=PATH, alpha=0.35, fill=False)
            keys += ["along"] if len(along) else []
            ax.plot(r.path[:, 0], r.path[:, 1], "-", color=PATH, linewidth=1.4)
            keys.append("path")
        elif r.solved and len(r.path):
            along = _poses(r.path, poses if single else 0)
            for q in along:
                draw_robot(ax, sc, q[0], q[1], color=PATH, alpha=0.25, fill=False)
            keys += ["along"] if len(along) else []
            ax.plot(r.path[:, 0], r.path[:, 1], "-", color=PATH, linewidth=1.4)
            keys.append("path")
        else:
            draw_failed(ax, r.start, r.goal, label=None if single else f"query {i}")
            keys.append("failed")
        draw_robot(ax, sc, *r.start[:3], color=ROBOT, alpha=0.6)
        draw_robot(ax, sc, *r.goal[:3], color=GOAL, alpha=0.6)
    keys += ["start", "goal"] if single else ["query_start", "query_goal"]
    order = ["start", "goal", "query_start", "query_goal", "along", "path", "reverse", "failed"]
    return [k for k in order if k in keys]


def _draw_car_path(ax, sc, path: np.ndarray, count: int) -> list[str]:
    """A car's path drawn along its curves (forward solid, reverse dashed), with its
    footprint at ``count`` poses spaced along them; returns the legend keys drawn."""
    from ..adapters.car import dense_curve

    xmin, xmax, ymin, ymax = sc.bounds
    poses, rev = dense_curve(path, sc.space, sc.turning_radius, step=max(xmax - xmin, ymax - ymin) / 400)
    keys = []
    if count and len(poses) > 2:
        for q in poses[np.linspace(0, len(poses) - 1, count).round().astype(int)[1:-1]]:
            draw_robot(ax, sc, q[0], q[1], q[2], color=PATH, alpha=0.35, fill=False)
        keys.append("along")
    # Runs of poses in one gear, each drawn as one line (joined to the next run's first pose).
    cuts = [0] + [i for i in range(1, len(rev)) if rev[i] != rev[i - 1]] + [len(rev)]
    for a, b in zip(cuts[:-1], cuts[1:]):
        seg = poses[a:min(b + 1, len(poses))]
        if rev[a]:
            ax.plot(seg[:, 0], seg[:, 1], "--", color=REVERSE, linewidth=1.6)
            keys.append("reverse")
        else:
            ax.plot(seg[:, 0], seg[:, 1], "-", color=PATH, linewidth=1.4)
            keys.append("path")
    return keys


def frame_axes(ax, bounds) -> None:
    """Axes on the bounds, with a 2 % margin, at equal scale, labelled."""
    xmin, xmax, ymin, ymax = bounds
    pad = 0.02 * max(xmax - xmin, ymax - ymin)
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(ymin - pad, ymax + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")


def _new_figure(sc, wide: bool = False):
    """A figure sized to the scene's aspect, with room below for the legend (and beside it for a zoom)."""
    plt = mpl()[0]
    (xmin, xmax, ymin, ymax) = sc.bounds
    return plt.subplots(figsize=(7 + 3.5 * wide, 7 * (ymax - ymin) / (xmax - xmin) + 1.4))


# ---------------------------------------------------------------- narrow passages

def narrow_gap(sc, cspace, results: list):
    """The narrowest gap along the solved paths when under :data:`GAP_FRACTION` of the scene, else None
    (:func:`cspace.paths.gap.narrowest_gap_of_paths`)."""
    from cspace.paths.gap import narrowest_gap_of_paths

    if cspace is None:
        return None
    return narrowest_gap_of_paths(cspace.pieces, cspace.bounds, [r.path for r in results if r.solved],
                                  GAP_FRACTION)


def draw_inset(ax, sc, cspace, results: list, gap) -> object:
    """An inset axis zoomed on ``gap``, beside ``ax`` (so it hides nothing); returns the inset."""
    xmin, xmax, ymin, ymax = sc.bounds
    size = max(xmax - xmin, ymax - ymin)
    cx, cy = gap.center
    half = max(3.0 * gap.width, 1e-4 * size)
    # To the right of the scene, level with the gap as far as it fits.
    fy = min(max((cy - ymin) / (ymax - ymin) - 0.25, 0.0), 0.5)
    ins = ax.inset_axes([1.06, fy, 0.5, 0.5])
    draw_scene(ins, sc, cspace)
    for r in results:
        if r.solved and len(r.path):
            ins.plot(r.path[:, 0], r.path[:, 1], "-", color=PATH, linewidth=1.4)
    (ax0, ay0), (ax1, ay1) = gap.ends
    ins.plot([ax0, ax1], [ay0, ay1], "-", color=GAP, lw=1.5, marker="|", ms=8)
    ins.set_xlim(cx - half, cx + half)
    ins.set_ylim(cy - half, cy + half)
    ins.set_aspect("equal")
    ins.set_xticks([])
    ins.set_yticks([])
    ins.set_facecolor("white")
    zoom = size / (2 * half)
    ins.set_title(f"zoom x{zoom:,.0f}: gap {gap.width:.3g}\n({100 * gap.width / size:.2g} % of the scene)",
                  fontsize=8, pad=3)
    ax.indicate_inset_zoom(ins, edgecolor=GAP, alpha=0.8)
    return ins


# ---------------------------------------------------------------- the pictures

def figure_result(res, scenario=None, cspace=None, poses: int = 4):
    """The Figure of a plan result (one query, or every query of ``--all-queries``)."""
    from cspace.translation.cspace import CSpace

    sc = scenario or res.scenario_data
    if sc is None:
        raise ValueError("plot_result needs the scenario (pass scenario=...)")
    # In SE(2) the C-obstacles depend on the angle: the picture shows the workspace and
    # the robot's footprint along the path (cspace show --space se2 --theta draws a slab).
    cs = None if sc.rotates else (cspace or res.cspace or CSpace.from_scenario(sc))
    results = res.queries or [res]
    gap = narrow_gap(sc, cs, results)
    fig, ax = _new_figure(sc, wide=gap is not None)
    keys = draw_scene(ax, sc, cs)
    keys += _draw_queries(ax, sc, results, poses)
    if len(results) == 1:
        keys += draw_closest(ax, sc, res)
    frame_axes(ax, sc.bounds)
    labels = {}
    if len(results) == 1 and res.min_clearance is not None and "closest" in keys:
        labels["closest"] = f"closest approach (clearance {res.min_clearance:.3g})"
        if sc.clearance > 0:
            labels["margin"] = f"robot with its safety margin {sc.clearance:g}"
    if len(results) == 1:
        ax.set_title(plan_title(sc.name, res))
        if res.solved:
            labels["path"] = f"path (length {res.length:.4g})"
    else:
        n = sum(r.solved for r in results)
        ax.set_title(f"{sc.name}: {res.planner}, {n}/{len(results)} queries solved")
        labels["path"] = f"paths ({_count(n, 'query', 'queries')})"
        labels["failed"] = f"no path found ({_count(len(results) - n, 'query', 'queries')}, start to goal)"
    if gap is not None:
        draw_inset(ax, sc, cs, results, gap)
        keys.append("gap")
        labels["gap"] = f"narrowest gap, {gap.width:.3g} wide (zoomed)"
    add_legend(ax, legend_handles(keys, sc.is_point_robot, labels))
    return fig


def _count(n: int, one: str, many: str) -> str:
    """'1 query', '3 queries'."""
    return f"{n} {one if n == 1 else many}"


def plot_result(res, out: str, fmt: str | None = None, scenario=None, cspace=None, poses: int = 4) -> None:
    """Save a picture of a plan result (PNG, SVG or PDF by ``fmt`` or extension)."""
    save(figure_result(res, scenario=scenario, cspace=cspace, poses=poses), out, fmt)


def figure_scene(scenario, cspace, theta: float | None = None, title: str | None = None):
    """The Figure of a scene: workspace, C-obstacles and their convex pieces, start and goal.

    In SE(2) ``cspace`` is one angle slab's C-space and ``theta`` the angle at which the
    robot is drawn at the start and the goal."""
    sc = scenario
    fig, ax = _new_figure(sc)
    keys = draw_scene(ax, sc, cspace, pieces_edges=True)
    th = () if theta is None else (theta,)
    draw_robot(ax, sc, *sc.start[:2], *th, color=ROBOT, alpha=0.6)
    draw_robot(ax, sc, *sc.goal[:2], *th, color=GOAL, alpha=0.6)
    frame_axes(ax, sc.bounds)
    ax.set_title(title or f"{sc.name}: {len(sc.obstacles)} obstacles, {len(cspace.pieces)} C-obstacle pieces")
    add_legend(ax, legend_handles(keys + ["start", "goal"], sc.is_point_robot))
    return fig


def plot_scene(scenario, cspace, out: str, fmt: str | None = None, theta: float | None = None,
               title: str | None = None) -> None:
    """Save a picture of the workspace, the C-obstacles and their convex pieces."""
    save(figure_scene(scenario, cspace, theta=theta, title=title), out, fmt)


def save(fig, out: str, fmt: str | None = None) -> None:
    """Write a figure atomically (format from ``fmt`` or the extension) and close it."""
    import os

    plt = mpl()[0]
    fmt = fmt or os.path.splitext(out)[1].lstrip(".").lower() or "png"
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format=fmt, dpi=130, bbox_inches="tight", pad_inches=0.1)
    plt.close(fig)


_save = save  # the older private name
