"""Paper §7 (Naidu & Margot 2015, text; script study11): robustness of the 1991 VH results to the secondary's c.

The secondary's short semi-axis c is not measured; the paper states that changing it by up
to 20 % leaves its results unchanged. Here 1991 VH at the radar elongation a/b = 1.5 (the
Fig. 7 system, script study06) is rebuilt with c scaled by 0.8, 0.9, 1.0, 1.1 and 1.2 at fixed
density ρ_s and fixed a, b (so the secondary's mass scales with c; docs/physics.md §7.1).
ω0 = sqrt(3(B − A)/C) of an ellipsoid does not depend on c at all; c enters through the mass
ratio (ω0,eff, §8.7) and the fourth-order terms of the mutual potential (§3). At this
elongation b = 196 m, so c ≥ 1.03 × 190 m makes c > b: the secondary is then built from its
inertia integrals directly (``Body``), still spinning about z in the planar problem.

For each c: the classification of the paper's 1991 VH starts (θ̇_p/n = 0.43 0.83 1.63 2.31
2.53, θ_p = 0; resonant / chaotic / quasi-periodic), the chaotic fraction of a MEGNO map of
the (θ_p, θ̇_p/n) plane, the centre of the synchronous island and its relaxed libration
amplitude (``relaxed_libration``), with m1/m2, ω0 and ω0,eff.

Prints: those numbers per c factor and the largest change against c × 1.0.
"""

import math

import numpy as np

from _common import parse, save
from _sections import section_panel

SYSTEM = "1991 VH"
ELONGATION = 1.5
FACTORS = [0.8, 0.9, 1.0, 1.1, 1.2]


def _double_factorial(k):
    return 1 if k <= 0 else k * _double_factorial(k - 2)


def secondary_with_c(a, b, c, mass, name):
    """Uniform ellipsoid of semi-axes a, b, c (m) along x, y, z and mass (kg), any order of
    b and c: the second- and fourth-order inertia integrals T^lmn = 3 m a^l b^m c^n
    (l−1)!!(m−1)!!(n−1)!!/(l+m+n+3)!! (docs/physics.md §2.2), as ``Ellipsoid`` builds them."""
    from ti_spinorbit.system.bodies import Body

    integrals = {}
    for order in (2, 4):
        for l in range(0, order + 1, 2):
            for m in range(0, order - l + 1, 2):
                n = order - l - m
                integrals[(l, m, n)] = (3.0 * mass * a**l * b**m * c**n * _double_factorial(l - 1)
                                        * _double_factorial(m - 1) * _double_factorial(n - 1)
                                        / _double_factorial(l + m + n + 3))
    return Body(mass, integrals, max(a, b, c), name)


