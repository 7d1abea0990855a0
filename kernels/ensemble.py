"""Ensemble kernels: every member advances with its own adaptive Cash-Karp loop in one launch.

One launch of :func:`advance` takes each running member from its current time to its window
end ``t_end[i]`` (scaled units). On the way it records

* pericentre crossings (osculating true anomaly through 0, i.e. g = R·V changing sign from
  − to +), located inside the step by Newton iteration on g(τ) where the state at τ comes
  from a Cash-Karp step of length τ from the step start, so the event state carries the
  integrator's own local accuracy (near the tolerance), not an interpolant's;
* optionally (``sampling``), the state at a regular grid of times (steps are shortened to
  land on them), for libration and spin-rate time series.

A member whose event or sample buffer fills stops where it is and resumes in the next
launch, so nothing is lost whatever the window length. A member that fails is stopped with a
status code and keeps everything recorded so far.

Status codes (``STATUS_NAMES`` gives the words).
"""

import taichi as ti

from . import eom
from .eom import (NSTATE, P_CONTACT, P_ESCAPE, Y_R, Y_S, Y_S1, get3, get33, state)
from .integrator import error_norm, make_step, step_factor
from .potential import mutual, vec3
from .tableau import CASH_KARP

RUNNING, DONE, COLLISION, ESCAPE, STEP_UNDERFLOW, NONFINITE = range(6)
STATUS_NAMES = ("running", "done", "collision", "escape", "step underflow", "non-finite")

# Columns of the event buffer and of the sample buffer.
EVENT_FIELDS = ("t", "theta_p", "thetadot_p", "r", "a", "e")
SAMPLE_FIELDS = ("t", "alpha", "theta", "thetadot", "r", "energy")
DIAG_FIELDS = ("E_orbit", "E_primary", "E_secondary",
               "L_orbit_x", "L_orbit_y", "L_orbit_z", "L_primary_x", "L_primary_y",
               "L_primary_z", "L_secondary_x", "L_secondary_y", "L_secondary_z",
               "orth_S", "orth_S1")
# Counter columns.
C_ACCEPTED, C_REJECTED, C_RHS = 0, 1, 2

NEWTON_MAX_ITER = 8

nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
nd3f = ti.types.ndarray(dtype=ti.f64, ndim=3)
nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)
nd2l = ti.types.ndarray(dtype=ti.i64, ndim=2)

rk_step = make_step(eom.rhs, CASH_KARP)
_EXPONENT = 1.0 / CASH_KARP.order  # controller exponent: the error estimate is O(h^5)


@ti.func
def _load(a: ti.template(), i):
    y = state(0.0)
    for k in ti.static(range(NSTATE)):
        y[k] = a[i, k]
    return y


@ti.func
def _store(a: ti.template(), i, y):
    for k in ti.static(range(NSTATE)):
        a[i, k] = y[k]


@ti.func
def _locate_pericentre(p: ti.template(), i, y, f0, g0, g1, h, order: ti.template(),
                       odd: ti.template()):
    """Newton iteration for g(τ) = 0 on (0, h]; returns (τ, y(τ), rhs evaluations)."""
    tau = h * g0 / (g0 - g1)        # secant guess, then Newton with exact-step states
    yt = y
    calls = 0
    for _ in range(NEWTON_MAX_ITER):
        dyt, errt = rk_step(p, i, y, f0, tau, order, odd)
        yt = y + dyt
        ft = eom.rhs(p, i, yt, order, odd)
        calls += 6
        g = eom.pericentre_function(yt)
        gp = eom.pericentre_rate(yt, ft)
        step = g / gp
        new_tau = ti.min(h, ti.max(0.0, tau - step))
        converged = ti.abs(new_tau - tau) <= 4e-16 * h + 1e-300
        if converged:
            break
        tau = new_tau
    return tau, yt, calls


