"""Rotating robots (SE(2)): validity and motion checks inside OMPL against peers, and plans.

(V) Validity of a state inside OMPL. For each scene, ``si.probabilityOfValidState(N)``
    (OMPL's own C++ loop: N uniform states from its sampler, one checker call each) is
    timed for: a no-op callback; ours (the sliced C-space's pose test, as
    ``planners.adapters.se2.SE2Space.validity()`` installs it); a shapely checker that
    rotates and translates the robot to the state (``shapely.affinity`` on the robot
    polygon, then ``STRtree.query`` and prepared ``intersects``); and, on a 2-D
    ``RealVectorStateSpace`` over the same scene, the translation checker (the robot at
    theta = 0, ``TranslationSpace.validity()``) -- the cost a state had before robots
    could turn. Rounds are interleaved, CPU time; medians of per-round ratios.
    Targets: ours <= 3x the translation checker; shapely >= 10x ours.
(M) Motions. M seeded random motions between valid states (second state within OMPL's
    default range, 0.2 x the space's maximum extent). Ours: ``SE2CSpace.motion_free``
    (certified along the whole motion). Baseline: OMPL's default discrete motion
    validator with the shapely checker at its default resolution (1 % of the space's
    extent), ``si.checkMotion``. Timed per motion, interleaved, medians. Every motion
    either accepts is then judged by an independent shapely sweep
    (``scripts/sweep_oracle.py``: the robot's hull between poses 2e-3 rad apart, padded
    by the arc's sagitta): "collides" when a sampled pose meets an obstacle, or the
    padded sweep does and a 100x finer pose sampling finds the contact.
    Targets: ours accepts 0 colliding motions; ours costs <= the baseline per motion.
(T) Time to first solution: every bundled SE(2) scene (scenarios/se2/*.toml) except
    those expected unsolvable, RRTConnect, 10 seeds, 10 s each, through
    ``planners.plan`` (the routine of ``cspace plan``); solved count, median solve time,
    median path length, and each path judged by the sweep oracle.
(P) Side by side (``--peers shapely,coal``): ours (the proof before sampling, then the
    planning routine stopped at its first certified path) against OMPL's planner with a
    shapely or a coal state checker and its default discrete motion check, on SE(2) scenes,
    generated ones and the car scenes; per seed every method once (interleaved), CPU time to
    the first solution, paired median ratios. The sweep oracle judges every returned path
    after the timed runs (a car's along its curves); "(sound)" is the paired ratio over the
    seeds whose peer path it passes. A seed whose runs all take under 0.1 s is run three
    times per method (interleaved) and the median taken (``--repeats``). ``--peer-resolution``
    sets the peers' motion-check step (a finer one tunnels less, and costs more).

Usage: python scripts/bench_se2.py [--quick] [--parts VMTP] [--peers shapely,coal] [--scenes WORDS]
                                   [--peer-resolution STEP] [--json FILE]
(--json is checked before any work, never over a bundled scene, and written atomically.)
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
sys.path.insert(0, HERE)
sys.path.insert(0, ROOT)

from sweep_oracle import sweep_check  # noqa: E402

from cspace.translation.cspace import CSpace  # noqa: E402
from cspace.io.load import load_scenario  # noqa: E402
from cspace.se2.cspace import SE2CSpace  # noqa: E402

SE2_DIR = os.path.join(ROOT, "scenarios", "se2")
VALIDITY_SCENES = ("car_maze.toml", "bug_trap.toml", "piano_corridor.toml")


def shapely_se2_checker(sc):
    """The peer: ``state -> bool``: the robot rotated and translated by shapely, STRtree + prepared
    intersects (``se2_peers.shapely_checker``, which part P uses too)."""
    import se2_peers

    return se2_peers.shapely_checker(sc)


def _si(space_adapter, checker=None, validator: str = "ours"):
    """OMPL's SpaceInformation over the adapter's state space, set up, and what must outlive it.

    ``checker``: the state validity checker (default: the adapter's own). ``validator``:
    "ours" (the adapter's certified motion validator), "discrete" (OMPL's default, states
    sampled along the motion) or "dubins" (OMPL's ``DubinsMotionValidator``). Returns
    ``(si, keep)``, ``keep[1]`` being the state space.
    """
    from planners.adapters.glue import ompl

    ob, og, ou = ompl()
    ou.RNG.setSeed(1)
    space = space_adapter.state_space()
    ss = og.SimpleSetup(space)
    si = ss.getSpaceInformation()
    ss.setStateValidityChecker(checker or space_adapter.validity())
    keep = [ss, space]
    if validator == "ours":
        mv = space_adapter.motion_validator(si)
    elif validator == "dubins":
        mv = ob.DubinsMotionValidator(si)
    elif validator == "discrete":
        mv = None
    else:
        raise ValueError(f"validator: expected 'ours', 'discrete' or 'dubins', got {validator!r}")
    if mv is not None:
        si.setMotionValidator(mv)
        keep.append(mv)
    si.setup()
    return si, keep


def part_v(n: int, reps: int) -> list[dict]:
    from planners.adapters.se2 import SE2Space
    from planners.adapters.translation import TranslationSpace

    rows = []
    for name in VALIDITY_SCENES:
        sc = load_scenario(os.path.join(SE2_DIR, name))
        se2 = SE2CSpace.from_scenario(sc, slabs=sc.slabs)
        ours_space = SE2Space(se2)
        si, keep = _si(ours_space)
        tcs = CSpace(sc.bounds, [o.polygon for o in sc.obstacles], [r.polygon for r in sc.robot],
                     obstacle_holes=[o.holes for o in sc.obstacles])
        tspace = TranslationSpace(tcs)
        tsi, tkeep = _si(tspace)
        checkers = {"noop": (si, lambda s: True), "ours": (si, ours_space.validity()),
                    "shapely": (si, shapely_se2_checker(sc)), "translation": (tsi, tspace.validity())}
        sizes = {"noop": n, "ours": n, "shapely": max(n // 20, 200), "translation": n}
        # warm-up: builds every slab the sampler reaches
        for key, (s_i, fn) in checkers.items():
            s_i.setStateValidityChecker(fn)
            s_i.probabilityOfValidState(max(sizes[key] // 4, 200) if key != "ours" else 20 * n)
        per = {k: [] for k in checkers}
        frac = {}
        for _ in range(reps):
            for key, (s_i, fn) in checkers.items():
                s_i.setStateValidityChecker(fn)
                t = time.process_time()
                frac[key] = s_i.probabilityOfValidState(sizes[key])
                per[key].append((time.process_time() - t) / sizes[key])
        ratio = lambda a, b: statistics.median(x / y for x, y in zip(per[a], per[b]))  # noqa: E731
        rows.append({
            "scene": sc.name, "slabs": se2.slabs, "slabs_built": len(se2._built),
            "us_per_state": {k: 1e6 * statistics.median(v) for k, v in per.items()},
            "valid_fraction": frac,
            "ours_over_translation": ratio("ours", "translation"),
            "shapely_over_ours": ratio("shapely", "ours"),
            "ours_over_noop": ratio("ours", "noop"),
        })
    return rows


def random_motions(sc, cs, m: int, seed: int):
    """m motions between free poses, the second within 0.2 x the SE(2) maximum extent."""
    rng = np.random.default_rng(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    reach = 0.2 * (math.hypot(xmax - xmin, ymax - ymin) + 0.5 * math.pi)
    out = []
    while len(out) < m:
        a = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if not cs.is_free(a):
            continue
        d = rng.normal(size=3)
        d *= rng.uniform(0, reach) / np.linalg.norm(d)
        b = (min(max(a[0] + d[0], xmin), xmax), min(max(a[1] + d[1], ymin), ymax),
             math.remainder(a[2] + d[2] / 0.5, 2 * math.pi))
        if b[2] >= math.pi:
            b = (b[0], b[1], -math.pi)
        if cs.is_free(b):
            out.append((a, b))
    return out


def part_m(m: int) -> list[dict]:
    from planners.adapters.se2 import SE2Space

    rows = []
    for name in VALIDITY_SCENES:
        sc = load_scenario(os.path.join(SE2_DIR, name))
        cs = SE2CSpace.from_scenario(sc, slabs=sc.slabs)
        motions = random_motions(sc, cs, m, seed=7)
        base_space = SE2Space(cs)
        si, keep = _si(base_space, checker=shapely_se2_checker(sc), validator="discrete")
        space = keep[1]
        s1, s2 = space.allocState(), space.allocState()
        t_ours, t_base, ours_ok, base_ok = [], [], [], []
        for i, (a, b) in enumerate(motions):
            base_space.set_state(s1, a)
            base_space.set_state(s2, b)
            for who in ((0, 1) if i % 2 else (1, 0)):
                t = time.process_time()
                if who == 0:
                    ours_ok.append(cs.motion_free(a, b))
                    t_ours.append(time.process_time() - t)
                else:
                    base_ok.append(bool(si.checkMotion(s1, s2)))
                    t_base.append(time.process_time() - t)
        judge = {}

        def collides(k):
            if k not in judge:
                path = np.array(motions[k])
                r = sweep_check(sc, path)
                if r["collides"] and not r["certain"]:
                    r = sweep_check(sc, path, dtheta=2e-5, dxy=1e-5 * (sc.bounds[1] - sc.bounds[0]))
                judge[k] = bool(r["certain"])
            return judge[k]

        ours_bad = sum(1 for k, ok in enumerate(ours_ok) if ok and collides(k))
        base_bad = sum(1 for k, ok in enumerate(base_ok) if ok and collides(k))
        rows.append({
            "scene": sc.name, "motions": m,
            "us_per_motion": {"ours": 1e6 * statistics.median(t_ours), "baseline": 1e6 * statistics.median(t_base)},
            "mean_us_per_motion": {"ours": 1e6 * statistics.fmean(t_ours), "baseline": 1e6 * statistics.fmean(t_base)},
            "accepted": {"ours": sum(ours_ok), "baseline": sum(base_ok)},
            "accepted_colliding": {"ours": ours_bad, "baseline": base_bad},
            "floor_decisions": cs.checks.get("motion_floor", 0),
        })
    return rows


def solve_runs(sc, seeds: int, budget: float, collides, **plan_kw) -> tuple:
    """``planners.plan`` on ``sc`` with seeds 0 .. seeds - 1 (the C-space built once):
    ``(solved, solve times, lengths, paths that collides(path) judges colliding)``."""
    from planners import plan

    times, lengths, solved, bad = [], [], 0, 0
    cs = None
    for seed in range(seeds):
        res = plan(sc, time=budget, seed=seed, cspace=cs, **plan_kw)
        cs = res.cspace
        if res.solved:
            solved += 1
            times.append(res.timings["solve"])
            lengths.append(res.length)
            bad += bool(collides(res.path))
    return solved, times, lengths, bad


def part_t(seeds: int, budget: float) -> list[dict]:
    rows = []
    for f in sorted(glob.glob(os.path.join(SE2_DIR, "*.toml"))):
        sc = load_scenario(f)
        if sc.expect == "unsolvable":
            continue
        solved, times, lengths, bad = solve_runs(sc, seeds, budget, lambda path: sweep_check(sc, path)["collides"],
                                                 planner="RRTConnect")
        rows.append({"scene": sc.name, "solved": solved, "seeds": seeds,
                     "median_solve_s": statistics.median(times) if times else None,
                     "median_length": statistics.median(lengths) if lengths else None,
                     "colliding_paths": bad})
    return rows


CAR = [[-0.6, -0.25], [0.5, -0.25], [0.7, -0.1], [0.7, 0.1], [0.5, 0.25], [-0.6, 0.25]]  # a car-shaped body


def generated(kind: str, size: int, robot: list, scale: float, seed: int = 0):
    """A generated scene (``cspace generate``) for a rotating robot of ``robot`` x ``scale``; the
    first seed from ``seed`` whose start and goal are free for it."""
    import tomllib

    from cspace.io.load import ScenarioError, scenario_from_dict
    from planners.cli.generate import generate

    for s in range(seed, seed + 50):
        data = tomllib.loads(generate(kind, seed=s, size=size))
        data["robot"] = {"polygon": [[scale * x, scale * y] for x, y in robot]}
        data["space"] = "se2"
        data["name"] = f"{kind}-{size}-car"
        try:
            return scenario_from_dict(data, f"<{kind} {size}, seed {s}>")
        except ScenarioError:
            continue
    raise SystemExit(f"no {kind} {size} scene with a free start and goal for the car")


def car_judge(sc):
    """``path -> bool``: a car's path swept along its own curves by the oracle."""
    from sweep_oracle import car_sweep_check

    from cspace.car.curves import dubins_segments, reeds_shepp_segments

    f = dubins_segments if sc.space == "dubins" else reeds_shepp_segments

    def collides(path) -> bool:
        j = car_sweep_check(sc, path, lambda a, b: f(a, b, sc.turning_radius), sc.turning_radius)
        return bool(j["collides"] or j["out_of_bounds"])

    return collides


# Part P: a seed whose runs all took less than this (CPU s) is run `repeats` times per method,
# interleaved, and each method's median taken: at a millisecond, timer noise and the caches'
# state move a single run's time by tens of percent.
REPEAT_BELOW = 0.1


def part_p(seeds: int, budget: float, peers: tuple[str, ...], planner: str = "RRTConnect",
           only: tuple[str, ...] = (), repeats: int = 3, resolution: float | None = None) -> list[dict]:
    """Side by side: ours (certified) against OMPL with shapely and coal checkers (sampled motions),
    RRTConnect, time to the first solution, CPU, interleaved per seed; every path judged by the
    sweep oracle. ``only``: keep the scenes whose name contains one of these words."""
    import se2_peers
    from planners.core.plan import build_cspace, make_adapter

    scenes = [load_scenario(os.path.join(SE2_DIR, f)) for f in
              ("bar_door.toml", "bug_trap.toml", "car_maze.toml", "piano_corridor.toml", "tee_slot.toml")]
    scenes += [generated("random", 40, CAR, 1.5), generated("maze", 8, CAR, 2.0), generated("maze", 14, CAR, 2.0)]
    scenes += [load_scenario(os.path.join(ROOT, "scenarios", "car", f)) for f in
               ("maze.toml", "parking.toml", "loading_dock.toml", "u_turn.toml", "parallel_tight.toml",
                "dead_end_alley.toml", "garage_reverse.toml", "u_turn_cusps.toml")]
    if only:
        scenes = [sc for sc in scenes if any(w in sc.name for w in only)]
    rows = []
    from benchutil import Progress

    progress = Progress(f"bench_se2 (P): {len(scenes)} scenes x {seeds} seeds, ours and {len(peers)} peer{'' if len(peers) == 1 else 's'}, interleaved",
                        len(scenes) * seeds, most_s=budget * (1 + len(peers)), unit="rounds")
    for sc in scenes:
        cs = build_cspace(sc)
        adapter = make_adapter(sc, cs)
        q = sc.all_queries()[0]
        collides = car_judge(sc) if sc.space in ("dubins", "reeds-shepp") else \
            (lambda path, sc=sc: (lambda j: bool(j["collides"] or j["out_of_bounds"]))(sweep_check(sc, path)))
        checkers = {"shapely": se2_peers.shapely_checker(sc)} if "shapely" in peers else {}
        if "coal" in peers:
            checkers["coal"] = se2_peers.coal_checker(cs.obstacle_pieces, cs.robot_pieces, sc.bounds)
        cpu = {m: [] for m in ("ours", *checkers)}
        solved = {m: 0 for m in cpu}
        bad = {m: 0 for m in cpu}
        sound = {m: [] for m in cpu}  # per seed: the path passed the sweep oracle
        found = []

        def one_round(seed):
            runs = {"ours": se2_peers.ours_first(sc, cs, adapter, q, seed, budget, planner)}
            for name, chk in checkers.items():  # auto's peer: OMPL's RRTConnect
                runs[name] = se2_peers.peer_first(adapter, chk, adapter.pose(q.start), adapter.pose(q.goal), seed,
                                                  budget, "RRTConnect" if planner == "auto" else planner, resolution)
            return runs

        for seed in range(seeds):  # interleaved: every method once per round
            rounds = [one_round(seed)]
            if max(c for _, c in rounds[0].values()) < REPEAT_BELOW:
                rounds += [one_round(seed) for _ in range(repeats - 1)]
            for m, (path, _) in rounds[0].items():  # the same seed: the same path in every round
                cpu[m].append(statistics.median(r[m][1] for r in rounds) if path is not None else None)
                found.append((m, path))
            progress.step(f"{sc.name}, seed {seed}")
        # The oracle judges the paths after the timed runs: its sweeps (shapely, ~0.1 s a path)
        # between two runs would flush the caches of whichever method runs next.
        for m, path in found:
            sound[m].append(False)
            if path is not None:
                solved[m] += 1
                hit = collides(path)
                bad[m] += hit
                sound[m][-1] = not hit
        row = {"scene": sc.name if sc.space == "se2" else f"{sc.name} ({sc.space})", "planner": planner, "vertices": sum(len(o.polygon) for o in sc.obstacles), "seeds": seeds,
               "solved": solved, "colliding": bad,
               "median_cpu_s": {m: (statistics.median([c for c in v if c is not None]) if any(c is not None for c in v)
                                    else None) for m, v in cpu.items()}}
        for m in checkers:  # the paired median: seeds both solved (a colliding peer path still counts as solved)
            pairs = [a / b for a, b in zip(cpu["ours"], cpu[m]) if a is not None and b is not None and b > 0]
            row[f"ours/{m}"] = statistics.median(pairs) if pairs else None
            # the same over the seeds whose peer path the oracle passes (a tunnelling peer's are left out)
            fair = [a / b for a, b, ok in zip(cpu["ours"], cpu[m], sound[m]) if a is not None and b and ok]
            row[f"ours/{m} sound"] = statistics.median(fair) if fair else None
        rows.append(row)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer states, motions and seeds")
    ap.add_argument("--parts", default="VMT", help="V validity, M motions, T plans, P side by side with peers")
    ap.add_argument("--peers", default="shapely,coal", help="part P's peers (coal needs the bench extra)")
    ap.add_argument("--planners", default="RRTConnect,RRTstar", help="part P's planners (auto: ours is the "
                                                                     "auto planner, the peers RRTConnect)")
    ap.add_argument("--scenes", default="", help="part P: only the scenes whose name contains one of these "
                                                 "comma-separated words (e.g. parking,loading_dock,u_turn)")
    ap.add_argument("--repeats", type=int, default=3, help="part P: runs per method of a seed whose runs all take "
                                                           f"under {REPEAT_BELOW} s (the median is taken)")
    ap.add_argument("--peer-resolution", type=float, default=None,
                    help="part P: the peers' motion-check step as a fraction of the space's extent "
                         "(default: OMPL's, 0.01); finer steps make a peer tunnel less and cost more")
    ap.add_argument("--json", help="write the figures to this file")
    a = ap.parse_args(argv)
    from benchutil import check_json, write_json

    check_json(a.json, [SE2_DIR, os.path.join(ROOT, "scenarios", "car")])  # (never over a scene)
    out = {}
    if "V" in a.parts:
        out["validity"] = part_v(n=5000 if a.quick else 50000, reps=5 if a.quick else 11)
        print("(V) validity inside OMPL, us per state (median of interleaved rounds, CPU time)")
        print(f"  {'scene':16} {'K':>4} {'built':>5} {'noop':>7} {'transl.':>8} {'ours':>7} {'shapely':>8}"
              f" {'ours/transl.':>12} {'shapely/ours':>12}")
        for r in out["validity"]:
            u = r["us_per_state"]
            print(f"  {r['scene']:16} {r['slabs']:>4} {r['slabs_built']:>5} {u['noop']:7.2f} {u['translation']:8.2f}"
                  f" {u['ours']:7.2f} {u['shapely']:8.2f} {r['ours_over_translation']:12.2f} {r['shapely_over_ours']:12.1f}")
    if "M" in a.parts:
        out["motions"] = part_m(m=100 if a.quick else 500)
        print("(M) motions: ours certified vs OMPL discrete (shapely checker, 1 % resolution), us per motion")
        print(f"  {'scene':16} {'ours':>9} {'baseline':>9} {'ratio':>6} {'acc. ours':>9} {'acc. base':>9}"
              f" {'coll. ours':>10} {'coll. base':>10} {'floor':>6}")
        for r in out["motions"]:
            u, acc, bad = r["us_per_motion"], r["accepted"], r["accepted_colliding"]
            print(f"  {r['scene']:16} {u['ours']:9.1f} {u['baseline']:9.1f} {u['ours'] / u['baseline']:6.2f}"
                  f" {acc['ours']:9} {acc['baseline']:9} {bad['ours']:10} {bad['baseline']:10} {r['floor_decisions']:6}")
    if "T" in a.parts:
        out["plans"] = part_t(seeds=3 if a.quick else 10, budget=10.0)
        print("(T) RRTConnect on the bundled SE(2) scenes, 10 s budget")
        for r in out["plans"]:
            ms = f"{r['median_solve_s']:.3f} s" if r["median_solve_s"] is not None else "-"
            ml = f"{r['median_length']:.3f}" if r["median_length"] is not None else "-"
            print(f"  {r['scene']:16} solved {r['solved']}/{r['seeds']}  median first solution {ms}"
                  f"  median length {ml}  colliding paths {r['colliding_paths']}")
    if "P" in a.parts:
        peers = tuple(p for p in a.peers.split(",") if p)
        if "coal" in peers:
            try:
                import coal  # noqa: F401
            except ImportError:
                print("(P) coal is not installed (pip install coal, or the bench extra): without it")
                peers = tuple(p for p in peers if p != "coal")
        rows = []
        for name in a.planners.split(","):
            rows += part_p(seeds=3 if a.quick else 10, budget=10.0, peers=peers, planner=name,
                           only=tuple(w for w in a.scenes.split(",") if w), repeats=max(1, a.repeats),
                           resolution=a.peer_resolution)
        out["peers"] = rows
        print("(P) side by side, time to the first solution, CPU s (median over solved seeds), paired median ratio;")
        print("    colliding = returned paths the sweep oracle finds colliding (a car's along its curves);")
        print("    (sound) = the paired ratio over the seeds whose peer path the oracle passes;")
        print("    peers' motion-check step: " + ("OMPL's default (1 % of the extent)" if a.peer_resolution is None
                                                   else f"{a.peer_resolution:g} of the extent"))
        print(f"  {'scene':24} {'planner':10} {'verts':>5}" + "".join(f" {m + ' solved':>14} {m + ' s':>10} {m + ' coll.':>11}"
                                                       for m in ("ours", *peers))
              + "".join(f" {'ours/' + m:>13} {'(sound)':>8}" for m in peers))
        for r in rows:
            med = r["median_cpu_s"]
            cells = "".join(f" {r['solved'][m]:>10}/{r['seeds']:<3} {'-' if med[m] is None else f'{med[m]:.4f}':>10}"
                            f" {r['colliding'][m]:>11}" for m in ("ours", *peers))
            ratio = {m: r["ours/" + m] for m in peers}
            fair = {m: r["ours/" + m + " sound"] for m in peers}
            ratios = "".join(f" {'-' if ratio[m] is None else f'{ratio[m]:.2f}':>13}"
                             f" {'-' if fair[m] is None else f'{fair[m]:.2f}':>8}" for m in peers)
            print(f"  {r['scene']:24} {r['planner']:10} {r['vertices']:>5}{cells}{ratios}")
        for name in a.planners.split(","):
            mine = [r for r in rows if r["planner"] == name]
            for m in peers:
                vals = [r["ours/" + m] for r in mine if r["ours/" + m] is not None]
                if vals:
                    print(f"  {name} ours/{m}: median over scenes {statistics.median(vals):.2f}x, worst "
                          f"{max(vals):.2f}x; colliding paths: ours {sum(r['colliding']['ours'] for r in mine)}, "
                          f"{m} {sum(r['colliding'][m] for r in mine)}")
    if a.json:
        write_json(a.json, out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
