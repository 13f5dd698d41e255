"""How a plan is named in words: who planned it and what came of it.

One wording for the command line's summary, the picture's title and the page: the exact
planners take no seed (the same scene gives the same path), a sampling planner's seed is
part of its name, and a query proven unsolvable says so rather than "not solved".
"""
from __future__ import annotations

SEEDLESS = ("exact",)
SEEDLESS_STAGES = ("slab graph", "proof", "refinement")  # auto's stages that draw no sample


def _seeded(res) -> bool:
    """Does the plan's answer depend on its seed (a sampling planner, or auto's sampling stage)?"""
    stage = getattr(res, "answered_by", None)
    return res.planner not in SEEDLESS and stage not in SEEDLESS_STAGES


def planner_words(res) -> str:
    """The planner, the stage of ``auto`` that answered, and the seed where it matters.

    >>> class R: planner, seed, answered_by = "RRTConnect", 3, None
    >>> planner_words(R()), planner_words(type("E", (), {"planner": "exact", "seed": 0})())
    ('RRTConnect (seed 3)', 'exact')
    >>> R.planner, R.answered_by = "auto", "slab graph"
    >>> planner_words(R())
    'auto (slab graph)'
    """
    stage = getattr(res, "answered_by", None)
    inner = [stage] if stage else []
    if _seeded(res):
        inner.append(f"seed {res.seed}")
    return f"{res.planner} ({', '.join(inner)})" if inner else res.planner


def outcome_words(res) -> str:
    """The outcome: the path's length, "proven unsolvable" (no path exists: the result's
    ``proven_unsolvable``, :class:`planners.core.result.PlanResult`'s rule), or "not solved".

    >>> class R: solved, length, proven_unsolvable = False, float("inf"), True
    >>> outcome_words(R())
    'proven unsolvable'
    """
    if res.solved:
        return f"length {res.length:.4g}"
    return "proven unsolvable" if res.proven_unsolvable else "not solved"


def plan_title(scene: str, res) -> str:
    """A picture's title: the scene, the planner (and seed), the outcome; no wall time (the
    same plan gives the same picture).

    >>> class R: planner, seed, solved, length, proven_unsolvable = "exact", 0, True, 17.42051, False
    >>> plan_title("basic", R())
    'basic: exact, length 17.42'
    >>> R.planner = "RRTConnect"
    >>> plan_title("basic", R())
    'basic: RRTConnect, seed 0, length 17.42'
    """
    stage = getattr(res, "answered_by", None)
    by = ", ".join([res.planner] + ([stage] if stage else []) + ([f"seed {res.seed}"] if _seeded(res) else []))
    return f"{scene}: {by}, {outcome_words(res)}"
