"""Slab hulls, the one rotation, slab indexing and the inscribed disk (cspace/kernel/slabs/slab.py).

Oracles: exact rational rotations (cos = (1 − t²)/(1 + t²), sin = 2t/(1 + t²), the
angle 2·atan(t)) with Fraction orientation tests; the exact predicate on the float
rotation; shapely for the inscribed disk; OMPL's own wrap where it is installed.
"""
from __future__ import annotations

import math
import os
from fractions import Fraction

import numpy as np
import pytest
import shapely

from cspace import CSpace, load_scenario
from cspace.kernel.polygons.predicates import orient2d_xy
from cspace.kernel.slabs.slab import ANGLE_SLACK, inscribed_polygon, inscribed_radius, slab_hull, slab_of, slab_range
from cspace.kernel.polygons.rotation import rotate, rotate_piece, wrap_angle

from conftest import SCENARIOS


def random_convex(rng, n=7, scale=1.0, integer=False):
    pts = rng.normal(size=(40, 2)) * scale
    if integer:
        pts = np.round(pts * 10)
    hull = shapely.MultiPoint(pts).convex_hull
    return np.asarray(shapely.geometry.polygon.orient(hull).exterior.coords)[:-1]


def _dyadic_scale(*arrays) -> int:
    """A power of two E with every coordinate times 2^E an integer (floats are dyadic)."""
    return max(Fraction(float(v)).denominator for a in arrays for v in np.ravel(a)).bit_length() - 1


def _rational_angles(a: float, b: float, count: int, rng) -> list[tuple[int, int]]:
    """Angles strictly inside [a, b] as t = p/q (p, q integers): the angle 2·atan(t) has
    cos = (q² − p²)/(q² + p²), sin = 2pq/(q² + p²) exactly. t is drawn in [tan(a/2),
    tan(b/2)] shrunk by 1e-6 of its width (against tan's rounding), plus both ends."""
    lo, hi = math.tan(a / 2), math.tan(b / 2)
    w = hi - lo
    lo, hi = lo + 1e-6 * w, hi - 1e-6 * w
    out = []
    for u in list(rng.random(count - 2)) + [0.0, 1.0]:
        t = Fraction(lo + (hi - lo) * float(u))
        near = t.limit_denominator(1 << 24)
        t = near if lo <= near <= hi else t
        out.append((t.numerator, t.denominator))
    return out


@pytest.mark.parametrize("seed", range(6))
def test_slab_hull_holds_exactly_rotated_piece(seed):
    """Thousands of exact rational rotations inside [a, b]: every vertex is in H (Fractions)."""
    rng = np.random.default_rng(seed)
    piece = random_convex(rng, scale=[0.5, 3.0, 1e3, 1e-3, 1.0, 7.0][seed], integer=seed == 4)
    # Slabs of K = 4..64 at random places (|a|, |b| < π so tan(a/2) is finite), and a tiny one.
    width = [math.pi / 2, 2 * math.pi / 64, 2 * math.pi / 16, 1e-7, 2 * math.pi / 32, 0.3][seed]
    a = float(rng.uniform(-math.pi + 1e-3, math.pi - 1e-3 - width))
    b = a + width
    H = slab_hull(piece, a, b)
    # Integers: coordinates times 2^E; a rotated vertex (x c − y s, x s + y c) with
    # c, s = (q² − p², 2pq)/D is tested as D times itself (D > 0 keeps every sign).
    E = _dyadic_scale(H, piece)
    Hi = [(int(Fraction(x) * 2**E), int(Fraction(y) * 2**E)) for x, y in H.tolist()]
    edges = [(Hi[i - 1], Hi[i]) for i in range(len(Hi))]
    verts = [(int(Fraction(x) * 2**E), int(Fraction(y) * 2**E)) for x, y in piece.tolist()]
    for p, q in _rational_angles(a, b, 400, rng):
        c, s, d = q * q - p * p, 2 * p * q, q * q + p * p
        for x, y in verts:
            px, py = x * c - y * s, x * s + y * c
            for (ax, ay), (bx, by) in edges:
                assert (bx - ax) * (py - ay * d) - (by - ay) * (px - ax * d) >= 0


def test_slab_hull_holds_float_rotations_and_is_tight():
    """rotate() at float angles of [a, b] is inside H (exact predicate), and H is not much larger."""
    rng = np.random.default_rng(7)
    piece = np.array([[-0.2, -1.5], [0.2, -1.5], [0.2, 1.5], [-0.2, 1.5]])
    r = float(np.hypot(piece[:, 0], piece[:, 1]).max())
    for k in range(32):
        a, b = slab_range(k, 32)
        H = slab_hull(piece, a - ANGLE_SLACK, b + ANGLE_SLACK)
        hl = H.tolist()
        for th in list(rng.uniform(a, b, 60)) + [a, b, np.nextafter(a, -4), np.nextafter(b, 4)]:
            for x, y in rotate(piece, float(th)).tolist():
                assert all(orient2d_xy(*hl[i - 1], *hl[i], x, y) >= 0 for i in range(len(hl)))
        # Tightness: H is within the sweep's hull grown by r·sin²(Δ/2)/cos(Δ/2) (+ rounding).
        delta = b - a
        sweep = shapely.MultiPoint(np.vstack([rotate(piece, float(t)) for t in np.linspace(a, b, 200)])).convex_hull
        excess = r * math.sin(delta / 2) ** 2 / math.cos(delta / 2)
        # the dense hull misses arcs by at most r (1 − cos(Δ/400))
        slack = excess + r * (1 - math.cos(delta / 400)) + 1e-9
        assert sweep.buffer(slack).covers(shapely.Polygon(H))


