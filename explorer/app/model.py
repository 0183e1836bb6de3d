"""The explorer's state and the actions on it: plain Python, no Qt, VTK or PyVista.

:class:`State` is everything the window shows (the scene, the mesh chosen, the preset, the
hidden terms, the selected light, the camera, the difference toggle) as one frozen value. An
action is a pure function ``action(state, ...) -> State``; :class:`Store` holds the present
state with its undo history and tells its observers of each change. A front end (the Qt window,
a notebook) only observes the store and sends actions: nothing of the model lives in widgets.

Undo: every committed action is one step, except that consecutive commits with the same
``merge`` key (the steps of one slider drag) make one step until :meth:`Store.seal` (the
slider's release) or any other commit. The camera is the viewer and moves with the mouse: its
moves are recorded in the present state without a history step, and undo / redo keep the
camera where it is.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from explorer.core import tolerances as tol
from explorer.core.controls import DISTANCE_RANGE
from explorer.core.errors import ExplorerError
from explorer.core.lights import PointLight, angles_of, direction_of
from explorer.core.material import MODELS, RGB_KEYS, Material
from explorer.core.scene import Scene, Viewer
from explorer.core.texture import MAP_KEYS
from explorer.render.camera import Camera, too_large

Vec3 = tuple[float, float, float]
#: the terms that can be hidden (hiding ``ambient`` also hides the emission)
TERMS = ("ambient", "diffuse", "specular")
#: where a new light's handle sits by default: azimuth, elevation (degrees), distance (radii)
DEFAULT_PLACEMENT = (40.0, 35.0, 2.5)
#: a spot made in the window lights about this fraction of the mesh radius around its aim
SPOT_SPREAD = 0.5
#: the cone of a spot made in the window is held within these half-angles (degrees)
SPOT_CUTOFF_RANGE = (5.0, 45.0)
#: a new light added next to others is turned this far (degrees of azimuth) from the last
NEW_LIGHT_TURN = 100.0
#: |elevation| at or above this (degrees) is a pole: the azimuth is kept, not recomputed
POLE = 89.999


@dataclass(frozen=True)
class MeshMaterials:
    """The materials a mesh file brings: an OBJ's ``usemtl`` groups read from its ``mtllib``.

    source : the mesh file's name (for labels)
    names : (k,) the group names (``mesh.groups.names``; ``""`` for faces without a material)
    materials : (k,) one :class:`~explorer.core.material.Material` per group, as read
    main : the group with the most vertices (the one the panel edits first)
    """

    source: str
    names: tuple[str, ...]
    materials: tuple[Material, ...]
    main: int = 0

    def label(self, group: int) -> str:
        """``'name'`` of a group (``(no usemtl)`` for the unnamed one)."""
        name = self.names[group]
        return f"'{name}'" if name else "(no usemtl)"


@dataclass(frozen=True)
class State:
    """Everything the explorer shows.

    scene : material, model, lights, viewer (the camera's), ambient, hdr
    mesh : the mesh chooser's name (a built-in name or a file path)
    resolution : the built-in mesh's resolution, or None (the explorer's choice)
    centre, radius : the mesh's bounding-box centre and radius (world units): lights are
        placed around them
    preset : name of the preset the material came from, or None
    preset_material : that preset's material as loaded or last saved (the material is
        "edited" when it differs)
    hidden : the terms not drawn, and the texture maps turned off (the material itself is
        unchanged: it keeps each map)
    light : index of the light the controls move
    handle_distance : where a directional light's handle sits, in mesh radii
    held_azimuth : the azimuth asked for last, kept while the light sits at a pole
    camera : the view's camera, or None (framed from the scene's viewer)
    difference : the per-pixel difference view is on
    compare : side B's material when the A / B compare view is on, else None
    compare_model, compare_preset : side B's specular model and preset name
    compare_difference : side B's pane shows the difference A − B instead of B
    compare_shading : side B's shading (``per-vertex`` / ``per-pixel``), or None: A's
    mesh_materials : the materials the mesh file brings (:class:`MeshMaterials`), or None
    groups : each group's material as shown (the mesh's own materials, edited), or None when
        one material (:attr:`material`: a preset, the scene's) covers the whole mesh
    group : the group the panel edits: while :attr:`groups` is shown, :attr:`material` is
        ``groups[group]`` (every material action edits that group)
    local_viewer : the engine's viewer is at the camera (a local viewer, OpenGL's
        ``GL_LIGHT_MODEL_LOCAL_VIEWER``); off: infinitely far along the camera's view (OpenGL's
        default; a parallel camera's viewer is always so)
    strip, strip_mode : the term strip under the view is on, and its tiles: ``weighted`` or
        ``raw`` (:mod:`explorer.app.termstrip`)
    strip_side : the compare view's panes that show their side's strip: ``both``, ``a``, ``b``
    strip_lights : a row of tiles per light under the strip (each light alone: a light pass
        per light while on)
    lobes, lobe_view, lobe_quantity, lobe_log, lobe_ndl : the lobe inset's lobes (the selected
        light's, or several) and how it plots them (:mod:`explorer.app.lobeinset`)
    lobe_hidden : the lobes of the inset's set not drawn (0-based indices in the set)
    lobe_incidence : the incidence θ_i (degrees) the lobe plot and its lit sphere show, set by
        a drag on the sphere (:mod:`explorer.app.litsphere`); None: the selected light's
    mesh_uv : the mesh has texture coordinates (its maps can be drawn)
    """

    scene: Scene
    mesh: str
    resolution: int | None = None
    centre: Vec3 = (0.0, 0.0, 0.0)
    radius: float = 1.0
    preset: str | None = None
    preset_material: Material | None = field(default=None, compare=False)
    hidden: frozenset = frozenset()
    light: int = 0
    handle_distance: float = DEFAULT_PLACEMENT[2]
    held_azimuth: float | None = None
    camera: Camera | None = None
    difference: bool = False
    compare: Material | None = None
    compare_model: str | None = None
    compare_preset: str | None = None
    compare_difference: bool = False
    compare_shading: str | None = None
    mesh_materials: MeshMaterials | None = None
    groups: tuple[Material, ...] | None = None
    group: int = 0
    local_viewer: bool = True
    strip: bool = False
    strip_mode: str = "weighted"
    strip_side: str = "both"
    strip_lights: bool = False
    lobes: str = "selected"
    lobe_view: str = "polar"
    lobe_quantity: str = "intensity"
    lobe_log: bool = False
    lobe_ndl: bool = False
    lobe_hidden: frozenset = frozenset()
    lobe_incidence: float | None = None
    mesh_uv: bool = False

    def replace(self, **changes) -> State:
        return replace(self, **changes)

    @property
    def material(self) -> Material:
        return self.scene.material

    @property
    def edited(self) -> bool:
        """The material differs from its preset's (or there is no preset)."""
        return self.preset_material is None or self.material != self.preset_material

    @property
    def selected_light(self):
        lights = self.scene.lights
        return lights[self.light] if lights else None

    def shown_scene(self) -> Scene:
        """The scene the engine shades: hidden terms have coefficient 0 (``ambient`` takes
        the emission with it). A hidden specular term under ``threejs`` is drawn under
        ``blinn``: the two differ only in the specular term, and threejs's has a part (Schlick's
        F toward 1) that no coefficient turns off."""
        scene = self.scene.replace(material=display_material(self.material, self.hidden))
        if "specular" in self.hidden and scene.model == "threejs":
            scene = scene.replace(model="blinn")
        return scene

    def shown_groups(self) -> tuple[Material, ...] | None:
        """Each group's material as drawn (hidden terms 0), or None (one material)."""
        if self.groups is None:
            return None
        return tuple(display_material(m, self.hidden) for m in self.groups)

    def placement(self, index: int | None = None) -> tuple[float, float, float]:
        """``(azimuth, elevation, distance)`` of a light (default: the selected one) around
        the mesh centre: degrees, degrees, world units. A directional light's distance is
        :attr:`handle_distance` (it only places the handle)."""
        i = self.light if index is None else index
        az, el, d = self.scene.lights[i].placement(self.centre)
        if abs(el) >= POLE and i == self.light and self.held_azimuth is not None:
            az = self.held_azimuth
        return az, el, (self.handle_distance * self.radius if d is None else d)

    def distance_range(self) -> tuple[float, float]:
        """The distance control's range in world units (widened to hold the light's own)."""
        lo, hi = (v * self.radius for v in DISTANCE_RANGE)
        if self.selected_light is not None:
            d = self.placement()[2]
            lo, hi = min(lo, d), max(hi, d)
        return lo, hi


