"""One result protocol (ti_spinorbit.engine.results) and the figures people put in talks
(ti_spinorbit.output.plotting): every result kind has status_names, seconds, rtol, orbits, plot(),
save() and to_xarray(); units live on the fields; statuses are one IntEnum; entry points take
one ``system``; the old vocabulary still reads; figures carry the run in their titles, use
mathtext, and keep legends off the data.

Checks are on the returned Axes/Figure (texts, legends, colourbars), never on images. The
results are the cheap module fixtures of conftest (a few members, a few orbits)."""

import ast
import dataclasses
import inspect
import json
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.output import io, plotting
from ti_spinorbit.engine import results
from ti_spinorbit.studies.chaosmap import ChaosMap, ParameterMap
from ti_spinorbit.studies.libration import RelaxedLibration
from ti_spinorbit.studies.overlap import OverlapScan
from ti_spinorbit.studies.section import SectionResult, TimeSeriesResult

KINDS = {"section": SectionResult, "time_series": TimeSeriesResult, "chaos_map": ChaosMap,
         "parameter_map": ParameterMap, "overlap_scan": OverlapScan,
         "relaxed_libration": RelaxedLibration}
ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt
    plt.close("all")


def _plain(text):
    """Text outside mathtext ($...$)."""
    return re.sub(r"\$[^$]*\$", "", text)


# ---- the protocol -----------------------------------------------------------------------------
@pytest.mark.parametrize("kind", list(KINDS))
def test_every_result_has_the_protocol(kind, request, tmp_path):
    result = request.getfixturevalue(kind)
    assert isinstance(result, results.Result) and type(result) is KINDS[kind]
    names = result.status_names
    assert names and all(n in results.STATUS_NAMES for n in names)
    assert sum(result.status_counts.values()) == len(names)
    assert isinstance(result.seconds, float) and result.seconds > 0
    assert isinstance(result.rtol, float) and 0 < result.rtol < 1e-6
    # a float whatever number was passed (integer orbits=3 once came back as an int)
    assert type(result.orbits) is float and result.orbits > 0
    ax = result.plot()
    assert ax.figure is not None and ax.get_title()
    path = result.save(tmp_path / f"{kind}.npz")
    loaded = tso.load(path)
    assert type(loaded) is type(result)
    assert loaded.status_names == names and loaded.rtol == result.rtol
    assert loaded.orbits == result.orbits and loaded.seconds == result.seconds
    pytest.importorskip("xarray")
    ds = result.to_xarray()
    assert ds.attrs["kind"] == kind and ds.attrs["rtol"] == result.rtol
    assert all("units" in v.attrs for name, v in ds.data_vars.items())


@pytest.mark.parametrize("kind", list(KINDS))
def test_units_live_on_the_fields(kind, request, tmp_path):
    """io's units are the fields' metadata (plus the archive's own entries), and the file
    and the xarray dataset carry exactly those."""
    cls = KINDS[kind]
    declared = {f.name: f.metadata["unit"] for f in dataclasses.fields(cls) if "unit" in f.metadata}
    assert declared and results.units(cls) == {**declared, **{k: v for k, v in
                                                              results.units(cls).items() if "/" in k}}
    assert io.units(kind) == {**io.ARCHIVE_UNITS, **results.units(cls)}
    meta = io.read_metadata(request.getfixturevalue(kind).save(tmp_path / "r.npz"))
    for name, unit in declared.items():
        if name in meta["units"]:
            assert meta["units"][name] == unit, name


def test_overlap_decision_units_come_from_its_fields():
    assert results.units(OverlapScan)["decisions/centre_1"] == results.SPIN
    assert results.units(OverlapScan)["decisions/connecting_lyapunov"] == "1/orbit"


def test_io_does_not_import_xarray_io():
    """The data flow one way: xarray_io reads io; io imports neither xarray_io nor results'
    users at import time (an import loop)."""
    def imported(path):
        tree = ast.parse(path.read_text())
        names = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                names.update([node.module or ""] + [a.name for a in node.names])
            elif isinstance(node, ast.Import):
                names.update(a.name for a in node.names)
        return names

    assert not {"xarray_io", "to_xarray"} & imported(ROOT / "ti_spinorbit" / "output" / "io.py")
    assert "io" in imported(ROOT / "ti_spinorbit" / "output" / "xarray_io.py")
    assert not hasattr(io, "to_xarray")
    assert tso.to_xarray.__module__ == "ti_spinorbit.output.xarray_io"


