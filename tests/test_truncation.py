"""The truncation error of the mutual potential: the table for choosing N before a run
(ti_spinorbit.model.truncation) and every member's estimate and verdict after it.

The table's errors are differences to a higher-order reference. For post-DART Didymos
ellipsoids in one configuration they must equal the true errors against the exact mutual
force and torque, computed by quadrature of the ellipsoid's exterior potential over the
secondary (tests/ellipsoid_exact.py); over its configuration set they must fall geometrically
with order, faster at a larger separation; a sphere feels no torque; bad inputs are refused.

The per-member estimates (engine.evaluation.truncation_estimates, through the kernels) must
equal the same differences computed by the NumPy expansion (ti_spinorbit.multipole) at the member's
closest recorded approach; the radar shape of Didymos is "truncated" at order 4 and not at 8;
the verdict is saved, loaded and reported by the command line.
"""

import os
import sys
import types

import numpy as np
import pytest

from ti_spinorbit.model import truncation as T

sys.path.insert(0, os.path.dirname(__file__))
import ellipsoid_exact as ex  # noqa: E402

import ti_spinorbit as tso
from ti_spinorbit import cli
from ti_spinorbit.engine import accuracy, evaluation
from ti_spinorbit.layout import spatial as _S
from ti_spinorbit import multipole as mp

G = 6.67430e-11
DENSITY = 2400.0
A_AXES = (409.5, 400.5, 303.5)
B_AXES = (88.5, 87.0, 58.0)


def mass(axes):
    return 4.0 / 3.0 * np.pi * np.prod(axes) * DENSITY


def body(axes, name, order=16):
    """A body as the table reads it: name, order, bounding radius and integral(l, m, n)."""
    table = ex.ellipsoid_integrals(mass(axes), axes, order)
    return types.SimpleNamespace(name=name, order=order, bounding_radius=max(axes),
                                 integral=lambda l, m, n: float(table[(l, m, n)]))


def binary(a, e=0.0, primary=A_AXES, secondary=B_AXES, order=16):
    return types.SimpleNamespace(primary=body(primary, "A", order),
                                 secondary=body(secondary, "B", order), a=a, e=e, name="pair")


def test_errors_equal_the_true_errors_against_exact_quadrature(monkeypatch):
    """One configuration (R = 1190 m along x, C = R_z(25°) R_x(10°)): the table's errors at
    orders 2-8, measured against order 16, are the errors against the exact force and torque
    to 1 % (the reference's own error, ~1e-12 in force, is negligible there)."""
    C = T._rotation(2, 25.0) @ T._rotation(0, 10.0)
    monkeypatch.setattr(T, "DIRECTIONS", (np.array([1.0, 0.0, 0.0]),))
    monkeypatch.setattr(T, "ATTITUDES", (C,))
    table = T.truncation(binary(1190.0), orders=(2, 4, 6, 8), reference=16)
    R = np.array([1190.0, 0.0, 0.0])
    _, F, tB, tA = ex.exact_mutual(G, mass(A_AXES), A_AXES, mass(B_AXES), B_AXES, R, C)
    TA = ex.ellipsoid_integrals(mass(A_AXES), A_AXES, 8)
    TB = ex.ellipsoid_integrals(mass(B_AXES), B_AXES, 8)
    for k, n in enumerate(table.orders):
        _, Fn, tBn, tAn = mp.mutual_force_torque(TA, TB, R, C, int(n), G=G)
        true_force = np.linalg.norm(Fn - F) / np.linalg.norm(F)
        true_torque = np.linalg.norm(tBn - tB) / np.linalg.norm(tB)
        assert table.force[k] == pytest.approx(true_force, rel=1e-2), n
        assert table.torque_secondary[k] == pytest.approx(true_torque, rel=1e-2), n


