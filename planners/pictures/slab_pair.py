"""The slab graph drawn for two neighbouring angle slabs: in each, POSSIBLE (pale: the reference
point may be free at some angle of the slab) and FREE (darker: free at every angle of it), their
components numbered; between them, the points where the robot may turn in place from one slab
into the other (FREE links) and the POSSIBLE links a proof has to respect.
"""
from __future__ import annotations

import math

from ..output import atomic_path
from .plot import frame_axes, mpl, poly_patch

FREE_COLOUR, POSSIBLE_COLOUR, OBSTACLE_COLOUR = "#4c9f70", "#cfe8d8", "#555555"


def figure_slab_pair(scenario, a: float, b: float, c: float):
    """The Figure of slabs [a, b] and [b, c] of a rotating robot's scenario (two panels)."""
    import numpy as np

    from cspace.translation.build import decompose_obstacles, decompose_robot
    from cspace.se2.slab_graph import SlabRegions

    sc = scenario
    obstacles, _, _ = decompose_obstacles([o.polygon for o in sc.obstacles], [o.holes for o in sc.obstacles],
                                          convex=[o.convex for o in sc.obstacles])
    robot, _ = decompose_robot([r.polygon for r in sc.robot], sc.robot_kind == "disk")
    R = SlabRegions(obstacles, robot, sc.bounds)
    slabs = [(a, b), (b, c)]
    free = [R.free(*s) for s in slabs]
    possible = [R.possible(*s) for s in slabs]
    plt = mpl()[0]
    xmin, xmax, ymin, ymax = sc.bounds
    aspect = (ymax - ymin) / max(xmax - xmin, 1e-300)
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.5 * min(max(aspect, 0.4), 1.6) + 0.8))
    links = R.free_links(free[0], free[1])
    plinks = R.possible_links(possible[0], possible[1])
    for ax, (lo, hi), F, P in zip(axes, slabs, free, possible):
        for comp in P.components:
            ax.add_patch(poly_patch(np.asarray(comp.exterior.coords), [np.asarray(h.coords) for h in comp.interiors],
                                    facecolor=POSSIBLE_COLOUR, edgecolor="none"))
        for i, comp in enumerate(F.components):
            ax.add_patch(poly_patch(np.asarray(comp.exterior.coords), [np.asarray(h.coords) for h in comp.interiors],
                                    facecolor=FREE_COLOUR, edgecolor="#2d6b47", linewidth=0.6, alpha=0.85))
            p = comp.representative_point()
            ax.annotate(str(i), (p.x, p.y), fontsize=7, color="white", ha="center", va="center")
        for o in sc.obstacles:
            ax.add_patch(poly_patch(o.polygon, o.holes, facecolor=OBSTACLE_COLOUR, edgecolor="none"))
        if links:
            pts = np.array([pt for _, _, pt in links])
            ax.plot(pts[:, 0], pts[:, 1], "o", color="#d62728", markersize=4, label="turn in place (FREE link)")
        frame_axes(ax, sc.bounds)
        ax.set_title(f"θ in [{math.degrees(lo):.1f}°, {math.degrees(hi):.1f}°]: FREE {len(F.components)} "
                     f"components, POSSIBLE {len(P.components)}", fontsize=9)
    from matplotlib.patches import Patch

    handles = [Patch(color=FREE_COLOUR, label="FREE: free at every angle of the slab"),
               Patch(color=POSSIBLE_COLOUR, label="POSSIBLE: free at some angle, perhaps"),
               Patch(color=OBSTACLE_COLOUR, label="obstacles")]
    if links:
        handles.append(axes[0].lines[0])
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    fig.suptitle(f"{sc.name}: the slab graph across θ = {math.degrees(b):.1f}° ({len(links)} FREE links, "
                 f"{len(plinks)} POSSIBLE links)", fontsize=10)
    fig.tight_layout(rect=(0, 0.06, 1, 0.95))
    return fig


def plot_slab_pair(scenario, a: float, b: float, c: float, out: str) -> None:
    """Save :func:`figure_slab_pair` as a PNG (atomically)."""
    plt = mpl()[0]
    fig = figure_slab_pair(scenario, a, b, c)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
