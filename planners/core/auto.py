"""``auto``: the planner that always answers, the default for a rotating robot and a car.

It runs the project's planners as stages of one budget, each only when the ones before it have
not answered, in the order of their cost on the scene (a rotating robot or a Reeds–Shepp car):

0. **sampling**, a slice -- a car first tries its one shortest curve from start to goal (the
   path when it is free: :func:`.car_sampling.direct_curve`); then RRTConnect (a small Reeds–Shepp scene: the car's own,
   compiled or in Python, :func:`.car_sampling.connect_slice`) for at most :data:`SLICE_ITERATIONS` iterations (and
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
3. **sampling** -- RRTConnect with a share of what is left (:data:`SAMPLE_SHARE`); not for a Reeds–Shepp
   car on a large map (no car RRT of its own), where the slice failed: on a warehouse map that turn
   answered few queries and cost the others 50 ms before their refinement. A Dubins car, which has no
   complete method here, goes from the slice to restarts of sampling with the reach proof and this
   proof between them (:func:`planners.core.auto_dubins.dubins_stages`);
4. **refinement** -- the exact planner with the rest: the slab graph refined where FREE and
   POSSIBLE disagree (SE(2); a Reeds–Shepp car's path converted as in 1), then sampling again
   with whatever is left; for a translating robot the exact shortest path.

**A small SE(2) scene** (:func:`small_scene`: at most :data:`SMALL_PAIRS` convex pairs, obstacle
pieces x robot pieces, which is what a slab region sums) orders the same stages by what they cost
there (:func:`_small_se2`). Its 8 POSSIBLE regions cost a few milliseconds, about a failed slice,
and every later stage but sampling reuses them, so the **proof** (POSSIBLE at the first 8 slabs,
not refined: a scene proven impossible pays what RRTConnect's proof before sampling costs) comes
after the slice's first :data:`FIRST_ITERATIONS` iterations (an open scene's answer, most often)
and before its rest; then the **slab graph**'s FREE at those 8 slabs; then one
**sampling** turn of :data:`TURN_ITERATIONS` more iterations of the slice's own search (its trees
kept: an open scene that needs a few thousand iterations, as a corner to turn, costs what they
cost once); then the **refinement** (the quick proof's 16 slabs are skipped: the refinement looks
for the proof too, in the slabs it bisects); then sampling with the rest. Every stage there ends
by a count (iterations, slabs) well before its share of the limit, so which stage answers, and the
path, is the same on every machine that answers within ``--time``. The
turn is a compromise between the scenes that need it (an open corner: 2 000 to 7 000 iterations,
a few ms each thousand) and those where only the refinement answers (a door 1 % wider than the
robot), which pay it on top of the exact planner's time. A larger scene (an imported map: a slab
region costs tens of milliseconds) or a car keeps the order 0-4: a slice answers most queries of a
large map before any region is built.

The slab regions are kept with the C-space, so stage 4 starts where stage 1 stopped. The result
says which stage answered (``PlanResult.answered_by``) and the seconds of each stage
(``timings``: ``proof``, ``slab graph``, ``sampling``, ``refinement``). Every path is certified
by the stage that found it and verified again by the adapter; a "proven unsolvable" carries its
proof, as the exact planner's does.
"""
from __future__ import annotations

import math
import time
import weakref

import numpy as np

