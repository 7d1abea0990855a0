"""Units: plain numbers in the documented units, or astropy Quantities converted once, here.

Every length, mass, density, angle, time or rate the package takes is a plain number in
the unit its docstring names (m, kg, kg/m³, degrees, s, units of the mean motion n,
orbital periods), exactly as before this module existed. Wherever a docstring says
"float or Quantity" an ``astropy.units.Quantity`` is accepted as well: :func:`to_plain`
converts it to the documented unit and checks its dimension (a length where a mass is
taken is refused in one line naming the parameter, the unit given and the unit expected).
Results give their fields back with units through ``result.quantity(name)``
(:func:`as_quantity`). The units of every parameter and field: docs/units.md; the
design of this module: docs/design.md, "Units at the interface".

Decisions
---------
* astropy stays optional: it is imported only when a value carries a ``.unit`` (or when
  :func:`as_quantity` or one of the units below is asked for), so plain numbers never
  import it, and a package without astropy behaves as it always did.
* Two units of the package are not astropy units: rates "in units of n" (the mean motion
  of the system's initial osculating orbit) and lengths of time "in orbits" (its period
  2π/n). They are defined as two custom astropy units, :data:`n` and :data:`orbit`
  (``ti_spinorbit.units.n``, ``ti_spinorbit.units.orbit``), irreducible, so a result's
  spin rate prints as ``1.2 n`` rather than a bare number, and
  :func:`equivalencies` converts them to rad/s and s for one system
  (``q.to(u.rad / u.s, equivalencies=ti_spinorbit.units.equivalencies(system))``).
* A rate "in units of n" (θ̇_p, spin_x, ...) may be given as a plain number, as a
  dimensionless Quantity, in :data:`n`, or as an angular rate (rad/s, deg/day, cycle/h),
  which is divided by the system's n where the function has one system; where it has
  none (or several of different n) an angular rate is refused in one line. A frequency
  in Hz or 1/s is refused everywhere: it does not say radians or turns.
* Likewise ``orbits`` takes a number, a dimensionless Quantity, :data:`orbit`, or a time
  (divided by the system's period 2π/n where there is one system).
* Angles in degrees refuse a dimensionless Quantity (is it degrees or radians?): give
  ``u.deg`` or ``u.rad``.
* Conversion factors within a few units in the last place of a short decimal
  (999.9999999999999 for g/cm³ -> kg/m³) are taken as that decimal, and a factor below 1
  whose inverse is such a number divides, so ``2.5 * u.g / u.cm**3`` gives exactly
  2500.0 and ``1.5 * u.km`` exactly 1500.0, bit for bit the plain numbers.

The degree hint
---------------
An angle the package takes in degrees (θ_p, tilts, obliquities, inclinations) given as a
plain number that looks like radians gets a one-line :class:`DegreesExpectedWarning`
(the value is still read as degrees). "Looks like radians" (:func:`looks_like_radians`):
every finite value lies within [-2π, 2π], not all are zero, and the largest magnitude is
within 5e-5 (relative) of a simple fraction kπ/m of π (m in 1, 2, 3, 4, 6; up to 2π), or,
for an evenly spaced grid of at least three values, its largest value plus one step is
(``np.linspace(0, 2 * np.pi, 50, endpoint=False)``). So ``np.pi / 2``, ``1.5708``,
``np.linspace(0, 2 * np.pi, 50)`` warn, while 0, 1, 5, 5.5, 30, 45, 90, 180 degrees or
``np.linspace(0, 5, 11)`` do not (no number with one or two decimals in (0, 360] is
that close to a fraction of π). A Quantity never warns.
"""

import math
import os
import sys
import warnings

import numpy as np

__all__ = ["to_plain", "degrees", "plain_fields", "as_quantity", "astropy_unit", "equivalencies",
           "looks_like_radians", "is_quantity", "UnitMismatchError", "DegreesExpectedWarning",
           "ImplausibleInputWarning", "INSTALL_HINT"]

