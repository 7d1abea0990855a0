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
# the gallery shows what each example prints, not Taichi's banner (printed at its import) nor
# its "Starting on arch" line (at ti.init: _start_taichi below runs it before the examples)
os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "false")

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
numpydoc_show_class_members = False    # result classes are dataclasses: fields are listed in
                                       # the class docstring, methods get their own entries
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- Markdown pages (physics, design, Dask) ----------------------------------------------
# GitHub's heading anchors (physics.html#67-section-coordinates-inertial-and-apsidal), down to ####
myst_heading_anchors = 4

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


# Docstrings cite the Markdown pages as "docs/physics.md §8.6" (tests/test_readme_links.py
# checks that every cited section exists): on the site those become links to the page and to
# each section's heading anchor (myst_heading_anchors, GitHub-style slugs).
_PAGES = ("physics", "design", "dask")
_CITATION = re.compile(r"docs/(%s)\.md((?:[ ,;]*§[\d.]+(?:[–-][\d.]+)?)*)" % "|".join(_PAGES))
_SECTION = re.compile(r"§([\d.]+)(?:[–-][\d.]+)?")


def _slug(title):
    """GitHub's (and MyST's default) heading anchor."""
    return re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")


def _anchors(page):
    """{"8.6": "86-width-of-the-chaotic-separatrix-layer", ...} for the numbered headings."""
    text = (ROOT / "docs" / f"{page}.md").read_text(encoding="utf-8")
    return {m.group(1).rstrip("."): _slug(m.group(0).lstrip("#"))
            for m in re.finditer(r"^#{2,4} (\d+(?:\.\d+)*)\.?\s.*$", text, flags=re.M)}


_ANCHORS = {page: _anchors(page) for page in _PAGES}


def _link_citations(app, text):
    try:
        here = app.env.docname
        uris = {page: app.builder.get_relative_uri(here, page) for page in _PAGES}
    except Exception:          # not while a document is being read: leave the text as it is
        return text

    def link(m):
        page, refs = m.group(1), m.group(2)
        first = _SECTION.search(refs)
        head_end = first.start() if first else len(refs)
        out = [f"`docs/{page}.md{refs[:head_end]}"]
        pos = head_end
        if first is None:
            return f"{out[0]} <{uris[page]}>`__"
        for k, sec in enumerate(_SECTION.finditer(refs)):
            anchor = _ANCHORS[page].get(sec.group(1).rstrip("."))
            target = uris[page] + (f"#{anchor}" if anchor else "")
            if k == 0:
                out[0] += f"{sec.group(0)} <{target}>`__"
            else:
                out.append(refs[pos:sec.start()] + f"`{sec.group(0)} <{target}>`__")
            pos = sec.end()
        return "".join(out) + refs[pos:]

    return _CITATION.sub(link, text)


def _plain_text(app, what, name, obj, options, lines):
    for i, line in enumerate(lines):
        if "|" in line or "docs/" in line:
            parts = _LITERAL.split(line)
            lines[i] = "".join(part if part.startswith("``") else
                               _link_citations(app, re.sub(r"(?<!\\)\|", r"\\|", part))
                               for part in parts)


def _start_taichi(app):
    """Start Taichi once, before sphinx-gallery runs the examples (when it does)."""
    if str(app.config.plot_gallery).lower() not in ("0", "false", "no", "off", ""):
        ti_spinorbit.init()


def setup(app):
    app.connect("autodoc-process-docstring", _plain_text, priority=600)
    app.connect("builder-inited", _start_taichi, priority=100)   # before the gallery (500)
