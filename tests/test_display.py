"""Readable reprs (ti_spinorbit.display): every system, body and result prints a few short
lines — never its arrays, however many members — and a small HTML table in notebooks.

Results come from tiny real runs (a 1024-member one-orbit section is about a second once the
kernels are cached; the others use 2-8 members and a few orbits)."""

import dataclasses

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import display

from conftest import lumpy_body

#: A repr must fit on a screen: at most this many lines and characters.
MAX_LINES = 6
MAX_CHARS = 400


@pytest.fixture(scope="module")
def big_section(vh):
    return tso.surface_of_section(vh, 0.0, np.linspace(0.5, 2.5, 1024), orbits=1)


#: fixture -> (class name, texts its repr must contain)
RESULTS = {
    "big_section": ("SectionResult", ["members 1024", "orbits 1", "rtol 1e-12", "'1991 VH'",
                                      "a/b 1.5", "e 0.05", "M_p/M_s", "P_orb 32.52 h",
                                      "status done", "coordinates inertial"]),
    "time_series": ("TimeSeriesResult", ["members 2", "orbits 2", "rtol 1e-09",
                                         "samples per member 16", "'1991 VH'", "status done"]),
    "chaos_map": ("ChaosMap", ["members 4", "orbits 3", "chaotic fraction 0 of 4 counted",
                               "threshold ⟨Y⟩ > 4", "grid θ_p × θ̇_p/n 2 × 2", "status done"]),
    "parameter_map": ("ParameterMap", ["members 8", "orbits 3", "'1991 VH'", "a/b 1.2–1.4",
                                       "e 0.05–0.1", "chaotic fraction", "ω0", "status done"]),
    "overlap_scan": ("OverlapScan", ["members 20", "rtol 1e-10", "'2004 DC'", "e 0.3",
                                     "a/b scanned 1.01–1.03 (2)", "lengths 5", "converged", "first overlap a/b",
                                     "analytic a/b at ω0^RO", "status (first run) done"]),
    "relaxed_libration": ("RelaxedLibration", ["members 1", "orbits 3", "'1991 VH'",
                                               "amplitude", "deg", "|ψ_A|", "status done",
                                               "converged no"]),
}


def assert_compact(text):
    assert len(text) <= MAX_CHARS, (len(text), text)
    assert len(text.splitlines()) <= MAX_LINES, text
    assert "array(" not in text and "[" not in text, text


@pytest.mark.parametrize("kind", list(RESULTS))
def test_result_repr_is_a_few_lines_naming_the_run(kind, request):
    result = request.getfixturevalue(kind)
    title, needles = RESULTS[kind]
    text = repr(result)
    assert_compact(text)
    assert text.startswith(f"<{title}>\n"), text
    for needle in needles:
        assert needle in text, (needle, text)


@pytest.mark.parametrize("kind", list(RESULTS))
def test_result_html_is_a_table_with_the_same_facts(kind, request):
    result = request.getfixturevalue(kind)
    page = result._repr_html_()
    title, _ = RESULTS[kind]
    assert isinstance(page, str)
    assert page.startswith("<table>") and page.endswith("</table>")
    assert f"<caption>{title}</caption>" in page
    # one row per fact of the text repr
    _, lines = display.summary(result)
    assert page.count("<tr>") == sum(len(line) for line in lines) >= 4


def test_a_1024_member_section_is_short_and_counts_statuses(big_section):
    """The dataclass default was 5 kB of arrays; the summary stays the same size at any N."""
    text = repr(big_section)
    assert len(text) < 400
    counts = big_section.status_counts
    assert sum(counts.values()) == 1024
    assert display.counts(counts) in text
    points = int(big_section.count.sum())
    assert f"section points {points}" in text
    assert str(big_section) == text               # print() shows the same


def test_status_counts_show_every_status_largest_first():
    assert display.counts({"inaccurate": 2, "done": 30, "collision": 1}) == \
        "done 30, inaccurate 2, collision 1"
    assert display.counts({}) == "none"


def test_system_repr_names_the_physics_with_units(vh):
    text = repr(vh)
    assert_compact(text)
    assert text.splitlines()[0] == "<BinarySystem '1991 VH'>"
    for needle in ("a/b 1.5", "e 0.05", f"M_p/M_s {vh.mass_ratio:.4g}",
                   f"ω0 {vh.omega0:.4g} n", f"P_orb {vh.orbital_period / 3600:.4g} h",
                   "a 3300 m", "primary sphere R 600 m", "secondary ellipsoid 293.9 × 196 × 190 m"):
        assert needle in text, (needle, text)
    assert "e+22" not in text and "integrals" not in text      # no inertia integrals dumped
    assert "primary spin period" not in text                   # none set
    page = vh._repr_html_()
    assert "<table>" in page and "M_p/M_s" in page and "P_orb" in page


