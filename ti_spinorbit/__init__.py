"""ti_spinorbit: coupled spin and orbital motion of binary asteroids, thousands at once.

The full two-body problem of two rigid bodies under their mutual gravity, with a
fourth-order mutual potential built from inertia integrals, integrated for whole ensembles
by Taichi kernels (one adaptive Cash-Karp loop per member). Reference science: Naidu &
Margot 2015, AJ 149:80.

Importing the package does not initialise Taichi, nor even import it (so it prints nothing):
the first computation does (CPU, f64), or call ``ti_spinorbit.init(arch=...)`` first.
"""

from pathlib import Path as _Path

# kernels/ lives at the top of the source tree and is installed as ti_spinorbit.kernels
# (pyproject package-dir). When this package is imported straight from a checkout (e.g.
# ``python -m pytest`` puts the checkout first on sys.path, ahead of an installed copy),
# look for the subpackage there as well; an installed package has its own kernels/ and
# never takes this branch.
_checkout = _Path(__file__).resolve().parent.parent
if not (_Path(__file__).parent / "kernels").is_dir() and (_checkout / "kernels" / "__init__.py").is_file():
    __path__.append(str(_checkout))        # noqa: F821 (the package's own module __path__)

from .system.bodies import Body, Ellipsoid, Sphere
from .system.shapes import Composite, Part, Polyhedron, read_shape
from .engine.evaluation import mutual_potential
from .runtime import init
from .engine.options import Integrator, Run
from .studies.section import SectionResult, TimeSeriesResult, surface_of_section, time_series
from .system.systems import G, BinarySystem, ImplausibleInputWarning, NearCircularWarning
from .model import analytic
from .model.truncation import TruncationTable, truncation
from .system import catalog
from .studies.chaosmap import chaos_map, parameter_map
from .studies.classify import classify_section
from .studies.libration import libration_amplitude, relaxed_libration
from .studies.overlap import overlap_threshold
from .output.io import ArchiveError, load, read_metadata, save
from .output.xarray_io import to_xarray
from .output import plotting as _plotting  # noqa: F401 (fills results.FIGURES: every .plot())
from .engine.results import Result, Status
from .system.initial import InitialState
from .model.perturbations import BYORP, YORP, Flyby, SolarTide, Tides
from .system.heliocentric import HeliocentricOrbit
from .studies.warmup import warmup
from ._version import __version__

__all__ = ["Body", "Ellipsoid", "Sphere", "Polyhedron", "read_shape", "Composite", "Part",
           "truncation", "TruncationTable",
           "BinarySystem", "G", "init", "mutual_potential",
           "Integrator", "Run",
           "ImplausibleInputWarning", "NearCircularWarning", "InitialState",
           "surface_of_section", "time_series", "SectionResult", "TimeSeriesResult", "catalog",
           "analytic", "classify_section", "relaxed_libration", "libration_amplitude",
           "overlap_threshold", "chaos_map", "parameter_map", "load", "save", "read_metadata",
           "ArchiveError", "to_xarray", "Result",
           "Status", "warmup", "Tides", "YORP", "BYORP", "SolarTide", "Flyby", "HeliocentricOrbit",
           "__version__"]
