"""Analytic spin-orbit theory of the decoupled problem, the yardstick for the simulations.

The secondary is a rigid body on a fixed Keplerian orbit about a point mass, spinning about
its short axis in the orbit plane (docs/physics.md §8.1):

    θ̈ + (ω0² n²/2) (a/r)³ sin 2(θ − f) = 0,     ω0² = 3 (B − A) / C,

θ the long axis from the pericentre direction, f the true anomaly, M the mean anomaly, n the
mean motion. Everything here is pure NumPy and closed form (or a spectrally converged
quadrature); frequencies and spin rates are in units of n, angles in radians, energies in J.

* ω0 of an ellipsoid and its inverse, and the coupled-problem correction
  ω0,eff² = ω0² m1/(m1 + m2) (docs/physics.md §8.7).
* Forced libration in synchronous rotation, ψ_A = 2e/(ω0² − 1) (Murray & Dermott 1999 §5;
  docs/physics.md §8.2).
* Cayley's coefficients H(p, e) (Cayley 1859 via Murray & Dermott 1999 §5.4, Table 5.1;
  docs/physics.md §8.3), resonance half-widths ω0 √|H(p, e)| (Wisdom, Peale & Mignard
  1984; Murray & Dermott 1999 §5.4; docs/physics.md §8.4).
* Resonance overlap ω0_RO = 1/(2 + √(14 e)) and the chaotic separatrix layer
  ΔE/E0 ≈ (14π e/ω0³) exp(−π/(2ω0)) (Wisdom, Peale & Mignard 1984, as used by Naidu &
  Margot 2015; docs/physics.md §8.5–8.6).
* Energy budgets per orbit that compete with chaotic spin-energy changes (docs/physics.md §9.4):
  tides (Murray & Dermott 1999 ch. 4–5; k2 of rubble piles from Goldreich & Sari 2009 or
  Jacobson & Scheeres 2011) and YORP (Naidu & Margot 2015), normalised by the separatrix
  energy E0 = n² ω0² C/4.
* Secular rates of the perturbed equations (docs/physics.md §13.6–13.9): the constant-time-lag
  tide's dω/dt, da/dt, de/dt (Hut 1981, in this package's normalisation κ = 3 k2 G M² R⁵), the
  constant-Q limit, BYORP's da/dt and the tide–BYORP equilibrium (Jacobson & Scheeres 2011);
  SI units.

Reference paper: Naidu & Margot 2015, AJ 149:80.

Examples
--------
>>> round(tso.analytic.omega0(1.5), 3)                 # a/b = 1.5
1.074
>>> round(tso.analytic.omega0_overlap(0.05), 4)        # ω0^RO = 1/(2 + √(14 e))
0.3525
"""

import math

import numpy as np

from .._validate import (require_count, require_finite, require_positive, require_range,
                         require_scalar)
from ..constants import AU, DEFAULT_F_YORP, DEFAULT_Q, K2_MODELS
from .perturbations import (BYORP, Q_RATE_FLOOR, YORP_CONVENTION, Tides, body_radius, yorp_torque,
                            yorp_turns_per_orbit)
from ..system.systems import G


#: Chaotic-layer coefficient as quoted by Naidu & Margot 2015 from Wisdom, Peale & Mignard 1984.
CHAOTIC_LAYER_COEFFICIENT_QUOTED = 14.0 * math.pi
#: Melnikov/Chirikov coefficient for the circulation-side border with E0 = n²ω0²C/4
#: (docs/physics.md §8.6).
CHAOTIC_LAYER_COEFFICIENT_MELNIKOV = 28.0 * math.pi



# Cayley series H(p, e) = Σ c_k e^k (docs/physics.md §8.3, re-derived with sympy),
# keyed by 2p so that half-integer p are exact dictionary keys.
_CAYLEY_SERIES = {
    -1: {3: 1 / 48, 5: 11 / 768},
    0: {},
    1: {1: -1 / 2, 3: 1 / 16, 5: -5 / 384},
    2: {0: 1.0, 2: -5 / 2, 4: 13 / 16, 6: -35 / 288},
    3: {1: 7 / 2, 3: -123 / 16, 5: 489 / 128},
    4: {2: 17 / 2, 4: -115 / 6, 6: 601 / 48},
    5: {3: 845 / 48, 5: -32525 / 768},
    6: {4: 533 / 16, 6: -13827 / 160},
}


def _result(x):
    """0-d arrays come back as Python floats, others as float64 arrays."""
    x = np.asarray(x, dtype=np.float64)
    return float(x) if x.ndim == 0 else x


def _eccentricity(e):
    require_range("e", e, 0.0, 1.0)
    return np.asarray(e, dtype=np.float64)


def _omega0(omega0):
    require_positive("omega0", omega0)
    return np.asarray(omega0, dtype=np.float64)


# ---- the libration frequency ω0 -------------------------------------------------------------
def omega0(a_over_b):
    """ω0 = sqrt(3 (q² − 1)/(q² + 1)) of a uniform ellipsoid spinning about its short axis.

    Parameters
    ----------
    a_over_b : float or array
        Elongation q = a/b >= 1 (dimensionless).

    Returns
    -------
    Free libration frequency in units of the mean motion n, in [0, sqrt(3)).
    """
    require_range("a_over_b", a_over_b, 1.0, np.inf)
    q2 = np.asarray(a_over_b, dtype=np.float64) ** 2
    return _result(np.sqrt(3.0 * (q2 - 1.0) / (q2 + 1.0)))


