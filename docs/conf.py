"""Sphinx configuration of the ti_spinorbit documentation site.

Build (warnings are errors):  python -m sphinx -W -b html docs docs/_build/html
Without executing the gallery: add  -D plot_gallery=0 (the notebook, docs/notebook.ipynb,
is executed either way: it is short, and its figures are what it shows)
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

# the notebook's kernel is a subprocess: it documents this checkout too
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))

import ti_spinorbit  # noqa: E402

project = "ti_spinorbit"
author = "the ti_spinorbit authors"
copyright = "ti_spinorbit authors, MIT licence"
version = release = ti_spinorbit.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",                 # MyST Markdown (it loads myst_parser) and executed notebooks
    "sphinx_gallery.gen_gallery",
]

# .rst here; myst_nb registers .md (MyST Markdown) and .ipynb (notebooks) itself
source_suffix = {".rst": "restructuredtext"}
exclude_patterns = ["_build", "figures", "_intersphinx", "**.ipynb_checkpoints",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip"]
templates_path = ["_templates"]

# --- API reference ---------------------------------------------------------------------
autosummary_generate = True
autodoc_typehints = "none"             # the numpydoc "Parameters" sections carry the types
numpydoc_show_class_members = False    # result classes are dataclasses: fields are listed in
                                       # the class docstring, methods get their own entries
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- every cross-reference resolves -------------------------------------------------------
# nitpicky: a reference to a name that is documented nowhere (here or in an inventory below)
# is a warning, so an error under -W: the docs never show a dead `name`.
nitpicky = True

# --- intersphinx from local inventories ---------------------------------------------------
# Decision: the site is built where nothing but package registries can be reached (CI and the
# build machines have no other network), so intersphinx cannot download each project's
# objects.inv. docs/_intersphinx/ holds small inventories in Sphinx's own format instead,
# written by docs/_intersphinx/make_inventories.py: only the external names these docs refer
# to, each with its real address on that project's site, so the links go where the
# downloaded inventories would send them. A new external reference fails the nitpicky build
# until its name is added there (rerun the script, commit the .inv files).
_INVENTORIES = Path(__file__).resolve().parent / "_intersphinx"
intersphinx_mapping = {
    name: (url, str(_INVENTORIES / f"{name}.inv")) for name, url in {
        "python": "https://docs.python.org/3/",
        "numpy": "https://numpy.org/doc/stable/",
        "matplotlib": "https://matplotlib.org/stable/",
        "xarray": "https://docs.xarray.dev/en/stable/",
        "astropy": "https://docs.astropy.org/en/stable/",
        "dask": "https://docs.dask.org/en/stable/",
        "distributed": "https://distributed.dask.org/en/stable/",
    }.items()}

# --- Markdown pages (physics, design, Dask, install, ...) and the notebook -------------------
# GitHub's heading anchors (physics.html#67-section-coordinates-inertial-and-apsidal), down to ####
myst_heading_anchors = 4
# $...$ and $$...$$ math (GitHub renders the same), and amsmath environments (align, ...)
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_dmath_double_inline = True
# docs/notebook.ipynb is executed at every build (it is stored without outputs), in its
# folder, with the build's environment; a cell that fails fails the build
nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_execution_excludepatterns = ["auto_examples/*"]
# progress bars go to stderr: the page shows results, not bars
nb_output_stderr = "remove"

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
_PAGES = ("physics", "design", "dask", "statuses", "units", "cli", "install", "extending")
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


# --- references by a module path to an object documented under its public name ------------
# The docstrings name objects where they are defined (ti_spinorbit.output.io.save), the site
# documents them where users meet them (ti_spinorbit.save). A reference that Sphinx does not
# find is looked up as a Python object (from the referring module or class, then from the
# package's front) and, when that very object is documented under another name, linked there.
_documented = {}


def _lookup(dotted):
    import importlib

    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except Exception:
            continue
        try:
            for attr in parts[i:]:
                obj = getattr(obj, attr)
        except AttributeError:
            return None
        return obj
    return None


def _linkable(obj):
    """Objects whose identity names them: classes, functions, modules, properties, and the
    registries (dicts, tuples, ...) a module keeps; not numbers or strings."""
    import types

    return isinstance(obj, (type, types.FunctionType, types.ModuleType, property,
                            types.BuiltinFunctionType, dict, list, tuple, set, frozenset))


def _documented_objects(env):
    key = len(env.domains["py"].objects)
    if _documented.get("key") != key:
        found = {}
        for name, entry in env.domains["py"].objects.items():
            if entry.aliased:
                continue
            obj = _lookup(name)
            if obj is not None:
                # the shortest documented name wins: ti_spinorbit.save over a module's own
                if id(obj) not in found or len(name) < len(found[id(obj)][0]):
                    found[id(obj)] = (name, obj)
        _documented.update(key=key, names=found)
    return _documented["names"]


def _docstring_owner(node):
    """The object whose docstring holds ``node`` ("...: docstring of ti_spinorbit.x.f")."""
    while node is not None:
        source = getattr(node, "source", None) or ""
        if "docstring of " in source:
            return source.rsplit("docstring of ", 1)[1].strip()
        node = node.parent
    return None


def _candidates(node):
    """Where a name in a docstring may live: as written, in the referring class (and the
    modules of its bases: an inherited docstring names its own module's objects), in the
    referring module, around the object whose docstring it is, and in the package's
    front."""
    target = node["reftarget"].lstrip("~.")
    module, cls = node.get("py:module"), node.get("py:class")
    out = [target]
    owner = _docstring_owner(node)
    if owner:
        parts = owner.split(".")
        out += [".".join(parts[:i] + [target]) for i in range(len(parts), 1, -1)]
    if module and cls:
        out.append(f"{module}.{cls}.{target}")
        klass = _lookup(f"{module}.{cls}")
        for base in getattr(klass, "__mro__", ())[:-1]:
            out += [f"{base.__module__}.{base.__qualname__}.{target}",
                    f"{base.__module__}.{target}"]
    if module:
        out.append(f"{module}.{target}")
    out.append(f"ti_spinorbit.{target}")
    return out


def _resolve_by_object(app, env, node, contnode):
    if node.get("refdomain") != "py":
        return None
    names = _documented_objects(env)
    objects = env.domains["py"].objects
    candidates = _candidates(node)
    public = next((c for c in candidates if c in objects and c != node["reftarget"]), None)
    if public is None and not node["reftarget"].lstrip("~.").startswith("ti_spinorbit."):
        # a name (or Class.member) documented exactly once, wherever it is
        tail = "." + node["reftarget"].lstrip("~.")
        ends = [name for name in objects if name.endswith(tail)]
        public = ends[0] if len(ends) == 1 else None
    if public is not None:
        return env.domains["py"].resolve_xref(env, node["refdoc"], app.builder, "obj", public,
                                              node, contnode)
    for dotted in candidates:
        obj = _lookup(dotted)
        if obj is None or id(obj) not in names:
            continue
        public, known = names[id(obj)]
        if known is not obj or public == node["reftarget"]:
            continue
        # numbers and strings are not told apart by identity: the names must end alike
        if not _linkable(obj) and public.rsplit(".", 1)[-1] != dotted.rsplit(".", 1)[-1]:
            continue
        return env.domains["py"].resolve_xref(env, node["refdoc"], app.builder, "obj", public,
                                              node, contnode)
    return None


# --- pages completed from the code at build time (docs/cli.md, docs/statuses.md) -----------
# A marker line in the page's source is replaced by text generated from the code, so the
# command-line reference and the status tables cannot drift from what the package does.
def _cli_reference():
    """Every subcommand's --help, as the parser of ti_spinorbit.cli prints it."""
    import argparse

    from ti_spinorbit import cli

    columns = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "100"               # argparse wraps the help at this width
    try:
        parser = cli.common.PARSER()
        out = ["### `ti-spinorbit`", "", "```text", parser.format_help().rstrip(), "```", ""]
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        for name, subparser in sub.choices.items():
            out += [f"### `ti-spinorbit {name}`", "", "```text",
                    subparser.format_help().rstrip(), "```", ""]
    finally:
        if columns is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = columns
    return "\n".join(out)


def _table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(map(str, row)) + " |" for row in rows])


