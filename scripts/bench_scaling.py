"""How the C-space's cost grows with the scene: build time, peak memory, query time.

Three sweeps, each on scenes built through the public API (a scenario dict ->
``cspace.scenario_from_dict`` -> ``CSpace.from_scenario``):

(a) obstacles: 10 -> 10 000 random convex 8-gons in a square whose side grows as
    sqrt(n) (constant density), robot a regular 8-gon;
(b) vertices per obstacle: 8 -> 1 000, 20 convex obstacles, same robot;
(c) non-convex pairs: a comb robot with n teeth against a comb obstacle with m = n
    teeth: build time, convex pieces kept, and the vertex count of the union of the
    pieces (shapely), i.e. the C-obstacle's boundary.

Build time (and each build stage's time, from ``CSpace.stages``) and query times are
medians over repetitions (``time.perf_counter``);
per-query time is the median over batches of the batch mean. Peak memory is
tracemalloc's peak during one separate build (tracemalloc slows code down, so it
never wraps a timed build).

Reading the slopes (exponent k of the fitted power law y ~ x^k, least squares on
log-log) against the theory, with the full run's figures (2-core machine, shared):
- (a) obstacles. A convex sum is an O(n + m) angular merge, one per obstacle: the
  sum stage fits k = 0.97-1.05 (theory 1). The build fits 0.7-0.9, not 1, because
  it is dominated (60-85 %) by the grid index, whose cell count is 1024 per piece
  clamped to [2^16, 2^20]: constant below 64 pieces, linear up to 1024, then only
  the per-piece classification grows. Peak memory (~0.6) is the grid too: linear
  from 100 to 1000 obstacles (13 -> 136 MiB), nearly flat after (172 MiB at 10^4).
  Queries: theory O(1) at constant density (a state or a fixed-length motion meets
  O(1) cells). is_free fits ~0.18, segment_free 0.2-0.25: flat-ish to 1000, then
  the clamped grid's cells each hold more pieces (more MIXED cells, more exact
  tests), so the cost creeps up; still ~1.5 us and ~40 us at 10 000 obstacles.
- (b) vertices per obstacle. Theory O(n + m) per sum: the measured k ~0.5 is below
  1 because 20 sums of <= 1000 vertices each are dominated by numpy's per-call
  overhead (scripts/bench_minkowski.py shows the linear regime at 10^3..10^4). The
  index classifies every edge against its cells and grows ~linearly from 128
  vertices on. is_free rises mildly (k ~0.4): FREE/BLOCKED cells are O(1), only
  MIXED cells run the vectorised O(n) exact test; segment_free stays within noise
  (k between -0.05 and 0.3 across runs: ~10-40 us, mostly per-call overhead).
  The machine is shared: slopes below ~0.3 move by +-0.2 from run to run.
- (c) non-convex pairs. A comb with n teeth decomposes into n + 1 convex pieces,
  so there are (n+1)(m+1) pairwise sums: pairs fit ~1.7 and approach 2 (theory
  O(nm), n = m); build time ~1.4 (fixed costs at small n). The union of the pieces,
  the C-obstacle's boundary that the C-space never computes, can have Θ(n²m²)
  vertices in the worst case (k = 4). These combs do NOT reach it: with the
  obstacle's pitch n times the robot's, the teeth of the sum fall on nm distinct
  vertical strips and the boundary has exactly 4(nm + 1) vertices (k ~1.9 -> 2;
  crossed and tilted combs measured lower). A Θ(n²m²) boundary needs Θ(nm) strips
  in each of two directions crossing without being filled in, and two long teeth
  in different directions always sum to a filled parallelogram; no such layout is
  built here. Either way the C-space's own cost follows the pieces, O(nm).
(d) big scenes (scripts/scaling_big.py): 90 601 triangles, a 100 000-vertex star, a
    10^6-vertex convex obstacle: load and build seconds per stage, slopes per stage.

Usage: python scripts/bench_scaling.py [--quick] [--big | --no-big] [--plot scaling.png] [--out-json rows.json]
(--plot: .png, .svg or .pdf; both outputs are checked before any work and written atomically.)
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import tracemalloc

import numpy as np

from cspace import CSpace, scenario_from_dict

FULL = {
    "obstacles": [10, 30, 100, 300, 1000, 3000, 10000],
    "vertices": [8, 32, 128, 512, 1000],
    "combs": [2, 4, 8, 16, 32],
}
QUICK = {
    "obstacles": [10, 100, 1000],
    "vertices": [8, 64, 512],
    "combs": [2, 4, 8],
}
ROBOT_RADIUS = 0.3
DENSITY_SIDE = 10.0  # square side per sqrt(obstacle): about 1 obstacle per 100 unit²
SEGMENT_LENGTH = 3.0  # fixed motion length, so the work per motion is scale-free


# ------------------------------------------------------------------ shapes


def regular_polygon(k: int, r: float, center=(0.0, 0.0), phase: float = 0.0) -> np.ndarray:
    """A regular CCW k-gon of circumradius r.

    >>> regular_polygon(4, 1.0).shape
    (4, 2)
    """
    a = phase + 2 * math.pi * np.arange(k) / k
    return np.c_[center[0] + r * np.cos(a), center[1] + r * np.sin(a)]


def random_convex(k: int, rng: np.random.Generator, center, r: float) -> np.ndarray:
    """A convex CCW k-gon inscribed in a circle: jittered angles, each gap >= half the
    regular one, so three consecutive vertices turn by far more than float rounding."""
    a = 2 * math.pi * (np.arange(k) + rng.uniform(0.0, 0.5, k)) / k + rng.uniform(0, 2 * math.pi)
    return np.c_[center[0] + r * np.cos(a), center[1] + r * np.sin(a)]


def comb(teeth: int, width: float = 1.0, gap: float = 1.0, height: float = 4.0, base: float = 1.0) -> np.ndarray:
    """A CCW comb: a base bar with ``teeth`` teeth pointing up (+y).

    >>> len(comb(3))
    12
    """
    pitch = width + gap
    length = teeth * pitch - gap
    pts = [(0.0, 0.0), (length, 0.0)]
    for t in range(teeth - 1, -1, -1):  # walk the top edge right to left
        x0 = t * pitch
        pts += [(x0 + width, base + height), (x0, base + height)]
        if t:
            pts += [(x0, base), (x0 - gap, base)]
    # the first tooth's left side runs straight down to (0, 0): no vertex at (0, base)
    return np.array(pts, dtype=np.float64)


# ------------------------------------------------------------------ scenes


def _scene(side: float, obstacles: list[np.ndarray], robot: np.ndarray, start, goal) -> dict:
    return {
        "bounds": {"xmin": 0.0, "xmax": side, "ymin": 0.0, "ymax": side},
        "robot": {"polygon": robot.tolist()},
        "obstacles": [{"polygon": p.tolist()} for p in obstacles],
        "start": {"x": start[0], "y": start[1]},
        "goal": {"x": goal[0], "y": goal[1]},
    }


def scattered_scene(n: int, k: int, seed: int, side: float | None = None) -> dict:
    """n random convex k-gons (circumradius 0.5..1.5) in a square of side
    DENSITY_SIDE * sqrt(n), kept 1.5 units off the border so the corners are free."""
    rng = np.random.default_rng([seed, n, k])
    side = DENSITY_SIDE * math.sqrt(n) if side is None else side
    obstacles = [random_convex(k, rng, rng.uniform(3.0, side - 3.0, 2), rng.uniform(0.5, 1.5)) for _ in range(n)]
    robot = regular_polygon(8, ROBOT_RADIUS, phase=math.pi / 8)
    return _scene(side, obstacles, robot, (0.5, 0.5), (side - 0.5, side - 0.5))


def comb_scene(n: int, m: int) -> dict:
    """Comb robot (n teeth, pointing down) above a comb obstacle (m teeth, pointing up)
    whose pitch is n times the robot's, so the nm teeth of the sum fall on distinct strips."""
    robot = comb(n, width=0.2, gap=0.8, height=6.0, base=0.2)
    robot = np.c_[robot[:, 0] - robot[:, 0].mean(), -robot[:, 1]][::-1]  # teeth down, still CCW
    obstacle = comb(m, width=0.2, gap=n * 1.0 - 0.2, height=6.0, base=0.2)
    obstacle = obstacle + np.array([10.0 + n, 10.0])
    side = obstacle[:, 0].max() + 10.0 + n
    return _scene(side, [obstacle], robot, (1.0 + n, side - 1.0), (side - 1.0 - n, side - 1.0))