@ti.kernel
def advance(par: nd2f, y_nd: nd2f, yc_nd: nd2f, t_nd: nd1f, tc_nd: nd1f, h_nd: nd1f,
            t_end: nd1f, status: nd1i, counters: nd2l,
            events: nd3f, n_events: nd1i, samples: nd3f, n_samples: nd1i, next_sample: nd1f,
            rtol: ti.f64, atol: ti.f64, min_step: ti.f64, sample_dt: ti.f64,
            order: ti.template(), odd: ti.template(), sampling: ti.template()):
    """Advance every running member to t_end[i] (or until a buffer is full / it fails)."""
    cap = events.shape[1]
    scap = samples.shape[1]
    for i in range(y_nd.shape[0]):
        if status[i] == RUNNING:
            y = _load(y_nd, i)
            yc = _load(yc_nd, i)       # Kahan compensation of y
            t = t_nd[i]
            tc = tc_nd[i]              # Kahan compensation of t
            h = h_nd[i]
            te = t_end[i]
            st = RUNNING
            nev = n_events[i]
            nsm = n_samples[i]
            acc = 0
            rej = 0
            calls = 1
            after_reject = 0
            bad_value = 0
            f0 = eom.rhs(par, i, y, order, odd)
            while t < te and st == RUNNING and nev < cap and nsm < scap:
                hs = h
                to_end = te - t
                if to_end <= hs:
                    hs = to_end
                hit_sample = 0
                if ti.static(sampling):
                    to_sample = next_sample[i] - t
                    if to_sample <= hs:
                        hs = to_sample
                        hit_sample = 1
                dy, err = rk_step(par, i, y, f0, hs, order, odd)
                y_new = y + dy
                en = error_norm(y, y_new, err, rtol, atol, NSTATE)
                calls += 5
                if en <= 1.0:
                    f1 = eom.rhs(par, i, y_new, order, odd)
                    calls += 1
                    g0 = eom.pericentre_function(y)
                    g1 = eom.pericentre_function(y_new)
                    if g0 < 0.0 and g1 >= 0.0:
                        tau, ye, c = _locate_pericentre(par, i, y, f0, g0, g1, hs, order, odd)
                        calls += c
                        theta_p, thetadot_p = eom.section_angles(par, i, ye)
                        a_osc, e_osc = eom.osculating_elements(ye)
                        events[i, nev, 0] = t + tau + tc
                        events[i, nev, 1] = theta_p
                        events[i, nev, 2] = thetadot_p
                        events[i, nev, 3] = get3(ye, Y_R).norm()
                        events[i, nev, 4] = a_osc
                        events[i, nev, 5] = e_osc
                        nev += 1
                    # Kahan-compensated updates of y and t
                    yk = dy - yc
                    ysum = y + yk
                    yc = (ysum - y) - yk
                    y = ysum
                    tk = hs - tc
                    tsum = t + tk
                    tc = (tsum - t) - tk
                    t = tsum
                    if hit_sample == 1 or to_end <= hs:
                        # landed on a sample time or the window end: snap to the exact value
                        t = t + tc
                        tc = 0.0
                        if hit_sample == 1:
                            t = next_sample[i]
                        else:
                            t = te
                    f0 = f1
                    acc += 1
                    fac = step_factor(en, after_reject, _EXPONENT)
                    if not (hs < h and fac >= 1.0):
                        h = hs * fac            # (a shortened step that did well keeps h)
                    after_reject = 0
                    if ti.static(sampling):
                        if hit_sample == 1:
                            alpha, thetadot = eom.section_angles(par, i, y)
                            S = get33(y, Y_S)
                            S1 = get33(y, Y_S1)
                            xin = S1 @ vec3(S[0, 0], S[1, 0], S[2, 0])
                            e_orb, e1, e2 = eom.energy_split(par, i, y, order, odd)
                            samples[i, nsm, 0] = t
                            samples[i, nsm, 1] = alpha
                            samples[i, nsm, 2] = ti.atan2(xin[1], xin[0])
                            samples[i, nsm, 3] = thetadot
                            samples[i, nsm, 4] = get3(y, Y_R).norm()
                            samples[i, nsm, 5] = e_orb + e1 + e2
                            nsm += 1
                            next_sample[i] += sample_dt
                    # stopping conditions after an accepted step
                    R = get3(y, Y_R)
                    r = R.norm()
                    if not (r == r):
                        st = NONFINITE
                    elif r <= par[i, P_CONTACT]:
                        st = COLLISION
                    elif r >= par[i, P_ESCAPE]:
                        st = ESCAPE
                    else:
                        a_osc, e_osc = eom.osculating_elements(y)
                        if a_osc < 0.0 and g1 > 0.0:   # unbound and receding
                            st = ESCAPE
                else:
                    rej += 1
                    if en > 1e300:
                        bad_value = 1
                        h = hs * 0.2
                    else:
                        h = hs * step_factor(en, 1, _EXPONENT)
                        bad_value = 0
                    after_reject = 1
                    if h < min_step:
                        st = ti.select(bad_value == 1, NONFINITE, STEP_UNDERFLOW)
            _store(y_nd, i, y)
            _store(yc_nd, i, yc)
            t_nd[i] = t
            tc_nd[i] = tc
            h_nd[i] = h
            status[i] = st
            n_events[i] = nev
            n_samples[i] = nsm
            counters[i, C_ACCEPTED] += acc
            counters[i, C_REJECTED] += rej
            counters[i, C_RHS] += calls


@ti.kernel
def diagnostics(par: nd2f, y_nd: nd2f, out: nd2f, order: ti.template(), odd: ti.template()):
    """Energy and angular-momentum split and orthonormality errors (columns DIAG_FIELDS)."""
    for i in range(y_nd.shape[0]):
        y = _load(y_nd, i)
        e_orb, e1, e2 = eom.energy_split(par, i, y, order, odd)
        l_orb, l1, l2 = eom.angular_momentum_split(par, i, y)
        o, o1 = eom.orthonormality_error(y)
        out[i, 0] = e_orb
        out[i, 1] = e1
        out[i, 2] = e2
        for k in ti.static(range(3)):
            out[i, 3 + k] = l_orb[k]
            out[i, 6 + k] = l1[k]
            out[i, 9 + k] = l2[k]
        out[i, 12] = o
        out[i, 13] = o1


@ti.kernel
def evaluate_rhs(par: nd2f, y_nd: nd2f, out: nd2f, order: ti.template(), odd: ti.template()):
    """dy/dt for each row of y (tests compare it with the NumPy reference)."""
    for i in range(y_nd.shape[0]):
        _store(out, i, eom.rhs(par, i, _load(y_nd, i), order, odd))


@ti.kernel
def evaluate_mutual(par: nd2f, R_nd: nd2f, S_nd: nd3f, out: nd2f, G: ti.f64,
                    order: ti.template(), odd: ti.template()):
    """Mutual potential for each row: out = [U, dU/dR (3), mu1 (3), mu2 (3)]."""
    for i in range(R_nd.shape[0]):
        R = vec3(R_nd[i, 0], R_nd[i, 1], R_nd[i, 2])
        S = ti.Matrix([[S_nd[i, r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
        U, dUdR, mu1, mu2 = mutual(par, i, eom.BODY_A, eom.BODY_B, G, R, S, order, odd)
        out[i, 0] = U
        for k in ti.static(range(3)):
            out[i, 1 + k] = dUdR[k]
            out[i, 4 + k] = mu1[k]
            out[i, 7 + k] = mu2[k]
