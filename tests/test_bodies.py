"""Bodies and their inertia integrals (docs/physics.md §2) against independent routes.

* Ellipsoid integrals of orders 2–4 (every monomial, odd ones included) against direct
  quadrature over the ellipsoid volume: Gauss–Legendre in r and θ, trapezoid in φ, which is
  exact or spectrally accurate for these polynomial integrands (agreement ~1e-15).
* Principal moments, ω0, sphere isotropy, moment tensors.
* Point-mass bodies against direct sums over the rotated points, and their invariance under a
  rigid motion of the input cloud.
* Bad inputs raise ValueError naming the parameter.
"""

import itertools
import math

import numpy as np
import pytest

from ti_spinorbit.system.bodies import Body, Ellipsoid, Sphere
from ti_spinorbit.layout import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4, ROW_LENGTH
from ti_spinorbit.system.systems import BinarySystem

AXES = (3.1, 1.7, 0.9)          # a > b > c, m: nothing degenerate
DENSITY = 2100.0                # kg m^-3
ALL_MONOMIALS = {order: [k for k in itertools.product(range(order + 1), repeat=3)
                         if sum(k) == order] for order in (2, 3, 4)}


def ellipsoid_quadrature(a, b, c, density, exponents, n_r=8, n_theta=40, n_phi=24):
    """∫ x^l y^m z^n ρ dV over the ellipsoid, x = a r sinθ cosφ, y = b r sinθ sinφ,
    z = c r cosθ, dV = abc r² sinθ dr dθ dφ.

    r: Gauss–Legendre (polynomial of degree ≤ 6: exact); θ: Gauss–Legendre on [0, π]
    (entire integrand: spectral); φ: trapezoid (trigonometric polynomial of degree ≤ 4: exact).
    """
    xr, wr = np.polynomial.legendre.leggauss(n_r)
    r, wr = 0.5 * (xr + 1.0), 0.5 * wr
    xt, wt = np.polynomial.legendre.leggauss(n_theta)
    theta, wt = 0.5 * math.pi * (xt + 1.0), 0.5 * math.pi * wt
    phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
    wp = np.full(n_phi, 2.0 * math.pi / n_phi)
    R, T, P = np.meshgrid(r, theta, phi, indexing="ij")
    W = np.einsum("i,j,k->ijk", wr, wt, wp) * R**2 * np.sin(T) * a * b * c * density
    x = a * R * np.sin(T) * np.cos(P)
    y = b * R * np.sin(T) * np.sin(P)
    z = c * R * np.cos(T)
    l, m, n = exponents
    return float(np.sum(W * x**l * y**m * z**n))