def test_zero_width_slab_is_the_translation_cspace():
    """b == a: the hull is rotate(piece, a) itself, and the slab C-space is CSpace of the rotated robot."""
    sc = load_scenario(os.path.join(SCENARIOS, "theta.toml"))
    body = np.array([[-0.2, -1.5], [0.2, -1.5], [0.2, 1.5], [-0.2, 1.5]])
    obstacles = [o.polygon for o in sc.obstacles]
    for a in (0.0, 0.7, -2.5, math.pi / 2):
        H = slab_hull(body, a, a)
        assert np.array_equal(H, rotate(body, a))
        slab = CSpace(sc.bounds, obstacles, [H])
        direct = CSpace(sc.bounds, obstacles, [rotate(body, a)])
        assert len(slab.pieces) == len(direct.pieces)
        for p, q in zip(slab.pieces, direct.pieces):
            assert np.array_equal(p, q)


def test_rotate_is_the_scenario_rotation():
    """The loader turns the robot by theta with rotate(): bit for bit."""
    sc = load_scenario(os.path.join(SCENARIOS, "theta.toml"))
    body = np.array([[-0.2, -1.5], [0.2, -1.5], [0.2, 1.5], [-0.2, 1.5]])
    assert np.array_equal(sc.robot[0].polygon, rotate(body, sc.theta))


def test_rotate_piece_stays_convex():
    """A sliver whose rotation bends a near-straight turn comes back as the exact hull."""
    rng = np.random.default_rng(3)
    sliver = np.array([[0.0, 0.0], [1.0, 1e-17], [2.0, 0.0], [1.0, 1.0]])
    for th in rng.uniform(-math.pi, math.pi, 200):
        p = rotate_piece(sliver, float(th)).tolist()
        n = len(p)
        assert n >= 3
        assert all(orient2d_xy(*p[i - 2], *p[i - 1], *p[i]) > 0 for i in range(n))


def test_slab_of_covers_its_angle():
    """slab_of(θ) returns a slab whose widened interval holds wrap(θ), also at and next to boundaries."""
    rng = np.random.default_rng(4)
    for K in (4, 7, 16, 64, 100):
        thetas = list(rng.uniform(-4 * math.pi, 4 * math.pi, 300))
        for k in range(K):
            a, b = slab_range(k, K)
            thetas += [a, b, np.nextafter(a, -9), np.nextafter(a, 9), np.nextafter(b, -9), np.nextafter(b, 9)]
        for th in thetas:
            t = wrap_angle(float(th))
            assert -math.pi <= t < math.pi
            k = slab_of(float(th), K)
            a, b = slab_range(k, K)
            assert a - ANGLE_SLACK <= t <= b + ANGLE_SLACK
    assert slab_of(math.pi, 8) == 0 and slab_of(-math.pi, 8) == 0 and slab_of(np.nextafter(math.pi, 0), 8) == 7
    with pytest.raises(ValueError):
        slab_of(float("nan"), 8)


def test_wrap_angle_matches_ompl():
    ob = pytest.importorskip("ompl.base")
    space = ob.SO2StateSpace()
    s = space.allocState()
    rng = np.random.default_rng(5)
    for v in list(rng.uniform(-20, 20, 500)) + [math.pi, -math.pi, 3 * math.pi, -3 * math.pi, 0.0, 2 * math.pi]:
        s.value = float(v)
        space.enforceBounds(s)
        assert wrap_angle(float(v)) == s.value


def test_inscribed_radius_and_polygon():
    rect = np.array([[-1.0, -0.5], [2.0, -0.5], [2.0, 3.0], [-1.0, 3.0]])
    r = inscribed_radius([rect])
    assert 0.5 - 1e-9 < r < 0.5
    u = load_scenario(os.path.join(SCENARIOS, "u_robot.toml"))
    parts = [p.polygon for p in u.robot]
    # The U's reference point (0, 0) is in its open middle: outside the robot.
    assert inscribed_radius(parts) == 0.0
    rng = np.random.default_rng(6)
    for _ in range(30):
        parts = [random_convex(rng, scale=2.0) for _ in range(2)]
        union = shapely.union_all([shapely.Polygon(p) for p in parts])
        r = inscribed_radius(parts)
        if not union.contains(shapely.Point(0, 0)):
            assert r == 0.0
            continue
        d = union.exterior.distance(shapely.Point(0, 0)) if union.geom_type == "Polygon" else None
        if d is not None and not list(union.interiors):
            assert d * (1 - 1e-9) < r <= d
        P = inscribed_polygon(r, 32)
        assert union.covers(shapely.Polygon(P))
        assert (np.hypot(P[:, 0], P[:, 1]) < r).all()
    assert len(inscribed_polygon(0.0)) == 0
