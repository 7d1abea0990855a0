"""Chaos indicators from the shadow trajectory: MEGNO ⟨Y⟩ → 2 and a
Lyapunov exponent falling like ln t / t on regular orbits, ⟨Y⟩ ≫ 2 and a positive exponent on
chaotic ones; independent of tolerance, slot, and leaving the main trajectory untouched."""

import numpy as np
import pytest

import ti_spinorbit as tso

VH_STARTS = [0.83, 1.63, 2.53]      # libration in the 1:1 island, chaotic sea, circulation


@pytest.fixture(scope="module")
def vh_runs():
    vh = tso.catalog.system("1991 VH")
    return {rtol: tso.surface_of_section(vh, 0.0, VH_STARTS, orbits=200, rtol=rtol, indicators=True)
            for rtol in (1e-10, 1e-11)}


def test_megno_regular_and_chaotic(vh_runs):
    r = vh_runs[1e-11]
    assert r.megno[0] == pytest.approx(2.0, abs=0.2) and r.megno[2] == pytest.approx(2.0, abs=0.2)
    assert r.megno[1] > 10.0
    assert r.lyapunov[1] > 0.2                        # e-folds per orbit in the chaotic sea
    assert max(r.lyapunov[0], r.lyapunov[2]) < r.lyapunov[1] / 5


def test_chaotic_2004_dc():
    """The example: 2004 DC a/b = 1.3, θ̇_p/n = 1.39."""
    r = tso.surface_of_section(tso.catalog.system("2004 DC"), 0.0, 1.39, orbits=150,
                               rtol=1e-10, indicators=True)
    assert r.megno[0] > 20 and r.lyapunov[0] > 0.5


def test_indicators_agree_between_tolerances(vh_runs):
    a, b = vh_runs[1e-10], vh_runs[1e-11]
    np.testing.assert_allclose(a.megno[[0, 2]], b.megno[[0, 2]], atol=0.1)
    assert a.megno[1] > 10 and b.megno[1] > 10


def test_regular_exponent_decays_like_log_t_over_t():
    vh = tso.catalog.system("1991 VH")
    lam = [tso.surface_of_section(vh, 0.0, 2.53, orbits=k, rtol=1e-11, indicators=True).lyapunov[0]
           for k in (50, 400)]
    assert lam[1] < lam[0] / 4                       # ln(400)/400 ÷ ln(50)/50 ≈ 0.19


def test_indicators_leave_the_trajectory_unchanged_and_are_slot_independent():
    vh = tso.catalog.system("1991 VH")
    plain = tso.surface_of_section(vh, 0.0, [1.63, 0.83], orbits=20, rtol=1e-10)
    ind = tso.surface_of_section(vh, 0.0, [1.63, 0.83], orbits=20, rtol=1e-10, indicators=True)
    swapped = tso.surface_of_section(vh, 0.0, [0.83, 1.63, 2.0], orbits=20, rtol=1e-10,
                                     indicators=True)
    np.testing.assert_array_equal(plain.thetadot_p, ind.thetadot_p)
    assert np.all(np.isnan(plain.megno))
    assert ind.megno[0] == swapped.megno[1] and ind.megno[1] == swapped.megno[0]
    assert ind.lyapunov[0] == swapped.lyapunov[1]


def test_classification_uses_the_indicator():
    vh = tso.catalog.system("1991 VH")
    r = tso.surface_of_section(vh, 0.0, VH_STARTS, orbits=200, rtol=1e-10, indicators=True)
    cls = tso.classify_section(r)
    assert list(cls.classification) == ["resonant", "chaotic", "quasi-periodic"]
    np.testing.assert_array_equal(cls.megno, r.megno)
