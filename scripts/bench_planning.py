"""Planning against peers: the same OMPL planner, four collision checkers, one run.

Each bundled translation scene that has a path (``scenarios/*.toml`` and
``scenarios/ompl/*.toml``; SE(2) scenes are ``bench_se2.py``'s, and scenes the exact
planner proves unsolvable are skipped) is planned with OMPL's RRTConnect and RRTstar
over 10 seeds by

- **ours**: the planning routine of ``cspace plan`` (:func:`planners.core.routine.run_planner`
  over :class:`planners.adapters.translation.TranslationSpace`): the C-space's exact point test and
  its exact segment test as OMPL's motion validator;
- **shapely**: a state checker that translates the robot to the state
  (``shapely.transform``) and asks an ``STRtree`` of the obstacles for an intersecting
  one, with OMPL's default ``DiscreteMotionValidator`` (states 1 % of the space's
  extent apart);
- **coal**: coal's convex shapes (our convex pieces of the obstacles and of the robot,
  as prisms ``coal.Convex``), the obstacles in a ``DynamicAABBTreeCollisionManager``,
  the robot's pieces moved to the state (``setTranslation``) and collided against
  it; the same discrete motion checking;
- **coal-fine**: the same coal checker, with the discrete motion checking at a
  resolution that cannot step over the thinnest obstacle (:func:`fine_spacing`:
  checked states at most half the narrowest C-obstacle piece's width bound apart,
  the minimum width of our convex obstacle pieces plus that of the robot's pieces;
  never coarser than OMPL's default). A motion that crosses an obstacle from side
  to side puts a checked state inside it, but this is still a sampled check: a
  motion that clips a corner can pass between two checked states.

The peers run through the same routine (their adapters only swap the state checker
and the motion validator, and accept OMPL's path as it is), seeded alike, so the
planners draw the same samples until the checkers disagree. Anytime planners stop at
their first solution (``until_first``: OMPL's cost threshold). Runs are interleaved
(seed-major, the checkers' order rotated per seed).

A run *solves* only when its returned path is collision-free: every returned path is
judged exactly by our certified segment test (:func:`colliding_exact`: does the swept
robot meet an obstacle?). Reported per scene, planner and checker (:func:`summarize`):
``check step`` (the spacing of the states the motion checks test; ``exact`` for ours);
``returned`` (runs that returned a path), ``valid`` (those whose path is free: the
solved runs), ``colliding`` (returned paths that meet an obstacle) and ``shapely says``
(the same count by shapely, independently: the hull of each convex robot piece at both
ends of each segment, which for a translation *is* the swept piece); over the valid
runs only, the median time to the first solution, wall and CPU (from the call of the
routine, so setting up OMPL's objects counts; the checker's one-off preparation -- our
C-space build, the STRtree, coal's shapes, coal-fine's widths -- is the ``prep``
column), and the median path length. ``ours/coal`` and ``ours/coal-fine`` are the
ratios of the median wall times (target against coal: <= 1.0), given only where both
checkers have at least one valid run; where the peer has none, the cell says so
(e.g. ``coal: 0/10 valid (10 colliding)``) instead of a ratio (:func:`ratio_cell`).

Usage: python scripts/bench_planning.py [--quick] [--seeds N] [--time S] [--scenes a,b] [--out-json FILE]
(--out-json is checked before any work, never over a bundled scenario, and written atomically.)
"""
from __future__ import annotations

import argparse
import glob
import math
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)
sys.path.insert(0, HERE)  # se2_peers

from cspace.translation.cspace import CSpace, decompose_obstacles, decompose_robot  # noqa: E402
from cspace.io.load import load_scenario  # noqa: E402
from planners.core.routine import run_planner  # noqa: E402
from planners.adapters.translation import TranslationSpace  # noqa: E402
from se2_peers import prism  # noqa: E402  (coal's prisms, shared with the SE(2) benches)

PLANNERS = ("RRTConnect", "RRTstar")
CHECKERS = ("ours", "shapely", "coal", "coal-fine")  # the coals only when installed (pip install -e ".[bench]")
QUICK_SCENES = ("maze", "office", "env1")


# ---------------------------------------------------------------- peers

