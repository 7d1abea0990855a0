"""Saving results with their parameters (NumPy ``.npz`` + JSON metadata).

Every array of a result goes into the archive under its own name; a ``metadata`` entry holds
JSON with all inputs and their units, the package version, tolerances, arch and timestamp,
so a file is self-describing without this package."""

import datetime
import json

import numpy as np

from . import runtime


def _metadata(result, kind, extra=None):
    from . import __version__

    meta = {
        "kind": kind,
        "package": "ti_spinorbit",
        "version": __version__,
        "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
        "arch": runtime.current_arch(),
        "rtol": getattr(result, "rtol", None),
        "atol": getattr(result, "atol", None),
        "order": getattr(result, "order", None),
        "orbits": getattr(result, "orbits", None),
        "systems": [s.describe() for s in result.systems],
        "units": {"theta_p": "deg", "thetadot_p": "mean motion n", "t": "s", "r": "m",
                  "a": "m", "e": "1", "initial_theta_p": "deg", "initial_thetadot_p": "n",
                  "alpha": "deg", "theta": "deg", "thetadot": "n", "energy": "J"},
    }
    if extra:
        meta.update(extra)
    return meta


def save_result(result, path, kind="section", extra=None):
    """Write a SectionResult or TimeSeriesResult to ``path`` (.npz); returns the path."""
    arrays = {k: np.asarray(v) for k, v in vars(result).items()
              if isinstance(v, np.ndarray)}
    if hasattr(result, "status_names"):
        arrays["status_names"] = np.array(result.status_names)
    meta = json.dumps(_metadata(result, kind, extra), indent=1, default=float)
    np.savez_compressed(path, metadata=np.array(meta), **arrays)
    return path


def read_metadata(path):
    """The JSON metadata of a saved result, as a dict."""
    with np.load(path) as data:
        return json.loads(str(data["metadata"]))
