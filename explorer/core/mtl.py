"""Wavefront material libraries (.mtl): read strictly, write exactly.

The statements the engine's material holds, and where each goes (the mapping, its
approximations and the sources it was checked against: ``docs/formats.md``)::

    Ka r g b    -> ambient          Kd r g b -> diffuse        Ks r g b -> specular
    Ke r g b    -> emission         Ns n     -> shininess (the exponent itself)
    d a         -> opacity          Tr t     -> opacity 1 - t (when no ``d`` is given)

A colour with one number is grey (``Kd 0.5`` is ``Kd 0.5 0.5 0.5``). A material without a
statement keeps the engine's default for it (OpenGL's: ambient 0.2, diffuse 0.8, specular 0,
emission 0, shininess 0). The texture maps ``map_Kd``, ``map_Ka``, ``map_Ke``, ``map_Ks``,
``map_Ns`` and ``bump`` (``map_Bump``) become the material's maps with their options ``-s``,
``-o``, ``-clamp``, ``-bm``, ``-imfchan`` (:mod:`explorer.core.texture`; an image named
outside the .mtl's folder is refused); the other options of a map and the other maps (``disp``,
``decal``, ``refl``, ``map_d``, ...) are dropped with a warning. ``Ni``, ``illum``, ``Tf``,
``sharpness`` and unknown statements are kept out of the material, each with a warning; so are
values that work differently here (``Ka 1 1 1``, ``Ns 0``, ``Ns`` above OpenGL's 128).

A file the reader cannot take (a word where a number belongs, ``spectral`` / ``xyz``
colours, a value outside the range a preset file holds, a statement before any ``newmtl``, no
``newmtl`` at all, binary data) raises one :class:`MtlError` whose message names the file and
the line; nothing is half read.

:func:`format_mtl` writes materials back with every float in ``repr`` form, so
``parse_mtl(format_mtl(m))`` gives identical coefficients.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from explorer.core import tolerances as tol
from explorer.core.atomic import check_target
from explorer.core.errors import ExplorerError
from explorer.core.files import UnreadableFile, read_checked
from explorer.core.material import (
    COEFFICIENT_RANGE,
    OPACITY_RANGE,
    SHININESS_RANGE,
    Material,
)
from explorer.core.presets import MAX_NAME_LENGTH, SUFFIX, save_presets
from explorer.core.texture import MAP_STATEMENTS, MTL_MAP_KEYS, parse_mtl_map, resolve_map
from explorer.core.validate import format_number

#: colour statement -> the material field it sets
COLOUR_KEYS = {"ka": "ambient", "kd": "diffuse", "ks": "specular", "ke": "emission"}
#: statements read and dropped, with why (the warning)
DROPPED = {
    "ni": "Ni (index of refraction) is not modelled: the engine has no refraction",
    "tf": "Tf (transmission filter) is not modelled: the engine has no transmission",
    "sharpness": "sharpness (reflection map sharpness) is not modelled",
}
#: illum models the engine's material is (0: colour only; 1: no highlight; 2: highlight)
MODELLED_ILLUM = (2,)
#: what each illum model means (the Alias MTL specification), for the warning
ILLUM_MEANING = {
    0: "colour on, ambient off (no lighting)",
    1: "colour and ambient on, no highlight",
    2: "highlight on",
    3: "reflection on, ray trace on",
    4: "glass, ray-traced reflection",
    5: "Fresnel reflection, ray trace on",
    6: "refraction, ray-traced reflection",
    7: "refraction, Fresnel reflection, ray trace on",
    8: "reflection on, ray trace off",
    9: "glass, reflection without ray tracing",
    10: "casts shadows onto invisible surfaces",
}
#: OpenGL 1.x / 2.1's largest GL_SHININESS: a larger exponent is legal in MTL and here
GL_MAX_SHININESS = 128.0
#: a number as MTL writes it: ASCII decimal digits, an optional sign, point and exponent
#: (``1``, ``-0.5``, ``.5``, ``1e-3``); not Python's ``1_0``, ``inf``, ``nan`` or other digits
MTL_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_TEXTURE = re.compile(r"(map_\w+|bump|disp|decal|refl|norm)")


class MtlError(ExplorerError):
    """An .mtl file the reader cannot take: the message is ``file:line: what is wrong``."""


class MtlUnreadable(MtlError):
    """An .mtl file that could not be opened or read at all (missing, not a regular file, too
    large); ``reason`` says which (:class:`explorer.core.files.UnreadableFile`)."""

    def __init__(self, exc: UnreadableFile):
        self.reason = exc.reason
        super().__init__(str(exc))


@dataclass(frozen=True)
class MtlMaterial:
    """One ``newmtl`` of a file.

    name : the name as the file has it
    material : the engine's material (``material.name`` is None: see :func:`preset_name`)
    line : the line of its ``newmtl``
    warnings : what was dropped or works differently here, one sentence each
    source : the file name the messages give; map_lines : map key -> the line of its statement
    """

    name: str
    material: Material
    line: int
    warnings: tuple[str, ...] = field(default=())
    source: str = field(default="<mtl>", compare=False)
    map_lines: dict = field(default_factory=dict, compare=False)


def read_mtl(path) -> list[MtlMaterial]:
    """The materials of an .mtl file (see :func:`parse_mtl`); a missing file, one that is not a
    regular file (a FIFO or device is refused without blocking) or one larger than
    ``MAX_MTL_FILE_BYTES`` raises an :class:`MtlError` naming it
    (:func:`explorer.core.files.read_checked`)."""
    shown = os.fspath(path)
    try:
        data = read_checked(shown, cap=tol.MAX_MTL_FILE_BYTES, what="material library")
    except UnreadableFile as exc:
        raise MtlUnreadable(exc) from None
    return [_resolved(m, os.path.dirname(shown)) for m in parse_mtl(data, shown)]


def _resolved(found: MtlMaterial, folder: str) -> MtlMaterial:
    """``found`` with its maps' images named from the .mtl's ``folder``; a name leading outside
    it is an :class:`MtlError` at the map's line."""
    changes = {}
    for key, tmap in found.material.maps().items():
        full = resolve_map(tmap, folder)
        if full is None:
            line = found.map_lines.get(key, found.line)
            raise MtlError(
                f"{found.source}:{line}: {MAP_STATEMENTS[key]} {tmap.file}: the image is outside "
                "the .mtl's folder; put it beside the .mtl (or in a folder below it)"
            )
        changes[key] = full
    if not changes:
        return found
    return dataclasses.replace(found, material=found.material.replace(**changes))


