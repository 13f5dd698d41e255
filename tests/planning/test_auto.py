"""``auto`` (planners/core/auto.py), the default for rotating robots and cars: it answers every
bundled scene, its paths pass the independent sweep (scripts/sweep_oracle.py, shapely: not the
C-space that certified them), its "proven unsolvable" carries a proof the independent checker
accepts, it answers wherever RRTConnect or exact does, and it says which stage answered.
"""
from __future__ import annotations

import glob
import json
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings, strategies as st

import planners
from conftest import SCENARIOS, load_script
from cspace.car.curves import reeds_shepp_segments
from cspace.io.load import load_scenario, scenario_from_dict
from planners.cli import main
from planners.core.auto import STAGES
from planners.core.proof_check import check_proof

ROTATING = sorted(glob.glob(os.path.join(SCENARIOS, "se2", "*.toml"))) + \
    sorted(glob.glob(os.path.join(SCENARIOS, "car", "*.toml")))
oracle = load_script("sweep_oracle")


def judged_free(sc, path) -> bool:
    """The independent sweep: SE(2) motions as OMPL interpolates them, a car's along its curves."""
    if sc.turning_radius is not None:
        f = (lambda a, b: reeds_shepp_segments(a, b, sc.turning_radius)) if sc.space == "reeds-shepp" else None
        if f is None:
            from cspace.car.curves import dubins_segments

            f = lambda a, b: dubins_segments(a, b, sc.turning_radius)  # noqa: E731
        j = oracle.car_sweep_check(sc, path, f, sc.turning_radius)
    else:
        j = oracle.sweep_check(sc, path)
    return not j["collides"] and not j["out_of_bounds"]


def assert_sound(sc, res, query_index: int = 0):
    """A path the sweep accepts from the exact start to the exact goal, or a proof the checker accepts."""
    assert res.planner == "auto", res.planner
    assert (res.answered_by in STAGES) == (res.solved or res.proven_unsolvable), (res.answered_by, res.message)
    if res.solved:
        assert tuple(res.path[0]) == tuple(res.start) and tuple(res.path[-1]) == tuple(res.goal)
        assert judged_free(sc, res.path), res.message
    elif res.proven_unsolvable:
        assert res.proof is not None, res.message
        verdict = check_proof(sc, res.proof, query_index)
        assert verdict.valid, verdict


# parallel_tight (2-6 s: its slab graph asks for room three times) in the slow pass.
@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.slow) if p.endswith("parallel_tight.toml") else p
                                  for p in ROTATING], ids=lambda p: "/".join(p.split(os.sep)[-2:]))
def test_the_default_answers_every_bundled_rotating_scene(path):
    sc = load_scenario(path)
    res = planners.plan(path)  # no planner named: auto
    assert res.answered_by is not None, res.message
    assert res.solved or res.proven_unsolvable, res.message
    assert res.solved == (sc.expect != "unsolvable")
    assert_sound(sc, res)
    stages = res.timings
    assert set(res.stages) >= {res.answered_by} and all(stages[s] >= 0 for s in STAGES if s in stages)
    assert stages["solve"] >= max(stages.get(s, 0.0) for s in STAGES)


def test_a_translating_robot_keeps_rrtconnect_and_auto_answers_it_too():
    basic = os.path.join(SCENARIOS, "basic.toml")
    assert planners.plan(basic).planner == "RRTConnect"
    res = planners.plan(basic, planner="auto", seed=3)
    assert res.solved and res.answered_by in ("sampling", "refinement")
    closed = planners.plan(os.path.join(SCENARIOS, "narrow_closed.toml"), planner="auto")
    assert closed.proven_unsolvable and closed.answered_by == "proof" and not closed.solved


def test_same_scene_same_seed_same_path():
    for name in ("se2/bug_trap.toml", "car/parking.toml", "se2/door_tight.toml"):
        a, b = (planners.plan(os.path.join(SCENARIOS, *name.split("/")), seed=5) for _ in range(2))
        assert a.answered_by == b.answered_by and np.array_equal(a.path, b.path), name


