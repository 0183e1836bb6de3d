"""The web front end: the explorer in the browser and in Jupyter, a trame server that is the
second front end of :class:`~explorer.app.controller.Controller` (the Qt window,
:mod:`explorer.app.qt`, is the first), as Qt's modules are in :mod:`explorer.app.qt`:

- :mod:`~explorer.app.web.server`: :class:`WebExplorer` (the controller's ports for a page) and
  :func:`serve` (``phong-explorer web``);
- :mod:`~explorer.app.web.jupyter`: :func:`show` (the explorer in a notebook cell, through
  jupyter-server-proxy where Jupyter is remote) and :class:`Shown`;
- :mod:`~explorer.app.web.page` (the page's layout), :mod:`~explorer.app.web.panel` (the
  controls' values and handlers, drawn from :mod:`explorer.app.panelmodel`'s rows),
  :mod:`~explorer.app.web.intents` (the menus, keys and help from
  :mod:`explorer.app.intents`), :mod:`~explorer.app.web.files` (uploads and downloads),
  :mod:`~explorer.app.web.compare` (pane B);
- :mod:`~explorer.app.web.guard` (who may connect and what a page may set) and
  :mod:`~explorer.app.web.wire` (wslink's websocket handler, bounded).

May import: trame, wslink and aiohttp (inside functions: importing this package imports none of
them, nor VTK or PyVista), the controller, the model, the view port; never Qt (an import
contract).
"""

from explorer.app.web.jupyter import Shown, notebook_state, page_url, proxy_prefix, show
from explorer.app.web.server import (
    DEFAULT_HOST,
    OPEN_HOST_WARNING,
    WebExplorer,
    check_listen,
    serve,
)

__all__ = [
    "DEFAULT_HOST",
    "OPEN_HOST_WARNING",
    "Shown",
    "WebExplorer",
    "check_listen",
    "notebook_state",
    "page_url",
    "proxy_prefix",
    "serve",
    "show",
]
