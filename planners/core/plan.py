"""Planning a path: scenario -> C-space -> OMPL -> simplified, exactly verified path.

This module owns :func:`plan` and :class:`PlanResult`: it resolves the options, builds
the C-space, checks the queries, and hands a state-space adapter
(:mod:`planners.adapters`) to :func:`planners.core.routine.run_planner`, the one routine
that drives OMPL. ``cspace plan``, ``planners.plan()`` and every ``cspace bench``
run go through it. A path is reported solved only if OMPL found an exact solution
*and* the adapter's exact verification accepts the final (simplified) path, from
the start exactly to the goal exactly.
"""
from __future__ import annotations

import math
import os
import time
import warnings

import numpy as np

from cspace.translation.cspace import CSpace
from cspace.io.load import Scenario, ScenarioError, load_scenario
from cspace.io.scenario.schema import MAX_SLABS

from ..adapters.frame import path_length  # noqa: F401  (planners.path_length, the API's name)
from .result import PlanResult


MAX_TIME = 1e8  # seconds (about three years); OMPL's steady clock overflows near 8e9 s
SEED_LIMIT = 2**32 - 1  # OMPL's seeds are 32-bit


DEFAULT_TIME_SE2 = 10.0  # seconds, when neither the call nor the file gives a time (translation: 1)


