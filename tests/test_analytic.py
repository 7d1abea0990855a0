"""Analytic spin-orbit theory (ti_spinorbit.model.analytic) against hand values, tables and
independent routes.

* ψ_A and the mean-direction amplitude at hand values, and against an independent RK4
  integration of the decoupled spin-orbit equation with Kepler's equation solved by Newton.
* Cayley's H(p, e): the quadrature against the series (the gap shrinks as the first omitted
  power of e), against the tabulated values, at e = 0, and as Fourier coefficients that rebuild
  (a/r)³ exp(2if) at arbitrary M.
* Resonance half-widths, overlap thresholds (table of docs/physics.md §8.5), the
  chaotic-layer formula, ω0 ↔ a/b, the coupled-problem ω0.
* Energy budgets: E0 against 3n²(B − A)/4, k2 models at 1 km, tidal energy ∝ n⁴ R_s⁵ and
  YORP ∝ R_s³/d² by rescaling inputs.
* Bad inputs raise ValueError naming the parameter.
"""

import dataclasses
import math

import numpy as np
import pytest

from ti_spinorbit.model import analytic as an
from ti_spinorbit.system import catalog
from ti_spinorbit.system.systems import G

SERIES_P = (-0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0)
#: First power of e the tabulated series leave out, per p.
FIRST_OMITTED_POWER = {-0.5: 7, 0.5: 7, 1.0: 8, 1.5: 7, 2.0: 8, 2.5: 7, 3.0: 8}


def kepler(M, e):
    """True anomaly f and a/r at mean anomaly M (Newton on Kepler's equation, independent of
    the f-grid used inside cayley_H)."""
    E = np.array(M, dtype=float)
    for _ in range(30):
        E = E - (E - e * np.sin(E) - M) / (1.0 - e * np.cos(E))
    f = 2.0 * np.arctan2(np.sqrt(1.0 + e) * np.sin(E / 2), np.sqrt(1.0 - e) * np.cos(E / 2))
    return f, 1.0 / (1.0 - e * np.cos(E))


# ---- ω0 ---------------------------------------------------------------------------------------
def test_omega0_of_ellipsoid_hand_values_and_round_trip():
    assert an.omega0(1.0) == 0.0
    # q = 1.5: 3 (2.25 − 1)/(2.25 + 1) = 3.75/3.25
    assert an.omega0(1.5) == pytest.approx(math.sqrt(3.75 / 3.25), rel=1e-15)
    q = np.array([1.0, 1.01, 1.06, 1.3, 1.5, 3.0, 20.0])
    np.testing.assert_allclose(an.elongation_from_omega0(an.omega0(q)), q, rtol=1e-12)
    w = np.array([0.0, 0.2, 0.5, 1.0, 1.7])
    np.testing.assert_allclose(an.omega0(an.elongation_from_omega0(w)), w, atol=1e-14)


def test_omega0_from_moments_matches_ellipsoid_and_system():
    system = catalog.system("1991 VH")
    A, B, C = system.secondary.moments
    a, b, _ = system.secondary.semi_axes
    assert an.omega0_from_moments(A, B, C) == pytest.approx(an.omega0(a / b), rel=1e-13)
    assert an.omega0_from_moments(A, B, C) == pytest.approx(system.omega0, rel=1e-15)


def test_effective_omega0_of_1991VH_carries_primary_mass_fraction():
    system = catalog.system("1991 VH")
    m1, m2 = system.primary.mass, system.secondary.mass
    ratio = an.omega0_effective(system) / system.omega0
    assert ratio == pytest.approx(math.sqrt(m1 / (m1 + m2)), rel=1e-14)
    # mass ratio ≈ 12 (docs/physics.md §7): ω0 shifts by ~4 %, i.e. sqrt(12/13) ≈ 0.961
    assert 0.95 < ratio < 0.97