def test_system_repr_shows_a_primary_spin_and_kilometres():
    system = tso.BinarySystem(tso.Ellipsoid(9000.0, 8000.0, 7000.0, 2000.0),
                              tso.Sphere(1000.0, 2000.0), a=40e3, e=0.1,
                              primary_spin_period=7200.0, name="big")
    text = repr(system)
    assert_compact(text)
    assert "primary spin period 2 h" in text
    assert "a 40 km" in text
    assert "primary ellipsoid 9000 × 8000 × 7000 m" in text
    assert "secondary sphere R 1000 m" in text
    assert "a/b 1," in text                                     # the secondary's (a sphere)


@pytest.mark.parametrize("make, needles", [
    (lambda: tso.Sphere(600.0, 1581.0, name="primary"),
     ["<Body 'primary'>", "sphere R 600 m", "density 1581 kg/m³", "bounding radius 600 m"]),
    (lambda: tso.Ellipsoid(245.0, 163.0, 190.0 - 30.0, mass=2.0e10, name="moon"),
     ["<Body 'moon'>", "ellipsoid 245 × 163 × 160 m", "mass 2e+10 kg"]),
])
def test_body_repr_gives_shape_mass_and_density(make, needles):
    text = repr(make())
    assert_compact(text)
    for needle in needles:
        assert needle in text, (needle, text)
    assert "<table>" in make()._repr_html_()


def test_general_body_repr_gives_its_equal_moment_ellipsoid(rng):
    body = lumpy_body(rng)
    text = repr(body)
    assert_compact(text)
    axes = [np.sqrt(5 * body.integral(*k) / body.mass) for k in ((2, 0, 0), (0, 2, 0), (0, 0, 2))]
    assert f"body ≈ {axes[0]:.4g} × {axes[1]:.4g} × {axes[2]:.4g} m" in text
    assert "odd integrals yes" in text
    assert "density" not in text                       # not a uniform body: no density claimed


def test_long_names_are_cut():
    system = tso.BinarySystem(tso.Sphere(600.0, 1581.0), tso.Sphere(100.0, 2000.0), a=3000.0,
                              e=0.0, name="x" * 500)
    text = repr(system)
    assert_compact(text)
    assert "x" * display.MAX_NAME not in text and "…" in text


def test_html_escapes_names():
    system = tso.BinarySystem(tso.Sphere(600.0, 1581.0), tso.Sphere(100.0, 2000.0), a=3000.0,
                              e=0.0, name="<b>&")
    page = system._repr_html_()
    assert "<b>" not in page and "&lt;b&gt;&amp;" in page


def test_a_result_over_several_systems_names_them_briefly(vh):
    others = [tso.catalog.system("1991 VH", elongation=q) for q in (1.1, 1.2, 1.3, 1.4)]
    section = tso.surface_of_section(others, 0.0, 1.0, orbits=1, rtol=1e-9)
    text = repr(section)
    assert_compact(text)
    assert "systems 4 ('1991 VH')," in text
    assert "a/b 1.1–1.4" in text


@pytest.mark.parametrize("kind", [k for k in RESULTS if k != "big_section"])
def test_a_loaded_result_prints_as_the_saved_one(kind, request, tmp_path):
    result = request.getfixturevalue(kind)
    loaded = tso.load(tso.save(result, tmp_path / f"{kind}.npz"))
    assert repr(loaded) == repr(result)
    assert loaded._repr_html_() == result._repr_html_()


def test_chaotic_fraction_says_how_many_members_it_counts(chaos_map):
    """Inaccurate members are left out of the fraction (unless included): the repr says so."""
    from ti_spinorbit.kernels.advance import INACCURATE

    status = chaos_map.status.copy()
    status.flat[0] = INACCURATE
    flagged = dataclasses.replace(chaos_map, status=status)
    text = repr(flagged)
    assert "of 3 counted" in text and "done 3, inaccurate 1" in text
    included = repr(dataclasses.replace(flagged, include_inaccurate=True))
    assert "of 4 counted" in included and "counts inaccurate yes" in included


def test_system_repr_says_when_densities_were_scaled_to_a_period():
    d = tso.catalog.system("Didymos")
    s = tso.BinarySystem(d.primary, d.secondary, a=d.a, e=d.e, orbital_period=11.0 * 3600)
    text = repr(s)
    assert "P_orb 11 h" in text and "scaled ×" in text and "to match P_orb" in text
    assert "scaled" not in repr(d)


