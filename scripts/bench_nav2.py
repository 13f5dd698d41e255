"""Nav2's planner benchmark map: one prepared C-space per space, 100 pose pairs, against OMPL with coal.

The map is navigation2's own (tools/planner_benchmarking/100by100_20.pgm + .yaml, Apache-2.0:
2000 x 2000 cells of 5 cm, 20 % blocked), read from the path given with ``--nav2`` (a
navigation2 checkout or the map's folder; never copied here). It is imported as a new user
would (``cspace.io.importers.imported``, the default tolerance) with a 0.6 x 0.5 m footprint.
The pairs are drawn as Nav2's tools/planner_benchmarking/metrics.py draws them (Python's
``random`` seeded 33; row and column ``randint(100, 2000 - 100)``, i.e. 5 m from the edges; x =
column x 5 cm, y = row x 5 cm; yaw ``uniform(0, 1) x 2 pi``; a goal more than 3 m from its
start), a pose kept where the footprint there is free (our C-space; Nav2 asks its costmap).

Per space (SE(2), Reeds-Shepp and Dubins with r = 0.4 m):

- preparation: what a user pays before the first query: the import and the C-space
  (``planners.core.plan.build_cspace``); CPU and wall. Nothing else is built ahead: the slabs
  are built on first use and the proof's POSSIBLE regions the first time a query needs the
  proof, both kept with the C-space, so that cost lands in the queries that ask for it, and is
  counted there (the lazy builds are reported beside).
- ours, plan(): ``planners.plan(..., cspace=the one C-space, seed=pair)`` with the default planner,
  as ``cspace plan`` runs it (``auto``: a slice of sampling, the slab graph or the proof where the
  slice fails, shortening, the clearance measure), the slabs and regions it builds included: CPU
  and wall of the whole call; "answered" = a certified path or a proof. The pairs are drawn
  with a second C-space of the same map (its slabs are not the measured one's).
- ours, first path: the default planner again on the pair (after plan(): the slabs it needs are
  built), unshortened as the peer's path is, no clearance measure
  (``se2_peers.ours_first(..., planner="auto")``): CPU.
- peer: OMPL's RRTConnect on the same state space, coal's DynamicAABBTree over the same convex
  obstacle pieces as prisms, OMPL's default discrete motion check, seeded the same
  (``se2_peers.peer_first``): CPU to its first path.

The methods run in turn on each pair. Every path is judged against the map's occupied cells
themselves (row runs as shapely boxes), not the import: the footprint swept between poses at
most 1 cm and 0.5 deg apart (hulls of consecutive placements); a car's curves placed by
``sweep_oracle.car_segment_placements`` (independent of cspace), hulls padded by the chord bound.
Targets (issue 47): preparation <= 2 s; SE(2), Reeds-Shepp and Dubins mean <= 45 ms, p95 <= 100
ms, every query answered (a path or a proof), 0 colliding. The machine may be shared: CPU time is the figure, wall beside.

Usage: python scripts/bench_nav2.py --nav2 DIR [--pairs N] [--spaces se2,reeds-shepp,dubins] [--time S]
       [--no-peer] [--quick] [--json FILE]
(``--nav2`` defaults to the environment's NAV2_DIR; with neither, nothing is run: the map is
another project's, never bundled. ``--quick``: 10 pairs, unless ``--pairs`` is given.)
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import os
import random
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

import se2_peers  # noqa: E402

MAP = "100by100_20"
FOOTPRINT = [[-0.3, -0.25], [0.3, -0.25], [0.3, 0.25], [-0.3, 0.25]]  # 0.6 x 0.5 m about its centre
RADIUS = 0.4  # the cars' turning radius (m)
SEED, SIDE, MIN_GAP = 33, 100, 3.0  # Nav2's metrics.py: seed(33), side_buffer = 100 cells, dist > 3.0


def find_map(path: str) -> str:
    """The map's YAML under ``path`` (a navigation2 checkout or the map's folder)."""
    for sub in ("", os.path.join("tools", "planner_benchmarking")):
        f = os.path.join(path, sub, MAP + ".yaml")
        if os.path.isfile(f):
            return f
    raise SystemExit(f"--nav2: no {MAP}.yaml in {path} or its tools/planner_benchmarking/")


def occupied(yaml_path: str):
    """(occupied cells as a bool image with row 0 at the top, resolution, origin) read from the
    map's YAML and PGM with the map_server rules (negate, occupied_thresh), written here."""
    meta = {}
    for line in open(yaml_path):
        if ":" in line:
            k, v = line.split(":", 1)
            meta[k.strip()] = v.strip()
    with open(os.path.join(os.path.dirname(yaml_path), meta["image"]), "rb") as fh:
        data = fh.read()
    head, pos = [], 0
    while len(head) < 4:  # P5, width, height, maxval (comments skipped)
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        head.append(data[pos:end])
        pos = end
    w, h, maxval = int(head[1]), int(head[2]), int(head[3])
    img = np.frombuffer(data, dtype=np.uint8, count=w * h, offset=pos + 1).reshape(h, w).astype(float)
    p = img / maxval if int(meta.get("negate", "0")) else (maxval - img) / maxval
    origin = [float(v) for v in meta["origin"].strip("[]").split(",")]
    return p > float(meta["occupied_thresh"]), float(meta["resolution"]), origin[:2]