def parse_mtl(data: bytes | str, source: str = "<mtl>") -> list[MtlMaterial]:
    """Every material of an .mtl file's text, in file order (see the module docstring).

    data : the file's bytes (UTF-8, else Latin-1) or text; CRLF, CR and LF line ends, tabs and
        runs of blanks all work, ``#`` starts a comment, a trailing ``\\`` joins two lines
    source : the file name the messages give
    """
    text = _decode(data, source)
    out: list[MtlMaterial] = []
    current: _Builder | None = None
    for number, words in _statements(text):
        where = f"{source}:{number}"
        key = words[0].lower()
        if key == "newmtl":
            if len(words) < 2:
                raise MtlError(f"{where}: newmtl needs a material name")
            if current is not None:
                out.append(current.build())
            current = _Builder(check_mtl_name(" ".join(words[1:]), where), number, source)
            continue
        if current is None:
            raise MtlError(
                f"{where}: '{words[0]}' before any newmtl (a material library starts each "
                "material with 'newmtl NAME')"
            )
        current.statement(key, words, where)
    if current is not None:
        out.append(current.build())
    if not out:
        raise MtlError(f"{source}: no 'newmtl' in the file, so it defines no material")
    names = [m.name for m in out]
    for i, m in enumerate(out):
        if m.name in names[:i]:
            first = out[names.index(m.name)].line
            raise MtlError(
                f"{source}:{m.line}: material '{m.name}' is defined twice (first on line {first})"
            )
    return out


def _decode(data: bytes | str, source: str) -> str:
    if isinstance(data, str):
        text = data
    else:
        if b"\0" in data:
            at = data[: data.index(b"\0")].count(b"\n") + 1
            raise MtlError(f"{source}:{at}: binary data (a NUL byte): not an .mtl text file")
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError:
            text = data.decode("latin-1")  # older tools write names in Latin-1
    for number, line in enumerate(text.splitlines(), 1):
        bad = next((c for c in line if ord(c) < 32 and c not in "\t\f\v"), None)
        if bad is not None:
            raise MtlError(
                f"{source}:{number}: binary data (control character {bad!r}): not an .mtl text file"
            )
    return text


