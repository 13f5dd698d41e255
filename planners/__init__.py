"""planners: OMPL glue, the command line, plots and reports on top of :mod:`cspace`.

The packages, each importing only those below it (docs/architecture.md, "Layers"):
:mod:`~planners.cli` (the ``cspace`` command) > :mod:`~planners.bench`, :mod:`~planners.stability`
> :mod:`~planners.pictures` > :mod:`~planners.core` (``plan``, the planning routine, ``exact``)
> :mod:`~planners.adapters` (OMPL and the state spaces) > the shared helpers
(:mod:`~planners.errors`, :mod:`~planners.output`, :mod:`~planners.progress`,
:mod:`~planners.children`) > :mod:`cspace`.

Importing this package does not import OMPL or matplotlib; they load when a plan or a
plot is asked for. Its names load on first use (PEP 562), so the command line's start
(``cspace --help``) does not pay for the geometry.

>>> import planners
>>> planners.plan.__module__
'planners.core.plan'
"""
from __future__ import annotations

import importlib

_NAMES = {"plan": ".core.plan", "PlanResult": ".core.result", "path_length": ".adapters.frame",
          "shortest_path": ".core.plan", "write_view": ".pictures.view"}

__all__ = ["plan", "shortest_path", "PlanResult", "path_length", "write_view"]


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module(_NAMES[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
