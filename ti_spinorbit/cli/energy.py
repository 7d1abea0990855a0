"""``ti-spinorbit energy``: energy and angular-momentum conservation check (PNG + .npz; exit
status 1 above --max-drift)."""

import math as m
import sys

import numpy as np

from .. import time_series
from ..display import negligible, sci
from ..system import catalog
from .common import (EXIT_CHECK_FAILED, EXIT_OK, build_system, catalogue_name,
                     check_figure_outputs, check_system_flags, entry_options, finish_checkpoint,
                     init_taichi, output_paths, progress_bar, say, write_outputs)
from .options import (ANGLE, Bounded, MAX_DRIFT, SPIN, add_command, announce_perturbations,
                      check_perturbation_flags, perturbation_flags, run_options, system_flags)

NAME = "energy"
EXAMPLES = """\
  ti-spinorbit energy                          # the paper's energy-check case ("test")
  ti-spinorbit energy --orbits 20 --rtol 1e-13 --max-drift 1e-10 --out energy.png
  ti-spinorbit energy --system "1991 VH" --thetadot 1.0 --orbits 50
  ti-spinorbit energy --system "1991 VH" --thetadot 0.8 --orbits 20 --tide secondary --time-lag 600 --strength 1e6"""
#: Samples per primary rotation when --samples-per-orbit is not given (resolves the fast
#: primary spin so the energy exchange is not aliased), at least MIN_SAMPLES_PER_ORBIT.
SAMPLES_PER_PRIMARY_ROTATION = 40
MIN_SAMPLES_PER_ORBIT = 64


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "energy and angular-momentum conservation check (PNG + "
                    ".npz; exit status 1 when the drift exceeds --max-drift)", EXAMPLES)
    system_flags(s, default="test")
    s.add_argument("--theta-p", type=ANGLE, default=0.0,
                   help="initial θ_p, deg, in [-360, 360] (default 0)")
    s.add_argument("--thetadot", type=SPIN, default=None,
                   help="initial θ̇_p/n (default: the catalogued spin period, else 1)")
    s.add_argument("--samples-per-orbit", type=Bounded(int, 1, 100000), default=None,
                   help=f"samples per orbit in [1, 100000] (default: {SAMPLES_PER_PRIMARY_ROTATION} "
                        f"per primary rotation, at least {MIN_SAMPLES_PER_ORBIT})")
    s.add_argument("--max-drift", type=MAX_DRIFT, default=1e-9,
                   help="largest relative energy or angular-momentum drift that passes, "
                        "in (0, 1] (default 1e-9)")
    run_options(s, "PNG path of drift vs time (default energy_<system>.png)", orbits=5.0,
                rtol=1e-12, resume=True)
    perturbation_flags(s)
    return s


def check(args):
    check_system_flags(args)
    check_perturbation_flags(args)
    check_figure_outputs(args)


def _exchange_line(numbers):
    """The orbit/spin energy exchange, |ΔE_i|/|E0|; an exchange below 1e-12 of the largest
    is round-off and prints as 0 (a sphere's spin: 1e-37; display.negligible)."""
    orbit, primary, secondary = negligible([numbers["exchange_orbit"], numbers["exchange_primary"],
                                            numbers["exchange_secondary"]])
    return (f"  largest exchange, |ΔE_i|/|E0|: orbit {sci(orbit)}, primary spin {sci(primary)}, "
            f"secondary spin {sci(secondary)}")


def energy_check(ts, member=0):
    """Conservation numbers of one member of a TimeSeriesResult and the per-sample arrays:
    :meth:`~ti_spinorbit.studies.section.TimeSeriesResult.conservation` (kept here for callers)."""
    return ts.conservation(member)


def _plot_energy(ts):
    return ts.plot_conservation(0)


def _work_line(ts, member=0):
    """The work the perturbations did on a time series member by its last sample, J, and the
    angular momentum they brought in (the drifts above are those of E - W and L - L_ext)."""

    ok = np.isfinite(ts.t[member])
    work = float(ts.work[member][ok][-1])
    lext = float(np.linalg.norm(ts.external_angmom[member][ok][-1]))
    return (f"  work done by the perturbations W = {work:.6e} J by the end (< 0: dissipated); "
            f"external angular momentum |L_ext| = {lext:.3e} kg m^2/s")


def run(args):
    system = build_system(args)
    out, data = output_paths(args, "energy", system.name)
    thetadot = args.thetadot
    if thetadot is None:
        known = catalogue_name(system)
        period = None if known is None else catalog.secondary_spin_period(known)
        thetadot = 1.0 if period is None else 2 * m.pi / period / system.mean_motion
    samples = args.samples_per_orbit
    if samples is None:
        rotations = 0 if not system.primary_spin_period else \
            system.orbital_period / abs(system.primary_spin_period)
        samples = max(MIN_SAMPLES_PER_ORBIT, m.ceil(SAMPLES_PER_PRIMARY_ROTATION * rotations))
    init_taichi(args)
    perturbations = announce_perturbations(args, system)
    with progress_bar(args) as bar:
        ts = time_series(system, args.theta_p, thetadot, args.orbits, samples_per_orbit=samples,
                         rtol=args.rtol, max_drift=args.max_drift, perturbations=perturbations,
                         **entry_options(args, data, bar))
    numbers, series = energy_check(ts)
    status = ts.status_names[0]
    out, data = write_outputs(ts, data, {"command": args.command_line, "energy_check": numbers,
                                         "member_status": status},
                              lambda: _plot_energy(ts), out)
    worst = max(numbers["energy_drift"], numbers["angmom_drift"])
    say(args,
        f"{system.name}: {args.orbits:g} orbits at rtol {args.rtol:g}, {numbers['samples']} "
        f"samples, status {status}",
        f"  max relative energy drift           {numbers['energy_drift']:.3e}",
        f"  max relative angular-momentum drift {numbers['angmom_drift']:.3e}",
        _exchange_line(numbers),
        *([] if ts.work is None else [_work_line(ts)]),
        f"wrote {out} and {data}", *filter(None, [finish_checkpoint(args, data)]))
    if not worst <= args.max_drift:          # also catches NaN
        print(f"ti-spinorbit energy: drift {worst:.3e} exceeds --max-drift {args.max_drift:g} "
              f"(status {status})", file=sys.stderr)
        return EXIT_CHECK_FAILED
    if status != "done":
        print(f"ti-spinorbit energy: the integration stopped early (status {status})",
              file=sys.stderr)
        return EXIT_CHECK_FAILED
    return EXIT_OK
