"""``auto``'s stages for a Dubins car after its slice: short restarts of sampling, the two proofs.

A Dubins car is not locally controllable: no complete method here, so after the slice (stage 0 of
:mod:`planners.core.auto`) it keeps sampling, in **restarts**: fresh RRTConnect searches, each with
samples of its own (:func:`planners.core.auto.turn_seed`), a shorter range (:data:`RESTART_RADII`
turning radii, not the slice's 20) and an iteration count that doubles from one to the next
(:data:`FIRST_RESTART`). On a large map a Dubins query that the slice does not answer most often
starts or ends close to a wall: long curves from there nearly always meet it, a tree that happened
to grow the wrong way stays stuck, and one long search has a heavy tail (the warehouse's hard
pairs: seconds at 20 radii where a restart at 7 answers in milliseconds; the range stops at
:data:`RESTART_FLOOR` of OMPL's own, so a car of tiny radius keeps useful steps).

The proofs, cheapest first. An impossible Dubins query most often has an end **boxed in** (on the
warehouse: a start facing a rack 0.8 m ahead, a goal backed against one). The car's lattice of
short certified moves from each end (:func:`cspace.car.lattice.boxed_in`: forward from the start,
backward from the goal, a few milliseconds) tells which: an end whose lattice stops short of
:data:`BOXED_CAP` poses gets its reach proof (:func:`planners.core.dubins_proof.reach_result`:
its reach closed under the car's steps, local regions, 20-100 ms) before any restart; after the
third restart, an end short of :data:`LATE_CAP` poses (a larger pocket) gets it too; after the
fourth, the SE(2) proof before sampling (:func:`planners.core.exact_se2.quick_proof`: the whole
map's first slabs, built once per C-space; a Nav2-sized map pays a second or more for them). The
lattice is a hint, never a proof: the reach proof decides, and an end whose lattice runs on to
its cap is not tried (a reach proof from there fails after 0.1-0.2 s: past the lattice's cap, the
reach is past the proof's cells' cap). Every restart and lattice ends by its count, within the
time left, so which stage answers and the path are the same on every machine that answers
within ``--time``.
"""
from __future__ import annotations

import math

RESTART_RADII = 7.0     # a restart's range, in turning radii
RESTART_FLOOR = 1 / 8   # ... never below this share of OMPL's own range (a tiny radius: OMPL's steps)
FIRST_RESTART = 2000    # iterations of the first restart (about 20 ms where the trees stay small)
RESTART_GROWTH = 2      # each restart counts this many times the last one's iterations
# The proofs run after these restarts: the reach of an end in a pocket (its lattice short of
# LATE_CAP) once sampling has spent about what it costs (2 000 + 4 000 + 8 000 iterations, 0.1-0.2 s),
# the SE(2) proof (its map-wide regions) after one more.
REACH_AFTER, QUICK_AFTER = 3, 4
BOXED_CAP = 300    # lattice poses: an end short of it gets its reach proof before the restarts
LATE_CAP = 1500    # ... and short of this, after REACH_AFTER restarts (a larger lattice: a reach past the cells' cap)


def boxed_ends(sc, cspace, query, cap: int = BOXED_CAP) -> tuple:
    """The ends of the query ("start", "goal") whose lattice (forward from the start, backward
    from the goal: :func:`cspace.car.lattice.boxed_in`) stops short of ``cap`` poses."""
    from cspace.car.lattice import boxed_in
    from cspace.car.motion import as_car

    car, r = as_car(cspace), float(sc.turning_radius)
    return tuple(end for end, q, back in (("start", query.start, False), ("goal", query.goal, True))
                 if boxed_in(car, q, r, backward=back, cap=cap))


def boxed_reach(sc, cspace, query, time_limit: float, cap: int):
    """The reach proof (:func:`planners.core.dubins_proof.reach_result`, every step down to
    :data:`cspace.car.dubins_reach.FINE_STEP`) of the ends :func:`boxed_ends` names for ``cap``;
    None where none is named or none is proven. A point robot has no reach proof: None."""
    from cspace.car.dubins_reach import FINE_STEP, STEPS

    from .dubins_proof import reach_budget, reach_result
    from .exact_se2 import slab_regions_of

    if not cspace.body_pieces or sc.space != "dubins":
        return None
    boxed = boxed_ends(sc, cspace, query, cap)
    return reach_result(sc, cspace, slab_regions_of(cspace), query, reach_budget(time_limit), ends=boxed,
                        steps=STEPS + (FINE_STEP,)) if boxed else None


def with_range(adapter, radii: float, call):
    """``call()`` with the adapter's sampling range bounded by ``radii`` turning radii (and its floor
    lowered to :data:`RESTART_FLOOR` of OMPL's own), restored afterwards."""
    saved = adapter.max_range, getattr(adapter, "range_floor", None)
    adapter.max_range = math.ldexp(radii * adapter.radius, adapter.k)
    adapter.range_floor = RESTART_FLOOR
    try:
        return call()
    finally:
        adapter.max_range = saved[0]
        if saved[1] is None:
            del adapter.range_floor
        else:
            adapter.range_floor = saved[1]


def restart_iterations(turn: int) -> int:
    """The iterations of the ``turn``-th restart (1, 2, ...): doubling from :data:`FIRST_RESTART`.

    >>> [restart_iterations(k) for k in (1, 2, 3)]
    [2000, 4000, 8000]
    """
    return FIRST_RESTART * RESTART_GROWTH ** (turn - 1)


def dubins_stages(sc, cspace, query, sample, clock, time_limit: float, iterations: int | None):
    """The stages after a Dubins car's slice: ``(result, stage)`` of the first that answers
    (stage "sampling" or "proof"), else ``(the last sampling result or None, None)``.
    ``sample(budget, budget_iterations, turn, radii)`` runs one turn of sampling; ``clock`` is
    auto's budget; ``iterations`` (the caller's, if any) bounds the restarts' iterations in all."""
    from .exact_se2 import quick_proof

    failed, turn, left = None, 0, iterations
    if clock.left() > 0:  # an end boxed in: its reach proof before any restart
        r = clock.run("proof", lambda: boxed_reach(sc, cspace, query, time_limit, BOXED_CAP))
        if r is not None:
            return r, "proof"
    proofs = {REACH_AFTER: lambda: boxed_reach(sc, cspace, query, time_limit, LATE_CAP),
              QUICK_AFTER: lambda: quick_proof(sc, cspace, query, time_limit)}
    while clock.left() > 0 and (left is None or left > 0):
        turn += 1
        n = restart_iterations(turn) if left is None else min(restart_iterations(turn), left)
        left = None if left is None else left - n
        # restart turns 3, 4, ... (0 is the slice's; 1 and 2 are other cars' later turns)
        failed = sample(clock.left(), n, turn + 2, RESTART_RADII)
        if failed.solved:
            return failed, "sampling"
        if turn in proofs and clock.left() > 0:
            r = clock.run("proof", proofs.pop(turn))
            if r is not None:
                return r, "proof"
    for k in sorted(proofs):  # the caller's iterations ran out first: the proofs still run
        if clock.left() > 0:
            r = clock.run("proof", proofs[k])
            if r is not None:
                return r, "proof"
    return failed, None
