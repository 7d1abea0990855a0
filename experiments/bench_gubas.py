"""GUBAS, measured: CPU seconds per mutual orbit and per right-hand side of the field's
reference code at expansion orders 2, 4, 6, 8 and 12, on one core, for bench_orders.py's
ellipsoid pair, beside the package's one-core cost per right-hand side.

GUBAS (General Use Binary Asteroid Simulator, github.com/meyeralexj/gubas, Davis & Scheeres
2020) is not part of this project and is not copied into it: give ``--gubas PATH`` to a
checkout of it and this script drives that checkout. It copies ``hou_cpp.cpp`` from there
into a scratch folder, adds two things to the copy only (a counter at the top of the
right-hand side ``hou_ode``, and a report at exit of that count and of the process CPU time
before and after the line that starts the integration: setup, inertia integrals included,
against integration), compiles it with GUBAS's own compile command plus -O2
(``g++ -std=c++11 -O2 hou_cpp_bench.cpp -o hou_cpp_bench -larmadillo``), writes GUBAS's C++
input file ``ic_input.txt`` per run (the lines its ``write_icfile.py`` writes: km, kg, s),
runs the executable pinned to one core (taskset) and reads the report. GUBAS's Python
wrapper is not used: its post-processing is not what is timed, and it needs NumPy < 2.
Setting GUBAS up (Debian):

    apt-get install -y libarmadillo-dev
    git clone https://github.com/meyeralexj/gubas /tmp/gubas

The pair (bench_orders.py): 1991 VH's orbit (a = 3300 m, e = 0.05), triaxial primary
660 × 600 × 545 m at 1581 kg/m³, secondary 294 × 196 × 190 m at 2618 kg/m³, started at
pericentre with the non-spinning primary and the secondary at θ_p = 90°, θ̇_p = 1.5 n (the
package benchmark's first member). GUBAS's closed-form ellipsoid integrals stop at order 4
(its user guide and ``ell_mass_params_met``), so orders ≤ 4 use them (shape flag 1) and
higher orders use polyhedral ellipsoids this script writes (subdivided icosahedra scaled to
the semi-axes and to the ellipsoid's volume, shape flag 2; GUBAS computes their integrals
to the order). ``--shape poly`` uses the polyhedra at every order.

Integrator: GUBAS's adaptive RK 7(8) (Dormand–Prince, 13 stages per attempted step, no
FSAL, rejected steps included in the count) at ``--tol`` (default 1e-12). GUBAS's error
test is max|x8 − x7| ≤ tol · max|x| over the whole 30-element state in km, km/s, rad/s and
rotation-matrix entries: an absolute test at about tol × 3.3 km on every component, not
the package's per-component mixed test (rtol = atol = 1e-12 on states scaled to a and 1/n).

Per order, three runs of the one executable: (1) one RK4 step (GUBAS's fixed-step RK4
calls the RHS exactly 4 times a step) that generates the inertia integrals: their CPU time
(with the expansion-coefficient setup) and a first RHS cost; (2) RK4 steps sized to
``--seconds`` of CPU with the integrals loaded from (1)'s files: CPU µs per RHS; (3) the
RK 7(8) at ``--tol`` over ``--orbits`` mutual orbits: accepted steps, RHS calls (rejected
steps included) and CPU s per orbit, skipped where it would exceed
``--max-orbit-seconds`` (then s/orbit = µs/RHS × the RHS per orbit of the highest order
run in full, marked "est."). Printed per order: those figures and the ratios to the
package's figures
(``PACKAGE_NS_PER_RHS``: experiments/README.md, bench_orders.py, 3-D, one core; and
``PACKAGE_STEPS_PER_ORBIT`` with Cash-Karp's 6 RHS per step for the per-orbit ratio).

Section ``accuracy`` (what "the same tolerance" means): the first member at order 2 over
2 orbits, GUBAS at tol 1e-10 … 1e-15 and the package at rtol 1e-10 … 1e-14, each against
its own tightest run (GUBAS 3e-16, the package 1e-15): end-position error in units of a,
attitude-matrix error, steps and RHS per orbit; and how far the two tightest runs differ
(the same physics and start: 2e-13 a).

    python experiments/bench_gubas.py --gubas /tmp/gubas --out out/   # about 12 min
    python experiments/bench_gubas.py --gubas /tmp/gubas --orders 4 8 --seconds 5
    python experiments/bench_gubas.py --gubas /tmp/gubas --sections accuracy   # 20 s
    python experiments/bench_gubas.py                                 # skips: no GUBAS

Without ``--gubas`` it prints one line and exits 0.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

EXPERIMENTS = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, EXPERIMENTS)

from bench_orders import A_M, E, PRIMARY, SECONDARY  # noqa: E402  the benchmarked pair

G_SI = 6.67430e-11                 # ti_spinorbit.system.systems.G
ORDERS = (2, 4, 6, 8, 12)
THETA_P_DEG, THETADOT_N = 90.0, 1.5          # bench_throughput.starts(1): the first member
#: experiments/README.md, bench_orders.py (ellipsoid pair, 3-D, full degrees, one core)
PACKAGE_NS_PER_RHS = {2: 81.0, 4: 117.0, 6: 1861.0, 8: 4885.0, 12: 27872.0}
PACKAGE_STEPS_PER_ORBIT = {2: 499.0, 4: 499.0, 6: 501.0, 8: 508.0, 12: 527.0}
PACKAGE_STAGES = 6                           # Cash-Karp RK4(5): 6 RHS per attempted step
TAG = "[bench_gubas]"
RK4_STEP = 30.0                              # s: the RK4 runs that time one RHS

#: added to the scratch copy only (never to the checkout): the RHS counter and CPU clocks
REPORT = r"""
#include <ctime>
#include <cstdio>
static long long bench_rhs_calls = 0;
static std::clock_t bench_clock_integrate = 0;
struct BenchReport { ~BenchReport() {
    std::clock_t end = std::clock();
    std::printf("BENCH rhs_calls %lld setup_cpu_s %.6f integrate_cpu_s %.6f\n", bench_rhs_calls,
                (double) bench_clock_integrate / CLOCKS_PER_SEC,
                (double) (end - bench_clock_integrate) / CLOCKS_PER_SEC);
    std::fflush(stdout); } } bench_report;
