"""The compiled pair sums (cspace/compiled/_build.c) against minkowski_sum, array for array.

The C merge writes only the pairs it certifies and leaves the rest (None) to the pure
path; either way every pair must equal ``minkowski_sum(a, b)`` exactly, and on ordinary
scenes the C route must really carry the pairs (else the fast path would be a no-op).
"""
import glob
import os

import numpy as np
import pytest
from hypothesis import example, given, settings, strategies as st

from conftest import ROOT
from convex_pieces import piece_lists
from cspace import CSpace, load_scenario
from cspace.kernel.polygons.disk import disk_polygon
from cspace.kernel.minkowski.margin import inflated_pieces, margin_shapes
from cspace.kernel.minkowski.merge import minkowski_sum, reflect
from cspace.compiled import fastpath
from cspace.translation.build import pair_sums

compiled = pytest.mark.skipif(not fastpath.compiled(), reason="compiled fast path not built")


def check(pa, pb, min_certified=0.0):
    got = fastpath.pair_sums(pa, pb)
    ref = [minkowski_sum(a, b) for a in pa for b in pb]
    assert len(got) == len(ref)
    for g, r in zip(got, ref):
        assert g is None or np.array_equal(g, r), (g, r)
    done = sum(g is not None for g in got)
    assert done >= min_certified * len(got), f"only {done} of {len(got)} pairs certified"
    full = pair_sums(pa, pb)  # with the pure path's answers where C left None
    assert all(np.array_equal(g, r) for g, r in zip(full, ref))
    return done


@pytest.mark.slow
@compiled
@settings(max_examples=400, deadline=None)
@given(piece_lists(), st.sampled_from([1.0, 2.0**-40, 2.0**40, 1e-300, 1e300]))
@example(([np.array([[0., 0], [2, 0], [2, 1], [0, 1]])], [np.array([[0., 0], [1, 0], [1, 1], [0, 1]])]), 1.0)
def test_compiled_pair_sums_equal_minkowski_sum(lists, scale):
    pa, pb = ([p * scale for p in ps] for ps in lists)
    check(pa, pb)
    check(pa[:1], pb[:1])  # one pair: fastpath.pair_sums' lean call


@compiled
def test_rounded_sums_that_need_their_hull():
    """A box robot with a margin, summed with boxes (theta.toml's pairs): the robot ⊕ margin's
    bottom edge is off the horizontal by rounding, so a rounded sum vertex falls exactly on
    the line of its neighbours (76 merged vertices, 75 in the hull). The C merge certifies
    that turn (an exact zero) and repairs the ring with the exact hull, as minkowski_sum
    does; the same arrays."""
    rect = np.array([[-1.5, -0.2], [1.5, -0.2], [1.5, 0.2], [-1.5, 0.2]])
    robot = [reflect(p) for p in inflated_pieces([rect], margin_shapes(0.12))]
    boxes = [np.array([[5.0, 0.0], [7.0, 0.0], [7.0, 5.4], [5.0, 5.4]]), np.array([[0.1, 0.3], [3.3, 0.3], [3.3, 0.7], [0.1, 0.7]])]
    assert check(boxes, robot, min_certified=1.0) == 2
    assert [len(minkowski_sum(b, robot[0])) for b in boxes] == [75, 75]


@compiled
def test_degenerate_non_canonical_and_non_finite_pieces_are_left_to_the_pure_path():
    seg = np.array([[0.0, 0.0], [1.0, 1.0]])
    cw = np.array([[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]])
    not_lowest = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]])
    collinear = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]])
    tri = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    got = fastpath.pair_sums([seg, cw, not_lowest, collinear, tri], [tri])
    assert [g is None for g in got] == [True, True, True, True, False]
    assert np.array_equal(got[-1], minkowski_sum(tri, tri))
    huge = np.array([[0.0, 0.0], [1e308, 0.0], [0.0, 1e308]])  # sums overflow: never certified
    assert fastpath.pair_sums([huge], [huge]) == [None]
    assert fastpath.pair_sums([], [tri]) == [] and fastpath.pair_sums([tri], []) == []


@compiled
def test_disks_and_margins():
    """Disk polygons of one side count have edges parallel to rounding: those comparisons are
    not certified and their pairs go to the pure path; the margin's turned polygon is not."""
    rng = np.random.default_rng(5)
    disks = [disk_polygon(tuple(rng.uniform(-20, 20, 2)), float(rng.uniform(0.2, 3)), max_error=1e-3 * 2)
             for _ in range(30)]
    boxes = [np.array([[x, y], [x + w, y], [x + w, y + h], [x, y + h]])
             for x, y, w, h in rng.integers(-20, 20, (30, 4)).astype(float) + [0, 0, 21, 21]]
    robot = np.array([[-0.5, -0.3], [0.5, -0.3], [0.2, 0.4]])
    for margin in ([], margin_shapes(0.3), margin_shapes(0.3, [[-1.0, -0.2], [1.5, -0.2], [1.5, 0.2], [-1, 0.2]])):
        r = [reflect(p) for p in inflated_pieces([robot], margin)]
        check(boxes, r, min_certified=0.95)
        check(disks, r, min_certified=0.5)
    check(disks, [reflect(disk_polygon((0.0, 0.0), 0.5, max_error=1e-3 * 0.5))])


