"""Chaos maps: MEGNO and chaotic fraction over grids of initial conditions
(docs/physics.md §10).

A *chaos map* integrates every start of a (θ_p, θ̇_p/n) grid, with a shadow trajectory per
member, in ONE ensemble launch (:func:`~ti_spinorbit.studies.section.surface_of_section` with
``indicators=True``), and turns the per-member indicators into 2-D maps:

* MEGNO ⟨Y⟩ (Cincotta & Simó 2000, A&AS 147:205; implementation modelled on REBOUND's,
  Rein & Tamayo 2015): ⟨Y⟩ → 2 on a torus (quasi-periodic or resonant), → 0 at a stable
  periodic orbit, and grows ∝ t for a chaotic orbit (⟨Y⟩ ≈ λt/2);
* the finite-time maximal Lyapunov exponent λ, in 1/orbit;
* the label from :func:`~ti_spinorbit.studies.classify.classify_section` (MEGNO ≥ 4 chaotic, ≤ 2.5
  regular, the section geometry in between).

The *chaotic fraction* is the share of finished members labelled chaotic. A *parameter map*
does the same over the secondary's elongation a/b and the eccentricity e: a few starts in the
band of the 1:1 and 3:2 resonances per (a/b, e), again all in one launch (one system per
member), to compare with the analytic overlap criterion ω0 > ω0^RO = 1/(2 + sqrt(14e)) and the
chaotic-layer estimate ΔE/E0 (Wisdom, Peale & Mignard 1984; docs/physics.md §8.6).
"""

from dataclasses import dataclass, field, replace
from typing import Callable, Union

import numpy as np

from .. import display as _display
from .._validate import _as_floats, require_positive, require_real, require_spin, show
from ..system import catalog
from ..system.systems import BinarySystem
from ..model import analytic
from ..model.attitude import CLASS_UNIT as ATTITUDE_CLASS, CLASSES, classify_crossings
from ..model.coordinates import check_coordinates
from ..model.models import check_indicator_space
from ..model.perturbations import UNIT as PERTURBATIONS, check_perturbations, needs_3d
from ..engine import accuracy, compiling, resources
from ..engine import options as _options
from ..engine import progress as _progress
from ..engine.checkpoint import Launches
from ..engine.convergence import run_lengths
from ..engine.results import (CLASS, COORDINATES, METHOD, ORBITS, RELATIVE, SPIN, STATUS, Result,
                              Status, unit)
from ..engine.results import FLOAT as _F, INTEGER as _I, BOOL as _B, TEXT as _S
from .classify import MIN_POINTS, classify_section
from .section import INDICATOR_SPACE, SectionResult, check_orbits, plain_starts, surface_of_section
from ..units import to_plain

#: Colour range of MEGNO maps: 2 (regular) sits low, everything ≥ 8 saturates as chaotic.
#: Default starts per (a/b, e) of a parameter map: θ_p ∈ {0°, 90°} × θ̇_p/n in the 1:1-3:2 band.
PARAMETER_MAP_THETA_P = (0.0, 90.0)
PARAMETER_MAP_THETADOT_P = tuple(np.linspace(0.6, 2.0, 12))


def _axis(name, values):
    """A 1-D float array of finite values with at least one element, or ValueError (TypeError
    for text, complex values or None)."""
    arr = _as_floats(name, values)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1 or arr.size < 1:
        raise ValueError(f"{name} must be a non-empty 1-D array (got shape {arr.shape})")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {values!r})")
    return arr


#: Default rtol of the maps (a map needs the class of a trajectory, not its last digits).
MAP_RTOL = 1e-10


def _check_megno_chaotic(megno_chaotic):
    """The maps' MEGNO threshold, checked before any member is built."""
    require_real("megno_chaotic", megno_chaotic)
    require_positive("megno_chaotic", megno_chaotic)


def _chaotic_fraction(labels, status, include_inaccurate=False):
    """Fraction of finished members ("done"; also "inaccurate" ones when
    ``include_inaccurate``) labelled chaotic; NaN if none counts."""
    ok = accuracy.usable(status, include_inaccurate)
    return float(np.mean(labels[ok] == "chaotic")) if ok.any() else float("nan")


def _classified(section, megno_chaotic, orbits):
    """classify_section of a map's section. MEGNO settles chaos on its own, so short runs
    (fewer than the classifier's 64 points) still get labels: the point minimum is relaxed to
    ~0.8 per orbit (at least 8), which only affects the geometric rule used in the
    2.5 < ⟨Y⟩ < 4 gap and for resonant vs quasi-periodic."""
    min_points = int(min(MIN_POINTS, max(8, np.floor(0.8 * orbits))))
    # inaccurate members are labelled too (their data are kept); summaries exclude them
    return classify_section(section, megno_chaotic=megno_chaotic, min_points=min_points,
                            geometric=False, include_inaccurate=True)


