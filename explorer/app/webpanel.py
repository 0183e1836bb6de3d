"""The web page's controls and the state: what every trame state key shows for a
:class:`~explorer.app.model.State` (:func:`values`), and the handlers that turn a user's change
into one of the controller's intents (:func:`connect`). The layout is
:mod:`explorer.app.webpage`.

Every number of :data:`explorer.core.controls.CONTROLS` has a slider of
:data:`~explorer.core.controls.STEPS` steps (state key ``<key>_step``; log-scaled for the
shininess, as the desktop's) and a field (state key ``<key>``): a slider drag is one undo step
(sealed when it ends), a value typed into a field and confirmed (Enter, or leaving the field)
is one step, parsed as the desktop's fields parse it (:func:`explorer.app.model.parse_number`).
A change the server pushed itself, or one equal to what the state shows, is no change.
"""

from __future__ import annotations

from urllib.parse import quote

from explorer.app import model as M
from explorer.app.colours import parse_hex, rgb_bytes, rgb_hex, rgb_text
from explorer.core.controls import CONTROLS, from_step, to_step
from explorer.core.errors import ExplorerError
from explorer.core.material import RGB_KEYS

MATERIAL_NUMBERS = ("ka", "kd", "ks", "shininess", "opacity")
LIGHT_NUMBERS = ("intensity", "azimuth", "elevation", "distance", "cutoff", "exponent")


def slider_range(state: M.State, key: str) -> tuple[float, float]:
    """The slider's range of control ``key``: the table's, but the distance's widened to hold
    the light's own (mesh radii, :meth:`State.distance_range`)."""
    if key == "distance":
        lo, hi = state.distance_range()
        return lo / state.radius, hi / state.radius
    c = CONTROLS[key]
    return c.lo, c.hi


def number_values(state: M.State) -> dict:
    """Every number control's value in ``state``, rounded to its decimals (None for a light
    control with no light, or one the selected light's type has not)."""
    ka, kd, ks = state.material.scalars()
    out = {"ka": ka, "kd": kd, "ks": ks, "shininess": state.material.shininess,
           "opacity": state.material.opacity}  # fmt: skip
    out.update(dict.fromkeys(LIGHT_NUMBERS))
    light = state.selected_light
    if light is not None:
        az, el, d = state.placement()
        out.update(intensity=M.light_colour(light)[1], azimuth=az, elevation=el,
                   distance=d / state.radius)  # fmt: skip
        if light.type == "spot":
            out.update(cutoff=min(float(light.cutoff), 90.0), exponent=float(light.exponent))
    return {k: None if v is None else round(float(v), CONTROLS[k].decimals)
            for k, v in out.items()}  # fmt: skip


def swatch_url(m) -> str:
    """The desktop's swatch of material ``m`` (the diffuse colour with the specular colour in
    the top right quarter) as an SVG data URL."""

    def css(rgb):
        return "rgb({},{},{})".format(*rgb_bytes(rgb))

    svg = ("<svg xmlns='http://www.w3.org/2000/svg' width='18' height='18'>"
           f"<rect width='18' height='18' fill='{css(m.diffuse)}'/>"
           f"<rect x='9' width='9' height='9' fill='{css(m.specular)}'/></svg>")  # fmt: skip
    return "data:image/svg+xml;utf8," + quote(svg)


def preset_item(info) -> dict:
    """A preset as the searchable list shows it: its name, its description and its swatch."""
    m = info.material
    return {"title": info.name, "value": info.name, "subtitle": m.description or "",
            "prependAvatar": swatch_url(m)}  # fmt: skip


def mesh_materials_values(state: M.State) -> dict:
    """What the page says of a mesh file's own materials (as the desktop's box): the line
    (``mesh_materials``: empty when the mesh brings none), the groups with their swatches and
    the one the controls edit (``groups``, ``group``: None while a preset covers the mesh)."""
    line = M.mesh_materials_line(state)
    mm = state.mesh_materials
    if mm is None or state.groups is None:
        return {"mesh_materials": line, "groups": [], "group": None}
    groups = [{"title": mm.names[i] or "(no usemtl)", "value": i, "prependAvatar": swatch_url(m)}
              for i, m in enumerate(state.groups)]  # fmt: skip
    return {"mesh_materials": line, "groups": groups, "group": state.group}


