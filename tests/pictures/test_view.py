"""``cspace view``: one offline HTML page per plan (issue 38).

The figure is checked as data (what each trace and frame holds), the page as text (nothing to
fetch, plotly.js and the figure packed and unpacking to the real thing), the command's exit
codes; then the pages of a translation scene, an SE(2) scene and a car are opened in headless
Chromium with the network off (scripts/make_view_screenshots.py's DevTools driver): drawn without
a JavaScript error, no request but the file itself, and real mouse clicks on the path slider,
the angle slider and the play button change what is drawn (the screenshots' pixels differ).
"""
from __future__ import annotations

import base64
import gzip
import json
import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT, SCENARIOS, load_script

plotly = pytest.importorskip("plotly", reason="cspace view needs plotly (pip install -e \".[view]\")")

import planners  # noqa: E402
from planners.pictures.view import view_html, write_view  # noqa: E402
from planners.pictures.view.figure import figure_dict  # noqa: E402

SCENES = {"translation": os.path.join(SCENARIOS, "basic.toml"),
          "se2": os.path.join(SCENARIOS, "se2", "bar_door.toml"),
          "car": os.path.join(SCENARIOS, "car", "u_turn.toml")}


@pytest.fixture(scope="module")
def results():
    return {kind: planners.plan(path, seed=0) for kind, path in SCENES.items()}


@pytest.fixture(scope="module")
def pages(results, tmp_path_factory):
    folder = tmp_path_factory.mktemp("view")
    out = {}
    for kind, res in results.items():
        out[kind] = str(folder / f"{kind}.html")
        write_view(res, out[kind])
    return out


def trace(fig, prefix):
    return next(t for t in fig["data"] if t["name"].startswith(prefix))


def unpack(page: str, block: str) -> str:
    m = re.search(rf'<script type="application/octet-stream" id="{block}">([^<]*)</script>', page)
    assert m, block
    return gzip.decompress(base64.b64decode(m.group(1))).decode("utf-8")


# ---------------------------------------------------------------- the figure as data

def test_translation_figure(results):
    res = results["translation"]
    assert res.solved
    fig = figure_dict(res, poses=50)
    names = [t["name"] for t in fig["data"]]
    assert names[:3] == ["bounds", "C-obstacle (reference point there: collision)", "obstacle"]
    cob = trace(fig, "C-obstacle")
    assert cob["x"].count(None) == len(res.cspace.pieces)  # one ring per convex piece
    assert [f["name"] for f in fig["frames"]] == [f"pose-{i}" for i in range(50)]
    first, last = fig["frames"][0]["data"][1], fig["frames"][-1]["data"][1]  # the reference point
    assert (first["x"][0], first["y"][0]) == pytest.approx(res.path[0])
    assert (last["x"][0], last["y"][0]) == pytest.approx(res.path[-1])
    assert [s["name"] for s in fig["layout"]["sliders"]] == ["pose"]
    play = fig["layout"]["updatemenus"][0]["buttons"][0]
    assert play["method"] == "animate" and len(play["args"][0]) == 50
    star = trace(fig, "closest approach")
    assert star["x"][1] == pytest.approx(res.min_clearance_obstacle[0], abs=1e-4)
    assert f"{res.min_clearance:.4g}" in star["name"]


