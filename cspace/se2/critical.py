"""Critical angles of a rotating robot among obstacles, and zero-width slabs at them.

A door just wider than the robot lets it through only near the angles at which a robot edge is
parallel to the door's walls; a slab around such an angle must be narrower than the room for its
FREE to hold the passage (a 0.1 % door: about 10⁴ slabs round the circle). At the angle itself,
the zero-width slab [φ, φ] (FREE: the exact translation C-space of the turned robot, shrunk by
δ) holds it at once. The critical angles are φ = ω − ρ (mod π): ω an obstacle edge's direction,
ρ a robot edge's; each is weighed by the obstacle edges' length at it, and the heaviest few are
inserted (4: the two senses of two perpendicular walls for a box) into the partition of the
search (:mod:`cspace.se2.exact`) after its second round, with the start's and goal's own angles.
:func:`initial_partition` is the search's first partition (8 equal slabs covering the circle).
"""
from __future__ import annotations

import math

import numpy as np

from ..kernel.polygons.rotation import wrap_angle
from ..kernel.slabs.slab import slab_range


def critical_angles(robot: list, obstacles: list, count: int = 4) -> list[float]:
    """The ``count`` heaviest angles φ in [−π, π) at which a robot edge is parallel to an obstacle
    edge (both senses: φ and φ + π), sorted; deterministic (ties by angle).

    >>> box = [np.array([[-1., -0.2], [1, -0.2], [1, 0.2], [-1, 0.2]])]
    >>> wall = [np.array([[4., 0], [5, 0], [5, 10], [4, 10]])]
    >>> [round(a, 6) for a in critical_angles(box, wall)]
    [-3.141593, -1.570796, 0.0, 1.570796]
    """
    def directions(pieces):
        out = []
        for p in pieces:
            p = np.asarray(p, dtype=np.float64)
            if len(p) < 2:
                continue
            e = np.roll(p, -1, axis=0) - p
            out += zip(np.mod(np.arctan2(e[:, 1], e[:, 0]), math.pi).tolist(), np.hypot(e[:, 0], e[:, 1]).tolist())
        return out

    rob = {round(t, 12) for t, ln in directions(robot) if ln > 0}
    weight: dict = {}
    for w, ln in directions(obstacles):
        for r in rob:
            for turn in (0.0, math.pi):
                phi = wrap_angle(w - r + turn)
                if abs(phi) > math.pi - 1e-12:
                    phi = -math.pi  # the seam: one angle
                key = round(phi, 12)
                wt, rep = weight.get(key, (0.0, phi))
                weight[key] = (wt + ln, rep)
    best = sorted(weight.values(), key=lambda v: (-v[0], v[1]))[:count]
    return sorted(rep for _, rep in best)


def with_zero_slabs(part: list, angles: list[float]) -> list:
    """The partition with a zero-width slab [φ, φ] at each angle φ: the slab holding it cut at
    φ (or, at a boundary, the zero-width slab put between the two; −π, where the partition
    starts, as the float π inside its last slab); slabs stay consecutive, the circle covered once.

    >>> with_zero_slabs([(-math.pi, 0.0), (0.0, math.pi)], [0.0, 1.0])
    [(-3.141592653589793, 0.0), (0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 3.141592653589793)]
    """
    out = list(part)
    for phi in angles:
        if out and phi == out[0][0] and out[-1][0] < math.pi < out[-1][1]:
            phi = math.pi  # −π, the partition's start: cut the last slab at the float π instead
        for k, (a, b) in enumerate(out):
            if a == b == phi:
                break
            if a < phi < b:
                out[k:k + 1] = [(a, phi), (phi, phi), (phi, b)]
                break
            if phi == b and k + 1 < len(out) and out[k + 1][0] == phi and out[k + 1][1] != phi:
                out[k + 1:k + 1] = [(phi, phi)]
                break
    return out


def initial_partition(n: int = 8) -> list[tuple[float, float]]:
    """The search's first slabs: ``n`` equal ones from −π, the last ending one ulp above the float
    π (which is below the true π), so that they cover the circle in exact arithmetic (last b −
    first a > 2π), as a proof needs.

    >>> p = initial_partition(8)
    >>> len(p), p[0][0] == -math.pi, p[-1][1] > math.pi, all(p[k][1] == p[k + 1][0] for k in range(7))
    (8, True, True, True)
    """
    part = [slab_range(k, n) for k in range(n)]
    part[-1] = (part[-1][0], math.nextafter(math.pi, math.inf))
    return part


def bisected(part: list, split=None) -> list[tuple[float, float]]:
    """The slabs ``part`` with those of ``split`` (indices; every one where None) cut in two at
    their middle: the search's refinement, and what a caller preparing its regions reads.

    >>> bisected([(0.0, 1.0), (1.0, 3.0)], {1})
    [(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)]
    """
    out = []
    for k, (a, b) in enumerate(part):
        cut = (split is None or k in split) and a < b
        out += [(a, 0.5 * (a + b)), (0.5 * (a + b), b)] if cut else [(a, b)]
    return out