def values(state: M.State) -> dict:
    """Every trame state key the panel shows, from ``state``."""
    out = number_values(state)
    for k in (*MATERIAL_NUMBERS, *LIGHT_NUMBERS):
        v = out[k]
        out[f"{k}_step"] = None if v is None else to_step(CONTROLS[k], v, *slider_range(state, k))
    m = state.material
    out.update({term: rgb_text(getattr(m, term)) for term in RGB_KEYS})
    out.update({f"{term}_hex": rgb_hex(getattr(m, term)) for term in RGB_KEYS})
    out.update({f"show_{t}": t not in state.hidden for t in M.TERMS})
    lights = state.scene.lights
    light = state.selected_light
    positional = light is not None and light.type in ("point", "spot")
    out.update(
        model=state.scene.model, preset=state.preset, edited=state.edited, mesh=state.mesh,
        lights=[{"title": f"{i + 1}: {lt.type}", "value": i} for i, lt in enumerate(lights)],
        light=state.light if lights else None, type=None if light is None else light.type,
        light_color=None if light is None else rgb_text(M.light_colour(light)[0]),
        light_color_hex=None if light is None else rgb_hex(M.light_colour(light)[0]),
        attenuation=rgb_text(light.attenuation) if positional else None,
        difference=state.difference, compare_on=state.compare is not None,
        compare_preset=state.compare_preset, compare_model=state.compare_model,
        compare_difference=state.compare_difference,
    )  # fmt: skip
    out.update(mesh_materials_values(state))
    return out


def _typed(app, parse, send) -> None:
    """A value typed into a field: parsed (``parse()``) and sent (``send(value)``) as one undo
    step; a refused value is said, and the field shows the state's again."""
    try:
        value = parse()
    except ExplorerError as exc:
        app.controller.reject_input(str(exc))
        return
    send(value)


