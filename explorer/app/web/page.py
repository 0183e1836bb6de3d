"""The web explorer's page: a vuetify layout of the panel (material, lights and view tabs), the
toolbar (undo / redo, sessions, exports) and the view rendered on the server (trame's
``VtkRemoteView``). Every control is named (``aria-label``) like the scene file's key it sets
(``kd``, ``shininess``, ``azimuth``...; a slider ``<key> slider``, a term's switch
``show_<term>``), so tests and screen readers find it. The state keys and their handlers are
:mod:`explorer.app.web.panel`'s.

trame is imported inside :func:`build` (``import explorer`` stays free of it).
"""

from __future__ import annotations

from explorer.app import intents as X
from explorer.app import panelmodel, rowlayout
from explorer.app.turntablejob import (
    DEFAULT_FRAMES,
    FRAMES_LABEL,
    MP4_NEEDS,
    format_name,
    turntable_formats,
)
from explorer.app.web import intents as webintents
from explorer.app.web import pictures
from explorer.app.web.panel import items_key
from explorer.core.controls import STEPS
from explorer.core.tolerances import MAX_TURNTABLE_FRAMES
from explorer.core.version import __version__
from explorer.geometry.meshes import MESH_SUFFIXES
from explorer.render.textures import THUMBNAIL_SIZE

#: the drawer's width on a wide page (pixels)
DRAWER_WIDTH = 380
#: the drawer's width (pixels) by the page's width: (narrower than, drawer) in order, else
#: DRAWER_WIDTH; at 640 pixels a 380-pixel drawer left the view 260 pixels
DRAWER_WIDTHS = ((800, 270), (1100, 320))
#: a number row's label column and its field (pixels): every slider of every tab starts and
#: ends at the same x (a label's own width moved its slider: shininess's started 52 pixels
#: right of ka's); the label is 4 pixels narrower than its column (its margin), "shininess" is
#: 69 pixels wide
NUMBER_LABEL_WIDTH, NUMBER_FIELD_WIDTH = 78, 92
#: the same below 800 pixels (the drawer's 270 pixels left the slider 46), the labels in 14
#: pixels ("shininess" 60 pixels wide); a field still shows "0.247", "2.50 r", "40.0°"
NARROW_NUMBER_WIDTHS = (66, 72)
#: the page's own rules for small windows: the toolbar scrolls sideways rather than squeezing
#: its title to a letter; below 1100 pixels the title goes (the tab's title says it) and the
#: toolbar's buttons show their icons instead of their words (:func:`_tool`; the session field
#: its icon alone), so the toolbar fits a 640-pixel page; the toolbar's buttons and the panel's
#: tabs are narrower below 900 (Vuetify's own tab rule is ``.v-tab.v-tab.v-btn``: its 90-pixel
#: tabs overflowed the 270-pixel drawer)
PAGE_CSS = """
html { overflow-y: auto; }
.v-app-bar .v-toolbar__content { overflow-x: auto; overflow-y: hidden; scrollbar-width: thin; }
.v-app-bar .v-toolbar__content > * { flex-shrink: 0; }
.v-app-bar .v-file-input { min-width: 150px; }
.v-app-bar .phong-tool-icon { display: none; }
@media (max-width: 1099px) {
  .v-app-bar .v-toolbar-title, .v-app-bar .phong-tool-text { display: none; }
  .v-app-bar .phong-tool-icon { display: inline-flex; }
  .v-app-bar .v-file-input { min-width: 48px; max-width: 48px !important; }
  .v-app-bar .v-file-input .v-label, .v-app-bar .v-file-input .v-field__input,
  .v-app-bar .v-file-input .v-field__overlay, .v-app-bar .v-file-input .v-field__outline {
    display: none; }
}
@media (max-width: 899px) {
  .v-app-bar .v-btn, .v-tab.v-tab.v-btn { padding: 0 6px; min-width: 0; }
}
"""
#: the number rows' label and field columns (narrower below 800 pixels), and the drawer's room
#: for its scroll bar kept in every tab (a tab that scrolls is no narrower than one that does
#: not): the sliders of every tab line up
NUMBER_CSS = f"""
.v-navigation-drawer__content {{ scrollbar-gutter: stable; }}
.phong-number .v-input__prepend {{ width: {NUMBER_LABEL_WIDTH}px; flex: none;
  margin-inline-end: 8px; }}
.phong-number .v-label {{ display: block; overflow: hidden; text-overflow: ellipsis;
  margin-inline-end: 4px; }}
.phong-number .v-text-field {{ width: {NUMBER_FIELD_WIDTH}px; flex: none; }}
@media (max-width: 799px) {{
  .phong-number .v-input__prepend {{ width: {NARROW_NUMBER_WIDTHS[0]}px; }}
  .phong-number .v-label {{ font-size: 14px; }}
  .phong-number .v-text-field {{ width: {NARROW_NUMBER_WIDTHS[1]}px; }}
}}
"""
#: the page's CSS animations per change, none (issue 42): Vuetify's slider slides its thumb and
#: its track's fill to a new value (0.2 s), a toolbar button fades in as it is enabled (undo
#: after the first change: 0.28 s), and the busy mark is a dot (:func:`_footer`), not
#: trame's spinning circle; each ran a style recalculation and a layout of the whole page every
#: frame while it moved (about 20 a change, 10-70 ms of the browser's CPU beside the picture's
#: decode, on the 2 cores the server's frame needs). The slider's thumb still follows a drag
#: at once (Vuetify turns the slide off while dragging).
QUIET_CSS = """
.v-slider-thumb, .v-slider-track__fill, .v-app-bar .v-btn { transition: none !important; }
.phong-busy { display: inline-block; width: 10px; height: 10px; border-radius: 50%;
  border: 2px solid #9e9e9e; margin-right: 8px; }
.phong-busy.on { background: rgb(var(--v-theme-primary));
  border-color: rgb(var(--v-theme-primary)); }
"""
#: the page's width as a client-only key (``page_w``), on load and on every resize
PAGE_WIDTH_JS = """
(() => {
  const set = () => window.trame.state.set('page_w', window.innerWidth);
  window.addEventListener('resize', () => window.trame && set());
  const first = setInterval(() => { if (window.trame && window.trame.state) {
    clearInterval(first); set(); } }, 20);
})();
"""


