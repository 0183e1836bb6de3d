"""``phong-explorer plan SCENE``: the work the engine will do for a scene, and why."""

from __future__ import annotations

import argparse

from explorer.cli.options import add_materials_dir_option
from explorer.core.scene import load_scene
from explorer.core.text import say
from explorer.geometry.meshes import DEFAULT_MESH, get_mesh
from explorer.shading.plan import make_plan


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene file (YAML)")
    add_materials_dir_option(parser)


def run(args) -> int:

    scene = load_scene(args.scene, materials_dirs=args.materials_dirs)
    mesh_kind = None
    if any(lt.shadows for lt in scene.lights):  # shadows depend on the mesh: look at it
        mesh = get_mesh(scene.mesh or DEFAULT_MESH)
        mesh_kind = "faces" if mesh.n_faces else None
        say(f"mesh {mesh.name}: {mesh.n_faces} triangles")
    plan = make_plan(scene, mesh=mesh_kind)
    m = scene.material
    viewer = (
        f"eye {list(scene.viewer.eye)}"
        if scene.viewer.local
        else (f"to_viewer {[round(c, 6) for c in scene.viewer.to_viewer]}")
    )
    say(
        f"scene {args.scene}: {len(scene.lights)} light(s), model {scene.model}, "
        f"shininess {m.shininess:g}, viewer {viewer}"
    )
    say(plan.describe())
    return 0
