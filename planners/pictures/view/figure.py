"""The page's figure as plotly's JSON form (data, layout, frames): the scene, the C-space (one
translation C-space, or for a rotating robot or a car a slider over the angle that swaps in the
slab at that angle), the path, the robot's footprint moving along it (play / pause and a slider
over the path), the closest approach and, for a proof that no path exists, its components.

Frames update only the traces they name: ``pose-I`` the moving footprint, ``slab-K`` the
C-obstacles (and the proof's components), so the two sliders are independent. A pose frame
draws the footprint with at most :data:`MOVING_VERTICES` vertices (a finely approximated disk
would otherwise repeat its thousands of vertices in every frame), and a figure of more than
:data:`MAX_POINTS` points is refused (exit 2) rather than written as a page no browser opens.

Every text of the figure is plotly's HTML subset (``<a href>``, ``<span style>``, ``<br>``): the
strings that reach it (the scene's name in the title, names, hover texts, labels) are escaped
(:func:`escape_texts`), so a name is shown as it is spelt, never as markup.
"""
from __future__ import annotations

import math

import numpy as np

from ..plot import PATH
from ..titles import plan_title
from . import traces as tr

DEFAULT_POSES = 120  # frames of the robot along the path
DEFAULT_ANGLES = 32  # steps of the angle slider (rotating robots and cars)
POSE_FRAME_MS = 40  # play: 25 frames a second
MOVING_VERTICES = 240  # vertices of the footprint in a pose frame (decimated beyond)
MAX_POINTS = 1_500_000  # points a page may draw in all (traces and frames): about 25 MB of figure
TEXT_KEYS = frozenset({"text", "name", "hovertext", "label", "prefix", "suffix"})  # plotly markup


def plotly_text(text: str) -> str:
    """``text`` with plotly's markup characters escaped: shown as written, never as a tag.

    >>> plotly_text('<a href="http://x">y</a> & z')
    '&lt;a href="http://x"&gt;y&lt;/a&gt; &amp; z'
    """
    return str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def escape_texts(node):
    """Escape (:func:`plotly_text`) every string under a text key of a figure (dicts and lists
    walked, coordinate arrays skipped), in place; returns ``node``.

    >>> escape_texts({"layout": {"title": {"text": "<b>x</b>"}}, "data": [{"x": [1], "name": "a<b"}]})
    {'layout': {'title': {'text': '&lt;b&gt;x&lt;/b&gt;'}}, 'data': [{'x': [1], 'name': 'a&lt;b'}]}
    """
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("x", "y"):
                continue
            if key in TEXT_KEYS and isinstance(value, str):
                node[key] = plotly_text(value)
            elif key in TEXT_KEYS and isinstance(value, list) and all(isinstance(v, str) for v in value):
                node[key] = [plotly_text(v) for v in value]
            else:
                escape_texts(value)
    elif isinstance(node, list):
        for item in node:
            if isinstance(item, (dict, list)):
                escape_texts(item)
    return node


def points(traces) -> int:
    """Points drawn by traces (their x arrays' lengths)."""
    return sum(len(t.get("x") or ()) for t in traces)


def check_size(count: int) -> None:
    """Refuse a figure of more than :data:`MAX_POINTS` points (bad input: exit 2)."""
    if count > MAX_POINTS:
        from ...errors import InputError

        raise InputError("page", "size", f"the page would draw {count} points, more than the bound {MAX_POINTS}: "
                                         "lower --poses or --angles, or coarsen the scene (disk_tolerance)")


def figure_dict(res, scenario=None, poses: int = DEFAULT_POSES, angles: int = DEFAULT_ANGLES) -> dict:
    """``{"data", "layout", "frames"}`` of a plan result's page (see the module notes).

    >>> import planners
    >>> fig = figure_dict(planners.plan(tr.example_scene(), planner="exact"))
    >>> len(fig["frames"]), fig["layout"]["sliders"][0]["name"]
    (120, 'pose')
    """
    sc = scenario or res.scenario_data
    if sc is None:
        raise ValueError("figure_dict needs the scenario (pass scenario=...)")
    nd = tr.digits(sc.bounds)
    data = [tr.bounds_trace(sc.bounds)]
    sliders, frames, menus = [], [], []
    if sc.rotates:
        slab_frames, slider, first = angle_frames(sc, res, nd, angles, len(data))
        data += first
        frames += slab_frames
        sliders += [slider] if slider else []
    else:
        cs = res.cspace
        if cs is None:
            from cspace.translation.cspace import CSpace

            cs = CSpace.from_scenario(sc)
        if not sc.is_point_robot:
            data.append(tr.cobstacle_trace(cs.pieces, nd))
    data.append(tr.obstacle_trace(sc, nd))
    dense = None
    if res.solved and len(res.path):
        lines, dense = tr.path_traces(sc, res, nd)
        data += lines
    data += tr.start_goal_traces(sc, res, nd)
    data += tr.closest_traces(sc, res, nd)
    if not sc.rotates:  # a passage narrower than 1 % of the scene, crossed by a path (as the plot's zoom)
        from cspace.paths.gap import narrowest_gap_of_paths

        data += tr.gap_traces(narrowest_gap_of_paths(cs.pieces, cs.bounds,
                                                     [r.path for r in (res.queries or [res]) if r.solved]), nd)
    check_size(points(data) + sum(points(f["data"]) for f in frames))
    if dense is not None:
        moving = len(data)
        along = pick_poses(sc, res, dense, poses)
        data += moving_traces(sc, along[0], nd)
        check_size(points(data) + sum(points(f["data"]) for f in frames) + (len(along) - 1) * points(data[moving:]))
        frames += [{"name": f"pose-{i}", "traces": [moving, moving + 1], "data": moving_traces(sc, q, nd)}
                   for i, q in enumerate(along)]
        sliders.insert(0, pose_slider(along))
        menus.append(play_menu(len(along)))
    if len(sliders) == 1 and sliders[0]["name"] == "angle":  # no path: the angle slider goes up
        sliders[0]["pad"] = {"t": 50}
    layout = scene_layout(sc, res, sliders, menus)
    return escape_texts({"data": data, "layout": layout, "frames": frames})


