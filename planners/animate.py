"""Poses along a path, and an animation of the robot moving along it (GIF, via Pillow).

This module owns "where is the robot along a path": :func:`poses_along` spaces poses
evenly along a path and moves between waypoints exactly as the planner's motions do
(straight in x, y; theta along the shorter arc, OMPL's SE(2) interpolation), so the
pictures show the motions that were certified. :func:`animate_path` writes an animated
GIF with matplotlib's animation module and Pillow (a matplotlib dependency): no ffmpeg.
"""
from __future__ import annotations

import math

import numpy as np

from .output import atomic_path


def poses_along(path: np.ndarray, count: int, weight: float = 0.5) -> np.ndarray:
    """``count`` poses from the first to the last waypoint (both included), spaced evenly
    by the path's length in the metric of the planner (``|dxy| + weight * |dtheta|`` for
    (N, 3) poses, ``|dxy|`` for (N, 2) positions).

    >>> poses_along(np.array([[0., 0], [2, 0]]), 3).tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]
    >>> p = poses_along(np.array([[0., 0, 3.0], [0, 0, -3.0]]), 3)   # the shorter arc, through pi
    >>> round(float(p[1, 2]), 6)
    3.141593
    """
    from cspace.spaces.se2 import interpolate

    path = np.asarray(path, dtype=np.float64)
    if len(path) == 1 or count < 2:
        return path[:1].repeat(max(count, 1), axis=0)
    se2 = path.shape[1] == 3
    step = np.hypot(*np.diff(path[:, :2], axis=0).T)
    if se2:
        step = step + weight * np.array([abs(_arc(a, b)) for a, b in zip(path[:-1, 2], path[1:, 2])])
    s = np.concatenate([[0.0], np.cumsum(step)])
    if s[-1] == 0.0:
        return path[:1].repeat(count, axis=0)
    out = []
    for target in np.linspace(0.0, s[-1], count):
        k = min(int(np.searchsorted(s, target, side="right")) - 1, len(path) - 2)
        t = 0.0 if step[k] == 0.0 else min(max((target - s[k]) / step[k], 0.0), 1.0)
        a, b = path[k], path[k + 1]
        out.append(interpolate(tuple(a), tuple(b), t) if se2 else tuple(a + t * (b - a)))
    return np.array(out, dtype=np.float64)


def _arc(a: float, b: float) -> float:
    """Signed shorter-arc angle from a to b, in [-pi, pi]."""
    d = math.remainder(b - a, 2.0 * math.pi)
    return d


def robot_polygons(scenario, pose) -> list[np.ndarray]:
    """The robot's parts at a pose ((x, y) or (x, y, theta)), in world coordinates."""
    theta = float(pose[2]) if len(pose) > 2 else 0.0
    return scenario.robot_at(float(pose[0]), float(pose[1]), theta)


def animate_path(res, out: str, frames: int = 80, fps: int = 20, scenario=None) -> None:
    """Write an animated GIF of the robot moving along ``res.path`` (a solved PlanResult).

    The scene (bounds, obstacles) is drawn once; each frame moves the robot's footprint
    and draws the path travelled so far.
    """
    from .plot import _frame, _mpl, _poly_patch, draw_scene

    plt = _mpl()[0]
    from matplotlib.animation import FuncAnimation, PillowWriter

    sc = scenario or res.scenario_data
    if sc is None:
        raise ValueError("animate_path needs the scenario (pass scenario=...)")
    if not res.solved or not len(res.path):
        raise ValueError("animate_path needs a solved plan")
    if sc.turning_radius is not None:  # a car: along its curves, not the chords
        from .space_car import dense_curve

        xmin, xmax, ymin, ymax = sc.bounds
        dense, _ = dense_curve(res.path, sc.space, sc.turning_radius, step=max(xmax - xmin, ymax - ymin) / 1000)
        poses = dense[np.linspace(0, len(dense) - 1, frames).round().astype(int)]
    else:
        poses = poses_along(res.path, frames)
    w, h = sc.bounds[1] - sc.bounds[0], sc.bounds[3] - sc.bounds[2]
    fig, ax = plt.subplots(figsize=(6, 6 * h / w + 0.5))
    draw_scene(ax, sc, None)
    trace = poses if sc.turning_radius is not None else res.path
    ax.plot(trace[:, 0], trace[:, 1], "-", color="#1f5fbf", linewidth=0.8, alpha=0.4)
    _frame(ax, sc.bounds)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(f"{sc.name}: {res.planner}, length {res.length:.4g}")
    patches = [ax.add_patch(_poly_patch(p, facecolor="#2a9d4b", edgecolor="#1d6b34", alpha=0.7))
               for p in robot_polygons(sc, poses[0])] if sc.robot else []
    dot, = ax.plot([poses[0, 0]], [poses[0, 1]], "o", color="#1d6b34", markersize=3)
    trail, = ax.plot([], [], "-", color="#1f5fbf", linewidth=1.6)

    def frame(i):
        for patch, poly in zip(patches, robot_polygons(sc, poses[i])):
            closed = np.vstack([poly, poly[:1]])
            patch.get_path().vertices[:] = closed
        dot.set_data([poses[i, 0]], [poses[i, 1]])
        trail.set_data(poses[: i + 1, 0], poses[: i + 1, 1])
        return [*patches, dot, trail]

    class GifWriter(PillowWriter):
        """Pillow's GIF writer, told the format (the atomic temporary has no extension)."""

        def finish(self):
            self._frames[0].save(self.outfile, format="GIF", save_all=True, append_images=self._frames[1:],
                                 duration=int(1000 / self.fps), loop=0)

    anim = FuncAnimation(fig, frame, frames=len(poses), blit=False)
    fig.tight_layout()
    with atomic_path(out, "--animate") as tmp:
        anim.save(tmp, writer=GifWriter(fps=fps), dpi=80)
    plt.close(fig)