def drawer_width_js() -> str:
    """The drawer's width as a Vue expression of ``page_w`` (:data:`DRAWER_WIDTHS`)."""
    expr = str(DRAWER_WIDTH)
    for below, width in reversed(DRAWER_WIDTHS):
        expr = f"page_w < {below} ? {width} : ({expr})"
    return expr


#: the export menu: download kind -> its entry
EXPORTS = {
    "png": "view as PNG",
    "mtl": "material as .mtl",
    "json": "material as three.js JSON",
    "x3d": "material as X3D",
    "preset": "material as preset YAML",
}
#: the colour pickers' hint (their tooltip, and a line under the picker)
PICKER_HINT = ("pick a colour: the picker is 8-bit (#rrggbb, steps of 1/255); the r, g, b "
               "field keeps the exact value")  # fmt: skip
#: the colour swatch beside a colour field (its background is the value's 8-bit colour)
SWATCH_STYLE = ("width: 36px; height: 36px; flex: none; border: 1px solid #757575; "
                "border-radius: 4px;")  # fmt: skip
#: the status line: at most three lines of the last message (the log has it whole)
MESSAGE_STYLE = ("display: -webkit-box; -webkit-line-clamp: 3; -webkit-box-orient: vertical; "
                 "overflow: hidden; white-space: pre-line")  # fmt: skip
#: a click that asks the server for a file and saves it (the browser's download)
DOWNLOAD_JS = ("trigger('download', ['{kind}']).then(f => f && utils.download(f.name, f.content, "
               "f.type))")  # fmt: skip