def test_status_is_one_intenum_naming_every_code():
    assert tso.Status is results.Status
    assert [s.value for s in tso.Status] == list(range(len(results.STATUS_NAMES)))
    assert [s.label for s in tso.Status] == list(results.STATUS_NAMES)
    assert tso.Status.STEP_UNDERFLOW.label == "step underflow"
    assert tso.Status.STEP_BUDGET.label == "step budget"
    assert tso.Status.from_label("non-finite") is tso.Status.NONFINITE
    assert io.status_codes() == dict(enumerate(results.STATUS_NAMES))
    with pytest.raises(ValueError, match=r"^status must be one of running, done, .* \(got 'ok'\)$"):
        tso.Status.from_label("ok")


def test_relaxed_libration_status_names(relaxed_libration):
    """One trajectory, its status stored by name: the protocol still gives a list."""
    assert relaxed_libration.status_names == [relaxed_libration.status]
    assert relaxed_libration.status_counts == {relaxed_libration.status: 1}


def test_overlap_scan_rtol_and_status(overlap_scan):
    assert overlap_scan.rtol == overlap_scan.sections.rtol == 1e-10
    np.testing.assert_array_equal(overlap_scan.status, overlap_scan.sections.status)


# ---- one `system` argument, catalogue names everywhere ------------------------------------------
ENTRY_POINTS = ["surface_of_section", "time_series", "chaos_map", "parameter_map",
                "overlap_threshold", "relaxed_libration", "libration_amplitude"]


@pytest.mark.parametrize("name", ENTRY_POINTS)
def test_entry_points_take_system_first_and_the_two_option_objects(name):
    """system first; how to integrate and how to run as the two option objects (rtol and
    method also direct, keyword-only); no **kwargs to hide keywords in."""
    params = inspect.signature(getattr(tso, name)).parameters
    assert list(params)[0] == "system"
    for keyword in ("rtol", "method", "integrator", "run"):
        assert params[keyword].kind is inspect.Parameter.KEYWORD_ONLY, (name, keyword)
    assert not [p for p in params.values() if p.kind is inspect.Parameter.VAR_KEYWORD], name
    assert not {"checkpoint", "resume", "progress", "model", "window_orbits"} & set(params)


def test_catalogue_name_equals_the_system(vh):
    by_name = tso.chaos_map("1991 VH", [30.0], [0.8], orbits=2, fraction_orbits=())
    by_system = tso.chaos_map(vh, [30.0], [0.8], orbits=2, fraction_orbits=())
    np.testing.assert_array_equal(by_name.megno, by_system.megno)
    ts = tso.time_series(["1991 VH", vh], 0.0, 1.0, orbits=1, samples_per_orbit=4)
    np.testing.assert_array_equal(ts.thetadot[0], ts.thetadot[1])


def test_old_keyword_names_are_gone(vh):
    """0.1.0 is unreleased: the renamed keywords have no shims (an old name is an unknown
    keyword, refused in one line)."""
    with pytest.raises(TypeError, match="system_or_systems"):
        tso.surface_of_section(system_or_systems=vh, theta_p=0.0, thetadot_p=1.0, orbits=1)
    with pytest.raises(TypeError, match="center_tol"):
        tso.relaxed_libration(vh, center_tol=1e-3)


