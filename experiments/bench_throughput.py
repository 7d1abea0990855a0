"""Benchmark: ensemble throughput on 1991 VH against scipy's DOP853, start-up, threads.

What is measured (all on the current Taichi arch, CPU by default; θ_p = 0 and θ̇_p/n spread
over linspace(0.4, 2.6, N), so every run is deterministic):

1. Kernel throughput: member-orbits per second of ``surface_of_section`` at rtol 1e-12 and
   1e-15 for N = 1, 64, 1024, 4096 members over 20 orbits (``--quick``: N = 1, 64 over 2
   orbits). The time is ``SectionResult.seconds`` (kernel launches and buffer draining, not
   set-up); one warm-up call first compiles or loads the kernels and is timed on its own.
   Accepted and rejected steps and right-hand-side calls are means per member per orbit.
2. Baseline: the plain NumPy reference (``reference.integrate``, scipy DOP853) on a few members
   at the same rtol. Tolerance choice: the kernels control the error of the *scaled* state
   (every component O(1)) with atol = rtol; the reference integrates the SI state, whose
   components span 1 (rotation matrices) to 1e13 (Γ1). The baseline therefore uses the
   per-component atol = rtol × (SI size of one scaled unit) = rtol · to_physical(ones), which is
   the kernels' own error control carried to SI (scipy's RMS norm is, if anything, looser than
   the kernels' max norm, which favours the baseline). A "pure relative" atol such as 1e-30
   does not work: components that are zero in this planar problem pick up round-off
   (Γ1_z ≈ 1e-27 N m s for the torque-free spherical primary, S1 entries ≈ 1e-52), pure
   relative control then asks for errors of ~1e-39, and DOP853 shrinks its step to ~1e-15 of
   an orbit (it did not finish 0.001 orbit in 300 s). scipy raises any rtol below 100 eps to
   2.2e-14, so the "1e-15" baseline really runs at rtol 2.2e-14 (atol stays 1e-15 · units):
   easier than the kernels' 1e-15, again in the baseline's favour; the table shows the rtol
   scipy used. One-off costs (importing scipy.integrate, the reference's cached multipole
   bases) are paid before timing. Each baseline member is also run by the kernels to the same
   end time and the final states are compared (max |Δy| in scaled units), so both sides
   integrate the same problem. The ratio printed is kernel throughput at the largest N over
   baseline throughput, per tolerance.
3. First result from a fresh process: ``sys.executable -c`` imports ti_spinorbit and computes
   a 1-member, 1-orbit section with the offline kernel cache in a new temporary folder: the
   first run compiles (cold cache), the next ``--repeat`` runs load (warm cache; the best is
   compared with the target). Wall time includes interpreter start-up.
4. Threads: N = 1024 (``--quick``: 64) at rtol 1e-12 in fresh processes with
   ``cpu_max_num_threads = 1`` and with the default (all cores), alternating; Taichi fixes the
   thread count at ``ti.init``.

``--repeat k`` times every kernel run, warm start and thread setting k times and keeps the
best, which helps on a shared machine (the load average at start and end is recorded).

Targets: >= 1000 member-orbits/s at N = 4096, rtol 1e-12; >= 300x the baseline; <= 3 s to
the first result from a fresh process with a warm cache.

Writes ``<out>/bench_throughput.json`` (every number plus machine information),
``bench_throughput.png`` (throughput against N) and ``bench_throughput.npz``; prints the table.

    python experiments/bench_throughput.py            # full: several minutes on 2 cores
    python experiments/bench_throughput.py --quick    # CI: under a minute
"""

import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

from _common import parse, save

SYSTEM = "1991 VH"
THETA_P_DEG = 0.0
THETADOT_RANGE = (0.4, 2.6)      # θ̇_p/n spread across the members (units of n)
RTOLS = (1e-12, 1e-15)
TARGET_RATE = 1000.0             # member-orbits/s at N = 4096, rtol 1e-12
TARGET_SPEEDUP = 300.0           # over the scipy baseline
TARGET_FIRST_RESULT_S = 3.0      # fresh process, warm offline cache
SCIPY_MIN_RTOL = 100 * np.finfo(float).eps  # scipy's RK solvers raise smaller rtol to this

