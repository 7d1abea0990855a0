"""Numerical overlap of the 1:1 and 3:2 spin-orbit resonances (docs/physics.md §9.2; Naidu & Margot
2015 §4, the overlap thresholds of their §6).

Decoupled theory (Wisdom, Peale & Mignard 1984; Chirikov): the synchronous and 3:2 islands
touch when ω0 exceeds ω0^RO = 1/(2 + sqrt(14 e)). Numerically, the two resonances overlap
when no invariant curve separates them, i.e. a single chaotic trajectory travels from the 1:1
zone to the 3:2 zone. :func:`overlap_threshold` scans the elongation a/b (steps of 0.01 by
default) and finds the first elongation where that happens.

Decision rule (geometric, from the pericentre section; documented choices):

1. *Island centres.* A column of starts at θ_p = 0 spanning both resonances. Starts whose
   trace librates (horizontal extent max |θ_p| below ``libration_limit``, θ_p taken in
   (−90°, 90°]) belong to an island. Among the librating starts closest to each nominal
   rate, the one with the smallest extent is that island's centre c_1 (nearest 1) or c_3/2
   (nearest 1.5). Coupling shifts island centres (relaxed-mode libration); at the small
   elongations where overlap sets in the shift is small, but the rule does not assume it.
   If no 3:2 island survives, c_3/2 = c_1 + 0.5.
2. *Connection.* A column of starts at θ_p = 90° (where both resonances have their unstable
   point at pericentre) spanning c_1 ... c_3/2. The resonances overlap when at least one of
   these trajectories reaches below c_1 **and** above c_3/2 within ``orbits`` orbits: it has
   crossed both islands' levels, which no trajectory can do while an invariant curve
   separates them.

Finite integration time can only miss a slow connection, never invent one, so the measured
threshold is an upper bound that converges as ``orbits`` grows. The scan therefore doubles the
length (``orbits``, 2·orbits, ... up to ``max_orbits``), integrating again only the
elongations still "separate", until two successive lengths agree at every elongation and no
elongation is "separate" where the MEGNO criterion (3.) already connects; otherwise it says
"not converged by N orbits" and ``first_overlap`` is an upper bound.

3. *MEGNO criterion* (:func:`megno_connects`, reported beside the geometric decision): the
   θ̇_p ranges of the separatrix-column trajectories with ⟨Y⟩ > 4, joined where they
   overlap, span c_1 ... c_3/2 — one chaotic layer connects the islands, though no single
   trajectory has crossed it yet (docs/physics.md §9.2).
 With ``indicators=True``
(default) every trajectory also carries MEGNO ⟨Y⟩ and its Lyapunov exponent: the evidence
records them for the connecting trajectory, which should be clearly chaotic (⟨Y⟩ ≫ 2).

All elongations of a scan run in one ensemble launch (each member carries its own system).
"""

from dataclasses import dataclass, field, replace
from typing import Callable, List, Optional, Union

import numpy as np

from .. import display as _display
from .._validate import _as_floats, require_count, require_range, require_scalar, show
from ..system import catalog
from ..system.systems import BinarySystem
from ..model import analytic
from ..model.coordinates import check_coordinates
from ..model.perturbations import UNIT as PERTURBATIONS, check_perturbations
from ..engine import accuracy, compiling, resources
from ..engine import options as _options
from ..engine import progress as _progress
from ..engine.checkpoint import Launches
from ..engine.convergence import run_lengths
from ..engine.results import COORDINATES, METHOD, ORBITS, RELATIVE, SPIN, Result, record, unit
from ..engine.results import FLOAT as _F, INTEGER as _I, BOOL as _B
from .chaosmap import MAP_RTOL
from .classify import MEGNO_CHAOTIC
from .libration import section_extent
from .section import check_orbits, surface_of_section
from ..units import to_plain

#: Horizontal extent (deg) below which a θ_p = 0 trace counts as librating.
LIBRATION_LIMIT_DEG = 80.0


