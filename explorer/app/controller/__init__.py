"""The explorer's flows, apart from any GUI toolkit: one :class:`Controller` for every front end
(the Qt window, the browser and Jupyter page).

How a front end uses it::

    ports = Ports(dialogs=..., messages=..., view=..., worker=..., choices=..., progress=...)
    c = Controller(state, mesh, ports, output_dir=...)   # the start (see explorer.app.start)
    c.start()                 # lists shown, the difference scheduled, the first frame asked for
    c.set_value("kd", 0.4)    # intents: set a value, pick_preset, open_file, save_session_as,
    c.release()               #   export_render, toggle_difference, toggle_compare, undo, ...
    c.store.state             # the state to draw; c.store.subscribe(fn) to hear of changes

The controller calls the model's actions (:mod:`explorer.app.model`), which make each change
one undo step; then it gives the new state to the view port (one engine update, one upload),
schedules the difference worker (once per change; a stale result is never shown) and asks for
one frame. Everything it needs from the front end goes through the small protocols of
:mod:`explorer.app.controller.ports`: questions, messages, progress, work off the main thread,
the view.

May import: the model and the app's toolkit-free modules (session, start, difference,
turntablejob), explorer.core, geometry, render; never PySide6, pyvistaqt or trame (an
import-linter contract, "the controller knows no toolkit").
"""

from explorer.app.controller.base import Controller
from explorer.app.controller.ports import (
    Choices,
    Dialogs,
    Messages,
    Ports,
    Progress,
    View,
    Worker,
)

__all__ = ["Controller", "Ports", "Dialogs", "Messages", "View", "Worker", "Choices", "Progress"]
