"""Relaxed-mode libration: the centre of the synchronous island and its libration amplitude.

Physics (docs/physics.md §9.1; Naidu & Margot 2015 §3). Let α be the angle between the secondary's
long axis and the line of centres (θ + α = f). A synchronous (1:1) secondary librates in two
modes: the *relaxed* mode at the orbital frequency, forced by the eccentric orbit, and the
*excited* mode at the free, shape-dependent frequency. On the pericentre surface of section
(θ_p, θ̇_p/n) the excited mode is the island's horizontal half extent; the relaxed mode is what
is left at the island's centre, where the section trace shrinks to a point. Following Naidu &
Margot, start at θ_p = 0 and vary θ̇_p(0)/n until the horizontal extent of the trace is ~0; the
relaxed-mode amplitude is then max |α| over the whole trajectory, sampled densely (not only at
pericentre, where the forced libration passes through zero).

For a massless secondary on a fixed Keplerian orbit (docs/physics.md §8.2) the forced
solution is α = −ψ_A sin M with ψ_A = 2e/(ω0² − 1), ω0² = 3(B − A)/C; spin-orbit coupling
changes this by an amount that depends on the mass ratio (docs/physics.md §8.7 gives the first correction,
ω0,eff² = ω0² m1/(m1 + m2)). Both values are reported next to the measured amplitude.

Method of :func:`relaxed_libration`. Near the island centre c the trace of a start (0, θ̇0) is a
small closed curve through that start and symmetric about θ_p = 0 (time-reversal symmetry), so
its horizontal half extent E(θ̇0) = max |θ_p| (θ_p in (−90°, 90°]) is V-shaped,
E ≈ k |θ̇0 − c|. The search

1. launches a coarse bracket of candidates (default 45 over 0.2-1.3: coupling can move the
   centre far from 1, e.g. to ≈ 0.45 for 1991 VH) once for the section and once densely, and
   keeps the candidates whose α librates (the period-180° unwrapped α stays inside ±90°: this
   rejects circulating and chaotic starts and the 1:2 and 3:2 islands, which also sit on
   θ_p = 0 in the 180°-periodic section);
2. takes the librating candidate with the smallest E and fits a straight line to each arm of
   the V (the points on either side of the minimum, the minimum itself excluded); the arms'
   intersection estimates c far more precisely than the grid spacing;
3. zooms: a window of ``zoom_candidates`` around the estimate, one launch, refit on the whole
   window; the first half-width is the coarse spacing, each next one two grid spacings of the
   previous window (a factor 8 narrower for 33 candidates); until the half-width is below
   ``xtol`` (the window moves without shrinking when the minimum lies on its edge);
4. measures the extent at the final centre (one section launch) and the amplitude (one dense
   time series, ``samples_per_orbit`` samples per orbit).
"""

import math
import warnings
from dataclasses import dataclass, field, replace
from typing import List

import numpy as np

from .. import display as _display
from .._validate import (require_bool, require_count, require_positive, require_real,
                         require_scalar, require_spin)
from ..system import catalog
from ..system.systems import BinarySystem
from ..model import analytic
from ..model.coordinates import check_coordinates
from ..engine import accuracy, compiling, resources
from ..engine import options as _options
from ..engine import progress as _progress
from ..engine.checkpoint import Launches
from ..engine.convergence import run_lengths
from ..engine.options import Run
from ..engine.results import COORDINATES, METHOD, ORBITS, RELATIVE, SPIN, Result, unit
from .classify import horizontal_extent
from .section import SystemLike, check_orbits, plain_starts, surface_of_section, time_series
from ..units import to_plain
from ..engine.results import FLOAT as _F
from ..model.perturbations import UNIT as PERTURBATIONS, check_perturbations

#: Default coarse bracket of θ̇_p(0)/n (wide: coupling shifts the synchronous island).
DEFAULT_CANDIDATES = np.linspace(0.2, 1.3, 45)

#: Samples per orbit of the coarse scan's libration check (α changes by < 90° per sample).
CLASSIFY_SAMPLES_PER_ORBIT = 32

#: Largest section extent (deg) at a found centre for the search to count as converged.
MAX_CENTER_EXTENT_DEG = 1.0

#: A section trace that reaches beyond this |θ_p| (deg) is not treated as librating.
LIBRATION_LIMIT_DEG = 85.0