def test_errors_fall_geometrically_and_faster_when_farther():
    near = T.truncation(binary(1190.0), orders=(2, 4, 6, 8, 10))
    far = T.truncation(binary(2380.0), orders=(2, 4, 6, 8, 10))
    for table in (near, far):
        for errors in (table.force, table.torque_secondary, table.torque_primary):
            assert np.all(np.diff(np.log(errors)) < 0)              # every order helps
    # each step of two orders gains about (size/separation)^2: more at twice the distance
    gain_near = near.force[:-1] / near.force[1:]
    gain_far = far.force[:-1] / far.force[1:]
    assert np.all(gain_far > 2.5 * gain_near)
    assert np.all(gain_near > 5.0)
    # torques converge more slowly than forces, as the expansion says
    assert np.all(near.torque_secondary > near.force)
    assert near.order_for(force=1e-6) == 8 and near.order_for(force=1e-30) is None


def test_a_sphere_feels_no_torque_and_the_repr_is_a_table():
    table = T.truncation(binary(1500.0, e=0.2, primary=(400.0, 400.0, 400.0)), orders=(2, 4))
    assert table.separation == pytest.approx(1200.0)                # pericentre by default
    np.testing.assert_array_equal(table.torque_primary, 0.0)
    assert np.all(table.torque_secondary > 0)
    text = repr(table)
    assert "against order 8" in text and len(text.splitlines()) == 4


@pytest.mark.parametrize("kwargs, error, text", [
    (dict(separation=400.0), ValueError, r"separation must exceed the sum of the bounding radii"),
    (dict(orders=(2, 4), reference=4), ValueError, r"reference must exceed every order"),
    (dict(orders=(2, 4), reference=20), ValueError, r"reference must be an integer in \[1, 16\]"),
    (dict(orders="4"), TypeError, r"orders must be a sequence of whole numbers"),
    (dict(orders=(2.5,)), ValueError, r"orders must be an integer in \[0, 16\]"),
])
def test_bad_inputs_are_refused_in_one_line(kwargs, error, text):
    with pytest.raises(error, match=text):
        T.truncation(binary(1190.0), **kwargs)


def test_a_body_of_too_low_an_order_is_refused():
    with pytest.raises(ValueError, match=r"holds integrals up to order 8, and the reference "
                                         r"order 10 needs them"):
        T.truncation(binary(1190.0, order=8), orders=(4, 6), reference=10)


# ---- per member, after a run ---------------------------------------------------------------------
def test_member_estimates_equal_the_numpy_expansion_at_the_closest_approach():
    """1999 KW4 (an ellipsoidal, tilted start: a generic attitude), order 4: the estimate is
    |F_6 − F_4| / |F_6| and |τ_6 − τ_4| / (|F_6| ρ_B) at the closest record, the larger of
    the recorded attitude and the same turned by 45° about z; recomputed here with the NumPy
    expansion from the recorded state."""
    kw4 = tso.catalog.system("1999 KW4")
    start = kw4.tilted_start(30.0, 1.2, roll=8.0, pitch=5.0)
    ts = tso.time_series(kw4, initial_states=[start], orbits=2, samples_per_orbit=16,
                         rtol=1e-10, states=True)
    k = int(np.nanargmin(ts.r[0]))
    y = ts.states[0, k]                                   # physical state row, inertial frame
    # the closest approach in the primary frame, from the packed physical rows
    from ti_spinorbit.system.initial import ROW_SLICES
    R_in = y[ROW_SLICES["R"]]
    A1 = y[ROW_SLICES["primary_attitude"]].reshape(3, 3)
    A2 = y[ROW_SLICES["secondary_attitude"]].reshape(3, 3)
    R, S = A1.T @ R_in, A1.T @ A2
    TA = {tuple(map(int, e)): kw4.primary.integral(*map(int, e)) for e in mp.multi_indices(6)}
    TB = {tuple(map(int, e)): kw4.secondary.integral(*map(int, e)) for e in mp.multi_indices(6)}
    turn = np.array([[np.sqrt(0.5), -np.sqrt(0.5), 0], [np.sqrt(0.5), np.sqrt(0.5), 0], [0, 0, 1]])
    force, torque = [], []
    for C in (S, turn @ S):
        _, F4, t4, _ = mp.mutual_force_torque(TA, TB, R, C, 4, G=G)
        _, F6, t6, _ = mp.mutual_force_torque(TA, TB, R, C, 6, G=G)
        force.append(np.linalg.norm(F6 - F4) / np.linalg.norm(F6))
        torque.append(np.linalg.norm(t6 - t4) / (np.linalg.norm(F6) * kw4.secondary.bounding_radius))
    assert ts.order == 4 and ts.status_names == ["done"]
    assert ts.truncation_force[0] == pytest.approx(max(force), rel=1e-6)
    assert ts.truncation_torque[0] == pytest.approx(max(torque), rel=1e-6)
    assert 1e-9 < ts.truncation_force[0] < accuracy.TRUNCATION_LIMITS[0]