def test_se2_angle_slider(results):
    res = results["se2"]
    fig = figure_dict(res, angles=32)
    angle = next(s for s in fig["layout"]["sliders"] if s["name"] == "angle")
    assert len(angle["steps"]) == 32
    slabs = {f["name"]: f for f in fig["frames"] if f["name"].startswith("slab-")}
    assert len(slabs) == min(32, res.cspace.slabs)
    # The bar lying flat (0 deg) and standing up (90 deg) block different places.
    flat = slabs[angle["steps"][16]["args"][0][0]]["data"][0]
    up = slabs[angle["steps"][24]["args"][0][0]]["data"][0]
    assert flat["x"] != up["x"]
    assert min(v for v in up["y"] if v is not None) < min(v for v in flat["y"] if v is not None)
    # The moving footprint turns: its first and middle frames differ in shape, not just place.
    poses = [f for f in fig["frames"] if f["name"].startswith("pose-")]
    assert poses[0]["data"][0]["x"] != poses[len(poses) // 2]["data"][0]["x"]


def test_car_curves_and_reverse(results):
    res = results["car"]
    assert res.solved
    fig = figure_dict(res)
    fwd, rev = trace(fig, "path (forward)"), trace(fig, "path (reverse)")
    assert rev["line"]["dash"] == "dash" and "dash" not in fwd["line"]
    assert any(s["direction"] == "reverse" for c in res.curves for s in c["segments"])
    # Drawn as curves: many more points than the waypoints' chords.
    assert len(fwd["x"]) > 10 * len(res.path)


def test_the_narrowest_gap_is_marked_only_where_a_path_crosses_one():
    """A door 1.001 times the robot: marked with the static plot's width, which equals the
    distance between the two C-obstacles (shapely); open space (clearance.toml): no mark."""
    import shapely

    from planners.pictures.plot import narrow_gap

    res = planners.plan(os.path.join(SCENARIOS, "narrow_passage.toml"))
    marks = [t for t in figure_dict(res)["data"] if t.get("name", "").startswith("narrowest gap")]
    gap = narrow_gap(res.scenario_data, res.cspace, [res])
    assert len(marks) == 1 and gap is not None and marks[0]["name"] == f"narrowest gap, {gap.width:.3g} wide"
    walls = [shapely.Polygon(p) for p in res.cspace.pieces]
    a, b = shapely.Point(gap.ends[0]), shapely.Point(gap.ends[1])
    assert min(w.distance(a) for w in walls) < 1e-9 and min(w.distance(b) for w in walls) < 1e-9
    open_space = planners.plan(os.path.join(SCENARIOS, "clearance.toml"))
    assert not [t for t in figure_dict(open_space)["data"] if t.get("name", "").startswith("narrowest gap")]


def test_point_robot_has_no_angle_slider(tmp_path):
    res = planners.plan(os.path.join(SCENARIOS, "ompl", "empty.toml"), space="se2", planner="RRTConnect", time=1)
    fig = figure_dict(res, angles=32)
    assert "angle" not in [s["name"] for s in fig["layout"]["sliders"]]


def test_proof_components_and_note():
    res = planners.plan(os.path.join(SCENARIOS, "se2", "wide_square.toml"), planner="exact")
    assert not res.solved and res.proof is not None
    fig = figure_dict(res, angles=16)
    assert fig["layout"]["updatemenus"] == []  # no path: nothing to play
    comps = [f["data"][1] for f in fig["frames"]]
    assert any(len(c["x"]) > 0 for c in comps), "the proof's components are drawn"
    page = view_html(res)
    assert "PROVEN UNSOLVABLE" in page and "proven unsolvable" in page


# ---------------------------------------------------------------- the page as text

def test_page_is_self_contained(pages):
    from plotly.offline import get_plotlyjs

    for kind, path in pages.items():
        text = open(path, encoding="utf-8").read()
        assert os.path.getsize(path) <= 4_000_000, kind
        assert not re.search(r"<(script|link|img|iframe)[^>]*\b(src|href)=", text), kind
        assert unpack(text, "plotly-gz") == get_plotlyjs()
        fig = json.loads(unpack(text, "figure-gz"))
        assert fig["frames"] and fig["layout"]["sliders"], kind
        outside = text.split('id="plotly-gz"')[0] + text.split('id="figure-gz"')[1]
        assert "http://" not in outside and "https://" not in outside


def test_page_uncompressed(results, tmp_path):
    text = view_html(results["translation"], compress=False)
    assert 'id="plotly-gz"' not in text and '<script type="application/json" id="figure">' in text
    block = text.split('<script type="application/json" id="figure">')[1].split("</script>")[0]
    assert json.loads(block)["frames"]


def test_cli_view(tmp_path):
    out = tmp_path / "v.html"
    run = subprocess.run([sys.executable, "-m", "planners.cli", "view", SCENES["translation"], "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    assert "solved by" in run.stdout and out.stat().st_size > 1_000_000
    bad = subprocess.run([sys.executable, "-m", "planners.cli", "view", SCENES["translation"], "--out",
                          str(tmp_path / "v.png")], capture_output=True, text=True, cwd=ROOT)
    assert bad.returncode == 2 and "--out" in bad.stderr
    inputs = subprocess.run([sys.executable, "-m", "planners.cli", "view", SCENES["translation"], "--out",
                             SCENES["translation"]], capture_output=True, text=True, cwd=ROOT)
    assert inputs.returncode == 2


def test_cli_view_takes_plan_s_import_and_margin_options(tmp_path):
    # what a user plans they can view (issue 51, point 5): an imported map with its robot, start and
    # goal, a safety margin, a car's turning radius; a scenario TOML still refuses the import options
    out = tmp_path / "m.html"
    office = os.path.join(SCENARIOS, "maps", "office.yaml")
    view = [sys.executable, "-m", "planners.cli", "view"]
    # RRTConnect stops at its first path: a generous limit costs nothing and holds on any machine
    run = subprocess.run(view + [office, "--radius", "0.2", "--start", "0.5,0.5", "--goal", "9.5,6.5",
                                 "--clearance", "0.05", "--time", "60", "--out", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    assert "margin asked 0.05" in run.stdout and out.stat().st_size > 1_000_000
    assert "office" in json.loads(unpack(out.read_text(encoding="utf-8"), "figure-gz"))["layout"]["title"]["text"]
    car = subprocess.run(view + [SCENES["car"], "--turning-radius", "0.9", "--out", str(tmp_path / "c.html")],
                         capture_output=True, text=True, cwd=ROOT)
    assert car.returncode in (0, 1) and car.stderr == "", car.stderr
    for args, option in (([office, "--start", "0.5,0.5"], "goal"), ([SCENES["translation"], "--radius", "0.2"], "--radius"),
                         ([SCENES["translation"], "--clearance", "-1"], "--clearance")):
        bad = subprocess.run(view + args + ["--out", str(tmp_path / "b.html")], capture_output=True, text=True, cwd=ROOT)
        assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and option in bad.stderr, bad.stderr
        assert not (tmp_path / "b.html").exists()
    image = os.path.join(SCENARIOS, "maps", "office.pgm")  # the map's image is an input: never written over
    over = subprocess.run(view + [office, "--radius", "0.2", "--start", "0.5,0.5", "--goal", "9.5,6.5", "--out", image],
                          capture_output=True, text=True, cwd=ROOT)
    assert over.returncode == 2


def test_cli_plan_html(tmp_path):
    out = tmp_path / "p.html"
    run = subprocess.run([sys.executable, "-m", "planners.cli", "plan", SCENES["car"], "--html", str(out)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    text = out.read_text(encoding="utf-8")
    assert "u-turn" in json.loads(unpack(text, "figure-gz"))["layout"]["title"]["text"]
    bad = subprocess.run([sys.executable, "-m", "planners.cli", "plan", SCENES["car"], "--html", str(out),
                          "--json", str(out)], capture_output=True, text=True, cwd=ROOT)
    assert bad.returncode == 2


def test_cli_view_without_plotly_is_bad_input(tmp_path, monkeypatch):
    import importlib.util

    from planners.errors import InputError
    from planners.pictures.view import check_plotly

    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "plotly" else object())
    with pytest.raises(InputError, match="pip install"):
        check_plotly(str(tmp_path / "v.html"), "--out")


# ---------------------------------------------------------------- in a real browser

shots = load_script("make_view_screenshots")
needs_chromium = pytest.mark.skipif(shots.chromium() is None,
                                    reason="chromium is not installed (apt-get install -y chromium; .ci/run does)")


def changed(a: bytes, b: bytes) -> int:
    """Pixels that differ between two PNG screenshots of one size."""
    from PIL import Image
    import io

    import numpy as np

    ia = np.asarray(Image.open(io.BytesIO(a)).convert("RGB"), dtype=np.int16)
    ib = np.asarray(Image.open(io.BytesIO(b)).convert("RGB"), dtype=np.int16)
    assert ia.shape == ib.shape
    return int((np.abs(ia - ib).sum(axis=2) > 30).sum())


@pytest.fixture(scope="module")
def browser():
    if shots.chromium() is None:
        pytest.skip("chromium is not installed")
    with shots.Browser(width=1200, height=1000) as b:
        yield b


def open_page(b, path):
    b.requests.clear()
    b.open("file://" + path, wait=60)
    assert b.eval("document.title") == "ok", b.eval("document.getElementById('errors').textContent")
    assert b.eval("document.getElementById('errors').textContent") == ""
    assert b.requests and all(u.startswith("file://") for u in b.requests), b.requests
    assert b.eval("document.querySelectorAll('.main-svg .scatterlayer .trace').length") >= 6


@needs_chromium
@pytest.mark.parametrize("kind", [k if k == "se2" else pytest.param(k, marks=pytest.mark.slow) for k in SCENES])
def test_browser_slider_moves_the_robot(browser, pages, kind):
    b = browser
    open_page(b, pages[kind])
    before = b.screenshot()
    assert b.state()["sliders"]["pose"] == 0
    b.click(*shots.slider_point(b, 0, 0.6))  # the path slider (the first)
    state = b.state()
    assert 0.5 * 119 <= state["sliders"]["pose"] <= 0.7 * 119 and state["frame"].startswith("pose-")
    after = b.screenshot()
    assert changed(before, after) > 200


@needs_chromium
@pytest.mark.parametrize("kind", ["se2", "car"])
def test_browser_angle_slider_changes_the_cspace(browser, pages, kind):
    b = browser
    open_page(b, pages[kind])
    start = b.state()["sliders"]["angle"]
    before = b.screenshot()
    b.click(*shots.slider_point(b, 1, 0.5))  # about 0 degrees: the robot lies along x
    after_state = b.state()
    assert after_state["sliders"]["angle"] != start and after_state["frame"].startswith("slab-")
    assert after_state["sliders"]["pose"] == 0  # the sliders are independent
    assert changed(before, b.screenshot()) > 200


@pytest.mark.slow
@needs_chromium
def test_browser_play_and_pause(browser, pages):
    b = browser
    open_page(b, pages["se2"])
    before = b.screenshot()
    play = b.box(".updatemenu-button", 0)
    b.click(play["left"] + play["width"] / 2, play["top"] + play["height"] / 2)
    b.pump(1.0)
    moving = b.state()["sliders"]["pose"]
    assert moving > 3, "play advances the frames and the path slider follows"
    pause = b.box(".updatemenu-button", 1)
    b.click(pause["left"] + pause["width"] / 2, pause["top"] + pause["height"] / 2)
    stopped = b.state()["sliders"]["pose"]
    b.pump(0.5)
    assert b.state()["sliders"]["pose"] == stopped < 119
    assert changed(before, b.screenshot()) > 200