def display_material(material: Material, hidden) -> Material:
    """The material drawn with some terms hidden: each hidden term's colour is 0
    (``ambient`` also hides the emission, the other constant term), and each map turned off
    (a map key in ``hidden``) is drawn as no map."""
    changes: dict = {t: (0.0, 0.0, 0.0) for t in TERMS if t in hidden}
    if "ambient" in changes:
        changes["emission"] = (0.0, 0.0, 0.0)
    changes.update({k: None for k in MAP_KEYS if k in hidden and getattr(material, k)})
    return material.replace(**changes) if changes else material


# -- material actions ----------------------------------------------------------------------------


def _material(state: State, material: Material) -> State:
    """The material the panel edits: the whole mesh's, or the edited group's."""
    new = state.replace(scene=state.scene.replace(material=material))
    if state.groups is not None:
        groups = list(state.groups)
        groups[state.group] = material
        new = new.replace(groups=tuple(groups))
    return new


def set_coefficient(state: State, name: str, value: float) -> State:
    """``ka`` / ``kd`` / ``ks`` (the largest channel of the term's colour, hue kept)."""
    if name not in ("ka", "kd", "ks"):
        raise ExplorerError(f"coefficient must be ka, kd or ks, got {name!r}")
    return _material(state, state.material.with_scalars(**{name: float(value)}))