def omega0_from_moments(A, B, C):
    """ω0 = sqrt(3 (B − A)/C) from principal moments A <= B <= C (kg m², any common unit).

    C is the moment about the spin axis (the short axis); the result is in units of n."""
    for label, value in (("A", A), ("B", B), ("C", C)):
        require_positive(label, value)
    A, B, C = (np.asarray(v, dtype=np.float64) for v in (A, B, C))
    if np.any(A > B) or np.any(B > C):
        raise ValueError(f"principal moments must satisfy A <= B <= C (got A={A}, B={B}, C={C})")
    return _result(np.sqrt(3.0 * (B - A) / C))


def omega0_effective(system):
    """ω0 of the coupled problem: sqrt(3 (B − A)/C · m1/(m1 + m2)), in units of n.

    The torque on the secondary scales with G m1 while n² a³ = G (m1 + m2), so written with the
    true mean motion the decoupled equation carries the primary's mass fraction
    (docs/physics.md §8.7,
    docs/physics.md §8.7). ``system`` is a :class:`~ti_spinorbit.system.systems.BinarySystem`;
    A, B, C are its secondary's moments about x, y, z, and ω0 is ``system.omega0`` (which
    also covers a secondary whose long axis is y)."""
    fraction = system.primary.mass / system.total_mass
    return system.omega0 * math.sqrt(fraction)


def elongation_from_omega0(omega0):
    """Inverse of :func:`omega0`: a/b = sqrt((3 + ω0²)/(3 − ω0²)) for 0 <= ω0 < sqrt(3)."""
    require_range("omega0", omega0, 0.0, math.sqrt(3.0))
    w2 = np.asarray(omega0, dtype=np.float64) ** 2
    return _result(np.sqrt((3.0 + w2) / (3.0 - w2)))


# ---- forced libration -----------------------------------------------------------------------
def psi_A(omega0, e):
    """Forced libration amplitude ψ_A = 2e/(ω0² − 1), radians (first order in e).

    ψ = θ − f is the angle of the long axis from the line of centres (α in the package,
    docs/physics.md §6.2; the paper's angle diagram writes it with the opposite sign, θ + α =
    f), which leaves the amplitude unchanged. In synchronous
    rotation ψ = ψ_A sin M. For ω0 < 1 the value is negative (the response is in antiphase):
    the amplitude is |ψ_A|, larger than 2e. It diverges at the forced resonance ω0 = 1, which
    is rejected.

    Parameters
    ----------
    omega0 : float or array
        Free libration frequency in units of n, > 0 and != 1.
    e : float or array
        Orbital eccentricity in [0, 1).
    """
    w2 = _omega0(omega0) ** 2
    e = _eccentricity(e)
    if np.any(w2 == 1.0):
        raise ValueError("omega0 = 1 is the forced resonance: psi_A = 2e/(omega0^2 - 1) diverges")
    return _result(2.0 * e / (w2 - 1.0))


def forced_amplitude_mean_direction(omega0, e):
    """Amplitude of θ − M, the long axis from the uniformly rotating mean direction:
    2e ω0²/(ω0² − 1), radians. Same conventions and validity as :func:`psi_A`; it equals
    ψ_A + 2e, the optical libration 2e sin M of the line of centres added back."""
    return _result(np.asarray(psi_A(omega0, e)) * np.asarray(omega0, dtype=np.float64) ** 2)


# ---- Cayley coefficients and resonance widths -----------------------------------------------
def _two_p(p):
    p = np.asarray(p, dtype=np.float64)
    require_finite("p", p)
    two_p = np.round(2.0 * p)
    if np.any(np.abs(2.0 * p - two_p) > 1e-12):
        raise ValueError(f"p must be an integer or half-integer (spin rate p n), got {p!r}")
    return two_p


def cayley_H(p, e, n=4096):
    """Cayley's coefficient H(p, e), the Fourier coefficients of (a/r)³ exp(2if) in M:

        (a/r)³ e^{2if} = Σ_p H(p, e) e^{2ipM},
        H(p, e) = (1/2π) ∮ (a/r)³ cos(2f − 2pM) dM.

    Evaluated by the trapezoid rule in the true anomaly f (dM = (r/a)² df / sqrt(1 − e²)),
    which converges exponentially for this smooth periodic integrand (docs/physics.md §8.3). n = 4096 points give ~1e-15 for e <= 0.5; raise n as e approaches 1.

    Parameters
    ----------
    p : float or array
        Resonance p (spin rate p n), an integer or half-integer.
    e : float or array
        Eccentricity in [0, 1); broadcasts against p.
    n : int
        Number of quadrature nodes in f (>= 16).

    Returns
    -------
    H(p, e), dimensionless; H(1, 0) = 1 and H(p != 1, 0) = 0.
    """
    two_p = _two_p(p)
    e = _eccentricity(e)
    n = require_count("n", n, minimum=16)
    two_p, e = np.broadcast_arrays(two_p, e)
    two_p, e = two_p[..., None], e[..., None]
    f = 2.0 * np.pi * np.arange(n) / n
    E = 2.0 * np.arctan2(np.sqrt(1.0 - e) * np.sin(f / 2), np.sqrt(1.0 + e) * np.cos(f / 2))
    M = E - e * np.sin(E)
    # (a/r)³ dM = (a/r) df / sqrt(1 − e²), with a/r = (1 + e cos f)/(1 − e²)
    weight = (1.0 + e * np.cos(f)) / (1.0 - e**2) ** 1.5
    return _result(np.mean(weight * np.cos(2.0 * f - two_p * M), axis=-1))


