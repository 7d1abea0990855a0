"""Exact (or exact-to-roundoff) references for testing the mutual potential.

Test-only code; scipy is allowed here. Conventions are those of ti_spinorbit.model.reference
(docs/physics.md §1.3–1.4): A frame, R from A's centre of mass to B's, C takes B-frame vectors
to the A frame, force_on_b = −∂U/∂R, torques defined by δU = −μ·δθ for a rotation of one body.

* Homogeneous ellipsoid exterior potential and attraction in closed form with Carlson's R_F and
  R_D (MacMillan 1930; Chandrasekhar 1969 ch. 3; docs/physics.md §11.1).
* Sphere–ellipsoid mutual potential, force and torques, exact (docs/physics.md §11.2): a
  uniform sphere acts, and is acted on, exactly as a point mass at its centre.
* Ellipsoid–ellipsoid by Gauss quadrature of the exact potential of one body over the volume
  of the other (docs/physics.md §11.3); spectrally convergent while the bodies are apart.
* Point-cloud pairwise sum of the truncated Legendre series (docs/physics.md §11.4,
  Hou et al. 2017 eq. 8): algebraically identical to the truncated inertia-integral potential
  of the same cloud, so it tests an implementation to roundoff, odd moments included.
"""

import numpy as np
from numpy.polynomial import legendre
from scipy.special import elliprd, elliprf


# ---- single homogeneous ellipsoid -----------------------------------------------------------
def confocal_lambda(x, semi_axes, iterations=200):
    """Largest root λ of Σ x_i²/(a_i² + λ) = 1 (0 for points inside), for points x of shape (N, 3).

    f(λ) = Σ x_i²/(a_i²+λ) − 1 is convex and decreasing; Newton from the left end of the bracket
    [max(0, r² − a_max²), r² − a_min²] climbs monotonically to the root."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    axes2 = np.asarray(semi_axes, dtype=np.float64) ** 2
    x2 = x * x
    r2 = x2.sum(-1)
    lam = np.maximum(0.0, r2 - axes2.max())
    upper = np.maximum(0.0, r2 - axes2.min())
    for _ in range(iterations):
        d = axes2 + lam[:, None]
        f = (x2 / d).sum(-1) - 1.0
        slope = -(x2 / d**2).sum(-1)
        step = np.where(slope < 0, -f / np.where(slope < 0, slope, -1.0), 0.0)
        new = np.clip(lam + step, lam, upper)
        if np.all(new - lam <= 1e-16 * np.maximum(1.0, lam)):
            lam = new
            break
        lam = new
    inside = (x2 / axes2).sum(-1) <= 1.0
    return np.where(inside, 0.0, lam)


def _carlson_arguments(x, semi_axes):
    lam = confocal_lambda(x, semi_axes)
    a, b, c = semi_axes
    return a * a + lam, b * b + lam, c * c + lam


def ellipsoid_potential(G, mass, semi_axes, x):
    """Gravitational potential Φ(x) (per unit mass, negative) of a homogeneous ellipsoid at points
    x (N, 3) of its own principal frame:

        Φ = −(3GM/2) [R_F(A,B,C) − x² R_D(B,C,A)/3 − y² R_D(C,A,B)/3 − z² R_D(A,B,C)/3],
        A = a² + λ, B = b² + λ, C = c² + λ."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    A, B, C = _carlson_arguments(x, semi_axes)
    return -1.5 * G * mass * (elliprf(A, B, C) - x[:, 0] ** 2 * elliprd(B, C, A) / 3
                              - x[:, 1] ** 2 * elliprd(C, A, B) / 3
                              - x[:, 2] ** 2 * elliprd(A, B, C) / 3)


