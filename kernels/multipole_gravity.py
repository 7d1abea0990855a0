"""Mutual potential, force and torques of two rigid bodies at any truncation order (Taichi),
table-driven, in Cartesian form: the kernels' independent check.

The integrators evaluate the order-N potential in real solid harmonics
(``harmonic_gravity.py``, docs/physics.md §3.8.2), which costs a fraction of this form's work
at every order above 4; this Cartesian kernel stays, tested against the host reference to
1e-13 (tests/test_kernel_multipole.py), as a second formulation in Taichi to hold the
harmonic one to, and as the baseline of experiments/bench_harmonics.py. Its arguments come
from ``multipole_tables.Multipole.cartesian_arguments``.

The formulation and the tables are those of ``ti_spinorbit.engine.multipole_tables`` (its
module docstring; docs/physics.md §3.8.1): the Cartesian multipole–multipole expansion

    U_N = −G Σ_{|α|+|β| ≤ N} t̂_A^α t̂_B'^β D_{α+β}(R),   D_γ = ∂^γ(1/|R|),

with the primary's terms and the mixed terms gathered into combined moments W_γ, the
secondary-only terms evaluated in the secondary's own frame, and the secondary's integrals
rotated into the primary's frame only up to the degree the mixed terms need.

Why tables and runtime loops. The order-4 kernels (``mutual_gravity.py``) unroll every term
at compile time; at order 8 that would be about 2 000 mixed terms and 400 derivative
entries, and Taichi's compile time grows faster than the code (docs/design.md, "Compile
time"). Here every loop runs over a table at run time, so the code is the same small loop
nest at every order: one compiled kernel serves every order above 4 (the kernels take
``layout.multipole.KERNEL_ORDER`` as their ``order`` template argument for all of them), and
what changes with the order, the degree caps or the odd terms is data (the integer and float
tables, built once per configuration on the host). Every member walks the same tables in
the same order: no thread divergence on a GPU.

Per-member data, passed as arguments of the kernels beside the parameter rows:

* ``rows`` (members × width): both bodies' integrals in their own frames
  (``multipole_tables.integral_rows``), row ``j`` for member j;
* ``scr`` (slots × scratch): per-slot scratch (D at R and at R_B, W, the normalised primary
  and rotated secondary integrals, the two rotation buffers), row ``k`` for the thread's slot
  (the member in the integrator, the state in the diagnostics);
* ``tab_i`` (int32) and ``tab_f`` (float64): the tables, with the header of
  ``ti_spinorbit.layout.multipole`` at the start of ``tab_i``.

Conventions as in ``mutual_gravity.py`` (primary frame A; R from A's centre of mass to B's; S
maps B-frame vectors into A; ``dUdR`` = ∂U/∂R; mu2 the torque on B, mu1 on A).
"""

import taichi as ti

from ti_spinorbit.layout import multipole as _H

from .mutual_gravity import make_evaluate, mat_t_vec, mat_vec, vec3


@ti.func
def _count(d):
    """Multi-indices of degree <= d (0 for d < 0), integer arithmetic."""
    return (d + 1) * (d + 2) * (d + 3) // 6