# ---- forced libration -------------------------------------------------------------------------
def test_psi_A_hand_value():
    # 2e/(ω0² − 1) = 0.1/(1.1449 − 1) = 0.1/0.1449 = 0.690131... rad
    assert an.psi_A(1.07, 0.05) == pytest.approx(0.1 / 0.1449, rel=1e-12)
    assert an.psi_A(1.07, 0.05) == pytest.approx(0.6901311249, rel=1e-9)
    # mean direction: 2eω0²/(ω0² − 1) = 0.1 · 1.1449/0.1449 = ψ_A + 2e
    assert an.forced_amplitude_mean_direction(1.07, 0.05) == pytest.approx(0.1 * 1.1449 / 0.1449)
    assert an.forced_amplitude_mean_direction(1.07, 0.05) == pytest.approx(
        an.psi_A(1.07, 0.05) + 0.1, rel=1e-12)
    # below the forced resonance the response is in antiphase and larger than 2e
    assert an.psi_A(0.5, 0.01) == pytest.approx(-0.02 / 0.75)


def test_psi_A_against_integration_of_decoupled_equation():
    """RK4 on θ'' = −(ω0²/2)(a/r)³ sin 2(θ − f), started on the forced solution at pericentre;
    the sin M component of θ − f over 20 orbits is ψ_A (docs/physics.md §8.2 table cases)."""
    e = np.array([0.01, 0.005, 0.02])
    w = np.array([0.5, 1.5, 0.3])
    orbits, steps = 20, 200
    h = 2.0 * np.pi / steps
    M = np.arange(2 * orbits * steps + 1) * h / 2          # nodes and midpoints of the steps
    f, a_over_r = kepler(M[:, None] * np.ones(3), e)
    k = (w**2 / 2) * a_over_r**3

    def acc(i, theta):
        return -k[i] * np.sin(2.0 * (theta - f[i]))

    theta, thetadot = np.zeros(3), 1.0 + an.forced_amplitude_mean_direction(w, e)
    history = []
    for j in range(orbits * steps):
        history.append(theta)
        i = 2 * j
        k1x, k1v = thetadot, acc(i, theta)
        k2x, k2v = thetadot + h / 2 * k1v, acc(i + 1, theta + h / 2 * k1x)
        k3x, k3v = thetadot + h / 2 * k2v, acc(i + 1, theta + h / 2 * k2x)
        k4x, k4v = thetadot + h * k3v, acc(i + 2, theta + h * k3x)
        theta = theta + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
        thetadot = thetadot + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    theta = np.array(history)
    M_nodes, f_nodes = M[:-1:2], f[:-1:2]
    sin_M = np.sin(M_nodes)[:, None]
    psi_amp = 2.0 * np.mean((theta - f_nodes) * sin_M, axis=0)
    mean_dir_amp = 2.0 * np.mean((theta - M_nodes[:, None]) * sin_M, axis=0)
    np.testing.assert_allclose(psi_amp, an.psi_A(w, e), rtol=3e-3)
    np.testing.assert_allclose(mean_dir_amp, an.forced_amplitude_mean_direction(w, e), rtol=3e-3)


# ---- Cayley's H -------------------------------------------------------------------------------
def test_cayley_H_tabulated_values():
    assert an.cayley_H(1.5, 0.05) == pytest.approx(0.17404026, abs=1e-8)
    assert an.cayley_H(1.0, 0.1) == pytest.approx(0.97508113, abs=1e-8)
    assert an.cayley_H_series(1.5, 0.05) == pytest.approx(0.17404026, abs=1e-8)
    assert an.cayley_H_series(1.0, 0.1) == pytest.approx(0.97508113, abs=1e-8)


@pytest.mark.parametrize("p", [-1.5, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.5])
def test_cayley_H_circular_orbit(p):
    assert an.cayley_H(p, 0.0) == pytest.approx(1.0 if p == 1.0 else 0.0, abs=1e-15)


def test_cayley_H_numeric_vs_series():
    e = np.linspace(0.0, 0.2, 21)
    for p in (1.0, 1.5):
        gap = np.abs(an.cayley_H(p, e) - an.cayley_H_series(p, e))
        assert np.all(gap <= 5 * e**6 + 1e-15), p
    # every tabulated series is right to its last term: the gap falls as e^(first omitted power)
    e = np.array([0.04, 0.08])
    for p, k in FIRST_OMITTED_POWER.items():
        gap = np.abs(an.cayley_H(p, e) - an.cayley_H_series(p, e))
        slope = math.log(gap[1] / gap[0]) / math.log(2.0)
        assert slope == pytest.approx(k, abs=0.1), p
    assert np.all(an.cayley_H_series(0.0, e) == 0.0)


