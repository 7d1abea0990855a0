"""Saving results with their parameters (NumPy ``.npz`` + JSON metadata).

Every array of a result goes into the archive under its own name; a ``metadata`` entry holds
JSON with all inputs and their units, the package version, tolerances, arch and timestamp,
so a file is self-describing without this package."""

import datetime
import json

import numpy as np

from . import runtime


def provenance():
    """Package, version, Taichi arch and UTC timestamp: the common head of every metadata."""
    from . import __version__

    return {"package": "ti_spinorbit", "version": __version__, "arch": runtime.current_arch(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat()}


def _json_default(x):
    """JSON for what json does not know: numpy scalars and arrays, anything else as text."""
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return str(x)


def write_archive(path, arrays, metadata):
    """Write ``arrays`` and the ``metadata`` dict (as JSON) to a compressed ``.npz``."""
    np.savez_compressed(path, metadata=np.array(json.dumps(metadata, indent=1, default=_json_default)),
                        **{k: np.asarray(v) for k, v in arrays.items()})
    return path


def _metadata(result, kind, extra=None):
    meta = {
        "kind": kind,
        **provenance(),
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
    return write_archive(path, arrays, _metadata(result, kind, extra))


def read_metadata(path):
    """The JSON metadata of a saved result, as a dict."""
    with np.load(path) as data:
        return json.loads(str(data["metadata"]))
