"""Stiff and extreme inputs for the stability catalogue (:mod:`planners.stability`).

Deterministic generators (fixed seeds): near-collinear triples a few ulps off a line,
squares with collinear, repeated and one-ulp-outside points, slivers of aspect 1e9,
100 000-gon circles, integers up to 2^52, random convex polygons, L shapes and combs,
touching contacts, and the passage scene whose gap is exactly, just over or just under
the robot's width.
"""
from __future__ import annotations

import math

import numpy as np


# ---------------------------------------------------------------- numbers


def seeded_rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def ulps_up(x: float, k: int = 1) -> float:
    for _ in range(k):
        x = math.nextafter(x, math.inf)
    return x


def ulps_down(x: float, k: int = 1) -> float:
    for _ in range(k):
        x = math.nextafter(x, -math.inf)
    return x


# ---------------------------------------------------------------- predicate


def pred_near_line(scale: float, offset: float, n: int = 400, seed: int = 0) -> list:
    """Triples (a, b, c) with c on or within a few ulps of line ab."""
    rng = seeded_rng(seed)
    out = []
    for _ in range(n):
        a = offset + scale * rng.uniform(-1, 1, 2)
        b = offset + scale * rng.uniform(-1, 1, 2)
        t = rng.uniform(-1, 2)
        c = a + t * (b - a)
        k = int(rng.integers(-3, 4))
        cy = ulps_up(float(c[1]), k) if k > 0 else ulps_down(float(c[1]), -k)
        out.append((tuple(a.tolist()), tuple(b.tolist()), (float(c[0]), cy)))
    # exactly collinear triples: c = a + 2^-j (b - a) on a dyadic grid
    for j in range(1, 6):
        a = (offset + scale * 0.25, offset - scale * 0.5)
        b = (offset + scale * 0.75, offset + scale * 0.5)
        c = (a[0] + (b[0] - a[0]) / 2 ** j, a[1] + (b[1] - a[1]) / 2 ** j)
        out.append((a, b, c))
    return out


def near_parallel_triples() -> list:
    """u = (1e6, 1), v = (2e6, 2 + d): cross(u, v) = 1e6 d, within a few ulps of 0."""
    out = []
    for y in (2 + 1e-9, ulps_up(2.0), ulps_down(2.0), 2.0, ulps_up(2.0, 3)):
        for o in (0.0, 1e8):
            out.append(((o, o), (o + 1e6, o + 1), (o + 2e6, o + y)))
    out.append(((0.0, 0.0), (1e-300, 1e-300), (2e-300, ulps_up(2e-300))))  # underflow
    out.append(((0.0, 0.0), (1e300, 1e300), (-1e300, ulps_up(-1e300))))  # overflow
    return out


# ---------------------------------------------------------------- polygons


def random_convex(rng, n: int, radius: float, offset: float = 0.0) -> np.ndarray:
    """A random convex polygon: the hull of n random points in a disk (floats, CCW)."""
    from cspace import convex_hull

    t = rng.uniform(0, 2 * np.pi, n)
    r = radius * np.sqrt(rng.uniform(0.2, 1, n))
    return convex_hull(np.c_[offset + r * np.cos(t), offset + r * np.sin(t)])


def square_with_extras(scale: float, offset: float, seed: int = 1) -> np.ndarray:
    """Corners, exactly collinear edge points, repeats, 1-ulp bumps outward, interior points."""
    rng = seeded_rng(seed)
    lo, hi = offset - scale, offset + scale
    pts = [(lo, lo), (hi, lo), (hi, hi), (lo, hi)] * 3  # repeats
    xs = np.linspace(lo, hi, 17)[1:-1].tolist()
    pts += [(x, lo) for x in xs] + [(hi, x) for x in xs]  # collinear with the edges
    pts += [(xs[3], ulps_down(lo)), (ulps_up(hi), xs[5])]  # one ulp outside: extreme, must be kept
    pts += [(xs[7], ulps_up(hi)), (ulps_down(lo), xs[9])]
    pts += (offset + 0.9 * scale * rng.uniform(-1, 1, (50, 2))).tolist()
    return np.array(pts)


def sliver_points(aspect: float = 1e9, offset: float = 0.0, n: int = 20) -> np.ndarray:
    """Points of a triangle of length 1 and height 1/aspect, with points along its long edge."""
    t = np.linspace(0, 1, n)
    pts = np.r_[np.c_[t, np.zeros(n)], [[0.5, 1 / aspect]]]
    return pts + offset


def circle_points(n: int, radius: float = 1.0, offset: float = 0.0) -> np.ndarray:
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[offset + radius * np.cos(t), offset + radius * np.sin(t)]


def int_points(rng, n: int, top: int = 2 ** 52) -> np.ndarray:
    return rng.integers(-top, top, (n, 2)).astype(np.float64)


def l_shape(scale: float, offset: float) -> np.ndarray:
    base = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], dtype=np.float64)
    return offset + scale * base


def comb_points(teeth: int, aspect: float, offset: float = 0.0) -> np.ndarray:
    """A comb of slivers: teeth of width 1/aspect and height 1 on a base, collinear base points."""
    w = 1.0 / aspect
    pts = [(0.0, 0.0), (1.0, 0.0), (1.0, 0.5)]
    xs = np.linspace(1.0, 0.0, 2 * teeth + 1)
    for k in range(teeth):
        x0 = xs[2 * k + 1]
        pts += [(x0, 0.5), (x0, 1.5), (x0 - w, 1.5), (x0 - w, 0.5)]
    pts.append((0.0, 0.5))
    return np.array(pts) + offset


def box_polygon(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)


def contact_pairs(s: float, o: float) -> list:
    """Touching pairs (edge-edge, vertex-edge, vertex-vertex) at scale s, offset o (exact in floats)."""
    sq = box_polygon(o, o, o + s, o + s)
    return [
        ("edge_edge", sq, box_polygon(o + s, o + s / 2, o + 2 * s, o + 1.5 * s)),
        ("vertex_edge", sq, np.array([[o + s, o + s / 2], [o + 2 * s, o], [o + 2 * s, o + s]])),
        ("vertex_vertex", sq, box_polygon(o + s, o + s, o + 2 * s, o + 2 * s)),
    ]


# ---------------------------------------------------------------- scenes


def passage(robot_w: float, slack: float, offset: float = 0.0) -> dict:
    """A scenario dict: a square robot of width ``robot_w`` and a wall with a passage of width
    ``robot_w + slack`` centred at (offset, offset); start and goal on either side."""
    h, g, L = robot_w / 2, (robot_w + slack) / 2, 8 * robot_w
    o = offset
    wall = lambda y0, y1: [[o - robot_w, y0], [o + robot_w, y0], [o + robot_w, y1], [o - robot_w, y1]]
    return {
        "name": f"passage_w{robot_w:g}_s{slack:g}_o{offset:g}",
        "bounds": {"xmin": o - L / 2, "xmax": o + L / 2, "ymin": o - L / 4, "ymax": o + L / 4},
        "robot": {"polygon": [[-h, -h], [h, -h], [h, h], [-h, h]]},
        "obstacles": [{"polygon": wall(o - L, o - g)}, {"polygon": wall(o + g, o + L)}],
        "start": {"x": o - 3 * robot_w, "y": o},
        "goal": {"x": o + 3 * robot_w, "y": o},
    }