def section_extent(section, members=None, include_inaccurate=False):
    """Horizontal half extent of each member's section trace, deg: max |θ_p| with θ_p in
    (−90°, 90°]; NaN where the member stopped early (collision, escape, ...), failed the
    accuracy check ("inaccurate", unless ``include_inaccurate``) or has no point.
    ``members`` (index array) restricts it to some members of the section."""
    idx = slice(None) if members is None else members
    extent = np.atleast_1d(horizontal_extent(section.theta_p[idx]))
    ok = accuracy.usable(section.status[idx], include_inaccurate) & (section.count[idx] > 0)
    return np.where(ok, extent, np.nan)


def _amplitudes(ts, include_inaccurate=False):
    """max |α| (deg) of each member of a time series, α unwrapped with period 180° from
    α(0); NaN where α circulates, the run stopped early or failed the accuracy check."""
    ok = accuracy.usable(ts.status, include_inaccurate)
    amplitude = np.full(len(ts.status), np.nan)
    for i, alpha in enumerate(ts.alpha):
        alpha = alpha[np.isfinite(alpha)]
        if not ok[i] or not len(alpha):
            continue
        excursion = np.max(np.abs(np.unwrap(alpha, period=180.0)))
        if excursion < 90.0:
            amplitude[i] = excursion
    return amplitude


def libration_amplitude(system: SystemLike, thetadot_p, orbits, samples_per_orbit=256, *,
                        rtol=None, method=None, integrator=None, run=None, max_drift=None,
                        include_inaccurate=False, coordinates="inertial", perturbations=None):
    """Libration amplitude max |α| (deg) of starts at θ_p = 0, sampled densely.

    α is unwrapped with period 180° from α(0) = 0, so a trajectory librates when it stays
    inside ±90°. All starts run in one kernel launch.

    Parameters
    ----------
    system : BinarySystem, str or list of them
        Broadcast against ``thetadot_p`` as in :func:`~ti_spinorbit.surface_of_section` (a
        str is a catalogue name).
    thetadot_p : float, array or Quantity
        Initial spin rate of the secondary, units of n (a Quantity as for
        :func:`~ti_spinorbit.surface_of_section`).
    orbits : float or Quantity
        Integration time in initial orbital periods (a Quantity as for
        :func:`~ti_spinorbit.surface_of_section`).
    samples_per_orbit : int
        Samples of α per orbital period (α's maximum falls between pericentres).
    rtol, method, integrator, run : optional
        As for :func:`~ti_spinorbit.studies.section.time_series` (:class:`ti_spinorbit.Integrator`,
        :class:`ti_spinorbit.Run`; one launch, in this process; ``rtol`` default 1e-12).
    max_drift, include_inaccurate
        Accuracy limit (default ``min(1e-4, 1000 · rtol · orbits)``,
        :mod:`ti_spinorbit.engine.accuracy`), and whether members above it still get an amplitude.
    coordinates : {"inertial", "apsidal"}
        Spin coordinate of ``thetadot_p`` (docs/physics.md §6.7); α, and so the amplitude,
        is the same in both.
    perturbations : list of Tides, YORP, BYORP, optional
        Tides, YORP and BYORP in the equations (docs/physics.md §13), as for
        :func:`~ti_spinorbit.studies.section.time_series`: the amplitude is then max |α| of the
        perturbed trajectory over the whole run (a tide damps the libration as it goes).

    Returns
    -------
    float or ndarray
        Amplitude in degrees, one per member (a float for a single member); NaN where α
        circulates, the integration stopped early (collision, escape, ...) or the member
        failed the accuracy check (unless ``include_inaccurate``).

    Examples
    --------
    >>> amplitude = tso.libration_amplitude("1991 VH", [0.45], orbits=5)
    >>> amplitude.shape                                    # deg, one per start
    (1,)
    """
    _, thetadot_p, orbits = plain_starts(system, None, thetadot_p, orbits)
    integrator = _options.integrator(integrator, rtol, method)
    run = _options.run(run)
    with _progress.reporting(run.progress, "libration_amplitude") as report:
        ts = time_series(system, 0.0, thetadot_p, orbits, samples_per_orbit=samples_per_orbit,
                         integrator=integrator, run=replace(run, progress=report),
                         max_drift=max_drift, coordinates=coordinates,
                         perturbations=perturbations)
    amplitude = _amplitudes(ts, include_inaccurate)
    return float(amplitude[0]) if np.ndim(thetadot_p) == 0 and len(amplitude) == 1 else amplitude


def _psi_A_deg(omega0, e):
    """ψ_A = 2e/(ω0² − 1) in degrees; inf at the forced resonance ω0 = 1 (0 for e = 0)."""
    if omega0 == 1.0:
        return math.inf if e else 0.0
    return math.degrees(analytic.psi_A(omega0, e))


