"""Any initial state of the full two-body problem, in physical units and an inertial frame.

The paper's studies all start planar: the secondary at pericentre, both spins along the orbit
normal, the secondary's long axis at θ_p from the line of centres
(:meth:`ti_spinorbit.BinarySystem.initial_state`). :class:`InitialState` describes any other
start the way an observer or another code would write it, and converts it to the kernels'
scaled state (docs/physics.md §4.3):

* ``R``, ``V`` (m, m/s): the secondary's position and velocity relative to the primary, in
  the inertial frame;
* ``primary_attitude``, ``secondary_attitude``: rotation matrices taking body-frame
  components to inertial ones (body axes are the principal axes, x the longest; a unit
  quaternion ``(w, x, y, z)``, scalar first, is accepted too);
* ``primary_omega``, ``secondary_omega`` (rad/s): each body's angular velocity in its own
  body frame.

:func:`tilted_start` builds the paper's start with the secondary tilted by roll, pitch and
yaw angles relative to the orbit frame, off-axis spin components, an inclination of the
mutual orbit to the primary's equator and a tilt of the primary's pole (docs/physics.md
§6.8).

Decision: the inertial frame of an :class:`InitialState` is the caller's; inside the kernels
every vector is in the primary's body frame and the primary's attitude S1 carries the
inertial orientation (docs/physics.md §1.3). The scaled units stay those of the system
(length a, time 1/n of ``system.a``): a state whose osculating orbit differs from ``system.a``
is integrated correctly, and orbits are counted in the system's period 2π/n.

Rotations (decision): the three conversions here (:func:`quaternion_to_matrix`,
:func:`matrix_to_quaternion` by Shepperd's method, :func:`rotation` about a body axis) and the
Euler angles of ``model.attitude`` stay hand-written rather than scipy's
``scipy.spatial.transform.Rotation``: they are about forty lines, scipy is not a run-time
dependency of the package (only of its tests), and scipy's quaternions are scalar-last while
the kernels' and this module's are scalar-first (w, x, y, z), a classic source of silent
errors at the interface. scipy's ``Rotation`` is their oracle instead
(tests/test_rotations_oracle.py: agreement to 3e-15, half turns included).
"""

from dataclasses import dataclass

import numpy as np

from .._validate import MAX_PRIMARY_SPIN, MAX_SPIN, require_scalar, show
from ..units import to_plain

#: |R × V| / (|R| |V|) at or below which V counts as parallel to R (the orbit normal is then
#: rounding noise): :meth:`InitialState.kicked` applies only radial kicks there.
_DEGENERATE_NORMAL = 64 * np.finfo(np.float64).eps
#: Largest |AᵀA − 1| entry of an attitude matrix, and largest ||q| − 1| of a quaternion: a
#: rotation typed with 12 significant digits passes, a scaled or sheared matrix does not.
ORTHONORMAL_TOLERANCE = 1e-9

_FIELDS = ("R", "V", "primary_attitude", "primary_omega", "secondary_attitude",
           "secondary_omega")
#: Columns of a state row (:meth:`InitialState.to_row`, results' ``initial_states`` and
#: ``states``): R (3, m), V (3, m/s), primary attitude (9, row-major, body -> inertial),
#: primary ω (3, rad/s, its body frame), secondary attitude (9), secondary ω (3).
ROW_SLICES = {"R": slice(0, 3), "V": slice(3, 6), "primary_attitude": slice(6, 15),
              "primary_omega": slice(15, 18), "secondary_attitude": slice(18, 27),
              "secondary_omega": slice(27, 30)}
#: Unit text of a state row, for saved files.
ROW_UNIT = ("state row (docs/physics.md §6.8): R m (3), V m/s (3), primary attitude body->inertial "
            "(9, row-major), primary omega rad/s body frame (3), secondary attitude (9), "
            "secondary omega rad/s (3)")
