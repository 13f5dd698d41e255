"""Bench-MR's suite, side by side: its four polygon worlds and MovingAI city maps, cspace against
OMPL with a discrete-checking peer, every path judged by an independent swept check.

Problems (read from a Bench-MR checkout, ``--bench-mr DIR``; nothing of it is copied here):

- the 20 polygon problems: parking1-3 and warehouse (``bin/polygon_mazes/*.svg``, imported with
  ``--convex-hulls`` as Bench-MR plans them; ``--true-shapes`` keeps the drawn shapes), each with
  its robot (``car.svg``, ``warehouse_robot.svg``) and the 5 start/goal poses of Bench-MR's notebook
  (``python/Benchmark Polygon Worlds.ipynb``), in Dubins and Reeds–Shepp with turning radius 4.
  The poses were written for the drawings before Bench-MR's commit 7692815 (which moved each
  world): they are shifted by the difference of the obstacles' box corners, old to new, as
  recorded (``SHIFT``, to 4 decimals: every checkout plans the same poses and draws the same
  pictures) and checked against the checkout's git history when it has it (``git show
  7692815^:...``, the old reading: absolute path coordinates, y negated, scaled 1/22);
- the last ``--rows`` rows (default 10) of ``Berlin_0_256`` and ``Boston_2_512`` (Reeds–Shepp,
  Bench-MR's car, MovingAI's frame, headings estimated as Bench-MR estimates them; rows whose
  start or goal puts the car on a blocked cell are counted and left out).

The bounds of a polygon world: the obstacles' box and a margin of two turning radii (``MARGIN``):
Bench-MR's box bounds only the states its planners sample, while OMPL's motion check walks a
curve's states against the obstacles alone, so its cars drive out of a drawing and back.
``--box-bounds`` keeps the box alone: a forward-only car facing its edge closer than its turning
radius (parking1's and parking2's slot poses) then cannot turn away before it leaves the box.

Per problem and seed, in turn: ours, cspace's time to its first certified path in the default
planner's order (``ours_first``: a slice of sampling, then the proof before sampling only where
the slice found nothing, then the planner, RRTConnect (RRT for Dubins, whose one-way curves
RRTConnect's goal tree drives backwards) stopped at its first solution; CPU seconds), and the
peer, the same OMPL planner on the same state space with a shapely state checker and OMPL's
discrete motion check at Bench-MR's step, 0.005 of its box's extent (``se2_peers.peer_first``).
The C-space's slabs are built once per world and car model before its queries (the column "C-space
(once)"), as the peer's checker is. Every path either returns is judged by the independent shapely
sweep along its curves (``sweep_oracle.car_sweep_check``). A Dubins query that the slice does not
answer goes on as in ``auto`` (``planners.core.auto_dubins``): restarts of the planner at a shorter
range, the reach proof (``planners.core.dubins_proof``: the reach of either end, closed under the
forward car's steps) and the SE(2) proof between them; every proof is re-checked by ``cspace
check-proof``'s independent checker (the count it accepts is printed). A Dubins query with
neither a path nor a proof is probed by a lattice (``boxed_in``): when the poses a forward-only
car reaches from the start, or reaches the goal from, run out without coming near the other end,
the script says so -- evidence, not a proof (the reach proof's cap or its over-approximation
stopped short). The table: solved, undecided, colliding, median and mean time to
the first path, and ours / peer over the runs both solve with the peer's path sound (medians and
means), per row and per world (target <= 0.5x). Then the peer's paths are written in Bench-MR's
results format and re-checked by ``cspace recheck``'s routine
(``planners.bench.benchmr_results.recheck``): how many paths its discrete check called
collision-free cross an obstacle, and the recheck's time.

Usage: python scripts/bench_benchmr.py [--bench-mr DIR] [--git-dir GIT] [--seeds N] [--time S] [--rows N]
       [--quick] [--skip-movingai] [--no-peer] [--true-shapes] [--box-bounds] [--json FILE] [--figures DIR]
Without a checkout (--bench-mr DIR, or $BENCH_MR) it says so and exits 0.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

import se2_peers  # noqa: E402  (the peer's checker and planning)
from sweep_oracle import car_sweep_check  # noqa: E402

# Bench-MR's notebook "Benchmark Polygon Worlds": (x, y, theta) start and goal per problem.
POSES = {
    "parking1": [((0, -2.27, 0), (7.72, -7.72, -1.58)), ((7.72, -7.72, -1.58), (0, -2.27, 3.14)),
                 ((7.72, -7.72, -1.58), (10, -7.72, 1.58)), ((7.72, -7.72, -1.58), (15, -2.27, 0)),
                 ((15, -2.27, 3.14), (7.72, -7.72, -1.58))],
    "parking2": [((0, -2.27, 0), (10.91, 2.73, 1.57)), ((10.91, 2.73, 1.57), (0, -2.27, 3.14)),
                 ((0, -2.27, 0), (13.5, -7, 1.57)), ((13.5, -7, 1.57), (0, -2.27, 3.14)),
                 ((13.5, -7, 1.57), (10.91, 2.73, 1.57))],
    "parking3": [((15.45, -2.27, 0), (3.4, 0.34, 0)), ((5, -2.27, 0), (19.5, -6, 0)),
                 ((19.5, -6, 3.14), (5, -2.27, 3.14)), ((19.5, -2.5, 3.14), (4.5, 0.5, 3.14)),
                 ((4.5, 0.5, 0), (19.5, -2.5, 0))],
    "warehouse": [((-2.5, 4.55, -1.58), (65, 2.5, -1.58)), ((-2.5, -55, 0), (55, 5.5, 0)),
                  ((14.5, -28, 1.58), (48, -28, 1.58)), ((65, -55, 3.14), (14.5, 0, 1.58)),
                  ((3, -5, 3.14), (66, -5, 1.58))],
}
ROBOT = {"parking1": "car.svg", "parking2": "car.svg", "parking3": "car.svg", "warehouse": "warehouse_robot.svg"}
# The old drawings' frame to the current one (the obstacles' box corners), measured on the
# checkout fetched 2026-11 (master after 7692815) with old_frame_shift().
SHIFT = {"parking1": (1.3795, -4.756), "parking2": (1.3795, -4.7422), "parking3": (9.0207, -9.451),
         "warehouse": (11.1359, -12.1615)}
OLD_COMMIT = "7692815^"
RADIUS = 4.0
RESOLUTION = 0.005  # Bench-MR's OMPL state validity checking resolution (fraction of the extent)
MAPS = ("Berlin_0_256", "Boston_2_512")
# Bench-MR's box (the obstacles') bounds only the states its planners sample: OMPL's motion check
# walks a curve's states against the obstacles alone, so its cars drive out of a drawing and back
# (a parking lot has no wall around it). The suite's bounds, which every motion of ours keeps to,
# are that box and this margin: two turning radii, room for a U-turn outside the drawing.
# (``--box-bounds``: the box alone. A forward-only car facing the box's edge, closer to it than
# its turning radius, then cannot turn away before it leaves the box: parking1's and parking2's
# slot poses make five Dubins queries unsolvable, which no method of cspace proves.)
MARGIN = 2 * RADIUS
LATTICE_STEP, LATTICE_CAP = 0.1, 20000  # boxed_in's lattice: step (length units), poses


def old_frame_shift(bench_mr: str, world: str, git_dir: str | None = None) -> tuple[float, float] | None:
    """The shift from the drawing before 7692815 (as Bench-MR read it then: absolute path
    coordinates, y negated, scaled 1/22, transforms ignored) to the current one (as it reads it
    now), from the checkout's git history: the obstacles' boxes' lower-left corners. None
    without the history."""
    import re

    import shapely

    from cspace.io.importers.svg import read_svg, path_shapes
    from cspace.io.importers.svg_path import parse_path

    try:
        where = ["--git-dir", git_dir] if git_dir else ["-C", bench_mr]
        old = subprocess.run(["git", *where, "show", f"{OLD_COMMIT}:bin/polygon_mazes/{world}.svg"],
                             capture_output=True, text=True, timeout=60, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    pts = [np.concatenate(parse_path(d)[0]) * (1, -1) / 22 for d in re.findall(r'^\s*d="([^"]*)"', old, re.M)]
    lo_old = np.concatenate(pts).min(axis=0)
    path = os.path.join(bench_mr, "bin", "polygon_mazes", f"{world}.svg")
    paths, _ = read_svg(path)
    new = shapely.union_all([g for p in paths for g in path_shapes(p, path, None, True)[0]])
    return float(new.bounds[0] - lo_old[0]), float(new.bounds[1] - lo_old[1])


def polygon_problems(bench_mr: str, hulls: bool, git_dir: str | None = None, margin: float = MARGIN) -> list[dict]:
    """The 20 polygon problems in both car models: {name, sc (with queries), shift}. The bounds:
    the obstacles' box (grown to hold the poses) and ``margin`` around it (see :data:`MARGIN`)."""
    from cspace.io.importers.imported import ImportOptions, import_file
    from cspace.io.importers.svg import svg_robot
    from cspace.io.scenario.validate import scenario_from_dict, with_queries

    folder = os.path.join(bench_mr, "bin", "polygon_mazes")
    out = []
    for world, pairs in POSES.items():
        # the recorded shift, so that every checkout plans the same poses (and draws the same
        # pictures); the history, where the checkout has it, must agree with it
        shift, measured = SHIFT[world], old_frame_shift(bench_mr, world, git_dir)
        if measured is not None and max(abs(a - b) for a, b in zip(measured, shift)) > 1e-3:
            raise SystemExit(f"{world}: the checkout's history shifts the poses by ({measured[0]:.4f}, "
                             f"{measured[1]:.4f}), not the recorded ({shift[0]}, {shift[1]}): another drawing?")
        robot = svg_robot(os.path.join(folder, ROBOT[world]), convex_hull=hulls)[0]
        moved = [tuple((p[0] + shift[0], p[1] + shift[1], p[2]) for p in pair) for pair in pairs]
        imp = import_file(os.path.join(folder, f"{world}.svg"),
                          ImportOptions(robot=robot, start=moved[0][0], goal=moved[0][1], convex_hulls=hulls))
        b = imp.data["bounds"]
        for s, g in moved:  # every pose inside the bounds (Bench-MR's boxes are the obstacles')
            for x, y, _ in (s, g):
                b["xmin"], b["xmax"] = min(b["xmin"], x), max(b["xmax"], x)
                b["ymin"], b["ymax"] = min(b["ymin"], y), max(b["ymax"], y)
        b.update(xmin=b["xmin"] - margin, xmax=b["xmax"] + margin, ymin=b["ymin"] - margin, ymax=b["ymax"] + margin)
        # the peer's step: Bench-MR's 0.005 of its box's extent, as a fraction of the grown bounds'
        step = RESOLUTION * math.hypot(b["xmax"] - b["xmin"] - 2 * margin, b["ymax"] - b["ymin"] - 2 * margin) / \
            math.hypot(b["xmax"] - b["xmin"], b["ymax"] - b["ymin"])
        for space in ("reeds-shepp", "dubins"):
            sc = scenario_from_dict(imp.data, world, space=space, turning_radius=RADIUS)
            sc = with_queries(sc, {"queries": [{"start": list(s), "goal": list(g)} for s, g in moved]}, world)
            out.append({"world": world, "space": space, "sc": sc, "shift": shift, "peer_resolution": step})
    return out


