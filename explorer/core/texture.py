"""Texture maps: which image a material term wears, and how (the .mtl options).

A material has one optional map per term, each a :class:`TextureMap` (key = the scene file's
and preset file's key = the ``--diffuse-map`` flag; the .mtl statement it comes from)::

    diffuse_map    map_Kd       ambient_map   map_Ka       emission_map   map_Ke
    specular_map   map_Ks       shininess_map map_Ns       bump_map       bump / map_Bump

and the options a map statement may carry, each a key of its own::

    -s u v w   -> scale   (default 1 1 1)    -o u v w   -> offset (default 0 0 0)
    -clamp on  -> clamp   (default off: the texture repeats)
    -bm m      -> bump_multiplier (bump only; default 1)
    -imfchan c -> channel (r, g, b, m (matte), l (luminance), z (depth); the scalar maps')

A texture coordinate (u, v) of the mesh is looked up at ``(u·su + ou, v·sv + ov)``. In a file a
map is the image's name (``diffuse_map: wood.png``) or a mapping with ``file`` and the options
above. A name is relative to the file that gives it (the scene, the .mtl) and must lie inside
that file's folder (:func:`explorer.core.files.inside`), as an OBJ's ``mtllib`` must; the image
itself is read when it is drawn (:mod:`explorer.render.textures`: PNG or JPEG, through the
checked open, with the caps of :mod:`explorer.core.tolerances`).

How each map is drawn per vertex (OpenGL 2.1's ``GL_MODULATE`` on the exact light sums) is in
``docs/formats.md``; ``specular_map``, ``shininess_map`` and ``bump_map`` need per-pixel
shading: a per-pixel picture draws every map (:mod:`explorer.render.pixelmaps`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import ClassVar

from explorer.core.files import inside
from explorer.core.validate import Check, Checked, Checker, check_fields

#: material key -> the .mtl statement written for it
MAP_STATEMENTS = {
    "diffuse_map": "map_Kd",
    "ambient_map": "map_Ka",
    "emission_map": "map_Ke",
    "specular_map": "map_Ks",
    "shininess_map": "map_Ns",
    "bump_map": "bump",
}
#: the material keys of the maps, in the order they are written
MAP_KEYS = tuple(MAP_STATEMENTS)
#: .mtl statement (lower case) -> material key
MTL_MAP_KEYS = {
    **{statement.lower(): key for key, statement in MAP_STATEMENTS.items()},
    "map_bump": "bump_map",
}
#: the maps a per-vertex picture draws (GL_MODULATE of the interpolated light sums; the ambient
#: and emission maps as layers of their own: explorer.render.textured)
PER_VERTEX_MAPS = ("diffuse_map", "ambient_map", "emission_map")
#: ``-imfchan`` values: red, green, blue, matte, luminance, depth
CHANNELS = ("r", "g", "b", "m", "l", "z")
#: keys of a map written as a mapping
TEXTURE_MAP_KEYS = ("file", "scale", "offset", "clamp", "bump_multiplier", "channel")
#: .mtl options of a map statement that are read, and how many numbers / words each takes
MTL_OPTIONS = {"-s": 3, "-o": 3, "-clamp": 1, "-bm": 1, "-imfchan": 1}
#: .mtl options a map statement may carry that are read and dropped (the warning says so), with
#: the number of words each takes at most
MTL_DROPPED_OPTIONS = {
    "-blendu": 1,
    "-blendv": 1,
    "-boost": 1,
    "-mm": 2,
    "-t": 3,
    "-texres": 1,
    "-cc": 1,
    "-type": 1,
}


def _file(checker: Checker, value, path):
    text = checker.string(value, path)
    if text is not None and (not text.strip() or "\0" in text):
        checker.problem(path, "must name an image file (PNG or JPEG)")
        return None
    return text


def _uvw(checker: Checker, value, path):
    return checker.triple(value, path)


def _flag(checker: Checker, value, path):
    return checker.boolean(value, path)


def _multiplier(checker: Checker, value, path):
    return checker.number(value, path)


def _channel(checker: Checker, value, path):
    return checker.choice(value, path, CHANNELS)


@dataclass(frozen=True)
class TextureMap(Checked):
    """One map: the image ``file`` and the options (see the module docstring)."""

    file: str
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    clamp: bool = False
    bump_multiplier: float = 1.0
    channel: str | None = None

    KEYS: ClassVar[dict[str, Check]] = {
        "file": _file,
        "scale": _uvw,
        "offset": _uvw,
        "clamp": _flag,
        "bump_multiplier": _multiplier,
        "channel": _channel,
    }

    def to_mapping(self):
        """The file's form: the name alone when every option is the default, else a mapping."""
        out: dict = {"file": self.file}
        defaults = TextureMap(self.file)
        for key in TEXTURE_MAP_KEYS[1:]:
            value = getattr(self, key)
            if value != getattr(defaults, key):
                out[key] = list(value) if isinstance(value, tuple) else value
        return self.file if len(out) == 1 else out

    def mtl_words(self) -> list[str]:
        """The options and the name as an .mtl map statement writes them (after the keyword)."""
        words: list[str] = []
        if self.scale != (1.0, 1.0, 1.0):
            words += ["-s", *(repr(float(c)) for c in self.scale)]
        if self.offset != (0.0, 0.0, 0.0):
            words += ["-o", *(repr(float(c)) for c in self.offset)]
        if self.clamp:
            words += ["-clamp", "on"]
        if self.bump_multiplier != 1.0:
            words += ["-bm", repr(float(self.bump_multiplier))]
        if self.channel is not None:
            words += ["-imfchan", self.channel]
        return [*words, self.file]

    def lookup(self, uv):
        """The texture coordinates looked up for the mesh's ``uv`` (n, 2): scaled, offset."""
        import numpy as np

        uv = np.asarray(uv, np.float64)
        return uv * np.asarray(self.scale[:2]) + np.asarray(self.offset[:2])


