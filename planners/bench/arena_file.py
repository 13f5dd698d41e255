"""The file of ``cspace bench --db``: claimed, checked and given its schema before a sweep runs.

:func:`open_campaign_db` is the one way a campaign opens its database:

1. **the name**: ``:memory:`` (SQLite's name for a database that is never stored) and an
   existing path that is not a regular file (a folder, ``/dev/null``, a pipe) are refused;
2. **the claim**: the file is opened for writing (a read-only file is refused here) and
   locked (``flock``, exclusive, not waiting): a second sweep on the same database is refused
   ("in use by another bench") until the first one ends, so two sweeps never interleave their
   experiments and runs;
3. **the check**, inside one write transaction (``BEGIN IMMEDIATE``), before anything is
   written: an SQLite header, ``PRAGMA integrity_check`` (a damaged page or index is refused),
   and, for a file that has tables, the five tables of a benchmark database with their key
   columns (an application's database is refused as it is);
4. **the schema** (created or upgraded: tables, columns, the run-key index, the status enum)
   and a write probe (a table created and dropped, so SQLite's journal beside the file must be
   writable: a read-only folder is refused now, not at the first stored run), in the same
   transaction: a refusal anywhere rolls all of it back, and so does an up-to-date database's
   check (its bytes stay as they were until a run is stored).

Every refusal is an :class:`planners.errors.InputError` on ``--db`` (one line, exit 2), and a
file this call created is removed again.
"""
from __future__ import annotations

import contextlib
import os
import sqlite3
import stat

from ..errors import InputError

MAGIC = b"SQLite format 3\x00"

# A benchmark database's tables and the columns a sweep relies on (OMPL's converter makes them).
KEY_COLUMNS = {"experiments": ("id", "name"), "plannerConfigs": ("id", "name", "settings"),
               "enums": ("name", "value", "description"), "runs": ("id", "experimentid", "plannerid"),
               "progress": ("runid", "time")}

# The claim: ``flock`` on the file. SQLite's own locks are POSIX byte-range locks, which flock
# does not touch (and which SQLite drops over the whole file when a transaction ends, so a POSIX
# claim would not last). A flock belongs to the open file, which forked children share: the
# sweep's children close it first thing (:func:`close_claims_in_child`), so a child outliving a
# killed sweep never keeps the database claimed.
_claims: set[int] = set()

SPECIAL_NAMES = (":memory:",)

# What a damaged or foreign database raises: SQLite's errors, and (Python decoding an error
# message that quotes a damaged schema's bytes) UnicodeDecodeError.
DB_ERRORS = (sqlite3.Error, UnicodeDecodeError)  # names SQLite gives a meaning other than a file


def quote(name: str) -> str:
    """An SQL identifier, quoted (a column named ``weird col`` or ``a"b`` stays one name).

    >>> quote('weird col'), quote('a"b')
    ('"weird col"', '"a""b"')
    """
    return '"' + str(name).replace('"', '""') + '"'


def columns(conn, table: str) -> list[tuple[str, str]]:
    """(name, declared type) of each column of ``table``."""
    return [(c[1], c[2]) for c in conn.execute(f"PRAGMA table_info({quote(table)})")]


def refuse(path: str, why: str) -> InputError:
    return InputError(path, "--db", why)


def claim(path: str) -> tuple[int, bool]:
    """Open ``path`` for writing (created if missing) and lock it; ``(fd, created)``."""
    if path in SPECIAL_NAMES or path.startswith("file:"):
        raise refuse(path, "names no database file (SQLite keeps :memory: and file: URIs for itself)")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        st = None
    except (OSError, ValueError) as exc:
        raise refuse(path, f"cannot open: {getattr(exc, 'strerror', None) or exc}") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise refuse(path, "is not a regular file")
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o644)
    except (OSError, ValueError) as exc:
        raise refuse(path, f"cannot write: {getattr(exc, 'strerror', None) or exc}") from None
    try:
        import fcntl
    except ImportError:  # pragma: no cover - no flock (Windows): SQLite's locks only
        return fd, st is None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise refuse(path, "in use by another bench (a sweep is storing runs in it; wait for it to end "
                           "or give another --db)") from None
    _claims.add(fd)
    return fd, st is None


def close_claims_in_child() -> None:
    """In a forked child: close the inherited claims (the parent's lock must not outlive it)."""
    for fd in list(_claims):
        with contextlib.suppress(OSError):
            os.close(fd)
    _claims.clear()


