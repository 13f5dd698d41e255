"""The scenario loader: what it accepts, and a one-line error naming file and field for each fault."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest

from cspace import ScenarioError, load_scenario
from cspace.kernel.polygons.disk import disk_error
from cspace.kernel.polygons.polygon import signed_area

BASE = """
name = "t"
[bounds]
xmin = 0
xmax = 10
ymin = 0
ymax = 10
[start]
x = 1
y = 1
[goal]
x = 9
y = 9
"""


def test_minimal_scenario_is_a_point_robot(write_toml):
    sc = load_scenario(write_toml(BASE))
    assert sc.is_point_robot and sc.robot_kind == "point"
    assert sc.bounds == (0.0, 10.0, 0.0, 10.0)
    assert sc.start == (1.0, 1.0) and sc.goal == (9.0, 9.0)


def test_polygons_are_normalised_to_ccw_with_collinear_vertices_dropped(write_toml):
    sc = load_scenario(write_toml(BASE + """
[[obstacles]]
polygon = [[4, 4], [4, 6], [5, 6], [6, 6], [6, 4]]
"""))
    p = sc.obstacles[0].polygon
    assert signed_area(p) > 0 and len(p) == 4 and sc.obstacles[0].convex


def test_disks_become_containing_polygons_within_the_tolerance(write_toml):
    sc = load_scenario(write_toml("disk_tolerance = 1e-4\n" + BASE + """
[[obstacles]]
center = [5, 5]
radius = 2
"""))
    ob = sc.obstacles[0]
    d = np.hypot(ob.polygon[:, 0] - 5, ob.polygon[:, 1] - 5)
    n = len(ob.polygon)
    # every vertex at the circumradius, so the polygon contains the disk; error within tolerance
    assert np.all(d >= 2 / math.cos(math.pi / n) * (1 - 1e-15))
    assert disk_error(2, n) <= 1e-4 * 2
    assert ob.disk == (5.0, 5.0, 2.0)


def test_theta_rotates_the_robot_and_goal_theta_must_match(write_toml):
    text = BASE.replace("y = 1\n[goal]", "y = 1\ntheta = 1.5707963267948966\n[goal]") + """
[robot]
polygon = [[0, 0], [2, 0], [2, 0.5], [0, 0.5]]
"""
    sc = load_scenario(write_toml(text))
    p = sc.robot[0].polygon
    # a quarter turn CCW maps the long x-extent onto y
    assert np.ptp(p[:, 1]) == pytest.approx(2.0) and np.ptp(p[:, 0]) == pytest.approx(0.5)
    bad = text.replace("y = 9\n", "y = 9\ntheta = 0.5\n", 1)
    with pytest.raises(ScenarioError, match="goal.theta"):
        load_scenario(write_toml(bad, "bad.toml"))


def test_queries_are_read(write_toml):
    sc = load_scenario(write_toml(BASE + """
