"""The narrowest free gap a path passes through: where a picture should zoom in.

At a point p of a path, the *gap* is the width of free C-space across the path: cast
the line through p perpendicular to the path's segment, keep the piece of that line
inside the free C-space F (bounds minus the C-obstacles) that contains p, and take
its length. In open space the piece runs from wall to wall (or to the bounds); in a
passage it spans the passage, whatever side of it the path hugs (the exact planner's
optimum touches the walls). The narrowest gap along the path is the minimum over
points sampled inside every segment (not at the bends, where the perpendicular is
ambiguous); along a passage of constant width, the middle of the narrowest run. This
is a measure for display, not a certificate: the sampling can step over a pinch
shorter than the spacing of the samples.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Gap:
    """The narrowest gap found: its width, the point of the path, and the gap's two ends."""

    width: float
    point: tuple[float, float]
    ends: tuple[tuple[float, float], tuple[float, float]]

    @property
    def center(self) -> tuple[float, float]:
        """The middle of the gap (between its two walls)."""
        (ax, ay), (bx, by) = self.ends
        return (0.5 * (ax + bx), 0.5 * (ay + by))


def narrowest_gap(pieces: list, bounds, path, samples: int = 400, free=None) -> Gap | None:
    """The narrowest gap across ``path`` ((N, 2) points, or poses whose first two are x, y).

    ``samples`` points are spread over the segments by length (at least one inside
    each segment); ``free`` may pass a prebuilt free space
    (:func:`cspace.shortest.free_space`). None for a path without a segment.

    >>> walls = [np.array([[4., 0], [6, 0], [6, 4.9], [4, 4.9]]),
    ...          np.array([[4., 5.1], [6, 5.1], [6, 10], [4, 10]])]
    >>> g = narrowest_gap(walls, (0, 10, 0, 10), np.array([[1., 5], [9, 5]]))
    >>> round(g.width, 12), [round(c, 1) for c in g.center]  # the middle of the passage
    (0.2, [5.0, 5.0])
    """
    import shapely

    from .shortest import free_space

    path = np.asarray(path, dtype=np.float64)
    path = path.reshape(-1, path.shape[-1])[:, :2]  # (x, y) of each pose; theta, if any, ignored
    d = np.diff(path, axis=0)
    seg_len = np.hypot(d[:, 0], d[:, 1])
    keep = seg_len > 0
    if not keep.any():
        return None
    a, d, seg_len = path[:-1][keep], d[keep], seg_len[keep]
    # Samples per segment in proportion to its length, at the midpoints of equal parts.
    k = np.maximum(1, np.round(samples * seg_len / seg_len.sum()).astype(int))
    seg = np.repeat(np.arange(len(a)), k)
    frac = np.concatenate([(np.arange(m) + 0.5) / m for m in k])
    p = a[seg] + frac[:, None] * d[seg]
    normal = np.column_stack([-d[seg, 1], d[seg, 0]]) / seg_len[seg, None]
    xmin, xmax, ymin, ymax = map(float, bounds)
    reach = 2.0 * np.hypot(xmax - xmin, ymax - ymin) + float(np.abs(p).max())  # beyond the bounds
    lines = shapely.linestrings(np.stack([p - reach * normal, p + reach * normal], axis=1))
    F = free_space(pieces, bounds) if free is None else free
    shapely.prepare(F)
    cuts = shapely.intersection(lines, F)
    found = []
    for i, cut in enumerate(cuts):
        piece = _piece_through(cut, p[i])
        if piece is not None:
            (x0, y0), (x1, y1) = piece
            found.append((float(np.hypot(x1 - x0, y1 - y0)), i, piece))
    if not found:
        return None
    # A passage gives a run of equal widths: take the middle of the narrowest ones.
    w_min = min(f[0] for f in found)
    ties = [f for f in found if f[0] <= w_min * (1 + 1e-6)]
    w, i, piece = ties[len(ties) // 2]
    return Gap(w, (float(p[i, 0]), float(p[i, 1])), piece)


def _piece_through(cut, p: np.ndarray):
    """The segment of ``cut`` (a line's intersection with F) that contains p, as two points."""
    import shapely

    if cut.is_empty:
        return None
    tol = 1e-9 * (1.0 + float(np.abs(p).max()))
    found = None
    for part in shapely.get_parts(shapely.line_merge(cut) if cut.geom_type == "MultiLineString" else cut):
        if part.geom_type != "LineString":
            continue  # an isolated touching point: no width on that side
        c = np.asarray(part.coords)
        if shapely.distance(part, shapely.Point(p)) <= tol:
            ends = ((float(c[0, 0]), float(c[0, 1])), (float(c[-1, 0]), float(c[-1, 1])))
            length = part.length
            if found is None or length > found[1]:  # p at the joint of two pieces: the wider side
                found = (ends, length)
    return None if found is None else found[0]