def history_tip(name: str) -> str:
    """The tooltip of the toolbar's ``undo`` or ``redo`` (:func:`explorer.app.intents.tooltip`,
    the registry's words and keys) as a Vue expression: naming the step (state
    ``<name>_label``) when there is one."""
    key = f"{name}_label"
    head, tail = X.tooltip(name, "\0", page=True).split("\0")
    bare = X.tooltip(name, page=True)
    return f"{key} ? {js_text(head)} + {key} + {js_text(tail)} : {js_text(bare)}"


def js_text(text: str) -> str:
    """``text`` as a JavaScript string in single quotes (a Vue expression sits in an HTML
    attribute's double quotes)."""
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def _number(v3, html, ctrl, key: str, label: str) -> None:
    """A slider (:data:`~explorer.core.controls.STEPS` steps) and a number field for ``key`` in
    one row (its label and its field in columns of fixed width: :data:`NUMBER_CSS`), shown
    when the state has a value for it (``v_show`` on a wrapper: Vuetify's ``d-flex`` is
    ``display: flex !important``, which would override v-show's ``display: none``)."""
    slider = rowlayout.part_name(key, "slider")  # (the window's slider's name too)
    with html.Div(v_show=f"{key} != null"), html.Div(classes="d-flex align-center phong-number"):
        v3.VSlider(
            v_model=(f"{key}_step", 0), min=0, max=STEPS, step=1, label=label, hide_details=True,
            density="compact", end=ctrl.seal, raw_attrs=[f'aria-label="{slider}"'],
            classes="flex-grow-1 mr-2",
        )  # fmt: skip
        v3.VTextField(
            model_value=(f"{key}_text", ""), key=(f"'{key}-' + field_rev",), type="text",
            density="compact", hide_details=True,
            variant="outlined",
            change=(ctrl.on_typed, f"['{key}', $event.target.value]"),
            raw_attrs=[f'aria-label="{key}"'],
        )  # fmt: skip


def _colour(v3, html, ctrl, key: str, label: str) -> None:
    """A colour field ``"r, g, b"`` for state key ``key``, named ``label`` (the scene file's
    key), and beside it a swatch of the value (state ``<key>_hex``) that opens an 8-bit
    colour picker (``<label> picker``); hidden while ``key`` is null (no light to colour)."""
    with html.Div(v_show=f"{key} != null"), html.Div(classes="d-flex align-center my-1"):
        v3.VTextField(
            model_value=(key, ""), key=(f"'{key}-' + field_rev",), label=label,
            density="compact", hide_details=True,
            variant="outlined", classes="flex-grow-1",
            change=(ctrl.on_typed, f"['{key}', $event.target.value]"),
            raw_attrs=[f'aria-label="{label}"'],
        )  # fmt: skip
        with v3.VMenu(close_on_content_click=False, location="end", update_modelValue=ctrl.seal):
            with v3.Template(v_slot_activator="{ props }"):
                html.Button(
                    v_bind="props", v_show=f"{key}_hex", title=PICKER_HINT, classes="ml-2",
                    style=(f"'{SWATCH_STYLE} background: ' + {key}_hex",),
                    raw_attrs=[f'aria-label="{label} picker"'],
                )  # fmt: skip
            with v3.VCard(raw_attrs=[f'aria-label="{label} picker dialog"']):
                v3.VColorPicker(
                    model_value=(f"{key}_hex", "#000000"), modes=("['hex']",), mode="hex",
                    update_modelValue=(ctrl.on_pick, f"['{key}', $event]"),
                    raw_attrs=[f'aria-label="{label} picker colours"'],
                )  # fmt: skip
                html.Div(PICKER_HINT, classes="text-caption pa-2", style="max-width: 300px")


