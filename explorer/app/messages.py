"""The window's message log: every message of the session (information, warnings, errors),
whole and copyable, in a dialog (View ▸ Messages, or the status bar's indicator). The status
bar has room for one short line; a message that does not fit it, or that comes with details
(an OBJ's material warnings), opens the log."""

from __future__ import annotations

import time
from dataclasses import dataclass

from PySide6 import QtCore, QtGui, QtWidgets

#: the levels of a message, in the order of their weight
LEVELS = ("info", "warning", "error")


@dataclass(frozen=True)
class Message:
    """One message: ``level`` (one of :data:`LEVELS`), its text and its details (each whole),
    and when it came (``HH:MM:SS``)."""

    level: str
    text: str
    details: tuple[str, ...] = ()
    at: str = ""

    def lines(self) -> list[str]:
        head = f"{self.at} {self.level}: {self.text}"
        return [head, *(f"    {d}" for d in self.details)]


class MessageLog(QtWidgets.QDialog):
    """The log (non-modal): a read-only text of every message, a Copy all button."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setObjectName("messages")
        self.setWindowTitle("phong-explorer: messages")
        self.messages: list[Message] = []
        self.text = QtWidgets.QPlainTextEdit()
        self.text.setObjectName("messages_text")
        self.text.setReadOnly(True)
        self.text.setLineWrapMode(QtWidgets.QPlainTextEdit.LineWrapMode.WidgetWidth)
        copy = QtWidgets.QPushButton("Copy all")
        copy.setObjectName("messages_copy")
        copy.clicked.connect(self.copy_all)
        close = QtWidgets.QPushButton("Close")
        close.clicked.connect(self.hide)
        row = QtWidgets.QHBoxLayout()
        row.addStretch(1)
        row.addWidget(copy)
        row.addWidget(close)
        box = QtWidgets.QVBoxLayout(self)
        box.addWidget(self.text, 1)
        box.addLayout(row)
        self.resize(640, 300)

    def add(self, level: str, text: str, details=()) -> Message:
        m = Message(level, text, tuple(details), time.strftime("%H:%M:%S"))
        self.messages.append(m)
        self.text.appendPlainText("\n".join(m.lines()))
        return m

    def plain_text(self) -> str:
        return self.text.toPlainText()

    def copy_all(self) -> None:
        QtGui.QGuiApplication.clipboard().setText(self.plain_text())

    def count(self, level: str) -> int:
        return sum(m.level == level for m in self.messages)


class MessageIndicator(QtWidgets.QToolButton):
    """The status bar's indicator: the number of warnings and errors so far; a click opens the
    log."""

    def __init__(self, log: MessageLog, parent=None):
        super().__init__(parent)
        self.setObjectName("messages_indicator")
        self.log = log
        self.setAutoRaise(True)
        self.setToolButtonStyle(QtCore.Qt.ToolButtonStyle.ToolButtonTextOnly)
        self.clicked.connect(lambda: open_log(log))
        self.refresh()

    def refresh(self) -> None:
        e, w = self.log.count("error"), self.log.count("warning")
        parts = [f"{n} {noun}{'s' * (n != 1)}" for n, noun in ((e, "error"), (w, "warning")) if n]
        self.setText(", ".join(parts) or "messages")
        self.setStyleSheet("color: #ff7766;" if e else "color: #e0a030;" if w else "")
        self.setToolTip("every message of this session, whole and copyable (View ▸ Messages)")


def open_log(log: MessageLog) -> None:
    """Show the log at its last line (raised, without taking the keyboard from the view)."""
    log.setAttribute(QtCore.Qt.WidgetAttribute.WA_ShowWithoutActivating, True)
    log.show()
    log.raise_()
    bar = log.text.verticalScrollBar()
    bar.setValue(bar.maximum())
