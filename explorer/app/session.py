"""Sessions: the explorer's state as a file, and back.

A session file is YAML (or JSON, which YAML reads too)::

    session: 1                 # the format
    scene: {...}               # the scene-file schema: material, model, lights, viewer, mesh
    mesh: teapot               # the mesh chooser's name (a built-in name or a file path)
    resolution: null           # a built-in mesh's resolution (null: the explorer's)
    preset: gold               # the preset the material came from, or null
    hidden: [specular]         # terms not drawn (and maps turned off: diffuse_map...)
    light: 1                   # the light the controls move (1 is the first)
    handle_distance: 2.5       # where a directional light's handle sits, in mesh radii
    camera: {position: [..], focal_point: [..], view_up: [..], parallel: false,
             parallel_scale: 1.0, view_angle: 30.0}
    difference: false
    strip: false               # optional: the term strip under the view (docs/terms.md),
    strip_mode: weighted       #   its tiles: weighted or raw
    strip_side: both           #   the compare view's panes with a strip: both, a or b
    strip_lights: false        #   a row of tiles per light under it
    lobes: {set: selected, view: polar, quantity: intensity, log: false, ndl: false,
            incidence: null, hidden: []}
                               # optional: the lobe inset's lobes and plot (docs/terms.md);
                               # incidence: the plot's θ_i in degrees (null: the light's);
                               # hidden: the lobes not drawn (1 is the set's first)
    local_viewer: true         # optional: the viewer at the camera (false: infinitely far
                               # along its view)
    compare: {material: {...}, model: phong, preset: gold, difference: false}   # optional:
                               # the A / B compare view's side B (and its shading: per-pixel,
                               # when it differs from the scene's: "Gouraud vs per-pixel")
    groups: {group: 1, materials: [{...}, ...]}   # optional: the mesh file's own materials
                               # as shown (one per usemtl group, edited), the group edited;
                               # absent: one material covers the mesh
    window: {...}              # optional: what the window reported (the --state-file's
                               # extras); never read back

:func:`session_mapping` makes the mapping, :func:`save_session` writes it atomically (never
over a file unless asked), :func:`load_session` reads one back with every problem named by file,
line and key. The ``--state-file`` the window writes after each frame is such a mapping, so it
reopens as a session.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from platformdirs import user_config_dir

from explorer.app.model import TERMS, State, check_window_lights
from explorer.app.start import add_mesh_materials, first_state, load_mesh_choice
from explorer.core.atomic import write_atomic
from explorer.core.controls import LOBE_INCIDENCE_RANGE
from explorer.core.errors import ExplorerError
from explorer.core.material import MODELS, parse_material
from explorer.core.mtl import MtlError
from explorer.core.scene import SHADINGS, load_scene
from explorer.core.texture import MAP_KEYS
from explorer.core.yamlio import dump_yaml, load_yaml
from explorer.geometry.meshes import Mesh
from explorer.render.camera import Camera

FORMAT = 1
KEYS = (
    "session", "scene", "mesh", "resolution", "preset", "hidden", "light", "handle_distance",
    "camera", "difference", "compare", "groups", "window", "local_viewer", "strip", "strip_mode",
    "strip_side", "strip_lights", "lobes",
)  # fmt: skip
CAMERA_KEYS = ("position", "focal_point", "view_up", "parallel", "parallel_scale", "view_angle")
#: environment variable naming the file the window keeps its last session in
LAST_SESSION_ENV = "PHONG_EXPLORER_LAST_SESSION"


def last_session_path() -> Path:
    """Where the window keeps the last session on quit (``gui --last`` reopens it):
    ``$PHONG_EXPLORER_LAST_SESSION``, else
    ``<user config dir>/phong-explorer/last-session.yaml``."""
    env = os.environ.get(LAST_SESSION_ENV)
    if env:
        return Path(env).expanduser()
    return Path(user_config_dir("phong-explorer")) / "last-session.yaml"


def camera_mapping(camera: Camera) -> dict:
    return {
        "position": [float(c) for c in camera.position],
        "focal_point": [float(c) for c in camera.focal_point],
        "view_up": [float(c) for c in camera.view_up],
        "parallel": bool(camera.parallel),
        "parallel_scale": float(camera.parallel_scale),
        "view_angle": float(camera.view_angle),
    }


def session_mapping(state: State) -> dict:
    """The session file's mapping of ``state`` (plain Python values)."""
    out = {
        "session": FORMAT,
        "scene": state.scene.to_mapping(),
        "mesh": state.mesh,
        "resolution": state.resolution,
        "preset": state.preset,
        "hidden": [t for t in (*TERMS, *MAP_KEYS) if t in state.hidden],
        "light": state.light + 1,
        "handle_distance": float(state.handle_distance),
        "difference": bool(state.difference),
        "local_viewer": bool(state.local_viewer),
        "strip": bool(state.strip),
        "strip_mode": state.strip_mode,
        "strip_side": state.strip_side,
        "strip_lights": bool(state.strip_lights),
        "lobes": {
            "set": state.lobes,
            "view": state.lobe_view,
            "quantity": state.lobe_quantity,
            "log": bool(state.lobe_log),
            "ndl": bool(state.lobe_ndl),
            "incidence": state.lobe_incidence,
            "hidden": sorted(i + 1 for i in state.lobe_hidden),
        },
    }
    if state.camera is not None:
        out["camera"] = camera_mapping(state.camera)
    if state.compare is not None:
        out["compare"] = {
            "material": state.compare.to_mapping(),
            "model": state.compare_model,
            "preset": state.compare_preset,
            "difference": bool(state.compare_difference),
        }
        if state.compare_shading is not None:
            out["compare"]["shading"] = state.compare_shading
    if state.groups is not None:
        out["groups"] = {
            "group": state.group + 1,
            "materials": [m.to_mapping() for m in state.groups],
        }
    return out


