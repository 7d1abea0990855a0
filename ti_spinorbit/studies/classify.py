"""Classify the trajectories of a surface of section: resonant, quasi-periodic or chaotic.

Physics (docs/physics.md §6, §8, §10; Wisdom, Peale & Mignard 1984; Naidu & Margot 2015 §2.3,
Figs. 4–5 and 7–9).
On the pericentre section (θ_p, θ̇_p/n) a regular orbit lies on invariant curves and a chaotic
one fills an area. A regular orbit whose θ_p stays in a bounded arc *librates*: it is
**resonant** (islands about θ_p = 0 near θ̇_p/n = 1, 3/2, 2, 5/2, ..., about 90° near 1/2). A
regular orbit whose θ_p runs round the whole 180° circle *circulates*: **quasi-periodic**.
Paper colours: resonant red, chaotic blue, quasi-periodic green (:data:`COLORS`).

The rule, per member; it needs only the section points in time order:

1. **Regular or chaotic: the order ratio.** On an invariant curve the section map is conjugate
   to a rotation (KAM; on a chain of q islands the q-th iterate rotates each island). Sorted
   by the phase k·ν mod 1, with ν the rotation frequency in cycles per pericentre passage, the
   points k = 0, 1, ... then join up into a short closed curve. A chaotic orbit has no such ν,
   and its sorted polygon is as long as one in random order. The *order ratio* is the polygon's
   length divided by its expected length in random order, N × (mean distance between two
   points). Typical values: ~0.01 for 500 points on one curve, up to ~0.06 on island chains,
   0.4-1 for chaotic orbits.
   * ν: the largest peaks of the Hann-windowed spectrum (Laskar's frequency analysis) of
     e^{2iθ_p} for a circulating trace, or of the whitened (θ_p, θ̇_p) about the trace's centre
     for a confined one.
   * Island chains: every q-th point is treated as one sequence, for strides q = 1..6 and the
     three strides after which the points return closest.
   * The ratio is the smallest found; the search stops once it is below half the threshold.
   A member is **chaotic** when the ratio exceeds ``order_ratio_chaotic`` (default 0.25).
2. **MEGNO** (optional, docs/physics.md §10). Where a finite ⟨Y⟩ is given, it overrides step 1:
   ⟨Y⟩ >= ``megno_chaotic`` (4) is chaotic, ⟨Y⟩ <= ``megno_regular`` (2.5) is regular
   (⟨Y⟩ → 2 on a torus, → 0 at a stable periodic orbit). In between, step 1 decides.
3. **Resonant or quasi-periodic: the largest gap.** A regular member is **resonant** when the
   largest empty arc between its sorted θ_p (on the 180° circle) exceeds ``libration_gap_deg``
   (default 30°, i.e. 60° of the doubled angle 2θ_p); otherwise it is **quasi-periodic**. The
   libration centre is the middle of the occupied arc; the half extent is half that arc, in
   deg. For an island this is the horizontal half extent of its trace, the excited-mode
   amplitude of docs/physics.md §9.1.
4. **Which resonance.** p is assigned only to a trace centred within ``centre_tolerance_deg``
   of θ_p = 0 (candidates p = 1, 3/2, 2, ...: Cayley H(p, e) > 0) or of 90° (p = 1/2:
   H(1/2, e) < 0), and only when its largest gap is at least ``dominant_gap_ratio`` times the
   second largest. Chains of a higher-order resonance, spread round the circle, get p = NaN.
   * The island's centre in θ̇_p/n (``libration_centre_thetadot``) is estimated as the middle
     of the θ̇_p range of the points near the trace's symmetry line.
   * That centre is *not* p. At pericentre the forced libration shifts it, strongly when ω0 is
     close to 1. For 1991 VH at a/b = 1.5 the 1:1 island sits at θ̇_p/n ≈ 0.45 and the 2:1
     island at ≈ 2.345; rounding to the nearest half-integer would give 1/2 and 5/2.
   * So the candidates' island centres are taken from the decoupled problem: a fixed Kepler
     orbit with ω0,eff² = ω0² m1/(m1 + m2) (docs/physics.md §8.1, §8.7), shooting for
     the symmetric periodic orbit. For 1991 VH (a/b = 1.5) this predicts 0.388 (1:1), 2.355
     (2:1), 2.732 (5:2) and 0.890 (1:2, at 90°); the coupled integration shows 0.45, 2.345,
     2.72 and 0.891. For 2003 YT1 and 2004 DC the p = 5/2 to 5 islands agree within 0.01,
     and the 1:1 island of YT1 sits at 0.439 against 0.432.
   * p is the candidate whose centre the trace *encloses*: it lies within the trace's θ̇_p
     range (else nearest to it); among several, the one nearest the estimated centre. A
     libration curve cannot enclose the centre of another p:1 resonance (inside it every orbit
     turns at the same mean rate), and the test also holds for a chain of secondary islands
     round a big island, whose points near the symmetry line may all lie on one side of it.
   * Without systems, the nominal centres p are used.

Members with fewer than ``min_points`` section points, or that stopped early (collision,
escape, ...), are **undetermined**.

Why not a dimension or roughness estimate (nearest-neighbour distances, local principal
components, neighbour divergence)? On these sections such measures fail at the folds of
crescent-shaped islands and on the thin loops of island chains, where points on opposite
branches are nearest neighbours. Regular orbits then look two-dimensional or divergent. The
phase order follows the dynamics instead of the geometry, so it is blind to both.

Evidence for the thresholds comes from 192 starts of 1991 VH (a/b = 1.5 and 1.06), 2003 YT1
and 2004 DC, run for 500 orbits. The truth came from a neighbour started 1e-9 away.
* With 500 points: regular order ratios <= 0.06, chaotic ones >= 0.47.
* With 200-250 points (the first part, or every second point): regular <= 0.14, chaotic
  >= 0.35.

Limits (what only a chaos indicator settles):
* A weakly chaotic orbit (a thin layer, or one that sticks to islands for the whole run) lies
  close to a curve over a few hundred orbits and is called regular.
* Below ~200 points, the order ratios of long island chains and of chaotic orbits begin to
  overlap.
* A chain that leaves no empty arc wider than ``libration_gap_deg`` (e.g. three long islands)
  counts as quasi-periodic.
"""

