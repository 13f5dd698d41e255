"""``cspace bench --scheduler ADDRESS``: the sweep on a Dask distributed cluster.

Dask's scheduler costs about a millisecond per task, more than a short planning run's share,
so runs travel in batches (:func:`batches`): runs of one scenario, grouped until their summed
budgets reach :data:`BATCH_SECONDS`. A worker runs a batch with :func:`run_batch`: it loads the
scenario and builds its C-space once per worker process (a module-level cache keyed by the
scenario file's SHA-256, space and slab count), then forks a child per run as the local sweep
does (:func:`planners.bench.pool.run_forked`: a planner that crashes or hangs costs one row, not
the worker). The client (:func:`sweep_on_cluster`) takes batches as they finish
(``as_completed``) and hands each one's rows on at once (``cspace bench --db`` stores a batch in
one transaction).

A worker that dies mid-batch (killed, out of memory, a lost machine) loses its batch; the
scheduler runs it again on another worker (and ``retries`` covers a batch that raised). A batch
gives one result, so a row reaches the client once; the client also drops a row it already
has, and the database refuses a run it already holds, so a retried batch never doubles a row.

Every worker reads the scenario files at the path the client gave (a shared folder, or the
same checkout on every machine); a worker that finds another file there refuses the batch.
"""
from __future__ import annotations

import os

from ..errors import InputError

BATCH_SECONDS = 0.1  # summed time budget of one batch (at least)


RETRIES = 2  # a batch that raised (not a run that crashed: that is a row) is run again this often


_held: dict[tuple, tuple] = {}  # in a worker process: (sha256, space, slabs) -> (scenario, cspace)


_builds = [0]  # C-spaces this process built (the cache's test: never more than it holds)


def batches(tasks: list[dict], seconds: float = BATCH_SECONDS) -> list[list[dict]]:
    """Runs of one scenario (file, space, slabs), in task order, grouped until their summed budgets
    reach ``seconds`` (the last batch of a scenario may be shorter).

    >>> ts = [{"file": f, "space": None, "slabs": None, "time_budget": b} for f in "ab" for b in (0.03, 0.05, 0.1)]
    >>> [[(t["file"], t["time_budget"]) for t in b] for b in batches(ts)]
    [[('a', 0.03), ('a', 0.05), ('a', 0.1)], [('b', 0.03), ('b', 0.05), ('b', 0.1)]]
    >>> [len(b) for b in batches(ts, 0.05)]
    [2, 1, 2, 1]
    """
    groups: dict[tuple, list[list[dict]]] = {}
    for t in tasks:
        runs = groups.setdefault((t["file"], t.get("space"), t.get("slabs")), [[]])
        if sum(float(x["time_budget"]) for x in runs[-1]) >= seconds:
            runs.append([])
        runs[-1].append(t)
    return [b for runs in groups.values() for b in runs if b]


def held_scenario(file: str, sha: str, space: str | None, slabs: int | None) -> tuple:
    """``(scenario, cspace)`` of a scenario file, built once per process (the worker's cache)."""
    key = (sha, space, slabs)
    if key not in _held:
        from cspace.io.load import load_scenario

        from .arena_db import file_hash
        from .reference import warmed

        try:
            found = file_hash(file)
        except OSError as exc:
            raise RuntimeError(f"worker on {os.uname().nodename}: cannot read {file}: {exc}") from None
        if found != sha:
            raise RuntimeError(f"worker on {os.uname().nodename}: {file} is not the client's file "
                               "(different content)")
        sc = load_scenario(file, space=space)
        cs, _ = warmed(sc, slabs)  # as reference() leaves it
        _held[key] = (sc, cs)
        _builds[0] += 1
    return _held[key]


def clear_held() -> int:
    """Forget this process's C-spaces (benchmarks start each repeat cold); returns how many."""
    n = len(_held)
    _held.clear()
    _builds[0] = 0
    return n


def held_stats() -> tuple[int, int]:
    """``(C-spaces held, C-spaces built)`` in this process since it started or was cleared."""
    return len(_held), _builds[0]


