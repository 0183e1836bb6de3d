"""A textured picture per vertex, as OpenGL 2.1's fixed function draws it.

OpenGL 2.1 lights each vertex, interpolates the result across the triangle and then applies the
texture per pixel (``GL_MODULATE``). Under ``GL_LIGHT_MODEL_COLOR_CONTROL``:

- ``GL_SINGLE_COLOR`` (the scene's ``color_control: single``, OpenGL's default): one colour,
  ``c = clamp(e + a·A + d·D + s·S)``, and ``out = c · T``: the texture darkens the highlight too;
- ``GL_SEPARATE_SPECULAR_COLOR`` (``color_control: separate``): the primary colour
  ``p = clamp(e + a·A + d·D)`` and the secondary ``q = clamp(s·S)`` are interpolated apart and
  ``out = min(1, p · T + q)``: a white highlight stays white on a dark texture.

``A, D, S`` are the engine's exact per-vertex sums (:attr:`explorer.shading.shader.Shader.terms`),
so each colour here is the engine's own colour of a material with the other terms set to zero
(:func:`textured_colors`); ``T`` is the ``diffuse_map``'s texel, nearest (``GL_NEAREST``),
repeated or clamped to the edge. VTK draws it in one pass (:func:`add_textured`): the primary
colour as the usual RGB point scalars (so a white texture gives today's pixels, bit for bit),
the secondary as a second vertex array, and a fragment-shader replacement of two lines doing
the multiply and the sum. The image goes to VTK bottom row first (v = 0 is the image's lower
edge, as in OBJ and OpenGL).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.texture import MAP_KEYS, PER_VERTEX_MAPS, TextureMap
from explorer.geometry.meshes import Mesh
from explorer.render.textures import gl_rows, read_texture
from explorer.shading.display import group_vertex_colors, to_bytes, vertex_colors

#: the vertex array of the secondary colour (RGBA float32, the bytes / 255)
SECONDARY = "secondary"
#: the fragment shader's texture and colour sum (VTK's ``//VTK::TCoord::Impl`` replaced):
#: GL_MODULATE (colour and alpha times the texel) then GL's colour sum and clamp
_FRAGMENT = """vec4 texel = texture(actortexture, tcoordVCVSOutput);
  fragOutput0 = vec4(min(fragOutput0.rgb * texel.rgb + secondaryVSOut.rgb, vec3(1.0)),
                     fragOutput0.a * texel.a);"""


@dataclass(frozen=True)
class Textured:
    """What a textured per-vertex picture draws.

    primary : (n, 3) uint8 the primary colour per vertex (the whole colour under ``single``)
    secondary : (n, 3) uint8 the specular colour per vertex (zeros under ``single``)
    image : (h, w, 4) uint8 RGBA rows top first; tmap : the map (its scale, offset, clamp)
    """

    primary: np.ndarray
    secondary: np.ndarray
    image: np.ndarray
    tmap: TextureMap


def texture_map(scene, materials=None) -> TextureMap | None:
    """The ``diffuse_map`` a per-vertex picture of the scene wears, or None.

    materials : a mesh file's group materials; they must name one map between them (or none:
        see :func:`file_maps`)
    """
    found = {m.diffuse_map for m in (materials or (scene.material,))}
    if len(found) > 1:
        raise ExplorerError(
            "the mesh's materials wear different diffuse maps (or some none): a per-vertex "
            "picture draws one texture; give --preset NAME (or --diffuse-map IMG) to draw one"
        )
    return found.pop()


def file_maps(mesh: Mesh, materials) -> tuple[tuple | None, list[str]]:
    """``(materials, warnings)``: a mesh file's own materials as a picture can draw them. Their
    diffuse maps are kept when the mesh has texture coordinates and the groups name one map
    between them; else they are taken off (the picture is untextured), with one warning."""
    if not materials or not any(m.diffuse_map is not None for m in materials):
        return materials, []
    names = sorted({m.diffuse_map.file for m in materials if m.diffuse_map is not None})
    if mesh.uv is None:
        why = "it has no texture coordinates (vt lines)"
    elif len({m.diffuse_map for m in materials}) > 1:
        why = "its groups wear different diffuse maps (or some none); a picture draws one"
    else:
        return materials, []
    plain = tuple(m.replace(diffuse_map=None) for m in materials)
    return plain, [f"{mesh.name}: diffuse_map {', '.join(names)} not drawn: {why}"]


def not_drawn_per_vertex(material) -> list[str]:
    """The maps of ``material`` a per-vertex picture does not draw (they need per-pixel
    shading), as keys."""
    return [k for k in MAP_KEYS if k not in PER_VERTEX_MAPS and getattr(material, k) is not None]


def textured_colors(scene, mesh: Mesh, materials=None) -> tuple[np.ndarray, np.ndarray]:
    """``(primary, secondary)`` display colours (n, 3) float64 of the mesh's vertices under the
    scene's ``color_control`` (see the module docstring); each group in its own material when
    ``materials`` are given (a mesh file's)."""

    def colours(change):
        if materials:
            return group_vertex_colors(scene, mesh, [change(m) for m in materials])
        return vertex_colors(scene.replace(material=change(scene.material)), mesh)

    if scene.color_control == "single":
        return colours(lambda m: m), np.zeros((mesh.n_vertices, 3))
    black = (0.0, 0.0, 0.0)
    primary = colours(lambda m: m.replace(specular=black))
    secondary = colours(lambda m: m.replace(ambient=black, diffuse=black, emission=black))
    return primary, secondary


def textured(scene, mesh: Mesh, materials=None) -> Textured | None:
    """What a per-vertex picture of the textured scene draws (None: it wears no texture).

    A mesh without texture coordinates, or a map whose image cannot be read
    (:func:`explorer.render.textures.read_texture`), raises an :class:`ExplorerError`."""
    tmap = texture_map(scene, materials)
    if tmap is None:
        return None
    if mesh.uv is None:
        raise ExplorerError(
            f"mesh '{mesh.name}' has no texture coordinates, so it cannot wear diffuse_map "
            f"'{tmap.file}' (an OBJ needs vt lines; a built-in mesh has its own)"
        )
    image = read_texture(tmap, "diffuse_map")
    primary, secondary = textured_colors(scene, mesh, materials)
    return Textured(to_bytes(primary), to_bytes(secondary), image, tmap)


def texture_arrays(poly, mesh: Mesh, t: Textured) -> None:
    """Put the texture coordinates and the secondary colour on ``poly`` (a PyVista PolyData of
    ``mesh``, its ``"colors"`` the primary colour)."""
    poly.active_texture_coordinates = t.tmap.lookup(mesh.uv).astype(np.float32)
    secondary = np.ones((mesh.n_vertices, 4), np.float32)
    secondary[:, :3] = t.secondary / np.float32(255.0)
    poly.point_data[SECONDARY] = secondary


def vtk_texture(t: Textured):
    """The VTK texture of ``t``'s image: nearest texel, repeated (or clamped to the edge), no
    mipmaps, bottom row first."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import vtkTexture

    rows = gl_rows(t.image)  # VTK's image: x fastest, then y from the bottom (v = 0)
    h, w = rows.shape[:2]
    data = vtkImageData()
    data.SetDimensions(w, h, 1)
    scalars = numpy_to_vtk(rows.reshape(-1, 4), deep=True)
    scalars.SetName("texture")
    data.GetPointData().SetScalars(scalars)
    texture = vtkTexture()
    texture.SetInputData(data)
    texture.SetColorModeToDirectScalars()
    texture.SetInterpolate(False)
    texture.SetMipmap(False)
    texture.SetRepeat(not t.tmap.clamp)
    texture.SetEdgeClamp(t.tmap.clamp)
    return texture


def add_textured(plotter, poly, t: Textured):
    """Draw ``poly`` (its ``"colors"`` the primary colour, :func:`texture_arrays` done) with
    ``t``'s texture as OpenGL 2.1 does (the module docstring), VTK's lighting off, without
    moving the camera. Returns the actor."""
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - the OpenGL mapper's factory
    from vtkmodules.vtkCommonDataModel import vtkDataObject
    from vtkmodules.vtkRenderingCore import vtkActor
    from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

    mapper = vtkOpenGLPolyDataMapper()
    mapper.SetInputData(poly)
    mapper.SetScalarModeToUsePointFieldData()
    mapper.SelectColorArray("colors")
    mapper.SetColorModeToDirectScalars()
    mapper.ScalarVisibilityOn()
    mapper.MapDataArrayToVertexAttribute(
        SECONDARY, SECONDARY, vtkDataObject.FIELD_ASSOCIATION_POINTS, -1
    )
    actor = vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().LightingOff()
    actor.SetTexture(vtk_texture(t))
    sp = actor.GetShaderProperty()
    sp.AddVertexShaderReplacement(
        "//VTK::Color::Dec",
        True,
        f"//VTK::Color::Dec\nin vec4 {SECONDARY};\nout vec4 secondaryVSOut;",
        False,
    )
    sp.AddVertexShaderReplacement(
        "//VTK::Color::Impl", True, f"//VTK::Color::Impl\nsecondaryVSOut = {SECONDARY};", False
    )
    sp.AddFragmentShaderReplacement(
        "//VTK::Color::Dec", True, "//VTK::Color::Dec\nin vec4 secondaryVSOut;", False
    )
    sp.AddFragmentShaderReplacement("//VTK::TCoord::Impl", True, _FRAGMENT, False)
    plotter.add_actor(actor, reset_camera=False)
    return actor
