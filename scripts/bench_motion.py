"""Motion check against state check, over the checks a real plan makes (issue 23's target: <= 3x).

For each scene (default: the bundled maze and random_polygons), RRTConnect plans it
(``planners.plan``, seeds 0..S-1) with the C-space's validity callback and motion
validator recording every state and every motion OMPL asks about. Those checks are
then replayed, in interleaved rounds timed in process CPU time: the state test
(``CSpace.point_test(state=True)``, what the validity callback is), the motion test
(``CSpace.segment_test()``, what the motion validator calls: the compiled routine
when built, see cspace/compiled/fastpath.py) and the pure-Python motion test (the exact path,
the compiled one's oracle; with CSPACE_PURE=1 both motion columns are pure). Figures:
mean cost per check of each round, medians over rounds, and the median over rounds of
the ratio motion / state. The replayed motion answers are checked equal on both paths.

Usage: python scripts/bench_motion.py [--seeds S] [--reps R] [scenario.toml ...]
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, ROOT)

from cspace import CSpace, load_scenario  # noqa: E402
from cspace.compiled import fastpath  # noqa: E402

DEFAULT = ("maze.toml", "random_polygons.toml")


def record(sc, seed: int):
    """Plan ``sc`` with RRTConnect; the states and motions OMPL checked, and the C-space."""
    import planners

    cs = CSpace.from_scenario(sc)
    states, motions = [], []
    point_test, segment_test = cs.point_test, cs.segment_test

    def recording_point_test(tick=None, state=False):
        f = point_test(tick, state=state)
        if not state:
            return f

        def g(s):
            states.append((s[0], s[1]))
            return f(s)
        return g

    def recording_segment_test():
        f = segment_test()

        def g(ax, ay, bx, by):
            motions.append((ax, ay, bx, by))
            return f(ax, ay, bx, by)
        return g

    cs.point_test, cs.segment_test = recording_point_test, recording_segment_test
    try:
        planners.plan(sc, planner="RRTConnect", seed=seed, cspace=cs)
    finally:
        del cs.point_test, cs.segment_test  # the class's methods again
    return cs, states, motions


def replay(cs, states, motions, reps: int) -> dict:
    """Interleaved rounds: per-check CPU time of states, motions, motions on the pure path."""
    state, motion, pure = cs.point_test(state=True), cs.segment_test(), cs._segment_pure
    got = [motion(*m) for m in motions]
    assert got == [pure(*m) for m in motions], "compiled and pure motion answers differ"
    ts, tm, tp = [], [], []
    clock = time.process_time
    for _ in range(reps):
        t0 = clock()
        for s in states:
            state(s)
        ts.append((clock() - t0) / len(states))
        t0 = clock()
        for ax, ay, bx, by in motions:
            motion(ax, ay, bx, by)
        tm.append((clock() - t0) / len(motions))
        t0 = clock()
        for ax, ay, bx, by in motions:
            pure(ax, ay, bx, by)
        tp.append((clock() - t0) / len(motions))
    med = statistics.median
    return {"states": len(states), "motions": len(motions), "free": sum(got), "state_us": med(ts) * 1e6,
            "motion_us": med(tm) * 1e6, "pure_us": med(tp) * 1e6,
            "ratio": med([m / s for m, s in zip(tm, ts)]), "pure_ratio": med([p / s for p, s in zip(tp, ts)])}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=list(DEFAULT))
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--reps", type=int, default=7)
    a = ap.parse_args(argv)
    print(f"motion check / state check, median over a plan (RRTConnect; compiled path "
          f"{'built' if fastpath.ENABLED else 'NOT built or CSPACE_PURE=1: both columns pure'})")
    print(f"{'scene':>22} {'seed':>4} {'states':>7} {'motions':>7} {'free':>5} {'us/state':>9} "
          f"{'us/motion':>9} {'pure':>8} {'motion/state':>12} {'pure/state':>10}")
    ratios = []
    for name in a.scenarios:
        path = name if os.path.exists(name) else os.path.join(ROOT, "scenarios", name)
        sc = load_scenario(path)
        for seed in range(a.seeds):
            cs, states, motions = record(sc, seed)
            if not states or not motions:
                print(f"{os.path.basename(path):>22} {seed:>4}: no checks recorded")
                continue
            r = replay(cs, states, motions, a.reps)
            ratios.append(r["ratio"])
            print(f"{os.path.basename(path):>22} {seed:>4} {r['states']:>7} {r['motions']:>7} {r['free']:>5} "
                  f"{r['state_us']:>9.2f} {r['motion_us']:>9.2f} {r['pure_us']:>8.1f} {r['ratio']:>12.2f} "
                  f"{r['pure_ratio']:>10.1f}")
    if ratios:
        worst = max(ratios)
        print(f"motion / state: median {statistics.median(ratios):.2f}x, worst plan {worst:.2f}x "
              f"(target <= 3: {'ok' if worst <= 3 else 'MISSED'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
