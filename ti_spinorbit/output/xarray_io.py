"""Results as labelled :class:`xarray.Dataset` objects (optional: ``pip install "ti-spinorbit[xarray]"``).

:func:`to_xarray` gives every array of a result its named dimensions and coordinates and a
``units`` attribute (the same units :func:`ti_spinorbit.output.io.save` writes), and the scalar
metadata as dataset attributes, ready for ``.sel``, ``.plot`` or ``.to_netcdf``. xarray is
imported only when :func:`to_xarray` is called, never at package import.

Dimensions per result:

=====================  ===========================================================
SectionResult          (member, crossing); member coords initial_theta_p, initial_thetadot_p
TimeSeriesResult       (member, sample); angular momenta also (component: x, y, z)
ChaosMap               (theta_p, thetadot_p)
ParameterMap           (elongation, eccentricity); per start also (start) with coords
                       theta_p, thetadot_p
OverlapScan            (elongation); the ranges also (bound: low, high)
RelaxedLibration       (candidate) with coord launch (0: coarse bracket, then zooms)
=====================  ===========================================================

Every array field of a result is there (round trip: ``tests/test_files_safety.py``):

* state rows, ``initial_states`` (member, element) and a time series' ``states`` (member,
  sample, element), with the coordinate ``element`` (``R_x`` ... ``secondary_omega_z``,
  docs/physics.md §6.8) and ``element_unit`` giving each column's unit;
* ``max_tilt``, ``max_npa_angle`` (deg), ``attitude_class`` (code) with
  ``attitude_class_name`` (text), per member (or per map cell); ``stop_status`` where kept;
  ``truncation_force``, ``truncation_torque`` (the mutual potential's truncation estimate);
* the convergence evidence over run lengths, dimension ``length`` (orbits):
  ``fraction_by_length`` (chaos map; parameter map also per elongation and eccentricity,
  with ``fraction_monotone``), ``overlaps_by_length`` and ``megno_overlaps_by_length``
  (overlap scan, per elongation), ``centres_by_length`` and ``amplitudes_by_length``
  (relaxed libration); a chaos map's start ``tilt`` (dimension ``tilt_angle``: roll, pitch).

A nested section (``ChaosMap.section``, ``OverlapScan.sections``) is not merged in (its
dimensions differ): convert it on its own, ``to_xarray(cmap.section)``.

Tides, YORP and BYORP (``perturbations=``, docs/physics.md §13) travel as the attribute
``perturbations``: JSON text of :func:`ti_spinorbit.model.perturbations.describe` (``"[]"``
without them), read back with ``perturbations.from_description(json.loads(...))``. A
perturbed time series also has ``work`` (J) and ``external_angmom`` (kg m² s⁻¹, with
``component``) per sample.
"""

import json
import os

import numpy as np

from . import io
from ..engine import results as _results
from ..model.attitude import CLASSES
from ..system.initial import _UNITS, ROW_SLICES
from ..model.perturbations import describe as _describe_perturbations
from ..engine.results import units as field_units

INSTALL_HINT = 'to_xarray needs xarray: pip install "ti-spinorbit[xarray]"'


def _xarray():
    try:
        import xarray           # optional dependency: imported on first use only
    except ImportError as exc:
        raise ImportError(INSTALL_HINT) from exc
    return xarray


def _attrs(result, kind, metadata):
    """JSON-able scalar metadata: the result's scalar fields, provenance, systems (as JSON)."""
    attrs = {"kind": kind}
    source = metadata if metadata is not None else {**io.provenance(),
                                                    "format_version": io.FORMAT_VERSION}
    for key in ("format_version", "package", "version", "arch", "created_utc"):
        if source.get(key) is not None:
            attrs[key] = source[key]
    for name, value in vars(result).items():
        if isinstance(value, np.generic):
            value = value.item()
        if isinstance(value, (bool, np.bool_)):
            attrs[name] = int(value)           # netCDF has no bool attribute
        elif isinstance(value, (int, float, str)):
            attrs[name] = value
    if isinstance(getattr(result, "perturbations", None), tuple):
        attrs["perturbations"] = json.dumps(_describe_perturbations(result.perturbations))
    systems = getattr(result, "systems", None)
    if systems is None and getattr(result, "system", None) is not None:
        systems = [result.system]
    for nested in ("section", "sections"):   # ChaosMap.section, OverlapScan.sections
        if systems is None and getattr(result, nested, None) is not None:
            systems = getattr(result, nested).systems
    if systems:
        unique = []
        for s in systems:
            if not any(s is u for u in unique):
                unique.append(s)
        attrs["systems"] = json.dumps([io.describe_system(s) for s in unique],
                                     default=io._json_default)
    return attrs