def rotation_about(axis, angle):
    k = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def lumpy_cloud(seed=7, n=60):
    """An asymmetric point cloud (distinct moments, non-zero odd integrals), arbitrary frame."""
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(n, 3)) * np.array([3.0, 2.0, 1.0])
    pts[: n // 3] += np.array([1.5, -0.7, 0.4])            # break every mirror symmetry
    pts = pts @ rotation_about((0.3, -1.0, 0.5), 0.8).T + np.array([10.0, -4.0, 2.5])
    return pts, rng.uniform(0.5, 2.0, n)


# ---- uniform ellipsoid ---------------------------------------------------------------------
def test_quadrature_reproduces_mass_and_known_moments():
    """The oracle itself: volume and ∫x² dm = m a²/5 of a known case."""
    a, b, c = AXES
    mass = DENSITY * 4.0 / 3.0 * math.pi * a * b * c
    assert ellipsoid_quadrature(a, b, c, DENSITY, (0, 0, 0)) == pytest.approx(mass, rel=1e-14)
    assert ellipsoid_quadrature(a, b, c, DENSITY, (2, 0, 0)) == pytest.approx(
        mass * a**2 / 5.0, rel=1e-14)


@pytest.mark.parametrize("order", [2, 3, 4])
def test_ellipsoid_integrals_match_volume_quadrature(order):
    """Every T^{lmn}, l+m+n = order, including the zero odd and off-diagonal ones."""
    a, b, c = AXES
    body = Ellipsoid(a, b, c, DENSITY)
    scale = body.mass * a**order
    for key in ALL_MONOMIALS[order]:
        expected = ellipsoid_quadrature(a, b, c, DENSITY, key)
        got = body.integral(*key)
        if any(i % 2 for i in key):
            assert got == 0.0, key
            assert abs(expected) < 1e-14 * scale, key      # oracle agrees it vanishes
        else:
            assert got == pytest.approx(expected, rel=1e-12, abs=0.0), key


def test_ellipsoid_closed_forms():
    a, b, c = AXES
    body = Ellipsoid(a, b, c, mass=5.0)
    assert body.integral(2, 0, 0) == pytest.approx(5.0 * a**2 / 5.0, rel=1e-15)
    assert body.integral(4, 0, 0) == pytest.approx(3.0 * 5.0 * a**4 / 35.0, rel=1e-15)
    assert body.integral(2, 2, 0) == pytest.approx(5.0 * a**2 * b**2 / 35.0, rel=1e-15)
    assert body.integral(0, 2, 2) == pytest.approx(5.0 * b**2 * c**2 / 35.0, rel=1e-15)
    assert body.bounding_radius == a


def test_ellipsoid_mass_from_density_or_mass():
    a, b, c = AXES
    by_density = Ellipsoid(a, b, c, DENSITY)
    volume = 4.0 / 3.0 * math.pi * a * b * c
    assert by_density.mass == pytest.approx(DENSITY * volume, rel=1e-15)
    by_mass = Ellipsoid(a, b, c, mass=by_density.mass)
    assert by_mass.mass == by_density.mass
    np.testing.assert_allclose(by_mass.as_row(), by_density.as_row(), rtol=1e-15, atol=0.0)
    # integrals are linear in the mass
    double = Ellipsoid(a, b, c, mass=2.0 * by_density.mass)
    np.testing.assert_allclose(double.as_row(), 2.0 * by_density.as_row(), rtol=1e-15, atol=0.0)


def test_ellipsoid_principal_moments():
    a, b, c = AXES
    body = Ellipsoid(a, b, c, DENSITY)
    m = body.mass
    A, B, C = body.moments
    assert A < B < C
    np.testing.assert_allclose(
        [A, B, C], [m * (b**2 + c**2) / 5, m * (a**2 + c**2) / 5, m * (a**2 + b**2) / 5],
        rtol=1e-14)


@pytest.mark.parametrize("a, b", [(1.5, 1.0), (1.06, 1.0), (1.01, 1.0), (2.0, 1.3)])
def test_omega0_of_an_ellipsoidal_secondary(a, b):
    """ω0 = sqrt(3(B−A)/C) = sqrt(3(a²−b²)/(a²+b²)), independent of c and of the density."""
    expected = math.sqrt(3.0 * (a**2 - b**2) / (a**2 + b**2))
    for c, density in ((0.5 * b, 2000.0), (0.9 * b, 3500.0)):
        A, B, C = Ellipsoid(a, b, c, density).moments
        assert math.sqrt(3.0 * (B - A) / C) == pytest.approx(expected, rel=1e-13)
        system = BinarySystem(Sphere(2.0, 1500.0), Ellipsoid(a, b, c, density), a=20.0, e=0.1)
        assert system.omega0 == pytest.approx(expected, rel=1e-13)


def test_sphere_is_the_isotropic_ellipsoid():
    r = 1.3
    sphere = Sphere(r, DENSITY)
    ball = Ellipsoid(r, r, r, DENSITY)
    assert sphere.mass == ball.mass
    assert sphere.bounding_radius == ball.bounding_radius == r
    np.testing.assert_array_equal(sphere.as_row(), ball.as_row())
    assert Sphere(r, mass=7.0).mass == 7.0
    # isotropy: equal moments 2mr²/5, trace-free M2 = 0 (point-mass exterior field) and the
    # fourth moment ∝ Sym(δ⊗δ), i.e. ∫x⁴ = 3∫x²y²
    m = sphere.mass
    np.testing.assert_allclose(sphere.moments, [0.4 * m * r**2] * 3, rtol=1e-15)
    M2 = sphere.moment_tensor(2)
    assert np.max(np.abs(M2 - np.trace(M2) / 3 * np.eye(3))) <= 1e-15 * np.trace(M2)
    assert sphere.integral(4, 0, 0) == pytest.approx(3.0 * sphere.integral(2, 2, 0), rel=1e-15)
    assert not sphere.has_odd_integrals


@pytest.mark.parametrize("order", [2, 3, 4])
def test_moment_tensor_symmetric_and_consistent(order):
    pts, masses = lumpy_cloud()
    for body in (Ellipsoid(*AXES, DENSITY), Body.from_point_masses(pts, masses)[0]):
        M = body.moment_tensor(order)
        assert M.shape == (3,) * order
        for perm in itertools.permutations(range(order)):
            np.testing.assert_array_equal(M, np.transpose(M, perm))
        for l, m, n in ALL_MONOMIALS[order]:
            assert M[(0,) * l + (1,) * m + (2,) * n] == body.integral(l, m, n)
    ellipsoid = Ellipsoid(*AXES, DENSITY)
    assert float(ellipsoid.moment_tensor(0)) == ellipsoid.mass
    np.testing.assert_array_equal(ellipsoid.moment_tensor(1), np.zeros(3))
    # ∫ r⁴ dm = Σ_ij M_iijj against quadrature of (x² + y² + z²)²
    a, b, c = AXES
    r4 = sum(ellipsoid_quadrature(a, b, c, DENSITY, k) * coef for k, coef in
             (((4, 0, 0), 1), ((0, 4, 0), 1), ((0, 0, 4), 1),
              ((2, 2, 0), 2), ((2, 0, 2), 2), ((0, 2, 2), 2)))
    assert np.einsum("iijj->", ellipsoid.moment_tensor(4)) == pytest.approx(r4, rel=1e-12)


def test_as_row_layout():
    body = Ellipsoid(*AXES, DENSITY)
    row = body.as_row()
    assert row.shape == (ROW_LENGTH,) == (29,)
    keys = [(0, 0, 0)] + list(EXPONENTS_2) + list(EXPONENTS_3) + list(EXPONENTS_4)
    np.testing.assert_array_equal(row, [body.integral(*k) for k in keys])
    assert sorted(EXPONENTS_3) == sorted(ALL_MONOMIALS[3])
    assert sorted(EXPONENTS_4) == sorted(ALL_MONOMIALS[4])
    row[0] = -1.0                                             # a copy, not the cache
    assert body.as_row()[0] == body.mass


# ---- point-mass bodies ---------------------------------------------------------------------
def body_frame_points(pts, masses, rotation):
    com = (masses[:, None] * pts).sum(0) / masses.sum()
    return (pts - com) @ rotation.T


def test_point_masses_integrals_are_direct_sums_in_principal_frame():
    pts, masses = lumpy_cloud()
    body, rotation = Body.from_point_masses(pts, masses)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-14)
    q = body_frame_points(pts, masses, rotation)
    assert body.mass == pytest.approx(masses.sum(), rel=1e-15)
    assert np.max(np.abs(masses @ q)) < 1e-13 * masses.sum() * np.max(np.abs(q))  # COM
    for order in (2, 3, 4):
        scale = np.sum(masses * np.linalg.norm(q, axis=1) ** order)
        for l, m, n in ALL_MONOMIALS[order]:
            direct = np.sum(masses * q[:, 0] ** l * q[:, 1] ** m * q[:, 2] ** n)
            assert abs(body.integral(l, m, n) - direct) <= 1e-13 * scale, (l, m, n)
        M = np.einsum("n,ni->ni", masses, q)
        for _ in range(order - 1):
            M = np.einsum("n...,nj->n...j", M, q)
        np.testing.assert_allclose(body.moment_tensor(order), M.sum(0), rtol=0, atol=1e-13 * scale)
    # principal axes: off-diagonal second order vanishes, x long axis (A ≤ B ≤ C)
    trace = np.sum(masses * np.sum(q**2, axis=1))
    for key in ((1, 1, 0), (1, 0, 1), (0, 1, 1)):
        assert abs(body.integral(*key)) < 1e-13 * trace
    A, B, C = body.moments
    assert A < B < C
    assert body.has_odd_integrals
    assert body.bounding_radius == pytest.approx(np.max(np.linalg.norm(q, axis=1)), rel=1e-14)


