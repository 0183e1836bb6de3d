"""The ports of the controller: what a front end (the Qt window, the browser page) implements
so that the controller can ask, tell, draw and work off the main thread. Each is a small
:class:`typing.Protocol`; one object may implement them all (the Qt window does).

No toolkit here: the ports name what is wanted, never how it is drawn.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from explorer.app.model import State


@runtime_checkable
class Dialogs(Protocol):
    """Questions to the user (None or False: the user gave up)."""

    def ask_text(self, title: str, label: str, default: str = "") -> str | None: ...

    def ask_yes(self, question: str) -> bool: ...

    def ask_path(self, title: str, *, save: bool = False, default: str = "",
                 filter: str = "") -> str | None: ...  # fmt: skip

    def ask_number(self, title: str, label: str, default: int, lo: int, hi: int) -> int | None: ...

    def tell(self, title: str, text: str, *, details: str = "", error: bool = False) -> None: ...


@runtime_checkable
class Messages(Protocol):
    """A short message for the user, kept in the session's message log: ``level`` one of
    ``info``, ``warning``, ``error``; ``details`` each a line of the log; ``msecs`` how long the
    status line shows it (None: the front end's default); ``open_log`` False: the details are
    shown elsewhere already (a dialog). An empty ``text`` takes the message shown away (an
    error, after an edit that worked) and adds nothing to the log."""

    def show_message(self, text: str, level: str = "info", details: Sequence[str] = (),
                     msecs: int | None = None, open_log: bool = True) -> None: ...  # fmt: skip


def log_head(at: str, level: str, text: str) -> str:
    """A message's first line in either front end's message log: ``"HH:MM:SS level: text"``,
    the level left out where the text starts with it already (the controller's errors read
    ``error (kd): ...``; the log said ``error: error (kd): ...``)."""
    said = text.startswith(level) and text[len(level) : len(level) + 1] in (":", " ")
    return f"{at} {text}" if said else f"{at} {level}: {text}"


@runtime_checkable
class Progress(Protocol):
    """A long job under a progress bar with a Cancel, stepped from the front end's event loop
    (so frames keep coming): ``step()`` does one unit and returns ``(done, text)`` (``text``
    None: the label stays) while there is more, None when finished; ``cancel()`` is called
    when the user cancels. Returns the front end's handle of the progress display."""

    def run_steps(self, title: str, text: str, total: int, step, cancel) -> object: ...


@runtime_checkable
class Worker(Protocol):
    """Work off the main thread: the latest submitted job is made, the one running cancelled;
    the front end delivers each result on its main thread to
    :meth:`explorer.app.controller.Controller.on_difference`."""

    def submit(self, job) -> None: ...

    def cancel(self) -> None: ...

    def close(self) -> None: ...


@runtime_checkable
class View(Protocol):
    """The 3D view. ``show(old, new)`` gives it a new state (one engine update and one upload
    at most: :class:`explorer.app.view.SceneView` recomputes only what changed); ``redraw()``
    draws one frame; ``size()`` (w, h) pixels; ``aspect()`` width / height; ``background()`` RGB in
    [0, 1]; ``colors()`` (n, 3) the full mesh's shown colours in [0, 1]; ``dragging()`` whether a
    drag is on (the difference waits for its end); ``show_difference(result)``: the heat map
    of ``result`` (a :class:`explorer.app.difference.Result`), or the live view with the
    "computing" legend (None while the difference is on), or the plain view (``on`` False);
    ``png()`` the view as drawn, PNG-encoded."""

    def show(self, old: State | None, new: State) -> None: ...

    def redraw(self) -> None: ...

    def size(self) -> tuple[int, int]: ...

    def aspect(self) -> float: ...

    def background(self) -> tuple[float, float, float]: ...

    def colors(self) -> np.ndarray: ...

    def dragging(self) -> bool: ...

    def show_difference(self, result, *, on: bool) -> None: ...

    def png(self) -> bytes: ...


@runtime_checkable
class Choices(Protocol):
    """The lists the front end offers: the presets (:class:`explorer.core.presets.PresetInfo`
    list), the meshes (chooser name -> label), the recent files (paths, newest first), and
    what undo and redo would do (labels, "" when nothing)."""

    def show_presets(self, presets: list) -> None: ...

    def show_meshes(self, labels: dict[str, str]) -> None: ...

    def show_recent(self, paths: list[str]) -> None: ...

    def show_history(self, undo: str | None, redo: str | None) -> None: ...


@dataclass(frozen=True)
class Ports:
    """Everything the controller needs from its front end."""

    dialogs: Dialogs
    messages: Messages
    view: View
    worker: Worker
    choices: Choices
    progress: Progress

    @classmethod
    def of(cls, front, *, worker: Worker, view: View | None = None) -> Ports:
        """All ports from one front-end object (the worker and, optionally, the view apart)."""
        view = front if view is None else view
        return cls(front, front, view, worker, front, front)