def _labels(section, megno_chaotic, orbits):
    """The classification labels of :func:`_classified`."""
    return _classified(section, megno_chaotic, orbits).classification


def _attitude_classes(section, classes):
    """Attitude class codes of a map's members (``attitude.classify_crossings``): libration
    where the section is resonant in the synchronous resonance, tumbling, circulation."""
    if section.max_tilt is None or section.max_npa_angle is None:
        return None
    with np.errstate(invalid="ignore"):
        synchronous = (classes.classification == "resonant") & \
            (np.abs(np.asarray(classes.resonance_p, dtype=float) - 1.0) < 1e-9)
    return classify_crossings(synchronous, section.max_tilt, section.max_npa_angle)


def _mean_thetadot(section):
    with np.errstate(invalid="ignore"):
        counts = section.count
        total = np.nansum(section.thetadot_p, axis=1)
        return np.where(counts > 0, total / np.maximum(counts, 1), np.nan)


@dataclass(repr=False)
class ChaosMap(Result, _display.Readable, kind="chaos_map"):
    """Chaos indicators over a θ_p × θ̇_p/n grid of starts (2-D arrays of shape
    (len(theta_p), len(thetadot_p)), i.e. ``[i, j]`` is the start (theta_p[i], thetadot_p[j])).

    Attributes
    ----------
    theta_p, thetadot_p : ndarray
        The grid's axes: initial θ_p (deg) and θ̇_p/n.
    megno : ndarray
        MEGNO ⟨Y⟩ per start (→ 2 regular, ≫ 2 chaotic).
    lyapunov : ndarray
        Finite-time maximal Lyapunov exponent, 1/orbit.
    classification : ndarray of str
        "resonant", "quasi-periodic", "chaotic" or "undetermined".
    mean_thetadot : ndarray
        Mean θ̇_p/n over the section points.
    chaotic_fraction : float
        Share of the finished starts labelled chaotic (``megno > megno_chaotic``), NaN when
        none can be counted.
    megno_chaotic : float
        The MEGNO threshold of "chaotic".
    fraction_lengths, fraction_by_length : ndarray
        The chaotic fraction at orbits/4, orbits/2 and orbits, with ``fraction_monotone`` and
        ``fraction_message`` saying whether it has settled.
    status : ndarray of int
        Status codes (:class:`~ti_spinorbit.Status`).
    energy_drift, angmom_drift : ndarray
        Relative drifts per start; ``max_drift`` their limit, ``n_inaccurate`` the starts above
        it (left out of ``chaotic_fraction`` unless ``include_inaccurate``).
    section : SectionResult
        The underlying section, members in the same C order.
    coordinates : str
        The spin coordinate of ``thetadot_p`` and ``mean_thetadot`` ("inertial" or "apsidal",
        docs/physics.md §6.7).
    indicator_space, tilt, max_tilt, attitude_class
        The indicators' shadow direction, the starts' tilt (deg) and, for tilted starts, the
        largest pole tilt and attitude class per start.
    orbits, rtol, method, seconds, perturbations
        Run length (orbital periods), tolerance, Runge-Kutta pair, wall time (s) and
        perturbations.
    """

    # what a loaded file's arrays must look like (Result.SHAPES; k lengths)
    SHAPES = {
        "theta_p": (("theta_p",), _F), "thetadot_p": (("thetadot_p",), _F),
        **{k: (("theta_p", "thetadot_p"), _F) for k in (
            "megno", "lyapunov", "mean_thetadot", "energy_drift", "angmom_drift", "max_tilt")},
        "status": (("theta_p", "thetadot_p"), _I),
        "attitude_class": (("theta_p", "thetadot_p"), _I),
        "classification": (("theta_p", "thetadot_p"), _S),
        "fraction_lengths": (("k",), _F), "fraction_by_length": (("k",), _F),
        "tilt": ((2,), _F)}

    theta_p: np.ndarray = unit('deg')
    thetadot_p: np.ndarray = unit(SPIN)
    megno: np.ndarray = unit('1')
    lyapunov: np.ndarray = unit('1/orbit')
    classification: np.ndarray = unit(CLASS)
    mean_thetadot: np.ndarray = unit(SPIN)
    status: np.ndarray = unit(STATUS)
    chaotic_fraction: float = unit('1')
    orbits: float = unit(ORBITS)
    rtol: float = unit('1')
    seconds: float = unit('s')
    megno_chaotic: float = unit('1', default=4.0)
    section: SectionResult = field(default=None, repr=False)
    energy_drift: np.ndarray = unit(RELATIVE, default=None)
    angmom_drift: np.ndarray = unit(RELATIVE, default=None)
    max_drift: float = unit(RELATIVE, default=float("nan"))
    n_inaccurate: int = unit('members', default=0)
    include_inaccurate: bool = unit('bool', default=False)
    coordinates: str = unit(COORDINATES, default="inertial")
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    # chaotic fraction against integration length (chaos_map(fraction_orbits=...)): the
    # lengths (orbits, ascending, the map's own last) and the fraction at each; whether it
    # never decreases (⟨Y⟩ of a chaotic orbit only grows) and a one-line verdict
    fraction_lengths: np.ndarray = unit(ORBITS, default=None)
    fraction_by_length: np.ndarray = unit('1', default=None)
    fraction_monotone: bool = unit('bool', default=True)
    fraction_message: str = unit('text', default="")
    # docs/physics.md §10.4: the shadow direction, the start tilt (roll, pitch) of every
    # grid start, and the largest tilt of the secondary's pole each member reached
    indicator_space: str = unit(INDICATOR_SPACE, default="planar")
    tilt: np.ndarray = unit('deg (roll, pitch)', default=None)
    max_tilt: np.ndarray = unit('deg', default=None)
    # attitude class per start from its crossings (attitude.classify_crossings)
    attitude_class: np.ndarray = unit(ATTITUDE_CLASS, default=None)
    # tides / YORP / BYORP in the equations of every member (docs/physics.md §13)
    perturbations: tuple = unit(PERTURBATIONS, default=())


    @property
    def attitude_class_names(self):
        """``attitude_class`` as text, the map's shape (an object array; "" where none)."""
        if self.attitude_class is None:
            return None
        codes = np.asarray(self.attitude_class)
        return np.array([CLASSES[c] if c >= 0 else "" for c in codes.ravel()],
                        dtype=object).reshape(codes.shape)

    @property
    def shape(self):
        return self.megno.shape


    @property
    def member_orbits_per_second(self) -> float:
        return float(self.orbits * self.megno.size / self.seconds) if self.seconds else float("nan")

    def plot(self, ax=None, quantity="megno", overlay=False, overlay_members=64, colorbar=True,
             title=None):
        """pcolormesh of MEGNO (colours 0-8, the colourbar's top marks ⟨Y⟩ ≥ 8), the Lyapunov
        exponent (``quantity="lyapunov"``), the classes (``"classification"``) or the largest
        pole tilt (``"max_tilt"``, deg, log colours) over θ_p and θ̇_p/n:
        :func:`ti_spinorbit.output.plotting.plot_chaos_map`. Returns the Axes."""
        return self._figure(ax=ax, quantity=quantity, overlay=overlay,
                            overlay_members=overlay_members, colorbar=colorbar, title=title)


