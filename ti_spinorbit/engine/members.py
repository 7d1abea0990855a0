"""The member table: what an ensemble integrates, built once.

Every entry point turns its inputs into one :class:`Members` table before any integration:
the systems (one per member), the scaled parameter rows and 3-D starts the kernels take,
each member's start as the paper's (θ_p, θ̇_p), the model of the equations of motion
(decided here, once, over the whole table: ``model="auto"`` takes the planar model only when
every member qualifies, and full-space indicators take the 3-D one), and the perturbation
rows. The table knows its record width and its memory estimate, and splits itself into
chunks (the Dask runner sends one chunk per task, ``ti_spinorbit.studies.distributed``), each chunk
integrating exactly as it would inside the whole launch.

Two ways in:

* :meth:`Members.from_starts`: systems × θ_p (deg) × θ̇_p (units of n) broadcast together,
  in inertial or apsidal spin coordinates (docs/physics.md §6.7);
* :meth:`Members.from_states`: explicit 3-D starts (:class:`ti_spinorbit.InitialState`), one
  member per state.

:meth:`Members.build` is the entry points' path: the starts or the states, checked, with the
memory check before any member is built.
"""

from dataclasses import dataclass, field, replace
from typing import List, Optional

import numpy as np

from .. import layout as _layout
from .._validate import _as_floats, require_count, require_finite, require_spin, show
from ..model import coordinates as _coords, models
from ..model.observables import derive
from ..model.perturbations import (NACC, check_perturbations, needs_3d, out_of_plane_rows,
                                   perturbation_rows)
from ..system import catalog
from ..system.initial import InitialState, as_scaled_states
from ..system.systems import BinarySystem, ESCAPE_DISTANCE
from . import evaluation, multipole_tables as _mp, resources



