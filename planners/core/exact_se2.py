"""``exact`` for a rotating robot: the slab graph's certified path, its proof that no path
exists, or the resolution it reached (:mod:`cspace.se2.exact`), as a PlanResult.

- *solved*: the slab graph's path (translations at fixed angles, each the exact shortest path
  inside its component, and rotations in place) is re-verified motion by motion by the
  SE(2) C-space's certified validator (the one OMPL's planners use), then shortened by OMPL's
  simplifier under that same validator and verified again; the result keeps both lengths
  (``length_unsimplified`` is the slab graph's). Without OMPL the shortening is skipped.
- *proven unsolvable*: the POSSIBLE graph separates start and goal: no collision-free path
  exists at any resolution; the proof (``PlanResult.proof``) can be written out and re-checked
  by ``cspace check-proof``.
- *not decided*: refinement reached its floor or the time limit: no path keeps more than D
  from the obstacles (D = r·Δ + the margin's reach + the disks' polygon error, the note's
  resolution statement: :mod:`cspace.se2.exact_report`).

A car moves along SE(2) paths, so the POSSIBLE graph's proof holds for it too; a car cannot
turn in place, so its ``exact`` answers only with a proof. :func:`quick_proof` is the cheap end
(the POSSIBLE graph at the first 8 slabs, no refinement), run before a sampling planner spends its budget.
"""
from __future__ import annotations

import math
import time
import weakref

import numpy as np

from .result import PlanResult

QUICK_SHARE = 0.1   # of the time limit, at most, for the proof before sampling
QUICK_MAX = 1.0     # seconds, at most, whatever the limit
# A search's room (a car's path kept off the obstacles, a heuristic, no promise) is a disk's polygon
# this much (relative) outside it: an octagon, not the 71 sides of a clearance the user asks for (its
# corners at every obstacle corner made FREE's boundary, its links and its mesh several times larger)
ROOM_DISK_TOLERANCE = 0.1
SHORTCUT_TRIES = 100  # the vertex reduction of a bounded shortening tries at least this many shortcuts
CAR_SLABS = 128     # the finest partition a car's proof-only search tries
# The proof before sampling refines the first 8 slabs once, where the POSSIBLE graph still joins
# start and goal (16 slabs at most): ~2-3x the 8 slabs' cost (~20 ms on the bundled scenes, the
# regions kept for the next query), and it proves a corner a long robot cannot turn.
QUICK_WIDTH = 2 * math.pi / 16
_REGIONS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # C-space -> {room: its SlabRegions}
# C-space -> the (start, goal) pairs whose proof before sampling ran to its end and found no proof.
# That search is deterministic (the same regions, slabs and graph), so asking again answers the same;
# a search cut short by its time budget is not remembered (a longer one might still prove).
_NO_PROOF: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
# C-space -> the POSSIBLE graphs of the proof before sampling's partitions, their components labelled
# (cspace.se2.possible_joins): built once per map, they answer "joined at every partition" (no proof)
# per query by lookups; only a query they separate runs the search (which writes the proof).
_JOINS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def search(cspace, query, time_limit: float | None, *, possible_only: bool = False, refine: bool = True,
           min_width: float | None = None, room: float = 0.0, near: bool = False):
    """The slab-graph search on an SE(2) C-space's pieces (body frame; its margin, if any,
    inflates the robot for the path, while a proof is made for the body itself). The slab
    regions are kept with the C-space, so the queries of one scene share them.

    ``room`` > 0 asks for a path that keeps that much more clearance: the robot is inflated by
    a polygon holding the disk of radius ``room`` as well (an octagon: :data:`ROOM_DISK_TOLERANCE`;
    its own regions, kept too); a start
    or goal closer than that to an obstacle raises ValueError. ``near``: the path turns where it
    is, not at the links' kept points (:func:`cspace.se2.exact_path.near_links`)."""
    from cspace.se2.exact import exact_se2_search

    margin = _room_margin(cspace, float(room))
    regions = _regions_of(cspace, float(room))
    return exact_se2_search(cspace.obstacle_pieces, cspace.body_pieces, cspace.bounds, tuple(query.start),
                            tuple(query.goal), time_limit=time_limit, margin=margin or None,
                            possible_only=possible_only, refine=refine, regions=regions, near=near,
                            **({} if min_width is None else {"min_width": min_width}))


