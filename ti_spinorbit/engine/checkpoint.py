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
* **one writer**: a run holds an exclusive lock on the directory (``lock``, a
  :class:`filelock.FileLock`) from before it reads the checkpoint until it returns, raises
  or is interrupted (KeyboardInterrupt included); ``lock-owner.json`` beside it names the
  holder (pid, host, start time, command line). A second run on the same directory is
  refused at once, never made to wait: :class:`CheckpointLocked`, one line naming the
  holder. Stale locks cannot block: the lock is an OS file lock (``flock``), which the OS
  releases the instant its process dies (``kill -9`` included), so a later run simply takes
  it; where the file system has no OS locks, filelock falls back to a marker file that it
  breaks when the holder's pid is gone on the same host (a holder on another host that
  died leaves a marker: delete ``lock`` by hand, as the message says);
* **no overwrite**: ``checkpoint=DIR`` without ``resume=True`` on a directory that holds a
  checkpoint (a ``state.npz``, of this run or any other) raises :class:`CheckpointExists`
  and touches nothing, unless ``overwrite_checkpoint=True`` (CLI ``--overwrite-checkpoint``)
  says to replace it. A directory left by a kill before the first state (records files or
  ``*.tmp-PID`` files only) holds no checkpoint: a run (resumed or not) starts afresh in it;
  stray ``*.tmp-*`` files are removed whenever a run takes the lock;
* **tidy**: the checkpoint of a run that finished is removed when the run returns, unless
  ``keep_checkpoint=True`` (:class:`ti_spinorbit.Run`; CLI ``--keep-checkpoint``): one rule,
  :func:`finish`, applied by :func:`claim` to a single run, by :meth:`Launches.owned` to the
  ``DIR`` of a computation of several launches once its last launch has succeeded (the
  launches themselves never remove their ``launch-kkk``: a resume reuses finished ones), and
  by the command line once its outputs are written (so that a kill before its figure still
  resumes without integrating). A run that raises or is interrupted (KeyboardInterrupt,
  kill) keeps its checkpoint, so that ``resume=True`` continues it;
* **read-only checkpoints**: a checkpoint in a directory that cannot be written (a read-only
  folder or mount, an archive of finished runs) resumes without a lock and without writing
  anything when its run is finished; an unfinished one is refused before any work, in one
  line (its next window could not be saved: copy the directory or make it writable);
* ``checkpoint=`` must be a path (str or os.PathLike) or None: anything else is a one-line
  TypeError naming ``checkpoint``;
* the state records the run settings, a SHA-256 digest of the inputs (parameter rows,
  initial states, end times) and the writing package version; resuming with anything
  different raises :class:`CheckpointError` (a ValueError) naming what differs, never reuses
  the files silently (a checkpoint of another package version is refused: its step
  sequence may differ, so the resumed result would not equal an uninterrupted run);
* **damage is one line**: the state holds the SHA-256 digest of every records file, checked
  before the file is parsed; every array is read with its sizes checked against the zip
  directory first (:class:`ti_spinorbit.output.io.ArchiveError` rules), and shapes and counts are
  checked against the state. Any damage (truncated, flipped bytes, renamed or missing
  entries or files, swapped or edited records files) raises :class:`CheckpointDamaged`
  whose message starts ``checkpoint damaged:`` and says to delete the directory; never a
  KeyError, IndexError or BadZipFile. The CLI prints it as one line with exit status 2.
