"""The web page's controls and the state: what every trame state key shows for a
:class:`~explorer.app.model.State` (:func:`values`), and the handlers that turn a user's change
into one of the controller's intents (:func:`connect`). The layout is
:mod:`explorer.app.web.page`.

The rows of :mod:`explorer.app.panelmodel` are handled by kind, none by name: a row's state key
is its key, None while the row is hidden (a spot's cutoff for a point light). A number has a
slider of :data:`~explorer.core.controls.STEPS` steps (state key ``<key>_step``; log-scaled for
the shininess, as the desktop's) and a field (state key ``<key>``): a slider drag is one undo
step (sealed when it ends), a value typed into a field and confirmed (Enter, or leaving the
field) is one step, parsed as the desktop's fields parse it
(:func:`explorer.app.model.parse_number`). An optional number has its switch ``<key>_on``; a
colour its ``r, g, b`` text and its 8-bit ``<key>_hex``; a choice, a toggle, a list and a triple
their value; an image (a texture map) its file's name (state key ``<key>``), its switch
``<key>_on``, its thumbnail as a PNG data URL (``<key>_thumbnail``, made once per file) and its
upload ``<key>_upload``. A list's (or a choice's) items are state key ``<key>_items`` when the
state gives them (the lights), or the catalogue's own key (``presets``, set when the
controller's presets change: :func:`item`). Every edit is :meth:`Controller.set_value`. A
change the server pushed itself, or one equal to what the state shows, is no change.
"""

from __future__ import annotations

import base64
import functools
import io
from urllib.parse import quote

from explorer.app import model as M
from explorer.app import panelmodel, rowlayout
from explorer.app.colours import parse_hex, rgb_hex, rgb_text, swatch_squares
from explorer.core.controls import field_text, from_step, to_step
from explorer.core.errors import ExplorerError
from explorer.render.textures import file_stamp, thumbnail

#: the number rows (a slider and a field each)
NUMBERS = tuple(r for r in panelmodel.ROWS if r.kind == "number")
#: what the page is told when its ``mesh`` is not one of the chooser's (the same words for a
#: missing file, an existing one or anything else: nothing is loaded, no path is named)
MESH_REFUSED = "mesh: choose one of the listed meshes, or upload a mesh file"


def number_values(state: M.State) -> dict:
    """Every number row's value in ``state``, rounded to its decimals (None for a row not
    shown: a light control with no light, or one the selected light has not; an optional
    number that is off)."""
    out = {}
    for r in NUMBERS:
        v = r.shown(state)
        out[r.key] = None if v is None else round(float(v), r.control.decimals)
    return out


def swatch_url(m) -> str:
    """The desktop's swatch of material ``m`` (:func:`~explorer.app.colours.swatch_squares`:
    the diffuse colour with the specular colour in the top right quarter) as an SVG data
    URL."""
    rects = "".join(
        f"<rect x='{x}' y='{y}' width='{w}' height='{h}' fill='rgb({r},{g},{b})'/>"
        for x, y, w, h, (r, g, b) in swatch_squares(m, 18)
    )
    svg = f"<svg xmlns='http://www.w3.org/2000/svg' width='18' height='18'>{rects}</svg>"
    return "data:image/svg+xml;utf8," + quote(svg)


def thumbnail_url(file: str, key: str) -> str:
    """Image ``file``'s thumbnail (:func:`explorer.render.textures.thumbnail`, the window's) as
    a PNG data URL; "" when the file cannot be read now (its name says which)."""
    try:
        return _png_url(file, key, file_stamp(file))
    except ExplorerError:
        return ""


@functools.lru_cache(maxsize=64)
def _png_url(file: str, key: str, _stamp) -> str:
    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(thumbnail(file, key)).save(out, format="PNG")
    return "data:image/png;base64," + base64.b64encode(out.getvalue()).decode("ascii")


def item(it: panelmodel.Item) -> dict:
    """A list's item as the page's lists show it: its title, its value, its subtitle and its
    swatch when it has them."""
    out = {"title": it.title, "value": it.value}
    if it.subtitle:
        out["subtitle"] = it.subtitle
    if it.swatch is not None:
        out["prependAvatar"] = swatch_url(it.swatch)
    return out


def items_key(r: panelmodel.Row) -> str:
    """The state key of a list's (or a choice's) items: its catalogue's, else its own."""
    return r.source or f"{r.key}_items"


def slider_step(r: panelmodel.Row, state: M.State) -> int | None:
    """Number row ``r``'s slider step in ``state`` (None while the row is not shown): its value
    rounded to its decimals, as its field shows it."""
    v = r.shown(state)
    if v is None:
        return None
    return to_step(r.control, round(float(v), r.control.decimals), *r.slider_range(state))


