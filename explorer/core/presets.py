"""The material preset library: built-in presets, the user's own, listed, found and saved.

A preset is one YAML file in a preset directory; its file stem is the preset's name
(lowercase letters, digits and ``_``; files with other names are ignored with a notice). Three
kinds of directories are searched, the first one holding a name wins:

1. ``materials_dirs`` (the ``--materials-dir DIR`` options), in the order given;
2. the user's directory, :func:`user_dir` (``$PHONG_EXPLORER_MATERIALS`` if set, otherwise
   ``<user config dir>/phong-explorer/materials``); it need not exist;
3. the built-in presets shipped inside the package, :func:`builtin_dir`.

A preset that hides another one of the same name gets a notice (once per process for
warnings, so nothing is repeated per frame); ``notices=[...]`` collects them instead.
"""

from __future__ import annotations

import os
import re
import stat
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from platformdirs import user_config_dir

from explorer.core.atomic import write_all_atomic, write_atomic
from explorer.core.errors import ExplorerError, Notice, ValidationError
from explorer.core.files import file_kind
from explorer.core.material import Material, parse_material
from explorer.core.texture import resolve_map
from explorer.core.validate import Checker, suggest
from explorer.core.version import __version__
from explorer.core.yamlio import dump_yaml, load_yaml

#: Environment variable overriding the user's preset directory (used by the tests).
ENV_VAR = "PHONG_EXPLORER_MATERIALS"
#: A valid preset name (also its file stem).
NAME_PATTERN = re.compile(r"[a-z0-9_]+")
MAX_NAME_LENGTH = 64
SUFFIX = ".yaml"


class PresetNotice(Notice):
    """A preset hides another of the same name, or a file in a preset directory is skipped."""


@dataclass(frozen=True)
class PresetInfo:
    """One preset as found in the library.

    name : preset name (the file stem)
    path : the file it was read from
    material : the loaded :class:`~explorer.core.material.Material` (``material.name == name``)
    source : "extra" (a ``--materials-dir`` directory), "user" or "builtin"
    hides : the file of the same name it hides (next in precedence), or None
    """

    name: str
    path: Path
    material: Material
    source: str
    hides: Path | None = None


# -- directories -----------------------------------------------------------------------------
def builtin_dir() -> Path:
    """Directory of the built-in presets (inside the installed package)."""
    root = resources.files("explorer.materials")
    if not isinstance(root, os.PathLike):  # e.g. a zipped install: the presets are no files
        raise TypeError(f"the built-in presets are not files on disk: {root!r}")
    return Path(os.fspath(root))


def user_dir() -> Path:
    """The user's preset directory (may not exist yet)."""
    env = os.environ.get(ENV_VAR)
    if env:
        return Path(env).expanduser()
    return Path(user_config_dir("phong-explorer")) / "materials"


def search_dirs(materials_dirs: Iterable = ()) -> list[tuple[Path, str]]:
    """``[(directory, source), ...]`` in precedence order (first wins).

    A ``--materials-dir`` directory that does not exist or cannot be read is an error (it was
    asked for); a missing user directory is simply skipped, one that cannot be searched (its
    folder locked, its name too long) is skipped with a notice.
    """
    dirs: list[tuple[Path, str]] = []
    for d in materials_dirs or ():
        path = Path(os.fspath(d)).expanduser()
        try:
            is_dir = stat.S_ISDIR(os.stat(path).st_mode)
        except FileNotFoundError:
            raise ExplorerError(f"materials directory {path} does not exist") from None
        except (OSError, ValueError) as exc:  # a folder on the way not searchable, too long
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise ExplorerError(f"materials directory {path}: cannot read it: {reason}") from None
        if not is_dir:
            raise ExplorerError(f"materials directory {path} is not a directory")
        dirs.append((path, "extra"))
    user = user_dir()
    try:
        if stat.S_ISDIR(os.stat(user).st_mode):
            dirs.append((user, "user"))
    except FileNotFoundError:
        pass
    except (OSError, ValueError) as exc:  # not searchable, a name too long: said, left out
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        _notice(
            None,
            f"cannot read the user's preset directory {user}: {reason}; its presets are left out",
        )
    dirs.append((builtin_dir(), "builtin"))
    # the same directory twice (e.g. --materials-dir pointing at the user dir) counts once
    seen: set = set()
    unique = []
    for path, source in dirs:
        key = os.path.realpath(path)
        if key not in seen:
            seen.add(key)
            unique.append((path, source))
    return unique


def is_valid_name(name) -> bool:
    return (
        isinstance(name, str)
        and len(name) <= MAX_NAME_LENGTH
        and NAME_PATTERN.fullmatch(name) is not None
    )


