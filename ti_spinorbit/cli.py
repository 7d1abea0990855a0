"""Command line: ``ti-spinorbit`` (console script) / ``python -m ti_spinorbit``.

Subcommands
-----------
systems   list the catalogued systems, or show one
section   surface of section of a catalogued system, written as PNG + .npz
map       chaos map (MEGNO, Lyapunov, classification) over a (θ_p, θ̇_p/n) grid, PNG + .npz
overlap   1:1 / 3:2 resonance-overlap scan over the elongation a/b, PNG + .npz
figures   run the experiment scripts that reproduce the paper's studies (needs a source
          checkout: the scripts live in experiments/)

Errors in the inputs print one line and exit with status 2 (no traceback)."""

import argparse
import sys

EXAMPLES = """examples:
  ti-spinorbit systems
  ti-spinorbit systems --show "2004 DC"
  ti-spinorbit section --system "1991 VH" --out sos_1991VH.png
  ti-spinorbit section --system "1991 VH" --elongation 1.06 --thetadot 1.13 1.63 1.70 1.78 --orbits 1000
  ti-spinorbit map --system "2004 DC" --grid 32 32 --orbits 300 --out dc_map.png
  ti-spinorbit overlap --system "1991 VH" --elongations 1.01 1.10 0.01 --orbits 500
"""