def row_values(state: M.State) -> dict:
    """Every row's state keys (see the module docstring), from ``state``."""
    out = number_values(state)
    for r in panelmodel.ROWS:
        v = r.shown(state)
        if r.kind == "number":
            out[f"{r.key}_step"] = slider_step(r, state)
            out[f"{r.key}_text"] = None if v is None else field_text(r.control, v)
            if r.optional is not None:
                out[f"{r.key}_on"] = (v is not None) if r.visible(state) else None
        elif r.kind == "colour":
            out[r.key] = None if v is None else rgb_text(v)
            out[f"{r.key}_hex"] = None if v is None else rgb_hex(v)
        elif r.kind == "triple":
            out[r.key] = None if v is None else rgb_text(v)
        elif r.kind == "image":
            file, on = v if v is not None else (None, None)
            out[r.key] = None if v is None else rowlayout.file_text(file)
            out[f"{r.key}_on"] = None if v is None else bool(on)
            out[f"{r.key}_thumbnail"] = "" if file is None else thumbnail_url(file, r.key)
        else:
            out[r.key] = v
        if r.items is not None:  # (none while the row is hidden)
            out[items_key(r)] = [item(it) for it in r.items(state)] if r.visible(state) else []
    return out


def values(state: M.State) -> dict:
    """Every trame state key the panel shows, from ``state``."""
    out = row_values(state)
    out.update(edited=state.edited, mesh=state.mesh)
    return out


def _kind(value) -> type:
    """The kind of a state value the page sends back: bool, int, float (an int is one too),
    text, or another type."""
    if isinstance(value, bool):
        return bool
    return float if isinstance(value, int | float) else type(value)


def page_value(name: str, read, value, like=None):
    """``read(value)``: a value the page sent for state key ``name``, read by its handler. A
    value of another kind than ``like`` (the server's own value of the key, when it has one)
    or that ``read`` cannot take (text where a number goes, NaN, a list: no page of ours
    sends one) is one line naming the key, not a traceback (issue 37)."""
    shown = repr(value)
    shown = shown if len(shown) <= 40 else shown[:37] + "..."
    problem = ExplorerError(f"{name}: the page sent {shown}, not a value of {name}")
    if like is not None and _kind(value) is not _kind(like):
        raise problem
    try:
        return read(value)
    except (TypeError, ValueError, ArithmeticError):
        raise problem from None


def _typed(app, parse, send) -> None:
    """A value typed into a field: parsed (``parse()``) and sent (``send(value)``, true when
    the state took it) as one undo step; a refused value is said, and the fields show the
    state's values again (:func:`show_fields_again`)."""
    try:
        value = parse()
    except ExplorerError as exc:
        app.controller.reject_input(str(exc))
        show_fields_again(app)
        return
    if not send(value):
        show_fields_again(app)


def show_fields_again(app) -> None:
    """The page's typed fields drawn anew from the state (state ``field_rev``, each field's Vue
    key): a field shows its state key one way, and trame sends no value equal to the one it
    sent last, so a field holding refused text (``5000``, ``abc``) kept it beside a slider
    showing the state."""
    with app.server.state as s:
        s.field_rev = (s.field_rev or 0) + 1


