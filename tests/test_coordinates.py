"""Section coordinates, inertial and apsidal (docs/physics.md §6.7; ti_spinorbit.model.coordinates).

Every check has an independent route: the Kepler identities, Gauss's planetary equation for
the argument of pericentre, the NumPy reference potential, finite differences of the apsidal
angle along a dense trajectory, and the same trajectory recorded in both coordinates."""

import json
import math
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import coordinates as C
from ti_spinorbit.model import reference
from ti_spinorbit.studies.classify import classify_section
from ti_spinorbit.engine.members import Members
from ti_spinorbit.engine.evaluation import apsidal_rates

from conftest import run_cli


def kepler_state(e, f, a=1.0, mu=1.0, varpi=0.0):
    """Position and velocity on a Kepler orbit (planar, pericentre at longitude varpi)."""
    p = a * (1.0 - e * e)
    r = p / (1.0 + e * math.cos(f))
    u = f + varpi
    R = r * np.array([math.cos(u), math.sin(u), 0.0])
    vr = math.sqrt(mu / p) * e * math.sin(f)
    vt = math.sqrt(mu / p) * (1.0 + e * math.cos(f))
    V = vr * R / r + vt * np.array([-math.sin(u), math.cos(u), 0.0])
    return R, V


# ---- exact identities of the osculating orbit (pure NumPy) -----------------------------

@pytest.mark.parametrize("e", [0.001, 0.05, 0.3, 0.9])
def test_rv_vanishes_exactly_at_osculating_pericentre(e):
    """R·V = (r/h) μ e sin f: R·V = 0 with R·V rising is exactly f = 0 (the section event)."""
    for f in np.linspace(-3.0, 3.0, 13):
        R, V = kepler_state(e, f, varpi=0.7)
        h = np.linalg.norm(np.cross(R, V))
        assert np.dot(R, V) == pytest.approx(np.linalg.norm(R) / h * e * math.sin(f), abs=1e-14)
        assert C.true_anomaly(R, V)[0] == pytest.approx(f, abs=1e-12)
    # and the eccentricity vector points at pericentre, with length e
    evec = C.eccentricity_vector(*kepler_state(e, 1.0, varpi=0.7))[0]
    np.testing.assert_allclose(evec, e * np.array([math.cos(0.7), math.sin(0.7), 0.0]),
                               atol=1e-14)


@pytest.mark.parametrize("model", ["planar", "3d"])
def test_recorded_pericentre_passages_are_osculating_f_zero(model):
    """The integrator's events (R·V = 0 rising, located by Newton on Cash-Karp sub-steps)
    are at osculating true anomaly 0 to the integration accuracy, in the coupled problem."""
    from ti_spinorbit.engine.ensemble import Ensemble
    from ti_spinorbit.kernels import eom

    vh = tso.catalog.system("1991 VH")
    table = Members.from_starts(vh, [0.0, 60.0], [0.45, 1.7])
    par, y0 = table.par, table.y0
    out = Ensemble(par, y0, rtol=1e-12, model=model).run(2 * np.pi * 5)
    for events in out.events:
        states = events[:, 1:]
        assert len(states) >= 4
        f = C.true_anomaly(states[:, eom.Y_R:eom.Y_R + 3], states[:, eom.Y_V:eom.Y_V + 3])
        assert np.max(np.abs(f)) < 1e-9


@pytest.mark.parametrize("e", [1e-3, 0.05, 0.6])
def test_keplerian_acceleration_gives_zero_apsidal_rate(e):
    """a_p = 0 (pure −μR/r³): the apsidal line does not move."""
    for f in np.linspace(-3.0, 3.0, 7):
        R, V = kepler_state(e, f, mu=2.5, varpi=-1.2)
        acc = -2.5 * R / np.linalg.norm(R) ** 3
        assert abs(C.apsidal_rate(R, V, acc, mu=2.5)[0]) < 1e-13 / e


@pytest.mark.parametrize("e, f", [(0.05, 0.0), (0.05, 1.0), (0.3, -2.0), (0.01, 2.9),
                                  (0.6, 0.4)])
