"""The layouts the kernels and the host share: state offsets, parameter columns, the
perturbation block, record widths and status codes, in one place and without Taichi.

The kernels (``kernels/eom.py``, ``kernels/planar_eom.py``, ``kernels/perturb.py``,
``kernels/advance.py``) take their offsets from here, and so does every host module that
reads a state or a parameter row (cost estimates, shadow directions, observables), so a
layout is written once and nothing has to be kept in step by hand.

**3-D model** (``kernels/eom.py``; docs/physics.md §4): the 30-number scaled state

    y = [R(3), V(3), w1(3), w2(3), S(9, row-major), S1(9, row-major)]

(length a, time 1/n, mass m1 + m2; w = Γ/C), and a parameter row of the two bodies' rows
(ROW_LENGTH each: the mass, then the inertia integrals T^{lmn} in the orders EXPONENTS_2,
EXPONENTS_3, EXPONENTS_4, :meth:`ti_spinorbit.system.bodies.Body.as_row`) followed by the derived
constants P_MRED ... P_ESCAPE.

**Planar model** (``kernels/planar_eom.py``; docs/physics.md §5): the 10-number state
[r, v_r, ℓ, λ, cos ψ_A, sin ψ_A, w1, cos ψ_B, sin ψ_B, w2] and a 37-column row of Fourier
coefficients of the mutual potential (``ti_spinorbit.model.planar.parameter_rows``).

**Perturbations** (``kernels/perturb.py``; docs/physics.md §13): a block of NPERT columns after
a model's row, and NACC accumulators (work W, external angular momentum L_ext) after its state.

**Records**: one row per event or sample, the time and then the 3-D state (RECORD_WIDTH);
planar records are converted to it on the host.

**Statuses**: the codes in every ``status`` array, archive and checkpoint
(:class:`ti_spinorbit.engine.results.Status` names them). Codes are never renumbered: files hold
them.
"""

# A body's row: mass, then T^{lmn} in these fixed orders (kernels/mutual_gravity.py unrolls
# them).
EXPONENTS_2 = ((2, 0, 0), (0, 2, 0), (0, 0, 2))
EXPONENTS_3 = tuple((l, m, 3 - l - m) for l in range(3, -1, -1) for m in range(3 - l, -1, -1))
EXPONENTS_4 = tuple((l, m, 4 - l - m) for l in range(4, -1, -1) for m in range(4 - l, -1, -1))
#: Length of a body's row: mass, 3 second-order, 10 third-order, 15 fourth-order integrals.
ROW_LENGTH = 1 + len(EXPONENTS_2) + len(EXPONENTS_3) + len(EXPONENTS_4)


class spatial:
    """The 3-D model's state offsets and parameter columns (``kernels/eom.py``)."""

    NSTATE = 30
    Y_R, Y_V, Y_W1, Y_W2, Y_S, Y_S1 = 0, 3, 6, 9, 12, 21
    BODY_A = 0                       # the primary's body row
    BODY_B = ROW_LENGTH              # the secondary's
    P_MRED = 2 * ROW_LENGTH          # reduced mass m1 m2 / (m1 + m2)
    P_C1 = P_MRED + 1                # largest principal moment of the primary
    P_C2 = P_MRED + 2                # largest principal moment of the secondary
    P_IA = P_MRED + 3                # C1 / (A1, B1, C1)
    P_IB = P_MRED + 6                # C2 / (A2, B2, C2)
    P_CONTACT = P_MRED + 9           # sum of bounding radii: collision below this distance
    P_ESCAPE = P_MRED + 10           # escape beyond this distance
    NPAR = P_MRED + 11


class planar:
    """The planar model's state offsets and parameter columns (``kernels/planar_eom.py``)."""

    NSTATE = 10
    Y_R, Y_VR, Y_L, Y_LAM, Y_CA, Y_SA, Y_W1, Y_CB, Y_SB, Y_W2 = range(10)
    P_MM = 0                         # mA mB
    P_INV_M = 1                      # 1 / reduced mass
    P_K1, P_F1 = 2, 3                # 1/C1 (torque -> dw1/dt), C1/I1zz (w1 -> ω1)
    P_K2, P_F2 = 4, 5
    P_P2, P_Q2 = 6, 9                # (a0, a2, b2)
    P_P3, P_Q3 = 12, 16              # (a1, b1, a3, b3)
    P_P4, P_Q4 = 20, 25              # (a0, a2, b2, a4, b4)
    P_X = 30                         # (x0, xA, xB, xAB, xm)
    P_CONTACT = 35
    P_ESCAPE = 36
    NPAR = 37


