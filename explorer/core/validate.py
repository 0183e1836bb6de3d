"""Validation helpers shared by scene files, material presets and the Python API.

A :class:`Checker` walks a parsed document, converts values and *collects* problems instead of
stopping at the first one; ``raise_if_any()`` raises one :class:`ValidationError` listing all of
them. Every helper takes the key path of the value (``path``) and says it in the message, along
with the allowed range, the file and the line (when the document came from a file).

Key paths are tuples such as ``("lights", 1, "attenuation")`` and print as
``lights[1].attenuation``.

Each key of a model class (a material, a light, the viewer, the HDR settings, the scene) is
checked by one function ``check(checker, value, path) -> value or None`` in the class's ``KEYS``
table: the file parser runs it with the document's checker (every problem of the file at once,
with file and line), the class's constructor runs it through :func:`checked` (a
:class:`ValidationError` with the same message). A key renamed for clarity keeps its old name
readable: :meth:`Checker.renamed` in documents, :func:`old_keywords` for constructors, both with
one :class:`DeprecatedName` notice.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import functools
import math
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from numbers import Real
from typing import Any, ClassVar

import numpy as np

from explorer.core.errors import DeprecatedName, ExplorerTypeError, Problem, ValidationError

Path = tuple


def line_of(lines: Mapping[Path, int], path: Path) -> int | None:
    """Line of ``path`` in ``lines``, or of its nearest enclosing key (None if none)."""
    path = tuple(path)
    while True:
        if path in lines:
            return lines[path]
        if not path:
            return None
        path = path[:-1]


def format_path(path: Path) -> str:
    """``("lights", 1, "position")`` -> ``"lights[1].position"``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def suggest(word: str, options: Iterable[str]) -> str:
    """A did-you-mean hint (``" (did you mean 'shininess'?)"``) or an empty string."""
    close = difflib.get_close_matches(str(word), list(options), n=1, cutoff=0.6)
    return f" (did you mean '{close[0]}'?)" if close else ""


def format_number(x: float) -> str:
    """A number as range errors show it: short (``1``, ``0.5``, ``1e+06``) when that is the
    number exactly, else every digit it needs (``179.0001``, not ``179``), so a refused value
    never reads as an allowed one."""
    x = float(x)
    short = f"{x:g}"
    if not math.isfinite(x) or (float(short) == x and len(short) <= len(repr(x))):
        return short
    return repr(x)


def _fmt(x) -> str:
    if isinstance(x, float):
        return format_number(x)
    return repr(x) if isinstance(x, str) else str(x)


