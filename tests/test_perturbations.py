"""Tides, YORP and BYORP in the equations (docs/physics.md §13): the integrated rates against
the closed forms of ``ti_spinorbit.model.analytic`` (Hut 1981 for the constant-time-lag tide, the
constant-Q limit, BYORP and the tide-BYORP equilibrium of Jacobson & Scheeres 2011), the
closed forms against an independent orbit average of the force law, the strength scaling,
and the accounting of the energy and angular momentum the perturbations exchange.

The integrations use two uniform spheres, so that gravity is exactly that of point masses
and every rate has a closed form. Each run is a few tens to a few hundred orbits with the
``strength`` chosen so that the elements change by ~1e-3 (or, for the equilibrium, converge
within the run) while each orbit changes them by < 1e-3: the weak-tide limit the formulas
assume, checked in each test. Secular rates come from the means of the osculating elements
over the first and the last orbit (uniform samples over a period average the short-period
terms out)."""

import math

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine import accuracy
from ti_spinorbit.model import analytic
from ti_spinorbit.system.bodies import Sphere
from ti_spinorbit.constants import AU, GM_SUN
from ti_spinorbit.system.systems import G

SPO = 64                      # samples per orbit
ORBITS = 20
# YORP and BYORP at their mean-distance value, the form the analytic rates these tests check
# against give (the Sun's distance of the moment: test_radiation_at_the_suns_distance in
# tests/test_heliocentric.py); SolarTide is not given it
HELIO = dict(heliocentric_a_au=1.5, heliocentric_e=0.2, distance="mean")
PRIMARY, SECONDARY = Sphere(400.0, 2000.0), Sphere(150.0, 2000.0)


def spheres(e=0.0, a=1500.0, primary_spin_period=None):
    return tso.BinarySystem(PRIMARY, SECONDARY, a=a, e=e, primary_spin_period=primary_spin_period,
                            name="two spheres")


def elements(ts, system, k=0):
    """Osculating (a m, e) of member ``k`` at every sample, from the SI states."""
    R, V = ts.R[k], ts.V[k]
    mu = G * system.total_mass
    r = np.linalg.norm(R, axis=-1)
    v2 = np.sum(V * V, axis=-1)
    ecc = ((v2 - mu / r)[:, None] * R - np.sum(R * V, axis=-1)[:, None] * V) / mu
    return 1.0 / (2.0 / r - v2 / mu), np.linalg.norm(ecc, axis=-1)


def secular(t, x):
    """(rate, mid value) of ``x`` from its means over the first and the last orbit."""
    first, last = slice(0, SPO), slice(len(t) - 1 - SPO, len(t) - 1)
    m0, m1 = x[first].mean(), x[last].mean()
    return (m1 - m0) / (t[last].mean() - t[first].mean()), 0.5 * (m0 + m1)


def run(system, perturbations, model="planar", thetadot=3.0, orbits=ORBITS, rtol=1e-12, **kw):
    return tso.time_series(system, 0.0, [thetadot], orbits=orbits, samples_per_orbit=SPO,
                           perturbations=perturbations, rtol=rtol, states=True, **kw,
                           integrator=tso.Integrator(model=model))


def measured_rates(ts, system):
    """Secular (dω/dt rad s⁻², da/dt m s⁻¹, de/dt s⁻¹) and mid (ω, a, e) of member 0."""
    t = ts.t[0]
    a, e = elements(ts, system)
    (dw, w), (da, am), (de, em) = (secular(t, x) for x in
                                   (ts.thetadot[0] * system.mean_motion, a, e))
    return (dw, da, de), (w, am, em)


def weak_strength(system, tide, x=3.0, change=1e-3):
    """The strength at which the spin ω = x n changes by ``change`` of itself over the run."""
    n = system.mean_motion
    rate = analytic.tidal_despin_rate(system, tide, x * n, system.e)
    return change * x * n / (abs(rate) * ORBITS * 2.0 * math.pi / n)


# ---- the closed forms --------------------------------------------------------------------------

