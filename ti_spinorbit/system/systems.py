"""A binary system (two bodies + initial osculating mutual orbit) and its member table rows.

This is the first arrow of the data flow: physical description in SI units -> scaled member
parameters and initial state (numpy), which the kernels consume.

Scaled units (docs/physics.md §4): length = a (initial osculating semimajor axis), time = 1/n with
n = sqrt(G (m1 + m2) / a³), mass = m1 + m2; hence G = 1 and one orbital period is 2π.

Initial conditions (docs/physics.md §6.4): pericentre of the osculating Kepler orbit (a, e,
μ = G(m1+m2)) with the line of centres along the primary's x (long) axis, both equators in
the orbit plane, the secondary's long axis rotated by θ_p from the line of centres, the
secondary spinning at θ̇_p·n about the orbit normal and the primary at 2π/P about its z axis.
The state is fully 3-D even though these starts are planar.
"""

import json
import math
import os
import warnings
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from .._validate import (MAX_BULK_DENSITY, MAX_MASS, MAX_MASS_RATIO, MAX_PRIMARY_SPIN,
                         MAX_SEMIMAJOR_AXIS, MIN_BULK_DENSITY, MIN_LENGTH, MIN_MASS,
                         MIN_MOMENT_RATIO, check_heliocentric, refuse_unknown_keys,
                         require_count, require_finite, require_positive_scalar, require_range,
                         require_real,
                         show)
from .bodies import DATA_ORDER, MAX_ORDER, ROW_ORDER, Body, Ellipsoid, check_order
from . import shapes as _shapes
from .integrals import _check_rotation
from .. import display as _display
from .initial import tilted_start as _tilted_start
from .heliocentric import HeliocentricOrbit
from ..layout import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4

#: Newtonian constant of gravitation, m^3 kg^-1 s^-2 (CODATA 2018).
G = 6.67430e-11

#: Default escape radius in units of a: beyond it a member is stopped with status "escape".
ESCAPE_DISTANCE = 50.0

#: Below these sizes a body or orbit is implausible for an asteroid (a warning, not an error:
#: "kilometres typed as metres?"): a body semi-axis or radius, and the semimajor axis, m.
SMALL_BODY_M, SMALL_ORBIT_M = 1.0, 10.0


# ImplausibleInputWarning (kilometres typed as metres?, radians typed as degrees?) lives with
# the unit conversions; this module's warnings derive from it
from ..units import ImplausibleInputWarning, plain_fields as _plain_fields, to_plain as _to_plain


#: Below this eccentricity a surface of section at pericentre warns (NearCircularWarning).
NEAR_CIRCULAR_E = 1e-3


class NearCircularWarning(ImplausibleInputWarning):
    """A surface of section at e < 1e-3 (``NEAR_CIRCULAR_E``): the pericentre, where the
    section samples, is ill-defined on a (nearly) circular orbit, and the section's points
    scatter with the osculating elements rather than the spin.

    Examples
    --------
    >>> import warnings
    >>> circular = tso.catalog.system("1991 VH", eccentricity=0.0)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     sos = tso.surface_of_section(circular, 0.0, [0.45], orbits=2)
    >>> any(issubclass(w.category, tso.NearCircularWarning) for w in caught)
    True
    """


