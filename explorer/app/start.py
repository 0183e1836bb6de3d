"""What the explorer starts from, and whether a window can open here: no Qt, VTK or PyVista.

The defaults (preset, mesh, light placement, camera distance), the meshes the chooser offers,
the first :class:`~explorer.app.model.State` for a scene and a mesh, and the no-display check
with its one-line message (the ``gui`` command exits with :data:`NO_DISPLAY_STATUS`).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import os
import sys

import numpy as np

from explorer.app.model import (
    DEFAULT_PLACEMENT,
    MeshMaterials,
    State,
    check_window_lights,
    with_mesh_materials,
)
from explorer.core.errors import ExplorerError
from explorer.core.lights import PointLight
from explorer.core.material import Material
from explorer.core.presets import find_preset, list_presets
from explorer.core.scene import Scene, Viewer, load_scene
from explorer.geometry.filematerials import group_materials
from explorer.geometry.meshes import Mesh, get_mesh

#: built-in meshes offered by the mesh chooser, with the resolution the explorer uses
MESH_CHOICES: dict[str, int | None] = {
    "teapot": 24,
    "sphere": 128,
    "icosphere": 5,
    "torus": 128,
    "cube": None,
    "plane": 64,
}
DEFAULT_PRESET = "gold"
DEFAULT_MESH = "teapot"
#: where the start camera sits (a local viewer): direction from the mesh centre, and the
#: distance in mesh radii
DEFAULT_EYE_DIRECTION = (0.0, 0.3, 1.0)
DEFAULT_EYE_DISTANCE = 6.5
#: the window's title (the real-window test finds the window by it) and default size
TITLE = "phong-explorer"
WINDOW_SIZE = (1100, 720)
#: the smallest window the panel lays itself out in without clipping
MIN_WINDOW_SIZE = (640, 480)
#: exit status when no window can be opened
NO_DISPLAY_STATUS = 3


class NoDisplayError(ExplorerError):
    """No window can be opened here (no X display, or VTK forced off-screen)."""


def load_mesh_choice(name: str, resolution: int | None = None) -> Mesh:
    """A chooser's mesh: a built-in name at the explorer's resolution, or a file. A built-in
    mesh comes with its (u, v) (:mod:`explorer.geometry.uv`: a few more vertices where the
    texture's seams split them, the same triangles and colours), so that a material chosen
    after it can wear a texture map."""
    if resolution is None:
        resolution = MESH_CHOICES.get(name)
    return get_mesh(name, resolution, uv=True)


def default_viewer(mesh: Mesh) -> Viewer:
    """The start camera: :data:`DEFAULT_EYE_DISTANCE` radii from the mesh centre."""
    e = np.asarray(DEFAULT_EYE_DIRECTION, dtype=np.float64)
    eye = mesh.centre + DEFAULT_EYE_DISTANCE * (mesh.radius or 1.0) * e / np.linalg.norm(e)
    return Viewer(eye=tuple(float(c) for c in eye))


def default_light(mesh: Mesh) -> PointLight:
    """The start's light: a white point light at :data:`~explorer.app.model.DEFAULT_PLACEMENT`
    (its distance in mesh radii) around the mesh centre."""
    az, el, d = DEFAULT_PLACEMENT
    return PointLight().placed(az, el, d * (mesh.radius or 1.0), mesh.centre)


def first_state(
    scene: Scene, mesh: Mesh, *, name: str | None = None, preset: str | None = None,
    materials_dirs=(), resolution: int | None = None,
) -> State:  # fmt: skip
    """The explorer's state for ``scene`` on ``mesh`` (shown as ``name`` in the mesh
    chooser, default the mesh's name; ``resolution`` its built-in resolution, None for the
    explorer's), under preset ``preset`` (marked clean when the library's
    preset of that name has this material)."""
    check_window_lights(len(scene.lights))
    name = name or scene.mesh or mesh.name
    clean = None
    if preset is not None:
        for info in list_presets(materials_dirs):
            if info.name == preset:
                clean = info.material
                break
    return State(
        scene=scene.replace(mesh=scene.mesh or name),
        mesh=name,
        resolution=resolution,
        centre=tuple(float(c) for c in mesh.centre),
        radius=float(mesh.radius or 1.0),
        preset=preset,
        preset_material=clean,
        mesh_uv=mesh.uv is not None,
    )


def notebook_state(
    scene=None, *, preset: str | None = DEFAULT_PRESET, mesh: str = DEFAULT_MESH, materials_dirs=()
) -> tuple[State, Mesh]:
    """``(state, mesh)`` for the notebook's explorer (:func:`explorer.app.web.show`): ``scene``
    (a Scene, a scene file or a mapping; None: one point light at
    :data:`~explorer.app.model.DEFAULT_PLACEMENT` seen from the explorer's start camera) on
    built-in mesh ``mesh``, in preset ``preset`` (None: the scene's material)."""
    m = load_mesh_choice(mesh)
    if scene is None:
        scene = Scene(lights=(default_light(m),), viewer=default_viewer(m))
    else:
        scene = load_scene(scene, materials_dirs=materials_dirs)
    if preset is not None:
        scene = scene.replace(material=find_preset(preset, materials_dirs))
    scene = scene.replace(mesh=mesh)
    state = first_state(scene, m, name=mesh, preset=preset, materials_dirs=materials_dirs)
    return state, m


def read_mesh_materials(mesh: Mesh, fallback: Material) -> tuple[MeshMaterials | None, list]:
    """``(materials, warnings)``: the materials ``mesh``'s file brings (an OBJ's ``usemtl``
    groups read from its ``mtllib``; ``fallback`` for a group no library defines), or None
    when it brings none; the .mtl reader's warnings, one sentence each. A library with a
    problem raises its :class:`~explorer.core.mtl.MtlError` (file and line)."""
    materials, warnings = group_materials(mesh, fallback)
    if not materials or all(m is fallback for m in materials):
        return None, warnings
    sizes = np.bincount(mesh.groups.of_vertex, minlength=len(materials))
    found = MeshMaterials(mesh.name, tuple(mesh.groups.names), tuple(materials),
                          int(np.argmax(sizes)))  # fmt: skip
    return found, warnings


def add_mesh_materials(state: State, mesh: Mesh, *, use: bool = True) -> tuple[State, list]:
    """``(state, warnings)``: ``state`` with the materials its mesh file brings
    (:func:`read_mesh_materials`, the state's material for groups no library defines), shown
    when ``use``."""
    found, warnings = read_mesh_materials(mesh, state.material)
    return with_mesh_materials(state, found, use=use), warnings


def no_display_reason(environ=None) -> str | None:
    """Why no window can open here, or None when it looks possible (Linux / X11 only; other
    systems are left to Qt)."""
    env = os.environ if environ is None else environ
    if sys.platform in ("darwin", "win32"):
        return None
    forced = env.get("VTK_DEFAULT_OPENGL_WINDOW", "")
    if forced and forced not in ("vtkXOpenGLRenderWindow", "vtkGenericOpenGLRenderWindow"):
        return f"VTK_DEFAULT_OPENGL_WINDOW={forced} makes VTK render off-screen only"
    platform = env.get("QT_QPA_PLATFORM", "")
    if platform and not platform.startswith("xcb"):
        return f"QT_QPA_PLATFORM={platform} cannot show the 3D view (it needs xcb)"
    display = env.get("DISPLAY")
    if not display:
        return "no display (DISPLAY is not set)"
    if not _x_display_opens(display):
        return f"cannot open the X display {display!r}"
    return None


def no_display_message(reason: str) -> str:
    """The one line printed when no window can open: why, and what to run instead."""
    return (
        f"phong-explorer: {reason}, so the explorer window cannot open; for pictures run "
        "'phong-explorer render --out FILE.png' (off-screen), or give the window a virtual "
        "display: 'xvfb-run -s \"-screen 0 1280x900x24\" phong-explorer gui'"
    )


def _x_display_opens(display: str) -> bool:
    """True if Xlib can connect to ``display`` (True when libX11 is not found: Qt decides)."""
    name = ctypes.util.find_library("X11")
    if not name:
        return True
    try:
        x11 = ctypes.CDLL(name)
    except OSError:
        return True
    x11.XOpenDisplay.restype = ctypes.c_void_p
    x11.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x11.XCloseDisplay.argtypes = [ctypes.c_void_p]
    handle = x11.XOpenDisplay(display.encode())
    if not handle:
        return False
    x11.XCloseDisplay(handle)
    return True


def start_xvfb(size=(1280, 900)):
    """A private Xvfb server for scripts, benchmarks and tests: ``(process, ":N")``, the
    display number chosen by the server. On Linux the server ends with the calling process
    (``PR_SET_PDEATHSIG``), even when that one crashes."""
    import signal
    import subprocess

    def die_with_parent():
        try:
            ctypes.CDLL("libc.so.6").prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        except OSError:
            pass

    r, w = os.pipe()
    proc = subprocess.Popen(
        ["Xvfb", "-displayfd", str(w), "-screen", "0", "{}x{}x24".format(*size), "-nolisten",
         "tcp"], pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        preexec_fn=die_with_parent if sys.platform.startswith("linux") else None,
    )  # fmt: skip
    os.close(w)
    with os.fdopen(r) as f:
        number = f.readline().strip()
    if not number:
        proc.terminate()
        raise ExplorerError("Xvfb did not start")
    return proc, f":{number}"


def round_sig(x: float, digits: int = 3) -> float:
    """``x`` rounded to ``digits`` significant digits (0 stays 0)."""
    if x == 0 or not math.isfinite(x):
        return float(x)
    return float(f"{x:.{digits}g}")


def free_name(stem: str, taken) -> str:
    """The first of ``stem_1``, ``stem_2``, ... not in ``taken``."""
    taken = set(taken)
    i = 1
    while f"{stem}_{i}" in taken:
        i += 1
    return f"{stem}_{i}"