def orbit_averaged_force(kappa, lag, m_red, C, mu, a, e, omega, points=4096):
    """(da/dt, de/dt, dω/dt) of F = −(κ/r⁸)[R + Δt(2(R·V)/r² R + V − Ω×R)] (on the relative
    motion, m_red dV/dt = F; torque −R×F on the body spinning at ω about z) averaged over a
    fixed Kepler ellipse with Gauss's perturbation equations: the trapezoid rule in the true
    anomaly f, weighted by dM/df = (r/a)²/sqrt(1 − e²), converges spectrally."""
    n = math.sqrt(mu / a ** 3)
    f = 2.0 * np.pi * np.arange(points) / points
    zero = np.zeros_like(f)
    p = a * (1.0 - e * e)
    r = p / (1.0 + e * np.cos(f))
    R = np.stack([r * np.cos(f), r * np.sin(f), zero], -1)
    V = math.sqrt(mu / p) * np.stack([-np.sin(f), e + np.cos(f), zero], -1)
    Om = np.array([0.0, 0.0, omega])
    rv = np.sum(R * V, -1)[:, None]
    F = -(kappa / r[:, None] ** 8) * (R + lag * (2.0 * rv / r[:, None] ** 2 * R + V
                                                 - np.cross(Om, R)))
    radial = np.sum(F * R, -1) / r / m_red
    along = np.sum(F * np.stack([-np.sin(f), np.cos(f), zero], -1), -1) / m_red
    E = 2.0 * np.arctan(math.sqrt((1.0 - e) / (1.0 + e)) * np.tan(f / 2.0))
    s = math.sqrt(1.0 - e * e)
    dadt = 2.0 / (n * s) * (radial * e * np.sin(f) + along * (1.0 + e * np.cos(f)))
    dedt = s / (n * a) * (radial * np.sin(f) + along * (np.cos(f) + np.cos(E)))
    dwdt = -np.cross(R, F)[:, 2] / C
    weight = (r / a) ** 2 / s
    return tuple(float(np.mean(x * weight)) for x in (dadt, dedt, dwdt))


@pytest.mark.parametrize("e", [0.0, 0.1, 0.3, 0.6])
@pytest.mark.parametrize("spin", [0.5, 1.0, 3.0])
@pytest.mark.parametrize("body", ["secondary", "primary"])
def test_hut_rates_in_our_normalisation_are_the_orbit_average_of_our_force(e, spin, body):
    system = spheres()
    tide = tso.Tides(body=body, k2=1e-3, time_lag=60.0, strength=7.0)
    m1, m2 = system.primary.mass, system.secondary.mass
    omega = spin * system.mean_motion
    da, de, dw = orbit_averaged_force(tide.coefficient(system), 60.0, m1 * m2 / (m1 + m2),
                                      getattr(system, body).moments[2], G * (m1 + m2),
                                      system.a, e, omega)
    rate_a, rate_e = analytic.tidal_orbit_rates(system, tide, omega, e)
    rate_w = analytic.tidal_despin_rate(system, tide, omega, e)
    scale_a = 2.0 * tide.coefficient(system) * 60.0 / (m1 * m2 / (m1 + m2) * system.a ** 7)
    assert rate_a == pytest.approx(da, rel=1e-10, abs=1e-12 * scale_a)
    assert rate_e == pytest.approx(de, rel=1e-10, abs=1e-12 * scale_a / system.a)
    scale_w = (tide.coefficient(system) * 60.0 * system.mean_motion
               / (getattr(system, body).moments[2] * system.a ** 6))
    assert rate_w == pytest.approx(dw, rel=1e-10, abs=1e-12 * scale_w)
    if e == 0.0:
        assert rate_e == 0.0
        # the brief's circular despin formula, written out
        M = (m2 if body == "primary" else m1)
        R = getattr(system, body).semi_axes[0]
        C = getattr(system, body).moments[2]
        assert rate_w == pytest.approx(-3 * 1e-3 * 7.0 * G * M ** 2 * R ** 5 * 60.0
                                       * (omega - system.mean_motion) / (system.a ** 6 * C),
                                       rel=1e-12, abs=1e-30)


@pytest.mark.parametrize("spin", [0.2, 3.0])
def test_constant_q_rates_are_the_classical_closed_forms(spin):
    system = spheres()
    k2, Q, s = 2e-3, 30.0, 5.0
    n, M, mb = system.mean_motion, system.primary.mass, system.secondary.mass
    R = system.secondary.semi_axes[0]
    tide = tso.Tides(body="secondary", k2=k2, Q=Q, strength=s)
    sign = math.copysign(1.0, spin - 1.0)
    # the kernels' floor on |ω − n| shifts the rates by (1e-3/|ω/n − 1|)²/2 <= 8e-7 here
    da, de = analytic.tidal_orbit_rates(system, tide, spin * n)
    assert da == pytest.approx(sign * 3 * (k2 / Q) * (M / mb) * math.sqrt(G * system.total_mass)
                               * R ** 5 * system.a ** -5.5 * s, rel=2e-6)
    assert de == 0.0
    assert analytic.tidal_despin_rate(system, tide, spin * n) == pytest.approx(
        -sign * 1.5 * (k2 / Q) * G * M ** 2 * R ** 5 / (system.a ** 6 * system.secondary.moments[2])
        * s, rel=2e-6)


