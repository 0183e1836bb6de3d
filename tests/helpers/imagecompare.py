"""Golden files of the tests: pictures and colour arrays. Every image tolerance is here.

Goldens live in ``tests/golden/`` and its subfolders: ``<name>.png`` pictures
(:func:`check_golden`) and ``<name>.npz`` arrays (:func:`check_golden_arrays`). Pictures are read
and written with the package's one PNG codec (:mod:`explorer.render.images`, Pillow's), which
tests/render/test_render.py checks against an independent one (VTK's PNG reader and writer).

A picture matches its golden when

- at most ``MAX_DIFFERENT_FRACTION`` of its pixels differ from the golden by more than
  ``PIXEL_TOL`` levels (of 255) in some channel, and
- the mean absolute difference over all pixels and channels is at most ``MEAN_TOL`` levels.

Why these numbers: on the same machine a render is bit-identical to the previous one (the tests
check that). Another Mesa/llvmpipe version may round an interpolated colour differently (one
level, possibly in every pixel) or rasterise a silhouette pixel on the other side of an edge (a
few dozen pixels of a 400×400 picture). A uniform shift of 3/255 (every pixel beyond
``PIXEL_TOL``, mean 3), or a highlight moved by a 2-degree turn of its light (a few percent of
the pixels), is far beyond that; the tests check both, and that rounding noise passes.

Arrays match when every element is within the tolerance the test gives (see
:mod:`explorer.core.tolerances`), with the same names and shapes.

A test that uses a golden has ``golden`` in its name (:func:`check_golden` insists), so
``-k golden`` selects every one of them. Regenerating goldens (after an intended change)::

    python -m pytest tests -k golden --regenerate-goldens

(or ``PHONG_EXPLORER_REGENERATE_GOLDENS=1``) writes every golden whose content changed (a file
that still holds exactly the current result is left as it is) and removes the files in
``tests/golden/`` no test used (tests/test_goldens.py). Check the new files before committing
them. When a comparison fails, the new picture (``<name>.new.png``) and a difference picture
(``<name>.diff.png``: differences amplified 8×, pixels beyond the tolerance in magenta), or the
new arrays (``<name>.new.npz``), are written to ``$PHONG_EXPLORER_ARTIFACTS`` (default:
``<temp dir>/phong-explorer-golden``) and the failure message says where.
"""

from __future__ import annotations

import io
import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from explorer.core.atomic import write_atomic
from explorer.render.images import encode_png, read_png

GOLDEN_DIR = Path(__file__).resolve().parent.parent / "golden"
REGENERATE_ENV = "PHONG_EXPLORER_REGENERATE_GOLDENS"
ARTIFACTS_ENV = "PHONG_EXPLORER_ARTIFACTS"
REGENERATE_COMMAND = "python -m pytest tests -k golden --regenerate-goldens"

#: a pixel differs when some channel is off by more than this many levels (of 255)
PIXEL_TOL = 2
#: at most this fraction of the pixels may differ (0.1%: 160 pixels of 400×400)
MAX_DIFFERENT_FRACTION = 0.001
#: mean absolute difference over every pixel and channel, in levels: one level of rounding
#: noise everywhere passes, a systematic shift of 2 levels does not
MEAN_TOL = 1.0
#: amplification of the difference picture
DIFF_GAIN = 8

#: golden files (paths relative to GOLDEN_DIR) that the tests of this session checked
USED: set[str] = set()
#: why this session cannot tell which goldens are unused (filled by tests/conftest.py's hooks)
INCOMPLETE: list[str] = []


def is_golden_test_name(name: str) -> bool:
    """Whether a test of this name (a node id's last part) is a golden test: the name says so.
    tests/conftest.py watches these tests, tests/helpers/workers.py keeps them in one worker."""
    return "golden" in name


