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

from ..constants import (AU, C_LIGHT, DEFAULT_F_YORP, DEFAULT_Q, GM_SUN, K2_MODELS, L_SUN,
                         PLANETS)
from .._validate import HELIOCENTRIC_A_RANGE as _HELIOCENTRIC_A_RANGE
from .._validate import (check_heliocentric, require_positive_scalar, require_range, require_real,
                         show)
from ..layout import perturbation as _layout
from ..system.heliocentric import (ANGLE_RANGE, INCLINATION_RANGE, HeliocentricOrbit, check_angle,
                                   conic_position, orbit_directions)
from ..system.systems import BinarySystem, G
from ..units import plain_fields as _plain_fields
from ..units import to_plain as _to_plain

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
Q_FLYBY, THIRD_BODIES, Q_RAD = _layout.Q_FLYBY, _layout.THIRD_BODIES, _layout.Q_RAD
T_MU, T_A, T_E, T_N, T_M0, T_P, T_Q, T_NU, T_J1, T_J2 = (
    _layout.T_MU, _layout.T_A, _layout.T_E, _layout.T_N, _layout.T_M0, _layout.T_P, _layout.T_Q,
    _layout.T_NU, _layout.T_J1, _layout.T_J2)
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
# Angles of the heliocentric orbit (INCLINATION_RANGE, ANGLE_RANGE): system/heliocentric.py
HELIOCENTRIC_A_RANGE = _HELIOCENTRIC_A_RANGE   # AU (ti_spinorbit._validate)
#: YORP torque conventions: name -> (k, turns). The torque is T = f_Y R³ L_⊙ /
#: (k c d² sqrt(1 − e_⊙²)) and ``turns`` the rotations of the body per mutual orbit whose
#: work 2π turns T is the paper's δE_YORP (docs/physics.md §13.2).
YORP_CONVENTIONS = {"paper": (6.0, 2), "one-turn": (3.0, 1)}
#: The default convention: the torque of Naidu & Margot's prose (two rotations per orbit).
YORP_CONVENTION = "paper"
#: The convention of a saved YORP that records none (written before the choice existed).
YORP_LEGACY_CONVENTION = "one-turn"
#: Where YORP and BYORP take the Sun's distance: on the heliocentric orbit at every step, or
#: its mean-distance form (docs/physics.md §13.12); the default, and that of a saved object
#: written before the choice existed.
DISTANCES = ("orbit", "mean")
DISTANCE = "orbit"
DISTANCE_LEGACY = "mean"
#: Unit text of a result's ``perturbations`` field (saved as their descriptions).
UNIT = ("objects: Tides / YORP / BYORP / SolarTide / Flyby with SI parameters "
        "(ti_spinorbit.model.perturbations)")


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
                             "give the system heliocentric_orbit=HeliocentricOrbit(a_AU, e, ...)")
        a_au, e = orbit.a_au, orbit.e
    return a_au * AU, (0.0 if e is None else e)


def _scales(system):
    """(mass, length, time) units of a member: m1 + m2 (kg), a (m), 1/n (s)."""
    return system.total_mass, system.a, 1.0 / system.mean_motion


def _check_distance(distance):
    if distance not in DISTANCES:
        raise ValueError(f"distance must be one of {', '.join(DISTANCES)} (got {show(distance)}): "
                         "'orbit' for the Sun's distance of the moment, 'mean' for the "
                         "mean-distance form")


def _conic_columns(out, c, a, e, n, M0, L, T):
    """The conic of the third-body slot at column ``c`` of ``out``: a/L (a in m), e, n T (n in
    rad/s), M0 (rad). The Sun slot's are read by the Sun's tide and by YORP/BYORP alike."""
    out[c + T_A] = a / L
    out[c + T_E] = e
    out[c + T_N] = n * T
    out[c + T_M0] = M0


def _sun_mean_motion(system, a):
    """The heliocentric mean motion sqrt(G (M_⊙ + m1 + m2) / a³), rad s⁻¹, a in m."""
    return math.sqrt((GM_SUN + G * system.total_mass) / a ** 3)


