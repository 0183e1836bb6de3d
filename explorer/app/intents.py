"""Every intent of the explorer declared once: its id, title, menu, keys, enablement and what
it runs. The Qt window's menus, its shortcuts, the 3D view's keys and the help
(:mod:`explorer.app.qt.menus`), and the page's menus, keyboard shortcuts and help
(:mod:`explorer.app.web.intents`) are all built from :data:`INTENTS`.

The shape is that of napari's app-model ``Action`` (id, title, menus, key bindings,
enablement, callback), in a few lines of our own and without its context expressions: an
intent's callback is a controller method named by :attr:`Intent.run`, or (``front:NAME``) one
the front end provides (quit, the help, the message log), and its enablement a predicate of the
controller.

The browser keeps some keys for itself: a page never sees Ctrl+N, Ctrl+Shift+N, Ctrl+T,
Ctrl+Shift+T, Ctrl+W, Ctrl+Shift+W, Ctrl+Tab, Ctrl+Shift+Tab, Ctrl+PgUp / PgDn, Ctrl+F4,
Ctrl+Shift+Q (Chromium's reserved commands, ``IsReservedCommandOrKey``: new window, new tab,
close, tab switching, quit). An intent bound to one of them says its page key in
:attr:`Intent.page_keys` (Ctrl+T, the turntable, is Alt+T on the page); the other desktop keys
work on the page as they are (the page's listener takes them before the browser).

Toolkit-free: imports the core and the model's actions (an import-linter contract keeps Qt and
trame out).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from explorer.app.effectactions import gouraud_vs_per_pixel
from explorer.core.errors import ExplorerError
from explorer.core.material import MODELS

#: the keys a page never receives (the browser's own, see the module's docstring), as
#: :func:`key_name` writes them
BROWSER_KEYS = frozenset(
    {
        "ctrl+n",
        "ctrl+shift+n",
        "ctrl+t",
        "ctrl+shift+t",
        "ctrl+w",
        "ctrl+shift+w",
        "ctrl+tab",
        "ctrl+shift+tab",
        "ctrl+pgup",
        "ctrl+pgdown",
        "ctrl+f4",
        "ctrl+shift+q",
    }
)
#: the menus, in the menu bar's order
MENUS = ("File", "Edit", "View", "Help")
#: a front end's own callbacks (``run="front:NAME"``): what each must provide
FRONT = ("quit", "help", "messages")
#: the model actions an intent applies itself (``act:NAME``): what needs no flow of its own
ACTIONS = {"gouraud_vs_per_pixel": gouraud_vs_per_pixel}


@dataclasses.dataclass(frozen=True)
class Intent:
    """One thing a person can ask the explorer to do.

    id : its name (the Qt action's object name, the page's ``intent <id>`` label, the page's
        trigger); title : the menu entry (``&`` before the desktop's mnemonic letter; the page
        shows it without); menu, group : the menu it sits in (None: keys only) and its group
        there (groups are separated, in order); keys : the window's shortcuts (Qt's key
        sequences, the first one shown); view_key : the 3D view's key (a plain character, while
        the view has the keyboard); help : what the help says of it (default: the title);
        run : the controller method it calls (``files.NAME``: of its file flows,
        :class:`~explorer.app.controller.files.FileFlows`), ``front:NAME`` (:data:`FRONT`), or
        ``act:NAME``: the model action :data:`ACTIONS` names, one undo step named by the title;
        enabled : ``enabled(controller)``, whether it can run now (None: always);
        page : how the page runs it (``server``: the controller's method through a trigger;
        ``download:KIND``, ``click:LABEL[@TAB]``, ``focus:LABEL[@TAB]``, ``toggle:STATE``: in
        the browser; None: not on the page); page_keys : the page's keys where the browser
        keeps the desktop's (None: the desktop's keys and view key); page_help : what the
        page's help says of it where the page does it otherwise (default: :attr:`what`)
    """

    id: str
    title: str
    run: str
    menu: str | None = None
    group: int = 0
    keys: tuple[str, ...] = ()
    view_key: str | None = None
    help: str = ""
    enabled: Callable[[object], bool] | None = None
    page: str | None = "server"
    page_keys: tuple[str, ...] | None = None
    page_help: str = ""

    @property
    def label(self) -> str:
        """The title without the mnemonic's ``&`` (the page's, the help's)."""
        return self.title.replace("&", "")

    @property
    def what(self) -> str:
        """What the help says the intent does."""
        return self.help or self.label[:1].lower() + self.label[1:]

    @property
    def page_what(self) -> str:
        """What the page's help says the intent does."""
        return self.page_help or self.what

    def all_keys(self) -> tuple[str, ...]:
        """The desktop's keys: the view key (if any) after the window's shortcuts."""
        return self.keys + ((self.view_key,) if self.view_key else ())

    def web_keys(self) -> tuple[str, ...]:
        """The keys that run it on the page (none when the page does not have it)."""
        if self.page is None:
            return ()
        keys = self.all_keys() if self.page_keys is None else self.page_keys
        return tuple(k for k in keys if key_name(k) not in BROWSER_KEYS)

    def keys_text(self, *, page: bool = False) -> str:
        """Its keys as the menus, the help and the tooltips write them (``Ctrl+Shift+Z / Ctrl+Y``):
        the window's shortcuts, or (``page``) the page's keys; "" when it has none."""
        return " / ".join(self.web_keys() if page else self.keys)

    def can_run(self, controller) -> bool:
        return self.enabled is None or bool(self.enabled(controller))