import math
import warnings
from dataclasses import dataclass, field
from functools import lru_cache
from typing import ClassVar, Dict

import numpy as np

from .. import display as _display
from .._validate import require_count, require_positive, require_range
from ..engine.accuracy import usable
from ..model.analytic import _decoupled_half_orbit, omega0_effective

#: Paper colour convention (Naidu & Margot 2015, Figs. 4–5 and 7–9).
COLORS = {"resonant": "red", "chaotic": "blue", "quasi-periodic": "green"}
LABELS = ("resonant", "quasi-periodic", "chaotic", "undetermined")

#: A trace whose largest empty arc of θ_p exceeds this (deg of θ_p on its 180° circle) librates.
LIBRATION_GAP_DEG = 30.0
#: Order ratio above which the points fill an area (chaotic).
ORDER_RATIO_CHAOTIC = 0.25
#: MEGNO ⟨Y⟩ at or above which a member is chaotic, whatever its points look like.
MEGNO_CHAOTIC = 4.0
#: MEGNO ⟨Y⟩ at or below which a member is regular, whatever its points look like.
MEGNO_REGULAR = 2.5
#: Fewer section points than this: undetermined.
MIN_POINTS = 64
#: A confined trace centred within this of θ_p = 0° or 90° (deg) gets a resonance p ...
CENTRE_TOLERANCE_DEG = 20.0
#: ... if its largest empty arc is at least this many times the second largest.
DOMINANT_GAP_RATIO = 2.0