@record
@dataclass(repr=False)
class OverlapDecision(_display.ReadableLine):
    """Evidence for one elongation: island centres (units of n), and the trajectory that
    connects them (index into the separatrix column, its start and its θ̇_p range) or None.
    Printed, one line (:mod:`ti_spinorbit.display`).
    ``inaccurate``: starts at this elongation whose conservation drift exceeded the limit
    (excluded from the decision unless the scan includes them); ``max_energy_drift`` the
    largest relative energy drift among its starts."""

    elongation: float = unit('1 (a/b)')
    omega0: float = unit(SPIN)
    overlap: bool
    centre_1: float = unit(SPIN)
    centre_3_2: float = unit(SPIN)
    centre_3_2_found: bool = unit('bool')
    connecting_start: Optional[float] = unit(SPIN)
    connecting_range: Optional[tuple] = unit(SPIN)
    widest_range: tuple = unit(SPIN)
    connecting_megno: float = unit('1', default=float("nan"))
    connecting_lyapunov: float = unit('1/orbit', default=float("nan"))
    separatrix_chaotic_fraction: float = unit('1', default=float("nan"))
    inaccurate: int = unit('members', default=0)
    max_energy_drift: float = unit(RELATIVE, default=float("nan"))
    #: the MEGNO connection criterion (see :func:`megno_connects`): None without indicators
    megno_overlap: Optional[bool] = unit('bool', default=None)
    #: orbits of the run this decision comes from
    orbits: float = unit(ORBITS, default=float("nan"))
    #: largest finite ⟨Y⟩ among this elongation's trajectories in that run (NaN: none, or
    #: no indicators; None in files written before it was kept)
    max_megno: Optional[float] = unit('1', default=None)