def cayley_H_series(p, e):
    """Cayley's H(p, e) from its series in e (docs/physics.md §8.3, Murray & Dermott 1999
    Table 5.1), for p in {−1/2, 0, 1/2, 1, 3/2, 2, 5/2, 3} (scalar) and e in [0, 1) (array ok).

    The series stop at e⁵ or e⁶ (the next term is O(e⁷) or O(e⁸)); use :func:`cayley_H` for
    anything beyond small e."""
    two_p = _two_p(p)
    if two_p.ndim != 0 or int(two_p) not in _CAYLEY_SERIES:
        raise ValueError(f"p must be one of -1/2, 0, 1/2, 1, 3/2, 2, 5/2, 3 for the series "
                         f"(got {p!r}); use cayley_H for other p")
    e = _eccentricity(e)
    terms = _CAYLEY_SERIES[int(two_p)]
    return _result(sum((c * e**k for k, c in terms.items()), np.zeros_like(e)))


def resonance_half_width(p, omega0, e):
    """Half-width of the p n spin-orbit resonance, ω0 sqrt(|H(p, e)|), in units of n.

    From averaging near θ̇ = p n: γ = θ − pM obeys the pendulum γ̈ = −(ω0²/2) H(p, e) sin 2γ,
    whose separatrix reaches |θ̇ − p n| = ω0 sqrt(|H|) (Wisdom, Peale & Mignard 1984; Murray &
    Dermott 1999 §5.4; docs/physics.md §8.4). H is the quadrature :func:`cayley_H`.
    ``p`` (integer or half-integer), ``omega0`` (> 0) and ``e`` (in [0, 1)) broadcast."""
    w = _omega0(omega0)
    return _result(w * np.sqrt(np.abs(cayley_H(p, e))))


# ---- resonance overlap and the chaotic layer ------------------------------------------------
def omega0_overlap(e):
    """ω0_RO = 1/(2 + sqrt(14 e)): the synchronous (half-width ≈ ω0) and 3:2 (half-width
    ω0 sqrt(7e/2)) islands touch when ω0 (1 + sqrt(7e/2)) = 1/2 (Chirikov criterion as used by
    Wisdom, Peale & Mignard 1984; docs/physics.md §8.5). Units of n; e in [0, 1)."""
    e = _eccentricity(e)
    return _result(1.0 / (2.0 + np.sqrt(14.0 * e)))


def overlap_elongation(e, primary_mass_fraction=1.0):
    """Elongation a/b at which the 1:1 and 3:2 resonances overlap, from :func:`omega0_overlap`.

    With ``primary_mass_fraction`` = m1/(m1 + m2) < 1 the threshold is on the coupled
    problem's ω0,eff = ω0 sqrt(m1/(m1 + m2)) (see :func:`omega0_effective`), i.e. the ellipsoid
    must reach ω0 = ω0_RO / sqrt(m1/(m1 + m2)); the default 1 is the decoupled theory."""
    require_range("primary_mass_fraction", primary_mass_fraction, 0.0, 1.0,
                  low_open=True, high_open=False)
    threshold = np.asarray(omega0_overlap(e)) / np.sqrt(primary_mass_fraction)
    return elongation_from_omega0(threshold)


def chaotic_layer_half_width(omega0, e, coefficient=CHAOTIC_LAYER_COEFFICIENT_QUOTED):
    """Half-width of the chaotic layer about the synchronous separatrix, as ΔE/E0:

        ΔE/E0 ≈ (coefficient · e / ω0³) exp(−π/(2 ω0)),   E0 = n² ω0² C/4.

    The default coefficient 14π is the formula as quoted by Naidu & Margot 2015 from Wisdom,
    Peale & Mignard 1984; it is what the paper plots, so reproductions should use it, as an
    order-of-magnitude estimate.

    Caveat (docs/physics.md §8.6): a Melnikov/Chirikov derivation for the dominant
    p = 3/2 perturbation gives a kick W = 28π e ω0⁻² exp(−π/(2ω0)) per separatrix passage in
    units of E0 = n²ω0²C/4, and a layer border λW = 28π e ω0⁻³ exp(−π/(2ω0)) (λ = 1/ω0) on the
    circulation side, about twice that on the libration side. 14π is λW/2, which is what the
    same estimate gives if E0 is the full well depth n²ω0²C/2. Layers measured numerically are
    1.2–1.4 × the 28π form (circulation side) and ~2 × it (libration side): the 14π form
    underestimates by a factor 2.5–4. Pass ``coefficient=CHAOTIC_LAYER_COEFFICIENT_MELNIKOV``
    (28π) for the Melnikov estimate; measure the layer with ensembles for quantitative work.

    Parameters
    ----------
    omega0 : float or array
        Free libration frequency in units of n, > 0.
    e : float or array
        Eccentricity in [0, 1).
    coefficient : float
        Prefactor, > 0 (default 14π).

    Returns
    -------
    ΔE/E0, dimensionless (broadcast of omega0 and e).
    """
    w = _omega0(omega0)
    e = _eccentricity(e)
    require_positive("coefficient", coefficient)
    return _result(coefficient * e / w**3 * np.exp(-np.pi / (2.0 * w)))


