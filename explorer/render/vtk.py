"""The VTK side of every picture: the plotter factory and the mesh builder.

Every window the project draws into (the off-screen renderer, the per-pixel comparison's
renders, the explorer window, the GUI benchmark) comes from :func:`plotter`, so all draw the
same way: no multisampling or anti-aliasing, no lights of VTK's own, plain "over" blending of
translucent triangles in the order they are drawn (VTK's weighted-average order-independent
transparency and its depth peeling, which orders layers wrongly on Mesa llvmpipe, are both off).
Every mesh goes to VTK through :func:`polydata`, and is drawn in the engine's colours by
:func:`add_unlit`: RGB point scalars with VTK's lighting off, so VTK adds nothing (no light of
its own, no specular, no ambient) and interpolates the colours linearly across each triangle.

With no display, an off-screen window asks VTK for EGL directly (:func:`headless_egl`): VTK
would otherwise probe X, log "bad X server connection" and then fall back to EGL.

PyVista and VTK are imported inside the functions only.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Sequence
from contextlib import contextmanager

import numpy as np

from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera, apply_camera, in_frame

#: the environment variable that picks VTK's OpenGL window class
WINDOW_ENV = "VTK_DEFAULT_OPENGL_WINDOW"


@contextmanager
def headless_egl():
    """While active, with no X or Wayland display and no window class chosen by the user,
    VTK creates EGL windows. The setting is taken back afterwards, so nothing else in the
    process (a window opened later on a display) inherits it."""
    headless = not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY")
    added = headless and WINDOW_ENV not in os.environ
    if added:
        os.environ[WINDOW_ENV] = "vtkEGLRenderWindow"
    try:
        yield
    finally:
        if added:
            del os.environ[WINDOW_ENV]


#: VTK draws in one thread at a time: a window's (or the page's) frames and the difference
#: worker's off-screen pictures share VTK's and Mesa's process-wide state, and the two drawn at
#: once crashed the window (a segmentation fault in the worker's render while the window drew,
#: tests/app/qt/test_panel.py's compare and difference test, 1 CI run in 3). Every render window
#: made here or by a front end holds it through each frame (:func:`one_frame_at_a_time`); an
#: off-screen picture holds it through all its VTK work: its window made, its actors added and
#: removed (they make and free OpenGL buffers), its render and read-back, its window closed
#: (:class:`explorer.render.offscreen.OffscreenWindow`: the difference worker makes, changes and
#: closes its windows in its own thread); a front end closes its view's window under it too.
#: Re-entrant: a frame's observers may draw another window (side B, the per-pixel G-buffer) in
#: the same thread.
DRAW_LOCK = threading.RLock()


def one_frame_at_a_time(render_window) -> None:
    """``render_window`` holds :data:`DRAW_LOCK` from each frame's start to its end (VTK's
    StartEvent and EndEvent, in the drawing thread); an end without its start releases
    nothing."""
    held = []

    def start(*_):
        DRAW_LOCK.acquire()
        held.append(True)

    def end(*_):
        if held:
            held.pop()
            DRAW_LOCK.release()

    render_window.AddObserver("StartEvent", start)
    render_window.AddObserver("EndEvent", end)


def plotter(size: Sequence[int], background, *, off_screen: bool = True, title: str | None = None):
    """A ``pyvista.Plotter`` set up to draw the engine's colours.

    size : (width, height) in pixels; background : RGB in [0, 1]
    off_screen : True: an off-screen window (EGL when there is no display); False: a window on
        the screen, titled ``title``
    """
    import pyvista as pv

    w, h = (int(v) for v in size)
    if off_screen:
        with headless_egl():
            pl = pv.Plotter(off_screen=True, window_size=[w, h], lighting=None)
    else:
        pl = pv.Plotter(window_size=[w, h], lighting=None, title=title)
    pl.render_window.SetMultiSamples(0)  # before the first render: no multisampling
    draw_as_the_engine(pl, background)
    return pl


def draw_as_the_engine(pl, background) -> None:
    """Any PyVista plotter (an off-screen one, a window, the Qt window's ``QtInteractor`` s)
    set up to show the engine's colours as they are: no anti-aliasing, translucency blended
    in draw order (:func:`plain_blending`), ``background`` (RGB in [0, 1]), and one frame at a
    time (:func:`one_frame_at_a_time`: the difference worker draws too)."""
    pl.disable_anti_aliasing()
    plain_blending(pl.renderer)
    pl.set_background(background)
    one_frame_at_a_time(pl.render_window)


def plain_blending(renderer) -> None:
    """Blend translucent triangles "over" what is drawn, in the order they are drawn (the
    callers sort them back to front): VTK's weighted-average order-independent transparency
    (on by default in every ``vtkOpenGLRenderer``) would average the front and back layers of a
    closed mesh whatever its opacity, and its depth peeling orders layers wrongly on Mesa
    llvmpipe. Every renderer that draws the engine's colours goes through here, the window's
    panes too, so the window blends as the off-screen renders do."""
    renderer.SetUseOIT(False)
    renderer.SetUseDepthPeeling(False)


def cells(faces) -> np.ndarray:
    """VTK's cell array of triangles: ``[3, i, j, k, 3, ...]``.

    faces : (m, 3) int
    Returns (4m,) int64.
    """
    faces = np.asarray(faces, np.int64).reshape(-1, 3)
    return np.hstack([np.full((len(faces), 1), 3, np.int64), faces]).ravel()


def polydata(
    mesh: Mesh, colors=None, *, faces=None, float32: bool = False, normals: bool = True, frame=None
):
    """A ``pyvista.PolyData`` of the mesh's triangles.

    colors : (n, 3|4) uint8 point data named ``"colors"``, or None
    faces : (m, 3) int triangles to use instead of the mesh's (a drawing order), or None
    float32 : float32 points (what the GPU draws) instead of a float64 copy
    normals : the vertex normals as the active point normals ``"Normals"`` (VTK's own lighting
        uses them; unlit colours do not)
    frame : (centre (3,), scale): the points in that frame, ``(p - centre) / scale``
        (:func:`explorer.render.camera.mesh_frame`; the camera goes there too: :func:`set_camera`)
    """
    import pyvista as pv

    dtype = np.float32 if float32 else np.float64
    P = np.asarray(mesh.positions, np.float64)
    if frame is not None:
        centre, scale = frame
        P = P / scale - np.asarray(centre, np.float64) / scale
    poly = pv.PolyData(np.array(P, dtype=dtype), cells(mesh.faces if faces is None else faces))
    if normals:
        poly.point_data["Normals"] = np.array(mesh.normals)
        poly.point_data.active_normals_name = "Normals"
    if colors is not None:
        poly.point_data["colors"] = np.asarray(colors)
    return poly


def add_unlit(plotter, poly):
    """Draw ``poly`` in its ``"colors"`` point data as they are (VTK's lighting off), without
    moving the camera and without drawing a frame now (PyVista's default renders one: in the
    window that frame ran the explorer's frame observers in the middle of a mesh switch, which
    switched side B's mesh a second time and left a stale copy drawn over the live one).
    Returns the actor."""
    return plotter.add_mesh(
        poly,
        scalars="colors",
        rgb=True,
        lighting=False,
        show_scalar_bar=False,
        reset_camera=False,
        render=False,
    )


def set_camera(plotter, camera: Camera, frame=None) -> None:
    """Point the plotter's camera as ``camera`` (:func:`explorer.render.camera.apply_camera`)
    and keep PyVista from resetting it at the first frame. frame : (centre, scale), the frame
    the meshes were given in (:func:`polydata`): the camera goes there too."""
    plotter.camera_set = True
    apply_camera(plotter.camera, camera if frame is None else in_frame(camera, *frame))
