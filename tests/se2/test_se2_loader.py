"""Scenario fields of rotating robots: space, slabs, poses with theta, and their errors."""
import math
import os

import pytest

from conftest import SCENARIOS
from cspace.io.load import ScenarioError, load_scenario, scenario_from_dict

SE2 = os.path.join(SCENARIOS, "se2")

BASE = {
    "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
    "robot": {"polygon": [[-1.0, -0.1], [1.0, -0.1], [1.0, 0.1], [-1.0, 0.1]]},
    "obstacles": [{"polygon": [[4, 4], [6, 4], [6, 6], [4, 6]]}],
    "start": {"x": 2, "y": 2, "theta": 0.5},
    "goal": {"x": 8, "y": 8, "theta": 2.0},
}


def doc(**kw):
    d = {k: (dict(v) if isinstance(v, dict) else v) for k, v in BASE.items()}
    d.update(kw)
    return d


def test_se2_poses_keep_theta_and_body_frame():
    sc = scenario_from_dict(doc(space="se2"))
    assert sc.space == "se2" and sc.dim == 3
    assert sc.start == (2.0, 2.0, 0.5) and sc.goal == (8.0, 8.0, 2.0)
    assert sc.theta == 0.0
    # the robot stays in its body frame (not turned by the start's theta)
    assert sc.robot[0].polygon[:, 0].max() == 1.0 and sc.robot[0].polygon[:, 1].max() == 0.1


def test_translation_goal_theta_differs_says_add_space():
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(doc())
    assert e.value.field == "goal.theta" and 'space = "se2"' in str(e.value)
    assert "\n" not in str(e.value)


def test_translation_default_unchanged():
    d = doc()
    d["goal"] = {"x": 8, "y": 8, "theta": 0.5}
    sc = scenario_from_dict(d)
    assert sc.space == "translation" and sc.dim == 2 and sc.start == (2.0, 2.0) and sc.theta == 0.5


@pytest.mark.parametrize("bad, field", [
    ({"space": "se3"}, "space"),
    ({"space": "se2", "slabs": 0}, "slabs"),
    ({"space": "se2", "slabs": 1.5}, "slabs"),
    ({"space": "se2", "slabs": True}, "slabs"),
    ({"slabs": 8}, "slabs"),  # translation has no slabs
])
def test_bad_space_and_slabs(bad, field):
    d = doc(**bad)
    d["goal"] = {"x": 8, "y": 8, "theta": 0.5}
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(d)
    assert e.value.field == field


def test_se2_queries_take_theta():
    sc = scenario_from_dict(doc(space="se2", queries=[
        {"start": [1, 1, 0.25], "goal": [9, 9]},
        {"start": {"x": 1, "y": 9, "theta": -1.0}, "goal": {"x": 9, "y": 1}},
    ]))
    assert sc.queries[0].start == (1.0, 1.0, 0.25) and sc.queries[0].goal == (9.0, 9.0, 0.0)
    assert sc.queries[1].start == (1.0, 9.0, -1.0) and sc.queries[1].goal == (9.0, 1.0, 0.0)


def test_translation_query_with_theta_is_refused():
    d = doc(queries=[{"start": [1, 1, 0.25], "goal": [9, 9]}])
    d["goal"] = {"x": 8, "y": 8, "theta": 0.5}
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(d)
    assert e.value.field == "queries[0].start" and 'space = "se2"' in str(e.value)


def test_se2_placement_uses_the_pose_angle():
    # Upright (theta = pi/2) at x = 3.5 the 2-long bar reaches x = 3.5 +- 0.1: free.
    # Flat (theta = 0) it reaches 4.5 and enters the obstacle (x >= 4): refused.
    ok = doc(space="se2")
    ok["start"] = {"x": 3.5, "y": 5, "theta": math.pi / 2}
    scenario_from_dict(ok)
    bad = doc(space="se2")
    bad["start"] = {"x": 3.5, "y": 5, "theta": 0.0}
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(bad)
    assert e.value.field == "start" and "collision" in str(e.value)


def test_bundled_se2_scenarios_load():
    files = sorted(f for f in os.listdir(SE2) if f.endswith(".toml"))
    assert len(files) >= 6
    for f in files:
        sc = load_scenario(os.path.join(SE2, f))
        assert sc.space == "se2" and len(sc.start) == 3


def test_space_override_turns_a_translation_file_into_se2(tmp_path):
    f = tmp_path / "t.toml"
    f.write_text('[bounds]\nxmin=0\nxmax=10\nymin=0\nymax=10\n[robot]\npolygon=[[-1,-0.1],[1,-0.1],[1,0.1],[-1,0.1]]\n'
                 '[start]\nx=2\ny=2\ntheta=0.5\n[goal]\nx=8\ny=8\ntheta=0.5\n')
    assert load_scenario(f).space == "translation"
    sc = load_scenario(f, space="se2")
    assert sc.space == "se2" and sc.start == (2.0, 2.0, 0.5) and sc.theta == 0.0
    with pytest.raises(ScenarioError):
        load_scenario(f, space="bogus")


def test_se2_angles_are_wrapped_into_ompls_range():
    d = doc(space="se2", queries=[{"start": [1, 1, 7.0], "goal": [9, 9, -4.0]}])
    d["goal"] = {"x": 8, "y": 8, "theta": math.pi}
    sc = scenario_from_dict(d)
    assert sc.goal[2] == -math.pi  # OMPL's SO(2) holds [-pi, pi): pi is -pi
    assert -math.pi <= sc.queries[0].start[2] < math.pi and abs(sc.queries[0].start[2] - (7.0 - 2 * math.pi)) < 1e-15
    assert abs(sc.queries[0].goal[2] - (-4.0 + 2 * math.pi)) < 1e-15
