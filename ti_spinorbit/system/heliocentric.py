"""The binary's heliocentric orbit, and conic orbits of third bodies relative to the binary.

:class:`HeliocentricOrbit` is a field of :class:`~ti_spinorbit.BinarySystem`
(``heliocentric_orbit=``): the Keplerian elements of the binary's barycentre about the Sun.
YORP and BYORP read the Sun's distance from it, and :class:`~ti_spinorbit.SolarTide` the
Sun's direction as well (docs/physics.md §13.11).

Frames (decisions):

* ``frame="binary"`` (default): the angles are relative to the package's inertial frame,
  which for the standard start (docs/physics.md §6.4) is the mutual orbit's initial frame:
  x to the initial line of centres (the pericentre), z along the initial orbit normal. The
  defaults i = Ω = ω = 0 put the Sun in the mutual orbit plane.
* ``frame="ecliptic"``: the angles are the usual heliocentric elements (ecliptic and
  equinox J2000, as the JPL Small-Body Database lists them), and the binary's orientation is
  given by ``pole`` = (λ, β), the ecliptic longitude and latitude of the mutual orbit's
  normal, and ``binary_periapsis_deg``, the angle in the mutual orbit plane from its
  ascending node on the ecliptic to the initial line of centres (unknown for most systems;
  default 0). Without ``pole`` the orbit still gives the Sun's distance (YORP, BYORP), but
  not its direction: a SolarTide then asks for the pole.
* The mean anomaly at t = 0 defaults to 0 (the barycentre at perihelion). A run's t = 0 is
  not a date, so the catalogue gives no epoch; set ``mean_anomaly_deg`` for the season.

:func:`conic_position` is the NumPy twin of the kernels' Kepler solution
(``kernels/perturb.py``), elliptic and hyperbolic, used by the tests and by
:class:`~ti_spinorbit.Flyby`. Importing this module does not import Taichi.
"""

import math
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from .._validate import (HELIOCENTRIC_A_RANGE, require_positive_scalar, require_range, require_real,
                         require_scalar, show)

#: Angles of an orbit, degrees (closed): inclinations in [0, 180], the others in [-360, 360].
INCLINATION_RANGE = (0.0, 180.0)
ANGLE_RANGE = (-360.0, 360.0)
#: Ecliptic latitude of a pole, degrees (closed).
LATITUDE_RANGE = (-90.0, 90.0)
FRAMES = ("binary", "ecliptic")


def check_angle(name, value, limits=ANGLE_RANGE):
    """``value`` (degrees) as a float, finite and within ``limits`` (closed), or ValueError
    naming ``name`` and the range."""
    return require_scalar(name, value, *limits, unit="deg")


def orbit_directions(inclination_deg, node_deg, periapsis_deg):
    """(P, Q): unit vectors to the pericentre and 90° ahead of it in the orbit's plane, in
    the frame the angles refer to (rotation Rz(Ω) Rx(i) Rz(ω))."""
    i, O, w = (math.radians(x) for x in (inclination_deg, node_deg, periapsis_deg))
    cO, sO, ci, si, cw, sw = (math.cos(O), math.sin(O), math.cos(i), math.sin(i),
                              math.cos(w), math.sin(w))
    if inclination_deg == 180.0:          # exactly in the plane, retrograde
        ci, si = -1.0, 0.0
    P = np.array([cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si])
    Q = np.array([-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si])
    return P, Q


def ecliptic_to_binary(pole, binary_periapsis_deg=0.0):
    """The rotation matrix (rows: the binary frame's x, y, z in ecliptic coordinates) from
    the ecliptic to the binary's frame of a mutual orbit whose normal has ecliptic longitude
    and latitude ``pole`` = (λ, β) degrees, x at ``binary_periapsis_deg`` from the ascending
    node of the mutual orbit on the ecliptic (the node is the ecliptic x axis when the pole
    is the ecliptic's)."""
    lam, beta = (math.radians(x) for x in pole)
    z = np.array([math.cos(beta) * math.cos(lam), math.cos(beta) * math.sin(lam), math.sin(beta)])
    node = np.cross([0.0, 0.0, 1.0], z)
    size = np.linalg.norm(node)
    node = np.array([1.0, 0.0, 0.0]) if size < 1e-12 else node / size
    w = math.radians(binary_periapsis_deg)
    x = math.cos(w) * node + math.sin(w) * np.cross(z, node)
    return np.array([x, np.cross(z, x), z])


def solve_kepler(M, e):
    """The eccentric (e < 1) or hyperbolic (e > 1) anomaly of mean anomaly ``M`` (rad), by
    Newton's method to round-off from Danby's starts (the kernels' algorithm)."""
    if e < 1.0:
        M = M - 2.0 * math.pi * math.floor(M / (2.0 * math.pi) + 0.5)
        E = M + math.copysign(0.85, M) * e
        for _ in range(60):
            dE = (E - e * math.sin(E) - M) / (1.0 - e * math.cos(E))
            E -= dE
            if abs(dE) <= 1e-15 * (1.0 + abs(E)):
                break
        return E
    H = math.copysign(math.log(2.0 * abs(M) / e + 1.8), M)
    for _ in range(60):
        dH = (e * math.sinh(H) - H - M) / (e * math.cosh(H) - 1.0)
        H -= dH
        if abs(dH) <= 1e-15 * (1.0 + abs(H)):
            break
    return H


