"""A material in other tools' terms (explorer.core.formats) and the ``presets`` commands that
use them: ``import``, ``export``, ``show --as``."""

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from explorer.cli import main
from explorer.core.formats import (
    blender_settings,
    convert,
    hex_colour,
    to_threejs,
    to_x3d,
    x3d_ambient_intensity,
)
from explorer.core.material import Material
from explorer.core.mtl import read_mtl
from explorer.core.presets import find_preset, load_material_file

DATA = Path(__file__).resolve().parents[1] / "data" / "mtl"


pytestmark = pytest.mark.usefixtures("isolated_user_dir")  # tests/core/conftest.py


# -- the conversions -------------------------------------------------------------------------


def test_threejs_json_holds_colours_as_8_bit_hex_and_the_exact_floats():
    gold = find_preset("gold")
    data = json.loads(to_threejs(gold, "gold").text)
    assert data["type"] == "MeshPhongMaterial" and data["metadata"]["type"] == "Material"
    assert data["color"] == hex_colour(gold.diffuse) == (192 << 16) | (155 << 8) | 58
    assert data["specular"] == hex_colour(gold.specular)
    assert data["shininess"] == gold.shininess and data["opacity"] == 1.0
    assert data["transparent"] is False
    assert data["userData"]["phong_explorer"]["ambient"] == list(gold.ambient)
    notes = " ".join(to_threejs(gold, "gold").notes)
    assert "ambient is dropped" in notes and "(n/2 + 1)/(4π)" in notes
    assert f"{(51.2 / 2 + 1) / 4:.3g} times OpenGL's" in notes


def test_x3d_material_maps_ambient_to_one_intensity_and_shininess_to_a_fraction():
    m = Material(ambient=(0.1, 0.2, 0.3), diffuse=(0.2, 0.4, 0.6), shininess=64.0, opacity=0.25)
    out = to_x3d(m, "blue")
    root = ET.fromstring(out.text)
    (mat,) = root.iter("Material")
    assert float(mat.get("ambientIntensity")) == pytest.approx(0.5)
    assert float(mat.get("shininess")) == 0.5
    assert float(mat.get("transparency")) == 0.75
    assert [float(v) for v in mat.get("diffuseColor").split()] == [0.2, 0.4, 0.6]
    assert not any("ambientIntensity" in n and "off by" in n for n in out.notes)
    # an ambient of another hue: the nearest multiple, and the error is said
    odd = to_x3d(Material(ambient=(0.3, 0, 0), diffuse=(0, 0, 0.5)), "odd")
    assert x3d_ambient_intensity(Material(ambient=(0.3, 0, 0), diffuse=(0, 0, 0.5))) == 0.0
    assert any("off by up to 0.3" in n for n in odd.notes)
    capped = to_x3d(Material(shininess=500.0), "x")
    assert float(next(ET.fromstring(capped.text).iter("Material")).get("shininess")) == 1.0
    assert any("capped at 128" in n for n in capped.notes)


def test_blender_settings_follow_its_obj_importer():
    m = Material(specular=(0.3, 0.6, 0.9), shininess=250.0, opacity=0.5)
    s = blender_settings(m)
    assert s["Specular"] == pytest.approx(0.6)
    assert s["Roughness"] == pytest.approx(1 - math.sqrt(0.25))
    assert s["Alpha"] == 0.5 and s["Metallic"] == 0.0
    # Blender's exporter writes Ns = (1 - roughness)^2 * 1000 back: the same Ns
    assert (1 - s["Roughness"]) ** 2 * 1000 == pytest.approx(250.0)
    notes = " ".join(convert(m, "m", "blender").notes)
    assert "Ka 1 1 1" in notes and "hue is lost" in notes


def test_unknown_format_is_refused():
    with pytest.raises(ValueError, match="unknown material format 'pov'"):
        convert(Material(), "m", "pov")


# -- presets import --------------------------------------------------------------------------


def test_import_writes_one_preset_per_newmtl_with_exact_values(tmp_path, capsys):
    into = tmp_path / "into"
    assert main(["presets", "import", str(DATA / "several.mtl"), "--into", str(into)]) == 0
    out = capsys.readouterr().out
    assert "red_paint.yaml (newmtl Red Paint)" in out and "red_paint_2.yaml" in out
    assert "3 presets imported" in out
    back = {p.stem: load_material_file(p) for p in into.glob("*.yaml")}
    src = {m.name: m.material for m in read_mtl(DATA / "several.mtl")}
    assert back["red_paint"] == src["Red Paint"]
    assert back["red_paint_2"] == src["red_paint"]
    assert back["blue"] == src["blue"]


def test_import_defaults_to_the_user_dir_and_prints_warnings(isolated_user_dir, capsys):
    assert main(["presets", "import", str(DATA / "blender.mtl")]) == 0
    captured = capsys.readouterr()
    assert (isolated_user_dir / "material.yaml").exists()
    assert "warning: " in captured.err and "'Ka 1 1 1'" in captured.err
    assert find_preset("material").shininess == 250.0


