"""Tides, YORP, BYORP and the Sun's tide as objects: SI parameters in, the kernels' scaled
block out.

``perturbations=[...]`` on every entry point takes a list of these objects; each member of
an ensemble gets the sum of their contributions, converted with its own system's units
(length a, time 1/n, mass m1 + m2), as a block of ``kernels.perturb.NPERT`` numbers after its
parameter row. The equations, and how the diagnostics account for the energy and angular
momentum the perturbations exchange, are in docs/physics.md §13 and ``kernels/perturb.py``.

Decisions:

* Every object has a ``strength`` factor (default 1) that multiplies its force and torque,
  so that effects acting over 1e5–1e7 years can be studied in thousands of orbits. Rates
  scale linearly with it (tested); an equilibrium between two effects scaled by the same
  factor does not move.
* A body's radius defaults to its volume-equivalent radius (a b c)^(1/3) (``radius=`` m
  overrides it); a body that is not an ellipsoid or sphere needs ``radius=``.
* Two perturbations of the same kind on the same body are refused (ValueError): their sum
  is one perturbation with the summed coefficient.
* YORP acts about the body's z axis (the spin axis of a principal-axis rotator, which every
  catalogued body is); BYORP along the relative velocity. Both need the binary's
  heliocentric orbit: catalogued where known (``catalog.heliocentric_orbit``), else give
  ``heliocentric_a_au`` and ``heliocentric_e``.
* The Sun's tide (:class:`SolarTide`, docs/physics.md §13.11) takes the same (a, e) and the
  orbit's angles relative to the inertial frame (the mutual orbit's initial frame for the
  standard start), by default the Sun in the mutual orbit's plane (i = Ω = ω = 0) and the
  barycentre at perihelion at t = 0; its ``strength`` scales the Sun's mass in the force and
  torques, not in the Sun's motion. It is one per run (no body to choose).
* The YORP torque has two conventions (:data:`YORP_CONVENTIONS`, docs/physics.md §13.2).
  Naidu & Margot (2015) give the YORP energy per orbit δE_YORP = 2π R³ L_⊙ f_Y /
  (3 c d² sqrt(1 − e_⊙²)) as the torque's work over TWO rotations of the secondary per
  mutual orbit, so their torque is δE_YORP / 4π = f_Y R³ L_⊙ / (6 c d² sqrt(1 − e_⊙²)): the
  Lambertian recoil (2/3)(L_⊙/4πd²c) πR² of the sunlight a sphere of radius R intercepts,
  with lever arm R and efficiency f_Y. That is the default, ``"paper"``. ``"one-turn"``
  reads δE_YORP as the work over ONE rotation, T = δE_YORP / 2π, twice as large: the
  package's torque before the choice existed. A saved YORP without a convention (files
  and checkpoints written before) is read back as ``"one-turn"``, the torque it was run
  with.

Importing this module does not import Taichi.
"""

import math
from dataclasses import asdict, dataclass
from typing import Optional

import numpy as np

from ..constants import AU, C_LIGHT, DEFAULT_F_YORP, DEFAULT_Q, GM_SUN, K2_MODELS, L_SUN
from .._validate import HELIOCENTRIC_A_RANGE as _HELIOCENTRIC_A_RANGE
from .._validate import (check_heliocentric, require_positive_scalar, require_range, require_real,
                         show)
from ..layout import perturbation as _layout
from ..system.systems import BinarySystem, G
from ..units import plain_fields as _plain_fields

#: The kernels' perturbation block, its accumulators (work, L_ext x, y, z) and the
#: constant-Q rate floor (units of the system's n; the analytic rates use it too), from
#: ti_spinorbit.layout, which the kernels read as well.
Q_TIDE1, Q_TIDE2, Q_YORP1, Q_YORP2, Q_BYORP = (_layout.Q_TIDE1, _layout.Q_TIDE2,
                                               _layout.Q_YORP1, _layout.Q_YORP2,
                                               _layout.Q_BYORP)
NPERT, NACC, Q_RATE_FLOOR = _layout.NPERT, _layout.NACC, _layout.Q_RATE_FLOOR
Q_SUN, Q_SUN_A, Q_SUN_E, Q_SUN_N, Q_SUN_M0, Q_SUN_P, Q_SUN_Q, Q_SUN_NU = (
    _layout.Q_SUN, _layout.Q_SUN_A, _layout.Q_SUN_E, _layout.Q_SUN_N, _layout.Q_SUN_M0,
    _layout.Q_SUN_P, _layout.Q_SUN_Q, _layout.Q_SUN_NU)
