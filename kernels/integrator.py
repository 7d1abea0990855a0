"""Generic explicit embedded Runge-Kutta step and the step-size controller (Taichi funcs).

The tableau is data (``tableau.py``); ``rk_step`` unrolls any tableau at compile time with
``ti.static`` so zero coefficients cost nothing. The first stage ``k1 = f(y)`` is passed in:
after an accepted step the caller evaluates f at the new point once and reuses it both as the
next step's first stage and for event location (a rejected step reuses it for free).

Error norm: max over components of |err_i| / (atol + rtol max(|y_i|, |y_new_i|)), i.e.
"tolerance units" as in scipy but with the max norm (NR §16.2): every component of the
scaled state, including the secondary's spin, is held to the tolerance.
"""

import taichi as ti

from .tableau import CASH_KARP, DEFAULT_CONTROLLER

_SAFETY = DEFAULT_CONTROLLER.SAFETY
_MIN_FACTOR = DEFAULT_CONTROLLER.MIN_FACTOR
_MAX_FACTOR = DEFAULT_CONTROLLER.MAX_FACTOR


def make_step(f, tableau=CASH_KARP):
    """Build ``rk_step(p, i, y, k1, h, order, odd) -> (y_new, err_vec)`` for the RHS func ``f``.

    ``err_vec`` is h Σ (b_i − b̂_i) k_i, the difference between the propagated and the
    embedded solution."""
    A, B, E = tableau.a, tableau.b, tableau.e

    @ti.func
    def rk_step(p: ti.template(), i, y, k1, h, order: ti.template(), odd: ti.template()):
        ks = [k1]
        for s in ti.static(range(1, len(B))):
            ys = y
            for j in ti.static(range(s)):
                if ti.static(A[s][j] != 0.0):
                    ys += (h * A[s][j]) * ks[j]
            ks.append(f(p, i, ys, order, odd))  # compile-time list: unrolled stages
        dy = ks[0] * 0.0
        err = ks[0] * 0.0
        for s in ti.static(range(len(B))):
            if ti.static(B[s] != 0.0):
                dy += B[s] * ks[s]
            if ti.static(E[s] != 0.0):
                err += E[s] * ks[s]
        return dy * h, err * h

    return rk_step


@ti.func
def error_norm(y, y_new, err, rtol, atol, n: ti.template()):
    """Max-norm of the error estimate in tolerance units; NaN or inf anywhere gives 1e301
    (callers treat > 1e300 as a non-finite trial step)."""
    worst = 0.0
    for k in ti.static(range(n)):
        scale = atol + rtol * ti.max(ti.abs(y[k]), ti.abs(y_new[k]))
        worst = ti.max(worst, ti.abs(err[k]) / scale)
    if not (worst <= 1e300):  # NaN compares false
        worst = 1e301
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
