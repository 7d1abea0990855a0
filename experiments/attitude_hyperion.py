"""Attitude instability of a Hyperion-like satellite (beyond the paper: its first "future work").

Wisdom, Peale & Mignard (1984, Icarus 58, 137) showed that for Hyperion (ω0 ≈ 0.89, e ≈ 0.1,
a satellite far lighter than Saturn) both the synchronous state and the chaotic zone are
*attitude unstable*: a small tilt of the spin axis out of the orbit plane grows
exponentially, with an e-folding time of a few orbital periods, so the satellite tumbles.

Here: Saturn as a uniform sphere (mass 5.68e26 kg, radius 58 232 km) and Hyperion as a uniform
ellipsoid 180 × 137 × 103 km of density 544 kg/m³ (ω0 = 0.894 n, mass ratio ~1e8: the
decoupled limit) on an orbit of a = 1.4811e6 km, e = 0.1. Starts at pericentre with the long
axis on the line of centres, tilted by 1e-4° in roll or in pitch, each spinning at

* the synchronous island centre (found by ``relaxed_libration`` in the planar problem),
* 1.6 n, in the chaotic zone,
* 2.5 n, beyond it (a regular fast rotation),

and, as a control, the synchronous Didymos secondary (ω0 = 0.88, e = 0.04, its libration
stable out of the plane as well). The 3-D model integrates each for ``--orbits`` orbits at
rtol 1e-12 (``time_series(initial_states=..., states=True)``); the pole tilt (angle between
the short axis and the orbit normal, ``TimeSeriesResult.pole_tilt``) is sampled 16 times per
orbit, and its e-folding time is
the slope of a least-squares line through log(tilt) while the tilt grows from 10× its start to
1° (the linear regime). "stable" means the tilt never left 10× its start.
"""

import numpy as np

import _common


def hyperion_system():
    import ti_spinorbit as tso

    radius = 5.8232e7
    saturn = tso.Sphere(radius, density=5.68e26 / (4.0 / 3.0 * np.pi * radius**3), name="Saturn")
    hyperion = tso.Ellipsoid(180e3, 137e3, 103e3, density=544.0, name="Hyperion")
    return tso.BinarySystem(saturn, hyperion, a=1.4811e9, e=0.1, name="Saturn–Hyperion")


def e_folding(t_orbits, tilt, start):
    """E-folding time (orbits) of the tilt's growth from 10× ``start`` to 1°; inf if it never
    grows past 10× its start."""
    grown = np.nonzero(tilt > 10 * start)[0]
    if len(grown) == 0:
        return np.inf
    window = (t_orbits >= t_orbits[grown[0]]) & (tilt < 1.0)
    end = np.nonzero(tilt >= 1.0)[0]
    if len(end):
        window &= t_orbits < t_orbits[end[0]]
    if window.sum() < 4:
        return np.nan
    slope = np.polyfit(t_orbits[window], np.log(tilt[window]), 1)[0]
    return 1.0 / slope


def main():
    args, started = _common.parse(__doc__.splitlines()[0], extra=lambda p: p.add_argument(
        "--orbits", type=float, default=None, help="orbits per run (default 40; quick 20)"))
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    orbits = args.orbits or (20.0 if args.quick else 40.0)
    tilt0 = 1e-4                                                    # degrees
    hyp = hyperion_system()
    centre = tso.relaxed_libration(hyp, orbits=50, rtol=1e-11).centre_thetadot_p
    didymos = tso.catalog.system("Didymos")
    cases = [("Hyperion, synchronous centre", hyp, centre), ("Hyperion, chaotic zone", hyp, 1.6),
             ("Hyperion, 2.5 n", hyp, 2.5), ("Didymos, synchronous", didymos, 1.0)]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    arrays, numbers = {}, {"island_centre_thetadot": float(centre)}
    for (label, system, spin), colour in zip(cases, ("C3", "C1", "C0", "C2")):
        states = [system.tilted_start(0.0, spin, roll=tilt0), system.tilted_start(0.0, spin, pitch=tilt0)]
        ts = tso.time_series(system, orbits=orbits, samples_per_orbit=16, rtol=1e-12,
                             model="3d", initial_states=states, states=True, progress=False)
        if not np.all(ts.status == tso.Status.DONE):
            raise SystemExit(f"{label}: a run stopped early or failed its accuracy check "
                             f"({ts.status_names})")
        key = label.split(",")[0].lower() + "_" + label.split(", ")[1].replace(" ", "_").replace(".", "")
        folds = []
        for k, how in enumerate(("roll", "pitch")):
            t = ts.t[k] / system.orbital_period
            tilt = ts.pole_tilt[k]
            folds.append(e_folding(t, tilt, tilt0))
            ax.semilogy(t, np.maximum(tilt, 1e-7), color=colour, lw=1.0, ls="-" if k == 0 else "--",
                        label=f"{label} ({how})" if k == 0 else None)
            arrays[f"{key}_{how}_t_orbits"] = t
            arrays[f"{key}_{how}_tilt_deg"] = tilt
        numbers[f"{key}_efold_orbits_roll"] = folds[0]
        numbers[f"{key}_efold_orbits_pitch"] = folds[1]
        numbers[f"{key}_max_tilt_deg"] = float(np.max(ts.max_tilt))
        numbers[f"{key}_attitude_class"] = ts.attitude_class_names
    ax.axhline(1.0, color="0.6", lw=0.6)
    ax.set_xlabel("time (orbits)")
    ax.set_ylabel(r"pole tilt from the orbit normal (deg)")
    ax.set_title(f"Attitude (in)stability from a {tilt0:g}° tilt (solid: roll, dashed: pitch), "
                 f"e = 0.1, rtol 1e-12", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    _common.save(args, "attitude_hyperion", fig, arrays,
                 {"orbits": orbits, "initial_tilt_deg": tilt0, "rtol": 1e-12,
                  "samples_per_orbit": 16, "system": hyp.describe()}, numbers, started)


if __name__ == "__main__":
    main()
