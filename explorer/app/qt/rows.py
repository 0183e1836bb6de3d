"""The panel's rows drawn in Qt: one widget factory per kind of
:class:`~explorer.app.panelmodel.Row` (number, colour, choice, toggle, triple, list, button).
Nothing here knows a control: :class:`RowWidgets` builds the widgets of any rows, shows a state
in them (:meth:`RowWidgets.show_state`: each row's ``visible``, ``value`` and items, signals
blocked) and sends every edit as ``set_value(key, value, merge=...)`` (the controller's one
dialect).

Every row's widget (or the box of one drawn as several widgets) is named like its key, as
object name and accessible name; a row's label is its caption (its key unless it says other
words: a term's toggle its term). A list is a list widget (a searched one with its search
field ``<key>_search`` above and its selected item's subtitle ``<key>_description`` below); a
choice whose values are not fixed (side B's preset, the mesh's groups) a combo box of its items;
a button is enabled when its value says it can be pressed; a text a label; an image (a texture
map) its caption over a line of its thumbnail ``<key>_thumbnail`` (made once per file:
:func:`explorer.render.textures.thumbnail`), its file's name ``<key>_file``, the toggle
``<key>_on``, ``<key>_choose`` (the window's file dialog) and ``<key>_clear``.
"""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from explorer.app.panelmodel import ASK_FILE, Item, Row
from explorer.app.qt.panel import ColourButton, NumberField, ValueSlider, swatch
from explorer.app.rowlayout import file_text, image_part, lines, part_name
from explorer.core.errors import ExplorerError
from explorer.render.textures import THUMBNAIL_SIZE, thumbnail

#: a label's least width (pixels): the labels of a tab line up with the sliders' own
LABEL_WIDTH = 64


def _label(text: str) -> QtWidgets.QLabel:
    label = QtWidgets.QLabel(text)
    label.setMinimumWidth(LABEL_WIDTH)
    return label


def _named(widget: QtWidgets.QWidget, name: str, tip: str = "") -> QtWidgets.QWidget:
    widget.setObjectName(name)
    widget.setAccessibleName(name)
    if tip:
        widget.setToolTip(tip)
    return widget