"""

import contextlib
import datetime
import hashlib
import json
import os
import re
import socket
import sys
import tempfile
import zipfile

import filelock
import numpy as np

from .._version import __version__
from ..npzfile import _DAMAGE, _Entries
from .results import Status

FORMAT = "ti_spinorbit checkpoint"
#: 3: the state holds the records files' SHA-256 digests and is checked on resume;
#: 4: the input fingerprint is one digest per part (systems, initial states, integration
#: times, perturbations), so that a refused resume names what changed.
FORMAT_VERSION = 4
STATE = "state.npz"
#: The lock file and the holder's identity beside it.
LOCK = "lock"
OWNER = "lock-owner.json"
_ARRAYS = ("y", "t", "h", "status", "counters", "yc", "tc", "f", "next_sample", "shadow",
           "shadow_f", "ind", "diag_start")
#: Arrays with one row per member (the shadow arrays have one row without indicators).
_PER_MEMBER = ("y", "t", "h", "status", "counters", "yc", "tc", "f", "next_sample",
               "diag_start")
_DTYPES = {"status": np.int32, "counters": np.int64}   # the others are float64
_RECORDS = ("events", "samples")
_RECORDS_FILE = re.compile(r"records-\d{6,}\.npz$")
#: The checkpoint of one launch of a multi-launch computation (:class:`Launches`).
_LAUNCH_DIR = re.compile(r"launch-\d{3,}$")


class CheckpointError(ValueError):
    """A checkpoint that cannot be used for this run (other inputs, settings or package
    version, or not a checkpoint directory). A ValueError: the CLI prints it as one line."""


class CheckpointDamaged(CheckpointError):
    """A damaged checkpoint; the message starts ``checkpoint damaged:``."""


class CheckpointLocked(CheckpointError):
    """Another run holds the checkpoint directory's lock; the message names it."""


class CheckpointExists(CheckpointError):
    """``checkpoint=DIR`` without ``resume=True`` on a directory that holds a checkpoint."""


def _fspath(path, what="checkpoint"):
    """``path`` as a str, or a one-line TypeError naming the parameter (``checkpoint=123``
    must not surface as os.fspath's "expected str, bytes or os.PathLike object")."""
    if isinstance(path, (str, os.PathLike)):
        path = os.fspath(path)
        if isinstance(path, str):
            if not path:
                raise ValueError(f"{what} must be a directory path, not the empty string")
            return path
    raise TypeError(f"{what} must be a directory path (str or os.PathLike) or None (got "
                    f"{type(path).__name__} {_one_line(repr(path), 60)})")


def check_path(path):
    """``checkpoint=`` of an entry point checked before any work: None stays None, a path
    becomes a str, anything else is a one-line TypeError naming ``checkpoint``."""
    return None if path is None else _fspath(path)


def _records_name(launch):
    return f"records-{launch:06d}.npz"


def _one_line(text, limit=200):
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _atomic_savez(path, digest=False, **arrays):
    """Write an .npz beside ``path`` and move it over; returns the SHA-256 (hex) of the bytes
    written when ``digest`` (read back: zipfile seeks while writing), else None."""
    tmp = f"{path}.tmp-{os.getpid()}"
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        sha = None
        if digest:
            with open(tmp, "rb") as fh:
                sha = hashlib.sha256(fh.read()).hexdigest()
        os.replace(tmp, path)
    except BaseException:       # a failed write leaves no temporary file behind
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise
    return sha


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
    previous save; ``state["launches"]`` counts the windows done including this one;
    ``state["records_sha256"]`` is the list of the digests of the records files written so
    far (hex str), shared with the caller: this window's digest is appended to it."""
    path = _fspath(path)
    os.makedirs(path, exist_ok=True)
    width = state["y"].shape[1] + 1
    launch = state["launches"] - 1
    records = {}
    for name in _RECORDS:
        records[name + "_members"], records[name + "_counts"], records[name + "_data"] = \
            _pack(new_records[name], width)
    digests = state["records_sha256"]
    del digests[launch:]            # a window redone after a resume replaces its file
    digests.append(_atomic_savez(os.path.join(path, _records_name(launch)), digest=True,
                                 **records))
    # 32 bytes per window: tiny beside the per-member arrays, rewritten with them
    table = np.array([bytes.fromhex(d) for d in digests], dtype="S32")
    header = {"format": FORMAT, "format_version": FORMAT_VERSION, "version": __version__,
              "settings": settings, "fingerprint": fingerprint, "members": len(state["y"]),
              "launches": state["launches"], "seconds": state["seconds"], "width": width}
    _atomic_savez(os.path.join(path, STATE), header=np.array(json.dumps(header)),
                  records_sha256=table, **{name: state[name] for name in _ARRAYS})


