"""Families of SE(2) scenes for the exact planner's benchmark and tests (issue 49), each scene
made from a seed, the solvable ones with a hand-built witness path.

- ``door(seed, spare)``: a wall with a door (1 + spare) x a box robot's width, random sizes and
  poses; ``door_witness``: turn to 0 in place, slide to the door's height, through, to the goal.
- ``pillars(seed)``: a box between two round pillars (disks) with 1 % to spare.
- ``far_reference(seed)``: the reference point 2-10 x the body's length outside it (a long
  lever: a slab's FREE must be very thin to hold the door), a door 0.5 % wider.
- ``offset_doors(seed)``: two parallel walls whose doors (0.5 % wider than the robot) are at
  different heights: through one, a slide between the walls, through the other.
- ``seam(seed)``: a bar in a corridor 0.5 % wider than it, pointing just below π at the start and
  just above −π at the goal: the witness is one motion across the ±π seam.
- ``two_parts(seed)``: a robot of two boxes in a line through a door 0.3 % wider than them.
- ``slanted(seed)``: a tunnel through a thick wall at the start's own angle θs, 0.1 % wider than
  the robot, the goal at another angle (no critical angle of the search is θs: a translation at
  the start's angle is the way).

``witness(name, seed)`` is the family's hand-built path (None for the pillars: not all have
one); :func:`witness_clearance` measures a lower bound on its clearance to the obstacles as
written (disks as circles), independently of cspace (shapely).
"""
from __future__ import annotations

import math
import random

import numpy as np
import shapely
from shapely import affinity

from cspace.io.load import scenario_from_dict


def _box(L: float, W: float, cx: float = 0.0, cy: float = 0.0) -> list:
    return [[cx - L / 2, cy - W / 2], [cx + L / 2, cy - W / 2], [cx + L / 2, cy + W / 2], [cx - L / 2, cy + W / 2]]


def _wall(x: float, y0: float, d: float, t: float = 0.1, far: float = 5.0) -> list:
    """A vertical wall at x (half thickness t) from −far to far with a door of height d at y0."""
    return [{"polygon": [[x - t, -far], [x + t, -far], [x + t, y0 - d / 2], [x - t, y0 - d / 2]]},
            {"polygon": [[x - t, y0 + d / 2], [x + t, y0 + d / 2], [x + t, far], [x - t, far]]}]


def _scene(name, bounds, robot, start, goal, obstacles):
    return scenario_from_dict({"space": "se2", "name": name, "bounds": dict(zip(("xmin", "xmax", "ymin", "ymax"), bounds)),
                               "robot": robot, "start": dict(zip("xy", start[:2]), theta=start[2]),
                               "goal": dict(zip("xy", goal[:2]), theta=goal[2]), "obstacles": obstacles}, f"{name}.toml")