from .car_sampling import connect_slice, direct_curve
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
BOUNDED_PAST = 32  # poses: a car's path longer than this gets the bounded shortening only
# A small SE(2) scene (obstacle pieces x robot pieces, the convex pairs each slab region sums, at
# most this): its first 8 slab regions cost a few milliseconds, about a failed slice, and run first.
SMALL_PAIRS = 16
FIRST_ITERATIONS = 500  # a small SE(2) scene: the slice's part before the proof (the rest after it)
TURN_ITERATIONS = 3500  # a small SE(2) scene: sampling's turn after the first slabs, continuing the slice
STAGES = ("sampling", "slab graph", "proof", "refinement")
# C-space -> the (start, goal) pairs of a small scene whose POSSIBLE graph at the first slabs joined
# them: that search is deterministic on the kept regions, so the same query skips it next time.
_NO_PROOF: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


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

    def sample(budget: float, budget_iterations: int | None = iterations, turn: int = 0,
               radii: float | None = None) -> PlanResult:
        """One turn of the sampler on this query (its stage's seconds counted as ``sampling``).
        Given ``iterations`` (the caller's), a turn is bounded by its count alone, within the
        time left: where it ends, and so which stage answers, does not depend on the machine.
        A car's later turns (``turn`` > 0) draw samples of their own (:func:`turn_seed`); given
        ``radii``, a turn's range is at most that many turning radii (a Dubins car's restarts)."""
        from .auto_dubins import with_range

        if iterations is not None:
            budget = clock.left()
        s = turn_seed(seed, turn) if turn and kind in ("reeds-shepp", "dubins") else seed
        call = lambda: run_planner(adapter, SAMPLER, [pair], budget, s, iterations=budget_iterations,  # noqa: E731
                                   simplify=simplify, scenario=sc.name)[0]
        return clock.run("sampling", call if radii is None else lambda: with_range(adapter, radii, call))

    if tuple(query.start) == tuple(query.goal):
        return _answer(sample(time_limit, None), "sampling", clock, seed)
    if turns and small_scene(sc, cspace):
        return _small_se2(sc, cspace, adapter, query, pair, clock, seed, source, iterations, simplify)
    if turns and kind in ("dubins", "reeds-shepp"):  # a car: its one curve from start to goal, if free
        r = clock.run("sampling", lambda: direct_curve(sc, adapter, query, pair, seed))
        if r is not None:
            return _answer(r, "sampling", clock, seed)
    own = clock.run("sampling", lambda: connect_slice(sc, adapter, query, pair, seed, clock, SLICE_SHARE * time_limit,
                                                       iterations, simplify)) if turns and kind == "reeds-shepp" else None
    if own is not None and own.solved:  # a small Reeds–Shepp scene: its own slice (None: OMPL's below)
        return _answer(own, "sampling", clock, seed)
    r, no_turn = own, turns and kind == "reeds-shepp" and own is None  # (3.: a large map's car has no turn)
    if turns and r is None:  # a slice of sampling: an open scene is answered here, a large map too
        r = sampling_slice(sample, cspace, clock, time_limit)
        if r.solved:
            return _answer(r, "sampling", clock, seed)
    if turns and kind != "dubins":  # FREE at the first slabs, and POSSIBLE there where FREE does not join
        r = clock.run("slab graph", lambda: _slab_graph(sc, cspace, adapter, query, source,
                                                       min(SLAB_SHARE * time_limit, clock.left()), simplify,
                                                       refine=False))
        if r is not None and (r.solved or r.proven_unsolvable):
            return _answer(r, "slab graph", clock, seed)
    if turns and kind == "dubins":  # restarts of sampling, the reach proof, the SE(2) proof
        from .auto_dubins import dubins_stages

        r, stage = dubins_stages(sc, cspace, query, sample, clock, time_limit, iterations)
        return _answer(r if r is not None else _timed_out(sc, adapter, query, time_limit, seed), stage, clock, seed)
    if turns or not sc.rotates:  # the proof before sampling (the first slabs refined once)
        from .exact import separated_proof
        from .exact_se2 import quick_proof

        prove = quick_proof if turns else separated_proof
        r = clock.run("proof", lambda: prove(sc, cspace, query, time_limit))
        if r is not None:
            return _answer(r, "proof", clock, seed)
    share = 1.0 if not turns and sc.rotates else \
        TRANSLATION_SAMPLE_SHARE if kind == "translation" else SAMPLE_SHARE
    sampled = None
    if clock.left() > 0 and not no_turn:
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
    return _answer(failed if failed is not None else _timed_out(sc, adapter, query, time_limit, seed), None,
                   clock, seed)


def _timed_out(sc, adapter, query, time_limit: float, seed: int) -> PlanResult:
    """Nothing to report but the time: the earlier stages used the whole limit."""
    return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, adapter.dim)), length=math.inf,
                      planner="auto", seed=seed, start=tuple(query.start), goal=tuple(query.goal),
                      message=f"not solved within the time limit ({time_limit:g} s)")


def prepare(sc, cspace) -> float:
    """For a C-space serving many queries (a large map), build what they read first on the map
    alone, kept with it; returns its seconds. A rotating robot or a car: the proof's POSSIBLE regions,
    labelled (:func:`planners.core.exact_se2.prepare`); a Reeds–Shepp car also FREE with the first room
    of :data:`ROOMS` at the first 8 slabs and at their halves (the refinement's first bisection: what a
    query through a door reads), and their links. A query answers the same, sooner."""
    from cspace.se2.critical import bisected, initial_partition
    from .exact_se2 import prepare as prepare_se2, slab_regions_of

    t = _now()
    if not (sc.rotates and cspace.body_pieces):
        return 0.0
    prepare_se2(cspace)
    if sc.space == "reeds-shepp":
        regions, part = slab_regions_of(cspace, ROOMS[0] * _reach(cspace)), initial_partition()
        for slabs in (part, bisected(part)):
            for (a, b), (c, d) in zip(slabs, slabs[1:] + slabs[:1]):
                regions.free_links(regions.free(a, b), regions.free(c, d))
    return _now() - t


def _reach(cspace) -> float:  # the robot's reach from its reference point (the unit of ROOMS)
    return max(float(np.max(np.hypot(p[:, 0], p[:, 1]))) for p in cspace.body_pieces)


def small_scene(sc, cspace) -> bool:
    """A rotating robot (not a car) in a scene of at most :data:`SMALL_PAIRS` convex pairs
    (obstacle pieces x robot pieces): its stages run in the order of :func:`_small_se2`."""
    return sc.space == "se2" and len(cspace.obstacle_pieces) * len(cspace.body_pieces) <= SMALL_PAIRS


