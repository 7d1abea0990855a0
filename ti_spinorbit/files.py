"""Writing files safely: atomic replaces, claimed output names, names that fit the folder.

Every result file (:func:`ti_spinorbit.output.io.save`), figure
(:func:`ti_spinorbit.output.plotting.save_figure`) and report of the command line is written through
:func:`atomic_write`, and every run of the command line owns its output names through
:func:`claim`. The decisions:

* **Atomic writes.** The bytes go to a temporary file in the same folder (hidden,
  ``.<name>.<random>.tmp``, created exclusively with the permissions a new file would get, or
  those of the file it replaces), which is flushed and ``fsync``-ed, then moved over the final
  name with ``os.replace`` (atomic on POSIX and Windows), and the folder is ``fsync``-ed so the
  rename survives a power cut. A write that fails or is interrupted (an exception,
  KeyboardInterrupt) removes its temporary file and leaves the final name as it was; a write
  killed outright (``kill -9``, power cut) leaves at most that hidden temporary file, never a
  partial file under the final name, and an existing file is byte-identical afterwards.
  The temporary file is in the same folder because ``os.replace`` is only atomic within one
  file system. A final name that is a symbolic link to a file keeps its link: the file it
  points to is replaced (as ``open(path, "w")`` would have written through it).
* **One overwrite rule.** An output that exists is refused, not replaced, unless the caller
  says so: Python's :func:`ti_spinorbit.save` (and ``result.save``) raise
  :class:`OutputExists` (a FileExistsError; one line naming the file and ``overwrite=True``)
  unless ``overwrite=True``; the command line refuses before any work unless
  ``--overwrite``. The check is made before the work and again when the file is put in
  place (a hard link, which fails on an existing name), so a file that appeared meanwhile
  is not replaced either. The package writes figures only for the command line (Python
  users call Matplotlib's ``savefig``, whose rule is Matplotlib's).
* **Claimed outputs.** A run takes an exclusive OS lock (``flock``) on a hidden file beside
  each output, ``.<name>.lock``, before it checks whether the output exists and holds it until
  it ends, so two runs with the same output names started together cannot both go on: the
  second is refused at once (:class:`OutputBusy`, one line naming the holder, whose pid,
  host, start time and command line the lock file holds). The OS frees the lock the instant
  its holder dies (``kill -9`` included), so a crashed run never blocks the names; the lock
  file is deleted when a run ends normally (a killed run leaves it, harmlessly: the next run
  takes it). Deleting a lock file while another process waits to lock it is made safe by
  checking, after locking, that the name still refers to the file that was locked.
* **Names that fit.** :func:`check_name` refuses, before any work, a name longer than the
  folder allows (``NAME_MAX``, 255 bytes on Linux, macOS and Windows file systems; the
  path as a whole against ``PATH_MAX``), a dangling symbolic link and control characters;
  :func:`safe_part` turns a system name or flag value into a file-name part (no folder
  separators, no control or shell-special characters). The names of the lock and
  temporary files are kept short whatever the output's name is.
"""

import contextlib
import datetime
import hashlib
import json
import os
import secrets
import socket
import stat
import sys
import unicodedata

try:
    import fcntl
except ImportError:      # pragma: no cover - Windows: claims take a filelock instead
    fcntl = None

import filelock

#: Longest file name (bytes) where the folder does not say (POSIX's common NAME_MAX).
NAME_MAX = 255
#: Longest path (bytes) where the system does not say (Linux's PATH_MAX).
PATH_MAX = 4096
#: Characters kept in a file-name part besides ASCII letters and digits (others become "-"):
#: a name made of [A-Za-z0-9._-] needs no quoting in any shell and means the same on every
#: file system.
SAFE_PUNCTUATION = "-_."


class OutputBusy(ValueError):
    """An output name claimed by another run that is still going (one line naming it)."""


# ---- names ----------------------------------------------------------------------------------
def name_max(folder):
    """Longest file name in ``folder``, bytes (``os.pathconf``; :data:`NAME_MAX` where unknown)."""
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (AttributeError, OSError, ValueError, TypeError):
        return NAME_MAX


def _bytes(text):
    return len(os.fsencode(text))


def _shorten(text, limit):
    """``text`` cut (at a character boundary) to at most ``limit`` bytes."""
    while _bytes(text) > limit:
        text = text[:-1]
    return text


def safe_part(text, fallback="unnamed", tidy=True):
    """``text`` as one shell-safe file-name part, made of ``[A-Za-z0-9._-]`` only: spaces
    dropped (``"1991 VH"`` -> ``"1991VH"``), accents taken off (``"Šteins"`` -> ``"Steins"``),
    every other character than an ASCII letter, digit or one of :data:`SAFE_PUNCTUATION`
    (parentheses, folder separators, control characters, newlines, quotes, ``*?<>|:$&;``,
    other scripts) replaced by ``-`` (``"Didymos (radar shape)"`` -> ``"Didymos-radarshape"``);
    with ``tidy`` (names) also runs of ``-`` joined and leading/trailing ``-`` and ``.``
    removed (without it, for flag values, ``-`` stays as it is: ``td-1--2`` is not
    ``td-1-2``); ``fallback`` when nothing is left."""
    out = []
    for ch in unicodedata.normalize("NFKD", str(text)):
        if ch == " " or unicodedata.combining(ch):      # spaces and accents go
            continue
        ok = (ch.isascii() and ch.isalnum()) or ch in SAFE_PUNCTUATION
        out.append(ch if ok else "-")
    part = "".join(out)
    if tidy:
        while "--" in part:
            part = part.replace("--", "-")
        part = part.strip("-.")
    return part or fallback


