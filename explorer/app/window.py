"""The desktop explorer: a PyVista window over the engine's cached :class:`~explorer.Shader`.

The app is a thin stateful front over pure functions. Its state is the scene (material, model,
lights, viewer), the mesh, the preset shown, which terms are drawn and which light the controls
move. Every change goes the same way::

    new state -> Shader.set_scene (the engine recomputes only what changed)
              -> uint8 colours written in place into the mesh's point data -> render

The colours are drawn as RGB point scalars with VTK's lighting off, so VTK adds nothing to the
engine's colours (see the last section of the lighting-equation reference). The camera *is* the
viewer: before each frame the engine's viewer is set from the camera (a perspective camera is a
local viewer at the camera's position, a parallel one an infinite viewer looking along it), so
rotating the camera moves the highlights and recomputes the specular sum only.

Meshes above :data:`LOD_VERTICES` get a lighter level of detail (quadric clustering to about
:data:`LOD_TARGET` vertices, shaded by its own Shader) drawn while a slider, the light handle
or the camera is being dragged; the full mesh is shaded and drawn on release.

PyVista and VTK are imported only inside this module's functions and methods that need them.
"""

from __future__ import annotations

import json
import logging
import math
import os
import time
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np

from explorer.analysis import advice as A
from explorer.app import layout as G
from explorer.app.difference import PENDING, DifferenceView, advice_lines
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.lights import angles_of, direction_of
from explorer.core.material import Material
from explorer.core.presets import MAX_NAME_LENGTH, list_presets, save_preset, user_dir
from explorer.core.scene import Scene, Viewer, check_materials_dirs
from explorer.geometry.meshes import Mesh, area_weighted_normals, get_mesh
from explorer.render.camera import Camera, apply_camera, back_to_front, camera_for, camera_from_vtk
from explorer.render.images import encode_png
from explorer.render.offscreen import BACKGROUND
from explorer.render.vtk import add_unlit, cells, plotter, polydata, set_camera
from explorer.shading.display import engine_clamps, shown, to_bytes
from explorer.shading.shader import Shader

log = logging.getLogger(__name__)

#: meshes with more vertices than this get a level of detail drawn while dragging
LOD_VERTICES = 250_000
#: about how many vertices the level of detail has
LOD_TARGET = 60_000
#: built-in meshes offered by the mesh chooser, with the resolution the explorer uses
MESH_CHOICES: dict[str, int | None] = {
    "teapot": 24,
    "sphere": 128,
    "icosphere": 5,
    "torus": 128,
    "cube": None,
    "plane": 64,
}
#: the explorer's start when nothing else is asked for
DEFAULT_PRESET = "gold"
DEFAULT_MESH = "teapot"
#: where the start light sits: azimuth, elevation (degrees) and distance (mesh radii)
DEFAULT_PLACEMENT = (40.0, 35.0, 2.5)
#: where the start camera sits (a local viewer): direction from the mesh centre, distance in
#: mesh radii
DEFAULT_EYE_DIRECTION = (0.0, 0.3, 1.0)
DEFAULT_EYE_DISTANCE = 6.5
#: a light's handle nearer than this (mesh radii) is kept in view when the camera is framed
HANDLE_FRAMING = 4.0
#: widest view angle (degrees) the framing may use to show the handle
MAX_VIEW_ANGLE = 60.0
#: exit status when no window can be opened
NO_DISPLAY_STATUS = 3
TERMS = G.TERM_BUTTONS


class NoDisplayError(ExplorerError):
    """No window can be opened here (no X display, or VTK forced off-screen)."""


# -- pure functions ----------------------------------------------------------------------------


def round_sig(x: float, digits: int = 3) -> float:
    """``x`` rounded to ``digits`` significant digits (0 stays 0)."""
    if x == 0 or not math.isfinite(x):
        return float(x)
    return float(f"{x:.{digits}g}")


def shininess_to_slider(n: float) -> float:
    """Position of the shininess slider for exponent ``n``: log10(n), held in [0, 3] (an
    exponent below 1 sits at the left end; the slider's title still shows the real n)."""
    lo, hi = G.SHININESS_SLIDER_RANGE
    return min(max(math.log10(n), lo), hi) if n > 0 else lo


def slider_to_shininess(value: float) -> float:
    """Exponent of a shininess slider position: 10**value, to 3 significant digits."""
    lo, hi = G.SHININESS_SLIDER_RANGE
    return round_sig(10.0 ** min(max(float(value), lo), hi), 3)


def slider_to_coefficient(value: float) -> float:
    """A ka / kd / ks slider position as the coefficient it sets (3 decimals, in [0, 1])."""
    return min(max(round(float(value), 3), 0.0), 1.0)


def display_material(material: Material, terms: dict) -> Material:
    """The material drawn when some terms are hidden: each hidden term's coefficient is 0
    (``ambient`` also hides the emission, the other constant term)."""
    changes = {t: (0.0, 0.0, 0.0) for t in TERMS if not terms.get(t, True)}
    if "ambient" in changes:
        changes["emission"] = (0.0, 0.0, 0.0)
    return material.replace(**changes) if changes else material


def lobe_curve(n: float, samples: int = G.LOBE_SAMPLES) -> np.ndarray:
    """The specular lobe ``r = cos^n(t)`` for -90° <= t <= 90° in polar coordinates around the
    mirror direction (the x axis), as the lecture notes draw it: (samples, 2) float64 points
    ``(r cos t, r sin t)``."""
    t = np.linspace(-0.5 * math.pi, 0.5 * math.pi, int(samples))
    c = np.clip(np.cos(t), 0.0, 1.0)
    r = c ** float(n) if n > 0 else np.ones_like(c)
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def viewer_of_camera(position, focal_point, parallel: bool) -> Viewer:
    """The engine's viewer seen by a camera: a local viewer at the position (perspective), or
    an infinite viewer looking along the camera (parallel projection)."""
    if parallel:
        return Viewer(to_viewer=tuple(np.subtract(position, focal_point)))
    return Viewer(eye=tuple(position))


def widen_to_show(camera, points, aspect: float, *, pad: float = 0.0, margin: float = 1.1):
    """``camera`` (a :class:`explorer.render.camera.Camera`) with its view widened just enough to
    show ``points`` (each a sphere of radius ``pad``) too, in a picture of ``aspect`` (width /
    height); points behind a perspective camera are left out. Position, direction and up are kept
    (the viewer does not move)."""
    from dataclasses import replace

    fwd = camera.direction
    up = np.asarray(camera.view_up, dtype=np.float64)
    right = np.cross(fwd, up)
    origin = np.asarray(camera.focal_point if camera.parallel else camera.position)
    need = 0.0
    for p in points:
        rel = np.asarray(p, dtype=np.float64) - origin
        x, y, z = abs(rel @ right) + pad, abs(rel @ up) + pad, rel @ fwd
        if camera.parallel:
            need = max(need, y, x / aspect)
        elif z > pad:
            need = max(need, y / (z - pad), x / (aspect * (z - pad)))
    need *= margin
    if camera.parallel:
        return replace(camera, parallel_scale=max(camera.parallel_scale, need))
    angle = math.degrees(2.0 * math.atan(need))
    return replace(camera, view_angle=max(camera.view_angle, min(angle, MAX_VIEW_ANGLE)))


