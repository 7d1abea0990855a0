"""Dissipative and radiative perturbations in the equations of motion (Taichi funcs):
constant-time-lag (or constant-Q) tides, YORP and BYORP (docs/physics.md §13).

The host objects (``ti_spinorbit.model.perturbations``) turn SI parameters into a block of
``NPERT`` scaled numbers appended to each member's kernel parameter row (after the model's
own ``NPAR`` columns). A kernel variant built with perturbations also carries ``NACC``
accumulators after the model's state:

    W        work done on the system by the perturbations (scaled energy, m a² n²):
             mechanical energy − W is constant along an exact solution;
    L_ext    angular momentum received from outside (inertial frame, 3 components):
             total angular momentum − L_ext is constant. Tides exchange angular momentum
             between the orbit and a spin only, so only YORP and BYORP change it.

Both are integrated by the same Runge-Kutta steps as the state (dW/dt = power, dL_ext/dt =
external torque) but left out of the error norm, so they cost steps nothing and are as
accurate as the quadrature of the method.

Tide raised on body b by the other body (mass M), constant time lag Δt (Mignard 1979; Hut
1981), R and V the relative position and velocity (secondary minus primary) and Ω_b the
body's angular velocity, all in one frame:

    F = −(κ / r⁸) [ R + Δt ( 2 (R·V)/r² R + V − Ω_b × R ) ],   κ = 3 k2 G M² R_b⁵,

the force on the relative motion (m_red dV/dt = F); the body receives the torque −R × F.
This is the first-order expansion in Δt of the lagged bulge's quadrupole (derived in
docs/physics.md §13.1). Constant Q replaces Δt by (1/2Q) / |w| with w = Ω_b × R̂ − (V −
(R̂·V) R̂)/r the bulge's angular rate relative to the tide raiser, regularised as
(1/2Q) / sqrt(|w|² + Q_RATE_FLOOR²) so that the torque turns smoothly through
synchronism.

YORP: a torque T_b along the body's z axis (its spin axis in the paper's configuration),
computed by the host in the chosen convention (``perturbations.YORP_CONVENTIONS``,
docs/physics.md §13.2); the kernels take its value as given.
BYORP: an acceleration a_B of the relative motion along V/|V| (a force on the secondary
F_B = m_s a_B; positive expands the orbit).

Third bodies (docs/physics.md §13.11, §13.12): the Sun and a passing planet, one slot each
(``THIRD_BODIES``), with the same terms. The body at D from the barycentre (on a conic
relative to it, solved per stage: the Sun on minus the barycentre's heliocentric ellipse, a
planet on its hyperbola), the primary at −νR and the secondary at
(1 − ν)R, ν = m2/(m1 + m2). The relative acceleration μ_⊙ [g((1 − ν)R) − g(−νR)] with
g(x) = (D − x)/|D − x|³ is written as the sum of Battin's cancellation-free differences

    g(x) − g(0) = −(x + f(q) D) / |D − x|³,   q = x·(x − 2D)/D²,
    f(q) = (1 + q)^{3/2} − 1 = q (3 + 3q + q²) / (1 + (1 + q)^{3/2}),

whose two terms add (never subtract) at a far Sun. Each body b at d_b from the Sun's
position (d = Sun − body) takes the quadrupole gravity-gradient torque
τ_b = 3 μ_⊙ (J_b d) × d / |d|⁵ = 3 μ_⊙ d × (I_b d) / |d|⁵, J_b = ∫ r rᵀ dm the body's
second moments (the body row's T^200, T^020, T^002 in its principal frame).
"""

import taichi as ti

from ti_spinorbit.layout import perturbation as _L

# The block's columns (relative to its start, the model's NPAR), the accumulators after the
# state and the constant-Q rate floor are ti_spinorbit.layout's, shared with the host.
Q_TIDE1, Q_TIDE2, Q_YORP1, Q_YORP2, Q_BYORP = _L.Q_TIDE1, _L.Q_TIDE2, _L.Q_YORP1, _L.Q_YORP2, _L.Q_BYORP
Q_SUN, Q_SUN_A, Q_SUN_E, Q_SUN_N, Q_SUN_M0 = _L.Q_SUN, _L.Q_SUN_A, _L.Q_SUN_E, _L.Q_SUN_N, _L.Q_SUN_M0
Q_SUN_P, Q_SUN_Q, Q_SUN_NU = _L.Q_SUN_P, _L.Q_SUN_Q, _L.Q_SUN_NU
Q_SUN_J1, Q_SUN_J2 = _L.Q_SUN_J1, _L.Q_SUN_J2
Q_FLYBY, THIRD_BODIES, Q_RAD = _L.Q_FLYBY, _L.THIRD_BODIES, _L.Q_RAD
T_MU, T_A, T_E, T_N, T_M0, T_P, T_Q, T_NU, T_J1, T_J2 = (_L.T_MU, _L.T_A, _L.T_E, _L.T_N, _L.T_M0,
                                                         _L.T_P, _L.T_Q, _L.T_NU, _L.T_J1, _L.T_J2)
