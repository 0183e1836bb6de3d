"""Texture maps as material keys: the .mtl statements and their options, scene and preset
files, names relative to (and inside) the file that gives them, written back (issue 40, item 2)."""

from __future__ import annotations

import pytest

from explorer.core.errors import ValidationError
from explorer.core.material import Material, parse_material
from explorer.core.mtl import MtlError, format_mtl, parse_mtl, read_mtl
from explorer.core.scene import Scene, load_scene
from explorer.core.texture import MAP_KEYS, TextureMap, parse_mtl_map
from explorer.core.validate import Checker

ALL_MAPS = """newmtl wood
Kd 0.8 0.6 0.4
map_Kd -s 2 2 1 -o 0.5 0.25 -clamp on wood grain.png
map_Ka amb.png
map_Ke glow.jpg
map_Ks -imfchan r spec.png
map_Ns -imfchan l rough.png
bump -bm 0.5 bump.png
"""


def test_every_map_statement_becomes_its_key_with_its_options(tmp_path):
    (tmp_path / "wood.mtl").write_text(ALL_MAPS)
    (m,) = read_mtl(tmp_path / "wood.mtl")
    mat = m.material
    assert m.warnings == ()  # nothing dropped: nothing warned
    assert sorted(mat.maps()) == sorted(MAP_KEYS)
    d = mat.diffuse_map
    assert d.file == str(tmp_path / "wood grain.png")  # a name with a blank, beside the .mtl
    assert d.scale == (2.0, 2.0, 1.0) and d.offset == (0.5, 0.25, 0.0) and d.clamp
    assert mat.specular_map.channel == "r" and mat.shininess_map.channel == "l"
    assert mat.bump_map.bump_multiplier == 0.5
    assert mat.emission_map.file.endswith("glow.jpg")


def test_map_bump_is_bump_and_dropped_options_and_maps_are_warned():
    (m,) = parse_mtl("newmtl a\nmap_Bump -blendu off -boost 2 -mm 0 1 b.png\ndisp d.png\n", "x")
    assert m.material.bump_map == TextureMap("b.png")
    text = "\n".join(m.warnings)
    assert "x:2: bump option -blendu is not modelled" not in text  # the keyword as written
    assert "x:2: map_Bump option -blendu is not modelled; dropped" in text
    assert "option -boost" in text and "option -mm" in text
    assert "x:3: texture map 'disp' is not used" in text


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("map_Kd", "map_Kd needs an image file name"),
        ("map_Kd -s a.png", "-s needs 1 to 3 numbers"),
        ("map_Kd -clamp maybe a.png", "-clamp takes on or off"),
        ("map_Kd -imfchan q a.png", "-imfchan takes one of r, g, b, m, l, z"),
        ("bump -bm x a.png", "-bm takes a number"),
    ],
)
def test_a_bad_map_statement_is_one_error_naming_the_line(line, message):
    with pytest.raises(MtlError, match=f"x.mtl:2: .*{message}"):
        parse_mtl(f"newmtl a\n{line}\n", "x.mtl")


@pytest.mark.parametrize("name", ["../up.png", "/etc/passwd", "sub/../../up.png"])
def test_a_map_outside_the_mtl_folder_is_refused(tmp_path, name):
    (tmp_path / "m.mtl").write_text(f"newmtl a\nKd 1 0 0\nmap_Kd {name}\n")
    with pytest.raises(MtlError, match=r"m.mtl:3: map_Kd .*outside the .mtl's folder"):
        read_mtl(tmp_path / "m.mtl")


def test_format_mtl_writes_the_maps_back_and_they_read_back_equal(tmp_path):
    (tmp_path / "wood.mtl").write_text(ALL_MAPS)
    (m,) = read_mtl(tmp_path / "wood.mtl")
    text = format_mtl([("wood", m.material)], folder=tmp_path)
    assert "map_Kd -s 2.0 2.0 1.0 -o 0.5 0.25 0.0 -clamp on wood grain.png" in text
    assert "bump -bm 0.5 bump.png" in text
    (tmp_path / "again.mtl").write_text(text)
    (back,) = read_mtl(tmp_path / "again.mtl")
    assert back.material == m.material