def check_name(name) -> str:
    """``name`` if it is a valid preset name, else an :class:`ExplorerError` saying why."""
    if is_valid_name(name):
        return name
    raise ExplorerError(
        f"{name!r} is not a valid preset name: use 1 to {MAX_NAME_LENGTH} lowercase letters, "
        "digits and '_' (it becomes the file name)"
    )


# -- reading ---------------------------------------------------------------------------------
def load_material_file(path) -> Material:
    """Load one material file (either form). Every problem in it, from YAML duplicate keys to
    out-of-range values, is reported in one :class:`~explorer.core.errors.ValidationError`, in
    line order. The material's name is the file stem."""
    doc = load_yaml(path, what="material file", collect=True)
    checker = doc.checker()
    material = None
    if checker.mapping(doc.data, (), "a mapping of material keys") is not None:
        material = parse_material(doc.data, checker, ())
    if material is not None and material.maps():
        material = _maps_from(material, os.path.dirname(os.fspath(path)), checker)
    if checker.problems:
        raise ValidationError(sorted(checker.problems, key=lambda p: p.line or 0))
    assert material is not None  # parse_material records a problem whenever it gives None
    return material.replace(name=Path(os.fspath(path)).stem)


def _maps_from(material: Material, folder: str, checker: Checker) -> Material:
    """A preset's maps: a relative image name from the preset's folder (inside it), a full
    one as it is (:func:`~explorer.core.texture.resolve_map`)."""
    changes = {}
    for key, tmap in material.maps().items():
        full = resolve_map(tmap, folder, absolute=True)
        if full is None:
            checker.problem((key,), f"the image {tmap.file!r} is outside the preset's folder")
        else:
            changes[key] = full
    return material.replace(**changes)


def _scan(dirs, notices) -> dict[str, list[tuple[Path, str]]]:
    """name -> [(file, source), ...] in precedence order."""
    found: dict[str, list[tuple[Path, str]]] = {}
    for directory, source in dirs:
        try:
            entries = sorted(directory.iterdir())
        except OSError as exc:
            _notice(notices, f"cannot list preset directory {directory}: {exc.strerror or exc}")
            continue
        for path in entries:
            if path.suffix != SUFFIX or path.name.startswith("."):
                continue
            if not is_valid_name(path.stem):
                _notice(
                    notices,
                    f"{path}: ignored, {path.stem!r} is not a preset name (lowercase letters, "
                    "digits and '_')",
                )
                continue
            kind = _not_a_regular_file(path)
            if kind is not None:
                _notice(notices, f"{path}: ignored, it is {kind}, not a preset file")
                continue
            found.setdefault(path.stem, []).append((path, source))
    return found


def _not_a_regular_file(path: Path) -> str | None:
    """What ``path`` is when it is not a regular file (following symlinks), else None. Only
    ``stat``: a FIFO is never opened, so scanning never blocks. A file that cannot be
    examined is kept (loading it reports why)."""
    try:
        mode = path.stat().st_mode
    except OSError:
        return None
    return None if stat.S_ISREG(mode) else file_kind(mode)


def list_presets(materials_dirs: Iterable = (), *, notices: list | None = None) -> list[PresetInfo]:
    """Every preset, sorted by name, each from the first directory that has it.

    A preset file that does not load is left out of the list with a notice (its problems);
    :func:`find_preset` on that name raises them. Notices go to ``notices`` when a list is
    given, otherwise each is issued once per process as a :class:`PresetNotice` warning.
    """
    found = _scan(search_dirs(materials_dirs), notices)
    out = []
    for name in sorted(found):
        (path, source), *rest = found[name]
        try:
            material = load_material_file(path)
        except ValidationError as exc:
            _notice(notices, f"preset '{name}' skipped, it has problems:\n{exc}")
            continue
        hides = rest[0][0] if rest else None
        if hides is not None:
            _notice(notices, _hidden_message(name, path, source, rest[0]))
        out.append(PresetInfo(name, path, material, source, hides))
    return out


def locate_preset(name: str, materials_dirs: Iterable = ()) -> tuple[Path, str, Path | None]:
    """``(file, source, hidden file or None)`` of preset ``name``, without loading it."""
    _check_lookup_name(name)
    dirs = search_dirs(materials_dirs)
    modes = [(d / f"{name}{SUFFIX}", s, _mode(d / f"{name}{SUFFIX}")) for d, s in dirs]
    hits = [(path, s) for path, s, mode in modes if mode is not None and stat.S_ISREG(mode)]
    if not hits:
        for path, _, mode in modes:  # the name is there, but not as a file: say what it is
            if mode is not None and not stat.S_ISREG(mode):
                kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
                raise ExplorerError(
                    f"material preset {name!r}: {path} is {kind}, not a preset file"
                )
        known = sorted(n for n, files in _scan(dirs, []).items() if _is_file(files[0][0]))
        hint = suggest(name.lower(), known) or suggest(name, known)
        where = "; ".join(f"{d} ({s})" for d, s in dirs)
        raise ExplorerError(
            f"unknown material preset {name!r}{hint}. Looked in: {where}. "
            "'phong-explorer presets' lists them all"
        )
    (path, source), *rest = hits
    return path, source, (rest[0][0] if rest else None)