def _shown_as(key: str, tip: str) -> dict:
    """What every row's widget has: compact, named (``aria-label``) by its state key, hidden
    while that key is null (the row is not shown), its tip as a tooltip."""
    return dict(
        density="compact",
        hide_details=True,
        v_show=f"{key} != null",
        title=tip,
        raw_attrs=[f'aria-label="{key}"'],
    )


def _choice(v3, r) -> None:
    """A select of a choice's values, or of a list's items (state ``<key>_items`` or the
    catalogue's key, with their subtitles and swatches): searched by words when the row says
    so. A list is always shown (its value is null when nothing is selected)."""
    listed = r.kind == "list" or not r.choices
    shown = _shown_as(r.key, r.tip)
    if r.kind == "list":
        del shown["v_show"]
    # a searched list finds its items by their subtitles too (Vuetify filters its own items:
    # the page's item is their ``raw``), as the window's search does ("stone" finds jade and
    # turquoise by their descriptions)
    searched = {"filter_keys": ("['title', 'raw.subtitle']",)} if r.search else {}
    (v3.VAutocomplete if r.search else v3.VSelect)(
        v_model=(r.key, None),
        items=(items_key(r) if listed else repr(list(r.choices)),),
        item_props=listed,
        label=r.caption,
        **searched,
        **shown,
    )


def _checkbox(v3, key: str, label: str, tip: str) -> None:
    """A toggle row's box, or an optional number's ``<key>_on`` switch."""
    v3.VCheckbox(v_model=(key, False), label=label, **_shown_as(key, tip))


def _text(html, r) -> None:
    """A text row: the line its state key holds, hidden while it is null."""
    html.Div(f"{{{{ {r.key} }}}}", v_show=f"{r.key} != null", classes="text-body-2 mb-1",
             title=r.tip, raw_attrs=[f'aria-label="{r.key}"'])  # fmt: skip


def _button(v3, ctrl, r) -> None:
    """A button row: pressed through the server's ``press`` handler, disabled while its state
    key (whether it can be pressed) is false, hidden while it is null."""
    v3.VBtn(r.caption, click=(ctrl.press, f"['{r.key}']"), size="small", classes="mr-1 my-1",
            disabled=(f"!{r.key}",), v_show=f"{r.key} != null", title=r.tip,
            raw_attrs=[f'aria-label="{r.key}"'])  # fmt: skip


def _triple(v3, ctrl, r) -> None:
    v3.VTextField(
        model_value=(r.key, ""), key=(f"'{r.key}-' + field_rev",), variant="outlined",
        label=f"{r.key} ({', '.join(r.choices)})",
        change=(ctrl.on_typed, f"['{r.key}', $event.target.value]"), **_shown_as(r.key, r.tip),
    )  # fmt: skip


def _part(r, part: str) -> dict:
    """An image row's ``part``: its name and its tooltip
    (:func:`explorer.app.rowlayout.image_part`)."""
    name, tip = rowlayout.image_part(r, part)
    return {"title": tip, "raw_attrs": [f'aria-label="{name}"']}


def _image(v3, html, ctrl, r) -> None:
    """A texture map: its key, its thumbnail (``<key>_thumbnail``), its file's name, its switch
    ``<key>_on``, its upload ``<key>_upload`` (an image where the page's other uploads go) and
    its clear; hidden while the row is not shown."""
    with html.Div(
        v_show=f"{r.key} != null", classes="my-1", title=r.tip, raw_attrs=[f'aria-label="{r.key}"']
    ):
        html.Div(r.caption, classes="text-body-2")
        with html.Div(classes="d-flex align-center"):
            html.Img(
                src=(f"{r.key}_thumbnail",),
                v_show=f"{r.key}_thumbnail",
                width=THUMBNAIL_SIZE,
                height=THUMBNAIL_SIZE,
                style="object-fit: contain; image-rendering: pixelated",
                classes="mr-2",
                raw_attrs=[f'aria-label="{r.key}_thumbnail"'],
            )
            html.Span(f"{{{{ {r.key} }}}}", classes="text-body-2", **_part(r, "file"))
        with html.Div(classes="d-flex align-center"):
            v3.VCheckbox(
                v_model=(f"{r.key}_on", False),
                label="on",
                density="compact",
                hide_details=True,
                disabled=(f"!{r.key}_thumbnail",),
                **_part(r, "on"),
            )
            v3.VFileInput(
                v_model=(f"{r.key}_upload", None),
                label="upload",
                accept=".png,.jpg,.jpeg",
                density="compact",
                hide_details=True,
                classes="mx-1",
                **_part(r, "choose"),
            )
            v3.VBtn(
                "clear",
                click=(ctrl.clear_map, f"['{r.key}']"),
                size="small",
                disabled=(f"!{r.key}_thumbnail",),
                **_part(r, "clear"),
            )


