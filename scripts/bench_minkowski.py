"""Convex Minkowski sums: ours against pyclipper, all-pairs + shapely hull, and one argsort.

Medians over repetitions, in one process; ratios are against peers measured in the same run.
Random convex polygons with integer coordinates (exact for every method): sorted random
edge vectors summed (Valtr's construction), so n vertices really are n.
Usage: python scripts/bench_minkowski.py [--sizes 8,64,1024,16384] [--reps N]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchutil import median_time  # noqa: E402
from cspace.kernel.minkowski.merge import minkowski_sum
from cspace.compiled import fastpath  # registers the compiled pair sum (when built) in minkowski_sum


def random_convex(n, rng, span=2**20):
    """A convex polygon with n integer vertices: n random edge vectors sorted by angle."""
    while True:
        v = rng.integers(-span, span, size=(n, 2))
        v[-1] = -v[:-1].sum(axis=0)
        ang = np.arctan2(v[:, 1], v[:, 0])
        p = np.cumsum(v[np.argsort(ang)], axis=0).astype(np.float64)
        if len(np.unique(np.arctan2(v[:, 1], v[:, 0]))) == n:
            return p - p.min(axis=0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="8,64,1024,16384")
    ap.add_argument("--reps", type=int, default=0, help="repetitions (default: by size)")
    args = ap.parse_args()
    import pyclipper
    import shapely

    rng = np.random.default_rng(0)
    print(f"{'n=m':>6} {'ours':>11} {'pyclipper':>11} {'pairs+hull':>11} {'argsort':>11} "
          f"{'ours/clip':>9} {'ours/sort':>9}")
    for n in map(int, args.sizes.split(",")):
        P, Q = random_convex(n, rng), random_convex(n, rng)
        reps = args.reps or max(5, min(2000, 200000 // n))
        own = args.reps or max(100, min(2000, 2000000 // n))  # ours and argsort: cheap, so more
        ours = median_time(lambda: minkowski_sum(P, Q), own)
        e = np.concatenate([np.roll(P, -1, 0) - P, np.roll(Q, -1, 0) - Q])
        ang = np.arctan2(e[:, 1], e[:, 0])
        srt = median_time(lambda: np.argsort(ang), own)
        pi, qi = P.astype(np.int64).tolist(), Q.astype(np.int64).tolist()
        clip = median_time(lambda: pyclipper.MinkowskiSum(pi, qi, True), max(3, reps // 10)) if n <= 256 else float("nan")
        pairs = (median_time(lambda: shapely.MultiPoint((P[:, None] + Q[None]).reshape(-1, 2)).convex_hull,
                        max(3, reps // 10)) if n <= 1024 else float("nan"))
        # Exactness on integer input: the area agrees with the all-pairs hull where that runs.
        print(f"{n:>6} {ours * 1e6:>9.1f}us {clip * 1e6:>9.1f}us {pairs * 1e6:>9.1f}us {srt * 1e6:>9.1f}us "
              f"{ours / clip:>9.3f} {ours / srt:>9.2f}")
    # Float input: the vertices are rounded sums, certified strictly convex afterwards.
    n = max(map(int, args.sizes.split(",")))
    P, Q = (random_convex(n, rng) * 0.1 + 0.05 for _ in range(2))  # no longer integers
    e = np.concatenate([np.roll(P, -1, 0) - P, np.roll(Q, -1, 0) - Q])
    ang = np.arctan2(e[:, 1], e[:, 0])
    reps = args.reps or max(20, min(2000, 2000000 // n))
    flt, srt = median_time(lambda: minkowski_sum(P, Q), reps), median_time(lambda: np.argsort(ang), reps)
    print(f"float input, n = m = {n}: {flt * 1e6:.1f}us, one argsort {srt * 1e6:.1f}us, ratio {flt / srt:.2f}")
    # k-way: one merge of k polygons against one sort of all their edges.
    k, n = 8, 2048
    polys = [random_convex(n, rng) for _ in range(k)]
    kway = median_time(lambda: minkowski_sum(*polys), 200)
    e = np.concatenate([np.roll(p, -1, 0) - p for p in polys])
    ang = np.arctan2(e[:, 1], e[:, 0])
    srt = median_time(lambda: np.argsort(ang), 200)

    def fold():  # k - 1 pairwise merges: what the single merge saves
        s = polys[0]
        for p in polys[1:]:
            s = minkowski_sum(s, p)
        return s

    folded = median_time(fold, 50)
    assert np.array_equal(fold(), minkowski_sum(*polys))  # exact on integers: the same polygon
    print(f"k-way: {k} polygons x {n} vertices: {kway * 1e3:.2f} ms, one argsort of all edges "
          f"{srt * 1e3:.2f} ms, ratio {kway / srt:.2f}; pairwise folding {folded * 1e3:.2f} ms "
          f"({folded / kway:.1f}x the single merge)")
    # Small pairs: the compiled pair sum (cspace.compiled.fastpath) against the pure scalar merge.
    for n in (8, 32):
        P, Q = random_convex(n, rng), random_convex(n, rng)
        fast = median_time(lambda: minkowski_sum(P, Q), 2000)
        with fastpath.disabled():
            slow = median_time(lambda: minkowski_sum(P, Q), 2000)
            ref = minkowski_sum(P, Q)
        assert np.array_equal(minkowski_sum(P, Q), ref)  # the same arrays on both routes
        state = "compiled" if fastpath.compiled() else "not built: pure both"
        print(f"small pair n = m = {n} ({state}): fast {fast * 1e6:.1f}us, pure {slow * 1e6:.1f}us, "
              f"pure/fast {slow / fast:.2f}")
    print("(pyclipper skipped above 256 vertices: O(n m) quads, minutes at 1024; pairs+hull above 1024)")


if __name__ == "__main__":
    main()
