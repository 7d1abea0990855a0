"""Surfaces of section and dense time series of ensembles (docs/physics.md §6, §9.1).

``surface_of_section`` records, at every pericentre passage of the osculating mutual orbit,
the angle θ_p from the line of apsides to the secondary's long axis and the secondary's spin
rate θ̇_p/n (Naidu & Margot 2015 §2.3, Figs. 4–9). ``time_series`` samples one or more members
densely (spin rate, α, r, energy) for libration and spin-rate studies (their Figs. 3, 10, 11).
Both take ``coordinates``: "inertial" (default; θ̇ the inertial spin rate) or "apsidal" (the
paper's: θ and θ̇ from the osculating line of apsides, θ̇ = spin rate − ϖ̇; docs/physics.md
§6.7, ``ti_spinorbit.model.coordinates``).

Inputs broadcast: a system (or a list giving one member per system), θ_p (deg) and θ̇_p/n,
scalars or arrays, are broadcast against each other to N members.
"""

import time
import warnings
from dataclasses import dataclass, field, replace
from typing import Sequence, Union

import numpy as np

from .. import display as _display
from .._validate import require_bool, require_count, require_real
from ..engine import accuracy, evaluation, options as _options, progress as _progress
from ..engine.ensemble import Ensemble, RunOutput
from ..engine.members import Members, member_groups
from ..engine.options import Integrator, Run
from ..engine.results import (COORDINATES, FLOAT as _F, INTEGER as _I, METHOD, ORBITS, RELATIVE,
                              Result, SPIN, STATUS, unit)
from ..layout import RECORD_WIDTH, spatial as _S
from ..model import attitude as _attitude, coordinates as _coords
from ..model.attitude import (CLASSES, CLASS_UNIT as ATTITUDE_CLASS, classify,
                              euler_angles_of_rows, npa_angle, pole_tilt)
from ..model.models import check_indicator_space
from ..model.observables import derive
from ..model.perturbations import UNIT as PERTURBATIONS
from ..system import catalog
from ..system.initial import ROW_SLICES, ROW_UNIT as STATE_ROW, physical_rows
from ..system.systems import BinarySystem, NEAR_CIRCULAR_E, NearCircularWarning
from ..units import to_plain

SystemLike = Union[BinarySystem, Sequence[BinarySystem]]

#: Unit text of the degree caps of an order-N run (None at orders up to 4).
DEGREES = "1 (degree caps of the primary's and the secondary's integrals)"
#: Unit text of the torque's truncation estimate (relative to the force times ρ_B).
TRUNCATION_TORQUE = "1 (of |F| times the secondary's bounding radius)"

#: Largest ``orbits`` accepted by surface_of_section and time_series (10 million orbits is
#: days of CPU time even for one member; the command line's --orbits has the same bound).
MAX_ORBITS = 1e7

#: Unit text of the indicator_space fields (docs/physics.md §10.4).
INDICATOR_SPACE = ("text: shadow direction of MEGNO and the Lyapunov exponent, 'planar' (fixed "
                   "planar direction) or 'full' (the whole state, attitudes by a small rotation)")


def plain_starts(system, theta_p, thetadot_p, orbits):
    """(θ_p in degrees, θ̇_p in units of n, orbits) of an entry point as plain numbers: a
    Quantity converted (:mod:`ti_spinorbit.units`: an angle, a rate dimensionless or in
    ``units.n``, or an angular rate divided by the system's n; a length of time in
    ``units.orbit`` or a time divided by the period 2π/n, where ``system`` is one system),
    a plain value unchanged after the degree hint. None stays None."""
    if isinstance(system, str) or (isinstance(system, (list, tuple)) and
                                   any(isinstance(s, str) for s in system)):
        try:                # a catalogue name: its n (a bad one is refused later, by name)
            system = catalog.as_system(system, allow_list=True)
        except (TypeError, ValueError):
            system = None
    return (to_plain("theta_p", theta_p, "deg"),
            to_plain("thetadot_p", thetadot_p, "n", system=system),
            to_plain("orbits", orbits, "orbit", system=system))


def check_orbits(orbits):
    """``orbits`` as a float, or ValueError unless it is finite and lies in (0, MAX_ORBITS]."""
    value = require_real("orbits", orbits, "orbit")
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"orbits must be a finite number > 0 (got {orbits!r})")
    if value > MAX_ORBITS:
        raise ValueError(f"orbits must lie in (0, {MAX_ORBITS:g}] (got {value:g})")
    return value


def _warn_near_circular(members):
    """NearCircularWarning when a section's system has e < NEAR_CIRCULAR_E (pericentre
    ill-defined); a warning, since such a run is still a valid integration."""

    low = sorted({m.e for m in members if m.e < NEAR_CIRCULAR_E})
    if low:
        warnings.warn(f"surface_of_section: e = {low[0]:g} < {NEAR_CIRCULAR_E:g}: the pericentre "
                      "where the section samples is ill-defined on a nearly circular orbit; the "
                      "points follow the osculating elements more than the spin",
                      NearCircularWarning, stacklevel=3)


def _segment_max(values, counts, floor):
    """Per segment of ``values`` (consecutive runs of ``counts``), the largest non-NaN value
    joined with ``floor`` by ``np.fmax`` (a segment with none keeps ``floor``)."""
    out = np.array(floor, dtype=np.float64, copy=True)
    has = counts > 0
    if has.any():
        starts = (np.cumsum(counts) - counts)[has]
        out[has] = np.fmax(out[has], np.fmax.reduceat(values, starts))
    return out


def _per_member(members, value):
    """``value(system)`` (a number or a tuple of numbers) for every member, as an array with
    one row per member, evaluated once per distinct system (no loop over members)."""
    groups = member_groups(members)
    first = np.asarray(value(groups[0][0]), dtype=np.float64) if groups else np.zeros(0)
    out = np.empty((len(members),) + first.shape)
    for system, idx in groups:
        out[idx] = value(system)
    return out


def _state_rows_and_tilt(members, records_list, y0, y_end):
    """Per member: its start as a state row (docs/physics.md §6.8), the largest pole tilt and
    the largest angle of the spin angular momentum from the short axis (degrees,
    docs/physics.md §6.9) over the start, every record and the end. Every record of every
    member goes through one array pass (no loop over members)."""

    rows = np.empty((len(members), 30))
    for m, idx in member_groups(members):
        rows[idx] = physical_rows(m, y0[idx])
    counts = np.fromiter((len(r) for r in records_list), dtype=np.int64, count=len(records_list))
    flat = np.concatenate([np.zeros((0, 30))] + [r[:, 1:31] for r in records_list if len(r)])
    tilt = _segment_max(pole_tilt(flat), counts, np.fmax(pole_tilt(y0), pole_tilt(y_end)))
    npa = _segment_max(npa_angle(flat), counts, np.fmax(npa_angle(y0), npa_angle(y_end)))
    return rows, tilt, npa


