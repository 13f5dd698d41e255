"""Planning a path: scenario -> C-space -> OMPL -> simplified, exactly verified path.

This module owns :func:`plan`, :class:`PlanResult` and :func:`run_planner`, the one
routine that sets up, queries, solves, simplifies and verifies with OMPL. ``cspace
plan``, ``planners.plan()`` and every ``cspace bench`` run go through it; the bench
only asks for anytime planners to be solved in time slices (``slices=True``) to time
the first solution and record the best cost along the run.

The routine talks to a state-space adapter (:mod:`planners.spaces`), never to the
geometry: a path is reported solved only if OMPL found an exact solution *and* the
adapter's exact verification accepts the final (simplified) path, from the start
exactly to the goal exactly.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from cspace.cspace import CSpace
from cspace.scenario import Scenario, ScenarioError, load_scenario


@dataclass
class PlanResult:
    """What a plan produced. ``path`` is an (N, 2) array of reference-point positions."""

    scenario: str
    solved: bool
    exact: bool
    path: np.ndarray
    length: float
    planner: str
    seed: int
    timings: dict = field(default_factory=dict)
    checks: dict = field(default_factory=dict)
    stages: list = field(default_factory=list)
    start: tuple = (0.0, 0.0)
    goal: tuple = (0.0, 0.0)
    message: str = ""
    length_unsimplified: float | None = None
    cspace_report: dict | None = None
    queries: list | None = None
    # Filled by run_planner: when the first exact solution was found (seconds into the
    # solve) and [time, best raw length] pairs along the run (the bench's anytime curve).
    first_solution: float | None = None
    progress: list = field(default_factory=list)
    # The objects behind the result, for plots and further queries (not serialised).
    scenario_data: Scenario | None = field(default=None, repr=False, compare=False)
    cspace: CSpace | None = field(default=None, repr=False, compare=False)

    def as_dict(self, nested: bool = True) -> dict:
        """The JSON form (the ``--json`` output of ``cspace plan``).

        With ``queries``, the top level describes the first query and ``queries``
        holds one entry per query with the fields of a single plan.
        """
        d = {
            "scenario": self.scenario,
            "solved": self.solved,
            "exact": self.exact,
            "planner": self.planner,
            "seed": self.seed,
            "start": list(self.start),
            "goal": list(self.goal),
            "path": self.path.tolist(),
            "length": self.length if math.isfinite(self.length) else None,
            "length_unsimplified": self.length_unsimplified,
            "timings": self.timings,
            "checks": self.checks,
            "stages": self.stages,
            "message": self.message,
        }
        if nested and self.cspace_report is not None:
            d["cspace"] = self.cspace_report
        if nested and self.queries is not None:
            d["queries"] = [q.as_dict(nested=False) for q in self.queries]
        return d


def path_length(path: np.ndarray) -> float:
    """Euclidean length of a polyline.

    >>> path_length(np.array([[0., 0], [3, 4], [3, 5]]))
    6.0
    """
    if len(path) < 2:
        return 0.0
    return float(np.hypot(*np.diff(path, axis=0).T).sum())


MAX_TIME = 1e8  # seconds (about three years); OMPL's steady clock overflows near 8e9 s
SEED_LIMIT = 2**32 - 1  # OMPL's seeds are 32-bit


def _resolve(scenario, planner, time_limit, seed, iterations=None, space=None):
    """Scenario object plus the effective planner, time and seed (arguments over file defaults)."""
    from .ompl_glue import planner_name

    t0 = time.perf_counter()
    if isinstance(scenario, Scenario):
        sc = scenario
        if space is not None and space != sc.space:
            raise ScenarioError("plan()", "space", f"the scenario was loaded as {sc.space!r}; load it with "
                                                   f"load_scenario(path, space={space!r}) or pass its path")
    else:
        sc = load_scenario(os.fspath(scenario), space=space)
    load_s = time.perf_counter() - t0
    src = sc.path or "<scenario>"
    opts = sc.planner
    # An argument is blamed as an argument of plan(), a file's value as the file's field.
    def where(arg, fld):
        return ("plan()", fld) if arg is not None else (src, f"planner.{fld}")

    if planner is not None:
        name = planner_name(planner, "plan()", "planner")
    else:
        name = planner_name(opts.get("name"), src, "planner.name")
    t = time_limit if time_limit is not None else opts.get("time", 1.0)
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t) or t <= 0:
        raise ScenarioError(*where(time_limit, "time"), f"must be a positive number of seconds, got {t!r}")
    if t > MAX_TIME:
        raise ScenarioError(*where(time_limit, "time"),
                            f"at most {MAX_TIME:g} s (OMPL's clock overflows near 8e9 s), got {t!r}")
    s = seed if seed is not None else opts.get("seed", 0)
    if iterations is not None and (isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1):
        raise ScenarioError("plan()", "iterations", f"must be a positive integer, got {iterations!r}")
    if isinstance(s, bool) or not isinstance(s, int) or not 0 <= s < SEED_LIMIT:
        raise ScenarioError(*where(seed, "seed"), f"must be an integer in [0, 2^32 - 1), got {s!r}")
    return sc, name, float(t), int(s), load_s


def plan(scenario, planner: str | None = None, time: float | None = None, seed: int | None = None,
         *, simplify: bool = True, iterations: int | None = None, cspace: CSpace | None = None,
         all_queries: bool = False, slices: bool = False, on_progress=None, space: str | None = None,
         slabs: int | None = None) -> PlanResult:
    """Plan a collision-free path for a scenario (a path or a :class:`Scenario`).

    ``planner``, ``time`` and ``seed`` override the scenario's ``[planner]`` table
    (defaults: RRTConnect, 1 s, seed 0). ``iterations`` adds a deterministic budget
    in planner iterations. With ``all_queries`` every ``[[queries]]`` entry is
    planned on the same C-space (and, for PRM-family planners, the same roadmap),
    each query with its own seeded random stream; the result then carries
    ``queries``, one result per query, and the top-level fields describe the first.
    ``cspace`` reuses a C-space built from the same scenario. ``slices`` and
    ``on_progress`` are the bench's hooks (see :func:`run_planner`).

    ``space="se2"`` (or ``space = "se2"`` in the file) lets the robot rotate: poses and
    the path's rows are (x, y, theta), the C-space is the sliced
    :class:`cspace.se2.SE2CSpace` (``slabs`` angle slabs; default: the file's, else
    derived from the scene) and every motion is certified along OMPL's SE(2)
    interpolation. There is no exact planner in SE(2); ``planner="exact"`` there
    answers only when the inscribed-disk rule proves the scene unsolvable.

    >>> import os
    >>> res = plan(os.path.join(os.path.dirname(__file__), "..", "scenarios", "basic.toml"), seed=3)
    >>> res.solved, res.path[0].tolist(), res.path[-1].tolist()
    (True, [1.0, 1.0], [9.0, 9.0])
    """
    sc, name, tlim, sd, load_s = _resolve(scenario, planner, time, seed, iterations, space)
    se2 = sc.space == "se2"
    if slabs is not None and not se2:
        raise ScenarioError("plan()", "slabs", 'applies to space = "se2" only')
    if name != "exact":
        from .ompl_glue import ompl

        ompl()  # without OMPL: fails here, before the C-space is built
    wall0 = _now()
    if cspace is None:
        t0 = _now()
        cspace = _build_cspace(sc, slabs)
        build_s = _now() - t0
    else:
        build_s = 0.0
    report = cspace.report()
    adapter = _adapter(sc, cspace)
    queries = sc.all_queries() if all_queries else sc.all_queries()[:1]
    src = sc.path or "<scenario>"
    poses = []
    for i, q in enumerate(queries):
        pair = (adapter.pose(q.start), adapter.pose(q.goal))
        for pt, fld in zip(pair, ("start", "goal")):
            if not adapter.is_free(pt):
                label = fld if i == 0 else f"queries[{i - 1}].{fld}"
                raise ScenarioError(src, label, f"{pt} is not a free state of the C-space")
        poses.append(pair)
    if name == "exact" and se2:
        from .exact import exact_se2

        results = [exact_se2(sc, q, src, time_limit=tlim) for q in queries]
    elif name == "exact":
        from .exact import exact_plan

        results = [exact_plan(sc, cspace, q, time_limit=tlim) for q in queries]
    else:
        results = run_planner(adapter, name, poses, tlim, sd, iterations=iterations, simplify=simplify,
                              slices=slices, on_progress=on_progress, scenario=sc.name)
        if se2:
            _explain_se2_failures(sc, queries, results)
    for r in results:
        r.timings = {"load": load_s, "cspace": build_s, **r.timings}
        r.stages = _stage_names(report) + r.stages
        r.cspace_report = report
    first = results[0]
    first.timings["total"] = load_s + (_now() - wall0)
    first.cspace_report = cspace.report()
    first.checks = {**first.checks, **{f"cspace_{k}": v for k, v in cspace.checks.items()}}
    if all_queries:
        first.queries = results
    first.scenario_data, first.cspace = sc, cspace
    return first


def _now() -> float:
    return time.perf_counter()


def _stage_names(report: dict) -> list[str]:
    """The C-space stages that ran (a sliced SE(2) C-space builds its slabs lazily, later)."""
    if "stages" in report:
        return [s["stage"] for s in report["stages"] if s["ran"]]
    return ["decompose", f"slabs (K = {report['slabs']}, lazy)"]


def _build_cspace(sc: Scenario, slabs: int | None = None):
    """The C-space a scenario's state space needs: translation, or sliced SE(2)."""
    if sc.space == "se2":
        from cspace.se2 import SE2CSpace

        return SE2CSpace.from_scenario(sc, slabs=slabs if slabs is not None else sc.slabs)
    return CSpace.from_scenario(sc)


