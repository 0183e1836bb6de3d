"""The .mtl reader and writer (explorer.core.mtl) on hand-written fixtures (tests/data/mtl)."""

from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from explorer.core.material import Material
from explorer.core.mtl import MtlError, format_mtl, parse_mtl, preset_names, read_mtl
from explorer.core.presets import find_preset, list_presets

DATA = Path(__file__).resolve().parents[1] / "data" / "mtl"


def one(name: str):
    (m,) = read_mtl(DATA / name)
    return m


def test_crlf_and_tabs_read_exactly():
    m = one("crlf_tabs.mtl")
    assert m.name == "shiny_red" and m.line == 2
    assert m.material == Material(
        ambient=(0.1, 0.0, 0.0),
        diffuse=(0.8, 0.1, 0.1),
        specular=(1.0, 1.0, 1.0),
        shininess=96.0,
    )
    assert m.warnings == ()


def test_a_single_value_is_grey_and_missing_terms_keep_opengls_defaults():
    m = one("single_values.mtl").material
    assert m.ambient == (0.05,) * 3 and m.diffuse == (0.5,) * 3 and m.specular == (0.25,) * 3
    assert m.emission == (0.0,) * 3 and m.shininess == 10.0
    (d,) = parse_mtl("newmtl bare\n")
    assert d.material == Material()  # ambient 0.2, diffuse 0.8, specular 0, shininess 0


def test_tr_is_one_minus_opacity_and_an_inverted_tr_is_warned():
    glass, inverted = read_mtl(DATA / "tr.mtl")
    assert glass.material.opacity == 0.75 and glass.warnings == ()
    assert inverted.material.opacity == 0.0
    assert any("Tr 1 makes the material invisible" in w for w in inverted.warnings)
    (both,) = parse_mtl("newmtl a\nd 0.5\nTr 0.1\n", "x.mtl")
    assert both.material.opacity == 0.5
    assert any("x.mtl:3: Tr 0.1 disagrees with d 0.5" in w for w in both.warnings)


def test_several_materials_in_file_order_with_unique_preset_names():
    ms = read_mtl(DATA / "several.mtl")
    assert [m.name for m in ms] == ["Red Paint", "red_paint", "blue"]
    assert [m.line for m in ms] == [2, 5, 8]
    assert ms[2].material.specular == (0.5, 0.5, 0.5) and ms[2].material.shininess == 200.0
    assert preset_names([m.name for m in ms]) == ["red_paint", "red_paint_2", "blue"]
    assert preset_names(["Ünïcode!!", "", "x" * 80]) == ["n_code", "material", "x" * 64]


def test_blender_files_warn_of_ka_1_texture_maps_and_ni():
    m = one("blender.mtl")
    assert m.material.ambient == (1.0, 1.0, 1.0)  # exact: the value is kept, and warned of
    text = "\n".join(m.warnings)
    assert "blender.mtl:6: 'Ka 1 1 1'" in text and "metallic" in text
    assert "blender.mtl:10: Ni" in text
    assert "map_Kd" not in text  # read now: the material's diffuse_map, beside the .mtl
    assert m.material.diffuse_map.file == str(DATA / "wood.png")
    assert "Ns 250 is above OpenGL's largest GL_SHININESS (128)" in text


def test_ns_0_with_a_highlight_and_unmodelled_illum_are_warned():
    text = "\n".join(one("max2mtl.mtl").warnings)
    assert "max2mtl.mtl:5: 'Ns 0' with a specular colour" in text and "0^0 = 1" in text
    assert "max2mtl.mtl:6: illum 3 (reflection on, ray trace on) is not modelled" in text
    (quiet,) = parse_mtl("newmtl a\nillum 1\n")  # no highlight asked and none given
    assert quiet.warnings == ()