#: Units the fields of an InitialState take a Quantity in (:mod:`ti_spinorbit.units`).
_FIELD_UNITS = {"R": "m", "V": "m/s", "primary_omega": "rad/s", "secondary_omega": "rad/s"}
_UNITS = {"R": "m", "V": "m/s", "primary_attitude": "1 (body -> inertial)",
          "primary_omega": "rad/s (primary body frame)",
          "secondary_attitude": "1 (body -> inertial)",
          "secondary_omega": "rad/s (secondary body frame)"}


def quaternion_to_matrix(q, name="quaternion"):
    """Rotation matrix of a unit quaternion ``(w, x, y, z)`` (scalar first, Hamilton
    convention: v' = q v q*), so that ``quaternion_to_matrix(q) @ v`` rotates v."""
    q = _finite(name, q, (4,))
    norm = np.linalg.norm(q)
    if abs(norm - 1.0) > ORTHONORMAL_TOLERANCE:
        raise ValueError(f"{name} must be a unit quaternion (w, x, y, z) with |q| = 1 within "
                         f"{ORTHONORMAL_TOLERANCE:g} (got |q| = {norm:.12g})")
    w, x, y, z = q / norm
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def matrix_to_quaternion(A):
    """Unit quaternion ``(w, x, y, z)`` with w >= 0 of a rotation matrix (Shepperd's method:
    divide by the largest of the four candidate components, so it is accurate at every
    angle)."""
    A = np.asarray(A, dtype=np.float64)
    t = np.trace(A)
    cand = np.array([1 + t, 1 + 2 * A[0, 0] - t, 1 + 2 * A[1, 1] - t, 1 + 2 * A[2, 2] - t])
    k = int(np.argmax(cand))
    s = 2.0 * np.sqrt(cand[k])
    if k == 0:
        q = [s / 4, (A[2, 1] - A[1, 2]) / s, (A[0, 2] - A[2, 0]) / s, (A[1, 0] - A[0, 1]) / s]
    elif k == 1:
        q = [(A[2, 1] - A[1, 2]) / s, s / 4, (A[0, 1] + A[1, 0]) / s, (A[0, 2] + A[2, 0]) / s]
    elif k == 2:
        q = [(A[0, 2] - A[2, 0]) / s, (A[0, 1] + A[1, 0]) / s, s / 4, (A[1, 2] + A[2, 1]) / s]
    else:
        q = [(A[1, 0] - A[0, 1]) / s, (A[0, 2] + A[2, 0]) / s, (A[1, 2] + A[2, 1]) / s, s / 4]
    q = np.array(q)
    return q if q[0] >= 0 else -q


