"""The Taichi mutual potential and right-hand side against independent routes: the NumPy
tensor reference (to round-off), finite differences, exact ellipsoid potentials
(truncation slope), quadrature, and the reference numbers of docs/physics.md §11.6."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import reference
from ti_spinorbit.kernels import advance as K

from conftest import lumpy_body, random_rotation
import oracles

C36, R36, ROWS36 = oracles.REFERENCE_S, oracles.REFERENCE_R, oracles.REFERENCE_NUMBERS


def _bodies36():
    return tso.Ellipsoid(1, 0.8, 0.6, mass=1.0), tso.Ellipsoid(0.45, 0.35, 0.3, mass=0.1)


@pytest.mark.parametrize("order", [2, 4])
def test_reference_numbers(order):
    A, B = _bodies36()
    V, F, muA, muB = tso.mutual_potential(A, B, R36, C36, order=order)
    U, dUdR, tB, tA = ROWS36[order]
    G = tso.G
    assert V / G == pytest.approx(U, rel=1e-13)
    # printed to 15 decimals: ~1e-12 relative for the 1e-4 torques
    np.testing.assert_allclose(-F / G, dUdR, rtol=1e-12, atol=1e-16)
    np.testing.assert_allclose(muB / G, tB, rtol=2e-11, atol=5e-16)
    np.testing.assert_allclose(muA / G, tA, rtol=2e-11, atol=5e-16)


def _reference(A, B, R, C, order):
    return reference.mutual_potential(tso.G, A.mass, reference.body_tensors(A), B.mass,
                                      reference.body_tensors(B), R, C, order=order)


@pytest.mark.parametrize("order", [0, 2, 3, 4])
@pytest.mark.parametrize("kind", ["ellipsoids", "lumpy"])
def test_kernel_equals_tensor_reference(order, kind, rng):
    """Explicit scalar form (kernels) = Cartesian tensor form (reference), to round-off,
    including odd integrals (lumpy point clouds)."""
    for _ in range(5):
        if kind == "ellipsoids":
            A = tso.Ellipsoid(*sorted(rng.uniform(300, 700, 3), reverse=True), 2000.0)
            B = tso.Ellipsoid(*sorted(rng.uniform(50, 250, 3), reverse=True), 2500.0)
            R = rng.normal(size=3) * 1500
            # outside the bounding spheres, where mutual_potential accepts R
            R *= max(1.0, 1.05 * (A.bounding_radius + B.bounding_radius) / np.linalg.norm(R))
        else:
            A, B = lumpy_body(rng, scale=300.0, mass=1e12), lumpy_body(rng, scale=100.0, mass=1e11)
            R = rng.normal(size=3) * 2000
        C = random_rotation(rng)
        got = tso.mutual_potential(A, B, R, C, order=order)
        want = _reference(A, B, R, C, order)
        scale_f = np.linalg.norm(want[1])
        scale_t = np.linalg.norm(want[1]) * np.linalg.norm(R)
        assert got[0] == pytest.approx(want[0], rel=1e-13)
        np.testing.assert_allclose(got[1], want[1], atol=1e-13 * scale_f)
        np.testing.assert_allclose(got[2], want[2], atol=1e-13 * scale_t)
        np.testing.assert_allclose(got[3], want[3], atol=1e-13 * scale_t)


def _rot(w):
    """exp(hat(w)) by Rodrigues."""
    th = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / th
    return np.eye(3) + np.sin(th) * k + (1 - np.cos(th)) * k @ k


@pytest.mark.parametrize("order", [2, 4])
def test_force_and_torques_are_gradients(order, rng):
    """F = −∂V/∂R and μ = −∂V/∂θ (rotating one body alone) by central differences."""
    A, B = lumpy_body(rng, scale=300.0, mass=1e12), lumpy_body(rng, scale=100.0, mass=1e11)
    R = np.array([1500.0, 700.0, -300.0])
    C = random_rotation(rng)
    V, F, muA, muB = tso.mutual_potential(A, B, R, C, order=order)
    hR, hth = 1e-2, 1e-5
    dR = np.eye(3)[:, None, :] * np.array([hR, -hR])[None, :, None]          # (3, 2, 3)
    Vr = tso.mutual_potential(A, B, R + dR, np.broadcast_to(C, (3, 2, 3, 3)), order=order)[0]
    F_fd = -(Vr[:, 0] - Vr[:, 1]) / (2 * hR)
    np.testing.assert_allclose(F, F_fd, rtol=0, atol=1e-7 * np.linalg.norm(F))
    muB_fd, muA_fd = np.zeros(3), np.zeros(3)
    for k in range(3):
        w = np.eye(3)[k] * hth
        # rotate B alone: S -> Q S ; rotate A alone: seen from A, R -> Qᵀ R and S -> Qᵀ S
        vp = tso.mutual_potential(A, B, R, _rot(w) @ C, order=order)[0]
        vm = tso.mutual_potential(A, B, R, _rot(-w) @ C, order=order)[0]
        muB_fd[k] = -(vp - vm) / (2 * hth)
        vp = tso.mutual_potential(A, B, _rot(w).T @ R, _rot(w).T @ C, order=order)[0]
        vm = tso.mutual_potential(A, B, _rot(-w).T @ R, _rot(-w).T @ C, order=order)[0]
        muA_fd[k] = -(vp - vm) / (2 * hth)
    np.testing.assert_allclose(muB, muB_fd, rtol=0, atol=1e-7 * np.linalg.norm(muB))
    np.testing.assert_allclose(muA, muA_fd, rtol=0, atol=1e-7 * np.linalg.norm(muA))
    # total torque balance: R × F + μ1 + μ2 = 0
    np.testing.assert_allclose(np.cross(R, F) + muA + muB, 0.0,
                               atol=1e-14 * np.linalg.norm(R) * np.linalg.norm(F))


def test_two_spheres_are_point_masses(rng):
    A, B = tso.Sphere(400, 2000), tso.Sphere(150, 3000)
    R = rng.normal(size=3) * 2000
    V, F, muA, muB = tso.mutual_potential(A, B, R, random_rotation(rng), order=4)
    r = np.linalg.norm(R)
    assert V == pytest.approx(-tso.G * A.mass * B.mass / r, rel=1e-14)
    np.testing.assert_allclose(F, -tso.G * A.mass * B.mass * R / r**3, rtol=1e-14)
    assert np.abs(muA).max() < 1e-14 * np.linalg.norm(F) * r
    assert np.abs(muB).max() < 1e-14 * np.linalg.norm(F) * r


@pytest.mark.parametrize("sphere_is", ["a", "b"])
def test_sphere_ellipsoid_truncation_error_falls_like_r6(sphere_is):
    """Against the exact homogeneous-ellipsoid potential (Carlson R_F, R_D): the order-4
    energy error relative to the point-mass term falls like (size/R)^6, the torque's like R^-4."""
    axes, M_e, M_s = (1.0, 0.7, 0.45), 2.7, 1.3
    C = C36
    ell = tso.Ellipsoid(*axes, mass=M_e)
    sph = tso.Sphere(0.1, mass=M_s)
    A, B = (sph, ell) if sphere_is == "a" else (ell, sph)
    direction = np.array([0.8, 0.5, 0.33]) / np.linalg.norm([0.8, 0.5, 0.33])
    dists = np.array([2.0, 4.0, 8.0])  # asymptotic regime (1.5 is nearly in contact)
    errU, errF, errT = [], [], []
    for d in dists:
        R = d * direction
        V, F, muA, muB = tso.mutual_potential(A, B, R, C, order=4)
        U, Fx, tA, tB = oracles.sphere_ellipsoid(tso.G, M_s, M_e, axes, R, C, sphere_is=sphere_is)
        errU.append(abs(V - U) / (tso.G * M_s * M_e / d))
        t_ell, t_ell_exact = (muB, tB) if sphere_is == "a" else (muA, tA)
        errT.append(np.linalg.norm(t_ell - t_ell_exact) / np.linalg.norm(t_ell_exact))
        errF.append(np.linalg.norm(F - Fx) / np.linalg.norm(Fx))
    slopeU = np.polyfit(np.log(dists), np.log(errU), 1)[0]
    slopeF = np.polyfit(np.log(dists), np.log(errF), 1)[0]
    assert slopeF == pytest.approx(-6.0, abs=0.4)
    slopeT = np.polyfit(np.log(dists), np.log(errT), 1)[0]
    assert slopeU == pytest.approx(-6.0, abs=0.3)
    assert slopeT == pytest.approx(-4.0, abs=0.3)


