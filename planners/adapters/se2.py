"""The SE(2) state space: OMPL's SE2StateSpace over the sliced C-space of a rotating robot.

The planning routine talks to a state-space adapter (see :mod:`planners.adapters`, whose
methods this one has); this is the one for robots that translate *and* rotate. OMPL interpolates x, y linearly and
theta along the shorter arc; the validity checker asks the sliced C-space
(:meth:`cspace.se2.cspace.SE2CSpace.pose_test`: a slab's certified FREE answer, else the exact
test of the robot turned to theta) and the motion validator asks
:meth:`cspace.se2.cspace.SE2CSpace.motion_free`, a certificate along the whole motion (never a
sample). Weights as OMPL.app: R^2 x 1, SO(2) x 0.5.
"""
from __future__ import annotations

import contextlib
import math
import time

import numpy as np

from .frame import frame_exponent, path_length, scaled_bounds, verify_path

SO2_WEIGHT = 0.5

_classes: dict = {}


class SE2Space:
    """Adapter for SE(2): poses (x, y, theta), OMPL states scaled by 2^k in x and y."""

    dim = 3
    name = "se2"
    step = "motion"  # what verify() calls one step of a path
    # Said when a sampling planner fails (the inscribed-disk rule has already been tried).
    unsolved_hint = "try a longer --time, or more --slabs for a tighter C-space near obstacles"

    def __init__(self, cspace, k: int | None = None):
        self.cspace = cspace
        self.k = frame_exponent(cspace.bounds) if k is None else int(k)

    def clearance_functions(self):
        """``(state -> clearance, (state, state) -> clearance)`` on OMPL states: the GJK
        distance from the (inflated) robot at the pose to the nearest obstacle piece; a
        motion takes the least of its two ends and its middle pose (a sample: this feeds
        the optimisation objective only; the reported clearance is certified)."""
        from cspace.translation.clearance import Nearest
        from cspace.se2.motion import interpolate
        from cspace.kernel.polygons.rotation import rotate_piece

        near, k = Nearest(self.cspace.obstacle_pieces), -self.k
        pieces = self.cspace.robot_pieces or [np.zeros((1, 2))]

        def at(x: float, y: float, th: float) -> float:
            return min(near.distance(rotate_piece(p, th) + (x, y)) if len(p) > 2 else near.distance(p + (x, y))
                       for p in pieces)

        def state(s) -> float:
            return at(math.ldexp(s.getX(), k), math.ldexp(s.getY(), k), s.getYaw())

        def motion(s1, s2) -> float:
            q0 = (math.ldexp(s1.getX(), k), math.ldexp(s1.getY(), k), s1.getYaw())
            q1 = (math.ldexp(s2.getX(), k), math.ldexp(s2.getY(), k), s2.getYaw())
            return min(at(*q0), at(*q1), at(*interpolate(q0, q1, 0.5)))

        return state, motion

    def path_clearance(self, path: np.ndarray, deadline: float | None = None):
        """A certified lower bound of the clearance of the ROBOT (body pieces, not inflated)
        along ``path`` (:func:`cspace.se2.clearance.se2_path_clearance`; refined until
        ``deadline``, a ``time.perf_counter()`` value, at most)."""
        from cspace.se2.clearance import se2_path_clearance
        from .frame import obstacle_nearest

        return se2_path_clearance(path, self.cspace.body_pieces, self.cspace.obstacle_pieces,
                                  nearest=obstacle_nearest(self.cspace), deadline=deadline)

    def state_space(self):
        from .glue import ompl

        ob = ompl()[0]
        space = ob.SE2StateSpace()
        space.setBounds(scaled_bounds(ob, self.cspace.bounds, self.k))
        space.setSubspaceWeight(1, SO2_WEIGHT)
        return space

    def set_state(self, state, pose) -> None:
        """Write the pose (x, y, theta) into an OMPL SE(2) state (x, y scaled by 2^k)."""
        state.setX(math.ldexp(float(pose[0]), self.k))
        state.setY(math.ldexp(float(pose[1]), self.k))
        state.setYaw(float(pose[2]))

    def path_array(self, path) -> np.ndarray:
        """An OMPL ``PathGeometric`` as an (N, 3) array of poses in the C-space's frame."""
        k = -self.k
        return np.array([(math.ldexp(s.getX(), k), math.ldexp(s.getY(), k), s.getYaw()) for s in path.getStates()],
                        dtype=np.float64).reshape(-1, 3)

    def validity(self):
        test = self.cspace.pose_test()
        if self.k:
            k = -self.k
            return lambda s: test(math.ldexp(s.getX(), k), math.ldexp(s.getY(), k), s.getYaw())
        return lambda s: test(s.getX(), s.getY(), s.getYaw())

    def motion_validator(self, si):
        if "validator" not in _classes:
            from .glue import ompl

            ob = ompl()[0]

            class CertifiedSE2MotionValidator(ob.MotionValidator):
                """A motion is valid iff the robot, moved as the adapter moves it (OMPL's SE(2)
                interpolation, or a car's curve), touches nothing: certified, never sampled."""

                def __init__(self, si, adapter):
                    super().__init__(si)
                    self.motion_free = adapter.motion_free
                    self.k = -adapter.k

                def checkMotion(self, s1, s2, *rest):
                    k = self.k
                    ok = self.motion_free((math.ldexp(s1.getX(), k), math.ldexp(s1.getY(), k), s1.getYaw()),
                                          (math.ldexp(s2.getX(), k), math.ldexp(s2.getY(), k), s2.getYaw()))
                    if rest and not ok:  # the (s1, s2, lastValid) form: report no progress
                        with contextlib.suppress(Exception):
                            rest[0].second = 0.0
                    return ok

            _classes["validator"] = CertifiedSE2MotionValidator
        return _classes["validator"](si, self)

    def motion_free(self, q0, q1) -> bool:
        """Whether the robot, moved along OMPL's SE(2) interpolation from q0 to q1, touches
        nothing (certified: :meth:`cspace.se2.cspace.SE2CSpace.motion_free`)."""
        return self.cspace.motion_free(q0, q1)

    def pose(self, p) -> tuple:
        """A pose as a tuple of 3 floats (theta 0 when only (x, y) is given).

        >>> SE2Space.pose(None, [1, 2, 0.5]), SE2Space.pose(None, (1, 2))
        ((1.0, 2.0, 0.5), (1.0, 2.0, 0.0))
        """
        return (float(p[0]), float(p[1]), float(p[2]) if len(p) > 2 else 0.0)

    def is_free(self, pose) -> bool:
        """Whether the robot at ``pose`` (x, y, theta) touches nothing."""
        return bool(self.cspace.is_free(tuple(pose)))

    def verify(self, path: np.ndarray, start, goal) -> tuple[bool, str]:
        """Every motion certified free, from the start pose exactly to the goal pose exactly."""
        return self._verify_with(path, start, goal, self.motion_free)

    def _verify_with(self, path: np.ndarray, start, goal, motion_free) -> tuple[bool, str]:
        return verify_path(path, self.pose(start), self.pose(goal), motion_free, step=self.step,
                           test="certified", ends="the start pose to the goal pose")

    def verify_until(self, path: np.ndarray, start, goal, deadline: float | None) -> tuple[bool, str, int | None]:
        """:meth:`verify` that stops at ``deadline`` (a ``time.perf_counter()`` value, looked at
        before each motion): (ok, why, None) when it ran to its end, else (True, why, k) after k
        motions all free (the rest not checked: the caller says so)."""
        if deadline is None:
            return (*self.verify(path, start, goal), None)
        done = [0]

        class Late(Exception):
            pass

        def motion_free(a, b) -> bool:
            if time.perf_counter() >= deadline:
                raise Late
            done[0] += 1
            return self.motion_free(a, b)

        try:
            ok, why = self._verify_with(path, start, goal, motion_free)
        except Late:
            return True, f"{done[0]} of {len(path) - 1} motions re-checked before the time limit", done[0]
        return ok, why, None

    def length(self, path: np.ndarray) -> float:
        """Length travelled by the reference point (the bound of the inscribed disk bounds it)."""
        return path_length(path)

    def counts(self) -> tuple[int, int]:
        """Checks made so far: (state checks, motion checks)."""
        return self.cspace.state_count(), self.cspace.checks.get("motions", 0)
