"""OMPL glue: importing OMPL, the planner names, the setup, the query and the budget.

OMPL never sees geometry: the state-space adapter (:mod:`planners.adapters`) gives the
state space, the validity checker (the C-space's exact point test) and the motion
validator (the exact segment test: no sampling along the segment, so a thin obstacle
cannot be tunnelled through).
"""
from __future__ import annotations

import contextlib
import os
import sys

from cspace.io.load import ScenarioError


_ompl = None


OMPL_HINT = ("OMPL 2 has wheels for Linux and macOS 15 on Python 3.10-3.13: "
             "pip install 'ompl>=2.0.1,<3'")


class OMPLNotInstalled(ModuleNotFoundError):
    """A sampling planner was asked for, but the ``ompl`` package cannot be imported."""


def ompl_available() -> bool:
    """Whether OMPL can be imported here (the exact planner works either way)."""
    try:
        ompl()
    except OMPLNotInstalled:
        return False
    return True


def ompl():
    """Import OMPL once, silence its logging, and return ``(base, geometric, util)``.

    Without OMPL: :class:`OMPLNotInstalled`, saying how to get it.
    """
    global _ompl
    if _ompl is None:
        try:
            with _quiet_fd(2), _sigint_held():
                from ompl import base as ob
                from ompl import geometric as og
                from ompl import util as ou
        except ImportError as exc:
            raise OMPLNotInstalled(f"the sampling planners need OMPL, which is not installed ({OMPL_HINT})",
                                   name="ompl") from exc
        ou.setLogLevel(ou.LOG_NONE)
        _ompl = (ob, og, ou)
    return _ompl


@contextlib.contextmanager
def _sigint_held():
    """Hold Ctrl-C while OMPL's extension starts: a KeyboardInterrupt inside it (nanobind
    building its enums) aborts the process (``terminate called``); it is raised once the
    import is done. Off the main thread nothing can be held (nor delivered)."""
    import signal

    hit = []
    if signal.getsignal(signal.SIGINT) is None:  # a handler set outside Python: it cannot be put back
        yield
        return
    try:
        prev = signal.signal(signal.SIGINT, lambda *_: hit.append(1))
    except ValueError:
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, prev)
    if hit:
        raise KeyboardInterrupt


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
    table["exact"], table["auto"] = "exact", "auto"
    canon = table.get(str(name).lower())
    if canon is None:
        raise ScenarioError(source, field, f"unknown planner {name!r} (choose from: auto, exact, "
                                           f"{', '.join(PLANNERS)})")
    return canon


def make_setup(space, planner: str, seed: int, query: int = 0):
    """A configured ``SimpleSetup`` over a state-space adapter (:mod:`planners.adapters`)
    with the named planner, seeded with query ``query``'s stream (:func:`ompl_seed`).

    ``space`` is an adapter (:mod:`planners.adapters.translation`, ``.se2``, ``.car``). Returns ``(setup, ompl_space, checker, validator)``;
    keep the last two alive as long as the setup is used (OMPL holds them by reference).
    """
    adapter = space
    ob, og, ou = ompl()
    # OMPL ignores seed 0, so user seeds map to seed + 1 (see :func:`ompl_seed`).
    # Re-seeding before any RNG is created makes every plan with the same seed draw
    # the same samples. (Re-seeding later logs an OMPL error, silenced: at LOG_NONE, the
    # level set on import, OMPL writes nothing, and the descriptor is left alone.)
    with _quiet_fd(2) if ou.getLogLevel() != ou.LOG_NONE else contextlib.nullcontext():
        ou.RNG.setSeed(ompl_seed(seed, query))
    ospace = adapter.state_space()
    ss = og.SimpleSetup(ospace)
    si = ss.getSpaceInformation()
    checker = adapter.validity()
    ss.setStateValidityChecker(checker)
    validator = adapter.motion_validator(si)
    si.setMotionValidator(validator)
    chosen = getattr(og, planner)(si)
    cap = getattr(adapter, "max_range", None)
    if cap is not None and hasattr(chosen, "setRange"):
        # OMPL's own range is a fifth of the space's extent (SelfConfig); an adapter may bound it,
        # never below RANGE_FLOOR of it: OMPL's connect step walks to its target in range-long
        # steps without looking at the clock (a car of turning radius 1e-8 in a 10 m scene, its
        # range 2e-7, walked for minutes past a 2 s limit)
        # (an adapter may lower the floor for a turn: ``range_floor``, a Dubins car's restarts)
        own = RANGE_SHARE * si.getMaximumExtent()
        if cap < own:
            chosen.setRange(max(cap, getattr(adapter, "range_floor", RANGE_FLOOR) * own))
    ss.setPlanner(chosen)
    return ss, ospace, checker, validator


