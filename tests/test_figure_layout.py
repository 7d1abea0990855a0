"""Figures that look right wherever they end up: every ``plot_*`` of
ti_spinorbit.output.plotting, drawn on the cheap results of conftest (a few members, a few
orbits) and saved with a plain ``fig.savefig(path)`` (no ``bbox_inches="tight"``, as a script
or the documentation gallery saves them), keeps every legend and every text inside the
image, writes legends in at least 8 pt, and has no panel (with its labels, ticks, title and
legend) overlapping another.

The checks measure the drawn figure with its renderer (window extents in pixels); a
half-pixel tolerance allows for rounding of extents, nothing more. A figure that breaks the
rules (an outside legend on a figure without a layout engine) is shown to fail them, so the
checks can fail."""

import ast
import warnings
from pathlib import Path

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.output import plotting

ROOT = Path(__file__).resolve().parent.parent
#: Pixels by which one extent may pass another (rounding of extents to the pixel grid).
TOL = 0.5


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt
    plt.close("all")


@pytest.fixture(scope="module")
def many_series(vh):
    return tso.time_series(vh, 0.0, np.linspace(0.8, 1.9, 12), orbits=1, samples_per_orbit=8,
                           rtol=1e-9)


# ---- the measurements ------------------------------------------------------------------------
def _inside(box, outer, tol=TOL):
    return (box.x0 >= outer.x0 - tol and box.y0 >= outer.y0 - tol
            and box.x1 <= outer.x1 + tol and box.y1 <= outer.y1 + tol)


def _overlap(a, b, tol=TOL):
    """True when two boxes share an area wider and taller than ``tol`` pixels."""
    return (min(a.x1, b.x1) - max(a.x0, b.x0) > tol) and (min(a.y1, b.y1) - max(a.y0, b.y0) > tol)


def _legends(fig):
    return [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)


def _panels(fig):
    """The figure's Axes without twins (a twin shares its host's place on purpose)."""
    panels = []
    for ax in fig.axes:
        if not any(np.allclose(ax.get_position().bounds, p.get_position().bounds)
                   for p in panels):
            panels.append(ax)
    return panels


def _texts(fig):
    """Every visible, non-empty text that is drawn, with its window extent: titles, axis
    labels, legend texts and titles, colourbar labels, and the tick labels that are drawn
    (those of ticks inside the view; matplotlib keeps Text objects for the others too)."""
    from matplotlib.text import Text

    renderer = fig.canvas.get_renderer()
    ticks, drawn = set(), []
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            span = hi - lo
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                labels = (tick.label1, tick.label2)
                ticks.update(map(id, labels))
                if lo - 1e-9 * span <= tick.get_loc() <= hi + 1e-9 * span:
                    drawn += [t for t in labels if t.get_visible()]
    out = []
    for t in fig.findobj(Text):
        if id(t) in ticks:
            continue
        if t.axes is not None and t.get_transform().contains_branch(t.axes.transData):
            continue                         # placed on the data (contour labels): not layout
        if t.get_visible():
            drawn.append(t)
    for t in drawn:
        if not t.get_text().strip():
            continue
        box = t.get_window_extent(renderer)
        if box.width > 0 and box.height > 0:
            out.append((t, box))
    return out


def layout_problems(fig, path):
    """Save ``fig`` with a plain ``savefig`` and list what is wrong with the image."""
    import matplotlib.image

    fig.savefig(path)
    problems = []
    height, width = matplotlib.image.imread(path).shape[:2]
    expected = (round(fig.get_figheight() * fig.dpi), round(fig.get_figwidth() * fig.dpi))
    if (height, width) != expected:
        problems.append(f"image {width}x{height} px, figure {expected[1]}x{expected[0]} px")
    renderer = fig.canvas.get_renderer()
    frame = fig.bbox
    texts_drawn = _texts(fig)
    for t, box in texts_drawn:
        if not _inside(box, frame):
            problems.append(f"text {t.get_text()!r} outside the image: {box.bounds}")
    for legend in _legends(fig):
        box = legend.get_window_extent(renderer)
        if not _inside(box, frame):
            problems.append(f"legend outside the image: {box.bounds} not in {frame.bounds}")
        texts = [t for t in legend.get_texts() if t.get_text()]
        if legend.get_title().get_text():
            texts.append(legend.get_title())
        small = [(t.get_text(), t.get_fontsize()) for t in texts if t.get_fontsize() < 8]
        if small:
            problems.append(f"legend texts under 8 pt: {small}")
        own = {id(t) for t in legend.get_texts()} | {id(legend.get_title())}
        for t, other in texts_drawn:
            if id(t) not in own and _overlap(box, other):
                problems.append(f"legend over the text {t.get_text()!r}: {box.bounds} and "
                                f"{other.bounds}")
    panels = _panels(fig)
    boxes = [ax.get_tightbbox(renderer) for ax in panels]
    for i in range(len(panels)):
        for j in range(i + 1, len(panels)):
            if _overlap(boxes[i], boxes[j]):
                problems.append(f"panels {i} and {j} overlap: {boxes[i].bounds} and "
                                f"{boxes[j].bounds}")
    return problems


