"""Dubins reach proofs (cspace.car.dubins_reach) and their independent checker
(planners.core.dubins_check): a confined car proven, its proof accepted and every mutation of it
refused; scenes where a forward path exists (built by driving random certified curves) never
proven, and proofs forged for them refused."""
from __future__ import annotations

import ast
import copy
import json
import math
import os
import random

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from car_scenes import room_toml, wall_scene
from cspace.car.curves import advance
from cspace.car.dubins_reach import reach_proof
from cspace.io.load import ScenarioError, load_scenario
from planners.cli import main as cli_main
from planners.core import dubins_check
from planners.core.dubins_check import TooBig, check_dubins_proof
from planners.core.exact_se2 import slab_regions_of
from planners.core.plan import build_cspace

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ALLEY = os.path.join(ROOT, "scenarios", "car", "dead_end_alley.toml")  # the car faces the dead end, 0.45 away


def scene(toml_text: str, tmp_path, name="scene.toml"):
    path = tmp_path / name
    path.write_text(toml_text)
    return str(path)


def prove(sc, **kw):
    cs = build_cspace(sc)
    q = sc.all_queries()[0]
    return cs, [reach_proof(slab_regions_of(cs), q.start, q.goal, sc.turning_radius, backward=b, **kw)
                for b in (False, True)]


@pytest.fixture(scope="module")
def alley():
    sc = load_scenario(ALLEY, space="dubins")
    _, (forward, backward) = prove(sc)
    assert forward is not None  # the car faces the dead end: its forward reach is confined
    return sc, forward


def test_a_car_that_turns_out_only_at_a_radius_14_percent_tighter_is_proven():
    # The reach over-approximates the car: per step of s it gains a slab's width of heading
    # (SLAB_OVER x s / r) where the car turns s / r, so its car turns up to SLAB_OVER tighter, and
    # the cells let it slip sideways. At a slab width of 1.08 s / r this car, facing a wall 1.5
    # ahead that only a radius of 0.86 turns away from, escaped in the reach: no proof, on the
    # warehouse a start facing a rack left "not decided" after 10 s. Its own proof, and the
    # checker's word on it; a wall far enough to turn away from (D = 1.75) is never proven.
    sc = wall_scene(1.5)
    _, (forward, _) = prove(sc)
    assert forward is not None and check_dubins_proof(sc, forward).valid
    _, both = prove(wall_scene(1.75))
    assert both == [None, None]


def test_confined_car_is_proven_and_the_proof_accepted(alley):
    sc, proof = alley
    r = check_dubins_proof(sc, proof)
    assert r.valid, r
    assert proof["format"] == dubins_check.FORMAT and proof["direction"] == "forward"
    reached = [k for k, s in enumerate(proof["slabs"]) if s["cells"]]
    assert 1 < len(reached) < len(proof["slabs"]) // 2  # headings near the start's only
    assert json.loads(json.dumps(proof)) == proof  # plain JSON