def door(seed: int, spare: float):
    """A wall at x = 0 with a door (1 + spare) x the box robot's width, random sizes and poses."""
    rng = random.Random(seed)
    L, W = rng.uniform(1.2, 2.5), rng.uniform(0.3, 0.7)
    d, y0 = (1 + spare) * W, rng.uniform(-1.5, 1.5)
    start = (-2.5, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    goal = (2.5, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    return _scene(f"door{seed}", (-4, 4, -3, 3), {"polygon": _box(L, W)}, start, goal, _wall(0.0, y0, d))


def door_witness(sc) -> list:
    """Turn to 0 at the start, slide to the door's height, through the door, to the goal's height, turn."""
    y0 = 0.5 * (sc.obstacles[0].polygon[2][1] + sc.obstacles[1].polygon[0][1])
    (xs, ys, ts), (xg, yg, tg) = sc.start, sc.goal
    return [(xs, ys, ts), (xs, ys, 0.0), (xs, y0, 0.0), (xg, y0, 0.0), (xg, yg, 0.0), (xg, yg, tg)]


def pillars(seed: int, spare: float = 0.01):
    """A box between two round pillars (disks of radius R), ``spare`` x its half-height to spare."""
    rng = random.Random(seed)
    R, h, w = rng.uniform(2, 20), rng.uniform(0.1, 0.5), rng.uniform(0.5, 1.0)
    c = R + h * (1 + spare)
    return scenario_from_dict({
        "space": "se2", "name": f"pillars{seed}", "bounds": {"xmin": -R - 4, "xmax": R + 4, "ymin": -R / 2, "ymax": R / 2},
        "robot": {"polygon": [[-w, -h], [w, -h], [w, h], [-w, h]]},
        "start": {"x": -R - 3, "y": 0.0, "theta": 0.0}, "goal": {"x": R + 3, "y": 0.0, "theta": 0.0},
        "obstacles": [{"center": [0.0, c], "radius": R}, {"center": [0.0, -c], "radius": R}]}, "pillars.toml")


def far_reference(seed: int, spare: float = 0.005):
    """A box L x W whose centre is ox (2-10 x L, either side) from the reference point, through a
    door 0.5 % wider than W at angle 0; start and goal at angle 0 at random heights."""
    rng = random.Random(seed)
    L, W = rng.uniform(0.6, 1.2), rng.uniform(0.3, 0.6)
    ox = rng.choice((-1, 1)) * rng.uniform(2, 10) * L
    y0 = rng.uniform(-1, 1)
    start = (-1.5 - L / 2 - ox, rng.uniform(-1.5, 1.5), 0.0)
    goal = (1.5 + L / 2 - ox, rng.uniform(-1.5, 1.5), 0.0)
    xs = sorted((start[0], goal[0]))
    return _scene(f"far{seed}", (xs[0] - 1, xs[1] + 1, -2, 2), {"polygon": _box(L, W, ox)}, start, goal,
                  _wall(0.0, y0, (1 + spare) * W))


def far_witness(sc) -> list:
    y0 = 0.5 * (sc.obstacles[0].polygon[2][1] + sc.obstacles[1].polygon[0][1])
    (xs, ys, _), (xg, yg, _) = sc.start, sc.goal
    return [(xs, ys, 0.0), (xs, y0, 0.0), (xg, y0, 0.0), (xg, yg, 0.0)]


def offset_doors(seed: int, spare: float = 0.005):
    """Walls at x = ±1 (0.2 thick), doors (1 + spare) x W at heights y1 and y2 (apart); a box
    L x W (L < 1.6: it slides between the walls at angle 0), start and goal at random angles."""
    rng = random.Random(seed)
    L, W = rng.uniform(0.8, 1.5), rng.uniform(0.2, 0.5)
    y1, y2 = rng.uniform(-1.5, -0.2), rng.uniform(0.2, 1.5)
    if rng.random() < 0.5:
        y1, y2 = y2, y1
    start = (-3.0, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    goal = (3.0, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    return _scene(f"offset{seed}", (-4, 4, -2.5, 2.5), {"polygon": _box(L, W)}, start, goal,
                  _wall(-1.0, y1, (1 + spare) * W) + _wall(1.0, y2, (1 + spare) * W))


def offset_witness(sc) -> list:
    y1 = 0.5 * (sc.obstacles[0].polygon[2][1] + sc.obstacles[1].polygon[0][1])
    y2 = 0.5 * (sc.obstacles[2].polygon[2][1] + sc.obstacles[3].polygon[0][1])
    (xs, ys, ts), (xg, yg, tg) = sc.start, sc.goal
    return [(xs, ys, ts), (xs, ys, 0.0), (xs, y1, 0.0), (0.0, y1, 0.0), (0.0, y2, 0.0), (xg, y2, 0.0),
            (xg, yg, 0.0), (xg, yg, tg)]


def seam(seed: int, spare: float = 0.005):
    """A bar L x W in a corridor (1 + spare) x W high, at π − ε at the start and −π + ε at the goal
    (ε below the room's allowance, so both ends are free)."""
    rng = random.Random(seed)
    L, W = rng.uniform(1.0, 2.5), rng.uniform(0.2, 0.5)
    d = (1 + spare) * W
    eps = rng.uniform(0.05, 0.5) * spare * W / L  # the bar's corner moves L/2·ε (+ W/2·ε²/2): < spare·W/2
    eps2 = rng.uniform(0.05, 0.5) * spare * W / L
    s1 = rng.choice((-1, 1))
    start, goal = (2.0, 0.0, s1 * (math.pi - eps)), (8.0, 0.0, -s1 * (math.pi - eps2))
    return _scene(f"seam{seed}", (1.5, 8.5, 0.0, 1e-3 * (spare * W)), {"polygon": _box(L, W)}, start, goal,
                  [{"polygon": [[0, -3], [10, -3], [10, -d / 2], [0, -d / 2]]},
                   {"polygon": [[0, d / 2], [10, d / 2], [10, 3], [0, 3]]}])


def seam_witness(sc) -> list:
    """One motion from start to goal: the shorter arc crosses ±π."""
    return [tuple(sc.start), tuple(sc.goal)]


def two_parts(seed: int, spare: float = 0.003):
    """Two boxes (L1 x W at the origin, L2 x W at (d, 0)) moving as one through a door (1 + spare) x W."""
    rng = random.Random(seed)
    W, L1, L2, gap = rng.uniform(0.3, 0.6), rng.uniform(0.4, 0.8), rng.uniform(0.4, 0.8), rng.uniform(0.1, 0.4)
    dx = (L1 + L2) / 2 + gap
    y0 = rng.uniform(-1.5, 1.5)
    start = (-3.5, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    goal = (3.5, rng.uniform(-1, 1), rng.uniform(-math.pi, math.pi))
    robot = {"parts": [{"polygon": _box(L1, W)}, {"polygon": _box(L2, W, dx)}]}
    xg = 3.5 - dx  # the goal's reference point: the second box clear of the bound's side
    return _scene(f"parts{seed}", (-5, 5, -3, 3), robot, start, (xg, goal[1], goal[2]), _wall(0.0, y0, (1 + spare) * W))


def slanted(seed: int, spare: float = 0.001):
    """A thick wall (x in [−0.5, 0.5]) pierced by a straight tunnel at angle θs (random in 0.3-0.8)
    (1 + spare) x the box's width W; start and goal in the open at θs. The heaviest critical angles
    are the wall's (0, ±π/2, −π): none at θs; the box passes only within ~spare·W/L of θs, so a
    slab's FREE never holds the tunnel, and a translation at the start's own angle does. Start in
    the open at θs, the goal in the open at a random angle (a turn there)."""
    rng = random.Random(seed)
    L, W = rng.uniform(0.8, 1.4), rng.uniform(0.2, 0.4)
    ts, y0 = rng.uniform(0.3, 0.8), rng.uniform(-0.3, 0.3)
    tn, dv = math.tan(ts), (1 + spare) * W / math.cos(ts)  # the tunnel's vertical height
    lo = [[-0.5, -5], [0.5, -5], [0.5, y0 + 0.5 * tn - dv / 2], [-0.5, y0 - 0.5 * tn - dv / 2]]
    hi = [[-0.5, y0 - 0.5 * tn + dv / 2], [0.5, y0 + 0.5 * tn + dv / 2], [0.5, 5], [-0.5, 5]]
    start, goal = (-2.5, rng.uniform(-1.5, 1.5), ts), (2.5, rng.uniform(-1.5, 1.5), rng.uniform(-math.pi, math.pi))
    return _scene(f"slant{seed}", (-3.5, 3.5, -3.2, 3.2), {"polygon": _box(L, W)}, start, goal,
                  [{"polygon": lo}, {"polygon": hi}])


def slanted_witness(sc) -> list:
    """At the start's angle: to the tunnel's centre line, along it, to the goal's height; turn."""
    lo, hi = sc.obstacles[0].polygon, sc.obstacles[1].polygon
    y0, tn = 0.25 * (lo[2][1] + lo[3][1] + hi[0][1] + hi[1][1]), (lo[2][1] - lo[3][1])
    (xs, ys, ts), (xg, yg, tg) = sc.start, sc.goal
    return [(xs, ys, ts), (xs, y0 + xs * tn, ts), (xg, y0 + xg * tn, ts), (xg, yg, ts), (xg, yg, tg)]


def parts_witness(sc) -> list:
    return door_witness(sc)


# name -> (scene maker, witness maker); the bench's --families and tests/se2/test_exact_doors.py read it
DESIGNED = {"far reference": (far_reference, far_witness), "offset doors 0.5 %": (offset_doors, offset_witness),
            "seam one motion": (seam, seam_witness), "two parts 0.3 %": (two_parts, parts_witness),
            "slanted tunnel 0.1 %": (slanted, slanted_witness),
            "doors 0.1 % witness": (lambda s: door(2000 + s, 0.001), door_witness)}


def witness_clearance(sc, path, dtheta: float = 1e-3) -> float:
    """A lower bound on the clearance of the (N, 3) path (OMPL's interpolation: x, y linear, θ
    along the shorter arc) to the obstacles as written (disks as circles): per step of at most
    ``dtheta`` rotation, the hull of each robot piece at both ends, less the bound on a point's
    stray from its chord (r·(1 − cos(Δθ/2))); negative when the path may touch."""
    obs = shapely.union_all([shapely.Point(o.disk[:2]).buffer(o.disk[2], quad_segs=2048) if o.disk is not None
                             else o.to_shapely() for o in sc.obstacles])
    pieces = []
    for part in sc.robot:
        poly = (shapely.Point(part.disk[:2]).buffer(part.disk[2], quad_segs=256) if part.disk is not None
                else shapely.Polygon(part.polygon))
        pieces += [poly] if poly.convex_hull.equals(poly) else list(shapely.get_parts(shapely.delaunay_triangles(poly)))
    r = max(float(np.hypot(*np.asarray(p.exterior.coords).T).max()) for p in pieces)
    best = math.inf
    for a, b in zip(path[:-1], path[1:]):
        turn = (b[2] - a[2] + math.pi) % (2 * math.pi) - math.pi
        n = max(1, math.ceil(abs(turn) / dtheta))
        for k in range(n):
            q0 = [a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n, a[2] + turn * k / n]
            q1 = [a[0] + (b[0] - a[0]) * (k + 1) / n, a[1] + (b[1] - a[1]) * (k + 1) / n, a[2] + turn * (k + 1) / n]
            pad = r * (1 - math.cos(abs(turn) / n / 2))
            for p in pieces:
                g = [affinity.translate(affinity.rotate(p, q[2], origin=(0, 0), use_radians=True), q[0], q[1])
                     for q in (q0, q1)]
                best = min(best, shapely.union(*g).convex_hull.distance(obs) - pad)
    return best
