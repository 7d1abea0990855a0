"""Paper §2 (Naidu & Margot 2015, model; script study15): beyond the paper, the truncation order and the primary's shape for post-DART Didymos–Dimorphos.

Why "§2". The paper sets up its model before it tests its integrator (its §3, reproduced by
study13): the mutual potential of two rigid bodies expanded in their inertia integrals and
truncated at fourth order (docs/physics.md §3.1), with spheres and ellipsoids for the bodies
of its Table 1. This study goes beyond the paper by putting that modelling choice to the
test: how the observables of a Hera-era binary change with the truncation order N
(docs/physics.md §3.8) and with a real primary shape instead of an ellipsoid. It is named by
the section whose choice it tests, as study14 is named by the §8 conclusion it tests; the
paper itself has no such computation.

Set-up (an illustration of the convergence, not a fit to the mission data):

* Two primaries of the SAME mass and the same second moments: the radar polyhedron of
  Didymos (Naidu et al. 2020; the catalogue entry "Didymos (radar shape)": density
  1955 kg m⁻³ of the catalogue's "Didymos" row, spin period 2.26 h about its shortest
  principal axis, its note in ti_spinorbit/data/systems.json), built here with integrals to
  order 16 instead of the entry's 12, so that the order-12 runs carry truncation estimates
  (they need order 14) and :func:`tso.truncation` can use order 16 as its reference; and its
  equal-moment ellipsoid (399.4 × 392.5 × 381.7 m: the uniform ellipsoid with the
  polyhedron's mass and principal moments; its volume is 0.8 % larger, so its density is
  1939 kg m⁻³), spinning in 2.26 h too. At N = 2 the two primaries are therefore the same
  body (checked: printed), and every difference at higher N is the shape beyond its
  ellipsoid.
* The secondary: Dimorphos as in the catalogue's "Didymos" row (Naidu & Margot 2015 Table 1:
  ab = 5625 m², c = 65 m, a/b = 1.3 assumed there, ρ_s = 2252 kg m⁻³), 85.5 × 65.8 × 65 m;
  the map's secondaries keep that volume and density with a/b ∈ {1.2, 1.3, 1.4, 1.5} and
  b/c ∈ {1.05, 1.15, 1.3} (dart_kick.py's grid).
* The orbit: a = 1180 m (the catalogue's), circular before the kick. With the catalogue's
  densities the (Keplerian and actual) period is about 12.3 h, not Didymos' 11.92 h; only
  differences between orders matter here, and 1 s is 2.3e-5 of either.
* The start (dart_kick.py's exact synchronous equilibrium, adapted): the secondary's long axis
  on the line of centres, the circular speed from the radial component of the order-N mutual
  force — for each order its own, so that no member starts off its own equilibrium — and the
  spin rate v/a. The primaries are triaxial and spin, so no exact equilibrium exists: the
  force is averaged over the primary's rotation phase (32 phases; its rms variation, 1.3e-3
  and 1.7e-3 of the mean, drives only a small forced wobble at the synodic frequency). The
  kick at t = 0: Δv = −2.7 mm/s along-track (DART-like; Cheng et al. 2023) plus 0.1 × |Δv|
  out of the plane (dart_kick.py's default; it seeds out-of-plane motion), which leaves the
  orbit with e ≈ 0.03, as observed after DART.
* One launch of the 3-D model per (primary, order), N = 2, 4, 6, 8 and 12, each with the
  unkicked and the kicked nominal secondary; the launches at N = 4 (the paper's, the package
  default) and N = 12 also hold the 12 kicked map secondaries. Verner 9(8) (``vern9``), rtol
  1e-11, 100 orbits, 32 samples per orbit, full degrees (N, N) (no caps). The highest-order
  pair is run again at rtol 1e-12 (rtol/10): its differences are the integration error.

Measured per member:

* the orbital period: the sidereal mutual period 2π/⟨λ̇⟩, ⟨λ̇⟩ the mean rate of the inertial
  longitude λ of the secondary, λ̇ = (R × V)_z / (R_x² + R_y²) from the recorded states,
  averaged over the whole run with a Hann window (w = sin²(π t/T)), which suppresses the
  periodic terms (the kicked orbit's e ≈ 0.03 makes λ̇ swing by ±6 %) far faster with the
  run length than a straight-line fit of λ(t) does (printed, "window vs line-fit period":
  0.002 s after 100 orbits, 0.8 s after the quick mode's 10);
* ΔP = P(kicked) − P(unkicked) at the same order and primary;
* the libration amplitude after the kick: the largest |yaw| of the secondary in the orbit
  frame (docs/physics.md §6.9; dart_kick.py's measure), refined by a parabola through the
  largest sample and its neighbours;
* the attitude class (planar or 3-D libration, circulation, tumbling: ``attitude_class``,
  with ``max_npa_angle`` and ``max_tilt``) of every map member;
* energy drift: the largest |E(t) − E(0)| over |E_orb(0)| (orbital energy; 1 s of period is
  1.5e-5 of it).

Convergence (the measure): the difference of each observable to its value at the HIGHEST
order run (N = 12; quick mode N = 6), |X_N − X_12|, against the precision Hera-era
measurements need: 1 s for the period and ΔP, 0.1° for the libration amplitude. An
observable has converged at order N when it and every higher order but the reference are
within that. Cross-checks: the differences against (a) the truncation estimates every member
carries (``truncation_force`` and ``truncation_torque``, the next two orders at the closest
approach, docs/physics.md §3.9), as the period error they imply, ½ e_F P (P ∝ F^(−1/2) at a
fixed a), and (b) :func:`tso.truncation` at a = 1180 m against order 16, which also says how
far order 12 itself is from converged.

Measured (full mode, 100 orbits, 183–257 s on 2 cores, load 1–3; experiments/README.md,
"Study 15"):

* Period before the kick, N = 12: 12.36099 h (ellipsoid), 12.35841 h (radar); the radar
  shape's figure beyond its ellipsoid shortens it by 9.3 s. |P(N) − P(12)|, N = 2, 4, 6, 8:
  ellipsoid 0.58, 0.006, 7e-5, 9e-7 s; radar 12.5, 1.41, 0.050, 0.011 s. Converged to 1 s at
  N = 2 (ellipsoid) and N = 6 (radar): the paper's order 4 misses by 1.4 s with the radar
  shape.
* ΔP at −2.7 mm/s, N = 12: −34.887 min (ellipsoid), −34.931 min (radar); |ΔP(N) − ΔP(12)|:
  ellipsoid 0.18, 0.002, 4e-5, 5e-7 s; radar 2.8, 0.49, 0.028, 0.006 s. Converged to 1 s at
  N = 2 and N = 4: most of the truncation error of the period cancels in the difference.
* Libration amplitude after the kick, N = 12: 25.89° (ellipsoid), 26.06° (radar);
  |A(N) − A(12)|: ellipsoid 0.30°, 0.002°, 2e-5°, 3e-7°; radar 0.48°, 0.055°, 0.006°,
  0.0002°. Converged to 0.1° at N = 4 for both (order 2 misses by 0.3–0.5°).
* Map (12 shapes, kicked): the same classes at N = 4 and N = 12 for both primaries, 4 of 12
  tumbling (a/b 1.4 and 1.5 with b/c 1.15 and 1.3), a/b 1.3 with b/c 1.3 in 3-D libration,
  the rest librating in the plane at 17–41°; the amplitudes of the librating cells change by
  at most 0.008° (ellipsoid) and 0.067° (radar) between N = 4 and 12. The order does not
  change the map.
* Cross-checks. The period differences lie below the table's ½ e_F P (tso.truncation, worst
  case over attitudes: ellipsoid 0.95, 0.009, 1e-4, 1.3e-6 s; radar 42, 3.2, 0.31, 0.063 s)
  by factors 1.4–6, and within a factor 3 of the members' own estimates (radar: 2–4 × above
  the measured differences; ellipsoid: 1.4–3 × below them). The members' force estimate
  crosses the package's 1e-5 limit between N = 4 (radar: 2.1e-4, status "truncated") and
  N = 6 (7.6e-6), the same order at which the period converges to 1 s. At N = 12 the table
  puts the remaining error (against order 16) at 3e-4 s in period and 5e-7 in torque, so
  N = 12 is a converged reference. At N = 2 the two primaries give the same period to 5e-10 s
  (the same body to second degree).
* Integration error. The N = 12 runs again at rtol 1e-12 change P by 2e-5 s, ΔP by 2e-6 s
  and the amplitude by 2e-9°; the energy drift over 100 orbits is 6.7e-10 of |E_orb| (1 s
  of period is 1.5e-5 of it).
"""