@dataclass(repr=False)
class RelaxedLibration(Result, _display.Readable, kind="relaxed_libration"):
    """Centre of the synchronous island and the relaxed-mode libration amplitude.

    Attributes
    ----------
    centre_thetadot_p : float
        Initial θ̇_p/n (θ_p(0) = 0) of the island centre.
    amplitude : float
        Max |α| of that trajectory, deg: the relaxed-mode libration amplitude.
    extent : float
        Its section's horizontal half extent, deg (the excited mode left over).
    psi_A, psi_A_effective : float
        The decoupled estimates 2e/(ω0² − 1), deg, with ω0 and with ω0,eff² = ω0² m1/(m1+m2)
        (``omega0``, ``omega0_effective``).
    converged : bool
        Whether the final window is narrower than ``xtol``, the extent at the centre is below
        ``max_extent``, the final trajectory passed the accuracy check and the checks at
        longer runs and at rtol/10 agree (``search_converged``, ``converged_in_orbits``,
        ``converged_in_tolerance``, ``convergence_checked``; ``message`` says which).
    iterations, candidates, extents
        Zoom launches, and the θ̇_p/n tried with their extents (deg), one array per launch, the
        coarse bracket first (extent NaN where the start does not librate).
    lengths, centres_by_length, amplitudes_by_length
        The evidence against run length; ``rtol_check``, ``centre_rtol_check`` and
        ``amplitude_rtol_check`` at rtol/10, held to ``centre_tol`` and ``amplitude_tol``.
    status, energy_drift, angmom_drift, max_drift
        The final trajectory's status, its relative drifts and their limit.
    coordinates : str
        The spin coordinate of ``centre_thetadot_p`` and ``candidates`` ("inertial" or
        "apsidal", docs/physics.md §6.7).
    system, orbits, rtol, method, samples_per_orbit, xtol, seconds, series, perturbations
        The system, run length (orbital periods), tolerance, Runge-Kutta pair, sampling, the
        search's tolerance, wall time (s), the centre's time series and the perturbations.
    """

    # what a loaded file's arrays must look like (Result.SHAPES; k lengths)
    SHAPES = {k: (("k",), _F) for k in ("lengths", "centres_by_length", "amplitudes_by_length")}

    centre_thetadot_p: float = unit(SPIN)
    amplitude: float = unit('deg')
    extent: float = unit('deg')
    psi_A: float = unit('deg')
    psi_A_effective: float = unit('deg')
    omega0: float = unit(SPIN)
    omega0_effective: float = unit(SPIN)
    iterations: int = unit('launches')
    converged: bool = unit('bool')
    candidates: List[np.ndarray] = unit(SPIN, repr=False)
    extents: List[np.ndarray] = unit('deg', repr=False)
    orbits: float = unit(ORBITS, default=0.0)
    rtol: float = unit('1', default=1e-12)
    samples_per_orbit: int = unit('1/orbit', default=256)
    xtol: float = unit(SPIN, default=1e-6)
    seconds: float = unit('s', default=0.0)
    system: BinarySystem = field(default=None, repr=False)
    status: str = unit('name', default="done")
    energy_drift: float = unit(RELATIVE, default=float("nan"))
    angmom_drift: float = unit(RELATIVE, default=float("nan"))
    max_drift: float = unit(RELATIVE, default=float("nan"))
    coordinates: str = unit(COORDINATES, default="inertial")
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    # convergence evidence (relaxed_libration(converge=True)): the centre and amplitude
    # found at each length of the doubling (orbits, 2·orbits, ...) and at rtol/10 at the
    # last length; the tolerances they were held to; the verdicts and a one-line message
    search_converged: bool = unit('bool', default=True)
    lengths: np.ndarray = unit(ORBITS, default=None)
    centres_by_length: np.ndarray = unit(SPIN, default=None)
    amplitudes_by_length: np.ndarray = unit('deg', default=None)
    rtol_check: float = unit('1', default=float("nan"))
    centre_rtol_check: float = unit(SPIN, default=float("nan"))
    amplitude_rtol_check: float = unit('deg', default=float("nan"))
    centre_tol: float = unit(SPIN, default=float("nan"))
    amplitude_tol: float = unit('deg', default=float("nan"))
    converged_in_orbits: bool = unit('bool', default=False)
    converged_in_tolerance: bool = unit('bool', default=False)
    convergence_checked: bool = unit('bool', default=False)
    message: str = unit('text', default="")
    #: the dense time series at the centre (the trajectory whose max |α| is ``amplitude``);
    #: None in files written before it was stored (``trajectory()`` computes it again)
    series: object = field(default=None, repr=False)
    #: tides / YORP / BYORP in the equations of every launch (docs/physics.md §13)
    perturbations: tuple = unit(PERTURBATIONS, default=())

    def trajectory(self):
        """The time series at the centre: ``series``, or (for files written without it) the
        same run again (θ_p = 0, θ̇_p/n = the centre, ``orbits``, ``samples_per_orbit``,
        ``rtol``)."""
        if self.series is None:
            self.series = time_series(self.system, 0.0, self.centre_thetadot_p, self.orbits,
                                      samples_per_orbit=self.samples_per_orbit, rtol=self.rtol,
                                      coordinates=self.coordinates, method=self.method,
                                      perturbations=self.perturbations)
        return self.series

    def plot(self, ax=None, title=None, search=None):
        """α(t) at the centre with the amplitude max |α| and the decoupled |ψ_A| band (and,
        on a new figure, the search's panels): :func:`ti_spinorbit.output.plotting.plot_libration`.
        Returns the Axes of α(t)."""
        return self._figure(ax=ax, title=title, search=search)

    def evidence(self):
        """Lines: centre and amplitude against orbits and tolerance, and the verdict."""
        if not self.convergence_checked:
            return [f"convergence in orbits and tolerance not checked ({self.message})"
                    if self.message else "convergence in orbits and tolerance not checked"]
        rows = [f"{'orbits':>8} {'rtol':>8} {'centre (n)':>14} {'amplitude (deg)':>16}"]
        for L, c, a in zip(self.lengths, self.centres_by_length, self.amplitudes_by_length):
            rows.append(f"{L:8g} {self.rtol:8.0e} {c:14.9f} {a:16.6f}")
        if np.isfinite(self.rtol_check):
            rows.append(f"{self.lengths[-1]:8g} {self.rtol_check:8.0e} "
                        f"{self.centre_rtol_check:14.9f} {self.amplitude_rtol_check:16.6f}")
        rows.append(f"(held to |Δcentre| <= {self.centre_tol:.3g} n, |Δamplitude| <= "
                    f"{self.amplitude_tol:.3g} deg)")
        rows.append(self.message)
        return rows