def _rows(v3, html, ctrl, tab: str, after=None) -> None:
    """The rows of ``tab`` (:mod:`explorer.app.panelmodel`), one factory per kind; a group of
    toggles on one line. Each is named (``aria-label``) by its key and hidden while its state
    key is null (the row is not shown). ``after``: key -> a function that draws the page's own
    controls after that row (the difference view's legend).

    Each row (a line of toggles) is the slot of its own renderless component
    (``VDefaultsProvider``), and so is what ``after`` draws: Vue tracks the state keys a slot
    reads in the component that renders it, so a change of a row's keys re-renders that row
    alone; in the tab's one slot, a kd change (``kd_text``) re-rendered every row of the tab
    (issue 42, benchmarks/trace_web_change.py)."""
    after = after or {}
    for how, group in rowlayout.lines(panelmodel.rows(tab)):
        if how == "line":  # toggles side by side: one component, one flex line
            with v3.VDefaultsProvider(), html.Div(classes="d-flex"):
                for r in group:
                    _row(v3, html, ctrl, r)
        for r in group:
            if how != "line":
                with v3.VDefaultsProvider():
                    _row(v3, html, ctrl, r)
            if r.key in after:  # (after a line's toggle: under the line)
                with v3.VDefaultsProvider():
                    after[r.key]()


def _row(v3, html, ctrl, r) -> None:
    """Row ``r``'s widgets, by its kind."""
    if r.kind == "number":
        if r.optional is not None:
            _checkbox(v3, f"{r.key}_on", r.caption, r.tip)
        _number(v3, html, ctrl, r.key, r.caption)
    elif r.kind == "colour":
        _colour(v3, html, ctrl, r.key, r.key)
    elif r.kind in ("choice", "list"):
        _choice(v3, r)
    elif r.kind == "toggle":
        _checkbox(v3, r.key, r.caption, r.tip)
    elif r.kind == "button":
        _button(v3, ctrl, r)
    elif r.kind == "text":
        _text(html, r)
    elif r.kind == "image":
        _image(v3, html, ctrl, r)
    else:
        _triple(v3, ctrl, r)


def _material_tab(v3, html, ctrl) -> None:
    """The mesh's own materials, the preset, the numbers, the colours, the model and the
    terms."""
    _rows(v3, html, ctrl, "material")


def _lights_tab(v3, html, ctrl) -> None:
    """The light list, add / duplicate / remove, and the selected light."""
    _rows(v3, html, ctrl, "lights")


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
    v3.VBtn("reset camera", click=ctrl.reset_camera, size="small", classes="my-2",
            title=X.tooltip("reset_camera", page=True),
            raw_attrs=['aria-label="reset camera"'])  # fmt: skip

    def legend():
        html.Div("{{ legend }}", classes="text-caption", v_show="difference")
        html.Div(
            "{{ advice }}",
            classes="text-caption mt-1",  # (apart from the legend's figures, as in the window)
            v_show="difference && advice",
            style="white-space: pre-line",
            raw_attrs=['aria-label="advice"'],
        )

    _rows(v3, html, ctrl, "view", {"difference": legend})
    _turntable(v3, html, ctrl)


