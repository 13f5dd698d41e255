"""The SE(2) C-space (cspace/se2/cspace.py) against independent oracles.

Oracles: shapely (the robot turned by shapely.affinity, translated, against the
obstacles); the translation C-space of the robot turned to a fixed angle (the same
exact semantics, so answers must be equal); dense sampling of motions; OMPL's own
interpolation where OMPL is installed.
"""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely import affinity

from cspace import CSpace, load_scenario
from cspace.se2.cspace import SE2CSpace, default_slabs, interpolate
from cspace.kernel.slabs.slab import slab_inner
from cspace.kernel.polygons.rotation import rotate_piece

from conftest import SCENARIOS

BAR = np.array([[-0.2, -1.5], [0.2, -1.5], [0.2, 1.5], [-0.2, 1.5]])


def _scene(name):
    return load_scenario(os.path.join(SCENARIOS, name))


def _shapes(sc):
    obs = shapely.union_all([shapely.Polygon(o.polygon, o.holes) for o in sc.obstacles])
    rob = shapely.union_all([shapely.Polygon(r.polygon) for r in sc.robot])
    return obs, rob


def _robot_at(rob, q):
    return affinity.translate(affinity.rotate(rob, q[2], origin=(0, 0), use_radians=True), q[0], q[1])


_CACHE: dict = {}


def _se2(name, K):
    if (name, K) not in _CACHE:
        _CACHE[(name, K)] = SE2CSpace.from_scenario(_scene(name), slabs=K)
    return _CACHE[(name, K)]


@pytest.mark.parametrize("name,K", [("theta.toml", 8), ("u_robot.toml", 8), ("parts.toml", 8), ("narrow_passage.toml", 16)])
def test_is_free_agrees_with_shapely(name, K):
    """Thousands of random poses: free iff the turned, translated robot misses every obstacle."""
    sc = _scene(name)
    cs = _se2(name, K)
    obs, rob = _shapes(sc)
    xmin, xmax, ymin, ymax = sc.bounds
    rng = np.random.default_rng(11)
    checked = 0
    for _ in range(1500):
        q = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)), float(rng.uniform(-math.pi, math.pi)))
        d = _robot_at(rob, q).distance(obs)
        if 0.0 < d < 1e-9:
            continue  # within rounding of contact
        if d == 0.0 and _robot_at(rob, q).intersection(obs).area < 1e-12 and not _robot_at(rob, q).buffer(-1e-9).intersects(obs):
            continue
        assert cs.is_free(q) == (d > 0.0), q
        checked += 1
    assert checked > 1400
    r = cs.report()["checks"]
    # The three routes all ran: slab grid, inner (certified blocked) and the exact test.
    assert r["exact_states"] > 0


def test_is_free_equals_the_translation_cspace_at_that_angle():
    """At a fixed θ the SE(2) answer is the translation C-space of the robot turned to θ: the same semantics."""
    sc = _scene("u_robot.toml")
    cs = _se2("u_robot.toml", 8)
    obstacles = [o.polygon for o in sc.obstacles]
    rng = np.random.default_rng(12)
    xmin, xmax, ymin, ymax = sc.bounds
    for th in [0.0, 0.3, -2.9, math.pi / 2, float(rng.uniform(-math.pi, math.pi))]:
        fixed = CSpace(sc.bounds, obstacles, [rotate_piece(p, th) for p in cs.robot_pieces])
        for _ in range(300):
            x, y = float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax))
            assert cs.is_free((x, y, th)) == fixed.is_free((x, y)), (x, y, th)
        # Motions at that fixed angle are the translation C-space's exact segments.
        for _ in range(60):
            a = (float(rng.uniform(xmin, xmax)), float(rng.uniform(ymin, ymax)))
            b = (a[0] + float(rng.normal()) * 3, a[1] + float(rng.normal()) * 3)
            assert cs.motion_free((*a, th), (*b, th)) == fixed.segment_free(a, b), (a, b, th)


def _motion_hits(sc_shapes, q0, q1, n=2000):
    """Dense oracle: some sampled pose, or the hull of two consecutive sampled poses of a part,
    meets an obstacle with positive area (so the motion collides, up to the tiny arc bulge)."""
    obs, parts = sc_shapes
    poses = [interpolate(q0, q1, t) for t in np.linspace(0.0, 1.0, n + 1)]
    for part in parts:
        placed = [_robot_at(part, q) for q in poses]
        for g in placed:
            if g.intersects(obs) and g.intersection(obs).area > 1e-12:
                return True
        hulls = [shapely.MultiPoint(np.vstack([np.asarray(a.exterior.coords), np.asarray(b.exterior.coords)])).convex_hull
                 for a, b in zip(placed[:-1], placed[1:])]
        if any(h.intersects(obs) and h.intersection(obs).area > 1e-12 for h in hulls):
            return True
    return False


