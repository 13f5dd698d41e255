"""Fuzzing the scenario loader and the command line against the promises (issue 24 item 9).

Every case runs ``planners.cli.main`` in this process and is checked against the contract of
tests/helpers/fuzzing.py (:func:`fuzzing.check_case`): exit 0, 1 or 2, never 3 nor a crash;
exit 2 one short ``error:`` line and no traceback; the input unchanged; no temporaries left; a
written JSON output valid; each case within a hang bound.

The budget is small in CI (a few seconds); set ``CSPACE_FUZZ_EXAMPLES=N`` for N
examples per test, e.g. ``CSPACE_FUZZ_EXAMPLES=3500 pytest tests/cli/test_fuzz_cli.py``
for a run of more than 10 000 cases, and ``CSPACE_FUZZ_REPORT=FILE`` for its figures
(cases, exit codes, slowest case) as JSON.
"""
from __future__ import annotations

import json
import os
import shutil

from hypothesis import given, strategies as st

from conftest import ROOT
from fuzzing import EXAMPLES, STATS, budget, check_case, mutate_bytes, workdir


# ------------------------------------------------------------------ scenario documents

BASE = {
    "name": "fuzz",
    "bounds": {"xmin": 0.0, "xmax": 10.0, "ymin": 0.0, "ymax": 10.0},
    "robot": {"polygon": [[-0.4, -0.3], [0.4, -0.3], [0.0, 0.5]]},
    "obstacles": [{"polygon": [[3, 0], [4, 0], [4, 6], [3, 6]]},
                  {"center": [7.0, 7.0], "radius": 1.0},
                  {"polygon": [[5, 1], [9, 1], [9, 4], [5, 4]], "holes": [[[6, 2], [8, 2], [8, 3], [6, 3]]]}],
    "start": {"x": 1.0, "y": 1.0},
    "goal": {"x": 9.0, "y": 9.0},
    "planner": {"name": "RRTConnect", "time": 0.5, "seed": 1},
}

# Literal tokens a serializer of Python values would not produce.
RAW = st.sampled_from([
    "nan", "inf", "-inf", "+nan", "1e999", "-1e999", "1e-999", "5e-324", "-0.0", "0x" + "f" * 4000, "9" * 5000,
    "0o777", "0b101", "1_000", "2e120", "1e300", "-2e400", str(2**64), str(2**63), str(-(2**63)), "[" * 400 + "]" * 400,
    "true", "false", '""', '"\\u0000"', "1979-05-27T07:32:00Z", "{}", "[]", "[[]]", "[[1]]", "[1, 2, 3]",
    "[" + ", ".join(["1.5"] * 20_000) + "]", '"' + "s" * 50_000 + '"',
])
SCALAR = st.one_of(
    st.integers(-(2**70), 2**70), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
    st.text(max_size=20), st.sampled_from([0, 1, -1, 0.5, 1e-9, 1e9, 5e7, 2.0**400, 2.0**-400]),
)
KEYS = st.sampled_from(["x", "y", "polygon", "holes", "center", "radius", "name", "time", "seed", "zz"])
VALUE = st.recursive(SCALAR, lambda kids: st.lists(kids, max_size=5) | st.dictionaries(KEYS, kids, max_size=4),
                     max_leaves=12)


def toml_value(v) -> str:
    """One TOML value (inline tables and arrays), for the values the strategies draw."""
    if isinstance(v, _Raw):
        return v.text
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return {"nan": "nan", "inf": "inf", "-inf": "-inf"}.get(repr(v), repr(v))
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # a JSON string is a valid TOML basic string
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(str(k), ensure_ascii=False)} = {toml_value(x)}"
                               for k, x in v.items()) + "}"
    return "[" + ", ".join(toml_value(x) for x in v) + "]"


def toml_document(doc: dict) -> str:
    return "".join(f"{json.dumps(str(k))} = {toml_value(v)}\n" for k, v in doc.items())


class _Raw:
    def __init__(self, text):
        self.text = text


def _paths(doc, prefix=()):
    """Every (path, value) inside a document, tables and arrays included."""
    yield prefix, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _paths(v, prefix + (i,))


