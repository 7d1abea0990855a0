"""The flags several subcommands share, and what checks them.

Every plain numeric flag is parsed by :class:`Bounded`, a ``type=`` that refuses a value
outside its interval during parsing ("--rtol must lie in [1e-16, 0.01] (got 1)"); the bounds
are the library's own (``_validate``, ``section``, ``perturbations``). Relations between
values (--max-orbits against --orbits, the perturbation flags among themselves) are checked
after parsing, by the functions here and each subcommand's ``check``."""

import argparse
import math
import re

from .._validate import MAX_DENSITY, MAX_ORDER, MAX_SPIN, MIN_DENSITY  # the library's bounds
from ..engine.compiling import METHODS
from ..model import models as _models  # the model requests (one registry)
from ..model import perturbations as _pert  # tide, YORP and BYORP bounds and defaults, likewise
from ..constants import PLANETS
from ..model.perturbations import BYORP, YORP, Flyby, SolarTide, Tides
from ..runtime import _KNOWN_ARCHS
from ..studies.section import MAX_ORBITS  # orbits limit shared with the library
from ..system import catalog
from .common import EXIT_INACCURATE, build_system, fmt, one_line, say

#: Accepted --rtol range (the integrator's own limits, ensemble.check_tolerances).
RTOL_RANGE = (1e-16, 1e-2)
#: Largest elongation a/b (the catalogue's own limit).
MAX_ELONGATION = 10.0
#: --heliocentric A_AU E: the binary's heliocentric orbit for --yorp / --byorp.
HELIOCENTRIC_A_RANGE = _pert.HELIOCENTRIC_A_RANGE


class CommandLineError(ValueError):
    """A bad command line (unknown flag, unparsable value): one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting, so every bad input ends
    the same way: one line on stderr, status 2 (``--help`` still prints and exits 0)."""

    def error(self, message):
        # argparse puts "argument --rtol: " before a type's message; a Bounded value's
        # message names its flag the way every other check does: "--rtol must lie in ..."
        message = re.sub(r"^argument (\S+): (?=must lie in )", r"\1 ", message)
        raise CommandLineError(f"{self.prog}: error: {message}")


class Bounded:
    """argparse ``type=`` for a number in an interval: ``Bounded(float, 1e-16, 1e-2)``.

    Parses with ``kind`` (a text that is no number is argparse's own "invalid float value:
    'x'": the type is named by ``__name__``), then refuses a value outside [low, high] (or
    the open ends asked for), NaN and infinities included, with "must lie in [low, high]
    (got value)"; :class:`Parser` puts the flag in front. :meth:`check` says the same for a
    value checked after parsing (one of several values of one flag, or a bound that depends
    on another flag)."""

    def __init__(self, kind, low, high, *, low_open=False, high_open=False):
        self.kind, self.low, self.high = kind, low, high
        self.low_open, self.high_open = low_open, high_open
        self.__name__ = kind.__name__

    def __repr__(self):
        return (f"Bounded({self.kind.__name__}, {self.low!r}, {self.high!r}, "
                f"low_open={self.low_open}, high_open={self.high_open})")

    @property
    def interval(self):
        """The interval as the messages write it: "(0, 1e+07]", "[1, 1024]"."""
        return (f"{'(' if self.low_open else '['}{fmt(self.low)}, {fmt(self.high)}"
                f"{')' if self.high_open else ']'}")

    def holds(self, value):
        return (math.isfinite(value)
                and (value > self.low if self.low_open else value >= self.low)
                and (value < self.high if self.high_open else value <= self.high))

    def _refusal(self, value):
        return f"must lie in {self.interval} (got {fmt(value)})"

    def __call__(self, text):
        value = self.kind(text)
        if not self.holds(value):
            raise argparse.ArgumentTypeError(self._refusal(value))
        return value

    def check(self, flag, value):
        """ValueError naming ``flag``, the value and the interval unless value lies in it."""
        if not self.holds(value):
            raise ValueError(f"{flag} {self._refusal(value)}")


class Order(Bounded):
    """``--order``: 0 or an integer in [2, MAX_ORDER] (1 adds nothing to 0: first moments
    vanish about the centre of mass), refused during parsing as every bounded flag is."""

    def __init__(self):
        super().__init__(int, 2, MAX_ORDER)

    @property
    def interval(self):
        return f"{{0}} ∪ [2, {MAX_ORDER}]"

    def holds(self, value):
        return value == 0 or super().holds(value)


