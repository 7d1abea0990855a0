"""What the subcommands share once their flags are parsed: exit statuses, one-line messages,
output checks and paths (claimed for the run, never overwritten unless --overwrite), the
Matplotlib backend, Taichi start-up, the system a command runs on (catalogued or a --system
file), default file names, progress, checkpoints, writing results and the accuracy verdict."""

import dataclasses
import math
import os
import re
import sys
import tempfile

import numpy as np

from .. import init
from ..engine import progress as _progress
from ..engine.accuracy import TRUNCATION_LIMITS
from ..engine.checkpoint import check_target, finish, holds_checkpoint
from ..engine.options import Integrator, Run
from ..engine.results import STATUS_NAMES, Status
from ..files import check_name, claim, safe_part, target
from ..model.coordinates import APSIDAL_MIN_ECCENTRICITY
from ..output import plotting as _plotting
from ..output.io import read_metadata, save
from ..system import catalog
from ..system.systems import read_system_file

#: Exit statuses (docs/statuses.md, "Statuses, exit codes and accuracy").
EXIT_OK, EXIT_CHECK_FAILED, EXIT_ERROR, EXIT_INACCURATE, EXIT_INTERRUPTED = 0, 1, 2, 3, 130
#: Figures and data files.
FIGURE_EXTENSIONS = (".png", ".pdf", ".svg")


# ---- messages ---------------------------------------------------------------------------

def fmt(x):
    """Integers as they are (1048576), other numbers short (1e+07, 0.01, nan)."""
    return str(x) if isinstance(x, int) and not isinstance(x, bool) else f"{x:g}"


def one_line(exc):
    return " ".join(str(exc).split())


def say(args, *lines):
    """Print lines on stdout, unless --quiet."""
    if not args.quiet:
        for line in lines:
            print(line)


# ---- outputs and the figure backend -----------------------------------------------------

def check_output(flag, path, extensions):
    """The output file must be writable where it is asked for, with one of our extensions:
    a typo, a folder, a read-only file, a dangling symbolic link, control characters or a
    name longer than the folder allows (:func:`ti_spinorbit.files.check_name`) must fail
    before a long run, not after it. Probes by opening (an existing file for appending, which
    changes nothing, and always a temporary file beside it, where the atomic write will put
    its bytes), because permission bits do not tell for root or read-only mounts."""

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


def choose_backend():
    """The command line only writes figures to files: without a display it uses Matplotlib's
    file backend (Agg) unless a file backend is already chosen. Only the command line does
    this; the library leaves the session's backend alone."""
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg") and not _has_display():
        matplotlib.use("Agg")


def check_plotting():
    """Matplotlib must load with the environment's backend before a run whose figure would
    otherwise fail at the end (an invalid MPLBACKEND raises at import)."""
    try:
        choose_backend()
        _plotting._pyplot()
    except Exception as exc:  # noqa: BLE001 - any failure here would lose the figure later
        backend = os.environ.get("MPLBACKEND")
        if backend:
            raise ValueError(f"MPLBACKEND={backend!r} is not a Matplotlib backend that works "
                             "here; unset it or set MPLBACKEND=Agg") from None
        raise ValueError(f"Matplotlib cannot start ({one_line(exc)[:200]})") from None


def check_figure_outputs(args):
    """--out (a figure) and --data (.npz) as given, and that Matplotlib starts: before any
    work (the default names are checked by :func:`output_paths`)."""
    check_output("--out", args.out, FIGURE_EXTENSIONS)
    check_output("--data", args.data, (".npz",))
    check_plotting()


# ---- Taichi -----------------------------------------------------------------------------

def init_taichi(args):
    """Start Taichi on --arch. Taichi's banner and "Starting on arch" line are hidden by the
    runtime, --quiet or not (TI_SPINORBIT_VERBOSE=1 shows them; ti_spinorbit/runtime.py)."""
    return init(arch=args.arch)


# ---- the system a command runs on -------------------------------------------------------

def is_system_file(value):
    """--system names a file (rather than a catalogued system) when it ends in .json."""
    return isinstance(value, str) and value.lower().endswith(".json")


