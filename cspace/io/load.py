"""Scenario files: :func:`load_scenario`, and the public names for scenarios.

A TOML file is read (:mod:`cspace.io.scenario.files`: only a regular file within the size limit, UTF-8),
parsed and validated (:mod:`cspace.io.scenario.validate`) into a :class:`Scenario` (the schema:
:mod:`cspace.io.scenario.schema`); a ROS map or an OMPL.app problem is imported (:mod:`cspace.io.importers.imported`).
Every fault in a file is reported as a :class:`ScenarioError` whose text is
``FILE: FIELD: what is wrong``, one line, so the command line can print it as it is. Loading
never modifies the file.

:class:`Scenario`, :class:`Shape`, :class:`Query`, :class:`ScenarioError` and
:func:`scenario_from_dict` are importable from here, as ``cspace`` lists them.
"""
from __future__ import annotations

import os

from .scenario.files import read_input, toml_reader, utf8_text
from .scenario.messages import ScenarioError
from .scenario.schema import Query, Scenario, Shape
from .scenario.validate import scenario_from_dict

__all__ = ["Query", "Scenario", "ScenarioError", "Shape", "load_scenario", "scenario_from_dict"]


def load_scenario(path, space: str | None = None, turning_radius: float | None = None, options=None) -> Scenario:
    """Read and validate a TOML scenario file; ``space`` (``"translation"``, ``"se2"``,
    ``"dubins"`` or ``"reeds-shepp"``) overrides the file's ``space`` (``--space`` on the
    command line), ``turning_radius`` its ``turning_radius`` (``--turning-radius``).

    A ROS map (``.yaml``), an OMPL.app problem (``.cfg``), an SVG drawing (``.svg``) or a MovingAI
    map (``.map``) is imported
    (:mod:`cspace.io.importers.imported`); ``options`` (an :class:`cspace.io.importers.imported.ImportOptions`)
    give what such a file does not say: the robot, a map's start and goal.

    >>> import tempfile, os
    >>> d = tempfile.mkdtemp(); f = os.path.join(d, "s.toml")
    >>> _ = open(f, "w").write('[bounds]\\nxmin=0\\nxmax=1\\nymin=0\\nymax=1\\n'
    ...                        '[start]\\nx=0.1\\ny=0.1\\n[goal]\\nx=0.9\\ny=0.9\\n')
    >>> load_scenario(f).goal
    (0.9, 0.9)
    """
    path = os.fspath(path)
    if path.lower().endswith((".yaml", ".yml", ".cfg", ".svg", ".map")):  # the suffixes of cspace.io.importers.imported
        from .importers.imported import load_imported

        return load_imported(path, space=space, options=options, turning_radius=turning_radius)
    return scenario_from_dict(read_toml(path), path, space=space, turning_radius=turning_radius)


def read_toml(path) -> dict:
    """A TOML file as a dict: a regular file within the size limit, UTF-8 (BOM allowed),
    valid TOML; any fault is one :class:`ScenarioError` line naming the file."""
    path = os.fspath(path)
    raw = read_input(path)
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in raw[:4096]:
        raise ScenarioError(path, "file", "UTF-16 or binary, not UTF-8 text (save the file as UTF-8)")
    text = utf8_text(raw, path)
    tomllib = toml_reader()
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(path, "toml", f"invalid TOML ({exc})") from None
    except ValueError as exc:  # an integer of more digits than Python converts
        raise ScenarioError(path, "toml", f"invalid TOML ({exc})") from None
    except RecursionError:
        raise ScenarioError(path, "toml", "invalid TOML (arrays or tables nested too deeply)") from None
    return data