def _clearance(sc_shapes, q0, q1, n=200):
    """Smallest robot-obstacle distance over n + 1 sampled poses, minus what a step can hide."""
    obs, parts = sc_shapes
    rob = shapely.union_all(parts)
    r = max(math.hypot(*v) for p in parts for v in np.asarray(p.exterior.coords))
    step = math.hypot(q1[0] - q0[0], q1[1] - q0[1]) / n + r * math.pi / n
    return min(_robot_at(rob, interpolate(q0, q1, t)).distance(obs) for t in np.linspace(0, 1, n + 1)) - step


_THETA = _scene("theta.toml")
_THETA_SHAPES = (_shapes(_THETA)[0], [shapely.Polygon(r.polygon) for r in _THETA.robot])
_pose = st.tuples(st.floats(0.5, 11.5), st.floats(0.5, 11.5), st.floats(-math.pi, math.pi, exclude_max=True))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_pose, st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-2.5, 2.5)))
def test_motion_free_never_accepts_a_colliding_motion(q0, d):
    """Near the slot of theta.toml: an accepted motion has no sampled colliding pose or sweep."""
    q0 = (4.0 + q0[0] * 0.3, 6.0 + (q0[1] - 6.0) * 0.5, q0[2])
    q1 = (q0[0] + d[0], q0[1] + d[1], (q0[2] + d[2] + math.pi) % (2 * math.pi) - math.pi)
    cs = _se2("theta.toml", 16)
    if cs.motion_free(q0, q1):
        assert not _motion_hits(_THETA_SHAPES, q0, q1, n=600), (q0, q1)


def test_motion_free_accepts_clearly_free_motions():
    """Every random motion with clearance > 0.02 along it is accepted (the certificate is not useless)."""
    cs = _se2("theta.toml", 16)
    rng = np.random.default_rng(13)
    accepted = clear = 0
    while clear < 60:
        q0 = (float(rng.uniform(0.5, 11.5)), float(rng.uniform(0.5, 11.5)), float(rng.uniform(-math.pi, math.pi)))
        q1 = (q0[0] + float(rng.normal()), q0[1] + float(rng.normal()),
              (q0[2] + float(rng.normal()) + math.pi) % (2 * math.pi) - math.pi)
        if not (0 <= q1[0] <= 12 and 0 <= q1[1] <= 12) or _clearance(_THETA_SHAPES, q0, q1) <= 0.02:
            continue
        clear += 1
        accepted += cs.motion_free(q0, q1)
    assert accepted == clear
    # And the dense oracle finds colliding motions rejected (sanity of the oracle pairing).
    assert not cs.motion_free((6.0, 6.0, 0.0), (6.0, 6.0, math.pi / 2 - 0.01 + 0.02))


@pytest.mark.parametrize("thick", [1e-6, 0.0])
def test_thin_wall_is_never_passed(thick):
    """A wall 1e-6 thick (or a zero-width gap between two walls: closed) across the path stops
    translating and rotating motions alike."""
    wall = np.array([[5.0, 0.0], [5.0 + thick, 0.0], [5.0 + thick, 10.0], [5.0, 10.0]]) if thick else \
        np.array([[5.0, 0.0], [6.0, 0.0], [6.0, 10.0], [5.0, 10.0]])
    cs = SE2CSpace((0, 10, 0, 10), [wall], [np.array([[-0.3, -0.1], [0.3, -0.1], [0.3, 0.1], [-0.3, 0.1]])], slabs=8)
    assert not cs.motion_free((2.0, 5.0, 0.0), (8.0, 5.0, 0.0))
    assert not cs.motion_free((2.0, 5.0, 0.0), (8.0, 5.0, 3.0))
    assert not cs.motion_free((2.0, 5.0, -1.0), (8.0, 6.0, 1.2))
    # A rotation in place whose tip sweeps through the wall (ends clear of it).
    assert cs.is_free((4.8, 5.0, math.pi / 2)) and cs.is_free((4.8, 5.0, -math.pi / 2 + 0.01))
    assert not cs.motion_free((4.8, 5.0, math.pi / 2), (4.8, 5.0, -math.pi / 2 + 0.01))
    assert cs.motion_free((4.4, 5.0, math.pi / 2), (4.4, 5.0, -math.pi / 2 + 0.01))


