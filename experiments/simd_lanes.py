"""SIMD lanes: several ensemble members per CPU thread as vector lanes, against
today's one member per thread, on the planar right-hand side of 1991 VH (a/b = 1.5).

Benchmark-only prototype: the package kernels are not changed. Three layouts of the same work
(every member evaluates the planar RHS ``repeats`` times in a dependent chain):

scalar
    today's layout: one member per loop iteration (per thread task), state and parameters
    of member i from (N, 10) and (N, 37) arrays, ``kernels/planar_eom.rhs_member``.
unrolled L
    structure of arrays, (10, N) and (37, N), so that L consecutive members are contiguous;
    one loop iteration takes L members and runs the package's scalar ``rhs_member`` on each,
    interleaved in one loop body (``ti.static`` unrolled), leaving it to LLVM's SLP
    vectoriser to pack the L independent copies into vector instructions.
lanes L
    the same layout, with an RHS written here over ``ti.types.vector(L, f64)``: every scalar
    of the planar equations is an L-vector (one lane per member), the state an (10, L)
    matrix: explicit vector lanes.

Workloads: ``rhs`` (z ← y0 + 1e-12 f(z), R dependent evaluations, as the split section
of bench_throughput.py) and ``rk4`` (R fixed steps of the classical 4th-order Runge-Kutta
method, h = 2π/256: a whole integrator loop, stage combination included). Checks: the
unrolled layout must equal the scalar one bit for bit (same operations per member); the
explicit lanes, whose RHS is written again here, must agree to round-off.

The machine may be shared: the variants are timed interleaved (variant A, B, C, A, B, C, ...),
``--repeat`` rounds, and each timing records wall and process CPU time; ns per RHS are given
per core (CPU time / evaluations, the figure to compare under load) and per wall second;
the speed-up is the scalar layout's median CPU time over the variant's.

A third workload, ``ck45``, is the kernels' adaptive scheme without events: Cash-Karp 4(5)
(``kernels/tableau.py``), max-norm error control at rtol = atol = 1e-12, the kernels'
controller constants, each member to its own end time (cost per member-orbit). Its lane
variant keeps the L members of a group in lock-step (every lane computes a step each round, a
finished lane's is discarded, as SIMD lanes would) and must equal the scalar results bit for
bit. Two more adaptive workloads use Verner's 9(8) pair, the fastest method: ``vern9`` in the
package kernels' own form (a runtime loop over the 16 stages, the stage matrix in memory,
``kernels/integrator.py``'s combinations; the lane kernel evaluates the L right-hand sides of
a stage in one loop body) and ``vern9u`` with every stage unrolled, as ``ck45``.

    python experiments/simd_lanes.py                 # N = 4096, lanes 2, 4, 8
    python experiments/simd_lanes.py --quick         # CI: N = 256, lanes 2, ~10 s
    python experiments/simd_lanes.py --llvm-ir       # and count vector instructions in the IR
"""

import os
import sys
import time

import warnings

import numpy as np

from _common import parse, save

# the stage list of the ck45 step is built with list.append at compile time (on purpose)
warnings.filterwarnings("ignore", message='.*non-taichi function "ks.append"',
                        category=SyntaxWarning)

EPS = 1e-12                 # rhs workload: next argument y0 + EPS f(previous)
RK4_STEP = 2.0 * np.pi / 256
# ck_lanes: lane counts of the adaptive workload (its L = 8 kernel took 195 s to compile and
# ran 1.08x the scalar one: measured once, left out)
# vern_lanes: the same for Verner's 9(8) pair (16 stages: L = 2 is 32 inlined RHS copies)
FULL = dict(members=4096, lanes=(2, 4, 8), ck_lanes=(2, 4), vern_lanes=(2,), seconds=0.5,
            repeat=5)
