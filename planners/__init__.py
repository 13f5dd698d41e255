"""planners: OMPL glue, the command line, plots and reports on top of :mod:`cspace`."""
