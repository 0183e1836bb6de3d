"""The materials a mesh file brings: an OBJ's ``mtllib`` libraries matched to its groups.

:func:`group_materials` gives one :class:`~explorer.core.material.Material` per group of
``mesh.groups`` (see :class:`~explorer.geometry.meshes.MaterialGroups`), read with the strict
.mtl reader (:mod:`explorer.core.mtl`); a group whose material no library defines keeps the
scene's material, with a warning.
"""

from __future__ import annotations

from explorer.core.material import Material
from explorer.core.mtl import MtlUnreadable, read_mtl
from explorer.geometry.meshes import Mesh


def group_materials(mesh: Mesh, fallback: Material) -> tuple[tuple[Material, ...], list[str]]:
    """``(materials, warnings)``: one material per name of ``mesh.groups`` (``fallback`` for a
    group no library defines) and what the reader warned of, one sentence each.

    A library that cannot be read (missing, not a regular file, too large) is a warning; one
    that is read but has a problem raises its :class:`~explorer.core.mtl.MtlError` (the file
    and line).
    """
    groups = mesh.groups
    if groups is None:
        return (), []
    found: dict[str, Material] = {}
    warnings: list[str] = []
    for lib in groups.libraries:
        try:
            materials = read_mtl(lib)
        except MtlUnreadable as exc:  # missing, a FIFO or device, too large: never blocks
            warnings.append(f"mtllib {lib}: {exc.reason}; its materials are not read")
            continue
        for m in materials:
            found.setdefault(m.name, m.material.replace(name=m.name))
            warnings.extend(m.warnings)
    out = [found.get(name, fallback) for name in groups.names]
    missing = [name for name in groups.used if name not in found]
    if missing and found:
        names = ", ".join(f"'{name}'" for name in missing)
        warnings.append(
            f"{mesh.name}: usemtl {names}: not in its mtllib; the scene's material is used there"
        )
    elif "" in groups.names and found:
        warnings.append(f"{mesh.name}: faces without a usemtl get the scene's material")
    return tuple(out), warnings
