"""The narrowest free gap a path passes through: where a picture should zoom in.

At a point p of a path, the *gap* is the width of free C-space across the path: cast
the line through p perpendicular to the path's segment, keep the piece of that line
inside the free C-space F (bounds minus the C-obstacles) that contains p, and take
its length: the distance between the nearest crossings of F's boundary on either
side of p (every edge of F against every sample line, vectorised). In open space the piece runs from wall to wall (or to the bounds); in a
passage it spans the passage, whatever side of it the path hugs (the exact planner's
optimum touches the walls). The narrowest gap along the path is the minimum over
points sampled inside every segment (not at the bends, where the perpendicular is
ambiguous); along a passage of constant width, the middle of the narrowest run. Looking
only for gaps below a width, a side with no wall within it is open space, not a gap. The
gap found is then measured wall to wall (:func:`wall_to_wall`): a path crossing a passage
at a slant cuts it longer than it is wide. This is a measure for display, not a
certificate: the sampling can step over a pinch shorter than the spacing of the samples.
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


def narrowest_gap(pieces: list, bounds, path, samples: int = 400, free=None,
                  below: float | None = None) -> Gap | None:
    """The narrowest gap across ``path`` ((N, 2) points, or poses whose first two are x, y).

    ``samples`` points are spread over the segments by length (at least one inside
    each segment); ``free`` may pass a prebuilt free space
    (:func:`cspace.paths.shortest.free_space`). With ``below``, only gaps narrower than it
    are looked for (None if there is none), and only F's edges within that distance
    of the path are examined, which is much faster in a large scene. None for a path
    without a segment.

    >>> walls = [np.array([[4., 0], [6, 0], [6, 4.9], [4, 4.9]]),
    ...          np.array([[4., 5.1], [6, 5.1], [6, 10], [4, 10]])]
    >>> g = narrowest_gap(walls, (0, 10, 0, 10), np.array([[1., 5], [9, 5]]))
    >>> round(g.width, 12), [round(c, 1) for c in g.center]  # the middle of the passage
    (0.2, [5.0, 5.0])
    """
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
    F = free_space(pieces, bounds) if free is None else free
    a, b = _ring_segments(F)
    if below is not None:
        # Both ends of a gap narrower than `below` lie within `below` of the path.
        import shapely

        near = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1))).query(
            shapely.LineString(path).buffer(below), predicate="intersects")
        a, b = a[near], b[near]
    t_minus, t_plus = _nearest_crossings(F, a, b, p, normal, reach=below)
    width = t_plus - t_minus
    real = np.isfinite(width)
    if below is not None:
        # A side cut at the reach found no wall within it: open space on that side, not a gap
        # (its "width" would be the reach, not a passage's).
        with np.errstate(invalid="ignore"):
            real &= (t_plus < below) & (t_minus > -below) & (width < below)
    idx = np.flatnonzero(real)
    if len(idx) == 0:
        return None
    width = width[idx]
    # A passage gives a run of equal widths: take the middle of the narrowest ones.
    ties = idx[width <= width.min() * (1 + 1e-6)]
    i = int(ties[len(ties) // 2])
    lo, hi = p[i] + t_minus[i] * normal[i], p[i] + t_plus[i] * normal[i]
    return wall_to_wall(F, Gap(float(t_plus[i] - t_minus[i]), (float(p[i, 0]), float(p[i, 1])),
                               ((float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1])))))


def wall_to_wall(F, gap: Gap) -> Gap:
    """The gap measured between its two walls rather than across the path: a path crossing a
    passage at a slant cuts it longer than it is wide.

    Near the gap (within its width of its centre), the complement of the free space ``F``
    falls into parts; when the gap's two ends lie on different parts, the gap becomes the
    shortest segment between those two walls (shapely), never longer than before. Otherwise
    (one wall on both sides, close to a corner) the gap is kept as it is.

    >>> import shapely
    >>> F = shapely.box(0, 0, 10, 10).difference(shapely.box(4, 0, 6, 4.9)).difference(shapely.box(4, 5.1, 6, 10))
    >>> g = wall_to_wall(F, Gap(0.2 * 2 ** 0.5, (5.0, 5.0), ((4.9, 4.9), (5.1, 5.1))))  # crossed at 45 degrees
    >>> round(g.width, 12), [round(e[1], 12) for e in g.ends]  # straight across
    (0.2, [4.9, 5.1])
    """
    import shapely

    (ax, ay), (bx, by) = gap.ends
    cx, cy = gap.center
    window = shapely.Point(cx, cy).buffer(max(gap.width, 1e-300), quad_segs=16)
    walls = [w for w in shapely.get_parts(window.difference(F)) if not w.is_empty]
    if len(walls) < 2:
        return gap
    ends = shapely.points([(ax, ay), (bx, by)])
    near = [int(np.argmin([shapely.distance(w, e) for w in walls])) for e in ends]
    if near[0] == near[1]:
        return gap
    lo, hi = walls[near[0]], walls[near[1]]
    line = shapely.shortest_line(lo, hi)
    width = float(line.length)
    # Between parallel walls every perpendicular is shortest: keep the one at the path's point.
    q = shapely.shortest_line(shapely.Point(gap.point), lo).coords[1]
    here = shapely.shortest_line(shapely.Point(q), hi)
    if here.length <= width * (1.0 + 1e-9):
        line = here
    if not width < gap.width:
        return gap
    (lx, ly), (hx, hy) = np.asarray(line.coords)[:2]
    return Gap(width, gap.point, ((float(lx), float(ly)), (float(hx), float(hy))))


def _ring_segments(F) -> tuple[np.ndarray, np.ndarray]:
    """Every edge of every ring of F, as start and end arrays (M, 2)."""
    import shapely

    starts, ends = [], []
    for poly in shapely.get_parts(F):
        if poly.geom_type != "Polygon" or poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            starts.append(c[:-1])
            ends.append(c[1:])
    if not starts:
        return np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(starts), np.concatenate(ends)


def _nearest_crossings(F, a: np.ndarray, b: np.ndarray, p: np.ndarray, n: np.ndarray,
                       reach: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """For each line p_i + t n_i: the parameters of F's nearest boundary crossings on either
    side of p_i, so that [t_minus, t_plus] is the line's piece of free space through p_i.

    An edge (a, b) meets the line where the signed distances of a and b to it change
    sign; the crossing is interpolated between them and projected on n. All pairs of
    lines and edges (a, b) of F, in blocks of about 2^21 pairs. A point on the boundary
    (a path touching a wall) keeps the side whose piece is free; a point outside F
    gets nan. With ``reach``, crossings farther than it count as at ``reach``.
    """
    import shapely

    m = len(p)
    t_minus, t_plus = np.full(m, -np.inf), np.full(m, np.inf)
    t_zero = np.full(m, np.nan)  # a crossing within tol of p (p on the boundary), if any
    if len(a) == 0:
        return np.full(m, np.nan), np.full(m, np.nan)
    tol = 1e-9 * (1.0 + float(np.abs(p).max()))
    block = max(1, 2 ** 21 // len(a))
    for lo in range(0, m, block):
        pp, nn = p[lo:lo + block, None, :], n[lo:lo + block, None, :]
        # Signed distance of each edge end to each line (n is a unit normal of the path,
        # so the line's direction is n and the distance is the cross product with it).
        sa = nn[..., 0] * (a[None, :, 1] - pp[..., 1]) - nn[..., 1] * (a[None, :, 0] - pp[..., 0])
        sb = nn[..., 0] * (b[None, :, 1] - pp[..., 1]) - nn[..., 1] * (b[None, :, 0] - pp[..., 0])
        cross = ((sa <= 0) & (sb >= 0) | (sa >= 0) & (sb <= 0)) & (sa != sb)
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.where(cross, sa / (sa - sb), np.nan)
        x = a[None, :, 0] + u * (b - a)[None, :, 0]
        y = a[None, :, 1] + u * (b - a)[None, :, 1]
        t = (x - pp[..., 0]) * nn[..., 0] + (y - pp[..., 1]) * nn[..., 1]  # nan where no crossing
        with np.errstate(invalid="ignore"):
            t_plus[lo:lo + block] = np.min(np.where(t > tol, t, np.inf), axis=1)
            t_minus[lo:lo + block] = np.max(np.where(t < -tol, t, -np.inf), axis=1)
            dist = np.where(np.abs(t) <= tol, np.abs(t), np.inf)
            j = np.argmin(dist, axis=1)
            rows = np.arange(len(j))
            t_zero[lo:lo + block] = np.where(np.isfinite(dist[rows, j]), t[rows, j], np.nan)
    on = ~np.isnan(t_zero)
    if reach is not None:
        t_plus, t_minus = np.minimum(t_plus, reach), np.maximum(t_minus, -reach)
    shapely.prepare(F)
    inside = shapely.contains_xy(F, p[:, 0], p[:, 1])
    t_minus[~on & ~inside] = np.nan
    t_plus[~on & ~inside] = np.nan
    # On the boundary: of the two pieces beside p, the free one (the wider if both are).
    if on.any():
        k = np.flatnonzero(on)
        # No crossing on a side (inf): F does not extend that way (it is bounded).
        fin_up, fin_down = np.isfinite(t_plus[k]), np.isfinite(t_minus[k])
        half_up = np.where(fin_up, 0.5 * t_plus[k], 0.0)
        half_down = np.where(fin_down, 0.5 * t_minus[k], 0.0)
        up = fin_up & shapely.contains_xy(F, *(p[k] + half_up[:, None] * n[k]).T)
        down = fin_down & shapely.contains_xy(F, *(p[k] + half_down[:, None] * n[k]).T)
        use_up = up & (~down | (t_plus[k] >= -t_minus[k]))
        use_down = down & ~use_up
        t_plus[k[use_down]] = t_zero[k[use_down]]  # the wall p (nearly) stands on
        t_minus[k[use_up]] = t_zero[k[use_up]]
        t_minus[k[~up & ~down]] = np.nan
        t_plus[k[~up & ~down]] = np.nan
    return t_minus, t_plus


GAP_FRACTION = 0.01  # a gap is shown when narrower than this share of the scene's larger side


def narrowest_gap_of_paths(pieces: list, bounds, paths: list, fraction: float = GAP_FRACTION) -> Gap | None:
    """The narrowest gap across any of ``paths`` narrower than ``fraction`` of the scene's larger
    side, else None (what the pictures zoom on and the offline page marks). 400 samples in all.

    >>> walls = [np.array([[4., 0], [6, 0], [6, 4.99], [4, 4.99]]),
    ...          np.array([[4., 5.01], [6, 5.01], [6, 10], [4, 10]])]
    >>> round(narrowest_gap_of_paths(walls, (0, 10, 0, 10), [np.array([[1., 5], [9, 5]])]).width, 12)
    0.02
    >>> narrowest_gap_of_paths(walls, (0, 10, 0, 10), [np.array([[1., 5], [9, 5]])], fraction=0.001) is None
    True
    """
    from .shortest import free_space

    paths = [p for p in paths if len(p) > 1]
    if not paths:
        return None
    xmin, xmax, ymin, ymax = bounds
    below = fraction * max(xmax - xmin, ymax - ymin)
    free = free_space(pieces, bounds)
    samples = max(16, 400 // len(paths))  # 400 in all: many queries are each sampled less
    gaps = [narrowest_gap(pieces, bounds, p, samples=samples, free=free, below=below) for p in paths]
    return min((g for g in gaps if g is not None), key=lambda g: g.width, default=None)
