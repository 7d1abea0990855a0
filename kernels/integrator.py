"""Embedded Runge-Kutta primitives and the step-size controller (Taichi funcs).

The tableau is data (``tableau.py``). A step is written as a *runtime* loop over stages that
stores the stage derivatives in a (stages x n) local matrix and evaluates the right-hand side
at one call site. Why: every Taichi ``ti.func`` call is inlined, and compile time grows much
faster than linearly with kernel size (measured on Taichi 1.7.4, 2-core CPU: one inlined copy
of the 4th-order RHS compiles in 1.3 s, a kernel with 13 copies — an unrolled Cash-Karp step,
its event-location twin and the extra evaluations — in 200 s). The ensemble kernel is built
around a single RHS call site; ``make_step`` assembles the same primitives into a standalone
step for tests and small kernels.

Error norm: max over components of |err_i| / (atol + rtol max(|y_i|, |y_new_i|)), i.e.
"tolerance units" as in scipy but with the max norm (NR §16.2): every component of the
scaled state, including the secondary's spin, is held to the tolerance. A tableau with two
error estimates (DOP853) combines them per component as Hairer's DOP853 does over the whole
vector (HNW I §II.10; scipy ``_ivp/rk.py`` ``DOP853._estimate_error_norm``):
err_i = e5_i² / sqrt(e5_i² + 0.01 e3_i²) with e5_i, e3_i the two estimates in tolerance
units, then the max over i (:func:`make_error_norm`).

The step-size policy is ``controller.Controller`` (its Taichi funcs come with it).
"""

import taichi as ti

from .controller import NONFINITE_ERROR  # noqa: F401  (re-exported)
from .tableau import CASH_KARP


def _padded_a(tableau):
    s = tableau.stages
    return [[(tableau.a[r][c] if c < len(tableau.a[r]) else 0.0) for c in range(s)] for r in range(s)]


def stage_matrix_type(tableau, n):
    """Local (stages x n) matrix holding the stage derivatives k_s."""
    return ti.types.matrix(tableau.stages, n, ti.f64)


def make_primitives(tableau, n, unroll_components=True):
    """``(stage_point, combine, put_stage)`` funcs for ``tableau`` on n-component states.

    * ``stage_point(y, K, h, s)``: y + h Σ_{j<s} a_sj K[j]  (s is a runtime index >= 1)
    * ``combine(K, h, estimates)``: (dy, err, err3) = (h Σ b_s K[s], h Σ e_s K[s],
      h Σ e3_s K[s]); err3 is zero (and costs nothing) for a tableau with one error
      estimate, and both estimates are zero without ``estimates`` (a compile-time flag: the
      chaos indicators' shadow rides on the member's steps and is never judged; leaving its
      sums out trims the 3-D kernels' compile by 0.1 s)
    * ``put_stage(K, s, v)``: K[s] = v for a runtime s

    The runtime stage index is dispatched to compile-time branches, so the a_sj are
    immediates. With ``unroll_components`` (the planar model) every access to K also has a
    constant index, so K lives in registers (indexing a local matrix with a runtime index
    forces it, and a copy of the tableau, into memory on every call; this alone cost about a
    third of the planar model's time per stage). Without it (the 3-D model, 30 components)
    each stage is one runtime loop over the components, with the stage's terms unrolled
    inside: K stays in memory, and the kernel compiles in a fraction of the time (a 6x30 or
    12x30 matrix of SSA values carried through the state machine is what made LLVM slow; the
    3-D step is dominated by its right-hand side, so nothing is lost at run time). Per
    component the operations and their order are the same either way: bit-identical results.

    K is taken by reference (``ti.template()``) by all three: a ``ti.func`` copies a matrix
    argument passed by value, and in the runtime-loop form LLVM could not remove the copy, so
    every stage evaluation copied the whole stage matrix (16 x 30 numbers for Verner's pair
    on the 3-D model). Removing the copies made DOP853 and Verner 9(8) 17-25 % faster and
    halved the 3-D compile, most of which was LLVM's SLP vectoriser working on those copies;
    results are bit for bit the same (docs/design.md, "Taichi's CFG pass").
    """
    A = _padded_a(tableau)
    B, E = tableau.b, tableau.e
    E3 = tableau.e3 if tableau.e3 is not None else (0.0,) * tableau.stages
    stages = tableau.stages

    unroll = bool(unroll_components)

    @ti.func
    def stage_point(y, K: ti.template(), h, s):
        ys = y
        for st in ti.static(range(1, stages)):
            if s == st:
                if ti.static(unroll):   # K in registers: constant indices only
                    for j in ti.static(range(st)):
                        if ti.static(A[st][j] != 0.0):
                            w = A[st][j] * h
                            for c in ti.static(range(n)):
                                ys[c] += w * K[j, c]
        if ti.static(not unroll):   # runtime loops; per component the same sum, same order
            row = ti.Vector([0.0] * stages, ti.f64)
            for st in ti.static(range(1, stages)):
                if s == st:
                    row = ti.Vector(A[st], ti.f64)
            for j in range(s):
                a = row[j]
                if a != 0.0:
                    w = a * h
                    for c in range(n):
                        ys[c] += w * K[j, c]
        return ys

    @ti.func
    def put_stage(K: ti.template(), s, v):
        if ti.static(unroll):
            for st in ti.static(range(stages)):
                if s == st:
                    for c in ti.static(range(n)):
                        K[st, c] = v[c]
        else:
            for c in range(n):
                K[s, c] = v[c]

    @ti.func
    def combine(K: ti.template(), h, estimates: ti.template()):
        dy = ti.Vector([0.0] * n, ti.f64)
        err = ti.Vector([0.0] * n, ti.f64)
        err3 = ti.Vector([0.0] * n, ti.f64)
        if ti.static(unroll):
            for s in ti.static(range(stages)):
                for c in ti.static(range(n)):
                    if ti.static(B[s] != 0.0):
                        dy[c] += B[s] * K[s, c]
                    if ti.static(estimates and E[s] != 0.0):
                        err[c] += E[s] * K[s, c]
                    if ti.static(estimates and E3[s] != 0.0):
                        err3[c] += E3[s] * K[s, c]
        else:
            for c in range(n):
                d = 0.0
                e = 0.0
                e3 = 0.0
                for s in ti.static(range(stages)):
                    if ti.static(B[s] != 0.0):
                        d += B[s] * K[s, c]
                    if ti.static(estimates and E[s] != 0.0):
                        e += E[s] * K[s, c]
                    if ti.static(estimates and E3[s] != 0.0):
                        e3 += E3[s] * K[s, c]
                dy[c] = d
                err[c] = e
                err3[c] = e3
        return dy * h, err * h, err3 * h

    return stage_point, combine, put_stage


