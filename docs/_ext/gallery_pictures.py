"""The gallery's image scraper: the pictures an example writes through :mod:`explorer.render`.

An example in ``docs/gallery/`` writes its pictures as files in its working folder, as a
user's script would: PNG through :func:`explorer.render.images.encode_png`, GIF through
:func:`explorer.render.turntable.encode`. sphinx-gallery runs each example in its own folder;
after each code block :func:`scrape` moves the pictures written meanwhile
(:func:`new_pictures`) to the gallery's image folder and shows them under the block. So the
site shows exactly what the product wrote, and ``tests/docs/test_gallery.py`` runs every example
in a temporary folder and checks each picture it writes against its golden
(``tests/golden/gallery/``): the gallery cannot drift from the product.
"""

from __future__ import annotations

import shutil
from pathlib import Path

#: the picture files the scraper collects (what explorer.render writes: PNG pictures, GIF
#: turntables)
PICTURE_SUFFIXES = (".png", ".gif")


def new_pictures(folder) -> list[Path]:
    """The pictures in ``folder``, oldest first (ties by name): an example's working folder
    holds no picture of its own, so each one there was written by the example."""
    found = [
        p for p in Path(folder).iterdir() if p.suffix.lower() in PICTURE_SUFFIXES and p.is_file()
    ]
    return sorted(found, key=lambda p: (p.stat().st_mtime_ns, p.name))


def scrape(block, block_vars, gallery_conf) -> str:
    """sphinx-gallery's image scraper (``image_scrapers`` in docs/conf.py): moves the pictures
    the block wrote into the gallery's image paths (a GIF keeps its suffix) and returns the
    reST that shows them."""
    from sphinx_gallery.scrapers import figure_rst

    paths = []
    targets = block_vars["image_path_iterator"]
    for picture in new_pictures(Path(block_vars["src_file"]).parent):
        target = Path(next(targets)).with_suffix(picture.suffix.lower())
        shutil.move(picture, target)
        paths.append(target)
    return figure_rst(paths, gallery_conf["src_dir"])


#: the gallery's order: the library, the models, the effects, then what accuracy costs, the
#: compare view and a turntable; an example not listed comes after these, by file name
ORDER = (
    "plot_presets.py",
    "plot_models.py",
    "plot_effects.py",
    "plot_accuracy.py",
    "plot_compare.py",
    "plot_turntable.py",
)


class GalleryOrder:
    """sphinx-gallery's ``within_subsection_order``: the examples in :data:`ORDER`."""

    def __init__(self, src_dir) -> None:
        self.src_dir = src_dir

    def __call__(self, filename: str) -> tuple[int, str]:
        return (ORDER.index(filename) if filename in ORDER else len(ORDER), filename)