# ---- ownership: lock, overwrite rule, clean-up --------------------------------------------
def _owner_text(path):
    """The lock holder as one line, from lock-owner.json (or why it is unknown)."""
    try:
        with open(os.path.join(path, OWNER)) as fh:
            o = json.load(fh)
        return _one_line(f"pid {o['pid']} on {o['host']}, started {o['started_utc']}, "
                         f"command {o['command']!r}", 300)
    except (OSError, ValueError, KeyError, TypeError):
        return f"holder unknown ({OWNER} missing or unreadable)"


def _lock_class():
    """The lock type (a function so that tests can substitute filelock.SoftFileLock)."""
    return filelock.FileLock


def _is_checkpoint_file(name):
    return name in (STATE, LOCK, OWNER) or _RECORDS_FILE.match(name) or ".tmp-" in name \
        or _LAUNCH_DIR.match(name)


def _launch_dirs(path):
    """The launch checkpoints (``launch-kkk`` directories) in ``path``, in order."""
    try:
        names = os.listdir(path)
    except OSError:
        return []
    return sorted(os.path.join(path, n) for n in names
                  if _LAUNCH_DIR.match(n) and os.path.isdir(os.path.join(path, n)))


def _clean(path, names):
    for name in names:
        with contextlib.suppress(FileNotFoundError):
            os.remove(os.path.join(path, name))


def _refuse_foreign(path):
    """A directory without a state that holds files no run of ours wrote is not ours to
    write into (a fresh start would delete records-*.npz files there)."""
    foreign = [n for n in os.listdir(path) if not _is_checkpoint_file(n)]
    if foreign:
        raise CheckpointError(
            f"checkpoint {path!r} is not a {FORMAT} directory (no {STATE}; holds "
            f"{_one_line(', '.join(sorted(foreign)[:5]))}); choose another path or delete it")


def holds_checkpoint(path):
    """True when the directory ``path`` holds a checkpoint of some run: a state file, or a
    launch checkpoint (``launch-kkk``, :class:`Launches`) that holds one."""
    path = _fspath(path)
    return os.path.isfile(os.path.join(path, STATE)) or any(
        os.path.isfile(os.path.join(d, STATE)) for d in _launch_dirs(path))


def remove(path, held=False):
    """Delete a finished run's checkpoint: the files a run writes in ``path`` (state, records,
    lock, temporary files; its launch checkpoints likewise), then the directory itself when
    nothing else is left in it. ``held``: this process holds the lock, whose file goes last
    (POSIX deletes a locked file; where the OS refuses, :func:`claim` deletes it once
    released)."""
    path = _fspath(path)
    for sub in _launch_dirs(path):
        remove(sub)
    _clean(path, [n for n in os.listdir(path) if _is_checkpoint_file(n)
                  and not _LAUNCH_DIR.match(n) and n != LOCK])
    with contextlib.suppress(FileNotFoundError) if not held else contextlib.suppress(OSError):
        os.remove(os.path.join(path, LOCK))
    with contextlib.suppress(OSError):
        os.rmdir(path)


def finish(path, keep=False, flag="keep_checkpoint=True", held=False):
    """The one rule for the checkpoint of a run that finished (its entry point returned): it
    is removed (:func:`remove`) unless ``keep``; a run that raised or was interrupted never
    gets here, so its checkpoint stays for a resume. :func:`claim` applies it when a run
    leaves its directory, :meth:`Launches.owned` when the last stage of a computation of
    several has succeeded, and the command line once its outputs are written. Returns one
    line saying what was done, naming ``flag`` (how the caller spells "keep"; a directory that
    cannot be removed is kept and says why), or None when there is no directory. ``held``: this
    process holds the directory's lock (:func:`remove`)."""
    path = _fspath(path)
    if not os.path.isdir(path):
        return None
    if keep:
        return f"kept checkpoint {path} ({flag})"
    try:
        remove(path, held=held)
    except OSError as exc:       # a read-only folder: the results stand all the same
        return f"kept checkpoint {path} (it cannot be removed: {exc.strerror or exc})"
    return f"removed checkpoint {path} (the run is complete; {flag} keeps it)"


