"""Scenes: a material, lights, a viewer and options, loaded from YAML or a mapping.

The scene-file schema (every key optional)::

    material: bronze          # a preset name, or an inline mapping of the material keys
    model: blinn              # or phong, threejs (default: the material's model, else blinn)
    ambient: [0.2, 0.2, 0.2]  # scene ambient (OpenGL's default)
    viewer: {eye: [0, 0, 5]}  # local viewer; or {to_viewer: [0, 0, 1]} (infinite, the default)
    two_sided: false
    lights:                   # default: one directional light toward +z (OpenGL's GL_LIGHT0)
      - {type: directional, to_light: [1, 1, 1]}     # toward the light
      - {type: point, position: [2, 3, 1], attenuation: [1, 0.1, 0.01]}
      - {type: spot, position: [0, 4, 0], aim: [0, -1, 0], cutoff: 30, exponent: 8}
    mesh: sphere              # built-in name or mesh file (relative to the scene file)
    hdr: {exposure: 0, tone_map: reinhard}   # unclamped colours, exposure, tone map, sRGB
                              # (hdr: true: these defaults; hdr: false: off)
    shading: per-vertex       # or per-pixel: where the explorer and render light the surface
    color_control: single     # or separate: how a texture meets the specular light (OpenGL
                              # 2.1's GL_LIGHT_MODEL_COLOR_CONTROL; docs/formats.md)

Effects beyond the local model are off by default (docs/effects.md): ``shadows: true`` on a
light, ``fresnel: F0`` and ``energy_conserving: true`` on the material, ``hdr`` on the scene.

Each key is checked by one function (:attr:`Scene.KEYS`, :attr:`Viewer.KEYS`; see
:mod:`explorer.core.validate`), run by :func:`load_scene` on a file and by the constructor, with
the same messages. The file's own forms stay in :func:`load_scene`: a material given by preset
name, the model taken from the material when the file gives none, a mesh path and the
material's texture maps relative to the file (a map must lie inside the file's folder).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import ClassVar

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError, ExplorerTypeError
from explorer.core.hdr import HDR, parse_hdr
from explorer.core.lights import DirectionalLight, parse_light, span, unit_vector
from explorer.core.material import MODELS, Material, parse_material
from explorer.core.presets import find_preset
from explorer.core.texture import resolve_map
from explorer.core.validate import Check, Checked, Checker, check_fields, old_keywords
from explorer.core.yamlio import load_yaml

Vec3 = tuple[float, float, float]

VIEWER_KEYS = ("eye", "to_viewer")
DEFAULT_AMBIENT = (0.2, 0.2, 0.2)
#: where the surface is lit: at the vertices, the colours interpolated across each triangle
#: (Gouraud, OpenGL 2.1's fixed function), or at every pixel's surface point with the
#: interpolated normal (the engine per pixel: :mod:`explorer.render.perpixel`)
SHADINGS = ("per-vertex", "per-pixel")
#: how a textured picture adds the specular light (OpenGL 2.1's GL_LIGHT_MODEL_COLOR_CONTROL):
#: ``single`` (GL_SINGLE_COLOR, the default: the texture multiplies every term) or
#: ``separate`` (GL_SEPARATE_SPECULAR_COLOR: the specular sum is added after the texture)
COLOR_CONTROLS = ("single", "separate")


# -- the checks of each key ------------------------------------------------------------------
def _eye(checker: Checker, value, path):
    return checker.triple(value, path)


def _to_viewer(checker: Checker, value, path):
    return checker.direction(value, path)


def _one_viewer(checker: Checker, given: Mapping, path) -> bool:
    """Exactly one of eye / to_viewer is given (else a problem)."""
    if ("eye" in given) == ("to_viewer" in given):
        checker.problem(path, Viewer.ONE_OF)
        return False
    return True


@old_keywords
@dataclass(frozen=True)
class Viewer(Checked):
    """Exactly one of ``eye`` (a local viewer at a point) or ``to_viewer`` (an infinite viewer:
    the unit vector from the scene toward the viewer)."""

    eye: Vec3 | None = None
    to_viewer: Vec3 | None = None

    #: key -> its check, run by the scene-file parser and by the constructor
    KEYS: ClassVar[dict[str, Check]] = {"eye": _eye, "to_viewer": _to_viewer}
    RENAMED: ClassVar[dict] = {"direction": ("to_viewer", "the direction toward the viewer")}
    ONE_OF: ClassVar[str] = "needs exactly one of eye (local viewer) or to_viewer (infinite)"

    def _check(self, checks) -> None:
        given = {k: getattr(self, k) for k in self.KEYS if getattr(self, k) is not None}
        checker = Checker(None)
        _one_viewer(checker, given, ())
        checker.raise_if_any()
        super()._check(checks)

    def _settle(self) -> None:
        if self.to_viewer is not None:
            object.__setattr__(self, "to_viewer", unit_vector(self.to_viewer))

    @property
    def local(self) -> bool:
        return self.eye is not None

    def framed(self, centre, scale: float) -> tuple[float, float, float]:
        """The eye in the normalised frame ``centre`` (3,), ``scale``: ``(eye - centre) / scale``,
        or, farther than :data:`~explorer.core.tolerances.FAR_VIEWER` (the far-viewer policy, both
        tiers), that distance along its direction (computed without overflow: an eye at 1e8 from
        a mesh of size 1e-300 would be at 1e308, beyond float32; ``eye - P`` of infinite length)."""
        assert self.eye is not None, "an infinite viewer has no eye"
        v, u, distance = span(self.eye, centre, scale)
        if distance <= tol.FAR_VIEWER:
            return v
        x, y, z = u
        return (tol.FAR_VIEWER * x, tol.FAR_VIEWER * y, tol.FAR_VIEWER * z)

    def to_mapping(self) -> dict:
        if self.eye is not None:
            return {"eye": list(self.eye)}
        assert self.to_viewer is not None  # _check: exactly one of the two is given
        return {"to_viewer": list(self.to_viewer)}


def parse_viewer(checker: Checker, value, path=("viewer",)) -> Viewer | None:
    """A :class:`Viewer` from a scene's ``viewer`` mapping (or a Viewer), reporting every
    problem to ``checker``."""
    if isinstance(value, Viewer):
        return value
    m = checker.mapping(value, path, "{eye: [x, y, z]} or {to_viewer: [x, y, z]}")
    if m is None:
        return None
    m = checker.renamed(m, path, Viewer.RENAMED)
    checker.keys(m, path, VIEWER_KEYS)
    if not _one_viewer(checker, m, path):
        return None
    kw = check_fields(Viewer.KEYS, m, checker, path)
    return None if None in kw.values() else Viewer(**kw)


def _material(checker: Checker, value, path):
    """A Material, or a mapping of material keys (a preset name is a file's form: see
    :func:`load_scene`; the constructor refuses it, naming the functions that take it)."""
    if isinstance(value, str):
        checker.problem(
            path,
            f"must be a Material or a mapping of material keys, got the text {value!r}; "
            "a preset name is looked up by find_preset() or load_scene({'material': name})",
        )
        return None
    return value if isinstance(value, Material) else parse_material(value, checker, path)


def _model(checker: Checker, value, path):
    return checker.choice(value, path, MODELS)


def _ambient(checker: Checker, value, path):
    return checker.triple(value, path, 0.0)


def _flag(checker: Checker, value, path):
    return checker.boolean(value, path)


def _lights(checker: Checker, value, path):
    """A list of lights: each a Light or a mapping of light keys."""
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Sequence):
        checker.problem(path, "must be a list of lights (- {type: ..., ...})")
        return None
    lights = tuple(parse_light(light, checker, path + (i,)) for i, light in enumerate(value))
    return None if any(light is None for light in lights) else lights


def _mesh(checker: Checker, value, path):
    """A built-in mesh name or a mesh file path (text, or an os.PathLike)."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    return checker.string(value, path)


