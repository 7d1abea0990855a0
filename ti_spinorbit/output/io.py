"""Saving and loading results with their parameters (NumPy ``.npz`` + JSON metadata).

:func:`save` writes any result object of the package (surface of section, time series, chaos
map, parameter map, overlap scan, relaxed libration) to one compressed ``.npz``: every array
under its own name, plus a ``metadata`` entry holding JSON with the result's kind, the
archive ``format_version``, the package version, Taichi arch and UTC timestamp, every scalar
input and output, the units of every array and scalar, the systems (all inputs with units,
body inertia integrals included) and the integrator status codes. A file is self-describing
without this package (``numpy.load`` + ``json``); :func:`load` turns it back into the same
result object, with identical arrays and equal systems.

Layout decisions (the README's "Saved files" section documents them for users):

* A result nested in another (``ChaosMap.section``, ``OverlapScan.sections``: the underlying
  :class:`~ti_spinorbit.studies.section.SectionResult`) is saved with its field name as prefix
  (``section/theta_p``) so a loaded map can still be plotted with its section overlay;
  ``save(..., include_sections=False)`` drops it (the file shrinks to the map alone and the
  loaded field is None).
* Systems are stored once each: ``metadata["systems"]`` lists the distinct systems and the
  array ``system_index`` gives each member's entry (a 10^4-member map of one system holds
  one description, not 10^4).
* Label arrays (Python ``object`` arrays of str) are stored as fixed-width unicode, so the
  file opens with ``allow_pickle=False``; :func:`load` gives them back as ``object`` arrays.
* ``status_names`` (the status code of each member as text) is written next to ``status``
  for readers without the package; :func:`load` ignores it.
* Format versions: 2 is this layout; 1 the same with older field names (``center_1``,
  ``mean_spin``, ... : ``RENAMED_FIELDS``), which :func:`load` renames; 0 is the layout :func:`save_result` wrote before
  ``format_version`` existed (sections and time series only), which :func:`load` still reads.
* Reading trusts nothing in the file: :func:`load` reads only the entries the metadata names,
  checks each entry's sizes (zip directory against the ``.npy`` header, deflate's largest
  ratio) before allocating, and turns every fault of a malformed file into one
  :class:`ArchiveError` (a ValueError) with a one-line message; a missing path stays
  FileNotFoundError.
"""

import dataclasses
import datetime
import json
import os
import zipfile

import numpy as np

from ..model import perturbations
from .. import runtime
from ..engine import results as _results
from .._version import __version__
from ..model.attitude import CLASS_UNIT, CLASSES
from .._validate import require_bool
from ..files import atomic_write, refuse_existing
from ..layout import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4
from ..npzfile import _DAMAGE, ArchiveError, _Entries, _one_line  # noqa: F401 (ArchiveError: public here)
from ..engine.results import STATUS, STATUS_NAMES, units as field_units
from ..system.systems import BinarySystem

#: Layout version written into every archive's metadata; bump it when the layout changes.
FORMAT_VERSION = 2
#: Versions :func:`load` reads (0: files from save_result before format_version existed;
#: 1: the same layout as 2 with the old field names of ``RENAMED_FIELDS``).
READABLE_FORMAT_VERSIONS = (0, 1, 2)
#: Field names of format 1 that format 2 spells in the project's one vocabulary
#: (docs/design.md "Vocabulary"), per kind (None: every kind, records included).
RENAMED_FIELDS = {
    None: {"center_thetadot_p": "centre_thetadot_p", "centers_by_length": "centres_by_length",
           "center_rtol_check": "centre_rtol_check", "center_tol": "centre_tol",
           "center_1": "centre_1", "center_3_2": "centre_3_2",
           "center_3_2_found": "centre_3_2_found", "mean_spin": "mean_thetadot"},
    "parameter_map": {"labels": "classification"},
}

