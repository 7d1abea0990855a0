"""``ti-spinorbit benchmark``: ensemble throughput in member-orbits/s (JSON)."""

import os
import platform
import time

import numpy as np

from .. import Integrator, Run, runtime, surface_of_section
from ..output.io import provenance
from .common import (build_system, check_output, check_system_flags, claim_outputs, init_taichi,
                     refuse_existing, say)
from .options import Bounded, add_command, run_options

NAME = "benchmark"
EXAMPLES = """\
  ti-spinorbit benchmark --members 1024 --orbits 20
  ti-spinorbit benchmark --arch cuda --members 65536 --orbits 20 --out bench_cuda.json"""
#: Most members of any run.
MAX_MEMBERS = 2**20
#: The spread of starts (as experiments/bench_throughput.py).
BENCH_THETADOT_RANGE = (0.4, 2.6)


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "ensemble throughput in member-orbits/s on 1991 VH (JSON)",
                    EXAMPLES)
    s.add_argument("--system", default="1991 VH", help="catalogued system (default 1991 VH)")
    s.add_argument("--members", type=Bounded(int, 1, MAX_MEMBERS), default=256,
                   help=f"ensemble size in [1, {MAX_MEMBERS}] (default 256)")
    s.add_argument("--repeat", type=Bounded(int, 1, 100), default=1,
                   help="timed runs, the best is reported, in [1, 100] (default 1)")
    run_options(s, "JSON path (default benchmark.json)", data=False, orbits=20.0, rtol=1e-12)
    return s


def check(args):
    check_system_flags(args)
    check_output("--out", args.out, (".json",))
    flag = "--out" if args.out else "the report (default --out)"
    claim_outputs(args, [(flag, args.out or "benchmark.json")])
    refuse_existing(args, args.out or "benchmark.json", flag)


def run(args):
    system = build_system(args)
    out = args.out or "benchmark.json"
    thetadot = np.linspace(*BENCH_THETADOT_RANGE, args.members)
    init_taichi(args)
    started = time.perf_counter()
    options = dict(rtol=args.rtol, method=args.method, integrator=Integrator(model=args.model, order=args.order),
                   run=Run(progress=False))
    surface_of_section(system, 0.0, thetadot[:1], orbits=1.0, **options)   # compile / load
    warmup = time.perf_counter() - started
    runs = [surface_of_section(system, 0.0, thetadot, orbits=args.orbits, **options)
            for _ in range(args.repeat)]
    best = min(runs, key=lambda r: r.seconds)
    rate = args.members * args.orbits / best.seconds
    names, counts = np.unique(best.status_names, return_counts=True)
    report = {**provenance(), "command": args.command_line, "system": args.system,
              "members": args.members, "orbits": args.orbits, "rtol": args.rtol,
              "method": args.method,
              "arch": runtime.current_arch(), "seconds": [r.seconds for r in runs],
              "best_seconds": best.seconds, "member_orbits_per_second": rate,
              "warmup_seconds": warmup,
              "steps_per_member_orbit": float(np.mean(best.accepted + best.rejected) / args.orbits),
              "rhs_calls_per_member_orbit": float(np.mean(best.rhs_calls) / args.orbits),
              "status_counts": {str(n): int(c) for n, c in zip(names, counts)},
              "machine": {"platform": platform.platform(), "processor": platform.processor(),
                          "cpu_count": os.cpu_count(), "python": platform.python_version()}}
    from ..files import write_json      # atomic: a killed write leaves no partial report

    write_json(out, report, indent=1)
    say(args, f"{args.system}: {args.members} members x {args.orbits:g} orbits at rtol "
              f"{args.rtol:g} on {report['arch']}: {best.seconds:.3g} s (best of {args.repeat}), "
              f"{rate:.0f} member-orbits/s; first call {warmup:.1f} s; wrote {out}")
    return 0
