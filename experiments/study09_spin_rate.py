"""Paper Fig. 11 (Naidu & Margot 2015; script study09): spin rate vs time for four 1991 VH trajectories.

θ_p = 0 and θ̇_p/n = 0.45 (synchronous island, shifted by relaxed-mode libration), 1.70
(chaotic), 2.38 (the paper's resonant example), 2.60 (quasi-periodic, circulating). A chaotic
spin wanders irregularly between resonances; regular ones stay in a band. Measured here
(300 orbits, apsidal): 0.45 resonant, 1.70 chaotic, 2.60 quasi-periodic, and 2.38 chaotic:
at θ_p = 0 the 2:1 island of this model tops out near 2.3 (study06's section), so 2.38 starts
in the chaotic layer just above it and wanders down to θ̇/n ≈ −0.1.

Coordinates: apsidal, the paper's (docs/physics.md §6.7): the starts are the paper's and the
plotted θ̇/n is the rate of θ measured from the osculating line of apsides (spin rate − ϖ̇).

Each panel names the trajectory's class (``classify_section`` of the same starts' pericentre
section, with MEGNO; the point minimum relaxed for the quick run as chaos maps do).

Prints: range of θ̇/n and the class of each trajectory.
"""

import numpy as np

from _common import parse, save

STARTS = [0.45, 1.70, 2.38, 2.60]


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    vh = tso.catalog.system("1991 VH")
    orbits = 20 if args.quick else 300
    ts = tso.time_series(vh, 0.0, STARTS, orbits=orbits, samples_per_orbit=32, rtol=1e-12,
                         coordinates="apsidal")
    from ti_spinorbit.classify import classify_section
    from ti_spinorbit.plotting import CLASS_COLORS, run_title

    section = tso.surface_of_section(vh, 0.0, STARTS, orbits=orbits, rtol=1e-12,
                                     coordinates="apsidal", indicators=True)
    classes = classify_section(section, min_points=int(min(64, max(8, 0.8 * orbits)))).classification
    fig, axes = plt.subplots(len(STARTS), 1, figsize=(7, 8), sharex=True)
    numbers = {}
    for k, (ax, w) in enumerate(zip(axes, STARTS)):
        ok = np.isfinite(ts.t[k])
        ax.plot(ts.t[k, ok] / vh.orbital_period, ts.thetadot[k, ok], lw=0.6,
                color=CLASS_COLORS.get(classes[k], "0.4"))
        ax.set_ylabel(r"$\dot\theta/n$ (apsidal)")
        ax.set_title(rf"$\dot\theta_p(0)/n$ = {w}: {classes[k]}", fontsize=8)
        numbers[f"thetadot range ({w})"] = [float(np.nanmin(ts.thetadot[k])), float(np.nanmax(ts.thetadot[k]))]
        numbers[f"class ({w})"] = str(classes[k])
    fig.suptitle(run_title([vh], orbits, 1e-12, "spin rate against time"), fontsize=9)
    axes[-1].set_xlabel("time (orbits)")
    save(args, "study09_spin_rate", fig,
         {"t_s": ts.t, "thetadot": ts.thetadot, "alpha_deg": ts.alpha, "starts": STARTS},
         {"system": vh.describe(), "orbits": orbits, "rtol": 1e-12, "coordinates": "apsidal"},
         numbers, started)


if __name__ == "__main__":
    main()
