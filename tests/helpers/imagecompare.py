"""Golden-image comparison for the render tests. Every image tolerance is here.

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

Regenerating goldens (after an intended change in the pictures)::

    PHONG_EXPLORER_REGENERATE_GOLDENS=1 python -m pytest tests/render/test_render.py -k golden

writes every golden again under ``tests/golden/`` (and removes goldens no test uses). Check the
new pictures before committing them. When a comparison fails, the new picture
(``<name>.new.png``) and a difference picture (``<name>.diff.png``: differences amplified 8×,
pixels beyond the tolerance in magenta) are written to ``$PHONG_EXPLORER_ARTIFACTS`` (default:
``<temp dir>/phong-explorer-golden``) and the failure message says where.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from explorer.render.images import encode_png, read_png

GOLDEN_DIR = Path(__file__).resolve().parent.parent / "golden"
REGENERATE_ENV = "PHONG_EXPLORER_REGENERATE_GOLDENS"
ARTIFACTS_ENV = "PHONG_EXPLORER_ARTIFACTS"

#: a pixel differs when some channel is off by more than this many levels (of 255)
PIXEL_TOL = 2
#: at most this fraction of the pixels may differ (0.1%: 160 pixels of 400×400)
MAX_DIFFERENT_FRACTION = 0.001
#: mean absolute difference over every pixel and channel, in levels: one level of rounding
#: noise everywhere passes, a systematic shift of 2 levels does not
MEAN_TOL = 1.0
#: amplification of the difference picture
DIFF_GAIN = 8


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


def artifacts_dir() -> Path:
    d = os.environ.get(ARTIFACTS_ENV) or os.path.join(
        tempfile.gettempdir(), "phong-explorer-golden"
    )
    path = Path(d)
    path.mkdir(parents=True, exist_ok=True)
    return path


def regenerating() -> bool:
    return os.environ.get(REGENERATE_ENV, "") not in ("", "0", "false", "no")


def _write(path: Path, image) -> None:

    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_bytes(encode_png(np.asarray(image)))
    os.replace(tmp, path)


def check_golden(name: str, image) -> None:
    """Compare ``image`` with ``tests/golden/<name>.png`` (or write it when regenerating).

    Fails the test with the comparison and where the new and difference pictures went."""
    import pytest

    GOLDEN_DIR.mkdir(exist_ok=True)
    golden = GOLDEN_DIR / f"{name}.png"
    if regenerating():
        _write(golden, image)
        return
    if not golden.exists():
        new = artifacts_dir() / f"{name}.new.png"
        _write(new, image)
        pytest.fail(
            f"no golden picture {golden}; the new picture is {new}. To create the goldens run "
            f"{REGENERATE_ENV}=1 python -m pytest tests/render/test_render.py -k golden"
        )
    expected = read_png(golden)
    result = compare(image, expected)
    if not result.ok:
        out = artifacts_dir()
        new, diff = out / f"{name}.new.png", out / f"{name}.diff.png"
        _write(new, image)
        _write(diff, diff_image(image, expected))
        pytest.fail(
            f"{name}: picture differs from {golden}: {result}.\n"
            f"new picture: {new}\ndifference (x{DIFF_GAIN}, magenta beyond tolerance): {diff}\n"
            f"if the change is intended: {REGENERATE_ENV}=1 python -m pytest "
            "tests/render/test_render.py -k golden"
        )