def test_point_masses_invariant_under_rigid_motion_of_the_input():
    """Moving the cloud rigidly leaves the body unchanged, up to the sign of each principal
    axis: even integrals are invariant, odd ones keep their magnitude."""
    pts, masses = lumpy_cloud()
    body, _ = Body.from_point_masses(pts, masses)
    moved = pts @ rotation_about((1.0, 2.0, -0.5), 2.3).T + np.array([-7.0, 3.0, 11.0])
    other, _ = Body.from_point_masses(moved, masses)
    for order in (2, 3, 4):
        scale = np.sum(masses * np.linalg.norm(pts - pts.mean(0), axis=1) ** order)
        for key in ALL_MONOMIALS[order]:
            if order == 2 and max(key) < 2:
                continue                                     # round-off zeros
            x, y = body.integral(*key), other.integral(*key)
            if any(i % 2 for i in key):
                x, y = abs(x), abs(y)
            assert abs(x - y) <= 1e-12 * scale, key


def test_has_odd_integrals():
    assert not Ellipsoid(*AXES, DENSITY).has_odd_integrals
    assert not Body(1.0, {(2, 0, 0): 1.0, (4, 0, 0): 0.5}, 1.0).has_odd_integrals
    assert Body(1.0, {(2, 0, 0): 1.0, (2, 1, 0): 1e-3}, 1.0).has_odd_integrals
    assert Body(1.0, {(2, 0, 0): 1.0, (1, 1, 2): -1e-3}, 1.0).has_odd_integrals


