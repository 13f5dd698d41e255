"""The C-space build's batched stages give the one-by-one answers: pair_sums equals
minkowski_sum pair by pair, the STRtree-proposed containment pruning equals the
per-piece scan it replaced, the loader's convexity flags give the pieces a fresh
is_convex gives, and PieceSet's packed boxes and edges are the per-piece ones."""
import glob
import os

import numpy as np
import pytest

from conftest import SCENARIOS
from cspace import CSpace, minkowski_sum, reflect
from cspace.translation.build import contained_pieces, pair_sums
from cspace.kernel.polygons.pieces import PieceSet
from cspace.kernel.polygons.predicates import orient2d_many


def contained_reference(pieces):
    """The per-piece scan the build used before (the oracle)."""
    n = len(pieces)
    if n < 2:
        return {}
    lo = np.array([p.min(axis=0) for p in pieces])
    hi = np.array([p.max(axis=0) for p in pieces])
    order = np.argsort(lo[:, 0], kind="stable")
    removed = {}
    lo_sorted = lo[order, 0]
    for q in range(n):
        if q in removed:
            continue
        j0 = np.searchsorted(lo_sorted, lo[q, 0], side="left")
        j1 = np.searchsorted(lo_sorted, hi[q, 0], side="right")
        cand = order[j0:j1]
        cand = cand[(cand != q) & (hi[cand, 0] <= hi[q, 0]) & (lo[cand, 1] >= lo[q, 1]) & (hi[cand, 1] <= hi[q, 1])]
        Q = pieces[q]
        s, e = Q, np.roll(Q, -1, axis=0)
        for p in cand.tolist():
            if p in removed:
                continue
            P = pieces[p]
            if P.shape == Q.shape and p < q and np.array_equal(P, Q):
                continue
            if (orient2d_many(s[None, :, :], e[None, :, :], P[:, None, :]) >= 0).all():
                removed[p] = q
    return removed


def random_pieces(rng, n, spread=10.0):
    out = []
    for _ in range(n):
        k = int(rng.integers(3, 9))
        a = np.sort(rng.uniform(0, 2 * np.pi, k))
        r = rng.uniform(0.1, 3.0)
        c = rng.uniform(0, spread, 2)
        p = np.unique(np.round(np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a)]), 1), axis=0)
        from cspace import convex_hull

        h = convex_hull(p)
        if len(h) >= 3:
            out.append(h)
    # duplicates and nested copies exercise the tie rules
    return out + [out[0].copy(), out[1] * 0.5 + out[1].mean(axis=0) * 0.5]


def _route(cb, route, monkeypatch):
    """The prune's candidate route: nested boxes (few pieces), or an STRtree of each piece's
    first vertex, or of its far vertex (many pieces)."""
    monkeypatch.setattr(cb, "BOX_PROPOSALS", 1 << 30 if route == "boxes" else 0)
    monkeypatch.setattr(cb, "FAR_VERTEX_PIECES", 0 if route == "far" else 1 << 30)


@pytest.mark.parametrize("route", ["boxes", "first", "far"])
@pytest.mark.parametrize("seed", range(6))
def test_containment_pruning_equals_the_scan(seed, route, monkeypatch):
    import cspace.translation.build as cb

    _route(cb, route, monkeypatch)
    pieces = random_pieces(np.random.default_rng(seed), 150, spread=15.0)
    want = contained_reference(pieces)
    assert want and contained_pieces(pieces) == want


@pytest.mark.parametrize("route", ["boxes", "first", "far"])
def test_containment_pruning_of_a_fan_equals_the_scan(route, monkeypatch):
    # Wedges from one centre (a star's spikes, as decomposed) share their inner vertex: among
    # many pieces each stands for itself by its far vertex; nested half-wedges must be found.
    import cspace.translation.build as cb

    _route(cb, route, monkeypatch)
    k = 60
    a = np.linspace(0, 2 * np.pi, k, endpoint=False)
    wedges = [np.array([[0.0, 0.0], [10 * np.cos(t), 10 * np.sin(t)], [10 * np.cos(t + 0.2), 10 * np.sin(t + 0.2)]])
              for t in a]
    nested = [0.5 * w for w in wedges[::7]] + [wedges[3].copy()]
    pieces = wedges + nested
    want = contained_reference(pieces)
    assert len(want) == len(nested) and contained_pieces(pieces) == want


def test_pair_sums_equal_minkowski_sum():
    rng = np.random.default_rng(3)
    obs = random_pieces(rng, 40) + [np.array([[np.cos(t), np.sin(t)] for t in np.linspace(0, 6.2, 90)])]
    robot = [reflect(p) for p in random_pieces(rng, 3)]
    got = pair_sums(obs, robot)
    want = [minkowski_sum(p, r) for p in obs for r in robot]
    assert len(got) == len(want) and all(np.array_equal(a, b) for a, b in zip(got, want))


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(SCENARIOS, "*.toml"))), ids=os.path.basename)
def test_build_with_the_loaders_convexity_equals_a_fresh_one(path):
    cs = CSpace.from_scenario(path)
    sc = cs.scenario
    fresh = CSpace(sc.bounds, [o.polygon for o in sc.obstacles], [r.polygon for r in sc.robot],
                   obstacle_holes=[o.holes for o in sc.obstacles], robot_is_disk=sc.robot_kind == "disk",
                   normalized=True, margin=sc.margins())
    assert len(cs.pieces) == len(fresh.pieces) and all(np.array_equal(a, b) for a, b in zip(cs.pieces, fresh.pieces))
    assert cs.piece_pairs == fresh.piece_pairs


def test_piece_set_packing():
    pieces = random_pieces(np.random.default_rng(9), 30)
    ps = PieceSet(pieces)
    assert np.array_equal(ps.end, np.concatenate([np.roll(p, -1, axis=0) for p in pieces]))
    assert np.array_equal(ps.lo, np.array([p.min(axis=0) for p in pieces]))
    assert np.array_equal(ps.hi, np.array([p.max(axis=0) for p in pieces]))
    assert ps._lists == [p.tolist() for p in pieces]


@pytest.mark.parametrize("seed", range(4))
def test_pruned_cspace_packs_exactly_its_kept_pieces(seed):
    # The prune hands its packing of the raw pieces to the index's PieceSet, cut down to
    # the pieces it keeps: pieces outside the bounds and pieces inside another are
    # dropped here, and the packing must still be the kept pieces' own, in their order.
    from cspace.translation.broadphase import GridIndex

    rng = np.random.default_rng(seed)
    obstacles = random_pieces(rng, 25)
    obstacles += [p * 0.2 + p.mean(axis=0) * 0.8 for p in obstacles[:5]]  # inside their originals
    obstacles += [p + 40.0 for p in obstacles[5:9]]  # beyond the bounds
    cs = CSpace((0, 10, 0, 10), obstacles, [np.array([[0., 0], [0.3, 0], [0, 0.2]])])
    kinds = {s.name: s.counts for s in cs.stages}["prune"]
    assert kinds["outside_bounds"] > 0 and kinds["inside_another"] > 0
    fresh = PieceSet(cs.pieces)
    assert np.array_equal(cs.packed.start, fresh.start) and np.array_equal(cs.packed.offsets, fresh.offsets)
    assert np.array_equal(cs.packed.lo, fresh.lo) and np.array_equal(cs.packed.hi, fresh.hi)
    # the grid's certified margin reads the packed vertices instead of the boxes: the same
    assert GridIndex(cs.pieces, cs.bounds, packed=cs.packed).margin == GridIndex(cs.pieces, cs.bounds).margin