@dataclass(frozen=True, eq=False)
class Members:
    """An ensemble's member table (see the module docstring).

    ``systems`` one BinarySystem per member; ``par`` (N, NPAR) scaled parameter rows
    (``BinarySystem.parameter_row``); ``y0`` (N, 30) scaled 3-D starts; ``theta_p`` (N,)
    each start's θ_p, deg; ``thetadot_p`` (N,) its θ̇_p/n in ``coordinates``; ``model`` the
    equations of motion decided for the whole table ("planar" or "3d");
    ``perturbations`` the Tides / YORP / BYORP objects and ``perturbation_rows`` their
    scaled blocks (N, NPERT), None without; ``order`` the potential's truncation order and
    ``escape_distance`` (units of a) the escape radius the rows carry. Above order 4,
    ``degrees`` (primary, secondary) are the degree caps and ``multipole_rows`` (N, width)
    both bodies' integrals to those degrees in their own frames, scaled
    (``multipole_tables.integral_rows``): the order-N kernels' block beside the parameter
    rows, which keep their order-4 layout; None at order <= 4."""

    systems: List[BinarySystem]
    par: np.ndarray
    y0: np.ndarray
    theta_p: np.ndarray
    thetadot_p: np.ndarray
    model: str
    coordinates: str = "inertial"
    order: int = 4
    escape_distance: float = ESCAPE_DISTANCE
    perturbations: tuple = ()
    perturbation_rows: Optional[np.ndarray] = field(default=None, repr=False)
    degrees: Optional[tuple] = None
    multipole_rows: Optional[np.ndarray] = field(default=None, repr=False)

    def __len__(self):
        return len(self.systems)

    @property
    def perturbed(self) -> bool:
        return self.perturbation_rows is not None

    @property
    def record_width(self) -> int:
        """Width of the kernels' record rows (time + state, + the accumulators when
        perturbed) under the decided model."""
        state = _layout.planar.NSTATE if self.model == "planar" else _layout.spatial.NSTATE
        return 1 + state + (NACC if self.perturbed else 0)

    def memory_bytes(self, orbits, samples_per_orbit=None, states=False) -> float:
        """Estimated peak memory of integrating this table for ``orbits`` orbits
        (:func:`ti_spinorbit.engine.resources.estimate_bytes`)."""
        return resources.estimate_bytes(len(self), orbits, samples_per_orbit,
                                        width=self.record_width, states=states)

    def multipole(self):
        """The order-N data of the table (``multipole_tables.Multipole``: its tables and
        rows), None at order <= 4."""
        if self.multipole_rows is None:
            return None
        odd = _mp.odd_present(self.multipole_rows, self.degrees)
        return _mp.Multipole(_mp.tables(self.order, *self.degrees, odd), self.multipole_rows)

    def chunk(self, lo, hi) -> "Members":
        """Members lo..hi-1 as a table of their own, with the same decided model."""
        rows = None if self.perturbation_rows is None else self.perturbation_rows[lo:hi]
        block = None if self.multipole_rows is None else self.multipole_rows[lo:hi]
        return replace(self, systems=self.systems[lo:hi], par=self.par[lo:hi],
                       y0=self.y0[lo:hi], theta_p=self.theta_p[lo:hi],
                       thetadot_p=self.thetadot_p[lo:hi], perturbation_rows=rows,
                       multipole_rows=block)

    def chunks(self, size):
        """[(lo, hi, table)] of consecutive chunks of at most ``size`` members."""
        size = require_count("chunk_size", size, 1, 10**9)
        return [(lo, min(lo + size, len(self)), self.chunk(lo, min(lo + size, len(self))))
                for lo in range(0, len(self), size)]

    # ---- building --------------------------------------------------------------------------
    @classmethod
    def from_starts(cls, system, theta_p, thetadot_p, escape_distance=ESCAPE_DISTANCE,
                    coordinates="inertial", order=4, model="auto", perturbations=None,
                    full_indicators=False, degrees=None) -> "Members":
        """Broadcast systems and initial conditions into a member table.

        ``system`` one BinarySystem (or catalogue name) or a list of them; ``theta_p``
        deg, ``thetadot_p`` units of n, broadcast with the systems. ``escape_distance`` is
        in units of a and must exceed 1. With ``coordinates="apsidal"`` thetadot_p is the
        apsidal spin rate θ̇ − ϖ̇ at the start and y0 carries the inertial spin θ̇_p + ϖ̇(0)
        (docs/physics.md §6.7; ϖ̇ of the ``order`` model). ``degrees`` (order > 4 only):
        the caps (primary, secondary) of the integrals, default (order, order)."""
        _coords.check_coordinates(coordinates)
        check_escape_distance(escape_distance)
        systems = system_list(as_systems(system))
        degrees = order_n_degrees(systems, order, degrees)
        # checked before the conversion, so complex values and text are refused, not cast
        theta_p = np.asarray(require_finite("theta_p", theta_p), dtype=np.float64)
        thetadot_p = np.asarray(require_spin("thetadot_p", thetadot_p), dtype=np.float64)
        if theta_p.size == 0 or thetadot_p.size == 0:
            raise ValueError(f"theta_p and thetadot_p must hold at least one start each (got "
                             f"shapes {theta_p.shape} and {thetadot_p.shape})")
        index = np.arange(len(systems)) if len(systems) > 1 else np.zeros((), dtype=int)
        try:
            index, theta_p, thetadot_p = np.broadcast_arrays(index, theta_p, thetadot_p)
        except ValueError:
            raise ValueError(f"cannot broadcast {len(systems)} systems, theta_p of shape "
                             f"{theta_p.shape} and thetadot_p of shape {thetadot_p.shape}") \
                from None
        index, theta_p, thetadot_p = (np.ravel(x) for x in (index, theta_p, thetadot_p))
        members = [systems[k] for k in index]
        # one row and one vectorised start per system, spread over its members
        par = parameter_rows(systems, escape_distance)[index]
        y0 = np.empty((len(index), 30))
        for k, s in enumerate(systems):
            sel = np.flatnonzero(index == k)
            if len(sel):
                y0[sel] = s.initial_states(np.radians(theta_p[sel]), thetadot_p[sel])
        block = None if degrees is None else _mp.integral_rows(systems, degrees)[index]
        if coordinates == "apsidal":
            _coords.check_apsidal_start(members)
            multipole = None if block is None else _mp.Multipole(
                _mp.tables(order, *degrees, _mp.odd_present(block, degrees)), block)
            rate = evaluation.apsidal_rates(par, y0, order, multipole=multipole)
            y0, _ = _coords.apsidal_initial_states(members, rate, theta_p, thetadot_p)
        return cls._decided(members, par, y0, theta_p.copy(), thetadot_p.copy(), model,
                            coordinates, order, escape_distance, perturbations,
                            full_indicators, degrees, block)

    @classmethod
    def from_states(cls, system, initial_states, escape_distance=ESCAPE_DISTANCE, order=4,
                    model="auto", perturbations=None, full_indicators=False,
                    degrees=None) -> "Members":
        """Member table of explicit 3-D starts (:class:`ti_spinorbit.InitialState`): one
        member per state; ``system`` one system for all or one per state. θ_p and θ̇_p are
        each start's α (degrees, docs/physics.md §6.2) and inertial spin rate about the
        orbit normal (units of n), so results report them as for the paper's starts."""

        states = [initial_states] if isinstance(initial_states, InitialState) \
            else list(initial_states)
        systems = system_list(as_systems(system))
        if len(systems) not in (1, len(states)):
            raise ValueError(f"with initial_states, system must be one system or one per "
                             f"state (got {len(systems)} systems for {len(states)} states)")
        members = systems * len(states) if len(systems) == 1 else systems
        check_escape_distance(escape_distance)
        degrees = order_n_degrees(systems, order, degrees)
        y0 = as_scaled_states(members, states)
        par = parameter_rows(members, escape_distance)
        d = derive(par, y0)
        block = None if degrees is None else _mp.integral_rows(members, degrees)
        return cls._decided(members, par, y0, np.degrees(d["alpha"]), d["thetadot"], model,
                            "inertial", order, escape_distance, perturbations,
                            full_indicators, degrees, block)

    @classmethod
    def _decided(cls, members, par, y0, theta_p, thetadot_p, model, coordinates, order,
                 escape_distance, perturbations, full_indicators, degrees=None, block=None):
        """The table with its model decided (once, over every member) and its perturbation
        rows built. Above order 4 the planar model also needs every order-N integral odd in
        z to vanish (the parameter rows only show degrees 2..4)."""
        if full_indicators:       # full-space indicators carry out-of-plane deviations
            if model == "planar":
                raise ValueError("indicator_space='full' needs the 3-D model (the planar model "
                                 "cannot carry out-of-plane deviations): use model='auto' or "
                                 "'3d'")
            model = "3d"
        symmetric = None if block is None else \
            ~np.any(block[:, _mp.odd_mask(degrees, axis=2)] != 0.0, axis=1)
        perturbations = check_perturbations(perturbations)
        rows = perturbation_rows(members, perturbations)
        decided = models.choose(model, par, y0, symmetric,
                                spatial_forces=bool(np.any(out_of_plane_rows(rows)))).name
        return cls(members, par, y0, theta_p, thetadot_p, decided, coordinates, int(order),
                   float(escape_distance), perturbations, rows, degrees, block)

    @classmethod
    def build(cls, what, system, theta_p, thetadot_p, initial_states, orbits, *,
              escape_distance=ESCAPE_DISTANCE, coordinates="inertial", order=4, model="auto",
              perturbations=None, full_indicators=False, samples_per_orbit=None,
              states=False, degrees=None) -> "Members":
        """The member table of the entry point ``what``, from (θ_p, θ̇_p) or from
        ``initial_states``, after the memory check (from the input sizes alone, before any
        member is built; ``samples_per_orbit`` for a time series, ``states`` when it keeps
        the state rows, ``resources.estimate_bytes``)."""
        system = as_systems(system)
        perturbed = bool(check_perturbations(perturbations))
        common = dict(escape_distance=escape_distance, order=order, model=model,
                      perturbations=perturbations, full_indicators=full_indicators,
                      degrees=degrees)
        if initial_states is None:
            if theta_p is None and thetadot_p is None:    # one None: from_starts names it
                raise TypeError(f"{what}: give the starts as theta_p and thetadot_p, or as "
                                "initial_states=[InitialState, ...]")
            check_size(what, system, theta_p, thetadot_p, orbits, samples_per_orbit,
                       "3d" if full_indicators or needs_3d(perturbations) else model, perturbed,
                       states)
            return cls.from_starts(system, theta_p, thetadot_p, coordinates=coordinates,
                                   **common)
        if theta_p is not None or thetadot_p is not None:
            raise ValueError(f"{what}: give theta_p and thetadot_p or initial_states, not both")
        if coordinates != "inertial":
            raise ValueError(f"{what}: initial_states need coordinates='inertial' (the apsidal "
                             "coordinates are defined for the paper's planar starts)")
        count = 1 if not isinstance(initial_states, (list, tuple, np.ndarray)) \
            else len(initial_states)
        if count == 0:
            raise ValueError("initial_states must hold at least one InitialState")
        check_size(what, system, np.zeros(count), 0.0, orbits, samples_per_orbit, "3d",
                   perturbed, states)
        return cls.from_states(system, initial_states, **common)


