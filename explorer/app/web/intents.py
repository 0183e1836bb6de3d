"""The page's menus, keyboard shortcuts and help, built from the intent registry
(:data:`explorer.app.intents.INTENTS`) as the Qt window's are.

The app bar has the desktop's menus (File, Edit, View, Help) with the intents the page has
(each entry named ``intent <id>``, titled as on the desktop); a document-level ``keydown``
listener runs the same intents from the same keys (:meth:`~explorer.app.intents.Intent.web_keys`:
the desktop's, but where the browser keeps a key for itself), except while a text field has the
keyboard (there the keys edit the text). An intent runs on the server (the trigger ``intent``,
which runs only the intents the page runs there) or in the browser (a download, a click on a
file field, the message log, the help).

trame is imported by the caller (:func:`explorer.app.web.page.build`); this module needs none.
"""

from __future__ import annotations

import json

from explorer.app import intents as X
from explorer.core.errors import ExplorerError

#: the listener and ``window.phongIntent(id)``, which the menus call too; ``%(INTENTS)s``: id ->
#: {run: Intent.page, keys: the page's keys as key_name writes them}
KEYS_JS = """
(() => {
  const INTENTS = %(INTENTS)s;
  const BY_KEY = {};
  for (const [id, it] of Object.entries(INTENTS)) for (const k of it.keys) BY_KEY[k] = id;
  // inputs that take no typed text: a key pressed there is a shortcut
  const NOT_TEXT = new Set(['checkbox', 'radio', 'button', 'submit', 'reset', 'range',
                            'color', 'file', 'image']);
  const typing = (t) => !!t && (t.isContentEditable || t.tagName === 'TEXTAREA'
    || t.tagName === 'SELECT'
    || (t.tagName === 'INPUT' && !NOT_TEXT.has((t.type || 'text').toLowerCase())));
  const keyName = (e) => {
    const parts = [];
    if (e.ctrlKey || e.metaKey) parts.push('ctrl');  // Cmd on a Mac
    if (e.altKey) parts.push('alt');
    if (e.shiftKey) parts.push('shift');
    let k = (e.key || '').toLowerCase();
    // with Alt, e.key may be another character (Option+T is a dagger on a Mac): the key's code
    if (e.altKey && e.code && e.code.startsWith('Key')) k = e.code.slice(3).toLowerCase();
    parts.push(k);
    return parts.join('+');
  };
  const shown = (label, tab, then) => {  // the control named label, once its tab shows it
    if (tab) window.trame.state.set('tab', tab);
    let tries = 0;
    const look = () => {
      let el = document.querySelector(`[aria-label="${label}"]`);
      if (el && !['INPUT', 'BUTTON'].includes(el.tagName)) el = el.querySelector('input') || el;
      if (el && el.getClientRects().length) then(el);  // laid out: its tab is shown
      else if (tries++ < 50) setTimeout(look, 20);
    };
    look();
  };
  window.phongIntent = (id) => {
    const it = INTENTS[id];
    if (!it) return;
    const at = it.run.indexOf(':');
    const how = at < 0 ? it.run : it.run.slice(0, at), arg = it.run.slice(at + 1);
    const [label, tab] = arg.split('@');
    if (how === 'server') window.trame.trigger('intent', [id]);
    else if (how === 'download') window.trame.trigger('download', [arg]).then(
      f => f && window.trame.utils.download(f.name, f.content, f.type));
    else if (how === 'click') shown(label, tab, el => el.click());
    else if (how === 'focus') shown(label, tab, el => el.focus());
    else if (how === 'toggle') window.trame.state.set(arg, !window.trame.state.get(arg));
  };
  document.addEventListener('keydown', (e) => {
    if (e.defaultPrevented || typing(e.target)) return;
    const id = BY_KEY[keyName(e)];
    if (!id) return;
    e.preventDefault();
    const on = window.trame.state.get('intents_enabled');
    if (!on || on[id] !== false) window.phongIntent(id);
  });
})();
"""


def page_intents() -> dict[str, dict]:
    """The intents the page has: id -> {run: how the page runs it, keys: its keys there}."""
    return {
        i.id: {"run": i.page, "keys": [X.key_name(k) for k in i.web_keys()]}
        for i in X.INTENTS
        if i.page
    }


def keys_js() -> str:
    """The page's script: the key listener and ``window.phongIntent``."""
    return KEYS_JS % {"INTENTS": json.dumps(page_intents())}


def menus(v3) -> None:
    """The app bar's menus: each the desktop's, with the intents the page has."""
    for name in X.MENUS:
        groups = [[i for i in g if i.page] for g in X.menu(name)]
        groups = [g for g in groups if g]
        if not groups:
            continue
        with v3.VMenu():
            with v3.Template(v_slot_activator="{ props }"):
                v3.VBtn(
                    name,
                    v_bind="props",
                    variant="text",
                    classes="px-2",
                    style="min-width: 0",
                    raw_attrs=[f'aria-label="menu {name}"'],
                )
            with v3.VList(density="compact", raw_attrs=[f'aria-label="menu {name} entries"']):
                for n, group in enumerate(groups):
                    if n:
                        v3.VDivider()
                    for i in group:
                        v3.VListItem(
                            title=i.label,
                            subtitle=i.keys_text(page=True) or None,
                            click=f"window.phongIntent('{i.id}')",
                            disabled=(f"intents_enabled['{i.id}'] === false",),
                            raw_attrs=[f'aria-label="intent {i.id}"'],
                        )


def help_dialog(v3, html) -> None:
    """The page's keys and mouse (F1 or ``h``; Help > Keys and mouse): every key of the
    registry the page has."""
    with v3.VDialog(v_model=("show_help", False), max_width=720, scrollable=True):
        with v3.VCard(raw_attrs=['aria-label="help"']):
            v3.VCardTitle(X.BY_ID["help"].label)
            with v3.VCardText(style="max-height: 70vh"):
                html.Pre(
                    "\n".join(X.help_lines(page=True)),
                    style="white-space: pre-wrap",
                    raw_attrs=['aria-label="help text"'],
                )
            with v3.VCardActions():
                v3.VSpacer()
                v3.VBtn("close", click="show_help = false", raw_attrs=['aria-label="close help"'])


def connect(app) -> None:
    """The trigger ``intent``: runs an intent the page runs on the server (any other id is
    refused: quit, for one, is the desktop's), when it can run."""
    server = app.server
    server.state.update(show_help=False, intents_enabled=X.enabled(app.controller))
    server.state.client_only("show_help")  # the help opens in the tab that asks, alone

    def run(intent_id):
        intent = X.BY_ID.get(str(intent_id))
        if intent is None or intent.page != "server":
            raise ExplorerError(f"the page has no intent named '{intent_id}'")
        return X.run(intent.id, app.controller, {})

    server.controller.trigger("intent")(app.guard(run, "intent"))
