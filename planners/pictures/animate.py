"""An animation of the robot moving along a path (GIF, via Pillow), at the poses of
:func:`planners.pictures.poses.poses_along`. :func:`animate_path` draws the frames with
matplotlib (the scene once, the moving robot blitted over it) and writes the GIF with Pillow
(a matplotlib dependency): no ffmpeg.
"""
from __future__ import annotations


import numpy as np

from ..output import atomic_path
from .poses import poses_along, robot_polygons  # noqa: F401  (robot_polygons: the animation's API)


def animate_path(res, out: str, frames: int = 80, fps: int = 20, scenario=None, dpi: int = 80,
                 progress: bool | None = None) -> int:
    """Write an animated GIF of the robot moving along ``res.path`` (a solved PlanResult).

    The scene (bounds, obstacles, axes) is drawn once and kept as the background; each frame
    restores it and draws only what moves: the robot's footprint and the path travelled so
    far (matplotlib's blitting), so a frame costs the robot, not the scene. ``progress``: a bar
    on a terminal (None: when stderr is one). Returns the number of frames written.
    """
    from PIL import Image

    from ..progress import Progress
    from .plot import frame_axes, mpl, poly_patch, draw_scene

    plt = mpl()[0]

    sc = scenario or res.scenario_data
    if sc is None:
        raise ValueError("animate_path needs the scenario (pass scenario=...)")
    if not res.solved or not len(res.path):
        raise ValueError("animate_path needs a solved plan")
    if sc.turning_radius is not None:  # a car: along its curves, not the chords
        from ..adapters.car import dense_curve

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
    frame_axes(ax, sc.bounds)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(f"{sc.name}: {res.planner}, length {res.length:.4g}")
    patches = [ax.add_patch(poly_patch(p, facecolor="#2a9d4b", edgecolor="#1d6b34", alpha=0.7))
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

    fig.tight_layout()
    fig.set_dpi(dpi)
    for artist in (*patches, dot, trail):  # left out of the background
        artist.set_animated(True)
    fig.canvas.draw()  # the scene, axes and labels: drawn once, then kept as the background
    background = fig.canvas.copy_from_bbox(fig.bbox)
    images = []
    with Progress(len(poses), "animating", unit="frame", delay=0.5, enabled=progress) as bar:
        for i in range(len(poses)):
            fig.canvas.restore_region(background)
            for artist in frame(i):
                ax.draw_artist(artist)
            fig.canvas.blit(fig.bbox)
            images.append(Image.frombuffer("RGBA", fig.canvas.get_width_height(), fig.canvas.buffer_rgba(),
                                           "raw", "RGBA", 0, 1).convert("RGB"))
            bar.update()
    plt.close(fig)
    with atomic_path(out, "--animate") as tmp:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], duration=int(1000 / fps), loop=0)
    return len(images)
