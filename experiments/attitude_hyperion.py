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
* 3.0 n, beyond it (a regular fast rotation: the control),

and, as a second control, the synchronous Didymos secondary at its own island centre
(ω0 = 0.88, e = 0.04, its libration stable out of the plane as well). The 3-D model integrates each for ``--orbits`` orbits at
rtol 1e-12 (``time_series(initial_states=..., states=True)``); the pole tilt (angle between
the short axis and the orbit normal, ``TimeSeriesResult.pole_tilt``) is sampled 16 times per
orbit, and its e-folding time is
the slope of a least-squares line through log(tilt) while the tilt grows from 10× its start to
1° (the linear regime). "stable" means the tilt never left 10× its start.

The controls check themselves, first, over a window long enough to tell (``CHECK_ORBITS``,
whatever ``--orbits`` and ``--quick`` say): each must be regular in the plane (the planar
pericentre section with MEGNO, ``classify_section``: resonant or quasi-periodic) and keep
its 3-D tilt below 10× its start; otherwise the script stops with exit status 1 and says
which control failed and how. A short window cannot tell: 2.5 n, the control this script
used before, is chaotic in the plane (MEGNO 44 after 150 orbits, 152 after 400) and, tilted,
tumbles after 60–130 orbits, yet its tilt stays below 5e-4° for the first 40 orbits.
3.0 n is quasi-periodic (MEGNO 2.00 over 400 orbits) and keeps its tilt below 2e-4° over
2000 orbits. The Didymos control likewise starts at its island centre (0.79 n): started at
1.0 n, as this script did before, its large libration is slowly attitude unstable (the tilt
passes 10× its start after about 280 orbits and reaches 48° after 1000), while from the
centre it stays below 1.1e-4° over 1500 orbits. ``--control X`` runs the check (and the
figure) with a Hyperion control spin of X n.
"""

import ti_spinorbit
import numpy as np

import _common

#: The regular fast-rotation control of the Hyperion-like satellite, θ̇_p(0)/n.
CONTROL_SPIN = 3.0
#: Window of the controls' own check, orbits: planar section (classes need the MEGNO of a
#: long run) and 3-D tilt (a chaotic 2.5 n start tumbles only after 60–130 orbits).
CHECK_ORBITS = {"planar": 400, "3d": 600}
REGULAR = ("resonant", "quasi-periodic")


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


def check_controls(controls, tilt0):
    """Each (label, system, spin) of ``controls`` must be regular: its planar pericentre
    section over CHECK_ORBITS["planar"] orbits classified resonant or quasi-periodic (MEGNO),
    and its tilt (roll and pitch by ``tilt0`` degrees) below 10× ``tilt0`` over
    CHECK_ORBITS["3d"] orbits of the 3-D model. Returns the printed numbers; SystemExit
    naming the control and the failure otherwise."""
    import ti_spinorbit as tso
    from ti_spinorbit.studies.classify import classify_section

    numbers, failures = {}, []
    for label, system, spin in controls:
        key = label.lower().replace(", ", "_").replace(" ", "_").replace(".", "")
        orbits = CHECK_ORBITS["planar"]
        sec = tso.surface_of_section(system, 0.0, [spin], orbits=orbits, rtol=1e-12,
                                     indicators=True, run=ti_spinorbit.Run(progress=False))
        cls = classify_section(sec, min_points=64)
        planar, megno = str(cls.classification[0]), float(sec.megno[0])
        numbers[f"control {key} planar class ({orbits} orbits)"] = planar
        numbers[f"control {key} planar MEGNO"] = round(megno, 3)
        if planar not in REGULAR:
            failures.append(f"{label}: {planar} in the plane over {orbits} orbits "
                            f"(MEGNO {megno:.3g})")
        orbits = CHECK_ORBITS["3d"]
        states = [system.tilted_start(0.0, spin, roll=tilt0),
                  system.tilted_start(0.0, spin, pitch=tilt0)]
        ts = tso.time_series(system, orbits=orbits, samples_per_orbit=16, rtol=1e-12,
                             initial_states=states, states=True,
                             integrator=ti_spinorbit.Integrator(model="3d"),
                             run=ti_spinorbit.Run(progress=False))
        tilt = float(np.nanmax(ts.pole_tilt))
        numbers[f"control {key} max tilt over {orbits} orbits (deg)"] = tilt
        if not np.all(ts.status == tso.Status.DONE):
            failures.append(f"{label}: the {orbits}-orbit 3-D check stopped early or failed "
                            f"its accuracy check ({ts.status_names})")
        elif not tilt < 10 * tilt0:
            grown = [float(ts.t[k][np.argmax(ts.pole_tilt[k] > 10 * tilt0)] / system.orbital_period)
                     for k in range(2) if np.any(ts.pole_tilt[k] > 10 * tilt0)]
            failures.append(f"{label}: tilted by {tilt0:g} deg its pole left 10x its start after "
                            f"{min(grown):.0f} orbits (largest tilt {tilt:.3g} deg in {orbits} "
                            "orbits)")
    if failures:
        raise SystemExit("[attitude_hyperion] a control is not regular, so it controls nothing: "
                         + "; ".join(failures))
    return numbers


def main():
    def extra(p):
        p.add_argument("--orbits", type=float, default=None,
                       help="orbits per run (default 40; quick 20)")
        p.add_argument("--control", type=float, default=CONTROL_SPIN,
                       help=f"spin of the regular fast-rotation control, n (default "
                            f"{CONTROL_SPIN:g}); checked before anything else")

    args, started = _common.parse(__doc__.splitlines()[0], extra=extra)
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    orbits = args.orbits or (20.0 if args.quick else 40.0)
    tilt0 = 1e-4                                                    # degrees
    hyp = hyperion_system()
    didymos = tso.catalog.system("Didymos")
    control = ("Hyperion, " + f"{args.control:g} n", hyp, args.control)
    checked = check_controls([control], tilt0)                      # fail fast
    didymos_centre = tso.relaxed_libration(didymos, orbits=50, rtol=1e-11).centre_thetadot_p
    didymos_control = ("Didymos, synchronous centre", didymos, didymos_centre)
    checked.update(check_controls([didymos_control], tilt0))
    centre = tso.relaxed_libration(hyp, orbits=50, rtol=1e-11).centre_thetadot_p
    cases = [("Hyperion, synchronous centre", hyp, centre), ("Hyperion, chaotic zone", hyp, 1.6),
             control, didymos_control]
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    arrays, numbers = {}, {"island_centre_thetadot": float(centre),
                           "didymos_island_centre_thetadot": float(didymos_centre), **checked}
    for (label, system, spin), colour in zip(cases, ("C3", "C1", "C0", "C2")):
        states = [system.tilted_start(0.0, spin, roll=tilt0), system.tilted_start(0.0, spin, pitch=tilt0)]
        ts = tso.time_series(system, orbits=orbits, samples_per_orbit=16, rtol=1e-12,
                             initial_states=states, states=True,
                             integrator=ti_spinorbit.Integrator(model="3d"),
                             run=ti_spinorbit.Run(progress=False))
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
        numbers[f"{key}_max_tilt_deg"] = float(np.nanmax(ts.pole_tilt))
        numbers[f"{key}_attitude_class"] = ts.attitude_class_names
    ax.axhline(1.0, color="0.6", lw=0.6)
    ax.set_xlabel("time (orbits)")
    ax.set_ylabel(r"pole tilt from the orbit normal (deg)")
    ax.set_title(f"Attitude (in)stability from a {tilt0:g}° tilt (solid: roll, dashed: pitch), "
                 f"e = 0.1, rtol 1e-12\ncontrols checked regular: planar MEGNO over "
                 f"{CHECK_ORBITS['planar']} orbits, 3-D tilt over {CHECK_ORBITS['3d']} orbits",
                 fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    _common.save(args, "attitude_hyperion", fig, arrays,
                 {"orbits": orbits, "initial_tilt_deg": tilt0, "rtol": 1e-12,
                  "samples_per_orbit": 16, "system": hyp.describe(), "control_spin": args.control,
                  "check_orbits": CHECK_ORBITS}, numbers, started)


if __name__ == "__main__":
    main()
