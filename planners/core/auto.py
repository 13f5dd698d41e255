"""``auto``: the planner that always answers, the default for a rotating robot and a car.

It runs the project's planners as stages of one budget, each only when the ones before it have
not answered, cheapest first (a rotating robot or a Reeds–Shepp car):

0. **sampling**, a slice -- RRTConnect for at most :data:`SLICE_ITERATIONS` iterations (and
   :data:`SLICE_SHARE` of the limit, not counting the slabs it builds: :func:`sampling_slice`): an open
   scene, or a query on a large map, is answered here in milliseconds, before any region of the
   slab graph is built (every rotating robot and car: a Dubins car too);
1. **slab graph** -- the slab graph's search at its first 8 slabs, no refinement (a few
   milliseconds on the bundled scenes): a certified path where FREE joins start and goal at
   once (a Reeds–Shepp car's SE(2) path, asked to keep some room, turned into certified curves:
   :func:`cspace.car.laumond.to_reeds_shepp`), else a proof where POSSIBLE separates them;
2. **proof** -- the proof before sampling (a rotating robot: those slabs refined once,
   :func:`planners.core.exact_se2.quick_proof`; a translating one, where it comes first: start
   and goal in different free components, :func:`planners.core.exact.separated_proof`);
3. **sampling** -- RRTConnect with a share of what is left (:data:`SAMPLE_SHARE`; all of it for a
   Dubins car, which has no complete method here and goes from the slice to the proof);
4. **refinement** -- the exact planner with the rest: the slab graph refined where FREE and
   POSSIBLE disagree (SE(2); a Reeds–Shepp car's path converted as in 1), then sampling again
   with whatever is left; for a translating robot the exact shortest path.

The slab regions are kept with the C-space, so stage 4 starts where stage 1 stopped. The result
says which stage answered (``PlanResult.answered_by``) and the seconds of each stage
(``timings``: ``proof``, ``slab graph``, ``sampling``, ``refinement``). Every path is certified
by the stage that found it and verified again by the adapter; a "proven unsolvable" carries its
proof, as the exact planner's does.
"""
from __future__ import annotations

import math
import time

import numpy as np

from .result import PlanResult

SAMPLER = "RRTConnect"
SLICE_ITERATIONS = 1000  # the first slice of sampling (a rotating robot, a Reeds–Shepp car): deterministic
SLICE_SHARE = 0.1        # and within this share of the time limit
SLAB_SHARE = 0.2    # of the time limit, at most, for the slab graph's first FREE search
SAMPLE_SHARE = 0.1  # of what is left after it, at most, for sampling where a refinement follows (SE(2), cars)
SAMPLE_MIN = 0.05   # seconds: sampling's turn before the refinement, at least
TRANSLATION_SAMPLE_SHARE = 0.5
# A Reeds–Shepp car's SE(2) path is asked to keep this much room (x the robot's reach from its
# reference point), the largest its start and goal allow first.
ROOMS = (0.05, 0.01, 0.002)
BOUNDED_PAST = 32  # poses: a car's path longer than this gets the bounded shortening only  # a translating robot: sampling, then the exact shortest path
STAGES = ("sampling", "slab graph", "proof", "refinement")


def _now() -> float:
    return time.perf_counter()


class _Clock:
    """The budget of one query: seconds left, and the seconds each stage took."""

    def __init__(self, limit: float):
        self.t0, self.limit, self.spent = _now(), float(limit), {}

    def left(self) -> float:
        return self.limit - (_now() - self.t0)

    def elapsed(self) -> float:
        return _now() - self.t0

    def run(self, stage: str, call):
        t = _now()
        try:
            return call()
        finally:
            self.spent[stage] = self.spent.get(stage, 0.0) + (_now() - t)


