"""A Dubins car's proof that no path exists, as a PlanResult: the reach of one end closed under
the forward car's steps (:func:`cspace.car.dubins_reach.reach_proof`), grown from the start and
from the goal (driving backward), each at the coarse step before either at the fine one, within
a share of the time limit. ``auto`` runs it after a Dubins query's third restart of sampling
(:mod:`planners.core.auto_dubins`), and ``exact`` before it gives up on a car; ``cspace
check-proof`` re-checks the proof (:mod:`planners.core.dubins_check`)."""
from __future__ import annotations

import math
import time
import weakref

import numpy as np

from .result import PlanResult

REACH_SHARE = 0.2  # of the time limit, at most, for both ends together
REACH_MAX = 3.0    # seconds, at most, whatever the limit (the cells' cap ends it first on the scenes we know)
# C-space -> the (start, goal, backward, steps) whose attempts ran to their end without a proof (each
# is deterministic: the same regions and cap answer the same); an attempt cut by time is not kept.
_NO_REACH: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def reach_budget(time_limit: float) -> float:
    """The seconds ``auto`` gives the reach proof of a query: :data:`REACH_SHARE` of its limit,
    at most :data:`REACH_MAX`.

    >>> reach_budget(5.0), reach_budget(60.0)
    (1.0, 3.0)
    """
    return min(REACH_SHARE * max(float(time_limit), 0.0), REACH_MAX)


def reach_result(sc, cspace, regions, query, budget: float, ends: tuple = ("start", "goal"),
                 steps: tuple | None = None) -> PlanResult | None:
    """A "proven unsolvable" result with its proof (format ``cspace-dubins-proof/1``) where the
    reach of the start, or of the goal driving backward, is confined away from the other end;
    None otherwise (not a Dubins car, a point robot, the reach not confined within the cap, or
    ``budget`` seconds spent). ``regions``: the C-space's slab regions
    (:func:`planners.core.exact_se2.slab_regions_of`), whose POSSIBLE the reach reads; ``ends``:
    the reaches tried ("start": forward from it, "goal": backward from it); ``steps``: the
    resolutions tried, coarse first (default :data:`cspace.car.dubins_reach.STEPS`). An end
    already tried to its end on this query at these steps is not tried again."""
    from cspace.car.dubins_reach import MAX_CELLS, STEPS, reach_proof

    steps = STEPS if steps is None else tuple(steps)
    if sc.space != "dubins" or not cspace.body_pieces or tuple(query.start) == tuple(query.goal):
        return None
    key = (tuple(map(float, query.start)), tuple(map(float, query.goal)))
    tried = _NO_REACH.setdefault(cspace, set())
    sides = [e == "goal" for e in ("start", "goal") if e in ends and key + (e == "goal", steps) not in tried]
    t0 = time.perf_counter()
    deadline = t0 + budget
    for frac, backward in ((f, b) for f in steps for b in sides):  # coarse first, either end
        proof = reach_proof(regions, query.start, query.goal, float(sc.turning_radius), backward=backward,
                            deadline=deadline, steps=(frac,), max_cells=int(MAX_CELLS * (STEPS[0] / frac) ** 4))
        if proof is not None:
            cells = sum(b - a for s in proof["slabs"] for _, a, b in s["cells"])
            held = sum(1 for s in proof["slabs"] if s["cells"])
            end, other = ("goal", "start") if backward else ("start", "goal")
            return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                              planner="", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                              timings={"reach": time.perf_counter() - t0},
                              checks={"reach_cells": cells, "reach_slabs": held}, stages=["reach"], proof=proof,
                              message=f"proven unsolvable: a forward-only car cannot reach the goal (the {end}'s "
                                      f"{'backward' if backward else 'forward'} reach, {cells} cells in {held} heading "
                                      f"slabs, is closed under the car's steps of {proof['step']:g} and keeps the "
                                      f"{other} out)")
    if time.perf_counter() <= deadline:
        tried.update(key + (b, steps) for b in sides)
    return None
