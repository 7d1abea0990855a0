"""The planar model (kernels/planar_eom.py) against the general 3-D model.

Independent routes: the planar potential's coefficients come from moment-tensor contractions
with Legendre polynomials (ti_spinorbit/model/planar.py), the 3-D kernel uses explicit monomial
tables, and the 3-D kernel is itself checked against the NumPy tensor reference
(test_reference.py). Here: the planar right-hand side equals the 3-D one mapped through the
state conversion; trajectories converge to each other as the tolerance shrinks; the 3-D model
keeps a qualifying start planar; the conversions round-trip."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import planar as PL
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.kernels import advance as K
from ti_spinorbit.engine.members import Members


def rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def flat_lumpy_body():
    """A body with in-plane odd integrals (no mirror symmetry in x or y) but symmetric about
    its equator, so the planar model applies to it."""
    T = {(2, 0, 0): 0.30, (0, 2, 0): 0.20, (0, 0, 2): 0.10,
         (3, 0, 0): 0.021, (2, 1, 0): -0.013, (1, 2, 0): 0.008, (0, 3, 0): 0.011,
         (1, 0, 2): 0.004, (0, 1, 2): -0.003,
         (4, 0, 0): 0.19, (0, 4, 0): 0.09, (0, 0, 4): 0.03, (2, 2, 0): 0.04, (2, 0, 2): 0.02,
         (0, 2, 2): 0.015, (3, 1, 0): 0.012, (1, 3, 0): -0.007, (1, 1, 2): 0.002}
    return tso.Body(mass=1.0, integrals=T, bounding_radius=1.5, name="flat lumpy")


def random_planar_states(rng, par, y0):
    y = y0.copy()
    for k in range(len(y)):
        y[k, 0:2] = rng.normal(size=2) * 0.3 + [1.1, 0.2]
        y[k, 3:5] = rng.normal(size=2)
        y[k, 8], y[k, 11] = rng.normal(), rng.normal() + 1.0
        y[k, 12:21] = rz(rng.uniform(0, 2 * np.pi)).ravel()
        y[k, 21:30] = rz(rng.uniform(0, 2 * np.pi)).ravel()
    return y


def systems():
    vh = tso.catalog.system("1991 VH")
    test = tso.catalog.system("test")               # ellipsoidal, spinning primary
    pair = (flat_lumpy_body(), tso.Ellipsoid(0.4, 0.3, 0.25, mass=0.2))
    period = tso.BinarySystem(*pair, a=4.0, e=0.1).orbital_period
    lumpy = tso.BinarySystem(*pair, a=4.0, e=0.1, primary_spin_period=period / 3, name="lumpy")
    return [vh, test, lumpy]


def test_conversions_round_trip(rng):
    table = Members.from_starts(tso.catalog.system("1991 VH"), [0.0, 40.0, 170.0],
                                [0.8, 1.5, 2.2], 1000.0)
    par, y0 = table.par, table.y0
    y = random_planar_states(rng, par, y0)
    np.testing.assert_allclose(PL.to_spatial(PL.to_planar(y)), y, atol=1e-15)
    q = PL.to_planar(y)
    np.testing.assert_allclose(PL.to_planar(PL.to_spatial(q)), q, atol=1e-14)


@pytest.mark.parametrize("order,odd", [(0, False), (2, False), (3, True), (4, False), (4, True)])
@pytest.mark.parametrize("which", [0, 1, 2])
def test_planar_rhs_equals_the_3d_rhs(rng, which, order, odd):
    """d/dt to_planar(y) = J(y) f_3d(y): compared by Richardson-extrapolated central
    differences (error O(ε⁴) ≈ 1e-12 at ε = 1e-3)."""
    system = systems()[which]
    if odd != (which == 2) and order >= 3:
        pytest.skip("odd=True exactly for the body with odd integrals")
    table = Members.from_starts(system, [0.0] * 4, [1.0] * 4, 1000.0)
    par, y0 = table.par, table.y0
    y = random_planar_states(rng, par, y0)
    f3 = np.zeros_like(y)
    K.SPATIAL.evaluate_rhs(par, y, f3, order, odd)
    q = PL.to_planar(y)
    fp = np.zeros_like(q)
    K.PLANAR.evaluate_rhs(PL.parameter_rows(par), q, fp, order, odd)

    def central(eps):
        return (PL.to_planar(y + eps * f3) - PL.to_planar(y - eps * f3)) / (2 * eps)

    expected = (4 * central(5e-4) - central(1e-3)) / 3
    np.testing.assert_allclose(fp, expected, rtol=0, atol=1e-10 * np.abs(fp).max())


def test_fourier_coefficients_reproduce_the_legendre_terms(rng):
    row = systems()[2].parameter_row()[:29]
    psi = rng.uniform(0, 2 * np.pi, 50)
    L = PL.legendre_terms(row, psi)
    (a0, a2, b2), (a1, b1, a3, b3), (c0, c2, d2, c4, d4) = PL.fourier_coefficients(row)
    np.testing.assert_allclose(L[0], a0 + a2 * np.cos(2 * psi) + b2 * np.sin(2 * psi), atol=1e-15)
    np.testing.assert_allclose(L[1], a1 * np.cos(psi) + b1 * np.sin(psi) + a3 * np.cos(3 * psi)
                               + b3 * np.sin(3 * psi), atol=1e-15)
    np.testing.assert_allclose(L[2], c0 + c2 * np.cos(2 * psi) + d2 * np.sin(2 * psi)
                               + c4 * np.cos(4 * psi) + d4 * np.sin(4 * psi), atol=1e-15)


def test_model_choice_and_clear_errors():
    vh = tso.catalog.system("1991 VH")
    table = Members.from_starts(vh, [0.0, 30.0], [1.0, 1.5], 1000.0)
    par, y0 = table.par, table.y0
    assert np.all(PL.qualifies(par, y0))
    assert Ensemble(par, y0).model == "planar"
    assert Ensemble(par, y0, model="3d").model == "3d"
    tilted = y0.copy()
    tilted[1, 12:21] = (rz(0.3) @ np.array([[1, 0, 0], [0, np.cos(0.1), -np.sin(0.1)],
                                            [0, np.sin(0.1), np.cos(0.1)]])).ravel()
    assert list(PL.qualifies(par, tilted)) == [True, False]
    assert Ensemble(par, tilted).model == "3d"
    with pytest.raises(ValueError, match=r"model='planar'.*members \[1\]"):
        Ensemble(par, tilted, model="planar")
    with pytest.raises(ValueError, match="model must be"):
        Ensemble(par, y0, model="2d")
    # a body with an integral odd in z (not symmetric about its equator) disqualifies
    T = dict(flat_lumpy_body().integrals)
    T[(2, 0, 1)] = 0.005
    odd_z = tso.BinarySystem(tso.Body(1.0, T, 1.5), tso.Sphere(0.3, mass=0.1), a=4.0, e=0.1)
    table = Members.from_starts(odd_z, 0.0, 1.0, 1000.0)
    par2, y2 = table.par, table.y0
    assert not PL.qualifies(par2, y2)[0]


@pytest.fixture(scope="module")
def vh_pair():
    """1991 VH regular starts (1:1 libration, quasi-periodic) with both models at 3 tolerances."""
    vh = tso.catalog.system("1991 VH")
    table = Members.from_starts(vh, [0.0, 0.0], [0.83, 2.53], 1000.0)
    par, y0 = table.par, table.y0
    return {(rtol, m): Ensemble(par, y0, rtol=rtol, model=m).run(2 * np.pi * 30)
            for rtol in (1e-10, 1e-12) for m in ("planar", "3d")}


def test_planar_and_3d_sections_converge_to_each_other(vh_pair):
    """Same physics, different discretisations: the difference between the two models'
    section records is integration error, so it shrinks in proportion to the tolerance
    (measured: 5.7e-6 at 1e-10, 5.7e-8 at 1e-12 over 30 orbits), and both see the same
    crossings."""
    diff = {}
    for rtol in (1e-10, 1e-12):
        a, b = vh_pair[(rtol, "planar")], vh_pair[(rtol, "3d")]
        diff[rtol] = 0.0
        for k in range(2):
            assert len(a.events[k]) == len(b.events[k]) >= 29
            diff[rtol] = max(diff[rtol], np.abs(a.events[k] - b.events[k]).max())
    assert diff[1e-12] < 1e-6
    assert diff[1e-10] / diff[1e-12] > 30


def test_planar_conserves_energy_like_3d(vh_pair):
    for rtol in (1e-10, 1e-12):
        drifts = []
        for m in ("planar", "3d"):
            out = vh_pair[(rtol, m)]
            e0, e1 = out.diag_start[:, :3].sum(axis=1), out.diag_end[:, :3].sum(axis=1)
            drifts.append(np.abs((e1 - e0) / e0).max())
            lz0 = out.diag_start[:, [5, 8, 11]].sum(axis=1)
            lz1 = out.diag_end[:, [5, 8, 11]].sum(axis=1)
            assert np.abs((lz1 - lz0) / lz0).max() < 1e3 * rtol
        assert drifts[0] < 1e3 * rtol and drifts[0] < 3 * drifts[1]


def test_3d_model_keeps_a_qualifying_start_planar():
    table = Members.from_starts(systems()[2], [0.0, 50.0], [1.0, 1.7], 1000.0)
    par, y0 = table.par, table.y0
    out = Ensemble(par, y0, rtol=1e-10, model="3d").run(2 * np.pi * 5)
    assert np.all(PL.qualifies(par, out.y))


def test_planar_is_slot_and_window_invariant():
    vh = tso.catalog.system("1991 VH")
    table = Members.from_starts(vh, [0.0, 20.0, 60.0], [0.83, 1.63, 2.2], 1000.0)
    par, y0 = table.par, table.y0
    a = Ensemble(par, y0, rtol=1e-10).run(2 * np.pi * 12, window_orbits=3)
    b = Ensemble(par[::-1], y0[::-1], rtol=1e-10).run(2 * np.pi * 12, window_orbits=16)
    for k in range(3):
        np.testing.assert_array_equal(a.events[k], b.events[2 - k])
    np.testing.assert_array_equal(a.y, b.y[::-1])