class GridJudge:
    """The footprint swept along a path against occupied cells (an STRtree of row runs).
    ``occ``: a bool image, row 0 at the top; ``res``: the cell size; ``origin``: the lower-left
    corner; ``footprint``: the robot's polygon about its reference point; ``radius``: a car's."""

    def __init__(self, occ: np.ndarray, res: float, origin, footprint=FOOTPRINT, radius: float = RADIUS):
        import shapely

        n = occ.shape[0]
        boxes = []
        for r in range(n):  # row runs of occupied cells, y up
            d = np.diff(np.concatenate([[0], occ[r].astype(np.int8), [0]]))
            y0 = origin[1] + (n - 1 - r) * res
            for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)):
                boxes.append(shapely.box(origin[0] + a * res, y0, origin[0] + b * res, y0 + res))
        self.tree = shapely.STRtree(np.array(boxes, dtype=object))
        self.body = shapely.Polygon(footprint)
        self.corners = np.asarray(footprint, dtype=float)
        self.radius = float(radius)

    def clear(self, pose, grow: float) -> bool:
        """The footprint at ``pose``, grown by ``grow``, meets no occupied cell."""
        from shapely import affinity

        x, y, t = pose
        placed = affinity.translate(affinity.rotate(self.body, t, origin=(0, 0), use_radians=True), x, y)
        return not len(self.tree.query(placed.buffer(grow), predicate="intersects"))

    def chain_hits(self, corners: np.ndarray, pad: float = 0.0) -> bool:
        """``corners`` (n, m, 2): n placements of the footprint; does the hull of any two
        consecutive ones (grown by ``pad``) meet an occupied cell? (one vectorised query)"""
        import shapely

        if len(corners) < 2:
            corners = np.concatenate([corners, corners])
        pairs = np.concatenate([corners[:-1], corners[1:]], axis=1)
        n, m = pairs.shape[:2]
        hulls = shapely.convex_hull(shapely.multipoints(pairs.reshape(-1, 2), indices=np.repeat(np.arange(n), m)))
        if pad:
            hulls = shapely.buffer(hulls, pad)
        return bool(len(self.tree.query(hulls, predicate="intersects")[0]))

    def se2(self, path) -> bool:
        """Collides: OMPL's SE(2) interpolation (x, y linear, the shorter turn), hulls of placements
        at most 1 cm and 0.5 deg apart."""
        for (x0, y0, t0), (x1, y1, t1) in zip(path[:-1], path[1:]):
            dt = math.remainder(t1 - t0, 2 * math.pi)
            steps = max(1, math.ceil(max(math.hypot(x1 - x0, y1 - y0) / 0.01, abs(dt) / math.radians(0.5))))
            f = np.arange(steps + 1) / steps
            t = t0 + f * dt
            c, s = np.cos(t)[:, None], np.sin(t)[:, None]
            bx, by = self.corners[None, :, 0], self.corners[None, :, 1]
            xs = x0 + f[:, None] * (x1 - x0) + bx * c - by * s
            ys = y0 + f[:, None] * (y1 - y0) + bx * s + by * c
            if self.chain_hits(np.stack([xs, ys], axis=2)):
                return True
        return False

    def car(self, path, segments_of) -> bool:
        """Collides: the footprint along each motion's curve segments (placements by sweep_oracle)."""
        import shapely
        from sweep_oracle import car_segment_placements

        for a, b in zip(path[:-1], path[1:]):
            pose = tuple(float(v) for v in a)
            for kind, length in segments_of(tuple(a), tuple(b)):
                places, end, pad = car_segment_placements(self.body, pose, kind, length, self.radius,
                                                          math.radians(0.5), 0.01)
                corners = shapely.get_coordinates(np.array(places, dtype=object)).reshape(len(places), -1, 2)
                if self.chain_hits(corners, pad):
                    return True
                pose = end
        return False


