"""One protocol for every result: statuses, units on the fields, plot, save, xarray.

Every result class of the package (:class:`~ti_spinorbit.studies.section.SectionResult`,
:class:`~ti_spinorbit.studies.section.TimeSeriesResult`, :class:`~ti_spinorbit.studies.chaosmap.ChaosMap`,
:class:`~ti_spinorbit.studies.chaosmap.ParameterMap`, :class:`~ti_spinorbit.studies.overlap.OverlapScan`,
:class:`~ti_spinorbit.studies.libration.RelaxedLibration`) is a dataclass deriving from
:class:`Result`, and so has

* ``status`` (codes, :class:`Status`), ``status_names``, ``status_counts``, ``n_inaccurate``;
* ``seconds`` (wall time), ``rtol`` (integrator tolerance), ``orbits`` (run length, orbital
  periods);
* ``.quantity(name)``: a field as an astropy Quantity in its unit (:mod:`ti_spinorbit.units`;
  needs astropy, the ``units`` extra);
* ``.plot()`` (figures live in :mod:`ti_spinorbit.output.plotting`), ``.save(path)``
  (:func:`ti_spinorbit.output.io.save`), ``.to_xarray()`` (:func:`ti_spinorbit.output.xarray_io.to_xarray`);
* the unit of every field on the field itself: ``dataclasses.fields(cls)[k].metadata["unit"]``
  (declared with :func:`unit`), which :mod:`ti_spinorbit.output.io` writes into every archive and
  :mod:`ti_spinorbit.output.xarray_io` puts on every variable; :func:`units` collects them.

The data flow one way: the archive modules sit above the result classes (io decodes them,
xarray_io labels them), so this module imports neither; ``save`` and ``to_xarray`` reach them
through :data:`BACKENDS`, which io and xarray_io fill when they are imported (the package
imports both).
"""

import dataclasses
import enum

import numpy as np

from .. import layout, units as _units
from ..kernels import tableau as _tableau


class Status(enum.IntEnum):
    """A member's status: the integrator's verdict (kernels), then the accuracy check's
    (``INACCURATE``, set on the host by :mod:`ti_spinorbit.engine.accuracy`). The values are the
    codes stored in every ``status`` array and archive. ``STEP_BUDGET``: the member took more
    steps than its budget (``ti_spinorbit.engine.cost``) and was stopped there, so that a member the
    integrator cannot carry never stalls the ensemble (a code after ``INACCURATE`` because
    archives already hold codes 0-6). ``TRUNCATED``: a member that ran to the end within the
    drift limit, whose mutual potential's truncation error at its closest approach exceeds
    the truncation limit (:mod:`ti_spinorbit.engine.accuracy`).

    See Also
    --------
    Result : every result's ``status``, ``status_names`` and ``status_counts``

    Examples
    --------
    >>> tso.Status.DONE.label, int(tso.Status.DONE)
    ('done', 1)
    >>> tso.Status.from_label("non-finite")
    <Status.NONFINITE: 5>
    """

    RUNNING = layout.RUNNING
    DONE = layout.DONE
    COLLISION = layout.COLLISION
    ESCAPE = layout.ESCAPE
    STEP_UNDERFLOW = layout.STEP_UNDERFLOW
    NONFINITE = layout.NONFINITE
    INACCURATE = layout.INACCURATE
    STEP_BUDGET = layout.STEP_BUDGET
    TRUNCATED = layout.TRUNCATED

    @property
    def label(self) -> str:
        """The status as text: "done", "step underflow", "non-finite", ..."""
        return STATUS_NAMES[self.value]

    @classmethod
    def from_label(cls, text):
        """The Status called ``text`` ("done", "non-finite", ...), or ValueError."""
        try:
            return cls(STATUS_NAMES.index(text))
        except ValueError:
            raise ValueError(f"status must be one of {', '.join(STATUS_NAMES)} "
                             f"(got {text!r})") from None


#: Status names by code (the text of ``status_names``), ti_spinorbit.layout's.
STATUS_NAMES = layout.STATUS_NAMES

