"""An independent checker of Dubins "no path" proofs (format ``cspace-dubins-proof/1``, written by
:mod:`cspace.car.dubins_reach`): a region of grid cells per heading slab, closed under the
forward car's steps of length s, that holds one end and keeps the other out.

It re-derives everything it relies on, with none of the builder's code: the scenario (a Dubins
car of the proof's turning radius), the robot pieces, the slab cover and the cores (the SE(2)
checker's steps, :mod:`planners.core.proof_check`), each slab's POSSIBLE from the cores
(:func:`planners.core.proof_geometry.possible_components`), its own displacement hulls and
stencils. Steps, in order (the first that fails is reported): format, query, robot, cover, cores,
parameters, seed, closure, other end.

- parameters: a Dubins scenario of radius r; 0 < s <= r (a step turns the heading by at most
  1 rad < pi/2); h >= 2^-30 S (S, u: the SE(2) checker's scale and unit); stencils and cell
  arrays within :data:`LIMITS`;
- seed: the start (``direction`` forward; backward: the goal) lies in R_k for every slab k whose
  interval, widened by 1e-9 rad, holds its heading: every cell whose box grown by 1e-9 h + u holds it;
- closure: for every slab k with cells and every slab j that [a_k - s/r, b_k + s/r] (widened by
  1e-9 rad) meets, the cells of dilate(R_k, stencil_k) outside R_j meet no component of slab j's
  POSSIBLE (their boxes grown by 2^-30 S); slab j must carry its cores;
- other end: for every slab k with cells whose interval widened by s/r + 1e-9 holds the other end's
  heading, no cell of R_k (grown by 1e-9 h + u) meets (other end - Disp<=_k).

Displacements (:func:`disp_hull`): the box [r sin(s/r), s] x [-c, c] (c = r (1 - cos(s/r));
[0, s] for the last step) in the heading's frame, turned by the slab's ends and its middle (the
middle scaled by 1 / cos(D/2)), hulled; the box's sides pushed out by 1e-12 relative, the heading
interval widened by 1e-9, and the hull grown by 1e-9 s: each errs toward refusing. A cell (i, j)
is the box o + [i, i + 1] h x [j, j + 1] h (as real numbers); its offsets reach the cells whose
box [di - 1, di + 1] h x [dj - 1, dj + 1] h (grown by 1e-9 h) meets the hull.
"""
from __future__ import annotations

import math

import numpy as np
import shapely

from .proof_check import CheckResult, Refused, TooBig, need, num, parse_header, ring, run_steps, shared_steps
from .proof_geometry import Obstacles, SHRINK_UNITS, convex_obstacles, possible_components

FORMAT = "cspace-dubins-proof/1"
KEYS = ("format", "start", "goal", "bounds", "robot_pieces", "turning_radius", "direction", "step", "grid", "slabs")
ANGLE_SLACK = 1e-9
GROW_REL = 2.0**-30  # cells grown by this x S before the POSSIBLE test (the builder keeps 1e-9 S)
# What the builder writes (at most a few hundred slabs, stencils of a few hundred offsets, a window
# of a few hundred cells a side); each is far above it.
# "cells": the regions' box x the slabs with cells (bytes held); "dilation": that box x the stencils'
# offsets summed over those slabs (byte operations, about a second each 10^9).
LIMITS = {"slabs": 2048, "runs": 1_000_000, "stencil": 20_000, "cells": 50_000_000, "dilation": 4_000_000_000,
          "work": 600_000}


