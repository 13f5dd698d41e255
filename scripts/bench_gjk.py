"""GJK distance and EPA depth: per-query time, iterations, and peers in the same run.

Pairs of random convex 8- and 64-gons, separated, touching (moved into contact along x)
and overlapping. Peers: coal (C++, via its Python bindings; 2-D polygons as prisms) when it
imports, and shapely's distance. EPA depths are checked against the exact depth of the
materialised difference, for ours and for coal. Medians over repetitions; ratios printed.
Usage: python scripts/bench_gjk.py [--pairs N] [--plot FILE]
(--plot: .png, .svg or .pdf, checked before any work and written atomically.)
"""
import argparse
import statistics
import time

import numpy as np

from cspace.kernel.distance.epa import epa_penetration
from cspace.kernel.distance.gjk import exact_relation, gjk_distance
from cspace.kernel.polygons.hull import convex_hull
from cspace.kernel.minkowski.merge import minkowski_sum, reflect


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


def coal_api():
    """coal's distance and penetration on 2-D polygons as prisms, or None.

    coal is 3-D: a polygon becomes a prism (se2_peers.prism: bottom and top fans plus two
    triangles per side, z in [-1, 1]), built once per shape outside the timing. Two query styles are timed: a
    fresh request/result per query (what a caller usually writes) and reused ones.
    """
    try:
        import coal
    except ImportError:
        return None
    from se2_peers import prism  # the SE(2) benches' prism (scripts/ is on the path of a script)

    eye = coal.Transform3s()
    req, res = coal.DistanceRequest(), coal.DistanceResult()

    def dist_fresh(A, B):
        return coal.distance(A, eye, B, eye, coal.DistanceRequest(), coal.DistanceResult())

    def dist_reused(A, B):
        return coal.distance(A, eye, B, eye, req, res)

    def depth(A, B):
        creq = coal.CollisionRequest()
        creq.enable_contact = True
        cres = coal.CollisionResult()
        coal.collide(A, eye, B, eye, creq, cres)
        return -cres.getContact(0).penetration_depth if cres.isCollision() else 0.0

    return prism, dist_fresh, dist_reused, depth


def make_pairs(rng, n, case, count):
    """Pairs of n-gons of radius 1: separated (centres 3 apart), touching, overlapping."""
    pairs = []
    while len(pairs) < count:
        A = rand_convex(rng, n, (0, 0))
        off = {"separated": 3.0, "touching": 2.0, "overlapping": 1.0}[case]
        B = rand_convex(rng, n, (off, rng.uniform(-0.5, 0.5)))
        if case == "touching":
            # Exact vertex contact: on a 2^-20 grid, move B's lowest vertex along u onto
            # A's highest (the line normal to u through it separates them weakly).
            A, B = np.round(A * 2**20) / 2**20, np.round(B * 2**20) / 2**20
            u = B.mean(axis=0) - A.mean(axis=0)
            B -= B[np.argmin(B @ u)] - A[np.argmax(A @ u)]
        # Keep the pair only if the exact relation is the case's (random gons may miss).
        if exact_relation(A, B) == case:
            pairs.append((A, B))
    return pairs