def check_target(path, resume=False, overwrite=False, cli=False,
                 holds=f"{FORMAT} directory"):
    """Refuse, before any work and without touching anything, a checkpoint path that a run
    with these flags must not write: a path that is not a directory, or (without ``resume``
    and ``overwrite``) a directory that holds a checkpoint. Raises CheckpointError (its
    message names the CLI flags when ``cli``, and what the directory ``holds``)."""
    path = _fspath(path)
    how = ("--resume to continue it or --overwrite-checkpoint to replace it" if cli else
           "Run(resume=True) to continue it or Run(overwrite=True) to replace it")
    if os.path.exists(path) and not os.path.isdir(path):
        raise CheckpointError(f"checkpoint {path!r} is a file, not a {holds}; "
                              "choose another path or delete it")
    if os.path.isdir(path) and not holds_checkpoint(path):
        _refuse_foreign(path)
    if not resume and not overwrite and holds_checkpoint(path):
        raise CheckpointExists(
            f"checkpoint {path!r} already holds a checkpoint of an earlier run; pass {how} "
            "(refused: a run would destroy it)")


def _writable(path):
    """Whether files can be created in the directory ``path`` (a real probe: permission bits
    say nothing for root or on a read-only mount)."""
    try:
        with tempfile.TemporaryFile(dir=path):
            return True
    except OSError:
        return False


def _check_finished(path):
    """A checkpoint in a directory this process cannot write (a read-only folder or mount, an
    archive of finished runs) can be resumed when its run is finished: resuming then only
    reads it (no lock, no state, no clean-up is written). An unfinished one is refused before
    any work, in one line: its next window could not be saved."""
    arrays = _read(os.path.join(path, STATE), STATE, ("status",))
    status = arrays.get("status")
    if status is None or status.ndim != 1 or status.dtype.kind not in "iu":
        raise _damaged(path, f"{STATE} has no status array")

    running = int(np.count_nonzero(status == Status.RUNNING))
    if running:
        raise CheckpointError(
            f"checkpoint {path!r} is in a folder that cannot be written and its run is not "
            f"finished ({running} of {status.size} members still running): make the folder "
            "writable, or copy the directory elsewhere and resume from the copy")