def _statements(text: str):
    """``(line number, words)`` of each statement; comments and blank lines skipped, a line
    ending in ``\\`` continued on the next."""
    pending: list[str] = []
    start = 0
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0]
        if not pending:
            start = number
        stripped = line.rstrip()
        if stripped.endswith("\\"):
            pending.extend(stripped[:-1].split())
            continue
        words = pending + line.split()
        pending = []
        if words:
            yield start, words
    if pending:
        yield start, pending


class _Builder:
    """The statements of one ``newmtl``, checked as they come."""

    def __init__(self, name: str, line: int, source: str):
        self.name, self.line, self.source = name, line, source
        self.fields: dict = {}
        self.warnings: list[tuple[int, str]] = []  # (line, message)
        self.tr: tuple[float, str] | None = None
        self.d_given = False
        self.illum: int | None = None
        self.seen: dict[str, int] = {}
        self.map_lines: dict[str, int] = {}

    def statement(self, key: str, words: list[str], where: str) -> None:
        line = int(where.rsplit(":", 1)[1])
        if key in self.seen:
            self._warn(
                line,
                f"{where}: '{words[0]}' given again (first on line {self.seen[key]}); the "
                "last one is used",
            )
        self.seen.setdefault(key, line)
        if key in COLOUR_KEYS:
            self.fields[COLOUR_KEYS[key]] = _colour(words, where)
        elif key == "ns":
            n = _number(words, 1, where, "Ns")
            _check_range(n, SHININESS_RANGE, where, "Ns (the specular exponent)")
            self.fields["shininess"] = n
        elif key == "d":
            args = words[1:]
            if args and args[0].lower() == "-halo":
                self._warn(line, f"{where}: 'd -halo' (view-dependent dissolve) read as d")
                args = args[1:]
            a = _number([words[0], *args], 1, where, "d")
            _check_range(a, OPACITY_RANGE, where, "d (opacity)")
            self.fields["opacity"] = a
            self.d_given = True
        elif key == "tr":
            t = _number(words, 1, where, "Tr")
            _check_range(t, OPACITY_RANGE, where, "Tr (transparency, 1 - d)")
            self.tr = (t, where)
        elif key == "illum":
            self.illum = _illum(words, where)
        elif key in DROPPED:
            _number(words, None, where, words[0])
            self._warn(line, f"{where}: {DROPPED[key]}")
        elif key in MTL_MAP_KEYS:
            tmap, dropped, problem = parse_mtl_map(words, where)
            if problem:
                raise MtlError(problem)
            for option in dropped:
                self._warn(line, f"{where}: {words[0]} option {option} is not modelled; dropped")
            self.fields[MTL_MAP_KEYS[key]] = tmap
            self.map_lines[MTL_MAP_KEYS[key]] = line
        elif _TEXTURE.fullmatch(key):
            self._warn(
                line,
                f"{where}: texture map '{words[0]}' is not used: the engine has no "
                f"{words[0]} (it reads map_Kd, map_Ka, map_Ke, map_Ks, map_Ns and bump)",
            )
        else:
            self._warn(line, f"{where}: '{words[0]}' is not an MTL statement this reader uses")

    def _warn(self, line: int, message: str) -> None:
        self.warnings.append((line, message))

    def build(self) -> MtlMaterial:
        if self.tr is not None:
            t, where = self.tr
            line = int(where.rsplit(":", 1)[1])
            if self.d_given:
                d = self.fields["opacity"]
                if not math.isclose(d, 1.0 - t, abs_tol=1e-9):
                    self._warn(
                        line,
                        f"{where}: Tr {t:g} disagrees with d {d:g} (Tr should be 1 - d); d is used",
                    )
            else:
                self.fields["opacity"] = 1.0 - t
                if t == 1.0:
                    self._warn(
                        line,
                        f"{where}: Tr 1 makes the material invisible (opacity 0); some writers "
                        "store opacity in Tr: if it should be opaque, write 'd 1'",
                    )
        material = Material(**self.fields)
        self._suspicious(material)
        warnings = [message for _, message in sorted(self.warnings, key=lambda w: w[0])]
        return MtlMaterial(
            self.name, material, self.line, tuple(warnings), self.source, dict(self.map_lines)
        )

    def _warn_at(self, key: str, text: str) -> None:
        """Warn at the statement ``key`` (the ``newmtl`` line when it is absent)."""
        line = self.seen.get(key, self.line)
        self._warn(line, f"{self.source}:{line}: {text}")

    def _suspicious(self, m: Material) -> None:
        """Warn of values that mean something else here than their writer meant."""
        if m.ambient == (1.0, 1.0, 1.0):
            self._warn_at(
                "ka",
                "'Ka 1 1 1' (Blender's exporter writes it: it holds Blender's 'metallic', not "
                "an ambient colour) adds the scene's whole ambient light, in white, to every "
                "vertex (a washed-out look); the diffuse colour times 0.2 is OpenGL's default",
            )
        if m.shininess == 0.0 and max(m.specular) > 0.0:
            self._warn_at(
                "ns",
                "'Ns 0' with a specular colour: under OpenGL 0^0 = 1, a flat full highlight on "
                "every lit vertex (writers such as Max2Mtl mean 'no highlight')",
            )
        if m.shininess > GL_MAX_SHININESS:
            self._warn_at(
                "ns",
                f"Ns {m.shininess:g} is above OpenGL's largest GL_SHININESS "
                f"({GL_MAX_SHININESS:g}); the engine takes it as it is",
            )
        quiet = self.illum == 1 and max(m.specular) == 0.0  # no highlight asked, none given
        if self.illum is not None and self.illum not in MODELLED_ILLUM and not quiet:
            self._warn_at(
                "illum",
                f"illum {self.illum} ({ILLUM_MEANING[self.illum]}) is not modelled: the "
                "material is shaded as illum 2 (ambient, diffuse and highlight)",
            )