def _fit_v(x, extent, best):
    """Centre of the V from straight lines fitted to its arms (points left and right of the
    minimum ``best``, which itself may sit on either arm). Returns None when an arm has
    fewer than two points or the lines do not cross between the minimum's neighbours."""
    left = np.arange(best)
    right = np.arange(best + 1, len(x))
    left = left[np.isfinite(extent[left])]
    right = right[np.isfinite(extent[right])]
    if len(left) < 2 or len(right) < 2:
        return None
    sl, bl = np.polyfit(x[left], extent[left], 1)
    sr, br = np.polyfit(x[right], extent[right], 1)
    if not (sl < 0 < sr):
        return None
    center = (bl - br) / (sr - sl)
    if not x[best - 1] <= center <= x[best + 1]:
        return None
    return float(center)


def _arm_window(x, extent, best, points):
    """Indices of up to ``points`` finite neighbours on each side of ``best`` (plus best)."""
    finite = np.flatnonzero(np.isfinite(extent))
    left = finite[finite < best][-points:]
    right = finite[finite > best][:points]
    return np.concatenate([left, [best], right])


def relaxed_libration(system: BinarySystem, orbits=100, *, rtol=None, method=None,
                      integrator=None, run=None, candidates=None, zoom_candidates=33,
                      xtol=1e-6, max_iterations=10, samples_per_orbit=256,
                      coarse_arm_points=3, max_extent=MAX_CENTER_EXTENT_DEG, max_drift=None,
                      coordinates="inertial", converge=True, max_orbits=None,
                      centre_tol=None, amplitude_tol=0.01,
                      perturbations=None) -> RelaxedLibration:
    """Find the centre of the synchronous island and measure the relaxed libration amplitude.

    Parameters
    ----------
    system : BinarySystem or str
        The system, or a catalogue name (``ti_spinorbit.system.catalog``).
    orbits : float or Quantity
        Integration time of every trajectory, initial orbital periods (the section of each
        candidate has about this many points); a Quantity in ``ti_spinorbit.units.orbit``
        or a time (divided by the system's period).
    rtol, method, integrator : optional
        How the equations are integrated (:class:`ti_spinorbit.Integrator`; ``rtol``
        default 1e-12), the same for every launch.
    run : Run, optional
        How the run is carried out (:class:`ti_spinorbit.Run`; in this process, no client):
        the progress (see below), the checkpoints of the search's launches (``DIR/launch-kkk``,
        one per launch: :class:`ti_spinorbit.engine.checkpoint.Launches`).
    candidates : array or Quantity, optional
        Coarse bracket of initial θ̇_p/n (θ_p = 0), at least 5 values, ascending, each in
        [-100, 100]; default 45 values over 0.2-1.3.
    zoom_candidates : int
        Candidates per zoom launch (odd, so the window's centre is one of them).
    xtol : float
        Stop zooming when the window's half-width is below this (units of n).
    max_iterations : int
        Most zoom launches.
    samples_per_orbit : int
        Samples per orbit of the final time series that measures the amplitude.
    coarse_arm_points : int
        Points per arm of the V fitted on the coarse bracket (its arms bend away from the
        centre, so only the nearest few are used).
    max_extent : float or Quantity
        Largest section extent (deg) allowed at the centre found; above it the search is
        reported as not converged (a chaotic zone can also narrow the zoom window).
    Progress (``run.progress``): None (default) a bar in a terminal or Jupyter for runs
        over 2 s; True/False: always/never (:mod:`ti_spinorbit.engine.progress`); a callable:
        ``progress(fraction)`` after every launch of the search, with the convergence checks' searches after it
        (each its share ∝ its length). Within a search: (the coarse section, the
        coarse libration check, each zoom, the final section, the final time series):
        launches done / (launches done + launches still expected), the zoom launches still
        expected estimated from the window's half-width, ``xtol`` and ``max_iterations``;
        1.0 after the last.
    max_drift : float, optional
        Accuracy limit of every trajectory (default ``min(1e-4, 1000 · rtol · orbits)``,
        :mod:`ti_spinorbit.engine.accuracy`): "inaccurate" candidates take no part in the search,
        and an inaccurate final trajectory makes the result not converged.
    coordinates : {"inertial", "apsidal"}
        Spin coordinate of the candidates and of the centre found (docs/physics.md §6.7):
        the centre in apsidal coordinates is the inertial one minus ϖ̇(0)/n. The amplitude
        max |α| does not depend on it.
    converge : bool
        Check the answer in integration length and tolerance (default True): the search is
        repeated, bracketed around the centre found, at 2·orbits, 4·orbits, ... until two
        successive lengths give centres within ``centre_tol`` and amplitudes within
        ``amplitude_tol`` (at most ``max_orbits``, default ``4 · orbits``), then at the last
        length with rtol/10 (skipped below rtol 1e-15). ``converged`` is then True only when
        the search converged *and* both checks pass; ``message`` says which failed
        ("not converged by N orbits", "not converged in tolerance"). The reported centre and
        amplitude are those at ``orbits`` and ``rtol``; the others are the evidence.
    max_orbits : float or Quantity, optional
        Cap of the doubling, in [orbits, 1e7] (default ``4 · orbits``).
    centre_tol : float, optional
        Agreement required of the centres, units of n (default ``max(10 · xtol, 1e-5)``).
    amplitude_tol : float
        Agreement required of the amplitudes, deg (default 0.01).
    perturbations : list of Tides, YORP, BYORP, optional
        Tides, YORP and BYORP in the equations of every launch of the search and of its
        convergence checks (docs/physics.md §13). With a dissipative tide the island's
        centre is no longer a fixed point of the section, so the search finds the start whose
        trace is narrowest over ``orbits``; keep the strength small enough that the centre
        moves little in that time. Recorded in the result.

    Returns
    -------
    RelaxedLibration

    Raises
    ------
    ValueError
        Bad input.
    RuntimeError
        No coarse candidate librates, or the trajectory at the centre found does not.

    See Also
    --------
    libration_amplitude : the amplitude of given starts
    ti_spinorbit.analytic.psi_A : the forced amplitude of the decoupled problem

    References
    ----------
    * Naidu, S. P. & Margot, J.-L. 2015, AJ 149:80, §7 and Fig. 3.

    Examples
    --------
    The centre of Didymos' synchronous island and the libration there (a short, unchecked
    search: ``converge=False``):

    >>> lib = tso.relaxed_libration("Didymos", orbits=5, converge=False)
    >>> round(float(lib.amplitude), 1)                     # deg
    15.8
    >>> lib.status_names
    ['done']
    """
    system = catalog.as_system(system)
    candidates, orbits, max_orbits = (to_plain(name, value, unit, system=system) for name, value, unit
                                      in (("candidates", candidates, "n"), ("orbits", orbits, "orbit"),
                                          ("max_orbits", max_orbits, "orbit")))
    check_coordinates(coordinates)
    if not system.omega0 > 0:
        raise ValueError("the secondary must be elongated (B > A, omega0 > 0) to have a "
                         "synchronous island")
    require_real("orbits", orbits)
    require_positive("orbits", orbits)
    check_orbits(orbits)
    integrator = _options.integrator(integrator, rtol, method)
    run = _options.run(run)
    if run.client is not None:
        raise ValueError("relaxed_libration runs in this process: run=Run(client=...) is for "
                         "surface_of_section and the maps and scans")
    rtol = integrator.rtol
    require_real("xtol", xtol)
    accuracy.drift_limit(rtol, orbits, max_drift)           # max_drift checked before any work
    require_positive("xtol", xtol)
    max_extent = require_scalar("max_extent", max_extent, 0.0, 90.0, low_open=True, unit="deg")
    zoom_candidates = require_count("zoom_candidates", zoom_candidates, 5, 100001)
    if zoom_candidates % 2 == 0:
        raise ValueError(f"zoom_candidates must be odd (got {zoom_candidates})")
    max_iterations = require_count("max_iterations", max_iterations, 0, 1000)
    samples_per_orbit = require_count("samples_per_orbit", samples_per_orbit, 1, 100000)
    coarse_arm_points = require_count("coarse_arm_points", coarse_arm_points, 2, 100000)
    x = DEFAULT_CANDIDATES.copy() if candidates is None else \
        np.asarray(require_spin("candidates", candidates), dtype=np.float64).ravel()
    if len(x) < 5 or np.any(np.diff(x) <= 0):
        raise ValueError(f"candidates must hold at least 5 ascending values (got {candidates!r})")

    # every launch of the search, sized before the first (the largest decides)
    for what, members, spo in (("relaxed_libration (coarse section)", len(x), None),
                               ("relaxed_libration (libration check)", len(x),
                                CLASSIFY_SAMPLES_PER_ORBIT),
                               ("relaxed_libration (zoom)", zoom_candidates, None),
                               ("relaxed_libration (amplitude)", 1, samples_per_orbit)):
        resources.check_memory(what, members, orbits, spo,
                               advice="use fewer orbits, candidates or samples per orbit")

    converge = require_bool("converge", converge)
    if centre_tol is None:
        centre_tol = max(10.0 * float(xtol), 1e-5)
    require_positive("centre_tol", require_real("centre_tol", centre_tol))
    require_positive("amplitude_tol", require_real("amplitude_tol", amplitude_tol))
    cap = 4.0 * float(orbits) if max_orbits is None else require_real("max_orbits", max_orbits)
    if not float(orbits) <= cap <= 1e7:
        raise ValueError(f"max_orbits must lie in [orbits, 1e7] = [{float(orbits):g}, 1e7] "
                         f"(got {cap:g})")

    perturbations = check_perturbations(perturbations)
    # every launch alike: one integrator (its rtol set per search), the run's window
    search = dict(zoom_candidates=zoom_candidates, xtol=xtol, max_iterations=max_iterations,
                  samples_per_orbit=samples_per_orbit, coarse_arm_points=coarse_arm_points,
                  max_extent=max_extent, max_drift=max_drift, integrator=integrator,
                  coordinates=coordinates, perturbations=perturbations,
                  launch=Run(window_orbits=run.window_orbits),
                  checkpoints=Launches(run.checkpoint, run.resume, run.overwrite,
                                       run.keep_checkpoint))
    with search["checkpoints"].owned(), \
            _progress.reporting(run.progress, "relaxed_libration") as report:
        # progress: each search its share of the work, ∝ its length (rtol/10: ~1.6x the steps)
        planned = [float(orbits)]
        while converge and planned[-1] * 2.0 <= cap * (1 + 1e-12):
            planned.append(planned[-1] * 2.0)
        tight_work = planned[-1] * 10 ** 0.2 if converge and len(planned) > 1 else 0.0
        work = sum(planned) + tight_work
        # the base search, then the doublings until centre and amplitude stop changing
        started = bracket = None

        def stage(k, length, share):
            nonlocal started, bracket
            if k == 0:
                base = _search(system, length, rtol, candidates, progress=share, **search)
                started = compiling.Stopwatch(already=base.seconds)   # compile time left out
                # the checks start bracketed around the centre found: the coarse scan is not
                # repeated
                spacing = float(np.max(np.diff(base.candidates[0])))
                bracket = base.centre_thetadot_p + spacing * np.linspace(-4.0, 4.0, 9)
                return base
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)   # summarised in the message
                return _search(system, length, rtol, bracket, progress=share, **search)

        def settled(a, b):
            return abs(b.centre_thetadot_p - a.centre_thetadot_p) <= centre_tol and \
                abs(b.amplitude - a.amplitude) <= amplitude_tol

        ladder = run_lengths(planned, stage, report, settled, extra_work=tight_work)
        base = ladder.outcomes[0]
        if not converge:
            return base
        lengths = ladder.lengths
        centres = [r.centre_thetadot_p for r in ladder.outcomes]
        amplitudes = [r.amplitude for r in ladder.outcomes]
        in_orbits = ladder.settled
        tight = float(rtol) / 10.0
        in_tol, c_tol, a_tol = False, float("nan"), float("nan")
        if tight >= 1e-16 and len(lengths) > 1:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                fine = _search(system, lengths[-1], tight, bracket,
                               progress=_progress.stage(report, 1.0 - tight_work / work,
                                                        tight_work / work), **search)
            c_tol, a_tol = fine.centre_thetadot_p, fine.amplitude
            in_tol = abs(c_tol - centres[-1]) <= centre_tol and \
                abs(a_tol - amplitudes[-1]) <= amplitude_tol and fine.converged
        messages = []
        if not base.converged:
            messages.append("search not converged (window or extent at the centre)")
        if len(lengths) == 1:
            messages.append(f"not converged by {lengths[-1]:g} orbits: max_orbits leaves no "
                            "doubling to compare")
        elif not in_orbits:
            messages.append(f"not converged by {lengths[-1]:g} orbits: centre/amplitude still "
                            f"move by {abs(centres[-1] - centres[-2]):.3g} n / "
                            f"{abs(amplitudes[-1] - amplitudes[-2]):.3g} deg")
        if not np.isfinite(c_tol):
            if len(lengths) > 1:
                messages.append(f"tolerance not checked (rtol/10 = {tight:.0e} is below 1e-16)")
        elif not in_tol:
            messages.append(f"not converged in tolerance: rtol {tight:.0e} moves the centre by "
                            f"{abs(c_tol - centres[-1]):.3g} n, the amplitude by "
                            f"{abs(a_tol - amplitudes[-1]):.3g} deg")
        converged = bool(base.converged and in_orbits and in_tol)
        if converged:
            messages.append(f"converged: centre and amplitude agree at {lengths[-2]:g} and "
                            f"{lengths[-1]:g} orbits and at rtol {rtol:.0e} and {tight:.0e}")
        base.search_converged = base.converged
        base.converged = converged
        base.lengths = np.array(lengths)
        base.centres_by_length = np.array(centres)
        base.amplitudes_by_length = np.array(amplitudes)
        base.rtol_check, base.centre_rtol_check, base.amplitude_rtol_check = \
            (tight if np.isfinite(c_tol) else float("nan")), c_tol, a_tol
        base.centre_tol, base.amplitude_tol = float(centre_tol), float(amplitude_tol)
        base.converged_in_orbits, base.converged_in_tolerance = in_orbits, bool(in_tol)
        base.convergence_checked = True
        base.message = "; ".join(messages)
        report(1.0)
    base.seconds = started.seconds()
    return base


