"""Progress on long work: one bar on stderr when a person is watching, nothing otherwise.

This module owns progress display for the command line: ``cspace stability`` (one step
per case), ``cspace generate`` and long ``exact`` searches (nodes settled by the A*
search) and ``cspace bench`` (one step per run). The bar is tqdm's, a small, pure-Python
and well-kept library, imported only when a bar is actually shown.

Silent unless stderr is a terminal (``enabled=None``), so logs, pipes and tests see
nothing; tqdm's own ``TQDM_DISABLE=1`` silences it on a terminal too. When tqdm is
not installed the bar is silently absent: progress is a courtesy, never a failure.
A ``delay`` hides the bar of work that ends quickly (tqdm shows it only after that
many seconds), so a 5 ms exact search never flickers a bar.
"""
from __future__ import annotations

import os
import sys
import time
from typing import Callable, Iterable, Iterator, TypeVar

T = TypeVar("T")

# Work that ends sooner than this (seconds) shows no bar: most exact searches and most
# generated scenes take milliseconds, and a bar that flickers for them is noise.
DELAY = 0.5
# Seconds between two redraws at most (keeps a fast loop from spending its time drawing).
MININTERVAL = 0.2
# Seconds between two redraws of a stage without steps (its name and a running clock).
TICK = 1.0
# An unknown-total bar before its first step: the stage it is in and a clock, not a "0node"
# that would not move while a long stage without steps (a C-space build) runs.
STAGE_FORMAT = "{desc} [{elapsed}]"


def enabled_default(stream=None) -> bool:
    """Whether a bar should be drawn on ``stream`` (stderr by default): a terminal, not disabled.

    >>> import io
    >>> enabled_default(io.StringIO())
    False
    """
    stream = sys.stderr if stream is None else stream
    if os.environ.get("TQDM_DISABLE", "").lower() in ("1", "true", "yes"):
        return False
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or fake stream
        return False


class Progress:
    """A progress bar as a context manager; every method is a no-op when disabled.

    ``total`` may be None (unknown: the bar counts and shows the rate), and may be set
    later by :meth:`set`. ``desc`` names the work; ``unit`` names one step.

    >>> with Progress(3, "cases", enabled=False) as bar:
    ...     for _ in range(3):
    ...         bar.update()
    >>> bar.n
    3
    """

    def __init__(self, total: int | None, desc: str, enabled: bool | None = None, unit: str = "it",
                 delay: float = 0.0, leave: bool = False, tick: float | None = None):
        self.n = 0
        self.total = total
        self._bar = None
        self._stop = self._ticker = None
        self._visible_at = time.monotonic() + delay  # a bar with a delay stays hidden until then
        if enabled is None:
            enabled = enabled_default()
        if not enabled:
            return
        try:
            from tqdm import tqdm
        except ImportError:  # the optional display is missing: stay silent
            return
        # dynamic_ncols follows the terminal's width; mininterval keeps redraws cheap.
        self._bar = tqdm(total=total, desc=desc, unit=unit, delay=delay, leave=leave, file=sys.stderr,
                         dynamic_ncols=True, mininterval=MININTERVAL,
                         bar_format=STAGE_FORMAT if total is None else None)
        if tick:
            self._start_ticker(delay, tick)

    def _start_ticker(self, delay: float, tick: float) -> None:
        """Redraw every ``tick`` seconds once ``delay`` has passed, so that a long stage
        without steps (a C-space build) still shows its name and a running clock."""
        import threading

        self._stop = stop = threading.Event()
        bar = self._bar

        def run() -> None:
            if stop.wait(delay):
                return
            while not stop.is_set():
                bar.refresh()
                stop.wait(tick)

        self._ticker = threading.Thread(target=run, name="progress-ticker", daemon=True)
        self._ticker.start()

    @property
    def shown(self) -> bool:
        """Whether a bar is being drawn (enabled, on a terminal, tqdm installed)."""
        return self._bar is not None

    def update(self, n: int = 1) -> None:
        """Advance by ``n`` steps."""
        self.n += n
        if self._bar is not None:
            if self.n and self._bar.bar_format is not None:  # the first step: counts from now on
                self._bar.bar_format = None
            self._bar.update(n)

    def set(self, done: int, total: int | None = None) -> None:
        """Jump to ``done`` steps (and set the total when it becomes known)."""
        if total is not None and total != self.total:
            self.total = total
            if self._bar is not None:
                self._bar.total = total
        self.update(done - self.n)

    def reset(self, total: int | None = None) -> None:
        """Start counting again from 0 (a new stage of the same work)."""
        self.n, self.total = 0, total
        if self._bar is not None:
            if self._bar.total is None and total is None:  # no steps yet: the stage's name again
                self._bar.bar_format = STAGE_FORMAT
            self._bar.reset(total=total)  # which draws the bar, even within its delay:
            if time.monotonic() < self._visible_at:
                self._bar.clear()  # erased at once (work that ends quickly shows no bar)

    def describe(self, desc: str) -> None:
        """Change the name of the work shown before the bar (a new stage)."""
        if self._bar is not None:
            # Shown at once once the bar is visible: a stage may last long without a step.
            self._bar.set_description_str(desc, refresh=time.monotonic() >= self._visible_at)

    def note(self, text: str) -> None:
        """A short note after the counts (the current item, a bound)."""
        if self._bar is not None:
            self._bar.set_postfix_str(text, refresh=False)

    def write(self, line: str) -> None:
        """One line on stderr that does not break the bar (printed only when the bar is shown)."""
        if self._bar is not None:
            self._bar.write(line, file=sys.stderr)

    def close(self) -> None:
        """Remove the bar (or leave its last state, with ``leave=True``), so that the next
        line written starts on a line of its own."""
        if self._stop is not None:
            self._stop.set()
            self._ticker.join(1.0)  # no redraw after the bar is cleared
        if self._bar is not None:
            bar = self._bar
            if time.monotonic() >= self._visible_at:
                # tqdm clears (or ends with a newline) only a bar it drew in update(); the ticker's
                # and describe()'s redraws are not counted, which left the bar on the line.
                bar.last_print_t = max(bar.last_print_t, bar.start_t + bar.delay)
            bar.close()
            self._bar = None

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def progress(total: int | None, desc: str, enabled: bool | None = None, **kw) -> Progress:
    """A :class:`Progress` bar (a context manager); ``enabled`` defaults to stderr being a terminal.

    >>> with progress(2, "work", enabled=False) as bar:
    ...     bar.update(2)
    >>> bar.n, bar.shown
    (2, False)
    """
    return Progress(total, desc, enabled=enabled, **kw)