def pick_poses(sc, res, dense: np.ndarray, count: int) -> np.ndarray:
    """``count`` poses along the path: a car's picked evenly from its dense curve, others
    spaced by length as the planner's motions move (:func:`planners.pictures.poses.poses_along`).

    >>> class R: path = np.array([[0., 0], [2, 0]])
    >>> pick_poses(tr.example_scene(), R(), R.path, 3).tolist()
    [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]
    """
    if sc.turning_radius is not None:
        return dense[np.linspace(0, len(dense) - 1, count).round().astype(int)]
    from ..poses import poses_along

    return poses_along(np.asarray(res.path, dtype=np.float64), count)


def moving_traces(sc, pose, nd: int) -> list[dict]:
    """The robot's footprint at ``pose`` and its reference point: the two traces a pose frame replaces.

    >>> [t["name"] for t in moving_traces(tr.example_scene(), (1.0, 2.0), 3)]
    ['robot moving along the path', 'reference point']
    """
    robot = tr.robot_trace("robot moving along the path", sc, pose, PATH, nd, opacity=0.55, limit=MOVING_VERTICES)
    th = f", θ = {math.degrees(float(pose[2])):.1f}°" if len(pose) > 2 else ""
    dot = {"type": "scatter", "mode": "markers", "name": "reference point",
           "x": [round(float(pose[0]), nd)], "y": [round(float(pose[1]), nd)], "showlegend": False,
           "marker": {"color": "black", "size": 5}, "hovertext": [f"robot at ({pose[0]:.4g}, {pose[1]:.4g}){th}"],
           "hoverinfo": "text"}
    return [robot, dot]


def angle_frames(sc, res, nd: int, angles: int, index: int) -> tuple[list, dict | None, list]:
    """A rotating robot's C-space by angle: frames ``slab-K`` (one per slab an angle step falls
    in) replacing traces ``index`` (C-obstacles) and ``index + 1`` (a proof's components), the
    angle slider, and the two traces at the start's angle.

    >>> class R: cspace, proof, start = None, None, (1.0, 1.0, 0.0)
    >>> sc = tr.example_scene()
    >>> frames, slider, first = angle_frames(sc, R(), 3, 8, 1)
    >>> len(slider["steps"]), first[0]["name"].startswith("C-obstacle")
    (8, True)
    """
    from cspace.kernel.slabs.slab import slab_of, slab_range

    se2 = res.cspace
    if se2 is None or not hasattr(se2, "slabs"):
        from cspace.se2.cspace import SE2CSpace

        se2 = SE2CSpace.from_scenario(sc, slabs=sc.slabs)
    K = se2.slabs
    proof = (res.proof or {}).get("slabs") or []
    steps, frames, seen, drawn = [], [], {}, 0
    for j in range(max(angles, 1)):
        th = -math.pi + (j + 0.5) * 2.0 * math.pi / max(angles, 1)
        k = slab_of(th, K) if K > 1 else 0
        name = f"slab-{k}"
        if k not in seen:
            seen[k] = len(frames)
            frames.append({"name": name, "traces": [index, index + 1], "data": slab_traces(se2, k, proof, th, nd)})
            drawn += points(frames[-1]["data"])
            check_size(drawn)  # as the frames grow, not once they are all built
        a, b = slab_range(k, K) if K > 1 else (-math.pi, math.pi)
        steps.append({"label": f"{math.degrees(th):.0f}°", "method": "animate",
                      "args": [[name], {"mode": "immediate", "frame": {"duration": 0, "redraw": True},
                                        "transition": {"duration": 0}}],
                      "name": f"slab {k} of {K}: θ in [{math.degrees(a):.1f}°, {math.degrees(b):.1f}°]"})
    th0 = float(res.start[2]) if len(res.start) > 2 else 0.0
    k0 = slab_of(th0, K) if K > 1 else 0
    first = slab_traces(se2, k0, proof, th0, nd)
    if K == 1:  # a point robot does not turn: one C-space at every angle, no slider
        return [], None, first
    active = min(range(len(steps)), key=lambda j: abs(math.remainder(
        -math.pi + (j + 0.5) * 2.0 * math.pi / len(steps) - th0, 2.0 * math.pi)))
    slider = {"name": "angle", "active": active, "steps": steps, "y": 0, "yanchor": "top", "len": 0.78,
              "x": 0.22, "pad": {"t": 150},
              "currentvalue": {"prefix": f"C-space ({K} slabs) at θ = ", "xanchor": "right"}}
    return frames, slider, first


