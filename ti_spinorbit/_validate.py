"""Input checks shared by every public entry point.

Each error names the parameter, the value received and the allowed range, so a researcher
can fix the call without reading the source."""

import difflib
import math
import numbers
import os

import numpy as np

from .layout import multipole as _multipole_layout
from . import units as _units

#: require_memory refuses a request above this share of the available memory (the rest is
#: left for the interpreter, Taichi and the operating system).
MEMORY_FRACTION = 0.8
GIB = 2.0**30

# ---- physical bounds, shared by the library and the command line -------------------------
# Outside them a run is not physics but a unit mistake, and the scaled quantities over- or
# underflow (Sphere(1e300, ...) overflowed in a**4; a density of 1e-300 gave NaN drifts).

#: Largest |θ̇_p/n| of a start (the command line's --thetadot range): a secondary spinning 100
#: times per orbit is no binary, and the step count grows with the spin (1e6 ran for minutes).
MAX_SPIN = 100.0
#: Largest primary spin rate 2π/(|P| n), units of n: wide binaries spin thousands of times
#: per orbit (a 2.5 h primary on a two-year orbit: 7000 n); the steps per orbit grow with the
#: spin, so beyond this one orbit costs minutes per member.
MAX_PRIMARY_SPIN = 1e5
#: Densities, kg/m^3: from silica aerogel (~1, anything lower is a unit mistake) to five
#: times osmium.
MIN_DENSITY, MAX_DENSITY = 1.0, 1e5
#: Bulk densities (m1 + m2)/(V1 + V2) that ``BinarySystem(orbital_period=)`` may imply, kg/m^3:
#: from a tenth of water (below the most porous comet nuclei and trans-Neptunian binaries
#: measured, 200-600) to just above osmium (22 590, the densest natural material). Their
#: ratio, 250, is below 24² = 576, so a period typed in hours for days, or seconds for hours
#: (3600²), always lands outside.
MIN_BULK_DENSITY, MAX_BULK_DENSITY = 100.0, 25000.0
#: Semimajor axis of a binary's heliocentric orbit, AU: inside Mercury's orbit to the
#: inner Oort cloud.
HELIOCENTRIC_A_RANGE = (0.05, 1e4)


def check_heliocentric(a_au, e, names=("heliocentric_a_au", "heliocentric_e")):
    """(a in AU, e) of a heliocentric orbit as floats, each checked and named, or ValueError;
    both None gives (None, None), one of them alone is refused."""
    if (a_au is None) != (e is None):
        raise ValueError(f"give both {names[0]} (AU) and {names[1]}, or neither")
    if a_au is None:
        return None, None
    return (require_positive_scalar(names[0], a_au, *HELIOCENTRIC_A_RANGE, "AU"),
            float(require_range(names[1], require_real(names[1], e), 0.0, 1.0)))


#: Lengths of a body (semi-axes, radius, bounding radius), m: a millimetre to ten solar radii.
MIN_LENGTH, MAX_LENGTH = 1e-3, 1e10
#: Mass of a body, kg: a microgram to 5e4 solar masses.
MIN_MASS, MAX_MASS = 1e-9, 1e35
#: Largest semimajor axis of the mutual orbit, m (67 au); the smallest is set by contact.
MAX_SEMIMAJOR_AXIS = 1e13
#: Largest mass ratio m1/m2 or m2/m1 of a binary: beyond it the lighter body's terms drown
#: in round-off of the scaled (m1 + m2 = 1) quantities.
MAX_MASS_RATIO = 1e12
#: Smallest principal moment of a body relative to its largest: a body collapsed onto a line
#: has a zero moment and its spin equations divide by it (two point masses gave NaN).
MIN_MOMENT_RATIO = 1e-6


def show(value, limit=80):
    """A one-line, bounded text of ``value`` for error messages: short sequences as lists,
    long arrays by their shape, text cut at ``limit`` characters."""
    try:
        if isinstance(value, np.ndarray):
            if value.size > 8:
                return f"array of shape {value.shape}"
            text = repr(value.tolist())
        elif isinstance(value, (list, tuple)) and len(value) > 8:
            return f"{type(value).__name__} of length {len(value)}"
        else:
            text = repr(value)
    except RecursionError:          # e.g. [[[...]]] nested thousands deep, from a JSON file
        return f"a {type(value).__name__} nested too deeply to show"
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


#: Words for a system file's keys -> the key (refuse_unknown_keys' suggestion).
KEY_SYNONYMS = {"eccentricity": "e", "ecc": "e", "a": "a_m", "semimajor_axis": "a_m",
                "semimajor_axis_m": "a_m", "mass": "mass_kg", "radius": "bounding_radius_m",
                "semi_axes": "semi_axes_m", "axes": "semi_axes_m"}


