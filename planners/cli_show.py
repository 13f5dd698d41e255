"""``cspace show``: draw a scene's workspace, C-obstacles and convex pieces without planning."""
from __future__ import annotations

from .output import PLOT_FORMATS, check_distinct, check_output


def register(sub) -> None:
    p = sub.add_parser("show", help="draw the workspace, the C-obstacles and their convex pieces",
                       description="Build the C-space of a scenario, print its report, and optionally plot it.")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--plot", help="picture file (.png, .svg or .pdf)")
    p.add_argument("--json", help="write the C-space report as JSON")
    p.add_argument("--verbose", "-v", action="store_true")
    p.set_defaults(run=run)


def run(args) -> int:
    from cspace.scenario import check_input, load_scenario

    check_input(args.scenario)
    fmt = check_output(args.plot, "--plot", PLOT_FORMATS, inputs=[args.scenario]) if args.plot is not None else None
    if args.json is not None:
        check_output(args.json, "--json", inputs=[args.scenario])
    check_distinct([(args.json, "--json"), (args.plot, "--plot")])
    from cspace.cspace import CSpace

    sc = load_scenario(args.scenario)
    cs = CSpace.from_scenario(sc)
    rep = cs.report()
    print(f"{sc.name}: {len(sc.obstacles)} obstacles, robot {sc.robot_kind}, "
          f"{rep['pieces']} C-obstacle pieces, built in {rep['build_seconds'] * 1e3:.1f} ms")
    for s in rep["stages"]:
        counts = {k: v for k, v in s.items() if k not in ("stage", "ran", "seconds", "note")}
        note = f" ({s['note']})" if s.get("note") else ""
        print(f"  {s['stage']:<20} {'ran' if s['ran'] else 'skipped':<8} {s['seconds'] * 1e3:8.2f} ms  {counts}{note}")
    if args.json is not None:
        from .output import write_json

        write_json(args.json, {"scenario": sc.name, **rep}, "--json")
    if args.plot is not None:
        from .plot import plot_scene

        plot_scene(sc, cs, args.plot, fmt=fmt)
    return 0