def test_interpolate_matches_ompl():
    ob = pytest.importorskip("ompl.base")
    space = ob.SE2StateSpace()
    b = ob.RealVectorBounds(2)
    b.setLow(-100)
    b.setHigh(100)
    space.setBounds(b)
    s0, s1, out = space.allocState(), space.allocState(), space.allocState()
    rng = np.random.default_rng(14)
    for _ in range(300):
        q0 = (*rng.uniform(-50, 50, 2), float(rng.uniform(-math.pi, math.pi)))
        q1 = (*rng.uniform(-50, 50, 2), float(rng.uniform(-math.pi, math.pi)))
        for s, q in ((s0, q0), (s1, q1)):
            s.setX(float(q[0]))
            s.setY(float(q[1]))
            s.setYaw(float(q[2]))
        for t in (0.0, 0.25, float(rng.random()), 1.0):
            space.interpolate(s0, s1, t, out)
            assert interpolate(q0, q1, t) == (out.getX(), out.getY(), out.getYaw())


def test_deterministic_and_reported():
    """Same inputs, same answers and counters; the report lists K, slabs built and counters."""
    sc = _scene("u_robot.toml")
    runs = []
    for _ in range(2):
        cs = SE2CSpace.from_scenario(sc, slabs=8)
        rng = np.random.default_rng(15)
        ans = [cs.is_free((float(rng.uniform(0, 20)), float(rng.uniform(0, 20)), float(rng.uniform(-3, 3))))
               for _ in range(300)]
        ans += [cs.motion_free((3.0, 3.0, 0.0), (float(rng.uniform(0, 20)), float(rng.uniform(0, 20)),
                                                 float(rng.uniform(-3, 3)))) for _ in range(30)]
        rep = cs.report()
        runs.append((ans, rep["checks"], [(d["slab"], d["pieces"], d["inner_pieces"]) for d in rep["slabs_built"]]))
    assert runs[0] == runs[1]
    assert rep["slabs"] == 8 and rep["checks"]["states"] > 300 and rep["checks"]["motions"] == 30


def test_point_robot_and_default_slabs():
    sq = np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])
    cs = SE2CSpace((0, 10, 0, 10), [sq], [])
    assert cs.slabs == 1
    assert not cs.is_free((5, 5, 2.0)) and cs.is_free((1, 1, -3.0))
    assert cs.motion_free((1, 1, 0), (9, 1, 3)) and not cs.motion_free((1, 5, 0), (9, 5, 0))
    k, why = default_slabs(1.2, 20.0)
    assert k in (16, 32, 64) and why.startswith(f"K = {k}:")
    assert default_slabs(10.0, 20.0)[0] == 64 and default_slabs(0.01, 20.0)[0] == 16
    with pytest.raises(ValueError):
        SE2CSpace((0, 10, 0, 10), [sq], [BAR], slabs=2)


def test_inner_sets_are_inside_the_robot_at_every_angle_of_their_slab():
    """The certified-blocked inner set of each slab lies in rotate_piece(piece, θ) at every θ of the slab
    (dense θ plus both widened ends; exact predicate on the float vertices)."""
    from cspace.kernel.polygons.predicates import orient2d_xy

    u = _scene("u_robot.toml")
    pieces = [BAR, np.array([[0.3, -0.2], [1.0, 0.1], [0.2, 0.6]])] + [p.polygon for p in u.robot]
    cs = SE2CSpace((0, 10, 0, 10), [np.array([[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]])], pieces, slabs=16)
    rng = np.random.default_rng(16)
    for k in range(16):
        a, b = cs._lo[k], cs._hi[k]
        inner = [j for j in (slab_inner(p, a, b, cs.pad) for p in cs.robot_pieces) if len(j)]
        assert len(inner) >= 2
        for th in list(rng.uniform(a, b, 40)) + [a, b]:
            for I in inner:
                assert any(all(orient2d_xy(*P[i - 1], *P[i], x, y) >= 0 for i in range(len(P)) for x, y in I.tolist())
                           for P in (rotate_piece(p, float(th)).tolist() for p in cs.robot_pieces))


