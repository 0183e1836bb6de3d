"""The one progress bar of the commands (turntables, the accuracy benchmark): a line redrawn in
place on a terminal, nothing at all when the stream is not one (a pipe, a file, a test)::

    turntable [###############---------------] 18/36  4s  eta 4s
    [##############################] 30/30  412s  eta 0s  200px adaptive
"""

from __future__ import annotations

import sys
import time
from typing import TextIO


class Progress:
    """A one-line progress bar on ``stream`` (default stderr), drawn only when it is a terminal.

    ``update(done, total)`` sets the count (a callback's form); ``step(note)`` adds one and
    shows ``note`` after the bar; ``close()`` ends the line. ``total`` may be set or changed
    after construction (a job that learns its size later)."""

    WIDTH = 30
    #: longest note shown after the bar (characters)
    NOTE_LENGTH = 40

    def __init__(self, label: str = "", total: int = 1, stream: TextIO | None = None,
                 enabled: bool | None = None):  # fmt: skip
        self.label = label
        self.total = max(1, int(total))
        self.done = 0
        self.stream = sys.stderr if stream is None else stream
        if enabled is None:
            isatty = getattr(self.stream, "isatty", None)
            enabled = bool(isatty and isatty())
        self.enabled = enabled
        self.drawn = 0  # length of the line on screen (0: nothing drawn yet)
        self.t0 = time.perf_counter()

    def update(self, done: int, total: int | None = None, note: str = "") -> None:
        """Show ``done`` of ``total`` (default: the total given before)."""
        if total is not None:
            self.total = max(1, int(total))
        self.done = int(done)
        if self.enabled:
            self._draw(note)

    def step(self, note: str = "") -> None:
        """One more done, with ``note`` after the bar (e.g. what was just finished)."""
        self.update(self.done + 1, note=note)

    def close(self) -> None:
        """End the bar's line (nothing when nothing was drawn)."""
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()
            self.drawn = 0

    def line(self, note: str = "", elapsed: float = 0.0) -> str:
        """The bar's text: ``label [####----] done/total  Ns  eta Ns  note``."""
        frac = min(1.0, max(0.0, self.done / self.total))
        filled = int(self.WIDTH * frac)
        bar = "#" * filled + "-" * (self.WIDTH - filled)
        eta = elapsed / frac - elapsed if frac > 0 else 0.0
        head = f"{self.label} " if self.label else ""
        text = f"{head}[{bar}] {self.done}/{self.total}  {elapsed:.0f}s  eta {eta:.0f}s"
        return f"{text}  {note[: self.NOTE_LENGTH]}" if note else text

    def _draw(self, note: str) -> None:
        text = self.line(note, time.perf_counter() - self.t0)
        # spaces over what a longer line before left on screen
        self.stream.write("\r" + text.ljust(self.drawn))
        self.stream.flush()
        self.drawn = max(self.drawn, len(text))
