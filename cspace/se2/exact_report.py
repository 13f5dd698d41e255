"""What the slab-graph search (:mod:`cspace.se2.exact`) hands back besides a path: its proof, as
the independent checker reads it, and the resolution statement of an undecided search.

The statement (note se2-exact.md, section 4) must be true of the scene as written. Slab k's FREE
is built of hulls H ⊇ R_θ P′ for θ in [a − s, b + s] (s = ANGLE_SLACK), P′ the robot as the
C-space has it: each disk part by its circumscribed polygon, grown by the margin operands M;
H ⊆ R_θ P′ ⊕ disk(r′·(Δ + 2 s) + 4 δ) (r′ the radius of P′, δ the hull pad). P′ ⊆ P ⊕ disk(e_R)
⊕ disk(m) (e_R the robot's disks' polygon error, m the margin's reach: the largest vertex norm
of M's operands, summed), and each obstacle lies within its disks' polygon error e_O of the
obstacle as written. So a path keeping the robot as written more than
D = m + r′·(Δmax + 2 s) + 4 δ + e_R + e_O from every obstacle as written lies in FREE at every
pose; any two consecutive slabs' FREE then overlap with an interior where it crosses between
them, which the links find (a point deep inside, or any interior point of a thin overlap,
re-checked exactly), so the FREE graph joins start and goal. "No path with clearance above D"
is then true, with bounds of any thinness, a margin, and across the ±π seam (the slabs cover the
circle and the last links to the first).
"""
from __future__ import annotations

import math

import numpy as np

PROOF_FORMAT = "cspace-se2-proof/1"


def proof_json(part, preg, regions, start, goal, s_p, g_p, edges) -> dict:
    """The proof (format ``cspace-se2-proof/1``): slabs with their cores and POSSIBLE components,
    the start's and goal's nodes and the links, as :mod:`planners.core.proof_check` reads it."""
    slabs = []
    for (a, b), reg in zip(part, preg):
        slabs.append({"a": float(a), "b": float(b), "cores": [c.tolist() if len(c) else [] for c in reg.cores],
                      "components": [component_json(c) for c in reg.components]})
    xmin, xmax, ymin, ymax = regions.bounds
    return {"format": PROOF_FORMAT, "start": list(start), "goal": list(goal),
            "bounds": [xmin, xmax, ymin, ymax], "robot_pieces": [p.tolist() for p in regions.core_robot],
            "slabs": slabs, "start_nodes": [list(n) for n in sorted(s_p)],
            "goal_nodes": [list(n) for n in sorted(g_p)], "edges": sorted(edges)}


def component_json(poly) -> dict:
    """A component as the proof stores it: shell CCW, holes CW, no closing repeat."""
    return {"shell": [list(p) for p in poly.exterior.coords[:-1]],
            "holes": [[list(p) for p in r.coords[:-1]] for r in poly.interiors]}


def margin_reach(margin: list | None) -> float:
    """m: how far the margin operands reach from the reference point (their vertex norms summed).

    >>> margin_reach([np.array([[-1., 0], [2, 0], [0, 1]])]), margin_reach(None)
    (2.0, 0.0)
    """
    return float(sum(np.hypot(m[:, 0], m[:, 1]).max() for m in (margin or []) if len(m)))


def resolution(regions, widest: float, slack: float) -> tuple[float, str]:
    """D (see the module docstring) and the statement's words for it.

    >>> from cspace.se2.slab_graph import SlabRegions
    >>> sr = SlabRegions([], [np.array([[0., 0], [1, 0], [0, 1]])], (0, 4, 0, 4))
    >>> D, words = resolution(sr, 0.01, 1e-8)
    >>> round(D, 6), words.startswith("no path with clearance above 0.01")
    (0.01, True)
    """
    if not math.isfinite(widest):
        return math.inf, "no statement on the clearance of paths (no FREE graph was searched to its end)"
    r = regions.radius
    turn = r * (widest + 2.0 * slack) + 4.0 * regions.hull_pad
    D = regions.margin_reach + turn + regions.excess
    parts = [f"robot radius {r:.6g} x widest slab {widest:.6g} rad"]
    if regions.margin_reach:
        parts.insert(0, f"the margin's reach {regions.margin_reach:.6g}")
    if regions.excess:
        parts.append(f"disks' polygon error {regions.excess:.3g}")
    disks = "; a smaller disk_tolerance narrows the disks' share" if regions.excess else ""
    return D, (f"no path with clearance above {D:.6g} ({' + '.join(parts)}) exists; a tighter one was not decided"
               f"{disks}")


def disk_excess(sc) -> float:
    """e_R + e_O of a scenario: the largest circumscribed-polygon error of its robot's disks plus
    that of its obstacles' (0 without disks).

    >>> from cspace.io.scenario.schema import Scenario, Shape
    >>> from cspace.kernel.polygons.disk import disk_polygon
    >>> sh = Shape(disk_polygon((0, 0), 1.0, sides=8), disk=(0.0, 0.0, 1.0), convex=True)
    >>> round(disk_excess(Scenario("d", (0, 4, 0, 4), [sh], [sh], (0, 0), (4, 4))), 6)
    0.164784
    """
    def err(shapes):
        out = 0.0
        for s in shapes:
            if s.disk is not None:
                cx, cy, r = s.disk
                out = max(out, float(np.hypot(s.polygon[:, 0] - cx, s.polygon[:, 1] - cy).max()) - r)
        return out

    return err(sc.robot) + err(sc.obstacles) + (math.ulp(1.0) if sc.has_disks else 0.0)
