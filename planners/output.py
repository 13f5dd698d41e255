"""Writing outputs safely: checked before any work, then written so nothing is lost.

This module owns output paths:

- **Early validation** (:func:`check_output`), before any work, one-line errors:
  an empty path, a folder, a path under a file, a missing or unwritable folder
  (probed by creating and removing a temporary file there, which also catches
  ``/proc`` and read-only mounts), a block device or socket, and an output that is
  one of the inputs (every file the command reads: the scenario, a map's image, a
  cfg's meshes, a robot or queries file; the same file also through a symbolic or
  hard link or another spelling: compared by device and inode when the output
  exists, by resolved path otherwise) are all refused.
- **What a path is decides how it is written** (:func:`atomic_path`):
  a regular file (or a new name) is written atomically: to an unnamed temporary
  file in the target's folder (Linux ``O_TMPFILE``), which is given a name only
  once complete and renamed over the target at once, so a crash, even ``kill -9``,
  leaves either the old file or the new one and no half-written file. A symbolic
  link is followed: its target is replaced, the link survives. A character device
  (``/dev/null``, a terminal) or a FIFO (``>(jq .)``) is written directly, never
  replaced by a file; a FIFO without a reader is refused rather than waited on.
- **Temporaries** are named ``.cspace-tmp-PID-RANDOM``: where ``O_TMPFILE`` is
  not available, or in the instant between naming and renaming. A process removes
  the ones it made (each is tracked from before its creation: on success, on failure,
  at exit); it never removes a file by its name alone, so another process's
  temporaries (alive or not, on this host or another) are left alone. Only a
  process killed outright (``kill -9``) can leave one behind.
- **Write failures** (a full disk, ``/dev/full``) are one-line :class:`InputError`
  s naming the path, never a traceback and never a silent success.
"""
from __future__ import annotations

import atexit
import contextlib
import errno
import json
import os
import secrets
import stat

from .errors import InputError

PLOT_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
TMP_PREFIX = ".cspace-tmp-"
NAMED_EXTENSIONS = {".gif"}  # formats whose writer reads the file name's extension
_OURS: set[str] = set()  # named temporaries this process made and has not removed yet


def check_output(path: str, option: str, suffixes: dict | None = None, inputs=()) -> str:
    """Validate an output path before any work; returns the format for plots.

    ``inputs`` are files the run reads: an output that is one of them is refused.

    >>> check_output("out.json", "--json")
    ''
    """
    if not path:
        raise InputError(repr(path), option, "an empty path names no file")
    fmt = ""
    if suffixes is not None:
        ext = os.path.splitext(path)[1].lower()
        if ext not in suffixes:
            raise InputError(path, option, f"unsupported extension {ext or '(none)'!r} (use {', '.join(suffixes)})")
        fmt = suffixes[ext]
    st = _stat(path, option)
    check_not_input(path, option, inputs, st)
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise InputError(path, option, "is a directory, expected a file name")
        if stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode):
            return fmt  # written directly (see atomic_path)
        if not stat.S_ISREG(st.st_mode):
            raise InputError(path, option, "is not a regular file, a character device or a FIFO")
    folder = os.path.dirname(os.path.realpath(path))
    if not os.path.isdir(folder):  # (realpath and isdir take a NUL byte; _stat refused it above)
        raise InputError(path, option, f"folder {folder} does not exist")
    try:  # the one reliable test (root passes access(); /proc and read-only mounts refuse files)
        with _temporary(folder, os.path.splitext(path)[1]) as (fd, _tmp):
            pass
    except OSError as exc:
        raise InputError(path, option, f"cannot create a file in {folder} ({exc.strerror or exc})") from None
    return fmt


def check_folder(path: str, option: str) -> None:
    """Validate an output folder before any work: created if missing, and writable.

    >>> import tempfile; check_folder(tempfile.mkdtemp(), "--out")
    """
    if not path:
        raise InputError(repr(path), option, "an empty path names no folder")
    try:
        os.makedirs(path, exist_ok=True)
    except FileExistsError:
        raise InputError(path, option, "exists and is not a folder") from None
    except NotADirectoryError:
        raise InputError(path, option, "a parent of this path is a file, not a folder") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte
        raise InputError(path, option, f"cannot create this folder ({getattr(exc, 'strerror', None) or exc})") from None
    try:
        with _temporary(path, ""):
            pass
    except OSError as exc:
        raise InputError(path, option, f"cannot create a file in it ({exc.strerror or exc})") from None


def check_distinct(outputs: list) -> None:
    """Refuse two options naming one output file (``[(path, option), ...]``, None skipped).

    >>> check_distinct([("a.json", "--json"), ("a.png", "--plot"), (None, "--csv")])
    """
    seen = {}
    for path, option in outputs:
        if not path:
            continue
        key = os.path.realpath(path)
        if key in seen:
            raise InputError(path, option, f"is also the {seen[key]} output")
        seen[key] = option