def test_tide_byorp_equilibrium_cancels_the_two_rates():
    system = spheres(primary_spin_period=3 * 3600.0)
    tide = tso.Tides(body="primary", k2=1e-6, Q=1.0)
    byorp = tso.BYORP(coefficient=-1e-3, **HELIO)
    a_eq = analytic.tide_byorp_equilibrium(system, tide, byorp)
    omega_p = 2 * math.pi / (3 * 3600.0)
    tidal = analytic.tidal_orbit_rates(system, tide, omega_p, a=a_eq)[0]
    assert tidal > 0 and tidal == pytest.approx(-analytic.byorp_da_dt(system, byorp, a=a_eq),
                                                rel=1e-5)
    # the same factor on both does not move it; a stronger tide pushes it out as s^(1/7)
    both = analytic.tide_byorp_equilibrium(system, tso.Tides(body="primary", k2=1e-6, Q=1.0,
                                                             strength=1e4),
                                           tso.BYORP(coefficient=-1e-3, strength=1e4, **HELIO))
    assert both == pytest.approx(a_eq, rel=1e-12)
    tide_only = analytic.tide_byorp_equilibrium(system, tso.Tides(body="primary", k2=1e-6,
                                                                  Q=1.0, strength=128.0), byorp)
    assert tide_only == pytest.approx(2.0 * a_eq, rel=1e-12)


@pytest.mark.parametrize("call, message", [
    (lambda s: analytic.tidal_despin_rate(s, "tide", 1e-4), "tides must be a ti_spinorbit.Tides"),
    (lambda s: analytic.tidal_despin_rate(s, tso.Tides(time_lag=1.0), math.nan),
     "omega must be finite"),
    (lambda s: analytic.tidal_orbit_rates(s, tso.Tides(time_lag=1.0), 1e-4, e=1.0),
     "e must lie in [0, 1)"),
    (lambda s: analytic.tidal_orbit_rates(s, tso.Tides(time_lag=1.0), 1e-4, a=-3.0),
     "a must lie in (0, inf] m"),
    (lambda s: analytic.tidal_orbit_rates(s, tso.Tides(Q=10.0), 1e-4, e=0.2),
     "e must be 0 for the orbit rates of a constant-Q tide"),
    (lambda s: analytic.byorp_da_dt(s, tso.YORP(**HELIO)), "byorp must be a ti_spinorbit.BYORP"),
    (lambda s: analytic.tide_byorp_equilibrium(s, tso.Tides(Q=1.0), tso.BYORP(-1e-3, **HELIO)),
     "tides.body must be 'primary'"),
    (lambda s: analytic.tide_byorp_equilibrium(s, tso.Tides("primary", time_lag=5.0),
                                               tso.BYORP(-1e-3, **HELIO)),
     "tides must be a constant-Q tide"),
    (lambda s: analytic.tide_byorp_equilibrium(s, tso.Tides("primary", Q=1.0),
                                               tso.BYORP(1e-3, **HELIO)),
     "byorp.coefficient must be < 0"),
])
def test_analytic_rate_inputs_are_checked_in_one_line(call, message):
    with pytest.raises((TypeError, ValueError)) as info:
        call(spheres())
    text = str(info.value)
    assert message in text and "\n" not in text


# ---- integrated rates against the closed forms ------------------------------------------------

@pytest.mark.parametrize("model", ["planar", "3d"])
@pytest.mark.parametrize("e", [0.0, 0.2])
def test_time_lag_tide_despin_and_orbit_rates_match_hut(model, e):
    system = spheres(e)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0, strength=weak_strength(system, tide))
    ts = run(system, [tide], model)
    assert accuracy.usable(ts.status).all()
    (dw, da, de), (w, a, em) = measured_rates(ts, system)
    # weak tide: the spin changed by ~1e-3 of itself over the run (the rates are evaluated
    # at the mid values; what is left, 2-5e-5, comes from the static part of the scaled tide,
    # 7e-6 of the point-mass attraction, which the osculating elements do not account for)
    change = abs(ts.thetadot[0, -1] - 3.0) / 3.0
    assert 5e-4 < change < 2e-3
    expect_w = analytic.tidal_despin_rate(system, tide, w, em if e else 0.0, a)
    expect_a, expect_e = analytic.tidal_orbit_rates(system, tide, w, em if e else 0.0, a)
    assert dw == pytest.approx(expect_w, rel=1e-3)
    assert da == pytest.approx(expect_a, rel=1e-3)
    if e:
        assert de == pytest.approx(expect_e, rel=1e-3)
    else:        # stays circular: e changes by < 1e-8 over the run
        assert abs(de) * (ts.t[0, -1] - ts.t[0, 0]) < 1e-8