# Full and --quick settings.
FULL = dict(sizes=(1, 64, 1024, 4096), orbits=20.0, baseline_members=2, baseline_orbits=2.0,
            thread_members=1024, thread_orbits=20.0)
QUICK = dict(sizes=(1, 64), orbits=2.0, baseline_members=1, baseline_orbits=0.5,
             thread_members=64, thread_orbits=2.0)

# Child processes print one JSON line last; sys.argv[1:] carries their inputs.
CHILD_FIRST_RESULT = """
import json, time
t0 = time.perf_counter()
import ti_spinorbit as tso
imported = time.perf_counter() - t0
r = tso.surface_of_section(tso.catalog.system({system!r}), {theta_p!r}, [1.0], orbits=1)
print(json.dumps({{"import_s": imported, "in_process_s": time.perf_counter() - t0,
                  "integrate_s": r.seconds, "crossings": int(r.count[0])}}))
"""
CHILD_THREADS = """
import json, sys
import numpy as np
import ti_spinorbit as tso
threads, n = int(sys.argv[1]), int(sys.argv[2])
orbits, rtol = float(sys.argv[3]), float(sys.argv[4])
tso.init(arch="cpu", cpu_max_num_threads=threads or None)
system = tso.catalog.system({system!r})
tso.surface_of_section(system, {theta_p!r}, [1.0], orbits=1, rtol=rtol)  # compile or load
r = tso.surface_of_section(system, {theta_p!r}, np.linspace({lo!r}, {hi!r}, n), orbits=orbits,
                           rtol=rtol)
print(json.dumps({{"seconds": r.seconds, "member_orbits_per_s": r.member_orbits_per_second}}))
"""


def spread(n):
    """The benchmark's initial spin rates θ̇_p/n for n members."""
    return np.linspace(*THETADOT_RANGE, n)


