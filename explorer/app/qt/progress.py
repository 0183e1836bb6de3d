"""The Qt window's progress displays: a long job stepped under a progress dialog (the
controller's progress port, :func:`run_steps`), and the status bar's word on the compiled
kernels (:class:`EngineStatus`)."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from explorer.app.qt.messages import FittedLabel, elide
from explorer.app.steps import Steps
from explorer.shading import tiers

#: how often the job's timer takes a step (ms; 0: whenever the event loop is idle)
STEP_MS = 0
#: how often the status bar asks whether the compiled kernels are ready yet (ms)
ENGINE_POLL_MS = 500
#: the widest the engine's word may be in the status bar (average characters); longer text is
#: elided there and said whole in its tooltip (it took 400 pixels of a 1000-pixel window)
ENGINE_CHARS = 30


def run_steps(parent, title: str, text: str, total: int, step, cancel):
    """``step()`` called from the event loop under a window-modal progress dialog until it
    returns None (see :class:`explorer.app.controller.ports.Progress`; stepped as
    :class:`~explorer.app.steps.Steps`); the dialog's Cancel calls ``cancel()``. Returns the
    dialog."""
    dialog = QtWidgets.QProgressDialog(text, "Cancel", 0, total, parent)
    dialog.setObjectName(f"{title}_progress")
    dialog.setWindowTitle(f"phong-explorer: {title}")
    dialog.setWindowModality(QtCore.Qt.WindowModality.WindowModal)
    dialog.setMinimumDuration(0)
    dialog.setAutoClose(False)
    dialog.setAutoReset(False)
    timer = QtCore.QTimer(dialog)
    job = Steps(title, text, total, step, cancel)

    def tick() -> None:
        if dialog.wasCanceled():
            timer.stop()
            dialog.close()
            job.cancel()
        elif job.next():
            dialog.setValue(job.done)
            dialog.setLabelText(job.text)
        else:
            timer.stop()
            dialog.setValue(total)
            dialog.close()

    timer.timeout.connect(tick)
    timer.start(STEP_MS)
    dialog.show()
    return dialog


class EngineStatus:
    """Load the compiled kernels in a thread as soon as numba's cache holds them (the numpy
    tier draws meanwhile; :func:`explorer.shading.tiers.preload`), and say so in the status bar
    (``window.engine_label``) while it lasts."""

    def __init__(self, window):
        tiers.preload()
        most = window.fontMetrics().averageCharWidth() * ENGINE_CHARS
        # (it gives way first: the least it asks room for is the start of its word)
        self.label = window.engine_label = FittedLabel("engine", elide, lambda t: t[:6], most)
        self.label.setContentsMargins(0, 0, 16, 0)  # apart from the preset and model
        window.statusBar().insertPermanentWidget(0, self.label)
        self.timer = QtCore.QTimer(window)
        self.timer.timeout.connect(self.show)
        self.timer.start(ENGINE_POLL_MS)
        self.show()

    def show(self) -> None:
        tiers.preload()  # looks for the ready marker (a stat at most every tiers.POLL seconds)
        text = tiers.status() or ""
        if text != self.label.text():
            self.label.setText(text)  # (drawn cut to fit, whole in its tooltip)
        if not text and (tiers.loaded() or tiers.mode() != "auto"):
            self.timer.stop()