def session_text(state: State, *, as_json: bool = False) -> str:
    """``state`` as a session file's text: YAML with its header line, or JSON."""
    data = session_mapping(state)
    if as_json:
        return json.dumps(data, indent=1)
    return dump_yaml(data, header="phong-explorer session (phong-explorer gui --session FILE)")


def save_session(path, state: State, *, overwrite: bool = False) -> Path:
    """Write ``state`` as a session file (YAML; ``.json`` names get JSON), atomically; an
    existing file is replaced only with ``overwrite``."""
    text = session_text(state, as_json=os.fspath(path).lower().endswith(".json"))
    return write_atomic(path, text.encode("utf-8"), overwrite=overwrite, make_dirs=True)


def load_session(path, *, materials_dirs=()) -> tuple[State, Mesh]:
    """The state and mesh of a session file. Every problem raises one
    :class:`~explorer.core.errors.ExplorerError` naming the file, line and key."""
    doc = load_yaml(path, what="session", collect=True)
    checker = doc.checker()
    m = checker.mapping(doc.data, (), "a mapping of session keys")
    checker.raise_if_any()
    checker.keys(m, (), KEYS, required=("session", "scene", "mesh"))
    if "session" in m and m["session"] != FORMAT:
        checker.problem(("session",), f"must be {FORMAT} (this version's format)")
    name = checker.string(m.get("mesh"), ("mesh",)) if "mesh" in m else None
    resolution = m.get("resolution")
    if resolution is not None and (isinstance(resolution, bool) or not isinstance(resolution, int)
                                   or resolution < 1):  # fmt: skip
        checker.problem(("resolution",), f"must be a whole number >= 1 or null, got {resolution!r}")
    preset = m.get("preset")
    if preset is not None:
        preset = checker.string(preset, ("preset",))
    hidden = m.get("hidden", [])
    if not isinstance(hidden, list) or any(h not in (*TERMS, *MAP_KEYS) for h in hidden):
        checker.problem(
            ("hidden",),
            f"must be a list of terms from {', '.join(TERMS)} and "
            f"maps turned off from {', '.join(MAP_KEYS)}",
        )
        hidden = []
    handle = checker.number(m.get("handle_distance", 2.5), ("handle_distance",), 0.0, 1e6,
                            lo_open=True)  # fmt: skip
    difference = checker.boolean(m.get("difference", False), ("difference",))
    local_viewer = checker.boolean(m.get("local_viewer", True), ("local_viewer",))
    strip = checker.boolean(m.get("strip", False), ("strip",))
    from explorer.app.termstrip import STRIP_SIDES  # (the strip's VTK side: as STRIP_MODES)
    from explorer.shading.strip import MODES as STRIP_MODES  # (the engine: when a file is read)

    strip_mode = checker.choice(m.get("strip_mode", "weighted"), ("strip_mode",), STRIP_MODES)
    strip_side = checker.choice(m.get("strip_side", "both"), ("strip_side",), STRIP_SIDES)
    strip_lights = checker.boolean(m.get("strip_lights", False), ("strip_lights",))
    lobes = _lobes(checker, m["lobes"]) if m.get("lobes") is not None else {}
    camera = _camera(checker, m["camera"]) if "camera" in m else None
    compare = _compare(checker, m["compare"]) if m.get("compare") is not None else {}
    groups = _groups(checker, m["groups"]) if m.get("groups") is not None else None
    checker.raise_if_any()
    lights = m["scene"].get("lights") if isinstance(m["scene"], dict) else None
    if isinstance(lights, list):  # counted before each light is parsed and checked
        check_window_lights(len(lights), f"{os.fspath(path)}: scene")
    try:
        scene = load_scene(m["scene"], materials_dirs=materials_dirs)
    except ExplorerError as exc:
        raise ExplorerError(f"{os.fspath(path)}: scene: {exc}") from None
    check_window_lights(len(scene.lights), f"{os.fspath(path)}: scene")
    mesh = load_mesh_choice(name, resolution)
    state = first_state(scene, mesh, name=name, preset=preset, materials_dirs=materials_dirs,
                        resolution=resolution)  # fmt: skip
    try:
        state, _ = add_mesh_materials(state, mesh, use=False)
    except MtlError:
        if groups is not None:
            raise
    if groups is not None:
        state = _with_groups(checker, state, *groups)
    n = len(scene.lights)
    light = m.get("light", 1)
    if n and (isinstance(light, bool) or not isinstance(light, int) or not 1 <= light <= n):
        checker.problem(("light",), f"must be a whole number from 1 to {n}, got {light!r}")
    checker.raise_if_any()
    state = state.replace(
        hidden=frozenset(hidden),
        light=(light - 1) if n else 0,
        handle_distance=handle,
        camera=camera,
        difference=bool(difference),
        local_viewer=bool(local_viewer),
        strip=bool(strip),
        strip_mode=strip_mode,
        strip_side=strip_side,
        strip_lights=bool(strip_lights),
        **lobes,
        **compare,
    )
    return state, mesh