def run_batch(batch: list[dict], sha: str) -> list[dict]:
    """On a worker: every run of one batch (one scenario), each in a forked child; the full rows."""
    from ..children import CAN_FORK
    from .pool import isolated_run, run_forked
    from .rows import complete_row, hard_limit

    t = batch[0]
    if not CAN_FORK:  # a fresh process per run (no C-space to share)
        return [isolated_run(task) for task in batch]
    from ..adapters.glue import ompl
    from ..core import plan  # noqa: F401  (imported once, before forking)

    ompl()
    sc_cs = held_scenario(t["file"], sha, t.get("space"), t.get("slabs"))
    rows: list[dict] = []
    run_forked(batch, {t["file"]: sc_cs}, 1, lambda task: hard_limit(task["time_budget"]),
               lambda task, row, wall: rows.append(complete_row(task, row, wall)))
    return rows


CONNECT_TIMEOUT = 10.0  # seconds for the connection and the scheduler's first words


DEFAULT_PORT = 8786  # a Dask scheduler's (its dashboard is 8787, and speaks HTTP)


MAX_HANDSHAKE = 1 << 20  # bytes a scheduler's handshake may announce (a few hundred in practice)


def scheduler_address(address: str) -> tuple[str, int]:
    """``(host, port)`` of a ``--scheduler`` address: ``tcp://HOST:PORT``, ``HOST:PORT`` or ``HOST``
    (port 8786). Every other form is one exit-2 line: an empty address, another protocol
    (``tls://`` needs certificates, ``ucx://`` a UCX build, ``inproc://`` this process), a path.

    >>> scheduler_address("tcp://10.0.0.5:8786"), scheduler_address("[::1]:9000"), scheduler_address("node7")
    (('10.0.0.5', 8786), ('::1', 9000), ('node7', 8786))
    """
    from urllib.parse import urlsplit

    from cspace.io.scenario.messages import printable

    text = str(address).strip()
    if not text:
        raise InputError("bench", "--scheduler", "an empty address names no scheduler (tcp://HOST:8786)")
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if scheme.lower() != "tcp":
        raise InputError("bench", "--scheduler", f"{printable(scheme)}:// is not supported: give the scheduler's "
                                                 "tcp://HOST:PORT address")
    try:
        parts = urlsplit("tcp://" + rest)
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise InputError("bench", "--scheduler", f"not an address {printable(text)!r}: {exc}") from None
    if not host or parts.path not in ("", "/") or parts.query or parts.fragment or parts.username:
        raise InputError("bench", "--scheduler", f"not an address {printable(text)!r} (expected tcp://HOST:PORT)")
    return host, DEFAULT_PORT if port is None else port


def probe(host: str, port: int, timeout: float | None = None) -> None:
    """Connect to ``host:port`` and read the handshake a Dask scheduler sends first (an 8-byte
    length, then that many bytes of msgpack frames naming its ``compression`` and
    ``pickle-protocol``), all within ``timeout`` seconds; one exit-2 line if the peer is
    unreachable, silent (an HTTP port such as Dask's own dashboard), closes, stops half-way, or
    says something else (an SSH server's banner would read as a length of exabytes)."""
    import socket
    import struct
    import time

    from cspace.io.scenario.messages import printable

    timeout = CONNECT_TIMEOUT if timeout is None else timeout
    where = f"{host}:{port}"
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except socket.timeout:
        raise InputError("bench", "--scheduler", f"no connection to {where} within {timeout:g} s") from None
    except (OSError, ValueError, OverflowError) as exc:
        raise InputError("bench", "--scheduler", f"cannot connect to {where}: "
                                                 f"{getattr(exc, 'strerror', None) or exc}") from None
    def read(n: int, got: bytes = b"") -> bytes:
        while len(got) < n:
            sock.settimeout(max(deadline - time.monotonic(), 0.001))
            chunk = sock.recv(min(n - len(got), 1 << 16))
            if not chunk:
                raise InputError("bench", "--scheduler", f"{where} closed the connection "
                                                         f"{'half-way' if got else 'without a word'}: not a Dask "
                                                         "scheduler")
            got += chunk
        return got

    with sock:
        try:
            head = read(8)
            (size,) = struct.unpack("<Q", head)
            if not 0 < size <= MAX_HANDSHAKE:
                raise InputError("bench", "--scheduler", f"{where} is not a Dask scheduler (it said "
                                                         f"{printable(head.decode('latin-1'))!r})")
            body = read(size)
        except socket.timeout:
            raise InputError("bench", "--scheduler", f"{where} did not answer as a Dask scheduler within "
                                                     f"{timeout:g} s (a scheduler listens on {DEFAULT_PORT}, its "
                                                     "dashboard on 8787)") from None
        except OSError as exc:
            raise InputError("bench", "--scheduler", f"{where}: {exc.strerror or exc}") from None
    if b"pickle-protocol" not in body and b"compression" not in body:
        raise InputError("bench", "--scheduler", f"{where} is not a Dask scheduler (its first message is not "
                                                 "a handshake)")


