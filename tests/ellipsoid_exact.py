"""Exact mutual potential, force and torques of two homogeneous ellipsoids (test reference).

Route (independent of any inertia-integral expansion):

* Exterior (and interior) potential of a homogeneous ellipsoid with semi-axes a_i, mass M, in
  its principal frame (MacMillan 1930, The Theory of the Potential, ch. on ellipsoids; Chandrasekhar
  1969, Ellipsoidal Figures of Equilibrium, ch. 3):

      Φ(x) = −(3GM/4) ∫_κ^∞ (1 − Σ_i x_i²/(a_i² + u)) du/Δ(u),   Δ = Π_i (a_i² + u)^{1/2},
      g = −∇Φ = −(3GM/2) (x_i ∫_κ^∞ du/((a_i² + u) Δ(u)))_i,

  κ the largest root of the confocal equation Σ x_i²/(a_i² + κ) = 1 (κ = 0 inside); the ∂κ/∂x
  terms vanish since the integrand of Φ is zero at u = κ.
* The u-integrals are evaluated by Gauss–Legendre quadrature after u + c² = λ/t², λ = c² + κ
  (c the smallest semi-axis), which maps [κ, ∞) to t ∈ (0, 1] with a smooth, pole-free
  integrand:  du/Δ = 2λ dt / Π_i (λ + d_i t²)^{1/2},  1/(a_i² + u) = t²/(λ + d_i t²),
  d_i = a_i² − c² ≥ 0.
* The second body's volume is integrated by a product Gauss rule (Gauss–Legendre in radius and
  cos θ, trapezoid in longitude) in the ellipsoidal coordinates of its unit ball: spectrally
  convergent while it lies outside the first body.

Conventions (those of ti_spinorbit.multipole): A frame; R from A's centre to B's; C takes
B-frame vectors to the A frame; force on B; torques about each centre, δU = −τ·ε.
"""

import numpy as np
from numpy.polynomial import legendre


def confocal_kappa(x, semi_axes, iterations=100):
    """Largest root κ ≥ 0 of Σ x_i²/(a_i² + κ) = 1 for points x (N, 3); 0 inside.

    f(κ) = Σ x_i²/(a_i²+κ) − 1 is decreasing and convex; Newton from κ0 = max(0, r² − a_max²)
    (where f ≥ 0) climbs monotonically to the root."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    s2 = np.asarray(semi_axes, dtype=np.float64) ** 2
    x2 = x * x
    kappa = np.maximum(0.0, x2.sum(1) - s2.max())
    for _ in range(iterations):
        d = s2 + kappa[:, None]
        f = (x2 / d).sum(1) - 1.0
        fp = -(x2 / d**2).sum(1)
        step = np.where(f > 0, -f / fp, 0.0)
        kappa = kappa + step
        if np.all(step <= 1e-16 * np.maximum(kappa, s2.min())):
            break
    return np.where((x2 / s2).sum(1) <= 1.0, 0.0, kappa)


def _u_integrals(x, semi_axes, nodes):
    """I0 = ∫_κ^∞ du/Δ and I_i = ∫_κ^∞ du/((a_i² + u)Δ), shapes (N,) and (N, 3)."""
    s2 = np.asarray(semi_axes, dtype=np.float64) ** 2
    kappa = confocal_kappa(x, semi_axes)
    lam = s2.min() + kappa                              # (N,)
    d = s2 - s2.min()                                   # (3,)
    t, w = legendre.leggauss(nodes)
    t, w = 0.5 * (t + 1.0), 0.5 * w                     # [0, 1]
    q = lam[:, None, None] + d[None, None, :] * (t * t)[None, :, None]   # (N, nt, 3)
    base = 2.0 * lam[:, None] / np.sqrt(q.prod(-1))     # du/Δ per dt, (N, nt)
    I0 = (base * w).sum(1)
    I = np.einsum("nt,t,ntj->nj", base, w * t * t, 1.0 / q)
    return I0, I


def ellipsoid_potential(G, mass, semi_axes, x, nodes=48):
    """Φ(x), J/kg, at points x (N, 3) of the ellipsoid's principal frame."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    I0, I = _u_integrals(x, semi_axes, nodes)
    return -0.75 * G * mass * (I0 - (x * x * I).sum(1))