def movingai_problems(bench_mr: str, rows: int) -> list[dict]:
    """The last ``rows`` rows of each city map, Reeds–Shepp, Bench-MR's car, as `cspace plan --scen` reads them."""
    from types import SimpleNamespace

    from cspace.io.importers.imported import ImportOptions
    from cspace.io.importers.movingai import read_scen
    from cspace.io.importers.svg import svg_robot
    from planners.cli.scen import scen_scenario

    folder = os.path.join(bench_mr, "bin", "moving_ai_scenarios")
    robot = svg_robot(os.path.join(bench_mr, "bin", "polygon_mazes", "car.svg"))[0]
    out = []
    for name in MAPS:
        src, scen = os.path.join(folder, f"{name}.map"), os.path.join(folder, f"{name}.map.scen")
        selected = read_scen(scen, f"-{rows}:")
        args = SimpleNamespace(scen=scen, space="reeds-shepp", turning_radius=RADIUS, scen_headings=None)
        sc, kept = scen_scenario(args, src, ImportOptions(robot=robot), selected, [])
        out.append({"world": name, "space": "reeds-shepp", "sc": sc, "left_out": len(selected) - len(kept)})
    return out


def run_problem(p: dict, seeds: int, limit: float, peer: bool) -> dict:
    """Every query x seed: ours then the peer, each path judged."""
    from cspace.car.curves import dubins_segments, reeds_shepp_segments
    from planners.core.plan import build_cspace, make_adapter

    sc = p["sc"]
    seg = dubins_segments if sc.space == "dubins" else reeds_shepp_segments
    c0 = time.process_time()
    cs = build_cspace(sc)
    adapter = make_adapter(sc, cs)
    for k in range(cs.slabs):  # the C-space's slabs, once per world (as the peer's checker is built once)
        cs.slab(k)
    build = time.process_time() - c0
    checker = se2_peers.shapely_checker(sc) if peer else None

    def collides(path):
        return car_sweep_check(sc, path, lambda a, b: seg(a, b, sc.turning_radius), sc.turning_radius)["collides"]

    planner = planner_for(sc.space)
    runs, boxed = [], {}
    for qi, q in enumerate(sc.all_queries()):
        for seed in range(seeds):
            path, cpu, proof_cpu, proof = ours_first(sc, cs, adapter, q, seed, limit, planner)
            row = {"query": qi, "seed": seed, "ours_s": cpu if path is not None else None, "ours_proof_s": proof_cpu,
                   "proven_unsolvable": proof is not None, "ours_colliding": bool(path is not None and collides(path))}
            if proof is not None:  # re-checked by check-proof's independent checker
                row["proof_format"], row["proof_accepted"] = proof["format"], accepted(sc, proof, qi)
            if peer:
                path, cpu = se2_peers.peer_first(adapter, checker, adapter.pose(q.start), adapter.pose(q.goal), seed,
                                                 limit, planner, resolution=p.get("peer_resolution", RESOLUTION))
                row.update(peer_s=cpu if path is not None else None,
                           peer_colliding=bool(path is not None and collides(path)),
                           peer_path=None if path is None else np.asarray(path, float).tolist())
            runs.append(row)
        if sc.space == "dubins" and not any(x["ours_s"] is not None or x["proven_unsolvable"]
                                            for x in runs if x["query"] == qi):
            boxed[qi] = boxed_in(adapter, q)
    return {"boxed_in": boxed, "world": p["world"], "space": p["space"], "planner": planner, "build_s": build, "runs": runs,
            "queries": len(sc.all_queries()), "left_out": p.get("left_out", 0), "sc": sc}