def ellipsoid_attraction(G, mass, semi_axes, x):
    """Attraction g = −∇Φ (N, 3) of a homogeneous ellipsoid at points x (N, 3) of its frame:
    g = −GM (x R_D(B,C,A), y R_D(C,A,B), z R_D(A,B,C)); the ∂λ/∂x terms vanish because the
    integrand of Φ is zero at u = λ."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    A, B, C = _carlson_arguments(x, semi_axes)
    return -G * mass * np.stack([x[:, 0] * elliprd(B, C, A), x[:, 1] * elliprd(C, A, B),
                                 x[:, 2] * elliprd(A, B, C)], axis=-1)


# ---- sphere + ellipsoid, exact --------------------------------------------------------------
def sphere_ellipsoid(G, sphere_mass, ellipsoid_mass, semi_axes, R, C, sphere_is="a"):
    """Exact U, force_on_b, torque_a, torque_b for a uniform sphere and a homogeneous ellipsoid.

    ``sphere_is='a'``: A is the sphere, B the ellipsoid with attitude C at R. Then with the sphere
    centre in B's frame p = Cᵀ(−R): U = M_s Φ_B(p), ∂U/∂R = C M_s g_B(p), torque_a = 0 and
    torque_b = −R × force_on_b.
    ``sphere_is='b'``: A is the ellipsoid (principal frame), B the sphere at R (C irrelevant).
    U = M_s Φ_A(R), force_on_b = M_s g_A(R), torque_b = 0, torque_a = −R × force_on_b."""
    R = np.asarray(R, dtype=np.float64)
    C = np.asarray(C, dtype=np.float64)
    if sphere_is == "a":
        p = C.T @ (-R)
        U = sphere_mass * ellipsoid_potential(G, ellipsoid_mass, semi_axes, p)[0]
        force_on_b = -C @ (sphere_mass * ellipsoid_attraction(G, ellipsoid_mass, semi_axes, p)[0])
        return U, force_on_b, np.zeros(3), -np.cross(R, force_on_b)
    if sphere_is == "b":
        U = sphere_mass * ellipsoid_potential(G, ellipsoid_mass, semi_axes, R)[0]
        force_on_b = sphere_mass * ellipsoid_attraction(G, ellipsoid_mass, semi_axes, R)[0]
        return U, force_on_b, -np.cross(R, force_on_b), np.zeros(3)
    raise ValueError(f"sphere_is must be 'a' or 'b' (got {sphere_is!r})")


# ---- ellipsoid + ellipsoid by quadrature ----------------------------------------------------
def ellipsoid_volume_nodes(mass, semi_axes, nodes=(16, 24, 48)):
    """Points (N, 3) and mass weights (N,) of a product quadrature over a homogeneous ellipsoid.

    x = (a r sinθ cosφ, b r sinθ sinφ, c r cosθ): Gauss–Legendre in r ∈ [0, 1] and μ = cosθ,
    uniform (trapezoid, spectrally accurate for periodic integrands) in φ. dm = ρ abc r² dr dμ dφ.
    The weights sum to the mass up to roundoff; integrals of smooth functions converge
    spectrally."""
    n_r, n_mu, n_phi = nodes
    a, b, c = semi_axes
    r, w_r = legendre.leggauss(n_r)
    r, w_r = 0.5 * (r + 1.0), 0.5 * w_r
    mu, w_mu = legendre.leggauss(n_mu)
    phi = 2.0 * np.pi * (np.arange(n_phi) + 0.5) / n_phi
    w_phi = np.full(n_phi, 2.0 * np.pi / n_phi)
    rr, mm, pp = np.meshgrid(r, mu, phi, indexing="ij")
    sin_theta = np.sqrt(1.0 - mm**2)
    points = np.stack([a * rr * sin_theta * np.cos(pp), b * rr * sin_theta * np.sin(pp),
                       c * rr * mm], axis=-1).reshape(-1, 3)
    density = mass / (4.0 / 3.0 * np.pi * a * b * c)
    weights = (density * a * b * c * np.einsum("i,j,k->ijk", w_r * r**2, w_mu, w_phi)).ravel()
    return points, weights


def ellipsoid_ellipsoid(G, mass_a, axes_a, mass_b, axes_b, R, C, nodes=(16, 24, 48), over="a"):
    """U, force_on_b, torque_a, torque_b for two homogeneous ellipsoids, exact to quadrature.

    ``over='a'`` integrates B's exact potential over A's volume:
        U = ∫_A Φ_B(Cᵀ(x − R)) dm,  ∂U/∂R = ∫_A C g_B dm (the force on A),
        torque_a = ∫_A x × C g_B dm,  torque_b = R × ∂U/∂R − torque_a.
    ``over='b'`` integrates A's potential over B's volume (an independent internal check):
        U = ∫_B Φ_A(R + C y) dm,  force_on_b = ∫_B g_A dm,  torque_b = ∫_B (C y) × g_A dm,
        torque_a = −R × force_on_b − torque_b.
    Needs the bodies to be apart (A's volume outside B for 'a'), else it does not converge."""
    R = np.asarray(R, dtype=np.float64)
    C = np.asarray(C, dtype=np.float64)
    if over == "a":
        x, w = ellipsoid_volume_nodes(mass_a, axes_a, nodes)
        local = (x - R) @ C  # rows: Cᵀ(x − R)
        U = w @ ellipsoid_potential(G, mass_b, axes_b, local)
        pull = ellipsoid_attraction(G, mass_b, axes_b, local) @ C.T  # C g_B, per node
        dU_dR = w @ pull
        torque_a = w @ np.cross(x, pull)
        return U, -dU_dR, torque_a, np.cross(R, dU_dR) - torque_a
    if over == "b":
        y, w = ellipsoid_volume_nodes(mass_b, axes_b, nodes)
        arm = y @ C.T  # rows: C y
        at = R + arm
        U = w @ ellipsoid_potential(G, mass_a, axes_a, at)
        pull = ellipsoid_attraction(G, mass_a, axes_a, at)
        force_on_b = w @ pull
        torque_b = w @ np.cross(arm, pull)
        return U, force_on_b, -np.cross(R, force_on_b) - torque_b, torque_b
    raise ValueError(f"over must be 'a' or 'b' (got {over!r})")


# ---- point clouds: pairwise truncated Legendre series ---------------------------------------
def pairwise_truncated(G, points_a, masses_a, points_b_rotated, masses_b, R, order):
    """U, force_on_b, torque_a, torque_b of two point clouds with each pair's 1/d truncated.

    points_a: (NA, 3) A's points (A frame, centre of mass at 0); points_b_rotated: (NB, 3) B's
    points already in the A frame (C r_b, centre of mass at 0). With h = r_a − C r_b,
    1/|R − h| = Σ_n χ_n,  χ_n = Σ_k t^n_k (R·h)^k (h²)^{(n−k)/2} / R^{n+k+1}, t^n_k the
    coefficients of the Legendre polynomial P_n; keep n ≤ order.
    Torques: rotating B by δθ moves C r_b by δθ × C r_b (h by −δθ × C r_b), so
    torque_b = Σ_b C r_b × Σ_a ∂U/∂h; likewise torque_a = −Σ_a r_a × Σ_b ∂U/∂h."""
    R = np.asarray(R, dtype=np.float64)
    pa = np.asarray(points_a, dtype=np.float64)
    pb = np.asarray(points_b_rotated, dtype=np.float64)
    h = pa[:, None, :] - pb[None, :, :]
    w = np.multiply.outer(masses_a, masses_b)
    r = np.linalg.norm(R)
    Rh = h @ R
    hh = (h * h).sum(-1)
    U = 0.0
    dU_dR = np.zeros(3)
    dU_dh = np.zeros_like(h)
    for n in range(order + 1):
        t = legendre.leg2poly([0] * n + [1])
        for k in range(n + 1):
            if t[k] == 0.0:
                continue
            q = (n - k) // 2
            scale = -G * t[k] * r ** (-(n + k + 1))
            Rh_k = Rh**k
            Rh_km1 = k * Rh ** (k - 1) if k > 0 else np.zeros_like(Rh)
            hh_q = hh**q
            term = w * scale * Rh_k * hh_q
            U += term.sum()
            dU_dR += np.einsum("ab,abi->i", w * scale * Rh_km1 * hh_q, h) \
                - (n + k + 1) * term.sum() * R / r**2
            dU_dh += (w * scale * Rh_km1 * hh_q)[..., None] * R
            if q > 0:
                dU_dh += (w * scale * Rh_k * 2 * q * hh ** (q - 1))[..., None] * h
    torque_b = np.cross(pb, dU_dh.sum(0)).sum(0)
    torque_a = -np.cross(pa, dU_dh.sum(1)).sum(0)
    return U, -dU_dR, torque_a, torque_b


# ---- reference numbers of docs/physics.md §11.6 (independent check script, G = 1) ----
# Primary (M, a, b, c) = (1, 1, 0.8, 0.6); secondary (0.1, 0.45, 0.35, 0.3); R and C below.
REFERENCE_R = np.array([2.0, 0.7, 0.4])
REFERENCE_S = np.array([[0.471809584044725, -0.777130365628833, 0.416490229442588],
                          [0.849984216105423, 0.526449971902167, 0.019423168018049],
                          [-0.234355603251114, 0.3448460843649, 0.908932686904263]])
# order: (U, dU/dR, torque_b, torque_a)
REFERENCE_NUMBERS = {
    0: (-4.637388957601683e-02, [0.019945758957427, 0.006981015635099, 0.003989151791485],
        None, None),
    2: (-4.722125681191042e-02, [0.020901821846979, 0.007531655778155, 0.004600471362575],
        [0.000106780706911, -0.000181360529184, -0.000216522608481],
        [0.00010088693563, -0.000658853457174, 0.000648558871906]),
    4: (-4.724872112328452e-02, [0.020943073120956, 0.0075641362118, 0.004680678125988],
        [0.000129307596712, -0.000205694371706, -0.000235296116478],
        [0.00012151260676, -0.000778432631888, 0.000703417355409]),
}
REFERENCE_EXACT = (
    -4.724895694704011e-02, [0.02094142513142, 0.007564587576963, 0.004691238197687],
    [0.000133002791455, -0.000208557107378, -0.00023608740019],
    [0.000125028916141, -0.000797349235428, 0.000706264962124])


