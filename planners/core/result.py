"""What a plan produced: :class:`PlanResult`, the one record that ``cspace plan``, the API,
the ``exact`` planner and every bench run return (its JSON form is ``as_dict``)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # annotations only (this module imports no geometry)
    from cspace.io.scenario.schema import Scenario
    from cspace.translation.cspace import CSpace


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
    # CPU seconds from the start of plan() until this query's first path existed (OMPL's first
    # solution, before shortening; exact's certified path, re-verified, before shortening),
    # the scenario's load and C-space included; None without a path (or for an anytime planner
    # run without the bench's slices, whose first solution is not timed). The planners stamp
    # time.process_time() here and plan() makes it relative.
    first_path_cpu: float | None = None
    # Clearance (filled by plan() on solved paths; cspace.translation.clearance): the smallest distance
    # between the ROBOT (not inflated) swept along the path and any obstacle, the reference
    # pose where it occurs, the obstacle's closest point, "exact" (translation) or "lower"
    # (SE(2): a certified lower bound); ``touches``: the path touches an obstacle (distance 0,
    # as the exact planner's optimum does at its bends without a clearance); ``clearance``:
    # the margin D the plan was asked to keep; ``objective``: what the planner optimised.
    min_clearance: float | None = None
    min_clearance_at: tuple | None = None
    min_clearance_obstacle: tuple | None = None
    min_clearance_bound: str | None = None
    touches: bool = False
    clearance: float = 0.0
    objective: str = "length"
    # A car's path: per motion its start and end poses and its segments (type, length,
    # direction), see planners.adapters.car.CarSpace.curves; None for other spaces.
    curves: list | None = None
    # A rotating robot's proof that no path exists (cspace.se2.exact's JSON form; written
    # by ``cspace plan --proof FILE``, re-checked by ``cspace check-proof``); None otherwise.
    proof: dict | None = field(default=None, repr=False, compare=False)
    # ``auto`` (planners.core.auto): the stage that answered ("proof", "slab graph", "sampling",
    # "refinement"; None where none did or for another planner).
    answered_by: str | None = None
    # The objects behind the result, for plots and further queries (not serialised).
    scenario_data: Scenario | None = field(default=None, repr=False, compare=False)
    cspace: CSpace | None = field(default=None, repr=False, compare=False)

    @property
    def proven_unsolvable(self) -> bool:
        """Was this query proven to have no collision-free path (not just left unsolved)?

        >>> PlanResult("s", False, False, np.zeros((0, 2)), math.inf, "exact", 0,
        ...            message="proven unsolvable: start and goal in different components").proven_unsolvable
        True
        """
        return self.proof is not None or "proven unsolvable" in self.message

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
            "clearance": self.clearance,
            "objective": self.objective,
            "min_clearance": _finite(self.min_clearance),
            "min_clearance_at": list(self.min_clearance_at) if self.min_clearance_at else None,
            "min_clearance_obstacle": list(self.min_clearance_obstacle) if self.min_clearance_obstacle else None,
            "min_clearance_bound": self.min_clearance_bound,
            "touches": self.touches,
            "proven_unsolvable": self.proven_unsolvable,
            "answered_by": self.answered_by,
        }
        if self.curves is not None:
            d["curves"] = self.curves
        if nested and self.cspace_report is not None:
            d["cspace"] = self.cspace_report
        if nested and self.queries is not None:
            d["queries"] = [q.as_dict(nested=False) for q in self.queries]
        return d


def _finite(x):
    """A float for JSON: None for None, "inf" for no obstacle at all (JSON has no infinity)."""
    return None if x is None else (float(x) if math.isfinite(x) else "inf")
