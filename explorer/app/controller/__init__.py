"""The explorer's flows, apart from any GUI toolkit: one :class:`Controller` for every front end
(the Qt window, the browser and Jupyter page).

How a front end uses it::

    ports = Ports(dialogs=..., messages=..., view=..., worker=..., choices=..., progress=...)
    c = Controller(state, mesh, ports, output_dir=...)   # the start (see explorer.app.start)
    c.start()                 # lists shown, the difference scheduled, the first frame asked for
    c.set_value("kd", 0.4)    # intents: set a value, pick_preset, files.open_file,
    c.release()               #   files.save_session_as, toggle_difference, undo, ...
    c.store.state             # the state to draw; c.store.subscribe(fn) to hear of changes

The intents (on :class:`Controller`): ``set_value(key, value)`` and ``release()`` (a
control of :data:`explorer.core.controls.CONTROLS`), ``act(action, *args, label=, merge=)`` (any
model action), ``pick_preset``, ``next_preset`` / ``previous_preset``,
``next_light`` / ``next_light_type``, ``toggle_model`` / ``toggle_term`` / ``toggle_difference``
/ ``toggle_compare`` / ``swap_sides``, ``undo`` / ``redo`` / ``reset_all``; on its file flows,
the collaborator ``files`` (:class:`~explorer.app.controller.files.FileFlows`):
``choose_mesh``, ``open_file`` / ``open_session`` / ``open_recent``, ``save_session_as`` /
``save_preset_as`` / ``keep_last_session``, ``import_materials``, ``export_material`` /
``export_render`` / ``export_turntable`` / ``screenshot`` (each takes a path, or asks the dialogs
port for one); the camera's ``camera_moved`` (before a frame), ``move_camera``, ``reset_camera``,
``frame_start``, drags' ``begin_drag`` / ``end_drag``, the worker's ``on_difference(result)``,
and ``reject_input(text)`` (a typed value the front end refused).

The menus, keys and help of both front ends are built from
:data:`explorer.app.intents.INTENTS`, which names these methods.

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