def ours_first(sc, cs, adapter, query, seed: int, limit: float, planner: str):
    """cspace's first certified path, in the order of the default planner (``auto``): a slice of
    sampling first (``auto.SLICE_ITERATIONS`` iterations, ``auto.SLICE_SHARE`` of the limit), the
    proof before sampling only where that slice found nothing (on a city map the proof's POSSIBLE
    regions cost seconds, and a solvable query needs none), then the planner with the rest; a
    Dubins car after its slice: ``auto``'s restarts and proofs (``planners.core.auto_dubins``),
    with this planner: (path or None, CPU seconds, of which the proofs, the proof where one found
    the query unsolvable, else None)."""
    from planners.core.auto import SLICE_ITERATIONS, SLICE_SHARE
    from planners.core.exact_se2 import quick_proof
    from planners.core.routine import run_planner

    c0, w0 = time.process_time(), time.perf_counter()
    pair = [(adapter.pose(query.start), adapter.pose(query.goal))]
    res = run_planner(adapter, planner, pair, SLICE_SHARE * limit, seed, iterations=SLICE_ITERATIONS,
                      simplify=False, until_first=True)[0]
    if res.solved:
        return res.path, time.process_time() - c0, 0.0, None
    if sc.space == "dubins":
        return _dubins_first(sc, cs, adapter, query, pair, seed, limit, planner, c0, w0)
    c1 = time.process_time()
    proof = quick_proof(sc, cs, query, limit)
    c2 = time.process_time()
    if proof is not None:
        return None, time.process_time() - c0, c2 - c1, proof.proof
    left = limit - (time.perf_counter() - w0)
    res = run_planner(adapter, planner, pair, max(left, 0.0), seed, simplify=False, until_first=True)[0]
    return (res.path if res.solved else None), time.process_time() - c0, c2 - c1, None


