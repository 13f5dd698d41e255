"""Field checks of a scenario document: tables, keys, numbers, points, poses, point lists,
the ``[planner]`` table and the ``[[queries]]``.

Each failure is a :class:`cspace.io.scenario.messages.ScenarioError` naming the file and the field.
Shapes are checked on top of these (:mod:`cspace.io.scenario.shapes`).
"""
from __future__ import annotations

import math

import numpy as np

from ...kernel.polygons.rotation import wrap_angle
from .messages import ScenarioError, short, show, unknown_field_message
from .schema import MAX_MAGNITUDE, MAX_SEED, Query


def clearance_fault(value) -> str | None:
    """Why ``value`` cannot be a safety margin D, None when it can: a real number, finite,
    >= 0, within the supported magnitude 2^400. The one rule of ``--clearance`` (plan,
    show) and ``plan(clearance=...)``; the scenario's ``clearance`` field says the same.

    >>> clearance_fault(0.5), clearance_fault(-1.0)
    (None, 'must be a finite distance >= 0, got -1.0')
    >>> clearance_fault(1e300)
    '1e+300 is beyond the supported magnitude 2^400 (about 2.6e+120)'
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return f"must be a finite distance >= 0, got {value!r}"
    try:
        d = float(value)
    except OverflowError:
        return f"{show(value)} is too large for a double"
    if not (math.isfinite(d) and d >= 0):
        return f"must be a finite distance >= 0, got {value!r}"
    if d > MAX_MAGNITUDE:
        return f"{show(value)} is beyond the supported magnitude 2^400 (about {MAX_MAGNITUDE:.2g})"
    return None


class FieldChecks:
    """Field-by-field checks; each failure names the file and the field."""

    def __init__(self, path: str):
        self.path = path

    def err(self, field: str, message: str) -> ScenarioError:
        return ScenarioError(self.path, field, message)

    def table(self, data: dict, key: str, required: bool = False) -> dict:
        t = data.get(key)
        if t is None:
            if required:
                raise self.err(key, "missing (a table is required)")
            return {}
        if not isinstance(t, dict):
            raise self.err(key, "must be a table")
        return t

    def no_extra(self, t: dict, where: str, allowed) -> None:
        for k in t:
            if k not in allowed:
                raise self.err(f"{where}.{k}" if where else str(k), unknown_field_message(k, allowed))

    def one_form(self, t: dict, field: str, forms: dict, hint: str) -> None:
        """Unknown keys, then keys of two forms (say polygon and radius) together, are errors."""
        self.no_extra(t, field, set().union(*forms.values()))
        used = [sorted(k for k in keys if k in t) for keys in forms.values()]
        used = [keys for keys in used if keys]
        if len(used) > 1:
            a, b = sorted((used[0][0], used[1][0]))
            raise self.err(field, f"{a} and {b} exclude each other ({hint})")

    def number(self, x, field: str, positive: bool = False) -> float:
        # The common cases first (a scene may hold 10^6 numbers): a finite float within
        # the supported magnitude (NaN and inf fail the comparison), a modest int.
        if not positive:
            if type(x) is float and -MAX_MAGNITUDE <= x <= MAX_MAGNITUDE:
                return x
            if type(x) is int and -(1 << 53) <= x <= 1 << 53:
                return float(x)
        if x is None:
            raise self.err(field, "missing (a number is required)")
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise self.err(field, f"must be a number, got {type(x).__name__} {show(x)}")
        try:
            xf = float(x)
        except OverflowError:
            raise self.err(field, f"{show(x)} is too large for a double") from None
        if not math.isfinite(xf):
            raise self.err(field, f"must be finite, got {x}")
        if abs(xf) > MAX_MAGNITUDE:
            raise self.err(field, f"{show(x)} is beyond the supported magnitude 2^400 (about {MAX_MAGNITUDE:.2g})")
        if positive and not xf > 0.0:
            raise self.err(field, f"must be positive, got {x}")
        return xf

    def point(self, p, field: str) -> tuple[float, float]:
        if not isinstance(p, list) or len(p) != 2:
            raise self.err(field, f"must be a point [x, y], got {show(p)}")
        return self.number(p[0], f"{field}[0]"), self.number(p[1], f"{field}[1]")

    def pose(self, t: dict, field: str) -> tuple[tuple[float, float], float | None]:
        self.no_extra(t, field, {"x", "y", "theta"})
        xy = (self.number(t.get("x"), f"{field}.x"), self.number(t.get("y"), f"{field}.y"))
        theta = self.number(t["theta"], f"{field}.theta") if "theta" in t else None
        return xy, theta

    def polygon(self, pts, field: str) -> np.ndarray:
        if not isinstance(pts, list):
            raise self.err(field, "must be a list of points [[x, y], ...]")
        arr = np.array([self.point(p, f"{field}[{i}]") for i, p in enumerate(pts)], dtype=np.float64).reshape(-1, 2)
        if len(np.unique(arr, axis=0)) < 3:
            raise self.err(field, f"needs at least 3 distinct vertices, got {len(np.unique(arr, axis=0))}")
        return arr

    def planner(self, t) -> dict:
        if not isinstance(t, dict):
            raise self.err("planner", "must be a table")
        self.no_extra(t, "planner", {"name", "time", "seed"})
        out = {}
        if "name" in t:
            if not isinstance(t["name"], str) or not t["name"]:
                raise self.err("planner.name", "must be a planner name")
            out["name"] = t["name"]
        if "time" in t:
            out["time"] = self.number(t["time"], "planner.time", positive=True)
        if "seed" in t:
            if isinstance(t["seed"], bool) or not isinstance(t["seed"], int) or not 0 <= t["seed"] <= MAX_SEED:
                raise self.err("planner.seed", f"must be an integer in [0, 2^32 - 1), got {show(t['seed'])}")
            out["seed"] = t["seed"]
        return out

    def queries(self, lst, se2: bool = False) -> list[Query]:
        """``start``/``goal`` as ``[x, y]`` or ``{x, y}``; in SE(2) ``[x, y, theta]`` or
        ``{x, y, theta}`` (theta defaults to 0)."""
        if not isinstance(lst, list):
            raise self.err("queries", "must be an array of tables [[queries]]")
        out = []
        for i, q in enumerate(lst):
            f = f"queries[{i}]"
            if not isinstance(q, dict):
                raise self.err(f, "must be a table")
            self.no_extra(q, f, {"start", "goal"})
            pts = []
            for key in ("start", "goal"):
                p, fk = q.get(key), f"{f}.{key}"
                if isinstance(p, dict):
                    xy, th = self.pose(p, fk)
                    if th is not None and not se2:
                        raise self.err(f"{fk}.theta", 'the robot only translates here: add space = "se2" to give '
                                                      "queries an angle")
                    pts.append((*xy, wrap_angle(th or 0.0)) if se2 else xy)
                elif p is None:
                    raise self.err(fk, "missing")
                elif se2 and isinstance(p, list) and len(p) == 3:
                    pts.append((*self.point(p[:2], fk), wrap_angle(self.number(p[2], f"{fk}[2]"))))
                elif not se2 and isinstance(p, list) and len(p) == 3:
                    raise self.err(fk, 'has an angle, but the robot only translates here: add space = "se2" '
                                       "to let it rotate")
                else:
                    if se2 and not (isinstance(p, list) and len(p) == 2):
                        raise self.err(fk, f"must be a pose [x, y, theta] (or [x, y]), got {short(p)}")
                    xy = self.point(p, fk)
                    pts.append((*xy, 0.0) if se2 else xy)
            out.append(Query(pts[0], pts[1]))
        return out