def draw_pairs(free, n: int, size: int, res: float, origin) -> list:
    """Nav2's metrics.py getRandomStart / getRandomGoal, a pose kept where ``free(pose)``."""
    rng = random.Random(SEED)

    def pose():
        while True:
            row, col = rng.randint(SIDE, size - SIDE), rng.randint(SIDE, size - SIDE)
            yaw = math.remainder(rng.uniform(0, 1) * 2 * math.pi, 2 * math.pi)
            p = (origin[0] + col * res, origin[1] + row * res, yaw)
            if free(p):
                return p

    pairs = []
    while len(pairs) < n:
        s = pose()
        while True:
            g = pose()
            if math.hypot(g[0] - s[0], g[1] - s[1]) > MIN_GAP:
                break
        pairs.append((s, g))
    return pairs


def pct(xs, q):
    return float(np.percentile(xs, q)) if xs else float("nan")


def prepare_space(yaml_path: str, space: str, first, footprint=FOOTPRINT, radius: float = RADIUS):
    """The imported scenario (``first``: its start and goal, a map has none; a car turns with
    ``radius``), its C-space, and the preparation's CPU and wall seconds."""
    from cspace.io.importers.imported import ImportOptions, import_file
    from cspace.io.load import scenario_from_dict
    from planners.core.plan import build_cspace

    c0, w0 = time.process_time(), time.perf_counter()
    imp = import_file(yaml_path, ImportOptions(robot={"polygon": footprint}, start=first[0], goal=first[1]))
    sc = scenario_from_dict(imp.data, yaml_path, space=space, turning_radius=None if space == "se2" else radius)
    c1 = time.process_time()
    cs = build_cspace(sc)  # its slabs and the proof's regions: on first use, inside the queries
    c2, w2 = time.process_time(), time.perf_counter()
    return sc, cs, {"import_cpu": c1 - c0, "cspace_cpu": c2 - c1, "cpu": c2 - c0, "wall": w2 - w0,
                    "pieces": len(cs.obstacle_pieces), "K": cs.slabs, "vertices": sum(len(o.polygon) for o in sc.obstacles)}


def lazy_builds(cs, before: dict | None = None) -> dict:
    """What the queries built on first use: the slabs (count, seconds) and the proof's regions
    (less ``before``: what a preparation built, as this returned it then)."""
    from planners.core.exact_se2 import built_regions

    n, seconds = cs.slabs_built()
    out = {"slabs": n, "slab_s": seconds, **built_regions(cs)}
    return {k: v - (before or {}).get(k, 0) for k, v in out.items()}


