"""Paper Fig. 11 (Naidu & Margot 2015; script study09): spin rate vs time for four 1991 VH trajectories.

θ_p = 0 and θ̇_p/n = 0.45 (synchronous island, shifted by relaxed-mode libration), 1.70
(chaotic), 2.38 (the paper's resonant example), 2.60 (quasi-periodic, circulating). A chaotic
spin wanders irregularly between resonances; regular ones stay in a band. Measured here
(300 orbits, inertial): 0.45 resonant 1:1, 1.70 chaotic, 2.38 resonant 2:1, 2.60
quasi-periodic, the paper's four classes.

Coordinates: INERTIAL (docs/physics.md §6.7, "Which figures of the paper use which"). The
paper's Fig. 11 starts are inertial spin rates: 0.45 is the inertial 1:1 island centre
(0.4518), and 1.70, 2.38 and 2.60 are the apsidal starts 1.63, 2.31 and 2.53 of its section of
1991 VH (study06) plus the apsidal rate at the start, ϖ̇(0) = 0.0666 n. Read as apsidal rates
(as this script did before) ϖ̇ is added twice: 2.38 becomes the inertial 2.447, which lies in
the chaotic layer above the 2:1 island and wanders down to θ̇/n ≈ −0.1. The plotted θ̇/n is the
inertial spin rate; the script prints ϖ̇(0) and the apsidal values of the starts.

Each panel names the trajectory's class (``classify_section`` of the same starts' pericentre
section, with MEGNO; the point minimum relaxed for the quick run as chaos maps do) and, for a
resonant one, its p:1.

Prints: ϖ̇(0)/n, the starts in apsidal coordinates, range of θ̇/n and the class of each
trajectory.
"""

import numpy as np

from _common import parse, save

STARTS = [0.45, 1.70, 2.38, 2.60]          # inertial θ̇_p(0)/n, the paper's Fig. 11
COORDINATES = "inertial"


def apsidal_rate_at_start(system):
    """ϖ̇(0)/n of the §6.4 start (θ_p = 0; the force does not depend on the spins), from the
    full fourth-order force (docs/physics.md §6.7)."""
    import ti_spinorbit as tso
    from ti_spinorbit.model.coordinates import apsidal_rate
    from ti_spinorbit.system.systems import G

    a, e, n = system.a, system.e, system.mean_motion
    R = np.array([a * (1.0 - e), 0.0, 0.0])
    V = np.array([0.0, n * a * np.sqrt((1.0 + e) / (1.0 - e)), 0.0])
    _, force, _, _ = tso.mutual_potential(system.primary, system.secondary, R, np.eye(3))
    m_red = system.primary.mass * system.secondary.mass / system.total_mass
    return float(apsidal_rate(R, V, force / m_red, G * system.total_mass)[0] / n)


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    vh = tso.catalog.system("1991 VH")
    orbits = 20 if args.quick else 300
    ts = tso.time_series(vh, 0.0, STARTS, orbits=orbits, samples_per_orbit=32, rtol=1e-12,
                         coordinates=COORDINATES)
    from ti_spinorbit.studies.classify import classify_section
    from ti_spinorbit.output.plotting import CLASS_COLORS, run_title

    section = tso.surface_of_section(vh, 0.0, STARTS, orbits=orbits, rtol=1e-12,
                                     coordinates=COORDINATES, indicators=True)
    found = classify_section(section, min_points=int(min(64, max(8, 0.8 * orbits))))
    classes = found.classification
    varpi_dot = apsidal_rate_at_start(vh)
    fig, axes = plt.subplots(len(STARTS), 1, figsize=(7, 8), sharex=True)
    numbers = {"apsidal rate at the start (n)": varpi_dot,
               "starts in apsidal coordinates": [round(w - varpi_dot, 4) for w in STARTS]}
    for k, (ax, w) in enumerate(zip(axes, STARTS)):
        ok = np.isfinite(ts.t[k])
        ax.plot(ts.t[k, ok] / vh.orbital_period, ts.thetadot[k, ok], lw=0.6,
                color=CLASS_COLORS.get(classes[k], "0.4"))
        label = str(classes[k])
        if label == "resonant" and np.isfinite(found.resonance_p[k]):
            label += f" {found.resonance_p[k]:g}:1"
        ax.set_ylabel(r"$\dot\theta/n$ (inertial)")
        ax.set_title(rf"$\dot\theta_p(0)/n$ = {w} (inertial; apsidal {w - varpi_dot:.2f}): "
                     f"{label}", fontsize=8)
        numbers[f"thetadot range ({w})"] = [float(np.nanmin(ts.thetadot[k])), float(np.nanmax(ts.thetadot[k]))]
        numbers[f"class ({w})"] = label
    fig.suptitle(run_title([vh], orbits, 1e-12, "spin rate against time"), fontsize=9)
    axes[-1].set_xlabel("time (orbits)")
    save(args, "study09_spin_rate", fig,
         {"t_s": ts.t, "thetadot": ts.thetadot, "alpha_deg": ts.alpha, "starts": STARTS},
         {"system": vh.describe(), "orbits": orbits, "rtol": 1e-12, "coordinates": COORDINATES,
          "apsidal_rate_at_start": varpi_dot},
         numbers, started)


if __name__ == "__main__":
    main()
