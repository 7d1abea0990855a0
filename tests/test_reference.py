"""Physics tests of the NumPy reference (ti_spinorbit.model.reference) against exact oracles.

Sources of the expected values: docs/physics.md §11 (exact ellipsoid potential,
sphere–ellipsoid closed form, quadrature, point-cloud pairwise sums, truncation-error table,
reference numbers, invariance/swap checks) and docs/physics.md §1, §3–4 (conventions, conservation).
"""

import os
import sys

import numpy as np
import pytest

from ti_spinorbit.model import reference as ref
from ti_spinorbit.system.bodies import Body, Ellipsoid, Sphere

sys.path.insert(0, os.path.dirname(__file__))
import oracles  # noqa: E402  (test helper next to this file)

G = 1.0
MASS_A, AXES_A = 1.0, (1.0, 0.8, 0.6)
MASS_B, AXES_B = 0.1, (0.45, 0.35, 0.3)
R_CASE = np.array([2.0, 0.7, 0.4])


def rotation(axis, angle):
    """Rodrigues: rotation by ``angle`` (rad) about ``axis``."""
    k = np.asarray(axis, dtype=np.float64)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


def rotation_vector(w):
    """exp(ŵ) for a rotation vector w."""
    angle = np.linalg.norm(w)
    return np.eye(3) if angle == 0.0 else rotation(w, angle)


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


C_CASE = rotation((0.2, 0.4, 1.0), 1.1)


def relative(x, y):
    return np.linalg.norm(np.subtract(x, y)) / np.linalg.norm(y)


@pytest.fixture(scope="module")
def ellipsoids():
    return Ellipsoid(*AXES_A, mass=MASS_A), Ellipsoid(*AXES_B, mass=MASS_B)


def potential(body_a, body_b, R, C, order=4):
    return ref.mutual_potential(G, body_a.mass, ref.body_tensors(body_a), body_b.mass,
                                ref.body_tensors(body_b), R, C, order)


def lumpy_cloud(rng, n, scale):
    """Random point masses in a few clumps: no symmetry, so odd moments are non-zero."""
    centres = rng.normal(size=(4, 3)) * scale
    points = centres[rng.integers(0, 4, n)] + 0.4 * rng.normal(size=(n, 3)) * scale
    return points, rng.uniform(0.2, 1.5, n)


@pytest.fixture(scope="module")
def clouds():
    """Two lumpy bodies: (body, body-frame points, masses) each."""
    rng = np.random.default_rng(20240611)
    out = []
    for n, scale in ((40, np.array([1.0, 0.8, 0.6])), (30, np.array([0.4, 0.35, 0.3]))):
        points, masses = lumpy_cloud(rng, n, scale)
        body, rot = Body.from_point_masses(points, masses)
        com = (masses[:, None] * points).sum(0) / masses.sum()
        out.append((body, (points - com) @ rot.T, masses))
    return out


# ---- building blocks ------------------------------------------------------------------------
def test_inverse_distance_derivatives_are_trace_free_gradients():
    R = np.array([1.3, -0.4, 0.9])
    D = ref.inverse_distance_derivatives(R, 5)
    r = np.linalg.norm(R)
    assert D[0] == pytest.approx(1.0 / r, rel=1e-15)
    e = R / r
    np.testing.assert_allclose(D[2], (3 * np.outer(e, e) - np.eye(3)) / r**3, atol=1e-15)
    h = 1e-3
    for rank in range(1, 6):
        if rank >= 2:  # trace-free and symmetric
            trace = np.trace(D[rank], axis1=0, axis2=1)
            assert np.max(np.abs(trace)) < 1e-14 * np.max(np.abs(D[rank]))
            for pair in ((0, 1), (0, rank - 1)):
                assert np.array_equal(np.swapaxes(D[rank], *pair), D[rank])
        fd = np.zeros_like(D[rank])
        for i in range(3):
            dR = np.zeros(3)
            dR[i] = h
            f = [ref.inverse_distance_derivatives(R + s * dR, rank - 1)[rank - 1]
                 for s in (2, 1, -1, -2)]
            fd[..., i] = (-f[0] + 8 * f[1] - 8 * f[2] + f[3]) / (12 * h)
        assert relative(fd, D[rank]) < 1e-9