#: What to run for the optional dependency (the ``units`` extra).
INSTALL_HINT = "pip install ti-spinorbit[units]"


class ImplausibleInputWarning(UserWarning):
    """An input that is allowed but probably not meant: bodies or an orbit far smaller than
    any asteroid (kilometres typed as metres?), an angle in degrees that looks like radians
    (:class:`DegreesExpectedWarning`), or a surface of section at e ≈ 0 where the
    pericentre is ill-defined.

    Examples
    --------
    Bodies and an orbit given in kilometres where metres are expected run, with a warning:

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     tiny = tso.BinarySystem(tso.Sphere(0.6, density=1581),
    ...                             tso.Ellipsoid(0.294, 0.196, 0.19, density=2618), a=3.3, e=0.05)
    >>> any(issubclass(w.category, tso.ImplausibleInputWarning) for w in caught)
    True
    """


class DegreesExpectedWarning(ImplausibleInputWarning):
    """A plain angle that looks like radians (a simple fraction of π up to 2π) where degrees
    are expected (module docstring, "The degree hint"); it is still read as degrees."""


class UnitMismatchError(ValueError):
    """A Quantity whose dimension does not fit the parameter (a time where a length is
    taken); a ValueError, one line naming the parameter, the unit given and the one
    expected."""


# ---- the package's unit texts ------------------------------------------------------------
#: Unit text of the validators and result fields -> astropy unit string ("n" and "orbit"
#: are the package's own units, see the module docstring; "1" is dimensionless).
_TEXT = {"m": "m", "kg": "kg", "kg/m^3": "kg / m3", "s": "s", "AU": "AU", "deg": "deg",
         "degrees": "deg", "rad/s": "rad / s", "m/s": "m / s", "J": "J",
         "kg m^2 s^-1": "kg m2 / s", "kg m^2": "kg m2", "N m": "N m", "1": "",
         "": "", "n": "n", "(units of n)": "n", "units of n": "n", "mean motion n": "n",
         "orbit": "orbit", "orbits": "orbit", "orbital periods": "orbit",
         "1/orbit": "1 / orbit", "member x orbital periods": "orbit",
         "km": "km", "km/s": "km / s", "h": "h"}
#: Result unit texts that count things: dimensionless numbers.
_COUNTS = ("members", "calls", "steps", "crossings", "launches", "potential truncation order")
#: What each package unit is called in messages.
_SAY = {"deg": "degrees (deg)", "n": "units of the mean motion n", "orbit": "orbital periods",
        "": "a dimensionless number"}
_DEGREE_UNITS = ("deg", "degrees")

_cache = {}


def is_quantity(value) -> bool:
    """True when ``value`` carries a unit (an astropy Quantity), or is a list or tuple
    whose first element does; checked without importing astropy."""
    if hasattr(value, "unit") and hasattr(value, "to_value"):
        return True
    return isinstance(value, (list, tuple)) and len(value) > 0 and \
        hasattr(value[0], "unit") and hasattr(value[0], "to_value")


def _astropy():
    """astropy.units, or ImportError naming the extra to install."""
    try:
        import astropy.units as u
    except ImportError:
        raise ImportError(f"units need astropy, which is not installed: {INSTALL_HINT} "
                          "(or pip install astropy)") from None
    return u


def _own_units():
    """(n, orbit): the package's two custom astropy units, made once."""
    if "n" not in _cache:
        u = _astropy()
        _cache["n"] = u.def_unit(
            "n", doc="mean motion n of a system's initial osculating orbit (a rate: "
                     "ti_spinorbit.units.equivalencies(system) converts it to rad/s)")
        _cache["orbit"] = u.def_unit(
            "orbit", doc="one orbital period 2π/n of a system's initial osculating orbit "
                         "(ti_spinorbit.units.equivalencies(system) converts it to s)")
    return _cache["n"], _cache["orbit"]


