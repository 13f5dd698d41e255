"""The HTML page: plotly.js inlined (gzip + base64 by default, see the package notes), the
figure as inline JSON, the plan's report as text, and a little glue script.

The glue draws the figure (``Plotly.newPlot``, ``Plotly.addFrames``), writes any JavaScript
error into the page (``#errors``, and the title ``error``), sets the title to ``ok`` once
drawn (``data-drawn-ms`` on the body: milliseconds since the navigation started), and keeps
``#state`` (the current frame, the sliders' positions) up to date. A URL
hash drives the controls, for links and scripted screenshots (read at load and on every
change): ``#pose=I`` or ``#angle=J`` moves that slider to step I (J) as a click on the step
does (I clamped to the slider's steps; a value that is not a number is ignored), ``#play``
clicks the play button.
"""
from __future__ import annotations

import base64
import functools
import gzip
import html
import math

from ...output import write_text
from ..titles import planner_words
from .figure import DEFAULT_ANGLES, DEFAULT_POSES, figure_dict

STYLE = """body{font-family:system-ui,sans-serif;margin:12px;color:#222}
#plot{width:100%;max-width:1100px}pre{background:#f6f6f6;padding:8px;white-space:pre-wrap;max-width:1100px}
#errors:empty,#state{display:none}#errors{color:#b00;background:#fee}"""

LOADER = """async function unpack(id) {  // a gzip-packed, base64-encoded data block, as text
  if (typeof DecompressionStream === "undefined")
    throw new Error("this browser cannot unpack the page (no DecompressionStream): write it uncompressed");
  const raw = atob(document.getElementById(id).textContent.trim()), bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
  return await new Response(stream).text();
}
async function loadPlotly() {
  if (window.Plotly) return;
  const script = document.createElement("script");
  script.textContent = await unpack("plotly-gz");
  document.head.appendChild(script);
}
async function figure() {
  const plain = document.getElementById("figure");
  return JSON.parse(plain ? plain.textContent : await unpack("figure-gz"));
}"""

GLUE = """function fail(message) {
  document.getElementById("errors").textContent += message + "\\n";
  document.title = "error";
}
window.onerror = (msg, src, line, col) => fail(msg + " (line " + line + ":" + col + ")");
window.addEventListener("unhandledrejection", ev => fail("unhandled: " + (ev.reason && ev.reason.stack || ev.reason)));
function sliderIndex(gd, name) {
  return (gd.layout.sliders || []).findIndex(s => s.name === name);
}
function state(gd) {
  const sliders = {};
  for (const s of gd._fullLayout.sliders || []) sliders[s.name] = s.active;
  document.getElementById("state").textContent = JSON.stringify({frame: gd._fullLayout._currentFrame || null, sliders});
}
async function follow(gd, hash) {
  const args = new URLSearchParams(hash.replace(/^#/, ""));
  for (const name of ["pose", "angle"]) {
    if (!args.has(name) || sliderIndex(gd, name) < 0) continue;  // no path, or no angle: nothing to move
    const s = gd.layout.sliders[sliderIndex(gd, name)], wanted = Number(args.get(name).trim() || NaN);
    if (!Number.isFinite(wanted)) continue;  // #pose=abc: not a step, the slider stays
    const step = s.steps[Math.max(0, Math.min(Math.round(wanted), s.steps.length - 1))];  // clamped
    await Plotly.animate(gd, step.args[0], step.args[1]);
  }
  const button = gd.querySelector(".updatemenu-button");  // none without a path
  if (args.has("play") && button) button.dispatchEvent(new MouseEvent("click", {bubbles: true}));
}
async function main() {
  await loadPlotly();
  const fig = await figure();
  const gd = document.getElementById("plot");
  await Plotly.newPlot(gd, fig.data, fig.layout, {scrollZoom: true, displaylogo: false, responsive: true});
  if (fig.frames.length) await Plotly.addFrames(gd, fig.frames);
  document.body.dataset.drawnMs = String(Math.round(performance.now()));  // since navigation started
  gd.on("plotly_animated", () => state(gd));
  gd.on("plotly_sliderchange", () => state(gd));
  state(gd);
  await follow(gd, location.hash);
  window.addEventListener("hashchange", () => follow(gd, location.hash).catch(err => fail(String(err))));
  setInterval(() => state(gd), 100);
  if (document.title !== "error") document.title = "ok";
}
main().catch(err => fail(String(err && err.stack || err)));"""


def check_plotly(out: str, option: str) -> None:
    """Refuse an HTML output up front, as bad input (exit 2), when plotly is not installed.

    >>> check_plotly("v.html", "--out")  # plotly installed: nothing to say
    """
    import importlib.util

    if importlib.util.find_spec("plotly") is None:
        from ...errors import InputError

        raise InputError(out, option, "the page needs plotly: pip install plotly (or pip install -e \".[view]\")")


@functools.lru_cache(maxsize=2)  # packed once per process: pages written in a row reuse it
def plotly_script(compress: bool = True) -> str:
    """plotly.js as the page inlines it: its minified bundle, gzip-compressed and base64-encoded
    in a data block (``compress``), else as a plain script.

    >>> plotly_script().startswith('<script type="application/octet-stream" id="plotly-gz">')
    True
    """
    from plotly.offline import get_plotlyjs

    js = get_plotlyjs()
    if not compress:
        return "<script>" + js.replace("</script", "<\\/script") + "</script>"
    return packed_block("plotly-gz", js)