#: Newton iterations on Kepler's equation at most (they stop at round-off, in a few)
KEPLER_ITERATIONS = 50
NPERT, NACC, Q_RATE_FLOOR = _L.NPERT, _L.NACC, _L.Q_RATE_FLOOR


@ti.func
def tide_force(kappa, dt, lag, R, V, Om):
    """Tidal force on the relative motion (see the module docstring) from a bulge with
    coefficient κ and time lag Δt, or constant lag angle ``lag`` = 1/(2Q) when > 0."""
    r2 = R.dot(R)
    rv = R.dot(V)
    d = dt
    if lag > 0.0:
        r = ti.sqrt(r2)
        w = Om.cross(R) / r - (V - (rv / r2) * R) / r
        d = lag / ti.sqrt(w.norm_sqr() + Q_RATE_FLOOR * Q_RATE_FLOOR)
    return -(kappa / (r2 * r2 * r2 * r2)) * (R + d * ((2.0 * rv / r2) * R + V - Om.cross(R)))


@ti.func
def tide_polar(kappa, dt, lag, r, vr, ell, omega):
    """The same force in the plane, radial and tangential components (F_r, F_t), for
    R = r r̂, V = v_r r̂ + (ℓ/r) t̂ and Ω_b = ω ẑ."""
    inv_r = 1.0 / r
    theta_dot = ell * inv_r * inv_r
    d = dt
    if lag > 0.0:
        w = omega - theta_dot
        d = lag / ti.sqrt(w * w + Q_RATE_FLOOR * Q_RATE_FLOOR)
    inv_r8 = inv_r * inv_r * inv_r * inv_r
    inv_r8 = inv_r8 * inv_r8
    return -kappa * inv_r8 * (r + 3.0 * d * vr), kappa * inv_r8 * d * r * (omega - theta_dot)


@ti.func
def tide_of(p: ti.template(), i, col: ti.template(), R, V, Om):
    """The 3-D tidal force of the tide whose block columns start at ``col`` (κ, Δt, 1/2Q)
    in member i's row; zero (and nothing evaluated) when κ = 0."""
    F = ti.Vector([0.0, 0.0, 0.0], ti.f64)
    if p[i, col] != 0.0:
        F = tide_force(p[i, col], p[i, col + 1], p[i, col + 2], R, V, Om)
    return F


@ti.func
def tide_polar_of(p: ti.template(), i, col: ti.template(), r, vr, ell, omega):
    """:func:`tide_polar` of the tide whose block columns start at ``col``; (0, 0) when
    κ = 0."""
    fr = 0.0
    ft = 0.0
    if p[i, col] != 0.0:
        fr, ft = tide_polar(p[i, col], p[i, col + 1], p[i, col + 2], r, vr, ell, omega)
    return fr, ft


@ti.func
def eccentric_anomaly(M, e):
    """E of Kepler's equation E − e sin E = M (e < 1) by Newton's method from Danby's start
    E = M + 0.85 e sign(M), M reduced to [−π, π), stopped at round-off."""
    two_pi = 6.283185307179586
    M = M - two_pi * ti.floor(M / two_pi + 0.5)          # in [−π, π)
    E = M + ti.select(M < 0.0, -0.85, 0.85) * e
    for _ in range(KEPLER_ITERATIONS):
        dE = (E - e * ti.sin(E) - M) / (1.0 - e * ti.cos(E))
        E -= dE
        if ti.abs(dE) <= 1e-15 * (1.0 + ti.abs(E)):   # the next would be below round-off
            break
    return E


@ti.func
def radiation_factor(p: ti.template(), i, q: ti.template(), t):
    """(a⊙² sqrt(1 − e⊙²)) / d(t)², the factor on the mean-distance YORP torques and BYORP
    acceleration at the Sun's distance d = a⊙ (1 − e⊙ cos E) of the moment (the Sun slot's
    orbit of the block starting at column ``q``); 1 for the mean-distance form (Q_RAD 0).
    Its average over a heliocentric orbit is 1."""
    f = 1.0
    k = p[i, q + Q_RAD]
    if k != 0.0:
        c = q + Q_SUN
        e = p[i, c + T_E]
        E = eccentric_anomaly(p[i, c + T_M0] + p[i, c + T_N] * t, e)
        d = p[i, c + T_A] * (1.0 - e * ti.cos(E))
        f = k / (d * d)
    return f


