"""``phong-explorer sheet``: every preset in one labelled grid.

::

    phong-explorer sheet --out presets.png --mesh teapot --columns 6 --tile 200x200
    phong-explorer sheet --out models.png --model blinn,threejs --preset bronze --preset chrome

``--strip`` draws each preset as a row of its terms instead (``emission | ambient | diffuse |
specular | sum | overflow``, :mod:`explorer.render.strip`), ``--strip-mode raw`` the light sums
alone. ``--model a,b`` draws each preset under each model, side by side (the same numbers under
OpenGL's Blinn-Phong and three.js's MeshPhongMaterial, say).

A mesh file with its own materials (an OBJ's ``mtllib``) gets a first tile in them, each
``usemtl`` group in its own material, before the presets; with ``--preset`` only the presets
named are drawn.
"""

from __future__ import annotations

import argparse

from explorer.cli.options import (
    add_scene_arguments,
    background_from_options,
    build_scene,
    check_out,
    mesh_materials,
    size_from_option,
)
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError
from explorer.core.lights import DirectionalLight
from explorer.core.presets import find_preset, list_presets
from explorer.core.text import say
from explorer.render.images import encode_png
from explorer.render.offscreen import SHEET_LIGHT_DIRECTION, sheet
from explorer.render.strip import OVERFLOW_NOTE, strip_picture
from explorer.shading.strip import MODES as STRIP_MODES


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", required=True, metavar="FILE.png", help="output picture (.png)")
    p.add_argument(
        "--preset", action="append", default=None, metavar="NAME",
        help="only these presets, in this order (repeatable); default: every preset",
    )  # fmt: skip
    p.add_argument("--columns", type=int, default=6, metavar="N", help="tiles per row (6)")
    p.add_argument("--tile", default="200x150", metavar="WxH", help="tile size (200x150)")
    p.add_argument(
        "--strip",
        action="store_true",
        help="each preset as a row of its terms: emission | ambient | diffuse | specular | "
        "sum | overflow (one --tile each)",
    )
    p.add_argument(
        "--strip-mode",
        choices=STRIP_MODES,
        default="weighted",
        help="with --strip: weighted (k·A, k·D, k·S) or raw (the light sums A, D, S alone)",
    )
    add_scene_arguments(p, mesh_default="teapot", models=True)


def run(args) -> int:

    check_out(args.out, (".png",), args.force)
    tile = size_from_option(args.tile, "--tile")
    if args.columns < 1:
        raise ExplorerError(f"--columns must be at least 1, got {args.columns}")
    if args.diffuse_map is not None:
        raise ExplorerError("--diffuse-map: the sheet draws each preset untextured; use render")
    background = background_from_options(args)
    args.mesh_default = "teapot"
    chosen = args.preset
    args.preset = None  # the sheet's --preset selects tiles; it does not set the material
    models, args.model = args.model, None  # each tile's model: the sheet's, else its own
    scene, mesh = build_scene(args, default_light=DirectionalLight(to_light=SHEET_LIGHT_DIRECTION))
    materials_dirs = tuple(args.materials_dirs)
    if chosen:
        items = [(name, find_preset(name, materials_dirs)) for name in chosen]
    else:
        items = [(info.name, info.material) for info in list_presets(materials_dirs)]
        _, own = mesh_materials(args, scene, mesh)
        if own:
            items.insert(0, (f"{mesh.name} (its materials)", own))
    if args.strip:
        return run_strip(args, items, scene, mesh, tile, background, models)
    image = sheet(
        items, scene, mesh, tile=tile, columns=args.columns, background=background,
        model=models,
    )  # fmt: skip
    write_atomic(args.out, encode_png(image), overwrite=args.force)
    h, w = image.shape[:2]
    under = f" under {', '.join(models)}" if models else ""
    say(f"wrote {args.out}: {len(items)} presets{under} on {mesh.name}, {w}x{h}")
    return 0


def run_strip(args, items, scene, mesh, tile, background, models) -> int:
    """``sheet --strip``: a strip row per preset (and per model of ``--model``)."""
    rows = []
    for name, material in items:
        own = material if isinstance(material, tuple) else None  # (the file's, one per group)
        first = material[0] if own else material
        for m in models or (None,):
            label = name if m is None else f"{name} · {m}"
            model = m or first.model or scene.model
            rows.append((label, scene.replace(material=first, model=model), own))
    picture = strip_picture(
        rows, mesh, tile=tile, mode=args.strip_mode, background=background, note=OVERFLOW_NOTE
    )
    write_atomic(args.out, encode_png(picture.image), overwrite=args.force)
    h, w = picture.image.shape[:2]
    say(f"wrote {args.out}: term strips of {len(rows)} presets on {mesh.name}, {w}x{h}")
    return 0
