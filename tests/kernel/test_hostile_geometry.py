"""Hostile geometry through the API (issue 24 items 3, 4): no silent wrong answer, no crash.

Degenerate C-obstacle pieces in the exact planner, NaN/inf/empty/boolean/complex
input to every public function, integers beyond 2^53 in the exact predicate, empty
or collinear holes (GEOS used to segfault on them).
"""
from __future__ import annotations

import math
import subprocess
import sys
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import cspace
from cspace import CSpace, orient2d
from cspace.paths.pathcheck import open_meets, path_violations, split_pieces
from cspace.paths.shortest import shortest_path

NAN, INF = float("nan"), float("inf")


# ------------------------------------------------------------------ degenerate pieces in the exact planner


def _agrees_with_the_pieces(pieces, bounds, sp):
    """No returned edge passes through a piece (exact), checked again by dense
    rational sampling of the open edges against the zero-area pieces."""
    assert not path_violations(sp.path, pieces, bounds)
    flat = [p for p in pieces if len(np.unique(p, axis=0)) <= 2]
    for a, b in zip(sp.path[:-1], sp.path[1:]):
        for p in flat:
            c, d = p.min(axis=0), p.max(axis=0)
            assert not open_meets(a, b, c, d)


def test_a_collapsed_disk_is_refused_or_avoided(tmp_path):
    """A disk of radius 1e-9 at (5e7, 5e7) collapses to a point: the exact planner went
    straight through it. The loader now refuses such a disk; given as a C-obstacle
    piece directly, the point still blocks the straight path."""
    f = tmp_path / "deg.toml"
    f.write_text("[bounds]\nxmin = 49999990.0\nxmax = 50000010.0\nymin = 49999990.0\nymax = 50000010.0\n"
                 "[[obstacles]]\ncenter = [50000000.0, 50000000.0]\nradius = 1e-9\n"
                 "[start]\nx = 49999995.0\ny = 50000000.0\n[goal]\nx = 50000005.0\ny = 50000000.0\n")
    with pytest.raises(cspace.ScenarioError):
        cspace.load_scenario(str(f))
    dot = np.full((8, 2), 5e7)  # the disk's polygon, rounded: one point
    bounds, s, g = (5e7 - 10, 5e7 + 10, 5e7 - 10, 5e7 + 10), (5e7 - 5, 5e7), (5e7 + 5, 5e7)
    assert path_violations(np.array([s, g]), [dot]) == [(0, 0)]  # the straight segment is refused
    sp = shortest_path([dot], bounds, s, g)
    if sp.solved:  # it may only bend at the point, touching it like any corner
        assert len(sp.path) > 2 and sp.length == pytest.approx(10.0)
        _agrees_with_the_pieces([dot], bounds, sp)


def test_a_wall_thinner_than_an_ulp_blocks():
    wall = np.array([[5, 0], [5 + 5e-324, 0], [5 + 5e-324, 10], [5, 10]])  # x + 5e-324 == x: a segment
    sp = shortest_path([wall], (0, 10, 0, 10), (1, 5), (9, 5))
    assert not sp.solved and sp.path.size == 0  # cut in two: there is no path at all


def test_a_zero_width_wall_with_a_gap_is_walked_around():
    wall = np.array([[5, 0], [5, 0], [5, 8], [5, 8]], dtype=float)
    sp = shortest_path([wall], (0, 10, 0, 10), (1, 5), (9, 5))
    assert sp.solved and sp.path[1].tolist() == [5.0, 8.0]
    assert sp.length == pytest.approx(2 * math.hypot(4, 3))
    _agrees_with_the_pieces([wall], (0, 10, 0, 10), sp)


def test_a_zero_width_wall_touching_an_obstacle_cannot_be_passed_at_the_joint():
    # the wall's top tip touches a block: no wrapping there; the way is round the bottom
    wall = np.array([[5, 2], [5, 2], [5, 8], [5, 8]], dtype=float)
    block = np.array([[4, 8], [6, 8], [6, 10], [4, 10]], dtype=float)
    sp = shortest_path([wall, block], (0, 10, 0, 10), (1, 5), (9, 5))
    assert sp.solved and [5.0, 8.0] not in sp.path.tolist() and [5.0, 2.0] in sp.path.tolist()
    _agrees_with_the_pieces([wall, block], (0, 10, 0, 10), sp)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(1, 9), st.integers(1, 9), st.integers(1, 9), st.integers(1, 9)),
                min_size=1, max_size=4))