Q_SUN_J1, Q_SUN_J2 = _layout.Q_SUN_J1, _layout.Q_SUN_J2
BODIES = ("primary", "secondary")
#: Allowed ranges (closed), shared with the command line's flags.
K2_RANGE = (1e-12, 10.0)
TIME_LAG_RANGE = (1e-9, 1e9)          # s
Q_RANGE = (1e-3, 1e12)
RADIUS_RANGE = (1e-3, 1e10)           # m
STRENGTH_RANGE = (1e-12, 1e15)
COEFFICIENT_LIMIT = 1.0               # |f_Y|, |B|
#: How far a perturbation may go and still be one (checked per system when a run starts,
#: :func:`perturbation_rows`): a spin changed by at most this many n per orbit (tide or
#: YORP torque, with the tide's lag at its largest), the orbit's semimajor axis by at most
#: this fraction per orbit (BYORP), the tide's conservative force at most this fraction of
#: the mutual gravity at pericentre. Beyond them the "perturbation" is the dynamics, the
#: first-order tidal expansion no longer holds, and the steps per orbit grow without bound.
SPIN_CHANGE_LIMIT = 10.0              # n per orbit
ORBIT_CHANGE_LIMIT = 0.1              # relative change of a per orbit
TIDE_FORCE_LIMIT = 0.1                # conservative tide / mutual gravity at pericentre
#: The Sun's tide over the mutual gravity (at apoapsis and perihelion) beyond which it is
#: the dynamics, not a perturbation: (a/r_Hill)³ = 3 × this, a ≈ 0.3 of the Hill radius.
SOLAR_TIDE_LIMIT = 0.01
#: Angles of the heliocentric orbit, degrees (closed): i in [0, 180], the others [-360, 360].
INCLINATION_RANGE = (0.0, 180.0)
ANGLE_RANGE = (-360.0, 360.0)
HELIOCENTRIC_A_RANGE = _HELIOCENTRIC_A_RANGE   # AU (ti_spinorbit._validate)
#: YORP torque conventions: name -> (k, turns). The torque is T = f_Y R³ L_⊙ /
#: (k c d² sqrt(1 − e_⊙²)) and ``turns`` the rotations of the body per mutual orbit whose
#: work 2π turns T is the paper's δE_YORP (docs/physics.md §13.2).
YORP_CONVENTIONS = {"paper": (6.0, 2), "one-turn": (3.0, 1)}
#: The default convention: the torque of Naidu & Margot's prose (two rotations per orbit).
YORP_CONVENTION = "paper"
#: The convention of a saved YORP that records none (written before the choice existed).
YORP_LEGACY_CONVENTION = "one-turn"
#: Unit text of a result's ``perturbations`` field (saved as their descriptions).
UNIT = "objects: Tides / YORP / BYORP / SolarTide with SI parameters (ti_spinorbit.model.perturbations)"


def solar_radiation_constant():
    """F_⊙ = L_⊙ / (4π c), kg m s⁻² (≈ 1.0e17; Jacobson & Scheeres 2011 round it to
    1e14 kg km s⁻²): radiation pressure times distance², N m² / m²."""
    return L_SUN / (4.0 * math.pi * C_LIGHT)


def yorp_torque(f_yorp, radius, distance, e, convention=YORP_CONVENTION):
    """The YORP torque f_Y R³ L_⊙ / (k c d² sqrt(1 − e_⊙²)), N m.

    For a body of ``radius`` (m) on a heliocentric orbit of semimajor axis ``distance`` (m)
    and eccentricity ``e``; k = 6 for ``convention="paper"`` (Naidu & Margot 2015: its work
    over two rotations is their δE_YORP), k = 3 for ``"one-turn"`` (its work over one
    rotation is δE_YORP); see :data:`YORP_CONVENTIONS` and docs/physics.md §13.2. Inputs
    unchecked (the callers check them), except the convention's name."""
    k = YORP_CONVENTIONS[_check_yorp_convention(convention)][0]
    return f_yorp * radius ** 3 * L_SUN / (k * C_LIGHT * distance ** 2 * math.sqrt(1.0 - e ** 2))