def test_centrally_symmetric_cloud_has_no_third_order_integrals():
    """Central symmetry kills the odd-order (3rd) integrals exactly (round-off is zeroed);
    4th-order ones with odd indices, e.g. T013, legitimately survive."""
    pts, masses = lumpy_cloud()
    pts = pts - pts.mean(0)
    sym_pts = np.concatenate([pts, -pts]) + np.array([1.0, 2.0, 3.0])
    body, _ = Body.from_point_masses(sym_pts, np.concatenate([masses, masses]))
    from ti_spinorbit.system.bodies import EXPONENTS_3
    assert all(body.integral(*k) == 0.0 for k in EXPONENTS_3)
    assert any(body.integral(*k) != 0.0 for k in ((3, 1, 0), (1, 3, 0), (0, 1, 3)))


# ---- bad inputs ----------------------------------------------------------------------------
BAD_NUMBERS = [0.0, -1.0, float("nan"), float("inf"), -float("inf")]


@pytest.mark.parametrize("value", BAD_NUMBERS)
@pytest.mark.parametrize("which", ["a", "b", "c"])
def test_ellipsoid_rejects_bad_semi_axes(which, value):
    axes = dict(a=3.0, b=2.0, c=1.0)
    axes[which] = value
    with pytest.raises(ValueError, match=rf"^{which} must be a finite number > 0"):
        Ellipsoid(axes["a"], axes["b"], axes["c"], DENSITY)


@pytest.mark.parametrize("value", BAD_NUMBERS)
def test_sphere_rejects_bad_radius(value):
    with pytest.raises(ValueError, match=r"^radius must be a finite number > 0"):
        Sphere(value, DENSITY)


@pytest.mark.parametrize("axes", [(2.0, 3.0, 1.0), (3.0, 1.0, 2.0), (1.0, 2.0, 3.0)])
def test_ellipsoid_rejects_unordered_semi_axes(axes):
    with pytest.raises(ValueError, match=r"a >= b >= c"):
        Ellipsoid(*axes, DENSITY)