def test_cayley_H_rebuilds_fourier_series():
    """(a/r)³ exp(2if) = Σ_p H(p, e) exp(2ipM), summed over p = −6 … 8 in steps of 1/2."""
    e = 0.05
    p = np.arange(-12, 17) / 2.0
    H = an.cayley_H(p, e)
    M = np.array([0.0, 0.3, 1.1, 2.0, math.pi, 4.4, 5.9])
    f, a_over_r = kepler(M, e)
    lhs = a_over_r**3 * np.exp(2j * f)
    rhs = np.exp(2j * np.outer(M, p)) @ H
    np.testing.assert_allclose(rhs.real, a_over_r**3 * np.cos(2 * f), atol=1e-6)
    np.testing.assert_allclose(rhs, lhs, atol=1e-6)


def test_cayley_H_vectorised_and_converged():
    e = np.array([0.0, 0.1, 0.3, 0.6])
    p = np.array([[0.5], [1.0], [2.5]])
    H = an.cayley_H(p, e)
    assert H.shape == (3, 4)
    assert H[1, 2] == an.cayley_H(1.0, 0.3)
    np.testing.assert_allclose(an.cayley_H(p, e, n=4096), an.cayley_H(p, e, n=16384), atol=1e-14)


# ---- resonance widths, overlap, chaotic layer ------------------------------------------------
def test_resonance_half_widths():
    # p = 1, e = 0.001: ω0 sqrt(1 − 5e²/2) ≈ 0.2; bisection in docs/physics.md §8.4: 0.19985/0.20006
    width = an.resonance_half_width(1.0, 0.2, 0.001)
    assert width == pytest.approx(0.2 * math.sqrt(1 - 2.5e-6), rel=1e-9)
    assert abs(width - 0.19985) < 3e-4 and abs(width - 0.20006) < 3e-4
    # p = 3/2: ω0 sqrt(7e/2) to leading order; mean of measured ± widths within ~2.5 %
    for w, e, plus, minus in [(0.15, 0.05, 0.0722, 0.0500), (0.1, 0.1, 0.0623, 0.0535)]:
        assert an.resonance_half_width(1.5, w, e) == pytest.approx((plus + minus) / 2, rel=0.03)
    assert an.resonance_half_width(0.5, 0.3, 0.02) == pytest.approx(0.3 * math.sqrt(0.01), rel=1e-3)


