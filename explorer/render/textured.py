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

**Ambient and emission maps** (beyond OpenGL 2.1, whose one texture unit in this mode
multiplies the whole primary colour): when the material has an ``ambient_map`` or an
``emission_map``, the picture passes the primary colour's terms apart (:attr:`Textured.layers`):
``E = clamp(e)``, ``Ā = clamp(a·A)`` and ``D̄ = clamp(d·D)``, each interpolated, each times its
own map's texel (white where a map is absent), then

- ``single``: ``out = min(1, E·Te + Ā·Ta + D̄·Td + S̄·Td)`` (the diffuse texture darkens the
  highlight, as GL's one texture does);
- ``separate``: ``out = min(1, E·Te + Ā·Ta + D̄·Td + S̄)``.

With the diffuse map alone the picture is GL 2.1's (the oracle's); with the other two it
departs from GL's ``clamp(e + a·A + d·D)·T`` only where a vertex's primary sum exceeds 1 (each
term is clamped apart) and by the rounding of each term to 8 bits (``docs/formats.md``).
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
#: the maps drawn as layers of their own (the module docstring), in the order of
#: :attr:`Textured.layers`, and the material colour each multiplies
LAYER_MAPS = {"emission_map": "emission", "ambient_map": "ambient"}
#: the fragment's sum with the layers (``{layers}``: each layer's colour times its texel;
#: ``{specular}``: the secondary colour, times the diffuse texel under ``single``)
_LAYERED_FRAGMENT = """vec4 texel = texture(actortexture, tcoordVCVSOutput);
  vec3 layered = fragOutput0.rgb * texel.rgb{layers};
  fragOutput0 = vec4(min(layered + {specular}, vec3(1.0)), fragOutput0.a * texel.a);"""
#: a white texel: the texture of a term without a map
WHITE = np.full((1, 1, 4), 255, np.uint8)


@dataclass(frozen=True)
class Textured:
    """What a textured per-vertex picture draws.

    primary : (n, 3) uint8 the primary colour per vertex (the whole colour under ``single``;
        with layers, the diffuse term ``D̄`` alone)
    secondary : (n, 3) uint8 the specular colour per vertex (zeros under ``single``, but with
        layers)
    image : (h, w, 4) uint8 RGBA rows top first; tmap : the map (its scale, offset, clamp), or
        None with layers and no diffuse map (a white texel)
    layers : () for OpenGL 2.1's one texture; else one :class:`Layer` per key of
        :data:`LAYER_MAPS` (the ambient and emission terms with their maps)
    color_control : the scene's (with layers, the fragment's sum depends on it)
    """

    primary: np.ndarray
    secondary: np.ndarray
    image: np.ndarray
    tmap: TextureMap | None
    layers: tuple = ()
    color_control: str = "single"


@dataclass(frozen=True)
class Layer:
    """One term drawn with its own map: ``key`` (of :data:`LAYER_MAPS`), ``colors`` (n, 3)
    uint8 the term per vertex, ``image`` (h, w, 4) uint8 and ``tmap`` (None: a white texel)."""

    key: str
    colors: np.ndarray
    image: np.ndarray
    tmap: TextureMap | None

    @property
    def name(self) -> str:
        """The layer's names in the shader: ``<name>`` its sampler, ``<name>_c`` its colour,
        ``<name>_st`` its texture coordinates."""
        return self.key.replace("_", "")