def set_shininess(state: State, n: float) -> State:
    return _material(state, state.material.replace(shininess=float(n)))


def set_opacity(state: State, alpha: float) -> State:
    return _material(state, state.material.replace(opacity=float(alpha)))


def set_colour(state: State, term: str, rgb) -> State:
    """The material's ``ambient`` / ``diffuse`` / ``specular`` / ``emission`` colour."""
    if term not in RGB_KEYS:
        raise ExplorerError(f"colour must be one of {RGB_KEYS}, got {term!r}")
    return _material(state, state.material.replace(**{term: tuple(float(c) for c in rgb)}))


def apply_preset(state: State, name: str, material: Material) -> State:
    """Show preset ``name`` (its material, and its specular model when it has one) over the
    whole mesh: it overrides the mesh's own materials (:func:`use_mesh_materials` brings them
    back)."""
    scene = state.scene.replace(material=material)
    if material.model is not None:
        scene = scene.replace(model=material.model)
    return state.replace(scene=scene, preset=name, preset_material=material, groups=None)


def use_mesh_materials(state: State) -> State:
    """Show the mesh's own materials as its file has them, each group its own; the panel
    edits the group it edited last (at first the largest)."""
    mm = state.mesh_materials
    if mm is None:
        raise ExplorerError(f"the mesh '{state.mesh}' brings no materials of its own")
    group = state.group if 0 <= state.group < len(mm.materials) else mm.main
    material = mm.materials[group]
    return state.replace(
        scene=state.scene.replace(material=material), groups=mm.materials, group=group,
        preset=None, preset_material=material,
    )  # fmt: skip


def select_group(state: State, index: int) -> State:
    """Edit group ``index`` of the mesh's own materials (its material goes to the panel)."""
    mm = state.mesh_materials
    if state.groups is None or mm is None:
        raise ExplorerError("the mesh's own materials are not shown: there is no group to edit")
    n = len(state.groups)
    if isinstance(index, bool) or not 0 <= int(index) < n:
        raise ExplorerError(f"group must be 1 to {n}, got {index + 1}")
    i = int(index)
    return state.replace(
        scene=state.scene.replace(material=state.groups[i]), group=i,
        preset_material=mm.materials[i],
    )  # fmt: skip


def with_mesh_materials(state: State, materials: MeshMaterials | None, *, use: bool = True):
    """``state`` knowing the materials its mesh file brings, shown when ``use`` (else the
    present material covers the mesh, and :func:`use_mesh_materials` can show them)."""
    state = state.replace(mesh_materials=materials, groups=None,
                          group=materials.main if materials else 0)  # fmt: skip
    return use_mesh_materials(state) if materials is not None and use else state


