"""Integrated dynamics: exact Kepler orbits, planarity, ensemble invariance, conservation
with tolerance scaling, agreement with the scipy-driven reference, failure flags."""

import numpy as np
import pytest

import ti_spinorbit as tso

from conftest import run_options
from ti_spinorbit.model import reference
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.kernels import eom
from ti_spinorbit.kernels.advance import COLLISION, DONE, ESCAPE, NONFINITE, RUNNING
from ti_spinorbit.engine.members import Members

DAY = 86400.0


def test_two_spheres_follow_kepler():
    """Pericentre times k·P, pericentre distance a(1−e) and osculating a, e to 1e-9."""
    two = tso.BinarySystem(tso.Sphere(500, 2000), tso.Sphere(100, 2000), 3000, 0.3)
    r = tso.surface_of_section(two, 0.0, 0.0, orbits=10.5, rtol=1e-12)
    assert r.count[0] == 10 and r.status[0] == DONE
    k = np.arange(1, 11)
    np.testing.assert_allclose(r.t[0, :10] / two.orbital_period, k, rtol=0, atol=1e-9)
    np.testing.assert_allclose(r.r[0, :10], 3000 * 0.7, rtol=1e-9)
    np.testing.assert_allclose(r.a[0, :10], 3000, rtol=1e-9)
    np.testing.assert_allclose(r.e[0, :10], 0.3, rtol=0, atol=1e-9)


def test_kepler_time_series_matches_analytic_radius():
    """Dense samples land on the requested times and r(t) is the Kepler solution."""
    two = tso.BinarySystem(tso.Sphere(500, 2000), tso.Sphere(100, 2000), 3000, 0.2)
    ts = tso.time_series(two, 0.0, 0.0, orbits=2, samples_per_orbit=50, rtol=1e-12)
    t = ts.t[0]
    np.testing.assert_allclose(t, np.arange(101) * two.orbital_period / 50, rtol=1e-13, atol=1e-9)
    M = two.mean_motion * t
    E = M.copy()
    for _ in range(50):
        E = E - (E - 0.2 * np.sin(E) - M) / (1 - 0.2 * np.cos(E))
    np.testing.assert_allclose(ts.r[0], 3000 * (1 - 0.2 * np.cos(E)), rtol=1e-9)


def test_planar_start_stays_planar(vh):
    table = Members.from_starts(vh, [0.0, 40.0], [0.8, 1.6])
    par, y0 = table.par, table.y0
    ens = Ensemble(par, y0, rtol=1e-11)
    out = ens.run(2 * np.pi * 5)
    z = [eom.Y_R + 2, eom.Y_V + 2, eom.Y_W1, eom.Y_W1 + 1, eom.Y_W2, eom.Y_W2 + 1,
         eom.Y_S + 2, eom.Y_S + 5, eom.Y_S + 6, eom.Y_S + 7]
    assert np.all(out.y[:, z] == 0.0)
    assert np.all(out.y[:, eom.Y_S + 8] == pytest.approx(1.0, abs=1e-12))


def test_member_result_independent_of_ensemble_size_and_slot(vh):
    """Each member runs its own loop: its section is bit-identical wherever it sits."""
    small = tso.surface_of_section(vh, 10.0, [0.83, 1.63], orbits=6, rtol=1e-11)
    grid = np.linspace(0.5, 2.5, 37)
    big = tso.surface_of_section(vh, 10.0, np.concatenate([grid[:20], [1.63], grid[20:], [0.83]]),
                                 orbits=6, rtol=1e-11, run=tso.Run(window_orbits=2))
    for i_small, i_big in ((0, -1), (1, 20)):
        n = small.count[i_small]
        assert big.count[i_big] == n
        np.testing.assert_array_equal(big.theta_p[i_big, :n], small.theta_p[i_small, :n])
        np.testing.assert_array_equal(big.thetadot_p[i_big, :n], small.thetadot_p[i_small, :n])


def test_list_of_systems_gives_one_member_each():
    systems = [tso.catalog.system("1991 VH", elongation=q) for q in (1.1, 1.3, 1.5)]
    r = tso.surface_of_section(systems, 0.0, 1.0, orbits=2, rtol=1e-10)
    assert r.count.shape == (3,) and np.all(r.count == 2)
    assert [s.omega0 for s in r.systems] == [s.omega0 for s in systems]
    # different shapes give different sections
    assert len(set(np.round(r.thetadot_p[:, 1], 8))) == 3


