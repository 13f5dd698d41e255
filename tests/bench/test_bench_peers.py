"""The peers of bench_se2's side-by-side part (scripts/se2_peers.py): the motion-check step
asked for is the one their discrete motion check uses."""
from __future__ import annotations

import os

import pytest

from conftest import ROOT, load_script

pytest.importorskip("ompl")


def test_a_finer_peer_step_checks_more_states_per_motion():
    from cspace.io.load import load_scenario
    from planners.core.plan import build_cspace, make_adapter

    peers = load_script("se2_peers")
    sc = load_scenario(os.path.join(ROOT, "scenarios", "se2", "bar_door.toml"))
    cs = build_cspace(sc)
    adapter = make_adapter(sc, cs)
    q = sc.all_queries()[0]
    base = peers.shapely_checker(sc)
    counts = {}
    for step in (None, 0.01, 0.001):
        calls = [0]

        def counting(s, calls=calls):
            calls[0] += 1
            return base(s)

        path, _ = peers.peer_first(adapter, counting, adapter.pose(q.start), adapter.pose(q.goal), 1, 10.0,
                                   resolution=step)
        assert path is not None
        counts[step] = calls[0]
    assert counts[None] == counts[0.01]  # OMPL's default step is 1 % of the extent: the same run
    assert counts[0.001] > 3 * counts[0.01]  # ten times finer: many more states per motion
