"""What both front ends say of the state in words (no toolkit): the line of the mesh file's own
materials, the name of the material shown, the line above the preset list and the state's
summary; the line under the mesh chooser and an entry of the recent files. The panel model's
text rows, the views' captions, the window's status bar, its view tab and its File menu read
them."""

from __future__ import annotations

from pathlib import Path

from explorer.app.model import TERMS, State
from explorer.core.texture import MAP_KEYS


def mesh_materials_line(state: State, source=str) -> str:
    """What a front end says of the mesh file's own materials: whether they are drawn (and
    which group the controls edit) or what covers the mesh instead ("" when it brings none).
    ``source`` formats the file's name (the Qt label makes it bold, HTML-escaped)."""
    mm = state.mesh_materials
    if mm is None:
        return ""
    k, name = len(mm.names), source(mm.source)
    if state.groups is not None:
        return (f"{name} brings its own materials, one per group ({k}); the controls below "
                f"edit group {mm.label(state.group)}")  # fmt: skip
    cover = f"preset {state.preset!r}" if state.preset else "one material"
    return (f"{name} brings {k} material{'s' * (k != 1)} of its own; {cover} covers the whole "
            "mesh instead")  # fmt: skip


def material_title(state: State) -> str:
    """What the captions call the material shown: the preset's name, else the material's own
    (an OBJ's ``newmtl`` name, kept when another mesh is chosen), else ``"scene material"``."""
    return state.preset or state.scene.material.name or "scene material"


def material_line(state: State) -> str:
    """What both front ends say of the material the controls edit, above the preset list:
    ``preset: gold``, ``material: Porcelain of the mesh`` (a group of the mesh's own), or
    ``material: NAME`` (:func:`material_title`), each with `` (edited)`` once changed."""
    edited = " (edited)" if state.edited else ""
    mm = state.mesh_materials
    if state.groups is not None and mm is not None:
        return f"material: {mm.label(state.group)} of the mesh{edited}"
    if state.preset:
        return f"preset: {state.preset}{edited}"
    return f"material: {material_title(state)}{edited}"


#: what separates the summary's parts (:func:`summary`)
SEPARATOR = ";  "


def summary(state: State) -> str:
    """The state in one line (the window's status bar): the material shown (or the mesh file's
    own materials), the model, and the terms and texture maps hidden:
    ``gold;  blinn-phong;  hidden: specular``."""
    what = material_title(state)
    if state.groups is not None:
        what = f"{state.mesh_materials.source}'s materials"
    parts = [what, state.scene.model]
    hidden = [t for t in (*TERMS, *MAP_KEYS) if t in state.hidden]  # (terms, maps off)
    if hidden:
        parts.append("hidden: " + ", ".join(hidden))
    return SEPARATOR.join(parts)


def mesh_line(name: str, n_vertices: int) -> str:
    """What the line under the mesh chooser says of the mesh shown: ``teapot: 1,234
    vertices``."""
    return f"{name}: {n_vertices:,} vertices"


def recent_entry(i: int, path: str) -> str:
    """Recent file ``path``'s entry, the ``i``-th (from 0) of the list: its number (the
    desktop's mnemonic, ``&``), its name and, apart, its folder."""
    return f"&{i + 1} {Path(path).name}   ({Path(path).parent})"