@pytest.mark.parametrize("value", BAD_NUMBERS)
def test_ellipsoid_rejects_bad_density_and_mass(value):
    with pytest.raises(ValueError, match=r"^density must be a finite number > 0"):
        Ellipsoid(*AXES, value)
    with pytest.raises(ValueError, match=r"^mass must be a finite number > 0"):
        Ellipsoid(*AXES, mass=value)
    with pytest.raises(ValueError, match=r"^mass must be a finite number > 0"):
        Sphere(1.0, mass=value)


def test_ellipsoid_needs_exactly_one_of_density_and_mass():
    with pytest.raises(ValueError, match=r"exactly one of density .* or mass"):
        Ellipsoid(*AXES)
    with pytest.raises(ValueError, match=r"exactly one of density .* or mass"):
        Ellipsoid(*AXES, DENSITY, mass=1.0)
    with pytest.raises(ValueError, match=r"exactly one of density .* or mass"):
        Sphere(1.0)


GOOD_SECOND = {(2, 0, 0): 0.3, (0, 2, 0): 0.2, (0, 0, 2): 0.1}   # fits in a sphere of radius 1


@pytest.mark.parametrize("value", BAD_NUMBERS)
def test_body_rejects_bad_mass_and_radius(value):
    with pytest.raises(ValueError, match=r"^mass must be a finite number > 0"):
        Body(value, GOOD_SECOND, 1.0)
    with pytest.raises(ValueError, match=r"^bounding_radius must be a finite number > 0"):
        Body(1.0, GOOD_SECOND, value)


@pytest.mark.parametrize("key", [(1, 1, 0), (1, 0, 1), (0, 1, 1)])
def test_body_rejects_non_principal_integrals(key):
    with pytest.raises(ValueError, match=r"principal-axis frame"):
        Body(1.0, {**GOOD_SECOND, key: 0.1}, 1.0)
    Body(1.0, {**GOOD_SECOND, key: 1e-14}, 1.0)               # round-off is tolerated


@pytest.mark.parametrize("key", [(1, 0, 0), (0, 0, 0), (17, 0, 0), (9, 4, 4), (-1, 3, 0),
                                 (2, 0), (1, 1, 1, 1), (1.5, 0.5, 0), (True, 1, 1)])
def test_body_rejects_bad_integral_keys(key):
    with pytest.raises(ValueError, match=r"^integrals: key"):
        Body(1.0, {**GOOD_SECOND, key: 0.1}, 1.0)


@pytest.mark.parametrize("key", [(5, 0, 0), (3, 1, 1)])
def test_keys_beyond_an_explicit_order_are_refused(key):
    """Without order= a key of degree 5 makes an order-5 body; with order=4 it is refused."""
    assert Body(1.0, {**GOOD_SECOND, key: 0.01}, 1.0).order == 5
    with pytest.raises(ValueError, match=r"^integrals: key .* has degree 5, above order=4 "
                                         r"\(raise order or drop the key\)$"):
        Body(1.0, {**GOOD_SECOND, key: 0.01}, 1.0, order=4)


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_body_rejects_non_finite_integrals(value):
    with pytest.raises(ValueError, match=r"^integrals\[\(2, 1, 1\)\] must be finite"):
        Body(1.0, {**GOOD_SECOND, (2, 1, 1): value}, 1.0)


@pytest.mark.parametrize("second", [{}, {(2, 0, 0): -1.0, (0, 2, 0): 0.5}])
def test_body_rejects_non_positive_second_order_trace(second):
    with pytest.raises(ValueError, match=r"^integrals: second-order trace"):
        Body(1.0, second, 1.0)


def test_point_masses_reject_bad_input():
    pts, masses = lumpy_cloud()
    with pytest.raises(ValueError, match=r"^points must have shape"):
        Body.from_point_masses(pts[:, :2], masses)
    with pytest.raises(ValueError, match=r"masses shape"):
        Body.from_point_masses(pts, masses[:-1])
    bad = pts.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"^points must be finite"):
        Body.from_point_masses(bad, masses)
    for value in (0.0, -1.0, np.nan, np.inf):
        m = masses.copy()
        m[5] = value
        with pytest.raises(ValueError, match=r"^masses must all be finite and > 0"):
            Body.from_point_masses(pts, m)


