"""Mesh files with the engine's colours or materials: PLY, GLB and OBJ + MTL.

* **PLY** (trimesh's writer): the mesh, its normals and the engine's display colours as 8-bit
  RGBA per vertex (alpha = opacity), as in the PNG.
* **GLB**: a glTF 2.0 binary whose one material is ``KHR_materials_unlit`` (a viewer shows
  the colours as they are, without lighting them again) and whose ``COLOR_0`` holds the
  engine's display colours converted from sRGB to linear (glTF's vertex colours are linear;
  the viewer encodes its output to sRGB again), as float RGBA. A glTF viewer then shows the
  engine's pixels.
* **GLB with a texture** (a ``diffuse_map``): ``TEXCOORD_0`` (v turned over: glTF's v = 0 is
  the image's top row), the image as a PNG in the file, ``baseColorTexture`` with nearest
  filtering and the map's wrap. glTF's base colour is factor × texture × ``COLOR_0``: exactly
  OpenGL's single colour mode (``COLOR_0`` is the whole lit colour), so the file always holds
  it; the separate specular colour has no place there (``docs/formats.md``).
* **OBJ + MTL**: the mesh with normals and its material(s) as an .mtl (one ``usemtl`` group
  per material), for tools that light the mesh themselves.
"""

from __future__ import annotations

import json
import struct

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.core.mtl import format_mtl
from explorer.core.version import __version__
from explorer.geometry.meshes import Mesh, has_area
from explorer.render.images import encode_png
from explorer.render.textured import Textured
from explorer.shading.display import to_bytes
from explorer.shading.effects.hdr import srgb_decode

#: output formats of ``phong-explorer render --out``
OUTPUT_SUFFIXES = (".png", ".ply", ".glb", ".obj")
#: the glTF extension of a material shown without lighting
UNLIT = "KHR_materials_unlit"

_GLB_MAGIC = 0x46546C67  # "glTF"
_CHUNK_JSON = 0x4E4F534A  # "JSON"
_CHUNK_BIN = 0x004E4942  # "BIN\0"
_FLOAT, _UINT = 5126, 5125  # glTF componentType: float32, uint32
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_NEAREST, _REPEAT, _CLAMP_TO_EDGE = 9728, 10497, 33071  # glTF sampler values (OpenGL's)


def mesh_file_bytes(
    mesh: Mesh,
    colors,
    suffix: str,
    opacity: float = 1.0,
    *,
    double_sided: bool = False,
    texture: Textured | None = None,
) -> bytes:
    """A PLY or GLB file (by ``suffix``) holding the mesh, its normals and its per-vertex
    colours (see the module docstring); ``double_sided``: the GLB material's flag (the
    scene's ``two_sided``); ``texture``: the GLB's base colour texture (its ``primary``, the
    single colour mode's colours, is ``COLOR_0`` then)."""
    kind = suffix.lower().lstrip(".")
    if kind == "glb":
        return glb_bytes(mesh, colors, opacity, double_sided=double_sided, texture=texture)
    if kind != "ply":
        raise ExplorerError(f"mesh export writes .ply or .glb, got {suffix!r}")
    check_float32(mesh, ".ply")
    import trimesh

    tm = trimesh.Trimesh(
        vertices=np.array(mesh.positions),
        faces=np.array(mesh.faces),
        vertex_normals=np.array(mesh.normals),
        vertex_colors=to_bytes(colors, opacity),
        process=False,
    )
    return tm.export(file_type="ply")


