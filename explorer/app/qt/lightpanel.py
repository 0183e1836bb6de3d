"""The panel's three tabs and the panel itself (the widgets are :mod:`explorer.app.qt.panel`'s).
Each tab draws its rows of :mod:`explorer.app.panelmodel` (:class:`~explorer.app.qt.rows.
RowWidgets`) among the controls that are not rows: the preset list, the light list, the mesh
chooser, the difference and compare views."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from explorer.app import model as M
from explorer.app import panelmodel
from explorer.app.qt.panel import MeshMaterialsBox, _form, _scroll, guard_wheel, swatch
from explorer.app.qt.rows import RowWidgets
from explorer.core.material import MODELS, RGB_KEYS


def light_summary(i: int, light, state: M.State) -> str:
    """One line of the light list: number, type and placement, and the light it shares its
    place with (a duplicate, until moved)."""
    az, el, d = state.placement(i)
    where = "from" if light.AT_INFINITY else "at"
    dist = "" if light.AT_INFINITY else f", {d / state.radius:.2f} r"
    j = M.same_place_as(state, i)
    same = "" if j is None else f" (same place as {j + 1})"
    return f"{i + 1}: {light.type} {where} az {az:.0f}°, el {el:.0f}°{dist}{same}"


class LightsTab(QtWidgets.QWidget):
    """The scene's lights (add, duplicate, remove) and the selected light's controls."""

    rejected = QtCore.Signal(str)

    def __init__(self, act, send, parent=None):
        super().__init__(parent)
        self.act = act
        box = _form(self)
        self.list = QtWidgets.QListWidget()
        self.list.setObjectName("lights")
        self.list.setMinimumHeight(60)
        self.list.setMaximumHeight(110)
        self.list.setWordWrap(True)  # a long line (a duplicate's) wraps in a narrow panel
        self.list.setHorizontalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        box.addWidget(self.list)
        row = QtWidgets.QHBoxLayout()
        self.buttons = {}
        for name, action in (("add", M.add_light), ("duplicate", M.duplicate_light),
                             ("remove", M.remove_light)):  # fmt: skip
            b = QtWidgets.QPushButton(name)
            b.setObjectName(f"{name}_light")
            b.clicked.connect(lambda _=False, a=action, n=name: self.act(a, label=f"{n} light"))
            row.addWidget(b)
            self.buttons[name] = b
        box.addLayout(row)
        self.controls = QtWidgets.QWidget()
        form = _form(self.controls)
        form.setContentsMargins(0, 0, 0, 0)
        self.rows = RowWidgets(panelmodel.rows("lights"), form, send, self)
        self.rows.rejected.connect(self.rejected)
        self.sliders = self.rows.sliders
        self.type, self.colour = self.rows.widgets["type"], self.rows.widgets["color"]
        self.attenuation_box = self.rows.widgets["attenuation"]
        self.attenuation = self.rows.fields["attenuation"]
        self.cutoff, self.exponent = self.sliders["cutoff"], self.sliders["exponent"]
        box.addWidget(self.controls)
        self.none = QtWidgets.QLabel("The scene has no lights: add one.")
        box.addWidget(self.none)
        box.addStretch(1)
        self.list.currentRowChanged.connect(
            lambda i: i >= 0 and self.act(M.select_light, i, label="select light")
        )

    def show_state(self, s: M.State) -> None:
        lights = s.scene.lights
        with QtCore.QSignalBlocker(self.list):
            self.list.clear()
            for i, light in enumerate(lights):
                text = light_summary(i, light, s)
                self.list.addItem(text)
                self.list.item(i).setToolTip(text)
            self.list.setCurrentRow(s.light if lights else -1)
        light = s.selected_light
        self.controls.setVisible(light is not None)
        self.none.setVisible(light is None)
        self.buttons["remove"].setEnabled(light is not None)
        self.buttons["duplicate"].setEnabled(light is not None)
        if light is None:
            return
        self.rows.show_state(s)


class MaterialTab(QtWidgets.QWidget):
    """Presets (searchable, with descriptions and swatches), then the material tab's rows
    (:mod:`explorer.app.panelmodel`: coefficients, colours, model, terms, the material's
    effects) and the save button."""

    def __init__(self, act, send, parent=None):
        super().__init__(parent)
        self.act = act
        box = _form(self)
        self.search = QtWidgets.QLineEdit()
        self.search.setObjectName("preset_search")
        self.search.setPlaceholderText("search presets")
        self.search.setClearButtonEnabled(True)
        self.presets = QtWidgets.QListWidget()
        self.presets.setObjectName("presets")
        self.presets.setMinimumHeight(90)
        self.presets.setIconSize(QtCore.QSize(18, 18))
        self.description = QtWidgets.QLabel("")
        self.description.setObjectName("preset_description")
        self.description.setWordWrap(True)
        self.preset_label = QtWidgets.QLabel("")
        self.preset_label.setObjectName("preset")
        self.preset_label.setWordWrap(True)
        self.mesh_materials = MeshMaterialsBox(act)
        for w in (
            self.mesh_materials,
            self.preset_label,
            self.search,
            self.presets,
            self.description,
        ):
            box.addWidget(w, 1 if w is self.presets else 0)  # the list takes the spare height
        self.rows = RowWidgets(panelmodel.rows("material"), box, send, self)
        self.sliders = self.rows.sliders
        self.colours = {t: self.rows.widgets[t] for t in RGB_KEYS}
        self.model = self.rows.radios["model"]
        self.terms = {t: self.rows.widgets[f"show_{t}"] for t in M.TERMS}
        self.save = QtWidgets.QPushButton("Save preset as…")
        self.save.setObjectName("save_preset")
        box.addWidget(self.save)
        self.search.textChanged.connect(self._filter)
        self.presets.itemClicked.connect(self._chosen)
        self.presets.currentItemChanged.connect(self._describe)
        self._infos = {}

    def set_presets(self, infos) -> None:
        """The preset list (``explorer.core.presets.PresetInfo`` items)."""
        self._infos = {p.name: p for p in infos}
        with QtCore.QSignalBlocker(self.presets):
            self.presets.clear()
            for p in infos:
                item = QtWidgets.QListWidgetItem(swatch(p.material), p.name)
                item.setToolTip(p.material.description or p.name)
                self.presets.addItem(item)
        self._filter(self.search.text())

    def _filter(self, text: str) -> None:
        t = text.strip().lower()
        for i in range(self.presets.count()):
            item = self.presets.item(i)
            info = self._infos.get(item.text())
            hay = item.text() + " " + (info.material.description if info else "")
            item.setHidden(bool(t) and t not in hay.lower())

    def _chosen(self, item) -> None:
        info = self._infos.get(item.text())
        if info is not None:
            self.act(M.apply_preset, info.name, info.material, label=f"preset {info.name}")

    def _describe(self, item, _previous=None) -> None:
        info = self._infos.get(item.text()) if item is not None else None
        self.description.setText(info.material.description if info else "")

    def show_state(self, s: M.State) -> None:
        self.rows.show_state(s)
        self.mesh_materials.show_state(s)
        edited = " (edited)" if s.edited else ""
        if s.groups is not None:
            label = s.mesh_materials.label(s.group)
            self.preset_label.setText(f"material: <b>{label}</b> of the mesh{edited}")
        elif s.preset:
            self.preset_label.setText(f"preset: <b>{s.preset}</b>{edited}")
        else:
            self.preset_label.setText(f"material: <b>{M.material_title(s)}</b>{edited}")
        with QtCore.QSignalBlocker(self.presets):
            found = self.presets.findItems(s.preset or "", QtCore.Qt.MatchFlag.MatchExactly)
            self.presets.setCurrentItem(found[0] if found and s.preset else None)
            if found and s.preset:
                self.presets.scrollToItem(found[0])
        self._describe(found[0] if found and s.preset else None)


class ViewTab(QtWidgets.QWidget):
    """The mesh chooser and the difference view (toggle, legend, advice)."""

    def __init__(self, act, choose_mesh, send, parent=None):
        super().__init__(parent)
        self.act = act
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
        self.difference = QtWidgets.QCheckBox("difference")
        self.difference.setObjectName("difference")
        self.difference.setToolTip("the per-pixel error of this view as a heat map (key d)")
        self.difference.toggled.connect(
            lambda on: self.act(M.set_difference, on, label="difference")
        )
        box.addWidget(self.difference)
        self.legend = QtWidgets.QLabel("")
        self.legend.setObjectName("legend")
        self.legend.setWordWrap(True)
        self.advice = QtWidgets.QLabel("")
        self.advice.setObjectName("advice")
        self.advice.setWordWrap(True)
        box.addWidget(self.legend)
        box.addWidget(self.advice)
        self._build_compare(box)
        self.rows = RowWidgets(panelmodel.rows("view"), box, send, self)
        box.addStretch(1)

    def _build_compare(self, box) -> None:
        """The A / B compare view: side B's preset and model, swap, and B as A − B."""
        act = self.act
        self.compare = QtWidgets.QCheckBox("compare A | B")
        self.compare.setObjectName("compare")
        self.compare.setToolTip("two panes with linked cameras and the same lights (key c)")
        self.compare.toggled.connect(lambda on: act(M.set_compare, on, label="compare"))
        box.addWidget(self.compare)
        self.compare_box = QtWidgets.QWidget()
        form = QtWidgets.QGridLayout(self.compare_box)
        form.setContentsMargins(0, 0, 0, 0)
        self.compare_preset = QtWidgets.QComboBox()
        self.compare_preset.setObjectName("compare_preset")
        self.compare_preset.setSizeAdjustPolicy(
            QtWidgets.QComboBox.SizeAdjustPolicy.AdjustToMinimumContentsLengthWithIcon
        )
        self.compare_preset.setMinimumContentsLength(8)
        self.compare_preset.activated.connect(self._compare_preset)
        form.addWidget(QtWidgets.QLabel("B preset"), 0, 0)
        form.addWidget(self.compare_preset, 0, 1, 1, 2)
        form.addWidget(QtWidgets.QLabel("B model"), 1, 0)
        self.compare_model = {}
        group = QtWidgets.QButtonGroup(self)
        for i, name in enumerate(MODELS):
            r = QtWidgets.QRadioButton(name)
            r.setObjectName(f"compare_{name}")
            group.addButton(r)
            r.toggled.connect(
                lambda on, n=name: on and act(M.set_compare_model, n, label="B model")
            )
            form.addWidget(r, 1, 1 + i)
            self.compare_model[name] = r
        self.swap = QtWidgets.QPushButton("swap A and B")
        self.swap.setObjectName("swap")
        self.swap.clicked.connect(lambda: act(M.swap_compare, label="swap A and B"))
        form.addWidget(self.swap, 2, 0, 1, 3)
        self.compare_difference = QtWidgets.QCheckBox("B shows A − B")
        self.compare_difference.setObjectName("compare_difference")
        self.compare_difference.setToolTip(
            "pane B shows the difference of the two sides' colours (largest channel, 1/255 "
            "levels, the difference view's colours)"
        )
        self.compare_difference.toggled.connect(
            lambda on: act(M.set_compare_difference, on, label="A − B")
        )
        form.addWidget(self.compare_difference, 3, 0, 1, 3)
        box.addWidget(self.compare_box)
        self._presets = {}

    def set_presets(self, infos) -> None:
        self._presets = {p.name: p for p in infos}
        with QtCore.QSignalBlocker(self.compare_preset):
            self.compare_preset.clear()
            self.compare_preset.addItems(list(self._presets))

    def _compare_preset(self, i: int) -> None:
        info = self._presets.get(self.compare_preset.itemText(i))
        if info is not None:
            self.act(M.set_compare_preset, info.name, info.material, label=f"B {info.name}")

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
        self.mesh_info.setText(f"{s.mesh}: {n_vertices:,} vertices")
        self.mesh_info.setToolTip(s.mesh)
        with QtCore.QSignalBlocker(self.difference):
            self.difference.setChecked(s.difference)
        self.legend.setVisible(s.difference)
        self.advice.setVisible(s.difference)
        on = s.compare is not None
        with QtCore.QSignalBlocker(self.compare):
            self.compare.setChecked(on)
        self.compare_box.setVisible(on)
        if on:
            with QtCore.QSignalBlocker(self.compare_preset):
                self.compare_preset.setCurrentIndex(self.compare_preset.findText(
                    s.compare_preset or ""))  # fmt: skip
            for name, r in self.compare_model.items():
                with QtCore.QSignalBlocker(r):
                    r.setChecked(s.compare_model == name)
            with QtCore.QSignalBlocker(self.compare_difference):
                self.compare_difference.setChecked(s.compare_difference)


class Panel(QtWidgets.QTabWidget):
    """The three tabs. act : the window's action sender; choose_mesh(name) : the mesh chooser.

    ``rejected(message)``: a typed value was refused (the field shows the state's again). The
    panel is never narrower than its widest tab's least width (with the scroll bar), so no
    control is cut at any window size; a wheel over a control it has not focused scrolls."""

    rejected = QtCore.Signal(str)

    def __init__(self, act, choose_mesh, send, parent=None):
        super().__init__(parent)
        self.setObjectName("panel")
        self.material = MaterialTab(act, send)
        self.lights = LightsTab(act, send)
        self.view = ViewTab(act, choose_mesh, send)
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
