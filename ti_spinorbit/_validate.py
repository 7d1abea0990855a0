"""Input checks shared by every public entry point.

Each error names the parameter, the value received and the allowed range, so a researcher
can fix the call without reading the source."""

import math

import numpy as np


def require_finite(name, value):
    """Raise ValueError unless every element of ``value`` is a finite number."""
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (got {value!r})")
    return value


def require_positive(name, value):
    """Raise ValueError unless ``value`` (scalar or array) is finite and > 0."""
    arr = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(f"{name} must be a finite number > 0 (got {value!r})")
    return value


def require_range(name, value, low, high, *, low_open=False, high_open=True):
    """Raise ValueError unless low <= value < high (ends as flagged), for scalars or arrays."""
    arr = np.asarray(value, dtype=np.float64)
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
    if isinstance(value, bool) or not float(value).is_integer() or not minimum <= value <= maximum:
        raise ValueError(f"{name} must be an integer in [{minimum}, {maximum}] (got {value!r})")
    return int(value)
