"""A collision-free SE(2) path turned into certified Reeds–Shepp curves (Laumond's method).

A Reeds–Shepp car is small-time locally controllable: the shortest Reeds–Shepp curve between
two poses q and q' stays within a neighbourhood of q that shrinks to q as q' -> q (its length
goes to 0 with the poses' distance). So along a collision-free SE(2) path (any robot motion,
sideways and in place included), which keeps a positive distance from the obstacles,
short enough pieces have Reeds–Shepp curves that are free too (Laumond, Jacobs, Taïx and Murray,
"A motion planner for nonholonomic mobile robots", IEEE T-RA 1994).

:func:`to_reeds_shepp` does exactly that: it tries the curve from one pose of the SE(2) path to
the next; where the car motion check (certified: :meth:`cspace.car.motion.CarCSpace.car_motion_free`)
refuses it, the SE(2) motion is cut in half at its middle pose (a free pose: it lies on the free
path) and both halves are tried, down to a depth and a number of checks that bound the work.
Every curve of the result is certified; the conversion fails (None) rather than return one that
is not. It does not prove anything when it fails: the SE(2) path may pass too close to an
obstacle for the curves to follow it within the budget (a path with more clearance converts
with fewer pieces).

A Dubins car (forward only) is not locally controllable: the method does not apply to it.
"""
from __future__ import annotations

import numpy as np

from ..se2.motion import interpolate

MAX_DEPTH = 24        # halvings of one SE(2) motion (2^-24 of it: far below any useful piece)
MAX_CHECKS = 100_000  # curve checks for a whole path, at most (about 6 us each on the compiled path)
# along_travel: where a sideways translation may turn to the way it goes, as fractions of it (the
# ends first: a turn at t in the first half ends it, one at t in the second half starts it)
TURN_AT = (0.0, 0.05, 0.1, 0.2, 0.35, 0.65, 0.8, 0.9, 0.95, 1.0)


def to_reeds_shepp(cspace, path, radius: float, *, max_depth: int = MAX_DEPTH, max_checks: int = MAX_CHECKS,
                   deadline=None) -> np.ndarray | None:
    """Poses along the SE(2) ``path`` (an (N, 3) array whose every motion, OMPL's SE(2)
    interpolation, is collision-free) such that the shortest Reeds–Shepp curve of turning
    ``radius`` between consecutive poses is certified free on ``cspace`` (a
    :class:`cspace.car.motion.CarCSpace`); None when a motion needs more than ``max_depth``
    halvings, the checks exceed ``max_checks`` or ``deadline()`` returns True.

    >>> from cspace.car.motion import CarCSpace
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> walls = [np.array([[0., 0], [4.6, 0], [4.6, 10], [0, 10]]), np.array([[5.4, 0], [10, 0], [10, 10], [5.4, 10]])]
    >>> cs = CarCSpace((0, 10, 0, 10), walls, [box], slabs=16)  # a corridor 0.2 longer than the car
    >>> sideways = np.array([[5.0, 3.0, 0.0], [5.0, 5.0, 0.0]])  # 2 sideways: no one curve fits
    >>> cs.car_motion_free((5.0, 3.0, 0.0), (5.0, 5.0, 0.0), "reeds-shepp", 0.5)
    False
    >>> out = to_reeds_shepp(cs, sideways, 0.5)
    >>> len(out), out[0].tolist(), out[-1].tolist()
    (129, [5.0, 3.0, 0.0], [5.0, 5.0, 0.0])
    >>> all(cs.car_motion_free(tuple(a), tuple(b), "reeds-shepp", 0.5) for a, b in zip(out[:-1], out[1:]))
    True
    """
    rows = [tuple(map(float, p)) for p in np.asarray(path, dtype=np.float64).reshape(-1, 3)]
    if not rows:
        return None
    out = [rows[0]]
    budget = [int(max_checks)]
    for a, b in zip(rows[:-1], rows[1:]):
        if not _convert(cspace, a, b, float(radius), int(max_depth), budget, deadline, out):
            return None
    return np.array(out, dtype=np.float64)


def _convert(cspace, a, b, radius: float, depth: int, budget: list, deadline, out: list) -> bool:
    """Append to ``out`` the poses after ``a`` up to ``b`` whose curves are certified: the curve
    a -> b itself, else the two halves of the SE(2) motion a -> b, depth first (an explicit stack:
    the order of the poses is the path's)."""
    stack = [(a, b, depth)]
    while stack:
        p, q, d = stack.pop()
        if budget[0] <= 0 or (deadline is not None and deadline()):
            return False
        budget[0] -= 1
        if cspace.car_motion_free(p, q, "reeds-shepp", radius):
            out.append(q)
            continue
        if d == 0:
            return False
        m = interpolate(p, q, 0.5)  # on the free SE(2) motion: a free pose
        stack.append((m, q, d - 1))  # popped after the first half is done
        stack.append((p, m, d - 1))
    return True