def test_apsidal_rate_matches_gauss_equation(e, f):
    """Planar Gauss equation: ϖ̇ = sqrt(p/μ)/e [−a_r cos f + a_t (1 + r/p) sin f]; at
    pericentre with a radial push, ϖ̇ = −sqrt(p/μ) a_r/e."""
    mu, a_r, a_t = 1.3, 2e-3, -7e-4
    R, V = kepler_state(e, f, a=1.7, mu=mu, varpi=0.4)
    r = np.linalg.norm(R)
    rhat = R / r
    that = np.cross([0.0, 0.0, 1.0], rhat)
    acc = -mu * R / r**3 + a_r * rhat + a_t * that
    p = 1.7 * (1 - e * e)
    gauss = math.sqrt(p / mu) / e * (-a_r * math.cos(f) + a_t * (1 + r / p) * math.sin(f))
    assert C.apsidal_rate(R, V, acc, mu=mu)[0] == pytest.approx(gauss, rel=1e-12, abs=1e-15)


def test_apsidal_rate_is_frame_independent():
    """A rotated frame (3-D, non-symmetric rotation) gives the same ϖ̇: it is a scalar."""
    rng = np.random.default_rng(7)
    R, V = kepler_state(0.2, 0.8)
    acc = -R / np.linalg.norm(R) ** 3 + rng.normal(size=3) * 1e-3
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    assert C.apsidal_rate(q @ R, q @ V, q @ acc)[0] == pytest.approx(
        C.apsidal_rate(R, V, acc)[0], rel=1e-12)


# ---- the coupled problem: force from the kernels against the NumPy reference -------------

@pytest.mark.parametrize("name, elongation, theta_p", [("1991 VH", 1.01, 0.0),
                                                      ("1991 VH", 1.5, 40.0),
                                                      ("test", None, 0.0),
                                                      ("2004 DC", None, 120.0)])
def test_initial_apsidal_rate_against_reference_potential(name, elongation, theta_p):
    """ϖ̇(0) from the kernels' right-hand side equals Gauss at pericentre, −sqrt(p/μ) a_r/e,
    with a_r from the NumPy reference potential (SI), to 1e-9."""
    system = tso.catalog.system(name, elongation=elongation)
    table = Members.from_starts(system, theta_p, 1.3)
    par, y0 = table.par, table.y0
    rate = apsidal_rates(par, y0)[0] * system.mean_motion           # rad/s
    R, P, _, _, S, _ = reference.unpack_state(system.to_physical(y0[0]))
    _, force, _, _ = reference.mutual_potential(
        tso.G, system.primary.mass, reference.body_tensors(system.primary),
        system.secondary.mass, reference.body_tensors(system.secondary), R, S)
    m1, m2 = system.primary.mass, system.secondary.mass
    mu = tso.G * (m1 + m2)
    acc = force / (m1 * m2 / (m1 + m2))
    a_r = np.dot(acc, R) / np.linalg.norm(R) + mu / np.dot(R, R)       # perturbing part
    p = system.a * (1 - system.e**2)
    assert rate == pytest.approx(-math.sqrt(p / mu) * a_r / system.e, rel=1e-9)


def test_initial_rate_does_not_depend_on_spin_and_converts_the_start():
    """ϖ̇(0) depends on positions and attitudes only, so the apsidal start is explicit:
    the integrated inertial spin is θ̇_p + ϖ̇(0) (about +0.0157 n for 1991 VH at a/b = 1.01,
    the difference the paper's coordinates make)."""
    from ti_spinorbit.kernels import eom
    from ti_spinorbit.model.observables import derive

    vh = tso.catalog.system("1991 VH", elongation=1.01)
    table = Members.from_starts(vh, 0.0, 0.5)
    par, y_slow = table.par, table.y0
    table = Members.from_starts(vh, 0.0, 2.5)
    y_fast = table.y0
    assert apsidal_rates(par, y_slow)[0] == apsidal_rates(par, y_fast)[0]
    rate = apsidal_rates(par, y_slow)[0]
    assert rate == pytest.approx(0.0157, abs=5e-4)
    table = Members.from_starts(vh, 0.0, 1.08, coordinates="apsidal")
    par, y_aps, td = table.par, table.y0, table.thetadot_p
    assert td[0] == 1.08                                     # the user's (apsidal) value
    spin = derive(par, y_aps)["thetadot"][0]
    assert spin == pytest.approx(1.08 + rate, abs=1e-14)
    assert y_aps[0, eom.Y_S] == y_slow[0, eom.Y_S]           # same attitude and orbit