def _adapter(sc: Scenario, cspace):
    """The state-space adapter of :mod:`planners.spaces` for the scenario's space."""
    if sc.space == "se2":
        from .space_se2 import SE2Space

        return SE2Space(cspace)
    from .spaces import TranslationSpace

    return TranslationSpace(cspace)


def _explain_se2_failures(sc: Scenario, queries, results) -> None:
    """A rotating robot's plan that failed: does the inscribed-disk rule prove it unsolvable?"""
    from .se2_bounds import disk_bound

    for q, r in zip(queries, results):
        if not r.solved:
            t = _now()
            db = disk_bound(sc, q, time_limit=5.0)
            r.timings["disk_bound"] = _now() - t
            if db.proven_unsolvable:
                r.message = db.message


# Anytime planners solved in slices (``slices=True``): MIN_SLICE s, doubling up to
# budget / SLICES. Calling solve() again continues the same search in these planners
# (not in AORRTC, which crashed under repeated solves).
SLICES = 20
MIN_SLICE = 0.002
SLICED = {"rrtstar", "informedrrtstar", "sorrtstar", "bitstar", "prm", "prmstar"}
ROADMAP = {"prm", "prmstar"}  # multi-query: the roadmap is kept from query to query


def run_planner(space, name: str, queries: list, time_limit: float, seed: int, *,
                iterations: int | None = None, simplify: bool = True, slices: bool = False,
                on_progress=None, scenario: str = "") -> list[PlanResult]:
    """THE planning routine: one OMPL planner over a state-space adapter, for each query.

    ``space`` is an adapter of :mod:`planners.spaces`; ``queries`` is a list of
    ``(start, goal)`` poses of its dimension, already checked to be free. Per query:
    set up (seeded with the query's own stream; PRM-family planners keep their
    roadmap from query to query), set the query, solve within ``time_limit`` seconds
    (and ``iterations`` if given), simplify, snap the last step to the exact goal,
    and verify exactly through the adapter.

    With ``slices``, anytime planners are solved in slices of the same total budget
    so that the time of the first solution (to within one slice) and the best raw
    length along the run are recorded in ``first_solution`` and ``progress``;
    ``on_progress(t, length)`` is called at each recorded point.
    """
    from .ompl_glue import make_setup, set_query

    out = []
    ss = None
    key = name.lower()
    for i, (start, goal) in enumerate(queries):
        t0 = _now()
        if tuple(start) == tuple(goal):  # nothing to plan: the one-point path
            out.append(_trivial(space, name, seed, scenario, start, goal))
            continue
        if ss is None or key not in ROADMAP:
            ss, _ospace, _checker, _validator = make_setup(space, name, seed, query=i)
        else:
            ss.getPlanner().clearQuery()  # keep the roadmap, drop the old start and goal
        set_query(ss, space, start, goal)
        setup_s = _now() - t0
        c0 = space.counts()
        t1 = _now()
        first, progress = _solve(ss, space, key, time_limit, iterations, slices, on_progress)
        solve_s = _now() - t1
        status = ss.getLastPlannerStatus()
        found = ss.haveExactSolutionPath()
        raw = _snap(space.path_array(ss.getSolutionPath()), goal) if found else None
        t2 = _now()
        if found and simplify:
            ss.simplifySolution()
        simp_s = _now() - t2 if found and simplify else 0.0
        path = _snap(space.path_array(ss.getSolutionPath()), goal) if found else None
        t3 = _now()
        ok, message = space.verify(path, start, goal) if found else (False, failure_message(status, space))
        verify_s = _now() - t3
        c1 = space.counts()
        if ok and key in SLICED | {"aorrtc"} and iterations is None and solve_s >= 0.9 * time_limit:
            message += " (anytime planner: ran to its time limit)"
        out.append(PlanResult(
            scenario=scenario, solved=ok, exact=ok, path=path if ok else np.zeros((0, space.dim)),
            length=space.length(path) if ok else math.inf, planner=name, seed=seed,
            timings={"setup": setup_s, "solve": solve_s, "simplify": simp_s, "verify": verify_s},
            checks={"states": c1[0] - c0[0], "motions": c1[1] - c0[1]},
            stages=["setup", "solve"] + (["simplify"] if found and simplify else []) + ["verify"],
            start=tuple(start), goal=tuple(goal), message=message,
            length_unsimplified=space.length(raw) if ok else None,
            first_solution=first if ok else None, progress=progress,
        ))
    return out


