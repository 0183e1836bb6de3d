"""The window's message log: every message of the session (information, warnings, errors),
whole and copyable, in a dialog (View ▸ Messages, or the status bar's indicator). The status
bar has room for one short line; a message that does not fit it, or that comes with details
(an OBJ's material warnings), opens the log."""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app.captions import SEPARATOR
from explorer.app.messagelog import LEVEL_COLOURS, Message, opens_log
from explorer.app.messagelog import MessageLog as Said

#: how long a status message stays (ms); errors stay until the next message
MESSAGE_MS = 6000


class MessageLog(QtWidgets.QDialog):
    """The log (non-modal): a read-only text of every message (``said``, the kit's
    :class:`~explorer.app.messagelog.MessageLog`), a Copy all button."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setObjectName("messages")
        self.setWindowTitle("phong-explorer: messages")
        self.said = Said()
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
        m = self.said.add(level, text, details)
        self.text.appendPlainText("\n".join(m.lines()))
        return m

    def plain_text(self) -> str:
        return self.text.toPlainText()

    def copy_all(self) -> None:
        QtGui.QGuiApplication.clipboard().setText(self.plain_text())


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
        text, colour = self.log.said.tally()
        self.setText(text)
        self.setStyleSheet(f"color: {colour};" if colour else "")
        self.setToolTip("every message of this session, whole and copyable (View ▸ Messages)")


class FittedLabel(QtWidgets.QLabel):
    """A one-line label of the status bar that draws as much of its text as its width allows,
    and marks what it leaves out with "…" (a plain ``QLabel`` squeezed by the bar, in a narrow
    window or beside the long engine word, was cut mid-word with no mark: "hidden: diffuse_",
    or "hidden:" with nothing after it). ``text()`` is the whole text, also its tooltip;
    :meth:`shown` is what is drawn at the label's present width (fitted at each paint, so a
    text set before the bar lays itself out again is drawn for the width it gets).

    shorten : ``(text, metrics, width) -> str``, the text made to fit ``width`` pixels
        (:func:`elide`, :func:`shorten_summary`)
    least : ``(text) -> str``, the shortest form the label asks room for (its minimum size)
    most : the widest text the label asks room for (pixels), or None: its whole text
    """

    def __init__(self, name: str, shorten, least, most: int | None = None):
        super().__init__("")
        self.setObjectName(name)
        self._shorten, self._least, self._most = shorten, least, most

    def setText(self, text: str) -> None:  # noqa: N802 - Qt's name
        super().setText(text)
        self.setToolTip(text)
        self.updateGeometry()

    def shown(self) -> str:
        """The text as drawn at the label's present width."""
        return self._shorten(self.text(), self.fontMetrics(), self.contentsRect().width())

    def _width(self, text: str, most: int | None = None) -> int:
        """The label's width for ``text`` (pixels, its margins too), its text at most ``most``."""
        m = self.contentsMargins()
        advance = self.fontMetrics().horizontalAdvance(text)
        return min(advance, advance if most is None else most) + m.left() + m.right() + 1

    def sizeHint(self) -> QtCore.QSize:  # noqa: N802 - Qt's name
        return QtCore.QSize(self._width(self.text(), self._most), super().sizeHint().height())

    def minimumSizeHint(self) -> QtCore.QSize:  # noqa: N802 - Qt's name
        width = min(self._width(self._least(self.text())), self.sizeHint().width())
        return QtCore.QSize(width, super().minimumSizeHint().height())

    def paintEvent(self, event: QtGui.QPaintEvent) -> None:  # noqa: N802 - Qt's name
        """Draw :meth:`shown` as a ``QLabel`` draws its text (the style's colours)."""
        painter = QtGui.QPainter(self)
        align = self.alignment() | QtCore.Qt.AlignmentFlag.AlignVCenter
        rect, role = self.contentsRect(), self.foregroundRole()
        style, palette, text = self.style(), self.palette(), self.shown()
        style.drawItemText(painter, rect, align, palette, self.isEnabled(), text, role)
        painter.end()


def elide(text: str, metrics: QtGui.QFontMetrics, width: int) -> str:
    """``text`` cut at its end to ``width`` pixels, "…" marking the cut."""
    return metrics.elidedText(text, QtCore.Qt.TextElideMode.ElideRight, width)


def shorten_summary(text: str, metrics: QtGui.QFontMetrics, width: int) -> str:
    """The state's summary (:func:`explorer.app.captions.summary`: the material, the model,
    what is hidden) in ``width`` pixels: whole when it fits; else the material's name is cut
    first (``textured_te…;  blinn;  hidden: diffuse_map``), so the model and every hidden
    term and map stay whole; else the whole line is cut at its end."""
    if metrics.horizontalAdvance(text) <= width:
        return text
    what, sep, rest = text.partition(SEPARATOR)
    room = width - metrics.horizontalAdvance(sep + rest)
    if sep and room >= metrics.horizontalAdvance("…"):
        return elide(what, metrics, room) + sep + rest
    return elide(text, metrics, width)


def summary_least(text: str) -> str:
    """The summary's shortest form the status bar leaves room for: the material's name cut to
    "…", the rest whole (:func:`shorten_summary`)."""
    what, sep, rest = text.partition(SEPARATOR)
    return "…" + sep + rest if sep else text


def open_log(log: MessageLog) -> None:
    """Show the log at its last line (raised, without taking the keyboard from the view)."""
    log.setAttribute(QtCore.Qt.WidgetAttribute.WA_ShowWithoutActivating, True)
    log.show()
    log.raise_()
    bar = log.text.verticalScrollBar()
    bar.setValue(bar.maximum())


class MessageBar:
    """The window's status bar and message log: the state's summary (``status_label``), the
    log (``messages``) and its indicator (``messages_indicator``), all set on ``window``,
    whose ``message`` is the last message shown."""

    def __init__(self, window):
        self.window = w = window
        w.status_label = FittedLabel("status", shorten_summary, summary_least)
        w.statusBar().addPermanentWidget(w.status_label)
        w.messages = MessageLog(w)
        w.messages_indicator = MessageIndicator(w.messages)
        w.statusBar().addPermanentWidget(w.messages_indicator)

    def show(self, text: str, level: str = "info", details=(), msecs: int | None = None,
             open_log_: bool = True) -> None:  # fmt: skip
        """Show a short message on the status bar (errors stay until the next message) and add
        it to the message log; the log opens when the message is an error or a warning that
        the status bar cannot show whole, or comes with ``details`` (each a line of the log).
        ``open_log_=False``: never opens it (the details are shown in a dialog already)."""
        w = self.window
        w.message = text
        bar = w.statusBar()
        bar.setStyleSheet(f"color: {LEVEL_COLOURS[level]};" if level in LEVEL_COLOURS else "")
        bar.showMessage(text, 0 if level == "error" else int(msecs or MESSAGE_MS))
        if not text:  # the message shown taken away: nothing to log
            return
        w.messages.add(level, text, details)
        w.messages_indicator.refresh()
        if open_log_ and opens_log(level, details, self._fits_status_bar(text)):
            open_log(w.messages)

    def _fits_status_bar(self, text: str) -> bool:
        """Whether ``text`` shows whole in the status bar's message area (the bar less its
        permanent widgets)."""
        w = self.window
        bar = w.statusBar()
        widgets = (getattr(w, "engine_label", None), w.status_label, w.messages_indicator)
        taken = sum(x.width() + 8 for x in widgets if x is not None and x.isVisible())
        return bar.fontMetrics().horizontalAdvance(text) <= max(bar.width() - taken - 16, 0)
