"""The numerical stability catalogue: stiff and extreme cases run through every layer against exact
references (:mod:`~planners.stability.catalogue`; references in :mod:`~planners.stability.exact`,
inputs in :mod:`~planners.stability.inputs`, per-layer checks in :mod:`~planners.stability.checks`).
The command is :mod:`planners.cli.stability`."""