def test_multi_launch_checkpoints_resume_to_the_same_result(vh, tmp_path):
    """relaxed_libration checkpoints every launch in DIR/launch-kkk; resuming gives the same
    answer from the finished checkpoints."""
    kw = dict(orbits=2, candidates=np.linspace(0.2, 1.3, 7), zoom_candidates=5,
              max_iterations=1, samples_per_orbit=8, converge=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        first = tso.relaxed_libration(vh, **kw, run=tso.Run(checkpoint=tmp_path / "ck",
                                                            keep_checkpoint=True))
        launches = sorted(p.name for p in (tmp_path / "ck").iterdir())
        again = tso.relaxed_libration(vh, **kw,
                                      run=tso.Run(checkpoint=tmp_path / "ck", resume=True))
    assert launches[0] == "launch-000" and len(launches) >= 4
    assert again.centre_thetadot_p == first.centre_thetadot_p
    assert again.amplitude == first.amplitude


# ---- one vocabulary ------------------------------------------------------------------------------
def test_old_attribute_names_are_gone(chaos_map, parameter_map, overlap_scan,
                                      relaxed_libration):
    """No alias properties: one name per field (format-1 files are renamed on load)."""
    for result, old in ((chaos_map, "mean_spin"), (parameter_map, "labels"),
                        (overlap_scan.decisions[0], "center_1"),
                        (relaxed_libration, "center_thetadot_p")):
        assert not hasattr(result, old), old


def test_format_1_archives_with_old_names_load(chaos_map, tmp_path):
    """A file written before the vocabulary was unified (format 1: mean_spin) loads, with
    the field under its new name."""
    path = chaos_map.save(tmp_path / "new.npz", include_sections=False)
    with np.load(path) as d:
        arrays = {k: d[k] for k in d.files if k != "metadata"}
        meta = json.loads(str(d["metadata"]))
    arrays["mean_spin"] = arrays.pop("mean_thetadot")
    meta["arrays"] = ["mean_spin" if a == "mean_thetadot" else a for a in meta["arrays"]]
    meta["format_version"] = 1
    old = io.write_archive(tmp_path / "old.npz", arrays, meta)
    loaded = tso.load(old)
    np.testing.assert_array_equal(loaded.mean_thetadot, chaos_map.mean_thetadot)
    assert io.FORMAT_VERSION == 2 and 1 in io.READABLE_FORMAT_VERSIONS


def test_conservation_is_the_clis_energy_check(time_series):
    from ti_spinorbit.cli import energy_check

    numbers, (t, de, dl, parts) = time_series.conservation(1)
    assert numbers == energy_check(time_series, 1)[0]
    assert numbers["samples"] == len(t) == np.count_nonzero(np.isfinite(time_series.t[1]))
    assert numbers["energy_drift"] == np.max(np.abs(de)) < 1e-6
    assert set(parts) == {"orbit", "primary", "secondary"}
    with pytest.raises(ValueError, match=r"^member must be an integer in \[0, 1\] \(got 2\)$"):
        time_series.conservation(2)


# ---- figures -----------------------------------------------------------------------------------
def _all_texts(fig):
    return plotting.figure_texts(fig)


@pytest.mark.parametrize("kind", list(KINDS))
def test_titles_carry_the_run_and_labels_use_mathtext(kind, request):
    result = request.getfixturevalue(kind)
    ax = result.plot()
    title = ax.get_title()
    for part in ("a/b", "e = ", "orbits", "rtol"):
        assert part in title, (part, title)
    assert ("1991 VH" if kind not in ("overlap_scan",) else "2004 DC") in title
    assert plotting.raw_markup(ax.figure) == [], plotting.raw_markup(ax.figure)


def test_conservation_figure_title_and_labels(time_series):
    ax = time_series.plot_conservation(0)
    assert "1991 VH" in ax.get_title() and "rtol 1e-09" in ax.get_title()
    assert plotting.raw_markup(ax.figure) == []


def test_few_members_get_a_legend_outside_the_axes(section):
    ax = section.plot()
    fig = ax.figure
    legend = ax.get_legend()
    assert legend is not None and len(legend.get_texts()) == 2
    assert legend.get_texts()[0].get_text() == r"$\dot\theta_p(0)/n$ = 0.83"
    fig.canvas.draw()
    assert legend.get_window_extent().x0 >= ax.get_window_extent().x1   # not on the data
    assert len(fig.axes) == 1                                           # no colourbar


def test_many_members_get_a_colourbar_of_the_start(many):
    ax = many.plot()
    assert ax.get_legend() is None
    bars = [a for a in ax.figure.axes if a is not ax]
    assert len(bars) == 1 and bars[0].get_ylabel() == plotting.START_LABEL
    lo, hi = bars[0].get_ylim()
    assert (lo, hi) == pytest.approx((0.8, 1.9))


def test_classes_get_a_legend_of_the_classes(section):
    ax = section.plot(classes=["resonant", "chaotic"], legend_loc="below")
    legend = ax.get_legend()
    assert legend.get_title().get_text() == "class"
    assert [t.get_text() for t in legend.get_texts()] == ["resonant", "chaotic"]
    colours = [h.get_color() for h in legend.legend_handles]
    assert colours == [plotting.CLASS_COLORS["resonant"], plotting.CLASS_COLORS["chaotic"]]
    ax.figure.canvas.draw()
    assert legend.get_window_extent().y1 <= ax.get_window_extent().y0   # below the axes
    with pytest.raises(ValueError, match=r"^legend_loc must be 'right', 'below' or 'inside' "
                                         r"\(got 'top'\)$"):
        section.plot(classes=["resonant", "chaotic"], legend_loc="top")


def test_megno_colourbar_marks_at_least_8(chaos_map):
    ax = chaos_map.plot()
    bar = ax.figure.axes[-1]
    assert bar is not ax and bar.get_ylabel() == plotting.MEGNO_LABEL
    colorbar = ax.collections[0].colorbar
    assert colorbar.extend == "max"
    assert [t.get_text() for t in bar.get_yticklabels()][-1] == r"$\geq$8"
    ax = chaos_map.plot(quantity="classification")
    assert ax.get_legend().get_title().get_text() == "class"


def test_overlap_figure_shows_megno(overlap_scan):
    ax = overlap_scan.plot()
    twin = ax.megno_axes
    assert twin.get_ylabel() == plotting.MEGNO_LABEL
    line = twin.get_lines()[0]
    np.testing.assert_array_equal(line.get_xdata(), overlap_scan.elongations)
    np.testing.assert_array_equal(line.get_ydata(), plotting.overlap_megno(overlap_scan))
    assert np.all(np.isfinite(line.get_ydata()))
    assert r"largest $\langle Y\rangle$" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_relaxed_libration_plot_shows_alpha_amplitude_and_psi_band(relaxed_libration):
    ax = relaxed_libration.plot()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert r"$\alpha(t)$" in labels
    assert any(t.startswith(r"amplitude max $|\alpha|$") for t in labels)
    assert any(t.startswith(r"$|\psi_A|$ = ") for t in labels)
    band = [p for p in ax.patches if p.get_label().startswith(r"$|\psi_A|$")]
    assert len(band) == 1
    patch = band[0]           # a Rectangle (Matplotlib >= 3.9) or a Polygon
    ys = [patch.get_y(), patch.get_y() + patch.get_height()] if hasattr(patch, "get_height") \
        else np.asarray(patch.get_xy())[:, 1]
    assert (min(ys), max(ys)) == pytest.approx((-abs(relaxed_libration.psi_A),
                                                  abs(relaxed_libration.psi_A)))
    levels = sorted(line.get_ydata()[0] for line in ax.get_lines()
                    if line.get_linestyle() == "--")
    assert levels == pytest.approx([-relaxed_libration.amplitude, relaxed_libration.amplitude])
    assert len(ax.figure.axes) == 3          # α(t) and the search's two panels
    alpha = ax.get_lines()
    assert any(len(line.get_xdata()) == np.count_nonzero(np.isfinite(relaxed_libration.series.t[0]))
               for line in alpha)


def test_time_series_plot(time_series):
    ax = time_series.plot()
    assert len(ax.get_lines()) == 2
    assert ax.get_ylabel().startswith(r"$\dot\theta/n$")
    with pytest.raises(ValueError, match=r"^quantity must be one of thetadot, alpha, theta, r"):
        time_series.plot(quantity="energy")


def test_raw_markup_is_found():
    plt = plotting._pyplot()
    fig, ax = plt.subplots()
    ax.set_xlabel(r"$\theta_p$ (deg)")
    ax.set_ylabel("theta_p")
    ax.set_title("ω0^RO")
    assert sorted(plotting.raw_markup(fig)) == ["theta_p", "ω0^RO"]


def test_a_loaded_overlap_scan_answers_as_the_fresh_one(tmp_path):
    """No hidden state: a scan whose longer lengths integrated only some elongations plots
    the same largest ⟨Y⟩ per elongation after save and load (each decision keeps it)."""
    from ti_spinorbit.output.plotting import overlap_megno

    scan = tso.overlap_threshold("1991 VH", elongations=[1.02, 1.3], orbits=4, max_orbits=8,
                                 centre_starts=4, separatrix_starts=4, rtol=1e-8,
                                 run=tso.Run(progress=False))
    assert not [k for k in vars(scan) if k.startswith("_")]
    tso.save(scan, tmp_path / "scan.npz")
    loaded = tso.load(tmp_path / "scan.npz")
    fresh = overlap_megno(scan)
    np.testing.assert_array_equal(overlap_megno(loaded), fresh)
    assert loaded.evidence() == scan.evidence() and repr(loaded) == repr(scan)
    # each value is the largest finite <Y> of its elongation's block in its decision's run
    assert np.all(np.isfinite(fresh)) and np.all(fresh >= 0)
    first, block = scan.section_block(0)
    if scan.decisions[0].orbits == scan.lengths[0]:
        assert fresh[0] == np.nanmax(first.megno[block])


def test_a_result_kind_is_declared_once_and_archives_read_it(tmp_path):
    """A new result class needs no entry in io: its class statement registers the kind,
    save and load work, and its SHAPES guard loading; a kind taken twice is refused."""
    from ti_spinorbit.engine.results import FLOAT, KINDS, Result, unit

    @dataclasses.dataclass(repr=False)
    class Toy(Result, kind="toy_result"):
        SHAPES = {"values": (("n",), FLOAT)}
        values: np.ndarray = unit("deg")
        orbits: float = unit("orbital periods", default=1.0)

    try:
        assert KINDS["toy_result"] is Toy and Toy.kind == "toy_result"
        toy = Toy(values=np.array([1.0, 2.5]))
        tso.save(toy, tmp_path / "toy.npz")
        back = tso.load(tmp_path / "toy.npz")
        assert type(back) is Toy
        np.testing.assert_array_equal(back.values, toy.values)
        with pytest.raises(TypeError, match="result kind 'toy_result' is already Toy's"):
            class Other(Result, kind="toy_result"):
                pass
        bad = Toy(values=np.array([[1.0]]))          # against its SHAPES
        tso.save(bad, tmp_path / "bad.npz")
        with pytest.raises(tso.output.io.ArchiveError, match="'values' has shape"):
            tso.load(tmp_path / "bad.npz")
    finally:
        KINDS.pop("toy_result", None)
