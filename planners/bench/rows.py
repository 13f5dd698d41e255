"""One bench run and its row: the fields of a row, the child's entry (:func:`run_one`, which
plans through :func:`planners.core.plan.plan` as ``cspace plan`` does), the hard limit
after which a run is killed, and the completion of a row with the task's identity.

Both the sweep (:mod:`planners.bench.sweep`) and its children (:mod:`planners.bench.pool`)
read these, so they live below both.
"""
from __future__ import annotations

import os
import threading


# Hard limit of one run: budget x HARD_FACTOR + HARD_MARGIN seconds (process start,
# C-space build, simplification and verification all fit many times over).
HARD_FACTOR = 2.0


HARD_MARGIN = 30.0


# Fields of a row, in CSV order. Times in seconds; lengths in scenario units.
FIELDS = (
    "scenario", "file", "planner", "time_budget", "seed", "status", "solved",
    "length", "length_unsimplified", "optimum", "reference", "error", "error_unsimplified",
    "first_solution_s", "solve_s", "simplify_s", "state_checks", "motion_checks",
    "wall_s", "message", "min_clearance", "min_clearance_bound", "clearance_s", "upper", "error_upper",
    "graph_states",
)


# clearance_s: measuring min_clearance, after the run's timed solve (in wall_s, not in solve_s).
TIMING_FIELDS = ("first_solution_s", "solve_s", "simplify_s", "wall_s", "clearance_s")


STATUSES = ("ok", "crashed", "timeout")


MARK = "CSPACE_BENCH_ROW "


def run_one(task: dict, scenario=None, cspace=None) -> dict:
    """Plan one seeded run in this process and return its row (status ``ok``).

    The run goes through :func:`planners.core.plan.plan`, the routine of ``cspace plan``
    (anytime planners solved in slices to time the first solution): the path is
    simplified and verified exactly, and a run is solved only if it passes.
    ``scenario`` and ``cspace`` reuse a loaded scenario and its built C-space. The row's
    ``min_clearance`` is the one ``plan()`` measures on the solved path, after the solve
    (so outside ``solve_s``; its time is ``clearance_s``).
    """
    from cspace.io.load import load_scenario

    from ..core.plan import plan

    if task.get("abort"):
        os.abort()
    sc = scenario if scenario is not None else load_scenario(task["file"], space=task.get("space"))
    planner, budget, iters = task["planner"], float(task["time_budget"]), task.get("iterations")
    res = plan(sc, planner=planner, time=budget, seed=int(task["seed"]), iterations=iters,
               cspace=cspace, slices=True, slabs=task.get("slabs") if cspace is None else None,
               objective=task.get("objective", "length"))
    ok = bool(res.solved)
    opt = task["optimum"]
    length = float(res.length) if ok else None
    raw_len = res.length_unsimplified if ok else None
    return {
        "scenario": task["scenario"], "file": task["file"], "planner": planner, "time_budget": budget,
        "seed": int(task["seed"]), "status": "ok", "solved": ok,
        "length": length, "length_unsimplified": raw_len, "optimum": opt,
        "reference": task.get("reference", "optimum"),
        "error": _error(length, opt), "error_unsimplified": _error(raw_len, opt),
        # SE(2): the exact planner's certified path is an upper bound on the optimum; a run may beat it
        "upper": task.get("upper"), "error_upper": _error(length, task.get("upper")),
        # A route records only the stages it ran (a proof before sampling: no solve, no checks).
        "first_solution_s": res.first_solution if ok else None, "solve_s": res.timings.get("solve", 0.0),
        "simplify_s": res.timings.get("simplify", 0.0), "state_checks": int(res.checks.get("states", 0)),
        "motion_checks": int(res.checks.get("motions", 0)), "graph_states": res.checks.get("graph_states"),
        "wall_s": None,
        "message": res.message, "progress": res.progress,
        # Measured by plan() on the solved path after its solve (None: unsolved, or a car).
        "min_clearance": res.min_clearance, "min_clearance_bound": res.min_clearance_bound,
        "clearance_s": res.timings.get("clearance"),
    }


def _error(length, optimum):
    """Relative excess length over the optimum (None when either is missing).

    >>> _error(3.0, 2.0)
    0.5
    """
    if length is None or not optimum:
        return None
    return length / optimum - 1.0


live_children: set = set()  # child processes running now, killed on Ctrl-C


stop_event = threading.Event()


def hard_limit(budget: float) -> float:
    """Seconds after which a run is killed and recorded as ``timeout``.

    >>> hard_limit(1.0)
    32.0
    """
    return budget * HARD_FACTOR + HARD_MARGIN


def complete_row(task: dict, row: dict, wall: float) -> dict:
    """A full row: the task's identity, the child's results, the wall time."""
    base = {f: None for f in FIELDS}
    base.update({"scenario": task["scenario"], "file": task["file"], "planner": task["planner"],
                 "time_budget": task["time_budget"], "seed": task["seed"], "optimum": task["optimum"],
                 "reference": task.get("reference", "optimum"), "upper": task.get("upper"), "solved": False,
                 "progress": []})
    base.update(row)
    base["wall_s"] = wall
    base["order"] = task["order"]
    return base
