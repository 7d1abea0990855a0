"""Paper Fig. 10 (Naidu & Margot 2015; script study08): relaxed libration amplitude vs elongation.

The synchronous systems of Table 1 (Didymos, 2000 DP107, 2002 CE26, 2001 SN263, 1994 CC,
1999 KW4, 1996 FG3) with the secondary's elongation a/b set to 1.01, 1.05, 1.1, 1.2 and 1.3.
For each, the centre of the synchronous island is searched (θ_p = 0, θ̇_p(0)/n varied until
the section trace shrinks to a point) and the relaxed-mode amplitude max |α| measured there.
The decoupled estimate |ψ_A| = 2e/(1 − ω0²) grows with a/b through ω0, and the measured
amplitude falls below it as a/b grows. That deficit is mostly NONLINEARITY, not coupling:
ψ_A is the small-amplitude (linear) response, and the pendulum's restoring torque
sin 2(θ − f) is weaker than linear at large angles, which detunes the forced response. The
nearly decoupled 2002 CE26 (m1/m2 ≈ 1580, so ω0,eff = ω0 to 0.03 %) reaches only 0.91 ψ_A at
a/b = 1.3, where the decoupled problem's own nonlinear amplitude (the symmetric 1:1
periodic orbit of θ̈ = −(ω0²/2)(a/r)³ sin 2(θ − f), ``analytic.decoupled_relaxed_libration``,
docs/physics.md §8.8) is 0.94 ψ_A. Each panel draws that nonlinear decoupled amplitude at
ω0,eff; the measured / nonlinear ratio isolates what coupling (and the non-Keplerian orbit)
adds.

Check of the method: the section is taken at minima of r (pericentre passages). For a nearly
circular mutual orbit (1999 KW4, e = 0.0004) the radial oscillation driven by the secondary's
own free libration can be larger than the Keplerian one; then the minima of r come at the
libration period, the section strobes the free libration, and its "island centre" is a pure
free libration. Such cases are flagged by the mean interval between section points
(T_sec/T far from 1) and re-measured by a second method: the start θ̇_p(0)/n (θ_p = 0) that
minimises max |α| (forced + free amplitudes add up over a long run, so the minimum is where the
free mode vanishes). A search whose final section extent stays above 1° found no stable centre
(e.g. 1996 FG3 at a/b = 1.1: ω0 ≈ 1/2, the free libration resonates with the orbit and the
region is chaotic); it is recorded as NaN. The orbit's radial eccentricity
e_r = (r_max − r_min)/(r_max + r_min) along each centre trajectory is reported: where it
exceeds the nominal (initial osculating) e, the non-Keplerian orbit sets the forcing.

Coordinates: inertial, unlike the other section studies. The table includes 1999 KW4
(e = 0.0004), below the eccentricity floor of the apsidal coordinates, where the apsidal rate
is several n (docs/physics.md §6.7); the amplitudes max |α| do not depend on the coordinates,
and an island centre in the paper's coordinates is the printed one minus ϖ̇(0)/n.

Prints: a system × elongation table of the island centre, amplitude, |ψ_A|, their ratio, the
nonlinear decoupled amplitude and the measured / nonlinear ratio, the section extent left at
the centre, T_sec/T, e_r and whether the search converged; the reason for every failed case;
for strobed cases the second method's centre, amplitude and ratio.
"""

import warnings

import numpy as np

from _common import parse, save

ELONGATIONS = [1.01, 1.05, 1.1, 1.2, 1.3]
QUICK_SYSTEMS = ("Didymos", "1999 KW4")
QUICK_ELONGATIONS = [1.01, 1.3]
#: Orbits per trajectory; the free libration period is 1/ω0 orbits (≈ 6 at a/b = 1.01).
ORBITS, ORBITS_QUICK = 120, 30
RTOL = 1e-12
#: Orbits and samples per orbit of the run that measures e_r along each centre trajectory.
RADIAL_ORBITS, RADIAL_SAMPLES_PER_ORBIT = 20, 128
#: A centre whose section points are further than this from one orbital period apart does
#: not sample the orbit (it strobes the free libration): flagged and re-measured.
STROBE_TOLERANCE = 0.05
#: Second method: window half-width (units of n) and candidates of its first launch, then
#: zooms of ZOOM_CANDIDATES over ±2 spacings; orbits per trajectory.
MINIMUM_HALF_WIDTH, MINIMUM_CANDIDATES, ZOOM_CANDIDATES, ZOOMS = 0.25, 51, 21, 5
MINIMUM_ORBITS = 60