def free_name(stem: str, taken: Iterable[str]) -> str:
    """The first of ``stem_1``, ``stem_2``, ... not in ``taken``."""
    taken = set(taken)
    i = 1
    while f"{stem}_{i}" in taken:
        i += 1
    return f"{stem}_{i}"


def help_text() -> str:
    """Every key and mouse control, one per line (the help overlay)."""
    lines = ["keys"]
    lines += [f"  {key:<4} {what}" for key, what in G.KEYS.items()]
    lines.append("mouse")
    lines += [f"  {how}: {what}" for how, what in G.MOUSE]
    return "\n".join(lines)


def no_display_reason(environ=None) -> str | None:
    """Why no window can open here, or None when it looks possible (Linux / X11 only; other
    systems are left to VTK)."""
    import sys

    env = os.environ if environ is None else environ
    if sys.platform in ("darwin", "win32"):
        return None
    forced = env.get("VTK_DEFAULT_OPENGL_WINDOW", "")
    if forced and forced != "vtkXOpenGLRenderWindow":
        return f"VTK_DEFAULT_OPENGL_WINDOW={forced} makes VTK render off-screen only"
    display = env.get("DISPLAY")
    if not display:
        return "no display (DISPLAY is not set)"
    if not _x_display_opens(display):
        return f"cannot open the X display {display!r}"
    return None


def no_display_message(reason: str) -> str:
    """The one line printed when no window can open: why, and what to run instead."""
    return (
        f"phong-explorer: {reason}, so the explorer window cannot open; for pictures run "
        "'phong-explorer render --out FILE.png' (off-screen), or give the window a virtual "
        "display: 'xvfb-run -s \"-screen 0 1280x900x24\" phong-explorer gui'"
    )


def _x_display_opens(display: str) -> bool:
    """True if Xlib can connect to ``display`` (True when libX11 is not found: VTK decides)."""
    import ctypes
    import ctypes.util

    name = ctypes.util.find_library("X11")
    if not name:
        return True
    try:
        x11 = ctypes.CDLL(name)
    except OSError:
        return True
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    handle = x11.XOpenDisplay(display.encode())
    if not handle:
        return False
    x11.XCloseDisplay(handle)
    return True


# -- meshes ------------------------------------------------------------------------------------


