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
scaled state, including the secondary's spin, is held to the tolerance.
"""

import taichi as ti

from .tableau import CASH_KARP, DEFAULT_CONTROLLER

_SAFETY = DEFAULT_CONTROLLER.SAFETY
_MIN_FACTOR = DEFAULT_CONTROLLER.MIN_FACTOR
_MAX_FACTOR = DEFAULT_CONTROLLER.MAX_FACTOR
#: Error-norm value standing for "NaN or inf somewhere in the trial step".
NONFINITE_ERROR = 1e301


def _padded_a(tableau):
    s = tableau.stages
    return [[(tableau.a[r][c] if c < len(tableau.a[r]) else 0.0) for c in range(s)] for r in range(s)]


def stage_matrix_type(tableau, n):
    """Local (stages x n) matrix holding the stage derivatives k_s."""
    return ti.types.matrix(tableau.stages, n, ti.f64)


def make_primitives(tableau, n):
    """``(stage_point, combine, put_stage)`` funcs for ``tableau`` on n-component states.

    * ``stage_point(y, K, h, s)``: y + h Σ_{j<s} a_sj K[j]  (s is a runtime index >= 1)
    * ``combine(K, h)``: (dy, err) = (h Σ b_s K[s], h Σ (b_s − b̂_s) K[s])
    * ``put_stage(K, s, v)``: K[s] = v for a runtime s

    The runtime stage index is dispatched to compile-time branches, so every access to K has
    a constant index: K then lives in registers and the a_sj are immediates (indexing a
    local matrix with a runtime index forces it, and a copy of the tableau, into memory on
    every call; this alone cost about a third of the planar model's time per stage).
    """
    A = _padded_a(tableau)
    B, E = tableau.b, tableau.e
    stages = tableau.stages

    @ti.func
    def stage_point(y, K, h, s):
        ys = y
        for st in ti.static(range(1, stages)):
            if s == st:
                for j in ti.static(range(st)):
                    if ti.static(A[st][j] != 0.0):
                        w = A[st][j] * h
                        for c in ti.static(range(n)):
                            ys[c] += w * K[j, c]
        return ys

    @ti.func
    def put_stage(K: ti.template(), s, v):
        for st in ti.static(range(stages)):
            if s == st:
                for c in ti.static(range(n)):
                    K[st, c] = v[c]

    @ti.func
    def combine(K, h):
        dy = ti.Vector([0.0] * n, ti.f64)
        err = ti.Vector([0.0] * n, ti.f64)
        for s in ti.static(range(stages)):
            for c in ti.static(range(n)):
                if ti.static(B[s] != 0.0):
                    dy[c] += B[s] * K[s, c]
                if ti.static(E[s] != 0.0):
                    err[c] += E[s] * K[s, c]
        return dy * h, err * h

    return stage_point, combine, put_stage


def make_step(f, n, tableau=CASH_KARP):
    """Standalone ``rk_step(p, i, y, k1, h, order, odd) -> (dy, err)`` for the RHS func ``f``
    (same primitives as the ensemble kernel; used by tests and small kernels).

    ``dy`` is the increment h Σ b_i k_i of the propagated solution, ``err`` the embedded
    error estimate h Σ (b_i − b̂_i) k_i."""
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
        return combine(K, h)

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
def step_factor(err_norm, after_reject, exponent: ti.template()):
    """Next-step factor from the controller (scipy/NR constants, no growth after a reject)."""
    fac = _MAX_FACTOR
    if err_norm > 0.0:
        fac = _SAFETY * ti.pow(err_norm, -exponent)
    fac = ti.min(_MAX_FACTOR, ti.max(_MIN_FACTOR, fac))
    if after_reject:
        fac = ti.min(1.0, fac)
    return fac
