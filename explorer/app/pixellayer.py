"""The per-pixel view: the engine's picture lit at every pixel, drawn by the mesh's own actor.

In per-pixel mode (the scene's ``shading: per-pixel``) a view shows
:class:`explorer.render.live.LivePixels`' picture for the view's own camera and size: the engine
evaluated at each pixel's surface point with the interpolated normal, through the display
pipeline, the numbers ``render --per-pixel`` gives. It is drawn by the mesh actor of the
:class:`~explorer.app.view.SceneView` as a texture looked up by the fragment's window position
(``texelFetch(actortexture, ivec2(gl_FragCoord.xy))``, one texel per pixel, no filtering), so
the mesh keeps its depth, the light handles pass in front of it and behind it as before, the
lobe inset and the difference view's heat map stay as they are, and the page's picture path
(the off-screen plotter's frame) is unchanged. No GLSL copy of the lighting: the shader only
copies a texel.

The picture is made before the window draws (the render window's ``StartEvent``, before VTK
makes its context current, so the G-buffer's own off-screen window may draw), for the camera
VTK is about to draw with and the state it makes (the camera is the viewer):
:meth:`PixelLayer.update`. A frame that shows the same scene, camera and size reuses the picture.
The rasteriser behind the G-buffer is VTK's, like the view's, but it draws the mesh in its own
frame: a silhouette pixel the view covers and the G-buffer does not takes its covered
neighbour's colour (:func:`fill_edges`).

The drag fallback: while a drag moves the camera and a per-pixel picture costs more than
:data:`FALLBACK_RATIO` times the per-vertex frame (the same window's frame without it: the
engine's per-vertex update, the upload and VTK's draw), the mesh is drawn with its per-vertex
colours (and the level of detail, as any drag draws it) and :attr:`PixelLayer.fallback` says
so; the release draws per pixel again.
"""

from __future__ import annotations

import time

import numpy as np

from explorer.app import model as M
from explorer.app.view import SceneView, view_camera
from explorer.render.pixelmaps import bare

#: the per-pixel mode's name (:data:`explorer.core.scene.SHADINGS`)
PER_PIXEL = "per-pixel"
#: a camera drag draws per vertex when a per-pixel frame costs more than this many times the
#: per-vertex frame (issue 39's rule)
FALLBACK_RATIO = 2.0

#: the fragment shader's colour: the texel at the fragment's pixel, the actor's opacity
FRAGMENT = (
    "//VTK::TCoord::Impl\n"
    "  gl_FragData[0] = vec4(texelFetch(actortexture, ivec2(gl_FragCoord.xy), 0).rgb, opacity);\n"
)


