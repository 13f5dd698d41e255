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


def warmed(sc, slabs: int | None = None, cs=None) -> tuple:
    """``(cspace, exact result or None)``: a scenario's C-space as the runs use it, its lazy parts
    filled once here rather than in every forked run (whose work is lost when it exits). A
    rotating robot: every slab built, the proof before sampling's regions and their labelled
    components (:func:`planners.core.exact_se2.prepare`: every run then answers it by lookups) and,
    in SE(2), the exact planner run on it (None for a car, which cannot follow its turns in place);
    translation: the exact planner's C-space and result. ``cs``: the rotating robot's C-space if
    it is already built (its slabs are filled here)."""
    from ..core.plan import build_cspace, plan

    if sc.rotates:
        from ..core.exact_se2 import prepare

        cs = cs if cs is not None else build_cspace(sc, slabs)
        for k in range(cs.slabs):
            cs.slab(k)
        if cs.body_pieces:  # (a point robot does not turn: no proof before sampling)
            prepare(cs)
        return cs, (plan(sc, planner="exact", cspace=cs) if sc.space == "se2" else None)
    res = plan(sc, planner="exact")
    return res.cspace, res


def reference(files: list[str], quiet: bool = True, held: dict | None = None, space: str | None = None,
              slabs: int | None = None, before=None) -> list[dict]:
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
    ``before(entries)``: called once every file is read, before any reference is computed, with
    the same entries but ``optimum`` None (what names a run: a campaign's conflicts are
    found before the costly part).
    """
    from cspace.io.load import load_scenario

    from ..core.plan import build_cspace

    loaded = []  # (file, scenario, its C-space if it rotates: lazy, so cheap to build here)
    for f in files:
        full = os.path.abspath(f)
        if any(o[0] == full for o in loaded):
            raise InputError(f, "scenario", "given twice")
        sc = load_scenario(f, space=space)
        loaded.append((full, sc, build_cspace(sc, slabs) if sc.rotates else None))
    names = [sc.name for _, sc, _ in loaded]
    names = [f"{n} ({os.path.relpath(files[i])}, #{i + 1})" if names.count(n) > 1 else n for i, n in enumerate(names)]
    ids = [{"file": full, "scenario": name, "optimum": None, "upper": None,
            "reference": "lower_bound" if sc.rotates else "optimum", "space": sc.space if sc.rotates else "translation",
            "slabs": cs.slabs if sc.rotates else None} for (full, sc, cs), name in zip(loaded, names)]
    if before is not None:
        before(ids)
    out = []
    for (full, sc, cs), entry in zip(loaded, ids):
        cs, ex = warmed(sc, slabs, cs)
        entry = dict(entry)
        if sc.rotates:  # SE(2) or a car: the inscribed disk gives a lower bound on the length
            from ..core.bounds import disk_bound

            db = disk_bound(sc, sc.all_queries()[0])
            entry["optimum"] = db.lower_bound if math.isfinite(db.lower_bound) else None
            note = db.message  # "lower bound L (inscribed disk r = ...)", or why there is none
            if ex is not None:  # SE(2); a car cannot follow the exact planner's turns in place
                entry.update(upper=float(ex.length) if ex.solved else None, exact_s=ex.timings.get("solve"),
                             exact_total_s=ex.timings.get("total"), exact_message=ex.message)
                note += f"; exact: {ex.message}"
        else:
            entry["optimum"] = float(ex.length) if ex.solved else None
            del entry["upper"]
            note = f"exact shortest path {ex.length:.6g} ({ex.message})"
        out.append(entry)
        if held is not None:
            held[full] = (sc, cs)
        if not quiet:
            sys.stderr.write(f"{sc.name}: {note}\n")
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
