"""Options shared by the commands that build a scene (``render``, ``sheet``, ``gui``).

A SCENE file gives the material, lights, viewer and mesh; every option overrides its part of
it. Options are named after the scene-file keys: ``--light-position`` is ``lights[].position``,
``--viewer-eye`` is ``viewer.eye``, ``--model`` is ``model``. Any ``--light-*`` option replaces
the scene's lights with that one light.
"""

from __future__ import annotations

import argparse
import os

from explorer.core.errors import ExplorerError, Problem, ValidationError
from explorer.core.hdr import HDR, TONE_MAPS
from explorer.core.lights import parse_light
from explorer.core.presets import find_preset
from explorer.core.scene import Viewer
from explorer.core.validate import Checker
from explorer.geometry.meshes import BUILTIN_MESHES, RESOLUTION, get_mesh
from explorer.render.images import parse_size
from explorer.render.offscreen import BACKGROUND

#: --light-<key> options, in the scene file's light keys
LIGHT_OPTIONS = {
    "type": dict(choices=("directional", "point", "spot"), help="kind of light"),
    "direction": dict(
        nargs=3, type=float, metavar=("X", "Y", "Z"),
        help="directional: toward the light; spot: the axis it points along",
    ),
    "position": dict(nargs=3, type=float, metavar=("X", "Y", "Z"), help="point/spot position"),
    "attenuation": dict(
        nargs=3, type=float, metavar=("KC", "KL", "KQ"),
        help="point/spot: 1 / (kc + kl·d + kq·d²), default 1 0 0",
    ),
    "cutoff": dict(type=float, metavar="DEG", help="spot cone half-angle, 0-90 or 180"),
    "exponent": dict(type=float, metavar="E", help="spot exponent, 0-128"),
    "color": dict(nargs=3, type=float, metavar=("R", "G", "B"), help="light colour"),
    "intensity": dict(type=float, metavar="K", help="multiplies the colour (default 1)"),
}  # fmt: skip
_KEYS_OF = {
    "directional": {"type", "direction", "color", "intensity"},
    "point": {"type", "position", "attenuation", "color", "intensity"},
    "spot": {"type", "position", "attenuation", "direction", "cutoff", "exponent", "color",
             "intensity"},
}  # fmt: skip


# -- arguments -----------------------------------------------------------------------------


def add_scene_arguments(
    p: argparse.ArgumentParser, *, mesh_default: str | None, force: bool = True
) -> None:
    """The SCENE argument and the options that override its parts; ``force``: also
    ``--force`` (commands that write a file)."""
    p.add_argument("scene", nargs="?", metavar="SCENE", help="scene file (YAML); optional")
    p.add_argument(
        "--materials", action="append", default=[], metavar="DIR",
        help="extra preset directory, searched first (repeatable)",
    )  # fmt: skip

    p.add_argument(
        "--mesh", metavar="NAME|FILE", default=None,
        help=f"built-in mesh ({', '.join(BUILTIN_MESHES)}) or a mesh file (OBJ, STL, PLY, "
        f"OFF, GLB); default: the scene's mesh, else {mesh_default}",
    )  # fmt: skip
    p.add_argument(
        "--resolution", type=int, metavar="N",
        help="built-in mesh detail: sphere/torus segments, icosphere subdivisions, plane "
        "subdivisions, teapot samples per patch edge",
    )  # fmt: skip
    p.add_argument("--model", choices=("blinn", "phong"), help="specular model")
    p.add_argument(
        "--two-sided", action=argparse.BooleanOptionalAction, default=None,
        help="light back faces with the flipped normal",
    )  # fmt: skip
    g = p.add_argument_group("light (replaces the scene's lights with one light)")
    for key, kw in LIGHT_OPTIONS.items():
        g.add_argument(f"--light-{key}", dest=f"light_{key}", default=None, **kw)
    v = p.add_argument_group("viewer").add_mutually_exclusive_group()
    v.add_argument(
        "--viewer-eye", "--eye", dest="viewer_eye", nargs=3, type=float, metavar=("X", "Y", "Z"),
        help="local viewer at this point (perspective camera there, looking at the mesh)",
    )  # fmt: skip
    v.add_argument(
        "--viewer-direction", dest="viewer_direction", nargs=3, type=float,
        metavar=("X", "Y", "Z"),
        help="infinite viewer in this direction (parallel projection); default 0 0 1",
    )  # fmt: skip
    p.add_argument(
        "--background", nargs=3, type=float, metavar=("R", "G", "B"),
        help="background colour, each in [0, 1] (default 0.32 0.32 0.32)",
    )  # fmt: skip
    h = p.add_argument_group("HDR (scene key hdr: {exposure, tone_map}); either option turns it on")
    h.add_argument(
        "--exposure", type=float, metavar="STOPS", default=None,
        help="HDR exposure in stops, -16 to 16 (colour x 2**STOPS; default 0)",
    )  # fmt: skip

    h.add_argument(
        "--tone-map", dest="tone_map", choices=TONE_MAPS, default=None,
        help="HDR tone map (default reinhard); the result is sRGB-encoded",
    )  # fmt: skip
    if force:
        p.add_argument("--force", action="store_true", help="replace the output file if it exists")


