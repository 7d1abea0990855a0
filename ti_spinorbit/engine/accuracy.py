"""Accuracy verdicts: every member's conservation drift held against a documented limit.

The total energy and the total angular-momentum vector of the full two-body problem are
constants of the motion, so their drift over a run measures the integration error directly,
independently of the integrator's own error estimate. Every result of the package carries,
per member, the relative drifts

    energy_drift = |E(t) − E(0)| / |E(0)|,   angmom_drift = |L(t) − L(0)| / |L(0)|

(scaled units; ``L`` is the inertial vector) and a verdict in its status:

* ``done`` — finished, drifts finite and within the limit;
* ``inaccurate`` — a drift exceeds the limit. Its data are kept (never dropped) and it is
  counted apart: summaries (chaotic fractions, overlap decisions, libration amplitudes)
  exclude it unless asked;
* ``non-finite`` — a drift or diagnostic is NaN/Inf (the kernels' own ``non-finite`` status
  also lands here), never ``done`` with a NaN;
* a member that stopped early (collision, escape, step underflow, step budget) is judged by
  its drift up to the stop, against the same limit: within it, it keeps that status (a
  physical outcome, or the integrator's own failure); past it, it is ``inaccurate``, because
  an escape or a collision reached with the conservation laws broken is an artefact of the
  tolerance as often as it is physics (an e = 0.6 orbit at rtol 1e-3 "escapes" with the
  energy off by 700 %, and stays bound at 1e-10). What it stopped for is kept beside the
  verdict, in the result's ``stop_status`` (the kernels' code).

**The truncation of the mutual potential** is the model's own error, apart from the
integration's: the series of docs/physics.md §3 is cut at order N. Every section and time
series carries, per member, the relative size of the next two orders (N+1, N+2) at the
member's closest recorded approach (``engine.evaluation.truncation_estimates``; the larger of
the recorded attitude and the same turned by 45° about the orbit normal, since an aligned
body feels no torque at any order): in the force
on the secondary, relative to that force, ``truncation_force``, and in the torque on the
secondary, relative to that force times the secondary's bounding radius (the torque scale of
the force; a torque itself can vanish by symmetry), ``truncation_torque``. A member that is
``done`` and whose estimate exceeds the limit becomes ``truncated``: kept, counted apart
like ``inaccurate``, and excluded from summaries unless they include the inaccurate ones.
The limits, :data:`TRUNCATION_LIMITS`, are 1e-5 in force and 1e-3 in torque: a force error
of 1e-5 moves the orbital period by about 5e-6 of itself (0.2 s for Didymos' 11.9 h; Hera-era
measurements resolve about 1 s), and a torque error of 1e-3 moves a libration amplitude by
about 1e-3 of itself (0.01° of a 10° amplitude). At order 4 every catalogued system of the
paper stays two decades or more below both; the radar shape of Didymos does not (about 2e-4
and 7e-3 in the worst configuration at pericentre: ``model.truncation``) and needs order 6
or more. Where the bodies hold no integrals above the run's order (a hand-given order-4
body) the estimate is NaN and no verdict is given.

**The default limit** scales with the tolerance and the run length, because the drift of a
healthy Cash-Karp run does: measured on 1991 VH and 2004 DC (48 starts each over the whole
(θ_p, θ̇_p/n) plane, planar and 3-D models) the largest energy drift is 4 to 18 × rtol per
orbit and the angular-momentum drift 2 to 9 × rtol per orbit, linear in both over rtol
1e-4 … 1e-14 (``experiments/drift_calibration.py`` prints the table). The default limit is

    max_drift = min(DRIFT_CAP, DRIFT_PER_ORBIT × rtol × max(orbits, 1))

with ``DRIFT_PER_ORBIT = 1000`` (over 50 × the healthy coefficient: a member must be far
off the healthy line to be flagged) and ``DRIFT_CAP = 1e-4``, a tolerance-independent ceiling:
the secondary's spin energy is only ~1e-3 of the total for the catalogued systems, so a
larger relative error in the total energy can swamp the spin dynamics whatever the
tolerance. At the defaults (rtol 1e-12 for sections, 1e-10 for maps) the cap binds only after
10^5 and 10^3 … 10^4 orbits. ``max_drift=`` (``--max-drift`` on the command line) overrides
the default with a number in (0, 1].
"""

import numpy as np

from .._validate import _as_floats, require_range
from .results import STATUS_NAMES, Result, Status

#: Drift limit per orbit per unit of rtol (50x what healthy runs show, see module docstring).
DRIFT_PER_ORBIT = 1000.0
#: Tolerance-independent ceiling of the default limit (relative drift).
DRIFT_CAP = 1e-4


