"""Is the line-of-centres harmonic form of the order-N potential cheaper in a kernel?

Benchmark-only prototype (the package kernels are unchanged): the mutual potential, force and
both torques of ``ti_spinorbit.harmonics`` (real solid harmonics, both bodies turned into the
frame whose z axis is the line of centres by z-rotations and the fixed matrices J, the
interaction then diagonal in m; docs/physics.md §3.8.2) written as a Taichi function over host
tables, timed beside the package's Cartesian table-driven ``kernels/multipole_gravity.mutual_n``
on the same members, in the same loop (the ``split`` harness of bench_orders.py: one member
per iteration, a dependent chain of evaluations, one core, process CPU time).

Checks before timing: the prototype's U, ∂U/∂R and torques against the Cartesian kernel's on
every member (relative difference printed; they must agree to ~1e-13), so the two timings are
of the same numbers.

    python experiments/bench_harmonics.py                       # orders 6, 8, 12, ~1 min
    python experiments/bench_harmonics.py --orders 6 8 --caps   # and degree caps (N, 4)
    python experiments/bench_harmonics.py --quick               # CI: order 6, a few members

What the prototype does per evaluation (N the order, dA, dB the degree caps):

* geometry: r, the angles φ, θ of R, the rotation Q = P S of the secondary into the frame
  P = Ry(−θ) Rz(−φ), and α, β, γ with Rz(−α) Q = Ry(β) Rz(γ), all from matrix entries;
* the multiple angles cos mψ, sin mψ (m ≤ N) of the five angles by the addition recurrence;
* A: X(−φ), J, X(−θ), Jᵀ, X(−α) per degree 2..dA; B: X(γ), J, X(β), Jᵀ per degree 2..dB
  (X: 4 products per pair ±m, index arithmetic; J, Jᵀ: row-compressed sparse tables);
* the interaction: per (l1, l2) with l1 + l2 ≤ N, 2 min(l1, l2) + 1 diagonal terms, each
  updating U and both bodies' ∂U/∂C;
* torques from the generators (row-compressed tables, two entries per row), the transverse
  force from R × ∂U/∂R = τ_A + τ_B, everything turned back into the primary's frame.
"""

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))


def measure(order, caps, n, reps, odd):
    """One row: ns per evaluation of both forms, their agreement, the table sizes."""
    import bench_orders as B
    from ti_spinorbit.engine import harmonic_tables as HT, multipole_tables as MT

    dA, dB = MT.check_degrees(order, caps)
    tab = MT.tables(order, dA, dB, odd)
    row = B.integral_rows(B.system(), order, (dA, dB))[0]
    if odd:      # a body without mirror planes: perturb every integral of degree >= 2
        rng = np.random.default_rng(5)
        E = MT.multi_indices(max(dA, dB))
        pert = np.concatenate([1e-3 * rng.standard_normal(MT.count(d)) *
                               (E[:MT.count(d)].sum(1) >= 2) for d in (dA, dB)])
        row = row + pert * np.abs(row).max()
    rows_c = np.repeat(row[None], n, 0)
    rows_h = HT.coefficient_rows(rows_c, dA, dB)
    R = np.column_stack([0.95 + 0.1 * np.sin(np.arange(n)), 0.2 * np.cos(np.arange(n)),
                         0.05 + 0.3 * np.cos(0.7 * np.arange(n))])
    ht = HT.tables(order, dA, dB, HT.degree_mask(rows_h, dA),
                   HT.degree_mask(rows_h, dB, first=(dA + 1) ** 2))
    ints, floats, width = ht.ints, ht.floats, ht.scratch
    kh, kc = KERNELS["harmonic"], KERNELS["cartesian"]
    out_c, out_h = np.zeros((n, 11)), np.zeros((n, 11))
    scr_c, scr_h = np.zeros((n, tab.scratch)), np.zeros(n * width)
    t0 = time.perf_counter()
    kc(rows_c, R, scr_c, tab.ints, tab.floats, out_c, 0)
    compile_c = time.perf_counter() - t0
    t0 = time.perf_counter()
    rows_h = rows_h.ravel()                  # the harmonic kernels' rows are one flat array
    kh(rows_h, R, scr_h, ints, floats, out_h, 0)
    compile_h = time.perf_counter() - t0
    diff = max(float(np.max(np.abs(out_h[:, sl] - out_c[:, sl]))
                     / np.max(np.abs(out_c[:, sl]))) for sl in
               (slice(0, 1), slice(1, 4), slice(4, 7), slice(7, 10)))
    times = {"cartesian": [], "harmonic": []}
    runs = (("cartesian", kc, rows_c, scr_c, tab.ints, tab.floats, out_c),
            ("harmonic", kh, rows_h, scr_h, ints, floats, out_h))
    for _ in range(ROUNDS):            # interleaved rounds, medians: the machine is shared
        for name, k, rows_, scr, it, ft, out in runs:
            t0 = time.process_time()
            k(rows_, R, scr, it, ft, out, reps)
            times[name].append((time.process_time() - t0) / (n * reps) * 1e9)
    times = {k: float(np.median(v)) for k, v in times.items()}
    return {"order": order, "degrees": (dA, dB), "odd": odd,
            "cartesian_ns": times["cartesian"], "harmonic_ns": times["harmonic"],
            "speedup": times["cartesian"] / times["harmonic"], "max_rel_diff": diff,
            "compile_cartesian_s": compile_c, "compile_harmonic_s": compile_h,
            "harmonic_tables_bytes": int(ints.nbytes + floats.nbytes),
            "harmonic_scratch": int(width), "cartesian_scratch": int(tab.scratch),
            "cartesian_mixed_pairs": tab.pairs}


KERNELS = {}
ROUNDS = 7


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--orders", type=int, nargs="+", default=[6, 8, 12])
    ap.add_argument("--caps", action="store_true", help="also degree caps (N, 4)")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=None, help="JSON path (default: print only)")
    args = ap.parse_args()
    import ti_spinorbit as tso
    tso.init(cpu_max_num_threads=1)
    from _order_n_loop import loop_kernel, tilted_rotation
    from ti_spinorbit.kernels.harmonic_gravity import mutual_h
    from ti_spinorbit.kernels.multipole_gravity import mutual_n
    rotation = tilted_rotation()
    KERNELS.update(harmonic=loop_kernel(mutual_h, rotation),
                   cartesian=loop_kernel(mutual_n, rotation))
    orders = [6] if args.quick else args.orders
    n, reps = (16, 5) if args.quick else (256, 100)
    rows = []
    for order in orders:
        for caps in [None] + ([(order, 4)] if args.caps else []):
            for odd in (False, True):
                r = measure(order, caps, n, reps, odd)
                rows.append(r)
                print(f"  order {order:2d} degrees {str(r['degrees']):8s} "
                      f"{'odd' if odd else 'even'}: Cartesian {r['cartesian_ns']:7.0f} ns, "
                      f"harmonic {r['harmonic_ns']:7.0f} ns ({r['speedup']:.2f}x), "
                      f"agree to {r['max_rel_diff']:.1e}; compile {r['compile_cartesian_s']:.1f}"
                      f" / {r['compile_harmonic_s']:.1f} s", flush=True)
                if r["max_rel_diff"] > 1e-11:
                    raise SystemExit(f"the two forms disagree ({r['max_rel_diff']:.1e})")
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"rows": rows, "load": os.getloadavg()}, f, indent=1, default=list)


if __name__ == "__main__":
    main()