def test_random_zero_width_walls_are_never_crossed(walls):
    """Oracle: dense sampling of each returned edge against the walls (exact on integers)."""
    pieces = [np.array([[a, b], [a, b], [c, d], [c, d]], dtype=float) for a, b, c, d in walls]
    sp = shortest_path(pieces, (0, 10, 0, 10), (0.5, 0.5), (9.5, 9.5))
    if not sp.solved:
        return
    for p, q in zip(sp.path[:-1], sp.path[1:]):
        for a, b, c, d in walls:
            assert not open_meets(p, q, (a, b), (c, d))
            # and with exact rationals: the open edge never crosses the wall's line inside it
            t = [Fraction(k, 64) for k in range(1, 64)]
            for s in t:
                x = Fraction(p[0]) + s * (Fraction(q[0]) - Fraction(p[0]))
                y = Fraction(p[1]) + s * (Fraction(q[1]) - Fraction(p[1]))
                on_line = (c - a) * (y - b) - (d - b) * (x - a) == 0
                inside = min(a, c) <= x <= max(a, c) and min(b, d) <= y <= max(b, d)
                assert not (on_line and inside)


def test_split_pieces_decides_zero_area_exactly():
    sliver = np.array([[0.0, 0.0], [1e300, 1.0], [2e300, 2.0 + 2.0**-40]])  # float area is noise here
    proper, deg = split_pieces([sliver, np.array([[0.0, 0], [1, 1], [2, 2]])])
    assert len(proper) == 1 and deg[0].tolist() == [[0.0, 0.0], [2.0, 2.0]]


# ------------------------------------------------------------------ one gate: NaN, inf, empty, wrong types

SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]
FAR = [[3, 0], [4, 0], [4, 1], [3, 1]]
CALLS = {
    "gjk_distance": lambda p: cspace.gjk_distance(p, FAR),
    "gjk_distance_b": lambda p: cspace.gjk_distance(FAR, p),
    "gjk_intersects": lambda p: cspace.gjk_intersects(p, FAR),
    "epa_penetration": lambda p: cspace.epa_penetration(p, SQ),
    "support": lambda p: cspace.support(p, (1, 0)),
    "support_point": lambda p: cspace.support_point(p, (1, 0)),
    "reflect": lambda p: cspace.reflect(p),
    "minkowski_sum": lambda p: cspace.minkowski_sum(p, SQ),
    "convex_hull": lambda p: cspace.convex_hull(p),
    "normalize": lambda p: cspace.normalize(p),
    "signed_area": lambda p: cspace.signed_area(p),
    "is_convex": lambda p: cspace.is_convex(p),
    "convex_decompose": lambda p: cspace.convex_decompose(p),
    "halfplanes": lambda p: cspace.halfplanes(p),
    "shortest_path": lambda p: cspace.shortest_path([p], (-5, 5, -5, 5), (-4, -4), (4, 4)),
    "CSpace": lambda p: CSpace((-5, 5, -5, 5), [p]),
}
BAD = {
    "nan": [[0, 0], [1, 0], [0, NAN]],
    "inf": [[0, 0], [INF, 0], [0, 1]],
    "empty": np.zeros((0, 2)),
    "empty list": [],
    "ragged": [[0, 0], [1], [0, 1]],
    "3 columns": [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
    "booleans": np.array([[True, False], [False, True], [True, True]]),
    "a boolean among numbers": [[0, 0], [True, 0], [0, 1]],
    "complex": [[0, 0], [1 + 1j, 0], [0, 1]],
    "strings": [["0", "0"], ["1", "0"], ["0", "1"]],
    "huge int": [[0, 0], [2**53 + 1, 0], [0, 1]],
    "dict": {"a": 1},
}


@pytest.mark.parametrize("bad", list(BAD))
@pytest.mark.parametrize("name", list(CALLS))
def test_every_public_function_refuses_bad_input_with_value_or_type_error(name, bad):
    if bad in ("empty", "empty list") and name in ("convex_hull", "normalize", "signed_area", "is_convex"):
        pytest.skip("an empty point set has a meaning here (no hull, no area)")
    with pytest.raises((ValueError, TypeError)) as info:
        CALLS[name](BAD[bad])
    assert not isinstance(info.value, (IndexError, KeyError))


def test_nan_vertex_is_not_separated_at_4():
    """Was: gjk_distance answered 'separated, 4.0' with a NaN vertex."""
    with pytest.raises(ValueError, match="finite"):
        cspace.gjk_distance([[0, 0], [1, 0], [NAN, 1]], FAR)


@pytest.mark.parametrize("args", [
    ((0, 3, 0, 3), (NAN, 0), (3, 3)), ((0, 3, 0, INF), (0, 0), (3, 3)), ((0, 3, 0, 3), (0, 0), (3, 3, 3)),
])
def test_shortest_path_refuses_non_finite_points_and_bounds(args):
    with pytest.raises(ValueError):
        shortest_path([], *args)


@pytest.mark.parametrize("d", [(NAN, 1), (1,), (1, 2, 3), (True, False), "ab"])
def test_support_direction_goes_through_the_gate(d):
    with pytest.raises((ValueError, TypeError)):
        cspace.support(SQ, d)


# ------------------------------------------------------------------ integers beyond 2^53


def test_orient2d_is_exact_on_big_python_ints():
    assert orient2d((0, 0), (2**53 + 1, 1), (2**53, 1)) == 1  # was 0: both rounded to 2^53
    assert orient2d((0, 0), (2**1100, 1), (2**1100 + 1, 1)) == -1  # beyond the double range


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(-2**70, 2**70), min_size=6, max_size=6))
def test_orient2d_matches_integer_arithmetic(v):
    ax, ay, bx, by, cx, cy = v
    det = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    assert orient2d((ax, ay), (bx, by), (cx, cy)) == (det > 0) - (det < 0)


