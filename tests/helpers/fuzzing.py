"""The fuzzing contract (issues 24 item 9 and 36), shared by the fuzz tests of the command line
(tests/cli/test_fuzz_cli.py) and of the imported maps and meshes (tests/io/test_fuzz_maps.py,
tests/io/test_fuzz_meshes.py).

Every case runs ``planners.cli.main`` in this process (no subprocess per case) and
:func:`check_case` checks what the README promises for any input whatsoever:

- the exit status is 0, 1 or 2 (never 3, an internal error, nor a crash);
- exit 2 prints exactly one short line, ``error: ...``, and no traceback (an import's
  ``warning:`` lines may come before it);
- the input file is unchanged, byte for byte;
- no temporary file is left behind (``.cspace-tmp-*``, ``.tmp-*``);
- a written JSON output is complete, valid JSON;
- each case ends within a bound (a hang detector: SIGALRM, far above normal times).

``CSPACE_FUZZ_EXAMPLES=N`` sets the examples per test (:data:`EXAMPLES`); :data:`STATS` holds
the figures of every case run in this process (the ``test_zz_*`` tests write them where
``CSPACE_FUZZ_REPORT`` says). With ``CSPACE_FUZZ_KEEP=FOLDER`` a case run by :func:`run` that
breaks the contract does not stop the run: its files are copied to FOLDER and counted in
:data:`FAILURES`.
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

from hypothesis import HealthCheck, settings, strategies as st

from planners.cli import main

EXAMPLES = int(os.environ.get("CSPACE_FUZZ_EXAMPLES", "0") or 0)
HANG_SECONDS = 120  # a hang detector, not a speed test: normal cases take milliseconds
STATS: dict = {"cases": 0, "exit": Counter(), "slowest_s": 0.0, "slowest": "", "by_test": Counter(), "seconds": 0.0}
KEEP = os.environ.get("CSPACE_FUZZ_KEEP")
FAILURES: list = []  # (label, why, folder) of each kept case
FILES = {"map": 0, "mesh": 0}  # imported files written per input kind
LAST: dict = {"stderr": ""}  # the last case's stderr (for a test's own checks after check_case)


def budget(small: int):
    return settings(max_examples=EXAMPLES or small, deadline=None, derandomize=not EXAMPLES,
                    suppress_health_check=list(HealthCheck))


# ------------------------------------------------------------------ running one case


class Hang(Exception):
    pass


def _alarm(signum, frame):
    raise Hang(f"a case ran past {HANG_SECONDS} s")


def check_case(argv: list, folder: str, inputs: list, label: str, json_out: str | None = None,
               warnings: bool = False) -> int:
    """Run ``cspace ARGV`` in-process and assert every promise; returns the exit status.

    ``warnings``: an exit 2 may print ``warning:`` lines before its one ``error:`` line (an
    imported file's: ``cspace plan`` writes them once the import is done)."""
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
    text = LAST["stderr"] = err.getvalue()
    assert code in (0, 1, 2), f"exit {code} for {_short(argv)}: {text[-500:]}"
    assert "Traceback" not in text and "internal error" not in text, text[-500:]
    if code == 2:
        lines = text.strip().splitlines()
        if warnings:
            assert all(line.startswith("warning: ") for line in lines[:-1]), f"{_short(argv)}: {text[-500:]}"
            lines = lines[-1:]
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


def run(argv, folder, inputs, label, kind, json_out=None):
    """:func:`check_case` for imported files (``kind``: "map" or "mesh", counted in
    :data:`FILES`); under ``CSPACE_FUZZ_KEEP`` a broken contract keeps the case and goes on."""
    FILES[kind] += len(inputs)
    STATS.setdefault("files", {}).setdefault(kind, 0)
    STATS["files"][kind] += len(inputs)
    try:
        return check_case(argv, folder, inputs, label, json_out=json_out, warnings=True)
    except AssertionError as exc:
        if not KEEP:
            raise
        dest = os.path.join(KEEP, f"case-{len(FAILURES):04d}")
        shutil.copytree(folder, dest, symlinks=True, ignore_dangling_symlinks=True)
        with open(os.path.join(dest, "WHY.txt"), "w") as fh:
            fh.write(f"{argv!r}\n{exc}\n")
        FAILURES.append((label, str(exc)[:300], dest))
        return None


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


# ------------------------------------------------------------------ mutations


def mutate_bytes(data: bytes, draw) -> bytes:
    """One to four byte insertions, deletions or replacements (``draw``: hypothesis's)."""
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