def mark_saved(state: State, name: str, material: Material) -> State:
    """The material was saved as preset ``name``: shown clean under that name."""
    return state.replace(preset=name, preset_material=material)


def set_model(state: State, model: str) -> State:
    return state.replace(scene=state.scene.replace(model=model))


def next_model(model: str) -> str:
    """The specular model after ``model`` in :data:`~explorer.core.material.MODELS` (cycling)."""
    return MODELS[(MODELS.index(model) + 1) % len(MODELS)]


def set_term(state: State, term: str, shown: bool) -> State:
    if term not in TERMS:
        raise ExplorerError(f"term must be one of {TERMS}, got {term!r}")
    hidden = set(state.hidden)
    (hidden.discard if shown else hidden.add)(term)
    return state.replace(hidden=frozenset(hidden))


def set_difference(state: State, on: bool) -> State:
    return state.replace(difference=bool(on))


def viewer_of_camera(camera: Camera, local: bool = True) -> Viewer:
    """The engine's viewer seen by a camera: a local viewer at the position (perspective), or
    an infinite viewer looking along the camera (parallel projection, or ``local`` off)."""
    if camera.parallel or not local:
        return Viewer(to_viewer=tuple(np.subtract(camera.position, camera.focal_point)))
    x, y, z = camera.position
    return Viewer(eye=(float(x), float(y), float(z)))


def set_camera(state: State, camera: Camera | None) -> State:
    """The view's camera, which is the viewer: the scene's viewer follows it."""
    if camera is None:
        return state.replace(camera=None)
    viewer = viewer_of_camera(camera, state.local_viewer)
    scene = state.scene if viewer == state.scene.viewer else state.scene.replace(viewer=viewer)
    return state.replace(camera=camera, scene=scene)


# -- the A / B compare view ----------------------------------------------------------------------


def start_compare(state: State) -> State:
    """Side B starts as this material under another specular model (Phong beside Blinn or
    threejs, Blinn beside Phong)."""
    other = "phong" if state.scene.model != "phong" else "blinn"
    return state.replace(compare=state.material, compare_model=other,
                         compare_preset=state.preset)  # fmt: skip


def stop_compare(state: State) -> State:
    return state.replace(compare=None, compare_model=None, compare_preset=None,
                         compare_difference=False, compare_shading=None)  # fmt: skip


def set_compare(state: State, on: bool) -> State:
    if bool(on) == (state.compare is not None):
        return state
    return start_compare(state) if on else stop_compare(state)


def _needs_compare(state: State) -> None:
    if state.compare is None:
        raise ExplorerError("the compare view is off: turn it on first")


def set_compare_preset(state: State, name: str, material: Material) -> State:
    """Side B shows preset ``name`` (and its specular model when it has one)."""
    _needs_compare(state)
    model = material.model or state.compare_model
    return state.replace(compare=material, compare_model=model, compare_preset=name)


def set_compare_model(state: State, model: str) -> State:
    _needs_compare(state)
    state.scene.replace(model=model)  # the scene checks the name
    return state.replace(compare_model=model)


def set_compare_difference(state: State, on: bool) -> State:
    _needs_compare(state)
    return state.replace(compare_difference=bool(on))


def swap_compare(state: State) -> State:
    """A becomes B and B becomes A (the panel edits side A)."""
    _needs_compare(state)
    shading = state.compare_shading or state.scene.shading
    scene = state.scene.replace(material=state.compare, model=state.compare_model, shading=shading)
    return state.replace(
        scene=scene, preset=state.compare_preset, preset_material=None, groups=None,
        compare=state.material, compare_model=state.scene.model, compare_preset=state.preset,
        compare_shading=None if state.compare_shading is None else state.scene.shading,
    )  # fmt: skip


def side_b(state: State) -> State:
    """The state side B shows: B's material (over the whole mesh), model and shading,
    everything else shared."""
    _needs_compare(state)
    shading = state.compare_shading or state.scene.shading
    scene = state.scene.replace(material=state.compare, model=state.compare_model, shading=shading)
    return state.replace(scene=scene, preset=state.compare_preset, preset_material=None,
                         groups=None)  # fmt: skip


