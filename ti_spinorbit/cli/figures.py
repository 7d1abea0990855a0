"""``ti-spinorbit figures``: run the experiment scripts that reproduce the paper's studies
(needs a source checkout: the scripts live in experiments/)."""

import glob
import os
import subprocess
import sys
import time

from ..runtime import _KNOWN_ARCHS
from .common import say
from .options import Bounded, add_command

NAME = "figures"
EXAMPLES = """\
  ti-spinorbit figures --quick --only 1 4 --out out/"""


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "reproduce the paper's studies (experiments/study*.py)",
                    EXAMPLES, description=None)
    s.add_argument("--quick", action="store_true", help="small runs (minutes in all)")
    s.add_argument("--out", default="out", help="output folder (default out/)")
    s.add_argument("--only", nargs="+", metavar="N", type=Bounded(int, 1, 99),
                   help="study numbers, e.g. 4 6")
    s.add_argument("--experiments", default=None,
                   help="folder holding the study scripts (default: ./experiments or the "
                        "checkout this package was installed from)")
    s.add_argument("--arch", choices=_KNOWN_ARCHS, default=None,
                   help="Taichi arch for the scripts (sets TI_SPINORBIT_ARCH)")
    s.add_argument("--quiet", action="store_true", help="hide the scripts' output; print failures only")
    return s


def check(args):
    # --out is a folder here
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        raise ValueError(f"--out: {args.out!r} is a file; give a folder")


def _experiments_dir(given):
    # this file is ti_spinorbit/cli/figures.py: the checkout is two folders up
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for d in ([given] if given else [os.path.join(os.getcwd(), "experiments"),
                                    os.path.join(os.path.dirname(package), "experiments")]):
        if d and os.path.isfile(os.path.join(d, "_common.py")):
            return d
    raise ValueError("experiments folder not found: run from a source checkout or pass "
                     "--experiments PATH")


def run(args):
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
        say(args, f"{os.path.basename(script)}: {'ok' if rc == 0 else f'FAILED ({rc})'} "
                  f"in {time.perf_counter() - t0:.0f} s")
        sys.stdout.flush()
        if rc:
            failed.append(os.path.basename(script))
    if failed:
        raise RuntimeError(f"{len(failed)} studies failed: {', '.join(failed)}")
    return 0