def auto_plan(sc, cspace, adapter, query, pair, time_limit: float, seed: int, *, source: str,
              iterations: int | None = None, simplify: bool = True) -> PlanResult:
    """One query planned by the stages of the module's notes within ``time_limit`` seconds;
    ``pair`` is its (start, goal) as the adapter's poses, already checked free."""
    from .routine import run_planner

    clock = _Clock(time_limit)
    kind = sc.space if sc.rotates else "translation"
    turns = sc.rotates and bool(cspace.body_pieces)  # a point robot does not turn: nothing to prove

    def sample(budget: float, budget_iterations: int | None = iterations, turn: int = 0) -> PlanResult:
        """One turn of the sampler on this query (its stage's seconds counted as ``sampling``).
        Given ``iterations`` (the caller's), a turn is bounded by its count alone, within the
        time left: where it ends, and so which stage answers, does not depend on the machine.
        A car's later turns (``turn`` > 0) draw samples of their own (:func:`turn_seed`)."""
        if iterations is not None:
            budget = clock.left()
        s = turn_seed(seed, turn) if turn and kind in ("reeds-shepp", "dubins") else seed
        return clock.run("sampling", lambda: run_planner(adapter, SAMPLER, [pair], budget, s,
                                                          iterations=budget_iterations, simplify=simplify,
                                                          scenario=sc.name)[0])

    if tuple(query.start) == tuple(query.goal):
        return _answer(sample(time_limit, None), "sampling", clock, seed)
    if turns:  # a slice of sampling: an open scene is answered here, a large map too
        r = sampling_slice(sample, cspace, clock, time_limit)
        if r.solved:
            return _answer(r, "sampling", clock, seed)
    if turns and kind != "dubins":  # FREE at the first slabs, and POSSIBLE there where FREE does not join
        r = clock.run("slab graph", lambda: _slab_graph(sc, cspace, adapter, query, source,
                                                       min(SLAB_SHARE * time_limit, clock.left()), simplify,
                                                       refine=False))
        if r is not None and (r.solved or r.proven_unsolvable):
            return _answer(r, "slab graph", clock, seed)
    if turns or not sc.rotates:  # the proof before sampling (the first slabs refined once)
        from .exact import separated_proof
        from .exact_se2 import quick_proof

        prove = quick_proof if turns else separated_proof
        r = clock.run("proof", lambda: prove(sc, cspace, query, time_limit))
        if r is not None:
            return _answer(r, "proof", clock, seed)
    share = 1.0 if kind == "dubins" or not turns and sc.rotates else \
        TRANSLATION_SAMPLE_SHARE if kind == "translation" else SAMPLE_SHARE
    sampled = None
    if clock.left() > 0:
        # Where a refinement follows, sampling gets a short turn: long enough for an open scene
        # (as long as the first slabs and the proof took), short of the refinement's time.
        budget = clock.left() if share == 1.0 else min(share * clock.left(), max(SAMPLE_MIN, clock.elapsed()))
        sampled = sample(budget, turn=1)
        if sampled.solved:
            return _answer(sampled, "sampling", clock, seed)
    failed = sampled
    if share < 1.0 and clock.left() > 0:
        r = clock.run("refinement", lambda: _refinement(sc, cspace, adapter, query, source, clock, simplify))
        if r is not None and (r.solved or r.proven_unsolvable):
            return _answer(r, "refinement", clock, seed)
        failed = r or failed  # its "not decided" statement says more than sampling's "no path found"
        if kind != "translation" and clock.left() > 0:  # refinement ended early: sample with the rest
            again = sample(clock.left(), turn=2)
            if again.solved:
                return _answer(again, "sampling", clock, seed)
    if failed is None:  # the earlier stages used the whole limit
        failed = PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, adapter.dim)),
                            length=math.inf, planner="auto", seed=seed, start=tuple(query.start),
                            goal=tuple(query.goal), message=f"not solved within the time limit ({time_limit:g} s)")
    return _answer(failed, None, clock, seed)


def turn_seed(seed: int, turn: int) -> int:
    """The seed of a car's ``turn``-th sampling turn after its slice: run with the query's own
    seed, a later turn would first replay the slice's samples (the same tree, the same failure:
    a turn about as long as the slice added nothing); derived, so the same every run.

    >>> turn_seed(7, 0), turn_seed(7, 1) != turn_seed(7, 2) != 7
    (7, True)
    """
    return int(seed) if turn == 0 else (int(seed) * 0x9E3779B1 + int(turn) * 0x85EBCA77) % (2**31 - 1)


def sampling_slice(sample, cspace, clock, time_limit: float) -> PlanResult:
    """Stage 0: RRTConnect for :data:`SLICE_ITERATIONS` iterations within :data:`SLICE_SHARE` of
    the limit. The slabs it meets first are built inside it (on a large map, tens of
    milliseconds each: a fresh C-space's first query builds most of them); a slice whose time
    ran out while it built slabs is run again (the same seed: the run a C-space with those slabs
    makes), so that the iteration budget, not the builds, decides whether the slice answers."""
    built = getattr(cspace, "slabs_built", lambda: (0, 0.0))
    while True:
        n, t = built()[0], _now()
        budget = min(SLICE_SHARE * time_limit, clock.left())
        r = sample(budget, SLICE_ITERATIONS)
        if r.solved or built()[0] == n or _now() - t < 0.9 * budget or clock.left() <= 0:
            return r


