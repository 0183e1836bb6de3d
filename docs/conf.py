"""Sphinx configuration of the documentation site.

Build (offline: no intersphinx, nothing downloaded; warnings are errors)::

    pip install -e ".[docs]"
    python -m sphinx -W --keep-going -b html docs docs/_build/html

The pages are the Markdown files of ``docs/`` as they are (MyST), so each one reads on its own
too; the API reference comes from the docstrings (autodoc + napoleon); the gallery is made by
sphinx-gallery from ``docs/gallery/`` with the scraper of ``docs/_ext/gallery_pictures.py``;
the presets page is generated from ``materials/`` by ``docs/_ext/preset_pages.py``. How the
site is put together, and how to add a page: docs/site.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))  # the package of this checkout (autodoc, the gallery)

from explorer.core.version import __version__  # noqa: E402

project = "phong-explorer"
author = "the phong-explorer developers"
copyright = "the phong-explorer developers (MIT licence)"
release = version = __version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx_gallery.gen_gallery",
    "preset_pages",
    "plain_docstrings",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = [
    "_build",
    "_ext",
    "examples",  # the notebook and the OBJ example's files (read by pages, not pages)
    "gallery",  # the gallery's sources; sphinx-gallery writes its pages to auto_gallery/
    "auto_gallery/*.md5",
    "auto_gallery/*.py",
    "auto_gallery/*.ipynb",
    "auto_gallery/*.zip",
]

# -- MyST: the Markdown files as GitHub shows them ------------------------------------------
myst_heading_anchors = 4  # [text](page.md#a-heading) links, as GitHub makes them
myst_enable_extensions = ["colon_fence"]

# -- autodoc: the public interface's docstrings ---------------------------------------------
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True, "undoc-members": False}
napoleon_numpy_docstring = True
napoleon_google_docstring = False

# -- the gallery -----------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_gallery",
    "filename_pattern": r"/plot_",
    "image_scrapers": ("gallery_pictures.scrape",),
    "reset_modules": (),
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "write_computation_times": False,  # its page loads DataTables from a CDN: none offline
    "abort_on_example_error": True,
    "within_subsection_order": "gallery_pictures.GalleryOrder",
    "first_notebook_cell": None,
    "capture_repr": (),  # no "Out:" for a block's last value (write_atomic's path)
    "min_reported_time": 10**9,  # no timing lines: they change from build to build
}

# -- HTML --------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"phong-explorer {release}"
html_static_path: list[str] = []
html_last_updated_fmt = None