# -- light actions -------------------------------------------------------------------------------


def check_window_lights(n: int, where: str = "the scene") -> None:
    """Refuse more than ``MAX_WINDOW_LIGHTS`` lights in the window: an :class:`ExplorerError`
    naming ``where``, the count and the cap."""
    if n > tol.MAX_WINDOW_LIGHTS:
        raise ExplorerError(
            f"{where}: {n} lights; the window holds at most {tol.MAX_WINDOW_LIGHTS} "
            "(MAX_WINDOW_LIGHTS; 'phong-explorer render' takes more)"
        )


def _lights(state: State, lights, selected: int | None = None) -> State:
    check_window_lights(len(lights))
    sel = state.light if selected is None else selected
    sel = min(max(sel, 0), max(len(lights) - 1, 0))
    held = state.held_azimuth if sel == state.light else None
    return state.replace(
        scene=state.scene.replace(lights=tuple(lights)), light=sel, held_azimuth=held
    )


def _with_selected(state: State, light) -> State:
    if state.selected_light is None:
        raise ExplorerError("the scene has no lights: add one first")
    lights = list(state.scene.lights)
    lights[state.light] = light
    return _lights(state, lights)


def select_light(state: State, index: int) -> State:
    n = len(state.scene.lights)
    if not 0 <= int(index) < n:
        raise ExplorerError(f"light must be 1 to {n}, got {int(index) + 1}")
    return state.replace(light=int(index), held_azimuth=None)


def place_light(state: State, azimuth=None, elevation=None, distance=None) -> State:
    """Move the selected light around the mesh centre (values not given are kept; distance in
    world units). At a pole (elevation ±90) the azimuth asked for is kept for the controls."""
    light = state.selected_light
    if light is None:
        raise ExplorerError("the scene has no lights to move")
    az, el, d = state.placement()
    az = az if azimuth is None else float(azimuth)
    el = el if elevation is None else float(elevation)
    d = d if distance is None else float(distance)
    if not all(math.isfinite(v) for v in (az, el, d)) or d <= 0.0:
        raise ExplorerError(f"light placement must be finite with distance > 0, got {d}")
    el = min(max(el, -90.0), 90.0)
    new = _with_selected(state, light.placed(az, el, d, state.centre))
    handle = state.handle_distance
    if light.placement(state.centre)[2] is None:  # directional: the distance moves the handle
        handle = d / state.radius
    return new.replace(held_azimuth=az, handle_distance=handle)


def spot_cutoff(distance: float, radius: float) -> float:
    """The cone half-angle (degrees) of a spot made in the window at ``distance`` from a mesh
    of ``radius``: it lights about :data:`SPOT_SPREAD` of the radius around its aim."""
    angle = math.degrees(math.atan2(SPOT_SPREAD * radius, max(distance, 1e-300)))
    return min(max(angle, SPOT_CUTOFF_RANGE[0]), SPOT_CUTOFF_RANGE[1])


def set_light_type(state: State, kind: str) -> State:
    """The selected light as another type, where it is; a new spot aims at the mesh centre with
    a cone that lights part of the mesh (:func:`spot_cutoff`)."""
    light = state.selected_light
    if light is None:
        raise ExplorerError("the scene has no lights to change")
    if kind == light.type:
        return state
    az, el, d = state.placement()
    new = light.as_type(kind).placed(az, el, d, state.centre)
    if "cutoff" in new.CONTROL_KEYS:  # a cone: one that lights part of the mesh
        new = new.replace(cutoff=spot_cutoff(d, state.radius))
    return _with_selected(state, new).replace(held_azimuth=az)


def light_colour(light) -> tuple[Vec3, float]:
    """``(colour, intensity)`` of a light: diffuse = intensity · colour, the colour's largest
    channel 1 (white for a black light)."""
    k = max(light.diffuse)
    if k <= 0.0:
        return (1.0, 1.0, 1.0), 0.0
    return tuple(c / k for c in light.diffuse), float(k)