@pytest.mark.parametrize("p", [(True, 0), (1j, 0), ("1", 0)])
def test_orient2d_refuses_non_reals(p):
    with pytest.raises(TypeError):
        orient2d((0, 0), p, (0, 1))


def test_polygon_ints_beyond_2_53_are_refused_not_rounded():
    with pytest.raises(ValueError, match="2\\^53"):
        cspace.as_array([[0, 0], [2**53 + 1, 0], [0, 1]])
    assert cspace.as_array([[0, 0], [2**60, 0], [0, 1]])[1, 0] == 2.0**60  # exactly a double: fine


# ------------------------------------------------------------------ item 4: holes that crashed GEOS


@pytest.mark.parametrize("hole", [[], [[1, 1], [2, 2], [3, 3]], [[1, 1], [1, 1], [1, 1]], [[1, 1], [2, 2]]])
def test_empty_or_collinear_hole_is_a_value_error_not_a_segfault(hole):
    # a subprocess: the failure mode was SIGSEGV, which would take the test run down
    code = ("import numpy as np, cspace\n"
            f"hole = np.array({hole!r}, dtype=float).reshape(-1, 2)\n"
            "for f in (lambda: cspace.convex_decompose([[0, 0], [8, 0], [8, 8], [0, 8]], [hole]),\n"
            "          lambda: cspace.CSpace((0, 10, 0, 10), [np.array([[0., 0], [8, 0], [8, 8], [0, 8]])],\n"
            "                                obstacle_holes=[[hole]])):\n"
            "    try:\n        f()\n        print('accepted')\n"
            "    except ValueError as e:\n        print('ValueError', e)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-500:]
    assert r.stdout.splitlines() and all(line.startswith("ValueError") for line in r.stdout.splitlines())
    assert "hole 0" in r.stdout


def test_no_runtime_warning_from_a_degenerate_piece():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would be raised here instead of the ValueError
        with pytest.raises(ValueError, match="area|vertices"):
            CSpace((0, 10, 0, 10), [np.array([[5.0, 5], [5, 5], [5, 5]])])
