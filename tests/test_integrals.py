"""Inertia integrals at any order (ti_spinorbit.system.integrals), each checked by a route of
its own: closed forms of a box, an independent volume of a torus (a non-star-shaped mesh),
the O(h²) convergence of polyhedral ellipsoids, brute-force sums over point clouds, exact
quadrature of the ellipsoid in spherical coordinates and a cell grid, and the error
messages. Pure NumPy, a few seconds."""

import importlib.util
import itertools
import math
import os

import numpy as np
import pytest

from conftest import random_rotation

try:
    from ti_spinorbit.system import integrals as I
except ImportError:             # the package is being reorganised: load the file on its own
    _path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                         "ti_spinorbit", "system", "integrals.py")
    _spec = importlib.util.spec_from_file_location("_integrals_standalone", _path)
    I = importlib.util.module_from_spec(_spec)
    _spec.loader.exec_module(I)

AXES = np.array([1.5, 1.0, 0.7])            # test ellipsoid's semi-axes, m


# ---- meshes and helpers -----------------------------------------------------------------
def box_mesh(a, b, c):
    """The box [-a, a] × [-b, b] × [-c, c] as 12 outward-wound triangles."""
    V = np.array([[x, y, z] for x in (-a, a) for y in (-b, b) for z in (-c, c)])  # 4i+2j+k
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    F = [t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))]
    return V, np.array(F)


def icosphere(level):
    """Unit icosphere, 20·4^level outward-wound triangles (edges split, midpoints projected
    onto the sphere)."""
    p = (1 + 5**0.5) / 2
    V = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
                  [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]],
                 dtype=float)
    V /= np.linalg.norm(V, axis=1)[:, None]
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                  [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                  [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                  [8, 6, 7], [9, 8, 1]])
    for _ in range(level):
        edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        uniq, inv = np.unique(edges, axis=0, return_inverse=True)
        inv = inv.ravel() + len(V)
        mid = V[uniq[:, 0]] + V[uniq[:, 1]]
        V = np.vstack([V, mid / np.linalg.norm(mid, axis=1)[:, None]])
        nf = len(F)
        ab, bc, ca = inv[:nf], inv[nf:2 * nf], inv[2 * nf:]
        a, b, c = F.T
        F = np.concatenate([np.stack(t, 1) for t in ((a, ab, ca), (b, bc, ab), (c, ca, bc),
                                                     (ab, bc, ca))])
    return V, F


def torus_mesh(R, r, nu, nv):
    """Torus of major radius R and tube radius r about z, nu × nv quads split in two,
    wound along ∂u × ∂v (outward)."""
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U),
                  r * np.sin(W)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    k = lambda a, b: (a % nu) * nv + (b % nv)               # noqa: E731
    p00, p10, p11, p01 = k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1)
    F = np.concatenate([np.stack([p00, p10, p11], -1).reshape(-1, 3),
                        np.stack([p00, p11, p01], -1).reshape(-1, 3)])
    return V, F




def degree_errors(T, ref, order):
    """Per degree n, max |T − ref| over the integrals of degree n divided by the scale of
    that degree: the largest |ref| of degree n, or M L^n if larger (M = ref[(0, 0, 0)], L
    the RMS radius about the origin), so that degrees whose integrals vanish or nearly
    vanish (odd degrees of a mirror-symmetric body; first moments about the centre) are
    measured against the size of the terms that cancel in them."""
    M = ref[(0, 0, 0)]
    L = math.sqrt((ref[(2, 0, 0)] + ref[(0, 2, 0)] + ref[(0, 0, 2)]) / M)
    out = []
    for n in range(order + 1):
        keys = [k for k in ref if sum(k) == n]
        scale = max(max(abs(ref[k]) for k in keys), M * L**n)
        out.append(max(abs(T[k] - ref[k]) for k in keys) / scale)
    return np.array(out)