# ---- energy budgets per orbit ---------------------------------------------------------------
def separatrix_energy(system, omega0=None):
    """E0 = n² ω0² C / 4, J: the energy scale of the synchronous separatrix.

    n is the system's mean motion (rad/s), C the secondary's largest principal moment
    (kg m²) and ω0 (units of n) the system's ``omega0`` unless given, e.g.
    ``omega0_effective(system)`` for the coupled-problem value."""
    w = system.omega0 if omega0 is None else omega0
    require_positive("omega0", w)
    C = float(np.max(system.secondary.moments))
    return system.mean_motion**2 * w**2 * C / 4.0


def secondary_radius(system):
    """R_s = sqrt(a_s b_s), m: the secondary's mean equatorial radius (docs/physics.md §7, ab = R_s²)."""
    axes = getattr(system.secondary, "semi_axes", None)
    if axes is None:
        raise ValueError("the secondary has no semi_axes (not an Ellipsoid): R_s = sqrt(a b) "
                         "is undefined; pass radius= (m) explicitly")
    return math.sqrt(axes[0] * axes[1])


def love_number_k2(radius, model="goldreich-sari"):
    """Rubble-pile Love number k2 of a body of radius ``radius`` (m), dimensionless.

    ``model``: "goldreich-sari", k2 = 1e-5 R[km] (Goldreich & Sari 2009), or
    "jacobson-scheeres", k2 = 2.5e-5 / R[km] (Jacobson & Scheeres 2011)."""
    require_positive("radius", radius)
    if model not in K2_MODELS:
        raise ValueError(f"k2_model must be one of {', '.join(K2_MODELS)} or a number > 0 "
                         f"(got {model!r})")
    return _result(K2_MODELS[model](np.asarray(radius, dtype=np.float64) / 1e3))


def tidal_energy_per_orbit(system, k2_model="goldreich-sari", Q=DEFAULT_Q, radius=None):
    """Tidal energy dissipated in the secondary per orbit, J (Murray & Dermott 1999;
    docs/physics.md §9.4):

        δE_tides = π (3/2) (k2/Q) (n⁴/G) R_s⁵.

    n⁴ R⁵/G has units s⁻⁴ m⁵ / (m³ kg⁻¹ s⁻²) = kg m² s⁻² = J. With n² a³ ≈ G m1 this is π times
    the tidal torque (3/2)(k2/Q) G m1² R_s⁵/a⁶; n here is the system's mean motion,
    n² a³ = G (m1 + m2).

    Parameters
    ----------
    system : BinarySystem
        Supplies n (rad/s) and, unless ``radius`` is given, R_s = sqrt(a_s b_s) of its
        ellipsoidal secondary.
    k2_model : str or float
        "goldreich-sari", "jacobson-scheeres" (see :func:`love_number_k2`) or k2 itself (> 0).
    Q : float
        Tidal quality factor, > 0 (default 100).
    radius : float, optional
        R_s in m, overriding the secondary's sqrt(a b).
    """
    R = secondary_radius(system) if radius is None else radius
    require_positive("radius", R)
    require_positive("Q", Q)
    if isinstance(k2_model, str):
        k2 = love_number_k2(R, k2_model)
    else:
        require_positive("k2_model", k2_model)
        k2 = float(k2_model)
    return math.pi * 1.5 * (k2 / Q) * system.mean_motion**4 / G * R**5


def yorp_energy_per_orbit(system, heliocentric_a_au, heliocentric_e, f_yorp=DEFAULT_F_YORP,
                          radius=None):
    """YORP energy input per orbit, J (Naidu & Margot 2015; docs/physics.md §9.4):

        δE_YORP = 2π R_s³ L_⊙ f_Y / (3 c d² sqrt(1 − e_⊙²)).

    Units: m³ W / (m s⁻¹ m²) = W s = J. 1/(d² sqrt(1 − e_⊙²)) is the time average of 1/r² over
    the heliocentric orbit. The paper reads it as the work of its YORP torque
    R_s³ L_⊙ f_Y/(6 c d² sqrt(1 − e_⊙²)) over two rotations of the secondary per mutual orbit
    (4π T); the same number is the work of the twice larger "one-turn" torque over one
    rotation (2π T). Either way δE_YORP is this formula (docs/physics.md §13.2,
    ``perturbations.YORP_CONVENTIONS``).

    Parameters
    ----------
    system : BinarySystem
        Supplies R_s = sqrt(a_s b_s) of its ellipsoidal secondary unless ``radius`` is given.
    heliocentric_a_au : float
        Heliocentric semimajor axis d of the binary, AU (> 0).
    heliocentric_e : float
        Heliocentric eccentricity e_⊙ in [0, 1).
    f_yorp : float
        YORP efficiency f_Y, > 0 (default 5e-4).
    radius : float, optional
        R_s in m, overriding the secondary's sqrt(a b).
    """
    R = secondary_radius(system) if radius is None else radius
    require_positive("radius", R)
    require_positive("heliocentric_a_au", heliocentric_a_au)
    require_range("heliocentric_e", heliocentric_e, 0.0, 1.0)
    require_positive("f_yorp", f_yorp)
    return (2.0 * math.pi * yorp_turns_per_orbit(YORP_CONVENTION)
            * yorp_torque(f_yorp, R, heliocentric_a_au * AU, heliocentric_e, YORP_CONVENTION))


