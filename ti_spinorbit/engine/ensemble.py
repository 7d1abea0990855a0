"""Ensemble driver: member table in, windows of kernel launches, drained buffers out.

Data flow: ``BinarySystem`` rows + initial states (numpy, scaled units) -> :class:`Ensemble`
-> one ``kernels.advance.advance`` launch per window -> per-member event / sample lists and
diagnostics -> :class:`RunOutput`, which the result classes of ``section`` turn into SI.

Decisions:
* A window is ``window_orbits`` initial orbital periods (scaled time 2π per orbit for every
  member, since each member's time unit is its own 1/n). Event buffers hold
  ``window_orbits + 4`` crossings; a member that fills its buffer pauses and resumes in the
  next launch, so the window length changes launch overhead, never results. Windows start at
  one orbit and adapt to the launch's wall time (``PROGRESS_SECONDS``), never longer than
  ``window_orbits``, so progress comes every few seconds even for slow ensembles.
* Arrays are numpy and handed to the kernels as external ndarrays; on the CPU Taichi uses
  them in place.
"""

import hashlib
import time
from dataclasses import dataclass, field, fields
from typing import Callable, List, Optional

import numpy as np

from .. import layout, runtime
from .._validate import (require_bool, require_count, require_memory, require_order,
                         require_positive, require_range, require_real)
from ..kernels.controller import DEFAULT_CONTROLLER
from ..model import models
from ..model.perturbations import NACC, NPERT, out_of_plane_rows
from . import checkpoint as ckpt, compiling, cost, evaluation, resources
from . import multipole_tables as _mp

#: Default window, in orbits: the most one kernel launch advances (checkpoints and progress
#: come between launches; slow windows are shortened, see PROGRESS_SECONDS).
DEFAULT_WINDOW_ORBITS = 16
MIN_STEP = 1e-10  # scaled time (1/n): below this a member stops with "step underflow"
#: Wall-clock seconds a window should take, so that progress (and a checkpoint) comes at
#: least every few seconds: a window that took more than twice this is shortened
#: proportionally, one that took less than half of it is doubled, never beyond
#: ``window_orbits`` (which sizes the buffers) nor below MIN_WINDOW_ORBITS.
PROGRESS_SECONDS = 1.0
MIN_WINDOW_ORBITS = 1.0 / 64
#: Shadow-trajectory separation (scaled-state norm): large against round-off (1e-16 · O(1)
#: components gives 1e-8 relative noise per step), small enough to stay linear.
SHADOW_SEPARATION = 1e-8


def _shadow_direction():
    """Fixed unit direction of the 3-D model's initial separation (``models.SPATIAL``)."""
    return models.SPATIAL.shadow_direction()


@dataclass
class RunOutput:
    """What the kernels produced, still in scaled units (per member)."""

    events: List[np.ndarray]          # each (count, 31): time, then the state at the crossing
    samples: List[np.ndarray]         # each (count, 31): time, state (empty without sampling)
    diag_start: np.ndarray            # (N, 14) DIAG_FIELDS at t = 0
    diag_end: np.ndarray              # (N, 14) at the final time reached
    t: np.ndarray                     # final time reached, scaled
    y: np.ndarray                     # final state, scaled (N, 30)
    status: np.ndarray                # (N,) int, kernels.advance.STATUS_NAMES
    counters: np.ndarray              # (N, 3) accepted, rejected, RHS calls
    launches: int = 0
    seconds: float = 0.0
    megno: Optional[np.ndarray] = None      # (N,) MEGNO <Y> at the final time (indicators on)
    lyapunov: Optional[np.ndarray] = None   # (N,) finite-time max Lyapunov exponent, 1/orbit
    #: with perturbations: per member, (count, 4) work W and external angular momentum
    #: L_ext (scaled) at each event / sample, and (N, 4) at the final time
    #: (``kernels/perturb.py``); None without
    event_exchange: Optional[List[np.ndarray]] = None
    sample_exchange: Optional[List[np.ndarray]] = None
    exchange: Optional[np.ndarray] = None


