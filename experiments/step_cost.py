"""Calibration of the step estimate behind the step budget and the long-run warning
(ti_spinorbit.engine.cost).

Integrates two starts (θ̇_p/n = 0.5 and 1.2) of every catalogued system for a few orbits
with each Runge-Kutta pair at three tolerances, and prints the measured steps per orbit
(accepted + rejected), the estimate ``cost.steps_per_orbit`` and their ratio. The estimate
should bound the measurement from above by a small factor everywhere (the budget allows 100
times it); the printed slope of log(steps) against log(rtol) should match the method's error
exponent (1/5, 1/8, 1/9).

    python experiments/step_cost.py            # 11 systems, 3 orbits, rtol 1e-8, 1e-12, 1e-15
    python experiments/step_cost.py --quick    # 3 systems, 1 orbit, two tolerances

Writes <out>/step_cost.png (measured against estimated steps per orbit) and .npz.
"""

import numpy as np

import _common


def main():
    args, started = _common.parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.engine import cost
    from ti_spinorbit.engine.members import Members

    names = ["1991 VH", "2004 DC", "test"] if args.quick else tso.catalog.names()
    tolerances = (1e-8, 1e-12) if args.quick else (1e-8, 1e-12, 1e-15)
    orbits = 1.0 if args.quick else 3.0
    starts = ([30.0, 60.0], [0.5, 1.2])
    rows = []          # method index, rtol, measured, estimated
    methods = list(cost.METHOD_COST)
    for name in names:
        system = tso.catalog.system(name)
        table = Members.from_starts(system, *starts, 50.0)
        par, y0 = table.par, table.y0
        for k, method in enumerate(methods):
            for rtol in tolerances:
                r = tso.surface_of_section(system, *starts, orbits=orbits, rtol=rtol,
                                           method=method)
                measured = (r.accepted + r.rejected) / orbits
                estimate = cost.steps_per_orbit(par, y0, rtol, method)
                rows += [(k, rtol, m, e) for m, e in zip(measured, estimate)]
                print(f"{name:>12} {method:>9} rtol {rtol:.0e}: measured "
                      f"{np.array2string(measured, precision=0)}, estimated "
                      f"{np.array2string(estimate, precision=0)}, ratio "
                      f"{np.array2string(estimate / measured, precision=2)}")
    data = np.array(rows)
    ratio = data[:, 3] / data[:, 2]
    numbers = {"smallest_ratio": float(ratio.min()), "largest_ratio": float(ratio.max())}
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for k, method in enumerate(methods):
        sel = data[:, 0] == k
        ax.loglog(data[sel, 2], data[sel, 3], "o", ms=4, label=method)
        # the rtol slope of the measured steps, per method (all systems pooled)
        slope = np.polyfit(np.log(data[sel, 1]), np.log(data[sel, 2]), 1)[0]
        numbers[f"rtol_slope_{method}"] = float(slope)
        numbers[f"error_exponent_{method}"] = float(cost.METHOD_COST[method][1])
    lim = np.array([data[:, 2:].min() / 2, data[:, 2:].max() * 2])
    ax.loglog(lim, lim, "k-", lw=0.8, label="estimate = measured")
    ax.loglog(lim, cost.BUDGET_FACTOR * lim, "k--", lw=0.8, label="the budget's factor")
    ax.set_xlabel("measured steps per orbit")
    ax.set_ylabel("estimated steps per orbit")
    ax.set_title("Step estimate of the step budget")
    ax.legend(fontsize=8)
    _common.save(args, "step_cost", fig, {"rows": data},
                 {"systems": list(names), "tolerances": list(tolerances), "orbits": orbits,
                  "starts": [list(s) for s in starts]}, numbers, started)


if __name__ == "__main__":
    main()