def prepare(cspace, exact: bool = False) -> float:
    """Build the POSSIBLE regions of every partition :func:`quick_proof` tries, and their graphs'
    components (:func:`proof_joins`: a query then looks up its start and goal), for a C-space
    that will serve many queries, and with ``exact`` also their FREE regions, the meshes their
    translations search and the links between them (what :func:`exact_se2` reads first), and
    FREE of their halves (a pair through a narrow door refines there first); returns the seconds
    it took."""
    from cspace.se2.exact import initial_partition
    from cspace.paths.shortest import warm

    t = time.perf_counter()
    regions = _regions_of(cspace)
    part = initial_partition()
    proof_joins(cspace)  # every partition the proof before sampling tries, labelled
    for a, b in part:
        if exact:
            free = regions.free(a, b)
            warm(free.pieces, regions.bounds, free.components)
    if exact:
        for (a, b), (c, d) in zip(part, part[1:] + part[:1]):  # the links between neighbouring slabs
            regions.free_links(regions.free(a, b), regions.free(c, d))
        for a, b in part:  # FREE of the halves the search's first refinement bisects a slab into
            regions.free(a, 0.5 * (a + b))
            regions.free(0.5 * (a + b), b)
    return time.perf_counter() - t


def proof_joins(cspace, build: bool = True) -> list:
    """The :class:`cspace.se2.possible_joins.PossibleJoins` of every partition :func:`quick_proof`'s
    search tries (its POSSIBLE regions built where missing), made once per C-space and kept;
    ``build=False``: those kept, or [] (nothing is built)."""
    from cspace.se2.exact import ANGLE_NEAR, initial_partition
    from cspace.se2.possible_joins import PossibleJoins, proof_partitions

    joins = _JOINS.get(cspace)
    if joins is None and build:
        regions = _regions_of(cspace)
        joins = _JOINS[cspace] = [PossibleJoins(regions, p, ANGLE_NEAR)
                                  for p in proof_partitions(initial_partition(), QUICK_WIDTH)]
    return joins or []


def built_regions(cspace) -> dict:
    """What the slab graph has built for this C-space so far, every room together: its FREE and
    POSSIBLE regions (``regions``, how many) and their seconds (``region_s``); nothing built: 0."""
    made = {id(r): r for sr in _REGIONS.get(cspace, {}).values() for r in (*sr._free.values(), *sr._possible.values())}
    made = list(made.values())  # (POSSIBLE shared between rooms: counted once)
    return {"regions": len(made), "region_s": sum(r.seconds for r in made)}


def slab_regions_of(cspace, room: float = 0.0):
    """The C-space's POSSIBLE and FREE regions (a :class:`cspace.se2.slab_graph.SlabRegions`), the
    ones the slab graph's search reads for this ``room`` and keeps (a Dubins car's reach proof
    reads the body's, ``room`` 0)."""
    return _regions_of(cspace, float(room))


def _room_margin(cspace, room: float) -> list:
    """The C-space's margin shapes, and the polygon holding the disk of radius ``room`` (an octagon:
    :data:`ROOM_DISK_TOLERANCE`) where ``room`` > 0: what the robot is inflated by."""
    margin = list(cspace.margin or [])
    if room > 0:
        from cspace.kernel.minkowski.margin import margin_shapes

        margin += margin_shapes(room, disk_tolerance=ROOM_DISK_TOLERANCE)
    return margin


def _regions_of(cspace, room: float = 0.0):
    """The C-space's :class:`cspace.se2.slab_graph.SlabRegions` (with the extra clearance
    ``room``, see :func:`search`), made on first use and kept."""
    from cspace.se2.exact import disk_excess, slab_regions

    kept = _REGIONS.setdefault(cspace, {})
    if room not in kept:
        margin = _room_margin(cspace, room)
        kept[room] = slab_regions(
            cspace.obstacle_pieces, cspace.body_pieces, cspace.bounds, margin or None,
            inner_obstacles=getattr(cspace, "inner_obstacle_pieces", None),
            inner_robot=getattr(cspace, "inner_body_pieces", None),
            excess=disk_excess(cspace.scenario) if getattr(cspace, "scenario", None) is not None else 0.0)
        if room > 0:  # a car's search for a path with room: FREE's union unchecked (its path is
            kept[room].free_checked = False  # certified again; it states nothing), POSSIBLE the body's,
            kept[room].quick_links = True  # links without the overlay where they can (its path turns where it is)
            kept[room].share_possible(_regions_of(cspace))
    return kept[room]