def _stat(path: str, option: str):
    """``os.stat`` (following links), None when nothing is there; other faults are one line."""
    try:
        return os.stat(path)
    except FileNotFoundError:  # a new name, or a dangling link (its target is created)
        return None
    except NotADirectoryError:
        raise InputError(path, option, "a parent of this path is a file, not a folder") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        raise InputError(path, option, f"cannot use this path ({getattr(exc, 'strerror', None) or exc})") from None


def check_not_input(path: str, option: str, inputs, st: os.stat_result | None = None) -> None:
    """Refuse an output that is one of ``inputs`` (the files the command reads).

    An existing output is compared by device and inode (``st``, its ``os.stat``: links
    followed, so a symbolic or hard link to an input is the input); a new name by its
    resolved path (``./x``, ``d/../x`` and a link's target are one file).

    >>> check_not_input("./new.json", "--json", ["new.json"])
    Traceback (most recent call last):
    ...
    planners.errors.InputError: ./new.json: --json: is the input new.json; writing it would destroy it
    """
    for src in inputs:
        if src is not None and _same(path, st, src):
            raise InputError(path, option, f"is the input {src}; writing it would destroy it")


def _same(path: str, st: os.stat_result | None, src) -> bool:
    try:
        s = os.stat(src)
    except (OSError, ValueError, TypeError):
        s = None
    if st is not None and s is not None:
        return (s.st_dev, s.st_ino) == (st.st_dev, st.st_ino)
    try:
        return os.path.realpath(path) == os.path.realpath(src)
    except (OSError, ValueError, TypeError):
        return False


def clean_stale(folder: str | None = None) -> int:
    """Remove the named temporaries this process made and still has (in ``folder``, or
    anywhere); returns how many. Only this process's own: never a file by its name alone
    (another process's, even one whose pid is gone, is not ours to judge).

    >>> import tempfile
    >>> clean_stale(tempfile.mkdtemp())
    0
    """
    removed = 0
    where = None if folder is None else os.path.realpath(folder)
    for name in sorted(_OURS):
        if where is not None and os.path.dirname(os.path.realpath(name)) != where:
            continue
        _OURS.discard(name)
        try:
            os.unlink(name)
            removed += 1
        except OSError:
            pass
    return removed


atexit.register(clean_stale)  # what a failure left (the context managers remove theirs already)


def _umask() -> int:
    mask = os.umask(0)  # the only way to read it; done once, at import (not thread-safe later)
    os.umask(mask)
    return mask


_UMASK = _umask()


@contextlib.contextmanager
def _temporary(folder: str, ext: str, unnamed: bool = True):
    """An open temporary file in ``folder``: ``(fd, name)``, name None while unnamed (O_TMPFILE)."""
    fd = None
    if unnamed and hasattr(os, "O_TMPFILE") and os.path.isdir("/proc/self/fd"):
        try:
            fd = os.open(folder, os.O_TMPFILE | os.O_RDWR | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            if exc.errno not in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT):
                raise
    name = None
    if fd is None:  # no O_TMPFILE here: a named temporary, removed below (or at exit)
        name = _new_name(folder, ext)  # tracked before it exists: an interrupt cannot orphan it
        try:
            fd = os.open(name, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666 & ~_UMASK)
        except BaseException:
            if fd is None:  # not created (O_EXCL: an existing file of that name is not ours)
                _OURS.discard(name)
            else:  # interrupted just after
                os.close(fd)
                _remove_ours(name)
            raise
    try:
        yield fd, name
    finally:
        os.close(fd)
        if name is not None:
            _remove_ours(name)


def _new_name(folder: str, ext: str) -> str:
    """A fresh temporary name in ``folder``, tracked as this process's."""
    name = os.path.join(folder, f"{TMP_PREFIX}{os.getpid()}-{secrets.token_hex(6)}{ext}")
    _OURS.add(name)
    return name


def _remove_ours(name: str) -> None:
    """Remove a temporary this process made (if still there) and stop tracking it."""
    if name in _OURS:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(name)
        _OURS.discard(name)