def _check(ax, tmp_path, name, legends=None):
    fig = ax.figure
    assert fig.get_layout_engine() is not None, "the package's figures are laid out"
    problems = layout_problems(fig, tmp_path / f"{name}.png")
    assert problems == [], "\n".join(problems)
    if legends is not None:
        assert len(_legends(fig)) == legends
    return fig


# ---- every figure of the package ------------------------------------------------------------
def test_section_legend_right(section, tmp_path):
    ax = section.plot()
    fig = _check(ax, tmp_path, "section", legends=1)
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    assert legend.x0 >= ax.get_window_extent(renderer).x1 - TOL      # off the data


@pytest.mark.parametrize("where", ["right", "below", "inside"])
def test_section_class_legend(section, tmp_path, where):
    ax = section.plot(classes=["resonant", "chaotic"], legend_loc=where)
    fig = _check(ax, tmp_path, f"classes_{where}", legends=1)
    renderer = fig.canvas.get_renderer()
    legend, data = ax.get_legend().get_window_extent(renderer), ax.get_window_extent(renderer)
    if where == "right":
        assert legend.x0 >= data.x1 - TOL
    elif where == "below":           # under the x label, not on it (checked above) nor the data
        assert legend.y1 <= ax.xaxis.get_tightbbox(renderer).y0 + TOL
    else:
        assert _inside(legend, data)
    assert ax.get_legend().get_title().get_fontsize() >= 8


def test_section_colourbar(many, tmp_path):
    ax = many.plot()
    fig = _check(ax, tmp_path, "many", legends=0)
    assert len(fig.axes) == 2                                        # axes and colourbar


def test_time_series(time_series, tmp_path):
    ax = time_series.plot()
    fig = _check(ax, tmp_path, "time_series", legends=1)
    renderer = fig.canvas.get_renderer()
    assert ax.get_legend().get_window_extent(renderer).x0 >= \
        ax.get_window_extent(renderer).x1 - TOL
    assert [t.get_fontsize() for t in ax.get_legend().get_texts()] == [8.0, 8.0]


def test_time_series_colourbar(many_series, tmp_path):
    _check(many_series.plot(quantity="alpha"), tmp_path, "many_series", legends=0)


def test_conservation(time_series, tmp_path):
    top = time_series.plot_conservation(0)
    fig = _check(top, tmp_path, "conservation", legends=2)
    assert len(_panels(fig)) == 2


@pytest.mark.parametrize("quantity", ["megno", "lyapunov", "classification"])
def test_chaos_map(chaos_map, tmp_path, quantity):
    ax = chaos_map.plot(quantity=quantity, overlay=True)
    _check(ax, tmp_path, f"chaos_map_{quantity}", legends=int(quantity == "classification"))


def test_parameter_map(parameter_map, tmp_path):
    _check(parameter_map.plot(), tmp_path, "parameter_map", legends=1)


def test_overlap(overlap_scan, tmp_path):
    ax = overlap_scan.plot()
    fig = _check(ax, tmp_path, "overlap", legends=1)
    assert len(fig.axes) == 2 and len(_panels(fig)) == 1             # the ⟨Y⟩ axis is a twin


def test_libration_three_panels(relaxed_libration, tmp_path):
    """The α(t) panel's legend (below it, two columns) stays off the search panels."""
    ax = relaxed_libration.plot()
    fig = _check(ax, tmp_path, "libration", legends=2)
    assert len(_panels(fig)) == 3
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    for other in fig.axes[1:]:
        assert not _overlap(legend, other.get_tightbbox(renderer))
    assert legend.y1 <= ax.xaxis.get_tightbbox(renderer).y0 + TOL


@pytest.mark.parametrize("where", ["right", "inside"])
def test_libration_legend_elsewhere(relaxed_libration, tmp_path, where):
    ax = plotting.plot_libration(relaxed_libration, legend_loc=where)
    _check(ax, tmp_path, f"libration_{where}", legends=2)


def test_libration_alone_and_search(relaxed_libration, tmp_path):
    _check(relaxed_libration.plot(search=False), tmp_path, "libration_alone", legends=1)
    _check(plotting.plot_libration_search(relaxed_libration), tmp_path, "search", legends=1)


def test_long_titles_are_broken_to_fit(section, tmp_path):
    """A title wider than its axes comes in lines, broken after commas, each line no wider
    than the axes was when the title was set."""
    title = ", ".join(["a long part of a run title"] * 8) + ": what it shows"
    ax = section.plot(title=title)
    width = ax.figure.get_figwidth() * 72.0 * ax.get_position().width     # before the layout
    lines = ax.get_title().split("\n")
    _check(ax, tmp_path, "long_title")
    assert len(lines) >= 3 and " ".join(lines) == title
    assert all(line.endswith((",", ":")) for line in lines[:-1])
    assert all(plotting._text_width_points(line, 9) <= width for line in lines)


