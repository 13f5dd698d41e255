"""Triangle meshes of extruded 2-D scenes, projected to polygons.

OMPL.app's 2-D problems are 3-D meshes: a planar robot or environment extruded
along the up axis. Seen from above, every triangle covers part of the footprint:
the caps cover all of it, the walls project to segments. The footprint is the
union of the projected triangles (GEOS), walls and other zero-area triangles left
out (each triangle judged by its own size and position); then:

- holes thinner than ``sliver`` x (the scene's size) or of area below ``sliver``
  x size^2 are filled: slits between triangles that do not share their vertices
  exactly (T-junctions, float32 rounding in the mesh) are not free space;
- vertices within s = ``sliver`` x size of the line through their neighbours are
  removed (Douglas-Peucker, topology kept: the near-collinear vertices of float32
  meshes), and then the result is grown by s (mitred, limit 10): it contains the
  union of the triangles, and moves the boundary out by at most 11 s. Without such
  vertices only the exactly collinear ones go, and the union is kept as it is.

The size is the largest of the extent and the coordinates' magnitude (float32
rounding grows with both).

The up axis follows the COLLADA convention of the loader OMPL.app uses (Assimp): a
Z_UP file is turned to Y_UP by (x, y, z) -> (x, z, -y), an X_UP file by
(x, y, z) -> (-y, x, z); the plane is then the x, y of the result (OMPL.app moves a
2-D robot in x, y and turns it about z).
"""
from __future__ import annotations

import numpy as np

from ...kernel.minkowski.union import union as checked_union

SLIVER = 1e-6  # relative to the scene's size (squared for areas)
MITRE = 10.0


def to_plane(points: np.ndarray, up_axis: str) -> np.ndarray:
    """(N, 3) points to the (N, 2) plane coordinates for a COLLADA ``up_axis``.

    >>> to_plane(np.array([[1.0, 2.0, 3.0]]), "Z_UP").tolist(), to_plane(np.array([[1.0, 2.0, 3.0]]), "X_UP").tolist()
    ([[1.0, 3.0]], [[-2.0, 1.0]])
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if up_axis == "Z_UP":  # Assimp's Z_UP -> Y_UP turn: (x, y, z) -> (x, z, -y)
        return np.column_stack((p[:, 0], p[:, 2]))
    if up_axis == "X_UP":  # (x, y, z) -> (-y, x, z)
        return np.column_stack((-p[:, 1], p[:, 0]))
    return p[:, :2].copy()


def triangle_areas(tri: np.ndarray) -> np.ndarray:
    """Unsigned areas of (N, 3, 2) triangles.

    >>> triangle_areas(np.array([[[0, 0], [2, 0], [0, 1]]], dtype=float)).tolist()
    [1.0]
    """
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    return 0.5 * np.abs((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]))


def footprint(tri: np.ndarray, sliver: float = SLIVER):
    """The union of (N, 3, 2) triangles, cleaned (see the module notes), and a dict of
    what the cleaning did: ``triangles``, ``flat`` (zero-area, left out),
    ``holes_filled``, ``vertices_before``, ``vertices_after``, ``max_shift``.

    >>> sq = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]], [[0, 0], [1, 0], [1, 0]]], float)
    >>> g, info = footprint(sq); g.area, info["flat"], info["vertices_after"]
    (1.0, 1, 4)
    """
    import shapely

    tri = np.asarray(tri, dtype=np.float64).reshape(-1, 3, 2)
    info = {"triangles": len(tri), "flat": 0, "holes_filled": 0, "vertices_before": 0, "vertices_after": 0,
            "max_shift": 0.0}
    if len(tri) == 0:
        return shapely.Polygon(), info
    lo, hi = tri.reshape(-1, 2).min(axis=0), tri.reshape(-1, 2).max(axis=0)
    size = float(max(max(hi - lo), np.abs(tri).max())) or 1.0
    areas = triangle_areas(tri)
    # walls (and any zero-area triangle) cover no area; each judged by its own size, so that no
    # triangle elsewhere (however large or far) can make the others count as flat
    own = np.maximum(np.ptp(tri, axis=1).max(axis=1), np.abs(tri).max(axis=(1, 2)))
    keep = areas > (1e-12 * own) ** 2
    info["flat"] = int((~keep).sum())
    tri = tri[keep]
    if len(tri) == 0:
        return shapely.Polygon(), info
    polys = shapely.polygons(np.concatenate((tri, tri[:, :1]), axis=1))
    union = checked_union(polys)
    info["vertices_before"] = _vertices(union)
    s = sliver * size
    parts = []
    for p in _polygons(union):
        holes = [h for h in p.interiors if not _slit(shapely.Polygon(h), s, size)]
        info["holes_filled"] += len(p.interiors) - len(holes)
        parts.append(shapely.Polygon(p.exterior, holes))
    filled = checked_union(parts)
    exact = shapely.simplify(filled, 0.0)  # exactly collinear vertices only: the same set
    simple = shapely.simplify(filled, s, preserve_topology=True)
    if _vertices(simple) < _vertices(exact):  # near-collinear vertices: removed, and the loss covered
        cleaned = shapely.buffer(simple, s, join_style="mitre", mitre_limit=MITRE)
        info["max_shift"] = (1.0 + MITRE) * s
    else:
        cleaned = exact
    info["vertices_after"] = _vertices(cleaned)
    return cleaned, info


def _slit(hole, s: float, size: float) -> bool:
    """A hole too thin (2 area / perimeter below s) or too small to be free space."""
    return hole.area < 2.0 * s * size or 2.0 * hole.area < s * hole.length


def _polygons(geom) -> list:
    if geom.is_empty:
        return []
    parts = list(geom.geoms) if hasattr(geom, "geoms") else [geom]
    return [p for p in parts if p.geom_type == "Polygon" and not p.is_empty]


def _vertices(geom) -> int:
    return sum(len(p.exterior.coords) - 1 + sum(len(r.coords) - 1 for r in p.interiors) for p in _polygons(geom))


def polygons(geom) -> list:
    """The polygons of a footprint, largest first, as ``(shell, [holes])`` float64 arrays
    (without the closing repeat).

    >>> import shapely
    >>> [s.shape for s, _ in polygons(shapely.box(0, 0, 2, 1))]
    [(4, 2)]
    """
    out = []
    for p in sorted(_polygons(geom), key=lambda p: -p.area):
        shell = np.asarray(p.exterior.coords, dtype=np.float64)[:-1]
        holes = [np.asarray(h.coords, dtype=np.float64)[:-1] for h in p.interiors]
        out.append((shell, holes))
    return out