def run_space(space: str, sc, cs, prep: dict, pairs: list, judge: GridJudge, peer: bool, limit: float) -> dict:
    """The pairs planned in turn on one C-space (``prep``: its preparation): ``plan()`` with the
    default planner, the default planner's first path, OMPL + coal; every path judged on the
    grid; the figures printed and returned. (Shared with scripts/bench_warehouse.py's cars.)"""
    from planners.core.plan import make_adapter, plan

    adapter = make_adapter(sc, cs)
    car = space != "se2"
    collides = (lambda p: judge.car(p, adapter.segments)) if car else judge.se2
    checker = se2_peers.coal_checker(cs.obstacle_pieces, cs.robot_pieces, sc.bounds) if peer else None
    rows = {"plan": {"cpu": [], "wall": [], "answered": 0, "solved": 0, "colliding": 0},
            "first": {"cpu": [], "solved": 0, "colliding": 0},
            "peer": {"cpu": [], "solved": 0, "colliding": 0}}
    for i, (s, g) in enumerate(pairs):
        q = dataclasses.replace(sc, start=s, goal=g, queries=[])
        c0, w0 = time.process_time(), time.perf_counter()
        r = plan(q, cspace=cs, seed=i, time=limit)
        row = rows["plan"]
        row["cpu"].append(time.process_time() - c0)
        row["wall"].append(time.perf_counter() - w0)
        row["answered"] += r.solved or r.proven_unsolvable
        row.setdefault("by", []).append(r.answered_by)
        if r.solved:
            row["solved"] += 1
            row["colliding"] += collides(r.path)
        path, cpu = se2_peers.ours_first(sc, cs, adapter, q.all_queries()[0], i, limit, planner="auto")
        rows["first"]["cpu"].append(cpu)
        if path is not None:
            rows["first"]["solved"] += 1
            rows["first"]["colliding"] += collides(path)
        if peer:
            path, cpu = se2_peers.peer_first(adapter, checker, adapter.pose(s), adapter.pose(g), i, limit)
            rows["peer"]["cpu"].append(cpu)
            if path is not None:
                rows["peer"]["solved"] += 1
                bad = collides(path)
                rows["peer"]["colliding"] += bad
                if not bad:
                    rows["peer"].setdefault("sound", []).append(cpu)
    n = len(pairs)
    p = rows["plan"]
    mean, p95 = statistics.mean(p["cpu"]), pct(p["cpu"], 95)
    checks = {"preparation <= 2 s": prep["cpu"] <= 2, "mean <= 45 ms": mean <= 0.045, "p95 <= 100 ms": p95 <= 0.1,
              "all answered": p["answered"] == n, "0 colliding": p["colliding"] == 0}
    met = "; ".join(f"{k} {'met' if v else 'MISSED'}" for k, v in checks.items())
    lazy = lazy_builds(cs, prep.get("prepared"))
    print(f"  ours, plan() (default planner): {p['answered']}/{n} answered ({p['solved']} paths); CPU mean "
          f"{mean * 1e3:.1f} ms, p95 {p95 * 1e3:.1f} ms, median {pct(p['cpu'], 50) * 1e3:.1f} ms (wall mean "
          f"{statistics.mean(p['wall']) * 1e3:.1f} ms, p95 {pct(p['wall'], 95) * 1e3:.1f} ms); colliding {p['colliding']}"
          + f"\n  built on first use inside these queries (counted in them): {lazy['slabs']} of {cs.slabs} slabs "
            f"({lazy['slab_s']:.2f} s wall), the slab graph's FREE and POSSIBLE regions (the proof's among them): "
            f"{lazy['regions']} ({lazy['region_s']:.2f} s wall)"
          + f"\n  targets (CPU): {met}")  # (a Dubins car's too: issue 47's "the same targets for cars")
    f = rows["first"]
    print(f"  ours, first certified path (the default planner again, unshortened, after plan(): its slabs built): "
          f"{f['solved']}/{n}; CPU mean "
          f"{statistics.mean(f['cpu']) * 1e3:.1f} ms, p95 {pct(f['cpu'], 95) * 1e3:.1f} ms; colliding {f['colliding']}")
    if peer:
        e = rows["peer"]
        sound = e.get("sound", [])
        sm = statistics.mean(sound) if sound else float("nan")
        print(f"  OMPL + coal (RRTConnect, discrete checks): {e['solved']}/{n} paths, {e['colliding']} colliding; "
              f"its {len(sound)} sound runs: CPU mean {sm * 1e3:.1f} ms, p95 {pct(sound, 95) * 1e3:.1f} ms (all runs: "
              f"mean {statistics.mean(e['cpu']) * 1e3:.1f} ms); ours / coal's sound runs, mean: first path "
              f"{statistics.mean(f['cpu']) / sm:.2f}x, plan() {mean / sm:.2f}x")
    return {"prep": prep, "lazy": lazy, **rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nav2", default=os.environ.get("NAV2_DIR"),
                    help="a navigation2 checkout, or the folder of 100by100_20.yaml (default: $NAV2_DIR)")
    ap.add_argument("--pairs", type=int, help="pose pairs (default 100)")
    ap.add_argument("--quick", action="store_true", help="10 pairs (unless --pairs is given)")
    ap.add_argument("--spaces", default="se2,reeds-shepp,dubins")
    ap.add_argument("--time", type=float, default=10.0, help="time limit per query (s), every method")
    ap.add_argument("--no-peer", action="store_true", help="skip OMPL + coal")
    ap.add_argument("--json", help="write the figures as JSON")
    args = ap.parse_args(argv)
    spaces = [s for s in args.spaces.split(",") if s]
    if not spaces or set(spaces) - {"se2", "reeds-shepp", "dubins"}:
        ap.error(f"--spaces: se2, reeds-shepp and/or dubins, got {args.spaces!r}")
    if not args.nav2:
        print("Nav2's map not given (--nav2 DIR or NAV2_DIR: a navigation2 checkout): nothing run")
        return 0
    if args.pairs is None:
        args.pairs = 10 if args.quick else 100
    yaml_path = find_map(args.nav2)
    from benchutil import check_json, coal_peer, write_json

    check_json(args.json, [os.path.dirname(yaml_path)])  # (never over the map's files)

    peer = coal_peer(not args.no_peer)
    from planners.core.plan import build_cspace

    occ, res, origin = occupied(yaml_path)
    judge = GridJudge(occ, res, origin)
    out = {}
    # The import needs a start and a goal: the first pair drawn where the footprint grown by the
    # import's tolerance (0.1 m) meets no occupied cell.
    first = draw_pairs(lambda p: judge.clear(p, 0.15), 1, occ.shape[0], res, origin)[0]
    pairs = None
    for space in spaces:
        sc, cs, prep = prepare_space(yaml_path, space, first)
        print(f"[{space}] {MAP}: {prep['vertices']} obstacle vertices, {prep['pieces']} convex pieces, K = {prep['K']}; "
              f"preparation {prep['cpu']:.2f} s CPU ({prep['wall']:.2f} s wall): import {prep['import_cpu']:.2f}, "
              f"C-space {prep['cspace_cpu']:.2f}; slabs and proof regions on first use, in the queries "
              f"(target <= 2 s: {'met' if prep['cpu'] <= 2 else 'MISSED'})")
        if pairs is None:  # free poses of a second C-space: the measured one builds only what the queries ask
            probe = build_cspace(dataclasses.replace(sc, space="se2", turning_radius=None))
            pairs = draw_pairs(probe.is_free, args.pairs, occ.shape[0], res, origin)
            del probe
        out[space] = run_space(space, sc, cs, prep, pairs, judge, peer, args.time)
    if args.json:
        write_json(args.json, out)
    return 0


if __name__ == "__main__":
    code = main()
    sys.stdout.flush()
    os._exit(code)  # skip the bindings' "nanobind: leaked" report