def test_material_mapping_round_trip_and_short_form():
    m = Material(diffuse_map="a.png", bump_map=TextureMap("b.png", bump_multiplier=2.0))
    out = m.to_mapping()
    assert out["diffuse_map"] == "a.png"  # every option the default: the name alone
    assert out["bump_map"] == {"file": "b.png", "bump_multiplier": 2.0}
    assert parse_material(out, Checker(None)) == m


def test_a_bad_map_in_a_file_names_the_key():
    checker = Checker(None)
    value = {"diffuse_map": {"file": "a.png", "scale": [1, 2]}, "bump_map": 3}
    assert parse_material(value, checker) is None
    keys = [p.key for p in checker.problems]
    assert keys == ["diffuse_map.scale", "bump_map"]


def test_a_scene_names_its_maps_from_its_folder_and_refuses_one_outside(tmp_path):
    sub = tmp_path / "scene"
    sub.mkdir()
    (sub / "s.yaml").write_text("material: {diffuse: [1, 1, 1], diffuse_map: tex/a.png}\n")
    scene = load_scene(sub / "s.yaml")
    assert scene.material.diffuse_map.file == str(sub / "tex" / "a.png")
    (sub / "bad.yaml").write_text("material: {diffuse_map: ../a.png}\n")
    with pytest.raises(ValidationError, match=r"bad.yaml.*material.diffuse_map.*outside"):
        load_scene(sub / "bad.yaml")


def test_color_control_is_a_scene_key():
    assert Scene().color_control == "single"
    scene = load_scene({"color_control": "separate"})
    assert scene.to_mapping()["color_control"] == "separate"
    assert "color_control" not in Scene().to_mapping()  # the default is not written
    with pytest.raises(ValidationError, match="must be one of single, separate"):
        load_scene({"color_control": "both"})


def test_parse_mtl_map_takes_a_name_starting_with_a_dash():
    tmap, dropped, problem = parse_mtl_map(["map_Kd", "-clamp", "off", "-x.png"], "w")
    assert tmap == TextureMap("-x.png") and dropped == [] and problem == ""


def test_presets_import_keeps_the_maps_and_export_writes_them_back(tmp_path, capsys):
    from explorer.cli import main
    from explorer.core.presets import load_material_file

    (tmp_path / "wood.mtl").write_text(ALL_MAPS)
    library = tmp_path / "library"
    assert main(["presets", "import", str(tmp_path / "wood.mtl"), "--into", str(library)]) == 0
    preset = load_material_file(library / "wood.yaml")
    assert preset.diffuse_map.file == str(tmp_path / "wood grain.png")  # its full name
    assert preset.diffuse_map.scale == (2.0, 2.0, 1.0) and preset.bump_map.bump_multiplier == 0.5
    out = tmp_path / "again.mtl"
    argv = ["presets", "export", "wood", "--out", str(out), "--materials-dir", str(library)]
    assert main(argv) == 0
    (back,) = read_mtl(out)  # the images beside it: named relative to it
    assert "map_Kd -s 2.0 2.0 1.0 -o 0.5 0.25 0.0 -clamp on wood grain.png" in out.read_text()
    assert back.material.replace(name=None) == preset.replace(name=None)


def test_a_preset_names_a_relative_map_from_its_folder(tmp_path):
    from explorer.core.presets import load_material_file

    (tmp_path / "p.yaml").write_text("diffuse: [1, 1, 1]\ndiffuse_map: img/a.png\n")
    assert load_material_file(tmp_path / "p.yaml").diffuse_map.file == str(tmp_path / "img/a.png")
    (tmp_path / "q.yaml").write_text("diffuse_map: ../a.png\n")
    with pytest.raises(ValidationError, match="outside the preset's folder"):
        load_material_file(tmp_path / "q.yaml")


def test_a_session_keeps_the_maps_and_the_colour_control(tmp_path):
    from explorer.app.session import load_session, save_session
    from explorer.app.start import first_state
    from explorer.geometry.meshes import get_mesh

    tmap = TextureMap(str(tmp_path / "a.png"), scale=(2.0, 3.0, 1.0), clamp=True)
    scene = Scene(material=Material(diffuse_map=tmap), color_control="separate")
    mesh = get_mesh("sphere", 8)
    state = first_state(scene, mesh, name="sphere")
    save_session(tmp_path / "s.yaml", state)
    back, _ = load_session(tmp_path / "s.yaml")
    assert back.scene.material.diffuse_map == tmap
    assert back.scene.color_control == "separate"