def edge_sources(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The silhouette's fill for ``mask`` (h, w) bool, the covered pixels: ``(dst, src)``, flat
    pixel indices, each uncovered pixel next to a covered one and that neighbour (the first of
    its 8, in a fixed order). Made once per G-buffer (:meth:`PixelLayer.update` keeps it)."""
    h, w = mask.shape
    index = np.arange(h * w).reshape(h, w)
    src = np.full(h * w, -1, np.int64)
    todo = ~mask
    for dy, dx in ((0, -1), (0, 1), (-1, 0), (1, 0), (-1, -1), (-1, 1), (1, -1), (1, 1)):
        ys = slice(max(dy, 0), h + min(dy, 0))
        yd = slice(max(-dy, 0), h + min(-dy, 0))
        xs = slice(max(dx, 0), w + min(dx, 0))
        xd = slice(max(-dx, 0), w + min(-dx, 0))
        take = todo[yd, xd] & mask[ys, xs]
        src[index[yd, xd][take]] = index[ys, xs][take]
        todo[yd, xd] &= ~take
    dst = np.flatnonzero(src >= 0)
    return dst, src[dst]


def fill_edges(rgb: np.ndarray, mask: np.ndarray, edges=None) -> np.ndarray:
    """``rgb`` (h, w, 3) uint8 with each uncovered pixel (``mask`` False) next to a covered one
    given that neighbour's colour (:func:`edge_sources`, or ``edges`` made by it): the
    silhouette pixels the view's rasterisation covers and the G-buffer's does not. In place;
    returns ``rgb``."""
    dst, src = edge_sources(mask) if edges is None else edges
    flat = rgb.reshape(-1, 3)
    flat[dst] = flat[src]
    return rgb


class PixelLayer:
    """The per-pixel picture of ``view`` (a :class:`SceneView`) in its plotter: made by
    :meth:`update` before each frame in per-pixel mode, drawn by the full mesh's actor.

    frames : per-pixel pictures made; ms : the last one's time (LivePixels' frame, the edge
    fill and the texture's upload); last : the last :class:`~explorer.render.live.PixelFrame`,
    made for ``camera`` and ``size``; rgb : that picture as drawn (silhouette filled);
    vertex_ms : the last frame's time without the per-pixel picture (the per-vertex frame);
    fallback : this drag draws per vertex (the camera moves and per pixel costs too much)
    """

    def __init__(self, view: SceneView):
        self.view = view
        self.plotter = view.plotter
        self.frames = 0
        self.ms = float("nan")
        self.last = None
        self.camera = self.size = self.rgb = None
        self.shown = False
        self.vertex_ms = float("nan")
        self.fallback = False
        self._t0: float | None = None
        self._made_ms = 0.0
        self._aside_ms = 0.0
        self.aside_ms = 0.0  # the last frame's other work (:meth:`set_aside`)
        self._live = None
        self._mesh = None
        self._key = None
        self._image = None
        self._texture = None
        self._texels: np.ndarray | None = None
        self._actor = None
        self._edges = (None, None)  # (the G-buffer's mask, its edge_sources)

    # -- the picture ---------------------------------------------------------------------------
    def wanted(self, state: M.State) -> bool:
        """Whether ``state`` is drawn per pixel now (its shading, and not the level of detail
        of a drag)."""
        return state.scene.shading == PER_PIXEL and not self.view.lod_active

    def before(self, state: M.State) -> bool:
        """The render window's StartEvent: :meth:`update`, the frame's time started."""
        self._t0 = time.perf_counter()
        self._aside_ms = 0.0
        made = self.update(state)
        self._made_ms = self.ms if made else 0.0
        return made

    def after(self) -> None:
        """The render window's EndEvent: the frame's time less the picture's and the other
        work set aside is :attr:`vertex_ms`."""
        if self._t0 is not None:
            total = 1000.0 * (time.perf_counter() - self._t0)
            self.vertex_ms = total - self._made_ms - self._aside_ms
            self.aside_ms = self._aside_ms
            self._t0 = None

    def set_aside(self, seconds: float) -> None:
        """Leave ``seconds`` of other work done in this frame (side B's) out of
        :attr:`vertex_ms` (and say how much: :attr:`aside_ms`)."""
        self._aside_ms += 1000.0 * seconds

    def too_slow(self) -> bool:
        """A per-pixel picture costs more than :data:`FALLBACK_RATIO` per-vertex frames."""
        return self.ms > FALLBACK_RATIO * max(self.vertex_ms, 0.0)

    def update(self, state: M.State) -> bool:
        """Before a frame of ``state`` (its camera the one VTK draws with): the per-pixel
        picture made (unless this scene, camera and size have it already) and drawn, or the
        mesh drawn per vertex. Returns whether a picture was made."""
        camera = view_camera(self.plotter.camera, state.centre, state.radius)
        if self.view.dragging == 0:
            self.fallback = False
        elif not self.fallback and self._key is not None and camera != self._key[2]:
            self.fallback = self.too_slow()  # (decided once per drag, when the camera moves)
        if not self.wanted(state) or self.fallback:
            self._show(False)
            return False
        made = False
        scene = M.set_camera(state, camera).shown_scene()
        groups = state.shown_groups()
        w, h = (int(v) for v in self.plotter.window_size)
        mesh = self.view.mesh
        if mesh.uv is None:  # no (u, v): untextured, as the per-vertex view draws it
            scene = scene.replace(material=bare(scene.material))
            groups = None if groups is None else tuple(bare(m) for m in groups)
        key = (repr(scene), repr(groups), camera, (w, h), id(mesh))
        if key != self._key:
            t0 = time.perf_counter()
            frame = self._live_for(mesh).frame(scene, camera, (w, h), materials=groups)
            if self._edges[0] is not frame.mask:  # (a new G-buffer)
                self._edges = (frame.mask, edge_sources(frame.mask))
            rgb = fill_edges(np.array(frame.rgb), frame.mask, self._edges[1])
            self.last, self._key = frame, key
            self.camera, self.size, self.rgb = camera, (w, h), rgb
            self.draw(rgb)
            self.frames += 1
            self.ms = 1000.0 * (time.perf_counter() - t0)
            made = True
        self._show(True)
        return made

    def _live_for(self, mesh):
        from explorer.render.live import LivePixels  # (VTK, for the G-buffer's rasterisation)

        if self._live is None:
            self._live = LivePixels(mesh)
        self._live.set_mesh(mesh)
        return self._live

    @property
    def live(self):
        """The :class:`~explorer.render.live.LivePixels` of the pictures (None before one)."""
        return self._live

    # -- drawing -------------------------------------------------------------------------------
    def draw(self, rgb: np.ndarray) -> None:
        """Draw ``rgb`` (h, w, 3) uint8, top row first, on the mesh (the texture; VTK's rows
        run bottom up): the picture, or the compare view's heat map in its place."""
        h, w = rgb.shape[:2]
        if self._texels is None or self._texels.shape[:2] != (h, w):
            self._make_texture(w, h)
        self._texels[:] = rgb[::-1]
        self._image.GetPointData().GetScalars().Modified()
        self._image.Modified()

    def _make_texture(self, w: int, h: int) -> None:
        from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
        from vtkmodules.vtkCommonDataModel import vtkImageData
        from vtkmodules.vtkRenderingCore import vtkTexture

        self._image = vtkImageData()
        self._image.SetDimensions(w, h, 1)
        data = numpy_to_vtk(np.zeros((w * h, 3), np.uint8), deep=True)
        data.SetName("pixels")
        self._image.GetPointData().SetScalars(data)
        self._texels = vtk_to_numpy(data).reshape(h, w, 3)  # a view of VTK's memory
        if self._texture is None:
            self._texture = vtkTexture()
            self._texture.InterpolateOff()
            self._texture.RepeatOff()
            self._texture.SetColorModeToDirectScalars()
        self._texture.SetInputData(self._image)

    def _show(self, on: bool) -> None:
        """The full mesh's actor draws the texture (on) or its per-vertex colours (off)."""
        drawing = self.view.drawings[0]
        if on and self._actor is not drawing.actor:
            self._show(False)
            n = drawing.mesh.n_vertices  # texture coordinates turn VTK's texture code on
            drawing.poly.active_texture_coordinates = np.zeros((n, 2), np.float32)
            drawing.actor.SetTexture(self._texture)
            drawing.actor.GetShaderProperty().AddFragmentShaderReplacement(
                "//VTK::TCoord::Impl", True, FRAGMENT, False
            )
            self._actor = drawing.actor
        elif not on and self._actor is not None:
            self._actor.SetTexture(None)
            self._actor.GetShaderProperty().ClearAllFragmentShaderReplacements()
            self._actor = None
            if drawing.texture is not None:  # a diffuse_map's actor: made anew, with its (u, v)
                drawing.texture = None
                drawing.set_texture(self.view.plotter, self.view.state.shown_scene())
        self.shown = self._actor is not None