def _hdr(checker: Checker, value, path):
    return parse_hdr(value, checker, path)


def _shading(checker: Checker, value, path):
    return checker.choice(value, path, SHADINGS)


def _color_control(checker: Checker, value, path):
    return checker.choice(value, path, COLOR_CONTROLS)


DEFAULT_VIEWER = Viewer(to_viewer=(0.0, 0.0, 1.0))
DEFAULT_LIGHTS: tuple = (DirectionalLight(to_light=(0.0, 0.0, 1.0)),)


@dataclass(frozen=True)
class Scene(Checked):
    """Everything but the geometry.

    material : the surface's coefficients
    model : "blinn" ((N·H)^n), "phong" ((R·V)^n) or "threejs" (three.js's MeshPhongMaterial:
        (n/2+1)/4·(N·H)^n·(N·L)·Schlick's F on the specular colour; see
        :mod:`explorer.shading.equation`)
    ambient : scene ambient RGB (``a_scene``), never attenuated
    viewer : local or infinite
    two_sided : light back faces with -N
    lights : tuple of lights
    mesh : built-in mesh name or a file path, or None where arrays are given
    hdr : display unclamped colours with this exposure and tone map
        (:mod:`explorer.shading.display`), or None (OpenGL: clamp to [0, 1])
    source : the file the scene came from (for messages), or None
    shading : "per-vertex" (Gouraud) or "per-pixel" (:data:`SHADINGS`): where the explorer's
        view and ``render`` light the surface; the engine's per-vertex colours do not depend
        on it
    color_control : "single" or "separate": where a texture's picture adds the specular sum
        (:data:`COLOR_CONTROLS`); a picture without a texture is the same under both
    """

    material: Material = field(default_factory=Material)
    model: str = "blinn"
    ambient: Vec3 = DEFAULT_AMBIENT
    viewer: Viewer = DEFAULT_VIEWER
    two_sided: bool = False
    lights: tuple = DEFAULT_LIGHTS
    mesh: str | None = None
    source: str | None = field(default=None, compare=False)
    hdr: HDR | None = None
    shading: str = "per-vertex"
    color_control: str = "single"

    #: key -> its check, run by the scene-file parser and by the constructor, in the order a
    #: file's problems are listed (a constructor also takes a mapping where a file does)
    KEYS: ClassVar[dict[str, Check]] = {
        "material": _material,
        "model": _model,
        "ambient": _ambient,
        "viewer": parse_viewer,
        "two_sided": _flag,
        "lights": _lights,
        "mesh": _mesh,
        "hdr": _hdr,
        "shading": _shading,
        "color_control": _color_control,
    }

    def to_mapping(self) -> dict:
        """The scene-file form (plain Python values, YAML-ready)."""
        out = {
            "material": self.material.to_mapping(),
            "model": self.model,
            "ambient": list(self.ambient),
            "viewer": self.viewer.to_mapping(),
            "two_sided": self.two_sided,
            "lights": [light.to_mapping() for light in self.lights],
        }
        if self.mesh is not None:
            out["mesh"] = self.mesh
        if self.hdr is not None:
            out["hdr"] = self.hdr.to_mapping()
        if self.shading != "per-vertex":
            out["shading"] = self.shading
        if self.color_control != "single":
            out["color_control"] = self.color_control
        return out


