"""What tides, YORP and BYORP cost: member-orbits per second with and without them.

1991 VH (a/b = 1.5), the members of the throughput benchmark (``bench_throughput.starts``),
rtol 1e-12, both models and both methods. The perturbed runs carry a constant-time-lag tide
on each body, YORP on the secondary and BYORP (strengths 1e4–1e6), i.e. every perturbation
term is evaluated at every stage. The tides despin the fastest members within the run, so
the perturbed runs take a few per cent fewer steps; the last ratio column is therefore per
accepted step (the cost of the terms themselves). Each pair (plain, perturbed) is timed interleaved, ``--repeat`` rounds, after
a warm-up launch that compiles both variants (the compile, measured separately as the first
call's extra time, is reported but kept out of the rates).

    python experiments/bench_perturbations.py              # N = 1024, 16 orbits
    python experiments/bench_perturbations.py --quick      # N = 16, 2 orbits, planar CK (CI)
"""

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common  # noqa: E402

RTOL = 1e-12


def perturbations():
    import ti_spinorbit as tso
    return [tso.Tides(body="secondary", k2=1e-5, time_lag=600.0, strength=1e6),
            tso.Tides(body="primary", Q=100.0, strength=1e4),
            tso.YORP(strength=1e4), tso.BYORP(coefficient=-1e-3, strength=1e4)]


def members(n):
    import ti_spinorbit as tso
    from bench_throughput import starts
    from ti_spinorbit.model.perturbations import perturbation_rows
    from ti_spinorbit.engine.members import Members

    system = tso.catalog.system("1991 VH", elongation=1.5)
    tp, td = starts(n)
    start = Members.from_starts(system, tp, td)
    systems, par, y0 = start.systems, start.par, start.y0
    return par, y0, perturbation_rows(systems, perturbations())


def timed_run(par, y0, rows, model, method, orbits):
    """(member-orbits per second, accepted steps per orbit, wall s incl. compile)."""
    from ti_spinorbit.engine.ensemble import Ensemble

    wall = time.perf_counter()
    ens = Ensemble(par, y0, rtol=RTOL, model=model, method=method, perturbation_rows=rows)
    out = ens.run(2.0 * np.pi * orbits)
    wall = time.perf_counter() - wall
    n = len(par)
    return n * orbits / out.seconds, float(np.mean(out.counters[:, 0])) / orbits, wall


def main():
    args, started = _common.parse(__doc__.splitlines()[0], lambda p: p.add_argument(
        "--repeat", type=int, default=3, help="interleaved rounds (median taken)"))
    n, orbits = (16, 2) if args.quick else (1024, 16)
    repeat = 1 if args.quick else max(1, args.repeat)
    par, y0, rows = members(n)
    table = []
    variants = [("planar", "cash-karp")] if args.quick else \
        [(m, k) for m in ("planar", "3d") for k in ("cash-karp", "dop853")]
    for model, method in variants:
        first = {}
        for label, r in (("plain", None), ("perturbed", rows)):   # compile both
            first[label] = timed_run(par[:1], y0[:1], None if r is None else r[:1],
                                     model, method, 0.25)[2]
        rates = {"plain": [], "perturbed": []}
        steps = {}
        for _ in range(repeat):
            for label, r in (("plain", None), ("perturbed", rows)):
                rate, spo, _ = timed_run(par, y0, r, model, method, orbits)
                rates[label].append(rate)
                steps[label] = spo
        plain, pert = np.median(rates["plain"]), np.median(rates["perturbed"])
        table.append(dict(model=model, method=method, plain=plain, perturbed=pert,
                          ratio=pert / plain, steps_plain=steps["plain"],
                          steps_perturbed=steps["perturbed"],
                          first_call_plain_s=first["plain"],
                          first_call_perturbed_s=first["perturbed"]))
    print(f"N = {n}, {orbits} orbits, rtol {RTOL:g}, {repeat} interleaved rounds (median), "
          f"{os.cpu_count()} CPUs")
    print("| model | method | plain mo/s | perturbed mo/s | perturbed/plain | steps/orbit "
          "plain, perturbed | first call s plain, perturbed | time per step plain/perturbed |")
    print("|---|---|---|---|---|---|---|---|")
    for r in table:
        r["step_ratio"] = r["ratio"] * r["steps_perturbed"] / r["steps_plain"]
        print(f"| {r['model']} | {r['method']} | {r['plain']:,.0f} | {r['perturbed']:,.0f} | "
              f"{r['ratio']:.2f} | {r['steps_plain']:.0f}, {r['steps_perturbed']:.0f} | "
              f"{r['first_call_plain_s']:.1f}, {r['first_call_perturbed_s']:.1f} | "
              f"{r['step_ratio']:.2f} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    x = np.arange(len(table))
    ax.bar(x - 0.2, [r["plain"] for r in table], 0.4, label="plain")
    ax.bar(x + 0.2, [r["perturbed"] for r in table], 0.4, label="tides + YORP + BYORP")
    ax.set_xticks(x, [f"{r['model']}\n{r['method']}" for r in table])
    ax.set_ylabel("member-orbits per second")
    ax.set_title(f"Cost of perturbations: 1991 VH, N = {n}, rtol $10^{{-12}}$")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    arrays = {k: np.array([r[k] for r in table]) for k in
              ("plain", "perturbed", "ratio", "steps_plain", "steps_perturbed")}
    _common.save(args, "bench_perturbations", fig, arrays,
                 {"members": n, "orbits": orbits, "rtol": RTOL, "repeat": repeat,
                  "rows": [f"{r['model']}/{r['method']}" for r in table]},
                 {f"{r['model']}/{r['method']} perturbed/plain": r["ratio"] for r in table},
                 started)


if __name__ == "__main__":
    main()