def exact_se2(sc, cspace, adapter, query, source: str, time_limit: float | None = None,
              simplify: bool = True, refine: bool = True) -> PlanResult:
    """``planner = "exact"`` for a rotating robot (``space = "se2"``) or a car (a proof or nothing).
    ``refine=False``: the first slabs only (``auto``'s second stage)."""
    from cspace.io.load import ScenarioError

    car = sc.space != "se2"
    t0 = time.perf_counter()
    # a car's proof-only search stops at CAR_SLABS slabs: past that, a proof is unlikely and the
    # user is waiting for the advice to sample
    res = search(cspace, query, time_limit, possible_only=car, refine=refine,
                 min_width=2 * math.pi / CAR_SLABS if car else None)
    search_s = time.perf_counter() - t0
    st = res.stats
    base, timings = _described(sc, query, res, search_s)
    graph = f"{st['slabs']} slabs, {st['refinements']} refinements"
    if res.status == "unsolvable":
        return from_search(sc, query, res, search_s)
    if car and sc.space == "dubins":  # a forward-only car: the reach of one end, closed under its steps
        from .dubins_proof import REACH_MAX, reach_result

        reach = reach_result(sc, cspace, _regions_of(cspace), query, REACH_MAX if time_limit is None else
                             min(REACH_MAX, max(float(time_limit) - search_s, 0.0)))
        if reach is not None:
            reach.planner, reach.timings = "exact", {**timings, **reach.timings}
            return reach
    if car:  # a Dubins car (a Reeds-Shepp car's exact is planners.core.auto.exact_reeds_shepp)
        from ..adapters.glue import ompl_available

        then = ("use a sampling planner such as RRTConnect" if ompl_available() else
                "a car's path needs OMPL's sampling planners (not installed)")
        raise ScenarioError(source, "planner", 'a Dubins car (space = "dubins") cannot turn in place: exact only '
                                               f"proves there is no path, and found no proof (slab graph: {graph}; "
                                               f"reach of either end): {then}")
    if res.status == "undecided":
        why = st.get("error") or st.get("reason", "")
        return PlanResult(solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf, timings=timings,
                          message=f"not decided ({why}; {graph}): {st['statement']}; try a longer --time, or a "
                                  "sampling planner (it may find a path closer to the obstacles)", **base)
    raw = np.asarray(res.path, dtype=np.float64)
    t1 = time.perf_counter()  # the re-check and the shortening keep --time too (a re-check cut short says so)
    ok, why, cut = adapter.verify_until(raw, query.start, query.goal, None if time_limit is None else t0 + time_limit)
    timings["verify"] = time.perf_counter() - t1
    found_cpu = time.process_time()
    if not ok:  # the slab graph certifies its path; this re-check is the second opinion
        return PlanResult(solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf, timings=timings,
                          message=f"the slab graph's path failed the certified re-check ({why}): not solved", **base)
    path, note = raw, "not shortened (--no-simplify)"
    if cut is not None:  # every motion was checked exactly as the slab graph built it; the second opinion ran out of time
        note = f"{why} (each motion was checked exactly as the slab graph built it); not shortened: no time left"
    elif simplify:
        t2 = time.perf_counter()
        left = None if time_limit is None else max(0.0, float(time_limit) - (t2 - t0))
        path, note = shorten(adapter, raw, query, time_limit=left)
        timings["simplify"] = time.perf_counter() - t2
        base["stages"] = ["slab graph", "verify", "simplify"]
    length, raw_len = adapter.length(path), adapter.length(raw)
    return PlanResult(solved=True, exact=True, path=path, length=length, timings=timings,
                      message=f"certified path from the slab graph ({graph}; length {raw_len:.6g}, {note})",
                      length_unsimplified=raw_len, first_path_cpu=found_cpu, **base)


def _described(sc, query, res, search_s: float) -> tuple[dict, dict]:
    """The fields every answer of the slab graph's search shares, and its timings."""
    st = res.stats
    checks = {"slabs": st["slabs"], "refinements": st["refinements"],
              **{f"{g}_{k}": v for g, d in st.get("graphs", {}).items() for k, v in d.items()},
              **{f"regions_{k}": v for k, v in st.get("regions_built", {}).items()}}
    timings = {"solve": search_s, "solve_cpu": st["cpu_seconds"],
               **{f"slab_{k}": v for k, v in st.get("seconds", {}).items()}}
    base = dict(scenario=sc.name, planner="exact", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                checks=checks, stages=["slab graph"])
    return base, timings


def from_search(sc, query, res, search_s: float) -> PlanResult:
    """A search that proved start and goal separated, as a PlanResult carrying its proof."""
    base, timings = _described(sc, query, res, search_s)
    graph = f"{res.stats['slabs']} slabs, {res.stats['refinements']} refinements"
    return PlanResult(solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf, timings=timings,
                      message=f"proven unsolvable: no collision-free path exists at any resolution (the "
                              f"slab graph's POSSIBLE regions separate start and goal; {graph}){_too_big(sc, res.proof)}",
                      proof=res.proof, **base)