def _resolve(scenario, planner, time_limit, seed, iterations=None, space=None, turning_radius=None):
    """Scenario object plus the effective planner, time and seed (arguments over file defaults)."""
    from ..adapters.glue import planner_name

    t0 = time.perf_counter()
    if isinstance(scenario, Scenario):
        sc = scenario
        if turning_radius is not None and turning_radius != sc.turning_radius:
            raise ScenarioError("plan()", "turning_radius", "the scenario was loaded with turning_radius "
                                f"{sc.turning_radius!r}; pass its path to plan with another")
        if space is not None and space != sc.space:
            raise ScenarioError("plan()", "space", f"the scenario was loaded as {sc.space!r}; load it with "
                                                   f"load_scenario(path, space={space!r}) or pass its path")
    else:
        sc = load_scenario(os.fspath(scenario), space=space, turning_radius=turning_radius)
    load_s = time.perf_counter() - t0
    src = sc.path or "<scenario>"
    opts = sc.planner
    # An argument is blamed as an argument of plan(), a file's value as the file's field.
    def where(arg, fld):
        return ("plan()", fld) if arg is not None else (src, f"planner.{fld}")

    if planner is not None:
        name = planner_name(planner, "plan()", "planner")
    elif opts.get("name") is None and sc.rotates:  # a rotating robot or a car: the planner that always answers
        name = "auto"
    else:
        name = planner_name(opts.get("name"), src, "planner.name")
    # SE(2) builds its angle slabs lazily, inside the planner's time: a longer default.
    t = time_limit if time_limit is not None else opts.get("time", DEFAULT_TIME_SE2 if sc.rotates else 1.0)
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
         slabs: int | None = None, turning_radius: float | None = None, clearance: float | None = None,
         objective: str = "length") -> PlanResult:
    """Plan a collision-free path for a scenario (a path or a :class:`Scenario`).

    ``planner``, ``time`` and ``seed`` override the scenario's ``[planner]`` table
    (defaults: ``auto`` for a rotating robot or a car (:mod:`planners.core.auto`: the proof,
    the slab graph, sampling, refinement, in one budget), RRTConnect for a translating one,
    1 s (10 s when the robot rotates), seed 0; without OMPL, a call that names no planner plans
    with ``exact`` and warns, as ``cspace plan`` does). ``iterations`` adds a deterministic budget
    in planner iterations. With ``all_queries`` every ``[[queries]]`` entry is
    planned on the same C-space (and, for PRM-family planners, the same roadmap),
    each query with its own seeded random stream; the result then carries
    ``queries``, one result per query, and the top-level fields describe the first.
    ``cspace`` reuses a C-space built from the same scenario. ``slices`` and
    ``on_progress`` are the bench's hooks (see :func:`run_planner`).

    ``space="se2"`` (or ``space = "se2"`` in the file) lets the robot rotate: poses and
    the path's rows are (x, y, theta), the C-space is the sliced
    :class:`cspace.se2.cspace.SE2CSpace` (``slabs`` angle slabs; default: the file's, else
    derived from the scene) and every motion is certified along OMPL's SE(2)
    interpolation. ``planner="exact"`` there searches the slab graph
    (:mod:`planners.core.exact_se2`): a certified path, a proof that none exists, or the
    resolution it reached.

    ``space="dubins"`` or ``"reeds-shepp"`` (with ``turning_radius``, or the file's
    ``turning_radius``) plans a car: the same poses and C-space, but every motion is the
    shortest Dubins (forward only) or Reeds–Shepp (forward and reverse) curve, certified
    segment by segment; ``PlanResult.curves`` holds each motion's segments. ``exact``
    answers a car only with a proof that no path exists.

    ``clearance=D`` (over the file's ``clearance``) inflates the robot by a polygon
    containing the disk of radius D (:mod:`cspace.kernel.minkowski.margin`): every path then keeps the
    robot at least D from every obstacle (``exact``: the shortest such path). Each solved
    result carries ``min_clearance`` (exact in translation, a certified lower bound in
    SE(2)), where it occurs, and ``touches``. ``objective`` is ``length`` (default),
    ``clearance`` or ``balanced`` (:mod:`planners.adapters.objectives`).

    >>> import os
    >>> res = plan(os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "basic.toml"), seed=3)
    >>> res.solved, res.path[0].tolist(), res.path[-1].tolist()
    (True, [1.0, 1.0], [9.0, 9.0])
    """
    cpu0 = _cpu()
    if planner is None:
        from ..adapters.glue import OMPL_HINT, ompl_available

        if not ompl_available():  # as `cspace plan` does: the exact planner, and a note
            warnings.warn(f"OMPL is not installed: planning with the exact planner instead ({OMPL_HINT})",
                          stacklevel=2)
            planner = "exact"
    sc, name, tlim, sd, load_s = _resolve(scenario, planner, time, seed, iterations, space, turning_radius)
    sc = _with_clearance(sc, clearance)
    try:
        from ..adapters.objectives import check_objective

        objective = check_objective(objective, name)
    except ValueError as exc:
        raise ScenarioError("plan()", "objective", str(exc)) from None
    se2 = sc.rotates  # SE(2) or a car: poses (x, y, theta) over the sliced C-space
    if slabs is not None and not se2:
        raise ScenarioError("plan()", "slabs", 'applies to a rotating robot only (space = "se2", "dubins" or '
                                               '"reeds-shepp")')
    if slabs is not None and (isinstance(slabs, bool) or not isinstance(slabs, int) or not 4 <= slabs <= MAX_SLABS):
        raise ScenarioError("plan()", "slabs", f"must be an integer from 4 to {MAX_SLABS}, got {slabs!r}")
    if name != "exact":
        from ..adapters.glue import ompl

        ompl()  # without OMPL: fails here, before the C-space is built
    wall0 = _now()
    if cspace is None:
        t0 = _now()
        cspace = build_cspace(sc, slabs)
        build_s = _now() - t0
    else:
        build_s = 0.0
        _check_margin(sc, cspace)
    report = cspace.report()
    adapter = make_adapter(sc, cspace)
    if objective != "length" and getattr(adapter, "clearance_functions", None) is None:
        raise ScenarioError("plan()", "objective", f"{objective} is not available for space {sc.space!r} "
                                                   "(translation and se2 only)")
    queries = sc.all_queries() if all_queries else sc.all_queries()[:1]
    src = sc.path or "<scenario>"
    poses = []
    for i, q in enumerate(queries):
        pair = (adapter.pose(q.start), adapter.pose(q.goal))
        for pt, fld in zip(pair, ("start", "goal")):
            if not adapter.is_free(pt):
                label = fld if i == 0 else f"queries[{i - 1}].{fld}"
                why = (f" with clearance {sc.clearance:g} (the robot there is closer than that to an obstacle)"
                       if sc.clearance > 0 else " with the margin" if sc.margin is not None else "")
                raise ScenarioError(src, label, f"{pt} is not a free state of the C-space{why}")
        poses.append(pair)
    # A rotating robot: the load, the decomposition and the slabs built so far (the start and
    # goal checks build the slabs of a small scene) count against the time limit.
    built_s = load_s + (_now() - wall0) if se2 else 0.0
    tlim -= built_s
    # exact's clearance measure of a rotating robot's path refines its bound only until the queries'
    # time is up (a sampling planner's, often anytime and using its whole limit, is measured in full)
    deadline = _now() + max(tlim, 0.0) * len(queries) if sc.space == "se2" and name == "exact" else None
    if tlim <= 0:
        results = [_out_of_time(sc, name, sd, q, built_s) for q in queries]
    elif name == "exact" and sc.space == "reeds-shepp":
        from .auto import exact_reeds_shepp

        results = [exact_reeds_shepp(sc, cspace, adapter, q, src, tlim, simplify) for q in queries]
    elif name == "exact" and se2:
        from .exact_se2 import exact_se2

        results = [exact_se2(sc, cspace, adapter, q, src, time_limit=tlim, simplify=simplify) for q in queries]
    elif name == "exact":
        from .exact import exact_plan

        results = [exact_plan(sc, cspace, q, time_limit=tlim) for q in queries]
    elif name == "auto":
        from .auto import auto_plan

        results = [auto_plan(sc, cspace, adapter, q, pair, tlim, sd, source=src, iterations=iterations,
                             simplify=simplify) for q, pair in zip(queries, poses)]
    else:
        from .routine import run_planner

        proven, spent = _proofs_before_sampling(sc, cspace, queries, tlim, name, sd, se2)
        todo = [pair for pair, p in zip(poses, proven) if p is None]
        sampled = iter(run_planner(adapter, name, todo, tlim, sd, iterations=iterations, simplify=simplify,
                                   slices=slices, on_progress=on_progress, scenario=sc.name, objective=objective)
                       if todo else [])
        results = [p if p is not None else next(sampled) for p in proven]
        for r, t in zip(results, spent):
            r.timings = {"proof": t, **r.timings}
        # (No inscribed-disk rule after a failure: the proof before sampling is at least as strong,
        # since every POSSIBLE region lies in the disk's free space, and the rule's C-space build,
        # seconds on a large map, would run past --time.)
    if hasattr(adapter, "curves"):  # a car's path, whichever planner found it
        for r in results:
            r.curves = adapter.curves(r.path) if r.solved else []
    for r in results:
        r.clearance, r.objective = sc.clearance, objective
        _measure_clearance(r, adapter, deadline)
        r.timings = {"load": load_s, "cspace": build_s, **r.timings}
        if r.first_path_cpu is not None:
            r.first_path_cpu -= cpu0
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


