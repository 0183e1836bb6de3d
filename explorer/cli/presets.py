"""``phong-explorer presets``: list, show and validate material presets.

::

    phong-explorer presets [list]            every preset: swatch, name, shininess, description
    phong-explorer presets show NAME|FILE    its values (copy-pastable YAML) and where it is from
    phong-explorer presets validate PATH...  check files (directories: every *.yaml in them);
                                             one line per problem on stdout, exit status 1
    phong-explorer presets show NAME --as mtl|threejs|x3d|blender
                                             the preset as that tool holds it, and what changes
    phong-explorer presets import FILE.mtl [--into DIR] [--force]
                                             one preset per newmtl (default DIR: the user's
                                             preset directory), warnings for what is dropped
    phong-explorer presets export NAME --out FILE.mtl|.json|.x3d [--force]
                                             MTL (exact), three.js MeshPhongMaterial JSON or an
                                             X3D Material, and the approximations made

``--materials-dir DIR`` (repeatable) adds preset directories searched before the user's and the
built-in ones. The colour swatch is drawn with 24-bit ANSI colour only when stdout is a
terminal, ``NO_COLOR`` is unset (or empty) and ``TERM`` is not ``dumb``.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from explorer.cli.options import add_materials_dir_option
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError, Problem, ValidationError
from explorer.core.formats import EXPORT_SUFFIXES, SHOW_FORMATS, convert
from explorer.core.material import Material
from explorer.core.mtl import MtlError, mtl_import, preset_name, read_mtl
from explorer.core.presets import (
    SUFFIX,
    is_valid_name,
    list_presets,
    load_material_file,
    locate_preset,
    user_dir,
)
from explorer.core.text import printable
from explorer.core.yamlio import dump_yaml

#: Scene ambient used for the swatch (OpenGL's default light-model ambient).
SWATCH_SCENE_AMBIENT = 0.2


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_materials_dir_option(parser)
    sub = parser.add_subparsers(dest="presets_command", metavar="ACTION")
    p_list = sub.add_parser("list", help="list every preset (the default)")
    p_show = sub.add_parser("show", help="print a preset's values and the file it came from")
    p_show.add_argument("name", metavar="NAME", help="preset name, or a material file")
    p_show.add_argument(
        "--as", dest="as_format", choices=SHOW_FORMATS, default=None,
        help="show it as that tool holds it (MTL, three.js MeshPhongMaterial JSON, X3D "
        "Material, Blender's Principled BSDF), with what changes",
    )  # fmt: skip
    p_imp = sub.add_parser("import", help="one preset per material of an .mtl file")
    p_imp.add_argument("file", metavar="FILE.mtl", help="Wavefront material library")
    p_imp.add_argument(
        "--into", metavar="DIR", default=None,
        help="preset directory to write to (default: the user's preset directory)",
    )  # fmt: skip
    p_imp.add_argument("--force", action="store_true", help="replace presets that exist")
    p_exp = sub.add_parser("export", help="write a preset as .mtl, three.js .json or .x3d")
    p_exp.add_argument("name", metavar="NAME", help="preset name, or a material file")
    p_exp.add_argument(
        "--out", required=True, metavar="FILE",
        help="output: .mtl (exact), .json (three.js MeshPhongMaterial), .x3d (X3D Material)",
    )  # fmt: skip
    p_exp.add_argument("--force", action="store_true", help="replace the output file")
    p_val = sub.add_parser("validate", help="check material files; exit 1 if any has a problem")
    p_val.add_argument(
        "paths", nargs="+", metavar="PATH",
        help="material file (.yaml, or an .mtl library), or directory of *.yaml files",
    )  # fmt: skip
    for p in (p_list, p_show, p_exp):
        add_materials_dir_option(p, dest="materials_dirs_after")


def run(args) -> int:
    materials_dirs = list(args.materials_dirs) + list(
        getattr(args, "materials_dirs_after", None) or []
    )
    command = getattr(args, "presets_command", None) or "list"
    if command == "show":
        if args.as_format is not None:
            return show_as(args.name, args.as_format, materials_dirs)
        return show(args.name, materials_dirs)
    if command == "import":
        return import_mtl(args.file, args.into, args.force)
    if command == "export":
        return export(args.name, args.out, args.force, materials_dirs)
    if command == "validate":
        return validate(args.paths)
    return list_(materials_dirs)


# -- list ------------------------------------------------------------------------------------
def list_(materials_dirs, out=None, err=None) -> int:

    out = out or sys.stdout
    err = err or sys.stderr
    notices: list[str] = []
    presets = list_presets(materials_dirs, notices=notices)
    _print_notices(notices, err)
    colour = use_colour(out)
    width = max((len(p.name) for p in presets), default=4)
    for p in presets:
        swatch = _swatch(p.material) + " " if colour else ""
        tag = "" if p.source == "builtin" else f" [{_source_label(p.source)}]"
        out.write(
            f"{swatch}{printable(p.name):<{width}}  {p.material.shininess:>7g}  "
            f"{printable(p.material.description)}{printable(tag)}\n"
        )
    return 0


def use_colour(stream) -> bool:
    """24-bit colour only on a terminal, without NO_COLOR (https://no-color.org), not dumb."""
    if os.environ.get("NO_COLOR") or os.environ.get("TERM") == "dumb":
        return False
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty and isatty())
    except (OSError, ValueError):
        return False