def test_rejects_unknown_order(ellipsoids):
    with pytest.raises(ValueError, match="order"):
        potential(*ellipsoids, R_CASE, C_CASE, order=1)


# ---- exactness: point clouds and published reference numbers --------------------------------
@pytest.mark.parametrize("order", [0, 2, 3, 4])
def test_matches_pairwise_truncated_sum_of_point_clouds(clouds, order):
    (body_a, pa, ma), (body_b, pb, mb) = clouds
    assert body_a.has_odd_integrals and body_b.has_odd_integrals
    C = random_rotation(np.random.default_rng(7))
    R = np.array([3.0, 1.2, -0.7])
    got = potential(body_a, body_b, R, C, order)
    want = oracles.pairwise_truncated(G, pa, ma, pb @ C.T, mb, R, order)
    assert got[0] == pytest.approx(want[0], rel=1e-13)
    assert relative(got[1], want[1]) < 1e-13
    if order == 0:
        assert np.abs(got[2]).max() == 0.0 and np.abs(got[3]).max() == 0.0
    else:
        assert relative(got[2], want[2]) < 1e-13
        assert relative(got[3], want[3]) < 1e-13
    if order == 3:  # the odd (S3) terms are really there and really tested
        lower = potential(body_a, body_b, R, C, 2)
        assert abs(got[0] - lower[0]) > 1e-6 * abs(got[0])
        assert relative(lower[3], got[3]) > 1e-3


REFERENCE_NUMBERS, REFERENCE_EXACT = oracles.REFERENCE_NUMBERS, oracles.REFERENCE_EXACT


def test_rotation_of_reference_case():
    np.testing.assert_allclose(C_CASE, oracles.REFERENCE_S, rtol=0, atol=1e-15)


@pytest.mark.parametrize("order", [0, 2, 4])
def test_reproduces_reference_numbers(ellipsoids, order):
    U, force, torque_a, torque_b = potential(*ellipsoids, R_CASE, C_CASE, order)
    U_want, dUdR_want, tb_want, ta_want = REFERENCE_NUMBERS[order]
    assert U == pytest.approx(U_want, rel=1e-12)
    # the table prints 15 decimals: the torques (~1e-4) carry only ~11 significant digits, so
    # allow half a unit of the last printed decimal on top of 1e-12 relative
    printed = 5e-16
    np.testing.assert_allclose(-force, dUdR_want, rtol=1e-12, atol=printed)
    if tb_want is not None:
        np.testing.assert_allclose(torque_b, tb_want, rtol=1e-12, atol=printed)
        np.testing.assert_allclose(torque_a, ta_want, rtol=1e-12, atol=printed)


def test_oracles_reproduce_reference_numbers():
    """The exact oracles themselves against docs/physics.md §11.6's exact rows."""
    U, force, ta, tb = oracles.ellipsoid_ellipsoid(G, MASS_A, AXES_A, MASS_B, AXES_B,
                                                   R_CASE, C_CASE, nodes=(24, 32, 64))
    U_want, dUdR_want, tb_want, ta_want = REFERENCE_EXACT
    assert U == pytest.approx(U_want, rel=1e-12)
    assert relative(-force, dUdR_want) < 1e-11
    assert relative(tb, tb_want) < 1e-10 and relative(ta, ta_want) < 1e-10

    U, force, ta, tb = oracles.sphere_ellipsoid(G, 1.0, MASS_B, AXES_B, R_CASE, C_CASE)
    assert U == pytest.approx(-4.640252167727904e-02, rel=1e-13)
    assert relative(-force, [0.01999885074447, 0.006891477414902, 0.004090966412556]) < 1e-12
    assert relative(tb, [0.000107085522828, -0.000182392527324, -0.000216240691324]) < 1e-11
    assert np.all(ta == 0.0)

    x = [1.2, -0.9, 0.5]
    assert oracles.ellipsoid_potential(G, 1.0, AXES_A, x)[0] == pytest.approx(
        -6.437065559016371e-01, rel=1e-13)
    assert relative(oracles.ellipsoid_attraction(G, 1.0, AXES_A, x)[0],
                    [-0.305048803780253, 0.249525554728334, -0.149496877622731]) < 1e-13