def test_ellipsoid_pair_against_quadrature():
    """Order 4 against the exact potential by Gauss quadrature (docs/physics.md §11.3, §11.5):
    close to contact the truncation errs ~1e-5 in U, ~1e-4 in F, ~1e-2 in torque, and order 4
    beats order 2 in each."""
    A, B = _bodies36()
    R = 2.2 * R36 / np.linalg.norm(R36)
    exact = oracles.ellipsoid_ellipsoid(tso.G, 1.0, (1, 0.8, 0.6), 0.1, (0.45, 0.35, 0.3), R, C36)
    errs = {}
    for order in (2, 4):
        got = tso.mutual_potential(A, B, R, C36, order=order)
        errs[order] = [abs(got[0] / exact[0] - 1)] + [
            np.linalg.norm(got[k] - exact[k]) / np.linalg.norm(exact[k]) for k in (1, 2, 3)]
    assert errs[4][0] < 5e-5 and errs[4][1] < 1e-3 and max(errs[4][2:]) < 3e-2
    assert all(e4 < e2 for e4, e2 in zip(errs[4], errs[2]))


def _random_state(rng, system):
    """A random, fully 3-D physical state (SI) of a system."""
    R = rng.normal(size=3) * system.a / 2 + np.array([system.a, 0, 0])
    m = system.primary.mass * system.secondary.mass / system.total_mass
    P = m * rng.normal(size=3) * system.a * system.mean_motion
    G1 = system.primary.moments * rng.normal(size=3) * 3 * system.mean_motion
    G2 = random_rotation(rng) @ (system.secondary.moments * rng.normal(size=3) * system.mean_motion)
    return np.concatenate([R, P, G1, G2, random_rotation(rng).ravel(), random_rotation(rng).ravel()])


