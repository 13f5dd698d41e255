"""``cspace bench`` and clearance: the ``--objective`` option's checks and the clearance
column of the summary.

Every solved run's ``min_clearance`` is the one :func:`planners.core.plan.plan` measures
(:mod:`cspace.translation.clearance`: exact in translation, a certified lower bound in SE(2)
and, along the curves, for cars: :mod:`cspace.car.clearance`), after the run's timed solve. ``--objective`` is handed to the
one planning routine (:func:`planners.core.routine.run_planner`) through ``plan()``; it is
checked here once, before any run, so that a planner or a scenario that cannot take it
is one line and exit 2, not a sweep of crashed rows.
"""
from __future__ import annotations

from ..errors import InputError
from ..adapters.objectives import OBJECTIVE_PLANNERS, OBJECTIVES, check_objective


def default_planners(objective: str, planners: tuple[str, ...]) -> tuple[str, ...]:
    """The default contestants: all of ``planners`` for ``length``, else those that take
    the objective (a non-optimising planner would ignore it; plan() refuses it).

    >>> default_planners("clearance", ("RRTConnect", "RRTstar", "PRMstar", "BITstar"))
    ('RRTstar', 'BITstar')
    >>> default_planners("length", ("RRTConnect", "RRTstar"))
    ('RRTConnect', 'RRTstar')
    """
    if objective == "length":
        return tuple(planners)
    return tuple(p for p in planners if p in OBJECTIVE_PLANNERS)


def check_planners(objective: str, planners: list[str]) -> None:
    """InputError (``--objective``) if a planner cannot take the objective.

    >>> check_planners("clearance", ["RRTstar", "BITstar"])
    >>> check_planners("clearance", ["RRTstar", "RRTConnect"])
    Traceback (most recent call last):
    ...
    planners.errors.InputError: bench: --objective: clearance needs an optimising planner that takes a Python objective: RRTstar, SORRTstar or BITstar (got RRTConnect)
    """
    if objective not in OBJECTIVES:
        raise InputError("bench", "--objective", f"must be one of {', '.join(OBJECTIVES)}, got {objective!r}")
    for p in planners:
        try:
            check_objective(objective, p)
        except ValueError as exc:
            raise InputError("bench", "--objective", str(exc)) from None


def check_scenarios(objective: str, held: dict) -> None:
    """InputError (the scenario's file, ``--objective``) if a scenario's space has no
    clearance objective (a car: its curves are not what the objective measures).

    ``held`` maps a file to ``(scenario, cspace)``, as :func:`planners.bench.reference` fills it.
    """
    if objective == "length":
        return
    from ..core.plan import make_adapter

    for file, (sc, cs) in held.items():
        if getattr(make_adapter(sc, cs), "clearance_functions", None) is None:
            raise InputError(file, "--objective", f"{objective} is not available for space {sc.space!r} "
                                                  "(translation and se2 only)")


def clearance_cell(median: float | None, lower: bool) -> str:
    """The summary's min-clearance cell: the median over solved runs, ``>=`` where it is a
    certified lower bound (SE(2)), ``-`` where nothing was measured (no solved run, a car).

    >>> clearance_cell(0.30168, False), clearance_cell(0.2, True), clearance_cell(None, False)
    ('0.3017', '>= 0.2000', '-')
    """
    if median is None:
        return "-"
    return f">= {median:.4f}" if lower else f"{median:.4f}"
