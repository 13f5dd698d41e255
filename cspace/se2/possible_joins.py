"""Which POSSIBLE components of a partition are joined, built once per map: a proof query in a lookup.

The proof-only search of :mod:`cspace.se2.exact` decides, at each partition it tries, whether
the POSSIBLE graph joins start and goal: a walk from the start node through components of
neighbouring slabs (linked where their closures meet) to the goal node. Everything in that
graph except the start and goal nodes depends on the map alone. So for a C-space that serves
many queries the connected components of the graph *without* start and goal are labelled
once (union-find over the links); a query then asks only which components its start and goal
join (:meth:`SlabRegions.near`'s rule, with the components' boxes as a numpy broad phase) and
whether a start node and a goal node carry the same label. That is exactly the search's
``reach`` from the start node: the start node's neighbours are the components it joins, and
what is reachable from them is the union of their labels' components.

Only the answer "joined" is taken from here (no proof at that partition: the search would
refine or give up there too); where a partition separates them the search itself runs and
writes the proof, as before, so the proof and every guarantee stay the search's.
"""
from __future__ import annotations

import numpy as np

from .exact_path import holding
from ..kernel.polygons.rotation import wrap_angle


def proof_partitions(initial: list, min_width: float) -> list[list]:
    """The partitions a proof-only search tries, from ``initial`` (its first slabs) to the last:
    each bisects every slab whose halves stay at least ``min_width`` wide (the search's refinement
    without FREE), until none does.

    >>> ps = proof_partitions([(0.0, 1.0), (1.0, 2.0)], 0.5)
    >>> [len(p) for p in ps], ps[-1][:2]
    ([2, 4], [(0.0, 0.5), (0.5, 1.0)])
    """
    parts = [list(initial)]
    while True:
        split = [k for k, (a, b) in enumerate(parts[-1]) if 0.5 * (b - a) >= min_width]
        if not split:
            return parts
        new = []
        for k, (a, b) in enumerate(parts[-1]):
            new += [(a, 0.5 * (a + b)), (0.5 * (a + b), b)] if k in set(split) else [(a, b)]
        parts.append(new)


class PossibleJoins:
    """The POSSIBLE graph of one partition of a :class:`cspace.se2.slab_graph.SlabRegions`,
    its components labelled (map only); :meth:`joined` answers a query by lookups.
    ``angle_near``: the slack with which start and goal join the slabs near their angle
    (the search's ``ANGLE_NEAR``).

    >>> from cspace.se2.slab_graph import SlabRegions
    >>> wall = np.array([[4., 0], [5, 0], [5, 10], [4, 10]])
    >>> sr = SlabRegions([wall], [np.array([[-0.5, -0.1], [0.5, -0.1], [0.5, 0.1], [-0.5, 0.1]])], (0, 10, 0, 10))
    >>> pj = PossibleJoins(sr, [(-np.pi + k * np.pi / 4, -np.pi + (k + 1) * np.pi / 4) for k in range(8)], 1e-8)
    >>> pj.joined((1, 1, 0.0), (3, 9, 2.0)), pj.joined((1, 1, 0.0), (8, 5, 0.0))
    (True, False)
    """

    def __init__(self, regions, part: list, angle_near: float):
        self.regions, self.part, self.angle_near = regions, [tuple(map(float, s)) for s in part], float(angle_near)
        self.preg = [regions.possible(a, b) for a, b in self.part]
        offset = np.cumsum([0] + [len(r.components) for r in self.preg])
        parent = list(range(int(offset[-1])))

        def root(i: int) -> int:
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        K = len(self.part)
        for k in range(K):
            k2 = (k + 1) % K
            for i, j in regions.possible_links(self.preg[k], self.preg[k2]):
                ri, rj = root(int(offset[k]) + i), root(int(offset[k2]) + j)
                if ri != rj:
                    parent[max(ri, rj)] = min(ri, rj)
        self.labels = [[root(int(offset[k]) + c) for c in range(len(self.preg[k].components))] for k in range(K)]
        self.builds = 1  # for the tests: one labelling per object

    def ends(self, pose) -> set:
        """The labels of the POSSIBLE components a start or goal pose joins."""
        x, y, th = float(pose[0]), float(pose[1]), wrap_angle(float(pose[2]))
        out = set()
        for k in holding(self.part, th, self.angle_near):
            out.update(self.labels[k][c] for c in near(self.regions, self.preg[k], x, y))
        return out

    def joined(self, start, goal) -> bool:
        """Does the POSSIBLE graph of this partition join ``start`` and ``goal`` (x, y, θ)?"""
        return bool(self.ends(start) & self.ends(goal))


def near(regions, region, x: float, y: float) -> list[int]:
    """:meth:`SlabRegions.near` (components whose closure is within ``regions.tol`` of (x, y)), the
    boxes filtered by numpy first: the same list, without a Python loop over every component.

    >>> from cspace.se2.slab_graph import SlabRegions
    >>> sr = SlabRegions([np.array([[4., 0], [5, 0], [5, 10], [4, 10]])], [np.array([[0., 0], [1, 0], [0, 1]])],
    ...                  (0, 10, 0, 10))
    >>> reg = sr.possible(0.0, 0.1)
    >>> near(sr, reg, 1.0, 1.0) == sr.near(reg, 1.0, 1.0), near(sr, reg, 4.5, 1.0)
    (True, [])
    """
    import shapely

    b, g = region.boxes, regions.tol
    if not len(b):
        return []
    cand = np.flatnonzero((b[:, 0] - g <= x) & (x <= b[:, 2] + g) & (b[:, 1] - g <= y) & (y <= b[:, 3] + g))
    pt = shapely.Point(x, y)
    return [i for i in cand.tolist() if shapely.intersects_xy(region.components[i], x, y)
            or shapely.distance(region.components[i], pt) <= g]