@dataclass(repr=False)
class SectionResult(Result, _display.Readable, kind="section"):
    """Pericentre surface of section for N members (arrays padded with NaN to (N, max count)).

    Attributes
    ----------
    theta_p : ndarray, shape (N, max count)
        θ_p at every pericentre crossing, deg in [0, 180); NaN-padded, as every per-crossing
        array. The same in both ``coordinates`` (docs/physics.md §6.7).
    thetadot_p : ndarray, shape (N, max count)
        θ̇_p/n at every crossing, units of the mean motion n: the inertial spin rate, or with
        ``coordinates="apsidal"`` the spin rate minus the apsidal rate ϖ̇ (the paper's).
    t : ndarray, shape (N, max count)
        Time of every crossing, s.
    r : ndarray, shape (N, max count)
        Pericentre distance, m.
    a, e : ndarray, shape (N, max count)
        Osculating semimajor axis (m) and eccentricity at every crossing.
    count : ndarray of int, shape (N,)
        Crossings recorded per member.
    initial_theta_p, initial_thetadot_p : ndarray, shape (N,)
        Each member's start, deg and units of n.
    energy_drift, angmom_drift : ndarray, shape (N,)
        Relative drift of the total energy and of the total angular-momentum vector from the
        start to the end of the run.
    max_drift : float
        The drift limit they were held against (docs/statuses.md).
    status : ndarray of int, shape (N,)
        Status codes (:class:`~ti_spinorbit.Status`), with ``status_names`` ("done",
        "inaccurate" when a drift exceeds ``max_drift``, "non-finite", "collision", ...) and
        ``status_counts``.
    stop_status : ndarray of int, shape (N,)
        The integrator's own codes before the accuracy verdict: why each member stopped
        ("done" when it ran to the end), kept for an "inaccurate" member that collided or
        escaped (None in files written before it existed).
    accepted, rejected, rhs_calls : ndarray of int, shape (N,)
        Accepted and rejected steps and right-hand-side calls per member.
    megno, lyapunov : ndarray, shape (N,)
        With ``indicators=True``: MEGNO ⟨Y⟩ at the end (→ 2 quasi-periodic, ≫ 2 chaotic) and the
        finite-time maximal Lyapunov exponent (1/orbit); else NaN.
    indicator_space : str
        The shadow direction of the indicators, "planar" or "full" (docs/physics.md §10.4).
    coordinates : str
        "inertial" or "apsidal", the spin coordinate of ``thetadot_p`` and
        ``initial_thetadot_p``.
    apsidal_rate : ndarray, shape (N, max count) or None
        With ``coordinates="apsidal"``: ϖ̇/n at every crossing (NaN where e is below the
        apsidal coordinates' minimum eccentricity).
    systems : list of BinarySystem
        Each member's system.
    initial_states, max_tilt, max_npa_angle : ndarray
        The members' SI start rows (docs/physics.md §6.8), and the largest tilt of the
        secondary's pole and non-principal-axis angle reached, deg.
    truncation_force, truncation_torque : ndarray, shape (N,)
        The relative size of the mutual potential's next two orders at each member's closest
        approach, in the force and in the secondary's torque (over |F| ρ_B): "truncated" above
        the truncation limits, NaN where not estimated (docs/physics.md §3.9).
    rtol, atol, method, order, degrees, orbits, seconds, perturbations
        The integration's tolerances, Runge-Kutta pair, truncation order and degree caps, run
        length (orbital periods), wall time (s) and perturbations.

    Examples
    --------
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45, 1.70], orbits=10)
    >>> sos.theta_p.shape                                  # (members, crossings), NaN-padded
    (2, 10)
    >>> bool(np.isnan(sos.theta_p[1, -1]))                 # the second member crossed 9 times
    True
    >>> sos.status_counts
    {'done': 2}
    """

    # what a loaded file's arrays must look like (Result.SHAPES; n members, w crossings)
    SHAPES = {
        **{k: (("n", "w"), _F) for k in ("theta_p", "thetadot_p", "t", "r", "a", "e",
                                          "apsidal_rate")},
        **{k: (("n",), _I) for k in ("count", "status", "accepted", "rejected", "rhs_calls",
                                      "stop_status")},
        **{k: (("n",), _F) for k in ("energy_drift", "angmom_drift", "initial_theta_p",
                                      "initial_thetadot_p", "megno", "lyapunov", "max_tilt",
                                      "max_npa_angle", "truncation_force",
                                      "truncation_torque")},
        "initial_states": (("n", 30), _F), "degrees": ((2,), _I),
    }

    theta_p: np.ndarray = unit('deg')
    thetadot_p: np.ndarray = unit(SPIN)
    t: np.ndarray = unit('s')
    r: np.ndarray = unit('m')
    a: np.ndarray = unit('m')
    e: np.ndarray = unit('1')
    count: np.ndarray = unit('crossings')
    energy_drift: np.ndarray = unit(RELATIVE)
    angmom_drift: np.ndarray = unit(RELATIVE)
    status: np.ndarray = unit(STATUS)
    accepted: np.ndarray = unit('steps')
    rejected: np.ndarray = unit('steps')
    rhs_calls: np.ndarray = unit('calls')
    initial_theta_p: np.ndarray = unit('deg')
    initial_thetadot_p: np.ndarray = unit(SPIN)
    systems: list = field(repr=False)
    rtol: float = unit('1', default=1e-12)
    atol: float = unit('1', default=1e-12)
    order: int = unit('potential truncation order', default=4)
    orbits: float = unit(ORBITS, default=0.0)
    seconds: float = unit('s', default=0.0)
    megno: np.ndarray = unit('1', default=None)
    lyapunov: np.ndarray = unit('1/orbit', default=None)
    max_drift: float = unit(RELATIVE, default=float("nan"))
    coordinates: str = unit(COORDINATES, default="inertial")
    apsidal_rate: np.ndarray = unit(SPIN, default=None)
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    initial_states: np.ndarray = unit(STATE_ROW, default=None)
    max_tilt: np.ndarray = unit('deg', default=None)
    max_npa_angle: np.ndarray = unit('deg', default=None)
    indicator_space: str = unit(INDICATOR_SPACE, default="planar")
    perturbations: tuple = unit(PERTURBATIONS, default=())
    stop_status: np.ndarray = unit(STATUS, default=None)
    truncation_force: np.ndarray = unit(RELATIVE, default=None)
    truncation_torque: np.ndarray = unit(TRUNCATION_TORQUE, default=None)
    degrees: np.ndarray = unit(DEGREES, default=None)

    @property
    def member_orbits_per_second(self) -> float:
        return float(self.orbits * len(self.count) / self.seconds) if self.seconds else float("nan")

    def plot(self, ax=None, colors=None, **kwargs):
        """Scatter θ̇_p/n against θ_p (deg) in the paper's convention
        (:func:`ti_spinorbit.output.plotting.plot_section`: ``classes=`` colours by class with a
        legend; many members get a colourbar of the start); returns the axes."""
        return self._figure(ax=ax, colors=colors, **kwargs)