@contextlib.contextmanager
def claim(path, resume=False, overwrite=False, keep=True):
    """Own the checkpoint directory ``path`` for one run (a context manager).

    Creates the directory, takes its lock at once or raises :class:`CheckpointLocked`
    naming the holder, writes the holder's identity, applies the overwrite rule
    (:func:`check_target`), removes stray temporary files and, for a fresh start, any
    earlier checkpoint files (the state first, so that a kill midway leaves no state).
    The lock is released however the block ends (return, exception, KeyboardInterrupt).
    With ``keep=False`` (what ``Run(keep_checkpoint=False)`` asks; the default here keeps,
    since a bare claim does not say that a run finished) a block that ends without an
    exception (the run finished) removes the checkpoint (:func:`finish`), still under the
    lock, so that no other run can have taken the directory in between; an exception or
    interruption always keeps it, and a read-only checkpoint (below) is only ever read.

    A ``resume`` of a checkpoint in a directory that cannot be written (read-only folder or
    mount) takes no lock and writes nothing: it is allowed when the checkpointed run is
    finished (the resumed run then only reads it), and refused with a CheckpointError
    before any work otherwise."""
    path = _fspath(path)
    check_target(path, resume, overwrite)
    if resume and holds_checkpoint(path) and not _writable(path):
        if os.path.isfile(os.path.join(path, STATE)):
            _check_finished(path)     # a read-only checkpoint of a finished run: read it
        yield path                    # (launch checkpoints: each launch checks its own)
        return
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as exc:
        raise CheckpointError(f"checkpoint {path!r} cannot be created: {_one_line(exc)}") from None
    lock = _lock_class()(os.path.join(path, LOCK), timeout=0)
    finished = False
    try:
        lock.acquire()
    except filelock.Timeout:
        raise CheckpointLocked(
            f"checkpoint {path!r} is locked by another run: {_owner_text(path)}; wait for it to "
            "end or use another checkpoint directory") from None
    try:
        owner = {"pid": os.getpid(), "host": socket.gethostname(),
                 "started_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
                     timespec="seconds"),
                 "command": " ".join(sys.argv), "version": __version__}
        tmp = os.path.join(path, f"{OWNER}.tmp-{os.getpid()}")
        with open(tmp, "w") as fh:
            json.dump(owner, fh)
        os.replace(tmp, os.path.join(path, OWNER))
        check_target(path, resume, overwrite)        # again, now that no one else can write
        names = os.listdir(path)
        _clean(path, [n for n in names if ".tmp-" in n])
        if not holds_checkpoint(path) or not resume:      # a fresh start: no stale records
            _clean(path, [STATE] + [n for n in names if _RECORDS_FILE.match(n)])
            for sub in _launch_dirs(path):                 # nor stale launches
                remove(sub)
        yield path
        finished = True
    finally:
        with contextlib.suppress(OSError):
            os.remove(os.path.join(path, OWNER))
        try:
            if finished and not keep:     # under the lock: no other run can take it meanwhile
                finish(path, held=True)
        finally:
            lock.release()
        if finished and not keep and os.path.isdir(path):
            with contextlib.suppress(OSError):   # where the OS kept the held lock file
                if os.name == "nt":
                    os.remove(os.path.join(path, LOCK))
                os.rmdir(path)


# ---- reading ------------------------------------------------------------------------------
def _damaged(path, what):
    return CheckpointDamaged(f"checkpoint damaged: {path!r}: {what}; delete the directory to "
                             "start the run afresh")


def _read(path, what, names, digest=None):
    """The arrays ``names`` of one checkpoint file (those present; no other entry is ever
    decompressed), sizes checked before reading (io.ArchiveError rules), its SHA-256
    compared with ``digest`` first when given."""
    folder = os.path.dirname(path)
    try:
        if digest is not None:
            with open(path, "rb") as fh:
                actual = hashlib.sha256(fh.read()).hexdigest()
            if actual != digest:
                raise _damaged(folder, f"{what} is not the file this run wrote (SHA-256 "
                                       f"{actual[:12]}..., the state records {digest[:12]}...: "
                                       "edited, swapped or corrupted)")
        with zipfile.ZipFile(path) as zf:
            entries = _Entries(path, zf)
            return {k: entries[k] for k in names if k in entries}
    except CheckpointDamaged:
        raise
    except _DAMAGE as exc:  # zip, header, size or key errors all mean the same thing
        raise _damaged(folder, f"{what} is damaged or not a checkpoint "
                               f"({type(exc).__name__}: {_one_line(exc)})") from None