@pytest.mark.parametrize("kind", ["ellipsoids", "lumpy"])
def test_kernel_rhs_equals_reference_rhs(kind, rng):
    """The scaled kernel RHS, converted to SI, equals the NumPy reference RHS."""
    if kind == "ellipsoids":
        system = tso.catalog.system("test")
    else:
        system = tso.BinarySystem(lumpy_body(rng, scale=300.0, mass=2e12),
                                  lumpy_body(rng, scale=100.0, mass=1e11), 3000.0, 0.1)
    ys = [_random_state(rng, system) for _ in range(4)]
    scaled = np.stack([system.from_physical(y) for y in ys])
    par = np.stack([system.parameter_row()] * len(ys))
    out = np.zeros_like(scaled)
    odd = system.primary.has_odd_integrals or system.secondary.has_odd_integrals
    K.evaluate_rhs(par, scaled, out, 4, odd)
    factor = system.to_physical(np.ones(30))
    for y, dy_scaled in zip(ys, out):
        want = reference.rhs(tso.G, system.primary, system.secondary, y, order=4)
        got = dy_scaled * factor * system.mean_motion
        for sl in (slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12), slice(12, 21), slice(21, 30)):
            np.testing.assert_allclose(got[sl], want[sl], rtol=0, atol=1e-12 * np.abs(want[sl]).max())


def test_written_out_products_equal_taichis_bit_for_bit(rng):
    """kernels/mutual_gravity.py writes the 3x3 products out (mat_vec, mat_t_vec,
    rotate_diagonal) instead of Taichi's ``@``, which starts each sum from a computed zero and
    multiplies a diagonal matrix's zeros. The dropped terms are exact zeros, so on finite
    inputs the values must be Taichi's to the bit (signed zeros aside: none occur here)."""
    import taichi as ti
    from ti_spinorbit.kernels.mutual_gravity import mat3, mat_t_vec, mat_vec, rotate_diagonal, vec3

    n = 64
    M = rng.normal(size=(n, 3, 3)) * 10.0 ** rng.integers(-8, 9, size=(n, 1, 1))
    v = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-8, 9, size=(n, 1))
    out = np.zeros((n, 6, 3, 3))

    @ti.kernel
    def products(M_nd: ti.types.ndarray(dtype=ti.f64, ndim=3),
                 v_nd: ti.types.ndarray(dtype=ti.f64, ndim=2),
                 out: ti.types.ndarray(dtype=ti.f64, ndim=4)):
        for i in range(M_nd.shape[0]):
            S = mat3([[M_nd[i, r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
            x = vec3(v_nd[i, 0], v_nd[i, 1], v_nd[i, 2])
            D = ti.Matrix([[x[0], 0.0, 0.0], [0.0, x[1], 0.0], [0.0, 0.0, x[2]]])
            mine = (mat_vec(S, x), mat_t_vec(S, x))
            taichi = (S @ x, S.transpose() @ x)
            for k in ti.static(range(2)):
                for r in ti.static(range(3)):
                    out[i, k, 0, r] = mine[k][r]
                    out[i, 2 + k, 0, r] = taichi[k][r]
            Q = rotate_diagonal(S, x)
            Qt = S @ D @ S.transpose()
            for r in ti.static(range(3)):
                for c in ti.static(range(3)):
                    out[i, 4, r, c] = Q[r, c]
                    out[i, 5, r, c] = Qt[r, c]

    products(M, v, out)
    np.testing.assert_array_equal(out[:, 0:2], out[:, 2:4])
    np.testing.assert_array_equal(out[:, 4], out[:, 5])
    # and they are the products (a check that the kernel compared something): to round-off
    # of the sums' magnitudes
    a, x = np.abs(M), np.abs(v)
    for got, spec in ((out[:, 0, 0], "nij,nj->ni"), (out[:, 1, 0], "nji,nj->ni")):
        err = np.abs(got - np.einsum(spec, M, v)) / np.einsum(spec, a, x)
        assert err.max() < 4 * np.finfo(float).eps
    spec = "nik,nk,njk->nij"
    err = np.abs(out[:, 4] - np.einsum(spec, M, v, M)) / np.einsum(spec, a, x, a)
    assert err.max() < 8 * np.finfo(float).eps