def cloud(rng, n=60):
    pts = rng.normal(size=(n, 3)) * [0.9, 0.6, 0.4] + [0.3, -0.2, 0.1]
    pts[: n // 3] += [0.5, 0.3, -0.2]                      # no mirror symmetry
    return pts, rng.uniform(0.5, 1.5, n)


@pytest.fixture
def rng():
    return np.random.default_rng(20170369)


# ---- representation ----------------------------------------------------------------------
def test_multi_indices_order_and_count():
    assert I.multi_indices(2)[4:] == ((2, 0, 0), (1, 1, 0), (1, 0, 1), (0, 2, 0), (0, 1, 1),
                                      (0, 0, 2))
    for order in (0, 1, 5, 12, 16):
        mi = I.multi_indices(order)
        assert len(mi) == math.comb(order + 3, 3) == len(set(mi))
        assert set(mi) == {a for a in itertools.product(range(order + 1), repeat=3)
                           if sum(a) <= order}
        assert list(mi) == sorted(mi, key=lambda a: (sum(a), -a[0], -a[1]))
    assert len(I.multi_indices(12)) == 455
    T = I.ellipsoid_integrals(1.0, 1.0, 1.0, 1.0, 3)
    assert tuple(T) == I.multi_indices(3) and all(type(v) is np.float64 for v in T.values())


# ---- (a) box: closed form, to rounding -----------------------------------------------------
def test_box_matches_closed_form_to_order_8():
    a, b, c, rho = 1.0, 0.7, 0.3, 2170.0                   # 2 × 1.4 × 0.6 m
    V, F = box_mesh(a, b, c)
    assert len(F) == 12 and I.volume_of(V, F) == pytest.approx(1.68, rel=1e-15)
    line = lambda k, h: 0.0 if k % 2 else 2 * h**(k + 1) / (k + 1)   # ∫_{-h}^{h} t^k dt
    absline = lambda k, h: 2 * h**(k + 1) / (k + 1)                  # ∫_{-h}^{h} |t|^k dt
    exact = {(l, m, n): rho * line(l, a) * line(m, b) * line(n, c)
             for l, m, n in I.multi_indices(8)}
    T = I.polyhedron_integrals(V, F, 8, rho)
    assert tuple(T) == I.multi_indices(8)
    for n in range(9):
        keys = [k for k in exact if sum(k) == n]
        # the largest of the degree (for odd degrees, whose integrals all vanish, the largest
        # ∫|x^l y^m z^n| dm instead: the size of the terms that cancel)
        scale = max(rho * absline(l, a) * absline(m, b) * absline(k, c) for l, m, k in keys)
        assert max(abs(T[k] - exact[k]) for k in keys) <= 1e-14 * scale, n


def test_translated_box_far_from_the_origin():
    # the mesh is integrated about its own centre and shifted back: far from the origin the
    # integrals equal the exact shift of the centred ones
    V, F = box_mesh(1.0, 0.7, 0.3)
    d = np.array([310.0, -145.0, 72.5])
    T0 = I.polyhedron_integrals(V, F, 6, 1.0)
    T = I.polyhedron_integrals(V + d, F, 6, 1.0)
    assert degree_errors(T, I.shift_integrals(T0, d), 6).max() < 2e-13     # measured 2.6e-14


def test_lopsided_tetrahedron_against_collapsed_gauss_quadrature(rng):
    # no mirror symmetry, so the odd integrals are tested too (the box's all vanish). The
    # independent route: the cube [0,1]³ collapsed onto the tetrahedron (u1 = s,
    # u2 = (1-s) t, u3 = (1-s)(1-t) w, Jacobian (1-s)² (1-t)) with 8 Gauss-Legendre nodes
    # per direction, exact for polynomials of degree <= 13 on the tetrahedron
    P = np.array([[0.3, -0.2, 0.5], [1.9, 0.1, 0.4], [0.6, 1.3, -0.2], [0.8, 0.5, 1.7]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    vol = np.dot(P[1] - P[0], np.cross(P[2] - P[0], P[3] - P[0])) / 6
    assert vol > 0 and I.volume_of(P, F) == pytest.approx(vol, rel=1e-14)
    g, w = np.polynomial.legendre.leggauss(8)
    g, w = (g + 1) / 2, w / 2
    s, t, u = np.meshgrid(g, g, g, indexing="ij")
    W = (w[:, None, None] * w[None, :, None] * w[None, None, :]) * (1 - s)**2 * (1 - t)
    u1, u2, u3 = s, (1 - s) * t, (1 - s) * (1 - t) * u
    pts = (P[0] + u1[..., None] * (P[1] - P[0]) + u2[..., None] * (P[2] - P[0])
           + u3[..., None] * (P[3] - P[0])).reshape(-1, 3)
    rho = 1500.0
    Q = I.point_mass_integrals(pts, rho * 6 * vol * W.ravel(), 12)
    T = I.polyhedron_integrals(P, F, 12, rho)
    assert degree_errors(T, Q, 12).max() < 1e-13
    assert abs(T[(1, 0, 0)] / T[(0, 0, 0)] - P[:, 0].mean()) < 1e-15


# ---- (b) torus: signed tetrahedra on a non-star-shaped mesh --------------------------------
def test_torus_signed_volume():
    R, r = 1.0, 0.3
    V, F = torus_mesh(R, r, 96, 48)
    vol = I.volume_of(V, F)
    # independent route: divergence theorem, V = (1/3) Σ A (centroid · n) with area vectors
    p1, p2, p3 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    area_vec = 0.5 * np.cross(p2 - p1, p3 - p1)
    div = np.sum(np.einsum("ij,ij->i", (p1 + p2 + p3) / 3, area_vec)) / 3
    assert vol == pytest.approx(div, rel=1e-13)
    assert vol == pytest.approx(2 * np.pi**2 * R * r**2, rel=5e-3)
    # with |D| the hole would count: +61 % about the centre, +62 % about a point off the axis;
    # the signed sum does not depend on the origin
    for d in (np.zeros(3), np.array([0.4, -0.25, 0.1])):
        Dabs = np.abs(np.einsum("ij,ij->i", p1 - d, np.cross(p2 - d, p3 - d))).sum() / 6
        assert Dabs > 1.5 * vol
    assert I.volume_of(V - d, F) == pytest.approx(vol, rel=1e-13)
    T = I.polyhedron_integrals(V, F, 4, 1.0)
    assert T[(0, 0, 0)] == pytest.approx(vol, rel=1e-13)
    # second moments of the solid torus: ∫(x²+y²) dV = V (R² + 3r²/4), ∫z² dV = V r²/4 (the
    # mesh's polygonal cross-section is ~0.3 % off)
    assert T[(2, 0, 0)] == pytest.approx(vol * (R**2 + 0.75 * r**2) / 2, rel=5e-3)
    assert T[(0, 0, 2)] == pytest.approx(vol * r**2 / 4, rel=1e-2)
    assert T[(1, 0, 0)] == pytest.approx(0, abs=1e-14)


# ---- (c) polyhedral ellipsoids converge at O(h²) ----------------------------------------------
def test_icosphere_ellipsoid_converges_at_second_order():
    E = I.ellipsoid_integrals(*AXES, 4 / 3 * np.pi * AXES.prod(), 4)
    errs = []
    for level in range(2, 6):                              # 320 ... 20480 facets
        V, F = icosphere(level)
        T = I.polyhedron_integrals(V * AXES, F, 4, 1.0)
        errs.append([abs(T[k] / E[k] - 1) for k in ((2, 0, 0), (2, 2, 0), (0, 0, 4))])
    slopes = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))   # h halves per level
    assert np.all((slopes > 1.8) & (slopes < 2.2)), slopes
    assert max(errs[-1]) < 2e-3


# ---- (d) shift and rotate, against the transformed cloud ------------------------------------
def test_shift_and_rotate_match_transformed_cloud(rng):
    pts, m = cloud(rng)
    T = I.point_mass_integrals(pts, m, 10)
    d = np.array([0.7, -1.1, 0.4])
    R = random_rotation(rng)
    assert degree_errors(I.shift_integrals(T, d), I.point_mass_integrals(pts + d, m, 10),
                         10).max() < 1e-13
    assert degree_errors(I.rotate_integrals(T, R), I.point_mass_integrals(pts @ R.T, m, 10),
                         10).max() < 1e-13
    # and composed, then undone
    T2 = I.rotate_integrals(I.shift_integrals(T, d), R)
    back = I.shift_integrals(I.rotate_integrals(T2, R.T), -d)
    assert degree_errors(back, T, 10).max() < 1e-12


def test_point_masses_by_brute_force(rng):
    pts, m = cloud(rng, 25)
    T = I.point_mass_integrals(pts, m, 7)
    for l, n_, k in I.multi_indices(7):
        ref = math.fsum(float(w) * float(x)**l * float(y)**n_ * float(z)**k
                        for w, (x, y, z) in zip(m, pts))
        assert T[(l, n_, k)] == pytest.approx(ref, rel=1e-12, abs=1e-14)


def test_rotate_at_order_12_and_16(rng):
    pts, m = cloud(rng, 30)
    R = random_rotation(rng)
    for order in (12, 16):
        T = I.point_mass_integrals(pts, m, order)
        err = degree_errors(I.rotate_integrals(T, R), I.point_mass_integrals(pts @ R.T, m, order),
                            order)
        assert err.max() < 1e-13, (order, err.max())


# ---- (e) principal frame of a rotated, shifted ellipsoid mesh ----------------------------------
def test_principal_frame_recovers_ellipsoid(rng):
    V, F = icosphere(4)                                    # 5120 facets
    V = V * AXES
    # the offset is of the body's size: integrals about an origin at distance D are of size
    # M D^n and recovering the centred ones from them loses a factor ~(D/L)^n to rounding
    Q0, c0 = random_rotation(rng), np.array([1.2, -0.75, 0.325])
    rho = 2000.0
    T = I.polyhedron_integrals(V @ Q0.T + c0, F, 6, rho)   # body rotated by Q0, moved to c0
    Tp, offset, rot = I.principal_frame(T)
    assert np.allclose(offset, c0, rtol=0, atol=1e-12 * np.linalg.norm(c0))
    # x_principal = rot @ (x - c0) = rot @ Q0 @ x_body: rot @ Q0 is diag(±1, ±1, ±1)
    P = rot @ Q0
    assert np.allclose(np.abs(P), np.eye(3), atol=1e-10) and np.linalg.det(rot) > 0
    for row in rot[:2]:                                    # largest component positive
        assert row[np.argmax(np.abs(row))] > 0
    # the mesh has the coordinate planes as mirror planes, so the signs of P do not matter
    ref = I.polyhedron_integrals(V, F, 6, rho)
    assert degree_errors(Tp, ref, 6).max() < 1e-12
    E = I.ellipsoid_integrals(*AXES, rho * 4 / 3 * np.pi * AXES.prod(), 6)
    assert degree_errors(Tp, E, 6).max() < 1e-2           # level 4: ~4e-3 discretisation
    assert Tp[(2, 0, 0)] > Tp[(0, 2, 0)] > Tp[(0, 0, 2)]


def test_principal_frame_maps_points(rng):
    pts, m = cloud(rng)
    T = I.point_mass_integrals(pts, m, 8)
    Tp, offset, rot = I.principal_frame(T)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-14) and np.linalg.det(rot) > 0
    ref = I.point_mass_integrals((pts - offset) @ rot.T, m, 8)
    assert degree_errors(Tp, ref, 8).max() < 1e-12
    s2 = Tp[(2, 0, 0)]
    assert Tp[(2, 0, 0)] >= Tp[(0, 2, 0)] >= Tp[(0, 0, 2)]
    for k in ((1, 0, 0), (0, 1, 0), (0, 0, 1)):
        assert abs(Tp[k]) < 1e-14 * m.sum() * 3
    for k in ((1, 1, 0), (1, 0, 1), (0, 1, 1)):
        assert abs(Tp[k]) < 1e-14 * s2
    # deterministic, and idempotent
    Tq, off2, rot2 = I.principal_frame(Tp)
    assert np.allclose(off2, 0, atol=1e-14) and np.allclose(rot2, np.eye(3), atol=1e-12)


