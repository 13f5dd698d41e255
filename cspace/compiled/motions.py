"""The compiled checks of SE(2) and car motions: handles over a rotating robot's C-space.

Each function here builds, once per C-space, the handle of one compiled routine of the
extension (:mod:`cspace.compiled.fastpath` says which is in use) and returns the call on
it, or None on the pure path; the callers (:mod:`cspace.se2.motion`, :mod:`cspace.car.motion`,
the car words of :mod:`cspace.car.dubins` and :mod:`cspace.car.reeds_shepp`) run their
Python path, the oracle, on None and on every "undecided" answer.
"""
from __future__ import annotations

import functools

import numpy as np

from ..kernel.slabs.slab import ANGLE_SLACK
from .fastpath import contiguous, extension, packed


def se2_motion(cs, max_refine: int, floor_rel: float):
    """The compiled SE(2) motion check of a :class:`cspace.se2.cspace.SE2CSpace`
    (cspace/compiled/_se2motion.c: ``SE2Motions.motion_free``'s split, slab segment tests and
    swept-hull halving in one call): ``(grids, x0, y0, a0, x1, y1, a1) -> int``, 1 free,
    0 not free, -1 undecided (the caller runs the pure path), -2 - k when slab k's
    C-space is not built (``grids[k]`` None: the caller builds it, puts its grid handle
    there and calls again). Angles wrapped, both end poses already free. ``max_refine``
    and ``floor_rel``: the Python path's budget of sweeps per motion and floor (a
    fraction of the extent). None on the pure path or without the SE(2) pose handle
    (a point robot).

    >>> import numpy as np
    >>> from cspace.se2.cspace import SE2CSpace
    >>> cs = SE2CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])],
    ...                [np.array([[-1., -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])], slabs=8)
    >>> f = se2_motion(cs, 2048, 1e-9)
    >>> f is None or f([cs.slab(k)._fast for k in range(8)], 2.5, 2.0, 0.0, 7.5, 2.0, 1.0) == 1
    True
    """
    _fast = extension()
    if not _handles_apply(_fast, cs):
        return None
    (o_off, o_xy), (r_off, r_xy) = packed(cs.obstacle_pieces), packed(cs.robot_pieces)
    handle = _fast.se2_motion_handle(
        cs._fast, cs.checks, contiguous(cs._lo), contiguous(cs._hi), o_off, o_xy, r_off, r_xy,
        cs.slabs, len(cs.obstacle_pieces), len(cs.robot_pieces), int(max_refine), float(cs.scale), float(cs.radius),
        floor_rel * cs.extent, ANGLE_SLACK)
    return functools.partial(_fast.se2_motion, handle)


def car_curve(cs, max_hulls: int, floor_rel: float, arc_chunk: float):
    """The compiled car curve check of a :class:`cspace.se2.cspace.SE2CSpace`
    (cspace/compiled/_carmotion.c: ``CarCSpace.curve_free``'s probe, straight segments and
    arc halving in one call): ``(grids, x, y, th, segments, radius) -> (r, x, y, th)``, r 1
    free, 0 not free, -1 undecided (the caller runs the pure path), -2 - k when slab k's
    C-space is not built (``grids[k]`` None: the caller builds it, puts its grid handle
    there and calls again); (x, y, th) the chain's end (th wrapped), for the join to q1
    that the caller certifies. The start pose: floats, θ wrapped. ``max_hulls``,
    ``floor_rel`` and ``arc_chunk``: the Python path's budget of hulls per curve, floor (a
    fraction of the extent) and initial split of an arc. None on the pure path or without
    the SE(2) pose handle (a point robot).

    >>> import math
    >>> import numpy as np
    >>> from cspace.se2.cspace import SE2CSpace
    >>> cs = SE2CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])],
    ...                [np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])], slabs=16)
    >>> f = car_curve(cs, 4096, 1e-9, math.pi / 8)
    >>> f is None or f([cs.slab(k)._fast for k in range(16)], 2.0, 2.0, 0.0, [("L", math.pi / 2), ("S", 5.0)], 1.0)[0] == 1
    True
    """
    _fast = extension()
    if not _handles_apply(_fast, cs):
        return None
    (o_off, o_xy), (r_off, r_xy) = packed(cs.obstacle_pieces), packed(cs.robot_pieces)
    o_edge = contiguous(np.array([e for edges in cs._obstacle_edges for e in edges], dtype=np.float64).reshape(-1, 4))
    xmin, xmax, ymin, ymax = cs.bounds
    handle = _fast.car_handle(
        cs._fast, cs.checks, contiguous(cs._lo), contiguous(cs._hi), o_off, o_xy, o_edge, r_off,
        r_xy, cs.slabs, len(cs.obstacle_pieces), len(cs.robot_pieces), int(max_hulls), float(cs.scale),
        float(cs.radius), floor_rel * cs.extent, float(arc_chunk), xmin, xmax, ymin, ymax)
    return functools.partial(_fast.car_curve, handle)