def set_light_colour(state: State, rgb) -> State:
    """The selected light's colour (its hue: the intensity is kept); diffuse = specular."""
    light = state.selected_light
    if light is None:
        raise ExplorerError("the scene has no lights")
    _, k = light_colour(light)
    m = max(float(c) for c in rgb)
    hue = tuple(float(c) / m for c in rgb) if m > 0 else (0.0, 0.0, 0.0)
    k = k if k > 0 or m == 0 else 1.0
    rgb = tuple(k * c for c in hue)
    return _with_selected(state, light.replace(diffuse=rgb, specular=rgb))


def set_light_intensity(state: State, k: float) -> State:
    """The selected light's intensity (diffuse = specular = intensity · colour)."""
    light = state.selected_light
    if light is None:
        raise ExplorerError("the scene has no lights")
    hue, _ = light_colour(light)
    rgb = tuple(float(k) * c for c in hue)
    return _with_selected(state, light.replace(diffuse=rgb, specular=rgb))


#: the selected light's fields :func:`set_light_field` sets as given (when the light's
#: ``CONTROL_KEYS`` have them)
LIGHT_FIELDS = ("attenuation", "cutoff", "exponent", "shadows")


def set_light_field(state: State, name: str, value) -> State:
    """``attenuation``, ``cutoff``, ``exponent`` or ``shadows`` of the selected light, when the
    light has that control (its ``CONTROL_KEYS``: attenuation on a positional light, the cone
    on a spot); the light checks the value."""
    light = state.selected_light
    if light is None or name not in LIGHT_FIELDS or name not in light.CONTROL_KEYS:
        kind = "no light" if light is None else f"a {light.type} light"
        raise ExplorerError(f"{name!r} cannot be set on {kind}")
    if name == "attenuation":
        value = tuple(float(v) for v in value)
    return _with_selected(state, light.replace(**{name: value}))


def add_light(state: State) -> State:
    """A white point light, turned :data:`NEW_LIGHT_TURN` degrees from the selected one (or at
    :data:`DEFAULT_PLACEMENT`); it becomes the selected light."""
    az, el, d = DEFAULT_PLACEMENT
    d *= state.radius
    if state.selected_light is not None:
        az, el, d = state.placement()
        az = (az + NEW_LIGHT_TURN + 180.0) % 360.0 - 180.0
    light = PointLight().placed(az, el, d, state.centre)
    lights = state.scene.lights + (light,)
    return _lights(state, lights, len(lights) - 1).replace(held_azimuth=None)


def duplicate_light(state: State) -> State:
    """An exact copy of the selected light (same type, colour, place and cone), selected, so
    that the controls or its handle move it from there; the light list says which lights share
    a place (:func:`same_place_as`)."""
    light = state.selected_light
    if light is None:
        raise ExplorerError("the scene has no light to duplicate")
    lights = state.scene.lights + (light,)
    return _lights(state, lights, len(lights) - 1).replace(held_azimuth=None)


def same_place_as(state: State, i: int) -> int | None:
    """The first light before light ``i`` with the same type and placement (azimuth, elevation,
    distance), or None: the light list says so, since such lights draw one
    handle over the other."""
    lights = state.scene.lights
    here = lights[i].placement(state.centre)
    for j in range(i):
        if lights[j].type == lights[i].type and lights[j].placement(state.centre) == here:
            return j
    return None


def remove_light(state: State) -> State:
    """Remove the selected light (the scene may end with none)."""
    if state.selected_light is None:
        raise ExplorerError("the scene has no lights to remove")
    lights = list(state.scene.lights)
    del lights[state.light]
    return _lights(state, lights, state.light).replace(held_azimuth=None)


# -- typed values ------------------------------------------------------------------------------


def parse_number(key: str, text: str, lo: float, hi: float) -> float:
    """The number typed for ``key`` (a unit such as ``°`` or `` r`` after it is allowed), which
    must lie within ``[lo, hi]``; anything else raises :class:`ExplorerError` naming the key
    and the range, so the user is told instead of the value being clamped or dropped."""
    t = text.strip().rstrip("°").removesuffix(" r").removesuffix("r").strip()
    try:
        v = float(t)
    except ValueError:
        v = None
    if v is None or not math.isfinite(v) or not lo <= v <= hi:
        raise ExplorerError(f"{key} must be a number within {lo:g} .. {hi:g}, got {text.strip()!r}")
    return v