def check_contents(conn, path: str) -> None:
    """Refuse a damaged file or one that is not a benchmark database (nothing written yet)."""
    bad = [r[0] for r in conn.execute("PRAGMA integrity_check(3)")]
    if bad != ["ok"]:
        raise refuse(path, f"damaged database ({'; '.join(bad)}): repair or remove it")
    tables = {name for (name,) in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table' "
                                               "AND name NOT LIKE 'sqlite%'")}
    if not tables:  # an empty database: the sweep makes it a benchmark database
        return
    for table in sorted(tables):  # a name that is not UTF-8 (read as U+FFFD): damaged bytes in the schema
        if "\ufffd" in table or any("\ufffd" in name for name, _ in columns(conn, table)):
            raise refuse(path, f"damaged database (a name in table {table!r} is not UTF-8): repair or remove it")
    missing = [t for t in KEY_COLUMNS if t not in tables]
    if missing:
        have = ", ".join(sorted(tables)[:5]) + (", ..." if len(tables) > 5 else "")
        raise refuse(path, f"not a benchmark database (it has the tables {have}; no {', '.join(missing)}): "
                           "give a new file or one an earlier --db sweep wrote")
    for table, need in KEY_COLUMNS.items():
        have = {name for name, _ in columns(conn, table)}
        lacking = [c for c in need if c not in have]
        if lacking:
            raise refuse(path, f"not a benchmark database (its table {table} has no column "
                               f"{', '.join(lacking)})")


def open_campaign_db(path: str, make_schema) -> tuple[sqlite3.Connection, int]:
    """``(connection, claim fd)`` of a checked benchmark database at ``path`` (see the module
    notes); ``make_schema(conn)`` creates or upgrades the schema inside the check's transaction.
    Close the connection, then the fd (:func:`release`), when the campaign ends."""
    fd, created = claim(path)
    conn = None
    try:
        os.lseek(fd, 0, os.SEEK_SET)  # read through the claim's descriptor (closing another would drop it)
        head = os.read(fd, len(MAGIC))
        if head and head != MAGIC:
            raise refuse(path, "not a benchmark database (not even an SQLite file)")
        conn = sqlite3.connect(path, timeout=10.0)
        conn.text_factory = decode  # text that is not UTF-8 (a damaged or foreign value) is read, not raised
        conn.execute("PRAGMA foreign_keys = ON")
        try:
            conn.execute("BEGIN IMMEDIATE")
            check_contents(conn, path)
            before = (conn.execute("PRAGMA schema_version").fetchone()[0], conn.total_changes)
            make_schema(conn)
            changed = (conn.execute("PRAGMA schema_version").fetchone()[0], conn.total_changes) != before
            conn.execute("CREATE TABLE cspace_write_probe (x)")  # the journal must be writable too
            conn.execute("DROP TABLE cspace_write_probe")
            if changed:
                conn.commit()
            else:  # an up-to-date database: the probe's write is undone, the file keeps every byte
                conn.rollback()
        except DB_ERRORS as exc:
            with contextlib.suppress(*DB_ERRORS):
                conn.rollback()
            raise refuse(path, describe(exc)) from None
        return conn, fd
    except BaseException:
        if conn is not None:
            conn.close()
        if created:
            with contextlib.suppress(OSError):
                os.remove(path)
        release(fd)
        raise


def decode(raw: bytes) -> str:
    r"""A TEXT value as a string: UTF-8, a byte that is not replaced by U+FFFD.

    >>> decode(b"ok \x80")
    'ok \ufffd'
    """
    return raw.decode("utf-8", "replace")


def describe(exc: Exception) -> str:
    """A database error (one of :data:`DB_ERRORS`) in words a user acts on.

    >>> describe(sqlite3.OperationalError("attempt to write a readonly database"))
    'cannot write (attempt to write a readonly database): the file and its folder must be writable, the disk not full'
    """
    if isinstance(exc, UnicodeDecodeError):
        return "damaged database (SQLite answered with text that is not UTF-8): repair or remove it"
    text = str(exc)
    low = text.lower()
    if any(w in low for w in ("readonly", "unable to open", "permission", "disk i/o", "full")):
        return f"cannot write ({text}): the file and its folder must be writable, the disk not full"
    if "malformed" in low or "not a database" in low or "corrupt" in low:
        return f"damaged database ({text}): repair or remove it"
    if "locked" in low or "busy" in low:
        return f"locked by another program ({text})"
    return f"database error ({text})"


def release(fd: int | None) -> None:
    """Give up a campaign's claim (closing the locked descriptor unlocks it)."""
    if fd is not None:
        _claims.discard(fd)
        with contextlib.suppress(OSError):
            os.close(fd)
