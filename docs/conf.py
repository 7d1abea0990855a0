"""Sphinx configuration of the ti_spinorbit documentation site.

Build (warnings are errors):  python -m sphinx -W -b html docs docs/_build/html
Without executing the gallery: add  -D plot_gallery=0
"""

import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# document the checkout this file belongs to, also when another copy is installed
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")   # no network for Taichi's version check

import ti_spinorbit  # noqa: E402

project = "ti_spinorbit"
author = "the ti_spinorbit authors"
copyright = "ti_spinorbit authors, MIT licence"
version = release = ti_spinorbit.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "figures", "**.ipynb_checkpoints",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip"]
templates_path = ["_templates"]

# --- API reference ---------------------------------------------------------------------
autosummary_generate = True
autodoc_typehints = "none"             # the numpydoc "Parameters" sections carry the types
autodoc_default_options = {"members": False}
numpydoc_show_class_members = False    # result classes are dataclasses: fields are listed in
                                       # the class docstring, methods get their own entries
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- Markdown pages (physics, design, Dask) ----------------------------------------------
myst_heading_anchors = 3               # "#6-section-coordinates"-style anchors like GitHub's
myst_enable_extensions = ["dollarmath"]

# --- gallery: examples/plot_*.py, executed at build time ----------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
}

# --- HTML -------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"ti_spinorbit {release}"
html_static_path = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}


# --- docstrings written for reading as plain text -------------------------------------------
# The docstrings write absolute values and norms as |x| (plain text, as help() shows them);
# reStructuredText reads |...| as a substitution reference and fails the build ("Undefined
# substitution referenced"). No docstring of the package uses substitutions, so escape every
# bar outside ``literals`` instead of rewriting formulas in modules other people edit.
_LITERAL = re.compile(r"(``.+?``)")


def _escape_bars(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        if "|" in line:
            parts = _LITERAL.split(line)
            lines[i] = "".join(part if part.startswith("``") else
                               re.sub(r"(?<!\\)\|", r"\\|", part) for part in parts)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=600)