def _status_codes(source):
    """The code table of ti_spinorbit.Status; the page's own table of meanings must name
    every status, and nothing else (the build fails otherwise)."""
    from ti_spinorbit.engine.results import STATUS_NAMES, Status

    described = set(re.findall(r"^\| `([a-z -]+)` \|", source, flags=re.M))
    if described != set(STATUS_NAMES):
        raise RuntimeError(f"docs/statuses.md: the meanings table names {sorted(described)}, "
                           f"the package's statuses are {list(STATUS_NAMES)}")
    return _table(("code", "`tso.Status`", "`status_names` (text)"),
                  [(s.value, f"`Status.{s.name}`", f"`{s.label}`") for s in Status])


def _exit_codes(source):
    """The exit statuses of ti-spinorbit (ti_spinorbit.cli.common.EXIT_*); the page's own
    table of meanings must give every one, and nothing else."""
    from ti_spinorbit.cli import common

    codes = {name: getattr(common, name) for name in dir(common) if name.startswith("EXIT_")}
    described = set(int(c) for c in re.findall(r"^\| (\d+) \| ", source, flags=re.M))
    if described != set(codes.values()):
        raise RuntimeError(f"docs/statuses.md: the exit-status table gives {sorted(described)}, "
                           f"the command line's are {sorted(codes.values())}")
    return _table(("exit status", "name in `ti_spinorbit.cli`"),
                  [(v, f"`{k}`") for k, v in sorted(codes.items(), key=lambda kv: kv[1])])


