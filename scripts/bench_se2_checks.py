"""The SE(2) checker against the translation checker outside OMPL: per-state and per-motion cost, slab builds.

Per state: ``SE2CSpace.pose_test(state=True)`` on uniform (x, y, θ) against
``CSpace.point_test(state=True)`` (the translational hot path) on the same (x, y),
batches interleaved, medians; the ratio is the cost of rotation. Per motion:
``SE2CSpace.motion_free`` against ``CSpace.segment_free`` on the same short random
motions (θ changes by a normal step of 0.5 rad), with the counters of the SE(2) run
(floor decisions, refinements). Slabs are all built before timing; their total
build time is printed separately.
Usage: python scripts/bench_se2_checks.py [--slabs K] [--grid-cells N] [--states N] [--reps R] [scenario.toml ...]
"""
import argparse
import math
import os
import statistics
import time

import numpy as np

from cspace import CSpace, SE2CSpace, load_scenario

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT = ["theta.toml", "u_robot.toml", "maze.toml"]


def interleaved(fns, batch, reps):
    """Median over reps of the mean time per call, the functions' batches interleaved."""
    times = [[] for _ in fns]
    for _ in range(reps):
        for t, fn in zip(times, fns):
            t0 = time.perf_counter()
            for q in batch:
                fn(q)
            t.append((time.perf_counter() - t0) / len(batch))
    return [statistics.median(t) for t in times]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    ap.add_argument("--slabs", type=int, default=None)
    ap.add_argument("--grid-cells", type=int, default=None)
    ap.add_argument("--states", type=int, default=20000)
    ap.add_argument("--motions", type=int, default=300)
    ap.add_argument("--reps", type=int, default=5)
    args = ap.parse_args()
    for name in args.scenarios:
        path = name if os.path.exists(name) else os.path.join(ROOT, "scenarios", name)
        sc = load_scenario(path)
        se2 = SE2CSpace.from_scenario(sc, slabs=args.slabs, grid_cells=args.grid_cells)
        cs = CSpace.from_scenario(sc)
        t0 = time.perf_counter()
        for k in range(se2.slabs):
            se2.slab(k)
        build = time.perf_counter() - t0
        xmin, xmax, ymin, ymax = sc.bounds
        rng = np.random.default_rng(0)
        states = [(float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)), float(rng.uniform(-math.pi, math.pi)))
                  for _ in range(args.states)]
        before = dict(se2.checks)
        t_tr, t_se2 = interleaved([cs.point_test(state=True), se2.pose_test(state=True)], states, args.reps)
        exact = (se2.checks["exact_states"] - before["exact_states"]) / (args.reps * len(states))
        motions = []
        for _ in range(args.motions):
            q0 = states[int(rng.integers(len(states)))]
            d = rng.normal(size=3) * np.array([0.05 * (xmax - xmin), 0.05 * (ymax - ymin), 0.5])
            q1 = (min(max(q0[0] + d[0], xmin), xmax), min(max(q0[1] + d[1], ymin), ymax),
                  (q0[2] + d[2] + math.pi) % (2 * math.pi) - math.pi)
            motions.append((q0, q1))
        before = dict(se2.checks)
        m_tr, m_se2 = interleaved([lambda m: cs.segment_free(m[0][:2], m[1][:2]), lambda m: se2.motion_free(m[0], m[1])],
                                  motions, args.reps)
        c = {k: (se2.checks[k] - before[k]) // args.reps for k in se2.checks}
        ok = sum(se2.motion_free(a, b) for a, b in motions)
        print(f"{os.path.basename(path)}: {se2.slabs_reason}")
        print(f"  slabs built in {build:.2f} s ({build / se2.slabs * 1e3:.0f} ms each)")
        print(f"  state: translation {t_tr * 1e6:.2f} us, SE(2) {t_se2 * 1e6:.2f} us, ratio {t_se2 / t_tr:.2f}; "
              f"exact-test share {100 * exact:.1f} %")
        print(f"  motion: translation {m_tr * 1e3:.3f} ms, SE(2) {m_se2 * 1e3:.3f} ms, ratio {m_se2 / m_tr:.1f}; "
              f"accepted {ok}/{len(motions)}; per run: slab-certified sub-motions {c['slab_certified']}, "
              f"refined {c['refined']}, sweeps {c['sweeps']}, floor decisions {c['motion_floor']}")


if __name__ == "__main__":
    main()