def _labels(a):
    """Object arrays of str as fixed-width unicode (netCDF cannot hold Python objects)."""
    return a.astype(str) if isinstance(a, np.ndarray) and a.dtype == object else a


def _element_labels():
    """The 30 columns of a state row (``ti_spinorbit.system.initial.ROW_SLICES``) as labels: ``R_x``,
    ``V_z``, ``primary_attitude_01`` (row 0, column 1), ``secondary_omega_y``, ...; and the
    unit of each column."""
    labels, col_units = [], []
    for name, sl in ROW_SLICES.items():
        size = sl.stop - sl.start
        labels += ([f"{name}_{c}" for c in "xyz"] if size == 3 else
                   [f"{name}_{i}{j}" for i in range(3) for j in range(3)])
        col_units += [_UNITS[name]] * size
    return labels, col_units


def _states(data, coords, r, dims):
    """Initial state rows (member, element) and sampled ones (``dims`` + element), where the
    result has them, with the element coordinate and the unit of each column."""
    rows = {"initial_states": ("member", "element"), "states": (*dims, "element")}
    present = [k for k in rows if getattr(r, k, None) is not None]
    for k in present:
        data[k] = (rows[k], getattr(r, k))
    if present:
        labels, col_units = _element_labels()
        coords["element"] = labels
        coords["element_unit"] = ("element", col_units)


def _attitude(data, r, dims):
    """Pole tilt, non-principal-axis angle, attitude class (code and name), stop status and
    truncation estimates, where present."""
    for k in ("max_tilt", "max_npa_angle", "stop_status", "truncation_force",
              "truncation_torque"):
        if getattr(r, k, None) is not None:
            data[k] = (dims, getattr(r, k))
    if getattr(r, "degrees", None) is not None:       # an order-N run's caps
        data["degrees"] = (("body",), np.asarray(r.degrees))
    if getattr(r, "attitude_class", None) is not None:
        codes = np.asarray(r.attitude_class)
        data["attitude_class"] = (dims, codes)
        names = np.array([CLASSES[c] if 0 <= c < len(CLASSES) else "" for c in codes.ravel()],
                         dtype=str).reshape(codes.shape)
        data["attitude_class_name"] = (dims, names)


def _by_length(data, coords, r, fields, dims):
    """Convergence evidence: the arrays over the run lengths checked (``length`` dimension,
    coordinate ``lengths``-field in orbits), with ``dims`` after it where given."""
    lengths_field, values = fields[0], fields[1:]
    lengths = getattr(r, lengths_field, None)
    if lengths is None:
        return
    coords["length"] = np.asarray(lengths)
    for k in values:
        v = getattr(r, k, None)
        if v is not None:
            data[k] = (("length", *dims[k]), v)


def _section(r, units):
    n, width = np.shape(r.theta_p)
    member_vars = ["count", "energy_drift", "angmom_drift", "status", "accepted", "rejected",
                   "rhs_calls", "megno", "lyapunov"]
    data = {k: (("member", "crossing"), getattr(r, k)) for k in ("theta_p", "thetadot_p", "t", "r", "a", "e")}
    data.update({k: ("member", getattr(r, k)) for k in member_vars if getattr(r, k) is not None})
    data["status_name"] = ("member", io.status_names(r.status))
    if getattr(r, "apsidal_rate", None) is not None:     # coordinates="apsidal" only
        data["apsidal_rate"] = (("member", "crossing"), r.apsidal_rate)
    coords = {"member": np.arange(n), "crossing": np.arange(width),
              "initial_theta_p": ("member", r.initial_theta_p),
              "initial_thetadot_p": ("member", r.initial_thetadot_p),
              "system": ("member", [s.name for s in r.systems])}
    _states(data, coords, r, ("member",))
    _attitude(data, r, ("member",))
    return data, coords


