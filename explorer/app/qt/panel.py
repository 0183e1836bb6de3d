"""The explorer's control panel's widgets: Qt widgets that show a value of a
:class:`~explorer.app.model.State` and signal a user's change (the number field, the slider
with its field, the colour button and dialog, the mesh's own materials). Nothing of the model
lives here: every widget is set from the state (signals blocked), and a user's change goes to
the controller (``set_value`` for a row of :mod:`explorer.app.panelmodel`, drawn by
:mod:`explorer.app.qt.rows`; the window's ``act(action, *args, label=..., merge=...)`` for the
rest).

Three tabs (:mod:`explorer.app.qt.lightpanel`): ``material`` (preset list, coefficients,
colours, model, terms, the material's effects), ``lights`` (the scene's lights and the selected
one's rows: type, colour, placement, attenuation, cone, shadows) and ``view`` (mesh, difference
and compare views, the scene's effects). Each widget is named like the scene file's key it
sets.
"""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app import model as M
from explorer.app.colours import rgb_bytes, rgb_text, swatch_squares, text_on
from explorer.app.rowlayout import part_name
from explorer.core.controls import CONTROLS, STEPS, Control, from_step, to_step
from explorer.core.errors import ExplorerError


def qcolour(rgb) -> QtGui.QColor:
    """:func:`rgb_bytes` as a ``QColor`` (8-bit, exact)."""
    return QtGui.QColor(*rgb_bytes(rgb))


class NumberField(QtWidgets.QDoubleSpinBox):
    """A number field for the state's key ``key`` that never changes a typed value behind the
    user's back: any text may be typed, and on Enter (or leaving the field) a value outside
    ``[lo, hi]``, or no number at all, is refused with ``rejected(message)`` (naming the key
    and the range, :func:`explorer.app.model.parse_number`) and the field shows again the value
    it held (the state's). A value inside the range is taken as QDoubleSpinBox takes it."""

    rejected = QtCore.Signal(str)

    def __init__(self, key: str, lo: float, hi: float, *, decimals: int = 3, suffix: str = "",
                 parent=None):  # fmt: skip
        super().__init__(parent)
        self.key = key
        self.setDecimals(decimals)
        self.setRange(lo, hi)
        self.setSuffix(suffix)
        self.setKeyboardTracking(False)

    def validate(self, text: str, pos: int):
        """Every text may be typed (Qt's own check would drop the keys that leave the range,
        turning 5000 into 500); :meth:`check` judges it when it is entered."""
        body = text.removesuffix(self.suffix()).strip()
        try:
            float(body)
        except ValueError:
            return QtGui.QValidator.State.Intermediate, text, pos
        return QtGui.QValidator.State.Acceptable, text, pos

    def check(self) -> bool:
        """True when the text is a value in range (or unchanged); else reject it (the signal)
        and show the field's value again."""
        text = self.lineEdit().text()
        if text == self.textFromValue(self.value()) + self.suffix() or (
            text == self.textFromValue(self.value())
        ):
            return True
        try:
            M.parse_number(self.key, text.removesuffix(self.suffix()), self.minimum(),
                           self.maximum())  # fmt: skip
        except ExplorerError as exc:
            self.lineEdit().setText(self.textFromValue(self.value()) + self.suffix())
            self.rejected.emit(str(exc))
            return False
        return True

    def keyPressEvent(self, event: QtGui.QKeyEvent) -> None:  # noqa: N802 - Qt's name
        if event.key() in (QtCore.Qt.Key.Key_Return, QtCore.Qt.Key.Key_Enter) and not self.check():
            event.accept()
            return
        super().keyPressEvent(event)

    def focusOutEvent(self, event: QtGui.QFocusEvent) -> None:  # noqa: N802 - Qt's name
        self.check()
        super().focusOutEvent(event)

    def stepBy(self, steps: int) -> None:  # noqa: N802 - Qt's name
        if self.check():
            super().stepBy(steps)


class WheelToScroll(QtCore.QObject):
    """An event filter for the panel's sliders, number fields and choosers: a wheel turned over
    one that does not have the keyboard focus scrolls the panel (the nearest scroll area)
    instead of changing the value; once clicked (focused) the wheel changes it."""

    def eventFilter(self, obj, event) -> bool:  # noqa: N802 - Qt's name
        if event.type() != QtCore.QEvent.Type.Wheel or obj.hasFocus():
            return False
        area = obj.parentWidget()
        while area is not None and not isinstance(area, QtWidgets.QScrollArea):
            area = area.parentWidget()
        if area is not None:
            QtWidgets.QApplication.sendEvent(area.verticalScrollBar(), event)
        return True


def guard_wheel(root: QtWidgets.QWidget) -> WheelToScroll:
    """Install :class:`WheelToScroll` on every slider, spin box and combo box under ``root``
    (they take the focus by click or Tab, not by the wheel). Returns the filter (keep it)."""
    f = WheelToScroll(root)
    for kind in (QtWidgets.QAbstractSlider, QtWidgets.QAbstractSpinBox, QtWidgets.QComboBox):
        for w in root.findChildren(kind):
            w.setFocusPolicy(QtCore.Qt.FocusPolicy.StrongFocus)
            w.installEventFilter(f)
    return f


