"""Parameter map: chaotic fraction of 1991 VH over elongation a/b and eccentricity e.

At every (a/b, e) the default starts of ti_spinorbit.studies.chaosmap.parameter_map (θ_p ∈ {0°, 90°}
× 12 rates θ̇_p/n from 0.6 to 2.0, the band of the 1:1 and 3:2 resonances) run with MEGNO, all
grid points in one launch. Overlaid: the analytic overlap line a/b at ω0 = ω0^RO(e) =
1/(2 + sqrt(14e)) and contours of the chaotic-layer half-width ΔE/E0 (14π form;
docs/physics.md §8.6).
Full: a/b 1.0-1.59 (13; b ≥ c caps it at 1.596) × e 0-0.3 (7) × 24 starts × 300 orbits; ``--quick``: 3 × 2 × 8 starts
× 40 orbits.

Prints: the chaotic-fraction table, the analytic overlap a/b per e, seconds and member-orbits/s.
"""

import numpy as np

from _common import parse, save

SYSTEM = "1991 VH"
#: 1991 VH's catalogued a·b and c allow a/b ≤ 1.596 (b ≥ c), so the top row is 1.59.
MAX_ELONGATION = 1.59
RTOL = 1e-10


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    from ti_spinorbit.model import analytic
    from ti_spinorbit.studies.chaosmap import (PARAMETER_MAP_THETA_P, PARAMETER_MAP_THETADOT_P,
                                       parameter_map)

    if args.quick:
        elongations, eccentricities, orbits = np.array([1.01, 1.3, MAX_ELONGATION]), np.array([0.0, 0.2]), 40
        thetadot_p = np.linspace(0.6, 2.0, 4)
    else:
        elongations, eccentricities, orbits = np.minimum(np.linspace(1.0, 1.6, 13), MAX_ELONGATION), np.linspace(0.0, 0.3, 7), 300
        thetadot_p = np.asarray(PARAMETER_MAP_THETADOT_P)
    pmap = parameter_map(SYSTEM, elongations, eccentricities, orbits, thetadot_p=thetadot_p,
                         theta_p=PARAMETER_MAP_THETA_P, rtol=RTOL)
    fig, ax = plt.subplots(figsize=(7, 5.2))
    pmap.plot(ax=ax)

    header = "a/b \\ e " + " ".join(f"{e:6.3f}" for e in eccentricities)
    rows = [f"{q:7.3f} " + " ".join(f"{f:6.2f}" for f in row)
            for q, row in zip(elongations, pmap.chaotic_fraction)]
    print("[parameter_map] chaotic fraction (rows a/b, columns e):")
    print("\n".join([header] + rows))
    overlap = np.asarray(analytic.overlap_elongation(eccentricities))
    print("[parameter_map] analytic overlap a/b(ω0^RO): "
          + ", ".join(f"e={e:.3f}: {q:.3f}" for e, q in zip(eccentricities, overlap)))
    starts = pmap.megno.shape[-1]
    numbers = {"starts per grid point": starts, "orbits": orbits,
               "members": int(pmap.megno.size), "seconds": pmap.seconds,
               "member-orbits/s": pmap.member_orbits_per_second,
               "mean chaotic fraction": float(np.nanmean(pmap.chaotic_fraction))}
    save(args, "parameter_map", fig,
         {"elongations": elongations, "eccentricities": eccentricities,
          "chaotic_fraction": pmap.chaotic_fraction, "megno": pmap.megno,
          "labels": pmap.classification.astype("U16"), "status": pmap.status,
          "theta_p": pmap.theta_p, "thetadot_p": pmap.thetadot_p,
          "overlap_elongation": overlap},
         {"system": SYSTEM, "rtol": RTOL, "orbits": orbits, "starts": starts},
         numbers, started)


if __name__ == "__main__":
    main()