def test_ellipsoid_oracle_attraction_is_minus_gradient_and_sphere_limit():
    rng = np.random.default_rng(3)
    h = 1e-4
    for x in rng.normal(size=(5, 3)) * 2.0:
        if np.sum((x / AXES_A) ** 2) < 1.2:
            continue
        fd = [(oracles.ellipsoid_potential(G, 2.0, AXES_A, x + h * d)[0]
               - oracles.ellipsoid_potential(G, 2.0, AXES_A, x - h * d)[0]) / (2 * h)
              for d in np.eye(3)]
        assert relative(-np.array(fd), oracles.ellipsoid_attraction(G, 2.0, AXES_A, x)[0]) < 1e-7
    x = np.array([[0.3, 1.1, -2.0]])
    assert oracles.ellipsoid_potential(G, 2.0, (0.5, 0.5, 0.5), x)[0] == pytest.approx(
        -2.0 / np.linalg.norm(x), rel=1e-14)


def test_quadrature_over_either_body_agrees():
    R = 2.3 * R_CASE / np.linalg.norm(R_CASE)
    over_a = oracles.ellipsoid_ellipsoid(G, MASS_A, AXES_A, MASS_B, AXES_B, R, C_CASE, over="a")
    over_b = oracles.ellipsoid_ellipsoid(G, MASS_A, AXES_A, MASS_B, AXES_B, R, C_CASE, over="b")
    assert over_a[0] == pytest.approx(over_b[0], rel=1e-12)
    for i in (1, 2, 3):
        assert relative(over_a[i], over_b[i]) < 1e-10


# ---- calculus: force and torques are derivatives of U ---------------------------------------
def five_point(f, h):
    return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)


def pairs(ellipsoids, clouds):
    return [("ellipsoids", *ellipsoids), ("lumpy", clouds[0][0], clouds[1][0])]


@pytest.mark.parametrize("order", [2, 3, 4])
def test_force_and_torques_are_derivatives_of_U(ellipsoids, clouds, order):
    for label, body_a, body_b in pairs(ellipsoids, clouds):
        R, C = R_CASE * 1.2, C_CASE
        _, force, torque_a, torque_b = potential(body_a, body_b, R, C, order)

        def U(R_, C_):
            return potential(body_a, body_b, R_, C_, order)[0]

        h = 1e-3
        grad = np.array([five_point(lambda s: U(R + s * d, C), h) for d in np.eye(3)])
        # B alone rotates by w: C -> exp(ŵ) C.  A alone: R -> exp(ŵ)ᵀ R, C -> exp(ŵ)ᵀ C.
        dU_b = np.array([five_point(lambda s: U(R, rotation_vector(s * d) @ C), h)
                         for d in np.eye(3)])
        dU_a = np.array([five_point(lambda s: U(rotation_vector(s * d).T @ R,
                                                rotation_vector(s * d).T @ C), h)
                         for d in np.eye(3)])
        assert relative(force, -grad) < 1e-7, label
        assert relative(torque_b, -dU_b) < 1e-7, label
        assert relative(torque_a, -dU_a) < 1e-7, label


@pytest.mark.parametrize("order", [0, 2, 3, 4])
def test_torque_identity(ellipsoids, clouds, order):
    """Rotating everything together leaves U unchanged: R × F + μ1 + μ2 = 0."""
    rng = np.random.default_rng(11)
    for label, body_a, body_b in pairs(ellipsoids, clouds):
        for _ in range(3):
            R = rng.normal(size=3)
            R *= rng.uniform(2.0, 5.0) / np.linalg.norm(R)
            _, force, torque_a, torque_b = potential(body_a, body_b, R, random_rotation(rng), order)
            rxf = np.cross(R, force)
            scale = np.linalg.norm(R) * np.linalg.norm(force) + np.linalg.norm(torque_a) \
                + np.linalg.norm(torque_b)
            assert np.linalg.norm(rxf + torque_a + torque_b) <= 1e-14 * scale, label


# ---- exact special cases --------------------------------------------------------------------
def test_two_spheres_are_point_masses():
    a, b = Sphere(0.7, mass=3.0), Sphere(0.2, mass=0.5)
    R = np.array([1.1, -2.0, 0.4])
    r = np.linalg.norm(R)
    for order in (0, 2, 3, 4):
        U, force, torque_a, torque_b = potential(a, b, R, C_CASE, order)
        assert U == pytest.approx(-G * 1.5 / r, rel=1e-14)
        assert relative(force, -G * 1.5 * R / r**3) < 1e-14
        scale = np.linalg.norm(R) * np.linalg.norm(force)
        assert np.linalg.norm(torque_a) < 1e-14 * scale and np.linalg.norm(torque_b) < 1e-14 * scale


