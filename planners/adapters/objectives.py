"""Optimisation objectives: path length, clearance, or a balance of the two.

OMPL 2.0's Python bindings bind ``PathLengthOptimizationObjective`` but not
``MaximizeMinClearanceObjective``; both clearance objectives here are Python
subclasses of OMPL's classes (checked to run inside RRTstar and the other optimising
planners), fed by the project's clearance (the adapter's ``clearance_functions``:
in translation, the exact distance from the reference point, or from a motion's
segment, to the nearest C-obstacle piece):

- ``length``: OMPL's default, path length (nothing is set: the plans of today);
- ``clearance``: maximise the minimum clearance (OMPL's MaximizeMinClearanceObjective,
  rewritten): a motion's cost is its clearance, costs combine by ``min``, a larger cost
  is better, and no cost ever satisfies it (an anytime planner keeps improving);
- ``balanced``: the integral along the path of ``1 + w · ρ / (c + ρ)`` (c the clearance,
  ρ = ``BALANCED_SCALE`` × the scene's extent, w = ``BALANCED_WEIGHT`` = 1): far from
  obstacles (c ≫ ρ) a unit of length costs 1, grazing them (c = 0) it costs 1 + w = 2,
  so a detour is taken when the length it adds is paid back by the clearance it gains
  (never one more than doubling the length). It is a sum of costs, so RRTstar and its kin are
  asymptotically optimal for it (OMPL's ``StateCostIntegralObjective``, trapezoids along
  each motion at the space's resolution).

The objective is set by :func:`planners.core.routine.run_planner` (the one routine), which
then does not simplify the path (OMPL's simplifier shortens, trading clearance away).
Only the optimising planners checked with Python objectives take one (``OBJECTIVE_PLANNERS``):
PRM and PRMstar evaluate costs on a thread of their own, where a Python objective
deadlocks; FMT and BFMT crashed (SIGSEGV); InformedRRTstar and AORRTC found no path with
the clearance objective (their informed sampling assumes a cost that adds up); the
non-optimising planners ignore objectives.
"""
from __future__ import annotations

import math

OBJECTIVES = ("length", "clearance", "balanced")
BALANCED_WEIGHT = 1.0  # w: extra cost of a unit of length at zero clearance
BALANCED_SCALE = 0.05  # ρ as a fraction of the bounds' extent (the clearance that halves the extra cost)


OBJECTIVE_PLANNERS = ("RRTstar", "SORRTstar", "BITstar")


def check_objective(name, planner: str = "RRTstar") -> str:
    """The objective's name, or ValueError (naming the allowed objectives, or the planners
    that take one).

    >>> check_objective("Balanced")
    'balanced'
    >>> check_objective("clearance", "RRTConnect")
    Traceback (most recent call last):
    ...
    ValueError: clearance needs an optimising planner that takes a Python objective: RRTstar, SORRTstar or BITstar (got RRTConnect)
    """
    n = str(name).lower()
    if n not in OBJECTIVES:
        raise ValueError(f"must be one of {', '.join(OBJECTIVES)}, got {name!r}")
    if n != "length" and planner.lower() not in {p.lower() for p in OBJECTIVE_PLANNERS}:
        raise ValueError(f"{n} needs an optimising planner that takes a Python objective: "
                         f"{', '.join(OBJECTIVE_PLANNERS[:-1])} or {OBJECTIVE_PLANNERS[-1]} (got {planner})")
    return n


def make_objective(name: str, si, adapter):
    """An OMPL objective for ``name`` over the adapter's clearance, or None for ``length``
    (OMPL's default path length, as without the option)."""
    if name == "length":
        return None
    from .glue import ompl

    ob = ompl()[0]
    state, motion = adapter.clearance_functions()
    if name == "clearance":
        return _min_clearance_class(ob)(si, state, motion)
    xmin, xmax, ymin, ymax = adapter.cspace.bounds
    rho = BALANCED_SCALE * max(xmax - xmin, ymax - ymin)
    return _balanced_class(ob)(si, state, rho, BALANCED_WEIGHT)


_classes: dict = {}


def _min_clearance_class(ob):
    if "min" not in _classes:
        class MaximizeMinClearance(ob.OptimizationObjective):
            """OMPL's MaximizeMinClearanceObjective in Python: cost = clearance, combined by
            min, larger is better; a motion's cost is the clearance of its whole segment."""

            def __init__(self, si, state, motion):
                super().__init__(si)
                self._state, self._motion = state, motion
                self.setCostThreshold(ob.Cost(math.inf))  # never satisfied: keep improving

            def stateCost(self, s):
                return ob.Cost(self._state(s))

            def motionCost(self, s1, s2):
                return ob.Cost(self._motion(s1, s2))

            def isCostBetterThan(self, c1, c2):
                return c1.value() > c2.value()

            def combineCosts(self, c1, c2):
                return ob.Cost(min(c1.value(), c2.value()))

            def identityCost(self):
                return ob.Cost(math.inf)

            def infiniteCost(self):
                return ob.Cost(-math.inf)

        _classes["min"] = MaximizeMinClearance
    return _classes["min"]


def _balanced_class(ob):
    if "balanced" not in _classes:
        class Balanced(ob.StateCostIntegralObjective):
            """Length weighted by 1 + w · ρ / (c + ρ): a sum of costs along the path."""

            def __init__(self, si, state, rho, weight):
                super().__init__(si, True)  # interpolate along motions
                self._state, self._rho, self._w = state, rho, weight

            def stateCost(self, s):
                return ob.Cost(1.0 + self._w * self._rho / (self._state(s) + self._rho))

        _classes["balanced"] = Balanced
    return _classes["balanced"]
