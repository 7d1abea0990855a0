"""Checkpoints of an ensemble run, written after every window, so a long run survives Ctrl-C,
kill or a crash and resumes with identical results.

What is saved is everything the kernels carry from one window to the next (state, Kahan
compensations, step proposals, first-stage derivatives, shadow trajectories and MEGNO sums,
counters, status) plus everything recorded so far. Resuming therefore continues the exact
same sequence of steps: a resumed run equals an uninterrupted one bit for bit
(``tests/test_checkpoint.py``).

Safety rules:

* the file is written beside its final name and moved over it with ``os.replace``, which is
  atomic on POSIX and Windows: a run killed while writing leaves the previous checkpoint;
* a checkpoint records the run settings and a SHA-256 digest of the inputs (parameter rows,
  initial states, end times); resuming with anything different raises ValueError naming what
  differs, never reuses the file silently;
* a file that cannot be read as a checkpoint raises ValueError saying so.

Format: an uncompressed ``.npz`` with a JSON ``header`` entry (``format``,
``format_version``, package ``version``, ``settings``, ``fingerprint``, ``members``).
"""

import json
import os

import numpy as np

FORMAT = "ti_spinorbit checkpoint"
FORMAT_VERSION = 1
_ARRAYS = ("y", "t", "h", "status", "counters", "yc", "tc", "f", "next_sample", "shadow",
           "shadow_f", "ind", "diag_start")
_RECORDS = ("events", "samples")


def save(path, settings, fingerprint, state):
    """Write ``state`` (see ``Ensemble.run``) to ``path`` atomically."""
    from . import __version__

    header = {"format": FORMAT, "format_version": FORMAT_VERSION, "version": __version__,
              "settings": settings, "fingerprint": fingerprint, "members": len(state["y"]),
              "launches": state["launches"], "seconds": state["seconds"]}
    arrays = {name: state[name] for name in _ARRAYS}
    for name in _RECORDS:
        chunks = [np.concatenate(c) if c else np.zeros((0, state["y"].shape[1] + 1))
                  for c in state[name]]
        arrays[name + "_count"] = np.array([len(c) for c in chunks], dtype=np.int64)
        arrays[name + "_data"] = np.concatenate(chunks)
    path = os.fspath(path)
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as fh:
        np.savez(fh, header=np.array(json.dumps(header)), **arrays)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def load(path, settings, fingerprint):
    """The saved state of a run with these ``settings`` and input ``fingerprint``, or None
    when ``path`` does not exist. Raises ValueError for a damaged or mismatched file."""
    path = os.fspath(path)
    if not os.path.exists(path):
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            header = json.loads(str(data["header"]))
            arrays = {k: data[k] for k in data.files if k != "header"}
    except Exception as exc:  # zip, JSON, pickle or key errors all mean the same thing
        raise ValueError(f"checkpoint {path!r} is damaged or not a checkpoint ({exc}); "
                         "delete it to start the run afresh") from exc
    if header.get("format") != FORMAT:
        raise ValueError(f"checkpoint {path!r} is not a {FORMAT} file")
    if header.get("format_version") != FORMAT_VERSION:
        raise ValueError(f"checkpoint {path!r} has format version {header.get('format_version')}"
                         f", this package reads version {FORMAT_VERSION}; delete it to start afresh")
    saved = header.get("settings", {})
    differ = [f"{k} (checkpoint {saved.get(k)!r}, now {v!r})" for k, v in settings.items()
              if saved.get(k) != v]
    if differ:
        raise ValueError(f"checkpoint {path!r} belongs to a run with other settings: "
                         + "; ".join(differ))
    if header.get("fingerprint") != fingerprint:
        raise ValueError(f"checkpoint {path!r} belongs to a run with other inputs (systems, "
                         "initial conditions or integration time differ); delete it or use "
                         "another checkpoint path")
    missing = [k for k in _ARRAYS + tuple(r + s for r in _RECORDS for s in ("_count", "_data"))
               if k not in arrays]
    if missing:
        raise ValueError(f"checkpoint {path!r} is damaged: missing {', '.join(missing)}")
    state = {name: np.array(arrays[name]) for name in _ARRAYS}
    for name in _RECORDS:
        counts = arrays[name + "_count"]
        parts = np.split(arrays[name + "_data"], np.cumsum(counts)[:-1])
        state[name] = [[p] if len(p) else [] for p in parts]
    state["launches"] = int(header["launches"])
    state["seconds"] = float(header["seconds"])
    return state