RANGE_SHARE = 0.2  # OMPL's default range: this share of the space's maximum extent
RANGE_FLOOR = 0.25  # an adapter's bound on the range: at least this share of OMPL's own


SEED_LIMIT = 2**32 - 1  # OMPL's seeds are 32-bit and must not be 0


def ompl_seed(seed: int, query: int = 0) -> int:
    """OMPL's seed for a user seed and a query index: its own stream per query.

    Query 0 gets ``seed + 1`` (OMPL ignores 0), so a single plan and the first query of
    a multi-query plan draw the same samples; later queries get well-mixed seeds.

    >>> ompl_seed(0), ompl_seed(7), ompl_seed(0, 1) != ompl_seed(1, 0)
    (1, 8, True)
    """
    if query == 0:
        return int(seed) % SEED_LIMIT + 1
    mixed = (int(seed) * 0x9E3779B1 + int(query) * 0x85EBCA77 + 0x165667B1) % (2**32)
    return mixed % SEED_LIMIT + 1


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
                return self.cspace.spaces.clearance((state[0], state[1]))

        _classes["checker"] = CSpaceValidityChecker
    return _classes["checker"](si, cspace)


_classes: dict = {}
GOAL_THRESHOLD = 1e-9


def set_query(ss, adapter, start, goal) -> None:
    """Set the start and goal poses through the adapter, the goal reached within
    ``GOAL_THRESHOLD`` (the rest of the way is appended and verified exactly)."""
    space = ss.getStateSpace()
    s = space.allocState()
    adapter.set_state(s, start)
    g = space.allocState()
    adapter.set_state(g, goal)
    ss.setStartAndGoalStates(s, g, GOAL_THRESHOLD)


MAX_TIME = 1e8  # seconds; OMPL's clock (int64 nanoseconds from now) overflows near 8e9 s


def clamp_time(t: float) -> float:
    """A time limit OMPL's clock can hold (at most ``MAX_TIME``, at least 0).

    >>> clamp_time(1e10), clamp_time(-1.0), clamp_time(0.5)
    (100000000.0, 0.0, 0.5)
    """
    return min(max(float(t), 0.0), MAX_TIME)


def configure(planner, name: str, iterations: int | None) -> None:
    """Planner settings that carry an iteration budget: FMT and BFMT sample that many states.

    (See :mod:`planners.core.routine` for what ``iterations`` means per planner.)
    """
    if iterations and name.lower() in ("fmt", "bfmt"):
        planner.setNumSamples(int(iterations))


def stop_at_first(ss) -> None:
    """Make an anytime planner stop at its first exact solution: the path-length
    objective with an infinite cost threshold, which every solution satisfies (OMPL's
    own stopping rule; without it RRTstar improves until its time limit)."""
    ob = ompl()[0]
    objective = ob.PathLengthOptimizationObjective(ss.getSpaceInformation())
    objective.setCostThreshold(ob.Cost(float("inf")))
    ss.setOptimizationObjective(objective)


def termination(time_limit: float, iterations: int | None = None):
    """Stop at the time limit, or after ``iterations`` evaluations of the condition if given.

    Most planners evaluate the condition once per iteration of their main loop, so an
    iteration budget is deterministic where a time budget is not. The counting
    condition is a Python function: never hand it to a planner that evaluates it on
    a thread of its own (PRM's solution thread: deadlock on the interpreter lock).
    """
    ob = ompl()[0]
    timed = ob.timedPlannerTerminationCondition(clamp_time(time_limit))
    if not iterations:
        return timed, None
    count = [0]

    def spent() -> bool:
        count[0] += 1
        return count[0] > iterations

    it = ob.PlannerTerminationCondition(spent)
    return ob.plannerOrTerminationCondition(timed, it), it
