"""Paper §6 (Naidu & Margot 2015, text; script study07): elongation at which the 1:1 and 3:2 resonances
overlap, numerically and from the decoupled theory ω0^RO = 1/(2 + sqrt(14 e)).

For each system (1991 VH, 2003 YT1, 2004 DC) the elongation a/b is scanned in steps of
0.01; at each value an ensemble of trajectories decides whether a single chaotic orbit
connects the synchronous and 3:2 zones (ti_spinorbit.overlap). All elongations of a system
run in one kernel launch.

Coordinates: apsidal, the paper's (docs/physics.md §6.7): the starts, island centres and
ranges are in θ̇ from the osculating line of apsides.

Prints: the first overlapping a/b per system, numerical and analytic.
"""

import numpy as np

from _common import parse, save

SYSTEMS = ("1991 VH", "2003 YT1", "2004 DC")


def main():
    args, started = parse(__doc__.splitlines()[0], lambda p: p.add_argument(
        "--orbits", type=float, default=None, help="orbits per trajectory (default 600; quick 150)"))
    import matplotlib.pyplot as plt

    from ti_spinorbit.overlap import overlap_threshold

    orbits = args.orbits or (150 if args.quick else 600)
    elong = np.round(np.arange(1.01, 1.035, 0.01) if args.quick else np.arange(1.01, 1.125, 0.01), 10)
    kw = dict(center_starts=24, separatrix_starts=12) if args.quick else {}
    fig, axes = plt.subplots(2, len(SYSTEMS), figsize=(14, 8), gridspec_kw={"height_ratios": [1, 2]})
    numbers, arrays = {}, {}
    for col, name in enumerate(SYSTEMS):
        scan = overlap_threshold(name, elongations=elong, orbits=orbits, coordinates="apsidal",
                                 **kw)
        scan.plot(axes[0, col], title=f"{name} (e = {scan.eccentricity})")
        # the connecting trajectory at the first overlap (or the widest one at the last a/b)
        k = (list(scan.elongations).index(scan.first_overlap) if scan.first_overlap is not None
             else len(scan.elongations) - 1)
        d = scan.decisions[k]
        per = scan.sections.count.size // len(scan.elongations)
        nc = per - int(np.sum(scan.sections.initial_theta_p[k * per:(k + 1) * per] == 90.0))
        sec, ax = scan.sections, axes[1, col]
        for m in range(k * per, k * per + nc, 3):   # a few θ_p = 0 traces for context
            ax.plot(sec.theta_p[m], sec.thetadot_p[m], ",", color="0.6")
        if d.connecting_start is not None:
            sep = np.where(np.isclose(sec.initial_thetadot_p[k * per + nc:(k + 1) * per],
                                      d.connecting_start))[0][0]
            m = k * per + nc + sep
            ax.plot(sec.theta_p[m], sec.thetadot_p[m], ".", ms=1.0, color="tab:blue",
                    label=f"connecting orbit (start {d.connecting_start:.3f})")
        ax.axhline(d.center_1, color="tab:red", lw=0.6)
        ax.axhline(d.center_3_2, color="tab:red", lw=0.6, ls=":")
        ax.set_xlim(0, 180)
        ax.set_xlabel(r"$\theta_p$ (deg)")
        ax.set_ylabel(r"$\dot\theta_p/n$ (apsidal)")
        ax.set_title(f"a/b = {d.elongation:.2f}: 1:1 and 3:2 centres (red)", fontsize=8)
        ax.legend(fontsize=6, loc="upper right")
        numbers[f"{name} numerical a/b"] = scan.first_overlap
        numbers[f"{name} analytic a/b"] = round(scan.elongation_ro, 4)
        numbers[f"{name} monotonic"] = scan.monotonic
        arrays[f"{name.replace(' ', '')}_elongations"] = scan.elongations
        arrays[f"{name.replace(' ', '')}_overlaps"] = scan.overlaps
    save(args, "study07_overlap_thresholds", fig, arrays,
         {"orbits": orbits, "elongations": elong, "systems": list(SYSTEMS)}, numbers, started)


if __name__ == "__main__":
    main()
