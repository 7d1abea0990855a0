"""What perturbations cost: member-orbits per second with and without tides, YORP and BYORP, the Sun's tide and a passing planet.

1991 VH (a/b = 1.5), the members of the throughput benchmark (``bench_throughput.starts``),
rtol 1e-12, both models and both methods. The first table's perturbed runs carry a
constant-time-lag tide on each body, YORP on the secondary and BYORP (strengths 1e4–1e6),
i.e. every perturbation term is evaluated at every stage; YORP and BYORP take the Sun's
distance of the moment (``distance="orbit"``, the default: an elliptic Kepler solve per
stage). The second table's first row is the same set with ``distance="mean"`` (the
paper's mean-distance form, no Kepler solve). The second table (``THIRD``) times
the third bodies, each alone: ``SolarTide`` (1991 VH's own heliocentric a, e; the Sun in the
mutual orbit's plane, which the planar model takes, and 30° out of it, 3-D only) and
``Flyby`` (Earth, v∞ 8 km/s, one flyby per member, q log-uniform in 30–60 Earth radii, a
distant pass that neither splits nor upsets a member so that the step counts stay
comparable, closest approach at mid-run; in the plane, node and periapsis random, and
isotropic, 3-D only). Every stage then solves the Sun's elliptic or the planet's hyperbolic
Kepler equation (Newton's method) besides the tide and the torques. The tides despin the fastest members within the run, so
the perturbed runs take a few per cent fewer steps; the last ratio column is therefore per
accepted step (the cost of the terms themselves). Rates are per process CPU-second (all threads; ``--wall`` for wall seconds, the
figures before 2026-12-03), which other load on a shared machine disturbs far less than
wall time; on a quiet machine the wall rate is the CPU rate times the cores. Each pair (plain, perturbed) is
timed interleaved, ``--repeat`` rounds, after
a warm-up launch that compiles both variants (the compile, measured separately as the first
call's extra time, is reported but kept out of the rates).

    python experiments/bench_perturbations.py              # N = 1024, 16 orbits
    python experiments/bench_perturbations.py --quick      # N = 16, 2 orbits, planar CK (CI)
    python experiments/bench_perturbations.py --third-only # the second table alone
"""

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _common  # noqa: E402

RTOL = 1e-12


def perturbations(distance="orbit"):
    import ti_spinorbit as tso
    return [tso.Tides(body="secondary", k2=1e-5, time_lag=600.0, strength=1e6),
            tso.Tides(body="primary", Q=100.0, strength=1e4),
            tso.YORP(strength=1e4, distance=distance),
            tso.BYORP(coefficient=-1e-3, strength=1e4, distance=distance)]


def third_bodies(n, orbits, system):
    """{label: (perturbations, planar allowed)} of the second table (module docstring)."""
    import ti_spinorbit as tso

    rng = np.random.default_rng(25)
    q = np.exp(rng.uniform(np.log(30.0), np.log(60.0), n)) * 6371.0
    node, peri = rng.uniform(0, 360, n), rng.uniform(0, 360, n)
    inc = np.degrees(np.arccos(rng.uniform(-1.0, 1.0, n)))
    t_q = 0.5 * orbits * system.orbital_period / 3600.0
    return {
        "tides + YORP + BYORP, mean distance": (perturbations("mean"), True),
        "SolarTide, in plane": ([tso.SolarTide(inclination_deg=0.0)], True),
        "SolarTide, 30 deg": ([tso.SolarTide(inclination_deg=30.0)], False),
        "Flyby, in plane": ([tso.Flyby("Earth", v_inf_km_s=8.0, q_km=list(q), inclination_deg=0.0,
                                       node_deg=list(node), periapsis_deg=list(peri),
                                       t_closest_h=t_q)], True),
        "Flyby, isotropic": ([tso.Flyby("Earth", v_inf_km_s=8.0, q_km=list(q),
                                        inclination_deg=list(inc), node_deg=list(node),
                                        periapsis_deg=list(peri), t_closest_h=t_q)], False),
    }


def members(n, orbits=16):
    import ti_spinorbit as tso
    from bench_throughput import starts
    from ti_spinorbit.model.perturbations import perturbation_rows
    from ti_spinorbit.engine.members import Members

    system = tso.catalog.system("1991 VH", elongation=1.5)
    tp, td = starts(n)
    start = Members.from_starts(system, tp, td)
    systems, par, y0 = start.systems, start.par, start.y0
    third = {label: (perturbation_rows(systems, p), planar)
             for label, (p, planar) in third_bodies(n, orbits, system).items()}
    return par, y0, perturbation_rows(systems, perturbations()), third


def timed_run(par, y0, rows, model, method, orbits, cpu=False):
    """(member-orbits per second, accepted steps per orbit, wall s incl. compile); with
    ``cpu`` the rate is per process CPU-second (all threads) instead of per wall second."""
    from ti_spinorbit.engine.ensemble import Ensemble

    wall = time.perf_counter()
    ens = Ensemble(par, y0, rtol=RTOL, model=model, method=method, perturbation_rows=rows)
    c0 = time.process_time()
    out = ens.run(2.0 * np.pi * orbits)
    c1 = time.process_time()
    wall = time.perf_counter() - wall
    n = len(par)
    return n * orbits / ((c1 - c0) if cpu else out.seconds), \
        float(np.mean(out.counters[:, 0])) / orbits, wall