@pytest.mark.parametrize("sphere_is", ["a", "b"])
def test_sphere_ellipsoid_truncation_error_falls_as_R_minus_6(sphere_is):
    """Against the exact Carlson-integral potential; the first neglected term is order 6, so the
    relative error in U falls like R^-6 and in the ellipsoid's torque like R^-4 (docs/physics.md §11.2)."""
    if sphere_is == "a":  # sphere primary, ellipsoid secondary: the torque is on B
        sphere_mass, ell_mass, ell_axes = 1.0, MASS_B, AXES_B
        bodies = (Sphere(0.3, mass=sphere_mass), Ellipsoid(*ell_axes, mass=ell_mass))
        ellipsoid_torque, sphere_torque = 3, 2
    else:  # ellipsoid primary, small sphere secondary: the torque is on A
        sphere_mass, ell_mass, ell_axes = 0.1, MASS_A, AXES_A
        bodies = (Ellipsoid(*ell_axes, mass=ell_mass), Sphere(0.1, mass=sphere_mass))
        ellipsoid_torque, sphere_torque = 2, 3
    direction = R_CASE / np.linalg.norm(R_CASE)
    distances = np.array([1.5, 3.0, 6.0])
    err_U, err_torque = [], []
    for d in distances:
        R = d * direction
        got = potential(*bodies, R, C_CASE, 4)
        exact = oracles.sphere_ellipsoid(G, sphere_mass, ell_mass, ell_axes, R, C_CASE, sphere_is)
        err_U.append(abs(got[0] - exact[0]) / abs(exact[0]))
        err_torque.append(relative(got[ellipsoid_torque], exact[ellipsoid_torque]))
        assert np.linalg.norm(got[sphere_torque]) < 1e-14 * np.linalg.norm(got[ellipsoid_torque])
    slope_U = np.polyfit(np.log(distances), np.log(err_U), 1)[0]
    slope_torque = np.polyfit(np.log(distances), np.log(err_torque), 1)[0]
    assert abs(slope_U + 6.0) < 0.3, err_U
    assert abs(slope_torque + 4.0) < 0.3, err_torque
    assert err_U[0] < 1e-3 and err_torque[0] < 0.1


# docs/physics.md §11.5 (its direction of R is not stated; along R_CASE the measured errors
# come out within a factor ~5 of these): |R| -> (dU, dF, dM_B, dM_A)
TRUNCATION_ERRORS = {
    2: {2.2: (2.8e-04, 3.9e-03, 1.1e-01, 1.3e-01), 4.4: (1.9e-05, 2.4e-04, 2.8e-02, 3.2e-02),
        8.8: (1.2e-06, 1.5e-05, 7.2e-03, 8.1e-03)},
    4: {2.2: (2.4e-05, 4.1e-04, 1.0e-02, 1.3e-02), 4.4: (3.1e-07, 6.1e-06, 6.5e-04, 8.4e-04),
        8.8: (4.7e-09, 9.4e-08, 4.1e-05, 5.3e-05)},
}


def test_ellipsoid_pair_truncation_error_matches_table(ellipsoids):
    direction = R_CASE / np.linalg.norm(R_CASE)
    errors = {}
    for distance in (2.2, 4.4, 8.8):
        R = distance * direction
        U, force, ta, tb = oracles.ellipsoid_ellipsoid(G, MASS_A, AXES_A, MASS_B, AXES_B, R, C_CASE)
        for order in (2, 4):
            got = potential(*ellipsoids, R, C_CASE, order)
            err = np.array([abs(got[0] - U) / abs(U), relative(got[1], force),
                            relative(got[3], tb), relative(got[2], ta)])
            table = np.array(TRUNCATION_ERRORS[order][distance])
            assert np.all(err < 3.0 * table), (order, distance, err, table)
            assert np.all(err > 0.1 * table), (order, distance, err, table)
            errors[order, distance] = err
        assert np.all(errors[4, distance] < errors[2, distance])


