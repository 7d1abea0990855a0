"""Ensemble kernels: every member advances with its own adaptive Runge-Kutta loop in one launch.

The method (a ``tableau.Tableau``: Cash-Karp 4(5), the default, DOP853 or Verner 9(8)) and the
step-size policy (a ``controller.Controller``) are arguments of the kernel factory
:func:`make_kernels`; :func:`kernels_for` builds and caches one kernel set per (model, method).

One launch of :func:`advance` takes each running member from its current time until its
first accepted step that reaches ``t_end[i]`` (a soft window end: steps are never shortened
for it, so results do not depend on the window length) and never past ``t_stop[i]`` (the hard
end: the last step lands on it exactly). On the way it records

* pericentre crossings (osculating true anomaly through 0, i.e. g = R·V changing sign from
  − to +): time and full state at the crossing. The crossing is located inside the accepted
  step by Newton iteration on g(τ), where the state at τ comes from a step of the same method of
  length τ from the step start, so event states carry the integrator's own local accuracy
  (near the tolerance), not an interpolant's;
* optionally (``sampling``), time and state on a regular time grid (steps are shortened to
  land on it) for libration and spin-rate time series.

Observables (θ_p, θ̇_p, α, osculating elements, energies) are derived from the recorded
states afterwards (``ti_spinorbit.model.observables``), which keeps the kernel small.

The member loop is a state machine with exactly one call site of the right-hand side: each
pass of the while loop evaluates one stage of a trial step, or the derivative at an accepted
step's end (the next step's first stage), or one Newton iterate of an event. Inlined copies
of the RHS dominate compile time (see ``integrator.py``), so this is what keeps a cold
compile in seconds instead of minutes.

A member whose event or sample buffer fills stops after that step and resumes in the next
launch from exactly the same state (Kahan compensations, step proposal and first-stage
derivative are stored), so nothing is lost and nothing changes. A member that fails is
stopped with a status code and keeps everything recorded so far.
"""

from types import SimpleNamespace

import taichi as ti

from ti_spinorbit.layout import multipole as _MP
from ti_spinorbit.layout import (C_ACCEPTED, C_REJECTED, C_RHS, COLLISION, DIAG_FIELDS, DONE,
                                 ESCAPE, INACCURATE, NONFINITE, RECORD_WIDTH, RUNNING,
                                 STATUS_NAMES, STEP_BUDGET, STEP_UNDERFLOW)

from . import eom, perturb, planar_eom
from .eom import NSTATE
from .controller import DEFAULT_CONTROLLER, NONFINITE_ERROR
from .integrator import make_error_norm, make_primitives, stage_matrix_type
from .mutual_gravity import mutual, vec3
from .tableau import CASH_KARP, DEFAULT_METHOD, METHODS, check_method

# Status codes, record width, diagnostics and counter columns are ti_spinorbit.layout's.
# INACCURATE is set on the host only, by the accuracy check; STEP_BUDGET when a member's
# accepted + rejected steps reach the launch's ``max_steps`` (stopped at its last accepted
# state, everything recorded kept). The host imports them from there, not from here.

NEWTON_MAX_ITER = DEFAULT_CONTROLLER.event_max_iter
#: Orders up to this one use the hand-written potential; the kernels take
#: ``KERNEL_ORDER`` as their ``order`` template for every order above it (the tables carry
#: the true order: ``kernels/harmonic_gravity.py``).
HAND_WRITTEN_MAX, KERNEL_ORDER = _MP.HAND_WRITTEN_MAX, _MP.KERNEL_ORDER
#: Largest stage matrix (stages x state components) kept in registers with unrolled
#: component loops: Cash-Karp planar (6 x 10). Larger ones (Cash-Karp 3-D 6 x 30, DOP853
#: 12 x 10 and 12 x 30) spill anyway, and unrolled they took 3-6x longer to compile
#: (docs/design.md, "Compile time").
UNROLL_LIMIT = 60
_STEP, _LOCATE = 0, 1

nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
nd3f = ti.types.ndarray(dtype=ti.f64, ndim=3)
nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)
nd2l = ti.types.ndarray(dtype=ti.i64, ndim=2)


