"""The preset library (explorer.core.presets) and ``phong-explorer presets``
(explorer.cli.presets)."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import tempfile
import warnings
from pathlib import Path

import pytest
import yaml
from helpers.scenes import materials
from hypothesis import given
from hypothesis import strategies as st

from explorer.cli import main
from explorer.cli.presets import swatch_rgb, use_colour
from explorer.core import presets
from explorer.core.errors import ExplorerError, ValidationError
from explorer.core.material import MATERIAL_KEYS, Material
from explorer.core.presets import (
    PresetNotice,
    builtin_dir,
    find_preset,
    list_presets,
    load_material_file,
    save_preset,
    user_dir,
)
from explorer.core.yamlio import MAX_BYTES

SHARED_TABLE = Path("/work/shared/reference/classic-materials.yaml")

# The reference table (docs: /work/shared/reference/classic-materials.yaml), copied here so the
# test does not depend on files outside the repository. `alpha` is kept as the preset's opacity.
REFERENCE = """
emerald:         {ambient: [0.0215, 0.1745, 0.0215],      diffuse: [0.07568, 0.61424, 0.07568],      specular: [0.633, 0.727811, 0.633],             shininess: 76.8,    alpha: 0.55}
jade:            {ambient: [0.135, 0.2225, 0.1575],       diffuse: [0.54, 0.89, 0.63],               specular: [0.316228, 0.316228, 0.316228],       shininess: 12.8,    alpha: 0.95}
obsidian:        {ambient: [0.05375, 0.05, 0.06625],      diffuse: [0.18275, 0.17, 0.22525],         specular: [0.332741, 0.328634, 0.346435],       shininess: 38.4,    alpha: 0.82}
pearl:           {ambient: [0.25, 0.20725, 0.20725],      diffuse: [1.0, 0.829, 0.829],              specular: [0.296648, 0.296648, 0.296648],       shininess: 11.264,  alpha: 0.922}
ruby:            {ambient: [0.1745, 0.01175, 0.01175],    diffuse: [0.61424, 0.04136, 0.04136],      specular: [0.727811, 0.626959, 0.626959],       shininess: 76.8,    alpha: 0.55}
turquoise:       {ambient: [0.1, 0.18725, 0.1745],        diffuse: [0.396, 0.74151, 0.69102],        specular: [0.297254, 0.30829, 0.306678],        shininess: 12.8,    alpha: 0.8}
brass:           {ambient: [0.329412, 0.223529, 0.027451], diffuse: [0.780392, 0.568627, 0.113725],  specular: [0.992157, 0.941176, 0.807843],       shininess: 27.8974}
bronze:          {ambient: [0.2125, 0.1275, 0.054],       diffuse: [0.714, 0.4284, 0.18144],         specular: [0.393548, 0.271906, 0.166721],       shininess: 25.6}
chrome:          {ambient: [0.25, 0.25, 0.25],            diffuse: [0.4, 0.4, 0.4],                  specular: [0.774597, 0.774597, 0.774597],       shininess: 76.8}
copper:          {ambient: [0.19125, 0.0735, 0.0225],     diffuse: [0.7038, 0.27048, 0.0828],        specular: [0.256777, 0.137622, 0.086014],       shininess: 12.8}
gold:            {ambient: [0.24725, 0.1995, 0.0745],     diffuse: [0.75164, 0.60648, 0.22648],      specular: [0.628281, 0.555802, 0.366065],       shininess: 51.2}
silver:          {ambient: [0.19225, 0.19225, 0.19225],   diffuse: [0.50754, 0.50754, 0.50754],      specular: [0.508273, 0.508273, 0.508273],       shininess: 51.2}
black_plastic:   {ambient: [0.0, 0.0, 0.0],               diffuse: [0.01, 0.01, 0.01],               specular: [0.5, 0.5, 0.5],                      shininess: 32.0}
cyan_plastic:    {ambient: [0.0, 0.1, 0.06],              diffuse: [0.0, 0.50980392, 0.50980392],    specular: [0.50196078, 0.50196078, 0.50196078], shininess: 32.0}
green_plastic:   {ambient: [0.0, 0.0, 0.0],               diffuse: [0.1, 0.35, 0.1],                 specular: [0.45, 0.55, 0.45],                   shininess: 32.0}
red_plastic:     {ambient: [0.0, 0.0, 0.0],               diffuse: [0.5, 0.0, 0.0],                  specular: [0.7, 0.6, 0.6],                      shininess: 32.0}
white_plastic:   {ambient: [0.0, 0.0, 0.0],               diffuse: [0.55, 0.55, 0.55],               specular: [0.7, 0.7, 0.7],                      shininess: 32.0}
yellow_plastic:  {ambient: [0.0, 0.0, 0.0],               diffuse: [0.5, 0.5, 0.0],                  specular: [0.6, 0.6, 0.5],                      shininess: 32.0}
black_rubber:    {ambient: [0.02, 0.02, 0.02],            diffuse: [0.01, 0.01, 0.01],               specular: [0.4, 0.4, 0.4],                      shininess: 10.0}
cyan_rubber:     {ambient: [0.0, 0.05, 0.05],             diffuse: [0.4, 0.5, 0.5],                  specular: [0.04, 0.7, 0.7],                     shininess: 10.0}
green_rubber:    {ambient: [0.0, 0.05, 0.0],              diffuse: [0.4, 0.5, 0.4],                  specular: [0.04, 0.7, 0.04],                    shininess: 10.0}
red_rubber:      {ambient: [0.05, 0.0, 0.0],              diffuse: [0.5, 0.4, 0.4],                  specular: [0.7, 0.04, 0.04],                    shininess: 10.0}
white_rubber:    {ambient: [0.05, 0.05, 0.05],            diffuse: [0.5, 0.5, 0.5],                  specular: [0.7, 0.7, 0.7],                      shininess: 10.0}
yellow_rubber:   {ambient: [0.05, 0.05, 0.0],             diffuse: [0.5, 0.5, 0.4],                  specular: [0.7, 0.7, 0.04],                     shininess: 10.0}
polished_bronze: {ambient: [0.25, 0.148, 0.06475],        diffuse: [0.4, 0.2368, 0.1036],            specular: [0.774597, 0.458561, 0.200621],       shininess: 76.8}
polished_copper: {ambient: [0.2295, 0.08825, 0.0275],     diffuse: [0.5508, 0.2118, 0.066],          specular: [0.580594, 0.223257, 0.0695701],      shininess: 51.2}
polished_gold:   {ambient: [0.24725, 0.2245, 0.0645],     diffuse: [0.34615, 0.3143, 0.0903],        specular: [0.797357, 0.723991, 0.208006],       shininess: 83.2}
polished_silver: {ambient: [0.23125, 0.23125, 0.23125],   diffuse: [0.2775, 0.2775, 0.2775],         specular: [0.773911, 0.773911, 0.773911],       shininess: 89.6}
pewter:          {ambient: [0.105882, 0.058824, 0.113725], diffuse: [0.427451, 0.470588, 0.541176],  specular: [0.333333, 0.333333, 0.521569],       shininess: 9.84615}
opengl_default:  {ambient: [0.2, 0.2, 0.2],               diffuse: [0.8, 0.8, 0.8],                  specular: [0.0, 0.0, 0.0],                      shininess: 0.0}
"""  # noqa: E501
TABLE = yaml.safe_load(REFERENCE)


#: every test gets its own (empty, not yet existing) user preset directory (tests/core/conftest.py)
pytestmark = pytest.mark.usefixtures("isolated_user_dir")


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


# -- the built-in library --------------------------------------------------------------------
def test_embedded_table_matches_the_shared_reference():
    if not SHARED_TABLE.exists():
        pytest.skip("shared reference table not on this machine")
    assert yaml.safe_load(SHARED_TABLE.read_text()) == TABLE


def test_reference_table_is_complete():
    assert len(TABLE) == 30


@pytest.mark.parametrize("name", sorted(TABLE))
def test_classic_preset_matches_the_reference_exactly(name):
    ref = TABLE[name]
    m = find_preset(name)
    assert m.name == name
    for key in ("ambient", "diffuse", "specular"):
        assert getattr(m, key) == tuple(ref[key]), key
    assert m.shininess == ref["shininess"]
    assert m.opacity == ref.get("alpha", 1.0)  # the table's alpha is the preset's opacity
    assert set(ref) <= {"ambient", "diffuse", "specular", "shininess", "alpha"}
    assert m.emission == (0.0, 0.0, 0.0) and m.model is None


def test_opengl_default_preset_is_the_material_default():
    assert find_preset("opengl_default") == Material()


def test_every_builtin_file_loads_and_has_a_one_line_description():
    files = sorted(builtin_dir().glob("*.yaml"))
    assert len(files) >= 38
    for path in files:
        assert presets.is_valid_name(path.stem), path
        m = load_material_file(path)
        assert m.name == path.stem
        assert m.description.strip() and "\n" not in m.description, path


def own_presets() -> dict[str, Material]:
    return {p.name: p.material for p in list_presets() if p.name not in TABLE}


def test_the_projects_own_presets_cover_what_people_look_for():
    own = own_presets()
    assert len(own) >= 8
    kinds = {
        "pure matte": [n for n, m in own.items() if max(m.specular) == 0 and max(m.diffuse) > 0.5],
        "emissive": [n for n, m in own.items() if max(m.emission) > 0.5],
        "translucent": [n for n, m in own.items() if m.opacity < 1],
        "mirror-like": [n for n, m in own.items() if m.shininess >= 300 and max(m.specular) > 0.8],
        "broad satin sheen": [
            n for n, m in own.items() if m.shininess < 10 and 0.2 <= max(m.specular) < 0.6
        ],
        "glossy, white highlight on a coloured body": [
            n
            for n, m in own.items()
            if 50 <= m.shininess <= 200
            and len(set(m.specular)) == 1
            and max(m.diffuse) - min(m.diffuse) > 0.3
        ],
    }
    for kind, names in kinds.items():
        assert names, kind
    for name in ("chalk", "glossy_plastic", "ceramic", "lacquered_wood", "warm_lamp"):
        assert name in own


def test_the_scalar_form_presets_resolve_to_color_products():
    text = (builtin_dir() / "satin.yaml").read_text()
    raw = yaml.safe_load(text)
    m = find_preset("satin")
    assert m.diffuse == tuple(raw["kd"] * c for c in raw["color"])
    assert m.specular == tuple(raw["ks"] * c for c in raw["specular_color"])


# -- user and extra directories --------------------------------------------------------------
GOLDISH = "description: my gold\ndiffuse: [0.9, 0.7, 0.1]\nshininess: 12\n"


def test_user_dir_env_override_and_default(isolated_user_dir, monkeypatch):
    assert user_dir() == isolated_user_dir
    monkeypatch.delenv(presets.ENV_VAR)
    d = user_dir()
    assert d.name == "materials" and "phong-explorer" in str(d)


def test_user_preset_is_listed_and_found(isolated_user_dir):
    write(isolated_user_dir / "my_clay.yaml", "kd: 0.7\ncolor: [0.8, 0.5, 0.3]\n")
    infos = {p.name: p for p in list_presets()}
    assert infos["my_clay"].source == "user" and infos["my_clay"].hides is None
    assert infos["gold"].source == "builtin"
    assert find_preset("my_clay").diffuse == tuple(0.7 * c for c in (0.8, 0.5, 0.3))


def test_user_preset_shadows_builtin_with_a_notice(isolated_user_dir):
    mine = write(isolated_user_dir / "gold.yaml", GOLDISH)
    notices: list = []
    infos = {p.name: p for p in list_presets(notices=notices)}
    assert infos["gold"].path == mine and infos["gold"].source == "user"
    assert infos["gold"].hides == builtin_dir() / "gold.yaml"
    assert infos["gold"].material.diffuse == (0.9, 0.7, 0.1)
    assert len(notices) == 1 and "gold" in notices[0] and str(mine) in notices[0]
    notices = []
    assert find_preset("gold", notices=notices).description == "my gold"
    assert len(notices) == 1


def test_shadow_notice_is_a_warning_issued_once(isolated_user_dir):
    write(isolated_user_dir / "gold.yaml", GOLDISH)
    with pytest.warns(PresetNotice, match="gold"):
        find_preset("gold")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for _ in range(3):  # no repeated notices (the GUI may look presets up often)
            find_preset("gold")
            list_presets()


def test_precedence_extra_then_user_then_builtin(tmp_path, isolated_user_dir):
    write(isolated_user_dir / "gold.yaml", "description: user\n")
    a = write(tmp_path / "a" / "gold.yaml", "description: extra a\n")
    write(tmp_path / "b" / "gold.yaml", "description: extra b\n")
    write(tmp_path / "b" / "only_b.yaml", "description: b\n")
    dirs = [tmp_path / "a", str(tmp_path / "b")]
    assert find_preset("gold", dirs, notices=[]).description == "extra a"
    assert find_preset("gold", dirs[1:], notices=[]).description == "extra b"
    assert find_preset("gold", notices=[]).description == "user"
    infos = {p.name: p for p in list_presets(dirs, notices=[])}
    assert infos["gold"].path == a and infos["gold"].source == "extra"
    assert infos["gold"].hides == tmp_path / "b" / "gold.yaml"
    assert infos["only_b"].source == "extra"


def test_missing_materials_dir_is_an_error(tmp_path):
    with pytest.raises(ExplorerError, match="does not exist"):
        list_presets([tmp_path / "nope"])
    write(tmp_path / "file.yaml", "a: 1\n")
    with pytest.raises(ExplorerError, match="not a directory"):
        find_preset("gold", [tmp_path / "file.yaml"])


def test_broken_user_preset_is_skipped_in_the_list_but_raised_by_find(isolated_user_dir):
    write(isolated_user_dir / "gold.yaml", "diffuse: [2, 0, 0]\n")
    notices: list = []
    infos = {p.name: p for p in list_presets(notices=notices)}
    assert "gold" not in infos and "silver" in infos
    assert any("gold" in n and "[0, 1]" in n for n in notices)
    with pytest.raises(ValidationError, match=r"gold.yaml:1: diffuse\[0\]: must be in \[0, 1\]"):
        find_preset("gold")  # never a silent fallback to the built-in


def test_files_that_are_not_preset_names_are_ignored_with_a_notice(isolated_user_dir):
    write(isolated_user_dir / "My Gold.yaml", GOLDISH)
    write(isolated_user_dir / "notes.txt", "not a preset")
    notices: list = []
    names = {p.name for p in list_presets(notices=notices)}
    assert "My Gold" not in names and "notes" not in names
    assert len(notices) == 1 and "My Gold" in notices[0]


class Blocked(Exception):
    """Raised by :func:`within` (not an OSError: the code under test must not swallow it)."""


@contextlib.contextmanager
def within(seconds: float):
    """Fail (instead of hanging the suite) when the body blocks for more than ``seconds``."""

    def blocked(signum, frame):
        raise Blocked(f"blocked for more than {seconds} s")

    previous = signal.signal(signal.SIGALRM, blocked)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_a_fifo_named_like_a_preset_is_skipped_not_opened(tmp_path, isolated_user_dir, capsys):
    """A FIFO waits for a writer forever when opened: scanning only stats, skips it with a
    notice; the presets next to it are still listed."""
    write(isolated_user_dir / "my_gold.yaml", GOLDISH)
    os.mkfifo(isolated_user_dir / "pipe.yaml")
    extra = tmp_path / "extra"
    extra.mkdir()
    os.mkfifo(extra / "other.yaml")
    notices: list = []
    with within(10):
        names = {p.name for p in list_presets([extra], notices=notices)}
        assert main(["presets", "--materials-dir", str(extra)]) == 0
    assert "my_gold" in names and "pipe" not in names and "other" not in names
    assert sum("FIFO" in n and "ignored" in n for n in notices) == 2
    captured = capsys.readouterr()
    assert "my_gold" in captured.out and "pipe.yaml: ignored, it is a FIFO" in captured.err


@pytest.mark.parametrize("special", ["fifo", "/dev/null"])
def test_a_special_file_named_directly_is_refused_without_blocking(tmp_path, special):
    path = tmp_path / "pipe.yaml"
    if special == "fifo":
        os.mkfifo(path)
    else:
        path = Path(special)
    kind = "FIFO" if special == "fifo" else "character device"
    with within(10), pytest.raises(ValidationError, match=f"it is a {kind}.*, not a file"):
        load_material_file(path)


def test_unknown_preset_suggests_and_says_where_it_looked(tmp_path):
    with pytest.raises(ExplorerError) as info:
        find_preset("emerlad", [tmp_path])
    msg = str(info.value)
    assert "did you mean 'emerald'?" in msg
    assert str(tmp_path) in msg and str(builtin_dir()) in msg


@pytest.mark.parametrize(("name", "hint"), [("Gold", "'gold'"), ("gold.yaml", "file"), ("", "")])
def test_invalid_lookup_names(name, hint):
    with pytest.raises(ExplorerError, match="not a valid preset name") as info:
        find_preset(name)
    assert hint in str(info.value)


# -- saving ----------------------------------------------------------------------------------


@given(materials)
def test_save_then_load_gives_identical_colours(m):
    with tempfile.TemporaryDirectory() as d:
        path = save_preset(m, "round_trip", d)
        assert path == Path(d) / "round_trip.yaml"
        back = load_material_file(path)
    assert back == m  # every colour, shininess, opacity, model: exactly
    assert back.description == m.description and back.name == "round_trip"


def test_save_every_builtin_round_trips(tmp_path):
    for info in list_presets():
        path = save_preset(info.material, info.name, tmp_path)
        assert load_material_file(path) == info.material


def test_save_defaults_to_the_user_dir_and_the_preset_is_then_found(isolated_user_dir):
    m = Material(diffuse=(0.1, 0.2, 0.3), shininess=42, description="mine")
    path = save_preset(m, "mine")
    assert path == isolated_user_dir / "mine.yaml"
    assert path.read_text().startswith("# phong-explorer material preset 'mine'")
    assert find_preset("mine") == m


def test_save_never_overwrites_unless_asked(tmp_path):
    first = Material(shininess=1)
    path = save_preset(first, "x", tmp_path)
    with pytest.raises(ExplorerError, match="already exists"):
        save_preset(Material(shininess=2), "x", tmp_path)
    assert load_material_file(path) == first
    save_preset(Material(shininess=2), "x", tmp_path, overwrite=True)
    assert load_material_file(path).shininess == 2
    assert sorted(os.listdir(tmp_path)) == ["x.yaml"]


@pytest.mark.parametrize("name", ["Gold", "my gold", "../evil", "a/b", "", "x" * 65, "é"])
def test_save_refuses_unsafe_names(tmp_path, name):
    with pytest.raises(ExplorerError, match="not a valid preset name"):
        save_preset(Material(), name, tmp_path)
    assert os.listdir(tmp_path) == []


def test_save_refuses_a_material_no_file_could_hold(tmp_path):
    with pytest.raises(ValidationError) as info:
        save_preset(Material(diffuse=(1.5, 0, 0), shininess=2000), "too_bright", tmp_path)
    assert "diffuse[0]" in str(info.value) and "shininess" in str(info.value)
    assert os.listdir(tmp_path) == []


# -- loading errors: message names file, line, key and allowed range ------------------------
@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("shinyness: 10\n", ":1: shinyness: unknown key (did you mean 'shininess'?)"),
        ("shininess: 10\nshininess: 20\n", ":2: shininess: duplicate key 'shininess' (first"),
        ("diffuse: red\n", ":1: diffuse: must be a list of 3 numbers each in [0, 1]"),
        ("kd: 1\nshininess: 1e4\n", ":2: shininess: must be in [0, 1000], got 10000"),
        ("opacity: 1.5\n", ":1: opacity: must be in [0, 1], got 1.5"),
        ("kd: -1\n", ":1: kd: must be in [0, 1], got -1"),
        ("", ": is empty"),
        ("- 1\n- 2\n", ":1: must be a mapping of material keys"),
        ("shininess: 1" + "0" * 350 + "\n", ":1: shininess: number is too large"),
        ("ambient: !!python/tuple [1, 1, 1]\n", ":1: ambient: the tag '!!python/tuple'"),
    ],
)
def test_material_file_problems(tmp_path, text, expected):
    path = write(tmp_path / "bad.yaml", text)
    with pytest.raises(ValidationError) as info:
        load_material_file(path)
    assert str(info.value).startswith(str(path) + expected)


def test_not_utf8_and_too_large_material_files(tmp_path):
    bad = tmp_path / "latin.yaml"
    bad.write_bytes(b"description: caf\xe9\n")
    with pytest.raises(ValidationError, match="not UTF-8 text.*byte offset 16"):
        load_material_file(bad)
    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (MAX_BYTES + 1))
    with pytest.raises(ValidationError, match="too large"):
        load_material_file(big)


def test_every_problem_in_a_file_in_one_pass_in_line_order(tmp_path):
    path = write(
        tmp_path / "bad.yaml",
        "shinyness: 3\n"
        "ambient: [1, 2, 0]\n"
        "ka: 0.2\n"
        "ambient: [0, 0, 0]\n"
        "opacity: 7\n"
        "1: x\n"
        "model: gouraud\n",
    )
    with pytest.raises(ValidationError) as info:
        load_material_file(path)
    lines = [p.line for p in info.value.problems]
    assert lines == [1, 2, 3, 4, 5, 6, 7]
    assert all(p.file == str(path) for p in info.value.problems)


# -- fuzz: only ever a ValidationError -------------------------------------------------------
@pytest.fixture(scope="module")
def fuzz_dir():
    with tempfile.TemporaryDirectory() as d:
        yield Path(d)


def load_or_validation_error(path: Path):
    try:
        m = load_material_file(path)
    except ValidationError as exc:
        assert exc.problems and all(p.file == str(path) for p in exc.problems)
        return None
    assert isinstance(m, Material)
    for key in ("ambient", "diffuse", "specular", "emission"):
        assert all(0 <= c <= 1 for c in getattr(m, key))
    assert 0 <= m.shininess <= 1000 and 0 <= m.opacity <= 1
    return m


scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-5, 2000),
    st.integers(),
    st.integers(10**300, 10**400),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
)
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=8,
)
documents = st.one_of(
    st.dictionaries(st.sampled_from(MATERIAL_KEYS) | st.text(max_size=10), values, max_size=8),
    values,
)


@given(documents)
def test_fuzz_random_documents(fuzz_dir, doc):
    path = fuzz_dir / "doc.yaml"
    path.write_text(yaml.safe_dump(doc, allow_unicode=True))
    load_or_validation_error(path)


BUILTIN_TEXTS = sorted(p.read_text() for p in builtin_dir().glob("*.yaml"))
MUTATIONS = st.sampled_from(
    list(":-[]{},#&*!'\"\t\n 0123456789.e") + ["\n  ", "!!python/name:os.system ", "*a", "<<: "]
)


@given(
    st.integers(0, len(BUILTIN_TEXTS) - 1),
    st.lists(
        st.tuples(st.floats(0, 1), st.integers(0, 4), MUTATIONS | st.text(max_size=3)),
        min_size=1,
        max_size=5,
    ),
)
def test_fuzz_mutations_of_valid_presets(fuzz_dir, which, edits):
    text = BUILTIN_TEXTS[which]
    for where, cut, insert in edits:
        pos = int(where * len(text))
        text = text[:pos] + insert + text[pos + cut :]
    path = fuzz_dir / "mutant.yaml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    load_or_validation_error(path)


@given(st.binary(max_size=200))
def test_fuzz_random_bytes(fuzz_dir, data):
    path = fuzz_dir / "bytes.yaml"
    path.write_bytes(data)
    load_or_validation_error(path)


# -- the CLI ---------------------------------------------------------------------------------
def test_cli_lists_every_preset_without_colour_when_not_a_tty(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    assert "\x1b[" not in out
    listed = [line.split()[0] for line in out.splitlines()]
    assert listed == sorted(p.name for p in list_presets())
    gold = next(line for line in out.splitlines() if line.startswith("gold "))
    assert "51.2" in gold and find_preset("gold").description in gold


class FakeTTY(io.StringIO):
    def isatty(self):
        return True


def test_colour_only_on_a_tty_without_no_color(monkeypatch):
    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.setenv("TERM", "xterm-256color")
    assert use_colour(FakeTTY()) and not use_colour(io.StringIO())
    monkeypatch.setenv("NO_COLOR", "1")
    assert not use_colour(FakeTTY())
    monkeypatch.setenv("NO_COLOR", "")
    assert use_colour(FakeTTY())
    monkeypatch.setenv("TERM", "dumb")
    assert not use_colour(FakeTTY())


def test_swatch_is_drawn_with_24_bit_colour_on_a_tty(monkeypatch):
    from explorer.cli.presets import list_

    monkeypatch.delenv("NO_COLOR", raising=False)
    monkeypatch.setenv("TERM", "xterm")
    out = FakeTTY()
    assert list_([], out=out, err=io.StringIO()) == 0
    r, g, b = swatch_rgb(find_preset("red_plastic"))
    assert (r, g, b) == (128, 0, 0)  # 0.5 diffuse red, black ambient
    red = next(line for line in out.getvalue().splitlines() if "red_plastic" in line)
    assert red.startswith(f"\x1b[48;2;{r};{g};{b}m")


def test_cli_list_shows_user_presets_and_prints_shadow_notices(capsys, tmp_path):
    write(tmp_path / "gold.yaml", GOLDISH)
    write(tmp_path / "my_own.yaml", "description: mine\n")
    assert main(["presets", "--materials", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "notice:" in captured.err and "gold" in captured.err
    assert any(
        ln.startswith("my_own") and "[--materials-dir]" in ln for ln in captured.out.splitlines()
    )


def test_cli_show_prints_the_file_and_values_that_load_back(capsys):
    assert main(["presets", "show", "emerald"]) == 0
    out = capsys.readouterr().out
    assert str(builtin_dir() / "emerald.yaml") in out
    from explorer.core.material import parse_material
    from explorer.core.validate import Checker

    shown = parse_material(yaml.safe_load(out), Checker(), ())
    assert shown == find_preset("emerald")


def test_cli_show_accepts_materials_after_the_action_and_a_file_path(capsys, tmp_path):
    write(tmp_path / "mine.yaml", "description: mine\nkd: 0.5\n")
    assert main(["presets", "show", "mine", "--materials", str(tmp_path)]) == 0
    assert "mine.yaml" in capsys.readouterr().out
    assert main(["presets", "show", str(tmp_path / "mine.yaml")]) == 0
    assert "diffuse: [0.5, 0.5, 0.5]" in capsys.readouterr().out


def test_cli_show_unknown_is_a_clean_error(capsys):
    assert main(["presets", "show", "gld"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: unknown material preset 'gld' (did you mean 'gold'?)")
    assert "Traceback" not in err


def test_cli_validate_builtins_ok(capsys):
    assert main(["presets", "validate", str(builtin_dir())]) == 0
    captured = capsys.readouterr()
    assert captured.out == "" and "no problems" in captured.err


def test_cli_validate_one_line_per_problem_exit_1(capsys, tmp_path):
    bad = write(tmp_path / "bad.yaml", "shinyness: 3\nopacity: 2\nopacity: 3\n")
    good = write(tmp_path / "good.yaml", "kd: 0.5\n")
    badly_named = write(tmp_path / "Bad Name.yaml", "kd: 0.5\n")
    code = main(["presets", "validate", str(bad), str(good), str(badly_named), "missing.yaml"])
    assert code == 1
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 5
    assert lines[0].startswith(f"{bad}:1: shinyness: unknown key (did you mean 'shininess'?)")
    assert lines[1].startswith(f"{bad}:2: opacity: must be in [0, 1], got 2")
    assert lines[2].startswith(f"{bad}:3: opacity: duplicate key")
    assert lines[3].startswith(f"{badly_named}: the file name 'Bad Name'")
    assert lines[4].startswith("missing.yaml: cannot read material file: no such file")


def test_cli_validate_a_directory(capsys, tmp_path):
    src = (builtin_dir() / "gold.yaml").read_text()
    write(tmp_path / "gold.yaml", src.replace("shininess:", "shininess: [1, 2]\nx:"))
    write(tmp_path / "fine.yaml", src)
    assert main(["presets", "validate", str(tmp_path)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 2 and "gold.yaml" in out[0] and "shininess" in out[0] and "x" in out[1]


# -- text from files never reaches the terminal raw (issue 19, item 8) ----------------------------
ESC = "\x1b]0;pwned\x07\x1b[2J\x1b[1A\r\u202e\x9b"


def assert_no_raw_controls(text: str) -> None:
    """Only printable text and line breaks: no ESC, BEL, CR, C1 control or bidi override."""
    bad = [c for c in text if c != "\n" and (not c.isprintable() and c != " ")]
    assert not bad, f"raw control characters {bad!r} in {text!r}"


def test_cli_list_and_show_escape_a_hostile_description(capsys, tmp_path):
    write(tmp_path / "evil.yaml", f'description: "{ESC.encode("unicode_escape").decode()}"\n')
    assert load_material_file(tmp_path / "evil.yaml").description == ESC
    assert main(["presets", "--materials", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert_no_raw_controls(out)
    assert "\\x1b]0;pwned\\x07\\x1b[2J" in out and "\\u202e" in out
    assert main(["presets", "show", "evil", "--materials", str(tmp_path)]) == 0
    assert_no_raw_controls(capsys.readouterr().out)


def test_hostile_keys_and_file_names_are_escaped_in_problems_and_notices(capsys, tmp_path):
    bad = write(tmp_path / "bad.yaml", '"\\e[2Jkd\\r": 0.5\n')
    assert main(["presets", "validate", str(bad)]) == 1
    out = capsys.readouterr().out
    assert_no_raw_controls(out)
    assert "\\x1b[2Jkd\\r: unknown key" in out
    with pytest.raises(ValidationError) as exc:
        load_material_file(bad)
    assert_no_raw_controls(str(exc.value))
    write(tmp_path / "x\x1b[2J.yaml", "kd: 0.5\n")  # not a preset name: a notice names it
    assert main(["presets", "--materials", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "notice:" in err and "x\\x1b[2J.yaml" in err
    assert_no_raw_controls(err)
    assert main(["presets", "--materials", str(tmp_path / "no\x1b[2Jdir")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: materials directory") and "no\\x1b[2Jdir" in err
    assert_no_raw_controls(err)


@pytest.mark.skipif(not os.path.exists("/dev/urandom"), reason="no /dev/urandom")
def test_a_device_as_a_preset_file_is_named_as_such_not_zero_bytes():
    """/dev/urandom has no size (stat says 0): it is refused as a device, never read."""
    with pytest.raises(ValidationError) as exc:
        load_material_file("/dev/urandom")
    msg = str(exc.value)
    assert "character device" in msg and " 0 bytes" not in msg


def test_a_directory_named_like_a_preset_is_said_to_be_one(tmp_path, capsys):
    (tmp_path / "shiny.yaml").mkdir()
    with pytest.raises(ExplorerError) as exc:
        find_preset("shiny", [tmp_path])
    msg = str(exc.value)
    assert str(tmp_path / "shiny.yaml") in msg and "is a directory" in msg
    assert "did you mean" not in msg
    assert main(["presets", "show", "shiny", "--materials", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_listing_into_a_closed_pipe_ends_quietly(tmp_path):
    """``phong-explorer presets | head -1``: the reader goes away after one line; the command
    stops without a BrokenPipeError traceback."""
    import subprocess
    import sys

    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    r = subprocess.run(
        f"{sys.executable} -m explorer.cli presets | head -1",
        shell=True,
        capture_output=True,
        text=True,
        env=env,
    )
    assert r.stdout.count("\n") == 1
    assert "Traceback" not in r.stderr and "BrokenPipe" not in r.stderr, r.stderr
