"""scripts/make_figures.py: the guide's figures are regenerated, non-trivial PNGs."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from conftest import ROOT

SCRIPT = os.path.join(ROOT, "scripts", "make_figures.py")


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True, timeout=120, cwd=ROOT)


@pytest.mark.slow
def test_basic_group_writes_real_pictures(tmp_path):
    out = tmp_path / "figs"
    proc = run("--out", str(out), "--only", "basic,theta_cspace")
    assert proc.returncode == 0, proc.stderr
    import matplotlib.image as mpimg

    names = sorted(os.listdir(out))
    assert names == ["basic_cspace.png", "basic_exact.png", "basic_plan.png", "theta_cspace.png", "u_robot_cspace.png"]
    for n in names:
        path = out / n
        assert path.stat().st_size > 10_000, n  # a drawing, not an empty canvas
        img = mpimg.imread(str(path))
        assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 300, (n, img.shape)
        # Several colours: obstacles, C-obstacles, robot and path were drawn on the white page.
        colours = np.unique((img[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
        assert len(colours) > 20, n
    assert "RRTConnect seed 1" in proc.stdout and "exact" in proc.stdout
    # Atomic writes leave no temporary files behind.
    assert not [n for n in names if not n.endswith(".png")]


def test_list_names_every_family_once():
    proc = run("--list")
    assert proc.returncode == 0, proc.stderr
    names = [line.split()[0] for line in proc.stdout.splitlines()]
    assert len(names) == len(set(names))
    for fam in ("maze", "bug_trap", "narrow_passage", "random_polygons", "disks", "office", "combs", "parts", "theta"):
        assert f"{fam}_cspace" in names and f"{fam}_plan" in names
    assert "circles_queries" in names


def test_unknown_selection_is_refused():
    proc = run("--only", "no_such_figure", "--out", os.devnull)
    assert proc.returncode != 0
    assert "no_such_figure" in proc.stderr
