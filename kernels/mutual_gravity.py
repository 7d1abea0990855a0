"""Fourth-order mutual potential, force and torques between two rigid bodies (Taichi).

Explicit truncation of the inertia-integral expansion (Ashenberg 2007; Hou, Scheeres & Xin
2017; docs/physics.md §3.2–3.5), evaluated the cheap way:

* each body's single-body terms L2, L3, L4 and their gradients are evaluated in that body's
  own frame (rotate the unit vector e, never a rank-3 or rank-4 tensor);
* only the quadrupole-quadrupole cross term X needs both bodies, and it needs only the
  rotated 3x3 second moment J'_B = S J_B S^T;
* the torque on the primary follows from the exact identity mu1 + mu2 = R x dU/dR, so total
  angular momentum is conserved to round-off by construction.

Conventions (primary frame A): R points from A's centre of mass to B's; S maps B-frame
vectors into A; U = -G ∫∫ dm dm / |R + S x_B - x_A|; ``dUdR`` = ∂U/∂R (the force on B is
-dUdR); mu2 = torque on B, mu1 = torque on A (δU = -mu·δθ for a rotation of one body).

Body parameters are read from a row of a 2-D f64 field in the order of
``ti_spinorbit.system.bodies.Body.as_row``: mass, (T200, T020, T002), 10 third-order and 15
fourth-order integrals in ``EXPONENTS_3`` / ``EXPONENTS_4`` order.

Static switches compile away what a model does not need: ``order`` in {0, 2, 3, 4} and
``odd`` (False when every body of the ensemble is mirror-symmetric, e.g. ellipsoids: then the
third-order terms and the 9 odd fourth-order monomials vanish and are not emitted).
Accuracy of the truncation itself, not of this code: near contact (|R| ≈ 2 a_primary)
about 1e-5 in U, 1e-4 in force and 1e-2 in torque (the torque error falls like R^-4).
"""

import math

import taichi as ti

from ti_spinorbit.layout import EXPONENTS_3, EXPONENTS_4

vec3 = ti.types.vector(3, ti.f64)
mat3 = ti.types.matrix(3, 3, ti.f64)

# Offsets inside a body row (Body.as_row).
MASS, T2, T3, T4 = 0, 1, 4, 14


def _multinomial(exponents):
    l, m, n = exponents
    return math.factorial(l + m + n) // (math.factorial(l) * math.factorial(m) * math.factorial(n))


def _is_even(exponents):
    return all(k % 2 == 0 for k in exponents)


def _index_of(table, exponents):
    return table.index(tuple(exponents))


# Monomial tables as plain tuples, unrolled with ti.static:
# (offset in the row, multinomial coefficient, exponents, parity)
_MONO3 = tuple((T3 + i, _multinomial(k), k, _is_even(k)) for i, k in enumerate(EXPONENTS_3))
_MONO4 = tuple((T4 + i, _multinomial(k), k, _is_even(k)) for i, k in enumerate(EXPONENTS_4))


def _contraction_terms(table, base, rank):
    """Offsets whose sum gives the contracted tensor S_{i..kk}: for each free index pattern,
    the integrals with one extra pair (2,0,0), (0,2,0), (0,0,2) added."""
    out = []
    free = rank - 2
    patterns = [(l, m, free - l - m) for l in range(free, -1, -1) for m in range(free - l, -1, -1)]
    for p in patterns:
        terms = []
        for pair in ((2, 0, 0), (0, 2, 0), (0, 0, 2)):
            k = tuple(x + y for x, y in zip(p, pair))
            terms.append(base + _index_of(table, k))
        out.append((p, tuple(terms), _is_even(p)))
    return tuple(out)


# S3_ikk for i = x, y, z (vector); S4_ijkk for the 6 (i, j) patterns (symmetric 3x3).
_CONTRACT3 = _contraction_terms(EXPONENTS_3, T3, 3)
_CONTRACT4 = _contraction_terms(EXPONENTS_4, T4, 4)


