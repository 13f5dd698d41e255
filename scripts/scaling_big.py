"""Big scenes for ``bench_scaling.py`` (sweep d): loading and building, stage by stage.

Three families, each grown until the issue's sizes (issue 23.7):

- ``triangles``: an m x m lattice of small triangles (m = 301: 90 601 obstacles) and a
  small square robot; theory: every stage linear in the obstacles;
- ``star``: one non-convex star of n vertices (spikes between radii 4 and 10) and a
  small pentagon robot (n = 100 000); theory: near-linear (the decomposition
  triangulates, O(n log n); each piece is summed once);
- ``convex``: one convex n-gon (a circle's points, n = 10^6) and the same robot;
  theory: linear (one angular merge).

Each row is one load (``scenario_from_dict``) and one build (``CSpace.from_scenario``),
with the build's stages from ``CSpace.report()``; the slopes are fitted on log-log per
family and stage. (Helper module: the scripts are not a package.)
"""
from __future__ import annotations

import math
import time

import numpy as np

from cspace import CSpace, scenario_from_dict

SIZES_FULL = {"triangles": [30, 100, 170, 301], "star": [2000, 10000, 30000, 100000],
              "convex": [10000, 100000, 1000000]}
SIZES_QUICK = {"triangles": [10, 20, 40], "star": [500, 1000, 2000], "convex": [1000, 10000, 100000]}
STAGES = ("load", "decompose_obstacles", "minkowski", "prune", "index", "build", "total")


def triangles(m: int) -> dict:
    """m x m triangles, one per 2 x 2 square; the robot a 0.4-wide square."""
    i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    x, y = 2.0 * i.ravel() + 1.0, 2.0 * j.ravel() + 1.0
    tris = np.stack([np.c_[x, y], np.c_[x + 1.0, y], np.c_[x + 0.5, y + 0.8]], axis=1)
    side = 2.0 * m + 1.0
    return _scene(side, [{"polygon": t} for t in tris.tolist()],
                  [[-0.2, -0.2], [0.2, -0.2], [0.2, 0.2], [-0.2, 0.2]], (0.25, 0.25), (side - 0.25, side - 0.25))


def star(n: int) -> dict:
    """One star of n vertices (n even) centred in a 100 x 100 box; a small pentagon robot."""
    a = np.arange(n) * (2.0 * math.pi / n)
    r = np.where(np.arange(n) % 2 == 0, 10.0, 4.0)
    pts = np.c_[50.0 + r * np.cos(a), 50.0 + r * np.sin(a)]
    return _scene(100.0, [{"polygon": pts.tolist()}], ROBOT, (1.0, 1.0), (99.0, 99.0))


def convex(n: int) -> dict:
    """One convex n-gon (radius 10) centred in a 100 x 100 box; the same robot."""
    a = np.arange(n) * (2.0 * math.pi / n)
    pts = np.c_[50.0 + 10.0 * np.cos(a), 50.0 + 10.0 * np.sin(a)]
    return _scene(100.0, [{"polygon": pts.tolist()}], ROBOT, (1.0, 1.0), (99.0, 99.0))


ROBOT = [[-0.3, -0.2], [0.3, -0.2], [0.35, 0.1], [0.0, 0.3], [-0.35, 0.1]]
SCENES = {"triangles": triangles, "star": star, "convex": convex}


def _scene(side, obstacles, robot, start, goal) -> dict:
    return {"bounds": {"xmin": 0.0, "xmax": side, "ymin": 0.0, "ymax": side}, "robot": {"polygon": robot},
            "obstacles": obstacles, "start": {"x": start[0], "y": start[1]}, "goal": {"x": goal[0], "y": goal[1]}}


def measure(family: str, size: int) -> dict:
    """One load and one build: seconds per stage, the pieces kept."""
    data = SCENES[family](size)
    t = time.perf_counter()
    sc = scenario_from_dict(data)
    load = time.perf_counter() - t
    t = time.perf_counter()
    cs = CSpace.from_scenario(sc)
    build = time.perf_counter() - t
    row = {"sweep": "big", "family": family, "x": size, "vertices": sum(len(o.polygon) for o in sc.obstacles),
           "pieces": len(cs.pieces), "load": load, "build": build, "total": load + build}
    for s in cs.report()["stages"]:
        row[s["stage"]] = s["seconds"]
    return row


def sweep(quick: bool, families=None, log=print) -> list[dict]:
    """Every family at its sizes, smallest first."""
    sizes = SIZES_QUICK if quick else SIZES_FULL
    rows = []
    for family in families or sizes:
        for n in sizes[family]:
            rows.append(measure(family, n))
            r = rows[-1]
            log(f"  {family} {n}: load {r['load']:.2f} s, build {r['build']:.2f} s", flush=True)
    return rows


def slopes(rows: list[dict], fit) -> list[dict]:
    """Fitted exponent per family and stage (x = the family's size)."""
    out = []
    for family in dict.fromkeys(r["family"] for r in rows):
        sel = [r for r in rows if r["family"] == family]
        for stage in STAGES:
            pts = [(r["x"], r[stage]) for r in sel if r.get(stage, 0) > 0]
            if len(pts) >= 2:
                out.append({"family": family, "stage": stage, "fitted": fit(*zip(*pts)),
                            "largest_s": pts[-1][1], "largest_x": pts[-1][0]})
    return out


def print_big(rows: list[dict], table: list[dict]) -> None:
    print("\n(d) big scenes: load and build, seconds (one run each)")
    print(f"{'family':>10} {'size':>8} {'pieces':>7} " + " ".join(f"{s[:9]:>9}" for s in STAGES))
    for r in rows:
        print(f"{r['family']:>10} {r['x']:>8} {r['pieces']:>7} " +
              " ".join(f"{r.get(s, 0.0):>9.3f}" for s in STAGES))
    print("\nfitted exponents of the big scenes (theory: 1, near-linear)")
    for f in table:
        print(f"{f['family']:>10} {f['stage']:>20} k = {f['fitted']:5.2f}   ({f['largest_s']:.2f} s at {f['largest_x']})")
