"""OMPL glue: the state space, the validity checker and motion validator over a C-space.

This module owns everything that touches OMPL's objects. OMPL never sees geometry:
the validity checker asks :meth:`cspace.CSpace.is_free_xy`, the motion validator asks
the exact :meth:`cspace.CSpace.segment_free` (no sampling along the segment, so a thin
obstacle cannot be tunnelled through), and the clearance goes through GJK.
"""
from __future__ import annotations

import contextlib
import math
import os
import sys

from cspace.scenario import ScenarioError

_ompl = None


def ompl():
    """Import OMPL once, silence its logging, and return ``(base, geometric, util)``."""
    global _ompl
    if _ompl is None:
        with _quiet_fd(2):
            from ompl import base as ob
            from ompl import geometric as og
            from ompl import util as ou
        ou.setLogLevel(ou.LOG_NONE)
        _ompl = (ob, og, ou)
    return _ompl


@contextlib.contextmanager
def _quiet_fd(fd: int):
    """Send a file descriptor to /dev/null for the duration (C++ code writes to it directly)."""
    try:
        saved = os.dup(fd)
    except OSError:  # pragma: no cover - no such descriptor
        yield
        return
    try:
        sys.stderr.flush()
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, fd)
        os.close(devnull)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


# Planners of ompl.geometric, by lower-case name. Anytime (optimising) planners keep
# improving until their budget ends; the others stop at their first solution.
PLANNERS = (
    "RRT", "RRTConnect", "RRTstar", "InformedRRTstar", "SORRTstar", "BITstar", "AORRTC",
    "PRM", "PRMstar", "FMT", "BFMT", "KPIECE1", "BKPIECE1", "LBKPIECE1",
)
ANYTIME = {"rrtstar", "informedrrtstar", "sorrtstar", "bitstar", "aorrtc", "prm", "prmstar"}
DEFAULT_PLANNER = "RRTConnect"


def planner_name(name: str | None, source: str = "<options>", field: str = "planner") -> str:
    """Canonical spelling of a planner name (case-insensitive), or a ScenarioError.

    >>> planner_name("rrtconnect")
    'RRTConnect'
    """
    if name is None:
        return DEFAULT_PLANNER
    table = {p.lower(): p for p in PLANNERS}
    table["exact"] = "exact"
    canon = table.get(str(name).lower())
    if canon is None:
        raise ScenarioError(source, field, f"unknown planner {name!r} (choose from: exact, {', '.join(PLANNERS)})")
    return canon


def frame_exponent(bounds) -> int:
    """The power of two k OMPL's states are scaled by: 0 for scenes of ordinary size.

    OMPL has absolute thresholds (a longest valid segment must exceed machine epsilon,
    the goal is reached within ``GOAL_THRESHOLD``), so a scene 1e-17 across cannot be
    planned as it is. Scenes whose extent leaves [2^-20, 2^100] are planned in a frame
    scaled by 2^k to an extent near 1: exact, so the C-space's answers, and so the
    path (scaled back), are the same. The hot path pays nothing when k is 0.

    >>> frame_exponent((0.0, 10.0, 0.0, 10.0)), frame_exponent((0.0, 1e-17, 0.0, 1e-17))
    (0, 56)
    """
    xmin, xmax, ymin, ymax = map(float, bounds)
    extent = max(xmax - xmin, ymax - ymin)
    if not (0.0 < extent < math.inf) or 2.0**-20 <= extent <= 2.0**100:
        return 0
    return -math.frexp(extent)[1]


def make_setup(cspace, planner: str, seed: int, k: int = 0):
    """A configured ``SimpleSetup`` over ``cspace`` with the named planner, seeded,
    its states scaled by 2^k (:func:`frame_exponent`).

    Returns ``(setup, space, checker, validator)``; keep the last two alive as long
    as the setup is used (OMPL holds them by reference).
    """
    ob, og, ou = ompl()
    # OMPL ignores seed 0, so user seeds map to seed + 1. Re-seeding before any
    # RNG is created makes every plan with the same seed draw the same samples.
    with _quiet_fd(2):
        ou.RNG.setSeed(int(seed) + 1)
    space = ob.RealVectorStateSpace(2)
    xmin, xmax, ymin, ymax = (math.ldexp(float(v), k) for v in cspace.bounds)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0, xmin)
    bounds.setHigh(0, xmax)
    bounds.setLow(1, ymin)
    bounds.setHigh(1, ymax)
    space.setBounds(bounds)
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    checker = validity_function(cspace, k)
    ss.setStateValidityChecker(checker)
    validator = _validator_class()(si, cspace, k)
    si.setMotionValidator(validator)
    ss.setPlanner(getattr(og, planner)(si))
    return ss, space, checker, validator


