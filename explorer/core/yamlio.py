"""Safe YAML in and out: plain values, line numbers, every mistake reported by name.

Every document a user gives the explorer (scene files, material presets) is read with
:func:`load_yaml` / :func:`parse_yaml`, which return a :class:`YamlDocument`:

* ``data`` holds plain Python values only: ``dict``, ``list``, ``str``, ``int``, ``float``,
  ``bool`` and ``None``;
* ``lines`` maps each key path to the 1-based line it is written on
  (``("lights", 1, "position") -> 12``; list items map to the line of the item; ``()`` maps to
  the line the document starts on), ready for :class:`~explorer.core.validate.Checker`.

What is refused (each as a :class:`~explorer.core.errors.ValidationError` naming file, line and key,
all problems of one document in one pass; YAML syntax errors stop at the first one):

* a missing or unreadable file, a directory, a FIFO, socket or device (never opened in a
  way that could block), more than :data:`MAX_BYTES` bytes;
* bytes that are not UTF-8 (the message gives the byte offset), control characters;
* an empty document, or several documents in one file;
* duplicate keys (PyYAML silently keeps the last one; here it is an error naming both lines);
* keys that are not text (``1:``, ``yes:``, ``[a, b]:``);
* aliases (``*name``) and merge keys (``<<``): refused outright, which also rules out
  "billion laughs" expansion bombs; anchors alone (``&name``) are harmless and ignored;
* every tag except the plain YAML ones (``!!str``, ``!!int``, ``!!float``, ``!!bool``,
  ``!!null``, ``!!seq``, ``!!map``; so no ``!!python/...``, ``!!binary``, ``!!set``, custom
  ``!tags``); dates and times (``2024-05-01``) are kept as the text written;
* nesting deeper than :data:`MAX_DEPTH`, integers longer than :data:`MAX_INT_DIGITS` digits or
  beyond the float range (no number a user writes can overflow a ``float()`` later).

One YAML 1.1 surprise is fixed: ``1e5`` and ``2E-3`` are read as numbers (PyYAML keeps them as
text unless written ``1.0e+5``), as every YAML 1.2 reader and every person would.

:func:`dump_yaml` gives the text of a document; :func:`explorer.core.atomic.write_atomic` writes
it (atomically, never over an existing file unless asked).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from numbers import Integral, Real
from typing import NoReturn

import yaml

from explorer.core.errors import Problem, ValidationError
from explorer.core.files import UnreadableFile, read_checked
from explorer.core.validate import Checker, format_path, line_of

#: Largest document accepted, in bytes (1 MiB: presets and scenes are a few hundred bytes).
MAX_BYTES = 1 << 20
#: Deepest nesting of lists/mappings accepted (scene files need 4).
MAX_DEPTH = 64
#: Longest integer literal accepted, in characters (beyond ~310 digits it is no float anyway).
MAX_INT_DIGITS = 400

_TAG = "tag:yaml.org,2002:"
_PLAIN_SCALAR_TAGS = {_TAG + t for t in ("str", "int", "float", "bool", "null")}
_TEXT_TAGS = {_TAG + "timestamp"}  # kept as the text written
_SURROGATE = re.compile("[\ud800-\udfff]")


@dataclass(frozen=True)
class YamlDocument:
    """A parsed document.

    data : plain Python values (dict / list / str / int / float / bool / None)
    lines : key path tuple -> 1-based line number (``()`` -> first line of the document)
    file : the path it was read from (as given), or None for in-memory text
    problems : with ``collect=True`` only, the problems that did not stop parsing (duplicate
        keys, keys that are not text, refused tags); empty otherwise
    """

    data: object
    lines: dict = field(default_factory=dict)
    file: str | None = None
    problems: tuple = ()

    def line(self, path: tuple) -> int | None:
        """Line of ``path`` or of its nearest enclosing key."""

        return line_of(self.lines, path)

    def checker(self):
        """A :class:`~explorer.core.validate.Checker` reporting against this document's lines,
        already holding :attr:`problems` (so one ``raise_if_any()`` reports everything)."""

        checker = Checker(self.file, self.lines)
        checker.problems.extend(self.problems)
        return checker


# -- reading ---------------------------------------------------------------------------------
def load_yaml(path, *, what: str = "file", collect: bool = False) -> YamlDocument:
    """Read and parse the YAML file at ``path``; ``what`` names it in messages ("scene").

    collect : False raises every problem at once. True raises only for problems that leave no
        document (unreadable, not UTF-8, too large, empty, syntax errors, aliases, too deep)
        and returns the rest in ``doc.problems``, so that a validator can add its own and
        report everything in one pass (``checker = doc.checker()``). The data then holds the
        first value of a duplicated key, and leaves out keys that are not text or whose value
        was refused.
    """
    name = os.fspath(path)
    data = _read_bytes(name, what)
    return parse_yaml(data, file=name, collect=collect)


def parse_yaml(
    text: str | bytes, *, file: str | None = None, collect: bool = False
) -> YamlDocument:
    """Parse YAML from a string (or UTF-8 bytes); ``file`` is only used in messages.
    ``collect``: see :func:`load_yaml`."""
    file = None if file is None else os.fspath(file)
    if isinstance(text, (bytes, bytearray, memoryview)):
        raw = bytes(text)
        if len(raw) > MAX_BYTES:
            _fail(file, None, _too_big(len(raw)))
        text = _decode(raw, file)
    elif not isinstance(text, str):
        raise TypeError(f"parse_yaml needs str or bytes, got {type(text).__name__}")
    else:
        # count UTF-8 bytes without encoding (surrogates would make .encode() raise)
        if len(text) > MAX_BYTES or len(text.encode("utf-8", "surrogatepass")) > MAX_BYTES:
            _fail(file, None, _too_big(len(text.encode("utf-8", "surrogatepass"))))
        if text.startswith("\ufeff"):
            text = text[1:]
    bad = _first_surrogate(text)
    if bad is not None:
        line = text.count("\n", 0, bad) + 1
        _fail(file, line, "is not valid Unicode text (lone surrogate character)")

    loader = None
    try:
        loader = _Loader(text)
        node = loader.get_single_node()
    except _Refused as exc:
        _fail(file, exc.line, exc.message)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        _fail(file, mark.line + 1 if mark is not None else None, _syntax_message(exc, mark))
    except yaml.reader.ReaderError as exc:
        line = text.count("\n", 0, exc.position) + 1
        _fail(file, line, _reader_message(exc))
    except yaml.YAMLError as exc:  # pragma: no cover - every PyYAML error is one of the above
        _fail(file, None, f"is not valid YAML: {exc}")
    except RecursionError:  # pragma: no cover - MAX_DEPTH stops nesting long before this
        _fail(file, None, f"is nested too deeply (more than {MAX_DEPTH} levels)")
    finally:
        if loader is not None:
            loader.dispose()

    if node is None:
        _fail(file, None, "is empty: expected YAML content, found none")
    builder = _Builder(loader, file)
    data = builder.build(node, ())
    if data is None and not builder.problems:
        builder.problems.append(
            Problem("is empty: the document holds only null", file, node.start_mark.line + 1)
        )
    if builder.problems and (not collect or data is None):
        raise ValidationError(builder.problems)
    return YamlDocument(data, builder.lines, file, tuple(builder.problems))


def _read_bytes(name: str, what: str) -> bytes:
    """The bytes of the regular file ``name`` (:func:`explorer.core.files.read_checked`: a FIFO,
    socket or device is refused without blocking, as is a file over :data:`MAX_BYTES`)."""
    try:
        return read_checked(name, cap=MAX_BYTES, what=what)
    except UnreadableFile as exc:
        if exc.reason.startswith("too large"):
            _fail(name, None, _too_big(exc.size))
        _fail(name, None, f"cannot read {what}: {exc.reason}")


def _decode(raw: bytes, file: str | None) -> str:
    try:
        return raw.decode("utf-8-sig")  # a leading byte-order mark is dropped
    except UnicodeDecodeError as exc:
        start = exc.start + (3 if raw.startswith(b"\xef\xbb\xbf") else 0)
        line = raw.count(b"\n", 0, start) + 1
        hint = ""
        if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
            hint = " (it looks like UTF-16: save it as UTF-8)"
        _fail(
            file,
            line,
            f"is not UTF-8 text: invalid byte 0x{raw[start]:02x} at byte offset {start}{hint}",
        )


def _first_surrogate(text: str) -> int | None:
    match = _SURROGATE.search(text)
    return None if match is None else match.start()


def _too_big(size: int | None) -> str:
    """The message for ``size`` bytes, or None: more than :data:`MAX_BYTES` of unknown size."""
    got = f"more than {MAX_BYTES}" if size is None else str(size)
    return f"is too large: {got} bytes, the limit is {MAX_BYTES} bytes ({MAX_BYTES >> 20} MiB)"


def _fail(file: str | None, line: int | None, message: str) -> NoReturn:
    raise ValidationError([Problem(message, file, line)])


def _syntax_message(exc: yaml.MarkedYAMLError, mark) -> str:
    problem = (exc.problem or exc.context or "not valid YAML").strip()
    context = (exc.context or "").strip() if exc.problem else ""
    if "single document" in context:
        return "holds more than one YAML document (a second '---'); keep one document per file"
    if "'\\t'" in problem:
        problem = "a tab character here; indent with spaces, not tabs"
        context = ""
    where = f"column {mark.column + 1}: " if mark is not None else ""
    ctx = f" ({context})" if context else ""
    return f"YAML syntax error at {where}{problem}{ctx}"


def _reader_message(exc) -> str:
    ch = exc.character
    code = ord(ch) if isinstance(ch, str) else int(ch)
    return f"contains the control character U+{code:04X}, which YAML does not allow"


class _Refused(Exception):
    def __init__(self, message: str, line: int | None):
        super().__init__(message)
        self.message = message
        self.line = line


class _Loader(yaml.SafeLoader):
    """SafeLoader that refuses aliases and caps nesting while composing the node tree."""

    def __init__(self, stream):
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise _Refused(
                f"uses the alias '*{event.anchor}': aliases and anchors are not supported, "
                "write the value out",
                event.start_mark.line + 1,
            )
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                event = self.peek_event()
                raise _Refused(
                    f"is nested too deeply (more than {MAX_DEPTH} levels)",
                    event.start_mark.line + 1,
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_BAD = object()  # stands for a value already reported as a problem


class _Builder:
    """Turns a composed node tree into plain values, collecting problems and line numbers."""

    def __init__(self, loader: _Loader, file: str | None):
        self.loader = loader
        self.file = file
        self.lines: dict = {}
        self.problems: list[Problem] = []

    def problem(self, path, node, message):

        self.problems.append(
            Problem(message, self.file, node.start_mark.line + 1, format_path(path) or None)
        )

    def build(self, node, path):
        value = self._build(node, path)
        return None if value is _BAD else value

    def _build(self, node, path):
        if not path:
            self.lines[()] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            return self._mapping(node, path)
        if isinstance(node, yaml.SequenceNode):
            if node.tag != _TAG + "seq":
                return self._bad_tag(node, path)
            out = []
            for i, item in enumerate(node.value):
                self.lines[path + (i,)] = item.start_mark.line + 1
                out.append(self.build(item, path + (i,)))
            return out
        return self._scalar(node, path)

    def _mapping(self, node, path):
        if node.tag != _TAG + "map":
            return self._bad_tag(node, path)
        out: dict = {}
        first: dict = {}
        for key_node, value_node in node.value:
            line = key_node.start_mark.line + 1
            if key_node.tag == _TAG + "merge":
                self.problem(path, key_node, "merge keys ('<<') are not supported")
                continue
            key = self._key(key_node, path)
            if key is None:
                continue
            if key in first:
                self.problem(
                    path + (key,), key_node, f"duplicate key '{key}' (first at line {first[key]})"
                )
                continue
            first[key] = line
            self.lines[path + (key,)] = line
            value = self._build(value_node, path + (key,))
            if value is not _BAD:
                out[key] = value
        return out

    def _key(self, node, path):
        if not isinstance(node, yaml.ScalarNode):
            kind = "a list" if isinstance(node, yaml.SequenceNode) else "a mapping"
            self.problem(path, node, f"a key must be text, got {kind}")
            return None
        value = self._scalar(node, path)
        if isinstance(value, str):
            return value
        if value is not _BAD:
            kind = {type(None): "null", bool: "true/false"}.get(type(value), "a number")
            self.problem(
                path,
                node,
                f"a key must be text, but {node.value!r} reads as {kind}; write it in quotes",
            )
        return None

    def _bad_tag(self, node, path):
        tag = node.tag
        shown = "!!" + tag[len(_TAG) :] if tag.startswith(_TAG) else tag
        self.problem(
            path,
            node,
            f"the tag '{shown}' is not allowed: only plain text, numbers, true/false, null, "
            "lists and mappings",
        )
        return _BAD

    def _scalar(self, node, path):
        tag = node.tag
        if tag in _TEXT_TAGS:
            return str(node.value)
        if tag not in _PLAIN_SCALAR_TAGS:
            return self._bad_tag(node, path)
        if tag == _TAG + "int" and len(node.value) > MAX_INT_DIGITS:
            self.problem(path, node, f"number is too long ({len(node.value)} digits)")
            return _BAD
        try:
            value = self.loader.construct_object(node, deep=True)
        except (yaml.YAMLError, ValueError, OverflowError, TypeError) as exc:
            reason = getattr(exc, "problem", None) or str(exc)
            self.problem(path, node, f"cannot read {node.value!r} as {tag[len(_TAG) :]}: {reason}")
            return _BAD
        if isinstance(value, int) and not isinstance(value, bool):
            try:
                float(value)
            except OverflowError:
                self.problem(path, node, "number is too large (beyond the float range, ~1.8e308)")
                return _BAD
        return value


# -- writing ---------------------------------------------------------------------------------
class _Dumper(yaml.SafeDumper):
    """Block style for mappings, flow style (``[0.1, 0.2, 0.3]``) for lists of scalars."""

    def represent_sequence(self, tag, sequence, flow_style=None):
        flat = all(not isinstance(x, (list, dict)) for x in sequence)
        return super().represent_sequence(tag, sequence, flow_style=flat)


# YAML 1.1 reads ``1e5`` (no dot, no exponent sign) as text; read it as the number meant, and
# quote such text when writing so it reads back as text.
_EXP_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")
for _cls in (_Loader, _Dumper):
    _cls.add_implicit_resolver(_TAG + "float", _EXP_FLOAT, list("-+0123456789."))


def _plain(value, path="document"):
    """Plain YAML-ready copy of ``value`` (tuples -> lists, numpy scalars -> float/int)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, Integral):
        return int(value)
    if isinstance(value, Real):
        return float(value)
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"{path}: YAML keys must be str, got {k!r}")
            out[k] = _plain(v, f"{path}.{k}")
        return out
    if isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
        seq = value.tolist() if hasattr(value, "tolist") else value
        return [_plain(v, f"{path}[{i}]") for i, v in enumerate(seq)]
    raise TypeError(f"{path}: cannot write {type(value).__name__} to YAML")


def _has_nel(value) -> bool:
    if isinstance(value, str):
        return "\x85" in value
    if isinstance(value, dict):
        return any(_has_nel(k) or _has_nel(v) for k, v in value.items())
    if isinstance(value, list):
        return any(_has_nel(v) for v in value)
    return False


def dump_yaml(data, *, header: str | None = None) -> str:
    """The YAML text of ``data`` (``header`` becomes ``#`` comments): write it with
    :func:`explorer.core.atomic.write_atomic`."""
    plain = _plain(data)
    # U+0085 (NEL) would be written raw and read back as a line break: escape all then
    text = yaml.dump(
        plain, Dumper=_Dumper, sort_keys=False, allow_unicode=not _has_nel(plain), width=100
    )
    if header:
        lines = [("# " + ln).rstrip() for ln in header.splitlines()]
        text = "\n".join(lines) + "\n" + text
    return text