def parse_texture_map(checker: Checker, value, path) -> TextureMap | None:
    """A :class:`TextureMap` from a file's value: an image name, or a mapping of
    :data:`TEXTURE_MAP_KEYS` (``file`` required); every problem reported to ``checker``."""
    if isinstance(value, TextureMap):
        return value
    if isinstance(value, str):
        name = _file(checker, value, path)
        return None if name is None else TextureMap(name)
    m = checker.mapping(value, path, "an image name or a mapping with 'file'")
    if m is None:
        return None
    if not checker.keys(m, path, TEXTURE_MAP_KEYS, required=("file",)):
        return None
    kw = check_fields(TextureMap.KEYS, m, checker, path)
    if any(v is None for v in kw.values()):
        return None
    return TextureMap(**kw)


def resolve_map(
    tmap: TextureMap, folder: str | None, *, absolute: bool = False
) -> TextureMap | None:
    """``tmap`` with its file named from the folder of the file that gave it (``folder``; None
    for a mapping given in code: the name as it is), or None when the name leads outside that
    folder. absolute : an absolute name is taken as it is (a preset file: ``presets import``
    writes the image's full name into the user's own library)."""
    name = os.path.expanduser(tmap.file) if folder is None else tmap.file
    if folder is None or (absolute and os.path.isabs(name)):
        return tmap if name == tmap.file else TextureMap(**{**_fields(tmap), "file": name})
    full = inside(folder, name)
    if full is None:
        return None
    return TextureMap(**{**_fields(tmap), "file": os.path.normpath(full)})


def _fields(tmap: TextureMap) -> dict:
    return {key: getattr(tmap, key) for key in TEXTURE_MAP_KEYS}


def parse_mtl_map(words: list[str], where: str) -> tuple[TextureMap | None, list[str], str]:
    """``(map, dropped, problem)`` of an .mtl map statement's words (the keyword first):
    ``dropped`` names each option read and not used; ``problem`` is "" or why the statement
    cannot be read (a missing file name, a bad option value)."""
    args = words[1:]
    kw: dict = {}
    dropped: list[str] = []
    i = 0
    while i < len(args) and args[i].startswith("-") and len(args[i]) > 1:
        option = args[i].lower()
        if option in MTL_OPTIONS:
            count = MTL_OPTIONS[option]
            values = args[i + 1 : i + 1 + count]
            if option in ("-s", "-o"):  # u [v [w]]: the ones not given keep their default
                numbers = _numbers(args, i + 1, 3)
                if not numbers:
                    return None, dropped, f"{where}: {args[i]} needs 1 to 3 numbers"
                default = 1.0 if option == "-s" else 0.0
                full = tuple(numbers + [default] * (3 - len(numbers)))
                kw["scale" if option == "-s" else "offset"] = full
                i += 1 + len(numbers)
                continue
            values = args[i + 1 : min(i + 2, len(args) - 1)]  # never the last word: the name
            if not values:
                return None, dropped, f"{where}: {args[i]} needs a value"
            value = values[0]
            if option == "-clamp":
                if value.lower() not in ("on", "off"):
                    return None, dropped, f"{where}: -clamp takes on or off, got {value!r}"
                kw["clamp"] = value.lower() == "on"
            elif option == "-bm":
                try:
                    kw["bump_multiplier"] = float(value)
                except ValueError:
                    return None, dropped, f"{where}: -bm takes a number, got {value!r}"
            else:
                if value.lower() not in CHANNELS:
                    return (
                        None,
                        dropped,
                        (f"{where}: -imfchan takes one of {', '.join(CHANNELS)}, got {value!r}"),
                    )
                kw["channel"] = value.lower()
            i += 2
            continue
        if option in MTL_DROPPED_OPTIONS:
            dropped.append(args[i])
            i = _after_values(args, i + 1, MTL_DROPPED_OPTIONS[option])
            continue
        break  # a name starting with '-'
    name = " ".join(args[i:])
    if not name:
        return None, dropped, f"{where}: {words[0]} needs an image file name"
    try:
        return TextureMap(file=name, **kw), dropped, ""
    except ValueError as exc:
        return None, dropped, f"{where}: {words[0]}: {exc}"


def _numbers(args: list[str], i: int, most: int) -> list[float]:
    """Up to ``most`` numbers from ``args[i]`` on, never the last word (the file name)."""
    out: list[float] = []
    while len(out) < most and i < len(args) - 1 and _is_number(args[i]):
        out.append(float(args[i]))
        i += 1
    return out


def _after_values(args: list[str], i: int, most: int) -> int:
    """The index after a dropped option's values from ``args[i]`` on: up to ``most`` words that
    are not the next option, never the last word (the file name)."""
    taken = 0
    while taken < most and i < len(args) - 1 and not args[i].startswith("-"):
        i += 1
        taken += 1
    return i


def _is_number(word: str) -> bool:
    try:
        value = float(word)
    except ValueError:
        return False
    return value == value and abs(value) != float("inf")