def _lobes(checker, value) -> dict:
    """The ``lobes`` section: the lobe inset's State fields."""
    from explorer.analysis.lobes import QUANTITIES, VIEWS  # (the plots: when a file is read)
    from explorer.app.lobeinset import LOBE_SETS  # (VTK-free, but the engine: likewise)

    path = ("lobes",)
    c = checker.mapping(value, path)
    if c is None:
        return {}
    checker.keys(
        c, path, ("set", "view", "quantity", "log", "ndl", "incidence", "hidden"), required=()
    )
    hidden = c.get("hidden", [])
    if not isinstance(hidden, list) or any(
        isinstance(i, bool) or not isinstance(i, int) or i < 1 for i in hidden
    ):
        checker.problem((*path, "hidden"), f"must be a list of whole numbers >= 1, got {hidden!r}")
        hidden = []
    incidence = c.get("incidence")
    if incidence is not None:
        incidence = checker.number(incidence, (*path, "incidence"), *LOBE_INCIDENCE_RANGE)
    return {
        "lobes": checker.choice(c.get("set", "selected"), (*path, "set"), LOBE_SETS),
        "lobe_view": checker.choice(c.get("view", "polar"), (*path, "view"), VIEWS),
        "lobe_quantity": checker.choice(
            c.get("quantity", "intensity"), (*path, "quantity"), QUANTITIES
        ),
        "lobe_log": bool(checker.boolean(c.get("log", False), (*path, "log"))),
        "lobe_ndl": bool(checker.boolean(c.get("ndl", False), (*path, "ndl"))),
        "lobe_incidence": None if incidence is None else float(incidence),
        "lobe_hidden": frozenset(i - 1 for i in hidden),
    }