def _number(words: list[str], count: int | None, where: str, what: str) -> float:
    """The single number after the keyword (``count`` 1), or just that the arguments are
    numbers (``count`` None)."""
    args = words[1:]
    if count is not None and len(args) != count:
        raise MtlError(f"{where}: {what} takes {count} number, got {len(args)} ({' '.join(args)})")
    values = [_float(a, where, what) for a in args]
    return values[0] if values else math.nan


def _float(word: str, where: str, what: str) -> float:
    if word.lstrip("+-").lower() in ("nan", "inf", "infinity"):
        raise MtlError(f"{where}: {what}: {word!r} is not a finite number")
    if not MTL_NUMBER.fullmatch(word):  # float() also takes '1_0' and non-ASCII digits
        raise MtlError(f"{where}: {what}: {word!r} is not a number")
    value = float(word)
    if not math.isfinite(value):
        raise MtlError(f"{where}: {what}: {word!r} is not a finite number")
    return value


def _colour(words: list[str], where: str) -> tuple[float, float, float]:
    what = words[0]
    args = words[1:]
    if args and args[0].lower() in ("spectral", "xyz"):
        raise MtlError(
            f"{where}: {what} {args[0]}: {args[0]} colours are not read (the engine takes RGB; "
            f"write '{what} r g b')"
        )
    if len(args) not in (1, 3):
        raise MtlError(
            f"{where}: {what} takes 1 number (grey) or 3 (r g b), got {len(args)} "
            f"({' '.join(args)})"
        )
    values = [_float(a, where, what) for a in args]
    for v in values:
        _check_range(v, COEFFICIENT_RANGE, where, what)
    r, g, b = values * 3 if len(values) == 1 else values
    return r, g, b


def _check_range(value: float, bounds: tuple[float, float], where: str, what: str) -> None:
    lo, hi = bounds
    if not lo <= value <= hi:
        shown = ", ".join(format_number(v) for v in (lo, hi))
        raise MtlError(f"{where}: {what} must be in [{shown}], got {format_number(value)}")


def _illum(words: list[str], where: str) -> int:
    value = _number(words, 1, where, "illum")
    if value != int(value) or int(value) not in ILLUM_MEANING:
        raise MtlError(f"{where}: illum must be a whole number from 0 to 10, got {words[1]}")
    return int(value)


# -- names -----------------------------------------------------------------------------------
def check_mtl_name(name: str, where: str) -> str:
    """``name`` if a ``newmtl`` may have it: at most ``MAX_MTL_NAME_LENGTH`` characters (a
    longer one would make a preset file that the preset reader refuses); else an
    :class:`MtlError` at ``where``."""
    if len(name) > tol.MAX_MTL_NAME_LENGTH:
        raise MtlError(
            f"{where}: newmtl name is {len(name)} characters long; the limit is "
            f"{tol.MAX_MTL_NAME_LENGTH}"
        )
    return name


def preset_name(name: str) -> str:
    """A preset name (lowercase letters, digits, ``_``) made from a material name: letters
    lowercased, runs of anything else one ``_``, at most ``MAX_NAME_LENGTH`` characters;
    ``material`` when nothing is left."""
    out = re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")[:MAX_NAME_LENGTH].strip("_")
    return out or "material"