#: Units of the archive's own entries (not result fields). The units of every result field
#: live on the field (``ti_spinorbit.engine.results.unit``) and are read from there.
ARCHIVE_UNITS = {"status_names": "name", "system_index": "index into metadata systems"}


def _kinds():
    """kind name -> result class (:data:`ti_spinorbit.engine.results.KINDS`, which every result
    class fills by declaring its kind; the package imports them all)."""
    return _results.KINDS


def _record_types():
    """Small dataclasses stored as JSON records inside a result (name -> class)."""
    return _results.RECORDS


def kind_of(result):
    """The archive kind of a result object ("section", "chaos_map", ...), or TypeError."""
    kind = getattr(type(result), "kind", "")
    if kind and _kinds().get(kind) is type(result):
        return kind
    raise TypeError(f"cannot save a {type(result).__name__}: save() takes one of "
                    f"{', '.join(c.__name__ for c in _kinds().values())}")


def units(kind):
    """Units of the arrays and scalars of a result kind (a new dict), e.g.
    ``units("section")``: the units declared on the result class's fields
    (:func:`ti_spinorbit.engine.results.units`) plus the archive's own entries."""
    if kind not in _kinds():
        raise ValueError(f"unknown kind {kind!r}; known kinds: {', '.join(_kinds())}")
    return {**ARCHIVE_UNITS, **field_units(_kinds()[kind])}


def status_codes():
    """Integrator status code -> name, e.g. {0: "running", 1: "done", ...}
    (:class:`ti_spinorbit.engine.results.Status`)."""
    return dict(enumerate(STATUS_NAMES))


def status_names(status):
    """Names of an array of status codes (same shape, str), e.g. [1, 3] -> ["done", "escape"]."""
    status = np.asarray(status)
    if not status.size:
        return status.astype(str)
    return np.vectorize(status_codes().get, otypes=[str])(status)