# Order-ratio internals: spectral peaks tried per sequence; strides (island periods) tried:
# 1 .. _SMALL_STRIDES and the _EXTRA_STRIDES of closest return; fewest points per strided
# sequence; zero padding of the spectrum.
_PEAKS = 4
_SMALL_STRIDES = 6
_EXTRA_STRIDES = 3
_MIN_SEQUENCE = 16
_PAD = 8
# Above this many points the mean pair distance is estimated from this many random pairs.
_EXACT_PAIRS_MAX = 2000


@dataclass(repr=False)
class SectionClassification(_display.Readable):
    """Per-member classification of a surface of section (arrays of length N). Printed, a
    few lines (members per label, resonances, ranges; :mod:`ti_spinorbit.display`), never
    the arrays.

    ``classification`` one of "resonant", "quasi-periodic", "chaotic", "undetermined";
    ``classification_geometric`` the same from the section points alone (before any MEGNO);
    ``resonance_p`` p of the p:1 resonance (1 = synchronous, 1.5, 2, ...; 0.5), NaN unless
    resonant and centred on θ_p = 0° or 90°; ``libration_centre_deg`` middle of the occupied
    θ_p arc, deg in (−90, 90], and ``libration_half_extent_deg`` half its width, deg (the
    excited-mode amplitude), both NaN for traces that run round the circle;
    ``libration_centre_thetadot`` island centre in θ̇_p/n (see the module notes), NaN unless
    confined; ``mean_thetadot`` mean θ̇_p/n over the section points; ``largest_gap_deg``
    largest empty arc of θ_p, deg; ``order_ratio`` the regularity score (≲ 0.1 regular,
    ≳ 0.4 chaotic); ``count`` section points used; ``megno`` the indicator passed in (NaN if
    none). ``COLORS`` maps labels to the paper's colours."""

    classification: np.ndarray
    classification_geometric: np.ndarray
    resonance_p: np.ndarray
    libration_centre_deg: np.ndarray
    libration_half_extent_deg: np.ndarray
    libration_centre_thetadot: np.ndarray
    mean_thetadot: np.ndarray
    largest_gap_deg: np.ndarray
    order_ratio: np.ndarray
    count: np.ndarray
    megno: np.ndarray
    parameters: dict = field(default_factory=dict, repr=False)

    COLORS: ClassVar[Dict[str, str]] = COLORS

    @property
    def colors(self):
        """One colour per member in the paper's convention (grey when undetermined)."""
        return [COLORS.get(lab, "grey") for lab in self.classification]

    def counts(self) -> Dict[str, int]:
        """Number of members per label."""
        return {lab: int(np.sum(self.classification == lab)) for lab in LABELS}


def wrap_half_turn(angle_deg):
    """Map angles (deg) to (−90°, 90°]: the secondary's long axis is symmetric under 180°."""
    return 90.0 - np.mod(90.0 - np.asarray(angle_deg, dtype=np.float64), 180.0)


def horizontal_extent(theta_p_deg, center_deg=0.0):
    """Horizontal half extent of island traces, deg: max |θ_p − centre| over the last axis,
    with θ_p − centre wrapped to (−90°, 90°] (θ_p is defined modulo 180°). NaNs (padding)
    are ignored; a row without points gives NaN. ``center_deg`` broadcasts against the
    leading axes (one centre per member)."""
    theta = np.asarray(theta_p_deg, dtype=np.float64)
    center = np.asarray(center_deg, dtype=np.float64)[..., None]
    dev = np.abs(wrap_half_turn(theta - center))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows give NaN
        out = np.nanmax(dev, axis=-1)
    return float(out) if out.ndim == 0 else out