def _numbers(app) -> None:
    """The sliders' and the number fields' handlers."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller

    def on_slider(key):
        def changed(**kw):
            step = kw.get(f"{key}_step")
            s = app.store.state
            shown = values(s)[f"{key}_step"]
            if app.pushing or step is None or shown is None or int(step) == shown:
                return  # the server's own value
            v = round(from_step(CONTROLS[key], int(step), *slider_range(s, key)),
                      CONTROLS[key].decimals)  # fmt: skip
            c.set_value(key, v)

        return app.guard(changed, key)

    for key in (*MATERIAL_NUMBERS, *LIGHT_NUMBERS):
        state.change(f"{key}_step")(on_slider(key))

    def on_field(key, text):
        lo, hi = CONTROLS[key].field_range
        _typed(app, lambda: M.parse_number(key, str(text), lo, hi),
               lambda v: v != number_values(app.store.state)[key]
               and c.set_value(key, v, merge=False))  # fmt: skip

    def colour_sender(key, merge):
        """``send(rgb)``: colour ``key`` set (a run of ``merge`` steps is one undo step)."""
        if key == "light_color":
            return lambda rgb: c.act(M.set_light_colour, rgb, label="light color",
                                     merge=key if merge else None)  # fmt: skip
        return lambda rgb: c.set_value(key, rgb, merge=merge)

    def on_colour(key, text):
        _typed(app, lambda: M.parse_colour(key, str(text)), colour_sender(key, False))

    def on_pick(key, text):
        """A colour picked (8-bit ``#rrggbb``): set when it is not the 8-bit colour the state
        shows already; a run of picks while the picker is open is one undo step (sealed when
        it closes)."""
        if app.pushing or not text:
            return
        send = colour_sender(key, True)
        _typed(app, lambda: parse_hex(key, str(text)), lambda rgb: rgb_hex(rgb)
               != values(app.store.state)[f"{key}_hex"] and send(rgb))  # fmt: skip

    def on_attenuation(text):
        lo, hi = CONTROLS["attenuation"].field_range

        def parse():
            parts = [M.parse_number("attenuation", t, lo, hi) for t in str(text).split(",")]
            if len(parts) != 3:
                raise ExplorerError(f"attenuation: give three numbers kc, kl, kq, got {text!r}")
            return tuple(parts)

        _typed(app, parse, lambda v: c.set_value("attenuation", v, merge=False))

    ctrl.on_field = app.guard(on_field, "field")
    ctrl.on_colour = app.guard(on_colour, "colour")
    ctrl.on_pick = app.guard(on_pick, "colour picker")
    ctrl.on_attenuation = app.guard(on_attenuation, "attenuation")
    ctrl.seal = app.guard(c.release, "slider")


def _choices(app) -> None:
    """The selects, switches and buttons: each an intent of the controller."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller

    def user(name, check, act):
        """State key ``name``'s handler: ``act(value)`` when ``check(value, state)`` says the
        page's value is not the state's."""

        def changed(**kw):
            v = kw.get(name)
            if not app.pushing and v is not None and check(v, app.store.state):
                act(v)

        state.change(name)(app.guard(changed, name))

    user("model", lambda v, s: v != s.scene.model,
         lambda v: c.act(M.set_model, v, label="model"))  # fmt: skip
    for term in M.TERMS:
        user(f"show_{term}", lambda v, s, t=term: bool(v) != (t not in s.hidden),
             lambda v, t=term: c.act(M.set_term, t, bool(v), label=f"{t} term"))  # fmt: skip
    user("preset", lambda v, s: v != s.preset, c.pick_preset)
    user("group", lambda v, s: s.groups is not None and int(v) != s.group,
         lambda v: c.act(M.select_group, int(v), label="group"))  # fmt: skip
    ctrl.use_mesh_materials = app.guard(
        lambda: c.act(M.use_mesh_materials, label="mesh materials"), "mesh materials"
    )
    user("light", lambda v, s: int(v) != s.light,
         lambda v: c.act(M.select_light, int(v), label="select light"))  # fmt: skip
    user("type", lambda v, s: s.selected_light is not None and v != s.selected_light.type,
         lambda v: c.act(M.set_light_type, v, label="light type"))  # fmt: skip
    user("mesh", lambda v, s: v != s.mesh, c.files.choose_mesh)
    user("difference", lambda v, s: bool(v) != s.difference,
         lambda v: c.act(M.set_difference, bool(v), label="difference"))  # fmt: skip
    _compare(app, user)
    for name, action in (("add", M.add_light), ("duplicate", M.duplicate_light),
                         ("remove", M.remove_light)):  # fmt: skip
        setattr(
            ctrl,
            f"{name}_light",
            app.guard(lambda a=action, n=name: c.act(a, label=f"{n} light"), f"{name} light"),
        )
    ctrl.undo, ctrl.redo = app.guard(c.undo, "undo"), app.guard(c.redo, "redo")
    ctrl.reset_camera = app.guard(c.reset_camera, "reset camera")
    ctrl.turntable = app.guard(lambda: app.start_turntable(
        str(state.turntable_format), state.turntable_frames), "turntable")  # fmt: skip
    ctrl.cancel_job = app.guard(app.cancel_job, "cancel")
    ctrl.save_preset = app.guard(lambda: app.save_preset(
        state.preset_name or "", bool(state.preset_replace)), "save preset")  # fmt: skip


def _compare(app, user) -> None:
    """The compare view's controls: on / off, side B's preset and model, A − B, swap."""
    c = app.controller

    def preset_b(name):
        info = next((p for p in c.presets if p.name == name), None)
        if info is None:
            raise ExplorerError(f"no preset named '{name}'")
        c.act(M.set_compare_preset, info.name, info.material, label=f"B {info.name}")

    user("compare_on", lambda v, s: bool(v) != (s.compare is not None),
         lambda v: c.act(M.set_compare, bool(v), label="compare"))  # fmt: skip
    user("compare_preset", lambda v, s: s.compare is not None and v != s.compare_preset,
         preset_b)  # fmt: skip
    user("compare_model", lambda v, s: s.compare is not None and v != s.compare_model,
         lambda v: c.act(M.set_compare_model, v, label="B model"))  # fmt: skip
    user("compare_difference", lambda v, s: s.compare is not None
         and bool(v) != s.compare_difference,
         lambda v: c.act(M.set_compare_difference, bool(v), label="A − B"))  # fmt: skip
    app.server.controller.swap_sides = app.guard(c.swap_sides, "swap A and B")


def _files(app) -> None:
    """The triggers (undo and redo from the keys, downloads, the test's report) and the
    uploads."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller
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

    def on_upload(name, opener, where=None):
        def changed(**kw):
            upload = kw.get(name)
            if not upload:
                return
            try:
                opener(upload)
            except ExplorerError as exc:
                c.report(exc, where or name.replace("_", " "))
            finally:
                state[name] = None

        state.change(name)(app.guard(changed, name))

    on_upload("session_upload", app.open_uploaded_session)
    on_upload("mesh_upload", app.open_uploaded_mesh)
    on_upload("mtl_upload", app.import_uploaded_materials, "import materials")


def connect(app) -> None:
    """Every handler of the page (``app``: the :class:`~explorer.app.web.WebExplorer`, with
    its ``server``, ``controller``, ``store``, ``guard`` and ``pushing``)."""
    _numbers(app)
    _choices(app)
    _files(app)
