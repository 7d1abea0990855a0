"""The order-N mutual potential in real solid harmonics along the line of centres (NumPy only).

A second, independent route to the truncated mutual potential, force and torques of
``ti_spinorbit.multipole`` (the Cartesian multipole–multipole form), built as the host
reference of a cheaper formulation for the kernels (docs/physics.md §3.8.2). It depends on NumPy
and on ``ti_spinorbit.multipole`` (for exact Cartesian rotations and the coefficients of 1/r
only while its tables are built).

Why. In Cartesian form every pair (α, β) of multi-indices with |α| + |β| ≤ N is a term, about
C(N+6, 6) of them, and the secondary's integrals must be rotated by a map of C(l+2, 2)²
entries per degree. In harmonics a body of degree l has 2l + 1 numbers, a rotation about z
costs 4 products per pair (m, −m), and in the frame whose z axis is the line of centres the
interaction of a degree-l1 multipole with a degree-l2 one keeps only the terms with equal
|m|: 2 min(l1, l2) + 1 of them instead of C(l1+2, 2) C(l2+2, 2) (Greengard & Rokhlin 1997,
Acta Numerica 6:229, for the rotate–translate–rotate scheme; Pinchon & Hoggan 2007, J. Phys.
A 40:1597, for rotations of real harmonics as z-rotations and one fixed matrix J per degree).

Definitions
-----------
Real regular solid harmonics S_lm(x), m = −l..l, homogeneous harmonic polynomials of degree
l with S_l0 = r^l P_l(cos θ), S_l,m ∝ r^l P_l^m(cos θ) cos mφ and S_l,−m ∝ r^l P_l^m sin mφ
(m > 0), all of one degree with the same norm on the unit sphere (Racah's, i.e. Schmidt's
semi-normalisation), from the recurrences of Helgaker, Jørgensen & Olsen (2000, Molecular
Electronic-Structure Theory, eqs. 6.4.70–6.4.72).

A body's degree-l coefficients C_lm are those of the harmonic part of
Φ_l(y) = ∫ (x·y)^l dm = Σ_{|α|=l} (l!/α!) T^α y^α in that basis: H[Φ_l] = Σ_m C_lm S_lm (the
projection onto degree-l harmonics on the unit sphere). Because ∂^γ(1/r) is harmonic in each
index of γ, the mutual potential depends on a body's degree-l integrals only through C_l, and
any tensor with the same harmonic part may stand in for T^α: :func:`representative` gives
T̃^α = (α!/l!) [y^α] Σ_m C_lm S_lm(y).

Rotating a body by Q (points x → Q x) maps C_l → M_l(Q) C_l with M_l(Q)[:, m] the coefficients
of S_lm(Qᵀ y); M_l(Q1 Q2) = M_l(Q1) M_l(Q2), and M_l is orthogonal (equal norms). A z-rotation
is X_l(ψ): C'_m = cos mψ C_m − sin mψ C_−m, C'_−m = sin mψ C_m + cos mψ C_−m; a y-rotation is
M(Ry(β)) = Jᵀ X(β) J with J = M(Rx(90°)) (Ry(β) = Rx(−90°) Rz(β) Rx(90°)).

Evaluation (:func:`mutual_force_torque_lc`)
------------------------------------------
With R = r (sin θ cos φ, sin θ sin φ, cos θ) in A's frame, P = Ry(−θ) Rz(−φ) takes R to r ẑ.
The secondary's rotation into that frame, Q = P C (C: B frame to A frame), is split as
Q = Rz(α) Ry(β) Rz(γ); since a common rotation about the line of centres changes nothing, the
frame used is L = Rz(−α) P, in which the secondary needs two rotations only,

    C_A^L = X(−α) Jᵀ X(−θ) J X(−φ) C_A,     C_B^L = Jᵀ X(β) J X(γ) C_B.

The angles come from matrix entries, never from trigonometric functions: (cos α, sin α) is the
direction of (Q13, Q23), then Q' = Rz(−α) Q = Ry(β) Rz(γ) gives cos β = Q'33,
sin β = Q'13, cos γ = Q'22, sin γ = Q'21, all well conditioned (no gimbal lock: near β = 0
any α serves, and β and γ are read from Q' itself).

Along ẑ the truncated potential is

    U = −G Σ_{l1 ≤ dA, l2 ≤ dB, l1 + l2 ≤ N} r^{−(l1+l2+1)} C_A^{L,l1 ᵀ} K_{l1 l2} C_B^{L,l2},

K_{l1 l2}[m1, m2] = Σ_{|α|=l1, |β|=l2} (−1)^{l1} (α+β)!/(α!β!) T̃_{m1}^α T̃_{m2}^β a_{α+β}(ẑ)
(the Cartesian coefficient of ``multipole`` for unit coefficients, a_γ = ∂^γ(1/r)/γ!),
non-zero only for |m1| = |m2| (axial symmetry). The torque on a body (δU = −τ·ε for a
rotation ε of that body alone) is τ_k = −Σ_lm (∂U/∂C_lm) (G_k C)_lm with G_k the generator of
rotations about axis k (M(I + ε[e_k]×) = I + ε G_k). In the frame L, R = r ẑ and the identity
R × ∂U/∂R = τ_A + τ_B gives the transverse gradient, (∂U/∂R)_x = (τ_A + τ_B)_y / r,
(∂U/∂R)_y = −(τ_A + τ_B)_x / r, while (∂U/∂R)_z = ∂U/∂r is the radial derivative of the
powers of r; so angular momentum is conserved exactly by construction, as in the kernels.
All vectors are returned in A's frame.
"""

