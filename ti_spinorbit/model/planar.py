"""Host side of the planar model (``kernels/planar_eom.py``): when it applies, its parameter rows,
and conversions between the planar and the 3-D scaled states.

Decision: the model is chosen per ensemble, not per member. ``Ensemble(model="auto")`` uses
the planar kernels when every member qualifies (:func:`qualifies`), else the 3-D ones;
``model="3d"`` forces the general model, ``model="planar"`` insists and raises if a member
does not qualify. Everything downstream (records, final states, diagnostics) is converted
to the 3-D layout, so observables and results do not know which model ran.

A member qualifies when its start is planar exactly (R and V in the xy plane, both spins
along z, both rotation matrices z-rotations) and neither body has an inertia integral with an
odd z exponent (then no force leaves the plane and no torque tilts a spin axis, so the motion
stays planar for all time: the 3-D model keeps such a start planar to round-off, which
``tests/test_planar.py`` checks).
"""

import numpy as np

from ..system.bodies import row_columns, tensor_from_integrals
from ..layout import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4, ROW_LENGTH

_SAMPLES = 16   # angles per Fourier fit: exact for trigonometric polynomials of degree < 8


def qualifies(par, y0):
    """Boolean per member: planar start and bodies symmetric about their equators."""
    from ..kernels import eom      # Taichi: on first use

    par = np.atleast_2d(par)
    y0 = np.atleast_2d(y0)
    cols = row_columns(lambda e: e[2] % 2)           # integrals odd in z
    symmetric = np.all(par[:, [eom.BODY_A + c for c in cols]] == 0.0, axis=1) & \
        np.all(par[:, [eom.BODY_B + c for c in cols]] == 0.0, axis=1)
    out_of_plane = [eom.Y_R + 2, eom.Y_V + 2, eom.Y_W1, eom.Y_W1 + 1, eom.Y_W2, eom.Y_W2 + 1]
    for base in (eom.Y_S, eom.Y_S1):                    # off-z entries of both rotations
        out_of_plane += [base + 2, base + 5, base + 6, base + 7]
    flat = np.all(y0[:, out_of_plane] == 0.0, axis=1)
    flat &= (y0[:, eom.Y_S + 8] == 1.0) & (y0[:, eom.Y_S1 + 8] == 1.0)
    return symmetric & flat


def _moment_tensors(row):
    """Second, third and fourth moment tensors of one body row (any consistent units)."""
    tensors = []
    off = 1
    for order, group in ((2, EXPONENTS_2), (3, EXPONENTS_3), (4, EXPONENTS_4)):
        values = dict(zip(group, row[off:off + len(group)]))
        off += len(group)
        tensors.append(tensor_from_integrals(order, lambda *lmn: values.get(lmn, 0.0)))
    return tensors


def legendre_terms(row, psi):
    """L_n(ψ) = ∫ |x|^n P_n(u·x/|x|) dm for n = 2, 3, 4 and u = (cos ψ, sin ψ, 0): the
    single-body terms of the mutual potential (docs/physics.md §3.2), by tensor contraction.
    Returns an array (3, len(psi))."""
    M2, M3, M4 = _moment_tensors(np.asarray(row, dtype=np.float64))
    u = np.stack([np.cos(psi), np.sin(psi), np.zeros_like(psi)], axis=-1)
    L2 = 1.5 * np.einsum("ij,pi,pj->p", M2, u, u) - 0.5 * np.trace(M2)
    L3 = 2.5 * np.einsum("ijk,pi,pj,pk->p", M3, u, u, u) - 1.5 * np.einsum("ikk,pi->p", M3, u)
    L4 = (4.375 * np.einsum("ijkl,pi,pj,pk,pl->p", M4, u, u, u, u)
          - 3.75 * np.einsum("ijkk,pi,pj->p", M4, u, u) + 0.375 * np.einsum("iijj->", M4))
    return np.stack([L2, L3, L4])


def fourier_coefficients(row):
    """Fourier coefficients of L2 (a0, a2, b2), L3 (a1, b1, a3, b3), L4 (a0, a2, b2, a4, b4)
    of one body row: L(ψ) = a0 + Σ_k a_k cos kψ + b_k sin kψ."""
    psi = 2.0 * np.pi * np.arange(_SAMPLES) / _SAMPLES
    F = np.fft.rfft(legendre_terms(row, psi), axis=-1) / _SAMPLES

    def ab(n, k):
        return 2.0 * F[n, k].real, -2.0 * F[n, k].imag

    a2, b2 = ab(0, 2)
    a1, b1 = ab(1, 1)
    a3, b3 = ab(1, 3)
    a42, b42 = ab(2, 2)
    a44, b44 = ab(2, 4)
    return (np.array([F[0, 0].real, a2, b2]), np.array([a1, b1, a3, b3]),
            np.array([F[2, 0].real, a42, b42, a44, b44]))


def _cross_coefficients(jA, jB):
    """(x0, xA, xB, xAB, xm) of the quadrupole-quadrupole term X (kernels/planar_eom.py) from the
    diagonal second moments (T200, T020, T002) of both bodies."""
    abar, alpha = 0.5 * (jA[0] + jA[1]), 0.5 * (jA[0] - jA[1])
    bbar, beta = 0.5 * (jB[0] + jB[1]), 0.5 * (jB[0] - jB[1])
    trA, trB = jA.sum(), jB.sum()
    x0 = (26.25 - 15.0 + 3.0) * abar * bbar - 3.75 * (abar * trB + bbar * trA) \
        + 0.75 * trA * trB + 1.5 * jA[2] * jB[2]
    return np.array([x0, alpha * (11.25 * bbar - 3.75 * trB), beta * (11.25 * abar - 3.75 * trA),
                     26.25 * alpha * beta, -12.0 * alpha * beta])


