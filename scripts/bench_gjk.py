"""GJK distance and EPA depth: per-query time, iterations, and peers in the same run.

Pairs of random convex 8- and 64-gons, separated, touching (moved into exact contact along x)
and overlapping. Peers: coal (C++, via its Python bindings; 2-D polygons as thin prisms) when it
imports, and shapely's distance. Medians over repetitions; ratios printed.
Usage: python scripts/bench_gjk.py [--pairs N] [--plot FILE]
"""
import argparse
import statistics
import time

import numpy as np

from cspace.epa import epa_penetration
from cspace.gjk import gjk_distance
from cspace.hull import convex_hull


def rand_convex(rng, n, c):
    a = np.sort(rng.uniform(0, 2 * np.pi, n))
    return convex_hull(np.asarray(c) + np.c_[np.cos(a), np.sin(a)])


def median_time(fn, pairs, reps=20):
    t = []
    for A, B in pairs:
        t0 = time.perf_counter()
        for _ in range(reps):
            fn(A, B)
        t.append((time.perf_counter() - t0) / reps)
    return statistics.median(t)


def coal_shapes():
    try:
        import coal
    except ImportError:
        return None

    def prism(P):
        v = [np.array([x, y, z]) for z in (-0.5, 0.5) for x, y in P]
        n = len(P)
        return coal.Convex.convexHull(coal.StdVec_Vec3s(v) if hasattr(coal, "StdVec_Vec3s") else v, False, "") \
            if hasattr(coal.Convex, "convexHull") else None

    def dist(A, B):
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        return coal.distance(A, coal.Transform3s(), B, coal.Transform3s(), req, res)

    return prism, dist


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=50)
    ap.add_argument("--plot", default=None)
    args = ap.parse_args()
    import shapely

    rng = np.random.default_rng(0)
    coal_api = coal_shapes()
    print(f"{'n':>3} {'case':<12} {'ours':>9} {'iters':>6} {'shapely':>9} {'coal':>9} {'ours/coal':>9}")
    rows = []
    for n in (8, 64):
        for case in ("separated", "touching", "overlapping"):
            pairs = []
            for _ in range(args.pairs):
                A = rand_convex(rng, n, (0, 0))
                off = {"separated": 3.0, "touching": 2.0, "overlapping": 1.0}[case]
                B = rand_convex(rng, n, (off, rng.uniform(-0.5, 0.5)))
                if case == "touching":  # slide B along x into exact contact
                    B[:, 0] -= gjk_distance(A, B).distance if gjk_distance(A, B).status == "separated" else 0.0
                pairs.append((A, B))
            ours = median_time(gjk_distance, pairs)
            its = statistics.mean(gjk_distance(A, B).iterations for A, B in pairs)
            sp = [(shapely.Polygon(A), shapely.Polygon(B)) for A, B in pairs]
            shp = median_time(lambda a, b: a.distance(b), sp)
            coal_t = float("nan")
            if coal_api is not None:
                prism, dist = coal_api
                try:
                    cp = [(prism(A), prism(B)) for A, B in pairs]
                    if cp[0][0] is not None:
                        coal_t = median_time(dist, cp)
                except Exception:  # the bindings' signatures differ between versions
                    coal_t = float("nan")
            rows.append((n, case, ours, its))
            print(f"{n:>3} {case:<12} {ours * 1e6:>7.1f}us {its:>6.2f} {shp * 1e6:>7.1f}us {coal_t * 1e6:>7.1f}us "
                  f"{ours / coal_t:>9.2f}")
        pairs = []
        for _ in range(args.pairs):
            pairs.append((rand_convex(rng, n, (0, 0)), rand_convex(rng, n, (1.0, rng.uniform(-0.5, 0.5)))))
        epa = median_time(epa_penetration, pairs)
        its = statistics.mean(epa_penetration(A, B).iterations for A, B in pairs)
        print(f"{n:>3} {'EPA':<12} {epa * 1e6:>7.1f}us {its:>6.2f}")
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 3.5))
        labels = [f"{n}/{c[:4]}" for n, c, _, _ in rows]
        ax.bar(labels, [t * 1e6 for _, _, t, _ in rows])
        ax.set_ylabel("µs per GJK distance query")
        fig.tight_layout()
        fig.savefig(args.plot)


if __name__ == "__main__":
    main()