@pytest.mark.parametrize(
    "name, message",
    [
        ("bad_number.mtl", "bad_number.mtl:3: Ns: 'shiny' is not a number"),
        ("bad_count.mtl", "bad_count.mtl:2: Kd takes 1 number (grey) or 3 (r g b), got 2"),
        ("spectral.mtl", "spectral.mtl:2: Kd spectral: spectral colours are not read"),
        ("xyz.mtl", "xyz.mtl:2: Ks xyz: xyz colours are not read"),
        ("no_newmtl.mtl", "no_newmtl.mtl: no 'newmtl' in the file"),
        ("before_newmtl.mtl", "before_newmtl.mtl:1: 'Kd' before any newmtl"),
        ("binary.mtl", "binary.mtl:3: binary data (a NUL byte)"),
        ("out_of_range.mtl", "out_of_range.mtl:2: Kd must be in [0, 1], got 1.5"),
        ("twice.mtl", "twice.mtl:3: material 'a' is defined twice (first on line 1)"),
    ],
)
def test_bad_files_give_one_line_naming_the_file_and_line(name, message):
    with pytest.raises(MtlError) as info:
        read_mtl(DATA / name)
    text = str(info.value)
    assert message in text and "\n" not in text
    assert isinstance(info.value, ValueError)


def test_more_bad_input():
    with pytest.raises(MtlError, match=r"x:2: binary data \(control character '\\x07'\)"):
        parse_mtl(b"newmtl a\nKd 1 \x07 0\n", "x")
    with pytest.raises(MtlError, match="x:2: Ns: 'nan' is not a finite number"):
        parse_mtl("newmtl a\nNs nan\n", "x")
    with pytest.raises(MtlError, match=r"x:2: Ns \(the specular exponent\) must be in \[0, 1000\]"):
        parse_mtl("newmtl a\nNs 1200\n", "x")
    with pytest.raises(MtlError, match="x:2: illum must be a whole number from 0 to 10"):
        parse_mtl("newmtl a\nillum 2.5\n", "x")
    with pytest.raises(MtlError, match="newmtl needs a material name"):
        parse_mtl("newmtl\n", "x")
    with pytest.raises(
        MtlError, match="does-not-exist.mtl: cannot read material library: no such file"
    ):
        read_mtl(DATA / "does-not-exist.mtl")


def test_latin1_names_comments_and_continued_lines():
    (m,) = parse_mtl(b"newmtl caf\xe9 # comment\nKd 0.1 \\\n 0.2 0.3\n")
    assert m.name == "café" and m.material.diffuse == (0.1, 0.2, 0.3)


_unit = st.floats(0.0, 1.0, allow_nan=False)
_rgb = st.tuples(_unit, _unit, _unit)


@given(
    ambient=_rgb,
    diffuse=_rgb,
    specular=_rgb,
    emission=_rgb,
    shininess=st.floats(0.0, 1000.0),
    opacity=_unit,
)
def test_mtl_out_and_back_in_keeps_every_value(
    ambient, diffuse, specular, emission, shininess, opacity
):
    m = Material(ambient, diffuse, specular, emission, shininess, opacity)
    (back,) = parse_mtl(format_mtl([("m", m)]))
    assert back.material == m


def test_every_builtin_preset_round_trips_through_mtl():
    items = [(p.name, p.material) for p in list_presets()]
    back = parse_mtl(format_mtl(items, header="all of them"))
    assert [b.name for b in back] == [name for name, _ in items]
    for b, (_, m) in zip(back, items, strict=True):
        # model / fresnel / energy_conserving have no MTL statement: compare the rest
        assert b.material == m.replace(model=None, fresnel=None, energy_conserving=False)


def test_format_mtl_says_what_mtl_cannot_hold():
    m = find_preset("gold").replace(model="phong", fresnel=0.5)
    text = format_mtl([("gold", m)])
    assert "# not in MTL: model phong" in text and "# not in MTL: fresnel 0.5" in text
    with pytest.raises(ValueError, match="needs no blanks"):
        format_mtl([("two words", m)])