def _cpu() -> float:
    return time.process_time()


def _now() -> float:
    return time.perf_counter()


def _out_of_time(sc: Scenario, name: str, seed: int, q, spent: float) -> PlanResult:
    """A query not planned: loading the scene and building its C-space used the whole time limit."""
    return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                      planner=name, seed=seed, timings={"setup": 0.0, "solve": 0.0, "simplify": 0.0, "verify": 0.0},
                      checks={"states": 0, "motions": 0}, stages=[], start=tuple(q.start), goal=tuple(q.goal),
                      message=f"not solved within the time limit (C-space build took {spent:.3g} s)")


def _with_clearance(sc: Scenario, clearance) -> Scenario:
    """The scenario with the margin D of ``plan(clearance=D)`` (the file's when None)."""
    if clearance is None:
        return sc
    from cspace.io.scenario.fields import clearance_fault

    fault = clearance_fault(clearance)
    if fault:
        raise ScenarioError("plan()", "clearance", fault)
    if float(clearance) == sc.clearance:
        return sc
    import dataclasses

    return dataclasses.replace(sc, clearance=float(clearance))


def _check_margin(sc: Scenario, cspace) -> None:
    """A C-space passed in must have been built with the margin the plan asks for."""
    want, have = sc.margins(), getattr(cspace, "margin", [])
    if len(want) != len(have) or not all(np.array_equal(a, b) for a, b in zip(want, have)):
        raise ScenarioError("plan()", "cspace", f"was built with another margin than clearance {sc.clearance:g}"
                                                f"{' and [margin]' if sc.margin is not None else ''}: build it from "
                                                f"the same scenario and clearance, or pass none")