# ---- frame consistency ----------------------------------------------------------------------
def test_invariance_under_global_rotation(clouds):
    (body_a, _, _), (body_b, _, _) = clouds
    rng = np.random.default_rng(5)
    Q = random_rotation(rng)
    R, C = np.array([2.5, -1.0, 0.8]), random_rotation(rng)
    J, S3, S4 = tensors_a = ref.body_tensors(body_a)
    rotated_a = (np.einsum("ia,jb,ab->ij", Q, Q, J), np.einsum("ia,jb,kc,abc->ijk", Q, Q, Q, S3),
                 np.einsum("ia,jb,kc,ld,abcd->ijkl", Q, Q, Q, Q, S4))
    tensors_b = ref.body_tensors(body_b)
    for order in (2, 3, 4):
        base = ref.mutual_potential(G, body_a.mass, tensors_a, body_b.mass, tensors_b,
                                    R, C, order)
        turned = ref.mutual_potential(G, body_a.mass, rotated_a, body_b.mass, tensors_b,
                                      Q @ R, Q @ C, order)
        assert turned[0] == pytest.approx(base[0], rel=1e-14)
        for i in (1, 2, 3):
            assert relative(turned[i], Q @ base[i]) < 1e-13


def test_swapping_the_bodies(clouds):
    """B as the primary: R' = −CᵀR, C' = Cᵀ; U unchanged, vectors rotate by Cᵀ (docs/physics.md §11.7)."""
    (body_a, _, _), (body_b, _, _) = clouds
    R, C = np.array([2.5, -1.0, 0.8]), random_rotation(np.random.default_rng(9))
    for order in (2, 3, 4):
        U, force, ta, tb = potential(body_a, body_b, R, C, order)
        U2, force2, ta2, tb2 = potential(body_b, body_a, -C.T @ R, C.T, order)
        assert U2 == pytest.approx(U, rel=1e-14)
        assert relative(force2, -C.T @ force) < 1e-13
        assert relative(ta2, C.T @ tb) < 1e-13
        assert relative(tb2, C.T @ ta) < 1e-13


# ---- equations of motion --------------------------------------------------------------------
def initial_state(body_a, body_b, R, velocity, omega1, omega2_body, C, S1=np.eye(3)):
    m = body_a.mass * body_b.mass / (body_a.mass + body_b.mass)
    inertia_a = ref.inertia_tensor(ref.body_tensors(body_a)[0])
    inertia_b = ref.inertia_tensor(ref.body_tensors(body_b)[0])
    # Ṙ = R × Ω1 + P/m is the rate in the rotating A frame; adding Ω1 × R leaves P/m, so P/m is
    # the inertial relative velocity expressed in the A frame
    P = m * np.asarray(velocity, dtype=np.float64)
    return np.concatenate([R, P, inertia_a @ omega1, C @ inertia_b @ omega2_body,
                           np.ravel(C), np.ravel(S1)])


def test_rhs_of_point_masses_is_kepler():
    a, b = Sphere(0.5, mass=2.0), Sphere(0.1, mass=0.5)
    R, v = np.array([3.0, 1.0, -0.5]), np.array([0.1, 0.6, 0.2])
    y = initial_state(a, b, R, v, np.zeros(3), np.zeros(3), C_CASE)
    dy = ref.rhs(G, a, b, y)
    m = 1.0 / 2.5
    np.testing.assert_allclose(dy[0:3], v, rtol=1e-15)
    np.testing.assert_allclose(dy[3:6] / m, -G * 2.5 * R / np.linalg.norm(R) ** 3, rtol=1e-14)
    assert np.abs(dy[6:]).max() < 1e-15


