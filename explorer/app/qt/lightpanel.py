"""The panel's ``lights`` and ``view`` tabs and the panel itself (see
:mod:`explorer.app.qt.panel`)."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from explorer.app import model as M
from explorer.app.qt.panel import (
    ColourButton,
    MaterialTab,
    NumberField,
    ValueSlider,
    _form,
    _scroll,
    guard_wheel,
)
from explorer.core.controls import CONTROLS
from explorer.core.lights import LIGHT_TYPES
from explorer.core.material import MODELS


def light_summary(i: int, light, state: M.State) -> str:
    """One line of the light list: number, type and placement, and the light it shares its
    place with (a duplicate, until moved)."""
    az, el, d = state.placement(i)
    where = "from" if light.type == "directional" else "at"
    dist = "" if light.type == "directional" else f", {d / state.radius:.2f} r"
    j = M.same_place_as(state, i)
    same = "" if j is None else f" (same place as {j + 1})"
    return f"{i + 1}: {light.type} {where} az {az:.0f}°, el {el:.0f}°{dist}{same}"


class LightsTab(QtWidgets.QWidget):
    """The scene's lights (add, duplicate, remove) and the selected light's controls."""

    rejected = QtCore.Signal(str)

    def __init__(self, act, parent=None):
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
        row = QtWidgets.QGridLayout()  # type and colour on rows of their own: a narrow panel
        label = QtWidgets.QLabel("type")
        label.setMinimumWidth(64)
        row.addWidget(label, 0, 0)
        self.type = QtWidgets.QComboBox()
        self.type.setObjectName("type")
        self.type.addItems(list(LIGHT_TYPES))
        self.type.activated.connect(
            lambda i: self.act(M.set_light_type, LIGHT_TYPES[i], label="light type")
        )
        row.addWidget(self.type, 0, 1)
        row.addWidget(QtWidgets.QLabel("color"), 1, 0)
        self.colour = ColourButton("color")
        self.colour.picked.connect(
            lambda rgb: self.act(M.set_light_colour, rgb, label="light color")
        )
        row.addWidget(self.colour, 1, 1)
        row.setColumnStretch(1, 1)
        form.addLayout(row)
        self.sliders = {
            name: ValueSlider(name) for name in ("intensity", "azimuth", "elevation", "distance")
        }
        self.sliders["distance"].note.setVisible(True)
        self.sliders["distance"].setToolTip("distance from the mesh centre in mesh radii")
        for name, s in self.sliders.items():
            form.addWidget(s)
            s.rejected.connect(self.rejected)
            s.edited.connect(lambda v, n=name: self._edited(n, v))
        form.addWidget(self._attenuation_fields())
        self.cutoff = ValueSlider("cutoff")
        self.exponent = ValueSlider("exponent")
        for name, s in (("cutoff", self.cutoff), ("exponent", self.exponent)):
            form.addWidget(s)
            s.rejected.connect(self.rejected)
            s.edited.connect(lambda v, n=name: self.act(M.set_light_field, n, v, label=n, merge=n))
        box.addWidget(self.controls)
        self.none = QtWidgets.QLabel("The scene has no lights: add one.")
        box.addWidget(self.none)
        box.addStretch(1)
        self.list.currentRowChanged.connect(
            lambda i: i >= 0 and self.act(M.select_light, i, label="select light")
        )

    def _attenuation_fields(self) -> QtWidgets.QWidget:
        """The attenuation's three number fields, a row a key (a narrow panel)."""
        self.attenuation_box = QtWidgets.QWidget()
        grid = QtWidgets.QGridLayout(self.attenuation_box)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.addWidget(QtWidgets.QLabel("attenuation  1 / (kc + kl·d + kq·d²)"), 0, 0, 1, 3)
        self.attenuation = []
        att = CONTROLS["attenuation"]
        for k, key in enumerate(("kc", "kl", "kq")):
            f = NumberField(key, *att.field_range, decimals=att.decimals)
            f.setObjectName(f"attenuation_{key}")
            f.setSingleStep(att.field_step)
            f.setToolTip(f"{key} of 1 / (kc + kl·d + kq·d²), d in world units")
            f.valueChanged.connect(self._attenuation)
            f.rejected.connect(self.rejected)
            label = QtWidgets.QLabel(key)
            label.setMinimumWidth(64)  # as the sliders' labels
            grid.addWidget(label, 1 + k, 0)
            grid.addWidget(f, 1 + k, 2)
            self.attenuation.append(f)
        grid.setColumnStretch(1, 1)
        return self.attenuation_box

    def _edited(self, name: str, v: float) -> None:
        if name == "intensity":
            self.act(M.set_light_intensity, v, label=name, merge=name)
        elif name == "distance":
            self.act(M.place_light, None, None, v * self._radius, label=name, merge=name)
        else:
            self.act(M.place_light, *((v, None) if name == "azimuth" else (None, v)),
                     label=name, merge=name)  # fmt: skip

    def _attenuation(self, _v=None) -> None:
        value = tuple(f.value() for f in self.attenuation)
        self.act(M.set_light_field, "attenuation", value, label="attenuation")

    def show_state(self, s: M.State) -> None:
        self._radius = s.radius
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
        with QtCore.QSignalBlocker(self.type):
            self.type.setCurrentIndex(LIGHT_TYPES.index(light.type))
        hue, k = M.light_colour(light)
        self.colour.set_rgb(hue)
        az, el, d = s.placement()
        lo, hi = s.distance_range()
        dist = self.sliders["distance"]
        dist.set_range(lo / s.radius, hi / s.radius)
        for name, v in (("intensity", k), ("azimuth", az), ("elevation", el),
                        ("distance", d / s.radius)):  # fmt: skip
            self.sliders[name].set_value(v)
        far = " (places the handle: a directional light is at infinity)"
        dist.note.setText(f"= {d:.3g} world units" + (far if light.type == "directional" else ""))
        dist.note.setWordWrap(True)
        positional = light.type in ("point", "spot")
        self.attenuation_box.setVisible(positional)
        if positional:
            for f, v in zip(self.attenuation, light.attenuation, strict=True):
                with QtCore.QSignalBlocker(f):
                    f.setValue(v)
        spot = light.type == "spot"
        self.cutoff.setVisible(spot)
        self.exponent.setVisible(spot)
        if spot:
            self.cutoff.set_value(min(light.cutoff, 90.0))
            self.exponent.set_value(light.exponent)


class ViewTab(QtWidgets.QWidget):
    """The mesh chooser and the difference view (toggle, legend, advice)."""

    def __init__(self, act, choose_mesh, parent=None):
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

    def __init__(self, act, choose_mesh, parent=None):
        super().__init__(parent)
        self.setObjectName("panel")
        self.material = MaterialTab(act)
        self.lights = LightsTab(act)
        self.view = ViewTab(act, choose_mesh)
        self.areas = [_scroll(self.material), _scroll(self.lights), _scroll(self.view)]
        for area, name in zip(self.areas, ("material", "lights", "view"), strict=True):
            area.setObjectName(f"{name}_scroll")
            self.addTab(area, name)
        for s in self.material.sliders.values():
            s.rejected.connect(self.rejected)
        self.lights.rejected.connect(self.rejected)
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
