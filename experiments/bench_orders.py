"""What the order of the mutual potential costs: member-orbits per second, cold compile and
memory per member at orders 2, 4, 6, 8, 12 (and degree caps), both models.

The system is an ellipsoid pair: 1991 VH's orbit (a = 3300 m, e = 0.05) with a triaxial
primary (660 × 600 × 545 m, 1581 kg/m³, about 1991 VH's primary volume) and 1991 VH's
a/b = 1.5 secondary as an ellipsoid (294 × 196 × 190 m, 2618 kg/m³); the members are the
throughput benchmark's (``bench_throughput.starts``: θ_p, θ̇_p/n on an R2 sequence). The
order-N integral rows come from the ellipsoids' closed form (``system.integrals``), so the
script runs whatever order the bodies store. Integration through ``Ensemble`` (Cash-Karp,
rtol = atol = 1e-12, escape distance 1000 a); orders up to 4 run the hand-written kernels,
higher ones the table-driven harmonic ones (docs/physics.md §3.8.2). Each point integrates about
``--seconds`` of wall time (a pilot run sizes it; at least 0.05 orbit), after a 1-member
launch that compiles or loads the variant. Sections:

rates
    member-orbits/s per (model, order, degree caps) at ``--members`` (default 1024), the
    ratio to the order-4 rate of the same model, accepted steps per orbit, and the time per
    right-hand side on one core (process CPU seconds / RHS calls: integrator overhead
    included); the targets of the order-N work (3-D: order 6 >= 1/4 and order 8 >= 1/12 of
    the order-4 rate) are printed with MET/MISS.
split
    one core, the Cartesian form's potential alone (``multipole_gravity.mutual_n``, the
    kernels' independent check, no longer what they integrate with; in a loop on 256 states,
    a dependent chain as in bench_throughput's RHS loop), and with each part of it switched
    off in turn through its table header (the secondary-frame derivatives, the rotation of
    the secondary's integrals, the mixed pairs): where that form's time goes. The harmonic
    form against it: ``bench_harmonics.py``.
compile
    cold compile of each order's variant in a fresh process with an empty kernel cache (the
    integrator and the diagnostics kernels, as ``tso.warmup`` counts them), per model.
memory
    bytes per member of the order-N block: the coefficient row and the scratch row
    (``harmonic_tables.HarmonicTables``; the Cartesian form's beside them), beside the ~100
    numbers every member carries anyway.

    python experiments/bench_orders.py                        # everything, ~10 min on 2 cores
    python experiments/bench_orders.py --sections rates --models 3d --orders 4 6 8
    python experiments/bench_orders.py --sections rates --models 3d --orders 4 6 8 --rounds 3
    python experiments/bench_orders.py --quick                # N = 16, 0.2 s per point
    python experiments/bench_orders.py --pair radar --sections rates --orders 4 6 8 12
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

EXPERIMENTS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, EXPERIMENTS)

RTOL = 1e-12
ESCAPE = 1000.0
PRIMARY = (660.0, 600.0, 545.0, 1581.0)        # semi-axes (m), density (kg/m³)
SECONDARY = (294.0, 196.0, 190.0, 2618.0)
A_M, E = 3300.0, 0.05
ORDERS = (2, 4, 6, 8, 12)
#: degree caps measured beside the full ones: a secondary described to degree 4 only
CAPS = {8: (8, 4), 12: (12, 4)}
TARGETS = {6: 1 / 4, 8: 1 / 12}               # 3-D rate / order-4 rate
SECTIONS = ("rates", "split", "compile", "memory")

CHILD_COMPILE = """
import json, sys, time
sys.path.insert(0, {experiments!r})
import bench_orders as B
import ti_spinorbit as tso
from ti_spinorbit.engine import compiling
tso.init()
model, order = sys.argv[1], int(sys.argv[2])
par, y0, rows, degrees = B.members(1, order)
ens = B.ensemble(par, y0, rows, degrees, order, model)
before = compiling._TOTAL[0]
ens.run(2.0 * 3.141592653589793 * 0.01)
print(json.dumps({{"compile_s": compiling._TOTAL[0] - before}}))
""".format(experiments=EXPERIMENTS)


#: The pair benchmarked: "ellipsoid" (the default, above) or "radar" (the catalogue's
#: "Didymos (radar shape)": the radar polyhedron of Didymos, odd integrals and all, with
#: Dimorphos as an ellipsoid; 3-D model only, since the shape has no mirror plane).
PAIR = ["ellipsoid"]


def system():
    import ti_spinorbit as tso
    if PAIR[0] == "radar":
        return tso.catalog.system("Didymos (radar shape)")
    p = tso.Ellipsoid(*PRIMARY[:3], PRIMARY[3], name="triaxial primary")
    s = tso.Ellipsoid(*SECONDARY[:3], SECONDARY[3], name="1991 VH secondary, a/b 1.5")
    return tso.BinarySystem(p, s, A_M, E, name="ellipsoid pair")


def integral_rows(sys_, order, degrees):
    """(1, width) scaled order-N row of the pair from the closed form."""
    from ti_spinorbit.engine import multipole_tables as MT
    from ti_spinorbit.multipole import multi_indices
    from ti_spinorbit.system import integrals as I

    M, a = sys_.total_mass, float(sys_.a)
    parts = []
    for ax, body, d in ((PRIMARY[:3], sys_.primary, degrees[0]),
                        (SECONDARY[:3], sys_.secondary, degrees[1])):
        T = I.ellipsoid_integrals(*(x / a for x in ax), body.mass / M, d)
        parts.append([T[tuple(int(x) for x in e)] for e in multi_indices(d)])
    row = np.concatenate(parts)[None]
    assert row.shape[1] == MT.count(degrees[0]) + MT.count(degrees[1])
    return row


def members(n, order, degrees=None):
    """(par, y0, order-N rows or None, degrees or None) of the first n members."""
    from bench_throughput import starts
    from ti_spinorbit.engine import multipole_tables as MT
    from ti_spinorbit.engine.members import Members

    s = system()
    tp, td = starts(n)
    if PAIR[0] == "radar":          # the member table builds the rows from Body.integral
        table = Members.from_starts(s, tp, td, ESCAPE, order=order, model="3d",
                                    degrees=None if order <= 4 else degrees)
        return table.par, table.y0, table.multipole_rows, table.degrees
    table = Members.from_starts(s, tp, td, ESCAPE)
    if order <= 4:
        return table.par, table.y0, None, None
    degrees = MT.check_degrees(order, degrees)
    return table.par, table.y0, np.repeat(integral_rows(s, order, degrees), n, 0), degrees


def ensemble(par, y0, rows, degrees, order, model):
    from ti_spinorbit.engine.ensemble import Ensemble
    return Ensemble(par, y0, order=order, rtol=RTOL, model=model, multipole_rows=rows,
                    degrees=degrees)


def run(par, y0, rows, degrees, order, model, orbits):
    """(member-orbits/s, accepted steps per orbit, CPU ns per RHS call) of one run."""
    ens = ensemble(par, y0, rows, degrees, order, model)
    cpu = time.process_time()
    out = ens.run(2.0 * np.pi * orbits)
    cpu = time.process_time() - cpu
    n = len(par)
    rhs = float(out.counters[:, 2].sum())
    return (n * orbits / out.seconds, float(out.counters[:, 0].mean()) / orbits,
            cpu / rhs * 1e9)


def rates(models, orders, n, seconds, rounds=1):
    """The rate of every (model, order, caps) point; with ``rounds`` > 1 the points are
    measured round after round (every point once per round) and each figure is the median
    over the rounds, the ratio to order 4 taken within each round first (the machine may be
    shared: a ratio of two runs minutes apart carries the load's changes)."""
    points = [(model, order, caps) for model in models for order in orders
              for caps in [None] + ([CAPS[order]] if order in CAPS else [])]
    setup = {}
    for model, order, caps in points:
        par, y0, mp, degrees = members(n, order, caps)
        run(par[:1], y0[:1], None if mp is None else mp[:1], degrees, order, model, 0.01)
        k = min(n, 256)          # pilot: sizes the timed run (16 members ran ~5x slower per
        rate, _, _ = run(par[:k], y0[:k], None if mp is None else mp[:k], degrees,  # member
                         order, model, 0.02)               # and cut every point short)
        orbits = max(0.05, float(f"{seconds * rate / n:.2g}"))
        setup[(model, order, caps)] = (par, y0, mp, degrees, orbits)
    measured = {p: [] for p in points}
    for rnd in range(rounds):
        for point in points:
            par, y0, mp, degrees, orbits = setup[point]
            measured[point].append(run(par, y0, mp, degrees, point[1], point[0], orbits))
            rate, steps, ns = measured[point][-1]
            print(f"  {'' if rounds == 1 else f'round {rnd + 1}: '}{point[0]:6s} order "
                  f"{point[1]:2d} degrees {str(degrees or (point[1],) * 2):8s} {rate:9.1f} "
                  f"member-orbits/s, {steps:5.0f} steps/orbit, {ns:7.0f} ns per RHS (one "
                  f"core), {orbits:g} orbits", flush=True)
    rows = []
    for point in points:
        model, order, caps = point
        par, y0, mp, degrees, orbits = setup[point]
        four = (model, 4, None)
        ratios = [m[0] / f[0] for m, f in zip(measured[point], measured[four])] \
            if four in measured else None
        rows.append({"model": model, "order": order, "degrees": degrees or (order, order),
                     "members": n, "orbits": orbits, "rounds": rounds,
                     "member_orbits_per_s": float(np.median([m[0] for m in measured[point]])),
                     "steps_per_orbit": float(np.median([m[1] for m in measured[point]])),
                     "cpu_ns_per_rhs": float(np.median([m[2] for m in measured[point]])),
                     "ratio_to_order_4": float(np.median(ratios)) if ratios else None,
                     "ratio_to_order_4_range": (min(ratios), max(ratios)) if ratios else None})
        if rounds > 1:
            r = rows[-1]
            print(f"  median {model:6s} order {order:2d} degrees {str(r['degrees']):8s} "
                  f"{r['member_orbits_per_s']:9.1f} member-orbits/s, {r['cpu_ns_per_rhs']:7.0f} "
                  f"ns per RHS, ratio to order 4 {r['ratio_to_order_4'] or float('nan'):.4f}",
                  flush=True)
    return rows


def split(orders, n=256, reps=200):
    """ns per order-N evaluation on one core, whole and with parts switched off."""
    import taichi as ti
    from _order_n_loop import loop_kernel
    from ti_spinorbit.engine import multipole_tables as MT
    from ti_spinorbit.kernels.multipole_gravity import mutual_n
    from ti_spinorbit.layout import multipole as H

    @ti.func
    def z_rotation(i):
        c, s = ti.cos(0.3 * i), ti.sin(0.3 * i)
        return ti.Matrix([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]], ti.f64)

    loop = loop_kernel(mutual_n, z_rotation)

    s = system()
    R = np.column_stack([0.95 + 0.1 * np.sin(np.arange(n)), 0.2 * np.cos(np.arange(n)),
                         0.05 * np.ones(n)])
    out = []
    for order in orders:
        if order <= 4:
            continue
        for caps in [None] + ([CAPS[order]] if order in CAPS else []):
            degrees = MT.check_degrees(order, caps)
            tab = MT.tables(order, *degrees, False)
            rows = np.repeat(integral_rows(s, order, degrees), n, 0)
            parts = {"whole": {}, "without D at R_B": {H.H_TOP_DB: 0},
                     "without the rotation": {H.H_KR: 0, H.H_NROT: 0}, "without the mixed pairs":
                     {H.H_NBETA: 0}}
            row = {"order": order, "degrees": degrees}
            for name, patch in parts.items():
                ints = tab.ints.copy()
                for k, v in patch.items():
                    ints[k] = v
                scr = np.zeros((n, tab.scratch))
                res = np.zeros((n, 11))
                loop(rows, R, scr, ints, tab.floats, res, 1)
                t0 = time.process_time()
                loop(rows, R, scr, ints, tab.floats, res, reps)
                row[name] = (time.process_time() - t0) / (n * reps) * 1e9
            out.append(row)
            print(f"  order {order:2d} degrees {str(degrees):8s} " + ", ".join(
                f"{k} {v:.0f} ns" for k, v in row.items() if k not in ("order", "degrees")),
                flush=True)
    return out


