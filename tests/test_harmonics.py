"""The order-N mutual potential in real solid harmonics along the line of centres
(ti_spinorbit/harmonics.py, the host reference of the kernels' form, and the tables of
ti_spinorbit/engine/harmonic_tables.py) against the Cartesian host reference
(ti_spinorbit/multipole.py), exact identities of the harmonics, and the kernel at the
configurations where its angles degenerate."""

import math

import numpy as np
import pytest

from ti_spinorbit import harmonics as H
from ti_spinorbit import multipole as M
from ti_spinorbit.engine import harmonic_tables as HT
from ti_spinorbit.engine import multipole_tables as MT
from ti_spinorbit.system import integrals as I

from conftest import axis_rotation, cloud, degenerate_geometries, random_rotation


def evaluate(poly, E, pts):
    """Values of a polynomial (coefficients over the exponents E) at points (n, 3)."""
    return np.prod(pts[:, None, :] ** E[None, :, :], axis=2) @ poly


def block(l):
    E = M.multi_indices(l)
    return E[(E.sum(1) == l)]


@pytest.mark.parametrize("l", range(0, 9))
def test_solid_harmonics_are_harmonic_orthogonal_and_legendre(rng, l):
    """S_lm is harmonic (a finite-difference Laplacian at random points), the 2l + 1 of a
    degree are orthogonal with one norm on the sphere (Gauss quadrature), and S_l0 is
    r^l P_l(cos θ)."""
    S = H.solid_harmonics(l)[l]
    E = block(l)
    pts = rng.normal(size=(6, 3))
    h = 1e-3
    lap = sum(evaluate(S.T, E, pts + h * e) + evaluate(S.T, E, pts - h * e) for e in np.eye(3)) \
        - 6 * evaluate(S.T, E, pts)
    assert np.abs(lap / h**2).max() <= 1e-5 * max(1.0, np.abs(evaluate(S.T, E, pts)).max())
    # Gauss-Legendre in cos θ times the trapezoid rule in φ: exact for degree 2l
    x, w = np.polynomial.legendre.leggauss(l + 2)
    phi = np.linspace(0.0, 2 * np.pi, 2 * l + 3, endpoint=False)
    st = np.sqrt(1 - x**2)
    P = np.stack([np.outer(st, np.cos(phi)).ravel(), np.outer(st, np.sin(phi)).ravel(),
                  np.repeat(x, len(phi))], axis=1)
    W = np.repeat(w, len(phi)) * (2 * np.pi / len(phi))
    V = evaluate(S.T, E, P)                        # (points, 2l + 1)
    gram = V.T @ (W[:, None] * V)
    norm = 4 * np.pi / (2 * l + 1)                 # Racah's (Schmidt) normalisation
    np.testing.assert_allclose(gram, norm * np.eye(2 * l + 1), atol=1e-12 * norm)
    legendre = np.polynomial.legendre.legval(x, [0] * l + [1])
    np.testing.assert_allclose(V[::len(phi), l], legendre, atol=1e-13)


@pytest.mark.parametrize("l", [1, 2, 3, 5, 8, 12])
def test_rotations_of_coefficients(rng, l):
    """M_l is a representation (M(Q1 Q2) = M(Q1) M(Q2)), orthogonal; X(ψ) is M(Rz(ψ)); a
    y-rotation is Jᵀ X(β) J with J = M(Rx(90°)); and the generators are the derivatives of
    M at the identity (central differences)."""
    Q1, Q2 = random_rotation(rng), random_rotation(rng)
    tol = 1e-13 * (2 * l + 1) ** 2
    np.testing.assert_allclose(H.rotation_matrix(Q1 @ Q2, l),
                               H.rotation_matrix(Q1, l) @ H.rotation_matrix(Q2, l), atol=tol)
    Mq = H.rotation_matrix(Q1, l)
    np.testing.assert_allclose(Mq @ Mq.T, np.eye(2 * l + 1), atol=tol)
    c = rng.normal(size=2 * l + 1)
    psi, beta = 0.83, -1.27
    np.testing.assert_allclose(H.z_rotation(c, l, math.cos(psi), math.sin(psi)),
                               H.rotation_matrix(axis_rotation(2, psi), l) @ c, atol=tol)
    J = H.j_matrix(l)
    np.testing.assert_allclose(J, H.rotation_matrix(axis_rotation(0, math.pi / 2), l), atol=tol)
    np.testing.assert_allclose(J.T @ H.z_rotation(J @ c, l, math.cos(beta), math.sin(beta)),
                               H.rotation_matrix(axis_rotation(1, beta), l) @ c, atol=tol)
    G = H.generators(l)
    eps = 1e-6
    for k in range(3):
        d = (H.rotation_matrix(axis_rotation(k, eps), l)
             - H.rotation_matrix(axis_rotation(k, -eps), l)) / (2 * eps)
        np.testing.assert_allclose(G[k], d, atol=1e-8 * l * l)


