"""A car's reach on a lattice of short certified moves, breadth first: an under-approximation of
where it can drive from a pose, used to tell cheaply whether one end of a query is boxed in.

From the seed, every pose reached drives one short move -- a left arc, a straight, a right arc,
each of length :data:`STEP` turning radii, forward (or backward, for the poses that reach the seed
driving forward) -- and each move whose swept poses the car C-space certifies free
(:meth:`cspace.car.motion.CarCSpace.curve_free`) gives a new pose, kept once per lattice cell
(:data:`CELL` radii a side, :data:`TURN` rad of heading). Every pose returned is joined to the seed
by a chain of certified moves, so it is truly reachable; the converse does not hold (the lattice
drives only three curvatures and keeps one pose per cell), so a small lattice is a hint, never a
proof: a Dubins car whose lattice stops short of ``cap`` poses is worth a reach proof
(:func:`cspace.car.dubins_reach.reach_proof`) at once, where one in the open is not.
"""
from __future__ import annotations

import math
from collections import deque

from .curves import advance

STEP = 0.1    # a move's length, in turning radii (a heading change of 0.1 rad on an arc)
CELL = 0.06   # a lattice cell's side, in turning radii
TURN = 0.05   # ... and its heading span (rad): an arc's move changes the cell
MOVES = ("L", "S", "R")


def _cell(q, r: float) -> tuple[int, int, int]:
    return (round(q[0] / (CELL * r)), round(q[1] / (CELL * r)), round((q[2] % (2.0 * math.pi)) / TURN))


def lattice_reach(car, pose, radius: float, *, backward: bool = False, cap: int = 300) -> list[tuple]:
    """The poses the car reaches from ``pose`` by chains of certified short moves, breadth first,
    at most ``cap`` of them (``backward``: driving in reverse, the poses from which the car
    reaches ``pose`` driving forward). ``car``: a :class:`cspace.car.motion.CarCSpace`.

    >>> import numpy as np
    >>> from cspace.car.motion import CarCSpace
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> walls = [np.array([[0., 0], [10, 0], [10, 1.15], [0, 1.15]]), np.array([[0., 1.85], [10, 1.85], [10, 3], [0, 3]])]
    >>> car = CarCSpace((0, 10, 0, 3), walls, [box], slabs=16)
    >>> len(lattice_reach(car, (5.0, 1.5, math.pi / 2), 1.0))  # across a 0.7 m corridor: stuck at once
    1
    >>> len(lattice_reach(car, (5.0, 1.5, 0.0), 1.0, cap=50))  # along it: free to go
    50
    """
    r = float(radius)
    length = -STEP * r if backward else STEP * r
    seed = tuple(float(v) for v in pose)
    seen = {_cell(seed, r)}
    out = [seed]
    todo = deque(out)
    while todo and len(out) < cap:
        q = todo.popleft()
        for kind in MOVES:
            if not car.curve_free(q, [(kind, length)], r):
                continue
            q1 = advance(q, kind, length, r)
            key = _cell(q1, r)
            if key not in seen:
                seen.add(key)
                out.append(q1)
                todo.append(q1)
                if len(out) >= cap:
                    break
    return out


def boxed_in(car, pose, radius: float, *, backward: bool = False, cap: int = 300) -> bool:
    """Whether the car's lattice from ``pose`` (:func:`lattice_reach`) ends before ``cap`` poses:
    a hint that the end is boxed in, never a proof.

    >>> import numpy as np
    >>> from cspace.car.motion import CarCSpace
    >>> box = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    >>> car = CarCSpace((0, 10, 0, 10), [np.array([[4., 4], [6, 4], [6, 6], [4, 6]])], [box], slabs=16)
    >>> boxed_in(car, (2.0, 2.0, 0.0), 1.0, cap=60), boxed_in(car, (2.0, 2.0, 0.0), 1.0, backward=True, cap=60)
    (False, False)
    """
    return len(lattice_reach(car, pose, radius, backward=backward, cap=cap)) < cap
