"""Relaxed-mode libration (docs/physics.md §9.1): the synchronous island's centre and amplitude in the
decoupled limit against first-order theory and against the decoupled equation solved
exactly, convergence of the search, the V fit, the libration check, and bad input."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import ti_spinorbit as tso
from ti_spinorbit.studies.classify import wrap_half_turn
from ti_spinorbit.studies.libration import (RelaxedLibration, _fit_v, libration_amplitude,
                                    relaxed_libration)

ORBITS = 60


def small_secondary_system(a):
    """A light secondary (a/b = 1.3, 26 m x 20 m x 15 m, mass ratio 1.3e5) on an e = 0.01
    orbit of semimajor axis ``a`` (m) about a 1 km sphere."""
    return tso.BinarySystem(tso.Sphere(1000, 2000), tso.Ellipsoid(26, 20, 15, 2000), a=a, e=0.01)


@pytest.fixture(scope="module")
def decoupled():
    """The decoupled limit: size/a = 5e-4."""
    return small_secondary_system(50000.0)


@pytest.fixture(scope="module")
def result(decoupled):
    return relaxed_libration(decoupled, orbits=ORBITS)


def decoupled_periodic_orbit(omega0, e):
    """Exact synchronous periodic solution of θ̈ = −(ω0²/2)(a/r)³ sin 2(θ − f) on a fixed Kepler
    orbit (docs/physics.md §8.1; time in 1/n). Symmetric about pericentre, it starts at
    θ = 0 and passes θ = π at apocentre (t = π). Returns its θ̇(0) and max |θ − f| (deg)."""
    def rhs(t, y):
        theta, thetadot, f = y
        one_plus = 1.0 + e * math.cos(f)
        r3 = ((1.0 - e * e) / one_plus) ** 3
        return [thetadot, -0.5 * omega0**2 / r3 * math.sin(2.0 * (theta - f)),
                one_plus**2 / (1.0 - e * e) ** 1.5]

    def solve(thetadot0, t_eval=None):
        return solve_ivp(rhs, (0.0, math.pi), [0.0, thetadot0, 0.0], method="DOP853",
                         rtol=1e-12, atol=1e-13, t_eval=t_eval)

    first_order = (1 + e) ** 2 / (1 - e * e) ** 1.5 + 2 * e / (omega0**2 - 1)
    center = brentq(lambda x: solve(x).y[0, -1] - math.pi, first_order - 0.02,
                    first_order + 0.02, xtol=1e-13)
    sol = solve(center, t_eval=np.linspace(0.0, math.pi, 4097))
    return center, math.degrees(np.max(np.abs(sol.y[0] - sol.y[2])))


def test_decoupled_limit_matches_forced_libration_theory(decoupled, result):
    """Decoupled limit (docs/physics.md §8.2). To first order in e the forced solution is
    ψ = θ − f = ψ_A sin M, ψ_A = 2e/(ω0² − 1), so the relaxed amplitude max |α| is |ψ_A|
    (ω0 = 0.877 < 1: ψ_A < 0, a phase of π). Its spin rate θ̇ = ḟ + ψ_A cos M (units of n) at
    pericentre (M = f = 0), where the start sits, with ḟ = (1 + e cos f)²/(1 − e²)^{3/2}:

        θ̇_p/n = (1 + e)²/(1 − e²)^{3/2} + ψ_A  ≈ 1 + 2e + ψ_A = 0.9335,

    the island centre. Terms of order e² and ψ_A³ (nonlinearity) are left out: about 1 % of
    ψ_A, 2e-4 of the centre. The exact periodic solution of the same decoupled equation then
    pins both far tighter: what is left is the finite size of the secondary (next test)."""
    e = decoupled.e
    omega0_eff = math.sqrt(decoupled.omega0**2 * decoupled.primary.mass / decoupled.total_mass)
    psi_A = 2 * e / (decoupled.omega0**2 - 1)
    assert psi_A < 0 and result.psi_A == pytest.approx(math.degrees(psi_A), rel=1e-12)
    assert result.omega0_effective == pytest.approx(omega0_eff, rel=1e-12)
    assert result.converged
    assert result.amplitude == pytest.approx(abs(result.psi_A), rel=0.03)
    first_order_center = (1 + e) ** 2 / (1 - e * e) ** 1.5 + psi_A
    assert result.centre_thetadot_p == pytest.approx(first_order_center, abs=1e-3)

    exact_center, exact_amplitude = decoupled_periodic_orbit(omega0_eff, e)
    assert result.centre_thetadot_p == pytest.approx(exact_center, abs=1e-5)
    assert result.amplitude == pytest.approx(exact_amplitude, rel=3e-4)


def test_departure_from_decoupled_limit_scales_as_size_over_a_squared(decoupled, result):
    """The secondary's size enters the full problem as (size/a)² (its quadrupole acts on the
    orbit, the orbit recoils). Ten times closer, the centre's offset from the exact decoupled
    solution is a hundred times larger (measured 1.05e-4 at size/a = 5e-3, 1.05e-6 at 5e-4)."""
    omega0_eff = math.sqrt(decoupled.omega0**2 * decoupled.primary.mass / decoupled.total_mass)
    exact_center, _ = decoupled_periodic_orbit(omega0_eff, decoupled.e)
    close = relaxed_libration(small_secondary_system(5000.0), orbits=ORBITS, xtol=1e-7)
    ratio = (close.centre_thetadot_p - exact_center) / (result.centre_thetadot_p - exact_center)
    assert ratio == pytest.approx(100.0, rel=0.1)


def test_centre_converged_and_amplitude_insensitive_to_tolerance(decoupled, result):
    """At the centre the excited mode is gone (extent ≪ 1°), and neither halving rtol nor
    doubling the sampling moves the answer by 1e-3."""
    assert isinstance(result, RelaxedLibration)
    assert result.extent < 1e-3
    # the zoom launches narrow in on the centre: extents fall by orders of magnitude
    best = [np.nanmin(e) for e in result.extents]
    assert best[-1] < 1e-4 * best[0]
    tighter = relaxed_libration(decoupled, orbits=ORBITS, rtol=0.5e-12)
    assert tighter.centre_thetadot_p == pytest.approx(result.centre_thetadot_p, abs=1e-6)
    assert tighter.amplitude == pytest.approx(result.amplitude, rel=1e-3)
    denser = libration_amplitude(decoupled, result.centre_thetadot_p, ORBITS,
                                 samples_per_orbit=2 * result.samples_per_orbit)
    assert denser == pytest.approx(result.amplitude, rel=1e-3)


def test_libration_amplitude_flags_circulation(decoupled):
    """A start in the synchronous island librates with a few degrees; one spinning at 2.5 n
    circulates (NaN). One launch, one value per member."""
    amplitude = libration_amplitude(decoupled, [0.93, 2.5], orbits=5, samples_per_orbit=64)
    assert amplitude.shape == (2,)
    assert 1.0 < amplitude[0] < 15.0 and np.isnan(amplitude[1])
    assert isinstance(libration_amplitude(decoupled, 0.93, orbits=1), float)


def test_v_fit_recovers_the_centre_of_unequal_arms():
    x = np.linspace(0.9, 1.0, 33)
    center = 0.94321
    extent = np.where(x < center, 61.0 * (center - x), 67.0 * (x - center))
    best = int(np.argmin(extent))
    assert _fit_v(x, extent, best) == pytest.approx(center, abs=1e-12)
    assert _fit_v(x, extent, 1) is None          # one point on the left arm is not a line


def test_wrap_half_turn():
    np.testing.assert_allclose(wrap_half_turn([0.0, 90.0, -90.0, 100.0, 179.0, -181.0, 360.0]),
                               [0.0, 90.0, 90.0, -80.0, -1.0, -1.0, 0.0])


@pytest.mark.parametrize("kwargs, match", [
    ({"orbits": 0}, "orbits"),
    ({"orbits": -5}, "orbits"),
    ({"orbits": float("nan")}, "orbits"),
    ({"rtol": 0}, "rtol"),
    ({"candidates": [0.5, 0.6, 0.7]}, "candidates"),
    ({"candidates": [0.9, 0.8, 0.7, 0.6, 0.5]}, "candidates"),
    ({"candidates": [0.5, 0.6, np.nan, 0.8, 0.9]}, "candidates"),
    ({"zoom_candidates": 32}, "zoom_candidates"),
    ({"zoom_candidates": 3}, "zoom_candidates"),
    ({"xtol": -1e-6}, "xtol"),
    ({"samples_per_orbit": 0}, "samples_per_orbit"),
])
def test_bad_input_names_the_parameter(decoupled, kwargs, match):
    with pytest.raises(ValueError, match=match):
        relaxed_libration(decoupled, **kwargs)


def test_bad_system():
    with pytest.raises(TypeError, match=r"^system must be a BinarySystem or a catalogue name \(got 5\)$"):
        relaxed_libration(5)
    with pytest.raises(ValueError, match="^unknown system '1991 XX'"):
        relaxed_libration("1991 XX")
    round_secondary = tso.BinarySystem(tso.Sphere(1000, 2000), tso.Sphere(20, 2000), 5000, 0.01)
    with pytest.raises(ValueError, match="elongated"):
        relaxed_libration(round_secondary)


def test_libration_amplitude_bad_input(decoupled):
    with pytest.raises(ValueError, match="orbits"):
        libration_amplitude(decoupled, 1.0, orbits=0)
    with pytest.raises(ValueError, match="samples_per_orbit"):
        libration_amplitude(decoupled, 1.0, orbits=1, samples_per_orbit=0)


def test_chaotic_zone_is_not_reported_as_a_centre():
    """1996 FG3 at a/b = 1.1: the free libration (~2 orbits) resonates with the e = 0.07
    forcing and θ_p = 0 holds no stable centre; the zoom window still narrows, but the trace
    at the 'centre' stays wide, so the search must say it did not converge."""
    import warnings

    import ti_spinorbit as tso
    from ti_spinorbit.studies.libration import relaxed_libration

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lib = relaxed_libration(tso.catalog.system("1996 FG3", elongation=1.1), orbits=120)
    assert not lib.converged and lib.extent > 1.0
    assert any("not converged" in str(w.message) for w in caught)
