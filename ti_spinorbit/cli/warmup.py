"""``ti-spinorbit warmup``: compile the kernel variants ahead of time (later runs start
without waiting)."""

import time

from .. import runtime
from ..engine.compiling import METHODS
from ..runtime import _KNOWN_ARCHS
from ..studies.warmup import warmup
from .common import init_taichi, say
from .options import add_command

NAME = "warmup"
EXAMPLES = """\
  ti-spinorbit warmup                                  # every variant (minutes, once)
  ti-spinorbit warmup --models planar --indicators off # what 'section' needs
  ti-spinorbit warmup --models planar --perturbed      # also with tides, YORP, BYORP"""


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "compile kernel variants ahead of time, so later runs "
                    "start at once", EXAMPLES)
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
    return s


def check(args):
    bad = [m for m in args.methods if m not in METHODS]
    if bad:
        raise ValueError(f"--methods must be among {', '.join(METHODS)} (got {bad[0]!r})")


def run(args):
    init_taichi(args)
    started = time.perf_counter()
    done = warmup(models=args.models, indicators=[v == "on" for v in args.indicators],
                  sampling=[v == "on" for v in args.sampling], methods=args.methods,
                  verbose=not args.quiet, perturbed=(False, True) if args.perturbed else (False,))
    compiled = sum(d["how"] == "compiled" for d in done)
    say(args, f"{len(done)} kernel variants ready ({compiled} compiled, "
              f"{len(done) - compiled} already in the cache) in "
              f"{time.perf_counter() - started:.1f} s; cache folder {runtime.cache_folder()}")
    return 0
