"""What a ``cspace bench`` sweep runs: each scenario's reference length, computed once, and
the tasks, one per (scenario, planner, budget, seed) in a deterministic order.

The reference of a translation scenario is its exact shortest path
(:mod:`cspace.paths.shortest` through ``plan(planner="exact")``); a rotating robot's is
the inscribed-disk lower bound (:mod:`planners.core.bounds`), so its error is an upper
bound; in SE(2) the exact planner's certified path (the slab graph, shortened) is also
computed once, an upper bound on the optimum, with the exact planner's own time. The sweep
itself is :mod:`planners.bench`.
"""
from __future__ import annotations

import math
import os
import sys

from ..errors import InputError


def warmed(sc, slabs: int | None = None) -> tuple:
    """``(cspace, exact result or None)``: a scenario's C-space as the runs use it, its lazy parts
    filled once here rather than in every forked run (whose work is lost when it exits). A
    rotating robot: every slab built, the proof before sampling's regions and their labelled
    components (:func:`planners.core.exact_se2.prepare`: every run then answers it by lookups) and,
    in SE(2), the exact planner run on it (None for a car, which cannot follow its turns in place);
    translation: the exact planner's C-space and result."""
    from ..core.plan import build_cspace, plan

    if sc.rotates:
        from ..core.exact_se2 import prepare

        cs = build_cspace(sc, slabs)
        for k in range(cs.slabs):
            cs.slab(k)
        if cs.body_pieces:  # (a point robot does not turn: no proof before sampling)
            prepare(cs)
        return cs, (plan(sc, planner="exact", cspace=cs) if sc.space == "se2" else None)
    res = plan(sc, planner="exact")
    return res.cspace, res


def reference(files: list[str], quiet: bool = True, held: dict | None = None, space: str | None = None,
              slabs: int | None = None) -> list[dict]:
    """Load each scenario and compute its reference length once.

    Returns ``[{"file", "scenario", "optimum", "reference", "space", "slabs"}]``.
    Translation: ``optimum`` is the exact shortest path's length (``reference`` is
    ``"optimum"``; None if no path exists). SE(2) has no exact optimum: ``optimum`` is
    the inscribed-disk lower bound on the reference point's path length
    (:mod:`planners.core.bounds`; ``reference`` is ``"lower_bound"``), so a row's
    ``error = length / lower bound - 1`` is an upper bound on its true error.
    ``scenario`` is the scenario's name, made unique when two files share a name (the
    file's name is added), so that the summary, the figure and the logs keep them
    apart. With ``held``, ``held[file] = (scenario, cspace)`` keeps each built C-space
    for the runs. A missing or malformed file is a ScenarioError (exit 2).
    """
    from cspace.io.load import load_scenario

    out = []
    for f in files:
        full = os.path.abspath(f)
        if any(o["file"] == full for o in out):
            raise InputError(f, "scenario", "given twice")
        sc = load_scenario(f, space=space)
        cs, ex = warmed(sc, slabs)
        if sc.rotates:  # SE(2) or a car: the inscribed disk gives a lower bound on the length
            from ..core.bounds import disk_bound

            db = disk_bound(sc, sc.all_queries()[0])
            bound = db.lower_bound if math.isfinite(db.lower_bound) else None
            entry = {"file": full, "scenario": sc.name, "optimum": bound, "reference": "lower_bound",
                     "space": sc.space, "slabs": cs.slabs, "upper": None}
            note = db.message  # "lower bound L (inscribed disk r = ...)", or why there is none
            if ex is not None:  # SE(2); a car cannot follow the exact planner's turns in place
                entry.update(upper=float(ex.length) if ex.solved else None, exact_s=ex.timings.get("solve"),
                             exact_total_s=ex.timings.get("total"), exact_message=ex.message)
                note += f"; exact: {ex.message}"
            out.append(entry)
        else:
            out.append({"file": full, "scenario": sc.name, "optimum": float(ex.length) if ex.solved else None,
                        "reference": "optimum", "space": "translation", "slabs": None})
            note = f"exact shortest path {ex.length:.6g} ({ex.message})"
        if held is not None:
            held[full] = (sc, cs)
        if not quiet:
            sys.stderr.write(f"{sc.name}: {note}\n")
    names = [o["scenario"] for o in out]
    for i, o in enumerate(out):
        if names.count(o["scenario"]) > 1:
            o["scenario"] = f"{o['scenario']} ({os.path.relpath(files[i])}, #{i + 1})"
    return out


def make_tasks(scenarios, planners, times, runs, iterations=None, abort_on=None, objective="length") -> list[dict]:
    """One task per (scenario, planner, budget, seed), in the deterministic row order."""
    tasks = []
    for si, sc in enumerate(scenarios):
        for pi, p in enumerate(planners):
            for t in times:
                for seed in range(runs):
                    tasks.append({"order": [si, pi, t, seed], "file": sc["file"], "scenario": sc["scenario"],
                                  "optimum": sc["optimum"], "reference": sc.get("reference", "optimum"),
                                  "upper": sc.get("upper"),
                                  "space": sc.get("space"), "slabs": sc.get("slabs"),
                                  "planner": p, "time_budget": t, "seed": seed,
                                  "iterations": iterations, "objective": objective,
                                  "abort": abort_on == (p, seed)})
    return tasks
