"""Benchmark-only baseline: a compiled single-trajectory DOP853 integrator of the planar model
(numba), for ``bench_throughput.py`` (the ensemble must run at least 2x per core
what a plain compiled loop does).

Written independently of the Taichi kernels: the right-hand side below is derived again from
the planar equations of docs/physics.md §3.2–3.5 and the docstring of ``kernels/planar_eom.py``
(state y = [r, v_r, ℓ, λ, cos ψ_A, sin ψ_A, w1, cos ψ_B, sin ψ_B, w2], scaled units, G = 1),
and only the member's parameter row (the Fourier coefficients of each body's Legendre terms,
``ti_spinorbit.model.planar.parameter_rows``) is shared. ``tests/test_experiments.py`` checks this RHS
against the package's to round-off, and the benchmark checks whole trajectories against the
kernels at tight tolerance.

    V(r, ψ_A, ψ_B) = mA mB / r + (P2 + Q2) / r³ + (P4 + Q4 + X) / r⁵     (V = −U)
    P(ψ) = a0 + a2 cos 2ψ + b2 sin 2ψ (+ a4 cos 4ψ + b4 sin 4ψ)
    X = x0 + xA cos 2ψ_A + xB cos 2ψ_B + xAB cos 2ψ_A cos 2ψ_B + xm cos(2ψ_A − 2ψ_B)
    dr/dt = v_r,  dv_r/dt = ℓ²/r³ + (∂V/∂r)/m,  dℓ/dt = (∂V/∂ψ_A + ∂V/∂ψ_B)/m,
    dλ/dt = ℓ/r²,  d(cos ψ, sin ψ)/dt = (−sin ψ, cos ψ) (ℓ/r² − f w),  dw/dt = −(∂V/∂ψ)/C

Order 4, bodies symmetric about their principal planes only (no order-3 terms: every
catalogued system, 1991 VH included); :func:`check_even` refuses other rows.

Integrator: Hairer's DOP853 pair (Dormand-Prince 8(5,3)), coefficients from scipy's
``dop853_coefficients`` (the same numbers as Hairer's Fortran code), 12 RHS calls per step
(the last stage of a step is the first of the next), Hairer's error norm (RMS of the 5th- and
3rd-order estimates combined, scale atol + rtol max(|y|, |y_new|)), scipy's controller
(safety 0.9, factor within [0.2, 10], exponent −1/8, no growth right after a rejection) and
Hairer's initial step. No events, no dense output: the cheapest honest single-trajectory loop.
"""

import numpy as np
from numba import njit
from scipy.integrate._ivp import dop853_coefficients as _D

# planar parameter row (kernels/planar_eom.py layout; not imported, to stay independent)
_MM, _INV_M, _K1, _F1, _K2, _F2 = 0, 1, 2, 3, 4, 5
_P2, _Q2, _P3, _Q3, _P4, _Q4, _X = 6, 9, 12, 16, 20, 25, 30
NSTATE = 10

_S = _D.N_STAGES                          # 12
A = np.ascontiguousarray(_D.A[:_S, :_S])
B = np.ascontiguousarray(_D.B)
C = np.ascontiguousarray(_D.C[:_S])
E3 = np.ascontiguousarray(_D.E3)           # 13 weights: stages 0..11 and the FSAL stage
E5 = np.ascontiguousarray(_D.E5)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0


def check_even(p):
    """Refuse parameter rows with order-3 (odd) coefficients: this baseline omits them."""
    p = np.atleast_2d(p)
    if np.any(p[:, _P3:_P3 + 4] != 0.0) or np.any(p[:, _Q3:_Q3 + 4] != 0.0):
        raise ValueError("the numba baseline supports bodies without odd inertia integrals "
                         "only (order-3 coefficients must be 0)")


