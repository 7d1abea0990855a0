"""Paper §7.1–7.3 (Naidu & Margot 2015, text; script study12): 2:1 capture, 2003 YT1 libration, no 2004 DC island.

* §7.1: probability of capture into the 2:1 spin-orbit resonance of a secondary despun by
  tides, P_c = 2/(1 + πV/(2 ω0 sqrt|H(2, e)|)) (Murray & Dermott 1999 eq. 5.110;
  ``analytic.capture_probability``, docs/physics.md §8.9), for the asynchronous systems, with
  ω0 and with the coupled problem's ω0,eff.
* §7.2: the relaxed libration amplitude 2003 YT1's secondary would have if it were
  synchronous: the centre of its synchronous island and max |α| there (``relaxed_libration``,
  starts at θ_p = 0), against ψ_A.
* §7.3: 2004 DC (e = 0.30) has no synchronous island for a/b ≥ 1.1: the island-centre search
  converges at a/b = 1.02 and 1.05 and fails for 1.1, 1.2 and 1.3 (no librating start, or a
  "centre" whose section still spreads over tens of degrees), and a MEGNO map of the
  synchronous region (θ̇_p/n 0.3–1.6, every start classified and its resonance p assigned,
  ``classify_section``) shows the starts librating in the 1:1 resonance disappear (other
  islands, e.g. the 1:2 chain at θ_p = 90°, are drawn apart and not counted).

Prints: P_c per system; YT1 centre, amplitude, ψ_A; for 2004 DC per a/b whether an island
centre was found, its extent, and the fraction of the map librating in the 1:1 resonance.
"""

import warnings

import numpy as np

from _common import parse, save

