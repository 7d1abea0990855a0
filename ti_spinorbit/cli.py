"""Command line: ``ti-spinorbit`` (console script) / ``python -m ti_spinorbit``.

Subcommands
-----------
systems    list the catalogued systems, or show one
section    surface of section of a catalogued system, PNG + .npz
map        chaos map (MEGNO, Lyapunov, classification) over a (θ_p, θ̇_p/n) grid, PNG + .npz
overlap    1:1 / 3:2 resonance-overlap scan over the elongation a/b, PNG + .npz
libration  relaxed libration amplitude at the synchronous island's centre, PNG + .npz
energy     energy and angular-momentum conservation check (exit 1 above --max-drift), PNG + .npz
benchmark  ensemble throughput in member-orbits/s, JSON
warmup     compile the kernel variants ahead of time (later runs start without waiting)
figures    run the experiment scripts that reproduce the paper's studies (needs a source
           checkout: the scripts live in experiments/)

Conventions: every flag is checked before any work starts; a bad value, like any other error
in the inputs, prints ONE line naming the flag, the value and the allowed range, and exits with
status 2 (no traceback). Long runs draw a progress bar on stderr (:mod:`ti_spinorbit.progress`:
a tqdm bar on a terminal, a line per 10 % elsewhere; ``--no-progress`` hides it), and the first
use of a kernel variant says "compiling kernels ... (first use only, about N s)"; compile time
is left out of elapsed times, ETAs and printed rates. ``--quiet`` prints nothing but errors.

File names: defaults carry every physics flag that differs from its default
(:func:`default_stem`: ``sos_1991VH_ab1.06.png`` for ``--elongation 1.06``). A run never
overwrites an existing output: it is refused before any work, naming the file, unless
``--overwrite``. The checkpoint directory of a run is removed once its outputs are written,
unless ``--keep-checkpoint``. Data files are self-describing ``.npz``
(:func:`ti_spinorbit.io.save`); figures are PNG (or PDF/SVG by the extension of ``--out``).

Outputs: every output path (and the Matplotlib backend) is checked before any work; the data
file is written before the figure, so a plotting failure never loses a run's numbers.

Accuracy: every member's energy and angular-momentum drift is held against a limit
(``--max-drift``, default scaled with the tolerance and run length; ti_spinorbit.accuracy).
Members above it are "inaccurate": kept in the data file, counted on stderr, and the command
exits with status 3 (EXIT_INACCURATE) unless ``--allow-inaccurate``.

Exit status: 0 success; 1 a check failed (``energy``); 2 bad input or a failed run (one
line); 3 results written but some members inaccurate; 130 interrupted. ``--debug`` re-raises
any error with its full traceback instead of the one-line message."""

import argparse
import math
import os
import shlex
import sys

from ._validate import MAX_DENSITY, MAX_SPIN, MIN_DENSITY  # bounds shared with the library
from .section import MAX_ORBITS  # orbits limit shared with the library
from . import perturbations as _pert  # tide, YORP and BYORP bounds and defaults, likewise

#: Exit statuses (README "Statuses, exit codes and accuracy").
EXIT_OK, EXIT_CHECK_FAILED, EXIT_ERROR, EXIT_INACCURATE, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
#: Accepted --rtol range (the integrator's own limits, ensemble.check_tolerances).
RTOL_RANGE = (1e-16, 1e-2)
#: Largest grid side of a chaos map, and most members of any run.
MAX_GRID = 1024
MAX_MEMBERS = 2**20
#: Largest elongation a/b (the catalogue's own limit) and scan length.
MAX_ELONGATION = 10.0
MAX_SCAN_STEPS = 1001
#: Smallest --elongations STEP (a/b is rounded to 10 digits; finer steps are meaningless).
MIN_ELONGATION_STEP = 1e-6
#: dest -> (flag, low, high, low_open, high_open): the allowed interval of every plain
#: numeric flag, whichever subcommand has it.
FLAG_RANGES = {
    "orbits": ("--orbits", 0.0, MAX_ORBITS, True, False),
    "rtol": ("--rtol", RTOL_RANGE[0], RTOL_RANGE[1], False, False),
    "elongation": ("--elongation", 1.0, MAX_ELONGATION, False, False),
    "density": ("--density", MIN_DENSITY, MAX_DENSITY, False, False),
    "eccentricity": ("--eccentricity", 0.0, 1.0, False, True),
    "theta_p": ("--theta-p", -360.0, 360.0, False, False),
    "thetadot": ("--thetadot", -MAX_SPIN, MAX_SPIN, False, False),
    "thetadot_range": ("--thetadot-range", -MAX_SPIN, MAX_SPIN, False, False),
    "grid": ("--grid", 1, MAX_GRID, False, False),
    "members": ("--members", 1, MAX_MEMBERS, False, False),
    "repeat": ("--repeat", 1, 100, False, False),
    "samples_per_orbit": ("--samples-per-orbit", 1, 100000, False, False),
    "max_drift": ("--max-drift", 0.0, 1.0, True, False),
    "xtol": ("--xtol", 1e-12, 0.1, False, False),
    "only": ("--only", 1, 99, False, False),
    "max_orbits": ("--max-orbits", 0.0, MAX_ORBITS, True, False),
    "tilt": ("--tilt", -360.0, 360.0, False, False),
    "spin_xy": ("--spin-xy", -MAX_SPIN, MAX_SPIN, False, False),
    "inclination": ("--inclination", -360.0, 360.0, False, False),
    # tides, YORP, BYORP (the bounds of ti_spinorbit.perturbations)
    "k2": ("--k2", *_pert.K2_RANGE, False, False),
    "time_lag": ("--time-lag", *_pert.TIME_LAG_RANGE, False, False),
    "Q": ("--Q", *_pert.Q_RANGE, False, False),
    "yorp": ("--yorp", -_pert.COEFFICIENT_LIMIT, _pert.COEFFICIENT_LIMIT, False, False),
    "byorp": ("--byorp", -_pert.COEFFICIENT_LIMIT, _pert.COEFFICIENT_LIMIT, False, False),
    "strength": ("--strength", *_pert.STRENGTH_RANGE, False, False),
    "tide_radius": ("--tide-radius", *_pert.RADIUS_RANGE, False, False),
    "yorp_radius": ("--yorp-radius", *_pert.RADIUS_RANGE, False, False),
    "byorp_radius": ("--byorp-radius", *_pert.RADIUS_RANGE, False, False),
}
#: --heliocentric A_AU E: the binary's heliocentric orbit for --yorp / --byorp.
HELIOCENTRIC_A_RANGE = _pert.HELIOCENTRIC_A_RANGE
#: Figures and data files.
FIGURE_EXTENSIONS = (".png", ".pdf", ".svg")
#: Energy check: samples per primary rotation when --samples-per-orbit is not given (resolves
#: the fast primary spin so the energy exchange is not aliased), at least MIN_SAMPLES_PER_ORBIT.
SAMPLES_PER_PRIMARY_ROTATION = 40
MIN_SAMPLES_PER_ORBIT = 64
#: Benchmark: the spread of starts (as experiments/bench_throughput.py).
BENCH_THETADOT_RANGE = (0.4, 2.6)

EXAMPLES_BY_COMMAND = {
    "systems": """\
  ti-spinorbit systems
  ti-spinorbit systems --show "2004 DC"
  ti-spinorbit systems --out catalogue.json""",
    "section": """\
  ti-spinorbit section --system "1991 VH" --out sos_1991VH.png
  ti-spinorbit section --system "1991 VH" --elongation 1.06 --thetadot 1.13 1.63 1.70 1.78 --orbits 1000""",
    "map": """\
  ti-spinorbit map --system "2004 DC" --grid 32 32 --orbits 300 --out dc_map.png
  ti-spinorbit map --system "2004 DC" --grid 128 128 --orbits 500 --resume   # Ctrl-C safe
  ti-spinorbit map --system "1991 VH" --grid 16 16 --model 3d                # force 3-D""",
    "overlap": """\
  ti-spinorbit overlap --system "1991 VH" --elongations 1.01 1.10 0.01 --orbits 500""",
    "libration": """\
  ti-spinorbit libration --system Didymos --orbits 100
  ti-spinorbit libration --system "2000 DP107" --elongation 1.2 --out dp107_libration.png""",
    "energy": """\
  ti-spinorbit energy                          # the paper's energy-check case ("test")
  ti-spinorbit energy --orbits 20 --rtol 1e-13 --max-drift 1e-10 --out energy.png
  ti-spinorbit energy --system "1991 VH" --thetadot 1.0 --orbits 50
  ti-spinorbit energy --system "1991 VH" --thetadot 0.8 --orbits 20 --tide secondary --time-lag 600 --strength 1e6""",
    "benchmark": """\
  ti-spinorbit benchmark --members 1024 --orbits 20
  ti-spinorbit benchmark --arch cuda --members 65536 --orbits 20 --out bench_cuda.json""",
    "warmup": """\
  ti-spinorbit warmup                                  # every variant (minutes, once)
  ti-spinorbit warmup --models planar --indicators off # what 'section' needs
  ti-spinorbit warmup --models planar --perturbed      # also with tides, YORP, BYORP""",
    "figures": """\
  ti-spinorbit figures --quick --only 1 4 --out out/""",
}
EXAMPLES = "examples:\n" + "\n".join(EXAMPLES_BY_COMMAND.values()) + "\n"