def surface_of_section(system: SystemLike, theta_p=None, thetadot_p=None, orbits=None, *,
                       rtol=None, method=None, integrator=None, run=None, indicators=False,
                       max_drift=None, coordinates="inertial", initial_states=None,
                       perturbations=None, indicator_space="planar") -> SectionResult:
    """Surface of section at pericentre for an ensemble of trajectories.

    Parameters
    ----------
    system : BinarySystem, str or list of them
        One system for all members, or one per member (broadcast with the other inputs); a
        str is a catalogue name (``ti_spinorbit.system.catalog``).
    theta_p : float, array or Quantity
        Initial angle of the secondary's long axis from the line of centres, degrees (a
        plain value that looks like radians, e.g. ``np.pi / 2``, gets a one-line
        ``DegreesExpectedWarning``), or an angle Quantity (``np.pi / 2 * u.rad``).
    thetadot_p : float, array or Quantity
        Initial spin rate of the secondary, units of the mean motion n, in [-100, 100]
        (the bound of the command line's --thetadot too); a Quantity
        dimensionless, in ``ti_spinorbit.units.n``, or an angular rate (rad/s), divided by
        the system's n (one system, or systems of one n).
    orbits : float or Quantity
        Integration time in initial orbital periods 2π/n (each member its own n); orbits
        must lie in (0, 1e7] (``MAX_ORBITS``). A Quantity in ``ti_spinorbit.units.orbit``,
        or a time, divided by the period of the system (one system, or systems of one n).
    rtol : float, optional
        Relative tolerance of the integration, in [1e-16, 1e-2] (default 1e-12); the same
        as ``Integrator(rtol=...)``, which it must not contradict.
    method : {"cash-karp", "dop853", "vern9"}, optional
        Runge-Kutta pair (default "cash-karp", the paper's), as ``Integrator(method=...)``.
    integrator : Integrator, optional
        How the equations are integrated (:class:`ti_spinorbit.Integrator`: atol, model
        "auto"/"planar"/"3d", potential order, escape distance, step-size controller).
    run : Run, optional
        How the run is carried out (:class:`ti_spinorbit.Run`: progress, checkpoint and
        resume, kernel window, Dask client and chunk size); never changes the numbers. With
        a client the members run in chunks on its workers, bit for bit the same result.
    indicators : bool
        Also integrate a shadow trajectory per member (same steps, about 2x the cost) for
        MEGNO and the maximal Lyapunov exponent; the main trajectory is unchanged.
    max_drift : float, optional
        Largest relative energy or angular-momentum drift of a member reported "done"; a
        member above it is "inaccurate" (kept, counted apart). Default:
        ``min(1e-4, 1000 · rtol · orbits)`` (``ti_spinorbit.engine.accuracy``); a number in (0, 1].
    coordinates : {"inertial", "apsidal"}
        Spin coordinate of the starts and of the recorded points (docs/physics.md §6.7).
        "inertial" (default): the secondary's inertial spin rate about the orbit normal.
        "apsidal" (Naidu & Margot 2015): the rate of θ measured from the osculating line of
        apsides, spin rate − ϖ̇; a start θ̇_p = 1.08 is then the paper's 1.08 (the integration
        starts at the inertial rate 1.08 + ϖ̇(0)). Needs e ≥ 1e-3
        (``coordinates.APSIDAL_MIN_ECCENTRICITY``); θ_p is the same in both.
    initial_states : InitialState or sequence of them, optional
        Explicit 3-D starts (:class:`ti_spinorbit.InitialState`, SI units, inertial frame;
        e.g. ``system.tilted_start(θ_p, θ̇_p, roll=...)``) instead of θ_p and θ̇_p (leave
        those None): one member per state, ``system`` one system or one per state,
        coordinates "inertial". The planar model is used only when every state is planar
        (docs/physics.md §6.8). Every result records its members' starts as state rows
        (``initial_states``, SI) and the largest tilt of the secondary's pole from the orbit
        normal (``max_tilt``, degrees, docs/physics.md §6.9).
    indicator_space : {"planar", "full"}
        Direction of the shadow trajectory with ``indicators`` (docs/physics.md §10.4):
        "planar" (default) a fixed planar direction, blind to out-of-plane instability;
        "full" a seeded direction spanning the whole state (attitudes perturbed through a
        small rotation). "full" integrates with the 3-D model (model="auto" picks it;
        model="planar" is refused). Recorded in the result.
    perturbations : list of Tides, YORP, BYORP, optional
        Dissipative and radiative forces in the equations (:mod:`ti_spinorbit.model.perturbations`,
        docs/physics.md §13): tides on either body (constant time lag or constant Q), YORP
        on either body, BYORP on the orbit, each with a ``strength`` factor. The accuracy
        verdict then holds E − W and L − L_ext to the limit (W the work done by the
        perturbations, L_ext the angular momentum they bring in). Recorded in the result.

    Returns
    -------
    SectionResult

    See Also
    --------
    time_series : dense samples of the same integrations
    chaos_map : MEGNO over a grid of starts
    classify_section : resonant, chaotic or quasi-periodic
    ti_spinorbit.output.plotting.plot_section : the options of ``.plot()``

    References
    ----------
    * Naidu, S. P. & Margot, J.-L. 2015, Near-Earth asteroid satellite spins under
      spin-orbit coupling, AJ 149:80.
    * Wisdom, J., Peale, S. J. & Mignard, F. 1984, The chaotic rotation of Hyperion,
      Icarus 58:137.

    Examples
    --------
    Two starts of 1991 VH at pericentre (θ_p = 0°; θ̇_p in units of n), 10 orbits each:

    >>> sos = tso.surface_of_section("1991 VH", theta_p=0.0, thetadot_p=[0.45, 1.70], orbits=10)
    >>> sos.count                                          # section points per member
    array([10,  9])
    >>> sos.status_names
    ['done', 'done']
    >>> sos.units()["thetadot_p"]
    'mean motion n'
    >>> ax = sos.plot()                                    # the paper's conventions
    """
    theta_p, thetadot_p, orbits = plain_starts(system, theta_p, thetadot_p, orbits)
    integrator = _options.integrator(integrator, rtol, method)
    run = _options.run(run)
    started = time.perf_counter()
    members, options = section_inputs(
        system, theta_p, thetadot_p, orbits, integrator=integrator, indicators=indicators,
        max_drift=max_drift, coordinates=coordinates, initial_states=initial_states,
        perturbations=perturbations, indicator_space=indicator_space)
    if run.client is None:
        return section_of(members, orbits, run=run, **options)
    from . import distributed                  # Dask: imported with a client only
    with _progress.reporting(run.progress, "surface_of_section") as report:
        result = distributed.run_members(run, section_of, members, orbits, options,
                                         progress=report)
    return replace(result, seconds=time.perf_counter() - started)