def _door(gap: float, length: float, offset: float, theta: float) -> dict:
    """A wall across a 10 x 10 box with a door of width ``gap`` at height 5 + offset; a bar
    ``length`` x 0.3 crossing from left to right, starting at angle ``theta``."""
    lo, hi = 5 + offset - gap / 2, 5 + offset + gap / 2
    return {"name": "door", "space": "se2", "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
            "robot": {"polygon": [[-length / 2, -0.15], [length / 2, -0.15], [length / 2, 0.15],
                                  [-length / 2, 0.15]]},
            "start": {"x": 2.0, "y": 5.0, "theta": theta}, "goal": {"x": 8.0, "y": 5.0, "theta": 0.0},
            "obstacles": [{"polygon": [[4.8, 0], [5.2, 0], [5.2, lo], [4.8, lo]]},
                          {"polygon": [[4.8, hi], [5.2, hi], [5.2, 10], [4.8, 10]]}]}


@settings(max_examples=8, deadline=None, suppress_health_check=list(HealthCheck),
          phases=(Phase.explicit, Phase.reuse, Phase.generate))  # no shrinking: each example plans for seconds
@given(gap=st.floats(0.2, 0.6), length=st.floats(0.5, 2.5), offset=st.floats(-2, 2),
       theta=st.floats(-math.pi, math.pi - 1e-6))
def test_auto_answers_wherever_rrtconnect_or_exact_does(gap, length, offset, theta):
    sc = scenario_from_dict(_door(gap, length, offset, theta))
    auto = planners.plan(sc, planner="auto", time=60.0)
    assert_sound(sc, auto)
    if auto.solved or auto.proven_unsolvable:
        return
    exact = planners.plan(sc, planner="exact", time=60.0)
    rrt = planners.plan(sc, planner="RRTConnect", time=60.0, iterations=20_000)
    assert not (exact.solved or exact.proven_unsolvable or rrt.solved), (auto.message, exact.message)


def test_the_cli_says_which_stage_answered_and_writes_its_proof(tmp_path, capsys):
    door, trap = os.path.join(SCENARIOS, "se2", "door_tight.toml"), os.path.join(SCENARIOS, "se2", "bug_trap_l.toml")
    js = tmp_path / "r.json"
    assert main(["plan", door, "--json", str(js)]) == 0
    out = capsys.readouterr().out
    d = json.loads(js.read_text())
    # a door 1 % wider than the box: the first slice of sampling fails, the exact refinement answers
    assert d["planner"] == "auto" and d["answered_by"] == "refinement"
    assert {"sampling", "slab graph", "proof", "refinement"} <= set(d["timings"])
    assert "solved by auto (refinement)" in out and "seed" not in out.splitlines()[0]
    proof = tmp_path / "p.json"
    assert main(["plan", trap, "--proof", str(proof), "--json", str(js)]) == 1
    assert json.loads(js.read_text())["proven_unsolvable"] is True
    capsys.readouterr()
    assert main(["check-proof", trap, str(proof)]) == 0
    assert capsys.readouterr().out.startswith("proof valid")


def test_a_sampled_answer_names_its_seed():
    res = planners.plan(os.path.join(SCENARIOS, "se2", "bug_trap.toml"), seed=7)
    from planners.pictures.titles import plan_title, planner_words

    if res.answered_by == "sampling":
        assert planner_words(res) == "auto (sampling, seed 7)" and "seed 7" in plan_title("s", res)
    else:
        assert "seed" not in planner_words(res)


def _corridor(slack: float) -> dict:
    """A car 0.6 x 0.4 in a corridor ``slack`` longer than the car, to be moved 2 sideways."""
    lo, hi = 5.0 - 0.3 - slack / 2, 5.0 + 0.3 + slack / 2
    return {"name": "corridor", "space": "reeds-shepp", "turning_radius": 0.5,
            "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
            "robot": {"polygon": [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]]},
            "start": {"x": 5.0, "y": 3.0, "theta": 0.0}, "goal": {"x": 5.0, "y": 5.0, "theta": 0.0},
            "obstacles": [{"polygon": [[0, 0], [lo, 0], [lo, 10], [0, 10]]},
                          {"polygon": [[hi, 0], [10, 0], [10, 10], [hi, 10]]}]}


@pytest.mark.parametrize("slack,parts", [(0.4, 3), pytest.param(0.2, 1, marks=pytest.mark.slow),
                                         pytest.param(0.3, 2, marks=pytest.mark.slow)])
