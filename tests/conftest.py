"""Shared fixtures: scenario files written from TOML text, paths to bundled data.

The test modules sit in folders by concern (tests/kernel/, tests/io/, ...); pytest puts each
test file's own folder on sys.path, and this file's folder, so ``from conftest import ROOT``
works from every one of them. What tests of different folders share (independent oracles, the
fuzzing contract) lives in tests/helpers/, plain modules put on sys.path here: a test imports
``from oracles import swept_clearance``, never another test module of another folder.
"""
from __future__ import annotations

import importlib.util
import sys
import os
import textwrap

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HELPERS = os.path.join(ROOT, "tests", "helpers")
if HELPERS not in sys.path:
    sys.path.insert(0, HELPERS)
SCENARIOS = os.path.join(ROOT, "scenarios")
# OMPL's planning-benchmark scenes, bundled (converted copies; see scenarios/ompl/README.md).
# Tests read only files inside the repository: a user's clone has nothing beside it.
OMPL_SCENES = os.path.join(SCENARIOS, "ompl")


@pytest.fixture
def write_toml(tmp_path):
    """write_toml(text, name="s.toml") -> path of a scenario file with that text."""

    def _write(text: str, name: str = "s.toml") -> str:
        p = tmp_path / name
        p.write_text(textwrap.dedent(text))
        return str(p)

    return _write


def load_script(name: str):
    """Import ``scripts/NAME.py`` (the scripts are not a package) as a module."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(ROOT, "scripts", f"{name}.py"))
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # as an import does: dataclasses and pickling look the module up there
    spec.loader.exec_module(mod)
    return mod


def pytest_unconfigure(config):
    """The suite's end: no "nanobind: leaked ..." report after pytest's summary.

    One test keeps OMPL objects past its end through no reference of ours: BITstar's
    ``getPlannerData`` (the bench's graph count, ``planners.core.routine.graph_states``) leaves a
    cycle of C++ shared pointers that holds the space information and our motion validator until
    exit, where nanobind lists them (measured: without that call, or with any other planner, none
    is left; ``tests/planning/test_no_leaks.py`` holds every other route to that). The CLI and the
    bench's workers end by ``os._exit`` and never print it; here, once pytest has written its
    summary, standard error is closed for what the interpreter's teardown would still print.
    """
    import atexit

    def quiet():
        sys.stderr.flush()
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 2)

    atexit.register(quiet)
