"""Writing outputs safely: to a temporary file beside the target, then an atomic rename.

This module owns output paths: their early validation (so a bad ``--json`` or
``--plot`` path fails before any work, with a one-line error) and atomic writes
(so an interrupted run never leaves a half-written file, and an existing file is
replaced only by a complete one).
"""
from __future__ import annotations

import contextlib
import json
import os
import tempfile

from .errors import InputError

PLOT_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def check_output(path: str, option: str, suffixes: dict | None = None) -> str:
    """Validate an output path before any work; returns the format for plots.

    >>> check_output("out.json", "--json")
    ''
    """
    folder = os.path.dirname(os.path.abspath(path)) or "."
    if os.path.isdir(path):
        raise InputError(path, option, "is a directory, expected a file name")
    if not os.path.isdir(folder):
        raise InputError(path, option, f"folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise InputError(path, option, f"folder {folder} is not writable")
    if suffixes is None:
        return ""
    ext = os.path.splitext(path)[1].lower()
    if ext not in suffixes:
        raise InputError(path, option, f"unsupported extension {ext or '(none)'!r} (use {', '.join(suffixes)})")
    return suffixes[ext]


def _read_umask() -> int:
    mask = os.umask(0)  # the only way to read it; done once, at import (not thread-safe later)
    os.umask(mask)
    return mask


_UMASK = _read_umask()


@contextlib.contextmanager
def atomic_path(path: str):
    """Yield a temporary path beside ``path``; on success rename it over ``path``."""
    folder = os.path.dirname(os.path.abspath(path))
    ext = os.path.splitext(path)[1]
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=ext, dir=folder)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; give the usual mode of a new file
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_json(path: str, data) -> None:
    """Write ``data`` as JSON atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1, allow_nan=False)
            fh.write("\n")


def write_text(path: str, text: str) -> None:
    """Write ``text`` atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
