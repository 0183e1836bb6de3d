"""The lit sphere in the lobe inset, beside the plot (docs/terms.md), as Disney's BRDF Explorer
shows one: the material and model of the view (A's) on a small sphere under one white light at
the plot's incidence, each pixel the engine's colour (:func:`explorer.analysis.litsphere.
sphere_picture`), a ring where the light comes from. A press on the sphere and a drag set the
incidence (:class:`SphereDrag`): the state's ``lobe_incidence`` (the panel model's row, so both
front ends have it as a number too), which the plot follows; the row switched off, the plot and
the sphere follow the selected light again. VTK is imported inside the methods.
"""

from __future__ import annotations

import math

import numpy as np

from explorer.analysis import litsphere as LS
from explorer.app.overlay import overlay, set_lines

#: the light's mark: a dark ring around a light one (seen on the highlight and on the dark
#: side), radii in pixels
MARK_RADII = (5.0, 3.5)
MARK_DARK = (0.05, 0.05, 0.06)
MARK_LIGHT = (1.0, 1.0, 1.0)
#: the priority of the sphere's mouse observers on the interactor: above the camera's style
#: and the handles' widgets (0 to 0.5), so a press on the sphere is the sphere's alone
PRIORITY = 10.0
#: a press this far out of the sphere (its radii) still takes it (the ring at the rim)
GRAB = 1.08


def circle(cx: float, cy: float, r: float, k: int = 24) -> np.ndarray:
    """(k + 1, 2) a closed polyline around ``(cx, cy)`` of radius ``r`` (pixels)."""
    a = np.linspace(0.0, 2.0 * math.pi, k + 1)
    return np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)])


class LitSphere:
    """The sphere in ``plotter``'s view: :meth:`place` puts it in a square of the inset,
    :meth:`update` draws it for a state at an incidence; :attr:`box` ``(x, y, size)`` in display
    pixels (origin bottom-left), :attr:`theta` the incidence drawn (radians), :attr:`picture`
    the (size, size, 3) bytes shown (rows top to bottom)."""

    def __init__(self, plotter, background):
        from vtkmodules.vtkRenderingCore import vtkActor2D, vtkImageMapper

        self.plotter = plotter
        self.background = background
        self.mapper = vtkImageMapper()
        self.mapper.SetColorWindow(255.0)
        self.mapper.SetColorLevel(127.5)
        self.image = None
        self.actor = vtkActor2D()
        self.actor.SetMapper(self.mapper)
        self.actor.SetVisibility(False)
        plotter.renderer.AddViewProp(self.actor)
        self._rings = [overlay(plotter, c, 1.5) for c in (MARK_DARK, MARK_LIGHT)]
        self.actors = [self.actor, *(a for _, a in self._rings)]
        self.box = None
        self.theta = None
        self.picture = None
        self._key = None

    def place(self, x: int, y: int, size: int) -> None:
        """The sphere's square: bottom-left ``(x, y)`` display pixels, ``size`` wide (0: no
        sphere, the view too small)."""
        box = (x, y, size) if size > 0 else None
        if self.box != box:
            self.box = box
            self._key = None
        if box is None:
            self.actor.SetVisibility(False)
            for poly, _ in self._rings:
                set_lines(poly, [])

    def update(self, scene, theta: float | None) -> None:
        """Draw ``scene``'s material and model lit at ``theta`` (radians; None: no light, the
        sphere lit from the viewer and no mark), when either changed."""
        if self.box is None:
            return
        t = 0.0 if theta is None else float(theta)
        key = (scene.material, scene.model, scene.ambient, scene.hdr, t, theta is None, self.box)
        if key == self._key:
            return
        self._key = key
        x, y, size = self.box
        self.picture = LS.sphere_picture(scene, t, size, self.background)
        self._upload(self.picture)
        self.actor.SetPosition(x, y)
        self.actor.SetVisibility(True)
        self.theta = theta
        if theta is None:
            for poly, _ in self._rings:
                set_lines(poly, [])
            return
        cx, cy = self.mark()
        for (poly, _), r in zip(self._rings, MARK_RADII, strict=True):
            set_lines(poly, [circle(cx, cy, r)])

    def _upload(self, picture: np.ndarray) -> None:
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.vtkCommonDataModel import vtkImageData

        size = picture.shape[0]
        image = vtkImageData()
        image.SetDimensions(size, size, 1)
        rows = np.ascontiguousarray(picture[::-1].reshape(-1, 3))  # (VTK's rows: bottom first)
        arr = numpy_to_vtk(rows, deep=True)
        arr.SetName("colors")
        image.GetPointData().SetScalars(arr)
        self.image = image
        self.mapper.SetInputData(image)

    def disc_point(self, px: float, py: float) -> tuple[float, float]:
        """Display pixel ``(px, py)`` (origin bottom-left) as a point ``(u, v)`` of the disc
        (radius 1 at the sphere's rim)."""
        x, y, size = self.box
        return ((px + 0.5 - x) * 2.0 / size - 1.0, (py + 0.5 - y) * 2.0 / size - 1.0)

    def mark(self) -> tuple[float, float]:
        """The light's mark in display pixels (origin bottom-left)."""
        x, y, size = self.box
        u, v = LS.light_point(0.0 if self.theta is None else self.theta)
        return (x + (u + 1.0) * size / 2.0, y + (v + 1.0) * size / 2.0)

    def report(self) -> dict | None:
        """What a test of a front end reads (plain JSON values, window pixels with the origin
        top-left): the sphere's box ``[x, y, size]`` (its top-left pixel), the incidence drawn
        (degrees) and the mark's pixel."""
        if self.box is None:
            return None
        x, y, size = self.box
        _, h = self.plotter.window_size
        mx, my = self.mark()
        return {
            "box": [int(x), int(h - y - size), int(size)],
            "theta": None if self.theta is None else math.degrees(self.theta),
            "mark": [mx, h - 1 - my],
        }