def _undo(c) -> bool:
    return c.store.can_undo


def _redo(c) -> bool:
    return c.store.can_redo


I = Intent  # short: the table below reads as a table
#: every intent, in the menus' order
INTENTS: tuple[Intent, ...] = (
    I(
        "open",
        "&Open mesh, scene or session…",
        "files.open_file",
        "File",
        0,
        ("Ctrl+O",),
        help="open a mesh, scene or session",
        page="click:open session",
        page_help="open a session (a mesh: the view tab's upload)",
    ),
    I(
        "import_materials",
        "&Import materials (.mtl)…",
        "files.import_materials",
        "File",
        1,
        ("Ctrl+I",),
        help="import materials (.mtl) as presets",
        page="click:import materials@material",
    ),
    I(
        "export_material",
        "&Export material…",
        "files.export_material",
        "File",
        1,
        ("Ctrl+E",),
        help="export the material",
        page="click:export",
        page_help="the export menu (downloads)",
    ),
    I(
        "export_render",
        "Export &view as PNG…",
        "files.export_render",
        "File",
        1,
        ("Ctrl+Shift+E",),
        help="export the view (PNG)",
        page="download:png",
        page_help="download the view (PNG)",
    ),
    I(
        "export_turntable",
        "Export &turntable (GIF, MP4)…",
        "files.export_turntable",
        "File",
        1,
        ("Ctrl+T",),
        help="export a turntable (GIF, MP4)",
        page="click:turntable@view",
        page_keys=("Alt+T",),
        page_help="make a turntable (the view tab)",
    ),
    I(
        "save_session",
        "&Save session…",
        "files.save_session_as",
        "File",
        2,
        ("Ctrl+S",),
        help="save the session",
        page="download:session",
        page_help="download the session",
    ),
    I(
        "save_preset",
        "Save &preset as…",
        "files.save_preset_as",
        "File",
        2,
        ("Ctrl+Shift+S",),
        help="save the material as a preset",
        page="focus:preset name@material",
        page_help="save the material as a preset (its name field)",
    ),
    I(
        "screenshot",
        "Save screens&hot",
        "files.screenshot",
        "File",
        2,
        view_key="i",
        help="save a screenshot of the view (never over a file)",
        page="download:png",
        page_help="download the view (PNG)",
    ),
    I(
        "quit",
        "&Quit",
        "front:quit",
        "File",
        3,
        ("Ctrl+Q",),
        view_key="q",
        help="quit (the session is kept for 'gui --last')",
        page=None,
    ),
    I("undo", "&Undo", "undo", "Edit", 0, ("Ctrl+Z",), enabled=_undo),
    I("redo", "&Redo", "redo", "Edit", 0, ("Ctrl+Shift+Z", "Ctrl+Y"), enabled=_redo),
    I("reset_all", "Reset &all (undoable)", "reset_all", "Edit", 1),
    I(
        "reset_camera",
        "Reset &camera",
        "reset_camera",
        "View",
        0,
        view_key="r",
        help="reset the camera (the material and lights stay)",
    ),
    I(
        "toggle_difference",
        "&Difference view",
        "toggle_difference",
        "View",
        0,
        view_key="d",
        help="show / hide the per-pixel difference",
    ),
    I(
        "toggle_compare",
        "&Compare A | B",
        "toggle_compare",
        "View",
        0,
        view_key="c",
        help="compare A | B on / off (two panes, linked cameras)",
    ),
    I("swap_sides", "&Swap A and B", "swap_sides", "View", 0, view_key="x"),
    I(
        "gouraud_vs_per_pixel",
        "&Gouraud vs per-pixel",
        "act:gouraud_vs_per_pixel",
        "View",
        0,
        view_key="g",
        help="compare A | B with A lit per vertex (Gouraud) and B per pixel: each one's time "
        "and the error, live",
    ),
    I(
        "messages",
        "&Messages",
        "front:messages",
        "View",
        1,
        ("Ctrl+M",),
        help="the message log",
        page="toggle:show_messages",
    ),
    I(
        "help",
        "&Keys and mouse",
        "front:help",
        "Help",
        0,
        ("F1",),
        view_key="h",
        help="show / hide this help",
        page="toggle:show_help",
    ),
    I(
        "toggle_model",
        "Next specular model",
        "toggle_model",
        view_key="b",
        help=f"next specular model ({' / '.join(MODELS)})",
    ),
    I(
        "toggle_ambient",
        "Ambient term on / off",
        "toggle_ambient",
        view_key="1",
        help="show / hide the ambient term",
    ),
    I(
        "toggle_diffuse",
        "Diffuse term on / off",
        "toggle_diffuse",
        view_key="2",
        help="show / hide the diffuse term",
    ),
    I(
        "toggle_specular",
        "Specular term on / off",
        "toggle_specular",
        view_key="3",
        help="show / hide the specular term",
    ),
    I("next_preset", "Next preset", "next_preset", view_key="n"),
    I("previous_preset", "Previous preset", "previous_preset", view_key="p"),
    I(
        "next_light_type",
        "Next light type",
        "next_light_type",
        view_key="t",
        help="next light type (directional / point / spot)",
    ),
    I("next_light", "Next light", "next_light", view_key="l", help="control the next light"),
)
del I
#: the intents by id
BY_ID = {i.id: i for i in INTENTS}
#: mouse controls of the view, for the help
MOUSE = (
    ("drag the yellow sphere", "move the light (the lights tab follows)"),
    ("left drag", "rotate the camera; the camera is the viewer, so highlights move"),
    ("right drag / wheel", "zoom"),
    ("middle drag / shift + left drag", "pan"),
)