def _dubins_first(sc, cs, adapter, query, pair, seed: int, limit: float, planner: str, c0: float, w0: float):
    """ours_first's Dubins car after its slice: ``auto``'s stages (``auto_dubins.dubins_stages``)."""
    from planners.core.auto import turn_seed
    from planners.core.auto_dubins import dubins_stages, with_range
    from planners.core.routine import run_planner

    class Clock:  # auto's budget, as dubins_stages reads it; the proofs' CPU counted apart
        proof_cpu = 0.0

        def left(self):
            return limit - (time.perf_counter() - w0)

        def run(self, stage, call):
            c = time.process_time()
            try:
                return call()
            finally:
                self.proof_cpu += time.process_time() - c

    def sample(budget, n, turn, radii):
        return with_range(adapter, radii, lambda: run_planner(adapter, planner, pair, max(budget, 0.0),
                                                              turn_seed(seed, turn), iterations=n, simplify=False,
                                                              until_first=True)[0])

    clock = Clock()
    r, stage = dubins_stages(sc, cs, query, sample, clock, limit, None)
    cpu = time.process_time() - c0
    if stage == "proof":
        return None, cpu, clock.proof_cpu, r.proof
    return (r.path if stage == "sampling" else None), cpu, clock.proof_cpu, None


def accepted(sc, proof: dict, query_index: int) -> bool:
    """Whether ``cspace check-proof``'s independent checker accepts the proof (either format)."""
    from planners.core.dubins_check import FORMAT, check_dubins_proof
    from planners.core.proof_check import check_proof

    check = check_dubins_proof if proof.get("format") == FORMAT else check_proof
    return check(sc, proof, query_index).valid


