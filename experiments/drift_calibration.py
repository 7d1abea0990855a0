"""Calibration of the default accuracy limit (ti_spinorbit.accuracy).

Integrates 48 starts spread over the (θ_p, θ̇_p/n) plane of a catalogued system at
tolerances 1e-2 ... 1e-14, in the planar and the 3-D model, and prints the largest relative
energy and angular-momentum drift per member divided by rtol × orbits. A healthy Cash-Karp
run drifts linearly in both, so that ratio is a constant (about 13 for the energy of 1991 VH);
the default limit, 1000 × rtol × orbits capped at 1e-4, sits far above it.

    python experiments/drift_calibration.py                  # 1991 VH, 100 orbits
    python experiments/drift_calibration.py --system "2004 DC" --orbits 300

The table is also written to <out>/drift_calibration.json.
"""

import argparse
import json
import os
import time

import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--system", default="1991 VH")
    p.add_argument("--orbits", type=float, default=100.0)
    p.add_argument("--quick", action="store_true",
                   help="10 orbits, rtol 1e-6 ... 1e-12, planar model only (CI)")
    p.add_argument("--out", default="out", help="output folder (default: out/)")
    args = p.parse_args()
    if args.quick:
        args.orbits = min(args.orbits, 10.0)
    os.makedirs(args.out, exist_ok=True)
    rows = []
    import ti_spinorbit as tso
    from ti_spinorbit import accuracy

    system = tso.catalog.system(args.system)
    tp, td = (x.ravel() for x in np.meshgrid(np.linspace(0, 180, 6), np.linspace(0.3, 3, 8),
                                             indexing="ij"))
    tolerances = (1e-6, 1e-8, 1e-10, 1e-12) if args.quick else \
        (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14)
    print(f"{system.name}, {len(tp)} starts, {args.orbits:g} orbits; drift / (rtol x orbits): "
          f"largest over the finished members; default limit factor {accuracy.DRIFT_PER_ORBIT:g}, "
          f"cap {accuracy.DRIFT_CAP:g}")
    print(f"{'model':6s} {'rtol':>7s} {'finished':>8s} {'E drift':>9s} {'E ratio':>8s} "
          f"{'L drift':>9s} {'L ratio':>8s} {'limit':>9s} {'flagged':>7s} {'s':>6s}")
    for model in (("planar",) if args.quick else ("planar", "3d")):
        for rtol in tolerances:
            t0 = time.perf_counter()
            s = tso.surface_of_section(system, tp, td, orbits=args.orbits, rtol=rtol, model=model)
            finished = np.isin(s.status_names, ("done", "inaccurate"))
            e = np.max(s.energy_drift[finished]) if finished.any() else np.nan
            l = np.max(s.angmom_drift[finished]) if finished.any() else np.nan
            scale = rtol * args.orbits
            print(f"{model:6s} {rtol:7.0e} {finished.sum():4d}/{len(tp):<3d} "
                  f"{e:9.2e} {e / scale:8.2f} {l:9.2e} {l / scale:8.2f} "
                  f"{s.max_drift:9.2e} {s.n_inaccurate:7d} {time.perf_counter() - t0:6.1f}",
                  flush=True)
            rows.append({"model": model, "rtol": rtol, "finished": int(finished.sum()),
                         "energy_drift": float(e), "angmom_drift": float(l),
                         "energy_per_rtol_orbit": float(e / scale),
                         "angmom_per_rtol_orbit": float(l / scale),
                         "limit": s.max_drift, "inaccurate": s.n_inaccurate})
    path = os.path.join(args.out, "drift_calibration.json")
    with open(path, "w") as f:
        json.dump({"system": system.name, "starts": int(len(tp)), "orbits": args.orbits,
                   "rows": rows}, f, indent=1)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
