"""Writes teapot_parts.obj: Newell's teapot (6 samples per patch edge) with one ``usemtl``
group per part, naming the materials of teapot_parts.mtl. Run from the repository root:
``python docs/examples/make_teapot_parts.py``.

The teapot's parts (body, handle, spout, lid) are its connected components: the built-in mesh
welds seams only within a part.
"""

from pathlib import Path

import numpy as np
import trimesh

from explorer.core.mtl import read_mtl
from explorer.geometry import meshes as M
from explorer.render.exports import obj_files

HERE = Path(__file__).resolve().parent
#: material of each part, found by where the part is (x: handle < 0 < spout; y: lid on top)
MATERIALS = {
    "body": "Porcelain",
    "handle": "Gold_Trim",
    "spout": "Cobalt_Glaze",
    "lid": "Cobalt_Glaze",
}


def part_of(centre) -> str:
    x, y, _ = centre
    if y > 0.3:
        return "lid"
    if x < -0.5:
        return "handle"
    if x > 0.5:
        return "spout"
    return "body"


def main() -> None:
    mesh = M.teapot(6)
    tm = trimesh.Trimesh(mesh.positions, mesh.faces, process=False)
    labels = trimesh.graph.connected_component_labels(tm.face_adjacency, len(tm.faces))
    names = ["Porcelain", "Cobalt_Glaze", "Gold_Trim"]
    of_vertex = np.zeros(mesh.n_vertices, np.int32)
    for k in range(labels.max() + 1):
        verts = np.unique(mesh.faces[labels == k])
        part = part_of(mesh.positions[verts].mean(axis=0))
        of_vertex[verts] = names.index(MATERIALS[part])
    grouped = M.Mesh(
        mesh.positions, mesh.normals, mesh.faces, "teapot_parts",
        M.MaterialGroups(tuple(names), of_vertex),
    )  # fmt: skip
    library = {m.name: m.material for m in read_mtl(HERE / "teapot_parts.mtl")}
    pairs = [(name, library[name]) for name in names]
    obj, _ = obj_files(grouped, pairs, "teapot_parts.mtl")  # the .mtl is the hand-written one
    (HERE / "teapot_parts.obj").write_bytes(obj)


if __name__ == "__main__":
    main()
