"""State-space adapters: what the planning routine needs to know about a robot's poses.

The one planning routine (:func:`planners.core.routine.run_planner`) never touches geometry or
the shape of a state. It asks an adapter for

- ``dim`` and ``state_space()``: the OMPL state space with its bounds;
- ``set_state(state, pose)``: a pose (a tuple of ``dim`` floats) written into an OMPL state;
- ``path_array(path)``: an OMPL ``PathGeometric`` as an (N, dim) float64 array;
- ``validity()`` and ``motion_validator(si)``: OMPL's state checker and motion validator;
- ``is_free(pose)``: whether a pose is a free state (for the query checks);
- ``verify(path, start, goal) -> (ok, message)``: the exact check of a whole path;
- ``length(path)``: the path's length in the space's metric.

:class:`TranslationSpace` is the translating robot: poses (x, y) of the reference point,
states of a 2-D ``RealVectorStateSpace``, validity and motions answered exactly by the
C-space. A rotating robot (poses (x, y, theta), an ``SE2StateSpace``) is another adapter
with the same methods; the routine does not change.

Importing this module does not import OMPL: only ``state_space`` and
``motion_validator`` do, so ``verify`` and ``length`` work without OMPL.
"""
from __future__ import annotations

import contextlib
import math

import numpy as np

from .frame import frame_exponent, path_length, scaled_bounds, verify_path


class TranslationSpace:
    """A translating robot over a :class:`cspace.CSpace`: poses are (x, y).

    OMPL's states are the poses scaled by 2^k (``k`` from :func:`frame_exponent`,
    exact in binary floating point); every answer is given in the C-space's own frame.

    >>> from cspace import CSpace
    >>> cs = CSpace((0, 10, 0, 10), [np.array([[4., 0], [6, 0], [6, 10], [4, 10]])],
    ...             [np.array([[-1., -1], [1, -1], [1, 1], [-1, 1]])])
    >>> ts = TranslationSpace(cs)
    >>> ts.dim, ts.is_free((1.5, 5)), ts.is_free((5, 5))
    (2, True, False)
    >>> ts.verify(np.array([[1.5, 1.5], [2.5, 1.5]]), (1.5, 1.5), (2.5, 1.5))
    (True, 'exact solution')
    >>> ts.length(np.array([[0., 0], [3, 4]]))
    5.0
    """

    name = "translation"
    dim = 2
    # Said when a sampling planner fails: the exact planner decides translation scenes.
    unsolved_hint = ("try --planner exact: it finds the shortest path or proves that none "
                     "exists, in milliseconds")

    def __init__(self, cspace, k: int | None = None):
        self.cspace = cspace
        self.k = frame_exponent(cspace.bounds) if k is None else int(k)

    # ---------------------------------------------------------------- OMPL side

    def state_space(self):
        """A 2-D ``RealVectorStateSpace`` bounded by the C-space's bounds (scaled by 2^k)."""
        from .glue import ompl

        ob = ompl()[0]
        space = ob.RealVectorStateSpace(2)
        space.setBounds(scaled_bounds(ob, self.cspace.bounds, self.k))
        return space

    def set_state(self, state, pose) -> None:
        """Write the pose (x, y) into an OMPL state (scaled by 2^k)."""
        state[0] = math.ldexp(float(pose[0]), self.k)
        state[1] = math.ldexp(float(pose[1]), self.k)

    def path_array(self, path) -> np.ndarray:
        """An OMPL ``PathGeometric`` as an (N, 2) array in the C-space's frame."""
        k = self.k
        if k:
            pts = [(math.ldexp(s[0], -k), math.ldexp(s[1], -k)) for s in path.getStates()]
        else:
            pts = [(s[0], s[1]) for s in path.getStates()]
        return np.array(pts, dtype=np.float64).reshape(-1, 2)

    def validity(self):
        """The state validity checker: a plain function, the cheapest callback OMPL can call.

        (A ``StateValidityChecker`` subclass costs about 0.15 us more per state from
        Python.) States scaled by 2^k are scaled back first.
        """
        cs, k = self.cspace, self.k
        if k:
            test = cs.point_test(cs._points.__next__)
            return lambda s: test(math.ldexp(s[0], -k), math.ldexp(s[1], -k))
        # The test reads ``state[0], state[1]`` itself: one Python frame per state, not two.
        return cs.point_test(cs._points.__next__, state=True)

    def motion_validator(self, si):
        """OMPL's motion validator: the exact segment test of the C-space (no sampling)."""
        return _validator_class()(si, self.cspace, self.k)

    # ---------------------------------------------------------------- exact side

    def pose(self, p) -> tuple:
        """A pose as a tuple of ``dim`` floats.

        >>> TranslationSpace.pose(None, [1, 2])
        (1.0, 2.0)
        """
        return (float(p[0]), float(p[1]))

    def is_free(self, pose) -> bool:
        """Whether the reference point at ``pose`` is a free state (exact)."""
        return bool(self.cspace.is_free((pose[0], pose[1])))

    def verify(self, path: np.ndarray, start, goal) -> tuple[bool, str]:
        """Every segment exactly free, and the path runs from the start to the goal exactly."""
        return verify_path(path, tuple(map(float, start)), tuple(map(float, goal)), self.cspace.segment_free)

    def length(self, path: np.ndarray) -> float:
        """Euclidean length of the polyline of reference points."""
        return path_length(path)

    def counts(self) -> tuple[int, int]:
        """Checks made so far: (state checks, motion checks)."""
        return self.cspace.point_count(), self.cspace.checks["segments"]

    def clearance_functions(self):
        """``(state -> clearance, (state, state) -> clearance)`` on OMPL states, in the
        C-space's units: the distance from the reference point (from the segment, for a
        motion) to the nearest C-obstacle edge, that is, for a free state or motion, how far
        the robot (inflated by the margin, if any) is from touching an obstacle (floats, all
        edges at once: :class:`cspace.translation.clearance.EdgeDistance`)."""
        from cspace.translation.clearance import EdgeDistance

        ed, k = EdgeDistance(self.cspace.pieces), -self.k
        point, segment = ed.point, ed.segment

        def state(s) -> float:
            return point(math.ldexp(s[0], k), math.ldexp(s[1], k))

        def motion(s1, s2) -> float:
            return segment(math.ldexp(s1[0], k), math.ldexp(s1[1], k), math.ldexp(s2[0], k), math.ldexp(s2[1], k))

        return state, motion

    def path_clearance(self, path: np.ndarray):
        """The exact clearance of the ROBOT (not inflated) swept along ``path``
        (:func:`cspace.translation.clearance.path_clearance`)."""
        from cspace.translation.clearance import path_clearance

        return path_clearance(path, self.cspace.robot_pieces, self.cspace.obstacle_pieces)