import math
from functools import lru_cache

import numpy as np

from .multipole import (G_SI, _check_C, _check_R, _check_degrees, _check_order,
                        _generator, _integral_vector, _rotate_vector, _table,
                        inverse_distance_coefficients)

__all__ = ["solid_harmonics", "coefficients", "representative", "rotation_matrix",
           "z_rotation", "projector", "j_matrix", "coupling", "generators", "mutual_force_torque_lc"]

MAX_DEGREE = 16


# ---- polynomials: {(a, b, c): coefficient} --------------------------------------------------
def _times(p, axis):
    out = {}
    for (a, b, c), v in p.items():
        e = [a, b, c]
        e[axis] += 1
        out[tuple(e)] = out.get(tuple(e), 0.0) + v
    return out


def _add(p, q, s=1.0):
    out = dict(p)
    for k, v in q.items():
        out[k] = out.get(k, 0.0) + s * v
    return out


def _scale(p, s):
    return {k: s * v for k, v in p.items()}


def _r2(p):
    return _add(_add(_times(_times(p, 0), 0), _times(_times(p, 1), 1)), _times(_times(p, 2), 2))


@lru_cache(maxsize=None)
def _block(l):
    """(exponents of degree l (n, 3), their offset in ``multipole``'s order)."""
    E, _, off = _table(l)
    return E[off[l]:off[l + 1]], int(off[l])


@lru_cache(maxsize=None)
def solid_harmonics(degree):
    """Real regular solid harmonics as polynomial coefficients: a list over l = 0..degree of
    (2l + 1, C(l+2, 2)) arrays, row m + l, columns the degree-l monomials in
    ``multipole.multi_indices`` order (module docstring for the normalisation)."""
    degree = int(degree)
    if not 0 <= degree <= MAX_DEGREE:
        raise ValueError(f"degree must be in [0, {MAX_DEGREE}] (got {degree})")
    S = {(0, 0): {(0, 0, 0): 1.0}}
    for l in range(degree):
        f = math.sqrt((2.0 if l == 0 else 1.0) * (2 * l + 1) / (2 * l + 2))
        top, bot = S[(l, l)], S[(l, -l)]
        if l == 0:
            S[(1, 1)], S[(1, -1)] = _times(top, 0), _times(top, 1)
        else:
            S[(l + 1, l + 1)] = _scale(_add(_times(top, 0), _times(bot, 1), -1.0), f)
            S[(l + 1, -l - 1)] = _scale(_add(_times(top, 1), _times(bot, 0)), f)
        for m in range(-l, l + 1):
            p = _scale(_times(S[(l, m)], 2), 2 * l + 1)
            if abs(m) <= l - 1:
                p = _add(p, _r2(S[(l - 1, m)]), -math.sqrt((l + m) * (l - m)))
            S[(l + 1, m)] = _scale(p, 1.0 / math.sqrt((l + m + 1) * (l - m + 1)))
    out = []
    for l in range(degree + 1):
        E, _ = _block(l)
        rows = np.array([[S[(l, m)].get(tuple(int(x) for x in e), 0.0) for e in E]
                         for m in range(-l, l + 1)])
        rows.setflags(write=False)
        out.append(rows)
    return out


def _sphere_monomial(e):
    """∫ x^a y^b z^c dΩ over the unit sphere."""
    if any(k % 2 for k in e):
        return 0.0
    return 2.0 * math.exp(sum(math.lgamma((k + 1) / 2.0) for k in e)
                          - math.lgamma((sum(e) + 3) / 2.0))