def _third_body_block(system, c, gm, a, e, n, M0, P, Q):
    """A block holding one third body in its slot at column ``c``: μ = ``gm`` (m³ s⁻²,
    strength included), its conic (a in m, e, n in rad/s, M0 rad, the body at x P + y Q),
    ν = m2 / (m1 + m2) and each body's J_xx − J_yy = B − A, scaled."""
    M, L, T = _scales(system)
    out = np.zeros(NPERT)
    out[c + T_MU] = gm / (L ** 3 / T ** 2)
    _conic_columns(out, c, a, e, n, M0, L, T)
    out[c + T_P:c + T_P + 3] = P
    out[c + T_Q:c + T_Q + 3] = Q
    out[c + T_NU] = system.secondary.mass / system.total_mass
    for col, body in ((c + T_J1, system.primary), (c + T_J2, system.secondary)):
        A, B, _ = body.moments         # J_xx − J_yy = I_yy − I_xx (principal frame)
        out[col] = (B - A) / (M * L ** 2)
    return out


def _radiation_orbit(p, system):
    """A block with the Sun's orbit and the distance factor a⊙² sqrt(1 − e⊙²) / L² of a YORP
    or BYORP ``p`` with ``distance="orbit"`` (zeros for ``"mean"``)."""
    out = np.zeros(NPERT)
    if p.distance == "orbit":
        _, L, T = _scales(system)
        a, e = _heliocentric(system, p.heliocentric_a_au, p.heliocentric_e)
        orbit = getattr(system, "heliocentric_orbit", None)
        M0 = math.radians(orbit.mean_anomaly_deg) if (
            p.heliocentric_a_au is None and orbit is not None) else 0.0
        _conic_columns(out, Q_SUN, a, e, _sun_mean_motion(system, a), M0, L, T)
        out[Q_RAD] = (a / L) ** 2 * math.sqrt(1.0 - e * e)
    return out


#: Columns of a block that describe one thing (the Sun's orbit, the distance factor): several
#: perturbations may set them, to the same values, and they are not summed.
SHARED_COLUMNS = (Q_SUN_A, Q_SUN_E, Q_SUN_N, Q_SUN_M0, Q_RAD)