# ---- the pieces ---------------------------------------------------------------------------
def as_systems(system):
    """Catalogue names (a str, or str entries of a list) as BinarySystems; anything else as
    given (:func:`system_list` checks it)."""

    if isinstance(system, str):
        return catalog.system(system)
    if isinstance(system, (list, tuple)) and any(isinstance(s, str) for s in system):
        return [catalog.system(s) if isinstance(s, str) else s for s in system]
    return system


def system_list(system):
    """The systems of a member table as a non-empty list, or TypeError naming ``system``."""
    try:
        systems = [system] if isinstance(system, BinarySystem) else list(system)
    except TypeError:                       # not iterable (a number, None)
        systems = []
    if not systems or not all(isinstance(s, BinarySystem) for s in systems):
        raise TypeError("system must be a BinarySystem, a catalogue name or a non-empty list "
                        f"of them (got {show(system)})")
    return systems


def order_n_degrees(systems, order, degrees):
    """The degree caps (primary, secondary) of an order-N table, None at order <= 4 (where
    ``degrees`` must be None): ``degrees`` or (order, order), each body checked to hold its
    integrals that far (``body.integral`` of a body that stops below would read zeros, and
    the potential would silently be of a lower order)."""
    if order <= _layout.multipole.HAND_WRITTEN_MAX:
        if degrees is not None:
            raise ValueError(f"degrees is for orders above "
                             f"{_layout.multipole.HAND_WRITTEN_MAX} (got order {order})")
        return None
    dA, dB = _mp.check_degrees(order, degrees)
    seen = set()
    for s in systems:
        if id(s) in seen:
            continue
        seen.add(id(s))
        for label, body, degree in (("primary", s.primary, dA), ("secondary", s.secondary, dB)):
            provided = _mp.degrees_provided(body)
            if provided < degree:
                raise ValueError(
                    f"{s.name}: the {label} holds integrals up to degree {provided}, but order "
                    f"{order} needs degree {degree}: give it integrals of degree {degree}, or "
                    f"cap it with Integrator(degrees=...)")
    return dA, dB