def chaos_map(system: BinarySystem, theta_p, thetadot_p, orbits, *, rtol=None, method=None,
              integrator=None, run=None, megno_chaotic=4.0, max_drift=None,
              include_inaccurate=False, coordinates="inertial", fraction_orbits=None,
              indicator_space="planar", tilt=None, perturbations=None) -> ChaosMap:
    """MEGNO, Lyapunov exponent and classification over a grid of starts, in one launch.

    Parameters
    ----------
    system : BinarySystem or str
        The system, or a catalogue name (``ti_spinorbit.system.catalog``).
    theta_p : 1-D array or Quantity
        Initial θ_p values, deg (x axis of the map); an angle Quantity is converted, a plain
        axis that looks like radians gets the degree hint (:mod:`ti_spinorbit.units`).
    thetadot_p : 1-D array or Quantity
        Initial θ̇_p/n values, units of n (y axis), in [-100, 100];
        a Quantity dimensionless, in ``ti_spinorbit.units.n``, or an angular rate (rad/s).
    orbits : float or Quantity
        Integration time in orbital periods, > 0 (a Quantity in ``units.orbit``, or a
        time, divided by the system's period). ⟨Y⟩ of a chaotic orbit grows ≈ λ t / 2, so
        with λ ≈ 0.5/orbit a few tens of orbits separate the classes; weak chaos needs more.
    rtol, method, integrator : optional
        How the equations are integrated (:class:`ti_spinorbit.Integrator`; ``rtol``
        default 1e-10 here, also atol).
    run : Run, optional
        How the run is carried out (:class:`ti_spinorbit.Run`): the progress (the shorter
        lengths included; with a client after every chunk), the checkpoint (one per stage,
        ``DIR/launch-kkk``), the Dask client (the map is identical to the single-process
        one; :mod:`ti_spinorbit.studies.distributed`).
    megno_chaotic : float
        ⟨Y⟩ at and above which a member is chaotic (default 4; ⟨Y⟩ → 2 when regular).
    max_drift : float, optional
        Drift limit of the accuracy verdict (default ``min(1e-4, 1000 · rtol · orbits)``;
        :mod:`ti_spinorbit.engine.accuracy`).
    include_inaccurate : bool
        Count "inaccurate" members in ``chaotic_fraction`` too (default: excluded).
    coordinates : {"inertial", "apsidal"}
        Spin coordinate of the θ̇_p/n axis, of the starts and of the section points
        (docs/physics.md §6.7; see :func:`~ti_spinorbit.studies.section.surface_of_section`).
    fraction_orbits : sequence of float, optional
        Shorter lengths (orbits, each in (0, orbits)) at which the same grid is also
        integrated, from the start, so that the chaotic fraction is reported against
        orbits (``fraction_lengths``, ``fraction_by_length``, ``fraction_message``); default
        (orbits/4, orbits/2), about 75 % more work; ``()`` skips it.
    indicator_space : {"planar", "full"}
        Shadow direction of MEGNO and λ (docs/physics.md §10.4): "planar" (default) the
        planar-restricted indicators, "full" deviations of the whole state (the 3-D model
        runs). Recorded in the map (``indicator_space``).
    tilt : (roll, pitch) of floats or Quantities, optional
        Start every grid point tilted out of the plane by these angles, degrees in
        [-90, 90] (``BinarySystem.tilted_start``; inertial coordinates):
        the map's ``max_tilt`` then shows how far each pole strays (``plot(quantity=
        "max_tilt")``; with ``client`` too). Without it every start is planar and stays so.
    perturbations : list of Tides, YORP, BYORP, optional
        Tides, YORP and BYORP in the equations of every member, each with its ``strength``
        factor (:mod:`ti_spinorbit.model.perturbations`, docs/physics.md §13); the shorter lengths
        of ``fraction_orbits`` run with them too. The accuracy verdict then holds E − W and
        L − L_ext (the energy and angular momentum they exchange taken off); MEGNO measures
        the divergence of the perturbed flow. Recorded in the map (``perturbations``, and in
        ``section``).

    Returns
    -------
    ChaosMap

    See Also
    --------
    parameter_map : the chaotic fraction over (a/b, e)
    ti_spinorbit.output.plotting.plot_chaos_map : the options of ``.plot()``

    References
    ----------
    * Cincotta, P. M. & Simó, C. 2000, Simple tools to study global dynamics in
      non-axisymmetric galactic potentials, A&AS 147:205 (MEGNO).

    Examples
    --------
    A 3 × 3 grid of starts of 1991 VH, 10 orbits each (the gallery's map is 64 × 64 × 500):

    >>> cmap = tso.chaos_map("1991 VH", np.linspace(0, 180, 3), np.linspace(0.4, 2.6, 3),
    ...                      orbits=10)
    >>> cmap.megno.shape                                   # (theta_p, thetadot_p)
    (3, 3)
    >>> 0.0 <= cmap.chaotic_fraction <= 1.0
    True
    >>> ax = cmap.plot()
    """
    check_coordinates(coordinates)
    system = catalog.as_system(system)
    theta_p, thetadot_p, orbits = plain_starts(system, theta_p, thetadot_p, orbits)
    theta_p = _axis("theta_p", theta_p)
    thetadot_p = require_spin("thetadot_p", _axis("thetadot_p", thetadot_p))
    check_orbits(orbits)
    integrator = _options.integrator(integrator, rtol, method, default_rtol=MAP_RTOL)
    run = _options.run(run)
    rtol, model = integrator.rtol, integrator.model
    _check_megno_chaotic(megno_chaotic)
    if max_drift is not None:
        accuracy.drift_limit(rtol, orbits, max_drift)        # checked before any work
    shorter = _fraction_lengths(orbits, fraction_orbits)
    launches = Launches(run.checkpoint, run.resume, run.overwrite, run.keep_checkpoint)
    indicator_space = check_indicator_space(indicator_space)
    tilt = _check_tilt(tilt, coordinates)
    perturbations = check_perturbations(perturbations)
    resources.check_memory("chaos_map", theta_p.size * thetadot_p.size, orbits,
                           advice="use a coarser grid or fewer orbits",
                           width=resources.record_width(system, "3d" if (
                               indicator_space == "full" or tilt is not None
                               or needs_3d(perturbations)) else model,
                               bool(perturbations)))
    tp, td = np.meshgrid(theta_p, thetadot_p, indexing="ij")
    states = None
    if tilt is not None:     # explicit tilted starts instead of the (θ_p, θ̇_p) grid
        states = [system.tilted_start(float(a), float(b), roll=tilt[0], pitch=tilt[1])
                  for a, b in zip(tp.ravel(), td.ravel())]
    grid_tp, grid_td = (tp, td) if tilt is None else (None, None)
    started = compiling.Stopwatch()          # compile time left out of seconds
    # the shorter lengths first, each dropped after its fraction: the peak memory stays
    # that of the map itself
    lengths = shorter + [float(orbits)]

    def stage(k, length, share):
        section = surface_of_section(
            system, grid_tp, grid_td, length, integrator=integrator,
            run=replace(run, progress=share, **launches.next()), indicators=True,
            max_drift=max_drift, coordinates=coordinates, initial_states=states,
            perturbations=perturbations, indicator_space=indicator_space)
        if k == len(lengths) - 1:
            return section                # the map itself
        return _chaotic_fraction(_labels(section, megno_chaotic, length), section.status,
                                 include_inaccurate)   # the section is dropped at once

    with launches.owned(), _progress.reporting(run.progress, "chaos_map") as report:
        *fractions, section = run_lengths(lengths, stage, report).outcomes
    classes = _classified(section, megno_chaotic, orbits)
    labels = classes.classification
    attitude_class = _attitude_classes(section, classes)
    seconds = started.seconds()
    full = _chaotic_fraction(labels, section.status, include_inaccurate)
    evidence = fraction_evidence(lengths, fractions + [full])
    shape = tp.shape
    return ChaosMap(
        theta_p=theta_p, thetadot_p=thetadot_p, megno=section.megno.reshape(shape),
        lyapunov=section.lyapunov.reshape(shape), classification=labels.reshape(shape),
        mean_thetadot=_mean_thetadot(section).reshape(shape), status=section.status.reshape(shape),
        chaotic_fraction=_chaotic_fraction(labels, section.status, include_inaccurate),
        orbits=float(orbits), rtol=float(rtol), seconds=seconds,
        megno_chaotic=float(megno_chaotic), section=section,
        energy_drift=section.energy_drift.reshape(shape),
        angmom_drift=section.angmom_drift.reshape(shape), max_drift=section.max_drift,
        n_inaccurate=section.n_inaccurate, include_inaccurate=bool(include_inaccurate),
        method=section.method,
        coordinates=coordinates, indicator_space=indicator_space, tilt=tilt,
        max_tilt=section.max_tilt.reshape(shape),
        attitude_class=None if attitude_class is None else attitude_class.reshape(shape),
        perturbations=perturbations, **evidence)


