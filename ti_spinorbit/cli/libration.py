"""``ti-spinorbit libration``: relaxed libration amplitude at the synchronous island's
centre (PNG + .npz)."""

import math
import sys
import warnings

import numpy as np

from ..engine.options import Run
from ..engine.results import Status
from ..output.plotting import plot_libration_search
from ..studies.libration import relaxed_libration
from .common import (EXIT_INACCURATE, accuracy_status, build_system, check_figure_outputs,
                     check_system_flags, init_taichi, output_paths, progress_bar, say,
                     write_outputs)
from .options import (Bounded, MAX_SPIN, ORBITS, SPIN, accuracy_flags, add_command,
                      announce_perturbations, check_max_orbits, check_perturbation_flags,
                      coordinates_flag, perturbation_flags, run_options, system_flags)

NAME = "libration"
EXAMPLES = """\
  ti-spinorbit libration --system Didymos --orbits 100
  ti-spinorbit libration --system "2000 DP107" --elongation 1.2 --out dp107_libration.png"""


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "relaxed libration amplitude at the synchronous island "
                    "centre (PNG + .npz)", EXAMPLES)
    system_flags(s, default="Didymos")
    s.add_argument("--xtol", type=Bounded(float, 1e-12, 0.1), default=1e-6,
                   help="stop the centre search when the window half-width (units of n) is "
                        "below this, in [1e-12, 0.1] (default 1e-6)")
    # LO, HI and N have ranges of their own, HI's from LO: checked after parsing
    s.add_argument("--candidates", type=float, nargs=3, metavar=("LO", "HI", "N"),
                   help="coarse bracket of θ̇_p/n: N (5 to 10001) values over LO..HI "
                        "(default 45 over 0.2..1.3)")
    s.add_argument("--max-orbits", type=ORBITS, default=None,
                   help="cap of the length doubling that checks the centre and amplitude "
                        "converge, in [--orbits, 1e7] (default 4 x --orbits)")
    run_options(s, "PNG path of the centre search, extent vs θ̇_p/n (default "
                "libration_<system>.png)", orbits=100.0, rtol=1e-12, model=False)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)
    return s


def check(args):
    check_max_orbits(args)
    if args.candidates:
        lo, hi, n = args.candidates
        SPIN.check("--candidates LO", lo)
        Bounded(float, lo, MAX_SPIN, low_open=True).check("--candidates HI", hi)
        if not (float(n).is_integer() and 5 <= n <= 10001):
            raise ValueError(f"--candidates N must be an integer in [5, 10001] (got {n:g})")
    system = check_system_flags(args)
    if not system.omega0 > 0:
        raise ValueError(f"--elongation must be > 1 for libration: a round secondary has no "
                         f"synchronous island (got {args.elongation:g})")
    check_perturbation_flags(args)
    check_figure_outputs(args)


def _plot_libration(result):
    return plot_libration_search(result)


def _status_code(name):
    return int(Status.from_label(name))


def run(args):
    system = build_system(args)
    out, data = output_paths(args, "libration", system.name)
    kwargs = dict(orbits=args.orbits, rtol=args.rtol, xtol=args.xtol, max_drift=args.max_drift,
                  max_orbits=args.max_orbits, coordinates=args.coordinates, method=args.method)
    kwargs["perturbations"] = announce_perturbations(args, system)
    if args.candidates:
        lo, hi, n = args.candidates
        kwargs["candidates"] = np.linspace(lo, hi, int(n))
    init_taichi(args)
    with progress_bar(args) as bar, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        result = relaxed_libration(system, **kwargs, run=Run(progress=bar))
    for w in caught:
        if not args.quiet:
            print(f"ti-spinorbit libration: warning: {w.message}", file=sys.stderr)
    plot = getattr(result, "plot", None)
    out, data = write_outputs(result, data, {"command": args.command_line,
                                             "converged": result.converged,
                                             "convergence": result.message},
                              plot if callable(plot) else lambda: _plot_libration(result), out)
    say(args,
        f"{system.name}: relaxed libration amplitude {result.amplitude:.4f} deg at the "
        f"synchronous centre thetadot_p/n = {result.centre_thetadot_p:.8f}",
        f"  forced libration amplitude |ψ_A| = {abs(result.psi_A):.4f} deg (omega0 "
        f"{result.omega0:.4f}), with spin-orbit coupling {abs(result.psi_A_effective):.4f} deg "
        f"(omega0_eff {result.omega0_effective:.4f})",
        f"  {psi_phase(result.psi_A)}",
        f"  section extent at the centre {result.extent:.2e} deg, {result.iterations} zooms, "
        f"{'converged' if result.converged else 'NOT converged'}, {result.seconds:.1f} s",
        f"  centre trajectory: status {result.status}, energy drift {result.energy_drift:.1e}"
        f" (limit {result.max_drift:.1e})",
        *("  " + line for line in result.evidence()),
        f"wrote {out} and {data}")
    code = accuracy_status(args, np.array([_status_code(result.status)]),
                           np.array([result.energy_drift]), result.max_drift, "trajectories")
    if not result.converged:     # on stderr even with --quiet: it qualifies the amplitude
        allowed = getattr(args, "allow_inaccurate", False)
        why = result.message or (f"search window not below --xtol {result.xtol:g} or section "
                                 f"extent at the centre {result.extent:.3g} deg too wide")
        print(f"ti-spinorbit libration: not converged ({why}); the amplitude "
              f"{result.amplitude:.4f} deg is not final, results written"
              + ("" if allowed else f"; raise --orbits/--max-orbits or tighten --rtol, or "
                                    f"--allow-inaccurate to accept (exit status "
                                    f"{EXIT_INACCURATE})"), file=sys.stderr)
        if not allowed:
            code = EXIT_INACCURATE
    return code


def psi_phase(psi_a):
    """The phase of the forced libration ψ = ψ_A sin M (docs/physics.md §8.2) in words: ψ_A
    (deg) is negative for ω0 < 1, which is a phase, not a negative amplitude."""
    if psi_a == 0:
        return "(no forced libration: e = 0)"
    if not math.isfinite(psi_a):
        return "(phase undefined: omega0 = 1 is the forced resonance)"
    sign, how = ("−", "in antiphase with M, as for omega0 < 1") if psi_a < 0 else \
        ("+", "in phase with M, as for omega0 > 1")
    return (f"(phase: ψ = {sign}|ψ_A| sin M, {how}; ψ is the long axis's angle from the line "
            "of centres, M the mean anomaly)")
