"""Fuzzing the scenario loader and the command line against the promises (issue 24 item 9).

Every case runs ``planners.cli.main`` in this process (no subprocess per case) and
checks what the README promises for any input whatsoever:

- the exit status is 0, 1 or 2 (never 3, an internal error, nor a crash);
- exit 2 prints exactly one short line, ``error: ...``, and no traceback;
- the input file is unchanged, byte for byte;
- no temporary file is left behind (``.cspace-tmp-*``, ``.tmp-*``);
- a written JSON output is complete, valid JSON;
- each case ends within a bound (a hang detector: SIGALRM, far above normal times).

The budget is small in CI (a few seconds); set ``CSPACE_FUZZ_EXAMPLES=N`` for N
examples per test, e.g. ``CSPACE_FUZZ_EXAMPLES=3500 pytest tests/test_fuzz_cli.py``
for a run of more than 10 000 cases, and ``CSPACE_FUZZ_REPORT=FILE`` for its figures
(cases, exit codes, slowest case) as JSON.
"""
from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
import signal
import stat
import tempfile
import time
from collections import Counter

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from planners.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = int(os.environ.get("CSPACE_FUZZ_EXAMPLES", "0") or 0)
HANG_SECONDS = 120  # a hang detector, not a speed test: normal cases take milliseconds
STATS: dict = {"cases": 0, "exit": Counter(), "slowest_s": 0.0, "slowest": "", "by_test": Counter(), "seconds": 0.0}


def budget(small: int):
    return settings(max_examples=EXAMPLES or small, deadline=None, derandomize=not EXAMPLES,
                    suppress_health_check=list(HealthCheck))


# ------------------------------------------------------------------ running one case


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang(f"a case ran past {HANG_SECONDS} s")


def check_case(argv: list, folder: str, inputs: list, label: str, json_out: str | None = None) -> int:
    """Run ``cspace ARGV`` in-process and assert every promise; returns the exit status."""
    before = {p: _digest(p) for p in inputs}
    out, err = io.StringIO(), io.StringIO()
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_SECONDS)
    t0 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse's one-line errors exit here
                code = exc.code
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    dt = time.perf_counter() - t0
    _record(label, code, dt, argv)
    text = err.getvalue()
    assert code in (0, 1, 2), f"exit {code} for {_short(argv)}: {text[-500:]}"
    assert "Traceback" not in text and "internal error" not in text, text[-500:]
    if code == 2:
        lines = text.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), f"{_short(argv)}: {text[-500:]}"
        assert len(lines[0]) <= 600, f"{len(lines[0])} characters: {lines[0][:200]}"
    for p, h in before.items():
        assert _digest(p) == h, f"input {p} changed by {_short(argv)}"
    left = [n for _, _, names in os.walk(folder) for n in names if n.startswith((".cspace-tmp-", ".tmp-"))]
    assert not left, f"temporaries left: {left}"
    if code in (0, 1) and json_out and os.path.isfile(json_out) and not os.path.islink(json_out):
        with open(json_out, encoding="utf-8") as fh:
            json.load(fh)  # complete and valid
    return code


def _digest(p: str):
    try:
        st_ = os.lstat(p)
    except OSError:
        return None
    if not stat.S_ISREG(st_.st_mode):
        return ("special", stat.S_IFMT(st_.st_mode))
    with open(p, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _short(argv) -> str:
    return " ".join(repr(a)[:60] for a in argv)


def _record(label, code, dt, argv) -> None:
    STATS["cases"] += 1
    STATS["exit"][str(code)] += 1
    STATS["by_test"][f"{label}: exit {code}"] += 1
    STATS["seconds"] += dt
    if dt > STATS["slowest_s"]:
        STATS["slowest_s"], STATS["slowest"] = dt, _short(argv)[:300]


@contextlib.contextmanager
def workdir():
    d = tempfile.mkdtemp(prefix="cspace-fuzz-")
    try:
        yield d
    finally:
        shutil.rmtree(d, ignore_errors=True)


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


def _mutate_bytes(data: bytes, draw) -> bytes:
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(data)))
        kind = draw(st.sampled_from(["insert", "delete", "replace"]))
        chunk = draw(st.binary(min_size=1, max_size=8))
        if kind == "insert":
            data = data[:i] + chunk + data[i:]
        elif kind == "delete":
            data = data[:i] + data[i + len(chunk):]
        else:
            data = data[:i] + chunk + data[i + len(chunk):]
    return data


@st.composite
def scenario_bytes(draw) -> bytes:
    base = open(os.path.join(ROOT, "scenarios", "basic.toml"), "rb").read()
    how = draw(st.sampled_from(["document", "document", "document", "bytes", "random", "bom", "utf16", "empty"]))
    if how == "document":
        return draw(mutated_document()).encode("utf-8")
    if how == "bytes":
        return _mutate_bytes(base, draw)
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