class PeerSpace(TranslationSpace):
    """A translation adapter whose states are judged by a peer checker, its motions by
    OMPL's default discrete validator, and whose paths are accepted as OMPL returns them
    (the peers have no exact motion test: that is the point of the comparison)."""

    def __init__(self, cspace, checker, spacing: float | None = None):
        super().__init__(cspace, 0)
        self.checker = checker
        self.spacing = spacing  # of the checked states along a motion; None: OMPL's 1 % of the extent

    def validity(self):
        return self.checker

    def motion_validator(self, si):
        if self.spacing is not None:
            # OMPL's resolution is a fraction of the space's maximum extent (the diagonal
            # of the bounds); its DiscreteMotionValidator then checks states at most
            # fraction * extent apart along each motion.
            si.setStateValidityCheckingResolution(self.spacing / si.getMaximumExtent())
        return si.getMotionValidator()  # OMPL's default: the DiscreteMotionValidator

    def verify(self, path, start, goal):
        ok = len(path) >= 2 and tuple(path[0]) == tuple(map(float, start)) and tuple(path[-1]) == tuple(map(float, goal))
        return ok, "accepted by the peer's own checks" if ok else "path does not run from start to goal"

    def counts(self):
        return 0, 0


def shapely_checker(sc):
    """``state -> bool``: the robot translated to the state, an STRtree of the obstacles."""
    import shapely

    obstacles = [o.to_shapely() for o in sc.obstacles]
    tree = shapely.STRtree(obstacles)
    body = shapely.union_all([shapely.Polygon(r.polygon) for r in sc.robot]) if sc.robot else shapely.Point(0, 0)
    xmin, xmax, ymin, ymax = sc.bounds
    query, transform, point = tree.query, shapely.transform, shapely.Point

    def is_valid(s) -> bool:
        x, y = s[0], s[1]
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        moved = transform(body, lambda c: c + (x, y)) if sc.robot else point(x, y)
        return not len(query(moved, predicate="intersects"))

    return is_valid


def coal_available() -> bool:
    """Whether coal (the ``bench`` extra) can be imported."""
    try:
        import coal  # noqa: F401
    except ImportError:
        return False
    return True


def convex_pieces(sc) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Our convex pieces of the scene: (obstacle pieces, robot pieces; none for a point)."""
    opieces, _owner, _n = decompose_obstacles([o.polygon for o in sc.obstacles], [o.holes for o in sc.obstacles])
    rpieces = decompose_robot([r.polygon for r in sc.robot], sc.robot_kind == "disk")[0] if sc.robot else []
    return opieces, rpieces


def coal_checker(sc):
    """``state -> bool``: our convex pieces as coal prisms, obstacles in coal's AABB tree."""
    import coal

    opieces, rpieces = convex_pieces(sc)
    manager = coal.DynamicAABBTreeCollisionManager()
    keep = []  # coal's objects hold the geometries by reference
    for p in opieces:
        obj = coal.CollisionObject(prism(p), coal.Transform3s())
        keep.append(obj)
        manager.registerObject(obj)
    manager.setup()
    if rpieces:
        robot = [coal.CollisionObject(prism(p), coal.Transform3s()) for p in rpieces]
    else:
        robot = [coal.CollisionObject(coal.Sphere(0.0), coal.Transform3s())]
    callback = coal.CollisionCallBackDefault()
    data = callback.data
    xmin, xmax, ymin, ymax = sc.bounds
    collide = manager.collide

    def is_valid(s) -> bool:
        x, y = s[0], s[1]
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        t = np.array([x, y, 0.0])
        for obj in robot:
            obj.setTranslation(t)
            obj.computeAABB()
            data.result.clear()
            data.done = False
            collide(obj, callback)
            if data.result.isCollision():
                return False
        return True

    is_valid.keep = (manager, keep, robot, callback)
    return is_valid


def polygon_width(poly: np.ndarray) -> float:
    """The width of a convex polygon: its narrowest slab, i.e. the minimum over its edges
    of the largest distance of a vertex from the edge's line (a convex polygon's minimum
    width is attained with one side of the slab on an edge)."""
    p = np.asarray(poly, dtype=np.float64)
    d = np.roll(p, -1, axis=0) - p  # edge i runs from vertex i to vertex i + 1
    lengths = np.hypot(d[:, 0], d[:, 1])
    keep = lengths > 0  # repeated vertices make no edge
    # |cross(edge, vertex - edge start)| / |edge|: every vertex's distance from every edge's line.
    rel = p[None, :, :] - p[keep][:, None, :]
    dist = np.abs(d[keep][:, None, 0] * rel[:, :, 1] - d[keep][:, None, 1] * rel[:, :, 0]) / lengths[keep][:, None]
    return float(dist.max(axis=1).min()) if keep.any() else 0.0