def drift_limit(rtol, orbits, max_drift=None):
    """The drift limit of a run: ``max_drift`` when given (a number in (0, 1]), else
    ``min(DRIFT_CAP, DRIFT_PER_ORBIT · rtol · max(orbits, 1))``. ``orbits`` in orbital
    periods; returns a float (relative drift)."""
    if max_drift is not None:
        if isinstance(max_drift, bool) or _as_floats("max_drift", max_drift).ndim != 0:
            raise TypeError(f"max_drift must be one number in (0, 1] (got {max_drift!r})")
        require_range("max_drift", max_drift, 0.0, 1.0, low_open=True, high_open=False)
        return float(max_drift)
    return float(min(DRIFT_CAP, DRIFT_PER_ORBIT * float(rtol) * max(float(orbits), 1.0)))


def totals(diag):
    """Total energy (N,) and total angular-momentum vector (N, 3) from DIAG_FIELDS rows
    (``kernels.advance``: three energies, then the orbit's, the primary's and the
    secondary's angular-momentum vectors, ...), scaled units."""
    return diag[:, :3].sum(1), diag[:, 3:6] + diag[:, 6:9] + diag[:, 9:12]


def drifts(diag_start, diag_end, exchange=None):
    """Relative energy and angular-momentum drift per member from DIAG_FIELDS rows at the
    start and at the end: |E1 − E0| / |E0| and |L1 − L0| / |L0|. NaN where a diagnostic is.

    ``exchange`` (N, 4), with perturbations: the work W and external angular momentum L_ext
    received by the end (``kernels/perturb.py``), taken off first, so that the drift is that
    of E − W and L − L_ext, which the equations conserve (docs/physics.md §13.4)."""
    e0, l0 = totals(diag_start)
    e1, l1 = totals(diag_end)
    if exchange is not None:
        e1, l1 = e1 - exchange[:, 0], l1 - exchange[:, 1:4]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        energy = np.abs(e1 - e0) / np.abs(e0)
        angmom = np.linalg.norm(l1 - l0, axis=1) / np.linalg.norm(l0, axis=1)
    return energy, angmom


#: Kernel statuses of members that stopped before the end, judged by their drift to the stop.
STOPPED_EARLY = (Status.COLLISION, Status.ESCAPE, Status.STEP_UNDERFLOW, Status.STEP_BUDGET)


def verdict(status, energy_drift, angmom_drift, limit):
    """Status codes after the accuracy check (a new int32 array) from the kernels' codes
    ``status``: ``done`` members whose drift is not finite become ``non-finite``; ``done``
    members and members that stopped early (:data:`STOPPED_EARLY`) whose finite drift is
    above ``limit`` become ``inaccurate``; every other status is kept. The kernels' codes
    themselves are what a result keeps as ``stop_status``."""
    status = np.array(status, dtype=np.int32, copy=True)
    energy_drift = np.asarray(energy_drift, dtype=np.float64)
    angmom_drift = np.asarray(angmom_drift, dtype=np.float64)
    done = status == Status.DONE
    judged = done | np.isin(status, np.array(STOPPED_EARLY, dtype=np.int32))
    finite = np.isfinite(energy_drift) & np.isfinite(angmom_drift)
    status[done & ~finite] = Status.NONFINITE
    worst = np.fmax(energy_drift, angmom_drift)
    status[judged & finite & (worst > limit)] = Status.INACCURATE
    return status


#: Truncation limits (force, torque), relative: module docstring, "The truncation".
TRUNCATION_LIMITS = (1e-5, 1e-3)


def truncation_verdict(status, force, torque, limits=TRUNCATION_LIMITS):
    """Status codes after the truncation check (a new int32 array): ``done`` members whose
    finite truncation estimate exceeds ``limits`` (force, torque) become ``truncated``; NaN
    estimates (not estimated) and every other status are kept."""
    status = np.array(status, dtype=np.int32, copy=True)
    with np.errstate(invalid="ignore"):
        over = (np.asarray(force) > limits[0]) | (np.asarray(torque) > limits[1])
    status[(status == Status.DONE) & over] = Status.TRUNCATED
    return status


def usable(status, include_inaccurate=False):
    """Boolean mask of members whose results count in summaries: ``done``, plus
    ``inaccurate`` and ``truncated`` when ``include_inaccurate``."""
    status = np.asarray(status)
    ok = status == Status.DONE
    return ok | np.isin(status, (Status.INACCURATE, Status.TRUNCATED)) \
        if include_inaccurate else ok


def count(status, name):
    """Members with the status called ``name`` ("inaccurate", "done", ...)."""
    return int(np.count_nonzero(np.asarray(status) == Status.from_label(name)))


def counts(status):
    """{status name: members} for the statuses present, e.g. {"done": 30, "inaccurate": 2}."""
    codes, n = np.unique(np.asarray(status).ravel(), return_counts=True)
    return {STATUS_NAMES[int(c)]: int(k) for c, k in zip(codes, n)}


#: The status views every result shares (kept under its old name: the protocol is
#: :class:`ti_spinorbit.engine.results.Result`).
StatusSummary = Result
