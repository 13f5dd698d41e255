"""The one planning routine: set up, query, solve, simplify, snap, verify, with OMPL.

``cspace plan``, ``planners.plan()`` and every ``cspace bench`` run call
:func:`run_planner`; the bench only asks for anytime planners to be solved in time
slices (``slices=True``) to time the first solution and record the best length along
the run. The routine talks to a state-space adapter (:mod:`planners.adapters`), never
to the geometry, so a rotating robot is another adapter, not another routine.

Budgets. ``time_limit`` always holds. ``iterations`` (deterministic where the time
limit is not reached) means, per planner:

- most planners (the RRT family, BITstar, AORRTC, the KPIECE family): iterations of
  the planner's main loop, counted on OMPL's termination condition (evaluated once per
  iteration: BITstar's own ``numIterations()`` agrees; an iteration of BITstar
  processes one edge, one of LBKPIECE1 adds one unchecked motion, motions being
  checked only when the trees meet, so these need thousands);
- FMT and BFMT (batch planners that sample first): the number of samples;
- PRM and PRMstar: iterations growing the roadmap (about one milestone each), run on
  this thread before the query (a Python condition evaluated on PRM's own solution
  thread would deadlock); the query then connects to the roadmap, growing it further
  only if needed, within the time limit. (PRM checks for a solution on a thread of
  its own, so its path can still differ from run to run.)

Ctrl-C during a solve stops OMPL through its termination condition (a planner
thread is never torn down by an exception) and raises KeyboardInterrupt afterwards.
"""
from __future__ import annotations

import math
import signal
import time

import numpy as np

from .result import PlanResult

# Anytime planners solved in slices (``slices=True``): MIN_SLICE s, doubling up to
# budget / SLICES. Calling solve() again continues the same search in these planners
# (not in AORRTC, which crashed under repeated solves).
SLICES = 20
MIN_SLICE = 0.002
SLICED = {"rrtstar", "informedrrtstar", "sorrtstar", "bitstar", "prm", "prmstar"}
ANYTIME = SLICED | {"aorrtc"}
ROADMAP = {"prm", "prmstar"}  # multi-query: the roadmap is kept from query to query
BATCH = {"fmt", "bfmt"}  # iterations = samples
QUERY_SLICE = 0.01  # PRM with an iteration budget: the query is solved in slices this long
# Planners run in a forked child with a wall-clock guard: OMPL 2.0's AORRTC has been
# seen to busy-loop far past its time limit. The guard is time_limit * 1.5 + GUARD_MARGIN.
GUARDED = {"aorrtc"}
GUARD_MARGIN = 2.0


def _now() -> float:
    return time.perf_counter()


def run_planner(space, name: str, queries: list, time_limit: float, seed: int, *,
                iterations: int | None = None, simplify: bool = True, slices: bool = False,
                on_progress=None, scenario: str = "", until_first: bool = False,
                objective: str = "length", keep: list | None = None) -> list[PlanResult]:
    """THE planning routine: one OMPL planner over a state-space adapter, for each query.

    ``space`` is an adapter of :mod:`planners.adapters`; ``queries`` is a list of
    ``(start, goal)`` poses of its dimension, already checked to be free. Per query:
    set up (seeded with the query's own stream; PRM-family planners keep their
    roadmap from query to query), set the query, solve within ``time_limit`` seconds
    (and ``iterations`` if given, see the module's notes), simplify, snap the last
    step to the exact goal, and verify exactly through the adapter.

    With ``slices``, anytime planners are solved in slices of the same total budget
    so that the time of the first solution (to within one slice) and the best raw
    length along the run are recorded in ``first_solution`` and ``progress``;
    ``on_progress(t, length)`` is called at each recorded point.

    With ``until_first`` (the peer benchmark, ``scripts/bench_planning.py``) an anytime
    planner stops at its first exact solution, by OMPL's own rule: the path-length
    objective gets an infinite cost threshold, which any solution satisfies. No slices
    are needed then: the first solution is the end of the solve.
    ``objective`` (:mod:`planners.adapters.objectives`): ``length`` (OMPL's default, nothing set),
    ``clearance`` (maximise the minimum clearance) or ``balanced``; it matters to the
    optimising planners (RRTstar, PRMstar, BITstar, ...).

    ``keep`` (one query; a list the caller keeps, ``[None]`` at first): the planner's setup is
    kept there, and a later call with the same list and query continues the same search where
    the earlier one stopped (its trees, its random stream) instead of starting again: turns of
    one search (``auto``'s), the second counting only its own iterations.
    """
    key = name.lower()
    out = []
    if keep is not None and len(queries) != 1:
        raise ValueError("run_planner: keep continues one query's search; got several queries")
    held = [None] if keep is None else keep  # the roadmap planners' setup, kept from query to query
    for i, (start, goal) in enumerate(queries):
        args = (space, name, key, held, i, start, goal, time_limit, seed, iterations, simplify,
                slices and not until_first, on_progress, objective, scenario, until_first,
                keep is not None and held[0] is not None)
        if tuple(start) == tuple(goal):  # nothing to plan: the one-point path
            out.append(_trivial(space, name, seed, scenario, start, goal))
        elif key == "aorrtc" and space.verify(np.array([start, goal], dtype=np.float64), start, goal)[0]:
            out.append(_straight(space, name, seed, scenario, start, goal))
        elif key in GUARDED:
            out.append(_guarded(args, time_limit * 1.5 + GUARD_MARGIN))
        else:
            out.append(_plan_query(*args))
    return out