def _small_se2(sc, cspace, adapter, query, pair, clock: _Clock, seed: int, source: str,
               iterations: int | None, simplify: bool) -> PlanResult:
    """A small SE(2) scene, every stage at most as dear as the one after it: the slice's first
    :data:`FIRST_ITERATIONS`, the proof (POSSIBLE at the first 8 slabs, whose regions the
    refinement reuses), the rest of the slice, FREE at those slabs, sampling's turn (one search
    continued throughout), the refinement, sampling again with the rest.
    Sampling's turns are counted in iterations, the slab graph's in slabs: where each stops, and
    so which stage answers and the path, is the same on every machine (within ``--time``)."""
    from .exact_se2 import from_search, search
    from .routine import run_planner

    keep = [None]  # one RRTConnect search, continued turn after turn

    def sample(n: int | None, budget: float) -> PlanResult:  # given ``iterations``: counted, within the time left
        budget = clock.left() if iterations is not None else budget
        return clock.run("sampling", lambda: run_planner(adapter, SAMPLER, [pair], budget, seed, iterations=n,
                                                          simplify=simplify, scenario=sc.name, keep=keep)[0])

    slice_s = min(SLICE_SHARE * clock.limit, clock.left())
    r = sample(FIRST_ITERATIONS, slice_s)  # the slice's first part: an open scene is answered here
    if r.solved:
        return _answer(r, "sampling", clock, seed)
    key = (tuple(map(float, query.start)), tuple(map(float, query.goal)))
    tried = _NO_PROOF.setdefault(cspace, set())
    if key not in tried:  # (deterministic on the kept regions: a query asked again skips it)
        res = clock.run("proof", lambda: search(cspace, query, min(SLAB_SHARE * clock.limit, clock.left()),
                                                possible_only=True, refine=False))
        if res.status == "unsolvable":
            return _answer(from_search(sc, query, res, clock.spent["proof"]), "proof", clock, seed)
        if res.stats.get("reason") != "time limit":
            tried.add(key)
    r = sample(SLICE_ITERATIONS - FIRST_ITERATIONS, max(0.0, min(slice_s - clock.spent["sampling"], clock.left())))
    if r.solved:  # the rest of the slice, its search continued
        return _answer(r, "sampling", clock, seed)
    failed = r
    if clock.left() > 0:
        r = clock.run("slab graph", lambda: _slab_graph(sc, cspace, adapter, query, source,
                                                       min(SLAB_SHARE * clock.limit, clock.left()), simplify, refine=False))
        if r is not None and (r.solved or r.proven_unsolvable):
            return _answer(r, "slab graph", clock, seed)
    if clock.left() > 0:
        failed = r = sample(iterations or TURN_ITERATIONS, 0.5 * clock.left())
        if r.solved:
            return _answer(r, "sampling", clock, seed)
    if clock.left() > 0:
        r = clock.run("refinement", lambda: _refinement(sc, cspace, adapter, query, source, clock, simplify))
        if r is not None and (r.solved or r.proven_unsolvable):
            return _answer(r, "refinement", clock, seed)
        failed = r or failed
    if clock.left() > 0:  # the refinement reached its floor: sampling goes on with the rest
        r = sample(iterations, clock.left())
        if r.solved:
            return _answer(r, "sampling", clock, seed)
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
        r = sample(budget, int(__import__("os").environ.get("SLICEN", SLICE_ITERATIONS)))
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
    reach = _reach(cspace)
    rooms = [f * reach for f in ROOMS] + ([0.0] if refine else [])
    for i, room in enumerate(rooms):
        t = _now()
        share = (end - t) / (len(rooms) - i)
        if share <= 0:
            return None
        try:
            res = search(cspace, query, share, refine=refine, room=room, near=True)
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
    from cspace.car.laumond import along_travel, shortcut, to_reeds_shepp

    from .exact_se2 import shorten

    t = _now()
    end = t + max(budget, 0.0)
    se2_path = along_travel(cspace, se2_path, adapter.radius)  # (no long sideways translation left)
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


def exact_reeds_shepp(sc, cspace, adapter, query, source: str, time_limit: float,
                      simplify: bool = True) -> PlanResult:
    """``planner = "exact"`` for a Reeds–Shepp car: the refinement stage alone, with the whole
    limit (the slab graph refined, its SE(2) path driven as certified curves; a proof where
    POSSIBLE separates start and goal), else "not decided". It needs no OMPL: the curves, their
    certificates and the shortcuts are the project's (OMPL shortens the path where installed)."""
    t0 = _now()
    r = _slab_graph(sc, cspace, adapter, query, source, time_limit, simplify, refine=True)
    if r is None:
        r = PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                       planner="exact", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                       timings={"solve": _now() - t0},
                       message=f"not decided within the time limit ({time_limit:.3g} s left of it after the "
                               "C-space): the slab graph found no SE(2) path that the car's curves could follow, "
                               "nor a proof that none exists; try a longer --time")
    r.planner, r.seed = "exact", 0
    return r