class ValueSlider(QtWidgets.QWidget):
    """A labelled slider with a number field. ``edited(value)`` while the user drags or
    types; ``released()`` when a drag ends (one undo step).

    name : a key of :data:`explorer.core.controls.CONTROLS`, whose entry gives the slider's
    range, the field's range, decimals and unit, and the scale (log for the shininess)
    """

    edited = QtCore.Signal(float)
    pressed = QtCore.Signal()
    released = QtCore.Signal()
    rejected = QtCore.Signal(str)

    def __init__(self, name: str, parent=None):
        super().__init__(parent)
        self.setObjectName(name)
        c: Control = CONTROLS[name]
        self.control = c
        self.lo, self.hi, self.log = c.lo, c.hi, c.scale == "log"
        self.label = QtWidgets.QLabel(name)
        self.label.setMinimumWidth(64)
        self.slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.slider.setObjectName(part_name(name, "slider"))  # (the page's aria-label too)
        self.slider.setAccessibleName(part_name(name, "slider"))
        self.slider.setRange(0, STEPS)
        self.slider.setMinimumWidth(60)
        self.field = NumberField(name, *c.field_range, decimals=c.decimals, suffix=c.unit)
        self.field.setObjectName(f"{name}_field")
        self.field.setSingleStep(c.field_step)
        self.field.setMinimumWidth(72)
        self.field.rejected.connect(self.rejected)
        self.note = QtWidgets.QLabel("")  # a second line (the distance in world units)
        self.note.setVisible(False)
        grid = QtWidgets.QGridLayout(self)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.addWidget(self.label, 0, 0)
        grid.addWidget(self.slider, 0, 1)
        grid.addWidget(self.field, 0, 2)
        grid.addWidget(self.note, 1, 1, 1, 2)
        grid.setColumnStretch(1, 1)
        self.slider.valueChanged.connect(self._from_slider)
        self.slider.sliderPressed.connect(self.pressed)
        self.slider.sliderReleased.connect(self.released)
        self.field.valueChanged.connect(self._from_field)

    def _to_step(self, v: float) -> int:
        return to_step(self.control, v, self.lo, self.hi)

    def _from_step(self, step: int) -> float:
        return from_step(self.control, step, self.lo, self.hi)

    def _from_slider(self, step: int) -> None:
        v = round(self._from_step(step), self.field.decimals())
        with QtCore.QSignalBlocker(self.field):
            self.field.setValue(v)
        self.edited.emit(v)
        if not self.slider.isSliderDown():  # a click or a key: a whole step
            self.released.emit()

    def _from_field(self, v: float) -> None:
        with QtCore.QSignalBlocker(self.slider):
            self.slider.setValue(self._to_step(v))
        self.edited.emit(float(v))
        self.released.emit()

    def set_range(self, lo: float, hi: float) -> None:
        self.lo, self.hi = float(lo), float(hi)
        self.field.setRange(min(self.field.minimum(), lo), max(self.field.maximum(), hi))

    def set_value(self, v: float) -> None:
        """Show ``v`` (no signal; nothing done when it is shown already: the control a user
        moves is not set back)."""
        step = self._to_step(v)
        if step == self.slider.value() and self.field.value() == round(v, self.field.decimals()):
            return
        with QtCore.QSignalBlocker(self.slider), QtCore.QSignalBlocker(self.field):
            self.slider.setValue(step)
            self.field.setValue(v)

    def value(self) -> float:
        return float(self.field.value())