def load(path, settings, fingerprint):
    """The saved state of a run with these ``settings`` and input ``fingerprint``, or None
    when ``path`` holds no checkpoint (does not exist, or only files of a run killed before
    its first state). Raises CheckpointDamaged for a damaged checkpoint, CheckpointError
    (both ValueError) for a mismatched one or a directory that is not a checkpoint."""
    path = _fspath(path)
    if not os.path.exists(path):
        return None
    if not os.path.isdir(path):
        raise CheckpointError(f"checkpoint {path!r} is not a {FORMAT} directory (a file); "
                              "choose another path or delete it")
    if not holds_checkpoint(path):
        _refuse_foreign(path)
        return None            # killed before its first state: start afresh
    if not os.path.isfile(os.path.join(path, STATE)):
        raise CheckpointError(f"checkpoint {path!r} holds the launches (launch-kkk) of a "
                              "computation of several launches (a map, scan or libration "
                              "search), not a single run's checkpoint; use another path")
    arrays = _read(os.path.join(path, STATE), STATE, ("header", "records_sha256") + _ARRAYS)
    try:
        header = json.loads(str(arrays.pop("header")))
        if not isinstance(header, dict):
            raise TypeError("header is not a JSON object")
    except (KeyError, TypeError, ValueError, RecursionError) as exc:
        raise _damaged(path, f"{STATE} is damaged or not a checkpoint ({type(exc).__name__}: "
                             f"{_one_line(exc)})") from None
    if header.get("format") != FORMAT:
        raise CheckpointError(f"checkpoint {path!r} is not a {FORMAT}")
    if header.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(
            f"checkpoint {path!r} has format version {header.get('format_version')!r}, this "
            f"package reads version {FORMAT_VERSION}; delete it to start afresh")
    if header.get("version") != __version__:
        raise CheckpointError(
            f"checkpoint {path!r} was written by ti_spinorbit {header.get('version')!r}, this "
            f"is {__version__}: a resumed run would not equal an uninterrupted one; finish it "
            "with that version or delete it to start afresh")
    saved = header.get("settings")
    if not isinstance(saved, dict):
        raise _damaged(path, f"{STATE} has no settings table")
    differ = [f"{k} (checkpoint {saved.get(k)!r}, now {v!r})" for k, v in settings.items()
              if saved.get(k) != v]
    if differ:
        raise CheckpointError(f"checkpoint {path!r} belongs to a run with other settings: "
                              + "; ".join(differ))
    saved = header.get("fingerprint")
    if saved != fingerprint:
        parts = sorted(fingerprint) if not isinstance(saved, dict) else \
            [k for k in fingerprint if saved.get(k) != fingerprint[k]]
        what = {"perturbations": "perturbations (tides, YORP, BYORP or their parameters)"}
        raise CheckpointError(f"checkpoint {path!r} belongs to a run with other inputs ("
                              + ", ".join(what.get(k, k) for k in parts) + " differ); resume "
                              "with the run's own inputs, or delete it or use another "
                              "checkpoint path")
    missing = [k for k in _ARRAYS + ("records_sha256",) if k not in arrays]
    if missing:
        raise _damaged(path, f"{STATE} lacks {', '.join(missing)}")
    try:
        n, width = header["members"], header["width"]
        launches, seconds = header["launches"], header["seconds"]
        if not all(type(v) is int and v >= 0 for v in (n, width, launches)) \
                or not isinstance(seconds, (int, float)):
            raise TypeError("members, width, launches or seconds has the wrong type")
    except (KeyError, TypeError) as exc:
        raise _damaged(path, f"{STATE} header is incomplete ({_one_line(exc)})") from None
    state = {name: np.array(arrays[name]) for name in _ARRAYS}
    bad = [k for k in _PER_MEMBER if state[k].ndim < 1 or len(state[k]) != n]
    bad += [k for k in ("shadow", "shadow_f", "ind")
            if state[k].ndim != 2 or len(state[k]) not in (1, n)]
    bad += [k for k in _ARRAYS if state[k].dtype != _DTYPES.get(k, np.float64)]
    if state["y"].shape != (n, width - 1) and "y" not in bad:
        bad.append("y")
    table = arrays["records_sha256"]
    if table.dtype != np.dtype("S32") or table.shape != (launches,):
        bad.append("records_sha256")
    if bad:
        raise _damaged(path, f"{STATE}: {', '.join(bad)} do not fit {n} members and "
                             f"{launches} windows")
    digests = [bytes(d).ljust(32, b"\0").hex() for d in table]
    for name in _RECORDS:
        state[name] = [[] for _ in range(n)]
    state["launches"] = launches
    state["seconds"] = float(seconds)
    state["records_sha256"] = digests
    for launch in range(launches):
        file = os.path.join(path, _records_name(launch))
        if not os.path.exists(file):
            raise _damaged(path, f"{_records_name(launch)} is missing")
        rec = _read(file, _records_name(launch),
                    [f"{n}_{part}" for n in _RECORDS for part in ("members", "counts", "data")],
                    digests[launch])
        lacks = [f"{name}_{part}" for name in _RECORDS for part in ("members", "counts", "data")
                 if f"{name}_{part}" not in rec]
        if lacks:
            raise _damaged(path, f"{_records_name(launch)} lacks {', '.join(lacks)}")
        for name in _RECORDS:
            try:
                members = rec[name + "_members"]
                counts = rec[name + "_counts"]
                data = rec[name + "_data"]
                if members.shape != counts.shape or members.ndim != 1 \
                        or data.ndim != 2 or data.shape[1] != width \
                        or np.any(counts < 0) or int(counts.sum()) != len(data) \
                        or np.any(members < 0) or np.any(members >= n):
                    raise ValueError(f"{name} members, counts and data disagree")
            except (KeyError, ValueError, TypeError) as exc:
                raise _damaged(path, f"{_records_name(launch)}: {_one_line(exc)}") from None
            for i, part in zip(members, np.split(data, np.cumsum(counts)[:-1])):
                state[name][int(i)].append(part)
    return state