def _energy_test_run(rtol, days=5.0):
    system = tso.catalog.system("test")
    spin2 = 2 * np.pi / tso.catalog.secondary_spin_period("test") / system.mean_motion
    table = Members.from_starts(system, 0.0, spin2)
    par, y0 = table.par, table.y0
    ens = Ensemble(par, y0, rtol=rtol)
    out = ens.run(days * DAY * system.mean_motion)
    d0, d1 = out.diag_start, out.diag_end
    e0, e1 = d0[0, :3].sum(), d1[0, :3].sum()
    l0 = d0[0, 3:6] + d0[0, 6:9] + d0[0, 9:12]
    l1 = d1[0, 3:6] + d1[0, 6:9] + d1[0, 9:12]
    return out, abs(e1 / e0 - 1), np.linalg.norm(l1 - l0) / np.linalg.norm(l0)


def test_energy_case_conserves_energy_and_angular_momentum():
    """docs/physics.md §7 energy-test case (ellipsoidal, fast-spinning primary), 5 days at rtol
    1e-13: total energy and angular momentum to ≤ 1e-10 while the parts exchange much more."""
    out, dE, dL = _energy_test_run(1e-13)
    assert out.status[0] == DONE
    assert dE < 1e-10 and dL < 1e-10
    exchange = np.abs(out.diag_end[0, :3] - out.diag_start[0, :3]).max() / abs(out.diag_start[0, :3].sum())
    assert exchange > 1e3 * max(dE, dL)
    assert out.diag_end[0, 12] < 1e-10 and out.diag_end[0, 13] < 1e-10


def test_drift_shrinks_with_tolerance():
    _, dE_loose, dL_loose = _energy_test_run(1e-8, days=2.0)
    _, dE_tight, dL_tight = _energy_test_run(1e-12, days=2.0)
    assert dE_tight < dE_loose / 100
    assert dL_tight < dL_loose / 100


def test_kernel_trajectory_matches_scipy_reference():
    """Half an orbit of the energy-test case: kernel (Cash-Karp, scaled units) against the
    NumPy reference RHS driven by scipy DOP853 in SI units."""
    system = tso.catalog.system("test")
    spin2 = 2 * np.pi / tso.catalog.secondary_spin_period("test") / system.mean_motion
    table = Members.from_starts(system, 20.0, spin2)
    par, y0 = table.par, table.y0
    t_end = np.pi
    out = Ensemble(par, y0, rtol=1e-13).run(t_end)
    got = system.to_physical(out.y[0])
    sol = reference.integrate(tso.G, system.primary, system.secondary, system.to_physical(y0[0]),
                              (0.0, t_end / system.mean_motion), rtol=1e-13, atol=1e-30)
    want = sol.y[:, -1]
    for sl in (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 21), slice(21, 30)):
        np.testing.assert_allclose(got[sl], want[sl], rtol=0, atol=1e-9 * np.abs(want[sl]).max())


def test_failed_members_are_flagged_and_the_rest_go_on(vh):
    """A NaN start, an infalling and an outbound-hyperbolic member stop with their status;
    the good members' results equal a run without the bad ones."""
    table = Members.from_starts(vh, 0.0, [0.9, 1.1, 1.2, 1.3, 1.7])
    par, y0 = table.par, table.y0
    bad = y0.copy()
    bad[1, eom.Y_R] = np.nan
    bad[2, eom.Y_V:eom.Y_V + 3] = (-3.0, 0.0, 0.0)          # straight in: collision
    bad[3, eom.Y_V:eom.Y_V + 3] = (0.5, 2.0, 0.0)           # hyperbolic and receding: escape
    out = Ensemble(par, bad, rtol=1e-10).run(2 * np.pi * 4)
    assert out.status.tolist() == [DONE, NONFINITE, COLLISION, ESCAPE, DONE]
    good = Ensemble(par[[0, 4]], y0[[0, 4]], rtol=1e-10).run(2 * np.pi * 4)
    for k, i in enumerate((0, 4)):
        np.testing.assert_array_equal(out.events[i], good.events[k])
    assert RUNNING not in out.status


def test_tolerance_1e15_works(vh):
    r = tso.surface_of_section(vh, 0.0, 1.63, orbits=2.5, rtol=1e-15)
    assert r.status[0] == DONE and r.count[0] == 2
    assert r.energy_drift[0] < 1e-13


@pytest.mark.parametrize("kwargs, message", [
    (dict(orbits=0), "orbits"),
    (dict(orbits=float("nan")), "orbits"),
    (dict(rtol=0.0), "rtol"),
    (dict(rtol=1e-20), "rtol"),
    (dict(atol=-1.0), "atol"),
    (dict(order=1), "order"),
    (dict(theta_p=float("nan")), "theta_p"),
    (dict(thetadot_p=[1.0, float("inf")]), "thetadot_p"),
    (dict(window_orbits=0), "window_orbits"),
])
def test_bad_run_inputs_raise_clear_errors(vh, kwargs, message):
    args = dict(theta_p=0.0, thetadot_p=1.0, orbits=1, rtol=1e-10)
    args.update(kwargs)
    integrator = {k: args.pop(k) for k in ("atol", "order") if k in args}
    with pytest.raises(ValueError, match=message):   # raised by the options objects too
        tso.surface_of_section(vh, **run_options(**args),
                               integrator=tso.Integrator(**integrator) if integrator else None)


