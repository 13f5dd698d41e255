"""Forked children: a call run in a child process under a wall-clock guard.

The planning routine runs the one planner that has no time check of its own (AORRTC)
through :func:`call_in_child`, and the bench forks a child per run
(:mod:`planners.bench.pool`); both end a child with :func:`kill_child`. Where
``os.fork`` does not exist (Windows), ``CAN_FORK`` is false and callers run in process.
"""
from __future__ import annotations

import contextlib
import os
import select
import signal
import sys
import time


CAN_FORK = hasattr(os, "fork") and sys.platform != "win32"


def kill_child(pid: int) -> None:
    """SIGKILL a child and reap it (gone already: nothing to do)."""
    try:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ProcessLookupError, ChildProcessError):
        pass


def call_in_child(fn, limit: float):
    """``fn()`` in a forked child, killed past ``limit`` seconds of wall clock.

    Returns ``(True, result)`` (the result pickled back), ``(False, "timeout")``, or
    ``(False, reason)`` if the child died or raised. KeyboardInterrupt in the parent
    kills the child and propagates (the child ignores SIGINT).
    """
    import pickle

    out_r, out_w = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_IGN)  # the parent ends its children (SIGTERM is its Ctrl-C)
            os.close(out_r)
            try:
                data = pickle.dumps((True, fn()))
            except Exception as exc:
                data = pickle.dumps((False, f"{type(exc).__name__}: {exc}"))
            while data:
                data = data[os.write(out_w, data):]
        finally:
            os._exit(0)
    os.close(out_w)
    buf, deadline = b"", time.perf_counter() + limit
    try:
        while True:
            left = deadline - time.perf_counter()
            if left <= 0:
                kill_child(pid)
                return False, "timeout"
            ready, _, _ = select.select([out_r], [], [], min(left, 0.5))
            if ready:
                chunk = os.read(out_r, 65536)
                if not chunk:
                    break
                buf += chunk
        _, status = os.waitpid(pid, 0)
    except BaseException:
        kill_child(pid)
        raise
    finally:
        os.close(out_r)
    if buf:
        with contextlib.suppress(Exception):
            return pickle.loads(buf)
    how = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"exit code {os.WEXITSTATUS(status)}"
    return False, f"child died ({how})"