def test_constant_q_despin_matches_the_closed_form():
    system = spheres()
    tide = tso.Tides(body="secondary", k2=1e-3, Q=5.0)
    tide = tso.Tides(body="secondary", k2=1e-3, Q=5.0, strength=weak_strength(system, tide))
    ts = run(system, [tide])
    (dw, da, _), (w, a, _) = measured_rates(ts, system)
    assert dw == pytest.approx(analytic.tidal_despin_rate(system, tide, w, a=a), rel=1e-3)
    assert da == pytest.approx(analytic.tidal_orbit_rates(system, tide, w, a=a)[0], rel=1e-3)


def test_rates_scale_linearly_with_strength():
    system = spheres(0.2)
    base = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0)
    s = weak_strength(system, base, change=5e-4)
    rates = [np.array(measured_rates(run(system, [tso.Tides(body="secondary", k2=1e-3,
                                                               time_lag=60.0, strength=k * s)]),
                                     system)[0]) for k in (1.0, 2.0)]
    np.testing.assert_allclose(rates[1] / rates[0], 2.0, rtol=2e-3)


@pytest.mark.parametrize("model", ["planar", "3d"])
def test_byorp_da_dt_matches_the_circular_rate(model):
    system = spheres()
    n = system.mean_motion
    base = tso.BYORP(coefficient=2e-3, **HELIO)
    s = 1e-3 * system.a / (analytic.byorp_da_dt(system, base) * ORBITS * 2 * math.pi / n)
    byorp = tso.BYORP(coefficient=2e-3, strength=s, **HELIO)
    ts = run(system, [byorp], model)
    a, e = elements(ts, system)
    assert 5e-4 < a[-1] / a[0] - 1.0 < 2e-3                   # weak: a grew by ~1e-3
    da, a_mid = secular(ts.t[0], a)
    assert da == pytest.approx(analytic.byorp_da_dt(system, byorp, a=a_mid), rel=1e-3)
    assert e.max() < 1e-4                                    # and the orbit stays circular


def test_tide_byorp_equilibrium_is_reached_from_both_sides():
    """A constant-Q tide on a fast-spinning primary (expanding) against a contracting BYORP,
    the same strength on both. Q = 1 keeps the conservative part of the scaled tide small
    (the equilibrium depends on k2/Q only), so the start is near-circular and stays so."""
    ref = spheres(primary_spin_period=3 * 3600.0)
    k2 = 9.176841422950388e-07                     # puts a_eq at 1500 m for this pair
    a_eq = analytic.tide_byorp_equilibrium(ref, tso.Tides("primary", k2=k2, Q=1.0),
                                           tso.BYORP(-1e-3, **HELIO))
    assert a_eq == pytest.approx(1500.0, rel=1e-9)
    orbits = 300
    # the linearised approach δa ∝ exp(−7 |da/dt_B| t / a): four e-folds over the run
    rate = abs(analytic.byorp_da_dt(ref, tso.BYORP(-1e-3, **HELIO)))
    s = 4.0 / (7.0 * rate / a_eq * orbits * 2.0 * math.pi / ref.mean_motion)
    perturbations = [tso.Tides("primary", k2=k2, Q=1.0, strength=s),
                     tso.BYORP(-1e-3, strength=s, **HELIO)]
    for start in (0.85, 1.15):
        system = spheres(a=start * a_eq, primary_spin_period=3 * 3600.0)
        ts = tso.time_series(system, 0.0, [1.0], orbits=orbits, samples_per_orbit=2,
                             perturbations=perturbations, rtol=1e-10, states=True,
                             integrator=tso.Integrator(model="planar"))
        assert accuracy.usable(ts.status).all()
        a, e = elements(ts, system)
        # weak on the orbital time scale: < 3e-3 of a per orbit; near-circular throughout
        per_orbit = a[::2]
        assert np.abs(np.diff(per_orbit) / per_orbit[:-1]).max() < 3e-3
        assert e.max() < 0.02
        dist = np.abs(per_orbit / a_eq - 1.0)
        assert np.all(np.diff(dist) < 1e-4)                   # approaches monotonically
        assert dist[-1] < 0.01                                 # and ends within 1 %


# ---- accounting ------------------------------------------------------------------------------

def test_energy_minus_work_drift_scales_with_rtol_while_energy_changes_a_lot():
    system = spheres(0.2)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0,
                     strength=weak_strength(system, tide, change=0.05))
    drift = {}
    for rtol in (1e-10, 1e-12):
        ts = run(system, [tide], rtol=rtol)
        drift[rtol] = ts.energy_drift[0]
        change = abs(ts.energy[0, -1] - ts.energy[0, 0]) / abs(ts.energy[0, 0])
        assert change > 1e4 * drift[rtol]
        # the work is the energy lost (to the drift)
        assert ts.work[0, -1] == pytest.approx(ts.energy[0, -1] - ts.energy[0, 0],
                                               rel=1e2 * drift[rtol] / change)
        assert ts.work[0, -1] < 0
    assert 100.0 / 3 < drift[1e-10] / drift[1e-12] < 100.0 * 3


