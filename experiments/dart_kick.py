"""A post-DART-like Didymos–Dimorphos: period change, excited libration and tumbling after a kick.

Beyond the paper. On 2022-09-26 NASA's DART spacecraft hit Dimorphos, the secondary of
(65803) Didymos; the mutual orbital period fell from 11.92 h by about 33 minutes (Thagard
et al. 2023; Thomas et al. 2023, Nature 616, 448: −33.0 ± 1.0 min), which corresponds to an
along-track velocity change of about −2.7 mm/s (Cheng et al. 2023, Nature 616, 457). Whether
the kick also excited Dimorphos' libration or set it tumbling depends on its shape and on the
momentum transferred (Agrusa et al. 2021, Icarus 370, 114624, studied this excitation with a
full-two-body code and found that it can leave the secondary librating strongly or, for some
shapes, in non-principal-axis rotation). The script shows the same dependence; it does not
restate their numbers.

Set-up (an illustration, not a fit to the mission data): a spinning oblate primary, semi-axes
400 × 400 × 300 m, spin period 2.26 h; the secondary an ellipsoid with the catalogue's volume
(a·b·c = 5625 × 65 m³) and a/b ∈ {1.2, 1.3, 1.4, 1.5}, b/c ∈ {1.05, 1.15, 1.3}; a circular
orbit of a = 1180 m with both densities scaled so the KEPLERIAN period 2π sqrt(a³/G(m1 + m2))
is 11.92 h (``BinarySystem(orbital_period=...)`` fixes that period, not the actual one).
Each member starts in its exact synchronous equilibrium: long axis on the line of centres,
circular speed and spin rate from the full fourth-order force at that position, so the
unkicked member neither librates nor drifts; then it receives at t = 0 a kick Δv
along-track ∈ {0, −1, −2, −2.7, −4} mm/s plus an out-of-plane component
``--normal-fraction`` × |Δv| (default 0.1: DART's momentum transfer was not exactly in the
orbit plane; it also seeds out-of-plane motion). All members run in ONE launch of the 3-D
model (each with its own shape), rtol 1e-11, sampled 32 times per orbit.

The oblate primary and the elongated secondary pull harder than two points, so the circular
orbit is 0.82–0.92 % faster than Keplerian (by shape; printed) and the unkicked period is
11.81 h, not 11.92 h. Two more sets of members, in the same launch, each with Δv = 0 and
−2.7 mm/s, say what that does to ΔP:

* *actual period 11.92 h*: the Keplerian period raised (a short fixed-point root-find,
  :func:`matched_keplerian_period`; the densities scale, a stays 1180 m) until the
  full-potential circular period is 11.92 h; ΔP at −2.7 mm/s is then about −33.7 min;
* *spherical primary*: the primary replaced by a sphere of the same mass and volume (the
  same Keplerian period), so that ΔP(oblate) − ΔP(sphere) is the oblate primary's share.

The closeness of ΔP at −2.7 mm/s (−33.1 … −33.3 min) to the first-order Kepler estimate
(−33.5 min) is then a cancellation, printed term by term: the Keplerian second-order term
(+1.5 min: P'/P = (1 − 2x − x²)^(−3/2) with x = Δv/v, against 1 + 3x) against the figures of
the two bodies (−1.1 … −1.3 min together: the oblate primary −0.8 … −0.9 min, the elongated
secondary and the rest −0.2 … −0.4 min).

Measured per member: the orbital period (slope of the unwrapped inertial longitude of the
secondary, least squares over the run) and its change against the Δv = 0 member of the same
shape and set; the Keplerian first-order estimate ΔP/P = 3 Δv/v (v = a n, Keplerian, P =
11.92 h) for comparison; the largest |yaw| of
the secondary in the orbit frame (its libration amplitude; docs/physics.md §6.9) and the
attitude class (planar/3-D libration, circulation, tumbling).
"""

import ti_spinorbit
import numpy as np

import _common

DV_MM_S = (0.0, -1.0, -2.0, -2.7, -4.0)
ELONGATIONS = (1.2, 1.3, 1.4, 1.5)
FLATTENINGS = (1.05, 1.15, 1.3)          # b/c
PERIOD_H = 11.92
DART_DP_MIN = -33.0