# ---- any order -----------------------------------------------------------------------------
def test_ellipsoid_holds_the_closed_form_at_every_order_and_the_row_is_unchanged():
    """Default order 16; every integral equals integrals.ellipsoid_integrals (an independent
    implementation: exact Fractions) to 1e-15, odd ones exactly 0; a lower order= holds the
    same values up to it, and as_row() is the same bit for bit at every order."""
    from ti_spinorbit.system import integrals

    a, b, c = AXES
    body = Ellipsoid(a, b, c, DENSITY)
    assert body.order == 16
    exact = integrals.ellipsoid_integrals(a, b, c, body.mass, 16)
    for key, want in exact.items():
        got = body.integral(*key)
        if any(i % 2 for i in key) or sum(key) == 1:
            assert got == 0.0, key
        else:
            assert got == pytest.approx(want, rel=1e-15, abs=0.0), key
    for order in (4, 5, 8, 12):
        low = Ellipsoid(a, b, c, DENSITY, order=order)
        assert low.order == order
        assert low.as_row().tobytes() == body.as_row().tobytes()
        assert all(low.integral(*k) == body.integral(*k) for k in integrals.multi_indices(order))
    sphere = Sphere(2.0, DENSITY, order=6)
    assert sphere.order == 6 and sphere.integral(6, 0, 0) == pytest.approx(
        sphere.mass * 2.0**6 / 21.0, rel=1e-15)        # 3 M r⁶ 5!!/9!! = M r⁶/21


@pytest.mark.parametrize("key", [(6, 0, 0), (2, 2, 2), (4, 0, 2), (0, 8, 0), (6, 2, 4)])
def test_ellipsoid_high_order_integrals_match_volume_quadrature(key):
    a, b, c = AXES
    body = Ellipsoid(a, b, c, DENSITY)
    assert body.integral(*key) == pytest.approx(
        ellipsoid_quadrature(a, b, c, DENSITY, key, n_r=12, n_theta=60, n_phi=40), rel=1e-12)


def test_integral_refuses_beyond_the_order_in_one_line():
    body = Ellipsoid(*AXES, DENSITY, order=6, name="Dimorphos")
    assert body.integral(5, 1, 0) == 0.0 and body.integral(6, 0, 0) > 0
    with pytest.raises(ValueError) as info:
        body.integral(4, 3, 0)
    assert str(info.value) == ("body 'Dimorphos' holds its integrals up to order 6: "
                               "T^(4, 3, 0) of degree 7 is beyond it (build the body with "
                               "order >= 7)")
    cloud = Body(1.0, GOOD_SECOND, 1.0, "hand")                  # order 4 by default
    assert cloud.order == 4 and cloud.integral(4, 0, 0) == 0.0
    with pytest.raises(ValueError, match=r"^body 'hand' holds its integrals up to order 4: "
                                         r"T\^\(0, 0, 5\) of degree 5"):
        cloud.integral(0, 0, 5)
    with pytest.raises(ValueError, match=r"up to order 4"):
        cloud.integral_set(5)
    with pytest.raises(ValueError, match=r"up to order 4"):
        cloud.moment_tensor(5)
    with pytest.raises(ValueError, match=r"^body 'hand': T\^lmn needs three non-negative"):
        cloud.integral(-1, 2, 0)
    for bad in (3, 17, 4.5, True, "8"):
        with pytest.raises((TypeError, ValueError), match=r"^order must be"):
            Body(1.0, GOOD_SECOND, 1.0, order=bad)


def test_integral_set_is_the_dense_set_of_the_integrals_module():
    from ti_spinorbit.system import integrals

    body = Ellipsoid(*AXES, DENSITY, order=8)
    T = body.integral_set()
    assert list(T) == list(integrals.multi_indices(8))
    assert T[(0, 0, 0)] == body.mass and T[(1, 0, 0)] == 0.0 and T[(3, 1, 0)] == 0.0
    assert all(T[k] == body.integral(*k) for k in T)
    assert list(body.integral_set(4)) == list(integrals.multi_indices(4))
    moved = integrals.shift_integrals(T, (1.0, -2.0, 0.5))     # accepted as an integral set
    assert moved[(1, 0, 0)] == pytest.approx(body.mass, rel=1e-15)