def libration_arc(theta_p_deg):
    """Occupied arc of one member's θ_p on the 180° circle.

    Returns (largest_gap_deg, center_deg, half_extent_deg, second_gap_deg): the largest empty
    arc between sorted θ_p, the middle of the occupied arc (the complement of that gap) in
    (−90, 90], half its width, and the second largest empty arc. NaN-padding is ignored; no
    points give NaNs."""
    theta = np.asarray(theta_p_deg, dtype=np.float64)
    theta = np.sort(np.mod(theta[np.isfinite(theta)], 180.0))
    if theta.size == 0:
        return math.nan, math.nan, math.nan, math.nan
    gaps = np.diff(np.append(theta, theta[0] + 180.0))
    i = int(np.argmax(gaps))
    gap = float(gaps[i])
    second = float(np.max(np.delete(gaps, i))) if gaps.size > 1 else 0.0
    start = theta[(i + 1) % theta.size]  # the occupied arc runs from here, counter-clockwise
    return gap, float(wrap_half_turn(start + 0.5 * (180.0 - gap))), 0.5 * (180.0 - gap), second


# ---- regularity: the order ratio ------------------------------------------------------------
def _coordinates(theta, thetadot, gap_deg):
    """Plane coordinates of a sequence in which distances are compared, and its signal for
    frequency analysis. Circulating: x = θ_p/180 on a unit circle, y = θ̇_p over its range,
    signal e^{2iθ_p}. Confined: (θ_p about the arc centre, θ̇_p) whitened by their covariance
    (a thin island becomes round), signal x + iy. Returns (x, y, periodic, signal)."""
    gap, center, _, _ = libration_arc(theta)
    if gap > gap_deg:
        pts = np.stack([wrap_half_turn(theta - center), thetadot], axis=1)
        pts -= pts.mean(axis=0)
        w, v = np.linalg.eigh(np.cov(pts.T))
        w = np.maximum(w, w.max() * 1e-12 + 1e-300)
        pts = pts @ v / np.sqrt(w)
        return pts[:, 0], pts[:, 1], False, pts[:, 0] + 1j * pts[:, 1]
    span = np.ptp(thetadot)
    y = (thetadot - thetadot.mean()) / span if span > 0 else np.zeros_like(thetadot)
    return theta / 180.0, y, True, np.exp(2j * np.radians(theta))


def _distance(x, y, periodic, i, j):
    dx = np.abs(x[i] - x[j])
    if periodic:
        dx = np.minimum(dx, 1.0 - dx)
    return np.hypot(dx, y[i] - y[j])


def _mean_pair_distance(x, y, periodic):
    n = x.size
    if n <= _EXACT_PAIRS_MAX:
        i, j = np.triu_indices(n, 1)
    else:  # deterministic sample of pairs
        rng = np.random.default_rng(0)
        i, j = rng.integers(0, n, (2, 200000))
        i, j = i[i != j], j[i != j]
    return float(np.mean(_distance(x, y, periodic, i, j)))


def _spectral_peaks(z, count):
    """Frequencies (cycles per point, in [−1/2, 1/2)) of the ``count`` largest local maxima of
    the Hann-windowed, zero-padded spectrum of z, refined by a parabola through log |Z|."""
    n = z.size
    window = 1.0 - np.cos(2.0 * np.pi * np.arange(n) / n)
    z = z - np.sum(window * z) / np.sum(window)
    m = _PAD * n
    spec = np.abs(np.fft.fft(window * z, m)) + 1e-300
    is_peak = (spec > np.roll(spec, 1)) & (spec >= np.roll(spec, -1))
    idx = np.flatnonzero(is_peak)
    idx = idx[np.argsort(spec[idx])[::-1][:count]]
    lo, mid, hi = (np.log(spec[(idx + s) % m]) for s in (-1, 0, 1))
    denom = lo - 2.0 * mid + hi
    shift = np.where(denom < 0, 0.5 * (lo - hi) / np.where(denom < 0, denom, -1.0), 0.0)
    return np.mod((idx + shift) / m + 0.5, 1.0) - 0.5