def file_system(args):
    """The BinarySystem of a --system .json (BinarySystem.describe() output, as written by
    'ti-spinorbit systems --show NAME --out PATH', or the one-item list 'systems --out'
    writes), with --eccentricity applied; read by BinarySystem.from_file's rules (unknown
    keys and derived entries that disagree with the inputs are refused). --elongation and
    --density are refused: they rebuild a catalogued secondary by the catalogue's
    prescription (docs/physics.md §7), which a file of your own system does not follow."""

    path = args.system
    for dest, flag in (("elongation", "--elongation"), ("density", "--density")):
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{flag} applies only to a catalogued --system (the catalogue's "
                             f"secondary prescription); for the file {path!r} edit the "
                             "secondary's semi_axes_m/mass_kg in it instead")
    if getattr(args, "elongations", None) is not None:
        raise ValueError(f"--system: overlap scans the catalogue's elongation prescription, so "
                         f"it needs a catalogued system name (got the file {path!r})")
    system = load_system_file(path, "--system")
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


def load_system_file(path, flag):
    """BinarySystem.from_file for the command line: every error one line naming ``flag``
    (--system, --show) and the file."""

    try:
        return read_system_file(path, flag)
    except FileNotFoundError as exc:
        raise ValueError(f"{exc} (a catalogued name, or a .json written by 'ti-spinorbit "
                         "systems --show NAME --out PATH')") from None


def catalogue_name(system):
    """The catalogue key of a system loaded from a file when its name is one, else None
    (its defaults, e.g. the section starts, then follow the catalogue)."""

    try:
        return catalog._resolve(system.name)
    except (TypeError, ValueError):
        return None


def build_system(args):
    """The BinarySystem of --system (a catalogue name or a .json file) and the shape flags."""

    if is_system_file(args.system):
        return file_system(args)
    return catalog.system(args.system, elongation=getattr(args, "elongation", None),
                          secondary_density=getattr(args, "density", None),
                          eccentricity=getattr(args, "eccentricity", None))


def check_system_flags(args):
    """Build the catalogued system the flags ask for (cheap: no integration), so that a value
    inside its flag's range that the system still refuses (an unknown --system, an
    --elongation making b < c, an --eccentricity making the bodies touch at pericentre)
    fails before any work, naming the flag rather than the library's argument. Returns the
    system (None for 'systems' without --show, or --show with a file)."""

    name = args.show if args.command == "systems" else getattr(args, "system", None)
    if name is None:
        return None
    flag = "--show" if args.command == "systems" else "--system"
    if flag == "--show" and is_system_file(name):
        load_system_file(name, flag)
        return None
    if flag == "--system" and is_system_file(name):
        system = file_system(args)
        check_derived(args, system)
        return system
    try:
        catalog.entry(name)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{flag}: {one_line(exc)}") from None
    shape_flag = "--elongations" if args.command == "overlap" else "--elongation"
    flags = {"elongation": shape_flag, "secondary_density": "--density",
             "eccentricity": "--eccentricity"}
    elongation = getattr(args, "elongation", None)
    if getattr(args, "elongations", None):
        start, stop, step = args.elongations
        scan = np.round(np.arange(start, stop + step / 2, step), 10)      # as overlap.run
        elongation = float(scan.max()) if scan.size else None   # the most elongated is the worst
    given = {"elongation": elongation, "secondary_density": getattr(args, "density", None),
             "eccentricity": getattr(args, "eccentricity", None)}
    try:
        system = catalog.system(name, **given)
    except (TypeError, ValueError) as exc:
        message = re.sub(r"^(elongation|secondary_density|eccentricity)\b",
                         lambda m: flags[m.group(1)], one_line(exc))
        if not message.startswith("--"):      # blame the first flag that changed the system
            culprit = next((flags[k] for k, v in given.items() if v is not None), flag)
            message = f"{culprit}: {message}"
        raise ValueError(message) from None
    check_derived(args, system)
    return system


def check_derived(args, system):
    """Checks of the built system that the catalogue and a --system file share."""

    if getattr(args, "coordinates", None) == "apsidal" and system.e < APSIDAL_MIN_ECCENTRICITY:
        raise ValueError(f"--coordinates apsidal needs an eccentricity >= "
                         f"{APSIDAL_MIN_ECCENTRICITY:g} ({system.name} has e = {system.e:g}): "
                         "use --coordinates inertial or a larger --eccentricity")


# ---- default file names -----------------------------------------------------------------