class multipole:
    """The order-N mutual potential's Cartesian tables (``ti_spinorbit.engine.multipole_tables``,
    ``kernels/multipole_gravity.py``, the kernels' independent check; the integrators use
    :class:`harmonic`'s): the positions of the header at the start of the integer table. Every other position (table sections, per-member scratch offsets) is read
    from this header at run time, so the kernels hold no size of their own."""

    #: Highest truncation order the tables and the kernels accept (the host reference's).
    MAX_ORDER = 16
    #: Orders up to this one use the hand-written kernels (``kernels/mutual_gravity.py``);
    #: above it the table-driven ones. The kernels are compiled once for every order above
    #: it: ``KERNEL_ORDER`` is the template value they take for all of them.
    HAND_WRITTEN_MAX = 4
    KERNEL_ORDER = 5
    (H_WIDTH_A,            # columns of the primary in a member's integral row: C(dA + 3, 3)
     H_TOP_D,              # top degree of D = ∂^γ(1/r) at R: N + 1
     H_TOP_DB,             # top degree of D at the secondary's frame R_B = Sᵀ R (0: none)
     H_NW,                 # entries of the combined moments W_γ: C(N + 3, 3)
     H_KR,                 # top degree of the rotated secondary integrals (< 2: none)
     H_NA,                 # primary terms (normalised primary integrals)
     H_NB,                 # secondary-only terms
     H_NBETA,              # secondary multi-indices β of the mixed terms
     H_NGAM,               # entries of the energy and force sum over W
     H_NROT,               # entries of the rotation recurrence (all stages, in order)
     H_I_D, H_I_DH, H_I_A, H_I_B, H_I_ROT, H_I_BETA, H_I_PAIR, H_I_GAM,   # integer table
     H_F_D, H_F_A, H_F_B, H_F_ROT, H_F_BETA,                      # sections, float table
     H_S_D, H_S_DB, H_S_W, H_S_TA, H_S_TB, H_S_P, H_S_S,          # scratch offsets
     H_SCRATCH,            # scratch columns per member
     NHEAD) = range(32)


class harmonic:
    """The order-N potential in harmonics (``ti_spinorbit.engine.harmonic_tables``,
    ``kernels/harmonic_gravity.py``): the positions of the header at the start of its integer
    table. Every size, list and per-member scratch offset is read from it at run time, so one
    compiled kernel serves every order, degree cap and degree mask.

    Within a degree l the 2l + 1 coefficients are stored by class: m = 0, 2, 4, ... (cos,
    even), m = 1, 3, ... (cos, odd), m = −2, −4, ... (sin, even), m = −1, −3, ... (sin, odd);
    every J_l then maps each class to one class as a dense block. The host turns the whole
    evaluation into flat lists (a program per body), so the kernel is a few flat loops."""

    (K_NPOW,               # powers −G r^−(L+1) tabulated, L = 0..N
     K_TOP,                # max(dA, dB, 1): the largest degree (the scratch buffers' size)
     K_NTERM, K_I_TERM, K_F_TERM,   # the interaction terms: (ia, ib, L) and K
     K_NBZ, K_I_BZ,        # the secondary's z-torque pairs: (g+, g−, m)
     K_S_A, K_S_B, K_S_GA, K_S_GB, K_S_T1, K_S_T2, K_S_W,   # scratch offsets
                           # (K_S_T1: the primary's first buffer, the secondary's after it)
     K_SCRATCH,            # scratch columns per member
     K_WIDTH,              # columns of a coefficient row: (dA + 1)² + (dB + 1)²
     K_TWO,                # 2: the kernel's loop counts and steps (2 and 2 − 1) read at
                           # run time, so that LLVM does not copy or unroll its loops
     K_PROG_A) = range(18)  # the primary's program; the secondary's PROGRAM_WIDTH after
    # fields of a body's program: count and integer offset of each list (load pairs
    # (p, q, m); J rows (dst, src, columns, value offset); pairs (p, q, m) on the J output;
    # Jᵀ rows; pairs on the final coefficients; the rows its torque reads: (row, the
    # generators' columns about x, about y)), the float offsets of the J rows', the Jᵀ rows'
    # and the torque rows' weights, then its row offset, its scratch regions (coefficients, ∂U/∂C, its own first buffer:
    # entries a program never writes stay zero) and angle slots (−1: none)
    (P_NLOAD, P_LOAD, P_NJ, P_J, P_NJX, P_JX, P_NJT, P_JT, P_NJTX, P_JTX, P_NROW, P_ROW,
     P_FJ, P_FJX, P_FJT, P_FJTX, P_FROW, P_SRC, P_DST, P_ACC, P_T1, P_Z0, P_Z1, P_Z2,
     PROGRAM_WIDTH) = range(25)
    K_PROG_B = K_PROG_A + PROGRAM_WIDTH
    KHEAD = K_PROG_B + PROGRAM_WIDTH


