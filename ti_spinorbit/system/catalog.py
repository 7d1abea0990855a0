"""Catalogue of the binary systems of Naidu & Margot 2015, Table 1 (packaged data), and
"Didymos (radar shape)": Didymos with its radar shape model as the primary.

The numbers live in ``data/systems.json`` with their source notes; this module turns an
entry into a :class:`~ti_spinorbit.system.systems.BinarySystem` following the paper's secondary
prescription (docs/physics.md §7): a = sqrt(ab · a/b), b = sqrt(ab / (a/b)), mass
ρ_s (4/3) π ab c, whatever the elongation. The primary is a sphere (``R_p``, ``rho_p``),
except where the entry gives ``primary`` as a packaged shape model
(``{"shape": "polyhedron", "packaged": ..., "density": ..., "order": ...}``,
:func:`~ti_spinorbit.system.shapes.packaged_shape`) with its ``primary_spin_period_h``; that
polyhedron is built once per process (it does not depend on the secondary's options).

Names are matched ignoring case and everything but letters and digits: "Didymos (radar
shape)", "didymos_radar_shape" and "DidymosRadarShape" are the same entry.

Examples
--------
>>> tso.catalog.names()[:4]
['test', '1991 VH', '2003 YT1', '2004 DC']
>>> vh = tso.catalog.system("1991 VH")
>>> round(vh.omega0, 3)
1.074
"""

import json
import math
from functools import lru_cache
from importlib import resources

from .._validate import (MAX_DENSITY, MIN_DENSITY, require_positive_scalar, require_range,
                         require_real, show)
from .heliocentric import HeliocentricOrbit
from .bodies import DATA_ORDER, Ellipsoid, Sphere
from .shapes import packaged_shape
from .systems import BinarySystem

HOUR = 3600.0

#: θ̇_p/n starts of a surface of section where the paper shows none (θ_p = 0).
DEFAULT_SECTION_STARTS = (0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)


@lru_cache(maxsize=1)
def _data():
    text = resources.files("ti_spinorbit.data").joinpath("systems.json").read_text()
    return json.loads(text)["systems"]


def names():
    """Catalogued system names, in table order."""
    return list(_data())


def entry(name):
    """The raw catalogue entry (a copy), SI units as stored."""
    return dict(_data()[_resolve(name)])


def _normal(name):
    """A name without case and without anything but letters and digits."""
    return "".join(ch for ch in name.lower() if ch.isalnum())


def _resolve(name):
    table = _data()
    if not isinstance(name, str):
        raise TypeError(f"system name must be a string (got {name!r})")
    key = {_normal(k): k for k in table}.get(_normal(name))
    if key is None:
        raise ValueError(f"unknown system {name!r}; known systems: {', '.join(table)}")
    return key


def system(name, elongation=None, secondary_density=None, eccentricity=None) -> BinarySystem:
    """A catalogued system as a BinarySystem, optionally with the elongation a/b (in [1, 10],
    and small enough that b >= c), secondary density ρ_s (kg m^-3, in [1, 1e5]) or
    eccentricity (0 <= e < 1, and small enough that the bodies clear each other at
    pericentre) changed.

    The energy-test case ("test") has fixed shapes; only its eccentricity may change."""
    key = _resolve(name)
    d = _data()[key]
    e = d["e"] if eccentricity is None else eccentricity
    require_real("eccentricity", e)
    require_range("eccentricity", e, 0.0, 1.0)
    for label, value in (("elongation", elongation), ("secondary_density", secondary_density)):
        if value is not None:
            require_real(label, value)
    try:
        return _system(key, d, e, elongation, secondary_density)
    except ValueError as exc:
        if eccentricity is None or not str(exc).startswith("bodies overlap at pericentre"):
            raise
        system = _system(key, d, 0.0, elongation, secondary_density)
        contact = system.primary.bounding_radius + system.secondary.bounding_radius
        raise ValueError(f"eccentricity must lie in [0, {1.0 - contact / system.a:.4g}) for {key}: "
                         f"at {eccentricity:g} the bodies overlap at pericentre (a(1-e) = "
                         f"{system.a * (1 - eccentricity):.6g} m, sum of bounding radii "
                         f"{contact:.6g} m)") from None