class ColourDialog(QtWidgets.QColorDialog):
    """Qt's colour dialog (non-native, so it can be driven in tests) with a ``value`` field
    that takes the colour typed as ``r, g, b`` (0 .. 1) or ``#rrggbb``
    (:func:`explorer.app.model.parse_colour`); a typed value is kept exactly (Qt's colours hold
    16 bits a channel). ``picked(rgb)`` carries the choice."""

    picked = QtCore.Signal(tuple)

    def __init__(self, key: str, rgb, parent=None):
        super().__init__(parent)
        self.key = key
        self.setObjectName(f"{key}_dialog")
        self.setOption(QtWidgets.QColorDialog.ColorDialogOption.DontUseNativeDialog, True)
        self.setWindowTitle(f"{key} colour")
        self.typed: tuple | None = None
        self.value = QtWidgets.QLineEdit(rgb_text(rgb))
        self.value.setObjectName("colour_value")
        self.value.setPlaceholderText("r, g, b (each 0 .. 1) or #rrggbb")
        self.value.setToolTip(f"type the {key} as r, g, b (each 0 .. 1) or as #rrggbb, then Enter")
        self.problem = QtWidgets.QLabel("")
        self.problem.setObjectName("colour_problem")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #c0392b;")
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("value"))
        row.addWidget(self.value, 1)
        lay = self.layout()
        lay.insertLayout(lay.count() - 1, row)
        lay.insertWidget(lay.count() - 1, self.problem)
        self.problem.setVisible(False)
        self.setCurrentColor(qcolour(rgb))
        self.value.returnPressed.connect(self.take_typed)
        self.currentColorChanged.connect(self._shown)
        self.colorSelected.connect(self._selected)

    def take_typed(self) -> bool:
        """Read the ``value`` field: the dialog shows that colour, or says what is wrong."""
        try:
            rgb = M.parse_colour(self.key, self.value.text())
        except ExplorerError as exc:
            self.problem.setText(str(exc))
            self.problem.setVisible(True)
            return False
        self.problem.setVisible(False)
        self.typed = rgb
        with QtCore.QSignalBlocker(self):
            self.setCurrentColor(qcolour(rgb))
        self.value.setModified(False)
        return True

    def _shown(self, c: QtGui.QColor) -> None:  # picked with the mouse or Qt's own fields
        self.typed = None
        self.problem.setVisible(False)
        self.value.setText(rgb_text((c.redF(), c.greenF(), c.blueF())))

    def accept(self) -> None:
        if self.value.isModified() and not self.take_typed():
            return  # the typed value is wrong: said so, the dialog stays open
        super().accept()

    def _selected(self, c: QtGui.QColor) -> None:
        rgb = self.typed if self.typed is not None and qcolour(self.typed) == c else None
        self.picked.emit(rgb or (c.redF(), c.greenF(), c.blueF()))


class ColourButton(QtWidgets.QPushButton):
    """A button showing a colour value and its RGB; a click opens a :class:`ColourDialog`, and
    ``picked(rgb)`` carries the choice. The swatch is painted here (no style sheet, which would
    also colour the dialog, the button's child) in exactly the 8-bit colour the view draws for
    the value (:func:`rgb_bytes`)."""

    picked = QtCore.Signal(tuple)
    #: the frame of the button around the swatch (pixels)
    INSET = 3

    def __init__(self, name: str, parent=None):
        super().__init__(parent)
        self.setObjectName(name)
        self.name = name
        self.rgb = (0.0, 0.0, 0.0)
        self.dialog: ColourDialog | None = None
        self.clicked.connect(self.open_dialog)

    def set_rgb(self, rgb) -> None:
        self.rgb = tuple(float(c) for c in rgb)
        self.setText(rgb_text(self.rgb))
        self.setToolTip(f"{self.name}: {rgb_text(self.rgb)}, drawn as the 8-bit "
                        f"{rgb_bytes(self.rgb)} as the view draws it (click to pick)")  # fmt: skip
        self.update()

    def swatch_rect(self) -> QtCore.QRect:
        """Where the colour is painted (the button less its frame)."""
        k = self.INSET
        return self.rect().adjusted(k, k, -k, -k)

    def paintEvent(self, event) -> None:  # noqa: N802 - Qt's name
        p = QtWidgets.QStylePainter(self)
        opt = QtWidgets.QStyleOptionButton()
        self.initStyleOption(opt)
        opt.text = ""
        p.drawControl(QtWidgets.QStyle.ControlElement.CE_PushButton, opt)
        colour = qcolour(self.rgb)
        p.fillRect(self.swatch_rect(), colour)
        p.setPen(QtGui.QColor(text_on(self.rgb)))  # the text colour of higher contrast
        p.drawText(self.swatch_rect(), QtCore.Qt.AlignmentFlag.AlignCenter, self.text())
        p.end()

    def open_dialog(self) -> ColourDialog:
        d = ColourDialog(self.name, self.rgb, self)
        d.picked.connect(self.picked)
        d.finished.connect(lambda _: setattr(self, "dialog", None))
        self.dialog = d
        d.open()
        return d


def _form(parent=None) -> QtWidgets.QVBoxLayout:
    box = QtWidgets.QVBoxLayout(parent)
    box.setContentsMargins(6, 6, 6, 6)
    box.setSpacing(6)
    return box


def _scroll(widget: QtWidgets.QWidget) -> QtWidgets.QScrollArea:
    area = QtWidgets.QScrollArea()
    area.setWidget(widget)
    area.setWidgetResizable(True)
    area.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAsNeeded)
    area.setFrameShape(QtWidgets.QFrame.Shape.NoFrame)
    return area


def swatch(material, size: int = 18) -> QtGui.QIcon:
    """A small square of the material's diffuse colour with its specular colour in a corner
    (:func:`~explorer.app.colours.swatch_squares`)."""
    pm = QtGui.QPixmap(size, size)
    p = QtGui.QPainter(pm)
    for x, y, w, h, rgb in swatch_squares(material, size):
        p.fillRect(x, y, w, h, QtGui.QColor(*rgb))
    p.end()
    return QtGui.QIcon(pm)