@st.composite
def mutated_document(draw) -> str:
    doc = json.loads(json.dumps(BASE))
    for _ in range(draw(st.integers(1, 2))):
        paths = [p for p, _ in _paths(doc) if p]
        where = draw(st.sampled_from(paths))
        parent = doc
        for k in where[:-1]:
            parent = parent[k]
        action = draw(st.sampled_from(["nudge"] * 5 + ["replace", "raw", "delete", "add"]))
        if action == "nudge":  # a plausible number: most such scenes load, and reach the geometry
            if isinstance(parent[where[-1]], (int, float)) and not isinstance(parent[where[-1]], bool):
                parent[where[-1]] = draw(st.one_of(st.integers(-12, 12), st.floats(-12, 12),
                                                   st.sampled_from([1e-300, 5e-324, 2.0**-400, 1e7 + 0.5])))
        elif action == "delete":
            del parent[where[-1]]
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["zz", "holes", "radius", "center", "theta", "seed", "x"]))] = draw(VALUE)
        elif action == "raw":
            parent[where[-1]] = _Raw(draw(RAW))
        else:
            parent[where[-1]] = draw(VALUE)
    return toml_document(doc)


@st.composite
def scenario_bytes(draw) -> bytes:
    base = open(os.path.join(ROOT, "scenarios", "basic.toml"), "rb").read()
    how = draw(st.sampled_from(["document", "document", "document", "bytes", "random", "bom", "utf16", "empty"]))
    if how == "document":
        return draw(mutated_document()).encode("utf-8")
    if how == "bytes":
        return mutate_bytes(base, draw)
    if how == "random":
        return draw(st.binary(max_size=300))
    if how == "bom":
        return b"\xef\xbb\xbf" + base
    if how == "utf16":
        return base.decode("utf-8").encode(draw(st.sampled_from(["utf-16", "utf-16-le", "utf-32"])))
    return b""


# ------------------------------------------------------------------ the loader


@budget(25)
@given(data=scenario_bytes())
def test_fuzz_scenario_files(data):
    with workdir() as d:
        f = os.path.join(d, "s.toml")
        with open(f, "wb") as fh:
            fh.write(data)
        check_case(["show", f], d, [f], "scenario files")


@budget(8)
@given(data=scenario_bytes(), planner=st.sampled_from(["exact", "RRTConnect"]))
def test_fuzz_scenario_files_planned(data, planner):
    with workdir() as d:
        f = os.path.join(d, "s.toml")
        with open(f, "wb") as fh:
            fh.write(data)
        check_case(["plan", f, "--planner", planner, "--time", "0.2", "--json", os.path.join(d, "r.json")], d, [f],
                   "scenario files planned", json_out=os.path.join(d, "r.json"))


# ------------------------------------------------------------------ options and output paths

OUTPUT_KINDS = ["new", "new", "existing", "empty", "input", "link to input", "hard link to input", "folder",
                "under a file", "missing folder", "proc", "fifo", "dangling link", "link to file", "long name",
                "newline", "nul byte", "dot", "same as other output"]
NUMBERS = ["0", "-1", "1", "0.05", "nan", "inf", "-inf", "1e300", "1e-300", "abc", "", "9" * 5000,
           str(2**64), str(2**63), str(2**32 - 2), str(2**32 - 1), "0x10", " 1", "1e", "-0"]


def output_path(kind: str, d: str, scene: str, ext: str, other: str | None, tag: str = "") -> str:
    """An output path of the given hostile kind, set up in folder d (``tag`` keeps two options apart)."""
    if kind not in ("input", "empty", "folder", "proc", "dot", "same as other output"):
        d = os.path.join(d, tag) if tag else d
        os.makedirs(d, exist_ok=True)
    if kind == "new":
        return os.path.join(d, "out" + ext)
    if kind == "existing":
        p = os.path.join(d, "old" + ext)
        with open(p, "w") as fh:
            fh.write("previous\n")
        return p
    if kind == "empty":
        return ""
    if kind == "input":
        return scene
    if kind == "link to input":
        p = os.path.join(d, "in-link" + ext)
        os.symlink(scene, p)
        return p
    if kind == "hard link to input":
        p = os.path.join(d, "in-hard" + ext)
        os.link(scene, p)
        return p
    if kind == "folder":
        return d
    if kind == "under a file":
        return os.path.join(scene, "x" + ext)
    if kind == "missing folder":
        return os.path.join(d, "no", "x" + ext)
    if kind == "proc":
        return "/proc/cspace-fuzz" + ext
    if kind == "fifo":
        p = os.path.join(d, "pipe" + ext)
        os.mkfifo(p)
        return p
    if kind == "dangling link":
        p = os.path.join(d, "dangling" + ext)
        os.symlink(os.path.join(d, "target" + ext), p)
        return p
    if kind == "link to file":
        target = os.path.join(d, "real" + ext)
        with open(target, "w") as fh:
            fh.write("old\n")
        p = os.path.join(d, "link" + ext)
        os.symlink(target, p)
        return p
    if kind == "long name":
        return os.path.join(d, "n" * 300 + ext)
    if kind == "newline":
        return os.path.join(d, "a\nb" + ext)
    if kind == "nul byte":
        return os.path.join(d, "a\0b" + ext)
    if kind == "dot":
        return "."
    return other or os.path.join(d, "out" + ext)