def _slab_graph(sc, cspace, adapter, query, source, budget: float, simplify: bool, refine: bool):
    """The slab graph's search as a PlanResult: SE(2) as the exact planner answers; a Reeds–Shepp
    car's path converted to certified curves (None where no search found a path or the
    conversion failed).

    A car asks the slab graph for a path with room to spare (:data:`ROOMS`, fractions of the
    robot's reach, the largest its start and goal allow): a path keeping clearance converts into
    few curves, one grazing an obstacle into none. Without refinement one room is tried; with
    it, each room in turn, then none, sharing the budget."""
    from .exact_se2 import exact_se2, from_search, search

    if sc.space == "se2":
        return exact_se2(sc, cspace, adapter, query, source, time_limit=budget, simplify=simplify, refine=refine)
    end = _now() + budget
    reach = max(float(np.max(np.hypot(p[:, 0], p[:, 1]))) for p in cspace.body_pieces)
    rooms = [f * reach for f in ROOMS] + ([0.0] if refine else [])
    for i, room in enumerate(rooms):
        t = _now()
        share = (end - t) / (len(rooms) - i)
        if share <= 0:
            return None
        try:
            res = search(cspace, query, share, refine=refine, room=room)
        except ValueError:  # the start or the goal is closer than ``room`` to an obstacle
            continue
        if res.status == "unsolvable":  # POSSIBLE is the body's whatever the room: a proof
            return from_search(sc, query, res, _now() - t)
        if res.status == "solved":
            r = _reeds_shepp(sc, cspace, adapter, query, np.asarray(res.path, dtype=np.float64), end - _now(),
                             simplify, _now() - t)
            if r is not None or not refine:
                return r
        elif not refine:
            return None
    return None


def _reeds_shepp(sc, cspace, adapter, query, se2_path, budget: float, simplify: bool, search_s: float):
    """A certified SE(2) path driven as certified Reeds–Shepp curves (Laumond's method), shortened
    under the car's validator; None if the conversion fails within ``budget``."""
    from cspace.car.laumond import shortcut, to_reeds_shepp

    from .exact_se2 import shorten

    t = _now()
    end = t + max(budget, 0.0)
    poses = to_reeds_shepp(cspace, se2_path, adapter.radius, deadline=lambda: _now() > end)
    if poses is None:
        return None
    curves = len(poses) - 1
    poses = shortcut(cspace, poses, adapter.radius, deadline=lambda: _now() > end)
    convert_s = _now() - t
    ok, why = adapter.verify(poses, query.start, query.goal)
    if not ok:  # every curve was certified: a failure here is a fault, reported, never hidden
        return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                          planner="auto", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                          message=f"the Reeds-Shepp curves failed the re-check ({why}): not solved")
    found_cpu = time.process_time()
    raw_len = adapter.length(poses)
    path, note = poses, "not shortened"
    t2 = _now()
    if simplify:  # bounded: a long wriggle of short curves costs OMPL's full simplifier seconds
        path, note = shorten(adapter, poses, query, time_limit=max(end - _now(), 0.0),
                             bounded=len(poses) > BOUNDED_PAST)
    return PlanResult(scenario=sc.name, solved=True, exact=True, path=path, length=adapter.length(path),
                      planner="auto", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                      timings={"solve": search_s + convert_s, "simplify": _now() - t2},
                      checks={"se2_waypoints": len(se2_path), "curves": curves},
                      stages=["slab graph", "Reeds-Shepp curves"] + (["simplify"] if simplify else []),
                      message=f"certified Reeds-Shepp path from the slab graph's SE(2) path ({len(se2_path)} "
                              f"poses, driven as {curves} curves, {len(poses) - 1} after shortcuts; length {raw_len:.6g}, "
                              f"{note})",
                      length_unsimplified=raw_len, first_path_cpu=found_cpu)


def _refinement(sc, cspace, adapter, query, source, clock: _Clock, simplify: bool):
    """Stage 4: the exact planner with the time left (a Reeds–Shepp car: half of it, the other
    half for sampling again should the conversion fail)."""
    if sc.rotates:
        budget = clock.left() * (0.5 if sc.space == "reeds-shepp" else 1.0)
        return _slab_graph(sc, cspace, adapter, query, source, budget, simplify, refine=True)
    from .exact import exact_plan

    return exact_plan(sc, cspace, query, time_limit=clock.left())


def _answer(r: PlanResult, stage: str | None, clock: _Clock, seed: int) -> PlanResult:
    """The stage's result as auto's: named ``auto``, the stage that answered (None: nothing did),
    each stage's seconds in ``timings`` and the whole run as its ``solve``."""
    inner = {k: v for k, v in r.timings.items() if k not in ("solve", "proof")}
    before = clock.elapsed() - clock.spent.get(stage, 0.0) if stage else 0.0
    if r.first_solution is not None:
        r.first_solution += before
    elif r.solved:
        r.first_solution = before + r.timings.get("solve", 0.0)
    r.planner, r.answered_by = "auto", stage
    r.seed = seed if stage in ("sampling", None) else 0
    r.timings = {**{s: clock.spent[s] for s in STAGES if s in clock.spent}, **inner, "solve": clock.elapsed()}
    r.stages = [s for s in STAGES if s in clock.spent]
    return r
