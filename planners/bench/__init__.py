"""``cspace bench``'s machinery: error against run time for OMPL planners, measured against
the exact shortest path (or, in SE(2), a lower bound on it).

- :mod:`~planners.bench.reference`: each scenario's reference length and the tasks;
- :mod:`~planners.bench.rows`: one run (:func:`run_one`, through :func:`planners.core.plan.plan`)
  and its row; the hard limit;
- :mod:`~planners.bench.pool`: forked children (one per run) and fresh processes where fork
  is missing;
- :mod:`~planners.bench.sweep`: the sweep over the tasks (local or on Dask) and its summary;
- :mod:`~planners.bench.cluster`: ``--scheduler``, batches of runs on a Dask cluster;
- :mod:`~planners.bench.outputs`: results.csv, results.json, OMPL's benchmark logs;
- :mod:`~planners.bench.clearance`: the ``--objective`` checks and the summary's clearance cell.
- :mod:`~planners.bench.campaign`: ``--db``/``--resume``, each run stored as it finishes, in
  :mod:`~planners.bench.arena_db`'s database (Planner Arena's schema);
  :mod:`~planners.bench.ompl_log`: ``--log``, OMPL's benchmark logs from that database.

The figure is :mod:`planners.pictures.bench_figure`; the command line :mod:`planners.cli.bench`.
The names below load on first use (PEP 562).
"""
from __future__ import annotations

import importlib

_NAMES = {
    "reference": "reference", "make_tasks": "reference",
    "run_one": "rows", "FIELDS": "rows", "TIMING_FIELDS": "rows", "STATUSES": "rows", "hard_limit": "rows",
    "sweep": "sweep", "summary": "sweep", "isolated_run": "sweep",
    "write_outputs": "outputs", "to_csv": "outputs", "ompl_logs": "outputs", "OUTPUTS": "outputs",
}
__all__ = sorted(_NAMES)


def __getattr__(name: str):
    if name in _NAMES:
        value = getattr(importlib.import_module(f".{_NAMES[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
