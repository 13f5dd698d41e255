"""Scenario messages: :class:`ScenarioError` and the helpers that keep each message one short line.

Every fault in an input file is a :class:`ScenarioError` whose text is ``FILE: FIELD: what is
wrong``; values echoed in it are clipped (:func:`clip`, :func:`show`, :func:`short`), and an
unknown key names the closest known one (:func:`unknown_field_message`).
"""
from __future__ import annotations

import difflib
import re

# Characters a terminal or a line-based log would act on rather than show: C0 and C1 controls
# (escape sequences recolour a terminal, a newline starts a new log line) and DEL, and the
# bidirectional overrides and isolates (they reorder what a reader sees).
CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u200e\u200f\u202a-\u202e\u2066-\u2069]")
_NAMED = {"\n": "\\n", "\r": "\\r", "\t": "\\t"}


def printable(text: str) -> str:
    r"""``text`` with every control character written as an escape (``\x1b``, ``\n``, ``\u202e``):
    safe to print on a terminal and as one line of a log.

    >>> printable("red \x1b[31m\nline")
    'red \\x1b[31m\\nline'
    """
    return CONTROL.sub(lambda m: _NAMED.get(m.group(), m.group().encode("unicode_escape").decode("ascii")),
                       str(text))


def control_character(text: str) -> str | None:
    r"""The first control character of ``text`` (see :func:`printable`) as an escape, or None.

    >>> control_character("a\x1bb"), control_character("plain")
    ('\\x1b', None)
    """
    m = CONTROL.search(str(text))
    return None if m is None else printable(m.group())


class ScenarioError(ValueError):
    """A fault in a scenario: ``str(err)`` is ``FILE: FIELD: message``, one short line.

    Each part is clipped (:func:`clip`): an echoed value is never longer than a line.
    """

    def __init__(self, file: str, field: str, message: str):
        self.file, self.field, self.message = clip(str(file)), clip(str(field)), clip(str(message), 240)
        super().__init__(f"{self.file}: {self.field}: {self.message}")


def clip(text: str, limit: int = 120) -> str:
    """``text`` on one line, at most about ``limit`` characters (the rest counted, not shown).

    >>> clip("x" * 1000, 10)
    'xxxxxxxxxx... (990 more characters)'
    """
    text = printable(text)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text) - limit} more characters)"


def show(x) -> str:
    """A value as echoed in a message: short, and safe for integers of any size.

    >>> show(10**5000), show([1.5] * 100)[:20]
    ('an integer of 5001 digits', '[1.5, 1.5, 1.5, 1.5,')
    """
    if isinstance(x, int) and not isinstance(x, bool) and x.bit_length() > 200:
        return f"an integer of {len(format(abs(x), 'x')) * 4 * 30103 // 100000 + 1} digits" \
            if x.bit_length() > 14000 else f"an integer of {len(str(abs(x)))} digits"
    if isinstance(x, (list, dict)) and len(x) > 40:  # do not even build a huge repr
        x = x[:40] if isinstance(x, list) else dict(list(x.items())[:40])
        return clip(repr(x)[:-1] + ", ...]" if isinstance(x, list) else repr(x)[:-1] + ", ...}", 80)
    try:
        return clip(repr(x), 80)
    except (ValueError, RecursionError):
        return f"a {type(x).__name__}"



def short(x, limit: int = 60) -> str:
    """repr(x), cut to ``limit`` characters (messages stay one short line)."""
    r = repr(x)
    return r if len(r) <= limit else r[: limit - 3] + "..."



def unknown_field_message(key: str, allowed) -> str:
    """The message for a key that is not one of ``allowed``: the closest known key, if any.

    >>> unknown_field_message("polgon", {"polygon", "holes", "center", "radius"})
    'unknown field (did you mean polygon?)'
    >>> unknown_field_message("colour", {"name", "bounds"})
    'unknown field (expected one of: bounds, name)'
    """
    close = difflib.get_close_matches(str(key), sorted(allowed), n=1, cutoff=0.6)
    if close:
        return f"unknown field (did you mean {close[0]}?)"
    return f"unknown field (expected one of: {', '.join(sorted(allowed))})"