def _time_series(r, units):
    n, width = np.shape(r.t)
    data = {k: (("member", "sample"), getattr(r, k))
            for k in ("t", "alpha", "theta", "thetadot", "r", "energy", "energy_orbit",
                      "energy_primary", "energy_secondary")}
    data.update({k: (("member", "sample", "component"), getattr(r, k))
                 for k in ("angmom_orbit", "angmom_primary", "angmom_secondary")})
    data["status"] = ("member", r.status)
    data["status_name"] = ("member", io.status_names(r.status))
    for k in ("energy_drift", "angmom_drift"):          # absent in files from before issue 10
        if getattr(r, k, None) is not None:
            data[k] = ("member", getattr(r, k))
    if getattr(r, "work", None) is not None:             # with perturbations only
        data["work"] = (("member", "sample"), r.work)
    if getattr(r, "external_angmom", None) is not None:
        data["external_angmom"] = (("member", "sample", "component"), r.external_angmom)
    coords = {"member": np.arange(n), "sample": np.arange(width), "component": ["x", "y", "z"],
              "system": ("member", [s.name for s in r.systems])}
    if r.initial_theta_p is not None:
        coords["initial_theta_p"] = ("member", r.initial_theta_p)
    if r.initial_thetadot_p is not None:
        coords["initial_thetadot_p"] = ("member", r.initial_thetadot_p)
    _states(data, coords, r, ("member", "sample"))
    _attitude(data, r, ("member",))
    return data, coords


def _chaos_map(r, units):
    dims = ("theta_p", "thetadot_p")
    data = {k: (dims, _labels(getattr(r, k)))
            for k in ("megno", "lyapunov", "classification", "mean_thetadot", "status",
                      "energy_drift", "angmom_drift") if getattr(r, k) is not None}
    data["status_name"] = (dims, io.status_names(r.status))
    coords = {"theta_p": r.theta_p, "thetadot_p": r.thetadot_p}
    _attitude(data, r, dims)
    _by_length(data, coords, r, ("fraction_lengths", "fraction_by_length"),
               {"fraction_by_length": ()})
    if getattr(r, "tilt", None) is not None:         # the map's start tilt (roll, pitch)
        data["tilt"] = ("tilt_angle", np.asarray(r.tilt))
        coords["tilt_angle"] = ["roll", "pitch"]
    return data, coords


def _parameter_map(r, units):
    grid, per_start = ("elongation", "eccentricity"), ("elongation", "eccentricity", "start")
    data = {"chaotic_fraction": (grid, r.chaotic_fraction),
            "megno": (per_start, r.megno), "classification": (per_start, _labels(r.classification)),
            "status": (per_start, r.status), "status_name": (per_start, io.status_names(r.status)),
            "omega0": ("elongation", r.omega0)}
    for k, dims in (("energy_drift", per_start), ("angmom_drift", per_start), ("inaccurate", grid)):
        if getattr(r, k) is not None:
            data[k] = (dims, getattr(r, k))
    coords = {"elongation": r.elongations, "eccentricity": r.eccentricities,
              "start": np.arange(len(r.theta_p)), "theta_p": ("start", r.theta_p),
              "thetadot_p": ("start", r.thetadot_p)}
    if getattr(r, "fraction_monotone", None) is not None:
        data["fraction_monotone"] = (grid, np.asarray(r.fraction_monotone))
    _by_length(data, coords, r, ("fraction_lengths", "fraction_by_length"),
               {"fraction_by_length": grid})
    return data, coords