@ti.func
def third_body_position(p: ti.template(), i, c: ti.template(), t):
    """A third body's position relative to the barycentre at scaled time t, inertial frame:
    x P + y Q on the conic of the slot at absolute column ``c`` of member i's row. Kepler's
    equation by Newton's method to round-off (at most KEPLER_ITERATIONS) from Danby's starts:
    E = M + 0.85 e sign(M) for an ellipse (e < 1, M reduced to [−π, π)), H = sign(M)
    ln(2|M|/e + 1.8) for a hyperbola (M = e sinh H − H)."""
    a = p[i, c + T_A]
    e = p[i, c + T_E]
    M = p[i, c + T_M0] + p[i, c + T_N] * t
    x = 0.0
    y = 0.0
    if e < 1.0:
        E = eccentric_anomaly(M, e)
        x = a * (ti.cos(E) - e)
        y = a * ti.sqrt((1.0 - e) * (1.0 + e)) * ti.sin(E)
    else:
        H = ti.select(M < 0.0, -1.0, 1.0) * ti.log(2.0 * ti.abs(M) / e + 1.8)
        for _ in range(KEPLER_ITERATIONS):
            u = ti.exp(H)
            dH = (0.5 * e * (u - 1.0 / u) - H - M) / (0.5 * e * (u + 1.0 / u) - 1.0)
            H -= dH
            if ti.abs(dH) <= 1e-15 * (1.0 + ti.abs(H)):
                break
        u = ti.exp(H)
        x = a * (e - 0.5 * (u + 1.0 / u))
        y = a * ti.sqrt((e - 1.0) * (e + 1.0)) * 0.5 * (u - 1.0 / u)
    P = ti.Vector([p[i, c + T_P], p[i, c + T_P + 1], p[i, c + T_P + 2]], ti.f64)
    Q = ti.Vector([p[i, c + T_Q], p[i, c + T_Q + 1], p[i, c + T_Q + 2]], ti.f64)
    return x * P + y * Q


@ti.func
def sun_position(p: ti.template(), i, q: ti.template(), t):
    """The Sun's position relative to the barycentre (the Sun slot of the block starting at
    column ``q``): minus the barycentre's heliocentric position, stored as −P, −Q."""
    return third_body_position(p, i, q + Q_SUN, t)


@ti.func
def battin_f(q):
    """f(q) = (1 + q)^{3/2} − 1 without cancellation at small q (Battin 1999, §8.4)."""
    s = 1.0 + q
    return q * (3.0 + 3.0 * q + q * q) / (1.0 + s * ti.sqrt(s))


@ti.func
def point_mass_difference(D, x):
    """g(x) − g(0) for g(x) = (D − x)/|D − x|³ (a unit point mass at D seen from x),
    cancellation-free: −(x + f(q) D)/|D − x|³, q = x·(x − 2D)/D²."""
    q = x.dot(x - 2.0 * D) / D.dot(D)
    d = D - x
    r = d.norm()
    return -(x + battin_f(q) * D) / (r * r * r)


@ti.func
def solar_acceleration(mu, D, R, nu):
    """The Sun's tidal acceleration of the relative motion (secondary minus primary): μ [g(x2)
    − g(x1)] with x2 = (1 − ν) R, x1 = −ν R, as the sum of the two Battin differences."""
    return mu * (point_mass_difference(D, (1.0 - nu) * R) - point_mass_difference(D, -nu * R))


@ti.func
def gravity_gradient_torque(mu, d, J):
    """3 μ (J d) × d / |d|⁵: the quadrupole torque of a point mass μ at d from a body whose
    second moments are diag(J) in the same frame."""
    d2 = d.dot(d)
    Jd = ti.Vector([J[0] * d[0], J[1] * d[1], J[2] * d[2]], ti.f64)
    return (3.0 * mu / (d2 * d2 * ti.sqrt(d2))) * Jd.cross(d)


@ti.func
def gravity_gradient_torque_z(mu, d, cl, sl, c, s, dJ):
    """The z component of :func:`gravity_gradient_torque` in the planar model: 3 μ (J_xx −
    J_yy) d_x d_y / |d|⁵ in the frame of a body whose long axis is at θ = λ − ψ (cos λ,
    sin λ = ``cl``, ``sl``; cos ψ, sin ψ = ``c``, ``s``), ``dJ`` = J_xx − J_yy."""
    ct = cl * c + sl * s
    st = sl * c - cl * s
    dx = ct * d[0] + st * d[1]
    dy = ct * d[1] - st * d[0]
    d2 = d.dot(d)
    return 3.0 * mu * dJ * dx * dy / (d2 * d2 * ti.sqrt(d2))
