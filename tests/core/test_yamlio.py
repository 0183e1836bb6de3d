"""The safe YAML loader and the atomic writer (explorer.core.yamlio)."""

from __future__ import annotations

import math
import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError, ValidationError
from explorer.core.yamlio import (
    MAX_BYTES,
    MAX_DEPTH,
    YamlDocument,
    dump_yaml,
    load_yaml,
    parse_yaml,
)

SCENE = """\
# a scene
material: gold
lights:
  - type: directional
    to_light: [0, 0, 1]
  - type: point
    position: [1, 2, 3]
    attenuation: [1, 0.1, 0]
viewer:
  eye: [0, 0, 5]
"""


def problems(text, file="doc.yaml"):
    with pytest.raises(ValidationError) as info:
        parse_yaml(text, file=file)
    return info.value.problems


def only_problem(text, file="doc.yaml"):
    (p,) = problems(text, file)
    return p


def assert_plain(value):
    if isinstance(value, dict):
        for k, v in value.items():
            assert isinstance(k, str)
            assert_plain(v)
    elif isinstance(value, list):
        for v in value:
            assert_plain(v)
    else:
        assert value is None or type(value) in (str, int, float, bool), type(value)


# -- reading valid documents -----------------------------------------------------------------
def test_data_and_line_numbers_of_nested_keys_and_items():
    doc = parse_yaml(SCENE, file="s.yaml")
    assert doc.file == "s.yaml"
    assert doc.data["lights"][1]["position"] == [1, 2, 3]
    assert doc.lines[()] == 2  # the document starts after the comment
    assert doc.lines[("material",)] == 2
    assert doc.lines[("lights",)] == 3
    assert doc.lines[("lights", 0)] == 4
    assert doc.lines[("lights", 1)] == 6
    assert doc.lines[("lights", 1, "position")] == 7
    assert doc.lines[("lights", 1, "attenuation", 2)] == 8
    assert doc.lines[("viewer", "eye")] == 10
    assert doc.line(("viewer", "eye", "nonexistent")) == 10
    assert_plain(doc.data)


