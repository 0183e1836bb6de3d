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

from explorer.app import model as M
from explorer.app.scales import (
    INTENSITY_RANGE,
    MAX_INTENSITY,
    STEPS,
    rgb_text,
    shininess_to_step,
    step_to_shininess,
)
from explorer.app.start import MESH_CHOICES
from explorer.core.errors import ExplorerError
from explorer.core.lights import LIGHT_TYPES
from explorer.core.material import (
    COEFFICIENT_RANGE,
    MODELS,
    OPACITY_RANGE,
    RGB_KEYS,
    SHININESS_RANGE,
)

#: the drawer's width (pixels)
DRAWER_WIDTH = 380
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


def number_action(state: M.State, key: str, value: float):
    """``(action, *args)`` that sets number ``key`` to ``value`` (distance in mesh radii)."""
    if key in ("ka", "kd", "ks"):
        return (M.set_coefficient, key, value)
    if key == "shininess":
        return (M.set_shininess, value)
    if key == "opacity":
        return (M.set_opacity, value)
    if key == "intensity":
        return (M.set_light_intensity, value)
    if key == "azimuth":
        return (M.place_light, value, None, None)
    if key == "elevation":
        return (M.place_light, None, value, None)
    if key == "distance":
        return (M.place_light, None, None, value * state.radius)
    if key in ("cutoff", "exponent"):
        return (M.set_light_field, key, value)
    raise ExplorerError(f"no number control {key!r}")


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
    out["can_undo"] = app.store.can_undo if app else False
    out["can_redo"] = app.store.can_redo if app else False
    return out


def _differs(a, b) -> bool:
    if a is None or b is None:
        return a is not b
    return not math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-9)


def connect(app) -> None:
    """The trame state's change handlers: each user change becomes an action on the store
    (changes the server itself pushes, and values equal to the state's, are ignored)."""
    state, ctrl = app.server.state, app.server.controller

    def on_slider(key, name):
        half = 0.5 * NUMBERS[key][2]

        def changed(**kw):
            v, shown = kw.get(name), values(app, app.store.state)[name]
            if app._pushing or v is None or shown is None or abs(float(v) - shown) <= half:
                return  # the server's own value, or the slider rounding it to its step
            s = app.store.state
            n = step_to_shininess(int(v)) if key == "shininess" else float(v)
            app.act(*number_action(s, key, n), label=key, merge=key)

        return changed

    for key in NUMBERS:
        name = "shininess_step" if key == "shininess" else f"{key}_slider"
        state.change(name)(on_slider(key, name))

    def on_field(key, text):
        lo, hi = NUMBERS[key][3:]
        try:
            v = M.parse_number(key, str(text), lo, hi)
        except ExplorerError as exc:
            app.report(exc, key)
            app._push(app.store.state)
            return
        if _differs(v, number_values(app.store.state)[key]):
            app.act(*number_action(app.store.state, key, v), label=key)

    ctrl.on_field = on_field

    def on_colour(key, text):
        try:
            rgb = M.parse_colour(key, str(text))
        except ExplorerError as exc:
            app.report(exc, key)
            app._push(app.store.state)
            return
        if key == "light_color":
            app.act(M.set_light_colour, rgb, label="light color")
        else:
            app.act(M.set_colour, key, rgb, label=key)

    ctrl.on_colour = on_colour

    @state.change("model")
    def _model(model, **_):
        if not app._pushing and model != app.store.state.scene.model:
            app.act(M.set_model, model, label="model")

    for term in M.TERMS:

        def toggled(term=term, **kw):
            on = bool(kw[f"show_{term}"])
            if not app._pushing and on != (term not in app.store.state.hidden):
                app.act(M.set_term, term, on, label=f"{term} term")

        state.change(f"show_{term}")(toggled)

    @state.change("preset")
    def _preset(preset, **_):
        if app._pushing or preset is None or preset == app.store.state.preset:
            return
        info = next((p for p in app.presets if p.name == preset), None)
        if info is None:
            app.report(ExplorerError(f"no preset {preset!r}"), "preset")
            return
        app.act(M.apply_preset, info.name, info.material, label=f"preset {info.name}")

    @state.change("light")
    def _light(light, **_):
        if not app._pushing and light is not None and light != app.store.state.light:
            app.act(M.select_light, int(light), label="select light")

    @state.change("type")
    def _type(type, **_):  # noqa: A002 - the scene file's key
        s = app.store.state
        if not app._pushing and type and s.selected_light is not None:
            if type != s.selected_light.type:
                app.act(M.set_light_type, type, label="light type")

    @state.change("mesh")
    def _mesh(mesh, **_):
        if not app._pushing and mesh and mesh != app.store.state.mesh:
            app.choose_mesh(mesh)

    ctrl.add_light = lambda: app.act(M.add_light, label="add light")
    ctrl.duplicate_light = lambda: app.act(M.duplicate_light, label="duplicate light")
    ctrl.remove_light = lambda: app.act(M.remove_light, label="remove light")

    def on_attenuation(text):
        try:
            parts = [M.parse_number("attenuation", t, 0.0, 1e6) for t in str(text).split(",")]
            if len(parts) != 3:
                raise ExplorerError(f"attenuation: give three numbers kc, kl, kq, got {text!r}")
        except ExplorerError as exc:
            app.report(exc, "attenuation")
            app._push(app.store.state)
            return
        app.act(M.set_light_field, "attenuation", tuple(parts), label="attenuation")

    ctrl.on_attenuation = on_attenuation
    ctrl.undo = app.undo
    ctrl.redo = app.redo
    ctrl.seal = app.seal


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
    v3.VTextField(
        model_value=(key, ""), label=label, density="compact", hide_details=True,
        variant="outlined", classes="my-1",
        change=(ctrl.on_colour, f"['{key}', $event.target.value]"),
        raw_attrs=[f'aria-label="{key}"'],
    )  # fmt: skip