def yorp_turns_per_orbit(convention=YORP_CONVENTION):
    """Rotations per mutual orbit over which the torque of ``convention`` does the paper's
    δE_YORP: 2 for ``"paper"``, 1 for ``"one-turn"`` (δE_YORP = 2π × turns × T)."""
    return YORP_CONVENTIONS[_check_yorp_convention(convention)][1]


def _check_yorp_convention(convention):
    if not isinstance(convention, str) or convention not in YORP_CONVENTIONS:
        raise ValueError(f"YORP convention must be {' or '.join(map(repr, YORP_CONVENTIONS))} "
                         f"(got {show(convention)})")
    return convention


def _check_body(body):
    if body not in BODIES:
        raise ValueError(f"body must be 'primary' or 'secondary' (got {show(body)})")
    return body


def _check_radius_and_strength(p):
    """The fields every perturbation has: an optional radius (m) and the strength factor."""
    if p.radius is not None:
        require_positive_scalar("radius", p.radius, *RADIUS_RANGE, "m")
    require_positive_scalar("strength", p.strength, *STRENGTH_RANGE)


def body_radius(system, body, radius=None):
    """The radius a perturbation uses for ``body`` of ``system``, m: ``radius`` when given,
    else the body's volume-equivalent radius (a b c)^(1/3)."""
    if radius is not None:
        return float(radius)
    b = getattr(system, body)
    axes = getattr(b, "semi_axes", None)
    if axes is None:
        raise ValueError(f"the {body} is not an ellipsoid or sphere, so its radius is "
                         "undefined: pass radius= (m) to the perturbation")
    return float(np.prod(axes)) ** (1.0 / 3.0)


def _heliocentric(system, a_au, e):
    """(d in m, e_⊙) of the binary's heliocentric orbit: given to the perturbation, else the
    system's own (``BinarySystem.heliocentric_orbit``; never looked up by name)."""
    if a_au is None:
        orbit = getattr(system, "heliocentric_orbit", None)
        if orbit is None:
            raise ValueError(f"{system.name!r} has no heliocentric orbit: pass "
                             "heliocentric_a_au (AU) and heliocentric_e to YORP / BYORP, or "
                             "give the system heliocentric_orbit=(a_AU, e)")
        a_au, e = orbit
    return a_au * AU, (0.0 if e is None else e)


def _scales(system):
    """(mass, length, time) units of a member: m1 + m2 (kg), a (m), 1/n (s)."""
    return system.total_mass, system.a, 1.0 / system.mean_motion


def _constructor_radius(name, body, radius_m, system):
    """The radius (m) a k2 model of ``Tides.<name>`` uses: ``radius_m``, else ``body``'s
    in ``system``; one-line errors when neither is usable."""
    _check_body(body)
    if radius_m is not None:
        return require_positive_scalar("radius_m", radius_m, *RADIUS_RANGE, "m")
    if system is None:
        raise ValueError(f"Tides.{name} needs radius_m (m) or system= (a BinarySystem) for the "
                         f"{body}'s radius")
    if not isinstance(system, BinarySystem):
        raise TypeError(f"system must be a ti_spinorbit.BinarySystem (got {show(system)})")
    return body_radius(system, body)