def _check_tilt(tilt, coordinates):
    """chaos_map's ``tilt`` as a float (roll, pitch) array in degrees, or None."""
    if tilt is None:
        return None
    values = _as_floats("tilt", to_plain("tilt", tilt, "deg"))
    if values.shape != (2,) or not np.all(np.isfinite(values)) or np.any(np.abs(values) > 90):
        raise ValueError(f"tilt must be (roll, pitch), two finite angles in [-90, 90] degrees "
                         f"(got {show(tilt)})")
    if coordinates != "inertial":
        raise ValueError("tilt needs coordinates='inertial' (the apsidal coordinates are "
                         "defined for planar starts)")
    return values


def _fraction_lengths(orbits, fraction_orbits):
    """The shorter lengths of chaos_map's fraction-against-orbits evidence, ascending."""
    if fraction_orbits is None:
        return [float(orbits) / 4.0, float(orbits) / 2.0]
    values = _as_floats("fraction_orbits", fraction_orbits).ravel()
    if np.any(~np.isfinite(values)) or np.any(values <= 0) or np.any(values >= float(orbits)):
        raise ValueError(f"fraction_orbits must hold lengths in (0, orbits) = (0, "
                         f"{float(orbits):g}) (got {show(fraction_orbits)})")
    if np.unique(values).size != values.size:      # the same length twice is the same run
        raise ValueError(f"fraction_orbits must hold distinct lengths (got "
                         f"{show(fraction_orbits)}: a length given twice would be integrated "
                         "twice for the same fraction)")
    return sorted(float(v) for v in values)