@contextlib.contextmanager
def atomic_path(path: str, option: str = "output"):
    """Yield a path to write ``path``'s new content to; see the module notes.

    Regular files (and new names) are replaced atomically, links followed, devices and
    FIFOs written directly. Any OS failure is an :class:`InputError` naming ``path``.
    """
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        st = None
    try:
        if st is not None and (stat.S_ISCHR(st.st_mode) or stat.S_ISFIFO(st.st_mode)):
            with _direct(path) as target:
                yield target
            return
        real = os.path.realpath(path)  # a link is followed: its target is what gets replaced
        folder = os.path.dirname(real)
        # Unnamed (O_TMPFILE) unless a writer needs the extension in the name (Pillow's GIF).
        ext = os.path.splitext(real)[1]
        with _temporary(folder, ext, unnamed=ext.lower() not in NAMED_EXTENSIONS) as (fd, name):
            if st is not None and stat.S_ISREG(st.st_mode):
                os.fchmod(fd, stat.S_IMODE(st.st_mode))  # a replaced file keeps its permissions
            yield name or f"/proc/self/fd/{fd}"
            if name is None:  # give the complete file a name, then move it over the target at once
                name = _new_name(folder, "")
                dfd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
                try:  # a dir fd makes this linkat(..., AT_SYMLINK_FOLLOW), which names an O_TMPFILE file
                    os.link(f"/proc/self/fd/{fd}", os.path.basename(name), dst_dir_fd=dfd)
                except BaseException:  # removed only if it is this very file (never another's)
                    with contextlib.suppress(OSError):
                        if os.path.samestat(os.stat(name), os.fstat(fd)):
                            os.unlink(name)
                    _OURS.discard(name)
                    raise
                finally:
                    os.close(dfd)
            try:
                os.replace(name, real)
            except BaseException:
                _remove_ours(name)
                raise
            _OURS.discard(name)  # renamed: it is the target now, no longer a temporary
    except (OSError, ValueError) as exc:
        raise InputError(path, option, f"cannot write ({getattr(exc, 'strerror', None) or exc})") from None


@contextlib.contextmanager
def _direct(path: str):
    """A device or FIFO: opened without blocking (a FIFO with no reader is refused)."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK | os.O_CLOEXEC | os.O_NOCTTY)
    except OSError as exc:
        if exc.errno == errno.ENXIO:
            raise OSError(errno.ENXIO, "a FIFO with no reader") from None
        raise
    try:
        os.set_blocking(fd, True)
        yield f"/proc/self/fd/{fd}" if os.path.isdir("/proc/self/fd") else path
    finally:
        os.close(fd)


def write_json(path: str, data, option: str = "output") -> None:
    """Write ``data`` as JSON (see :func:`atomic_path`)."""
    write_text(path, json.dumps(data, indent=1, allow_nan=False) + "\n", option)


def write_text(path: str, text: str, option: str = "output") -> None:
    """Write ``text`` (see :func:`atomic_path`); a short write or a full disk is an error."""
    with atomic_path(path, option) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)


def path_csv(path, dim: int = 2) -> str:
    """A path as CSV text: a header (``x,y`` or ``x,y,theta``) and one waypoint per line,
    each number written with ``repr`` (shortest round-trip: read back, the same doubles).

    >>> print(path_csv([[0.0, 1.5], [2.0, 3.0]]), end="")
    x,y
    0.0,1.5
    2.0,3.0
    """
    import numpy as np

    rows = np.asarray(path, dtype=np.float64).reshape(-1, dim)
    header = "x,y,theta" if dim == 3 else "x,y"
    return header + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in rows.tolist())


def write_csv(path: str, waypoints, dim: int = 2, option: str = "--csv") -> None:
    """Write a path as CSV (:func:`path_csv`), atomically (see :func:`atomic_path`)."""
    write_text(path, path_csv(waypoints, dim), option)


def queries_csv(paths, dim: int = 2) -> str:
    """Several queries' paths as one CSV: a ``query`` column (the query's index) before
    ``x,y`` (or ``x,y,theta``); ``paths`` is ``[(index, waypoints)]`` (the solved ones).

    >>> print(queries_csv([(0, [[0.0, 1.0]]), (2, [[2.0, 3.0], [4.0, 5.0]])]), end="")
    query,x,y
    0,0.0,1.0
    2,2.0,3.0
    2,4.0,5.0
    """
    lines = []
    for i, waypoints in paths:
        body = path_csv(waypoints, dim).split("\n", 1)[1]
        lines += [f"{int(i)},{row}" for row in body.splitlines()]
    return f"query,{'x,y,theta' if dim == 3 else 'x,y'}\n" + "".join(line + "\n" for line in lines)


def say(text: str, gone: bool = False) -> bool:
    """Print a command's report ``text`` (flushed), unless its reader went away (``cspace plan ...
    --json out.json | head -1``); True once it has (``gone``: it had already), so that the caller
    still writes the files it was asked for, then ends as the closed pipe asks (it raises
    BrokenPipeError: exit 141, quietly).

    >>> say("report")
    report
    False
    """
    if gone:
        return True
    import sys

    try:
        print(text)
        sys.stdout.flush()
    except BrokenPipeError:
        return True
    return False