def _search(system, orbits, rtol, candidates, zoom_candidates, xtol, max_iterations,
            samples_per_orbit, coarse_arm_points, max_extent, max_drift, integrator,
            coordinates, perturbations, launch, checkpoints,
            progress=None) -> RelaxedLibration:
    """The search of :func:`relaxed_libration` at one length and tolerance ``rtol`` (inputs
    checked; ``launch`` the run options of every launch, checkpoints added per launch)."""
    limit = accuracy.drift_limit(rtol, orbits, max_drift)
    integrator = replace(integrator, rtol=rtol)
    method = integrator.method
    common = dict(integrator=integrator, max_drift=limit, coordinates=coordinates,
                  perturbations=perturbations)

    def run_next():
        return replace(launch, **checkpoints.next())
    x = DEFAULT_CANDIDATES.copy() if candidates is None else \
        np.asarray(candidates, dtype=np.float64).ravel()
    shrink = (zoom_candidates - 1) / 4.0           # window narrowing per zoom launch
    launches = 0

    def zooms_left(half_width, iterations):
        """Zoom launches still expected from the window's half-width (a guess: a window
        that moves instead of shrinking costs one more)."""
        if half_width <= xtol:
            return 0
        needed = max_iterations if shrink <= 1.0 else \
            math.ceil(math.log(half_width / xtol) / math.log(shrink))
        return max(0, min(max_iterations - iterations, needed))

    def launched(left):
        """One more launch done, ``left`` still expected: report the fraction done."""
        nonlocal launches
        launches += 1
        if progress is not None:
            progress(launches / (launches + left))

    start = compiling.Stopwatch()          # compile time left out of seconds
    # 1. coarse bracket: the section gives the extent, a dense run says which starts librate
    half_width = float(np.max(np.diff(x)))
    coarse = surface_of_section(system, 0.0, x, orbits, run=run_next(), **common)
    if coarse.n_inaccurate == len(x):
        raise RuntimeError(f"every candidate's conservation drift exceeds max_drift {limit:.3g} "
                           f"(largest energy drift {np.nanmax(coarse.energy_drift):.3g}); "
                           "tighten rtol")
    extent = section_extent(coarse)
    launched(1 + zooms_left(half_width, 0) + 2)
    librates = np.isfinite(libration_amplitude(system, x, orbits,
                                               samples_per_orbit=CLASSIFY_SAMPLES_PER_ORBIT,
                                               run=run_next(), **common))
    launched(zooms_left(half_width, 0) + 2)
    extent[~librates | (extent >= LIBRATION_LIMIT_DEG)] = np.nan
    tried, extents = [x], [extent]
    if not np.any(np.isfinite(extent)):
        raise RuntimeError(f"no candidate in [{x[0]:.6g}, {x[-1]:.6g}] librates about the "
                           f"synchronous state over {orbits} orbits; pass other candidates")
    best = int(np.nanargmin(extent))
    near = _arm_window(x, extent, best, coarse_arm_points)
    center = _fit_v(x[near], extent[near], int(np.flatnonzero(near == best)[0]))
    if center is None:
        center = float(x[best])

    # 2-3. zoom: each launch one window, the V refitted on all of it
    iterations = 0
    while half_width > xtol and iterations < max_iterations:
        x = center + np.linspace(-half_width, half_width, zoom_candidates)
        extent = section_extent(surface_of_section(system, 0.0, x, orbits, run=run_next(),
                                                   **common))
        extent[extent >= LIBRATION_LIMIT_DEG] = np.nan
        tried.append(x)
        extents.append(extent)
        iterations += 1
        if not np.any(np.isfinite(extent)):
            raise RuntimeError(f"no start librates near θ̇_p/n = {center:.9g}")
        best = int(np.nanargmin(extent))
        if best in (0, len(x) - 1):            # centre outside the window: move, keep width
            center = float(x[best])
        else:
            fitted = _fit_v(x, extent, best)
            center = float(x[best]) if fitted is None else fitted
            half_width *= 4.0 / (zoom_candidates - 1)
        launched(zooms_left(half_width, iterations) + 2)
    # 4. the centre itself
    final_extent = float(section_extent(surface_of_section(system, 0.0, center, orbits,
                                                           run=run_next(), **common),
                                        include_inaccurate=True)[0])
    launched(1)
    # a narrow window is not enough: at a true centre the trace shrinks to a point (a chaotic
    # zone, e.g. 1996 FG3 at a/b = 1.1, also narrows the window but leaves a wide trace)
    converged = half_width <= xtol and final_extent <= max_extent
    if not converged:
        warnings.warn(f"relaxed_libration: not converged (window half-width {half_width:.3g}, "
                      f"xtol {xtol:.3g}; extent at the centre {final_extent:.3g} deg, allowed "
                      f"{max_extent:g} deg) after {iterations} launches", RuntimeWarning,
                      stacklevel=2)
    ts = time_series(system, 0.0, center, orbits, samples_per_orbit=samples_per_orbit,
                     run=run_next(), **common)
    amplitude = float(_amplitudes(ts, include_inaccurate=True)[0])   # kept, flagged below
    launched(0)
    if not np.isfinite(amplitude):
        raise RuntimeError(f"the trajectory from θ̇_p/n = {center:.9g} does not librate")
    status = ts.status_names[0]
    if status != "done":
        converged = False
        warnings.warn(f"relaxed_libration: the trajectory at the centre is {status} (energy "
                      f"drift {ts.energy_drift[0]:.3g}, limit {limit:.3g}); its amplitude is "
                      "not trustworthy: tighten rtol", RuntimeWarning, stacklevel=2)
    omega0_effective = analytic.omega0_effective(system)
    return RelaxedLibration(
        centre_thetadot_p=center, amplitude=float(amplitude), extent=final_extent,
        psi_A=_psi_A_deg(system.omega0, system.e), psi_A_effective=_psi_A_deg(omega0_effective, system.e),
        omega0=system.omega0, omega0_effective=omega0_effective,
        iterations=iterations, converged=converged, candidates=tried, extents=extents,
        orbits=float(orbits), rtol=float(rtol), samples_per_orbit=samples_per_orbit, xtol=xtol,
        seconds=start.seconds(), system=system, status=status,
        energy_drift=float(ts.energy_drift[0]), angmom_drift=float(ts.angmom_drift[0]),
        max_drift=limit, coordinates=coordinates, series=ts, method=method,
        perturbations=perturbations)
