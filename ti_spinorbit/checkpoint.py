"""Checkpoints of an ensemble run, written after every window, so a long run survives Ctrl-C,
kill or a crash and resumes with identical results.

A checkpoint is a directory:

* ``state.npz``: everything the kernels carry from one window to the next (state, Kahan
  compensations, step proposals, first-stage derivatives, shadow trajectories and MEGNO
  sums, counters, status, the initial diagnostics), small (≈ 100 numbers per member) and
  rewritten after every window;
* ``records-NNNNNN.npz``: the crossings and samples recorded during window NNNNNN, written
  once. Records are appended, never rewritten, so the I/O of a run is linear in its length
  (rewriting all records every window would be quadratic: a 64 × 64 × 500-orbit map holds
  ≈ 0.5 GB of crossings).

Resuming continues the exact same sequence of steps: a resumed run equals an uninterrupted
one bit for bit (``tests/test_checkpoint.py``).

Safety rules:

* every file is written beside its final name and moved over it with ``os.replace`` (atomic
  on POSIX and Windows); the records of a window are written before the state that counts
  them, so a run killed at any instant leaves a consistent checkpoint (a records file the
  state does not count yet is ignored and overwritten);
* the state records the run settings and a SHA-256 digest of the inputs (parameter rows,
  initial states, end times); resuming with anything different raises ValueError naming what
  differs, never reuses the files silently;
* a directory that cannot be read as a checkpoint raises ValueError saying so.
"""

import json
import os

import numpy as np

FORMAT = "ti_spinorbit checkpoint"
FORMAT_VERSION = 2
STATE = "state.npz"
_ARRAYS = ("y", "t", "h", "status", "counters", "yc", "tc", "f", "next_sample", "shadow",
           "shadow_f", "ind", "diag_start")
_RECORDS = ("events", "samples")


def _records_name(launch):
    return f"records-{launch:06d}.npz"


def _atomic_savez(path, **arrays):
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as fh:
        np.savez(fh, **arrays)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def _pack(chunks_by_member, width):
    """{member: [arrays]} -> (members, counts, data) arrays."""
    members = sorted(chunks_by_member)
    parts = [np.concatenate(chunks_by_member[i]) for i in members]
    data = np.concatenate(parts) if parts else np.zeros((0, width))
    return (np.array(members, dtype=np.int64), np.array([len(p) for p in parts], dtype=np.int64),
            data)


def save(path, settings, fingerprint, state, new_records):
    """Append this window's records and rewrite the state (see ``Ensemble.run``).

    ``new_records`` maps "events" and "samples" to ``{member: [arrays]}`` recorded since the
    previous save; ``state["launches"]`` counts the windows done including this one."""
    from . import __version__

    path = os.fspath(path)
    os.makedirs(path, exist_ok=True)
    width = state["y"].shape[1] + 1
    launch = state["launches"] - 1
    records = {}
    for name in _RECORDS:
        records[name + "_members"], records[name + "_counts"], records[name + "_data"] = \
            _pack(new_records[name], width)
    _atomic_savez(os.path.join(path, _records_name(launch)), **records)
    header = {"format": FORMAT, "format_version": FORMAT_VERSION, "version": __version__,
              "settings": settings, "fingerprint": fingerprint, "members": len(state["y"]),
              "launches": state["launches"], "seconds": state["seconds"], "width": width}
    _atomic_savez(os.path.join(path, STATE), header=np.array(json.dumps(header)),
                  **{name: state[name] for name in _ARRAYS})


def _read(path, what):
    try:
        with np.load(path, allow_pickle=False) as data:
            return {k: data[k] for k in data.files}
    except Exception as exc:  # zip, pickle or key errors all mean the same thing
        raise ValueError(f"checkpoint {os.path.dirname(path)!r}: {what} is damaged or not a "
                         f"checkpoint ({exc}); delete the directory to start the run afresh") from exc


def load(path, settings, fingerprint):
    """The saved state of a run with these ``settings`` and input ``fingerprint``, or None
    when ``path`` does not exist. Raises ValueError for a damaged or mismatched checkpoint."""
    path = os.fspath(path)
    if not os.path.exists(path):
        return None
    if not os.path.isdir(path) or not os.path.exists(os.path.join(path, STATE)):
        raise ValueError(f"checkpoint {path!r} is not a {FORMAT} directory (no {STATE}); "
                         "choose another path or delete it")
    arrays = _read(os.path.join(path, STATE), STATE)
    try:
        header = json.loads(str(arrays.pop("header")))
    except Exception as exc:
        raise ValueError(f"checkpoint {path!r}: {STATE} is damaged or not a checkpoint "
                         f"({exc}); delete the directory to start the run afresh") from exc
    if header.get("format") != FORMAT:
        raise ValueError(f"checkpoint {path!r} is not a {FORMAT}")
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
    missing = [k for k in _ARRAYS if k not in arrays]
    if missing:
        raise ValueError(f"checkpoint {path!r} is damaged: {STATE} lacks {', '.join(missing)}")
    state = {name: np.array(arrays[name]) for name in _ARRAYS}
    n = len(state["y"])
    for name in _RECORDS:
        state[name] = [[] for _ in range(n)]
    state["launches"] = int(header["launches"])
    state["seconds"] = float(header["seconds"])
    for launch in range(state["launches"]):
        file = os.path.join(path, _records_name(launch))
        if not os.path.exists(file):
            raise ValueError(f"checkpoint {path!r} is damaged: {_records_name(launch)} is "
                             "missing; delete the directory to start the run afresh")
        rec = _read(file, _records_name(launch))
        for name in _RECORDS:
            members, counts = rec[name + "_members"], rec[name + "_counts"]
            for i, part in zip(members, np.split(rec[name + "_data"], np.cumsum(counts)[:-1])):
                state[name][int(i)].append(part)
    return state
