"""Fuzzing the surfaces of issue 48: benchmark databases, OMPL logs, scheduler addresses, sweep
sizes and the offline page, under the contract of tests/helpers/fuzzing.py (exit 0, 1 or 2, never
3; exit 2 one line; no hang; inputs unchanged) and this campaign's own promises:

- a ``--db`` file the command refuses (exit 2) is unchanged, byte for byte; a file it accepts is
  a benchmark database afterwards;
- nothing appears or changes in the case's folder but the outputs (``--out``, ``--log DIR``,
  the database), whatever names the database holds (``../x``, ``/abs``, control characters);
- a log's text carries no control character;
- a ``--scheduler`` address or server that is not a scheduler is refused within the connect
  timeout (the hang bound catches a wait);
- a page's figure texts hold no plotly markup.

``CSPACE_FUZZ_EXAMPLES=N`` sets the examples per test; scripts/fuzz_inputs.py runs this file as
its ``campaigns`` part and reports its counts.
"""
from __future__ import annotations

import hashlib
import json
import os
import random
import socket
import sqlite3
import threading

import pytest
from hypothesis import given, strategies as st

import conftest
from fuzzing import EXAMPLES, LAST, STATS, budget, check_case, mutate_bytes, workdir

pytest.importorskip("ompl")
BASIC = os.path.join(conftest.ROOT, "scenarios", "basic.toml")
SWEEP = ["--planners", "RRTConnect", "--times", "0.01", "--runs", "1", "-q", "--no-plot"]
NAMES = st.one_of(st.text(max_size=30), st.sampled_from([
    os.path.join(os.pardir, os.pardir, "escaped"), "/tmp/abs", "..", ".", "", "a/b", "x\n|>>>\ny", "\x1b[2J",
    "con", "a;b", 'q"uote',
    "<a href='http://127.0.0.1:9/'>l</a>", "\u202eevil", "a" * 300]))


def digest(path) -> str | None:
    try:
        with open(path, "rb") as fh:
            return hashlib.sha256(fh.read()).hexdigest()
    except OSError:
        return None


def tree(folder) -> dict:
    """Every file under ``folder`` (relative path -> digest)."""
    out = {}
    for base, _, names in os.walk(folder):
        for n in names:
            p = os.path.join(base, n)
            out[os.path.relpath(p, folder)] = digest(p)
    return out


