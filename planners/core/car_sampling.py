"""``auto``'s first sampling for a car: its direct curve, and a Reeds–Shepp car's own RRT-Connect (compiled, or the same in Python).

OMPL's RRTConnect on a car spends most of a small scene's time in its own nearest-neighbour
search (the Reeds–Shepp length to the tree's nodes, at every step of either tree); the
compiled search (:func:`cspace.car.connect.connect`) grows its trees the same way with a
search that passes over nodes by lower bounds of that length, and asks the adapter's certified
motion test for every motion. :func:`connect_slice` runs it for :data:`SLICE_ITERATIONS`
samples at most, stepping :data:`STEP_SHARE` of the space's extent, and returns a
:class:`PlanResult` as the sampling planners' (the path re-checked by the adapter; shortened
under the same validator when asked), or None on a scene larger than OMPL's range bound for a
car (:func:`small_car_scene`: a map of hundreds of turning radii, whose first queries build slabs
inside the slice): the caller samples with OMPL there, as before. On the pure path the search is
the same one in Python (:func:`cspace.car.connect.search_python`): the same path.
"""
from __future__ import annotations

import math
import time

import numpy as np

from .result import PlanResult

SLICE_ITERATIONS = 1000  # samples of the slice (each grows one tree, then connects the other)
# Its step along a curve: this share of the space's extent (R^2's diagonal plus SO(2)'s pi at
# OMPL's SE(2) weight 1/2), half OMPL's own range (1/5). Median samples to a path over 20 seeds:
# parking 190 at 1/10, 487 at 1/5; the other bundled car scenes 10-40 either way.
STEP_SHARE = 0.1


def _extent(adapter) -> float:
    xmin, xmax, ymin, ymax = adapter.cspace.bounds
    return math.hypot(xmax - xmin, ymax - ymin) + 0.5 * math.pi


def step_length(adapter) -> float:
    """The slice's step: :data:`STEP_SHARE` of the space's extent.

    >>> class A: cspace = type("C", (), {"bounds": (0.0, 30.0, 0.0, 40.0)})()
    >>> round(step_length(A()), 6)
    5.15708
    """
    return STEP_SHARE * _extent(adapter)


def small_car_scene(adapter) -> bool:
    """Whether OMPL's own range (:data:`planners.adapters.glue.RANGE_SHARE` of the extent) is within
    the adapter's range bound (:data:`planners.adapters.car.RANGE_RADII` turning radii): a scene
    of about 100 radii or less, as the bundled car scenes (10-20), not a building's map (hundreds).

    >>> class A: cspace = type("C", (), {"bounds": (0.0, 30.0, 0.0, 40.0)})(); k = 0; max_range = 20.0
    >>> small_car_scene(A())
    True
    """
    from ..adapters.glue import RANGE_SHARE

    cap = getattr(adapter, "max_range", None)
    return cap is not None and RANGE_SHARE * _extent(adapter) <= math.ldexp(cap, -adapter.k)


def connect_slice(sc, adapter, query, pair, seed: int, clock, share_s: float, iterations: int | None,
                  simplify: bool) -> PlanResult | None:
    """The slice on one query within ``share_s`` seconds, or all the time ``clock`` has
    left (``clock.left()``) where the caller counts ``iterations`` (its samples are counted either
    way, so where it ends is the same on every machine that finishes them in time): a solved or
    unsolved PlanResult, or None on a large scene (OMPL's slice there). The
    shortening stops at the clock's end (``clock.t0 + clock.limit``, ``time.perf_counter()``)."""
    from cspace.car.connect import connect

    if not small_car_scene(adapter):
        return None
    t0, end = time.perf_counter(), clock.t0 + clock.limit
    budget = clock.left() if iterations is not None else min(share_s, clock.left())
    adapter.forget()  # a new run: nothing remembered from the last query's
    got = connect(adapter.motion_free, pair[0], pair[1], adapter.radius, adapter.cspace.bounds,
                  step_length(adapter), seed, SLICE_ITERATIONS, deadline=t0 + max(budget, 0.0))
    path, stats = got
    found_cpu = time.process_time()
    solve_s = time.perf_counter() - t0
    base = dict(scenario=sc.name, planner="RRTConnect", seed=seed, start=tuple(query.start), goal=tuple(query.goal))
    checks = {"states": 0, "motions": stats["motions"] or 0, "samples": stats["iterations"]}
    if path is None:
        why = "its time" if stats.get("late") else f"{SLICE_ITERATIONS} samples"
        return PlanResult(solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                          timings={"solve": solve_s}, checks=checks, stages=["solve"],
                          message=f"no path found within the budget (the car's own RRT-Connect slice: {why})", **base)
    ok, why = adapter.verify(path, query.start, query.goal)
    if not ok:  # every motion was certified as the trees grew: a failure here is a fault, reported
        return PlanResult(solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                          timings={"solve": solve_s}, checks=checks, stages=["solve", "verify"],
                          message=f"the car's own RRT-Connect's path failed the re-check ({why}): not solved", **base)
    raw_len = adapter.length(path)
    out, note, t1 = path, "", time.perf_counter()
    if simplify:
        from .exact_se2 import shorten

        out, note = shorten(adapter, path, query, time_limit=end - time.perf_counter())
        note = f"; {note}" if note else ""
    return PlanResult(solved=True, exact=True, path=out, length=raw_len if out is path else adapter.length(out),
                      timings={"solve": solve_s, "simplify": time.perf_counter() - t1}, checks=checks,
                      stages=["solve", "verify"] + (["simplify"] if simplify else []),
                      message=f"certified solution (the car's own RRT-Connect: {stats['iterations']} samples, "
                              f"{len(path) - 1} curves{note})",
                      length_unsimplified=raw_len, first_path_cpu=found_cpu, first_solution=solve_s, **base)


def direct_curve(sc, adapter, query, pair, seed: int) -> PlanResult | None:
    """``auto``'s first try for a car: the shortest curve from start to goal, the whole path when
    the car's motion validator certifies it free (one curve check; None otherwise)."""
    t = time.perf_counter()
    adapter.forget()  # a new run: nothing remembered from the last query's
    if not adapter.motion_free(*pair):
        return None
    found_cpu = time.process_time()
    path = np.array(pair, dtype=np.float64)
    ok, _ = adapter.verify(path, query.start, query.goal)
    if not ok:  # certified a moment ago: a fault, left to the stages after
        return None
    length = adapter.length(path)
    return PlanResult(scenario=sc.name, solved=True, exact=True, path=path, length=length, planner="auto",
                      seed=seed, timings={"solve": time.perf_counter() - t}, checks={"states": 0, "motions": 1},
                      stages=["direct curve"], start=tuple(query.start), goal=tuple(query.goal),
                      message="certified solution: the direct curve from start to goal is free",
                      length_unsimplified=length, first_path_cpu=found_cpu)