def test_laumond_curves_follow_a_sideways_path_and_pass_the_sweep(slack, parts):
    """A car can't drive sideways, but it can follow a sideways SE(2) path closely enough with
    many short Reeds–Shepp curves: every curve passes the independent sweep."""
    from cspace.car.laumond import to_reeds_shepp
    from planners.core.plan import build_cspace

    sc = scenario_from_dict(_corridor(slack))
    cs = build_cspace(sc)
    se2 = np.array([[5.0, 3.0 + 2.0 * k / parts, 0.0] for k in range(parts + 1)])
    out = to_reeds_shepp(cs, se2, 0.5)
    assert out is not None
    assert tuple(out[0]) == (5.0, 3.0, 0.0) and tuple(out[-1]) == (5.0, 5.0, 0.0)
    assert judged_free(sc, out)
    # the judge is not blind: one curve for the whole move swings into a wall
    assert not judged_free(sc, se2[[0, -1]])


def test_laumond_converts_where_the_room_is_a_hundredth_of_the_car():
    from cspace.car.laumond import to_reeds_shepp
    from planners.core.plan import build_cspace

    cs = build_cspace(scenario_from_dict(_corridor(0.02)))
    out = to_reeds_shepp(cs, np.array([[5.0, 3.0, 0.0], [5.0, 5.0, 0.0]]), 0.5)
    assert out is not None and len(out) > 1000
    assert all(cs.car_motion_free(tuple(a), tuple(b), "reeds-shepp", 0.5) for a, b in zip(out[:-1], out[1:]))


def test_laumond_gives_up_within_its_budget_rather_than_return_a_colliding_curve():
    from cspace.car.laumond import to_reeds_shepp
    from planners.core.plan import build_cspace

    cs = build_cspace(scenario_from_dict(_corridor(0.05)))
    through = np.array([[5.0, 3.0, 0.0], [5.0, 5.0, 0.0]])
    assert to_reeds_shepp(cs, through, 0.5, max_checks=10) is None
    assert to_reeds_shepp(cs, through, 0.5, max_depth=2) is None


def test_a_long_sideways_translation_is_driven_along_its_way_where_the_car_can_turn():
    """The slab graph translates at its slab's angle, often across the way it goes: 8 m sideways
    in a corridor is a chain of parking manoeuvres; turned in place to the way it goes (where the
    corridor lets it turn: the car's diagonal 0.72 < 1.0), then driven, it is a few curves; the
    path passes the independent sweep. Where the car cannot turn (0.65 wide), the path is kept."""
    from cspace.car.laumond import along_travel, to_reeds_shepp
    from planners.core.plan import build_cspace

    sideways = np.array([[5.0, 1.0, 0.0], [5.0, 9.0, 0.0]])
    sc = scenario_from_dict(_corridor(0.4))
    cs = build_cspace(sc)
    turned = along_travel(cs, sideways, 0.5)
    assert turned[:, :2].tolist() == [[5.0, 1.0], [5.0, 1.0], [5.0, 9.0], [5.0, 9.0]]
    assert abs(abs(turned[1, 2]) - np.pi / 2) < 1e-12 and turned[1, 2] == turned[2, 2]
    direct, aligned = to_reeds_shepp(cs, sideways, 0.5), to_reeds_shepp(cs, turned, 0.5)
    assert direct is not None and aligned is not None and len(aligned) * 4 < len(direct), (len(aligned), len(direct))
    assert judged_free(sc, aligned)
    narrow = build_cspace(scenario_from_dict(_corridor(0.05)))
    assert along_travel(narrow, sideways, 0.5).tolist() == sideways.tolist()


def test_given_iterations_auto_s_turns_of_sampling_count_them_not_time(monkeypatch):
    # The short turn of sampling is timed (a share of what is left); with --iterations each turn is
    # bounded by its count alone, so which stage answers does not depend on the machine's speed.
    import planners.core.routine as routine
    from planners.core.auto import FIRST_ITERATIONS, SLICE_ITERATIONS

    seen = []
    real = routine.run_planner
    monkeypatch.setattr(routine, "run_planner", lambda *a, **k: seen.append((a[3], k.get("iterations"))) or real(*a, **k))
    res = planners.plan(os.path.join(SCENARIOS, "se2", "door_tight.toml"), seed=0, iterations=40, time=1000.0)
    assert res.solved and len(seen) >= 2, (res.message, seen)  # the slice and the short turn at least
    assert all(budget > 500 for budget, _ in seen), seen  # the time left, never a short share of it
    # (a small scene: the slice in two parts, the proof between them, then the turn)
    assert [it for _, it in seen][:3] == [FIRST_ITERATIONS, SLICE_ITERATIONS - FIRST_ITERATIONS, 40], seen


