"""Paper §8.1 (Naidu & Margot 2015, text; script study10): tidal and YORP energy per orbit vs chaotic energy changes.

For each asynchronous system (1991 VH, 2003 YT1, 2004 DC) energies per mutual orbit are
normalised by the separatrix energy E0 = n²ω0²C/4: the analytic chaotic-layer half-width
(14π form quoted by the paper, and the 28π Melnikov form), the tidal dissipation
π(3/2)(k2/Q)(n⁴/G)R_s⁵ with Q = 100 and two rubble-pile k2 models, and the YORP work
2πR_s³L_⊙f_Y/(3cd²√(1−e_⊙²)). The chaotic variation is also measured: a start in the chaotic
sea (checked by a shadow trajectory 1e-9 away, whose separation must grow to O(1)) is sampled
at fixed times and the change of the secondary's spin energy over one orbital period gives an
RMS ΔE/E0 (it holds the reversible spin-orbit exchange as well as the chaotic kicks; either
way it is the energy scale tides and YORP would have to compete with). Tides and YORP are many
orders of magnitude smaller, so they cannot pull a secondary out of chaos quickly.

Prints: per system E0, the analytic and measured chaotic ΔE/E0, the tidal and YORP ΔE/E0, and
the ratios tidal/chaotic and YORP/chaotic (against the measured RMS).

Coordinates: apsidal, the paper's (docs/physics.md §6.7): the chaotic starts are the paper's
θ̇_p(0)/n; the energies do not depend on the coordinates.
"""

import numpy as np

from _common import parse, save

