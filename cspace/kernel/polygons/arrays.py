"""The one input gate of the geometry: arrays of real numbers from what a caller passes.

Every public geometry function turns its polygons (and points, directions) into
``(N, 2)`` float64 arrays here, so one place decides what is refused: NaN and
infinities, wrong shapes and ragged rows (``ValueError``); booleans, complex
numbers, strings and other non-numbers (``TypeError``, since numpy would quietly
read ``True`` as 1 and drop an imaginary part); integers that a double cannot
hold exactly (beyond 2^53: rounding them would move the geometry silently). The
checks cost one pass over the array; a float64 array goes straight through.
"""
from __future__ import annotations

import numpy as np


def as_array(polygon, copy: bool = True, nonempty: bool = False) -> np.ndarray:
    """Vertices of ``polygon`` as a fresh ``(N, 2)`` float64 array, closing repeat dropped.

    The one gate every public geometry function passes its polygons through.
    Accepts an array-like of real numbers or a shapely ``Polygon`` / ``LinearRing`` /
    ``LineString`` / ``Point`` (a polygon's exterior is used). Refused, with one
    message: NaN and infinities (``ValueError``), a wrong shape or ragged rows
    (``ValueError``), booleans, complex numbers, strings and other non-numbers
    (``TypeError``), integers a double cannot hold exactly (beyond 2^53, ``ValueError``:
    rounding them would change the geometry silently), and with ``nonempty`` an
    empty array (``ValueError``). With ``copy=False`` a float64 array comes back as a
    view of itself (for callers that only read it).

    >>> as_array([[0, 0], [1, 0], [0, 1], [0, 0]]).tolist()
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    >>> as_array([[0, float("nan")], [1, 0]])
    Traceback (most recent call last):
    ...
    ValueError: coordinates must be finite, got NaN or an infinity
    """
    if hasattr(polygon, "geom_type"):
        geom = polygon
        if geom.geom_type == "Polygon":
            geom = geom.exterior
        elif geom.geom_type not in ("LinearRing", "LineString", "Point"):  # not one sequence of points
            raise ValueError(f"expected one polygon, got a {geom.geom_type} (pass its parts, .geoms, one by one)")
        pts = np.array(geom.coords, dtype=np.float64).reshape(-1, 2 if geom.is_empty else len(geom.coords[0]))[:, :2]
    elif type(polygon) is np.ndarray and polygon.dtype == np.float64:
        pts = polygon.copy() if copy else polygon
    else:
        pts = _real_array(polygon)
    if pts.ndim == 1 and pts.size == 2:
        pts = pts.reshape(1, 2)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"expected an (N, 2) array of points, got shape {pts.shape}")
    if not np.isfinite(pts).all():
        raise ValueError("coordinates must be finite, got NaN or an infinity")
    if nonempty and not len(pts):
        raise ValueError("an operand has no vertices (an empty array)")
    if len(pts) > 1 and pts[0, 0] == pts[-1, 0] and pts[0, 1] == pts[-1, 1]:
        pts = pts[:-1]
    return pts


def as_point(p) -> tuple[float, float]:
    """A point or direction ``(x, y)`` as two finite floats, through :func:`as_array`'s gate.

    >>> as_point([1, 2]), as_point(np.array([[3.5, 4]]))
    ((1.0, 2.0), (3.5, 4.0))
    """
    q = as_array(p, copy=False)
    if q.shape != (1, 2):
        raise ValueError(f"expected a point (x, y), got {q.size} numbers")
    return float(q[0, 0]), float(q[0, 1])


def _real_array(values) -> np.ndarray:
    """A new float64 array of real numbers, or TypeError / ValueError (see :func:`as_array`)."""
    if isinstance(values, (list, tuple)):  # numpy would turn True into 1 among numbers: look first
        for row in values:
            for v in (row if isinstance(row, (list, tuple)) else (row,)):
                if isinstance(v, (bool, np.bool_, complex, str, bytes)):
                    raise TypeError(f"coordinates must be real numbers, got {type(v).__name__}")
    try:
        raw = np.asarray(values)
    except ValueError:  # ragged rows
        raise ValueError("expected an (N, 2) array of points, got rows of different lengths") from None
    kind = raw.dtype.kind
    if kind in "fiu":
        if kind != "f" and raw.size and int(np.abs(raw).max()) > 2**53:
            _check_exact(raw.ravel().tolist())
        return raw.astype(np.float64)
    if kind == "O":
        flat = raw.ravel().tolist()
        for v in flat:
            if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
                raise TypeError(f"coordinates must be real numbers, got {type(v).__name__}")
        _check_exact(flat)
        try:
            return raw.astype(np.float64)
        except OverflowError:
            raise ValueError("an integer coordinate is beyond the double range") from None
    names = {"b": "booleans", "c": "complex numbers", "U": "strings", "S": "bytes", "M": "dates", "m": "time spans"}
    raise TypeError(f"coordinates must be real numbers, got {names.get(kind, raw.dtype.name)}")


def _check_exact(values: list) -> None:
    """ValueError for an integer that a double does not hold exactly (|v| > 2^53, odd bits)."""
    for v in values:
        if isinstance(v, (int, np.integer)) and abs(int(v)) > 2**53:
            try:
                exact = float(v) == int(v)
            except OverflowError:
                exact = False
            if not exact:
                raise ValueError(f"integer coordinate {_digits(int(v))} is not exactly a double (beyond 2^53): "
                                 f"give it as a float to accept the rounding")


def _digits(v: int) -> str:
    return str(v) if v.bit_length() < 200 else f"of {int(v.bit_length() * 0.30103) + 1} digits"