def key_name(key: str) -> str:
    """A key as the page's listener names a key press: the modifiers (``ctrl``, ``alt``,
    ``shift``, in that order) and the key, lower case, joined by ``+`` (``Ctrl+Shift+Z`` ->
    ``ctrl+shift+z``; ``F1`` -> ``f1``; ``r`` -> ``r``)."""
    *mods, last = key.split("+") if key != "+" else [key]
    order = [m for m in ("ctrl", "alt", "shift") if m in {x.lower() for x in mods}]
    return "+".join([*order, last.lower()])


def menu(name: str) -> list[list[Intent]]:
    """The intents of menu ``name``, in groups (each a list, in order)."""
    groups: dict[int, list[Intent]] = {}
    for i in INTENTS:
        if i.menu == name:
            groups.setdefault(i.group, []).append(i)
    return [groups[g] for g in sorted(groups)]


def enabled(controller) -> dict[str, bool]:
    """Whether each intent can run now (id -> bool)."""
    return {i.id: i.can_run(controller) for i in INTENTS}


def run(intent_id: str, controller, front: dict[str, Callable[[], object]]):
    """Run intent ``intent_id``: its controller method, ``front[NAME]`` for ``front:NAME``, its
    model action through :meth:`Controller.act` for ``act:NAME``;
    an intent that cannot run now (:attr:`Intent.enabled`) does nothing and returns False."""
    intent = BY_ID.get(intent_id)
    if intent is None:
        raise ExplorerError(f"no intent named '{intent_id}'")
    if not intent.can_run(controller):
        return False
    if intent.run.startswith("front:"):
        return front[intent.run.removeprefix("front:")]()
    if intent.run.startswith("act:"):
        return controller.act(ACTIONS[intent.run.removeprefix("act:")], label=intent.label)
    target = controller
    for name in intent.run.split("."):  # files.NAME: a method of the controller's file flows
        target = getattr(target, name)
    return target()


def tooltip(intent_id: str, what: str = "", *, page: bool = False) -> str:
    """The tooltip of a button that runs intent ``intent_id`` (a toolbar's, the material tab's
    Save): its title (with ``page``: what the page's help says it does there), ``what`` it
    would do now when given (the step an undo undoes), and its keys in brackets (the page's
    keys with ``page``; the desktop's: its shortcuts, then its 3D view key):
    ``Save preset as… (Ctrl+Shift+S)``; on the page ``undo kd (Ctrl+Z)``, ``download the
    session (Ctrl+S)``."""
    intent = BY_ID[intent_id]
    keys = intent.keys_text(page=True) if page else " / ".join(intent.all_keys())
    title = intent.page_what if page else intent.label
    text = f"{title} {what}" if what else title
    return f"{text} ({keys})" if keys else text


def history_title(intent_id: str, what: str | None) -> str:
    """Undo's or redo's title naming the step it undoes or redoes (``what``; None: its title
    alone): the desktop's menu entry (``&Undo kd``)."""
    title = BY_ID[intent_id].title
    return f"{title} {what}" if what else title


def help_lines(*, page: bool = False) -> list[str]:
    """Every key and mouse control, one per line: the desktop's (the 3D view's keys, the
    window's shortcuts), or the page's (``page``: the keys the page has)."""
    if page:
        lines = ["Keys (not while typing in a field):"]
        lines += [f"  {i.keys_text(page=True)}   {i.page_what}" for i in INTENTS if i.web_keys()]
    else:
        lines = ["Keys in the 3D view (VTK's own keys are switched off):"]
        lines += [f"  {i.view_key}   {i.what}" for i in INTENTS if i.view_key]
        lines += ["", "Window shortcuts:"]
        lines += [f"  {i.keys_text()}   {i.what}" for i in INTENTS if i.keys]
    lines += ["", "Mouse in the 3D view:"]
    lines += [f"  {how}: {what}" for how, what in MOUSE]
    return lines