class Launches:
    """Checkpoints of a computation made of several ensemble launches: a chaos or parameter
    map's lengths (the fraction-against-orbits evidence, then the map itself),
    overlap_threshold's doubling, relaxed_libration's search and its convergence checks.
    Launch k checkpoints into ``DIR/launch-kkk`` (an ordinary run checkpoint). The launches
    of a computation are the same on every run of it (each follows from the inputs and the
    launches before it), so resuming resumes each in turn: a finished launch's checkpoint
    gives its result back without integrating, the interrupted one continues, later ones
    start afresh. A resume therefore never recomputes a finished stage, and ends bit for bit
    as an uninterrupted run.

    The rules of a run checkpoint hold for ``DIR`` as a whole: it is checked when the object
    is made (:func:`check_target`: no overwrite without ``overwrite``, no file, no foreign
    directory), and :meth:`owned` holds ``DIR``'s lock for the whole computation, so that a
    second computation on it is refused at once (:class:`CheckpointLocked`), and a fresh
    start (no ``resume``) removes every earlier launch first. When the computation's last
    launch has succeeded (the :meth:`owned` block ends without an exception) ``DIR`` is
    removed, launches and all, unless ``keep`` (:func:`finish`); the launches themselves
    always keep theirs until then. ``next()`` gives the keywords of the next launch ({}
    without a directory)."""

    def __init__(self, directory, resume=False, overwrite=False, keep=False):
        self.directory = None if directory is None else _fspath(directory)
        self.resume, self.overwrite, self.count = bool(resume), bool(overwrite), 0
        self.keep = bool(keep)
        if self.directory is not None:
            check_target(self.directory, self.resume, self.overwrite,
                         holds="directory of launch checkpoints")
            if self.resume and os.path.isfile(os.path.join(self.directory, STATE)):
                raise CheckpointError(
                    f"checkpoint {self.directory!r} holds a single run's checkpoint "
                    f"({STATE}), not the launches of a computation of several; resume it "
                    "with the entry point that wrote it, or use another path")

    @contextlib.contextmanager
    def owned(self):
        """Hold ``DIR`` (its lock, :func:`claim`) while the launches run; nothing without a
        directory."""
        if self.directory is None:
            yield self
            return
        with claim(self.directory, self.resume, self.overwrite, keep=self.keep):
            yield self

    def next(self):
        if self.directory is None:
            return {}
        path = os.path.join(self.directory, f"launch-{self.count:03d}")
        self.count += 1
        # DIR's own claim applied the overwrite rule to every launch at once, and removes
        # them all when the last one has succeeded: a launch keeps its own until then
        return {"checkpoint": path, "resume": self.resume, "overwrite": False,
                "keep_checkpoint": True}                                   # Run's fields
