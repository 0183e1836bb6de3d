"""Text from files made safe to show on a terminal.

A preset's description, a YAML key or a file name can hold characters a terminal acts on
instead of showing: escape sequences (clear the screen, set the title), a carriage return that
overwrites a line, a bidi override that reverses what follows. :func:`printable` shows each
such character escaped, the way Python writes it (``\\x1b``, ``\\r``, ``\\u202e``); everything
else, accented letters included, is kept as it is.
"""

from __future__ import annotations

import sys
import unicodedata

#: Unicode categories escaped: controls (C0, DEL, C1), format characters (bidi overrides,
#: zero-width characters), line and paragraph separators, lone surrogates
UNSAFE_CATEGORIES = frozenset({"Cc", "Cf", "Zl", "Zp", "Cs"})
_NAMED = {"\t": "\\t", "\n": "\\n", "\r": "\\r"}


def printable(text, keep: str = "") -> str:
    """``str(text)`` with every character of :data:`UNSAFE_CATEGORIES` escaped; characters in
    ``keep`` (``"\\n"`` for a message of several lines) are left as they are."""
    s = str(text)
    return "".join(
        _escaped(c) if c not in keep and unicodedata.category(c) in UNSAFE_CATEGORIES else c
        for c in s
    )


def _escaped(c: str) -> str:
    n = ord(c)
    if c in _NAMED:
        return _NAMED[c]
    if n < 0x100:
        return f"\\x{n:02x}"
    if n < 0x10000:
        return f"\\u{n:04x}"
    return f"\\U{n:08x}"


def say(text, *, file=None, keep: str = "\n") -> None:
    """Print one message that holds user text (a file name, a mesh name, a preset's words):
    the CLI's one printing path for such messages, so what a terminal would act on is shown
    escaped (:func:`printable`; ``keep`` as there). ``file``: the stream (stdout if None)."""
    print(printable(text, keep=keep), file=file if file is not None else sys.stdout)
