"""Paper §8 (Naidu & Margot 2015, text; script study16): beyond the paper, Earth flybys of a 1991 VH-like binary: the change of the mutual orbit and of the secondary's spin state against q/R_Earth.

Why "§8". The paper's discussion (its §8) turns to the secondary of 1991 VH, which is
observed not to rotate synchronously, and to what could have excited it; a close planetary
encounter is one such excitation (Fang & Margot 2012, AJ 143, 24). The paper computes no
encounter; this study does, with the planet in the equations of motion (``tso.Flyby``,
docs/physics.md §13.12), as study14 puts §8's tides into them. It is named by the section
whose question it takes up.

Set-up (decisions):

* The binary: the catalogue's "1991 VH" (spherical primary R = 600 m, secondary ellipsoid
  293.9 × 196 × 190 m, a/b = 1.5, a = 3300 m, e = 0.05, P = 32.5 h). The secondary starts at
  the paper's θ_p = 0, θ̇_p/n = 1 (pericentre, long axis on the line of centres, spinning at
  the mean motion; ``MEMBERS`` encounters): without the planet that start librates in the
  synchronous island with an amplitude of 50°, at its upper rim (the island's centre is at
  θ̇_p/n = 0.452, inertial), and stays in the plane: tilted by 0.014° it stays below 0.05°
  for 150 orbits (checked when this study was set up). Every change of spin state below is
  therefore the encounter's doing. A tidally relaxed secondary would sit at the island's
  centre instead (the least libration, 33.6°: the forced libration of a/b = 1.5 at e =
  0.05), so the first ``RELAXED`` of the same encounters are run from there too, found by
  the script (``island_centre``), in the same launch. The 3-D model (the flybys are
  inclined), order 4 (the paper's), DOP853.
* The planet: Earth (``tso.Flyby("Earth", ...)``), on its hyperbola relative to the
  barycentre. v∞ FIXED at 1991 VH's own Öpik encounter speed with Earth, v∞ = v_E U,
  U² = 3 − 1/a − 2 sqrt(a (1 − e²)) cos i, from the catalogue's heliocentric orbit (a =
  1.137 AU, e = 0.144, i = 13.91°; Earth on a circular orbit, v_E = 29.78 km/s): 7.99 km/s.
  A fixed v∞ keeps q the only distance scale: in the impulsive regime the tidal velocity
  kick is ∝ 1/(q² v_q) (v_q the speed at closest approach), so the thresholds below move
  roughly as v_q^(−1/2) for another encounter speed (not run).
* The ensemble: ONE launch of ``MEMBERS`` encounters (quick mode ``QUICK_MEMBERS``), each
  member its own flyby (per-member fields of ``tso.Flyby``): q log-uniform in
  [2, 80] R_E (R_E = 6371 km; beyond 40 R_E so that the fractions reach the unperturbed
  state, which they do only above about 60 R_E); isotropic orientations, cos i uniform in [−1, 1] (i in
  [0°, 180°]: retrograde passes included), node Ω and periapsis ω uniform in [0°, 360°);
  time of closest approach t_q = lead(q) + φ P with φ uniform in [0, 1) (the encounter's
  phase in the mutual orbit) and lead(q) the time the planet takes on its hyperbola from
  50 q to q, so that every member starts with the planet 50 q away. The tide there is
  50⁻³ = 8e-6 of its value at closest approach, i.e. (printed) 6e-4 of the mutual gravity
  at q = 2 R_E and 1e-8 at 80 R_E (``Flyby.tide_ratio``, mutual apoapsis); the tidal impulse
  a straight-line passage delivers beyond 50 q is q²/(4 (50 q)²) = 1e-4 of the encounter's,
  on each side. Two control members meet Earth at q = 1e8 km (tide 1e-10 of the mutual
  gravity): the unperturbed binary in the same launch.
* The run: to T = max(t_q + lead) + ``WINDOW`` mutual orbits (every member's planet is back
  beyond 50 q when the window starts), 16 samples per orbit, rtol 1e-10 (the nominal), the
  whole state recorded. The escape radius is the package's 50 a (165 km, beyond 1991 VH's
  Hill radius at 1 AU, about 96 km: a pair that far apart is split for good).

Measured per member:

* Osculating mutual elements a, e (two-body, μ = G (m1 + m2), from the recorded R, V:
  vis-viva and the Laplace–Runge–Lenz vector), averaged over the final window (this
  removes most of the short-period terms that the secondary's figure puts into osculating
  elements); Δa/a and Δe against the same averages of the control members (the "before":
  every member starts from the same state). The noise floor of the measure is printed: the
  difference of the two halves of the window of the controls.
* The final state, over the final ``WINDOW`` orbits (planet ≥ 50 q away): ``split`` — the
  member stopped as ``escape`` or its two-body energy is positive at its last sample;
  ``collision`` — stopped as ``collision``; else, from the secondary's state rows, with
  the thresholds of ``ti_spinorbit.model.attitude`` (docs/physics.md §6.9): ``tumbling`` —
  its spin angular momentum more than 30° from its short axis at some sample, or in the
  long-axis mode; ``circulating`` — not tumbling and the yaw angle (long axis from the line
  of centres, orbit frame) sweeps 180° or more (another spin state: a faster or slower
  spin, a chaotic one); ``synchronous`` — librating, split in the figure into pole within
  1° of the orbit normal and pole tilted (3-D libration). "No longer synchronous" is
  circulating + tumbling + split + collision. Members whose accuracy verdict is not usable
  (``inaccurate``, ``non-finite``) are counted apart and left out of the fractions.
* Fractions per q bin (``BINS`` log bins over [2, 80] R_E) with binomial 68 % (Wilson)
  intervals, and q_half, the q below which half the members are no longer synchronous: the
  maximum-likelihood logistic curve in ln q through the members (its 68 % interval from
  ``BOOTSTRAP`` resamplings), and, as a cross-check, the crossing of 1/2 by the binned
  fractions (interpolated in ln q). The same for "split".

Convergence (evidence): every fourth member (quick mode: every second) is run again at rtol
1e-11, the same flybys and run; printed: how many change final state, the largest change of
a bin's fraction (against its binomial error), of q_half, and of Δa/a and Δe of the members
that stay bound. The final state of a chaotic member is a snapshot over the window: a member
classed circulating may later return to libration and the reverse; the window check prints
how many members change class between the window's two halves, a measure of that.

Measured (full mode, 2400 + 800 encounters in one launch, 67-orbit run (the lead at 80 R_E
is 27 orbits), 114–166 s on 2 cores, load 2–3, 3.6 GB resident; experiments/README.md,
"Study 16"):

* Split: the binary is split (escape, or positive two-body energy) or its bodies collide
  below q_1/2 = 6.35 R_E (68 %: 6.24–6.46; binned 6.45), from the start θ̇_p/n = 1; 100 %
  of the encounters below 2.7 R_E, none beyond 11.3 R_E. (Collisions: 96 of 2400, at
  2–10 R_E, where the kick leaves e high enough for the bodies to touch.) The peak tide is
  the mutual gravity at q ≈ 8.5 R_E (77 times it at 2 R_E).
* The secondary's spin: half the encounters leave it no longer synchronous below
  q_1/2 = 26.0 R_E (68 %: 25.7–26.5; binned 27.7): 99–100 % below 12.7 R_E (split, tumbling
  and a few circulating), 51 % at 23–32 R_E, 20 % at 32–43 R_E, 1.5 % at 43–59 R_E and none
  of 208 beyond 59 R_E. Where the binary survives, tumbling dominates (69–86 % of the bins
  between 6.8 and 23 R_E); circulation (a non-synchronous principal-axis spin, mean 1.1–2.3 n,
  quartiles) is rare, 0–9 %. Libration with the pole tilted more than 1° makes 24–44 % of
  the bins between 17 and 43 R_E. From the island's centre the threshold is a little
  closer, q_1/2 = 23.5 R_E (22.7–24.2): the 50° libration of θ̇_p/n = 1 makes the secondary
  only slightly easier to upset.
* The mutual orbit (bound members, window means against the controls): median |Δa/a| 0.32,
  0.098, 0.016 and 8e-4 and median |Δe| 0.40, 0.13, 0.018 and 0.003 at q 5–10, 10–20, 20–40
  and 40–80 R_E; noise floor 4e-5 (a) and 8e-4 (e: the 50° libration modulates the
  osculating e; 1.4e-5 from the island's centre).
* Convergence: at rtol 1e-11, 23 of the 800 re-run encounters change final state, all
  between tumbling and circulating (both "no longer synchronous"): no encounter changes
  between synchronous and not, so the not-synchronous fractions and q_1/2 on the subset
  (26.29 R_E; centre 23.03 R_E) are unchanged; the largest change of a bin's single-state
  fraction is 0.056 (0.13 for the centre's 200, one bin). Δa/a of the bound members changes
  by a median 9e-5 (relative 8e-4), the tumbling ones by up to O(1): their trajectories are
  chaotic. E − W holds to 1.4e-9.
* Bounds: the final state is a snapshot over the last 12 orbits: tumbling ↔ circulating
  changes between the window's halves (99 of the 1668 bound members from θ̇_p/n = 1; 10
  of them between synchronous and not, 6 of 554 from the centre) are as frequent as between
  tolerances; the split fraction counts only pairs that escaped to
  50 a or are unbound at the end, so wide bound pairs (Δa/a up to 19) count as bound, though
  the Sun's tide would strip those beyond 1991 VH's Hill radius (29 a).
"""