def __getattr__(name):              # ti_spinorbit.units.n, .orbit: astropy on first use
    if name in ("n", "orbit"):
        return dict(zip(("n", "orbit"), _own_units()))[name]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _key(text):
    """The unit text's head: "deg (roll, pitch)" -> "deg", "1 (relative)" -> "1"."""
    text = str(text).strip()
    if text in _TEXT:
        return text
    head = text.split(" (")[0].split(":")[0].strip()
    return head


def astropy_unit(text):
    """The astropy unit of a package unit text ("m", "deg", "mean motion n",
    "orbital periods", "1/orbit", "1 (relative)", "kg m^2 s^-1", ...), or None when the text
    is no physical unit (a status code, a name, a flag, a state row of mixed units).
    Counts (members, steps, ...) are dimensionless."""
    u = _astropy()
    key = _key(text)
    if key in _COUNTS:
        return u.dimensionless_unscaled
    spelled = _TEXT.get(key)
    if spelled is None:
        return None
    if spelled == "":
        return u.dimensionless_unscaled
    n, orbit = _own_units()
    if spelled == "n":
        return n
    if spelled == "orbit":
        return orbit
    if spelled == "1 / orbit":
        return orbit ** -1
    return u.Unit(spelled)


def _mean_motion(system):
    """n (rad/s) of ``system``: one BinarySystem, or a list of systems that share one n;
    None when there is none (or they differ, or ``system`` is a catalogue name: the entry
    points resolve names first, so that this module, below the systems, never imports
    them)."""
    if system is None or isinstance(system, str):
        return None
    if isinstance(system, (list, tuple)):
        rates = {_mean_motion(s) for s in system}
        return rates.pop() if len(rates) == 1 else None
    rate = getattr(system, "mean_motion", None)
    return float(rate) if isinstance(rate, (int, float)) else None


def equivalencies(system):
    """astropy equivalencies of one system: :data:`n` <-> rad/s (its mean motion), and
    :data:`orbit` <-> s and 1/:data:`orbit` <-> 1/s (its period 2π/n), e.g.
    ``result.quantity("thetadot_p").to(u.rad / u.s, equivalencies=equivalencies(system))``."""
    u = _astropy()
    n, orbit = _own_units()
    rate = _mean_motion(system)
    if rate is None:
        raise ValueError(f"equivalencies need one BinarySystem (or catalogue name) with a "
                         f"mean motion (got {type(system).__name__})")
    period = 2.0 * math.pi / rate
    return [(n, u.rad / u.s, lambda x: x * rate, lambda x: x / rate),
            (orbit, u.s, lambda x: x * period, lambda x: x / period),
            (orbit ** -1, u.s ** -1, lambda x: x / period, lambda x: x * period)]


def _snap(scale):
    """``scale``, or the 12-digit decimal it is within 4 ulp of (999.9999999999999 ->
    1000.0): a conversion factor as a person would write it."""
    short = float(f"{scale:.12g}")
    return short if abs(short - scale) <= 4.0 * math.ulp(scale) else scale


def _expected(unit_text, target):
    say = _SAY.get(_TEXT.get(_key(unit_text), _key(unit_text)))
    if say is not None:
        return say
    kind = str(target.physical_type)
    return f"{target} (a {kind})" if kind != "unknown" else str(target)


def _scaled(values, scale):
    """values × scale, or values / (1/scale) when that inverse is a short decimal (mm -> m
    divides by 1000, as the plain number would be computed)."""
    scale = _snap(float(scale))
    if scale == 1.0:
        return values
    if 0.0 < abs(scale) < 1.0:
        inverse = _snap(1.0 / scale)
        if inverse == float(f"{inverse:.12g}"):
            return values / inverse
    return values * scale