def check_float32(mesh: Mesh, what: str) -> np.ndarray:
    """The mesh's positions as float32, as a .glb and a .ply store them, when they keep the mesh:
    finite (coordinates within ±3.4e38), an extent of at least float32's smallest normal number
    (1.2e-38: below it the numbers keep fewer digits) and every triangle with an area in float64
    keeping one; else an
    :class:`ExplorerError` naming the format and the range, before anything is written.
    (A mesh of that size renders: see explorer.render.camera.)"""
    P = np.asarray(mesh.positions, np.float64)
    with np.errstate(over="ignore", under="ignore"):
        P32 = P.astype(np.float32)
    if not np.isfinite(P32).all():
        big = float(np.abs(P).max())
        raise ExplorerError(
            f"mesh '{mesh.name}' has coordinates up to {big:.3g}: a {what} file stores float32, "
            f"at most {float(np.finfo(np.float32).max):.3g}; scale the mesh down to export it"
        )
    F = np.asarray(mesh.faces)
    size = float(np.max(P.max(axis=0) - P.min(axis=0)))
    tiny = float(np.finfo(np.float32).tiny)  # below it float32 loses precision
    if 0.0 < size < tiny or has_area(P32.astype(np.float64), F).sum() < has_area(P, F).sum():
        raise ExplorerError(
            f"mesh '{mesh.name}' of size {size:.3g} is too small for a {what} file: it stores "
            f"float32, whose numbers below {tiny:.3g} lose the mesh's shape; scale the mesh up "
            "to export it"
        )
    return P32


def linear_colors(colors) -> np.ndarray:
    """Display colours (n, 3) in [0, 1] (what the PNG shows, sRGB-encoded) as linear values,
    (n, 3) float64: what glTF's ``COLOR_0`` holds."""
    c = np.clip(np.asarray(colors, np.float64), 0.0, 1.0)
    return srgb_decode(c)