def section_inputs(system, theta_p=None, thetadot_p=None, orbits=None, *,
                   integrator: Integrator, indicators=False, max_drift=None,
                   coordinates="inertial", initial_states=None, perturbations=None,
                   indicator_space="planar"):
    """:func:`surface_of_section`'s inputs checked (all of them, before any work) and turned
    into (member table, the keywords of :func:`section_of`): the one front door of the
    local and the Dask runner alike. ``integrator`` is already checked (its own
    ``__post_init__``) and resolved (its rtol set)."""
    _coords.check_coordinates(coordinates)
    orbits = check_orbits(orbits)
    if max_drift is not None:
        accuracy.drift_limit(integrator.rtol, orbits, max_drift)   # checked before any work
    indicator_space = check_indicator_space(indicator_space)
    members = Members.build("surface_of_section", system, theta_p, thetadot_p, initial_states,
                            orbits, escape_distance=integrator.escape_distance,
                            coordinates=coordinates, order=integrator.order,
                            degrees=integrator.degrees,
                            model=integrator.model, perturbations=perturbations,
                            full_indicators=bool(indicators) and indicator_space == "full")
    _warn_near_circular(members.systems)
    return members, dict(integrator=integrator, indicators=indicators, max_drift=max_drift,
                         indicator_space=indicator_space)


def section_of(members: Members, orbits, *, integrator: Integrator, run: Run,
               indicators=False, max_drift=None, indicator_space="planar") -> SectionResult:
    """The local runner of :func:`surface_of_section`: integrate a member table
    (:class:`ti_spinorbit.engine.members.Members`) in this process, in one ensemble launch, and
    build its SectionResult. The Dask runner (:func:`ti_spinorbit.studies.distributed.run_members`)
    calls it on every chunk of the table. Arguments as for :func:`surface_of_section`."""
    orbits = check_orbits(orbits)       # a float in the result, whatever number came in
    ens = _ensemble(members, integrator)
    with _progress.reporting(run.progress, "surface_of_section") as report:
        out = ens.run(2.0 * np.pi * orbits, window_orbits=run.window_orbits,
                      indicators=indicators, progress=report, indicator_space=indicator_space,
                      **run.checkpoint_keywords())
    par, systems, coordinates = members.par, members.systems, members.coordinates
    cols = _derived_columns(par, out.events, ("alpha", "thetadot", "r", "a", "e"),
                            apsidal=coordinates == "apsidal", order=members.order,
                            multipole=members.multipole())
    thetadot, rate = cols["thetadot"], None
    if coordinates == "apsidal":
        rate, = _coords.mask_small_eccentricity(cols["e"], cols["apsidal_rate"],
                                                what="pericentre passages")
        thetadot = thetadot - rate
    n, a = _per_member(systems, lambda s: (s.mean_motion, s.a)).T
    energy_drift, angmom_drift = accuracy.drifts(out.diag_start, out.diag_end, out.exchange)
    limit = accuracy.drift_limit(ens.rtol, orbits, max_drift)
    status = accuracy.verdict(out.status, energy_drift, angmom_drift, limit)
    t_force, t_torque, status = _truncation(members, cols["closest_state"], status)
    rows, tilt, npa = _state_rows_and_tilt(systems, out.events, members.y0, out.y)
    return SectionResult(
        theta_p=np.mod(np.degrees(cols["alpha"]), 180.0), thetadot_p=thetadot,
        t=cols["t"] / n[:, None], r=cols["r"] * a[:, None], a=cols["a"] * a[:, None], e=cols["e"],
        count=np.array([len(ev) for ev in out.events]), energy_drift=energy_drift,
        angmom_drift=angmom_drift, status=status, accepted=out.counters[:, 0],
        rejected=out.counters[:, 1], rhs_calls=out.counters[:, 2],
        initial_theta_p=members.theta_p, initial_thetadot_p=members.thetadot_p,
        systems=systems, rtol=ens.rtol, atol=ens.atol, order=members.order,
        orbits=orbits, seconds=out.seconds, megno=out.megno, lyapunov=out.lyapunov,
        max_drift=limit, coordinates=coordinates, apsidal_rate=rate, method=ens.method,
        initial_states=rows, max_tilt=tilt, max_npa_angle=npa,
        indicator_space=indicator_space, perturbations=members.perturbations,
        stop_status=np.asarray(out.status, dtype=np.int32).copy(),
        truncation_force=t_force, truncation_torque=t_torque,
        degrees=_degrees(members))


def _degrees(members: Members):
    """The degree caps (primary, secondary) of an order-N table as an int array, None at
    orders up to 4 (the hand-written kernels take every integral to the order)."""
    return None if members.degrees is None else np.array(members.degrees, dtype=np.int64)


def _truncation(members: Members, closest, status):
    """(force, torque, status): the truncation estimates at each member's closest approach
    (the closest record, or the start when nearer) and the status after the truncation
    verdict (``engine.accuracy``, "The truncation of the mutual potential")."""
    start = np.asarray(members.y0, dtype=np.float64)
    r_start = np.linalg.norm(start[:, _S.Y_R:_S.Y_R + 3], axis=1)
    with np.errstate(invalid="ignore"):
        nearer = ~(np.linalg.norm(closest[:, _S.Y_R:_S.Y_R + 3], axis=1) <= r_start)
    states = np.where(nearer[:, None], start, closest)
    force, torque = evaluation.truncation_estimates(member_groups(members.systems), states,
                                                    members.order)
    return force, torque, accuracy.truncation_verdict(status, force, torque)


def _ensemble(members: Members, integrator: Integrator) -> Ensemble:
    """The ensemble of a member table, integrated as ``integrator`` says."""
    return Ensemble(members.par, members.y0, order=members.order, rtol=integrator.rtol,
                    atol=integrator.atol, model=members.model, method=integrator.method,
                    controller=integrator.controller,
                    perturbation_rows=members.perturbation_rows,
                    multipole_rows=members.multipole_rows, degrees=members.degrees)