def ellipsoid_attraction(G, mass, semi_axes, x, nodes=48):
    """g = −∇Φ, m/s², at points x (N, 3) of the ellipsoid's principal frame."""
    x = np.atleast_2d(np.asarray(x, dtype=np.float64))
    _, I = _u_integrals(x, semi_axes, nodes)
    return -1.5 * G * mass * x * I


def volume_nodes(mass, semi_axes, nodes=(20, 20, 40)):
    """Points (N, 3) and mass weights (N,) of a product Gauss rule over a homogeneous ellipsoid:
    x = (a s sinθ cosφ, b s sinθ sinφ, c s cosθ), dm = ρ abc s² ds dcosθ dφ."""
    n_s, n_mu, n_phi = nodes
    a, b, c = semi_axes
    s, ws = legendre.leggauss(n_s)
    s, ws = 0.5 * (s + 1.0), 0.5 * ws
    mu, wmu = legendre.leggauss(n_mu)
    phi = 2.0 * np.pi * np.arange(n_phi) / n_phi
    S, MU, PHI = np.meshgrid(s, mu, phi, indexing="ij")
    st = np.sqrt(1.0 - MU * MU)
    pts = np.stack([a * S * st * np.cos(PHI), b * S * st * np.sin(PHI), c * S * MU], -1)
    w = np.einsum("i,j,k->ijk", ws * s * s, wmu, np.full(n_phi, 2.0 * np.pi / n_phi))
    return pts.reshape(-1, 3), (w.ravel() * 3.0 * mass / (4.0 * np.pi))


def exact_mutual(G, mass_a, axes_a, mass_b, axes_b, R, C, nodes=(20, 20, 40), u_nodes=48):
    """Exact (to quadrature) U (J), force on B (N), torque on B and torque on A (N m), A frame.

    U = ∫_B Φ_A dm, F = ∫_B g_A dm, τ_B = ∫_B (C y) × g_A dm about B's centre,
    τ_A = −∫_B x × g_A dm about A's centre (reaction of every element of B on A)."""
    R = np.asarray(R, dtype=np.float64)
    C = np.asarray(C, dtype=np.float64)
    y, w = volume_nodes(mass_b, axes_b, nodes)
    arm = y @ C.T
    x = R + arm
    U = float(w @ ellipsoid_potential(G, mass_a, axes_a, x, u_nodes))
    g = ellipsoid_attraction(G, mass_a, axes_a, x, u_nodes)
    F = w @ g
    torque_b = w @ np.cross(arm, g)
    torque_a = -(w @ np.cross(x, g))
    return U, F, torque_b, torque_a


def ellipsoid_integrals(mass, semi_axes, degree):
    """T^lmn = 3 M a^l b^m c^n (l−1)!!(m−1)!!(n−1)!!/(l+m+n+3)!! (all even), else 0, every
    l + m + n ≤ degree (zeros kept, so the set states its degree)."""
    def dfact(n):
        return 1.0 if n <= 0 else n * dfact(n - 2)
    a, b, c = semi_axes
    out = {}
    for d in range(degree + 1):
        for l in range(d + 1):
            for m in range(d - l + 1):
                n = d - l - m
                if l % 2 or m % 2 or n % 2:
                    out[(l, m, n)] = 0.0
                else:
                    out[(l, m, n)] = (3.0 * mass * a**l * b**m * c**n * dfact(l - 1)
                                      * dfact(m - 1) * dfact(n - 1) / dfact(l + m + n + 3))
    return out