def make_kernels(model, tableau=CASH_KARP, controller=DEFAULT_CONTROLLER, unroll_components=None,
                 perturbed=False):
    """``advance`` and ``evaluate_rhs`` kernels for one model of the equations of motion,
    integrating with ``tableau`` under the step-size policy ``controller``.

    ``model`` is a module (``eom`` for the 3-D model, ``planar`` for the planar one) that
    provides NSTATE, state, rhs, pericentre_function, pericentre_rate, osculating_elements,
    distance, P_CONTACT and P_ESCAPE. Kernels compile on first call, per model and variant.

    ``unroll_components`` (default: only when the stage matrix has at most
    ``UNROLL_LIMIT`` entries, i.e. Cash-Karp on the planar model) unrolls the stage
    combinations over the state components so the stage matrix lives in registers; otherwise
    they are runtime loops (``integrator.make_primitives``; docs/design.md, "Compile time").

    ``perturbed`` integrates the model's ``rhs_perturbed`` (tides, YORP, BYORP from a
    block of ``perturb.NPERT`` columns after the model's parameters) and carries the
    ``perturb.NACC`` accumulators (work, external angular momentum) after the model's state;
    they ride in every step, record and checkpoint but not in the error norm.
    """
    NSTATE = model.NSTATE                   # what the error norm holds to the tolerance
    NK = NSTATE + (perturb.NACC if perturbed else 0)   # what the kernel carries
    if unroll_components is None:   # decided by the model's state: the perturbed planar
        # Cash-Karp kernel (6 x 14) unrolled runs 17 % faster (and now compiles in about 1 s)
        unroll_components = tableau.stages * NSTATE <= UNROLL_LIMIT
    state = model.state_perturbed if perturbed else model.state
    # the order-N arguments (integral rows, scratch, tables) ride along; order <= 4 never
    # reads them and compiles the code it always did
    rhs = model.rhs_perturbed_mp if perturbed else model.rhs_mp
    rhs_at_stage = rhs       # the perturbed RHS takes the stage's time last (the Sun moves)
    if perturbed:
        @ti.func
        def rhs(p: ti.template(), i, y, order: ti.template(), odd: ti.template(),
                mpr: ti.template(), mps: ti.template(), mpi: ti.template(), mpf: ti.template()):
            return rhs_at_stage(p, i, y, order, odd, mpr, mps, mpi, mpf, 0.0)   # at t = 0
    stage_point, combine, put_stage = make_primitives(tableau, NK, unroll_components)
    kmat = stage_matrix_type(tableau, NK)
    error_norm = make_error_norm(tableau, unroll_components)
    ctl = controller.funcs()
    _STAGES = tableau.stages
    # the stage nodes c_s, then 1.0 for the end point (the perturbed RHS's stage times)
    _NODES = tuple(float(c) for c in tableau.c) + (1.0,)
    _EXPONENT = tableau.error_exponent   # 1/5 Cash-Karp (error O(h^5)), 1/8 DOP853, 1/9 Verner

    @ti.func
    def _trial_size(h, t, ts, t_sample, sampling: ti.template()):
        """Size of the next trial step from t with proposal h, shortened to land on the hard
        end ts or (``sampling``) on the next sample time: (hs, hit_end, hit_sample)."""
        hs = h
        hit_end = 0
        hit_sample = 0
        if ts - t <= hs:
            hs = ts - t
            hit_end = 1
        if ti.static(sampling):
            if t_sample - t <= hs:
                hs = t_sample - t
                hit_sample = 1
                hit_end = 0
                if ts - t <= hs:
                    hit_end = 1
        return hs, hit_end, hit_sample

    @ti.func
    def _newton_tau(y_tau, f_tau, tau, h_step):
        """One Newton iterate for the event time τ in [0, h_step] from the state y(τ) and
        its derivative: τ − g/g' with g the pericentre function."""
        g = model.pericentre_function(y_tau)
        gp = model.pericentre_rate(y_tau, f_tau)
        return ti.min(h_step, ti.max(0.0, tau - g / gp))

    @ti.func
    def _renormalised_shadow(y, ys_try, fy, f_s1, d0):
        """The shadow's log growth over the step and its state and derivative renormalised
        to the separation d0 (the derivative rescaled linearly: exact to O(d0²)), and
        whether it moved at all: (dl, y_s, f_s, grew)."""
        delta = ys_try - y
        for k in ti.static(range(NSTATE, NK)):  # accumulators: the shadow shares the member's
            delta[k] = 0.0
        d = delta.norm()
        dl = 0.0
        y_s = ys_try
        f_s = f_s1
        grew = 0
        if d > 0.0:
            dl = ti.log(d / d0)
            scale = d0 / d
            y_s = y + delta * scale
            f_s = fy + (f_s1 - fy) * scale
            grew = 1
        return dl, y_s, f_s, grew

    @ti.func
    def _kahan_add(x, comp, dx):
        """x + dx with Kahan compensation comp (the true sum is x - comp): (sum, new comp)."""
        xk = dx - comp
        xsum = x + xk
        return xsum, (xsum - x) - xk

    @ti.func
    def _stop_status(par: ti.template(), i, y):
        """RUNNING, or why member i stops at the accepted state y: non-finite, collision
        (distance at most P_CONTACT), escape (beyond P_ESCAPE, or unbound and receding)."""
        st = RUNNING
        r = model.distance(y)
        if not (r == r):
            st = NONFINITE
        elif r <= par[i, model.P_CONTACT]:
            st = COLLISION
        elif r >= par[i, model.P_ESCAPE]:
            st = ESCAPE
        else:
            a_osc, e_osc = model.osculating_elements(y)
            if a_osc < 0.0 and model.pericentre_function(y) > 0.0:
                st = ESCAPE                     # unbound and receding
        return st

    # Whole-state copies (loads, stores, records, a stage row): unrolled when the state lives
    # in registers (``unroll_components``), else runtime loops over the components. Taichi
    # lowers every unrolled assignment by rescanning the whole kernel (quadratic in its size),
    # so the 3-D kernels' dozen 30-component copies cost 0.1-0.2 s of compile each; the copies
    # are exact either way.
    @ti.func
    def _load(a: ti.template(), i):
        y = state(0.0)
        if ti.static(unroll_components):
            for k in ti.static(range(NK)):
                y[k] = a[i, k]
        else:
            for k in range(NK):
                y[k] = a[i, k]
        return y

    @ti.func
    def _store(a: ti.template(), i, y):
        if ti.static(unroll_components):
            for k in ti.static(range(NK)):
                a[i, k] = y[k]
        else:
            for k in range(NK):
                a[i, k] = y[k]

    @ti.func
    def _record(buf: ti.template(), i, slot, t, y):
        buf[i, slot, 0] = t
        if ti.static(unroll_components):
            for k in ti.static(range(NK)):
                buf[i, slot, 1 + k] = y[k]
        else:
            for k in range(NK):
                buf[i, slot, 1 + k] = y[k]

    @ti.func
    def _set_first_stage(K: ti.template(), v):
        """Row 0 of the stage matrix K = v."""
        if ti.static(unroll_components):
            for k in ti.static(range(NK)):
                K[0, k] = v[k]
        else:
            for k in range(NK):
                K[0, k] = v[k]

    @ti.func
    def _first_stage(K: ti.template()):
        """Row 0 of the stage matrix K (the first stage) as a state vector."""
        v = state(0.0)
        if ti.static(unroll_components):
            for k in ti.static(range(NK)):
                v[k] = K[0, k]
        else:
            for k in range(NK):
                v[k] = K[0, k]
        return v

    @ti.kernel
    def advance(par: nd2f, y_nd: nd2f, yc_nd: nd2f, f_nd: nd2f, t_nd: nd1f, tc_nd: nd1f,
                h_nd: nd1f, t_end: nd1f, t_stop: nd1f, status: nd1i, counters: nd2l,
                events: nd3f, n_events: nd1i, samples: nd3f, n_samples: nd1i, next_sample: nd1f,
                shadow_nd: nd2f, shadow_f_nd: nd2f, ind: nd2f,
                mpr: nd1f, mps: nd1f, mpi: nd1i, mpf: nd1f,
                rtol: ti.f64, atol: ti.f64, min_step: ti.f64, sample_dt: ti.f64, d0: ti.f64,
                max_steps: ti.i64, order: ti.template(), odd: ti.template(), sampling: ti.template(),
                indicators: ti.template()):
        """Advance every running member (see the module docstring)."""
        cap = events.shape[1]
        scap = samples.shape[1]
        _nodes = ti.Vector(_NODES, ti.f64)
        for i in range(y_nd.shape[0]):
            if status[i] == RUNNING:
                y = _load(y_nd, i)
                yc = _load(yc_nd, i)            # Kahan compensation of y
                f0 = _load(f_nd, i)             # dy/dt at (t, y): first stage of the next step
                # NaN: not evaluated yet (a fresh run): the first pass evaluates it, at the one
                # RHS call site (stage 0), instead of a separate kernel to trace and compile
                first_stage_pending = 0
                if not (f0[0] == f0[0]):
                    first_stage_pending = 1
                t = t_nd[i]
                tc = tc_nd[i]                   # Kahan compensation of t
                h = h_nd[i]                     # step proposal
                te = t_end[i]
                ts = t_stop[i]
                st = RUNNING
                nev = n_events[i]
                nsm = n_samples[i]
                acc = 0
                rej = 0
                # steps left before the budget (counters carry every earlier launch's, so a
                # resumed run stops at the same step as an uninterrupted one)
                budget = max_steps - counters[i, C_ACCEPTED] - counters[i, C_REJECTED]
                calls = 0
                after_reject = 0
                K = kmat(0.0)
                if first_stage_pending == 0:
                    _set_first_stage(K, f0)
                # shadow trajectory (chaos indicators): same steps, its own stages in K2
                y_s = state(0.0)
                ys_try = state(0.0)
                f_s1 = state(0.0)
                K2 = kmat(0.0)
                ell = 0.0
                s_weighted = 0.0
                ybar_int = 0.0
                if ti.static(indicators):
                    y_s = _load(shadow_nd, i)
                    if first_stage_pending == 0:
                        _set_first_stage(K2, _load(shadow_f_nd, i))
                    ell = ind[i, 0]
                    s_weighted = ind[i, 1]
                    ybar_int = ind[i, 2]
                # trial-step and event-location state
                new_attempt = 1
                mode = _STEP
                stage = 1
                hs = h
                hit_end = 0
                hit_sample = 0
                dy = state(0.0)
                y_try = y
                en = 0.0
                dy_acc = state(0.0)
                f_acc = state(0.0)
                hs_acc = 0.0
                en_acc = 0.0
                g0 = 0.0
                tau = 0.0
                it = 0
                while st == RUNNING and t < te and nev < cap and nsm < scap:
                    if new_attempt == 1:         # a new trial step from (t, y) with proposal h
                        hs, hit_end, hit_sample = _trial_size(h, t, ts, next_sample[i],
                                                              sampling)
                        stage = 1 - first_stage_pending
                        new_attempt = 0
                    copies = 1
                    if ti.static(indicators):
                        if mode == _STEP:
                            copies = 2                          # the shadow rides along
                    fy = state(0.0)
                    for copy in range(copies):                  # runtime loop: one call site
                        pt = y_try
                        if copy == 0:
                            if stage == 0:
                                pt = y
                            elif stage < _STAGES:
                                pt = stage_point(y, K, hs, stage)
                        else:
                            pt = ys_try
                            if stage == 0:
                                pt = y_s
                            elif stage < _STAGES:
                                pt = stage_point(y_s, K2, hs, stage)
                        fc = state(0.0)
                        if ti.static(perturbed):   # time-dependent fields (the Sun) need
                            # the stage's time: t (Kahan: true t = t - tc) + c_s h, and t + h
                            # at the end point (stage == _STAGES)
                            t_stage = (t - tc) + _nodes[stage] * hs
                            fc = rhs_at_stage(par, i, pt, order, odd, mpr, mps, mpi, mpf, t_stage)
                        else:
                            fc = rhs(par, i, pt, order, odd, mpr, mps, mpi, mpf)  # the only RHS call site
                        if stage > 0 or copy == 0:    # (the shadow's start is not counted)
                            calls += 1
                        if copy == 0:
                            fy = fc
                        elif stage < _STAGES:
                            put_stage(K2, stage, fc)
                        else:
                            f_s1 = fc
                    do_accept = 0
                    if stage < _STAGES:
                        put_stage(K, stage, fy)
                        if stage == 0:
                            f0 = fy
                            first_stage_pending = 0
                        stage += 1
                        if stage == _STAGES:
                            dy, err, err3 = combine(K, hs, True)
                            y_try = y + dy
                            if ti.static(indicators):
                                if mode == _STEP:
                                    dy_s, err_s, err3_s = combine(K2, hs, False)   # its step is never judged
                                    ys_try = y_s + dy_s
                            en = error_norm(y, y_try, err, err3, rtol, atol, NSTATE)
                            if mode == _STEP and en > 1.0:
                                rej += 1
                                h = ctl.rejected(hs, en, _EXPONENT)
                                after_reject = 1
                                new_attempt = 1
                                if h < min_step:
                                    st = ti.select(en >= NONFINITE_ERROR, NONFINITE, STEP_UNDERFLOW)
                                elif acc + rej >= budget:
                                    st = STEP_BUDGET
                    elif mode == _STEP:                         # fy = f(y_try) of an accepted step
                        g0 = model.pericentre_function(y)
                        g1 = model.pericentre_function(y_try)
                        if g0 < 0.0 and g1 >= 0.0:
                            dy_acc = dy
                            f_acc = fy
                            hs_acc = hs
                            en_acc = en
                            tau = hs * g0 / (g0 - g1)           # secant guess, then Newton
                            it = 0
                            mode = _LOCATE
                            hs = tau
                            stage = 1
                        else:
                            do_accept = 1
                    else:                                       # Newton iterate at y_try = y(τ)
                        new_tau = _newton_tau(y_try, fy, tau, hs_acc)
                        it += 1
                        if ctl.event_converged(new_tau, tau, hs_acc, it):
                            _record(events, i, nev, t - tc + tau, y_try)   # Kahan: true t = t - tc
                            nev += 1
                            mode = _STEP
                            dy = dy_acc
                            fy = f_acc
                            hs = hs_acc
                            en = en_acc
                            do_accept = 1
                        else:
                            tau = new_tau
                            hs = tau
                            stage = 1
                    if do_accept == 1:
                        t_mid = t + 0.5 * hs
                        y, yc = _kahan_add(y, yc, dy)           # Kahan-compensated y += dy
                        t, tc = _kahan_add(t, tc, hs)           # and t += hs
                        if hit_sample == 1 or hit_end == 1:     # landed on a grid time: exact
                            tc = 0.0
                            t = ti.select(hit_end == 1, ts, next_sample[i])
                        f0 = fy
                        _set_first_stage(K, fy)
                        if ti.static(indicators):
                            dl, ys_new, fs_new, grew = _renormalised_shadow(y, ys_try, fy, f_s1,
                                                                            d0)
                            if grew == 1:
                                ell += dl
                                s_weighted += t_mid * dl
                                ybar_int += 2.0 * s_weighted / t * hs
                                y_s = ys_new
                                _set_first_stage(K2, fs_new)
                        acc += 1
                        # (a step shortened for a sample or the end that did well keeps h)
                        h = ctl.accepted(h, hs, en, after_reject, hit_end == 1 or hit_sample == 1,
                                         _EXPONENT)
                        after_reject = 0
                        new_attempt = 1
                        if ti.static(sampling):
                            if hit_sample == 1:
                                _record(samples, i, nsm, t, y)
                                nsm += 1
                                next_sample[i] += sample_dt
                        st = _stop_status(par, i, y)
                        if st == RUNNING and t < ts and acc + rej >= budget:
                            st = STEP_BUDGET
                _store(y_nd, i, y)
                _store(yc_nd, i, yc)
                _store(f_nd, i, f0)
                if ti.static(indicators):
                    _store(shadow_nd, i, y_s)
                    _store(shadow_f_nd, i, _first_stage(K2))
                    ind[i, 0] = ell
                    ind[i, 1] = s_weighted
                    ind[i, 2] = ybar_int
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
    def evaluate_rhs(par: nd2f, y_nd: nd2f, out: nd2f, order: ti.template(), odd: ti.template()):
        """dy/dt for each row of y (also the first stage of every member's first step)."""
        ti.static_assert(order <= HAND_WRITTEN_MAX, "evaluate_rhs: order > 4 needs evaluate_rhs_mp")
        for i in range(y_nd.shape[0]):
            _store(out, i, rhs(par, i, _load(y_nd, i), order, odd, par, par, par, par))

    @ti.kernel
    def evaluate_rhs_mp(par: nd2f, y_nd: nd2f, out: nd2f, mpr: nd1f, mps: nd1f, mpi: nd1i,
                        mpf: nd1f, order: ti.template(), odd: ti.template()):
        """:func:`evaluate_rhs` at any order (order-N rows, scratch row i, tables)."""
        for i in range(y_nd.shape[0]):
            _store(out, i, rhs(par, i, _load(y_nd, i), order, odd, mpr, mps, mpi, mpf))

    return SimpleNamespace(advance=advance, evaluate_rhs=evaluate_rhs,
                           evaluate_rhs_mp=evaluate_rhs_mp, load=_load,
                           NSTATE=NK, MODEL_NSTATE=NSTATE, RECORD_WIDTH=1 + NK, model=model,
                           tableau=tableau, controller=controller, perturbed=bool(perturbed))


