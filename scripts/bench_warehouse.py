"""A warehouse-scale map in SE(2): one prepared C-space, many queries, against OMPL with coal.

The map and the pairs come from scripts/make_warehouse_map.py (2000 x 2000 cells of 5 cm:
offices, racks and aisles, docks; a 0.62 x 0.9 m rectangular footprint; seeded start/goal poses
free with a margin), written to a temporary folder.

- preparation: the map imported (``cspace.io.importers.imported``, the default tolerance), the SE(2)
  C-space built (``planners.core.plan.build_cspace``) with all its slabs, the POSSIBLE regions
  that the proof before sampling reads, and the first slabs' FREE regions, meshes and links that
  the exact planner reads first (``planners.core.exact_se2.prepare``).
- ours, RRTConnect: every pair planned on that one prepared C-space (seed = the pair's index):
  the CPU time to its first certified path, the proof before sampling included
  (``se2_peers.ours_first``).
- ours, exact: ``planners.plan(..., planner="exact", cspace=the prepared one)`` per pair (the
  slab graph: deterministic): ``PlanResult.first_path_cpu``, the CPU time from the call to its
  certified path re-verified by the motion validator.
- peer: OMPL's RRTConnect on the same state space (bounds and weights as ours), coal's
  DynamicAABBTree over the same convex obstacle pieces as prisms, the footprint's prism turned
  and moved to each state, and OMPL's default discrete motion check (1 % of the space's
  extent), seeded the same (``se2_peers.peer_first``), CPU time to its first path.

Per pair the methods run in turn (RRTConnect, exact, peer). Every returned path is judged by an
independent check on the grid: the occupied cells, merged into row runs as shapely boxes,
against the footprint swept between poses at most 1 cm and 0.5 deg apart (each step the hull
of the two footprints; a turn's sagitta is far below a cell). Targets (issue 35): preparation
<= 2 s; mean time to a certified path <= 100 ms and p95 <= 200 ms over the 100 pairs; 0
colliding paths of ours.

Cars (``--spaces`` reeds-shepp, dubins; turning radius ``--radius``): the same map and pairs, run
as scripts/bench_nav2.py runs Nav2's map (its ``prepare_space`` and ``run_space``): preparation
= the import, the C-space and what the default planner reads first on the map alone
(``planners.core.auto.prepare``: the proof's POSSIBLE regions; a Reeds-Shepp car's FREE at the
first slabs with room, and their links), counted; slabs and the other regions built on first use,
inside the queries that need them, and counted there; per pair ``plan()`` with the default planner
(``auto``), its unshortened first path, and OMPL + coal; each car path judged along its curves.
Targets (issue 47, "the same targets for cars": Reeds-Shepp and Dubins): preparation <= 2 s,
mean <= 45 ms, p95 <= 100 ms, every query answered (a path or a proof), 0 colliding.

Usage: python scripts/bench_warehouse.py [--pairs N] [--size CELLS] [--time S] [--planners A,B]
       [--spaces se2,reeds-shepp,dubins] [--radius R] [--no-peer] [--json FILE]
(--json is checked before any work and written atomically.)
"""
from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

import bench_nav2  # noqa: E402
import make_warehouse_map as wh  # noqa: E402
import se2_peers  # noqa: E402

L, W = wh.FOOTPRINT
POLYGON = [[-L / 2, -W / 2], [L / 2, -W / 2], [L / 2, W / 2], [-L / 2, W / 2]]


def grid_judge(img: np.ndarray):
    """``path -> bool`` (collides): the footprint swept along the path against the occupied cells."""
    import shapely

    n = img.shape[0]
    boxes = []
    occ = img != wh.FREE
    for r in range(n):  # row runs of occupied cells, y up
        row = occ[r]
        if not row.any():
            continue
        d = np.diff(np.concatenate([[0], row.astype(np.int8), [0]]))
        y0 = (n - 1 - r) * wh.RES
        for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)):
            boxes.append(shapely.box(a * wh.RES, y0, b * wh.RES, y0 + wh.RES))
    boxes = np.array(boxes, dtype=object)
    tree = shapely.STRtree(boxes)
    body = np.array(POLYGON)

    def at(x, y, t):
        c, s = math.cos(t), math.sin(t)
        return body @ np.array([[c, s], [-s, c]]) + (x, y)

    def collides(path) -> bool:
        for (x0, y0, t0), (x1, y1, t1) in zip(path[:-1], path[1:]):
            dt = math.remainder(t1 - t0, 2 * math.pi)  # OMPL turns the shorter way
            steps = max(1, int(math.ceil(max(math.hypot(x1 - x0, y1 - y0) / 0.01, abs(dt) / math.radians(0.5)))))
            prev = at(x0, y0, t0)
            for k in range(1, steps + 1):
                f = k / steps
                cur = at(x0 + f * (x1 - x0), y0 + f * (y1 - y0), t0 + f * dt)
                hull = shapely.MultiPoint(np.vstack([prev, cur])).convex_hull
                if len(tree.query(hull, predicate="intersects")):
                    return True
                prev = cur
        return False

    return collides


