"""The paper's extras (Naidu & Margot 2015 §3, §7): the 2:1 capture probability of
Murray & Dermott eq. 5.110 checked against independent routes (quadrature of the tidal
averages, a hand-computed value, limits, a scaling symmetry and a direct integration of the
averaged equation with weak tides), and the numbering of the study scripts by the paper's
figures and sections."""

import math
import os
import re

import numpy as np
import pytest

from ti_spinorbit.model import analytic

EXPERIMENTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "experiments")


@pytest.mark.parametrize("e", [0.0, 0.05, 0.18, 0.3, 0.6])
def test_tidal_factors_are_orbit_averages(e):
    # independent route: average (a/r)^6 and (a/r)^6 df/dM over a uniform grid in M
    M = 2 * np.pi * np.arange(20000) / 20000
    E = M.copy()
    for _ in range(60):                                    # Kepler's equation by Newton
        E = E - (E - e * np.sin(E) - M) / (1 - e * np.cos(E))
    a_over_r = 1 / (1 - e * np.cos(E))
    fdot = np.sqrt(1 - e**2) * a_over_r**2                 # df/dM
    omega, big_n = analytic.tidal_torque_factors(e)
    assert omega == pytest.approx(np.mean(a_over_r**6), rel=1e-12)
    assert big_n == pytest.approx(np.mean(a_over_r**6 * fdot), rel=1e-12)


def test_mercury_by_hand():
    # p = 3/2, e = 0.206, (B - A)/C = 1.2e-4, by hand: H = 7e/2 - 123e^3/16 = 0.6538,
    # Omega = 1.3706, N = 1.7218, V = 1.5 - N/Omega = 0.2438,
    # P = 2/(1 + pi 0.2438/(2 * 0.018974 * 0.8086)) = 0.0773 (textbook: "about 7 %")
    w = math.sqrt(3 * 1.2e-4)
    assert analytic.tidal_offset_V(1.5, 0.206) == pytest.approx(0.2438, abs=1e-3)
    assert analytic.capture_probability(1.5, w, 0.206) == pytest.approx(0.0773, abs=5e-4)


def test_limits_and_symmetry():
    w, e = 1.074, 0.05
    width = w * math.sqrt(analytic.cayley_H(2, e))
    # weak offset: certain capture; strong offset: P -> 4 w sqrt(H) / (pi V)
    assert analytic.capture_probability(2, w, e, V=1e-9) == 1.0
    assert analytic.capture_probability(2, w, e, V=1e4) == pytest.approx(4 * width / (np.pi * 1e4), rel=1e-3)
    # P depends on V and omega0 sqrt|H| only through their ratio
    for s in (0.3, 2.0, 7.0):
        assert analytic.capture_probability(2, s * w, e, V=s * 0.9) == pytest.approx(
            analytic.capture_probability(2, w, e, V=0.9), rel=1e-13)
    # monotonic: larger e (wider 2:1 island) captures more often
    ps = analytic.capture_probability(2, w, np.array([0.02, 0.05, 0.1, 0.2, 0.3]))
    assert np.all(np.diff(ps) > 0) and np.all((ps > 0) & (ps <= 1))