def connect(scheduler: str):
    """A Dask client of the scheduler at this address (exit 2 if dask or the scheduler is missing,
    or the address does not answer as one within :data:`CONNECT_TIMEOUT`)."""
    host, port = scheduler_address(scheduler)
    try:
        from distributed import Client
    except ImportError:
        raise InputError("bench", "--scheduler", "needs dask[distributed] (pip install 'cspace[cluster]')") from None
    probe(host, port)
    address = f"tcp://[{host}]:{port}" if ":" in host else f"tcp://{host}:{port}"
    # Dask's own connection, under a deadline too: a peer that passed the probe and then stalls
    # costs the timeout, not the run (the thread is left behind; the command ends anyway).
    import threading

    got: list = []

    def make():
        try:
            got.append(Client(address, timeout=f"{CONNECT_TIMEOUT:g}s"))
        except Exception as exc:  # noqa: BLE001 - whatever the handshake raised: the address does not work
            got.append(exc)

    worker = threading.Thread(target=make, name="cspace-dask-connect", daemon=True)
    worker.start()
    worker.join(3 * CONNECT_TIMEOUT + 5)
    if not got:
        raise InputError("bench", "--scheduler", f"{address} passed the handshake, then did not connect within "
                                                 f"{3 * CONNECT_TIMEOUT + 5:g} s")
    if isinstance(got[0], Exception):
        raise InputError("bench", "--scheduler", f"cannot connect to {address}: {type(got[0]).__name__}: "
                                                 f"{got[0]}")
    return got[0]


def sweep_on_cluster(tasks: list[dict], scheduler, on_batch, seconds: float = BATCH_SECONDS) -> None:
    """Run ``tasks`` on the cluster; ``on_batch(rows)`` gets each finished batch's rows (each run once).

    ``scheduler``: an address, or a connected ``distributed.Client`` (left open).
    KeyboardInterrupt cancels the batches not finished and propagates.
    """
    from distributed import as_completed

    from .arena_db import file_hash

    shas: dict[str, str] = {}
    for t in tasks:
        if t["file"] not in shas:
            try:
                shas[t["file"]] = file_hash(t["file"])
            except OSError as exc:
                raise InputError(t["file"], "scenario", f"cannot read: {exc}") from None
    client = connect(scheduler) if isinstance(scheduler, str) else scheduler
    futures = as_completed(loop=client.loop)
    seen: set = set()
    try:
        futures.update([client.submit(run_batch, b, shas[b[0]["file"]], pure=False, retries=RETRIES)
                        for b in batches(tasks, seconds)])
        for fut in futures:
            try:
                got = fut.result()
            except Exception as exc:  # a batch that failed on every try (a worker lacks the file...)
                raise InputError("bench", "--scheduler", f"a batch failed on the cluster: {exc}") from None
            fut.release()  # the worker may drop it (lost with a worker later, it is not run again)
            fresh = []
            for row in filter(None, got):
                key = (row["file"], row["planner"], float(row["time_budget"]), int(row["seed"]))
                if key not in seen:
                    seen.add(key)
                    fresh.append(row)
            on_batch(fresh)
    except BaseException:
        client.cancel(list(futures.futures))
        raise
    finally:
        if isinstance(scheduler, str):
            client.close()