def test_the_radar_shape_is_truncated_at_order_4_and_not_at_8(tmp_path):
    radar = tso.catalog.system("Didymos (radar shape)")
    low = tso.surface_of_section(radar, 0.0, [0.8, 1.2], orbits=2, rtol=1e-9)
    high = tso.surface_of_section(radar, 0.0, [0.8, 1.2], orbits=2, rtol=1e-9,
                                  integrator=tso.Integrator(order=8))
    assert low.status_names == ["truncated"] * 2 and low.n_inaccurate == 0
    assert np.all(low.truncation_force > accuracy.TRUNCATION_LIMITS[0])
    assert high.status_names == ["done"] * 2
    assert np.all(high.truncation_force < low.truncation_force / 10)     # 40x measured
    assert np.all(high.truncation_torque < accuracy.TRUNCATION_LIMITS[1])
    assert not accuracy.usable(low.status).any() and accuracy.usable(low.status, True).all()
    back = tso.load(tso.save(low, tmp_path / "low.npz"))
    np.testing.assert_array_equal(back.truncation_force, low.truncation_force)
    assert back.status_names == ["truncated"] * 2


def test_a_body_without_higher_integrals_is_not_estimated():
    """A hand-given order-4 body holds nothing beyond the run's order: NaN, no verdict."""
    vh = tso.catalog.system("1991 VH")
    s = vh.secondary
    plain = tso.Body(s.mass, {k: s.integral(*k) for k in s.integrals if sum(k) <= 4},
                     s.bounding_radius, name="order-4 secondary")
    assert plain.order == 4
    system = tso.BinarySystem(vh.primary, plain, a=vh.a, e=vh.e)
    r = tso.surface_of_section(system, 0.0, [1.0], orbits=1, rtol=1e-9)
    assert r.status_names == ["done"] and np.isnan(r.truncation_force).all()
    f, t = evaluation.truncation_estimates([(system, np.array([0]))], np.full((1, _S.NSTATE),
                                           np.nan), 4)
    assert np.isnan(f).all() and np.isnan(t).all()


def test_the_command_line_says_so_and_exits_3(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    args = ["section", "--system", "Didymos (radar shape)", "--orbits", "2", "--thetadot",
            "1.0", "--quiet"]
    assert cli.main(args) == cli.EXIT_INACCURATE
    err = capsys.readouterr().err
    assert "1 of 1 members truncated: the mutual potential's next orders exceed 1e-05" in err
    assert "raise --order, or --allow-inaccurate" in err and "tighten --rtol" not in err
    assert cli.main(args + ["--order", "8", "--out", "o8.png"]) == cli.EXIT_OK


def test_order_and_degree_caps_are_recorded(tmp_path):
    """An order-N run keeps its order and degree caps in the result, the file and xarray."""
    vh = tso.catalog.system("1991 VH")
    r = tso.surface_of_section(vh, 0.0, [1.0], orbits=1, rtol=1e-9,
                               integrator=tso.Integrator(order=6, degrees=(6, 2)))
    assert r.order == 6 and r.degrees.tolist() == [6, 2]
    back = tso.load(tso.save(r, tmp_path / "r.npz"))
    assert back.order == 6 and back.degrees.tolist() == [6, 2]
    assert tso.time_series(vh, 0.0, [1.0], orbits=0.5, samples_per_orbit=4).degrees is None
    pytest.importorskip("xarray")
    ds = tso.to_xarray(back)
    assert ds["degrees"].values.tolist() == [6, 2] and ds.attrs["order"] == 6
