"""The Sun's tide (``tso.SolarTide``, docs/physics.md §13.11) validated by independent routes:
the relative orbit over one whole heliocentric orbit against REBOUND (WHFast, the Sun and two
point masses), the suppression of Kozai cycles by the primary's oblateness against the
secular theory and its linear criterion (Fang & Margot 2012, AJ 143, 59), and the work
accounting E − W converging with the tolerance while E itself changes by orders more."""

import math

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.constants import AU, GM_SUN
from ti_spinorbit.engine import accuracy
from ti_spinorbit.system.bodies import Ellipsoid, Sphere
from ti_spinorbit.system.systems import G

from test_solar_tide import _kepler_state


def _rotation(inclination_deg, node_deg, periapsis_deg):
    """Rz(Ω) Rx(i) Rz(ω): the heliocentric orbit's plane to the inertial frame (own copy)."""
    def rz(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    i = math.radians(inclination_deg)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(i), -math.sin(i)],
                   [0.0, math.sin(i), math.cos(i)]])
    return rz(math.radians(node_deg)) @ rx @ rz(math.radians(periapsis_deg))


def _eccentricity(R, V, mu):
    """Osculating eccentricity vectors of the relative orbit, one per row."""
    r, v2 = np.linalg.norm(R, axis=1), np.sum(V * V, axis=1)
    return ((v2 - mu / r)[:, None] * R - np.sum(R * V, axis=1)[:, None] * V) / mu


# --- 1. one whole heliocentric orbit against REBOUND ---------------------------------------