def find_preset(
    name: str, materials_dirs: Iterable = (), *, notices: list | None = None
) -> Material:
    """The material of preset ``name`` (``material.name == name``).

    Unknown name: :class:`ExplorerError` with a did-you-mean and the directories searched. A
    preset file with problems: its :class:`ValidationError` (no silent fallback to a built-in
    of the same name).
    """
    path, source, hidden = locate_preset(name, materials_dirs)
    material = load_material_file(path)
    if hidden is not None:
        _notice(notices, _hidden_message(name, path, source, (hidden, None)))
    return material


def _check_lookup_name(name) -> None:
    if not isinstance(name, str):
        raise ExplorerError(f"a preset name must be text, got {type(name).__name__}")
    if not is_valid_name(name):
        hint = ""
        if is_valid_name(name.lower()):
            hint = f" (preset names are lowercase: '{name.lower()}')"
        elif name.endswith((".yaml", ".yml")) or "/" in name or os.sep in name:
            hint = " (that looks like a file; preset names are file stems, e.g. 'gold')"
        raise ExplorerError(
            f"{name!r} is not a valid preset name: lowercase letters, digits and '_'{hint}"
        )


# -- writing ---------------------------------------------------------------------------------
def save_preset(material: Material, name: str, directory=None, overwrite: bool = False) -> Path:
    """Write ``material`` as preset ``name`` (``<directory>/<name>.yaml``, default
    :func:`user_dir`) in the RGB form; returns the file written.

    The file loads back to identical colours. It is written atomically and an existing file
    is only replaced with ``overwrite=True``. A material a file could not hold (a coefficient
    above 1, shininess above 1000) is refused before anything is written.
    """
    data = preset_bytes(material, name)  # before touching the disk: bad data fails first
    return write_atomic(preset_path(name, directory), data, overwrite=overwrite, make_dirs=True)


def save_presets(items, directory=None, overwrite: bool = False) -> list[Path]:
    """Write several presets all-or-nothing: ``items`` is ``[(material, name), ...]``. Every
    file is checked and made first, then all are put in place together
    (:func:`~explorer.core.atomic.write_all_atomic`): a problem, a directory where a file
    goes, a preset that exists (without ``overwrite``) or an interrupt leaves the directory as
    it was. Returns the files written, in order."""
    files = {preset_path(name, directory): preset_bytes(m, name) for m, name in items}
    return write_all_atomic(files, overwrite=overwrite, make_dirs=True)


def preset_path(name: str, directory=None) -> Path:
    """Where preset ``name`` is saved in ``directory`` (default :func:`user_dir`)."""
    directory = user_dir() if directory is None else Path(os.fspath(directory)).expanduser()
    return directory / f"{name}{SUFFIX}"


def preset_bytes(material: Material, name: str) -> bytes:
    """The preset file of ``material`` named ``name``, checked as :func:`save_preset` says."""
    check_name(name)
    if not isinstance(material, Material):
        raise ExplorerError(f"save_preset needs a Material, got {type(material).__name__}")
    data = material.to_mapping()
    checker = Checker(f"preset '{name}'")
    parse_material(data, checker, ())
    checker.raise_if_any()
    header = f"phong-explorer material preset '{name}' (saved by phong-explorer {__version__})"
    return dump_yaml(data, header=header).encode("utf-8")


# -- notices ---------------------------------------------------------------------------------
_NOTICED: set[str] = set()


def _hidden_message(name, path, source, hidden) -> str:
    label = {"extra": "--materials-dir", "user": "user", "builtin": "built-in"}.get(source, source)
    return f"preset '{name}': using {path} ({label}), which hides {hidden[0]}"


def _is_file(path: Path) -> bool:
    mode = _mode(path)
    return mode is not None and stat.S_ISREG(mode)


def _mode(path: Path) -> int | None:
    """``st_mode`` of ``path`` (links followed), None when it cannot be had: nothing there, or
    a directory that cannot be searched (its listing says so in a notice)."""
    try:
        return os.stat(path).st_mode
    except (OSError, ValueError):
        return None


def _notice(notices: list | None, message: str) -> None:
    if notices is not None:
        notices.append(message)
    elif message not in _NOTICED:
        _NOTICED.add(message)
        warnings.warn(message, PresetNotice, stacklevel=3)