def glb_bytes(
    mesh: Mesh,
    colors,
    opacity: float = 1.0,
    *,
    double_sided: bool = False,
    texture: Textured | None = None,
) -> bytes:
    """A binary glTF 2.0 file: one mesh, one unlit material, linear ``COLOR_0`` (float RGBA,
    alpha = opacity); see the module docstring.

    colors : (n, 3) display colours in [0, 1] (with ``texture``: its primary colours instead)
    texture : a textured picture's :class:`~explorer.render.textured.Textured` (single colour)
    """
    n = mesh.n_vertices
    if texture is not None:
        colors = texture.primary / 255.0
    colors = np.asarray(colors, np.float64)
    if colors.shape != (n, 3):
        raise ExplorerError(f"colors must have shape ({n}, 3), got {colors.shape}")
    rgba = np.empty((n, 4), np.float32)
    rgba[:, :3] = linear_colors(colors)
    rgba[:, 3] = float(opacity)
    arrays = [
        (check_float32(mesh, ".glb"), "VEC3", _FLOAT, _ARRAY_BUFFER),
        (np.asarray(mesh.normals, np.float32), "VEC3", _FLOAT, _ARRAY_BUFFER),
        (rgba, "VEC4", _FLOAT, _ARRAY_BUFFER),
        (np.asarray(mesh.faces, np.uint32).ravel(), "SCALAR", _UINT, _ELEMENT_ARRAY_BUFFER),
    ]
    if texture is not None:
        st = texture.tmap.lookup(mesh.uv)
        st[:, 1] = 1.0 - st[:, 1]  # glTF's v = 0 is the image's top row; OBJ's and GL's bottom
        arrays.append((st.astype(np.float32), "VEC2", _FLOAT, _ARRAY_BUFFER))
        arrays.append((np.frombuffer(encode_png(texture.image), np.uint8), "", 0, 0))
    blob = bytearray()
    views, accessors = [], []
    for data, kind, component, target in arrays:
        raw = np.ascontiguousarray(data).tobytes()
        view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw), "target": target}
        if not kind:  # the image: a view with no target and no accessor
            del view["target"]
            views.append(view)
            blob += raw + b"\0" * (-len(raw) % 4)
            continue
        views.append(view)
        accessor = {
            "bufferView": len(views) - 1,
            "componentType": component,
            "count": len(data),
            "type": kind,
        }
        blob += raw + b"\0" * (-len(raw) % 4)
        accessors.append(accessor)
    pos = arrays[0][0]
    accessors[0]["min"] = [float(v) for v in pos.min(axis=0)]
    accessors[0]["max"] = [float(v) for v in pos.max(axis=0)]
    material = {
        "name": "engine colours (unlit)",
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "extensions": {UNLIT: {}},
        "alphaMode": "BLEND" if opacity < 1.0 else "OPAQUE",
        "doubleSided": bool(double_sided),
    }
    primitive = {"POSITION": 0, "NORMAL": 1, "COLOR_0": 2}
    textures = {}
    if texture is not None:
        primitive["TEXCOORD_0"] = 4
        material["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0, "texCoord": 0}
        wrap = _CLAMP_TO_EDGE if texture.tmap.clamp else _REPEAT
        textures = {
            "images": [{"bufferView": len(views) - 1, "mimeType": "image/png"}],
            "samplers": [
                {"magFilter": _NEAREST, "minFilter": _NEAREST, "wrapS": wrap, "wrapT": wrap}
            ],
            "textures": [{"source": 0, "sampler": 0}],
        }
    doc = {
        "asset": {"version": "2.0", "generator": f"phong-explorer {__version__}"},
        "extensionsUsed": [UNLIT],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": mesh.name}],
        "meshes": [
            {
                "name": mesh.name,
                "primitives": [
                    {
                        "attributes": primitive,
                        "indices": 3,
                        "material": 0,
                        "mode": 4,
                    }
                ],
            }
        ],
        "materials": [material],
        **textures,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return b"".join(
        [
            struct.pack("<III", _GLB_MAGIC, 2, total),
            struct.pack("<II", len(text), _CHUNK_JSON),
            text,
            struct.pack("<II", len(blob), _CHUNK_BIN),
            bytes(blob),
        ]
    )


def obj_files(mesh: Mesh, materials, mtl_name: str) -> tuple[bytes, bytes]:
    """``(obj, mtl)`` file contents: the mesh with normals (and its texture coordinates as
    ``vt`` when it has them), and its materials (their maps as they name them).

    materials : ``[(name, Material), ...]``: one for the whole mesh, or one per group of
        ``mesh.groups`` (each group becomes a ``usemtl`` block)
    mtl_name : the .mtl file name the OBJ's ``mtllib`` names (next to the OBJ)
    """
    materials = list(materials)
    groups = mesh.groups
    per_group = groups is not None and len(materials) == len(groups.names) > 1
    if not per_group and len(materials) != 1:
        raise ExplorerError("an OBJ export takes one material, or one per group of the mesh")
    lines = [f"# written by phong-explorer {__version__}", f"mtllib {mtl_name}"]
    lines += [f"v {x!r} {y!r} {z!r}" for x, y, z in mesh.positions.tolist()]
    lines += [f"vn {x!r} {y!r} {z!r}" for x, y, z in mesh.normals.tolist()]
    if mesh.uv is not None:  # the texture coordinates: vertex k's vt is k too
        lines += [f"vt {u!r} {v!r}" for u, v in mesh.uv.tolist()]
    corner = "{0}/{0}/{0}" if mesh.uv is not None else "{0}//{0}"
    faces = mesh.faces + 1
    if per_group:
        owner = groups.of_vertex[mesh.faces[:, 0]]
        blocks = [(name, faces[owner == g]) for g, (name, _) in enumerate(materials)]
    else:
        blocks = [(materials[0][0], faces)]
    for name, block in blocks:
        lines.append(f"usemtl {name}")
        lines += ["f " + " ".join(corner.format(i) for i in tri) for tri in block.tolist()]
    obj = "\n".join(lines) + "\n"
    header = f"materials of {mesh.name}, written by phong-explorer {__version__}"
    return obj.encode("utf-8"), format_mtl(materials, header=header).encode("utf-8")