#: The 3-D model's kernels (30-number state) and the planar model's (10 numbers), Cash-Karp.
SPATIAL = make_kernels(eom)
PLANAR = make_kernels(planar_eom)
_KERNEL_SETS = {("3d", DEFAULT_METHOD): SPATIAL, ("planar", DEFAULT_METHOD): PLANAR}


def kernels_for(model, method=DEFAULT_METHOD, perturbed=False, controller=None):
    """The kernel set of ``model`` ("planar" or "3d") integrating with ``method`` (a name of
    ``tableau.METHODS``), with or without perturbations, under ``controller`` (None: the
    default step-size policy), built once per process (Taichi compiles each on first
    launch)."""
    if controller == DEFAULT_CONTROLLER:
        controller = None
    key = (model, check_method(method)) + (("perturbed",) if perturbed else ()) + \
        ((controller,) if controller is not None else ())
    if key not in _KERNEL_SETS:
        _KERNEL_SETS[key] = make_kernels(planar_eom if model == "planar" else eom, METHODS[method],
                                         controller or DEFAULT_CONTROLLER, perturbed=perturbed)
    return _KERNEL_SETS[key]
advance = SPATIAL.advance
evaluate_rhs = SPATIAL.evaluate_rhs


_load_spatial = SPATIAL.load