def provenance():
    """Package, version, Taichi arch and UTC timestamp: the common head of every metadata."""
    return {"package": "ti_spinorbit", "version": __version__, "arch": runtime.current_arch(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat()}


def _json_default(x):
    """JSON for what json does not know: numpy scalars and arrays, anything else as text."""
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return str(x)


def _archive_name(path):
    """The name an archive is written under: ``path``, with ``.npz`` appended unless it ends
    so in any case (``r.NPZ`` stays); a file object as it is."""
    if isinstance(path, (str, os.PathLike)) and not os.fspath(path).lower().endswith(".npz"):
        return os.fspath(path) + ".npz"
    return path


def write_archive(path, arrays, metadata, overwrite=True):
    """Write ``arrays`` and the ``metadata`` dict (as JSON) to a compressed ``.npz``,
    atomically (:func:`ti_spinorbit.files.atomic_write`: a temporary file in the same folder,
    fsync-ed, then moved over the name; a failed or killed write leaves an existing file as
    it was and never a partial one). ``path`` may also be an open binary file object.

    Returns the path written. A name ending in ``.npz`` in any case (``r.NPZ``) is written
    as given; NumPy's rule of appending ``.npz`` applies to other names only. This is the
    low-level writer (experiment scripts rewrite their own files with it); :func:`save`
    applies the overwrite rule, ``overwrite=False`` here refusing an existing file
    (:class:`ti_spinorbit.files.OutputExists`)."""
    entries = dict(metadata=np.array(json.dumps(metadata, indent=1, default=_json_default)),
                   **{k: np.asarray(v) for k, v in arrays.items()})
    if isinstance(path, (str, os.PathLike)):
        path = _archive_name(path)
        # a temporary file beside it, fsync-ed, then os.replace: a write that fails or is
        # killed never leaves a partial file under the name nor harms the file it replaces
        with atomic_write(path, overwrite=overwrite) as fh:   # NumPy keeps a file object's name
            np.savez_compressed(fh, **entries)
        return path
    np.savez_compressed(path, **entries)
    return path


# ---- writing ----------------------------------------------------------------------------
class _Systems:
    """The distinct systems of an archive, each described once (by identity, then content)."""

    def __init__(self):
        self.descriptions, self._by_id, self._by_text = [], {}, {}

    def index(self, system):
        key = id(system)
        if key not in self._by_id:
            d = describe_system(system)
            text = json.dumps(d, sort_keys=True, default=_json_default)
            if text not in self._by_text:
                self._by_text[text] = len(self.descriptions)
                self.descriptions.append(d)
            self._by_id[key] = self._by_text[text]
        return self._by_id[key]


def describe_system(system):
    """``system.describe()`` plus each body's inertia integrals (``"integrals"``,
    ``{"l,m,n": T^{lmn}}`` in kg m^(l+m+n), non-zero entries), so that
    :meth:`BinarySystem.from_description` rebuilds any body exactly, not only ellipsoids.

    A general body's integrals are written up to its order (those of degree <= 4 first, in
    the kernels' row order, then the higher ones by degree); a uniform ellipsoid's only up to
    degree 4, as a check, since its ``semi_axes_m`` and ``mass_kg`` give every order."""
    d = system.describe()
    for label, body in (("primary", system.primary), ("secondary", system.secondary)):
        row = body.as_row()[1:]
        keys = EXPONENTS_2 + EXPONENTS_3 + EXPONENTS_4
        table = {",".join(map(str, k)): float(v) for k, v in zip(keys, row) if v != 0.0}
        if not hasattr(body, "semi_axes"):
            higher = sorted((k for k in body.integrals if sum(k) > 4),
                            key=lambda k: (sum(k), -k[0], -k[1]))
            table.update({",".join(map(str, k)): float(body.integrals[k]) for k in higher})
        d[label] = {**d[label], "integrals": table}
    return d


def _is_system(x):
    return isinstance(x, BinarySystem)


#: Metadata entries that tell load() how to rebuild a result (empty ones are left out).
_BLOCK_KEYS = {"arrays": [], "object_arrays": [], "array_lists": {}, "system_refs": {},
               "records": {}, "nested": {}, "dropped": [], "perturbations": {}}


def _encode(result, prefix, systems, arrays, units_out, include_sections):
    """Put a result's arrays into ``arrays`` (names prefixed) and return its metadata block:
    which fields are arrays, scalars, systems, records, nested results."""
    kind = kind_of(result)
    table = units(kind)
    block = {"kind": kind, "fields": {}, **{k: type(v)() for k, v in _BLOCK_KEYS.items()}}
    kinds = tuple(_kinds().values())
    for f in dataclasses.fields(result):
        name, value = f.name, getattr(result, f.name)
        key = prefix + name
        if isinstance(value, kinds):
            if include_sections:
                block["nested"][name] = _encode(value, key + "/", systems, arrays, units_out,
                                                include_sections)
            else:
                block["fields"][name] = None
                block["dropped"].append(name)
        elif isinstance(value, np.ndarray):
            if value.dtype == object:
                if not all(isinstance(v, str) for v in value.flat):
                    raise TypeError(f"{kind} field {name!r}: object arrays can only be saved "
                                    "when they hold str")
                value = value.astype(str)
                block["object_arrays"].append(name)
            arrays[key] = value
            block["arrays"].append(name)
            if name == "status":
                arrays[key + "_names"] = status_names(value)
                units_out[key + "_names"] = table["status_names"]
        elif _is_system(value):
            block["system_refs"][name] = {"index": systems.index(value)}
        elif isinstance(value, list) and value and all(_is_system(s) for s in value):
            arrays[prefix + "system_index"] = np.array([systems.index(s) for s in value],
                                                       dtype=np.int64)
            block["system_refs"][name] = {"array": "system_index"}
            units_out[prefix + "system_index"] = table["system_index"]
        elif isinstance(value, list) and all(isinstance(a, np.ndarray) for a in value):
            for k, a in enumerate(value):
                arrays[f"{key}/{k}"] = a
                if name in table:
                    units_out[f"{key}/{k}"] = table[name]
            block["array_lists"][name] = len(value)
        elif isinstance(value, tuple) and name == "perturbations":
            block["perturbations"][name] = perturbations.describe(value)
        elif isinstance(value, list) and all(dataclasses.is_dataclass(r) for r in value):
            block["records"][name] = _encode_records(kind, name, value)
        elif value is None or isinstance(value, (bool, int, float, str, np.generic)):
            block["fields"][name] = value.item() if isinstance(value, np.generic) else value
        else:
            raise TypeError(f"{kind} field {name!r} of type {type(value).__name__} has no "
                            "archive representation")
        if name in table:
            units_out[key] = table[name]
        for k, v in table.items():   # units of record fields ("decisions/centre_1")
            if k.startswith(name + "/"):
                units_out[prefix + k] = v
    return {k: v for k, v in block.items() if v or k in ("kind", "fields")}


def _encode_records(kind, name, records):
    types = {type(r).__name__ for r in records}
    known = _record_types()
    if len(types) > 1 or not types <= set(known):
        raise TypeError(f"{kind} field {name!r}: records of type {sorted(types)} cannot be saved")
    items = [dataclasses.asdict(r) for r in records]
    tuples = sorted({k for item in items for k, v in item.items() if isinstance(v, tuple)})
    return {"type": types.pop() if types else None, "tuples": tuples, "items": items}


def save(result, path, extra=None, include_sections=True, overwrite=False):
    """Save a result object to ``path`` (``.npz``, compressed); returns the path written.

    An existing file is never replaced unless ``overwrite=True``: without it the save is
    refused before any work with one line naming the file and ``overwrite=True``
    (:class:`ti_spinorbit.files.OutputExists`, a FileExistsError), the rule of the command
    line's ``--overwrite``. The write is atomic: a failed or killed save leaves an existing
    file as it was and never a partial one.

    Parameters
    ----------
    result : SectionResult, TimeSeriesResult, ChaosMap, ParameterMap, OverlapScan or
        RelaxedLibration
        What the package's entry points return.
    path : str or path-like
        File to write; NumPy appends ``.npz`` when the name lacks it.
    extra : dict, optional
        More JSON-able metadata (e.g. the command line that made the result); its keys must
        not clash with the standard ones.
    include_sections : bool
        Also save a nested section (``ChaosMap.section``, ``OverlapScan.sections``) under the
        prefix ``section/`` (or ``sections/``). False drops it: smaller file, and the loaded
        result has None there.
    overwrite : bool
        Replace a file already at ``path`` (default False: refused, see above).

    The metadata holds ``kind``, ``format_version``, ``package``, ``version``, ``arch``,
    ``created_utc``, ``rtol``/``atol``/``order``/``orbits`` where the result has them,
    ``fields`` (every scalar field), ``units`` (every array and scalar), ``systems``,
    ``status_codes`` and ``status_counts``; see the module docstring for the layout.

    See Also
    --------
    load, read_metadata, to_xarray

    Examples
    --------
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5)
    >>> path = tso.save(sos, "vh_sos.npz")
    >>> with np.load("vh_sos.npz") as f:                   # NumPy alone reads it
    ...     f["theta_p"].shape
    (1, 5)
    """
    kind = kind_of(result)
    _check_save_args(path, extra)
    overwrite = require_bool("overwrite", overwrite)
    if not overwrite and isinstance(path, (str, os.PathLike)):
        refuse_existing(_archive_name(path))          # before any work; again when written
    systems, arrays, units_out = _Systems(), {}, {}
    block = _encode(result, "", systems, arrays, units_out, bool(include_sections))
    fields = block["fields"]
    meta = {"kind": kind, "format_version": FORMAT_VERSION, **provenance(),
            **{k: fields.get(k) for k in ("rtol", "atol", "order", "orbits", "method")},
            "systems": systems.descriptions, "units": units_out,
            "status_codes": {str(k): v for k, v in status_codes().items()}}
    if "status_names" in arrays:            # a top-level status array (not a nested one's)
        names, counts = np.unique(arrays["status_names"], return_counts=True)
        meta["status_counts"] = {str(n): int(c) for n, c in zip(names, counts)}
    meta.update(block)
    if extra:
        clash = sorted(set(extra) & (set(meta) | set(_BLOCK_KEYS) | {"status_counts"}))
        if clash:
            raise ValueError(f"extra metadata keys {clash} clash with the standard keys; "
                             "rename them")
        meta.update(extra)
    return write_archive(path, arrays, meta, overwrite=overwrite)


def _check_save_args(path, extra):
    """save()'s ``path`` and ``extra`` before any work: one-line TypeErrors naming them."""
    if not isinstance(path, (str, os.PathLike)) and not callable(getattr(path, "write", None)):
        raise TypeError(f"path must be a file name (str or os.PathLike) or a binary file "
                        f"object (got {type(path).__name__} {_one_line(repr(path))[:60]})")
    if extra is None:
        return
    if not isinstance(extra, dict):
        raise TypeError(f"extra must be a dict of JSON-able metadata, {{name: value}} (got "
                        f"{type(extra).__name__} {_one_line(repr(extra))[:60]})")
    bad = [k for k in extra if not isinstance(k, str)]
    if bad:
        raise TypeError(f"extra: metadata keys must be str (got {type(bad[0]).__name__} "
                        f"{bad[0]!r})")


def save_result(result, path, kind=None, extra=None, overwrite=False):
    """Alias of :func:`save` kept for older callers; ``kind``, if given, must match the
    result's kind ("section" for a SectionResult, "time_series" for a TimeSeriesResult, ...)."""
    if kind is not None and kind != kind_of(result):
        raise ValueError(f"kind {kind!r} does not match the result: a {type(result).__name__} "
                         f"is saved as kind {kind_of(result)!r}")
    return save(result, path, extra=extra, overwrite=overwrite)


# ---- reading ----------------------------------------------------------------------------
def _open(path):
    """The entries of an archive and its metadata dict, with clear errors; returns
    (zipfile.ZipFile, _Entries, metadata). The caller closes the ZipFile."""
    p = os.fspath(path)
    if not os.path.isfile(p):
        hint = f" (did you mean {p + '.npz'!r}?)" if os.path.isfile(p + ".npz") else ""
        raise FileNotFoundError(f"no saved result at {p!r}{hint}")
    try:
        with open(p, "rb") as fh:
            magic = fh.read(6)
    except OSError as exc:
        raise ArchiveError(f"{p!r} cannot be read: {_one_line(exc)}") from None
    if magic == b"\x93NUMPY":
        raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: a single .npy array, not an .npz")
    if not magic.startswith(b"PK"):
        raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: not a NumPy .npz file "
                           "(no zip signature)")
    try:
        zf = zipfile.ZipFile(p)
    except _DAMAGE as exc:
        raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: not a NumPy .npz file "
                           f"({_one_line(exc)})") from None
    try:
        entries = _Entries(p, zf)
        if "metadata" not in entries:
            raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: it has no 'metadata' "
                               f"entry (entries: {', '.join(entries.files) or 'none'})")
        try:
            text = entries.metadata()
        except ArchiveError:
            raise
        except _DAMAGE as exc:
            raise ArchiveError(f"{p!r} is damaged: its 'metadata' entry cannot be read "
                               f"({type(exc).__name__}: {_one_line(exc)})") from None
        if text.dtype.kind != "U" or text.shape != ():
            raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: its 'metadata' is not "
                               "JSON text")
        try:
            meta = json.loads(str(text))
        except (ValueError, TypeError, RecursionError) as exc:
            raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: its 'metadata' is not "
                               f"JSON ({type(exc).__name__}: {_one_line(exc)})") from None
        if not isinstance(meta, dict):
            raise ArchiveError(f"{p!r} is not a ti_spinorbit archive: its 'metadata' is not a "
                               "JSON object")
    except BaseException:
        zf.close()
        raise
    return zf, entries, meta