def synchronous_systems():
    """Catalogue names flagged synchronous, in table order."""
    import ti_spinorbit as tso

    return [n for n in tso.catalog.names() if tso.catalog.entry(n).get("synchronous")]


def minimum_amplitude(system, guess, orbits):
    """Start θ̇_p(0)/n (θ_p = 0) that minimises max |α| over ``orbits``, and that minimum (deg).

    Returns (centre, amplitude, resolved): NaN, NaN, False when no candidate librates;
    ``resolved`` is False when the last window's minimum sat on its edge."""
    from ti_spinorbit.studies.libration import libration_amplitude

    center, half_width, count = guess, MINIMUM_HALF_WIDTH, MINIMUM_CANDIDATES
    for _ in range(ZOOMS):
        x = center + np.linspace(-half_width, half_width, count)
        amplitude = libration_amplitude(system, x, orbits, samples_per_orbit=64, rtol=RTOL)
        if not np.any(np.isfinite(amplitude)):
            return np.nan, np.nan, False
        best = int(np.nanargmin(amplitude))
        center = float(x[best])
        resolved = 0 < best < count - 1
        if resolved:                              # minimum inside: zoom; else move the window
            half_width, count = 2.0 * (x[1] - x[0]), ZOOM_CANDIDATES
    return center, float(libration_amplitude(system, center, orbits, rtol=RTOL)), resolved


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.model import analytic
    from ti_spinorbit.studies.libration import MAX_CENTER_EXTENT_DEG, relaxed_libration

    names = list(QUICK_SYSTEMS) if args.quick else synchronous_systems()
    elongations = QUICK_ELONGATIONS if args.quick else ELONGATIONS
    orbits = ORBITS_QUICK if args.quick else ORBITS
    shape = (len(names), len(elongations))
    fields = ("center", "amplitude", "psi_A", "psi_A_eff", "extent")
    table = {k: np.full(shape, np.nan) for k in fields}
    converged = np.zeros(shape, dtype=bool)
    failures = {}

    for i, name in enumerate(names):
        for j, q in enumerate(elongations):
            system = tso.catalog.system(name, elongation=q)
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always", RuntimeWarning)
                    lib = relaxed_libration(system, orbits=orbits, rtol=RTOL)
            except RuntimeError as err:
                failures[f"{name} a/b={q}"] = str(err)
                print(f"FAILED {name} a/b = {q}: {err}")
                continue
            for w in caught:
                print(f"warning {name} a/b = {q}: {w.message}")
            converged[i, j] = lib.converged
            if not lib.extent < MAX_CENTER_EXTENT_DEG:
                # no stable centre on θ_p = 0 (e.g. chaos near the ω0 ≈ 1/2 libration resonance)
                reason = (f"no island centre on theta_p = 0: smallest section extent "
                          f"{lib.extent:.1f} deg at thetadot_p/n = {lib.centre_thetadot_p:.5f} "
                          f"(omega0_eff = {lib.omega0_effective:.3f}, free libration period "
                          f"{1 / lib.omega0_effective:.2f} orbits)")
                failures[f"{name} a/b={q}"] = reason
                print(f"FAILED {name} a/b = {q}: {reason}")
                continue
            for k, v in zip(fields, (lib.centre_thetadot_p, lib.amplitude, abs(lib.psi_A),
                                     abs(lib.psi_A_effective), lib.extent)):
                table[k][i, j] = v

    # which centre trajectories sample the orbit: mean interval between section points
    table["T_sec"] = np.full(shape, np.nan)
    table["center_min"] = np.full(shape, np.nan)
    table["amplitude_min"] = np.full(shape, np.nan)
    done = np.argwhere(np.isfinite(table["center"]))
    if len(done):
        systems = [tso.catalog.system(names[i], elongation=elongations[j]) for i, j in done]
        sec = tso.surface_of_section(systems, 0.0, table["center"][tuple(done.T)], orbits,
                                     rtol=RTOL)
        periods = np.array([s.orbital_period for s in systems])
        table["T_sec"][tuple(done.T)] = np.nanmean(np.diff(sec.t, axis=1), axis=1) / periods
    strobed = np.abs(table["T_sec"] - 1.0) > STROBE_TOLERANCE
    for i, j in np.argwhere(strobed):
        system = tso.catalog.system(names[i], elongation=elongations[j])
        print(f"{names[i]} a/b = {elongations[j]}: section points {table['T_sec'][i, j]:.4f} "
              f"orbits apart, the section strobes the free libration; re-measuring by min max|α|")
        # the forced solution α = −ψ_A sin M starts at θ̇_p/n ≈ 1 + 2e + ψ_A (ψ_A signed)
        e = system.e
        guess = 1.0 + 2.0 * e + analytic.psi_A(system.omega0, e)
        table["center_min"][i, j], table["amplitude_min"][i, j], resolved = minimum_amplitude(
            system, guess, MINIMUM_ORBITS)
        if not resolved:
            print(f"  warning: min max|alpha| not bracketed for {names[i]} a/b = {elongations[j]}")
    # the best estimate of the relaxed amplitude: the second method where the section fails
    best = np.where(strobed, table["amplitude_min"], table["amplitude"])
    best_center = np.where(strobed, table["center_min"], table["center"])
    ratio = best / table["psi_A"]
    # the decoupled problem without the small-amplitude approximation, at ω0,eff
    table["nonlinear"] = np.full(shape, np.nan)
    for i, name in enumerate(names):
        for j, q in enumerate(elongations):
            system = tso.catalog.system(name, elongation=q)
            # the root nearest the linear centre: the branch that continues ψ_A
            table["nonlinear"][i, j] = np.degrees(analytic.decoupled_relaxed_libration(
                analytic.omega0_effective(system), system.e)[1])
    ratio_nonlinear = best / table["nonlinear"]
    # e_r = (r_max − r_min)/(r_max + r_min) along every best centre trajectory, one launch
    table["e_radial"] = np.full(shape, np.nan)
    done = np.argwhere(np.isfinite(best_center))
    if len(done):
        systems = [tso.catalog.system(names[i], elongation=elongations[j]) for i, j in done]
        ts = tso.time_series(systems, 0.0, best_center[tuple(done.T)], RADIAL_ORBITS,
                             samples_per_orbit=RADIAL_SAMPLES_PER_ORBIT, rtol=RTOL)
        r_max, r_min = np.nanmax(ts.r, axis=1), np.nanmin(ts.r, axis=1)
        table["e_radial"][tuple(done.T)] = (r_max - r_min) / (r_max + r_min)

    print(f"\n{'system':<11} {'a/b':>5} {'e':>7} {'centre':>9} {'amplitude':>10} {'|psi_A|':>9} "
          f"{'ratio':>6} {'nonlin':>8} {'ratio':>6} {'extent':>8} {'T_sec/T':>7} {'e_r':>7} conv"
          f"   (angles deg, centre in n)")
    numbers = {}
    for i, name in enumerate(names):
        e = tso.catalog.entry(name)["e"]
        for j, q in enumerate(elongations):
            line = (f"{name:<11} {q:5.2f} {e:7.4f} {table['center'][i, j]:9.5f} "
                    f"{table['amplitude'][i, j]:10.4f} {table['psi_A'][i, j]:9.4f} "
                    f"{table['amplitude'][i, j] / table['psi_A'][i, j]:6.3f} "
                    f"{table['nonlinear'][i, j]:8.4f} {ratio_nonlinear[i, j]:6.3f} "
                    f"{table['extent'][i, j]:8.1e} {table['T_sec'][i, j]:7.4f} "
                    f"{table['e_radial'][i, j]:7.4f} {'yes' if converged[i, j] else 'NO'}")
            if strobed[i, j]:
                line += (f"   strobed; min max|alpha|: centre {table['center_min'][i, j]:.5f}, "
                         f"amplitude {table['amplitude_min'][i, j]:.4f}, ratio {ratio[i, j]:.3f}")
            if f"{name} a/b={q}" in failures:
                line += "   FAILED (see above)"
            print(line)
        numbers[f"{name} amplitude_deg"] = np.round(best[i], 4).tolist()
        numbers[f"{name} amplitude/|psi_A|"] = np.round(ratio[i], 3).tolist()
        numbers[f"{name} nonlinear decoupled/|psi_A|"] = np.round(
            table["nonlinear"][i] / table["psi_A"][i], 3).tolist()
        numbers[f"{name} amplitude/nonlinear decoupled"] = np.round(ratio_nonlinear[i], 3).tolist()
    numbers["elongations"] = elongations
    numbers["converged"] = f"{int(converged.sum())}/{converged.size}"
    numbers["failed"] = list(failures) or "none"
    numbers["strobed (re-measured)"] = [f"{names[i]} a/b={elongations[j]}"
                                        for i, j in np.argwhere(strobed)] or "none"

    # figure: one panel per system (amplitude and |ψ_A| vs a/b), last panel the ratios
    ncols = 4 if len(names) > 3 else len(names) + 1
    nrows = int(np.ceil((len(names) + 1) / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.6 * ncols, 3.1 * nrows), squeeze=False)
    axes = axes.ravel()
    fine = np.linspace(1.005, max(elongations) + 0.02, 200)
    for i, name in enumerate(names):
        ax = axes[i]
        e = tso.catalog.entry(name)["e"]
        psi_curve = np.degrees(np.abs(analytic.psi_A(analytic.omega0(fine), e)))
        ax.plot(fine, psi_curve, "k--", lw=1, label=r"$|\psi_A|$, nominal e")
        ax.plot(elongations, table["nonlinear"][i], "d:", color="C0", ms=4, lw=1,
                label=r"decoupled, nonlinear ($\omega_{0,\rm eff}$)")
        e_r = table["e_radial"][i]
        if np.nanmax(e_r) > 1.5 * e:   # the orbit's own radial oscillation dominates the forcing
            ax.plot(elongations, np.degrees(np.abs(analytic.psi_A(
                analytic.omega0(np.array(elongations)), np.nan_to_num(e_r)))), "s", mfc="none",
                mec="0.3", ms=6, label=r"$|\psi_A|$ with e = $e_r$ (measured)")
        ax.plot(elongations, best[i], "o-", color="C3", ms=5, label="measured")
        failed = np.array([f"{name} a/b={q}" in failures for q in elongations])
        if failed.any():
            ax.plot(np.array(elongations)[failed], np.zeros(failed.sum()), "x", color="C3",
                    ms=9, mew=2, clip_on=False, label="no stable centre")
        for j in np.flatnonzero(strobed[i]):   # off the scale: a note, not a point
            ax.annotate(f"a/b = {elongations[j]}: section 'centre' {table['amplitude'][i, j]:.1f}°"
                        f"\n(strobes the free libration; not used)", (0.03, 0.55),
                        xycoords="axes fraction", fontsize=6, color="C0")
        bad = ~converged[i] & np.isfinite(table["amplitude"][i])
        ax.plot(np.array(elongations)[bad], table["amplitude"][i][bad], "x", color="k", ms=9,
                label="search not converged" if bad.any() else None)
        ax.set_title(f"{name}  (e = {e}, $m_1/m_2$ = "
                     f"{tso.catalog.system(name).mass_ratio:.3g})", fontsize=8)
        ax.set_xlabel("a/b", fontsize=8)
        ax.set_ylabel("amplitude (deg)", fontsize=8)
        ax.set_ylim(bottom=0)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6, loc="upper left")
    ax = axes[len(names)]
    for i, name in enumerate(names):
        ax.plot(elongations, ratio[i], "o-", ms=4, label=name)
    ax.axhline(1.0, color="k", lw=0.8, ls="--")
    ax.set_yscale("log")
    ticks = [t for t in (0.5, 0.7, 1, 1.5, 2, 3, 5, 10)
             if np.nanmin(ratio) / 1.2 <= t <= np.nanmax(ratio) * 1.2]
    ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
    ax.minorticks_off()
    ax.set_title(r"measured / $|\psi_A|$ (nominal e)", fontsize=8)
    ax.set_xlabel("a/b", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6)
    for ax in axes[len(names) + 1:]:
        ax.set_visible(False)
    fig.suptitle(f"Paper Fig. 10: relaxed-mode libration at the synchronous island centre "
                 f"({orbits} orbits per trajectory, rtol {RTOL:.0e})", fontsize=9)
    save(args, "study08_libration_elongation", fig,
         {"systems": np.array(names), "elongations": np.array(elongations), **table,
          "best_amplitude": best, "best_center": best_center, "ratio": ratio,
          "ratio_nonlinear": ratio_nonlinear,
          "converged": converged, "strobed": strobed},
         {"paper": "Fig. 10", "orbits": orbits, "rtol": RTOL, "strobe_tolerance": STROBE_TOLERANCE,
          "extent_tolerance": MAX_CENTER_EXTENT_DEG, "radial_orbits": RADIAL_ORBITS,
          "minimum_orbits": MINIMUM_ORBITS, "failures": failures}, numbers, started)


if __name__ == "__main__":
    main()