# ---- (f) ellipsoid closed form against quadratures -------------------------------------------
def test_ellipsoid_against_spherical_gauss_quadrature():
    # x = (a ρ sinθ cosφ, b ρ sinθ sinφ, c ρ cosθ), dV = abc ρ² dρ dcosθ dφ; for |α| <= 6 the
    # integrand is a polynomial of degree <= 8 in ρ and <= 6 in cosθ (odd powers of sinθ only
    # come with odd powers of cosφ or sinφ, which the φ sum cancels) and a trigonometric
    # polynomial of degree <= 6 in φ: 8 Gauss-Legendre nodes in ρ and cosθ and 16 equal
    # steps in φ are exact, so the two must agree to rounding.
    M = 3.0e11
    g, w = np.polynomial.legendre.leggauss(8)
    rho, wr = (g + 1) / 2, w / 2
    phi = 2 * np.pi * np.arange(16) / 16
    R_, C_, P_ = np.meshgrid(rho, g, phi, indexing="ij")
    W = wr[:, None, None] * w[None, :, None] * R_**2 * (2 * np.pi / 16)
    S_ = np.sqrt(1 - C_**2)
    pts = np.stack([AXES[0] * R_ * S_ * np.cos(P_), AXES[1] * R_ * S_ * np.sin(P_),
                    AXES[2] * R_ * C_], -1).reshape(-1, 3)
    weights = (W * AXES.prod()).ravel()
    vol = 4 / 3 * np.pi * AXES.prod()
    Q = I.point_mass_integrals(pts, weights * M / vol, 6)
    E = I.ellipsoid_integrals(*AXES, M, 6)
    assert degree_errors(Q, E, 6).max() < 1e-13
    assert E[(2, 0, 0)] == pytest.approx(M * AXES[0]**2 / 5, rel=1e-15)
    assert E[(4, 0, 0)] == pytest.approx(3 * M * AXES[0]**4 / 35, rel=1e-15)
    assert E[(2, 2, 2)] == pytest.approx(M * (AXES**2).prod() / 315, rel=1e-15)


