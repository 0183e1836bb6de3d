"""The session's message log, for both front ends (no toolkit here): every message said
(information, warnings, errors), whole, with when it came and its details. The window's log
dialog (:mod:`explorer.app.qt.messages`) and the page's log (:mod:`explorer.app.web.server`'s
``message_log``) each show one :class:`MessageLog`."""

from __future__ import annotations

import time
from dataclasses import dataclass

from explorer.app.controller.ports import log_head

#: the levels of a message, in the order of their weight
LEVELS = ("info", "warning", "error")
#: the colour a message of a level is written in on the window's dark status bar (an info's:
#: the bar's own)
LEVEL_COLOURS = {"warning": "#e0a030", "error": "#ff7766"}


def opens_log(level: str, details=(), fits: bool = True) -> bool:
    """Whether a message said on a status line opens the log: an error or a warning that comes
    with ``details`` or that the line cannot show whole (``fits``: it can)."""
    return level != "info" and (bool(details) or not fits)


@dataclass(frozen=True)
class Message:
    """One message: ``level`` (one of :data:`LEVELS`), its text and its details (each whole),
    and when it came (``HH:MM:SS``)."""

    level: str
    text: str
    details: tuple[str, ...] = ()
    at: str = ""

    @property
    def head(self) -> str:
        """Its first line in the log (:func:`~explorer.app.controller.ports.log_head`)."""
        return log_head(self.at, self.level, self.text)

    def lines(self) -> list[str]:
        """Its lines in the log: the head, then each detail indented."""
        return [self.head, *(f"    {d}" for d in self.details)]

    def as_dict(self) -> dict:
        """Plain values (the page's state): text, level, details, at and head."""
        return {
            "text": self.text,
            "level": self.level,
            "details": list(self.details),
            "at": self.at,
            "head": self.head,
        }


class MessageLog:
    """The messages said so far, oldest first: at most ``keep`` (the oldest go first; None:
    every one)."""

    def __init__(self, keep: int | None = None):
        self.keep = keep
        self.messages: list[Message] = []

    def add(self, level: str, text: str, details=()) -> Message:
        """``text`` said now at ``level``, with ``details`` (each a line); returns it."""
        m = Message(level, text, tuple(details), time.strftime("%H:%M:%S"))
        self.messages.append(m)
        if self.keep is not None:
            del self.messages[: -self.keep]
        return m

    def count(self, level: str) -> int:
        """How many messages of ``level`` it holds."""
        return sum(m.level == level for m in self.messages)

    def tally(self) -> tuple[str, str]:
        """Its errors and warnings in words (``1 error, 2 warnings``; ``messages`` when it has
        none), and the colour of the heaviest level (:data:`LEVEL_COLOURS`; "": none)."""
        counts = [(self.count(level), level) for level in ("error", "warning")]
        words = ", ".join(f"{n} {level}{'s' * (n != 1)}" for n, level in counts if n)
        heaviest = next((level for n, level in counts if n), "")
        return words or "messages", LEVEL_COLOURS.get(heaviest, "")
