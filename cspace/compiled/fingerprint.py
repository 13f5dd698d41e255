"""The C sources' fingerprint: setup.py compiles it into the extension (``_fast.source_hash``) and
:mod:`cspace.compiled.fastpath` compares it with the sources beside the built module, so that
sources edited or pulled since the build never run as stale compiled code (a routine taking other
arguments fails mid-plan; one computing otherwise answers otherwise): the pure path runs instead.

Plain standard library: setup.py loads this file by its path, before numpy is installed.
"""
from __future__ import annotations

import hashlib
import os


def fingerprint(folder: str) -> str:
    """sha256 over each ``.c``/``.h`` file's name and bytes in ``folder``, in name order: its first
    16 hex digits ('' where there are none: an installed wheel ships no sources).

    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> fingerprint(d)
    ''
    >>> _ = open(os.path.join(d, "_x.c"), "w").write("int x;")
    >>> len(fingerprint(d)), fingerprint(d) == fingerprint(d)
    (16, True)
    """
    names = sorted(f for f in os.listdir(folder) if f.endswith((".c", ".h")))
    if not names:
        return ""
    h = hashlib.sha256()
    for name in names:
        with open(os.path.join(folder, name), "rb") as fh:
            h.update(name.encode() + b"\0" + fh.read())
    return h.hexdigest()[:16]


def stale(ext, folder: str) -> str | None:
    """Why the built extension ``ext`` is not the build of the C sources in ``folder`` (None: it
    is, or no sources lie there to tell).

    >>> import tempfile, types
    >>> d = tempfile.mkdtemp(); _ = open(os.path.join(d, "_x.c"), "w").write("int x;")
    >>> stale(types.SimpleNamespace(source_hash=fingerprint(d)), d) is None
    True
    >>> stale(types.SimpleNamespace(source_hash="0" * 16), d)
    'built from other sources than the ones beside it (rebuild it: pip install -e .)'
    """
    here = fingerprint(folder)
    if not here or getattr(ext, "source_hash", "") == here:
        return None
    return "built from other sources than the ones beside it (rebuild it: pip install -e .)"