def _sequence_order(theta, thetadot, gap_deg):
    """(polygon length in the best phase order, expected length in random order) of one
    sequence of section points."""
    x, y, periodic, z = _coordinates(theta, thetadot, gap_deg)
    n = x.size
    mean_dist = _mean_pair_distance(x, y, periodic)
    if mean_dist == 0.0:  # every point the same: a periodic orbit
        return 0.0, 0.0
    k = np.arange(n)
    best = math.inf
    for nu in _spectral_peaks(z, _PEAKS):
        order = np.argsort(np.mod(k * nu, 1.0), kind="stable")
        best = min(best, float(np.sum(_distance(x, y, periodic, order, np.roll(order, -1)))))
    return best, n * mean_dist


def order_ratio(theta_p_deg, thetadot_p, libration_gap_deg=LIBRATION_GAP_DEG, stop_below=0.0):
    """Regularity score of one member's section points (in time order), see the module notes.

    Parameters
    ----------
    theta_p_deg, thetadot_p : array
        Section points in time order, θ_p in degrees (any branch) and θ̇_p/n; NaNs (padding)
        are dropped.
    libration_gap_deg : float
        Largest-gap threshold (deg of θ_p) that selects confined coordinates.
    stop_below : float
        Stop trying further strides once the ratio is below this (0: try them all).

    Returns
    -------
    float
        Length of the polygon through the points in the order of their rotation phase over its
        expected length in random order: ~(curve length)/(N × mean distance) ≪ 1 for points
        on invariant curves, ≈ 0.4-1 for area-filling (chaotic) points. NaN for < 8 points.
    """
    theta = np.asarray(theta_p_deg, dtype=np.float64)
    thetadot = np.asarray(thetadot_p, dtype=np.float64)
    ok = np.isfinite(theta) & np.isfinite(thetadot)
    theta, thetadot = np.mod(theta[ok], 180.0), thetadot[ok]
    n = theta.size
    if n < 8:
        return math.nan
    q_max = n // _MIN_SEQUENCE
    strides = list(range(1, min(_SMALL_STRIDES, q_max) + 1))
    strides += [q for q in _closest_return_strides(theta, thetadot, q_max, libration_gap_deg)
                if q not in strides]
    best = math.inf
    for q in strides:
        parts = [_sequence_order(theta[r::q], thetadot[r::q], libration_gap_deg) for r in range(q)]
        length, expected = (sum(v) for v in zip(*parts))
        best = min(best, 0.0 if expected == 0.0 else length / expected)
        if best < stop_below:
            break
    return best


def _closest_return_strides(theta, thetadot, q_max, gap_deg):
    """Strides q in [2, q_max] after which points return closest (median distance), best
    first: the island period of an island chain is among them."""
    if q_max < 2:
        return []
    x, y, periodic, _ = _coordinates(theta, thetadot, gap_deg)
    k = np.arange(x.size)
    med = [np.median(_distance(x, y, periodic, k[q:], k[:-q])) for q in range(2, q_max + 1)]
    return [int(q) + 2 for q in np.argsort(med, kind="stable")[:_EXTRA_STRIDES]]


# ---- which resonance ------------------------------------------------------------------------
@lru_cache(maxsize=64)
def _decoupled_centers(omega0, e, two_p_max, steps=1024, dw=0.005):
    """Pericentre spin rates (units of n) of the symmetric p:1 periodic orbits of the decoupled
    equation θ̈ = −(ω0²/2)(a/r)³ sin 2(θ − f) (time 1/n), for 2p = 1 .. two_p_max: the island
    centres on the section. By symmetry an orbit leaving pericentre at θ = θc (0, or 90° for
    p = 1/2) with θ̇ = w is periodic when θ(π) − θc = pπ at apocentre; w is found by RK4 over a
    grid of w (vectorised; f integrated alongside, df/dM = (1 + e cos f)²/(1 − e²)^{3/2}) and
    linear interpolation of the root nearest p. Returns a dict {2p: w} (NaN if none)."""
    w = np.arange(-1.0, 0.5 * two_p_max + 1.5, dw)
    out = {}
    for theta_c, two_ps in ((0.0, range(2, two_p_max + 1)), (0.5 * math.pi, (1,))):
        y = _decoupled_half_orbit(omega0, e, w, steps, theta0=theta_c)
        for two_p in two_ps:
            g = y[0] - theta_c - 0.5 * two_p * math.pi
            i = np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0))
            if i.size == 0:
                out[two_p] = math.nan
                continue
            roots = w[i] - g[i] * dw / (g[i + 1] - g[i])
            out[two_p] = float(roots[np.argmin(np.abs(roots - 0.5 * two_p))])
    return out


