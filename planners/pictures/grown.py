"""The robot grown by its safety margin, for drawing: R ⊕ M at a pose, whatever R's shape.

The Minkowski sum of the convex kernel only takes convex operands, and a robot part may
not be convex (a U, a T). The sum distributes over a union, R ⊕ M = ∪ (Rᵢ ⊕ M) for the
convex pieces Rᵢ of R (:func:`cspace.translation.build.decompose_robot`), so each piece
is summed with the margin (:func:`cspace.kernel.minkowski.margin.inflated_pieces`, as the C-space
build does) and the outline drawn is their union's (shapely), not every piece's.
"""
from __future__ import annotations

import numpy as np


def grown_robot(scenario, x: float, y: float, theta: float = 0.0) -> list[tuple[np.ndarray, list[np.ndarray]]]:
    """The robot at (x, y, theta) grown by the scenario's margin: (shell, holes) rings of the union.

    Empty without a margin. ``theta`` turns the body frame (SE(2)) and the margin with it.

    >>> from types import SimpleNamespace
    >>> u = np.array([[-1., -1], [1, -1], [1, 1], [0.6, 1], [0.6, -0.6], [-0.6, -0.6], [-0.6, 1], [-1, 1]])
    >>> sq = np.array([[-.1, -.1], [.1, -.1], [.1, .1], [-.1, .1]])
    >>> sc = SimpleNamespace(robot=[SimpleNamespace(polygon=u)], robot_kind="polygon", margins=lambda: [sq])
    >>> [(len(s), len(h)) for s, h in grown_robot(sc, 0.0, 0.0)]  # one U, 0.1 thicker all round
    [(8, 0)]
    """
    margins = scenario.margins()
    if not margins:
        return []
    import shapely

    from cspace.kernel.minkowski.margin import inflated_pieces
    from cspace.kernel.polygons.rotation import rotate
    from cspace.translation.build import decompose_robot

    body, _ = decompose_robot([s.polygon for s in scenario.robot], getattr(scenario, "robot_kind", "") == "disk")
    if theta:
        body = [rotate(p, theta) for p in body]
        margins = [rotate(m, theta) for m in margins]
    grown = shapely.union_all([shapely.Polygon(p + (x, y)) for p in inflated_pieces(body, margins)])
    grown = shapely.simplify(grown, 0.0)  # the seams' collinear vertices dropped
    out = []
    for poly in shapely.get_parts(grown):
        if poly.geom_type == "Polygon" and not poly.is_empty:
            out.append((np.asarray(poly.exterior.coords)[:-1],
                        [np.asarray(r.coords)[:-1] for r in poly.interiors]))
    return out
