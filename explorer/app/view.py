"""The explorer's 3D view: the engine's colours on the mesh, the light's handle, the specular
lobe inset and the difference heat map, drawn by VTK into a PyVista plotter (pyvistaqt's
``QtInteractor`` in the window, an off-screen ``Plotter`` in benchmarks). No Qt here.

Every state goes the same way::

    state.shown_scene() -> Shader.set_scene (the engine recomputes only what changed)
                        -> uint8 colours written in place into the mesh's point data -> render

Scale: VTK is handed the mesh, the handles, the glyph and the camera in the view's frame
(:func:`view_frame`: the mesh's centre at the origin, lengths in units of the power of two
nearest its radius), as the off-screen renderers do (:func:`explorer.render.camera.in_frame`),
so that a mesh of size 1e-20 or 1e300 is drawn as a unit one (VTK draws in float32). Everything
outside this module speaks world coordinates: :func:`view_camera` reads the camera back out of
the frame, :meth:`SceneView.to_view` and :meth:`SceneView.from_view` convert points.

The colours are drawn as RGB point scalars with VTK's lighting off, so VTK adds nothing to the
engine's colours. Meshes above :data:`LOD_VERTICES` get a lighter level of detail (quadric
clustering to about :data:`LOD_TARGET` vertices, shaded by its own Shader) drawn while something
is dragged; the full mesh is shaded and drawn on release (a mesh with material groups is
clustered group by group, so its level of detail keeps them). A mesh file's own materials
(``State.groups``) are drawn group by group from one Shader's light sums.

PyVista and VTK are imported inside the functions that need them.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from explorer.analysis.comparison import heat_map
from explorer.app.difference import VMAX
from explorer.app.lobeinset import LobeInset
from explorer.app.model import State, handle_point, light_colour
from explorer.app.overlay import overlay, set_lines, set_triangles
from explorer.app.termstrip import TermStrip
from explorer.geometry.meshes import Mesh, area_weighted_normals
from explorer.render.camera import (
    Camera,
    apply_camera,
    back_to_front,
    camera_for,
    camera_from_vtk,
    in_frame,
    mesh_frame,
    out_of_frame,
)
from explorer.render.textured import (
    LAYER_MAPS,
    SECONDARY,
    WHITE,
    Layer,
    Textured,
    add_textured,
    only,
    texture_arrays,
)
from explorer.render.textures import read_texture
from explorer.render.vtk import add_unlit, cells, polydata
from explorer.shading.display import engine_clamps, grouped_colors, shown, to_bytes
from explorer.shading.shader import Shader

#: meshes with more vertices than this get a level of detail drawn while dragging
LOD_VERTICES = 250_000
#: about how many vertices the level of detail has
LOD_TARGET = 60_000
#: the fewest vertices a material group's part of the level of detail is clustered to
LOD_GROUP_MIN = 64
#: the light handles' radius, in mesh radii (the selected light's is SELECTED_SCALE times it)
HANDLE_RADIUS = 0.07
SELECTED_SCALE = 1.3
#: the ring that marks the selected light's handle: its colour and its gap (pixels) around it
RING_COLOR = (1.0, 1.0, 1.0)
RING_GAP = 4
#: the ring's line width (pixels)
RING_WIDTH = 2
#: the selected handle's glyph (the light's GLYPH: an arrow, a cone), in mesh radii
GLYPH_LENGTH = 0.6
GLYPH_COLOR = (1.0, 0.85, 0.2)
#: a handle nearer than this (mesh radii) is kept in view when the camera is framed
HANDLE_FRAMING = 5.5
#: widest view angle (degrees) the framing may use to show the handle, across the view's
#: narrower side (a view taller than wide may open wider upward: its width is what limits)
MAX_VIEW_ANGLE = 60.0
#: the widest vertical view angle (degrees) of any framing (as :func:`camera_for`'s)
MAX_VERTICAL_ANGLE = 150.0
#: pixels kept between the selected handle's ring and the view's edge when the camera is
#: framed to show the handle (the ring's line, 2 pixels wide, included)
RING_MARGIN = 12
#: a handle out of the view is shown by an arrow at the view's edge: its length (pixels), its
#: distance from the edge (pixels), and the outline drawn around it (for contrast)
MARKER_SIZE = 18
MARKER_MARGIN = 6
MARKER_OUTLINE = (0.08, 0.08, 0.08)


def widen_to_show(camera: Camera, points, aspect: float, *, pad: float = 0.0,
                  edge_px: float = 0.0, height_px: float = 0.0) -> Camera:  # fmt: skip
    """``camera`` with its view widened just enough to show ``points`` too, each a sphere of
    radius ``pad`` ringed ``edge_px`` pixels beyond its outline and kept that far inside the
    edge of a picture ``height_px`` pixels tall (0: no pixels, the spheres alone) of
    ``aspect`` (width / height); points behind a perspective camera are left out. Position,
    direction and up are kept (the viewer does not move). The widening stops at
    :data:`MAX_VIEW_ANGLE` across the picture's narrower side.

    The pixels are a margin of the view's own: with ``T`` the tangent of half the vertical
    angle (a parallel camera: its half height), a pixel spans ``2 T / height_px``, and a
    sphere whose centre is seen ``x`` from the view's axis across (in tangents; in world units
    for a parallel camera), ``s`` its apparent radius, is in when ``x + s + edge_px · 2 T /
    height_px <= aspect · T`` (and ``<= T`` upward): ``T`` at least ``(x + s) / (aspect -
    2 edge_px / height_px)``."""
    from dataclasses import replace

    fwd = camera.direction
    up = np.asarray(camera.view_up, dtype=np.float64)
    right = np.cross(fwd, up)
    origin = np.asarray(camera.focal_point if camera.parallel else camera.position)
    px = 2.0 * edge_px / height_px if height_px > 0 else 0.0  # a pixel's tangents, over T
    if px >= min(aspect, 1.0):  # (a view too small for the margin: the spheres alone)
        px = 0.0
    need = 0.0
    for p in points:
        rel = np.asarray(p, dtype=np.float64) - origin
        x, y, z = abs(rel @ right), abs(rel @ up), rel @ fwd
        if camera.parallel:
            s = pad
        elif z > pad:
            x, y, s = x / z, y / z, pad / math.hypot(*rel)  # (hypot: no overflow at 1e300)
        else:
            continue
        need = max(need, (y + s) / (1.0 - px), (x + s) / (aspect - px))
    if camera.parallel:
        return replace(camera, parallel_scale=max(camera.parallel_scale, need))
    widest = math.tan(math.radians(0.5 * MAX_VIEW_ANGLE)) / min(aspect, 1.0)
    angle = min(math.degrees(2.0 * math.atan(min(need, widest))), MAX_VERTICAL_ANGLE)
    return replace(camera, view_angle=max(camera.view_angle, angle))


def view_frame(centre, radius: float) -> tuple[np.ndarray, float]:
    """The frame the view hands VTK its points and camera in, for a mesh of bounding-box
    centre (3,) and radius: ``(centre, scale)``, ``scale`` the power of two nearest the radius
    (exact to divide by; 1 for a radius that is 0 or not finite)."""
    r = float(radius)
    scale = 2.0 ** round(math.log2(r)) if 0.0 < r < math.inf else 1.0
    return np.asarray(centre, np.float64), scale


def view_camera(vtk_camera, centre, radius: float) -> Camera:
    """The view's camera in world coordinates (read out of :func:`view_frame`) with a clipping
    range around the mesh (centre (3,), radius): what the state records and the difference
    view compares (the window's own range follows what is visible, and the mesh is hidden
    while the heat map shows)."""
    cam = camera_from_vtk(vtk_camera, window_center=(0.0, 0.0))
    cam = out_of_frame(cam, *view_frame(centre, radius))
    d = float((np.asarray(centre) - np.asarray(cam.position, float)) @ cam.direction)
    r = 1.01 * radius
    return dataclasses.replace(cam, clipping_range=(max(d - r, 1e-3 * r), max(d + r, 2e-3 * r)))


def framed_camera(state: State, mesh: Mesh, aspect: float, height_px: float = 0.0) -> Camera:
    """The camera at the scene's viewer framing the mesh, widened to show a near handle: the
    selected handle and its ring wholly inside the view, :data:`RING_MARGIN` pixels from its
    edge, in a view ``height_px`` pixels tall (0: the handle alone, unknown pixels)."""
    cam = camera_for(state.scene, mesh, aspect)
    if state.selected_light is not None:
        d = state.placement()[2]
        if d <= HANDLE_FRAMING * state.radius:
            pad = HANDLE_RADIUS * SELECTED_SCALE * state.radius  # (the selected one's)
            edge = RING_GAP + 0.5 * RING_WIDTH + RING_MARGIN  # the ring's outside, and more
            cam = widen_to_show(
                cam, [handle_point(state)], aspect, pad=pad, edge_px=edge, height_px=height_px
            )
    return cam


def lod_mesh(mesh: Mesh, target: int = LOD_TARGET) -> Mesh:
    """A lighter version of ``mesh`` with about ``target`` vertices (VTK quadric clustering),
    with smooth area-weighted normals. Used only while dragging. A mesh with material groups
    (``mesh.groups``) is clustered group by group, each to its share of ``target``, so every
    vertex of the lighter mesh keeps its group (and its colour)."""
    groups = mesh.groups
    if groups is None:
        pos, faces = _clustered(mesh, target)
        return Mesh(pos, area_weighted_normals(pos, faces), faces, f"{mesh.name} (LOD)")
    F = np.asarray(mesh.faces, np.int64)
    of_face = groups.of_vertex[F[:, 0]]  # (a face's corners share their group: see MaterialGroups)
    parts, keys, offset = [], [], 0
    for g in range(len(groups.names)):
        used, inverse = np.unique(F[of_face == g], return_inverse=True)
        if not len(used):
            continue
        part = Mesh(mesh.positions[used], mesh.normals[used], inverse.reshape(-1, 3), mesh.name)
        pos, faces = _clustered(part, max(LOD_GROUP_MIN, target * len(used) // mesh.n_vertices))
        parts.append((pos, faces + offset))
        keys.append(np.full(len(pos), g, np.int32))
        offset += len(pos)
    pos = np.vstack([p for p, _ in parts])
    faces = np.vstack([f for _, f in parts])
    kept = dataclasses.replace(groups, of_vertex=np.concatenate(keys))
    return Mesh(pos, area_weighted_normals(pos, faces), faces, f"{mesh.name} (LOD)", kept)


def _clustered(mesh: Mesh, target: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions (k, 3) float64 and faces (j, 3) int64 of ``mesh`` clustered to about
    ``target`` vertices (see :func:`lod_mesh`)."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkQuadricClustering

    centre, scale = mesh_frame(mesh)  # clustered in the mesh's frame: float32 at any scale
    poly = polydata(mesh, float32=True, normals=False, frame=(centre, scale))

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
        step = 0.5 if count >= 0.8 * mesh.n_vertices else math.sqrt(target / count)
        d = max(4, int(round(d * step)))
        out = cluster(d)
    pos = vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64) * scale + centre
    faces = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).astype(np.int64).reshape(-1, 3)
    return pos, faces


class MeshDrawing:
    """One drawn version of the mesh (the full mesh or its level of detail): its Shader, its
    PolyData (in ``frame``, :func:`view_frame`) and actor, and the uint8 colour array VTK
    draws, written in place."""

    def __init__(self, plotter, mesh: Mesh, scene, frame):
        from vtkmodules.util.numpy_support import vtk_to_numpy

        self.mesh = mesh
        self.shader = Shader(
            scene, mesh.positions, mesh.normals, precision="float32",
            clamp=engine_clamps(scene), faces=mesh.faces,
        )  # fmt: skip
        self.poly = polydata(mesh, np.zeros((mesh.n_vertices, 3), np.uint8), float32=True,
                             normals=False, frame=frame)  # fmt: skip
        self.actor = add_unlit(plotter, self.poly)
        self.vtk_colors = self.poly.GetPointData().GetArray("colors")
        self.rgb = vtk_to_numpy(self.vtk_colors)  # a view of VTK's memory
        self.sorted_for = None  # camera the triangles were last sorted for (translucency)
        self.groups = None  # one material per group of mesh.groups, or None: the scene's
        self._rows = None
        self.texture = None  # (diffuse map, color_control, layer maps...) worn, or None
        self.secondary = None  # the separate specular colour VTK draws (RGBA float32 view)
        self.layers: dict = {}  # term -> the name of its layer's colour array (RGBA float32)

    def set_groups(self, materials) -> None:
        """Draw each group of ``mesh.groups`` in its own material (a tuple, one per group),
        or the whole mesh in the scene's (None)."""
        if materials is not None and self._rows is None:
            g = self.mesh.groups
            self._rows = [g.vertices(i) for i in range(len(g.names))]
        self.groups = materials

    def set_texture(self, plotter, scene) -> None:
        """Wear the drawn materials' one ``diffuse_map`` as ``render`` does
        (:mod:`explorer.render.textured`: GL_MODULATE, the scene's ``color_control``), and
        their ``ambient_map`` and ``emission_map`` as its layers, when the mesh has (u, v);
        else none. The actor is made anew only when a map or the mode changes."""
        materials = self.groups or (scene.material,)

        def one(key):
            maps = {getattr(m, key) for m in materials}
            return maps.pop() if len(maps) == 1 and self.mesh.uv is not None else None

        tmap, layers = one("diffuse_map"), {k: one(k) for k in LAYER_MAPS}
        drawn = tmap is not None or any(t is not None for t in layers.values())
        texture = (tmap, scene.color_control, *layers.values()) if drawn else None
        if texture == self.texture:
            return
        visible = self.actor.GetVisibility()
        plotter.remove_actor(self.actor, render=False)
        self.texture, self.secondary, self.layers = texture, None, {}
        if not drawn:
            self.actor = add_unlit(plotter, self.poly)
        else:
            n = self.mesh.n_vertices
            black = np.zeros((n, 3), np.uint8)
            image = WHITE if tmap is None else read_texture(tmap)
            built = ()
            if any(t is not None for t in layers.values()):
                built = tuple(
                    Layer(k, black, WHITE if t is None else read_texture(t, k), t)
                    for k, t in layers.items()
                )
            t = Textured(self.rgb, black, image, tmap, built, scene.color_control)
            texture_arrays(self.poly, self.mesh, t)
            self.actor = add_textured(plotter, self.poly, t)
            self.secondary = self.poly.point_data[SECONDARY]
            self.layers = {LAYER_MAPS[x.key]: x.name + "_c" for x in built}
        self.actor.SetVisibility(visible)

    def colors(self, change=None) -> np.ndarray:
        """(n, 3) display colours in [0, 1] (:func:`explorer.shading.display.shown`): each
        group in its material when :attr:`groups` is set (the Shader keeps the light sums;
        each material recomposes them); ``change(material)``: each material changed so."""
        if change is None and self.groups is None:
            return shown(self.shader.colors, self.shader.scene)
        own = self.shader.scene.material
        if self.groups is None:
            self.shader.set_material(change(own))
            out = np.array(self.shader.colors)
            self.shader.set_material(own)
            return shown(out, self.shader.scene)
        groups = [change(m) for m in self.groups] if change else self.groups
        return shown(grouped_colors(self.shader, self._rows, groups), self.shader.scene)

    def upload(self) -> None:
        """Write the display colours into VTK's array as 8-bit values and mark it modified
        (under separate specular: the primary colour there, the specular one beside it; with
        layers: the diffuse term there, the specular and each layer's term beside it)."""
        if self.secondary is None or (self.texture[1] != "separate" and not self.layers):
            to_bytes(self.colors(), out=self.rgb)
        else:
            to_bytes(self.colors(only("diffuse" if self.layers else "primary")), out=self.rgb)
            q = self.colors(only("specular"))
            self.secondary[:, :3] = to_bytes(q) / np.float32(255.0)
            self.poly.GetPointData().GetArray(SECONDARY).Modified()
            for term, name in self.layers.items():
                array = self.poly.point_data[name]  # (a view of VTK's memory)
                array[:, :3] = to_bytes(self.colors(only(term))) / np.float32(255.0)
                self.poly.GetPointData().GetArray(name).Modified()
        self.vtk_colors.Modified()

    def sort_for(self, camera: Camera) -> None:
        """Draw the triangles back to front for ``camera`` (translucency)."""
        key = (camera.position, camera.focal_point, camera.parallel)
        if self.sorted_for != key:
            self.poly.faces = cells(self.mesh.faces[back_to_front(self.mesh, camera)])
            self.sorted_for = key

    def show(self, visible: bool) -> None:
        self.actor.SetVisibility(bool(visible))