ORBITS = Bounded(float, 0.0, MAX_ORBITS, low_open=True)
ORDER = Order()
RTOL = Bounded(float, *RTOL_RANGE)
ELONGATION = Bounded(float, 1.0, MAX_ELONGATION)
DENSITY = Bounded(float, MIN_DENSITY, MAX_DENSITY)
ECCENTRICITY = Bounded(float, 0.0, 1.0, high_open=True)
ANGLE = Bounded(float, -360.0, 360.0)                  # deg: --theta-p, --tilt, --inclination
SUN_INCLINATION = Bounded(float, *_pert.INCLINATION_RANGE)   # deg: --sun-inclination
SPIN = Bounded(float, -MAX_SPIN, MAX_SPIN)             # units of n: --thetadot, --spin-xy, ...
MAX_DRIFT = Bounded(float, 0.0, 1.0, low_open=True)
# tides, YORP, BYORP (the bounds of ti_spinorbit.model.perturbations)
K2 = Bounded(float, *_pert.K2_RANGE)
TIME_LAG = Bounded(float, *_pert.TIME_LAG_RANGE)
Q = Bounded(float, *_pert.Q_RANGE)
COEFFICIENT = Bounded(float, -_pert.COEFFICIENT_LIMIT, _pert.COEFFICIENT_LIMIT)
STRENGTH = Bounded(float, *_pert.STRENGTH_RANGE)
RADIUS = Bounded(float, *_pert.RADIUS_RANGE)
HELIOCENTRIC_A = Bounded(float, *HELIOCENTRIC_A_RANGE)
HELIOCENTRIC_E = Bounded(float, 0.0, 1.0, high_open=True)
FLYBY_Q = Bounded(float, 1.0, 1e9)                    # km: --flyby-q
FLYBY_VINF = Bounded(float, 0.01, 100.0)              # km/s: --flyby-vinf
FLYBY_TIME = Bounded(float, -1e6, 1e6)                # h: --flyby-time


# ---- subcommand parsers -----------------------------------------------------------------

DEBUG_HELP = "on any error print the full traceback (for bug reports) instead of one line"


def debug_parent():
    """--debug before or after the subcommand: each subcommand has it too, with SUPPRESS so
    that the top-level value stays when the subcommand's own flag is absent."""
    debug = Parser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                       help=DEBUG_HELP)
    return debug


_SAME = object()


def add_command(subparsers, name, help, examples, description=_SAME):
    """A subcommand's parser: its help line (also its description unless another, or None,
    is given), its examples as the epilog, and --debug."""
    if description is _SAME:
        description = help
    return subparsers.add_parser(name, help=help, description=description,
                                 epilog=f"examples:\n{examples}\n",
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 parents=[debug_parent()])


# ---- shared option groups ---------------------------------------------------------------