def _turntable(v3, html, ctrl) -> None:
    """A turntable (its frames in a full turn and its format chosen first) made on the server
    under a progress bar (Cancel), then downloaded."""
    with html.Div(classes="d-flex align-center mt-2"):
        v3.VTextField(
            v_model=("turntable_frames", DEFAULT_FRAMES), label=FRAMES_LABEL,
            type="number", min=2, max=MAX_TURNTABLE_FRAMES, density="compact",
            hide_details=True, variant="outlined", classes="mr-2",
            raw_attrs=['aria-label="turntable frames"'],
        )  # fmt: skip
        v3.VSelect(v_model=("turntable_format", ".gif"), items=("turntable_formats",),
                   label="format", density="compact", hide_details=True,
                   raw_attrs=['aria-label="turntable format"'])  # fmt: skip
    html.Div(MP4_NEEDS, classes="text-caption",
             v_show="turntable_formats.length < 2")  # fmt: skip
    v3.VBtn("make a turntable", click=ctrl.turntable, size="small", classes="my-1",
            disabled=("progress && progress.running",),
            title=X.tooltip("export_turntable", page=True),
            raw_attrs=['aria-label="turntable"'])  # fmt: skip
    with html.Div(v_show="progress && progress.running", classes="my-1"):
        html.Div("{{ progress && progress.text }}", classes="text-caption")
        v3.VProgressLinear(model_value=("progress ? 100 * progress.done / progress.total : 0",),
                           height=6, raw_attrs=['aria-label="progress"'])  # fmt: skip
        v3.VBtn("cancel", click=ctrl.cancel_job, size="small", variant="text",
                raw_attrs=['aria-label="cancel"'])  # fmt: skip
    v3.VBtn("download the turntable ({{ turntable_made }})", v_show="turntable_ready",
            size="small",
            click=DOWNLOAD_JS.format(kind="turntable"),
            raw_attrs=['aria-label="download turntable"'])  # fmt: skip


def _footer(layout, v3, html) -> None:
    """The page's foot: a busy mark (a dot, filled while the server works on the page's last
    request: trame's spinning circle cost a style recalculation every frame of each change,
    :data:`QUIET_CSS`) and the explorer's name and version (trame's own foot advertises trame
    and Kitware and lists the server's package versions)."""

    layout.footer.clear()
    with layout.footer:
        html.Span(
            classes=("trame__busy ? 'phong-busy on' : 'phong-busy'",),
            title=("trame__busy ? 'busy' : 'ready'",),
            raw_attrs=['aria-label="busy"'],
        )
        html.Span(f"phong-explorer {__version__}", classes="text-caption text-grey")


#: the toolbar's icons (Material Design Icons, served with the page) shown instead of the
#: buttons' words in a page narrower than 1100 pixels (PAGE_CSS)
TOOL_ICONS = {
    "undo": "mdi-undo",
    "redo": "mdi-redo",
    "save session": "mdi-content-save-outline",
    "open session": "mdi-folder-open-outline",
    "export": "mdi-export-variant",
    "messages": "mdi-message-text-outline",
}


def _tool(v3, html, name: str, **kw) -> None:
    """A toolbar button named ``name`` (its word and accessible name): its word, or its icon
    (:data:`TOOL_ICONS`) in a narrow page, the word then in its tooltip and accessible name;
    ``kw``: the button's own (click, title, v_bind, disabled)."""
    with v3.VBtn(variant="text", raw_attrs=[f'aria-label="{name}"'], **kw):
        v3.VIcon(TOOL_ICONS[name], classes="phong-tool-icon")
        html.Span(name, classes="phong-tool-text")


