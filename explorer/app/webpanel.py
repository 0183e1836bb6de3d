"""The web explorer's page: vuetify widgets bound to trame state keys, each named
(``aria-label``) like the scene file's key it sets, and the view rendered on the server.

Every number has a slider (``aria-label="<key> slider"``) and a field (``aria-label="<key>"``):
a slider drag is one undo step (sealed when it ends), a value typed into a field and confirmed
(Enter, or leaving the field) is one step, parsed as the desktop's fields parse it
(:func:`explorer.app.model.parse_number`). :func:`values` gives every control's value from a
state; :func:`build` lays out the page and connects the controls to the explorer's actions.

trame is imported inside :func:`build` (``import explorer`` stays free of it).
"""

from __future__ import annotations

import math
from urllib.parse import quote

from explorer.app import model as M
from explorer.app.scales import (
    INTENSITY_RANGE,
    MAX_INTENSITY,
    STEPS,
    rgb_bytes,
    rgb_text,
    shininess_to_step,
    step_to_shininess,
)
from explorer.core.errors import ExplorerError
from explorer.core.lights import LIGHT_TYPES
from explorer.core.material import (
    COEFFICIENT_RANGE,
    MODELS,
    OPACITY_RANGE,
    RGB_KEYS,
    SHININESS_RANGE,
)
from explorer.geometry.meshes import MESH_SUFFIXES

#: the drawer's width (pixels)
DRAWER_WIDTH = 380
#: the export menu: download kind -> its entry
EXPORTS = {
    "png": "view as PNG",
    "mtl": "material as .mtl",
    "json": "material as three.js JSON",
    "x3d": "material as X3D",
    "preset": "material as preset YAML",
}
#: a click that asks the server for a file and saves it (the browser's download)
DOWNLOAD_JS = ("trigger('download', ['{kind}']).then(f => f && utils.download(f.name, f.content, "
               "f.type))")  # fmt: skip
#: Ctrl+Z and Ctrl+Shift+Z (also Cmd on a Mac) undo and redo, except in a text field (where
#: they edit the text)
KEYS_JS = """
document.addEventListener('keydown', (e) => {
  if (!(e.ctrlKey || e.metaKey) || (e.key !== 'z' && e.key !== 'Z')) return;
  const t = e.target;
  if (t && t.tagName === 'INPUT' && t.type === 'text') return;
  e.preventDefault();
  window.trame.trigger(e.shiftKey ? 'redo' : 'undo');
});
"""
#: numbers: key -> (slider min, slider max, slider step, field min, field max)
NUMBERS = {
    "ka": (*COEFFICIENT_RANGE, 0.001, *COEFFICIENT_RANGE),
    "kd": (*COEFFICIENT_RANGE, 0.001, *COEFFICIENT_RANGE),
    "ks": (*COEFFICIENT_RANGE, 0.001, *COEFFICIENT_RANGE),
    "opacity": (*OPACITY_RANGE, 0.001, *OPACITY_RANGE),
    "shininess": (0, STEPS, 1, *SHININESS_RANGE),  # the slider's steps are log-scaled
    "intensity": (*INTENSITY_RANGE, 0.01, 0.0, MAX_INTENSITY),
    "azimuth": (-180.0, 180.0, 0.5, -180.0, 180.0),
    "elevation": (-90.0, 90.0, 0.5, -90.0, 90.0),
    "distance": (*M.DISTANCE_RANGE, 0.01, *M.DISTANCE_RANGE),
    "cutoff": (0.0, 90.0, 0.5, 0.0, 90.0),
    "exponent": (0.0, 128.0, 0.5, 0.0, 128.0),
}
MATERIAL_NUMBERS = ("ka", "kd", "ks", "shininess", "opacity")
LIGHT_NUMBERS = ("intensity", "azimuth", "elevation", "distance", "cutoff", "exponent")