def check_name(label, path):
    """Refuse, with one ValueError naming ``label`` (the flag), an output path that cannot be
    written as such: control characters in it, a name longer than the folder allows or a
    path longer than the system allows, or a dangling symbolic link."""
    path = os.fspath(path)
    bad = [ch for ch in path if unicodedata.category(ch) == "Cc"]
    if bad:
        raise ValueError(f"{label}: {path!r} holds control characters ({bad[0]!r}); give a "
                         "name without them")
    folder = os.path.dirname(os.path.abspath(path)) or os.sep
    name = os.path.basename(path)
    limit = name_max(folder if os.path.isdir(folder) else os.sep)
    if _bytes(name) > limit:
        raise ValueError(f"{label}: the file name {_shorten(name, 40)!r}... is {_bytes(name)} "
                         f"bytes long, more than the {limit} bytes a name may have here; give "
                         "a shorter name with --out" + ("" if label.startswith("--") else
                                                        " (the default name is too long)"))
    if _bytes(os.path.abspath(path)) >= PATH_MAX:
        raise ValueError(f"{label}: the path is {_bytes(os.path.abspath(path))} bytes long, "
                         f"more than the {PATH_MAX - 1} bytes a path may have; give a shorter one")
    if os.path.islink(path) and not os.path.exists(path):
        raise ValueError(f"{label}: {path!r} is a symbolic link to {os.readlink(path)!r}, which "
                         "does not exist; remove the link or give another name")


def _side_name(path, suffix):
    """A hidden name beside ``path``: ``.<name><suffix>``, shortened (with a digest of the
    full name, so that distinct long names stay distinct) to fit any folder."""
    folder, name = os.path.split(os.fspath(path))
    side = f".{name}{suffix}"
    if _bytes(side) > NAME_MAX:
        digest = hashlib.sha256(os.fsencode(name)).hexdigest()[:16]
        side = f".{_shorten(name, NAME_MAX - 40)}-{digest}{suffix}"
    return os.path.join(folder, side)


# ---- atomic writes --------------------------------------------------------------------------
def _fsync_folder(folder):
    """Make a rename in ``folder`` durable (POSIX; a no-op where folders cannot be opened)."""
    if not hasattr(os, "O_DIRECTORY"):
        return
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def target(path):
    """The file a write to ``path`` replaces: ``path`` itself, or the file it links to."""
    path = os.fspath(path)
    return os.path.realpath(path) if os.path.islink(path) else path


class OutputExists(FileExistsError):
    """An output that exists already, written with ``overwrite=False`` (one line naming the
    file and ``overwrite=True``)."""


def refuse_existing(path, how="overwrite=True"):
    """Raise :class:`OutputExists` when ``path`` (or a symbolic link by that name) exists: the
    one overwrite rule (module docstring), ``how`` saying what allows it."""
    path = os.fspath(path)
    if os.path.lexists(path):
        raise OutputExists(f"{path!r} already exists; pass {how} to replace it, or choose "
                           "another name")


def _publish_new(tmp, final, path):
    """Give the finished temporary file ``tmp`` the name ``final`` only if no file has it: a
    hard link fails when the name exists (atomic, so a file that appeared while this one was
    written is never replaced); where the file system has no hard links, the name is checked
    and then replaced."""
    try:
        os.link(tmp, final)
    except FileExistsError:
        refuse_existing(path)
    except OSError:          # no hard links here (FAT, some network and FUSE file systems)
        refuse_existing(path)
        os.replace(tmp, final)
        return
    os.remove(tmp)