QUICK = dict(members=256, lanes=(2,), ck_lanes=(2,), vern_lanes=(2,), seconds=0.02, repeat=2)
ORDER, ODD = 4, False       # 1991 VH: ellipsoids, no order-3 terms
#: Largest relative difference of the explicit-lane results from the scalar ones after 8
#: repeats (measure()): round-off of a differently ordered RHS, which the rk4 steps (chaotic
#: members among them) amplify with length: 5e-11 after 912 steps, 1e-5 after several
#: thousand, so the check uses the fixed 8-repeat run. The unrolled layouts and the adaptive
#: workloads do the same operations per member: bit for bit.
AGREE = {"rhs": 1e-13, "rk4": 1e-8, "ck45": 0.0, "vern9": 0.0, "vern9u": 0.0}
#: ck45 workload: adaptive Cash-Karp at rtol = atol = CK_TOL to repeats x CK_UNIT (scaled
#: time), first step CK_H0; its cost is given per member-orbit, not per RHS
CK_TOL = 1e-12
CK_UNIT = 2.0 * np.pi / 64
CK_H0 = 0.01
#: step-size controller of the ensemble kernels (scipy naming, NR §16.2): factor
#: clip(SAFETY err^(-1/5), MIN_FACTOR, MAX_FACTOR), no growth right after a rejection
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 5.0
WORKLOADS = ("rhs", "rk4", "ck45", "vern9", "vern9u")
ADAPTIVE = ("ck45", "vern9", "vern9u")          # cost per member-orbit, not per RHS