def parameter_rows(par):
    """Planar kernel rows (kernels/planar_eom.py layout) from 3-D member rows (eom layout)."""
    from ..kernels import eom, planar_eom as P      # Taichi: on first use

    par = np.atleast_2d(np.asarray(par, dtype=np.float64))
    out = np.zeros((len(par), P.NPAR))
    cache = {}
    for i, row in enumerate(par):
        key = row.tobytes()
        if key not in cache:
            A = row[eom.BODY_A:eom.BODY_A + ROW_LENGTH]
            B = row[eom.BODY_B:eom.BODY_B + ROW_LENGTH]
            mA, mB = A[0], B[0]
            p = np.zeros(P.NPAR)
            p[P.P_MM] = mA * mB
            p[P.P_INV_M] = 1.0 / row[eom.P_MRED]
            p[P.P_K1], p[P.P_F1] = 1.0 / row[eom.P_C1], row[eom.P_IA + 2]
            p[P.P_K2], p[P.P_F2] = 1.0 / row[eom.P_C2], row[eom.P_IB + 2]
            (a2, a3, a4), (b2, b3, b4) = fourier_coefficients(A), fourier_coefficients(B)
            p[P.P_P2:P.P_P2 + 3], p[P.P_Q2:P.P_Q2 + 3] = mB * a2, mA * b2
            p[P.P_P3:P.P_P3 + 4], p[P.P_Q3:P.P_Q3 + 4] = mB * a3, -mA * b3
            p[P.P_P4:P.P_P4 + 5], p[P.P_Q4:P.P_Q4 + 5] = mB * a4, mA * b4
            p[P.P_X:P.P_X + 5] = _cross_coefficients(A[1:4], B[1:4])
            p[P.P_CONTACT], p[P.P_ESCAPE] = row[eom.P_CONTACT], row[eom.P_ESCAPE]
            cache[key] = p
        out[i] = cache[key]
    return out


def to_planar(y):
    """3-D scaled states (..., 30) -> planar states (..., 10), layout of kernels/planar_eom.py."""
    from ..kernels import eom, planar_eom as P      # Taichi: on first use

    y = np.asarray(y, dtype=np.float64)
    R = y[..., eom.Y_R:eom.Y_R + 3]                      # primary frame
    V = y[..., eom.Y_V:eom.Y_V + 3]
    S = y[..., eom.Y_S:eom.Y_S + 9].reshape(y.shape[:-1] + (3, 3))
    S1 = y[..., eom.Y_S1:eom.Y_S1 + 9].reshape(y.shape[:-1] + (3, 3))
    r = np.hypot(R[..., 0], R[..., 1])
    eA = R[..., :2] / r[..., None]
    eB = np.einsum("...ji,...j->...i", S[..., :2, :2], eA)    # Sᵀ e: R in the B frame
    R_in = np.einsum("...ij,...j->...i", S1[..., :2, :2], R[..., :2])
    out = np.empty(y.shape[:-1] + (P.NSTATE,))
    out[..., P.Y_R] = r
    out[..., P.Y_VR] = np.sum(eA * V[..., :2], axis=-1)
    out[..., P.Y_L] = R[..., 0] * V[..., 1] - R[..., 1] * V[..., 0]
    out[..., P.Y_LAM] = np.arctan2(R_in[..., 1], R_in[..., 0])
    out[..., P.Y_CA], out[..., P.Y_SA] = eA[..., 0], eA[..., 1]
    out[..., P.Y_CB], out[..., P.Y_SB] = eB[..., 0], eB[..., 1]
    out[..., P.Y_W1] = y[..., eom.Y_W1 + 2]
    out[..., P.Y_W2] = y[..., eom.Y_W2 + 2]
    return out


def to_spatial(q):
    """Planar states (..., 10) -> 3-D scaled states (..., 30) in the primary's frame."""
    from ..kernels import eom, planar_eom as P      # Taichi: on first use

    q = np.asarray(q, dtype=np.float64)
    r, vr, ell, lam = q[..., P.Y_R], q[..., P.Y_VR], q[..., P.Y_L], q[..., P.Y_LAM]
    cA, sA, cB, sB = q[..., P.Y_CA], q[..., P.Y_SA], q[..., P.Y_CB], q[..., P.Y_SB]
    vt = ell / r                                         # transverse velocity
    out = np.zeros(q.shape[:-1] + (eom.NSTATE,))
    out[..., eom.Y_R], out[..., eom.Y_R + 1] = r * cA, r * sA
    out[..., eom.Y_V], out[..., eom.Y_V + 1] = vr * cA - vt * sA, vr * sA + vt * cA
    out[..., eom.Y_W1 + 2] = q[..., P.Y_W1]
    out[..., eom.Y_W2 + 2] = q[..., P.Y_W2]
    cl, sl = np.cos(lam), np.sin(lam)
    rotations = ((eom.Y_S, cA * cB + sA * sB, sA * cB - cA * sB),       # θ2 − θ1 = ψ_A − ψ_B
                 (eom.Y_S1, cl * cA + sl * sA, sl * cA - cl * sA))      # θ1 = λ − ψ_A
    for base, c, s in rotations:
        out[..., base], out[..., base + 1] = c, -s
        out[..., base + 3], out[..., base + 4] = s, c
        out[..., base + 8] = 1.0
    return out


def shadow_direction():
    """Unit direction of the chaos-indicator shadow's initial offset: r, v_r, ℓ and the
    secondary's spin (the planar counterpart of the 3-D model's direction)."""
    from ..kernels import planar_eom as P      # Taichi: on first use

    u = np.zeros(P.NSTATE)
    u[[P.Y_R, P.Y_VR, P.Y_L, P.Y_W2]] = 1.0
    return u / np.linalg.norm(u)