def compile_times(models, orders):
    rows = []
    for model in models:
        for order in orders:
            with tempfile.TemporaryDirectory(prefix="ti_spinorbit_cache_") as cache:
                env = dict(os.environ, TI_OFFLINE_CACHE_FILE_PATH=cache)
                t0 = time.perf_counter()
                p = subprocess.run([sys.executable, "-c", CHILD_COMPILE, model, str(order)],
                                   capture_output=True, text=True, env=env, cwd=EXPERIMENTS)
                wall = time.perf_counter() - t0
            if p.returncode:
                raise RuntimeError(p.stderr[-3000:])
            seconds = json.loads(p.stdout.strip().splitlines()[-1])["compile_s"]
            rows.append({"model": model, "order": order, "compile_s": seconds,
                         "process_s": wall})
            print(f"  cold compile {model:6s} order {order:2d}: {seconds:.2f} s "
                  f"(fresh process {wall:.1f} s)", flush=True)
    return rows


def memory(orders):
    """Bytes per member of the kernels' order-N block (the harmonic form: coefficient row
    and scratch) and of the shared tables, beside the Cartesian form's for reference."""
    from ti_spinorbit.engine import harmonic_tables as HT, multipole_tables as MT
    rows = []
    for order in orders:
        if order <= 4:
            continue
        for caps in [None] + ([CAPS[order]] if order in CAPS else []):
            degrees = MT.check_degrees(order, caps)
            h = HT.tables(order, *degrees)
            t = MT.tables(order, *degrees, False)
            rows.append({"order": order, "degrees": degrees, "row_bytes": 8 * h.width,
                         "scratch_bytes": 8 * h.scratch,
                         "table_bytes": h.ints.nbytes + h.floats.nbytes,
                         "cartesian_row_bytes": 8 * t.width,
                         "cartesian_scratch_bytes": 8 * t.scratch, "cartesian_pairs": t.pairs})
            print(f"  order {order:2d} degrees {str(degrees):8s}: {8 * h.width} B row + "
                  f"{8 * h.scratch} B scratch per member; tables "
                  f"{h.ints.nbytes + h.floats.nbytes} B shared (Cartesian form: {8 * t.width}"
                  f" + {8 * t.scratch} B, {t.pairs} mixed pairs)", flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    ap.add_argument("--models", nargs="+", choices=("planar", "3d"), default=["3d", "planar"])
    ap.add_argument("--orders", nargs="+", type=int, default=list(ORDERS))
    ap.add_argument("--members", type=int, default=1024)
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--rounds", type=int, default=1,
                    help="measure every rate point this many times, round after round, and "
                         "report medians (ratios to order 4 taken within each round)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=None, help="JSON path (default: print only)")
    ap.add_argument("--pair", choices=("ellipsoid", "radar"), default="ellipsoid",
                    help="the benchmarked pair (radar: the polyhedral primary; 3-D only)")
    args = ap.parse_args()
    PAIR[0] = args.pair
    if args.pair == "radar":
        args.models = ["3d"]
    if args.quick:
        args.members, args.seconds = 16, 0.2
    import ti_spinorbit as tso
    tso.init()
    report = {"rtol": RTOL, "members": args.members, "load_before": os.getloadavg()}
    if "memory" in args.sections:
        print("memory per member", flush=True)
        report["memory"] = memory(args.orders)
    if "rates" in args.sections:
        print("rates", flush=True)
        report["rates"] = rates(args.models, args.orders, args.members, args.seconds,
                                args.rounds)
        for r in report["rates"]:
            if r["model"] == "3d" and r["order"] in TARGETS and r["degrees"] == (r["order"],) * 2 \
                    and r["ratio_to_order_4"] is not None:
                goal = TARGETS[r["order"]]
                print(f"  target 3-D order {r['order']} >= {goal:.3g} x order 4: "
                      f"{r['ratio_to_order_4']:.4f} ({r['ratio_to_order_4'] / goal:.2f} of the "
                      f"target) {'MET' if r['ratio_to_order_4'] >= goal else 'MISS'}")
    if "split" in args.sections:
        print("split (one core, the potential alone)", flush=True)
        tso.init(cpu_max_num_threads=1)
        report["split"] = split(args.orders, 64 if args.quick else 256, 20 if args.quick else 200)
    if "compile" in args.sections:
        print("cold compile", flush=True)
        report["compile"] = compile_times(args.models, [o for o in args.orders if o != 2])
    report["load_after"] = os.getloadavg()
    report["max_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"load average {report['load_before'][0]:.2f} before, {report['load_after'][0]:.2f} after")
    if args.out:
        with open(args.out, "w") as f:
            json.dump(report, f, indent=1, default=list)


if __name__ == "__main__":
    main()