# ------------------------------------------------------------------ measuring


def median_build(sc, reps: int) -> tuple[float, dict[str, float], CSpace]:
    """Median wall time of ``CSpace.from_scenario(sc)`` over ``reps`` builds, the median
    seconds of each build stage the C-space records, and the last C-space built."""
    total, stages = [], {}
    for _ in range(reps):
        t = time.perf_counter()
        cs = CSpace.from_scenario(sc)
        total.append(time.perf_counter() - t)
        for st in cs.stages:
            stages.setdefault(st.name, []).append(st.seconds)
    return statistics.median(total), {k: statistics.median(v) for k, v in stages.items()}, cs


def peak_memory(fn) -> float:
    """tracemalloc's peak (MiB) while ``fn()`` runs."""
    tracemalloc.start()
    try:
        fn()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return peak / 2**20


def query_times(cs: CSpace, rng: np.random.Generator, queries: int, batches: int) -> tuple[float, float]:
    """Median per-query seconds of is_free (uniform states) and segment_free (random
    motions of SEGMENT_LENGTH whose start is uniform in the bounds)."""
    xmin, xmax, ymin, ymax = cs.bounds
    lo, hi = np.array([xmin, ymin]), np.array([xmax, ymax])
    pts = [rng.uniform(lo, hi, (queries, 2)).tolist() for _ in range(batches)]
    segs = []
    for _ in range(batches):
        a = rng.uniform(lo, hi, (queries, 2))
        ang = rng.uniform(0, 2 * math.pi, queries)
        b = np.clip(a + SEGMENT_LENGTH * np.c_[np.cos(ang), np.sin(ang)], lo, hi)
        segs.append(list(zip(a.tolist(), b.tolist())))
    point_t, seg_t = [], []
    for batch in pts:
        t = time.perf_counter()
        for q in batch:
            cs.is_free(q)
        point_t.append((time.perf_counter() - t) / queries)
    for batch in segs:
        t = time.perf_counter()
        for a, b in batch:
            cs.segment_free(a, b)
        seg_t.append((time.perf_counter() - t) / queries)
    return statistics.median(point_t), statistics.median(seg_t)