def _derived_columns(par, records, names, diagnostics=False, apsidal=False, order=4,
                     multipole=None):
    """Observables of per-member record lists, padded with NaN to (N, max count): "t" and
    ``names`` (observables.derive); with ``diagnostics`` also the energy and angular-momentum
    split (scaled, ``engine.evaluation.diagnostics``); with ``apsidal`` also "apsidal_rate" (ϖ̇/n, model of ``order``) and
    "true_anomaly" (rad) of the osculating orbit (docs/physics.md §6.7). All records are
    derived together: one NumPy pass, one kernel launch. Above order 4 ``multipole`` holds
    the members' order-N rows (``Members.multipole``). Also "closest_state" (N, 30): each
    member's record nearest the primary (NaN for a member without records)."""

    counts = np.array([len(r) for r in records])
    width = max(int(counts.max(initial=0)), 1)
    member = np.repeat(np.arange(len(records)), counts)
    slot = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    flat = np.concatenate([np.zeros((0, RECORD_WIDTH))] + list(records))

    def padded(values):
        out = np.full((len(records), width) + values.shape[1:], np.nan)
        out[member, slot] = values
        return out

    d = derive(par[member], flat[:, 1:])
    cols = {"t": padded(flat[:, 0]), **{k: padded(d[k]) for k in names}}
    if apsidal:
        states = flat[:, 1:]
        cols["apsidal_rate"] = padded(evaluation.apsidal_rates(
            par[member], states, order, evaluation.has_odd(par),
            None if multipole is None else multipole.take(member)))
        cols["true_anomaly"] = padded(_coords.true_anomaly(states[:, _S.Y_R:_S.Y_R + 3],
                                                           states[:, _S.Y_V:_S.Y_V + 3]))
    # each member's closest recorded approach (NaN rows without records), for the truncation
    r = np.linalg.norm(flat[:, 1 + _S.Y_R:1 + _S.Y_R + 3], axis=1)
    first = np.lexsort((r, member))[np.cumsum(counts)[counts > 0] - counts[counts > 0]]
    cols["closest_state"] = np.full((len(records), _S.NSTATE), np.nan)
    cols["closest_state"][member[first]] = flat[first, 1:]
    if diagnostics:
        diag = evaluation.diagnostics(par, flat[:, 1:], member, order, multipole=multipole)
        for c, k in enumerate(("energy_orbit", "energy_primary", "energy_secondary")):
            cols[k] = padded(diag[:, c])
        for c, k in enumerate(("angmom_orbit", "angmom_primary", "angmom_secondary")):
            cols[k] = padded(diag[:, 3 + 3 * c:6 + 3 * c])
    return cols


def _state_property(name, shape, doc):
    """A read-only view of one part of a time series' ``states`` (docs/physics.md §6.8)."""
    return property(lambda self: self._state(name, shape), doc=doc)


@dataclass(repr=False, eq=False)
class Conservation(_display.Readable):
    """Conservation check of one member of a time series
    (:meth:`ti_spinorbit.TimeSeriesResult.conservation`):
    prints as a few lines, draws with :meth:`Conservation.plot`, and unpacks as the ``(numbers, series)``
    pair it replaces (``numbers, (t, de, dl, parts) = ts.conservation(0)``).

    ``energy_drift``, ``angmom_drift`` the largest relative drift of the total energy
    (ΔE/|E0|) and of the total angular-momentum vector (|ΔL|/|L0|) over the samples;
    ``exchange_orbit``, ``exchange_primary``, ``exchange_secondary`` the largest change of
    each energy part relative to |E0|; ``samples`` the samples used; ``t`` their times (s),
    ``de``, ``dl`` the drifts and ``parts`` {part: ΔE_part/|E0|} per sample; ``numbers`` and
    ``series`` the dict and tuple of before. Printed, an exchange below 1e-12 of the largest
    one is round-off and shows as 0 (``ti_spinorbit.display.negligible``); the numbers
    themselves are kept as computed."""

    member: int
    energy_drift: float
    angmom_drift: float
    exchange_orbit: float
    exchange_primary: float
    exchange_secondary: float
    samples: int
    t: np.ndarray
    de: np.ndarray
    dl: np.ndarray
    parts: dict
    orbital_period: float = float("nan")
    result: "TimeSeriesResult" = None

    @property
    def numbers(self) -> dict:
        """The numbers as a dict (what the CLI writes to its data file's metadata)."""
        return {"energy_drift": self.energy_drift, "angmom_drift": self.angmom_drift,
                "exchange_orbit": self.exchange_orbit, "exchange_primary": self.exchange_primary,
                "exchange_secondary": self.exchange_secondary, "samples": self.samples}

    @property
    def series(self) -> tuple:
        """(t s, ΔE/|E0|, |ΔL|/|L0|, {part: ΔE_part/|E0|}) per sample."""
        return self.t, self.de, self.dl, self.parts

    def __iter__(self):        # numbers, series = ts.conservation(member)
        return iter((self.numbers, self.series))

    def __len__(self):
        return 2

    def __getitem__(self, key):
        """``[0]`` the numbers, ``[1]`` the series (the pair of before); a name, one number."""
        if isinstance(key, str):
            return self.numbers[key]
        return (self.numbers, self.series)[key]

    def plot(self, title=None):
        """The conservation figure of this member
        (:func:`ti_spinorbit.output.plotting.plot_conservation`). Returns the top Axes."""
        if self.result is None:
            raise ValueError("this conservation check has no time series to plot")
        return self.result.plot_conservation(member=self.member, title=title)


