"""Options shared by the commands that build a scene (``render``, ``sheet``, ``gui``).

A SCENE file gives the material, lights, viewer and mesh; every option overrides its part of
it. Options are named after the scene-file keys: ``--light-position`` is ``lights[].position``,
``--light-to-light`` is ``lights[].to_light``, ``--viewer-eye`` is ``viewer.eye``, ``--model`` is
``model``. Any ``--light-*`` option replaces the scene's lights with that one light. The old
``--light-direction`` (``--light-to-light`` or ``--light-aim`` by the light's type) and
``--viewer-direction`` still work, with a notice.
"""

from __future__ import annotations

import argparse
import os
import stat
import sys

import numpy as np

from explorer.core.atomic import UnwritableFile, check_target
from explorer.core.errors import ExplorerError, Problem, ValidationError
from explorer.core.hdr import HDR, TONE_MAPS
from explorer.core.lights import LIGHT_CLASSES, LIGHT_TYPES, parse_light
from explorer.core.material import MODELS
from explorer.core.mtl import MtlError
from explorer.core.presets import find_preset
from explorer.core.scene import COLOR_CONTROLS, Scene, Viewer, load_scene
from explorer.core.text import printable, say
from explorer.core.validate import Checker, notice
from explorer.geometry.filematerials import group_materials
from explorer.geometry.meshes import BUILTIN_MESHES, RESOLUTION, get_mesh
from explorer.render.images import parse_size
from explorer.render.offscreen import BACKGROUND

_XYZ = dict(nargs=3, type=float, metavar=("X", "Y", "Z"))
#: --light-<key> options, in the scene file's light keys
LIGHT_OPTIONS = {
    "type": dict(choices=LIGHT_TYPES, help="kind of light"),
    "to_light": dict(_XYZ, help="directional: the direction toward the light"),
    "position": dict(_XYZ, help="point/spot position"),
    "attenuation": dict(
        nargs=3, type=float, metavar=("KC", "KL", "KQ"),
        help="point/spot: 1 / (kc + kl·d + kq·d²), default 1 0 0",
    ),
    "aim": dict(_XYZ, help="spot: the axis it shines along, from the light outward"),
    "cutoff": dict(type=float, metavar="DEG", help="spot cone half-angle, 0-90 or 180"),
    "exponent": dict(type=float, metavar="E", help="spot exponent, 0-128"),
    "color": dict(nargs=3, type=float, metavar=("R", "G", "B"), help="light colour"),
    "intensity": dict(type=float, metavar="K", help="multiplies the colour (default 1)"),
}  # fmt: skip
#: the --light-* keys each light type takes
_KEYS_OF = {
    kind: {k for k in cls.FILE_KEYS if k in LIGHT_OPTIONS} for kind, cls in LIGHT_CLASSES.items()
}
#: keys that only a spot takes, or only a positional light: they decide the type when
#: --light-type is not given
_SPOT_ONLY = _KEYS_OF["spot"] - _KEYS_OF["point"] - _KEYS_OF["directional"]
_POSITIONAL = (_KEYS_OF["point"] & _KEYS_OF["spot"]) - _KEYS_OF["directional"]


def _flag(key: str) -> str:
    return "--light-" + key.replace("_", "-")


class _OldName(argparse.Action):
    """An option's old name: stores like the new one, with one notice."""

    NEW = {"--viewer-direction": ("--viewer-to-viewer", "the direction toward the viewer")}

    def __call__(self, parser, namespace, values, option_string=None):
        new, meaning = self.NEW[option_string]
        notice(f"{option_string} is now {new} ({meaning}); the old name still works")
        setattr(namespace, self.dest, values)


# -- arguments -----------------------------------------------------------------------------


def add_materials_dir_option(p: argparse.ArgumentParser, dest: str = "materials_dirs") -> None:
    """``--materials-dir DIR`` (repeatable; ``--materials`` is the same option): extra preset
    directories, searched before the user's and the built-in ones (``materials_dirs`` in the
    Python API)."""
    p.add_argument(
        "--materials-dir", "--materials", dest=dest, action="append", default=[], metavar="DIR",
        help="extra preset directory, searched first (repeatable)",
    )  # fmt: skip


def model_list(text: str) -> tuple[str, ...]:
    """``--model a,b``: the names, each one of MODELS, no repeats (argparse's type)."""
    names = tuple(t.strip() for t in text.split(","))
    bad = [n for n in names if n not in MODELS]
    if bad or len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(
            f"expected names from {', '.join(MODELS)}, comma-separated, each once; got {text!r}"
        )
    return names


