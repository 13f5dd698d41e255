"""Ctrl-C for the command line: a KeyboardInterrupt only where Python code can take it.

Python's own handler raises KeyboardInterrupt in whatever frame runs when the signal
lands. Two kinds of frame cannot take it:

- **an import.** A C extension importing numpy (``import_array``) prints the
  KeyboardInterrupt with its traceback and raises ImportError in its place; importlib's
  module-lock callbacks print "Exception ignored". So while any frame of the stack is
  importlib's, the handler only notes the Ctrl-C, and a profile hook (``sys.setprofile``,
  set only while a Ctrl-C is held) delivers it when the outermost import returns: in the
  importing frame, at its ``import`` line. A second Ctrl-C while one is held raises at once.
- **a callback** (``__del__``, a weakref's callback, ...). Python prints "Exception
  ignored in ..." and goes on as if no Ctrl-C came. :func:`install` also sets
  ``sys.unraisablehook``: a KeyboardInterrupt that dies there is held the same way and
  delivered at the next call or return outside the hook (or when the import it came in
  returns), silently; every other unraisable error goes to the hook that was there before.

SIGTERM (how batch systems and ``kill`` end a job) is taken as a Ctrl-C: the same
KeyboardInterrupt, so a command stops as it does on Ctrl-C (``cspace bench`` writes its
finished rows), and its exit code is 143 (128 + SIGTERM) instead of 130 (:func:`exit_code`).

Delivering goes to whichever SIGINT handler is current by then (the planning routine's
own handler stops OMPL's planners cleanly, for instance). Where the profile hook is not
ours to use (a profiler runs), Python's own behaviour stands: a Ctrl-C raises at once,
and one lost in a callback is reported as Python reports it.

>>> from planners.cli import interrupt
>>> interrupt.came()
False
"""
from __future__ import annotations

import signal
import sys

_MODULE = globals()
_state = {"came": False, "held": False, "previous_hook": None, "signum": signal.SIGINT}


def came() -> bool:
    """Whether a Ctrl-C came since :func:`install` (also one a library turned into an error)."""
    return _state["came"]


def exit_code() -> int:
    """The exit code of an interrupted command: 130 after Ctrl-C, 143 after SIGTERM.

    >>> exit_code()
    130
    """
    return 128 + int(_state["signum"])


def install() -> bool:
    """Take SIGINT and SIGTERM (KeyboardInterrupt, held through imports) and KeyboardInterrupts
    lost in callbacks. Returns False off the main thread, where no handler can be set."""
    try:
        signal.signal(signal.SIGINT, _on_sigint)
        signal.signal(signal.SIGTERM, _on_sigterm)
    except ValueError:  # not the main thread
        return False
    if _state["previous_hook"] is None:
        _state["previous_hook"] = sys.unraisablehook
        sys.unraisablehook = _on_unraisable
    return True


def release() -> None:
    """The exit code is known: ignore a later Ctrl-C and drop one still held."""
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    except ValueError:
        return
    _end_hold()


def _on_sigterm(signum, frame):
    _state["signum"] = signal.SIGTERM
    _on_sigint(signum, frame)


def _on_sigint(signum, frame):
    _state["came"] = True
    if _state["held"]:  # a second Ctrl-C while one is held: now, and the hold is over
        _end_hold()
    elif _importing(frame) and _hold():
        return
    raise KeyboardInterrupt


def _on_unraisable(unraisable) -> None:
    if issubclass(unraisable.exc_type, KeyboardInterrupt) and _state["came"] and (_state["held"] or _hold()):
        return
    _state["previous_hook"](unraisable)


def _hold() -> bool:
    """Watch calls and returns until the Ctrl-C can be delivered; False under a profiler."""
    if sys.getprofile() is not None:
        return False
    sys.setprofile(_watch)
    _state["held"] = True
    return True


def _end_hold() -> None:
    """Take the profile hook off (if a Ctrl-C is held): nothing is held any more."""
    if _state["held"]:
        sys.setprofile(None)
        _state["held"] = False


def _watch(frame, event, arg) -> None:
    """Profile hook while a Ctrl-C is held: deliver it at the first call or return outside
    the unraisable hook and outside any import, or as the outermost import returns."""
    if frame.f_globals is _MODULE:  # this module's own calls (setting the hook, the unraisable hook)
        return
    if _importing(frame) and not (event == "return" and _is_importlib(frame) and not _importing(frame.f_back)):
        return
    _end_hold()
    _deliver()  # raised here, it comes out of the returning import (or the called function)


def _deliver() -> None:
    """The Ctrl-C, to the SIGINT handler current now: ours raises KeyboardInterrupt here."""
    handler = signal.getsignal(signal.SIGINT)
    if handler is _on_sigint:
        raise KeyboardInterrupt
    if handler != signal.SIG_IGN:
        signal.raise_signal(signal.SIGINT)


def _is_importlib(frame) -> bool:
    return frame.f_code.co_filename.startswith("<frozen importlib")


def _importing(frame) -> bool:
    """Whether a frame of importlib's is on the stack (an import has not yet returned)."""
    while frame is not None:
        if _is_importlib(frame):
            return True
        frame = frame.f_back
    return False