def island_centres(system, p_max=6.0):
    """Decoupled-problem island centres θ̇_p/n at pericentre for p = 1/2, 1, 3/2, ..., p_max,
    with ω0,eff² = ω0² m1/(m1 + m2) and the system's e (see the module notes).

    Returns a dict {p: θ̇_p/n}; NaN where no symmetric periodic orbit was found."""
    two_p_max = int(math.ceil(2.0 * p_max))
    centers = _decoupled_centers(round(float(omega0_effective(system)), 12),
                                 round(float(system.e), 12), two_p_max)
    return {0.5 * k: v for k, v in centers.items()}


def _center_thetadot(theta, thetadot, center_deg, half_extent_deg):
    """θ̇_p/n of an island centre: middle of the θ̇_p range of the points near the trace's
    symmetry line (where it crosses it above and below the centre): within a quarter of the
    half extent, else a half, else all points (a bent, crescent-shaped trace sags away from
    its centre towards its ends, so the narrowest window with a few points is best)."""
    offset = np.abs(wrap_half_turn(theta - center_deg))
    for fraction in (0.25, 0.5):
        near = offset <= fraction * half_extent_deg
        if np.count_nonzero(near) >= 4:
            return 0.5 * (float(np.min(thetadot[near])) + float(np.max(thetadot[near])))
    return 0.5 * (float(np.min(thetadot)) + float(np.max(thetadot)))


def _resonance_p(center_deg, center_thetadot, low, high, centers, tolerance_deg):
    """p whose island centre (of the right phase) the trace encloses, i.e. lies in the trace's
    θ̇_p range [low, high] or nearest to it; among several, the one nearest the estimated
    centre. NaN for an off-axis trace."""
    if abs(center_deg) <= tolerance_deg:
        candidates = {p: c for p, c in centers.items() if p >= 1.0}
    elif abs(center_deg) >= 90.0 - tolerance_deg:
        candidates = {p: c for p, c in centers.items() if p == 0.5}
    else:
        return math.nan
    candidates = {p: c for p, c in candidates.items() if np.isfinite(c)}
    if not candidates:
        return math.nan
    def key(p):
        c = candidates[p]
        return max(low - c, c - high, 0.0), abs(c - center_thetadot)

    return min(candidates, key=key)