def texture_map(scene, materials=None, key: str = "diffuse_map") -> TextureMap | None:
    """The map ``key`` (default ``diffuse_map``) a per-vertex picture of the scene wears, or
    None.

    materials : a mesh file's group materials; they must name one map between them (or none:
        see :func:`file_maps`)
    """
    found = {getattr(m, key) for m in (materials or (scene.material,))}
    if len(found) > 1:
        what = key.replace("_", " ") + "s"
        raise ExplorerError(
            f"the mesh's materials wear different {what} (or some none): a per-vertex "
            "picture draws one texture each; give --preset NAME (or --diffuse-map IMG) to "
            "draw one"
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
    return colours(only("primary")), colours(only("specular"))


def only(term: str):
    """material -> the material with only ``term`` kept (the others black): ``emission``,
    ``ambient``, ``diffuse``, ``specular``, or ``primary`` (all but the specular)."""
    black = (0.0, 0.0, 0.0)
    keep = ("emission", "ambient", "diffuse") if term == "primary" else (term,)
    off = {k: black for k in ("emission", "ambient", "diffuse", "specular") if k not in keep}
    return lambda m: m.replace(**off)


def layered(scene, materials=None) -> bool:
    """Whether a per-vertex picture draws the primary colour's terms apart (an ``ambient_map``
    or ``emission_map``: see the module docstring)."""
    return any(
        getattr(m, k) is not None for m in (materials or (scene.material,)) for k in LAYER_MAPS
    )


def textured(scene, mesh: Mesh, materials=None, *, layers: bool = True) -> Textured | None:
    """What a per-vertex picture of the textured scene draws (None: it wears no texture).

    layers : draw an ``ambient_map`` and ``emission_map`` too (:attr:`Textured.layers`); False:
        the ``diffuse_map`` alone, as GL 2.1 draws it (a GLB holds that)
    A mesh without texture coordinates, or a map whose image cannot be read
    (:func:`explorer.render.textures.read_texture`), raises an :class:`ExplorerError`."""
    tmap = texture_map(scene, materials)
    layers = layers and layered(scene, materials)
    if tmap is None and not layers:
        return None
    maps = {k: texture_map(scene, materials, k) for k in LAYER_MAPS} if layers else {}
    for key, t in (("diffuse_map", tmap), *maps.items()):
        if t is not None and mesh.uv is None:
            raise ExplorerError(
                f"mesh '{mesh.name}' has no texture coordinates, so it cannot wear {key} "
                f"'{t.file}' (an OBJ needs vt lines; a built-in mesh has its own)"
            )
    image = WHITE if tmap is None else read_texture(tmap, "diffuse_map")
    if not layers:
        primary, secondary = textured_colors(scene, mesh, materials)
        return Textured(to_bytes(primary), to_bytes(secondary), image, tmap)
    images = {k: WHITE if t is None else read_texture(t, k) for k, t in maps.items()}

    def term(name):
        change = only(name)
        if materials:
            return to_bytes(group_vertex_colors(scene, mesh, [change(m) for m in materials]))
        return to_bytes(vertex_colors(scene.replace(material=change(scene.material)), mesh))

    built = tuple(Layer(k, term(LAYER_MAPS[k]), images[k], t) for k, t in maps.items())
    return Textured(term("diffuse"), term("specular"), image, tmap, built, scene.color_control)


def texture_arrays(poly, mesh: Mesh, t: Textured) -> None:
    """Put the texture coordinates and the secondary colour on ``poly`` (a PyVista PolyData of
    ``mesh``, its ``"colors"`` the primary colour), and each layer's colour and coordinates."""
    poly.active_texture_coordinates = _st(t.tmap, mesh)
    poly.point_data[SECONDARY] = _rgba(t.secondary)
    for layer in t.layers:
        poly.point_data[layer.name + "_c"] = _rgba(layer.colors)
        poly.point_data[layer.name + "_st"] = _st(layer.tmap, mesh)


def _st(tmap: TextureMap | None, mesh: Mesh) -> np.ndarray:
    """(n, 2) float32 the texture coordinates the map looks up (zeros: a white texel's)."""
    if tmap is None:
        return np.zeros((mesh.n_vertices, 2), np.float32)
    return tmap.lookup(mesh.uv).astype(np.float32)


def _rgba(colors) -> np.ndarray:
    """(n, 4) float32 the bytes / 255 and an alpha of 1: a colour as a vertex array."""
    out = np.ones((len(colors), 4), np.float32)
    out[:, :3] = np.asarray(colors) / np.float32(255.0)
    return out


def vtk_texture(t: Textured | Layer):
    """The VTK texture of ``t``'s image: nearest texel, repeated (or clamped to the edge), no
    mipmaps, bottom row first."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkRenderingCore import vtkTexture

    clamp = t.tmap is not None and t.tmap.clamp
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
    texture.SetRepeat(not clamp)
    texture.SetEdgeClamp(clamp)
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
    fragment = _FRAGMENT
    if t.layers:
        fragment = _layers(mapper, actor, t)
    sp.AddFragmentShaderReplacement("//VTK::TCoord::Impl", True, fragment, False)
    plotter.add_actor(actor, reset_camera=False)
    return actor


def _layers(mapper, actor, t: Textured) -> str:
    """Bind each layer's colour, coordinates and texture (a named texture of the actor's
    property: VTK declares and binds its sampler) and return the fragment's sum."""
    from vtkmodules.vtkCommonDataModel import vtkDataObject

    points = vtkDataObject.FIELD_ASSOCIATION_POINTS
    sp = actor.GetShaderProperty()
    vs_dec, vs_impl, fs_dec, terms = [], [], [], []
    for layer in t.layers:
        n = layer.name
        for array in (f"{n}_c", f"{n}_st"):
            mapper.MapDataArrayToVertexAttribute(array, array, points, -1)
        vs_dec += [
            f"in vec4 {n}_c;",
            f"in vec2 {n}_st;",
            f"out vec4 {n}_cVS;",
            f"out vec2 {n}_stVS;",
        ]
        vs_impl += [f"{n}_cVS = {n}_c;", f"{n}_stVS = {n}_st;"]
        fs_dec += [f"in vec4 {n}_cVS;", f"in vec2 {n}_stVS;"]
        terms.append(f" + {n}_cVS.rgb * texture({n}, {n}_stVS).rgb")
        actor.GetProperty().SetTexture(n, vtk_texture(layer))
    sp.AddVertexShaderReplacement(
        "//VTK::Normal::Dec", True, "//VTK::Normal::Dec\n" + "\n".join(vs_dec), False
    )
    sp.AddVertexShaderReplacement(
        "//VTK::Normal::Impl", True, "//VTK::Normal::Impl\n" + "\n".join(vs_impl), False
    )
    sp.AddFragmentShaderReplacement(
        "//VTK::Normal::Dec", True, "//VTK::Normal::Dec\n" + "\n".join(fs_dec), False
    )
    specular = "secondaryVSOut.rgb"
    if t.color_control == "single":
        specular += " * texel.rgb"
    return _LAYERED_FRAGMENT.format(layers="".join(terms), specular=specular)
