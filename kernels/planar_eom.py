"""Planar model: both bodies spin about the orbit normal with their equators in the orbit plane.

This is the configuration of every study in Naidu & Margot 2015. When both bodies are
mirror-symmetric about their own equator (every inertia integral with an odd z exponent is
zero, true of ellipsoids) and the start is planar, the motion stays planar exactly, so a
10-number state carries everything the 30-number 3-D state does.

State (scaled units as in ``eom.py``: length a, time 1/n, mass m1 + m2, G = 1):

    y = [r, v_r, ℓ, λ, cA, sA, w1, cB, sB, w2]

r = |R|, v_r = dr/dt, ℓ = r² dλ/dt (orbital angular momentum per reduced mass), λ the
inertial longitude of R; (cA, sA) = (cos ψ_A, sin ψ_A) and (cB, sB) = (cos ψ_B, sin ψ_B) with
ψ_A = λ − θ1, ψ_B = λ − θ2 the direction of R in each body's frame (θ_k the inertial angle
of body k's long axis); w_k = Γ_k/C_k as in the 3-D model (Γ_k the spin angular momentum
about z, C_k the body's largest principal moment; dθ_k/dt = ω_k = w_k C_k/I_zz).

Why this form (the cheapest formulation measured in experiments/README.md):

* the potential needs exactly r and the angles ψ_A, ψ_B: no square root, no rotation;
* the angles are stored as cosine and sine, so no transcendental call is made, every
  component is O(1) under one tolerance, and c² + s² = 1 drifts at the tolerance level, as
  the 3-D model's rotation matrices do;
* the stored angles are relative to the line of centres: a synchronous secondary's ψ_B only
  librates, and a fast one turns at ω − n, not ω. The Cash-Karp steps, which the fastest
  rotating component sets, are then longer than in an inertial Cartesian form;
* λ enters no derivative (only the inertial attitude of the 3-D output), so its growth with
  time costs nothing.

Potential (the 3-D model's 4th-order truncation restricted to the plane, docs/physics.md §3.2–3.5, §4.4), with V = −U (G = 1):

    V = mA mB / r + [P2(ψ_A) + Q2(ψ_B)] / r³ + [P3 + Q3] / r⁴ + [P4 + Q4 + X(ψ_A, ψ_B)] / r⁵

P_n = mB L_n^A and Q_n = ±mA L_n^B (− for odd n) are trigonometric polynomials of degree n;
their Fourier coefficients are computed once per member on the host
(``ti_spinorbit.model.planar.parameter_rows``) by contracting each body's moment tensors with the
Legendre polynomial P_n, a different route from the 3-D kernel's monomial tables. The
quadrupole-quadrupole term is

    X = x0 + xA cos2ψ_A + xB cos2ψ_B + xAB cos2ψ_A cos2ψ_B + xm cos(2ψ_A − 2ψ_B).

Equations (m the reduced mass; V_A = ∂V/∂ψ_A, V_B = ∂V/∂ψ_B):

    dr/dt = v_r        dv_r/dt = ℓ²/r³ + V_r/m        dℓ/dt = (V_A + V_B)/m
    dλ/dt = ℓ/r²       dψ_k/dt = ℓ/r² − ω_k          dw_k/dt = −V_k / C_k

The torques about z are τ_k = −V_k, so m ℓ + Γ1 + Γ2 is conserved exactly by the equations.
"""

import taichi as ti

from ti_spinorbit.layout import multipole as _MP, planar as _L

from . import perturb
from .harmonic_gravity import mutual_h

# The state offsets and the member parameter row (scaled units) are ti_spinorbit.layout's,
# shared with the host (ti_spinorbit.model.planar fills the row).
NSTATE = _L.NSTATE
Y_R, Y_VR, Y_L, Y_LAM, Y_CA, Y_SA = _L.Y_R, _L.Y_VR, _L.Y_L, _L.Y_LAM, _L.Y_CA, _L.Y_SA
Y_W1, Y_CB, Y_SB, Y_W2 = _L.Y_W1, _L.Y_CB, _L.Y_SB, _L.Y_W2
P_MM, P_INV_M, P_K1, P_F1, P_K2, P_F2 = _L.P_MM, _L.P_INV_M, _L.P_K1, _L.P_F1, _L.P_K2, _L.P_F2
P_P2, P_Q2, P_P3, P_Q3, P_P4, P_Q4 = _L.P_P2, _L.P_Q2, _L.P_P3, _L.P_Q3, _L.P_P4, _L.P_Q4
P_X, P_CONTACT, P_ESCAPE, NPAR = _L.P_X, _L.P_CONTACT, _L.P_ESCAPE, _L.NPAR
state = ti.types.vector(NSTATE, ti.f64)
#: State with the perturbation accumulators (W, L_ext) appended (``perturb.NACC``).
state_perturbed = ti.types.vector(NSTATE + perturb.NACC, ti.f64)


