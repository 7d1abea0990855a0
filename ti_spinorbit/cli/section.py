"""``ti-spinorbit section``: surface of section of a system (PNG + .npz)."""

import numpy as np

from .. import surface_of_section
from ..engine.results import STATUS_NAMES, Status
from ..output.plotting import plot_section
from ..system import catalog
from .common import (accuracy_status, build_system, catalogue_name, check_figure_outputs,
                     check_system_flags, entry_options, finish_checkpoint, init_taichi,
                     output_paths, progress_bar, say, write_outputs)
from .options import (ANGLE, SPIN, accuracy_flags, add_command, announce_perturbations,
                      check_perturbation_flags, coordinates_flag, perturbation_flags, run_options,
                      system_flags, tilt_flags)

NAME = "section"
EXAMPLES = """\
  ti-spinorbit section --system "1991 VH" --out sos_1991VH.png
  ti-spinorbit section --system "1991 VH" --elongation 1.06 --thetadot 1.13 1.63 1.70 1.78 --orbits 1000"""


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "surface of section of a catalogued system (PNG + .npz)",
                    EXAMPLES)
    system_flags(s)
    s.add_argument("--theta-p", type=ANGLE, default=0.0,
                   help="initial θ_p, deg, in [-360, 360] (default 0)")
    s.add_argument("--thetadot", type=SPIN, nargs="+",
                   help="initial θ̇_p/n values (default: the paper's starts for this system)")
    tilt_flags(s)
    run_options(s, "PNG path (default sos_<system>.png)", orbits=500.0, rtol=1e-12, resume=True)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)
    return s


def check(args):
    check_system_flags(args)
    check_perturbation_flags(args)
    check_figure_outputs(args)


def _status_text(result, k):
    """Member k's status, with what it stopped for when the verdict overrode it
    ("inaccurate (escape)")."""

    name = result.status_names[k]
    stop = getattr(result, "stop_status", None)
    if stop is not None and name == "inaccurate" and int(stop[k]) != Status.DONE:
        name += f" ({STATUS_NAMES[int(stop[k])]})"
    return name


def run(args):
    system = build_system(args)
    known = catalogue_name(system)
    starts = args.thetadot or (catalog.section_starts(known) if known else
                               list(catalog.DEFAULT_SECTION_STARTS))
    tilted = args.tilt is not None or args.spin_xy is not None or args.inclination is not None
    if tilted and args.coordinates != "inertial":
        raise ValueError("--tilt, --spin-xy and --inclination need --coordinates inertial (the "
                         "apsidal coordinates are defined for planar starts)")
    out, data = output_paths(args, "sos", system.name)
    init_taichi(args)
    perturbations = announce_perturbations(args, system)
    if tilted:                     # explicit 3-D starts (docs/physics.md §6.8)
        roll, pitch, yaw = args.tilt or (0.0, 0.0, 0.0)
        sx, sy = args.spin_xy or (0.0, 0.0)
        starts_kw = {"initial_states": [system.tilted_start(
            args.theta_p, v, roll=roll, pitch=pitch, yaw=yaw, spin_x=sx, spin_y=sy,
            inclination=args.inclination or 0.0) for v in starts]}
    else:
        starts_kw = {"theta_p": args.theta_p, "thetadot_p": np.array(starts)}
    with progress_bar(args) as bar:
        result = surface_of_section(system, orbits=args.orbits, **starts_kw,
                                    rtol=args.rtol, max_drift=args.max_drift,
                                    coordinates=args.coordinates, perturbations=perturbations,
                                    **entry_options(args, data, bar))
    out, data = write_outputs(result, data, {"command": args.command_line},
                              lambda: plot_section(result), out)
    say(args, f"{system.name}: mass ratio {system.mass_ratio:.2f}, omega0 {system.omega0:.4f}, "
              f"{args.coordinates} coordinates, "
              f"{len(starts)} trajectories x {args.orbits:g} orbits in {result.seconds:.2f} s "
              f"({result.member_orbits_per_second:.0f} member-orbits/s), drift limit "
              f"{result.max_drift:.1e}")
    for k, v in enumerate(starts):
        tilt = f", largest pole tilt {result.max_tilt[k]:.3g} deg" if tilted else ""
        say(args, f"  thetadot_p/n = {v:5.2f}: {result.count[k]} crossings, status "
                  f"{_status_text(result, k)}, energy drift {result.energy_drift[k]:.1e}, "
                  f"angular-momentum drift {result.angmom_drift[k]:.1e}{tilt}")
    say(args, f"wrote {out} and {data}", *filter(None, [finish_checkpoint(args, data)]))
    return accuracy_status(args, result.status, result.energy_drift, result.max_drift,
                           stop_status=result.stop_status)