def _measure_clearance(r: PlanResult, adapter, deadline: float | None = None) -> None:
    """Fill a solved result's min_clearance (timed as ``clearance``) and ``touches``; with
    ``deadline`` (SE(2)), the measure's refinement stops there and the message says so."""
    measure = getattr(adapter, "path_clearance", None)
    if not r.solved or not len(r.path) or measure is None:
        return
    t = _now()
    c = measure(r.path) if deadline is None else measure(r.path, deadline=deadline)
    r.timings["clearance"] = _now() - t
    if c.cut:
        r.message += ("; the clearance measure stopped at the time limit: min clearance is a looser "
                      "certified lower bound")
    r.min_clearance, r.min_clearance_bound = float(c.distance), c.bound
    if c.bound == "lower" and r.clearance > r.min_clearance:
        # every motion was certified free for the robot grown by a polygon holding the disk of
        # radius D: D itself is a certified lower bound, tighter than a loose measurement
        r.min_clearance = float(r.clearance)
    r.min_clearance_at = tuple(c.where) or None
    r.min_clearance_obstacle = tuple(c.obstacle_point) or None
    r.touches = c.distance == 0.0 and c.bound == "exact"


def _stage_names(report: dict) -> list[str]:
    """The C-space stages that ran (a sliced SE(2) C-space builds its slabs lazily, later)."""
    if "stages" in report:
        return [s["stage"] for s in report["stages"] if s["ran"]]
    return ["decompose", f"slabs (K = {report['slabs']}, lazy)"]


def build_cspace(sc: Scenario, slabs: int | None = None):
    """The C-space a scenario's state space needs: translation, sliced SE(2), or a car's."""
    if sc.rotates:
        if sc.turning_radius is not None:
            from cspace.car.motion import CarCSpace as SE2CSpace
        else:
            from cspace.se2.cspace import SE2CSpace

        try:
            return SE2CSpace.from_scenario(sc, slabs=slabs if slabs is not None else sc.slabs)
        except ValueError as exc:  # a robot the slabs cannot take (too many vertices with the margin)
            raise ScenarioError(sc.path or "<scenario>", "robot", str(exc).removeprefix("robot: ")) from None
    return CSpace.from_scenario(sc)


def make_adapter(sc: Scenario, cspace):
    """The state-space adapter of :mod:`planners.adapters` for the scenario's space."""
    if sc.turning_radius is not None:
        from ..adapters.car import CarSpace

        return CarSpace(cspace, sc.space, sc.turning_radius)
    if sc.space == "se2":
        from ..adapters.se2 import SE2Space

        return SE2Space(cspace)
    from ..adapters.translation import TranslationSpace

    return TranslationSpace(cspace)


def _proofs_before_sampling(sc: Scenario, cspace, queries, tlim: float, name: str, seed: int,
                            rotates: bool) -> tuple[list, list]:
    """The queries proven unsolvable before any sampling, answered without it; None for the
    others; and the seconds each check took. A rotating robot: the slab graph's POSSIBLE regions
    within a small share of the time limit (:func:`planners.core.exact_se2.quick_proof`; a point
    robot does not turn: nothing to prove). A translating one: start and goal in different
    components of the free C-space (:func:`planners.core.exact.separated_proof`)."""
    if rotates and not cspace.body_pieces:
        return [None] * len(queries), [0.0] * len(queries)
    if rotates:
        from .exact_se2 import quick_proof as prove
    else:
        from .exact import separated_proof as prove

    out, spent = [], []
    for q in queries:
        t = _now()
        r = prove(sc, cspace, q, tlim) if tuple(q.start) != tuple(q.goal) else None
        if r is not None:
            r.planner, r.seed = name, seed
        out.append(r)
        spent.append(_now() - t)
    return out, spent


def run_planner(*args, **kwargs):
    """See :func:`planners.core.routine.run_planner` (re-exported here)."""
    from .routine import run_planner as run

    return run(*args, **kwargs)


def shortest_path(scenario, query_index: int = 0) -> PlanResult:
    """Exact shortest path of a scenario (a path or a Scenario), as a :class:`PlanResult`.

    Unsolvable scenes come back with ``solved`` false and a message saying whether
    that was proven.
    """
    return plan(scenario, planner="exact", all_queries=query_index > 0) if query_index == 0 else \
        plan(scenario, planner="exact", all_queries=True).queries[query_index]