def fraction_evidence(lengths, fractions):
    """ChaosMap fields for the chaotic fraction against orbits: arrays, whether it never
    decreases (finite values only), and a message that says so or where it drops."""
    lengths, fractions = np.asarray(lengths, float), np.asarray(fractions, float)
    finite = fractions[np.isfinite(fractions)]
    monotone = bool(np.all(np.diff(finite) >= 0))
    table = ", ".join(f"{f:.3f} at {L:g}" for L, f in zip(lengths, fractions))
    if len(lengths) < 2:
        message = f"chaotic fraction {table} orbits (one length: not checked against orbits)"
    elif monotone:
        change = fractions[-1] - fractions[-2]
        message = (f"chaotic fraction vs orbits: {table}; never decreases; the last step "
                   f"adds {change:+.3f}")
    else:
        message = (f"chaotic fraction vs orbits: {table}; NOT monotone (a member's label "
                   "changed back: the fraction is not converged)")
    return {"fraction_lengths": lengths, "fraction_by_length": fractions,
            "fraction_monotone": monotone, "fraction_message": message}


def _inaccurate_code():
    """The "inaccurate" status code (:class:`ti_spinorbit.engine.results.Status`)."""
    return int(Status.INACCURATE)


@dataclass(repr=False)
class ParameterMap(Result, _display.Readable, kind="parameter_map"):
    """Chaotic fraction over elongation a/b × eccentricity e.

    Attributes
    ----------
    elongations, eccentricities : ndarray
        The axes: a/b and e.
    chaotic_fraction : ndarray, shape (len(elongations), len(eccentricities))
        The share of chaotic starts at each grid point.
    megno, classification, status : ndarray, shape (len(elongations), len(eccentricities), starts)
        Per start.
    theta_p, thetadot_p : ndarray
        The starts used at every grid point, deg and units of n.
    omega0 : ndarray
        ω0(a/b) of the ellipsoid, units of n.
    energy_drift, angmom_drift : ndarray
        Relative drifts per start; ``max_drift`` their limit.
    inaccurate : ndarray of int
        The "inaccurate" starts per (a/b, e), left out of ``chaotic_fraction`` unless
        ``include_inaccurate``.
    fraction_lengths, fraction_by_length
        The chaotic fraction at shorter run lengths, with ``fraction_monotone`` and
        ``fraction_message``.
    coordinates : str
        The spin coordinate of ``thetadot_p`` ("inertial" or "apsidal", docs/physics.md §6.7).
    name, orbits, rtol, method, seconds, indicator_space, perturbations
        The system family's name, run length (orbital periods), tolerance, Runge-Kutta pair,
        wall time of the one launch (s), indicators' shadow direction and perturbations.
    """

    # what a loaded file's arrays must look like (Result.SHAPES; k lengths)
    SHAPES = {
        "elongations": (("elongations",), _F), "eccentricities": (("eccentricities",), _F),
        "theta_p": (("start",), _F), "thetadot_p": (("start",), _F),
        "omega0": (("elongations",), _F),
        "chaotic_fraction": (("elongations", "eccentricities"), _F),
        **{k: (("elongations", "eccentricities", "start"), _F)
           for k in ("megno", "energy_drift", "angmom_drift")},
        "classification": (("elongations", "eccentricities", "start"), _S),
        "status": (("elongations", "eccentricities", "start"), _I),
        "inaccurate": (("elongations", "eccentricities"), _I),
        "fraction_monotone": (("elongations", "eccentricities"), _B),
        "fraction_lengths": (("k",), _F),
        "fraction_by_length": (("k", "elongations", "eccentricities"), _F)}

    elongations: np.ndarray = unit('1 (a/b)')
    eccentricities: np.ndarray = unit('1')
    chaotic_fraction: np.ndarray = unit('1')
    megno: np.ndarray = unit('1')
    classification: np.ndarray = unit(CLASS)
    status: np.ndarray = unit(STATUS)
    theta_p: np.ndarray = unit('deg')
    thetadot_p: np.ndarray = unit(SPIN)
    omega0: np.ndarray = unit(SPIN)
    orbits: float = unit(ORBITS)
    rtol: float = unit('1')
    seconds: float = unit('s')
    name: str = ""
    energy_drift: np.ndarray = unit(RELATIVE, default=None)
    angmom_drift: np.ndarray = unit(RELATIVE, default=None)
    max_drift: float = unit(RELATIVE, default=float("nan"))
    inaccurate: np.ndarray = unit('members', default=None)
    include_inaccurate: bool = unit('bool', default=False)
    coordinates: str = unit(COORDINATES, default="inertial")
    method: str = unit(METHOD, default="cash-karp")   # Runge-Kutta pair
    # chaotic fraction against integration length (parameter_map(fraction_orbits=...)):
    # fraction_by_length has shape (len(fraction_lengths), len(elongations),
    # len(eccentricities)); fraction_monotone per grid point; fraction_message one line
    fraction_lengths: np.ndarray = unit(ORBITS, default=None)
    fraction_by_length: np.ndarray = unit('1', default=None)
    fraction_monotone: np.ndarray = unit('bool', default=None)
    fraction_message: str = unit('text', default="")
    indicator_space: str = unit(INDICATOR_SPACE, default="planar")   # docs/physics.md §10.4
    # tides / YORP / BYORP in the equations of every member (docs/physics.md §13)
    perturbations: tuple = unit(PERTURBATIONS, default=())

    @property
    def member_orbits_per_second(self) -> float:
        return float(self.orbits * self.megno.size / self.seconds) if self.seconds else float("nan")


    def plot(self, ax=None, contours=(1e-3, 1e-2, 0.1, 1.0), colorbar=True, title=None):
        """pcolormesh of the chaotic fraction over (e, a/b) with the analytic overlap line and
        chaotic-layer contours: :func:`ti_spinorbit.output.plotting.plot_parameter_map`."""
        return self._figure(ax=ax, contours=contours, colorbar=colorbar, title=title)