def test_relative_orbit_over_one_heliocentric_orbit_agrees_with_rebound():
    """A wide binary of two spheres (radii 50 and 5 km, 1600 km apart, e = 0.05: a Hill-radius
    fraction of 0.27 at perihelion, the Sun's tide 0.8 % of the mutual gravity there) on an
    eccentric heliocentric orbit (a⊙ = 1 AU, e⊙ = 0.3, 30° out of the mutual orbit plane),
    over one whole heliocentric orbit (20.8 mutual orbits, up to the first sample past P⊙),
    sampled 16 times a mutual orbit: the relative vector secondary − primary equals REBOUND's
    to 5e-10 of the separation (1.4e-10 measured), where the Sun moves it by more than the
    separation itself (1.3 separations).

    The package runs DOP853 at rtol 1e-12 (it agrees with Verner 9(8) at 1e-14 to 2e-12; the
    default Cash–Karp reaches 4e-9 at rtol 1e-13, falling as rtol). REBOUND runs the Sun and
    two point masses (spheres are point masses here) from the same heliocentric elements,
    with WHFast in Jacobi coordinates (the pair first, so its relative vector is a Jacobi
    coordinate kept at full precision; the pair's mutual Kepler motion is solved exactly and
    the Sun enters as the interaction), symplectic correctors of order 11 and 2000 steps per
    sample: its error falls as dt² to a floor of 1.5e-10 (2e-8 at 100 steps, 2e-10 at 1000).
    IAS15 is not used because in inertial coordinates at 1 AU its round-off leaves the pair's
    relative vector with errors of 1e-9 to 2e-8 of the separation over this orbit, depending
    on where the origin is put. A Sun mass off by 1e-8 moves the package's orbit by 1.5e-8 of
    the separation, 30 times the tolerance."""
    rebound = pytest.importorskip("rebound")
    system = tso.BinarySystem(Sphere(50e3, 2000.0), Sphere(5e3, 2000.0), a=1.6e6, e=0.05,
                              name="wide binary")
    a_au, e_s, inc, node, peri, M0 = 1.0, 0.3, 30.0, 40.0, 10.0, 30.0
    sun = tso.SolarTide(heliocentric_a_au=a_au, heliocentric_e=e_s, inclination_deg=inc,
                        node_deg=node, periapsis_deg=peri, mean_anomaly_deg=M0, strength=1.0)
    assert 5e-3 < sun.tide_ratio(system) < 1e-2
    m1, m2 = system.primary.mass, system.secondary.mass
    mu_h = GM_SUN + G * (m1 + m2)
    period = 2.0 * math.pi * math.sqrt((a_au * AU) ** 3 / mu_h)
    spo = 16
    orbits = math.ceil(period / system.orbital_period * spo) / spo    # the last sample ≥ P⊙
    kw = dict(orbits=orbits, samples_per_orbit=spo, rtol=1e-12, states=True)
    ts = tso.time_series(system, 0.0, [1.0], perturbations=[sun], **kw,
                         integrator=tso.Integrator(method="dop853", model="3d"))
    bare = tso.time_series(system, 0.0, [1.0], **kw,
                           integrator=tso.Integrator(method="dop853", model="3d"))
    assert accuracy.usable(ts.status).all()
    t = ts.t[0]
    assert period <= t[-1] < period + system.orbital_period / spo and len(t) > 300
    dt = t[1] - t[0]
    assert np.allclose(np.diff(t), dt, rtol=1e-9)
    R, V = ts.states[0][:, 0:3], ts.states[0][:, 3:6]
    sep = np.linalg.norm(R, axis=1)

    # the barycentre's heliocentric state from the elements (own Kepler solution and rotation)
    rot = _rotation(inc, node, peri)
    r_h, v_h = _kepler_state(a_au * AU, e_s, math.radians(M0), mu_h)
    r_h, v_h = rot @ r_h, rot @ v_h
    nu = m2 / (m1 + m2)
    # inertial frame moving with the barycentre's initial velocity, origin at it
    sim = rebound.Simulation()
    sim.G = G
    for m, f in ((m1, -nu), (m2, 1.0 - nu)):
        sim.add(m=m, x=f * R[0, 0], y=f * R[0, 1], z=f * R[0, 2],
                vx=f * V[0, 0], vy=f * V[0, 1], vz=f * V[0, 2])
    sim.add(m=GM_SUN / G, x=-r_h[0], y=-r_h[1], z=-r_h[2], vx=-v_h[0], vy=-v_h[1], vz=-v_h[2])
    sim.integrator = "whfast"
    steps = 2000
    sim.dt = dt / steps
    sim.integrator.corrector = 11
    sim.integrator.safe_mode = 0
    sim.integrator.keep_unsynchronized = 1
    theirs = np.empty_like(R)
    theirs[0] = R[0]
    for k in range(1, len(t)):
        sim.steps(steps)
        sim.synchronize()
        p = sim.particles
        theirs[k] = np.array(p[1].xyz) - np.array(p[0].xyz)
    err = np.linalg.norm(R - theirs, axis=1) / sep
    moved = np.linalg.norm(R - bare.states[0][:, 0:3], axis=1) / sep
    assert err.max() < 5e-10, err.max()
    assert moved.max() > 0.5, moved.max()


# --- 2. Kozai cycles suppressed by the primary's oblateness -------------------------------

KOZAI_INCLINATION = 65.0
LAMBDA_CRITICAL = 4.0 * math.sin(math.radians(KOZAI_INCLINATION)) ** 2 - 1.0     # 2.29
E_KOZAI = math.sqrt(1.0 - 5.0 / 3.0 * math.cos(math.radians(KOZAI_INCLINATION)) ** 2)  # 0.838