def pct(xs, q):
    return float(np.percentile(xs, q)) if xs else float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--size", type=int, default=2000, help="cells per side (5 cm each)")
    ap.add_argument("--time", type=float, default=10.0, help="time limit per query (s), both planners")
    ap.add_argument("--planners", default="RRTConnect,exact", help="ours: RRTConnect, exact or both")
    ap.add_argument("--spaces", default="se2,reeds-shepp,dubins", help="se2 (--planners), and cars (the default planner)")
    ap.add_argument("--radius", type=float, default=0.5, help="the cars' turning radius (m)")
    ap.add_argument("--no-peer", action="store_true", help="skip OMPL + coal")
    ap.add_argument("--json", help="write the figures as JSON")
    args = ap.parse_args(argv)
    mine = [m for m in args.planners.split(",") if m]
    if not mine or set(mine) - {"RRTConnect", "exact"}:
        ap.error(f"--planners: RRTConnect and/or exact, got {args.planners!r}")
    spaces = [s for s in args.spaces.split(",") if s]
    if not spaces or set(spaces) - {"se2", "reeds-shepp", "dubins"}:
        ap.error(f"--spaces: se2, reeds-shepp and/or dubins, got {args.spaces!r}")
    from benchutil import check_json, coal_peer, write_json

    check_json(args.json)  # (the map is written to a temporary folder: no input of the run's to protect)
    peer = coal_peer(not args.no_peer)
    out = {}
    with tempfile.TemporaryDirectory(prefix="warehouse-") as folder:
        yaml, qfile = wh.write(folder, args.size, 0, args.pairs)
        img = wh.warehouse(args.size, 0)
        if "se2" in spaces:
            out["se2"] = se2_run(args, mine, peer, yaml, qfile, img)
        cars = [s for s in spaces if s != "se2"]
        if cars:
            from cspace.io.load import read_toml

            pairs = [(tuple(q["start"]), tuple(q["goal"])) for q in read_toml(qfile)["queries"]]
            judge = bench_nav2.GridJudge(img != wh.FREE, wh.RES, (0.0, 0.0), POLYGON, args.radius)
        for space in cars:
            sc, cs, prep = bench_nav2.prepare_space(yaml, space, pairs[0], POLYGON, args.radius)
            prepare_regions(sc, cs, prep)
            print(f"[{space}, r = {args.radius:g} m] preparation {prep['cpu']:.2f} s CPU ({prep['wall']:.2f} s wall): "
                  f"import {prep['import_cpu']:.2f}, C-space {prep['cspace_cpu']:.2f} ({prep['pieces']} convex pieces, "
                  f"K = {prep['K']}), the default planner's first regions {prep['regions_cpu']:.2f} "
                  f"({prep['prepared']['regions']}); slabs and the other regions on first use, in the queries "
                  f"(target <= 2 s: {'met' if prep['cpu'] <= 2 else 'MISSED'})")
            out[space] = bench_nav2.run_space(space, sc, cs, prep, pairs, judge, peer, args.time)
    if args.json:
        write_json(args.json, out)
    return 0


def prepare_regions(sc, cs, prep: dict) -> None:
    """What the default planner reads first on this map alone (``planners.core.auto.prepare``),
    built once and added to the preparation's CPU and wall seconds (``regions_cpu``; ``prepared``:
    the regions then built, which the queries' count of regions built on first use leaves out)."""
    from planners.core.auto import prepare

    c0, w0 = time.process_time(), time.perf_counter()
    prepare(sc, cs)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    prep.update(regions_cpu=cpu, cpu=prep["cpu"] + cpu, wall=prep["wall"] + wall, prepared=bench_nav2.lazy_builds(cs))