import numpy as np

import _common

ORDERS = (2, 4, 6, 8, 12)
QUICK_ORDERS = (2, 4, 6)
MAP_LOW = 4                                # the paper's order; the map's other is the highest
ELONGATIONS = (1.2, 1.3, 1.4, 1.5)         # secondary a/b of the map
FLATTENINGS = (1.05, 1.15, 1.3)            # secondary b/c of the map
QUICK_SHAPES = ((1.3, 1.15), (1.5, 1.3))
DV_MM_S = -2.7                             # along-track kick
NORMAL_FRACTION = 0.1                      # out-of-plane kick, fraction of |Δv|
A_M = 1180.0                               # catalogue "Didymos": a (m)
RHO_P, RHO_S = 1955.0, 2252.0              # catalogue "Didymos": densities (kg m⁻³)
SPIN_H = 2.26                              # primary spin period (h), catalogue radar entry
RTOL = 1e-11
METHOD = "vern9"
SAMPLES = 32
PHASES = 32                                # primary phases the start's force is averaged over
TOL_PERIOD_S, TOL_AMPLITUDE_DEG = 1.0, 0.1
PRIMARIES = ("ellipsoid", "radar")


def primaries():
    """The radar polyhedron (integrals to order 16) and its equal-moment ellipsoid of the
    same mass (module docstring)."""
    import ti_spinorbit as tso
    from ti_spinorbit.system.shapes import packaged_shape

    radar = packaged_shape("didymos_radar", density=RHO_P, name="Didymos (radar shape)",
                           order=16)
    A, B, C = radar.moments
    m = radar.mass
    axes = [np.sqrt(2.5 / m * (B + C - A)), np.sqrt(2.5 / m * (A + C - B)),
            np.sqrt(2.5 / m * (A + B - C))]
    ellipsoid = tso.Ellipsoid(*axes, mass=m, name="Didymos (equal-moment ellipsoid)")
    return {"ellipsoid": ellipsoid, "radar": radar}