def _oblate_binary(lam, e0=0.02, separation=8.0, sun_periods=40.0, kozai_orbits=200.0):
    """A primary of fixed mass (that of a 5 km sphere at 2000 kg m⁻³) flattened to the
    homogeneous oblate ellipsoid (A, A, c) whose J2 gives Λ = ω̇_J2 t_K = ``lam``, spinning
    in 3 h about its short axis, the orbit normal, with a 300 m moonlet ``separation``
    volume radii away; the Sun on a circular orbit of ``sun_periods`` mutual periods,
    65° out of the mutual orbit plane, its strength set so that t_K = ``kozai_orbits``
    mutual periods. Returns (system, sun, t_K in s, Λ from the built bodies)."""
    from scipy.optimize import brentq

    req, rho = 5000.0, 2000.0
    m1 = 4.0 / 3.0 * math.pi * req ** 3 * rho
    moon = Sphere(300.0, rho)
    a = separation * req
    m = m1 + moon.mass
    n = math.sqrt(G * m / a ** 3)
    P = 2.0 * math.pi / n
    n_sun = 2.0 * math.pi / (sun_periods * P)
    a_sun = ((GM_SUN + G * m) / n_sun ** 2) ** (1.0 / 3.0)
    t_k = kozai_orbits * P
    strength = 4.0 / 3.0 * n * a_sun ** 3 / (GM_SUN * t_k)     # t_K = (4/3) n a⊙³ / (G s M⊙)
    j2r2 = lam * a ** 2 * (1.0 - e0 ** 2) ** 2 / (1.5 * n * t_k)
    # J2 R² = (A² − c²)/5 with A = req q^(−1/3), c = req q^(2/3) (the volume kept)
    q = brentq(lambda q: req ** 2 * (q ** (-2 / 3) - q ** (4 / 3)) / 5.0 - j2r2, 0.05, 1.0)
    A, c = req * q ** (-1.0 / 3.0), req * q ** (2.0 / 3.0)
    primary = Ellipsoid(A, A, c, m1 / (4.0 / 3.0 * math.pi * A * A * c))
    system = tso.BinarySystem(primary, moon, a=a, e=e0, primary_spin_period=3 * 3600.0,
                              name="oblate wide binary")
    sun = tso.SolarTide(heliocentric_a_au=a_sun / AU, heliocentric_e=0.0,
                        inclination_deg=KOZAI_INCLINATION, node_deg=0.0, periapsis_deg=0.0,
                        mean_anomaly_deg=0.0, strength=strength)
    # Λ again, from the bodies as built (their moments) and the Sun's block
    Ix, Iy, Iz = primary.moments
    j2r2_built = (Iz - 0.5 * (Ix + Iy)) / primary.mass
    n_built = math.sqrt(G * system.total_mass / system.a ** 3)
    a_s, e_s = sun.orbit(system)
    t_k_built = 4.0 / 3.0 * n_built * a_s ** 3 * (1 - e_s ** 2) ** 1.5 / (sun.strength * GM_SUN)
    omega_j2 = 1.5 * n_built * j2r2_built / system.a ** 2 / (1.0 - system.e ** 2) ** 2
    return system, sun, t_k_built, omega_j2 * t_k_built


def _secular_e_max(lam, e0, duration, inclination_deg=KOZAI_INCLINATION):
    """e_max over ``duration`` (units of t_K) of the doubly averaged quadrupole equations of
    the test-particle limit (Tremaine, Touma & Kazandjian 2009, vector form) with the
    orbit-averaged J2 potential of a primary whose pole ŝ stays fixed (its spin angular
    momentum is 500 times the orbit's):

        dj/dt = [(j·n)(j×n) − 5(e·n)(e×n)]/t_K + ω (j·ŝ) u^(−5/2) (j×ŝ),
        de/dt = [(j·n)(e×n) + 2 j×e − 5(e·n)(j×n)]/t_K
                + (ω/2) u^(−5/2) [(5(j·ŝ)²/u − 1) j×e + 2 (j·ŝ) e×ŝ],

    u = 1 − e², ω = (3/2) n J2 (R/a)² = Λ/t_K (from Φ_J2 = −(G m J2 R²/4a³) [3(j·ŝ)² − u] u^(−5/2)
    by the Milankovitch equations; at e → 0 in the equator it is the apsidal rate
    (3/2) n J2 (R/a)²), from the start j = sqrt(1 − e0²) ŝ, e = e0 x̂ (the standard start)."""
    from scipy.integrate import solve_ivp

    i = math.radians(inclination_deg)
    n_hat = np.array([0.0, -math.sin(i), math.cos(i)])     # Rx(i) ẑ: the Sun's orbit normal
    s_hat = np.array([0.0, 0.0, 1.0])

    def rhs(_, y):
        j, e = y[:3], y[3:]
        u = 1.0 - e @ e
        js = j @ s_hat
        dj = ((j @ n_hat) * np.cross(j, n_hat) - 5 * (e @ n_hat) * np.cross(e, n_hat)
              + lam * js * u ** -2.5 * np.cross(j, s_hat))
        de = ((j @ n_hat) * np.cross(e, n_hat) + 2 * np.cross(j, e)
              - 5 * (e @ n_hat) * np.cross(j, n_hat)
              + 0.5 * lam * u ** -2.5 * ((5 * js ** 2 / u - 1) * np.cross(j, e)
                                         + 2 * js * np.cross(e, s_hat)))
        return np.concatenate([dj, de])

    y0 = np.concatenate([math.sqrt(1 - e0 ** 2) * s_hat, [e0, 0.0, 0.0]])
    sol = solve_ivp(rhs, (0.0, duration), y0, rtol=1e-10, atol=1e-12, max_step=0.01,
                    t_eval=np.linspace(0.0, duration, 2001))
    return float(np.linalg.norm(sol.y[3:], axis=0).max())


