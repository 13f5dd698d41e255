"""The direct route (GJK on the placed robot) against the materialised C-space.

Both routes answer "is q free?" from the same convex pieces; they round different
things (the C-space its piece vertices o − r, the direct route the shifted obstacle
vertices o − q), so they may disagree only within the sum of the two rounding bands
of the C-obstacle boundary. Every disagreement is measured against that bound with
shapely, on the bundled scenarios, random scenes and scenes moved far from the
origin or scaled; exact integer contacts must be "not free" on both routes.
"""
from __future__ import annotations

import glob
import math
import os
from fractions import Fraction

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import ROOT
from cspace.translation.cspace import CSpace
from cspace.translation.direct import U, DirectChecker, cspace_band
from cspace.io.load import load_scenario

SCENARIOS = sorted(glob.glob(os.path.join(ROOT, "scenarios", "*.toml")))
# scene -> [uniform states, their disagreements, boundary states, their disagreements,
#           disagreements checked exactly, of which the direct route got right], printed at the end
TALLY: dict[str, list[int]] = {}
EXACT_PER_SCENE = 12  # disagreements per scene settled against the exact geometry (rational SAT)


def _extent(cs: CSpace) -> float:
    xmin, xmax, ymin, ymax = cs.bounds
    return max(xmax - xmin, ymax - ymin)