def system_with_c(factor):
    """1991 VH at a/b = 1.5 with the secondary's c scaled by ``factor`` (density fixed)."""
    import ti_spinorbit as tso
    from ti_spinorbit.system.bodies import Sphere
    from ti_spinorbit.system.systems import BinarySystem

    d = tso.catalog.entry(SYSTEM)
    a_s, b_s = math.sqrt(d["ab"] * ELONGATION), math.sqrt(d["ab"] / ELONGATION)
    c_s = d["c"] * factor
    mass = d["rho_s"] * 4.0 / 3.0 * math.pi * a_s * b_s * c_s
    secondary = secondary_with_c(a_s, b_s, c_s, mass, f"{SYSTEM} secondary, c x {factor:g}")
    return BinarySystem(Sphere(d["R_p"], d["rho_p"], name=f"{SYSTEM} primary"), secondary,
                        d["a_m"], d["e"], name=f"{SYSTEM} c x {factor:g}")


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.model import analytic
    from ti_spinorbit.studies.libration import relaxed_libration

    starts = tso.catalog.section_starts(SYSTEM)
    orbits = 150 if args.quick else 600
    grid = (4, 4) if args.quick else (24, 24)
    map_orbits = 30 if args.quick else 300
    lib_orbits = 20 if args.quick else 100
    theta = np.linspace(0.0, 180.0, grid[0], endpoint=False)
    thetadot = np.linspace(0.3, 3.0, grid[1])

    fig = plt.figure(figsize=(16, 7.5))
    axes = [fig.add_subplot(2, len(FACTORS), k + 1) for k in range(len(FACTORS))]
    summary = fig.add_subplot(2, 1, 2)
    rows = {k: [] for k in ("mass_ratio", "omega0", "omega0_eff", "chaotic_fraction",
                            "center", "amplitude", "labels")}
    numbers = {}
    for ax, f in zip(axes, FACTORS):
        system = system_with_c(f)
        w_eff = analytic.omega0_effective(system)
        _, cls = section_panel(ax, system, starts, orbits,
                               what=f"c × {f:g} (c = {190 * f:.0f} m), $m_1/m_2$ = {system.mass_ratio:.1f}")
        labels = [lab if lab != "resonant" or not np.isfinite(p) else f"resonant p={p:g}"
                  for lab, p in zip(cls.classification, cls.resonance_p)]
        cmap = tso.chaos_map(system, theta, thetadot, orbits=map_orbits, rtol=1e-10)
        lib = relaxed_libration(system, orbits=lib_orbits, rtol=1e-12)
        for k, v in zip(rows, (system.mass_ratio, system.omega0, w_eff, cmap.chaotic_fraction,
                               lib.centre_thetadot_p, lib.amplitude, labels)):
            rows[k].append(v)
        numbers[f"c x {f:g}"] = (f"m1/m2 {system.mass_ratio:.2f}, omega0 {system.omega0:.4f}, "
                                 f"omega0_eff {w_eff:.4f}, chaotic fraction "
                                 f"{cmap.chaotic_fraction:.3f}, centre {lib.centre_thetadot_p:.4f}, "
                                 f"amplitude {lib.amplitude:.2f} deg, starts {labels}")
        print(f"c x {f:<4g} {numbers[f'c x {f:g}']}")
    nominal = FACTORS.index(1.0)
    same = [lab == rows["labels"][nominal] for lab in rows["labels"]]
    cf = np.array(rows["chaotic_fraction"])
    centre = np.array(rows["center"])
    amp = np.array(rows["amplitude"])
    numbers["start classifications unchanged from c x 1"] = bool(all(same))
    numbers["largest |change| of the chaotic fraction"] = float(np.max(np.abs(cf - cf[nominal])))
    numbers["largest |change| of the island centre (n)"] = float(np.max(np.abs(centre - centre[nominal])))
    numbers["largest |change| of the libration amplitude (deg)"] = float(np.max(np.abs(amp - amp[nominal])))
    numbers["omega0 (all c)"] = float(rows["omega0"][0])

    x = np.array(FACTORS)
    summary.plot(x, cf, "o-", color="C0", label=f"chaotic fraction ({grid[0]}×{grid[1]} MEGNO map, {map_orbits} orbits)")
    summary.set_ylabel("chaotic fraction", color="C0")
    summary.set_ylim(0, 1)
    twin = summary.twinx()
    twin.plot(x, centre, "s-", color="C3", label=r"synchronous island centre $\dot\theta_p(0)/n$")
    twin.set_ylabel(r"island centre $\dot\theta_p(0)/n$", color="C3")
    summary.set_xlabel(r"$c / c_{\rm nominal}$ (density fixed)")
    summary.set_xticks(FACTORS)
    summary.legend(loc="upper left", fontsize=8)
    twin.legend(loc="upper right", fontsize=8)
    summary.set_title(f"Paper §7: {SYSTEM}, a/b = {ELONGATION}, e = {system.e}: results against the "
                      f"secondary's c (ω0 = {rows['omega0'][0]:.3f} for every c)", fontsize=9)
    save(args, "study11_c_robustness", fig,
         {"factor": x, "mass_ratio": np.array(rows["mass_ratio"]),
          "omega0_eff": np.array(rows["omega0_eff"]), "chaotic_fraction": cf,
          "center": centre, "amplitude_deg": amp},
         {"paper": "§7", "system": SYSTEM, "elongation": ELONGATION, "factors": FACTORS,
          "section_orbits": orbits, "map_grid": list(grid), "map_orbits": map_orbits,
          "libration_orbits": lib_orbits, "starts": starts}, numbers, started)


if __name__ == "__main__":
    main()
