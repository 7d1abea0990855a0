"""Section coordinates: inertial and apsidal (docs/physics.md §6.7).

The surface of section is recorded at every pericentre passage of the osculating mutual
orbit (R·V crossing zero from − to +, which is exactly the osculating true anomaly f
crossing 0, since R·V = (r/h) μ e sin f). Its angle θ_p, the secondary's long axis from the
line of centres, is therefore also the long axis from the osculating line of apsides: it is
the same in both coordinate systems. The spin coordinate differs:

* ``"inertial"`` (the package default): θ̇ is the secondary's inertial spin rate about the
  orbit normal, in units of n; θ in time series is measured from the inertial x axis (the
  initial pericentre direction). Well defined for every eccentricity.
* ``"apsidal"`` (Naidu & Margot 2015, §2.3-§4): θ is measured from the osculating line of
  apsides and θ̇ is its time derivative, θ̇_aps = θ̇_inertial − ϖ̇, with ϖ̇ the rotation rate
  of the osculating eccentricity vector about the orbit normal (:func:`apsidal_rate`).

ϖ̇ is exact, not averaged: with h = R × V, e = (V × h)/μ − R/r and a_p the perturbing
acceleration (true relative acceleration + μR/r³),

    de/dt = [a_p × h + V × (R × a_p)]/μ,        ϖ̇ = ĥ · (e × de/dt) / |e|².

It grows like 1/e as e → 0, where the apsidal line is ill-defined. Below
:data:`APSIDAL_MIN_ECCENTRICITY` the apsidal θ and θ̇ are NaN (with a RuntimeWarning), and
an apsidal start on an orbit with e below it is refused.

Initial conditions: ``BinarySystem.initial_state`` takes the inertial spin rate. With
``coordinates="apsidal"`` a start θ̇_p(0) is the apsidal rate and is converted with
θ̇_inertial(0) = θ̇_aps(0) + ϖ̇(0); ϖ̇(0) depends on the positions and attitudes only (the
force does not depend on the spins), so the conversion is explicit.
"""

import warnings

import numpy as np

from .._validate import MAX_SPIN

#: The section coordinate systems, and the package default (docs/design.md, "Section
#: coordinates": inertial is well defined at every e and is what the equations integrate).
COORDINATES = ("inertial", "apsidal")
DEFAULT_COORDINATES = "inertial"
#: Smallest osculating eccentricity at which apsidal coordinates are given. ϖ̇ ∝ |a_p|/e: below
#: 1e-3 (1999 KW4 has e = 0.0004) the apsidal line turns by tens of degrees per orbit under the
#: short-period forcing alone and θ̇_aps is dominated by ϖ̇, so it no longer describes the spin.
APSIDAL_MIN_ECCENTRICITY = 1e-3

#: Axis labels of the spin coordinate, per coordinate system (plots).
THETADOT_LABEL = {"inertial": r"$\dot\theta_p / n$ (inertial)",
                  "apsidal": r"$\dot\theta_p / n$ (apsidal)"}


def check_coordinates(coordinates, flag="coordinates"):
    """``coordinates`` if it is "inertial" or "apsidal", else a one-line ValueError naming
    ``flag`` (the parameter, or a command-line flag)."""
    if not isinstance(coordinates, str) or coordinates not in COORDINATES:
        raise ValueError(f"{flag} must be 'inertial' or 'apsidal' (got {coordinates!r})")
    return coordinates


def eccentricity_vector(R, V, mu=1.0):
    """Osculating eccentricity vector e = (V × h)/μ − R/r (same components as R, V)."""
    R, V = np.atleast_2d(R), np.atleast_2d(V)
    h = np.cross(R, V)
    return np.cross(V, h) / mu - R / np.linalg.norm(R, axis=1)[:, None]