#: The sets of members: Keplerian period 11.92 h (the figure), actual period 11.92 h, and
#: Keplerian 11.92 h with a spherical primary; the last two at these Δv only.
SETS = ("kepler", "matched", "sphere")
EXTRA_DV_MM_S = (0.0, -2.7)


def system_for(a_over_b, b_over_c, period_h=PERIOD_H, spherical_primary=False):
    """The binary with a secondary of a/b, b/c and Keplerian period ``period_h`` (h); the
    primary oblate (400 × 400 × 300 m) or, with ``spherical_primary``, a sphere of the same
    volume and mass."""
    import ti_spinorbit as tso

    volume = 5625.0 * 65.0                     # a b c of the catalogue's Dimorphos, m³
    c = (volume / (a_over_b * b_over_c**2)) ** (1.0 / 3.0)
    b = b_over_c * c
    if spherical_primary:
        primary = tso.Sphere((400.0 * 400.0 * 300.0) ** (1.0 / 3.0), density=2170.0,
                             name="Didymos (sphere)")
    else:
        primary = tso.Ellipsoid(400.0, 400.0, 300.0, density=2170.0, name="Didymos (oblate)")
    secondary = tso.Ellipsoid(a_over_b * b, b, c, density=2170.0, name="Dimorphos")
    return tso.BinarySystem(primary, secondary, a=1180.0, e=0.0, primary_spin_period=2.26 * 3600,
                            orbital_period=period_h * 3600, name=f"a/b {a_over_b}, b/c {b_over_c}")


def actual_period_h(system):
    """Period (h) of the circular orbit of radius a in the full potential, 2π a / v_circ."""
    return 2.0 * np.pi * system.a / circular_speed(system) / 3600.0


def matched_keplerian_period(a_over_b, b_over_c, target_h=PERIOD_H, tol=1e-12):
    """Keplerian period (h) whose actual (full-potential) circular period is ``target_h``,
    by fixed-point iteration P_K ← P_K · target / P_actual (the masses scale as 1/P_K², so
    v_circ scales as 1/P_K and one step is nearly exact); returns (P_K, system)."""
    period = target_h
    for _ in range(20):
        system = system_for(a_over_b, b_over_c, period)
        actual = actual_period_h(system)
        if abs(actual - target_h) <= tol * target_h:
            return period, system
        period *= target_h / actual
    raise RuntimeError(f"a/b {a_over_b}, b/c {b_over_c}: the period root-find did not converge")


def kepler_dp_min(dv_mm_s, v, period_h=PERIOD_H):
    """(first-order, exact) Keplerian ΔP (min) of a circular orbit of speed v (m/s) kicked
    along-track by Δv: ΔP/P = 3x and (1 − 2x − x²)^(−3/2) − 1, x = Δv/v."""
    x = 1e-3 * dv_mm_s / v
    return 3.0 * x * period_h * 60.0, ((1.0 - 2.0 * x - x * x) ** -1.5 - 1.0) * period_h * 60.0


def circular_speed(system):
    """Speed (m/s) of a circular orbit of radius a with the secondary's long axis on the line
    of centres, from the radial component of the full (fourth-order) mutual force."""
    import ti_spinorbit as tso

    _, force, _, _ = tso.mutual_potential(system.primary, system.secondary,
                                          np.array([system.a, 0.0, 0.0]), np.eye(3))
    m_red = system.primary.mass * system.secondary.mass / system.total_mass
    return float(np.sqrt(system.a * -force[0] / m_red))


def inertial_longitude(R):
    """Unwrapped angle of the secondary's inertial position R (samples, 3) in the xy plane."""
    return np.unwrap(np.arctan2(R[:, 1], R[:, 0]))


