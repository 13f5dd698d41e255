"""``cspace stability``: the numerical stability catalogue (:mod:`planners.stability`), as a table,
JSON and a chart."""
from __future__ import annotations


from ..stability.catalogue import GUARANTEES, WIDTH, catalogue, format_table, run_all, runnable


def register(sub) -> None:
    p = sub.add_parser("stability", help="run stiff and extreme cases through every layer",
                       description="Run the numerical stability catalogue against exact references.")
    p.add_argument("--json", metavar="FILE", help="write the rows as JSON")
    p.add_argument("--plot", metavar="FILE", help="write a PNG bar chart of times, coloured by pass")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..output import check_output, say, write_json

    if args.json is not None:  # "" is refused by check_output, not skipped
        check_output(args.json, "--json")
    if args.plot is not None:
        check_output(args.plot, "--plot", {".png": "png"})
    import textwrap

    cases, skipped = runnable(catalogue())
    rows = run_all(cases, progress=None)
    failed = [r["case"] for r in rows if not r["passed"]]
    text = [format_table(rows), "\n" + textwrap.fill(f"{len(rows) - len(failed)}/{len(rows)} cases pass"
                                                     + (f"; FAILED: {', '.join(failed)}" if failed else ""), WIDTH,
                                                     subsequent_indent="  ", break_on_hyphens=False)]
    if skipped:
        from ..adapters.glue import OMPL_HINT

        text.append(textwrap.fill(f"note: skipped {len(skipped)} case(s) that need OMPL, which is not installed "
                                  f"({', '.join(c.name for c in skipped)}; {OMPL_HINT})", WIDTH,
                                  subsequent_indent="  ", break_on_hyphens=False))
    gone = say("\n".join(text))  # (a reader gone: the files below are still written)
    if args.json is not None:
        write_json(args.json, {"cases": rows, "guarantees": GUARANTEES, "passed": not failed,
                               "skipped": [c.name for c in skipped]})
    if args.plot is not None:
        from ..pictures.stability_chart import plot_stability

        plot_stability(rows, args.plot)
    if gone:
        raise BrokenPipeError
    return 0 if not failed else 1