@ti.func
def _derivatives(scr: ti.template(), k, base, top, tab_i: ti.template(), tab_f: ti.template(),
                 R, inv_r, inv_r2):
    """D_γ = ∂^γ(1/|R|) for every |γ| <= ``top``, into scr[k, base + γ]. Per degree d, the
    2d + 1 entries with z exponent <= 1 from the two-term recurrence (five terms: the
    z second-order one vanishes there), the others from harmonicity,
    D_(l,m,n) = −D_(l+2,m,n−2) − D_(l,m+2,n−2) (∇²(1/r) = 0: two loads, no recurrence), in
    order of increasing n; indices and weights from the tables."""
    scr[k, base] = inv_r
    oi = tab_i[_H.H_I_D]
    of = tab_i[_H.H_F_D]
    oh = tab_i[_H.H_I_DH]
    rec = 0
    har = 0
    for d in range(1, top + 1):
        for e in range(rec, rec + 2 * d + 1):
            t = oi + 6 * e
            f = of + 5 * e
            s = (tab_f[f] * R[0] * scr[k, base + tab_i[t + 1]]
                 + tab_f[f + 1] * R[1] * scr[k, base + tab_i[t + 2]]
                 + tab_f[f + 2] * R[2] * scr[k, base + tab_i[t + 3]]
                 + tab_f[f + 3] * scr[k, base + tab_i[t + 4]]
                 + tab_f[f + 4] * scr[k, base + tab_i[t + 5]])
            scr[k, base + tab_i[t]] = -inv_r2 * s
        rec += 2 * d + 1
        for e in range(har, har + d * (d - 1) // 2):
            t = oh + 3 * e
            scr[k, base + tab_i[t]] = -scr[k, base + tab_i[t + 1]] - scr[k, base + tab_i[t + 2]]
        har += d * (d - 1) // 2


@ti.func
def _rotate_secondary(rows: ti.template(), j, wA, scr: ti.template(), k, tab_i: ti.template(),
                      tab_f: ti.template(), S):
    """The secondary's integrals of degrees 2..KR carried into the primary's frame,
    T'^β = ∫ (S x)^β dm, by the exact recurrence P_{p+1}[β'+e_i][δ] = Σ_j S_ij P_p[β'][δ+e_j]
    (P_p[β'][δ] = ∫ (S x)^{β'} x^δ dm), then normalised by 1/β! in scr[k, TB + β].

    Every stage of every degree is one entry list, walked in one flat loop: an entry names
    its output, its three inputs and 3 × the axis it peels (the row of S, copied into the
    scratch first), all as scratch offsets (``multipole_tables``), so no short loop nest
    runs and no index is computed here."""
    KR = tab_i[_H.H_KR]
    sP = tab_i[_H.H_S_P]
    sS = tab_i[_H.H_S_S]
    tb = tab_i[_H.H_S_TB]
    for r in ti.static(range(3)):
        for c in ti.static(range(3)):
            scr[k, sS + 3 * r + c] = S[r, c]
    for q in range(4, _count(KR)):                 # the copy: degrees 2..KR
        scr[k, sP + q] = rows[j, wA + q]
    rot = tab_i[_H.H_I_ROT]
    for e in range(tab_i[_H.H_NROT]):
        t = rot + 5 * e
        a = sS + tab_i[t + 4]
        scr[k, tab_i[t]] = (scr[k, a] * scr[k, tab_i[t + 1]] + scr[k, a + 1] * scr[k, tab_i[t + 2]]
                            + scr[k, a + 2] * scr[k, tab_i[t + 3]])
    frot = tab_i[_H.H_F_ROT]
    for q in range(4, _count(KR)):
        scr[k, tb + q] *= tab_f[frot + q]


@ti.func
def mutual_n(rows: ti.template(), j, scr: ti.template(), k, tab_i: ti.template(),
             tab_f: ti.template(), G, R, S):
    """Mutual potential U, gradient dU/dR, torque on A (mu1) and on B (mu2), frame A, at the
    order, degree caps and odd terms the tables were built for; member j's integrals
    (``rows[j]``), slot k's scratch (``scr[k]``)."""
    wA = tab_i[_H.H_WIDTH_A]
    sD = tab_i[_H.H_S_D]
    sDB = tab_i[_H.H_S_DB]
    sW = tab_i[_H.H_S_W]
    sTA = tab_i[_H.H_S_TA]
    sTB = tab_i[_H.H_S_TB]
    mA = rows[j, 0]
    mB = rows[j, wA]
    r2 = R.dot(R)
    inv_r2 = 1.0 / r2
    inv_r = ti.sqrt(inv_r2)
    # derivatives of 1/r at R (primary frame) and at R_B = Sᵀ R (secondary frame)
    _derivatives(scr, k, sD, tab_i[_H.H_TOP_D], tab_i, tab_f, R, inv_r, inv_r2)
    RB = mat_t_vec(S, R)
    _derivatives(scr, k, sDB, tab_i[_H.H_TOP_DB], tab_i, tab_f, RB, inv_r, inv_r2)
    # combined moments W: the monopole, then the primary-only terms
    for g in range(tab_i[_H.H_NW]):
        scr[k, sW + g] = 0.0
    scr[k, sW] = mA * mB
    oa = tab_i[_H.H_I_A]
    fa = tab_i[_H.H_F_A]
    for a in range(tab_i[_H.H_NA]):
        q = tab_i[oa + a]
        t = tab_f[fa + a] * rows[j, q]
        scr[k, sTA + q] = t
        scr[k, sW + q] += mB * t
    # secondary-only terms in the secondary's frame: value and gradient (frame B)
    ob = tab_i[_H.H_I_B]
    fb = tab_i[_H.H_F_B]
    uB = 0.0
    gB = vec3(0.0)
    for b in range(tab_i[_H.H_NB]):
        o = ob + 4 * b
        q = tab_i[o]
        t = tab_f[fb + b] * rows[j, wA + q]
        uB += t * scr[k, sDB + q]
        gB += t * vec3(scr[k, sDB + tab_i[o + 1]], scr[k, sDB + tab_i[o + 2]],
                       scr[k, sDB + tab_i[o + 3]])
    # mixed terms: the secondary rotated into frame A, then the pairs by β
    _rotate_secondary(rows, j, wA, scr, k, tab_i, tab_f, S)
    obeta = tab_i[_H.H_I_BETA]
    fbeta = tab_i[_H.H_F_BETA]
    opair = tab_i[_H.H_I_PAIR]
    tau = vec3(0.0)
    for bi in range(tab_i[_H.H_NBETA]):
        o = obeta + 9 * bi
        f = fbeta + 6 * bi
        tb = scr[k, sTB + tab_i[o]]
        acc = 0.0
        for pk in range(tab_i[o + 1], tab_i[o + 2]):
            ia = tab_i[opair + 2 * pk]
            ig = tab_i[opair + 2 * pk + 1]
            ta = scr[k, sTA + ia]
            acc += ta * scr[k, sD + ig]
            scr[k, sW + ig] += ta * tb
        tau += acc * vec3(tab_f[f] * scr[k, sTB + tab_i[o + 3]] + tab_f[f + 1] * scr[k, sTB + tab_i[o + 4]],
                          tab_f[f + 2] * scr[k, sTB + tab_i[o + 5]] + tab_f[f + 3] * scr[k, sTB + tab_i[o + 6]],
                          tab_f[f + 4] * scr[k, sTB + tab_i[o + 7]] + tab_f[f + 5] * scr[k, sTB + tab_i[o + 8]])
    # energy and force from W
    og = tab_i[_H.H_I_GAM]
    uW = 0.0
    gW = vec3(0.0)
    for gi in range(tab_i[_H.H_NGAM]):
        o = og + 4 * gi
        w = scr[k, sW + tab_i[o]]
        uW += w * scr[k, sD + tab_i[o]]
        gW += w * vec3(scr[k, sD + tab_i[o + 1]], scr[k, sD + tab_i[o + 2]],
                       scr[k, sD + tab_i[o + 3]])
    gBA = mat_vec(S, gB)
    dUdR = -G * (gW + mA * gBA)
    mu2 = G * tau + R.cross(-G * mA * gBA)
    mu1 = R.cross(dUdR) - mu2
    return -G * (uW + mA * uB), dUdR, mu1, mu2


#: The order-N potential for each row i (member i's integrals, R_nd[i], S_nd[i]):
#: out = [U, dU/dR (3), mu1 (3), mu2 (3)], scratch row i (``mutual_gravity.make_evaluate``).
evaluate_multipole = make_evaluate(mutual_n)
