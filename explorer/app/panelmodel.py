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
  ``choice`` (one of ``choices``), ``toggle`` (on / off) or ``triple`` (three numbers);
- ``value(state)`` what it shows, ``visible(state)`` whether it is shown, and ``edit(state,
  value)`` the model action that sets it: the one table of the edits
  (:func:`edit`, which :meth:`Controller.set_value` applies), so no front end names an action.

A light's rows are shown when the selected light has them (its ``CONTROL_KEYS``,
:mod:`explorer.core.lights`): no front end knows a light type. A new control is a row here (and
its range in :mod:`explorer.core.controls` for a number, its action in :mod:`explorer.app.model`
when none fits); both front ends draw it with no code of their own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from explorer.analysis.lobes import QUANTITIES as LOBE_QUANTITIES
from explorer.analysis.lobes import VIEWS as LOBE_VIEWS
from explorer.app import effectactions as E
from explorer.app import lobeinset as LI
from explorer.app import model as M
from explorer.app import termstrip as T
from explorer.core.controls import CONTROLS, Control
from explorer.core.errors import ExplorerError
from explorer.core.hdr import TONE_MAPS
from explorer.core.lights import LIGHT_TYPES
from explorer.core.material import MODELS, RGB_KEYS
from explorer.shading.strip import MODES as STRIP_MODES

KINDS = ("number", "colour", "choice", "toggle", "triple")
TABS = ("material", "lights", "view")


def _always(_state: M.State) -> bool:
    return True


@dataclass(frozen=True)
class Row:
    """One control of the panel (see the module docstring).

    key, tab, kind, group : its name, where it is drawn and what it is
    value(state) : the value shown (an optional number's None: off)
    edit(state, value) : ``(action, args)``, the model action that sets ``value``
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

    def slider_range(self, state: M.State) -> tuple[float, float]:
        """A number's slider range in ``state`` (:attr:`slider`, else the table's)."""
        if self.slider is not None:
            return self.slider(state)
        return self.control.lo, self.control.hi


# -- the rows ----------------------------------------------------------------------------------
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


def _hdr_on(s: M.State) -> bool:
    return s.scene.hdr is not None


def _view_rows() -> list[Row]:
    return [
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
            choices=STRIP_MODES,
            inline=True,
            tip="weighted: each term as it enters the colour (k·A, k·D, k·S); raw: the light "
            "sums A, D, S alone",
        ),
        *_lobe_rows(),
    ]


def _lobe_option(name: str):
    return lambda s, v: (LI.set_lobe_option, (name, v))


def _lobe_rows() -> list[Row]:
    """The lobe inset's rows: which lobes, and how they are plotted (docs/terms.md)."""
    several = lambda s: s.lobes != "selected"  # noqa: E731 - the rows' one test
    return [
        Row(
            "lobes",
            "view",
            "choice",
            lambda s: s.lobes,
            _lobe_option("lobes"),
            choices=LI.LOBE_SETS,
            tip="the inset's lobes: the selected light's, the three models', each light's, or "
            "sides A and B",
        ),
        Row(
            "lobe_view",
            "view",
            "choice",
            lambda s: s.lobe_view,
            _lobe_option("lobe_view"),
            visible=several,
            choices=LOBE_VIEWS,
            inline=True,
            tip="polar: the plane of incidence, the normal up; cartesian: against the view angle",
        ),
        Row(
            "lobe_quantity",
            "view",
            "choice",
            lambda s: s.lobe_quantity,
            _lobe_option("lobe_quantity"),
            visible=several,
            choices=LOBE_QUANTITIES,
            tip="intensity per unit light, the BRDF (intensity / (π N·L), 1/sr), or the "
            "directional albedo ρ(θ_i)",
        ),
        Row(
            "lobe_log",
            "view",
            "toggle",
            lambda s: s.lobe_log,
            _lobe_option("lobe_log"),
            visible=several,
            group="lobe_scale",
            tip="a log scale: four decades",
        ),
        Row(
            "lobe_ndl",
            "view",
            "toggle",
            lambda s: s.lobe_ndl,
            _lobe_option("lobe_ndl"),
            visible=several,
            group="lobe_scale",
            text="× N·L",
            tip="each value times N·L",
        ),
    ]


#: every row, in the order each tab draws them
ROWS: tuple[Row, ...] = (
    *_material_rows(),
    *_material_effect_rows(),
    *_light_rows(),
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


def edit(state: M.State, key: str, value) -> tuple[Callable, tuple, str]:
    """``(action, args, label)``: what sets control ``key`` to ``value`` in ``state`` (the
    undo step's label). The action refuses a row the state does not show (a spot's cutoff on
    a point light: :func:`explorer.app.model.set_light_field`)."""
    r = row(key)
    action, args = r.edit(state, value)
    return action, args, r.undo_label


def names(r: Row) -> tuple[str, ...]:
    """The accessible names of a row's widgets that both front ends give: its key (the
    control, or the box of a control drawn as several widgets), and an optional number's
    ``<key>_on`` toggle."""
    return (r.key, f"{r.key}_on") if r.kind == "number" and r.optional is not None else (r.key,)


def client_keys() -> dict[str, str]:
    """The page's state keys the rows let a client set (their ``v_model``), with their kind
    as the web guard names kinds (``number``, ``bool``, ``text``): a number's slider step
    ``<key>_step`` and an optional number's switch ``<key>_on``, a choice's value, a toggle's.
    A number's, a colour's and a triple's typed text and a colour's picks are not state: they
    call the page's handlers, which parse what they are given."""
    out: dict[str, str] = {}
    for r in ROWS:
        if r.kind == "number":
            out[f"{r.key}_step"] = "number"
            if r.optional is not None:
                out[f"{r.key}_on"] = "bool"
        elif r.kind == "choice":
            out[r.key] = "text"
        elif r.kind == "toggle":
            out[r.key] = "bool"
    return out
