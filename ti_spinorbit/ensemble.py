"""Ensemble driver: member table in, windows of kernel launches, drained buffers out.

Data flow: ``BinarySystem`` rows + initial states (numpy, scaled units) -> :class:`Ensemble`
-> one ``kernels.ensemble.advance`` launch per window -> per-member event / sample lists and
diagnostics -> :class:`RunOutput`, which the result classes of ``section`` turn into SI.

Decisions:
* A window is ``window_orbits`` initial orbital periods (scaled time 2π per orbit for every
  member, since each member's time unit is its own 1/n). Event buffers hold
  ``window_orbits + 4`` crossings; a member that fills its buffer pauses and resumes in the
  next launch, so the window length changes launch overhead, never results.
* Arrays are numpy and handed to the kernels as external ndarrays; on the CPU Taichi uses
  them in place.
"""

from dataclasses import dataclass
from typing import Callable, List, Optional

import numpy as np

from . import runtime
from ._validate import require_count, require_positive, require_range

#: Default tolerance floor: atol = rtol unless given (the scaled state is O(1)).
DEFAULT_WINDOW_ORBITS = 16
MIN_STEP = 1e-10  # scaled time (1/n): below this a member stops with "step underflow"
#: Shadow-trajectory separation (scaled-state norm): large against round-off (1e-16 · O(1)
#: components gives 1e-8 relative noise per step), small enough to stay linear.
SHADOW_SEPARATION = 1e-8


def _shadow_direction():
    """Fixed unit direction of the initial separation: R_x, R_y, V_x, V_y and the secondary's
    spin w2_z, so a planar start stays planar (same for every member: slot-invariant)."""
    from .kernels import eom

    u = np.zeros(eom.NSTATE)
    u[[eom.Y_R, eom.Y_R + 1, eom.Y_V, eom.Y_V + 1, eom.Y_W2 + 2]] = 1.0
    return u / np.linalg.norm(u)


@dataclass
class RunOutput:
    """What the kernels produced, still in scaled units (per member)."""

    events: List[np.ndarray]          # each (count, 31): time, then the state at the crossing
    samples: List[np.ndarray]         # each (count, 31): time, state (empty without sampling)
    diag_start: np.ndarray            # (N, 14) DIAG_FIELDS at t = 0
    diag_end: np.ndarray              # (N, 14) at the final time reached
    t: np.ndarray                     # final time reached, scaled
    y: np.ndarray                     # final state, scaled (N, 30)
    status: np.ndarray                # (N,) int, kernels.ensemble.STATUS_NAMES
    counters: np.ndarray              # (N, 3) accepted, rejected, RHS calls
    launches: int = 0
    seconds: float = 0.0
    megno: Optional[np.ndarray] = None      # (N,) MEGNO <Y> at the final time (indicators on)
    lyapunov: Optional[np.ndarray] = None   # (N,) finite-time max Lyapunov exponent, 1/orbit


def check_tolerances(rtol, atol):
    """Validate rtol/atol; returns floats (atol defaults to rtol)."""
    require_range("rtol", rtol, 1e-16, 1e-2, low_open=False, high_open=False)
    atol = rtol if atol is None else atol
    require_positive("atol", atol)
    return float(rtol), float(atol)