def fine_spacing(sc) -> float | None:
    """The spacing of checked states for ``coal-fine``: half the narrowest C-obstacle piece
    we can bound, ``(min obstacle piece width + min robot piece width) / 2`` (None: no
    obstacle, nothing to resolve).

    A C-obstacle piece is an obstacle piece O plus a reflected robot piece -R; the widths
    of convex sets add under the Minkowski sum (their support functions do), so its width
    is at least w(O) + w(R) >= the two minima (a point robot adds 0). A segment that
    crosses such a slab from side to side runs at least its width inside it, so states at
    most half of it apart put one state inside. A segment that only clips a corner runs
    less than that inside: this is still a sampled check."""
    opieces, rpieces = convex_pieces(sc)
    widths = [w for w in map(polygon_width, opieces) if w > 0]  # a flat piece: nothing to sample
    if not widths:
        return None
    robot = min((polygon_width(p) for p in rpieces), default=0.0)
    return 0.5 * (min(widths) + robot)


# ---------------------------------------------------------------- judges

def colliding_exact(cs: CSpace, path: np.ndarray) -> bool:
    """Whether the path's swept robot meets an obstacle: our certified segment test."""
    return not all(cs.segment_free(tuple(a), tuple(b)) for a, b in zip(path[:-1].tolist(), path[1:].tolist()))


def shapely_judge(sc):
    """``path -> bool``: shapely's independent sweep (hull of each convex robot piece at
    both ends of each segment, which is the piece's swept region for a translation)."""
    import shapely
    from shapely.prepared import prep

    union = shapely.union_all([o.to_shapely() for o in sc.obstacles]) if sc.obstacles else shapely.Polygon()
    obs = prep(union) if not union.is_empty else None
    pieces = decompose_robot([r.polygon for r in sc.robot], sc.robot_kind == "disk")[0] if sc.robot else []

    def collides(path: np.ndarray) -> bool:
        if obs is None:
            return False
        for a, b in zip(path[:-1], path[1:]):
            if not pieces:
                if obs.intersects(shapely.LineString([a, b]) if (a != b).any() else shapely.Point(a)):
                    return True
                continue
            for p in pieces:
                if obs.intersects(shapely.MultiPoint(np.vstack([p + a, p + b])).convex_hull):
                    return True
        return False

    return collides


# ---------------------------------------------------------------- runs

def scenes(names=None) -> list[str]:
    """The bundled translation scenes (optionally only ``names``, by file stem)."""
    paths = sorted(glob.glob(os.path.join(ROOT, "scenarios", "*.toml"))) + \
        sorted(glob.glob(os.path.join(ROOT, "scenarios", "ompl", "*.toml")))
    out = []
    for p in paths:
        stem = os.path.splitext(os.path.basename(p))[0]
        if names and stem not in names:
            continue
        if load_scenario(p).space != "se2":
            out.append(p)
    return out


def unsolvable(sc, cs) -> bool:
    """Proven unsolvable by the exact planner (2 s; undecided counts as solvable)."""
    from cspace.paths.shortest import shortest_path

    return bool(shortest_path(cs.pieces, cs.bounds, sc.start[:2], sc.goal[:2], time_limit=2.0).proven_unsolvable)


def one_run(space, planner: str, seed: int, start, goal, time_limit: float) -> dict:
    """One plan through the routine: the times of the first solution (wall, CPU) from the call."""
    mark = {}
    w0, c0 = time.perf_counter(), time.process_time()

    def first(t, length):
        mark.setdefault("wall", time.perf_counter() - w0)
        mark.setdefault("cpu", time.process_time() - c0)

    res = run_planner(space, planner, [(start, goal)], time_limit, seed, on_progress=first, until_first=True)[0]
    found = res.first_solution is not None or bool(res.solved)
    return {"solved": bool(found and len(res.path) >= 2), "wall": mark.get("wall"), "cpu": mark.get("cpu"),
            "length": res.length if res.solved else None, "path": res.path if res.solved else None}