def se2_run(args, mine: list, peer: bool, yaml: str, qfile: str, img: np.ndarray) -> dict:
    """SE(2): RRTConnect and/or exact on one prepared C-space (the module's notes), printed; the figures."""

    from cspace.io.importers.imported import ImportOptions, import_file
    from cspace.io.load import read_toml, scenario_from_dict
    from cspace.io.scenario.validate import with_queries
    from planners.core.exact_se2 import prepare
    from planners.core.plan import build_cspace

    qdata = read_toml(qfile)
    first = qdata["queries"][0]
    t0 = time.perf_counter()
    imp = import_file(yaml, ImportOptions(robot={"polygon": POLYGON}, start=tuple(first["start"]),
                                          goal=tuple(first["goal"])))
    sc = with_queries(scenario_from_dict(imp.data, yaml, space="se2"), qdata, qfile)
    t1 = time.perf_counter()
    cs = build_cspace(sc)
    t2 = time.perf_counter()
    for k in range(cs.slabs):
        cs.slab(k)
    t3 = time.perf_counter()
    regions_s = prepare(cs)  # the POSSIBLE regions the proof before sampling reads
    exact_s = prepare(cs, exact=True) if "exact" in mine else 0.0  # FREE, meshes, links
    t3 += regions_s + exact_s
    prep = {"import_s": t1 - t0, "cspace_s": t2 - t1, "slabs_s": t3 - t2 - regions_s - exact_s,
            "regions_s": regions_s, "exact_s": exact_s, "total_s": t3 - t0,
            "obstacle_pieces": len(cs.obstacle_pieces), "slabs": cs.slabs,
            "vertices": sum(len(o.polygon) for o in sc.obstacles)}
    print(f"map {args.size} x {args.size} cells; {prep['vertices']} obstacle vertices, {prep['obstacle_pieces']} "
          f"convex pieces; K = {cs.slabs}")
    print(f"preparation: import {prep['import_s']:.2f} s, C-space {prep['cspace_s']:.2f} s, all slabs "
          f"{prep['slabs_s']:.2f} s, proof regions {prep['regions_s']:.2f} s, exact's first slabs "
          f"{prep['exact_s']:.2f} s: {prep['total_s']:.2f} s (target <= 2 s: "
          f"{'met' if prep['total_s'] <= 2 else 'MISSED'})")
    judge = grid_judge(img)
    checker = se2_peers.coal_checker(cs.obstacle_pieces, cs.robot_pieces, sc.bounds) if peer else None
    from planners.core.plan import make_adapter

    adapter = make_adapter(sc, cs)
    ours = {m: {"first": [], "solved": 0, "colliding": 0} for m in mine}
    peer_first, peer_solved, peer_bad = [], 0, 0
    queries = sc.all_queries()
    for i, q in enumerate(queries):  # in turn: ours, then the peer, on the same pair and seed
        for m in mine:
            if m == "RRTConnect":
                path, cpu = se2_peers.ours_first(sc, cs, adapter, q, i, args.time)
            else:
                path, cpu = exact_first(sc, cs, q, args.time)
            if path is not None:
                ours[m]["solved"] += 1
                ours[m]["first"].append(cpu)
                ours[m]["colliding"] += judge(path)
        if peer:
            path, cpu = se2_peers.peer_first(adapter, checker, adapter.pose(q.start), adapter.pose(q.goal), i,
                                             args.time)
            if path is not None:
                peer_solved += 1
                peer_first.append(cpu)
                peer_bad += judge(path)
    n = len(queries)
    pm = statistics.mean(peer_first) if peer_first else float("nan")
    for m in mine:
        first, bad = ours[m]["first"], ours[m]["colliding"]
        mean_first = statistics.mean(first) if first else float("nan")
        ours[m].update(mean=mean_first, p95=pct(first, 95), median=pct(first, 50))
        print(f"ours, {m}: {ours[m]['solved']}/{n} solved; time to a certified path mean {mean_first * 1e3:.1f} ms, "
              f"p95 {pct(first, 95) * 1e3:.1f} ms, median {pct(first, 50) * 1e3:.1f} ms (CPU); colliding paths {bad}")
        met = ours[m]["solved"] == n and mean_first <= 0.1 and pct(first, 95) <= 0.2 and bad == 0
        print(f"  targets: all solved, mean <= 100 ms, p95 <= 200 ms, 0 colliding: {'met' if met else 'MISSED'}"
              + (f"; ours / coal, mean time to a (certified / first) path: {mean_first / pm:.2f}x" if peer else ""))
    if peer:
        print(f"OMPL + coal (discrete motion checks): {peer_solved}/{n} solved; first solution mean {pm * 1e3:.1f} ms, "
              f"p95 {pct(peer_first, 95) * 1e3:.1f} ms; colliding paths {peer_bad}")
    return {"prep": prep, "ours": ours,
            "peer": {"first": peer_first, "solved": peer_solved, "colliding": peer_bad} if peer else None}


def exact_first(sc, cs, q, limit: float):
    """The exact planner on the prepared C-space, one query: ``(path or None, CPU seconds from
    the call to its certified path)`` (``plan()``'s own stamp, unsimplified)."""
    import dataclasses

    from planners.core.plan import plan

    res = plan(dataclasses.replace(sc, start=q.start, goal=q.goal, queries=[]), planner="exact", time=limit,
               simplify=False, cspace=cs)
    return (res.path, res.first_path_cpu) if res.solved else (None, None)


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    os._exit(code)  # skip the bindings' "nanobind: leaked" report