def car_motion(curve):
    """The compiled car motion on the handle of ``curve`` (a check :func:`car_curve` made):
    ``(grids, x0, y0, th0, x1, y1, th1, radius, dubins, longest, turns) -> (r, x, y, th)``,
    the segments of :func:`cspace.car.curves.dubins_segments` (``dubins`` true) or
    ``reeds_shepp_segments`` computed in C with their doubles (cspace/compiled/_carwords.c),
    then checked as ``curve`` checks them from q0 (its angle wrapped). r as ``curve``'s, and
    -1 also where the Python segments would take another branch, or a segment would exceed
    ``longest`` (an arc ``turns``): the caller runs the Python path.

    >>> import math
    >>> import numpy as np
    >>> from cspace.se2.cspace import SE2CSpace
    >>> cs = SE2CSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])],
    ...                [np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])], slabs=16)
    >>> c = car_curve(cs, 4096, 1e-9, math.pi / 8)
    >>> grids = [cs.slab(k)._fast for k in range(16)]
    >>> c is None or car_motion(c)(grids, 1.0, 1.0, 0.0, 8.0, 1.0, 0.0, 1.0, False, 1e7, 400.0)[0] == 1
    True
    """
    return functools.partial(extension().car_motion, curve.args[0])


def reeds_shepp_word(x: float, y: float, phi: float):
    """:func:`cspace.car.reeds_shepp.reeds_shepp_word` compiled (cspace/compiled/_carwords.c: the
    same float operations, the same word and doubles), or None on the pure path or where the
    compiled one declines (non-finite or huge values): the caller then runs the Python one.

    >>> reeds_shepp_word(2.0, 0.0, 0.0) in (None, ("LSL", (0.0, 2.0, 0.0)))
    True
    """
    _fast = extension()
    return None if _fast is None else _fast.reeds_shepp_word(x, y, phi)


def dubins_word(d: float, alpha: float, beta: float):
    """:func:`cspace.car.dubins.dubins_word` compiled (cspace/compiled/_carwords.c), or None as
    :func:`reeds_shepp_word`.

    >>> dubins_word(4.0, 0.0, 0.0) in (None, ("LSL", (0.0, 4.0, 0.0)))
    True
    """
    _fast = extension()
    return None if _fast is None else _fast.dubins_word(d, alpha, beta)


def _handles_apply(ext, cs) -> bool:
    """Can a compiled motion handle be made over ``cs``: the extension in use, the SE(2)
    pose handle built (the C-space was made on the compiled path) and a robot to turn?"""
    return ext is not None and getattr(cs, "_fast", None) is not None and bool(cs.robot_pieces)


def car_connect(start, goal, radius: float, bounds, step: float, seed: int, iterations: int, motion_free):
    """A Reeds–Shepp car's RRT-Connect compiled (cspace/compiled/_carrrt.c): ``(path or None,
    iterations, motions asked)``, or None on the pure path (:func:`cspace.car.connect.connect`
    says what it does)."""
    _fast = extension()
    if _fast is None:
        return None
    return _fast.car_connect(*map(float, start), *map(float, goal), float(radius), *map(float, bounds), float(step),
                             int(seed), int(iterations), motion_free)