def test_coefficients_are_the_harmonic_part_of_the_integrals(rng):
    """Integrals whose polynomial Φ_l(y) = Σ (l!/α!) T^α y^α differs by |y|² q(y) (q any
    polynomial of degree l − 2, which no harmonic sees) have the same coefficients; the
    representative tensor of a coefficient vector gives it back; the monopole coupling is 1
    (U = −G m_A m_B / r)."""
    l = 4
    t = rng.normal(size=(l + 1) * (l + 2) // 2)
    trace = np.zeros_like(t)
    q = rng.normal(size=l * (l - 1) // 2)          # a degree-(l − 2) tensor times r²
    E, E2 = block(l), block(l - 2)
    keys = [tuple(x) for x in E.tolist()]
    for coef, e in zip(q, E2):
        for i in range(3):
            f = tuple(int(x) for x in e + 2 * np.eye(3, dtype=int)[i])
            weight = math.prod(math.factorial(x) for x in f) / math.factorial(l)   # α!/l!
            trace[keys.index(f)] += weight * coef
    P = H.projector(l)
    np.testing.assert_allclose(P @ (t + trace), P @ t, atol=1e-13 * np.abs(P @ t).max())
    c = rng.normal(size=2 * l + 1)
    np.testing.assert_allclose(P @ H.representative(c, l), c, atol=1e-13)
    assert H.coupling(0, 0)[0, 0] == pytest.approx(1.0, abs=1e-15)
    K = H.coupling(3, 5)
    assert np.count_nonzero(K) == 7 and np.count_nonzero(np.diag(K[:, 2:9])) == 7


@pytest.mark.parametrize("order,degrees", [(2, None), (4, None), (6, None), (8, None),
                                           (12, None), (8, (8, 4)), (6, (2, 6)), (9, (5, 9))])
def test_host_harmonic_form_equals_the_cartesian_reference(rng, order, degrees):
    """U, force and both torques of the two host references agree to round-off at orders 2
    to 12, with degree caps, at degenerate and generic geometries; the secondary's rotation C
    is built so that its z axis lies along or against R where a case asks for β = 0 or π."""
    TA = cloud(rng, 40, 0.4, 1.0, order)
    TB = cloud(rng, 30, 0.2, 0.1, order)
    tol = 2e-13 if order <= 8 else 3e-12
    for R, C in degenerate_geometries(rng):
        ref = M.mutual_force_torque(TA, TB, R, C, order, degrees=degrees, G=1.0)
        got = H.mutual_force_torque_lc(TA, TB, R, C, order, degrees=degrees, G=1.0)
        assert abs(got[0] - ref[0]) <= tol * abs(ref[0])
        for g, r in zip(got[1:], ref[1:]):
            assert np.linalg.norm(g - r) <= tol * max(np.linalg.norm(r), 1e-300) \
                or np.linalg.norm(g - r) <= tol * np.linalg.norm(ref[1]) * np.linalg.norm(R)


def test_tables_hold_the_matrices_and_rows_do_not_depend_on_their_neighbours(rng):
    """The primary's program (its J and Jᵀ rows: dense class blocks in chunks of
    ``CHUNK`` columns) rebuilds J_l exactly and the rows of J_lᵀ its degree needs (|m| up
    to one past what its terms reach), every chunk inside its degree; an ellipsoid's odd
    degrees are masked out and a cloud's are not; a member's coefficient row is bit for bit
    the same alone and among other rows."""
    from ti_spinorbit.layout import harmonic as K
    tab = HT.tables(12, 8, 8)                      # degrees 2..8, reaching m = 4..8
    tops = HT.top_orders(12, 8, 8)[0]
    assert tops == {2: 2, 3: 3, 4: 4, 5: 5, 6: 6, 7: 5, 8: 4}
    pg, W = K.K_PROG_A, HT.CHUNK
    mask = (1 << HT.BITS) - 1
    for which, keys in enumerate(((K.P_NJ, K.P_J, K.P_FJ, K.P_NJX, K.P_JX, K.P_FJX),
                                  (K.P_NJT, K.P_JT, K.P_FJT, K.P_NJTX, K.P_JTX, K.P_FJTX))):
        n, o, f0, nx, ox, fx = (int(tab.ints[pg + key]) for key in keys)
        # every chunk as (destination, source, weights): the plain list's, then both rows of
        # each fused entry (dst | src << 9 | flags << 18 for row p, then dst | src << 9 for q)
        chunks = [(w & mask, (w >> HT.BITS) & mask, tab.floats[f0 + W * e:f0 + W * (e + 1)])
                  for e, w in enumerate(tab.ints[o:o + n])]
        fused = tab.ints[ox:ox + 2 * nx].reshape(nx, 2)
        for e, (wp, wq) in enumerate(fused):
            assert not wp >> 2 * HT.BITS & HT.ZERO_SIN            # a cloud: no zero class
            f = fx + 2 * W * e
            chunks += [(wp & mask, (wp >> HT.BITS) & mask, tab.floats[f:f + W]),
                       (wq & mask, (wq >> HT.BITS) & mask, tab.floats[f + W:f + 2 * W])]
        for l in range(2, 9):
            reach = 8 if which == 0 else min(l, tops[l] + 1)
            rows = [l * l + HT.position(l, m) for m in range(-l, l + 1) if abs(m) <= reach]
            J = np.zeros((2 * l + 1, 2 * l + 1))
            mine = [c for c in chunks if l * l <= c[0] < (l + 1) ** 2]
            assert {c[0] for c in mine} == set(rows)
            for dst, src, w in mine:
                assert l * l <= src and src + W <= (l + 1) ** 2
                J[dst - l * l, src - l * l:src - l * l + W] += w
            target = H.j_matrix(l) if which == 0 else H.j_matrix(l).T
            perm = HT.permutation(l)
            kept = [r - l * l for r in rows]
            np.testing.assert_array_equal(J[kept], target[np.ix_(perm, perm)][kept])
    ell = MT.body_integrals(_Ell(), 6)
    rows = np.concatenate([ell, ell])[None]
    mask = HT.degree_mask(HT.coefficient_rows(rows, 6, 6), 6)
    assert mask == 1 | 4 | 16 | 64
    T = cloud(rng, 20, 0.3, 1.0, 6)
    crow = np.array([T.get(tuple(int(x) for x in e), 0.0) for e in M.multi_indices(6)])
    many = np.concatenate([crow, crow])[None] * rng.uniform(0.5, 2.0, size=(37, 1))
    assert HT.degree_mask(HT.coefficient_rows(many, 6, 6), 6) == 1 | sum(1 << l
                                                                        for l in range(2, 7))
    alone = HT.coefficient_rows(many[5:6], 6, 6)
    np.testing.assert_array_equal(HT.coefficient_rows(many, 6, 6)[5:6], alone)


class _Ell:
    """An ellipsoid's integrals as a body would answer them (exact zeros when odd)."""

    def __init__(self):
        self.T = I.ellipsoid_integrals(1.0, 0.8, 0.6, 1.0, 6)

    def integral(self, l, m, n):
        return self.T.get((l, m, n), 0.0)