class RowWidgets(QtCore.QObject):
    """The widgets of ``rows`` added to ``box`` (a ``QVBoxLayout``) in order; rows of one
    ``group`` share a grid (colours) or a line (toggles, buttons, in a group of their own).

    send(key, value, merge=...) : the edit (``Controller.set_value``)
    after : key -> the front end's own widgets or layouts drawn after that row (the difference
        view's legend); they show and hide themselves
    ``rejected(message)``: a typed value was refused; ``widgets[key]``: each row's widget
    (a :class:`ValueSlider`, :class:`ColourButton`, ``QComboBox``, ``QCheckBox``,
    ``QListWidget``, ``QPushButton``, or the box of radio buttons / three fields),
    ``parts[key]``: every widget the row shows or hides; ``items[key]``: a list's (or a
    choice's) items shown.
    """

    rejected = QtCore.Signal(str)

    def __init__(self, rows, box: QtWidgets.QVBoxLayout, send, parent=None, after=None):
        super().__init__(parent)
        self.rows = tuple(rows)
        self.send = send
        self.widgets: dict[str, QtWidgets.QWidget] = {}
        self.parts: dict[str, list[QtWidgets.QWidget]] = {}
        self.switches: dict[str, QtWidgets.QCheckBox] = {}  # an optional number's on / off
        self.radios: dict[str, dict[str, QtWidgets.QRadioButton]] = {}
        self.fields: dict[str, list[NumberField]] = {}  # a triple's three fields
        self.sliders: dict[str, ValueSlider] = {}  # a number's slider and field
        self.items: dict[str, tuple[Item, ...]] = {}
        self.searches: dict[str, QtWidgets.QLineEdit] = {}  # a searched list's field
        self.descriptions: dict[str, QtWidgets.QLabel] = {}  # its selected item's subtitle
        self.images: dict[str, dict[str, QtWidgets.QWidget]] = {}  # an image's parts
        for how, group in lines(self.rows):  # (the kit's layout: lines, grids, rows)
            if how == "line":
                line = QtWidgets.QHBoxLayout()
                box.addLayout(line)
                for r in group:
                    self._add(r, getattr(self, f"_{r.kind}")(r), line)
                if group[0].kind == "toggle":  # toggles kept left; buttons share the width
                    line.addStretch(1)
            elif how == "grid":
                grid = QtWidgets.QGridLayout()
                grid.setColumnStretch(1, 1)
                box.addLayout(grid)
                for n, r in enumerate(group):
                    label, widget = _label(r.caption), getattr(self, f"_{r.kind}")(r)
                    grid.addWidget(label, n, 0)
                    grid.addWidget(widget, n, 1)
                    self.widgets[r.key] = widget
                    self.parts[r.key] = [label, widget]
            elif group[0].kind == "list":
                self._list(group[0], box)
            else:
                self._add(group[0], getattr(self, f"_{group[0].kind}")(group[0]), box)
            for r in group:
                for extra in (after or {}).get(r.key, ()):
                    (box.addLayout if isinstance(extra, QtWidgets.QLayout) else box.addWidget)(
                        extra
                    )

    def _add(self, r: Row, widget: QtWidgets.QWidget, layout) -> None:
        layout.addWidget(widget)
        self.widgets[r.key] = widget
        self.parts[r.key] = [widget]

    # -- one factory per kind ----------------------------------------------------------------
    def _number(self, r: Row) -> QtWidgets.QWidget:
        s = ValueSlider(r.key)
        s.setAccessibleName(r.key)
        if r.tip:
            s.setToolTip(r.tip)
        s.note.setVisible(r.note is not None)
        s.note.setWordWrap(True)
        s.rejected.connect(self.rejected)
        s.edited.connect(lambda v, k=r.key: self.send(k, v, merge=True))
        self.sliders[r.key] = s
        if r.optional is None:
            return s
        box = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(box)
        lay.setContentsMargins(0, 0, 0, 0)
        switch = _named(QtWidgets.QCheckBox(r.key), part_name(r.key, "on"), r.tip)
        switch.toggled.connect(
            lambda on, k=r.key, v=r.optional: self.send(k, v if on else None, merge=False)
        )
        lay.addWidget(switch)
        lay.addWidget(s)
        self.switches[r.key] = switch
        return box

    def _colour(self, r: Row) -> QtWidgets.QWidget:
        b = ColourButton(r.key)
        b.setAccessibleName(r.key)
        b.picked.connect(lambda rgb, k=r.key: self.send(k, rgb, merge=False))
        return b

    def _values(self, r: Row) -> tuple:
        """A choice's or a list's values, in the order shown."""
        return r.choices or tuple(i.value for i in self.items.get(r.key, ()))

    def _choice(self, r: Row) -> QtWidgets.QWidget:
        if not r.inline:
            combo = _named(QtWidgets.QComboBox(), r.key, r.tip)
            combo.addItems(list(r.choices))
            if r.source or r.items:  # its items come and go: long names do not widen it
                combo.setSizeAdjustPolicy(
                    QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
                )
                combo.setMinimumContentsLength(8)
            combo.activated.connect(
                lambda i, k=r.key, r=r: self.send(k, self._values(r)[i], merge=False)
            )
            return combo
        box = _named(QtWidgets.QWidget(), r.key, r.tip)
        row = QtWidgets.QHBoxLayout(box)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QtWidgets.QLabel(r.caption))
        group = QtWidgets.QButtonGroup(box)
        self.radios[r.key] = {}
        for name in r.choices:
            b = QtWidgets.QRadioButton(name)
            b.setObjectName(name)
            group.addButton(b)
            b.toggled.connect(lambda on, k=r.key, n=name: on and self.send(k, n, merge=False))
            row.addWidget(b)
            self.radios[r.key][name] = b
        row.addStretch(1)
        return box

    def _toggle(self, r: Row) -> QtWidgets.QWidget:
        c = _named(QtWidgets.QCheckBox(r.caption), r.key, r.tip)
        c.toggled.connect(lambda on, k=r.key: self.send(k, on, merge=False))
        return c

    def _text(self, r: Row) -> QtWidgets.QWidget:
        label = _named(QtWidgets.QLabel(""), r.key, r.tip)
        label.setWordWrap(True)
        return label

    def _button(self, r: Row) -> QtWidgets.QWidget:
        b = _named(QtWidgets.QPushButton(r.caption), r.key, r.tip)
        b.clicked.connect(lambda _=False, k=r.key: self.send(k, True, merge=False))
        return b

    def _image(self, r: Row) -> QtWidgets.QWidget:
        """A texture map: its key over its thumbnail, its file's name, on / off, choose, clear."""
        box = _named(QtWidgets.QWidget(), r.key, r.tip)
        lay = QtWidgets.QGridLayout(box)
        lay.setContentsMargins(0, 0, 0, 0)
        thumb = _named(QtWidgets.QLabel(), f"{r.key}_thumbnail")
        thumb.setFixedSize(THUMBNAIL_SIZE, THUMBNAIL_SIZE)
        thumb.setAlignment(QtCore.Qt.AlignmentFlag.AlignCenter)
        thumb.setFrameShape(QtWidgets.QFrame.Shape.StyledPanel)
        name = _named(QtWidgets.QLabel(""), *image_part(r, "file"))
        name.setMinimumWidth(40)
        on = _named(QtWidgets.QCheckBox("on"), *image_part(r, "on"))
        on.toggled.connect(lambda v, k=r.key: self.send(k, bool(v), merge=False))
        choose = _named(QtWidgets.QPushButton("choose…"), *image_part(r, "choose"))
        choose.clicked.connect(lambda _=False, k=r.key: self.send(k, ASK_FILE, merge=False))
        clear = _named(QtWidgets.QPushButton("clear"), *image_part(r, "clear"))
        clear.clicked.connect(lambda _=False, k=r.key: self.send(k, None, merge=False))
        lay.addWidget(QtWidgets.QLabel(r.caption), 0, 0, 1, 4)
        lay.addWidget(thumb, 1, 0, 2, 1)
        lay.addWidget(name, 1, 1, 1, 3)
        lay.addWidget(on, 2, 1)
        lay.addWidget(choose, 2, 2)
        lay.addWidget(clear, 2, 3)
        lay.setColumnStretch(1, 1)
        self.images[r.key] = {"thumbnail": thumb, "file": name, "on": on, "clear": clear}
        return box

    def _triple(self, r: Row) -> QtWidgets.QWidget:
        """Three number fields (the attenuation's kc, kl, kq), a row a part (a narrow panel),
        under a line saying what they are (the row's tip)."""
        box = _named(QtWidgets.QWidget(), r.key)
        grid = QtWidgets.QGridLayout(box)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.addWidget(QtWidgets.QLabel(f"{r.key}  {r.tip}"), 0, 0, 1, 3)
        c = r.control
        self.fields[r.key] = []
        for k, part in enumerate(r.choices):
            f = NumberField(part, *c.field_range, decimals=c.decimals)
            f.setObjectName(f"{r.key}_{part}")
            f.setSingleStep(c.field_step)
            f.setToolTip(f"{part} of {r.tip}")
            f.valueChanged.connect(lambda _v, key=r.key: self._send_triple(key))
            f.rejected.connect(self.rejected)
            grid.addWidget(_label(part), 1 + k, 0)
            grid.addWidget(f, 1 + k, 2)
            self.fields[r.key].append(f)
        grid.setColumnStretch(1, 1)
        return box

    def _send_triple(self, key: str) -> None:
        self.send(key, tuple(f.value() for f in self.fields[key]), merge=False)

    def _list(self, r: Row, box: QtWidgets.QVBoxLayout) -> None:
        """A list widget; a searched one (a long list: it takes the tab's spare height) with its
        search field above and its selected item's subtitle below, and an item is taken by a
        click (the keys browse it); another takes its current item (a short list)."""
        w = _named(QtWidgets.QListWidget(), r.key, r.tip)
        w.setWordWrap(True)  # a long line (a duplicate light's) wraps in a narrow panel
        w.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.widgets[r.key] = w
        self.parts[r.key] = [w]
        self.items[r.key] = ()
        if not r.search:
            w.setMinimumHeight(60)
            w.setMaximumHeight(110)
            w.currentRowChanged.connect(
                lambda i, r=r: i >= 0 and self.send(r.key, self._values(r)[i], merge=False)
            )
            box.addWidget(w)
            return
        search = QtWidgets.QLineEdit()
        search.setObjectName(f"{r.key}_search")
        search.setPlaceholderText(f"search {r.key}s")
        search.setClearButtonEnabled(True)
        description = QtWidgets.QLabel("")
        description.setObjectName(f"{r.key}_description")
        description.setWordWrap(True)
        w.setMinimumHeight(90)
        w.setIconSize(QtCore.QSize(18, 18))
        self.searches[r.key], self.descriptions[r.key] = search, description
        self.parts[r.key] = [search, w, description]
        search.textChanged.connect(lambda _t, r=r: self._filter(r))
        w.itemClicked.connect(
            lambda item, r=r: self.send(r.key, self._values(r)[w.row(item)], merge=False)
        )
        w.currentRowChanged.connect(lambda i, r=r: self._describe(r, i))
        box.addWidget(search)
        box.addWidget(w, 1)  # the list takes the spare height
        box.addWidget(description)

    def show_items(self, source: str, items) -> None:
        """The items of every row whose items come from catalogue ``source`` (the presets)."""
        for r in self.rows:
            if r.source == source:
                self._set_items(r, tuple(items))

    def _set_items(self, r: Row, items: tuple[Item, ...]) -> None:
        if items == self.items.get(r.key):
            return
        self.items[r.key] = items
        w = self.widgets[r.key]
        with QtCore.QSignalBlocker(w):
            w.clear()
            for it in items:
                if r.kind == "choice":
                    icon = QtGui.QIcon() if it.swatch is None else swatch(it.swatch, 16)
                    w.addItem(icon, it.title)
                    continue
                item = QtWidgets.QListWidgetItem(it.title)
                if it.swatch is not None:
                    item.setIcon(swatch(it.swatch))
                item.setToolTip(it.subtitle or it.title)
                w.addItem(item)
        if r.key in self.searches:
            self._filter(r)

    def _filter(self, r: Row) -> None:
        """A searched list shows the items whose title or subtitle has the typed words."""
        t = self.searches[r.key].text().strip().lower()
        w = self.widgets[r.key]
        for i, it in enumerate(self.items[r.key]):
            w.item(i).setHidden(bool(t) and t not in f"{it.title} {it.subtitle}".lower())

    def _describe(self, r: Row, i: int) -> None:
        items = self.items[r.key]
        self.descriptions[r.key].setText(items[i].subtitle if 0 <= i < len(items) else "")

    # -- showing a state ---------------------------------------------------------------------
    def show_state(self, s) -> None:
        """Each row shown or hidden (``visible``) and set to its value (no signal sent)."""
        for r in self.rows:
            on = r.visible(s)
            for w in self.parts[r.key]:
                w.setVisible(on)
            if on:
                getattr(self, f"_show_{r.kind}")(r, self.widgets[r.key], r.value(s), s)

    def _show_number(self, r: Row, w, v, s) -> None:
        if r.optional is not None:
            with QtCore.QSignalBlocker(self.switches[r.key]):
                self.switches[r.key].setChecked(v is not None)
            w = self.sliders[r.key]
            w.setVisible(v is not None)
            if v is None:
                return
        if r.slider is not None:
            w.set_range(*r.slider(s))
        w.set_value(v)
        if r.note is not None:
            w.note.setText(r.note(s))

    def _show_colour(self, r: Row, w, v, s) -> None:
        w.set_rgb(v)

    def _show_choice(self, r: Row, w, v, s) -> None:
        if r.items is not None:
            self._set_items(r, r.items(s))
        if not r.inline:
            values = self._values(r)
            with QtCore.QSignalBlocker(w):
                w.setCurrentIndex(values.index(v) if v in values else -1)
            return
        for name, b in self.radios[r.key].items():
            with QtCore.QSignalBlocker(b):
                b.setChecked(v == name)

    def _show_toggle(self, r: Row, w, v, s) -> None:
        with QtCore.QSignalBlocker(w):
            w.setChecked(bool(v))

    def _show_list(self, r: Row, w, v, s) -> None:
        if r.items is not None:
            self._set_items(r, r.items(s))
        values = self._values(r)
        i = values.index(v) if v in values else -1
        with QtCore.QSignalBlocker(w):
            w.setCurrentRow(i)
            if i >= 0:
                w.scrollToItem(w.item(i))
        if r.key in self.descriptions:
            self._describe(r, i)

    def _show_text(self, r: Row, w, v, s) -> None:
        w.setText(v)

    def _show_button(self, r: Row, w, v, s) -> None:
        w.setEnabled(bool(v))

    def _show_image(self, r: Row, w, v, s) -> None:
        file, on = v
        parts = self.images[r.key]
        thumb, name = parts["thumbnail"], parts["file"]
        with QtCore.QSignalBlocker(parts["on"]):
            parts["on"].setChecked(bool(on))
        parts["on"].setEnabled(file is not None)
        parts["clear"].setEnabled(file is not None)
        name.setText(file_text(file))
        name.setToolTip(file or image_part(r, "file")[1])
        if file is None:
            thumb.clear()
            return
        try:
            rgb = thumbnail(file, r.key)
        except ExplorerError:  # the file went away or changed: its name says it, no picture
            thumb.clear()
            return
        h, wd = rgb.shape[:2]
        image = QtGui.QImage(rgb.data, wd, h, 3 * wd, QtGui.QImage.Format.Format_RGB888)
        thumb.setPixmap(QtGui.QPixmap.fromImage(image.copy()))

    def _show_triple(self, r: Row, w, v, s) -> None:
        for f, x in zip(self.fields[r.key], v, strict=True):
            with QtCore.QSignalBlocker(f):
                f.setValue(x)