ASYNCHRONOUS = ("1991 VH", "2003 YT1", "2004 DC")
DC_ELONGATIONS = [1.02, 1.05, 1.1, 1.2, 1.3]
#: Largest section extent (deg) of a synchronous-island centre (relaxed_libration's default).
ISLAND_EXTENT_DEG = 1.0


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from matplotlib.colors import ListedColormap

    from ti_spinorbit.model import analytic
    from ti_spinorbit.studies.classify import classify_section
    from ti_spinorbit.studies.libration import relaxed_libration

    numbers = {}
    arrays = {}
    # §7.1 -------------------------------------------------------------------------------
    pc, pc_eff = [], []
    for name in ASYNCHRONOUS:
        s = tso.catalog.system(name)
        pc.append(analytic.capture_probability(2, s.omega0, s.e))
        pc_eff.append(analytic.capture_probability(2, analytic.omega0_effective(s), s.e))
        numbers[f"§7.1 P_c(2:1) {name}"] = (f"{pc[-1]:.3f} (omega0 {s.omega0:.3f}, e {s.e}); "
                                          f"{pc_eff[-1]:.3f} with omega0_eff")
    arrays["capture_probability"] = np.array(pc)
    arrays["capture_probability_eff"] = np.array(pc_eff)

    # §7.2 -------------------------------------------------------------------------------
    lib_orbits = 30 if args.quick else 200
    yt1 = tso.catalog.system("2003 YT1")
    lib = relaxed_libration(yt1, orbits=lib_orbits, rtol=1e-12)
    numbers["§7.2 2003 YT1 island centre thetadot_p(0)/n"] = round(lib.centre_thetadot_p, 5)
    numbers["§7.2 2003 YT1 relaxed libration amplitude (deg)"] = round(lib.amplitude, 2)
    numbers["§7.2 2003 YT1 |psi_A| (deg)"] = round(abs(lib.psi_A), 2)
    numbers["§7.2 2003 YT1 search converged"] = bool(lib.converged)
    ts = tso.time_series(yt1, 0.0, lib.centre_thetadot_p, orbits=3, samples_per_orbit=256)

    # §7.3 -------------------------------------------------------------------------------
    grid = (4, 4) if args.quick else (24, 24)
    map_orbits = 40 if args.quick else 300
    theta = np.linspace(0.0, 180.0, grid[0], endpoint=False)
    thetadot = np.linspace(0.3, 1.6, grid[1])
    elongations = [1.05, 1.2] if args.quick else DC_ELONGATIONS
    found, extents, resonant = [], [], []
    fig = plt.figure(figsize=(16, 9))
    gs = fig.add_gridspec(2, 30)         # 30 columns: 3 panels above, 2 or 5 maps below
    top = [fig.add_subplot(gs[0, 10 * k:10 * k + 10]) for k in range(3)]
    w = 30 // len(elongations)
    maps = [fig.add_subplot(gs[1, w * k:w * k + w]) for k in range(len(elongations))]
    for ax, q in zip(maps, elongations):
        s = tso.catalog.system("2004 DC", elongation=q)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")     # "not converged" is the answer here
            try:
                r = relaxed_libration(s, orbits=lib_orbits, rtol=1e-12)
                ok, ext = bool(r.converged and r.extent <= ISLAND_EXTENT_DEG), float(r.extent)
                why = "" if ok else f"centre search not converged, extent {ext:.1f} deg"
            except (RuntimeError, ValueError):   # the search found no librating start
                ok, ext, why = False, float("nan"), "no start in 0.2–1.3 librates"
        cmap = tso.chaos_map(s, theta, thetadot, orbits=map_orbits, rtol=1e-10)
        cls = classify_section(cmap.section)         # members in the map's C order
        lab = np.asarray(cls.classification).reshape(cmap.shape)
        p = np.asarray(cls.resonance_p).reshape(cmap.shape)
        synchronous = (lab == "resonant") & (p == 1.0)
        frac = float(np.mean(synchronous))
        found.append(ok), extents.append(ext), resonant.append(frac)
        numbers[f"§7.3 2004 DC a/b = {q}"] = (f"synchronous island {'found' if ok else 'absent'}"
                                            f"{'' if ok else ' (' + why + ')'}, extent "
                                            f"{ext:.2g} deg, 1:1 fraction of the map {frac:.3f}")
        codes = np.select([synchronous, lab == "resonant", lab == "quasi-periodic",
                           lab == "chaotic"], [0, 1, 2, 3], 4)
        ax.pcolormesh(theta, thetadot, codes.T, shading="nearest", vmin=-0.5, vmax=4.5,
                      cmap=ListedColormap(["red", "orange", "green", "blue", "0.7"]))
        ax.set_title(f"a/b = {q}: {'island' if ok else 'no island'}, 1:1 {frac:.2f}", fontsize=8)
        ax.set_xlabel(r"$\theta_p(0)$ (deg)")
    maps[0].set_ylabel(r"2004 DC $\dot\theta_p(0)/n$" "\n(red 1:1, orange other p)")
    numbers["§7.3 no 2004 DC synchronous island for a/b >= 1.1"] = bool(
        not any(f for f, q in zip(found, elongations) if q >= 1.1))
    arrays.update({"dc_elongation": np.array(elongations), "dc_island_found": np.array(found),
                   "dc_extent_deg": np.array(extents), "dc_synchronous_fraction": np.array(resonant)})

    top[0].bar(range(3), pc, color="C0", label=r"$\omega_0$")
    top[0].plot(range(3), pc_eff, "k_", ms=30, label=r"$\omega_{0,\rm eff}$")
    top[0].set_xticks(range(3), ASYNCHRONOUS)
    top[0].set_ylim(0, 1.05)
    top[0].set_ylabel("P(capture into 2:1)")
    top[0].set_title("§7.1: 2:1 capture probability (M&D eq. 5.110)", fontsize=9)
    top[0].legend(fontsize=8)
    ok = np.isfinite(ts.t[0])
    top[1].plot(ts.t[0, ok] / yt1.orbital_period, ts.alpha[0, ok], color="C3")
    top[1].axhline(abs(lib.psi_A), color="k", ls="--", lw=0.8, label=rf"$|\psi_A|$ = {abs(lib.psi_A):.1f}°")
    top[1].axhline(-abs(lib.psi_A), color="k", ls="--", lw=0.8)
    top[1].set_xlabel("time (orbits)")
    top[1].set_ylabel(r"$\alpha$ (deg)")
    top[1].set_title(f"§7.2: 2003 YT1 at its synchronous-island centre: max |α| = {lib.amplitude:.1f}°",
                     fontsize=9)
    top[1].legend(fontsize=8)
    top[2].plot(elongations, resonant, "o-", color="C3")
    top[2].axvline(1.1, color="0.5", ls=":")
    top[2].set_xlabel("2004 DC a/b")
    top[2].set_ylabel("1:1 fraction of the map")
    top[2].set_title("§7.3: the synchronous island of 2004 DC disappears", fontsize=9)
    save(args, "study12_section7", fig, arrays,
         {"paper": "§7.1-7.3", "libration_orbits": lib_orbits, "map_grid": list(grid),
          "map_orbits": map_orbits, "dc_elongations": elongations}, numbers, started)


if __name__ == "__main__":
    main()