def secondary(a_over_b=None, b_over_c=None):
    """Dimorphos of the catalogue (a_over_b None) or of the same volume and density with
    the given a/b and b/c."""
    import ti_spinorbit as tso

    if a_over_b is None:
        return tso.catalog.system("Didymos").secondary
    volume = 5625.0 * 65.0                     # a b c of the catalogue's Dimorphos, m³
    c = (volume / (a_over_b * b_over_c**2)) ** (1.0 / 3.0)
    b = b_over_c * c
    return tso.Ellipsoid(a_over_b * b, b, c, density=RHO_S,
                         name=f"Dimorphos a/b {a_over_b}, b/c {b_over_c}")


def _rz(phi):
    c, s = np.cos(phi), np.sin(phi)
    out = np.zeros(np.shape(phi) + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    out[..., 2, 2] = 1.0
    return out


def circular_speed(system, order):
    """Speed (m/s) of the circular orbit of radius a with the secondary's long axis on the
    line of centres, from the radial order-N mutual force averaged over the primary's
    rotation phase; and the rms variation of that force over the phase (relative)."""
    import ti_spinorbit as tso

    phi = np.linspace(0.0, 2.0 * np.pi, PHASES, endpoint=False)
    Q = _rz(-phi)                       # inertial -> primary frame, primary turned by phi
    R = Q @ np.array([system.a, 0.0, 0.0])
    _, F, _, _ = tso.mutual_potential(system.primary, system.secondary, R, Q, order=order)
    radial = np.einsum("ki,kij->kj", F, Q)[:, 0]      # back to inertial: Qᵀ F, x component
    m_red = system.primary.mass * system.secondary.mass / system.total_mass
    return float(np.sqrt(system.a * -radial.mean() / m_red)), float(radial.std() / -radial.mean())


def equilibrium_kicked(system, order, dv_mm_s):
    """The order-N synchronous circular start (module docstring), kicked by dv_mm_s along
    track and NORMAL_FRACTION × |dv| out of the plane."""
    v, _ = circular_speed(system, order)
    start = system.tilted_start(0.0, v / system.a / system.mean_motion)
    return start.kicked(np.array([0.0, v - system.a * system.mean_motion + 1e-3 * dv_mm_s,
                                  1e-3 * NORMAL_FRACTION * abs(dv_mm_s)]))


def mean_period_h(t, R, V):
    """Sidereal period (h) 2π/⟨λ̇⟩, ⟨·⟩ the Hann-window mean over the samples (module
    docstring); and the straight-line-fit period of the unwrapped λ, for comparison."""
    fine = np.isfinite(t)
    t, R, V = t[fine], R[fine], V[fine]
    rate = (R[:, 0] * V[:, 1] - R[:, 1] * V[:, 0]) / (R[:, 0] ** 2 + R[:, 1] ** 2)
    w = np.sin(np.pi * (t - t[0]) / (t[-1] - t[0])) ** 2
    mean = np.trapezoid(w * rate, t) / np.trapezoid(w, t)
    line = np.polyfit(t, np.unwrap(np.arctan2(R[:, 1], R[:, 0])), 1)[0]
    return 2 * np.pi / mean / 3600.0, 2 * np.pi / line / 3600.0


def peak_abs(y):
    """Largest |y| of a sampled series, refined by a parabola through the largest sample and
    its neighbours."""
    y = y[np.isfinite(y)]
    k = int(np.argmax(np.abs(y)))
    if k == 0 or k == len(y) - 1:
        return float(abs(y[k]))
    y0, y1, y2 = np.sign(y[k]) * y[k - 1:k + 2]
    curv = y0 - 2 * y1 + y2
    return float(y1 - 0.125 * (y0 - y2) ** 2 / curv) if curv < 0 else float(y1)


def converged_order(orders, diffs, tol):
    """Smallest order whose difference to the reference (the last order) and those of every
    higher order below the reference are within tol; the reference order itself when none."""
    ok = [d <= tol for d in diffs[:-1]]
    for k in range(len(ok)):
        if all(ok[k:]):
            return int(orders[k])
    return int(orders[-1])


def run_launch(systems, states, orbits, order, rtol):
    import ti_spinorbit as tso

    return tso.time_series(systems, orbits=orbits, samples_per_orbit=SAMPLES, rtol=rtol,
                           initial_states=states, states=True,
                           integrator=tso.Integrator(model="3d", order=order, method=METHOD),
                           run=tso.Run(progress=False))


def measure(ts, k):
    """(period h, line-fit period h, amplitude deg, |ΔE|/|E_orb|) of member k."""
    p, line = mean_period_h(ts.t[k], ts.R[k], ts.V[k])
    amp = peak_abs(ts.euler_angles[k, :, 2])
    e = ts.energy[k]
    e = e[np.isfinite(e)]
    drift = float(np.max(np.abs(e - e[0])) / abs(ts.energy_orbit[k, 0]))
    return p, line, amp, drift


def main():
    def extra(p):
        p.add_argument("--orbits", type=float, default=None, help="orbits (default 100; quick 10)")

    args, started = _common.parse(__doc__.splitlines()[0], extra=extra)
    import time

    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    import ti_spinorbit as tso
    from ti_spinorbit.model import attitude

    orders = QUICK_ORDERS if args.quick else ORDERS
    orbits = args.orbits or (10.0 if args.quick else 100.0)
    shapes = list(QUICK_SHAPES) if args.quick else [(q, r) for q in ELONGATIONS for r in FLATTENINGS]
    top = orders[-1]
    map_orders = (MAP_LOW, top)
    bodies = primaries()
    nominal = secondary()
    map_secondaries = [secondary(q, r) for q, r in shapes]
    spin_s = SPIN_H * 3600.0

    def system(kind, sec):
        return tso.BinarySystem(bodies[kind], sec, a=A_M, e=0.0, primary_spin_period=spin_s,
                                name=f"{kind} primary, {sec.name}")

    # --- the launches: one per (primary, order) ------------------------------------------
    res = {kind: {} for kind in PRIMARIES}
    maps = {kind: {} for kind in PRIMARIES}
    seconds, truncation_member, force_spread = {}, {}, {}
    for kind in PRIMARIES:
        base = system(kind, nominal)
        for order in orders:
            systems = [base, base]
            states = [equilibrium_kicked(base, order, 0.0), equilibrium_kicked(base, order, DV_MM_S)]
            if order in map_orders:
                for sec in map_secondaries:
                    s = system(kind, sec)
                    systems.append(s)
                    states.append(equilibrium_kicked(s, order, DV_MM_S))
            force_spread[(kind, order)] = circular_speed(base, order)[1]
            t0 = time.perf_counter()
            ts = run_launch(systems, states, orbits, order, RTOL)
            seconds[f"{kind} N={order}"] = round(time.perf_counter() - t0, 1)
            bad = [n for n in ts.status_names if n not in ("done", "truncated")]
            if bad:
                print(f"[study15] {kind} N={order}: members not usable: {bad}")
            pre, post = measure(ts, 0), measure(ts, 1)
            res[kind][order] = {
                "P_pre_h": pre[0], "P_post_h": post[0], "P_line_pre_h": pre[1],
                "P_line_post_h": post[1], "dP_s": (post[0] - pre[0]) * 3600.0,
                "A_pre_deg": pre[2], "A_deg": post[2], "drift": max(pre[3], post[3]),
                "class": int(ts.attitude_class[1]), "status": list(ts.status_names[:2]),
                "truncation_force": float(np.nanmax(ts.truncation_force[:2])),
                "truncation_torque": float(np.nanmax(ts.truncation_torque[:2])),
                "energy_drift_total": float(np.nanmax(ts.energy_drift[:2])),
            }
            truncation_member[(kind, order)] = (res[kind][order]["truncation_force"],
                                                res[kind][order]["truncation_torque"])
            if order in map_orders:
                amps = np.array([peak_abs(ts.euler_angles[k, :, 2]) for k in range(2, len(systems))])
                maps[kind][order] = {"class": np.asarray(ts.attitude_class[2:], dtype=int),
                                     "amplitude": amps,
                                     "npa": np.asarray(ts.max_npa_angle[2:], dtype=float),
                                     "tilt": np.asarray(ts.max_tilt[2:], dtype=float),
                                     "status": list(ts.status_names[2:])}

    # --- rtol/10 at the highest order ---------------------------------------------------
    tight = {}
    for kind in PRIMARIES:
        base = system(kind, nominal)
        states = [equilibrium_kicked(base, top, 0.0), equilibrium_kicked(base, top, DV_MM_S)]
        t0 = time.perf_counter()
        ts = run_launch([base, base], states, orbits, top, RTOL / 10)
        seconds[f"{kind} N={top} rtol/10"] = round(time.perf_counter() - t0, 1)
        pre, post = measure(ts, 0), measure(ts, 1)
        r = res[kind][top]
        tight[kind] = {"P_s": max(abs(pre[0] - r["P_pre_h"]), abs(post[0] - r["P_post_h"])) * 3600.0,
                       "dP_s": abs((post[0] - pre[0]) * 3600.0 - r["dP_s"]),
                       "A_deg": abs(post[2] - r["A_deg"]), "drift": max(pre[3], post[3])}

    # --- tso.truncation at a = 1180 m against order 16 -----------------------------------
    tables = {kind: tso.truncation(system(kind, nominal), orders=orders, reference=16)
              for kind in PRIMARIES}

    # --- convergence --------------------------------------------------------------------
    conv, diffs = {}, {}
    for kind in PRIMARIES:
        r = res[kind]
        ref = r[top]
        d = {"P_s": [max(abs(r[o]["P_pre_h"] - ref["P_pre_h"]), abs(r[o]["P_post_h"] - ref["P_post_h"])) * 3600
                     for o in orders],
             "dP_s": [abs(r[o]["dP_s"] - ref["dP_s"]) for o in orders],
             "A_deg": [abs(r[o]["A_deg"] - ref["A_deg"]) for o in orders]}
        diffs[kind] = d
        conv[kind] = {
            "period": converged_order(orders, d["P_s"], TOL_PERIOD_S),
            "dP": converged_order(orders, d["dP_s"], TOL_PERIOD_S),
            "amplitude": converged_order(orders, d["A_deg"], TOL_AMPLITUDE_DEG)}
    # implied period errors: ½ e_F P from the members' estimates and from the table
    implied_member = {kind: [0.5 * truncation_member[(kind, o)][0] * res[kind][top]["P_pre_h"] * 3600
                             for o in orders] for kind in PRIMARIES}
    implied_table = {kind: [0.5 * float(tables[kind].force[k]) * res[kind][top]["P_pre_h"] * 3600
                            for k in range(len(orders))] for kind in PRIMARIES}

    # --- figure ---------------------------------------------------------------------------
    colours = {"ellipsoid": "C0", "radar": "C3"}
    labels = {"ellipsoid": "equal-moment ellipsoid", "radar": "radar polyhedron"}
    fig = plt.figure(figsize=(13, 8.2))
    gs = fig.add_gridspec(2, 12, height_ratios=[1.0, 1.05])
    axp, axd, axa = (fig.add_subplot(gs[0, 4 * i:4 * i + 4]) for i in range(3))
    floor = 1e-7                              # differences below it are drawn on it
    low = [o for o in orders if o != top]
    for kind in PRIMARIES:
        c = colours[kind]
        for ax, key in ((axp, "P_s"), (axd, "dP_s"), (axa, "A_deg")):
            ax.semilogy(low, np.maximum([diffs[kind][key][k] for k, o in enumerate(orders) if o != top], floor),
                        "o-", color=c, ms=5, lw=1.2)
            ax.semilogy([top], [max(tight[kind][key], floor)], "*", color=c, ms=11, mfc="none")
        axp.semilogy(low, np.maximum(implied_member[kind][:-1], floor), "s--", color=c, ms=4,
                     mfc="none", lw=0.8)
        axp.semilogy(orders, np.maximum(implied_table[kind], floor), ":", color=c, lw=1.0)
    r_e, r_r = res["ellipsoid"][top], res["radar"][top]
    for ax, tol, unit, title in (
            (axp, TOL_PERIOD_S, "s", f"orbital period; N = {top}, before the kick:\n"
                                     f"{r_e['P_pre_h']:.5f} h (ellipsoid), {r_r['P_pre_h']:.5f} h (radar)"),
            (axd, TOL_PERIOD_S, "s", f"period change $\\Delta P$; N = {top}:\n"
                                     f"{r_e['dP_s'] / 60:.3f} min (ellipsoid), {r_r['dP_s'] / 60:.3f} min (radar)"),
            (axa, TOL_AMPLITUDE_DEG, "deg", f"libration amplitude after the kick; N = {top}:\n"
                                            f"{r_e['A_deg']:.2f}° (ellipsoid), {r_r['A_deg']:.2f}° (radar)")):
        ax.axhline(tol, color="k", lw=0.8, ls="--")
        ax.text(orders[-1], tol * 1.3, f"Hera-era precision {tol:g} {unit}", fontsize=8, ha="right")
        ax.set_xlabel("truncation order N", fontsize=9)
        ax.set_ylabel(f"|difference to N = {top}| ({unit})", fontsize=9)
        ax.set_xticks(list(orders))
        ax.set_ylim(floor / 2, None)
        ax.set_title(title, fontsize=9)
        ax.tick_params(labelsize=8)
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=colours[k], marker="o", ms=5, label=labels[k]) for k in PRIMARIES]
    handles += [Line2D([], [], color="0.3", marker="*", ms=10, mfc="none", ls="none",
                       label=f"rtol/10 change at N = {top} (on the floor if below)"),
                Line2D([], [], color="0.3", marker="s", ms=4, mfc="none", ls="--", lw=0.8,
                       label=r"$\frac{1}{2}e_F P$, the members' estimate"),
                Line2D([], [], color="0.3", ls=":", label=r"$\frac{1}{2}e_F P$, tso.truncation")]
    axd.set_ylim(floor * 1e-4, None)                  # room for the key below the data
    axd.legend(handles=handles, fontsize=8, loc="lower left")

    class_colour = ["#9ecae1", "#fdd49e", "#d9d9d9", "#fb6a4a"]
    class_short = ["lib", "lib 3-D", "circ", "tumbl"]
    for i, (kind, order) in enumerate([(k, o) for k in PRIMARIES for o in map_orders]):
        ax = fig.add_subplot(gs[1, 3 * i:3 * i + 3])
        m = maps[kind][order]
        qs = sorted({q for q, _ in shapes})
        rs = sorted({r for _, r in shapes})
        for k, (q, r) in enumerate(shapes):
            x, y = qs.index(q), rs.index(r)
            cls = m["class"][k]
            ax.add_patch(plt.Rectangle((x - 0.5, y - 0.5), 1, 1,
                                       color=class_colour[cls] if cls >= 0 else "white", ec="w"))
            text = f"{class_short[cls]}\n{m['amplitude'][k]:.1f}°" if cls in (0, 1) else \
                f"{class_short[cls]}\nnpa {m['npa'][k]:.0f}°"
            ax.text(x, y, text, ha="center", va="center", fontsize=8)
        ax.set_xlim(-0.5, len(qs) - 0.5)
        ax.set_ylim(-0.5, len(rs) - 0.5 + 0.9)          # room for the key
        ax.set_xticks(range(len(qs)), [f"{q:g}" for q in qs])
        ax.set_yticks(range(len(rs)), [f"{r:g}" for r in rs])
        ax.set_xlabel("secondary a/b", fontsize=9)
        if i == 0:
            ax.set_ylabel("secondary b/c", fontsize=9)
        ax.tick_params(labelsize=8)
        n_t = int(np.count_nonzero(m["class"] == attitude.TUMBLING))
        ax.set_title(f"{labels[kind]}, N = {order}: {n_t} of {len(shapes)} tumbling", fontsize=9)
    ax.legend(handles=[Patch(color=class_colour[k], label=attitude.CLASSES[k]) for k in range(4)],
              loc="upper center", ncol=2, fontsize=8, handlelength=1.0, columnspacing=0.8,
              borderaxespad=0.2)
    fig.suptitle(f"Beyond the paper (its §2 model, order 4): post-DART Didymos–Dimorphos, "
                 f"Δv = {DV_MM_S} mm/s, a = {A_M:g} m, {orbits:g} orbits, {METHOD} rtol {RTOL:g}, "
                 f"3-D model; libration (max |yaw|) and tumbling after the kick", fontsize=10)

    # --- numbers ---------------------------------------------------------------------------
    same_at_2 = {"P_s": abs(res["radar"][2]["P_pre_h"] - res["ellipsoid"][2]["P_pre_h"]) * 3600,
                 "A_deg": abs(res["radar"][2]["A_deg"] - res["ellipsoid"][2]["A_deg"])}
    changed = {}
    for kind in PRIMARIES:
        lo, hi = maps[kind][MAP_LOW]["class"], maps[kind][top]["class"]
        changed[kind] = [f"a/b {q} b/c {r}: {attitude.CLASSES[a]} -> {attitude.CLASSES[b]}"
                         for (q, r), a, b in zip(shapes, lo, hi) if a != b]
    numbers = {"orders": list(orders), "orbits": orbits, "members per map launch": 2 + len(shapes)}
    for kind in PRIMARIES:
        r = res[kind]
        numbers[f"{kind}: period before kick (h)"] = [round(r[o]["P_pre_h"], 6) for o in orders]
        numbers[f"{kind}: period after kick (h)"] = [round(r[o]["P_post_h"], 6) for o in orders]
        numbers[f"{kind}: dP (min)"] = [round(r[o]["dP_s"] / 60, 4) for o in orders]
        numbers[f"{kind}: libration amplitude after kick (deg)"] = [round(r[o]["A_deg"], 3) for o in orders]
        numbers[f"{kind}: |P(N) - P({top})| (s)"] = [float(f"{x:.3g}") for x in diffs[kind]["P_s"]]
        numbers[f"{kind}: |dP(N) - dP({top})| (s)"] = [float(f"{x:.3g}") for x in diffs[kind]["dP_s"]]
        numbers[f"{kind}: |A(N) - A({top})| (deg)"] = [float(f"{x:.3g}") for x in diffs[kind]["A_deg"]]
        numbers[f"{kind}: converged order (period 1 s, dP 1 s, amplitude 0.1 deg)"] = [
            conv[kind]["period"], conv[kind]["dP"], conv[kind]["amplitude"]]
        numbers[f"{kind}: member truncation_force"] = [float(f"{truncation_member[(kind, o)][0]:.3g}") for o in orders]
        numbers[f"{kind}: member truncation_torque"] = [float(f"{truncation_member[(kind, o)][1]:.3g}") for o in orders]
        numbers[f"{kind}: implied period error 1/2 e_F P, members (s)"] = [float(f"{x:.3g}") for x in implied_member[kind]]
        numbers[f"{kind}: tso.truncation force (ref 16)"] = [float(f"{x:.3g}") for x in tables[kind].force]
        numbers[f"{kind}: tso.truncation torque secondary (ref 16)"] = [float(f"{x:.3g}") for x in tables[kind].torque_secondary]
        numbers[f"{kind}: implied period error 1/2 e_F P, table (s)"] = [float(f"{x:.3g}") for x in implied_table[kind]]
        numbers[f"{kind}: unkicked amplitude (deg)"] = [round(r[o]["A_pre_deg"], 3) for o in orders]
        numbers[f"{kind}: kicked class"] = [attitude.CLASSES[r[o]["class"]] for o in orders]
        numbers[f"{kind}: status (unkicked, kicked)"] = ["/".join(r[o]["status"]) for o in orders]
        numbers[f"{kind}: |A(N) - A({top})| / A"] = [float(f"{x / r[top]['A_deg']:.3g}") for x in diffs[kind]["A_deg"]]
        numbers[f"{kind}: energy drift |dE|/|E_orb| max"] = float(f"{max(r[o]['drift'] for o in orders):.3g}")
        numbers[f"{kind}: window vs line-fit period (s)"] = float(f"{max(abs(r[o]['P_line_post_h'] - r[o]['P_post_h']) * 3600 for o in orders):.3g}")
        numbers[f"{kind}: rtol/10 change at N={top}: P (s), dP (s), A (deg), drift"] = [
            float(f"{tight[kind][k]:.3g}") for k in ("P_s", "dP_s", "A_deg", "drift")]
        numbers[f"{kind}: start force spread over primary phase"] = float(f"{force_spread[(kind, top)]:.3g}")
        for order in map_orders:
            m = maps[kind][order]
            numbers[f"{kind}: map N={order} tumbling"] = int(np.count_nonzero(m["class"] == attitude.TUMBLING))
            numbers[f"{kind}: map N={order} classes"] = attitude.class_names(np.maximum(m["class"], 0))
        numbers[f"{kind}: map cells changing class N={MAP_LOW} -> {top}"] = changed[kind] or "none"
        lib = (maps[kind][MAP_LOW]["class"] <= 1) & (maps[kind][top]["class"] <= 1)
        numbers[f"{kind}: map largest amplitude change N={MAP_LOW} -> {top} (deg)"] = (
            round(float(np.max(np.abs(maps[kind][MAP_LOW]["amplitude"][lib] - maps[kind][top]["amplitude"][lib]))), 3)
            if lib.any() else "no librating cell")
    numbers["order 2: radar - ellipsoid (P s, A deg)"] = [float(f"{same_at_2['P_s']:.3g}"),
                                                          float(f"{same_at_2['A_deg']:.3g}")]
    numbers["seconds per launch"] = seconds

    arrays = {"orders": np.array(orders), "map_orders": np.array(map_orders),
              "map_a_over_b": np.array([q for q, _ in shapes]),
              "map_b_over_c": np.array([r for _, r in shapes])}
    for kind in PRIMARIES:
        for key in ("P_pre_h", "P_post_h", "dP_s", "A_deg", "A_pre_deg", "drift",
                    "truncation_force", "truncation_torque"):
            arrays[f"{kind}_{key}"] = np.array([res[kind][o][key] for o in orders])
        for order in map_orders:
            for key in ("class", "amplitude", "npa", "tilt"):
                arrays[f"{kind}_map{order}_{key}"] = maps[kind][order][key]
        arrays[f"{kind}_table_force"] = tables[kind].force
        arrays[f"{kind}_table_torque_secondary"] = tables[kind].torque_secondary
    _common.save(args, "study15_order_and_shape", fig, arrays,
                 {"orders": list(orders), "map_orders": list(map_orders), "orbits": orbits,
                  "rtol": RTOL, "method": METHOD, "samples_per_orbit": SAMPLES,
                  "dv_mm_s": DV_MM_S, "normal_fraction": NORMAL_FRACTION, "shapes": shapes,
                  "tolerances": {"period_s": TOL_PERIOD_S, "amplitude_deg": TOL_AMPLITUDE_DEG},
                  "convergence_measure": f"difference to the highest order run, N = {top}",
                  "systems": {k: system(k, nominal).describe() for k in PRIMARIES}},
                 numbers, started)


if __name__ == "__main__":
    main()