def conic_position(a, e, M, P, Q):
    """Position on a conic about its focus at mean anomaly ``M``: semimajor axis ``a`` (its
    magnitude for a hyperbola, e > 1), pericentre along ``P``, motion towards ``Q``."""
    if e < 1.0:
        E = solve_kepler(M, e)
        x, y = a * (math.cos(E) - e), a * math.sqrt((1.0 - e) * (1.0 + e)) * math.sin(E)
    else:
        H = solve_kepler(M, e)
        x, y = a * (e - math.cosh(H)), a * math.sqrt((e - 1.0) * (e + 1.0)) * math.sinh(H)
    return x * np.asarray(P) + y * np.asarray(Q)


@dataclass(frozen=True)
class HeliocentricOrbit:
    """Keplerian elements of the binary's barycentre about the Sun.

    Parameters
    ----------
    a_au : float or Quantity
        Semimajor axis, AU, in [0.05, 1e4].
    e : float
        Eccentricity, 0 <= e < 1.
    inclination_deg : float or Quantity
        i, degrees in [0, 180] (default 0).
    node_deg, periapsis_deg, mean_anomaly_deg : float or Quantity
        Ω, ω and the mean anomaly at t = 0, degrees in [−360, 360] (default 0: the
        barycentre at perihelion at t = 0).
    frame : {"binary", "ecliptic"}
        What the angles are relative to (module docstring): the binary's inertial frame
        (default), or the ecliptic, with the binary's ``pole``.
    pole : (float, float), optional
        ``frame="ecliptic"`` only: ecliptic longitude λ in [−360, 360] and latitude β in
        [−90, 90] of the mutual orbit's normal, degrees. None: unknown (the Sun's distance is
        known, its direction is not).
    binary_periapsis_deg : float
        ``frame="ecliptic"`` only: the angle in the mutual orbit plane from its ascending
        node on the ecliptic to the initial line of centres, degrees (default 0).

    Examples
    --------
    >>> orbit = tso.HeliocentricOrbit(1.0, 0.1)            # a in AU, e
    >>> orbit.frame
    'binary'
    """

    a_au: float
    e: float
    inclination_deg: float = 0.0
    node_deg: float = 0.0
    periapsis_deg: float = 0.0
    mean_anomaly_deg: float = 0.0
    frame: str = "binary"
    pole: Optional[Tuple[float, float]] = None
    binary_periapsis_deg: float = 0.0

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "a_au", require_positive_scalar("heliocentric_orbit a", self.a_au,
                                                   *HELIOCENTRIC_A_RANGE, "AU"))
        set_(self, "e", float(require_range("heliocentric_orbit e",
                                            require_real("heliocentric_orbit e", self.e), 0.0, 1.0)))
        set_(self, "inclination_deg", check_angle("heliocentric_orbit inclination_deg",
                                                  self.inclination_deg, INCLINATION_RANGE))
        for name in ("node_deg", "periapsis_deg", "mean_anomaly_deg", "binary_periapsis_deg"):
            set_(self, name, check_angle(f"heliocentric_orbit {name}", getattr(self, name)))
        if self.frame not in FRAMES:
            raise ValueError(f"heliocentric_orbit frame must be one of {', '.join(FRAMES)} "
                             f"(got {show(self.frame)})")
        if self.frame == "binary" and (self.pole is not None or self.binary_periapsis_deg):
            raise ValueError("heliocentric_orbit pole and binary_periapsis_deg belong to "
                             "frame='ecliptic' (the binary frame's angles need no pole)")
        if self.pole is not None:
            if not isinstance(self.pole, (tuple, list, np.ndarray)) or len(self.pole) != 2:
                raise TypeError(f"heliocentric_orbit pole must be (longitude, latitude) in "
                                f"degrees or None (got {show(self.pole)})")
            set_(self, "pole", (check_angle("heliocentric_orbit pole longitude", self.pole[0]),
                                check_angle("heliocentric_orbit pole latitude", self.pole[1],
                                            LATITUDE_RANGE)))

    @classmethod
    def coerce(cls, value, name="heliocentric_orbit"):
        """``value`` as a HeliocentricOrbit: one already, (a in AU, e), or a dict of its
        fields; None stays None."""
        if value is None or isinstance(value, cls):
            return value
        if isinstance(value, dict):
            return cls(**value)
        if isinstance(value, (tuple, list)) and len(value) == 2:
            return cls(*value)
        raise TypeError(f"{name} must be a HeliocentricOrbit, (a in AU, e) or None "
                        f"(got {show(value)})")

    @property
    def oriented(self):
        """Whether the Sun's direction relative to the binary is known (binary frame, or
        ecliptic with the pole)."""
        return self.frame == "binary" or self.pole is not None

    def directions(self):
        """(P, Q) of the heliocentric orbit (to perihelion, and 90° ahead) in the binary's
        inertial frame; ValueError when the orbit is not :attr:`oriented`."""
        P, Q = orbit_directions(self.inclination_deg, self.node_deg, self.periapsis_deg)
        if self.frame == "binary":
            return P, Q
        if self.pole is None:
            raise ValueError("this heliocentric orbit is given in the ecliptic without the "
                             "binary's pole, so the Sun's direction is unknown: give "
                             "HeliocentricOrbit(..., pole=(longitude, latitude)), or the Sun's "
                             "angles relative to the binary to SolarTide(inclination_deg=...)")
        R = ecliptic_to_binary(self.pole, self.binary_periapsis_deg)
        return R @ P, R @ Q

    def describe(self):
        """The fields as a JSON-ready dict (defaults left out)."""
        d = {"a_au": self.a_au, "e": self.e}
        for name in ("inclination_deg", "node_deg", "periapsis_deg", "mean_anomaly_deg",
                     "binary_periapsis_deg"):
            if getattr(self, name):
                d[name] = getattr(self, name)
        if self.frame != "binary":
            d["frame"] = self.frame
        if self.pole is not None:
            d["pole"] = list(self.pole)
        return d