#: Physics flags named in default file names, in this order, when they differ from their
#: default: (dest, tag). The value follows the tag: ab1.06 (--elongation 1.06), rho2500,
#: e0.1, tp30 (--theta-p), td1.13-1.63 (--thetadot; over three values: first-last n count),
#: g64x64 (--grid), tdr0.5-2 (--thetadot-range), ab1.01-1.1-0.01 (--elongations), cand0.2-1.3-45
#: (--candidates), xtol1e-8, spo128 (--samples-per-orbit), o1000 (--orbits), maxo8000
#: (--max-orbits), rtol1e-13, ord8 (--order), tilt5-0-0, sxy0-0.1, inc10; --model, --coordinates, --method and
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
             ("rtol", "rtol"), ("model", ""), ("order", "ord"), ("coordinates", ""),
             ("method", ""),
             ("tilt", "tilt"), ("spin_xy", "sxy"), ("inclination", "inc"),
             ("indicator_space", ""), ("tide", "tide-"), ("k2", "k2"), ("time_lag", "dt"),
             ("Q", "Q"), ("yorp", "yorp"), ("yorp_body", "yorp-"),
             ("yorp_convention", "yorp-"), ("byorp", "byorp"),
             ("strength", "str"), ("heliocentric", "helio"), ("tide_radius", "Rtide"),
             ("yorp_radius", "Ryorp"), ("byorp_radius", "Rbyorp"), ("sun", "sun"),
             ("sun_inclination", "suni"), ("sun_node", "sunO"), ("sun_periapsis", "sunw"),
             ("sun_mean_anomaly", "sunM"), ("radiation_distance", "rad-"),
             ("flyby", "flyby-"), ("flyby_q", "q"), ("flyby_vinf", "vinf"),
             ("flyby_time", "tq"), ("flyby_inclination", "flyi"), ("flyby_node", "flyO"),
             ("flyby_periapsis", "flyw"))


#: The whole command line's parser factory (``ti_spinorbit.cli._parser``), set by the cli
#: package when it is imported: the package assembles the subcommands, which sit above this
#: module.
PARSER = None


def default_stem(args, prefix, system_name):
    """Default output name without extension: ``<prefix>_<system>`` and one ``_<tag><value>``
    per physics flag that differs from its default (:data:`NAME_TAGS`), so that runs with
    other parameters never share a file: ``sos_1991VH_ab1.06_o1000``."""
    defaults = vars(PARSER().parse_args([args.command]))
    # a system's name (a system file's included) is made shell-safe, [A-Za-z0-9._-] only:
    # no folder separators, parentheses, spaces or newlines ("sub/evil" -> "sub-evil")
    parts = [prefix, safe_part(system_name)]
    for dest, tag in NAME_TAGS:
        value = getattr(args, dest, None)
        if value is None or value == defaults.get(dest):
            continue
        if isinstance(value, (list, tuple)):
            items = [name_number(v) if isinstance(v, (int, float)) else str(v) for v in value]
            if dest == "grid":
                text = "x".join(items)
            elif len(items) > 3:
                text = f"{items[0]}-{items[-1]}n{len(items)}"
            else:
                text = "-".join(items)
        elif isinstance(value, bool):                # a switch: its tag alone
            text = ""
        elif isinstance(value, (int, float)):
            text = name_number(value, power=dest in ("rtol", "xtol"))
        else:
            text = str(value)
        parts.append(safe_part(tag + text, tidy=False))
    return "_".join(parts)


def name_number(value, power=False):
    """A number as a file name writes it: ``%g`` (``1e6``, ``0.0005``, ``1000``, ``-30``), with
    up to 12 significant digits where ``%g``'s 6 would change the value (``1.0000001``), never
    the binary noise of a double (``--rtol 1e-11`` is 9.999999999999999e-12: ``1e-11``); the
    exponent short and without "+" (``1e6``, ``1e-13``); ``power`` (tolerances) always as a
    power of ten (``1e-4``, ``2.5e-11``). Integers as they are."""
    if isinstance(value, int) and not isinstance(value, bool):
        return str(value)
    value = float(value)
    if power and value and math.isfinite(value):
        mantissa, exponent = f"{value:.12e}".split("e")
        text = f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"
    else:
        text = f"{value:g}"
        if float(text) != float(f"{value:.12g}"):
            text = f"{value:.12g}"
    return re.sub(r"e\+?(-?)0*(\d)", r"e\1\2", text)


