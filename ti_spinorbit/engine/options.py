"""The run options as two frozen objects, each checked once, where it is made.

Every entry point (``surface_of_section``, ``time_series``, ``chaos_map``, ``parameter_map``,
``overlap_threshold``, ``relaxed_libration``, ``libration_amplitude``) takes the same two:

* :class:`Integrator`, *how* the equations are integrated: method, tolerances, model,
  step-size controller, escape distance, order of the mutual potential;
* :class:`Run`, *how the work is carried out*: progress reporting, checkpoint and resume,
  kernel window, Dask client and chunk size. None of these changes a result.

``rtol=`` and ``method=`` stay direct keywords of every entry point, where scipy users look
for them; given beside an ``integrator=``, they must not contradict it. The objects are
frozen dataclasses in the manner of diffrax's ``PIDController`` and the kernels' own
:class:`~ti_spinorbit.kernels.controller.Controller`: a bad value fails when the object is
made, with a one-line message naming the field, never halfway through a run.
"""

from dataclasses import dataclass, replace
from os import PathLike
from typing import Any, Callable, Optional, Tuple, Union

from .._validate import require_bool, require_count, require_order, require_real, show
from ..kernels.controller import DEFAULT_CONTROLLER, Controller
from ..kernels.tableau import check_method
from ..model import models
from ..system.systems import ESCAPE_DISTANCE
from . import checkpoint as _checkpoint
from . import progress as _progress
from .ensemble import DEFAULT_WINDOW_ORBITS, check_tolerances
from .members import check_escape_distance
from .multipole_tables import check_degrees
from ..layout import multipole as _multipole_layout

_HAND_WRITTEN_MAX = _multipole_layout.HAND_WRITTEN_MAX

#: Default retries of a failed chunk on a Dask cluster before the run gives up.
DEFAULT_RETRIES = 2


def check_client(client):
    """``client`` if it is a ``dask.distributed.Client`` (or None), else a one-line TypeError
    naming what was given: raised before any work, not as an AttributeError from inside the
    run (``client.nthreads``, ``client.submit``)."""
    if client is None:
        return None
    try:
        from distributed import Client          # Dask: optional, imported with a client only
    except ImportError:
        Client = None
    if Client is not None and isinstance(client, Client):
        return client
    hint = "" if Client is not None else \
        " (dask is not installed: pip install ti-spinorbit[dask])"
    raise TypeError(f"client must be a dask.distributed.Client or None, not "
                    f"{type(client).__name__}{hint}")