def machine_info():
    """Versions, CPU, git state and the load average (taken at the start; the machine may be
    shared, and other processes' load lowers every timing here)."""
    import scipy
    import taichi as ti

    import ti_spinorbit as tso

    model = platform.processor()
    try:
        with open("/proc/cpuinfo") as f:
            model = next(line.split(":", 1)[1].strip() for line in f
                         if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    try:
        commit = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                                text=True, cwd=os.path.dirname(os.path.abspath(__file__)),
                                check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = None
    return {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "cpu_count": os.cpu_count(),
            "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else None,
            "cpu_model": model, "machine": platform.machine(), "platform": platform.platform(),
            "python": platform.python_version(), "taichi": ".".join(map(str, ti.__version__)),
            "numpy": np.__version__, "scipy": scipy.__version__,
            "ti_spinorbit": tso.__version__, "arch": tso.runtime.current_arch(), "git": commit,
            "load_average_1min_start": os.getloadavg()[0]}


def bench_kernel(system, sizes, orbits, repeat):
    """Warm-up, then ``surface_of_section`` per (rtol, N), best of ``repeat`` timings."""
    import ti_spinorbit as tso

    t0 = time.perf_counter()
    tso.surface_of_section(system, THETA_P_DEG, [1.0], orbits=1, rtol=RTOLS[0])
    warmup = time.perf_counter() - t0
    rows = []
    for rtol in RTOLS:
        for n in sizes:
            runs = [tso.surface_of_section(system, THETA_P_DEG, spread(n), orbits=orbits,
                                           rtol=rtol) for _ in range(repeat)]
            r = min(runs, key=lambda run: run.seconds)
            rows.append({"rtol": rtol, "members": n, "orbits": orbits, "seconds": r.seconds,
                         "all_seconds": [run.seconds for run in runs],
                         "member_orbits_per_s": r.member_orbits_per_second,
                         "accepted_per_orbit": float(r.accepted.mean() / orbits),
                         "rejected_per_orbit": float(r.rejected.mean() / orbits),
                         "rhs_per_orbit": float(r.rhs_calls.mean() / orbits),
                         "not_done": int(np.sum(np.asarray(r.status_names) != "done"))})
            print(f"  kernel rtol {rtol:.0e} N {n:5d}: {r.seconds:8.3f} s", flush=True)
    return warmup, rows


def bench_baseline(system, members, orbits):
    """scipy DOP853 on the NumPy reference, and the same members through the kernels."""
    import ti_spinorbit as tso
    from ti_spinorbit import reference
    from ti_spinorbit.ensemble import Ensemble
    from ti_spinorbit.section import build_members

    unit = system.to_physical(np.ones(30))  # SI size of one scaled unit, per component
    t_end = orbits * system.orbital_period
    _, par, y0_scaled, _, _ = build_members(system, THETA_P_DEG, spread(members))
    # one-off costs (importing scipy.integrate, building the cached multipole bases) before timing
    import scipy.integrate  # noqa: F401
    reference.rhs(tso.G, system.primary, system.secondary, system.to_physical(y0_scaled[0]))
    rows = []
    for rtol in RTOLS:
        seconds, steps, rhs, final = 0.0, 0, 0, []
        for y0 in y0_scaled:
            t0 = time.perf_counter()
            with warnings.catch_warnings():  # "rtol too small": recorded as scipy_rtol below
                warnings.simplefilter("ignore", UserWarning)
                sol = reference.integrate(tso.G, system.primary, system.secondary,
                                          system.to_physical(y0), (0.0, t_end), rtol=rtol,
                                          atol=rtol * unit)
            seconds += time.perf_counter() - t0
            if sol.status != 0:
                raise RuntimeError(f"reference integration failed at rtol {rtol}: {sol.message}")
            steps += len(sol.t) - 1
            rhs += sol.nfev
            final.append(sol.y[:, -1])
        kernel = Ensemble(par, y0_scaled, rtol=rtol).run(2.0 * np.pi * orbits)
        mismatch = np.max(np.abs(np.array(final) - system.to_physical(kernel.y)) / unit)
        rows.append({"rtol": rtol, "scipy_rtol": max(rtol, SCIPY_MIN_RTOL),
                     "atol": "rtol * to_physical(ones)", "members": members,
                     "orbits": orbits, "seconds": seconds,
                     "member_orbits_per_s": members * orbits / seconds,
                     "steps_per_orbit": steps / (members * orbits),
                     "rhs_per_orbit": rhs / (members * orbits),
                     "kernel_reference_max_diff_scaled": float(mismatch)})
        print(f"  scipy  rtol {rtol:.0e}: {seconds:8.3f} s", flush=True)
    return rows


def run_child(code, args=(), env=None):
    """Run ``sys.executable -c code *args``; returns (wall seconds, its last-line JSON)."""
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True,
                          text=True, env=env)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"child process failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return wall, json.loads(proc.stdout.strip().splitlines()[-1])


def child_env(arch, **extra):
    env = dict(os.environ, **extra)
    if arch:
        env["TI_SPINORBIT_ARCH"] = arch
    return env


def bench_first_result(arch, repeat):
    """A cold run, then ``repeat`` warm runs, in fresh processes sharing a new cache folder."""
    code = CHILD_FIRST_RESULT.format(system=SYSTEM, theta_p=THETA_P_DEG)
    runs = []
    with tempfile.TemporaryDirectory(prefix="ti_spinorbit_cache_") as cache:
        env = child_env(arch, TI_OFFLINE_CACHE_FILE_PATH=cache)
        for label in ["cold cache"] + ["warm cache"] * repeat:
            wall, inside = run_child(code, env=env)
            runs.append({"run": label, "wall_s": wall, **inside})
            print(f"  fresh process, {label}: {wall:8.3f} s", flush=True)
    return runs