@dataclass(repr=False)
class OverlapScan(Result, _display.Readable, kind="overlap_scan"):
    """Result of :func:`overlap_threshold`.

    Attributes
    ----------
    first_overlap : float or None
        The first elongation a/b where the 1:1 and 3:2 resonances overlap (None if none in the
        scan).
    elongation_ro, omega0_ro : float
        The analytic a/b at ω0^RO(e) and ω0^RO = 1/(2 + √(14e)) itself.
    elongations, overlaps : ndarray
        The scan and its verdict per elongation.
    decisions : list of OverlapDecision
        The evidence per elongation.
    converged, converged_orbits, message : bool, float, str
        Whether the decisions stopped changing as the run length doubled, at which length, and
        the verdict in words; ``lengths``, ``overlaps_by_length``,
        ``megno_overlaps_by_length`` and ``megno_first_overlap`` the evidence against length.
    max_drift, n_inaccurate : float, int
        The accuracy limit every trajectory was held against and the trajectories above it,
        left out of the decisions unless ``include_inaccurate``.
    coordinates : str
        The spin coordinate of the starts, centres and ranges ("inertial" or "apsidal",
        docs/physics.md §6.7).
    name, eccentricity, orbits, max_orbits, member_orbits, rtol, method, seconds, sections, perturbations
        The system, its e, the run lengths (orbital periods), tolerance, Runge-Kutta pair,
        wall time (s), the sections of the last length, and the perturbations.
    """

    # what a loaded file's arrays must look like (Result.SHAPES; m elongations, k lengths)
    SHAPES = {
        "elongations": (("m",), _F), "overlaps": (("m",), _B), "lengths": (("k",), _F),
        "overlaps_by_length": (("k", "m"), _B), "megno_overlaps_by_length": (("k", "m"), _I)}

    name: str
    eccentricity: float = unit('1')
    elongations: np.ndarray = unit('1 (a/b)')
    overlaps: np.ndarray = unit('bool')
    decisions: List[OverlapDecision] = field(metadata={"records": OverlapDecision})
    first_overlap: Optional[float] = unit('1 (a/b)')
    omega0_ro: float = unit(SPIN)
    elongation_ro: float = unit('1 (a/b)')
    orbits: float = unit(ORBITS)
    seconds: float = unit('s', default=0.0)
    sections: object = field(default=None, repr=False)
    max_drift: float = unit(RELATIVE, default=float("nan"))
    n_inaccurate: int = unit('members', default=0)
    include_inaccurate: bool = unit('bool', default=False)
    coordinates: str = unit(COORDINATES, default="inertial")
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    # convergence in integration length (doubling; see overlap_threshold): the lengths run
    # (orbits), the geometric and MEGNO decisions at each (rows: lengths, columns:
    # elongations), the verdict, and the cost in member-orbits
    lengths: np.ndarray = unit(ORBITS, default=None)
    overlaps_by_length: np.ndarray = unit('bool (lengths x elongations)', default=None)
    megno_overlaps_by_length: np.ndarray = unit('1 = connects, 0 = not, -1 = no indicators', default=None)
    converged: bool = unit('bool', default=False)
    converged_orbits: float = unit(ORBITS, default=float("nan"))
    max_orbits: float = unit(ORBITS, default=float("nan"))
    message: str = unit('text', default="")
    megno_first_overlap: Optional[float] = unit('1 (a/b)', default=None)
    member_orbits: float = unit('member x orbital periods', default=float("nan"))
    #: integrator tolerance of every trajectory (NaN in files written before it was stored)
    rtol: float = unit('1', default=float("nan"))
    #: tides / YORP / BYORP in the equations of every trajectory (docs/physics.md §13)
    perturbations: tuple = unit(PERTURBATIONS, default=())

    def __post_init__(self):
        if not np.isfinite(self.rtol) and self.sections is not None:
            self.rtol = float(self.sections.rtol)

    @property
    def status(self):
        """Status codes of the trajectories of the first run (``sections``; empty when it
        was not saved)."""
        return np.zeros(0, np.int32) if self.sections is None else self.sections.status

    @property
    def upper_bound(self) -> bool:
        """True when ``first_overlap`` is only an upper bound (not converged in length)."""
        return not self.converged

    def section_block(self, k):
        """(SectionResult, member slice) of elongation k in the first run (``sections``,
        every elongation; longer runs integrate only the elongations still separate and are
        not kept: each decision keeps what it needs, ``OverlapDecision.max_megno``)."""
        per = self.sections.count.size // len(self.elongations)
        return self.sections, slice(k * per, (k + 1) * per)

    def evidence(self):
        """Lines: decisions per elongation against integration length, and the verdict."""
        if self.lengths is None or self.overlaps_by_length is None:
            return [f"{self.name}: one length ({self.orbits:g} orbits), convergence not checked"]
        rows = [f"{'orbits':>8}  " + " ".join(f"{q:5.2f}" for q in self.elongations)
                + "  first overlap (geometric / MEGNO)"]
        for L, geo, meg in zip(self.lengths, self.overlaps_by_length,
                               self.megno_overlaps_by_length):
            first = next((f"{q:.2f}" for q, o in zip(self.elongations, geo) if o), "none")
            mfirst = next((f"{q:.2f}" for q, o in zip(self.elongations, meg) if o == 1), "none")
            cells = " ".join(f"{'O' if g else '.'}{'m' if m == 1 else ' '}".rjust(5)
                             for g, m in zip(geo, meg))
            rows.append(f"{L:8g}  {cells}  {first} / {mfirst}")
        rows.append("(O geometric overlap, . separate, m MEGNO criterion connects)")
        rows.append(self.message)
        return rows

    def plot(self, ax=None, title=None):
        """Decision per elongation with the numerical and analytic thresholds and the largest
        ⟨Y⟩ per elongation: :func:`ti_spinorbit.output.plotting.plot_overlap`. Returns the Axes."""
        return self._figure(ax=ax, title=title)

    @property
    def monotonic(self) -> bool:
        """True when the decisions switch from 'separate' to 'overlap' once and stay."""
        o = self.overlaps.astype(int)
        return bool(np.all(np.diff(o) >= 0))


SystemFactory = Callable[[float], BinarySystem]


def _factory(system, eccentricity):
    if callable(system):
        if eccentricity is not None:       # it would be ignored: the factory sets e itself
            raise TypeError(f"eccentricity={show(eccentricity)} applies to a catalogue name; "
                            "a factory builds its systems with their own eccentricity: set it "
                            "in the factory")
        return system, "custom"
    name = system
    catalog.entry(name)  # raises for unknown names, listing the known ones
    return (lambda q: catalog.system(name, elongation=q, eccentricity=eccentricity)), name