def third_table(par, y0, third, variants, orbits, repeat, cpu):
    """Rows of the second table: per (model, method) the plain rate and each third body's,
    timed interleaved (plain first in every round), medians."""
    out = []
    for model, method in variants:
        sets = {label: rows for label, (rows, planar) in third.items()
                if planar or model == "3d"}
        timed_run(par[:1], y0[:1], None, model, method, 0.25)                  # compile
        for rows in sets.values():
            timed_run(par[:1], y0[:1], rows[:1], model, method, 0.25)
        rates = {label: [] for label in ("plain", *sets)}
        steps = {}
        for _ in range(repeat):
            for label, rows in (("plain", None), *sets.items()):
                rate, spo, _ = timed_run(par, y0, rows, model, method, orbits, cpu=cpu)
                rates[label].append(rate)
                steps[label] = spo
        plain = float(np.median(rates["plain"]))
        for label in sets:
            rate = float(np.median(rates[label]))
            out.append(dict(model=model, method=method, set=label, plain=plain, perturbed=rate,
                            ratio=rate / plain, steps_plain=steps["plain"],
                            steps_perturbed=steps[label],
                            step_ratio=rate / plain * steps[label] / steps["plain"]))
    return out


def main():
    def extra(p):
        p.add_argument("--repeat", type=int, default=3, help="interleaved rounds (median taken)")
        p.add_argument("--third-only", action="store_true",
                       help="only the second table (SolarTide and Flyby)")
        p.add_argument("--wall", action="store_true",
                       help="rates per wall second (default: per process CPU-second)")

    args, started = _common.parse(__doc__.splitlines()[0], extra)
    n, orbits = (16, 2) if args.quick else (1024, 16)
    repeat = 1 if args.quick else max(1, args.repeat)
    par, y0, rows, third = members(n, orbits)
    table = []
    variants = [("planar", "cash-karp")] if args.quick else \
        [(m, k) for m in ("planar", "3d") for k in ("cash-karp", "dop853")]
    for model, method in ([] if args.third_only else variants):
        first = {}
        for label, r in (("plain", None), ("perturbed", rows)):   # compile both
            first[label] = timed_run(par[:1], y0[:1], None if r is None else r[:1],
                                     model, method, 0.25)[2]
        rates = {"plain": [], "perturbed": []}
        steps = {}
        for _ in range(repeat):
            for label, r in (("plain", None), ("perturbed", rows)):
                rate, spo, _ = timed_run(par, y0, r, model, method, orbits, cpu=not args.wall)
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
    unit = "mo/s" if args.wall else "mo/CPU-s"
    print("rates in member-orbits per " + ("wall second" if args.wall else
          "process CPU-second (all threads: robust to other load on a shared machine; times the "
          "cores, it is the wall rate of a quiet machine)"))
    print(f"| model | method | plain {unit} | perturbed {unit} | perturbed/plain | steps/orbit "
          "plain, perturbed | first call s plain, perturbed | time per step plain/perturbed |")
    print("|---|---|---|---|---|---|---|---|")
    for r in table:
        r["step_ratio"] = r["ratio"] * r["steps_perturbed"] / r["steps_plain"]
        print(f"| {r['model']} | {r['method']} | {r['plain']:,.0f} | {r['perturbed']:,.0f} | "
              f"{r['ratio']:.2f} | {r['steps_plain']:.0f}, {r['steps_perturbed']:.0f} | "
              f"{r['first_call_plain_s']:.1f}, {r['first_call_perturbed_s']:.1f} | "
              f"{r['step_ratio']:.2f} |")

    third_rows = third_table(par, y0, third, variants, orbits, repeat, not args.wall)
    print()
    print(f"| model | method | perturbation | plain {unit} | perturbed {unit} | perturbed/plain | "
          "steps/orbit plain, perturbed | time per step plain/perturbed |")
    print("|---|---|---|---|---|---|---|---|")
    for r in third_rows:
        print(f"| {r['model']} | {r['method']} | {r['set']} | {r['plain']:,.0f} | "
              f"{r['perturbed']:,.0f} | {r['ratio']:.2f} | {r['steps_plain']:.0f}, "
              f"{r['steps_perturbed']:.0f} | {r['step_ratio']:.2f} |")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.4, 3.8))
    bars = [(f"{r['model']}\n{r['method']}", r["plain"], r["perturbed"], "tides + YORP + BYORP")
            for r in table]
    bars += [(f"{r['model']}\n{r['method']}\n{r['set']}", r["plain"], r["perturbed"], r["set"])
             for r in third_rows]
    x = np.arange(len(bars))
    ax.bar(x - 0.2, [b[1] for b in bars], 0.4, label="plain", color="0.6")
    ax.bar(x + 0.2, [b[2] for b in bars], 0.4, label="perturbed", color="C0")
    ax.set_xticks(x, [b[0] for b in bars], fontsize=6)
    ax.set_yscale("log")
    ax.set_ylabel("member-orbits per " + ("second" if args.wall else "CPU-second"))
    ax.set_title(f"Cost of perturbations: 1991 VH, N = {n}, rtol $10^{{-12}}$")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    everything = table + third_rows
    arrays = {k: np.array([r[k] for r in everything]) for k in
              ("plain", "perturbed", "ratio", "steps_plain", "steps_perturbed")}
    numbers = {f"{r['model']}/{r['method']} perturbed/plain": r["ratio"] for r in table}
    numbers.update({f"{r['model']}/{r['method']} {r['set']}/plain": r["ratio"] for r in third_rows})
    _common.save(args, "bench_perturbations", fig, arrays,
                 {"members": n, "orbits": orbits, "rtol": RTOL, "repeat": repeat,
                  "rate": "per wall second" if args.wall else "per process CPU-second",
                  "rows": [f"{r['model']}/{r['method']}" for r in table] +
                          [f"{r['model']}/{r['method']}/{r['set']}" for r in third_rows]},
                 numbers, started)


if __name__ == "__main__":
    main()