@dataclass(frozen=True)
class Integrator:
    """How the equations of motion are integrated (checked when made).

    Parameters
    ----------
    method : {"cash-karp", "dop853", "vern9"}
        Runge-Kutta pair (``ti_spinorbit.kernels.tableau.METHODS``); default Cash-Karp 5(4),
        the paper's.
    rtol : float, optional
        Relative tolerance in [1e-16, 1e-2]. None: the entry point's default (1e-12 for
        sections and time series, 1e-10 for maps and scans).
    atol : float, optional
        Absolute tolerance on the scaled state (components O(1)), in (0, 1e-2]; default rtol.
    model : {"auto", "planar", "3d"}
        Equations of motion: "auto" takes the planar model when every member qualifies
        (planar starts, bodies symmetric about their equators), else the 3-D one.
    order : int
        Order of the mutual potential's expansion in inertia integrals: 0 or 2 to 16 (4, the
        paper's, by default). Up to 4 the hand-written kernels; above 4 the table-driven
        ones (docs/physics.md §3.8.2), which need both bodies' integrals to that degree.
    degrees : (int, int), optional
        Above order 4 only: caps (primary, secondary) on the degree of each body's integrals,
        each in [0, order] (a small secondary usually needs fewer); default (order, order).
    escape_distance : float
        A member stops as "escape" beyond this separation, units of a, finite and > 1.
    controller : Controller
        Step-size policy (``ti_spinorbit.kernels.controller.Controller``: safety, factor
        limits, event tolerances); another one than the default compiles its own kernels.

    See Also
    --------
    Run : how to run (progress, checkpoints, Dask)

    Examples
    --------
    >>> how = tso.Integrator(method="dop853", rtol=1e-12)
    >>> how.method, how.rtol, how.order
    ('dop853', 1e-12, 4)
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5, integrator=how)
    >>> sos.method
    'dop853'
    """

    method: str = "cash-karp"
    rtol: Optional[float] = None
    atol: Optional[float] = None
    model: str = "auto"
    order: int = 4
    escape_distance: float = ESCAPE_DISTANCE
    controller: Controller = DEFAULT_CONTROLLER
    degrees: Optional[Tuple[int, int]] = None

    def __post_init__(self):
        set_ = object.__setattr__                # frozen: normalise once, here
        set_(self, "method", check_method(self.method))
        if self.rtol is not None:
            rtol, atol = check_tolerances(self.rtol, self.atol)
            set_(self, "rtol", rtol)
            set_(self, "atol", None if self.atol is None else atol)
        elif self.atol is not None:
            check_tolerances(1e-12, self.atol)
            set_(self, "atol", float(self.atol))
        if self.model not in models.REQUESTS:
            raise ValueError(f"model must be one of {', '.join(map(repr, models.REQUESTS))} "
                             f"(got {show(self.model)})")
        set_(self, "order", require_order(self.order))
        if self.degrees is not None:
            if self.order <= _HAND_WRITTEN_MAX:
                raise ValueError(f"degrees is for orders above {_HAND_WRITTEN_MAX} (got "
                                 f"order {self.order}; up to 4 every body uses its integrals "
                                 "to the order)")
            set_(self, "degrees", check_degrees(self.order, self.degrees))
        set_(self, "escape_distance", check_escape_distance(self.escape_distance))
        if not isinstance(self.controller, Controller):
            raise TypeError(f"controller must be a ti_spinorbit.kernels.controller.Controller "
                            f"(got {type(self.controller).__name__})")

    def resolved(self, rtol=None, method=None, default_rtol=1e-12) -> "Integrator":
        """This integrator with an entry point's direct ``rtol=`` and ``method=`` applied and
        its default tolerance filled in. A direct keyword that contradicts a value set here
        is refused: the run would otherwise silently use one of the two."""
        changes = {}
        for name, value in (("rtol", rtol), ("method", method)):
            if value is None:
                continue
            mine = getattr(self, name)
            if name == "method" and mine != Integrator.method and check_method(value) != mine:
                raise ValueError(f"method={value!r} contradicts integrator=Integrator("
                                 f"method={mine!r}): give it in one place")
            if name == "rtol" and mine is not None and require_real("rtol", value) != mine:
                raise ValueError(f"rtol={value!r} contradicts integrator=Integrator("
                                 f"rtol={mine!r}): give it in one place")
            changes[name] = value
        if changes.get("rtol", self.rtol) is None:
            changes["rtol"] = default_rtol
        return replace(self, **changes) if changes else self

    @property
    def kernel_atol(self) -> float:
        """The absolute tolerance the kernels use (atol, or rtol when none was given)."""
        return self.rtol if self.atol is None else self.atol


def integrator(integrator=None, rtol=None, method=None, default_rtol=1e-12) -> Integrator:
    """An entry point's integrator: ``integrator`` (an :class:`Integrator` or None for the
    defaults) with its direct ``rtol=`` and ``method=`` (:meth:`Integrator.resolved`)."""
    if integrator is None:
        integrator = Integrator()
    elif not isinstance(integrator, Integrator):
        raise TypeError(f"integrator must be a ti_spinorbit.Integrator or None (got "
                        f"{type(integrator).__name__})")
    return integrator.resolved(rtol, method, default_rtol)