def build_kernels(lanes_list, ck_lanes=(), vern_lanes=()):
    """Taichi kernels {(workload, variant, L): kernel(par, y, out, repeats)}."""
    import taichi as ti

    from ti_spinorbit.kernels import planar_eom as P

    nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
    NS, NP = P.NSTATE, P.NPAR

    # ---- lane helpers shared by the explicit-lane variants ----
    @ti.func
    def column(M, l: ti.template(), n: ti.template()):
        """Column l (one member) of an (n, L) lane matrix as an n-vector."""
        return ti.Vector([M[k, l] for k in ti.static(range(n))], ti.f64)

    @ti.func
    def gather(a: ti.template(), base, L: ti.template(), n: ti.template()):
        """Rows 0..n-1 of members base .. base+L-1 of an (n, members) array: (n, L)."""
        return ti.Matrix([[a[k, base + l] for l in ti.static(range(L))]
                          for k in ti.static(range(n))], ti.f64)

    # ---- scalar: one member per iteration (AoS, the package's layout) ----
    @ti.kernel
    def scalar_rhs(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
        for i in range(y.shape[0]):
            pv = P.member(par, i)
            y0 = ti.Vector([y[i, k] for k in ti.static(range(NS))], ti.f64)
            z = y0
            for _ in range(repeats):
                z = y0 + EPS * P.rhs_member(pv, z, ORDER, ODD)
            for k in ti.static(range(NS)):
                out[i, k] = z[k]

    @ti.kernel
    def scalar_rk4(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
        for i in range(y.shape[0]):
            pv = P.member(par, i)
            z = ti.Vector([y[i, k] for k in ti.static(range(NS))], ti.f64)
            h = RK4_STEP
            for _ in range(repeats):
                k1 = P.rhs_member(pv, z, ORDER, ODD)
                k2 = P.rhs_member(pv, z + 0.5 * h * k1, ORDER, ODD)
                k3 = P.rhs_member(pv, z + 0.5 * h * k2, ORDER, ODD)
                k4 = P.rhs_member(pv, z + h * k3, ORDER, ODD)
                z = z + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            for k in ti.static(range(NS)):
                out[i, k] = z[k]

    kernels = {("rhs", "scalar", 1): scalar_rhs, ("rk4", "scalar", 1): scalar_rk4}

    # ---- unrolled: L members per iteration, scalar code per member (SoA) ----
    def unrolled(L, workload):
        @ti.kernel
        def kernel(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
            for g in range(y.shape[1] // L):
                base = g * L
                PV = gather(par, base, L, NP)
                Y0 = gather(y, base, L, NS)
                Z = Y0
                h = RK4_STEP
                for _ in range(repeats):
                    for l in ti.static(range(L)):
                        pv = column(PV, l, NP)
                        z = column(Z, l, NS)
                        if ti.static(workload == "rhs"):
                            z = column(Y0, l, NS) + EPS * P.rhs_member(pv, z, ORDER, ODD)
                        else:
                            k1 = P.rhs_member(pv, z, ORDER, ODD)
                            k2 = P.rhs_member(pv, z + 0.5 * h * k1, ORDER, ODD)
                            k3 = P.rhs_member(pv, z + 0.5 * h * k2, ORDER, ODD)
                            k4 = P.rhs_member(pv, z + h * k3, ORDER, ODD)
                            z = z + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
                        for k in ti.static(range(NS)):
                            Z[k, l] = z[k]
                for k in ti.static(range(NS)):
                    for l in ti.static(range(L)):
                        out[k, base + l] = Z[k, l]
        return kernel

    # ---- lanes: the RHS over L-vectors, one lane per member (SoA) ----
    def lanes(L, workload):
        @ti.func
        def row(M, k: ti.template()):
            return ti.Vector([M[k, l] for l in ti.static(range(L))], ti.f64)

        @ti.func
        def rhs_lanes(PV, Y):
            """kernels/planar_eom.py's equations (order 4, no odd terms), every scalar an
            L-vector of members."""
            r, vr, ell = row(Y, P.Y_R), row(Y, P.Y_VR), row(Y, P.Y_L)
            ca, sa, cb, sb = row(Y, P.Y_CA), row(Y, P.Y_SA), row(Y, P.Y_CB), row(Y, P.Y_SB)
            c2a = ca * ca - sa * sa
            s2a = 2.0 * ca * sa
            c4a = c2a * c2a - s2a * s2a
            s4a = 2.0 * c2a * s2a
            c2b = cb * cb - sb * sb
            s2b = 2.0 * cb * sb
            c4b = c2b * c2b - s2b * s2b
            s4b = 2.0 * c2b * s2b
            f2 = (row(PV, P.P_P2) + row(PV, P.P_P2 + 1) * c2a + row(PV, P.P_P2 + 2) * s2a
                  + row(PV, P.P_Q2) + row(PV, P.P_Q2 + 1) * c2b + row(PV, P.P_Q2 + 2) * s2b)
            d2a = 2.0 * (row(PV, P.P_P2 + 2) * c2a - row(PV, P.P_P2 + 1) * s2a)
            d2b = 2.0 * (row(PV, P.P_Q2 + 2) * c2b - row(PV, P.P_Q2 + 1) * s2b)
            f4 = (row(PV, P.P_P4) + row(PV, P.P_P4 + 1) * c2a + row(PV, P.P_P4 + 2) * s2a
                  + row(PV, P.P_P4 + 3) * c4a + row(PV, P.P_P4 + 4) * s4a
                  + row(PV, P.P_Q4) + row(PV, P.P_Q4 + 1) * c2b + row(PV, P.P_Q4 + 2) * s2b
                  + row(PV, P.P_Q4 + 3) * c4b + row(PV, P.P_Q4 + 4) * s4b)
            d4a = (2.0 * (row(PV, P.P_P4 + 2) * c2a - row(PV, P.P_P4 + 1) * s2a)
                   + 4.0 * (row(PV, P.P_P4 + 4) * c4a - row(PV, P.P_P4 + 3) * s4a))
            d4b = (2.0 * (row(PV, P.P_Q4 + 2) * c2b - row(PV, P.P_Q4 + 1) * s2b)
                   + 4.0 * (row(PV, P.P_Q4 + 4) * c4b - row(PV, P.P_Q4 + 3) * s4b))
            xa, xb, xab, xm = (row(PV, P.P_X + 1), row(PV, P.P_X + 2), row(PV, P.P_X + 3),
                               row(PV, P.P_X + 4))
            cm = c2a * c2b + s2a * s2b
            sm = s2a * c2b - c2a * s2b
            f4 += row(PV, P.P_X) + xa * c2a + xb * c2b + xab * c2a * c2b + xm * cm
            d4a += -2.0 * (s2a * (xa + xab * c2b) + xm * sm)
            d4b += -2.0 * (s2b * (xb + xab * c2a) - xm * sm)
            u = 1.0 / r
            u2 = u * u
            u3 = u2 * u
            u5 = u3 * u2
            v_r = -row(PV, P.P_MM) * u2 - 3.0 * f2 * u3 * u - 5.0 * f4 * u5 * u
            v_a = d2a * u3 + d4a * u5
            v_b = d2b * u3 + d4b * u5
            lam_dot = ell * u2
            inv_m = row(PV, P.P_INV_M)
            rate_a = lam_dot - row(PV, P.P_F1) * row(Y, P.Y_W1)
            rate_b = lam_dot - row(PV, P.P_F2) * row(Y, P.Y_W2)
            return ti.Matrix.rows([vr, ell * lam_dot * u + inv_m * v_r, inv_m * (v_a + v_b),
                                   lam_dot, -sa * rate_a, ca * rate_a,
                                   -v_a * row(PV, P.P_K1), -sb * rate_b, cb * rate_b,
                                   -v_b * row(PV, P.P_K2)])

        @ti.kernel
        def kernel(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
            for g in range(y.shape[1] // L):
                base = g * L
                PV = gather(par, base, L, NP)
                Y0 = gather(y, base, L, NS)
                Z = Y0
                h = RK4_STEP
                for _ in range(repeats):
                    if ti.static(workload == "rhs"):
                        Z = Y0 + EPS * rhs_lanes(PV, Z)
                    else:
                        K1 = rhs_lanes(PV, Z)
                        K2 = rhs_lanes(PV, Z + 0.5 * h * K1)
                        K3 = rhs_lanes(PV, Z + 0.5 * h * K2)
                        K4 = rhs_lanes(PV, Z + h * K3)
                        Z = Z + h / 6.0 * (K1 + 2.0 * K2 + 2.0 * K3 + K4)
                for k in ti.static(range(NS)):
                    for l in ti.static(range(L)):
                        out[k, base + l] = Z[k, l]
        return kernel

    # ---- adaptive embedded pairs, max-norm error control (the kernels' scheme, no events) ----
    # Two forms of a step, one controller, one scalar kernel and one lock-step lane kernel:
    # "unrolled" (every stage inlined, the first evaluated afresh each step: the same RHS
    # count as the kernels' reuse of the accepted end's derivative) and "loop" (the package
    # kernels' form: a runtime loop over the stages, the stage matrix in memory, the
    # combinations of kernels/integrator.py; its lane kernel evaluates the L right-hand sides
    # of a stage together in one loop body).
    from ti_spinorbit.kernels.integrator import (make_error_norm, make_primitives,
                                                 stage_matrix_type)
    from ti_spinorbit.kernels.tableau import CASH_KARP, VERN9

    def adaptive(tab, form):
        """(scalar kernel, lane-kernel factory) of the adaptive workload with ``tab`` in
        ``form`` ("unrolled" or "loop")."""
        if form == "loop":
            stage_point, combine, put_stage = make_primitives(tab, NS, unroll_components=False)
            norm = make_error_norm(tab, unroll_components=False)
            kmat = stage_matrix_type(tab, NS)
        else:   # no stage matrix (a placeholder type) and no loop primitives
            stage_point = combine = put_stage = norm = None
            kmat = ti.types.matrix(1, 1, ti.f64)

        @ti.func
        def unrolled_step(pv, z, h):
            """One step, every stage inlined: (propagated solution, max-norm error in
            tolerance units)."""
            ks = [P.rhs_member(pv, z, ORDER, ODD)]
            for st in ti.static(range(1, tab.stages)):
                zs = z
                for j in ti.static(range(st)):
                    if ti.static(tab.a[st][j] != 0.0):
                        zs = zs + (tab.a[st][j] * h) * ks[j]
                ks.append(P.rhs_member(pv, zs, ORDER, ODD))
            dy = ti.Vector([0.0] * NS, ti.f64)
            er = ti.Vector([0.0] * NS, ti.f64)
            for st in ti.static(range(tab.stages)):
                if ti.static(tab.b[st] != 0.0):
                    dy += tab.b[st] * ks[st]
                if ti.static(tab.e[st] != 0.0):
                    er += tab.e[st] * ks[st]
            z_new = z + h * dy
            worst = 0.0
            for k in ti.static(range(NS)):
                scale = CK_TOL + CK_TOL * ti.max(ti.abs(z[k]), ti.abs(z_new[k]))
                worst = ti.max(worst, ti.abs(h * er[k]) / scale)
            return z_new, worst

        @ti.func
        def finish_loop_step(z, K: ti.template(), h):
            """The loop form's step from its filled stage matrix: (solution, error)."""
            dy, err, err3 = combine(K, h, True)
            z_new = z + dy
            return z_new, norm(z, z_new, err, err3, CK_TOL, CK_TOL, NS)

        @ti.func
        def step(pv, z, h, K: ti.template()):
            """One step of member (pv, z); K is the loop form's stage matrix."""
            z_new, err = z, 0.0
            if ti.static(form == "loop"):
                put_stage(K, 0, P.rhs_member(pv, z, ORDER, ODD))
                for st in range(1, tab.stages):
                    put_stage(K, st, P.rhs_member(pv, stage_point(z, K, h, st), ORDER, ODD))
                z_new, err = finish_loop_step(z, K, h)
            else:
                z_new, err = unrolled_step(pv, z, h)
            return z_new, err

        @ti.func
        def lane_steps(PV, Z, HT, Ks: ti.template(), L: ti.template()):
            """One step of each of the L lanes: (new states as an (NS, L) matrix, errors)."""
            ZN = Z
            ERR = ti.Vector([0.0] * L, ti.f64)
            if ti.static(form == "loop"):
                for l in ti.static(range(L)):
                    put_stage(Ks[l], 0, P.rhs_member(column(PV, l, NP), column(Z, l, NS),
                                                     ORDER, ODD))
                for st in range(1, tab.stages):         # the L RHS of a stage together
                    for l in ti.static(range(L)):
                        zs = stage_point(column(Z, l, NS), Ks[l], HT[l], st)
                        put_stage(Ks[l], st, P.rhs_member(column(PV, l, NP), zs, ORDER, ODD))
                for l in ti.static(range(L)):
                    z_new, err = finish_loop_step(column(Z, l, NS), Ks[l], HT[l])
                    ERR[l] = err
                    for k in ti.static(range(NS)):
                        ZN[k, l] = z_new[k]
            else:
                for l in ti.static(range(L)):
                    z_new, err = unrolled_step(column(PV, l, NP), column(Z, l, NS), HT[l])
                    ERR[l] = err
                    for k in ti.static(range(NS)):
                        ZN[k, l] = z_new[k]
            return ZN, ERR

        @ti.func
        def controlled(t, h, h_try, z, z_new, err, rejected):
            """Accept or reject a step (the kernels' controller constants, above)."""
            if err <= 1.0:
                fac = MAX_FACTOR
                if err > 0.0:
                    fac = ti.min(MAX_FACTOR, SAFETY * ti.pow(err, -tab.error_exponent))
                if rejected:
                    fac = ti.min(1.0, fac)
                t += h_try
                z = z_new
                h = h_try * fac
                rejected = 0
            else:
                h = h_try * ti.max(MIN_FACTOR, SAFETY * ti.pow(err, -tab.error_exponent))
                rejected = 1
            return t, h, z, rejected

        @ti.kernel
        def scalar(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
            for i in range(y.shape[0]):
                pv = P.member(par, i)
                z = ti.Vector([y[i, k] for k in ti.static(range(NS))], ti.f64)
                t_end = repeats * CK_UNIT
                t, h, rejected = 0.0, CK_H0, 0
                K = kmat(0.0)
                while t < t_end:
                    h_try = ti.min(h, t_end - t)
                    z_new, err = step(pv, z, h_try, K)
                    t, h, z, rejected = controlled(t, h, h_try, z, z_new, err, rejected)
                for k in ti.static(range(NS)):
                    out[i, k] = z[k]

        def lanes_kernel(L):
            @ti.kernel
            def kernel(par: nd2f, y: nd2f, out: nd2f, repeats: ti.i32):
                for g in range(y.shape[1] // L):
                    base = g * L
                    PV = gather(par, base, L, NP)
                    Z = gather(y, base, L, NS)
                    t_end = repeats * CK_UNIT
                    T = ti.Vector([0.0] * L, ti.f64)
                    H = ti.Vector([CK_H0] * L, ti.f64)
                    HT = ti.Vector([0.0] * L, ti.f64)
                    REJ = ti.Vector([0] * L, ti.i32)
                    Ks = [kmat(0.0) for _ in ti.static(range(L))]
                    running = 1
                    while running:
                        running = 0
                        # every lane computes a step (a finished lane's is discarded): the
                        # lanes stay in lock-step, as SIMD lanes would
                        for l in ti.static(range(L)):
                            HT[l] = ti.min(H[l], t_end - T[l])
                        ZN, ERR = lane_steps(PV, Z, HT, Ks, L)
                        for l in ti.static(range(L)):
                            if T[l] < t_end:
                                t, h, z, rej = controlled(T[l], H[l], HT[l], column(Z, l, NS),
                                                          column(ZN, l, NS), ERR[l], REJ[l])
                                T[l], H[l], REJ[l] = t, h, rej
                                for k in ti.static(range(NS)):
                                    Z[k, l] = z[k]
                            if T[l] < t_end:
                                running = 1
                    for k in ti.static(range(NS)):
                        for l in ti.static(range(L)):
                            out[k, base + l] = Z[k, l]
            return kernel

        return scalar, lanes_kernel

    for L in lanes_list:
        for workload in ("rhs", "rk4"):
            kernels[(workload, "unrolled", L)] = unrolled(L, workload)
            kernels[(workload, "lanes", L)] = lanes(L, workload)
    for workload, tab, form, lane_counts in (("ck45", CASH_KARP, "unrolled", ck_lanes),
                                             ("vern9", VERN9, "loop", vern_lanes),
                                             ("vern9u", VERN9, "unrolled", vern_lanes)):
        scalar, lanes_kernel = adaptive(tab, form)
        kernels[(workload, "scalar", 1)] = scalar
        for L in lane_counts:
            kernels[(workload, "unrolled", L)] = lanes_kernel(L)
    return kernels


def member_inputs(n):
    """Planar parameter rows and states of the first n benchmark members (bench_throughput's
    R2 sequence of starts, 1991 VH at a/b = 1.5)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import bench_throughput as bt

    from ti_spinorbit.model import planar

    par, y0 = bt.member_table(n)
    return planar.parameter_rows(par), planar.to_planar(y0)


def timed(kernel, par, y, out, repeats):
    import taichi as ti

    wall, cpu = time.perf_counter(), time.process_time()
    kernel(par, y, out, repeats)
    ti.sync()
    return time.perf_counter() - wall, time.process_time() - cpu


def measure(kernels, kpar, q, seconds, rounds):
    """Interleaved timings of every kernel; one row per (workload, variant, L)."""
    n = len(q)
    aos = (np.ascontiguousarray(kpar), np.ascontiguousarray(q))
    soa = (np.ascontiguousarray(kpar.T), np.ascontiguousarray(q.T))
    outputs, repeats, compile_s, checked = {}, {}, {}, {}
    for key, kernel in kernels.items():
        par, y = aos if key[1] == "scalar" else soa
        out = np.zeros_like(y)
        wall, _ = timed(kernel, par, y, out, 1)          # compile or load
        compile_s[key] = wall
        wall, _ = timed(kernel, par, y, out, 8)
        repeats[key] = max(8, int(8 * seconds / max(wall, 1e-6)))
        # the layouts are compared after these 8 repeats: a fixed length, because the timed
        # runs' length varies with the machine and chaotic members amplify round-off with it
        checked[key] = out.copy()
        outputs[key] = out
    # the scalar variant's repeats for every variant of a workload: the same work
    for key in kernels:
        repeats[key] = repeats[(key[0], "scalar", 1)]
    times = {key: [] for key in kernels}
    for _ in range(rounds):
        for key, kernel in kernels.items():
            par, y = aos if key[1] == "scalar" else soa
            times[key].append(timed(kernel, par, y, outputs[key], repeats[key]))
    rows = []
    for key in kernels:
        workload, variant, L = key
        # work units: RHS evaluations (rhs, rk4), member-orbits (ck45, vern9)
        rhs_calls = (n * repeats[key] / 64 if workload in ADAPTIVE
                     else n * repeats[key] * (4 if workload == "rk4" else 1))
        walls = np.array([t[0] for t in times[key]])
        cpus = np.array([t[1] for t in times[key]])
        out = checked[key] if variant == "scalar" else checked[key].T
        rows.append({"workload": workload, "variant": variant, "lanes": L, "members": n,
                     "repeats": repeats[key], "rhs_calls": rhs_calls,
                     "compile_s": compile_s[key], "wall_s": walls.tolist(),
                     "cpu_s": cpus.tolist(),
                     "ns_per_rhs_cpu_median": 1e9 * float(np.median(cpus)) / rhs_calls,
                     "ns_per_rhs_cpu_best": 1e9 * float(cpus.min()) / rhs_calls,
                     "ns_per_rhs_wall_median": 1e9 * float(np.median(walls)) / rhs_calls,
                     "out": out})
    for r in rows:
        ref = next(s for s in rows if (s["workload"], s["variant"]) == (r["workload"], "scalar"))
        diff = np.abs(r["out"] - ref["out"]) / np.maximum(np.abs(ref["out"]).max(axis=0), 1e-300)
        r["max_rel_diff_vs_scalar"] = float(diff.max())
        r["bit_identical"] = bool(np.array_equal(r["out"], ref["out"]))
        r["speedup_cpu"] = ref["ns_per_rhs_cpu_median"] / r["ns_per_rhs_cpu_median"]
        r["speedup_wall"] = ref["ns_per_rhs_wall_median"] / r["ns_per_rhs_wall_median"]
    for r in rows:
        del r["out"]
    return rows


def llvm_ir_counts(lanes_list, ck_lanes, vern_lanes, kpar, q):
    """Floating-point instructions in each kernel's optimised LLVM IR, scalar and vector
    (``<k x double>``), by vector width: whether LLVM packed the lanes. Re-initialises Taichi
    (the package's settings, no kernel cache, IR written to a temporary folder)."""
    import glob
    import re
    import tempfile

    import taichi as ti

    here = os.getcwd()
    counts = {}
    with tempfile.TemporaryDirectory(prefix="simd_lanes_ir_") as folder:
        os.chdir(folder)
        try:
            ti.reset()
            ti.init(arch=ti.cpu, default_fp=ti.f64, default_ip=ti.i32, fast_math=False,
                    offline_cache=False, log_level=ti.WARN, make_cpu_multithreading_loop=False,
                    cpu_block_dim_adaptive=False, default_cpu_block_dim=1,
                    print_kernel_llvm_ir_optimized=True)
            seen = set()
            for key, kernel in build_kernels(lanes_list, ck_lanes, vern_lanes).items():
                par, y = (kpar, q) if key[1] == "scalar" else (np.ascontiguousarray(kpar.T),
                                                               np.ascontiguousarray(q.T))
                kernel(par, y, np.zeros_like(y), 1)
                new = sorted(set(glob.glob("*.ll")) - seen)
                seen.update(new)
                text = "".join(open(f).read() for f in new)
                op = r"(?:fadd|fsub|fmul|fdiv)"
                counts[key] = {
                    "scalar_ops": len(re.findall(op + r" (?:\w+ )*double ", text)),
                    "vector_ops": len(re.findall(op + r" (?:\w+ )*<\d+ x double>", text)),
                    "widths": {int(w): text.count(f"<{w} x double>")
                               for w in sorted(set(re.findall(r"<(\d+) x double>", text)),
                                               key=int)}}
        finally:
            os.chdir(here)
    return counts


def figure(rows):
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(WORKLOADS), figsize=(4.3 * len(WORKLOADS), 3.8))
    for ax, workload in zip(axes, WORKLOADS):
        group = [r for r in rows if r["workload"] == workload]
        labels = [r["variant"] if r["variant"] == "scalar" else f"{r['variant']} {r['lanes']}"
                  for r in group]
        x = np.arange(len(group))
        unit = 1e-3 if workload in ADAPTIVE else 1.0        # microseconds per orbit
        ax.bar(x - 0.2, [unit * r["ns_per_rhs_cpu_median"] for r in group], 0.4,
               label="per core (CPU time)")
        ax.bar(x + 0.2, [unit * r["ns_per_rhs_wall_median"] for r in group], 0.4, label="wall")
        ax.set_xticks(x, labels, rotation=30, fontsize=8)
        ax.set_ylabel("us per member-orbit (median)" if workload in ADAPTIVE
                      else "ns per RHS evaluation (median)")
        ax.set_title(f"planar RHS, 1991 VH a/b = 1.5: workload {workload}", fontsize=9)
        ax.legend(fontsize=7)
    return fig


def main():
    def extra(p):
        p.add_argument("--repeat", type=int, default=None,
                       help="interleaved rounds (default 5; quick 2)")
        p.add_argument("--llvm-ir", action="store_true",
                       help="also count scalar and vector floating-point instructions in each "
                            "kernel's optimised LLVM IR (recompiles every kernel)")

    args, started = parse(__doc__.splitlines()[0], extra)
    s = dict(QUICK if args.quick else FULL)
    rounds = args.repeat or s["repeat"]
    kpar, q = member_inputs(s["members"])
    t0 = time.perf_counter()
    kernels = build_kernels(s["lanes"], s["ck_lanes"], s["vern_lanes"])
    rows = measure(kernels, kpar, q, s["seconds"], rounds)
    load = os.getloadavg()[0]
    import bench_throughput as bt                           # on the path after member_inputs
    cpu_model, ghz, flags = bt.cpu_info()
    simd = sorted(f for f in flags if f in ("avx2", "fma", "avx512f"))
    print(f"[simd_lanes] CPU {cpu_model} ({', '.join(simd) or 'no AVX2'}), "
          f"{os.cpu_count()} CPUs")
    print(f"[simd_lanes] N = {s['members']}, {rounds} interleaved rounds, load average "
          f"{load:.2f}; ns per RHS (adaptive workloads: per member-orbit), median, per core = process "
          "CPU time / work")
    print(f"{'workload':>8} {'variant':>9} {'L':>2} {'CPU ns':>7} {'best':>7} {'wall ns':>8} "
          f"{'speed-up':>8} {'(wall)':>7} {'max rel diff':>12} {'compile s':>9}")
    for r in rows:
        print(f"{r['workload']:>8} {r['variant']:>9} {r['lanes']:>2} "
              f"{r['ns_per_rhs_cpu_median']:7.2f} {r['ns_per_rhs_cpu_best']:7.2f} "
              f"{r['ns_per_rhs_wall_median']:8.2f} {r['speedup_cpu']:7.2f}x "
              f"{r['speedup_wall']:6.2f}x {r['max_rel_diff_vs_scalar']:12.1e} "
              f"{r['compile_s']:9.2f}")
    bad = [(r["workload"], r["variant"], r["lanes"]) for r in rows
           if (r["variant"] == "unrolled" and not r["bit_identical"])
           or r["max_rel_diff_vs_scalar"] > AGREE[r["workload"]]]
    if bad:
        raise SystemExit(f"[simd_lanes] results differ from the scalar layout: {bad}")
    ir = {}
    if args.llvm_ir:
        ir = llvm_ir_counts(s["lanes"], s["ck_lanes"], s["vern_lanes"], kpar[:64], q[:64])
        print("[simd_lanes] optimised LLVM IR, f64 fadd/fsub/fmul/fdiv: scalar, vector "
              "(<k x double>), occurrences of each vector width")
        for (workload, variant, L), c in ir.items():
            print(f"  {workload:>4} {variant:>9} {L:2d}: scalar {c['scalar_ops']:5d}  vector "
                  f"{c['vector_ops']:5d}  widths {c['widths']}")
    best = {w: max((r for r in rows if r["workload"] == w), key=lambda r: r["speedup_cpu"])
            for w in WORKLOADS}
    numbers = {f"{w} speed-up per core, best ({b['variant']} {b['lanes']})": b["speedup_cpu"]
               for w, b in best.items()}
    numbers.update({f"{w} scalar ns per {'member-orbit' if w in ADAPTIVE else 'RHS'} per core": next(
        r["ns_per_rhs_cpu_median"] for r in rows if (r["workload"], r["variant"]) == (w, "scalar"))
        for w in WORKLOADS})
    keys = ("workload", "variant", "lanes", "ns_per_rhs_cpu_median", "ns_per_rhs_wall_median",
            "speedup_cpu", "max_rel_diff_vs_scalar")
    save(args, "simd_lanes", figure(rows), {k: [r[k] for r in rows] for k in keys},
         {**s, "rounds": rounds, "rows": rows,
          "llvm_ir": {" ".join(map(str, k)): v for k, v in ir.items()}, "load_average": load,
          "cpu": cpu_model, "simd": simd,
          "build_and_time_s": time.perf_counter() - t0}, numbers, started)


if __name__ == "__main__":
    main()