_classes: dict = {}


def _validator_class():
    if "validator" not in _classes:
        from .glue import ompl

        ob = ompl()[0]

        class ExactMotionValidator(ob.MotionValidator):
            """A motion is valid iff the closed segment lies in the free C-space (exact)."""

            def __init__(self, si, cspace, k: int = 0):
                super().__init__(si)
                self.segment_free = cspace.segment_free
                self.segment = cspace.segment_test()  # four floats: no tuples per motion
                self.k = k

            def checkMotion(self, s1, s2, *rest):
                if self.k:  # states scaled by 2^k (exactly): back to the C-space's frame
                    k = -self.k
                    ok = self.segment_free((math.ldexp(s1[0], k), math.ldexp(s1[1], k)),
                                           (math.ldexp(s2[0], k), math.ldexp(s2[1], k)))
                else:
                    ok = self.segment(s1[0], s1[1], s2[0], s2[1])
                if rest and not ok:  # the (s1, s2, lastValid) form: report no progress
                    with contextlib.suppress(Exception):
                        rest[0].second = 0.0
                return ok

        _classes["validator"] = ExactMotionValidator
    return _classes["validator"]


def validity_function(cspace, k: int = 0):
    """The state validity checker of a translation C-space (see
    :meth:`planners.adapters.translation.TranslationSpace.validity`)."""
    return TranslationSpace(cspace, k).validity()