def _material_tab(v3, html, ctrl) -> None:
    """The preset, the numbers, the colours, the model and the terms."""
    v3.VAutocomplete(
        v_model=("preset", None), items=("presets",), label="preset",
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
                         raw_attrs=[f'aria-label="{term}"'])  # fmt: skip


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
    """The mesh chooser."""
    v3.VSelect(v_model=("mesh", None), items=("meshes",), label="mesh",
               density="compact", hide_details=True,
               raw_attrs=['aria-label="mesh"'])  # fmt: skip


def build(app) -> None:
    """The page: the toolbar (undo / redo, files), the drawer (the panel) and the view."""
    from trame.ui.vuetify3 import SinglePageWithDrawerLayout
    from trame.widgets import html
    from trame.widgets import vtk as vtkw
    from trame.widgets import vuetify3 as v3

    server = app.server
    ctrl = server.controller
    connect(app)
    server.state.update(
        presets=[p.name for p in app.presets], meshes=list(MESH_CHOICES), models=list(MODELS),
        light_types=list(LIGHT_TYPES), message="", tab="material",
    )  # fmt: skip
    with SinglePageWithDrawerLayout(server, full_height=True) as layout:
        layout.title.set_text("phong-explorer")
        layout.drawer.width = DRAWER_WIDTH
        with layout.toolbar:
            v3.VSpacer()
            v3.VBtn("undo", click=ctrl.undo, disabled=("!can_undo",), variant="text",
                    raw_attrs=['aria-label="undo"'])  # fmt: skip
            v3.VBtn("redo", click=ctrl.redo, disabled=("!can_redo",), variant="text",
                    raw_attrs=['aria-label="redo"'])  # fmt: skip
            v3.VBtn("save session", variant="text", raw_attrs=['aria-label="save session"'],
                    click="utils.download('session.yaml', trigger('session_text'), "
                    "'text/yaml')")  # fmt: skip
            v3.VFileInput(
                v_model=("session_upload", None), label="open session", accept=".yaml,.yml,.json",
                density="compact", hide_details=True, style="max-width: 220px",
                prepend_icon="", raw_attrs=['aria-label="open session"'],
            )  # fmt: skip
        with layout.drawer:
            with v3.VTabs(v_model="tab", density="compact", grow=True):
                for t in ("material", "lights", "view"):
                    v3.VTab(t, value=t, raw_attrs=[f'aria-label="{t} tab"'])
            with v3.VWindow(v_model="tab"):
                with v3.VWindowItem(value="material", classes="pa-2"):
                    _material_tab(v3, html, ctrl)
                with v3.VWindowItem(value="lights", classes="pa-2"):
                    _lights_tab(v3, html, ctrl)
                with v3.VWindowItem(value="view", classes="pa-2"):
                    _view_tab(v3, html, ctrl)
            html.Div("{{ message }}", classes="text-caption pa-2", raw_attrs=['role="status"'])
        with layout.content, v3.VContainer(fluid=True, classes="pa-0 fill-height"):
            view = vtkw.VtkRemoteView(app.plotter.render_window, interactive_ratio=1,
                                      still_quality=100, interactive_quality=100,
                                      raw_attrs=['aria-label="view"'])  # fmt: skip
            ctrl.view_update = view.update
            ctrl.view_reset_camera = view.reset_camera
    app.layout = layout

    @ctrl.trigger("session_text")
    def session_text():
        return app.session_text()

    @ctrl.trigger("report")
    def report():
        return app.report_state()

    @server.state.change("session_upload")
    def _upload(session_upload, **_):
        if not session_upload:
            return
        f = session_upload[0] if isinstance(session_upload, list) else session_upload
        try:
            app.open_uploaded_session(f)
        except ExplorerError as exc:
            app.report(exc, "open session")
        finally:
            server.state.session_upload = None