def _parser():
    p = argparse.ArgumentParser(prog="ti-spinorbit", description=(
        "Coupled spin-orbit dynamics of binary asteroids (full two-body problem, 4th-order "
        "mutual potential), ensembles integrated with Taichi."),
        epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("systems", help="list catalogued systems or show one")
    s.add_argument("--show", metavar="NAME", help="print one system's parameters")

    s = sub.add_parser("section", help="surface of section of a catalogued system (PNG + .npz)",
                       epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    s.add_argument("--system", default="1991 VH", help="catalogued system name (default: 1991 VH)")
    s.add_argument("--elongation", type=float, help="secondary a/b (default: catalogue value)")
    s.add_argument("--density", type=float, help="secondary density, kg/m^3")
    s.add_argument("--eccentricity", type=float, help="initial osculating eccentricity")
    s.add_argument("--theta-p", type=float, default=0.0, help="initial θ_p, deg (default 0)")
    s.add_argument("--thetadot", type=float, nargs="+",
                   help="initial θ̇_p/n values (default: the paper's starts for this system)")
    s.add_argument("--orbits", type=float, default=500, help="orbits to integrate (default 500)")
    s.add_argument("--rtol", type=float, default=1e-12, help="relative tolerance (default 1e-12)")
    s.add_argument("--arch", default=None, help="cpu (default) or cuda, vulkan, ...")
    s.add_argument("--out", default=None, help="PNG path (default sos_<system>.png)")
    s.add_argument("--data", default=None, help=".npz path (default: PNG path with .npz)")
    s.add_argument("--quiet", action="store_true", help="print nothing but errors")

    def system_flags(s):
        s.add_argument("--system", default="1991 VH", help="catalogued system name (default: 1991 VH)")
        s.add_argument("--eccentricity", type=float, help="initial osculating eccentricity")
        s.add_argument("--orbits", type=float, default=300, help="orbits per trajectory (default 300)")
        s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance (default 1e-10)")
        s.add_argument("--arch", default=None, help="cpu (default) or cuda, vulkan, ...")
        s.add_argument("--out", default=None, help="PNG path (the .npz is written beside it)")
        s.add_argument("--quiet", action="store_true", help="print nothing but errors")

    s = sub.add_parser("map", help="chaos map over (theta_p, thetadot_p/n): MEGNO, Lyapunov, classes",
                       epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    system_flags(s)
    s.add_argument("--elongation", type=float, help="secondary a/b (default: catalogue value)")
    s.add_argument("--density", type=float, help="secondary density, kg/m^3")
    s.add_argument("--grid", type=int, nargs=2, default=[32, 32], metavar=("NTHETA", "NTHETADOT"),
                   help="grid size (default 32 32)")
    s.add_argument("--thetadot-range", type=float, nargs=2, default=[0.2, 3.0], metavar=("LO", "HI"),
                   help="θ̇_p/n range (default 0.2 3.0)")

    s = sub.add_parser("overlap", help="resonance-overlap scan over a/b (1:1 and 3:2)",
                       epilog=EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter)
    system_flags(s)
    s.add_argument("--elongations", type=float, nargs=3, default=[1.01, 1.15, 0.01],
                   metavar=("START", "STOP", "STEP"), help="a/b scan (default 1.01 1.15 0.01)")

    s = sub.add_parser("figures", help="reproduce the paper's studies (experiments/study*.py)")
    s.add_argument("--quick", action="store_true", help="small runs (minutes in all)")
    s.add_argument("--out", default="out", help="output folder (default out/)")
    s.add_argument("--only", nargs="+", metavar="N", type=int, help="study numbers, e.g. 4 6")
    s.add_argument("--experiments", default=None,
                   help="folder holding the study scripts (default: ./experiments or the "
                        "checkout this package was installed from)")
    return p


def _base_meta(args, system):
    from .io import provenance

    return {**provenance(), "command": args.command, "orbits": args.orbits, "rtol": args.rtol,
            "system": system.describe()}


def _cmd_map(args):
    import os

    import numpy as np

    from . import catalog, init
    from .chaosmap import chaos_map
    from .io import write_archive
    from .plotting import save_figure

    system = catalog.system(args.system, elongation=args.elongation,
                            secondary_density=args.density, eccentricity=args.eccentricity)
    nt, nd = args.grid
    if not (1 <= nt <= 1024 and 1 <= nd <= 1024):
        raise ValueError(f"--grid sizes must lie in [1, 1024] (got {nt} {nd})")
    lo, hi = args.thetadot_range
    if not hi > lo:
        raise ValueError(f"--thetadot-range needs LO < HI (got {lo} {hi})")
    init(arch=args.arch)
    theta = (np.arange(nt) + 0.5) * 180.0 / nt
    cmap = chaos_map(system, theta, np.linspace(lo, hi, nd), orbits=args.orbits, rtol=args.rtol)
    out = args.out or f"map_{system.name.replace(' ', '')}.png"
    save_figure(cmap.plot(), out)
    meta = _base_meta(args, system)
    meta.update(chaotic_fraction=cmap.chaotic_fraction, units={"theta_p": "deg", "thetadot_p": "n",
                "lyapunov": "1/orbit", "megno": "1"})
    write_archive(os.path.splitext(out)[0] + ".npz",
               {"theta_p": cmap.theta_p, "thetadot_p": cmap.thetadot_p, "megno": cmap.megno,
                "lyapunov": cmap.lyapunov, "classification": cmap.classification,
                "mean_spin": cmap.mean_spin, "status": cmap.status}, meta)
    if not args.quiet:
        print(f"{system.name}: {nt} x {nd} map, {args.orbits:g} orbits: chaotic fraction "
              f"{cmap.chaotic_fraction:.3f} in {cmap.seconds:.1f} s; wrote {out}")
    return 0


def _cmd_overlap(args):
    import os

    import numpy as np

    from . import catalog, init
    from .io import write_archive
    from .overlap import overlap_threshold
    from .plotting import save_figure

    start, stop, step = args.elongations
    if not (step > 0 and stop >= start > 1.0):
        raise ValueError(f"--elongations needs 1 < START <= STOP and STEP > 0 (got {start} {stop} {step})")
    catalog.system(args.system, eccentricity=args.eccentricity)       # validates the name and e
    init(arch=args.arch)
    q = np.round(np.arange(start, stop + step / 2, step), 10)
    scan = overlap_threshold(args.system, elongations=q, eccentricity=args.eccentricity,
                             orbits=args.orbits, rtol=args.rtol)
    out = args.out or f"overlap_{scan.name.replace(' ', '')}.png"
    save_figure(scan.plot(), out)
    system = catalog.system(args.system, eccentricity=args.eccentricity)
    meta = _base_meta(args, system)
    meta.update(first_overlap=scan.first_overlap, elongation_ro=scan.elongation_ro,
                omega0_ro=scan.omega0_ro, decisions=[vars(d) for d in scan.decisions])
    write_archive(os.path.splitext(out)[0] + ".npz",
               {"elongations": scan.elongations, "overlaps": scan.overlaps}, meta)
    if not args.quiet:
        print(f"{scan.name} (e = {scan.eccentricity}): first overlap at a/b = {scan.first_overlap} "
              f"(analytic {scan.elongation_ro:.4f}) in {scan.seconds:.1f} s; wrote {out}")
        for d in scan.decisions:
            extra = f", connecting <Y> = {d.connecting_megno:.1f}" if d.overlap else ""
            print(f"  a/b = {d.elongation:.2f}: {'overlap' if d.overlap else 'separate'}{extra}")
    return 0


def _experiments_dir(given):
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    for d in ([given] if given else [os.path.join(os.getcwd(), "experiments"),
                                    os.path.join(os.path.dirname(here), "experiments")]):
        if d and os.path.isfile(os.path.join(d, "_common.py")):
            return d
    raise ValueError("experiments folder not found: run from a source checkout or pass "
                     "--experiments PATH")


def _cmd_figures(args):
    import glob
    import os
    import subprocess
    import time

    folder = _experiments_dir(args.experiments)
    scripts = sorted(glob.glob(os.path.join(folder, "study[0-9][0-9]_*.py")))
    if args.only:
        scripts = [s for s in scripts if int(os.path.basename(s)[5:7]) in args.only]
    if not scripts:
        raise ValueError(f"no study scripts selected in {folder}")
    out = os.path.abspath(args.out)
    failed = []
    for script in scripts:
        t0 = time.perf_counter()
        cmd = [sys.executable, script, "--out", out] + (["--quick"] if args.quick else [])
        rc = subprocess.call(cmd, cwd=folder)
        print(f"{os.path.basename(script)}: {'ok' if rc == 0 else f'FAILED ({rc})'} "
              f"in {time.perf_counter() - t0:.0f} s", flush=True)
        if rc:
            failed.append(os.path.basename(script))
    if failed:
        raise RuntimeError(f"{len(failed)} studies failed: {', '.join(failed)}")
    return 0


def _cmd_systems(args):
    from . import catalog

    if args.show:
        system = catalog.system(args.show)
        for k, v in system.describe().items():
            print(f"{k:24s} {v}")
        return 0
    print(f"{'name':12s} {'mass ratio':>10s} {'a (m)':>8s} {'e':>7s} {'a/b':>5s} {'omega0':>7s}")
    for name in catalog.names():
        s = catalog.system(name)
        ax = s.secondary.semi_axes
        print(f"{name:12s} {s.mass_ratio:10.2f} {s.a:8.0f} {s.e:7.4f} {ax[0] / ax[1]:5.2f} {s.omega0:7.3f}")
    return 0


def _cmd_section(args):
    import os

    import numpy as np

    from . import catalog, init, surface_of_section
    from .io import save_result
    from .plotting import plot_section, save_figure

    system = catalog.system(args.system, elongation=args.elongation,
                            secondary_density=args.density, eccentricity=args.eccentricity)
    init(arch=args.arch)
    starts = args.thetadot or catalog.section_starts(args.system)
    stem = "sos_" + system.name.replace(" ", "")
    out = args.out or f"{stem}.png"
    data = args.data or os.path.splitext(out)[0] + ".npz"
    result = surface_of_section(system, args.theta_p, np.array(starts), orbits=args.orbits,
                                rtol=args.rtol)
    save_figure(plot_section(result), out)
    save_result(result, data, kind="section")
    if not args.quiet:
        print(f"{system.name}: mass ratio {system.mass_ratio:.2f}, omega0 {system.omega0:.4f}, "
              f"{len(starts)} trajectories x {args.orbits:g} orbits in {result.seconds:.2f} s "
              f"({result.member_orbits_per_second:.0f} member-orbits/s)")
        for k, v in enumerate(starts):
            print(f"  thetadot_p/n = {v:5.2f}: {result.count[k]} crossings, status "
                  f"{result.status_names[k]}, energy drift {result.energy_drift[k]:.1e}")
        print(f"wrote {out} and {data}")
    return 0


def main(argv=None):
    args = _parser().parse_args(argv)
    handler = {"systems": _cmd_systems, "section": _cmd_section, "map": _cmd_map,
               "overlap": _cmd_overlap, "figures": _cmd_figures}[args.command]
    try:
        return handler(args)
    except (ValueError, TypeError, RuntimeError) as exc:
        print(f"ti-spinorbit {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