def overlap_threshold(system: Union[str, SystemFactory], elongations=None,
                      eccentricity=None, orbits=1000, *, rtol=None, method=None,
                      integrator=None, run=None, centre_starts=48, separatrix_starts=32,
                      libration_limit=LIBRATION_LIMIT_DEG, indicators=True, max_drift=None,
                      include_inaccurate=False, coordinates="inertial", max_orbits=None,
                      perturbations=None) -> OverlapScan:
    """Scan the elongation a/b and decide, for each, whether the 1:1 and 3:2 resonances
    overlap (see the module docstring for the rule).

    Parameters
    ----------
    system : str or callable
        A catalogue name, or a factory ``f(elongation) -> BinarySystem`` (the family scanned).
    elongations : array, optional
        a/b values (default 1.01 ... 1.15 in steps of 0.01).
    eccentricity : float, optional
        Override the catalogue eccentricity, in [0, 1) (names only: with a factory it is
        refused, the factory sets e, the same for every elongation).
    orbits : float or Quantity
        Orbits of the first (shortest) integration; longer ones find slower connections
        (a Quantity dimensionless or in ``ti_spinorbit.units.orbit``: the elongations'
        systems differ in period).
    max_orbits : float or Quantity, optional
        Cap of the doubling (default ``4 · orbits``: lengths orbits, 2·orbits, 4·orbits).
        The scan integrates at orbits, 2·orbits, 4·orbits, ... (each length integrates again,
        from the start, only the elongations still "separate": a connection once seen is
        final) until two successive lengths give the same decision at every elongation and
        no elongation is still "separate" where the MEGNO criterion already connects
        (``converged``, ``converged_orbits``); at the cap without that, ``message`` says
        "not converged by N orbits" and ``first_overlap`` is an upper bound
        (``upper_bound``). ``max_orbits = orbits`` runs one length (never converged).
        ``overlaps_by_length`` / ``megno_overlaps_by_length`` hold the evidence (rows
        ``lengths``); ``member_orbits`` the cost.
    rtol, method, integrator : optional
        How the equations are integrated (:class:`ti_spinorbit.Integrator`; ``rtol``
        default 1e-10: chaos detection needs no more).
    run : Run, optional
        How the run is carried out (:class:`ti_spinorbit.Run`): progress, the checkpoints of
        the scan's launches (one per length, ``DIR/launch-kkk``), and a Dask client (the
        members run in chunks on its workers, with an identical result).
    centre_starts, separatrix_starts : int
        Starts per elongation in the θ_p = 0 and θ_p = 90° columns, each in [2, 100000].
    libration_limit : float or Quantity
        Section extent (deg, in (0, 90]) below which a θ_p = 0 trace counts as librating.
    indicators : bool
        Integrate MEGNO / Lyapunov shadows too (about twice the cost) for the evidence.
    max_drift : float, optional
        Drift limit of the accuracy verdict (default ``min(1e-4, 1000 · rtol · orbits)``;
        :mod:`ti_spinorbit.engine.accuracy`).
    include_inaccurate : bool
        Let "inaccurate" trajectories take part in the decisions (default: left out).
    coordinates : {"inertial", "apsidal"}
        Spin coordinate of the starts and of the centres and ranges in the decisions
        (docs/physics.md §6.7; "apsidal" is the paper's).
    perturbations : list of Tides, YORP, BYORP, optional
        Tides, YORP and BYORP in the equations of every trajectory of every length, built
        for each elongation's own system from the same SI objects (docs/physics.md §13).
        A dissipative tide lets trajectories drift across the section, so a connection can
        then also mean a tidal drift between the islands' levels: compare with the scan
        without them. Recorded in the scan (``perturbations``).
    Each decision also carries the MEGNO criterion (:func:`megno_connects`,
    ``OverlapDecision.megno_overlap``; ``megno_first_overlap`` its threshold): a chaotic
    layer spanning both islands shows in ⟨Y⟩ before a single trajectory has crossed it.

    See Also
    --------
    ti_spinorbit.analytic.omega0_overlap : the analytic threshold ω0^RO = 1/(2 + √(14e))

    References
    ----------
    * Naidu, S. P. & Margot, J.-L. 2015, AJ 149:80, §6.
    * Chirikov, B. V. 1979, A universal instability of many-dimensional oscillator
      systems, Physics Reports 52:263.

    Examples
    --------
    Two elongations of 1991 VH, a few starts and 20 orbits each (the paper's scan takes 1000 to
    4000 orbits):

    >>> scan = tso.overlap_threshold("1991 VH", elongations=[1.02, 1.06], orbits=20,
    ...                              max_orbits=20, centre_starts=4, separatrix_starts=4)
    >>> scan.elongations
    array([1.02, 1.06])
    >>> round(scan.elongation_ro, 3)                       # the analytic threshold
    1.042
    """
    # every scalar before any system is built or integrated
    check_coordinates(coordinates)
    orbits, max_orbits = (to_plain(k, v, "orbit") for k, v in (("orbits", orbits),
                                                                ("max_orbits", max_orbits)))
    check_orbits(orbits)
    if max_orbits is None:
        max_orbits = 4.0 * float(orbits)
    elif isinstance(max_orbits, bool) or not isinstance(max_orbits, (int, float, np.integer,
                                                                     np.floating)) \
            or not float(orbits) <= float(max_orbits) <= 1e7:
        raise ValueError(f"max_orbits must be a number in [orbits, 1e7] = [{float(orbits):g}, "
                         f"1e7] (got {max_orbits!r})")
    max_orbits = float(max_orbits)
    if max_orbits < float(orbits):
        raise ValueError(f"max_orbits must lie in [orbits, 1e7] = [{float(orbits):g}, 1e7] "
                         f"(got {max_orbits:g})")
    integrator = _options.integrator(integrator, rtol, method, default_rtol=MAP_RTOL)
    run = _options.run(run)
    rtol = integrator.rtol
    centre_starts = require_count("centre_starts", centre_starts, 2, 100000)
    separatrix_starts = require_count("separatrix_starts", separatrix_starts, 2, 100000)
    libration_limit = require_scalar("libration_limit", libration_limit, 0.0, 90.0, low_open=True,
                                     unit="deg")
    if not (isinstance(system, str) or callable(system)):
        raise TypeError(f"system must be a catalogue name or a callable "
                        f"(elongation) -> BinarySystem (got {type(system).__name__})")
    make, name = _factory(system, eccentricity)
    perturbations = check_perturbations(perturbations)
    launches = Launches(run.checkpoint, run.resume, run.overwrite, run.keep_checkpoint)
    if elongations is not None and (np.ndim(elongations) != 1 or np.size(elongations) == 0):
        raise ValueError(f"elongations must be a non-empty 1-D array of a/b values in (1, 10] "
                         f"(got {show(elongations)})")
    q = np.round(np.arange(1.01, 1.155, 0.01), 10) if elongations is None else \
        _as_floats("elongations", elongations).ravel()
    require_range("elongations", q, 1.0, 10.0, low_open=True, high_open=False)
    if max_drift is not None:
        accuracy.drift_limit(rtol, orbits, max_drift)        # checked before any work
    try:
        per_elongation = int(centre_starts) + int(separatrix_starts)
    except (TypeError, ValueError):
        per_elongation = None                  # named by the checks that build the columns
    if per_elongation is not None and per_elongation > 0:
        # the first length, all elongations; every longer one (the elongations still
        # separate) is sized by surface_of_section before it starts
        resources.check_memory("overlap_threshold", q.size * per_elongation, orbits,
                               advice="scan fewer elongations or starts, or fewer orbits")
    systems = [make(float(x)) for x in q]
    if not all(isinstance(s, BinarySystem) for s in systems):
        bad = next(s for s in systems if not isinstance(s, BinarySystem))
        raise TypeError(f"system (a factory) must return a BinarySystem (got "
                        f"{type(bad).__name__})")
    e = systems[0].e
    if any(s.e != e for s in systems):   # one analytic threshold ω0^RO(e) for the whole scan
        raise ValueError("system (a factory) must give every elongation the same eccentricity "
                         f"(got {sorted({float(s.e) for s in systems})}); scan each e apart "
                         "(overlap_vs_eccentricity)")
    # θ_p = 0 column for the centres; θ_p = 90° column for the connection
    centre_rates = np.linspace(0.6, 2.0, int(centre_starts))
    sep_rates = np.linspace(0.8, 1.8, int(separatrix_starts))
    per = len(centre_rates) + len(sep_rates)
    lengths = _lengths(orbits, max_orbits)
    t0 = compiling.Stopwatch()           # compile time left out of seconds
    decisions = [None] * q.size
    geo_rows, megno_rows = [], []
    first_sec = None
    member_orbits = 0.0

    def stage(step, length, share):
        """One length: the elongations still "separate" (a connection seen at a shorter
        length is a fact, a trajectory crossed both levels) integrated again, longer."""
        nonlocal first_sec, member_orbits
        todo = [k for k in range(q.size) if decisions[k] is None or not decisions[k].overlap]
        if todo:
            members, theta0, rates = [], [], []
            for k in todo:
                members += [systems[k]] * per
                theta0 += [0.0] * len(centre_rates) + [90.0] * len(sep_rates)
                rates += list(centre_rates) + list(sep_rates)
            sec = surface_of_section(
                members, np.array(theta0), np.array(rates), length, integrator=integrator,
                run=replace(run, progress=share, **launches.next()), indicators=indicators,
                max_drift=max_drift, coordinates=coordinates, perturbations=perturbations)
            member_orbits += len(members) * float(length)
            first_sec = sec if first_sec is None else first_sec
            for j, k in enumerate(todo):
                block = slice(j * per, (j + 1) * per)
                decisions[k] = _decide(float(q[k]), systems[k], sec, block, centre_rates,
                                       sep_rates, libration_limit, include_inaccurate)
                decisions[k].orbits = float(length)
        geo_rows.append([d.overlap for d in decisions])
        megno_rows.append([-1 if d.megno_overlap is None else int(d.megno_overlap)
                           for d in decisions])
        # a "separate" elongation where the MEGNO criterion already sees one chaotic layer is
        # a slow connection the trajectories have not completed yet
        return geo_rows[-1], any(d.megno_overlap and not d.overlap for d in decisions)

    def settled(previous, current):
        """The decisions no longer change with length, and none is still pending."""
        return current[0] == previous[0] and not current[1]

    with launches.owned(), _progress.reporting(run.progress, "overlap_threshold") as report:
        ladder = run_lengths(lengths, stage, report, settled)
    converged_at = ladder.lengths[-1] if ladder.settled else None
    overlaps = np.array([d.overlap for d in decisions])
    first = next((float(x) for x, o in zip(q, overlaps) if o), None)
    megno_first = next((float(x) for x, d in zip(q, decisions) if d.megno_overlap), None)
    w_ro = float(analytic.omega0_overlap(e))
    ran = np.array(lengths[:len(geo_rows)], dtype=np.float64)
    converged = converged_at is not None
    where = "none in the scan" if first is None else f"a/b = {first:.2f}"
    if converged:
        message = (f"converged: decisions at {ran[-2]:g} and {ran[-1]:g} orbits agree at every "
                   f"elongation; first overlap {where}")
    else:
        message = (f"not converged by {ran[-1]:g} orbits: first overlap {where} is an upper "
                   f"bound (longer runs can only move it down)")
        waiting = [f"{d.elongation:.2f}" for d in decisions if d.megno_overlap and not d.overlap]
        if waiting:
            message += (f"; the MEGNO criterion already connects at a/b = "
                        f"{', '.join(waiting)}")
    n_inaccurate = sum(d.inaccurate for d in decisions)   # each in the run it comes from
    scan = OverlapScan(rtol=float(rtol), name=name, eccentricity=e, elongations=q, overlaps=overlaps,
                       decisions=decisions, first_overlap=first, omega0_ro=w_ro,
                       elongation_ro=float(analytic.elongation_from_omega0(w_ro)),
                       orbits=float(ran[-1]), seconds=t0.seconds(),
                       sections=first_sec, max_drift=first_sec.max_drift,
                       n_inaccurate=int(n_inaccurate),
                       include_inaccurate=bool(include_inaccurate), lengths=ran,
                       overlaps_by_length=np.array(geo_rows, dtype=bool),
                       megno_overlaps_by_length=np.array(megno_rows, dtype=np.int64),
                       converged=converged,
                       converged_orbits=converged_at if converged else float("nan"),
                       max_orbits=float(lengths[-1]), message=message,
                       megno_first_overlap=megno_first, member_orbits=member_orbits,
                       coordinates=coordinates, method=first_sec.method,
                       perturbations=perturbations)
    return scan


