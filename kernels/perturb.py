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
"""

import taichi as ti

from ti_spinorbit.layout import perturbation as _L

# The block's columns (relative to its start, the model's NPAR), the accumulators after the
# state and the constant-Q rate floor are ti_spinorbit.layout's, shared with the host.
Q_TIDE1, Q_TIDE2, Q_YORP1, Q_YORP2, Q_BYORP = _L.Q_TIDE1, _L.Q_TIDE2, _L.Q_YORP1, _L.Q_YORP2, _L.Q_BYORP
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