@ti.func
def _harmonics(c, s):
    """cos and sin of 2ψ, 3ψ, 4ψ from (cos ψ, sin ψ) by the double-angle recurrences."""
    c2 = c * c - s * s
    s2 = 2.0 * c * s
    return c2, s2, c * c2 - s * s2, s * c2 + c * s2, c2 * c2 - s2 * s2, 2.0 * c2 * s2


@ti.func
def _series(pv, o2: ti.template(), o3: ti.template(), o4: ti.template(), c, s,
            order: ti.template(), odd: ti.template()):
    """One body's P2, P3, P4 and their ψ-derivatives (trig polynomials, coefficients in p)."""
    c2, s2, c3, s3, c4, s4 = _harmonics(c, s)
    f2 = pv[o2] + pv[o2 + 1] * c2 + pv[o2 + 2] * s2
    d2 = 2.0 * (pv[o2 + 2] * c2 - pv[o2 + 1] * s2)
    f3 = 0.0
    d3 = 0.0
    f4 = 0.0
    d4 = 0.0
    if ti.static(order >= 3 and odd):
        f3 = pv[o3] * c + pv[o3 + 1] * s + pv[o3 + 2] * c3 + pv[o3 + 3] * s3
        d3 = pv[o3 + 1] * c - pv[o3] * s + 3.0 * (pv[o3 + 3] * c3 - pv[o3 + 2] * s3)
    if ti.static(order >= 4):
        f4 = (pv[o4] + pv[o4 + 1] * c2 + pv[o4 + 2] * s2 + pv[o4 + 3] * c4
              + pv[o4 + 4] * s4)
        d4 = (2.0 * (pv[o4 + 2] * c2 - pv[o4 + 1] * s2)
              + 4.0 * (pv[o4 + 4] * c4 - pv[o4 + 3] * s4))
    return f2, d2, f3, d3, f4, d4, c2, s2


