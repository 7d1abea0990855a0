"""Paper §6 (Naidu & Margot 2015, text; script study07): elongation at which the 1:1 and 3:2 resonances
overlap, numerically and from the decoupled theory ω0^RO = 1/(2 + sqrt(14 e)).

For each system (1991 VH, 2003 YT1, 2004 DC) the elongation a/b is scanned in steps of
0.01; at each value an ensemble of trajectories decides whether a single chaotic orbit
connects the synchronous and 3:2 zones (ti_spinorbit.studies.overlap). A decision at a fixed orbit
count is only an upper bound on the threshold, so the scan doubles the integration length
(300, 600, 1200, 2400 orbits in full mode; 50, 100 in quick mode) until two successive
lengths agree at every elongation and no elongation is still "separate" where the MEGNO
criterion already sees one chaotic layer spanning both islands; otherwise the threshold is
reported as "not converged by N orbits" (an upper bound). Each length integrates again only
the elongations still separate.

Coordinates: apsidal, the paper's (docs/physics.md §6.7), by default: the starts, island
centres and ranges are in θ̇ from the osculating line of apsides; ``--coordinates inertial``
runs the same scan in the package's default coordinates (the figure and files then carry the
suffix ``_inertial``).

Prints: per system the decisions per elongation against length (geometric and MEGNO), the
first overlapping a/b with its verdict, the MEGNO-criterion threshold and the analytic one.
"""

import numpy as np

from _common import parse, save

SYSTEMS = ("1991 VH", "2003 YT1", "2004 DC")


def main():
    def flags(p):
        p.add_argument("--orbits", type=float, default=None,
                       help="orbits of the first length (default 300; quick 50)")
        p.add_argument("--max-orbits", type=float, default=None,
                       help="cap of the doubling (default 8 x --orbits; quick 2 x)")
        p.add_argument("--coordinates", choices=("apsidal", "inertial"), default="apsidal",
                       help="section coordinates (default apsidal, the paper's)")

    args, started = parse(__doc__.splitlines()[0], flags)
    import matplotlib.pyplot as plt

    from ti_spinorbit.studies.overlap import overlap_threshold

    orbits = args.orbits or (50 if args.quick else 300)
    max_orbits = args.max_orbits or (2 * orbits if args.quick else 8 * orbits)
    elong = np.round(np.arange(1.01, 1.035, 0.01) if args.quick else np.arange(1.01, 1.125, 0.01), 10)
    kw = dict(centre_starts=24, separatrix_starts=12) if args.quick else {}
    fig, axes = plt.subplots(2, len(SYSTEMS), figsize=(14, 8), gridspec_kw={"height_ratios": [1, 2]})
    numbers, arrays = {}, {}
    for col, name in enumerate(SYSTEMS):
        scan = overlap_threshold(name, elongations=elong, orbits=orbits, max_orbits=max_orbits,
                                 coordinates=args.coordinates, **kw)
        print(f"{name} (e = {scan.eccentricity}, analytic a/b = {scan.elongation_ro:.4f}), "
              f"{scan.seconds:.1f} s, {scan.member_orbits:.3g} member-orbits:")
        print("\n".join("  " + line for line in scan.evidence()))
        scan.plot(axes[0, col], title=f"{name} (e = {scan.eccentricity})")
        # the connecting trajectory at the first overlap (or the widest one at the last a/b)
        k = (list(scan.elongations).index(scan.first_overlap) if scan.first_overlap is not None
             else len(scan.elongations) - 1)
        d = scan.decisions[k]
        sec, block = scan.section_block(k)           # the run this decision comes from
        lo = block.start
        nc = block.stop - lo - int(np.sum(sec.initial_theta_p[block] == 90.0))
        ax = axes[1, col]
        for m in range(lo, lo + nc, 3):   # a few θ_p = 0 traces for context
            ax.plot(sec.theta_p[m], sec.thetadot_p[m], ",", color="0.6")
        if d.connecting_start is not None:
            sep = np.where(np.isclose(sec.initial_thetadot_p[lo + nc:block.stop],
                                      d.connecting_start))[0][0]
            m = lo + nc + sep
            ax.plot(sec.theta_p[m], sec.thetadot_p[m], ".", ms=1.0, color="tab:blue",
                    label=f"connecting orbit (start {d.connecting_start:.3f})")
        ax.axhline(d.centre_1, color="tab:red", lw=0.6)
        ax.axhline(d.centre_3_2, color="tab:red", lw=0.6, ls=":")
        ax.set_xlim(0, 180)
        ax.set_xlabel(r"$\theta_p$ (deg)")
        ax.set_ylabel(rf"$\dot\theta_p/n$ ({args.coordinates})")
        ax.set_title(f"a/b = {d.elongation:.2f}, {d.orbits:g} orbits: 1:1 and 3:2 centres (red)",
                     fontsize=8)
        ax.legend(fontsize=6, loc="upper right")
        numbers[f"{name} numerical a/b"] = scan.first_overlap
        numbers[f"{name} converged"] = scan.converged
        numbers[f"{name} converged at orbits"] = (scan.converged_orbits if scan.converged
                                                  else None)
        numbers[f"{name} verdict"] = scan.message
        numbers[f"{name} MEGNO-criterion a/b"] = scan.megno_first_overlap
        numbers[f"{name} analytic a/b"] = round(scan.elongation_ro, 4)
        numbers[f"{name} monotonic"] = scan.monotonic
        numbers[f"{name} member-orbits"] = scan.member_orbits
        key = name.replace(' ', '')
        arrays[f"{key}_elongations"] = scan.elongations
        arrays[f"{key}_overlaps"] = scan.overlaps
        arrays[f"{key}_lengths"] = scan.lengths
        arrays[f"{key}_overlaps_by_length"] = scan.overlaps_by_length
        arrays[f"{key}_megno_overlaps_by_length"] = scan.megno_overlaps_by_length
    suffix = "" if args.coordinates == "apsidal" else "_" + args.coordinates
    save(args, "study07_overlap_thresholds" + suffix, fig, arrays,
         {"orbits": orbits, "max_orbits": max_orbits, "elongations": elong,
          "systems": list(SYSTEMS), "coordinates": args.coordinates}, numbers, started)


if __name__ == "__main__":
    main()
