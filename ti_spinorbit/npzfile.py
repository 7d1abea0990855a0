"""Reading NumPy ``.npz`` archives that may be damaged or hostile, safely.

Used by :mod:`ti_spinorbit.output.io` (saved results) and :mod:`ti_spinorbit.engine.checkpoint` (records
files). Entries are read one at a time and only when asked for; before anything is
allocated, every entry's size in the zip directory is checked against its ``.npy`` header and
against the largest ratio deflate can reach, so a small file cannot make a reader allocate
gigabytes, and pickles are never loaded. Every fault is an :class:`ArchiveError`, one line
naming the file.
"""

import struct
import zipfile
import zlib

import numpy as np


class ArchiveError(ValueError):
    """A file that :func:`load` (or :func:`read_metadata`) cannot read as a ti_spinorbit
    archive: not an ``.npz``, damaged (truncated, flipped bytes, renamed or missing entries,
    bad ``.npy`` headers), malformed metadata (wrong types, absurd nesting), an unknown kind
    or an unreadable ``format_version``. The message is one line naming the file and what is
    wrong. A subclass of ValueError, so ``except ValueError`` still catches it.

    Examples
    --------
    >>> _ = open("not_a_result.npz", "wb").write(b"junk")
    >>> try:
    ...     tso.load("not_a_result.npz")
    ... except tso.ArchiveError as error:
    ...     print("refused")
    refused
    """


#: Largest ratio of uncompressed to compressed size that deflate can reach (≈ 1032:1), with
#: margin: an entry whose zip directory claims more is damaged, and is refused before reading.
_MAX_DEFLATE_RATIO = 1100
#: Largest metadata entry read (bytes uncompressed): real metadata is kilobytes to megabytes.
_MAX_METADATA_BYTES = 256 * 2**20
#: Zip general-purpose flag bit 0: the entry is encrypted (zipfile asks for a password).
_ENCRYPTED = 0x1
#: Errors that reading or decoding a damaged or hostile file can raise (never a bug of ours
#: with a valid file): each becomes an ArchiveError naming the file.
_DAMAGE = (KeyError, IndexError, TypeError, AttributeError, ValueError, RecursionError,
           OverflowError, MemoryError, EOFError, OSError, UnicodeError, zipfile.BadZipFile,
           zlib.error, struct.error, NotImplementedError)


def _one_line(exc):
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 300 else text[:297] + "..."


#: Bytes read per call when filling an array (as numpy.lib.format's BUFFER_SIZE).
_BLOCK = 2**24


def _read_data(fh, shape, fortran, dtype, count, where):
    """The array after an entry's ``.npy`` header, read straight into place in blocks (one
    allocation, as ``numpy.lib.format.read_array``), then the end of the entry read, which
    makes zipfile check its CRC-32: a flipped bit anywhere in the data is an error, never a
    changed number."""
    array = np.empty(count, dtype=dtype)
    nbytes = count * dtype.itemsize
    if nbytes:
        view = memoryview(array.view(np.uint8))
        done = 0
        while done < nbytes:
            got = fh.readinto(view[done:done + _BLOCK])
            if not got:
                raise ArchiveError(f"{where} ends after {done} of its {nbytes} bytes of data")
            done += got
    if fh.read(1):
        raise ArchiveError(f"{where} holds more data than its header says")
    if fortran:
        return array.reshape(tuple(shape)[::-1]).transpose()
    return array.reshape(tuple(shape))


class _Entries:
    """The arrays of an ``.npz``, read one by one on first use with every size checked
    against the zip directory before anything is allocated; entries never asked for are
    never decompressed (a small file cannot make :func:`load` allocate gigabytes)."""

    def __init__(self, path, zf):
        self.path, self.zf, self._cache = path, zf, {}
        self._names = {}
        for info in zf.infolist():
            key = info.filename[:-4] if info.filename.endswith(".npy") else info.filename
            self._names[key] = info

    @property
    def files(self):
        return list(self._names)

    def __contains__(self, key):
        return key in self._cache or key in self._names

    def __iter__(self):
        return iter(dict.fromkeys([*self._names, *self._cache]))

    def __setitem__(self, key, value):
        self._cache[key] = value

    def __getitem__(self, key):
        if key in self._cache:
            return self._cache[key]
        if not isinstance(key, str) or key not in self._names:
            raise ArchiveError(f"{self.path!r} is damaged: its metadata names the array "
                               f"{key!r}, which is not in the file")
        self._cache[key] = value = self._read(key, self._names[key])
        return value

    def _read(self, key, info, limit=None):
        where = f"{self.path!r} is damaged: entry {info.filename!r}"
        if info.compress_type == zipfile.ZIP_STORED:
            ok = info.file_size == info.compress_size
        elif info.compress_type == zipfile.ZIP_DEFLATED:
            ok = info.file_size <= _MAX_DEFLATE_RATIO * info.compress_size + 1024
        else:
            raise ArchiveError(f"{where} uses zip compression method {info.compress_type}; "
                               "NumPy archives use stored or deflated entries")
        if not ok:
            raise ArchiveError(f"{where} claims {info.file_size} bytes from "
                               f"{info.compress_size} compressed bytes (impossible)")
        if info.flag_bits & _ENCRYPTED:     # zipfile would raise RuntimeError (password)
            raise ArchiveError(f"{where} is flagged as encrypted (NumPy never writes that: a "
                               "flipped bit)")
        if limit is not None and info.file_size > limit:
            raise ArchiveError(f"{where} holds {info.file_size} bytes, more than the "
                               f"{limit} bytes allowed for it")
        fmt = np.lib.format
        with self.zf.open(info) as fh:
            try:
                version = fmt.read_magic(fh)
                if version == (1, 0):
                    shape, fortran, dtype = fmt.read_array_header_1_0(fh)
                elif version == (2, 0):
                    shape, fortran, dtype = fmt.read_array_header_2_0(fh)
                else:
                    reader = getattr(fmt, "_read_array_header", None)
                    if reader is None:
                        raise ArchiveError(f"{where} has .npy format version {version}")
                    shape, fortran, dtype = reader(fh, version)
            except (ArchiveError, zipfile.BadZipFile, zlib.error):
                raise             # damage the caller names as such (a bad CRC-32, deflate)
            except Exception as exc:  # noqa: BLE001 - the header is Python literal text
                # parsed by NumPy (ast): damaged text raises ValueError, SyntaxError,
                # tokenize.TokenError, RecursionError, MemoryError, ...; every one means the
                # same: a bad header
                raise ArchiveError(f"{where} has a bad .npy header "
                                   f"({type(exc).__name__})") from None
            header = fh.tell()
            if dtype.hasobject:
                raise ArchiveError(f"{where} holds Python objects (pickles are never loaded)")
            count = 1
            for n in shape:
                count *= int(n)
            if count * dtype.itemsize != info.file_size - header:
                raise ArchiveError(f"{where} has a header for shape {tuple(shape)} of {dtype} "
                                   f"({count * dtype.itemsize} bytes) but holds "
                                   f"{info.file_size - header} bytes of data")
            # sizes agree: reading allocates what the file holds, from the same stream
            return _read_data(fh, shape, fortran, dtype, count, where)

    def metadata(self):
        info = self._names.get("metadata")
        if info is None:
            return None
        return self._read("metadata", info, limit=_MAX_METADATA_BYTES)
