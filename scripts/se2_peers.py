"""The peers of the SE(2) benches: OMPL's RRTConnect with a shapely or a coal state checker and
OMPL's default discrete motion check, against cspace's certified planning, one seed at a time.

Not used by the product. ``shapely_checker(sc)`` turns and moves the robot's polygon with
shapely and asks an STRtree of the obstacles; ``coal_checker(obstacle_pieces, robot_pieces,
bounds)`` puts convex pieces as prisms in coal's dynamic AABB tree (coal is 3-D) and turns the
robot's prisms by a rotation about z. ``peer_first(adapter, checker, start, goal, seed, limit)``
plans with OMPL on the adapter's own state space (the same bounds and weights as ours), the
checker and OMPL's default motion validator; ``ours_first(sc, cs, adapter, query, seed, limit)``
is cspace's time to its first certified path: the proof before sampling (planners.core.exact_se2)
and the one planning routine stopped at its first solution, unsimplified, as the peer is (with
``planner="auto"``: auto's stages, unsimplified; its peer is then RRTConnect).
Both return ``(path or None, CPU seconds)``.
"""
from __future__ import annotations

import math
import time

import numpy as np


def shapely_checker(sc):
    """``state -> bool``: the robot turned and moved by shapely, an STRtree and prepared intersects."""
    import shapely
    from shapely import affinity

    obstacles = np.array([o.to_shapely() for o in sc.obstacles], dtype=object)
    shapely.prepare(obstacles)
    tree = shapely.STRtree(obstacles)
    body = shapely.union_all([shapely.Polygon(r.polygon) for r in sc.robot])
    xmin, xmax, ymin, ymax = sc.bounds
    rot, tr, intersects, query = affinity.rotate, affinity.translate, shapely.intersects, tree.query

    def is_valid(s) -> bool:
        x, y = s.getX(), s.getY()
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        moved = tr(rot(body, s.getYaw(), origin=(0, 0), use_radians=True), x, y)
        cand = query(moved)
        return not (len(cand) and intersects(obstacles[cand], moved).any())

    return is_valid


def prism(poly: np.ndarray):
    """A convex polygon as a coal.Convex prism (z in [-1, 1])."""
    import coal

    n = len(poly)
    pts = coal.StdVec_Vec3s()
    for z in (-1.0, 1.0):
        for x, y in np.asarray(poly, dtype=float).tolist():
            pts.append(np.array([x, y, z]))
    tris = coal.StdVec_Triangle()
    for i in range(1, n - 1):
        tris.append(coal.Triangle(0, i + 1, i))
        tris.append(coal.Triangle(n, n + i, n + i + 1))
    for i in range(n):
        j = (i + 1) % n
        tris.append(coal.Triangle(i, j, n + j))
        tris.append(coal.Triangle(i, n + j, n + i))
    return coal.Convex(pts, tris)


def coal_checker(obstacle_pieces, robot_pieces, bounds):
    """``state -> bool``: obstacle pieces as prisms in coal's AABB tree, the robot's turned and moved."""
    import coal

    manager = coal.DynamicAABBTreeCollisionManager()
    keep = []
    for p in obstacle_pieces:
        obj = coal.CollisionObject(prism(p), coal.Transform3s())
        keep.append(obj)
        manager.registerObject(obj)
    manager.setup()
    robot = [coal.CollisionObject(prism(p), coal.Transform3s()) for p in robot_pieces]
    callback = coal.CollisionCallBackDefault()
    data = callback.data
    xmin, xmax, ymin, ymax = bounds

    def is_valid(s) -> bool:
        x, y, t = s.getX(), s.getY(), s.getYaw()
        if not (xmin <= x <= xmax and ymin <= y <= ymax):
            return False
        c, sn = math.cos(t), math.sin(t)
        tf = coal.Transform3s(np.array([[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]]), np.array([x, y, 0.0]))
        for obj in robot:
            obj.setTransform(tf)
            obj.computeAABB()
            data.result.clear()
            data.done = False
            manager.collide(obj, callback)
            if data.result.isCollision():
                return False
        return True

    is_valid.keep = (manager, keep, robot, callback)
    return is_valid


def peer_first(adapter, checker, start, goal, seed: int, limit: float, planner: str = "RRTConnect",
               resolution: float | None = None):
    """OMPL's ``planner`` on the adapter's state space with ``checker`` and OMPL's default discrete
    motion check, seeded as ours, stopped at its first solution (an anytime planner by OMPL's own
    rule, as ours): ``(path or None, CPU seconds of the set-up and solve)``. ``resolution``: the
    motion check's step as a fraction of the space's extent (None: OMPL's default, 0.01)."""
    from planners.adapters.glue import ANYTIME, ompl, ompl_seed, stop_at_first

    ob, og, ou = ompl()
    c0 = time.process_time()
    ou.RNG.setSeed(ompl_seed(seed))
    space = adapter.state_space()
    ss = og.SimpleSetup(space)
    ss.setStateValidityChecker(checker)
    s, g = space.allocState(), space.allocState()
    adapter.set_state(s, start)
    adapter.set_state(g, goal)
    ss.setStartAndGoalStates(s, g, 1e-9)
    if resolution is not None:
        ss.getSpaceInformation().setStateValidityCheckingResolution(resolution)
    ss.setPlanner(getattr(og, planner)(ss.getSpaceInformation()))
    if planner.lower() in ANYTIME:
        stop_at_first(ss)
    ss.setup()
    ok = ss.solve(ob.timedPlannerTerminationCondition(limit))
    cpu = time.process_time() - c0
    if not (ok and ss.haveExactSolutionPath()):
        return None, cpu
    return adapter.path_array(ss.getSolutionPath()), cpu


def ours_first(sc, cs, adapter, query, seed: int, limit: float, planner: str = "RRTConnect"):
    """cspace's first certified path (the proof before sampling, then the routine stopped at its
    first solution, unsimplified): ``(path or None, CPU seconds)``."""
    from planners.core.exact_se2 import quick_proof
    from planners.core.routine import run_planner

    c0 = time.process_time()
    if planner == "auto":  # its stages, unshortened as the peer's path is; a path or a proof ends it
        from planners.core.auto import auto_plan

        pose = adapter.pose
        res = auto_plan(sc, cs, adapter, query, (pose(query.start), pose(query.goal)), limit, seed,
                        source=sc.name, simplify=False)
        return (res.path if res.solved else None), time.process_time() - c0
    if quick_proof(sc, cs, query, limit) is not None:
        return None, time.process_time() - c0
    pose = adapter.pose
    res = run_planner(adapter, planner, [(pose(query.start), pose(query.goal))], limit, seed, simplify=False,
                      until_first=True)[0]
    return (res.path if res.solved else None), time.process_time() - c0
