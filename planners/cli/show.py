"""``cspace show``: draw a scene's workspace, C-obstacles and convex pieces without planning."""
from __future__ import annotations

from ..output import PLOT_FORMATS, check_distinct, check_output, say


def register(sub) -> None:
    p = sub.add_parser("show", help="draw the workspace, the C-obstacles and their convex pieces",
                       description="Build the C-space of a scenario, print its report, and optionally plot it.")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--plot", help="picture file (.png, .svg or .pdf)")
    p.add_argument("--json", help="write the C-space report as JSON")
    from .plan import add_space_options, number

    add_space_options(p)
    from .imports import add_import_options

    add_import_options(p)
    p.add_argument("--theta", type=number,
                   help="a rotating robot or a car (--space se2, dubins or reeds-shepp): draw the C-space of "
                        "the angle slab that holds this angle (radians, default 0)")
    p.add_argument("--clearance", type=number, help="safety margin D: the C-obstacles of the robot inflated by "
                                                     "the disk of radius D (default: the scenario's)")
    p.add_argument("--verbose", "-v", action="store_true",
                   help="on an internal error, print its traceback; let numpy and matplotlib warnings through")
    p.set_defaults(run=run)


def run(args) -> int:
    from cspace.io.scenario.files import check_input
    from cspace.io.load import load_scenario

    from ..errors import InputError

    if args.clearance is not None:
        from cspace.io.scenario.fields import clearance_fault

        if fault := clearance_fault(args.clearance):
            raise InputError(args.scenario, "--clearance", fault)
    from .imports import input_files

    check_input(args.scenario)
    inputs = input_files(args.scenario, args.robot)  # a map's image, a cfg's meshes, the robot file too
    fmt = check_output(args.plot, "--plot", PLOT_FORMATS, inputs=inputs) if args.plot is not None else None
    if args.json is not None:
        check_output(args.json, "--json", inputs=inputs)
    check_distinct([(args.json, "--json"), (args.plot, "--plot")])
    from cspace.translation.cspace import CSpace

    from .imports import import_options

    sc = load_scenario(args.scenario, space=args.space, options=import_options(args, args.scenario))
    if args.clearance is not None:
        import dataclasses

        sc = dataclasses.replace(sc, clearance=float(args.clearance))
    if sc.rotates:
        return _show_se2(sc, args, fmt)
    for value, option in ((args.theta, "--theta"), (args.slabs, "--slabs")):
        if value is not None:  # a translation scene has one C-space: the option would be ignored
            raise InputError(args.scenario, option, f"applies to a rotating robot only: add --space se2 "
                                                    f"(the scenario's space is {sc.space!r})")
    cs = CSpace.from_scenario(sc)
    rep = cs.report()
    margin = f" (with a margin: clearance {sc.clearance:g})" if sc.margins() else ""
    lines = [f"{sc.name}: {len(sc.obstacles)} obstacles, robot {sc.robot_kind}{margin}, "
             f"{rep['pieces']} C-obstacle pieces, built in {rep['build_seconds'] * 1e3:.1f} ms"]
    for s in rep["stages"]:
        counts = {k: v for k, v in s.items() if k not in ("stage", "ran", "seconds", "note")}
        note = f" ({s['note']})" if s.get("note") else ""
        lines.append(f"  {s['stage']:<20} {'ran' if s['ran'] else 'skipped':<8} {s['seconds'] * 1e3:8.2f} ms  {counts}{note}")
    gone = say("\n".join(lines))  # (a reader gone: the files below are still written)
    if args.json is not None:
        from ..output import write_json

        write_json(args.json, {"scenario": sc.name, **rep}, "--json")
    if args.plot is not None:
        from ..pictures.plot import plot_scene

        plot_scene(sc, cs, args.plot, fmt=fmt)
    if gone:
        raise BrokenPipeError
    return 0


def _show_se2(sc, args, fmt) -> int:
    """SE(2): the slab of ``--theta``: its C-space (the obstacles summed with the robot's
    slab hulls, free there means free at every angle of the slab) and the report."""
    import math

    from cspace.se2.cspace import SE2CSpace
    from cspace.kernel.slabs.slab import slab_range
    from cspace.kernel.polygons.rotation import wrap_angle

    from ..errors import InputError

    if args.theta is None:
        args.theta = 0.0
    if not math.isfinite(args.theta):
        raise InputError(args.scenario, "--theta", f"must be a finite angle in radians, got {args.theta}")
    if args.slabs is not None and not 4 <= args.slabs <= 4096:
        raise InputError(args.scenario, "--slabs", f"must be an integer from 4 to 4096, got {args.slabs}")
    se2 = SE2CSpace.from_scenario(sc, slabs=args.slabs if args.slabs is not None else sc.slabs)
    th = wrap_angle(args.theta)
    k = se2._slab_index(th)
    slab = se2.slab(k)
    a, b = slab_range(k, se2.slabs)
    rep = se2.report()
    gone = say(f"{sc.name}: {len(sc.obstacles)} obstacles, robot {sc.robot_kind}, SE(2) with {rep['slabs_reason']}\n"
               f"  slab {k} of {se2.slabs}: theta in [{math.degrees(a):.4g}, {math.degrees(b):.4g}] deg, "
               f"{len(slab.pieces)} C-obstacle pieces, built in {rep['build_seconds'] * 1e3:.1f} ms")
    if args.json is not None:
        from ..output import write_json

        write_json(args.json, {"scenario": sc.name, "slab": k, "slab_range": [a, b], **rep,
                               "slab_report": slab.report()}, "--json")
    if args.plot is not None:
        from ..pictures.plot import plot_scene

        plot_scene(sc, slab, args.plot, fmt=fmt, theta=th,
                   title=f"{sc.name}: slab {k}/{se2.slabs} (theta {math.degrees(a):.3g} to {math.degrees(b):.3g} deg), "
                         f"{len(slab.pieces)} pieces")
    if gone:
        raise BrokenPipeError
    return 0