def test_overlap_threshold_table():
    e = np.array([0.01, 0.05, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(np.round(an.omega0_overlap(e), 3),
                                  [0.421, 0.353, 0.314, 0.272, 0.247])
    # at ω0_RO the synchronous and 3:2 separatrices touch: ω0 + ω0 sqrt(7e/2) = 1/2
    w = an.omega0_overlap(e)
    np.testing.assert_allclose(w * (1 + np.sqrt(3.5 * e)), 0.5, rtol=1e-14)


def test_overlap_elongation():
    e = 0.05
    q = an.overlap_elongation(e)
    assert an.omega0(q) == pytest.approx(an.omega0_overlap(e), rel=1e-12)
    # coupled problem: the ellipsoid needs ω0 larger by 1/sqrt(m1/(m1+m2)), so a larger a/b
    q_coupled = an.overlap_elongation(e, primary_mass_fraction=12 / 13)
    assert an.omega0(q_coupled) * math.sqrt(12 / 13) == pytest.approx(an.omega0_overlap(e))
    assert q_coupled > q


def test_chaotic_layer_hand_value():
    # ω0 = 0.5, e = 0.1: 14π · 0.1 / 0.125 · exp(−π) = 11.2π e^{−π} = 35.18584 · 0.04321392
    expected = 11.2 * math.pi * math.exp(-math.pi)
    assert an.chaotic_layer_half_width(0.5, 0.1) == pytest.approx(expected, rel=1e-14)
    assert expected == pytest.approx(1.520518, rel=1e-6)
    melnikov = an.chaotic_layer_half_width(0.5, 0.1, an.CHAOTIC_LAYER_COEFFICIENT_MELNIKOV)
    assert melnikov == pytest.approx(2 * expected)
    # docs/physics.md §8.6 table rows (e, ω0) -> 14π and 28π forms
    for e, w, quoted, mel in [(0.01, 0.25, 0.053, 0.105), (0.01, 0.30, 0.087, 0.173),
                              (0.003, 0.30, 0.026, 0.052), (0.02, 0.25, 0.105, 0.210)]:
        assert an.chaotic_layer_half_width(w, e) == pytest.approx(quoted, abs=6e-4)
        assert an.chaotic_layer_half_width(w, e, 28 * math.pi) == pytest.approx(mel, abs=6e-4)


# ---- energy budgets ---------------------------------------------------------------------------
def test_separatrix_energy():
    system = catalog.system("2003 YT1")
    A, B, C = system.secondary.moments
    n = system.mean_motion
    # n² ω0² C/4 with ω0² = 3(B − A)/C is 3 n² (B − A)/4
    assert an.separatrix_energy(system) == pytest.approx(0.75 * n**2 * (B - A), rel=1e-13)
    w_eff = an.omega0_effective(system)
    ratio = an.separatrix_energy(system, w_eff) / an.separatrix_energy(system)
    assert ratio == pytest.approx(system.primary.mass / system.total_mass, rel=1e-13)


def test_k2_models_at_one_km():
    assert an.love_number_k2(1000.0, "goldreich-sari") == pytest.approx(1e-5, rel=1e-15)
    assert an.love_number_k2(1000.0, "jacobson-scheeres") == pytest.approx(2.5e-5, rel=1e-15)
    assert an.love_number_k2(240.0, "goldreich-sari") == pytest.approx(2.4e-6)
    assert an.love_number_k2(240.0, "jacobson-scheeres") == pytest.approx(2.5e-5 / 0.24)


def test_tidal_energy_value_and_scaling():
    system = catalog.system("1991 VH")
    R = math.sqrt(catalog.entry("1991 VH")["ab"])                  # 240 m
    assert an.secondary_radius(system) == pytest.approx(R, rel=1e-14)
    n = system.mean_motion
    expected = math.pi * 1.5 * (2.4e-6 / 100) * n**4 / G * R**5
    assert an.tidal_energy_per_orbit(system) == pytest.approx(expected, rel=1e-13)
    # at fixed k2: ∝ n⁴ (a -> 2a makes n⁴ fall by 2⁶) and ∝ R_s⁵
    wide = dataclasses.replace(system, a=2 * system.a)
    base = an.tidal_energy_per_orbit(system, k2_model=1e-5)
    assert an.tidal_energy_per_orbit(wide, k2_model=1e-5) / base == \
        pytest.approx(2.0**-6, rel=1e-12)
    assert an.tidal_energy_per_orbit(system, k2_model=1e-5, radius=2 * R) / base == \
        pytest.approx(32.0, rel=1e-12)
    assert an.tidal_energy_per_orbit(system, k2_model=1e-5, Q=50) / base == pytest.approx(2.0)
    # with the radius-dependent k2: R⁶ (Goldreich & Sari), R⁴ (Jacobson & Scheeres)
    for model, power in (("goldreich-sari", 6), ("jacobson-scheeres", 4)):
        ratio = (an.tidal_energy_per_orbit(system, model, radius=2 * R)
                 / an.tidal_energy_per_orbit(system, model))
        assert ratio == pytest.approx(2.0**power, rel=1e-12)


def test_yorp_energy_value_and_scaling():
    system = catalog.system("2004 DC")
    R = an.secondary_radius(system)                                 # 30 m
    d = 1.5 * an.AU
    expected = (2 * math.pi * R**3 * 3.828e26 * 5e-4
                / (3 * 299792458.0 * d**2 * math.sqrt(1 - 0.2**2)))
    base = an.yorp_energy_per_orbit(system, 1.5, 0.2)
    assert base == pytest.approx(expected, rel=1e-13)
    assert an.yorp_energy_per_orbit(system, 3.0, 0.2) / base == pytest.approx(0.25, rel=1e-13)
    assert an.yorp_energy_per_orbit(system, 1.5, 0.2, radius=2 * R) / base == pytest.approx(8.0)
    assert an.yorp_energy_per_orbit(system, 1.5, 0.0) / base == pytest.approx(math.sqrt(0.96))


def test_energy_budget_is_consistent():
    system = catalog.system("1991 VH")
    budget = an.energy_budget(system, 1.14, 0.14)
    E0 = an.separatrix_energy(system)
    assert budget["E0_J"] == E0
    assert budget["chaotic_dE_over_E0"] == an.chaotic_layer_half_width(system.omega0, system.e)
    assert budget["chaotic_dE_over_E0_melnikov"] == pytest.approx(2 * budget["chaotic_dE_over_E0"])
    assert budget["tidal_dE_over_E0_goldreich_sari"] == pytest.approx(
        an.tidal_energy_per_orbit(system, "goldreich-sari") / E0)
    assert budget["tidal_dE_over_E0_jacobson_scheeres"] == pytest.approx(
        an.tidal_energy_per_orbit(system, "jacobson-scheeres") / E0)
    assert budget["yorp_dE_over_E0"] == pytest.approx(
        an.yorp_energy_per_orbit(system, 1.14, 0.14) / E0)
    # the paper's point: tides and YORP are many orders of magnitude below chaotic changes
    competing = max(budget["tidal_dE_over_E0_goldreich_sari"],
                    budget["tidal_dE_over_E0_jacobson_scheeres"], budget["yorp_dE_over_E0"])
    assert competing < 1e-4 * budget["chaotic_dE_over_E0"]


# ---- bad inputs -------------------------------------------------------------------------------
@pytest.mark.parametrize("call, name", [
    (lambda: an.psi_A(1.07, 1.0), "e"),
    (lambda: an.psi_A(1.07, -0.1), "e"),
    (lambda: an.psi_A(0.0, 0.05), "omega0"),
    (lambda: an.psi_A(-1.0, 0.05), "omega0"),
    (lambda: an.psi_A(1.0, 0.05), "omega0"),
    (lambda: an.forced_amplitude_mean_direction(np.nan, 0.05), "omega0"),
    (lambda: an.omega0(0.9), "a_over_b"),
    (lambda: an.omega0_from_moments(2.0, 1.0, 3.0), "A <= B <= C"),
    (lambda: an.omega0_from_moments(1.0, 2.0, -3.0), "C"),
    (lambda: an.elongation_from_omega0(1.8), "omega0"),
    (lambda: an.cayley_H(0.3, 0.1), "p"),
    (lambda: an.cayley_H(1.0, 1.0), "e"),
    (lambda: an.cayley_H(1.0, 0.1, n=4), "n"),
    (lambda: an.cayley_H_series(4.0, 0.1), "p"),
    (lambda: an.resonance_half_width(1.0, 0.0, 0.1), "omega0"),
    (lambda: an.omega0_overlap(-0.01), "e"),
    (lambda: an.overlap_elongation(0.05, primary_mass_fraction=0.0), "primary_mass_fraction"),
    (lambda: an.chaotic_layer_half_width(0.0, 0.1), "omega0"),
    (lambda: an.chaotic_layer_half_width(0.3, 0.1, coefficient=-1.0), "coefficient"),
    (lambda: an.love_number_k2(1000.0, "maxwell"), "k2_model"),
    (lambda: an.love_number_k2(0.0), "radius"),
    (lambda: an.tidal_energy_per_orbit(catalog.system("1991 VH"), Q=0), "Q"),
    (lambda: an.tidal_energy_per_orbit(catalog.system("1991 VH"), k2_model=-1e-5), "k2_model"),
    (lambda: an.yorp_energy_per_orbit(catalog.system("1991 VH"), 0.0, 0.1), "heliocentric_a_au"),
    (lambda: an.yorp_energy_per_orbit(catalog.system("1991 VH"), 1.0, 1.0), "heliocentric_e"),
    (lambda: an.yorp_energy_per_orbit(catalog.system("1991 VH"), 1.0, 0.1, f_yorp=0), "f_yorp"),
    (lambda: an.separatrix_energy(catalog.system("1991 VH"), omega0=-1.0), "omega0"),
])
def test_bad_inputs_name_the_parameter(call, name):
    with pytest.raises(ValueError, match=name):
        call()