def energy_budget(system, heliocentric_a_au, heliocentric_e, Q=DEFAULT_Q, f_yorp=DEFAULT_F_YORP,
                  omega0=None):
    """Chaotic, tidal and YORP energy changes per orbit for one system, normalised by E0.

    ω0 is the system's ``omega0`` unless given (e.g. ``omega0_effective(system)``); e is the
    system's mutual-orbit eccentricity. Returns a dict of floats:

    * ``omega0``, ``E0_J`` (:func:`separatrix_energy`);
    * ``chaotic_dE_over_E0``: the 14π layer half-width (:func:`chaotic_layer_half_width`),
      ``chaotic_dE_over_E0_melnikov``: the 28π one;
    * ``tidal_dE_over_E0_goldreich_sari``, ``tidal_dE_over_E0_jacobson_scheeres`` and the
      matching ``k2_goldreich_sari``, ``k2_jacobson_scheeres``;
    * ``yorp_dE_over_E0``;
    * ``R_s_m``, ``Q``, ``f_yorp``, ``heliocentric_a_au``, ``heliocentric_e`` (the inputs).
    """
    w = system.omega0 if omega0 is None else omega0
    E0 = separatrix_energy(system, w)
    R = secondary_radius(system)
    out = {"omega0": float(w), "E0_J": E0, "R_s_m": R, "Q": float(Q), "f_yorp": float(f_yorp),
           "heliocentric_a_au": float(heliocentric_a_au), "heliocentric_e": float(heliocentric_e),
           "chaotic_dE_over_E0": chaotic_layer_half_width(w, system.e),
           "chaotic_dE_over_E0_melnikov": chaotic_layer_half_width(
               w, system.e, CHAOTIC_LAYER_COEFFICIENT_MELNIKOV)}
    for model in K2_MODELS:
        key = model.replace("-", "_")
        out[f"k2_{key}"] = love_number_k2(R, model)
        out[f"tidal_dE_over_E0_{key}"] = tidal_energy_per_orbit(system, model, Q) / E0
    out["yorp_dE_over_E0"] = yorp_energy_per_orbit(system, heliocentric_a_au, heliocentric_e,
                                                   f_yorp) / E0
    return out


# ---- capture into resonance under a tidal torque ---------------------------------------------
def tidal_torque_factors(e):
    """Eccentricity functions of the orbit-averaged viscous (constant time-lag) tidal torque,
    ⟨N⟩ = −K [Ω(e) θ̇/n − N(e)] (Murray & Dermott 1999 §5.7; docs/physics.md §8.9):

        Ω(e) = ⟨(a/r)⁶⟩ = (1 + 3e² + 3e⁴/8) / (1 − e²)^{9/2},
        N(e) = ⟨(a/r)⁶ ḟ/n⟩ = (1 + 15e²/2 + 45e⁴/8 + 5e⁶/16) / (1 − e²)⁶,

    averages over the mean anomaly, dimensionless. N/Ω is the spin rate (units of n) at
    which the averaged torque vanishes (pseudo-synchronous rotation). ``e`` in [0, 1).
    Returns (Ω, N)."""
    e = _eccentricity(e)
    e2 = e * e
    omega = (1.0 + 3.0 * e2 + 0.375 * e2**2) / (1.0 - e2) ** 4.5
    big_n = (1.0 + 7.5 * e2 + 5.625 * e2**2 + 0.3125 * e2**3) / (1.0 - e2) ** 6
    return _result(omega), _result(big_n)


def tidal_offset_V(p, e):
    """V = p − N(e)/Ω(e), in units of n: the averaged viscous tidal torque near the p n
    resonance, written with γ = θ − pM, is ⟨N⟩ = −K Ω(e) (V + γ̇/n) (Murray & Dermott 1999
    §5.7; docs/physics.md §8.9). V > 0 means the tides spin the body down through the
    resonance; V <= 0 means they stop it (at N/Ω) before it gets there. ``p`` an integer or
    half-integer (> 0), ``e`` in [0, 1); they broadcast. Dimensionless."""
    two_p = _two_p(p)
    if np.any(two_p <= 0):
        raise ValueError(f"p must be a positive integer or half-integer (got {p!r})")
    omega, big_n = tidal_torque_factors(e)
    return _result(two_p / 2.0 - np.asarray(big_n) / np.asarray(omega))


def capture_probability(p, omega0, e, V=None):
    """Probability of capture into the p n spin-orbit resonance of a body despun through it
    by tides, dimensionless in [0, 1] (Goldreich & Peale 1966; Murray & Dermott 1999 §5.7,
    eq. 5.110; Naidu & Margot 2015 §7.1 for the 2:1 resonance; docs/physics.md §8.9):

        P_c = 2 / (1 + π V / (2 ω0 sqrt|H(p, e)|)),      capped at 1,

    with ω0 in units of n (ω0² = 3(B − A)/C), H Cayley's coefficient (:func:`cayley_H`) and
    V = p − N(e)/Ω(e) (:func:`tidal_offset_V`, viscous tides) unless ``V`` is given. It is the
    ratio of the energy the tides remove over one full circulation along the separatrix,
    4 K Ω ω0 sqrt|H| (per unit C), to the energy they remove on the upper half alone,
    K Ω (π V + 2 ω0 sqrt|H|): a spin that has just crossed the separatrix energy (uniformly
    distributed in that window) is captured if it cannot climb back out on the lower half.

    Parameters
    ----------
    p : float
        The resonance (spin rate p n), a positive integer or half-integer (2 for 2:1).
    omega0 : float or array
        Free libration frequency in units of n, > 0.
    e : float or array
        Eccentricity in [0, 1); H(p, e) must not vanish (e > 0 for p != 1).
    V : float or array, optional
        Offset V > 0 of the tidal torque (units of n); default from viscous tides. V <= 0
        (the tides never spin the body down to p n) is rejected.
    """
    w = _omega0(omega0)
    e = _eccentricity(e)
    if V is None:
        V = tidal_offset_V(p, e)
    V = np.asarray(V, dtype=np.float64)
    if not np.all(np.isfinite(V)) or np.any(V <= 0):
        raise ValueError(f"V = p - N(e)/Omega(e) must be > 0 (tides spinning the body down "
                         f"through the resonance; got {V!r}): lower e or raise p")
    H = np.abs(np.asarray(cayley_H(p, e)))
    width = w * np.sqrt(H)
    if np.any(H < 1e-14):               # the quadrature leaves ~1e-17 where H vanishes
        raise ValueError(f"e must be > 0 for p = {p!r}: H(p, 0) = 0, the resonance has no width")
    return _result(np.minimum(1.0, 2.0 / (1.0 + np.pi * V / (2.0 * width))))


