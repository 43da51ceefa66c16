"""Sphinx configuration of the stochcable manual.

Build: ``python3 -m pip install -e ".[docs]"`` then
``sphinx-build -W -b html docs docs/_build/html`` (what ``.ci/run`` does).  The scene,
results, warnings, CLI and HTTP references are generated from the code at build time
(``docs/_ext``); the gallery scripts in ``docs/gallery`` run at build time.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # the checkout's stochcable, not an installed copy
sys.path.insert(0, str(HERE / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import stochcable  # noqa: E402

project = "stochcable"
author = "stochcable developers"
copyright = "stochcable developers, BSD-3-Clause"  # noqa: A001 - Sphinx's name
release = stochcable.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "manual",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = [
    "_build",
    "_ext",
    "gallery",  # sphinx-gallery's sources; the rendered pages are in auto_gallery
    "auto_gallery/*.ipynb",
    "auto_gallery/*.py",
    "auto_gallery/*.zip",
    "auto_gallery/*.md5",
    "auto_gallery/*.json",
]

# Markdown pages (myst-parser): headings get anchors for links inside the manual.
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

# API reference: autodoc of the public API, numpydoc sections.
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc Parameters sections carry types and units
autodoc_default_options = {"members": True, "undoc-members": False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()

# Gallery: scripts docs/gallery/plot_*.py run at build time; none is fine too.
sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "abort_on_example_error": True,
    "write_computation_times": False,
}

html_theme = "pydata_sphinx_theme"
html_title = f"stochcable {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
html_static_path: list[str] = []