def _combine(blocks, names):
    """The sum of ``blocks``, except the shared columns: set once, and a ValueError when two
    perturbations (``names``) give them different values (two heliocentric orbits)."""
    out = np.zeros(NPERT)
    shared = list(SHARED_COLUMNS)
    owner = {}
    for block, name in zip(blocks, names):
        for c in shared:
            if block[c] != 0.0:
                if out[c] != 0.0 and not math.isclose(out[c], block[c], rel_tol=1e-12):
                    raise ValueError(f"{owner[c]} and {name} are on different heliocentric "
                                     "orbits: give them the same one (the system's, or the "
                                     "same heliocentric_a_au and heliocentric_e)")
                out[c], owner[c] = block[c], name
        rest = block.copy()
        rest[shared] = 0.0
        out += rest
    return out


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

    See Also
    --------
    YORP, BYORP, SolarTide
    ti_spinorbit.analytic.tidal_despin_rate : the decoupled despin rate

    References
    ----------
    * Mignard, F. 1979, The evolution of the lunar orbit revisited. I, Moon and Planets
      20:301.
    * Hut, P. 1981, Tidal evolution in close binary systems, A&A 99:126.

    Examples
    --------
    A tide on the secondary, 600 s time lag, made a million times stronger so that it acts in
    a few orbits:

    >>> tide = tso.Tides(body="secondary", k2=1e-5, time_lag=600.0, strength=1e6)
    >>> ts = tso.time_series("1991 VH", 0.0, [1.70], orbits=2, samples_per_orbit=16,
    ...                      perturbations=[tide])
    >>> ts.work.shape                                      # J done by the tide, per sample
    (1, 32)
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
    distance : {"orbit", "mean"}
        ``"orbit"`` (default): the torque at the Sun's distance d(t) of the moment, on the
        heliocentric orbit, T (a⊙² sqrt(1 − e⊙²)) / d(t)², whose orbit average is T;
        ``"mean"``: T at all times (the paper's form). A saved YORP without it is read back
        as ``"mean"``, the torque it was run with.

    See Also
    --------
    Tides, BYORP

    Examples
    --------
    >>> yorp = tso.YORP(coefficient=5e-4)                  # f_Y, on the secondary
    >>> yorp.body, yorp.convention
    ('secondary', 'paper')
    """

    body: str = "secondary"
    coefficient: float = DEFAULT_F_YORP
    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    radius: Optional[float] = None
    strength: float = 1.0
    convention: str = YORP_CONVENTION
    distance: str = DISTANCE

    kind = "yorp"

    def __post_init__(self):
        _plain_fields(self, coefficient="", heliocentric_a_au="AU", heliocentric_e="",
                      radius="m", strength="")
        _check_body(self.body)
        _check_signed("YORP coefficient (f_Y)", self.coefficient, COEFFICIENT_LIMIT)
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        _check_radius_and_strength(self)
        _check_yorp_convention(self.convention)
        _check_distance(self.distance)

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
        out = _radiation_orbit(self, system)
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
    distance : {"orbit", "mean"}
        As for :class:`YORP`: the force at the Sun's distance of the moment (default), or
        its mean-distance value at all times.

    See Also
    --------
    Tides, YORP

    Examples
    --------
    >>> byorp = tso.BYORP(coefficient=1e-3)
    >>> byorp.strength
    1.0
    """

    coefficient: float = 1e-3
    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    radius: Optional[float] = None
    strength: float = 1.0
    distance: str = DISTANCE

    kind = "byorp"
    body = "secondary"

    def __post_init__(self):
        _plain_fields(self, coefficient="", heliocentric_a_au="AU", heliocentric_e="",
                      radius="m", strength="")
        _check_signed("BYORP coefficient (B)", self.coefficient, COEFFICIENT_LIMIT)
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        _check_radius_and_strength(self)
        _check_distance(self.distance)

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
        out = _radiation_orbit(self, system)
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

    By default the orbit is the system's own ``heliocentric_orbit`` (a
    :class:`~ti_spinorbit.HeliocentricOrbit`: all six elements, relative to the binary or to
    the ecliptic with the binary's pole). Any orbit field given here replaces it: the fields
    left out then take the system's a and e and zero angles, relative to the package's
    inertial frame, which for the standard start (docs/physics.md §6.4) is the mutual orbit's
    initial frame: x to the initial pericentre (the line of centres), z the initial orbit
    normal (a start given as an ``InitialState`` uses its own inertial frame). Zero angles
    put the Sun in the mutual orbit plane (i = 0, Ω = ω = 0) with the barycentre at
    perihelion at t = 0 (M = 0), the Sun then on the −x axis.

    Parameters
    ----------
    heliocentric_a_au, heliocentric_e : float or Quantity, optional
        The barycentre's heliocentric semimajor axis (AU) and eccentricity.
    inclination_deg : float or Quantity, optional
        i, degrees in [0, 180].
    node_deg, periapsis_deg, mean_anomaly_deg : float or Quantity, optional
        Ω, ω and the mean anomaly at t = 0, degrees in [−360, 360].
    strength : float
        Factor on the Sun's mass in the force and torques (default 1); the Sun's motion
        keeps the real mass.

    See Also
    --------
    HeliocentricOrbit : the orbit it takes by default
    Flyby : a planet passing by

    Examples
    --------
    The Sun's tide on 1991 VH, on the system's own heliocentric orbit:

    >>> sun = tso.SolarTide()
    >>> sun.inclination_deg is None                        # from the system's orbit
    True
    """

    heliocentric_a_au: Optional[float] = None
    heliocentric_e: Optional[float] = None
    inclination_deg: Optional[float] = None
    node_deg: Optional[float] = None
    periapsis_deg: Optional[float] = None
    mean_anomaly_deg: Optional[float] = None
    strength: float = 1.0

    kind = "solar_tide"
    body = "both"
    radius = None
    ANGLES = ("inclination_deg", "node_deg", "periapsis_deg", "mean_anomaly_deg")

    def __post_init__(self):
        _plain_fields(self, heliocentric_a_au="AU", heliocentric_e="", inclination_deg="deg",
                      node_deg="deg", periapsis_deg="deg", mean_anomaly_deg="deg", strength="")
        _check_heliocentric(self.heliocentric_a_au, self.heliocentric_e)
        if self.heliocentric_e is not None and not self.heliocentric_e < 1.0:
            raise ValueError(f"heliocentric_e must be in [0, 1) (got {show(self.heliocentric_e)})")
        for name in self.ANGLES:
            if getattr(self, name) is not None:
                check_angle(name, getattr(self, name),
                            INCLINATION_RANGE if name == "inclination_deg" else ANGLE_RANGE)
        require_positive_scalar("strength", self.strength, *STRENGTH_RANGE)

    @property
    def own_orbit(self):
        """Whether this object gives (part of) the orbit itself, replacing the system's."""
        return self.heliocentric_a_au is not None or any(
            getattr(self, name) is not None for name in self.ANGLES)

    def heliocentric(self, system):
        """The :class:`~ti_spinorbit.HeliocentricOrbit` the Sun moves on for ``system``."""
        if not self.own_orbit:
            orbit = getattr(system, "heliocentric_orbit", None)
            if orbit is None:
                raise ValueError(f"{system.name!r} has no heliocentric orbit: give the system "
                                 "heliocentric_orbit=HeliocentricOrbit(a_AU, e, ...), or "
                                 "SolarTide(heliocentric_a_au=..., heliocentric_e=...)")
            return orbit
        a_au, e = self.heliocentric_a_au, self.heliocentric_e
        if a_au is None:
            orbit = getattr(system, "heliocentric_orbit", None)
            if orbit is None:
                raise ValueError(f"{system.name!r} has no heliocentric orbit: pass "
                                 "heliocentric_a_au (AU) and heliocentric_e to SolarTide")
            a_au, e = orbit.a_au, orbit.e
        return HeliocentricOrbit(a_au, e, **{name: getattr(self, name) or 0.0
                                             for name in self.ANGLES})

    def orbit(self, system):
        """(a in m, e) of the barycentre's heliocentric orbit."""
        orbit = self.heliocentric(system)
        if not orbit.e < 1.0:
            raise ValueError(f"SolarTide needs a bound heliocentric orbit, e < 1 (got {orbit.e!r})")
        return orbit.a_au * AU, orbit.e

    def directions(self, system=None):
        """(P, Q): unit vectors to the heliocentric perihelion and 90° ahead of it in the
        orbit's plane, in the inertial frame (rotation Rz(Ω) Rx(i) Rz(ω); from the ecliptic
        with the binary's pole for a system's ecliptic orbit). ``system`` may be left out
        when this object gives the orbit's angles itself."""
        if system is None and not self.own_orbit:
            raise ValueError("the Sun's direction comes from the system's heliocentric orbit: "
                             "pass the system")
        if system is None:
            return orbit_directions(*(getattr(self, name) or 0.0 for name in self.ANGLES[:3]))
        return self.heliocentric(system).directions()

    def mean_motion(self, system):
        """The heliocentric mean motion sqrt(G (M_⊙ + m1 + m2) / a³), rad s⁻¹."""
        a, _ = self.orbit(system)
        return _sun_mean_motion(system, a)

    def sun_position(self, system, t):
        """The Sun's position relative to the barycentre at time t (s), m, inertial frame
        (NumPy; the kernels solve the same Kepler equation)."""
        a, e = self.orbit(system)
        M = math.radians(self.heliocentric(system).mean_anomaly_deg) + self.mean_motion(system) * t
        return -conic_position(a, e, M, *self.directions(system))

    def tide_ratio(self, system):
        """The Sun's tide over the mutual gravity, G M_⊙ r / d³ over G (m1 + m2) / r², at the
        mutual apoapsis r = a (1 + e) and the heliocentric perihelion d = a_⊙ (1 − e_⊙)."""
        a, e = self.orbit(system)
        r = system.a * (1.0 + system.e)
        return self.strength * GM_SUN * r ** 3 / (G * system.total_mass * (a * (1.0 - e)) ** 3)

    def block(self, system):
        a, e = self.orbit(system)
        P, Q = self.directions(system)
        M0 = math.radians(self.heliocentric(system).mean_anomaly_deg)
        # the kernels put a third body at +(x P + y Q) of its conic: the Sun is at minus the
        # barycentre's heliocentric position
        return _third_body_block(system, Q_SUN, self.strength * GM_SUN, a, e,
                                 _sun_mean_motion(system, a), M0, -P, -Q)

    def in_plane(self, system=None):
        """Whether the Sun stays in the start's orbit plane (its orbit's P and Q without a z
        component). Without ``system``, for an orbit the system gives: False (unknown)."""
        if system is None and not self.own_orbit:
            return False
        P, Q = self.directions(system)
        return P[2] == 0.0 and Q[2] == 0.0

    @property
    def slot(self):
        return ("solar_tide", "both")


def _per_member(name, value, low, high, unit=""):
    """A Flyby field as a tuple of floats (one value, or one per member), each finite and in
    [low, high]; ValueError naming the field and the range."""
    value = _to_plain(name, value, unit)
    values = np.atleast_1d(np.asarray(value, dtype=object))
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"{name} must be a number or a 1-D sequence of numbers, one per member "
                         f"(got {show(value)})")
    out = []
    for v in values:
        require_real(name, v)
        require_range(name, v, low, high, low_open=False, high_open=False)
        out.append(float(v))
    return tuple(out)


