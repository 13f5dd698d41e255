"""A Dubins car's reach, over-approximated and closed under its motion: a proof that a
forward-only car cannot get from one pose to another (format ``cspace-dubins-proof/1``,
checked independently by :mod:`planners.core.dubins_check`).

Cut a feasible path (forward, curvature at most 1/r, every pose free, the reference point in the
bounds) at arc lengths 0, s, 2 s, ...: each sample q_{i+1} is free and lies in E_s(q_i), the poses
a curvature-bounded forward path of length exactly s reaches from q_i; the far end lies in
E_{<=s}(q_last). For s/r < pi/2 and a heading theta, E_s changes the heading by at most s/r and
moves the reference point by d with, in theta's frame,

    d.u in [r sin(s/r), s],  |d.u_perp| <= r (1 - cos(s/r))   (E_{<=s}: d.u in [0, s])

(d = integral of u(phi(t)), |phi(t) - theta| <= t/r < pi/2: cos and sin bound the two parts).
For headings in a slab [a, b] of width D < pi the displacements lie in the hull of the rectangle
turned by a, by b and by (a + b) / 2 scaled by 1 / cos(D / 2) (:func:`displacements`: for a point p
the points R_t p, t in [a, b], form an arc of angle D; an arc lies in the triangle of its chord and
its end tangents, whose apex is R_m p / cos(D / 2); rotations and scalings are linear, so the union
of those triangles over the rectangle lies in the hull of the 12 turned and scaled corners).

Regions are sets of grid cells (origin o, side h; cell (i, j) = o + [i, i+1] h x [j, j+1] h) per
heading slab. The points a cell c of slab k reaches in one step lie in c (+) Disp_k, and the cells
meeting that set are c's index plus a fixed *stencil* of offsets (:func:`stencil`): the cells
meeting [-h, h]^2 (+) Disp_k. The certificate (R_k per slab) holds when

(a) the seed (the start, or the goal driving backward: Disp negated) lies in R_k for every slab
    holding its heading; (b) for every slab k and every slab j that [a_k - s/r, b_k + s/r] meets,
    every cell of dilate(R_k, stencil_k) outside R_j is *certainly blocked* in slab j (a
    reference point there collides at every angle of j or leaves the bounds: outside POSSIBLE_j,
    note se2-exact.md); (c) the other end is not in R_k (+) Disp<=_k for any slab k whose widened
    interval holds its heading. Then every sample of every path lies in R, and the path never
    ends at the other end: no path exists.

:func:`reach_proof` builds R by a fixed-point iteration (cells grow from the seed until nothing
new), capped in cells and in the window around the seed: past the cap there is no proof.
"""
from __future__ import annotations

import functools
import math
import time
import weakref

import numpy as np
import shapely

from ..se2.critical import initial_partition

FORMAT = "cspace-dubins-proof/1"
# Resolutions tried in turn (step s as a fraction of r; cell side h = FACTOR s^2 / r, the two
# leaks per unit length balanced): coarse first, so a car that is not confined pays little.
STEPS = (0.07, 0.05)
FINE_STEP = 0.04   # a last, finer try where an end looks boxed in (planners.core.auto_dubins)
CELL_FACTOR = 1.0
# slab width >= this x s / r: a step reaches its own slab and its two neighbours only. The reach
# gains a slab's width of heading per step where the car turns s / r: this ratio is how much
# tighter than r the over-approximated car turns (1.08 let a car facing a rack 0.8 m ahead, which
# cannot turn at r = 0.5 m, turn out at r / 1.08 in the reach: no proof)
SLAB_OVER = 1.01
WINDOW = 2.0       # the window's half side, in turning radii (at least 3 robot radii)
WINDOW_CELLS = 256  # ... and at most this many cells of the step (of the first of STEPS, at a finer one)
MAX_CELLS = 60_000  # region cells summed over the slabs at the first step: past this, no proof
ERODE = 1.0 / math.cos(math.pi / 32)  # a round buffer's chords (8 per quarter) lie inside its circle


