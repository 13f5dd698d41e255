"""The offline page (``cspace view``, ``plan --html``) under hostile scenarios (issue 48).

Classes of fault: a string of the scenario read as plotly markup (a ``url()`` fetched, a link
made), the URL hash driving the sliders with values that are not steps, and a page whose size
grows as (footprint vertices) x (frames).
"""
from __future__ import annotations

import json
import os
import re

import pytest

from conftest import load_script

plotly = pytest.importorskip("plotly", reason="cspace view needs plotly (pip install -e \".[view]\")")

import planners  # noqa: E402
from planners.errors import InputError  # noqa: E402
from planners.pictures.view import view_html, write_view  # noqa: E402
from planners.pictures.view import figure as fg  # noqa: E402
from planners.pictures.view.figure import figure_dict  # noqa: E402

MARKUP = ['<span style="background-image:url(http://127.0.0.1:9/a)">x</span>',
          '<a href="http://127.0.0.1:9/b">link</a>', "<b>bold</b><br>next", "&lt;img&gt; & <i>",
          '<sup style="background:url(http://127.0.0.1:9/c)">s</sup><img src=x onerror=alert(1)>']


def scene(name: str, robot: dict | None = None, tolerance: float | None = None) -> dict:
    d = {"name": name, "bounds": {"xmin": 0, "xmax": 10, "ymin": 0, "ymax": 10},
         "robot": robot or {"polygon": [[-0.4, -0.3], [0.4, -0.3], [0.0, 0.5]]},
         "obstacles": [{"polygon": [[4, 0], [5, 0], [5, 6], [4, 6]]}],
         "start": {"x": 1, "y": 1}, "goal": {"x": 9, "y": 9}}
    if tolerance is not None:
        d["disk_tolerance"] = tolerance
    return d


def texts(node, out=None):
    """Every string under a plotly text key of a figure."""
    out = [] if out is None else out
    if isinstance(node, dict):
        for k, v in node.items():
            if k in fg.TEXT_KEYS and isinstance(v, str):
                out.append(v)
            elif k in fg.TEXT_KEYS and isinstance(v, list):
                out += [s for s in v if isinstance(s, str)]
            else:
                texts(v, out)
    elif isinstance(node, list):
        for v in node:
            texts(v, out)
    return out


