"""Helpers shared by the bench scripts (they are scripts, not a package: each puts this
folder on ``sys.path`` before importing it)."""
from __future__ import annotations

import json
import os
import statistics
import sys
import time


def median_time(fn, reps: int) -> float:
    """Median wall seconds of ``fn()`` over ``reps`` calls.

    >>> median_time(lambda: None, 3) >= 0
    True
    """
    out = []
    for _ in range(reps):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return statistics.median(out)


def coal_peer(wanted: bool) -> bool:
    """Whether the OMPL + coal peer runs: ``wanted`` and coal importable (a line says why not).

    >>> coal_peer(False)
    False
    """
    import importlib.util

    if not wanted:
        return False
    if importlib.util.find_spec("coal") is None:
        print("coal is not installed (pip install coal, or the bench extra): the peer is skipped")
        return False
    return True


def check_out(path: str | None, inputs=(), option: str = "--json", suffixes: dict | None = None,
              folder: bool = False) -> str:
    """Before any work: refuse an output ``path`` given as ``option`` that names one of the run's
    ``inputs`` (files, or folders standing for every file in them: the bundled scenarios' folder,
    another project's checkout), a folder, an unwritable place, or (with ``suffixes``, e.g.
    :data:`planners.output.PLOT_FORMATS`) an extension not among them, in one line, exit 2
    (:func:`planners.output.check_output`, the CLI's own check); returns the format for plots.
    With ``folder`` the output is a folder: created if missing, and writable
    (:func:`planners.output.check_folder`). ``None`` is no output.

    >>> check_out(None), check_out("out.json"), check_out("fig.svg", (), "--plot", {".svg": "svg"})
    ('', '', 'svg')
    """
    if path is None:
        return ""
    from planners.output import check_folder, check_output

    files = []
    for p in inputs:
        files += [os.path.join(p, f) for f in sorted(os.listdir(p))] if os.path.isdir(p) else [p]
    if folder:
        return _refused(check_folder, path, option) or ""
    return _refused(check_output, path, option, suffixes, files)


def check_distinct(outputs) -> None:
    """Before any work: refuse two options naming one output file (``[(path, option), ...]``,
    None and '' skipped; :func:`planners.output.check_distinct`), in one line, exit 2.

    >>> check_distinct([("a.json", "--out-json"), ("a.png", "--plot"), ("", "--csv")])
    """
    from planners.output import check_distinct as check

    _refused(check, outputs)


def _refused(check, *args):
    """``check(*args)``; its :class:`planners.errors.InputError` is one line on stderr, exit 2."""
    from planners.errors import InputError

    try:
        return check(*args)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        raise SystemExit(2) from None


def check_json(path: str | None, inputs=(), option: str = "--json") -> None:
    """:func:`check_out` for a bench's JSON figures (``--json``, ``--out-json``).

    >>> check_json(None), check_json("out.json")
    (None, None)
    """
    check_out(path, inputs, option)


def write_json(path: str, data, option: str = "--json", default=None) -> None:
    """Write a bench's figures as JSON, atomically (:func:`planners.output.atomic_path`): a run
    stopped half-way leaves the old file, never half a new one (``default``: as ``json.dump``'s)."""
    from planners.output import atomic_path

    with atomic_path(path, option) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1, default=default)


def _clock(s: float) -> str:
    """``75.0`` -> ``1m15s``; under a minute, seconds.

    >>> _clock(75.0), _clock(9.4), _clock(3725)
    ('1m15s', '9s', '62m05s')
    """
    s = int(round(s))
    return f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s"


class Progress:
    """What a long benchmark runs and how far it has got, on stderr (the tables stay on stdout).

    At once: ``what``, the number of steps and, with ``most_s`` (the longest one step may take),
    the longest the whole can take. Then, at most every ``every`` seconds of wall time, a line
    with the steps done, the time so far and an estimate of the time left (from the mean step).

    >>> import io
    >>> out = io.StringIO()
    >>> p = Progress("demo: 2 scenes x 2 seeds", 4, most_s=10, every=0, stream=out)
    >>> for k in range(4):
    ...     p.step(f"scene {k}")
    >>> lines = out.getvalue().splitlines()
    >>> lines[0]
    'demo: 2 scenes x 2 seeds: 4 runs, each at most 10s (at most 40s in all)'
    >>> lines[1].startswith("  1/4 runs,"), lines[-1].startswith("  4/4 runs,"), len(lines)
    (True, True, 5)
    """

    def __init__(self, what: str, total: int, most_s: float | None = None, every: float = 10.0,
                 unit: str = "runs", stream=None):
        import sys

        self.total, self.every, self.unit = total, every, unit
        self.stream = stream if stream is not None else sys.stderr
        self.done = 0
        self.t0 = self.last = time.perf_counter()
        bound = f", each at most {_clock(most_s)} (at most {_clock(most_s * total)} in all)" if most_s else ""
        self._say(f"{what}: {total} {unit}{bound}")

    def _say(self, line: str) -> None:
        self.stream.write(line + "\n")
        self.stream.flush()

    def step(self, label: str = "") -> None:
        """One step done (``label``: what it was, shown on the progress line)."""
        self.done += 1
        now = time.perf_counter()
        if now - self.last >= self.every or self.done == self.total:
            self.last = now
            spent = now - self.t0
            left = spent / self.done * (self.total - self.done)
            self._say(f"  {self.done}/{self.total} {self.unit}, {_clock(spent)} so far, about {_clock(left)} left"
                      + (f" (last: {label})" if label else ""))