def _system(key, d, e, elongation, secondary_density):
    if key == "test":
        if elongation is not None or secondary_density is not None:
            raise ValueError("the 'test' system has fixed shapes: only eccentricity may be changed")
        p = d["primary"]
        primary = Ellipsoid(*p["semi_axes_m"], p["density"], name="test primary")
        secondary = Ellipsoid(*d["secondary_semi_axes_m"], d["rho_s"], name="test secondary")
        return BinarySystem(primary, secondary, d["a_m"], e,
                            primary_spin_period=d["primary_spin_period_h"] * HOUR, name="test",
                            heliocentric_orbit=heliocentric_orbit(key))
    q = d["elongation"] if elongation is None else elongation
    require_range("elongation", q, 1.0, 10.0, high_open=False)
    rho_s = d["rho_s"] if secondary_density is None else secondary_density
    require_positive_scalar("secondary_density", rho_s, MIN_DENSITY, MAX_DENSITY, "kg/m^3")
    a_s, b_s, c_s = math.sqrt(d["ab"] * q), math.sqrt(d["ab"] / q), d["c"]
    if c_s > b_s:
        raise ValueError(f"elongation {q} makes b = {b_s:.4g} m < c = {c_s} m for {key}: "
                         f"the largest allowed is {d['ab'] / c_s**2:.4g}")
    mass_s = rho_s * 4.0 / 3.0 * math.pi * d["ab"] * c_s
    secondary = Ellipsoid(a_s, b_s, c_s, mass=mass_s, name=f"{key} secondary")
    period = d.get("primary_spin_period_h")
    return BinarySystem(_primary(key, d), secondary, d["a_m"], e,
                        primary_spin_period=None if period is None else period * HOUR, name=key,
                        heliocentric_orbit=heliocentric_orbit(key))


def _primary(key, d):
    """A sphere (R_p, rho_p), or the packaged shape model the entry names."""
    p = d.get("primary")
    if p is None:
        return Sphere(d["R_p"], d["rho_p"], name=f"{key} primary")
    return _shape_primary(key, p["packaged"], p["density"], p.get("order", DATA_ORDER))


@lru_cache(maxsize=None)
def _shape_primary(key, packaged, density, order):
    # a Body is immutable (its offset and rotation arrays read-only), so one serves all
    return packaged_shape(packaged, density=density, name=f"{key} primary", order=order)


def secondary_spin_period(name):
    """Initial spin period of the secondary in s where the catalogue gives one, else None."""
    h = _data()[_resolve(name)].get("secondary_spin_period_h")
    return None if h is None else h * HOUR


def section_starts(name):
    """Initial θ̇_p/n of the paper's surfaces of section for this system (θ_p = 0), or a
    default spread over 0.5-2.5 where the paper shows none."""
    values = _data()[_resolve(name)].get("section_thetadot_p")
    return list(values) if values else list(DEFAULT_SECTION_STARTS)


def heliocentric_orbit(name):
    """The system's heliocentric orbit (a :class:`~ti_spinorbit.HeliocentricOrbit`, ecliptic
    elements, with the binary's pole where published) where catalogued, else None."""
    d = _data()[_resolve(name)].get("heliocentric_orbit")
    return None if d is None else HeliocentricOrbit(**d)


def as_system(system, allow_list=False):
    """The ``system`` argument of every entry point as a BinarySystem: a catalogue name
    (str, e.g. "1991 VH") is looked up (unknown names raise ValueError listing the known
    ones), a BinarySystem is returned as it is; with ``allow_list`` a list of either gives a
    list of systems. Anything else: TypeError naming what is accepted."""
    if isinstance(system, str):
        return globals()["system"](system)
    if isinstance(system, BinarySystem):
        return system
    if allow_list and isinstance(system, (list, tuple)) and system \
            and all(isinstance(s, (str, BinarySystem)) for s in system):
        return [as_system(s) for s in system]
    accepted = "a BinarySystem or a catalogue name" + (" or a non-empty list of them"
                                                         if allow_list else "")
    raise TypeError(f"system must be {accepted} (got {show(system)})")
