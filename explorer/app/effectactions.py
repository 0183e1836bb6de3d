"""The actions that switch the engine's effects from the explorer's panel (docs/effects.md):
the material's Fresnel and energy-conserving specular, the scene's two-sided lighting, HDR
display (exposure, tone map) and local viewer; and where the surface is lit, per vertex or per
pixel (the scene's ``shading``), with the compare view that puts the two side by side. A light's
shadows are a light field (:func:`explorer.app.model.set_light_field`); translucency is the
material's opacity (:func:`explorer.app.model.set_opacity`). Each is a pure action of the
:mod:`explorer.app.model` kind (one undo step; the scene keeps the value, so a session saves it).
"""

from __future__ import annotations

from explorer.app.model import State, set_camera, start_compare
from explorer.app.model import _material as with_material
from explorer.core.errors import ExplorerError
from explorer.core.hdr import HDR, HDR_KEYS

#: the material's effects :func:`set_material_field` sets (docs/effects.md)
MATERIAL_EFFECTS = ("fresnel", "energy_conserving")
#: the scene's flags :func:`set_scene_field` sets
SCENE_FLAGS = ("two_sided",)


def set_material_field(state: State, name: str, value) -> State:
    """An effect of the material: ``fresnel`` (Schlick's F0, or None: off) or
    ``energy_conserving``; the material checks the value."""
    if name not in MATERIAL_EFFECTS:
        raise ExplorerError(f"material effect must be one of {MATERIAL_EFFECTS}, got {name!r}")
    if name == "fresnel" and value is not None:
        value = float(value)
    return with_material(state, state.material.replace(**{name: value}))


def set_scene_field(state: State, name: str, value) -> State:
    """A flag of the scene (``two_sided``: back faces lit with -N); the scene checks it."""
    if name not in SCENE_FLAGS:
        raise ExplorerError(f"scene flag must be one of {SCENE_FLAGS}, got {name!r}")
    return state.replace(scene=state.scene.replace(**{name: value}))


def set_hdr(state: State, on: bool) -> State:
    """The HDR display on (exposure 0, Reinhard: :class:`~explorer.core.hdr.HDR`'s defaults)
    or off (OpenGL's clamp); a display already on is kept."""
    if bool(on) == (state.scene.hdr is not None):
        return state
    return state.replace(scene=state.scene.replace(hdr=HDR() if on else None))


def set_hdr_field(state: State, name: str, value) -> State:
    """The HDR display's ``exposure`` (stops) or ``tone_map``; the display must be on."""
    hdr = state.scene.hdr
    if hdr is None:
        raise ExplorerError(f"{name!r} needs the HDR display on (hdr)")
    if name not in HDR_KEYS:
        raise ExplorerError(f"hdr key must be one of {HDR_KEYS}, got {name!r}")
    return state.replace(scene=state.scene.replace(hdr=hdr.replace(**{name: value})))


def set_local_viewer(state: State, on: bool) -> State:
    """The viewer at the camera (on) or infinitely far along its view (off); the scene's
    viewer follows the camera at once."""
    new = state.replace(local_viewer=bool(on))
    return set_camera(new, new.camera) if new.camera is not None else new


def set_shading(state: State, shading: str) -> State:
    """The view lit per vertex (``per-vertex``, Gouraud) or per pixel (``per-pixel``, the engine
    at every pixel's surface point); the scene checks the name."""
    return state.replace(scene=state.scene.replace(shading=shading))


def gouraud_vs_per_pixel(state: State) -> State:
    """The compare view with side A per vertex and side B per pixel, the same material, model
    and everything else: what Gouraud costs and misses, side by side."""
    a = set_shading(state, "per-vertex")
    b = start_compare(a) if a.compare is None else a
    return b.replace(
        compare=a.material,
        compare_model=a.scene.model,
        compare_preset=a.preset,
        compare_shading="per-pixel",
        compare_difference=False,
    )