def refuse_unknown_keys(mapping, valid, where):
    """Raise ValueError on the first key of ``mapping`` not in ``valid``, naming it, ``where``
    it is (e.g. "'secondary'") and the nearest valid key (``difflib.get_close_matches``), or
    the valid keys when none is near: a misspelt key is refused rather than ignored."""
    for key in mapping:
        if key not in valid:
            # words people type for a key, which spelling similarity would map elsewhere
            # ("eccentricity" is nearest to "heliocentric_e")
            named = KEY_SYNONYMS.get(str(key).lower())
            close = [named] if named in valid else \
                difflib.get_close_matches(str(key), list(valid), n=1, cutoff=0.6)
            hint = (f"did you mean {close[0]!r}?" if close else
                    f"the keys are {', '.join(map(repr, valid))}")
            raise ValueError(f"unknown key {show(key)} in {where}: {hint} (unknown keys are "
                             "refused, not ignored)")


def _fmt(x):
    return f"{x:g}" if isinstance(x, float) else str(x)


def require_real(name, value, unit=None):
    """``value`` as a float, or TypeError naming the parameter unless it is ONE real number
    (int, float, NumPy real scalar or 0-d array): not text, None, bool, complex, a list or an
    array of several values. An astropy Quantity is converted to ``unit`` (a unit text of
    :mod:`ti_spinorbit.units`: "m", "kg", "s", "deg", "(units of n)", ...; None or "" for
    dimensionless), or refused in one line when its dimension does not fit."""
    if _units.is_quantity(value):
        value = _units.to_plain(name, value, "" if unit is None else unit)
    if isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)):
        return float(value)
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        return float(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        raise TypeError(f"{name} must be a single number, not a {type(value).__name__} "
                        f"(got {show(value)})")
    if isinstance(value, (bool, np.bool_)):
        what = "a number, not a bool"
    elif isinstance(value, (complex, np.complexfloating)):
        what = "a real number, not complex"
    else:
        what = "a number"
    raise TypeError(f"{name} must be {what} (got {show(value)})")


def require_scalar(name, value, low=-math.inf, high=math.inf, *, low_open=False,
                   high_open=False, unit=""):
    """``value`` as a float: one real number (:func:`require_real`, else TypeError), finite,
    in the interval (ends as flagged, else ValueError "<name> must lie in [low, high] <unit>
    (got ...)"). Infinite ends only check finiteness. A Quantity is converted to ``unit``
    first (:func:`require_real`); a plain angle in degrees ("deg", "degrees") that looks
    like radians gets the degree hint (:mod:`ti_spinorbit.units`)."""
    value = _units.to_plain(name, value, unit)
    number = require_real(name, value, unit)
    ok = math.isfinite(number)
    ok = ok and (number > low if low_open else number >= low)
    ok = ok and (number < high if high_open else number <= high)
    if not ok:
        if low == -math.inf and high == math.inf:
            raise ValueError(f"{name} must be finite (got {show(value)})")
        lb = "(" if low_open else "["
        hb = ")" if high_open else "]"
        unit = f" {unit}" if unit else ""
        raise ValueError(f"{name} must lie in {lb}{_fmt(low)}, {_fmt(high)}{hb}{unit} "
                         f"(got {show(value)})")
    return number


def require_positive_scalar(name, value, low, high, unit=""):
    """One real number (TypeError otherwise) that is finite and > 0 (require_positive's
    message) and lies in [low, high] (require_scalar's message); returns it as a float,
    a Quantity converted to ``unit`` first (:func:`require_real`)."""
    value = _units.to_plain(name, value, unit)
    require_real(name, value)
    require_positive(name, value)
    return require_scalar(name, value, low, high, unit=unit)


#: Highest truncation order of the mutual potential (the order-N kernels' tables).
MAX_ORDER = _multipole_layout.MAX_ORDER


def require_order(order):
    """The truncation order of the mutual potential as an int: 0 (point masses) or 2 to
    MAX_ORDER (1 adds nothing to 0: first moments vanish about the centre of mass). Orders
    up to 4 use the hand-written kernels, higher ones the table-driven ones."""
    if isinstance(order, (bool, np.bool_, str, bytes)) or np.ndim(order) != 0:
        raise TypeError(f"order must be an integer, 0 or in [2, {MAX_ORDER}] (got {show(order)})")
    try:
        value = float(order)
    except (TypeError, ValueError):
        raise TypeError(f"order must be an integer, 0 or in [2, {MAX_ORDER}] "
                        f"(got {show(order)})") from None
    if not (value == 0 or (value.is_integer() and 2 <= value <= MAX_ORDER)):
        raise ValueError(f"order must be 0 or an integer in [2, {MAX_ORDER}] (got {show(order)})")
    return int(value)


def require_callable(name, value):
    """None or a callable, else TypeError naming the parameter (a progress callback that is
    not callable would fail only after the first window of a long run)."""
    if value is not None and not callable(value):
        raise TypeError(f"{name} must be a callable or None (got {show(value)})")
    return value


def require_bool(name, value):
    """``value`` as a bool, or a one-line TypeError naming ``name``: a flag must be True or
    False (a str such as "yes" is truthy and would be taken silently)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False (got {show(value)})")
    return bool(value)


def require_spin(name, value, system=None):
    """Spin rates in units of n (scalar or array): finite with |value| <= MAX_SPIN. Returns
    ``value``; a Quantity converted to units of n first (dimensionless, ``units.n``, or an
    angular rate divided by the mean motion of ``system`` when there is one:
    :func:`ti_spinorbit.units.to_plain`)."""
    value = _units.to_plain(name, value, "n", system=system)
    arr = _as_floats(name, value)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {show(value)})")
    if np.any(np.abs(arr) > MAX_SPIN):
        worst = float(arr.flat[np.argmax(np.abs(arr))])
        raise ValueError(f"{name} must lie in [{-MAX_SPIN:g}, {MAX_SPIN:g}] (units of the mean "
                         f"motion n; got {worst:g})")
    return value


class InsufficientMemoryError(ValueError, MemoryError):
    """A request for more memory than the machine has available. A ValueError (bad input:
    too many members, orbits or samples) that ``except MemoryError`` also catches."""


def _as_floats(name, value):
    """``value`` as a float64 array, or TypeError naming the parameter (text is not a number,
    even where NumPy would parse it). A Quantity must be dimensionless here (the callers
    that take a unit convert it first), else :class:`~ti_spinorbit.units.UnitMismatchError`."""
    if _units.is_quantity(value):
        value = _units.to_plain(name, value, "")
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):                    # ragged nesting
        kind = "O"
    if value is None or isinstance(value, (str, bytes)) or kind in "USV":
        raise TypeError(f"{name} must be a number (got {show(value)})")
    if kind == "c":
        raise TypeError(f"{name} must be a real number, not complex (got {show(value)})")
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number (got {show(value)})") from None


def require_finite(name, value):
    """Raise ValueError unless every element of ``value`` is a finite number."""
    arr = _as_floats(name, value)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {show(value)})")
    return value


def require_positive(name, value):
    """Raise ValueError unless ``value`` (scalar or array) is finite and > 0."""
    arr = _as_floats(name, value)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(f"{name} must be a finite number > 0 (got {show(value)})")
    return value


def require_range(name, value, low, high, *, low_open=False, high_open=True):
    """Raise ValueError unless low <= value < high (ends as flagged), for scalars or arrays."""
    arr = _as_floats(name, value)
    ok = np.isfinite(arr)
    ok &= (arr > low) if low_open else (arr >= low)
    ok &= (arr < high) if high_open else (arr <= high)
    if not np.all(ok):
        lb = "(" if low_open else "["
        hb = ")" if high_open else "]"
        raise ValueError(f"{name} must lie in {lb}{low}, {high}{hb} (got {show(value)})")
    return value


def require_count(name, value, minimum=1, maximum=math.inf):
    """Raise ValueError unless ``value`` is an integer in [minimum, maximum]."""
    arr = _as_floats(name, value)
    number = float(arr) if arr.ndim == 0 else math.nan
    if isinstance(value, (bool, np.bool_)) or not number.is_integer() or not minimum <= number <= maximum:
        raise ValueError(f"{name} must be an integer in [{minimum}, {maximum}] (got {show(value)})")
    return int(value)


def available_memory():
    """Memory available to a new allocation without swapping, bytes: psutil's
    ``virtual_memory().available`` when psutil is installed (every platform), else
    :func:`_os_available_memory`; None when neither says (ti_spinorbit.engine.resources
    gives the decision)."""
    got = _psutil_available_memory()
    return got if got is not None else _os_available_memory()


def _psutil_available_memory():
    """psutil's available memory, bytes, or None without psutil (or where it cannot say)."""
    try:
        import psutil
    except ImportError:
        return None
    try:
        return int(psutil.virtual_memory().available)
    except Exception:  # noqa: BLE001 - a platform psutil cannot read: the fallback decides
        return None


def _os_available_memory():
    """Without psutil: ``MemAvailable`` of /proc/meminfo (Linux), else free physical pages ×
    page size (``os.sysconf``), else None when the platform says neither."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024          # the kernel reports kB
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def require_memory(what, nbytes, advice, available=None):
    """Raise :class:`InsufficientMemoryError` (a ValueError and a MemoryError) when ``what``
    needs more than MEMORY_FRACTION of the available memory: "<what> needs X GiB, Y GiB
    available; <advice>". ``available`` (bytes) defaults to :func:`available_memory`; when
    that is unknown nothing is checked. Returns ``nbytes``."""
    nbytes = float(nbytes)
    if available is None:
        available = available_memory()
    if available is not None and nbytes > MEMORY_FRACTION * available:
        raise InsufficientMemoryError(
            f"{what} needs {nbytes / GIB:.3g} GiB, {available / GIB:.3g} GiB available; {advice}")
    return nbytes