def add_scene_arguments(
    p: argparse.ArgumentParser,
    *,
    mesh_default: str | None,
    force: bool = True,
    models: bool = False,
) -> None:
    """The SCENE argument and the options that override its parts; ``force``: also
    ``--force`` (commands that write a file); ``models``: ``--model`` takes a comma-separated
    list (a tuple of names; the sheet draws each material under each)."""
    p.add_argument("scene", nargs="?", metavar="SCENE", help="scene file (YAML); optional")
    add_materials_dir_option(p)

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
    if models:
        p.add_argument(
            "--model", type=model_list, metavar="MODEL[,MODEL...]",
            help=f"specular model(s), side by side: {', '.join(MODELS)} (e.g. blinn,threejs)",
        )  # fmt: skip
    else:
        p.add_argument("--model", choices=MODELS, help="specular model")
    p.add_argument(
        "--two-sided", action=argparse.BooleanOptionalAction, default=None,
        help="light back faces with the flipped normal",
    )  # fmt: skip
    g = p.add_argument_group("light (replaces the scene's lights with one light)")
    for key, kw in LIGHT_OPTIONS.items():
        g.add_argument(_flag(key), dest=f"light_{key}", default=None, **kw)
    g.add_argument(
        "--light-direction", dest="light_direction", default=None, **_XYZ,
        help="old name of --light-to-light (directional) and --light-aim (spot)",
    )  # fmt: skip
    v = p.add_argument_group("viewer").add_mutually_exclusive_group()
    v.add_argument(
        "--viewer-eye", "--eye", dest="viewer_eye", nargs=3, type=float, metavar=("X", "Y", "Z"),
        help="local viewer at this point (perspective camera there, looking at the mesh)",
    )  # fmt: skip
    v.add_argument(
        "--viewer-to-viewer", dest="viewer_to_viewer", **_XYZ,
        help="infinite viewer: the direction from the scene toward it (parallel projection); "
        "default 0 0 1",
    )  # fmt: skip
    v.add_argument(
        "--viewer-direction", dest="viewer_to_viewer", action=_OldName, **_XYZ,
        help="old name of --viewer-to-viewer",
    )  # fmt: skip
    p.add_argument(
        "--background", nargs=3, type=float, metavar=("R", "G", "B"),
        help="background colour, each in [0, 1] (default 0.32 0.32 0.32)",
    )  # fmt: skip
    t = p.add_argument_group("texture (docs/formats.md)")
    t.add_argument(
        "--diffuse-map",
        dest="diffuse_map",
        metavar="IMG",
        default=None,
        help="the material's diffuse_map: a PNG or JPEG image the surface wears (GL_MODULATE)",
    )
    t.add_argument(
        "--color-control",
        dest="color_control",
        choices=COLOR_CONTROLS,
        default=None,
        help="how a texture meets the highlight: single (OpenGL's default: the texture "
        "darkens it) or separate (GL_SEPARATE_SPECULAR_COLOR: added after the texture)",
    )
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
    old = getattr(args, "light_direction", None)
    if not given and old is None:
        return None
    kind = given.get("type")
    if kind is None:
        if set(given) & _SPOT_ONLY:
            kind = "spot"
        elif set(given) & _POSITIONAL:
            kind = "point"
        else:
            kind = "directional"
    if old is not None:
        new = LIGHT_CLASSES[kind].RENAMED.get("direction")
        if new is None:
            given["direction"] = old  # reported below: it does not apply to this type
        elif new[0] in given:
            raise ExplorerError(f"--light-direction is the old name of {_flag(new[0])}: give one")
        else:
            notice(f"--light-direction is now {_flag(new[0])} ({new[1]}); the old name still works")
            given[new[0]] = old
    wrong = sorted(set(given) - _KEYS_OF[kind])
    if wrong:
        flags = ", ".join(_flag(k) for k in wrong)
        fits = ", ".join(
            t for t, cls in LIGHT_CLASSES.items() if set(wrong) <= _KEYS_OF[t] | set(cls.RENAMED)
        )
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
    head = key.split("[")[0].split(".")[0].replace("_", "-")
    where = f"{prefix}{head}" if head else prefix.rstrip("-")
    return Problem(problem.message, key=where)