def rotation(axis, angle):
    """Rotation matrix by ``angle`` (radians, right-handed) about body axis 0, 1 or 2."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    A = np.eye(3)
    A[i, i] = A[j, j] = c
    A[i, j], A[j, i] = -s, s
    return A


def _finite(name, value, shape, unit=""):
    value = to_plain(name, value, unit)          # a Quantity in ``unit`` (or dimensionless)
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be an array of real numbers of shape {shape} "
                        f"(got {show(value)})") from None
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape} (got shape {a.shape})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite (got {show(a)})")
    return a


def _attitude(name, value):
    """A body -> inertial rotation matrix from a 3x3 matrix or a unit quaternion."""
    if np.shape(value) == (4,):
        return quaternion_to_matrix(value, name)
    A = _finite(name, value, (3, 3))
    err = np.max(np.abs(A.T @ A - np.eye(3)))
    if err > ORTHONORMAL_TOLERANCE:
        raise ValueError(f"{name} must be orthonormal (a rotation matrix, body -> inertial): "
                         f"largest |AᵀA - 1| entry is {err:.3g}, allowed {ORTHONORMAL_TOLERANCE:g}")
    if np.linalg.det(A) < 0:
        raise ValueError(f"{name} must be a proper rotation with det +1 (got det = "
                         f"{np.linalg.det(A):.6g}: a reflection)")
    return A


@dataclass(frozen=True, repr=False, eq=False)
class InitialState:
    """One start of the full two-body problem (SI units, inertial frame; module docstring).

    Parameters
    ----------
    R, V : array_like or Quantity, shape (3,)
        Secondary's position (m) and velocity (m/s) relative to the primary, inertial frame.
    primary_attitude, secondary_attitude : array_like, shape (3, 3) or (4,)
        Body -> inertial rotation matrix, or a unit quaternion (w, x, y, z).
    primary_omega, secondary_omega : array_like or Quantity, shape (3,)
        Angular velocity in the body's own (principal) frame, rad/s (a Quantity in any
        angular rate, e.g. ``u.deg / u.day``).

    Checked on construction: shapes, finiteness, orthonormal with det +1. What needs the
    bodies (no contact, a bound orbit) is checked by :meth:`check` and by every entry point.

    Two states are equal (``==``) when every field is equal element by element (attitudes
    as matrices, so a quaternion and its matrix give equal states); comparing with anything
    else is ``NotImplemented`` (so ``state == 3`` is False). States are immutable (frozen,
    read-only arrays) and hashable, consistently with ``==``.

    Examples
    --------
    The paper's start (θ_p = 0°, θ̇_p = 0.43 n) with the secondary rolled by 5°, then kicked
    by 2.7 mm/s against its motion:

    >>> vh = tso.catalog.system("1991 VH")
    >>> start = vh.tilted_start(0.0, 0.43, roll=5.0)
    >>> start                                              # doctest: +ELLIPSIS
    InitialState(|R| = 3135 m, ..., secondary z axis 5° from the orbit normal)
    >>> kicked = start.kicked([0.0, -2.7e-3, 0.0])         # Δv in m/s, orbit frame
    >>> ts = tso.time_series(vh, orbits=2, initial_states=[start], samples_per_orbit=16)
    >>> ts.attitude_class_names
    ['3-D libration']
    """

    R: np.ndarray
    V: np.ndarray
    primary_attitude: np.ndarray
    primary_omega: np.ndarray
    secondary_attitude: np.ndarray
    secondary_omega: np.ndarray

    def __post_init__(self):
        for name in _FIELDS:
            value = getattr(self, name)
            v = _attitude(name, value) if name.endswith("attitude") else \
                _finite(name, value, (3,), _FIELD_UNITS[name])
            v.setflags(write=False)
            object.__setattr__(self, name, v)
        if not np.linalg.norm(self.R) > 0:
            raise ValueError("R must be a non-zero separation (m) (got R = 0)")

    def __eq__(self, other):
        if not isinstance(other, InitialState):
            return NotImplemented
        return all(np.array_equal(getattr(self, name), getattr(other, name))
                   for name in _FIELDS)

    def __hash__(self):
        # the floats' own hashes (hash(0.0) == hash(-0.0)), as == compares them; every
        # element is finite (checked on construction), so equal states hash alike
        return hash(tuple(self.to_row().tolist()))

    # ---- checks that need the bodies ---------------------------------------------------------
    def check(self, system, name="initial state"):
        """Raise ValueError (one line) if the bodies touch, the orbit is not bound, or a spin
        is beyond the bounds every other path holds (|ω₁| <= ``MAX_PRIMARY_SPIN`` n and
        |ω₂| <= ``MAX_SPIN`` n: the steps per orbit grow with
        the spin, so a faster one makes a run of unbounded length).

        Contact: |R| <= the sum of the bodies' bounding radii (the kernels' collision test).
        Bound: the two-point-mass orbital energy V²/2 − G(m1 + m2)/|R| must be negative; the
        mutual potential's higher orders change it by (size/|R|)² only, so this is the
        orbit's eccentricity < 1 test of the paper's set-up."""
        n = system.mean_motion
        for body, omega, limit in (("primary", self.primary_omega, MAX_PRIMARY_SPIN),
                                   ("secondary", self.secondary_omega, MAX_SPIN)):
            rate = float(np.linalg.norm(omega)) / n
            if not rate <= limit:
                raise ValueError(f"{name}: {body}_omega is {rate:.3g} n (|ω| = "
                                 f"{rate * n:.3g} rad/s); it must be at most {limit:g} n "
                                 f"({limit * n:.3g} rad/s) for {system.name!r}")
        r = float(np.linalg.norm(self.R))
        contact = system.primary.bounding_radius + system.secondary.bounding_radius
        if r <= contact:
            raise ValueError(f"{name}: the bodies overlap at the start: |R| = {r:.6g} m <= "
                             f"{contact:.6g} m, the sum of their bounding radii")
        gm = system.mean_motion ** 2 * system.a ** 3          # G (m1 + m2), Kepler's third law
        energy = 0.5 * float(self.V @ self.V) - gm / r
        if not energy < 0:
            raise ValueError(f"{name}: the mutual orbit is not bound (e >= 1): V²/2 - GM/|R| = "
                             f"{energy:.6g} J/kg must be < 0")
        return self

    # ---- conversions ----------------------------------------------------------------------
    def to_scaled(self, system, name="initial state"):
        """The kernels' 30-element scaled state (docs/physics.md §4.3) for ``system``, after
        :meth:`check` (whose errors start with ``name``)."""
        self.check(system, name=name)
        A1, A2 = self.primary_attitude, self.secondary_attitude
        S = A1.T @ A2                                   # secondary -> primary frame
        m_red = system.primary.mass * system.secondary.mass / system.total_mass
        x = np.concatenate([A1.T @ self.R, m_red * (A1.T @ self.V),
                            system.primary.moments * self.primary_omega,
                            S @ (system.secondary.moments * self.secondary_omega),
                            S.ravel(), A1.ravel()])
        return system.from_physical(x)

    @classmethod
    def from_scaled(cls, system, y):
        """Inverse of :meth:`to_scaled`: the physical state of a scaled 30-element state."""
        x = system.to_physical(np.asarray(y, dtype=np.float64))
        S, A1 = x[12:21].reshape(3, 3), x[21:30].reshape(3, 3)
        m_red = system.primary.mass * system.secondary.mass / system.total_mass
        return cls(R=A1 @ x[0:3], V=A1 @ x[3:6] / m_red,
                   primary_attitude=_nearest_rotation(A1),
                   primary_omega=x[6:9] / system.primary.moments,
                   secondary_attitude=_nearest_rotation(A1 @ S),
                   secondary_omega=(S.T @ x[9:12]) / system.secondary.moments)

    def kicked(self, dv):
        """This state after an impulsive velocity change of the secondary, e.g. an impact:
        ``dv`` = (radial, along-track, normal) in m/s, in the orbit frame of this state
        (:func:`orbit_frame`); a DART-like deflection is mostly along-track and negative. The
        bodies' attitudes and spins are unchanged (a kick at a later time: integrate to it,
        take ``InitialState.from_scaled(system, y)`` of the state reached, kick that).

        When V is parallel to R (a radial orbit, or V = 0) the orbit plane is undefined, so
        are the along-track and normal directions: a purely radial kick ``(dv_r, 0, 0)`` is
        still well defined (V + dv_r R/|R|) and is applied; any other is refused (ValueError
        naming ``dv``)."""
        dv = _finite("dv", dv, (3,))
        radial = self.R / np.linalg.norm(self.R)
        h = np.linalg.norm(np.cross(self.R, self.V))
        if h > _DEGENERATE_NORMAL * np.linalg.norm(self.R) * np.linalg.norm(self.V):
            change = orbit_frame(self.R, self.V) @ dv
        elif dv[1] == 0.0 and dv[2] == 0.0:
            change = dv[0] * radial          # radial: needs no orbit plane
        else:
            raise ValueError(f"dv = {show(dv.tolist())} m/s has along-track/normal components, "
                             "but V is parallel to R (|R x V| = 0: no orbit plane), so only a "
                             "radial kick dv = (dv_r, 0, 0) is defined for this state")
        return InitialState(R=self.R, V=self.V + change,
                            primary_attitude=self.primary_attitude, primary_omega=self.primary_omega,
                            secondary_attitude=self.secondary_attitude,
                            secondary_omega=self.secondary_omega)

    def to_row(self):
        """The 30 numbers of this state in the row layout :data:`ROW_SLICES` (SI)."""
        return np.concatenate([getattr(self, name).ravel() for name in _FIELDS])

    @classmethod
    def from_row(cls, row):
        """Inverse of :meth:`to_row`."""
        row = _finite("row", row, (30,))
        return cls(**{name: row[sl].reshape(3, 3) if name.endswith("attitude") else row[sl]
                      for name, sl in ROW_SLICES.items()})

    def angular_momentum(self, system):
        """Total angular momentum about the centre of mass, inertial frame (kg m²/s):
        m R × V + A1 I1 ω1 + A2 I2 ω2 (docs/physics.md §4.2)."""
        m_red = system.primary.mass * system.secondary.mass / system.total_mass
        return (m_red * np.cross(self.R, self.V)
                + self.primary_attitude @ (system.primary.moments * self.primary_omega)
                + self.secondary_attitude @ (system.secondary.moments * self.secondary_omega))

    def describe(self):
        """Plain lists with units, for saved files (``from_description`` reads it back)."""
        return {name: getattr(self, name).tolist() for name in _FIELDS} | {"units": dict(_UNITS)}

    @classmethod
    def from_description(cls, d):
        return cls(**{name: d[name] for name in _FIELDS})

    def __repr__(self):
        r = np.linalg.norm(self.R)
        tilt = np.degrees(np.arccos(np.clip(self.secondary_attitude[:, 2] @ _unit(
            np.cross(self.R, self.V)), -1, 1)))
        return (f"InitialState(|R| = {r:.6g} m, |V| = {np.linalg.norm(self.V):.6g} m/s, "
                f"secondary z axis {tilt:.3g}° from the orbit normal)")


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _nearest_rotation(A):
    """Closest rotation matrix (polar decomposition): removes the integrator's tiny
    orthonormality drift so a recorded state is a valid InitialState again."""
    u, _, vt = np.linalg.svd(A)
    return u @ vt


def orbit_frame(R, V):
    """Orbit frame of positions R and velocities V (any leading shape, ..., 3): a matrix
    (..., 3, 3) whose columns are radial R/|R|, along-track (normal × radial) and the orbit
    normal (R × V)/|R × V|."""
    R = np.asarray(R, dtype=np.float64)
    x = _unit(R)
    z = _unit(np.cross(R, V))
    return np.stack([x, np.cross(z, x), z], axis=-1)


def tilted_start(system, theta_p, thetadot_p, *, roll=0.0, pitch=0.0, yaw=0.0,
                 spin_x=0.0, spin_y=0.0, inclination=0.0, primary_tilt=0.0):
    """The paper's pericentre start, tilted out of the plane (docs/physics.md §6.8).

    Parameters
    ----------
    system : BinarySystem
    theta_p : float or Quantity
        Angle of the secondary's long axis from the line of centres, degrees (as in
        :func:`ti_spinorbit.surface_of_section`), or an angle Quantity (``u.rad``). A plain
        value that looks like radians gets the degree hint (:mod:`ti_spinorbit.units`).
    thetadot_p : float or Quantity
        The secondary's spin about its body z axis, units of the mean motion n; a Quantity
        dimensionless, in ``ti_spinorbit.units.n``, or an angular rate (rad/s), divided by
        the system's n.
    roll, pitch, yaw : float or Quantity
        Further rotation of the secondary, degrees, about the orbit frame's radial,
        along-track and normal axes, applied as yaw, then pitch, then roll in body axes
        (secondary attitude = orbit frame · Rz(θ_p + yaw) · Ry(pitch) · Rx(roll)).
    spin_x, spin_y : float or Quantity
        Off-axis components of the secondary's angular velocity in its body frame, units of n.
    inclination : float or Quantity
        Inclination of the mutual orbit to the primary's equator, degrees: the orbit is
        turned about the line of centres (the pericentre is its ascending node).
    primary_tilt : float or Quantity
        Tilt of the primary's pole from the initial orbit normal toward the line of centres
        (a rotation of the primary about the along-track axis), degrees: with
        ``inclination`` it sets the primary's obliquity to the mutual orbit in any direction.

    With every angle and off-axis spin zero this is exactly
    ``system.initial_state(radians(theta_p), thetadot_p)`` (the paper's start, §6.4).
    """
    theta_p = require_scalar("theta_p", theta_p, unit="deg")
    thetadot_p = require_scalar("thetadot_p", to_plain("thetadot_p", thetadot_p, "n", system=system),
                                -MAX_SPIN, MAX_SPIN, unit="(units of n)")
    ang = {k: np.radians(require_scalar(k, v, -360.0, 360.0, unit="deg")) for k, v in
           dict(roll=roll, pitch=pitch, yaw=yaw, inclination=inclination,
                primary_tilt=primary_tilt).items()}
    spins = [require_scalar(k, to_plain(k, v, "n", system=system), -MAX_SPIN, MAX_SPIN,
                            unit="(units of n)")
             for k, v in (("spin_x", spin_x), ("spin_y", spin_y))]
    n, a, e = system.mean_motion, system.a, system.e
    # the paper's pericentre start (docs/physics.md §6.4), then the orbit turned about x
    orbit = rotation(0, ang["inclination"])
    R = orbit @ np.array([a * (1.0 - e), 0.0, 0.0])
    V = orbit @ np.array([0.0, a * n * np.sqrt((1.0 + e) / (1.0 - e)), 0.0])
    A1 = rotation(1, ang["primary_tilt"])
    omega1 = 0.0 if system.primary_spin_period is None else 2 * np.pi / system.primary_spin_period
    A2 = (orbit @ rotation(2, np.radians(theta_p) + ang["yaw"]) @ rotation(1, ang["pitch"])
          @ rotation(0, ang["roll"]))
    return InitialState(R=R, V=V, primary_attitude=A1, primary_omega=[0.0, 0.0, omega1],
                        secondary_attitude=A2,
                        secondary_omega=n * np.array([spins[0], spins[1], thetadot_p]))


def as_scaled_states(system, states):
    """(N, 30) scaled states of a sequence of :class:`InitialState`, for one ``system`` or a
    list of one system per state (each state checked once; errors name the member)."""
    if isinstance(states, InitialState):
        states = [states]
    states = list(states)
    systems = system if isinstance(system, (list, tuple)) else [system] * len(states)
    out = []
    for k, (m, s) in enumerate(zip(systems, states)):
        if not isinstance(s, InitialState):
            raise TypeError(f"initial_states[{k}] must be an InitialState (got {show(s)})")
        out.append(s.to_scaled(m, name=f"initial_states[{k}]"))
    if not out:
        raise ValueError("initial_states must hold at least one InitialState")
    return np.stack(out)


def physical_rows(system, y):
    """State rows (:data:`ROW_SLICES`, SI, inertial) of scaled 3-D states ``y`` (..., 30) of
    ``system``, vectorised (no re-orthonormalisation: the attitudes are the integrator's,
    orthonormal to its tolerance). NaN rows stay NaN."""
    y = np.asarray(y, dtype=np.float64)
    x = system.to_physical(y)
    S = x[..., 12:21].reshape(y.shape[:-1] + (3, 3))
    A1 = x[..., 21:30].reshape(y.shape[:-1] + (3, 3))
    m_red = system.primary.mass * system.secondary.mass / system.total_mass
    R = np.einsum("...ij,...j->...i", A1, x[..., 0:3])
    V = np.einsum("...ij,...j->...i", A1, x[..., 3:6]) / m_red
    A2 = A1 @ S
    w1 = x[..., 6:9] / system.primary.moments
    w2 = np.einsum("...ji,...j->...i", S, x[..., 9:12]) / system.secondary.moments
    flat = y.shape[:-1] + (9,)
    return np.concatenate([R, V, A1.reshape(flat), w1, A2.reshape(flat), w2], axis=-1)