@lru_cache(maxsize=None)
def projector(l):
    """(2l+1, C(l+2,2)) matrix taking the degree-l integrals T^α to C_l."""
    E, _ = _block(l)
    S = solid_harmonics(l)[l]
    gram = np.array([[_sphere_monomial(a + b) for b in E] for a in E])
    norm = float(S[l] @ gram @ S[l])             # the common norm of the degree (m = 0)
    weights = np.array([math.factorial(l) / math.prod(math.factorial(int(k)) for k in e)
                        for e in E])             # Φ_l = Σ (l!/α!) T^α y^α
    P = (S @ gram) * weights[None, :] / norm
    P.setflags(write=False)
    return P


def coefficients(T, degree):
    """Harmonic coefficients [C_0, ..., C_degree] (arrays of 2l + 1, kg m^l) of a body from its
    integrals, a flat vector in ``multipole`` order (degree ≤ ``degree``) or a mapping."""
    if not isinstance(T, np.ndarray):
        T = np.array([float(T.get(tuple(int(x) for x in e), 0.0))
                      for e in _table(degree)[0]])
    out = []
    for l in range(degree + 1):
        _, off = _block(l)
        out.append(projector(l) @ T[off:off + (l + 1) * (l + 2) // 2])
    return out


def representative(c, l):
    """The degree-l integrals T̃^α (flat, degree-l block) whose harmonic part is c."""
    E, _ = _block(l)
    inv_w = np.array([math.prod(math.factorial(int(k)) for k in e) / math.factorial(l)
                      for e in E])
    return inv_w * (np.asarray(c, dtype=float) @ solid_harmonics(l)[l])


def _full(t_block, l):
    v = np.zeros(len(_table(l)[0]))
    _, off = _block(l)
    v[off:] = t_block
    return v


def rotation_matrix(Q, l):
    """M_l(Q), (2l+1, 2l+1): the degree-l coefficients of a body rotated by Q (points
    x → Q x), exact (the Cartesian rotation of each basis element, projected)."""
    Q = np.asarray(Q, dtype=float)
    _, off = _block(l)
    cols = []
    for m in range(2 * l + 1):
        e = np.zeros(2 * l + 1)
        e[m] = 1.0
        t = _rotate_vector(_full(representative(e, l), l), Q, l)
        cols.append(projector(l) @ t[off:])
    return np.array(cols).T


def z_rotation(c, l, cos_psi, sin_psi):
    """X_l(ψ) c: degree-l coefficients of a body rotated by ψ about z (multiple angles by the
    recurrence of cos and sin, no trigonometric call)."""
    c = np.asarray(c, dtype=float)
    out = c.copy()
    cm, sm = 1.0, 0.0
    for m in range(1, l + 1):
        cm, sm = cm * cos_psi - sm * sin_psi, sm * cos_psi + cm * sin_psi
        p, q = c[l + m], c[l - m]
        out[l + m] = cm * p - sm * q
        out[l - m] = sm * p + cm * q
    return out


@lru_cache(maxsize=None)
def j_matrix(l):
    """J_l = M_l(Rx(90°)), the fixed matrix of every y-rotation (exact zeros kept zero)."""
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    J = rotation_matrix(Rx, l)
    J[np.abs(J) < 1e-9] = 0.0          # round-off of the projection, not entries
    J.setflags(write=False)
    return J


@lru_cache(maxsize=None)
def coupling(l1, l2):
    """K_{l1 l2} (2l1+1, 2l2+1): the axial interaction of unit coefficients at unit distance
    (module docstring), exact zeros where |m1| ≠ |m2|."""
    top = l1 + l2
    a = inverse_distance_coefficients((0.0, 0.0, 1.0), top)
    E1, _ = _block(l1)
    E2, _ = _block(l2)
    fact = math.factorial
    H = np.empty((len(E1), len(E2)))
    for i, al in enumerate(E1):
        for j, be in enumerate(E2):
            g = tuple(int(x) for x in al + be)
            w = math.prod(fact(x) for x in g) / (math.prod(fact(int(x)) for x in al)
                                                 * math.prod(fact(int(x)) for x in be))
            H[i, j] = (-1.0) ** l1 * w * a[g]
    R1 = np.array([representative(np.eye(2 * l1 + 1)[m], l1) for m in range(2 * l1 + 1)])
    R2 = np.array([representative(np.eye(2 * l2 + 1)[m], l2) for m in range(2 * l2 + 1)])
    K = R1 @ H @ R2.T
    K[np.abs(K) < 1e-13 * max(1.0, np.abs(K).max())] = 0.0
    K.setflags(write=False)
    return K


@lru_cache(maxsize=None)
def generators(l):
    """(3, 2l+1, 2l+1): G_k, the derivative of M_l(exp(ε [e_k]×)) at ε = 0, exact (the
    Cartesian rotation generator of each basis element, projected)."""
    _, off = _block(l)
    G = np.zeros((3, 2 * l + 1, 2 * l + 1))
    for m in range(2 * l + 1):
        e = np.zeros(2 * l + 1)
        e[m] = 1.0
        d = _generator(_full(representative(e, l), l), l)      # (3, count): ∂t/∂ε_k
        for k in range(3):
            G[k, :, m] = projector(l) @ d[k][off:]
    G[np.abs(G) < 1e-9] = 0.0
    G.setflags(write=False)
    return G


def _line_of_centres(R, C):
    """(r, L, (cos, sin) of φ, θ, α, β, γ): the frame L = Rz(−α) Ry(−θ) Rz(−φ) and the angles
    of the module docstring, from matrix entries only."""
    x, y, z = R
    rho = math.hypot(x, y)
    r = math.sqrt(rho * rho + z * z)
    cf, sf = (x / rho, y / rho) if rho > 0.0 else (1.0, 0.0)
    ct, st = z / r, rho / r
    Rz_f = np.array([[cf, sf, 0.0], [-sf, cf, 0.0], [0.0, 0.0, 1.0]])       # Rz(−φ)
    Ry_t = np.array([[ct, 0.0, -st], [0.0, 1.0, 0.0], [st, 0.0, ct]])       # Ry(−θ)
    P = Ry_t @ Rz_f
    Q = P @ C
    h = math.hypot(Q[0, 2], Q[1, 2])
    ca, sa = (Q[0, 2] / h, Q[1, 2] / h) if h > 0.0 else (1.0, 0.0)
    Rz_a = np.array([[ca, sa, 0.0], [-sa, ca, 0.0], [0.0, 0.0, 1.0]])       # Rz(−α)
    Qp = Rz_a @ Q
    cb, sb = Qp[2, 2], Qp[0, 2]
    cg, sg = Qp[1, 1], Qp[1, 0]
    return r, Rz_a @ P, (cf, sf), (ct, st), (ca, sa), (cb, sb), (cg, sg)


def _y_rotation(c, l, cos_b, sin_b):
    J = j_matrix(l)
    return J.T @ z_rotation(J @ c, l, cos_b, sin_b)


def mutual_force_torque_lc(TA, TB, R, C, order, *, degrees=None, G=G_SI,
                           allow_lower_degree=False):
    """U_N, force on B, torque on B, torque on A (SI, A frame): the arguments, units and
    returns of :func:`ti_spinorbit.multipole.mutual_force_torque`, computed in real solid
    harmonics along the line of centres (module docstring)."""
    order = _check_order(order)
    dA, dB = _check_degrees(degrees, order)
    R = _check_R(R)
    C = _check_C(C)
    tA = coefficients(_integral_vector(TA, "TA", dA, dA, order, allow_lower_degree), dA)
    tB = coefficients(_integral_vector(TB, "TB", dB, dB, order, allow_lower_degree), dB)
    r, L, (cf, sf), (ct, st), (ca, sa), (cb, sb), (cg, sg) = _line_of_centres(R, C)
    A = [z_rotation(_y_rotation(z_rotation(tA[l], l, cf, -sf), l, ct, -st), l, ca, -sa)
         for l in range(dA + 1)]
    B = [_y_rotation(z_rotation(tB[l], l, cg, sg), l, cb, sb) for l in range(dB + 1)]
    U = 0.0
    dUdr = 0.0
    accA = [np.zeros(2 * l + 1) for l in range(dA + 1)]
    accB = [np.zeros(2 * l + 1) for l in range(dB + 1)]
    for l1 in range(dA + 1):
        for l2 in range(min(dB, order - l1) + 1):
            if l1 == 1 or l2 == 1:
                continue            # first moments vanish about the centres of mass
            w = -G / r ** (l1 + l2 + 1)
            K = coupling(l1, l2)
            KB = K @ B[l2]
            e = float(A[l1] @ KB)
            U += w * e
            dUdr -= (l1 + l2 + 1) * w * e / r
            accA[l1] += w * KB
            accB[l2] += w * (K.T @ A[l1])
    tauA = np.array([-sum(float(accA[l] @ (generators(l)[k] @ A[l])) for l in range(dA + 1))
                     for k in range(3)])
    tauB = np.array([-sum(float(accB[l] @ (generators(l)[k] @ B[l])) for l in range(dB + 1))
                     for k in range(3)])
    s = tauA + tauB
    dUdR = np.array([s[1] / r, -s[0] / r, dUdr])
    return U, -(L.T @ dUdR), L.T @ tauB, L.T @ tauA
