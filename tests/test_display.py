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