def read_metadata(path):
    """The JSON metadata of a saved result, as a dict (ArchiveError for a malformed file).

    Examples
    --------
    >>> _ = tso.save(tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5), "vh_meta.npz")
    >>> meta = tso.read_metadata("vh_meta.npz")
    >>> meta["kind"], meta["units"]["theta_p"]
    ('section', 'deg')
    """
    zf, _, meta = _open(path)
    zf.close()
    return meta


def load(path):
    """Load a file written by :func:`save` (or the CLI) into the same result object.

    Arrays come back identical (dtype and values, NaN padding included), scalar fields
    equal, and systems rebuilt with :meth:`BinarySystem.from_description` (identical
    parameter rows and initial states; members that shared a system share it again).
    Only the entries the metadata refers to are read, each after its sizes are checked.

    Raises
    ------
    FileNotFoundError
        No file at ``path``.
    ArchiveError
        (a ValueError) Not a ti_spinorbit archive (not an .npz, no metadata, no ``kind``), an
        unknown kind, a ``format_version`` this version of the package cannot read, or a
        damaged, malformed or edited file of any sort (every one-bit flip included; arrays
        whose shapes, dtypes or status / attitude codes are not what the package writes);
        one line naming the file and the fault.

    Examples
    --------
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5)
    >>> _ = tso.save(sos, "vh_load.npz")
    >>> again = tso.load("vh_load.npz")
    >>> type(again).__name__, bool(np.array_equal(again.theta_p, sos.theta_p))
    ('SectionResult', True)
    """
    p = os.fspath(path)
    zf, entries, meta = _open(p)
    with zf:
        if "kind" not in meta:
            raise ArchiveError(
                f"{p!r} is not a ti_spinorbit result archive: its metadata has no 'kind' (it was "
                "written by write_archive directly, e.g. by an experiment script; read it with "
                "numpy.load and ti_spinorbit.output.io.read_metadata)")
        version = meta.get("format_version", 0)
        readable = ", ".join(map(str, READABLE_FORMAT_VERSIONS))
        if type(version) is int and version > max(READABLE_FORMAT_VERSIONS):
            raise ArchiveError(
                f"{p!r} has archive format_version {version!r}; ti_spinorbit {__version__} reads "
                f"format versions {readable} (a newer package wrote it: upgrade ti_spinorbit)")
        if type(version) is not int or version not in READABLE_FORMAT_VERSIONS:
            raise ArchiveError(
                f"{p!r} has archive format_version {version!r}, which no ti_spinorbit writes "
                f"(format versions are integers; this package reads {readable}): the file is "
                "damaged")
        kind = meta["kind"]
        if not isinstance(kind, str) or kind not in _kinds():
            raise ArchiveError(f"{p!r} holds unknown kind {kind!r}; known kinds: "
                               f"{', '.join(_kinds())}")
        try:
            if version == 0:
                meta = _upgrade_v0(p, meta, entries)
            result = _decode_file(meta, entries)
            _check_loaded(p, result)
            return result
        except ArchiveError:
            raise
        except _DAMAGE as exc:
            raise ArchiveError(f"{p!r} is damaged or malformed: {type(exc).__name__}: "
                               f"{_one_line(exc)}") from None