def test_import_never_replaces_without_force(tmp_path, capsys):
    into = tmp_path / "into"
    argv = ["presets", "import", str(DATA / "several.mtl"), "--into", str(into)]
    assert main(argv) == 0
    (into / "blue.yaml").write_text("shininess: 1.0\n")
    (into / "red_paint.yaml").unlink()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "already exist" in err and "nothing was written" in err
    assert not (into / "red_paint.yaml").exists()  # nothing half done
    assert main([*argv, "--force"]) == 0
    assert load_material_file(into / "blue.yaml").shininess == 200.0


@pytest.mark.parametrize("name", ["bad_number.mtl", "binary.mtl", "spectral.mtl", "no_newmtl.mtl"])
def test_import_of_a_bad_file_is_one_line_and_writes_nothing(tmp_path, capsys, name):
    into = tmp_path / "into"
    assert main(["presets", "import", str(DATA / name), "--into", str(into)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and name in err
    assert "Traceback" not in err and not into.exists()


def test_validate_checks_mtl_files(capsys):
    assert main(["presets", "validate", str(DATA / "crlf_tabs.mtl")]) == 0
    assert main(["presets", "validate", str(DATA / "bad_count.mtl")]) == 1
    assert "bad_count.mtl:2: Kd takes 1 number" in capsys.readouterr().out


# -- presets export / show --as --------------------------------------------------------------


def test_export_mtl_round_trips_through_import(tmp_path):
    out = tmp_path / "jade.mtl"
    assert main(["presets", "export", "jade", "--out", str(out)]) == 0
    into = tmp_path / "back"
    assert main(["presets", "import", str(out), "--into", str(into)]) == 0
    assert load_material_file(into / "jade.yaml") == find_preset("jade")


@pytest.mark.parametrize("suffix", [".json", ".x3d"])
def test_export_by_suffix_states_its_approximations(tmp_path, capsys, suffix):
    out = tmp_path / f"gold{suffix}"
    assert main(["presets", "export", "gold", "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "note: " in captured.err
    text = out.read_text()
    if suffix == ".json":
        assert json.loads(text)["type"] == "MeshPhongMaterial"
    else:
        assert next(ET.fromstring(text).iter("Material")).get("DEF") == "gold"
    assert main(["presets", "export", "gold", "--out", str(out)]) == 2  # never over a file
    assert "already exists" in capsys.readouterr().err
    assert main(["presets", "export", "gold", "--out", str(tmp_path / "g.obj")]) == 2
    assert "must end in .mtl or .json or .x3d" in capsys.readouterr().err


@pytest.mark.parametrize("fmt, expect", [
    ("mtl", "newmtl ruby"), ("threejs", '"MeshPhongMaterial"'), ("x3d", "<Material DEF=\"ruby\""),
    ("blender", "Roughness: "),
])  # fmt: skip
def test_show_as_prints_the_material_and_what_changes(capsys, fmt, expect):
    assert main(["presets", "show", "ruby", "--as", fmt]) == 0
    captured = capsys.readouterr()
    assert expect in captured.out
    assert captured.err == "" if fmt == "mtl" else "note: " in captured.err


def _import_mtl(tmp_path, n: int) -> Path:
    path = tmp_path / "many.mtl"
    path.write_text("".join(f"newmtl m{i}\nKd 0.5 0.5 0.5\n" for i in range(n)))
    return path


def test_import_is_all_or_nothing_when_a_target_is_a_directory(tmp_path, capsys):
    """With --force and a directory at the 2nd target, the 1st was replaced, then rc 2."""
    into = tmp_path / "p"
    into.mkdir()
    (into / "m0.yaml").write_text("diffuse: [0.1, 0.1, 0.1]\n")
    (into / "m1.yaml").mkdir()
    argv = ["presets", "import", str(_import_mtl(tmp_path, 3)), "--into", str(into), "--force"]
    assert main(argv) == 2
    assert "m1.yaml: is a directory" in capsys.readouterr().err
    assert (into / "m0.yaml").read_text() == "diffuse: [0.1, 0.1, 0.1]\n"
    assert sorted(p.name for p in into.iterdir()) == ["m0.yaml", "m1.yaml"]


def test_import_interrupted_while_placing_leaves_nothing_and_can_be_run_again(
    tmp_path, monkeypatch, capsys
):
    """SIGTERM during a 20,000-material import left 9,621 presets and a re-run refused. Here
    the interrupt (what SIGTERM raises in the CLI) comes at the 5th file put in place."""
    from explorer.cli import Terminated
    from explorer.core import atomic

    into = tmp_path / "p"
    mtl = _import_mtl(tmp_path, 10)
    real = atomic._link_no_clobber
    calls = []

    def interrupted(tmp, target):
        calls.append(target)
        if len(calls) == 5:
            raise Terminated()
        return real(tmp, target)

    monkeypatch.setattr(atomic, "_link_no_clobber", interrupted)
    assert main(["presets", "import", str(mtl), "--into", str(into)]) == 143
    assert list(into.iterdir()) == []  # no preset, no temporary file
    monkeypatch.setattr(atomic, "_link_no_clobber", real)
    assert main(["presets", "import", str(mtl), "--into", str(into)]) == 0
    assert len(list(into.iterdir())) == 10
    capsys.readouterr()