def rectangle(s: float, r: float, exact: bool) -> np.ndarray:
    """The corners of E_s's (``exact``) or E_<=s's displacement box in the heading's frame.

    >>> rectangle(0.4, 4.0, True).round(4).tolist()
    [[0.3993, -0.02], [0.4, -0.02], [0.4, 0.02], [0.3993, 0.02]]
    """
    lo = r * math.sin(s / r) if exact else 0.0
    c = r * (1.0 - math.cos(s / r))
    return np.array([[lo, -c], [s, -c], [s, c], [lo, c]])


def displacements(a: float, b: float, s: float, r: float, exact: bool = True, sign: float = 1.0) -> np.ndarray:
    """The hull (CCW vertices) holding every displacement of a step of length s (``exact``) or
    at most s from a heading in [a, b] (``sign`` -1: driving backward), grown by a rounding pad.

    >>> p = displacements(0.0, 0.1, 0.4, 4.0)
    >>> bool(shapely.Polygon(p).contains(shapely.Point(0.4 * math.cos(0.05), 0.4 * math.sin(0.05))))
    True
    """
    rect = rectangle(s, r, exact)
    pts = []
    for t, scale in ((a, 1.0), (b, 1.0), (0.5 * (a + b), 1.0 / math.cos(0.5 * (b - a)))):
        co, si = math.cos(t), math.sin(t)
        pts.append(scale * (rect @ np.array([[co, si], [-si, co]])))
    hull = shapely.convex_hull(shapely.multipoints(sign * np.concatenate(pts)))
    hull = shapely.buffer(hull, 1e-9 * s, join_style="mitre")
    return np.asarray(hull.exterior.coords)[:-1]


def stencil(disp: np.ndarray, h: float) -> np.ndarray:
    """The offsets (di, dj) of the cells that the points of cell (0, 0) (+) ``disp`` meet: those
    whose box [di - 1, di + 1] h x [dj - 1, dj + 1] h meets ``disp`` (grown by a rounding pad).

    >>> len(stencil(np.array([[0.0, 0.0], [0.5, 0.0], [0.5, 0.5]]), 1.0))  # the 3 x 3 around (0, 0)
    9
    >>> stencil(np.array([[2.5, 0.1], [3.5, 0.1], [3.5, 0.4]]), 1.0).tolist()  # x 2.5 .. 4.5, y 0.1 .. 1.4
    [[2, 0], [2, 1], [3, 0], [3, 1], [4, 0], [4, 1]]
    """
    lo, hi = np.floor(disp.min(axis=0) / h) - 1, np.ceil(disp.max(axis=0) / h) + 1
    di, dj = np.meshgrid(np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1), indexing="ij")
    di, dj = di.ravel(), dj.ravel()
    pad = 1e-9 * h
    boxes = shapely.box((di - 1) * h - pad, (dj - 1) * h - pad, (di + 1) * h + pad, (dj + 1) * h + pad)
    hit = shapely.intersects(boxes, shapely.Polygon(disp))
    return np.column_stack([di[hit], dj[hit]]).astype(np.int64)


