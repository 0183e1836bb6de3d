"""The Qt window's view port (:class:`explorer.app.controller.ports.View`): the controller's
changes drawn in the 3D view, the compare pane and the controls; the difference view's heat
map or the live view; the view's size, colours and pixels."""

from __future__ import annotations

import time

import numpy as np

from explorer.app import model as M
from explorer.app.difference import PENDING, advice_lines
from explorer.app.view import view_camera
from explorer.render.images import encode_png


class QtView:
    """The view port of ``window`` (an :class:`explorer.app.qt.window.ExplorerWindow`: its
    ``view``, ``plotter``, ``panel``, ``heat``, ``compare``, ``status_label``)."""

    def __init__(self, window):
        self.w = window

    def show(self, old: M.State | None, new: M.State) -> None:
        """One change drawn: the view (one engine update, one upload), side B, the camera when
        it did not come from the view, the controls unless only the camera moved. ``old``
        None: a value was refused; the controls show the state again."""
        w = self.w
        if w._t0 is None:
            w._t0 = time.perf_counter()
        if old is None:
            self.show_panel(new)
            return
        if new.mesh != old.mesh:
            w.view.set_mesh(w.controller.meshes[new.mesh], new)
        else:
            w.view.show_state(new)
        w.compare.show(old, new)
        if new.camera is not None and not w.controller.in_frame:
            if view_camera(w.plotter.camera, new.centre, new.radius) != new.camera:
                w.view.apply_camera(new.camera)
        viewer = old.scene.replace(viewer=new.scene.viewer)
        if (old.replace(camera=None, scene=viewer) != new.replace(camera=None)
                or new.preset_material is not old.preset_material):  # fmt: skip
            self.show_panel(new)

    def show_panel(self, state: M.State) -> None:
        """The controls and the status bar's summary show ``state``."""
        w = self.w
        w.panel.show_state(state, w.view.mesh.n_vertices)
        what = state.preset or "(scene material)"
        if state.groups is not None:
            what = f"{state.mesh_materials.source}'s materials"
        parts = [what, state.scene.model]
        if state.hidden:
            parts.append("hidden: " + ", ".join(t for t in M.TERMS if t in state.hidden))
        w.status_label.setText(";  ".join(parts))

    def redraw(self) -> None:
        self.w.render()

    def size(self) -> tuple[int, int]:
        return tuple(int(v) for v in self.w.plotter.window_size)

    def aspect(self) -> float:
        return self.w.view_aspect

    def background(self):
        return tuple(self.w.plotter.renderer.GetBackground())

    def colors(self) -> np.ndarray:
        return self.w.view.drawings[0].colors()

    def dragging(self) -> bool:
        return bool(self.w.view.dragging)

    def show_difference(self, result, *, on: bool) -> None:
        w = self.w
        current = on and result is not None
        if current and w.heat.result is not result:
            w.heat.set(result)
        w.heat.show(current)
        w.view.show_mesh(not current)
        if on:
            w.panel.view.legend.setText(w.heat.legend() if current else PENDING)
            w.panel.view.advice.setText(advice_lines(result.advice) if current else "")

    def png(self) -> bytes:
        """The 3D view as drawn now, PNG-encoded (in the compare view both panes, side by side
        as in the window)."""
        self.w.render()
        img = self.w.plotter.screenshot(return_img=True)[:, :, :3]
        return encode_png(np.ascontiguousarray(self.w.compare.beside(img)))