# units shared by many fields
SPIN = "mean motion n"                 # spin rates and frequencies in units of n
_METHODS = tuple(_tableau.METHODS)     # the one registry of methods (pure Python)
METHOD = ("name: Runge-Kutta pair (" + ", ".join(map(repr, _METHODS[:-1])) + " or "
          + repr(_METHODS[-1]) + ")")
STATUS = "status code (metadata status_codes)"
CLASS = "label"
RELATIVE = "1 (relative)"
ORBITS = "orbital periods"
COORDINATES = ("name: 'inertial' (θ̇ = inertial spin rate) or 'apsidal' (θ̇ = spin rate − "
               "apsidal rate ϖ̇, θ from the osculating line of apsides)")


def unit(text, **kwargs):
    """A dataclass field whose unit is ``text`` ("deg", "mean motion n", "1" for
    dimensionless); ``kwargs`` go to :func:`dataclasses.field` (``default=``, ``repr=``)."""
    metadata = dict(kwargs.pop("metadata", {}), unit=text)
    return dataclasses.field(metadata=metadata, **kwargs)


def units(cls_or_result):
    """{field: unit} of a result class or object; fields holding records (a ``records``
    entry in the field metadata, e.g. ``OverlapScan.decisions``) add their records' units
    as ``"field/name"``."""
    cls = cls_or_result if isinstance(cls_or_result, type) else type(cls_or_result)
    out = {}
    for f in dataclasses.fields(cls):
        if "unit" in f.metadata:
            out[f.name] = f.metadata["unit"]
        record = f.metadata.get("records")
        if record is not None:
            out.update({f"{f.name}/{k}": v for k, v in units(record).items()})
    return out


#: {"save": io.save, "to_xarray": xarray_io.to_xarray}, registered by those modules.
BACKENDS = {}
#: Figures, (result kind, figure name) -> function(result, **options), registered by
#: ``ti_spinorbit.output.plotting`` (which the package's front imports): a result's ``plot``
#: draws through here, so the studies never import the output layer.
FIGURES = {}
#: Result kinds, archive name -> class: each class declares its kind once, in its class
#: statement (``class ChaosMap(Result, kind="chaos_map")``); archives (io), xarray and reprs
#: read it from here or from the class's ``kind``.
KINDS = {}
#: Small dataclasses stored as JSON records inside a result (``OverlapScan.decisions``),
#: name -> class, each registered by :func:`record`.
RECORDS = {}
#: dtype kinds of ``Result.SHAPES`` (``numpy.dtype.kind`` letters).
FLOAT, INTEGER, BOOL, TEXT = "f", "iu", "b", "UO"


def record(cls):
    """Class decorator: ``cls`` (a dataclass) may be stored as records inside a result."""
    RECORDS[cls.__name__] = cls
    return cls


def _backend(name, module):
    try:
        return BACKENDS[name]
    except KeyError:
        raise RuntimeError(f"{name}: import ti_spinorbit.{module} first (importing "
                           "ti_spinorbit does)") from None