def slab_traces(se2, k: int, proof: list, th: float, nd: int) -> list[dict]:
    """Slab ``k``'s C-obstacles and the components of the proof slab holding ``th`` (empty without a proof).

    >>> from cspace.se2.cspace import SE2CSpace
    >>> se2 = SE2CSpace.from_scenario(tr.example_scene(), slabs=8)
    >>> [len(t["x"]) > 0 for t in slab_traces(se2, 0, [], 0.0, 3)]
    [True, False]
    """
    pieces = se2.slab(k).pieces
    rings = []
    for s in proof:
        if s["a"] <= th <= s["b"]:
            rings = tr.proof_rings(s)
            break
    return [tr.cobstacle_trace(pieces, nd, name="C-obstacle of the slab at θ (robot = its hull over the slab)"),
            tr.proof_trace(rings, nd)]


def pose_slider(along: np.ndarray) -> dict:
    """The slider over the path: one step per pose frame, labelled by the fraction travelled.

    >>> s = pose_slider(np.zeros((3, 2)))
    >>> [st["label"] for st in s["steps"]]
    ['0%', '50%', '100%']
    """
    n = len(along)
    steps = [{"label": f"{round(100 * i / max(n - 1, 1))}%", "method": "animate",
              "args": [[f"pose-{i}"], {"mode": "immediate", "frame": {"duration": 0, "redraw": False},
                                       "transition": {"duration": 0}}]} for i in range(n)]
    return {"name": "pose", "active": 0, "steps": steps, "y": 0, "yanchor": "top", "len": 0.78, "x": 0.22,
            "pad": {"t": 50}, "currentvalue": {"prefix": "along the path: ", "xanchor": "right"}}


def play_menu(n: int) -> dict:
    """Play (the pose frames from the current one) and pause buttons.

    >>> [b["label"] for b in play_menu(3)["buttons"]]
    ['▶ play', '❚❚ pause']
    """
    play = {"frame": {"duration": POSE_FRAME_MS, "redraw": False}, "transition": {"duration": 0},
            "fromcurrent": True, "mode": "immediate"}
    pause = {"frame": {"duration": 0, "redraw": False}, "transition": {"duration": 0}, "mode": "immediate"}
    return {"type": "buttons", "direction": "left", "x": 0.0, "y": 0, "xanchor": "left", "yanchor": "top",
            "pad": {"t": 60, "r": 10}, "showactive": False,
            "buttons": [{"label": "▶ play", "method": "animate", "args": [[f"pose-{i}" for i in range(n)], play]},
                        {"label": "❚❚ pause", "method": "animate", "args": [[None], pause]}]}


def scene_layout(sc, res, sliders: list, menus: list) -> dict:
    """Equal-scale axes on the bounds (pan by drag, zoom by wheel), the title, the controls.

    >>> class R: planner, seed, solved, length, message, proven_unsolvable = "exact", 0, True, 2.0, "", False
    >>> lay = scene_layout(tr.example_scene(), R(), [], [])
    >>> lay["yaxis"]["scaleanchor"], lay["dragmode"]
    ('x', 'pan')
    """
    xmin, xmax, ymin, ymax = sc.bounds
    pad = 0.02 * max(xmax - xmin, ymax - ymin)
    bottom = 60 + 100 * len(sliders)
    return {"title": {"text": plan_title(sc.name, res)},
            "xaxis": {"range": [xmin - pad, xmax + pad], "title": {"text": "x"}, "constrain": "domain"},
            "yaxis": {"range": [ymin - pad, ymax + pad], "title": {"text": "y"}, "scaleanchor": "x",
                      "scaleratio": 1, "constrain": "domain"},
            "dragmode": "pan", "hovermode": "closest", "plot_bgcolor": "white", "height": 640 + 100 * len(sliders),
            "margin": {"l": 60, "r": 20, "t": 50, "b": bottom}, "legend": {"x": 1.02, "y": 1},
            "sliders": sliders, "updatemenus": menus}
