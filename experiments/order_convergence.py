"""Convergence of the mutual potential's force and torque with truncation order N, and its cost.

Beyond the paper. Two homogeneous-ellipsoid binaries, equal densities 2400 kg/m³ (the
relative errors do not depend on the common density), the secondary turned 25° about z and
then 10° about its own (turned) x axis, C = R_z(25°) R_x(10°), at R along the primary's x
axis:

* post-DART (65803) Didymos: primary 409.5 × 400.5 × 303.5 m, secondary 88.5 × 87 × 58 m,
  |R| = 1190 m;
* (66391) 1999 KW4: primary 766 × 747.5 × 673.5 m, secondary 285 × 231.5 × 174.5 m,
  |R| = 2548 m.

For each N the order-N force on the secondary and torque on it
(ti_spinorbit.multipole.mutual_force_torque: Cartesian multipole–multipole expansion of
Hou, Scheeres & Xin 2017, CeMDA 127:369, at any order) are compared with the exact ones: the
exterior potential of the homogeneous primary in closed confocal form (MacMillan 1930;
Chandrasekhar 1969), its elliptic-type integral by Gauss–Legendre quadrature, integrated over
the secondary's volume by a product Gauss rule (tests/ellipsoid_exact.py; converged to
~1e-14, printed). Also printed: the same with the secondary capped at degree 2 (its
second-order integrals only), and the time of one evaluation of U, F and both torques at each
N (best of several, after the first call, which builds and caches the index tables; the first
call's cost is printed too).
"""

import os
import sys
import time

import numpy as np

import _common

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import ellipsoid_exact as ex  # noqa: E402  (the exact reference lives with the tests)

from ti_spinorbit import multipole as mp  # noqa: E402

NAME = "order_convergence"
DENSITY = 2400.0
SYSTEMS = {
    "Didymos": ((409.5, 400.5, 303.5), (88.5, 87.0, 58.0), 1190.0),
    "1999 KW4": ((766.0, 747.5, 673.5), (285.0, 231.5, 174.5), 2548.0),
}


def rotation(z_deg, x_deg):
    """R_z(z) R_x(x): turned about z, then about the turned x axis."""
    cz, sz = np.cos(np.radians(z_deg)), np.sin(np.radians(z_deg))
    cx, sx = np.cos(np.radians(x_deg)), np.sin(np.radians(x_deg))
    Rz = np.array([[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]])
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]])
    return Rz @ Rx


def rel(a, b):
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b))


def best_time(f, repeat):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def main():
    args, started = _common.parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    orders = list(range(2, 9, 2)) if args.quick else list(range(2, 17, 2))
    repeat = 5 if args.quick else 30
    C = rotation(25.0, 10.0)
    G = mp.G_SI
    arrays, numbers = {"orders": np.array(orders)}, {}
    fig, (ax_err, ax_time) = plt.subplots(1, 2, figsize=(10, 4))
    for label, (axes_a, axes_b, r) in SYSTEMS.items():
        key = label.replace(" ", "_").lower()
        MA = 4.0 / 3.0 * np.pi * np.prod(axes_a) * DENSITY
        MB = 4.0 / 3.0 * np.pi * np.prod(axes_b) * DENSITY
        R = np.array([r, 0.0, 0.0])
        U0, F0, tB0, tA0 = ex.exact_mutual(G, MA, axes_a, MB, axes_b, R, C)
        fine = ex.exact_mutual(G, MA, axes_a, MB, axes_b, R, C, nodes=(26, 26, 52), u_nodes=64)
        print(f"[{NAME}] {label}: exact reference converged to force {rel(fine[1], F0):.1e}, "
              f"torque on B {rel(fine[2], tB0):.1e} (two quadrature sizes)")
        print(f"[{NAME}] {label}: {'N':>3} {'force err':>10} {'torque_B err':>12} "
              f"{'torque_A err':>12} {'U err':>9} | {'dB=2: force':>11} {'torque_B':>9} | "
              f"{'ms/eval':>8} {'first call ms':>13} {'pairs':>6}")
        errs, capped, times = [], [], []
        for N in orders:
            TA = ex.ellipsoid_integrals(MA, axes_a, N)
            TB = ex.ellipsoid_integrals(MB, axes_b, N)
            mp._pair_tables.cache_clear()
            t0 = time.perf_counter()
            U, F, tB, tA = mp.mutual_force_torque(TA, TB, R, C, N, G=G)
            first = time.perf_counter() - t0
            per = best_time(lambda: mp.mutual_force_torque(TA, TB, R, C, N, G=G), repeat)
            _, Fc, tBc, _ = mp.mutual_force_torque(TA, TB, R, C, N, degrees=(N, 2), G=G)
            e = (rel(F, F0), rel(tB, tB0), rel(tA, tA0), abs(U - U0) / abs(U0))
            c = (rel(Fc, F0), rel(tBc, tB0))
            pairs = len(mp._pair_tables(N, N, N)[0])
            errs.append(e)
            capped.append(c)
            times.append(per)
            print(f"[{NAME}] {label}: {N:>3} {e[0]:>10.2e} {e[1]:>12.2e} {e[2]:>12.2e} "
                  f"{e[3]:>9.2e} | {c[0]:>11.2e} {c[1]:>9.2e} | {per * 1e3:>8.3f} "
                  f"{first * 1e3:>13.1f} {pairs:>6}")
        errs, capped, times = np.array(errs), np.array(capped), np.array(times)
        arrays[f"{key}_errors"] = errs
        arrays[f"{key}_capped_errors"] = capped
        arrays[f"{key}_seconds"] = times
        numbers[f"{key}_force_err_N{orders[-1]}"] = float(errs[-1, 0])
        numbers[f"{key}_torque_err_N{orders[-1]}"] = float(errs[-1, 1])
        ax_err.semilogy(orders, errs[:, 0], "o-", label=f"{label}: force")
        ax_err.semilogy(orders, errs[:, 1], "s--", label=f"{label}: torque on B")
        ax_time.semilogy(orders, times * 1e3, "o-", label=label)
    numbers["ms_per_eval_max_order"] = float(times[-1] * 1e3)
    ax_err.set_xlabel("truncation order $N$")
    ax_err.set_ylabel("relative error vs exact")
    ax_err.legend(fontsize=7)
    ax_time.set_xlabel("truncation order $N$")
    ax_time.set_ylabel("ms per evaluation ($U$, $F$, both torques)")
    ax_time.legend(fontsize=7)
    fig.suptitle("Mutual potential at order $N$: convergence and cost", fontsize=10)
    _common.save(args, NAME, fig, arrays,
                 {"density": DENSITY, "C": "Rz(25 deg) Rx(10 deg)", "orders": orders,
                  "systems": {k: list(map(list, v[:2])) + [v[2]] for k, v in SYSTEMS.items()}},
                 numbers, started)


if __name__ == "__main__":
    main()