@pytest.mark.parametrize("build, message", [
    (lambda: tso.BinarySystem(tso.Sphere(600, 1581), tso.Ellipsoid(200, 150, 100, 2000), 3000, 1.0), "e must lie"),
    (lambda: tso.BinarySystem(tso.Sphere(600, 1581), tso.Ellipsoid(200, 150, 100, 2000), -3000, 0.1), "a must be"),
    (lambda: tso.BinarySystem(tso.Sphere(600, 1581), tso.Ellipsoid(200, 150, 100, 2000), 700, 0.1), "overlap"),
    (lambda: tso.BinarySystem("sphere", tso.Ellipsoid(200, 150, 100, 2000), 3000, 0.1), "primary must be"),
    (lambda: tso.catalog.system("1991 XX"), "unknown system"),
    (lambda: tso.catalog.system("1991 VH", elongation=0.9), "elongation"),
    (lambda: tso.catalog.system("1991 VH", secondary_density=-1), "secondary_density"),
    (lambda: tso.catalog.system("1991 VH", eccentricity=1.2), "eccentricity"),
    (lambda: tso.Ellipsoid(100, 200, 50, 2000), "a >= b >= c"),
    (lambda: tso.Sphere(-1, 2000), "radius"),
    (lambda: tso.init(arch="tpu"), "arch"),
])
def test_bad_system_inputs_raise_clear_errors(build, message):
    with pytest.raises((ValueError, TypeError), match=message):
        build()


def test_catalogue_1991_vh_matches_the_table(vh):
    assert vh.mass_ratio == pytest.approx(11.92, abs=0.01)     # "≈ 12" in the paper
    a_s, b_s, c_s = vh.secondary.semi_axes
    assert a_s * b_s == pytest.approx(57600) and a_s / b_s == pytest.approx(1.5) and c_s == 190
    assert vh.omega0 == pytest.approx(np.sqrt(3 * (1.5**2 - 1) / (1.5**2 + 1)), rel=1e-14)


@pytest.mark.parametrize("model", ["planar", "3d"])
def test_time_series_energy_split_exchanges_but_total_is_conserved(model):
    """Energy-test case over one orbit: the orbit and secondary-spin energies trade by far
    more than the total drifts; the angular momenta likewise (SI units). Measured drifts at
    rtol 1e-12: energy 1.2e-11 planar, 3.4e-12 3-D (the primary spins at 15 n, and the planar
    model's stored angles turn at ω − n), angular momentum 4.4e-11 and 1.4e-11."""
    system = tso.catalog.system("test")
    spin2 = 2 * np.pi / tso.catalog.secondary_spin_period("test") / system.mean_motion
    ts = tso.time_series(system, 0.0, spin2, orbits=1, samples_per_orbit=40, rtol=1e-12,
                         integrator=tso.Integrator(model=model))
    e_tot = ts.energy_orbit[0] + ts.energy_primary[0] + ts.energy_secondary[0]
    np.testing.assert_allclose(ts.energy[0], e_tot)
    drift = np.abs(e_tot - e_tot[0]).max() / abs(e_tot[0])
    swing = np.ptp(ts.energy_secondary[0]) / abs(e_tot[0])
    assert drift < 2e-11 and swing > 1e4 * drift
    l_tot = ts.angmom_orbit[0] + ts.angmom_primary[0] + ts.angmom_secondary[0]
    ldrift = np.linalg.norm(l_tot - l_tot[0], axis=1).max() / np.linalg.norm(l_tot[0])
    assert ldrift < 1e-10 and np.ptp(ts.angmom_secondary[0][:, 2]) > 1e4 * ldrift * np.linalg.norm(l_tot[0])
    # unit conversion: E_orbit(0) = ½ m v_p² + V(R_p, S_0) evaluated independently in SI
    m = system.primary.mass * system.secondary.mass / system.total_mass
    v_p = system.a * system.mean_motion * np.sqrt((1 + system.e) / (1 - system.e))
    V0 = tso.mutual_potential(system.primary, system.secondary, [system.a * (1 - system.e), 0, 0],
                              np.eye(3))[0]
    assert ts.energy_orbit[0, 0] == pytest.approx(0.5 * m * v_p**2 + V0, rel=1e-13)