def track(items: Iterable[T], desc: str, total: int | None = None, enabled: bool | None = None,
          **kw) -> Iterator[T]:
    """Iterate over ``items`` with a bar; the bar is removed when the loop ends or breaks.

    >>> list(track([1, 2, 3], "numbers", enabled=False))
    [1, 2, 3]
    """
    if total is None and hasattr(items, "__len__"):
        total = len(items)  # type: ignore[arg-type]
    with Progress(total, desc, enabled=enabled, **kw) as bar:
        for item in items:
            yield item
            bar.update()


def search_reporter(bar: Progress, desc: str | None = None) -> Callable[[int, int, float], None]:
    """A callback for :func:`cspace.paths.shortest.shortest_path`'s ``on_progress``.

    The search calls it with (nodes settled, nodes in the graph, lower bound on the
    length): A* settles nodes in order of f = g + h, and with a consistent heuristic
    the f of the last settled node never exceeds the shortest length, so the bar shows
    a bound that only rises towards the answer. The graph's size is shown but is not
    the bar's total: A* usually stops long before settling every node, so a
    percentage and an estimated time left would mislead.

    ``desc``, when given, names the stage once the first report comes (the search
    itself, after a preparation the bar named before).

    >>> bar = progress(None, "search", enabled=False)
    >>> search_reporter(bar)(10, 40, 3.5)
    >>> bar.n, bar.total
    (10, None)
    """

    def report(settled: int, nodes: int, bound: float) -> None:
        if desc is not None and bar.n == 0:
            bar.describe(desc)
        bar.note(f"of {nodes}; length >= {bound:.6g}")  # before the step, which redraws
        bar.set(settled)

    return report


class BenchBar:
    """Drop-in for ``planners.bench``'s progress line: ``BenchBar(total, enabled)``, ``.step(row)``, ``.close()``.

    ``enabled`` is the bench's own switch (false with ``--quiet``); the bar is drawn
    only when stderr is also a terminal. A run that crashed or overran its hard limit
    is worth a line of its own even in a log, so those (and only those) are written
    when the bar is not shown; the sweep's summary follows in any case.

    >>> bar = BenchBar(2, enabled=False)
    >>> bar.step({"scenario": "s", "planner": "P", "time_budget": 0.1, "seed": 0, "status": "ok"})
    >>> bar.n, bar.bad
    (1, 0)
    >>> bar.close()
    """

    def __init__(self, total: int, enabled: bool):
        self.total, self.enabled, self.n, self.bad = total, enabled, 0, 0
        self._bar = Progress(total, "bench", enabled=enabled and enabled_default(), unit="run", leave=True)

    def step(self, row: dict) -> None:
        """One finished run (a result row of the bench)."""
        self.n += 1
        ok = row.get("status") == "ok"
        self.bad += not ok
        what = f"{row['scenario']} {row['planner']} {row['time_budget']:g}s seed {row['seed']}"
        if not ok and self.enabled:
            line = f"bench: {what}: {row.get('status')}"
            if self._bar.shown:
                self._bar.write(line)
            else:
                sys.stderr.write(line + "\n")
                sys.stderr.flush()
        self._bar.note(what + (f" ({self.bad} crashed/timeout)" if self.bad else ""))
        self._bar.update()

    def close(self) -> None:
        """End the bar (its last state stays on the terminal above the summary)."""
        self._bar.close()


_Bar = BenchBar  # the name the task brief uses
_Progress = BenchBar  # the name of the class it replaces in planners/bench.py