def test_load_yaml_reads_a_file_and_strips_a_bom(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_bytes(b"\xef\xbb\xbf" + SCENE.encode())
    doc = load_yaml(path)
    assert isinstance(doc, YamlDocument)
    assert doc.file == str(path)
    assert doc.data["material"] == "gold"
    assert doc.lines[("lights", 1, "position")] == 7


def test_plain_scalars_and_yaml_quirks():
    doc = parse_yaml(
        "a: 1\nb: 2.5\nc: true\nd: ~\ne: text\nf: 1e5\ng: -2.5E-3\nh: '1e5'\n"
        "i: 2024-05-01\nj: 2001-12-14t21:59:43.10-05:00\nk: !!float 3\n"
    )
    d = doc.data
    assert d["a"] == 1 and type(d["a"]) is int
    assert d["b"] == 2.5 and d["c"] is True and d["d"] is None and d["e"] == "text"
    assert d["f"] == 1e5 and type(d["f"]) is float
    assert d["g"] == -2.5e-3
    assert d["h"] == "1e5"
    assert d["i"] == "2024-05-01"  # dates stay the text written
    assert d["j"] == "2001-12-14t21:59:43.10-05:00"
    assert d["k"] == 3.0 and type(d["k"]) is float
    assert_plain(d)


def test_anchor_without_alias_is_harmless():
    assert parse_yaml("a: &x [1, 2]\nb: 3\n").data == {"a": [1, 2], "b": 3}


def test_top_level_list_and_scalar_documents_parse():
    assert parse_yaml("- 1\n- 2\n").data == [1, 2]
    assert parse_yaml("hello").data == "hello"


# -- file-level problems ---------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(ValidationError) as info:
        load_yaml(tmp_path / "nope.yaml", what="scene")
    msg = str(info.value)
    assert "nope.yaml" in msg and "no such file" in msg and "scene" in msg


def test_directory_instead_of_file(tmp_path):
    with pytest.raises(ValidationError, match="directory"):
        load_yaml(tmp_path)


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root reads anything")
def test_unreadable_file(tmp_path):
    path = tmp_path / "secret.yaml"
    path.write_text("a: 1\n")
    path.chmod(0)
    with pytest.raises(ValidationError, match="permission denied"):
        load_yaml(path)


def test_too_large_file_is_refused_without_parsing(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_bytes(b"a: 1\n" + b"#" * MAX_BYTES)
    with pytest.raises(ValidationError) as info:
        load_yaml(path)
    msg = str(info.value)
    assert str(MAX_BYTES) in msg and str(MAX_BYTES + 5) in msg and "big.yaml" in msg


def test_exactly_max_bytes_is_accepted():
    text = "a: 1\n" + "#" * (MAX_BYTES - 5)
    assert len(text.encode()) == MAX_BYTES
    assert parse_yaml(text).data == {"a": 1}
    with pytest.raises(ValidationError, match="too large"):
        parse_yaml(text + "#")


def test_not_utf8_names_the_byte_offset_and_line(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes("a: 1\nname: caf\u00e9\n".encode("latin-1"))
    with pytest.raises(ValidationError) as info:
        load_yaml(path)
    (p,) = info.value.problems
    assert p.line == 2 and p.file == str(path)
    assert "UTF-8" in p.message and "byte offset 14" in p.message and "0xe9" in p.message


def test_utf16_gets_a_hint():
    assert "UTF-16" in only_problem("a: 1\n".encode("utf-16")).message


@pytest.mark.parametrize("text", ["", "   \n\n", "# just a comment\n", "~\n", "null"])
def test_empty_documents(text):
    assert "empty" in only_problem(text).message


def test_control_character():
    p = only_problem("a: 1\nb: x\x07y\n")
    assert p.line == 2 and "U+0007" in p.message


def test_lone_surrogate_in_text():
    assert "Unicode" in only_problem("a: '\ud800'\n").message


# -- syntax ----------------------------------------------------------------------------------
def test_syntax_error_gives_line_column_and_reason():
    p = only_problem("a: 1\nb: c: d\n")
    assert p.file == "doc.yaml" and p.line == 2
    assert "column 5" in p.message and "mapping values are not allowed" in p.message


def test_unclosed_flow_list():
    p = only_problem("a: [1, 2\nb: 3\n")
    assert "syntax" in p.message and p.line is not None


def test_tab_indentation_explained():
    p = only_problem("a:\n\t- 1\n")
    assert p.line == 2 and "tab" in p.message and "spaces" in p.message


def test_several_documents_refused():
    p = only_problem("a: 1\n---\nb: 2\n")
    assert "more than one YAML document" in p.message


def test_too_deep_nesting():
    assert "nested too deeply" in only_problem("[" * (MAX_DEPTH + 1)).message
    assert "nested too deeply" in only_problem("a: [" * 10_000).message
    deep_ok = "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1)
    assert parse_yaml(deep_ok).data is not None


def test_too_long_integer():
    p = only_problem("a: " + "9" * 5000 + "\n")
    assert p.key == "a" and "too long" in p.message


@pytest.mark.parametrize("literal", ["9" * 309, "-" + "9" * 350, "0x" + "f" * 300])
def test_integer_beyond_float_range(literal):
    p = only_problem(f"a: {literal}\n")
    assert p.key == "a" and "too large" in p.message
    assert parse_yaml("a: " + "9" * 300).data["a"] == int("9" * 300)  # still fits a float


# -- duplicate and bad keys ------------------------------------------------------------------
def test_duplicate_key_names_both_lines():
    p = only_problem("shininess: 10\ndiffuse: [1, 1, 1]\nshininess: 20\n")
    assert p.line == 3 and p.key == "shininess"
    assert "duplicate key 'shininess' (first at line 1)" in p.message


def test_nested_and_flow_duplicates_all_reported_in_one_pass():
    ps = problems("a: 1\nb: {x: 1, x: 2}\nc:\n  - y: 1\n    y: 2\na: 3\n")
    assert [(p.line, p.key) for p in ps] == [(2, "b.x"), (5, "c[0].y"), (6, "a")]


def test_non_text_keys_reported_with_advice():
    ps = problems("1: a\nyes: b\n~: c\n[1]: d\n1.5: e\nok: f\n")
    assert [p.line for p in ps] == [1, 2, 3, 4, 5]
    assert "number" in ps[0].message and "quotes" in ps[0].message
    assert "true/false" in ps[1].message
    assert "null" in ps[2].message
    assert "list" in ps[3].message


def test_every_problem_in_one_pass():
    ps = problems("a: 1\na: 2\nb: !!binary aGk=\n2: x\nc: *nothing\n")
    # an alias stops composing at once; otherwise problems accumulate
    assert len(ps) == 1 and "alias" in ps[0].message
    ps = problems("a: 1\na: 2\nb: !!binary aGk=\n2: x\nc: !foo 1\n")
    assert [p.line for p in ps] == [2, 3, 4, 5]


# -- unsafe constructs -----------------------------------------------------------------------
def test_python_tags_are_refused_and_never_run(tmp_path):
    marker = tmp_path / "pwned"
    text = f"a: !!python/object/apply:os.system ['touch {marker}']\n"
    p = only_problem(text)
    assert "!!python/object/apply:os.system" in p.message and p.key == "a"
    assert not marker.exists()


@pytest.mark.parametrize("tag", ["!!binary aGk=", "!!set {a}", "!!omap [a: 1]", "!custom 1"])
def test_non_plain_tags_refused(tag):
    assert "not allowed" in only_problem(f"v: {tag}\n").message


def test_bad_explicit_conversion_reported():
    p = only_problem("a: !!int abc\n")
    assert p.key == "a" and "abc" in p.message


def test_aliases_refused_so_billion_laughs_cannot_expand():
    lol = ['a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for i, name in enumerate("bcdefghi"):
        prev = "abcdefghi"[i]
        lol.append(f"{name}: &{name} [" + ",".join([f"*{prev}"] * 9) + "]")
    p = only_problem("\n".join(lol) + "\n")
    assert p.line == 2 and "alias" in p.message


def test_merge_keys_refused():
    assert "merge" in only_problem("<<: {a: 1}\nb: 2\n").message


# -- writing ---------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "text", ["1e5", "-2E-3", "yes", "null", "0x10", "a\x85b", "\x07", "#", "é"]
)
def test_text_that_looks_special_round_trips_as_text(text):
    assert parse_yaml(dump_yaml({"d": text})).data == {"d": text}


def test_write_round_trip_with_header(tmp_path):
    data = {
        "description": "a test: with colon",
        "diffuse": (0.1, 0.2, 1 / 3),
        "shininess": 76.8,
        "nested": {"list": [{"a": 1}, {"b": None}], "flag": True},
    }
    path = write_atomic(
        tmp_path / "sub" / "dir" / "m.yaml",
        dump_yaml(data, header="line 1\nline 2").encode(),
        make_dirs=True,
    )
    assert path == tmp_path / "sub" / "dir" / "m.yaml"
    text = path.read_text()
    assert text.startswith("# line 1\n# line 2\n")
    assert "diffuse: [0.1, 0.2, 0.3333333333333333]" in text
    doc = load_yaml(path)
    assert doc.data == {**data, "diffuse": [0.1, 0.2, 1 / 3]}
    assert os.listdir(path.parent) == ["m.yaml"]  # no temp file left behind


def test_write_refuses_to_overwrite_unless_asked(tmp_path):
    path = tmp_path / "m.yaml"
    path.write_text("old: 1\n")
    with pytest.raises(ExplorerError) as info:
        write_atomic(path, dump_yaml({"new": 2}).encode())
    assert "already exists" in str(info.value) and "overwrite" in str(info.value)
    assert path.read_text() == "old: 1\n"
    write_atomic(path, dump_yaml({"new": 2}).encode(), overwrite=True)
    assert load_yaml(path).data == {"new": 2}
    assert sorted(os.listdir(tmp_path)) == ["m.yaml"]


def test_write_into_a_directory_path_refused(tmp_path):
    with pytest.raises(ExplorerError, match="directory"):
        write_atomic(tmp_path, dump_yaml({"a": 1}).encode(), overwrite=True)


def test_write_cleans_up_temp_file_when_the_disk_fails(tmp_path, monkeypatch):
    path = tmp_path / "m.yaml"
    path.write_text("old: 1\n")

    def broken_fsync(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", broken_fsync)
    with pytest.raises(ExplorerError, match="No space left"):
        write_atomic(path, dump_yaml({"new": 2}).encode(), overwrite=True)
    assert path.read_text() == "old: 1\n"
    assert os.listdir(tmp_path) == ["m.yaml"]


def test_unserialisable_data_touches_nothing(tmp_path):
    with pytest.raises(TypeError):
        write_atomic(tmp_path / "x" / "m.yaml", dump_yaml({"a": object()}).encode(), make_dirs=True)
    assert os.listdir(tmp_path) == []


def test_written_file_mode_follows_umask(tmp_path):
    path = write_atomic(tmp_path / "m.yaml", dump_yaml({"a": 1}).encode())
    mask = os.umask(0o022)
    os.umask(mask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~mask


finite = st.floats(allow_nan=False, allow_infinity=False)


@given(st.lists(finite, min_size=1, max_size=5), st.text(max_size=30))
def test_floats_and_text_round_trip_exactly(values, text):
    data = {"values": values, "text": text, text or "k": text}
    doc = parse_yaml(dump_yaml(data))
    assert doc.data == data
    signs = [math.copysign(1, v) for v in doc.data["values"]]
    assert signs == [math.copysign(1, v) for v in values]  # -0.0 stays -0.0


# -- fuzz ------------------------------------------------------------------------------------
def _parse_or_validation_error(source):
    try:
        doc = parse_yaml(source, file="fuzz.yaml")
    except ValidationError as exc:
        assert exc.problems
        assert all(p.file == "fuzz.yaml" and p.message for p in exc.problems)
        return None
    assert_plain(doc.data)
    assert doc.data is not None
    for path, line in doc.lines.items():
        assert isinstance(path, tuple) and isinstance(line, int) and line >= 1
    return doc


@given(st.text(max_size=300))
def test_fuzz_random_text(text):
    _parse_or_validation_error(text)


@given(st.binary(max_size=300))
def test_fuzz_random_bytes(data):
    _parse_or_validation_error(data)


_YAMLISH = st.sampled_from(
    list(":-[]{},#&*!|>'\"%@`?\t\n ~") + ["\n  ", "!!python/name:os.system", "*a", "&a", "<<"]
)


@given(
    st.lists(
        st.tuples(st.integers(0, len(SCENE)), st.integers(0, 3), st.one_of(_YAMLISH, st.text())),
        min_size=1,
        max_size=6,
    )
)
def test_fuzz_mutations_of_a_valid_document(edits):
    text = SCENE
    for pos, cut, insert in edits:
        pos = min(pos, len(text))
        text = text[:pos] + insert + text[pos + cut :]
    _parse_or_validation_error(text)


# -- collect mode (one pass with a validator) ------------------------------------------------
def test_collect_returns_non_fatal_problems_with_the_data():
    doc = parse_yaml("a: 1\na: 2\nb: !!binary aGk=\n3: x\nc: [1, !foo 2]\n", collect=True)
    assert doc.data == {"a": 1, "c": [1, None]}  # first value kept, refused entries left out
    assert [p.line for p in doc.problems] == [2, 3, 4, 5]
    checker = doc.checker()
    checker.problem(("a",), "a validator's own problem")
    assert len(checker.problems) == 5
    with pytest.raises(ValidationError) as info:
        checker.raise_if_any()
    assert "duplicate key 'a'" in str(info.value) and "validator's own" in str(info.value)


def test_collect_still_raises_when_there_is_no_document():
    for text in ("", "a: [1,\n", "a: &x 1\nb: *x\n", "!!binary aGk="):
        with pytest.raises(ValidationError):
            parse_yaml(text, collect=True)


def test_clean_document_has_no_problems(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(SCENE)
    assert load_yaml(path, collect=True).problems == ()
    assert load_yaml(path).problems == ()
