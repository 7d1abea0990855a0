"""Chaos maps: MEGNO over (θ_p, θ̇_p/n) for 1991 VH (a/b = 1.5), 2003 YT1 and 2004 DC.

Each map is one ensemble launch with shadow trajectories (ti_spinorbit.studies.chaosmap.chaos_map);
section points of a subsample of members are overlaid. A fourth panel histograms ⟨Y⟩ over
all maps: regular orbits pile up at ⟨Y⟩ ≈ 2 and chaotic ones spread far above it, which is
why the chaotic threshold sits at 4. Full run: 64 × 64 starts × 500 orbits for 1991 VH (the
package's benchmark size) and 48 × 48 × 300 for the other two; ``--quick``: 8 × 8 × 50.

Prints: chaotic fraction per system, seconds and member-orbits/s per map, and the share of
members in the histogram's gap 2.5 < ⟨Y⟩ < 4.
"""

import numpy as np

from _common import parse, save

#: (name, θ̇_p/n range of the map, full grid size, full orbits).
MAPS = (("1991 VH", (0.2, 3.0), 64, 500),
        ("2003 YT1", (0.2, 4.0), 48, 300),
        ("2004 DC", (0.2, 5.6), 48, 300))
QUICK_GRID, QUICK_ORBITS = 8, 50
RTOL = 1e-10


def _extra(p):
    p.add_argument("--systems", nargs="+", default=None,
                   help="only these systems (e.g. --systems '1991 VH' for the benchmark)")


def main():
    args, started = parse(__doc__.splitlines()[0], _extra)
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.studies.chaosmap import chaos_map
    from ti_spinorbit.output.plotting import MEGNO_COLOR_RANGE

    maps = [m for m in MAPS if args.systems is None or m[0] in args.systems]
    if not maps:
        raise SystemExit(f"--systems matches none of {[m[0] for m in MAPS]}")
    fig, axes = plt.subplots(1, len(maps) + 1, figsize=(5.2 * (len(maps) + 1), 4.6))
    numbers, arrays, megno_all = {}, {}, []
    for ax, (name, (low, high), size, orbits) in zip(axes, maps):
        if args.quick:
            size, orbits = QUICK_GRID, QUICK_ORBITS
        system = tso.catalog.system(name)
        theta_p = (np.arange(size) + 0.5) * 180.0 / size
        thetadot_p = np.linspace(low, high, size)
        cmap = chaos_map(system, theta_p, thetadot_p, orbits, rtol=RTOL)
        q = system.secondary.semi_axes[0] / system.secondary.semi_axes[1]
        cmap.plot(ax=ax, overlay=True, overlay_members=min(cmap.megno.size, 96),
                  title=f"{name}, a/b = {q:.2f}, e = {system.e}, {size}×{size}, {orbits} orbits\n"
                        f"chaotic fraction {cmap.chaotic_fraction:.3f}")
        key = name.replace(" ", "")
        numbers[f"{key} chaotic fraction"] = cmap.chaotic_fraction
        numbers[f"{key} grid"] = f"{size}x{size}x{orbits} orbits"
        numbers[f"{key} seconds"] = cmap.seconds
        numbers[f"{key} member-orbits/s"] = cmap.member_orbits_per_second
        arrays.update({f"{key}_theta_p": cmap.theta_p, f"{key}_thetadot_p": cmap.thetadot_p,
                       f"{key}_megno": cmap.megno, f"{key}_lyapunov": cmap.lyapunov,
                       f"{key}_classification": cmap.classification.astype("U16"),
                       f"{key}_mean_thetadot": cmap.mean_thetadot, f"{key}_status": cmap.status})
        megno_all.append(cmap.megno[np.isfinite(cmap.megno)].ravel())
        print(f"[chaos_maps] {name}: {size}x{size} x {orbits} orbits in {cmap.seconds:.1f} s "
              f"= {cmap.member_orbits_per_second:.0f} member-orbits/s; chaotic fraction "
              f"{cmap.chaotic_fraction:.3f}")

    y = np.concatenate(megno_all)
    ax = axes[-1]
    bins = np.logspace(np.log10(max(y.min(), 0.5)), np.log10(max(y.max(), 10.0)), 60)
    ax.hist(y, bins=bins, color="0.3")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(plt.NullFormatter())
    for v, text in ((2.0, "regular ⟨Y⟩ = 2"), (4.0, "threshold 4")):
        ax.axvline(v, color="r" if v == 4.0 else "g", ls="--", lw=1)
        ax.text(v * 1.05, ax.get_ylim()[1] * 0.5, text, rotation=90, va="top", fontsize=7)
    ax.set_xlabel(r"MEGNO $\langle Y\rangle$")
    ax.set_ylabel("members")
    ax.set_title(f"⟨Y⟩ of all {y.size} members (map colour range "
                 f"{MEGNO_COLOR_RANGE[0]:g}-{MEGNO_COLOR_RANGE[1]:g})", fontsize=9)
    numbers["share with 2.5 < <Y> < 4"] = float(np.mean((y > 2.5) & (y < 4.0)))
    numbers["share with <Y> <= 2.5"] = float(np.mean(y <= 2.5))
    numbers["share with <Y> >= 4"] = float(np.mean(y >= 4.0))
    save(args, "chaos_maps", fig, arrays,
         {"rtol": RTOL, "maps": [m[0] for m in maps], "quick": bool(args.quick)},
         numbers, started)


if __name__ == "__main__":
    main()
