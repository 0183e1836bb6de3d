"""Every picture of the documentation's gallery is a golden test, so the docs cannot drift.

Each example of ``docs/gallery/`` runs here as sphinx-gallery runs it (a script in its working
folder, here a temporary one); every picture it writes, found by the site's own scraper's
:func:`new_pictures` (docs/_ext/gallery_pictures.py), is compared with
``tests/golden/gallery/<example>/<file>.png`` by the goldens' comparator
(tests/helpers/imagecompare.py). A GIF turntable is compared as its frames side by side. After
an intended change: ``python -m pytest tests -k golden --regenerate-goldens``, and look at the
new pictures before committing them.
"""

from __future__ import annotations

import io
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.imagecompare import check_golden

ROOT = Path(__file__).resolve().parents[2]
GALLERY = ROOT / "docs" / "gallery"
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

from gallery_pictures import ORDER, PICTURE_SUFFIXES, new_pictures  # noqa: E402

EXAMPLES = sorted(GALLERY.glob("plot_*.py"))


def picture_of(path: Path) -> np.ndarray:
    """The pixels of a picture the gallery shows: a PNG as it is, a GIF's frames side by side
    (each as RGB), as (h, w, 3) uint8."""
    from PIL import Image, ImageSequence

    from explorer.render.images import read_png

    if path.suffix.lower() == ".png":
        return read_png(path)[:, :, :3]
    with Image.open(io.BytesIO(path.read_bytes())) as im:
        frames = [np.array(frame.convert("RGB")) for frame in ImageSequence.Iterator(im)]
    return np.concatenate(frames, axis=1)


def test_the_gallery_has_its_examples():
    """The examples the issue asks for, each a file sphinx-gallery runs (``plot_*.py``)."""
    names = {p.name for p in EXAMPLES}
    assert names == set(ORDER), names  # an example sphinx-gallery runs is in the gallery's order
    assert PICTURE_SUFFIXES == (".png", ".gif")


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_golden_gallery(example, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(example), run_name="__main__")
    pictures = new_pictures(tmp_path)
    assert pictures, f"{example.name} wrote no picture"
    for picture in pictures:
        check_golden(f"gallery/{example.stem}/{picture.stem}", picture_of(picture))