SE2 = sorted(glob.glob(os.path.join(SCENARIOS, "se2", "*.toml")))


def _turns(monkeypatch) -> list:
    """The iteration budgets of the sampling turns ``auto`` asks for, in order."""
    import planners.core.routine as routine

    seen = []
    real = routine.run_planner
    monkeypatch.setattr(routine, "run_planner", lambda *a, **k: seen.append(k.get("iterations")) or real(*a, **k))
    return seen


@pytest.mark.parametrize("name", ["bug_trap_l", "wide_square"])
def test_a_small_impossible_scene_is_proven_after_half_a_slice(name, monkeypatch):
    # On a small scene the POSSIBLE graph at the first 8 slabs comes before the slice's rest: a scene
    # it separates is answered by the proof, after the slice's first part only.
    from planners.core.auto import FIRST_ITERATIONS, small_scene
    from planners.core.plan import build_cspace

    path = os.path.join(SCENARIOS, "se2", f"{name}.toml")
    sc = load_scenario(path)
    assert small_scene(sc, build_cspace(sc))
    turns = _turns(monkeypatch)
    res = planners.plan(path, seed=0)
    assert res.proven_unsolvable and res.answered_by == "proof", res.message
    assert turns == [FIRST_ITERATIONS] and "slab graph" not in res.timings and "refinement" not in res.timings
    assert_sound(sc, res)


def test_an_open_small_scene_is_answered_by_the_slice_s_first_part_before_any_region(monkeypatch):
    from planners.core.auto import FIRST_ITERATIONS
    from planners.core.exact_se2 import built_regions

    turns = _turns(monkeypatch)
    path = os.path.join(SCENARIOS, "se2", "bar_door.toml")
    res = planners.plan(path, seed=0)
    assert res.solved and res.answered_by == "sampling" and turns == [FIRST_ITERATIONS], (res.message, turns)
    assert set(res.stages) & set(STAGES) == {"sampling"} and built_regions(res.cspace)["regions"] == 0
    assert_sound(load_scenario(path), res)


def test_the_turn_after_the_first_slabs_continues_the_slice_s_search(monkeypatch):
    # plank_corner at seed 2: RRTConnect needs more than the slice's 1 000 iterations and fewer than
    # the slice and the turn together; the turn continues the slice's trees, so auto's path is the
    # path of one RRTConnect run of that many iterations (the same seed), not of a fresh start.
    from planners.core.auto import FIRST_ITERATIONS, SLICE_ITERATIONS, TURN_ITERATIONS

    path = os.path.join(SCENARIOS, "se2", "plank_corner.toml")
    alone = planners.plan(path, planner="RRTConnect", seed=2, iterations=SLICE_ITERATIONS + TURN_ITERATIONS,
                          simplify=False, time=100.0)
    short = planners.plan(path, planner="RRTConnect", seed=2, iterations=SLICE_ITERATIONS, simplify=False, time=100.0)
    assert alone.solved and not short.solved  # the scene and seed are as the test needs
    turns = _turns(monkeypatch)
    res = planners.plan(path, seed=2, simplify=False, time=100.0)
    assert res.answered_by == "sampling", (res.message, turns)
    assert turns == [FIRST_ITERATIONS, SLICE_ITERATIONS - FIRST_ITERATIONS, TURN_ITERATIONS], turns
    assert np.array_equal(res.path, alone.path)
    assert set(res.stages) & set(STAGES) == {"proof", "slab graph", "sampling"}


# the scenes whose checks take over a second (the sweep of a long path, the exact search) in the slow pass
SLOW_SE2 = ("car_maze", "door_tight", "hole_turn", "plank_corner_tight", "tee_slot")


@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.slow) if os.path.basename(p)[:-5] in SLOW_SE2
                                  else p for p in SE2], ids=lambda p: os.path.basename(p)[:-5])
