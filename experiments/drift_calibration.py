"""Calibration of the default accuracy limit (ti_spinorbit.engine.accuracy).

Integrates 48 starts spread over the (θ_p, θ̇_p/n) plane of a catalogued system at
tolerances 1e-2 ... 1e-14, in the planar and the 3-D model, and prints the largest relative
energy and angular-momentum drift per member divided by rtol × orbits. A healthy Cash-Karp
run drifts linearly in both, so that ratio is a constant (4 to 18 for the energy of 1991 VH
and 2004 DC); the default limit, 1000 × rtol × orbits capped at 1e-4, sits far above it.

    python experiments/drift_calibration.py                  # 1991 VH, 100 orbits
    python experiments/drift_calibration.py --system "2004 DC" --orbits 300
    python experiments/drift_calibration.py --quick          # 10 orbits, planar, 4 tolerances

Writes <out>/drift_calibration.png (ratio vs rtol, with the limit's factor) and .npz.
"""

import ti_spinorbit
import time

import numpy as np

import _common


def main():
    def extra(p):
        p.add_argument("--system", default="1991 VH", help="catalogued system (default 1991 VH)")
        p.add_argument("--orbits", type=float, default=100.0, help="orbits per run (default 100)")

    args, started = _common.parse(__doc__.splitlines()[0], extra)
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.engine import accuracy

    orbits = min(args.orbits, 10.0) if args.quick else args.orbits
    models = ("planar",) if args.quick else ("planar", "3d")
    tolerances = np.array((1e-6, 1e-8, 1e-10, 1e-12) if args.quick else
                          (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14))
    system = tso.catalog.system(args.system)
    tp, td = (x.ravel() for x in np.meshgrid(np.linspace(0, 180, 6), np.linspace(0.3, 3, 8),
                                             indexing="ij"))
    print(f"{system.name}, {len(tp)} starts, {orbits:g} orbits; largest drift over the finished "
          f"members / (rtol x orbits); default limit {accuracy.DRIFT_PER_ORBIT:g} x rtol x orbits,"
          f" cap {accuracy.DRIFT_CAP:g}")
    print(f"{'model':6s} {'rtol':>7s} {'finished':>8s} {'E drift':>9s} {'E ratio':>8s} "
          f"{'L drift':>9s} {'L ratio':>8s} {'limit':>9s} {'flagged':>7s} {'s':>6s}")
    shape = (len(models), len(tolerances))
    energy, angmom, limit = np.full(shape, np.nan), np.full(shape, np.nan), np.zeros(shape)
    finished, flagged = np.zeros(shape, int), np.zeros(shape, int)
    for i, model in enumerate(models):
        for j, rtol in enumerate(tolerances):
            t0 = time.perf_counter()
            s = tso.surface_of_section(system, tp, td, orbits=orbits, rtol=rtol,
                                       integrator=ti_spinorbit.Integrator(model=model))
            ok = np.isin(s.status_names, ("done", "inaccurate"))
            finished[i, j], flagged[i, j], limit[i, j] = ok.sum(), s.n_inaccurate, s.max_drift
            if ok.any():
                energy[i, j], angmom[i, j] = s.energy_drift[ok].max(), s.angmom_drift[ok].max()
            scale = rtol * orbits
            print(f"{model:6s} {rtol:7.0e} {ok.sum():4d}/{len(tp):<3d} {energy[i, j]:9.2e} "
                  f"{energy[i, j] / scale:8.2f} {angmom[i, j]:9.2e} {angmom[i, j] / scale:8.2f} "
                  f"{s.max_drift:9.2e} {s.n_inaccurate:7d} {time.perf_counter() - t0:6.1f}",
                  flush=True)
    ratio_e = energy / (tolerances * orbits)
    ratio_l = angmom / (tolerances * orbits)

    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=150)
    for i, model in enumerate(models):
        ax.loglog(tolerances, ratio_e[i], "o-", label=f"energy, {model}")
        ax.loglog(tolerances, ratio_l[i], "s--", label=f"angular momentum, {model}")
    ax.axhline(accuracy.DRIFT_PER_ORBIT, color="k", lw=1, label="default limit factor")
    ax.set_xlabel("rtol")
    ax.set_ylabel("largest drift / (rtol × orbits)")
    ax.set_title(f"{system.name}: {len(tp)} starts × {orbits:g} orbits", fontsize=9)
    ax.legend(fontsize=7)
    healthy = np.isfinite(ratio_e) & (tolerances >= 1e-14) & (tolerances <= 1e-4)
    numbers = {"energy ratio min": float(np.nanmin(ratio_e[healthy])),
               "energy ratio max": float(np.nanmax(ratio_e[healthy])),
               "angular-momentum ratio max": float(np.nanmax(ratio_l[healthy])),
               "limit factor": accuracy.DRIFT_PER_ORBIT,
               "flagged at rtol <= 1e-8": int(flagged[:, tolerances <= 1e-8].sum())}
    _common.save(args, "drift_calibration", fig,
                 {"rtol": tolerances, "energy_drift": energy, "angmom_drift": angmom,
                  "limit": limit, "finished": finished, "inaccurate": flagged},
                 {"system": system.name, "starts": int(len(tp)), "orbits": orbits,
                  "models": list(models)}, numbers, started)


if __name__ == "__main__":
    main()