def swatch_rgb(material: Material) -> tuple[int, int, int]:
    """8-bit colour of the material facing a white light head-on, without the highlight:
    ``emission + 0.2 * ambient + diffuse`` clamped to [0, 1]."""
    rgb = (
        e + SWATCH_SCENE_AMBIENT * a + d
        for e, a, d in zip(material.emission, material.ambient, material.diffuse, strict=True)
    )
    return tuple(int(round(min(1.0, max(0.0, c)) * 255)) for c in rgb)


def _swatch(material: Material) -> str:
    r, g, b = swatch_rgb(material)
    return f"\x1b[48;2;{r};{g};{b}m    \x1b[0m"


def _source_label(source: str) -> str:
    return {"extra": "--materials-dir", "user": "user", "builtin": "built-in"}.get(source, source)


def _print_notices(notices, err) -> None:
    for n in notices:
        err.write(f"notice: {printable(n, keep=chr(10))}\n")


# -- show ------------------------------------------------------------------------------------
def show(name: str, materials_dirs, out=None, err=None) -> int:

    out = out or sys.stdout
    err = err or sys.stderr
    if name.endswith((SUFFIX, ".yml")) or os.sep in name or "/" in name:
        path = Path(name)
        material = load_material_file(path)
        origin = f"# from the file {path}"
    else:
        path, source, hidden = locate_preset(name, materials_dirs)
        material = load_material_file(path)
        origin = f"# preset '{name}' ({_source_label(source)}): {path}"
        if hidden is not None:
            _print_notices([f"preset '{name}': {path} hides {hidden}"], err)
    ka, kd, ks = material.scalars()
    out.write(printable(origin) + "\n")
    out.write(f"# scalars (largest channel of each term): ka {ka:g}, kd {kd:g}, ks {ks:g}\n")
    if use_colour(out):
        out.write(f"# swatch: {_swatch(material)}\n")
    # YAML escapes controls itself but writes a bidi override raw: shown escaped too
    out.write(printable(dump_yaml(material.to_mapping()), keep="\n"))
    return 0


def _load(name: str, materials_dirs) -> tuple[Material, str, str]:
    """``(material, preset name, where it came from)`` of a preset name or a material file."""
    if name.endswith((SUFFIX, ".yml")) or os.sep in name or "/" in name:
        path = Path(name)
        material = load_material_file(path)
        return material, preset_name(path.stem), f"the file {path}"
    path, source, _ = locate_preset(name, materials_dirs)
    return load_material_file(path), name, f"preset '{name}' ({_source_label(source)}): {path}"


def show_as(name: str, fmt: str, materials_dirs, out=None, err=None) -> int:
    """``presets show NAME --as FMT``: the text on ``out``, each approximation on ``err``."""
    out = out or sys.stdout
    err = err or sys.stderr
    material, preset, _ = _load(name, materials_dirs)
    converted = convert(material, preset, fmt)
    out.write(printable(converted.text, keep="\n"))
    for note in converted.notes:
        err.write(f"note: {printable(note)}\n")
    return 0