def measure_scene(scene: dict, reps: int, queries: int, batches: int, seed: int) -> dict:
    """Build time (median), peak memory, pieces and query times of one scene."""
    sc = scenario_from_dict(scene)
    CSpace.from_scenario(sc)  # warm-up: first-call imports and caches stay out of the median
    build, stages, cs = median_build(sc, reps)
    mem = peak_memory(lambda: CSpace.from_scenario(sc))
    point_s, seg_s = query_times(cs, np.random.default_rng(seed), queries, batches)
    return {
        "build_s": build, "sum_s": stages["minkowski"], "index_s": stages["index"], "peak_mib": mem, "pieces": len(cs.pieces),
        "is_free_us": point_s * 1e6, "segment_free_us": seg_s * 1e6,
    }


def _reps(work: float) -> int:
    """Repetitions for a build of about ``work`` units (pieces x vertices)."""
    return int(min(15, max(3, 2e5 / max(work, 1.0))))


def sweep_obstacles(sizes, seed: int = 0, queries: int = 400, batches: int = 5) -> list[dict]:
    """Sweep (a): one row per obstacle count (8-gons, 8-gon robot, constant density)."""
    rows = []
    for n in sizes:
        row = measure_scene(scattered_scene(n, 8, seed), _reps(n * 16), queries, batches, seed)
        rows.append({"sweep": "obstacles", "x": n, "obstacles": n, "vertices": 8, **row})
    return rows