def _overlap_scan(r, units):
    d = r.decisions

    def col(name):
        return np.array([np.nan if getattr(x, name) is None else getattr(x, name) for x in d],
                        dtype=np.float64)

    def ranges(name):
        return np.array([(np.nan, np.nan) if getattr(x, name) is None else getattr(x, name)
                         for x in d], dtype=np.float64).reshape(len(d), 2)

    data = {"overlaps": ("elongation", r.overlaps)}
    for name in ("omega0", "centre_1", "centre_3_2", "connecting_start", "connecting_megno",
                 "connecting_lyapunov", "separatrix_chaotic_fraction", "inaccurate",
                 "max_energy_drift"):
        data[name] = ("elongation", col(name))
    data["centre_3_2_found"] = ("elongation", np.array([x.centre_3_2_found for x in d], dtype=bool))
    for name in ("connecting_range", "widest_range"):
        data[name] = (("elongation", "bound"), ranges(name))
    for name in list(data):
        units.setdefault(name, units.get("decisions/" + name))
    coords = {"elongation": r.elongations, "bound": ["low", "high"]}
    _by_length(data, coords, r, ("lengths", "overlaps_by_length", "megno_overlaps_by_length"),
               {"overlaps_by_length": ("elongation",),
                "megno_overlaps_by_length": ("elongation",)})
    return data, coords


def _relaxed_libration(r, units):
    launch = np.concatenate([np.full(len(c), k) for k, c in enumerate(r.candidates)])
    data = {"extent": ("candidate", np.concatenate(r.extents))}
    coords = {"candidate": np.arange(len(launch)), "launch": ("candidate", launch),
              "thetadot_p": ("candidate", np.concatenate(r.candidates))}
    units["extent"], units["thetadot_p"] = units["extents"], units["candidates"]
    _by_length(data, coords, r, ("lengths", "centres_by_length", "amplitudes_by_length"),
               {"centres_by_length": (), "amplitudes_by_length": ()})
    return data, coords


#: Dataset layouts by result kind (``Result.kind``).
_BUILDERS = {"section": _section, "time_series": _time_series, "chaos_map": _chaos_map,
             "parameter_map": _parameter_map, "overlap_scan": _overlap_scan,
             "relaxed_libration": _relaxed_libration}
_COORD_UNITS = {"elongation": "1 (a/b)", "eccentricity": "1", "member": "index",
                "crossing": "index", "sample": "index", "start": "index", "candidate": "index",
                "launch": "index", "component": "inertial axis", "bound": "",
                "system": "name", "status_name": "name", "attitude_class_name": "name",
                "element": "state row column (docs/physics.md §6.8)", "element_unit": "unit",
                "length": "orbital periods", "tilt_angle": "name"}


def to_xarray(result_or_path):
    """An :class:`xarray.Dataset` of a result, or of a file written by :func:`ti_spinorbit.output.io.save`.

    Parameters
    ----------
    result_or_path : result object or str / path-like
        A SectionResult, TimeSeriesResult, ChaosMap, ParameterMap, OverlapScan or
        RelaxedLibration, or the path of a saved one (then the dataset's attrs carry the
        file's provenance: version, arch, created_utc).

    Returns
    -------
    xarray.Dataset
        Data variables and coordinates with a ``units`` attribute each; scalar fields,
        provenance and the systems (JSON text, ``attrs["systems"]``) as attributes.

    Raises
    ------
    ImportError
        xarray is not installed (``pip install "ti-spinorbit[xarray]"``).

    Examples
    --------
    >>> ds = tso.to_xarray(tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5))
    >>> ds["theta_p"].attrs["units"]
    'deg'
    """
    xr = _xarray()
    metadata = None
    if isinstance(result_or_path, (str, os.PathLike)):
        metadata = io.read_metadata(result_or_path)
        result = io.load(result_or_path)
    else:
        result = result_or_path
    kind = io.kind_of(result)                       # the kind the result class declares
    units = {**io.ARCHIVE_UNITS, **field_units(result)}     # units live on the fields
    if kind not in _BUILDERS:
        raise TypeError(f"to_xarray has no layout for {type(result).__name__} (kind {kind!r})")
    data, coords = _BUILDERS[kind](result, units)
    ds = xr.Dataset(data, coords=coords, attrs=_attrs(result, kind, metadata))
    for name, var in ds.variables.items():
        unit = units.get(name, _COORD_UNITS.get(name))
        if unit is not None:
            var.attrs["units"] = unit
    return ds


__all__ = ["to_xarray"]


_results.BACKENDS["to_xarray"] = to_xarray      # every result's to_xarray (results.BACKENDS)