def _files(v3, html, ctrl) -> None:
    """The toolbar's files: save and open a session, export the view and the material."""
    _tool(v3, html, "save session", title=X.tooltip("save_session", page=True),
          click=DOWNLOAD_JS.format(kind="session"))  # fmt: skip
    v3.VFileInput(
        v_model=("session_upload", None), label="open session", accept=".yaml,.yml,.json",
        density="compact", hide_details=True, style="max-width: 200px", prepend_icon="",
        prepend_inner_icon=TOOL_ICONS["open session"],
        title=X.tooltip("open", page=True), raw_attrs=['aria-label="open session"'],
    )  # fmt: skip
    with v3.VMenu():
        with v3.Template(v_slot_activator="{ props }"):
            _tool(v3, html, "export", v_bind="props", title=X.tooltip("export_material", page=True))
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
                title=X.tooltip("save_preset", page=True),
                raw_attrs=['aria-label="save preset"'])  # fmt: skip
    v3.VFileInput(
        v_model=("mtl_upload", None), label=X.BY_ID["import_materials"].what, accept=".mtl",
        density="compact", hide_details=True, classes="my-2",
        raw_attrs=['aria-label="import materials"'],
    )  # fmt: skip


def _message_log(v3, html) -> None:
    """The toolbar's "messages" button and the message log it opens: every message of the
    session (state ``message_log``: time, level, text and details), oldest first."""
    _tool(v3, html, "messages", click="show_messages = true",
          title=X.tooltip("messages", page=True))  # fmt: skip
    with v3.VDialog(v_model=("show_messages", False), max_width=720, scrollable=True):
        with v3.VCard(raw_attrs=['aria-label="message log"', 'role="log"']):
            v3.VCardTitle("messages")
            with v3.VCardText(style="max-height: 60vh"):
                html.Div("no messages yet", v_show="!message_log.length",
                         classes="text-caption")  # fmt: skip
                with html.Div(v_for="(m, i) in message_log", key="i", classes="mb-1",
                              raw_attrs=['aria-label="message"']):  # fmt: skip
                    html.Div("{{ m.head }}",
                             classes=("m.level === 'error' ? 'text-error' : m.level === "
                                      "'warning' ? 'text-warning' : ''",),
                             style="white-space: pre-wrap")  # fmt: skip
                    html.Div("{{ d }}", v_for="(d, j) in m.details", key="j",
                             classes="text-caption ml-4",
                             style="white-space: pre-wrap")  # fmt: skip
            with v3.VCardActions():
                v3.VSpacer()
                v3.VBtn("close", click="show_messages = false",
                        raw_attrs=['aria-label="close messages"'])  # fmt: skip


def _page_state(state) -> None:
    """The page's own keys, their first values, and which of them each page keeps to itself
    (trame's client-only keys: never sent to the server, so never to another page)."""
    state.update(
        message="", message_level="info", message_seq=0, seen_seq=0, page_w=1280, field_rev=0,
        message_log=[], legend="", advice="", tab="material", preset_name="", preset_replace=False,
        session_upload=None, mesh_upload=None, mtl_upload=None, progress=None,
        **{f"{r.key}_upload": None for r in panelmodel.ROWS if r.kind == "image"},
        turntable_ready=False, turntable_made="",
        turntable_formats=[{"title": format_name(s), "value": s} for s in turntable_formats()],
        compare=False,
        can_undo=False, can_redo=False, undo_label="", redo_label="",
    )  # fmt: skip
    state.client_only("show_messages")  # the log opens in the tab that asks, alone
    # the panel's tab, the drawer and the page's width are each page's own: another page's
    # choice moves none of them
    state.client_only("tab", "main_drawer", "page_w")
    # a page shows the messages said after it opened, not the last one said to another page
    # (``seen_seq``: the message count when this page mounted, kept in the page)
    state.client_only("seen_seq")


