"""Hostile input to the public geometry functions: an answer or one ValueError, never another
exception from inside (IndexError, shapely's NotImplementedError, a GEOSException), never a
warning or a GEOS message on the terminal."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely

import cspace as C
from cspace.kernel.polygons.polygon import is_simple

SQ = [[0, 0], [1, 0], [1, 1], [0, 1]]
INPUTS = {
    "nan": [[0, 0], [math.nan, 0], [1, 1]],
    "inf": [[0, 0], [math.inf, 0], [1, 1]],
    "bowtie": [[0, 0], [2, 2], [2, 0], [0, 2]],
    "closed": SQ + [[0, 0]],
    "segment": [[0, 0], [1, 1]],
    "point": [[1, 1]],
    "empty": np.zeros((0, 2)),
    "collinear": [[0, 0], [1, 0], [2, 0]],
    "multipolygon": shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(3, 3, 4, 4)]),
    "linestring": shapely.LineString([(0, 0), (1, 1)]),
    "shapely": shapely.Polygon([[0, 0], [1, 0], [1, 1]]),
    "three_columns": [[0, 0, 0], [1, 0, 0], [0, 1, 0]],
}
FUNCTIONS = {
    "convex_decompose": lambda p: C.convex_decompose(p),
    "minkowski_sum": lambda p: C.minkowski_sum(p, SQ),
    "erode": lambda p: C.erode(SQ, p),
    "convex_hull": lambda p: C.convex_hull(p),
    "gjk_distance": lambda p: C.gjk_distance(p, SQ),
    "epa_penetration": lambda p: C.epa_penetration(p, SQ),
    "minkowski_sum_nonconvex": lambda p: C.minkowski_sum_nonconvex(p, SQ),
    "minkowski_pieces": lambda p: C.minkowski_pieces(p, SQ),
    "is_simple": lambda p: is_simple(p),
    "CSpace obstacle": lambda p: C.CSpace((0, 10, 0, 10), [p]),
    "CSpace robot": lambda p: C.CSpace((0, 10, 0, 10), [np.array(SQ, float) + 5], [p]),
}
# The pieces-level helpers take arrays only (documented): a shapely object is a TypeError there.
ARRAY_ONLY = {
    "pairwise_sums": lambda p: C.pairwise_sums([p], [np.array(SQ, float)]),
    "convex_sums_with": lambda p: C.convex_sums_with([np.array(SQ, float)], p),
}


# Degenerate but meaningful operands: the kernel answers (a point or a segment is a convex set).
KERNEL = {"convex_decompose", "minkowski_sum", "erode", "convex_hull", "gjk_distance", "epa_penetration",
          "minkowski_sum_nonconvex", "minkowski_pieces"}
MEANINGFUL = {"closed", "segment", "point", "collinear", "shapely"}


def _call(f, p, capfd, allowed=(ValueError,)):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning from shapely/numpy fails the test
        try:
            f(p)
        except allowed as e:
            assert "Exception:" not in str(e) and "\n" not in str(e), str(e)  # no raw GEOS text
    assert capfd.readouterr() == ("", "")


@pytest.mark.parametrize("fn", sorted(FUNCTIONS))
@pytest.mark.parametrize("kind", sorted(INPUTS))
def test_answer_or_one_value_error(fn, kind, capfd):
    _call(FUNCTIONS[fn], INPUTS[kind], capfd, () if fn in KERNEL and kind in MEANINGFUL else (ValueError,))


@pytest.mark.parametrize("fn", sorted(ARRAY_ONLY))
@pytest.mark.parametrize("kind", sorted(INPUTS))
def test_array_only_helpers(fn, kind, capfd):
    p = INPUTS[kind]
    _call(ARRAY_ONLY[fn], p, capfd, (ValueError, TypeError) if hasattr(p, "geom_type") else (ValueError,))


def test_the_messages_say_what_is_wrong():
    with pytest.raises(ValueError, match=r"not a simple polygon \(Self-intersection\[1 1\]\)"):
        C.convex_decompose(INPUTS["bowtie"])
    with pytest.raises(ValueError, match="expected one polygon, got a MultiPolygon"):
        C.convex_hull(INPUTS["multipolygon"])
    with pytest.raises(ValueError, match="empty array|no vertices"):  # the one array gate (cspace/kernel/polygons/arrays.py)
        C.minkowski_sum(INPUTS["empty"], SQ)
    assert is_simple(INPUTS["nan"]) is False  # a predicate answers, it does not raise
