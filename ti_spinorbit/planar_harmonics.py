"""The order-N mutual potential of a planar configuration as a double Fourier series in the
two bodies' angles (NumPy only): the host reference of a planar order-N path.

When R lies in the primary's xy plane and the secondary is turned about z only (the planar
model's configurations, docs/physics.md §4.4), the line-of-centres form of
``ti_spinorbit.harmonics`` has θ = 90° and, with R = r (cos φ, sin φ, 0) in A's frame and
S = Rz(δ) (B's frame into A's), α = π, β = 90°, γ = δ − φ + π (the angles its
``_line_of_centres`` reads off the matrices). Both bodies' rotations into the frame of the
line of centres are then a z-rotation by the body's own angle followed by a fixed matrix,

    C_A^L = D_A X(χ_A) C_A,   D_A = X(π) Jᵀ X(−π/2) J,     χ_A = −φ,
    C_B^L = D_B X(χ_B) C_B,   D_B = Jᵀ X(π/2) J X(π),      χ_B = δ − φ,

(χ_A, χ_B: minus the azimuth of R in each body's frame; the planar state's angles are
ψ_A = −χ_A, ψ_B = −χ_B, since ``planar_eom`` puts R at azimuth ψ_A and δ = ψ_A − ψ_B). Since X(ψ) C = Σ_j cos jψ u_j +
sin jψ v_j with u_j, v_j made of C_±j, the potential of the harmonic form becomes

    U = −G Σ_L r^{−(L+1)} Σ_{j ≤ dA, k ≤ dB} [W^cc cos jχ_A cos kχ_B + W^cs cos jχ_A sin kχ_B
                                              + W^sc sin jχ_A cos kχ_B + W^ss sin jχ_A sin kχ_B],

W_{L,j,k} = Σ_{l1 + l2 = L} (D_A t^A_j)ᵀ K_{l1 l2} (D_B t^B_k) for t ∈ {u, v}
(:func:`fourier_coefficients`). The coefficients depend on the bodies only, so they are built
once per member; evaluating U, ∂U/∂r and the two torques about z (τ_A,z = −∂U/∂χ_A,
τ_B,z = −∂U/∂χ_B: turning body A by ε about z raises χ_A by ε and leaves χ_B, turning B
raises χ_B) is then one sum over the non-zero terms (:func:`potential`). For a pair of
ellipsoids at order 6 that is about 60 terms, against the 250 table entries of the general
kernel; this module is the reference such a planar kernel is to be checked against, and is
itself held to :func:`ti_spinorbit.harmonics.mutual_force_torque_lc` to 1e-13
(tests/test_planar_harmonics.py).
"""

from functools import lru_cache

import numpy as np

from . import harmonics as _hm


def _x_matrix(l, c, s):
    """X_l(ψ) as a matrix (natural order m = −l..l), for cos ψ = c, sin ψ = s."""
    return np.array([_hm.z_rotation(e, l, c, s) for e in np.eye(2 * l + 1)]).T


@lru_cache(maxsize=None)
def fixed_matrices(l):
    """(D_A, D_B) of degree l (module docstring), read-only."""
    J = _hm.j_matrix(l)
    DA = _x_matrix(l, -1.0, 0.0) @ J.T @ _x_matrix(l, 0.0, -1.0) @ J
    DB = J.T @ _x_matrix(l, 0.0, 1.0) @ J @ _x_matrix(l, -1.0, 0.0)
    for D in (DA, DB):
        D.setflags(write=False)
    return DA, DB


def _split(c, l):
    """(u, v): (l+1, 2l+1) each, X(ψ) c = Σ_j cos jψ u_j + sin jψ v_j."""
    u = np.zeros((l + 1, 2 * l + 1))
    v = np.zeros((l + 1, 2 * l + 1))
    u[0, l] = c[l]
    for j in range(1, l + 1):
        p, q = c[l + j], c[l - j]
        u[j, l + j], u[j, l - j] = p, q
        v[j, l + j], v[j, l - j] = -q, p
    return u, v