def test_section_in_both_coordinates_records_the_same_events():
    """One physical trajectory recorded in both systems: the same crossings and θ_p, and
    θ̇_inertial − θ̇_apsidal = ϖ̇ at every crossing."""
    vh = tso.catalog.system("1991 VH", elongation=1.06)
    table = Members.from_starts(vh, 0.0, 1.0)
    par, y0 = table.par, table.y0
    rate0 = apsidal_rates(par, y0)[0]
    starts = np.array([1.13, 1.70])
    aps = tso.surface_of_section(vh, 0.0, starts, orbits=20, rtol=1e-12, coordinates="apsidal")
    ine = tso.surface_of_section(vh, 0.0, starts + rate0, orbits=20, rtol=1e-12)
    assert (aps.coordinates, ine.coordinates, ine.apsidal_rate) == ("apsidal", "inertial", None)
    np.testing.assert_array_equal(aps.count, ine.count)
    np.testing.assert_allclose(aps.t, ine.t, rtol=1e-12)
    np.testing.assert_allclose(aps.theta_p, ine.theta_p, atol=1e-8)
    np.testing.assert_allclose(ine.thetadot_p - aps.thetadot_p, aps.apsidal_rate, atol=1e-10)
    finite = aps.apsidal_rate[np.isfinite(aps.apsidal_rate)]
    assert finite.size == aps.count.sum() and np.all((finite > 0.005) & (finite < 0.03))


def test_apsidal_angle_derivative_equals_apsidal_rate():
    """Along a dense trajectory, d/dt of θ_aps = α + f (geometry of the osculating orbit)
    equals θ̇_aps = spin − ϖ̇ (the force formula), by a 5-point stencil, to 1e-7 n."""
    vh = tso.catalog.system("1991 VH", elongation=1.06)
    spo = 2048
    ts = tso.time_series(vh, 30.0, 1.4, orbits=0.5, samples_per_orbit=spo, rtol=1e-13,
                         coordinates="apsidal")
    assert ts.theta[0, 0] == pytest.approx(30.0, abs=1e-12)    # f = 0 at the start
    theta = np.unwrap(np.radians(ts.theta[0]))
    h = 2 * np.pi / spo                                     # scaled time between samples
    d = (theta[:-4] - 8 * theta[1:-3] + 8 * theta[3:-1] - theta[4:]) / (12 * h)
    np.testing.assert_allclose(d, ts.thetadot[0, 2:-2], atol=1e-7)
    ine = tso.time_series(vh, 30.0, 1.4, orbits=0.5, samples_per_orbit=spo, rtol=1e-13)
    # the two series start from different spins; their difference ϖ̇ is not small
    assert np.ptp(ine.thetadot[0] - ts.thetadot[0]) > 0.01


def test_models_agree_on_the_apsidal_rate():
    """The planar and the 3-D equations give the same apsidal section (to the tolerance)."""
    vh = tso.catalog.system("1991 VH")
    kw = dict(orbits=3, rtol=1e-12, coordinates="apsidal")
    planar = tso.surface_of_section(vh, 0.0, [0.45, 1.7], **kw,
                                    integrator=tso.Integrator(model="planar"))
    spatial = tso.surface_of_section(vh, 0.0, [0.45, 1.7], **kw,
                                     integrator=tso.Integrator(model="3d"))
    np.testing.assert_allclose(planar.apsidal_rate, spatial.apsidal_rate, atol=1e-8)
    np.testing.assert_allclose(planar.thetadot_p, spatial.thetadot_p, atol=1e-8)


# ---- e → 0 ----------------------------------------------------------------------------