@dataclass(frozen=True)
class Flyby:
    """A planet passing the binary on a hyperbola relative to its barycentre: its tidal
    acceleration of the mutual orbit and its quadrupole torques on both bodies, the same
    terms as the Sun's (docs/physics.md §13.12). The planet's hyperbola is that of the
    two-body problem planet–barycentre (μ = G (M + m1 + m2)); the binary does not deflect it.

    Every orbit field may be one number or a sequence with one value per member of the
    ensemble (member k takes element k), so that an ensemble over q, orientation and time
    runs in one launch, one flyby per member.

    Parameters
    ----------
    planet : {"Earth", "Venus", "Mars", "Moon"}, optional
        The passing body, by name (``constants.PLANETS``: GM and radius); default Earth,
        unless ``mass_kg`` is given.
    v_inf_km_s : float, sequence or Quantity
        Speed at infinity relative to the barycentre, km/s in [0.01, 100].
    q_km : float, sequence or Quantity
        Closest distance of the planet from the barycentre, km in [1, 1e9]; at least the
        named planet's radius (closer, the binary hits it).
    inclination_deg, node_deg, periapsis_deg : float, sequence or Quantity
        Orientation of the hyperbola relative to the package's inertial frame (the mutual
        orbit's initial frame for the standard start): i in [0, 180] and Ω, ω in
        [−360, 360] degrees, as for :class:`SolarTide`; ω places the planet's closest
        approach within the hyperbola's plane (default 0: in the mutual orbit plane, along
        the initial line of centres).
    t_closest_h : float, sequence or Quantity
        Time of closest approach after t = 0, hours in [−1e6, 1e6] (negative: before the
        start, the planet receding).
    mass_kg : float, optional
        The passing body's mass, kg, instead of ``planet`` (no radius check then).
    strength : float
        Factor on the planet's mass in the force and torques (default 1); its motion keeps
        the real mass.

    See Also
    --------
    SolarTide

    Examples
    --------
    Earth passing at 200 000 km and 4 km/s:

    >>> earth = tso.Flyby("Earth", v_inf_km_s=4.0, q_km=2e5)
    >>> earth.planet, earth.q_km
    ('Earth', 200000.0)
    """

    planet: Optional[str] = None
    v_inf_km_s: object = 10.0
    q_km: object = 1e5
    inclination_deg: object = 0.0
    node_deg: object = 0.0
    periapsis_deg: object = 0.0
    t_closest_h: object = 0.0
    mass_kg: Optional[float] = None
    strength: float = 1.0

    kind = "flyby"
    body = "both"
    radius = None
    FIELDS = ("v_inf_km_s", "q_km", "inclination_deg", "node_deg", "periapsis_deg",
              "t_closest_h")

    def __post_init__(self):
        if self.planet is None and self.mass_kg is None:
            object.__setattr__(self, "planet", "Earth")
        if self.planet is not None and self.mass_kg is not None:
            raise ValueError("Flyby takes planet= (one of " + ", ".join(PLANETS) +
                             ") or mass_kg=, not both")
        if self.planet is not None and self.planet not in PLANETS:
            raise ValueError(f"Flyby planet must be one of {', '.join(PLANETS)} (got "
                             f"{show(self.planet)}), or give mass_kg=")
        if self.mass_kg is not None:
            object.__setattr__(self, "mass_kg", require_positive_scalar(
                "mass_kg", self.mass_kg, 1e3, 1e31, "kg"))
        ranges = {"v_inf_km_s": (0.01, 100.0, "km/s"), "q_km": (1.0, 1e9, "km"),
                  "inclination_deg": (*INCLINATION_RANGE, "deg"),
                  "node_deg": (*ANGLE_RANGE, "deg"), "periapsis_deg": (*ANGLE_RANGE, "deg"),
                  "t_closest_h": (-1e6, 1e6, "h")}
        sizes = set()
        for name in self.FIELDS:
            values = _per_member(name, getattr(self, name), *ranges[name])
            object.__setattr__(self, name, values[0] if len(values) == 1 else values)
            if len(values) > 1:
                sizes.add(len(values))
        if len(sizes) > 1:
            raise ValueError("Flyby fields given per member must all have the same length "
                             f"(got lengths {sorted(sizes)})")
        if self.planet is not None:
            radius = PLANETS[self.planet][1]
            closest = min(np.atleast_1d(self.q_km))
            if closest < radius:
                raise ValueError(f"q_km must be at least {self.planet}'s radius {radius:g} km "
                                 f"(got {closest:g} km: the binary would hit it)")
        require_positive_scalar("strength", self.strength, *STRENGTH_RANGE)

    @property
    def members(self):
        """How many members the per-member fields are for (1: one flyby for all)."""
        return max(np.size(getattr(self, name)) for name in self.FIELDS)

    def field(self, name, k=0):
        """Field ``name`` for member ``k``."""
        value = getattr(self, name)
        return value[k] if isinstance(value, tuple) else value

    @property
    def gm(self):
        """G M of the passing body, m³ s⁻²."""
        return PLANETS[self.planet][0] if self.planet is not None else G * self.mass_kg

    def hyperbola(self, system, k=0):
        """(a in m, e, mean motion in rad/s, mean anomaly at t = 0 in rad) of member ``k``'s
        hyperbola: a = μ / v∞², e = 1 + q v∞² / μ, n = sqrt(μ / a³), M(0) = −n t_closest."""
        mu = self.gm + G * system.total_mass
        v = self.field("v_inf_km_s", k) * 1e3
        a = mu / v ** 2
        e = 1.0 + self.field("q_km", k) * 1e3 * v ** 2 / mu
        n = math.sqrt(mu / a ** 3)
        return a, e, n, -n * self.field("t_closest_h", k) * 3600.0

    def directions(self, k=0):
        """(P, Q) of member ``k``'s hyperbola: to the closest approach, and the planet's
        direction of motion there, inertial frame."""
        return orbit_directions(*(self.field(name, k) for name in
                                  ("inclination_deg", "node_deg", "periapsis_deg")))

    def position(self, system, t, k=0):
        """The planet's position relative to the barycentre at time t (s), m, inertial frame
        (NumPy; the kernels solve the same hyperbolic Kepler equation)."""
        a, e, n, M0 = self.hyperbola(system, k)
        return conic_position(a, e, M0 + n * t, *self.directions(k))

    def in_plane(self, system=None):
        """Whether every member's planet stays in the start's orbit plane."""
        return all(p[2] == 0.0 and q[2] == 0.0 for p, q in
                   (self.directions(k) for k in range(self.members)))

    def tide_ratio(self, system, k=0):
        """The planet's tide over the mutual gravity at closest approach and the mutual
        apoapsis, G M r / q³ over G (m1 + m2) / r²."""
        r = system.a * (1.0 + system.e)
        q = self.field("q_km", k) * 1e3
        return self.strength * self.gm * r ** 3 / (G * system.total_mass * q ** 3)

    def block(self, system, k=0):
        # the planet at +(x P + y Q) of its hyperbola
        return _third_body_block(system, Q_FLYBY, self.strength * self.gm,
                                 *self.hyperbola(system, k), *self.directions(k))

    @property
    def slot(self):
        return ("flyby", "both")