def parse(proof) -> dict:
    """Step "format": the proof's fields as floats, rings and integer runs."""
    out = parse_header(proof, KEYS, FORMAT)
    out["r"], out["s"] = num(proof["turning_radius"], "turning_radius"), num(proof["step"], "step")
    need(proof["direction"] in ("forward", "backward"), "format", "direction: not 'forward' or 'backward'")
    out["backward"] = proof["direction"] == "backward"
    g = proof["grid"]
    need(isinstance(g, dict) and set(g) == {"origin", "cell"} and isinstance(g["origin"], list)
         and len(g["origin"]) == 2, "format", "grid: not an object of origin [x, y] and cell")
    out["o"], out["h"] = [num(v, "grid.origin") for v in g["origin"]], num(g["cell"], "grid.cell")
    need(isinstance(proof["slabs"], list) and proof["slabs"], "format", "slabs: not a non-empty list")
    if len(proof["slabs"]) > LIMITS["slabs"]:
        raise TooBig(f"{len(proof['slabs'])} slabs (the builder writes at most {LIMITS['slabs']})")
    slabs, n_runs = [], 0
    for k, s in enumerate(proof["slabs"]):
        w = f"slabs[{k}]"
        need(isinstance(s, dict) and set(s) == {"a", "b", "cores", "cells"}, "format",
             f"{w}: not an object of a, b, cores, cells")
        cores = None
        if s["cores"] is not None:
            need(isinstance(s["cores"], list) and len(s["cores"]) == len(out["pieces"]), "format",
                 f"{w}.cores: not null or one core per robot piece")
            cores = [ring(c, f"{w}.cores[{i}]", True) for i, c in enumerate(s["cores"])]
            for i, c in enumerate(cores):
                if len(c) > 3 * len(out["pieces"][i]) + 1024:
                    raise TooBig(f"{w}.cores[{i}] has {len(c)} vertices")
        need(isinstance(s["cells"], list), "format", f"{w}.cells: not a list")
        n_runs += len(s["cells"])
        if n_runs > LIMITS["runs"]:
            raise TooBig(f"more than {LIMITS['runs']} runs of cells")
        for t, run in enumerate(s["cells"]):
            need(isinstance(run, list) and len(run) == 3 and all(type(v) is int and abs(v) < 2**40 for v in run)
                 and run[1] < run[2], "format", f"{w}.cells[{t}]: not a run [i, j_first, j_end] of integers")
        slabs.append({"a": num(s["a"], f"{w}.a"), "b": num(s["b"], f"{w}.b"), "cores": cores,
                      "cells": s["cells"]})
    out["slabs"] = slabs
    return out


def check_parameters(p: dict, scenario):
    """Step "parameters": a Dubins car of the proof's turning radius; 0 < s <= r; h > 0."""
    need(scenario.space == "dubins", "parameters", f"the scenario's space is {scenario.space!r}, not 'dubins' "
                                                   "(a reach proof holds for a forward-only car)")
    need(p["r"] == float(scenario.turning_radius), "parameters",
         f"turning_radius {p['r']} is not the scenario's {scenario.turning_radius}")
    need(0.0 < p["s"] <= p["r"], "parameters", f"step {p['s']} is not in (0, r]")
    need(p["h"] > 0.0, "parameters", f"grid cell {p['h']} is not positive")


def check_grid(p: dict, unit: float):
    """Step "parameters": cells far above the coordinates' rounding (h >= 2^10 u = 2^-30 S)."""
    need(p["h"] >= 1024.0 * unit, "parameters", f"grid cell {p['h']} is below 2^-30 of the scene's scale")


def disp_hull(a: float, b: float, s: float, r: float, exact: bool, sign: float):
    """The checker's own hull of the displacements of one step of length s (``exact``; else at
    most s) from a heading in [a, b] (see the module docstring), a shapely Polygon.

    >>> poly = disp_hull(0.0, 0.1, 0.4, 4.0, True, 1.0)  # a left arc of length 0.4 from heading t:
    >>> all(poly.contains(shapely.Point(4 * (math.sin(t + 0.1) - math.sin(t)), 4 * (math.cos(t) - math.cos(t + 0.1))))
    ...     for t in (0.0, 0.05, 0.1))
    True
    >>> poly.contains(shapely.Point(0.4, 0.0)), poly.contains(shapely.Point(0.0, 0.0))
    (True, False)
    """
    a, b = a - ANGLE_SLACK, b + ANGLE_SLACK
    lo = r * math.sin(s / r) * (1 - 1e-12) if exact else -1e-12 * s
    c = r * (1.0 - math.cos(s / r)) * (1 + 1e-12) + 1e-12 * s
    hi = s * (1 + 1e-12)
    box = np.array([[lo, -c], [hi, -c], [hi, c], [lo, c]])
    pts = []
    for t, k in ((a, 1.0), (b, 1.0), (0.5 * (a + b), (1 + 1e-12) / math.cos(0.5 * (b - a)))):
        co, si = math.cos(t), math.sin(t)
        pts.append(k * np.column_stack([box[:, 0] * co - box[:, 1] * si, box[:, 0] * si + box[:, 1] * co]))
    hull = shapely.convex_hull(shapely.multipoints(sign * np.concatenate(pts)))
    return shapely.buffer(hull, 1e-9 * s, join_style="mitre")


def offsets(poly, h: float) -> np.ndarray:
    """The stencil: offsets (di, dj) whose box [di - 1, di + 1] h x [dj - 1, dj + 1] h, grown by 1e-9 h,
    meets ``poly``."""
    x0, y0, x1, y1 = poly.bounds
    lo = (math.floor(x0 / h) - 2, math.floor(y0 / h) - 2)
    hi = (math.ceil(x1 / h) + 2, math.ceil(y1 / h) + 2)
    if (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) > LIMITS["stencil"]:
        raise TooBig(f"a stencil of {(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1)} offsets (step over cell too large)")
    di, dj = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1), indexing="ij")
    di, dj = di.ravel(), dj.ravel()
    g = 1e-9 * h
    hit = shapely.intersects(shapely.box((di - 1) * h - g, (dj - 1) * h - g, (di + 1) * h + g, (dj + 1) * h + g), poly)
    return np.column_stack([di[hit], dj[hit]])