# ---- output paths, claims and checkpoints -----------------------------------------------

def refuse_existing(args, path, flag):
    """A run never overwrites an existing output unless --overwrite: refused before any work,
    one line naming the file and the flag."""
    if not getattr(args, "overwrite", False) and os.path.exists(path):
        raise ValueError(f"{flag}: {path!r} already exists (an earlier run's output?); pass "
                         "--overwrite to replace it, or choose another --out")


#: The output names this process's running command owns (files.Claim), freed when it ends.
_CLAIMS = []


def claim_outputs(args, outputs):
    """Own the output names of this run (:func:`ti_spinorbit.files.claim`: a lock beside each
    one, held until the command ends): a second run with the same names, started while this
    one goes, is refused at once in one line (exit status 2) instead of silently replacing
    this run's files."""

    _CLAIMS.append(claim(outputs, command=getattr(args, "command_line", None)))


def release_outputs():
    """Free the output names of the command that ends (its lock files are deleted)."""
    while _CLAIMS:
        _CLAIMS.pop().release()


def _finishes_a_run(args, out, data, checkpoint):
    """True when this ``--resume`` command finishes an earlier run of the same command that
    was killed after writing its data file and before its figure: the data file exists, the
    figure does not, the checkpoint is still there and the data file records this very
    command line. The run then resumes from its checkpoint (nothing is integrated again),
    and rewrites the data file (the same numbers) and the figure, instead of being refused."""

    if not getattr(args, "resume", False) or checkpoint is None or os.path.exists(out) \
            or not os.path.isfile(data) or not os.path.isdir(checkpoint) \
            or not holds_checkpoint(checkpoint):
        return False
    try:
        meta = read_metadata(data)
    except (OSError, ValueError):
        return False
    return meta.get("command") == getattr(args, "command_line", None)


def output_paths(args, prefix, system_name):
    """(figure path, data path) from --out/--data or the defaults :func:`default_stem`.png
    /.npz, both checked writable (defaults included; names that fit, no dangling links),
    claimed for this run (:func:`claim_outputs`) and then not already there (unless
    --overwrite, or this --resume finishes the same command's run: :func:`_finishes_a_run`),
    and the checkpoint directory checked, before any work."""

    out = args.out or default_stem(args, prefix, system_name) + ".png"
    data = args.data or os.path.splitext(out)[0] + ".npz"
    out_flag = "--out" if args.out else "the figure (default --out)"
    data_flag = "--data" if args.data else "the data file (default --data)"
    check_output(out_flag, out, FIGURE_EXTENSIONS)
    check_output(data_flag, data, (".npz",))
    checkpoint = checkpoint_path(args, data)
    if checkpoint is not None:
        check_name("--checkpoint" if getattr(args, "checkpoint", None) is not None else
                   "the checkpoint (default: the --data path with .ckpt)", checkpoint)
    claim_outputs(args, [(out_flag, out), (data_flag, data)])     # before the checks below
    refuse_existing(args, out, out_flag)
    if not _finishes_a_run(args, out, data, checkpoint):
        refuse_existing(args, data, data_flag)
    if checkpoint is not None:   # a checkpoint that would be refused: before any work

        check_target(checkpoint, args.resume, args.overwrite_checkpoint, cli=True)
    return out, data


def checkpoint_path(args, data):
    """The checkpoint directory of a run (--checkpoint; with --resume alone the data path with
    .ckpt), or None for commands and runs without one."""
    if getattr(args, "checkpoint", None) is not None:
        return args.checkpoint
    if getattr(args, "resume", False):
        return os.path.splitext(data)[0] + ".ckpt"
    return None


def entry_options(args, data, bar):
    """An entry point's ``method``, ``integrator`` (the model) and ``run`` (progress bar,
    checkpoint and resume) from the flags; the directory was checked by :func:`output_paths`
    before any work."""

    # keep_checkpoint=True: the run keeps its checkpoint until the command's outputs are
    # written, then finish_checkpoint applies the library's rule (a kill before the figure
    # still resumes without integrating: _finishes_a_run)
    return {"method": args.method,
            "integrator": Integrator(model=args.model, order=getattr(args, "order", 4)),
            "run": Run(progress=bar, checkpoint=checkpoint_path(args, data), resume=args.resume,
                       overwrite=args.overwrite_checkpoint, keep_checkpoint=True)}