# ---- helper results: classification, overlap decisions, conservation, status names --------

def assert_short(text, lines=MAX_LINES):
    assert len(text) <= MAX_CHARS, (len(text), text)
    assert len(text.splitlines()) <= lines, text
    assert "array(" not in text and "{" not in text, text


def test_classification_repr_counts_labels_not_arrays(big_section):
    """classify_section() printed ~200 lines of arrays; now members per label and ranges."""
    c = tso.classify_section(big_section)
    text = repr(c)
    assert_short(text)
    assert text.startswith("<SectionClassification>\n") and "members 1024" in text
    labels, n = np.unique(c.classification, return_counts=True)
    for label, k in zip(labels, n):
        assert f"{label} {k}" in text, (label, text)
    assert f"section points {display.span(c.count, 'g')}" in text
    page = c._repr_html_()
    assert page.startswith("<table><caption>SectionClassification</caption>")


def test_classification_names_its_resonances():
    c = SimpleClassification(["resonant", "resonant", "chaotic"], [1.0, 1.5, np.nan])
    text = repr(c)
    assert "resonances 1:1 (1), 3:2 (1)" in text and "resonant 2, chaotic 1" in text


def SimpleClassification(labels, p):
    from ti_spinorbit.studies.classify import SectionClassification

    n = len(labels)
    nan = np.full(n, np.nan)
    return SectionClassification(
        classification=np.array(labels, dtype=object),
        classification_geometric=np.array(labels, dtype=object), resonance_p=np.array(p),
        libration_centre_deg=nan, libration_half_extent_deg=nan, libration_centre_thetadot=nan,
        mean_thetadot=nan, largest_gap_deg=nan, order_ratio=np.array([0.05, 0.06, 0.6]),
        count=np.array([100, 100, 90]), megno=nan)


def test_overlap_decision_is_one_line_with_its_verdict(overlap_scan):
    d = overlap_scan.decisions[0]
    text = repr(d)
    assert "\n" not in text and len(text) <= 250, text
    assert text.startswith("<OverlapDecision a/b 1.01,") and text.endswith(">")
    assert f"ω0 {d.omega0:.4g} n" in text
    assert ("verdict overlap" if d.overlap else "verdict separate") in text
    assert f"inaccurate {d.inaccurate}" in text
    # the scan's list of decisions prints one line per decision
    assert repr(overlap_scan.decisions).count("<OverlapDecision") == 2
    assert len(repr(overlap_scan.decisions)) <= 2 * 250 + 4
    page = d._repr_html_()
    assert "<caption>OverlapDecision</caption>" in page and "1:1 centre" in page


def test_conservation_is_a_small_result_that_still_unpacks(time_series):
    c = time_series.conservation(1)
    text = repr(c)
    assert_short(text, lines=4)
    assert text.startswith("<Conservation>\n") and "member 1" in text
    assert f"samples {c.samples}" in text and "orbits" in text
    assert display.sci(c.energy_drift) in text and display.sci(c.angmom_drift) in text
    # the data stay reachable: attributes, the dict, the per-sample series, and the old pair
    numbers, (t, de, dl, parts) = c
    assert numbers == c.numbers and numbers["energy_drift"] == c.energy_drift == c["energy_drift"]
    assert c[0] == numbers and len(c) == 2
    assert t.shape == de.shape == dl.shape == parts["orbit"].shape == (c.samples,)
    assert c.energy_drift == float(np.max(np.abs(de)))
    assert "<caption>Conservation</caption>" in c._repr_html_()


def test_conservation_plot_draws_plot_conservation(time_series):
    import matplotlib.pyplot as plt

    c = time_series.conservation(0)
    ax = c.plot(title="member 0")
    try:
        fig = ax.figure
        assert len(fig.axes) == 2 and ax.get_title() == "member 0"
        assert len(ax.lines) >= 2 and len(ax.lines[0].get_xdata()) == c.samples
    finally:
        plt.close("all")


def test_a_spheres_spin_exchange_prints_as_zero(time_series):
    """1991 VH has a spherical primary: its spin energy exchange is round-off (1e-37 of
    |E0|) and prints as 0, while the data keep the computed value."""
    c = time_series.conservation(0)
    assert 0 < c.exchange_primary < 1e-20 and c.exchange_orbit > 1e-6
    assert "primary spin 0," in repr(c)
    assert display.sci(c.exchange_orbit) in repr(c)