@pytest.mark.parametrize("name", MARKUP)
def test_no_text_of_the_figure_holds_markup(name):
    from cspace.io.load import scenario_from_dict

    res = planners.plan(scenario_from_dict(scene(name), "x.toml"), planner="exact")
    fig = figure_dict(res)
    shown = texts(fig)
    assert any(name.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;") in t for t in shown)
    assert all("<" not in t and ">" not in t for t in shown)  # no tag at all, ours included
    assert all(re.fullmatch(r"([^&]|&(amp|lt|gt);)*", t) for t in shown)  # every & starts an escape


def test_a_hostile_name_in_the_html_outside_the_figure_is_escaped():
    from cspace.io.load import scenario_from_dict

    res = planners.plan(scenario_from_dict(scene(MARKUP[0] + "</script><script>alert(1)</script>"), "x.toml"),
                        planner="exact")
    page = view_html(res, compress=False)
    assert "<script>alert(1)</script>" not in page and "<span style" not in page.split('id="figure"')[0]


def test_a_fine_disk_robot_shares_the_frames_budget_and_the_size_is_bounded(tmp_path, monkeypatch):
    # a disk robot at disk_tolerance 1e-8 has about 22 000 vertices: each pose frame draws at most
    # MOVING_VERTICES of them, so the frames cost (poses x MOVING_VERTICES), not (poses x 22 000)
    from cspace.io.load import scenario_from_dict

    pytest.importorskip("ompl")
    res = planners.plan(scenario_from_dict(scene("disk", {"radius": 0.5}, 1e-8), "d.toml"), seed=0)
    assert res.solved
    n_robot = sum(len(p) for p in res.scenario_data.robot_at(1.0, 1.0, 0.0))
    assert n_robot > 10_000
    fig = figure_dict(res, poses=500)
    per_frame = [fg.points(f["data"]) for f in fig["frames"]]
    assert len(per_frame) == 500 and max(per_frame) <= fg.MOVING_VERTICES + 2 * 2 + 1
    assert sum(per_frame) * 50 < 500 * n_robot  # the frames: a fiftieth of the footprint repeated
    # a bound below this figure's size: refused as bad input on the page's option, nothing written
    monkeypatch.setattr(fg, "MAX_POINTS", fg.points(fig["data"]) - 1)
    out = tmp_path / "v.html"
    with pytest.raises(InputError, match=r"--out: the page would draw \d+ points, more than the bound"):
        write_view(res, str(out), poses=500, option="--out")
    assert not out.exists() and os.listdir(tmp_path) == []


def test_the_size_bound_is_checked_as_the_angle_frames_grow(monkeypatch):
    # an SE(2) scene: the slab frames are counted as they are made (a bound below one frame:
    # refused within the first few, not after all of them were built)
    from cspace.io.load import scenario_from_dict

    d = scene("se2")
    d["space"], d["slabs"] = "se2", 16
    res = planners.plan(scenario_from_dict(d, "s.toml"), planner="exact")
    made = []
    real = fg.slab_traces
    monkeypatch.setattr(fg, "slab_traces", lambda *a: made.append(1) or real(*a))
    monkeypatch.setattr(fg, "MAX_POINTS", 50)
    with pytest.raises(InputError, match="the page would draw"):
        figure_dict(res, angles=720)
    assert len(made) < 16  # of the 16 slab frames


# ---------------------------------------------------------------- in a real browser

shots = load_script("make_view_screenshots")
needs_chromium = pytest.mark.skipif(shots.chromium() is None, reason="chromium is not installed")


@pytest.fixture(scope="module")
def browser():
    if shots.chromium() is None:
        pytest.skip("chromium is not installed")
    with shots.Browser(width=1200, height=1000) as b:
        yield b


@pytest.mark.slow
@needs_chromium
def test_a_hostile_name_fetches_nothing_and_makes_no_link(browser, tmp_path):
    from cspace.io.load import scenario_from_dict

    name = " ".join(MARKUP)
    d = scene(name)
    d["space"], d["slabs"] = "se2", 8
    res = planners.plan(scenario_from_dict(d, "x.toml"), planner="exact")
    out = str(tmp_path / "h.html")
    write_view(res, out)
    b = browser
    b.requests.clear()
    b.open("file://" + out, wait=60)
    assert b.eval("document.title") == "ok", b.eval("document.getElementById('errors').textContent")
    b.pump(0.5)
    assert b.requests and all(u.startswith("file://") for u in b.requests), b.requests
    assert b.eval("document.querySelectorAll('#plot a, #plot img, #plot [style*=url]').length") == 0
    title = b.eval("document.querySelector('.gtitle').textContent")
    assert '<span style="background-image:url(http://127.0.0.1:9/a)">' in title and "<a href=" in title
    # the hash: not-a-number ignored, out of range clamped, never a JavaScript error
    for hash_, pose in (("#pose=-1", 0), ("#pose=abc", 0), ("#pose=99999", 119), ("#pose=1e400", 119),
                        ("#pose=%20", 119), ("#angle=-7&pose=3", 3), ("#angle=NaN&pose=", 3)):
        b.eval(f"location.hash = {json.dumps(hash_)}")
        b.pump(0.4)
        assert b.eval("document.getElementById('errors').textContent") == "", hash_
        assert b.eval("document.title") == "ok", hash_
        assert b.state()["sliders"]["pose"] == pose, hash_


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full (a full disk)")
@pytest.mark.parametrize("command,option", [("plan", "--html"), ("view", "--out")])
def test_a_page_on_a_full_disk_names_its_own_option(tmp_path, capsys, command, option):
    from conftest import SCENARIOS
    from planners.cli import main

    full = tmp_path / "full.html"
    full.symlink_to("/dev/full")
    assert main([command, os.path.join(SCENARIOS, "basic.toml"), "--planner", "exact", option, str(full)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{full}: {option}: cannot write" in err[0], err
