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
status 2 (no traceback). Long runs draw a progress bar on stderr (:mod:`ti_spinorbit.engine.progress`:
a tqdm bar on a terminal, a line per 10 % elsewhere; ``--no-progress`` hides it), and the first
use of a kernel variant says "compiling kernels ... (first use only, about N s)"; compile time
is left out of elapsed times, ETAs and printed rates. ``--quiet`` prints nothing but errors.

File names: defaults carry every physics flag that differs from its default
(:func:`default_stem`: ``sos_1991VH_ab1.06.png`` for ``--elongation 1.06``). A run never
overwrites an existing output: it is refused before any work, naming the file, unless
``--overwrite``. The checkpoint directory of a run is removed once its outputs are written,
unless ``--keep-checkpoint``. Data files are self-describing ``.npz``
(:func:`ti_spinorbit.output.io.save`); figures are PNG (or PDF/SVG by the extension of ``--out``).

Outputs: every output path (and the Matplotlib backend) is checked before any work; the data
file is written before the figure, so a plotting failure never loses a run's numbers.

Accuracy: every member's energy and angular-momentum drift is held against a limit
(``--max-drift``, default scaled with the tolerance and run length; ti_spinorbit.engine.accuracy).
Members above it are "inaccurate": kept in the data file, counted on stderr, and the command
exits with status 3 (EXIT_INACCURATE) unless ``--allow-inaccurate``.

Exit status: 0 success; 1 a check failed (``energy``); 2 bad input or a failed run (one
line); 3 results written but some members inaccurate; 130 interrupted. ``--debug`` re-raises
any error with its full traceback instead of the one-line message.

Layout: this package holds one module per subcommand (``section.py``, ``map.py``, ...), each
with its flags (``add_parser``), the checks of its flags that need more than one value or the
system (``check``) and its handler (``run``) side by side; :mod:`.options` holds the flags
several subcommands share (and :class:`~.options.Bounded`, the ``type=`` that checks a numeric
flag's range while parsing), :mod:`.common` the steps they share once parsed (output paths
and claims, exit statuses, printing, the system, the accuracy verdict). Here: the parser
assembled from the subcommands, and :func:`main`."""

import argparse
import shlex
import sys
import warnings

from ..system.systems import ImplausibleInputWarning
from . import benchmark, common, energy, figures, libration, map, overlap, section, systems
from . import warmup
from .common import one_line, release_outputs
from .options import DEBUG_HELP, CommandLineError, Parser
# the names other modules and the tests import from ti_spinorbit.cli
from .common import (EXIT_CHECK_FAILED, EXIT_ERROR, EXIT_INACCURATE, EXIT_INTERRUPTED, EXIT_OK,
                     FIGURE_EXTENSIONS, NAME_TAGS, FigureError, default_stem)
from .energy import energy_check  # noqa: F401
from .libration import psi_phase  # noqa: F401
from .options import MAX_SPIN, perturbation_summary  # noqa: F401

__all__ = ["main", "check_args", "default_stem", "energy_check", "psi_phase",
           "perturbation_summary", "CommandLineError", "FigureError", "HANDLERS",
           "EXAMPLES_BY_COMMAND", "NAME_TAGS", "EXIT_OK", "EXIT_CHECK_FAILED", "EXIT_ERROR",
           "EXIT_INACCURATE", "EXIT_INTERRUPTED", "FIGURE_EXTENSIONS", "MAX_SPIN"]

#: The subcommands, in the order of the top-level help.
COMMANDS = (systems, section, map, overlap, libration, energy, benchmark, warmup, figures)
EXAMPLES_BY_COMMAND = {c.NAME: c.EXAMPLES for c in COMMANDS}
EXAMPLES = "examples:\n" + "\n".join(EXAMPLES_BY_COMMAND.values()) + "\n"
#: name -> handler; main dispatches through this dict (tests replace entries)
HANDLERS = {c.NAME: c.run for c in COMMANDS}
_CHECKS = {c.NAME: c.check for c in COMMANDS}


def _parser():
    p = Parser(prog="ti-spinorbit", description=(
        "Coupled spin-orbit dynamics of binary asteroids (full two-body problem, 4th-order "
        "mutual potential), ensembles integrated with Taichi."),
        epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--debug", action="store_true", help=DEBUG_HELP)
    sub = p.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(sub)
    return p


common.PARSER = _parser         # default_stem reads the flags' defaults through it


def check_args(args):
    """Check a parsed command line beyond what argparse checked (every numeric flag's range:
    :class:`~.options.Bounded`): the relations between values, the system, the
    perturbations and the output paths, by the subcommand's ``check``; ValueError naming
    the flag, the value and what is allowed."""
    _CHECKS[args.command](args)


def _checked_run(args):
    """check_args then the handler, with this package's input warnings (ImplausibleInputWarning:
    tiny bodies, a section at e ~ 0) printed once each as one line on stderr (none with
    --quiet); other warnings as Python shows them."""

    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, ImplausibleInputWarning):
            return shown(message, category, filename, lineno, file, line)
        if not getattr(args, "quiet", False):
            print(f"ti-spinorbit {args.command}: warning: {one_line(message)}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default", ImplausibleInputWarning)   # once per run, per place
        warnings.showwarning = show
        try:
            check_args(args)
            return HANDLERS[args.command](args)
        finally:
            release_outputs()


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
        print(one_line(exc), file=sys.stderr)
        return 2
    # recorded in every data file, quoted so that it can be pasted back into a shell
    args.command_line = shlex.join(["ti-spinorbit", *(sys.argv[1:] if argv is None else argv)])
    if getattr(args, "debug", False):
        return _checked_run(args)
    try:
        return _checked_run(args)
    except (ValueError, TypeError, RuntimeError, OSError) as exc:
        print(f"ti-spinorbit {args.command}: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_ERROR
    except MemoryError:
        print(f"ti-spinorbit {args.command}: error: out of memory; use fewer members "
              "(--grid, --members, --thetadot) or orbits", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        print(f"ti-spinorbit {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