KINDS = {"tides": Tides, "yorp": YORP, "byorp": BYORP, "solar_tide": SolarTide, "flyby": Flyby}


def _check_signed(name, value, limit):
    require_real(name, value)
    require_range(name, value, -limit, limit, low_open=False, high_open=False)


def _check_heliocentric(a_au, e):
    check_heliocentric(a_au, e)


def check_perturbations(perturbations):
    """``perturbations`` (None, one object, or a sequence of Tides / YORP / BYORP / SolarTide /
    Flyby) as a tuple; a TypeError names anything else, a ValueError a repeated kind on one
    body."""
    if perturbations is None:
        return ()
    if isinstance(perturbations, tuple(KINDS.values())):
        perturbations = [perturbations]
    try:
        items = tuple(perturbations)
    except TypeError:
        raise TypeError("perturbations must be a list of ti_spinorbit.Tides, YORP, BYORP, "
                        f"SolarTide or Flyby objects (got {show(perturbations)})") from None
    seen = set()
    for k, p in enumerate(items):
        if not isinstance(p, tuple(KINDS.values())):
            raise TypeError(f"perturbations[{k}] must be a Tides, YORP, BYORP, SolarTide or "
                            f"Flyby object (got {show(p)})")
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
    if isinstance(p, Flyby):     # a close flyby may be the dynamics: it can split a binary
        return []
    if isinstance(p, YORP):
        spin = 2.0 * math.pi * abs(p.torque(system)) / (_largest_moment(system, p.body) * n ** 2)
        return [(f"the {p.body}'s spin", spin, SPIN_CHANGE_LIMIT, "n per orbit")]
    change = 4.0 * math.pi * abs(p.acceleration(system)) / (n ** 2 * system.a)
    return [("the semimajor axis", change, ORBIT_CHANGE_LIMIT, "of itself per orbit")]