[[queries]]
start = [2, 2]
goal = [8, 8]
[[queries]]
start = {x = 3, y = 3}
goal = {x = 7, y = 7}
"""))
    assert [q.start for q in sc.queries] == [(2.0, 2.0), (3.0, 3.0)]
    assert len(sc.all_queries()) == 3


def test_peer_scenarios_load():
    from conftest import OMPL_SCENES

    for f in sorted(os.listdir(OMPL_SCENES)):
        if f.endswith(".toml"):
            sc = load_scenario(os.path.join(OMPL_SCENES, f))
            assert sc.is_point_robot


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda t: t.replace("xmax = 10", 'xmax = "10"'), "bounds.xmax"),
        (lambda t: t.replace("xmax = 10\n", ""), "bounds.xmax"),
        (lambda t: t.replace("xmax = 10", "xmax = nan"), "bounds.xmax"),
        (lambda t: t.replace("ymax = 10", "ymax = inf"), "bounds.ymax"),
        (lambda t: t.replace("xmax = 10", "xmax = 0"), "bounds"),
        (lambda t: t.replace("x = 1\n", "x = -1\n", 1), "start"),
        (lambda t: t.replace("y = 9", "y = 11"), "goal"),
        (lambda t: t.replace("[goal]\nx = 9\ny = 9\n", ""), "goal"),
        (lambda t: t.replace("x = 1\n", "x = true\n", 1), "start.x"),
        (lambda t: t + "[[obstacles]]\npolygon = [[1, 1], [2, 2], [1, 1]]\n", "obstacles[0].polygon"),
        (lambda t: t + "[[obstacles]]\npolygon = [[3, 3], [5, 5], [5, 3], [3, 5]]\n", "obstacles[0].polygon"),
        (lambda t: t + "[[obstacles]]\npolygon = [[3, 3], [4, 4], [5, 5]]\n", "obstacles[0].polygon"),
        (lambda t: t + "[[obstacles]]\npolygon = [[0, 0], [2, 0], [2, 2], [0, 2]]\n", "start"),
        (lambda t: t + "[[obstacles]]\ncenter = [9, 9]\nradius = 0.5\n", "goal"),
        (lambda t: t + "[[obstacles]]\ncenter = [5, 5]\nradius = -1\n", "obstacles[0].radius"),
        (lambda t: t + "[robot]\npolygon = [[0, 0], [1, 0]]\n", "robot.polygon"),
        (lambda t: t + "[planner]\ntime = 0\n", "planner.time"),
        (lambda t: t + "[planner]\nseed = -3\n", "planner.seed"),
        (lambda t: "colour = 3\n" + t, "colour"),
        (lambda t: t + "[[obstacles]]\npolygon = [[2, 2], [8, 2], [8, 8], [2, 8]]\n"
                       "holes = [[[1, 1], [3, 1], [3, 3], [1, 3]]]\n", "obstacles[0].holes"),
        (lambda t: t.replace("[bounds]", "[bounds\n"), "toml"),
        (lambda t: t.replace("xmax = 10", "xmax = 1e121"), "bounds.xmax"),  # beyond 2^400
        (lambda t: t + "[[obstacles]]\ncenter = [5, 5]\nradius = 3e120\n", "obstacles[0].radius"),
        (lambda t: t.replace("xmin = 0", "xmin = 1e-300").replace("xmax = 10", "xmax = 2e-300")
                    .replace("ymin = 0", "ymin = 1e-300").replace("ymax = 10", "ymax = 2e-300"), "bounds"),
    ],
)
def test_each_fault_names_the_file_and_the_field(write_toml, edit, field):
    path = write_toml(edit(BASE))
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    err = exc.value
    assert err.field == field
    assert str(err).startswith(f"{path}: {field}: ")
    assert "\n" not in str(err)


def test_unreadable_file(tmp_path):
    with pytest.raises(ScenarioError, match="file: cannot read"):
        load_scenario(tmp_path / "missing.toml")


def test_loading_does_not_modify_the_file(write_toml):
    path = write_toml(BASE + "[[obstacles]]\npolygon = [[6, 6], [4, 6], [4, 4], [6, 4]]\n")
    before = open(path, "rb").read()
    load_scenario(path)
    assert open(path, "rb").read() == before


TRI = "[[0, 0], [1, 0], [0, 1]]"


@pytest.mark.parametrize(
    "extra, field, message",
    [
        (f"[robot]\npolgon = {TRI}\n", "robot.polgon", "unknown field (did you mean polygon?)"),
        ("[robot]\nraduis = 0.5\n", "robot.raduis", "unknown field (did you mean radius?)"),
        (f"[robot]\n[[robot.parts]]\npolgyon = {TRI}\n", "robot.parts[0].polgyon",
         "unknown field (did you mean polygon?)"),
        ("[[obstacles]]\ncenter = [5, 5]\nraduis = 1\n", "obstacles[0].raduis", "unknown field (did you mean radius?)"),
        ("[planer]\nname = 'RRT'\n", "planer", "unknown field (did you mean planner?)"),
        ("[planner]\nnmae = 'RRT'\n", "planner.nmae", "unknown field (did you mean name?)"),
        ("[[obstacle]]\ncenter = [5, 5]\nradius = 1\n", "obstacle", "unknown field (did you mean obstacles?)"),
        # Nothing close: the whole list, so the user still learns what is allowed.
        ("colour = 3\n", "colour", "unknown field (expected one of: bounds, clearance, disk_tolerance, expect, goal, "
                                   "margin, name, obstacles, planner, queries, robot, slabs, space, start, "
                                   "turning_radius)"),
        ("[robot]\nholes = []\n", "robot.holes", "unknown field (expected one of: parts, polygon, radius)"),
        # Two forms in one table.
        (f"[[obstacles]]\ncenter = [5, 5]\npolygon = {TRI}\n", "obstacles[0]", "center and polygon exclude each other"),
        (f"[[obstacles]]\nradius = 1\npolygon = {TRI}\n", "obstacles[0]", "polygon and radius exclude each other"),
        (f"[robot]\nradius = 0.5\npolygon = {TRI}\n", "robot", "polygon and radius exclude each other"),
        (f"[robot]\npolygon = {TRI}\n[[robot.parts]]\npolygon = {TRI}\n", "robot", "parts and polygon exclude each other"),
        ("[robot]\nradius = 0.5\ncenter = [0, 0]\n", "robot.center", "a disk robot is centred on its reference point"),
        ("[[obstacles]]\nradius = 1\n", "obstacles[0].center", "missing"),
    ],
)
def test_messages_name_the_key_and_what_to_do(write_toml, extra, field, message):
    # Tables go at the end, plain keys at the top (after a table they would belong to it).
    path = write_toml(BASE + extra if extra.startswith("[") else extra + BASE)
    with pytest.raises(ScenarioError) as exc:
        load_scenario(path)
    assert exc.value.field == field
    assert str(exc.value).startswith(f"{path}: {field}: {message}")
    assert "\n" not in str(exc.value)


def test_the_known_keys_are_one_set_to_extend(write_toml, monkeypatch):
    # A new top-level section (say `velocity`) is one entry in TOP_LEVEL_KEYS; suggestions follow it.
    from cspace.io.scenario import validate
    path = write_toml("velocty = 0.5\n" + BASE)
    with pytest.raises(ScenarioError, match="expected one of"):
        load_scenario(path)
    monkeypatch.setattr(validate, "TOP_LEVEL_KEYS", validate.TOP_LEVEL_KEYS | {"velocity"})
    with pytest.raises(ScenarioError, match=r"velocty: unknown field \(did you mean velocity\?\)"):
        load_scenario(path)
    # `clearance` was added that way (issue 21).
    with pytest.raises(ScenarioError, match=r"clearence: unknown field \(did you mean clearance\?\)"):
        load_scenario(write_toml("clearence = 0.5\n" + BASE, "c.toml"))


def test_validity_is_checked_at_a_scale_geos_can_compute(write_toml):
    # GEOS's own arithmetic underflows on a triangle 1e-300 wide and called it
    # self-intersecting; the check now runs on an exact power-of-two copy near 1.
    sc = load_scenario(write_toml(BASE + "[robot]\npolygon = [[0, 0], [1e-300, 0], [0, 1e-300]]\n"))
    assert sc.robot[0].polygon.shape == (3, 2)
    bow = "[[0, 0], [2e-300, 2e-300], [2e-300, 0], [0, 2e-300]]"
    with pytest.raises(ScenarioError, match=r"robot.polygon: not a simple polygon \(Self-intersection"):
        load_scenario(write_toml(BASE + f"[robot]\npolygon = {bow}\n"))


@pytest.mark.parametrize("name", ["parts.toml", "u_robot.toml", "ompl/circles.toml", "se2/tee_slot.toml", "se2/bar_door.toml"])
def test_probe_batch_matches_a_union_per_pose(name):
    # CollisionProbe.first_hits places every pose's robot parts in one tree query; the
    # oracle here is the robot's parts united at each pose (shapely) and queried alone.
    import shapely

    from conftest import SCENARIOS
    from cspace.io.scenario.probe import CollisionProbe

    sc = load_scenario(os.path.join(SCENARIOS, name))
    probe = CollisionProbe(sc)
    rng = np.random.default_rng(7)
    xmin, xmax, ymin, ymax = sc.bounds
    poses = [(float(x), float(y), float(t)) if sc.space == "se2" else (float(x), float(y))
             for x, y, t in zip(rng.uniform(xmin, xmax, 300), rng.uniform(ymin, ymax, 300), rng.uniform(-3, 3, 300))]
    obstacles = [o.to_shapely() for o in sc.obstacles]
    want = []
    for q in poses:
        parts = sc.robot_at(q[0], q[1], q[2] if len(q) > 2 else 0.0)
        body = shapely.union_all([shapely.Polygon(p) for p in parts]) if parts else shapely.Point(q[0], q[1])
        want.append(next((k for k, o in enumerate(obstacles) if body.intersects(o)), None))
    got = probe.first_hits(poses)
    assert got == want and any(h is None for h in got) and any(h is not None for h in got)


FULL = BASE + """
[robot]
polygon = [[-0.2, -0.2], [0.2, -0.2], [0.0, 0.3]]
[[obstacles]]
polygon = [[4.0, 4.0], [6.0, 4.0], [6.0, 6.0], [4.0, 6.0]]
[planner]
name = "RRTConnect"
time = 1.0
"""


def _keys(doc: dict, where: str = "") -> list[str]:
    """Every key of a TOML document, dotted (a list of tables as its first element)."""
    out = []
    for k, v in doc.items():
        path = f"{where}.{k}" if where else k
        out.append(path)
        if isinstance(v, dict):
            out += _keys(v, path)
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            out += _keys(v[0], f"{path}[0]")
    return out


def _rename(text: str, dotted: str, new: str) -> str:
    """The document with the key ``dotted`` renamed ``new`` (by its line inside its table)."""
    *tables, key = dotted.replace("[0]", "").split(".")
    lines, table = text.splitlines(), ""
    for i, line in enumerate(lines):
        if line.startswith("["):
            table = line.strip("[]")
        elif table == ".".join(tables) and line.split("=")[0].strip() == key:
            lines[i] = line.replace(key, new, 1)
            return "\n".join(lines) + "\n"
    raise AssertionError(dotted)


try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib


@pytest.mark.parametrize("dotted", [k for k in _keys(tomllib.loads(FULL))
                                    if "." in k and not k.startswith("planner.")])
def test_a_misspelt_key_is_named_with_its_correction(dotted, write_toml):
    # a typo in a key (xmaxx) is reported as the unknown key with a suggestion, never as the
    # key it was meant to be being missing (issue 51, point 7)
    key = dotted.rsplit(".", 1)[1]
    with pytest.raises(ScenarioError) as exc:
        load_scenario(write_toml(_rename(FULL, dotted, key + key[-1])))
    assert exc.value.field.endswith(key + key[-1]) and f"did you mean {key}?" in exc.value.message, str(exc.value)