def _decode_file(meta, entries):
    descriptions = meta.get("systems", [])
    if not isinstance(descriptions, list):
        raise TypeError(f"metadata 'systems' is a {type(descriptions).__name__}, not a list")
    systems = [BinarySystem.from_description(d) for d in descriptions]
    return _decode(meta, entries, "", systems)


def _system(systems, index):
    """systems[index] for a stored index (an int in range, never a negative one)."""
    if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)) \
            or not 0 <= index < len(systems):
        raise IndexError(f"system index {index!r} is not in 0..{len(systems) - 1}")
    return systems[int(index)]


def _decode(block, arrays, prefix, systems):
    if not isinstance(block, dict):
        raise TypeError(f"a result block is a {type(block).__name__}, not a JSON object")
    cls = _kinds()[block["kind"]]
    kwargs = dict(block.get("fields", {}))
    renamed = {**RENAMED_FIELDS[None], **RENAMED_FIELDS.get(block["kind"], {})}
    for name in block.get("arrays", []):
        value = arrays[prefix + name]
        kwargs[name] = value.astype(object) if name in block.get("object_arrays", []) else value
    for name, count in block.get("array_lists", {}).items():
        kwargs[name] = [arrays[f"{prefix}{name}/{k}"] for k in range(count)]
    for name, ref in block.get("system_refs", {}).items():
        if "index" in ref:
            kwargs[name] = _system(systems, ref["index"])
        else:
            kwargs[name] = [_system(systems, i) for i in arrays[prefix + ref["array"]].tolist()]
    for name, rec in block.get("records", {}).items():
        rtype = _record_types()[rec["type"]] if rec["type"] else None
        kwargs[name] = [rtype(**{renamed.get(k, k): tuple(v) if k in rec["tuples"] and
                                 v is not None else v for k, v in item.items()})
                        for item in rec["items"]]
    for name, sub in block.get("nested", {}).items():
        kwargs[name] = _decode(sub, arrays, f"{prefix}{name}/", systems)
    for name, items in block.get("perturbations", {}).items():
        kwargs[name] = perturbations.from_description(items)
    return cls(**{renamed.get(k, k): v for k, v in kwargs.items()})   # format 1's old names


