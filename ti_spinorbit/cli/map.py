"""``ti-spinorbit map``: chaos map (MEGNO, Lyapunov, classes) over a (θ_p, θ̇_p/n) grid."""

import numpy as np

from ..display import counts
from ..studies.chaosmap import chaos_map
from .common import (accuracy_status, build_system, check_figure_outputs, check_system_flags,
                     entry_options, finish_checkpoint, init_taichi, output_paths, progress_bar,
                     say, write_outputs)
from .options import (Bounded, SPIN, accuracy_flags, add_command, announce_perturbations,
                      check_perturbation_flags, coordinates_flag, perturbation_flags, run_options,
                      system_flags)

NAME = "map"
EXAMPLES = """\
  ti-spinorbit map --system "2004 DC" --grid 32 32 --orbits 300 --out dc_map.png
  ti-spinorbit map --system "2004 DC" --grid 128 128 --orbits 500 --resume   # Ctrl-C safe
  ti-spinorbit map --system "1991 VH" --grid 16 16 --model 3d                # force 3-D"""
#: Largest grid side of a chaos map.
MAX_GRID = 1024


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "chaos map over (θ_p, θ̇_p/n): MEGNO, Lyapunov, classes "
                    "(PNG + .npz)", EXAMPLES)
    system_flags(s)
    s.add_argument("--grid", type=Bounded(int, 1, MAX_GRID), nargs=2, default=[32, 32],
                   metavar=("NTHETA", "NTHETADOT"),
                   help=f"grid size, each in [1, {MAX_GRID}] (default 32 32)")
    s.add_argument("--thetadot-range", type=SPIN, nargs=2, default=[0.2, 3.0],
                   metavar=("LO", "HI"), help="θ̇_p/n range, LO < HI (default 0.2 3.0)")
    s.add_argument("--indicator-space", choices=("planar", "full"), default="planar",
                   help="shadow direction of MEGNO: planar-restricted (default) or the full "
                        "state, attitudes included (the 3-D model runs; docs/physics.md §10.4)")
    run_options(s, "PNG path (default map_<system>.png)", resume=True)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)
    return s


def check(args):
    lo, hi = args.thetadot_range
    if not hi > lo:
        raise ValueError(f"--thetadot-range needs LO < HI (got {lo:g} {hi:g})")
    check_system_flags(args)
    check_perturbation_flags(args)
    check_figure_outputs(args)


def run(args):
    system = build_system(args)
    nt, nd = args.grid
    lo, hi = args.thetadot_range
    out, data = output_paths(args, "map", system.name)
    init_taichi(args)
    perturbations = announce_perturbations(args, system)
    theta = (np.arange(nt) + 0.5) * 180.0 / nt
    with progress_bar(args) as bar:
        cmap = chaos_map(system, theta, np.linspace(lo, hi, nd), orbits=args.orbits,
                         rtol=args.rtol, max_drift=args.max_drift,
                         include_inaccurate=args.allow_inaccurate, coordinates=args.coordinates,
                         indicator_space=args.indicator_space, perturbations=perturbations,
                         **entry_options(args, data, bar))
    out, data = write_outputs(cmap, data, {"command": args.command_line}, cmap.plot, out)
    counted = "all finished members" if args.allow_inaccurate else \
        f"{cmap.n_inaccurate} inaccurate left out"
    say(args, f"{system.name}: {nt} x {nd} map, {args.orbits:g} orbits: chaotic fraction "
              f"{cmap.chaotic_fraction:.3f} ({counted}; statuses: {counts(cmap.status_counts)}) in "
              f"{cmap.seconds:.1f} s; largest energy drift {np.nanmax(cmap.energy_drift):.1e}"
              f" (limit {cmap.max_drift:.1e}); wrote {out} and {data}")
    say(args, f"  {cmap.fraction_message}", *filter(None, [finish_checkpoint(args, data)]))
    return accuracy_status(args, cmap.status, cmap.energy_drift, cmap.max_drift)