@budget(25)
@given(cmd=st.sampled_from(["plan", "show"]), json_kind=st.sampled_from(OUTPUT_KINDS + ["new"] * 6 + [None] * 6),
       plot_kind=st.sampled_from(OUTPUT_KINDS + [None] * 12),
       plot_ext=st.sampled_from([".svg", ".png", ".gif", ""]), json_ext=st.sampled_from([".json", ".toml", ""]),
       seed=st.sampled_from(NUMBERS + ["3", "7"] * 4 + [None] * 12),
       time_=st.sampled_from(NUMBERS + ["0.2", "0.05"] * 4 + [None] * 12),
       planner=st.sampled_from(["exact", "RRTConnect", "rrtconnect", "", "NoSuch", None, None]),
       extra=st.sampled_from([[], [], ["--no-simplify"], ["--all-queries"], ["--iterations", "0"],
                              ["--iterations", "50"], ["--bogus"], ["--seed"]]))
def test_fuzz_options_and_outputs(cmd, json_kind, plot_kind, plot_ext, json_ext, seed, time_, planner, extra):
    with workdir() as d:
        scene = os.path.join(d, "s.toml")
        shutil.copy(os.path.join(ROOT, "scenarios", "basic.toml"), scene)
        argv = [cmd, scene]
        json_out = output_path(json_kind, d, scene, json_ext, None) if json_kind else None
        if json_out is not None:
            argv += ["--json", json_out]
        if plot_kind:
            argv += ["--plot", output_path(plot_kind, d, scene, plot_ext, json_out, tag="p")]
        if cmd == "plan":
            for opt, v in (("--seed", seed), ("--time", time_), ("--planner", planner)):
                if v is not None:
                    argv += [opt, v]
            argv += extra
        code = check_case(argv, d, [scene], "options and outputs", json_out=json_out)
        if json_kind in ("input", "link to input", "hard link to input"):
            assert code == 2  # refused: the input survives (checked above)
        if json_kind == "fifo" and code == 2:
            pass  # no reader: refused, not waited on


@budget(8)
@given(kind=st.sampled_from(["random", "maze", "narrow", "disks", "office", "nope"]),
       seed=st.sampled_from(["0", "1", "-1", str(2**64), "abc"] + ["2", None] * 4),
       size=st.sampled_from(["1", "3", "0", "-5", "100000000", "abc"] + ["2", None] * 4),
       ratio=st.sampled_from(["1.001", "0.5", "0", "-1", "nan", "inf", "1e300", "7", "7.5"] + ["1.2", None] * 5),
       out_kind=st.sampled_from(["new"] * 8 + ["existing", "empty", "folder", "under a file", "proc",
                                              "dangling link", "link to file", "missing folder"]),
       ext=st.sampled_from([".toml"] * 4 + [".json", ""]))
def test_fuzz_generate(kind, seed, size, ratio, out_kind, ext):
    if kind in ("random", "disks", "maze", "office") and size not in ("1", "3"):
        size = None if size is None else size  # large valid sizes are refused or small: keep the case fast
        if size is None:
            size = "3"
    with workdir() as d:
        keep = os.path.join(d, "keep.toml")
        with open(keep, "w") as fh:
            fh.write("x = 1\n")
        argv = ["generate", kind, "--out", output_path(out_kind, d, keep, ext, None)]
        for opt, v in (("--seed", seed), ("--size", size), ("--ratio", ratio)):
            if v is not None:
                argv += [opt, v]
        check_case(argv, d, [keep], "generate")


def test_zz_report():
    """Write the run's figures where CSPACE_FUZZ_REPORT says (the large run's summary)."""
    path = os.environ.get("CSPACE_FUZZ_REPORT")
    if path:
        rep = {**STATS, "exit": dict(STATS["exit"]), "by_test": dict(STATS["by_test"]),
               "examples_per_test": EXAMPLES or "default"}
        with open(path, "w") as fh:
            json.dump(rep, fh, indent=1)
    assert STATS["exit"].get("3", 0) == 0