def test_ellipsoid_against_cell_grid():
    # cells of side h whose centres lie inside, weight h³ each; a rigorous bound of the
    # error: the misclassified parts lie in the cells the surface crosses (each contributes
    # at most h³ max|x^α|), and the midpoint rule on the others errs by at most
    # h⁵/24 Σ_i max|∂ii x^α| per cell
    h, order, M = 0.02, 6, 1.0
    edges = [np.arange(-A, A + h / 2, h) for A in AXES]
    lo = [e[:-1] for e in edges]
    X, Y, Z = np.meshgrid(*[e + h / 2 for e in lo], indexing="ij")
    q = (X / AXES[0])**2 + (Y / AXES[1])**2 + (Z / AXES[2])**2
    inside = q <= 1
    pts = np.stack([X[inside], Y[inside], Z[inside]], -1)
    vol = 4 / 3 * np.pi * AXES.prod()
    G = I.point_mass_integrals(pts, np.full(len(pts), h**3 * M / vol), order)
    E = I.ellipsoid_integrals(*AXES, M, order)

    def qrange(c, A):                       # range of (t/A)² over [c - h/2, c + h/2]
        t0, t1 = (c - h / 2) / A, (c + h / 2) / A
        return np.where(t0 * t1 <= 0, 0, np.minimum(t0**2, t1**2)), np.maximum(t0**2, t1**2)
    (a0, a1), (b0, b1), (c0, c1) = qrange(X, AXES[0]), qrange(Y, AXES[1]), qrange(Z, AXES[2])
    crossing = int(np.sum((a0 + b0 + c0 <= 1) & (a1 + b1 + c1 >= 1)))
    for l, m, n in I.multi_indices(order):
        top = lambda i, e: AXES[i]**max(e, 0)              # noqa: E731  (max |t^e| on the box)
        fmax = top(0, l) * top(1, m) * top(2, n)
        curv = sum(e * (e - 1) * fmax / AXES[i]**2 for i, e in enumerate((l, m, n)))
        bound = (crossing * h**3 * fmax + inside.sum() * h**5 / 24 * curv) * M / vol
        assert abs(G[(l, m, n)] - E[(l, m, n)]) <= bound, (l, m, n)
    # the bound is loose (the boundary errors partly cancel): the grid is within 0.12 %
    assert degree_errors(G, E, order).max() < 2e-3