@ti.func
def potential(pv, y, order: ti.template(), odd: ti.template(), mpr: ti.template(), i,
              mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
    """V = −U and its derivatives (V, V_r, V_A, V_B) at the state y: the Fourier series
    below for order <= 4, the table-driven order-N potential above (member i's integral
    row ``mpr[i]``, scratch row ``mps[i]``)."""
    if ti.static(order > _MP.HAND_WRITTEN_MAX):
        return potential_n(y, mpr, i, mps, mpi, mpf)
    else:
        return potential_4(pv, y, order, odd)


@ti.func
def potential_n(y, mpr: ti.template(), i, mps: ti.template(), mpi: ti.template(),
                mpf: ti.template()):
    """(V, V_r, V_A, V_B) of the order-N potential (``harmonic_gravity.mutual_h``) in the
    plane: R = r (cos ψ_A, sin ψ_A, 0) in the primary's frame (the stored cosine and sine
    normalised) and S the z-rotation by
    θ_B − θ_A = ψ_A − ψ_B. V_r = −∂U/∂R · R/r, and V_k = −τ_k,z (the torques about z;
    docs/physics.md §5)."""
    r = y[Y_R]
    # the stored (cos, sin) pairs drift off the unit circle at the tolerance level; taken as
    # they are, |R| would be r times that drift and the monopole would feed it back into the
    # orbit (measured: about 30 % more steps); normalised, they are the angles the state means
    nA = 1.0 / ti.sqrt(y[Y_CA] * y[Y_CA] + y[Y_SA] * y[Y_SA])
    nB = 1.0 / ti.sqrt(y[Y_CB] * y[Y_CB] + y[Y_SB] * y[Y_SB])
    cA = y[Y_CA] * nA
    sA = y[Y_SA] * nA
    cB = y[Y_CB] * nB
    sB = y[Y_SB] * nB
    c = cA * cB + sA * sB                      # cos(ψ_A − ψ_B)
    s = sA * cB - cA * sB                      # sin(ψ_A − ψ_B)
    R = ti.Vector([r * cA, r * sA, 0.0], ti.f64)
    S = ti.Matrix([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], ti.f64)
    U, dUdR, mu1, mu2 = mutual_h(mpr, i, mps, i, mpi, mpf, 1.0, R, S)
    return -U, -(dUdR[0] * cA + dUdR[1] * sA), -mu1[2], -mu2[2]


@ti.func
def potential_4(pv, y, order: ti.template(), odd: ti.template()):
    """(V, V_r, V_A, V_B) of the order <= 4 Fourier series."""
    inv_r = 1.0 / y[Y_R]
    mm = pv[P_MM]
    V = mm * inv_r
    Vr = -mm * inv_r * inv_r
    VA = 0.0
    VB = 0.0
    if ti.static(order >= 2):
        f2A, d2A, f3A, d3A, f4A, d4A, c2A, s2A = _series(pv, P_P2, P_P3, P_P4, y[Y_CA], y[Y_SA],
                                                         order, odd)
        f2B, d2B, f3B, d3B, f4B, d4B, c2B, s2B = _series(pv, P_Q2, P_Q3, P_Q4, y[Y_CB], y[Y_SB],
                                                         order, odd)
        inv_r2 = inv_r * inv_r
        inv_r3 = inv_r2 * inv_r
        V += (f2A + f2B) * inv_r3
        Vr -= 3.0 * (f2A + f2B) * inv_r3 * inv_r
        VA += d2A * inv_r3
        VB += d2B * inv_r3
        if ti.static(order >= 3 and odd):
            inv_r4 = inv_r3 * inv_r
            V += (f3A + f3B) * inv_r4
            Vr -= 4.0 * (f3A + f3B) * inv_r4 * inv_r
            VA += d3A * inv_r4
            VB += d3B * inv_r4
        if ti.static(order >= 4):
            x0 = pv[P_X]
            xA = pv[P_X + 1]
            xB = pv[P_X + 2]
            xAB = pv[P_X + 3]
            xm = pv[P_X + 4]
            cm = c2A * c2B + s2A * s2B                 # cos(2ψ_A − 2ψ_B)
            sm = s2A * c2B - c2A * s2B                 # sin(2ψ_A − 2ψ_B)
            X = x0 + xA * c2A + xB * c2B + xAB * c2A * c2B + xm * cm
            XA = -2.0 * (s2A * (xA + xAB * c2B) + xm * sm)
            XB = -2.0 * (s2B * (xB + xAB * c2A) - xm * sm)
            inv_r5 = inv_r3 * inv_r2
            f4 = f4A + f4B + X
            V += f4 * inv_r5
            Vr -= 5.0 * f4 * inv_r5 * inv_r
            VA += (d4A + XA) * inv_r5
            VB += (d4B + XB) * inv_r5
    return V, Vr, VA, VB


@ti.func
def member(p: ti.template(), i):
    """Member i's parameter row as a local vector: read once per launch, not per RHS (the
    loads from a kernel-argument array cannot be hoisted past the record stores)."""
    return ti.Vector([p[i, k] for k in ti.static(range(NPAR))], ti.f64)


@ti.func
def rhs(p: ti.template(), i, y, order: ti.template(), odd: ti.template()):
    """dy/dt of the planar scaled state of member i (G = 1), order <= 4."""
    return rhs_member(member(p, i), y, order, odd)


@ti.func
def rhs_mp(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
           mpr: ti.template(), mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
    """dy/dt of the planar scaled state of member i (G = 1) at any order; ``mpr`` ... ``mpf``
    the order-N integral rows, scratch and tables (not read at order <= 4)."""
    return rhs_member_mp(member(p, i), y, order, odd, mpr, i, mps, mpi, mpf)


@ti.func
def rhs_member(pv, y, order: ti.template(), odd: ti.template()):
    """dy/dt for the parameter vector ``pv`` (:func:`member`), order <= 4."""
    return rhs_member_mp(pv, y, order, odd, pv, 0, pv, pv, pv)


@ti.func
def rhs_member_mp(pv, y, order: ti.template(), odd: ti.template(), mpr: ti.template(), i,
                  mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
    """dy/dt for the parameter vector ``pv`` (:func:`member`) at any order."""
    V, Vr, VA, VB = potential(pv, y, order, odd, mpr, i, mps, mpi, mpf)
    inv_r = 1.0 / y[Y_R]
    ell = y[Y_L]
    lam_dot = ell * inv_r * inv_r
    inv_m = pv[P_INV_M]
    rateA = lam_dot - pv[P_F1] * y[Y_W1]           # dψ_A/dt
    rateB = lam_dot - pv[P_F2] * y[Y_W2]
    dy = state(0.0)
    dy[Y_R] = y[Y_VR]
    dy[Y_VR] = ell * lam_dot * inv_r + inv_m * Vr
    dy[Y_L] = inv_m * (VA + VB)
    dy[Y_LAM] = lam_dot
    dy[Y_CA] = -y[Y_SA] * rateA
    dy[Y_SA] = y[Y_CA] * rateA
    dy[Y_W1] = -VA * pv[P_K1]
    dy[Y_CB] = -y[Y_SB] * rateB
    dy[Y_SB] = y[Y_CB] * rateB
    dy[Y_W2] = -VB * pv[P_K2]
    return dy


@ti.func
def rhs_perturbed(p: ti.template(), i, y, order: ti.template(), odd: ti.template()):
    """:func:`rhs_perturbed_mp` at order <= 4."""
    return rhs_perturbed_mp(p, i, y, order, odd, p, p, p, p, 0.0)


@ti.func
def rhs_perturbed_mp(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
                     mpr: ti.template(), mps: ti.template(), mpi: ti.template(),
                     mpf: ti.template(), t):
    """dy/dt with member i's tides, YORP and BYORP (``kernels/perturb.py``; the block starts
    at column NPAR) in the plane, and the accumulators' rates (work, external torque along
    z; the x and y components stay zero), at the stage's time ``t`` (the Sun moves; a Sun
    out of the orbit plane is the 3-D model's: ``models.choose`` sends its members there)."""
    pv = member(p, i)
    base = rhs_member_mp(pv, y, order, odd, mpr, i, mps, mpi, mpf)
    q = NPAR
    r = y[Y_R]
    vr = y[Y_VR]
    ell = y[Y_L]
    om1 = pv[P_F1] * y[Y_W1]
    om2 = pv[P_F2] * y[Y_W2]
    fr1, ft1 = perturb.tide_polar_of(p, i, q + perturb.Q_TIDE1, r, vr, ell, om1)
    fr2, ft2 = perturb.tide_polar_of(p, i, q + perturb.Q_TIDE2, r, vr, ell, om2)
    Fr = fr1 + fr2
    Ft = ft1 + ft2
    rad = perturb.radiation_factor(p, i, q, t)      # YORP, BYORP at the Sun's distance
    N1 = rad * p[i, q + perturb.Q_YORP1] - r * ft1  # each body takes its own tide's torque
    N2 = rad * p[i, q + perturb.Q_YORP2] - r * ft2
    vt = ell / r
    speed = ti.sqrt(vr * vr + vt * vt)
    fb = rad * p[i, q + perturb.Q_BYORP] / (pv[P_INV_M] * speed)   # m a_B / |V|
    Fr += fb * vr
    Ft += fb * vt
    for c in ti.static(perturb.THIRD_BODIES):   # the Sun, a passing planet
        mu3 = p[i, q + c + perturb.T_MU]
        if mu3 != 0.0:    # its tide in the plane (its orbit's z components are 0)
            nu = p[i, q + c + perturb.T_NU]
            D = perturb.third_body_position(p, i, q + c, t)
            cl = ti.cos(y[Y_LAM])
            sl = ti.sin(y[Y_LAM])
            R3 = ti.Vector([r * cl, r * sl, 0.0], ti.f64)
            a = perturb.solar_acceleration(mu3, D, R3, nu)
            m = 1.0 / pv[P_INV_M]
            Fr += m * (a[0] * cl + a[1] * sl)
            Ft += m * (a[1] * cl - a[0] * sl)
            N1 += perturb.gravity_gradient_torque_z(mu3, D + nu * R3, cl, sl, y[Y_CA], y[Y_SA],
                                                    p[i, q + c + perturb.T_J1])
            N2 += perturb.gravity_gradient_torque_z(mu3, D - (1.0 - nu) * R3, cl, sl, y[Y_CB],
                                                    y[Y_SB], p[i, q + c + perturb.T_J2])
    dy = state_perturbed(0.0)
    for k in ti.static(range(NSTATE)):
        dy[k] = base[k]
    dy[Y_VR] += pv[P_INV_M] * Fr
    dy[Y_L] += pv[P_INV_M] * r * Ft
    dy[Y_W1] += N1 * pv[P_K1]
    dy[Y_W2] += N2 * pv[P_K2]
    dy[NSTATE] = Fr * vr + Ft * vt + N1 * om1 + N2 * om2
    dy[NSTATE + 3] = r * Ft + N1 + N2
    return dy


@ti.func
def pericentre_function(y):
    """g = R·V = r v_r, as in the 3-D model."""
    return y[Y_R] * y[Y_VR]


@ti.func
def pericentre_rate(y, dy):
    return dy[Y_R] * y[Y_VR] + y[Y_R] * dy[Y_VR]


@ti.func
def distance(y):
    return y[Y_R]


@ti.func
def osculating_elements(y):
    """Osculating semimajor axis and eccentricity (scaled units, μ = 1)."""
    ell = y[Y_L]
    inv_r = 1.0 / y[Y_R]
    eps = 0.5 * (y[Y_VR] * y[Y_VR] + ell * ell * inv_r * inv_r) - inv_r
    return -0.5 / eps, ti.sqrt(ti.max(0.0, 1.0 + 2.0 * eps * ell * ell))
