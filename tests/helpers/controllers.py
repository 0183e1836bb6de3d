"""Fake ports of :class:`explorer.app.controller.Controller` that record what it asked of its
front end (a view, a worker, the dialogs, messages, choices and progress), and a controller in
the gui's start on them: the controller's tests and the view port's share them."""

from __future__ import annotations

import numpy as np

from explorer.app import start as A
from explorer.app.controller import Controller, Ports
from explorer.cli import build_parser
from explorer.cli.gui import start
from explorer.render.images import encode_png

SIZE = (64, 48)


class FakeView:
    """The view port: records each change shown, each frame asked for, each difference
    shown; ``size`` and ``dragging`` set by the test."""

    def __init__(self, n: int):
        self.n = n
        self.shown: list = []
        self.frames = 0
        self.differences: list = []
        self.drag = False
        self.px = SIZE

    def show(self, old, new):
        self.shown.append((old, new))

    def redraw(self):
        self.frames += 1

    def size(self):
        return self.px

    def aspect(self):
        return self.px[0] / self.px[1]

    def background(self):
        return (0.1, 0.1, 0.1)

    def colors(self):
        return np.full((self.n, 3), 0.5)

    def dragging(self):
        return self.drag

    def show_difference(self, result, *, on):
        self.differences.append((result, on))

    def png(self):
        return encode_png(np.zeros((SIZE[1], SIZE[0], 3), np.uint8))


class FakeWorker:
    def __init__(self):
        self.jobs: list = []
        self.cancels = 0

    def submit(self, job):
        self.jobs.append(job)

    def cancel(self):
        self.cancels += 1

    def close(self):
        pass


class FakeFront:
    """Dialogs answered from queues (``answers``), messages, lists and progress recorded."""

    def __init__(self):
        self.answers = {"text": [], "yes": [], "path": [], "number": []}
        self.messages: list = []
        self.told: list = []
        self.presets = self.meshes = self.recent = None
        self.history = (None, None)

    def ask_text(self, title, label, default=""):
        return self.answers["text"].pop(0)

    def ask_yes(self, question):
        return self.answers["yes"].pop(0)

    def ask_path(self, title, *, save=False, default="", filter=""):
        return self.answers["path"].pop(0)

    def ask_number(self, title, label, default, lo, hi):
        return self.answers["number"].pop(0)

    def tell(self, title, text, *, details="", error=False):
        self.told.append((title, text, details, error))

    def show_message(self, text, level="info", details=(), msecs=None, open_log=True):
        self.messages.append((level, text))

    def show_presets(self, presets):
        self.presets = presets

    def show_meshes(self, labels):
        self.meshes = labels

    def show_recent(self, paths):
        self.recent = paths

    def show_history(self, undo, redo):
        self.history = (undo, redo)

    def run_steps(self, title, text, total, step, cancel):
        while step() is not None:
            pass
        return "handle"


def icosphere_controller(mesh, view, tmp_path, monkeypatch, resolution: int) -> Controller:
    """A controller on ``mesh`` (the icosphere of ``resolution``) in the gui's start, with fake
    ports but ``view`` (not started); presets saved under ``tmp_path``."""
    monkeypatch.setenv("PHONG_EXPLORER_MATERIALS", str(tmp_path / "presets"))
    scene, _, preset = start(build_parser().parse_args(["gui", "--mesh", "icosphere"]))
    state = A.first_state(scene, mesh, name="icosphere", preset=preset, resolution=resolution)
    return Controller(state, mesh, Ports.of(FakeFront(), worker=FakeWorker(), view=view),
                      output_dir=tmp_path, last_session=tmp_path / "last.yaml")  # fmt: skip