# ---- nonlinear forced libration of the decoupled problem ------------------------------------
def _decoupled_half_orbit(omega0, e, w, steps, theta0=0.0):
    """RK4 over half an orbit (M from 0 to π, time 1/n) of θ̈ = −(ω0²/2)(a/r)³ sin 2(θ − f),
    f alongside (df/dM = (1 + e cos f)²/(1 − e²)^{3/2}), from θ = theta0, θ̇ = w (array) at
    pericentre; returns θ(π) and max |θ − f| over the half orbit (rad). Serves the relaxed
    amplitude here and the island centres of ``classify``."""
    one_minus_e2 = 1.0 - e * e
    w = np.asarray(w, dtype=np.float64)
    y = np.stack([np.full_like(w, theta0), w.copy(), np.zeros_like(w)])

    def rhs(s):
        theta, thetadot, f = s
        one_plus = 1.0 + e * np.cos(f)
        return np.stack([thetadot,
                         -0.5 * omega0**2 * (one_plus / one_minus_e2) ** 3 * np.sin(2.0 * (theta - f)),
                         one_plus**2 / one_minus_e2**1.5])

    h = math.pi / steps
    amp = np.zeros_like(y[0])
    for _ in range(steps):
        k1 = rhs(y)
        k2 = rhs(y + 0.5 * h * k1)
        k3 = rhs(y + 0.5 * h * k2)
        k4 = rhs(y + h * k3)
        y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        np.maximum(amp, np.abs(y[0] - y[2]), out=amp)
    return y[0], amp


def decoupled_relaxed_libration(omega0, e, guess=None, steps=512):
    """Centre of the synchronous island and relaxed libration amplitude of the DECOUPLED
    problem (docs/physics.md §8.1, §8.8), without the small-amplitude approximation of ψ_A.

    The island centre is the 1:1 periodic orbit symmetric about pericentre: θ = 0 at
    pericentre and θ = π at apocentre. Its pericentre spin rate w is found by shooting (RK4,
    ``steps`` steps per half orbit: relative error ~1e-9) on a grid of w in [−1, 3] step 0.01,
    taking the root of θ(π) − π nearest ``guess`` (default: the linear value
    (1 + e)²/(1 − e²)^{3/2} + ψ_A, or 1 + 2e at ω0 = 1), then zooming on it (64 points a
    launch, to 1e-10); its amplitude is max |θ − f| over the orbit (the angle α of the long
    axis from the line of centres). It tends to |ψ_A| = 2e/|ω0² − 1| as e → 0 away from
    ω0 = 1, and stays finite at ω0 = 1, where the pendulum's nonlinearity detunes the forced
    resonance.

    Parameters
    ----------
    omega0 : float
        Free libration frequency in units of n, in (0, 1.8] (every ellipsoid has ω0 < √3; at
        ω0 = 2 the half orbit is a whole free period and the shooting condition degenerates).
        Use ω0,eff (:func:`omega0_effective`) for the coupled problem's estimate.
    e : float
        Eccentricity in [0, 1).
    guess : float, optional
        Pericentre spin rate θ̇_p/n near which to take the root (picks the branch where the
        forced response has several periodic orbits).

    Returns
    -------
    (center, amplitude): θ̇_p/n at pericentre (units of n) and the amplitude (rad); NaN, NaN
    when no symmetric 1:1 orbit exists in θ̇_p/n ∈ [−1, 3].
    """
    require_range("omega0", omega0, 0.0, 1.8, low_open=True, high_open=False)
    w0 = float(omega0)
    e = float(_eccentricity(e))
    steps = require_count("steps", steps, minimum=64)
    if guess is None:
        base = (1.0 + e) ** 2 / (1.0 - e * e) ** 1.5
        guess = base + (2.0 * e / (w0 * w0 - 1.0) if w0 != 1.0 else 0.0)
    grid = np.arange(-1.0, 3.0, 0.01)
    g = _decoupled_half_orbit(w0, e, grid, steps)[0] - math.pi
    i = np.flatnonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)
    if i.size == 0:
        return math.nan, math.nan
    roots = grid[i] - g[i] * 0.01 / (g[i + 1] - g[i])
    k = i[int(np.argmin(np.abs(roots - guess)))]
    low, high = grid[k], grid[k + 1]
    while high - low > 1e-10:                       # zoom: 64 points across the bracket
        x = np.linspace(low, high, 64)
        gx = _decoupled_half_orbit(w0, e, x, steps)[0] - math.pi
        j = np.flatnonzero(np.sign(gx[:-1]) * np.sign(gx[1:]) <= 0)
        if j.size == 0:
            break
        low, high = x[j[0]], x[j[0] + 1]
    center = 0.5 * (low + high)
    amp = _decoupled_half_orbit(w0, e, np.array([center]), steps)[1][0]
    return float(center), float(amp)