# 3x3 products written out. Taichi's ``@`` starts every sum from a computed zero
# (x[0,0] y[0] * 0) and multiplies the explicit zeros of a diagonal matrix too: the same sums
# in the same order plus work LLVM may not drop (no fast-math), and a front end that costs
# the 3-D kernels a third of their variables. These give the same values (the dropped terms
# are exact zeros) with the terms summed in Taichi's order, k = 0, 1, 2.
@ti.func
def mat_vec(M, v):
    """M v."""
    return vec3(M[0, 0] * v[0] + M[0, 1] * v[1] + M[0, 2] * v[2],
                M[1, 0] * v[0] + M[1, 1] * v[1] + M[1, 2] * v[2],
                M[2, 0] * v[0] + M[2, 1] * v[1] + M[2, 2] * v[2])


@ti.func
def mat_t_vec(M, v):
    """Mᵀ v."""
    return vec3(M[0, 0] * v[0] + M[1, 0] * v[1] + M[2, 0] * v[2],
                M[0, 1] * v[0] + M[1, 1] * v[1] + M[2, 1] * v[2],
                M[0, 2] * v[0] + M[1, 2] * v[1] + M[2, 2] * v[2])


@ti.func
def rotate_diagonal(S, d):
    """S diag(d) Sᵀ, each entry Σ_k (S_rk d_k) S_ck."""
    return mat3([[(S[r, 0] * d[0]) * S[c, 0] + (S[r, 1] * d[1]) * S[c, 1]
                  + (S[r, 2] * d[2]) * S[c, 2] for c in ti.static(range(3))]
                 for r in ti.static(range(3))])


@ti.func
def _powers(x):
    return ti.Vector([1.0, x, x * x, x * x * x, x * x * x * x])


@ti.func
def _monomials(p: ti.template(), i, off: ti.template(), table: ti.template(), px, py, pz,
               odd: ti.template()):
    """Q = Σ c T^{lmn} x^l y^m z^n over a monomial table and its gradient; with ``odd``
    False the monomials with an odd exponent are not emitted."""
    q = 0.0
    dq = vec3(0.0)
    for o, c, k, even in ti.static(table):
        if ti.static(odd or even):
            t = c * p[i, off + o]
            q += t * px[k[0]] * py[k[1]] * pz[k[2]]
            if ti.static(k[0] > 0):
                dq[0] += t * k[0] * px[k[0] - 1] * py[k[1]] * pz[k[2]]
            if ti.static(k[1] > 0):
                dq[1] += t * k[1] * px[k[0]] * py[k[1] - 1] * pz[k[2]]
            if ti.static(k[2] > 0):
                dq[2] += t * k[2] * px[k[0]] * py[k[1]] * pz[k[2] - 1]
    return q, dq