@ti.func
def _diagnose(par: ti.template(), i, k, y_nd: ti.template(), out: ti.template(),
              order: ti.template(), odd: ti.template(), mpr: ti.template(), mps: ti.template(),
              mpi: ti.template(), mpf: ti.template()):
    """DIAG_FIELDS of state y_nd[k] of member i into out[k] (order-N scratch row k)."""
    y = _load_spatial(y_nd, k)
    e_orb, e1, e2 = eom.energy_split_mp(par, i, y, order, odd, mpr, mps, k, mpi, mpf)
    l_orb, l1, l2 = eom.angular_momentum_split(par, i, y)
    o, o1 = eom.orthonormality_error(y)
    out[k, 0] = e_orb
    out[k, 1] = e1
    out[k, 2] = e2
    for c in ti.static(range(3)):
        out[k, 3 + c] = l_orb[c]
        out[k, 6 + c] = l1[c]
        out[k, 9 + c] = l2[c]
    out[k, 12] = o
    out[k, 13] = o1


@ti.kernel
def diagnostics(par: nd2f, y_nd: nd2f, member: nd1i, out: nd2f, order: ti.template(),
                odd: ti.template()):
    """Energy and angular-momentum split and orthonormality errors (columns DIAG_FIELDS) of
    states y_nd[k] belonging to members member[k] (order <= 4)."""
    ti.static_assert(order <= HAND_WRITTEN_MAX, "diagnostics: order > 4 needs diagnostics_mp")
    for k in range(y_nd.shape[0]):
        _diagnose(par, member[k], k, y_nd, out, order, odd, par, par, par, par)