def _turned(c, degree, body):
    """{l: (D u_j, D v_j) for all j}: a body's split coefficients (degrees 0..degree, first
    moments left out: zero about the centre of mass) turned by its fixed matrix."""
    out = {}
    for l in range(degree + 1):
        if l != 1:
            u, v = _split(np.asarray(c[l], dtype=float), l)
            D = fixed_matrices(l)[body]
            out[l] = (u @ D.T, v @ D.T)
    return out


def fourier_coefficients(cA, cB, order, degrees=None):
    """W (order + 1, dA + 1, dB + 1, 4): the planar Fourier coefficients of the order-``order``
    potential (module docstring; last axis cc, cs, sc, ss) of two bodies with harmonic
    coefficients ``cA``, ``cB`` (``harmonics.coefficients``: lists of arrays of 2l + 1, the
    same units as there; degrees 0..dA and 0..dB). U at unit G and distance r is
    −Σ_L r^−(L+1) Σ_jk W[L, j, k] · (the four products of cos, sin jχ_A and kχ_B)."""
    N = int(order)
    dA, dB = (N, N) if degrees is None else (int(degrees[0]), int(degrees[1]))
    if not (0 <= dA <= N and 0 <= dB <= N and len(cA) > dA and len(cB) > dB):
        raise ValueError(f"fourier_coefficients: degrees ({dA}, {dB}) need 0 <= degree <= order "
                         f"= {N} and coefficients up to each degree")
    W = np.zeros((N + 1, dA + 1, dB + 1, 4))
    A, B = _turned(cA, dA, 0), _turned(cB, dB, 1)
    for l1 in A:
        for l2 in B:
            if l1 + l2 > N:
                continue
            K = _hm.coupling(l1, l2)
            for t, (ta, tb) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
                W[l1 + l2, :l1 + 1, :l2 + 1, t] += A[l1][ta] @ K @ B[l2][tb].T
    return W


def planar_angles(R, S):
    """(r, χ_A, χ_B) of a planar configuration: R in A's xy plane (m), S = Rz(δ) (one
    trigonometric call each: a host reference)."""
    R = np.asarray(R, dtype=float)
    S = np.asarray(S, dtype=float)
    phi = np.arctan2(R[1], R[0])
    delta = np.arctan2(S[1, 0], S[0, 0])
    return float(np.hypot(R[0], R[1])), -phi, delta - phi


def potential(W, r, chi_a, chi_b, G=1.0):
    """(U, ∂U/∂r, τ_A,z, τ_B,z) of the series W (:func:`fourier_coefficients`) at distance r
    and body angles χ_A, χ_B (module docstring)."""
    N, nA, nB, _ = W.shape
    ja = np.arange(nA)[:, None]
    kb = np.arange(nB)[None, :]
    ca, sa = np.cos(ja * chi_a), np.sin(ja * chi_a)
    cb, sb = np.cos(kb * chi_b), np.sin(kb * chi_b)
    trig = np.stack([ca * cb, ca * sb, sa * cb, sa * sb], axis=-1)
    d_a = np.stack([-ja * sa * cb, -ja * sa * sb, ja * ca * cb, ja * ca * sb], axis=-1)
    d_b = np.stack([-kb * ca * sb, kb * ca * cb, -kb * sa * sb, kb * sa * cb], axis=-1)
    U = dUdr = dUa = dUb = 0.0
    for L in range(N):
        w = -G * r ** -(L + 1)
        U += w * float(np.sum(W[L] * trig))
        dUdr -= (L + 1) * w / r * float(np.sum(W[L] * trig))
        dUa += w * float(np.sum(W[L] * d_a))
        dUb += w * float(np.sum(W[L] * d_b))
    return U, dUdr, -dUa, -dUb


__all__ = ["fourier_coefficients", "fixed_matrices", "planar_angles", "potential"]