def total_angmom(ts):
    return ts.angmom_orbit[0] + ts.angmom_primary[0] + ts.angmom_secondary[0]


@pytest.mark.parametrize("model", ["planar", "3d"])
def test_angular_momentum_minus_external_is_conserved_under_yorp_and_byorp(model):
    system = spheres(0.1)
    yorp = tso.YORP(body="secondary", coefficient=1e-3, strength=1e6, **HELIO)
    byorp = tso.BYORP(coefficient=1e-3, strength=1e3, **HELIO)
    ts = run(system, [yorp, byorp], model)
    L = total_angmom(ts)
    change = np.linalg.norm(L[-1] - L[0]) / np.linalg.norm(L[0])
    assert change > 1e-4 and ts.angmom_drift[0] < 1e-10
    np.testing.assert_allclose(ts.external_angmom[0, -1], L[-1] - L[0],
                               rtol=1e-6, atol=1e-8 * np.linalg.norm(L[0]))
    assert accuracy.usable(ts.status).all()


def test_tides_alone_exchange_no_angular_momentum_with_the_outside():
    system = spheres(0.2)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0,
                     strength=weak_strength(system, tide, change=0.05))
    ts = run(system, [tide], "3d")
    assert np.all(ts.external_angmom[0] == 0.0)
    spin = ts.angmom_secondary[0]
    moved = np.linalg.norm(spin[-1] - spin[0]) / np.linalg.norm(total_angmom(ts)[0])
    assert moved > 1e-4 and ts.angmom_drift[0] < 1e-4 * moved


@pytest.mark.parametrize("model", ["planar", "3d"])
@pytest.mark.parametrize("body", ["secondary", "primary"])
def test_yorp_spin_up_rate_is_torque_over_moment(model, body):
    system = spheres(0.1, primary_spin_period=5 * 3600.0)
    yorp = tso.YORP(body=body, coefficient=-2e-3, strength=1e5, **HELIO)
    ts = run(system, [yorp], model, orbits=5)
    omega = (ts.secondary_omega if body == "secondary" else ts.primary_omega)[0, :, 2]
    rate = np.polyfit(ts.t[0], omega, 1)[0]
    C = getattr(system, body).moments[2]
    assert rate == pytest.approx(yorp.torque(system) / C, rel=1e-6)
    assert yorp.torque(system) == pytest.approx(
        1e5 * tso.YORP(body=body, coefficient=-2e-3, **HELIO).torque(system), rel=1e-14)
    assert abs(omega[-1] / omega[0] - 1.0) > 1e-3


def test_planar_and_3d_models_agree_on_a_planar_perturbed_run():
    system = tso.catalog.system("1991 VH")
    perturbations = [tso.Tides("secondary", k2=1e-5, time_lag=600.0, strength=1e5),
                     tso.Tides("primary", k2=1e-5, Q=10.0, strength=1e5),
                     tso.YORP("secondary", coefficient=1e-3, strength=1e6),
                     tso.BYORP(coefficient=1e-3, strength=1e3)]
    runs = [tso.time_series(system, 0.0, [1.2], orbits=3, samples_per_orbit=16,
                            perturbations=perturbations, rtol=1e-13, states=True,
                            integrator=tso.Integrator(model=m))
            for m in ("planar", "3d")]
    planar, full = runs
    scale = np.abs(planar.states[0]).max(axis=0)
    scale[scale == 0] = 1.0
    np.testing.assert_allclose(planar.states[0] / scale, full.states[0] / scale, rtol=0, atol=1e-8)
    np.testing.assert_allclose(planar.work, full.work, rtol=1e-7)
    np.testing.assert_allclose(planar.external_angmom[0, :, 2], full.external_angmom[0, :, 2],
                               rtol=1e-7)
    assert planar.work[0, -1] != 0.0