def sweep_vertices(sizes, obstacles: int = 20, seed: int = 0, queries: int = 400, batches: int = 5) -> list[dict]:
    """Sweep (b): one row per vertex count per obstacle (20 convex obstacles)."""
    rows = []
    side = DENSITY_SIDE * math.sqrt(obstacles)
    for k in sizes:
        row = measure_scene(scattered_scene(obstacles, k, seed, side), _reps(obstacles * (k + 8)),
                            queries, batches, seed)
        rows.append({"sweep": "vertices", "x": k, "obstacles": obstacles, "vertices": k, **row})
    return rows


def sweep_combs(sizes, budget_s: float = 60.0) -> list[dict]:
    """Sweep (c): comb(n) robot against comb(n) obstacle; pieces, build time and the
    vertex count of the union of the pieces. Stops early once the sweep has used
    ``budget_s`` seconds (the next size costs ~16x more)."""
    import shapely

    rows, t_start = [], time.perf_counter()
    for n in sizes:
        if rows and time.perf_counter() - t_start > budget_s / 16:
            print(f"# combs: n={n} skipped (time budget)", file=sys.stderr)
            break
        sc = scenario_from_dict(comb_scene(n, n))
        CSpace.from_scenario(sc)  # warm-up
        build, stages, cs = median_build(sc, _reps(n * n * 50))
        raw = next(s.counts["pairs"] for s in cs.stages if s.name == "minkowski")
        t = time.perf_counter()
        union = shapely.union_all(shapely.polygons(cs.pieces) if len({len(p) for p in cs.pieces}) == 1
                                  else [shapely.Polygon(p) for p in cs.pieces])
        union_s = time.perf_counter() - t
        rows.append({"sweep": "combs", "x": n, "teeth_robot": n, "teeth_obstacle": n,
                     "build_s": build, "sum_s": stages["minkowski"], "pairs": raw, "pieces": len(cs.pieces),
                     "union_vertices": boundary_vertices(union), "union_holes": holes(union),
                     "union_s": union_s})
    return rows


def boundary_vertices(geom) -> int:
    """Vertices on the boundary of a shapely (Multi)Polygon, closing repeats excluded."""
    import shapely

    parts = getattr(geom, "geoms", [geom])
    return int(sum(len(r.coords) - 1 for p in parts for r in [p.exterior, *p.interiors] if not shapely.is_empty(r)))


def holes(geom) -> int:
    parts = getattr(geom, "geoms", [geom])
    return sum(len(p.interiors) for p in parts)


# ------------------------------------------------------------------ fitting and printing


def fit_exponent(xs, ys) -> float:
    """Slope k of the least-squares line log y = k log x + c.

    >>> round(fit_exponent([1, 2, 4], [3, 12, 48]), 9)
    2.0
    """
    x, y = np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float))
    return float(np.polyfit(x, y, 1)[0])