def _states(cs: CSpace, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """Uniform states; states on the C-obstacle boundary (piece vertices, edge points) and one ulp off."""
    xmin, xmax, ymin, ymax = cs.bounds
    uni = np.column_stack([rng.uniform(xmin, xmax, n), rng.uniform(ymin, ymax, n)])
    if not cs.pieces:
        return uni, np.zeros((0, 2))
    verts = np.concatenate(cs.pieces)
    edges = np.concatenate([0.5 * (p + np.roll(p, -1, axis=0)) for p in cs.pieces])
    edge_t = np.concatenate([p + rng.uniform(0, 1, (len(p), 1)) * (np.roll(p, -1, axis=0) - p) for p in cs.pieces])
    bnd = np.concatenate([verts, edges, edge_t])
    pick = bnd[rng.choice(len(bnd), size=min(len(bnd), n), replace=False)]
    up = np.nextafter(pick, np.inf)
    down = np.nextafter(pick, -np.inf)
    out = np.concatenate([pick, up, down])
    inside = (out[:, 0] >= xmin) & (out[:, 0] <= xmax) & (out[:, 1] >= ymin) & (out[:, 1] <= ymax)
    return uni, out[inside]


def _boundary_distance(cs: CSpace, q, free_cs: bool) -> float:
    """How far q is from deciding the other way on the C-space's pieces (shapely).

    C-space free: distance to the nearest piece. C-space blocked: the largest
    distance to the boundary over the pieces containing q (q must be shallow in all).
    """
    pt = shapely.Point(float(q[0]), float(q[1]))
    polys = [shapely.Polygon(p) if len(p) >= 3 else shapely.LineString(p) if len(p) == 2 else shapely.Point(p[0])
             for p in cs.pieces]
    if free_cs:
        return min(pt.distance(g) for g in polys)
    depths = [pt.distance(g.boundary) if g.geom_type == "Polygon" else 0.0 for g in polys if g.covers(pt)]
    return max(depths) if depths else 0.0


def _agree(name: str, cs: CSpace, dc: DirectChecker, states: tuple[np.ndarray, np.ndarray], n_clear: int = 60) -> int:
    """Assert the routes agree up to the rounding bands; tally and return the disagreements."""
    band_c = cspace_band(cs)
    ext = _extent(cs)
    uni, bnd = states
    allq = np.concatenate([uni, bnd])
    big = max(float(np.abs(allq).max()), max((float(np.abs(p).max()) for p in cs.pieces), default=0.0))
    slack = 16 * U * big  # shapely's own rounding of the distance
    row = [len(uni), 0, len(bnd), 0, 0, 0]
    for k, q in enumerate(allq):
        a, b = cs.is_free(q), dc.is_free(q)
        if a == b:
            continue
        row[1 if k < len(uni) else 3] += 1
        tol = dc.band(q) + band_c + slack
        d = _boundary_distance(cs, q, a)
        assert d <= tol, f"{name}: q={q.tolist()} cspace={a} direct={b} off the boundary by {d} > {tol}"
        if row[4] < EXACT_PER_SCENE:
            row[4] += 1
            row[5] += b == _exact_free(dc, q)
    for q in allq[:: max(1, len(allq) // n_clear)]:
        c1, c2 = cs.clearance(q), dc.clearance(q)
        if math.isinf(c1) or math.isinf(c2):
            assert c1 == c2
            continue
        assert abs(c1 - c2) <= 1e-9 * ext + dc.band(q) + band_c + slack, (name, q.tolist(), c1, c2)
    TALLY[name] = row
    return row[1] + row[3]


def _exact_free(dc: DirectChecker, q) -> bool:
    """The true answer: no robot piece at q meets an obstacle piece, in rational arithmetic."""
    x, y = float(q[0]), float(q[1])
    for i, r in enumerate(dc.robot_pieces):
        for j, o in enumerate(dc.obstacle_pieces):
            if not dc.pairs[i, j]:
                continue
            # Boxes apart by more than a float's error cannot meet: skip the rational test.
            lo, hi = o.min(axis=0) - (x, y), o.max(axis=0) - (x, y)
            gap = max(lo[0] - r[:, 0].max(), r[:, 0].min() - hi[0], lo[1] - r[:, 1].max(), r[:, 1].min() - hi[1])
            if gap > 1e-9 * (1.0 + abs(x) + abs(y) + float(np.abs(o).max())):
                continue
            if _exact_relation(r, o, (x, y)) != "separated":
                return False
    return True


# ---------------------------------------------------------------- bundled scenarios


@pytest.mark.parametrize("path", SCENARIOS, ids=[os.path.basename(p) for p in SCENARIOS])
@pytest.mark.slow
def test_bundled_scenarios_agree(path):
    cs = CSpace.from_scenario(path)
    dc = DirectChecker.from_cspace(cs)
    rng = np.random.default_rng(len(path))
    _agree(os.path.basename(path), cs, dc, _states(cs, 500, rng))


@pytest.mark.slow
def test_from_scenario_builds_the_same_pieces():
    for path in SCENARIOS:
        cs = CSpace.from_scenario(path)
        dc = DirectChecker.from_scenario(path)
        assert len(dc.obstacle_pieces) == len(cs.obstacle_pieces)
        assert len(dc.robot_pieces) == max(1, len(cs.robot_pieces))
        rng = np.random.default_rng(7)
        for q in np.concatenate(_states(cs, 60, rng)):
            assert dc.is_free(q) == DirectChecker.from_cspace(cs).is_free(q)


def test_holes_and_nonconvex_robots_are_covered():
    names = {os.path.basename(p) for p in SCENARIOS}
    assert {"combs.toml", "u_robot.toml", "parts.toml", "bug_trap.toml"} <= names
    assert any(o.holes for o in load_scenario(os.path.join(os.path.dirname(SCENARIOS[0]), "bug_trap.toml")).obstacles)
    assert len(CSpace.from_scenario(os.path.join(os.path.dirname(SCENARIOS[0]), "combs.toml")).robot_pieces) > 1


# ---------------------------------------------------------------- random scenes


def random_convex(rng, cx, cy, r, k):
    pts = np.column_stack([cx + rng.uniform(-r, r, k), cy + rng.uniform(-r, r, k)])
    hull = shapely.MultiPoint(pts).convex_hull
    if hull.geom_type != "Polygon":
        return None
    return np.array(shapely.geometry.polygon.orient(hull).exterior.coords)[:-1]


def _random_star(rng, r, k):
    """A non-convex star-shaped robot around the origin."""
    ang = np.sort(rng.uniform(0, 2 * np.pi, k))
    rad = rng.uniform(0.3 * r, r, k)
    return np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])


def _random_scene(seed: int) -> CSpace:
    rng = np.random.default_rng(seed)
    obstacles = []
    while len(obstacles) < rng.integers(3, 12):
        p = random_convex(rng, rng.uniform(0, 20), rng.uniform(0, 20), rng.uniform(0.3, 3), int(rng.integers(3, 9)))
        if p is not None:
            obstacles.append(p)
    star = _random_star(rng, 1.2, int(rng.integers(5, 9)))
    robot = [star] if shapely.Polygon(star).is_valid else [random_convex(rng, 0, 0, 1, 6)]
    return CSpace((0, 20, 0, 20), obstacles, robot)


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_random_scenes_agree(seed):
    cs = _random_scene(seed)
    _agree(f"random[{seed}]", cs, DirectChecker.from_cspace(cs), _states(cs, 250, np.random.default_rng(seed)),
           n_clear=20)


# ---------------------------------------------------------------- far from the origin, scaled


def _moved(path: str, scale: float, shift: float) -> CSpace:
    """The scenario with obstacles and bounds mapped by x -> x·scale + shift, the robot scaled only."""
    sc = load_scenario(path)
    xmin, xmax, ymin, ymax = sc.bounds
    return CSpace((xmin * scale + shift, xmax * scale + shift, ymin * scale + shift, ymax * scale + shift),
                  [o.polygon * scale + shift for o in sc.obstacles],
                  [r.polygon * scale for r in sc.robot],
                  obstacle_holes=[[h * scale + shift for h in o.holes] for o in sc.obstacles],
                  robot_is_disk=sc.robot_kind == "disk")


@pytest.mark.parametrize("scale,shift", [(1.0, 1e8), (1e-6, 0.0), (1e6, 0.0), (1e-6, 1.0)])
@pytest.mark.parametrize("name", ["combs.toml", "u_robot.toml", "bug_trap.toml"])
def test_moved_scenes_agree(name, scale, shift):
    cs = _moved(os.path.join(os.path.dirname(SCENARIOS[0]), name), scale, shift)
    _agree(f"{name} x{scale:g}+{shift:g}", cs, DirectChecker.from_cspace(cs), _states(cs, 250, np.random.default_rng(3)),
           n_clear=20)


# ---------------------------------------------------------------- exact contacts


SQUARE = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
DIAMOND = np.array([[1, 0], [2, 1], [1, 2], [0, 1]], dtype=float)
# (robot, obstacle, q) with the robot at q touching the obstacle exactly, integer coordinates.
CONTACTS = {
    "edge_edge": (SQUARE, np.array([[5, 1], [8, 1], [8, 4], [5, 4]], float), (3, 0)),
    "vertex_vertex": (SQUARE, np.array([[5, 5], [8, 5], [8, 8], [5, 8]], float), (3, 3)),
    "vertex_edge": (DIAMOND, np.array([[5, 0], [8, 0], [8, 4], [5, 4]], float), (3, 1)),
    "edge_vertex": (SQUARE, np.array([[5, 1], [7, -1], [9, 1], [7, 3]], float), (3, 0)),
}


def _exact_relation(robot, obstacle, q) -> str:
    """Robot (convex, >= 3 vertices) at q against a convex obstacle, rational SAT over all edges."""
    F = Fraction
    qx, qy = F(float(q[0])), F(float(q[1]))
    r = [(F(x) + qx, F(y) + qy) for x, y in np.asarray(robot).tolist()]
    o = [(F(x), F(y)) for x, y in np.asarray(obstacle).tolist()]
    weak = False
    for poly, other in ((r, o), (o, r)):
        for k in range(len(poly)):
            (ax, ay), (bx, by) = poly[k], poly[(k + 1) % len(poly)]
            s = [(bx - ax) * (cy - ay) - (by - ay) * (cx - ax) for cx, cy in other]
            if all(v < 0 for v in s):
                return "separated"
            weak = weak or all(v <= 0 for v in s)
    return "touching" if weak else "overlapping"


def _exact_touch(robot, obstacle, q) -> bool:
    return _exact_relation(robot, obstacle, q) == "touching"


@pytest.mark.parametrize("scale,shift", [(1.0, 0.0), (1.0, 1e8), (1e6, 0.0), (2.0**-20, 0.0), (2.0**20, 1e8)])
@pytest.mark.parametrize("kind", list(CONTACTS))
def test_exact_contacts_are_not_free_on_both_routes(kind, scale, shift):
    robot, obstacle, q = CONTACTS[kind]
    robot, obstacle = robot * scale, obstacle * scale + shift
    q = np.array(q, float) * scale + shift
    assert _exact_touch(robot, obstacle, q)  # the construction really is an exact contact
    lo, hi = shift - 20 * scale, shift + 20 * scale
    cs = CSpace((lo, hi, lo, hi), [obstacle], [robot])
    dc = DirectChecker.from_cspace(cs)
    assert not cs.is_free(q) and not dc.is_free(q)
    assert cs.clearance(q) == 0.0 and dc.clearance(q) == 0.0
    assert dc.penetration(q) == 0.0  # touching: no depth
    # One ulp away from the obstacle the robot is strictly apart on both routes.
    away = np.nextafter(q, q - np.array([1.0, 1.0]) * scale)
    assert not _exact_touch(robot, obstacle, away)
    assert cs.is_free(away) and dc.is_free(away)
    assert dc.clearance(away) > 0.0


def test_penetration_matches_a_worked_example():
    dc = DirectChecker([SQUARE], [np.array([[3, 0], [6, 0], [6, 2], [3, 2]], float)])
    assert dc.penetration((1.5, 0)) == pytest.approx(0.5, abs=1e-12)  # overlap [3, 3.5] along x
    assert dc.penetration((0, 0)) == 0.0 and dc.is_free((0, 0)) and dc.clearance((0, 0)) == 1.0


def test_point_robot_and_empty_scene():
    sq = np.array([[1, 1], [3, 1], [3, 3], [1, 3]], float)
    cs = CSpace((0, 4, 0, 4), [sq])
    dc = DirectChecker.from_cspace(cs)
    assert [dc.is_free(q) for q in ((1, 2), (0.5, 2), (5, 2))] == [False, True, False]
    assert dc.clearance((0.5, 2)) == cs.clearance((0.5, 2)) == 0.5
    empty = DirectChecker([SQUARE], [], (0, 4, 0, 4))
    assert empty.is_free((1, 1)) and empty.clearance((1, 1)) == math.inf and empty.band((1, 1)) == 0.0


def test_bounds_prune_pairs_like_the_cspace():
    # An obstacle far outside the bounds: its C-piece is pruned, so clearance ignores it on both routes.
    far = np.array([[100, 0], [101, 0], [101, 1], [100, 1]], float)
    near = np.array([[5, 5], [6, 5], [6, 6], [5, 6]], float)
    cs = CSpace((0, 10, 0, 10), [far, near], [SQUARE])
    dc = DirectChecker.from_cspace(cs)
    assert not dc.pairs[0, 0] and dc.pairs[0, 1]
    assert dc.clearance((1, 1)) == pytest.approx(cs.clearance((1, 1)), abs=1e-12)


def test_band_bounds_the_shift_rounding():
    rng = np.random.default_rng(1)
    obstacle = rng.uniform(-1e8, 1e8, (6, 2))
    dc = DirectChecker([SQUARE], [obstacle])
    for q in rng.uniform(-1e8, 1e8, (50, 2)):
        shifted = obstacle - q
        err = max(abs(Fraction(float(s)) - (Fraction(float(o)) - Fraction(float(v))))
                  for s_row, o_row in zip(shifted, obstacle) for s, o, v in zip(s_row, o_row, q))
        assert math.sqrt(2) * float(err) <= dc.band(q)


def test_zz_report_disagreements(capsys):
    """Print the disagreement tally of the agreement tests that ran in this session."""
    with capsys.disabled():
        tot = [sum(r[k] for r in TALLY.values()) for k in range(6)]
        print(f"\n[direct] {len(TALLY)} scenes; uniform states {tot[0]}, disagreements {tot[1]}; "
              f"boundary states {tot[2]}, disagreements {tot[3]} (all within the bands); "
              f"{tot[4]} settled exactly, direct route right in {tot[5]}")
        print(f"[direct]   {'scene':30s} {'uniform':>8s} {'disagree':>8s} {'boundary':>8s} {'disagree':>8s} "
              f"{'exact':>5s} {'direct ok':>9s}")
        rnd = [0] * 6
        for name, r in sorted(TALLY.items()):
            if name.startswith("random"):
                rnd = [a + b for a, b in zip(rnd, r)]
                continue
            print(f"[direct]   {name:30s} " + " ".join(f"{v:8d}" if k < 4 else f"{v:5d}" if k == 4 else f"{v:9d}"
                                                      for k, v in enumerate(r)))
        print(f"[direct]   {'random scenes (all)':30s} " + " ".join(
            f"{v:8d}" if k < 4 else f"{v:5d}" if k == 4 else f"{v:9d}" for k, v in enumerate(rnd)))