def viewer_from_options(args):
    """The --viewer-* options as a viewer, or None when none is given."""
    try:
        if args.viewer_eye is not None:
            return Viewer(eye=tuple(args.viewer_eye))
        if args.viewer_to_viewer is not None:
            return Viewer(to_viewer=tuple(args.viewer_to_viewer))
    except ValueError as exc:
        flag = "--viewer-eye" if args.viewer_eye is not None else "--viewer-to-viewer"
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
    materials_dirs = tuple(args.materials_dirs)
    for d in materials_dirs:
        try:
            is_dir = stat.S_ISDIR(os.stat(d).st_mode)
        except FileNotFoundError:
            raise ExplorerError(f"--materials-dir: {d!r} does not exist") from None
        except (OSError, ValueError) as exc:  # a folder on the way locked, a name too long
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
            raise ExplorerError(f"--materials-dir: {d!r}: cannot read it: {reason}") from None
        if not is_dir:
            raise ExplorerError(f"--materials-dir: {d!r} is not a directory")
    scene = load_scene(args.scene, materials_dirs=materials_dirs) if args.scene else None
    if scene is None:
        scene = Scene()
        if default_light is not None:
            scene = scene.replace(lights=(default_light,))
    changes: dict = {}
    preset = getattr(args, "preset", None)
    if isinstance(preset, str):
        material = find_preset(preset, materials_dirs)
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
        except ValidationError as exc:
            raise ValidationError([as_flag(p, "--") for p in exc.problems]) from None
    diffuse_map = getattr(args, "diffuse_map", None)
    if diffuse_map is not None:
        material = changes.get("material", scene.material)
        changes["material"] = material.replace(diffuse_map=os.path.expanduser(diffuse_map))
    if getattr(args, "color_control", None) is not None:
        changes["color_control"] = args.color_control
    scene = scene.replace(**changes)
    spec = args.mesh if args.mesh is not None else scene.mesh
    if spec is None:
        spec = args.mesh_default
    if args.resolution is not None and RESOLUTION.get(str(spec)) is None:
        have = ", ".join(n for n, r in RESOLUTION.items() if r is not None)
        raise ExplorerError(
            f"--resolution applies to the built-in meshes {have}; not to {str(spec)!r}"
        )
    return scene, get_mesh(spec, args.resolution, uv=bool(scene.material.maps()))


def check_out(path: str, suffixes: tuple[str, ...], force: bool) -> str:
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in suffixes:
        raise ExplorerError(f"--out {path!r}: the file name must end in {' or '.join(suffixes)}")
    try:  # what no --force replaces: a folder, a FIFO, a device; a name too long...
        check_target(os.path.abspath(path), overwrite=True)
    except UnwritableFile as exc:
        raise ExplorerError(f"--out {path!r}: {exc.reason}") from None
    if os.path.lexists(path) and not force:
        raise ExplorerError(f"--out {path!r}: already exists; use --force to replace it")
    return suffix


def size_from_option(text: str, flag: str) -> tuple[int, int]:

    try:
        return parse_size(text)
    except ExplorerError as exc:
        raise ExplorerError(f"{flag} {text}: {exc}") from None


def mesh_materials(args, scene, mesh):
    """``(scene, materials)``: the materials of a mesh file's groups (an OBJ's ``usemtl``
    groups, read from its ``mtllib``), one per group, or None when the mesh has none or
    ``--preset`` gives the material. With materials, the scene's material becomes that of the
    largest group (its opacity is the picture's); every warning of the .mtl reader is printed.
    """
    if mesh.groups is None or isinstance(getattr(args, "preset", None), str):
        return scene, None
    try:
        materials, warnings = group_materials(mesh, scene.material)
    except MtlError as exc:
        raise MtlError(f"{exc}: give --preset NAME to draw the mesh in one preset") from None
    for w in warnings:
        say(f"warning: {printable(w)}", file=sys.stderr)
    sizes = np.bincount(mesh.groups.of_vertex, minlength=len(materials))
    main = materials[int(np.argmax(sizes))]
    opacities = {m.opacity for m, size in zip(materials, sizes, strict=True) if size}
    if len(opacities) > 1:
        say(
            f"warning: {mesh.name}: its materials' opacities differ "
            f"({', '.join(f'{o:g}' for o in sorted(opacities))}); the whole mesh is drawn "
            f"with {main.opacity:g}",
            file=sys.stderr,
        )
    return scene.replace(material=main), materials