# ---- what a loaded result must look like -------------------------------------------------
# (each result class's SHAPES, ti_spinorbit.engine.results.Result)
_F, _I, _B, _S = _results.FLOAT, _results.INTEGER, _results.BOOL, _results.TEXT


def _code_ranges():
    """Unit text of a code field -> the codes allowed (status codes, attitude classes)."""
    return {STATUS: (0, len(STATUS_NAMES) - 1), CLASS_UNIT: (-1, len(CLASSES) - 1)}


def _check_loaded(path, result):
    """Refuse a loaded result whose arrays do not have the shapes, dtypes and code ranges the
    package writes (an edited or damaged file): ArchiveError naming the file and field."""
    kind = kind_of(result)
    where = f"{path!r} is damaged or edited: {kind} field"
    dims = {}
    systems = getattr(result, "systems", None)
    if isinstance(systems, list):
        dims["n"] = len(systems)
    unit_of = field_units(result)
    ranges = _code_ranges()
    for name, (shape, kinds) in type(result).SHAPES.items():
        value = getattr(result, name, None)
        if value is None:
            continue
        if kinds == _S and isinstance(value, np.ndarray) and value.dtype == object \
                and not all(isinstance(v, str) for v in value.flat):
            bad = next(v for v in value.flat if not isinstance(v, str))
            raise ArchiveError(f"{where} {name!r} holds {type(bad).__name__} {bad!r}, not text")
        if not isinstance(value, np.ndarray) or value.dtype.kind not in kinds:
            got = value.dtype if isinstance(value, np.ndarray) else type(value).__name__
            want = {_F: "float", _I: "integer", _B: "bool", _S: "text"}[kinds]
            raise ArchiveError(f"{where} {name!r} holds {got}, not {want}")
        if value.ndim != len(shape):
            raise ArchiveError(f"{where} {name!r} has shape {value.shape}, not "
                               f"{len(shape)}-dimensional ({', '.join(map(str, shape))})")
        for axis, (d, size) in enumerate(zip(shape, value.shape)):
            want = d if isinstance(d, int) else dims.setdefault(d, size)
            if size != want:
                why = "" if isinstance(d, int) else f" ({d}), as in the other fields"
                raise ArchiveError(f"{where} {name!r} has shape {value.shape}, but its axis "
                                   f"{axis} must have {want} entries{why}")
    for name, unit_text in unit_of.items():
        value = getattr(result, name, None)
        if unit_text not in ranges or not isinstance(value, np.ndarray) or value.size == 0:
            continue
        low, high = ranges[unit_text]
        if value.dtype.kind not in _I:
            raise ArchiveError(f"{where} {name!r} holds {value.dtype}, not integer codes")
        if value.min() < low or value.max() > high:
            bad = value[(value < low) | (value > high)].flat[0]
            raise ArchiveError(f"{where} {name!r} holds code {bad}, outside {low}..{high} "
                               f"({unit_text})")
    status = getattr(result, "status", None)
    if isinstance(status, str) and status not in STATUS_NAMES:      # RelaxedLibration
        raise ArchiveError(f"{where} 'status' is {status!r}, not one of "
                           f"{', '.join(STATUS_NAMES)}")
    if kind == "relaxed_libration":
        c, x = result.candidates, result.extents
        if len(c) != len(x) or any(not isinstance(a, np.ndarray) or not isinstance(b, np.ndarray)
                                   or a.ndim != 1 or a.shape != b.shape or a.dtype.kind != "f"
                                   or b.dtype.kind != "f" for a, b in zip(c, x)):
            raise ArchiveError(f"{where}s 'candidates' and 'extents' do not pair up (one "
                               "float vector of each per launch, of equal lengths)")
    if kind == "overlap_scan" and len(result.decisions) != len(result.elongations):
        raise ArchiveError(f"{where} 'decisions' holds {len(result.decisions)} records for "
                           f"{len(result.elongations)} elongations")
    for name in ("section", "sections"):        # nested results: the same rules
        nested = getattr(result, name, None)
        if nested is not None and type(nested) in _kinds().values():
            _check_loaded(path, nested)