@ti.func
def single_body_terms(p: ti.template(), i, off: ti.template(), u, order: ti.template(),
                      odd: ti.template()):
    """L2, L3, L4 of one body for the unit vector ``u`` in that body's frame, and their free
    gradients (docs/physics.md §3.2). Returns (L2, g2, L3, g3, L4, g4)."""
    t200 = p[i, off + T2]
    t020 = p[i, off + T2 + 1]
    t002 = p[i, off + T2 + 2]
    L2 = 1.5 * (t200 * u[0] * u[0] + t020 * u[1] * u[1] + t002 * u[2] * u[2]) - 0.5 * (t200 + t020 + t002)
    g2 = 3.0 * vec3(t200 * u[0], t020 * u[1], t002 * u[2])
    L3 = 0.0
    g3 = vec3(0.0)
    L4 = 0.0
    g4 = vec3(0.0)
    px = _powers(u[0])
    py = _powers(u[1])
    pz = _powers(u[2])
    if ti.static(order >= 3 and odd):
        q3, dq3 = _monomials(p, i, off, _MONO3, px, py, pz, True)
        v3 = vec3(0.0)
        for pat, terms, _even in ti.static(_CONTRACT3):
            axis = ti.static(0 if pat[0] else (1 if pat[1] else 2))
            v3[axis] = p[i, off + terms[0]] + p[i, off + terms[1]] + p[i, off + terms[2]]
        L3 = 2.5 * q3 - 1.5 * v3.dot(u)
        g3 = 2.5 * dq3 - 1.5 * v3
    if ti.static(order >= 4):
        q4, dq4 = _monomials(p, i, off, _MONO4, px, py, pz, odd)
        # K_ij = S4_ijkk (symmetric); Q2 = u.K.u, Q0 = tr K
        K = mat3(0.0)
        for pat, terms, even in ti.static(_CONTRACT4):
            if ti.static(odd or even):
                a = ti.static([0] * pat[0] + [1] * pat[1] + [2] * pat[2])
                val = p[i, off + terms[0]] + p[i, off + terms[1]] + p[i, off + terms[2]]
                K[a[0], a[1]] = val
                K[a[1], a[0]] = val
        Ku = mat_vec(K, u)
        L4 = 4.375 * q4 - 3.75 * u.dot(Ku) + 0.375 * (K[0, 0] + K[1, 1] + K[2, 2])
        g4 = 4.375 * dq4 - 7.5 * Ku
    return L2, g2, L3, g3, L4, g4


@ti.func
def mutual(p: ti.template(), i, offA: ti.template(), offB: ti.template(), G, R, S,
           order: ti.template(), odd: ti.template()):
    """Mutual potential U, gradient dU/dR, torque on A (mu1) and on B (mu2), all in frame A.

    ``p[i, offA + ...]`` and ``p[i, offB + ...]`` hold the two body rows (Body.as_row), in
    whatever unit system ``G`` belongs to."""
    mA = p[i, offA + MASS]
    mB = p[i, offB + MASS]
    r2 = R.dot(R)
    r = ti.sqrt(r2)
    inv_r = 1.0 / r
    e = R * inv_r
    U = mA * mB * inv_r                      # Ũ0 / r, the sign and G applied at the end
    grad = -mA * mB * inv_r * inv_r * e      # ∂(Ũ0/r)/∂R
    torqueB_e = vec3(0.0)                    # ∇_e of B-only terms, times its 1/r^(n+1)
    mu2 = vec3(0.0)
    if ti.static(order >= 2):
        eB = mat_t_vec(S, e)
        L2A, g2A, L3A, g3A, L4A, g4A = single_body_terms(p, i, offA, e, order, odd)
        L2B, g2B, L3B, g3B, L4B, g4B = single_body_terms(p, i, offB, eB, order, odd)
        inv_r2 = inv_r * inv_r
        inv_r3 = inv_r2 * inv_r
        # order 2
        gB2 = mat_vec(S, g2B)
        U2 = mB * L2A + mA * L2B
        g2 = mB * g2A + mA * gB2
        U += U2 * inv_r3
        grad += ((g2 - g2.dot(e) * e) - 3.0 * U2 * e) * inv_r3 * inv_r
        torqueB_e += mA * gB2 * inv_r3
        if ti.static(order >= 3 and odd):
            gB3 = mat_vec(S, g3B)
            U3 = mB * L3A - mA * L3B
            g3 = mB * g3A - mA * gB3
            inv_r4 = inv_r3 * inv_r
            U += U3 * inv_r4
            grad += ((g3 - g3.dot(e) * e) - 4.0 * U3 * e) * inv_r4 * inv_r
            torqueB_e -= mA * gB3 * inv_r4
        if ti.static(order >= 4):
            # quadrupole-quadrupole cross term X (docs/physics.md §3.2)
            JA = ti.Vector([p[i, offA + T2], p[i, offA + T2 + 1], p[i, offA + T2 + 2]])
            jB = ti.Vector([p[i, offB + T2], p[i, offB + T2 + 1], p[i, offB + T2 + 2]])
            JBp = rotate_diagonal(S, jB)             # J'_B = S J_B Sᵀ
            trA = JA[0] + JA[1] + JA[2]
            trB = jB[0] + jB[1] + jB[2]
            u = JA * e                               # J_A e
            w = mat_vec(JBp, e)                      # J'_B e
            a = e.dot(u)
            b = e.dot(w)
            JAJB = ti.Matrix([[JA[r_] * JBp[r_, c_] for c_ in ti.static(range(3))]
                              for r_ in ti.static(range(3))])
            X = (26.25 * a * b - 3.75 * (a * trB + b * trA) - 15.0 * u.dot(w)
                 + 0.75 * trA * trB + 1.5 * (JAJB[0, 0] + JAJB[1, 1] + JAJB[2, 2]))
            Jw = JA * w                              # J_A J'_B e
            Ju = mat_vec(JBp, u)                     # J'_B J_A e
            gX = 52.5 * (b * u + a * w) - 7.5 * (trB * u + trA * w) - 15.0 * (Jw + Ju)
            gB4 = mat_vec(S, g4B)
            U4 = mB * L4A + mA * L4B + X
            g4 = mB * g4A + mA * gB4 + gX
            inv_r5 = inv_r3 * inv_r2
            U += U4 * inv_r5
            grad += ((g4 - g4.dot(e) * e) - 5.0 * U4 * e) * inv_r5 * inv_r
            torqueB_e += mA * gB4 * inv_r5
            epsAB = vec3((JA[1] - JA[2]) * JBp[1, 2], (JA[2] - JA[0]) * JBp[0, 2],
                         (JA[0] - JA[1]) * JBp[0, 1])
            mu2 += -2.0 * G * inv_r5 * ((26.25 * a - 3.75 * trA) * e.cross(w)
                                        - 7.5 * (u.cross(w) + e.cross(Ju)) + 1.5 * epsAB)
        mu2 += e.cross(-G * torqueB_e)
    dUdR = -G * grad
    mu1 = R.cross(dUdR) - mu2
    return -G * U, dUdR, mu1, mu2


