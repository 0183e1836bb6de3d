"""The panel model: every control of the explorer's panel declared once, as a :class:`Row`,
and drawn by both front ends (the Qt panel, :mod:`explorer.app.qt.rows`; the web page,
:mod:`explorer.app.web.page` and :mod:`explorer.app.web.panel`). Toolkit-free.

A row says what a control is, never how a toolkit draws it:

- ``key``: the scene file's key (``kd``, ``cutoff``, ``fresnel``...), which is also the key of
  :meth:`Controller.set_value <explorer.app.controller.Controller.set_value>`, the Qt widget's
  object name, the page's ``aria-label`` and its trame state key (one name end to end);
- ``tab`` (``material``, ``lights``, ``view``), ``group`` (rows drawn together: a grid of
  colours, a line of toggles) and ``kind``: ``number`` (a slider and a field; range, scale,
  decimals and unit from :data:`explorer.core.controls.CONTROLS`), ``colour`` (r, g, b),
  ``choice`` (one of ``choices``), ``toggle`` (on / off), ``triple`` (three numbers),
  ``list`` (one of a list of :class:`Item`: the presets, the scene's lights) or ``button`` (an
  action that takes no value: add a light, swap A and B; its value is whether it can be
  pressed now, and ``set_value(key, True)`` presses it), ``text`` (a line the state says:
  what the mesh's own materials are; nothing to set) or ``image`` (a texture map of the
  material: its thumbnail, its file's name, an on / off toggle ``<key>_on``, a choose-file and
  a clear; its value is ``(file, on)``, ``(None, False)`` without a map, and its edit takes a
  file name (choose), None (clear), True / False (on / off) or :data:`ASK_FILE` (the window
  asks for a file first));
- ``value(state)`` what it shows, ``visible(state)`` whether it is shown, and ``edit(state,
  value)`` the model action that sets it: the one table of the edits
  (:func:`edit`, which :meth:`Controller.set_value` applies), so no front end names an action.

A list, or a choice whose values are not fixed, has :class:`Item` s: from the state
(``items(state)``: the light list) or from a catalogue the controller holds (``source``:
``"presets"``, the preset list and side B's preset, whose items :func:`preset_items` makes when
the controller's presets change). Its value is an item's ``value``; a preset row's edit is given
the preset itself (:func:`edit` finds it by name).

A light's rows are shown when the selected light has them (its ``CONTROL_KEYS``,
:mod:`explorer.core.lights`): no front end knows a light type. A new control is a row here (and
its range in :mod:`explorer.core.controls` for a number, its action in :mod:`explorer.app.model`
when none fits); both front ends draw it with no code of their own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from explorer.app import captions, loberows, maprows
from explorer.app import effectactions as E
from explorer.app import model as M
from explorer.app import termstrip as T
from explorer.core.controls import CONTROLS, Control, without_unit
from explorer.core.errors import ExplorerError
from explorer.core.hdr import TONE_MAPS
from explorer.core.lights import LIGHT_TYPES
from explorer.core.material import MODELS, RGB_KEYS, Material
from explorer.core.scene import SHADINGS
from explorer.shading.strip import MODES as STRIP_MODES

KINDS = ("number", "colour", "choice", "toggle", "triple", "list", "button", "text", "image")
#: an image row's value that asks the front end's file dialog for the file first
#: (:meth:`Controller.set_value <explorer.app.controller.Controller.set_value>`)
ASK_FILE = object()

TABS = ("material", "lights", "view")


def _always(_state: M.State) -> bool:
    return True


@dataclass(frozen=True)
class Item:
    """One entry of a list row (or of a choice whose values are not fixed): its ``value`` (what
    the row's value and edit hold), the words shown (``title``), a second line (``subtitle``:
    a preset's description) and the material whose swatch is drawn beside it (None: none)."""

    value: object
    title: str
    subtitle: str = ""
    swatch: Material | None = None


@dataclass(frozen=True)
class Row:
    """One control of the panel (see the module docstring).

    key, tab, kind, group : its name, where it is drawn and what it is
    value(state) : the value shown (an optional number's None: off)
    edit(state, value) : ``(action, args)``, the model action that sets ``value`` (or
        ``(action, args, label)`` when the undo step's name says the value: a preset's)
    visible(state) : whether the row is shown
    label : the undo step's name (default: the key); text : the words beside the control
        (default: the key)
    choices : a choice's values, or a triple's parts; inline : draw a choice's values side by
        side (else a list to open)
    optional : a number that may be off (None): the value it takes when turned on; the row
        is drawn with a ``<key>_on`` toggle before the number
    tip : what the control does (a tooltip)
    note(state) : a line under a number (None: none)
    slider(state) : a number's slider range when the table's is not the one (None: the
        table's)
    items(state) : a list's (or a choice's) items from the state (the lights; defined for any
        state, empty while the row is hidden); source : the
        catalogue its items come from instead (``"presets"``); search : the list is long and
        searched by words (the presets): a field to type them, the selected item's subtitle
        under it, and a click takes an item (browsing with the keys only shows it)
    """

    key: str
    tab: str
    kind: str
    value: Callable[[M.State], object]
    edit: Callable[[M.State, object], tuple]
    visible: Callable[[M.State], bool] = _always
    group: str = ""
    label: str = ""
    text: str = ""
    choices: tuple[str, ...] = ()
    inline: bool = False
    optional: float | None = None
    tip: str = ""
    note: Callable[[M.State], str | None] | None = None
    slider: Callable[[M.State], tuple[float, float]] | None = None
    items: Callable[[M.State], tuple[Item, ...]] | None = None
    source: str = ""
    search: bool = False

    @property
    def control(self) -> Control:
        """A number's entry of :data:`explorer.core.controls.CONTROLS`."""
        return CONTROLS[self.key]

    @property
    def undo_label(self) -> str:
        return self.label or self.key

    @property
    def caption(self) -> str:
        return self.text or self.key

    def shown(self, state: M.State):
        """The value when the row is shown, else None (the page hides a row whose value is
        None)."""
        return self.value(state) if self.visible(state) else None

    def parse(self, text):
        """The value of ``text`` typed into this row's field: a number (its unit may follow,
        :func:`~explorer.core.controls.without_unit`) or a triple's numbers (``kc, kl, kq``),
        each within the field's range (:func:`~explorer.app.model.parse_number`), or a colour
        (``r, g, b`` or ``#rrggbb``, :func:`~explorer.app.model.parse_colour`). Anything else
        is an :class:`ExplorerError` naming the key (and the range)."""
        if self.kind == "colour":
            return M.parse_colour(self.key, str(text))
        if self.kind not in ("number", "triple"):
            raise ExplorerError(f"'{self.key}' takes no typed value")
        lo, hi = self.control.field_range
        if self.kind == "number":
            return M.parse_number(self.key, without_unit(self.control, str(text)), lo, hi)
        parts = [M.parse_number(self.key, t, lo, hi) for t in str(text).split(",")]
        if len(parts) != len(self.choices):
            names = ", ".join(self.choices)
            raise ExplorerError(
                f"{self.key}: give {len(self.choices)} numbers {names}, got {text!r}"
            )
        return tuple(parts)

    def slider_range(self, state: M.State) -> tuple[float, float]:
        """A number's slider range in ``state`` (:attr:`slider`, else the table's)."""
        if self.slider is not None:
            return self.slider(state)
        return self.control.lo, self.control.hi


# -- the rows ----------------------------------------------------------------------------------
def preset_items(presets) -> tuple[Item, ...]:
    """The items of a ``source="presets"`` row: each preset (``PresetInfo``) by name, with its
    description and its swatch."""
    return tuple(Item(p.name, p.name, p.material.description or "", p.material) for p in presets)


def _read_only(key: str):
    """A text row's edit: it sets nothing (an :class:`ExplorerError`)."""

    def edit(s: M.State, v):
        raise ExplorerError(f"'{key}' is a line of text: nothing to set")

    return edit


def _mesh_materials_rows() -> list[Row]:
    """A mesh file's own materials, first in the material tab (shown when the mesh brings
    some): what is drawn, the group the controls edit, or a button that draws them again."""

    def brings(s: M.State) -> bool:
        return s.mesh_materials is not None

    def groups(s: M.State) -> tuple[Item, ...]:
        if s.groups is None:  # a preset covers the mesh (or it brings no materials)
            return ()
        names = s.mesh_materials.names
        return tuple(Item(i, names[i] or "(no usemtl)", "", m) for i, m in enumerate(s.groups))

    return [
        Row(
            "mesh_materials",
            "material",
            "text",
            captions.mesh_materials_line,
            _read_only("mesh_materials"),
            brings,
        ),
        Row(
            "group",
            "material",
            "choice",
            lambda s: s.group,
            lambda s, v: (M.select_group, (int(v),)),
            lambda s: s.groups is not None,
            items=groups,
            tip="the group of the mesh whose material the controls below edit",
        ),
        Row(
            "use_mesh_materials",
            "material",
            "button",
            _always,
            lambda s, v: (M.use_mesh_materials, ()),
            lambda s: brings(s) and s.groups is None,
            label="mesh materials",
            text="use the mesh's materials",
            tip="draw each group in the material its file gives (undoable)",
        ),
    ]


def _preset_rows() -> list[Row]:
    """The line naming the material the controls edit (``preset: gold (edited)``), then the
    preset list."""
    return [
        Row(
            "material_line",
            "material",
            "text",
            captions.material_line,
            _read_only("material_line"),
            _always,
        ),
        Row(
            "preset",
            "material",
            "list",
            lambda s: s.preset,
            lambda s, p: (M.apply_preset, (p.name, p.material), f"preset {p.name}"),
            source="presets",
            search=True,
            tip="the built-in and the user's presets (type to search)",
        ),
    ]


def _material_rows() -> list[Row]:
    def scalar(i):
        return lambda s: s.material.scalars()[i]

    rows = [
        Row(k, "material", "number", scalar(i), lambda s, v, k=k: (M.set_coefficient, (k, v)))
        for i, k in enumerate(("ka", "kd", "ks"))
    ]
    rows += [
        Row(
            "shininess",
            "material",
            "number",
            lambda s: s.material.shininess,
            lambda s, v: (M.set_shininess, (v,)),
        ),
        Row(
            "opacity",
            "material",
            "number",
            lambda s: s.material.opacity,
            lambda s, v: (M.set_opacity, (v,)),
            tip="below 1 the mesh is translucent: drawn back to front",
        ),
    ]
    rows += [
        Row(
            t,
            "material",
            "colour",
            lambda s, t=t: getattr(s.material, t),
            lambda s, v, t=t: (M.set_colour, (t, v)),
            group="colours",
        )
        for t in RGB_KEYS
    ]
    rows.append(
        Row(
            "model",
            "material",
            "choice",
            lambda s: s.scene.model,
            lambda s, v: (M.set_model, (v,)),
            choices=MODELS,
            inline=True,
        )
    )
    rows += [
        Row(
            f"show_{t}",
            "material",
            "toggle",
            lambda s, t=t: t not in s.hidden,
            lambda s, v, t=t: (M.set_term, (t, bool(v))),
            group="terms",
            label=f"{t} term",
            text=t,
            tip=f"draw the {t} term (the material is unchanged)",
        )
        for t in M.TERMS
    ]
    return rows


def _material_effect_rows() -> list[Row]:
    """The material's effects beyond OpenGL 2.1 (docs/effects.md), after its own rows."""
    return [
        Row(
            "fresnel",
            "material",
            "number",
            lambda s: s.material.fresnel,
            lambda s, v: (E.set_material_field, ("fresnel", v)),
            optional=0.04,
            tip="Schlick's Fresnel on the specular term: F0 at normal incidence, toward 1 at "
            "grazing angles",
        ),
        Row(
            "energy_conserving",
            "material",
            "toggle",
            lambda s: s.material.energy_conserving,
            lambda s, v: (E.set_material_field, ("energy_conserving", bool(v))),
            tip="normalise the specular lobe: a higher shininess narrows the highlight and "
            "raises its peak",
        ),
    ]


def _has(key: str) -> Callable[[M.State], bool]:
    """A light row's ``visible``: the selected light has control ``key``."""

    def visible(s: M.State) -> bool:
        light = s.selected_light
        return light is not None and key in light.CONTROL_KEYS

    return visible


def _placement(i: int, scale: bool = False):
    return lambda s: s.placement()[i] / (s.radius if scale else 1.0)


def _place(i: int):
    def edit(s: M.State, v):
        args = [None, None, None]
        args[i] = v * s.radius if i == 2 else v
        return M.place_light, tuple(args[: max(i + 1, 2)])

    return edit


def _distance_note(s: M.State) -> str:
    d = s.placement()[2]
    far = " (places the handle: a directional light is at infinity)"
    return f"= {d:.3g} world units" + (far if s.selected_light.AT_INFINITY else "")


def _distance_slider(s: M.State) -> tuple[float, float]:
    lo, hi = s.distance_range()
    return lo / s.radius, hi / s.radius


def light_summary(i: int, light, state: M.State) -> str:
    """One line of the light list: number, type and placement, and the light it shares its
    place with (a duplicate, until moved)."""
    az, el, d = state.placement(i)
    where = "from" if light.AT_INFINITY else "at"
    dist = "" if light.AT_INFINITY else f", {d / state.radius:.2f} r"
    j = M.same_place_as(state, i)
    same = "" if j is None else f" (same place as {j + 1})"
    return f"{i + 1}: {light.type} {where} az {az:.0f}°, el {el:.0f}°{dist}{same}"


#: what the lights tab says when the scene has no lights (the ``no_lights`` row)
NO_LIGHTS = "The scene has no lights: add one."


def _light_list_rows() -> list[Row]:
    """The scene's lights, first in the lights tab: the selected one is the value; add,
    duplicate, remove; the line saying the scene has none (:data:`NO_LIGHTS`)."""
    return [
        Row(
            "light",
            "lights",
            "list",
            lambda s: s.light if s.scene.lights else None,
            lambda s, v: (M.select_light, (int(v),)),
            label="select light",
            items=lambda s: tuple(
                Item(i, light_summary(i, lt, s)) for i, lt in enumerate(s.scene.lights)
            ),
        ),
        *(
            Row(
                f"{name}_light",
                "lights",
                "button",
                _always if name == "add" else lambda s: s.selected_light is not None,
                lambda s, v, a=action: (a, ()),
                group="light_buttons",
                label=f"{name} light",
                text=name,
            )
            for name, action in (
                ("add", M.add_light),
                ("duplicate", M.duplicate_light),
                ("remove", M.remove_light),
            )
        ),
        Row(
            "no_lights",
            "lights",
            "text",
            lambda s: NO_LIGHTS,
            _read_only("no_lights"),
            lambda s: s.selected_light is None,
        ),
    ]


def _light_rows() -> list[Row]:
    def light(name):
        return lambda s: getattr(s.selected_light, name)

    def field(name):
        return lambda s, v: (M.set_light_field, (name, v))

    rows = [
        Row(
            "type",
            "lights",
            "choice",
            lambda s: s.selected_light.type,
            lambda s, v: (M.set_light_type, (v,)),
            choices=LIGHT_TYPES,
            group="light",
            label="light type",
        ),
        Row(
            "color",
            "lights",
            "colour",
            lambda s: M.light_colour(s.selected_light)[0],
            lambda s, v: (M.set_light_colour, (v,)),
            group="light",
            label="light color",
        ),
        Row(
            "intensity",
            "lights",
            "number",
            lambda s: M.light_colour(s.selected_light)[1],
            lambda s, v: (M.set_light_intensity, (v,)),
        ),
        Row("azimuth", "lights", "number", _placement(0), _place(0)),
        Row("elevation", "lights", "number", _placement(1), _place(1)),
        Row(
            "distance",
            "lights",
            "number",
            _placement(2, True),
            _place(2),
            tip="distance from the mesh centre in mesh radii",
            note=_distance_note,
            slider=_distance_slider,
        ),
        Row(
            "attenuation",
            "lights",
            "triple",
            light("attenuation"),
            field("attenuation"),
            choices=("kc", "kl", "kq"),
            tip="1 / (kc + kl·d + kq·d²)",
        ),
        Row(
            "cutoff",
            "lights",
            "number",
            lambda s: min(float(s.selected_light.cutoff), 90.0),
            field("cutoff"),
        ),
        Row(
            "exponent",
            "lights",
            "number",
            lambda s: float(s.selected_light.exponent),
            field("exponent"),
        ),
        Row(
            "shadows",
            "lights",
            "toggle",
            light("shadows"),
            field("shadows"),
            tip="the light casts hard shadows on the mesh (rays through its BVH)",
        ),
    ]
    return [replace(r, visible=_has(r.key)) for r in rows]


def _comparing(s: M.State) -> bool:
    return s.compare is not None


def _compare_rows() -> list[Row]:
    """The difference view and the A / B compare view, first in the view tab."""
    b_rows = [
        Row(
            "compare_preset",
            "view",
            "choice",
            lambda s: s.compare_preset or "",
            lambda s, p: (M.set_compare_preset, (p.name, p.material), f"B {p.name}"),
            text="B preset",
            source="presets",
            search=True,
        ),
        Row(
            "compare_model",
            "view",
            "choice",
            lambda s: s.compare_model,
            lambda s, v: (M.set_compare_model, (v,)),
            label="B model",
            text="B model",
            choices=MODELS,
            inline=True,
        ),
        Row(
            "compare_difference",
            "view",
            "toggle",
            lambda s: s.compare_difference,
            lambda s, v: (M.set_compare_difference, (bool(v),)),
            label="A − B",
            text="B shows A − B",
            tip="pane B shows the difference of the two sides' colours (largest channel, "
            "1/255 levels, the difference view's colours)",
        ),
        Row(
            "swap",
            "view",
            "button",
            _always,
            lambda s, v: (M.swap_compare, ()),
            label="swap A and B",
            text="swap A and B",
        ),
    ]
    return [
        Row(
            "difference",
            "view",
            "toggle",
            lambda s: s.difference,
            lambda s, v: (M.set_difference, (bool(v),)),
            tip="the per-pixel error of this view as a heat map (key d)",
        ),
        Row(
            "compare",
            "view",
            "toggle",
            _comparing,
            lambda s, v: (M.set_compare, (bool(v),)),
            text="compare A | B",
            tip="two panes with linked cameras and the same lights (key c)",
        ),
        *(replace(r, visible=_comparing) for r in b_rows),
    ]


def _hdr_on(s: M.State) -> bool:
    return s.scene.hdr is not None


def _view_rows() -> list[Row]:
    return [
        Row(
            "shading",
            "view",
            "choice",
            lambda s: s.scene.shading,
            lambda s, v: (E.set_shading, (v,)),
            choices=SHADINGS,
            inline=True,
            tip="per-vertex: lit at the vertices, colours interpolated (Gouraud, OpenGL 2.1); "
            "per-pixel: the engine at every pixel's surface point, with the interpolated normal",
        ),
        Row(
            "two_sided",
            "view",
            "toggle",
            lambda s: s.scene.two_sided,
            lambda s, v: (E.set_scene_field, ("two_sided", bool(v))),
            tip="light back faces too, with the normal turned (-N)",
        ),
        Row(
            "local_viewer",
            "view",
            "toggle",
            lambda s: s.local_viewer,
            lambda s, v: (E.set_local_viewer, (bool(v),)),
            tip="the viewer at the camera (highlights move across a flat face); off: "
            "infinitely far along the view (OpenGL's default)",
        ),
        Row(
            "hdr",
            "view",
            "toggle",
            _hdr_on,
            lambda s, v: (E.set_hdr, (bool(v),)),
            tip="unclamped colours shown with an exposure and a tone map, then sRGB",
        ),
        Row(
            "exposure",
            "view",
            "number",
            lambda s: s.scene.hdr.exposure,
            lambda s, v: (E.set_hdr_field, ("exposure", v)),
            visible=_hdr_on,
            tip="stops: each doubles the light",
        ),
        Row(
            "tone_map",
            "view",
            "choice",
            lambda s: s.scene.hdr.tone_map,
            lambda s, v: (E.set_hdr_field, ("tone_map", v)),
            visible=_hdr_on,
            choices=TONE_MAPS,
        ),
        *_strip_rows(),
        *loberows.lobe_rows(Row),
    ]


def _strip_rows() -> list[Row]:
    """The term strip's rows (:mod:`explorer.app.termstrip`): on, its tiles' mode, the
    compare view's panes that show one, and a row of tiles per light."""
    return [
        Row(
            "strip",
            "view",
            "toggle",
            lambda s: s.strip,
            lambda s, v: (T.set_strip, (bool(v),)),
            tip="the equation term by term under the view: emission, ambient, diffuse, "
            "specular, their sum and where the display clamps it (docs/terms.md)",
        ),
        Row(
            "strip_mode",
            "view",
            "choice",
            lambda s: s.strip_mode,
            lambda s, v: (T.set_strip_mode, (v,)),
            visible=lambda s: s.strip,  # (shown with the strip, as exposure with hdr)
            choices=STRIP_MODES,
            inline=True,
            tip="weighted: each term as it enters the colour (k·A, k·D, k·S); raw: the light "
            "sums A, D, S alone",
        ),
        Row(
            "strip_side",
            "view",
            "choice",
            lambda s: s.strip_side,
            lambda s, v: (T.set_strip_side, (v,)),
            visible=lambda s: s.strip and s.compare is not None,  # (the compare view's)
            choices=T.STRIP_SIDES,
            inline=True,
            tip="the compare view's panes that show their side's strip: both, A's or B's",
        ),
        Row(
            "strip_lights",
            "view",
            "toggle",
            lambda s: s.strip_lights,
            lambda s, v: (T.set_strip_lights, (bool(v),)),
            visible=lambda s: s.strip,
            tip="a row of tiles per light under the strip: what each light alone adds (its "
            "ambient, diffuse, specular and their sum); a light pass per light while on",
        ),
    ]


#: every row, in the order each tab draws them
ROWS: tuple[Row, ...] = (
    *_mesh_materials_rows(),
    *_preset_rows(),
    *_material_rows(),
    *_material_effect_rows(),
    *maprows.map_rows(),
    *_light_list_rows(),
    *_light_rows(),
    *_compare_rows(),
    *_view_rows(),
)
#: the rows by key
BY_KEY: dict[str, Row] = {r.key: r for r in ROWS}
#: the effects of docs/effects.md as rows (translucency is ``opacity``)
EFFECT_KEYS = (
    "shadows",
    "fresnel",
    "energy_conserving",
    "hdr",
    "exposure",
    "tone_map",
    "opacity",
    "two_sided",
    "local_viewer",
)


def rows(tab: str) -> tuple[Row, ...]:
    """The rows of ``tab``, in order."""
    return tuple(r for r in ROWS if r.tab == tab)


def row(key: str) -> Row:
    """The row of ``key`` (an :class:`ExplorerError` naming the keys for an unknown one)."""
    try:
        return BY_KEY[key]
    except KeyError:
        raise ExplorerError(f"no control named '{key}' (one of {', '.join(BY_KEY)})") from None


def edit(state: M.State, key: str, value, presets=()) -> tuple[Callable, tuple, str]:
    """``(action, args, label)``: what sets control ``key`` to ``value`` in ``state`` (the
    undo step's label). The action refuses a row the state does not show (a spot's cutoff on
    a point light: :func:`explorer.app.model.set_light_field`). A preset row's ``value`` is a
    preset's name, found in ``presets`` (the controller's ``PresetInfo`` list; an
    :class:`ExplorerError` when none has it)."""
    r = row(key)
    if r.source == "presets":
        found = next((p for p in presets if p.name == value), None)
        if found is None:
            raise ExplorerError(f"no preset named '{value}'")
        value = found
    action, args, *label = r.edit(state, value)
    return action, args, label[0] if label else r.undo_label


def client_keys() -> dict[str, str]:
    """The page's state keys the rows let a client set (their ``v_model``), with their kind
    as the web guard names kinds (``number``, ``bool``, ``text``): a number's slider step
    ``<key>_step`` and an optional number's switch ``<key>_on``, a choice's value, a toggle's.
    A number's, a colour's and a triple's typed text and a colour's picks are not state: they
    call the page's handlers, which parse what they are given. A list's value is its item's
    (a preset's name, a light's index); a button's and a text's are not the page's to set."""
    out: dict[str, str] = {}
    for r in ROWS:
        if r.kind == "number":
            out[f"{r.key}_step"] = "number"
            if r.optional is not None:
                out[f"{r.key}_on"] = "bool"
        elif r.kind in ("choice", "list"):  # an index into the state's items, or a name
            out[r.key] = "index" if r.items is not None else "text"
        elif r.kind == "toggle":
            out[r.key] = "bool"
        elif r.kind == "image":  # (its clear calls the page's handler)
            out[f"{r.key}_on"] = "bool"
            out[f"{r.key}_upload"] = "upload"
    return out
