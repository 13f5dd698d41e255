"""planners: OMPL glue, the command line, plots and reports on top of :mod:`cspace`.

Importing this package does not import OMPL or matplotlib; they load when a plan
or a plot is asked for. Its names load on first use (PEP 562), so the command
line's start (``cspace --help``) does not pay for the geometry.
"""
from __future__ import annotations

import importlib
import sys
import types

_NAMES = {"PlanResult": ".plan", "path_length": ".plan", "shortest_path": ".exact"}

__all__ = ["plan", "shortest_path", "PlanResult", "path_length"]


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module(_NAMES[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """``planners.plan`` is the function, also once the submodule of the same name is
    imported (the import system then sets the package's attribute to the submodule;
    an eager ``from .plan import plan`` used to overwrite it back)."""

    @property
    def plan(self):
        return importlib.import_module(".plan", __name__).plan

    @plan.setter
    def plan(self, value) -> None:  # the submodule being bound: keep the function
        pass


sys.modules[__name__].__class__ = _Package