@njit(cache=True, fastmath=False)
def rhs(p, y, out):
    """dy/dt of the planar state ``y`` for the parameter row ``p`` into ``out``."""
    r, vr, ell = y[0], y[1], y[2]
    ca, sa, w1, cb, sb, w2 = y[4], y[5], y[6], y[7], y[8], y[9]
    # harmonics of ψ from (cos ψ, sin ψ)
    c2a = ca * ca - sa * sa
    s2a = 2.0 * ca * sa
    c4a = c2a * c2a - s2a * s2a
    s4a = 2.0 * c2a * s2a
    c2b = cb * cb - sb * sb
    s2b = 2.0 * cb * sb
    c4b = c2b * c2b - s2b * s2b
    s4b = 2.0 * c2b * s2b
    # degree-2 and degree-4 series and their ψ-derivatives
    f2 = (p[_P2] + p[_P2 + 1] * c2a + p[_P2 + 2] * s2a) + (p[_Q2] + p[_Q2 + 1] * c2b
                                                            + p[_Q2 + 2] * s2b)
    d2a = 2.0 * (p[_P2 + 2] * c2a - p[_P2 + 1] * s2a)
    d2b = 2.0 * (p[_Q2 + 2] * c2b - p[_Q2 + 1] * s2b)
    f4a = p[_P4] + p[_P4 + 1] * c2a + p[_P4 + 2] * s2a + p[_P4 + 3] * c4a + p[_P4 + 4] * s4a
    f4b = p[_Q4] + p[_Q4 + 1] * c2b + p[_Q4 + 2] * s2b + p[_Q4 + 3] * c4b + p[_Q4 + 4] * s4b
    d4a = 2.0 * (p[_P4 + 2] * c2a - p[_P4 + 1] * s2a) + 4.0 * (p[_P4 + 4] * c4a - p[_P4 + 3] * s4a)
    d4b = 2.0 * (p[_Q4 + 2] * c2b - p[_Q4 + 1] * s2b) + 4.0 * (p[_Q4 + 4] * c4b - p[_Q4 + 3] * s4b)
    # quadrupole-quadrupole term: cos(2ψ_A − 2ψ_B) = c2a c2b + s2a s2b
    x0, xa, xb, xab, xm = p[_X], p[_X + 1], p[_X + 2], p[_X + 3], p[_X + 4]
    cm = c2a * c2b + s2a * s2b
    sm = s2a * c2b - c2a * s2b
    xx = x0 + xa * c2a + xb * c2b + xab * c2a * c2b + xm * cm
    dxa = -2.0 * s2a * (xa + xab * c2b) - 2.0 * xm * sm
    dxb = -2.0 * s2b * (xb + xab * c2a) + 2.0 * xm * sm
    u = 1.0 / r
    u2 = u * u
    u3 = u2 * u
    u5 = u3 * u2
    f4 = f4a + f4b + xx
    # ∂V/∂r of mm/r + f2/r³ + f4/r⁵, and ∂V/∂ψ_A, ∂V/∂ψ_B
    v_r = -u2 * (p[_MM] + 3.0 * f2 * u2 + 5.0 * f4 * u2 * u2)
    v_a = d2a * u3 + (d4a + dxa) * u5
    v_b = d2b * u3 + (d4b + dxb) * u5
    lam_dot = ell * u2
    rate_a = lam_dot - p[_F1] * w1
    rate_b = lam_dot - p[_F2] * w2
    inv_m = p[_INV_M]
    out[0] = vr
    out[1] = ell * lam_dot * u + inv_m * v_r
    out[2] = inv_m * (v_a + v_b)
    out[3] = lam_dot
    out[4] = -sa * rate_a
    out[5] = ca * rate_a
    out[6] = -p[_K1] * v_a
    out[7] = -sb * rate_b
    out[8] = cb * rate_b
    out[9] = -p[_K2] * v_b


@njit(cache=True)
def rhs_many(p, y, out):
    """:func:`rhs` of each row of ``y`` (N, 10) with its row of ``p`` (N, 37)."""
    for i in range(y.shape[0]):
        rhs(p[i], y[i], out[i])