@dataclass(frozen=True)
class Tides:
    """The tide raised on ``body`` by the other body, constant time lag or constant Q
    (Mignard 1979; Hut 1981; docs/physics.md §13.1).

    Parameters
    ----------
    body : {"secondary", "primary"}
        The body that deforms (and whose spin the tide brakes or drives).
    k2 : float, optional
        Love number, in (0, 10]. Default: the rubble-pile model of Goldreich & Sari (2009),
        k2 = 1e-5 R[km] (:meth:`rubble_pile`); :meth:`jacobson_scheeres` gives
        k2 = 2.5e-5 / R[km].
    time_lag : float or Quantity, optional
        Constant time lag Δt, s (> 0). Give this or ``Q``, not both.
    Q : float, optional
        Constant tidal quality factor (> 0): the lag angle is 1/(2Q) whatever the tidal
        frequency. Default when neither is given: Q = 100 (the paper's, docs/physics.md §9.4).
    radius : float or Quantity, optional
        The body's radius, m; default its volume-equivalent radius.
    strength : float
        Factor on the force and torque (default 1): 1e5 makes 1e5 years of tides act in one.
    """

    body: str = "secondary"
    k2: Optional[float] = None
    time_lag: Optional[float] = None
    Q: Optional[float] = None
    radius: Optional[float] = None
    strength: float = 1.0

    kind = "tides"

    def __post_init__(self):
        _plain_fields(self, k2="", time_lag="s", Q="", radius="m", strength="")
        _check_body(self.body)
        if self.k2 is not None:
            require_positive_scalar("k2", self.k2, *K2_RANGE)
        if self.time_lag is not None and self.Q is not None:
            raise ValueError("give the tide a time_lag (s) or a Q, not both")
        if self.time_lag is not None:
            require_positive_scalar("time_lag", self.time_lag, *TIME_LAG_RANGE, "s")
        if self.Q is not None:
            require_positive_scalar("Q", self.Q, *Q_RANGE)
        _check_radius_and_strength(self)

    @classmethod
    def rubble_pile(cls, body="secondary", radius_m=None, system=None, **kw):
        """Tides with the Goldreich & Sari (2009) rubble-pile k2 = 1e-5 R[km] of the body's
        radius (``radius_m``, or that of ``body`` in ``system``)."""
        R = _constructor_radius("rubble_pile", body, radius_m, system)
        return cls(body=body, k2=K2_MODELS["goldreich-sari"](R / 1e3), radius=radius_m, **kw)

    @classmethod
    def jacobson_scheeres(cls, body="secondary", radius_m=None, system=None, **kw):
        """Tides with the Jacobson & Scheeres (2011) k2 = 2.5e-5 / R[km]."""
        R = _constructor_radius("jacobson_scheeres", body, radius_m, system)
        return cls(body=body, k2=K2_MODELS["jacobson-scheeres"](R / 1e3), radius=radius_m,
                   **kw)

    def love_number(self, system):
        """k2 used for ``system`` (the rubble-pile default when none was given)."""
        if self.k2 is not None:
            return self.k2
        return K2_MODELS["goldreich-sari"](body_radius(system, self.body, self.radius) / 1e3)

    def coefficient(self, system):
        """κ = 3 k2 G M² R⁵ × strength, N m⁷ (force κ / r⁷ at zero lag), M the other body's
        mass."""
        other = system.secondary if self.body == "primary" else system.primary
        R = body_radius(system, self.body, self.radius)
        return 3.0 * self.love_number(system) * G * other.mass ** 2 * R ** 5 * self.strength

    def block(self, system):
        M, L, T = _scales(system)
        out = np.zeros(NPERT)
        col = Q_TIDE1 if self.body == "primary" else Q_TIDE2
        out[col] = self.coefficient(system) / (M * L ** 8 / T ** 2)
        if self.time_lag is not None:
            out[col + 1] = self.time_lag / T
        else:
            out[col + 2] = 0.5 / (self.Q if self.Q is not None else DEFAULT_Q)
        return out

    @property
    def slot(self):
        return ("tides", self.body)