def _numbers(app) -> None:
    """The sliders', the number fields', the colours' and the triples' handlers (every row of
    those kinds)."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller

    def on_slider(r):
        def changed(**kw):
            step = kw.get(f"{r.key}_step")
            s = app.store.state
            shown = slider_step(r, s)  # this row's step only (every slider event comes here)
            if app.pushing or step is None or shown is None:
                return  # the server's own value
            step = page_value(f"{r.key}_step", int, step)
            if step == shown:
                return
            v = round(from_step(r.control, step, *r.slider_range(s)), r.control.decimals)
            c.set_value(r.key, v)

        return app.guard(changed, r.key)

    for r in NUMBERS:
        state.change(f"{r.key}_step")(on_slider(r))

    def on_typed(key, text):
        """A number's, a colour's or a triple's field confirmed: its text parsed as the row
        parses it (:meth:`~explorer.app.panelmodel.Row.parse`), set when it is not the value
        the field shows (a number's, rounded)."""
        r = panelmodel.row(str(key))
        shown = number_values(app.store.state).get(r.key)
        _typed(
            app, lambda: r.parse(text), lambda v: v != shown and c.set_value(r.key, v, merge=False)
        )

    def on_pick(key, text):
        """A colour picked (8-bit ``#rrggbb``): set when it is not the 8-bit colour the state
        shows already; a run of picks while the picker is open is one undo step (sealed when
        it closes)."""
        if app.pushing or not text:
            return
        _typed(
            app,
            lambda: parse_hex(key, str(text)),
            lambda rgb: (
                rgb_hex(rgb) == values(app.store.state)[f"{key}_hex"] or c.set_value(key, rgb)
            ),
        )

    ctrl.on_typed = app.guard(on_typed, "field")
    ctrl.on_pick = app.guard(on_pick, "colour picker")
    ctrl.seal = app.guard(c.release, "slider")


def _rows(app, user) -> None:
    """The choices', the toggles', the lists' and the optional numbers' switches' handlers:
    each ``set_value`` of its row, when the page's value is not the state's (a button is
    pressed through ``press``)."""
    c = app.controller
    for r in panelmodel.ROWS:
        if r.kind in ("choice", "toggle", "list"):
            user(
                r.key,
                lambda v, s, r=r: r.visible(s) and v != r.value(s),
                lambda v, r=r: c.set_value(r.key, v, merge=False),
            )
        elif r.kind == "image":
            user(
                f"{r.key}_on",
                lambda v, s, r=r: (
                    r.visible(s) and r.value(s)[0] is not None and bool(v) != r.value(s)[1]
                ),
                lambda v, r=r: c.set_value(r.key, bool(v), merge=False),
            )
        elif r.optional is not None:
            user(
                f"{r.key}_on",
                lambda v, s, r=r: r.visible(s) and bool(v) != (r.value(s) is not None),
                lambda v, r=r: c.set_value(r.key, r.optional if v else None, merge=False),
            )


def _choices(app) -> None:
    """The selects, switches and buttons: each an intent of the controller."""
    state, ctrl, c = app.server.state, app.server.controller, app.controller

    def user(name, check, act):
        """State key ``name``'s handler: ``act(value)`` when ``check(value, state)`` says the
        page's value is not the state's."""

        def changed(**kw):
            v = kw.get(name)
            if app.pushing or v is None:
                return
            s = app.store.state
            if page_value(name, lambda x: check(x, s), v, like=values(s).get(name)):
                act(v)

        state.change(name)(app.guard(changed, name))

    _rows(app, user)

    def choose_mesh(value):
        """A mesh of the chooser's list only (a built-in, the start's, an upload: values the
        page was given, :class:`~explorer.app.web.guard.MeshValues`): any other value (a path
        sent over the socket) is refused in the same words, naming nothing."""
        name = app.mesh_values.name(value)
        if name in c.mesh_choices:
            c.files.choose_mesh(name)
        else:
            c.reject_input(MESH_REFUSED)

    user("mesh", lambda v, s: v != app.mesh_values.page(s.mesh), choose_mesh)

    def row_edit(kind: str, value, noun: str):
        """What the page's ``kind`` rows send by key (a button pressed: True; an image row's
        clear: None); any other key from the page is refused."""

        def edit(key):
            r = panelmodel.BY_KEY.get(str(key))
            if r is None or r.kind != kind:
                raise ExplorerError(f"the page has no {noun} named '{key}'")
            c.set_value(r.key, value, merge=False)

        return edit

    ctrl.press = app.guard(row_edit("button", True, "button"), "button")
    ctrl.clear_map = app.guard(row_edit("image", None, "texture map"), "clear map")
    ctrl.undo, ctrl.redo = app.guard(c.undo, "undo"), app.guard(c.redo, "redo")
    ctrl.reset_camera = app.guard(c.reset_camera, "reset camera")
    ctrl.turntable = app.guard(lambda: app.files.start_turntable(
        str(state.turntable_format), state.turntable_frames), "turntable")  # fmt: skip
    ctrl.cancel_job = app.guard(app.cancel_job, "cancel")
    ctrl.save_preset = app.guard(lambda: app.files.save_preset(
        state.preset_name or "", bool(state.preset_replace)), "save preset")  # fmt: skip


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
            return app.files.download(kind)
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

    on_upload("session_upload", app.files.open_uploaded_session)
    on_upload("mesh_upload", app.files.open_uploaded_mesh)
    on_upload("mtl_upload", app.files.import_uploaded_materials, "import materials")
    for r in panelmodel.ROWS:
        if r.kind == "image":
            on_upload(
                f"{r.key}_upload", lambda u, k=r.key: app.files.open_uploaded_map(k, u), r.key
            )


def connect(app) -> None:
    """Every handler of the page (``app``: the :class:`~explorer.app.web.WebExplorer`, with
    its ``server``, ``controller``, ``store``, ``guard`` and ``pushing``)."""
    _numbers(app)
    _choices(app)
    _files(app)