def run_boxes(runs, o, h: float, grow: float):
    """Shapely boxes of runs [i, j0, j1] (cells (i, j0) .. (i, j1 - 1)), grown by ``grow``."""
    r = np.asarray(runs, dtype=np.float64).reshape(-1, 3)
    return shapely.box(o[0] + r[:, 0] * h - grow, o[1] + r[:, 1] * h - grow,
                       o[0] + (r[:, 0] + 1) * h + grow, o[1] + r[:, 2] * h + grow)


def arcs_meet(a0: float, a1: float, b0: float, b1: float) -> bool:
    """Whether the angle intervals [a0, a1] and [b0, b1] (widths below 2 pi) meet modulo 2 pi.

    >>> arcs_meet(3.0, 3.3, -3.1, -3.0), arcs_meet(0.0, 0.1, 0.2, 0.3)
    (True, False)
    """
    two = 2.0 * math.pi
    return (b0 - a0) % two <= a1 - a0 or (a0 - b0) % two <= b1 - b0


def holds(t: float, a: float, b: float, slack: float) -> bool:
    return arcs_meet(a - slack, b + slack, t, t)


class Bitmaps:
    """The proof's regions as boolean arrays over the box of all their cells and a border wide
    enough for every stencil."""

    def __init__(self, slabs, stencils, border: int):
        runs = [np.asarray(s["cells"], dtype=np.int64).reshape(-1, 3) for s in slabs]
        full = [x for x in runs if len(x)]
        need(full, "seed", "every slab's region is empty")
        allr = np.concatenate(full)
        self.i0, self.j0 = int(allr[:, 0].min()) - border, int(allr[:, 1].min()) - border
        self.n0 = int(allr[:, 0].max()) + border + 1 - self.i0
        self.n1 = int(allr[:, 2].max()) + border - self.j0
        if self.n0 * self.n1 * len(full) > LIMITS["cells"]:
            raise TooBig(f"regions over {self.n0} x {self.n1} cells in {len(full)} slabs")
        self.work = self.n0 * self.n1 * sum(len(st) for st, x in zip(stencils, runs) if len(x))
        if self.work > LIMITS["dilation"]:
            raise TooBig(f"{self.work} cell shifts to dilate the regions (at most {LIMITS['dilation']})")
        self.maps = []
        for x in runs:
            m = np.zeros((self.n0, self.n1), bool) if len(x) else None
            for i, a, b in x.tolist():
                m[i - self.i0, a - self.j0:b - self.j0] = True
            self.maps.append(m)

    def dilate(self, m: np.ndarray, st: np.ndarray) -> np.ndarray:
        out = np.zeros_like(m)
        n0, n1 = m.shape
        for di, dj in st.tolist():
            out[max(di, 0):n0 + min(di, 0), max(dj, 0):n1 + min(dj, 0)] |= \
                m[max(-di, 0):n0 - max(di, 0), max(-dj, 0):n1 - max(dj, 0)]
        return out

    def as_runs(self, m: np.ndarray) -> list:
        out = []
        for i in np.flatnonzero(m.any(axis=1)).tolist():
            d = np.diff(np.concatenate([[0], m[i].astype(np.int8), [0]]))
            out += [[i + self.i0, a + self.j0, b + self.j0] for a, b in
                    zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist())]
        return out


def check_dubins_proof(scenario, proof: dict, query_index: int = 0) -> CheckResult:
    """Check a Dubins reach proof that no forward path joins query ``query_index`` of
    ``scenario``: the first failing step, or ``valid``. Past :data:`LIMITS`: :class:`TooBig`."""
    def steps(at: list) -> CheckResult:
        p = parse(proof)
        obstacles = convex_obstacles(scenario)
        n_obs = sum(map(len, obstacles))
        work = sum(n_obs + sum(map(len, s["cores"])) + 64 for s in p["slabs"] if s["cores"] is not None)
        if work > LIMITS["work"]:
            raise TooBig(f"{work} units of POSSIBLE work (at most {LIMITS['work']})")
        q, unit = shared_steps(scenario, p, query_index, obstacles, [s for s in p["slabs"] if s["cores"] is not None],
                               at)
        at[0] = "parameters"
        check_parameters(p, scenario)
        check_grid(p, unit)
        return CheckResult(True, "ok", _regions(scenario, p, q, unit, obstacles))

    return run_steps(steps)