def test_pair_filter_decides_like_the_exact_sum():
    """The float filter in front of the exact test never contradicts the exact sum, and defers near its boundary."""
    from cspace.kernel.minkowski.merge import minkowski_sum, reflect
    from cspace.kernel.polygons.polygon import point_in_convex
    from cspace.kernel.slabs.slab import edge_planes
    from cspace.se2.pair_filter import pair_filter

    rng = np.random.default_rng(17)
    O = np.array([[4.0, 4.0], [6.0, 4.5], [5.5, 6.0], [4.2, 5.5]])
    cs = SE2CSpace((0, 10, 0, 10), [O], [BAR], slabs=8)
    oe, op = edge_planes(O), O.tolist()
    undecided = 0
    for _ in range(1500):
        th = float(rng.uniform(-math.pi, math.pi))
        c, s = math.cos(th), math.sin(th)
        rp = rotate_piece(BAR, th)
        r = rp.tolist()
        axes = [(-(bx * c - by * s), -(bx * s + by * c), r[e][0], r[e][1], ln)
                for e, (bx, by, _, ln) in enumerate(edge_planes(BAR))]
        S = minkowski_sum(O, reflect(rp))
        # a point near the sum's boundary: on an edge, pushed by ±10^-(3..17) along the normal (below rounding too)
        e = int(rng.integers(len(S)))
        p0, p1 = S[e - 1], S[e]
        t = float(rng.random())
        n = np.array([p1[1] - p0[1], p0[0] - p1[0]])
        q = p0 + (p1 - p0) * t + n / np.linalg.norm(n) * float(rng.choice([-1, 1])) * 10.0 ** -float(rng.uniform(3, 17))
        side = pair_filter(oe, op, r, axes, float(q[0]), float(q[1]), cs.pad)
        inside = point_in_convex(S, float(q[0]), float(q[1])) >= 0
        if side == 0:
            undecided += 1
        else:
            assert (side < 0) == inside
    assert 0 < undecided < 1500


def test_piece_pairs_cover_every_sum():
    """CSpace.piece_pairs: each kept piece lists pairs whose sums lie inside it, and every pair
    whose sum meets the bounds is listed once (including sums pruned as inside another piece)."""
    from cspace.kernel.minkowski.merge import minkowski_sum, reflect
    from cspace.kernel.polygons.predicates import orient2d_xy

    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    parts = [sq * 0.3, sq * 0.2 + 0.05, sq * 0.1 + 0.1, np.array([[-0.5, -0.5], [-0.4, -0.5], [-0.45, -0.3]])]
    obstacles = [sq * 2 + 3, sq + 6, sq * 0.5 + 3.2, np.array([[20.0, 20.0], [21.0, 20.0], [21.0, 21.0]])]
    cs = CSpace((0, 10, 0, 10), obstacles, parts)
    listed = [pair for pairs in cs.piece_pairs for pair in pairs]
    assert len(listed) == len(set(listed)) == 3 * 4  # the far obstacle's sums are outside the bounds
    assert len(cs.pieces) < 12  # some sums were pruned as inside another: their pairs moved
    for piece, pairs in zip(cs.pieces, cs.piece_pairs):
        P = piece.tolist()
        for i, j in pairs:
            S = minkowski_sum(cs.obstacle_pieces[i], reflect(cs.robot_pieces[j]))
            assert all(orient2d_xy(*P[e - 1], *P[e], x, y) >= 0 for e in range(len(P)) for x, y in S.tolist())


def test_bench_script_runs(capsys):
    from conftest import load_script
    import sys

    bench = load_script("bench_se2_checks")
    argv = sys.argv
    sys.argv = ["bench_se2_checks.py", "--slabs", "4", "--states", "200", "--motions", "10", "--reps", "1", "theta.toml"]
    try:
        bench.main()
    finally:
        sys.argv = argv
    out = capsys.readouterr().out
    assert "ratio" in out and "floor decisions" in out


@pytest.mark.parametrize("gap,expect", [(1e-3, "free"), (1e-12, "free"), (1e-14, "floor"), (0.0, "floor"),
                                        (-1e-12, "collision")])
def test_grazing_rotation_is_refined_to_the_pad(gap, expect):
    """A bar turning in place whose corner passes `gap` from a wall (its reach is sqrt(1.01)): clear
    by more than the pad (~6e-13 here) is certified free; within the pad it ends at the floor
    (False, counted); overlapping it finds a colliding pose."""
    bar = np.array([[-1.0, -0.1], [1.0, -0.1], [1.0, 0.1], [-1.0, 0.1]])
    x = 5 + math.sqrt(1.01) + gap
    cs = SE2CSpace((0, 10, 0, 10), [np.array([[x, 0.0], [9.0, 0.0], [9.0, 10.0], [x, 10.0]])], [bar], slabs=16)
    ok = cs.motion_free((5.0, 5.0, 0.5), (5.0, 5.0, -0.5))
    assert ok == (expect == "free")
    assert cs.checks["motion_floor"] == (expect == "floor")
    assert cs.checks["motion_collisions"] == (expect == "collision")