@dataclass(frozen=True)
class Comparison:
    """How far a picture is from another.

    different_fraction : fraction of pixels with a channel off by more than PIXEL_TOL
    mean_abs : mean absolute difference (levels) over all pixels and channels
    max_abs : largest channel difference (levels)
    """

    different_fraction: float
    mean_abs: float
    max_abs: int

    @property
    def ok(self) -> bool:
        return self.different_fraction <= MAX_DIFFERENT_FRACTION and self.mean_abs <= MEAN_TOL

    def __str__(self) -> str:
        return (
            f"{100 * self.different_fraction:.3f}% of pixels off by > {PIXEL_TOL} levels "
            f"(allowed {100 * MAX_DIFFERENT_FRACTION:.3f}%), mean difference "
            f"{self.mean_abs:.3f} levels (allowed {MEAN_TOL}), largest {self.max_abs}"
        )


def _rgb(image) -> np.ndarray:
    a = np.asarray(image)
    if a.ndim != 3 or a.shape[2] not in (3, 4) or a.dtype != np.uint8:
        raise ValueError(f"expected an (h, w, 3|4) uint8 picture, got {a.shape} {a.dtype}")
    return a[:, :, :3].astype(np.int16)


def compare(actual, expected) -> Comparison:
    """Compare two pictures of the same size (h, w, 3|4) uint8."""
    a, b = _rgb(actual), _rgb(expected)
    if a.shape != b.shape:
        raise AssertionError(f"picture size {a.shape[:2]} differs from the golden's {b.shape[:2]}")
    d = np.abs(a - b)
    bad = (d > PIXEL_TOL).any(axis=2)
    return Comparison(float(bad.mean()), float(d.mean()), int(d.max()))


def diff_image(actual, expected) -> np.ndarray:
    """Differences amplified DIFF_GAIN times; pixels beyond PIXEL_TOL in magenta."""
    a, b = _rgb(actual), _rgb(expected)
    d = np.abs(a - b)
    out = np.clip(d * DIFF_GAIN, 0, 255).astype(np.uint8)
    out[(d > PIXEL_TOL).any(axis=2)] = (255, 0, 255)
    return out


# -- files ---------------------------------------------------------------------------------


def read_picture(path) -> np.ndarray:
    """A PNG read with the package's codec: (h, w, 3) or (h, w, 4) uint8."""
    return read_png(path)


def write_picture(path, image) -> None:
    """Write an (h, w, 3|4) uint8 picture as PNG (atomically, folders made)."""
    a = np.ascontiguousarray(image)
    _rgb(a)  # shape and type check
    write_atomic(path, encode_png(a), overwrite=True, make_dirs=True)


def write_arrays(path, arrays: Mapping[str, np.ndarray]) -> None:
    """Write named arrays as one compressed .npz (atomically, folders made)."""
    buf = io.BytesIO()
    np.savez_compressed(buf, **{k: np.asarray(v) for k, v in arrays.items()})
    write_atomic(path, buf.getvalue(), overwrite=True, make_dirs=True)


def read_arrays(path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def artifacts_dir() -> Path:
    d = os.environ.get(ARTIFACTS_ENV) or os.path.join(
        tempfile.gettempdir(), "phong-explorer-golden"
    )
    path = Path(d)
    path.mkdir(parents=True, exist_ok=True)
    return path


def regenerating() -> bool:
    return os.environ.get(REGENERATE_ENV, "") not in ("", "0", "false", "no")


def golden_files() -> set[str]:
    """Every file under GOLDEN_DIR, subfolders included, as paths relative to it ('/'-separated)."""
    if not GOLDEN_DIR.exists():
        return set()
    return {p.relative_to(GOLDEN_DIR).as_posix() for p in GOLDEN_DIR.rglob("*") if p.is_file()}


def _use(relative: str) -> Path:
    """Record that the running test checks golden ``relative``; its path."""
    test = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" ", 1)[0]  # drop " (call)"
    if "golden" not in test.rsplit("::", 1)[-1]:
        raise AssertionError(
            f"{test or 'this code'} checks golden {relative!r}: a test that uses a golden needs "
            f"'golden' in its name, so that `{REGENERATE_COMMAND}` selects it"
        )
    USED.add(relative)
    return GOLDEN_DIR / relative


