"""``phong-explorer render``: an off-screen picture (per vertex, or per pixel) or a mesh file.

::

    phong-explorer render [SCENE] --preset gold --mesh teapot --out gold.png --size 400x400
    phong-explorer render --preset jade --light-type point --light-position 2 2 2 --out j.ply
    phong-explorer render --preset jade --per-pixel --out reference.png

The scene options are in :mod:`explorer.cli.options`.
"""

from __future__ import annotations

import argparse
import sys

from explorer.cli.options import (
    add_scene_arguments,
    background_from_options,
    build_scene,
    check_out,
    size_from_option,
)
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.hdr import energy_warnings
from explorer.render.exports import OUTPUT_SUFFIXES, mesh_file_bytes
from explorer.render.images import encode_png
from explorer.render.offscreen import render_image
from explorer.render.perpixel import reference
from explorer.shading.display import vertex_colors


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--out", required=True, metavar="FILE",
        help="output: .png (picture), .ply or .glb (mesh with per-vertex colours)",
    )  # fmt: skip
    p.add_argument("--preset", metavar="NAME", help="material preset (overrides the scene's)")
    p.add_argument(
        "--size", default="400x400", metavar="WxH", help="picture size in pixels (default 400x400)"
    )
    p.add_argument(
        "--per-pixel", action="store_true",
        help="light every pixel instead of every vertex (exact sphere for the built-in spheres, "
        "else ray casting with interpolated normals): the accuracy reference; .png only",
    )  # fmt: skip
    add_scene_arguments(p, mesh_default="sphere")


# -- commands ------------------------------------------------------------------------------


def run(args) -> int:

    suffix = check_out(args.out, OUTPUT_SUFFIXES, args.force)
    size = size_from_option(args.size, "--size")
    background = background_from_options(args)
    args.mesh_default = "sphere"
    scene, mesh = build_scene(args)
    if scene.hdr is not None:
        for w in energy_warnings(scene.material):
            print(f"warning: {w}", file=sys.stderr)
    if args.per_pixel:
        return run_per_pixel(args, scene, mesh, size, background, suffix)
    colors = vertex_colors(scene, mesh)
    if suffix == ".png":
        image = render_image(scene, mesh, size, background=background, colors=colors)
        data = encode_png(image)
        what = f"{size[0]}x{size[1]} picture"
    else:
        data = mesh_file_bytes(mesh, colors, suffix, scene.material.opacity)
        what = f"{mesh.n_vertices} vertices with colours"
    write_atomic(args.out, data, overwrite=args.force)
    name = scene.material.name or "material"
    print(f"wrote {args.out}: {what} ({mesh.name}, {name}, {scene.model})")
    return 0


def run_per_pixel(args, scene, mesh, size, background, suffix: str) -> int:
    """``phong-explorer render --per-pixel``: write the per-pixel picture to ``args.out``."""
    if suffix != ".png":
        raise ExplorerError(f"--per-pixel draws a picture: give --out FILE.png, not {suffix}")
    if scene.material.opacity < 1.0:
        print(
            f"note: --per-pixel draws the nearest surface only (opacity "
            f"{scene.material.opacity:g} is not blended)",
            file=sys.stderr,
        )
    ref = reference(scene, mesh, size)
    write_atomic(args.out, encode_png(ref.image(background)), overwrite=args.force)
    how = "exact sphere" if ref.hits.method == "sphere" else "ray cast"
    name = scene.material.name or "material"
    print(
        f"wrote {args.out}: {size[0]}x{size[1]} per-pixel picture ({mesh.name}, {how}, {name}, "
        f"{scene.model})"
    )
    return 0
