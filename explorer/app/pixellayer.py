"""The per-pixel view: the engine's picture lit at every pixel, drawn by a screen quad that
writes the surface's depth.

In per-pixel mode (the scene's ``shading: per-pixel``) a view shows
:class:`explorer.render.live.LivePixels`' picture for the view's own camera and size: the engine
evaluated at each pixel's surface point with the interpolated normal, through the display
pipeline, the numbers ``render --per-pixel`` gives, on exactly the pixels its G-buffer covers.

It is drawn by the full mesh's actor with its mapper swapped for a screen quad's
(:meth:`PixelLayer._show`: VTK does not rasterise the mesh, which cost a 100k-vertex teapot's
frame 40 ms on llvmpipe): two triangles over the surface pixels' bounding box whose fragment
shader (:data:`FRAGMENT`) copies the picture's texel at the fragment's window position
(``texelFetch``, one texel per pixel, no filtering) and writes ``gl_FragDepth`` from the
G-buffer: each covered pixel's surface point's distance along the view direction, a 24-bit
code in the texture's other half (:func:`depth_codes`), converted with the clipping range VTK
draws the frame with (set as it draws: :meth:`PixelLayer._uniforms`); a pixel with no surface
is discarded. So the light handles pass in front of the surface and behind it as they did in
front of and behind the mesh, the actor's visibility (the difference view's heat map hides
the mesh) and opacity still apply, the lobe inset and the edge arrows stay as they are, and
the page's picture path (the off-screen plotter's frame) is unchanged. The quad's points lie
at the mesh's bounds, so VTK's clipping range and culling see the mesh's extent. No GLSL copy
of the lighting: the shader only copies bytes. While the quad stands in, a change does not
upload the mesh's per-vertex colours (:attr:`explorer.app.view.SceneView.colors_unseen`).

The picture is made before the window draws (the render window's ``StartEvent``, before VTK
makes its context current, so the G-buffer's own off-screen window may draw), for the camera
VTK is about to draw with and the state it makes (the camera is the viewer):
:meth:`PixelLayer.update`. A frame that shows the same scene, camera and size reuses the
picture; a new G-buffer (a camera or size change) draws a new depth half.

The drag fallback: while a drag moves the camera and a per-pixel picture costs more than
:data:`FALLBACK_RATIO` times the per-vertex frame (the last frame this view drew per vertex:
the engine's per-vertex update, the upload and VTK's draw of the mesh; none yet, no
fallback), the mesh is drawn with its per-vertex
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

#: the quad's vertex shader: its four corners (``tcoord`` (0, 0) to (1, 1)) are those of the
#: surface's pixels' bounding box in the renderer's viewport (``quadBox``: left, bottom, right,
#: top in clip coordinates, -1 to 1; :meth:`PixelLayer._draw_depth`), at depth 0: the pixels
#: around the surface cost no fragment; its points only carry the mesh's bounds
VERTEX = """//VTK::System::Dec
in vec4 vertexMC;
in vec2 tcoord;
uniform vec4 quadBox;
void main () {
  gl_Position = vec4(mix(quadBox.xy, quadBox.zw, tcoord), 0.0 * vertexMC.z, 1.0);
}
"""
#: the quad's fragment shader: the colour texel at the fragment's window pixel (the left half
#: of the texture), the depth of the surface there from the right half's 24-bit code of its
#: distance along the view direction (DEPTH_NONE: no surface, discarded), converted to the
#: window's depth with the clipping range VTK draws this frame with (``depthNear``,
#: ``depthFar``; :meth:`PixelLayer._uniforms`): OpenGL's perspective or parallel projection
#: then the default depth range [0, 1]. No lighting: the shader only copies the engine's bytes.
FRAGMENT = """//VTK::System::Dec
//VTK::Output::Dec
uniform sampler2D actortexture;
uniform float opacityUniform;
uniform int pictureWidth;
uniform float depthFirst;
uniform float depthStep;
uniform float depthNear;
uniform float depthFar;
uniform int depthParallel;
void main () {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 e = floor(texelFetch(actortexture, p + ivec2(pictureWidth, 0), 0).rgb * 255.0 + 0.5);
  float code = e.r * 65536.0 + e.g * 256.0 + e.b;
  if (code > 16777214.5) discard;
  float d = depthFirst + depthStep * code;
  float n = depthNear;
  float f = depthFar;
  float ndc = depthParallel == 1 ? (2.0 * d - (f + n)) / (f - n)
                                  : ((f + n) - 2.0 * f * n / d) / (f - n);
  gl_FragDepth = clamp(0.5 * ndc + 0.5, 0.0, 1.0);
  gl_FragData[0] = vec4(texelFetch(actortexture, p, 0).rgb, opacityUniform);
}
"""
#: the depth code of a pixel with no surface (24 bits all set); a surface's codes run from 0
#: (its nearest pixel) to DEPTH_NONE - 1 (its farthest)
DEPTH_NONE = (1 << 24) - 1


def depth_codes(d: np.ndarray) -> tuple[np.ndarray, float, float]:
    """The distances ``d`` (k,) along the view direction as 24-bit codes (k, 3) uint8 (big end
    first): ``(codes, first, step)``, a code ``c`` standing for ``first + step * c`` (the
    range of ``d`` in DEPTH_NONE - 1 steps: a step of 1/16,777,214 of the surface's depth,
    finer than a 24-bit depth buffer's over the whole clipping range)."""
    d = np.asarray(d, np.float64)
    if d.size == 0:
        return np.zeros((0, 3), np.uint8), 0.0, 0.0
    first, last = float(d.min()), float(d.max())
    step = (last - first) / (DEPTH_NONE - 1) if last > first else 0.0
    c = np.zeros(d.shape, np.int64) if step == 0.0 else np.rint((d - first) / step).astype(np.int64)
    out = np.empty((d.size, 3), np.uint8)
    out[:, 0], out[:, 1], out[:, 2] = c >> 16, (c >> 8) & 255, c & 255
    return out, first, step


def quad_box(mask: np.ndarray) -> tuple[float, float, float, float]:
    """The bounding box of ``mask`` (h, w) bool's True pixels (row 0 at the top) in clip
    coordinates of a viewport of its size: (left, bottom, right, top), the pixels' outer
    edges; an empty box (all 0) when none is True."""
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return (0.0, 0.0, 0.0, 0.0)
    h, w = mask.shape
    left, right = 2.0 * cols[0] / w - 1.0, 2.0 * (cols[-1] + 1) / w - 1.0
    bottom, top = 1.0 - 2.0 * (rows[-1] + 1) / h, 1.0 - 2.0 * rows[0] / h
    return (float(left), float(bottom), float(right), float(top))


class PixelLayer:
    """The per-pixel picture of ``view`` (a :class:`SceneView`) in its plotter: made by
    :meth:`update` before each frame in per-pixel mode, drawn by the full mesh's actor as a
    screen quad.

    frames : per-pixel pictures made; ms : the last one's time (LivePixels' frame, the
    texture's colour half and, after a new G-buffer, its depth half); last : the last
    :class:`~explorer.render.live.PixelFrame`, made for ``camera`` and ``size``; rgb : that
    picture (the G-buffer's pixels covered);
    vertex_ms : the time of the last frame drawn per vertex (NaN before one); vertex_frames :
    the frames drawn per vertex (the mesh's own mapper, no quad);
    fallback : this drag draws per vertex (the camera moves and per pixel costs too much);
    drags : the camera drags decided (each once, at its first camera frame in per-pixel
    mode); drag_decision : the last one's ``(ms, vertex_ms, fallback)``, the two times it
    compared and what it decided (None before one): what a test reads instead of guessing
    the decision from times read before the drag (another picture may come between)
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
        self.vertex_frames = 0
        self.fallback = False
        self.drags = 0
        self.drag_decision: tuple[float, float, bool] | None = None
        self._decided = False  # this drag's fallback is decided
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
        self._depth_of = None  # the G-buffer whose depth the texture holds
        self._depth = (0.0, 0.0)  # its codes' (first, step): see depth_codes
        self._box = (-1.0, -1.0, 1.0, 1.0)  # the quad's corners (VERTEX's quadBox)
        self._quad = None  # (PolyData, mapper) of the screen quad (_make_quad)
        self._mapper = None  # the full mesh's own mapper, while the quad stands in for it

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
        """The render window's EndEvent: a frame drawn per vertex (no quad), its time less
        the other work set aside, is :attr:`vertex_ms` (a per-pixel frame's own time without
        its picture is no per-vertex frame's: it neither draws nor shades the mesh)."""
        if self._t0 is not None:
            total = 1000.0 * (time.perf_counter() - self._t0)
            if not self.shown:
                self.vertex_ms = total - self._made_ms - self._aside_ms
                self.vertex_frames += 1
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
            self.fallback = self._decided = False
        elif not self._decided and self._key is not None and camera != self._key[2]:
            # decided once per drag, when the camera first moves, on the pictures made before
            # it (a picture of the drag that happens to take longer does not switch mid-drag)
            self.fallback, self._decided = self.too_slow(), True
            self.drags += 1
            self.drag_decision = (self.ms, self.vertex_ms, self.fallback)
        if not self.wanted(state) or self.fallback:
            self._show(False)
            return False
        made = False
        scene = M.set_camera(state, camera).shown_scene()
        groups = state.shown_groups()
        # the main renderer's own size: the term strip under it takes the window's bottom
        w, h = (int(v) for v in self.plotter.renderer.GetSize())
        mesh = self.view.mesh
        if mesh.uv is None:  # no (u, v): untextured, as the per-vertex view draws it
            scene = scene.replace(material=bare(scene.material))
            groups = None if groups is None else tuple(bare(m) for m in groups)
        key = (
            repr(scene),
            repr(groups),
            camera,
            (w, h),
            id(mesh),
            tuple(self.plotter.renderer.GetOrigin()),
        )
        if key != self._key:
            t0 = time.perf_counter()
            live = self._live_for(mesh)
            frame = live.frame(scene, camera, (w, h), materials=groups)
            self.last, self._key = frame, key
            self.camera, self.size, self.rgb = camera, (w, h), frame.rgb
            self.draw(frame.rgb)
            g, _ = live.gbuffer(camera, (w, h))  # (the frame's: kept)
            if g is not self._depth_of:
                self._draw_depth(g)
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
        """Draw ``rgb`` (h, w, 3) uint8, top row first, over the surface's pixels (the
        texture's colour half; VTK's rows run bottom up): the picture, or the compare view's
        heat map in its place; a picture of the main renderer's part of the window (the strip
        on) goes where that part is."""
        _, w = self._texels_for()
        self._texels[:, :w] = self._in_window(rgb)[::-1]
        self._image.GetPointData().GetScalars().Modified()
        self._image.Modified()

    def _draw_depth(self, g) -> None:
        """The texture's depth half: each pixel of the G-buffer ``g`` its surface point's
        distance along the view direction in VTK's frame (:func:`depth_codes`), DEPTH_NONE
        where no surface is seen."""
        cam = g.camera
        scale = float(self.view.frame[1])
        d = (g.hits.positions - np.asarray(cam.position)) @ np.asarray(cam.direction) / scale
        codes, first, step = depth_codes(d)
        w, h = g.size
        rh, rw = self._texels_for()
        half = self._texels[:, rw:]  # (VTK's rows: bottom up)
        half[:] = 255
        ox, oy = (0, 0) if (w, h) == (rw, rh) else self.plotter.renderer.GetOrigin()
        rows, cols = np.divmod(g.pixels, w)
        half[h - 1 - rows + int(oy), cols + int(ox)] = codes  # (the renderer's part)
        self._image.GetPointData().GetScalars().Modified()
        self._image.Modified()
        self._depth_of, self._depth = g, (first, step)
        self._box = quad_box(g.hits.mask)

    def _in_window(self, rgb: np.ndarray) -> np.ndarray:
        """``rgb`` of the main renderer's part of the window placed in the whole window's
        picture (black elsewhere), as it is when the renderer is the whole window."""
        rw, rh = (int(v) for v in self.plotter.window_size)
        if rgb.shape[:2] == (rh, rw):
            return rgb
        ox, oy = (int(v) for v in self.plotter.renderer.GetOrigin())
        full = np.zeros((rh, rw, 3), np.uint8)
        full[rh - oy - rgb.shape[0] : rh - oy, ox : ox + rgb.shape[1]] = rgb
        return full

    def _texels_for(self) -> tuple[int, int]:
        """The texture for the window's size (made anew for a new size): its halves, the
        colours then the depth codes, each (h, w) of the window, one texel per pixel.
        Returns (h, w)."""
        rw, rh = (int(v) for v in self.plotter.window_size)
        if self._texels is None or self._texels.shape[:2] != (rh, 2 * rw):
            self._make_texture(2 * rw, rh)
            self._texels[:, rw:] = 255  # (no surface until a depth is drawn)
            self._depth_of = None
        return rh, rw

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

    def release(self) -> None:
        """The screen quad's shader observer removed (before the plotter closes: it calls this
        layer from VTK's C++, where the garbage collector does not see it)."""
        if self._quad is not None:
            self._quad[1].RemoveAllObservers()
            self._quad = None

    def _make_quad(self):
        """The screen quad's PolyData and mapper: two triangles over the renderer's viewport
        (their ``tcoord`` the corners, :data:`VERTEX`), their points at the mesh's bounds
        (:meth:`_bound_quad`: VTK's clipping range and culling see the mesh's extent)."""
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - the OpenGL mapper's factory
        from vtkmodules.util.misc import calldata_type
        from vtkmodules.util.numpy_support import numpy_to_vtk
        from vtkmodules.util.vtkConstants import VTK_OBJECT
        from vtkmodules.vtkCommonCore import vtkCommand, vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
        from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

        poly = vtkPolyData()
        points = vtkPoints()
        points.SetNumberOfPoints(4)
        for i in range(4):
            points.SetPoint(i, 0.0, 0.0, 0.0)
        poly.SetPoints(points)
        cells = vtkCellArray()
        for tri in ((0, 1, 3), (0, 3, 2)):
            cells.InsertNextCell(3, tri)
        poly.SetPolys(cells)
        corners = np.array([[0, 0], [1, 0], [0, 1], [1, 1]], np.float32)
        poly.GetPointData().SetTCoords(numpy_to_vtk(corners, deep=True))
        mapper = vtkOpenGLPolyDataMapper()
        mapper.SetInputData(poly)
        mapper.ScalarVisibilityOff()

        @calldata_type(VTK_OBJECT)
        def uniforms(_caller, _event, program):
            if program is not None:
                self._uniforms(program)

        mapper.AddObserver(vtkCommand.UpdateShaderEvent, uniforms)
        return poly, mapper

    def _bound_quad(self, drawing) -> None:
        """The quad's points at two corners of the full mesh's bounds (in VTK's frame)."""
        x0, x1, y0, y1, z0, z1 = drawing.poly.GetBounds()
        poly = self._quad[0]
        corners = ((x0, y0, z0), (x1, y1, z1), (x0, y0, z0), (x1, y1, z1))
        if any(poly.GetPoint(i) != c for i, c in enumerate(corners)):
            for i, c in enumerate(corners):
                poly.GetPoints().SetPoint(i, c)
            poly.GetPoints().Modified()
            poly.Modified()

    def _uniforms(self, program) -> None:
        """The quad's uniforms, set as VTK draws it (after the frame's clipping range is
        set): where the depth half starts, the depth codes' scale, the camera's clipping range
        and projection."""
        camera = self.plotter.renderer.GetActiveCamera()
        near, far = camera.GetClippingRange()
        first, step = self._depth
        program.SetUniform4f("quadBox", self._box)
        program.SetUniformi("pictureWidth", int(self.plotter.window_size[0]))
        program.SetUniformf("depthFirst", first)
        program.SetUniformf("depthStep", step)
        program.SetUniformf("depthNear", near)
        program.SetUniformf("depthFar", far)
        program.SetUniformi("depthParallel", int(bool(camera.GetParallelProjection())))

    def _show(self, on: bool) -> None:
        """The full mesh's actor draws the screen quad with the picture (on: its own mapper
        set aside, so VTK does not rasterise the mesh) or the mesh in its per-vertex colours
        (off)."""
        drawing = self.view.drawings[0]
        if on and self._actor is not drawing.actor:
            self._show(False)
            if self._quad is None:
                self._quad = self._make_quad()
            actor = drawing.actor
            self._mapper = actor.GetMapper()
            actor.SetMapper(self._quad[1])
            actor.SetTexture(self._texture)
            sp = actor.GetShaderProperty()
            sp.SetVertexShaderCode(VERTEX)
            sp.SetFragmentShaderCode(FRAGMENT)
            self._actor = actor
            self.view.colors_unseen = True  # (a change does not upload the mesh's colours)
        elif not on and self._actor is not None:
            actor = self._actor
            actor.SetMapper(self._mapper)
            actor.SetTexture(None)
            sp = actor.GetShaderProperty()
            sp.SetVertexShaderCode(None)
            sp.SetFragmentShaderCode(None)
            self._actor = self._mapper = None
            if drawing.texture is not None:  # a diffuse_map's actor: made anew, with its (u, v)
                drawing.texture = None
                drawing.set_texture(self.view.plotter, self.view.state.shown_scene())
            self.view.colors_unseen = False
            drawing.upload()  # (the colours of the changes made while the quad stood in)
        if self._actor is not None:
            self._bound_quad(drawing)
        self.shown = self._actor is not None