def main():
    def extra(p):
        p.add_argument("--orbits", type=float, default=None, help="orbits (default 100; quick 8)")
        p.add_argument("--normal-fraction", type=float, default=0.1,
                       help="out-of-plane kick as a fraction of |Δv| (default 0.1)")

    args, started = _common.parse(__doc__.splitlines()[0], extra=extra)
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.model import attitude

    orbits = args.orbits or (8.0 if args.quick else 100.0)
    shapes = [(q, r) for q in ELONGATIONS for r in FLATTENINGS]
    if args.quick:
        shapes = [(1.3, 1.15), (1.5, 1.3)]
    members, systems, states = [], [], []
    matched_period = {}
    for q, r in shapes:
        matched_period[(q, r)], matched = matched_keplerian_period(q, r)
        for which, system, dvs_set in (("kepler", system_for(q, r), DV_MM_S),
                                       ("matched", matched, EXTRA_DV_MM_S),
                                       ("sphere", system_for(q, r, spherical_primary=True),
                                        EXTRA_DV_MM_S)):
            v_circular = circular_speed(system)
            spin = v_circular / system.a / system.mean_motion
            for dv in dvs_set:
                state = system.tilted_start(0.0, spin)
                kick = np.array([0.0, v_circular - system.a * system.mean_motion + 1e-3 * dv,
                                 1e-3 * args.normal_fraction * abs(dv)])
                members.append((q, r, dv, system, which))
                systems.append(system)
                states.append(state.kicked(kick))
    # every member its own shape: one launch of the 3-D model
    ts = tso.time_series(systems, orbits=orbits, samples_per_orbit=32, rtol=1e-11,
                         initial_states=states, states=True,
                         integrator=ti_spinorbit.Integrator(model="3d"),
                         run=ti_spinorbit.Run(progress=False))
    ok = ts.status == tso.Status.DONE
    if not np.all(ok):
        print(f"[dart_kick] {np.count_nonzero(~ok)} members stopped early or failed the "
              f"accuracy check: {sorted(set(ts.status_names))} (kept, excluded from the table)")
    n = members[0][3].mean_motion
    period_h = np.full(len(members), np.nan)
    amplitude = np.full(len(members), np.nan)
    classes = np.full(len(members), -1, dtype=np.int8)
    yaw = ts.euler_angles[..., 2]
    for k in range(len(members)):
        if not ok[k]:
            continue
        t = ts.t[k]
        fine = np.isfinite(t)
        rate = np.polyfit(t[fine], inertial_longitude(ts.R[k][fine]), 1)[0]
        period_h[k] = 2 * np.pi / rate / 3600
        amplitude[k] = np.nanmax(np.abs(yaw[k]))
        classes[k] = ts.attitude_class[k]
    base = {(w, q, r): period_h[k] for k, (q, r, dv, _, w) in enumerate(members) if dv == 0.0}
    dp_min = np.array([(period_h[k] - base[(w, q, r)]) * 60
                       for k, (q, r, dv, _, w) in enumerate(members)])
    v = members[0][3].a * n
    kepler_min = np.array([kepler_dp_min(dv, v)[0] for (_, _, dv, _, _) in members])
    which = np.array([m[4] for m in members])
    extra = {w: dp_min[(which == w) & (np.array([m[2] for m in members]) == -2.7)]
             for w in SETS}
    # the figure and the attitude numbers are the Keplerian-period set's
    keep = which == "kepler"
    all_members, members = members, [m for m, k in zip(members, keep) if k]
    period_all, period_h, dp_min, kepler_min = period_h, period_h[keep], dp_min[keep], kepler_min[keep]
    amplitude, classes, status = amplitude[keep], classes[keep], ts.status[keep]
    faster = [100.0 * (circular_speed(system_for(q, r)) / v - 1.0) for q, r in shapes]
    first, exact = kepler_dp_min(-2.7, v)

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.4))
    dvs = np.array([m[2] for m in members])
    for (q, r) in shapes:
        sel = np.array([(m[0], m[1]) == (q, r) for m in members])
        ax1.plot(dvs[sel], dp_min[sel], "o-", ms=3, lw=0.8, label=f"a/b {q}, b/c {r}")
        ax2.plot(dvs[sel], amplitude[sel], "o-", ms=3, lw=0.8)
        tumbling = sel & (classes == attitude.TUMBLING)
        ax2.plot(dvs[tumbling], amplitude[tumbling], "kx", ms=7)
    ax1.plot(DV_MM_S, [3e-3 * d / v * PERIOD_H * 60 for d in DV_MM_S], "k--", lw=0.8,
             label=r"Kepler, $\Delta P/P = 3\,\Delta v/v$")
    ax1.errorbar([-2.7], [DART_DP_MIN], yerr=[1.0], fmt="s", color="C3", ms=6,
                 label="DART, measured (−33 ± 1 min)")
    ax1.plot(np.full(len(extra["matched"]), -2.7), extra["matched"], "D", color="k", ms=3,
             mfc="none", label="actual (not Keplerian) P = 11.92 h")
    ax1.set_xlabel(r"along-track $\Delta v$ (mm/s)")
    ax1.set_ylabel(r"orbital period change $\Delta P$ (min)")
    ax1.legend(fontsize=6, ncol=2)
    ax2.set_xlabel(r"along-track $\Delta v$ (mm/s)")
    ax2.set_ylabel(r"largest $|$yaw$|$ after the kick (deg)")
    ax2.set_title("x: tumbling", fontsize=8)
    fig.suptitle(f"DART-like kick, Didymos–Dimorphos-like binary (Keplerian P = {PERIOD_H} h, "
                 f"actual {np.nanmin(period_h[dvs == 0.0]):.2f} h, circular), "
                 f"{orbits:g} orbits, rtol 1e-11, 3-D model", fontsize=9)
    at_dart = dvs == -2.7
    unkicked = dvs == 0.0
    matched_unkicked = np.array([period_all[k] for k, m in enumerate(all_members)
                                 if m[4] == "matched" and m[2] == 0.0])
    oblate_share = extra["kepler"] - extra["sphere"]
    numbers = {
        "members": len(all_members), "orbits": orbits,
        "faster than Keplerian (%)": [round(min(faster), 3), round(max(faster), 3)],
        "unkicked period, Keplerian period 11.92 h (h)": [round(float(np.nanmin(period_h[unkicked])), 4),
                                                          round(float(np.nanmax(period_h[unkicked])), 4)],
        "dP_at_dart_min": [round(float(x), 2) for x in dp_min[at_dart]],
        "kepler_dP_at_dart_min": round(float(kepler_min[at_dart][0]), 2),
        "kepler second-order term at dart (min)": round(float(exact - first), 2),
        "figures of both bodies at dart (min)": [round(float(np.nanmin(extra["kepler"] - exact)), 2),
                                                 round(float(np.nanmax(extra["kepler"] - exact)), 2)],
        "oblate primary term at dart (min)": [round(float(np.nanmin(oblate_share)), 2),
                                              round(float(np.nanmax(oblate_share)), 2)],
        "secondary figure and rest at dart (min)": [
            round(float(np.nanmin(extra["sphere"] - exact)), 2),
            round(float(np.nanmax(extra["sphere"] - exact)), 2)],
        "matched Keplerian period (h)": [round(min(matched_period.values()), 4),
                                         round(max(matched_period.values()), 4)],
        "unkicked period, actual period matched (h)": [round(float(np.nanmin(matched_unkicked)), 4),
                                                       round(float(np.nanmax(matched_unkicked)), 4)],
        "dP_at_dart_actual_period_matched_min": [round(float(x), 2) for x in extra["matched"]],
        "amplitude_at_dart_deg": [round(float(x), 1) for x in amplitude[at_dart]],
        "classes_at_dart": attitude.class_names(np.maximum(classes[at_dart], 0)),
        "tumbling_members": int(np.count_nonzero(classes == attitude.TUMBLING)),
        "amplitude_unkicked_max_deg": round(float(np.nanmax(amplitude[dvs == 0.0])), 3),
    }
    arrays = {"a_over_b": np.array([m[0] for m in members]), "b_over_c": np.array([m[1] for m in members]),
              "dv_mm_s": dvs, "period_h": period_h, "dP_min": dp_min, "kepler_dP_min": kepler_min,
              "amplitude_deg": amplitude, "attitude_class": classes, "status": status,
              "set_all": which, "dv_mm_s_all": np.array([m[2] for m in all_members]),
              "period_h_all": period_all, "status_all": ts.status}
    _common.save(args, "dart_kick", fig, arrays,
                 {"orbits": orbits, "rtol": 1e-11, "normal_fraction": args.normal_fraction,
                  "dv_mm_s": list(DV_MM_S), "shapes": shapes, "samples_per_orbit": 32,
                  "system": members[0][3].describe()}, numbers, started)


if __name__ == "__main__":
    main()
