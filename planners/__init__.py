"""planners: OMPL glue, the command line, plots and reports on top of :mod:`cspace`.

Importing this package does not import OMPL or matplotlib; they load when a plan
or a plot is asked for.
"""
from .exact import shortest_path
from .plan import PlanResult, path_length, plan

__all__ = ["plan", "shortest_path", "PlanResult", "path_length"]
