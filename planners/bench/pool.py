"""Forked children: bench runs isolated from the process that holds the C-spaces, and
planners run under a wall-clock guard (:func:`call_in_child`).

A run must not take the sweep down (a planner may segfault, abort or hang), so each
run is a child process. Starting a fresh interpreter and rebuilding the C-space cost
about half a second per run; here the bench process loads every scenario and builds
its C-space once, then forks a child per run: the child inherits the built C-space
(copy-on-write), plans, writes its row on a pipe and exits. The parent is one thread
waiting on the children's pipes with ``select`` (no thread pool: forking a threaded
process is unsafe), so:

- the per-run hard limit is a deadline in that loop (no ``signal.alarm``): a child
  past it is killed and its row is ``timeout``;
- a child that dies by a signal or exits without a row is ``crashed``;
- children die with the bench: each holds the read end of a "lifeline" pipe whose
  only write end is the parent's; when the parent dies (even by ``kill -9``), the
  read ends in EOF and the child exits (on Linux the kernel also sends SIGKILL,
  ``PR_SET_PDEATHSIG``);
- children ignore SIGINT: Ctrl-C reaches the parent, which kills them.

Where ``os.fork`` does not exist (Windows), :mod:`planners.bench` falls back to a
fresh process per run (:func:`planners.bench.isolated_run`).
"""
from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time

from ..children import CAN_FORK, kill_child  # noqa: F401  (CAN_FORK: the sweep asks here)
from .arena_file import close_claims_in_child

_TAIL = 4000  # bytes of a child's stderr kept for the crash message


def run_forked(tasks: list[dict], held: dict, workers: int, limit, on_row) -> None:
    """Run ``tasks`` in forked children, at most ``workers`` at a time.

    ``held`` maps a task's ``file`` to ``(scenario, cspace)``; ``limit(task)`` gives the
    hard limit in seconds; ``on_row(task, row, wall)`` receives each finished run's row
    (``status`` ok, crashed or timeout). KeyboardInterrupt kills the running children
    and propagates.
    """
    from .rows import run_one

    life_r, life_w = os.pipe()
    pending = list(reversed(tasks))
    running: dict[int, dict] = {}
    try:
        while pending or running:
            while pending and len(running) < workers:
                task = pending.pop()
                running.update(_spawn(task, held, run_one, life_r, life_w, limit(task)))
            _wait(running, on_row)
    except BaseException:
        for pid in list(running):
            kill_child(pid)
        raise
    finally:
        os.close(life_r)
        os.close(life_w)


def _spawn(task, held, run_one, life_r, life_w, limit) -> dict:
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_IGN)  # the parent ends its children (SIGTERM is its Ctrl-C)
            close_claims_in_child()  # the campaign's claim on its database stays the parent's
            os.close(life_w)
            os.close(out_r)
            os.close(err_r)
            os.dup2(err_w, 2)
            import faulthandler

            faulthandler.disable()  # a crash is reported by its signal, not by a traceback dump
            _die_with_parent(life_r, parent)
            sc, cs = held[task["file"]]
            try:
                row = run_one(task, sc, cs)
            except Exception as exc:  # a Python error in the run: recorded, the sweep goes on
                row = {"status": "crashed", "message": f"{type(exc).__name__}: {exc}"}
            data = (json.dumps(row) + "\n").encode()
            while data:
                data = data[os.write(out_w, data):]
        finally:
            os._exit(0)  # no atexit handlers, no "nanobind: leaked" report
    os.close(out_w)
    os.close(err_w)
    now = time.perf_counter()
    return {pid: {"task": task, "out": out_r, "err": err_r, "buf": b"", "tail": b"", "t0": now,
                  "deadline": now + limit, "limit": limit, "open": {out_r, err_r}}}