def run_options(s, out_help, data=True, orbits=300.0, rtol=1e-10, model=True, resume=False):
    """--orbits, --rtol, --method, --arch, the outputs, --quiet, --no-progress, --overwrite,
    --model (``model``) and the checkpoint group (``resume``) of a command that integrates."""

    if orbits is not None:
        s.add_argument("--orbits", type=ORBITS, default=orbits,
                       help=f"orbits to integrate, in (0, {MAX_ORBITS:g}] (default {orbits:g})")
    s.add_argument("--rtol", type=RTOL, default=rtol,
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
        s.add_argument("--model", choices=_models.REQUESTS, default="auto",
                       help="equations of motion: the reduced planar model for planar "
                            "starts (auto, default) or the general 3-D one (3d)")
        s.add_argument("--order", type=ORDER, default=4,
                       help=f"truncation order of the mutual potential, 0 or 2..{MAX_ORDER} "
                            "(default 4, the paper's; above 4 the table-driven order-N "
                            "kernels, with every body's integrals to that degree)")
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


def accuracy_flags(s):
    """--max-drift (default None: scaled with the run) and --allow-inaccurate."""
    s.add_argument("--max-drift", type=MAX_DRIFT, default=None,
                   help="largest relative energy or angular-momentum drift of a member "
                        "counted as accurate, in (0, 1] (default: min(1e-4, 1000 x rtol "
                        "x orbits)); members above it are 'inaccurate'")
    s.add_argument("--allow-inaccurate", action="store_true",
                   help=f"exit with status 0 even when members are inaccurate (default: "
                        f"status {EXIT_INACCURATE}; they are kept in the data file either way)")


def coordinates_flag(s):
    s.add_argument("--coordinates", choices=("inertial", "apsidal"), default="inertial",
                   help="spin coordinate θ̇_p/n of the starts and results: inertial (the "
                        "inertial spin rate, default) or apsidal (the paper's: spin rate "
                        "minus the apsidal precession rate; needs e >= 0.001); "
                        "docs/physics.md §6.7")


def tilt_flags(s):
    s.add_argument("--tilt", type=ANGLE, nargs=3, default=None,
                   metavar=("ROLL", "PITCH", "YAW"),
                   help="tilt every start out of the plane: the secondary turned by these "
                        "angles (deg, each in [-360, 360]) about the orbit frame's radial, "
                        "along-track and normal axes (docs/physics.md §6.8; 3-D model)")
    s.add_argument("--spin-xy", type=SPIN, nargs=2, default=None, metavar=("SX", "SY"),
                   help="off-axis spin of the secondary in its body frame, units of n")
    s.add_argument("--inclination", type=ANGLE, default=None,
                   help="inclination of the mutual orbit to the primary's equator, deg")


def system_flags(s, default="1991 VH", shape=True):
    s.add_argument("--system", default=default,
                   help=f"catalogued system name (default: {default}; see 'ti-spinorbit "
                        "systems') or a .json file of your own system, as written by "
                        "'ti-spinorbit systems --show NAME --out PATH' (then --elongation "
                        "and --density are refused: edit the file; --eccentricity applies)")
    if shape:
        s.add_argument("--elongation", type=ELONGATION,
                       help=f"secondary a/b in [1, {MAX_ELONGATION:g}] (default: catalogue value)")
        s.add_argument("--density", type=DENSITY,
                       help=f"secondary density, kg/m^3, in [{MIN_DENSITY:g}, {MAX_DENSITY:g}] (default: catalogue value)")
    s.add_argument("--eccentricity", type=ECCENTRICITY,
                   help="initial osculating eccentricity in [0, 1) (default: catalogue value)")


def check_max_orbits(args):
    """--max-orbits (a cap of the length doubling) is at least --orbits."""
    if args.max_orbits is not None and args.max_orbits < args.orbits:
        raise ValueError(f"--max-orbits must lie in [--orbits, {MAX_ORBITS:g}] = "
                         f"[{args.orbits:g}, {MAX_ORBITS:g}] (got {args.max_orbits:g})")


# ---- tides, YORP and BYORP --------------------------------------------------------------

def perturbation_flags(s):
    g = s.add_argument_group("tides, YORP, BYORP and the Sun in the equations "
                             "(docs/physics.md §13)")
    g.add_argument("--tide", choices=("primary", "secondary"), default=None,
                   help="constant-time-lag (--time-lag) or constant-Q (--Q, default Q = "
                        "100) tide raised on this body by the other")
    g.add_argument("--k2", type=K2, default=None,
                   help="Love number of the --tide body, in [1e-12, 10] (default: the "
                        "rubble-pile k2 = 1e-5 R[km])")
    g.add_argument("--time-lag", type=TIME_LAG, default=None, metavar="S",
                   help="constant tidal time lag, s, in [1e-9, 1e9] (or --Q)")
    g.add_argument("--Q", type=Q, default=None,
                   help="constant tidal quality factor, in [0.001, 1e12] (default 100)")
    g.add_argument("--yorp", type=COEFFICIENT, default=None, metavar="F_Y",
                   help="YORP coefficient f_Y in [-1, 1] (the paper's 5e-4; > 0 spins up) "
                        "on --yorp-body")
    g.add_argument("--yorp-body", choices=("primary", "secondary"), default="secondary",
                   help="the body --yorp acts on (default secondary)")
    g.add_argument("--yorp-convention", choices=tuple(_pert.YORP_CONVENTIONS),
                   default=_pert.YORP_CONVENTION,
                   help="which torque f_Y stands for: 'paper' (default; f_Y R^3 L/(6 c d^2 "
                        "sqrt(1-e^2)), the paper's energy per orbit over two rotations) or "
                        "'one-turn' (twice that; docs/physics.md §13.2)")
    g.add_argument("--byorp", type=COEFFICIENT, default=None, metavar="B",
                   help="BYORP coefficient B in [-1, 1] (> 0 expands the orbit)")
    for kind, whose in (("tide", "the --tide body"), ("yorp", "the --yorp-body"),
                        ("byorp", "the secondary, for --byorp")):
        g.add_argument(f"--{kind}-radius", type=RADIUS, default=None, metavar="M",
                       help=f"radius of {whose}, m, in [{_pert.RADIUS_RANGE[0]:g}, "
                            f"{_pert.RADIUS_RANGE[1]:g}] (default its "
                            "volume-equivalent radius (abc)^(1/3); needed when a "
                            "--system file gives the body by its inertia integrals)")
    g.add_argument("--strength", type=STRENGTH, default=1.0,
                   help="factor on every perturbation's force and torque, in [1e-12, "
                        "1e15] (default 1; 1e6 makes a million years act in one)")
    # two values with two ranges: checked after parsing (check_perturbation_flags)
    g.add_argument("--heliocentric", type=float, nargs=2, default=None,
                   metavar=("A_AU", "E"),
                   help="the binary's heliocentric orbit for --yorp/--byorp/--sun: a in AU in "
                        "[0.05, 1e4] and e in [0, 1) (default: the catalogued one)")
    g.add_argument("--sun", action="store_true",
                   help="the Sun's tide and torques (SolarTide, docs/physics.md §13.11), the "
                        "barycentre on the system's heliocentric orbit (oriented by its pole), "
                        "or on --heliocentric with the --sun-* angles")
    g.add_argument("--sun-inclination", type=SUN_INCLINATION, default=None, metavar="DEG",
                   help="inclination of the --sun orbit to the mutual orbit's initial plane, "
                        "degrees in [0, 180]; any --sun-* angle replaces the system's orbit "
                        "orientation (the angles not given are then 0: i 0 puts the Sun in the "
                        "plane)")
    for dest, what in (("node", "longitude of the ascending node"),
                       ("periapsis", "argument of perihelion"),
                       ("mean-anomaly", "mean anomaly at t = 0")):
        g.add_argument(f"--sun-{dest}", type=ANGLE, default=None, metavar="DEG",
                       help=f"{what} of the --sun orbit, degrees in [-360, 360] (0 when "
                            "another --sun-* angle is given)")
    g.add_argument("--radiation-distance", choices=_pert.DISTANCES, default=_pert.DISTANCE,
                   help="where --yorp and --byorp take the Sun's distance: 'orbit' (default; "
                        "on the heliocentric orbit at every step) or 'mean' (the paper's "
                        "mean-distance form; docs/physics.md §13.12)")
    g.add_argument("--flyby", choices=tuple(PLANETS), default=None,
                   help="a planet passing on a hyperbola relative to the barycentre (Flyby, "
                        "docs/physics.md §13.12): its tide and torques")
    g.add_argument("--flyby-q", type=FLYBY_Q, default=None, metavar="KM",
                   help="closest distance of the --flyby planet from the barycentre, km "
                        "(at least the planet's radius; required with --flyby)")
    g.add_argument("--flyby-vinf", type=FLYBY_VINF, default=None, metavar="KM_S",
                   help="speed at infinity of the --flyby planet, km/s in [0.01, 100] "
                        "(default 10)")
    g.add_argument("--flyby-time", type=FLYBY_TIME, default=None, metavar="H",
                   help="time of closest approach after the start, hours (default 0)")
    g.add_argument("--flyby-inclination", type=SUN_INCLINATION, default=None, metavar="DEG",
                   help="inclination of the --flyby hyperbola to the mutual orbit's initial "
                        "plane, degrees in [0, 180] (default 0)")
    for dest, what in (("node", "longitude of the ascending node"),
                       ("periapsis", "argument of the closest approach")):
        g.add_argument(f"--flyby-{dest}", type=ANGLE, default=None, metavar="DEG",
                       help=f"{what} of the --flyby hyperbola, degrees in [-360, 360] "
                            "(default 0)")


def perturbations(args):
    """The Tides / YORP / BYORP objects the flags ask for (a list, empty without them)."""

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
                        strength=args.strength, convention=args.yorp_convention,
                        distance=args.radiation_distance, **sun))
    if args.byorp is not None:
        out.append(BYORP(coefficient=args.byorp, radius=args.byorp_radius,
                         strength=args.strength, distance=args.radiation_distance, **sun))
    if args.sun:
        # the angles given replace the system's orbit (the others then 0); none given: the
        # system's own heliocentric orbit, oriented by its pole
        angles = {f"{name}_deg": value for name, value in (
            ("inclination", args.sun_inclination), ("node", args.sun_node),
            ("periapsis", args.sun_periapsis), ("mean_anomaly", args.sun_mean_anomaly))
            if value is not None}
        out.append(SolarTide(strength=args.strength, **angles, **sun))
    if args.flyby is not None:
        given = {name: value for name, value in (
            ("v_inf_km_s", args.flyby_vinf), ("t_closest_h", args.flyby_time),
            ("inclination_deg", args.flyby_inclination), ("node_deg", args.flyby_node),
            ("periapsis_deg", args.flyby_periapsis)) if value is not None}
        out.append(Flyby(args.flyby, q_km=args.flyby_q, strength=args.strength, **given))
    return out