SCENE_KEYS = tuple(Scene.KEYS)


def load_scene(scene=None, *, materials_dirs: Sequence = ()) -> Scene:
    """A :class:`Scene` from a scene-file path, a mapping in the scene schema, or a Scene.

    Every problem in the document is reported at once in one
    :class:`~explorer.core.errors.ValidationError` naming the file, line and key.
    ``materials_dirs`` are extra preset directories searched before the built-in ones.
    """
    materials_dirs = check_materials_dirs(materials_dirs)
    if scene is None:
        return Scene()
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, os.PathLike)):
        doc = load_yaml(scene, what="scene", collect=True)
        checker = doc.checker()  # already holds duplicate keys etc.: one pass reports all
        return _parse(doc.data, checker, materials_dirs, os.path.dirname(os.fspath(scene)))
    if isinstance(scene, Mapping):
        return _parse(scene, Checker(None), materials_dirs, None)
    raise ExplorerTypeError(
        f"scene must be a scene-file path, a mapping or a Scene, got {type(scene).__name__}"
    )


def check_materials_dirs(materials_dirs) -> tuple:
    """``materials_dirs`` as a tuple of directories (str or os.PathLike).

    One path given alone (``"/tmp"``) is refused with an
    :class:`~explorer.core.errors.ExplorerTypeError` rather than taken as one directory: a str is
    also a sequence of one-letter names, and guessing which was meant would hide the mistake
    wherever else a list is passed on. None means none.
    """
    if materials_dirs is None:
        return ()
    if isinstance(materials_dirs, (str, bytes, os.PathLike)):
        raise ExplorerTypeError(
            f"materials_dirs must be a list of directories, got one path {materials_dirs!r}: "
            f"pass [{materials_dirs!r}]"
        )
    if not isinstance(materials_dirs, Iterable):
        raise ExplorerTypeError(
            f"materials_dirs must be a list of directories, got {type(materials_dirs).__name__}"
        )
    dirs = tuple(materials_dirs)
    for d in dirs:
        if not isinstance(d, (str, os.PathLike)):
            raise ExplorerTypeError(
                f"materials_dirs must hold directory paths, got {type(d).__name__} {d!r}"
            )
    return dirs