# ---- secular rates of the perturbed problem (docs/physics.md §13.6–13.9) ---------------------
# Hut (1981) eccentricity functions of e², f_k(0) = 1 (docs/physics.md §13.7).
def hut_f1(e2):
    """f1(e²) = 1 + 31/2 e² + 255/8 e⁴ + 185/16 e⁶ + 25/64 e⁸ (Hut 1981)."""
    return 1.0 + e2 * (31 / 2 + e2 * (255 / 8 + e2 * (185 / 16 + e2 * 25 / 64)))


def hut_f2(e2):
    """f2(e²) = 1 + 15/2 e² + 45/8 e⁴ + 5/16 e⁶ (Hut 1981)."""
    return 1.0 + e2 * (15 / 2 + e2 * (45 / 8 + e2 * 5 / 16))


def hut_f3(e2):
    """f3(e²) = 1 + 15/4 e² + 15/8 e⁴ + 5/64 e⁶ (Hut 1981)."""
    return 1.0 + e2 * (15 / 4 + e2 * (15 / 8 + e2 * 5 / 64))


def hut_f4(e2):
    """f4(e²) = 1 + 3/2 e² + 1/8 e⁴ (Hut 1981)."""
    return 1.0 + e2 * (3 / 2 + e2 / 8)


def hut_f5(e2):
    """f5(e²) = 1 + 3 e² + 3/8 e⁴ (Hut 1981)."""
    return 1.0 + e2 * (3.0 + e2 * 3 / 8)


def _check_tides(tides):
    if not isinstance(tides, Tides):
        raise TypeError(f"tides must be a ti_spinorbit.Tides object (got {type(tides).__name__})")
    return tides


def _tide_inputs(system, tides, omega, e, a):
    """(κ N m⁷, m_red kg, C kg m², a m, n rad/s, e, ω rad/s) of a tide on its body, checked."""
    _check_tides(tides)
    omega = require_scalar("omega", omega, unit="rad/s")
    e = require_scalar("e", e, 0.0, 1.0, high_open=True)
    a = system.a if a is None else require_scalar("a", a, 0.0, math.inf, low_open=True, unit="m")
    body = getattr(system, tides.body)
    m1, m2 = system.primary.mass, system.secondary.mass
    n = math.sqrt(G * (m1 + m2) / a ** 3)
    # the spin axis is the body's z axis (kernels/perturb.py: Ω_b × R with Ω_b along z)
    return tides.coefficient(system), m1 * m2 / (m1 + m2), float(body.moments[2]), a, n, e, omega


def _effective_lag(system, tides, omega, n):
    """The time lag the kernels use, s: Δt for a constant-time-lag tide; for constant Q,
    (1/2Q)/sqrt((ω − n)² + (ε n0)²), ε = kernels.perturb.Q_RATE_FLOOR and n0 the system's
    (initial) mean motion, the circular orbit's bulge rate ω − n regularised as in the
    kernels."""
    if tides.time_lag is not None:
        return tides.time_lag
    Q = tides.Q if tides.Q is not None else DEFAULT_Q
    floor = Q_RATE_FLOOR * system.mean_motion
    return 0.5 / Q / math.sqrt((omega - n) ** 2 + floor ** 2)


def _circular_only(tides, e, what):
    if tides.time_lag is None and e != 0.0:
        raise ValueError(f"e must be 0 for the {what} of a constant-Q tide (its lag varies along "
                         f"an eccentric orbit; got e = {e:g}); use a time_lag tide")


def tidal_despin_rate(system, tides, omega, e=0.0, a=None):
    """Orbit-averaged dω/dt of the body that ``tides`` deforms, rad s⁻², in the weak-tide limit
    (the orbit is a fixed Kepler ellipse over one period; docs/physics.md §13.7):

        dω/dt = −κ Δt / (C a⁶) (1 − e²)⁻⁶ [(1 − e²)^{3/2} f5(e²) ω − f2(e²) n],

    κ = 3 k2 G M² R⁵ × strength (:meth:`Tides.coefficient`, M the other body's mass, R the
    deformed body's radius), C the body's moment about its spin (z) axis, n the mean motion
    sqrt(G (m1 + m2)/a³) and f2, f5 Hut's (1981) functions. On a circular orbit this is
    −3 k2 G M² R⁵ Δt (ω − n)/(a⁶ C). A constant-Q tide (circular orbits only) has
    Δt = (1/2Q)/|ω − n| (with the kernels' floor on |ω − n|, docs/physics.md §13.8), i.e.
    dω/dt = −(3/2)(k2/Q) G M² R⁵ sign(ω − n)/(a⁶ C).

    Parameters
    ----------
    system : BinarySystem
        Masses, the deformed body's moment C and radius, and a unless given.
    tides : Tides
        Which body deforms, k2, Δt or Q, radius, strength.
    omega : float
        The body's spin rate about the orbit normal, rad/s.
    e : float
        Orbital eccentricity in [0, 1) (0 for a constant-Q tide).
    a : float, optional
        Semimajor axis, m (default the system's).
    """
    kappa, _, C, a, n, e, omega = _tide_inputs(system, tides, omega, e, a)
    _circular_only(tides, e, "despin rate")
    lag = _effective_lag(system, tides, omega, n)
    e2 = e * e
    s = 1.0 - e2
    return -kappa * lag / (C * a ** 6) * s ** -6 * (s ** 1.5 * hut_f5(e2) * omega - hut_f2(e2) * n)