@dataclass(repr=False)
class TimeSeriesResult(Result, _display.Readable, kind="time_series"):
    """Densely sampled trajectories (padded with NaN to (N, max samples)).

    Attributes
    ----------
    t : ndarray, shape (N, max samples)
        Sample times, s; NaN-padded, as every per-sample array.
    alpha : ndarray, shape (N, max samples)
        The secondary's long axis from the line of centres, deg in (−180, 180].
    theta : ndarray, shape (N, max samples)
        The long axis from the initial pericentre direction (inertial, orbit plane), deg; with
        ``coordinates="apsidal"`` from the osculating line of apsides (α + f).
    thetadot : ndarray, shape (N, max samples)
        Spin rate about the orbit normal, units of n; apsidal: spin rate − ϖ̇ (NaN where the
        osculating e is too small), docs/physics.md §6.7.
    r : ndarray, shape (N, max samples)
        Separation, m.
    energy, energy_orbit, energy_primary, energy_secondary : ndarray, shape (N, max samples)
        The total energy and its split: the orbit (|P|²/2m + V) and the two spins, J.
    angmom_orbit, angmom_primary, angmom_secondary : ndarray, shape (N, max samples, 3)
        Inertial angular momenta, kg m² s⁻¹.
    work, external_angmom : ndarray
        The work the perturbations did (J) and the angular momentum they brought in
        (kg m² s⁻¹), per sample.
    states : ndarray or None
        With ``states=True``: the SI state rows at every sample (docs/physics.md §6.8).
    attitude_class, max_tilt, max_npa_angle : ndarray, shape (N,)
        The secondary's attitude class code (with ``attitude_class_names``), the largest pole
        tilt and non-principal-axis angle reached, deg.
    initial_theta_p, initial_thetadot_p : ndarray, shape (N,)
        Each member's start, deg and units of n.
    energy_drift, angmom_drift : ndarray, shape (N,)
        The largest relative drift of the total energy and angular-momentum vector over every
        sample and the end of the run, held against ``max_drift`` for the ``status`` verdict.
    status, stop_status : ndarray of int, shape (N,)
        Status codes (:class:`~ti_spinorbit.Status`, with ``status_names``) and the
        integrator's codes before the accuracy verdict (why each member stopped).
    truncation_force, truncation_torque : ndarray, shape (N,)
        The size of the mutual potential's next orders at each member's closest sampled
        approach ("truncated" above the truncation limits; NaN where not estimated;
        docs/physics.md §3.9).
    coordinates : str
        "inertial" or "apsidal".
    systems, initial_states : list, ndarray
        Each member's system and SI start row.
    rtol, method, order, degrees, orbits, seconds, max_drift, perturbations
        The run's tolerance, Runge-Kutta pair, truncation order and degree caps, length
        (orbital periods), wall time (s), drift limit and perturbations.

    Examples
    --------
    >>> ts = tso.time_series("1991 VH", 0.0, [0.45], orbits=2, samples_per_orbit=16)
    >>> ts.thetadot.shape, ts.status_names
    ((1, 32), ['done'])
    >>> check = ts.conservation(0)                         # drifts of one member
    >>> bool(check.energy_drift < 1e-9)
    True
    """

    # what a loaded file's arrays must look like (Result.SHAPES; n members, s samples)
    SHAPES = {
        **{k: (("n", "s"), _F) for k in ("t", "alpha", "theta", "thetadot", "r", "energy",
                                          "energy_orbit", "energy_primary", "energy_secondary",
                                          "work")},
        **{k: (("n", "s", 3), _F) for k in ("angmom_orbit", "angmom_primary",
                                             "angmom_secondary", "external_angmom")},
        **{k: (("n",), _I) for k in ("status", "attitude_class", "stop_status")},
        **{k: (("n",), _F) for k in ("initial_theta_p", "initial_thetadot_p", "energy_drift",
                                      "angmom_drift", "max_tilt", "max_npa_angle",
                                      "truncation_force", "truncation_torque")},
        "initial_states": (("n", 30), _F), "states": (("n", "s", 30), _F),
        "degrees": ((2,), _I),
    }

    t: np.ndarray = unit('s')
    alpha: np.ndarray = unit('deg')
    theta: np.ndarray = unit('deg')
    thetadot: np.ndarray = unit(SPIN)
    r: np.ndarray = unit('m')
    energy: np.ndarray = unit('J')
    energy_orbit: np.ndarray = unit('J')
    energy_primary: np.ndarray = unit('J')
    energy_secondary: np.ndarray = unit('J')
    angmom_orbit: np.ndarray = unit('kg m^2 s^-1')
    angmom_primary: np.ndarray = unit('kg m^2 s^-1')
    angmom_secondary: np.ndarray = unit('kg m^2 s^-1')
    status: np.ndarray = unit(STATUS)
    systems: list = field(repr=False)
    initial_theta_p: np.ndarray = unit('deg', default=None)
    initial_thetadot_p: np.ndarray = unit(SPIN, default=None)
    energy_drift: np.ndarray = unit(RELATIVE, default=None)
    angmom_drift: np.ndarray = unit(RELATIVE, default=None)
    max_drift: float = unit(RELATIVE, default=float("nan"))
    rtol: float = unit('1', default=float("nan"))
    orbits: float = unit(ORBITS, default=float("nan"))
    coordinates: str = unit(COORDINATES, default="inertial")
    seconds: float = unit('s', default=0.0)
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    initial_states: np.ndarray = unit(STATE_ROW, default=None)
    max_tilt: np.ndarray = unit('deg', default=None)
    max_npa_angle: np.ndarray = unit('deg', default=None)
    attitude_class: np.ndarray = unit(ATTITUDE_CLASS, default=None)
    states: np.ndarray = unit(STATE_ROW, default=None)
    perturbations: tuple = unit(PERTURBATIONS, default=())
    stop_status: np.ndarray = unit(STATUS, default=None)
    work: np.ndarray = unit('J', default=None)
    external_angmom: np.ndarray = unit('kg m^2 s^-1', default=None)
    order: int = unit('potential truncation order', default=4)
    truncation_force: np.ndarray = unit(RELATIVE, default=None)
    truncation_torque: np.ndarray = unit(TRUNCATION_TORQUE, default=None)
    degrees: np.ndarray = unit(DEGREES, default=None)

    def _state(self, name, shape):
        if self.states is None:
            raise ValueError(f"{name}: this time series kept no states; run time_series(..., "
                             "states=True)")
        part = self.states[..., ROW_SLICES[name]]
        return part.reshape(part.shape[:-1] + shape)

    R = _state_property("R", (3,), "Secondary's position relative to the primary, inertial "
                        "frame, m (N, samples, 3).")
    V = _state_property("V", (3,), "Secondary's velocity relative to the primary, inertial "
                        "frame, m/s (N, samples, 3).")
    primary_attitude = _state_property("primary_attitude", (3, 3),
                                       "Primary's body -> inertial rotation (N, samples, 3, 3).")
    secondary_attitude = _state_property("secondary_attitude", (3, 3), "Secondary's body -> "
                                         "inertial rotation (N, samples, 3, 3).")
    primary_omega = _state_property("primary_omega", (3,), "Primary's angular velocity in its "
                                    "body frame, rad/s (N, samples, 3).")
    secondary_omega = _state_property("secondary_omega", (3,), "Secondary's angular velocity "
                                      "in its body frame, rad/s (N, samples, 3).")

    @property
    def euler_angles(self):
        """Roll, pitch, yaw of the secondary in the orbit frame, degrees (N, samples, 3):
        :func:`ti_spinorbit.model.attitude.euler_angles_of_rows`."""
        self._state("R", (3,))                                    # the message if none kept
        return euler_angles_of_rows(self.states)

    @property
    def pole_tilt(self):
        """Angle between the secondary's short axis and the orbit normal, degrees (N, samples):
        cos tilt = cos roll cos pitch (docs/physics.md §6.9)."""
        roll, pitch = np.radians(self.euler_angles[..., 0]), np.radians(self.euler_angles[..., 1])
        return np.degrees(np.arccos(np.clip(np.cos(roll) * np.cos(pitch), -1.0, 1.0)))

    @property
    def attitude_class_names(self):
        """``attitude_class`` as text ("planar libration", ..., "" where not classified)."""
        return [CLASSES[c] if c >= 0 else "" for c in np.asarray(self.attitude_class).tolist()]

    def plot(self, ax=None, quantity="thetadot", members=None, title=None):
        """Each member's θ̇/n (or ``quantity`` "alpha", "theta", "r") against time:
        :func:`ti_spinorbit.output.plotting.plot_time_series`. Returns the Axes."""
        return self._figure(ax=ax, quantity=quantity, members=members, title=title)

    def plot_conservation(self, member=0, title=None):
        """Energy and angular-momentum drift and the orbit/spin energy exchange of one member
        against time (:func:`ti_spinorbit.output.plotting.plot_conservation`). Returns the top Axes."""
        return self._figure("conservation", member=member, title=title)

    def conservation(self, member=0) -> Conservation:
        """Conservation numbers of one member: the largest relative drift of the total energy
        and of the total angular-momentum vector over its samples, and the largest change of
        each energy part relative to |E0| (the orbit/spin exchange). With perturbations the
        totals are E − W and L − L_ext (``work``, ``external_angmom``; docs/physics.md §13.4).

        Returns a :class:`~ti_spinorbit.studies.section.Conservation`: a few lines when
        printed, ``.plot()`` draws :meth:`~ti_spinorbit.TimeSeriesResult.plot_conservation`;
        the numbers are attributes (``energy_drift``,
        ``angmom_drift``, ``exchange_orbit``, ``exchange_primary``, ``exchange_secondary``,
        ``samples``) and it unpacks as ``numbers, (t, de, dl, parts)``: a dict of those and
        (t s, ΔE/|E0|, |ΔL|/|L0|, {part: ΔE_part/|E0|}) per sample."""
        member = require_count("member", member, 0, len(self.t) - 1)
        ok = np.isfinite(self.t[member])
        t = self.t[member][ok]
        energy = self.energy[member][ok]
        angmom = sum(getattr(self, f"angmom_{k}")[member][ok] for k in ("orbit", "primary", "secondary"))
        if getattr(self, "work", None) is not None:   # perturbed: E − W, L − L_ext conserved (§13.4)
            energy = energy - self.work[member][ok]
            angmom = angmom - self.external_angmom[member][ok]
        e0 = energy[0]
        l0 = np.linalg.norm(angmom[0])
        de = (energy - e0) / abs(e0)
        dl = np.linalg.norm(angmom - angmom[0], axis=1) / l0
        parts = {k: (getattr(self, f"energy_{k}")[member][ok] - getattr(self, f"energy_{k}")[member][ok][0])
                 / abs(e0) for k in ("orbit", "primary", "secondary")}
        systems = getattr(self, "systems", None) or ()
        period = float(systems[member].orbital_period) if len(systems) > member else float("nan")
        return Conservation(member=member, energy_drift=float(np.max(np.abs(de))),
                            angmom_drift=float(np.max(dl)),
                            **{f"exchange_{k}": float(np.max(np.abs(v))) for k, v in parts.items()},
                            samples=int(len(t)), t=t, de=de, dl=dl, parts=parts,
                            orbital_period=period, result=self)