def _spheres_oracle(system, perturbations, row0, t):
    """An independent integration (scipy DOP853, SI, inertial frame) of two spheres under
    point-mass gravity and the perturbations of docs/physics.md §13: relative motion
    dV/dt = −G M R/r³ + (F1 + F2)/m_red + a_B V/|V|, spins dω_b/dt = (−R × F_b + T_b ẑ_b)/C_b,
    attitudes dS_b/dt = [ω_b]× S_b, and (a sixth perturbation, a SolarTide) the Sun's point-mass
    attraction of each body differenced, the Sun on its own Kepler solution (Newton's method on
    E − e sin E = M, scipy-free); YORP and BYORP with ``distance="orbit"`` scaled by
    a⊙² sqrt(1 − e⊙²) / |D|² of that Sun. Returns (R, V, S1, S2, ω1, ω2) at ``t``."""
    from scipy.integrate import solve_ivp

    tide2, tide1, yorp2, yorp1, byorp = perturbations[:5]
    sun = perturbations[5] if len(perturbations) > 5 else None
    m1, m2 = system.primary.mass, system.secondary.mass
    M, m_red = m1 + m2, m1 * m2 / (m1 + m2)
    C1, C2 = system.primary.moments[2], system.secondary.moments[2]
    k1, k2 = tide1.coefficient(system), tide2.coefficient(system)
    T1, T2 = yorp1.torque(system), yorp2.torque(system)
    a_B = byorp.acceleration(system)
    lag_q, floor = 0.5 / tide1.Q, 1e-3 * system.mean_motion

    def force(kappa, lag, R, V, Om):
        r2, rv = R @ R, R @ V
        return -(kappa / r2 ** 4) * (R + lag * (2 * rv / r2 * R + V - np.cross(Om, R)))

    def hat(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    def sun_from_barycentre(tnow):
        a_s, e_s = sun.heliocentric_a_au * AU, sun.heliocentric_e
        n_s = math.sqrt((GM_SUN + G * M) / a_s ** 3)
        E = Mean = math.radians(sun.mean_anomaly_deg) + n_s * tnow
        for _ in range(60):
            E -= (E - e_s * math.sin(E) - Mean) / (1.0 - e_s * math.cos(E))
        i, O, w = (math.radians(x) for x in (sun.inclination_deg, sun.node_deg,
                                             sun.periapsis_deg))
        rz = lambda a: np.array([[math.cos(a), -math.sin(a), 0.0],      # noqa: E731
                                 [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
        rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(i), -math.sin(i)],
                       [0.0, math.sin(i), math.cos(i)]])
        return -(rz(O) @ rx @ rz(w) @ np.array([a_s * (math.cos(E) - e_s), a_s * math.sqrt(
            1.0 - e_s ** 2) * math.sin(E), 0.0]))

    def rhs(tnow, y):
        R, V, S1, S2 = y[0:3], y[3:6], y[6:15].reshape(3, 3), y[15:24].reshape(3, 3)
        w1, w2 = y[24:27], y[27:30]
        r = np.linalg.norm(R)
        w = np.cross(w1, R) / r - (V - (R @ V) / r ** 2 * R) / r    # bulge rate, constant Q
        F1 = force(k1, lag_q / math.sqrt(w @ w + floor ** 2), R, V, w1)
        F2 = force(k2, tide2.time_lag, R, V, w2)
        f = 1.0       # YORP and BYORP at the Sun's distance of the moment
        if yorp1.distance == "orbit":
            a_s, e_s = sun.heliocentric_a_au * AU, sun.heliocentric_e
            f = a_s ** 2 * math.sqrt(1.0 - e_s ** 2) / np.sum(sun_from_barycentre(tnow) ** 2)
        dV = -G * M * R / r ** 3 + (F1 + F2) / m_red + f * a_B * V / np.linalg.norm(V)
        if sun is not None:
            D = sun_from_barycentre(tnow)
            g = lambda x: (D - x) / np.linalg.norm(D - x) ** 3      # noqa: E731
            dV = dV + sun.strength * GM_SUN * (g(m1 / M * R) - g(-m2 / M * R))
        return np.concatenate([V, dV, (hat(w1) @ S1).ravel(), (hat(w2) @ S2).ravel(),
                               (-np.cross(R, F1) + f * T1 * S1[:, 2]) / C1,
                               (-np.cross(R, F2) + f * T2 * S2[:, 2]) / C2])

    S1, S2 = row0[6:15].reshape(3, 3), row0[18:27].reshape(3, 3)
    y0 = np.concatenate([row0[0:6], S1.ravel(), S2.ravel(), S1 @ row0[15:18], S2 @ row0[27:30]])
    Y = solve_ivp(rhs, (t[0], t[-1]), y0, method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t).y.T
    return Y[:, 0:3], Y[:, 3:6], Y[:, 6:15], Y[:, 15:24], Y[:, 24:27], Y[:, 27:30]


def test_3d_kernel_matches_an_independent_integration_with_tilted_spins():
    """Every perturbation at once, on tilted spins and an inclined orbit: the 3-D kernel
    against a plain SI integration of the same equations. Each perturbation moves the result
    by 1e-6 or more (checked when this test was written by leaving each out of the oracle),
    the two agree to 1e-9. YORP and BYORP take the Sun's distance of the moment, on the
    SolarTide's orbit (they follow its Sun: its phase M0 = 120°, d from 1.2 to 1.6 AU here)."""
    system = spheres(0.15, primary_spin_period=4 * 3600.0)
    orbit = dict(heliocentric_a_au=1.5, heliocentric_e=0.2)
    perturbations = [tso.Tides("secondary", k2=1e-3, time_lag=60.0, strength=3e3),
                     tso.Tides("primary", k2=1e-4, Q=3.0, strength=3e3),
                     tso.YORP("secondary", coefficient=1e-3, strength=1e6, **orbit),
                     tso.YORP("primary", coefficient=-1e-3, strength=1e7, **orbit),
                     tso.BYORP(coefficient=1e-3, strength=1e3, **orbit),
                     tso.SolarTide(inclination_deg=35.0, node_deg=10.0, periapsis_deg=60.0,
                                   mean_anomaly_deg=120.0, strength=100.0, **orbit)]
    start = system.tilted_start(20.0, 2.5, pitch=30.0, roll=10.0, spin_x=0.4, inclination=10.0,
                                primary_tilt=25.0)
    ts = tso.time_series(system, initial_states=[start], orbits=3, samples_per_orbit=8,
                         perturbations=perturbations, rtol=1e-12, states=True,
                         integrator=tso.Integrator(model="3d"))
    assert accuracy.usable(ts.status).all()
    st = ts.states[0]
    S1, S2 = st[:, 6:15].reshape(-1, 3, 3), st[:, 18:27].reshape(-1, 3, 3)
    ours = (st[:, 0:3], st[:, 3:6], st[:, 6:15], st[:, 18:27],
            np.einsum("nij,nj->ni", S1, st[:, 15:18]), np.einsum("nij,nj->ni", S2, st[:, 27:30]))
    oracle = _spheres_oracle(system, perturbations, st[0], ts.t[0])
    for name, a, b in zip(("R", "V", "S1", "S2", "omega1", "omega2"), ours, oracle):
        assert np.abs(a - b).max() < 1e-9 * np.abs(b).max(), name
    # the spins did move (by 0.4 % or more: YORP at 1.7 AU is 0.77 of its mean-distance
    # value), and the secondary's stays tilted by ~40°
    assert np.linalg.norm(ours[5][-1] - ours[5][0]) > 0.003 * np.linalg.norm(ours[5][0])
    assert np.linalg.norm(ours[4][-1] - ours[4][0]) > 0.003 * np.linalg.norm(ours[4][0])
    tilt = np.degrees(np.arccos(ours[5][:, 2] / np.linalg.norm(ours[5], axis=1)))
    assert tilt.min() > 30.0


def test_a_perturbed_member_whose_accounting_fails_is_flagged_inaccurate():
    system = spheres(0.2)
    tide = tso.Tides(body="secondary", k2=1e-3, time_lag=60.0, strength=1e3)
    ts = run(system, [tide], orbits=3, rtol=1e-8, max_drift=1e-15)
    assert ts.energy_drift[0] > 1e-15
    assert ts.status[0] == accuracy.Status.INACCURATE
    assert not accuracy.usable(ts.status).any()


# ---- the objects' layout and input checks -----------------------------------------------------

@pytest.mark.parametrize("make, error, message", [
    (lambda: tso.Tides(k2=-1e-5), ValueError, "k2 must be a finite number > 0"),
    (lambda: tso.Tides(k2=50.0), ValueError, "k2 must lie in [1e-12, 10]"),
    (lambda: tso.Tides(time_lag=10.0, Q=100.0), ValueError,
     "give the tide a time_lag (s) or a Q, not both"),
    (lambda: tso.Tides(body="moon"), ValueError, "body must be 'primary' or 'secondary'"),
    (lambda: tso.Tides(time_lag=-1.0), ValueError, "time_lag must be a finite number > 0"),
    (lambda: tso.Tides(Q=0.0), ValueError, "Q must be a finite number > 0"),
    (lambda: tso.Tides(strength=math.inf), ValueError, "strength must be a finite number > 0"),
    (lambda: tso.Tides(strength=math.nan), ValueError, "strength must be a finite number > 0"),
    (lambda: tso.Tides(strength="big"), TypeError, "strength must be a number"),
    (lambda: tso.YORP(body="moon"), ValueError, "body must be 'primary' or 'secondary'"),
    (lambda: tso.YORP(coefficient=2.0), ValueError, "YORP coefficient (f_Y) must lie in [-1.0, 1.0]"),
    (lambda: tso.YORP(strength=-1.0), ValueError, "strength must be a finite number > 0"),
    (lambda: tso.YORP(heliocentric_a_au=1.0), ValueError,
     "give both heliocentric_a_au (AU) and heliocentric_e, or neither"),
    (lambda: tso.BYORP(coefficient=math.nan), ValueError, "BYORP coefficient (B) must lie in [-1.0, 1.0]"),
    (lambda: tso.BYORP(heliocentric_a_au=1.0, heliocentric_e=1.0), ValueError,
     "heliocentric_e must lie in [0.0, 1.0)"),
    (lambda: tso.BYORP(strength=1e20), ValueError, "strength must lie in [1e-12, 1e+15]"),
    (lambda: tso.Tides.rubble_pile(), ValueError,
     "Tides.rubble_pile needs radius_m (m) or system= (a BinarySystem) for the secondary's"),
    (lambda: tso.Tides.jacobson_scheeres("primary", system="1991 VH"), TypeError,
     "system must be a ti_spinorbit.BinarySystem (got '1991 VH')"),
    (lambda: tso.Tides.rubble_pile(radius_m=-5.0), ValueError,
     "radius_m must be a finite number > 0"),
    (lambda: tso.model.perturbations.check_perturbations([tso.Tides(), tso.Tides(k2=1e-3)]),
     ValueError, "perturbations[1]: a second tides on the secondary"),
    (lambda: tso.model.perturbations.check_perturbations([tso.Tides(), "yorp"]), TypeError,
     "perturbations[1] must be a Tides, YORP, BYORP, SolarTide or Flyby object"),
])
def test_perturbation_inputs_are_refused_in_one_line_naming_the_parameter(make, error, message):
    with pytest.raises(error) as info:
        make()
    text = str(info.value)
    assert message in text and "\n" not in text


def test_a_tide_on_each_body_is_accepted():
    items = tso.model.perturbations.check_perturbations([tso.Tides("primary"), tso.Tides("secondary"),
                                                   tso.YORP("primary"), tso.YORP("secondary")])
    assert [p.slot for p in items] == [("tides", "primary"), ("tides", "secondary"),
                                       ("yorp", "primary"), ("yorp", "secondary")]


@pytest.mark.parametrize("model, k2", [("rubble_pile", lambda km: 1e-5 * km),
                                       ("jacobson_scheeres", lambda km: 2.5e-5 / km)])
def test_k2_models_use_the_given_radius_or_the_bodys(model, k2):
    system = spheres()
    by_radius = getattr(tso.Tides, model)("primary", radius_m=400.0, time_lag=10.0)
    by_system = getattr(tso.Tides, model)("primary", system=system, time_lag=10.0)
    assert by_radius.k2 == pytest.approx(k2(0.4), rel=1e-14)
    assert by_system.k2 == pytest.approx(k2(0.4), rel=1e-12) and by_system.radius is None
    assert by_radius.coefficient(system) == pytest.approx(by_system.coefficient(system), rel=1e-12)


@pytest.mark.parametrize("name, model, a_eq", [
    ("1991 VH", "rubble_pile", 1704.0), ("1991 VH", "jacobson_scheeres", 2247.0),
    ("2003 YT1", "rubble_pile", 1037.0), ("2003 YT1", "jacobson_scheeres", 1402.0),
    ("2004 DC", "rubble_pile", 189.0), ("2004 DC", "jacobson_scheeres", 352.0),
])
def test_equilibria_of_the_papers_systems_are_those_in_the_physics_notes(name, model, a_eq):
    """The table of docs/physics.md §13.9 (Q = 100, B = -1e-3, catalogued heliocentric orbits)."""
    system = tso.catalog.system(name)
    tide = getattr(tso.Tides, model)("primary", system=system, Q=100.0)
    found = analytic.tide_byorp_equilibrium(system, tide, tso.BYORP(-1e-3))
    assert found == pytest.approx(a_eq, abs=0.5)
    assert found < system.a


def test_constant_q_rate_turns_smoothly_through_synchronism_as_in_the_kernels():
    """|ω − n| is floored at Q_RATE_FLOOR n (docs/physics.md §13.1): zero at ω = n, and
    1/sqrt(2) of the sign(ω − n) closed form where |ω − n| equals the floor."""
    system = spheres()
    n = system.mean_motion
    tide = tso.Tides(body="secondary", k2=2e-3, Q=30.0)
    far = analytic.tidal_despin_rate(system, tide, 3.0 * n)
    assert analytic.tidal_despin_rate(system, tide, n) == 0.0
    near = analytic.tidal_despin_rate(system, tide, (1.0 + 1e-3) * n)
    assert near == pytest.approx(far / math.sqrt(2.0), rel=1e-6)