class SphereDrag:
    """A press on the lit sphere of ``window`` (an :class:`explorer.app.viewport.PlotterView`)
    and a drag set the lobe plot's incidence (``lobe_incidence``, through the controller as the
    panel's row sets it: the drag's steps are one undo step); a click on a legend entry of the
    plot of several lobes shows or hides its lobe. The camera does not turn. VTK's interactor
    events, so the window and the page alike."""

    def __init__(self, window):
        self.window = window
        self.dragging = False
        self.clicked = False
        iren = window.plotter.iren.interactor
        self._tags = {}  # (the tags, not the commands: a command held would hold the window)
        for event, fn in (
            ("LeftButtonPressEvent", self._press),
            ("MouseMoveEvent", self._move),
            ("LeftButtonReleaseEvent", self._release),
        ):
            self._tags[event] = window.observe(iren, event, fn, "lit sphere", PRIORITY)

    def _sphere(self):
        view = self.window.view
        return None if view is None else view.lobe.sphere

    def _pointer(self) -> tuple[int, int]:
        x, y = self.window.plotter.iren.interactor.GetEventPosition()
        return int(x), int(y)

    def _take(self, event: str) -> None:
        """The event is the sphere's: no observer after this one sees it."""
        self.window.plotter.iren.interactor.GetCommand(self._tags[event]).SetAbortFlag(1)

    def _press(self, _obj, event) -> None:
        if self._legend(event):
            return
        sphere = self._sphere()
        if sphere is None or sphere.box is None or not sphere.actor.GetVisibility():
            return
        u, v = sphere.disc_point(*self._pointer())
        if math.hypot(u, v) > GRAB:
            return
        self._take(event)
        self.dragging = True
        self._set(u, v)

    def _legend(self, event) -> bool:
        """A press on a legend entry of the inset's plot of several lobes: its lobe shown or
        hidden (its ``show_lobe_<i>`` row; one undo step); True when it was one."""
        view = self.window.view
        i = None if view is None else view.lobe.legend_at(*self._pointer())
        if i is None:
            return False
        from explorer.app import lobeinset as LI  # (it draws this module's sphere)

        self._take(event)
        self.clicked = True
        c = self.window.controller
        show = i in c.state.lobe_hidden
        if i < LI.LOBE_ROWS:
            c.set_value(f"show_lobe_{i + 1}", show, merge=False)
        else:
            c.act(LI.set_lobe_shown, i, show, label=f"lobe {i + 1}")
        return True

    def _move(self, _obj, event) -> None:
        if not self.dragging:
            return
        self._take(event)
        self._set(*self._sphere().disc_point(*self._pointer()))

    def _release(self, _obj, event) -> None:
        if self.clicked:  # (the legend's press was ours: its release too)
            self.clicked = False
            self._take(event)
            return
        if not self.dragging:
            return
        self._take(event)
        self._set(*self._sphere().disc_point(*self._pointer()))
        self.dragging = False
        self.window.controller.release()

    def _set(self, u: float, v: float) -> None:
        deg = round(LS.incidence_at(u, v), 1)
        if self.window.controller.state.lobe_incidence != deg:
            self.window.controller.set_value("lobe_incidence", deg)