import math

import numpy as np

import _common

MEMBERS, QUICK_MEMBERS = 2400, 64        # encounters from the paper's start θ̇_p/n = 1
RELAXED, QUICK_RELAXED = 800, 32         # the same encounters from the island centre
CONTROLS = 2                             # per start
Q_RANGE_RE = (2.0, 80.0)            # q in Earth radii, log-uniform
LEAD_FACTOR = 50.0                  # the planet starts LEAD_FACTOR q away
WINDOW = 12                         # mutual orbits after the planet is back beyond 50 q
SAMPLES = 16
RTOL, RTOL_CHECK = 1e-10, 1e-11
METHOD = "dop853"
BINS, QUICK_BINS = 12, 4
BOOTSTRAP = 200
SEED = 16
R_EARTH_KM = 6371.0
V_EARTH_KM_S = 29.78                # Earth's mean orbital speed (circular orbit)
CONTROL_Q_KM = 1e8
#: Final states (codes), in the figure's stacking order.
STATES = ("synchronous, pole < 1°", "synchronous, pole tilted", "circulating", "tumbling",
          "split", "collision")
SYNC, SYNC_3D, CIRC, TUMBLE, SPLIT, COLLIDE = range(6)
UNUSABLE = -1
COLOURS = ["#9ecae1", "#3182bd", "#d9d9d9", "#fb6a4a", "#252525", "#756bb1"]
NPA_ANGLE, TILT_ANGLE = 30.0, 1.0   # the package's attitude thresholds (attitude.py)


def opik_v_inf(orbit):
    """Öpik's encounter speed with Earth (km/s) of a heliocentric orbit (a AU, e, i deg),
    Earth on a circular orbit of 1 AU."""
    a, e, i = orbit.a_au, orbit.e, math.radians(orbit.inclination_deg)
    u2 = 3.0 - 1.0 / a - 2.0 * math.sqrt(a * (1.0 - e * e)) * math.cos(i)
    return V_EARTH_KM_S * math.sqrt(u2)