@dataclass(frozen=True)
class YORP:
    """YORP torque on ``body`` about its spin (z) axis, the form Naidu & Margot (2015) use
    (docs/physics.md §13.2):

        T = f_Y R³ L_⊙ / (k c d² sqrt(1 − e_⊙²))    (N m),

    k = 6 by default (``convention="paper"``: the paper's δE_YORP is the work of T over two
    rotations per mutual orbit, 4πT) or k = 3 (``"one-turn"``: δE_YORP = 2πT, the torque
    twice as large, as the package had it before the choice existed). Positive
    ``coefficient`` f_Y spins the body up, negative spins it down.

    Parameters
    ----------
    body : {"secondary", "primary"}
    coefficient : float
        f_Y, signed, |f_Y| <= 1 (default 5e-4, the paper's).
    heliocentric_a_au, heliocentric_e : float or Quantity, optional
        The binary's heliocentric orbit (AU, and e in [0, 1)); default the catalogued one.
    radius : float or Quantity, optional
        The body's radius, m; default its volume-equivalent radius.
    strength : float
        Factor on the torque (default 1).
    convention : {"paper", "one-turn"}
        Which torque f_Y stands for (:data:`YORP_CONVENTIONS`; default ``"paper"``). Saved
        with the object; a saved YORP without it is read back as ``"one-turn"``.
    """

    body: str = "secondary"
    coefficient: float = DEFAULT_F_YORP
    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    radius: Optional[float] = None
    strength: float = 1.0
    convention: str = YORP_CONVENTION

    kind = "yorp"

    def __post_init__(self):
        _plain_fields(self, coefficient="", heliocentric_a_au="AU", heliocentric_e="",
                      radius="m", strength="")
        _check_body(self.body)
        _check_signed("YORP coefficient (f_Y)", self.coefficient, COEFFICIENT_LIMIT)
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        _check_radius_and_strength(self)
        _check_yorp_convention(self.convention)

    def torque(self, system):
        """T × strength, N m (signed), in this object's ``convention``."""
        d, e = _heliocentric(system, self.heliocentric_a_au, self.heliocentric_e)
        return yorp_torque(self.coefficient, body_radius(system, self.body, self.radius), d,
                           e, self.convention) * self.strength

    def energy_per_orbit(self, system):
        """The work of the torque over the convention's rotations per mutual orbit,
        2π × turns × T, J (signed): the paper's δE_YORP × strength in either convention
        (``analytic.yorp_energy_per_orbit`` with this body's radius)."""
        return 2.0 * math.pi * yorp_turns_per_orbit(self.convention) * self.torque(system)

    def block(self, system):
        M, L, T = _scales(system)
        out = np.zeros(NPERT)
        out[Q_YORP1 if self.body == "primary" else Q_YORP2] = self.torque(system) / (M * L ** 2 / T ** 2)
        return out

    @property
    def slot(self):
        return ("yorp", self.body)


@dataclass(frozen=True)
class BYORP:
    """Binary YORP: a force on the secondary along the relative velocity, the
    constant-coefficient form of McMahon & Scheeres (2010) and Jacobson & Scheeres (2011)
    (docs/physics.md §13.3):

        F_B = B F_⊙ R_s² / (d² sqrt(1 − e_⊙²)),     F_⊙ = L_⊙ / (4π c),

    so the relative motion accelerates by F_B / m_s along V/|V|; on a circular orbit
    da/dt = 2 F_B / (m_s n). Positive ``coefficient`` B expands the orbit.

    Parameters
    ----------
    coefficient : float
        B, signed, |B| <= 1 (default 1e-3, the order Jacobson & Scheeres 2011 use).
    heliocentric_a_au, heliocentric_e : float or Quantity, optional
        The binary's heliocentric orbit; default the catalogued one.
    radius : float or Quantity, optional
        The secondary's radius R_s, m; default its volume-equivalent radius.
    strength : float
        Factor on the force (default 1).
    """

    coefficient: float = 1e-3
    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    radius: Optional[float] = None
    strength: float = 1.0

    kind = "byorp"
    body = "secondary"

    def __post_init__(self):
        _plain_fields(self, coefficient="", heliocentric_a_au="AU", heliocentric_e="",
                      radius="m", strength="")
        _check_signed("BYORP coefficient (B)", self.coefficient, COEFFICIENT_LIMIT)
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        _check_radius_and_strength(self)

    def force(self, system):
        """F_B × strength, N (signed)."""
        d, e = _heliocentric(system, self.heliocentric_a_au, self.heliocentric_e)
        R = body_radius(system, "secondary", self.radius)
        return (self.coefficient * solar_radiation_constant() * R ** 2
                / (d ** 2 * math.sqrt(1.0 - e ** 2)) * self.strength)

    def acceleration(self, system):
        """F_B / m_s, m s⁻²: the relative motion's acceleration along V."""
        return self.force(system) / system.secondary.mass

    def block(self, system):
        M, L, T = _scales(system)
        out = np.zeros(NPERT)
        out[Q_BYORP] = self.acceleration(system) / (L / T ** 2)
        return out

    @property
    def slot(self):
        return ("byorp", "secondary")


