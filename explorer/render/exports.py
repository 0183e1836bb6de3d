"""Mesh files with the engine's colours: PLY and GLB (trimesh's writers)."""

from __future__ import annotations

import numpy as np

from explorer.core.errors import ExplorerError
from explorer.geometry.meshes import Mesh
from explorer.shading.display import to_bytes

#: output formats of ``phong-explorer render --out``
OUTPUT_SUFFIXES = (".png", ".ply", ".glb")


def mesh_file_bytes(mesh: Mesh, colors, suffix: str, opacity: float = 1.0) -> bytes:
    """A PLY or GLB file (by ``suffix``) holding the mesh, its normals and its per-vertex
    colours as 8-bit RGBA (alpha = opacity). The colours are the engine's display values, as
    in the PNG; a viewer that lights the mesh again adds its own shading on top."""
    import trimesh

    rgba = to_bytes(colors, opacity)
    tm = trimesh.Trimesh(
        vertices=np.array(mesh.positions),
        faces=np.array(mesh.faces),
        vertex_normals=np.array(mesh.normals),
        vertex_colors=rgba,
        process=False,
    )
    kind = suffix.lower().lstrip(".")
    if kind not in ("ply", "glb"):
        raise ExplorerError(f"mesh export writes .ply or .glb, got {suffix!r}")
    return tm.export(file_type=kind)