def test_point_masses_at_any_order_are_direct_sums_and_keep_the_order_4_row():
    pts, masses = lumpy_cloud()
    body4, rot4 = Body.from_point_masses(pts, masses, order=4)
    body, rotation = Body.from_point_masses(pts, masses, order=11)
    assert body.order == 11 and body4.order == 4
    assert body.as_row().tobytes() == body4.as_row().tobytes()
    np.testing.assert_array_equal(rotation, rot4)
    np.testing.assert_array_equal(body.rotation, rotation)
    np.testing.assert_allclose(body.offset, (masses[:, None] * pts).sum(0) / masses.sum(),
                               rtol=1e-15)
    q = body_frame_points(pts, masses, rotation)
    for order in (5, 8, 11):
        scale = np.sum(masses * np.linalg.norm(q, axis=1) ** order)
        for l, m, n in itertools.product(range(order + 1), repeat=3):
            if l + m + n == order:
                direct = np.sum(masses * q[:, 0] ** l * q[:, 1] ** m * q[:, 2] ** n)
                assert abs(body.integral(l, m, n) - direct) <= 1e-13 * scale, (l, m, n)
    assert Body.from_point_masses(pts, masses)[0].order == 8      # DATA_ORDER


def test_hand_given_integrals_at_any_order():
    high = {**GOOD_SECOND, (6, 0, 0): 0.05, (3, 2, 2): -1e-3}
    body = Body(1.0, high, 1.0)
    assert body.order == 7 and body.integral(3, 2, 2) == -1e-3 and body.integral(7, 0, 0) == 0.0
    assert Body(1.0, high, 1.0, order=12).integral(12, 0, 0) == 0.0
    assert body.has_odd_integrals
    assert body.as_row().tobytes() == Body(1.0, GOOD_SECOND, 1.0).as_row().tobytes()
    with pytest.raises(ValueError, match=r"^bounding_radius must be >= "):   # |T600| <= M ρ⁶
        Body(1.0, {**GOOD_SECOND, (6, 0, 0): 2.0}, 1.0)


def test_bodies_of_any_order_round_trip_through_saved_descriptions():
    """io.describe_system writes a general body's integrals up to its order and the order
    where it cannot be inferred; an ellipsoid keeps its order; an old description (no
    "order") gives the ellipsoid MAX_ORDER and the general body its highest key."""
    import json

    from ti_spinorbit.output import io

    pts, masses = lumpy_cloud()
    cloud = Body.from_point_masses(pts * 100.0, masses * 1e9, name="cloud", order=10)[0]
    sparse = Body(cloud.mass, {k: v for k, v in cloud.integrals.items() if sum(k) <= 6},
                  cloud.bounding_radius, "sparse", order=9)           # degrees 7-9 all zero
    for primary, secondary in ((Ellipsoid(3000.0, 2000.0, 1500.0, 2000.0, order=6), cloud),
                               (Sphere(2500.0, 2000.0), sparse)):
        system = BinarySystem(primary, secondary, 2e4, 0.1, primary_spin_period=1e4)
        d = json.loads(json.dumps(io.describe_system(system)))
        back = BinarySystem.from_description(d)
        assert back == system
        for was, now in ((system.primary, back.primary), (system.secondary, back.secondary)):
            assert now.order == was.order and now.integrals == was.integrals
            assert hasattr(now, "semi_axes") == hasattr(was, "semi_axes")
    assert "order" not in io.describe_system(system)["primary"]    # a sphere of order 16
    system = BinarySystem(Ellipsoid(3000.0, 2000.0, 1500.0, 2000.0, order=6), sparse, 2e4, 0.1)
    d = io.describe_system(system)
    assert d["primary"]["order"] == 6 and d["secondary"]["order"] == 9
    for body in (d["primary"], d["secondary"]):
        del body["order"]
    back = BinarySystem.from_description(d)
    assert back.primary.order == 16 and back.secondary.order == 6