def _solve(ss, space, key, time_limit, iterations, slices, on_progress):
    """Solve within the budget; returns (time of the first exact solution, progress)."""
    from .ompl_glue import ompl, termination

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

    if slices and key in SLICED and not iterations:
        # Continue the same search slice by slice: same total budget. Slices double
        # from MIN_SLICE up to budget / SLICES, so an early first solution is timed
        # finely and a long run still takes few slices.
        step, n = max(time_limit / SLICES, MIN_SLICE), 0
        while (left := time_limit - (_now() - t0)) > 0:
            ss.solve(ob.timedPlannerTerminationCondition(min(step, MIN_SLICE * 2 ** n, left)))
            n += 1
            record()
    else:
        ptc, _keep = termination(time_limit, iterations)
        ss.solve(ptc)
        record()
    return first, progress


def failure_message(status, space=None) -> str:
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
    hint = getattr(space, "unsolved_hint", None)
    return msg + (f"; {hint}" if hint else "")


def _trivial(space, name, seed, scenario, start, goal) -> PlanResult:
    """Start equals goal: the one-point path, verified like any other."""
    path = np.array([start], dtype=np.float64).reshape(1, space.dim)
    ok, message = space.verify(path, start, goal)
    return PlanResult(scenario=scenario, solved=ok, exact=ok, path=path, length=0.0, planner=name, seed=seed,
                      timings={"setup": 0.0, "solve": 0.0, "simplify": 0.0, "verify": 0.0},
                      checks={"states": 0, "motions": 0}, stages=["verify"], start=tuple(start), goal=tuple(goal),
                      message=message, length_unsimplified=0.0, first_solution=0.0, progress=[[0.0, 0.0]])


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
