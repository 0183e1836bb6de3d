"""
A turntable
===========

``render --turntable N --out spin.gif``: N frames of the camera and its lights orbiting the mesh
(the lights turn with the camera, so the highlights stay put on the screen while the teapot
turns). Here the teapot OBJ of ``docs/examples/`` in its own .mtl materials, one per ``usemtl``
group, in 12 small frames.
"""

from pathlib import Path

import explorer
from explorer.core.atomic import write_atomic
from explorer.geometry.filematerials import group_materials
from explorer.geometry.meshes import get_mesh
from explorer.render.turntable import encode, iter_frames
from explorer.shading.display import group_vertex_colors

examples = Path(explorer.__file__).resolve().parent.parent / "docs" / "examples"
mesh = get_mesh(str(examples / "teapot_parts.obj"))
scene = explorer.load_scene({"lights": [{"type": "point", "position": [2.0, 2.0, 3.0]}]})
materials, warnings = group_materials(mesh, scene.material)  # one per usemtl group
frames = iter_frames(scene, mesh, 12, lambda s: group_vertex_colors(s, mesh, materials), (160, 120))
write_atomic("turntable.gif", encode(frames, ".gif"), overwrite=True)