def preset_names(names: list[str]) -> list[str]:
    """:func:`preset_name` of each, made unique with ``_2``, ``_3``... in file order."""
    out: list[str] = []
    for name in names:
        base = preset_name(name)
        candidate, k = base, 2
        while candidate in out:
            suffix = f"_{k}"
            candidate = base[: MAX_NAME_LENGTH - len(suffix)] + suffix
            k += 1
        out.append(candidate)
    return out


@dataclass(frozen=True)
class MtlImport:
    """What importing an .mtl file into a preset directory writes (``presets import``, the
    window's Import materials): one preset per ``newmtl``, named by :func:`preset_names`.

    found : the file's materials; names : their preset names; targets : the preset files
    """

    source: str
    found: tuple
    names: tuple
    targets: tuple

    @property
    def existing(self) -> list[Path]:
        """The targets that exist already (replaced only when asked). A target that could
        not be written (its folder locked, its name too long, a FIFO there) is an
        :class:`~explorer.core.atomic.UnwritableFile` here, before anything is written."""
        return [
            t
            for t in self.targets
            if check_target(t, overwrite=True, make_dirs=True) and os.path.lexists(t)
        ]

    def write(self, overwrite: bool) -> list[Path]:
        """Write every preset, all or nothing (:func:`~explorer.core.presets.save_presets`:
        an existing file is replaced only with ``overwrite``; a failure or an interrupt
        leaves the directory as it was)."""
        origin = Path(self.source).name
        items = [
            (m.material.replace(description=f"imported from {origin}: {m.name}"), name)
            for m, name in zip(self.found, self.names, strict=True)
        ]
        return save_presets(items, self.targets[0].parent if self.targets else None, overwrite)


def mtl_import(path, directory) -> MtlImport:
    """Read ``path`` (:func:`read_mtl`: a problem raises :class:`MtlError`) and name the preset
    files it makes in ``directory``; nothing is written yet (:meth:`MtlImport.write`)."""
    found = read_mtl(path)
    names = preset_names([m.name for m in found])
    targets = tuple(Path(directory) / f"{name}{SUFFIX}" for name in names)
    return MtlImport(str(path), tuple(found), tuple(names), targets)


# -- writing ---------------------------------------------------------------------------------
def format_mtl(materials, header: str = "", folder=None) -> str:
    """An .mtl file of ``[(name, Material), ...]``: ``Ka Kd Ks Ke Ns d illum`` with every float
    in ``repr`` form (it reads back identical), then its maps (``map_Kd [options] file``; an
    image inside ``folder``, the .mtl's own, is named relative to it). ``illum`` is 2
    (highlight on), 1 when the material has no specular colour. What MTL has no statement for
    (the specular model, ``fresnel``, ``energy_conserving``) is written as a comment."""
    lines = [f"# {line}" for line in header.splitlines()] if header else []
    for name, m in materials:
        if not name or any(c.isspace() for c in name):
            raise ExplorerError(f"an MTL material name needs no blanks, got {name!r}")
        if lines:
            lines.append("")
        lines.append(f"newmtl {name}")
        for key, attr in COLOUR_KEYS.items():
            rgb = " ".join(repr(float(c)) for c in getattr(m, attr))
            lines.append(f"{key.capitalize()} {rgb}")
        lines.append(f"Ns {float(m.shininess)!r}")
        lines.append(f"d {float(m.opacity)!r}")
        lines.append(f"illum {2 if max(m.specular) > 0.0 else 1}")
        for key, tmap in m.maps().items():
            if folder is not None and os.path.isabs(tmap.file):
                inside_folder = os.path.relpath(tmap.file, folder)
                if not inside_folder.startswith(os.pardir):
                    tmap = dataclasses.replace(tmap, file=inside_folder)
            lines.append(" ".join([MAP_STATEMENTS[key], *tmap.mtl_words()]))
        lines.extend(f"# not in MTL: {note}" for note in lost_in_mtl(m))
    return "\n".join(lines) + "\n"


def lost_in_mtl(m: Material) -> list[str]:
    """What of ``m`` an .mtl file cannot hold, one phrase each."""
    out = []
    if m.model is not None:
        out.append(f"model {m.model} (MTL names no specular model; readers mostly use Blinn)")
    if m.fresnel is not None:
        out.append(f"fresnel {m.fresnel!r}")
    if m.energy_conserving:
        out.append("energy_conserving true")
    return out