def boxed_in(adapter, query, step: float = LATTICE_STEP, cap: int = LATTICE_CAP) -> str | None:
    """Why a Dubins query found neither a path nor a proof, where a lattice shows it: the poses a
    forward-only car reaches from the start by certified steps of ``step`` (left, straight,
    right; poses merged on a grid of 0.6 steps and 2 degrees), or from which it reaches the goal
    (the same steps in reverse from the goal). When either set ends within ``cap`` poses without
    coming near the other end (its grid cell or a neighbour), that end's reach is said to end --
    evidence, not a proof (a finer lattice, or a curve between its poses, might get further;
    cspace has no proof method for Dubins cars). None: no such claim.

    >>> boxed_in.__defaults__ == (LATTICE_STEP, LATTICE_CAP)
    True
    """
    from cspace.car.curves import advance

    car, r = adapter.cspace, adapter.radius

    def key(z):
        return round(z[0] / (0.6 * step)), round(z[1] / (0.6 * step)), round(z[2] % (2 * math.pi) / math.radians(2)) % 180

    ends = (("start", query.start, query.goal, 1.0), ("goal", query.goal, query.start, -1.0))
    for end, pose, other, sign in ends:
        z0 = tuple(float(v) for v in pose)
        seen, todo = {key(z0)}, [z0]
        while todo and len(seen) <= cap:
            z = todo.pop()
            for kind in "LSR":
                if car.curve_free(z, [(kind, sign * step)], r):
                    z2 = tuple(float(v) for v in advance(z, kind, sign * step, r))
                    if key(z2) not in seen:
                        seen.add(key(z2))
                        todo.append(z2)
        i, j, k = key(tuple(float(v) for v in other))
        near = any((i + a, j + b, (k + c) % 180) in seen for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1))
        if not todo and not near:
            way, what = ("forward", "goal") if sign > 0 else ("backward", "start")
            return f"the {end}'s {way} reach ends: {len(seen)} lattice poses, none near the {what}"
    return None


def planner_for(space: str) -> str:
    """RRTConnect, but RRT for Dubins: RRTConnect's goal tree grows by motions driven backwards,
    which a one-way Dubins curve is not (both sides use the same planner).

    >>> planner_for("dubins"), planner_for("reeds-shepp")
    ('RRT', 'RRTConnect')
    """
    return "RRT" if space == "dubins" else "RRTConnect"


def peer_recheck(r: dict) -> dict:
    """The peer's paths in Bench-MR's results format (each called collision-free, as its discrete
    check called them), re-checked by ``cspace recheck``'s routine: paths, colliding, seconds."""
    from planners.bench.benchmr_results import recheck

    doc = peer_document(r)
    t0 = time.perf_counter()
    rows = recheck(doc, r["world"])
    return {"paths": len(rows), "colliding": sum(x["colliding"] for x in rows), "seconds": time.perf_counter() - t0}


def peer_document(r: dict) -> dict:
    """The peer's paths of one world and car model as a Bench-MR results document (one run)."""
    sc = r["sc"]
    robot = [np.asarray(x.polygon, float).tolist() for x in sc.robot]
    return {"settings": {"env": {"collision": {"collision_model": 1, "robot_shape": robot[0], "robot_parts": robot}},
                        "steer": {"car_turning_radius": sc.turning_radius},
                        "steering": "dubins" if sc.space == "dubins" else "reeds_shepp"},
           "runs": [{"environment": {"type": "polygon", "obstacles": [np.asarray(o.polygon).tolist() for o in sc.obstacles],
                                     "holes": [[np.asarray(h).tolist() for h in o.holes] for o in sc.obstacles]},
                     "plans": {f"peer_{i}": {"path": x["peer_path"], "stats": {"path_found": True, "path_collides": False}}
                               for i, x in enumerate(r["runs"]) if x.get("peer_path")}}]}