def test_energy_and_angular_momentum_parts(ellipsoids):
    body_a, body_b = ellipsoids
    omega1, omega2 = np.array([0.1, -0.2, 0.9]), np.array([0.05, 0.1, 0.3])
    y = initial_state(body_a, body_b, R_CASE, [0.1, 0.5, 0.05], omega1, omega2, C_CASE,
                      rotation((1, -1, 2), 0.4))
    E = ref.energy(G, body_a, body_b, y)
    K = ref.angular_momentum(body_a, body_b, y)
    moments_a, moments_b = body_a.moments, body_b.moments
    assert E["primary_spin"] == pytest.approx(0.5 * omega1 @ (moments_a * omega1), rel=1e-14)
    assert E["secondary_spin"] == pytest.approx(0.5 * omega2 @ (moments_b * omega2), rel=1e-14)
    U = potential(body_a, body_b, R_CASE, C_CASE)[0]
    m = MASS_A * MASS_B / (MASS_A + MASS_B)
    assert E["orbit"] == pytest.approx(y[3:6] @ y[3:6] / (2 * m) + U, rel=1e-14)
    parts = E["orbit"] + E["primary_spin"] + E["secondary_spin"]
    assert E["total"] == pytest.approx(parts, rel=1e-15)
    S1 = y[21:].reshape(3, 3)
    assert relative(K["secondary_spin"], S1 @ C_CASE @ (moments_b * omega2)) < 1e-14
    assert relative(K["orbit"], S1 @ np.cross(R_CASE, y[3:6])) < 1e-15
    assert relative(K["total"], K["orbit"] + K["primary_spin"] + K["secondary_spin"]) < 1e-15


def test_integrate_conserves_energy_and_angular_momentum(ellipsoids):
    """Two ellipsoids, inclined eccentric orbit, tumbling spins: E and K drift < 1e-9 over
    ~3.5 orbits at rtol 1e-11 while the parts exchange far more than that."""
    body_a, body_b = ellipsoids
    R = np.array([3.0, 0.0, 0.4])
    v = 0.9 * np.sqrt(G * 1.1 / 3.0) * np.array([0.0, 0.95, 0.3])
    y0 = initial_state(body_a, body_b, R, v, np.array([0.05, 0.02, 0.5]),
                       np.array([0.02, 0.05, 0.3]), C_CASE)
    t_eval = np.linspace(0.0, 120.0, 41)
    sol = ref.integrate(G, body_a, body_b, y0, (0.0, 120.0), rtol=1e-11, atol=1e-13, t_eval=t_eval)
    assert sol.success
    energies = [ref.energy(G, body_a, body_b, y) for y in sol.y.T]
    momenta = [ref.angular_momentum(body_a, body_b, y) for y in sol.y.T]
    total_E = np.array([e["total"] for e in energies])
    total_K = np.array([k["total"] for k in momenta])
    assert np.max(np.abs(total_E - total_E[0])) < 1e-9 * abs(total_E[0])
    assert np.max(np.linalg.norm(total_K - total_K[0], axis=1)) < 1e-9 * np.linalg.norm(total_K[0])
    # the test has teeth: energy and angular momentum really flow between orbit and spins
    secondary_E = np.array([e["secondary_spin"] for e in energies])
    orbit_K = np.array([k["orbit"] for k in momenta])
    assert np.ptp(secondary_E) > 1e-4 * abs(total_E[0])
    assert np.max(np.linalg.norm(orbit_K - orbit_K[0], axis=1)) > 1e-4 * np.linalg.norm(total_K[0])
    for y in sol.y.T:  # the attitude matrices stay rotations
        for M in (y[12:21].reshape(3, 3), y[21:30].reshape(3, 3)):
            assert np.abs(M.T @ M - np.eye(3)).max() < 1e-9


def test_planar_start_stays_planar(ellipsoids):
    body_a, body_b = ellipsoids
    R = np.array([3.0, 0.0, 0.0])
    v = np.array([0.0, 0.55, 0.0])
    y0 = initial_state(body_a, body_b, R, v, np.array([0.0, 0.0, 0.5]), np.array([0.0, 0.0, 0.35]),
                       rotation((0, 0, 1), 0.3))
    sol = ref.integrate(G, body_a, body_b, y0, (0.0, 60.0), rtol=1e-10, atol=1e-12)
    assert sol.success
    y = sol.y
    out_of_plane = np.concatenate([y[[2, 5, 6, 7, 9, 10]],          # R_z, P_z, Γ1_xy, Γ2_xy
                                   y[[14, 17, 18, 19]],             # S_xz, S_yz, S_zx, S_zy
                                   y[[23, 26, 27, 28]]])            # same for S1
    assert np.abs(out_of_plane).max() < 1e-12
    spin_b = y[11] / y0[11]   # the secondary's spin changes: the dynamics is not trivial
    assert np.ptp(spin_b) > 1e-3