def along_travel(cspace, path, radius: float) -> np.ndarray:
    """The SE(2) ``path`` with its long sideways translations driven along their own direction: a
    translation p -> q at heading θ (the slab graph translates at the angle of its slab, often across
    the way it goes), longer than 2 ``radius`` and more than 1/20 sideways, becomes a turn in place at
    p to the travel direction φ (or φ + π, the nearer to θ: forward or reverse), the translation at
    φ, and a turn back to θ at q, where :meth:`motion_free` certifies all three (else it is kept);
    where a turn at an end is not free, the first and last places along it (:data:`TURN_AT`) where
    it is, the short pieces before and after still sideways.
    A car drives the new translation as one straight curve, where :func:`to_reeds_shepp` turns a
    sideways one into a chain of parking manoeuvres (on a warehouse map, 87 m sideways: 13 684 curves).

    >>> from cspace.car.motion import CarCSpace
    >>> cs = CarCSpace((0, 10, 0, 10), [np.array([[4., 0], [6, 0], [6, 4], [4, 4]])],
    ...                [np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])], slabs=16)
    >>> along_travel(cs, np.array([[1.0, 6.0, 1.5], [8.0, 6.0, 1.5]]), 0.5).round(6).tolist()
    [[1.0, 6.0, 1.5], [1.0, 6.0, 0.0], [8.0, 6.0, 0.0], [8.0, 6.0, 1.5]]
    """
    import math

    from ..kernel.polygons.rotation import wrap_angle

    rows = [tuple(map(float, p)) for p in np.asarray(path, dtype=np.float64).reshape(-1, 3)]
    out = rows[:1]
    for a, b in zip(rows[:-1], rows[1:]):
        d = math.hypot(b[0] - a[0], b[1] - a[1])
        go = math.atan2(b[1] - a[1], b[0] - a[0])
        if a[2] == b[2] and d > 2.0 * radius and abs(math.sin(go - a[2])) > 0.05:
            phi = go if math.cos(go - a[2]) >= 0.0 else wrap_angle(go + math.pi)
            # where to turn: at the ends, else a little inside (a piece of the free translation at θ
            # is free, so only the turns and the new translation are checked)
            at = [(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])) for t in TURN_AT]
            first = next((m for m in at if cspace.motion_free((*m, a[2]), (*m, phi))), None)
            last = next((m for m in at[::-1] if cspace.motion_free((*m, phi), (*m, a[2]))), None)
            if first is not None and last is not None and at.index(first) < at.index(last) \
                    and cspace.motion_free((*first, phi), (*last, phi)):
                out += [p for p in [(*first, a[2]), (*first, phi), (*last, phi), (*last, a[2])] if p not in (a, b)]
        out.append(b)
    return np.array(out, dtype=np.float64)


def shortcut(cspace, poses, radius: float, *, deadline=None) -> np.ndarray:
    """Fewer poses along a path of certified Reeds–Shepp curves: from each kept pose, the farthest
    later pose that one certified curve reaches (tried from the far end: the last pose, then halfway
    to it, ..., then bisected back between the first reached and the last refused; which poses one
    curve reaches is not monotone: a sideways shift is one S-shaped curve where its short pieces
    are tiny parking manoeuvres), so a path of many short curves from
    :func:`to_reeds_shepp` becomes one of a few long ones before a costlier shortening. Every
    curve of the result is certified; ``deadline()`` True keeps the rest as it is.

    >>> from cspace.car.motion import CarCSpace
    >>> cs = CarCSpace((0, 10, 0, 10), [np.array([[4., 0], [6, 0], [6, 4], [4, 4]])],
    ...                [np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])], slabs=16)
    >>> shortcut(cs, np.array([[1.0, 6.0, 0.0], [2.0, 6.0, 0.0], [3.0, 6.0, 0.0], [8.0, 6.0, 0.0]]), 0.5).tolist()
    [[1.0, 6.0, 0.0], [8.0, 6.0, 0.0]]
    """
    rows = [tuple(map(float, p)) for p in np.asarray(poses, dtype=np.float64).reshape(-1, 3)]
    n = len(rows)
    if n < 3:
        return np.array(rows, dtype=np.float64).reshape(-1, 3)

    def free(i: int, j: int) -> bool:
        return j == i + 1 or cspace.car_motion_free(rows[i], rows[j], "reeds-shepp", radius)

    out, i = [rows[0]], 0
    while i < n - 1:
        if deadline is not None and deadline():
            out.extend(rows[i + 1:])
            break
        # long jumps first: the last pose, then halfway to it, ...
        good, bad, j = i + 1, None, n - 1
        while j > i + 1:
            if free(i, j):
                good = j
                break
            bad, j = j, i + (j - i) // 2
        while bad is not None and bad - good > 1:  # back between the reached and the refused
            mid = (good + bad) // 2
            good, bad = (mid, bad) if free(i, mid) else (good, mid)
        out.append(rows[good])
        i = good
    return np.array(out, dtype=np.float64)