def _artifact(name: str, suffix: str) -> Path:
    return artifacts_dir() / f"{name.replace('/', '_')}{suffix}"


def _check(name: str, suffix: str, value, *, read, write, same, differences) -> None:
    """The golden mechanism of one file ``<name><suffix>``: write it when regenerating (unless
    it holds exactly ``value`` already), fail when it is missing, else fail with
    ``differences(value, golden)`` when that is not empty; each failure writes ``value`` to
    the artifacts folder as ``<name>.new<suffix>``.

    read(path) / write(path, value) / same(a, b) -> bool (exactly equal) /
    differences(value, golden) -> str ("" when they match)."""
    golden = _use(f"{name}{suffix}")
    if regenerating():
        if not (golden.exists() and same(read(golden), value)):
            write(golden, value)
        return
    new = _artifact(name, f".new{suffix}")
    if not golden.exists():
        write(new, value)
        pytest.fail(f"no golden {golden}; the new one is {new}. To create it: {REGENERATE_COMMAND}")
    problems = differences(value, read(golden))
    if problems:
        write(new, value)
        pytest.fail(
            f"{name}: differs from {golden}: {problems}\nnew: {new}\n"
            f"if the change is intended: {REGENERATE_COMMAND}"
        )


def check_golden(name: str, image) -> None:
    """Compare ``image`` (h, w, 3|4) uint8 with ``tests/golden/<name>.png`` (or write it when
    regenerating).

    Fails the test with the comparison and where the new and difference pictures went."""

    def differences(actual, expected) -> str:
        result = compare(actual, expected)
        if result.ok:
            return ""
        diff = _artifact(name, ".diff.png")
        write_picture(diff, diff_image(actual, expected))
        return f"{result}.\ndifference (x{DIFF_GAIN}, magenta beyond tolerance): {diff}"

    _check(
        name,
        ".png",
        image,
        read=read_picture,
        write=write_picture,
        same=np.array_equal,
        differences=differences,
    )


def array_differences(actual: Mapping, expected: Mapping, atol: float) -> list[str]:
    """What differs between two sets of named arrays, one line per problem (empty: they match).

    Arrays match when names and shapes are equal and every element is within ``atol``."""
    problems = []
    for key in sorted(set(expected) - set(actual)):
        problems.append(f"{key}: in the golden, not computed")
    for key in sorted(set(actual) - set(expected)):
        problems.append(f"{key}: computed, not in the golden")
    for key in sorted(set(actual) & set(expected)):
        a, b = np.asarray(actual[key], np.float64), np.asarray(expected[key], np.float64)
        if a.shape != b.shape:
            problems.append(f"{key}: shape {a.shape}, golden {b.shape}")
            continue
        d = np.abs(a - b)
        bad = ~(d <= atol)  # NaN counts as a difference
        if bad.any():
            rows = np.unique(np.nonzero(bad)[0])
            problems.append(
                f"{key}: {len(rows)} of {len(a)} rows differ by more than {atol:g} "
                f"(largest {np.nanmax(np.where(np.isnan(d), np.inf, d)):.3g}, first row {rows[0]})"
            )
    return problems


def _identical(a: Mapping, b: Mapping) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


def check_golden_arrays(name: str, arrays: Mapping[str, np.ndarray], atol: float) -> None:
    """Compare named float arrays with ``tests/golden/<name>.npz`` (or write it when
    regenerating); every element must be within ``atol`` of the golden's.

    Fails the test naming each array that differs, and where the new arrays went."""

    def differences(actual, expected) -> str:
        return "".join(f"\n  {p}" for p in array_differences(actual, expected, atol))

    _check(
        name,
        ".npz",
        arrays,
        read=read_arrays,
        write=write_arrays,
        same=_identical,
        differences=differences,
    )