@pytest.mark.parametrize("p, e, message", [
    (1, 0.1, "V = p - N(e)/Omega(e) must be > 0"),       # tides stop the spin above 1:1
    (2, 0.0, "e must be > 0 for p = 2"),
    (2.3, 0.1, "p must be an integer or half-integer"),
])
def test_capture_probability_rejects(p, e, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        analytic.capture_probability(p, 1.0, e)


def test_capture_probability_matches_a_direct_integration():
    """Integrate the averaged equation γ̈ = −(ω0²/2) H sin 2γ − k (V + γ̇) (time 1/n) from
    1.3–1.5 half-widths above the 2:1 resonance with random phases and weak tides; a spin that
    escapes circulates backwards (γ falls by more than one turn of the pendulum, 2π, from its
    highest value), a captured one stays in its well."""
    w, e, k = 1.074, 0.05, 1e-4       # weak: tides take ~1 % of the well's depth per pass
    H = analytic.cayley_H(2, e)
    V = analytic.tidal_offset_V(2, e)
    width = w * math.sqrt(H)
    rng = np.random.default_rng(1)
    n = 2000
    y = np.array([rng.uniform(-np.pi, np.pi, n), rng.uniform(1.3 * width, 1.5 * width, n)])
    top = y[0].copy()

    def rhs(y):
        return np.array([y[1], -0.5 * w * w * H * np.sin(2 * y[0]) - k * (V + y[1])])

    dt = 0.2                      # the libration period is ~30: RK4 converged to << 1 %
    for _ in range(int(1800 / dt)):               # all arrive by ~700, all decided by ~1600                    # RK4
        k1 = rhs(y); k2 = rhs(y + dt / 2 * k1); k3 = rhs(y + dt / 2 * k2); k4 = rhs(y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        np.maximum(top, y[0], out=top)
    fall = top - y[0]
    assert np.all((fall < np.pi) | (fall > 2 * np.pi))          # two clean outcomes
    captured = np.mean(fall < np.pi)
    expected = analytic.capture_probability(2, w, e)
    assert expected == pytest.approx(0.1833, abs=1e-3)
    assert captured == pytest.approx(expected, abs=0.03)        # 3.5 sigma of 2000 draws


# ---- nonlinear relaxed libration of the decoupled problem -----------------------------------
@pytest.mark.parametrize("w, e", [(1.5, 0.005), (0.5, 0.01), (1.3, 0.01)])   # O(e²) left out
def test_decoupled_libration_tends_to_psi_A(w, e):
    center, amp = analytic.decoupled_relaxed_libration(w, e)
    assert amp == pytest.approx(abs(analytic.psi_A(w, e)), rel=3e-3)
    linear = (1 + e) ** 2 / (1 - e * e) ** 1.5 + analytic.psi_A(w, e)
    assert center == pytest.approx(linear, abs=2e-3)


@pytest.mark.parametrize("w, e", [(1.0318, 0.05), (0.877, 0.025), (1.0, 0.05)])
def test_decoupled_libration_is_a_periodic_orbit(w, e):
    """Independent route: scipy's DOP853 over a whole orbit from the centre found returns to
    the start (θ(2π) = 2π, same spin rate) and its max |θ − f| is the amplitude."""
    solve_ivp = pytest.importorskip("scipy.integrate").solve_ivp
    center, amp = analytic.decoupled_relaxed_libration(w, e)

    def rhs(t, y):
        theta, thetadot, f = y
        one_plus = 1 + e * np.cos(f)
        return [thetadot, -0.5 * w * w * (one_plus / (1 - e * e)) ** 3 * np.sin(2 * (theta - f)),
                one_plus**2 / (1 - e * e) ** 1.5]

    t = np.linspace(0, 2 * np.pi, 4001)
    sol = solve_ivp(rhs, (0, 2 * np.pi), [0.0, center, 0.0], method="DOP853", rtol=1e-12,
                    atol=1e-12, t_eval=t)
    assert sol.y[0, -1] == pytest.approx(2 * np.pi, abs=1e-6)
    assert sol.y[1, -1] == pytest.approx(center, abs=1e-6)
    assert np.max(np.abs(sol.y[0] - sol.y[2])) == pytest.approx(amp, rel=1e-4)


def test_decoupled_libration_stays_finite_where_psi_A_diverges():
    # at the nominal 1991 VH mass ratio ω0,eff = 1.0318: ψ_A says 88.7°, the pendulum 37.7°
    assert math.degrees(abs(analytic.psi_A(1.0318, 0.05))) == pytest.approx(88.68, abs=0.01)
    assert math.degrees(analytic.decoupled_relaxed_libration(1.0318, 0.05)[1]) == pytest.approx(37.66, abs=0.02)
    with pytest.raises(ValueError, match=re.escape("omega0 must lie in (0.0, 1.8]")):
        analytic.decoupled_relaxed_libration(2.0, 0.01)
