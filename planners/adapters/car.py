"""Car-like state spaces: OMPL's Dubins and Reeds–Shepp spaces over the sliced SE(2) C-space.

A car is a rotating robot (poses (x, y, theta), the C-space of :mod:`cspace.se2.cspace`)
whose motions are not straight lines in SE(2) but the shortest Dubins curves
(forward only) or Reeds–Shepp curves (forward and reverse) of a minimum turning
radius. OMPL's ``DubinsStateSpace`` / ``ReedsSheppStateSpace`` give the planners
their metric and interpolation; every motion the planners ask about is recomputed
here as its segments (:mod:`cspace.car.curves`, checked against OMPL's own
``distance`` and ``interpolate`` by the tests) and certified segment by segment
(:meth:`cspace.car.motion.CarCSpace.curve_free`: exact straight segments, arcs bounded by
hulls about the turning centre), never sampled.
"""
from __future__ import annotations

import functools
import math

import numpy as np

from cspace.car.motion import as_car
from cspace.car.curves import curve_length, dubins_segments, knots, pose_along, reeds_shepp_segments

from .se2 import SE2Space
from .frame import scaled_bounds

SEGMENTS_KEPT = 512
FREE_KEPT = 4096  # motions certified free, remembered by their exact floats (CarSpace.motion_free)
# A sampling planner's step (its range) for a car, at most this many turning radii. OMPL's default,
# a fifth of the space's extent, is 20-30 m on a building's map: curves that long between random
# poses nearly always meet a rack or a wall, and the trees stop growing. 40 of the warehouse's
# Reeds-Shepp pairs, plan()'s mean CPU: 159 ms at OMPL's range, 111 ms at 20 radii, 91 ms at 10;
# but 10 radii made Bench-MR's open city grids (Berlin_0_256, r = 4: OMPL's range about 18 radii)
# 2-7x slower. A scene smaller than about 100 radii keeps OMPL's range.
RANGE_RADII = 20.0
SEGMENT_NAMES = {"L": "left", "S": "straight", "R": "right"}


