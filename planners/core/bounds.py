"""What the inscribed disk proves about a rotating robot (note on SE(2), section 5).

The largest disk about the reference point inside the robot is inside it at every
angle. So the exact shortest path of the reference point among obstacles ⊕ that disk
(here a regular polygon inside the disk, which only weakens the bound) is a lower
bound on the (x, y) length of every collision-free SE(2) path, and a start and goal it
cannot connect are proven disconnected for the rotating robot too.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np


@dataclass
class DiskBound:
    """The inscribed-disk verdict for one query."""

    radius: float            # radius of the disk about the reference point inside the robot
    proven_unsolvable: bool  # start and goal disconnected for the disk: no SE(2) path exists
    lower_bound: float       # lower bound on the x, y length of any free path (inf if unsolvable, nan if unknown)
    seconds: float
    message: str


def disk_bound(sc, query, time_limit: float = 10.0, sides: int = 32) -> DiskBound:
    """The inscribed-disk lower bound and unsolvability proof for ``query`` of an SE(2) scenario."""
    from cspace.translation.cspace import CSpace
    from cspace.paths.shortest import shortest_path
    from cspace.kernel.slabs.slab import inscribed_polygon, inscribed_radius

    t0 = time.perf_counter()
    rho = inscribed_radius([s.polygon for s in sc.robot]) if sc.robot else 0.0
    robot = [inscribed_polygon(rho, sides)] if rho > 0.0 else []
    cs = CSpace(sc.bounds, [o.polygon for o in sc.obstacles], robot,
                obstacle_holes=[o.holes for o in sc.obstacles], robot_is_disk=bool(robot))
    start, goal = tuple(query.start[:2]), tuple(query.goal[:2])
    if not (cs.is_free(start) and cs.is_free(goal)):  # cannot happen for a valid query: the disk is inside the robot
        return DiskBound(rho, False, math.nan, time.perf_counter() - t0, "inscribed disk not free at start or goal")
    sp = shortest_path(cs.pieces, cs.bounds, start, goal, time_limit=time_limit)
    dt = time.perf_counter() - t0
    if sp.proven_unsolvable:
        return DiskBound(rho, True, math.inf, dt,
                         f"proven unsolvable: the disk of radius {rho:.4g} inside the robot at every angle cannot "
                         "connect start and goal (different free components)")
    if sp.solved:
        return DiskBound(rho, False, float(sp.length), dt, f"lower bound {float(sp.length):.6g} (inscribed disk r = {rho:.4g})")
    return DiskBound(rho, False, math.nan, dt, "inscribed-disk search did not finish")