class Checker:
    """Collects :class:`Problem` for one document.

    file : shown in every message (a path, or None for an in-memory mapping)
    lines : optional mapping ``path tuple -> 1-based line`` (from :mod:`explorer.core.yamlio`); a
        problem is reported on the line of its key, or of the nearest enclosing key
    """

    def __init__(self, file: str | None = None, lines: Mapping[Path, int] | None = None):
        self.file = None if file is None else str(file)
        self.lines = dict(lines or {})
        self.problems: list[Problem] = []

    # -- bookkeeping -------------------------------------------------------------------------
    def line(self, path: Path) -> int | None:
        return line_of(self.lines, path)

    def problem(self, path: Path, message: str) -> None:
        self.problems.append(
            Problem(message, self.file, self.line(path), format_path(path) or None)
        )

    def raise_if_any(self) -> None:
        if self.problems:
            raise ValidationError(self.problems)

    # -- structure ---------------------------------------------------------------------------
    def mapping(self, value, path: Path, what: str = "a mapping") -> dict | None:
        if isinstance(value, Mapping):
            return dict(value)
        self.problem(path, f"must be {what} (key: value lines), got {_type(value)}")
        return None

    def keys(
        self,
        mapping: Mapping,
        path: Path,
        allowed: Sequence[str],
        required: Sequence[str] = (),
    ) -> bool:
        """Report unknown keys (with a did-you-mean) and missing required keys."""
        ok = True
        for key in mapping:
            if not isinstance(key, str) or key not in allowed:
                hint = suggest(key, allowed) if isinstance(key, str) else ""
                self.problem(
                    path + (key,),
                    f"unknown key{hint}; allowed keys: {', '.join(allowed)}",
                )
                ok = False
        for key in required:
            if key not in mapping:
                self.problem(path, f"missing required key '{key}'")
                ok = False
        return ok

    def renamed(self, mapping: Mapping, path: Path, renames: Mapping[str, tuple[str, str]]) -> dict:
        """``mapping`` with keys given by an old name moved to the new one.

        renames : old key -> (new key, what the new name means), e.g. ``{"direction":
            ("to_light", "the direction toward the light")}``
        Each old name in use issues one :class:`DeprecatedName` notice naming the file, line and
        key path; giving both names is a problem."""
        out = dict(mapping)
        for old, (new, meaning) in renames.items():
            if old not in out:
                continue
            if new in out:
                self.problem(path + (old,), f"is the old name of {new}: give only one of them")
                del out[old]
                continue
            where = Problem("", self.file, self.line(path + (old,))).where
            notice(f"{where}{format_path(path + (old,))} is now {new} ({meaning}); "
                   "the old name still works")  # fmt: skip
            out = {new if k == old else k: v for k, v in out.items()}
            n = len(path) + 1
            for p, line in list(self.lines.items()):  # problems in the value keep their line
                if p[:n] == path + (old,):
                    self.lines[path + (new,) + p[n:]] = line
        return out

    # -- scalars -----------------------------------------------------------------------------
    def number(
        self,
        value,
        path: Path,
        lo: float = -math.inf,
        hi: float = math.inf,
        *,
        lo_open: bool = False,
    ) -> float | None:
        """A finite real number in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``)."""
        rng = _range(lo, hi, lo_open)
        if isinstance(value, bool) or not isinstance(value, Real):
            self.problem(path, f"must be a number{rng}, got {_type(value)} {_fmt(value)}")
            return None
        try:
            x = float(value)
        except OverflowError:  # an int beyond the float range
            self.problem(path, f"must be a number{rng}, got an integer too large for a float")
            return None
        if not math.isfinite(x):
            self.problem(path, f"must be a finite number{rng}, got {_fmt(x)}")
            return None
        if x < lo or x > hi or (lo_open and x == lo):
            self.problem(path, f"must be{rng or ' a number'}, got {_fmt(x)}")
            return None
        return x

    def boolean(self, value, path: Path) -> bool | None:
        if isinstance(value, bool):
            return value
        self.problem(path, f"must be true or false, got {_type(value)} {_fmt(value)}")
        return None

    def choice(self, value, path: Path, options: Sequence[str]) -> str | None:
        if isinstance(value, str) and value in options:
            return value
        hint = suggest(value, options) if isinstance(value, str) else ""
        self.problem(path, f"must be one of {', '.join(options)}, got {_fmt(value)}{hint}")
        return None

    def string(self, value, path: Path) -> str | None:
        if isinstance(value, str):
            return value
        self.problem(path, f"must be text, got {_type(value)} {_fmt(value)}")
        return None

    # -- vectors -----------------------------------------------------------------------------
    def triple(
        self, value, path: Path, lo: float = -math.inf, hi: float = math.inf
    ) -> tuple[float, float, float] | None:
        rng = _range(lo, hi, False)
        if (
            isinstance(value, (str, bytes, Mapping))
            or not isinstance(value, (Sequence, np.ndarray))
            or len(value) != 3
        ):
            self.problem(
                path,
                f"must be a list of 3 numbers{' each' + rng if rng else ''}, "
                f"got {_type(value)} {_fmt(value)}",
            )
            return None
        out = []
        for i, v in enumerate(value):
            x = self.number(v, path + (i,), lo, hi)
            if x is None:
                return None
            out.append(x)
        return (out[0], out[1], out[2])

    def rgb(self, value, path: Path, lo: float = 0.0, hi: float = 1.0):
        """An RGB triple with every channel in ``[lo, hi]``."""
        return self.triple(value, path, lo, hi)

    def direction(self, value, path: Path):
        """A non-zero 3-vector of finite numbers, any scale (normalised by its owner)."""
        v = self.triple(value, path)
        if v is not None and not any(v):
            self.problem(path, "must be a non-zero direction, got [0, 0, 0]")
            return None
        return v


#: checks one key's value: (checker, value, path) -> the converted value, or None (a problem)
Check = Callable[[Checker, object, Path], object]


def check_fields(
    checks: Mapping[str, Check], values: Mapping, checker: Checker, path: Path
) -> dict:
    """Run the check of each key present in ``values``; returns key -> converted value (None
    where the check reported a problem)."""
    return {k: check(checker, values[k], path + (k,)) for k, check in checks.items() if k in values}