def make_evaluate(potential, flat=False):
    """A kernel evaluating an order-N ``potential`` func (``harmonic_gravity.mutual_h`` or
    ``multipole_gravity.mutual_n``: (rows, j, scr, k, tab_i, tab_f, G, R, S) -> (U, dU/dR,
    mu1, mu2)) for each row i of R_nd (3) and S_nd (3, 3): out[i] = [U, dU/dR, mu1, mu2],
    member i's row and scratch slot i (``flat``: rows and scratch as the harmonic kernels'
    flat arrays, row i at i times the row's width; else one row per member)."""
    nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
    nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
    nd3f = ti.types.ndarray(dtype=ti.f64, ndim=3)
    nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)
    ndsf = ti.types.ndarray(dtype=ti.f64, ndim=1 if flat else 2)

    @ti.kernel
    def evaluate_multipole(rows: ndsf, R_nd: nd2f, S_nd: nd3f, scr: ndsf, tab_i: nd1i,
                           tab_f: nd1f, out: nd2f, G: ti.f64):
        for i in range(R_nd.shape[0]):
            R = vec3(R_nd[i, 0], R_nd[i, 1], R_nd[i, 2])
            S = ti.Matrix([[S_nd[i, r, c] for c in ti.static(range(3))]
                           for r in ti.static(range(3))])
            U, dUdR, mu1, mu2 = potential(rows, i, scr, i, tab_i, tab_f, G, R, S)
            out[i, 0] = U
            for c in ti.static(range(3)):
                out[i, 1 + c] = dUdR[c]
                out[i, 4 + c] = mu1[c]
                out[i, 7 + c] = mu2[c]

    return evaluate_multipole