def lod_mesh(mesh: Mesh, target: int = LOD_TARGET) -> Mesh:
    """A lighter version of ``mesh`` with about ``target`` vertices (VTK quadric clustering),
    with smooth area-weighted normals. Used only while dragging."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkQuadricClustering

    poly = polydata(mesh, float32=True, normals=False)

    def cluster(divisions: int):
        q = vtkQuadricClustering()
        q.SetInputData(poly)
        q.SetAutoAdjustNumberOfDivisions(False)
        q.SetNumberOfDivisions(divisions, divisions, divisions)
        q.Update()
        return q.GetOutput()

    # a surface's vertex count grows as the divisions squared, until it saturates at the
    # mesh's own count: a few corrections reach the target within ~25 %
    d = max(4, int(0.5 * math.sqrt(target)))
    out = cluster(d)
    for _ in range(6):
        count = out.GetNumberOfPoints()
        if count == 0 or abs(count - target) <= 0.25 * target:
            break
        if count >= 0.8 * mesh.n_vertices:
            step = 0.5
        else:
            step = math.sqrt(target / count)
        d = max(4, int(round(d * step)))
        out = cluster(d)
    pos = vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
    faces = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).astype(np.int64).reshape(-1, 3)
    return Mesh(pos, area_weighted_normals(pos, faces), faces, f"{mesh.name} (LOD)")


class _View:
    """One drawn version of the mesh (the full mesh or its level of detail): its Shader, its
    PolyData and actor, and the uint8 colour array VTK draws, written in place."""

    def __init__(self, pl, mesh: Mesh, scene: Scene):
        from vtkmodules.util.numpy_support import vtk_to_numpy

        self.mesh = mesh
        self.centre = mesh.centre  # (3,): Mesh computes these on every call
        self.radius = mesh.radius or 1.0
        self.shader = Shader(
            scene,
            mesh.positions,
            mesh.normals,
            precision="float32",
            clamp=engine_clamps(scene),
            faces=mesh.faces,
        )
        # float32 points, no normals: the colours are drawn unlit
        self.poly = polydata(
            mesh, np.zeros((mesh.n_vertices, 3), np.uint8), float32=True, normals=False
        )
        self.actor = add_unlit(pl, self.poly)
        self.vtk_colors = self.poly.GetPointData().GetArray("colors")
        self.rgb = vtk_to_numpy(self.vtk_colors)  # a view of VTK's memory
        self.sorted_for = None  # camera the triangles were last sorted for (translucency)

    def colors(self) -> np.ndarray:
        """(n, 3) display colours in [0, 1]: the shader's through the display pipeline
        (:func:`explorer.shading.display.shown`)."""
        return shown(self.shader.colors, self.shader.scene)

    def upload(self) -> None:
        """Write the display colours into VTK's array as 8-bit values
        (:func:`explorer.shading.display.to_bytes`) and mark it modified."""
        to_bytes(self.colors(), out=self.rgb)
        self.vtk_colors.Modified()

    def show(self, visible: bool) -> None:
        self.actor.SetVisibility(bool(visible))


# -- the app -----------------------------------------------------------------------------------


class Explorer:
    """The explorer window.

    scene : the start scene (material, model, lights, viewer); the camera starts at its viewer
    mesh : the start mesh
    preset : name of the start preset in the chooser (None: the scene's material, unnamed)
    materials_dirs : extra preset directories (``--materials-dir``)
    off_screen : draw into an off-screen buffer (tests, benchmarks); no event loop
    state_file : write the app's state as JSON here (atomically) after every frame
    output_dir : where screenshots go (default: the current directory)
    preset_dir : where saved presets go (default: the user's preset directory)
    lod_vertices : meshes with more vertices get a level of detail while dragging
    lod_target : about how many vertices the level of detail has
    background : RGB in [0, 1] (default: the renderer's background)
    """

    def __init__(
        self,
        scene: Scene,
        mesh: Mesh,
        *,
        preset: str | None = None,
        materials_dirs: Sequence = (),
        off_screen: bool = False,
        window_size: Sequence[int] = G.WINDOW_SIZE,
        state_file=None,
        output_dir=None,
        preset_dir=None,
        lod_vertices: int = LOD_VERTICES,
        lod_target: int = LOD_TARGET,
        background=None,
    ):
        self.materials_dirs = check_materials_dirs(materials_dirs)
        self.state_file = Path(state_file) if state_file else None
        self.output_dir = Path(output_dir) if output_dir else Path.cwd()
        self.preset_dir = preset_dir
        self.lod_vertices = int(lod_vertices)
        self.lod_target = int(lod_target)
        self.presets = self._list_presets()
        self.errors: list[str] = []
        self.message = ""
        self.frames = 0
        self.frame_ms = float("nan")
        self.last_saved: str | None = None
        self.last_screenshot: str | None = None
        self.help_visible = False
        self._t0: float | None = None
        self._building = True
        self._deferred = False
        self._dragging = 0

        self.scene = scene
        self.terms = {t: True for t in TERMS}
        self.light_index = 0
        self.preset_name = preset if preset is not None else scene.material.name
        self.mesh_choices = dict(MESH_CHOICES)
        if mesh.name not in self.mesh_choices:  # a file: first in the chooser
            self.mesh_choices = {mesh.name: None, **self.mesh_choices}
        self._meshes = {mesh.name: mesh}
        self._mesh_specs = {mesh.name: scene.mesh or mesh.name}  # name -> scene.mesh value
        self._lods: dict[str, Mesh] = {}

        w, h = (int(v) for v in window_size)
        background = BACKGROUND if background is None else background
        self.plotter = pl = plotter((w, h), background, off_screen=off_screen, title=G.TITLE)
        if not off_screen:
            reason = _window_problem(pl.render_window)
            if reason:
                pl.close()
                raise NoDisplayError(reason)
        self._build_panel()
        self._views: list[_View] = []
        self._set_mesh(mesh)
        self._build_sliders()
        self._build_buttons()
        self._build_handle()
        self._build_lobe()
        self._build_texts()
        self.difference = DifferenceView(pl.renderer)
        self.difference_ms = float("nan")  # time of the last comparison
        self.advice = ""
        self._diff_pending = False  # the shown map is stale: compute it when the change ends
        self._diff_timer = None
        self._on_screen = not off_screen
        self._frame_camera()
        self._observe()
        self._start = (
            self.scene,
            mesh.name,
            self.preset_name,
            camera_from_vtk(self.plotter.camera),
        )
        self._building = False
        self._push_scene(render=False)
        self._sync_controls()

    # -- construction ----------------------------------------------------------------------
    def _build_panel(self) -> None:
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkRenderingCore import vtkActor2D, vtkCoordinate, vtkPolyDataMapper2D

        pts = vtkPoints()
        for x, y in ((G.PANEL_X, 0.0), (1.0, 0.0), (1.0, 1.0), (G.PANEL_X, 1.0)):
            pts.InsertNextPoint(x, y, 0.0)
        cells = vtkCellArray()
        cells.InsertNextCell(4, [0, 1, 2, 3])
        poly = vtkPolyData()
        poly.SetPoints(pts)
        poly.SetPolys(cells)
        coord = vtkCoordinate()
        coord.SetCoordinateSystemToNormalizedViewport()
        mapper = vtkPolyDataMapper2D()
        mapper.SetInputData(poly)
        mapper.SetTransformCoordinate(coord)
        actor = vtkActor2D()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*G.PANEL_COLOR)
        actor.GetProperty().SetOpacity(G.PANEL_OPACITY)
        self.plotter.renderer.AddViewProp(actor)

    def _build_sliders(self) -> None:
        pl = self.plotter
        self.sliders = {}
        for name in G.MATERIAL_SLIDERS + G.LIGHT_SLIDERS:
            y = G.SLIDER_Y[name]
            lo, hi = self._slider_range(name)
            value = lo
            if name == "distance":  # a directional light's handle sits at this distance
                value = min(max(DEFAULT_PLACEMENT[2] * self.radius, lo), hi)
            w = pl.add_slider_widget(
                self._guard(self._on_slider, name, name="slider"),
                (lo, hi),
                value=value,
                title=name,
                pointa=(G.SLIDER_X[0], y),
                pointb=(G.SLIDER_X[1], y),
                color=G.TEXT_COLOR,
                pass_widget=True,
                interaction_event="always",
                fmt=G.SLIDER_FORMAT.get(name, "%.3f"),
            )
            rep = w.GetRepresentation()
            g = G.SLIDER_GEOMETRY
            rep.SetSliderLength(g["slider_length"])
            rep.SetSliderWidth(g["slider_width"])
            rep.SetTubeWidth(g["tube_width"])
            rep.SetEndCapLength(g["end_cap_length"])
            rep.SetEndCapWidth(g["end_cap_width"])
            rep.SetTitleHeight(g["title_height"])
            rep.SetLabelHeight(g["label_height"])
            rep.GetSliderProperty().SetColor(*G.ACCENT_COLOR)
            rep.GetTubeProperty().SetColor(*G.DIM_COLOR)
            rep.GetCapProperty().SetColor(*G.DIM_COLOR)
            for prop in (rep.GetTitleProperty(), rep.GetLabelProperty()):
                prop.SetBold(False)
                prop.SetShadow(False)
            if name == "shininess":
                rep.ShowSliderLabelOff()  # log10(n) means nothing to people: the title shows n
            w._name = name
            w.AddObserver("StartInteractionEvent", self._guard(self._begin_drag))
            w.AddObserver("EndInteractionEvent", self._guard(self._end_drag))
            self.sliders[name] = w

    def _slider_range(self, name: str) -> tuple[float, float]:
        if name in ("ka", "kd", "ks"):
            return (0.0, 1.0)
        if name == "shininess":
            return G.SHININESS_SLIDER_RANGE
        if name == "azimuth":
            return G.AZIMUTH_RANGE
        if name == "elevation":
            return G.ELEVATION_RANGE
        r = self.radius
        lo, hi = G.DISTANCE_RANGE[0] * r, G.DISTANCE_RANGE[1] * r
        d = None if self.light is None else self.light.placement(self.centre)[2]
        if d is not None:  # a light at a distance (not at infinity)
            lo, hi = min(lo, d), max(hi, d)
        return (lo, hi)

    def _build_buttons(self) -> None:
        pl = self.plotter
        self.buttons = {}
        for name in G.BUTTONS:
            w = pl.add_checkbox_button_widget(
                self._guard(self._on_button, name, name="button"),
                value=False,
                position=(0, 0),
                size=G.BUTTON_SIZE,
                border_size=2,
                color_on=G.ACCENT_COLOR,
                color_off=G.DIM_COLOR,
                background_color=G.TEXT_COLOR,
            )
            self.buttons[name] = w
        self._place_buttons()

    def _place_buttons(self, *_) -> None:
        w, h = self.plotter.window_size
        s = G.BUTTON_SIZE
        for name, (x, y) in G.BUTTONS.items():
            x0, y0 = round(x * w), round(y * h)
            self.buttons[name].GetRepresentation().PlaceWidget([x0, x0 + s, y0, y0 + s, 0, 0])

    def _build_handle(self) -> None:
        r = G.HANDLE_RADIUS * self.radius
        self.handle = self.plotter.add_sphere_widget(
            self._guard(self._on_handle, name="light handle"),
            center=(0.0, 0.0, 0.0),
            radius=r,
            theta_resolution=20,
            phi_resolution=12,
            color=G.HANDLE_COLOR,
            selected_color=(1.0, 1.0, 1.0),
            test_callback=False,
            interaction_event="always",
        )
        self.handle.ScaleOff()  # right-drag would resize it
        self.handle.AddObserver("StartInteractionEvent", self._guard(self._begin_drag))
        self.handle.AddObserver("EndInteractionEvent", self._guard(self._end_drag))

    def _build_lobe(self) -> None:
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkRenderingCore import vtkActor2D, vtkPolyDataMapper2D

        x0, y0, side = G.LOBE_BOX
        self._lobe_polys = {}
        ren = self.plotter.renderer
        for key, color, width in (
            ("frame", G.LOBE_FRAME_COLOR, 1.0),
            ("reference", G.LOBE_REFERENCE_COLOR, 1.0),
            ("lobe", G.LOBE_COLOR, 2.0),
        ):
            poly = vtkPolyData()
            poly.SetPoints(vtkPoints())
            poly.SetLines(vtkCellArray())
            mapper = vtkPolyDataMapper2D()
            mapper.SetInputData(poly)
            actor = vtkActor2D()
            actor.SetMapper(mapper)
            actor.GetProperty().SetColor(*color)
            actor.GetProperty().SetLineWidth(width)
            ren.AddViewProp(actor)
            self._lobe_polys[key] = poly
        pad = 8
        frame = [(x0, y0), (x0 + side, y0), (x0 + side, y0 + side), (x0, y0 + side), (x0, y0)]
        axes = [(x0 + pad, y0 + side / 2), (x0 + side - pad, y0 + side / 2)]
        self._set_lines(self._lobe_polys["frame"], [frame, axes])
        self._lobe_n = None  # the exponent the lobe is drawn for
        self._set_lines(self._lobe_polys["reference"], [self._lobe_points(1.0)])

    @staticmethod
    def _lobe_points(n: float) -> np.ndarray:
        x0, y0, side = G.LOBE_BOX
        pad = 8
        p = lobe_curve(n)
        scale = side - 2 * pad
        return np.column_stack([x0 + pad + p[:, 0] * scale, y0 + side / 2 + p[:, 1] * scale])

    @staticmethod
    def _set_lines(poly, polylines) -> None:
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray

        pts = vtkPoints()
        cells = vtkCellArray()
        for line in polylines:
            ids = []
            for x, y in line:
                ids.append(pts.InsertNextPoint(float(x), float(y), 0.0))
            cells.InsertNextCell(len(ids), ids)
        poly.SetPoints(pts)
        poly.SetLines(cells)
        poly.Modified()

    def _build_texts(self) -> None:
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkTextActor

        ren = self.plotter.renderer
        self.texts = {}

        def text(name, x, y, *, normalized=True, size=G.FONT_SIZE, bold=False):
            t = vtkTextActor()
            if normalized:
                t.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
            t.SetPosition(x, y)
            prop = t.GetTextProperty()
            prop.SetFontSize(size)
            prop.SetColor(*G.TEXT_COLOR)
            prop.SetFontFamilyToArial()
            prop.SetBold(bold)
            ren.AddViewProp(t)
            self.texts[name] = t
            return t

        for name, (x, y) in G.TEXT.items():
            text(name, x, y, bold=name.startswith("heading"))
        self.texts["heading_material"].SetInput("material")
        self.texts["heading_light"].SetInput("light")
        self.texts["heading_mesh"].SetInput("mesh")
        self.texts["hint"].SetInput("press h for help")
        for name, label in G.BUTTON_LABELS.items():
            x, y = G.BUTTONS[name]
            if name in G.PUSH_BUTTONS:  # the arrow inside the button
                t = text(f"label_{name}", x + 0.004, y + 0.002)
                t.GetTextProperty().SetColor(*G.PANEL_COLOR)
                t.GetTextProperty().SetBold(True)
            else:
                t = text(f"label_{name}", x + G.LABEL_GAP, y + 0.002)
            t.SetInput(label)
        x0, y0, side = G.LOBE_BOX
        text("lobe", x0, y0 + side + 6, normalized=False)
        h = text("help", 0.02, 0.93, size=G.HELP_FONT_SIZE)
        h.SetInput(help_text())
        prop = h.GetTextProperty()
        prop.SetVerticalJustificationToTop()
        prop.SetFontFamilyToCourier()
        prop.SetBackgroundColor(0.0, 0.0, 0.0)
        prop.SetBackgroundOpacity(0.75)
        h.SetVisibility(False)
        for name in ("difference", "advice"):  # shown with the difference view
            self.texts[name].SetVisibility(False)
            self.texts[name].GetTextProperty().SetBackgroundColor(0.0, 0.0, 0.0)
            self.texts[name].GetTextProperty().SetBackgroundOpacity(0.6)

    def _frame_camera(self) -> None:
        """The camera at the scene's viewer, the mesh framed in the area left of the panel."""
        from dataclasses import replace

        w, h = self.plotter.window_size
        aspect = G.PANEL_X * w / h
        cam = camera_for(self.scene, self.mesh, aspect)
        if self.light is not None:  # widen the view to show the light's handle, if near
            az, el, d = self._placement()
            if d <= HANDLE_FRAMING * self.radius:
                handle = self.centre + d * direction_of(az, el)
                r = G.HANDLE_RADIUS * self.radius
                cam = widen_to_show(cam, [handle], aspect, pad=r)
        # the picture moved left by half the panel's width, without turning the camera
        set_camera(self.plotter, replace(cam, window_center=(1.0 - G.PANEL_X, 0.0)))
        self.plotter.renderer.ResetCameraClippingRange()

    def _observe(self) -> None:
        pl = self.plotter
        ren = pl.renderer
        ren.AddObserver("StartEvent", self._guard(self._before_frame))
        pl.render_window.AddObserver("EndEvent", self._guard(self._after_frame))
        pl.render_window.AddObserver("WindowResizeEvent", self._guard(self._place_buttons))
        style = pl.iren.interactor.GetInteractorStyle()
        if style is not None:
            style.AddObserver("StartInteractionEvent", self._guard(self._begin_drag))
            style.AddObserver("EndInteractionEvent", self._guard(self._end_drag))
        # our keys only: PyVista's 'b' (box picking) off, and VTK's own meaning of these
        # characters (r: reset camera, s: surface, p: pick, m: animate, 3: stereo...) blocked
        pl.clear_events_for_key("b")
        actions = {
            "h": self.toggle_help,
            "n": lambda: self.next_preset(1),
            "p": lambda: self.next_preset(-1),
            "m": lambda: self.next_mesh(1),
            "M": lambda: self.next_mesh(-1),
            "b": self.toggle_model,
            "t": self.next_light_type,
            "l": self.next_light,
            "1": lambda: self.toggle_term("ambient"),
            "2": lambda: self.toggle_term("diffuse"),
            "3": lambda: self.toggle_term("specular"),
            "d": self.toggle_difference,
            "s": self.save_preset,
            "i": self.screenshot,
            "r": self.reset,
        }
        for key, fn in actions.items():
            guarded = self._guard(fn, name=f"key {key}", renders_after=False)
            pl.add_key_event(key, lambda g=guarded: g())
        iren = pl.iren.interactor
        blocked = set(actions)

        def block(obj, _event):
            if obj.GetKeySym() in blocked:
                obj.GetCommand(self._char_tag).SetAbortFlag(1)

        self._char_tag = iren.AddObserver("CharEvent", block, 10.0)
        iren.AddObserver("TimerEvent", self._guard(self._on_timer, renders_after=False))

    def _list_presets(self) -> list:

        notices: list[str] = []
        presets = list_presets(self.materials_dirs, notices=notices)
        for text in notices:
            log.warning("%s", text)
        return presets

    # -- error handling --------------------------------------------------------------------
    def _guard(self, fn, *bound, name: str | None = None, renders_after: bool = True):
        """``fn`` made safe for VTK: any exception is logged and shown in the window's message
        line (never lost in VTK's or PyVista's callback machinery).

        renders_after : VTK draws a frame right after this callback (widgets after their
            events, the camera style after an interaction, and callbacks inside a frame), so
            ``fn``'s own :meth:`render` calls are left to it: one frame per event, not two.
            Key callbacks render themselves.
        """
        label = name or getattr(fn, "__name__", "callback").lstrip("_")
        if bound:
            label = f"{label} {bound[0]}"

        def call(*args):
            outer = self._deferred
            self._deferred = renders_after
            try:
                return fn(*bound, *args)
            except Exception as exc:  # noqa: BLE001 - every error is shown, none is lost
                self._report(exc, label)
                return None
            finally:
                self._deferred = outer

        return call

    def _report(self, exc: BaseException, where: str) -> None:
        if isinstance(exc, ExplorerError):
            text = str(exc)
            log.error("%s: %s", where, text)
        else:
            text = f"{type(exc).__name__}: {exc}"
            log.error("%s failed", where, exc_info=exc)
        first = text.splitlines()[0] if text else type(exc).__name__
        self.errors.append(f"{where}: {text}")
        self._say(f"error ({where}): {first}", error=True)
        try:
            self.render()
        except Exception:  # noqa: BLE001 - the error is already logged and recorded
            log.exception("render after an error failed")

    def _say(self, text: str, *, error: bool = False) -> None:
        self.message = text
        t = self.texts.get("message") if hasattr(self, "texts") else None
        if t is not None:
            t.SetInput(text)
            t.GetTextProperty().SetColor(*(G.ERROR_COLOR if error else G.TEXT_COLOR))

    # -- state -----------------------------------------------------------------------------
    @property
    def mesh(self) -> Mesh:
        return self._views[0].mesh

    @property
    def centre(self) -> np.ndarray:
        """(3,) centre of the mesh's bounding box (computed once per mesh)."""
        return self._views[0].centre

    @property
    def radius(self) -> float:
        """The mesh's bounding radius about :attr:`centre` (1 for a single point)."""
        return self._views[0].radius

    @property
    def shader(self):
        """The full mesh's Shader."""
        return self._views[0].shader

    @property
    def active_view(self) -> _View:
        return self._views[1] if self._lod_active else self._views[0]

    @property
    def light(self):
        lights = self.scene.lights
        return lights[self.light_index] if lights else None

    @property
    def preset_index(self) -> int | None:
        names = [p.name for p in self.presets]
        return names.index(self.preset_name) if self.preset_name in names else None

    def shown_scene(self) -> Scene:
        """The scene the engine shades: the state's, with hidden terms zeroed."""
        return self.scene.replace(material=display_material(self.scene.material, self.terms))

    def displayed_colors(self) -> np.ndarray:
        """(n, 3) uint8 colours VTK draws for the full mesh (a copy)."""
        return np.array(self._views[0].rgb)

    # -- the update path -------------------------------------------------------------------
    def _push_scene(self, *, render: bool = True) -> None:
        """Give the shown scene to every view's Shader (each recomputes only what changed,
        lazily) and upload the drawn view's colours."""
        if self._building:
            return
        shown = self.shown_scene()
        for v in self._views:
            v.shader.set_scene(shown)
        opacity = self.scene.material.opacity
        for v in self._views:
            v.actor.GetProperty().SetOpacity(opacity)
        self.active_view.upload()
        self._update_lobe()
        self._update_preset_text()
        if render:
            self.render()

    def _refresh(self) -> None:
        """After a change of state: the engine, every control, and a frame."""
        self._push_scene(render=False)
        self._sync_controls()
        self.render()

    def render(self) -> None:
        """Draw a frame now (works before and during the event loop, on- and off-screen);
        inside a widget callback the widget draws it right after."""
        if self._deferred:
            return
        if self._t0 is None:
            self._t0 = time.perf_counter()
        self._update_difference()
        self.plotter.render_window.Render()

    def _before_frame(self, *_) -> None:
        """Renderer StartEvent: the camera is the viewer; also keep translucent triangles
        sorted back to front for the camera."""
        if self._building:
            return
        if self._t0 is None:
            self._t0 = time.perf_counter()
        self._sync_viewer()
        view = self.active_view
        if self.scene.material.opacity < 1.0:
            self._sort(view)
        self._show_difference()
        self._update_status()
        # the handle may be nearer the camera than the mesh: keep it inside the clipping range
        self.plotter.renderer.ResetCameraClippingRange()

    def _sync_viewer(self) -> None:
        """The camera is the viewer: a moved camera moves the highlights."""
        c = self.plotter.camera
        viewer = viewer_of_camera(c.GetPosition(), c.GetFocalPoint(), c.GetParallelProjection())
        if viewer != self.scene.viewer:
            self.scene = self.scene.replace(viewer=viewer)
            shown = self.shown_scene()
            for v in self._views:
                v.shader.set_viewer(shown.viewer)
            self.active_view.upload()

    def _sort(self, view: _View) -> None:
        """Draw the view's triangles back to front for the camera (translucency)."""
        camera = camera_from_vtk(self.plotter.camera)
        key = (camera.position, camera.focal_point, camera.parallel)  # what the order depends on
        if view.sorted_for == key:
            return
        view.poly.faces = cells(view.mesh.faces[back_to_front(view.mesh, camera)])
        view.sorted_for = key

    def _after_frame(self, *_) -> None:
        """Render window EndEvent: count the frame, time it, and write the state file (after
        the frame, so a reader of the file never races the pixels)."""
        self.frames += 1
        if self._t0 is not None:
            self.frame_ms = 1000.0 * (time.perf_counter() - self._t0)
            self._t0 = None
        if self._diff_pending and self._on_screen and self._diff_timer is None:
            # a widget or the camera drew this frame: compare once the event loop is free
            self._diff_timer = self.plotter.iren.interactor.CreateOneShotTimer(20)
        if self.state_file is not None:
            self.write_state()

    # -- level of detail -------------------------------------------------------------------
    @property
    def _lod_active(self) -> bool:
        return self._dragging > 0 and len(self._views) > 1

    def _begin_drag(self, *_) -> None:
        self._dragging += 1
        if self._dragging == 1 and len(self._views) > 1:
            self._views[0].show(False)
            self._views[1].show(True)
            self._views[1].upload()

    def _end_drag(self, *_) -> None:
        self._dragging = max(0, self._dragging - 1)
        if self._dragging == 0 and len(self._views) > 1:
            self._views[1].show(False)
            self._views[0].show(True)
            self._t0 = time.perf_counter()
            self._views[0].upload()
            self.render()

    # -- mesh ------------------------------------------------------------------------------
    def _set_mesh(self, mesh: Mesh) -> None:
        for v in self._views:
            self.plotter.remove_actor(v.actor)
        shown = self.shown_scene()
        self._views = [_View(self.plotter, mesh, shown)]
        if mesh.n_vertices > self.lod_vertices:
            if mesh.name not in self._lods or self._meshes.get(mesh.name) is not mesh:
                self._lods[mesh.name] = lod_mesh(mesh, self.lod_target)
            lod = _View(self.plotter, self._lods[mesh.name], shown)
            lod.show(False)
            self._views.append(lod)
        self._meshes[mesh.name] = mesh

    def set_mesh(self, name: str) -> None:
        """Show another mesh (a built-in name or the file given at the start)."""

        mesh = self._meshes.get(name)
        if mesh is None:
            mesh = get_mesh(name, self.mesh_choices.get(name))
        old_centre, old_radius = self.centre, self.radius
        self._set_mesh(mesh)
        # keep each light where it is relative to the mesh, scaled to the new mesh's size
        lights = []
        for light in self.scene.lights:
            az, el, d = light.placement(old_centre)
            d = (d or 0.0) * self.radius / old_radius
            lights.append(light.placed(az, el, d, self.centre))
        spec = self._mesh_specs.get(name, name)
        self.scene = self.scene.replace(lights=tuple(lights), mesh=spec)
        self.handle.SetRadius(G.HANDLE_RADIUS * self.radius)
        self._frame_camera()
        self._reset_distance_range()
        self._refresh()

    def next_mesh(self, step: int = 1) -> None:
        names = list(self.mesh_choices)
        i = names.index(self.mesh.name) if self.mesh.name in names else -1
        self.set_mesh(names[(i + step) % len(names)])

    # -- material --------------------------------------------------------------------------
    def set_material(self, material: Material, *, preset: str | None = None) -> None:
        self.scene = self.scene.replace(material=material)
        if preset is not None:
            self.preset_name = preset
        self._refresh()

    def set_preset(self, name: str) -> None:
        """Show preset ``name`` (and its specular model, when it has one)."""
        info = next((p for p in self.presets if p.name == name), None)
        if info is None:
            raise ExplorerError(f"no preset named {name!r} in the chooser")
        if info.material.model is not None:
            self.scene = self.scene.replace(model=info.material.model)
        self.set_material(info.material, preset=name)

    def next_preset(self, step: int = 1) -> None:
        if not self.presets:
            raise ExplorerError("no presets found")
        i = self.preset_index
        if i is None:
            i = -1 if step > 0 else 0
        self.set_preset(self.presets[(i + step) % len(self.presets)].name)

    def set_model(self, model: str) -> None:
        self.scene = self.scene.replace(model=model)
        self._refresh()

    def toggle_model(self) -> None:
        self.set_model("phong" if self.scene.model == "blinn" else "blinn")

    def set_term(self, term: str, on: bool) -> None:
        if term not in TERMS:
            raise ExplorerError(f"term must be one of {TERMS}, got {term!r}")
        self.terms[term] = bool(on)
        self._refresh()

    def toggle_term(self, term: str) -> None:
        self.set_term(term, not self.terms[term])

    # -- the difference view (see explorer.app.difference) ---------------------------------
    def set_difference(self, on: bool) -> None:
        """Show the per-pixel difference of the view as a heat map, and the mesh advice."""
        self._set_difference_on(on)
        self._refresh()

    def toggle_difference(self) -> None:
        self.set_difference(not self.difference.on)

    def _set_difference_on(self, on: bool) -> None:
        self.difference.on = bool(on)
        for name in ("difference", "advice"):
            self.texts[name].SetVisibility(self.difference.on)
        if not self.difference.on:
            self.difference.show(False)
            self.active_view.show(True)
            self._diff_pending = False

    def _difference_key(self) -> tuple:
        """What the heat map depends on: the shown scene (camera included, as the viewer), the
        mesh, the camera and the window's size."""
        return (
            repr(self.shown_scene()),
            self.mesh.name,
            self.mesh.n_vertices,
            self._view_camera(),
            tuple(self.plotter.window_size),
        )

    def _update_difference(self) -> None:
        """Compare the view now if the difference view is on, nothing is being dragged and
        the shown map is stale (called before a frame the app draws itself)."""
        d = self.difference
        if not d.on or self._dragging:
            return
        self._sync_viewer()
        key = self._difference_key()
        if not d.stale(key):
            return

        t = time.perf_counter()
        scene = self.shown_scene()
        try:
            d.compute(
                scene,
                self.mesh,
                self._views[0].colors(),
                self._view_camera(),
                self.plotter.window_size,
                key,
                self.plotter.renderer.GetBackground(),
            )
            w, h = self.plotter.window_size
            view_size = (max(1, round(G.PANEL_X * w)), h)  # the view, left of the panel
            self.advice = A.advice(scene.material.shininess, view_size, model=scene.model)
        except Exception:
            self._set_difference_on(False)
            raise
        self.difference_ms = 1000.0 * (time.perf_counter() - t)
        self.texts["advice"].SetInput(advice_lines(self.advice))
        self._diff_pending = False

    def _view_camera(self) -> Camera:
        """The window's camera, with a clipping range around the mesh (the window's own range
        follows what is visible, and the mesh is hidden while the heat map shows): what the
        difference view compares."""
        import dataclasses

        cam = camera_from_vtk(self.plotter.camera)
        pos, focal = np.asarray(cam.position, float), np.asarray(cam.focal_point, float)
        ahead = (focal - pos) / max(float(np.linalg.norm(focal - pos)), 1e-300)
        d = float((self.centre - pos) @ ahead)
        r = 1.01 * self.radius
        return dataclasses.replace(cam, clipping_range=(max(d - r, 1e-3 * r), max(d + r, 2e-3 * r)))

    def _show_difference(self) -> None:
        """Before a frame: the heat map if it matches the view, else the live view."""
        d = self.difference
        if not d.on:
            return
        live = self._dragging > 0 or d.stale(self._difference_key())
        d.show(not live)
        self.active_view.show(live)
        self.texts["difference"].SetInput(PENDING if live else d.legend())
        self._diff_pending = live and self._dragging == 0

    def _on_timer(self, *_) -> None:
        # (VTK's X interactor does not say which timer fired: any timer may do this)
        if self._diff_timer is not None:
            self._diff_timer = None
            self.render()

    # -- lights ----------------------------------------------------------------------------
    def _placement(self) -> tuple[float, float, float]:
        """The controlled light's placement; a directional light's distance is the distance
        slider's (it only places the handle)."""
        az, el, d = self.light.placement(self.centre)
        if d is None:
            d = self.sliders["distance"].GetRepresentation().GetValue()
        return az, el, d

    def _set_light(self, light) -> None:
        lights = list(self.scene.lights)
        lights[self.light_index] = light
        self.scene = self.scene.replace(lights=tuple(lights))
        self._push_scene(render=False)

    def place_light(self, azimuth=None, elevation=None, distance=None) -> None:
        """Move the controlled light (values not given are kept)."""
        if self.light is None:
            raise ExplorerError("the scene has no lights to move")
        az, el, d = self._placement()
        az = az if azimuth is None else float(azimuth)
        el = el if elevation is None else float(elevation)
        d = d if distance is None else float(distance)
        self._set_light(self.light.placed(az, el, d, self.centre))
        self._sync_controls(placement=(az, el, d))
        self.render()

    def set_light_type(self, kind: str) -> None:
        if self.light is None:
            raise ExplorerError("the scene has no lights to change")
        az, el, d = self._placement()
        self._set_light(self.light.as_type(kind).placed(az, el, d, self.centre))
        self._sync_controls(placement=(az, el, d))
        self.render()

    def next_light_type(self) -> None:
        kinds = G.RADIO_GROUPS["light_type"]
        if self.light is not None:
            self.set_light_type(kinds[(kinds.index(self.light.type) + 1) % len(kinds)])

    def next_light(self) -> None:
        if len(self.scene.lights) > 1:
            self.light_index = (self.light_index + 1) % len(self.scene.lights)
            self._reset_distance_range()
            self._sync_controls()
            self.render()

    def _reset_distance_range(self) -> None:
        lo, hi = self._slider_range("distance")
        rep = self.sliders["distance"].GetRepresentation()
        rep.SetMinimumValue(lo)
        rep.SetMaximumValue(hi)

    # -- actions ---------------------------------------------------------------------------
    def save_preset(self) -> Path:
        """Save the material (with the current specular model) as a new preset in the user's
        preset directory: ``<preset>_1``, ``<preset>_2``..., never over an existing file."""

        directory = Path(self.preset_dir) if self.preset_dir else user_dir()
        stem = (self.preset_name or "material")[: MAX_NAME_LENGTH - 8]  # room for "_<k>"
        taken = {p.name for p in self.presets}
        if directory.is_dir():
            taken |= {p.stem for p in directory.glob("*.yaml")}
        name = free_name(stem, taken)
        material = self.scene.material.replace(
            model=self.scene.model,
            description=f"{stem} as edited in phong-explorer",
        )
        path = save_preset(material, name, directory)
        self.presets = self._list_presets()
        self.last_saved = str(path)
        self.preset_name = name if any(p.name == name for p in self.presets) else None
        self._say(f"saved preset '{name}' to {path}")
        self._sync_controls()
        self.render()
        return path

    def screenshot(self) -> Path:
        """Save the window as a PNG in the output directory (a new file every time)."""

        self.render()
        img = self.plotter.screenshot(return_img=True)
        stem = f"phong-explorer-{self.preset_name or 'material'}-{self.mesh.name}"
        stem = "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in stem)
        taken = {p.stem for p in self.output_dir.glob(f"{stem}_*.png")}
        path = self.output_dir / f"{free_name(stem, taken)}.png"
        write_atomic(path, encode_png(np.ascontiguousarray(img[:, :, :3])))
        self.last_screenshot = str(path)
        self._say(f"saved screenshot {path}")
        self.render()
        return path

    def reset(self) -> None:
        """Back to the start: scene, mesh, preset, terms, light, camera."""
        scene, mesh_name, preset, camera = self._start
        self.terms = {t: True for t in TERMS}
        self._set_difference_on(False)
        self.light_index = 0
        self.preset_name = preset
        if mesh_name != self.mesh.name:
            self._set_mesh(self._meshes[mesh_name])
            self.handle.SetRadius(G.HANDLE_RADIUS * self.radius)
        self.scene = scene
        apply_camera(self.plotter.camera, camera)
        self._reset_distance_range()
        self._say("reset to the start")
        self._refresh()

    def toggle_help(self) -> None:
        self.help_visible = not self.help_visible
        self.texts["help"].SetVisibility(self.help_visible)
        self.render()

    # -- widget callbacks ------------------------------------------------------------------
    def _on_slider(self, name: str, value: float, widget=None) -> None:
        if self._building:
            return
        if self._t0 is None:
            self._t0 = time.perf_counter()
        if name in ("ka", "kd", "ks"):
            k = slider_to_coefficient(value)
            self.scene = self.scene.replace(material=self.scene.material.with_scalars(**{name: k}))
            self._push_scene()
        elif name == "shininess":
            n = slider_to_shininess(value)
            self.scene = self.scene.replace(material=self.scene.material.replace(shininess=n))
            self._show_shininess()
            self._push_scene()
        else:
            self.place_light(**{name: value})

    def _on_button(self, name: str, state: bool) -> None:
        if self._building:
            return
        if name in G.PUSH_BUTTONS:
            self.buttons[name].GetRepresentation().SetState(0)
            {
                "preset_previous": lambda: self.next_preset(-1),
                "preset_next": lambda: self.next_preset(1),
                "mesh_previous": lambda: self.next_mesh(-1),
                "mesh_next": lambda: self.next_mesh(1),
            }[name]()
        elif name in G.RADIO_GROUPS["model"]:
            self.set_model(name)
        elif name in G.RADIO_GROUPS["light_type"]:
            self.set_light_type(name)
        elif name in TERMS:
            self.set_term(name, state)
        elif name == "difference":
            self.set_difference(bool(state))

    def _on_handle(self, center) -> None:
        if self._building or self.light is None:
            return
        if self._t0 is None:
            self._t0 = time.perf_counter()
        az, el, d = angles_of(np.subtract(center, self.centre))
        if d == 0.0:
            return
        lo, hi = self._slider_range("distance")
        self.place_light(az, el, min(max(d, lo), hi))

    # -- showing the state in the controls -----------------------------------------------------
    def _show_shininess(self) -> None:
        """The shininess slider's title: the material's real exponent."""
        n = self.scene.material.shininess
        self.sliders["shininess"].GetRepresentation().SetTitleText(f"shininess {n:g}")

    def _sync_controls(self, *, placement=None) -> None:
        """Sliders, buttons, handle and texts from the state (no widget events fire)."""
        m = self.scene.material
        ka, kd, ks = m.scalars()
        values = {"ka": ka, "kd": kd, "ks": ks, "shininess": shininess_to_slider(m.shininess)}
        sliders = self.sliders
        self._show_shininess()
        light = self.light
        if light is not None:
            az, el, d = placement if placement is not None else self._placement()
            values.update(azimuth=az, elevation=el, distance=d)
            self.handle.SetCenter(*(self.centre + d * direction_of(az, el)))
            self.handle.On()
            kind = light.type
            word, where = light.anchor
            where = f"{word} {_fmt_vec(where)}"
            n = len(self.scene.lights)
            which = f"{self.light_index + 1} of {n}: " if n > 1 else ""
            self.texts["light"].SetInput(f"{which}{kind} {where}")
        else:
            self.handle.Off()
            self.texts["light"].SetInput("the scene has no lights")
        for name, v in values.items():
            sliders[name].GetRepresentation().SetValue(v)
        states = {
            "blinn": self.scene.model == "blinn",
            "phong": self.scene.model == "phong",
            **{t: self.terms[t] for t in TERMS},
            "difference": self.difference.on,
            **{k: light is not None and light.type == k for k in G.RADIO_GROUPS["light_type"]},
        }
        for name, on in states.items():
            self.buttons[name].GetRepresentation().SetState(int(on))
        self._update_preset_text()
        self.texts["mesh"].SetInput(f"{self.mesh.name}, {self.mesh.n_vertices:,} vertices")

    def _update_preset_text(self) -> None:
        """The preset's name and place in the chooser; ``*`` once the material is edited."""
        i = self.preset_index
        if i is None:
            self.texts["preset"].SetInput(self.preset_name or "(scene material)")
            return
        edited = "*" if self.scene.material != self.presets[i].material else ""
        self.texts["preset"].SetInput(f"{self.preset_name}{edited} ({i + 1}/{len(self.presets)})")

    def _update_lobe(self) -> None:
        n = self.scene.material.shininess
        if n == self._lobe_n:
            return
        self._lobe_n = n
        self._set_lines(self._lobe_polys["lobe"], [self._lobe_points(n)])
        self.texts["lobe"].SetInput(f"specular lobe cos^n t, n = {n:g}")

    def _update_status(self) -> None:
        light = self.light
        parts = [
            self.preset_name or "(scene material)",
            f"{self.mesh.name} ({self.mesh.n_vertices:,} vertices)",
            self.scene.model,
            f"{len(self.scene.lights)} light(s)" if light is None else f"{light.type} light",
        ]
        hidden = [t for t in TERMS if not self.terms[t]]
        if hidden:
            parts.append("hidden: " + ", ".join(hidden))
        if math.isfinite(self.frame_ms):
            parts.append(f"last frame {self.frame_ms:.0f} ms")
        self.texts["status"].SetInput(";  ".join(parts))

    # -- reporting -------------------------------------------------------------------------
    def _to_window_pixels(self, x: float, y: float) -> list[int]:
        """Display coordinates (origin bottom-left) as window pixels (origin top-left)."""
        _, h = self.plotter.window_size
        return [int(round(x)), int(round(h - 1 - y))]

    def _world_to_window(self, point) -> list[int]:
        ren = self.plotter.renderer
        ren.SetWorldPoint(*point, 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        return self._to_window_pixels(x, y)

    def slider_pixels(self, name: str, value: float) -> list[int]:
        """Window pixel (origin top-left) where slider ``name``'s knob sits at ``value``."""
        w, h = self.plotter.window_size
        rep = self.sliders[name].GetRepresentation()
        x1 = G.SLIDER_X[0] * w
        x2 = G.SLIDER_X[1] * w
        inset = (rep.GetEndCapLength() + rep.GetSliderLength() / 2.0) * w
        lo, hi = rep.GetMinimumValue(), rep.GetMaximumValue()
        t = (value - lo) / (hi - lo) if hi > lo else 0.0
        x = x1 + inset + t * (x2 - x1 - 2.0 * inset)
        return self._to_window_pixels(x, G.SLIDER_Y[name] * h)

    def probe_vertex(self) -> int:
        """Index of the full mesh's vertex that faces the camera most (on a convex mesh it is
        visible): the window test reads its pixel."""
        mesh = self.mesh
        c = self.plotter.camera
        if c.GetParallelProjection():
            v = np.subtract(c.GetPosition(), c.GetFocalPoint())[None, :]
        else:
            v = np.asarray(c.GetPosition()) - mesh.positions
        v = v / np.linalg.norm(v, axis=1, keepdims=True)
        return int(np.argmax(np.einsum("ij,ij->i", mesh.normals, v)))

    def state(self) -> dict:
        """Everything a test or a script may want to know, as plain JSON values."""
        w, h = self.plotter.window_size
        m = self.scene.material
        ka, kd, ks = m.scalars()
        sliders = {}
        for name, wdg in self.sliders.items():
            rep = wdg.GetRepresentation()
            value = rep.GetValue()
            lo, hi = rep.GetMinimumValue(), rep.GetMaximumValue()
            sliders[name] = {
                "value": value,
                "title": rep.GetTitleText(),
                "range": [lo, hi],
                "knob_px": self.slider_pixels(name, value),
                "ends_px": [self.slider_pixels(name, lo), self.slider_pixels(name, hi)],
            }
        buttons = {}
        s = G.BUTTON_SIZE
        for name, (x, y) in G.BUTTONS.items():
            buttons[name] = {
                "state": bool(self.buttons[name].GetRepresentation().GetState()),
                "px": self._to_window_pixels(round(x * w) + s / 2, round(y * h) + s / 2),
            }
        light = self.light
        placement = None
        if light is not None:
            az, el, d = self._placement()
            placement = {"azimuth": az, "elevation": el, "distance": d}
        probe = self.probe_vertex()
        c = self.plotter.camera
        return {
            "frame": self.frames,
            "frame_ms": self.frame_ms if math.isfinite(self.frame_ms) else None,
            "window_size": [w, h],
            "preset": self.preset_name,
            "presets": [p.name for p in self.presets],
            "mesh": self.mesh.name,
            "n_vertices": self.mesh.n_vertices,
            "dragging": self._dragging > 0,
            "lod": self._lod_active,
            "scene": self.scene.to_mapping(),
            "material": {"ka": ka, "kd": kd, "ks": ks, "shininess": m.shininess},
            "terms": dict(self.terms),
            "light_index": self.light_index,
            "light": placement,
            "handle_px": self._world_to_window(self.handle.GetCenter()),
            "sliders": sliders,
            "buttons": buttons,
            "camera": {
                "position": list(c.GetPosition()),
                "focal_point": list(c.GetFocalPoint()),
                "parallel": bool(c.GetParallelProjection()),
            },
            "probe": {"vertex": probe, "px": self._world_to_window(self.mesh.positions[probe])},
            "help_visible": self.help_visible,
            "difference": {
                **self.difference.state(),
                "ms": self.difference_ms if math.isfinite(self.difference_ms) else None,
                "advice": self.advice,
            },
            "message": self.message,
            "errors": list(self.errors),
            "last_saved": self.last_saved,
            "last_screenshot": self.last_screenshot,
        }

    def write_state(self) -> None:

        data = json.dumps(self.state(), indent=1).encode()
        write_atomic(self.state_file, data, overwrite=True)

    # -- running ---------------------------------------------------------------------------
    def show(self, exit_after: float | None = None) -> None:
        """Open the window and run the event loop until the user quits (key q), or until
        ``exit_after`` seconds have passed (a safety net for scripts and tests)."""
        pl = self.plotter
        if exit_after is not None:
            iren = pl.iren.interactor

            started = time.monotonic()

            def expire(*_):
                # every timer's event comes here (the difference view has one too), and VTK's X
                # interactor does not say which timer fired: go by the time
                if time.monotonic() - started < float(exit_after) - 0.01:
                    return
                log.warning("closing after %g s (--exit-after)", exit_after)
                pl.iren.terminate_app()

            iren.AddObserver("TimerEvent", expire)
            pl.iren.initialize()
            iren.CreateOneShotTimer(max(1, int(float(exit_after) * 1000)))
        pl.show(auto_close=True)

    def close(self) -> None:
        self.difference.close()
        self.plotter.close()


def _fmt_vec(v) -> str:
    return "(" + ", ".join(f"{c:.2f}" for c in v) + ")"


def _window_problem(render_window) -> str | None:
    """Why ``render_window`` is no on-screen window (VTK fell back to off-screen), or None."""
    import sys

    if sys.platform.startswith("linux") and render_window.GetClassName() != (
        "vtkXOpenGLRenderWindow"
    ):
        return f"VTK opened a {render_window.GetClassName()}, which cannot show a window"
    return None