@dataclass(frozen=True, repr=False)
class BinarySystem(_display.Readable):
    """Primary + secondary on an initial osculating orbit.

    Parameters
    ----------
    primary, secondary : Body
        e.g. ``Sphere(600, 1581)`` (radius 600 m, density 1581 kg m^-3),
        ``Ellipsoid(245, 190, 163, 2618)`` (semi-axes a >= b >= c in m, not diameters, and
        density). Lengths are metres: a body under 1 m or an orbit under 10 m warns.
        The mass ratio m1/m2 must lie in [1e-12, 1e12] (``MAX_MASS_RATIO``) and each body's
        principal moments must be at least 1e-6 of its largest (``MIN_MOMENT_RATIO``: the
        spin equations divide by them, so a body collapsed onto a line is refused).
    a : float or Quantity
        Initial osculating semimajor axis of the mutual orbit, m, in [1e-3, 1e13]
        (``MAX_SEMIMAJOR_AXIS``) and beyond contact at pericentre.
    e : float
        Initial osculating eccentricity, 0 <= e < 1.
    primary_spin_period : float or Quantity, optional
        Primary's spin period about its short axis, s (None: not spinning; irrelevant for a
        spherical primary); negative for retrograde spin. Its rate 2π/|P| may be at most
        1e5 n (``MAX_PRIMARY_SPIN``): |P| >= orbital period / 1e5.
    name : str
        Label used in plots and saved files. Only a label: nothing is looked up by it.
    heliocentric_orbit : HeliocentricOrbit or (float, float), optional
        The barycentre's heliocentric orbit: a :class:`~ti_spinorbit.HeliocentricOrbit`
        (all six elements, relative to the binary's frame or to the ecliptic with the
        binary's pole), or just (a in AU, e), a in [0.05, 1e4] AU (``HELIOCENTRIC_A_RANGE``),
        0 <= e < 1, the other elements 0. YORP and BYORP read the Sun's distance from it,
        SolarTide its direction too (:mod:`ti_spinorbit.model.perturbations`). The
        catalogue fills it where the orbit is known (``catalog.heliocentric_orbit``); None
        (default) for a system of your own, whatever its name, until you give it.
    orbital_period : float or Quantity, optional
        Observed orbital period of the mutual orbit, s (positive, finite), e.g. 11.92 h =
        42912 s for Didymos-Dimorphos. When given, both bodies' masses (hence densities; shapes
        unchanged) are multiplied by one factor ``density_scale`` = (P_match / P)² so that
        the period ``period_match`` names equals it: by default the Keplerian period
        2π sqrt(a³ / (G (m1 + m2))), with ``period_match="circular"`` the period of the
        circular synchronous orbit under the figures' order-4 force
        (:meth:`circular_period`), which is what an observed period measures (the two
        differ by 0.8 % for Didymos); the mass ratio and ω0 are unchanged. The period must imply a bulk density (m1 + m2) / (V1 + V2) in
        [100, 25000] kg/m³ (``MIN_BULK_DENSITY``, ``MAX_BULK_DENSITY``: a tenth of water to
        just above osmium), so P lies in [2π sqrt(a³ / (G 25000 V)), 2π sqrt(a³ / (G 100 V))],
        V = V1 + V2; the error names that range and the implied density (a period in the wrong
        unit, e.g. 1 s or 1e20 s, lands outside). V of an ellipsoid is (4/3)π abc; of a
        polyhedron its own ``volume``; of any other :class:`Body`, that of the uniform
        ellipsoid with its second moments, semi-axes sqrt(5 T^200 / m) etc. (docs/physics.md
        §7.5). Not stored: the scaled bodies are, with ``density_scale``.

    Attributes
    ----------
    density_scale : float
        The factor ``orbital_period`` applied to both bodies' masses and densities (1.0 when
        the bodies were used as given); shown by ``repr``. :meth:`describe` does not write
        it (the masses it writes are already scaled, and nothing could check it on reading),
        so a system read back has 1.0; it takes no part in ``==``.

    Warns
    -----
    ImplausibleInputWarning
        A body with a semi-axis (or bounding radius) below 1 m or a semimajor axis below 10 m
        (``SMALL_BODY_M``, ``SMALL_ORBIT_M``): kilometres typed as metres?

    See Also
    --------
    ti_spinorbit.catalog.system : the systems of Naidu & Margot 2015, Table 1

    References
    ----------
    * Naidu, S. P. & Margot, J.-L. 2015, Near-Earth asteroid satellite spins under
      spin-orbit coupling, AJ 149:80.

    Examples
    --------
    A system in SI units (radius and semi-axes in metres, densities in kg/m³):

    >>> system = tso.BinarySystem(tso.Sphere(600, density=1581),
    ...                           tso.Ellipsoid(294, 196, 190, density=2618),
    ...                           a=3300, e=0.05, name="mine")
    >>> round(system.mass_ratio, 1), round(system.omega0, 3)
    (11.9, 1.074)
    >>> round(system.orbital_period / 3600, 1)             # hours
    32.5

    The same bodies matched to an observed orbital period (both densities scaled by one
    factor):

    >>> matched = tso.BinarySystem(system.primary, system.secondary, a=3300, e=0.05,
    ...                            orbital_period=30 * 3600)
    >>> round(matched.density_scale, 3)
    1.175
    """

    primary: Body
    secondary: Body
    a: float
    e: float
    primary_spin_period: Optional[float] = None
    name: str = "binary"
    heliocentric_orbit: Optional[HeliocentricOrbit] = None
    density_scale: float = field(default=1.0, init=False, compare=False)

    def __post_init__(self):
        _plain_fields(self, a="m", e="", primary_spin_period="s")
        for label, body in (("primary", self.primary), ("secondary", self.secondary)):
            if not isinstance(body, Body):
                raise TypeError(f"{label} must be a ti_spinorbit Body (Sphere, Ellipsoid, Body), "
                                f"got {type(body).__name__}")
        require_positive_scalar("a", self.a, MIN_LENGTH, MAX_SEMIMAJOR_AXIS, "m")
        require_real("e", self.e)
        require_range("e", self.e, 0.0, 1.0)
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a string (got {show(self.name)})")
        object.__setattr__(self, "heliocentric_orbit",
                           HeliocentricOrbit.coerce(self.heliocentric_orbit))
        ratio = self.primary.mass / self.secondary.mass
        if not 1.0 / MAX_MASS_RATIO <= ratio <= MAX_MASS_RATIO:
            raise ValueError(f"mass ratio m1/m2 must lie in [{1 / MAX_MASS_RATIO:g}, "
                             f"{MAX_MASS_RATIO:g}] (got {ratio:.6g}: primary {self.primary.mass:.6g} "
                             f"kg, secondary {self.secondary.mass:.6g} kg)")
        for label, body in (("primary", self.primary), ("secondary", self.secondary)):
            moments = body.moments
            if not moments.min() >= MIN_MOMENT_RATIO * moments.max():
                raise ValueError(
                    f"{label}: each principal moment must be at least {MIN_MOMENT_RATIO:g} of the "
                    f"largest (got A, B, C = {', '.join(f'{m:.6g}' for m in moments)} kg m^2): "
                    "a body collapsed onto a line or a point cannot spin")
        if self.primary_spin_period is not None:
            require_real("primary_spin_period", self.primary_spin_period)
            require_finite("primary_spin_period", self.primary_spin_period)
            if self.primary_spin_period == 0:
                raise ValueError("primary_spin_period must be non-zero (None for no spin)")
            shortest = self.orbital_period / MAX_PRIMARY_SPIN
            if abs(self.primary_spin_period) < shortest:
                raise ValueError(
                    f"primary_spin_period must satisfy |P| >= orbital period / "
                    f"{MAX_PRIMARY_SPIN:g} = {shortest:.6g} s (a spin of at most "
                    f"{MAX_PRIMARY_SPIN:g} n; got {self.primary_spin_period:.6g})")
        contact = self.primary.bounding_radius + self.secondary.bounding_radius
        pericentre = self.a * (1.0 - self.e)
        if pericentre <= contact:
            raise ValueError(
                f"bodies overlap at pericentre: a(1-e) = {pericentre:.6g} m must exceed the sum "
                f"of bounding radii {contact:.6g} m (increase a or decrease e)")
        self._warn_if_implausibly_small()

    def _warn_if_implausibly_small(self):
        small = []
        for label, body in (("primary", self.primary), ("secondary", self.secondary)):
            sizes = getattr(body, "semi_axes", None) or (body.bounding_radius,)
            if min(sizes) < SMALL_BODY_M:
                small.append(f"{label} size {min(sizes):.3g} m")
        if self.a < SMALL_ORBIT_M:
            small.append(f"a = {self.a:.3g} m")
        if small:
            warnings.warn(f"{self.name}: {', '.join(small)} is implausibly small for an asteroid "
                          f"(below {SMALL_BODY_M:g} m for a body, {SMALL_ORBIT_M:g} m for a): "
                          "kilometres typed as metres? All lengths are in metres",
                          ImplausibleInputWarning, stacklevel=5)

    # ---- physical quantities (SI) ----------------------------------------------------------
    @property
    def total_mass(self) -> float:
        """m1 + m2, kg."""
        return self.primary.mass + self.secondary.mass

    @property
    def mean_motion(self) -> float:
        """n = sqrt(G (m1 + m2) / a³) of the initial osculating orbit, rad/s."""
        return math.sqrt(G * self.total_mass / self.a**3)

    @property
    def orbital_period(self) -> float:
        """2π/n, s."""
        return 2.0 * math.pi / self.mean_motion

    def circular_period(self, order: int = 4, phases: int = 32) -> float:
        """The period, s, of a circular orbit at separation ``a`` under the mutual force of
        the figures at truncation ``order`` (2 to the bodies' order; default 4, the paper's), the secondary
        synchronous (its long, x axis on the line of centres) and the primary's figure
        averaged over its rotation phase (``phases`` equally spaced; exact for a primary
        symmetric about its z axis): 2π sqrt(m_red a / F_r), F_r the mean attraction along
        the line of centres (docs/physics.md §7.5). The figures' extra attraction makes it
        shorter than the Keplerian :attr:`orbital_period` (0.8 % for the catalogue's Didymos),
        and it is what an observed period measures (to first order in e)."""
        from ..multipole import multi_indices, mutual_force_torque   # NumPy only

        order = require_count("order", order, 2, min(self.primary.order, self.secondary.order))
        TA, TB = ({tuple(int(i) for i in k): body.integral(*(int(i) for i in k))
                   for k in multi_indices(order)}
                  for body in (self.primary, self.secondary))
        reduced = self.primary.mass * self.secondary.mass / self.total_mass
        attraction = 0.0
        for phi in 2.0 * math.pi * np.arange(phases) / phases:
            c, s_ = math.cos(phi), math.sin(phi)
            turn = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
            _, force, _, _ = mutual_force_torque(TA, TB, self.a * turn[:, 0], turn, order, G=G)
            attraction -= force @ turn[:, 0] / phases
        return 2.0 * math.pi * math.sqrt(reduced * self.a / attraction)

    @property
    def mass_ratio(self) -> float:
        """Primary-to-secondary mass ratio m1/m2."""
        return self.primary.mass / self.secondary.mass

    @property
    def omega0(self) -> float:
        """Secondary's free libration frequency in units of n: sqrt(3 |B − A| / C)
        (docs/physics.md §2), A, B, C the moments about the body's x, y, z axes (kg m²).

        The secondary spins about its z axis; its long axis in the xy plane (x when A <= B,
        y when B < A) librates about the line of centres with this small-amplitude
        frequency, so a body whose long axis is y has the same ω0 as the same body turned
        by 90° about z. 0 for a body symmetric about z (A = B)."""
        A, B, C = self.secondary.moments
        return math.sqrt(3.0 * abs(B - A) / C)

    # ---- scaled member rows -------------------------------------------------------------
    def scaled_body_row(self, body: Body) -> np.ndarray:
        """Body.as_row in scaled units: T^{lmn} / ((m1+m2) a^{l+m+n})."""
        row = body.as_row()
        M = self.total_mass
        scale = [M] + [M * self.a**2] * len(EXPONENTS_2) + [M * self.a**3] * len(EXPONENTS_3) \
            + [M * self.a**4] * len(EXPONENTS_4)
        return row / np.array(scale)

    def parameter_row(self, escape_distance: float = ESCAPE_DISTANCE) -> np.ndarray:
        """The kernels' parameter row (kernels/eom.py layout), scaled units."""
        from ..kernels import eom      # Taichi: imported on first use

        p = np.zeros(eom.NPAR)
        p[eom.BODY_A:eom.BODY_A + len(self.primary.as_row())] = self.scaled_body_row(self.primary)
        p[eom.BODY_B:eom.BODY_B + len(self.secondary.as_row())] = self.scaled_body_row(self.secondary)
        m1, m2 = self.primary.mass / self.total_mass, self.secondary.mass / self.total_mass
        p[eom.P_MRED] = m1 * m2
        I1 = self.primary.moments / (self.total_mass * self.a**2)
        I2 = self.secondary.moments / (self.total_mass * self.a**2)
        p[eom.P_C1], p[eom.P_C2] = I1.max(), I2.max()
        p[eom.P_IA:eom.P_IA + 3] = I1.max() / I1
        p[eom.P_IB:eom.P_IB + 3] = I2.max() / I2
        p[eom.P_CONTACT] = (self.primary.bounding_radius + self.secondary.bounding_radius) / self.a
        p[eom.P_ESCAPE] = escape_distance
        return p

    def initial_state(self, theta_p: float, thetadot_p: float) -> np.ndarray:
        """Scaled 30-element state at pericentre (docs/physics.md §6.4).

        theta_p in radians from the line of centres, thetadot_p in units of n."""
        return self.initial_states(np.array([theta_p], dtype=np.float64),
                                   np.array([thetadot_p], dtype=np.float64))[0]

    def initial_states(self, theta_p, thetadot_p) -> np.ndarray:
        """:meth:`initial_state` of many starts at once: theta_p (radians) and thetadot_p
        (units of n) 1-D arrays of one length; returns (N, 30). The numbers are those of
        the one-start form, bit for bit (the same operations, elementwise)."""
        from ..kernels import eom      # Taichi: imported on first use

        theta_p = np.asarray(theta_p, dtype=np.float64).ravel()
        thetadot_p = np.asarray(thetadot_p, dtype=np.float64).ravel()
        e = self.e
        r = 1.0 - e
        v = math.sqrt((1.0 + e) / (1.0 - e))        # vis-viva at pericentre, μ = a = 1
        omega1 = 0.0 if self.primary_spin_period is None else \
            2.0 * math.pi / (self.primary_spin_period * self.mean_motion)
        I1 = self.primary.moments / (self.total_mass * self.a**2)
        I2 = self.secondary.moments / (self.total_mass * self.a**2)
        # the C library's cos and sin, as ever (NumPy's vector forms may differ in the last bit)
        c = np.fromiter(map(math.cos, theta_p), dtype=np.float64, count=len(theta_p))
        s = np.fromiter(map(math.sin, theta_p), dtype=np.float64, count=len(theta_p))
        y = np.zeros((len(theta_p), eom.NSTATE))
        y[:, eom.Y_R] = r
        y[:, eom.Y_V + 1] = v
        y[:, eom.Y_W1 + 2] = I1[2] * omega1 / I1.max()
        # spin about z (a principal axis of both frames since S is a z-rotation)
        y[:, eom.Y_W2 + 2] = I2[2] * thetadot_p / I2.max()
        S = y[:, eom.Y_S:eom.Y_S + 9]                 # [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        S[:, 0], S[:, 1], S[:, 3], S[:, 4], S[:, 8] = c, -s, s, c, 1.0
        y[:, eom.Y_S1:eom.Y_S1 + 9] = np.eye(3).ravel()
        return y

    def tilted_start(self, theta_p: float, thetadot_p: float, **tilts):
        """The paper's start (θ_p in degrees, θ̇_p in units of n) tilted out of the plane:
        an :class:`ti_spinorbit.InitialState` (keywords roll, pitch, yaw, spin_x, spin_y,
        inclination, primary_tilt: :func:`ti_spinorbit.system.initial.tilted_start`,
        docs/physics.md §6.8)."""
        return _tilted_start(self, theta_p, thetadot_p, **tilts)

    def to_physical(self, y: np.ndarray) -> np.ndarray:
        """Scaled internal state -> SI physical state [R, P, Γ1, Γ2, S, S1] (reference layout)."""
        from ..kernels import eom      # Taichi: imported on first use

        y = np.asarray(y, dtype=np.float64)
        out = y.copy()
        L, T, M = self.a, 1.0 / self.mean_motion, self.total_mass
        m_red = self.primary.mass * self.secondary.mass / M
        C1 = self.primary.moments.max()
        C2 = self.secondary.moments.max()
        out[..., eom.Y_R:eom.Y_R + 3] *= L
        out[..., eom.Y_V:eom.Y_V + 3] *= m_red * L / T
        out[..., eom.Y_W1:eom.Y_W1 + 3] *= C1 / T
        out[..., eom.Y_W2:eom.Y_W2 + 3] *= C2 / T
        return out

    def from_physical(self, x: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`to_physical`."""
        ones = np.ones(30)
        factor = self.to_physical(ones)
        return np.asarray(x, dtype=np.float64) / factor

    def describe(self) -> dict:
        """All inputs with units, for saved files and plots, and the derived entries
        ``mean_motion_rad_s``, ``mass_ratio``, ``omega0``, ``orbital_period_h`` (and each
        body's ``bounding_radius_m``, for an ellipsoid its largest semi-axis), which
        :meth:`from_description` checks against the inputs rather than reads.
        ``density_scale`` is not written: the masses written already carry it.

        A body read from a shape file (:func:`~ti_spinorbit.system.shapes.read_shape`, or a
        packaged shape) is written as that file (``shape``, ``file`` or ``packaged``,
        ``unit``, ``density`` or ``mass_kg``, ``order``), so the description rebuilds it; a
        body in its principal frame from a shape (polyhedron, composite, point cloud) also
        gets its ``offset_m`` and ``rotation`` (shape frame -> body frame)."""
        def body(b):
            d = {"name": b.name, "mass_kg": b.mass, "bounding_radius_m": b.bounding_radius}
            if hasattr(b, "semi_axes"):
                d["semi_axes_m"] = list(b.semi_axes)
            source = getattr(b, "source", None)         # read from a shape file
            if source is not None:
                d.update(source)
            if source is not None or b.order != _default_order(b):
                d["order"] = b.order
            for attribute, key in (("offset", "offset_m"), ("rotation", "rotation")):
                if getattr(b, attribute, None) is not None:
                    d[key] = np.asarray(getattr(b, attribute), dtype=np.float64).tolist()
            return d
        return {"name": self.name, "primary": body(self.primary), "secondary": body(self.secondary),
                "a_m": self.a, "e": self.e, "primary_spin_period_s": self.primary_spin_period,
                "mean_motion_rad_s": self.mean_motion, "mass_ratio": self.mass_ratio,
                "omega0": self.omega0, "orbital_period_h": self.orbital_period / 3600.0,
                **({} if self.heliocentric_orbit is None else
                   {"heliocentric_orbit": self.heliocentric_orbit.describe()})}

    @classmethod
    def from_description(cls, d: dict, *, directory=None) -> "BinarySystem":
        """Rebuild a system from :meth:`describe` output (e.g. read back from a saved file).

        The result has the identical :meth:`parameter_row` and :meth:`initial_state`.

        Each body entry (``d["primary"]``, ``d["secondary"]``) is rebuilt

        * from ``"integrals"``, ``{"l,m,n": T^{lmn} in kg m^(l+m+n)}`` with ``"mass_kg"`` and
          ``"bounding_radius_m"``, when present (:func:`ti_spinorbit.output.io.save` writes them for
          every body): a general :class:`Body`, or a uniform ellipsoid when ``"semi_axes_m"``
          is also given and the ellipsoid's integrals equal the saved ones exactly;
        * else from ``"semi_axes_m"`` (m) and ``"mass_kg"`` as a uniform ellipsoid, which is
          exact because an ellipsoid's integrals depend on nothing else.

        * else from a shape file, ``{"shape": "polyhedron", "file": PATH, "unit": "km",
          "density": kg/m^3}`` (``"mass_kg"`` instead of ``"density"``; optional ``"facets"``
          for the GUBAS CSV pair, ``"format"``, ``"order"``, default 8, and ``"name"``,
          default the file's stem), read with
          :func:`~ti_spinorbit.system.shapes.read_shape`; a relative PATH is relative to
          ``directory`` (the system file's folder when read by :meth:`from_file`, else the
          current directory). ``{"shape": "polyhedron", "packaged": "didymos_radar", ...}``
          names a shape packaged with ti_spinorbit (``shapes.PACKAGED``) instead. With
          ``"density"``, ``"mass_kg"`` is derived (checked), and so are
          ``"bounding_radius_m"``, ``"offset_m"`` and ``"rotation"``. A shape body that also
          has ``"integrals"`` (as saved results hold it) is rebuilt from them, and the file
          is not read.

        ``"order"`` (optional, 4..16) is the order of the body's integrals; without it an
        ellipsoid has ``MAX_ORDER`` (16, as :func:`Ellipsoid` gives it), a shape file 8
        (``DATA_ORDER``) and a general body the highest degree among its ``integrals``, at
        least 4 (:meth:`describe` writes it where it differs from these, and for every shape
        file). ``"offset_m"`` and ``"rotation"`` of a body given by its integrals are kept on
        it as given.

        A general body described by :meth:`describe` alone (no semi-axes, no integrals)
        cannot be rebuilt: ValueError.

        Nothing is ignored. A key that :meth:`describe` and :func:`ti_spinorbit.output.io.save` do
        not write (``SYSTEM_KEYS``, and ``BODY_KEYS`` in each body) is refused, naming it
        and the nearest valid key. Derived entries are recomputed from the inputs and
        checked, never read: ``mean_motion_rad_s``, ``mass_ratio``, ``orbital_period_h``
        (from ``a_m`` and the masses), ``omega0`` (from the secondary's shape) and an
        ellipsoid's ``bounding_radius_m`` (its largest semi-axis) must agree with the
        recomputed value to a relative ``DERIVED_RTOL`` = 1e-9 (ω0 also to 1e-9 absolute),
        else ValueError naming the entry, both values and the inputs to edit instead; each
        may be left out (delete them after editing the inputs). ``semi_axes_m`` given with
        ``integrals`` must describe the same ellipsoid to 1e-9. ``density_scale`` (written by
        earlier versions) may only be 1: nothing scales a description's masses. The
        entries and rules: docs/physics.md §7.5.
        """
        if not isinstance(d, dict):
            raise TypeError(f"system description must be a dict from BinarySystem.describe() "
                            f"(got {type(d).__name__})")
        refuse_unknown_keys(d, SYSTEM_KEYS, "the system description")
        missing = [k for k in ("primary", "secondary", "a_m", "e") if k not in d]
        if missing:
            raise ValueError(f"system description lacks {', '.join(map(repr, missing))} "
                             f"(has {', '.join(map(repr, d))}); expected BinarySystem.describe() output")
        mismatches = []           # derived entries that disagree, all named in one message
        if directory is not None and not isinstance(directory, (str, os.PathLike)):
            raise TypeError(f"directory must be a folder path or None (got {show(directory)})")
        primary = _body_from(d["primary"], "primary", mismatches, directory)
        secondary = _body_from(d["secondary"], "secondary", mismatches, directory)
        period = d.get("primary_spin_period_s")
        observed = d.get("observed_orbital_period_h")
        if "period_match" in d and observed is None:
            raise ValueError("period_match needs observed_orbital_period_h (the period the masses "
                             "are scaled to)")
        system = cls(primary, secondary, require_real("a_m", d["a_m"]), require_real("e", d["e"]),
                     primary_spin_period=None if period is None else
                     require_real("primary_spin_period_s", period),
                     name=d.get("name", "binary"),
                     heliocentric_orbit=_heliocentric_from(d),
                     orbital_period=None if observed is None else
                     require_real("observed_orbital_period_h", observed) * 3600.0,
                     period_match=d.get("period_match", "keplerian"))
        _check_derived_entries(d, system, mismatches)
        if "density_scale" in d:
            scale = require_real("density_scale", d["density_scale"])
            if scale != 1.0:
                raise ValueError(
                    f"density_scale is {scale:.12g}, but a description's masses are used as they "
                    "are and nothing scales them (it recorded a factor BinarySystem("
                    "orbital_period=) had already applied to mass_kg, and cannot be checked): "
                    "delete density_scale, and edit the bodies' mass_kg to change the densities")
        return system

    @classmethod
    def from_file(cls, path) -> "BinarySystem":
        """The system in a JSON file: one :meth:`describe` object, as written by
        ``ti-spinorbit systems --show NAME --out PATH`` (a one-item list, as ``systems
        --out`` writes, is accepted), read with every check of :meth:`from_description`
        (unknown keys, derived entries). The command line's ``--system PATH.json`` reads
        files this way.

        Raises
        ------
        FileNotFoundError
            No file at ``path``.
        ValueError
            One line naming ``path`` and the file: not JSON (or a key given twice in one
            object), JSON nested too deeply, not a JSON object, or a description
            :meth:`from_description` refuses.
        """
        return read_system_file(path, "path")


#: Keys of a system description (BinarySystem.describe() output; "density_scale" only as
#: earlier versions wrote it, 1) and of each of its bodies (io.describe_system adds
#: "integrals"): any other key is refused, not ignored.
SYSTEM_KEYS = ("name", "primary", "secondary", "a_m", "e", "primary_spin_period_s",
               "observed_orbital_period_h", "period_match",
               "heliocentric_orbit", "heliocentric_a_au", "heliocentric_e",
               "mean_motion_rad_s", "mass_ratio",
               "omega0", "orbital_period_h", "density_scale")
BODY_KEYS = ("name", "mass_kg", "bounding_radius_m", "semi_axes_m", "integrals", "order",
             "shape", "file", "facets", "unit", "format", "packaged", "density", "offset_m",
             "rotation")
#: The keys of a body given by a shape file (with "shape": "polyhedron").
SHAPE_KEYS = ("shape", "file", "facets", "unit", "format", "packaged", "density")
#: Relative tolerance of a derived entry against its value recomputed from the inputs: the
#: package writes them unrounded (JSON keeps every bit), so only an edit differs.
DERIVED_RTOL = 1e-9


def _heliocentric_from(d):
    """The heliocentric orbit of a system description: its ``heliocentric_orbit`` dict, or
    the (a, e) pair ``heliocentric_a_au``, ``heliocentric_e`` that earlier versions wrote."""
    if "heliocentric_orbit" in d:
        if "heliocentric_a_au" in d or "heliocentric_e" in d:
            raise ValueError("give heliocentric_orbit or heliocentric_a_au and heliocentric_e, "
                             "not both")
        orbit = d["heliocentric_orbit"]
        if not isinstance(orbit, dict):
            raise TypeError(f"heliocentric_orbit must be a dict of HeliocentricOrbit fields "
                            f"(a_au, e, inclination_deg, ...) (got {show(orbit)})")
        return HeliocentricOrbit(**orbit)
    if "heliocentric_a_au" not in d and "heliocentric_e" not in d:
        return None
    return HeliocentricOrbit(*check_heliocentric(d.get("heliocentric_a_au"), d.get("heliocentric_e")))


def _body_from(b, label, mismatches, directory=None):
    """A body of a system description (see BinarySystem.from_description); a derived
    bounding_radius_m that disagrees is added to ``mismatches``."""
    if not isinstance(b, dict):
        raise TypeError(f"{label} must be an object with the keys {', '.join(BODY_KEYS)} "
                        f"(got {show(b)})")
    refuse_unknown_keys(b, BODY_KEYS, repr(label))
    if "shape" in b:
        return _shape_body_from(b, label, mismatches, directory)
    # an ellipsoid may be given by its density instead of its mass (_plain_body_from)
    by_density = "semi_axes_m" in b and "integrals" not in b
    stray = [k for k in SHAPE_KEYS if k in b and not (k == "density" and by_density)]
    if stray:
        raise ValueError(f"{label} {stray[0]!r} belongs to a body given by a shape file: add "
                         "\"shape\": \"polyhedron\" and \"file\" (or \"packaged\"), or delete it")
    body = _plain_body_from(b, label, mismatches)
    _record_frame(body, b, label)
    return body


def _record_frame(body, b, label):
    """Keep a description's offset_m and rotation on a body rebuilt from its integrals."""
    if "offset_m" in b:
        offset = np.asarray(require_finite(f"{label} offset_m", b["offset_m"]), dtype=np.float64)
        if offset.shape != (3,):
            raise ValueError(f"{label} offset_m must be a list of 3 lengths in m (got "
                             f"{show(b['offset_m'])})")
        offset.setflags(write=False)
        object.__setattr__(body, "offset", offset)
    if "rotation" in b:
        try:
            rotation = _check_rotation(b["rotation"]).copy()
        except ValueError as exc:
            raise ValueError(f"{label} rotation: {exc}") from None
        rotation.setflags(write=False)
        object.__setattr__(body, "rotation", rotation)


def _table_from(integrals, label):
    if not isinstance(integrals, dict):
        raise TypeError(f"{label} integrals must be an object {{'l,m,n': T^lmn}} "
                        f"(got {show(integrals)})")
    table = {}
    for key, value in integrals.items():
        try:
            lmn = tuple(int(i) for i in key.split(","))
        except (AttributeError, ValueError):
            raise ValueError(f"{label} integrals: key {show(key)} is not 'l,m,n'") from None
        table[lmn] = require_real(f"{label} integrals[{key!r}]", value)
    return table


def _shape_body_from(b, label, mismatches, directory):
    """A body given by a shape file (or, with "integrals", by the integrals saved with it)."""
    if b["shape"] != "polyhedron":
        raise ValueError(f"{label} shape must be 'polyhedron' (a shape-model file; an ellipsoid "
                         f"is given by semi_axes_m) (got {show(b['shape'])})")
    if "semi_axes_m" in b:
        raise ValueError(f"{label}: a polyhedron has no semi_axes_m; delete it")
    if ("file" in b) == ("packaged" in b):
        raise ValueError(f"{label} needs exactly one of 'file' (a shape-model file, relative to "
                         f"the system file) and 'packaged' (a shape packaged with ti_spinorbit: "
                         f"{', '.join(map(repr, _shapes.PACKAGED))})")
    if "packaged" in b:
        extra = [k for k in ("facets", "unit", "format") if k in b]
        if extra:
            raise ValueError(f"{label} {extra[0]!r} is for a shape file, not a packaged shape")
    order = check_order(b.get("order", DATA_ORDER), f"{label} order")
    density = b.get("density")
    if density is None and "mass_kg" not in b:
        raise ValueError(f"{label} needs 'density' (kg/m^3) or 'mass_kg' (its shape gives the "
                         f"other)")
    if density is not None:
        density = require_real(f"{label} density", density)
    mass = None if density is not None else require_real(f"{label} mass_kg", b["mass_kg"])
    source = {k: b[k] for k in SHAPE_KEYS if k in b}
    name = b.get("name")
    if "integrals" in b:                            # a saved body: its integrals are read
        for key in ("mass_kg", "bounding_radius_m"):
            if key not in b:
                raise ValueError(f"{label} description lacks {key!r} (has "
                                 f"{', '.join(map(repr, b))})")
        try:
            body = Body(require_real(f"{label} mass_kg", b["mass_kg"]),
                        _table_from(b["integrals"], label),
                        require_real(f"{label} bounding_radius_m", b["bounding_radius_m"]),
                        "body" if name is None else name, order)
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"{label}: {exc}") from None
        if density is not None:
            object.__setattr__(body, "density", density)
            object.__setattr__(body, "volume", body.mass / density)
        _record_frame(body, b, label)
        object.__setattr__(body, "source", _shapes.Source(
            {**source, **({} if density is not None else {"mass_kg": body.mass})}))
        return body
    try:
        if "packaged" in b:
            body = _shapes.packaged_shape(b["packaged"], density=density, mass=mass, name=name,
                                          order=order)
        else:
            def resolve(p):
                if not isinstance(p, str):
                    raise TypeError(f"file paths must be strings (got {show(p)})")
                return p if os.path.isabs(p) else os.path.join(directory or os.getcwd(), p)

            body = _shapes.read_shape(resolve(b["file"]), unit=b.get("unit", "km"),
                                      density=density, mass=mass, format=b.get("format"),
                                      facets=None if "facets" not in b else resolve(b["facets"]),
                                      name=name, order=order)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{label}: {exc}") from None
    checks = [("mass_kg", body.mass, 0.0)] if density is not None else []
    checks += [("bounding_radius_m", body.bounding_radius, 0.0),
               ("offset_m", body.offset, body.bounding_radius),
               ("rotation", body.rotation, 1.0)]
    for key, value, scale in checks:
        if key in b:
            given = np.asarray(require_finite(f"{label} {key}", b[key]), dtype=np.float64)
            want = np.asarray(value, dtype=np.float64)
            if given.shape != want.shape or not np.allclose(
                    given, want, rtol=DERIVED_RTOL, atol=DERIVED_RTOL * scale):
                mismatches.append(f"{label} {key} is {show(given.tolist())} in the "
                                  f"description, but its shape file gives "
                                  f"{show(want.tolist())}")
    return body


def _plain_body_from(b, label, mismatches):
    """An ellipsoid (semi_axes_m, with mass_kg or density) or a general body (integrals)."""
    axes, integrals = b.get("semi_axes_m"), b.get("integrals")
    by_density = "density" in b          # an ellipsoid's: its mass_kg is then derived
    needed = () if by_density else ("mass_kg",) if axes is not None and integrals is None else \
        ("mass_kg", "bounding_radius_m")
    for key in needed:
        if key not in b:
            raise ValueError(f"{label} description lacks {key!r} (has {', '.join(map(repr, b))})")
    name = b.get("name", "body")
    mass = None if by_density else require_real(f"{label} mass_kg", b["mass_kg"])
    order = b.get("order")
    if order is not None:
        order = check_order(order, f"{label} order")
    ellipsoid = None
    if axes is not None:
        if not isinstance(axes, (list, tuple)) or len(axes) != 3:
            raise TypeError(f"{label} semi_axes_m must be a list [a, b, c] of three lengths in m "
                            f"(got {show(axes)})")
        density = require_real(f"{label} density", b["density"]) if by_density else None
        try:
            ellipsoid = Ellipsoid(*axes, density, mass=mass, name=name,
                                  order=MAX_ORDER if order is None else order)
        except (TypeError, ValueError) as exc:
            raise type(exc)(f"{label}: {exc}") from None
    if integrals is None:
        if ellipsoid is None:
            raise ValueError(
                f"{label} {name!r} is a general Body: its description needs 'integrals' "
                "({'l,m,n': T^lmn}, as written by ti_spinorbit.output.io.save) or 'semi_axes_m'; "
                "describe() alone does not hold its inertia integrals")
        if by_density and "mass_kg" in b:
            given = require_real(f"{label} mass_kg", b["mass_kg"])
            if not math.isclose(given, ellipsoid.mass, rel_tol=DERIVED_RTOL):
                mismatches.append(f"{label} mass_kg is {given:.12g} in the description, but its "
                                  f"semi_axes_m and density give {ellipsoid.mass:.12g}")
        if "bounding_radius_m" in b:
            given = require_real(f"{label} bounding_radius_m", b["bounding_radius_m"])
            derived = ellipsoid.bounding_radius
            if not math.isclose(given, derived, rel_tol=DERIVED_RTOL):
                mismatches.append(f"{label} bounding_radius_m is {given:.12g} in the "
                                  f"description, but its semi_axes_m give {derived:.12g} (an "
                                  "ellipsoid's is its largest semi-axis)")
        return ellipsoid
    table = _table_from(integrals, label)
    try:
        general = Body(mass, table, require_real(f"{label} bounding_radius_m",
                                                 b["bounding_radius_m"]), name,
                       order if order is not None or ellipsoid is None else ellipsoid.order)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{label}: {exc}") from None
    if ellipsoid is None:
        return general
    if np.array_equal(ellipsoid.as_row(), general.as_row()) \
            and ellipsoid.bounding_radius == general.bounding_radius:
        return ellipsoid
    longest = ellipsoid.semi_axes[0]
    keys = EXPONENTS_2 + EXPONENTS_3 + EXPONENTS_4
    for k, want, have in zip(keys, ellipsoid.as_row()[1:], general.as_row()[1:]):
        if abs(want - have) > DERIVED_RTOL * mass * longest ** sum(k):
            raise ValueError(
                f"{label} semi_axes_m {show(list(axes))} and mass_kg make T^{''.join(map(str, k))}"
                f" = {want:.12g} for a uniform ellipsoid, but its integrals give {have:.12g}: "
                "the integrals are read and semi_axes_m only checked; delete semi_axes_m or "
                "make the two agree")
    return general


def _check_derived_entries(d, system, bad):
    """Refuse derived entries of a description that disagree with ``system`` rebuilt from
    its inputs (BinarySystem.from_description), with those already in ``bad``, in one
    message."""
    masses = "a_m and the bodies' mass_kg"
    derived = (("mean_motion_rad_s", system.mean_motion, masses, 0.0),
               ("mass_ratio", system.mass_ratio, "the bodies' mass_kg", 0.0),
               ("omega0", system.omega0, "the secondary's semi_axes_m or integrals", DERIVED_RTOL),
               ("orbital_period_h", system.orbital_period / 3600.0, masses, 0.0))
    for key, value, inputs, atol in derived:
        if key in d:
            given = require_real(key, d[key])
            if not math.isclose(given, value, rel_tol=DERIVED_RTOL, abs_tol=atol):
                bad.append(f"{key} is {given:.12g} in the description, but {inputs} give "
                           f"{value:.12g}")
    if bad:
        it = "it is" if len(bad) == 1 else "they are"
        raise ValueError(f"{'; '.join(bad)}: {it} derived from the inputs, never read: edit "
                         "those inputs instead (derived entries are optional: delete those "
                         "that no longer match)")


class _DuplicateKey(ValueError):
    pass


def _object_without_duplicates(pairs):
    """json object_pairs_hook: a key given twice in one object is refused (json keeps the
    last one silently)."""
    out = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(f"key {show(key)} is given twice in one object (JSON would "
                                "keep the last silently)")
        out[key] = value
    return out


_JSON_KINDS = {dict: "object", list: "array", str: "string", int: "number", float: "number",
               bool: "true/false", type(None): "null"}


def read_system_file(path, what="path"):
    """The BinarySystem of a system file (BinarySystem.from_file), every error one line
    starting with ``what`` (the parameter, or the command line's flag: "--system") and
    naming the file."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} must be a file path (str or os.PathLike), got {show(path)}")
    p = os.fsdecode(os.fspath(path))
    try:
        with open(p, encoding="utf-8") as f:
            d = json.load(f, object_pairs_hook=_object_without_duplicates)
    except FileNotFoundError:
        raise FileNotFoundError(f"{what}: no such file {p!r}") from None
    except RecursionError:
        raise ValueError(f"{what}: {p!r} holds JSON nested too deeply to read; a system file "
                         "is one JSON object (BinarySystem.describe() output, as 'ti-spinorbit "
                         "systems --show NAME --out PATH' writes)") from None
    except _DuplicateKey as exc:
        raise ValueError(f"{what}: {p!r}: {exc}") from None
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{what}: cannot read {p!r} as JSON "
                         f"({' '.join(str(exc).split())[:200]})") from None
    if isinstance(d, list) and len(d) == 1 and isinstance(d[0], dict):
        d = d[0]                                    # the one-item list 'systems --out' writes
    if isinstance(d, list) and len(d) > 1 and all(isinstance(x, dict) for x in d):
        raise ValueError(f"{what}: {p!r} holds a list of {len(d)} system descriptions; give a "
                         "file of one ('ti-spinorbit systems --show NAME --out PATH' writes one)")
    if not isinstance(d, dict):
        kind = _JSON_KINDS.get(type(d), type(d).__name__)
        raise ValueError(f"{what}: {p!r} holds a JSON {kind}, not an object; a system file is "
                         "one JSON object (BinarySystem.describe() output, as 'ti-spinorbit "
                         "systems --show NAME --out PATH' writes)")
    try:
        return BinarySystem.from_description(d, directory=os.path.dirname(os.path.abspath(p)))
    except RecursionError:
        raise ValueError(f"{what}: {p!r} holds a value nested too deeply") from None
    except (TypeError, ValueError, KeyError, AttributeError) as exc:
        text = " ".join(str(exc).split())
        raise ValueError(f"{what}: {p!r}: {text if len(text) <= 1000 else text[:997] + '...'}") \
            from None


def _scaled_body(body: Body, factor: float) -> Body:
    """The same shape with every mass element (hence mass, density and every inertia
    integral) multiplied by ``factor``. A uniform ellipsoid is rebuilt from its semi-axes
    and new mass, so that its description (semi-axes, mass) rebuilds it bit for bit."""
    if hasattr(body, "semi_axes"):
        return Ellipsoid(*body.semi_axes, mass=body.mass * factor, name=body.name,
                         order=body.order)
    scaled = Body(body.mass * factor, {k: v * factor for k, v in body.integrals.items()},
                  body.bounding_radius, body.name, body.order)
    for attribute in ("offset", "rotation", "volume"):      # the shape and its frame are kept
        if hasattr(body, attribute):
            object.__setattr__(scaled, attribute, getattr(body, attribute))
    if getattr(body, "density", None) is not None:         # not its source: that density
        object.__setattr__(scaled, "density", body.density * factor)   # is no longer the body's
    return scaled


def _default_order(body: Body) -> int:
    """The order a description without "order" gives a body: MAX_ORDER for a uniform
    ellipsoid, else the highest degree of its (non-zero) integrals, at least ROW_ORDER."""
    if hasattr(body, "semi_axes"):
        return MAX_ORDER
    return max([ROW_ORDER] + [sum(k) for k in body.integrals])


_dataclass_init = BinarySystem.__init__


def _volume(body: Body) -> float:
    """A body's volume, m³, for its bulk density: (4/3)π abc of an ellipsoid, the
    ``volume`` of a polyhedron; of any other Body, that of the uniform ellipsoid with its
    second moments (semi-axes sqrt(5 T^200 / m), sqrt(5 T^020 / m), sqrt(5 T^002 / m))."""
    if getattr(body, "volume", None) is not None:          # a polyhedron
        return float(body.volume)
    axes = getattr(body, "semi_axes", None) or \
        [math.sqrt(5.0 * body.integral(*k) / body.mass) for k in EXPONENTS_2]
    return 4.0 / 3.0 * math.pi * axes[0] * axes[1] * axes[2]


#: What ``orbital_period=`` is matched to: the Keplerian period of the masses, or the period
#: of the circular orbit under the figures' mutual force (:meth:`BinarySystem.circular_period`
#: at order 4), which an observed period measures.
PERIOD_MATCHES = ("keplerian", "circular")


def _init_with_period(self, primary, secondary, a, e, primary_spin_period=None, name="binary",
                      heliocentric_orbit=None, *, orbital_period=None, period_match="keplerian"):
    orbital_period = _to_plain("orbital_period", orbital_period, "s")
    if period_match not in PERIOD_MATCHES:
        raise ValueError(f"period_match must be one of {', '.join(PERIOD_MATCHES)} (got "
                         f"{show(period_match)})")
    if orbital_period is None:
        if period_match != "keplerian":
            raise ValueError("period_match needs orbital_period= (the observed period the "
                             "masses are scaled to)")
        return _dataclass_init(self, primary, secondary, a, e, primary_spin_period, name,
                               heliocentric_orbit)
    require_real("orbital_period", orbital_period)
    require_positive_scalar("orbital_period", orbital_period, 0.0, math.inf, "s")
    for label, body in (("primary", primary), ("secondary", secondary)):
        if not isinstance(body, Body):
            raise TypeError(f"{label} must be a ti_spinorbit Body (Sphere, Ellipsoid, Body), "
                            f"got {type(body).__name__}")
    a_m = require_positive_scalar("a", a, MIN_LENGTH, MAX_SEMIMAJOR_AXIS, "m")
    period, total = float(orbital_period), primary.mass + secondary.mass
    kepler = 2.0 * math.pi * math.sqrt(a_m ** 3 / (G * total))
    if period_match == "circular":
        # both masses × k: the force × k², the reduced mass × k, so the period × k^(-1/2),
        # as the Keplerian one: the same factor rule
        kepler = _dataclass_probe(primary, secondary, a_m, e).circular_period()
    ratio = kepler / period         # the matched period (Keplerian or circular) over P
    factor = ratio * ratio                    # a product overflows to inf, ** 2 would raise
    volume = _volume(primary) + _volume(secondary)
    if volume > 0.0:
        implied = factor * total / volume
        if not MIN_BULK_DENSITY <= implied <= MAX_BULK_DENSITY:
            def period_of(density):
                return 2.0 * math.pi * math.sqrt(a_m ** 3 / (G * density * volume))
            raise ValueError(
                f"orbital_period must lie in [{period_of(MAX_BULK_DENSITY):.6g}, "
                f"{period_of(MIN_BULK_DENSITY):.6g}] s for these bodies at a = {a_m:g} m, the "
                f"periods of a bulk density (m1 + m2)/(V1 + V2) in [{MIN_BULK_DENSITY:g}, "
                f"{MAX_BULK_DENSITY:g}] kg/m^3 (got {period:.6g} s, which implies "
                f"{implied:.3g} kg/m^3)")
    for label, body in (("primary", primary), ("secondary", secondary)):
        mass = body.mass * factor
        if not MIN_MASS <= mass <= MAX_MASS:
            raise ValueError(
                f"orbital_period {period:.6g} s scales both masses by {factor:.6g}, which makes "
                f"the {label}'s {mass:.6g} kg, outside [{MIN_MASS:g}, {MAX_MASS:g}] kg")
    scaled = [_scaled_body(b, factor) for b in (primary, secondary)]
    _dataclass_init(self, *scaled, a, e, primary_spin_period, name, heliocentric_orbit)
    object.__setattr__(self, "density_scale", factor)


def _dataclass_probe(primary, secondary, a, e):
    """The unscaled system, for its circular period (no name, spin or orbit needed)."""
    probe = object.__new__(BinarySystem)
    _dataclass_init(probe, primary, secondary, a, e)
    return probe


_init_with_period.__doc__ = _dataclass_init.__doc__
_init_with_period.__qualname__ = "BinarySystem.__init__"
BinarySystem.__init__ = _init_with_period
