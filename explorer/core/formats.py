"""A material as other tools hold it: MTL, three.js MeshPhongMaterial, X3D Material, Blender.

Each writer returns :class:`Converted`: the file text and the approximations it made, one
sentence each (``presets export`` and ``presets show --as`` print them). The mappings, and the
sources each was checked against, are in ``docs/formats.md``; in short:

* **MTL** keeps every coefficient exactly (:func:`explorer.core.mtl.format_mtl`).
* **three.js** ``MeshPhongMaterial``: ``color`` = diffuse, ``specular``, ``emissive``,
  ``shininess`` = the exponent, ``opacity``. Its colours are 8-bit sRGB hex numbers (what
  ``Color.getHex()`` writes), read as the display values they are here (as three.js's
  MTLLoader reads an .mtl's ``Kd``); the material has no ambient colour (three.js takes the
  ambient from an ``AmbientLight`` times ``color``); its shader divides diffuse by π and
  normalises the highlight, ``(n/2 + 1)/π · (N·H)^n`` with Schlick's Fresnel on the specular
  colour and a visibility of 1/4, so the same numbers look different under the same lights.
* **X3D** ``Material``: ``diffuseColor``, ``specularColor``, ``emissiveColor``,
  ``ambientIntensity`` (one number: ambient = ambientIntensity × diffuseColor),
  ``shininess`` = n / 128 in [0, 1], ``transparency`` = 1 − opacity.
* **Blender** (Principled BSDF, as Blender's OBJ importer maps an .mtl): Base Color = diffuse,
  Specular = mean of the specular colour, Roughness = 1 − sqrt(min(n, 1000) / 1000), Metallic
  0, Emission = emission, Alpha = opacity; no ambient.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

from explorer.core import tolerances as tol
from explorer.core.errors import ExplorerError
from explorer.core.material import Material
from explorer.core.mtl import format_mtl, lost_in_mtl
from explorer.core.version import __version__

#: ``presets export --out`` suffix -> format name
EXPORT_SUFFIXES = {".mtl": "mtl", ".json": "threejs", ".x3d": "x3d"}
#: ``presets show --as`` choices
SHOW_FORMATS = ("mtl", "threejs", "x3d", "blender")
#: X3D's shininess is a fraction of this exponent (the VRML97 / X3D lighting model)
X3D_SHININESS_SCALE = 128.0
#: Blender's OBJ importer clamps Ns to this before it maps it to roughness
BLENDER_NS_MAX = 1000.0


@dataclass(frozen=True)
class Converted:
    """text : the file (or, for Blender, the settings) as the tool holds the material;
    notes : every approximation made, one sentence each."""

    text: str
    notes: tuple[str, ...]


def convert(material: Material, name: str, fmt: str, folder=None) -> Converted:
    """``material`` (preset ``name``) in format ``fmt`` (:data:`SHOW_FORMATS`); folder : where
    the file goes (its texture images are named relative to it when inside it)."""
    writers = {"mtl": to_mtl, "threejs": to_threejs, "x3d": to_x3d, "blender": to_blender}
    if fmt not in writers:
        raise ExplorerError(f"unknown material format {fmt!r}; use one of {', '.join(writers)}")
    if fmt == "mtl":
        return to_mtl(material, name, folder)
    return writers[fmt](material, name)


def _header(name: str) -> str:
    return f"material '{name}', written by phong-explorer {__version__}"


def to_mtl(material: Material, name: str, folder=None) -> Converted:
    """Wavefront MTL: exact (floats written in ``repr`` form), the texture maps with their
    options (images inside ``folder`` named relative to it)."""
    notes = [f"MTL cannot hold {what}" for what in lost_in_mtl(material)]
    text = format_mtl([(name, material)], header=_header(name), folder=folder)
    return Converted(text, tuple(notes))


def hex_colour(rgb) -> int:
    """An RGB triple in [0, 1] as three.js's 24-bit hex colour (8 bits per channel,
    rounded to nearest)."""
    r, g, b = (int(round(min(1.0, max(0.0, c)) * 255)) for c in rgb)
    return (r << 16) | (g << 8) | b


def to_threejs(material: Material, name: str) -> Converted:
    """three.js ``MeshPhongMaterial`` JSON (the ``Material.toJSON`` form ``MaterialLoader``
    reads), the exact floats in ``userData.phong_explorer``."""
    data = {
        "metadata": {"version": 4.6, "type": "Material", "generator": "phong-explorer"},
        "type": "MeshPhongMaterial",
        "name": name,
        "color": hex_colour(material.diffuse),
        "specular": hex_colour(material.specular),
        "shininess": float(material.shininess),
        "emissive": hex_colour(material.emission),
        "opacity": float(material.opacity),
        "transparent": material.opacity < 1.0,
        "userData": {"phong_explorer": material.to_mapping()},
    }
    if material.diffuse_map is not None:
        data.update(_threejs_map(material.diffuse_map))
    notes = [
        "colours become 8-bit sRGB hex numbers (three.js's JSON form), within 1/510 of the "
        "values; the exact floats are kept in userData.phong_explorer",
        "ambient is dropped: MeshPhongMaterial has no ambient colour (an AmbientLight lights "
        "'color' instead)",
        "three.js's shader divides diffuse by π and weights the highlight (N·H)^n by "
        "(n/2 + 1)/(4π) · N·L with Schlick's Fresnel on 'specular': under lights of intensity "
        "π diffuse matches OpenGL's and the highlight's peak is (n/2 + 1)/4 = "
        f"{(material.shininess / 2 + 1) / 4:.3g} times OpenGL's (less towards the terminator, "
        "whiter at grazing angles); see it with --model threejs",
    ]
    if material.model == "phong":
        notes.append("model phong becomes Blinn-Phong (three.js's only Phong lobe)")
    if material.diffuse_map is not None:
        notes.append(
            "map: three.js decodes the image as sRGB and multiplies in linear light "
            "(colorSpace SRGBColorSpace); OpenGL 2.1 multiplies the stored values, so mid "
            "tones of the texture come out darker in three.js"
        )
    notes += [f"three.js has no {what}" for what in _effects(material)]
    notes += [
        f"{key} is not written (MeshPhongMaterial JSON here keeps only map)"
        for key in material.maps()
        if key != "diffuse_map"
    ]
    text = json.dumps(data, indent=2) + "\n"
    return Converted(text, tuple(notes))


#: three.js's constants: RepeatWrapping, ClampToEdgeWrapping, NearestFilter
_THREE_REPEAT, _THREE_CLAMP, _THREE_NEAREST = 1000, 1001, 1003


def _threejs_map(tmap) -> dict:
    """``map`` and the texture and image it names, as three.js's ``toJSON`` writes them (the
    ids fixed, so a file is the same every time)."""
    wrap = _THREE_CLAMP if tmap.clamp else _THREE_REPEAT
    return {
        "map": "phong-explorer-diffuse-map",
        "textures": [
            {
                "uuid": "phong-explorer-diffuse-map",
                "image": "phong-explorer-diffuse-image",
                "repeat": [tmap.scale[0], tmap.scale[1]],
                "offset": [tmap.offset[0], tmap.offset[1]],
                "wrap": [wrap, wrap],
                "magFilter": _THREE_NEAREST,
                "minFilter": _THREE_NEAREST,
                "flipY": True,
                "colorSpace": "srgb",
            }
        ],
        "images": [{"uuid": "phong-explorer-diffuse-image", "url": tmap.file}],
    }


def x3d_ambient_intensity(material: Material) -> float:
    """The one number X3D keeps of the ambient colour: the ``k`` in [0, 1] for which
    ``k × diffuse`` is nearest ``ambient`` (least squares over the channels; 0 for a black
    diffuse)."""
    dd = sum(d * d for d in material.diffuse)
    if dd == 0.0:
        return 0.0
    k = sum(a * d for a, d in zip(material.ambient, material.diffuse, strict=True)) / dd
    return min(1.0, max(0.0, k))


def to_x3d(material: Material, name: str) -> Converted:
    """An X3D file holding one sphere in an ``Appearance`` with the ``Material``."""
    k = x3d_ambient_intensity(material)
    shininess = min(1.0, material.shininess / X3D_SHININESS_SCALE)
    attrs = {
        "DEF": name,
        "diffuseColor": _triple(material.diffuse),
        "specularColor": _triple(material.specular),
        "emissiveColor": _triple(material.emission),
        "ambientIntensity": repr(k),
        "shininess": repr(shininess),
        "transparency": repr(1.0 - float(material.opacity)),
    }
    body = " ".join(f"{key}={quoteattr(value)}" for key, value in attrs.items())
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f"<!-- {_header(name)} -->\n"
        '<X3D profile="Interchange" version="3.3">\n'
        "  <Scene>\n"
        "    <Shape>\n"
        "      <Appearance>\n"
        f"        <Material {body}/>\n"
        f"{_x3d_texture(material.diffuse_map)}"
        "      </Appearance>\n"
        "      <Sphere/>\n"
        "    </Shape>\n"
        "  </Scene>\n"
        "</X3D>\n"
    )
    notes = []
    near = tuple(k * d for d in material.diffuse)
    off = max(abs(a - b) for a, b in zip(near, material.ambient, strict=True))
    if off > tol.X3D_AMBIENT_TOLERANCE:
        notes.append(
            f"ambient {_triple(material.ambient)} becomes ambientIntensity {k:.6g} × diffuse "
            f"= {_triple(near, '.4g')} (X3D's ambient is one number times diffuseColor; off "
            f"by up to {off:.3g})"
        )
    if material.shininess > X3D_SHININESS_SCALE:
        notes.append(
            f"shininess {material.shininess:g} is capped at 128 (X3D's shininess 1.0 is "
            "exponent 128)"
        )
    else:
        notes.append(f"shininess {material.shininess:g} is written as {shininess:.6g} × 128")
    if material.model == "phong":
        notes.append("model phong: X3D does not say which lobe a browser uses (mostly Blinn)")
    if material.diffuse_map is not None:
        notes.append(
            "ImageTexture: an RGB texture replaces diffuseColor in X3D's lighting (it does not "
            "multiply it as OpenGL's GL_MODULATE does the lit colour)"
        )
    notes += [f"X3D has no {what}" for what in _effects(material)]
    return Converted(text, tuple(notes))


def _x3d_texture(tmap) -> str:
    """The ``ImageTexture`` (and its ``TextureTransform``) of a diffuse map, or ""."""
    if tmap is None:
        return ""
    repeat = "false" if tmap.clamp else "true"
    url = quoteattr(json.dumps(tmap.file))
    text = f"        <ImageTexture url={url} repeatS='{repeat}' repeatT='{repeat}'/>\n"
    if tmap.scale[:2] != (1.0, 1.0) or tmap.offset[:2] != (0.0, 0.0):
        scale = f"{tmap.scale[0]!r} {tmap.scale[1]!r}"
        offset = f"{tmap.offset[0]!r} {tmap.offset[1]!r}"
        text += f"        <TextureTransform scale='{scale}' translation='{offset}'/>\n"
    return text


def blender_settings(material: Material) -> dict:
    """Principled BSDF inputs as Blender's OBJ importer sets them from this material's MTL."""
    ns = min(BLENDER_NS_MAX, max(0.0, material.shininess))
    return {
        "Base Color": tuple(material.diffuse),
        "Specular": sum(material.specular) / 3.0,
        "Roughness": 1.0 - math.sqrt(ns / BLENDER_NS_MAX),
        "Metallic": 0.0,
        "Emission": tuple(material.emission),
        "Alpha": float(material.opacity),
    }


def to_blender(material: Material, name: str) -> Converted:
    """What Blender shows after importing this material's .mtl (text, not a file format)."""
    settings = blender_settings(material)
    lines = [f"# {_header(name)}: Principled BSDF after Blender's OBJ import"]
    for key, value in settings.items():
        shown = _triple(value, ".6g") if isinstance(value, tuple) else f"{value:.6g}"
        lines.append(f"{key}: {shown}")
    roughness = settings["Roughness"]
    back = (1.0 - roughness) ** 2 * BLENDER_NS_MAX
    notes = [
        "ambient is dropped (Blender's importer reads Ka as 'metallic', and only for illum 3 "
        "and above)",
        f"Specular is the mean of the specular colour ({settings['Specular']:.6g}): its hue "
        "is lost",
        f"Roughness 1 - sqrt(Ns / 1000) = {roughness:.6g}; Blender's exporter writes it back "
        f"as Ns = (1 - roughness)² × 1000 = {back:.6g}, and 'Ka 1 1 1'",
        "the Principled BSDF is a physically based model: the same numbers do not give the "
        "same picture",
    ]
    notes += [f"Blender's MTL import has no {what}" for what in _effects(material)]
    return Converted("\n".join(lines) + "\n", tuple(notes))


def _effects(material: Material) -> list[str]:
    out = []
    if material.fresnel is not None:
        out.append(f"fresnel ({material.fresnel:g}): dropped")
    if material.energy_conserving:
        out.append("energy_conserving: dropped")
    return out


def _triple(rgb, spec: str = "r") -> str:
    if spec == "r":
        return " ".join(repr(float(c)) for c in rgb)
    return " ".join(format(float(c), spec) for c in rgb)
