"""Regenerate (or check) the command outputs quoted in docs/guide.md.

    python scripts/make_guide_outputs.py            # check: list every quoted number that drifted
    python scripts/make_guide_outputs.py --write    # rewrite the quoted lines from fresh runs
    python scripts/make_guide_outputs.py --slow     # also the slow blocks (stability, bench)

A quoted output is a ```text block right after a marker line

    <!-- output: cspace plan scenarios/basic.toml --plot path.png [&& COMMAND ...] [| loose] [| slow] -->

The commands run in order in one temporary folder holding links to ``scenarios/`` and
``scripts/`` (so what they write never lands in the repository), stdout and stderr merged. Each
quoted line (``...`` lines are elisions) is matched with the first fresh line of the same *shape*:
the same text once every number is replaced by ``#``. Numbers followed by ``ms``, ``s`` or
``seconds`` are times: they agree when within a factor :data:`TIME_FACTOR` or both under
:data:`TIME_FLOOR_MS`. Other numbers (lengths, waypoints, counts, bytes) are deterministic with
the commands' seeds and must equal the fresh ones to the printed digits, unless the block is
marked ``loose`` (a time-limited anytime planner, a timed benchmark: only the shape is checked).
A quote with no ``...`` line is the whole output: a fresh line of a shape it lacks is drift.
``slow`` blocks run only with ``--slow`` (tests/project/test_docs_drift.py: ``CSPACE_DOCS_SLOW=1``).

``--write`` replaces each quoted line by its fresh match (numbers, times included, and wording
of the same shape); a quoted line whose shape no fresh line has is reported, to edit by hand.
Exit 1 when a check finds drift.
"""
from __future__ import annotations

import argparse
import os
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GUIDE = os.path.join(ROOT, "docs", "guide.md")
TIME_FACTOR = 10.0  # a shared, loaded 2-core machine: times agree within an order of magnitude
TIME_FLOOR_MS = 50.0  # below this both times are "instant" and agree
NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[+-]?\d+)?(?![\w.])")
TIME_UNIT = re.compile(r"\s*(ms|s|seconds)\b")
# Numbers quoted in the guide's prose, each checked against a marked block's fresh output:
# (text in the block's commands, regex of the fresh output, regex of the guide, kind). "value":
# equal to the guide's printed digits; "time": fresh milliseconds against the guide's seconds,
# within TIME_FACTOR.
PROSE = [
    ("basic.toml --plot path.png", r"solved by RRTConnect .*length ([\d.]+)",
     r"RRTConnect's simplified path is ([\d.]+) /", "value"),
    ("basic.toml --planner exact", r"solved by exact: length ([\d.]+)", r"/ ([\d.]+) − 1 ≈", "value"),
    ("--iterations 1000", r"length ([\d.]+)", r"gives length ([\d.]+) on every machine", "value"),
    ("circles.toml", r"queries solved, mean length ([\d.]+)", r"verified exactly\), mean length ([\d.]+)", "value"),
    ("circles.toml", r"queries solved, mean length ([\d.]+)", r"# \(100, ([\d.]+)\)", "value"),
    ("circles.toml", r"^total time: .*total ([\d.]+) ms", r"in about ([\d.]+) s for the whole\s+run", "time"),
]
MARKER = re.compile(r"^<!-- output: (.*?) -->\n```text\n(.*?)^```", re.S | re.M)


@dataclass
class Block:
    """One quoted output of the guide: its commands, flags, and lines (with their offset in the guide)."""

    commands: list[str]
    loose: bool
    slow: bool
    lines: list[str]
    start: int  # character offset of the block's body in the guide
    end: int
    line_no: int
    fresh: list[str] = field(default_factory=list)


def shape(line: str) -> str:
    """The line with every number replaced by '#'."""
    return re.sub(r"(?<=\S)\s+", " ", NUMBER.sub("#", line.rstrip()))  # column padding aside


def label(line: str) -> str | None:
    """The line's leading label up to its first colon ("time:", "query 0 time:"), or None."""
    m = re.match(r"([A-Za-z][\w -]{0,30}):\s", line)
    return m.group(1) if m else None


def to_ms(text: str, line: str, at: int) -> float:
    unit = TIME_UNIT.match(line, at).group(1)
    return float(text) * (1.0 if unit == "ms" else 1000.0)


def blocks(text: str | None = None) -> list[Block]:
    """The marked quoted outputs of the guide."""
    if text is None:
        with open(GUIDE, encoding="utf-8") as fh:
            text = fh.read()
    out = []
    for m in MARKER.finditer(text):
        head, *flags = [p.strip() for p in m.group(1).split("|")]
        out.append(Block(commands=[c.strip() for c in head.split("&&")], loose="loose" in flags, slow="slow" in flags,
                         lines=m.group(2).splitlines(), start=m.start(2), end=m.end(2),
                         line_no=text.count("\n", 0, m.start()) + 1))
    return out


def run(block: Block, timeout: float = 600) -> list[str]:
    """The fresh output lines of the block's commands (stdout and stderr merged), in a scratch folder."""
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""),
               MPLBACKEND="Agg", PYTHONUNBUFFERED="1", COLUMNS="200")
    lines = []
    with tempfile.TemporaryDirectory(prefix="cspace-guide-") as work:
        for name in ("scenarios", "scripts"):
            os.symlink(os.path.join(ROOT, name), os.path.join(work, name))
        for command in block.commands:
            argv = shlex.split(command)
            if argv[0] == "python":
                argv[0] = sys.executable
            proc = subprocess.run(argv, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  text=True, timeout=timeout)
            lines += proc.stdout.splitlines()
    block.fresh = lines
    return lines