def check_escape_distance(escape_distance):
    """The escape distance (units of the semi-major axis a) as a float: finite and > 1."""
    distance = _as_floats("escape_distance", escape_distance)
    if distance.ndim != 0 or not np.isfinite(distance) or distance <= 1:
        raise ValueError(f"escape_distance must be a finite number > 1 (units of a) "
                         f"(got {escape_distance!r})")
    return float(distance)


def parameter_rows(members, escape_distance):
    """(N, NPAR) kernel parameter rows, one ``parameter_row`` per distinct system."""
    rows = {}
    for m in members:
        if id(m) not in rows:
            rows[id(m)] = m.parameter_row(escape_distance)
    return np.stack([rows[id(m)] for m in members])


def check_size(what, system, theta_p, thetadot_p, orbits, samples_per_orbit=None,
               model="auto", perturbed=False, states=False):
    """Refuse a run whose estimated peak memory (``resources.estimate_bytes``) exceeds what
    is available, from the input sizes alone: before any member is built. Inputs that do
    not broadcast are left to :meth:`Members.from_starts`, which names them."""
    systems = () if isinstance(system, BinarySystem) else \
        (len(system),) if hasattr(system, "__len__") else None
    n = None if systems is None else resources.member_count(systems, theta_p, thetadot_p)
    if n is not None:
        resources.check_memory(what, n, orbits, samples_per_orbit,
                               width=resources.record_width(system, model, perturbed),
                               states=states)


def member_groups(members):
    """[(system, member indices)] of the distinct systems of a member list, in first-seen
    order (one entry for an ensemble of one system)."""
    ids = np.fromiter(map(id, members), dtype=np.uint64, count=len(members))
    _, first, inverse = np.unique(ids, return_index=True, return_inverse=True)
    order = np.argsort(first)                       # groups in first-seen order
    return [(members[first[g]], np.flatnonzero(inverse.ravel() == g)) for g in order]


__all__ = ["Members", "as_systems", "system_list", "parameter_rows", "check_size",
           "member_groups"]