@pytest.mark.slow
@pytest.mark.parametrize("lam, duration, regime", [
    (0.1, 4.0, "cycles"),          # J2 precession 10 times slower than Kozai
    (1.8, 8.0, "reduced"),         # 0.79 of the criterion: cycles, smaller
    (3.0, 4.0, "suppressed"),      # 1.31 of the criterion: e stays near e0
    (10.0, 4.0, "suppressed"),     # J2 precession 10 times faster than Kozai
])
def test_kozai_cycles_suppressed_by_the_primarys_oblateness(lam, duration, regime):
    """Kozai cycles of a wide binary (a moonlet 8 primary radii out, e0 = 0.02, 65° out of a
    circular heliocentric orbit) and their suppression by the primary's oblateness, against
    the ratio of the two precession rates (Fang & Margot 2012 compare the two timescales):

        Λ = ω̇_J2 t_K,   ω̇_J2 = (3/2) n J2 (R/a)² / (1 − e²)²   (apsidal, equatorial orbit),
        t_K = (2/(3π)) (P⊙² / P) (1 − e⊙²)^{3/2} (M⊙ + m1 + m2) / (s M⊙)

    (Kiseleva, Eggleton & Mikkola 1998; = (4/3) n a⊙³ (1 − e⊙²)^{3/2} / (G s M⊙), the inverse
    of the rate 3/(4τ) of Tremaine, Touma & Kazandjian's equations), with J2 R² = (C − A)/m1
    ((A² − c²)/5 for the homogeneous ellipsoid). ``strength`` s multiplies the Sun's mass in
    the force but not in its motion, so t_K ∝ 1/s at a fixed P⊙ and Λ ∝ J2/s: the critical
    J2 scales as s, the critical separation at a fixed J2 as s^(−1/5). Here s = 1.7 sets
    t_K = 200 mutual periods (5 heliocentric ones, P⊙ = 40 P at a⊙ = 0.39 AU), the Kozai
    time short enough for a few-second run and still long against P⊙.

    The criterion: linearising the secular equations about e = 0 with the orbit plane held
    in the primary's equator, in axes with x on the node of the Sun's plane,
    t_K de_x/dt = (4 sin² i − 1 − Λ) e_y and t_K de_y/dt = (1 + sin² i + Λ) e_x, so e grows
    only while Λ < Λ_c = 4 sin² i − 1 (2.29 at 65°; with the plane free to regress about the
    Sun's normal the same analysis gives 5 sin² i − 2 = 2.11, the classic 39.2° at Λ = 0).

    The cases and what they hold (observed values in brackets; the secular reference, the
    doubly averaged equations with J2 integrated from the same start, in braces):

    * Λ = 0.1: e_max ≥ 0.9 sqrt(1 − (5/3) cos² i) = 0.754 within 4 t_K [0.776] and within
      0.03 of the secular reference {0.771};
    * Λ = 1.8 = 0.79 Λ_c: cycles, reduced, 0.15 < e_max < 0.6 within 8 t_K [0.278] {0.396}
      (near Λ_c the growth rate, ∝ sqrt(Λ_c − Λ), is sensitive to the non-averaged terms,
      which here act as a Λ about 14 % larger);
    * Λ = 3.0 = 1.31 Λ_c: suppressed, e_max ≤ 2.5 e0 within 4 t_K [0.038] {0.051};
    * Λ = 10: suppressed, e_max ≤ 1.5 e0 [0.021] {0.025}.

    Each case also checks that Λ computed back from the bodies as built (their moments, the
    Sun's orbit and strength) is the one asked for; a J2 precession off by a factor 2 would
    put the 1.8 case above Λ_c."""
    system, sun, t_k, lam_built = _oblate_binary(lam)
    assert lam_built == pytest.approx(lam, rel=1e-9)
    assert sun.tide_ratio(system) < 2e-3
    e0 = system.e
    ts = tso.time_series(system, 0.0, [1.0], orbits=duration * t_k / system.orbital_period,
                         samples_per_orbit=2, perturbations=[sun], rtol=1e-9, states=True)
    assert accuracy.usable(ts.status).all(), ts.status
    R, V = ts.states[0][:, 0:3], ts.states[0][:, 3:6]
    e_max = float(np.linalg.norm(_eccentricity(R, V, G * system.total_mass), axis=1).max())
    secular = _secular_e_max(lam, e0, duration)
    if regime == "cycles":
        assert e_max >= 0.9 * E_KOZAI, e_max
        assert abs(e_max - secular) < 0.03, (e_max, secular)
    elif regime == "reduced":
        assert lam < LAMBDA_CRITICAL and 0.15 < e_max < 0.6, e_max
        assert 0.15 < secular < 0.6, secular
    else:
        assert lam > LAMBDA_CRITICAL
        assert e_max <= (2.5 if lam < 5 else 1.5) * e0, e_max
        assert secular <= 3.0 * e0, secular