def test_title_lines_never_split_mathtext():
    plt = plotting._pyplot()
    fig, ax = plt.subplots(figsize=(2.0, 2.0))
    title = r"a, b, c, $x, y, z$, d, e, f, g, h, i, j, k"
    plotting._title(ax, title)
    lines = ax.get_title().split("\n")
    assert len(lines) > 1
    assert all(line.count("$") % 2 == 0 for line in lines)
    assert " ".join(lines) == title


def test_your_own_constrained_figure_with_two_panels(section, time_series, tmp_path):
    """Both figures side by side on a figure of one's own, in constrained layout as the
    gallery makes them: legends kept, panels apart."""
    plt = plotting._pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4), layout="constrained")
    section.plot(ax=left)
    time_series.plot(ax=right)
    problems = layout_problems(fig, tmp_path / "two.png")
    assert problems == [], "\n".join(problems)


def test_save_figure_keeps_the_size_of_a_laid_out_figure(time_series, tmp_path):
    """The command line's writer saves the package's figures as laid out (no cropping)."""
    import matplotlib.image

    ax = time_series.plot()
    w, h = ax.figure.get_figwidth(), ax.figure.get_figheight()
    path = plotting.save_figure(ax, tmp_path / "ts.png")
    assert matplotlib.image.imread(path).shape[:2] == (round(h * 150), round(w * 150))


# ---- the checks can fail ---------------------------------------------------------------------
def test_checks_catch_a_clipped_legend_and_small_fonts(tmp_path):
    plt = plotting._pyplot()
    fig, ax = plt.subplots(figsize=(4, 3))                   # no layout engine
    ax.plot([0, 1], label="a line whose legend sits outside the axes")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=6)
    problems = layout_problems(fig, tmp_path / "clipped.png")
    assert any(p.startswith("legend outside the image") for p in problems)
    assert any(p.startswith("legend texts under 8 pt") for p in problems)


def test_checks_catch_overlapping_panels(tmp_path):
    plt = plotting._pyplot()
    fig = plt.figure(figsize=(4, 3))
    fig.add_axes((0.1, 0.1, 0.5, 0.5)).set_title("one")
    fig.add_axes((0.4, 0.4, 0.5, 0.5)).set_title("two")
    problems = layout_problems(fig, tmp_path / "overlap.png")
    assert any(p.startswith("panels 0 and 1 overlap") for p in problems)


# ---- the library never picks a backend; the gallery's figures are laid out ---------------------
def test_no_backend_switch_in_the_library():
    """Only the command line may call matplotlib.use (cli/common.choose_backend): a library
    that switches the backend turns a notebook's inline figures off for the whole kernel."""
    found = []
    for path in sorted((ROOT / "ti_spinorbit").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr in ("use", "switch_backend"):
                owner = node.func.value
                name = getattr(owner, "id", getattr(owner, "attr", ""))
                if name in ("matplotlib", "mpl", "plt", "pyplot"):
                    found.append(str(path.relative_to(ROOT)))
    assert found == ["ti_spinorbit/cli/common.py"]


def test_importing_plotting_and_drawing_keeps_the_backend(section):
    import matplotlib

    before = matplotlib.get_backend()
    section.plot()
    assert matplotlib.get_backend() == before


def _calls(tree, name):
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and getattr(n.func, "attr", getattr(n.func, "id", None)) == name]


@pytest.mark.parametrize("path", sorted((ROOT / "examples").glob("plot_*.py")),
                         ids=lambda p: p.name)
def test_gallery_figures_use_constrained_layout(path):
    """The gallery saves its figures with a plain savefig: every figure an example makes is
    in constrained layout, and none relies on tight_layout or bbox_inches."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    made = _calls(tree, "subplots") + _calls(tree, "figure")
    assert made, "each example draws a figure"
    for call in made:
        layout = {k.arg: k.value for k in call.keywords}.get("layout")
        assert isinstance(layout, ast.Constant) and layout.value == "constrained", \
            f"{path.name}, line {call.lineno}: layout='constrained' missing"
    assert not _calls(tree, "tight_layout")
    assert "bbox_inches" not in path.read_text(encoding="utf-8")


def test_gallery_example_2_keeps_its_legend(vh, tmp_path):
    """Gallery example 2's figure as the example makes it (a constrained figure of one's own,
    a section with a legend right of the axes), on a shorter run."""
    plt = plotting._pyplot()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sos = tso.surface_of_section(vh, theta_p=0.0, thetadot_p=np.linspace(0.6, 1.6, 8),
                                     orbits=2, rtol=1e-9)
    fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
    sos.plot(ax=ax)
    problems = layout_problems(fig, tmp_path / "example2.png")
    assert problems == [], "\n".join(problems)
    assert len(ax.get_legend().get_texts()) == 8