def recheck_throughput(r: dict, n: int = 1000, per_run: int = 10) -> float | None:
    """Seconds ``cspace recheck``'s routine takes for ``n`` of the peer's trajectories laid out as a
    Bench-MR results file holds them: runs of ``per_run`` plans, each run repeating its world
    (the issue's target: <= 1 s per 1 000). None where the peer found no path."""
    from planners.bench.benchmr_results import recheck

    one = peer_document(r)
    paths = [p for p in one["runs"][0]["plans"].values()]
    if not paths:
        return None
    runs = [{"environment": one["runs"][0]["environment"],
             "plans": {f"peer_{j}": paths[(k * per_run + j) % len(paths)] for j in range(per_run)}}
            for k in range(n // per_run)]
    doc = {**one, "runs": json.loads(json.dumps(runs))}  # every run its own copy, as parsed from a file
    t0 = time.perf_counter()
    recheck(doc, r["world"])
    return time.perf_counter() - t0


def ratios(runs: list[dict]) -> tuple[float | None, float | None, int]:
    """ours / peer over the runs both solved with the peer's path sound: (medians' ratio, means'
    ratio, how many runs).

    >>> ratios([{"ours_s": 1.0, "peer_s": 4.0, "peer_colliding": False},
    ...         {"ours_s": 3.0, "peer_s": 2.0, "peer_colliding": True}, {"ours_s": None, "peer_s": 1.0}])
    (0.25, 0.25, 1)
    """
    both = [(x["ours_s"], x["peer_s"]) for x in runs if x["ours_s"] is not None and x.get("peer_s") is not None
            and not x["peer_colliding"]]
    if not both:
        return None, None, 0
    a, b = zip(*both)
    return statistics.median(a) / statistics.median(b), statistics.mean(a) / statistics.mean(b), len(both)


def summary(r: dict, peer: bool) -> dict:
    runs = r["runs"]
    ours = [x["ours_s"] for x in runs if x["ours_s"] is not None]
    proofs = [x["ours_proof_s"] for x in runs if x["ours_s"] is not None]
    row = {"world": r["world"], "space": r["space"], "runs": len(runs), "left_out": r["left_out"],
           "prep_s": r["build_s"], "ours_solved": len(ours), "ours_colliding": sum(x["ours_colliding"] for x in runs),
           "proven_unsolvable": sum(x["proven_unsolvable"] for x in runs),
           "proofs_accepted": sum(bool(x.get("proof_accepted")) for x in runs),
           "proven_proof_median_s": statistics.median(p) if (p := [x["ours_proof_s"] for x in runs
                                                                    if x["proven_unsolvable"]]) else None,
           "boxed_in": {str(k): v for k, v in r["boxed_in"].items() if v},
           "undecided_queries": sorted(r["boxed_in"]),
           "ours_proof_median_s": statistics.median(proofs) if proofs else None,
           "ours_median_s": statistics.median(ours) if ours else None,
           "ours_mean_s": statistics.mean(ours) if ours else None}
    if peer:
        theirs = [x["peer_s"] for x in runs if x["peer_s"] is not None]
        row.update(peer_solved=len(theirs), peer_colliding=sum(x["peer_colliding"] for x in runs),
                   peer_median_s=statistics.median(theirs) if theirs else None,
                   peer_mean_s=statistics.mean(theirs) if theirs else None)
        row["ratio"], row["ratio_mean"], row["ratio_runs"] = ratios(runs)
    return row


def table(rows: list[dict], peer: bool) -> str:
    head = ["world", "space", "runs", "C-space (once)", "ours solved (proven unsolvable)", "undecided (a reach ends)",
            "ours colliding", "ours median", "ours mean"]
    if peer:
        head += ["peer solved", "peer colliding", "peer median", "peer mean", "ours / peer, medians (sound, both)",
                 "means"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    ms = lambda v: "-" if v is None else f"{v * 1e3:.0f} ms"  # noqa: E731
    for r in rows:
        undecided = len(r["undecided_queries"])
        cells = [r["world"], r["space"], str(r["runs"]) + (f" ({r['left_out']} rows left out)" if r["left_out"] else ""),
                 ms(r["prep_s"]), f"{r['ours_solved']} ({r['proven_unsolvable']})",
                 f"{undecided} queries ({len(r['boxed_in'])})" if undecided else "0",
                 str(r["ours_colliding"]), ms(r["ours_median_s"]), ms(r["ours_mean_s"])]
        if peer:
            cells += [str(r["peer_solved"]), str(r["peer_colliding"]), ms(r["peer_median_s"]), ms(r["peer_mean_s"]),
                      "-" if r["ratio"] is None else f"{r['ratio']:.2f}x",
                      "-" if r["ratio_mean"] is None else f"{r['ratio_mean']:.2f}x"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def per_world(results: list[dict]) -> list[dict]:
    """Per world (both car models of a polygon world together): ours / peer over the peer's sound
    runs, against the target of 0.5x, in medians and in means."""
    out = []
    for world in dict.fromkeys(r["world"] for r in results):
        runs = [x for r in results if r["world"] == world for x in r["runs"]]
        med, mean, n = ratios(runs)
        out.append({"world": world, "sound_runs": n, "ratio_median": med, "ratio_mean": mean,
                    "met_median": med is not None and med <= 0.5, "met_mean": mean is not None and mean <= 0.5})
    return out


def figures(problems: list[dict], folder: str, limit: float) -> None:
    """One picture per world and car model: every query planned (seed 0) on one C-space."""
    from planners import plan
    from planners.pictures.plot import plot_result

    os.makedirs(folder, exist_ok=True)
    for p in problems:
        res = plan(p["sc"], planner=planner_for(p["sc"].space), time=limit, seed=0, all_queries=True)
        out = os.path.join(folder, f"{p['world']}_{p['space']}.png")
        plot_result(res, out)
        solved = sum(r.solved for r in (res.queries or [res]))
        print(f"figure {out}: {solved}/{len(res.queries or [res])} queries solved")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bench-mr", default=os.environ.get("BENCH_MR", ""),
                    help="a Bench-MR checkout (github.com/robot-motion/bench-mr); default: $BENCH_MR")
    ap.add_argument("--quick", action="store_true", help="1 seed, 3 s a run, the last 3 rows of each map")
    ap.add_argument("--git-dir", help="the checkout's git directory, when it is not DIR/.git (a bare mirror)")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--time", type=float, default=10.0, help="seconds per run")
    ap.add_argument("--rows", type=int, default=10, help="the last N .scen rows of each city map")
    ap.add_argument("--skip-movingai", action="store_true")
    ap.add_argument("--no-peer", action="store_true", help="cspace only")
    ap.add_argument("--true-shapes", action="store_true", help="the drawn shapes, not Bench-MR's convex hulls")
    ap.add_argument("--box-bounds", action="store_true", help="the polygon worlds' bounds: the obstacles' box alone "
                                                               "(default: and a margin of two turning radii)")
    ap.add_argument("--json", "--out-json", dest="json", metavar="FILE", help="write the rows and runs as JSON")
    ap.add_argument("--figures", metavar="DIR", help="also plan every problem's queries once (seed 0) and save a "
                                                     "picture of each world and car model with cspace's paths")
    args = ap.parse_args(argv)
    if not os.path.isdir(os.path.join(args.bench_mr or "-", "bin", "polygon_mazes")):
        print(f"no Bench-MR checkout at {args.bench_mr!r} (give --bench-mr DIR or set BENCH_MR): nothing run")
        return 0
    if args.quick:
        args.seeds, args.time, args.rows = 1, 3.0, 3
    from benchutil import check_json, check_out, write_json

    check_json(args.json, [os.path.join(args.bench_mr, "bin", d) for d in ("polygon_mazes", "moving_ai_scenarios")
                           if os.path.isdir(os.path.join(args.bench_mr, "bin", d))])  # (never over the checkout's files)
    check_out(args.figures, (), "--figures", folder=True)  # (created now, not after the runs)
    peer = not args.no_peer
    load = os.getloadavg()
    print(f"load average at start {load[0]:.2f}, {load[1]:.2f}, {load[2]:.2f} ({os.cpu_count()} CPUs)")
    problems = polygon_problems(args.bench_mr, hulls=not args.true_shapes, git_dir=args.git_dir,
                                margin=0.0 if args.box_bounds else MARGIN)
    for p in problems[::2]:
        print(f"{p['world']}: the published poses shifted by ({p['shift'][0]:.4f}, {p['shift'][1]:.4f})")
    if not args.skip_movingai:
        problems += movingai_problems(args.bench_mr, args.rows)
    results = []
    for p in problems:
        r = run_problem(p, args.seeds, args.time, peer)
        results.append(r)
        s = summary(r, peer)
        proven = (f", {s['proven_unsolvable']} proven unsolvable ({s['proofs_accepted']} proofs accepted by check-proof's "
                  f"checker; median {s['proven_proof_median_s'] * 1e3:.0f} ms of proofs)" if s["proven_unsolvable"] else "")
        print(f"{s['world']} {s['space']}: ours {s['ours_solved']}/{s['runs']} solved{proven}, {s['ours_colliding']} colliding"
              + (f"; peer {s['peer_solved']}/{s['runs']}, {s['peer_colliding']} colliding" if peer else ""),
              flush=True)
    rows = [summary(r, peer) for r in results]
    print(table(rows, peer))
    if peer:
        n = bad = 0
        secs = 0.0
        for r, row in zip(results, rows):
            rc = peer_recheck(r)
            row["peer_recheck"] = rc
            n, bad, secs = n + rc["paths"], bad + rc["colliding"], secs + rc["seconds"]
            print(f"recheck of the peer's paths, {r['world']} {r['space']}: {rc['colliding']} of {rc['paths']} called "
                  f"collision-free by its 0.005 discrete check collide")
        print(f"recheck: {n} paths in {secs:.2f} s ({secs / max(n, 1) * 1e3:.1f} ms a path, a C-space per world "
              f"included), {bad} colliding")
        busy = next((r for r in results if sum(bool(x.get("peer_path")) for x in r["runs"]) >= 2), None)
        t = recheck_throughput(busy) if busy else None
        if t is not None:
            print(f"recheck, 1 000 of the peer's {busy['world']} {busy['space']} trajectories as a results file holds "
                  f"them (100 runs of 10 plans, each run repeating the world): {t:.2f} s (target <= 1 s: "
                  f"{'met' if t <= 1.0 else 'MISSED'})")
    for r in results:
        for qi, why in sorted(r["boxed_in"].items()):
            print(f"{r['world']} {r['space']} query {qi}: neither a path nor a proof"
                  + (f"; {why} (a lattice's evidence, not a proof)" if why else ""))
    worlds = per_world(results) if peer else []
    for w in worlds:
        fmt = lambda v: "-" if v is None else f"{v:.2f}x"  # noqa: E731
        print(f"ours / peer, {w['world']} (its {w['sound_runs']} runs both solve, the peer's path sound): "
              f"medians {fmt(w['ratio_median'])}, means {fmt(w['ratio_mean'])} (target <= 0.5x: "
              f"{'met' if w['met_median'] and w['met_mean'] else 'met in medians' if w['met_median'] else 'MISSED'})")
    poly = [x for r in results if r["world"] in POSES for x in r["runs"]]
    firsts = [x["ours_s"] for x in poly if x["ours_s"] is not None]
    if firsts:
        print(f"polygon worlds: ours {len(firsts)}/{len(poly)} runs solved, "
              f"{sum(x['proven_unsolvable'] for x in poly)} proven unsolvable, median time to the first certified path "
              f"{statistics.median(firsts) * 1e3:.0f} ms (target <= 150 ms), "
              f"{sum(x['ours_colliding'] for x in poly)} colliding (target 0)")
    for r in results:
        if r["world"] in MAPS:
            t = [x["ours_s"] for x in r["runs"] if x["ours_s"] is not None]
            mean = statistics.mean(t) if t else None
            print(f"{r['world']}: ours {len(t)}/{len(r['runs'])} solved, mean {'-' if mean is None else f'{mean * 1e3:.0f} ms'}"
                  f" (target <= 150 ms; the C-space's slabs, built once before the rows, {r['build_s']:.2f} s), "
                  f"{sum(x['ours_colliding'] for x in r['runs'])} colliding")
    if args.figures:
        figures(problems, args.figures, args.time)
    if args.json:
        write_json(args.json, {"rows": rows, "worlds": worlds, "load_start": list(load), "load_end": list(os.getloadavg()),
                               "results": [{k: v for k, v in r.items() if k != "sc"} for r in results]})
    return 0


if __name__ == "__main__":
    sys.exit(main())