def dilate(cells: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The cells of ``cells`` (a boolean array) shifted by every offset, ORed (offsets that leave
    the array are cut: the caller keeps a border of the stencil's reach free of cells)."""
    out = np.zeros_like(cells)
    n0, n1 = cells.shape
    for di, dj in offsets.tolist():
        out[max(di, 0):n0 + min(di, 0), max(dj, 0):n1 + min(dj, 0)] |= \
            cells[max(-di, 0):n0 - max(di, 0), max(-dj, 0):n1 - max(dj, 0)]
    return out


def in_slab(t: float, a: float, b: float, slack: float) -> bool:
    """Whether the angle t (modulo 2 pi) is in [a - slack, b + slack].

    >>> in_slab(-3.0, 3.0, 3.5, 0.0), in_slab(0.0, 0.1, 0.2, 0.0)
    (True, False)
    """
    d = (t - a + slack) % (2.0 * math.pi)
    return d <= (b - a) + 2.0 * slack


class _Lazy(dict):
    """A dict that computes a missing key's value by ``make(key)`` and keeps it."""

    def __init__(self, make):
        super().__init__()
        self.make = make

    def __missing__(self, key):
        self[key] = value = self.make(key)
        return value


# SlabRegions -> {(a, b, h): the slab's certainly blocked cells' test}, kept with the regions
_BLOCKED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


class _Blocked:
    """Slab j's certainly blocked cells: a cell is blocked when its centre lies in (the bounds,
    grown by a cell, minus POSSIBLE_j) eroded by the cell's half diagonal (the whole cell then
    lies outside POSSIBLE_j or outside the bounds)."""

    def __init__(self, region, bounds, h: float, scale: float):
        xmin, xmax, ymin, ymax = bounds
        comps = region.components
        free = shapely.union_all(comps) if comps else shapely.Polygon()
        blocked = shapely.difference(shapely.box(xmin - 2 * h, ymin - 2 * h, xmax + 2 * h, ymax + 2 * h), free)
        d = (0.5 * math.sqrt(2.0) * h) * ERODE * (1.0 + 1e-6) + 1e-9 * scale
        self.core = shapely.buffer(blocked, -d, quad_segs=8)
        shapely.prepare(self.core)
        self.box = (xmin - h, xmax + h, ymin - h, ymax + h)

    def of(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Whether the cells centred at (x, y) are certainly blocked (outside the grown bounds: yes)."""
        x0, x1, y0, y1 = self.box
        return shapely.contains_xy(self.core, x, y) | (x < x0) | (x > x1) | (y < y0) | (y > y1)


_LOCAL: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # SlabRegions -> {window: local regions}


def _local(regions, box):
    """Slab regions of the obstacles within the robot's reach of ``box`` (x0, y0, x1, y1) only,
    with the full regions' bounds, robot and proof unit (so the same cores): their POSSIBLE holds
    the full one's inside the box (fewer obstacles: more possible, never less)."""
    from ..se2.slab_graph import SlabRegions

    kept = _LOCAL.setdefault(regions, {})
    if box not in kept:
        g = regions.radius
        x0, y0, x1, y1 = box[0] - g, box[1] - g, box[2] + g, box[3] + g
        close = [ob for ob in regions.core_obstacles if len(ob) and ob[:, 0].max() >= x0 and ob[:, 0].min() <= x1
                 and ob[:, 1].max() >= y0 and ob[:, 1].min() <= y1]
        local = SlabRegions(close, regions.core_robot, regions.bounds)
        local.unit, local.pad, local.eps = regions.unit, regions.pad, regions.eps
        kept[box] = local
    return kept[box]


def _blocked(regions, slab, h: float) -> _Blocked:
    kept = _BLOCKED.setdefault(regions, {})
    key = (float(slab[0]), float(slab[1]), float(h))
    if key not in kept:
        scale = max([abs(v) for v in regions.bounds] + [regions.radius])
        kept[key] = _Blocked(regions.possible(*slab), regions.bounds, h, scale)
    return kept[key]


def reach_proof(regions, start, goal, radius: float, *, backward: bool = False, deadline: float | None = None,
                steps=STEPS, max_cells: int = MAX_CELLS) -> dict | None:
    """A proof that no forward Dubins path of turning radius ``radius`` joins ``start`` to
    ``goal`` (a :class:`cspace.se2.slab_graph.SlabRegions` gives POSSIBLE per slab), the reach
    grown from the start (``backward``: from the goal, driving backward); None where the reach
    leaves its window, passes ``max_cells``, meets the other end at every resolution tried, or
    ``deadline`` (perf_counter) passes."""
    for frac in steps:
        if deadline is not None and time.perf_counter() > deadline:
            return None
        # a finer grid holds (s / s')^4 as many cells for the same reach: the cap grows with it
        cap = int(max_cells * (steps[0] / frac) ** 4)
        got = _attempt(regions, start, goal, radius, frac * radius, backward, deadline, cap)
        if got is not None:
            return got
    return None


@functools.lru_cache(maxsize=1024)
def _stencil_of(K: int, k: int, s: float, r: float, sign: float, h: float) -> np.ndarray:
    """Slab k of K's stencil (the same for every query of a car: kept)."""
    a, b = initial_partition(K)[k]
    out = stencil(displacements(a, b, s, r, True, sign), h)
    out.flags.writeable = False
    return out


def _attempt(regions, start, goal, r: float, s: float, backward: bool, deadline, max_cells: int):
    K = int(math.floor(2.0 * math.pi / (SLAB_OVER * s / r)))  # the most slabs at least that wide
    h = CELL_FACTOR * s * s / r
    sign = -1.0 if backward else 1.0
    seed, other = (goal, start) if backward else (start, goal)
    xmin, xmax, ymin, ymax = regions.bounds
    o = (xmin, ymin)
    # the window: at most WINDOW_CELLS cells of this step, or of the first of STEPS when finer
    half = min(max(WINDOW * r, 3.0 * regions.radius), WINDOW_CELLS * max(h, CELL_FACTOR * STEPS[0] ** 2 * r))
    i0 = int(math.floor((seed[0] - half - o[0]) / h))
    j0 = int(math.floor((seed[1] - half - o[1]) / h))
    n = int(math.ceil(2 * half / h)) + 1
    # POSSIBLE of the obstacles near the window only (a reference point in it touches no other):
    # on a large map a slab's region is then milliseconds; the cores are the full regions' own
    near = _local(regions, (o[0] + i0 * h, o[1] + j0 * h, o[0] + (i0 + n) * h, o[1] + (j0 + n) * h))
    slabs = initial_partition(K)  # the last ends one ulp past pi: the cover is closed in exact arithmetic
    sten = _Lazy(lambda k: _stencil_of(K, k, s, r, sign, h))
    # the slabs a step's heading can end in: those [a_k - s/r, b_k + s/r] meets (padded)
    turn = s / r + 1e-9
    targets = _Lazy(lambda k: [j for j, (c, d) in enumerate(slabs)
                               if in_slab(c, slabs[k][0] - turn, slabs[k][1] + turn, 0.0)
                               or in_slab(slabs[k][0] - turn, c, d, 0.0)])
    # every stencil's reach: a step moves at most s / cos(D/2) (< 1.01 s), a cell's neighbours one more
    border = int(math.ceil(1.01 * s / h)) + 3
    R = {}
    tested = {}
    front = {}
    blocked = {}
    cx = o[0] + (i0 + np.arange(n) + 0.5) * h
    cy = o[1] + (j0 + np.arange(n) + 0.5) * h
    for k, (a, b) in enumerate(slabs):
        if in_slab(seed[2], a, b, 1e-9):
            R[k] = np.zeros((n, n), bool)
            for ii in _cells_at(seed[0], o[0], h):
                for jj in _cells_at(seed[1], o[1], h):
                    R[k][ii - i0, jj - j0] = True
            tested[k] = R[k].copy()
            front[k] = [np.nonzero(R[k])]
    # (c), checked as cells arrive: the cells from which a last step of at most s reaches the other end
    ends = _near_cells(other, slabs, s, r, sign, h, o, (i0, j0), n)
    if any((R[k] & ends[k]).any() for k in R if k in ends):
        return None
    total = sum(int(x.sum()) for x in R.values())
    count = {k: int(R[k].sum()) for k in front}
    while front:  # the smallest front first (its cells as index arrays: no pass over the window)
        if deadline is not None and time.perf_counter() > deadline:
            return None
        k = min(front, key=lambda key: (count[key], key))
        parts = front.pop(k)
        fi, fj = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
        lo = np.array([fi.min(), fj.min()])
        hi = np.array([fi.max(), fj.max()])
        if lo.min() < border or hi.max() >= n - border:
            return None  # the reach leaves its window: not confined enough to prove
        b0, b1 = lo - border, hi + border + 1
        f = np.zeros(tuple(b1 - b0), bool)
        f[fi - b0[0], fj - b0[1]] = True
        grown = dilate(f, sten[k])
        for j in targets[k]:
            if j not in R:
                R[j], tested[j] = np.zeros((n, n), bool), np.zeros((n, n), bool)
            if j not in blocked:
                blocked[j] = _blocked(near, slabs[j], h)
            view_t = tested[j][b0[0]:b1[0], b0[1]:b1[1]]
            cand = grown & ~view_t
            if not cand.any():
                continue
            ci, cj = np.nonzero(cand)
            ok = ~blocked[j].of(cx[ci + b0[0]], cy[cj + b0[1]])
            view_t |= cand
            if ok.any():
                ai, aj = ci[ok] + b0[0], cj[ok] + b0[1]
                if j in ends and ends[j][ai, aj].any():
                    return None  # the other end is within reach
                R[j][ai, aj] = True
                count[j] = (count[j] if j in front else 0) + len(ai)
                front.setdefault(j, []).append((ai, aj))
                total += len(ai)
                if total > max_cells:
                    return None
    return _json(near, start, goal, r, s, h, o, i0, j0, slabs, R, targets, backward)


def _near_cells(other, slabs, s: float, r: float, sign: float, h: float, o, corner, n: int) -> dict:
    """Per slab whose interval widened by s/r holds the other end's heading: the window's cells
    (a boolean array) meeting other - Disp<=_k (grown by a rounding pad): a region holding one of
    them may reach the other end by a last step (cells outside the window: the region never
    holds them, it fails on reaching the window's border)."""
    out = {}
    for k, (a, b) in enumerate(slabs):
        if not in_slab(other[2], a - s / r, b + s / r, 1e-9):
            continue
        poly = shapely.Polygon(np.array([other[0], other[1]]) - displacements(a, b, s, r, False, sign))
        x0, y0, x1, y1 = poly.bounds
        ii = np.arange(math.floor((x0 - o[0]) / h) - 1, math.ceil((x1 - o[0]) / h) + 1)
        jj = np.arange(math.floor((y0 - o[1]) / h) - 1, math.ceil((y1 - o[1]) / h) + 1)
        I, J = (v.ravel() for v in np.meshgrid(ii, jj, indexing="ij"))
        pad = 1e-6 * h
        hit = shapely.intersects(shapely.box(o[0] + I * h - pad, o[1] + J * h - pad, o[0] + (I + 1) * h + pad,
                                             o[1] + (J + 1) * h + pad), poly)
        I, J = I[hit] - corner[0], J[hit] - corner[1]
        keep = (I >= 0) & (I < n) & (J >= 0) & (J < n)
        out[k] = np.zeros((n, n), bool)
        out[k][I[keep], J[keep]] = True
    return out


def _cells_at(x: float, origin: float, h: float) -> list:
    """The indices of the cells whose closed span holds x (two where x is on or near a line)."""
    t = (x - origin) / h
    i = int(math.floor(t))
    return sorted({i, int(math.floor(t - 1e-6)), int(math.floor(t + 1e-6))})


def runs(cells: np.ndarray, i0: int, j0: int) -> list:
    """A region's cells as runs [i, j_first, j_last + 1] (absolute indices), row by row.

    >>> runs(np.array([[1, 1, 0, 1], [0, 0, 0, 0]], bool), 10, 20)
    [[10, 20, 22], [10, 23, 24]]
    """
    rows = np.flatnonzero(cells.any(axis=1))
    if not len(rows):
        return []
    cols = np.flatnonzero(cells[rows].any(axis=0))
    c0, c1 = int(cols[0]), int(cols[-1]) + 1  # only the columns that hold cells
    pad = np.zeros((len(rows), c1 - c0 + 2), np.int8)
    pad[:, 1:-1] = cells[rows, c0:c1]
    d = np.diff(pad, axis=1)  # +1 where a run starts, -1 one past its end; row-major: they pair up
    ri, a = np.nonzero(d == 1)
    _, b = np.nonzero(d == -1)
    return np.column_stack([rows[ri] + i0, a + c0 + j0, b + c0 + j0]).tolist()


def _json(regions, start, goal, r, s, h, o, i0, j0, slabs, R, targets, backward) -> dict:
    xmin, xmax, ymin, ymax = regions.bounds
    out = []
    needed = set()
    for k, cells in R.items():
        if cells.any():
            needed |= set(targets[k])
    for k, (a, b) in enumerate(slabs):
        cores = [c.tolist() if len(c) else [] for c in regions.possible(a, b).cores] if k in needed else None
        out.append({"a": float(a), "b": float(b), "cores": cores,
                    "cells": runs(R[k], i0, j0) if k in R else []})
    return {"format": FORMAT, "start": [float(v) for v in start], "goal": [float(v) for v in goal],
            "bounds": [xmin, xmax, ymin, ymax], "robot_pieces": [p.tolist() for p in regions.core_robot],
            "turning_radius": float(r), "direction": "backward" if backward else "forward", "step": float(s),
            "grid": {"origin": [float(o[0]), float(o[1])], "cell": float(h)}, "slabs": out}