def test_apsidal_start_below_the_eccentricity_floor_is_refused():
    kw4 = tso.catalog.system("1999 KW4")                     # e = 0.0004
    with pytest.raises(ValueError, match=r"coordinates='apsidal' needs an orbit eccentricity "
                                         r">= 0.001 \(system '1999 KW4' has e = 0.0004\)"):
        tso.surface_of_section(kw4, 0.0, 1.0, orbits=1, coordinates="apsidal")
    # its ϖ̇ would be several n: the apsidal θ̇ would describe the orbit, not the spin
    table = Members.from_starts(kw4, 0.0, 1.0)
    par, y0 = table.par, table.y0
    assert abs(apsidal_rates(par, y0)[0]) > 1.0


def test_small_eccentricity_points_become_nan_with_a_warning():
    e = np.array([[0.05, 5e-4, np.nan], [2e-3, 1e-3, 0.0]])
    with pytest.warns(RuntimeWarning, match=r"2 of 5 points have an osculating eccentricity "
                                            r"below 0.001"):
        (x,) = C.mask_small_eccentricity(e, np.ones_like(e))
    np.testing.assert_array_equal(np.isnan(x), [[False, True, False], [False, False, True]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        C.mask_small_eccentricity(np.array([0.05, np.nan]), np.zeros(2))   # padding: silent


# ---- API, saving, plotting -------------------------------------------------------------

def _run(entry):
    vh = tso.catalog.system("1991 VH")
    calls = {
        "surface_of_section": lambda c: tso.surface_of_section(vh, 0.0, 1.0, 1, coordinates=c),
        "time_series": lambda c: tso.time_series(vh, 0.0, 1.0, 1, coordinates=c),
        "chaos_map": lambda c: tso.chaos_map(vh, [0.0], [1.0], 1, coordinates=c),
        "parameter_map": lambda c: tso.parameter_map("1991 VH", [1.1], [0.05], 1,
                                                     coordinates=c),
        "overlap_threshold": lambda c: tso.overlap_threshold("1991 VH", [1.1], orbits=1,
                                                             coordinates=c),
        "libration_amplitude": lambda c: tso.libration_amplitude(vh, 1.0, 1, coordinates=c),
        "relaxed_libration": lambda c: tso.relaxed_libration(vh, 1, coordinates=c),
    }
    return calls[entry]


@pytest.mark.parametrize("entry", ["surface_of_section", "time_series", "chaos_map",
                                   "parameter_map", "overlap_threshold",
                                   "libration_amplitude", "relaxed_libration"])
def test_every_entry_point_checks_coordinates_first(entry):
    with pytest.raises(ValueError, match=r"^coordinates must be 'inertial' or 'apsidal' "
                                         r"\(got 'apsides'\)$"):
        _run(entry)("apsides")


def test_chaos_map_keeps_coordinates_and_labels_its_axis(tmp_path):
    vh = tso.catalog.system("1991 VH", elongation=1.06)
    cmap = tso.chaos_map(vh, [0.0, 90.0], [1.1, 1.7], orbits=4, coordinates="apsidal")
    assert cmap.coordinates == cmap.section.coordinates == "apsidal"
    np.testing.assert_allclose(cmap.section.initial_thetadot_p.reshape(2, 2),
                               [[1.1, 1.7], [1.1, 1.7]])
    ax = cmap.plot()
    assert ax.get_ylabel().endswith("(apsidal)")
    loaded = tso.load(tso.save(cmap, tmp_path / "m.npz"))
    assert (loaded.coordinates, loaded.section.coordinates) == ("apsidal", "apsidal")
    np.testing.assert_array_equal(loaded.section.apsidal_rate, cmap.section.apsidal_rate)


def test_saved_section_says_which_coordinates(tmp_path):
    vh = tso.catalog.system("1991 VH", elongation=1.01)
    sec = tso.surface_of_section(vh, 0.0, [1.08], orbits=2, coordinates="apsidal")
    path = tso.save(sec, tmp_path / "s.npz")
    meta = json.loads(str(np.load(path)["metadata"]))
    assert "apsidal" in json.dumps(meta)
    assert "apsidal" in meta["units"]["coordinates"] and meta["units"]["apsidal_rate"] == \
        "mean motion n"
    loaded = tso.load(path)
    assert loaded.coordinates == "apsidal"
    np.testing.assert_array_equal(loaded.thetadot_p, sec.thetadot_p)
    assert sec.plot().get_ylabel() == r"$\dot\theta_p / n$ (apsidal)"
    default = tso.surface_of_section(vh, 0.0, [1.08], orbits=2)
    assert (default.coordinates, default.apsidal_rate) == ("inertial", None)
    assert default.plot().get_ylabel() == r"$\dot\theta_p / n$ (inertial)"


def test_relaxed_libration_centre_shifts_by_the_initial_apsidal_rate():
    """The island centre in apsidal coordinates is the inertial one minus ϖ̇(0); the
    amplitude (max |α|) is the same trajectory's."""
    vh = tso.catalog.system("1991 VH", elongation=1.3)
    kw = dict(orbits=30, xtol=1e-4, candidates=np.linspace(0.7, 1.2, 21))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ine = tso.relaxed_libration(vh, **kw)
        aps = tso.relaxed_libration(vh, coordinates="apsidal", **kw)
    table = Members.from_starts(vh, 0.0, 1.0)
    par, y0 = table.par, table.y0
    rate0 = apsidal_rates(par, y0)[0]
    assert aps.coordinates == "apsidal"
    assert aps.centre_thetadot_p == pytest.approx(ine.centre_thetadot_p - rate0, abs=2e-4)
    assert aps.amplitude == pytest.approx(ine.amplitude, abs=0.05)


def test_cli_coordinates_flag(tmp_path):
    p = run_cli("section", "--system", "1991 VH", "--elongation", "1.01", "--thetadot", "1.08",
                "--orbits", "2", "--coordinates", "apsidal", "--out", "s.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert tso.load(tmp_path / "s.npz").coordinates == "apsidal"
    p = run_cli("map", "--system", "1999 KW4", "--coordinates", "apsidal", "--out", "m.png",
                cwd=tmp_path)
    assert p.returncode == 2
    assert p.stderr.strip().splitlines()[-1] == (
        "ti-spinorbit map: error: --coordinates apsidal needs an eccentricity >= 0.001 "
        "(1999 KW4 has e = 0.0004): use --coordinates inertial or a larger --eccentricity")
    assert not (tmp_path / "m.png").exists()


# ---- the paper's Fig. 4 starts ----------------------------------------------------------

#: Classes of the paper's low-elongation starts in apsidal (the paper's) coordinates, over
#: 150 orbits (the same at 1500). At a/b = 1.01 the starts come in pairs on either side of
#: the 1:1 separatrix (1.08 in, 1.15 out) and of the 3:2 separatrix (1.55 in, 1.57 out).
PAPER_STARTS = {
    1.01: {1.08: "resonant 1", 1.15: "quasi-periodic", 1.28: "quasi-periodic",
           1.55: "resonant 1.5", 1.57: "quasi-periodic", 1.68: "quasi-periodic",
           1.78: "quasi-periodic"},
    1.06: {1.13: "resonant 1", 1.63: "resonant 1.5", 1.70: "chaotic", 1.78: "quasi-periodic"},
}
#: In inertial coordinates (starts shifted by −ϖ̇(0) ≈ −0.016 n) three of them change class.
INERTIAL_CHANGES = {(1.01, 1.15): "resonant 1", (1.01, 1.28): "resonant",
                    (1.01, 1.57): "resonant 1.5"}


def _classes(result):
    cls = classify_section(result)
    return [lab + (f" {p:g}" if lab == "resonant" and np.isfinite(p) else "")
            for lab, p in zip(cls.classification, cls.resonance_p)]


@pytest.mark.parametrize("elongation", [1.01, 1.06])
def test_paper_low_elongation_starts_in_both_coordinates(elongation):
    vh = tso.catalog.system("1991 VH", elongation=elongation)
    starts = list(PAPER_STARTS[elongation])
    aps = tso.surface_of_section(vh, 0.0, starts, orbits=150, rtol=1e-12, coordinates="apsidal")
    ine = tso.surface_of_section(vh, 0.0, starts, orbits=150, rtol=1e-12)
    assert list(aps.status_names) == list(ine.status_names) == ["done"] * len(starts)
    assert _classes(aps) == list(PAPER_STARTS[elongation].values())
    expected = [INERTIAL_CHANGES.get((elongation, w), PAPER_STARTS[elongation][w])
                for w in starts]
    assert _classes(ine) == expected
