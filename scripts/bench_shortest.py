"""Exact shortest paths at scale: the mesh search against the lazy search it replaced.

Two families of random scenes, a point robot (so the C-obstacles are the obstacles
and their vertex count is the input size N), start and goal at opposite corners:

(a) scattered: N/8 random convex 8-gons (circumradius 0.5..1.5, overlapping where
    they fall) in a square whose side grows as sqrt(N) (constant density);
(b) grid mazes: a random occupancy grid of unit cells (35 % full, like OMPL's env2),
    merged into polygons, with a free corridor around it; side ~ sqrt(N).

For each scene, ``cspace.paths.shortest.shortest_path`` (the mesh search, with its
preparation: F, the triangulation, its checks) and ``method="lazy"`` (the old search,
time-limited) run interleaved, ``--reps`` times each, the scene cache cleared before
every call; the table shows medians of CPU seconds (the machine is shared), the old/new ratio where the old search
finished, and whether the lengths agree to 1e-9 (they must). The fitted slope k of
time ~ N^k (least squares on log-log) is printed per family and search.

Full run (2026-11-24, 2-core machine shared with other jobs, load 6-9; CPU seconds,
medians of 3; ``--old-limit 30``): the lengths agree on every scene both finish.
- (a) scattered, 500 -> 20 000 vertices: mesh 0.021 -> 1.22 s (k = 1.08), lazy 0.012
  -> 3.87 s (k = 1.46). The lazy search wins below ~8 000 vertices (0.6-0.8x: in
  open space the straight-line heuristic leads it to the goal after a dozen corners,
  while the mesh search pays for GEOS's triangulation, about half its time); the
  mesh search wins above (1.2x at 10 000, 3.2x at 20 000), as the lazy search pushes
  O(V) candidates per settled corner.
- (b) grid mazes, 500 -> 20 000 vertices: mesh 0.036 -> 1.89 s (k = 1.09); lazy 0.22
  -> 2.15 s up to 2 000 vertices (6-17x slower, k = 1.68), then past its 30 s limit.
The figure: docs/shortest_scaling.png (``--plot``).

Usage: python scripts/bench_shortest.py [--quick] [--plot docs/shortest_scaling.png] [--out-json rows.json]
(--plot: .png, .svg or .pdf; both outputs are checked before any work and written atomically.)
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time

import numpy as np

from cspace import CSpace, scenario_from_dict
from cspace.paths.shortest import clear_cache, shortest_path

FULL = [500, 1000, 2000, 5000, 10000, 20000]
QUICK = [500, 2000, 5000]


def _scene(side: float, obstacles: list, start, goal) -> dict:
    return {"bounds": {"xmin": 0.0, "xmax": side, "ymin": 0.0, "ymax": side},
            "obstacles": [{"polygon": np.asarray(p).tolist()} for p in obstacles],
            "start": {"x": start[0], "y": start[1]}, "goal": {"x": goal[0], "y": goal[1]}}


def scattered(n_vertices: int, seed: int) -> dict:
    """N/8 random convex 8-gons at constant density, 1.5 units off the border."""
    rng = np.random.default_rng([seed, n_vertices])
    n = max(1, n_vertices // 8)
    side = 10.0 * math.sqrt(n)
    obs = []
    for _ in range(n):
        c, r = rng.uniform(3.0, side - 3.0, 2), rng.uniform(0.5, 1.5)
        a = 2 * math.pi * (np.arange(8) + rng.uniform(0.0, 0.5, 8)) / 8 + rng.uniform(0, 2 * math.pi)
        obs.append(np.c_[c[0] + r * np.cos(a), c[1] + r * np.sin(a)])
    return _scene(side, obs, (0.5, 0.5), (side - 0.5, side - 0.5))


def grid_maze(n_vertices: int, seed: int) -> dict:
    """A random 35 %-full occupancy grid whose merged cells have about N vertices, inside
    a one-cell free border (so start and goal corners connect unless walled off)."""
    import shapely

    rng = np.random.default_rng([seed, n_vertices, 1])
    m = max(4, int(round(math.sqrt(n_vertices / 0.78))))  # ~0.78 union vertices per cell, measured
    full = rng.random((m, m)) < 0.35
    cells = [shapely.box(i + 1, j + 1, i + 2, j + 2) for i, j in zip(*np.nonzero(full))]
    union = shapely.union_all(cells)
    obs = []
    for p in shapely.get_parts(union):
        p = shapely.geometry.polygon.orient(shapely.simplify(p, 0), 1.0)
        obs.append({"polygon": np.asarray(p.exterior.coords)[:-1].tolist(),
                    **({"holes": [np.asarray(h.coords)[:-1].tolist() for h in p.interiors]} if p.interiors else {})})
    side = float(m + 2)
    sc = _scene(side, [], (0.5, 0.5), (side - 0.5, side - 0.5))
    sc["obstacles"] = obs
    return sc


FAMILIES = {"scattered": scattered, "grid": grid_maze}


def _timed(fn) -> tuple[float, object]:
    """CPU seconds of fn() (the machine is shared: CPU time is steadier than wall time;
    GEOS runs in this thread, so it is counted)."""
    clear_cache()  # every call pays its preparation (F, mesh)
    t = time.process_time()
    out = fn()
    return time.process_time() - t, out


def measure(family: str, n: int, reps: int, old_limit: float, seed: int) -> dict:
    """Interleaved medians of the new and the old search on one scene."""
    cs = CSpace.from_scenario(scenario_from_dict(FAMILIES[family](n, seed)))
    sc_start, sc_goal = (0.5, 0.5), (cs.bounds[1] - 0.5, cs.bounds[3] - 0.5)
    verts = sum(len(p) for p in cs.pieces)
    new_t, old_t, new, old = [], [], None, None
    for _ in range(reps):
        dt, new = _timed(lambda: shortest_path(cs.pieces, cs.bounds, sc_start, sc_goal))
        new_t.append(dt)
        if old_limit > 0:
            dt, old = _timed(lambda: shortest_path(cs.pieces, cs.bounds, sc_start, sc_goal, method="lazy",
                                                   time_limit=old_limit))
            if old.stats.get("reason") == "time limit":
                old_limit = 0.0  # unfinished: not repeated
                old_t = []
            else:
                old_t.append(dt)
    row = {"family": family, "n": n, "vertices": verts, "nodes": new.stats["counts"].get("nodes", 0),
           "new_s": statistics.median(new_t), "solved": bool(new.solved), "length": new.length,
           "method": new.stats.get("method")}
    if old_t:
        row["old_s"] = statistics.median(old_t)
        row["ratio"] = row["old_s"] / row["new_s"]
        row["agree"] = (new.solved == old.solved and (not new.solved or math.isclose(new.length, old.length, rel_tol=1e-9)))
    return row


def fit_exponent(xs, ys) -> float:
    """Slope k of the least-squares line log y = k log x + c.

    >>> round(fit_exponent([1, 2, 4], [3, 12, 48]), 9)
    2.0
    """
    return float(np.polyfit(np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float)), 1)[0])


def fits(rows: list[dict]) -> list[dict]:
    """Fitted exponent of time against C-obstacle vertices, per family and search."""
    out = []
    for fam in FAMILIES:
        for key in ("new_s", "old_s"):
            sel = [r for r in rows if r["family"] == fam and key in r]
            if len(sel) >= 2:
                out.append({"family": fam, "search": "mesh" if key == "new_s" else "lazy", "points": len(sel),
                            "k": fit_exponent([r["vertices"] for r in sel], [r[key] for r in sel])})
    return out


def print_rows(rows: list[dict], table: list[dict]) -> None:
    print(f"{'family':>9} {'vertices':>8} {'nodes':>6} {'mesh s':>8} {'lazy s':>8} {'lazy/mesh':>9} {'agree':>5}  length")
    for r in rows:
        old = f"{r['old_s']:8.3f}" if "old_s" in r else f"{'>limit':>8}"
        ratio = f"{r['ratio']:9.1f}" if "ratio" in r else f"{'-':>9}"
        agree = ("yes" if r["agree"] else "NO") if "agree" in r else "-"
        print(f"{r['family']:>9} {r['vertices']:>8} {r['nodes']:>6} {r['new_s']:8.3f} {old} {ratio} {agree:>5}  "
              f"{r['length']:.9g}")
    print("\nfitted slope k of time ~ vertices^k (least squares on log-log)")
    for f in table:
        print(f"{f['family']:>9} {f['search']:>5} k = {f['k']:.2f} ({f['points']} sizes)")


def plot(rows: list[dict], table: list[dict], path: str, fmt: str = "png") -> None:
    """Time against C-obstacle vertices, log-log, one line per family and search, written
    atomically to ``path`` in ``fmt``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from planners.output import atomic_path

    ks = {(f["family"], f["search"]): f["k"] for f in table}
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for fam, marker in zip(FAMILIES, "os"):
        for key, search, style in (("new_s", "mesh", "-"), ("old_s", "lazy", "--")):
            pts = [(r["vertices"], r[key]) for r in rows if r["family"] == fam and key in r]
            if pts:
                k = ks.get((fam, search))
                label = f"{fam}, {search} search" + (f" (k = {k:.2f})" if k is not None else "")
                ax.loglog(*zip(*pts), marker + style, label=label)
    ax.set_xlabel("C-obstacle vertices")
    ax.set_ylabel("CPU seconds (median, preparation included)")
    ax.set_title("exact shortest path: mesh search vs the lazy search (time-limited)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path, "--plot") as tmp:
        fig.savefig(tmp, dpi=110, format=fmt)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="sizes up to 5000 vertices, one repetition (~1 min)")
    ap.add_argument("--sizes", help="comma-separated vertex counts (default: 500 .. 20000)")
    ap.add_argument("--reps", type=int, help="repetitions per scene (default 3, quick 1)")
    ap.add_argument("--old-limit", type=float, default=None, help="seconds per lazy search (default 60, quick 20)")
    ap.add_argument("--plot", default="", help="PNG to write (e.g. docs/shortest_scaling.png; '' for none)")
    ap.add_argument("--out-json", default=None, help="write the rows and slopes as JSON")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    import os

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_distinct, check_json, check_out, write_json
    from planners.output import PLOT_FORMATS

    fmt = check_out(args.plot or None, (), "--plot", PLOT_FORMATS)  # (the scenes are made here: no input files)
    check_json(args.out_json, (), "--out-json")
    check_distinct([(args.plot, "--plot"), (args.out_json, "--out-json")])
    sizes = [int(s) for s in args.sizes.split(",")] if args.sizes else (QUICK if args.quick else FULL)
    reps = args.reps or (1 if args.quick else 3)
    limit = args.old_limit if args.old_limit is not None else (20.0 if args.quick else 60.0)
    t0 = time.perf_counter()
    rows = []
    for fam in FAMILIES:
        lim = limit
        for n in sizes:
            rows.append(measure(fam, n, reps, lim, args.seed))
            if "old_s" not in rows[-1]:
                lim = 0.0  # the lazy search ran out of time: larger scenes are not tried
    table = fits(rows)
    print_rows(rows, table)
    print(f"\n{time.perf_counter() - t0:.0f} s wall")
    if args.plot:
        plot(rows, table, args.plot, fmt)
    if args.out_json:
        write_json(args.out_json, {"rows": rows, "fits": table}, "--out-json")
    bad = [r for r in rows if r.get("agree") is False]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