@dataclass(frozen=True)
class SolarTide:
    """The Sun's tide: its differential (tidal) acceleration of the mutual orbit, exact (not
    only the quadrupole) and in a cancellation-free form, and its quadrupole
    gravity-gradient torque on both bodies (docs/physics.md §13.11). The Sun moves on the
    barycentre's heliocentric Kepler orbit, solved in the kernels at every stage.

    The orbit's angles are relative to the package's inertial frame, which for the standard
    start (docs/physics.md §6.4) is the mutual orbit's initial frame: x to the initial
    pericentre (the line of centres), z the initial orbit normal (a start given as an
    ``InitialState`` uses its own inertial frame). The defaults put the Sun in the mutual
    orbit plane (i = 0, Ω = ω = 0) with the barycentre at perihelion at t = 0 (M = 0), the
    Sun then on the −x axis.

    Parameters
    ----------
    heliocentric_a_au, heliocentric_e : float or Quantity, optional
        The barycentre's heliocentric semimajor axis (AU) and eccentricity; default the
        system's ``heliocentric_orbit``.
    inclination_deg : float or Quantity
        i, degrees in [0, 180] (default 0: the Sun in the mutual orbit plane).
    node_deg, periapsis_deg, mean_anomaly_deg : float or Quantity
        Ω, ω and the mean anomaly at t = 0, degrees in [−360, 360] (default 0).
    strength : float
        Factor on the Sun's mass in the force and torques (default 1); the Sun's motion
        keeps the real mass.
    """

    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    inclination_deg: float = 0.0
    node_deg: float = 0.0
    periapsis_deg: float = 0.0
    mean_anomaly_deg: float = 0.0
    strength: float = 1.0

    kind = "solar_tide"
    body = "both"
    radius = None

    def __post_init__(self):
        _plain_fields(self, heliocentric_a_au="AU", heliocentric_e="", inclination_deg="deg",
                      node_deg="deg", periapsis_deg="deg", mean_anomaly_deg="deg", strength="")
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        if self.heliocentric_e is not None and not self.heliocentric_e < 1.0:
            raise ValueError(f"heliocentric_e must be in [0, 1) (got {show(self.heliocentric_e)})")
        require_real("inclination_deg", self.inclination_deg)
        require_range("inclination_deg", self.inclination_deg, *INCLINATION_RANGE,
                      high_open=False)
        for name in ("node_deg", "periapsis_deg", "mean_anomaly_deg"):
            require_real(name, getattr(self, name))
            require_range(name, getattr(self, name), *ANGLE_RANGE, high_open=False)
        require_positive_scalar("strength", self.strength, *STRENGTH_RANGE)

    def orbit(self, system):
        """(a in m, e) of the barycentre's heliocentric orbit: given, else the system's."""
        a, e = _heliocentric(system, self.heliocentric_a_au, self.heliocentric_e)
        if not e < 1.0:
            raise ValueError(f"SolarTide needs a bound heliocentric orbit, e < 1 (got {e!r})")
        return a, e

    def directions(self):
        """(P, Q): unit vectors to the heliocentric perihelion and 90° ahead of it in the
        orbit's plane, in the inertial frame (rotation Rz(Ω) Rx(i) Rz(ω))."""
        i, O, w = (math.radians(x) for x in (self.inclination_deg, self.node_deg,
                                             self.periapsis_deg))
        cO, sO, ci, si, cw, sw = (math.cos(O), math.sin(O), math.cos(i), math.sin(i),
                                  math.cos(w), math.sin(w))
        if self.inclination_deg == 180.0:          # exactly in the plane, retrograde
            ci, si = -1.0, 0.0
        P = np.array([cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si])
        Q = np.array([-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si])
        return P, Q

    def mean_motion(self, system):
        """The heliocentric mean motion sqrt(G (M_⊙ + m1 + m2) / a³), rad s⁻¹."""
        a, _ = self.orbit(system)
        return math.sqrt((GM_SUN + G * system.total_mass) / a ** 3)

    def sun_position(self, system, t):
        """The Sun's position relative to the barycentre at time t (s), m, inertial frame
        (NumPy; the kernels solve the same Kepler equation)."""
        a, e = self.orbit(system)
        M = math.radians(self.mean_anomaly_deg) + self.mean_motion(system) * t
        E = M
        for _ in range(100):
            dE = (E - e * math.sin(E) - M) / (1.0 - e * math.cos(E))
            E -= dE
            if abs(dE) < 1e-15:
                break
        P, Q = self.directions()
        return -(a * (math.cos(E) - e) * P + a * math.sqrt(1.0 - e * e) * math.sin(E) * Q)

    def tide_ratio(self, system):
        """The Sun's tide over the mutual gravity, G M_⊙ r / d³ over G (m1 + m2) / r², at the
        mutual apoapsis r = a (1 + e) and the heliocentric perihelion d = a_⊙ (1 − e_⊙)."""
        a, e = self.orbit(system)
        r = system.a * (1.0 + system.e)
        return self.strength * GM_SUN * r ** 3 / (G * system.total_mass * (a * (1.0 - e)) ** 3)

    def block(self, system):
        M, L, T = _scales(system)
        a, e = self.orbit(system)
        P, Q = self.directions()
        out = np.zeros(NPERT)
        out[Q_SUN] = self.strength * GM_SUN / (L ** 3 / T ** 2)
        out[Q_SUN_A] = a / L
        out[Q_SUN_E] = e
        out[Q_SUN_N] = self.mean_motion(system) * T
        out[Q_SUN_M0] = math.radians(self.mean_anomaly_deg)
        out[Q_SUN_P:Q_SUN_P + 3] = P
        out[Q_SUN_Q:Q_SUN_Q + 3] = Q
        out[Q_SUN_NU] = system.secondary.mass / system.total_mass
        for col, body in ((Q_SUN_J1, system.primary), (Q_SUN_J2, system.secondary)):
            A, B, _ = body.moments         # J_xx − J_yy = I_yy − I_xx (principal frame)
            out[col] = (B - A) / (M * L ** 2)
        return out

    @property
    def in_plane(self):
        """Whether the Sun stays in the start's orbit plane (i = 0 or 180)."""
        return self.inclination_deg in (0.0, 180.0)

    @property
    def slot(self):
        return ("solar_tide", "both")


