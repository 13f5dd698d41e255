"""Optimisation objectives: path length, clearance, or a balance of the two.

OMPL 2.0's Python bindings bind ``PathLengthOptimizationObjective`` but not
``MaximizeMinClearanceObjective``; both clearance objectives here are Python
subclasses of OMPL's classes (checked to run inside RRTstar and the other optimising
planners), fed by :func:`clearance_functions` (in translation: a state's clearance is the
exact float distance from the reference point to the nearest C-obstacle piece, through the
grid of :class:`cspace.translation.point_clearance.PointClearance`, computed once per state; a
motion's is :func:`cspace.translation.point_clearance.disc_bound` of its ends' clearances and
its length, a certified lower bound of the segment's exact clearance that costs no
geometry; in SE(2), the adapter's ``clearance_functions``):

- ``length``: OMPL's default, path length (nothing is set: the plans of today);
- ``clearance``: maximise the least clearance through its soft minimum: a motion of
  clearance c (the bound above) costs exp(−c/σ), σ = the bounds' extent / ``SOFTMIN_STEPS``,
  and costs add (OMPL's own sum, identity and comparison, in C++: RRTstar combines and compares
  costs hundreds of times per iteration, and each call into Python costs about 0.5 µs); a
  path's cost C stands for the clearance −σ·ln C (:func:`softmin_value`), within σ·ln n below
  its least motion bound (n motions), never above the exact ``min_clearance`` the plan reports.
  OMPL's MaximizeMinClearanceObjective combines by max instead: written in Python it cost
  three calls into Python per neighbour (8x the length objective per iteration on bug_trap,
  and a median clearance of 0.08 there against this one's 0.31, 3 seeds of 3000 iterations). In translation the motion's cost is compiled
  (:func:`cspace.compiled.fastpath.disc_cost`, the same doubles; this Python one is its oracle and
  the pure path): ~3-4x the length objective per RRTstar iteration (the Python motion
  cost over a compiled C-space: 4-7x; all pure: 1.4-1.8x; ``scripts/bench_objective.py``);
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

from cspace.compiled import fastpath

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


def unsolved_hint(objective: str, space_hint: str | None) -> str | None:
    """What a failed plan suggests under ``objective``: the space's own hint under ``length``;
    under another objective a longer budget or the length objective (the exact planner,
    which the translation hint names, takes only the length objective).

    >>> unsolved_hint("length", "try --planner exact")
    'try --planner exact'
    >>> "exact" in unsolved_hint("clearance", "try --planner exact")
    False
    """
    if objective == "length":
        return space_hint
    return (f"try a longer --time (--objective {objective} costs a few times more per iteration than "
            f"the length objective), or plan without --objective {objective}")


SOFTMIN_STEPS = 1000  # σ = the bounds' extent / this: costs stay above exp(-500) where c <= extent / 2
CACHE_MAX = 1 << 17  # states whose clearance the translation objective remembers (then it starts over)


def clearance_functions(adapter):
    """``(state -> clearance, (state, state) -> clearance)`` on OMPL states, as the
    clearance objectives read them (C-space units). Translation: a state's exact float
    clearance (0 for a state that is not free), remembered per state; a motion's
    :func:`cspace.translation.point_clearance.disc_bound` of its ends (a lower bound of its
    exact clearance). Other spaces: the adapter's ``clearance_functions``."""
    if getattr(adapter, "name", None) != "translation":
        return adapter.clearance_functions()
    return _translation_functions(adapter, lambda v: -v)[:2]


def _translation_functions(adapter, box):
    """The translation pair of :func:`clearance_functions`, the motion's answer returned as
    ``box(-clearance)`` (``ob.Cost`` inside the objective: one Python call per motion), and
    the state's clearance at raw OMPL coordinates, not remembered (what the compiled motion
    cost calls on a state it has not met)."""
    from cspace.translation.point_clearance import PointClearance

    cs, k = adapter.cspace, -adapter.k
    near = PointClearance(cs.pieces, cs.bounds)
    free = cs.point_test()  # (x, y) -> bool, not counted among the planner's state checks
    unit, ldexp, hypot, sqrt, inf = math.ldexp(1.0, k), math.ldexp, math.hypot, math.sqrt, math.inf
    cache: dict = {}  # x -> (y, clearance): a float key hashes faster than a pair
    get = cache.get
    lx = ly = math.nan  # the state met last and its clearance (RRTstar weighs ~100 motions to each new state)
    lc = 0.0

    def raw(x: float, y: float) -> float:
        ux, uy = ldexp(x, k), ldexp(y, k)
        return near(ux, uy) if free(ux, uy) else 0.0

    def at(x: float, y: float) -> float:  # raw OMPL coordinates
        e = get(x)
        if e is not None and e[0] == y:
            return e[1]
        c = raw(x, y)
        if len(cache) >= CACHE_MAX:
            cache.clear()
        cache[x] = (y, c)
        return c

    def state(s) -> float:
        return at(s[0], s[1])

    def motion(s1, s2):  # disc_bound, written out: called hundreds of times per iteration
        nonlocal lx, ly, lc
        x2 = s2[0]
        y2 = s2[1]
        if x2 == lx and y2 == ly:
            c2 = lc
        else:
            c2 = lc = at(x2, y2)
            lx, ly = x2, y2
        x1 = s1[0]
        y1 = s1[1]
        e = get(x1)
        c1 = e[1] if e is not None and e[0] == y1 else at(x1, y1)
        dx, dy = x2 - x1, y2 - y1
        d = hypot(dx, dy) * unit
        if d >= c1 + c2:  # the discs apart
            return box(-0.0)
        m = c1 if c1 < c2 else c2
        if d <= 0.0 or m == inf:  # one point (or no obstacles: both inf)
            return box(-m)
        a = (d * d + c1 * c1 - c2 * c2) / (2.0 * d)  # where the discs' boundaries cross
        if a <= 0.0:
            return box(-c1)
        if a >= d:
            return box(-c2)
        h = c1 * c1 - a * a
        h = sqrt(h) if h > 0.0 else 0.0
        return box(-(h if h < m else m))

    return state, motion, raw