def number_values(state: M.State) -> dict:
    """Every number control's value in ``state`` (None for a light control with no light, or
    one the selected light's type has not)."""
    m = state.material
    ka, kd, ks = m.scalars()
    out = {"ka": ka, "kd": kd, "ks": ks, "shininess": float(m.shininess),
           "opacity": float(m.opacity)}  # fmt: skip
    light = state.selected_light
    out.update(dict.fromkeys(LIGHT_NUMBERS))
    if light is not None:
        az, el, d = state.placement()
        out.update(intensity=M.light_colour(light)[1], azimuth=az, elevation=el,
                   distance=d / state.radius)  # fmt: skip
        if light.type == "spot":
            out.update(cutoff=min(float(light.cutoff), 90.0), exponent=float(light.exponent))
    return {k: (None if v is None else round(float(v), 6)) for k, v in out.items()}


def _css(rgb) -> str:
    r, g, b = (int(v) for v in rgb_bytes(rgb))
    return f"rgb({r},{g},{b})"


def preset_item(info) -> dict:
    """A preset as the searchable list shows it: its name, its description and the desktop's
    swatch (the diffuse colour with the specular colour in the top right quarter), as an SVG
    data URL."""
    m = info.material
    svg = ("<svg xmlns='http://www.w3.org/2000/svg' width='18' height='18'>"
           f"<rect width='18' height='18' fill='{_css(m.diffuse)}'/>"
           f"<rect x='9' width='9' height='9' fill='{_css(m.specular)}'/></svg>")  # fmt: skip
    return {"title": info.name, "value": info.name, "subtitle": m.description or "",
            "prependAvatar": "data:image/svg+xml;utf8," + quote(svg)}  # fmt: skip


def values(app, state: M.State) -> dict:
    """Every trame state key the page shows, from ``state``."""
    nums = number_values(state)
    out = dict(nums)
    out["shininess_step"] = shininess_to_step(nums["shininess"])
    for k in LIGHT_NUMBERS:
        out[f"{k}_slider"] = nums[k]
    for k in ("ka", "kd", "ks", "opacity"):
        out[f"{k}_slider"] = nums[k]
    m = state.material
    for term in RGB_KEYS:
        out[term] = rgb_text(getattr(m, term))
    out["model"] = state.scene.model
    for term in M.TERMS:
        out[f"show_{term}"] = term not in state.hidden
    out["preset"] = state.preset
    out["edited"] = state.edited
    lights = state.scene.lights
    out["lights"] = [{"title": f"{i + 1}: {lt.type}", "value": i} for i, lt in enumerate(lights)]
    out["light"] = state.light if lights else None
    light = state.selected_light
    out["type"] = None if light is None else light.type
    out["light_color"] = None if light is None else rgb_text(M.light_colour(light)[0])
    positional = light is not None and light.type in ("point", "spot")
    out["attenuation"] = rgb_text(light.attenuation) if positional else None
    out["mesh"] = state.mesh
    out["difference"] = state.difference
    return out


def _differs(a, b) -> bool:
    if a is None or b is None:
        return a is not b
    return not math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)


def _typed(app, key: str, parse, send) -> None:
    """A value typed into field ``key``: parsed (``parse(text)``) and sent (``send(value)``) as
    one undo step; a refused value is said, and the field shows the state's again."""
    try:
        value = parse()
    except ExplorerError as exc:
        app.controller.reject_input(str(exc))
        return
    send(value)