# -- building the scene --------------------------------------------------------------------


def light_from_options(args):
    """The --light-* options as one light, or None when none is given."""

    given = {k: getattr(args, f"light_{k}") for k in LIGHT_OPTIONS}
    given = {k: v for k, v in given.items() if v is not None}
    if not given:
        return None
    kind = given.get("type")
    if kind is None:
        if "cutoff" in given or "exponent" in given:
            kind = "spot"
        elif "position" in given or "attenuation" in given:
            kind = "point"
        else:
            kind = "directional"
    wrong = sorted(set(given) - _KEYS_OF[kind])
    if wrong:
        flags = ", ".join(f"--light-{k}" for k in wrong)
        fits = ", ".join(t for t, keys in _KEYS_OF.items() if set(wrong) <= keys)
        raise ExplorerError(
            f"{flags} does not apply to a {kind} light" + (f" (only to: {fits})" if fits else "")
        )
    mapping = {k: (list(v) if isinstance(v, list) else v) for k, v in given.items()}
    mapping["type"] = kind
    checker = Checker(None)
    light = parse_light(mapping, checker, ())
    if checker.problems:
        raise ValidationError([as_flag(p, "--light-") for p in checker.problems])
    return light


def as_flag(problem: Problem, prefix: str) -> Problem:
    key = problem.key or ""
    head = key.split("[")[0].split(".")[0]
    where = f"{prefix}{head}" if head else prefix.rstrip("-")
    return Problem(problem.message, key=where)


def viewer_from_options(args):

    try:
        if args.viewer_eye is not None:
            return Viewer(eye=tuple(args.viewer_eye))
        if args.viewer_direction is not None:
            return Viewer(direction=tuple(args.viewer_direction))
    except ValueError as exc:
        flag = "--viewer-eye" if args.viewer_eye is not None else "--viewer-direction"
        raise ExplorerError(f"{flag}: {exc}") from None
    return None


def background_from_options(args):

    if args.background is None:
        return BACKGROUND
    if not all(0.0 <= c <= 1.0 for c in args.background):
        raise ExplorerError(f"--background: each of R G B must be in [0, 1], got {args.background}")
    return tuple(args.background)


def build_scene(args, *, default_light=None):
    """The scene of a render/sheet command: the SCENE file (or the defaults) with the
    command-line options applied. Returns (scene, mesh)."""
    import explorer

    dirs = tuple(args.materials)
    for d in dirs:
        if not os.path.isdir(d):
            raise ExplorerError(f"--materials: {d!r} is not a directory")
    scene = explorer.load_scene(args.scene, materials_dirs=dirs) if args.scene else None
    if scene is None:
        scene = explorer.Scene()
        if default_light is not None:
            scene = scene.replace(lights=(default_light,))
    changes: dict = {}
    preset = getattr(args, "preset", None)
    if isinstance(preset, str):
        material = find_preset(preset, dirs)
        changes["material"] = material
        if material.model is not None:
            changes["model"] = material.model
    if args.model is not None:
        changes["model"] = args.model
    if args.two_sided is not None:
        changes["two_sided"] = args.two_sided
    light = light_from_options(args)
    if light is not None:
        changes["lights"] = (light,)
    viewer = viewer_from_options(args)
    if viewer is not None:
        changes["viewer"] = viewer
    if args.exposure is not None or args.tone_map is not None:
        old = scene.hdr or HDR()
        try:
            changes["hdr"] = HDR(
                exposure=old.exposure if args.exposure is None else args.exposure,
                tone_map=old.tone_map if args.tone_map is None else args.tone_map,
            )
        except ValueError as exc:
            raise ExplorerError(f"--exposure: {exc}") from None
    scene = scene.replace(**changes)
    spec = args.mesh if args.mesh is not None else scene.mesh
    if spec is None:
        spec = args.mesh_default
    if args.resolution is not None and RESOLUTION.get(str(spec)) is None:
        have = ", ".join(n for n, r in RESOLUTION.items() if r is not None)
        raise ExplorerError(
            f"--resolution applies to the built-in meshes {have}; not to {str(spec)!r}"
        )
    return scene, get_mesh(spec, args.resolution)


def check_out(path: str, suffixes: tuple[str, ...], force: bool) -> str:
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in suffixes:
        raise ExplorerError(f"--out {path!r}: the file name must end in {' or '.join(suffixes)}")
    if os.path.isdir(path):
        raise ExplorerError(f"--out {path!r}: is a directory; give a file name")
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise ExplorerError(f"--out {path!r}: directory {parent!r} does not exist")
    if os.path.exists(path) and not force:
        raise ExplorerError(f"--out {path!r}: already exists; use --force to replace it")
    return suffix


def size_from_option(text: str, flag: str) -> tuple[int, int]:

    try:
        return parse_size(text)
    except ExplorerError as exc:
        raise ExplorerError(f"{flag} {text}: {exc}") from None