def _result_units(source):
    """One table per result class: every field and its unit (the fields' own metadata)."""
    import dataclasses

    from ti_spinorbit.engine.results import KINDS, units

    out = []
    for kind, cls in sorted(KINDS.items()):
        if not dataclasses.is_dataclass(cls):
            continue
        public = f"ti_spinorbit.{cls.__name__}"
        name = public if getattr(ti_spinorbit, cls.__name__, None) is cls else \
            f"{cls.__module__}.{cls.__name__}"
        rows = [(f"`{field}`", unit.replace("|", "\\|"))
                for field, unit in units(cls).items() if "/" not in field]
        out += [f"**{{class}}`~{name}`** (archive kind `{kind}`)", "",
                _table(("field", "unit"), rows), ""]
    return "\n".join(out)


_GENERATED = {
    "<!-- generated: result-units -->": _result_units,
    "<!-- generated: cli-reference -->": lambda source: _cli_reference(),
    "<!-- generated: status-codes -->": _status_codes,
    "<!-- generated: exit-codes -->": _exit_codes,
}


def _complete_page(app, docname, source):
    original = source[0]          # each table checks the page as written, not as completed
    for marker, make in _GENERATED.items():
        if marker in original:
            source[0] = source[0].replace(marker, make(original))


def _notebook_backend(app):
    """The notebook runs in a Jupyter kernel, which shows figures inline unless MPLBACKEND
    says otherwise; the Agg this file sets for the gallery (run in this process at
    builder-inited, before any notebook) must not reach that kernel."""
    if os.environ.get("MPLBACKEND", "").lower() == "agg":
        os.environ.pop("MPLBACKEND")


def _start_taichi(app):
    """Start Taichi once, before sphinx-gallery runs the examples (when it does)."""
    if str(app.config.plot_gallery).lower() not in ("0", "false", "no", "off", ""):
        ti_spinorbit.init()


def setup(app):
    app.connect("autodoc-process-docstring", _plain_text, priority=600)
    app.connect("builder-inited", _start_taichi, priority=100)   # before the gallery (500)
    app.connect("builder-inited", _notebook_backend, priority=900)   # after the gallery
    app.connect("missing-reference", _resolve_by_object)
    app.connect("source-read", _complete_page)