def test_negligible_is_relative_to_the_values_beside_it():
    assert display.negligible([2.3e-3, 9.4e-37, 2.3e-3]) == [2.3e-3, 0.0, 2.3e-3]
    assert display.negligible([1e-13, 1e-14]) == [1e-13, 1e-14]     # alike: both kept
    assert display.negligible([5e-14, 1.0], scale=400.0) == [0.0, 1.0]
    nan = float("nan")
    kept = display.negligible([nan, 1e-30])
    assert np.isnan(kept[0]) and kept[1] == 1e-30                   # nothing to compare with
    assert display.sci(0.0) == "0" and display.sci(2.274e-3) == "2.274e-03"


def test_status_names_print_on_one_line(big_section):
    names = big_section.status_names
    assert names == ["done"] * 1024 and isinstance(names, list)    # still a plain list
    text = repr(names)
    assert "\n" not in text and len(text) < 120, text
    assert "1024 items: done 1024" in text
    mixed = display.Names(["done"] * 1020 + ["inaccurate"] * 4)
    assert repr(mixed) == ("['done', 'done', 'done', …, 'inaccurate', 'inaccurate'] "
                           "(1024 items: done 1020, inaccurate 4)")
    assert repr(display.Names(["done", "collision"])) == "['done', 'collision']"


def test_fields_print_a_description_without_dict_reprs():
    lines = display.fields({"name": "x", "primary": {"bounding_radius_m": 400.0,
                                                     "offset_m": [1.2e-14, -5e-15, 3e-14],
                                                     "semi_axes_m": [400.0, 400.0, 400.0]},
                            "rotation": [[1.0, -1.3e-14, 0.0], [1.3e-14, 1.0, 0.0],
                                         [0.0, 0.0, 1.0]],
                            "period_s": None, "e": 0.05000000001})
    text = "\n".join(lines)
    assert "{" not in text and "[" not in text, text
    assert "  offset_m" in text and "0 × 0 × 0" in text         # round-off of a 400 m body
    assert "400 × 400 × 400" in text and "(1, 0, 0), (0, 1, 0), (0, 0, 1)" in text
    assert "period_s                 —" in text and "e                        0.05" in text


# ---- the command line's summaries: tables and counts, never a dict/list repr -------------

def no_reprs(text):
    return "{" not in text and "[" not in text and "None" not in text and "array(" not in text


def test_systems_show_prints_a_table(capsys):
    from ti_spinorbit import cli

    assert cli.main(["systems", "--show", "Didymos (radar shape)"]) == 0
    out = capsys.readouterr().out
    assert no_reprs(out), out
    lines = out.splitlines()
    assert "primary" in lines and "secondary" in lines                 # nested blocks
    assert any(line.split()[:1] == ["mass_ratio"] for line in lines)
    offset = next(line for line in lines if line.strip().startswith("offset_m"))
    assert offset.split()[1:] == ["0", "×", "0", "×", "0"], offset       # 1e-14 m: round-off


def test_cli_summaries_count_statuses_and_zero_round_off(tmp_path, capsys):
    from ti_spinorbit import cli

    assert cli.main(["map", "--system", "1991 VH", "--grid", "2", "2", "--orbits", "3",
                     "--out", str(tmp_path / "m.png")]) == 0
    out = capsys.readouterr().out
    assert "statuses: done 4)" in out and no_reprs(out), out
    # 1991 VH has a spherical primary: its spin exchange is round-off and prints as 0
    assert cli.main(["energy", "--system", "1991 VH", "--orbits", "1", "--rtol", "1e-10",
                     "--max-drift", "1e-6", "--out", str(tmp_path / "e.png")]) == 0
    out = capsys.readouterr().out
    exchange = next(line for line in out.splitlines() if "largest exchange" in line)
    assert "primary spin 0," in exchange and "orbit 0," not in exchange, exchange
    assert no_reprs(out), out


def test_overlap_summary_says_none_in_words(tmp_path, capsys):
    from ti_spinorbit import cli

    assert cli.main(["overlap", "--system", "2004 DC", "--elongations", "1.01", "1.03", "0.02",
                     "--orbits", "5", "--max-orbits", "10", "--out", str(tmp_path / "o.png")]) \
        in (0, cli.EXIT_INACCURATE)
    out = capsys.readouterr().out
    first = out.splitlines()[0]
    assert first.startswith("2004 DC (e = 0.3): first overlap at a/b = "), first
    assert "None" not in out and "MEGNO criterion" in first