@njit(cache=True)
def _rms(x, y_a, y_b, rtol, atol):
    s = 0.0
    for j in range(x.shape[0]):
        sc = atol + rtol * max(abs(y_a[j]), abs(y_b[j]))
        s += (x[j] / sc) ** 2
    return np.sqrt(s / x.shape[0])


@njit(cache=True)
def _initial_step(p, y0, f0, rtol, atol, work, f1):
    """Hairer's starting step (Hairer, Nørsett & Wanner I, II.4), order 8."""
    d0 = _rms(y0, y0, y0, rtol, atol)                  # scale atol + rtol |y0|
    d1 = _rms(f0, y0, y0, rtol, atol)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    for j in range(y0.shape[0]):
        work[j] = y0[j] + h0 * f0[j]
    rhs(p, work, f1)
    for j in range(y0.shape[0]):
        work[j] = f1[j] - f0[j]
    d2 = _rms(work, y0, y0, rtol, atol) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1)


@njit(cache=True)
def integrate(p, y0, t_end, rtol, atol):
    """One trajectory from t = 0 to ``t_end`` (scaled time) with DOP853; returns
    (final state, accepted steps, rejected steps, RHS calls)."""
    n = y0.shape[0]
    K = np.empty((_S + 1, n))
    y = y0.copy()
    y_new = np.empty(n)
    work = np.empty(n)
    rhs(p, y, K[0])
    nfev = 1
    h = _initial_step(p, y, K[0], rtol, atol, work, K[1])
    nfev += 1
    t = 0.0
    accepted = 0
    rejected = 0
    rejected_last = False
    while t < t_end:
        last = False
        if t + h >= t_end:
            h = t_end - t
            last = True
        for s in range(1, _S):
            for j in range(n):
                acc = 0.0
                for q in range(s):
                    acc += A[s, q] * K[q, j]
                work[j] = y[j] + h * acc
            rhs(p, work, K[s])
        for j in range(n):
            acc = 0.0
            for q in range(_S):
                acc += B[q] * K[q, j]
            y_new[j] = y[j] + h * acc
        rhs(p, y_new, K[_S])
        nfev += _S
        # Hairer's error estimate: |h| e5² / sqrt(e5² + 0.01 e3²), RMS over components
        e5 = 0.0
        e3 = 0.0
        for j in range(n):
            a5 = 0.0
            a3 = 0.0
            for q in range(_S + 1):
                a5 += E5[q] * K[q, j]
                a3 += E3[q] * K[q, j]
            sc = atol + rtol * max(abs(y[j]), abs(y_new[j]))
            e5 += (a5 / sc) ** 2
            e3 += (a3 / sc) ** 2
        if e5 == 0.0 and e3 == 0.0:
            err = 0.0
        else:
            err = abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)
        if err <= 1.0:
            t = t_end if last else t + h
            for j in range(n):
                y[j] = y_new[j]
                K[0, j] = K[_S, j]
            accepted += 1
            if err == 0.0:
                factor = MAX_FACTOR
            else:
                factor = min(MAX_FACTOR, SAFETY * err ** (-1.0 / 8.0))
            if rejected_last:
                factor = min(1.0, factor)
            h *= factor
            rejected_last = False
        else:
            h *= max(MIN_FACTOR, SAFETY * err ** (-1.0 / 8.0))
            rejected += 1
            rejected_last = True
    return y, accepted, rejected, nfev


@njit(cache=True)
def integrate_many(p, y0, t_end, rtol, atol, y_out, counters):
    """Members one after the other on the calling thread (one core): row i of ``y0`` with
    row i of ``p`` to ``t_end``; final states into ``y_out``, (accepted, rejected, RHS calls)
    into ``counters``."""
    for i in range(y0.shape[0]):
        y, a, r, f = integrate(p[i], y0[i], t_end, rtol, atol)
        y_out[i, :] = y
        counters[i, 0] = a
        counters[i, 1] = r
        counters[i, 2] = f