"""


def build(gubas, folder):
    """Instrumented copy of GUBAS's hou_cpp.cpp compiled in folder; returns the executable."""
    src = open(os.path.join(gubas, "hou_cpp.cpp"), encoding="utf-8", errors="replace").read()
    head = "mat hou_ode(mat x, mat t, parameters inputs){"
    start = 'cout<<"Integrating"<<endl;'
    main = "int main() {"
    for needle, n in ((head, 1), (start, 1), (main, 1)):
        if src.count(needle) != n:
            raise SystemExit(f"{TAG} cannot instrument {gubas}/hou_cpp.cpp: expected {n} "
                             f"occurrence(s) of {needle!r}, found {src.count(needle)}")
    src = src.replace(head, head + " bench_rhs_calls++;")
    src = src.replace(start, "bench_clock_integrate = std::clock(); " + start)
    src = src.replace(main, REPORT + main)
    path = os.path.join(folder, "hou_cpp_bench.cpp")
    with open(path, "w", encoding="utf-8") as f:
        f.write(src)
    exe = os.path.join(folder, "hou_cpp_bench")
    cmd = ["g++", "-std=c++11", "-O2", "-w", path, "-o", exe, "-larmadillo"]
    t = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode:
        raise SystemExit(f"{TAG} compile failed ({' '.join(cmd)}):\n{p.stderr[-3000:]}")
    print(f"{TAG} compiled {exe} in {time.time() - t:.0f} s: {' '.join(cmd)}", flush=True)
    return exe


