"""Paper Fig. 1 (Naidu & Margot 2015; script study01): energy and angular-momentum exchange over 5 days.

The paper's energy-check case (docs/physics.md §7): ellipsoidal primary 600 x 500 x 400 m spinning
with a 2.775 h period, secondary 252 x 229 x 190 m with a 32.59 h period, a = 3300 m,
e = 0.05. Orbit, primary-spin and secondary-spin energies (and angular momenta) trade with
each other while the totals stay constant to the integration tolerance.

Prints: the largest exchange of each part and the total's relative drift.
"""

import numpy as np

from _common import parse, save

DAY = 86400.0


def main():
    args, started = parse(__doc__.splitlines()[0], lambda p: p.add_argument(
        "--rtol", type=float, default=1e-13, help="tolerance (paper: 1e-15; default 1e-13)"))
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    system = tso.catalog.system("test")
    spin2 = 2 * np.pi / tso.catalog.secondary_spin_period("test") / system.mean_motion
    days = 1.0 if args.quick else 5.0
    # resolve the fast primary spin (2.775 h): ~40 samples per rotation, else the plot aliases
    per_orbit = int(np.ceil(40 * system.orbital_period / system.primary_spin_period))
    ts = tso.time_series(system, 0.0, spin2, orbits=days * DAY / system.orbital_period,
                         samples_per_orbit=per_orbit, rtol=args.rtol)
    t = ts.t[0] / DAY
    parts = {"orbit": ts.energy_orbit[0], "primary spin": ts.energy_primary[0],
             "secondary spin": ts.energy_secondary[0]}
    E0 = ts.energy[0, 0]
    lparts = {"orbit": ts.angmom_orbit[0, :, 2], "primary spin": ts.angmom_primary[0, :, 2],
              "secondary spin": ts.angmom_secondary[0, :, 2]}
    L0 = sum(v[0] for v in lparts.values())
    fig, axes = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True)
    for name, e in parts.items():
        axes[0].plot(t, (e - e[0]) / abs(E0), label=name)
    axes[0].plot(t, (ts.energy[0] - E0) / abs(E0), "k", label="total")
    axes[0].set_ylabel(r"$\Delta E / |E_0|$")
    for name, l in lparts.items():
        axes[1].plot(t, (l - l[0]) / abs(L0), label=name)
    ltot = sum(lparts.values())
    axes[1].plot(t, (ltot - L0) / abs(L0), "k", label="total")
    axes[1].set_ylabel(r"$\Delta L_z / |L_0|$")
    axes[1].set_xlabel("time (days)")
    axes[0].legend(fontsize=8)
    axes[0].set_title(f"Energy-check system, rtol {args.rtol:.0e}: exchange between orbit and spins",
                      fontsize=9)
    numbers = {f"max |dE_{k.replace(' ', '_')}|/|E0|": float(np.max(np.abs(v - v[0])) / abs(E0))
               for k, v in parts.items()}
    numbers["total energy drift"] = float(np.max(np.abs(ts.energy[0] - E0)) / abs(E0))
    numbers["total angular momentum drift"] = float(np.max(np.abs(ltot - L0)) / abs(L0))
    numbers["days"] = days
    save(args, "study01_energy", fig, {"t_days": t, **{f"E_{k}": v for k, v in parts.items()},
                                       "E_total": ts.energy[0], "Lz_total": ltot},
         {"system": system.describe(), "rtol": args.rtol, "days": days}, numbers, started)


if __name__ == "__main__":
    main()