@compiled
@pytest.mark.parametrize("path", [pytest.param(p, marks=pytest.mark.slow) if p.endswith("env2.toml") else p  # (2.5 s)
                                  for p in sorted(glob.glob(os.path.join(ROOT, "scenarios", "*.toml"))
                                                  + glob.glob(os.path.join(ROOT, "scenarios", "ompl", "*.toml")))],
                         ids=lambda p: os.path.relpath(p, os.path.join(ROOT, "scenarios")))
def test_bundled_builds_equal_the_pure_path(path):
    """Every bundled translation scene, plain and with a margin of 1 % of its extent: the same
    C-space pieces built with the compiled pair sums as on the pure path."""
    import dataclasses

    sc = load_scenario(path)
    if sc.space != "translation":
        pytest.skip("not a translation scene")
    xmin, xmax, ymin, ymax = sc.bounds
    for s in (sc, dataclasses.replace(sc, clearance=0.01 * max(xmax - xmin, ymax - ymin))):
        fast = CSpace.from_scenario(s)
        with fastpath.disabled():
            pure = CSpace.from_scenario(s)
        assert len(fast.pieces) == len(pure.pieces)
        assert all(np.array_equal(a, b) for a, b in zip(fast.pieces, pure.pieces))
        assert fast.piece_pairs == pure.piece_pairs
        # ... and the C route carried every pair: its rounded sums are certified, or their
        # exact hull is (theta.toml's robot is turned off the axes by rounding: its sums with
        # the boxes have exactly collinear rounded vertices, repaired in C).
        if fast.robot_pieces or fast.margin:
            neg = [reflect(r) for r in inflated_pieces(fast.robot_pieces, fast.margin)]
            assert all(g is not None for g in fastpath.pair_sums(fast.obstacle_pieces, neg))


@pytest.mark.parametrize("seed", range(4))
def test_inflated_equals_inflated_pieces(seed):
    """The build's inflated robot pieces (pair sums, compiled when built) equal the kernel's
    k-way merges, array for array: one margin operand, two, none; a point robot."""
    from cspace.kernel.polygons.hull import convex_hull
    from cspace.translation.build import inflated

    rng = np.random.default_rng(seed)
    robot = [convex_hull(rng.normal(0, 1, (int(rng.integers(3, 9)), 2))) for _ in range(3)]
    aniso = [[-1.0, -0.3], [2.0, -0.3], [2.0, 0.4], [-1.0, 0.4]]
    for margin in (margin_shapes(float(rng.uniform(0.01, 1))), margin_shapes(0.0, aniso),
                   margin_shapes(0.3, aniso), []):
        for rob in (robot, []):
            got, want = inflated(rob, margin), inflated_pieces(rob, margin)
            assert len(got) == len(want) and all(np.array_equal(a, b) for a, b in zip(got, want))


@pytest.mark.slow
@compiled
@settings(max_examples=200, deadline=None)
@given(piece_lists(), st.sampled_from([1.0, 2.0**-30, 1e200]))
def test_compiled_containment_equals_the_exact_test(lists, scale):
    """The prune's containment answers (cspace/compiled/_build.c): certified ones equal the
    exact vertex-edge test; nested, shared-edge and identical pieces included."""
    from cspace.kernel.polygons.predicates import orient2d_many

    pieces = [p * scale for p in lists[0] + lists[1]]
    pieces += [pieces[0].copy(), (pieces[0] - pieces[0].mean(axis=0)) * 0.5 + pieces[0].mean(axis=0)]
    n = len(pieces)
    qs, ps = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), indexing="ij"))
    got = fastpath.contained(pieces, qs, ps)
    for q, p, g in zip(qs.tolist(), ps.tolist(), got.tolist()):
        Q, P = pieces[q], pieces[p]
        want = bool((orient2d_many(Q[None], np.roll(Q, -1, axis=0)[None], P[:, None]) >= 0).all())
        assert g == -1 or g == want, (q, p, g, want)
    if scale <= 1.0:  # mostly certified (integer pieces: exact zeros); at 1e200 products overflow
        assert (got >= 0).mean() > 0.5