def packed_block(block_id: str, text: str) -> str:
    """``text`` gzip-compressed and base64-encoded in an inert script element (the glue unpacks it).

    >>> packed_block("x", "hello")[:49]
    '<script type="application/octet-stream" id="x">H4'
    """
    packed = base64.b64encode(gzip.compress(text.encode("utf-8"), compresslevel=6, mtime=0)).decode("ascii")
    return f'<script type="application/octet-stream" id="{block_id}">{packed}</script>'


def report_text(res, scenario=None, extra: str = "") -> str:
    """The plan's report as the page prints it: planner, seed, times, checks, length, clearance.

    >>> class R:
    ...     scenario, planner, seed, solved, length, message = "s", "exact", 0, True, 2.5, ""
    ...     timings, checks, stages, path, proof, cspace_report = {"solve": 0.001}, {}, [], [], None, None
    ...     min_clearance = min_clearance_bound = None
    ...     proven_unsolvable = False
    >>> print(report_text(R()).splitlines()[0])
    s: solved by exact: length 2.5
    """
    sc = scenario or getattr(res, "scenario_data", None)
    by = planner_words(res)
    lines = [f"{res.scenario}: solved by {by}: length {res.length:.6g}" if res.solved
             else f"{res.scenario}: NOT solved by {by}: {res.message}"]
    if sc is not None:
        lines.append(f"space {sc.space}, robot {sc.robot_kind}, {len(sc.obstacles)} obstacles"
                     + (f", turning radius {sc.turning_radius:g}" if sc.turning_radius is not None else ""))
    if res.solved:
        lines.append(f"{len(res.path)} waypoints; {res.message}" if res.message else f"{len(res.path)} waypoints")
    lines.append("time: " + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in res.timings.items()))
    if res.checks:
        lines.append("checks: " + ", ".join(f"{k} {v}" for k, v in res.checks.items()))
    if res.stages:
        lines.append("stages: " + " -> ".join(res.stages))
    c = res.min_clearance
    if res.solved and c is not None:
        kind = "a certified lower bound" if res.min_clearance_bound == "lower" else "exact"
        where = ", ".join(f"{v:.4g}" for v in (res.min_clearance_at or ()))
        lines.append(f"min clearance {c:.6g} at ({where}) ({kind}), marked by a star" if math.isfinite(c)
                     else "min clearance: inf (no obstacle)")
    rep = res.cspace_report or {}
    if "slabs" in rep:
        lines.append(f"C-space: {rep['slabs']} angle slabs ({rep.get('slabs_reason', '')}); the angle slider "
                     "shows the slab at that angle: where the reference point collides at some angle of the slab")
    if res.proof is not None:
        lines.append(f"PROVEN UNSOLVABLE: a proof over {len(res.proof.get('slabs', []))} slabs; the angle slider "
                     "also shows, in green, the components the proof lists for the slab at that angle "
                     "(re-check it: cspace plan --proof FILE, then cspace check-proof)")
    elif res.proven_unsolvable:  # no proof file: the free space's components separate start and goal
        lines.append("PROVEN UNSOLVABLE: start and goal are in different free components")
    return "\n".join(lines + ([extra] if extra else []))


def view_html(res, scenario=None, poses: int = DEFAULT_POSES, angles: int = DEFAULT_ANGLES,
              compress: bool = True, extra: str = "") -> str:
    """The offline page of a plan result (a :class:`planners.core.result.PlanResult`) as text.

    >>> import planners
    >>> from planners.pictures.view.traces import example_scene
    >>> page = view_html(planners.plan(example_scene(), planner="exact"))
    >>> page.startswith("<!DOCTYPE html>"), "http://" in page.split('id="plotly-gz"')[0]
    (True, False)
    """
    import plotly.graph_objects as go
    import plotly.io as pio

    sc = scenario or res.scenario_data
    fig = figure_dict(res, sc, poses=poses, angles=angles)
    # plotly checks every property name and value of the traces and the layout; the frames hold
    # more of the same traces (made by the same functions), left unchecked: checking is slow.
    go.Figure({"data": fig["data"], "layout": fig["layout"]})
    body = pio.to_json(fig, validate=False, pretty=False, remove_uids=True)
    if compress:
        figure_block = packed_block("figure-gz", body)
    else:  # inline JSON cannot close its script element
        figure_block = '<script type="application/json" id="figure">' + body.replace("</", "<\\/") + "</script>"
    title = html.escape(f"{sc.name}: {res.planner}" if sc is not None else res.scenario)
    return "\n".join([
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>loading {title}</title><style>{STYLE}</style></head><body>",
        f"<h2>{title}</h2>", '<pre id="errors"></pre><div id="plot"></div>',
        f'<pre id="report">{html.escape(report_text(res, sc, extra))}</pre><pre id="state"></pre>',
        plotly_script(compress),
        figure_block,
        f"<script>\n{LOADER}\n{GLUE}\n</script>", "</body></html>", ""])


def write_view(res, out: str, scenario=None, poses: int = DEFAULT_POSES, angles: int = DEFAULT_ANGLES,
               compress: bool = True, extra: str = "", option: str = "--html") -> None:
    """Write :func:`view_html` to ``out``, atomically (a temporary file, then a rename); a fault
    (a page over the size bound, a full disk) is an error on ``option``, the option naming ``out``.

    >>> import os, tempfile, planners
    >>> from planners.pictures.view.traces import example_scene
    >>> out = os.path.join(tempfile.mkdtemp(), "v.html")
    >>> write_view(planners.plan(example_scene(), planner="exact"), out)
    >>> os.path.getsize(out) > 1_000_000
    True
    """
    from ...errors import InputError

    try:
        page = view_html(res, scenario, poses=poses, angles=angles, compress=compress, extra=extra)
    except InputError as exc:  # the figure's own refusal (its size), said of the page's file
        raise InputError(out, option, exc.message) from None
    write_text(out, page, option)