def _too_big(sc, proof) -> str:
    """A note when the proof asks ``check-proof`` for more work than it takes (it would refuse it)."""
    from .proof_check import LIMITS, convex_obstacles, proof_work

    work = proof_work(convex_obstacles(sc), proof["slabs"])
    return "" if work <= LIMITS["work"] else (f"; the proof is past check-proof's work limit ({work} > "
                                              f"{LIMITS['work']}): it cannot be re-checked")


def shorten(adapter, path: np.ndarray, query, time_limit: float | None = None,
            bounded: bool = False) -> tuple[np.ndarray, str]:
    """``path`` shortened by OMPL's simplifier under the adapter's certified motion validator,
    and verified again; the original path where OMPL is missing, the result is not better, or
    ``time_limit`` (seconds) runs out: the simplifier stops at it (its termination condition,
    and every motion check asked after it answers "not free" at once, so OMPL keeps what it has),
    and a shortening that ended past it is dropped for the certified path (its re-check would
    take more time). Deterministic within its time: OMPL's random stream is seeded with 0.
    ``bounded``: only OMPL's vertex reduction, a number of tries bounded by the path's size (the
    whole simplifier's rounds are not bounded: seconds on a car's path of hundreds of short curves)."""
    from ..adapters.glue import make_setup, ompl, ompl_available

    if len(path) < 3:
        return path, "nothing to shorten"
    if not ompl_available():
        return path, "OMPL not installed: not shortened"
    if time_limit is not None and time_limit <= 0.0:
        return path, "no time left to shorten it"
    ob, og = ompl()[:2]
    ss, _space, _checker, validator = make_setup(adapter, "RRTConnect", 0)
    deadline = None if time_limit is None else time.perf_counter() + float(time_limit)
    if deadline is not None and hasattr(validator, "motion_free"):
        check = validator.motion_free
        validator.motion_free = lambda q0, q1: time.perf_counter() < deadline and check(q0, q1)
    ss.setup()
    si = ss.getSpaceInformation()
    p = og.PathGeometric(si)
    for pose in path:
        s = si.allocState()
        adapter.set_state(s, pose)
        p.append(s)
    if bounded:  # shortcuts between random vertices, a bounded number of tries (OMPL's rounds are not)
        og.PathSimplifier(si).reduceVertices(p, max(SHORTCUT_TRIES, 4 * len(path)))
    elif deadline is None:
        og.PathSimplifier(si).simplifyMax(p)
    else:
        og.PathSimplifier(si).simplify(p, ob.timedPlannerTerminationCondition(deadline - time.perf_counter()), False)
    if deadline is not None and time.perf_counter() >= deadline:
        return path, "the time limit stopped the shortening: the certified path is kept as found"
    out = adapter.path_array(p)
    out[0], out[-1] = path[0], path[-1]  # the exact ends (the states' round trip may round x, y)
    ok, _ = adapter.verify(out, query.start, query.goal)
    if ok and adapter.length(out) <= adapter.length(path):
        return out, f"shortened to {adapter.length(out):.6g} by OMPL's simplifier"
    return path, "OMPL's simplifier did not shorten it"


def quick_proof(sc, cspace, query, time_limit: float) -> PlanResult | None:
    """Before a sampling planner spends its budget: the POSSIBLE graph at the first slabs, refined
    once (:data:`QUICK_WIDTH`), within a small share of the time limit. A result (not solved, proven unsolvable) when it separates
    start and goal, else None (the planner runs). A query whose search ran to its end without a
    proof is remembered with the C-space (:data:`_NO_PROOF`): the next seed skips the search."""
    from cspace.se2.exact import NO_PROOF_FOUND

    key = (tuple(map(float, query.start)), tuple(map(float, query.goal)))
    tried = _NO_PROOF.setdefault(cspace, set())
    if key in tried:  # this search ran to its end before and found no proof: it would again
        return None
    joins = proof_joins(cspace, build=False)
    if joins and all(j.joined(query.start, query.goal) for j in joins):  # the search's answer, by lookups
        tried.add(key)
        return None
    budget = min(QUICK_SHARE * time_limit, QUICK_MAX)
    res = search(cspace, query, budget, possible_only=True, min_width=QUICK_WIDTH)
    if res.status != "unsolvable":
        if res.stats.get("reason") == NO_PROOF_FOUND:
            tried.add(key)
            proof_joins(cspace)  # its regions and links are all built now: label them for the next query
        return None
    return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 3)), length=math.inf,
                      planner="", seed=0, start=tuple(query.start), goal=tuple(query.goal),
                      timings={}, checks={"slabs": res.stats["slabs"]},
                      stages=["slab graph"], proof=res.proof,
                      message="proven unsolvable before sampling: no collision-free path exists at any resolution "
                              f"(the slab graph's POSSIBLE regions at {res.stats['slabs']} slabs separate start and goal)")