def check_perturbation_flags(args):
    """Relations between the perturbation flags, and that the system can carry them (a
    catalogued heliocentric orbit or --heliocentric for YORP / BYORP), before any work; the
    single values were checked while parsing (:class:`Bounded`)."""
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
    if not args.sun:
        for dest in ("sun_inclination", "sun_node", "sun_periapsis", "sun_mean_anomaly"):
            if getattr(args, dest) is not None:
                raise ValueError(f"--{dest.replace('_', '-')} needs --sun (the Sun's tide)")
    if args.flyby is None:
        for dest in ("flyby_q", "flyby_vinf", "flyby_time", "flyby_inclination", "flyby_node",
                     "flyby_periapsis"):
            if getattr(args, dest) is not None:
                raise ValueError(f"--{dest.replace('_', '-')} needs --flyby PLANET")
    elif args.flyby_q is None or args.flyby_q < PLANETS[args.flyby][1]:
        raise ValueError(f"--flyby needs --flyby-q KM, the closest distance (at least "
                         f"{PLANETS[args.flyby][1]:g} km for {args.flyby}: closer, the binary "
                         f"hits it){'' if args.flyby_q is None else f'; got {args.flyby_q:g}'}")
    if args.yorp is None and args.byorp is None and args.radiation_distance != _pert.DISTANCE:
        raise ValueError("--radiation-distance needs --yorp or --byorp")
    if args.heliocentric is not None:
        a_au, e = args.heliocentric
        HELIOCENTRIC_A.check("--heliocentric A_AU", a_au)
        HELIOCENTRIC_E.check("--heliocentric E", e)
        if args.yorp is None and args.byorp is None and not args.sun:
            raise ValueError("--heliocentric needs --yorp or --byorp, or --sun (only they use "
                             "the heliocentric orbit)")
    items = perturbations(args)
    if not items:
        if args.strength != 1.0:
            raise ValueError("--strength needs --tide, --yorp, --byorp, --sun or --flyby (it "
                             "scales them)")
        return
    if args.command == "overlap":
        system = catalog.system(args.system, eccentricity=args.eccentricity)
    else:
        system = build_system(args)
    for p in items:
        flag = {"tides": "--tide", "yorp": "--yorp", "byorp": "--byorp",
                "solar_tide": "--sun", "flyby": "--flyby"}[p.kind]
        try:
            p.block(system)
        except ValueError as exc:
            text = one_line(exc)
            for api, cli_words in (
                    ("pass heliocentric_a_au (AU) and heliocentric_e to YORP / BYORP, or give "
                     "the system heliocentric_orbit=HeliocentricOrbit(a_AU, e, ...)",
                     "pass --heliocentric A_AU E, or give the system file a heliocentric_orbit"),
                    ("give the system heliocentric_orbit=HeliocentricOrbit(a_AU, e, ...), or "
                     "SolarTide(heliocentric_a_au=..., heliocentric_e=...)",
                     "pass --heliocentric A_AU E, or give the system file a heliocentric_orbit"),
                    ("give HeliocentricOrbit(..., pole=(longitude, latitude)), or the Sun's "
                     "angles relative to the binary to SolarTide(inclination_deg=...)",
                     "give --sun-inclination DEG (and --sun-node, --sun-periapsis), or a "
                     "system file whose heliocentric_orbit has a pole")):
                text = text.replace(api, cli_words)
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
            parts.append(f"YORP on the {p.body} (f_Y {p.coefficient:g}, {p.convention} torque, "
                         f"{p.distance} distance)")
        elif p.kind == "solar_tide":
            if p.own_orbit:
                i, node, peri, m0 = (getattr(p, name) or 0.0 for name in p.ANGLES)
                parts.append(f"the Sun's tide (i {i:g}°, node {node:g}°, perihelion {peri:g}°, "
                             f"M0 {m0:g}°)")
            else:
                parts.append("the Sun's tide (on the system's heliocentric orbit)")
        elif p.kind == "flyby":
            parts.append(f"{p.planet} flyby (q {p.q_km:g} km, v_inf {p.v_inf_km_s:g} km/s, "
                         f"closest at {p.t_closest_h:g} h, i {p.inclination_deg:g}°)")
        else:
            parts.append(f"BYORP (B {p.coefficient:g})")
    if not parts:
        return ""
    strengths = sorted({p.strength for p in items})
    scale = ", ".join(f"{x:g}" for x in strengths)
    return (f"perturbations: {'; '.join(parts)}; strength {scale} (docs/physics.md §13; "
            "drifts are those of E - W and L - L_ext)")


def announce_perturbations(args, system):
    """The perturbations of the flags (a list), their one-line summary printed first."""
    items = perturbations(args)
    if items:
        say(args, perturbation_summary(items, system))
    return items
