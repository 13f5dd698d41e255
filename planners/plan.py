"""Planning a path: scenario -> C-space -> OMPL -> simplified, exactly verified path.

This module owns :func:`plan` and :class:`PlanResult`. A path is reported solved
only if OMPL found an exact solution *and* every segment of the final (simplified)
path passes the exact segment test of the C-space again, from the start exactly to
the goal exactly.
"""
from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from cspace.cspace import CSpace
from cspace.scenario import MAX_SEED, Scenario, ScenarioError, load_scenario, show


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


def _resolve(scenario, planner, time_limit, seed, iterations=None):
    """Scenario object plus the effective planner, time and seed (arguments over file defaults)."""
    from .ompl_glue import planner_name

    t0 = time.perf_counter()
    sc = scenario if isinstance(scenario, Scenario) else load_scenario(os.fspath(scenario))
    load_s = time.perf_counter() - t0
    src = sc.path or "<scenario>"
    opts = sc.planner
    name = planner_name(planner if planner is not None else opts.get("name"), src,
                        "planner" if planner is not None else "planner.name")
    t = time_limit if time_limit is not None else opts.get("time", 1.0)
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t) or t <= 0:
        raise ScenarioError(src, "time", f"must be a positive number of seconds, got {t!r}")
    s = seed if seed is not None else opts.get("seed", 0)
    if iterations is not None and (isinstance(iterations, bool) or not isinstance(iterations, int) or iterations < 1):
        raise ScenarioError(src, "iterations", f"must be a positive integer, got {iterations!r}")
    if isinstance(s, bool) or not isinstance(s, int) or not 0 <= s <= MAX_SEED:
        raise ScenarioError(src, "seed", f"must be an integer from 0 to 2^63 - 1, got {show(s)}")
    return sc, name, float(t), int(s), load_s


def plan(scenario, planner: str | None = None, time: float | None = None, seed: int | None = None,
         *, simplify: bool = True, iterations: int | None = None, cspace: CSpace | None = None,
         all_queries: bool = False) -> PlanResult:
    """Plan a collision-free path for a scenario (a path or a :class:`Scenario`).

    ``planner``, ``time`` and ``seed`` override the scenario's ``[planner]`` table
    (defaults: RRTConnect, 1 s, seed 0). ``iterations`` adds a deterministic budget
    in planner iterations. With ``all_queries`` every ``[[queries]]`` entry is
    planned on the same C-space (and, for PRM-family planners, the same roadmap);
    the result then carries ``queries``, one result per query, and the top-level
    fields describe the first one.
    """
    sc, name, tlim, sd, load_s = _resolve(scenario, planner, time, seed, iterations)
    wall0 = _now()
    if cspace is None:
        t0 = _now()
        cspace = CSpace.from_scenario(sc)
        build_s = _now() - t0
    else:
        build_s = 0.0
    report = cspace.report()
    queries = sc.all_queries() if all_queries else sc.all_queries()[:1]
    src = sc.path or "<scenario>"
    for i, q in enumerate(queries):
        for pt, fld in ((q.start, "start"), (q.goal, "goal")):
            if not cspace.is_free(pt):
                label = fld if i == 0 else f"queries[{i - 1}].{fld}"
                raise ScenarioError(src, label, f"({pt[0]}, {pt[1]}) is not a free state of the C-space")
    if name == "exact":
        from .exact import exact_plan

        results = [exact_plan(sc, cspace, q, time_limit=tlim) for q in queries]
    else:
        results = _plan_ompl(sc, cspace, queries, name, tlim, sd, simplify, iterations)
    for r in results:
        r.timings = {"load": load_s, "cspace": build_s, **r.timings}
        r.stages = [s["stage"] for s in report["stages"] if s["ran"]] + r.stages
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


def _plan_ompl(sc, cspace, queries, name, tlim, seed, simplify, iterations) -> list[PlanResult]:
    from .ompl_glue import ANYTIME, frame_exponent, make_setup, path_states, set_query, termination

    t0 = _now()
    k = frame_exponent(cspace.bounds)
    ss, space, checker, validator = make_setup(cspace, name, seed, k)
    setup_s = _now() - t0
    planner = ss.getPlanner()
    multi = name.lower() in ("prm", "prmstar")
    out = []
    for i, q in enumerate(queries):
        if i:
            if multi:
                planner.clearQuery()  # keep the roadmap, drop the old start and goal
            else:
                ss.clear()
        set_query(ss, space, q.start, q.goal, k)
        before = {"points": cspace.point_count(), "segments": cspace.checks["segments"]}
        t1 = _now()
        ptc, _keep = termination(tlim, iterations)
        status = ss.solve(ptc)
        solve_s = _now() - t1
        exact_sol = bool(status) and ss.haveExactSolutionPath()
        raw = _snap(path_states(ss.getSolutionPath(), k), q) if exact_sol else np.zeros((0, 2))
        length_raw = path_length(raw) if exact_sol else None
        t2 = _now()
        if exact_sol and simplify:
            ss.simplifySolution()
        simp_s = _now() - t2 if exact_sol and simplify else 0.0
        path = _snap(path_states(ss.getSolutionPath(), k), q) if exact_sol else np.zeros((0, 2))
        t3 = _now()
        verified, message = _verify(cspace, path, q) if exact_sol else (False, str(status))
        verify_s = _now() - t3
        after = {"points": cspace.point_count(), "segments": cspace.checks["segments"]}
        out.append(PlanResult(
            scenario=sc.name, solved=verified, exact=verified, path=path if verified else np.zeros((0, 2)),
            length=path_length(path) if verified else math.inf, planner=name, seed=seed,
            timings={"setup": setup_s if i == 0 else 0.0, "solve": solve_s, "simplify": simp_s, "verify": verify_s},
            checks={"states": after["points"] - before["points"], "motions": after["segments"] - before["segments"]},
            stages=["setup", "solve"] + (["simplify"] if exact_sol and simplify else []) + ["verify"],
            start=tuple(q.start), goal=tuple(q.goal), message=message,
            length_unsimplified=length_raw,
        ))
        if name.lower() in ANYTIME and iterations is None:
            out[-1].message += " (anytime planner: ran to its time limit)"
    return out


def _snap(states, q) -> np.ndarray:
    """The planner's path, ending exactly at the goal.

    OMPL reports the goal reached within ``GOAL_THRESHOLD`` (1e-9; a threshold of 0
    makes RRT miss a goal it has sampled); the last little step to the exact goal is
    appended and, like every segment, verified exactly afterwards.
    """
    path = np.array(states, dtype=np.float64).reshape(-1, 2)
    goal = np.array(q.goal, dtype=np.float64)
    if len(path) and not (path[-1] == goal).all():
        path = np.vstack([path, goal])
    return path


def _verify(cspace: CSpace, path: np.ndarray, q) -> tuple[bool, str]:
    """Every segment exactly free, and the path runs from the start to the goal exactly."""
    if len(path) < 2:
        same = len(path) == 1 and tuple(path[0]) == tuple(q.start) == tuple(q.goal)
        return same, "" if same else "empty path"
    if tuple(path[0]) != tuple(map(float, q.start)) or tuple(path[-1]) != tuple(map(float, q.goal)):
        return False, "path does not run exactly from start to goal"
    for k in range(len(path) - 1):
        if not cspace.segment_free(path[k], path[k + 1]):
            return False, f"segment {k} failed the exact test"
    return True, "exact solution"