def to_plain(name, value, unit, *, system=None):
    """``value`` in the package's ``unit`` ("m", "kg", "kg/m^3", "s", "AU", "deg",
    "rad/s", "m/s", "n", "orbit", "1" or "" for dimensionless).

    A plain value (no ``.unit``) comes back unchanged (an angle in degrees may get the
    degree hint, :func:`degrees`). A Quantity (or a list of them) is converted, as a float
    when it is a scalar, else a float64 array, or :class:`UnitMismatchError` naming ``name``,
    the unit given and the one expected. ``system`` (a BinarySystem, catalogue name or
    list sharing one n) lets a rate in rad/s stand for units of n and a time for orbits."""
    if value is None:
        return None
    if not is_quantity(value):
        if unit in _DEGREE_UNITS:
            _hint(name, value)
        return value
    u = _astropy()
    if isinstance(value, (list, tuple)):
        try:
            value = u.Quantity(value)
        except (TypeError, ValueError, u.UnitsError) as exc:
            raise UnitMismatchError(f"{name}: a list of Quantities must share one dimension "
                                    f"({exc})") from None
    key = _key(unit)
    target = astropy_unit(key)
    if target is None:
        raise ValueError(f"{name}: no unit known for {unit!r}")
    given = value.unit
    equiv = []
    n, orbit = _own_units()
    if target in (n, orbit):
        if given.physical_type == "dimensionless":
            return _out(_scaled(np.asarray(value.value, dtype=np.float64),
                                given.to(u.dimensionless_unscaled)))
        if given != target and given.is_equivalent(u.rad / u.s if target is n else u.s):
            rate = _mean_motion(system)
            if rate is None:
                own = _TEXT[key]
                raise UnitMismatchError(
                    f"{name} in {given} needs one system's mean motion to become {_SAY[own]}, "
                    f"and there is none here (no system, or systems of different n): give it "
                    f"in {_SAY[own]} (a plain number, u.dimensionless_unscaled or "
                    f"ti_spinorbit.units.{own})")
            equiv = equivalencies(system)
    elif key in _DEGREE_UNITS and given.physical_type == "dimensionless":
        raise UnitMismatchError(f"{name} must be an angle, u.deg or u.rad (got a dimensionless "
                                f"Quantity: is it degrees or radians?); a plain number is "
                                f"degrees")
    try:
        scale = given.to(target, 1.0, equivalencies=equiv)
    except u.UnitsError:
        if target is n:
            raise UnitMismatchError(f"{name} must be in units of the mean motion n (a plain "
                                    f"number, u.dimensionless_unscaled or ti_spinorbit.units.n) "
                                    f"or an angular rate such as u.rad / u.s (got a Quantity in "
                                    f"{given}; a frequency in Hz does not say radians or turns)") \
                from None
        if target == u.dimensionless_unscaled:
            raise UnitMismatchError(f"{name} must be dimensionless (a plain number or "
                                    f"u.dimensionless_unscaled; got a Quantity in {given})") \
                from None
        raise UnitMismatchError(f"{name} must be in {_expected(unit, target)} or a unit "
                                f"convertible to it (got a Quantity in {given})") from None
    return _out(_scaled(np.asarray(value.value, dtype=np.float64), scale))


def _out(values):
    values = np.asarray(values, dtype=np.float64)
    return float(values) if values.ndim == 0 else values


def plain_fields(obj, **fields):
    """Replace each Quantity among the named fields of a (frozen) dataclass ``obj`` by its
    plain value in the unit given (``plain_fields(self, a="m", e="")``), before the field
    checks run; plain values stay as given (an angle in degrees after the degree hint)."""
    for name, unit in fields.items():
        value = getattr(obj, name)
        plain = to_plain(name, value, unit)
        if plain is not value:
            object.__setattr__(obj, name, plain)


def degrees(name, value):
    """An angle in degrees: a Quantity converted (:func:`to_plain`), a plain value unchanged
    after the degree hint (module docstring)."""
    return to_plain(name, value, "deg")


# ---- the degree hint -------------------------------------------------------------------
#: Simple fractions of π, k/m for m in (1, 2, 3, 4, 6), up to 2.
_FRACTIONS = np.array(sorted({k / m for m in (1, 2, 3, 4, 6) for k in range(1, 2 * m + 1)}))
#: Relative distance from a fraction of π within which a value counts as radians.
RADIAN_TOLERANCE = 5e-5