# -- import / export -------------------------------------------------------------------------
def import_mtl(file: str, into, force: bool, out=None, err=None) -> int:
    """``presets import FILE.mtl``: every material of the file as a preset in ``into`` (the
    user's directory by default). Nothing is written when the file has a problem, or when a
    preset file exists and ``force`` is not given."""
    out = out or sys.stdout
    err = err or sys.stderr
    directory = user_dir() if into is None else Path(into).expanduser()
    job = mtl_import(file, directory)
    existing = [str(t) for t in job.existing]
    if existing and not force:
        raise ExplorerError(
            f"{len(existing)} preset file{'s' if len(existing) != 1 else ''} already exist: "
            f"{', '.join(existing)}; nothing was written (use --force to replace them)"
        )
    found = job.found
    for m, name, path in zip(found, job.names, job.write(force), strict=True):
        renamed = "" if name == m.name else f" (newmtl {m.name})"
        out.write(f"wrote {printable(path)}{printable(renamed)}\n")
        for w in m.warnings:
            err.write(f"warning: {printable(w)}\n")
    n = len(found)
    out.write(f"{n} preset{'s' if n != 1 else ''} imported into {printable(directory)}\n")
    return 0


def export(name: str, out_path: str, force: bool, materials_dirs, out=None, err=None) -> int:
    """``presets export NAME --out FILE``: the format by the file's suffix
    (:data:`~explorer.core.formats.EXPORT_SUFFIXES`); each approximation on ``err``."""
    out = out or sys.stdout
    err = err or sys.stderr
    suffix = Path(out_path).suffix.lower()
    if suffix not in EXPORT_SUFFIXES:
        raise ExplorerError(
            f"--out {out_path!r}: the file name must end in {' or '.join(EXPORT_SUFFIXES)}"
        )
    material, preset, origin = _load(name, materials_dirs)
    folder = os.path.dirname(os.path.abspath(out_path))
    converted = convert(material, preset, EXPORT_SUFFIXES[suffix], folder)
    write_atomic(out_path, converted.text.encode("utf-8"), overwrite=force)
    out.write(f"wrote {printable(out_path)}: {printable(origin)} as {EXPORT_SUFFIXES[suffix]}\n")
    for note in converted.notes:
        err.write(f"note: {printable(note)}\n")
    return 0


# -- validate --------------------------------------------------------------------------------
def validate(paths, out=None, err=None) -> int:
    """Check every file; one line per problem on ``out``; 1 if any problem, else 0."""

    out = out or sys.stdout
    err = err or sys.stderr
    files: list[Path] = []
    problems: list[Problem] = []
    for p in paths:
        path = Path(p)
        try:  # the loader says why a file cannot be read; here: a folder on the way that
            # cannot be searched, a folder that cannot be listed, a name too long
            found = None
            if path.is_dir():
                found = sorted(f for f in path.iterdir() if f.suffix == SUFFIX and f.is_file())
        except OSError as exc:
            problems.append(Problem(f"cannot read: {exc.strerror or exc}", str(path)))
            continue
        if found is not None:
            if not found:
                problems.append(Problem(f"no *{SUFFIX} files in this directory", str(path)))
            files.extend(found)
        else:
            files.append(path)
    for path in files:
        try:
            if path.suffix.lower() == ".mtl":
                read_mtl(path)  # its warnings are not problems: 'presets import' prints them
                continue
            load_material_file(path)
        except MtlError as exc:
            problems.append(Problem(str(exc)))
        except ValidationError as exc:
            problems.extend(exc.problems)
        except ExplorerError as exc:  # pragma: no cover - the loader raises ValidationError
            problems.append(Problem(str(exc), str(path)))
        if path.suffix == SUFFIX and os.path.exists(path) and not is_valid_name(path.stem):
            problems.append(
                Problem(
                    f"the file name {path.stem!r} is not a valid preset name (lowercase letters, "
                    "digits and '_'); a preset directory ignores this file",
                    str(path),
                )
            )
    for problem in problems:
        out.write(f"{problem}\n")
    n = len(files)
    err.write(
        f"{n} file{'s' if n != 1 else ''} checked, "
        f"{len(problems) or 'no'} problem{'s' if len(problems) != 1 else ''}\n"
    )
    return 1 if problems else 0