def _median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def summarize(rs: list[dict], collides, judge) -> dict:
    """One table row's numbers from the runs of one scene, planner and checker.

    A run *returned* a path when the planner reported one; the path is *valid* when
    ``collides(path)`` (the exact judge, :func:`colliding_exact`) finds it free; only
    valid runs are solutions, so the times and lengths are medians over them. The raw
    counts stay visible: ``returned``, ``colliding`` (exact) and ``shapely says`` (the
    independent judge), over every returned path."""
    returned = [r for r in rs if r["solved"]]
    bad = [bool(collides(r["path"])) for r in returned]
    valid = [r for r, b in zip(returned, bad) if not b]
    return {"returned": f"{len(returned)}/{len(rs)}", "valid": f"{len(valid)}/{len(rs)}",
            "colliding": sum(bad), "shapely says": sum(bool(judge(r["path"])) for r in returned),
            "first wall ms": _ms(_median([r["wall"] for r in valid])),
            "first cpu ms": _ms(_median([r["cpu"] for r in valid])),
            "length": _median([r["length"] for r in valid])}


def _count(frac: str) -> int:
    """The numerator of a ``"k/n"`` count."""
    return int(frac.split("/")[0])


def ratio_cell(ours: dict, peer: dict, who: str):
    """``ours/peer`` of the median wall times to a first valid solution, only where both
    have at least one valid run; otherwise a sentence saying who has none (a peer that
    only returned colliding paths has no time to compare with)."""
    if _count(peer["valid"]) and _count(ours["valid"]):
        return ours["first wall ms"] / peer["first wall ms"]
    none = [f"ours: {ours['valid']} valid"] if not _count(ours["valid"]) else []
    if not _count(peer["valid"]):
        none.append(f"{who}: {peer['valid']} valid ({peer['colliding']} colliding)")
    return "; ".join(none)


def prepare(names) -> list[tuple]:
    """Each solvable scene with its checkers' adapters, their preparation times and the
    shapely judge: ``(name, scenario, cspace, spaces, prep, step, judge)``."""
    prepared = []
    for path in scenes(names):
        sc = load_scenario(path)
        t = time.perf_counter()
        cs = CSpace.from_scenario(sc)
        prep = {"ours": time.perf_counter() - t}
        if unsolvable(sc, cs):
            print(f"skip {sc.name}: proven unsolvable", file=sys.stderr)
            continue
        xmin, xmax, ymin, ymax = sc.bounds
        step = {"ours": "exact", "shapely": 0.01 * math.hypot(xmax - xmin, ymax - ymin)}  # OMPL's default
        t = time.perf_counter()
        spaces = {"ours": TranslationSpace(cs), "shapely": PeerSpace(cs, shapely_checker(sc))}
        prep["shapely"] = time.perf_counter() - t
        if coal_available():
            t = time.perf_counter()
            spaces["coal"] = PeerSpace(cs, coal_checker(sc))
            prep["coal"] = time.perf_counter() - t
            step["coal"] = step["shapely"]
            t = time.perf_counter()
            fine = fine_spacing(sc)
            step["coal-fine"] = step["coal"] if fine is None else min(fine, step["coal"])  # never coarser
            spaces["coal-fine"] = PeerSpace(cs, coal_checker(sc), step["coal-fine"])
            prep["coal-fine"] = time.perf_counter() - t
        rel = os.path.relpath(path, os.path.join(ROOT, "scenarios"))
        prepared.append((os.path.splitext(rel)[0], sc, cs, spaces, prep, step, shapely_judge(sc)))
    return prepared


def run_all(prepared, checkers, planners, seeds: int, tlim: float) -> dict:
    """Every run, interleaved: seed-major, the checkers' order rotated per seed (so that no
    checker always runs first on a warm or cold machine). ``{(scene, planner, checker): [run]}``"""
    from benchutil import Progress

    runs: dict = {}
    progress = Progress(f"bench_planning: {seeds} seeds x {len(prepared)} scenes x {len(planners)} planners x "
                        f"{len(checkers)} checkers, interleaved", seeds * len(prepared) * len(planners) * len(checkers),
                        most_s=tlim)
    for seed in range(seeds):
        order = checkers[seed % len(checkers):] + checkers[:seed % len(checkers)]
        for name, sc, _cs, spaces, *_ in prepared:
            start, goal = (float(sc.start[0]), float(sc.start[1])), (float(sc.goal[0]), float(sc.goal[1]))
            for planner in planners:
                for who in order:
                    runs.setdefault((name, planner, who), []).append(one_run(spaces[who], planner, seed, start, goal, tlim))
                    progress.step(f"seed {seed}, {name}, {planner}, {who}")
    return runs