def _plan_query(space, name, key, held, i, start, goal, time_limit, seed, iterations, simplify, slices,
                on_progress, objective, scenario, until_first=False, resume=False) -> PlanResult:
    from ..adapters.glue import configure, make_setup, set_query, stop_at_first

    t0 = _now()
    if resume:  # the same query's search, continued: its setup, trees and random stream as they are
        pass
    elif held[0] is None or key not in ROADMAP:
        held[0] = make_setup(space, name, seed, query=i)
        configure(held[0][0].getPlanner(), name, iterations)
        if until_first and key in ANYTIME:
            stop_at_first(held[0][0])
        if objective != "length":
            from ..adapters.objectives import make_objective

            obj = make_objective(objective, held[0][0].getSpaceInformation(), space)
            held[0][0].setOptimizationObjective(obj)
            held[0] = (*held[0], obj)  # OMPL holds the objective by reference: keep it alive
    else:
        held[0][0].getPlanner().clearQuery()  # keep the roadmap, drop the old start and goal
    ss = held[0][0]
    if not resume:
        set_query(ss, space, start, goal)
    setup_s = _now() - t0
    c0 = space.counts()
    t1, cpu1 = _now(), time.process_time()
    first, progress = _solve(ss, space, key, time_limit, iterations, slices, on_progress)
    solve_s = _now() - t1
    # an anytime planner's first solution came before the end of its solve: known when the
    # bench's slices timed it, else not
    timed = slices and key in SLICED and not iterations and first is not None
    found_cpu = time.process_time() if key not in ANYTIME else cpu1 + first if timed else None
    status = ss.getLastPlannerStatus()
    found = ss.haveExactSolutionPath()
    raw = _snap(space.path_array(ss.getSolutionPath()), goal) if found else None
    t2 = _now()
    # OMPL's simplifier shortens paths, trading clearance away: kept for the length objective only.
    simplify = simplify and objective == "length"
    if found and simplify:
        ss.simplifySolution()
    simp_s = _now() - t2 if found and simplify else 0.0
    path = (_snap(space.path_array(ss.getSolutionPath()), goal) if simplify else raw) if found else None
    t3 = _now()
    ok, message = space.verify(path, start, goal) if found else (False, failure_message(status, space, objective))
    if found and not ok:
        message = f"OMPL's path failed the exact check ({message}): not solved"
    verify_s = _now() - t3
    c1 = space.counts()
    checks = {"states": c1[0] - c0[0], "motions": c1[1] - c0[1]}
    # A car's length recomputes its curves: once when the simplifier left the path as it was.
    length = space.length(path) if ok else math.inf
    raw_length = (length if np.array_equal(raw, path) else space.length(raw)) if ok else None
    if slices:  # the bench's run: the planner's graph size, as OMPL's benchmark records it
        checks["graph_states"] = graph_states(ss)
    if ok and key in ANYTIME and iterations is None and solve_s >= 0.9 * time_limit:
        message += " (anytime planner: ran to its time limit)"
    return PlanResult(
        scenario=scenario, solved=ok, exact=ok, path=path if ok else np.zeros((0, space.dim)),
        length=length, planner=name, seed=seed,
        timings={"setup": setup_s, "solve": solve_s, "simplify": simp_s, "verify": verify_s},
        checks=checks,
        stages=["setup", "solve"] + (["simplify"] if found and simplify else []) + ["verify"],
        start=tuple(start), goal=tuple(goal), message=message,
        length_unsimplified=raw_length,
        first_solution=first if ok else None, progress=progress, first_path_cpu=found_cpu if ok else None,
    )