@contextlib.contextmanager
def atomic_write(path, mode="wb", encoding=None, overwrite=True):
    """Write ``path`` atomically (module docstring): yields a file object on a temporary file
    beside it (``mode`` "wb" or "w"; text in ``encoding``, UTF-8 by default) that replaces
    ``path`` when the block ends without an exception. On an exception (KeyboardInterrupt
    included) the temporary file is removed and ``path`` is left as it was.

    ``overwrite=False`` refuses a ``path`` that exists (:class:`OutputExists`, one line), at
    once and again when the file is put in place, where a file that appeared meanwhile is
    never replaced either."""
    if mode not in ("wb", "w"):
        raise ValueError(f"mode must be 'wb' or 'w' (got {mode!r})")
    if not overwrite:
        refuse_existing(path)
    final = target(path)
    folder = os.path.dirname(os.path.abspath(final))
    old_mode = None
    with contextlib.suppress(OSError):
        old_mode = stat.S_IMODE(os.stat(final).st_mode)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = _side_name(os.path.join(folder, os.path.basename(final)),
                         f".{secrets.token_hex(4)}.tmp")
        try:
            fd = os.open(tmp, flags, 0o666)      # the umask applies, as for a new file
            break
        except FileExistsError:
            continue
        except OSError as exc:     # name the file asked for, not the temporary one
            raise type(exc)(exc.errno, f"cannot write {os.fspath(path)!r} in folder {folder!r} "
                                       f"({exc.strerror})") from None
    else:   # pragma: no cover - 100 collisions of 32 random bits
        raise FileExistsError(f"cannot create a temporary file beside {final!r}")
    try:
        if old_mode is not None:
            with contextlib.suppress(OSError):
                os.chmod(tmp, old_mode)
        fh = os.fdopen(fd, mode, **({"encoding": encoding or "utf-8"} if mode == "w" else {}))
    except BaseException:
        os.close(fd)
        os.remove(tmp)
        raise
    try:
        with fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        if overwrite:
            os.replace(tmp, final)
        else:
            _publish_new(tmp, final, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise
    _fsync_folder(folder)


def write_text(path, text):
    """Write ``text`` to ``path`` atomically (UTF-8); returns ``path``."""
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return path


def write_json(path, obj, **kwargs):
    """Write ``obj`` as JSON to ``path`` atomically (``kwargs`` go to ``json.dump``)."""
    with atomic_write(path, "w") as fh:
        json.dump(obj, fh, **kwargs)
    return path


# ---- claimed output names ----------------------------------------------------------------------
def lock_path(path):
    """The lock file of an output name: ``.<name>.lock`` beside it."""
    return _side_name(target(path), ".lock")


def _holder_text(fd):
    try:
        os.lseek(fd, 0, os.SEEK_SET)
        o = json.loads(os.read(fd, 65536).decode("utf-8"))
        text = (f"pid {o['pid']} on {o['host']}, started {o['started_utc']}, command "
                f"{o['command']!r}")
    except (OSError, ValueError, KeyError, TypeError, UnicodeError):
        return "holder unknown"
    text = " ".join(text.split())
    return text if len(text) <= 300 else text[:297] + "..."


class Claim:
    """Output names owned by one run (from :func:`claim`); :meth:`release` (or the end of a
    ``with`` block) frees them and deletes the lock files."""

    def __init__(self):
        self._held = []          # (lock path, fd or filelock object)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    @property
    def paths(self):
        return [p for p, _ in self._held]

    def _take(self, label, path, command):
        lock = lock_path(path)
        if fcntl is None:        # pragma: no cover - Windows: filelock, without holder text
            return self._take_filelock(label, path, lock)
        for _ in range(100):
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = _holder_text(fd)
                os.close(fd)
                raise OutputBusy(f"{label}: {os.fspath(path)!r} is being written by another run "
                                 f"({holder}); wait for it to end or choose another --out") from None
            try:       # the name must still be the file locked (a holder deletes it on release)
                same = os.path.samestat(os.fstat(fd), os.stat(lock))
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            owner = {"pid": os.getpid(), "host": socket.gethostname(),
                     "started_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(
                         timespec="seconds"), "command": command or " ".join(sys.argv),
                     "output": os.fspath(path)}
            with contextlib.suppress(OSError):
                os.ftruncate(fd, 0)
                os.write(fd, json.dumps(owner).encode("utf-8"))
            self._held.append((lock, fd))
            return
        raise OutputBusy(f"{label}: cannot lock {lock!r} (it keeps being replaced)")  # pragma: no cover

    def _take_filelock(self, label, path, lock):     # pragma: no cover - no fcntl
        fl = filelock.FileLock(lock, timeout=0)
        try:
            fl.acquire()
        except filelock.Timeout:
            raise OutputBusy(f"{label}: {os.fspath(path)!r} is being written by another run; "
                             "wait for it to end or choose another --out") from None
        self._held.append((lock, fl))

    def release(self):
        """Free every name (deleting its lock file first, while it is still held)."""
        while self._held:
            lock, handle = self._held.pop()
            if isinstance(handle, int):
                with contextlib.suppress(OSError):
                    os.remove(lock)
                os.close(handle)
            else:                       # pragma: no cover - filelock
                handle.release()


def claim(outputs, command=None):
    """Own output names for one run: ``outputs`` is a list of (label, path), ``label`` naming
    the flag in messages. Returns a :class:`Claim`; raises :class:`OutputBusy` (freeing what it
    took) when another running process holds one of them. A folder where no lock file can be
    created (read-only) is reported by the writability check of the caller, not here: such a
    name is skipped."""
    held = Claim()
    try:
        for label, path in outputs:
            try:
                held._take(label, path, command)
            except OutputBusy:
                raise
            except OSError:     # cannot create the lock file: the write check says why
                continue
    except BaseException:
        held.release()
        raise
    return held


__all__ = ["OutputExists", "refuse_existing", "atomic_write", "write_text", "write_json",
           "claim", "Claim", "OutputBusy", "check_name", "safe_part", "lock_path", "name_max",
           "target"]