def _check_strength(k, p, system):
    """ValueError when ``p`` (perturbations[k]) is too strong to be a perturbation of
    ``system`` (:func:`change_per_orbit`), naming the largest strength that is."""
    changes = change_per_orbit(p, system)
    if not changes:
        return
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
    (:func:`change_per_orbit` against :data:`SPIN_CHANGE_LIMIT`, ``ORBIT_CHANGE_LIMIT``,
    ``TIDE_FORCE_LIMIT``) is refused here, before any work (ValueError naming it and the
    largest strength allowed)."""
    items = check_perturbations(perturbations)
    if not items:
        return None
    rows = np.zeros((len(systems), NPERT))
    shared = [p for p in items if not isinstance(p, Flyby)]
    flybys = [p for p in items if isinstance(p, Flyby)]
    for p in flybys:
        if p.members not in (1, len(systems)):
            raise ValueError(f"Flyby fields are given for {p.members} members, but the ensemble "
                             f"has {len(systems)}: give one value, or one per member")
    cache = {}
    for k, s in enumerate(systems):
        key = id(s)
        if key not in cache:
            for j, p in enumerate(items):
                _check_strength(j, p, s)
            cache[key] = _combine([p.block(s) for p in shared],
                                  [f"perturbations[{items.index(p)}] ({p.kind})" for p in shared])
        rows[k] = cache[key]
        for p in flybys:        # one flyby per member
            rows[k] += p.block(s, k if p.members > 1 else 0)
    return rows


def describe(perturbations):
    """JSON-ready list of dicts (``kind`` plus the fields) for saved files."""
    return [{"kind": p.kind, **{k: list(v) if isinstance(v, tuple) else v
                                for k, v in asdict(p).items()}}
            for p in check_perturbations(perturbations)]


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
        if kind in ("yorp", "byorp"):    # written before the distance was recorded
            d.setdefault("distance", DISTANCE_LEGACY)
        out.append(KINDS[kind](**d))
    return tuple(out)


def needs_3d(perturbations, systems=None):
    """Whether ``perturbations`` hold a force the planar model does not carry: the Sun's
    tide out of the start's orbit plane (``models.choose`` then takes the 3-D model), for
    any of ``systems`` (a BinarySystem or a list; None: a Sun on the system's own orbit
    counts as out of the plane, as for a memory estimate)."""
    items = check_perturbations(perturbations)
    if systems is not None and not isinstance(systems, (list, tuple)):
        systems = [systems]
    unique = list({id(s): s for s in systems}.values()) if systems is not None else [None]
    return any(isinstance(p, (SolarTide, Flyby)) and not p.in_plane(s)
               for p in items for s in unique)


def out_of_plane_rows(rows):
    """Per member of the (N, NPERT) ``rows`` (or None): a third body (the Sun, a passing
    planet) out of the orbit plane (its orbit's P or Q with a z component), which the planar
    model cannot carry."""
    if rows is None:
        return None
    rows = np.asarray(rows)
    return np.logical_or.reduce([(rows[:, c + T_MU] != 0.0) & ((rows[:, c + T_P + 2] != 0.0) |
                                                              (rows[:, c + T_Q + 2] != 0.0))
                                 for c in THIRD_BODIES])