def graph_states(ss) -> int | None:
    """The number of vertices in the planner's graph (OMPL's "graph states"), or None where
    the planner cannot say."""
    from ..adapters.glue import ompl

    try:
        data = ompl()[0].PlannerData(ss.getSpaceInformation())
        ss.getPlannerData(data)
        return int(data.numVertices())
    except Exception:  # a planner without planner data: not known
        return None


class _Interrupt:
    """Ctrl-C while OMPL solves: terminate the current condition, remember it.

    Raising KeyboardInterrupt inside a Python callback would unwind through OMPL's
    C++ (PRM then aborts: "terminate called without an active exception"); setting
    the condition's terminate flag lets every planner stop on its own.
    """

    def __init__(self):
        self.ptc, self.hit, self.prev = None, False, None

    def __enter__(self):
        try:
            self.prev = signal.signal(signal.SIGINT, self._handler)
        except ValueError:  # not the main thread (or no signals): nothing to catch
            self.prev = None
        return self

    def _handler(self, *_):
        self.hit = True
        if self.ptc is not None:
            self.ptc.terminate()

    def solve(self, ss, ptc, call=None):
        if self.hit:
            raise KeyboardInterrupt
        self.ptc = ptc
        (call or ss.solve)(ptc)
        self.ptc = None
        if self.hit:
            raise KeyboardInterrupt

    def __exit__(self, *exc):
        if self.prev is not None:
            signal.signal(signal.SIGINT, self.prev)
        return False


def _solve(ss, space, key, time_limit, iterations, slices, on_progress):
    """Solve within the budget; returns (time of the first exact solution, progress)."""
    from ..adapters.glue import clamp_time, ompl, termination

    ob = ompl()[0]
    first, progress = None, []
    t0 = _now()

    def record():
        nonlocal first
        if ss.haveExactSolutionPath():
            t = _now() - t0
            first = t if first is None else first
            progress.append([t, space.length(space.path_array(ss.getSolutionPath()))])
            if on_progress is not None:
                on_progress(*progress[-1])

    with _Interrupt() as guard:
        if slices and key in SLICED and not iterations:
            # Continue the same search slice by slice: same total budget. Slices double
            # from MIN_SLICE up to budget / SLICES, so an early first solution is timed
            # finely and a long run still takes few slices.
            step, n = max(time_limit / SLICES, MIN_SLICE), 0
            while (left := time_limit - (_now() - t0)) > 0:
                guard.solve(ss, ob.timedPlannerTerminationCondition(min(step, MIN_SLICE * 2 ** n, left)))
                n += 1
                record()
        elif key in ROADMAP and iterations:
            ss.setup()
            grow, _keep = termination(time_limit, iterations)
            guard.solve(ss, grow, ss.getPlanner().growRoadmapPtc)
            # The query: short slices until it is connected (PRMstar would otherwise
            # keep improving to the time limit), within the time limit.
            while not ss.haveExactSolutionPath() and (left := clamp_time(time_limit - (_now() - t0))) > 0:
                guard.solve(ss, ob.timedPlannerTerminationCondition(min(left, QUERY_SLICE)))
            record()
        else:
            ptc, _keep = termination(time_limit, None if key in BATCH else iterations)
            guard.solve(ss, ptc)
            record()
    return first, progress


