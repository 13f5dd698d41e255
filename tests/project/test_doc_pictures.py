"""Every picture the documentation shows is in the repository: the file exists beside the page
that links it, and .gitignore lets it through (a picture drawn into an ignored folder exists on
the machine that drew it and nowhere else: docs/figures/benchmr/ was such a folder)."""
from __future__ import annotations

import glob
import os
import re
import subprocess

import pytest

from conftest import ROOT

PAGES = [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
LINK = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")


def pictures() -> list[tuple[str, str]]:
    """(page, picture's path relative to the root) of every local picture link."""
    out = []
    for page in PAGES:
        with open(page, encoding="utf-8") as fh:
            for target in LINK.findall(fh.read()):
                if not re.match(r"[a-z]+://", target):
                    out.append((os.path.relpath(page, ROOT),
                                os.path.relpath(os.path.normpath(os.path.join(os.path.dirname(page), target)), ROOT)))
    return out


def test_every_linked_picture_exists():
    found = pictures()
    assert len(found) >= 20  # the guide's and the benchmarks page's pictures: the pattern matches
    missing = [f"{page}: {pic}" for page, pic in found if not os.path.isfile(os.path.join(ROOT, pic))]
    assert missing == []


def test_no_linked_picture_is_ignored_by_git():
    if not os.path.exists(os.path.join(ROOT, ".git")):  # a folder, or a worktree's file
        pytest.skip("not a git checkout")
    found = sorted({pic for _, pic in pictures()})
    proc = subprocess.run(["git", "-C", ROOT, "check-ignore", "--no-index", "--stdin"], input="\n".join(found),
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode in (0, 1), proc.stderr  # 1: none ignored
    probe = subprocess.run(["git", "-C", ROOT, "check-ignore", "--no-index", "x.png"], capture_output=True, text=True,
                           timeout=60)
    assert probe.stdout.strip() == "x.png"  # the check sees the ignore rules (an output picture is ignored)
    assert [p for p in proc.stdout.split("\n") if p] == []