# ---- entry points ---------------------------------------------------------------------------
def classify_points(theta_p, thetadot_p, systems=None, megno=None, failed=None, *,
                    libration_gap_deg=LIBRATION_GAP_DEG, order_ratio_chaotic=ORDER_RATIO_CHAOTIC,
                    megno_chaotic=MEGNO_CHAOTIC, megno_regular=MEGNO_REGULAR,
                    min_points=MIN_POINTS, centre_tolerance_deg=CENTRE_TOLERANCE_DEG,
                    dominant_gap_ratio=DOMINANT_GAP_RATIO, geometric=True):
    """Classify section traces given as arrays (see the module notes for the rule).

    Parameters
    ----------
    theta_p, thetadot_p : array, shape (N, count) or (count,)
        Section points in time order, θ_p in degrees, θ̇_p in units of n; NaN-padded.
    systems : BinarySystem, list of BinarySystem or None
        One per member (or one for all): island centres are then shifted by the decoupled
        forced libration before p is assigned; None assigns p from the nominal centres p.
    megno : array (N,) or None
        MEGNO ⟨Y⟩ per member (NaN where not known); overrides the geometric chaos decision
        beyond ``megno_chaotic`` / ``megno_regular``.
    failed : bool array (N,) or None
        Members that stopped early (collision, escape, ...): undetermined.
    libration_gap_deg : float
        Largest empty arc of θ_p (deg, of 180) above which a trace librates.
    order_ratio_chaotic : float
        Order ratio above which the points fill an area.
    megno_chaotic, megno_regular : float
        MEGNO thresholds (chaotic at or above, regular at or below).
    min_points : int
        Fewer section points: undetermined.
    centre_tolerance_deg : float
        A confined trace centred within this of 0° or 90° gets a resonance p.
    dominant_gap_ratio : float
        ... and only if its largest empty arc is at least this many times the second largest
        (one island, or a chain inside one island, rather than a chain round the circle).
    geometric : bool
        Compute the order ratio (and ``classification_geometric``) for every member. False skips it
        where MEGNO already decides (chaos maps: the order ratio costs ~10 ms per member of
        single-threaded NumPy, more than integrating it); those members get NaN and
        "undetermined" there, their ``label`` is unchanged.

    Returns
    -------
    SectionClassification
    """
    require_range("libration_gap_deg", libration_gap_deg, 0.0, 180.0, low_open=True)
    require_positive("order_ratio_chaotic", order_ratio_chaotic)
    require_range("megno_regular", megno_regular, 0.0, megno_chaotic, high_open=False)
    min_points = require_count("min_points", min_points, minimum=8)
    require_range("centre_tolerance_deg", centre_tolerance_deg, 0.0, 45.0)
    require_range("dominant_gap_ratio", dominant_gap_ratio, 1.0, math.inf)
    theta_all = np.atleast_2d(np.asarray(theta_p, dtype=np.float64))
    thetadot_all = np.atleast_2d(np.asarray(thetadot_p, dtype=np.float64))
    if theta_all.shape != thetadot_all.shape or theta_all.ndim != 2:
        raise ValueError(f"theta_p and thetadot_p must have the same shape (N, count) "
                         f"(got {np.shape(theta_p)} and {np.shape(thetadot_p)})")
    n = theta_all.shape[0]
    megno_arr = np.full(n, np.nan) if megno is None else np.broadcast_to(
        np.asarray(megno, dtype=np.float64), (n,)).copy()
    failed = np.broadcast_to(np.zeros(n, bool) if failed is None else np.asarray(failed, bool),
                             (n,))
    members = _systems_per_member(systems, n)
    finite = thetadot_all[np.isfinite(thetadot_all)]
    p_max = max(3.0, math.ceil(float(finite.max())) + 1.0) if finite.size else 3.0  # candidates

    out = {k: np.full(n, np.nan) for k in (
        "resonance_p", "libration_centre_deg", "libration_half_extent_deg",
        "libration_centre_thetadot", "mean_thetadot", "largest_gap_deg", "order_ratio")}
    label = np.full(n, "undetermined", dtype=object)
    label_geometric = np.full(n, "undetermined", dtype=object)
    count = np.zeros(n, dtype=int)
    for i in range(n):
        ok = np.isfinite(theta_all[i]) & np.isfinite(thetadot_all[i])
        theta, thetadot = np.mod(theta_all[i, ok], 180.0), thetadot_all[i, ok]
        count[i] = theta.size
        if theta.size:
            out["mean_thetadot"][i] = float(np.mean(thetadot))
        if failed[i] or theta.size < min_points:
            continue
        gap, center, half, second_gap = libration_arc(theta)
        out["largest_gap_deg"][i] = gap
        confined = gap > libration_gap_deg
        if confined:
            out["libration_centre_deg"][i] = center
            out["libration_half_extent_deg"][i] = half
            out["libration_centre_thetadot"][i] = _center_thetadot(theta, thetadot, center, half)
        chaotic = False
        if geometric or not (megno_arr[i] >= megno_chaotic or megno_arr[i] <= megno_regular):
            ratio = order_ratio(theta, thetadot, libration_gap_deg, 0.5 * order_ratio_chaotic)
            out["order_ratio"][i] = ratio
            chaotic = ratio > order_ratio_chaotic
            label_geometric[i] = _label(chaotic, confined)
        if megno_arr[i] >= megno_chaotic:
            chaotic = True
        elif megno_arr[i] <= megno_regular:
            chaotic = False
        label[i] = _label(chaotic, confined)
        if label[i] == "resonant" and gap >= dominant_gap_ratio * second_gap:
            # one island (or a chain inside one island), not a chain round the circle
            centers = (island_centres(members[i], p_max) if members[i] is not None
                       else {0.5 * k: 0.5 * k for k in range(1, int(2 * p_max) + 1)})
            out["resonance_p"][i] = _resonance_p(
                center, out["libration_centre_thetadot"][i], float(np.min(thetadot)),
                float(np.max(thetadot)), centers, centre_tolerance_deg)
    params = dict(libration_gap_deg=libration_gap_deg, order_ratio_chaotic=order_ratio_chaotic,
                  megno_chaotic=megno_chaotic, megno_regular=megno_regular,
                  min_points=min_points, centre_tolerance_deg=centre_tolerance_deg,
                  dominant_gap_ratio=dominant_gap_ratio, island_shift=systems is not None)
    return SectionClassification(classification=label, classification_geometric=label_geometric, count=count,
                                 megno=megno_arr, parameters=params, **out)