def failure_message(status, space=None, objective: str = "length") -> str:
    """Why a sampling planner did not solve, in plain words (OMPL's status explained).

    >>> failure_message("Timeout")
    'no path found within the budget (OMPL: Timeout)'
    """
    text = str(status)
    if "Approximate" in text:
        msg = ("no path found within the budget (OMPL's \"Approximate solution\": its best path only "
               "comes near the goal, it does not reach it)")
    else:
        msg = f"no path found within the budget (OMPL: {text})"
    from ..adapters.objectives import unsolved_hint

    hint = unsolved_hint(objective, getattr(space, "unsolved_hint", None))
    return msg + (f"; {hint}" if hint else "")


def _guarded(args, limit: float) -> PlanResult:
    """Plan one query in a forked child, killed past ``limit`` seconds (wall clock)."""
    from ..children import CAN_FORK, call_in_child

    if not CAN_FORK:
        return _plan_query(*args)
    space, name, key, held, i, start, goal, time_limit, seed = args[:9]
    ok, res = call_in_child(lambda: _plan_query(*args), limit)
    if ok:
        return res
    why = f"did not stop at its time limit and was killed after {limit:.3g} s" if res == "timeout" else \
        f"crashed ({res})"
    return PlanResult(scenario=args[13], solved=False, exact=False, path=np.zeros((0, space.dim)), length=math.inf,
                      planner=name, seed=seed, timings={"setup": 0.0, "solve": limit, "simplify": 0.0, "verify": 0.0},
                      checks={"states": 0, "motions": 0}, stages=["setup", "solve"], start=tuple(start),
                      goal=tuple(goal), message=f"not solved: {name} {why} (a fault of OMPL's {name}; "
                                                f"try another planner)")


def _trivial(space, name, seed, scenario, start, goal) -> PlanResult:
    """Start equals goal: the one-point path, verified like any other."""
    path = np.array([start], dtype=np.float64).reshape(1, space.dim)
    ok, message = space.verify(path, start, goal)
    return PlanResult(scenario=scenario, solved=ok, exact=ok, path=path, length=0.0, planner=name, seed=seed,
                      timings={"setup": 0.0, "solve": 0.0, "simplify": 0.0, "verify": 0.0},
                      checks={"states": 0, "motions": 0}, stages=["verify"], start=tuple(start), goal=tuple(goal),
                      message=message, length_unsimplified=0.0, first_solution=0.0, progress=[[0.0, 0.0]])


def _straight(space, name, seed, scenario, start, goal) -> PlanResult:
    """The straight motion is free: for AORRTC, the optimum without running it.

    OMPL 2.0's AORRTC mishandles this case (it simplifies its first path to cost 0
    and returns a path that does not reach the goal, or busy-loops on "Failed to find
    any neighbours"); the straight path is what it would converge to.
    """
    path = np.array([start, goal], dtype=np.float64)
    length = space.length(path)
    return PlanResult(scenario=scenario, solved=True, exact=True, path=path, length=length, planner=name, seed=seed,
                      timings={"setup": 0.0, "solve": 0.0, "simplify": 0.0, "verify": 0.0},
                      checks={"states": 0, "motions": 1}, stages=["verify"], start=tuple(start), goal=tuple(goal),
                      message=f"exact solution: the straight motion is free ({name} is not run on such a query: "
                              f"OMPL 2.0's {name} fails on it)",
                      length_unsimplified=length, first_solution=0.0, progress=[[0.0, length]])


def _snap(path: np.ndarray, goal) -> np.ndarray:
    """The planner's path, ending exactly at the goal.

    OMPL reports the goal reached within ``GOAL_THRESHOLD`` (1e-9; a threshold of 0
    makes RRT miss a goal it has sampled); the last little step to the exact goal is
    appended and, like every segment, verified exactly afterwards.

    >>> _snap(np.array([[0., 0], [1, 1 - 1e-12]]), (1, 1)).tolist()
    [[0.0, 0.0], [1.0, 0.999999999999], [1.0, 1.0]]
    """
    goal = np.array(goal, dtype=np.float64)
    if len(path) and not (path[-1] == goal).all():
        path = np.vstack([path, goal])
    return path