def _regions(scenario, p, q, unit, obstacles) -> str:
    """Steps "seed", "closure" and "other end"."""
    r, s, h, o, slabs = p["r"], p["s"], p["h"], p["o"], p["slabs"]
    sign = -1.0 if p["backward"] else 1.0
    seed, other = (q.goal, q.start) if p["backward"] else (q.start, q.goal)
    turn = s / r
    hulls = [disp_hull(x["a"], x["b"], s, r, True, sign) for x in slabs]
    stencils = [offsets(hl, h) if x["cells"] else None for hl, x in zip(hulls, slabs)]
    border = max(int(np.abs(st).max()) for st in stencils if st is not None) + 1
    maps = Bitmaps(slabs, stencils, border)
    # seed (cells within 1e-9 h + u of it: their corners' rounding is a few ulps of S, far below u)
    tol = 1e-9 * h + unit
    for k, x in enumerate(slabs):
        if holds(seed[2], x["a"], x["b"], ANGLE_SLACK):
            cells = [(i, j) for i in _spans(seed[0], o[0], h, tol) for j in _spans(seed[1], o[1], h, tol)]
            m = maps.maps[k]
            missing = [c for c in cells if m is None or not (0 <= c[0] - maps.i0 < maps.n0 and 0 <= c[1] - maps.j0 < maps.n1)
                       or not m[c[0] - maps.i0, c[1] - maps.j0]]
            need(not missing, "seed", f"slab {k} holds the seed's heading but not its cell {list(missing[0]) if missing else ''}")
    # closure: per target slab, the cells its sources' steps reach beyond it
    xmin, xmax, ymin, ymax = (float(v) for v in scenario.bounds)
    shrink = SHRINK_UNITS * unit
    box = shapely.box(xmin - shrink, ymin - shrink, xmax + shrink, ymax + shrink)
    parts = Obstacles(obstacles)
    grow = GROW_REL * unit / 2.0**-40
    reached = {k: maps.dilate(m, stencils[k]) for k, m in enumerate(maps.maps) if m is not None}
    checked = 0
    for j, y in enumerate(slabs):
        sources = [k for k in reached if arcs_meet(slabs[k]["a"] - turn - ANGLE_SLACK,
                                                   slabs[k]["b"] + turn + ANGLE_SLACK, y["a"], y["b"])]
        if not sources:
            continue
        extra = np.logical_or.reduce([reached[k] for k in sources])
        if maps.maps[j] is not None:
            extra &= ~maps.maps[j]
        if not extra.any():
            continue
        need(y["cores"] is not None, "closure", f"slab {j} is reached but carries no cores")
        comps = possible_components(y["cores"], parts, box, shrink)
        runs = maps.as_runs(extra)
        boxes = run_boxes(runs, o, h, grow)
        poss = shapely.union_all(comps) if comps else shapely.Polygon()
        shapely.prepare(poss)
        hit = np.flatnonzero(shapely.intersects(boxes, poss))
        if len(hit):
            i, a, b = runs[int(hit[0])]
            raise Refused("closure", f"slab {j}: cells ({i}, {a}..{b - 1}) are reached from the regions but are "
                                     "neither in its region nor certainly blocked")
        checked += len(runs)
    # other end
    for k, x in enumerate(slabs):
        if maps.maps[k] is None or not holds(other[2], x["a"] - turn, x["b"] + turn, ANGLE_SLACK):
            continue
        near = _translated(disp_hull(x["a"], x["b"], s, r, False, -sign), other)  # other - Disp<=_k
        boxes = run_boxes(x["cells"], o, h, tol)
        need(not shapely.intersects(boxes, near).any(), "other end",
             f"slab {k}'s region reaches the {'start' if p['backward'] else 'goal'} within one step")
    n_cells = sum(int(m.sum()) for m in maps.maps if m is not None)
    return (f"{len(slabs)} slabs, {n_cells} cells of side {h:g}, step {s:g}: closed under the car's "
            f"{'backward' if p['backward'] else 'forward'} steps, the {'start' if p['backward'] else 'goal'} "
            f"out of reach ({checked} runs of cells checked blocked)")


def _translated(poly, point):
    """{point + v : v in poly} (poly: the negated hull, so this is point - Disp)."""
    xy = np.asarray(poly.exterior.coords) + np.array([float(point[0]), float(point[1])])
    return shapely.Polygon(xy)


def _spans(x: float, origin: float, h: float, tol: float) -> list:
    """The indices i whose closed span [origin + i h - tol, origin + (i + 1) h + tol] holds x."""
    lo, hi = math.floor((x - origin - tol) / h - 1e-9), math.floor((x - origin + tol) / h + 1e-9)
    return [i for i in range(lo - 1, hi + 2) if origin + i * h - tol <= x <= origin + (i + 1) * h + tol]