def bench_threads(members, orbits, repeat, rtol=RTOLS[0]):
    """Same ensemble with one thread and with Taichi's default, each in its own process;
    the two settings alternate and the best of ``repeat`` runs of each is kept."""
    code = CHILD_THREADS.format(system=SYSTEM, theta_p=THETA_P_DEG, lo=THETADOT_RANGE[0],
                                hi=THETADOT_RANGE[1])
    settings = (1, 0)  # 0: Taichi's default, all cores
    seconds = {threads: [] for threads in settings}
    for _ in range(repeat):
        for threads in settings:
            _, inside = run_child(code, (threads, members, orbits, rtol), env=child_env(None))
            seconds[threads].append(inside["seconds"])
    rows = []
    for threads in settings:
        best = min(seconds[threads])
        rows.append({"threads": threads or f"default ({os.cpu_count()})", "members": members,
                     "orbits": orbits, "rtol": rtol, "seconds": best,
                     "all_seconds": seconds[threads],
                     "member_orbits_per_s": members * orbits / best})
        print(f"  threads {rows[-1]['threads']}: {best:8.3f} s", flush=True)
    return rows


def targets(kernel_rows, baseline_rows, first_runs):
    """Each target with its measured value; kernel figures at the largest N measured."""
    largest = max(r["members"] for r in kernel_rows)
    rate = {r["rtol"]: r["member_orbits_per_s"] for r in kernel_rows if r["members"] == largest}
    out = [{"target": f">= {TARGET_RATE:.0f} member-orbits/s, N = {largest}, "
                      f"rtol {RTOLS[0]:.0e}",
            "value": rate[RTOLS[0]], "met": rate[RTOLS[0]] >= TARGET_RATE}]
    for b in baseline_rows:
        ratio = rate[b["rtol"]] / b["member_orbits_per_s"]
        out.append({"target": f">= {TARGET_SPEEDUP:.0f}x scipy DOP853, N = {largest}, "
                              f"rtol {b['rtol']:.0e}",
                    "value": ratio, "met": ratio >= TARGET_SPEEDUP})
    warm = min(f["wall_s"] for f in first_runs if f["run"] == "warm cache")
    out.append({"target": f"<= {TARGET_FIRST_RESULT_S:.0f} s first result, fresh process, "
                          "warm cache",
                "value": warm, "met": warm <= TARGET_FIRST_RESULT_S})
    return out


def print_report(result):
    m, p = result["machine"], result["parameters"]
    print()
    mode = "quick" if result["quick"] else "full"
    print(f"ti_spinorbit throughput benchmark  {m['date_utc']}  {mode}")
    print(f"machine: {m['cpu_model']}, {m['cpu_count']} CPUs ({m['machine']}), "
          f"Taichi {m['taichi']}, arch {m['arch']}, git {m['git']}")
    print(f"load average (1 min) at start {m['load_average_1min_start']:.2f}, at end "
          f"{m['load_average_1min_end']:.2f} (other processes share the CPUs if > 0)")
    print(f"system {SYSTEM}, theta_p = {THETA_P_DEG} deg, thetadot_p/n = linspace"
          f"({THETADOT_RANGE[0]}, {THETADOT_RANGE[1]}, N), {p['orbits']:g} orbits; "
          f"warm-up (compile/load) {result['warmup_s']:.2f} s")
    print()
    print(f"{'rtol':>6} {'N':>5} {'seconds':>9} {'member-orb/s':>13} {'acc/orbit':>10} "
          f"{'rej/orbit':>10} {'RHS/orbit':>10} {'not done':>8}")
    for r in result["kernel"]:
        print(f"{r['rtol']:6.0e} {r['members']:5d} {r['seconds']:9.3f} "
              f"{r['member_orbits_per_s']:13.1f} {r['accepted_per_orbit']:10.1f} "
              f"{r['rejected_per_orbit']:10.2f} {r['rhs_per_orbit']:10.1f} {r['not_done']:8d}")
    print()
    print("scipy DOP853 + NumPy reference RHS, atol = rtol * to_physical(ones)")
    print(f"{'rtol':>6} {'scipy rtol':>10} {'members x orbits':>16} {'seconds':>9} "
          f"{'member-orb/s':>13} {'steps/orbit':>11} {'RHS/orbit':>10} {'max|dy| vs kernel':>18}")
    for b in result["baseline"]:
        print(f"{b['rtol']:6.0e} {b['scipy_rtol']:10.2g} {b['members']:>7d} x {b['orbits']:<6g} "
              f"{b['seconds']:9.3f} "
              f"{b['member_orbits_per_s']:13.3f} {b['steps_per_orbit']:11.1f} "
              f"{b['rhs_per_orbit']:10.1f} {b['kernel_reference_max_diff_scaled']:18.2e}")
    print()
    print("first result from a fresh process (1 member, 1 orbit; new offline-cache folder)")
    for f in result["first_result"]:
        print(f"  {f['run']:<10}  wall {f['wall_s']:6.2f} s  (import {f['import_s']:.2f} s, "
              f"in process {f['in_process_s']:.2f} s)")
    print()
    print("threads (fresh processes, rtol 1e-12)")
    for t in result["threads"]:
        print(f"  {str(t['threads']):<12} N {t['members']:5d} x {t['orbits']:g} orbits: "
              f"{t['seconds']:8.3f} s  {t['member_orbits_per_s']:9.1f} member-orbits/s")
    print()
    print("targets")
    for t in result["targets"]:
        print(f"  {'MET ' if t['met'] else 'MISS'}  {t['target']}: {t['value']:.4g}")


