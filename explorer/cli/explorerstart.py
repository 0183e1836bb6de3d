"""The explorer's start from the command line, shared by the ``gui`` and ``web`` commands: the
scene, mesh and preset their options name, or a saved session."""

from __future__ import annotations

import argparse
import os
import sys

from explorer.app import session as S
from explorer.app import start as gui
from explorer.app.effectactions import set_shading
from explorer.cli.options import build_scene
from explorer.core.errors import ExplorerError
from explorer.core.lights import PointLight
from explorer.core.text import printable, say
from explorer.geometry.meshes import get_mesh


def add_preset_option(p: argparse.ArgumentParser) -> None:
    """``--preset NAME``: the explorer's start preset."""
    p.add_argument(
        "--preset", metavar="NAME",
        help=f"start preset (overrides the scene's material; default {gui.DEFAULT_PRESET})",
    )  # fmt: skip


def add_shading_option(p: argparse.ArgumentParser) -> None:
    """``--per-pixel``: the view lit per pixel (the scene and session key ``shading``)."""
    p.add_argument(
        "--per-pixel",
        action="store_true",
        help="light every pixel of the view (the engine at each pixel's surface point, as "
        "render --per-pixel; the scene key shading: per-pixel); the panel's shading row "
        "switches back",
    )


def start(args):
    """The explorer's start from the command line: ``(scene, mesh, preset name)``.

    Without a SCENE file the start is :data:`explorer.app.start.DEFAULT_PRESET` on the teapot
    under one point light placed at :data:`explorer.app.model.DEFAULT_PLACEMENT`
    (:func:`explorer.app.start.default_light`), seen from a
    local viewer (a perspective camera); built-in meshes get the explorer's finer resolutions
    (:data:`explorer.app.start.MESH_CHOICES`) unless ``--resolution`` is given, with their
    (u, v) as the mesh chooser loads them (:func:`explorer.app.start.load_mesh_choice`), so the
    material tab's texture maps can be chosen for the start's mesh too.
    """
    if args.scene is None and args.preset is None:
        args.preset = gui.DEFAULT_PRESET
    args.mesh_default = gui.DEFAULT_MESH
    placeholder = PointLight(position=(0.0, 0.0, 0.0), diffuse=(1.0, 1.0, 1.0))
    scene, mesh = build_scene(args, default_light=placeholder)
    spec = args.mesh if args.mesh is not None else (scene.mesh or gui.DEFAULT_MESH)
    scene = scene.replace(mesh=spec)  # the state names the mesh shown
    if args.resolution is None and spec in gui.MESH_CHOICES:
        mesh = get_mesh(spec, gui.MESH_CHOICES[spec], uv=True)  # (maps can be chosen later)
    if scene.lights == (placeholder,):  # no scene lights and no --light-* option
        scene = scene.replace(lights=(gui.default_light(mesh),))
    if args.scene is None and args.viewer_eye is None and args.viewer_to_viewer is None:
        scene = scene.replace(viewer=gui.default_viewer(mesh))
    preset = args.preset if isinstance(args.preset, str) else scene.material.name
    return scene, mesh, preset


def start_state(args, warnings: list | None = None):
    """``(state, mesh)``: a session (``--session``, ``--last``) or :func:`start`'s, lit per
    pixel with ``--per-pixel``."""
    state, mesh = _start_state(args, warnings)
    if getattr(args, "per_pixel", False):
        state = set_shading(state, "per-pixel")
    return state, mesh


def _start_state(args, warnings: list | None = None):
    """``(state, mesh)``: a session (``--session``, ``--last``) or :func:`start`'s; a mesh
    file's own materials are shown unless ``--preset`` is given (as ``render`` does). The
    warnings of the mesh's materials are printed, and appended to ``warnings`` when given (the
    front end shows them in its message log too)."""
    dirs = tuple(args.materials_dirs)
    if getattr(args, "last", False):
        path = S.last_session_path()
        try:  # what is there is read, or refused, by the checked open
            os.lstat(path)
        except FileNotFoundError:
            raise ExplorerError(f"--last: no session kept yet ({path} does not exist)") from None
        except (OSError, ValueError) as exc:  # its folder cannot be searched, a name too long
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise ExplorerError(f"--last: cannot read the last session {path}: {reason}") from None
        return S.load_session(path, materials_dirs=dirs)
    if getattr(args, "session", None) is not None:
        return S.load_session(args.session, materials_dirs=dirs)
    own = not isinstance(args.preset, str)  # --preset overrides the mesh's own materials
    scene, mesh, preset = start(args)
    state = gui.first_state(scene, mesh, preset=preset, materials_dirs=dirs,
                            resolution=args.resolution)  # fmt: skip
    state, found = gui.add_mesh_materials(state, mesh, use=own)
    for w in found:
        say(f"warning: {printable(w)}", file=sys.stderr)
    if warnings is not None:
        warnings.extend(found)
    return state, mesh