def remote_view(vtkw, window, name: str):
    """A view of the server's ``window`` (pane A's or pane B's) named ``name``: trame's remote
    view, whose pictures :mod:`explorer.app.web.pictures` makes for both panes alike (a JPEG
    with full chroma at once, the still frame as PNG); the quality it asks for is not used."""
    return vtkw.VtkRemoteView(
        window,
        interactive_ratio=1,
        still_quality=100,
        interactive_quality=100,
        raw_attrs=[f'aria-label="{name}"'],
    )


def build(app) -> None:
    """The page: the toolbar (the registry's menus, undo / redo, files), the drawer (the
    panel) and the view; the registry's keys (:mod:`explorer.app.web.intents`)."""
    from trame.ui.vuetify3 import SinglePageWithDrawerLayout
    from trame.widgets import client, html
    from trame.widgets import vtk as vtkw
    from trame.widgets import vuetify3 as v3

    server = app.server
    ctrl = server.controller
    _page_state(server.state)
    webintents.connect(app)
    with SinglePageWithDrawerLayout(server, full_height=True) as layout:
        layout.title.set_text("phong-explorer")
        _footer(layout, v3, html)
        layout.drawer.width = (drawer_width_js(),)
        client.Script(webintents.keys_js())  # the registry's keys (the desktop's)
        client.ClientTriggers(mounted="seen_seq = message_seq")
        # Vuetify reserves a page scrollbar (html: overflow-y scroll); the page fits its window
        client.Style(PAGE_CSS + NUMBER_CSS + QUIET_CSS)
        client.Script(PAGE_WIDTH_JS)
        with layout.toolbar:
            webintents.menus(v3)
            v3.VSpacer()
            for name in ("undo", "redo"):
                _tool(v3, html, name, click=getattr(ctrl, name), disabled=(f"!can_{name}",),
                      title=(history_tip(name),))  # fmt: skip
            _files(v3, html, ctrl)
            _message_log(v3, html)
            webintents.help_dialog(v3, html)
        with layout.drawer:
            with v3.VTabs(v_model="tab", density="compact", grow=True):
                for t in ("material", "lights", "view"):
                    v3.VTab(t, value=t, raw_attrs=[f'aria-label="{t} tab"'])
            # no sliding between the tabs: a control is where it is drawn (a click during the
            # slide could land beside it)
            with v3.VWindow(v_model="tab", transition=("false",), reverse_transition=("false",)):
                with v3.VWindowItem(value="material", classes="pa-2"):
                    _material_tab(v3, html, ctrl)
                    _save_preset(v3, html, ctrl)
                with v3.VWindowItem(value="lights", classes="pa-2"):
                    _lights_tab(v3, html, ctrl)
                with v3.VWindowItem(value="view", classes="pa-2"):
                    _view_tab(v3, html, ctrl)
            # the engine and the last message stay at the drawer's foot (the panel above
            # scrolls when it is taller than the window)
            with v3.Template(v_slot_append=True):
                html.Div("{{ engine }}", v_show="engine", classes="text-caption px-2",
                         raw_attrs=['aria-label="engine"'])  # fmt: skip
                html.Div("{{ message }}", classes=("'text-caption px-2 pb-1 ' + (message_level "
                         "=== 'error' ? 'text-error' : '')",), style=MESSAGE_STYLE,
                         v_show="message_seq > seen_seq",
                         raw_attrs=['role="status"'])  # fmt: skip
        with layout.content, v3.VContainer(fluid=True, classes="pa-0 fill-height"):
            with html.Div(classes="d-flex", style="width: 100%; height: 100%"):
                client.Script(pictures.PAGE_JS)  # (before the views: their streams)
                with html.Div(style="flex: 1 1 0; height: 100%; position: relative"):
                    view = remote_view(vtkw, app.plotter.render_window, "view")
                with html.Div(v_if="compare", style="flex: 1 1 0; height: 100%; "
                              "position: relative; margin-left: 4px"):  # fmt: skip
                    view_b = remote_view(vtkw, app.compare.plotter.render_window, "view_b")
            ctrl.view_update = view.update
            ctrl.view_b_update = view_b.update
    app.layout = layout
