"""The planar Fourier series of the order-N potential (``ti_spinorbit.planar_harmonics``)
against the line-of-centres harmonic form it is derived from (``ti_spinorbit.harmonics``),
itself held to the Cartesian reference in test_harmonics.py."""

import numpy as np
import pytest

from ti_spinorbit import harmonics as H
from ti_spinorbit import planar_harmonics as PH
from ti_spinorbit.system import integrals as I

from conftest import axis_rotation, cloud


def _pair(rng, kind, order):
    if kind == "ellipsoids":
        return (I.ellipsoid_integrals(1.0, 0.9, 0.8, 1.0, order),
                I.ellipsoid_integrals(0.3, 0.2, 0.19, 0.05, order))
    return cloud(rng, 12, 0.8, 1.0, order), cloud(rng, 9, 0.25, 0.05, order)


@pytest.mark.parametrize("kind", ["ellipsoids", "clouds"])
@pytest.mark.parametrize("order,degrees", [(2, None), (4, None), (6, None), (8, None),
                                           (6, (6, 2)), (7, (3, 7))])
def test_planar_series_equals_the_harmonic_form(rng, kind, order, degrees):
    """U, the radial and transverse force and both torques about z agree with the
    line-of-centres form to round-off at planar configurations (R in the primary's xy plane,
    the secondary turned about z), near contact and far."""
    TA, TB = _pair(rng, kind, order)
    dA, dB = (order, order) if degrees is None else degrees
    W = PH.fourier_coefficients(H.coefficients(TA, dA), H.coefficients(TB, dB), order,
                                degrees=(dA, dB))
    for r in (2.2, 3.0, 6.0):
        phi, delta = rng.uniform(-np.pi, np.pi, 2)
        R = r * np.array([np.cos(phi), np.sin(phi), 0.0])
        S = axis_rotation(2, delta)
        U, F, tauB, tauA = H.mutual_force_torque_lc(TA, TB, R, S, order, degrees=(dA, dB),
                                                    G=1.0)
        rr, pa, pb = PH.planar_angles(R, S)
        u, dudr, ta, tb = PH.potential(W, rr, pa, pb)
        assert abs(rr - r) < 1e-15 * r
        scale = abs(U)
        assert abs(u - U) <= 1e-13 * scale
        assert abs(-dudr - F @ R / r) <= 1e-13 * scale / r       # radial force on B
        # the transverse force from the torques: R × F_B = −(τ_A + τ_B) (the identity of
        # physics §3.4), here about z
        assert abs((R[0] * F[1] - R[1] * F[0]) + ta + tb) <= 1e-13 * scale
        assert abs(ta - tauA[2]) <= 1e-13 * scale
        assert abs(tb - tauB[2]) <= 1e-13 * scale


def test_ellipsoid_pair_keeps_only_even_cosine_products():
    """Two ellipsoids (three mirror planes each) leave only even j and k and the cos·cos and
    sin·sin products, exact zeros elsewhere (the cos 2χ_A, cos 2χ_B, cos(2χ_A ± 2χ_B), ...
    of the written-out order-4 planar series), at every order."""
    TA = I.ellipsoid_integrals(1.0, 0.9, 0.8, 1.0, 8)
    TB = I.ellipsoid_integrals(0.3, 0.2, 0.19, 0.05, 8)
    W = PH.fourier_coefficients(H.coefficients(TA, 8), H.coefficients(TB, 8), 8)
    L, j, k, t = np.nonzero(W)
    assert len(L) > 0
    assert np.all(L % 2 == 0) and np.all(j % 2 == 0) and np.all(k % 2 == 0)
    assert set(t.tolist()) <= {0, 3}
    W4 = PH.fourier_coefficients(H.coefficients(TA, 4), H.coefficients(TB, 4), 4)
    assert np.count_nonzero(W4) == 11          # L = 0: 1 term, L = 2: 3, L = 4: 7


def test_bad_degrees_are_refused_in_one_line():
    c = H.coefficients(I.ellipsoid_integrals(1.0, 0.9, 0.8, 1.0, 4), 4)
    with pytest.raises(ValueError, match=r"degrees \(5, 4\) need 0 <= degree <= order = 4"):
        PH.fourier_coefficients(c, c, 4, degrees=(5, 4))