def parameter_map(system: Union[str, Callable[[float, float], BinarySystem]],
                  elongations, eccentricities, orbits, thetadot_p=PARAMETER_MAP_THETADOT_P,
                  theta_p=PARAMETER_MAP_THETA_P, *, rtol=None, method=None, integrator=None,
                  run=None, megno_chaotic=4.0, max_drift=None, include_inaccurate=False,
                  coordinates="inertial", fraction_orbits=None, indicator_space="planar",
                  perturbations=None) -> ParameterMap:
    """Chaotic fraction of a set of starts at every (a/b, e), all members in one launch.

    Parameters
    ----------
    system : str or callable
        A catalogue name (``catalog.system(name, elongation=q, eccentricity=e)``) or a
        function ``(q, e) -> BinarySystem``.
    elongations, eccentricities : 1-D arrays
        The a/b (≥ 1) and e (0 ≤ e < 1) axes.
    orbits : float or Quantity
        Integration time in orbital periods, > 0 (a Quantity dimensionless or in
        ``ti_spinorbit.units.orbit``: the grid's systems differ in period).
    thetadot_p, theta_p : 1-D arrays or Quantities
        Starts per grid point: the product θ_p (deg, or an angle Quantity) × θ̇_p/n (a
        Quantity dimensionless or in ``units.n``: the grid's systems differ in n). Default {0°, 90°} × 12 rates
        from 0.6 to 2.0 n, the band of the 1:1 and 3:2 resonances whose overlap is at issue.
    rtol, method, integrator, run
        As for :func:`chaos_map` (``rtol`` default 1e-10).
    megno_chaotic : float
        ⟨Y⟩ at and above which a member is chaotic.
    max_drift, include_inaccurate, coordinates, fraction_orbits, indicator_space
        As for :func:`chaos_map` ("apsidal" needs every e ≥ 1e-3, docs/physics.md §6.7; the
        fraction against orbits per grid point; ``indicator_space`` docs/physics.md §10.4,
        recorded in the map).
    perturbations : list of Tides, YORP, BYORP, optional
        Tides, YORP and BYORP in the equations of every member (docs/physics.md §13). The
        same objects apply at every (a/b, e): they hold SI parameters (k2, time lag or Q,
        f_Y, B, strength) and are turned into each grid system's scaled block with that
        system's own radius, masses, a and n, so a tide with the default (volume-equivalent)
        radius follows the secondary's shape across the a/b axis. Recorded in the map.

    Returns
    -------
    ParameterMap

    See Also
    --------
    chaos_map : one system, a grid of starts

    Examples
    --------
    >>> pmap = tso.parameter_map("1991 VH", [1.3, 1.5], [0.05], orbits=10,
    ...                          thetadot_p=[1.0, 1.5])
    >>> pmap.chaotic_fraction.shape                        # (elongations, eccentricities)
    (2, 1)
    """
    check_coordinates(coordinates)
    theta_p, thetadot_p, orbits = plain_starts(None, theta_p, thetadot_p, orbits)
    elongations = _axis("elongations", elongations)
    eccentricities = _axis("eccentricities", eccentricities)
    theta_p = _axis("theta_p", theta_p)
    thetadot_p = require_spin("thetadot_p", _axis("thetadot_p", thetadot_p))
    check_orbits(orbits)
    integrator = _options.integrator(integrator, rtol, method, default_rtol=MAP_RTOL)
    run = _options.run(run)
    rtol = integrator.rtol
    _check_megno_chaotic(megno_chaotic)
    indicator_space = check_indicator_space(indicator_space)
    if np.any(elongations < 1.0):
        raise ValueError(f"elongations must be >= 1 (got {elongations!r})")
    if np.any((eccentricities < 0.0) | (eccentricities >= 1.0)):
        raise ValueError(f"eccentricities must lie in [0, 1) (got {eccentricities!r})")
    if max_drift is not None:
        accuracy.drift_limit(rtol, orbits, max_drift)        # checked before any work
    shorter = _fraction_lengths(orbits, fraction_orbits)
    launches = Launches(run.checkpoint, run.resume, run.overwrite, run.keep_checkpoint)
    perturbations = check_perturbations(perturbations)
    if isinstance(system, str):
        name = system
        factory = lambda q, e: catalog.system(name, elongation=q, eccentricity=e)  # noqa: E731
    elif callable(system):
        factory, name = system, ""
    else:
        raise TypeError("system must be a catalogue name or a callable (a/b, e) -> "
                        f"BinarySystem (got {show(system)})")
    tp, td = (x.ravel() for x in np.meshgrid(theta_p, thetadot_p, indexing="ij"))
    starts = tp.size
    resources.check_memory("parameter_map", elongations.size * eccentricities.size * starts,
                           orbits, advice="use a coarser grid, fewer starts or fewer orbits")
    grid = []
    for q in elongations:
        for e in eccentricities:
            made = factory(float(q), float(e))
            if not isinstance(made, BinarySystem):       # named before it is used
                raise TypeError(f"factory system(a/b, e) must return a BinarySystem; at the "
                                f"grid point (a/b, e) = ({q:g}, {e:g}) it returned "
                                f"{type(made).__name__}")
            grid.append(made)
    if not name:
        name = grid[0].name
    members = [s for s in grid for _ in range(starts)]
    shape = (elongations.size, eccentricities.size, starts)

    def fractions_of(sec, length):
        lab, st = _labels(sec, megno_chaotic, length).reshape(shape), sec.status.reshape(shape)
        return lab, st, np.array([[_chaotic_fraction(lab[i, j], st[i, j], include_inaccurate)
                                   for j in range(shape[1])] for i in range(shape[0])])

    started = compiling.Stopwatch()          # compile time left out of seconds
    lengths = shorter + [float(orbits)]

    def stage(k, length, share):
        section = surface_of_section(
            members, np.tile(tp, len(grid)), np.tile(td, len(grid)), length,
            integrator=integrator, run=replace(run, progress=share, **launches.next()),
            indicators=True, max_drift=max_drift, coordinates=coordinates,
            perturbations=perturbations, indicator_space=indicator_space)
        # the shorter lengths first, each dropped after its fractions (as chaos_map)
        return section if k == len(lengths) - 1 else fractions_of(section, length)[2]

    with launches.owned(), _progress.reporting(run.progress, "parameter_map") as report:
        *by_length, section = run_lengths(lengths, stage, report).outcomes
    seconds = started.seconds()
    labels, status, fraction = fractions_of(section, orbits)
    by_length = np.array(by_length + [fraction])
    with np.errstate(invalid="ignore"):
        steps = np.diff(by_length, axis=0)
    monotone = np.all(~(steps < 0), axis=0)          # NaN steps do not count as drops
    lengths = np.array(lengths)
    message = (f"chaotic fraction at {', '.join(f'{L:g}' for L in lengths)} orbits: "
               + ("never decreases at any grid point" if monotone.all() else
                  f"decreases at {int((~monotone).sum())} of {monotone.size} grid points "
                  "(not converged there)"))
    return ParameterMap(
        elongations=elongations, eccentricities=eccentricities, chaotic_fraction=fraction,
        megno=section.megno.reshape(shape), classification=labels, status=status, theta_p=tp,
        thetadot_p=td, omega0=np.asarray(analytic.omega0(elongations)), orbits=float(orbits),
        rtol=float(rtol), seconds=seconds, name=name,
        energy_drift=section.energy_drift.reshape(shape),
        angmom_drift=section.angmom_drift.reshape(shape), max_drift=section.max_drift,
        inaccurate=np.sum(status == _inaccurate_code(), axis=-1),
        include_inaccurate=bool(include_inaccurate), coordinates=coordinates,
        method=section.method, fraction_lengths=lengths, fraction_by_length=by_length, fraction_monotone=monotone,
        fraction_message=message, indicator_space=section.indicator_space,
        perturbations=perturbations)