def test_on_every_bundled_se2_scene_auto_answers_where_rrtconnect_or_exact_does(path):
    # exact's answer, and RRTConnect's within the iterations auto's turns give it: auto answers
    # too, and before its refinement where RRTConnect alone did within the slice and the turn.
    from planners.core.auto import SLICE_ITERATIONS, TURN_ITERATIONS

    from cspace.se2.exact import from_scenario

    sc = load_scenario(path)
    exact = from_scenario(sc, time_limit=100.0).status  # the slab graph's search, no shortening or measure
    rrt = planners.plan(path, planner="RRTConnect", seed=1, iterations=SLICE_ITERATIONS + TURN_ITERATIONS, time=100.0)
    res = planners.plan(path, seed=1, time=100.0)
    assert_sound(sc, res)
    assert res.solved or not (exact == "solved" or rrt.solved), res.message
    assert res.proven_unsolvable or not (exact == "unsolvable" or rrt.proven_unsolvable), res.message
    if rrt.solved:  # every stage before the refinement that could answer did: sampling's turns are enough
        assert res.answered_by in ("sampling", "slab graph"), res.answered_by


@pytest.mark.parametrize("name, direct", [("u_turn_cusps.toml", True), ("parking.toml", False)])
def test_a_car_tries_its_direct_curve_first(name, direct):
    """A car whose one shortest curve from start to goal is free is answered by it (stage 0, one
    curve check, no sampling); the path passes the sweep. Where that curve is not free, the
    slice of sampling answers as before."""
    sc = load_scenario(os.path.join(SCENARIOS, "car", name))
    res = planners.plan(sc, seed=0, time=10.0, simplify=False)
    assert res.solved and res.answered_by == "sampling"
    assert ("direct curve" in res.message) == direct, res.message
    if direct:
        assert len(res.path) == 2 and tuple(res.path[0]) == tuple(sc.start) and tuple(res.path[-1]) == tuple(sc.goal)
    assert judged_free(sc, np.asarray(res.path))


def test_a_car_s_later_turns_of_sampling_draw_their_own_samples(monkeypatch):
    # Run with the query's seed, the short turn after a failed slice replayed the slice's first
    # iterations (the same tree, the same failure) before it drew anything new: a car's later turns
    # get seeds of their own, derived from the query's, so the same seed still gives the same path.
    import planners.core.auto as auto
    import planners.core.routine as routine

    seeds = []
    real = routine.run_planner
    monkeypatch.setattr(routine, "run_planner", lambda *a, **k: seeds.append(a[4]) or real(*a, **k))
    monkeypatch.setattr(auto, "SLICE_ITERATIONS", 2)  # a slice that cannot answer
    scene = os.path.join(SCENARIOS, "car", "maze.toml")  # a Dubins car: the slice, then restarts and proofs
    paths = []
    for _ in range(2):
        seeds.clear()
        res = planners.plan(scene, seed=3, iterations=3000, time=1000.0)
        assert res.solved and res.answered_by == "sampling" and res.seed == 3, res.message
        assert seeds[0] == 3 and seeds[1:] and all(s != 3 for s in seeds[1:]), seeds
        # each later turn its own seed (a Dubins car's restarts: turns 3, 4, ...; planners/core/auto_dubins.py)
        assert seeds[1:] == [auto.turn_seed(3, t) for t in range(3, 2 + len(seeds))], seeds
        paths.append(res.path)
    assert np.array_equal(*paths)


def test_the_shortcut_finds_a_far_pose_one_curve_reaches_past_refused_near_ones():
    # Which later poses one curve reaches is not monotone: a sideways shift is one S-shaped curve
    # end to end where its short pieces are tiny parking manoeuvres that graze a wall (the
    # warehouse's pair 60: 2 125 curves of 6 mm kept 2 068 when the search galloped up from the
    # nearest pose and stopped at the first refusal). A stand-in C-space answers which are free.
    from cspace.car.laumond import shortcut

    poses = np.array([[0.1 * k, 0.0, 0.0] for k in range(41)])
    asked = []

    class Stub:
        def car_motion_free(self, a, b, kind, radius):
            i, j = round(a[0] * 10), round(b[0] * 10)
            asked.append((i, j))
            return j - i == 1 or (i == 0 and 15 <= j <= 35) or (i == 35 and j == 40)

    out = shortcut(Stub(), poses, 0.5)
    assert out.tolist() == [poses[0].tolist(), poses[35].tolist(), poses[40].tolist()]
    assert len(asked) < 40  # from the far end down, then bisected: a few checks per kept pose