def parse_colour(key: str, text: str) -> Vec3:
    """A colour typed as ``r, g, b`` (each within 0 .. 1, commas or spaces between) or as hex
    ``#rrggbb`` (``#rgb``, the ``#`` optional) -> (3,) floats in [0, 1]; anything else raises
    :class:`ExplorerError` naming ``key`` and the forms taken."""
    t = text.strip()
    forms = "'r, g, b' with each within 0 .. 1, or '#rrggbb'"
    h = t.removeprefix("#")
    if (
        len(h) in (3, 6)
        and all(c in "0123456789abcdefABCDEF" for c in h)
        and (t.startswith("#") or "," not in t and " " not in t and not _is_number(t))
    ):
        if len(h) == 3:
            h = "".join(c * 2 for c in h)
        r, g, b = (int(h[k : k + 2], 16) / 255.0 for k in (0, 2, 4))
        return r, g, b
    parts = [p for p in t.replace(",", " ").split() if p]
    try:
        rgb = tuple(float(p) for p in parts)
    except ValueError:
        rgb = ()
    if len(rgb) != 3 or not all(math.isfinite(c) and 0.0 <= c <= 1.0 for c in rgb):
        raise ExplorerError(f"{key} must be {forms}, got {t!r}")
    return rgb


def _is_number(t: str) -> bool:
    try:
        float(t)
    except ValueError:
        return False
    return True


# -- mesh ----------------------------------------------------------------------------------------


def set_mesh(
    state: State, name: str, centre, radius: float, spec: str | None = None, uv: bool = False
) -> State:
    """Show another mesh: each light and a local viewer keep their places relative to the
    mesh, scaled to the new mesh's size (so the camera frames a mesh of size 1e-20 or 1e300 as
    it framed the last one); the material shown is kept over the whole mesh
    (:func:`with_mesh_materials` adds the new mesh's own). ``spec`` is the scene's ``mesh``
    value (default: ``name``); ``uv``: the mesh has texture coordinates."""
    centre = tuple(float(c) for c in np.asarray(centre, dtype=np.float64))
    radius = float(radius) or 1.0
    # in radii first: no overflow from 1e-300 to 1e300
    places = [light.placement(state.centre) for light in state.scene.lights]
    places = [(az, el, (d or 0.0) / state.radius * radius) for az, el, d in places]
    viewer = state.scene.viewer
    if not state.local_viewer and state.camera is not None and not state.camera.parallel:
        viewer = viewer_of_camera(state.camera)  # framed from the camera's place, not along it
    far = max(abs(c) for c in centre)
    ends = [far + d for _, _, d in places]
    eye = None
    if viewer.eye is not None:
        with np.errstate(over="ignore", invalid="ignore"):  # too far: refused below
            eye = np.subtract(viewer.eye, state.centre) / state.radius * radius + centre
        ends.append(float(np.max(np.abs(eye))))
    if not all(math.isfinite(e) for e in ends):
        raise too_large(os.path.basename(name), radius)
    lights = [light.placed(az, el, d, centre) if d > 0 else light
              for light, (az, el, d) in zip(state.scene.lights, places, strict=True)]  # fmt: skip
    if eye is not None:
        x, y, z = (float(c) for c in eye)
        viewer = Viewer(eye=(x, y, z))
    scene = state.scene.replace(lights=tuple(lights), mesh=spec or name, viewer=viewer)
    return state.replace(
        scene=scene, mesh=name, resolution=None, centre=centre, radius=radius, camera=None,
        mesh_materials=None, groups=None, group=0, mesh_uv=uv,
    )  # fmt: skip


# -- the store -----------------------------------------------------------------------------------


Observer = Callable[[State, State], None]