@pytest.fixture(scope="module")
def good_db(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fuzzdb")
    db = str(tmp / "good.db")
    code = check_case(["bench", BASIC, *SWEEP, "--out", str(tmp / "o"), "--db", db], str(tmp), [BASIC], "db seed")
    assert code == 0
    return db


def hostile_db(path: str, good: bytes, draw) -> None:
    """A database file: a benchmark database with hostile names and columns, a foreign one,
    damaged bytes or pages, noise, or nothing."""
    kind = draw(st.sampled_from(["names", "columns", "foreign", "bytes", "page", "noise", "empty", "none"]))
    if kind == "none":
        return
    if kind in ("names", "columns", "bytes", "page"):
        with open(path, "wb") as fh:
            fh.write(good)
    if kind == "names":
        conn = sqlite3.connect(path)
        for name in draw(st.lists(NAMES, min_size=1, max_size=3)):
            conn.execute("UPDATE experiments SET name = ?, setup = ?, hostname = ? WHERE id = "
                         "(SELECT MIN(id) FROM experiments)", (name, name, name))
            conn.execute("INSERT INTO experiments (name, setup, version, hostname, cpuinfo, date, seed, totaltime, "
                         "timelimit, memorylimit, runcount, time_budget, scenario_sha256) VALUES "
                         "(?, ?, 'OMPL 2.0', ?, ?, 'd', '0', 0, 1, 0, 0, 1, ?)",
                         (name, name, name, name, hashlib.sha256(repr(name).encode()).hexdigest()))
        conn.commit()
        conn.close()
    elif kind == "columns":
        conn = sqlite3.connect(path)
        for name in draw(st.lists(NAMES, min_size=1, max_size=3, unique=True)):
            quoted = '"' + name.replace('"', '""') + '"'
            try:
                conn.execute(f"ALTER TABLE runs ADD {quoted} {draw(st.sampled_from(['REAL', 'TEXT', '', 'BLOB']))}")
                conn.execute(f"UPDATE runs SET {quoted} = ?", (draw(NAMES),))
            except sqlite3.Error:  # a name SQLite itself refuses (empty, taken)
                pass
        conn.commit()
        conn.close()
    elif kind == "foreign":
        conn = sqlite3.connect(path)
        tables = draw(st.lists(st.sampled_from(["experiments", "plannerConfigs", "enums", "runs", "progress",
                                                "users"]), min_size=1, max_size=5, unique=True))
        for t in tables:
            conn.execute(f'CREATE TABLE "{t}" (id INTEGER PRIMARY KEY, name TEXT)')
            conn.execute(f'INSERT INTO "{t}" (name) VALUES (?)', (draw(NAMES),))
        conn.commit()
        conn.close()
    elif kind == "bytes":
        with open(path, "wb") as fh:
            fh.write(mutate_bytes(good, draw))
    elif kind == "page":
        size = 4096
        k = draw(st.integers(1, max(1, len(good) // size - 1)))
        rng = random.Random(draw(st.integers(0, 2**32)))
        bad = bytearray(good)
        bad[k * size:(k + 1) * size] = bytes(rng.randrange(256) for _ in range(size))
        with open(path, "wb") as fh:
            fh.write(bytes(bad))
    elif kind == "noise":
        with open(path, "wb") as fh:
            fh.write(draw(st.binary(min_size=1, max_size=300)))
    else:
        open(path, "wb").close()


@budget(12)
@given(data=st.data())
def test_fuzz_databases_and_logs(good_db, data):
    draw = data.draw
    with workdir() as d:
        db = os.path.join(d, "c.db")
        with open(good_db, "rb") as fh:
            hostile_db(db, fh.read(), draw)
        if draw(st.booleans()) and os.path.exists(db) and draw(st.booleans()):
            os.mkdir(db + "-journal")  # SQLite cannot write beside it
        special = draw(st.sampled_from([None, None, None, ":memory:", "/dev/null", d, "file:x?mode=memory"]))
        argv = ["bench", BASIC, *SWEEP, "--out", os.path.join(d, "out"), "--db", special or db]
        logs = draw(st.sampled_from([None, os.path.join(d, "deep", "er", "logs"), os.path.join(d, "out", "ompl")]))
        argv += ["--log", logs] if logs else []
        argv += ["--resume"] if draw(st.booleans()) else []
        argv += ["--runs", str(draw(st.sampled_from([1, 2, 10**6, 10**12])))] if draw(st.booleans()) else []
        before, db_before = tree(d), digest(db)
        code = check_case(argv, d, [BASIC], "db files")
        after = tree(d)
        if code == 2 and "runs were stored" not in LAST["stderr"]:  # refused (not an error after storing)
            assert digest(db) == db_before, "a refused database changed"
            assert {k: v for k, v in after.items() if not k.startswith("out" + os.sep)} == before
        elif code == 2:  # an error after some runs were stored: only outputs changed
            outputs = ("out" + os.sep, os.path.join("deep", "er", "logs") + os.sep, "c.db")
            assert all(k.startswith(outputs) for k in after if k not in before or after[k] != before[k])
        else:
            outputs = ("out" + os.sep, os.path.join("deep", "er", "logs") + os.sep, "c.db")
            extra = {k for k in after if k not in before or after[k] != before[k]}
            assert all(k.startswith(outputs) for k in extra), sorted(extra)
            conn = sqlite3.connect(db)
            assert {t for (t,) in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")} >= {
                "experiments", "plannerConfigs", "enums", "runs", "progress"}
            conn.close()
            if logs and not logs.endswith("ompl"):
                for name in os.listdir(logs):
                    with open(os.path.join(logs, name), encoding="utf-8") as fh:
                        text = fh.read()
                    assert not any(ord(c) < 32 and c != "\n" or 0x7f <= ord(c) <= 0x9f for c in text), name


class Server:
    """127.0.0.1: says ``greeting`` on each connection (None: silent), or closes at once."""

    def __init__(self, greeting, close):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port, self.greeting, self.close_at_once, self.conns = self.sock.getsockname()[1], greeting, close, []
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            if self.close_at_once:
                c.close()
                continue
            self.conns.append(c)
            if self.greeting:
                try:
                    c.sendall(self.greeting)
                except OSError:
                    pass

    def stop(self):
        self.sock.close()
        for c in self.conns:
            c.close()


@pytest.mark.slow
@budget(12)
@given(data=st.data())
def test_fuzz_scheduler_addresses(data, monkeypatch_module):
    draw = data.draw
    srv = None
    if draw(st.booleans()):
        srv = Server(draw(st.one_of(st.none(), st.binary(min_size=1, max_size=64),
                                    st.sampled_from([b"SSH-2.0-OpenSSH_9.6\r\n", b"HTTP/1.1 200 OK\r\n\r\n",
                                                     b"\xff" * 8, b"\x01" + b"\x00" * 7]))),
                     draw(st.booleans()))
        address = draw(st.sampled_from(["tcp://127.0.0.1:{p}", "127.0.0.1:{p}", "tls://127.0.0.1:{p}",
                                        "ucx://127.0.0.1:{p}", "tcp://localhost:{p}/", "tcp://[::1]:{p}"]))
        address = address.format(p=srv.port)
    else:
        address = draw(st.one_of(st.text(max_size=40), st.sampled_from(
            ["", " ", "tcp://", "tcp://:8786", "tcp://h:0", "tcp://h:65536", "inproc://x", "tcp://127.0.0.1:1",
             "tcp://user@h:1", "tcp://h:1?x=1", "\x1b[31m", "tcp://" + "a" * 300 + ":1"])))
    with workdir() as d:
        try:
            check_case(["bench", BASIC, *SWEEP, "--out", os.path.join(d, "o"), "--scheduler", address], d, [BASIC],
                       "scheduler")
        finally:
            if srv is not None:
                srv.stop()


@pytest.fixture(scope="module")
def monkeypatch_module():
    from planners.bench import cluster

    mp = pytest.MonkeyPatch()
    mp.setattr(cluster, "CONNECT_TIMEOUT", 1.0)  # a silent server: refused in 1 s, not 10
    yield mp
    mp.undo()


@budget(8)
@given(name=NAMES, hostile=st.sampled_from(["", "<b>", "</script>", "&amp;", "<span style=\"x:url(y)\">"]),
       command=st.sampled_from(["view", "plan"]))
def test_fuzz_page_names(name, hostile, command):
    from planners.pictures.view.figure import TEXT_KEYS

    with workdir() as d:
        scen = os.path.join(d, "s.toml")
        with open(BASIC, encoding="utf-8") as fh:
            text = fh.read().replace('name = "basic"', f"name = {json.dumps(hostile + name + hostile)}", 1)
        with open(scen, "w", encoding="utf-8") as fh:
            fh.write(text)
        out = os.path.join(d, "v.html")
        argv = (["view", scen, "--out", out] if command == "view" else ["plan", scen, "--html", out])
        code = check_case(argv + ["--planner", "exact", "--poses", "4", "--angles", "2"][: 2 if command == "plan"
                                                                                            else 6], d, [scen], "page")
        if code in (0, 1):
            import base64
            import gzip
            import re

            with open(out, encoding="utf-8") as fh:
                page = fh.read()
            m = re.search(r'id="figure-gz">([^<]*)</script>', page)
            fig = json.loads(gzip.decompress(base64.b64decode(m.group(1))))

            def texts(node):
                if isinstance(node, dict):
                    for k, v in node.items():
                        if k in TEXT_KEYS and isinstance(v, str):
                            yield v
                        elif k not in ("x", "y"):
                            yield from texts(v)
                elif isinstance(node, list):
                    for v in node:
                        yield from texts(v)

            assert all("<" not in t and ">" not in t for t in texts(fig))


def test_zz_report():
    """Write the run's figures where CSPACE_FUZZ_REPORT says (scripts/fuzz_inputs.py's campaigns part)."""
    path = os.environ.get("CSPACE_FUZZ_REPORT")
    if path:
        rep = {**STATS, "exit": dict(STATS["exit"]), "by_test": dict(STATS["by_test"]),
               "examples_per_test": EXAMPLES or "default"}
        with open(path, "w") as fh:
            json.dump(rep, fh, indent=1)
    assert STATS["exit"].get("3", 0) == 0