def classify_section(result, megno=None, island_shift=True, include_inaccurate=False,
                     **thresholds):
    """Classify every member of a :class:`~ti_spinorbit.studies.section.SectionResult`.

    Parameters
    ----------
    result : SectionResult
        From :func:`~ti_spinorbit.surface_of_section`.
    megno : array (N,) or None
        MEGNO ⟨Y⟩ per member, NaN where unknown (see :func:`classify_points`); by default the
        result's own ``megno`` (a run with ``indicators=True``), if any.
    island_shift : bool
        Assign p against the decoupled island centres of each member's system (default) rather
        than against the nominal centres p.
    include_inaccurate : bool
        Also classify members whose status is "inaccurate" (conservation drift above the
        limit, ``ti_spinorbit.engine.accuracy``); by default they are "undetermined" like members
        that stopped early.
    **thresholds
        ``libration_gap_deg``, ``order_ratio_chaotic``, ``megno_chaotic``, ``megno_regular``,
        ``min_points``, ``centre_tolerance_deg``, ``dominant_gap_ratio`` (see
        :func:`classify_points`).

    Returns
    -------
    SectionClassification

    See Also
    --------
    surface_of_section : the sections it classifies
    chaos_map : chaos by MEGNO alone, over a grid

    Examples
    --------
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45, 1.70], orbits=10, indicators=True)
    >>> labels = tso.classify_section(sos).classification
    >>> len(labels)
    2
    """
    failed = ~usable(result.status, include_inaccurate)
    systems = result.systems if island_shift else None
    if megno is None:
        megno = getattr(result, "megno", None)
    return classify_points(result.theta_p, result.thetadot_p, systems=systems, megno=megno,
                           failed=failed, **thresholds)


def _label(chaotic, confined):
    if chaotic:
        return "chaotic"
    return "resonant" if confined else "quasi-periodic"


def _systems_per_member(systems, n):
    if systems is None:
        return [None] * n
    if isinstance(systems, (list, tuple)):
        if len(systems) == n:
            return list(systems)
        if len(systems) == 1:
            return list(systems) * n
        raise ValueError(f"systems must give one system per member ({n}), got {len(systems)}")
    return [systems] * n