def _lengths(orbits, max_orbits):
    """Integration lengths of the doubling: orbits, 2·orbits, 4·orbits, ... while ≤ max_orbits
    (max_orbits itself ends the list when it is not a doubling of orbits)."""
    out = [float(orbits)]
    while out[-1] * 2.0 <= float(max_orbits) * (1 + 1e-12):
        out.append(out[-1] * 2.0)
    if out[-1] < float(max_orbits) * (1 - 1e-12):
        out.append(float(max_orbits))
    return out


def megno_connects(lo, hi, megno, c1, c32, megno_chaotic=MEGNO_CHAOTIC):
    """MEGNO connection criterion (faster than the geometric one): True when the θ̇_p ranges
    [lo, hi] of the *chaotic* separatrix-column members (⟨Y⟩ > ``megno_chaotic``), joined where
    they overlap, form one interval reaching from ≤ c1 to ≥ c32 — a single chaotic layer
    spans both islands' levels, though no one trajectory has crossed it yet. None when no
    member has a finite ⟨Y⟩ (indicators off)."""
    megno = np.asarray(megno, dtype=np.float64)
    if not np.isfinite(megno).any():
        return None
    chaotic = np.isfinite(lo) & np.isfinite(hi) & (megno > megno_chaotic)
    if not chaotic.any():
        return False
    order = np.argsort(lo[chaotic])
    start, end = lo[chaotic][order][0], hi[chaotic][order][0]
    for a, b in zip(lo[chaotic][order][1:], hi[chaotic][order][1:]):
        if a > end:                  # a gap: close the interval reaching c1, if it did
            if start <= c1 and end >= c32:
                break
            start, end = a, b
        else:
            end = max(end, b)
    return bool(start <= c1 and end >= c32)


