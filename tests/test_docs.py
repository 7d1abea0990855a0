"""The documentation site builds with warnings as errors and every cross-reference resolved
(``nitpicky``, intersphinx from the inventories in docs/_intersphinx/), quickly: the
gallery's pages are generated but its examples are not executed (``-D plot_gallery=0``; CI's
full build in .ci/run executes them), while the notebook (docs/notebook.ipynb, tiny runs) is
executed and must show every figure. The build runs on a copy of docs/ and examples/ in a
temporary folder, so the checkout gains no generated files."""

import importlib.util
import os
import re
import shutil
import subprocess
import sys

import pytest

import ti_spinorbit as tso

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOLS = ["sphinx", "numpydoc", "pydata_sphinx_theme", "sphinx_gallery", "myst_parser", "myst_nb",
         "ipykernel"]
MISSING = [name for name in TOOLS if importlib.util.find_spec(name) is None]
GENERATED = ("_build", "auto_examples", "generated", "sg_execution_times.rst")

# the slow part of the suite (deselect with -m "not slow", README, its first lines); skipped without
# the documentation tools
pytestmark = [pytest.mark.slow, pytest.mark.skipif(
    bool(MISSING), reason=f"documentation tools not installed ({', '.join(MISSING)}): "
                          'pip install -e ".[docs]"')]


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """Build the site once for this module; the HTML folder."""
    tmp = tmp_path_factory.mktemp("docs")
    shutil.copytree(os.path.join(ROOT, "docs"), tmp / "docs",
                    ignore=shutil.ignore_patterns(*GENERATED))
    shutil.copytree(os.path.join(ROOT, "examples"), tmp / "examples")
    env = {**os.environ, "MPLBACKEND": "Agg",
           # document this checkout's package, whatever else is installed
           "PYTHONPATH": os.pathsep.join(filter(None, [ROOT, os.environ.get("PYTHONPATH")]))}
    out = tmp / "html"
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q",
                           "-b", "html", "-D", "plot_gallery=0", str(tmp / "docs"), str(out)],
                          cwd=tmp, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"sphinx -W failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-6000:]}"
    return out


def test_the_site_builds_with_warnings_as_errors(site):
    index = (site / "index.html").read_text(encoding="utf-8")
    for page in ("auto_examples/index.html", "api/index.html", "physics.html", "design.html",
                 "dask.html", "install.html", "notebook.html", "cli.html", "statuses.html",
                 "units.html", "extending.html"):
        assert (site / page).is_file(), page
        assert f'href="{page}"' in index, f"the index does not link {page}"


def test_every_public_name_has_an_api_page(site):
    """Everything in ti_spinorbit.__all__ (a name added there needs a line in
    docs/api/index.rst)."""
    missing = [name for name in tso.__all__ if name != "__version__"
               and not (site / "api" / "generated" / f"ti_spinorbit.{name}.html").is_file()]
    assert not missing, f"add to docs/api/index.rst: {missing}"


def test_every_example_is_in_the_gallery(site):
    examples = sorted(f[:-3] for f in os.listdir(os.path.join(ROOT, "examples"))
                      if re.fullmatch(r"plot_\w+\.py", f))
    assert len(examples) >= 5
    gallery = (site / "auto_examples" / "index.html").read_text(encoding="utf-8")
    for name in examples:
        assert (site / "auto_examples" / f"{name}.html").is_file(), name
        assert f"{name}.html" in gallery, name


def test_the_markdown_pages_keep_their_numbered_sections(site):
    """MyST renders docs/physics.md with its headings (the docstrings cite "§N")."""
    physics = (site / "physics.html").read_text(encoding="utf-8")
    assert "6.7 Section coordinates: inertial and apsidal" in physics
    assert 'id="units-frames-and-sign-conventions"' in physics
    # formulas are math (MyST dollarmath/amsmath, rendered by MathJax), not code blocks:
    # the order-N series, the polyhedron integral and the Sun's tidal acceleration among them
    assert physics.count('class="math notranslate nohighlight"') >= 50
    for formula in (r"U_N = -G \sum", r"\int_\mathrm{tet} x^\alpha", r"\mathbf a_\odot = G M_\odot"):
        assert formula in physics, formula


