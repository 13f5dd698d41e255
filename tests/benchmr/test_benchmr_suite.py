"""Bench-MR's suite script and its page section (issue 50, points 1, 3 and 4), without a checkout:
the lattice that says why a Dubins query is undecided, the per-world ratios against the peer, and
the benchmarks page's section, which reads nothing outside the repository unless given a checkout.

Oracles: scenes built so the answer is known (a car in a slot one car long, walls a tenth of a
unit from its sides and its bumper: it cannot leave forward; the same car in the open), and
ratios computed by hand.
"""
from __future__ import annotations

import json

from conftest import load_script

SUITE = load_script("bench_benchmr")
PAGE = load_script("make_benchmarks_page")


def car_scene(walls: bool):
    from cspace.io.scenario.validate import scenario_from_dict
    from planners.core.plan import build_cspace, make_adapter

    slot = [[[8, 8.8], [12, 8.8], [12, 9.4], [8, 9.4]], [[8, 10.6], [12, 10.6], [12, 11.2], [8, 11.2]],
            [[11.1, 8.8], [12, 8.8], [12, 11.2], [11.1, 11.2]]]  # sides and bumper, 0.1 from the car
    data = {"bounds": {"xmin": 0, "xmax": 30, "ymin": 0, "ymax": 30},
            "robot": {"polygon": [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]},
            "obstacles": [{"polygon": p} for p in slot] if walls else [],
            "start": {"x": 10, "y": 10, "theta": 0}, "goal": {"x": 20, "y": 20, "theta": 0}}
    sc = scenario_from_dict(data, "slot", space="dubins", turning_radius=4.0)
    cs = build_cspace(sc)
    return sc, make_adapter(sc, cs)


def test_a_car_parked_facing_a_bumper_is_boxed_in_and_one_in_the_open_is_not():
    sc, adapter = car_scene(walls=True)
    why = SUITE.boxed_in(adapter, sc.all_queries()[0], cap=2000)
    assert why is not None and why.startswith("the start's forward reach ends"), why
    from types import SimpleNamespace

    near = SimpleNamespace(start=(10.0, 10.0, 0.0), goal=(10.05, 10.0, 0.0))  # within the slot's reach
    assert SUITE.boxed_in(adapter, near, cap=2000) is None
    sc, adapter = car_scene(walls=False)
    assert SUITE.boxed_in(adapter, sc.all_queries()[0], cap=200) is None  # past the cap: no claim


def test_the_ratio_against_the_peer_is_given_per_world_over_its_sound_runs():
    def run(ours, peer, colliding=False):
        return {"ours_s": ours, "peer_s": peer, "peer_colliding": colliding}

    results = [{"world": "a", "runs": [run(1.0, 4.0), run(2.0, 1.0, colliding=True)]},
               {"world": "a", "runs": [run(3.0, 4.0), run(None, 2.0)]},
               {"world": "b", "runs": [run(2.0, 2.0), run(1.0, None)]}]
    worlds = {w["world"]: w for w in SUITE.per_world(results)}
    assert worlds["a"]["sound_runs"] == 2 and worlds["a"]["ratio_median"] == 2.0 / 4.0  # (1, 3) against (4, 4)
    assert worlds["a"]["met_median"] and worlds["a"]["met_mean"]
    assert worlds["b"]["ratio_median"] == 1.0 and not worlds["b"]["met_median"]


def test_the_page_section_shows_the_table_ratios_and_recheck_counts(tmp_path):
    row = {"world": "parking1", "space": "dubins", "runs": 5, "left_out": 0, "prep_s": 0.1, "ours_solved": 4,
           "proven_unsolvable": 0, "undecided_queries": [3], "boxed_in": {"3": "the start's forward reach ends"},
           "ours_colliding": 0, "ours_median_s": 0.02, "ours_mean_s": 0.03, "peer_solved": 5, "peer_colliding": 2,
           "peer_median_s": 0.1, "peer_mean_s": 0.2, "ratio": 0.2, "ratio_mean": 0.15, "ratio_runs": 4,
           "peer_recheck": {"paths": 5, "colliding": 2, "seconds": 0.1}}
    doc = {"rows": [row], "worlds": [{"world": "parking1", "sound_runs": 4, "ratio_median": 0.2, "ratio_mean": 0.15}],
           "load_start": [2.5, 2.0, 1.5]}
    (tmp_path / "b.json").write_text(json.dumps(doc))
    text = "\n".join(PAGE.benchmr_lines({"json": str(tmp_path / "b.json"), "stdout": ""}))
    assert "| parking1 | dubins | 5 | 100 ms | 4 (0) | 1 | 0 | 20 ms | 30 ms | 5 | 2 | 100 ms | 200 ms | 0.20x | 0.15x |" \
        in text
    assert "| parking1 | 4 | 0.20x | 0.15x |" in text and "| parking1 | dubins | 5 | 2 |" in text
    assert "2.50, 2.00, 1.50" in text  # the load beside the figures
    proven = dict(row, space="reeds-shepp", proven_unsolvable=2, proofs_accepted=2, proven_proof_median_s=0.18)
    doc["rows"] = [row, proven]
    (tmp_path / "b.json").write_text(json.dumps(doc))
    text = "\n".join(PAGE.benchmr_lines({"json": str(tmp_path / "b.json"), "stdout": ""}))
    assert "- parking1 reeds-shepp: 2 runs, 2 proofs accepted, median 180 ms CPU for the proofs" in text
    assert "- parking1 dubins:" not in text.split("Proven unsolvable")[1].split("Undecided")[0]  # none proven