def _compare(checker, value) -> dict:
    """The ``compare`` section: side B's State fields."""
    path = ("compare",)
    c = checker.mapping(value, path)
    if c is None:
        return {}
    checker.keys(c, path, ("material", "model", "preset", "difference", "shading"),
                 required=("material", "model"))  # fmt: skip
    material = parse_material(c.get("material"), checker, path + ("material",))
    model = checker.choice(c.get("model"), path + ("model",), MODELS)
    preset = c.get("preset")
    if preset is not None:
        preset = checker.string(preset, path + ("preset",))
    difference = checker.boolean(c.get("difference", False), path + ("difference",))
    shading = c.get("shading")
    if shading is not None:
        shading = checker.choice(shading, path + ("shading",), SHADINGS)
    return {"compare": material, "compare_model": model, "compare_preset": preset,
            "compare_difference": bool(difference), "compare_shading": shading}  # fmt: skip


def _groups(checker, value) -> tuple[int, tuple] | None:
    """The ``groups`` section: ``(group index, materials)``."""
    path = ("groups",)
    g = checker.mapping(value, path)
    if g is None or not checker.keys(g, path, ("group", "materials"), required=("materials",)):
        return None
    items = g["materials"]
    if not isinstance(items, list) or not items:
        checker.problem(path + ("materials",), "must be a list of materials, one per group")
        return None
    materials = tuple(parse_material(v, checker, path + ("materials", i))
                      for i, v in enumerate(items))  # fmt: skip
    group = g.get("group", 1)
    if isinstance(group, bool) or not isinstance(group, int) or not 1 <= group <= len(items):
        checker.problem(path + ("group",), f"must be a whole number from 1 to {len(items)}")
        return None
    return group - 1, materials


def _with_groups(checker, state: State, group: int, materials) -> State:
    """``state`` showing the session's group materials (as many as the mesh has groups)."""
    have = state.mesh_materials
    n = 0 if have is None else len(have.materials)
    if n != len(materials):
        checker.problem(("groups", "materials"), f"the mesh '{state.mesh}' has {n} material "
                        f"groups of its own, the session {len(materials)}")  # fmt: skip
        checker.raise_if_any()
    return state.replace(
        scene=state.scene.replace(material=materials[group]), groups=tuple(materials),
        group=group, preset=None, preset_material=have.materials[group],
    )  # fmt: skip


def _camera(checker, value) -> Camera | None:
    path = ("camera",)
    c = checker.mapping(value, path)
    if c is None:
        return None
    if not checker.keys(c, path, CAMERA_KEYS, required=CAMERA_KEYS):
        return None
    pos = checker.triple(c["position"], path + ("position",))
    focal = checker.triple(c["focal_point"], path + ("focal_point",))
    up = checker.direction(c["view_up"], path + ("view_up",))
    parallel = checker.boolean(c["parallel"], path + ("parallel",))
    scale = checker.number(c["parallel_scale"], path + ("parallel_scale",), 0.0, lo_open=True)
    angle = checker.number(c["view_angle"], path + ("view_angle",), 0.0, 179.0, lo_open=True)
    if None in (pos, focal, up, parallel, scale, angle):
        return None
    if pos == focal:
        checker.problem(path + ("focal_point",), "must differ from the position")
        return None
    return Camera(pos, focal, tuple(up), parallel, scale, angle, (0.01, 1000.0))