def _decide(q, system, sec, block, centre_rates, sep_rates, libration_limit,
            include_inaccurate=False):
    idx = np.arange(sec.count.size)[block]
    nc = len(centre_rates)
    centre_idx, sep_idx = idx[:nc], idx[nc:]
    extent = section_extent(sec, centre_idx, include_inaccurate)
    librating = np.isfinite(extent) & (extent < libration_limit)

    def centre_near(nominal, window):
        near = librating & (np.abs(centre_rates - nominal) <= window)
        if not near.any():
            return None
        k = np.nanargmin(np.where(near, extent, np.inf))
        return float(centre_rates[k])

    c1 = centre_near(1.0, 0.35)
    if c1 is None:   # no synchronous island at all: nothing to overlap with
        c1 = 1.0
    c32 = centre_near(c1 + 0.5, 0.2)
    found = c32 is not None
    if not found:
        c32 = c1 + 0.5
    # only trajectories that passed the accuracy check (and have points) take part
    usable = accuracy.usable(sec.status[sep_idx], include_inaccurate) & (sec.count[sep_idx] > 0)
    points = np.where(usable[:, None], sec.thetadot_p[sep_idx], np.nan)
    with np.errstate(invalid="ignore"):
        lo = np.array([np.nanmin(p) if np.isfinite(p).any() else np.nan for p in points])
        hi = np.array([np.nanmax(p) if np.isfinite(p).any() else np.nan for p in points])
    connects = (lo <= c1) & (hi >= c32)
    widest = int(np.nanargmax(hi - lo)) if np.isfinite(hi - lo).any() else 0
    k = int(np.argmax(connects)) if connects.any() else None
    megno = sec.megno[sep_idx]
    return OverlapDecision(
        elongation=q, omega0=system.omega0, overlap=bool(connects.any()), centre_1=c1,
        centre_3_2=c32, centre_3_2_found=found,
        connecting_start=None if k is None else float(sep_rates[k]),
        connecting_range=None if k is None else (float(lo[k]), float(hi[k])),
        widest_range=(float(lo[widest]), float(hi[widest])),
        connecting_megno=float("nan") if k is None else float(megno[k]),
        connecting_lyapunov=float("nan") if k is None else float(sec.lyapunov[sep_idx][k]),
        separatrix_chaotic_fraction=float(np.mean(megno > MEGNO_CHAOTIC)) if np.isfinite(megno).all()
        else float("nan"),
        inaccurate=accuracy.count(sec.status[idx], "inaccurate"),
        max_energy_drift=float(np.nanmax(sec.energy_drift[idx], initial=0.0)),
        megno_overlap=megno_connects(lo, hi, np.where(usable, megno, np.nan), c1, c32),
        max_megno=_max_megno(sec, idx))


