"""A walk whose exact re-check fails is repaired, never reported as undecided while time is left
(issue 49, point 4): its links are routed round, its slab refined below the floor if need be."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cspace.se2 import exact
from cspace.se2.exact_path import AssemblyError

WALL = [np.array([[4., 0], [5, 0], [5, 4], [4, 4]]), np.array([[4., 6], [5, 6], [5, 10], [4, 10]])]
BAR = [np.array([[-1.5, -0.2], [1.5, -0.2], [1.5, 0.2], [-1.5, 0.2]])]


def run(monkeypatch, fails):
    """The door scene (the bar must turn to pass), with ``assemble`` failing as ``fails(walk, part)``
    says (an AssemblyError at that walk index, like an overlay rounding at a vertex)."""
    real = exact.assemble
    seen = []

    def flaky(walk, part, freg, regions, start, goal, near=False):
        i = fails(walk, part)
        seen.append([part[n[0]] if n[0] >= 0 else n for n, _ in walk])
        if i is not None:
            e = AssemblyError(f"simulated failure at node {i}")
            e.index = i
            raise e
        return real(walk, part, freg, regions, start, goal, near=near)

    monkeypatch.setattr(exact, "assemble", flaky)
    r = exact.exact_se2_search(WALL, BAR, (0, 10, 0, 10), (2, 5, 0.0), (8, 5, 0.0), time_limit=60.0)
    return r, seen


def test_a_failed_walk_is_routed_round(monkeypatch):
    calls = iter(range(100))
    r, seen = run(monkeypatch, lambda walk, part: 1 if next(calls) < 3 else None)
    assert r.status == "solved" and r.stats["repairs"] == 3 and len(seen) == 4
    assert all(seen[i] != seen[i + 1] for i in range(3))  # each retry takes another walk
    d = np.diff(r.path, axis=0)
    assert np.all((np.hypot(d[:, 0], d[:, 1]) == 0) | (d[:, 2] == 0))  # translations and turns only


def test_a_slab_that_always_fails_is_refined_until_its_halves_pass(monkeypatch):
    """Every walk through the first failing walk's slab fails there: the search bisects it (below
    the floor if need be) and finds a walk through its halves or round it, not "undecided"."""
    bad = []

    def fails(walk, part):
        for i, (n, _) in enumerate(walk):
            if n[0] >= 0:
                if not bad:
                    bad.append(part[n[0]])
                if part[n[0]] == bad[0]:
                    return i
        return None

    r, seen = run(monkeypatch, fails)
    assert r.status == "solved" and r.stats["repairs"] >= 1
    assert all(bad[0] not in w for w in seen[-1:])


@pytest.mark.slow
def test_no_time_left_after_failures_is_undecided_with_the_reason(monkeypatch):
    r, _ = run(monkeypatch, lambda walk, part: 1)
    assert r.status == "undecided" and r.stats["repairs"] >= 1
    # Every FREE graph searched joined start and goal (only the assembly failed): none establishes
    # that no path keeps more than some D, so the answer states none, and says why.
    assert not math.isfinite(r.resolution)
    assert "no FREE graph was searched to its end" in r.stats["statement"], r.stats