def _upgrade_v0(path, meta, arrays):
    """Metadata of a pre-format_version file (save_result of ti_spinorbit 0.1: a section or
    time series with one system description per member) in the version-1 layout."""
    kind = "time_series" if "alpha" in arrays else "section"
    if meta["kind"] not in ("section", "time_series"):
        raise ValueError(f"{path!r} (format_version 0) holds kind {meta['kind']!r}; format 0 "
                         "files can only be sections or time series")
    names = {f.name for f in dataclasses.fields(_kinds()[kind])}
    members = meta.get("systems", [])
    if len(members) != len(arrays["status"]):
        raise ValueError(f"{path!r}: {len(members)} system descriptions for "
                         f"{len(arrays['status'])} members")
    unique, index = [], []
    for d in members:
        if d not in unique:
            BinarySystem.from_description(d)   # fail here, naming the file's content
            unique.append(d)
        index.append(unique.index(d))
    arrays["system_index"] = np.array(index, dtype=np.int64)
    return {"kind": kind, "systems": unique,
            "fields": {k: meta[k] for k in ("rtol", "atol", "order", "orbits")
                       if k in names and meta.get(k) is not None},
            "arrays": [k for k in arrays if k in names],
            "system_refs": {"systems": {"array": "system_index"}}}


__all__ = ["save", "load", "save_result", "read_metadata", "write_archive",
           "provenance", "describe_system", "units", "status_codes", "status_names", "kind_of",
           "FORMAT_VERSION", "ArchiveError"]


def _register():
    """Give every result its ``save`` (:data:`ti_spinorbit.engine.results.BACKENDS`)."""
    _results.BACKENDS["save"] = save


_register()