def _wait(running: dict, on_row) -> None:
    """Read what the children wrote; finish those at EOF or past their deadline."""
    now = time.perf_counter()
    timeout = max(0.0, min(r["deadline"] for r in running.values()) - now)
    fds = {fd: pid for pid, r in running.items() for fd in r["open"]}
    ready, _, _ = select.select(list(fds), [], [], min(timeout, 0.5))
    for fd in ready:
        pid = fds[fd]
        r = running[pid]
        chunk = os.read(fd, 65536)
        if chunk:
            if fd == r["out"]:
                r["buf"] += chunk
            else:
                r["tail"] = (r["tail"] + chunk)[-_TAIL:]
        else:
            os.close(fd)
            r["open"].discard(fd)
    now = time.perf_counter()
    for pid in list(running):
        r = running[pid]
        if not r["open"]:
            _, status = os.waitpid(pid, 0)
            del running[pid]
            on_row(r["task"], _row(r, status), now - r["t0"])
        elif now >= r["deadline"]:
            kill_child(pid)
            for fd in r["open"]:
                os.close(fd)
            del running[pid]
            on_row(r["task"], {"status": "timeout", "message": f"killed after {r['limit']:g} s"}, now - r["t0"])


def _row(r: dict, status: int) -> dict:
    lines = [ln for ln in r["buf"].decode(errors="replace").splitlines() if ln.strip()]
    if lines and os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0:
        try:
            return json.loads(lines[-1])
        except ValueError:
            pass
    how = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"exit code {os.WEXITSTATUS(status)}"
    tail = r["tail"].decode(errors="replace").strip().splitlines()
    return {"status": "crashed", "message": f"child died ({how})" + (f": {tail[-1][:200]}" if tail else "")}


def _die_with_parent(life_r: int, parent: int) -> None:  # pragma: no cover - the child
    """End this child when the bench process ends, however it ends."""
    import threading

    if sys.platform.startswith("linux"):
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:  # the parent died before the call above
        os._exit(1)

    def watch() -> None:
        while os.read(life_r, 1):  # nobody writes: returns b"" (EOF) once the parent is gone
            pass
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


# ---------------------------------------------------------------- without fork: a fresh process per run

def isolated_run(task: dict, limit: float | None = None) -> dict | None:
    """Run one task in a fresh child process; the row records ``ok``, ``crashed`` or ``timeout``.

    A child that dies by a signal, exits without a row or raises is ``crashed``; one
    still running after ``limit`` seconds (default :func:`hard_limit`) is killed and is
    ``timeout``. Returns None if the sweep was interrupted meanwhile.
    """
    from .rows import MARK, complete_row, hard_limit, live_children, stop_event

    limit = hard_limit(task["time_budget"]) if limit is None else limit
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the repository
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [root, os.environ.get("PYTHONPATH")])))
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", "from planners.bench.pool import child_main; child_main()"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=env, start_new_session=True, text=True)
    live_children.add(proc)
    try:
        out, err = proc.communicate(json.dumps({**task, "hard_limit": limit}), timeout=limit)
        status = None
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        status = "timeout"
    finally:
        live_children.discard(proc)
    if stop_event.is_set():
        return None
    wall = time.perf_counter() - t0
    row = None
    for line in (out or "").splitlines():
        if line.startswith(MARK):
            row = json.loads(line[len(MARK):])
    if status == "timeout":
        row = {"status": "timeout", "message": f"killed after {limit:g} s"}
    elif row is None:
        code = proc.returncode
        how = f"signal {-code}" if code < 0 else f"exit code {code}"
        tail = (err or "").strip().splitlines()
        row = {"status": "crashed", "message": f"child died ({how})" + (f": {tail[-1][:200]}" if tail else "")}
    return complete_row(task, row, wall)


def child_main() -> None:  # pragma: no cover - runs in the child process
    """Entry of a child process: task JSON on stdin, one marked row line on stdout."""
    import signal

    from .rows import MARK, run_one

    task = json.loads(sys.stdin.read())
    if hasattr(signal, "alarm"):  # a backstop only: the parent kills us at the hard limit
        signal.alarm(int(task["hard_limit"]) + 5)
    try:
        row = run_one(task)
    except Exception as exc:  # a Python error in the run: recorded, the sweep goes on
        row = {"status": "crashed", "message": f"{type(exc).__name__}: {exc}"}
    sys.stdout.write(MARK + json.dumps(row) + "\n")
    sys.stdout.flush()
    os._exit(0)  # skip the bindings' "nanobind: leaked" report at exit
