"""The panel's three tabs and the panel itself (the widgets are :mod:`explorer.app.qt.panel`'s).
Each tab draws its rows of :mod:`explorer.app.panelmodel` (:class:`~explorer.app.qt.rows.
RowWidgets`: the preset list, the light list, the difference and compare views among them)
among the few controls that are not rows: the mesh's own materials and the preset's line, the
light buttons, the mesh chooser, the difference view's legend, the swap button."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from explorer.app import captions, intents, panelmodel
from explorer.app import model as M
from explorer.app.qt.panel import _form, _scroll, guard_wheel
from explorer.app.qt.rows import RowWidgets
from explorer.core.material import RGB_KEYS


class LightsTab(QtWidgets.QWidget):
    """The scene's lights (the list; add, duplicate, remove) and the selected light's
    controls."""

    def __init__(self, send, parent=None):
        super().__init__(parent)
        box = _form(self)
        self.rows = RowWidgets(panelmodel.rows("lights"), box, send, self)
        self.list, self.sliders = self.rows.widgets["light"], self.rows.sliders
        self.buttons = {n: self.rows.widgets[f"{n}_light"] for n in ("add", "duplicate", "remove")}
        self.type, self.colour = self.rows.widgets["type"], self.rows.widgets["color"]
        self.attenuation_box = self.rows.widgets["attenuation"]
        self.attenuation = self.rows.fields["attenuation"]
        self.cutoff, self.exponent = self.sliders["cutoff"], self.sliders["exponent"]
        box.addStretch(1)

    def show_state(self, s: M.State) -> None:
        self.rows.show_state(s)


class MaterialTab(QtWidgets.QWidget):
    """The material tab's rows (:mod:`explorer.app.panelmodel`: the mesh's own materials, the
    line naming the material, the presets, searchable, with descriptions and swatches;
    coefficients, colours, model, terms, the material's effects) and the save button."""

    def __init__(self, send, parent=None):
        super().__init__(parent)
        box = _form(self)
        self.rows = RowWidgets(panelmodel.rows("material"), box, send, self)
        self.preset_label = self.rows.widgets["material_line"]  # (a text row)
        self.presets, self.search = self.rows.widgets["preset"], self.rows.searches["preset"]
        self.description = self.rows.descriptions["preset"]
        self.sliders = self.rows.sliders
        self.colours = {t: self.rows.widgets[t] for t in RGB_KEYS}
        self.model = self.rows.radios["model"]
        self.terms = {t: self.rows.widgets[f"show_{t}"] for t in M.TERMS}
        self.save = QtWidgets.QPushButton(intents.BY_ID["save_preset"].label)
        self.save.setObjectName("save_preset")
        self.save.setToolTip(intents.tooltip("save_preset"))
        box.addWidget(self.save)

    def show_state(self, s: M.State) -> None:
        self.rows.show_state(s)


class ViewTab(QtWidgets.QWidget):
    """The mesh chooser, then the view tab's rows (the difference view, with its legend and
    advice; the compare view, with the swap button; the scene's effects)."""

    def __init__(self, choose_mesh, send, parent=None):
        super().__init__(parent)
        box = _form(self)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("mesh"))
        self.mesh = QtWidgets.QComboBox()
        self.mesh.setObjectName("mesh")
        self.mesh.setSizeAdjustPolicy(
            QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
        )
        self.mesh.setMinimumContentsLength(8)
        self.mesh.activated.connect(lambda i: choose_mesh(self.mesh.itemData(i)))
        row.addWidget(self.mesh, 1)
        box.addLayout(row)
        self.mesh_info = QtWidgets.QLabel("")
        self.mesh_info.setObjectName("mesh_info")
        self.mesh_info.setWordWrap(True)
        box.addWidget(self.mesh_info)
        self.legend, self.advice = QtWidgets.QLabel(""), QtWidgets.QLabel("")
        for w, name in ((self.legend, "legend"), (self.advice, "advice")):
            w.setObjectName(name)
            w.setWordWrap(True)
        after = {"difference": [self.legend, self.advice]}
        self.rows = RowWidgets(panelmodel.rows("view"), box, send, self, after)
        w = self.rows.widgets
        self.difference, self.compare, self.swap = w["difference"], w["compare"], w["swap"]
        self.compare_preset, self.compare_difference = w["compare_preset"], w["compare_difference"]
        box.addStretch(1)

    def set_meshes(self, choices: dict) -> None:
        """``choices``: chooser name -> label shown."""
        with QtCore.QSignalBlocker(self.mesh):
            self.mesh.clear()
            for name, label in choices.items():
                self.mesh.addItem(label, name)

    def show_state(self, s: M.State, n_vertices: int) -> None:
        self.rows.show_state(s)
        with QtCore.QSignalBlocker(self.mesh):
            self.mesh.setCurrentIndex(max(self.mesh.findData(s.mesh), 0))
        self.mesh_info.setText(captions.mesh_line(s.mesh, n_vertices))
        self.mesh_info.setToolTip(s.mesh)
        self.legend.setVisible(s.difference)
        self.advice.setVisible(s.difference)


class Panel(QtWidgets.QTabWidget):
    """The three tabs. act : the window's action sender; choose_mesh(name) : the mesh chooser.

    ``rejected(message)``: a typed value was refused (the field shows the state's again). The
    panel is never narrower than its widest tab's least width (with the scroll bar), so no
    control is cut at any window size; a wheel over a control it has not focused scrolls."""

    rejected = QtCore.Signal(str)

    def __init__(self, choose_mesh, send, parent=None):
        super().__init__(parent)
        self.setObjectName("panel")
        self.material = MaterialTab(send)
        self.lights = LightsTab(send)
        self.view = ViewTab(choose_mesh, send)
        self.areas = [_scroll(self.material), _scroll(self.lights), _scroll(self.view)]
        for area, name in zip(self.areas, ("material", "lights", "view"), strict=True):
            area.setObjectName(f"{name}_scroll")
            self.addTab(area, name)
        for tab in (self.material, self.lights, self.view):
            tab.rows.rejected.connect(self.rejected)
        self._wheel = [guard_wheel(t) for t in (self.material, self.lights, self.view)]
        self.fit_width()

    def fit_width(self) -> None:
        """The least width that shows every tab's controls whole (the vertical scroll bar
        included: the tabs scroll when the window is low)."""
        bar = self.style().pixelMetric(QtWidgets.QStyle.PixelMetric.PM_ScrollBarExtent)
        need = max(t.minimumSizeHint().width() for t in (self.material, self.lights, self.view))
        frame = 2 * self.style().pixelMetric(QtWidgets.QStyle.PixelMetric.PM_DefaultFrameWidth)
        self.setMinimumWidth(need + bar + frame + 4)

    def show_state(self, s: M.State, n_vertices: int) -> None:
        self.material.show_state(s)
        self.lights.show_state(s)
        self.view.show_state(s, n_vertices)

    def show_items(self, source: str, items) -> None:
        """The items of every tab's rows whose items come from catalogue ``source``."""
        for tab in (self.material, self.lights, self.view):
            tab.rows.show_items(source, items)