def tidal_orbit_rates(system, tides, omega, e=0.0, a=None):
    """Orbit-averaged (da/dt m s⁻¹, de/dt s⁻¹) of the relative orbit under ``tides`` in the
    weak-tide limit (Hut 1981, in this package's normalisation; derivation and
    the mapping of Hut's constants in docs/physics.md §13.6–13.7):

        da/dt = −(2 κ Δt / (m_red a⁷)) (1 − e²)^{−15/2} [f1(e²) − (1 − e²)^{3/2} f2(e²) ω/n],
        de/dt = −(9 κ Δt e / (m_red a⁸)) (1 − e²)^{−13/2} [f3(e²) − (11/18)(1 − e²)^{3/2} f4(e²) ω/n],

    m_red = m1 m2/(m1 + m2), κ and the rest as in :func:`tidal_despin_rate`. A constant-Q tide
    (circular orbits only, de/dt = 0) gives

        da/dt = 3 (k2/Q) (M/m_b) sqrt(G (m1 + m2)) R⁵ a^{−11/2} sign(ω − n) × strength,

    M the other body's mass and m_b the deformed body's (regularised near ω = n as in the
    kernels). Parameters as for :func:`tidal_despin_rate`."""
    kappa, m_red, _, a, n, e, omega = _tide_inputs(system, tides, omega, e, a)
    _circular_only(tides, e, "orbit rates")
    lag = _effective_lag(system, tides, omega, n)
    e2 = e * e
    s = 1.0 - e2
    x = omega / n
    da = -2.0 * kappa * lag / (m_red * a ** 7) * s ** -7.5 * (hut_f1(e2) - s ** 1.5 * hut_f2(e2) * x)
    de = -9.0 * kappa * lag * e / (m_red * a ** 8) * s ** -6.5 * (
        hut_f3(e2) - 11.0 / 18.0 * s ** 1.5 * hut_f4(e2) * x)
    return da, de


def byorp_da_dt(system, byorp, a=None):
    """da/dt of a circular orbit under ``byorp``, m s⁻¹ (McMahon & Scheeres 2010; Jacobson &
    Scheeres 2011; docs/physics.md §13.8):

        da/dt = 2 F_B / (m_s n),

    F_B = :meth:`BYORP.force` (N, strength included), m_s the secondary's mass and
    n = sqrt(G (m1 + m2)/a³); a is the system's unless given (m). F_B does not depend on a,
    so da/dt grows as a^{3/2}."""
    if not isinstance(byorp, BYORP):
        raise TypeError(f"byorp must be a ti_spinorbit.BYORP object (got {type(byorp).__name__})")
    a = system.a if a is None else require_scalar("a", a, 0.0, math.inf, low_open=True, unit="m")
    n = math.sqrt(G * system.total_mass / a ** 3)
    return 2.0 * byorp.force(system) / (system.secondary.mass * n)


def tide_byorp_equilibrium(system, tides, byorp):
    """Semimajor axis, m, where the constant-Q tide raised on the primary (expanding the orbit
    of a primary spinning faster than n) balances a contracting BYORP (Jacobson & Scheeres
    2011; docs/physics.md §13.9):

        3 (k2/Q) (m_s/m_p) sqrt(G M) R_p⁵ a^{−11/2} × s_T = −2 F_B a^{3/2} / (m_s sqrt(G M))
        ⇒  a_eq⁷ = 3 (k2/Q) s_T G M m_s² R_p⁵ / (2 m_p |F_B|),

    M = m_p + m_s, s_T the tide's strength and F_B = :meth:`BYORP.force` (strength included),
    so scaling both by one factor leaves a_eq unchanged. The equilibrium is stable: inside it
    the tide wins, outside BYORP.

    Parameters
    ----------
    system : BinarySystem
        Masses and the primary's radius.
    tides : Tides
        A constant-Q tide (``Q=``, or neither Q nor time_lag: Q = 100) on the primary.
    byorp : BYORP
        With a negative coefficient (a contracting BYORP), else there is no equilibrium.
    """
    _check_tides(tides)
    if not isinstance(byorp, BYORP):
        raise TypeError(f"byorp must be a ti_spinorbit.BYORP object (got {type(byorp).__name__})")
    if tides.body != "primary":
        raise ValueError(f"tides.body must be 'primary' for the tide-BYORP equilibrium (got "
                         f"{tides.body!r})")
    if tides.time_lag is not None:
        raise ValueError("tides must be a constant-Q tide (Q=, not time_lag=) for the "
                         "tide-BYORP equilibrium of Jacobson & Scheeres (2011)")
    F = byorp.force(system)
    if not F < 0:
        raise ValueError(f"byorp.coefficient must be < 0 (a contracting BYORP) for a tide-BYORP "
                         f"equilibrium (got {byorp.coefficient:g})")
    Q = tides.Q if tides.Q is not None else DEFAULT_Q
    mp, ms = system.primary.mass, system.secondary.mass
    Rp = body_radius(system, "primary", tides.radius)
    k2 = tides.love_number(system)
    a7 = 3.0 * (k2 / Q) * tides.strength * G * (mp + ms) * ms ** 2 * Rp ** 5 / (2.0 * mp * abs(F))
    return a7 ** (1.0 / 7.0)