def path_clearance_bound(adapter, path) -> float:
    """The clearance the ``clearance`` objective gives a translation path of reference
    points (rows x, y, C-space units): the least :func:`cspace.translation.point_clearance.disc_bound`
    over its motions (inf without obstacles), never more than the path's exact clearance."""
    from cspace.translation.point_clearance import PointClearance, disc_bound

    cs = adapter.cspace
    near = PointClearance(cs.pieces, cs.bounds)
    pts = [(float(p[0]), float(p[1])) for p in path]
    c = [near(x, y) if cs.is_free((x, y)) else 0.0 for x, y in pts]
    if len(pts) == 1:
        return c[0]
    return min(disc_bound(c[i], c[i + 1], math.hypot(pts[i + 1][0] - pts[i][0], pts[i + 1][1] - pts[i][1]))
               for i in range(len(pts) - 1))


def make_objective(name: str, si, adapter):
    """An OMPL objective for ``name`` over the adapter's clearance, or None for ``length``
    (OMPL's default path length, as without the option)."""
    if name == "length":
        return None
    from .glue import ompl

    ob = ompl()[0]
    if name == "clearance":
        sigma = softmin_sigma(adapter)
        if getattr(adapter, "name", None) != "translation":
            return _softmin_class(ob)(si, *clearance_functions(adapter), sigma)
        inv, exp, cost_of = 1.0 / sigma, math.exp, ob.Cost
        state, cost, raw = _translation_functions(adapter, lambda v: cost_of(exp(v * inv)))
        obj = _softmin_class(ob)(si, state, None, sigma)
        # OMPL's calls find the instance's function: the compiled disc bound where built (the same
        # doubles), else one Python frame per motion
        obj.motionCost = fastpath.disc_cost(math.ldexp(1.0, -adapter.k), sigma, cost_of, raw) or cost
        return obj
    state, motion = clearance_functions(adapter)
    xmin, xmax, ymin, ymax = adapter.cspace.bounds
    rho = BALANCED_SCALE * max(xmax - xmin, ymax - ymin)
    return _balanced_class(ob)(si, state, rho, BALANCED_WEIGHT)


_classes: dict = {}


def softmin_sigma(adapter) -> float:
    """σ of the clearance objective's soft minimum: the bounds' extent / :data:`SOFTMIN_STEPS`."""
    xmin, xmax, ymin, ymax = adapter.cspace.bounds
    return max(xmax - xmin, ymax - ymin) / SOFTMIN_STEPS


def softmin_value(cost: float, sigma: float) -> float:
    """The clearance a path's cost under the clearance objective stands for: −σ·ln(cost), at
    most the least motion clearance c_min and more than c_min − σ·ln(n) for n motions.

    >>> softmin_value(math.exp(-2.0) + math.exp(-5.0), 1.0) <= 2.0
    True
    """
    return -sigma * math.log(cost) if cost > 0.0 else math.inf


def _softmin_class(ob):
    if "soft" not in _classes:
        class SoftMinClearance(ob.OptimizationObjective):
            """Maximise the path's least clearance through its soft minimum: a motion of
            clearance c costs exp(−c/σ) (translation: c the ends' disc bound), costs add and a
            smaller one is better (OMPL's sum, identity and comparison, all in C++)."""

            def __init__(self, si, state, motion, sigma):
                super().__init__(si)  # (motion None: the caller sets the instance's motionCost)
                self._state, self._motion, self._inv = state, motion, 1.0 / sigma
                self.setCostThreshold(ob.Cost(0.0))  # never satisfied (costs are >= 0): keep improving

            def stateCost(self, s):
                return ob.Cost(math.exp(-self._state(s) * self._inv))

            def motionCost(self, s1, s2):
                return ob.Cost(math.exp(-self._motion(s1, s2) * self._inv))

        _classes["soft"] = SoftMinClearance
    return _classes["soft"]


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
