"""The ``exact`` planner: the true shortest path over the C-space, as a PlanResult.

The geometry lives in :mod:`cspace.paths.shortest` (a reduced visibility graph over the
C-obstacle corners, searched lazily with A*). Here it is only wrapped so that it
answers like any other planner: ``cspace plan --planner exact`` or
``planners.shortest_path(scenario)``.

The optimum is an infimum: it may touch C-obstacle boundaries, which the planners'
closed-obstacle validity forbids. So its path is reported as the reference length,
``exact`` is true when it was computed exactly, and ``solved`` means a path exists;
``touches`` (filled by :func:`planners.core.plan.plan`) says the path touches an obstacle.
With a clearance D > 0 the C-obstacles are those of the robot inflated by the margin,
so the path is the shortest keeping the robot at least D from every obstacle.
"""
from __future__ import annotations

import math
import time

import numpy as np

from .result import PlanResult


def exact_plan(sc, cspace, query, time_limit: float | None = None, progress: bool | None = None) -> PlanResult:
    """Shortest path for one query on a built C-space (search bounded by ``time_limit``).

    A search that lasts longer than :data:`planners.progress.DELAY` shows a bar on a terminal
    (nodes settled, and a lower bound on the length that rises towards the answer);
    ``progress=False`` silences it, ``None`` draws it only when stderr is a terminal.
    """
    from cspace.paths.shortest import shortest_path as geometric_shortest

    from .. import progress as pg

    t = time.perf_counter()
    # The free space, its reflex vertices and its mesh come first (no steps, possibly seconds):
    # the bar names that stage, then the A* search's settled nodes once they come.
    with pg.progress(None, "exact search: building the free space", enabled=progress, unit="node",
                     delay=pg.DELAY, tick=pg.TICK) as bar:
        sp = geometric_shortest(cspace.pieces, cspace.bounds, query.start, query.goal, time_limit=time_limit,
                                on_progress=pg.search_reporter(bar, "exact search: A*") if bar.shown else None)
    dt = time.perf_counter() - t
    found_cpu = time.process_time() if sp.solved else None
    d = getattr(sc, "clearance", 0.0)
    if sp.solved and d > 0:
        message = (f"exact shortest path keeping clearance {d:g} (it touches the C-obstacles inflated by "
                   f"the margin where it bends)")
    elif sp.solved:
        message = ("exact shortest path: the limit of free paths, it touches C-obstacle boundaries where it "
                   "bends (set a clearance to drive it)")
    elif sp.proven_unsolvable and separated_as_written(sc, cspace, query):
        message = "proven unsolvable (start and goal are in different free components" + _kept(sc) + ")"
    elif sp.proven_unsolvable:  # only the disks' circumscribed polygons close the way: not a proof
        message = ("no path found: start and goal are in different free components of the C-space built of "
                   "the disks' circumscribed polygons, but not of their inscribed ones (raise the disks' "
                   "precision, disk_tolerance, or use a sampling planner)")
    else:
        message = f"no path found ({sp.stats.get('reason', 'search exhausted')})"
    return PlanResult(
        scenario=sc.name, solved=bool(sp.solved), exact=bool(sp.solved),
        path=np.asarray(sp.path, dtype=np.float64) if sp.solved else np.zeros((0, 2)),
        length=float(sp.length) if sp.solved else math.inf, planner="exact", seed=0,
        timings={"solve": dt}, checks=dict(sp.stats.get("counts", {})) if isinstance(sp.stats, dict) else {},
        stages=["visibility"], start=tuple(query.start), goal=tuple(query.goal), message=message,
        length_unsimplified=float(sp.length) if sp.solved else None, first_path_cpu=found_cpu,
    )


def separated_proof(sc, cspace, query, time_limit: float | None = None) -> PlanResult | None:
    """A translating robot's query proven unsolvable before sampling: start and goal in different
    components of the free C-space (:func:`cspace.paths.shortest.separated`, the exact
    planner's proof; F is kept for later searches on the same C-space), as a PlanResult; None
    when they share a component (the time limit is not used: building F is not interruptible,
    and it is the first stage of the exact planner's search).

    >>> from cspace import CSpace
    >>> from cspace.io.load import load_scenario
    >>> import os
    >>> sc = load_scenario(os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "narrow_closed.toml"))
    >>> separated_proof(sc, CSpace.from_scenario(sc), sc.all_queries()[0]).message.startswith("proven unsolvable")
    True
    """
    from cspace.paths.shortest import separated

    if not separated(cspace.pieces, cspace.bounds, query.start, query.goal):
        return None
    if not separated_as_written(sc, cspace, query):
        return None
    return PlanResult(scenario=sc.name, solved=False, exact=False, path=np.zeros((0, 2)), length=math.inf,
                      planner="", seed=0, start=tuple(query.start), goal=tuple(query.goal), timings={},
                      checks={}, stages=["free components"],
                      message="proven unsolvable before sampling: start and goal are in different free "
                              "components (no collision-free path exists" + _kept(sc) + ")")


def _kept(sc) -> str:
    """What "no path" is about: with a clearance or a margin, paths keeping it."""
    d = getattr(sc, "clearance", 0.0)
    if d > 0 or getattr(sc, "margin", None) is not None:
        return f" keeping clearance {d:g}" if getattr(sc, "margin", None) is None else " keeping the margin"
    return ""


def separated_as_written(sc, cspace, query) -> bool:
    """Given that start and goal are in different components of the C-space (built of each disk's
    circumscribed polygon), are they also in that of the shapes INSIDE the scene as written (each
    disk, robot's, obstacle's and the clearance's, by its inscribed polygon)? Only then is "no
    path exists" true for the disks themselves. Scenes of polygons only: True, nothing built.

    >>> import os
    >>> from cspace import CSpace
    >>> from cspace.io.load import load_scenario
    >>> sc = load_scenario(os.path.join(os.path.dirname(__file__), "..", "..", "scenarios", "narrow_closed.toml"))
    >>> separated_as_written(sc, CSpace.from_scenario(sc), sc.all_queries()[0])
    True
    """
    if not sc.has_disks and not getattr(sc, "clearance", 0.0) > 0:
        return True
    from cspace import CSpace
    from cspace.paths.shortest import separated

    obs = [(o.inner_polygon(), o.holes) for o in sc.obstacles]
    obs = [(p, h) for p, h in obs if len(p) >= 3]
    robot = [p for p in (r.inner_polygon() for r in sc.robot) if len(p) >= 3]
    inner = CSpace(cspace.bounds, [p for p, _ in obs], robot, obstacle_holes=[h for _, h in obs],
                   robot_is_disk=sc.robot_kind == "disk", normalized=True, margin=sc.margins(inner=True))
    return separated(inner.pieces, inner.bounds, query.start, query.goal)
