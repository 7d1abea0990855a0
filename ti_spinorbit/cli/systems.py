"""``ti-spinorbit systems``: list the catalogued systems, or show one (a name or a file)."""

from ..display import fields
from ..files import write_json   # atomic: a killed write leaves no partial file
from ..system import catalog
from .common import check_output, check_system_flags, is_system_file, load_system_file, say
from .options import add_command

NAME = "systems"
EXAMPLES = """\
  ti-spinorbit systems
  ti-spinorbit systems --show "2004 DC"
  ti-spinorbit systems --out catalogue.json"""


def add_parser(subparsers):
    s = add_command(subparsers, NAME, "list catalogued systems or show one", EXAMPLES,
                    description="List the catalogued systems (Naidu & Margot 2015, Table 1).")
    s.add_argument("--show", metavar="NAME", help="print one system's parameters (a "
                                                   "catalogued name, or a .json system file)")
    s.add_argument("--out", default=None, help="also write the descriptions (SI) to this .json")
    s.add_argument("--quiet", action="store_true", help="print nothing (with --out)")
    return s


def check(args):
    check_system_flags(args)
    check_output("--out", args.out, (".json",))


def _body_size(body):
    """A body's size for the systems table: "R 600" for a sphere, else its semi-axes a x b x c
    (m), else its bounding radius."""
    axes = getattr(body, "semi_axes", None)
    if axes is None:
        return f"<= {body.bounding_radius:.0f}"
    if axes[0] == axes[1] == axes[2]:
        return f"R {axes[0]:.0f}"
    return " x ".join(f"{x:.0f}" for x in axes)


def run(args):
    if args.show:
        system = load_system_file(args.show, "--show") if is_system_file(args.show) \
            else catalog.system(args.show)
        if args.out:
            write_json(args.out, system.describe(), indent=1)
        if not args.quiet:               # a table: nested entries indented, no dict reprs
            for line in fields(system.describe()):
                print(line)
            # what an observed period measures: the circular orbit under the figures' force
            print(f"{'circular_period_h':24s} {system.circular_period() / 3600.0:.6g} "
                  "(order 4; orbital_period_h is the Keplerian one)")
        return 0
    systems = [catalog.system(name) for name in catalog.names()]
    if args.out:
        write_json(args.out, [s.describe() for s in systems], indent=1)
    width = max([12] + [len(s.name) for s in systems])      # "Didymos (radar shape)"
    say(args, f"{'name':{width}s} {'mass ratio':>10s} {'a (m)':>8s} {'e':>7s} {'a/b':>5s} "
              f"{'omega0':>7s} {'P_orb (h)':>9s}  {'primary (m)':>17s}  "
              f"{'secondary semi-axes (m)':>23s}")
    for s in systems:
        ax = s.secondary.semi_axes
        say(args, f"{s.name:{width}s} {s.mass_ratio:10.2f} {s.a:8.0f} {s.e:7.4f} "
                  f"{ax[0] / ax[1]:5.2f} {s.omega0:7.3f} {s.orbital_period / 3600:9.2f}  "
                  f"{_body_size(s.primary):>17s}  {_body_size(s.secondary):>23s}")
    return 0