def make_step(f, n, tableau=CASH_KARP):
    """Standalone ``rk_step(p, i, y, k1, h, order, odd) -> (dy, err)`` for the RHS func ``f``
    (same primitives as the ensemble kernel; used by tests and small kernels).

    ``dy`` is the increment h Σ b_i k_i of the propagated solution, ``err`` the (first)
    embedded error estimate h Σ e_i k_i."""
    stage_point, combine, put_stage = make_primitives(tableau, n)
    kmat = stage_matrix_type(tableau, n)
    stages = tableau.stages

    @ti.func
    def rk_step(p: ti.template(), i, y, k1, h, order: ti.template(), odd: ti.template()):
        K = kmat(0.0)
        for c in ti.static(range(n)):
            K[0, c] = k1[c]
        for s in range(1, stages):
            put_stage(K, s, f(p, i, stage_point(y, K, h, s), order, odd))
        dy, err, err3 = combine(K, h, True)
        return dy, err

    return rk_step


@ti.func
def error_norm(y, y_new, err, rtol, atol, n: ti.template()):
    """Max-norm of the error estimate in tolerance units; NaN or inf anywhere gives
    NONFINITE_ERROR."""
    worst = 0.0
    for k in ti.static(range(n)):
        scale = atol + rtol * ti.max(ti.abs(y[k]), ti.abs(y_new[k]))
        worst = ti.max(worst, ti.abs(err[k]) / scale)
    if not (worst <= 1e300):  # NaN compares false
        worst = NONFINITE_ERROR
    return worst


@ti.func
def _combined_norm(y, y_new, err, err3, rtol, atol, n: ti.template()):
    """DOP853's combination of a 5th- and a 3rd-order estimate, per component, max norm."""
    worst = 0.0
    bad = 0
    for k in ti.static(range(n)):
        scale = atol + rtol * ti.max(ti.abs(y[k]), ti.abs(y_new[k]))
        e5 = err[k] / scale
        e3 = err3[k] / scale
        e5sq = e5 * e5
        den = e5sq + 0.01 * e3 * e3
        v = 0.0
        if den != 0.0:                  # true for NaN too
            v = e5sq / ti.sqrt(den)
        if not (v <= 1e300):            # NaN compares false (max() may drop a NaN)
            bad = 1
        worst = ti.max(worst, v)
    if bad == 1 or not (worst <= 1e300):
        worst = NONFINITE_ERROR
    return worst


@ti.func
def _norm_loop(y, y_new, err, err3, rtol, atol, n: ti.template(), combined: ti.template()):
    """:func:`error_norm` (or :func:`_combined_norm`) as a runtime loop over components: the
    same values in the same order (max is exact), for kernels that keep states in memory."""
    worst = 0.0
    bad = 0
    for k in range(n):
        scale = atol + rtol * ti.max(ti.abs(y[k]), ti.abs(y_new[k]))
        v = 0.0
        if ti.static(combined):
            e5 = err[k] / scale
            e3 = err3[k] / scale
            e5sq = e5 * e5
            den = e5sq + 0.01 * e3 * e3
            if den != 0.0:
                v = e5sq / ti.sqrt(den)
            if not (v <= 1e300):
                bad = 1
        else:
            v = ti.abs(err[k]) / scale
        worst = ti.max(worst, v)
    if bad == 1 or not (worst <= 1e300):
        worst = NONFINITE_ERROR
    return worst


def make_error_norm(tableau, unroll_components=True):
    """``norm(y, y_new, err, err3, rtol, atol, n)`` for ``tableau``: :func:`error_norm` of
    ``err`` for a single estimate, the DOP853 combination when the tableau has ``e3``;
    a runtime loop over the components unless ``unroll_components``."""
    combined = tableau.e3 is not None
    unroll = bool(unroll_components)

    @ti.func
    def norm(y, y_new, err, err3, rtol, atol, n: ti.template()):
        v = 0.0
        if ti.static(not unroll):
            v = _norm_loop(y, y_new, err, err3, rtol, atol, n, combined)
        elif ti.static(combined):
            v = _combined_norm(y, y_new, err, err3, rtol, atol, n)
        else:
            v = error_norm(y, y_new, err, rtol, atol, n)
        return v

    return norm