class Result:
    """The protocol every result shares (see the module docstring). Subclasses are
    dataclasses with ``status``, ``seconds``, ``rtol``, ``orbits`` fields (or properties)
    and a ``plot`` that delegates to :mod:`ti_spinorbit.output.plotting`.

    A subclass declares its archive kind in its class statement, ``class X(Result,
    kind="x")`` (registered in :data:`KINDS`), and ``SHAPES``, what its loaded arrays must
    look like: field -> (dimensions, dtype kinds). Dimensions are names bound by the first
    array that has them (``n`` members, ``w`` crossings, ``s`` samples, ``k`` lengths, ...) or
    fixed sizes; dtype kinds are :data:`FLOAT`, :data:`INTEGER`, :data:`BOOL`, :data:`TEXT`.
    A field not listed is not checked; a listed one that does not fit makes
    :func:`ti_spinorbit.output.io.load` refuse the file, naming the field.

    See Also
    --------
    save, load, to_xarray, Status

    Examples
    --------
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5)
    >>> isinstance(sos, tso.Result)
    True
    >>> sos.units()["t"], sos.orbits
    ('s', 5.0)
    """

    #: the archive kind (:data:`KINDS`); "" for the protocol itself
    kind = ""
    SHAPES = {}

    def __init_subclass__(cls, kind=None, **kwargs):
        super().__init_subclass__(**kwargs)
        if kind is not None:
            if KINDS.get(kind, cls) is not cls:
                raise TypeError(f"result kind {kind!r} is already {KINDS[kind].__name__}'s")
            cls.kind = kind
            KINDS[kind] = cls

    def _status_array(self):
        status = getattr(self, "status", None)
        if status is None:
            return np.zeros(0, dtype=np.int32)
        if isinstance(status, str):            # RelaxedLibration: one trajectory, by name
            return np.array([Status.from_label(status).value], dtype=np.int32)
        return np.asarray(status)

    @property
    def status_names(self):
        """Each member's status as text ("done", "inaccurate", "collision", ...), a list in
        the order (and, flattened, the shape) of ``status``; it prints on one line, however
        many members (:class:`ti_spinorbit.display.Names`)."""
        from ..display import Names      # the display module: no engine imports, no cycle

        return Names(STATUS_NAMES[s] for s in self._status_array().ravel())

    @property
    def status_counts(self) -> dict:
        """Members per status name, e.g. {"done": 30, "inaccurate": 2}."""
        codes, n = np.unique(self._status_array().ravel(), return_counts=True)
        return {STATUS_NAMES[int(c)]: int(k) for c, k in zip(codes, n)}

    @property
    def n_inaccurate(self) -> int:
        """Members that finished with a drift above ``max_drift`` (data kept, status
        "inaccurate")."""
        return int(np.count_nonzero(self._status_array() == Status.INACCURATE))

    def save(self, path, **kwargs):
        """Write this result to ``path`` (``.npz``): :func:`ti_spinorbit.output.io.save` (keywords
        ``extra``, ``include_sections``, ``overwrite``: an existing file is refused unless
        ``overwrite=True``); returns the path written."""
        return _backend("save", "io")(self, path, **kwargs)

    def to_xarray(self):
        """This result as a labelled ``xarray.Dataset`` with units
        (:func:`ti_spinorbit.output.xarray_io.to_xarray`; needs xarray)."""
        return _backend("to_xarray", "xarray_io")(self)

    def _figure(self, name="plot", **options):
        """Draw figure ``name`` of this result (:data:`FIGURES`); returns what it returns."""
        try:
            draw = FIGURES[self.kind, name]
        except KeyError:
            raise RuntimeError(f"{type(self).__name__}: no figure {name!r}; import "
                               "ti_spinorbit.output.plotting first (importing ti_spinorbit "
                               "does)") from None
        return draw(self, **options)

    @classmethod
    def units(cls):
        """{field: unit} of this result class (:func:`units`)."""
        return units(cls)

    def quantity(self, name):
        """Field ``name`` as an ``astropy.units.Quantity`` in its unit (the unit text of
        :meth:`units` read by :func:`ti_spinorbit.units.astropy_unit`): "m", "s", "J",
        "deg" as astropy's, dimensionless ratios as ``dimensionless_unscaled``, spin rates
        in ``ti_spinorbit.units.n`` (the mean motion) and lengths of time in
        ``ti_spinorbit.units.orbit`` (the orbital period), which
        ``ti_spinorbit.units.equivalencies(system)`` turns into rad/s and s. A field of
        records is named "field/name", as :meth:`units` lists it
        (``scan.quantity("decisions/centre_1")``: one value per record). A field that holds no physical quantity
        (status codes, names, flags, objects) or no field at all: ValueError listing the
        valid names. Needs astropy (``pip install ti-spinorbit[units]``): ImportError
        otherwise."""
        return _units.field_quantity(self, name, units(self))

    def plot(self, *args, **kwargs):      # pragma: no cover - every result overrides it
        raise NotImplementedError(f"{type(self).__name__}.plot")


__all__ = ["Status", "STATUS_NAMES", "Result", "KINDS", "RECORDS", "FIGURES", "record", "unit",
           "units"]