class Store:
    """The present state, its undo history, and the observers told of each change.

    state : the start; limit : how many undo steps are kept
    """

    def __init__(self, state: State, limit: int = 500):
        self.state = state
        self.limit = int(limit)
        self._past: list[tuple[State, str]] = []
        self._future: list[tuple[State, str]] = []
        self._merge: object = None
        self._observers: list[Observer] = []

    def subscribe(self, observer: Observer) -> None:
        """``observer(old, new)`` is called after every change."""
        self._observers.append(observer)

    def _set(self, new: State) -> None:
        old, self.state = self.state, new
        if new is not old:
            for observer in list(self._observers):
                observer(old, new)

    def commit(self, new: State, label: str, *, merge: object = None) -> bool:
        """Make ``new`` the present as one undo step named ``label``; with ``merge``, a commit
        with the same key as the last one (and no seal between) joins its step. Returns False
        when nothing changed."""
        if new == self.state and new.preset_material == self.state.preset_material:
            return False
        if merge is None or merge != self._merge or not self._past:
            self._past.append((self.state, label))
            del self._past[: max(0, len(self._past) - self.limit)]
        self._future.clear()
        self._merge = merge
        self._set(new)
        return True

    def apply(self, action: Callable[..., State], *args, label: str | None = None, merge=None):
        """Run ``action(state, *args)`` and commit its result (see :meth:`commit`)."""
        return self.commit(action(self.state, *args), label or action.__name__, merge=merge)

    def seal(self) -> None:
        """End the current merged step (a slider's release)."""
        self._merge = None

    def set_camera(self, camera: Camera | None) -> None:
        """Record the camera in the present state (no undo step)."""
        if camera != self.state.camera:
            self._set(set_camera(self.state, camera))

    @property
    def can_undo(self) -> bool:
        return bool(self._past)

    @property
    def can_redo(self) -> bool:
        return bool(self._future)

    def undo_label(self) -> str | None:
        return self._past[-1][1] if self._past else None

    def redo_label(self) -> str | None:
        return self._future[-1][1] if self._future else None

    def undo(self) -> bool:
        """Back one step (the camera stays where it is)."""
        return self._step(self._past, self._future)

    def redo(self) -> bool:
        return self._step(self._future, self._past)

    def _step(self, source: list, target: list) -> bool:
        """Move the present onto ``target`` and take ``source``'s last state."""
        if not source:
            return False
        state, label = source.pop()
        target.append((self.state, label))
        self._merge = None
        self._set(self._keep_camera(state))
        return True

    def _keep_camera(self, state: State) -> State:
        """``state`` with the present camera (and so viewer), when both show the same mesh."""
        if state.mesh != self.state.mesh or self.state.camera is None:
            return state
        return set_camera(state, self.state.camera)


def handle_point(state: State, index: int | None = None) -> np.ndarray:
    """(3,) where a light's handle is drawn (world units); default: the selected light's."""
    az, el, d = state.placement(index)
    return np.asarray(state.centre) + d * direction_of(az, el)


def point_on_ray(origin, direction, centre, distance: float, near: bool = True) -> np.ndarray:
    """Where a handle dragged under the pointer goes: the point of the pointer's ray
    ``origin + t·direction`` (each (3,), t >= 0) at ``distance`` from ``centre`` (3,), the
    nearer of the two such points when ``near`` (else the farther); where the ray passes
    farther than ``distance`` from the centre, its point nearest the centre (the two
    intersections meet there, so a drag across the sphere's outline is continuous). The point
    is always on the ray: the handle stays under the pointer. Returns (3,) float64."""
    o = np.asarray(origin, np.float64)
    u = np.asarray(direction, np.float64)
    u = u / max(float(np.linalg.norm(u)), 1e-300)
    t0 = float((np.asarray(centre, np.float64) - o) @ u)  # the ray's point nearest the centre
    miss2 = float(np.sum((o + t0 * u - np.asarray(centre, np.float64)) ** 2))
    half = math.sqrt(max(float(distance) ** 2 - miss2, 0.0))
    t = t0 - half if near else t0 + half
    return o + max(t, 0.0) * u


def angles_from_point(state: State, point) -> tuple[float, float, float]:
    """The placement of a handle dragged to ``point`` (3,), the distance held in the distance
    control's range."""
    az, el, d = angles_of(np.subtract(point, state.centre))
    lo, hi = state.distance_range()
    if abs(el) >= POLE and state.selected_light is not None:
        az = state.placement()[0]  # at a pole the azimuth stays where it was
    return az, el, min(max(d, lo), hi)
