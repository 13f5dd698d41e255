"""``cspace bench --scheduler`` against addresses and servers that are not a Dask scheduler (issue
48): every address form that cannot work is one exit-2 line before the sweep, and a server that
does not answer as a scheduler (silent, speaking first, announcing a plausible length then
stalling) is refused within the connect timeout. The servers are local sockets on 127.0.0.1."""
from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pytest

import conftest
from planners.bench import cluster
from planners.cli import main

BASIC = str(Path(conftest.ROOT) / "scenarios" / "basic.toml")
ARGS = ["--planners", "RRTConnect", "--times", "0.01", "--runs", 1]
pytest.importorskip("ompl")


def bench(*args) -> int:
    return main(["bench", *map(str, args), "-q", "--no-plot"])


def one_line(capsys, *needles) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, err
    return err


class Server:
    """A TCP server on 127.0.0.1 that says ``greeting`` on each connection (None: stays silent)."""

    def __init__(self, greeting: bytes | None):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port = self.sock.getsockname()[1]
        self.greeting, self.conns = greeting, []
        threading.Thread(target=self.serve, daemon=True).start()

    def serve(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            self.conns.append(c)
            if self.greeting is not None:
                c.sendall(self.greeting)

    def close(self):
        self.sock.close()
        for c in self.conns:
            c.close()


@pytest.mark.parametrize("greeting", [b"SSH-2.0-OpenSSH_9.6\r\n", b"HTTP/1.1 400 Bad Request\r\n\r\n",
                                      b"\x00" * 8, None, b""])
def test_a_server_that_is_not_a_scheduler_is_refused_within_the_timeout(monkeypatch, greeting):
    pytest.importorskip("distributed")
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 0.5)
    srv = Server(greeting)
    try:
        if greeting == b"":  # accepts, then closes at once
            srv.greeting = None
            threading.Thread(target=lambda: [time.sleep(0.05), srv.close()], daemon=True).start()
        with pytest.raises(cluster.InputError) as err:
            cluster.connect(f"tcp://127.0.0.1:{srv.port}")
        assert "--scheduler" in str(err.value) and "\n" not in str(err.value)
    finally:
        srv.close()


@pytest.mark.parametrize("address", ["", "   ", "ucx://127.0.0.1:8786", "tls://127.0.0.1:8786",
                                     "inproc://x", "tcp://", "tcp://host:notaport", "tcp://h:99999",
                                     "tcp://h:1/path", "\x1b[31m://x"])
def test_address_forms_that_cannot_work_are_refused_before_the_sweep(tmp_path, capsys, address):
    assert bench(BASIC, *ARGS, "--out", tmp_path / "o", "--scheduler", address) == 2
    err = one_line(capsys, "--scheduler")
    assert "\x1b" not in err and not (tmp_path / "o").exists()


def test_a_closed_port_is_refused(tmp_path, capsys):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    with pytest.raises(cluster.InputError, match="cannot connect"):
        cluster.probe("127.0.0.1", port, 2.0)


@pytest.mark.parametrize("greeting", [b"\x01" + b"\x00" * 7, b"\x10" + b"\x00" * 7 + b"0123456789abcdef",
                                      b"\x05" + b"\x00" * 7 + b"ab"])
def test_a_server_that_mimics_the_handshake_s_length_is_refused_within_the_timeout(monkeypatch, greeting):
    # a plausible length, then nothing, a wrong message, or half a message: the probe reads the
    # whole handshake under the deadline and checks it (Dask's own connect would wait for ever)
    pytest.importorskip("distributed")
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 0.5)
    srv = Server(greeting)
    try:
        with pytest.raises(cluster.InputError, match="--scheduler"):
            cluster.connect(f"tcp://127.0.0.1:{srv.port}")
    finally:
        srv.close()