def check_values(checks: Mapping[str, Check], values: Mapping, path: Path = ()) -> dict:
    """:func:`check_fields` for values given in code: raises one :class:`ValidationError`
    listing every problem (key paths and messages as in a file, without file and line)."""
    checker = Checker(None)
    out = check_fields(checks, values, checker, path)
    checker.raise_if_any()
    return out


def checked(obj, checks: Mapping[str, Check]) -> None:
    """Check and convert the fields ``checks`` names on a frozen dataclass instance, in place
    (from its ``__post_init__``); raises one :class:`ValidationError` listing every problem, with
    the key paths and messages the scene-file parser gives. A field whose default is None
    (an optional part: a material's ``fresnel``, a scene's ``hdr``) takes None as "not given"."""
    optional = {f.name for f in dataclasses.fields(obj) if f.default is None}
    given = {k: getattr(obj, k) for k in checks if not (k in optional and getattr(obj, k) is None)}
    for k, v in check_values(checks, given).items():
        object.__setattr__(obj, k, v)


class Checked:
    """Base of the model's frozen dataclasses (material, lights, viewer, scene, HDR): each field
    named in ``KEYS`` is checked and converted once, when the object is made (:func:`checked`),
    and :meth:`replace` checks only the fields it changes: the others were checked when the
    original was made (a slider moves one value many times a second; the rest need no new
    look). Old key names of ``RENAMED`` are accepted by :meth:`replace` too."""

    KEYS: ClassVar[Mapping[str, Check]] = {}
    RENAMED: ClassVar[Mapping[str, tuple[str, str]]] = {}
    #: every subclass is a dataclass (what ``dataclasses.fields`` needs; declared for checkers)
    __dataclass_fields__: ClassVar[dict[str, dataclasses.Field[Any]]]

    def __post_init__(self):
        self._check(type(self).KEYS)

    def _check(self, checks: Mapping[str, Check]) -> None:
        """Check the fields ``checks`` names, then :meth:`_settle` the whole object."""
        checked(self, checks)
        self._settle()

    def _settle(self) -> None:
        """What follows the checks on the whole object (storing directions unit length)."""

    def replace(self, **changes):
        """A copy with some fields changed (``m.replace(shininess=64)``); only those are
        checked again."""
        changes = new_keywords(type(self), changes) if type(self).RENAMED else changes
        names = {f.name for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - names)
        if unknown:
            raise ExplorerTypeError(f"{type(self).__name__} has no field {unknown[0]!r}")
        new = copy.copy(self)
        for k, v in changes.items():
            object.__setattr__(new, k, v)
        new._check({k: c for k, c in type(self).KEYS.items() if k in changes})
        return new


def notice(message: str) -> None:
    """Issue one :class:`DeprecatedName` notice (the CLI prints it as ``notice: ...``)."""
    warnings.warn(message, DeprecatedName, stacklevel=4)


def old_keywords(cls):
    """Class decorator: the constructor also takes the old names in ``cls.RENAMED`` (old ->
    (new, meaning)) as keywords, with one :class:`DeprecatedName` notice each."""
    init = cls.__init__

    @functools.wraps(init)
    def __init__(self, *args, **kwargs):
        init(self, *args, **new_keywords(cls, kwargs))

    cls.__init__ = __init__
    return cls


def new_keywords(cls, kwargs: Mapping) -> dict:
    """``kwargs`` with the old names of ``cls.RENAMED`` replaced by the new ones (one notice
    each; both names at once raise a :class:`ValidationError`)."""
    out = dict(kwargs)
    for old, (new, meaning) in cls.RENAMED.items():
        if old not in out:
            continue
        if new in out:
            raise ValidationError(
                [Problem(f"is the old name of {new}: give only one of them", key=old)]
            )
        notice(f"{cls.__name__}({old}=...) is now {new} ({meaning}); the old name still works")
        out[new] = out.pop(old)
    return out


def _range(lo: float, hi: float, lo_open: bool) -> str:
    if lo == -math.inf and hi == math.inf:
        return ""
    if hi == math.inf:
        return f" > {_fmt(lo)}" if lo_open else f" >= {_fmt(lo)}"
    if lo == -math.inf:
        return f" <= {_fmt(hi)}"
    return f" in {'(' if lo_open else '['}{_fmt(lo)}, {_fmt(hi)}]"


def _type(value) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, str):
        return "text"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    return type(value).__name__
