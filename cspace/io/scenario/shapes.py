"""Shape checks of a scenario: polygons (simple, holes inside), disks, the robot's forms, the
``[margin]`` polygon, and the obstacles, plain polygons checked and normalised in batches.
"""
from __future__ import annotations

import numpy as np

from ...kernel.polygons.disk import disk_polygon
from ...kernel.polygons.polygon import invalid_reason, is_convex, normalize
from .fields import FieldChecks
from .messages import ScenarioError
from .schema import MAX_MAGNITUDE, Shape

# The forms of a robot table and of a shape (obstacle or robot part), by their keys: keys of two
# different forms in one table exclude each other.
ROBOT_FORMS = {"polygon": {"polygon"}, "parts": {"parts"}, "disk": {"radius"}}
SHAPE_FORMS = {"polygon": {"polygon", "holes"}, "disk": {"center", "radius"}}


class ShapeChecks(FieldChecks):
    """The field checks, and those of shapes (obstacles, robot parts, the margin)."""

    def shape(self, t: dict, field: str, tol: float, allow_holes: bool) -> Shape:
        if not isinstance(t, dict):
            raise self.err(field, "must be a table")
        if field == "robot":  # the robot table's forms are checked by robot()
            forms = {"polygon": {"polygon"}, "disk": {"radius"}}
        else:
            forms = SHAPE_FORMS if allow_holes else {"polygon": {"polygon"}, "disk": {"center", "radius"}}
        self.one_form(t, field, forms, "a polygon = [[x, y], ...] or a disk: center = [x, y], radius = r")
        if "polygon" in t:
            ext = self.polygon(t["polygon"], f"{field}.polygon")
            holes_raw = t.get("holes", [])
            if not isinstance(holes_raw, list):
                raise self.err(f"{field}.holes", "must be a list of polygons")
            holes = [self.polygon(h, f"{field}.holes[{i}]") for i, h in enumerate(holes_raw)]
            reason = invalid_reason(ext)  # GEOS's check, on a copy near 1 at extreme scales
            if reason:
                raise self.err(f"{field}.polygon", f"not a simple polygon ({reason})")
            ext_n = normalize(ext, ccw=True)
            if len(ext_n) < 3:  # exact: a float area underflows near 1e-160
                raise self.err(f"{field}.polygon", "has zero area")
            holes_n = []
            for i, h in enumerate(holes):
                holes_n.append(normalize(h, ccw=False))
                if invalid_reason(h) or len(holes_n[-1]) < 3:
                    raise self.err(f"{field}.holes[{i}]", "not a simple polygon of non-zero area")
            if holes:
                reason = invalid_reason(ext, holes)
                if reason:
                    raise self.err(f"{field}.holes", f"holes do not fit the polygon ({reason})")
            return Shape(ext_n, holes_n, None, convex=not holes_n and is_convex(ext_n))
        if "radius" in t:
            if field != "robot" and "center" not in t:
                raise self.err(f"{field}.center", "missing (a disk needs center = [x, y] with its radius)")
            r = self.number(t.get("radius"), f"{field}.radius", positive=True)
            c = self.point(t.get("center", [0.0, 0.0] if field == "robot" else None), f"{field}.center")
            poly = disk_polygon(c, r, max_error=tol * r)
            # A disk far below the spacing of doubles at its centre rounds to a point or a
            # segment, which the C-space cannot represent: refuse it rather than misplace it.
            if r < 1e-6 * max(abs(c[0]), abs(c[1])) and len(normalize(poly)) < 3:
                raise self.err(f"{field}.radius", f"{r} is too small for a disk centred at ({c[0]}, {c[1]}): "
                                                  f"its polygon rounds to a point or a segment in doubles")
            return Shape(poly, [], (c[0], c[1], r), convex=True)
        raise self.err(field, "needs polygon = [[x, y], ...] or center = [x, y] with radius = r")

    def robot(self, t, theta: float, tol: float) -> tuple[list[Shape], str]:
        if t is None:
            return [], "point"
        if not isinstance(t, dict):
            raise self.err("robot", "must be a table")
        if "center" in t and "radius" in t:
            raise self.err("robot.center", "a disk robot is centred on its reference point; give radius only")
        self.one_form(t, "robot", ROBOT_FORMS, "one of polygon = [...], [[robot.parts]] or radius = r")
        if "parts" in t:
            parts = t["parts"]
            if not isinstance(parts, list) or not parts:
                raise self.err("robot.parts", "must be a non-empty array of tables")
            shapes = [self.shape(p, f"robot.parts[{i}]", tol, allow_holes=False) for i, p in enumerate(parts)]
            kind = "parts"
        elif "radius" in t:
            shapes = [self.shape(t, "robot", tol, allow_holes=False)]
            kind = "disk"
        elif "polygon" in t:
            shapes = [self.shape(t, "robot", tol, allow_holes=False)]
            kind = "polygon"
        else:
            raise self.err("robot", "needs polygon, [[robot.parts]] or radius")
        if theta:
            from ...kernel.polygons.rotation import rotate  # the one rotation used for "the robot at theta"

            for sh in shapes:
                sh.polygon = rotate(sh.polygon, theta)
                if sh.disk is not None:  # a part's disk turns about the reference point with it
                    (cx, cy), = rotate(np.array([sh.disk[:2]], dtype=np.float64), theta).tolist()
                    sh.disk = (cx, cy, sh.disk[2])
        return shapes, kind

    def margin(self, t, theta: float, tol: float) -> np.ndarray | None:
        """``[margin] polygon = [...]``: convex, containing the origin, turned by theta like the robot."""
        if t is None:
            return None
        if not isinstance(t, dict):
            raise self.err("margin", "must be a table with polygon = [[x, y], ...]")
        self.no_extra(t, "margin", {"polygon"})
        if "polygon" not in t:
            raise self.err("margin.polygon", "missing (a convex polygon around the reference point)")
        from ...kernel.minkowski.margin import check_margin_polygon

        p = self.shape({"polygon": t["polygon"]}, "margin", tol, allow_holes=False).polygon
        why = check_margin_polygon(p)
        if why:
            raise self.err("margin.polygon", why)
        if theta:
            from ...kernel.polygons.rotation import rotate

            p = rotate(p, theta)
        return p

    def obstacles(self, lst, tol: float) -> list[Shape]:
        """The obstacles, in order, as :meth:`shape` reads each one.

        Plain polygons (no holes) have their numbers read here and their geometry
        checked and normalised in batches (:func:`cspace.kernel.polygons.polygon_batch.normalize_many`);
        any the batch does not decide, and every other obstacle, go through
        :meth:`shape`. The first faulty obstacle in file order is the one reported,
        as if each were read in turn.
        """
        if not isinstance(lst, list):
            raise self.err("obstacles", "must be an array of tables [[obstacles]]")
        from ...kernel.polygons.polygon_batch import normalize_many

        out: list = [None] * len(lst)
        raw: dict = {}  # obstacle -> its plain [[x, y], ...] list
        fault = None
        for i, t in enumerate(lst):
            if isinstance(t, dict) and "polygon" in t and set(t) <= {"polygon", "holes"} and \
                    t.get("holes", []) == [] and _plain_list(t["polygon"]):
                raw[i] = t["polygon"]
                continue
            try:
                out[i] = self.shape(t, f"obstacles[{i}]", tol, allow_holes=True)
            except ScenarioError as exc:
                fault = exc  # raised below, unless an earlier obstacle has a fault
                break
        # Plain lists: converted per vertex count in one numpy call, then checked and
        # normalised in batches; what either step does not accept is read by shape().
        slow = []
        groups: dict = {}
        for i, pts in raw.items():
            groups.setdefault(len(pts), []).append(i)
        for n, idx in groups.items():
            try:
                block = np.array([raw[i] for i in idx], dtype=np.float64).reshape(len(idx), n, 2)
            except (OverflowError, ValueError):  # an int too large for a double, somewhere
                slow += idx
                continue
            fine = (np.abs(block) <= MAX_MAGNITUDE).all(axis=(1, 2)) if n else np.zeros(len(idx), dtype=bool)
            good = [i for i, f in zip(idx, fine.tolist()) if f]
            slow += [i for i, f in zip(idx, fine.tolist()) if not f]
            rows = np.flatnonzero(fine)
            for i, got in zip(good, normalize_many(list(block[rows]))):
                if got is None:
                    slow.append(i)
                else:
                    out[i] = Shape(got[0], [], None, convex=got[1])
        for i in sorted(slow):  # in file order: the first faulty one raises, worded as always
            out[i] = self.shape(lst[i], f"obstacles[{i}]", tol, allow_holes=True)
        if fault is not None:
            raise fault
        return out


def _plain_list(pts) -> bool:
    """Whether ``pts`` is a non-empty ``[[x, y], ...]`` of plain floats and ints (no bool,
    no string): the loader's batched route; the values are checked after conversion.

    >>> _plain_list([[0, 1.5], [2, 3]]), _plain_list([[0, True]]), _plain_list([[0, 1, 2]])
    (True, False, False)
    """
    if type(pts) is not list or not pts:
        return False
    for p in pts:
        if type(p) is not list or len(p) != 2:
            return False
        x, y = p
        if (type(x) is not float and type(x) is not int) or (type(y) is not float and type(y) is not int):
            return False
    return True