class Ensemble:
    """N members, each with its own parameters and initial state (scaled units).

    Parameters
    ----------
    par : (N, NPAR) array
        Member parameter rows (``BinarySystem.parameter_row``).
    y0 : (N, 30) array
        Initial scaled states (``BinarySystem.initial_state``).
    order : {0, 2, 3, 4}
        Truncation order of the mutual potential.
    rtol, atol : float
        Tolerances on the scaled state (error in tolerance units, max norm).
    """

    def __init__(self, par, y0, *, order=4, rtol=1e-12, atol=None, odd=None,
                 min_step=MIN_STEP):
        from .bodies import ROW_LENGTH
        from .kernels import eom

        runtime.ensure_init()
        self.par = np.ascontiguousarray(par, dtype=np.float64)
        self.y = np.ascontiguousarray(y0, dtype=np.float64).copy()
        if self.par.ndim != 2 or self.par.shape[1] != eom.NPAR or self.y.shape != (len(self.par), eom.NSTATE):
            raise ValueError("par must be (N, NPAR) and y0 (N, 30) with the same N")
        if order not in (0, 2, 3, 4):
            raise ValueError(f"order must be 0, 2, 3 or 4 (got {order!r})")
        self.order = int(order)
        self.rtol, self.atol = check_tolerances(rtol, atol)
        if odd is None:  # any non-zero odd-index integral in either body row?
            odd = bool(np.any(self.par[:, _odd_columns(ROW_LENGTH)] != 0.0))
        self.odd = bool(odd)
        self.min_step = float(min_step)
        n = len(self.par)
        self.n = n
        self.t = np.zeros(n)
        self.h = np.full(n, 0.5 * self.rtol ** 0.2)  # a first guess the controller fixes
        self.status = np.zeros(n, dtype=np.int32)
        self.counters = np.zeros((n, 3), dtype=np.int64)

    def diagnostics(self, y=None, member=None) -> np.ndarray:
        """DIAG_FIELDS (energies, angular momenta, orthonormality) of states y (default: the
        current ones) belonging to members ``member`` (default 0..N-1), scaled units."""
        from .kernels import ensemble as K

        y = self.y if y is None else np.ascontiguousarray(y, dtype=np.float64).reshape(-1, 30)
        member = np.arange(len(y), dtype=np.int32) if member is None else \
            np.ascontiguousarray(member, dtype=np.int32)
        out = np.zeros((len(y), len(K.DIAG_FIELDS)))
        if len(y):
            K.diagnostics(self.par, y, member, out, self.order, self.odd)
        return out

    def run(self, t_stop, *, window_orbits=DEFAULT_WINDOW_ORBITS, sample_dt=None,
            indicators=False, separation=SHADOW_SEPARATION,
            progress: Optional[Callable[[float], None]] = None) -> RunOutput:
        """Integrate every member to ``t_stop`` (scaled; scalar or per member).

        ``sample_dt`` (scaled) turns on the dense time series. ``progress(fraction)`` is
        called after every window. Window ends are soft (no step is shortened for them), so
        the window length changes launch overhead only, never results.

        ``indicators`` integrates a shadow trajectory with the same steps, started
        ``separation`` away (scaled-state Euclidean norm) along a fixed planar direction and
        renormalised to that separation after every accepted step; it yields the finite-time
        maximal Lyapunov exponent and MEGNO ⟨Y⟩ (``RunOutput.lyapunov``, ``.megno``)."""
        import time

        from .kernels import ensemble as K

        n = self.n
        t_stop = np.broadcast_to(np.asarray(t_stop, dtype=np.float64), (n,)).copy()
        require_positive("t_stop", t_stop)
        window_orbits = require_count("window_orbits", window_orbits, 1, 10**6)
        window = 2.0 * np.pi * window_orbits
        cap = window_orbits + 4
        sampling = sample_dt is not None
        if sampling:
            require_positive("sample_dt", sample_dt)
            scap = int(np.ceil(window / sample_dt)) + 4
            next_sample = np.full(n, float(sample_dt))
        else:
            scap = 1
            next_sample = np.zeros(n)
        events_buf = np.zeros((n, cap, K.RECORD_WIDTH))
        samples_buf = np.zeros((n, scap, K.RECORD_WIDTH))
        n_events = np.zeros(n, dtype=np.int32)
        n_samples = np.zeros(n, dtype=np.int32)
        yc = np.zeros_like(self.y)
        tc = np.zeros(n)
        f = np.zeros_like(self.y)
        K.evaluate_rhs(self.par, self.y, f, self.order, self.odd)
        self.counters[:, K.C_RHS] += 1
        if indicators:
            require_range("separation", separation, 1e-14, 1e-3)
            shadow = self.y + separation * _shadow_direction()
            shadow_f = np.zeros_like(shadow)
            K.evaluate_rhs(self.par, shadow, shadow_f, self.order, self.odd)
            ind = np.zeros((n, 3))
        else:  # unused by the kernel variant without indicators
            shadow, shadow_f, ind = np.zeros((1, 30)), np.zeros((1, 30)), np.zeros((1, 3))
        events = [[] for _ in range(n)]
        samples = [[] for _ in range(n)]
        if sampling:  # the first sample is the initial state
            for i in range(n):
                samples[i].append(np.concatenate([[0.0], self.y[i]])[None])
        diag_start = self.diagnostics()
        launches = 0
        t0 = time.perf_counter()
        while np.any(self.status == K.RUNNING):
            t_end = np.minimum(t_stop, self.t + window)
            K.advance(self.par, self.y, yc, f, self.t, tc, self.h, t_end, t_stop, self.status,
                      self.counters, events_buf, n_events, samples_buf, n_samples, next_sample,
                      shadow, shadow_f, ind,
                      self.rtol, self.atol, self.min_step, float(sample_dt or 0.0),
                      float(separation), self.order, self.odd, sampling, bool(indicators))
            launches += 1
            for i in np.nonzero(n_events)[0]:
                events[i].append(events_buf[i, :n_events[i]].copy())
            for i in np.nonzero(n_samples)[0]:
                samples[i].append(samples_buf[i, :n_samples[i]].copy())
            n_events[:] = 0
            n_samples[:] = 0
            finished = (self.status == K.RUNNING) & (self.t >= t_stop)
            self.status[finished] = K.DONE
            if progress is not None:
                progress(float(np.mean(np.minimum(self.t, t_stop)) / np.mean(t_stop)))
        seconds = time.perf_counter() - t0
        empty = np.zeros((0, K.RECORD_WIDTH))
        megno = lyapunov = np.full(n, np.nan)
        if indicators:
            with np.errstate(divide="ignore", invalid="ignore"):
                megno = ind[:, 2] / self.t
                lyapunov = ind[:, 0] / self.t * 2.0 * np.pi   # per orbit (2π scaled time)
        return RunOutput(
            events=[np.concatenate(e) if e else empty for e in events],
            samples=[np.concatenate(s) if s else empty for s in samples],
            diag_start=diag_start, diag_end=self.diagnostics(), t=self.t.copy(), y=self.y.copy(),
            status=self.status.copy(), counters=self.counters.copy(), launches=launches,
            seconds=seconds, megno=megno, lyapunov=lyapunov)


def _odd_columns(row_length):
    """Parameter columns holding integrals with an odd index, for both body rows."""
    from .bodies import EXPONENTS_3, EXPONENTS_4
    from .kernels.potential import T3, T4

    cols = [T3 + k for k in range(len(EXPONENTS_3))]
    cols += [T4 + k for k, e in enumerate(EXPONENTS_4) if any(x % 2 for x in e)]
    return cols + [row_length + c for c in cols]