def finish_checkpoint(args, data):
    """After a run's outputs are written: the library's rule for a finished run's checkpoint
    (:func:`ti_spinorbit.engine.checkpoint.finish`, as ``Run(keep_checkpoint=...)``): removed
    unless --keep-checkpoint. Returns the line to print, or None."""
    path = checkpoint_path(args, data)
    if path is None:
        return None
    return finish(path, keep=getattr(args, "keep_checkpoint", False), flag="--keep-checkpoint")


# ---- progress ---------------------------------------------------------------------------

def progress_bar(args):
    """The command's reporter: a bar (terminal) or a line per 10 % (log) on stderr, compile
    announcements; nothing with --quiet, no bar with --no-progress."""
    return _progress.Progress(args.command, enabled=not args.quiet, delay=_progress.DELAY_S,
                              bar=not getattr(args, "no_progress", False))


# ---- writing results --------------------------------------------------------------------

def _save(result, path, extra):
    """Write a result with :func:`ti_spinorbit.output.io.save` (self-describing, loadable with
    ``io.load``; atomic: a killed write leaves no partial file), the command's own numbers in
    the metadata under ``extra``. The overwrite rule was applied before any work
    (:func:`output_paths`: --overwrite, or a --resume that finishes the same command's run)
    and the name is this run's since (:func:`claim_outputs`), hence ``overwrite=True``."""

    return save(result, path, extra=extra, overwrite=True)


class FigureError(RuntimeError):
    """The data file was written but the figure could not be (exit status 2)."""


def write_outputs(result, data, extra, figure, out):
    """The data file first, then the figure (``figure()`` returns its Axes), each written
    atomically (:mod:`ti_spinorbit.files`): a plotting failure never loses the numbers of a
    run, and a run killed between the two is finished by the same ``--resume`` command
    (:func:`_finishes_a_run`). Returns the paths written."""

    data = _save(result, data, extra)
    try:
        _plotting.save_figure(figure(), out)
    except Exception as exc:  # noqa: BLE001 - whatever Matplotlib raises, the data are safe
        raise FigureError(f"the figure {out!r} could not be written ({one_line(exc)}); "
                          f"the data are saved in {data}") from exc
    return out, data


# ---- the accuracy verdict ---------------------------------------------------------------

def accuracy_status(args, status, energy_drift, max_drift, what="members", stop_status=None):
    """Exit status of a run by its accuracy verdict. Members whose numbers cannot be trusted,
    "inaccurate" (drift above the limit, also when the member stopped early: an escape or a
    collision reached with the conservation laws broken), "non-finite" (NaN/Inf),
    "truncated" (the mutual potential's truncation error above its limit) and members
    stopped by their step budget, are counted on stderr (even with --quiet: it
    qualifies the results); returns EXIT_INACCURATE when there are any, unless
    --allow-inaccurate. Collisions, escapes and step underflows within the drift limit are
    outcomes of a start, reported per member, and do not change the exit status.
    ``stop_status`` (the kernels' codes) names what inaccurate members stopped for."""

    INACCURATE, NONFINITE, BUDGET = Status.INACCURATE, Status.NONFINITE, Status.STEP_BUDGET
    status = np.asarray(status)
    inaccurate = int(np.count_nonzero(status == INACCURATE))
    nonfinite = int(np.count_nonzero(status == NONFINITE))
    budget = int(np.count_nonzero(status == BUDGET))
    truncated = int(np.count_nonzero(status == Status.TRUNCATED))
    if not inaccurate and not nonfinite and not budget and not truncated:
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
    if truncated:
        force, torque = TRUNCATION_LIMITS
        parts.append(f"{truncated} of {status.size} {what} truncated: the mutual potential's "
                     f"next orders exceed {force:g} in force or {torque:g} in torque at their "
                     "closest approach")
    fix = " or ".join((["tighten --rtol"] if inaccurate or nonfinite or budget else [])
                      + (["raise --order"] if truncated else []))
    print(f"ti-spinorbit {args.command}: {'; '.join(parts)}; kept in the data file with their "
          "status" + ("" if allowed else f"; {fix}, or --allow-inaccurate to accept "
                                         f"(exit status {EXIT_INACCURATE})"), file=sys.stderr)
    return EXIT_OK if allowed else EXIT_INACCURATE