KINDS = {"tides": Tides, "yorp": YORP, "byorp": BYORP, "solar_tide": SolarTide}


def _check_signed(name, value, limit):
    require_real(name, value)
    require_range(name, value, -limit, limit, low_open=False, high_open=False)


def _check_heliocentric(a_au, e):
    check_heliocentric(a_au, e)


def check_perturbations(perturbations):
    """``perturbations`` (None, one object, or a sequence of Tides / YORP / BYORP / SolarTide) as a
    tuple; a TypeError names anything else, a ValueError a repeated kind on one body."""
    if perturbations is None:
        return ()
    if isinstance(perturbations, tuple(KINDS.values())):
        perturbations = [perturbations]
    try:
        items = tuple(perturbations)
    except TypeError:
        raise TypeError("perturbations must be a list of ti_spinorbit.Tides, YORP, BYORP or SolarTide "
                        f"objects (got {show(perturbations)})") from None
    seen = set()
    for k, p in enumerate(items):
        if not isinstance(p, tuple(KINDS.values())):
            raise TypeError(f"perturbations[{k}] must be a Tides, YORP, BYORP or SolarTide object "
                            f"(got {show(p)})")
        if p.slot in seen:
            raise ValueError(f"perturbations[{k}]: a second {p.kind}"
                             f"{'' if p.body == 'both' else ' on the ' + p.body}; combine "
                             "them into one (coefficients add)")
        seen.add(p.slot)
    return items


def _largest_moment(system, body):
    return float(np.max(getattr(system, body).moments))


def change_per_orbit(p, system):
    """How strongly ``p`` acts on ``system``: a list of (quantity, value, limit) with the
    value scaling linearly with ``p.strength``. Spins in units of n per orbit (the torque's
    largest value × 2π / (C n²), C the body's largest moment; a tide's lag taken at its
    largest, 1/(2Q) or Δt·n), the semimajor axis as a fraction per orbit (BYORP, 4π a_B /
    (n² a)), and the tide's conservative force κ / r_p⁷ over the mutual gravity G m₁ m₂ / r_p²
    at pericentre r_p = a (1 − e)."""
    n, rp = system.mean_motion, system.a * (1.0 - system.e)
    if isinstance(p, Tides):
        kappa = p.coefficient(system)
        lag = 0.5 / (p.Q if p.Q is not None else DEFAULT_Q) if p.time_lag is None \
            else min(1.0, p.time_lag * n)
        force = kappa / rp ** 5 / (G * system.primary.mass * system.secondary.mass)
        spin = 2.0 * math.pi * kappa * lag / (rp ** 6 * _largest_moment(system, p.body) * n ** 2)
        return [(f"the {p.body}'s spin", spin, SPIN_CHANGE_LIMIT, "n per orbit"),
                ("the tide's force over the mutual gravity at pericentre", force,
                 TIDE_FORCE_LIMIT, "")]
    if isinstance(p, SolarTide):
        return [("the Sun's tide over the mutual gravity at apoapsis and perihelion",
                 p.tide_ratio(system), SOLAR_TIDE_LIMIT, "")]
    if isinstance(p, YORP):
        spin = 2.0 * math.pi * abs(p.torque(system)) / (_largest_moment(system, p.body) * n ** 2)
        return [(f"the {p.body}'s spin", spin, SPIN_CHANGE_LIMIT, "n per orbit")]
    change = 4.0 * math.pi * abs(p.acceleration(system)) / (n ** 2 * system.a)
    return [("the semimajor axis", change, ORBIT_CHANGE_LIMIT, "of itself per orbit")]