def icosphere(level):
    """Unit-sphere vertices and triangles of an icosahedron subdivided `level` times."""
    p = (1 + 5 ** 0.5) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p),
         (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    v = [np.array(x, float) / np.linalg.norm(x) for x in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid, g = {}, []

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                x = v[a] + v[b]
                v.append(x / np.linalg.norm(x))
                mid[key] = len(v) - 1
            return mid[key]
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            g += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = g
    return np.array(v), np.array(f)


def write_polyhedron(folder, name, axes, level):
    """GUBAS vertex (id, x, y, z in m) and tetrahedron (1-based vertex ids) files of an
    ellipsoid polyhedron with the ellipsoid's volume; returns the two file names."""
    v, f = icosphere(level)
    v = v * np.asarray(axes)
    vol = sum(abs(np.linalg.det(v[list(t)])) for t in f) / 6.0
    v *= (4.0 / 3.0 * math.pi * np.prod(axes) / vol) ** (1.0 / 3.0)
    vert, tet = f"{name}_vert.csv", f"{name}_facet.csv"
    np.savetxt(os.path.join(folder, vert), np.column_stack([np.zeros(len(v)), v]),
               delimiter=",", fmt="%.17g")
    np.savetxt(os.path.join(folder, tet), f + 1, delimiter=",", fmt="%d")
    return tet, vert, len(f)


def mean_motion():
    m1 = 4.0 / 3.0 * math.pi * np.prod(PRIMARY[:3]) * PRIMARY[3]
    m2 = 4.0 / 3.0 * math.pi * np.prod(SECONDARY[:3]) * SECONDARY[3]
    return math.sqrt(G_SI * (m1 + m2) / A_M ** 3), m1 + m2


def initial_state():
    """GUBAS's 30 states [r, v (km, km/s, A frame), ω_A, ω_B (rad/s, A frame), C_AN, C_BA
    (row-major)] of the benchmark's first member at pericentre."""
    n, M = mean_motion()
    r = A_M * (1 - E)
    v = math.sqrt(G_SI * M / A_M * (1 + E) / (1 - E))
    th = math.radians(THETA_P_DEG)
    C = [math.cos(th), -math.sin(th), 0.0, math.sin(th), math.cos(th), 0.0, 0.0, 0.0, 1.0]
    return ([r / 1e3, 0.0, 0.0, 0.0, v / 1e3, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, THETADOT_N * n]
            + [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] + C)


def write_input(folder, order, tf, tol, shapes, tgen=1, integ=3, h=30.0):
    """GUBAS's ic_input.txt (its write_icfile.py line order; km, kg, s; densities kg/km³)."""
    (fa, ta, va), (fb, tb, vb) = shapes
    lines = [G_SI / 1e9, order, order, order, *PRIMARY[:3], *SECONDARY[:3], fa, fb,
             PRIMARY[3] * 1e9, SECONDARY[3] * 1e9, 0.0, tf,
             f"TDP_{order}.mat", f"TDS_{order}.mat", "IDP.mat", "IDS.mat", ta, va, tb, vb,
             *initial_state(), tgen, integ, h, tol,
             0, 0, 0, 0,                                   # flyby, helio, solar, tides: off
             5.9722e24, -1.1072e4, 9.1284, 0.1745, 0.1745, 0.1745, 345600.0,   # unused
             1.989e30, 246013901.32, 0.38362664, 0.059475759, 1.2776, 5.573, 2582993.15688,
             1.0, 149597870.7, 1e-5, 1e-5, 660.0, 225.0, 0.005, 0.005, 1.988e30]
    with open(os.path.join(folder, "ic_input.txt"), "w") as f:
        for x in lines:
            f.write((x if isinstance(x, str) else repr(x)) + "\n")


def run_once(exe, folder, core):
    """(report dict, wall s, accepted steps) of one GUBAS run in folder, pinned to core."""
    cmd = ([shutil.which("taskset"), "-c", str(core)] if shutil.which("taskset") else []) + [exe]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    t = time.time()
    p = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, env=env)
    wall = time.time() - t
    m = re.search(r"BENCH rhs_calls (\d+) setup_cpu_s (\S+) integrate_cpu_s (\S+)", p.stdout)
    if p.returncode or not m:
        raise SystemExit(f"{TAG} GUBAS run failed in {folder} (rc {p.returncode}):\n"
                         f"{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    steps = os.path.getsize(os.path.join(folder, "output_t", "t_out.bin")) // 8 - 1
    return ({"rhs_calls": int(m.group(1)), "setup_cpu_s": float(m.group(2)),
             "integrate_cpu_s": float(m.group(3))}, wall, steps)


def measure(exe, root, order, args, rhs_per_orbit=None):
    """One order: inertia integrals, CPU per RHS (RK4 runs: exactly 4 RHS per step), and
    CPU per orbit (RK 7(8) at args.tol over args.orbits orbits) where that fits in
    args.max_orbit_seconds, else estimated from rhs_per_orbit (an RK 7(8) count measured at
    a lower order)."""
    period = 2 * math.pi / mean_motion()[0]
    folder = os.path.join(root, f"order{order:02d}")
    os.makedirs(folder, exist_ok=True)
    poly = args.shape == "poly" or order > 4
    shapes, faces = [], None
    for name, body in (("primary", PRIMARY), ("secondary", SECONDARY)):
        if poly:
            tet, vert, faces = write_polyhedron(folder, name, body[:3], args.level)
            shapes.append((2, tet, vert))
        else:
            shapes.append((1, "none.csv", "none.csv"))
    h = RK4_STEP
    # 1. one RK4 step (4 RHS) generating the inertia integrals: their cost, a first RHS cost
    write_input(folder, order, h, args.tol, shapes, tgen=1, integ=1, h=h)
    pilot, _, _ = run_once(exe, folder, args.core)
    assert pilot["rhs_calls"] == 4, pilot
    us = pilot["integrate_cpu_s"] / 4 * 1e6
    # 2. RK4 sized to args.seconds of CPU, integrals loaded from step 1's files (flag 0)
    k = max(1, math.ceil(args.seconds / (4 * us * 1e-6)))
    for _ in range(3):                       # resized until it lasts about args.seconds
        write_input(folder, order, k * h, args.tol, shapes, tgen=0, integ=1, h=h)
        rk4, wall, _ = run_once(exe, folder, args.core)
        if rk4["integrate_cpu_s"] >= 0.6 * args.seconds or k == 1 and \
                rk4["integrate_cpu_s"] >= 0.3 * args.seconds:
            break
        k = math.ceil(k * args.seconds / max(rk4["integrate_cpu_s"], 1e-3))
    us = rk4["integrate_cpu_s"] / rk4["rhs_calls"] * 1e6
    row = {"order": order, "shape": "polyhedral ellipsoids" if poly else "ellipsoids (closed form)",
           "facets": faces, "tol": args.tol,
           # setup = input + expansion coefficients (+ the integrals when generated)
           "setup_with_integrals_cpu_s": pilot["setup_cpu_s"],
           "setup_without_integrals_cpu_s": rk4["setup_cpu_s"],
           "inertia_integrals_cpu_s": pilot["setup_cpu_s"] - rk4["setup_cpu_s"],
           "rk4_rhs_calls": rk4["rhs_calls"],
           "rk4_cpu_s": rk4["integrate_cpu_s"], "us_per_rhs": us}
    # 3. RK 7(8) over whole orbits where affordable
    guess = (rhs_per_orbit or 1000.0) * us * 1e-6          # CPU s per orbit, expected
    if guess * args.orbits <= args.max_orbit_seconds:
        # whole multiples of args.orbits, enough of them to last about args.seconds
        orbits = args.orbits * min(100, max(1, math.ceil(args.seconds / (guess * args.orbits))))
        write_input(folder, order, orbits * period, args.tol, shapes, tgen=0, integ=3)
        rep, wall, steps = run_once(exe, folder, args.core)
        row.update({"orbits": orbits, "rk78_cpu_s": rep["integrate_cpu_s"],
                    "rk78_rhs_calls": rep["rhs_calls"], "accepted_steps": steps,
                    "steps_per_orbit": steps / orbits,
                    "rhs_per_orbit": rep["rhs_calls"] / orbits,
                    "rk78_us_per_rhs": rep["integrate_cpu_s"] / rep["rhs_calls"] * 1e6,
                    "s_per_orbit": rep["integrate_cpu_s"] / orbits, "orbit_measured": True})
    else:
        row.update({"rhs_per_orbit": rhs_per_orbit, "s_per_orbit": us * 1e-6 * rhs_per_orbit,
                    "orbit_measured": False})
    pk = PACKAGE_NS_PER_RHS.get(order)
    if pk:
        row["package_ns_per_rhs"] = pk
        row["ratio_per_rhs"] = us * 1e3 / pk
        pk_orbit = pk * 1e-9 * PACKAGE_STEPS_PER_ORBIT[order] * PACKAGE_STAGES
        row["package_s_per_orbit"] = pk_orbit
        row["ratio_per_orbit"] = row["s_per_orbit"] / pk_orbit
    return row


ACC_ORDER, ACC_ORBITS = 2, 2
ACC_GUBAS_TOLS = (1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15)
ACC_GUBAS_REF = 3e-16                        # GUBAS's tightest usable tolerance (≈ eps × |x|)
ACC_PACKAGE_RTOLS = (1e-10, 1e-11, 1e-12, 1e-13, 1e-14)
ACC_PACKAGE_REF = 1e-15


def accuracy(exe, root, core):
    """What "the same tolerance" means: the first member's end state after ACC_ORBITS orbits
    at order 2, each code against its own tightest run: the relative position (units of a)
    and the secondary's inertial attitude matrix (Frobenius norm), with steps and RHS per
    orbit, for GUBAS's RK 7(8) over tol and the package's Cash-Karp over rtol (= atol)."""
    period = 2 * math.pi / mean_motion()[0]
    shapes = [(1, "none.csv", "none.csv")] * 2
    gub = {}
    for tol in ACC_GUBAS_TOLS + (ACC_GUBAS_REF,):
        folder = os.path.join(root, f"accuracy_tol{tol:g}")
        os.makedirs(folder, exist_ok=True)
        write_input(folder, ACC_ORDER, ACC_ORBITS * period, tol, shapes, tgen=1, integ=3)
        rep, _, steps = run_once(exe, folder, core)
        x = np.fromfile(os.path.join(folder, "output_x", "x_out.bin"))[-30:]
        # GUBAS's stored r and B-into-A matrix: they are the package's R and S (to 1e-8 a)
        gub[tol] = (x[:3] * 1e3 / A_M, x[21:30].reshape(3, 3), steps / ACC_ORBITS,
                    rep["rhs_calls"] / ACC_ORBITS)
    import bench_orders as BO
    import ti_spinorbit as tso
    from ti_spinorbit.engine.ensemble import Ensemble
    from ti_spinorbit.kernels import eom
    tso.init(cpu_max_num_threads=1)
    par, y0, _, _ = BO.members(1, ACC_ORDER)
    pkg = {}
    for method in PACKAGE_METHODS:
        rtols = ACC_PACKAGE_RTOLS + ((ACC_PACKAGE_REF,) if method == "cash-karp" else ())
        for rtol in rtols:
            out = Ensemble(par, y0, order=ACC_ORDER, rtol=rtol, model="3d",
                           method=method).run(2 * math.pi * ACC_ORBITS)
            y, c = out.y[0], out.counters[0]
            pkg[method, rtol] = (y[eom.Y_R:eom.Y_R + 3].copy(),
                                 y[eom.Y_S:eom.Y_S + 9].reshape(3, 3).copy(),
                                 c[0] / ACC_ORBITS, c[2] / ACC_ORBITS)
    gub = {("RK 7(8)", tol): v for tol, v in gub.items()}
    rows = []
    for code, res, ref in (("GUBAS", gub, ("RK 7(8)", ACC_GUBAS_REF)),
                           ("package", pkg, ("cash-karp", ACC_PACKAGE_REF))):
        for (method, tol), (r, att, steps, rhs) in res.items():
            if (method, tol) != ref:
                rows.append({"code": f"{code} {method}", "tol": tol, "steps_per_orbit": steps,
                             "rhs_per_orbit": rhs,
                             "position_error_a": float(np.linalg.norm(r - res[ref][0])),
                             "attitude_error": float(np.linalg.norm(att - res[ref][1]))})
    gr, pr = gub["RK 7(8)", ACC_GUBAS_REF], pkg["cash-karp", ACC_PACKAGE_REF]
    agree = {"position_a": float(np.linalg.norm(gr[0] - pr[0])),
             "attitude": float(np.linalg.norm(gr[1] - pr[1]))}
    print(f"\n{TAG} accuracy: order {ACC_ORDER}, first member, end state after {ACC_ORBITS} "
          f"orbits against each code's own tightest run (GUBAS tol {ACC_GUBAS_REF:g}, package "
          f"Cash-Karp rtol {ACC_PACKAGE_REF:g})")
    print("| code | tol | steps/orbit | RHS/orbit | position error (a) | attitude error |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['code']} | {r['tol']:g} | {r['steps_per_orbit']:.0f} | "
              f"{r['rhs_per_orbit']:.0f} | {r['position_error_a']:.2g} | "
              f"{r['attitude_error']:.2g} |")
    print(f"{TAG} the two tightest runs agree to {agree['position_a']:.1e} a in position and "
          f"{agree['attitude']:.1e} in the attitude matrix")
    return {"rows": rows, "tightest_runs_agree": agree}


PACKAGE_METHODS = ("cash-karp", "dop853")


def package_rates(orders, n, seconds, methods=PACKAGE_METHODS):
    """The package measured here, beside GUBAS and at its load: bench_orders.py's pair and
    members (N = n, rtol = atol = 1e-12, 3-D) with Cash-Karp and DOP853: one-core CPU ns per
    RHS (process CPU / RHS calls, the integrator's work included), RHS and steps per member
    orbit, and CPU ms per member-orbit (process CPU / member-orbits: the per-core cost)."""
    import bench_orders as BO
    import ti_spinorbit as tso
    from ti_spinorbit.engine.ensemble import Ensemble
    tso.init()
    out_rows = []
    for method in methods:
        for order in orders:
            par, y0, mp, degrees = BO.members(n, order)

            def run(k, orbits):
                ens = Ensemble(par[:k], y0[:k], order=order, rtol=BO.RTOL, model="3d",
                               method=method, multipole_rows=None if mp is None else mp[:k],
                               degrees=degrees)
                cpu = time.process_time()
                out = ens.run(2.0 * math.pi * orbits)
                cpu = time.process_time() - cpu
                c = out.counters
                return {"method": method, "order": order, "members": k, "orbits": orbits,
                        "member_orbits_per_s": k * orbits / out.seconds,
                        "steps_per_orbit": float(c[:, 0].mean()) / orbits,
                        "rhs_per_orbit": float(c[:, 2].mean()) / orbits,
                        "ns_per_rhs": cpu / float(c[:, 2].sum()) * 1e9,
                        "cpu_ms_per_member_orbit": cpu / (k * orbits) * 1e3}
            run(1, 0.01)                                     # compile or load the variant
            pilot = run(16, 0.02)
            orbits = max(0.05, float(f"{seconds * pilot['member_orbits_per_s'] / n:.2g}"))
            r = run(n, orbits)
            out_rows.append(r)
            print(f"{TAG} package {method:9s} order {order:2d}: {r['ns_per_rhs']:8.0f} ns/RHS "
                  f"(one core), {r['rhs_per_orbit']:5.0f} RHS and {r['steps_per_orbit']:4.0f} "
                  f"steps per orbit, {r['cpu_ms_per_member_orbit']:8.3f} ms CPU per "
                  f"member-orbit ({n} members, {orbits:g} orbits)", flush=True)
    return out_rows


def commit_of(path):
    try:
        return subprocess.run(["git", "-C", path, "rev-parse", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gubas", default=None, help="a GUBAS checkout (outside this repository)")
    ap.add_argument("--orders", nargs="+", type=int, default=list(ORDERS))
    ap.add_argument("--tol", type=float, default=1e-12, help="GUBAS's RK 7(8) tolerance")
    ap.add_argument("--shape", choices=("auto", "poly"), default="auto",
                    help="auto: closed-form ellipsoids to order 4, polyhedra above")
    ap.add_argument("--level", type=int, default=2,
                    help="icosahedron subdivisions of the polyhedra (2: 320 facets)")
    ap.add_argument("--seconds", type=float, default=8.0, help="CPU s of the per-RHS run")
    ap.add_argument("--orbits", type=float, default=2.0,
                    help="orbits of the RK 7(8) runs (a multiple of it where cheap)")
    ap.add_argument("--max-orbit-seconds", type=float, default=600.0,
                    help="skip (and estimate) an RK 7(8) run expected to take longer")
    ap.add_argument("--sections", nargs="+", choices=("rates", "package", "accuracy"),
                    default=["rates", "package", "accuracy"])
    ap.add_argument("--members", type=int, default=1024, help="package section: N")
    ap.add_argument("--core", type=int, default=0, help="the CPU core the runs are pinned to")
    ap.add_argument("--build", default=None, help="scratch folder (default: a temporary one)")
    ap.add_argument("--quick", action="store_true", help="orders 2 and 4, 1 s per point")
    ap.add_argument("--out", default=None, help="folder for bench_gubas.json")
    args = ap.parse_args()
    if not args.gubas:
        print(f"{TAG} skipped: no GUBAS checkout given (--gubas PATH)")
        return
    gubas = os.path.abspath(args.gubas)
    if not os.path.isfile(os.path.join(gubas, "hou_cpp.cpp")):
        raise SystemExit(f"{TAG} {gubas} holds no hou_cpp.cpp (is it a GUBAS checkout?)")
    if args.quick:
        args.orders, args.seconds = [o for o in args.orders if o <= 4] or [2], 1.0
    root = args.build or tempfile.mkdtemp(prefix="bench_gubas_")
    os.makedirs(root, exist_ok=True)
    load0 = os.getloadavg()
    n, M = mean_motion()
    print(f"{TAG} GUBAS {gubas} (commit {commit_of(gubas)}), scratch {root}; load average "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}; orbital period "
          f"{2 * math.pi / n / 3600:.3f} h; RK 7(8) tol {args.tol:g}", flush=True)
    exe = build(gubas, root)
    rows, rhs_per_orbit = [], None
    for order in sorted(args.orders) if "rates" in args.sections else ():
        r = measure(exe, root, order, args, rhs_per_orbit)
        rows.append(r)
        if r["orbit_measured"]:
            rhs_per_orbit = r["rhs_per_orbit"]
            orbit = (f"RK 7(8): {r['steps_per_orbit']:.0f} steps and {r['rhs_per_orbit']:.0f} "
                     f"RHS per orbit at {r['rk78_us_per_rhs']:.1f} us/RHS over {r['orbits']:g} "
                     f"orbits ({r['rk78_cpu_s']:.1f} s CPU)")
        else:
            orbit = f"per orbit estimated from {rhs_per_orbit:.0f} RHS/orbit (a lower order's)"
        print(f"{TAG} order {order:2d}: {r['us_per_rhs']:10.1f} us/RHS (RK4, "
              f"{r['rk4_rhs_calls']} RHS, {r['rk4_cpu_s']:.1f} s CPU), {r['s_per_orbit']:8.2f} "
              f"s/orbit; {orbit}; inertia integrals {r['inertia_integrals_cpu_s']:.2f} s, other "
              f"setup {r['setup_without_integrals_cpu_s']:.2f} s "
              f"({r['shape']}{', %d facets' % r['facets'] if r['facets'] else ''})", flush=True)
    pkg = package_rates(sorted(args.orders), 16 if args.quick else args.members,
                        args.seconds) if "package" in args.sections else []
    acc = accuracy(exe, root, args.core) if "accuracy" in args.sections else None
    load1 = os.getloadavg()
    if rows:
        print(f"\n{TAG} one core, GUBAS RK 7(8) tol {args.tol:g} vs the package "
              f"(bench_orders.py, Cash-Karp rtol 1e-12, 3-D)")
        print("| order | GUBAS s/orbit | GUBAS µs/RHS | GUBAS RHS/orbit | package ns/RHS "
              "| package s/orbit | ratio per RHS | ratio per orbit |")
        print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        if "ratio_per_rhs" in r:
            est = "" if r["orbit_measured"] else " (est.)"
            print(f"| {r['order']} | {r['s_per_orbit']:.3g}{est} | {r['us_per_rhs']:.4g} | "
                  f"{r['rhs_per_orbit']:.0f} | {r['package_ns_per_rhs']:.0f} | "
                  f"{r['package_s_per_orbit']:.3g} | {r['ratio_per_rhs']:,.0f} | "
                  f"{r['ratio_per_orbit']:,.0f} |")
    if rows and pkg:
        print(f"\n{TAG} per core, both measured here: GUBAS s per orbit / package CPU s per "
              f"member-orbit at rtol 1e-12 (ratio per RHS in brackets)")
        print("| order | " + " | ".join(PACKAGE_METHODS) + " |")
        print("|---|" + "---|" * len(PACKAGE_METHODS))
        for r in rows:
            cells = []
            for m in PACKAGE_METHODS:
                p = [q for q in pkg if q["method"] == m and q["order"] == r["order"]]
                cells.append(f"{r['s_per_orbit'] / (p[0]['cpu_ms_per_member_orbit'] * 1e-3):,.0f}"
                             f" ({r['us_per_rhs'] * 1e3 / p[0]['ns_per_rhs']:,.0f})" if p else "")
            print(f"| {r['order']}{'' if r['orbit_measured'] else ' (est.)'} | "
                  + " | ".join(cells) + " |")
    print(f"{TAG} load average {load0[0]:.2f} before, {load1[0]:.2f} after")
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "bench_gubas.json"), "w") as f:
            json.dump({"gubas": gubas, "commit": commit_of(gubas), "tol": args.tol,
                       "load_before": load0, "load_after": load1, "rows": rows,
                       "package": pkg, "accuracy": acc}, f, indent=1)
    if not args.build:
        shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