def exact_depth(A, B):
    """Penetration depth from the materialised A ⊕ (−B): distance from the origin to its boundary."""
    import shapely

    D = shapely.Polygon(minkowski_sum(A, reflect(B)))
    return D.exterior.distance(shapely.Point(0, 0))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=50)
    ap.add_argument("--plot", default=None, help="PNG: distance error against the iteration cap")
    args = ap.parse_args(argv)
    import os
    import sys

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from benchutil import check_out
    from planners.output import PLOT_FORMATS, atomic_path

    fmt = check_out(args.plot or None, (), "--plot", PLOT_FORMATS)  # (the pairs are made here: no input files)
    import shapely

    rng = np.random.default_rng(0)
    peer = coal_api()
    print("GJK distance, per query (median over pairs of 20 repetitions each)")
    print(f"{'n':>3} {'case':<12} {'ours':>9} {'iters':>6} {'max':>4} {'shapely':>9} {'coal new':>9} "
          f"{'coal reuse':>10} {'ours/coal new':>13} {'ours/coal reuse':>15}")
    for n in (8, 64):
        for case in ("separated", "touching", "overlapping"):
            pairs = make_pairs(rng, n, case, args.pairs)
            ours = median_time(gjk_distance, pairs)
            its = [gjk_distance(A, B).iterations for A, B in pairs]
            sp = [(shapely.Polygon(A), shapely.Polygon(B)) for A, B in pairs]
            shp = median_time(lambda a, b: a.distance(b), sp)
            fresh = reused = float("nan")
            if peer is not None:
                cp = [(peer[0](A), peer[0](B)) for A, B in pairs]
                fresh, reused = median_time(peer[1], cp), median_time(peer[2], cp)
            print(f"{n:>3} {case:<12} {ours * 1e6:>7.1f}us {statistics.mean(its):>6.2f} {max(its):>4} "
                  f"{shp * 1e6:>7.1f}us {fresh * 1e6:>7.2f}us {reused * 1e6:>8.2f}us "
                  f"{ours / fresh:>13.1f} {ours / reused:>15.1f}")
    print("\nEPA penetration depth on overlapping pairs: time, and error against the exact depth of the")
    print("materialised A ⊕ (−B) (relative to the sets' size 1)")
    print(f"{'n':>3} {'ours':>9} {'iters':>6} {'max err':>9} {'coal':>9} {'coal max err':>12} {'coal wrong>1e-9':>15}")
    for n in (8, 64):
        pairs = make_pairs(rng, n, "overlapping", max(32, args.pairs // 2))
        epa = median_time(epa_penetration, pairs, reps=5)
        res = [epa_penetration(A, B) for A, B in pairs]
        ref = [exact_depth(A, B) for A, B in pairs]
        err = max(abs(r.depth - e) for r, e in zip(res, ref))
        ct, cerr, wrong = float("nan"), float("nan"), "-"
        if peer is not None:
            cp = [(peer[0](A), peer[0](B)) for A, B in pairs]
            ct = median_time(peer[3], cp, reps=5)
            ce = [abs(peer[3](a, b) - e) for (a, b), e in zip(cp, ref)]
            cerr, wrong = max(ce), f"{sum(e > 1e-9 for e in ce)}/{len(ce)}"
        print(f"{n:>3} {epa * 1e6:>7.1f}us {statistics.mean(r.iterations for r in res):>6.2f} {err:>9.1e} "
              f"{ct * 1e6:>7.1f}us {cerr:>12.1e} {wrong:>15}")
    print("\nGJK distance error against the iteration cap (separated pairs; reference: shapely)")
    caps = [1, 2, 3, 4, 5, 6, 8]
    table = {}
    for n in (8, 64):
        pairs = make_pairs(rng, n, "separated", args.pairs)
        ref = [shapely.Polygon(A).distance(shapely.Polygon(B)) for A, B in pairs]
        table[n] = [statistics.median(abs(gjk_distance(A, B, max_iterations=c).distance - r) / r
                                      for (A, B), r in zip(pairs, ref)) for c in caps]
        table[n, "max"] = [max(abs(gjk_distance(A, B, max_iterations=c).distance - r) / r
                               for (A, B), r in zip(pairs, ref)) for c in caps]
    print(f"{'cap':>4} " + " ".join(f"{'median ' + str(n):>12} {'max ' + str(n):>10}" for n in (8, 64)))
    for i, c in enumerate(caps):
        print(f"{c:>4} " + " ".join(f"{table[n][i]:>12.1e} {table[n, 'max'][i]:>10.1e}" for n in (8, 64)))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5.5, 3.8))
        for n in (8, 64):
            floor = 1e-17  # exact answers drawn at the floor of the log axis
            ax.semilogy(caps, [max(v, floor) for v in table[n]], "o-", label=f"{n}-gons, median")
            ax.semilogy(caps, [max(v, floor) for v in table[n, "max"]], "s--", label=f"{n}-gons, max")
        ax.set_xlabel("GJK iteration cap")
        ax.set_ylabel("relative distance error vs shapely")
        ax.set_title("GJK convergence (separated pairs)")
        ax.legend()
        fig.tight_layout()
        with atomic_path(args.plot, "--plot") as tmp:
            fig.savefig(tmp, dpi=120, format=fmt)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