@dataclass(frozen=True)
class Run:
    """How a run is carried out: none of these changes its numbers (checked when made).

    Parameters
    ----------
    progress : bool or callable, optional
        None (default): a bar in a terminal or Jupyter for runs over 2 s; True/False:
        always/never; a callable: ``progress(fraction)`` after every window (with a
        ``client``: after every chunk) (:mod:`ti_spinorbit.engine.progress`).
    checkpoint : path, optional
        Checkpoint directory, written after every window (a map or scan: one per stage,
        ``DIR/launch-kkk``); single process only (:mod:`ti_spinorbit.engine.checkpoint`).
    resume : bool
        Continue from ``checkpoint`` (a run resumed gives the uninterrupted run's result
        bit for bit).
    overwrite : bool
        Replace a checkpoint already in ``checkpoint`` when not resuming (refused by
        default).
    keep_checkpoint : bool
        Keep ``checkpoint`` when the run finishes (default: removed once the run returns; a
        map or scan removes it after its last stage succeeded). A run that raises or is
        interrupted always keeps it, so that ``resume=True`` continues it
        (:func:`ti_spinorbit.engine.checkpoint.finish`; CLI ``--keep-checkpoint``).
    window_orbits : int
        Orbits per kernel launch, in [1, 1e6] (default 16): the interval of progress reports
        and checkpoints, and the size of the event buffers.
    client : dask.distributed.Client, optional
        Run maps and scans in chunks on the cluster behind it (the same result).
    chunk_size : int, optional
        Members per chunk with a ``client`` (default: a few chunks per worker; on GPU workers
        prefer thousands of members per chunk).
    retries : int
        Times the scheduler re-runs a failed chunk before the run fails naming it (0-1000).
    worker_arch, worker_threads : optional
        ``arch`` and ``cpu_max_num_threads`` of :func:`ti_spinorbit.init` in each worker; by
        default a worker initialises lazily (``TI_SPINORBIT_ARCH`` or the CPU).

    See Also
    --------
    Integrator : how to integrate (method, tolerances, model, order)

    Examples
    --------
    >>> quiet = tso.Run(progress=False)                   # no progress bar
    >>> sos = tso.surface_of_section("1991 VH", 0.0, [0.45], orbits=5, run=quiet)
    >>> resumable = tso.Run(checkpoint="vh.ckpt", resume=True)   # for long runs
    """

    progress: Union[None, bool, Callable[[float], None]] = None
    checkpoint: Optional[Union[str, PathLike]] = None
    resume: bool = False
    overwrite: bool = False
    window_orbits: int = DEFAULT_WINDOW_ORBITS
    client: Any = None
    chunk_size: Optional[int] = None
    retries: int = DEFAULT_RETRIES
    worker_arch: Optional[str] = None
    worker_threads: Optional[int] = None
    keep_checkpoint: bool = False

    def __post_init__(self):
        set_ = object.__setattr__
        _progress.check(self.progress)
        set_(self, "checkpoint", _checkpoint.check_path(self.checkpoint))   # a str or None
        set_(self, "resume", require_bool("resume", self.resume))
        set_(self, "overwrite", require_bool("overwrite", self.overwrite))
        set_(self, "keep_checkpoint", require_bool("keep_checkpoint", self.keep_checkpoint))
        set_(self, "window_orbits", require_count("window_orbits", self.window_orbits, 1, 10**6))
        check_client(self.client)
        if self.chunk_size is not None:
            set_(self, "chunk_size", require_count("chunk_size", self.chunk_size, 1, 10**9))
        set_(self, "retries", require_count("retries", self.retries, 0, 1000))
        if self.worker_threads is not None:
            set_(self, "worker_threads", require_count("worker_threads", self.worker_threads,
                                                       1, 4096))
        if self.client is not None and (self.checkpoint is not None or self.resume):
            raise ValueError("checkpoint/resume do not combine with a Dask client (every chunk "
                             "would share one file); failed chunks are retried instead")

    def on_worker(self) -> "Run":
        """The options a chunk runs with on a Dask worker: no client (it is not sent), no bar
        (the client reports chunks), the same kernel window."""
        return Run(progress=False, window_orbits=self.window_orbits)

    def checkpoint_keywords(self) -> dict:
        """``checkpoint``, ``resume``, ``overwrite_checkpoint``, ``keep_checkpoint`` as
        ``Ensemble.run`` takes them."""
        return dict(checkpoint=self.checkpoint, resume=self.resume,
                    overwrite_checkpoint=self.overwrite, keep_checkpoint=self.keep_checkpoint)


def run(run=None) -> Run:
    """An entry point's run options: ``run`` (a :class:`Run`), or the defaults for None."""
    if run is None:
        return Run()
    if not isinstance(run, Run):
        raise TypeError(f"run must be a ti_spinorbit.Run or None (got {type(run).__name__})")
    return run


__all__ = ["Integrator", "Run", "integrator", "run", "check_client"]
