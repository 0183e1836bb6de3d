"""``phong-explorer render``: an off-screen picture (per vertex, or per pixel) or a mesh file.

::

    phong-explorer render [SCENE] --preset gold --mesh teapot --out gold.png --size 400x400
    phong-explorer render --preset jade --light-type point --light-position 2 2 2 --out j.ply
    phong-explorer render --preset jade --per-pixel --out reference.png
    phong-explorer render --mesh model.obj --out model.png         (the OBJ's own materials)
    phong-explorer render --preset gold --mesh teapot --out gold.glb   (unlit glTF)
    phong-explorer render --preset gold --mesh teapot --out gold.obj   (gold.obj + gold.mtl)
    phong-explorer render --preset gold --mesh teapot --turntable 36 --out spin.gif
    phong-explorer render --preset gold --mesh teapot --strip --out strip.png  (term by term)
    phong-explorer render --preset gold --strip --strip-mode raw --strip-lights --out s.png
    phong-explorer render --preset gold --lobes --out lobes.png   (the lobes, BRDF, albedo)
    phong-explorer render --preset gold --mesh teapot --diffuse-map wood.png --out t.png

An OBJ whose ``mtllib`` defines materials is drawn with them, each ``usemtl`` group in its own
material; ``--preset`` draws the whole mesh in one preset instead. The scene options are in
:mod:`explorer.cli.options`.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
from pathlib import Path

from explorer.analysis.lobeplot import light_incidences, lobe_picture, scene_charts
from explorer.cli.options import (
    add_scene_arguments,
    background_from_options,
    build_scene,
    check_out,
    mesh_materials,
    size_from_option,
)
from explorer.core import tolerances as tol
from explorer.core.atomic import write_all_atomic, write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.hdr import energy_warnings
from explorer.core.mtl import preset_name, preset_names
from explorer.core.progress import Progress
from explorer.core.text import say
from explorer.geometry.frame import frame_of
from explorer.render.exports import OUTPUT_SUFFIXES, mesh_file_bytes, obj_files
from explorer.render.faceids import MAX_FACES
from explorer.render.images import encode_png
from explorer.render.live import METHODS as PER_PIXEL_METHODS
from explorer.render.live import picture
from explorer.render.offscreen import render_image
from explorer.render.perpixel import reference
from explorer.render.strip import STRIP_TILE, render_strip
from explorer.render.textured import file_maps, layered, not_drawn_per_vertex, textured
from explorer.render.turntable import (
    FPS,
    TURNTABLE_SUFFIXES,
    check_frames,
    check_turntable,
    encode,
    iter_frames,
)
from explorer.shading.display import group_vertex_colors, vertex_colors
from explorer.shading.strip import MODES as STRIP_MODES


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--out", required=True, metavar="FILE",
        help="output: .png (picture), .ply or .glb (mesh with per-vertex colours; the GLB "
        "unlit, so glTF viewers show the engine's colours), .obj (with an .mtl of its "
        "material), or with --turntable .gif / .mp4",
    )  # fmt: skip
    p.add_argument(
        "--turntable", type=int, metavar="N", default=None,
        help=f"N frames of the camera orbiting the mesh (a full turn, {FPS} frames/s) into "
        "--out .gif or .mp4",
    )  # fmt: skip
    p.add_argument("--preset", metavar="NAME", help="material preset (overrides the scene's)")
    p.add_argument(
        "--size", default="400x400", metavar="WxH", help="picture size in pixels (default 400x400)"
    )
    p.add_argument(
        "--per-pixel-method",
        choices=PER_PIXEL_METHODS,
        default=None,
        help="what --per-pixel lights: raster (default) the triangles VTK draws at each pixel, "
        "as the live view; raycast the nearest triangle along each pixel's ray; sphere the exact "
        "sphere (built-in spheres: the accuracy reference); auto sphere for those, else raycast",
    )
    p.add_argument(
        "--per-pixel", action="store_true",
        help="light every pixel instead of every vertex: the engine at the surface point each "
        "pixel shows, with the interpolated normal (the live per-pixel view's picture); .png only",
    )  # fmt: skip
    p.add_argument(
        "--strip",
        action="store_true",
        help="the equation term by term: emission | ambient | diffuse | specular | sum | "
        "overflow, one tile each (--tile), labelled; .png only",
    )
    p.add_argument(
        "--strip-mode",
        choices=STRIP_MODES,
        default="weighted",
        help="weighted: each term as it enters the colour (k·A, k·D, k·S); raw: the light sums "
        "A, D, S alone (default weighted)",
    )
    p.add_argument("--strip-lights", action="store_true", help="with --strip: a row per light")
    p.add_argument(
        "--lobes",
        action="store_true",
        help="the lobe plots of the material at the scene's lights: the three models' lobes "
        "(polar, and BRDF on a log scale), their directional albedo, one lobe per light; .png",
    )
    p.add_argument(
        "--tile",
        default=None,
        metavar="WxH",
        help=f"with --strip: the size of one tile (default {STRIP_TILE[0]}x{STRIP_TILE[1]})",
    )
    add_scene_arguments(p, mesh_default="sphere")


# -- commands ------------------------------------------------------------------------------


def run(args) -> int:

    turntable = args.turntable is not None
    suffixes = TURNTABLE_SUFFIXES if turntable else OUTPUT_SUFFIXES
    suffix = check_out(args.out, suffixes, args.force)
    if turntable:
        check_frames(args.turntable)
    if args.lobes and (turntable or args.per_pixel or args.strip or suffix != ".png"):
        raise ExplorerError(
            "--lobes draws one picture: give --out FILE.png, and no --strip, "
            "--per-pixel or --turntable"
        )
    if args.strip and (turntable or args.per_pixel):
        raise ExplorerError(
            "--strip draws the terms per vertex: not with --turntable or --per-pixel"
        )
    if args.strip and suffix != ".png":
        raise ExplorerError(f"--strip draws a picture: give --out FILE.png, not {suffix}")
    size = size_from_option(args.size, "--size")
    if turntable:  # its format's needs and its total, before the mesh is read or a frame drawn
        check_turntable(args.turntable, size, suffix)
    background = background_from_options(args)
    args.mesh_default = "sphere"
    scene, mesh = build_scene(args)
    scene, materials = mesh_materials(args, scene, mesh)
    if scene.hdr is not None:
        for m in materials or (scene.material,):
            for w in energy_warnings(m):
                say(f"warning: {w}", file=sys.stderr)
    if args.lobes:
        return run_lobes(args, scene, mesh)
    # the flag, or the scene's key for a picture (a mesh file or a turntable is per vertex)
    if args.per_pixel or (scene.shading == "per-pixel" and suffix == ".png" and not turntable):
        if materials:
            raise ExplorerError(
                "--per-pixel draws one material: give --preset NAME for a mesh with its own "
                "materials"
            )
        return run_per_pixel(args, scene, mesh, size, background, suffix)
    if args.strip:
        return run_strip(args, scene, mesh, materials, background)
    if args.tile is not None or args.strip_lights:
        raise ExplorerError("--tile and --strip-lights draw the strip: give --strip too")
    materials, notes = file_maps(mesh, materials)
    for note in notes:
        say(f"warning: {note}", file=sys.stderr)
    texture = textured(scene, mesh, materials)  # the image read (or refused) before any work
    if suffix == ".glb" and layered(scene, materials):
        say(
            f"warning: {args.out}: a GLB holds the diffuse_map alone (glTF's base colour "
            "texture); ambient_map and emission_map are not written into it",
            file=sys.stderr,
        )
        texture = textured(scene, mesh, materials, layers=False)
    for m in materials or (scene.material,):
        for key in not_drawn_per_vertex(m):
            say(
                f"warning: {key} {getattr(m, key).file}: not drawn per vertex (it needs "
                "per-pixel shading: --per-pixel draws it); the material keeps it",
                file=sys.stderr,
            )
    if texture is not None and suffix == ".glb" and scene.color_control == "separate":
        say(
            f"warning: {args.out}: glTF's base colour is texture x COLOR_0, OpenGL's single "
            "colour: the GLB holds that (the texture darkens the highlight; glTF has no "
            "separate specular colour)",
            file=sys.stderr,
        )
        texture = textured(scene.replace(color_control="single"), mesh, materials, layers=False)
    elif texture is not None and (turntable or suffix not in (".png", ".glb")):
        say(
            f"warning: {args.out}: the texture maps are not drawn into this output (a PNG "
            "picture and a GLB wear them); the vertices carry their untextured colours",
            file=sys.stderr,
        )
    name = scene.material.name or "material"
    if materials:
        name = f"{len(materials)} material{'s' if len(materials) != 1 else ''} of the file"
    if args.per_pixel_method is not None:  # (a picture per vertex: nothing for it to choose)
        raise ExplorerError("--per-pixel-method chooses what --per-pixel lights: give --per-pixel")
    if turntable:
        return run_turntable(args, scene, mesh, materials, size, background, suffix)
    colors = colors_of(scene, mesh, materials)
    if suffix == ".obj":
        return run_obj(args, scene, mesh, materials)
    if suffix == ".png":
        image = render_image(
            scene, mesh, size, background=background, colors=colors, texture=texture
        )
        data = encode_png(image)
        what = f"{size[0]}x{size[1]} picture"
    else:
        data = mesh_file_bytes(
            mesh,
            colors,
            suffix,
            scene.material.opacity,
            double_sided=scene.two_sided,
            texture=texture if suffix == ".glb" else None,
        )
        what = f"{mesh.n_vertices} vertices with colours"
        warn_if_unreadable(args.out, len(data))
    write_atomic(args.out, data, overwrite=args.force)
    say(f"wrote {args.out}: {what} ({mesh.name}, {name}, {scene.model})")
    return 0


def colors_of(scene, mesh, materials):
    """Display colours of the mesh's vertices: each group in its material, or the scene's."""
    if materials:
        return group_vertex_colors(scene, mesh, materials)
    return vertex_colors(scene, mesh)


def run_obj(args, scene, mesh, materials) -> int:
    """``--out x.obj``: the mesh and ``x.mtl`` beside it (:func:`mtl_file_name`), written
    together (:func:`~explorer.core.atomic.write_all_atomic`); neither replaces a file without
    ``--force``."""
    out = Path(args.out)
    mtl_path = out.with_name(mtl_file_name(out))
    if materials:
        names = preset_names([n or "default" for n in mesh.groups.names])
        pairs = list(zip(names, materials, strict=True))
    else:
        pairs = [(preset_name(scene.material.name or "material"), scene.material)]
    obj, mtl = obj_files(mesh, pairs, mtl_path.name)
    warn_if_unreadable(out, len(obj))
    write_all_atomic({mtl_path: mtl, out: obj}, overwrite=args.force)
    say(
        f"wrote {out} and {mtl_path}: {mesh.n_vertices} vertices, "
        f"{len(pairs)} material{'s' if len(pairs) != 1 else ''} ({mesh.name})"
    )
    return 0


def mtl_file_name(out: Path) -> str:
    """The name of the .mtl written beside the OBJ ``out``: its stem with every run of
    characters other than letters, digits, ``.``, ``-`` and ``_`` made one ``_``, so that the
    ``mtllib`` line reads back the same in every reader (a blank would split it in most, a
    ``#`` would start a comment): ``my model.obj`` -> ``my_model.mtl``."""
    stem = re.sub(r"[^\w.\-]+", "_", out.stem).strip("_") or "materials"
    return f"{stem}.mtl"


def warn_if_unreadable(out, size: int) -> None:
    """A warning when a mesh file written is larger than the product reads back
    (``MAX_MESH_FILE_BYTES``): it is still written."""
    if size > tol.MAX_MESH_FILE_BYTES:
        say(
            f"warning: {out} is {size} bytes, more than the {tol.MAX_MESH_FILE_BYTES} bytes "
            f"({tol.MAX_MESH_FILE_BYTES >> 20} MiB) phong-explorer reads as a mesh file "
            "(MAX_MESH_FILE_BYTES); other tools can read it, --mesh cannot",
            file=sys.stderr,
        )


def run_turntable(args, scene, mesh, materials, size, background, suffix: str) -> int:
    """``--turntable N``: N frames of the orbit into a GIF or MP4, with a progress bar."""
    bar = Progress("turntable")
    frames = iter_frames(
        scene,
        mesh,
        args.turntable,
        lambda s: colors_of(s, mesh, materials),
        size,
        background=background,
        progress=bar.update,
    )
    data = encode(frames, suffix)  # each frame encoded as it renders
    bar.close()
    write_atomic(args.out, data, overwrite=args.force)
    say(
        f"wrote {args.out}: {args.turntable} frames of {size[0]}x{size[1]} at {FPS} frames/s "
        f"({mesh.name}, {scene.model})"
    )
    return 0


def run_per_pixel(args, scene, mesh, size, background, suffix: str) -> int:
    """``phong-explorer render --per-pixel``: write the per-pixel picture to ``args.out``."""
    if suffix != ".png":
        raise ExplorerError(f"--per-pixel draws a picture: give --out FILE.png, not {suffix}")
    if scene.material.opacity < 1.0:
        say(
            f"note: --per-pixel draws the nearest surface only (opacity "
            f"{scene.material.opacity:g} is not blended)",
            file=sys.stderr,
        )
    method = args.per_pixel_method or "raster"
    if method != "raster" and scene.material.maps():
        raise ExplorerError(
            f"--per-pixel-method {method} draws no texture maps (the G-buffer's (u, v) are the "
            "raster method's): leave --per-pixel-method out (raster) to draw "
            f"{', '.join(scene.material.maps())}"
        )
    if method == "raster" and mesh.n_faces > MAX_FACES:
        raise ExplorerError(
            f"--per-pixel: mesh {mesh.name!r} has {mesh.n_faces:,} triangles, more than a "
            f"picture of triangle indices tells apart ({MAX_FACES:,}); give --per-pixel-method "
            "raycast"
        )
    if method == "raster":
        image = picture(scene, mesh, size, background=background).rgb
        how = "rasterised"
    else:
        ref = reference(scene, mesh, size, method=method)
        image = ref.image(background)
        how = "exact sphere" if ref.hits.method == "sphere" else "ray cast"
    write_atomic(args.out, encode_png(image), overwrite=args.force)
    name = scene.material.name or "material"
    say(
        f"wrote {args.out}: {size[0]}x{size[1]} per-pixel picture ({mesh.name}, {how}, {name}, "
        f"{scene.model})"
    )
    return 0


def run_strip(args, scene, mesh, materials, background) -> int:
    """``phong-explorer render --strip``: the term strip
    (:func:`explorer.render.strip.render_strip`) to ``args.out``, and its caption."""
    tile = STRIP_TILE if args.tile is None else size_from_option(args.tile, "--tile")
    picture = render_strip(
        scene,
        mesh,
        tile=tile,
        mode=args.strip_mode,
        lights=args.strip_lights,
        background=background,
        materials=materials,  # (a mesh file's own: each group's tiles in its material)
    )
    write_atomic(args.out, encode_png(picture.image), overwrite=args.force)
    h, w = picture.image.shape[:2]
    name = scene.material.name or "material"
    if materials:
        name = f"{len(materials)} material{'s' if len(materials) != 1 else ''} of the file"
    rows = len(picture.rows)
    say(
        f"wrote {args.out}: {w}x{h} term strip, {rows} row{'s' if rows != 1 else ''} "
        f"({mesh.name}, {name}, {scene.model}, {args.strip_mode})"
    )
    say(picture.caption)
    return 0


def run_lobes(args, scene, mesh) -> int:
    """``phong-explorer render --lobes``: the lobe plots
    (:func:`explorer.analysis.lobeplot.scene_charts`) of the scene's material, each light at
    its incidence on the mesh's point that faces the viewer, to ``args.out``."""
    centre, _ = frame_of(mesh.positions)
    incidences = light_incidences(scene, centre)
    image = lobe_picture(scene_charts(scene, incidences))
    write_atomic(args.out, encode_png(image), overwrite=args.force)
    h, w = image.shape[:2]
    degrees = ", ".join(f"{math.degrees(t):.0f}°" for t in incidences)
    name = scene.material.name or "material"
    say(f"wrote {args.out}: {w}x{h} lobe plots ({name}, incidence {degrees})")
    return 0