_classes: dict = {}


def validity_function(cspace, k: int = 0):
    """The state validity checker: a plain function, the cheapest callback OMPL can call.

    (A ``StateValidityChecker`` subclass costs about 0.15 us more per state from Python;
    :func:`clearance_checker` provides one, with ``clearance``, for the planners that
    ask for it.) States scaled by 2^k are scaled back first.
    """
    if k:
        test = cspace.point_test(cspace._points.__next__)
        return lambda s: test(math.ldexp(s[0], -k), math.ldexp(s[1], -k))
    # The test reads ``state[0], state[1]`` itself: one Python frame per state, not two.
    return cspace.point_test(cspace._points.__next__, state=True)


def clearance_checker(si, cspace):
    """A ``StateValidityChecker`` whose ``clearance`` is the GJK distance to the C-obstacles."""
    if "checker" not in _classes:
        ob = ompl()[0]

        class CSpaceValidityChecker(ob.StateValidityChecker):
            """Validity = the reference point is a free state; clearance via GJK."""

            def __init__(self, si, cspace):
                super().__init__(si)
                self.is_free_xy = cspace.is_free_xy
                self.cspace = cspace

            def isValid(self, state):
                return self.is_free_xy(state[0], state[1])

            def clearance(self, state):
                return self.cspace.clearance((state[0], state[1]))

        _classes["checker"] = CSpaceValidityChecker
    return _classes["checker"](si, cspace)


def _validator_class():
    if "validator" not in _classes:
        ob = ompl()[0]

        class ExactMotionValidator(ob.MotionValidator):
            """A motion is valid iff the closed segment lies in the free C-space (exact)."""

            def __init__(self, si, cspace, k: int = 0):
                super().__init__(si)
                self.segment_free = cspace.segment_free
                self.k = k

            def checkMotion(self, s1, s2, *rest):
                if self.k:  # states scaled by 2^k (exactly): back to the C-space's frame
                    k = -self.k
                    ok = self.segment_free((math.ldexp(s1[0], k), math.ldexp(s1[1], k)),
                                           (math.ldexp(s2[0], k), math.ldexp(s2[1], k)))
                else:
                    ok = self.segment_free((s1[0], s1[1]), (s2[0], s2[1]))
                if rest and not ok:  # the (s1, s2, lastValid) form: report no progress
                    with contextlib.suppress(Exception):
                        rest[0].second = 0.0
                return ok

        _classes["validator"] = ExactMotionValidator
    return _classes["validator"]


GOAL_THRESHOLD = 1e-9


def set_query(ss, space, start, goal, k: int = 0) -> None:
    """Set the start and goal states, scaled by 2^k, the goal reached within
    ``GOAL_THRESHOLD`` (the rest of the way is appended and verified exactly)."""
    s = space.allocState()
    s[0], s[1] = math.ldexp(float(start[0]), k), math.ldexp(float(start[1]), k)
    g = space.allocState()
    g[0], g[1] = math.ldexp(float(goal[0]), k), math.ldexp(float(goal[1]), k)
    ss.setStartAndGoalStates(s, g, GOAL_THRESHOLD)


def termination(time_limit: float, iterations: int | None = None):
    """Stop at the time limit, or after ``iterations`` planner iterations if given.

    OMPL evaluates the condition once per planner iteration, so an iteration budget
    is deterministic where a time budget is not (for anytime planners).
    """
    ob = ompl()[0]
    timed = ob.timedPlannerTerminationCondition(float(time_limit))
    if not iterations:
        return timed, None
    count = [0]

    def spent() -> bool:
        count[0] += 1
        return count[0] > iterations

    it = ob.PlannerTerminationCondition(spent)
    return ob.plannerOrTerminationCondition(timed, it), it


def path_states(path, k: int = 0) -> list[tuple[float, float]]:
    """States of an OMPL PathGeometric as (x, y) tuples, scaled back by 2^-k."""
    if k:
        return [(math.ldexp(s[0], -k), math.ldexp(s[1], -k)) for s in path.getStates()]
    return [(s[0], s[1]) for s in path.getStates()]