def connect(app) -> None:
    """The trame state's change handlers and the page's triggers: each user change becomes one
    of the controller's intents (values the server itself pushes, and values equal to the
    state's, are ignored)."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller
    guard = app._guard

    def on_slider(key, name):
        half = 0.5 * NUMBERS[key][2]

        def changed(**kw):
            v, shown = kw.get(name), values(app, app.store.state)[name]
            if app._pushing or v is None or shown is None or abs(float(v) - shown) <= half:
                return  # the server's own value, or the slider rounding it to its step
            c.set_value(key, step_to_shininess(int(v)) if key == "shininess" else float(v))

        return guard(changed)

    for key in NUMBERS:
        name = "shininess_step" if key == "shininess" else f"{key}_slider"
        state.change(name)(on_slider(key, name))

    def on_field(key, text):
        lo, hi = NUMBERS[key][3:]
        _typed(app, key, lambda: M.parse_number(key, str(text), lo, hi),
               lambda v: _differs(v, number_values(app.store.state)[key])
               and c.set_value(key, v, merge=False))  # fmt: skip

    def on_colour(key, text):
        if key == "light_color":
            send = lambda rgb: c.act(M.set_light_colour, rgb, label="light color")  # noqa: E731
        else:
            send = lambda rgb: c.set_value(key, rgb, merge=False)  # noqa: E731
        _typed(app, key, lambda: M.parse_colour(key, str(text)), send)

    def on_attenuation(text):
        def parse():
            parts = [M.parse_number("attenuation", t, 0.0, 1e6) for t in str(text).split(",")]
            if len(parts) != 3:
                raise ExplorerError(f"attenuation: give three numbers kc, kl, kq, got {text!r}")
            return tuple(parts)

        _typed(app, "attenuation", parse, lambda v: c.set_value("attenuation", v, merge=False))

    ctrl.on_field, ctrl.on_colour = guard(on_field), guard(on_colour)
    ctrl.on_attenuation = guard(on_attenuation)

    def user(name, check, act):
        """A handler of state key ``name``: ``act(value)`` when ``check(value, state)`` says
        the page's value is not the state's."""

        def changed(**kw):
            v = kw.get(name)
            if not app._pushing and v is not None and check(v, app.store.state):
                act(v)

        state.change(name)(guard(changed))

    user("model", lambda v, s: v != s.scene.model,
         lambda v: c.act(M.set_model, v, label="model"))  # fmt: skip
    for term in M.TERMS:
        user(f"show_{term}", lambda v, s, t=term: bool(v) != (t not in s.hidden),
             lambda v, t=term: c.act(M.set_term, t, bool(v), label=f"{t} term"))  # fmt: skip
    user("preset", lambda v, s: v != s.preset, c.pick_preset)
    user("light", lambda v, s: int(v) != s.light,
         lambda v: c.act(M.select_light, int(v), label="select light"))  # fmt: skip
    user("type", lambda v, s: s.selected_light is not None and v != s.selected_light.type,
         lambda v: c.act(M.set_light_type, v, label="light type"))  # fmt: skip
    user("mesh", lambda v, s: v != s.mesh, c.choose_mesh)
    user("difference", lambda v, s: bool(v) != s.difference,
         lambda v: c.act(M.set_difference, bool(v), label="difference"))  # fmt: skip

    ctrl.add_light = guard(lambda: c.act(M.add_light, label="add light"))
    ctrl.duplicate_light = guard(lambda: c.act(M.duplicate_light, label="duplicate light"))
    ctrl.remove_light = guard(lambda: c.act(M.remove_light, label="remove light"))
    ctrl.undo, ctrl.redo, ctrl.seal = guard(c.undo), guard(c.redo), guard(c.release)
    ctrl.reset_camera = guard(c.reset_camera)
    ctrl.save_preset = guard(lambda: app.save_preset(state.preset_name or "",
                                                     bool(state.preset_replace)))  # fmt: skip
    ctrl.trigger("undo")(c.undo)
    ctrl.trigger("redo")(c.redo)
    ctrl.trigger("report")(app.report_state)

    @ctrl.trigger("download")
    def download(kind):
        try:
            return app.download(kind)
        except ExplorerError as exc:
            c.report(exc, f"download {kind}")
            return None

    def on_upload(name, opener):
        def changed(**kw):
            upload = kw.get(name)
            if not upload:
                return
            try:
                opener(upload)
            except ExplorerError as exc:
                c.report(exc, name.replace("_", " "))
            finally:
                state[name] = None

        state.change(name)(guard(changed))

    on_upload("session_upload", app.open_uploaded_session)
    on_upload("mesh_upload", app.open_uploaded_mesh)


def _number(v3, html, ctrl, key: str, label: str) -> None:
    """A slider and a number field for ``key`` in one row."""
    lo, hi, step, _, _ = NUMBERS[key]
    model = "shininess_step" if key == "shininess" else f"{key}_slider"
    with html.Div(classes="d-flex align-center", v_show=f"{key} !== null"):
        v3.VSlider(
            v_model=(model, 0), min=lo, max=hi, step=step, label=label, hide_details=True,
            density="compact", end=ctrl.seal, raw_attrs=[f'aria-label="{key} slider"'],
            classes="flex-grow-1 mr-2",
        )  # fmt: skip
        v3.VTextField(
            model_value=(key, 0), type="text", density="compact", hide_details=True,
            variant="outlined", style="max-width: 92px",
            change=(ctrl.on_field, f"['{key}', $event.target.value]"),
            raw_attrs=[f'aria-label="{key}"'],
        )  # fmt: skip


def _colour(v3, ctrl, key: str, label: str) -> None:
    """A colour field ``"r, g, b"`` for state key ``key``, named ``label`` (the scene file's
    key)."""
    v3.VTextField(
        model_value=(key, ""), label=label, density="compact", hide_details=True,
        variant="outlined", classes="my-1",
        change=(ctrl.on_colour, f"['{key}', $event.target.value]"),
        raw_attrs=[f'aria-label="{label}"'],
    )  # fmt: skip


def _material_tab(v3, html, ctrl) -> None:
    """The preset, the numbers, the colours, the model and the terms."""
    v3.VAutocomplete(
        v_model=("preset", None), items=("presets", []), label="preset", item_props=True,
        density="compact", hide_details=True, raw_attrs=['aria-label="preset"'],
    )  # fmt: skip
    for key in MATERIAL_NUMBERS:
        _number(v3, html, ctrl, key, key)
    for term in RGB_KEYS:
        _colour(v3, ctrl, term, term)
    v3.VSelect(v_model=("model", "blinn"), items=("models",), label="model",
               density="compact", hide_details=True,
               raw_attrs=['aria-label="model"'])  # fmt: skip
    with html.Div(classes="d-flex"):
        for term in M.TERMS:
            v3.VCheckbox(v_model=(f"show_{term}", True), label=term,
                         density="compact", hide_details=True,
                         raw_attrs=[f'aria-label="show_{term}"'])  # fmt: skip


def _lights_tab(v3, html, ctrl) -> None:
    """The light list, add / duplicate / remove, and the selected light."""
    v3.VSelect(v_model=("light", 0), items=("lights",), label="light",
               density="compact", hide_details=True,
               raw_attrs=['aria-label="light"'])  # fmt: skip
    with html.Div(classes="d-flex my-1"):
        for name in ("add", "duplicate", "remove"):
            v3.VBtn(name, click=getattr(ctrl, f"{name}_light"), size="small",
                    classes="mr-1", raw_attrs=[f'aria-label="{name} light"'])  # fmt: skip
    v3.VSelect(v_model=("type", None), items=("light_types",), label="type",
               density="compact", hide_details=True, v_show="type !== null",
               raw_attrs=['aria-label="type"'])  # fmt: skip
    _colour(v3, ctrl, "light_color", "color")
    for key in LIGHT_NUMBERS:
        _number(v3, html, ctrl, key, key)
    v3.VTextField(
        model_value=("attenuation", ""), label="attenuation (kc, kl, kq)",
        density="compact", hide_details=True, variant="outlined",
        v_show="attenuation !== null",
        change=(ctrl.on_attenuation, "[$event.target.value]"),
        raw_attrs=['aria-label="attenuation"'],
    )  # fmt: skip


def _view_tab(v3, html, ctrl) -> None:
    """The mesh chooser and upload, the difference view and its legend."""
    v3.VSelect(v_model=("mesh", None), items=("meshes",), label="mesh",
               density="compact", hide_details=True,
               raw_attrs=['aria-label="mesh"'])  # fmt: skip
    v3.VFileInput(
        v_model=("mesh_upload", None), label="upload a mesh (an OBJ with its .mtl files)",
        multiple=True, density="compact", hide_details=True, classes="my-2",
        accept=",".join(MESH_SUFFIXES) + ",.mtl", raw_attrs=['aria-label="upload mesh"'],
    )  # fmt: skip
    v3.VSwitch(v_model=("difference", False), label="difference from the exact lighting",
               density="compact", hide_details=True, color="primary",
               raw_attrs=['aria-label="difference"'])  # fmt: skip
    html.Div("{{ legend }}", classes="text-caption", v_show="difference")
    v3.VBtn("reset camera", click=ctrl.reset_camera, size="small", classes="my-2",
            raw_attrs=['aria-label="reset camera"'])  # fmt: skip


def _files(v3, ctrl) -> None:
    """The toolbar's files: save and open a session, export the view and the material."""
    v3.VBtn("save session", variant="text", raw_attrs=['aria-label="save session"'],
            click=DOWNLOAD_JS.format(kind="session"))  # fmt: skip
    v3.VFileInput(
        v_model=("session_upload", None), label="open session", accept=".yaml,.yml,.json",
        density="compact", hide_details=True, style="max-width: 200px", prepend_icon="",
        raw_attrs=['aria-label="open session"'],
    )  # fmt: skip
    with v3.VMenu():
        with v3.Template(v_slot_activator="{ props }"):
            v3.VBtn("export", v_bind="props", variant="text", raw_attrs=['aria-label="export"'])
        with v3.VList(density="compact"):
            for kind, text in EXPORTS.items():
                v3.VListItem(title=text, click=DOWNLOAD_JS.format(kind=kind),
                             raw_attrs=[f'aria-label="export {kind}"'])  # fmt: skip


