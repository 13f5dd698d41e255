"""The planning core: :func:`~planners.core.plan.plan` (scenario -> C-space -> adapter -> path),
the one planning routine behind ``cspace plan``, the API and every bench run
(:mod:`~planners.core.routine`), the ``exact`` planner (:mod:`~planners.core.exact`), the
inscribed-disk bounds for rotating robots (:mod:`~planners.core.bounds`) and the result record
(:mod:`~planners.core.result`)."""