def _parse(data, checker: Checker, materials_dirs, base_dir) -> Scene:
    """The file's form on top of :attr:`Scene.KEYS`: a material may be a preset name, the
    model defaults to the material's, a mesh path is relative to the file."""
    m = checker.mapping(data, (), "a mapping of scene keys")
    checker.raise_if_any()
    assert m is not None  # mapping() records a problem whenever it gives None
    checker.keys(m, (), SCENE_KEYS)
    checks = dict(Scene.KEYS)
    if isinstance(m.get("material"), str):
        checks["material"] = partial(_preset, materials_dirs=materials_dirs)
    kw = check_fields(checks, m, checker, ())
    material = kw.get("material")
    if "model" not in m and material is not None and material.model is not None:
        kw["model"] = material.model
    mesh = kw.get("mesh")
    if mesh is not None and base_dir and _looks_like_path(mesh):
        kw["mesh"] = os.path.normpath(os.path.join(base_dir, os.path.expanduser(mesh)))
    if material is not None and material.maps() and isinstance(m.get("material"), Mapping):
        kw["material"] = _maps_from(material, base_dir, checker)
    checker.raise_if_any()
    return Scene(source=checker.file, **kw)


def _maps_from(material: Material, base_dir, checker: Checker) -> Material:
    """``material`` with its maps' images named from the scene file's folder ``base_dir`` (a
    mapping given in code: as they are); a name leading outside that folder is a problem."""
    changes = {}
    for key, tmap in material.maps().items():
        full = resolve_map(tmap, base_dir or None)
        if full is None:
            checker.problem(
                ("material", key),
                f"the image {tmap.file!r} is outside the scene file's folder; put it beside the "
                "scene (or in a folder below it)",
            )
            continue
        changes[key] = full
    return material.replace(**changes)


def _looks_like_path(mesh: str) -> bool:
    return os.sep in mesh or "/" in mesh or "." in os.path.basename(mesh)


def _preset(checker: Checker, name: str, path, materials_dirs: Sequence = ()) -> Material | None:
    """The material of preset ``name`` (searched in ``materials_dirs``, then the built-ins)."""
    try:
        return find_preset(name, materials_dirs)
    except ExplorerError as exc:
        checker.problem(path, str(exc))
        return None