def test_docstring_citations_link_to_sections_that_exist(site):
    """"docs/physics.md §8.6" in a docstring becomes a link to that heading's anchor
    (docs/conf.py); every such link on the site lands on an id of the page it names."""
    ids, links, broken = {}, 0, []
    for page in site.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        for href in re.findall(r'href="([^":]*(?:physics|design|dask)\.html#[^"]+)"', text):
            path, anchor = href.split("#", 1)
            target = (page.parent / path).resolve()
            if target not in ids:
                ids[target] = set(re.findall(r'id="([^"]+)"', target.read_text(encoding="utf-8")))
            links += 1
            if anchor not in ids[target]:
                broken.append(f"{page.relative_to(site)}: {href}")
    assert not broken, broken[:10]
    surface = (site / "api" / "generated" / "ti_spinorbit.surface_of_section.html").read_text(
        encoding="utf-8")
    assert 'href="../../physics.html#67-section-coordinates-inertial-and-apsidal"' in surface
    assert links > 20


def test_the_configuration_is_nitpicky_with_local_inventories():
    """-W makes every unresolved reference an error only when nitpicky is on; the
    inventories are local files (no network where the site is built), and the script that
    writes them reproduces them byte for byte."""
    conf = open(os.path.join(ROOT, "docs", "conf.py"), encoding="utf-8").read()
    assert re.search(r"^nitpicky = True$", conf, flags=re.M)
    spec = importlib.util.spec_from_file_location(
        "make_inventories", os.path.join(ROOT, "docs", "_intersphinx", "make_inventories.py"))
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    for project in ("python", "numpy", "matplotlib", "xarray", "astropy", "dask"):
        path = os.path.join(ROOT, "docs", "_intersphinx", f"{project}.inv")
        root, version, entries = make.NAMES[project]
        assert open(path, "rb").read() == make.inventory(project, version, entries), project
        assert f'"{project}": "{root}"' in conf, project


def test_the_notebook_shows_every_figure(site):
    """docs/notebook.ipynb is executed by the build in a Jupyter kernel without a display:
    one image per plotting cell (four .plot() calls or figures of the user's own)."""
    import json

    nb = json.load(open(os.path.join(ROOT, "docs", "notebook.ipynb"), encoding="utf-8"))
    plotting = [c for c in nb["cells"] if c["cell_type"] == "code"
                and re.search(r"\.plot\(|plt\.subplots", "".join(c["source"]))]
    assert len(plotting) >= 4
    assert all(not c.get("outputs") for c in nb["cells"] if c["cell_type"] == "code"), \
        "store the notebook without outputs: the build executes it"
    page = (site / "notebook.html").read_text(encoding="utf-8")
    images = re.findall(r'<img[^>]+src="([^"]+\.png)"', page)
    assert len(images) >= len(plotting), images
    for src in images:
        assert (site / src).is_file(), src
    assert "Traceback" not in page


def test_the_command_line_page_is_the_parser_help(site):
    from ti_spinorbit.cli import COMMANDS

    page = (site / "cli.html").read_text(encoding="utf-8")
    for command in COMMANDS:
        assert f"usage: ti-spinorbit {command.NAME}" in page, command.NAME
    assert "--max-drift" in page and "--checkpoint" in page


def test_the_status_tables_come_from_the_code(site):
    from ti_spinorbit.cli import common

    page = (site / "statuses.html").read_text(encoding="utf-8")
    for status in tso.Status:
        assert f"Status.{status.name}" in page and status.label in page, status
    for name in ("EXIT_OK", "EXIT_CHECK_FAILED", "EXIT_ERROR", "EXIT_INACCURATE",
                 "EXIT_INTERRUPTED"):
        assert name in page and hasattr(common, name), name


def test_the_plot_options_are_documented(site):
    """Every result's .plot(**options) forwards to a plot_* function with its own page."""
    from ti_spinorbit.engine.results import FIGURES

    functions = {f.__name__ for f in FIGURES.values()}
    assert functions
    for name in functions:
        page = site / "api" / "generated" / f"ti_spinorbit.output.plotting.{name}.html"
        assert page.is_file(), f"add output.plotting.{name} to docs/api/index.rst"


def test_no_private_name_in_the_api_pages(site):
    """A private module (ti_spinorbit._validate, ...) is named in no page of the API
    reference: the pages say what the bound is, not where it is kept."""
    leaks = []
    for page in (site / "api").rglob("*.html"):
        text = re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8"))
        leaks += [f"{page.name}: {text[max(0, m.start() - 40):m.end() + 20]!r}"
                  for m in re.finditer(r"\b_validate\b", text)]
    assert not leaks, leaks[:10]
