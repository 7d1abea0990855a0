"""Equations of motion of the full two-body problem, Maciejewski (1995) form, in the primary's
body frame (docs/physics.md §4; docs/physics.md §4.1–4.2), and the member parameter layout.

Internal state (30 numbers, scaled units: length = initial osculating semimajor axis a,
time = 1/n, mass = m1 + m2, so G = 1):

    y = [R(3), V(3), w1(3), w2(3), S(9, row-major), S1(9, row-major)]

with V = P/m the relative velocity (P the relative momentum, m the reduced mass),
w1 = Γ1/C1 and w2 = Γ2/C2 the spin angular momenta divided by each body's largest
principal moment. These constant rescalings make every component O(1), so one relative
tolerance controls the secondary's spin (Γ2 ~ 1e-5 in plain scaled units) as tightly as
the orbit. The equations are the docs/physics.md §4.1 ones divided by m, C1, C2:

    dR/dt  = R × Ω1 + V            dV/dt  = V × Ω1 − (∂U/∂R)/m
    dw1/dt = w1 × Ω1 + μ1/C1       dw2/dt = w2 × Ω1 + μ2/C2
    dS/dt  = hat(Ω2 − Ω1) S        dS1/dt = S1 hat(Ω1)

with Ω1 = I1⁻¹ C1 w1 (principal frame), Ω2 = S I2⁻¹ Sᵀ C2 w2 (primary frame). The form
dS/dt = hat(Ω2 − Ω1) S equals S hat(Ω2') − hat(Ω1) S because S hat(x) Sᵀ = hat(S x).
"""

import taichi as ti

from ti_spinorbit.layout import multipole as _MP, spatial as _L

from . import perturb
from .harmonic_gravity import mutual_h
from .mutual_gravity import mat_t_vec, mat_vec, mutual, vec3, mat3

# The state offsets and the member parameter row (two body rows, then derived constants,
# scaled units) are ti_spinorbit.layout's, shared with the host.
NSTATE = _L.NSTATE
Y_R, Y_V, Y_W1, Y_W2, Y_S, Y_S1 = _L.Y_R, _L.Y_V, _L.Y_W1, _L.Y_W2, _L.Y_S, _L.Y_S1
BODY_A, BODY_B = _L.BODY_A, _L.BODY_B
P_MRED, P_C1, P_C2, P_IA, P_IB = _L.P_MRED, _L.P_C1, _L.P_C2, _L.P_IA, _L.P_IB
P_CONTACT, P_ESCAPE, NPAR = _L.P_CONTACT, _L.P_ESCAPE, _L.NPAR
state = ti.types.vector(NSTATE, ti.f64)
#: State with the perturbation accumulators (W, L_ext) appended (``perturb.NACC``).
state_perturbed = ti.types.vector(NSTATE + perturb.NACC, ti.f64)


@ti.func
def get3(y, o: ti.template()):
    return vec3(y[o], y[o + 1], y[o + 2])


@ti.func
def get33(y, o: ti.template()):
    return mat3([[y[o], y[o + 1], y[o + 2]], [y[o + 3], y[o + 4], y[o + 5]],
                 [y[o + 6], y[o + 7], y[o + 8]]])


@ti.func
def put3(y: ti.template(), o: ti.template(), v):
    for k in ti.static(range(3)):
        y[o + k] = v[k]


@ti.func
def angular_velocities(p: ti.template(), i, y):
    """Ω1 (primary frame = its body frame) and Ω2 (secondary's, primary-frame components)."""
    w1 = get3(y, Y_W1)
    w2 = get3(y, Y_W2)
    S = get33(y, Y_S)
    om1 = vec3(p[i, P_IA] * w1[0], p[i, P_IA + 1] * w1[1], p[i, P_IA + 2] * w1[2])
    w2b = mat_t_vec(S, w2)
    om2 = mat_vec(S, vec3(p[i, P_IB] * w2b[0], p[i, P_IB + 1] * w2b[1], p[i, P_IB + 2] * w2b[2]))
    return om1, om2