class CommandLineError(ValueError):
    """A bad command line (unknown flag, unparsable value): one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting, so every bad input ends
    the same way: one line on stderr, status 2 (``--help`` still prints and exits 0)."""

    def error(self, message):
        raise CommandLineError(f"{self.prog}: error: {message}")


def _help_epilog(command):
    return f"examples:\n{EXAMPLES_BY_COMMAND[command]}\n"


def _parser():
    from .compiling import METHODS
    from .runtime import _KNOWN_ARCHS

    p = _Parser(prog="ti-spinorbit", description=(
        "Coupled spin-orbit dynamics of binary asteroids (full two-body problem, 4th-order "
        "mutual potential), ensembles integrated with Taichi."),
        epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    debug_help = "on any error print the full traceback (for bug reports) instead of one line"
    p.add_argument("--debug", action="store_true", help=debug_help)
    # --debug before or after the subcommand; SUPPRESS keeps the top-level value when the
    # subcommand's own flag is absent
    debug = _Parser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=debug_help)
    sub = p.add_subparsers(dest="command", required=True)

    def command(name, help):
        return sub.add_parser(name, help=help, description=help, epilog=_help_epilog(name),
                              formatter_class=argparse.RawDescriptionHelpFormatter,
                              parents=[debug])

    def accuracy_flags(s):
        s.add_argument("--max-drift", type=float, default=None,
                       help="largest relative energy or angular-momentum drift of a member "
                            "counted as accurate, in (0, 1] (default: min(1e-4, 1000 x rtol "
                            "x orbits)); members above it are 'inaccurate'")
        s.add_argument("--allow-inaccurate", action="store_true",
                       help=f"exit with status 0 even when members are inaccurate (default: "
                            f"status {EXIT_INACCURATE}; they are kept in the data file either way)")

    def common(s, out_help, data=True, orbits=300.0, rtol=1e-10, model=True, resume=False):
        if orbits is not None:
            s.add_argument("--orbits", type=float, default=orbits,
                           help=f"orbits to integrate, in (0, {MAX_ORBITS:g}] (default {orbits:g})")
        s.add_argument("--rtol", type=float, default=rtol,
                       help=f"relative tolerance in [{RTOL_RANGE[0]:g}, {RTOL_RANGE[1]:g}] "
                            f"(default {rtol:g})")
        s.add_argument("--method", choices=METHODS, default="cash-karp",
                       help="Runge-Kutta pair: cash-karp (default, the paper's 4(5)), dop853 "
                            "(8(5,3): fewer steps, faster at tight tolerances) or vern9 "
                            "(Verner's 9(8): fewest steps, for the tightest tolerances)")
        s.add_argument("--arch", choices=_KNOWN_ARCHS, default=None,
                       help="Taichi arch: cpu (default, or $TI_SPINORBIT_ARCH), cuda, vulkan, "
                            "...; a missing GPU is an error, never a silent CPU fallback")
        s.add_argument("--out", default=None, help=out_help)
        if data:
            s.add_argument("--data", default=None,
                           help=".npz path (default: the --out path with .npz)")
        s.add_argument("--quiet", action="store_true",
                       help="print nothing but errors (no progress bar, no summary)")
        s.add_argument("--no-progress", action="store_true",
                       help="no progress bar (the summary and compile notices still print)")
        s.add_argument("--overwrite", action="store_true",
                       help="replace output files that already exist (refused by default, "
                            "before any work)")
        if model:
            s.add_argument("--model", choices=("auto", "planar", "3d"), default="auto",
                           help="equations of motion: the reduced planar model for planar "
                                "starts (auto, default) or the general 3-D one (3d)")
        if resume:
            s.add_argument("--checkpoint", default=None, metavar="DIR",
                           help="write a checkpoint directory after every window (default "
                                "with --resume: the --data path with .ckpt)")
            s.add_argument("--resume", action="store_true",
                           help="continue an interrupted run from its checkpoint (same "
                                "results as an uninterrupted run; starts afresh if none)")
            s.add_argument("--overwrite-checkpoint", action="store_true",
                           help="without --resume, replace a checkpoint already in the "
                                "--checkpoint directory (refused by default)")
            s.add_argument("--keep-checkpoint", action="store_true",
                           help="keep the checkpoint directory after a successful run "
                                "(default: removed once the outputs are written)")

    def coordinates_flag(s):
        s.add_argument("--coordinates", choices=("inertial", "apsidal"), default="inertial",
                       help="spin coordinate θ̇_p/n of the starts and results: inertial (the "
                            "inertial spin rate, default) or apsidal (the paper's: spin rate "
                            "minus the apsidal precession rate; needs e >= 0.001); "
                            "docs/physics.md §6.7")

    def tilt_flags(s):
        s.add_argument("--tilt", type=float, nargs=3, default=None,
                       metavar=("ROLL", "PITCH", "YAW"),
                       help="tilt every start out of the plane: the secondary turned by these "
                            "angles (deg, each in [-360, 360]) about the orbit frame's radial, "
                            "along-track and normal axes (docs/physics.md §6.8; 3-D model)")
        s.add_argument("--spin-xy", type=float, nargs=2, default=None, metavar=("SX", "SY"),
                       help="off-axis spin of the secondary in its body frame, units of n")
        s.add_argument("--inclination", type=float, default=None,
                       help="inclination of the mutual orbit to the primary's equator, deg")

    def perturbation_flags(s):
        g = s.add_argument_group("tides, YORP and BYORP in the equations (docs/physics.md §13)")
        g.add_argument("--tide", choices=("primary", "secondary"), default=None,
                       help="constant-time-lag (--time-lag) or constant-Q (--Q, default Q = "
                            "100) tide raised on this body by the other")
        g.add_argument("--k2", type=float, default=None,
                       help="Love number of the --tide body, in [1e-12, 10] (default: the "
                            "rubble-pile k2 = 1e-5 R[km])")
        g.add_argument("--time-lag", type=float, default=None, metavar="S",
                       help="constant tidal time lag, s, in [1e-9, 1e9] (or --Q)")
        g.add_argument("--Q", type=float, default=None,
                       help="constant tidal quality factor, in [0.001, 1e12] (default 100)")
        g.add_argument("--yorp", type=float, default=None, metavar="F_Y",
                       help="YORP coefficient f_Y in [-1, 1] (the paper's 5e-4; > 0 spins up) "
                            "on --yorp-body")
        g.add_argument("--yorp-body", choices=("primary", "secondary"), default="secondary",
                       help="the body --yorp acts on (default secondary)")
        g.add_argument("--yorp-convention", choices=tuple(_pert.YORP_CONVENTIONS),
                       default=_pert.YORP_CONVENTION,
                       help="which torque f_Y stands for: 'paper' (default; f_Y R^3 L/(6 c d^2 "
                            "sqrt(1-e^2)), the paper's energy per orbit over two rotations) or "
                            "'one-turn' (twice that; docs/physics.md §13.2)")
        g.add_argument("--byorp", type=float, default=None, metavar="B",
                       help="BYORP coefficient B in [-1, 1] (> 0 expands the orbit)")
        for kind, whose in (("tide", "the --tide body"), ("yorp", "the --yorp-body"),
                            ("byorp", "the secondary, for --byorp")):
            g.add_argument(f"--{kind}-radius", type=float, default=None, metavar="M",
                           help=f"radius of {whose}, m, in [{_pert.RADIUS_RANGE[0]:g}, "
                                f"{_pert.RADIUS_RANGE[1]:g}] (default its "
                                "volume-equivalent radius (abc)^(1/3); needed when a "
                                "--system file gives the body by its inertia integrals)")
        g.add_argument("--strength", type=float, default=1.0,
                       help="factor on every perturbation's force and torque, in [1e-12, "
                            "1e15] (default 1; 1e6 makes a million years act in one)")
        g.add_argument("--heliocentric", type=float, nargs=2, default=None,
                       metavar=("A_AU", "E"),
                       help="the binary's heliocentric orbit for --yorp/--byorp: a in AU in "
                            "[0.05, 1e4] and e in [0, 1) (default: the catalogued one)")

    def system_flags(s, default="1991 VH", shape=True):
        s.add_argument("--system", default=default,
                       help=f"catalogued system name (default: {default}; see 'ti-spinorbit "
                            "systems') or a .json file of your own system, as written by "
                            "'ti-spinorbit systems --show NAME --out PATH' (then --elongation "
                            "and --density are refused: edit the file; --eccentricity applies)")
        if shape:
            s.add_argument("--elongation", type=float,
                           help=f"secondary a/b in [1, {MAX_ELONGATION:g}] (default: catalogue value)")
            s.add_argument("--density", type=float,
                           help=f"secondary density, kg/m^3, in [{MIN_DENSITY:g}, {MAX_DENSITY:g}] (default: catalogue value)")
        s.add_argument("--eccentricity", type=float,
                       help="initial osculating eccentricity in [0, 1) (default: catalogue value)")

    s = sub.add_parser("systems", help="list catalogued systems or show one", parents=[debug],
                       description="List the catalogued systems (Naidu & Margot 2015, Table 1).",
                       epilog=_help_epilog("systems"),
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("--show", metavar="NAME", help="print one system's parameters (a "
                                                   "catalogued name, or a .json system file)")
    s.add_argument("--out", default=None, help="also write the descriptions (SI) to this .json")
    s.add_argument("--quiet", action="store_true", help="print nothing (with --out)")

    s = command("section", "surface of section of a catalogued system (PNG + .npz)")
    system_flags(s)
    s.add_argument("--theta-p", type=float, default=0.0,
                   help="initial θ_p, deg, in [-360, 360] (default 0)")
    s.add_argument("--thetadot", type=float, nargs="+",
                   help="initial θ̇_p/n values (default: the paper's starts for this system)")
    tilt_flags(s)
    common(s, "PNG path (default sos_<system>.png)", orbits=500.0, rtol=1e-12, resume=True)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)

    s = command("map", "chaos map over (θ_p, θ̇_p/n): MEGNO, Lyapunov, classes (PNG + .npz)")
    system_flags(s)
    s.add_argument("--grid", type=int, nargs=2, default=[32, 32], metavar=("NTHETA", "NTHETADOT"),
                   help=f"grid size, each in [1, {MAX_GRID}] (default 32 32)")
    s.add_argument("--thetadot-range", type=float, nargs=2, default=[0.2, 3.0],
                   metavar=("LO", "HI"), help="θ̇_p/n range, LO < HI (default 0.2 3.0)")
    s.add_argument("--indicator-space", choices=("planar", "full"), default="planar",
                   help="shadow direction of MEGNO: planar-restricted (default) or the full "
                        "state, attitudes included (the 3-D model runs; docs/physics.md §10.4)")
    common(s, "PNG path (default map_<system>.png)", resume=True)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)

    s = command("overlap", "resonance-overlap scan over a/b, 1:1 and 3:2 (PNG + .npz)")
    system_flags(s, shape=False)
    s.add_argument("--elongations", type=float, nargs=3, default=[1.01, 1.15, 0.01],
                   metavar=("START", "STOP", "STEP"),
                   help=f"a/b scan, 1 < START <= STOP <= {MAX_ELONGATION:g}, STEP > 0 "
                        "(default 1.01 1.15 0.01)")
    s.add_argument("--max-orbits", type=float, default=None,
                   help="cap of the length doubling (--orbits, 2x, 4x, ...) that checks the "
                        "decisions converge, in [--orbits, 1e7] (default 4 x --orbits)")
    common(s, "PNG path (default overlap_<system>.png)")
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)

    s = command("libration", "relaxed libration amplitude at the synchronous island centre "
                "(PNG + .npz)")
    system_flags(s, default="Didymos")
    s.add_argument("--xtol", type=float, default=1e-6,
                   help="stop the centre search when the window half-width (units of n) is "
                        "below this, in [1e-12, 0.1] (default 1e-6)")
    s.add_argument("--candidates", type=float, nargs=3, metavar=("LO", "HI", "N"),
                   help="coarse bracket of θ̇_p/n: N (5 to 10001) values over LO..HI "
                        "(default 45 over 0.2..1.3)")
    s.add_argument("--max-orbits", type=float, default=None,
                   help="cap of the length doubling that checks the centre and amplitude "
                        "converge, in [--orbits, 1e7] (default 4 x --orbits)")
    common(s, "PNG path of the centre search, extent vs θ̇_p/n (default libration_<system>.png)",
           orbits=100.0, rtol=1e-12, model=False)
    perturbation_flags(s)
    accuracy_flags(s)
    coordinates_flag(s)

    s = command("energy", "energy and angular-momentum conservation check (PNG + .npz; "
                "exit status 1 when the drift exceeds --max-drift)")
    system_flags(s, default="test")
    s.add_argument("--theta-p", type=float, default=0.0,
                   help="initial θ_p, deg, in [-360, 360] (default 0)")
    s.add_argument("--thetadot", type=float, default=None,
                   help="initial θ̇_p/n (default: the catalogued spin period, else 1)")
    s.add_argument("--samples-per-orbit", type=int, default=None,
                   help=f"samples per orbit in [1, 100000] (default: {SAMPLES_PER_PRIMARY_ROTATION} "
                        f"per primary rotation, at least {MIN_SAMPLES_PER_ORBIT})")
    s.add_argument("--max-drift", type=float, default=1e-9,
                   help="largest relative energy or angular-momentum drift that passes, "
                        "in (0, 1] (default 1e-9)")
    common(s, "PNG path of drift vs time (default energy_<system>.png)", orbits=5.0, rtol=1e-12,
           resume=True)
    perturbation_flags(s)

    s = command("benchmark", "ensemble throughput in member-orbits/s on 1991 VH (JSON)")
    s.add_argument("--system", default="1991 VH", help="catalogued system (default 1991 VH)")
    s.add_argument("--members", type=int, default=256,
                   help=f"ensemble size in [1, {MAX_MEMBERS}] (default 256)")
    s.add_argument("--repeat", type=int, default=1,
                   help="timed runs, the best is reported, in [1, 100] (default 1)")
    common(s, "JSON path (default benchmark.json)", data=False, orbits=20.0, rtol=1e-12)

    s = command("warmup", "compile kernel variants ahead of time, so later runs start at once")
    s.add_argument("--models", nargs="+", choices=("planar", "3d"), default=["planar", "3d"],
                   help="equations of motion to compile for (default both)")
    s.add_argument("--indicators", nargs="+", choices=("off", "on"), default=["off", "on"],
                   help="without (sections, libration) and/or with chaos indicators (map, "
                        "overlap) (default both)")
    s.add_argument("--sampling", nargs="+", choices=("off", "on"), default=["off", "on"],
                   help="without (sections) and/or with dense sampling (energy, libration) "
                        "(default both)")
    s.add_argument("--methods", nargs="+", default=["cash-karp"],
                   help="integration methods: cash-karp (default), dop853, vern9 (one or more)")
    s.add_argument("--perturbed", action="store_true",
                   help="also compile the variants with tides, YORP and BYORP in the "
                        "equations (--tide, --yorp, --byorp of the other commands)")
    s.add_argument("--arch", choices=_KNOWN_ARCHS, default=None,
                   help="Taichi arch (default cpu, or $TI_SPINORBIT_ARCH)")
    s.add_argument("--quiet", action="store_true", help="print nothing but errors")

    s = sub.add_parser("figures", help="reproduce the paper's studies (experiments/study*.py)",
                       parents=[debug],
                       epilog=_help_epilog("figures"),
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("--quick", action="store_true", help="small runs (minutes in all)")
    s.add_argument("--out", default="out", help="output folder (default out/)")
    s.add_argument("--only", nargs="+", metavar="N", type=int, help="study numbers, e.g. 4 6")
    s.add_argument("--experiments", default=None,
                   help="folder holding the study scripts (default: ./experiments or the "
                        "checkout this package was installed from)")
    s.add_argument("--arch", choices=_KNOWN_ARCHS, default=None,
                   help="Taichi arch for the scripts (sets TI_SPINORBIT_ARCH)")
    s.add_argument("--quiet", action="store_true", help="hide the scripts' output; print failures only")
    return p


# ---- flag checks ------------------------------------------------------------------------

def _fmt(x):
    """Integers as they are (1048576), other numbers short (1e+07, 0.01, nan)."""
    return str(x) if isinstance(x, int) and not isinstance(x, bool) else f"{x:g}"


def _interval(low, high, low_open, high_open):
    return f"{'(' if low_open else '['}{_fmt(low)}, {_fmt(high)}{')' if high_open else ']'}"


def _check_range(flag, value, low, high, low_open=False, high_open=False):
    """ValueError naming the flag, the value and the interval unless value lies in it."""
    ok = math.isfinite(value)
    ok = ok and (value > low if low_open else value >= low)
    ok = ok and (value < high if high_open else value <= high)
    if not ok:
        raise ValueError(f"{flag} must lie in {_interval(low, high, low_open, high_open)} "
                         f"(got {_fmt(value)})")


def _check_output(flag, path, extensions):
    """The output file must be writable where it is asked for, with one of our extensions:
    a typo, a folder, a read-only file, a dangling symbolic link, control characters or a
    name longer than the folder allows (:func:`ti_spinorbit.files.check_name`) must fail
    before a long run, not after it. Probes by opening (an existing file for appending, which
    changes nothing, and always a temporary file beside it, where the atomic write will put
    its bytes), because permission bits do not tell for root or read-only mounts."""
    import tempfile

    from .files import check_name, target

    if path is None:
        return
    ext = os.path.splitext(path)[1].lower()
    if ext not in extensions:
        raise ValueError(f"{flag} must end in {', '.join(extensions)} (got {path!r})")
    check_name(flag, path)
    if os.path.isdir(path):
        raise ValueError(f"{flag}: {path!r} is a folder; give a file name")
    folder = os.path.dirname(os.path.abspath(target(path)))
    if not os.path.isdir(folder):
        raise ValueError(f"{flag}: folder {folder!r} does not exist (got {path!r})")
    try:
        if os.path.exists(path):
            with open(path, "ab"):
                pass
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        what = "file" if os.path.exists(path) else "folder"
        raise ValueError(f"{flag}: cannot write {path!r} ({what} not writable: "
                         f"{exc.strerror or exc})") from None


def _has_display():
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _choose_backend():
    """The command line only writes figures to files: without a display it uses Matplotlib's
    file backend (Agg) unless a file backend is already chosen. Only the command line does
    this; the library leaves the session's backend alone."""
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg") and not _has_display():
        matplotlib.use("Agg")


def _check_plotting():
    """Matplotlib must load with the environment's backend before a run whose figure would
    otherwise fail at the end (an invalid MPLBACKEND raises at import)."""
    try:
        from .plotting import _pyplot

        _choose_backend()
        _pyplot()
    except Exception as exc:  # noqa: BLE001 - any failure here would lose the figure later
        backend = os.environ.get("MPLBACKEND")
        if backend:
            raise ValueError(f"MPLBACKEND={backend!r} is not a Matplotlib backend that works "
                             "here; unset it or set MPLBACKEND=Agg") from None
        raise ValueError(f"Matplotlib cannot start ({_one_line(exc)[:200]})") from None


def check_args(args):
    """Check every flag of a parsed command line; ValueError with flag, value and range.

    FLAG_RANGES covers the plain numeric flags of every subcommand (a flag is checked
    wherever it exists; each value of a multi-value flag); relations between values and the
    output paths follow."""
    for dest, (flag, low, high, low_open, high_open) in FLAG_RANGES.items():
        value = getattr(args, dest, None)
        for v in (value if isinstance(value, list) else [] if value is None else [value]):
            _check_range(flag, v, low, high, low_open, high_open)
    if getattr(args, "max_orbits", None) is not None and args.max_orbits < args.orbits:
        raise ValueError(f"--max-orbits must lie in [--orbits, {MAX_ORBITS:g}] = "
                         f"[{args.orbits:g}, {MAX_ORBITS:g}] (got {args.max_orbits:g})")
    if getattr(args, "thetadot_range", None):
        lo, hi = args.thetadot_range
        if not hi > lo:
            raise ValueError(f"--thetadot-range needs LO < HI (got {lo:g} {hi:g})")
    if getattr(args, "elongations", None):
        start, stop, step = args.elongations
        _check_range("--elongations START", start, 1.0, MAX_ELONGATION, low_open=True)
        _check_range("--elongations STOP", stop, start, MAX_ELONGATION)
        _check_range("--elongations STEP", step, MIN_ELONGATION_STEP, MAX_ELONGATION)
        if (stop - start) / step + 1 > MAX_SCAN_STEPS:
            raise ValueError(f"--elongations: at most {MAX_SCAN_STEPS} elongations per scan "
                             f"(got {start:g} {stop:g} {step:g}); use a larger STEP")
        import numpy as np

        scan = np.round(np.arange(start, stop + step / 2, step), 10)      # as _cmd_overlap
        if scan.size and scan.max() > MAX_ELONGATION:
            raise ValueError(f"--elongations {start:g} {stop:g} {step:g} steps to a/b = "
                             f"{scan.max():g}, past {MAX_ELONGATION:g}: lower STOP or change STEP")
    if getattr(args, "candidates", None):
        lo, hi, n = args.candidates
        _check_range("--candidates LO", lo, -MAX_SPIN, MAX_SPIN)
        _check_range("--candidates HI", hi, lo, MAX_SPIN, low_open=True)
        if not (float(n).is_integer() and 5 <= n <= 10001):
            raise ValueError(f"--candidates N must be an integer in [5, 10001] (got {n:g})")
    _check_system_flags(args)
    _check_perturbation_flags(args)
    if args.command == "warmup":
        from .compiling import METHODS

        bad = [m for m in args.methods if m not in METHODS]
        if bad:
            raise ValueError(f"--methods must be among {', '.join(METHODS)} (got {bad[0]!r})")
    elif args.command in ("benchmark", "systems"):
        _check_output("--out", getattr(args, "out", None), (".json",))
        if args.command == "benchmark":
            flag = "--out" if args.out else "the report (default --out)"
            _claim_outputs(args, [(flag, args.out or "benchmark.json")])
            _refuse_existing(args, args.out or "benchmark.json", flag)
    elif args.command == "figures":                  # figures: --out is a folder
        if os.path.exists(args.out) and not os.path.isdir(args.out):
            raise ValueError(f"--out: {args.out!r} is a file; give a folder")
    else:
        _check_output("--out", args.out, FIGURE_EXTENSIONS)
        _check_output("--data", args.data, (".npz",))
        _check_plotting()


def _check_system_flags(args):
    """Build the catalogued system the flags ask for (cheap: no integration), so that a value
    inside its flag's range that the system still refuses (an unknown --system, an
    --elongation making b < c, an --eccentricity making the bodies touch at pericentre)
    fails before any work, naming the flag rather than the library's argument."""
    import re

    from . import catalog

    name = args.show if args.command == "systems" else getattr(args, "system", None)
    if name is None or args.command == "figures":
        return
    flag = "--show" if args.command == "systems" else "--system"
    if flag == "--show" and _is_system_file(name):
        _read_system_file(name, flag)
        return
    if flag == "--system" and _is_system_file(name):
        system = _file_system(args)
        _check_derived(args, system)
        return
    try:
        catalog.entry(name)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{flag}: {_one_line(exc)}") from None
    shape_flag = "--elongations" if args.command == "overlap" else "--elongation"
    flags = {"elongation": shape_flag, "secondary_density": "--density",
             "eccentricity": "--eccentricity"}
    elongation = getattr(args, "elongation", None)
    if getattr(args, "elongations", None):
        import numpy as np

        start, stop, step = args.elongations
        scan = np.round(np.arange(start, stop + step / 2, step), 10)      # as _cmd_overlap
        elongation = float(scan.max()) if scan.size else None   # the most elongated is the worst
    given = {"elongation": elongation, "secondary_density": getattr(args, "density", None),
             "eccentricity": getattr(args, "eccentricity", None)}
    try:
        system = catalog.system(name, **given)
    except (TypeError, ValueError) as exc:
        message = re.sub(r"^(elongation|secondary_density|eccentricity)\b",
                         lambda m: flags[m.group(1)], _one_line(exc))
        if not message.startswith("--"):      # blame the first flag that changed the system
            culprit = next((flags[k] for k, v in given.items() if v is not None), flag)
            message = f"{culprit}: {message}"
        raise ValueError(message) from None
    _check_derived(args, system)


def _perturbations(args):
    """The Tides / YORP / BYORP objects the flags ask for (a list, empty without them)."""
    from .perturbations import BYORP, YORP, Tides

    if not hasattr(args, "tide"):
        return []
    sun = {} if args.heliocentric is None else {"heliocentric_a_au": args.heliocentric[0],
                                                "heliocentric_e": args.heliocentric[1]}
    out = []
    if args.tide is not None:
        out.append(Tides(body=args.tide, k2=args.k2, time_lag=args.time_lag, Q=args.Q,
                         radius=args.tide_radius, strength=args.strength))
    if args.yorp is not None:
        out.append(YORP(body=args.yorp_body, coefficient=args.yorp, radius=args.yorp_radius,
                        strength=args.strength, convention=args.yorp_convention, **sun))
    if args.byorp is not None:
        out.append(BYORP(coefficient=args.byorp, radius=args.byorp_radius,
                         strength=args.strength, **sun))
    return out


def _check_perturbation_flags(args):
    """Relations between the perturbation flags, and that the system can carry them (a
    catalogued heliocentric orbit or --heliocentric for YORP / BYORP), before any work; the
    ranges of the single values are in FLAG_RANGES."""
    if not hasattr(args, "tide"):
        return
    if args.tide is None:
        for dest, flag in (("k2", "--k2"), ("time_lag", "--time-lag"), ("Q", "--Q"),
                           ("tide_radius", "--tide-radius")):
            if getattr(args, dest) is not None:
                raise ValueError(f"{flag} needs --tide primary|secondary (the body that deforms)")
    for kind in ("yorp", "byorp"):
        if getattr(args, f"{kind}_radius") is not None and getattr(args, kind) is None:
            raise ValueError(f"--{kind}-radius needs --{kind} (the {kind.upper()} coefficient)")
    if args.time_lag is not None and args.Q is not None:
        raise ValueError("--time-lag and --Q exclude each other: the tide has a constant time "
                         "lag or a constant Q, give one")
    if args.yorp is None and args.yorp_body != "secondary":
        raise ValueError("--yorp-body needs --yorp F_Y (the YORP coefficient, in [-1, 1])")
    if args.yorp is None and args.yorp_convention != _pert.YORP_CONVENTION:
        raise ValueError("--yorp-convention needs --yorp F_Y (the YORP coefficient, in [-1, 1])")
    if args.heliocentric is not None:
        a_au, e = args.heliocentric
        _check_range("--heliocentric A_AU", a_au, *HELIOCENTRIC_A_RANGE)
        _check_range("--heliocentric E", e, 0.0, 1.0, high_open=True)
        if args.yorp is None and args.byorp is None:
            raise ValueError("--heliocentric needs --yorp or --byorp (only they use the "
                             "heliocentric orbit)")
    items = _perturbations(args)
    if not items:
        if args.strength != 1.0:
            raise ValueError("--strength needs --tide, --yorp or --byorp (it scales them)")
        return
    if args.command == "overlap":
        from . import catalog
        system = catalog.system(args.system, eccentricity=args.eccentricity)
    else:
        system = _system(args)
    for p in items:
        flag = {"tides": "--tide", "yorp": "--yorp", "byorp": "--byorp"}[p.kind]
        try:
            p.block(system)
        except ValueError as exc:
            text = _one_line(exc).replace("pass heliocentric_a_au (AU) and heliocentric_e to "
                                          "YORP / BYORP, or give the system "
                                          "heliocentric_orbit=(a_AU, e)",
                                          "pass --heliocentric A_AU E, or give the system "
                                          "file heliocentric_a_au and heliocentric_e")
            text = text.replace("pass radius= (m) to the perturbation", f"give {flag}-radius M")
            raise ValueError(f"{flag}: {text}") from None


def perturbation_summary(items, system=None):
    """One line naming the perturbations of a run (their SI parameters and the strength),
    "" without any."""
    parts = []
    for p in items:
        if p.kind == "tides":
            k2 = p.k2 if p.k2 is not None or system is None else p.love_number(system)
            lag = f"time lag {p.time_lag:g} s" if p.time_lag is not None else \
                f"Q {_pert.DEFAULT_Q if p.Q is None else p.Q:g}"
            rubble = " (rubble pile)" if p.k2 is None else ""
            parts.append(f"tide on the {p.body} (k2 {k2:.3g}{rubble}, {lag})")
        elif p.kind == "yorp":
            parts.append(f"YORP on the {p.body} (f_Y {p.coefficient:g}, {p.convention} torque)")
        else:
            parts.append(f"BYORP (B {p.coefficient:g})")
    if not parts:
        return ""
    strengths = sorted({p.strength for p in items})
    scale = ", ".join(f"{x:g}" for x in strengths)
    return (f"perturbations: {'; '.join(parts)}; strength {scale} (docs/physics.md §13; "
            "drifts are those of E - W and L - L_ext)")


def _check_derived(args, system):
    """Checks of the built system that the catalogue and a --system file share."""
    from .coordinates import APSIDAL_MIN_ECCENTRICITY

    if getattr(args, "coordinates", None) == "apsidal" and system.e < APSIDAL_MIN_ECCENTRICITY:
        raise ValueError(f"--coordinates apsidal needs an eccentricity >= "
                         f"{APSIDAL_MIN_ECCENTRICITY:g} ({system.name} has e = {system.e:g}): "
                         "use --coordinates inertial or a larger --eccentricity")
    if args.command == "libration" and not system.omega0 > 0:
        raise ValueError(f"--elongation must be > 1 for libration: a round secondary has no "
                         f"synchronous island (got {args.elongation:g})")


# ---- shared steps -----------------------------------------------------------------------

def _init(args):
    """Start Taichi on --arch; with --quiet, Taichi's own "Starting on arch" line is hidden."""
    import contextlib
    import io

    from . import init

    if not args.quiet:
        return init(arch=args.arch)
    # Taichi decides at import whether stdout is "a graphical shell" (sys.stdout is not
    # sys.__stdout__) and then logs a line and wraps printing: import it before redirecting
    import taichi  # noqa: F401  (its banner is off in the command, see runtime.py)

    with contextlib.redirect_stdout(io.StringIO()):
        return init(arch=args.arch)


def _is_system_file(value):
    """--system names a file (rather than a catalogued system) when it ends in .json."""
    return isinstance(value, str) and value.lower().endswith(".json")


def _file_system(args):
    """The BinarySystem of a --system .json (BinarySystem.describe() output, as written by
    'ti-spinorbit systems --show NAME --out PATH', or the one-item list 'systems --out'
    writes), with --eccentricity applied; read by BinarySystem.from_file's rules (unknown
    keys and derived entries that disagree with the inputs are refused). --elongation and
    --density are refused: they rebuild a catalogued secondary by the catalogue's
    prescription (docs/physics.md §7), which a file of your own system does not follow."""
    import dataclasses

    path = args.system
    for dest, flag in (("elongation", "--elongation"), ("density", "--density")):
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{flag} applies only to a catalogued --system (the catalogue's "
                             f"secondary prescription); for the file {path!r} edit the "
                             "secondary's semi_axes_m/mass_kg in it instead")
    if getattr(args, "elongations", None) is not None:
        raise ValueError(f"--system: overlap scans the catalogue's elongation prescription, so "
                         f"it needs a catalogued system name (got the file {path!r})")
    system = _read_system_file(path, "--system")
    e = getattr(args, "eccentricity", None)
    if e is not None and e != system.e:
        contact = system.primary.bounding_radius + system.secondary.bounding_radius
        if not system.a * (1.0 - e) > contact:
            raise ValueError(f"--eccentricity must lie in [0, {1.0 - contact / system.a:.4g}) "
                             f"for {system.name}: at {e:g} the bodies overlap at pericentre")
        scale = system.density_scale
        system = dataclasses.replace(system, e=float(e))
        object.__setattr__(system, "density_scale", scale)    # not an __init__ argument
    return system


def _read_system_file(path, flag):
    """BinarySystem.from_file for the command line: every error one line naming ``flag``
    (--system, --show) and the file."""
    from .systems import read_system_file

    try:
        return read_system_file(path, flag)
    except FileNotFoundError as exc:
        raise ValueError(f"{exc} (a catalogued name, or a .json written by 'ti-spinorbit "
                         "systems --show NAME --out PATH')") from None


def _catalogue_name(system):
    """The catalogue key of a system loaded from a file when its name is one, else None
    (its defaults, e.g. the section starts, then follow the catalogue)."""
    from . import catalog

    try:
        return catalog._resolve(system.name)
    except (TypeError, ValueError):
        return None


def _system(args):
    from . import catalog

    if _is_system_file(args.system):
        return _file_system(args)
    return catalog.system(args.system, elongation=getattr(args, "elongation", None),
                          secondary_density=getattr(args, "density", None),
                          eccentricity=getattr(args, "eccentricity", None))


#: Physics flags named in default file names, in this order, when they differ from their
#: default: (dest, tag). The value follows the tag: ab1.06 (--elongation 1.06), rho2500,
#: e0.1, tp30 (--theta-p), td1.13-1.63 (--thetadot; over three values: first-last n count),
#: g64x64 (--grid), tdr0.5-2 (--thetadot-range), ab1.01-1.1-0.01 (--elongations), cand0.2-1.3-45
#: (--candidates), xtol1e-8, spo128 (--samples-per-orbit), o1000 (--orbits), maxo8000
#: (--max-orbits), rtol1e-13, tilt5-0-0, sxy0-0.1, inc10; --model, --coordinates, --method and
#: --indicator-space by their value alone (3d, apsidal, dop853, full); tides, YORP and BYORP:
#: tide-secondary (--tide), k2 (--k2), dt600 (--time-lag), Q100 (--Q), yorp0.0005 (--yorp),
#: yorp-primary (--yorp-body), yorp-one-turn (--yorp-convention), byorp1e-3, str1e6
#: (--strength), helio1.1-0.2 (--heliocentric),
#: Rtide150 (--tide-radius; Ryorp, Rbyorp likewise).
#: --max-drift, --arch and output flags change no physics: not named.
NAME_TAGS = (("elongation", "ab"), ("density", "rho"), ("eccentricity", "e"),
             ("elongations", "ab"), ("theta_p", "tp"), ("thetadot", "td"), ("grid", "g"),
             ("thetadot_range", "tdr"), ("candidates", "cand"), ("xtol", "xtol"),
             ("samples_per_orbit", "spo"), ("orbits", "o"), ("max_orbits", "maxo"),
             ("rtol", "rtol"), ("model", ""), ("coordinates", ""), ("method", ""),
             ("tilt", "tilt"), ("spin_xy", "sxy"), ("inclination", "inc"),
             ("indicator_space", ""), ("tide", "tide-"), ("k2", "k2"), ("time_lag", "dt"),
             ("Q", "Q"), ("yorp", "yorp"), ("yorp_body", "yorp-"),
             ("yorp_convention", "yorp-"), ("byorp", "byorp"),
             ("strength", "str"), ("heliocentric", "helio"), ("tide_radius", "Rtide"),
             ("yorp_radius", "Ryorp"), ("byorp_radius", "Rbyorp"))


def default_stem(args, prefix, system_name):
    """Default output name without extension: ``<prefix>_<system>`` and one ``_<tag><value>``
    per physics flag that differs from its default (:data:`NAME_TAGS`), so that runs with
    other parameters never share a file: ``sos_1991VH_ab1.06_o1000``."""
    import re

    from .files import safe_part

    defaults = vars(_parser().parse_args([args.command]))
    # a system's name (a system file's included) is made safe for a file name: no folder
    # separators, control characters or newlines ("sub/evil" -> "sub-evil")
    parts = [prefix, safe_part(system_name)]
    for dest, tag in NAME_TAGS:
        value = getattr(args, dest, None)
        if value is None or value == defaults.get(dest):
            continue
        if isinstance(value, (list, tuple)):
            items = [_fmt(v) for v in value]
            if dest == "grid":
                text = "x".join(items)
            elif len(items) > 3:
                text = f"{items[0]}-{items[-1]}n{len(items)}"
            else:
                text = "-".join(items)
        elif dest in ("rtol", "xtol"):               # tolerances always as powers: 1e-4
            mantissa, exponent = f"{value:.15e}".split("e")
            text = f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
        else:
            text = _fmt(value) if isinstance(value, (int, float)) else str(value)
        # exponents short and without "+": 1e6, 1e-13 (not 1e+06, 1e-13 stays)
        text = re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", text)
        parts.append(safe_part(tag + text, tidy=False))
    return "_".join(parts)


def _refuse_existing(args, path, flag):
    """A run never overwrites an existing output unless --overwrite: refused before any work,
    one line naming the file and the flag."""
    if not getattr(args, "overwrite", False) and os.path.exists(path):
        raise ValueError(f"{flag}: {path!r} already exists (an earlier run's output?); pass "
                         "--overwrite to replace it, or choose another --out")


#: The output names this process's running command owns (files.Claim), freed when it ends.
_CLAIMS = []


def _claim_outputs(args, outputs):
    """Own the output names of this run (:func:`ti_spinorbit.files.claim`: a lock beside each
    one, held until the command ends): a second run with the same names, started while this
    one goes, is refused at once in one line (exit status 2) instead of silently replacing
    this run's files."""
    from .files import claim

    _CLAIMS.append(claim(outputs, command=getattr(args, "command_line", None)))


def _release_outputs():
    """Free the output names of the command that ends (its lock files are deleted)."""
    while _CLAIMS:
        _CLAIMS.pop().release()


def _finishes_a_run(args, out, data, checkpoint):
    """True when this ``--resume`` command finishes an earlier run of the same command that
    was killed after writing its data file and before its figure: the data file exists, the
    figure does not, the checkpoint is still there and the data file records this very
    command line. The run then resumes from its checkpoint (nothing is integrated again),
    and rewrites the data file (the same numbers) and the figure, instead of being refused."""
    from .checkpoint import holds_checkpoint
    from .io import read_metadata

    if not getattr(args, "resume", False) or checkpoint is None or os.path.exists(out) \
            or not os.path.isfile(data) or not os.path.isdir(checkpoint) \
            or not holds_checkpoint(checkpoint):
        return False
    try:
        meta = read_metadata(data)
    except (OSError, ValueError):
        return False
    return meta.get("command") == getattr(args, "command_line", None)


def _paths(args, prefix, system_name):
    """(figure path, data path) from --out/--data or the defaults :func:`default_stem`.png
    /.npz, both checked writable (defaults included; names that fit, no dangling links),
    claimed for this run (:func:`_claim_outputs`) and then not already there (unless
    --overwrite, or this --resume finishes the same command's run: :func:`_finishes_a_run`),
    and the checkpoint directory checked, before any work."""
    from .files import check_name

    out = args.out or default_stem(args, prefix, system_name) + ".png"
    data = args.data or os.path.splitext(out)[0] + ".npz"
    out_flag = "--out" if args.out else "the figure (default --out)"
    data_flag = "--data" if args.data else "the data file (default --data)"
    _check_output(out_flag, out, FIGURE_EXTENSIONS)
    _check_output(data_flag, data, (".npz",))
    checkpoint = _checkpoint_path(args, data)
    if checkpoint is not None:
        check_name("--checkpoint" if getattr(args, "checkpoint", None) is not None else
                   "the checkpoint (default: the --data path with .ckpt)", checkpoint)
    _claim_outputs(args, [(out_flag, out), (data_flag, data)])     # before the checks below
    _refuse_existing(args, out, out_flag)
    if not _finishes_a_run(args, out, data, checkpoint):
        _refuse_existing(args, data, data_flag)
    if checkpoint is not None:   # a checkpoint that would be refused: before any work
        from .checkpoint import check_target

        check_target(checkpoint, args.resume, args.overwrite_checkpoint, cli=True)
    return out, data


def _progress(args):
    """The command's reporter: a bar (terminal) or a line per 10 % (log) on stderr, compile
    announcements; nothing with --quiet, no bar with --no-progress."""
    from .progress import DELAY_S, Progress

    return Progress(args.command, enabled=not args.quiet, delay=DELAY_S,
                    bar=not getattr(args, "no_progress", False))


def _with_progress(func, bar):
    """``{"progress": bar}`` where ``func`` takes a progress callback, else nothing."""
    import inspect

    return {"progress": bar} if "progress" in inspect.signature(func).parameters else {}


def _checkpoint_path(args, data):
    """The checkpoint directory of a run (--checkpoint; with --resume alone the data path with
    .ckpt), or None for commands and runs without one."""
    if getattr(args, "checkpoint", None) is not None:
        return args.checkpoint
    if getattr(args, "resume", False):
        return os.path.splitext(data)[0] + ".ckpt"
    return None


def _run_flags(args, data):
    """model, checkpoint and resume keywords from the flags (the directory was checked by
    :func:`_paths` before any work)."""
    return {"model": args.model, "method": args.method, "checkpoint": _checkpoint_path(args, data),
            "resume": args.resume, "overwrite_checkpoint": args.overwrite_checkpoint}


def _announce_perturbations(args, system):
    """The perturbations of the flags (a list), their one-line summary printed first."""
    items = _perturbations(args)
    if items:
        _print(args, perturbation_summary(items, system))
    return items


def _finish_checkpoint(args, data):
    """After a run's outputs are written: remove its checkpoint directory (the files a run
    writes there, then the directory if empty) unless --keep-checkpoint. Returns the line to
    print, or None."""
    path = _checkpoint_path(args, data)
    if path is None or not os.path.isdir(path):
        return None
    if getattr(args, "keep_checkpoint", False):
        return f"kept checkpoint {path} (--keep-checkpoint)"
    from .checkpoint import remove

    try:
        remove(path)
    except OSError as exc:       # a read-only folder: the outputs are written all the same
        return f"kept checkpoint {path} (it cannot be removed: {exc.strerror or exc})"
    return f"removed checkpoint {path} (the run is complete; --keep-checkpoint keeps it)"


def _save(result, path, extra):
    """Write a result with :func:`ti_spinorbit.io.save` (self-describing, loadable with
    ``io.load``; atomic: a killed write leaves no partial file), the command's own numbers in
    the metadata under ``extra``."""
    from .io import save

    return save(result, path, extra=extra)


class FigureError(RuntimeError):
    """The data file was written but the figure could not be (exit status 2)."""


def _write(result, data, extra, figure, out):
    """The data file first, then the figure (``figure()`` returns its Axes), each written
    atomically (:mod:`ti_spinorbit.files`): a plotting failure never loses the numbers of a
    run, and a run killed between the two is finished by the same ``--resume`` command
    (:func:`_finishes_a_run`). Returns the paths written."""
    from .plotting import save_figure

    data = _save(result, data, extra)
    try:
        save_figure(figure(), out)
    except Exception as exc:  # noqa: BLE001 - whatever Matplotlib raises, the data are safe
        raise FigureError(f"the figure {out!r} could not be written ({_one_line(exc)}); "
                          f"the data are saved in {data}") from exc
    return out, data


def _accuracy_status(args, status, energy_drift, max_drift, what="members", stop_status=None):
    """Exit status of a run by its accuracy verdict. Members whose numbers cannot be trusted,
    "inaccurate" (drift above the limit, also when the member stopped early: an escape or a
    collision reached with the conservation laws broken) and "non-finite" (NaN/Inf), and
    members stopped by their step budget, are counted on stderr (even with --quiet: it
    qualifies the results); returns EXIT_INACCURATE when there are any, unless
    --allow-inaccurate. Collisions, escapes and step underflows within the drift limit are
    outcomes of a start, reported per member, and do not change the exit status.
    ``stop_status`` (the kernels' codes) names what inaccurate members stopped for."""
    import numpy as np

    from .results import STATUS_NAMES, Status

    INACCURATE, NONFINITE, BUDGET = Status.INACCURATE, Status.NONFINITE, Status.STEP_BUDGET
    status = np.asarray(status)
    inaccurate = int(np.count_nonzero(status == INACCURATE))
    nonfinite = int(np.count_nonzero(status == NONFINITE))
    budget = int(np.count_nonzero(status == BUDGET))
    if not inaccurate and not nonfinite and not budget:
        return EXIT_OK
    allowed = getattr(args, "allow_inaccurate", False)
    parts = []
    if inaccurate:
        worst = float(np.nanmax(np.where(status == INACCURATE, energy_drift, np.nan)))
        early = ""
        if stop_status is not None:
            stops = np.asarray(stop_status).reshape(status.shape)[status == INACCURATE]
            codes, n = np.unique(stops[stops != Status.DONE], return_counts=True)
            if len(codes):
                early = " (stopped early, not trusted: " + ", ".join(
                    f"{k} {STATUS_NAMES[c]}" for c, k in zip(codes, n)) + ")"
        parts.append(f"{inaccurate} of {status.size} {what} inaccurate: conservation drift "
                     f"above {max_drift:.3g} (largest energy drift {worst:.3g}){early}")
    if budget:
        parts.append(f"{budget} of {status.size} {what} stopped by the step budget (far more "
                     "steps than their time scales need: a perturbation too strong, or a "
                     "near-contact)")
    if nonfinite:
        parts.append(f"{nonfinite} of {status.size} {what} non-finite (NaN/Inf)")
    print(f"ti-spinorbit {args.command}: {'; '.join(parts)}; kept in the data file with their "
          "status" + ("" if allowed else f"; tighten --rtol, or --allow-inaccurate to accept "
                                         f"(exit status {EXIT_INACCURATE})"), file=sys.stderr)
    return EXIT_OK if allowed else EXIT_INACCURATE


def _status_text(result, k):
    """Member k's status, with what it stopped for when the verdict overrode it
    ("inaccurate (escape)")."""
    from .results import STATUS_NAMES, Status

    name = result.status_names[k]
    stop = getattr(result, "stop_status", None)
    if stop is not None and name == "inaccurate" and int(stop[k]) != Status.DONE:
        name += f" ({STATUS_NAMES[int(stop[k])]})"
    return name


def _print(args, *lines):
    if not args.quiet:
        for line in lines:
            print(line)


# ---- subcommands ------------------------------------------------------------------------

def _body_size(body):
    """A body's size for the systems table: "R 600" for a sphere, else its semi-axes a x b x c
    (m), else its bounding radius."""
    axes = getattr(body, "semi_axes", None)
    if axes is None:
        return f"<= {body.bounding_radius:.0f}"
    if axes[0] == axes[1] == axes[2]:
        return f"R {axes[0]:.0f}"
    return " x ".join(f"{x:.0f}" for x in axes)


def _cmd_systems(args):
    import json

    from . import catalog

    if args.show:
        system = _read_system_file(args.show, "--show") if _is_system_file(args.show) \
            else catalog.system(args.show)
        if args.out:
            from .files import write_json     # atomic: a killed write leaves no partial file

            write_json(args.out, system.describe(), indent=1)
        if not args.quiet:
            for k, v in system.describe().items():
                print(f"{k:24s} {v}")
        return 0
    systems = [catalog.system(name) for name in catalog.names()]
    if args.out:
        from .files import write_json

        write_json(args.out, [s.describe() for s in systems], indent=1)
    _print(args, f"{'name':12s} {'mass ratio':>10s} {'a (m)':>8s} {'e':>7s} {'a/b':>5s} "
                 f"{'omega0':>7s} {'P_orb (h)':>9s}  {'primary (m)':>17s}  "
                 f"{'secondary semi-axes (m)':>23s}")
    for s in systems:
        ax = s.secondary.semi_axes
        _print(args, f"{s.name:12s} {s.mass_ratio:10.2f} {s.a:8.0f} {s.e:7.4f} "
                     f"{ax[0] / ax[1]:5.2f} {s.omega0:7.3f} {s.orbital_period / 3600:9.2f}  "
                     f"{_body_size(s.primary):>17s}  {_body_size(s.secondary):>23s}")
    return 0


def _cmd_section(args):
    import numpy as np

    from . import catalog, surface_of_section
    from .plotting import plot_section

    system = _system(args)
    known = _catalogue_name(system)
    starts = args.thetadot or (catalog.section_starts(known) if known else
                               list(catalog.DEFAULT_SECTION_STARTS))
    tilted = args.tilt is not None or args.spin_xy is not None or args.inclination is not None
    if tilted and args.coordinates != "inertial":
        raise ValueError("--tilt, --spin-xy and --inclination need --coordinates inertial (the "
                         "apsidal coordinates are defined for planar starts)")
    out, data = _paths(args, "sos", system.name)
    _init(args)
    perturbations = _announce_perturbations(args, system)
    if tilted:                     # explicit 3-D starts (docs/physics.md §6.8)
        roll, pitch, yaw = args.tilt or (0.0, 0.0, 0.0)
        sx, sy = args.spin_xy or (0.0, 0.0)
        starts_kw = {"initial_states": [system.tilted_start(
            args.theta_p, v, roll=roll, pitch=pitch, yaw=yaw, spin_x=sx, spin_y=sy,
            inclination=args.inclination or 0.0) for v in starts]}
    else:
        starts_kw = {"theta_p": args.theta_p, "thetadot_p": np.array(starts)}
    with _progress(args) as bar:
        result = surface_of_section(system, orbits=args.orbits, **starts_kw,
                                    rtol=args.rtol, progress=bar, max_drift=args.max_drift,
                                    coordinates=args.coordinates, perturbations=perturbations,
                                    **_run_flags(args, data))
    out, data = _write(result, data, {"command": args.command_line},
                       lambda: plot_section(result), out)
    _print(args, f"{system.name}: mass ratio {system.mass_ratio:.2f}, omega0 {system.omega0:.4f}, "
                 f"{args.coordinates} coordinates, "
                 f"{len(starts)} trajectories x {args.orbits:g} orbits in {result.seconds:.2f} s "
                 f"({result.member_orbits_per_second:.0f} member-orbits/s), drift limit "
                 f"{result.max_drift:.1e}")
    for k, v in enumerate(starts):
        tilt = f", largest pole tilt {result.max_tilt[k]:.3g} deg" if tilted else ""
        _print(args, f"  thetadot_p/n = {v:5.2f}: {result.count[k]} crossings, status "
                     f"{_status_text(result, k)}, energy drift {result.energy_drift[k]:.1e}, "
                     f"angular-momentum drift {result.angmom_drift[k]:.1e}{tilt}")
    _print(args, f"wrote {out} and {data}", *filter(None, [_finish_checkpoint(args, data)]))
    return _accuracy_status(args, result.status, result.energy_drift, result.max_drift,
                            stop_status=result.stop_status)


def _cmd_map(args):
    import numpy as np

    from .chaosmap import chaos_map

    system = _system(args)
    nt, nd = args.grid
    lo, hi = args.thetadot_range
    out, data = _paths(args, "map", system.name)
    _init(args)
    perturbations = _announce_perturbations(args, system)
    theta = (np.arange(nt) + 0.5) * 180.0 / nt
    with _progress(args) as bar:
        cmap = chaos_map(system, theta, np.linspace(lo, hi, nd), orbits=args.orbits,
                         rtol=args.rtol, progress=bar, max_drift=args.max_drift,
                         include_inaccurate=args.allow_inaccurate, coordinates=args.coordinates,
                         indicator_space=args.indicator_space, perturbations=perturbations,
                         **_run_flags(args, data))
    out, data = _write(cmap, data, {"command": args.command_line}, cmap.plot, out)
    counted = "all finished members" if args.allow_inaccurate else \
        f"{cmap.n_inaccurate} inaccurate left out"
    _print(args, f"{system.name}: {nt} x {nd} map, {args.orbits:g} orbits: chaotic fraction "
                 f"{cmap.chaotic_fraction:.3f} ({counted}; statuses {cmap.status_counts}) in "
                 f"{cmap.seconds:.1f} s; largest energy drift {np.nanmax(cmap.energy_drift):.1e}"
                 f" (limit {cmap.max_drift:.1e}); wrote {out} and {data}")
    _print(args, f"  {cmap.fraction_message}", *filter(None, [_finish_checkpoint(args, data)]))
    return _accuracy_status(args, cmap.status, cmap.energy_drift, cmap.max_drift)


def _cmd_overlap(args):
    import numpy as np

    from . import catalog
    from .overlap import overlap_threshold

    start, stop, step = args.elongations
    system = catalog.system(args.system, eccentricity=args.eccentricity)   # checks name and e
    out, data = _paths(args, "overlap", system.name)
    _init(args)
    perturbations = _announce_perturbations(args, system)
    q = np.round(np.arange(start, stop + step / 2, step), 10)
    with _progress(args) as bar:
        scan = overlap_threshold(args.system, elongations=q, eccentricity=args.eccentricity,
                                 orbits=args.orbits, rtol=args.rtol, progress=bar,
                                 model=args.model, method=args.method, max_drift=args.max_drift,
                                 include_inaccurate=args.allow_inaccurate,
                                 max_orbits=args.max_orbits, coordinates=args.coordinates,
                                 perturbations=perturbations)
    out, data = _write(scan, data, {"command": args.command_line, "converged": scan.converged,
                                    "convergence": scan.message}, scan.plot, out)
    bound = "" if scan.converged else " (upper bound: not converged)"
    _print(args, f"{scan.name} (e = {scan.eccentricity}): first overlap at a/b = {scan.first_overlap}"
                 f"{bound} (analytic {scan.elongation_ro:.4f}; MEGNO criterion "
                 f"{scan.megno_first_overlap}) in {scan.seconds:.1f} s, "
                 f"{scan.member_orbits:.3g} member-orbits; wrote {out} and {data}")
    _print(args, *scan.evidence())
    for d in scan.decisions:
        extra = f", connecting <Y> = {d.connecting_megno:.1f}" if d.overlap else ""
        extra += f", {d.inaccurate} inaccurate trajectories" if d.inaccurate else ""
        _print(args, f"  a/b = {d.elongation:.2f}: {'overlap' if d.overlap else 'separate'}{extra}")
    sec = scan.sections
    return _accuracy_status(args, sec.status, sec.energy_drift, scan.max_drift, "trajectories")


def _plot_libration(result):
    from .plotting import plot_libration_search
    return plot_libration_search(result)


def _cmd_libration(args):
    import warnings

    import numpy as np

    from .libration import relaxed_libration

    system = _system(args)
    out, data = _paths(args, "libration", system.name)
    kwargs = dict(orbits=args.orbits, rtol=args.rtol, xtol=args.xtol, max_drift=args.max_drift,
                  max_orbits=args.max_orbits, coordinates=args.coordinates, method=args.method)
    kwargs["perturbations"] = _announce_perturbations(args, system)
    if args.candidates:
        lo, hi, n = args.candidates
        kwargs["candidates"] = np.linspace(lo, hi, int(n))
    _init(args)
    with _progress(args) as bar, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        result = relaxed_libration(system, **kwargs, **_with_progress(relaxed_libration, bar))
    for w in caught:
        if not args.quiet:
            print(f"ti-spinorbit libration: warning: {w.message}", file=sys.stderr)
    plot = getattr(result, "plot", None)
    out, data = _write(result, data, {"command": args.command_line,
                                      "converged": result.converged,
                                      "convergence": result.message},
                       plot if callable(plot) else lambda: _plot_libration(result), out)
    _print(args,
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
    code = _accuracy_status(args, np.array([_status_code(result.status)]),
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


def energy_check(ts, member=0):
    """Conservation numbers of one member of a TimeSeriesResult and the per-sample arrays:
    :meth:`~ti_spinorbit.section.TimeSeriesResult.conservation` (kept here for callers)."""
    return ts.conservation(member)


def _plot_energy(ts):
    return ts.plot_conservation(0)


def _cmd_energy(args):
    import math as m

    from . import catalog, time_series

    system = _system(args)
    out, data = _paths(args, "energy", system.name)
    thetadot = args.thetadot
    if thetadot is None:
        known = _catalogue_name(system)
        period = None if known is None else catalog.secondary_spin_period(known)
        thetadot = 1.0 if period is None else 2 * m.pi / period / system.mean_motion
    samples = args.samples_per_orbit
    if samples is None:
        rotations = 0 if not system.primary_spin_period else \
            system.orbital_period / abs(system.primary_spin_period)
        samples = max(MIN_SAMPLES_PER_ORBIT, m.ceil(SAMPLES_PER_PRIMARY_ROTATION * rotations))
    _init(args)
    perturbations = _announce_perturbations(args, system)
    with _progress(args) as bar:
        ts = time_series(system, args.theta_p, thetadot, args.orbits, samples_per_orbit=samples,
                         rtol=args.rtol, max_drift=args.max_drift, perturbations=perturbations,
                         **_with_progress(time_series, bar), **_run_flags(args, data))
    numbers, series = energy_check(ts)
    status = ts.status_names[0]
    out, data = _write(ts, data, {"command": args.command_line, "energy_check": numbers,
                                  "member_status": status},
                       lambda: _plot_energy(ts), out)
    worst = max(numbers["energy_drift"], numbers["angmom_drift"])
    _print(args,
           f"{system.name}: {args.orbits:g} orbits at rtol {args.rtol:g}, {numbers['samples']} "
           f"samples, status {status}",
           f"  max relative energy drift           {numbers['energy_drift']:.3e}",
           f"  max relative angular-momentum drift {numbers['angmom_drift']:.3e}",
           "  largest exchange, |ΔE_i|/|E0|: orbit {exchange_orbit:.3e}, primary spin "
           "{exchange_primary:.3e}, secondary spin {exchange_secondary:.3e}".format(**numbers),
           *([] if ts.work is None else [_work_line(ts)]),
           f"wrote {out} and {data}", *filter(None, [_finish_checkpoint(args, data)]))
    if not worst <= args.max_drift:          # also catches NaN
        print(f"ti-spinorbit energy: drift {worst:.3e} exceeds --max-drift {args.max_drift:g} "
              f"(status {status})", file=sys.stderr)
        return EXIT_CHECK_FAILED
    if status != "done":
        print(f"ti-spinorbit energy: the integration stopped early (status {status})",
              file=sys.stderr)
        return EXIT_CHECK_FAILED
    return EXIT_OK


def _work_line(ts, member=0):
    """The work the perturbations did on a time series member by its last sample, J, and the
    angular momentum they brought in (the drifts above are those of E - W and L - L_ext)."""
    import numpy as np

    ok = np.isfinite(ts.t[member])
    work = float(ts.work[member][ok][-1])
    lext = float(np.linalg.norm(ts.external_angmom[member][ok][-1]))
    return (f"  work done by the perturbations W = {work:.6e} J by the end (< 0: dissipated); "
            f"external angular momentum |L_ext| = {lext:.3e} kg m^2/s")


def _status_code(name):
    from .results import Status

    return int(Status.from_label(name))


def _cmd_benchmark(args):
    import json
    import platform
    import time

    import numpy as np

    from . import runtime, surface_of_section
    from .io import provenance

    system = _system(args)
    out = args.out or "benchmark.json"
    thetadot = np.linspace(*BENCH_THETADOT_RANGE, args.members)
    _init(args)
    started = time.perf_counter()
    surface_of_section(system, 0.0, thetadot[:1], orbits=1.0, rtol=args.rtol,
                       model=args.model, method=args.method, progress=False)                          # compile / load
    warmup = time.perf_counter() - started
    runs = [surface_of_section(system, 0.0, thetadot, orbits=args.orbits, rtol=args.rtol,
                               model=args.model, method=args.method, progress=False)
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
    from .files import write_json      # atomic: a killed write leaves no partial report

    write_json(out, report, indent=1)
    _print(args, f"{args.system}: {args.members} members x {args.orbits:g} orbits at rtol "
                 f"{args.rtol:g} on {report['arch']}: {best.seconds:.3g} s (best of {args.repeat}), "
                 f"{rate:.0f} member-orbits/s; first call {warmup:.1f} s; wrote {out}")
    return 0


def _cmd_warmup(args):
    import time

    from . import runtime
    from .warmup import warmup

    _init(args)
    started = time.perf_counter()
    done = warmup(models=args.models, indicators=[v == "on" for v in args.indicators],
                  sampling=[v == "on" for v in args.sampling], methods=args.methods,
                  verbose=not args.quiet, perturbed=(False, True) if args.perturbed else (False,))
    compiled = sum(d["how"] == "compiled" for d in done)
    _print(args, f"{len(done)} kernel variants ready ({compiled} compiled, "
                 f"{len(done) - compiled} already in the cache) in "
                 f"{time.perf_counter() - started:.1f} s; cache folder {runtime.cache_folder()}")
    return 0


def _experiments_dir(given):
    here = os.path.dirname(os.path.abspath(__file__))
    for d in ([given] if given else [os.path.join(os.getcwd(), "experiments"),
                                    os.path.join(os.path.dirname(here), "experiments")]):
        if d and os.path.isfile(os.path.join(d, "_common.py")):
            return d
    raise ValueError("experiments folder not found: run from a source checkout or pass "
                     "--experiments PATH")


def _cmd_figures(args):
    import glob
    import subprocess
    import time

    folder = _experiments_dir(args.experiments)
    scripts = sorted(glob.glob(os.path.join(folder, "study[0-9][0-9]_*.py")))
    if args.only:
        scripts = [s for s in scripts if int(os.path.basename(s)[5:7]) in args.only]
    if not scripts:
        raise ValueError(f"no study scripts selected in {folder}")
    out = os.path.abspath(args.out)
    env = dict(os.environ, **({"TI_SPINORBIT_ARCH": args.arch} if args.arch else {}))
    hide = subprocess.DEVNULL if args.quiet else None
    failed = []
    for script in scripts:
        t0 = time.perf_counter()
        cmd = [sys.executable, script, "--out", out] + (["--quick"] if args.quick else [])
        rc = subprocess.call(cmd, cwd=folder, env=env, stdout=hide)
        _print(args, f"{os.path.basename(script)}: {'ok' if rc == 0 else f'FAILED ({rc})'} "
                     f"in {time.perf_counter() - t0:.0f} s")
        sys.stdout.flush()
        if rc:
            failed.append(os.path.basename(script))
    if failed:
        raise RuntimeError(f"{len(failed)} studies failed: {', '.join(failed)}")
    return 0


HANDLERS = {"systems": _cmd_systems, "section": _cmd_section, "map": _cmd_map,
            "overlap": _cmd_overlap, "libration": _cmd_libration, "energy": _cmd_energy,
            "benchmark": _cmd_benchmark, "warmup": _cmd_warmup, "figures": _cmd_figures}


def _one_line(exc):
    return " ".join(str(exc).split())


def _checked_run(args):
    """check_args then the handler, with this package's input warnings (ImplausibleInputWarning:
    tiny bodies, a section at e ~ 0) printed once each as one line on stderr (none with
    --quiet); other warnings as Python shows them."""
    import warnings

    from .systems import ImplausibleInputWarning

    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, ImplausibleInputWarning):
            return shown(message, category, filename, lineno, file, line)
        if not getattr(args, "quiet", False):
            print(f"ti-spinorbit {args.command}: warning: {_one_line(message)}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default", ImplausibleInputWarning)   # once per run, per place
        warnings.showwarning = show
        try:
            check_args(args)
            return HANDLERS[args.command](args)
        finally:
            _release_outputs()


def main(argv=None):
    """Run the command line ``argv`` (default ``sys.argv[1:]``); returns the exit status:
    0 success, 1 a check failed (energy), 2 bad input or a failed run (one line on stderr),
    3 results written but some members inaccurate (unless --allow-inaccurate), 130
    interrupted. With --debug every error propagates with its traceback."""
    try:
        args, unknown = _parser().parse_known_args(argv)
        if unknown:       # argparse would blame the top-level parser; name the subcommand
            raise CommandLineError(f"ti-spinorbit {args.command}: error: unrecognized "
                                   f"arguments: {' '.join(unknown)}")
    except CommandLineError as exc:
        print(_one_line(exc), file=sys.stderr)
        return 2
    # recorded in every data file, quoted so that it can be pasted back into a shell
    args.command_line = shlex.join(["ti-spinorbit", *(sys.argv[1:] if argv is None else argv)])
    if getattr(args, "debug", False):
        return _checked_run(args)
    try:
        return _checked_run(args)
    except (ValueError, TypeError, RuntimeError, OSError) as exc:
        print(f"ti-spinorbit {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_ERROR
    except MemoryError:
        print(f"ti-spinorbit {args.command}: error: out of memory; use fewer members "
              "(--grid, --members, --thetadot) or orbits", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print(f"ti-spinorbit {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
