"""The presets page of the site, generated from ``materials/`` at each build.

For every built-in preset: a swatch (the preset on a small sphere under the preset sheet's
light, drawn by :mod:`explorer.render`), its YAML file as it is, and the two forms other tools
read: the Wavefront ``.mtl`` (exact) and three.js's ``MeshPhongMaterial`` JSON, with the notes
of what each approximates (:func:`explorer.core.formats.convert`, as ``presets show NAME --as``
prints them). The page and its pictures go to ``docs/generated/`` (not kept in git); a file is
rewritten only when its content changes, so an unchanged library rebuilds nothing.
"""

from __future__ import annotations

from pathlib import Path

#: the folder of the generated page and swatches, inside the documentation's sources
GENERATED = "generated"
#: the swatch's size in pixels and the sphere's resolution (small: 42 pictures in a second)
SWATCH_SIZE = (96, 96)
SWATCH_RESOLUTION = 48


def _write_if_changed(path: Path, data: bytes) -> None:
    if not (path.exists() and path.read_bytes() == data):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)


def _fenced(language: str, text: str) -> str:
    return f"```{language}\n{text.rstrip()}\n```\n"


def builtin_presets() -> list:
    """``[(name, path, material), ...]`` of the built-in library's files, by name (the user's
    own presets never enter the page, nor hide a built-in one)."""
    from explorer.core.presets import builtin_dir, load_material_file

    return [(p.stem, p, load_material_file(p)) for p in sorted(builtin_dir().glob("*.yaml"))]


def page(presets, swatch_dir: str) -> str:
    """The Markdown of the presets page: ``presets`` as :func:`builtin_presets` gives them;
    the swatches are ``<swatch_dir>/<name>.png``."""
    from explorer.core.formats import convert

    out = [
        "# The preset library\n",
        "Every built-in preset (`materials/`, installed as `explorer.materials`): its swatch on a",
        "sphere under the preset sheet's light, its YAML file as it is, and the forms other tools",
        "read: Wavefront `.mtl` (exact) and three.js's `MeshPhongMaterial` (with what changes).",
        "The same text comes from `phong-explorer presets show NAME [--as mtl|threejs]`; writing",
        "your own: [presets.md](../presets.md); every mapping: [formats.md](../formats.md).",
        "This page is generated at each build from the files, so it cannot fall behind them.\n",
    ]
    for name, path, material in presets:
        out.append(f"## {name}\n")
        out.append(f"![{name} on a sphere]({swatch_dir}/{name}.png)\n")
        description = material.description
        if description:
            out.append(f"{description}\n")
        out.append(f"`materials/{path.name}`:\n")
        out.append(_fenced("yaml", path.read_text(encoding="utf-8")))
        for fmt, language, title in (("mtl", "text", ".mtl"), ("threejs", "json", "three.js")):
            converted = convert(material, name, fmt)
            out.append(f"{title}:\n")
            out.append(_fenced(language, converted.text))
            if converted.notes:
                out.append("".join(f"- {note}\n" for note in converted.notes))
    return "\n".join(out)


def generate(srcdir: Path) -> list:
    """Write ``<srcdir>/generated/library.md`` and its swatches; the presets drawn."""
    import explorer
    from explorer.geometry.meshes import get_mesh
    from explorer.render.images import encode_png
    from explorer.render.offscreen import SHEET_LIGHT_DIRECTION, OffscreenRenderer

    folder = srcdir / GENERATED
    presets = builtin_presets()
    scene = explorer.load_scene(
        {"lights": [{"type": "directional", "to_light": list(SHEET_LIGHT_DIRECTION)}]}
    )
    sphere = get_mesh("sphere", SWATCH_RESOLUTION)
    with OffscreenRenderer(SWATCH_SIZE) as renderer:
        for name, _, material in presets:
            s = scene.replace(material=material, model=material.model or scene.model)
            picture = encode_png(renderer.render(s, sphere))
            _write_if_changed(folder / "swatches" / f"{name}.png", picture)
    _write_if_changed(folder / "library.md", page(presets, "swatches").encode("utf-8"))
    return presets


def _builder_inited(app) -> None:
    generate(Path(app.srcdir))


def setup(app):
    app.connect("builder-inited", _builder_inited)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