# ---- (g) errors: one line, naming the parameter ---------------------------------------------
def test_errors_name_the_parameter():
    V, F = box_mesh(1.0, 0.7, 0.3)
    pts, m = np.zeros((2, 3)), np.ones(2)
    T = I.ellipsoid_integrals(1.0, 0.8, 0.5, 1.0, 4)
    cases = [
        (lambda: I.multi_indices(17), r"^order must be an integer in \[0, 16\]"),
        (lambda: I.multi_indices(-1), r"^order must be an integer in \[0, 16\]"),
        (lambda: I.multi_indices(2.0), r"^order must be an integer"),
        (lambda: I.multi_indices(True), r"^order must be an integer"),
        (lambda: I.ellipsoid_integrals(0.0, 1, 1, 1, 2), r"^a must be a finite number > 0"),
        (lambda: I.ellipsoid_integrals(1, np.inf, 1, 1, 2), r"^b must be a finite number > 0"),
        (lambda: I.ellipsoid_integrals(1, 1, -1, 1, 2), r"^c must be a finite number > 0"),
        (lambda: I.ellipsoid_integrals(1, 1, 1, np.nan, 2), r"^mass must be a finite number > 0"),
        (lambda: I.ellipsoid_integrals(1, 1, 1, 1, 20), r"^order must be an integer in \[0, 16\]"),
        (lambda: I.point_mass_integrals(np.zeros((2, 2)), m, 2), r"^points must be .*\(N, 3\)"),
        (lambda: I.point_mass_integrals([[0, 0, np.nan]], [1.0], 2), r"^points must be finite"),
        (lambda: I.point_mass_integrals(pts, [1.0, 0.0], 2), r"^masses must be finite and > 0"),
        (lambda: I.point_mass_integrals(pts, [1.0, np.inf], 2), r"^masses must be finite and > 0"),
        (lambda: I.point_mass_integrals(pts, [1.0], 2), r"^masses must be .*shape \(2,\)"),
        (lambda: I.polyhedron_integrals(V, F, 4, 0.0), r"^density must be a finite number > 0"),
        (lambda: I.polyhedron_integrals(V, F, 4, np.nan), r"^density must be a finite number > 0"),
        (lambda: I.polyhedron_integrals(V, F, 99, 1.0), r"^order must be an integer in \[0, 16\]"),
        (lambda: I.polyhedron_integrals(V[:, :2], F, 4, 1.0), r"^vertices must be .*\(N, 3\)"),
        (lambda: I.polyhedron_integrals(np.where(V > 0.9, np.inf, V), F, 4, 1.0),
         r"^vertices must be finite"),
        (lambda: I.polyhedron_integrals(V, F + 1, 4, 1.0),
         r"^faces must hold vertex indices in \[0, 7\]"),
        (lambda: I.polyhedron_integrals(V, F - 1, 4, 1.0),
         r"^faces must hold vertex indices in \[0, 7\]"),
        (lambda: I.polyhedron_integrals(V, F.astype(float), 4, 1.0),
         r"^faces must be an integer array"),
        (lambda: I.polyhedron_integrals(V, F[:, :2], 4, 1.0),
         r"^faces must be an integer array of shape \(F, 3\)"),
        (lambda: I.polyhedron_integrals(V, F[:-1], 4, 1.0), r"^faces must form a closed surface"),
        (lambda: I.polyhedron_integrals(V, F[:, ::-1], 4, 1.0), r"^faces must be wound outward"),
        (lambda: I.volume_of(V, F[:-2]), r"^faces must form a closed surface"),
        (lambda: I.shift_integrals(T, [1.0, 2.0]),
         r"^d must be a finite displacement of shape \(3,\)"),
        (lambda: I.shift_integrals(T, [1.0, 2.0, np.nan]), r"^d must be a finite displacement"),
        (lambda: I.shift_integrals({(0, 0, 0): 1.0, (1, 0, 0): 0.0}, [0, 0, 0]),
         r"^T must hold exactly the multi-indices"),
        (lambda: I.shift_integrals([1.0], [0, 0, 0]), r"^T must be a dict"),
        (lambda: I.shift_integrals({**T, (0, 0, 0): np.nan}, [0, 0, 0]), r"^T must map each"),
        (lambda: I.rotate_integrals(T, np.diag([1.0, 1.0, -1.0])), r"^R must be a rotation matrix"),
        (lambda: I.rotate_integrals(T, 1.01 * np.eye(3)), r"^R must be a rotation matrix"),
        (lambda: I.rotate_integrals(T, np.eye(2)), r"^R must be a finite 3x3 rotation matrix"),
        (lambda: I.principal_frame(I.ellipsoid_integrals(1, 1, 1, 1, 1)),
         r"^T must be of order >= 2"),
        (lambda: I.principal_frame({**T, (0, 0, 0): -1.0}), r"^T must have a positive mass"),
    ]
    for call, match in cases:
        with pytest.raises(ValueError, match=match) as info:
            call()
        assert "\n" not in str(info.value), str(info.value)


def test_rotation_tolerance_is_1e_10():
    T = I.ellipsoid_integrals(1.0, 0.8, 0.5, 1.0, 2)
    I.rotate_integrals(T, np.eye(3) * (1 + 2e-11))        # accepted
    with pytest.raises(ValueError, match="^R must be a rotation matrix"):
        I.rotate_integrals(T, np.eye(3) * (1 + 1e-9))
