"""Stability of the paper's planar states out of the plane (beyond the paper).

Naidu & Margot (2015) integrate planar starts only, and their chaos indicators (like this
package's default) perturb planar directions only: an island that is regular in the plane
may still be unstable to a tilt of the secondary's pole. For 1991 VH, 2003 YT1 and 2004 DC
(catalogue systems) this script maps, over the grid (θ_p, θ̇_p/n):

* the planar-restricted MEGNO ⟨Y⟩ (``indicator_space="planar"``, planar start);
* the full MEGNO (``indicator_space="full"``: deviations of the whole state, attitudes by a
  small rotation; docs/physics.md §10.4) and, from the same run,
* the largest tilt of the secondary's pole from the orbit normal reached from a start
  tilted by ``TILT0`` in roll and in pitch (``chaos_map(..., tilt=...)``, 3-D model).

Printed per system: the planar-regular area (⟨Y⟩ < 4 in the plane, usable members) and the
share of it that turns chaotic in full space (⟨Y⟩ ≥ 4), that tilts past 10°, or either.
``--quick``: 1991 VH alone, 8 × 8 grid, 20 orbits.
"""

import numpy as np

import _common

SYSTEMS = ("1991 VH", "2003 YT1", "2004 DC")
TILT0 = 0.01                 # degrees, roll and pitch of every tilted start
MEGNO_CHAOTIC = 4.0
TILT_LIMIT = 10.0            # degrees: "left the plane"
THETADOT_RANGE = (0.4, 2.6)  # units of n: the 1:1, 3:2 and 2:1 bands
RTOL = 1e-10
#: Bands of θ̇_p/n for the printed breakdown: the 1:1 island and below, between, the 3:2
#: band, the 2:1 band.
BANDS = (0.0, 1.0, 1.45, 2.2, np.inf)


def grid(n_theta, n_thetadot):
    """Cell centres in θ_p (deg, [0, 180)) and θ̇_p/n."""
    theta = (np.arange(n_theta) + 0.5) * 180.0 / n_theta
    return theta, np.linspace(*THETADOT_RANGE, n_thetadot)


def shares(planar, full):
    """Planar-regular area and the shares of it that turn chaotic in full space, tilt past
    TILT_LIMIT, or either (members usable in both runs only)."""
    from ti_spinorbit.engine import accuracy

    ok = accuracy.usable(planar.status) & accuracy.usable(full.status)
    regular = ok & (planar.megno < MEGNO_CHAOTIC)
    n = int(regular.sum())
    chaotic = regular & (full.megno >= MEGNO_CHAOTIC)
    tilted = regular & (full.max_tilt > TILT_LIMIT)
    frac = (lambda m: float(m.sum()) / n if n else float("nan"))
    sea = ok & (planar.megno >= MEGNO_CHAOTIC)
    spin = np.broadcast_to(planar.thetadot_p[None, :], regular.shape)
    bands = [(int((regular & (spin >= lo) & (spin < hi)).sum()),
              int((tilted & (spin >= lo) & (spin < hi)).sum())) for lo, hi in zip(BANDS, BANDS[1:])]
    return {"planar_regular_area": n / max(int(ok.sum()), 1), "regular_cells": n,
            "full_chaotic_share": frac(chaotic), "tilted_share": frac(tilted),
            "either_share": frac(chaotic | tilted), "unusable_cells": int((~ok).sum()),
            "band_regular_cells": [b[0] for b in bands], "band_tilted_cells": [b[1] for b in bands],
            "sea_tilted_share": float((sea & (full.max_tilt > TILT_LIMIT)).sum() / max(sea.sum(), 1))}


def main():
    def extra(p):
        p.add_argument("--grid", type=int, nargs=2, default=None, metavar=("NTHETA", "NTHETADOT"),
                       help="grid (default 32 32; quick 8 8)")
        p.add_argument("--orbits", type=float, default=None,
                       help="orbits per member (default 150; quick 20)")

    args, started = _common.parse(__doc__.splitlines()[0], extra=extra)
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    names = SYSTEMS[:1] if args.quick else SYSTEMS
    nt, nd = args.grid or ((8, 8) if args.quick else (32, 32))
    orbits = args.orbits or (20.0 if args.quick else 150.0)
    theta, thetadot = grid(nt, nd)
    fig, axes = plt.subplots(len(names), 3, figsize=(13.5, 3.6 * len(names)), squeeze=False)
    arrays, numbers = {"theta_p": theta, "thetadot_p": thetadot}, {}
    common = dict(orbits=orbits, rtol=RTOL, megno_chaotic=MEGNO_CHAOTIC, fraction_orbits=(),
                  run=tso.Run(progress=False))
    for row, name in zip(axes, names):
        system = tso.catalog.system(name)
        planar = tso.chaos_map(system, theta, thetadot, indicator_space="planar", **common)
        full = tso.chaos_map(system, theta, thetadot, indicator_space="full",
                             tilt=(TILT0, TILT0), **common)
        key = name.replace(" ", "")
        got = shares(planar, full)
        numbers.update({f"{key}_{k}": v for k, v in got.items()})
        numbers[f"{key}_seconds"] = planar.seconds + full.seconds
        for k, m in (("planar", planar), ("full", full)):
            arrays[f"{key}_{k}_megno"] = m.megno
            arrays[f"{key}_{k}_status"] = m.status
        arrays[f"{key}_max_tilt"] = full.max_tilt
        for ax, m, q, what in ((row[0], planar, "megno", "MEGNO, planar-restricted"),
                               (row[1], full, "megno", "MEGNO, full space"),
                               (row[2], full, "max_tilt", f"largest tilt from {TILT0:g} deg")):
            m.plot(ax=ax, quantity=q, title=f"{name}: {what}")
        print(f"{name}: planar-regular {got['regular_cells']} of {nt * nd} cells; of them "
              f"{got['full_chaotic_share']:.2f} chaotic in full space, {got['tilted_share']:.2f} "
              f"tilt past {TILT_LIMIT:g} deg, {got['either_share']:.2f} either "
              f"({planar.seconds + full.seconds:.1f} s)", flush=True)
        print(f"  by band of spin/n {', '.join(f'{lo:g}-{hi:g}' for lo, hi in zip(BANDS, BANDS[1:]))}: "
              f"planar-regular cells {got['band_regular_cells']}, of them tilted past "
              f"{TILT_LIMIT:g} deg {got['band_tilted_cells']}; chaotic-sea cells tilted past "
              f"{TILT_LIMIT:g} deg: {got['sea_tilted_share']:.2f}", flush=True)
    fig.suptitle(f"Planar states out of the plane: {nt} x {nd} starts, {orbits:g} orbits, "
                 f"rtol {RTOL:g}, start tilt {TILT0:g} deg (roll and pitch)", fontsize=10)
    _common.save(args, "planar_stability", fig, arrays,
                 {"systems": list(names), "grid": [nt, nd], "orbits": orbits, "rtol": RTOL,
                  "tilt0_deg": TILT0, "megno_chaotic": MEGNO_CHAOTIC,
                  "tilt_limit_deg": TILT_LIMIT, "thetadot_range": list(THETADOT_RANGE)},
                 numbers, started)


if __name__ == "__main__":
    main()