class SceneView:
    """The mesh, handle, glyph and lobe inset in ``plotter``, showing one :class:`State`.

    plotter : a PyVista plotter (``QtInteractor`` or off-screen); mesh, state : the start
    lod_vertices, lod_target : see :data:`LOD_VERTICES`, :data:`LOD_TARGET`
    side : the compare view's side it shows (``a``, or ``b``: side B's pane), for its strip
    """

    def __init__(self, plotter, mesh: Mesh, state: State, *, lod_vertices: int = LOD_VERTICES,
                 lod_target: int = LOD_TARGET, side: str = "a"):  # fmt: skip
        self.plotter = plotter
        self.lod_vertices = int(lod_vertices)
        self.lod_target = int(lod_target)
        self.state = state
        self.drawings: list[MeshDrawing] = []
        self.dragging = 0
        self._lods: dict[str, Mesh] = {}
        self.handles: list = []
        self._handle_calls = None
        self._ring = None
        self.marker_triangles: dict[int, np.ndarray] = {}
        self._glyph = None
        self._glyph_kind = None
        self._switching = False  # set while the drawings change meshes
        # the full mesh's colours are not seen (the per-pixel picture stands in for the mesh:
        # explorer.app.pixellayer): a change does not upload them; shown again, they are
        self.colors_unseen = False
        self.set_mesh(mesh, state)
        self.lobe = LobeInset(plotter, state)
        self.strip = TermStrip(plotter, side)
        self.strip.show(state, self.active)

    # -- mesh --------------------------------------------------------------------------------
    @property
    def mesh(self) -> Mesh:
        return self.drawings[0].mesh

    @property
    def active(self) -> MeshDrawing:
        return self.drawings[1] if self.lod_active else self.drawings[0]

    @property
    def lod_active(self) -> bool:
        return self.dragging > 0 and len(self.drawings) > 1

    def set_mesh(self, mesh: Mesh, state: State) -> None:
        self._switching = True
        try:
            self._set_mesh(mesh, state)
        finally:
            self._switching = False

    def _set_mesh(self, mesh: Mesh, state: State) -> None:
        for d in self.drawings:
            self.plotter.remove_actor(d.actor, render=False)
        scene = state.shown_scene()
        self.frame = view_frame(state.centre, state.radius)
        self.drawings = [MeshDrawing(self.plotter, mesh, scene, self.frame)]
        if mesh.n_vertices > self.lod_vertices:
            if mesh.name not in self._lods:
                self._lods = {mesh.name: lod_mesh(mesh, self.lod_target)}
            lod = MeshDrawing(self.plotter, self._lods[mesh.name], scene, self.frame)
            lod.show(False)
            self.drawings.append(lod)
        self.state = None  # everything is shown afresh
        self.show_state(state)

    def to_view(self, point) -> np.ndarray:
        """A world point (3,) in the coordinates VTK draws in (:func:`view_frame`)."""
        centre, scale = self.frame
        return (np.asarray(point, np.float64) - centre) / scale

    def from_view(self, point) -> np.ndarray:
        """A point (3,) in VTK's coordinates as a world point (the inverse of :meth:`to_view`)."""
        centre, scale = self.frame
        return np.asarray(point, np.float64) * scale + centre

    # -- state -------------------------------------------------------------------------------
    def show_state(self, state: State) -> None:
        """Give the shown scene to every drawing's Shader (each recomputes only what changed)
        and upload the drawn one's colours; move the handle and its glyph; redraw the lobe."""
        old, self.state = self.state, state
        if (old is None or old.scene != state.scene or old.hidden != state.hidden
                or old.groups != state.groups):  # fmt: skip
            scene = state.shown_scene()
            groups = state.shown_groups()
            for d in self.drawings:
                d.shader.set_scene(scene)
                d.set_groups(groups if d.mesh.groups is not None else None)
                d.set_texture(self.plotter, scene)
                d.actor.GetProperty().SetOpacity(state.material.opacity)
            if not (self.colors_unseen and self.active is self.drawings[0]):
                self.active.upload()
        self._show_handle(state)
        if getattr(self, "lobe", None) is not None:
            self.lobe.update(state)
            self.strip.show(state, self.active)

    def frame_camera(self, state: State, camera_moved) -> None:
        """Before a frame of either front end: the VTK camera read as the viewer's camera
        (``camera_moved(camera)``: the controller puts it in the state, no undo step), then
        :meth:`before_frame` for it, and VTK's clipping range set around what is drawn. A frame
        drawn while the view changes meshes (VTK draws when an actor comes) leaves the camera
        alone: the state shows the new mesh, the drawings and camera the last one."""
        if self._switching:
            return
        cam = view_camera(self.plotter.camera, state.centre, state.radius)
        camera_moved(cam)
        self.before_frame(cam)
        self.plotter.renderer.ResetCameraClippingRange()

    def before_frame(self, camera: Camera) -> None:
        """Before a frame: translucent triangles sorted back to front for the camera, the lobe
        inset sized for the view, the selected handle's ring and the arrows toward handles
        out of the view placed for the camera."""
        if self.state.material.opacity < 1.0:
            self.active.sort_for(camera)
        self.lobe.layout(self.state)
        self.strip.show(self.state, self.active)  # (the drawn mesh: a drag's level of detail)
        self._show_markers()

    def begin_drag(self) -> None:
        self.dragging += 1
        if self.dragging == 1 and len(self.drawings) > 1:
            self.drawings[0].show(False)
            self.drawings[1].show(True)
            self.drawings[1].upload()

    def end_drag(self) -> None:
        self.dragging = max(0, self.dragging - 1)
        if self.dragging == 0 and len(self.drawings) > 1:
            self.drawings[1].show(False)
            self.drawings[0].show(True)
            self.drawings[0].upload()

    def show_mesh(self, visible: bool) -> None:
        """Show the mesh (False while the heat map stands in for it)."""
        for i, d in enumerate(self.drawings):
            d.show(visible and (i == 1) == self.lod_active)

    def displayed_colors(self) -> np.ndarray:
        """(n, 3) uint8 colours VTK draws for the full mesh (a copy); while the per-pixel
        picture stands in for the mesh (:attr:`colors_unseen`), uploaded first (a change did
        not upload them)."""
        if self.colors_unseen:
            self.drawings[0].upload()
        return np.array(self.drawings[0].rgb)

    @property
    def lobe_caption(self):
        """The lobe inset's caption (a ``vtkTextActor``)."""
        return self.lobe.caption

    def set_caption(self, text: str) -> None:
        """A line (or two) at the top left of the view (which side of the compare view it is,
        and Gouraud vs per-pixel's figures)."""
        import vtkmodules.vtkRenderingFreeType  # noqa: F401 - registers the text renderer
        from vtkmodules.vtkRenderingCore import vtkTextActor

        if getattr(self, "caption", None) is None:
            self.caption = vtkTextActor()
            self.caption.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
            self.caption.SetPosition(0.02, 0.98)
            prop = self.caption.GetTextProperty()
            prop.SetVerticalJustificationToTop()  # (a second line goes below the first)
            prop.SetFontSize(14)
            prop.SetColor(0.92, 0.92, 0.92)
            self.plotter.renderer.AddViewProp(self.caption)
        self.caption.SetInput(text)
        self.caption.SetVisibility(bool(text))

    def paint_levels(self, levels) -> None:
        """Draw ``levels`` (n,) per-vertex errors in 1/255 levels on the full mesh in the
        difference view's colours (until the next :meth:`show_state`)."""
        d = self.drawings[0]
        d.rgb[:] = heat_map(np.asarray(levels)[None, :], vmax=VMAX)[0]
        d.vtk_colors.Modified()

    # -- the handles ---------------------------------------------------------------------------
    def add_handles(self, grab, move, release) -> None:
        """Every light's handle: a sphere widget in the light's colour, the selected light's
        larger and ringed. ``grab(i)``, ``move(i)`` and ``release(i)`` are called when light
        ``i``'s handle is pressed, dragged and let go."""
        self._handle_calls = (grab, move, release)
        self._show_handle(self.state)

    @property
    def handle(self):
        """The selected light's sphere widget (None before :meth:`add_handles` or with no
        light)."""
        s = self.state
        if s.selected_light is None or s.light >= len(self.handles):
            return None
        return self.handles[s.light]

    def _new_handle(self, i: int):
        grab, move, release = self._handle_calls
        w = self.plotter.add_sphere_widget(
            lambda *_: move(i), center=(0.0, 0.0, 0.0), radius=HANDLE_RADIUS,
            theta_resolution=20, phi_resolution=12, color=(1.0, 1.0, 1.0),
            selected_color=(1.0, 1.0, 1.0), test_callback=False, interaction_event="always",
        )  # fmt: skip
        w.ScaleOff()  # right-drag would resize it
        w.AddObserver("StartInteractionEvent", lambda *_: grab(i))
        w.AddObserver("EndInteractionEvent", lambda *_: release(i))
        return w

    def release_handles(self) -> None:
        """The handles gone, before the plotter closes: their observers removed (PyVista's and
        :meth:`_new_handle`'s call into the view port from VTK's C++, where the garbage
        collector does not see them) and their interactor unset (a sphere widget freed after
        its interactor reads the freed interactor: a crash)."""
        self.plotter.clear_sphere_widgets()  # (off, and out of PyVista's list: the handles)
        for w in self.handles:
            w.RemoveAllObservers()
            w.SetInteractor(None)
        self.handles = []
        self._handle_calls = None

    def _show_handle(self, state: State) -> None:
        """Each light's handle where the light is, in the light's colour; the rest off."""
        if self._handle_calls is None:
            return
        lights = state.scene.lights
        while len(self.handles) < len(lights):
            self.handles.append(self._new_handle(len(self.handles)))
        for i, w in enumerate(self.handles):
            if i >= len(lights):
                w.Off()
                continue
            scale = SELECTED_SCALE if i == state.light else 1.0
            w.SetRadius(HANDLE_RADIUS * state.radius * scale / self.frame[1])
            w.SetCenter(*self.to_view(handle_point(state, i)))
            w.GetSphereProperty().SetColor(*light_colour(lights[i])[0])
            w.On()
        self._set_glyph(state.selected_light, state)

    def handle_pixels(self) -> list[tuple[float, float, bool]]:
        """Each light's handle centre in the view's pixels (origin bottom-left, VTK's display
        coordinates) and whether it is in front of the camera."""
        s = self.state
        return [self._display(handle_point(s, i)) for i in range(len(s.scene.lights))]

    def _display(self, point) -> tuple[float, float, bool]:
        ren = self.plotter.renderer
        point = self.to_view(point)
        ren.SetWorldPoint(*point, 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        cam = ren.GetActiveCamera()
        pos, focal = np.asarray(cam.GetPosition()), np.asarray(cam.GetFocalPoint())
        ahead = float((np.asarray(point) - pos) @ (focal - pos)) > 0.0
        return x, y, ahead or bool(cam.GetParallelProjection())

    def _show_markers(self) -> None:
        """The ring around the selected light's handle, and an arrow at the view's edge for
        every handle out of the view (:func:`edge_marker`)."""
        if self._handle_calls is None:
            return
        s = self.state
        ox, oy, w, h = self.viewport_pixels()
        shown = self.handle_pixels()
        self.marker_triangles = {}
        rings = []
        for i, (x, y, ahead) in enumerate(shown):
            # the overlay draws in the renderer's own pixels: the window's, less its viewport's
            # origin (the main renderer starts above the term strip's band when it is on)
            x, y = x - ox, y - oy
            tri = edge_marker(x, y, ahead, w, h)
            if tri is not None:
                self.marker_triangles[i] = tri
            elif i == s.light:
                size = HANDLE_RADIUS * SELECTED_SCALE * s.radius / self.frame[1]
                r = self._pixel_radius(self.to_view(handle_point(s, i)), size)
                t = np.linspace(0.0, 2.0 * math.pi, 49)
                rings.append(np.column_stack([x + (r + RING_GAP) * np.cos(t),
                                              y + (r + RING_GAP) * np.sin(t)]))  # fmt: skip
        if self._ring is None:
            self._ring = overlay(self.plotter, RING_COLOR, RING_WIDTH)[0]
            self._markers = overlay(self.plotter, (1.0, 1.0, 1.0), 1.0, filled=True)[0]
            self._marker_edges = overlay(self.plotter, MARKER_OUTLINE, 2.0)[0]
        set_lines(self._ring, rings)
        colours = [light_colour(s.scene.lights[i])[0] for i in self.marker_triangles]
        set_triangles(self._markers, list(self.marker_triangles.values()), colours)
        triangles = list(self.marker_triangles.values())
        set_lines(self._marker_edges, [np.vstack([t, t[:1]]) for t in triangles])

    def viewport_pixels(self) -> tuple[float, float, float, float]:
        """The main renderer's area of the window in pixels: its origin (bottom-left, the
        window's display coordinates) and its width and height (the whole window unless the
        term strip's band takes the bottom)."""
        W, H = self.plotter.window_size
        x0, y0, x1, y1 = self.plotter.renderer.GetViewport()
        return x0 * W, y0 * H, (x1 - x0) * W, (y1 - y0) * H

    def _pixel_radius(self, point, radius: float) -> float:
        """How many pixels a sphere of ``radius`` at ``point`` (VTK's coordinates) spans (its
        projected radius; the view angle spans the renderer's height, not the window's)."""
        cam = self.plotter.renderer.GetActiveCamera()
        h = self.viewport_pixels()[3]
        if cam.GetParallelProjection():
            return radius * h / (2.0 * cam.GetParallelScale())
        depth = float(np.linalg.norm(np.subtract(point, cam.GetPosition())))
        return radius * h / (2.0 * depth * math.tan(math.radians(0.5 * cam.GetViewAngle())))

    def _set_glyph(self, light, state: State) -> None:
        """What the light says its handle shows (its ``GLYPH``): an arrow toward the mesh, its
        cone, or nothing."""
        import pyvista as pv

        kind = "" if light is None else light.GLYPH
        if not kind:
            if self._glyph is not None:
                self._glyph.SetVisibility(False)
            return
        at = self.to_view(handle_point(state))
        toward = -at  # toward the mesh's centre, the view's origin
        toward /= max(float(np.linalg.norm(toward)), 1e-300)
        length = GLYPH_LENGTH * state.radius / self.frame[1]
        if kind == "arrow":
            shape = pv.Arrow(start=at, direction=toward, scale=length, tip_length=0.3,
                             tip_radius=0.12, shaft_radius=0.04)  # fmt: skip
        else:
            aim, cutoff = light.cone()
            aim = np.asarray(aim)
            cutoff = min(cutoff, 89.0)
            shape = pv.Cone(center=at + 0.5 * length * aim, direction=-aim, height=length,
                            radius=length * math.tan(math.radians(cutoff)), resolution=32,
                            capping=False)  # fmt: skip
        if self._glyph is None:
            self._glyph_poly = shape
            self._glyph = self.plotter.add_mesh(
                self._glyph_poly, color=GLYPH_COLOR, opacity=0.55 if kind == "cone" else 1.0,
                lighting=False, reset_camera=False, pickable=False,
            )  # fmt: skip
        else:
            self._glyph_poly.copy_from(shape)
            self._glyph.GetProperty().SetOpacity(0.55 if kind == "cone" else 1.0)
        self._glyph.SetVisibility(True)
        self._glyph_kind = kind

    @property
    def glyph_kind(self) -> str | None:
        """ "arrow", "cone" or None: what the selected light's handle shows."""
        if self._glyph is None or not self._glyph.GetVisibility():
            return None
        return self._glyph_kind

    # -- pixels ---------------------------------------------------------------------------------
    def world_to_window(self, point) -> list[int]:
        """Window pixel (origin top-left) of a world point."""
        ren = self.plotter.renderer
        ren.SetWorldPoint(*self.to_view(point), 1.0)
        ren.WorldToDisplay()
        x, y, _ = ren.GetDisplayPoint()
        _, h = self.plotter.window_size
        return [int(round(x)), int(round(h - 1 - y))]

    def probe_vertex(self) -> int:
        """Index of the full mesh's vertex that faces the camera most (on a convex mesh it is
        visible): the window test reads its pixel."""
        mesh = self.mesh
        c = self.plotter.camera
        if c.GetParallelProjection():
            v = np.subtract(c.GetPosition(), c.GetFocalPoint())[None, :]
        else:
            v = np.asarray(c.GetPosition()) - self.to_view(mesh.positions)
        v = v / np.linalg.norm(v, axis=1, keepdims=True)
        return int(np.argmax(np.einsum("ij,ij->i", mesh.normals, v)))

    def apply_camera(self, camera: Camera) -> None:
        """Point the plotter's camera (PyVista will not reset it at the first frame)."""
        self.plotter.camera_set = True
        apply_camera(self.plotter.camera, in_frame(camera, *self.frame))
        self.plotter.renderer.ResetCameraClippingRange()


def edge_marker(x: float, y: float, ahead: bool, width: int, height: int,
                size: float = MARKER_SIZE, margin: float = MARKER_MARGIN):  # fmt: skip
    """The arrow that shows a handle out of the view: a (3, 2) triangle in display pixels
    (origin bottom-left) at the view's edge, its tip toward the handle's projection ``(x, y)``,
    or None when the handle is in the view. ``ahead``: the handle is in front of the camera
    (a point behind it projects mirrored through the view's centre, so the arrow points the
    other way)."""
    w, h = float(width), float(height)
    if ahead and 0.0 <= x < w and 0.0 <= y < h:
        return None
    cx, cy = 0.5 * w, 0.5 * h
    d = np.array([x - cx, y - cy]) * (1.0 if ahead else -1.0)
    if not np.all(np.isfinite(d)) or float(np.hypot(*d)) < 1e-9:
        d = np.array([0.0, 1.0])
    u = d / float(np.hypot(*d))
    reach = min(
        (cx - margin) / abs(u[0]) if abs(u[0]) > 1e-12 else math.inf,
        (cy - margin) / abs(u[1]) if abs(u[1]) > 1e-12 else math.inf,
    )
    tip = np.array([cx, cy]) + max(reach, 0.0) * u
    side = np.array([-u[1], u[0]])
    back = tip - size * u
    return np.array([tip, back + 0.45 * size * side, back - 0.45 * size * side])
