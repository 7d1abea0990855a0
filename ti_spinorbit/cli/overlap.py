"""``ti-spinorbit overlap``: 1:1 / 3:2 resonance-overlap scan over the elongation a/b."""

import numpy as np

from ..engine.options import Integrator, Run
from ..studies.overlap import overlap_threshold
from ..system import catalog
from .common import (accuracy_status, check_figure_outputs, check_system_flags, init_taichi,
                     output_paths, progress_bar, say, write_outputs)
from .options import (Bounded, MAX_ELONGATION, ORBITS, accuracy_flags, add_command,
                      announce_perturbations, check_max_orbits, check_perturbation_flags,
                      coordinates_flag, perturbation_flags, run_options, system_flags)

NAME = "overlap"
EXAMPLES = """\
  ti-spinorbit overlap --system "1991 VH" --elongations 1.01 1.10 0.01 --orbits 500"""
#: Most elongations of one scan.
MAX_SCAN_STEPS = 1001
#: Smallest --elongations STEP (a/b is rounded to 10 digits; finer steps are meaningless).
MIN_ELONGATION_STEP = 1e-6


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "resonance-overlap scan over a/b, 1:1 and 3:2 (PNG + .npz)",
                    EXAMPLES)
    system_flags(s, shape=False)
    # START, STOP and STEP have ranges of their own, STOP's from START: checked after parsing
    s.add_argument("--elongations", type=float, nargs=3, default=[1.01, 1.15, 0.01],
                   metavar=("START", "STOP", "STEP"),
                   help=f"a/b scan, 1 < START <= STOP <= {MAX_ELONGATION:g}, STEP > 0 "
                        "(default 1.01 1.15 0.01)")
    s.add_argument("--max-orbits", type=ORBITS, default=None,
                   help="cap of the length doubling (--orbits, 2x, 4x, ...) that checks the "
                        "decisions converge, in [--orbits, 1e7] (default 4 x --orbits)")
    run_options(s, "PNG path (default overlap_<system>.png)")
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)
    return s


def _scan(start, stop, step):
    """The a/b values of --elongations START STOP STEP (rounded to 10 digits)."""

    return np.round(np.arange(start, stop + step / 2, step), 10)


def check(args):
    check_max_orbits(args)
    start, stop, step = args.elongations
    Bounded(float, 1.0, MAX_ELONGATION, low_open=True).check("--elongations START", start)
    Bounded(float, start, MAX_ELONGATION).check("--elongations STOP", stop)
    Bounded(float, MIN_ELONGATION_STEP, MAX_ELONGATION).check("--elongations STEP", step)
    if (stop - start) / step + 1 > MAX_SCAN_STEPS:
        raise ValueError(f"--elongations: at most {MAX_SCAN_STEPS} elongations per scan "
                         f"(got {start:g} {stop:g} {step:g}); use a larger STEP")
    scan = _scan(start, stop, step)
    if scan.size and scan.max() > MAX_ELONGATION:
        raise ValueError(f"--elongations {start:g} {stop:g} {step:g} steps to a/b = "
                         f"{scan.max():g}, past {MAX_ELONGATION:g}: lower STOP or change STEP")
    check_system_flags(args)
    check_perturbation_flags(args)
    check_figure_outputs(args)


def run(args):
    system = catalog.system(args.system, eccentricity=args.eccentricity)   # checks name and e
    out, data = output_paths(args, "overlap", system.name)
    init_taichi(args)
    perturbations = announce_perturbations(args, system)
    q = _scan(*args.elongations)
    with progress_bar(args) as bar:
        scan = overlap_threshold(args.system, elongations=q, eccentricity=args.eccentricity,
                                 orbits=args.orbits, rtol=args.rtol, method=args.method,
                                 integrator=Integrator(model=args.model, order=args.order),
                                 run=Run(progress=bar), max_drift=args.max_drift,
                                 include_inaccurate=args.allow_inaccurate,
                                 max_orbits=args.max_orbits, coordinates=args.coordinates,
                                 perturbations=perturbations)
    out, data = write_outputs(scan, data, {"command": args.command_line,
                                           "converged": scan.converged,
                                           "convergence": scan.message}, scan.plot, out)
    bound = "" if scan.converged or scan.first_overlap is None else \
        " (upper bound: not converged)"
    say(args, f"{scan.name} (e = {scan.eccentricity:g}): first overlap at a/b = "
              f"{_elongation(scan.first_overlap)}{bound} (analytic {scan.elongation_ro:.4f}; "
              f"MEGNO criterion {_elongation(scan.megno_first_overlap)}) in "
              f"{scan.seconds:.1f} s, {scan.member_orbits:.3g} member-orbits; wrote {out} and "
              f"{data}")
    say(args, *scan.evidence())
    for d in scan.decisions:
        extra = f", connecting <Y> = {d.connecting_megno:.1f}" if d.overlap else ""
        extra += f", {d.inaccurate} inaccurate trajectories" if d.inaccurate else ""
        say(args, f"  a/b = {d.elongation:.2f}: {'overlap' if d.overlap else 'separate'}{extra}")
    sec = scan.sections
    return accuracy_status(args, sec.status, sec.energy_drift, scan.max_drift, "trajectories")


def _elongation(q):
    """An a/b threshold as printed: "1.23", or "none in the scan" (None)."""
    return "none in the scan" if q is None else f"{q:.4g}"