def _near_fraction(x):
    return bool(np.any(np.abs(x / math.pi - _FRACTIONS) <= RADIAN_TOLERANCE * _FRACTIONS))


def looks_like_radians(value) -> bool:
    """The rule of the degree hint (module docstring): True when every finite value lies in
    [-2π, 2π], not all are zero, and the largest magnitude is within 5e-5 of kπ/m (m in 1,
    2, 3, 4, 6), or an evenly spaced grid of at least three values ends one step short of
    such a fraction."""
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError):
        return False
    if arr.dtype.kind not in "iuf":                  # text, complex, objects: not angles
        return False
    arr = arr.astype(np.float64).ravel()
    arr = arr[np.isfinite(arr)]
    if arr.size == 0:
        return False
    top = float(np.abs(arr).max())
    if top == 0.0 or top > 2.0 * math.pi * (1.0 + RADIAN_TOLERANCE):
        return False
    if _near_fraction(top):
        return True
    if arr.size >= 3:
        grid = np.sort(arr)
        step = np.diff(grid)
        if step[0] > 0 and np.allclose(step, step[0], rtol=1e-6, atol=0.0):
            return _near_fraction(abs(grid[-1] + step[0])) or _near_fraction(abs(grid[0] - step[0]))
    return False


def _hint(name, value):
    if looks_like_radians(value):
        arr = np.asarray(value, dtype=np.float64)
        shown = f"{float(arr):.6g}" if arr.ndim == 0 else \
            f"an array up to {float(np.nanmax(np.abs(arr))):.6g}"
        warnings.warn(f"{name} = {shown} looks like radians, but {name} is in degrees (read as "
                      f"degrees): pass np.degrees({name}), or a Quantity ({name} * u.rad)",
                      DegreesExpectedWarning, stacklevel=_user_level())


_PACKAGE = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _user_level():
    """stacklevel of the first frame outside the package (and dataclasses' generated
    ``__init__``), for the caller of _hint's caller's warn."""
    frame, level = sys._getframe(1), 1
    while frame is not None and (frame.f_code.co_filename.startswith(_PACKAGE)
                                 or (frame.f_code.co_filename == "<string>"
                                     and frame.f_code.co_name == "__init__")):
        frame, level = frame.f_back, level + 1
    return level


# ---- results ---------------------------------------------------------------------------
def as_quantity(name, value, unit_text):
    """``value`` as an astropy Quantity in the unit ``unit_text`` names (:func:`astropy_unit`);
    ValueError when the text is no physical unit, ImportError without astropy."""
    u = _astropy()
    unit = astropy_unit(unit_text)
    if unit is None:
        raise ValueError(f"{name} holds {unit_text!r}, not a physical quantity: read it as "
                         f"an attribute instead")
    if value is None:
        raise ValueError(f"{name} is empty (None) in this result")
    try:
        return u.Quantity(np.asarray(value, dtype=np.float64), unit, copy=True)
    except (TypeError, ValueError):                # ragged: one array per entry
        return [u.Quantity(np.asarray(v, dtype=np.float64), unit, copy=True) for v in value]


def field_quantity(result, name, table):
    """``result``'s field ``name`` as a Quantity (``Result.quantity``); ``table`` is its
    {field: unit text} (``results.units``), records' fields as "field/name"."""
    _astropy()
    if not isinstance(name, str) or name not in table or not _physical(table[name]):
        valid = ", ".join(k for k, v in table.items() if _physical(v))
        why = (f"{name!r} holds {table[name]!r}, not a physical quantity (read it as an "
               f"attribute)" if isinstance(name, str) and name in table else
               f"no field {name!r} with a unit")
        raise ValueError(f"{type(result).__name__}: {why}; the fields with a unit are {valid}")
    if "/" in name:
        field, sub = name.split("/", 1)
        value = [getattr(r, sub) for r in getattr(result, field)]
    else:
        value = getattr(result, name)
    return as_quantity(name, value, table[name])


def _physical(text):
    key = _key(text)
    return key in _COUNTS or key in _TEXT