def drop_run(p):
    k = max((k for k, s in enumerate(p["slabs"]) if s["cells"]), key=lambda k: len(p["slabs"][k]["cells"]))
    cells = p["slabs"][k]["cells"]
    del cells[len(cells) // 2]


def drop_seed_slab(p):
    k = min(k for k, s in enumerate(p["slabs"]) if s["cells"] and s["a"] <= 0.0 <= s["b"])
    p["slabs"][k]["cells"] = []


def drop_cores(p):
    k = max((k for k, s in enumerate(p["slabs"]) if s["cells"]), key=lambda k: len(p["slabs"][k]["cells"]))
    p["slabs"][k]["cores"] = None


def swell_core(p):
    k = next(k for k, s in enumerate(p["slabs"]) if s["cores"] and s["cores"][0])
    p["slabs"][k]["cores"][0] = [[1.5 * x, 1.5 * y] for x, y in p["slabs"][k]["cores"][0]]


@pytest.mark.parametrize("how, step", [
    (drop_run, "closure"),
    (drop_seed_slab, "seed"),
    (drop_cores, "closure"),
    (swell_core, "cores"),
    (lambda p: p.update(step=p["step"] * 1.5), "closure"),     # longer steps reach cells the region lacks
    (lambda p: p.update(step=p["turning_radius"] * 1.01), "parameters"),
    (lambda p: p.update(turning_radius=2.0), "parameters"),   # a wider car turns less: not this scene's
    (lambda p: p["grid"].update(cell=p["grid"]["cell"] * 1.25), "seed"),  # the cells move
    (lambda p: p["grid"]["origin"].__setitem__(0, p["grid"]["origin"][0] + 0.3), "seed"),
    (lambda p: p["grid"].update(cell=1e-12), "parameters"),  # cells below the coordinates' rounding
    (lambda p: p.update(direction="backward"), "seed"),       # the goal is no seed of it
    (lambda p: p["goal"].__setitem__(0, 9.6), "query"),       # not the scenario's goal
    (lambda p: p["slabs"].pop(), "cover"),
    (lambda p: p["slabs"][3].update(b=p["slabs"][3]["b"] + 0.01), "cover"),
    (lambda p: p.update(extra=1), "format"),
    (lambda p: p["slabs"][5]["cells"].append([1, 5, 5]), "format"),
])
def test_mutated_proofs_are_refused_at_their_step(alley, how, step):
    sc, proof = alley
    bad = copy.deepcopy(proof)
    how(bad)
    r = check_dubins_proof(sc, bad)
    assert not r.valid and r.step == step, r


def test_the_goal_moved_within_reach_is_refused(alley, tmp_path):
    """The dead end moved back: the goal 0.3 ahead of the car is reachable. No proof is built; the
    alley's proof, its goal set to that one, is refused (the region reaches it)."""
    sc, proof = alley
    text = open(ALLEY).read().replace('space = "reeds-shepp"', 'space = "dubins"')
    text = text.replace("[goal]                # out of the alley, facing the street\nx = 2.0\ny = 3.0\n"
                        "theta = 3.141592653589793", "[goal]\nx = 9.8\ny = 3.0\ntheta = 0.0")
    near = load_scenario(scene(text, tmp_path))
    assert near.all_queries()[0].goal == (9.8, 3.0, 0.0)
    _, proofs = prove(near)
    assert proofs == [None, None]
    forged = copy.deepcopy(proof)
    forged["goal"] = [9.8, 3.0, 0.0]
    r = check_dubins_proof(near, forged)
    assert not r.valid and r.step == "other end", r


def test_a_reeds_shepp_scenario_is_refused(alley):
    sc, proof = alley
    rs = load_scenario(ALLEY)
    assert rs.space == "reeds-shepp"
    r = check_dubins_proof(rs, proof)
    assert not r.valid and r.step == "parameters" and "dubins" in r.detail


def test_too_big_proofs_are_refused_before_work(alley):
    sc, proof = alley
    big = copy.deepcopy(proof)
    big["grid"]["cell"] = proof["grid"]["cell"] / 1000  # a stencil of millions of offsets
    with pytest.raises(TooBig):
        check_dubins_proof(sc, big)
    wide = copy.deepcopy(proof)
    wide["slabs"][0]["cells"] = [[0, -2**39, 2**39]]  # a window of 2^40 cells
    with pytest.raises(TooBig):
        check_dubins_proof(sc, wide)


def dubins_alley(tmp_path) -> str:
    return scene(open(ALLEY).read().replace('space = "reeds-shepp"', 'space = "dubins"'), tmp_path, "alley.toml")


@pytest.mark.parametrize("planner", ["exact", "auto"])
def test_plan_writes_it_and_check_proof_accepts_it(planner, tmp_path, capsys):
    path, out = dubins_alley(tmp_path), tmp_path / "proof.json"
    res = tmp_path / "result.json"
    code = cli_main(["plan", path, "--planner", planner, "--proof", str(out), "--time", "5", "--json", str(res)])
    said = json.loads(res.read_text())
    assert code == 1 and said["proven_unsolvable"] and "a forward-only car cannot" in said["message"], said
    assert said["answered_by"] == ("proof" if planner == "auto" else None)
    capsys.readouterr()
    assert cli_main(["check-proof", path, str(out)]) == 0
    assert capsys.readouterr().out.startswith("proof valid: ")


def test_check_proof_command_on_a_dubins_scene(alley, tmp_path, capsys):
    sc, proof = alley
    path = dubins_alley(tmp_path)
    good = tmp_path / "good.json"
    good.write_text(json.dumps(proof))
    assert cli_main(["check-proof", path, str(good)]) == 0
    assert capsys.readouterr().out.startswith(f"proof valid: {len(proof['slabs'])} slabs")
    bad = copy.deepcopy(proof)
    drop_run(bad)
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    assert cli_main(["check-proof", path, str(tmp_path / "bad.json")]) == 1
    out = capsys.readouterr().out
    assert out.startswith("proof invalid: step closure: ") and out.count("\n") == 1
    huge = copy.deepcopy(proof)
    huge["grid"]["cell"] /= 1000
    (tmp_path / "huge.json").write_text(json.dumps(huge))
    (tmp_path / "junk.json").write_text('{"format": "cspace-dubins-proof/1", ')
    for name in ("huge.json", "junk.json"):
        assert cli_main(["check-proof", path, str(tmp_path / name)]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: {tmp_path / name}: ") and err.count("\n") == 1, err


def test_check_proof_takes_the_space_the_plan_had(alley, tmp_path, capsys):
    """The alley's file says reeds-shepp: planned with --space dubins, checked with it too."""
    sc, proof = alley
    good = tmp_path / "good.json"
    good.write_text(json.dumps(proof))
    assert cli_main(["check-proof", ALLEY, str(good)]) == 1
    assert "step parameters: the scenario's space is 'reeds-shepp'" in capsys.readouterr().out
    assert cli_main(["check-proof", ALLEY, str(good), "--space", "dubins"]) == 0
    assert cli_main(["check-proof", ALLEY, str(good), "--space", "dubins", "--turning-radius", "1.5"]) == 1
    assert "turning_radius 1.0 is not the scenario's 1.5" in capsys.readouterr().out


def test_checker_is_independent_of_the_builder():
    tree = ast.parse(open(dubins_check.__file__).read())
    modules = {n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
    modules |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert not any(m and m.startswith("cspace") for m in modules), modules


# --- soundness: scenes where a forward path exists ---------------------------------------------

def driven_scene(seed: int):
    """A room with 2-5 random boxes and a goal reached from a random start by 2-4 random forward
    curves, every one certified free by the car's motion check (None where the drive collides)."""
    rnd = random.Random(seed)
    boxes = []
    for _ in range(rnd.randint(2, 5)):
        x, y = rnd.uniform(0.5, 8.5), rnd.uniform(0.5, 6.5)
        boxes.append((round(x, 3), round(y, 3), round(x + rnd.uniform(0.3, 2.0), 3), round(y + rnd.uniform(0.3, 2.0), 3)))
    start = (round(rnd.uniform(1.5, 8.5), 3), round(rnd.uniform(1.5, 6.5), 3), round(rnd.uniform(-3.1, 3.1), 3))
    try:
        cs = build_cspace(load_scenario_text(room_toml(boxes, start, start)))
    except ScenarioError:  # the start collides
        return None
    pose, curves = start, []
    for _ in range(rnd.randint(2, 4)):
        kind, length = rnd.choice("LSR"), rnd.uniform(0.2, 2.0)
        curves.append((kind, length))
        pose = advance(pose, kind, length, 1.0)
    if not cs.curve_free(start, curves, 1.0):
        return None
    goal = (pose[0], pose[1], math.remainder(pose[2], 2 * math.pi))
    return room_toml(boxes, start, goal)


def load_scenario_text(text: str):
    from cspace.io.scenario.validate import scenario_from_dict
    import tomllib

    return scenario_from_dict(tomllib.loads(text), "<test>")


def forged(sc, cs, hole: bool) -> dict:
    """A proof of the test's own for ``sc``: every cell of a box around the bounds in every slab
    (closed under every step: cells outside the bounds are blocked), or (``hole``) all but the
    cells within 0.5 of the goal."""
    from cspace.se2.critical import initial_partition

    regions, h = slab_regions_of(cs), 0.1
    q = sc.all_queries()[0]
    rows = []
    for i in range(-20, 120):
        if hole and abs((i + 0.5) * h - q.goal[0]) < 0.5:
            lo, hi = int((q.goal[1] - 0.5) / h), int((q.goal[1] + 0.5) / h)
            rows += [[i, -20, lo], [i, hi, 100]]
        else:
            rows.append([i, -20, 100])
    slabs = [{"a": a, "b": b, "cores": [c.tolist() for c in regions.possible(a, b).cores], "cells": rows}
             for a, b in initial_partition(16)]
    return {"format": dubins_check.FORMAT, "start": list(q.start), "goal": list(q.goal), "bounds": [0.0, 10.0, 0.0, 8.0],
            "robot_pieces": [p.tolist() for p in regions.core_robot], "turning_radius": 1.0, "direction": "forward",
            "step": 0.06, "grid": {"origin": [0.0, 0.0], "cell": h}, "slabs": slabs}


def check_solvable(seed: int, forge: bool = False) -> bool:
    text = driven_scene(seed)
    if text is None:
        return False
    try:
        sc = load_scenario_text(text)
    except ScenarioError:  # the goal, rounded, touches (the drive ends grazing an obstacle)
        return False
    cs, proofs = prove(sc)
    assert proofs == [None, None], seed  # a path exists: never proven unsolvable
    if forge:
        for hole in (False, True):
            proof = forged(sc, cs, hole)
            # the hole around the goal is not closed ("closure"), unless it takes the start's own
            # cell too (a drive that ended within 0.5 of the start): then the start is not held ("seed")
            step = "other end" if not hole else "closure" if holds_start(proof, sc) else "seed"
            r = check_dubins_proof(sc, proof)
            assert not r.valid and r.step == step, (seed, r)
    return True


def holds_start(proof: dict, sc) -> bool:
    """Whether every slab of the forged proof holds every cell whose closed box holds the start."""
    (x, y, _), h = sc.all_queries()[0].start, proof["grid"]["cell"]
    cells = {(i, j) for i in {math.floor(x / h - 1e-9), math.floor(x / h + 1e-9)}
             for j in {math.floor(y / h - 1e-9), math.floor(y / h + 1e-9)}}
    return all(any(i == a and lo <= j < hi for a, lo, hi in slab["cells"]) for slab in proof["slabs"] for i, j in cells)


def test_solvable_scenes_are_never_proven_and_forged_proofs_refused():
    assert check_solvable(2, forge=True)  # a scene where the random drive was free (many more: slow)


def alley_goals(cs, count: int, seed: int):
    """Goals a forward car reaches from the alley's start: random certified curves of total length
    at most 0.5 (the car has 0.45 to the dead end: many collide and are skipped)."""
    rnd, start, out = random.Random(seed), (9.5, 3.0, 0.0), []
    while len(out) < count:
        pose, curves = start, []
        for _ in range(rnd.randint(1, 3)):
            curves.append((rnd.choice("LSR"), rnd.uniform(0.01, 0.5 / 3)))
            pose = advance(pose, curves[-1][0], curves[-1][1], 1.0)
        if cs.curve_free(start, curves, 1.0):
            out.append(pose)
    return out


@pytest.mark.parametrize("count, seed", [(3, 0), pytest.param(40, 1, marks=pytest.mark.slow)])
def test_goals_within_the_confined_reach_are_never_proven(alley, count, seed):
    """Where the reach is confined, every goal inside it must stop the proof: goals driven to
    from the start by certified curves, from either end (the goal's backward reach holds the start)."""
    sc, _ = alley
    cs = build_cspace(sc)
    regions, start = slab_regions_of(cs), sc.all_queries()[0].start
    for goal in alley_goals(cs, count, seed):
        for backward in (False, True):
            assert reach_proof(regions, start, goal, 1.0, backward=backward) is None, (goal, backward)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.integers(0, 10**6))
@example(184)  # a drive that ends 0.43 from its start: the forged hole takes the start's cell too
def test_solvable_scenes_are_never_proven_many(seed):
    check_solvable(seed, forge=seed % 8 == 0)


@pytest.mark.parametrize("frac", [0.05, 0.2, 0.4])
def test_every_resolution_writes_proofs_the_checker_accepts(alley, frac):
    """Other steps (s / r from 0.05 to 0.4: slabs, cells and stencils of other sizes): a proof the
    builder writes is one the checker accepts."""
    sc, _ = alley
    q = sc.all_queries()[0]
    proof = reach_proof(slab_regions_of(build_cspace(sc)), q.start, q.goal, 1.0, steps=(frac,))
    assert proof is not None and proof["step"] == frac
    r = check_dubins_proof(sc, proof)
    assert r.valid, r


@settings(max_examples=60, deadline=None)
@given(st.floats(-math.pi, math.pi), st.floats(0.0, 0.5), st.floats(0.01, 1.0), st.floats(0.0, 1.0),
       st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=6), st.booleans(), st.booleans())
@example(2.0, 0.0, 0.01171875, 0.0, [1e-05], True, False)  # a near-straight path (the integration's own error)
def test_displacement_hulls_hold_every_curvature_bounded_step(a, width, frac, at, controls, exact, backward):
    """The lemma both sides rest on, against integration: a forward (or backward) path of length s
    (exactly s, or at most s) from a heading in [a, a + width], its curvature any piecewise constant
    in [-1/r, 1/r] (r = 2), ends inside the builder's hull and the checker's."""
    from cspace.car.dubins_reach import displacements
    from planners.core.dubins_check import disp_hull
    import shapely

    r = 2.0
    s = frac * r
    b, theta = a + width, a + at * width
    length = s if exact else s * at
    sign = -1.0 if backward else 1.0
    x = y = 0.0
    n = 60
    dt = length / n
    for i in range(n):  # each piece an exact arc (or segment) of constant curvature
        k = controls[i * len(controls) // n] / r
        # the chord of an arc of turn k dt: 2 sin(k dt / 2) / k along the mid heading (no
        # difference of sines: at k = 5e-6 that cancellation alone put a point 2.6e-9 off)
        chord = dt if k == 0.0 else 2.0 * math.sin(0.5 * k * dt) / k
        mid = theta + 0.5 * k * dt
        x, y, theta = x + sign * chord * math.cos(mid), y + sign * chord * math.sin(mid), theta + k * dt
    point = shapely.Point(x, y)
    mine = shapely.Polygon(displacements(a, b, s, r, exact, sign))
    theirs = disp_hull(a, b, s, r, exact, sign)
    assert mine.buffer(1e-9).covers(point) and theirs.buffer(1e-9).covers(point), (x, y)
    assert abs(theta - (a + at * width)) <= length / r + 1e-12


def test_an_end_tried_at_coarse_steps_is_tried_again_at_a_finer_one():
    # A wall 1.52 ahead: only a radius 11 % tighter turns away. The default steps (0.07, 0.05) find
    # no proof; 0.04 (auto's last try for a boxed-in end) does. The memo of failed attempts once
    # kept the query alone, so the finer attempt after a coarse one was skipped.
    from cspace.car.dubins_reach import FINE_STEP, STEPS
    from planners.core.dubins_proof import reach_result

    sc = wall_scene(1.52)
    cs = build_cspace(sc)
    q = sc.all_queries()[0]
    args = (sc, cs, slab_regions_of(cs), q, 60.0)
    assert reach_result(*args, ends=("start",)) is None
    assert reach_result(*args, ends=("start",)) is None  # (remembered: not tried again)
    res = reach_result(*args, ends=("start",), steps=STEPS + (FINE_STEP,))
    assert res is not None and res.proof["step"] == FINE_STEP and check_dubins_proof(sc, res.proof).valid
