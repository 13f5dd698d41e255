"""Reading input files safely: the size and file-type gate, the bytes, UTF-8 text, the TOML reader.

Scenario files and the files an import reads (:mod:`cspace.io.importers.occupancy`, :mod:`cspace.io.importers.omplapp`)
all come through here, so a FIFO, a device, a folder or a huge file is refused with one
:class:`cspace.io.scenario.messages.ScenarioError` before it is opened or read.
"""
from __future__ import annotations

import os
import stat

from .messages import ScenarioError


def toml_reader():
    """The TOML reader, imported when a file is read (not by ``import cspace``)."""
    try:  # Python >= 3.11
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib


# The largest scenario file read: a scene of about a million vertices. Bigger files
# (or /dev/zero) are refused before reading, as is anything that is not a regular file
# (a FIFO would block the open, a device could be read forever).
MAX_FILE_BYTES = 64 * 2**20


def check_input(path) -> os.stat_result:
    """Refuse, without opening it, what cannot be a scenario file: a missing path, a
    folder, a FIFO or device (whose open or read may never end), a file over
    :data:`MAX_FILE_BYTES`. Returns the file's ``os.stat``.

    >>> check_input("/dev/zero")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: /dev/zero: file: is not a regular file (a FIFO, device or socket)
    """
    path = os.fspath(path)
    try:
        st = os.stat(path)
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise ScenarioError(path, "file", f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ScenarioError(path, "file", "is a folder, not a scenario file")
    if not stat.S_ISREG(st.st_mode):
        raise ScenarioError(path, "file", "is not a regular file (a FIFO, device or socket)")
    if st.st_size > MAX_FILE_BYTES:
        raise ScenarioError(path, "file", f"is {st.st_size} bytes, over the {MAX_FILE_BYTES >> 20} MiB limit")
    return st


def read_input(path: str) -> bytes:
    """The bytes of a scenario file, read only once :func:`check_input` accepts it.

    Opened without blocking and checked again on the open file (the path may have
    been swapped for a FIFO in between); never more than the limit is read.
    """
    check_input(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise ScenarioError(path, "file", "is not a regular file (a FIFO, device or socket)")
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ScenarioError(path, "file", f"cannot read ({exc.strerror or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ScenarioError(path, "file", f"is over the {MAX_FILE_BYTES >> 20} MiB limit")
    return raw



def utf8_text(raw: bytes, path: str) -> str:
    """The text of an input file's bytes: UTF-8, a byte-order mark allowed and skipped;
    anything else is a :class:`ScenarioError` naming the first invalid byte.

    >>> utf8_text(b"\\xef\\xbb\\xbfa = 1", "s.toml")
    'a = 1'
    >>> utf8_text(b"a\\xff", "s.toml")
    Traceback (most recent call last):
    ...
    cspace.io.scenario.messages.ScenarioError: s.toml: file: not UTF-8 text (invalid byte at offset 1)
    """
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ScenarioError(path, "file", f"not UTF-8 text (invalid byte at offset {exc.start})") from None