@ti.func
def gravity(p: ti.template(), i, k, G, R, S, order: ti.template(), odd: ti.template(),
            mpr: ti.template(), mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
    """U, ∂U/∂R, μ1, μ2 of member i (frame A): the hand-written formulas of
    ``mutual_gravity.py`` for order <= 4 (the code as it always was), the table-driven ones
    of ``harmonic_gravity.py`` above (``order`` is then ``layout.multipole.KERNEL_ORDER``
    and the tables ``mpi``, ``mpf`` hold the true order; member i's coefficient row is
    ``mpr[i]``, the scratch row ``mps[k]``)."""
    if ti.static(order > _MP.HAND_WRITTEN_MAX):
        return mutual_h(mpr, i, mps, k, mpi, mpf, G, R, S)
    else:
        return mutual(p, i, BODY_A, BODY_B, G, R, S, order, odd)


@ti.func
def rhs(p: ti.template(), i, y, order: ti.template(), odd: ti.template()):
    """dy/dt of the scaled state of member i (G = 1), order <= 4."""
    return rhs_mp(p, i, y, order, odd, p, p, p, p)


@ti.func
def rhs_mp(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
           mpr: ti.template(), mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
    """dy/dt of the scaled state of member i (G = 1) at any order: ``mpr`` ... ``mpf`` the
    order-N integral rows, scratch and tables (:func:`gravity`; not read at order <= 4,
    where any array may stand in for them)."""
    dy, om1, om2 = _rhs_and_rates(p, i, y, order, odd, mpr, mps, mpi, mpf)
    return dy


@ti.func
def _rhs_and_rates(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
                   mpr: ti.template(), mps: ti.template(), mpi: ti.template(),
                   mpf: ti.template()):
    """dy/dt and the two angular velocities Ω1, Ω2 it used (primary frame), so that the
    perturbed RHS does not compute them again."""
    R = get3(y, Y_R)
    V = get3(y, Y_V)
    w1 = get3(y, Y_W1)
    w2 = get3(y, Y_W2)
    S = get33(y, Y_S)
    om1, om2 = angular_velocities(p, i, y)
    U, dUdR, mu1, mu2 = gravity(p, i, i, 1.0, R, S, order, odd, mpr, mps, mpi, mpf)
    dy = state(0.0)
    put3(dy, Y_R, R.cross(om1) + V)
    put3(dy, Y_V, V.cross(om1) - dUdR / p[i, P_MRED])
    put3(dy, Y_W1, w1.cross(om1) + mu1 / p[i, P_C1])
    put3(dy, Y_W2, w2.cross(om1) + mu2 / p[i, P_C2])
    dom = om2 - om1
    for c in ti.static(range(3)):  # columns of S: d s_c/dt = (Ω2 − Ω1) × s_c
        col = dom.cross(vec3(S[0, c], S[1, c], S[2, c]))
        for r in ti.static(range(3)):
            dy[Y_S + 3 * r + c] = col[r]
    for r in ti.static(range(3)):  # rows of S1: d r/dt = r × Ω1
        put3(dy, Y_S1 + 3 * r, get3(y, Y_S1 + 3 * r).cross(om1))
    return dy, om1, om2


@ti.func
def rhs_perturbed(p: ti.template(), i, y, order: ti.template(), odd: ti.template()):
    """:func:`rhs_perturbed_mp` at order <= 4."""
    return rhs_perturbed_mp(p, i, y, order, odd, p, p, p, p, 0.0)


@ti.func
def rhs_perturbed_mp(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
                     mpr: ti.template(), mps: ti.template(), mpi: ti.template(),
                     mpf: ti.template(), t):
    """dy/dt with the tides, YORP, BYORP and the third bodies' tides of member i's perturbation block
    (columns from NPAR, ``kernels/perturb.py``) at the scaled time ``t`` (the Sun moves), and
    the accumulators' rates: work and external torque."""
    base, om1, om2 = _rhs_and_rates(p, i, y, order, odd, mpr, mps, mpi, mpf)
    R = get3(y, Y_R)
    V = get3(y, Y_V)
    S = get33(y, Y_S)
    q = NPAR
    f1 = perturb.tide_of(p, i, q + perturb.Q_TIDE1, R, V, om1)
    f2 = perturb.tide_of(p, i, q + perturb.Q_TIDE2, R, V, om2)
    F = f1 + f2
    # YORP about each body's z axis; each body takes its own tide's torque
    rad = perturb.radiation_factor(p, i, q, t)      # YORP, BYORP at the Sun's distance
    N1 = vec3(0.0, 0.0, rad * p[i, q + perturb.Q_YORP1]) - R.cross(f1)
    N2 = (rad * p[i, q + perturb.Q_YORP2]) * vec3(S[0, 2], S[1, 2], S[2, 2]) - R.cross(f2)
    m = p[i, P_MRED]
    F += (m * rad * p[i, q + perturb.Q_BYORP] / V.norm()) * V
    for c in ti.static(perturb.THIRD_BODIES):   # the Sun, a passing planet
        mu3 = p[i, q + c + perturb.T_MU]
        if mu3 != 0.0:    # its tide and its torques on both bodies (frame A)
            nu = p[i, q + c + perturb.T_NU]
            D = mat_t_vec(get33(y, Y_S1), perturb.third_body_position(p, i, q + c, t))
            F += m * perturb.solar_acceleration(mu3, D, R, nu)
            N1 += perturb.gravity_gradient_torque(
                mu3, D + nu * R, vec3(p[i, BODY_A + 1], p[i, BODY_A + 2], p[i, BODY_A + 3]))
            N2 += mat_vec(S, perturb.gravity_gradient_torque(
                mu3, mat_t_vec(S, D - (1.0 - nu) * R),
                vec3(p[i, BODY_B + 1], p[i, BODY_B + 2], p[i, BODY_B + 3])))
    dy = state_perturbed(0.0)
    for k in ti.static(range(NSTATE)):
        dy[k] = base[k]
    put3(dy, Y_V, get3(base, Y_V) + F / m)
    put3(dy, Y_W1, get3(base, Y_W1) + N1 / p[i, P_C1])
    put3(dy, Y_W2, get3(base, Y_W2) + N2 / p[i, P_C2])
    dy[NSTATE] = F.dot(V) + N1.dot(om1) + N2.dot(om2)
    put3(dy, NSTATE + 1, mat_vec(get33(y, Y_S1), R.cross(F) + N1 + N2))
    return dy


@ti.func
def pericentre_function(y):
    """g = R·V: negative before, positive after a pericentre passage (osculating f = 0)."""
    return get3(y, Y_R).dot(get3(y, Y_V))


@ti.func
def pericentre_rate(y, dy):
    """dg/dt = dR/dt·V + R·dV/dt (frame terms cancel: R·(R×Ω1) = 0, V·(V×Ω1) = 0)."""
    return get3(dy, Y_R).dot(get3(y, Y_V)) + get3(y, Y_R).dot(get3(dy, Y_V))


@ti.func
def distance(y):
    return get3(y, Y_R).norm()


@ti.func
def osculating_elements(y):
    """Osculating semimajor axis and eccentricity (scaled units, μ = G(m1+m2) = 1)."""
    R = get3(y, Y_R)
    V = get3(y, Y_V)
    eps = 0.5 * V.dot(V) - 1.0 / R.norm()
    h2 = R.cross(V).norm_sqr()
    return -0.5 / eps, ti.sqrt(ti.max(0.0, 1.0 + 2.0 * eps * h2))


@ti.func
def energy_split(p: ti.template(), i, y, order: ti.template(), odd: ti.template()):
    """:func:`energy_split_mp` at order <= 4."""
    return energy_split_mp(p, i, y, order, odd, p, p, i, p, p)


@ti.func
def energy_split_mp(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
                    mpr: ti.template(), mps: ti.template(), k, mpi: ti.template(),
                    mpf: ti.template()):
    """(orbit, primary spin, secondary spin) energies, scaled units: orbit = |P|²/2m + U
    (at any order; the order-N scratch row ``k``)."""
    R = get3(y, Y_R)
    V = get3(y, Y_V)
    S = get33(y, Y_S)
    om1, om2 = angular_velocities(p, i, y)
    U, dUdR, mu1, mu2 = gravity(p, i, k, 1.0, R, S, order, odd, mpr, mps, mpi, mpf)
    e_orb = 0.5 * p[i, P_MRED] * V.dot(V) + U
    e1 = 0.5 * p[i, P_C1] * get3(y, Y_W1).dot(om1)
    e2 = 0.5 * p[i, P_C2] * get3(y, Y_W2).dot(om2)
    return e_orb, e1, e2


@ti.func
def angular_momentum_split(p: ti.template(), i, y):
    """Inertial-frame (orbit, primary spin, secondary spin) angular momenta, scaled units."""
    S1 = get33(y, Y_S1)
    R = get3(y, Y_R)
    V = get3(y, Y_V)
    l_orb = S1 @ (p[i, P_MRED] * R.cross(V))
    l1 = S1 @ (p[i, P_C1] * get3(y, Y_W1))
    l2 = S1 @ (p[i, P_C2] * get3(y, Y_W2))
    return l_orb, l1, l2


@ti.func
def orthonormality_error(y):
    """max |SᵀS − 1| and max |S1ᵀS1 − 1| (should stay at the tolerance level)."""
    S = get33(y, Y_S)
    S1 = get33(y, Y_S1)
    d = S.transpose() @ S - ti.Matrix.identity(ti.f64, 3)
    d1 = S1.transpose() @ S1 - ti.Matrix.identity(ti.f64, 3)
    m = 0.0
    m1 = 0.0
    for r in ti.static(range(3)):
        for c in ti.static(range(3)):
            m = ti.max(m, ti.abs(d[r, c]))
            m1 = ti.max(m1, ti.abs(d1[r, c]))
    return m, m1