def table_rows(prepared, runs, checkers, planners) -> list[dict]:
    """The table: one row per scene, planner and checker; the ratios on the ``ours`` row."""
    rows = []
    for name, _sc, cs, _spaces, prep, step, judge in prepared:
        for planner in planners:
            group = {}
            for who in checkers:
                row = {"scene": name, "planner": planner, "checker": who, "check step": step[who]}
                row.update(summarize(runs[(name, planner, who)], lambda p: colliding_exact(cs, p), judge))
                row["prep ms"] = _ms(prep[who])
                group[who] = row
            for peer in ("coal", "coal-fine"):
                for who, row in group.items():
                    row[f"ours/{peer}"] = ratio_cell(group["ours"], group[peer], peer) \
                        if who == "ours" and peer in group else None
            rows += group.values()
    return rows


def report(rows: list[dict], checkers) -> list[str]:
    """The lines under the table: the ratios against coal, where coal has no valid run,
    and the colliding paths per checker."""
    out = []
    for peer in ("coal", "coal-fine"):
        key = f"ours/{peer}"
        both = [r for r in rows if r["checker"] == "ours" and isinstance(r.get(key), float)]
        if both:
            worst = max(both, key=lambda r: r[key])
            losing = [f"{r['scene']}/{r['planner']} {r[key]:.2f}x" for r in both if r[key] > 1.0]
            out.append(f"{key} (median wall to first valid solution, where both have one): worst "
                       f"{worst[key]:.2f}x ({worst['scene']}, {worst['planner']}); above 1.0x on "
                       f"{len(losing)} of {len(both)}: {', '.join(losing) or 'none'}")
        apart = [f"{r['scene']}/{r['planner']} ({r[key]})" for r in rows
                 if r["checker"] == "ours" and isinstance(r.get(key), str)]
        if apart:
            out.append(f"{key} not compared (no valid run on one side): {', '.join(apart)}")
    total = {w: sum(r["colliding"] for r in rows if r["checker"] == w) for w in checkers}
    out.append("colliding paths returned: " + ", ".join(f"{w} {n}" for w, n in total.items()))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help=f"scenes {', '.join(QUICK_SCENES)}, RRTConnect, 3 seeds, 5 s")
    ap.add_argument("--seeds", type=int, default=None)
    ap.add_argument("--time", type=float, default=None, help="time limit per run, seconds (default 10)")
    ap.add_argument("--scenes", default=None, help="comma-separated scene stems")
    ap.add_argument("--planners", default=None)
    ap.add_argument("--out-json", default=None)
    args = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(args.out_json, [os.path.join(ROOT, "scenarios"), os.path.join(ROOT, "scenarios", "ompl")],
               "--out-json")  # (never over a scene)
    names = set(args.scenes.split(",")) if args.scenes else (set(QUICK_SCENES) if args.quick else None)
    seeds = args.seeds or (3 if args.quick else 10)
    tlim = args.time or (5.0 if args.quick else 10.0)
    planners = args.planners.split(",") if args.planners else (["RRTConnect"] if args.quick else list(PLANNERS))

    prepared = prepare(names)
    checkers = CHECKERS if coal_available() else CHECKERS[:2]
    if len(checkers) < len(CHECKERS):
        print("coal is not installed (pip install -e '.[bench]'): its columns are left out", file=sys.stderr)
    rows = table_rows(prepared, run_all(prepared, checkers, planners, seeds, tlim), checkers, planners)
    print(f"Time to first valid solution, {seeds} seeds, {tlim:g} s limit.\n"
          "returned = runs that returned a path; valid = those whose path is collision-free by our exact segment\n"
          "test, the only runs counted as solved (times and lengths are medians over them); colliding = returned\n"
          "paths whose swept robot meets an obstacle (exact; 'shapely says': shapely's independent judge);\n"
          "check step = spacing of the checked states along a motion; ours/peer only where both have a valid run.")
    print(_table(rows))
    print()
    print("\n".join(report(rows, checkers)))
    if args.out_json:
        write_json(args.out_json, rows, "--out-json")
    return 0


def _ms(s):
    return None if s is None else s * 1000.0


def _table(rows: list[dict]) -> str:
    cols = list(rows[0]) if rows else []
    cells = [[_fmt(r.get(c)) for c in cols] for r in rows]
    width = [max(len(c), *(len(x[i]) for x in cells)) for i, c in enumerate(cols)]
    out = ["  ".join(c.ljust(w) for c, w in zip(cols, width))]
    out += ["  ".join(x.ljust(w) for x, w in zip(row, width)) for row in cells]
    return "\n".join(out)


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return f"{v:.3g}" if math.isfinite(v) else str(v)
    return str(v)


if __name__ == "__main__":
    sys.exit(main())
