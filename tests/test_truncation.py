"""The truncation table (ti_spinorbit.model.truncation) against an independent route.

Its errors are differences to a higher-order reference. For post-DART Didymos ellipsoids in
one configuration they must equal the true errors against the exact mutual force and torque,
computed by quadrature of the ellipsoid's exterior potential over the secondary
(tests/ellipsoid_exact.py); over its configuration set they must fall geometrically with
order, faster at a larger separation; a sphere feels no torque; bad inputs are refused.
"""

import os
import sys
import types

import numpy as np
import pytest

from ti_spinorbit.model import truncation as T

sys.path.insert(0, os.path.dirname(__file__))
import ellipsoid_exact as ex  # noqa: E402

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


def rot(axis, deg):
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(3)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s, s
    return m


def test_errors_equal_the_true_errors_against_exact_quadrature(monkeypatch):
    """One configuration (R = 1190 m along x, C = R_z(25°) R_x(10°)): the table's errors at
    orders 2-8, measured against order 16, are the errors against the exact force and torque
    to 1 % (the reference's own error, ~1e-12 in force, is negligible there)."""
    C = rot(2, 25.0) @ rot(0, 10.0)
    monkeypatch.setattr(T, "DIRECTIONS", (np.array([1.0, 0.0, 0.0]),))
    monkeypatch.setattr(T, "ATTITUDES", (C,))
    table = T.truncation(binary(1190.0), orders=(2, 4, 6, 8), reference=16)
    R = np.array([1190.0, 0.0, 0.0])
    _, F, tB, tA = ex.exact_mutual(G, mass(A_AXES), A_AXES, mass(B_AXES), B_AXES, R, C)
    from ti_spinorbit.model import multipole as mp
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