def _save_preset(v3, html, ctrl) -> None:
    """Save the material as a preset in the user's preset folder."""
    with html.Div(classes="d-flex align-center my-1"):
        v3.VTextField(v_model=("preset_name", ""), label="save as preset", density="compact",
                      hide_details=True, variant="outlined", classes="mr-1",
                      raw_attrs=['aria-label="preset name"'])  # fmt: skip
        v3.VCheckbox(v_model=("preset_replace", False), label="replace", density="compact",
                     hide_details=True, raw_attrs=['aria-label="replace preset"'])  # fmt: skip
        v3.VBtn("save", click=ctrl.save_preset, size="small",
                raw_attrs=['aria-label="save preset"'])  # fmt: skip


def build(app) -> None:
    """The page: the toolbar (undo / redo, files), the drawer (the panel) and the view."""
    from trame.ui.vuetify3 import SinglePageWithDrawerLayout
    from trame.widgets import client, html
    from trame.widgets import vtk as vtkw
    from trame.widgets import vuetify3 as v3

    server = app.server
    ctrl = server.controller
    connect(app)
    server.state.update(
        models=list(MODELS), light_types=list(LIGHT_TYPES), message="", message_level="info",
        message_log=[], legend="", tab="material", preset_name="", preset_replace=False,
        session_upload=None, mesh_upload=None, can_undo=False, can_redo=False,
    )  # fmt: skip
    with SinglePageWithDrawerLayout(server, full_height=True) as layout:
        layout.title.set_text("phong-explorer")
        layout.drawer.width = DRAWER_WIDTH
        client.Script(KEYS_JS)
        with layout.toolbar:
            v3.VSpacer()
            v3.VBtn("undo", click=ctrl.undo, disabled=("!can_undo",), variant="text",
                    title=("'Undo ' + undo_label + ' (Ctrl+Z)'",),
                    raw_attrs=['aria-label="undo"'])  # fmt: skip
            v3.VBtn("redo", click=ctrl.redo, disabled=("!can_redo",), variant="text",
                    title=("'Redo ' + redo_label + ' (Ctrl+Shift+Z)'",),
                    raw_attrs=['aria-label="redo"'])  # fmt: skip
            _files(v3, ctrl)
        with layout.drawer:
            with v3.VTabs(v_model="tab", density="compact", grow=True):
                for t in ("material", "lights", "view"):
                    v3.VTab(t, value=t, raw_attrs=[f'aria-label="{t} tab"'])
            with v3.VWindow(v_model="tab"):
                with v3.VWindowItem(value="material", classes="pa-2"):
                    _material_tab(v3, html, ctrl)
                    _save_preset(v3, html, ctrl)
                with v3.VWindowItem(value="lights", classes="pa-2"):
                    _lights_tab(v3, html, ctrl)
                with v3.VWindowItem(value="view", classes="pa-2"):
                    _view_tab(v3, html, ctrl)
            html.Div("{{ message }}", classes=("'text-caption pa-2 ' + (message_level === "
                     "'error' ? 'text-error' : '')",), raw_attrs=['role="status"'])  # fmt: skip
        with layout.content, v3.VContainer(fluid=True, classes="pa-0 fill-height"):
            view = vtkw.VtkRemoteView(app.plotter.render_window, interactive_ratio=1,
                                      still_quality=100, interactive_quality=100,
                                      raw_attrs=['aria-label="view"'])  # fmt: skip
            ctrl.view_update = view.update
    app.layout = layout