class perturbation:
    """Columns of the perturbation block, relative to its start (a model's NPAR)."""

    Q_TIDE1 = 0        # tide on the primary: κ, Δt, 1/(2Q) (0: constant time lag)
    Q_TIDE2 = 3        # tide on the secondary
    Q_YORP1 = 6        # YORP torque on the primary, about its z axis
    Q_YORP2 = 7        # on the secondary
    Q_BYORP = 8        # BYORP acceleration of the relative motion along V
    # Third bodies, one slot each: the Sun (SolarTide) and a passing planet (Flyby). A slot
    # holds μ = G M × strength (0: none), then the body's conic orbit relative to the
    # barycentre: a (its magnitude for a hyperbola), e (< 1 ellipse, > 1 hyperbola), mean
    # motion, mean anomaly at t = 0, the unit vectors P and Q (the body at x P + y Q of its
    # conic, inertial frame), ν = m2 / (m1 + m2), and each body's J_xx − J_yy = B − A (the
    # planar model's torques). Offsets within a slot:
    T_MU, T_A, T_E, T_N, T_M0, T_P, T_Q, T_NU, T_J1, T_J2 = 0, 1, 2, 3, 4, 5, 8, 11, 12, 13
    NTHIRD = 14
    Q_SUN = 9
    Q_FLYBY = Q_SUN + NTHIRD
    THIRD_BODIES = (Q_SUN, Q_FLYBY)
    Q_SUN_A, Q_SUN_E, Q_SUN_N, Q_SUN_M0 = Q_SUN + T_A, Q_SUN + T_E, Q_SUN + T_N, Q_SUN + T_M0
    Q_SUN_P, Q_SUN_Q, Q_SUN_NU = Q_SUN + T_P, Q_SUN + T_Q, Q_SUN + T_NU
    Q_SUN_J1, Q_SUN_J2 = Q_SUN + T_J1, Q_SUN + T_J2
    # YORP and BYORP at the Sun's distance of the moment: a⊙² sqrt(1 − e⊙²) (scaled), the
    # factor that turns their mean-distance values into (a⊙² sqrt(1 − e⊙²)) / d(t)² of the
    # Sun slot's orbit; 0: the mean-distance form
    Q_RAD = Q_FLYBY + NTHIRD
    NPERT = Q_RAD + 1
    NACC = 4           # accumulators after the state: W, then L_ext (x, y, z)
    #: Floor of the bulge's relative angular rate in the constant-Q lag (units of n).
    Q_RATE_FLOOR = 1e-3


#: Columns of a 3-D event or sample record: the scaled time, then the 30-number state.
RECORD_WIDTH = 1 + spatial.NSTATE

#: Status codes (``ti_spinorbit.engine.results.Status``): the kernels set RUNNING ... NONFINITE and
#: STEP_BUDGET; the host's accuracy check sets INACCURATE and, for the mutual potential's
#: truncation error, TRUNCATED (codes are only ever appended: files hold them).
(RUNNING, DONE, COLLISION, ESCAPE, STEP_UNDERFLOW, NONFINITE, INACCURATE, STEP_BUDGET,
 TRUNCATED) = range(9)
STATUS_NAMES = ("running", "done", "collision", "escape", "step underflow", "non-finite",
                "inaccurate", "step budget", "truncated")

#: Counter columns of every member: accepted steps, rejected steps, right-hand-side calls.
C_ACCEPTED, C_REJECTED, C_RHS = 0, 1, 2

#: The diagnostics' columns (``kernels/advance.py`` ``diagnostics``): three energies, the
#: orbit's, the primary's and the secondary's angular-momentum vectors, orthonormality errors.
DIAG_FIELDS = ("E_orbit", "E_primary", "E_secondary",
               "L_orbit_x", "L_orbit_y", "L_orbit_z", "L_primary_x", "L_primary_y",
               "L_primary_z", "L_secondary_x", "L_secondary_y", "L_secondary_z",
               "orth_S", "orth_S1")