def figure(result):
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for k, rtol in enumerate(RTOLS):
        rows = [r for r in result["kernel"] if r["rtol"] == rtol]
        line, = ax.loglog([r["members"] for r in rows], [r["member_orbits_per_s"] for r in rows],
                          "o-", label=f"kernels, rtol {rtol:.0e}")
        for b in result["baseline"]:
            if b["rtol"] == rtol:
                ax.axhline(b["member_orbits_per_s"], color=line.get_color(), ls=":",
                           label=f"scipy DOP853, rtol {b['scipy_rtol']:.2g}")
    ax.axhline(TARGET_RATE, color="k", ls="--", lw=0.8, label="target (rtol 1e-12)")
    ax.set_xlabel("members N")
    ax.set_ylabel("member-orbits per second")
    m = result["machine"]
    ax.set_title(f"{SYSTEM}, {m['cpu_count']}-CPU {m['arch']}, Taichi {m['taichi']}", fontsize=9)
    ax.legend(fontsize=7)
    return fig


def main():
    args, started = parse(__doc__.splitlines()[0], lambda p: p.add_argument(
        "--repeat", type=lambda text: max(1, int(text)), default=1,
        help="time each kernel run and thread setting this many times, keep the best "
             "(default 1; raise it on a shared or noisy machine)"))
    import ti_spinorbit as tso

    settings = QUICK if args.quick else FULL
    machine = machine_info()
    system = tso.catalog.system(SYSTEM)
    print(f"bench_throughput ({'quick' if args.quick else 'full'}): running ...", flush=True)
    warmup, kernel_rows = bench_kernel(system, settings["sizes"], settings["orbits"],
                                       args.repeat)
    baseline_rows = bench_baseline(system, settings["baseline_members"],
                                   settings["baseline_orbits"])
    first_runs = bench_first_result(args.arch, args.repeat)
    thread_rows = (bench_threads(settings["thread_members"], settings["thread_orbits"],
                                 args.repeat)
                   if tso.runtime.current_arch() in ("cpu", "x64", "arm64") else [])
    parameters = {"system": SYSTEM, "theta_p_deg": THETA_P_DEG, "thetadot_range": THETADOT_RANGE,
                  "rtols": RTOLS, "repeat": args.repeat, **settings}
    result = {"benchmark": "bench_throughput", "quick": bool(args.quick),
              "machine": {**machine, "load_average_1min_end": os.getloadavg()[0]},
              "parameters": parameters,
              "warmup_s": warmup, "kernel": kernel_rows, "baseline": baseline_rows,
              "first_result": first_runs, "threads": thread_rows,
              "targets": targets(kernel_rows, baseline_rows, first_runs)}
    print_report(result)
    path = os.path.join(args.out, "bench_throughput.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=1)
    print(f"[bench_throughput] wrote {path}")
    save(args, "bench_throughput", figure(result),
         {key: [r[key] for r in kernel_rows] for key in ("rtol", "members", "member_orbits_per_s")},
         {"machine": result["machine"], **parameters},
         {t["target"]: t["value"] for t in result["targets"]}, started)


if __name__ == "__main__":
    main()