def match(block: Block) -> list[tuple[str, str | None]]:
    """(quoted line, its fresh match or None) for each quoted line that is not an elision."""
    used: set[int] = set()
    pairs = []
    last = 0
    for q in block.lines:
        if q.strip() in ("...", ""):
            continue
        if q.startswith("    "):  # a result line indented under a table row: the fresh row's next line
            hit = last if last < len(block.fresh) and block.fresh[last].startswith("    ") else None
            if hit is not None:
                used.add(hit)
                last = hit + 1
            pairs.append((q, None if hit is None else block.fresh[hit]))
            continue
        want = shape(q)
        order = list(range(last, len(block.fresh))) + list(range(0, last))
        hit = next((i for i in order if i not in used and shape(block.fresh[i]) == want), None)
        if hit is None and label(q):  # reworded: the fresh line of the same label ("time:", "query 0 time:")
            hit = next((i for i in order if i not in used and label(block.fresh[i]) == label(q)), None)
        if hit is not None:
            used.add(hit)
            last = hit + 1
        pairs.append((q, None if hit is None else block.fresh[hit]))
    return pairs


def drift(block: Block) -> list[str]:
    """What differs between the quoted lines and the fresh run, one message per line (empty: none)."""
    problems = []
    for q, f in match(block):
        if f is None:
            problems.append(f"guide.md:{block.line_no}: no fresh line has the shape of {q!r}")
            continue
        if block.loose or q.startswith("    ") and shape(q) != shape(f):
            continue
        if shape(q) != shape(f):
            problems.append(f"guide.md:{block.line_no}: reworded: {q!r} is now {f!r}")
            continue
        qm, fm = list(NUMBER.finditer(q)), list(NUMBER.finditer(f))
        for a, b in zip(qm, fm):
            timed = TIME_UNIT.match(q, a.end()) is not None
            if timed:
                ta, tb = to_ms(a.group(), q, a.end()), to_ms(b.group(), f, b.end())
                if max(ta, tb) > TIME_FLOOR_MS and max(ta, tb) > TIME_FACTOR * max(min(ta, tb), 1e-9):
                    problems.append(f"guide.md:{block.line_no}: time {a.group()} now {b.group()} in {q!r}")
            elif a.group() != b.group():
                problems.append(f"guide.md:{block.line_no}: {a.group()} now {b.group()} in {q!r}")
    if not block.loose and "..." not in [q.strip() for q in block.lines]:  # a quote with no elision is whole
        quoted = {shape(q) for q in block.lines}
        problems += [f"guide.md:{block.line_no}: the run prints {f!r}, which the quote leaves out (or mark it ...)"
                     for f in block.fresh if f.strip() and shape(f) not in quoted]
    return problems


def prose_drift(text: str, done: list[Block]) -> list[str]:
    """The numbers of :data:`PROSE` that differ from the fresh runs (blocks not run are passed over)."""
    problems = []
    for key, fresh_re, guide_re, kind in PROSE:
        block = next((b for b in done if key in " && ".join(b.commands)), None)
        if block is None:
            continue
        g = re.search(guide_re, text)
        f = next((m for m in (re.search(fresh_re, line) for line in block.fresh) if m), None)
        if g is None or f is None:
            problems.append(f"guide.md: prose {guide_re!r}: {'not in the guide' if g is None else 'no fresh value'}")
            continue
        quoted, now = g.group(1), float(f.group(1))
        if kind == "time":
            ta, tb = float(quoted) * 1000.0, now
            if max(ta, tb) > TIME_FLOOR_MS and max(ta, tb) > TIME_FACTOR * max(min(ta, tb), 1e-9):
                problems.append(f"guide.md: prose time {quoted} s, now {now / 1000:.3g} s ({guide_re!r})")
        else:
            digits = len(quoted.partition(".")[2])
            if round(now, digits) != float(quoted):
                problems.append(f"guide.md: prose {quoted}, now {now:.{digits}f} ({guide_re!r})")
    return problems


def rewrite(text: str, done: list[Block]) -> str:
    """The guide with each run block's quoted lines replaced by their fresh matches."""
    for block in sorted(done, key=lambda b: -b.start):
        fresh = dict(match(block))
        body = "".join((fresh.get(q) or q) + "\n" for q in block.lines)
        text = text[:block.start] + body + text[block.end:]
    return text


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="rewrite the quoted lines of docs/guide.md")
    ap.add_argument("--slow", action="store_true", help="also the blocks marked slow (stability, bench)")
    ap.add_argument("--only", help="only the blocks whose commands contain this text")
    args = ap.parse_args(argv)
    with open(GUIDE, encoding="utf-8") as fh:
        text = fh.read()
    done, problems = [], []
    for block in blocks(text):
        if args.only and args.only not in " && ".join(block.commands):
            continue
        if block.slow and not args.slow:
            print(f"guide.md:{block.line_no}: skipped (slow; --slow runs it): {' && '.join(block.commands)}")
            continue
        run(block)
        done.append(block)
        found = drift(block)
        problems += found
        print(f"guide.md:{block.line_no}: {'drifted' if found else 'ok'}: {' && '.join(block.commands)}", flush=True)
    problems += prose_drift(text, done)  # reported, never rewritten: prose is edited by hand
    for p in problems:
        print("  " + p)
    if args.write:
        new = rewrite(text, done)
        if new != text:
            with open(GUIDE, "w", encoding="utf-8") as fh:
                fh.write(new)
            print("rewrote docs/guide.md's quoted outputs")
        unmatched = [p for p in problems if "no fresh line" in p]  # left as they were: edit by hand
        return 1 if unmatched else 0
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