def lead_time_s(flyby, system, k, factor=LEAD_FACTOR):
    """Time (s) the planet of member k takes on its hyperbola from factor × q to q:
    r = a (e cosh H − 1), t = (e sinh H − H)/n."""
    a, e, n, _ = flyby.hyperbola(system, k)
    q = flyby.field("q_km", k) * 1e3
    H = math.acosh((factor * q / a + 1.0) / e)
    return (e * math.sinh(H) - H) / n


def osculating(R, V, mu):
    """Two-body osculating a (m) and e of relative positions R and velocities V (..., 3)."""
    r = np.linalg.norm(R, axis=-1)
    v2 = np.sum(V * V, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = 1.0 / (2.0 / r - v2 / mu)
        h = np.cross(R, V)
        evec = np.cross(V, h) / mu - R / r[..., None]
    return a, np.linalg.norm(evec, axis=-1)


def classify_window(rows, moments):
    """Attitude class of one member over SI state rows (times, 30) of its window, by the
    package's rules (ti_spinorbit.model.attitude.classify) written for state rows:
    TUMBLE, CIRC, SYNC_3D or SYNC; also (largest npa angle, largest pole tilt, yaw span,
    mean inertial spin rate / n is done by the caller)."""
    from ti_spinorbit.model.attitude import euler_angles_of_rows
    from ti_spinorbit.system.initial import ROW_SLICES

    A, B, C = moments
    w = rows[:, ROW_SLICES["secondary_omega"]]
    L = w * np.array([A, B, C])
    npa = np.degrees(np.arctan2(np.hypot(L[:, 0], L[:, 1]), np.abs(L[:, 2])))
    dyn = np.sum(L * L, axis=1) / np.sum(L * w, axis=1) / B
    long_axis = C > B * (1.0 + 1e-9) and np.min(dyn) < 1.0
    ang = euler_angles_of_rows(rows)
    roll, pitch = np.radians(ang[:, 0]), np.radians(ang[:, 1])
    tilt = np.degrees(np.arccos(np.clip(np.cos(roll) * np.cos(pitch), -1.0, 1.0)))
    yaw = np.degrees(np.unwrap(np.radians(ang[:, 2])))
    span = float(np.max(yaw) - np.min(yaw))
    if np.max(npa) > NPA_ANGLE or long_axis:
        code = TUMBLE
    elif span >= 180.0:
        code = CIRC
    elif np.max(tilt) > TILT_ANGLE:
        code = SYNC_3D
    else:
        code = SYNC
    return code, float(np.max(npa)), float(np.max(tilt)), span


def wilson(k, n, z=1.0):
    """Wilson score interval (z = 1: 68 %) of a binomial fraction k/n: (p, low, high)."""
    if n == 0:
        return float("nan"), float("nan"), float("nan")
    p = k / n
    d = 1.0 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, c - h, c + h


def logistic_half(x, y):
    """Maximum-likelihood logistic P(y = 1) = 1 / (1 + exp((x − x0) / s)) (falling with x);
    returns x0 (NaN when y is all one value)."""
    from scipy.optimize import minimize

    if y.all() or not y.any():
        return float("nan")

    def nll(p):
        z = (x - p[0]) / math.exp(p[1])
        return float(np.sum(np.logaddexp(0.0, np.where(y, z, -z))))

    res = minimize(nll, [float(np.median(x)), math.log(0.3)], method="Nelder-Mead",
                   options={"xatol": 1e-6, "fatol": 1e-9, "maxiter": 4000})
    return float(res.x[0])


def binned_half(centres, fractions):
    """ln q where the binned fraction falls through 1/2 (first crossing from below q, linear
    in ln q); NaN when it does not."""
    for k in range(len(fractions) - 1):
        f0, f1 = fractions[k], fractions[k + 1]
        if np.isfinite(f0) and np.isfinite(f1) and f0 >= 0.5 > f1:
            return float(centres[k] + (0.5 - f0) * (centres[k + 1] - centres[k]) / (f1 - f0))
    return float("nan")


def island_centre(system, quick):
    """θ̇_p/n (inertial) of the synchronous island's centre at θ_p = 0, 3-D model, no planet:
    the start of least libration amplitude (largest |yaw| over 40 orbits), on a 0.002 grid
    in [0.40, 0.50] refined by a parabola; and that amplitude (deg)."""
    import ti_spinorbit as tso

    grid = np.linspace(0.40, 0.50, 26 if quick else 51)
    ts = tso.time_series(system, 0.0, list(grid), orbits=40, samples_per_orbit=32, rtol=1e-11,
                         states=True, integrator=tso.Integrator(model="3d", method=METHOD),
                         run=tso.Run(progress=False))
    amp = np.nanmax(np.abs(ts.euler_angles[:, :, 2]), axis=1)
    k = int(np.clip(np.argmin(amp), 1, len(grid) - 2))
    y0, y1, y2 = amp[k - 1:k + 2]
    h = grid[1] - grid[0]
    shift = 0.5 * h * (y0 - y2) / (y0 - 2 * y1 + y2)
    return float(grid[k] + shift), float(np.min(amp))


def run_ensemble(system, flyby, thetadot, orbits, rtol):
    import ti_spinorbit as tso

    return tso.time_series(system, 0.0, list(thetadot), orbits=orbits,
                           samples_per_orbit=SAMPLES, rtol=rtol, states=True,
                           perturbations=[flyby],
                           integrator=tso.Integrator(model="3d", method=METHOD),
                           run=tso.Run(progress=False))


def final_states(ts, system, window_start_s):
    """Per member: (state code, Δ-less window means a, e, window-half means a, e, npa, tilt,
    yaw span, mean spin, last-sample two-body energy sign)."""
    from ti_spinorbit.engine import accuracy
    from ti_spinorbit.system.systems import G

    mu = G * system.total_mass
    names = ts.status_names
    usable = accuracy.usable(ts.status) | (np.asarray(ts.status_names) == "truncated")
    n = len(names)
    out = {k: np.full(n, np.nan) for k in ("a", "e", "a1", "e1", "a2", "e2", "npa", "tilt",
                                             "span", "spin")}
    code = np.full(n, UNUSABLE, dtype=int)
    half_code = np.full((n, 2), UNUSABLE, dtype=int)
    moments = system.secondary.moments
    for k in range(n):
        t = ts.t[k]
        fine = np.isfinite(t)
        rows = ts.states[k][fine]
        R, V = rows[:, 0:3], rows[:, 3:6]
        unbound = (0.5 * np.sum(V[-1] ** 2) - mu / np.linalg.norm(R[-1])) > 0.0
        if names[k] == "escape" or (usable[k] and unbound):
            code[k] = SPLIT
            continue
        if names[k] == "collision":
            code[k] = COLLIDE
            continue
        if not usable[k]:
            continue
        win = t[fine] >= window_start_s - 1.0
        if win.sum() < 2 * SAMPLES or t[fine][-1] < window_start_s:
            continue                                     # stopped early for another reason
        a, e = osculating(R[win], V[win], mu)
        m = len(a) // 2
        out["a"][k], out["e"][k] = a.mean(), e.mean()
        out["a1"][k], out["e1"][k] = a[:m].mean(), e[:m].mean()
        out["a2"][k], out["e2"][k] = a[m:].mean(), e[m:].mean()
        code[k], out["npa"][k], out["tilt"][k], out["span"][k] = classify_window(rows[win], moments)
        half_code[k, 0] = classify_window(rows[win][:m], moments)[0]
        half_code[k, 1] = classify_window(rows[win][m:], moments)[0]
        out["spin"][k] = float(np.nanmean(ts.thetadot[k][fine][win]))
    return code, half_code, out


def fractions_per_bin(code, q_re, edges):
    """Per bin: counts of each state, usable total, and the no-longer-synchronous count."""
    nb = len(edges) - 1
    counts = np.zeros((nb, len(STATES)), dtype=int)
    for b in range(nb):
        sel = (q_re >= edges[b]) & (q_re < edges[b + 1]) & (code >= 0)
        for s in range(len(STATES)):
            counts[b, s] = int(np.count_nonzero(code[sel] == s))
    return counts



def analyse(code, half_code, el, q_re, members, controls, edges, quick, seed):
    """Statistics of one start: Δa/a, Δe against its controls, fractions per bin, q_half."""
    ctrl = controls
    a0, e0 = float(np.mean(el["a"][ctrl])), float(np.mean(el["e"][ctrl]))
    out = {"a0": a0, "e0": e0,
           "floor_a": float(np.max(np.abs(el["a1"][ctrl] - el["a2"][ctrl]))) / a0,
           "floor_e": float(np.max(np.abs(el["e1"][ctrl] - el["e2"][ctrl]))),
           "controls": [STATES[c] if c >= 0 else "unusable" for c in code[ctrl]]}
    cls = code[members]
    q = q_re
    out["cls"], out["q"] = cls, q
    out["da"] = (el["a"][members] - a0) / a0
    out["de"] = el["e"][members] - e0
    counts = fractions_per_bin(cls, q, edges)
    total = counts.sum(axis=1)
    out["counts"], out["total"] = counts, total
    out["frac"] = counts / np.maximum(total, 1)[:, None]
    out["f_ns"] = np.array([wilson(k, n) for k, n in zip(counts[:, CIRC:].sum(axis=1), total)])
    out["f_sp"] = np.array([wilson(k, n) for k, n in zip(counts[:, SPLIT:].sum(axis=1), total)])
    ok = cls >= 0
    x = np.log(q[ok])
    y_ns, y_sp = cls[ok] >= CIRC, cls[ok] >= SPLIT
    out["half_ns"], out["half_sp"] = logistic_half(x, y_ns), logistic_half(x, y_sp)
    boot_ns, boot_sp = [], []
    rng = np.random.default_rng(seed)
    for _ in range(20 if quick else BOOTSTRAP):
        idx = rng.integers(0, len(x), len(x))
        boot_ns.append(logistic_half(x[idx], y_ns[idx]))
        boot_sp.append(logistic_half(x[idx], y_sp[idx]))
    out["boot_ns"], out["boot_sp"] = interval(boot_ns), interval(boot_sp)
    lc = np.log(np.sqrt(edges[:-1] * edges[1:]))
    out["bin_ns"] = binned_half(lc, out["f_ns"][:, 0])
    out["bin_sp"] = binned_half(lc, out["f_sp"][:, 0])
    out["window_changes"] = int(np.count_nonzero((half_code[members, 0] != half_code[members, 1])
                                                 & (cls >= 0) & (cls <= TUMBLE)))
    h = half_code[members]
    out["window_sync_flips"] = int(np.count_nonzero(((h[:, 0] <= SYNC_3D) != (h[:, 1] <= SYNC_3D))
                                                    & (cls >= 0) & (cls <= TUMBLE) & (h >= 0).all(axis=1)))
    out["spins"] = el["spin"][members][cls == CIRC]
    return out


def interval(v):
    """16th and 84th percentiles of bootstrap ln q values, as q."""
    v = np.asarray(v)
    v = v[np.isfinite(v)]
    if not len(v):
        return ["nan", "nan"]
    return [round(float(np.exp(np.percentile(v, 16))), 2), round(float(np.exp(np.percentile(v, 84))), 2)]


def _q(x):
    return round(math.exp(x), 2) if np.isfinite(x) else "none"


def r3(v):
    return [float(f"{x:.3g}") for x in v]


def state_numbers(r, label, edges):
    """Printed numbers of one start."""
    cls, q, da, de = r["cls"], r["q"], r["da"], r["de"]
    bound = (cls >= 0) & (cls <= TUMBLE)
    n = {f"{label}: controls' final state": r["controls"],
         f"{label}: before a (m), e (control window means)": [round(r["a0"], 3), round(r["e0"], 6)],
         f"{label}: noise floor da/a, de (control window halves)": r3([r["floor_a"], r["floor_e"]]),
         f"{label}: unusable members": int(np.count_nonzero(cls == UNUSABLE)),
         f"{label}: final states (all q)": {STATES[s]: int(np.count_nonzero(cls == s))
                                           for s in range(len(STATES))},
         f"{label}: members per bin": [int(x) for x in r["total"]]}
    for s in range(len(STATES)):
        n[f"{label}: fraction {STATES[s]} per bin"] = [round(float(x), 3) for x in r["frac"][:, s]]
    n[f"{label}: fraction no longer synchronous per bin"] = [round(float(x), 3) for x in r["f_ns"][:, 0]]
    n[f"{label}:   68% interval low"] = [round(float(x), 3) for x in r["f_ns"][:, 1]]
    n[f"{label}:   68% interval high"] = [round(float(x), 3) for x in r["f_ns"][:, 2]]
    n[f"{label}: fraction split (incl. collision) per bin"] = [round(float(x), 3) for x in r["f_sp"][:, 0]]
    n[f"{label}: q_half no longer synchronous (R_E), logistic [68% bootstrap]"] = [_q(r["half_ns"])] + r["boot_ns"]
    n[f"{label}: q_half no longer synchronous (R_E), binned"] = _q(r["bin_ns"])
    n[f"{label}: q_half split (R_E), logistic [68% bootstrap]"] = [_q(r["half_sp"])] + r["boot_sp"]
    n[f"{label}: q_half split (R_E), binned"] = _q(r["bin_sp"])
    n[f"{label}: largest q split or collided (R_E)"] = round(float(np.max(q[cls >= SPLIT])), 2) \
        if (cls >= SPLIT).any() else "none"
    sync = (cls >= 0) & (cls <= SYNC_3D)
    n[f"{label}: smallest q still synchronous (R_E)"] = round(float(np.min(q[sync])), 2) if sync.any() else "none"
    n[f"{label}: largest q no longer synchronous (R_E)"] = round(float(np.max(q[cls >= CIRC])), 2) \
        if (cls >= CIRC).any() else "none"
    for lo, hi in ((2, 5), (5, 10), (10, 20), (20, 40), (40, 80)):
        sel = bound & (q >= lo) & (q < hi) & np.isfinite(da)
        if sel.any():
            n[f"{label}: |da/a| median, max, q {lo}-{hi} R_E (bound)"] = r3([np.median(np.abs(da[sel])),
                                                                            np.max(np.abs(da[sel]))])
            n[f"{label}: |de| median, max, q {lo}-{hi} R_E (bound)"] = r3([np.median(np.abs(de[sel])),
                                                                          np.max(np.abs(de[sel]))])
    n[f"{label}: circulating: mean spin rate / n, quartiles"] = r3(np.percentile(r["spins"], [25, 50, 75])) \
        if len(r["spins"]) else "none"
    n[f"{label}: window halves: members changing class (bound)"] = r["window_changes"]
    n[f"{label}: window halves: members changing synchronous / not"] = r["window_sync_flips"]
    return n


def draw_fractions(ax, r, edges, title):
    from matplotlib.patches import Patch

    nb = len(edges) - 1
    bottom = np.zeros(nb)
    widths = np.diff(np.log10(edges))
    for s in range(len(STATES)):
        ax.bar(np.log10(edges[:-1]), r["frac"][:, s], width=widths, bottom=bottom, align="edge",
               color=COLOURS[s], edgecolor="w", lw=0.5)
        bottom += r["frac"][:, s]
    lc = np.log10(np.sqrt(edges[:-1] * edges[1:]))
    top = r["frac"][:, :CIRC].sum(axis=1)
    ax.errorbar(lc, top, yerr=[np.maximum(top - (1 - r["f_ns"][:, 2]), 0),
                               np.maximum((1 - r["f_ns"][:, 1]) - top, 0)],
                fmt="none", ecolor="k", capsize=2, lw=0.8)
    if np.isfinite(r["half_ns"]):
        x = r["half_ns"] / math.log(10)
        ax.axvline(x, color="k", ls="--", lw=1.0)
        ax.text(x + 0.01, 1.06, f"$q_{{1/2}}$ = {math.exp(r['half_ns']):.1f} $R_\\oplus$", ha="left",
                fontsize=8, bbox=dict(fc="w", ec="none", pad=0.5))
    for k in range(nb):
        ax.text(lc[k], 1.008, f"{r['total'][k]}", ha="center", va="bottom", fontsize=6, color="0.2")
    ticks = [2, 5, 10, 20, 40, 80]
    ax.set_xticks(np.log10(ticks), [str(t) for t in ticks])
    ax.set_xlim(np.log10(edges[0]), np.log10(edges[-1]))
    ax.set_ylim(0, 1.1)
    ax.set_xlabel(r"closest approach $q/R_\oplus$ (members per bin at the top)", fontsize=9)
    ax.set_ylabel("fraction of encounters", fontsize=9)
    ax.set_title(title, fontsize=9)
    ax.tick_params(labelsize=8)
    return [Patch(color=COLOURS[s], label=STATES[s]) for s in range(len(STATES))][::-1]


def draw_scatter(ax, r, key, floor, name, quick):
    from matplotlib.ticker import NullFormatter

    cls, q, v = r["cls"], r["q"], r[key]
    bound = (cls >= 0) & (cls <= TUMBLE) & np.isfinite(v)
    for s in range(TUMBLE + 1):
        sel = (cls == s) & np.isfinite(v)
        ax.scatter(q[sel], v[sel], s=12 if quick else 4, color=COLOURS[s],
                   edgecolors="none" if s != CIRC else "0.4", linewidths=0.3,
                   label=f"{STATES[s]} ({int(np.count_nonzero(cls == s))})", zorder=3)
    top = (np.max(np.abs(v[bound])) if bound.any() else 1.0) * 4
    for s, y in ((SPLIT, top), (COLLIDE, top * 2.5)):
        sel = cls == s
        ax.scatter(q[sel], np.full(sel.sum(), y), marker="|", s=25, color=COLOURS[s],
                   label=f"{STATES[s]} ({int(sel.sum())})", zorder=3)
    ax.set_xscale("log")
    lin = 10.0 ** math.ceil(math.log10(max(floor, 1e-6)))
    ax.set_yscale("symlog", linthresh=lin, linscale=0.6)
    top_exp = int(math.ceil(math.log10(top * 3)))
    exps = range(int(math.log10(lin)), top_exp + 1)
    ticks = [-(10.0 ** k) for k in exps][::-1] + [0.0] + [10.0 ** k for k in exps]
    ax.set_yticks(ticks, [("−" if t < 0 else "") + (f"$10^{{{int(round(math.log10(abs(t))))}}}$" if t else "0")
                          for t in ticks])
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.axhspan(-floor, floor, color="0.88", zorder=1, lw=0)
    ax.set_xlabel(r"closest approach $q/R_\oplus$", fontsize=9)
    ax.set_ylabel(name, fontsize=9)
    ticks = [2, 5, 10, 20, 40, 80]
    ax.set_xticks(ticks, [str(t) for t in ticks])
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlim(Q_RANGE_RE[0] / 1.05, Q_RANGE_RE[1] * 1.05)
    ax.tick_params(labelsize=8)


def main():
    def extra(p):
        p.add_argument("--members", type=int, default=None,
                       help=f"encounters from θ̇_p/n = 1 (default {MEMBERS}; quick {QUICK_MEMBERS}); "
                            "a third as many from the island centre")

    args, started = _common.parse(__doc__.splitlines()[0], extra=extra)
    import time

    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    system = tso.catalog.system("1991 VH")
    quick = args.quick
    n_nom = args.members or (QUICK_MEMBERS if quick else MEMBERS)
    n_rel = max(1, n_nom // 3) if args.members else (QUICK_RELAXED if quick else RELAXED)
    nbins = QUICK_BINS if quick else BINS
    P = system.orbital_period
    v_inf = round(opik_v_inf(system.heliocentric_orbit), 2)
    seconds = {}
    t0 = time.perf_counter()
    centre, centre_amp = island_centre(system, quick)
    seconds["island centre"] = round(time.perf_counter() - t0, 1)

    # --- the encounters: one draw, the relaxed start takes its first n_rel ---------------------
    rng = np.random.default_rng(SEED)
    q_re = np.exp(rng.uniform(*np.log(Q_RANGE_RE), n_nom))
    inc = np.degrees(np.arccos(rng.uniform(-1.0, 1.0, n_nom)))
    node = rng.uniform(0.0, 360.0, n_nom)
    peri = rng.uniform(0.0, 360.0, n_nom)
    phase = rng.uniform(0.0, 1.0, n_nom)
    probe = tso.Flyby("Earth", v_inf_km_s=v_inf, q_km=list(q_re * R_EARTH_KM))
    lead = np.array([lead_time_s(probe, system, k) for k in range(n_nom)])
    t_q = lead + phase * P
    t_end = float(np.max(t_q + lead)) + WINDOW * P
    orbits = t_end / P
    window_start = t_end - WINDOW * P
    # member layout: [nominal n_nom | relaxed n_rel | nominal controls | relaxed controls]
    enc = np.concatenate([np.arange(n_nom), np.arange(n_rel)])
    i_nom = np.arange(n_nom)
    i_rel = n_nom + np.arange(n_rel)
    i_cn = n_nom + n_rel + np.arange(CONTROLS)
    i_cr = n_nom + n_rel + CONTROLS + np.arange(CONTROLS)
    c_inc, c_node, c_peri = [30.0, 120.0][:CONTROLS], [0.0, 90.0][:CONTROLS], [0.0, 45.0][:CONTROLS]
    fields = dict(
        v_inf_km_s=v_inf,
        q_km=np.concatenate([q_re[enc] * R_EARTH_KM, np.full(2 * CONTROLS, CONTROL_Q_KM)]),
        inclination_deg=np.concatenate([inc[enc], c_inc * 2]),
        node_deg=np.concatenate([node[enc], c_node * 2]),
        periapsis_deg=np.concatenate([peri[enc], c_peri * 2]),
        t_closest_h=np.concatenate([t_q[enc], np.full(2 * CONTROLS, 0.5 * t_end)]) / 3600.0)
    thetadot = np.concatenate([np.ones(n_nom), np.full(n_rel, centre), np.ones(CONTROLS),
                               np.full(CONTROLS, centre)])
    flyby = tso.Flyby("Earth", **{k: (list(v) if np.ndim(v) else v) for k, v in fields.items()})
    ends = tso.Flyby("Earth", v_inf_km_s=v_inf, q_km=[Q_RANGE_RE[0] * R_EARTH_KM,
                                                       Q_RANGE_RE[1] * R_EARTH_KM])
    peak_ends = [ends.tide_ratio(system, k) for k in range(2)]

    t0 = time.perf_counter()
    ts = run_ensemble(system, flyby, thetadot, orbits, RTOL)
    seconds["nominal launch"] = round(time.perf_counter() - t0, 1)
    code, half_code, el = final_states(ts, system, window_start)
    edges = np.exp(np.linspace(*np.log(Q_RANGE_RE), nbins + 1))
    nom = analyse(code, half_code, el, q_re, i_nom, i_cn, edges, quick, SEED + 1)
    rel = analyse(code, half_code, el, q_re[:n_rel], i_rel, i_cr, edges, quick, SEED + 2)

    # --- rtol/10 on every 4th encounter (both starts) and the controls: one launch -------------
    step = 2 if quick else 4
    sub = np.concatenate([np.arange(0, n_nom + n_rel, step), i_cn, i_cr])
    sub_fields = {k: (list(np.asarray(v)[sub]) if np.ndim(v) else v) for k, v in fields.items()}
    t0 = time.perf_counter()
    ts_sub = run_ensemble(system, tso.Flyby("Earth", **sub_fields), thetadot[sub], orbits, RTOL_CHECK)
    seconds["rtol/10 launch"] = round(time.perf_counter() - t0, 1)
    code_sub, _, el_sub = final_states(ts_sub, system, window_start)
    m_enc = len(sub) - 2 * CONTROLS
    enc_sub = sub[:m_enc]
    changed = np.flatnonzero(code_sub[:m_enc] != code[enc_sub])
    a0_sub = {True: float(np.mean(el_sub["a"][m_enc:m_enc + CONTROLS])),
              False: float(np.mean(el_sub["a"][m_enc + CONTROLS:]))}
    e0_sub = {True: float(np.mean(el_sub["e"][m_enc:m_enc + CONTROLS])),
              False: float(np.mean(el_sub["e"][m_enc + CONTROLS:]))}
    is_nom = enc_sub < n_nom
    da_all = np.where(np.arange(len(code)) < n_nom, (el["a"] - nom["a0"]) / nom["a0"],
                      (el["a"] - rel["a0"]) / rel["a0"])
    de_all = np.where(np.arange(len(code)) < n_nom, el["e"] - nom["e0"], el["e"] - rel["e0"])
    da_sub = np.array([(el_sub["a"][j] - a0_sub[bool(is_nom[j])]) / a0_sub[bool(is_nom[j])]
                       for j in range(m_enc)])
    de_sub = np.array([el_sub["e"][j] - e0_sub[bool(is_nom[j])] for j in range(m_enc)])
    both = (code[enc_sub] >= 0) & (code[enc_sub] <= TUMBLE) & (code_sub[:m_enc] >= 0) & \
        (code_sub[:m_enc] <= TUMBLE)
    d_da = np.abs(da_sub - da_all[enc_sub])[both]
    d_de = np.abs(de_sub - de_all[enc_sub])[both]
    rel_da = d_da / np.maximum(np.abs(da_all[enc_sub][both]), nom["floor_a"])
    check = {}
    for label, mask, r, qq in (("start 1", is_nom, nom, q_re), ("centre", ~is_nom, rel, q_re[:n_rel])):
        j = enc_sub[mask] - (0 if label == "start 1" else n_nom)
        c_nom = fractions_per_bin(code[enc_sub[mask]], qq[j], edges)
        c_chk = fractions_per_bin(code_sub[:m_enc][mask], qq[j], edges)
        f_nom = c_nom / np.maximum(c_nom.sum(axis=1), 1)[:, None]
        f_chk = c_chk / np.maximum(c_chk.sum(axis=1), 1)[:, None]
        ns_nom = f_nom[:, CIRC:].sum(axis=1)
        ns_chk = f_chk[:, CIRC:].sum(axis=1)
        sig = np.sqrt(np.maximum(ns_nom * (1 - ns_nom), 0.25 / np.maximum(c_nom.sum(axis=1), 1))
                      / np.maximum(c_nom.sum(axis=1), 1))
        ok_n = code[enc_sub[mask]] >= 0
        ok_c = code_sub[:m_enc][mask] >= 0
        check[label] = {
            "members": int(mask.sum()),
            "changed": int(np.count_nonzero(code_sub[:m_enc][mask] != code[enc_sub[mask]])),
            "state_frac": float(np.max(np.abs(f_nom - f_chk))),
            "ns_frac": float(np.max(np.abs(ns_nom - ns_chk))),
            "ns_sigma": float(np.max(np.abs(ns_nom - ns_chk) / sig)),
            "half": [_q(logistic_half(np.log(qq[j][ok_n]), code[enc_sub[mask]][ok_n] >= CIRC)),
                     _q(logistic_half(np.log(qq[j][ok_c]), code_sub[:m_enc][mask][ok_c] >= CIRC))]}
    ctrl_sub = [STATES[c] if c >= 0 else "unusable" for c in code_sub[m_enc:]]

    # --- figure --------------------------------------------------------------------------------
    fig, axes = plt.subplots(2, 2, figsize=(12.5, 9.0))
    (axa, axe), (axf, axr) = axes
    draw_scatter(axa, nom, "da", nom["floor_a"], r"$\Delta a/a$ (window mean minus the controls')", quick)
    draw_scatter(axe, nom, "de", nom["floor_e"], r"$\Delta e$ (window mean minus the controls')", quick)
    axa.set_title(r"mutual semimajor axis after the encounter, start $\dot\theta_p/n$ = 1" + "\n"
                  f"(colour: final state, key at the lower right; grey: noise floor {nom['floor_a']:.1g};\n"
                  "split and collided members on top)",
                  fontsize=9)
    axe.set_title(f"mutual eccentricity (two-body e = {nom['e0']:.4f} before, window mean)\n"
                  f"(grey: noise floor {nom['floor_e']:.1g})", fontsize=9)
    handles = draw_fractions(axf, nom, edges, f"the secondary after the encounter: start "
                             f"$\\dot\\theta_p/n$ = 1 ({n_nom} encounters)\n(error bars: 68 % "
                             "binomial, synchronous vs no longer synchronous)")
    draw_fractions(axr, rel, edges, f"the same encounters from the island centre "
                   f"$\\dot\\theta_p/n$ = {centre:.3f} ({n_rel})\n(relaxed libration "
                   f"{centre_amp:.1f}°, against 50° from $\\dot\\theta_p/n$ = 1)")
    axr.legend(handles=handles, fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle(f"Beyond the paper (its §8, 1991 VH's non-synchronous secondary): Earth "
                 f"encounters of 1991 VH in one launch, q log-uniform {Q_RANGE_RE[0]:g}–"
                 f"{Q_RANGE_RE[1]:g} $R_\\oplus$, isotropic, v∞ = {v_inf:g} km/s;\nsynchronous "
                 f"starts, 3-D model, {METHOD} rtol {RTOL:g}, state over the last {WINDOW} "
                 f"orbits with the planet beyond 50 q", fontsize=10)

    # --- numbers -------------------------------------------------------------------------------
    numbers = {
        "encounters (start 1, centre)": [n_nom, n_rel],
        "v_inf (km/s, Opik, 1991 VH's orbit)": v_inf,
        "island centre thetadot_p/n, relaxed amplitude (deg)": [round(centre, 4), round(centre_amp, 2)],
        "run (orbits)": round(orbits, 2), "window (orbits)": WINDOW,
        "peak tide / mutual gravity, q = 2 and 80 R_E": r3(peak_ends),
        "tide at start / mutual gravity, q = 2 and 80 R_E": r3(np.array(peak_ends) / LEAD_FACTOR ** 3),
        "lead (orbits), smallest and largest q": r3([lead[np.argmin(q_re)] / P, lead[np.argmax(q_re)] / P]),
        "statuses": {str(nm): int(c) for nm, c in zip(*np.unique(ts.status_names, return_counts=True))},
        "truncated members (classified, flagged): final states": [
            STATES[c] if c >= 0 else "unusable" for c in code[np.asarray(ts.status_names) == "truncated"]],
        "bin edges q/R_E": [round(float(x), 2) for x in edges],
    }
    numbers.update(state_numbers(nom, "start 1", edges))
    numbers.update(state_numbers(rel, "centre", edges))
    numbers["rtol/10: members (encounters, every %d)" % step] = m_enc
    numbers["rtol/10: controls' final states"] = ctrl_sub
    for label, c in check.items():
        numbers[f"rtol/10 {label}: members changing final state (of {c['members']})"] = c["changed"]
        numbers[f"rtol/10 {label}: largest change of a bin's state fraction"] = round(c["state_frac"], 4)
        numbers[f"rtol/10 {label}: largest change of a bin's not-synchronous fraction (sigma)"] = [
            round(c["ns_frac"], 4), round(c["ns_sigma"], 2)]
        numbers[f"rtol/10 {label}: q_half on the subset, nominal -> check"] = c["half"]
    numbers["rtol/10: changes (q/R_E: nominal -> check)"] = [
        f"{q_re[enc[enc_sub[k]]]:.2f}: {STATES[code[enc_sub[k]]] if code[enc_sub[k]] >= 0 else 'unusable'}"
        f" -> {STATES[code_sub[k]] if code_sub[k] >= 0 else 'unusable'}" for k in changed[:16]] or "none"
    numbers["rtol/10: |change| of da/a, de (bound both), median and max"] = r3(
        [np.median(d_da), np.max(d_da), np.median(d_de), np.max(d_de)]) if len(d_da) else "none"
    numbers["rtol/10: median relative change of da/a (bound both)"] = float(f"{np.median(rel_da):.3g}") \
        if len(rel_da) else "nan"
    usable = code >= 0
    numbers["energy drift (E - W) max, usable"] = float(f"{np.nanmax(ts.energy_drift[usable]):.3g}")
    numbers["seconds"] = seconds

    arrays = {"q_re": q_re, "inclination_deg": inc, "node_deg": node, "periapsis_deg": peri,
              "phase": phase, "t_closest_s": t_q, "lead_s": lead, "thetadot_p": thetadot,
              "member_encounter": np.concatenate([enc, -np.ones(2 * CONTROLS, dtype=int)]),
              "state": code, "da_over_a": da_all, "de": de_all, "a_window_m": el["a"],
              "e_window": el["e"], "max_npa_deg": el["npa"], "max_tilt_deg": el["tilt"],
              "yaw_span_deg": el["span"], "mean_spin_n": el["spin"],
              "status": np.asarray(ts.status), "energy_drift": np.asarray(ts.energy_drift),
              "bin_edges_re": edges, "bin_counts_start1": nom["counts"],
              "bin_counts_centre": rel["counts"], "check_members": sub, "check_state": code_sub,
              "check_da_over_a": da_sub, "check_de": de_sub}
    _common.save(args, "study16_flybys", fig, arrays,
                 {"system": system.describe(), "members_start1": n_nom, "members_centre": n_rel,
                  "controls_per_start": CONTROLS, "control_q_km": CONTROL_Q_KM,
                  "q_range_re": Q_RANGE_RE, "q_distribution": "log-uniform",
                  "orientation": "isotropic (cos i uniform in [-1, 1], node and periapsis "
                                 "uniform in [0, 360))",
                  "v_inf_km_s": v_inf, "v_inf_choice": "fixed: Opik encounter speed of the "
                  "catalogue's heliocentric orbit of 1991 VH with a circular Earth orbit",
                  "lead_factor": LEAD_FACTOR, "phase": "uniform over one mutual period",
                  "window_orbits": WINDOW, "run_orbits": orbits, "samples_per_orbit": SAMPLES,
                  "rtol": RTOL, "rtol_check": RTOL_CHECK, "check_every": step,
                  "method": METHOD, "model": "3d", "order": 4,
                  "starts": {"theta_p_deg": 0.0, "thetadot_p_n": [1.0, centre]},
                  "thresholds_deg": {"npa": NPA_ANGLE, "tilt": TILT_ANGLE},
                  "states": list(STATES), "bins": nbins, "bootstrap": BOOTSTRAP, "seed": SEED,
                  "r_earth_km": R_EARTH_KM},
                 numbers, started)


if __name__ == "__main__":
    main()