# --- 3. the work accounting converges with the tolerance ------------------------------------

def test_energy_minus_work_drifts_linearly_in_rtol_while_energy_changes():
    """Tilted ellipsoids (the primary's pole 15° off the orbit normal) under a strong Sun
    (×5, a⊙ = 0.3 AU, e⊙ = 0.1, 40° out of the orbit plane, so that both the force and the
    torques do work) over ten orbits, at rtol 1e-9, 1e-10 and 1e-11: the largest relative
    drift of E − W over the run (8.8e-8, 8.8e-9, 8.8e-10 measured) falls as rtol^p with p
    fitted on log-log axes within 0.7…1.3 (1.000 measured), while E itself changes by
    6.3e-3 at every tolerance: |ΔE| ≥ 1e4 |Δ(E − W)| at each (7e4 measured at rtol 1e-9;
    the issue asks 100). A work term left out or mis-scaled would leave an rtol-independent
    part in E − W and flatten the slope."""
    system = tso.BinarySystem(Ellipsoid(300.0, 250.0, 200.0, 2000.0),
                              Ellipsoid(100.0, 80.0, 70.0, 2000.0), a=1500.0, e=0.1,
                              name="ellipsoids")
    sun = tso.SolarTide(heliocentric_a_au=0.3, heliocentric_e=0.1, inclination_deg=40.0,
                        node_deg=20.0, periapsis_deg=60.0, mean_anomaly_deg=30.0,
                        strength=5.0)
    start = system.tilted_start(10.0, 1.2, pitch=20.0, roll=10.0, inclination=0.0,
                                primary_tilt=15.0)
    rtols = (1e-9, 1e-10, 1e-11)
    drift, change = [], []
    for rtol in rtols:
        ts = tso.time_series(system, initial_states=[start], orbits=10, samples_per_orbit=8,
                             perturbations=[sun], rtol=rtol)
        assert accuracy.usable(ts.status).all()
        E, W = ts.energy[0], ts.work[0]
        scale = abs(E[0])
        change.append(np.abs(E - E[0]).max() / scale)
        drift.append(np.abs(E - W - E[0]).max() / scale)
        # the verdict's drift is that of E − W at the end
        assert ts.energy_drift[0] == pytest.approx(abs(E[-1] - W[-1] - E[0]) / scale, rel=1e-6)
        assert change[-1] > 1e-3 and change[-1] >= 1e4 * drift[-1], (rtol, change[-1], drift[-1])
    slope = np.polyfit(np.log10(rtols), np.log10(drift), 1)[0]
    assert 0.7 <= slope <= 1.3, (slope, drift)
    assert max(change) / min(change) < 1.0 + 1e-4        # E's change is physics, not error