# (sweep, measured field, theory slope, theory text)
THEORY = [
    ("obstacles", "build_s", 1.0, "O(N (n+m)) convex sums + near-linear prune/index"),
    ("obstacles", "sum_s", 1.0, "one O(n + m) convex sum per obstacle"),
    ("obstacles", "index_s", 1.0, "grid cells ~ pieces (capped at 1024²)"),
    ("obstacles", "peak_mib", 1.0, "pieces stored once, grid ~ pieces"),
    ("obstacles", "is_free_us", 0.0, "grid broad phase: O(1) cells at constant density"),
    ("obstacles", "segment_free_us", 0.0, "fixed-length motion: O(1) cells"),
    ("vertices", "build_s", 1.0, "O(n + m) merge per pair + O(n) normalisation"),
    ("vertices", "sum_s", 1.0, "O(n + m) angular merge, 20 pairs"),
    ("vertices", "peak_mib", 1.0, "O(n + m) vertices per piece"),
    ("vertices", "is_free_us", 0.0, "O(1) FREE/BLOCKED cells; O(n) vectorised in MIXED ones"),
    ("vertices", "segment_free_us", 1.0, "exact SAT over the candidate's O(n) edges"),
    ("combs", "pairs", 2.0, "O(n) x O(m) convex pairs, n = m"),
    ("combs", "pieces", 2.0, "pairs kept after pruning"),
    ("combs", "build_s", 2.0, "O(nm) pairwise sums, n = m"),
    ("combs", "sum_s", 2.0, "O(nm) sums of O(1)-vertex pieces"),
    ("combs", "union_vertices", 4.0, "worst case Θ(n²m²), n = m"),
]


def fits(rows: list[dict]) -> list[dict]:
    """Fitted exponent of each (sweep, field) of THEORY present in ``rows``."""
    out = []
    for sweep, field, theory, why in THEORY:
        sel = [r for r in rows if r["sweep"] == sweep and r.get(field, 0) > 0]
        if len(sel) >= 2:
            out.append({"sweep": sweep, "field": field, "fitted": fit_exponent([r["x"] for r in sel],
                                                                               [r[field] for r in sel]),
                        "theory": theory, "why": why, "points": len(sel)})
    return out


def print_rows(rows: list[dict]) -> None:
    for sweep, label in (("obstacles", "obstacles"), ("vertices", "vertices/obstacle")):
        sel = [r for r in rows if r["sweep"] == sweep]
        if not sel:
            continue
        print(f"\n({'a' if sweep == 'obstacles' else 'b'}) {label}")
        print(f"{label:>17} {'pieces':>7} {'build':>10} {'sums':>9} {'index':>9} {'peak MiB':>9} "
              f"{'is_free':>9} {'segment_free':>12}")
        for r in sel:
            print(f"{r['x']:>17} {r['pieces']:>7} {r['build_s'] * 1e3:>8.1f}ms {r['sum_s'] * 1e3:>7.2f}ms "
                  f"{r['index_s'] * 1e3:>7.1f}ms {r['peak_mib']:>9.2f} "
                  f"{r['is_free_us']:>7.2f}us {r['segment_free_us']:>10.2f}us")
    sel = [r for r in rows if r["sweep"] == "combs"]
    if sel:
        print("\n(c) comb(n) robot vs comb(n) obstacle")
        print(f"{'n=m':>5} {'pairs':>6} {'pieces':>7} {'build':>10} {'sums':>9} {'union verts':>12} {'holes':>6} "
              f"{'union':>9}")
        for r in sel:
            print(f"{r['x']:>5} {r['pairs']:>6} {r['pieces']:>7} {r['build_s'] * 1e3:>8.1f}ms {r['sum_s'] * 1e3:>7.2f}ms "
                  f"{r['union_vertices']:>12} {r['union_holes']:>6} {r['union_s'] * 1e3:>7.1f}ms")


def print_fits(table: list[dict]) -> None:
    print("\nfitted exponents (y ~ x^k, least squares on log-log)")
    print(f"{'sweep':>10} {'quantity':>16} {'fitted k':>9} {'theory':>7}  why")
    for f in table:
        print(f"{f['sweep']:>10} {f['field']:>16} {f['fitted']:>9.2f} {f['theory']:>7.1f}  {f['why']}")