def apsidal_rate(R, V, acceleration, mu=1.0):
    """Rate ϖ̇ of the osculating line of apsides about the orbit normal (rad per time unit,
    units of n in scaled units), exact for any perturbation (docs/physics.md §6.7).

    R, V: relative position and inertial velocity (M, 3); ``acceleration`` the true relative
    acceleration (M, 3), all in one frame's components; μ = G(m1 + m2). A Keplerian
    acceleration −μR/r³ gives exactly 0. Where e = 0 the result is ±inf or NaN."""
    R, V, acc = (np.atleast_2d(np.asarray(x, dtype=np.float64)) for x in (R, V, acceleration))
    r = np.linalg.norm(R, axis=1)[:, None]
    h = np.cross(R, V)
    e = eccentricity_vector(R, V, mu)
    a_p = acc + mu * R / r**3
    edot = (np.cross(a_p, h) + np.cross(V, np.cross(R, a_p))) / mu
    hhat = h / np.linalg.norm(h, axis=1)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.einsum("mi,mi->m", hhat, np.cross(e, edot)) / np.einsum("mi,mi->m", e, e)


def true_anomaly(R, V, mu=1.0):
    """Osculating true anomaly f (rad, in (−π, π]): the line of centres from the osculating
    eccentricity vector, about the orbit normal."""
    R, V = np.atleast_2d(R), np.atleast_2d(V)
    e = eccentricity_vector(R, V, mu)
    h = np.cross(R, V)
    hhat = h / np.linalg.norm(h, axis=1)[:, None]
    rhat = R / np.linalg.norm(R, axis=1)[:, None]
    return np.arctan2(np.einsum("mi,mi->m", hhat, np.cross(e, rhat)),
                      np.einsum("mi,mi->m", e, rhat))


def mask_small_eccentricity(e, *values, what="points"):
    """``values`` with NaN where the osculating eccentricity ``e`` is below
    APSIDAL_MIN_ECCENTRICITY, and a RuntimeWarning saying how many (NaN entries of ``e``, the
    padding of unrecorded slots, are left alone)."""
    e = np.asarray(e, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        bad = np.isfinite(e) & (e < APSIDAL_MIN_ECCENTRICITY)
    if not np.any(bad):
        return values
    warnings.warn(f"coordinates='apsidal': {int(np.count_nonzero(bad))} of "
                  f"{int(np.count_nonzero(np.isfinite(e)))} {what} have an osculating "
                  f"eccentricity below {APSIDAL_MIN_ECCENTRICITY:g}, where the apsidal line is "
                  "ill-defined; their apsidal θ and θ̇ are NaN (docs/physics.md §6.7)",
                  RuntimeWarning, stacklevel=3)
    return tuple(np.where(bad, np.nan, v) for v in values)


def check_apsidal_start(members):
    """Refuse (ValueError) an apsidal start on a member whose system's e is below
    APSIDAL_MIN_ECCENTRICITY, where the apsidal line is ill-defined."""
    ecc = np.array([s.e for s in members])
    if np.any(ecc < APSIDAL_MIN_ECCENTRICITY):
        k = int(np.argmin(ecc))
        raise ValueError(f"coordinates='apsidal' needs an orbit eccentricity >= "
                         f"{APSIDAL_MIN_ECCENTRICITY:g} (system {members[k].name!r} has e = "
                         f"{ecc[k]:g}); use coordinates='inertial'")


def apsidal_initial_states(members, rate, theta_p_deg, thetadot_p):
    """Initial states whose apsidal spin rate is ``thetadot_p``: θ̇_inertial(0) = θ̇_aps(0) +
    ϖ̇(0), rebuilt with ``BinarySystem.initial_state``. ``rate`` is ϖ̇(0) per member (units
    of n; ``engine.evaluation.apsidal_rates`` of the inertial starts: the force does not
    depend on the spins); the caller has refused near-circular orbits first
    (:func:`check_apsidal_start`, before any kernel is launched). Returns (y0, rate)."""
    spin = np.asarray(thetadot_p, dtype=np.float64) + rate
    if np.any(np.abs(spin) > MAX_SPIN):
        raise ValueError(f"thetadot_p + apsidal rate must lie in [-{MAX_SPIN:g}, {MAX_SPIN:g}] "
                         f"(got {spin[np.argmax(np.abs(spin))]:g})")
    theta = np.radians(np.asarray(theta_p_deg, dtype=np.float64))
    y = np.empty((len(members), 30))
    groups = {}                 # one vectorised start per system, as the member table does
    for k, s in enumerate(members):
        groups.setdefault(id(s), (s, []))[1].append(k)
    for s, sel in groups.values():
        y[sel] = s.initial_states(theta[sel], spin[sel])
    return y, rate
