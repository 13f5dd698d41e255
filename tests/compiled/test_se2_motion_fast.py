"""The compiled SE(2) motion check (cspace/compiled/_se2motion.c, motions.se2_motion) against the
pure path (SE2Motions._motion_pure, the oracle) and an independent shapely sweep.

On thousands of random motions over several scenes (the bundled car maze, bug trap and piano
corridor, a generated 40-obstacle scene with a car-shaped robot, a small hand-made one):
whenever the compiled call decides, its answer is the pure path's; it never says "free" where
the pure path says "not free"; and scripts/sweep_oracle.py finds no pose in collision along a
motion either path calls free.
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import SCENARIOS, load_script
from cspace.io.load import load_scenario
from cspace.compiled import fastpath, motions
from cspace.se2.cspace import SE2CSpace
from cspace.se2.motion import FLOOR_REL, MAX_REFINE, interpolate
from cspace.kernel.polygons.rotation import wrap_angle
from planners.cli.generate import generate

oracle = load_script("sweep_oracle")
compiled = pytest.mark.skipif(not fastpath.compiled(), reason="the compiled fast path is not built (or CSPACE_PURE=1)")

CAR = [[-0.6, -0.25], [0.5, -0.25], [0.7, -0.1], [0.7, 0.1], [0.5, 0.25], [-0.6, 0.25]]
SMALL = """name = "small"
space = "se2"
[bounds]
xmin = 0
xmax = 10
ymin = 0
ymax = 10
[start]
x = 1
y = 1
theta = 0
[goal]
x = 9
y = 9
theta = 0
[robot]
polygon = [[-1.0, -0.1], [1.0, -0.1], [1.0, 0.1], [-1.0, 0.1]]
[[obstacles]]
polygon = [[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]]
[[obstacles]]
polygon = [[2.0, 7.0], [3.0, 6.5], [3.5, 8.0], [2.5, 8.5]]
"""


def _generated(tmp_dir) -> str:
    text = generate("random", seed=1, size=40)
    lines = text.splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("[robot]"))
    lines[at + 1] = f"polygon = {CAR}"
    name = next(i for i, line in enumerate(lines) if line.startswith("name"))
    lines.insert(name + 1, 'space = "se2"')
    path = os.path.join(tmp_dir, "r40car.toml")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    d = str(tmp_path_factory.mktemp("se2motion"))
    small = os.path.join(d, "small.toml")
    with open(small, "w") as f:
        f.write(SMALL)
    files = [os.path.join(SCENARIOS, "se2", n) for n in ("car_maze.toml", "bug_trap.toml", "piano_corridor.toml")]
    out = {}
    for f in files + [_generated(d), small]:
        sc = load_scenario(f)
        cs = SE2CSpace.from_scenario(sc, slabs=sc.slabs)
        with fastpath.disabled():
            pure = SE2CSpace.from_scenario(sc, slabs=sc.slabs)  # its slabs and motions: the pure path
        out[sc.name] = (sc, cs, pure)
    return out


def compiled_answer(cs, q0, q1) -> int:
    """The compiled call alone (1 free, 0 not free, -1 undecided), its end poses free; 2 if
    an end pose is not free (not the compiled call's question)."""
    x0, y0, a0 = float(q0[0]), float(q0[1]), wrap_angle(float(q0[2]))
    x1, y1, a1 = float(q1[0]), float(q1[1]), wrap_angle(float(q1[2]))
    if not (cs.is_free((x0, y0, a0)) and cs.is_free((x1, y1, a1))):
        return 2
    f = motions.se2_motion(cs, MAX_REFINE, FLOOR_REL)
    grids = [None] * cs.slabs
    while True:
        r = f(grids, x0, y0, a0, x1, y1, a1)
        if r >= -1:
            return r
        grids[-2 - r] = cs.slab(-2 - r)._fast


def random_motions(sc, cs, n: int, seed: int) -> list:
    """n motions between free poses: a third short (near contact, refined), the rest up to
    OMPL's default range (0.2 x the space's maximum extent), some at one fixed angle."""
    rng = np.random.default_rng(seed)
    xmin, xmax, ymin, ymax = sc.bounds
    reach = 0.2 * (math.hypot(xmax - xmin, ymax - ymin) + 0.5 * math.pi)
    out = []
    while len(out) < n:
        a = (rng.uniform(xmin, xmax), rng.uniform(ymin, ymax), rng.uniform(-math.pi, math.pi))
        if not cs.is_free(a):
            continue
        d = rng.normal(size=3)
        d *= rng.uniform(0, reach if len(out) % 3 else 0.05 * reach) / np.linalg.norm(d)
        th = a[2] if len(out) % 17 == 0 else math.remainder(a[2] + d[2] / 0.5, 2 * math.pi)
        b = (min(max(a[0] + d[0], xmin), xmax), min(max(a[1] + d[1], ymin), ymax), th)
        if b[2] >= math.pi:
            b = (b[0], b[1], -math.pi)
        if cs.is_free(b):
            out.append((a, b))
    return out


def judged_colliding(sc, a, b) -> bool:
    """The shapely sweep (scripts/sweep_oracle.py) finds a pose in collision along a -> b."""
    path = np.array([a, b])
    r = oracle.sweep_check(sc, path)
    if r["collides"] and not r["certain"]:
        r = oracle.sweep_check(sc, path, dtheta=2e-5, dxy=1e-5 * (sc.bounds[1] - sc.bounds[0]))
    return bool(r["certain"])


@compiled
@pytest.mark.parametrize("name", ["car-maze", "bug-trap-se2", "piano-corridor", "random-40", "small"])
@pytest.mark.slow
def test_compiled_agrees_with_pure_and_the_sweep(scenes, name):
    sc, cs, pure = scenes[name]
    motions = random_motions(sc, cs, 1200, seed=11)
    decided = free = 0
    refined = []
    for a, b in motions:
        sweeps = cs.checks["sweeps"]
        c = compiled_answer(cs, a, b)
        p = pure.motion_free(a, b)
        assert c != 2
        if c >= 0:
            decided += 1
            assert (c == 1) == p, (a, b, c, p)
        assert not (c == 1 and not p), (a, b)
        assert cs.motion_free(a, b) == p  # the product's answer: compiled, else pure
        free += p
        if p and cs.checks["sweeps"] > sweeps:
            refined.append((a, b))
    assert decided >= 0.97 * len(motions)
    assert free >= 50
    # The independent judge: every motion decided free by halving swept hulls (the part this
    # file adds), and a sample of the others.
    rng = np.random.default_rng(5)
    others = [m for m in motions if m not in refined]
    sample = refined[:60] + [others[i] for i in rng.choice(len(others), size=min(30, len(others)), replace=False)]
    for a, b in sample:
        if cs.motion_free(a, b):
            assert not judged_colliding(sc, a, b), (a, b)


@compiled
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(x=st.floats(0.0, 10.0), y=st.floats(0.0, 10.0), th=st.floats(-math.pi, math.pi),
       dx=st.floats(-3.0, 3.0), dy=st.floats(-3.0, 3.0), dth=st.floats(-math.pi, math.pi))
def test_hypothesis_motions_small_scene(scenes, x, y, th, dx, dy, dth):
    sc, cs, pure = scenes["small"]
    a = (x, y, wrap_angle(th))
    b = (min(max(x + dx, 0.0), 10.0), min(max(y + dy, 0.0), 10.0), wrap_angle(th + dth))
    c = compiled_answer(cs, a, b)
    if c == 2:
        return
    p = pure.motion_free(a, b)
    if c >= 0:
        assert (c == 1) == p
    if p or c == 1:
        # A free answer: the poses along it are free (a dense sample, the exact pose test).
        for t in np.linspace(0.0, 1.0, 41):
            assert pure.is_free(interpolate(a, b, t))


@compiled
def test_plans_motions_match(scenes):
    """Motions as a planner asks them (RRTConnect on the car maze): same answers on both paths."""
    from planners import plan

    sc, cs, pure = scenes["car-maze"]
    asked = []
    fresh = SE2CSpace.from_scenario(sc, slabs=sc.slabs)  # slabs built on demand by the compiled call's retry
    inner = fresh.motion_free

    def logged(q0, q1):
        r = inner(q0, q1)
        asked.append((tuple(q0), tuple(q1), r))
        return r

    fresh.motion_free = logged
    res = plan(sc, planner="RRTConnect", seed=0, time=10.0, cspace=fresh)
    assert res.solved and len(asked) > 100
    for q0, q1, r in asked:
        assert pure.motion_free(q0, q1) == r


@compiled
def test_fixed_angle_and_errors(scenes):
    sc, cs, pure = scenes["small"]
    # One fixed angle through the square: the compiled call leaves it to the exact translation test.
    a, b = (2.0, 5.0, 0.0), (8.0, 5.0, 0.0)
    assert compiled_answer(cs, a, b) == -1
    assert cs.motion_free(a, b) is False and pure.motion_free(a, b) is False
    assert cs.motion_free((2.0, 2.0, 0.0), (8.0, 2.0, 0.0)) is True
    f = motions.se2_motion(cs, MAX_REFINE, FLOOR_REL)
    with pytest.raises(TypeError):
        f([None], 1.0, 1.0, 0.0, 2.0, 2.0, 0.0)  # not one entry per slab
    with pytest.raises(TypeError):
        f([None] * cs.slabs, 1.0)
    assert f([None] * cs.slabs, float("nan"), 1.0, 0.0, 2.0, 2.0, 0.5) == -1


def test_pure_path_has_no_compiled_motion(scenes):
    sc, cs, pure = scenes["small"]
    assert motions.se2_motion(pure, MAX_REFINE, FLOOR_REL) is None
    with fastpath.disabled():
        assert motions.se2_motion(cs, MAX_REFINE, FLOOR_REL) is None
    assert pure.motion_free((2.5, 2, 0), (7.5, 2, 0)) and not pure.motion_free((3.1, 5, 1.5), (3.1, 5, -1.5))


@pytest.mark.slow
def test_pure_answers_are_sweep_checked(scenes):
    """On any build (CSPACE_PURE=1 too): free motions of the product path pass the shapely sweep."""
    sc, cs, pure = scenes["bug-trap-se2"]
    for a, b in random_motions(sc, cs, 60, seed=3):
        if cs.motion_free(a, b):
            assert not judged_colliding(sc, a, b), (a, b)