class CarSpace(SE2Space):
    """Adapter for a car: ``kind`` is ``"dubins"`` or ``"reeds-shepp"``, ``radius`` its
    minimum turning radius (OMPL's states and radius scaled by 2^k, exactly)."""

    unsolved_hint = "try a longer --time (a car needs room to turn: check the turning radius)"
    step = "curve"
    # The SE(2) clearance objective follows OMPL's SE(2) interpolation between waypoints, not a
    # car's curves: not inherited. The path's clearance is measured along the curves (path_clearance).
    clearance_functions = None

    def __init__(self, cspace, kind: str, radius: float, k: int | None = None):
        super().__init__(as_car(cspace), k)
        if kind not in ("dubins", "reeds-shepp"):
            raise ValueError(f"CarSpace: kind must be 'dubins' or 'reeds-shepp', got {kind!r}")
        self.name = kind
        self.radius = float(radius)
        curve, r = (dubins_segments if kind == "dubins" else reeds_shepp_segments), self.radius
        # The curves of a path's motions are asked for again and again (its length when it is
        # found, when it is returned, its JSON and picture): the last few hundred are kept.
        self._curve = functools.lru_cache(maxsize=SEGMENTS_KEPT)(lambda q0, q1: curve(q0, q1, r))
        self._test, self._free = None, {}  # the motion check (made on the first motion); free motions
        self._last_length = (None, 0.0)  # the last path measured (its rows) and its length
        # the planners' range bound, in OMPL's scaled units (glue.make_setup keeps OMPL's if smaller)
        self.max_range = math.ldexp(RANGE_RADII * self.radius, self.k)

    def state_space(self):
        from .glue import ompl

        ob = ompl()[0]
        r = math.ldexp(self.radius, self.k)
        space = ob.DubinsStateSpace(r, False) if self.name == "dubins" else ob.ReedsSheppStateSpace(r)
        space.setBounds(scaled_bounds(ob, self.cspace.bounds, self.k))
        return space

    def path_clearance(self, path: np.ndarray):
        """A certified lower bound of the clearance of the ROBOT (body pieces, not inflated)
        driven along the curves of ``path`` (:func:`cspace.car.clearance.car_path_clearance`)."""
        from cspace.car.clearance import car_path_clearance
        from .frame import obstacle_nearest

        return car_path_clearance(path, self.segments, self.radius, self.cspace.body_pieces,
                                  self.cspace.obstacle_pieces, nearest=obstacle_nearest(self.cspace))

    # ---------------------------------------------------------------- curves

    def segments(self, q0, q1) -> list:
        """The motion q0 -> q1 as (kind, signed length) segments (the shortest curve)."""
        if type(q0) is tuple and type(q1) is tuple and 0.0 not in q0 and 0.0 not in q1:
            # the kept curves (a key with a zero is not: 0.0 == -0.0, and their curves may differ)
            return list(self._curve(q0, q1))
        return self._curve.__wrapped__(q0, q1)

    def forget(self) -> None:
        """A new planning run: what this adapter remembered of the last one (free motions, the
        last length) is dropped, so a run repeated on the same adapter (a benchmark's rounds)
        costs what the first did."""
        self._free.clear()
        self._last_length = (None, 0.0)

    def motion_validator(self, si):
        """The certified validator of :class:`SE2Space`, for a new planning run (:meth:`forget`)."""
        self.forget()
        return super().motion_validator(si)

    def motion_free(self, q0, q1) -> bool:
        """Whether the car, driven along the shortest curve from q0 to q1, touches nothing
        (certified: :meth:`cspace.car.motion.CarCSpace.car_motion_free`, through its
        :meth:`~cspace.car.motion.CarCSpace.car_motion_test`).

        A motion certified free is remembered (up to :data:`FREE_KEPT`, by its exact floats,
        none with a zero): the same floats get the same certificate, so the path's re-check
        (:meth:`verify`) of the motions the planner asked costs a look-up each. Only "free"
        is kept; a motion in collision is checked each time it is asked. A new planning run
        (:meth:`motion_validator`) starts with nothing remembered."""
        known, key = self._free, None
        # a key with a zero is not kept: 0.0 == -0.0, and their curves may differ (an angle of ±π)
        if type(q0) is tuple and type(q1) is tuple and 0.0 not in q0 and 0.0 not in q1:
            key = (q0, q1)
            if key in known:
                return True
        test = self._test
        if test is None:
            test = self._test = self.cspace.car_motion_test(self.name, self.radius)
        ok = test(q0, q1)
        if ok and key is not None:
            if len(known) >= FREE_KEPT:
                known.clear()
            known[key] = True
        return ok

    def counts(self) -> tuple[int, int]:
        """Checks made so far: (state checks, motion checks), a car's motion being a curve (the
        SE(2) motions joining a curve's end to its target pose are part of it, not counted)."""
        return self.cspace.state_count(), self.cspace.checks.get("curves", 0)

    def verify(self, path: np.ndarray, start, goal) -> tuple[bool, str]:
        """Every curve between consecutive poses certified free, from the start pose to the goal pose.

        A Dubins curve is one-way (the curve from b to a is not the one from a to b
        reversed); planners that use a motion in both directions (PRM, PRMstar,
        BKPIECE1, ...) can return paths that fail here, and the message says so."""
        ok, msg = super().verify(path, start, goal)
        if not ok and self.name == "dubins":
            msg += (" (Dubins curves are one-way: planners that use a motion in both directions, such as "
                    "PRM, PRMstar and BKPIECE1, return such paths; use RRT, RRTConnect, RRTstar or BITstar)")
        return ok, msg

    def length(self, path: np.ndarray) -> float:
        """The distance driven: the sum of the curves' lengths (OMPL's metric of the space).

        >>> CarSpace.__new__(CarSpace)._len_of([("L", 1.5), ("S", -2.0)])
        3.5
        """
        rows = [tuple(r) for r in np.asarray(path, dtype=np.float64).tolist()]  # Python floats: the fast paths
        if rows == self._last_length[0]:  # a path is measured when it is found and when it is returned
            return self._last_length[1]
        total = float(sum(self._len_of(self.segments(a, b)) for a, b in zip(rows[:-1], rows[1:])))
        if not any(0.0 in r for r in rows):  # 0.0 == -0.0: such rows could be another path's
            self._last_length = (rows, total)
        return total

    @staticmethod
    def _len_of(segments) -> float:
        return curve_length(segments)

    def curves(self, path: np.ndarray) -> list[dict]:
        """Per motion of the path: its start pose and its segments (type, length, direction),
        the JSON form of a car's path."""
        out = []
        for a, b in zip(np.asarray(path)[:-1], np.asarray(path)[1:]):
            segs = self.segments(tuple(a), tuple(b))
            out.append({"from": [float(v) for v in a], "to": [float(v) for v in b],
                        "segments": [{"type": SEGMENT_NAMES[kind], "length": abs(float(ln)),
                                      "direction": "reverse" if ln < 0 else "forward"} for kind, ln in segs]})
        return out

    def dense(self, path: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
        """See :func:`dense_curve`."""
        return dense_curve(path, self.name, self.radius, step)


def dense_curve(path: np.ndarray, kind: str, radius: float, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Poses along a car's path, driven along its curves, about ``step`` apart (each
    segment's ends included), and per pose whether the car drives in reverse there:
    what plots and animations draw (the curves, not the chords between waypoints).

    >>> p, rev = dense_curve(np.array([[0., 0, 0], [2, 0, 0]]), "dubins", 1.0, 0.5)
    >>> p[:, 0].round(6).tolist(), bool(rev.any())
    ([0.0, 0.5, 1.0, 1.5, 2.0, 2.0], False)
    """
    segments = dubins_segments if kind == "dubins" else reeds_shepp_segments
    poses, reverse = [], []
    path = np.asarray(path, dtype=np.float64)
    for a, b in zip(path[:-1], path[1:]):
        segs = [sg for sg in segments(tuple(a), tuple(b), radius) if sg[1] != 0.0]
        for (k, ln), k0 in zip(segs, knots(tuple(a), segs, radius)[:-1]):
            n = max(2, math.ceil(abs(ln) / step) + 1)
            for i in range(n):
                poses.append(pose_along(k0, [(k, ln)], radius, i / (n - 1)))
                reverse.append(ln < 0)
    if len(path):
        poses.append(tuple(path[-1]))
        reverse.append(reverse[-1] if reverse else False)
    return np.array(poses, dtype=np.float64).reshape(-1, 3), np.array(reverse, dtype=bool)
