"""Host time around the kernels: what a surface of section costs beyond its integration.

A planar surface of section of 1991 VH (2048 members by default: θ_p = 0, θ̇_p/n spread over
0.5-2.5), 20 orbits, Verner's 9(8) pair, rtol 1e-12, after a warm-up call that compiles the
kernels. Timed:

* the whole call, ``tso.surface_of_section(...)`` (wall);
* its integration alone, ``Ensemble.run`` on the same member table (the kernel launches and
  the window bookkeeping), measured inside the call by wrapping ``Ensemble.run``;
* the host time = whole − integration: input checks, the member table, the derived columns
  (observables, ϖ̇ where apsidal), the accuracy verdict and the result object.

Then the same call under cProfile, printing the functions with the most own host time and any
function called at least once per member (a per-member Python loop shows up there).

Target (the structure issue): host time ≤ 10 % of the integration at N ≥ 1024, and no per-member
Python loop on any path.

    python experiments/bench_host_overhead.py                 # 2048 members, about 10 s
    python experiments/bench_host_overhead.py --members 4096 --method cash-karp
"""

import argparse
import cProfile
import pstats
import time

import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--members", type=int, default=2048)
    p.add_argument("--orbits", type=float, default=20.0)
    p.add_argument("--method", default="vern9")
    p.add_argument("--rtol", type=float, default=1e-12)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--coordinates", default="inertial", choices=("inertial", "apsidal"))
    args = p.parse_args()

    import ti_spinorbit as tso
    from ti_spinorbit.engine import ensemble

    tso.init()
    vh = tso.catalog.system("1991 VH")
    starts = np.linspace(0.5, 2.5, args.members)
    call = dict(orbits=args.orbits, rtol=args.rtol, method=args.method,
                coordinates=args.coordinates, run=tso.Run(progress=False))
    tso.surface_of_section(vh, 0.0, starts[:8], **dict(call, orbits=0.1))   # compile

    inner = []
    real_run = ensemble.Ensemble.run

    def timed_run(self, *a, **k):
        t0 = time.perf_counter()
        try:
            return real_run(self, *a, **k)
        finally:
            inner.append(time.perf_counter() - t0)

    ensemble.Ensemble.run = timed_run
    rows = []
    try:
        for _ in range(args.repeats):
            inner.clear()
            t0 = time.perf_counter()
            result = tso.surface_of_section(vh, 0.0, starts, **call)
            whole = time.perf_counter() - t0
            rows.append((whole, sum(inner)))
    finally:
        ensemble.Ensemble.run = real_run
    whole, kernel = min(rows, key=lambda r: r[0] - r[1])
    host = whole - kernel
    print(f"surface_of_section: {args.members} members, {args.orbits:g} orbits, {args.method}, "
          f"rtol {args.rtol:g}, {args.coordinates} coordinates, {len(result.count)} members done")
    print(f"  whole call   {whole:8.3f} s   (best of {args.repeats} by host time)")
    print(f"  integration  {kernel:8.3f} s   (Ensemble.run)")
    print(f"  host         {host:8.3f} s   = {100 * host / kernel:.1f} % of the integration "
          f"(target <= 10 %)")

    profile = cProfile.Profile()
    profile.enable()
    tso.surface_of_section(vh, 0.0, starts, **call)
    profile.disable()
    stats = pstats.Stats(profile)
    own = []
    per_member = []
    for (file, line, name), (cc, nc, tt, ct, callers) in stats.stats.items():
        if "ti_spinorbit" in file or "kernels" in file:
            own.append((tt, nc, f"{file.split('ti_spinorbit')[-1].lstrip('/')}:{line} {name}"))
            if nc >= args.members and "kernels" not in file:
                per_member.append((nc, tt, f"{file.split('ti_spinorbit')[-1].lstrip('/')}:{line} {name}"))
    print("  most own time in the package (profiled call):")
    for tt, nc, where in sorted(own, reverse=True)[:8]:
        print(f"    {tt:7.3f} s  {nc:8d} calls  {where}")
    print(f"  package functions called >= {args.members} times (once per member or more): "
          f"{len(per_member)}")
    for nc, tt, where in sorted(per_member, reverse=True)[:10]:
        print(f"    {nc:8d} calls  {tt:7.3f} s  {where}")


if __name__ == "__main__":
    main()