def _check_strength(k, p, system):
    """ValueError when ``p`` (perturbations[k]) is too strong to be a perturbation of
    ``system`` (:func:`change_per_orbit`), naming the largest strength that is."""
    changes = change_per_orbit(p, system)
    largest = min(p.strength * limit / value if value > 0 else math.inf
                  for _, value, limit, _ in changes)
    for quantity, value, limit, unit_text in changes:
        if not value <= limit:
            amount = f"{value:.3g} {unit_text}".rstrip()
            what = f"make {quantity} {amount}" if not unit_text else \
                f"change {quantity} by {amount}"
            raise ValueError(
                f"perturbations[{k}] ({p.kind}{'' if p.body == 'both' else ' on the ' + p.body}"
                f", strength {p.strength:g}) would "
                f"{what} for {system.name!r}, above the limit {limit:g}: it would no longer be "
                f"a perturbation; use a strength of at most {largest:.3g}")


def perturbation_rows(systems, perturbations):
    """(N, NPERT) scaled blocks of the members' ``systems`` (one per member), or None
    without perturbations. A perturbation too strong to be one for a member's system
    (:func:`change_per_orbit` against :data:`SPIN_CHANGE_LIMIT`, :data:`ORBIT_CHANGE_LIMIT`,
    :data:`TIDE_FORCE_LIMIT`) is refused here, before any work (ValueError naming it and the
    largest strength allowed)."""
    items = check_perturbations(perturbations)
    if not items:
        return None
    rows = np.zeros((len(systems), NPERT))
    cache = {}
    for k, s in enumerate(systems):
        key = id(s)
        if key not in cache:
            for j, p in enumerate(items):
                _check_strength(j, p, s)
            cache[key] = sum((p.block(s) for p in items), np.zeros(NPERT))
        rows[k] = cache[key]
    return rows


def describe(perturbations):
    """JSON-ready list of dicts (``kind`` plus the fields) for saved files."""
    return [{"kind": p.kind, **asdict(p)} for p in check_perturbations(perturbations)]


def from_description(items):
    """The objects back from :func:`describe`'s list. A YORP entry without ``convention``
    (saved before the convention was recorded) gets :data:`YORP_LEGACY_CONVENTION`, the
    torque it was integrated with."""
    out = []
    for d in items or ():
        d = dict(d)
        kind = d.pop("kind")
        if kind not in KINDS:
            raise ValueError(f"unknown perturbation kind {kind!r} (known: {', '.join(KINDS)})")
        if kind == "yorp":           # written before the convention was recorded
            d.setdefault("convention", YORP_LEGACY_CONVENTION)
        out.append(KINDS[kind](**d))
    return tuple(out)


def needs_3d(perturbations):
    """Whether ``perturbations`` hold a force the planar model does not carry: the Sun's
    tide out of the start's orbit plane (``models.choose`` then takes the 3-D model)."""
    return any(isinstance(p, SolarTide) and not p.in_plane
               for p in check_perturbations(perturbations))


def out_of_plane_rows(rows):
    """Per member of the (N, NPERT) ``rows`` (or None): a Sun out of the orbit plane (its
    orbit's P or Q with a z component), which the planar model cannot carry."""
    if rows is None:
        return None
    rows = np.asarray(rows)
    return (rows[:, Q_SUN] != 0.0) & ((rows[:, Q_SUN_P + 2] != 0.0) | (rows[:, Q_SUN_Q + 2] != 0.0))