def time_series(system: SystemLike, theta_p=None, thetadot_p=None, orbits=None,
                samples_per_orbit=64, *, rtol=None, method=None, integrator=None, run=None,
                max_drift=None, coordinates="inertial", initial_states=None, states=False,
                perturbations=None) -> TimeSeriesResult:
    """Dense time series of spin rate, α, r and energy (same inputs as surface_of_section).

    Steps are shortened to land exactly on the sample times (every 1/samples_per_orbit of an
    initial orbital period), so samples carry the integrator's accuracy. orbits must lie in
    (0, 1e7] (``MAX_ORBITS``), as for surface_of_section. The drifts are the largest over
    every sample (and the end); ``max_drift`` and ``coordinates`` as for surface_of_section
    (apsidal: θ from the osculating line of apsides and θ̇ its rate, the starts' θ̇_p too);
    ``rtol``, ``method``, ``integrator`` and ``run`` (:class:`ti_spinorbit.Integrator`,
    :class:`ti_spinorbit.Run`; a time series runs in this process, never on a Dask client) and
    ``initial_states`` explicit 3-D starts, as for surface_of_section.

    Every member is classified by its attitude (``attitude_class``: planar libration, 3-D
    libration, circulation, tumbling; docs/physics.md §6.9) and carries its largest pole
    tilt ``max_tilt``. With ``states=True`` the result also keeps the full physical state at
    every sample (``states``, SI state rows of docs/physics.md §6.8; read through ``R``,
    ``V``, ``primary_attitude``, ``secondary_attitude``, ``primary_omega``,
    ``secondary_omega`` and the Euler angles ``roll``, ``pitch``, ``yaw``): 30 more numbers
    per sample, off by default to keep long series small.

    ``perturbations`` (tides, YORP, BYORP; as for surface_of_section) also fill ``work``
    (the energy the perturbations put in since the start, J, negative when they dissipate)
    and ``external_angmom`` (the angular momentum they brought in, inertial, kg m² s⁻¹) at
    every sample; the drifts are those of E − W and L − L_ext.

    ``theta_p``, ``thetadot_p`` and ``orbits`` are floats (arrays) or Quantities, as for
    surface_of_section.

    See Also
    --------
    surface_of_section : the same integrations recorded at pericentre
    ti_spinorbit.output.plotting.plot_time_series : the options of ``.plot()``

    Examples
    --------
    >>> ts = tso.time_series("1991 VH", 0.0, [0.45, 1.70], orbits=2, samples_per_orbit=16)
    >>> ts.t.shape                                         # (members, samples), s
    (2, 32)
    >>> ts.units()["thetadot"], ts.units()["alpha"]
    ('mean motion n', 'deg')
    >>> ax = ts.plot()                                     # θ̇/n against time in orbits
    """
    theta_p, thetadot_p, orbits = plain_starts(system, theta_p, thetadot_p, orbits)
    integrator = _options.integrator(integrator, rtol, method)
    run = _options.run(run)
    if run.client is not None:
        raise ValueError("time_series runs in this process: run=Run(client=...) is for "
                         "surface_of_section and the maps and scans")
    _coords.check_coordinates(coordinates)
    samples_per_orbit = require_count("samples_per_orbit", samples_per_orbit, 1, 100000)
    orbits = check_orbits(orbits)
    limit = accuracy.drift_limit(integrator.rtol, orbits, max_drift) \
        if max_drift is not None else None
    states = require_bool("states", states)
    order = integrator.order
    table = Members.build("time_series", system, theta_p, thetadot_p, initial_states, orbits,
                          escape_distance=integrator.escape_distance, coordinates=coordinates,
                          order=order, degrees=integrator.degrees, model=integrator.model,
                          perturbations=perturbations, samples_per_orbit=samples_per_orbit,
                          states=states)
    members, par, y0 = table.systems, table.par, table.y0
    tp, td, perturbations = table.theta_p, table.thetadot_p, table.perturbations
    ens = _ensemble(table, integrator)
    with _progress.reporting(run.progress, "time_series") as report:
        out = ens.run(2.0 * np.pi * orbits, window_orbits=run.window_orbits,
                      sample_dt=2.0 * np.pi / samples_per_orbit, progress=report,
                      **run.checkpoint_keywords())
    apsidal = coordinates == "apsidal"
    cols = _derived_columns(par, out.samples, ("alpha", "theta", "thetadot", "r", "e"),
                            diagnostics=True, apsidal=apsidal, order=order,
                            multipole=table.multipole())
    if apsidal:   # θ from the osculating apsidal line: α + f, wrapped to (−π, π]
        theta = np.angle(np.exp(1j * (cols["alpha"] + cols["true_anomaly"])))
        cols["theta"], cols["thetadot"] = _coords.mask_small_eccentricity(
            cols["e"], theta, cols["thetadot"] - cols["apsidal_rate"], what="samples")
    n, a, e_unit = _per_member(
        members, lambda s: (s.mean_motion, s.a, s.total_mass * (s.a * s.mean_motion) ** 2)).T
    e_unit = e_unit[:, None]
    l_unit = (e_unit / n[:, None])[..., None]
    energies = {k: cols[k] * e_unit for k in ("energy_orbit", "energy_primary", "energy_secondary")}
    exchange = _padded_exchange(out, cols["t"].shape)
    energy_drift, angmom_drift = _sampled_drifts(cols, out, exchange)
    limit = accuracy.drift_limit(ens.rtol, orbits) if limit is None else limit
    status = accuracy.verdict(out.status, energy_drift, angmom_drift, limit)
    t_force, t_torque, status = _truncation(table, cols["closest_state"], status)
    rows, tilt, npa = _state_rows_and_tilt(members, out.samples, y0, out.y)
    return TimeSeriesResult(
        t=cols["t"] / n[:, None], alpha=np.degrees(cols["alpha"]), theta=np.degrees(cols["theta"]),
        thetadot=cols["thetadot"], r=cols["r"] * a[:, None], energy=sum(energies.values()),
        **energies, **{k: cols[k] * l_unit for k in ("angmom_orbit", "angmom_primary", "angmom_secondary")},
        status=status, systems=members, initial_theta_p=tp, initial_thetadot_p=td,
        energy_drift=energy_drift, angmom_drift=angmom_drift, max_drift=limit, rtol=ens.rtol,
        orbits=orbits, coordinates=coordinates, seconds=out.seconds, method=ens.method,
        initial_states=rows, max_tilt=tilt, max_npa_angle=npa,
        attitude_class=_attitude_classes(members, out.samples, tilt, npa),
        states=_sample_rows(members, out.samples, cols["t"].shape[1]) if states else None,
        perturbations=perturbations, stop_status=np.asarray(out.status, dtype=np.int32).copy(),
        work=None if exchange is None else exchange[..., 0] * e_unit,
        external_angmom=None if exchange is None else exchange[..., 1:4] * l_unit,
        truncation_force=t_force, truncation_torque=t_torque, order=table.order,
        degrees=_degrees(table))