@dataclass
class RunState:
    """Everything a run carries between windows: the arrays a checkpoint holds
    (``checkpoint._ARRAYS``: kernel-layout states, times with their Kahan compensations,
    step proposals, status, counters, first-stage derivatives, sampling clock, shadow state
    and indicator sums, diagnostics at t = 0), the records so far and the bookkeeping.
    :meth:`launch` is the one place that hands them to the ``advance`` kernel, in its order."""

    y: np.ndarray              # (N, nstate) kernel-layout state
    t: np.ndarray              # (N,) scaled time
    h: np.ndarray              # (N,) step proposal
    status: np.ndarray         # (N,) int32, kernels.advance.STATUS_NAMES
    counters: np.ndarray       # (N, 3) int64 accepted, rejected, RHS calls
    yc: np.ndarray             # Kahan compensation of y
    tc: np.ndarray             # Kahan compensation of t
    f: np.ndarray              # dy/dt at (t, y): the next step's first stage
    next_sample: np.ndarray    # (N,) next sample time (zeros without sampling)
    shadow: np.ndarray         # (N, nstate) shadow state ((1, nstate) without indicators)
    shadow_f: np.ndarray       # its derivative
    ind: np.ndarray            # (N, 3) log-growth sums for the Lyapunov exponent and MEGNO
    diag_start: np.ndarray     # (N, 14) DIAG_FIELDS at t = 0
    events: list = field(default_factory=list)    # per member: list of record chunks
    samples: list = field(default_factory=list)
    launches: int = 0
    seconds: float = 0.0
    records_sha256: list = field(default_factory=list)   # digests (checkpoint.save)

    def as_dict(self):
        """The fields as a dict (the arrays themselves, not copies), for checkpoint.save."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_dict(cls, d):
        return cls(**{f.name: d[f.name] for f in fields(cls) if f.name in d})

    def launch(self, advance, par, multipole, t_end, t_stop, events_buf, n_events, samples_buf,
               n_samples, rtol, atol, min_step, sample_dt, separation, max_steps, order, odd,
               sampling, indicators):
        """One launch of ``advance`` (a kernel set's ``advance``, or ``compiling.FirstUse``
        wrapping it) on this state, updated in place; ``multipole`` the four order-N arrays
        (``multipole_tables.Multipole.arguments``, stand-ins at order <= 4)."""
        advance(par, self.y, self.yc, self.f, self.t, self.tc, self.h, t_end, t_stop,
                self.status, self.counters, events_buf, n_events, samples_buf, n_samples,
                self.next_sample, self.shadow, self.shadow_f, self.ind, *multipole, rtol, atol,
                min_step, sample_dt, separation, max_steps, order, odd, sampling, indicators)


def check_tolerances(rtol, atol):
    """Validate rtol/atol; returns floats (atol defaults to rtol).

    rtol in [1e-16, 1e-2]. atol is an absolute tolerance in the kernels' scaled units
    (docs/physics.md §4.3, §5.2: lengths in a, velocities in a n, spins in n, attitudes
    unitless), in which every state component is O(1): so atol in (0, 1e-2], the same ceiling
    as rtol (a larger one lets the error be a sizeable fraction of the state), with no floor
    above 0 (1e-15 and below are fine). 0 itself is refused: the planar run's out-of-plane
    components are exactly 0, where a pure relative test divides by zero."""
    require_real("rtol", rtol)
    if atol is not None:
        require_real("atol", atol)
    require_range("rtol", rtol, 1e-16, 1e-2, low_open=False, high_open=False)
    atol = rtol if atol is None else atol
    atol_max = 1e-2
    if not 0.0 < float(atol) <= atol_max:          # NaN fails too
        raise ValueError(f"atol must lie in (0, {atol_max:g}] (absolute tolerance on the "
                         f"scaled state, whose components are O(1); got {float(atol):.12g})")
    return float(rtol), float(atol)


class Ensemble:
    """N members, each with its own parameters and initial state (scaled units).

    Parameters
    ----------
    par : (N, NPAR) array
        Member parameter rows (``BinarySystem.parameter_row``).
    y0 : (N, 30) array
        Initial scaled states (``BinarySystem.initial_state``).
    order : int
        Truncation order of the mutual potential: 0 or 2 to 16. Up to 4 the hand-written
        kernels; above 4 the table-driven harmonic ones (``kernels/harmonic_gravity.py``),
        which need ``multipole_rows``.
    rtol, atol : float
        Tolerances on the scaled state (error in tolerance units, max norm).
    model : {"auto", "planar", "3d"}
        Equations of motion: "planar" integrates the reduced planar state
        (``kernels/planar_eom.py``, about 3x cheaper per step), "3d" the general one; "auto"
        (default) takes the planar model when every member qualifies
        (``ti_spinorbit.model.planar.qualifies``). Inputs and outputs are 3-D states either way.
    method : {"cash-karp", "dop853", "vern9"}
        Runge-Kutta pair (``kernels/tableau.py``): "cash-karp" (default; Cash-Karp 4(5), the
        paper's), "dop853" (Hairer's 8(5,3) pair: fewer, longer steps; faster at tight
        tolerances) or "vern9" (Verner's 9(8) pair, 16 stages: fewer steps still). All hold
        the same error norm to ``rtol``; events, sampling, indicators, checkpoints and both
        models work with each.
    controller : Controller, optional
        Step-size policy (``kernels/controller.py``); another one than the default
        compiles its own kernels and is recorded in checkpoints.
    perturbation_rows : (N, NPERT) array, optional
        Scaled tides / YORP / BYORP blocks (``ti_spinorbit.model.perturbations.perturbation_rows``):
        the kernels then integrate the perturbed equations and carry the work and external
        angular momentum after the state (``kernels/perturb.py``; docs/physics.md §13).
    multipole_rows : (N, width) array, optional
        Order > 4 only (and then required): both bodies' integrals of degrees 0..dA and
        0..dB in their own frames, scaled (``multipole_tables.integral_rows``).
    degrees : (int, int), optional
        Order > 4 only: degree caps (primary, secondary) of the integrals, each in
        [0, order]; default (order, order).
    """

    def __init__(self, par, y0, *, order=4, rtol=1e-12, atol=None, odd=None,
                 min_step=MIN_STEP, model="auto", method="cash-karp", controller=None,
                 perturbation_rows=None, multipole_rows=None, degrees=None):
        from ..kernels import eom
        from ..kernels.tableau import METHODS, check_method

        runtime.ensure_init()
        self.par = np.ascontiguousarray(par, dtype=np.float64)
        self.y = np.ascontiguousarray(y0, dtype=np.float64).copy()
        self._y_start = self.y.copy()
        if self.par.ndim != 2 or self.par.shape[1] != eom.NPAR or self.y.shape != (len(self.par), eom.NSTATE):
            raise ValueError("par must be (N, NPAR) and y0 (N, 30) with the same N")
        self.order = require_order(order)
        self.rtol, self.atol = check_tolerances(rtol, atol)
        #: the order-N tables and integral rows (``multipole_tables.Multipole``), None at
        #: order <= 4
        self.multipole = _multipole(self.order, multipole_rows, degrees, len(self.par), odd)
        if self.multipole is not None:
            odd = self.multipole.tables.odd
        elif odd is None:  # any non-zero odd-index integral in either body row?
            odd = evaluation.has_odd(self.par)
        self.odd = bool(odd)
        self.min_step = float(min_step)
        self.method = check_method(method)
        #: the step-size policy; None for the kernels' default
        self.controller = None if controller is None or controller == DEFAULT_CONTROLLER \
            else controller
        #: the model object (``ti_spinorbit.model.models``); ``model`` is its name
        self.equations = models.choose(
            model, self.par, self.y, self._planar_symmetric(),
            spatial_forces=perturbation_rows is not None and bool(
                np.any(out_of_plane_rows(perturbation_rows))))
        self._model_request = model      # "auto" may still turn 3-D for full-space indicators
        self.model = self.equations.name
        self.prows = None
        if perturbation_rows is not None:
            self.prows = np.ascontiguousarray(perturbation_rows, dtype=np.float64)
            if self.prows.shape != (len(self.par), NPERT) or not np.all(np.isfinite(self.prows)):
                raise ValueError(f"perturbation_rows must be a finite (N, {NPERT}) array")
        self.kpar = self._kernel_parameters()
        self.y = self._kernel_state(self.y)
        n = len(self.par)
        self.n = n
        self.t = np.zeros(n)
        # a first guess the controller fixes (Cash-Karp's kept as it was: results unchanged)
        self.h = np.full(n, 0.5 * self.rtol ** (0.2 if self.method == "cash-karp" else
                                                METHODS[self.method].error_exponent))
        self.status = np.zeros(n, dtype=np.int32)
        self.counters = np.zeros((n, 3), dtype=np.int64)

    def _planar_symmetric(self):
        """Order > 4: per member, whether no integral of its order-N row is odd in z (the
        planar model needs it at every degree); None at order <= 4 (the rows say)."""
        if self.multipole is None:
            return None
        mask = _mp.odd_mask(self.multipole.degrees, axis=2)
        return ~np.any(self.multipole.rows[:, mask] != 0.0, axis=1)

    @property
    def kernel_order(self):
        """The ``order`` template the kernels take: the order itself up to 4, one value
        (``layout.multipole.KERNEL_ORDER``) for every higher one, whose tables carry it."""
        return self.order if self.multipole is None else layout.multipole.KERNEL_ORDER

    @property
    def kernel_odd(self):
        """The ``odd`` template the kernels take (above order 4 the tables decide: False)."""
        return self.odd if self.multipole is None else False

    def multipole_arguments(self, slots=None):
        """The four order-N arrays of a launch (stand-ins at order <= 4)."""
        if self.multipole is None:
            return _mp.no_arguments()
        return self.multipole.arguments(self.n if slots is None else slots)

    @property
    def perturbed(self):
        """Whether the members carry tides, YORP or BYORP (``perturbation_rows`` given)."""
        return self.prows is not None

    @property
    def kernels(self):
        """The kernel set of this ensemble's model and method (``kernels_for``)."""
        return self.equations.kernels(self.method, self.perturbed, self.controller)

    def _kernel_parameters(self):
        """The kernels' parameter rows: the model's, then the perturbation block."""
        kpar = self.equations.kernel_parameters(self.par)
        return kpar if self.prows is None else np.ascontiguousarray(np.hstack([kpar, self.prows]))

    def _kernel_state(self, y):
        """3-D states -> kernel states, with zero accumulators when perturbed."""
        k = self.equations.to_kernel_state(y)
        return k if not self.perturbed else np.hstack([k, np.zeros((len(k), NACC))])

    def spatial(self, y):
        """Kernel states of this model -> 3-D scaled states (a copy; accumulators dropped)."""
        return self.equations.to_spatial(np.asarray(y)[:, :self.equations.nstate])

    def exchange(self, y):
        """The accumulators (work, L_ext; (N, 4) scaled) of kernel states, or None."""
        return np.array(np.asarray(y)[:, self.equations.nstate:]) if self.perturbed else None

    def diagnostics(self, y=None, member=None) -> np.ndarray:
        """DIAG_FIELDS (energies, angular momenta, orthonormality) of 3-D states y (default:
        the current ones) belonging to members ``member`` (default 0..N-1), scaled units
        (``evaluation.diagnostics`` with this ensemble's rows, order and odd terms)."""
        y = self.spatial(self.y) if y is None else y
        y = np.asarray(y, dtype=np.float64).reshape(-1, 30)
        member = np.arange(len(y), dtype=np.int32) if member is None else member
        return evaluation.diagnostics(self.par, y, member, self.order, self.odd,
                                      multipole=self.multipole)

    def run(self, t_stop, *, window_orbits=DEFAULT_WINDOW_ORBITS, sample_dt=None,
            indicators=False, separation=SHADOW_SEPARATION,
            progress: Optional[Callable[[float], None]] = None, checkpoint=None,
            resume=False, overwrite_checkpoint=False, keep_checkpoint=False,
            indicator_space="planar", max_steps=None) -> RunOutput:
        """Integrate every member to ``t_stop`` (scaled; scalar or per member).

        ``sample_dt`` (scaled) turns on the dense time series. ``progress(fraction)`` is
        called after every window. Window ends are soft (no step is shortened for them), so
        the window length changes launch overhead only, never results; a window is
        ``window_orbits`` orbits at most and shorter when launches take seconds (so that
        progress comes every ~PROGRESS_SECONDS, see :func:`_next_span`).

        ``indicators`` integrates a shadow trajectory with the same steps, started
        ``separation`` away (scaled-state Euclidean norm) along a fixed planar direction and
        renormalised to that separation after every accepted step; it yields the finite-time
        maximal Lyapunov exponent and MEGNO ⟨Y⟩ (``RunOutput.lyapunov``, ``.megno``).

        ``indicator_space`` chooses that direction (docs/physics.md §10.4): "planar"
        (default) the fixed planar one above, blind to out-of-plane instability by
        construction; "full" a seeded random direction spanning the whole state (position,
        velocity, both spins, and both attitudes through a small rotation,
        :meth:`ti_spinorbit.model.models.Spatial.full_direction`). "full" needs the 3-D model: an
        ensemble built with model="auto" switches to it for the run, model="planar" is
        refused (ValueError). Ignored without ``indicators``.

        ``checkpoint`` (a directory path) saves everything needed to resume after every
        window, with atomic replaces (``ti_spinorbit.engine.checkpoint``); with ``resume=True`` a run
        continues from it when it exists and gives the same results as an uninterrupted run.
        A checkpoint written for other inputs or settings, or a damaged one, raises
        ValueError (``checkpoint.CheckpointError``; damage: ``CheckpointDamaged``, "checkpoint
        damaged: ..."). The run holds the directory's lock throughout; a second run on it is
        refused at once (``CheckpointLocked``). Without ``resume`` a directory that holds a
        checkpoint is refused (``CheckpointExists``, nothing touched) unless
        ``overwrite_checkpoint=True`` replaces it. A run that returns removes its checkpoint
        unless ``keep_checkpoint=True``; one that raises or is interrupted keeps it for a
        resume (``checkpoint.finish``).

        ``max_steps`` caps every member's accepted + rejected steps (default: the budget of
        :func:`ti_spinorbit.engine.cost.step_budget`, 100 times the most expensive member's
        estimate); a member that reaches it stops with the status "step budget" and keeps
        what it recorded. A run whose estimated cost is above ``cost.LONG_RUN_STEPS`` warns
        (:class:`ti_spinorbit.engine.cost.LongRunWarning`) before it starts.
        """

        kern = self.kernels
        n = self.n
        t_stop = np.broadcast_to(np.asarray(t_stop, dtype=np.float64), (n,)).copy()
        require_positive("t_stop", t_stop)
        window_orbits = require_count("window_orbits", window_orbits, 1, 10**6)
        cap = window_orbits + 4
        sampling = sample_dt is not None
        if sampling:
            require_positive("sample_dt", sample_dt)
        if indicators:
            require_range("separation", separation, 1e-14, 1e-3)
        indicator_space = models.check_indicator_space(indicator_space)
        if indicators and indicator_space == "full":
            self._use_spatial()
            kern = self.kernels
        scratch = 0 if self.multipole is None else self.multipole.bytes(n)
        require_memory("the recorded crossings and samples" + (
                       " and the order-N scratch" if scratch else ""),
                       _record_bytes(t_stop, sample_dt, kern.RECORD_WIDTH, cap) + scratch,
                       "integrate fewer members or orbits per call, or sample less densely")
        estimate = cost.steps_per_orbit(self.par, self._y_start, self.rtol, self.method)
        orbits = t_stop / (2.0 * np.pi)
        cost.check_cost("the integration", estimate, orbits)
        # the default budget follows from the inputs (the fingerprint covers them), so a
        # checkpoint records only what was asked for
        requested = None if max_steps is None else require_count("max_steps", max_steps, 1,
                                                                   2 ** 62)
        budget = cost.step_budget(estimate, orbits) if requested is None else requested
        settings = {"model": self.model, "method": self.method, "order": self.order, "odd": self.odd,
                    "rtol": self.rtol, "atol": self.atol, "min_step": self.min_step,
                    "window_orbits": window_orbits, "sample_dt": sample_dt,
                    "indicators": bool(indicators), "separation": float(separation),
                    "indicator_space": indicator_space, "perturbed": self.perturbed,
                    "max_steps": requested}
        if self.controller is not None:          # only then: older checkpoints stay valid
            settings["controller"] = repr(self.controller)
        if self.multipole is not None:           # likewise: order-N runs only
            settings["degrees"] = list(self.multipole.degrees)
        args = (t_stop, window_orbits, sample_dt, indicators, separation, progress, checkpoint,
                resume, settings, budget)
        if checkpoint is None:
            return self._windows(*args)
        keep = require_bool("keep_checkpoint", keep_checkpoint)
        with ckpt.claim(checkpoint, resume=resume, overwrite=overwrite_checkpoint, keep=keep):
            return self._windows(*args)

    def _windows(self, t_stop, window_orbits, sample_dt, indicators, separation, progress,
                 checkpoint, resume, settings, max_steps) -> RunOutput:
        """The windows of :meth:`run` (inputs checked, checkpoint directory owned)."""


        kern = self.kernels
        n = self.n
        window = 2.0 * np.pi * window_orbits
        cap = window_orbits + 4
        sampling = sample_dt is not None
        st = None
        fingerprint = self._fingerprint(t_stop) if checkpoint is not None else None
        if checkpoint is not None and resume:
            st = ckpt.load(checkpoint, settings, fingerprint)
        # the first use of a variant in this process compiles its kernels, announced; that
        # time stays out of seconds, rates and window lengths (ti_spinorbit.engine.compiling)
        advance = compiling.FirstUse(kern.advance, compiling.KernelVariant(
            self.model, bool(indicators), sampling, self.order, self.odd, self.method,
            self.perturbed, self.controller), lambda: self.status)
        multipole = self.multipole_arguments()
        if st is None:
            with advance.other_kernels():
                st = self._fresh_run_state(sampling, sample_dt, indicators, separation,
                                           settings.get("indicator_space", "planar"))
        else:
            st = RunState.from_dict(st)
            for name in ("y", "t", "h", "status", "counters"):   # the same arrays
                setattr(self, name, getattr(st, name))
        scap = int(np.ceil(window / sample_dt)) + 4 if sampling else 1
        events_buf = np.zeros((n, cap, kern.RECORD_WIDTH))
        samples_buf = np.zeros((n, scap, kern.RECORD_WIDTH))
        n_events = np.zeros(n, dtype=np.int32)
        n_samples = np.zeros(n, dtype=np.int32)
        events, samples = st.events, st.samples
        # records not yet in the checkpoint (a fresh run's first sample is the initial state)
        pending = {"events": {}, "samples": {} if st.launches else
                   {i: list(s) for i, s in enumerate(samples) if s}}
        t0 = time.perf_counter() - st.seconds
        span = min(window, 2.0 * np.pi)  # first window: one orbit, then adapted to wall time
        while np.any(self.status == layout.RUNNING):
            t_end = np.minimum(t_stop, self.t + span)
            launched = time.perf_counter()
            st.launch(advance, self.kpar, multipole, t_end, t_stop, events_buf, n_events,
                      samples_buf, n_samples, self.rtol, self.atol, self.min_step,
                      float(sample_dt or 0.0), float(separation), int(max_steps),
                      self.kernel_order, self.kernel_odd, sampling, bool(indicators))
            compiled = advance.take_seconds()
            t0, launched = t0 + compiled, launched + compiled
            st.launches += 1
            # the kernel's time only: draining and checkpointing do not shrink with the span
            span = _next_span(span, time.perf_counter() - launched, window)
            for name, store, buf, count in (("events", events, events_buf, n_events),
                                            ("samples", samples, samples_buf, n_samples)):
                for i in np.nonzero(count)[0]:
                    chunk = buf[i, :count[i]].copy()
                    store[i].append(chunk)
                    pending[name].setdefault(i, []).append(chunk)
            n_events[:] = 0
            n_samples[:] = 0
            finished = (self.status == layout.RUNNING) & (self.t >= t_stop)
            self.status[finished] = layout.DONE
            st.seconds = time.perf_counter() - t0
            if checkpoint is not None:
                ckpt.save(checkpoint, settings, fingerprint, st.as_dict(), pending)
            pending = {"events": {}, "samples": {}}
            if progress is not None:
                progress(float(np.mean(np.minimum(self.t, t_stop)) / np.mean(t_stop)))
        megno = lyapunov = np.full(n, np.nan)
        if indicators:
            ind = st.ind
            with np.errstate(divide="ignore", invalid="ignore"):
                megno = ind[:, 2] / self.t
                lyapunov = ind[:, 0] / self.t * 2.0 * np.pi   # per orbit (2π scaled time)
        ev, ev_x = self._spatial_records(events)
        sm, sm_x = self._spatial_records(samples)
        return RunOutput(
            events=ev, samples=sm,
            event_exchange=ev_x if self.perturbed else None,
            sample_exchange=sm_x if self.perturbed else None,
            exchange=self.exchange(self.y),
            diag_start=st.diag_start, diag_end=self.diagnostics(), t=self.t.copy(),
            y=self.spatial(self.y), status=self.status.copy(), counters=self.counters.copy(),
            launches=st.launches, seconds=st.seconds, megno=megno, lyapunov=lyapunov)

    def _use_spatial(self):
        """Integrate with the 3-D model from now on (full-space indicators), or refuse when
        the planar model was asked for by name."""
        if self.equations is models.SPATIAL:
            return
        if self._model_request == "planar":
            raise ValueError("indicator_space='full' needs the 3-D model (the planar model "
                             "cannot carry out-of-plane deviations): use model='auto' or '3d'")
        # the exact 3-D start before any step (no round trip through the planar layout)
        acc = self.exchange(self.y)
        y = self._y_start.copy() if not np.any(self.t) else self.spatial(self.y)
        self.equations = models.SPATIAL
        self.model = self.equations.name
        self.kpar = self._kernel_parameters()
        self.y = y if acc is None else np.hstack([y, acc])

    def _fresh_run_state(self, sampling, sample_dt, indicators, separation,
                         indicator_space="planar"):
        """The :class:`RunState` of a run from the start (y, t, h, status, counters are this
        ensemble's own arrays)."""
        kern = self.kernels
        n = self.n
        # NaN first stages: the integrator evaluates them itself on its first pass (counted
        # there, the shadow's not), so a first run traces and compiles one kernel fewer
        f = np.full_like(self.y, np.nan)
        if indicators:
            ys = self.y[:, :self.equations.nstate]
            direction = self.equations.full_direction(ys) if indicator_space == "full" \
                else self.equations.shadow_direction()
            shadow = self.y.copy()         # accumulators: the same as the member's
            shadow[:, :self.equations.nstate] = ys + separation * direction
            shadow_f = np.full_like(shadow, np.nan)
            ind = np.zeros((n, 3))
        else:  # unused by the kernel variant without indicators
            shadow = shadow_f = np.zeros((1, kern.NSTATE))
            ind = np.zeros((1, 3))
        samples = [[] for _ in range(n)]
        if sampling:  # the first sample is the initial state
            for i in range(n):
                samples[i].append(np.concatenate([[0.0], self.y[i]])[None])
        return RunState(y=self.y, t=self.t, h=self.h, status=self.status,
                        counters=self.counters, yc=np.zeros_like(self.y), tc=np.zeros(n), f=f,
                        next_sample=np.full(n, float(sample_dt)) if sampling else np.zeros(n),
                        shadow=shadow, shadow_f=shadow_f, ind=ind,
                        events=[[] for _ in range(n)], samples=samples,
                        diag_start=self.diagnostics(), launches=0, seconds=0.0)

    def _fingerprint(self, t_stop):
        """SHA-256 digests of what determines a run's results (inputs at the start of the
        run), one per part, so that a refused resume can name the part that changed
        (``checkpoint.load``)."""

        def digest(a):
            return None if a is None else hashlib.sha256(
                np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()

        parts = {"systems": digest(self.par), "initial states": digest(self._y_start),
                 "integration times": digest(t_stop), "perturbations": digest(self.prows)}
        if self.multipole is not None:      # order-N runs only: older checkpoints stay valid
            parts["order-N integrals"] = digest(self.multipole.rows)
        return parts

    def _spatial_records(self, chunks_per_member):
        """Every member's record chunks as (count, 31) 3-D rows (time, state), and apart the
        accumulators of a perturbed run, (count, NACC) (zero columns without): two lists,
        one entry per member. All members are converted in one pass, then split."""
        counts = np.array([sum(len(c) for c in chunks) for chunks in chunks_per_member],
                          dtype=np.int64)
        ns = 1 + self.equations.nstate
        width = self.kernels.RECORD_WIDTH
        rec = np.concatenate([np.zeros((0, width))] +
                             [c for chunks in chunks_per_member for c in chunks])
        acc = rec[:, ns:]
        if self.equations is models.SPATIAL:
            rows = rec[:, :ns]
        else:
            rows = np.empty((len(rec), layout.RECORD_WIDTH))
            rows[:, 0] = rec[:, 0]
            rows[:, 1:] = self.equations.to_spatial(rec[:, 1:ns])
        cuts = np.cumsum(counts)[:-1]
        return np.split(rows, cuts), np.split(acc, cuts)


def _next_span(span, seconds, window):
    """Scaled length of the next window after one of ``span`` took ``seconds``: shortened
    when it took over 2·PROGRESS_SECONDS, lengthened (doubled) below PROGRESS_SECONDS/2,
    within [MIN_WINDOW_ORBITS orbits, window]. Window ends are soft, so this changes when
    progress is reported, never the results."""
    if seconds > 2.0 * PROGRESS_SECONDS:
        span = span * PROGRESS_SECONDS / seconds
    elif seconds < 0.5 * PROGRESS_SECONDS:
        span = 2.0 * span
    return float(min(max(span, 2.0 * np.pi * MIN_WINDOW_ORBITS), window))


def _record_bytes(t_stop, sample_dt, width, cap):
    """Peak bytes of a run and of the observables derived from its records
    (:func:`ti_spinorbit.engine.resources.estimate_bytes`, the model the entry points check before
    building members), with the kernels' record ``width`` (11 planar, 31 3-D)."""

    spo = None if sample_dt is None else 2.0 * np.pi / float(sample_dt)
    orbits = np.asarray(t_stop, dtype=np.float64) / (2.0 * np.pi)
    return resources.estimate_bytes(len(orbits), orbits, spo, window_orbits=cap - 4,
                                    width=width)


def _choose_model(model, par, y0):
    """"planar" or "3d" for Ensemble(model=...) (the name of ``models.choose``)."""
    return models.choose(model, par, y0).name


def _multipole(order, rows, degrees, n, odd=None):
    """The order-N data of an ensemble (``multipole_tables.Multipole``), None at order <= 4;
    ``rows`` are required above 4 and refused below (as are ``degrees``)."""
    if order <= layout.multipole.HAND_WRITTEN_MAX:
        if rows is not None or degrees is not None:
            raise ValueError(f"multipole_rows and degrees are for orders above "
                             f"{layout.multipole.HAND_WRITTEN_MAX} (got order {order})")
        return None
    dA, dB = _mp.check_degrees(order, degrees)
    if rows is None:
        raise ValueError(f"order {order} needs multipole_rows: both bodies' integrals to "
                         f"degrees ({dA}, {dB}) (multipole_tables.integral_rows)")
    rows = np.ascontiguousarray(rows, dtype=np.float64)
    width = _mp.count(dA) + _mp.count(dB)
    if rows.ndim != 2 or rows.shape != (n, width):
        raise ValueError(f"multipole_rows must be ({n}, {width}): one row per member, both "
                         f"bodies' integrals to degrees ({dA}, {dB}) (got shape {rows.shape})")
    if odd is None:
        odd = _mp.odd_present(rows, (dA, dB))
    return _mp.Multipole(_mp.tables(order, dA, dB, bool(odd)), rows)