def _max_megno(sec, idx):
    """Largest finite ⟨Y⟩ among the members ``idx`` of ``sec`` (NaN when none is finite)."""
    megno = np.full(len(idx), np.nan) if sec.megno is None else \
        np.asarray(sec.megno[idx], dtype=np.float64)
    return float(np.nanmax(megno)) if np.isfinite(megno).any() else float("nan")


def overlap_vs_eccentricity(name, eccentricities, elongations=None, orbits=1000, *, rtol=None,
                            method=None, integrator=None, run=None, centre_starts=48,
                            separatrix_starts=32, libration_limit=LIBRATION_LIMIT_DEG,
                            indicators=True, max_drift=None, include_inaccurate=False,
                            coordinates="inertial", max_orbits=None, perturbations=None):
    """Overlap scans of a catalogued system at several eccentricities: one
    :func:`overlap_threshold` per eccentricity, every keyword passed on as it is (their
    meaning is documented there; ``run=Run(client=...)`` sends every scan to the cluster).
    Returns (eccentricities, numerical first_overlap (NaN if none), analytic a/b at
    ω0^RO(e), list of OverlapScan)."""
    orbits, max_orbits = (to_plain(k, v, "orbit") for k, v in (("orbits", orbits),
                                                                ("max_orbits", max_orbits)))
    ecc = _as_floats("eccentricities", eccentricities).ravel()
    require_range("eccentricities", ecc, 0.0, 1.0)
    # every scan keeps its sections: size all of them together, before the first
    try:
        per_scan = (15 if elongations is None else np.size(elongations)) * \
            (int(centre_starts) + int(separatrix_starts))
        length = float(orbits)
    except (TypeError, ValueError):
        per_scan = None                        # named by overlap_threshold's own checks
    if per_scan and np.isfinite(length) and length > 0:
        resources.check_memory("overlap_vs_eccentricity", ecc.size * per_scan, length,
                               advice="use fewer eccentricities, elongations, starts or orbits")
    scan = dict(rtol=rtol, method=method, integrator=integrator, run=run,
                centre_starts=centre_starts, separatrix_starts=separatrix_starts,
                libration_limit=libration_limit, indicators=indicators, max_drift=max_drift,
                include_inaccurate=include_inaccurate, coordinates=coordinates,
                max_orbits=max_orbits, perturbations=perturbations)
    scans = [overlap_threshold(name, elongations, float(e), orbits, **scan) for e in ecc]
    first = np.array([np.nan if s.first_overlap is None else s.first_overlap for s in scans])
    return ecc, first, np.array([s.elongation_ro for s in scans]), scans


__all__ = ["overlap_threshold", "overlap_vs_eccentricity", "OverlapScan", "OverlapDecision"]