def _padded_exchange(out: RunOutput, shape):
    """The accumulators (W, L_ext) at every sample, (N, samples, 4) scaled, NaN-padded like
    the sample columns; None without perturbations."""
    if out.sample_exchange is None:
        return None
    return _stack_padded(out.sample_exchange, shape[1], 4)


def _stack_padded(arrays, width, columns):
    """Per-member (count, columns) arrays stacked into (N, width, columns), NaN-padded."""
    x = np.full((len(arrays), width, columns), np.nan)
    for k, a in enumerate(arrays):
        x[k, :len(a)] = a
    return x


def _attitude_classes(members, samples, max_tilt, max_npa):
    """Attitude class code per member (``attitude.CLASSES``; −1 with fewer than 2 samples),
    from its samples, made to agree with the reported ``max_tilt`` and ``max_npa_angle``,
    which also hold the start and the end state: a member whose spin leaves its short axis
    (or whose pole tilts) only after its last sample, as an escaping one may, is tumbling
    (or librating in 3-D), not what its samples alone would say."""

    out = np.full(len(members), -1, dtype=np.int8)
    for k, (m, rec) in enumerate(zip(members, samples)):
        if np.count_nonzero(np.all(np.isfinite(rec[:, 1:]), axis=1)) >= 2:
            out[k] = classify([rec[:, 1:]], m)[0]
    known = out >= 0
    out[known & (np.asarray(max_npa) > _attitude.NPA_ANGLE)] = _attitude.TUMBLING
    out[(out == _attitude.PLANAR_LIBRATION) & (np.asarray(max_tilt) > _attitude.TILT_ANGLE)] = \
        _attitude.LIBRATION_3D
    return out


def _sample_rows(members, samples, width):
    """State rows (SI, docs/physics.md §6.8) at every sample, (N, width, 30), NaN-padded."""

    return _stack_padded([physical_rows(m, rec[:, 1:]) if len(rec) else np.zeros((0, 30))
                          for m, rec in zip(members, samples)], width, 30)


def _sampled_drifts(cols, out: RunOutput, exchange=None):
    """Largest relative energy and angular-momentum drift per member over its samples and the
    end of the run (scaled units, ``_derived_columns`` with an ensemble). A non-finite
    diagnostic in any recorded sample makes the member's drift NaN, so it can never pass.
    With perturbations (``exchange``, :func:`_padded_exchange`) the drifts are those of
    E − W and L − L_ext (docs/physics.md §13.4)."""
    end_energy, end_angmom = accuracy.drifts(out.diag_start, out.diag_end, out.exchange)
    e0, l0 = accuracy.totals(out.diag_start)
    e0, l0 = e0[:, None], l0[:, None]
    recorded = np.isfinite(cols["t"])
    energy = cols["energy_orbit"] + cols["energy_primary"] + cols["energy_secondary"]
    angmom = cols["angmom_orbit"] + cols["angmom_primary"] + cols["angmom_secondary"]
    if exchange is not None:
        energy, angmom = energy - exchange[..., 0], angmom - exchange[..., 1:4]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        de = np.abs(energy - e0) / np.abs(e0)
        dl = np.linalg.norm(angmom - l0, axis=-1) / np.linalg.norm(l0, axis=-1)
    bad = np.any(recorded & ~(np.isfinite(de) & np.isfinite(dl)), axis=1)
    de = np.where(recorded, de, 0.0).max(axis=1, initial=0.0)
    dl = np.where(recorded, dl, 0.0).max(axis=1, initial=0.0)
    energy_drift = np.where(bad, np.nan, np.fmax(de, end_energy))
    angmom_drift = np.where(bad, np.nan, np.fmax(dl, end_angmom))
    # fmax ignores a NaN end diagnostic: keep it
    energy_drift[~np.isfinite(end_energy)] = np.nan
    angmom_drift[~np.isfinite(end_angmom)] = np.nan
    return energy_drift, angmom_drift