#: Chaotic starts θ̇_p(0)/n (θ_p = 0): the paper's Fig. 7 chaotic orbit for 1991 VH; for the
#: others starts of its Figs. 8–9 that lie in the chaotic sea.
CHAOTIC_STARTS = {"1991 VH": 1.63, "2003 YT1": 1.29, "2004 DC": 1.39}
#: Shadow offset in θ̇_p/n and the separation that counts as O(1) divergence.
SHADOW_OFFSET, DIVERGED = 1e-9, 1e-2
SAMPLES_PER_ORBIT = 8
RTOL = 1e-12


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.model import analytic

    orbits = 120 if args.quick else 1000     # 1991 VH needs ~60 orbits to diverge
    names = list(CHAOTIC_STARTS)
    systems = [tso.catalog.system(n) for n in names]
    starts = np.array([CHAOTIC_STARTS[n] for n in names])

    # chaos check: every start and its shadow in one section launch
    sec = tso.surface_of_section([s for s in systems for _ in (0, 1)], 0.0,
                                 np.repeat(starts, 2) + np.tile([0.0, SHADOW_OFFSET], len(names)),
                                 orbits, rtol=RTOL, coordinates="apsidal")
    # spin energy at fixed times, one orbital period apart every SAMPLES_PER_ORBIT samples
    ts = tso.time_series(systems, 0.0, starts, orbits, samples_per_orbit=SAMPLES_PER_ORBIT,
                         rtol=RTOL, coordinates="apsidal")

    budgets, measured, separations, diverged_at, dE_series = [], [], [], [], []
    for k, (name, system) in enumerate(zip(names, systems)):
        orbit = tso.catalog.heliocentric_orbit(name)
        budget = analytic.energy_budget(system, orbit.a_au, orbit.e)
        budgets.append(budget)
        pair = sec.thetadot_p[2 * k:2 * k + 2]
        m = int(min(sec.count[2 * k:2 * k + 2]))
        gap = np.abs(pair[0, :m] - pair[1, :m])
        separations.append(float(np.max(gap)) if m else np.nan)
        over = np.flatnonzero(gap > DIVERGED)
        diverged_at = diverged_at + [float(sec.t[2 * k, over[0]] / system.orbital_period)
                                     if len(over) else np.nan]
        E = ts.energy_secondary[k]
        E = E[np.isfinite(E)]
        dE = (E[SAMPLES_PER_ORBIT:] - E[:-SAMPLES_PER_ORBIT]) / budget["E0_J"]
        dE_series.append(dE)
        measured.append(float(np.sqrt(np.mean(dE**2))))

    print(f"{'system':<9} {'start':>5} {'E0 (J)':>10} {'chaos 14pi':>10} {'chaos 28pi':>10} "
          f"{'measured':>9} {'tidal GS':>9} {'tidal JS':>9} {'YORP':>9} "
          f"{'tidal/chaos':>11} {'YORP/chaos':>10}  shadow")
    numbers = {}
    for k, name in enumerate(names):
        b = budgets[k]
        tidal = max(b["tidal_dE_over_E0_goldreich_sari"], b["tidal_dE_over_E0_jacobson_scheeres"])
        chaotic = separations[k] > DIVERGED
        print(f"{name:<9} {starts[k]:5.2f} {b['E0_J']:10.3e} {b['chaotic_dE_over_E0']:10.3e} "
              f"{b['chaotic_dE_over_E0_melnikov']:10.3e} {measured[k]:9.3e} "
              f"{b['tidal_dE_over_E0_goldreich_sari']:9.2e} "
              f"{b['tidal_dE_over_E0_jacobson_scheeres']:9.2e} {b['yorp_dE_over_E0']:9.2e} "
              f"{tidal / measured[k]:11.2e} {b['yorp_dE_over_E0'] / measured[k]:10.2e}  "
              + (f"diverged (> {DIVERGED:g}) after {diverged_at[k]:.0f} orbits" if chaotic
                 else f"NOT chaotic: max separation {separations[k]:.1e}"))
        numbers[f"{name} E0_J"] = b["E0_J"]
        numbers[f"{name} chaotic dE/E0 analytic 14pi, 28pi, measured RMS"] = [
            b["chaotic_dE_over_E0"], b["chaotic_dE_over_E0_melnikov"], measured[k]]
        numbers[f"{name} tidal dE/E0 (GS, JS)"] = [b["tidal_dE_over_E0_goldreich_sari"],
                                                   b["tidal_dE_over_E0_jacobson_scheeres"]]
        numbers[f"{name} YORP dE/E0"] = b["yorp_dE_over_E0"]
        numbers[f"{name} max tidal/chaotic"] = tidal / measured[k]
        numbers[f"{name} YORP/chaotic"] = b["yorp_dE_over_E0"] / measured[k]
        numbers[f"{name} chaotic start confirmed"] = bool(chaotic)

    # figure: (a) the budgets, log scale; (b) the measured per-orbit spin-energy changes
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8), gridspec_kw={"width_ratios": [1.3, 1]})
    bars = [("chaotic, 14π (analytic)", "chaotic_dE_over_E0", "C0", None),
            ("chaotic, 28π (analytic)", "chaotic_dE_over_E0_melnikov", "C9", None),
            ("chaotic, measured RMS", None, "C3", None),
            ("tides, k2 Goldreich & Sari", "tidal_dE_over_E0_goldreich_sari", "C2", None),
            ("tides, k2 Jacobson & Scheeres", "tidal_dE_over_E0_jacobson_scheeres", "C8", "//"),
            ("YORP", "yorp_dE_over_E0", "C1", None)]
    ax = axes[0]
    width = 0.8 / len(bars)
    x = np.arange(len(names))
    for j, (label, key, color, hatch) in enumerate(bars):
        values = measured if key is None else [b[key] for b in budgets]
        ax.bar(x + (j - (len(bars) - 1) / 2) * width, values, width, color=color, hatch=hatch,
               edgecolor="k", lw=0.4, label=label)
    ax.set_yscale("log")
    ax.set_xticks(x, [f"{n}\n(a/b = {tso.catalog.entry(n)['elongation']}, e = {s.e})"
                      for n, s in zip(names, systems)], fontsize=8)
    ax.set_ylabel(r"energy change per orbit, $\Delta E / E_0$")
    ax.set_title(r"Energy per mutual orbit, $E_0 = n^2\omega_0^2 C/4$ (Q = 100, $f_Y$ = 5e-4)",
                 fontsize=9)
    ax.grid(axis="y", which="major", lw=0.3)
    ax.set_ylim(1e-10, 1e5)                       # headroom for the legend
    ax.legend(fontsize=7, loc="upper center", ncol=2, framealpha=0.9)
    ax = axes[1]
    edges = np.linspace(-1.05, 1.05, 85) * max(np.max(np.abs(d)) for d in dE_series)
    for k, name in enumerate(names):
        ax.hist(dE_series[k], bins=edges, histtype="step", density=True, lw=1.2,
                color=f"C{k}",
                label=rf"{name}, $\dot\theta_p(0)/n$ = {starts[k]}: RMS {measured[k]:.2g}")
    ax.set_xlabel(r"$[E_{spin}(t + T) - E_{spin}(t)] / E_0$")
    ax.set_ylabel("probability density")
    ax.set_title(f"Measured: secondary spin-energy change over one orbital period T\n"
                 f"({orbits} orbits, {SAMPLES_PER_ORBIT} samples per orbit)", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    save(args, "study10_energy_budget", fig,
         {"systems": np.array(names), "starts": starts, "measured_rms_dE_over_E0": measured,
          "shadow_separation": separations,
          **{f"{key}": [b[key] for b in budgets] for key in budgets[0]},
          **{f"dE_over_E0_{n.replace(' ', '')}": d for n, d in zip(names, dE_series)}},
         {"orbits": orbits, "rtol": RTOL, "samples_per_orbit": SAMPLES_PER_ORBIT,
          "shadow_offset": SHADOW_OFFSET, "starts": CHAOTIC_STARTS}, numbers, started)


if __name__ == "__main__":
    main()