def plot(rows: list[dict], path: str, fmt: str = "png") -> None:
    """One log-log panel per sweep, written atomically to ``path`` in ``fmt``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    panels = [
        ("obstacles", "obstacles (8-gons)", [("build_s", "build s"), ("sum_s", "sums s"),
                                             ("peak_mib", "peak MiB"), ("is_free_us", "is_free µs"), ("segment_free_us", "segment_free µs")]),
        ("vertices", "vertices per obstacle (20 obstacles)", [("build_s", "build s"), ("sum_s", "sums s"),
                                                              ("peak_mib", "peak MiB"), ("is_free_us", "is_free µs"),
                                                              ("segment_free_us", "segment_free µs")]),
        ("combs", "comb teeth n = m", [("build_s", "build s"), ("sum_s", "sums s"), ("pieces", "pieces"),
                                       ("union_vertices", "union boundary vertices")]),
    ]
    table = {(f["sweep"], f["field"]): f["fitted"] for f in fits(rows)}
    for ax, (sweep, xlabel, fields) in zip(axes, panels):
        sel = [r for r in rows if r["sweep"] == sweep]
        for field, label in fields:
            pts = [(r["x"], r[field]) for r in sel if r.get(field, 0) > 0]
            if pts:
                k = table.get((sweep, field))
                ax.loglog(*zip(*pts), "o-", label=f"{label} (k={k:.2f})" if k is not None else label)
        if sweep == "combs" and sel:
            # reference slopes: O(nm) = n² and the worst case O(n²m²) = n⁴, through the first union point
            x0, y0 = sel[0]["x"], sel[0]["union_vertices"]
            xs = np.array([r["x"] for r in sel], float)
            ax.loglog(xs, y0 * (xs / x0) ** 2, "k:", lw=1, label="slope 2 (nm)")
            ax.loglog(xs, y0 * (xs / x0) ** 4, "k--", lw=1, label="slope 4 (n²m² worst case)")
            ax.set_xticks(xs, [str(int(x)) for x in xs])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_title("(a) obstacles")
    axes[1].set_title("(b) vertices per obstacle")
    axes[2].set_title("(c) non-convex pairs")
    fig.tight_layout()
    from planners.output import atomic_path

    with atomic_path(path, "--plot") as tmp:
        fig.savefig(tmp, dpi=110, format=fmt)
    plt.close(fig)


def run(quick: bool = False, seed: int = 0) -> list[dict]:
    """All three sweeps (the quick or the full sizes)."""
    sizes = QUICK if quick else FULL
    queries = 200 if quick else 400
    rows = sweep_obstacles(sizes["obstacles"], seed, queries)
    rows += sweep_vertices(sizes["vertices"], seed=seed, queries=queries)
    rows += sweep_combs(sizes["combs"], budget_s=20.0 if quick else 120.0)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sweeps (< 60 s)")
    ap.add_argument("--plot", default="scaling.png", help="log-log PNG to write ('' for none)")
    ap.add_argument("--out-json", default=None, help="write the rows and fitted exponents as JSON")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--big", action="store_true", help="only sweep (d), the big scenes")
    ap.add_argument("--no-big", action="store_true", help="skip sweep (d)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    import os

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import scaling_big
    from benchutil import check_distinct, check_json, check_out, write_json
    from planners.output import PLOT_FORMATS

    fmt = check_out(args.plot or None, (), "--plot", PLOT_FORMATS)  # (the scenes are made here: no input files)
    check_json(args.out_json, (), "--out-json")
    check_distinct([(args.plot, "--plot"), (args.out_json, "--out-json")])

    rows = [] if args.big else run(args.quick, args.seed)
    big = [] if args.no_big else scaling_big.sweep(args.quick, log=lambda *a, **k: print(*a, file=sys.stderr, **k))
    print_rows(rows)
    table = fits(rows)
    print_fits(table)
    big_table = scaling_big.slopes(big, fit_exponent)
    if big:
        scaling_big.print_big(big, big_table)
    rows += big
    if args.plot:
        plot(rows, args.plot, fmt)
        print(f"\nplot: {args.plot}")
    if args.out_json:
        write_json(args.out_json, {"rows": rows, "fits": table, "big_fits": big_table, "quick": args.quick},
                   "--out-json")
    print(f"total {time.perf_counter() - t0:.1f}s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