@ti.kernel
def diagnostics_mp(par: nd2f, y_nd: nd2f, member: nd1i, out: nd2f, mpr: nd1f, mps: nd1f,
                   mpi: nd1i, mpf: nd1f, order: ti.template(), odd: ti.template()):
    """:func:`diagnostics` at any order: member[k]'s order-N integral row, scratch row k."""
    for k in range(y_nd.shape[0]):
        _diagnose(par, member[k], k, y_nd, out, order, odd, mpr, mps, mpi, mpf)


@ti.kernel
def evaluate_mutual(par: nd2f, R_nd: nd2f, S_nd: nd3f, out: nd2f, G: ti.f64,
                    order: ti.template(), odd: ti.template()):
    """Mutual potential for each row: out = [U, dU/dR (3), mu1 (3), mu2 (3)]."""
    for i in range(R_nd.shape[0]):
        R = vec3(R_nd[i, 0], R_nd[i, 1], R_nd[i, 2])
        S = ti.Matrix([[S_nd[i, r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
        U, dUdR, mu1, mu2 = mutual(par, i, eom.BODY_A, eom.BODY_B, G, R, S, order, odd)
        out[i, 0] = U
        for c in ti.static(range(3)):
            out[i, 1 + c] = dUdR[c]
            out[i, 4 + c] = mu1[c]
            out[i, 7 + c] = mu2[c]
