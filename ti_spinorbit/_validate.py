"""Input checks shared by every public entry point.

Each error names the parameter, the value received and the allowed range, so a researcher
can fix the call without reading the source."""

import math
import os

import numpy as np

#: require_memory refuses a request above this share of the available memory (the rest is
#: left for the interpreter, Taichi and the operating system).
MEMORY_FRACTION = 0.8
GIB = 2.0**30


class InsufficientMemoryError(ValueError, MemoryError):
    """A request for more memory than the machine has available. A ValueError (bad input:
    too many members, orbits or samples) that ``except MemoryError`` also catches."""


def _as_floats(name, value):
    """``value`` as a float64 array, or TypeError naming the parameter (text is not a number,
    even where NumPy would parse it)."""
    if isinstance(value, (str, bytes)) or np.asarray(value).dtype.kind in "USV":
        raise TypeError(f"{name} must be a number (got {value!r})")
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number (got {value!r})") from None


def require_finite(name, value):
    """Raise ValueError unless every element of ``value`` is a finite number."""
    arr = _as_floats(name, value)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {value!r})")
    return value


def require_positive(name, value):
    """Raise ValueError unless ``value`` (scalar or array) is finite and > 0."""
    arr = _as_floats(name, value)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(f"{name} must be a finite number > 0 (got {value!r})")
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
        raise ValueError(f"{name} must lie in {lb}{low}, {high}{hb} (got {value!r})")
    return value


def require_count(name, value, minimum=1, maximum=math.inf):
    """Raise ValueError unless ``value`` is an integer in [minimum, maximum]."""
    arr = _as_floats(name, value)
    number = float(arr) if arr.ndim == 0 else math.nan
    if isinstance(value, bool) or not number.is_integer() or not minimum <= number <= maximum:
        raise ValueError(f"{name} must be an integer in [{minimum}, {maximum}] (got {value!r})")
    return int(value)


def available_memory():
    """Memory available to a new allocation without swapping, bytes: ``MemAvailable`` of
    /proc/meminfo (Linux), else free physical pages × page size (``os.sysconf``), else None
    when the platform says neither."""
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
