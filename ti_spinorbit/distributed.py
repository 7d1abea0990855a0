"""Scale-out over a Dask cluster: one ensemble split into chunks, one chunk per task (issue 5,
item 5).

The integrator is per-member deterministic: a member's result does not depend on how many
members share its launch or on its slot (tests/test_kernels.py, ensemble invariance). So a
flat member list can be cut into contiguous chunks, each chunk integrated by
:func:`~ti_spinorbit.section.surface_of_section` in a Dask worker process with its own Taichi
runtime, and the chunks' :class:`~ti_spinorbit.section.SectionResult` s concatenated in
member order: the result is bit-for-bit the single-process one.

Decisions:
* Dask is an optional extra (``pip install ti-spinorbit[dask]``) and is imported only inside
  :func:`run_sections`, i.e. only when a ``client`` is given.
* A failed chunk is retried ``retries`` times by the scheduler (possibly on another worker);
  when the retries are spent, :class:`ChunkError` names the chunk, its members and the
  original exception, and the other chunks are cancelled. No chunk is ever dropped.
* What one launch decides for all its members (``model="auto"``: the planar model only when
  every member qualifies) is decided here over the whole member list and passed to every
  chunk, so a chunk integrates its members exactly as the full launch would.
* ``checkpoint``/``resume`` are refused: every chunk would write the same file.
* Taichi's runtime is process-global and its LLVM backends compile only in the thread that
  initialised them, so each worker process runs its chunks one at a time in one dedicated
  thread: use process-based workers with one thread each, and let Taichi use the cores
  (``cpu_max_num_threads``) or the GPU. Do not call ``ti_spinorbit.init`` on the workers
  yourself (``client.run`` uses another thread).
* Workers initialise Taichi with ``arch``/``cpu_max_num_threads`` when given, else lazily with
  the package defaults (which honour ``TI_SPINORBIT_ARCH`` in the worker's environment).
* ``progress(fraction)`` is called on the client, with the share of members in finished
  chunks, each time a chunk comes back.
"""

import dataclasses
import inspect
import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import runtime, section
from ._validate import require_count
from .ensemble import check_tolerances

#: Default number of chunks per worker process: enough to balance members of unequal cost
#: (chaotic members, early escapes) without paying Taichi's per-launch overhead too often.
#: Per process, not per thread: a worker runs its chunks one at a time (see _taichi_thread).
CHUNKS_PER_WORKER = 3
#: Default retries of a failed chunk before :func:`run_sections` gives up.
DEFAULT_RETRIES = 2

_THREAD = {"executor": None, "generation": None}  # see _taichi_thread
_THREAD_LOCK = threading.Lock()


class ChunkError(RuntimeError):
    """A chunk kept failing after all its retries; ``chunk`` is its index, ``members`` the
    slice of the flat member list it held; the original exception is ``__cause__``."""

    def __init__(self, message, chunk, members):
        super().__init__(message)
        self.chunk = chunk
        self.members = members


def check_client(client):
    """``client`` if it is a ``dask.distributed.Client`` (or None), else a one-line TypeError
    naming what was given: raised before any work, not as an AttributeError from inside the
    run (``client.nthreads``, ``client.submit``)."""
    if client is None:
        return None
    try:
        from distributed import Client
    except ImportError:
        Client = None
    if Client is not None and isinstance(client, Client):
        return client
    hint = "" if Client is not None else \
        " (dask is not installed: pip install ti-spinorbit[dask])"
    raise TypeError(f"client must be a dask.distributed.Client or None, not "
                    f"{type(client).__name__}{hint}")


def sections(client, system_or_systems, theta_p, thetadot_p, orbits, chunk_size=None,
             **kwargs) -> section.SectionResult:
    """``surface_of_section`` in this process when ``client`` is None, else
    :func:`run_sections` on the cluster behind ``client`` (same arguments, same result)."""
    check_client(client)
    if client is None:
        return section.surface_of_section(system_or_systems, theta_p, thetadot_p, orbits,
                                          **kwargs)
    return run_sections(client, system_or_systems, theta_p, thetadot_p, orbits,
                        chunk_size=chunk_size, **kwargs)


def run_sections(client, system_or_systems, theta_p, thetadot_p, orbits, chunk_size=None,
                 retries=DEFAULT_RETRIES, arch=None, cpu_max_num_threads=None, progress=None,
                 **kwargs) -> section.SectionResult:
    """:func:`~ti_spinorbit.section.surface_of_section` split over the workers of a Dask
    cluster; the result equals the single-process one bit for bit (``seconds`` aside).

    Parameters
    ----------
    client : dask.distributed.Client
    system_or_systems, theta_p, thetadot_p, orbits
        As for ``surface_of_section`` (broadcast to a flat list of N members).
    chunk_size : int, optional
        Members per task. Default: N split into ``CHUNKS_PER_WORKER`` chunks per worker
        process. On GPU workers prefer large chunks (thousands of members per launch).
    retries : int
        Times the scheduler re-runs a failed chunk before :class:`ChunkError` is raised.
    arch, cpu_max_num_threads : optional
        Passed to :func:`ti_spinorbit.init` in each worker; by default a worker initialises
        lazily (``TI_SPINORBIT_ARCH`` or the CPU). A worker already initialised with the same
        arch keeps its runtime.
    progress : callable, optional
        ``progress(fraction)`` on the client after every finished chunk.
    **kwargs
        Passed to ``surface_of_section`` (``rtol``, ``atol``, ``order``, ``window_orbits``,
        ``escape_distance``, ``indicators``, ``coordinates``, ``perturbations``).
        ``perturbations`` (tides, YORP, BYORP; docs/physics.md §13) are checked here and sent
        to every chunk as the same objects, so each member's block is built from its own
        system exactly as in one launch: the result is again bit for bit the
        single-process one, ``perturbations`` recorded.

    Returns
    -------
    SectionResult
        Members in input order; ``seconds`` is the wall time of the whole run, ``systems``
        the flat member list of this process.
    """
    check_client(client)
    from distributed import as_completed

    started = time.perf_counter()
    retries = require_count("retries", retries, 0, 1000)
    # argument errors are raised here, not retried on the workers
    call = inspect.signature(section.surface_of_section).bind(
        system_or_systems, theta_p, thetadot_p, orbits, **kwargs)
    call.apply_defaults()
    section.check_orbits(orbits)
    from .perturbations import check_perturbations
    kwargs["perturbations"] = check_perturbations(call.arguments["perturbations"])
    section.check_size("run_sections", system_or_systems, theta_p, thetadot_p, orbits,
                       perturbed=bool(kwargs["perturbations"]))
    check_tolerances(call.arguments["rtol"], call.arguments["atol"])
    from .kernels.tableau import check_method
    check_method(call.arguments["method"])
    if call.arguments.get("checkpoint") is not None or call.arguments.get("resume"):
        raise ValueError("checkpoint/resume do not combine with a Dask client (every chunk "
                         "would share one file); failed chunks are retried instead")
    members, par, y0, tp, td = section.build_members(system_or_systems, theta_p, thetadot_p,
                                                     call.arguments["escape_distance"],
                                                     call.arguments["coordinates"],
                                                     call.arguments["order"])
    if call.arguments.get("indicators") and call.arguments.get("indicator_space") == "full" \
            and call.arguments.get("model") == "auto":
        kwargs["model"] = "3d"            # full-space indicators need the 3-D model
    elif call.arguments.get("model") == "auto":
        # decided over the whole ensemble, as one launch would, not chunk by chunk
        from .models import choose
        kwargs["model"] = choose("auto", par, y0).name
    n = len(members)
    if chunk_size is None:
        workers = max(len(client.nthreads()), 1)
        chunk_size = -(-n // (CHUNKS_PER_WORKER * workers))
    chunk_size = require_count("chunk_size", chunk_size, 1, 10**9)
    bounds = [(lo, min(lo + chunk_size, n)) for lo in range(0, n, chunk_size)]
    init = {"arch": arch, "cpu_max_num_threads": cpu_max_num_threads}
    run_id = uuid.uuid4().hex[:8]
    futures = {}
    for k, (lo, hi) in enumerate(bounds):
        future = client.submit(_run_chunk, members[lo:hi], tp[lo:hi], td[lo:hi], orbits, init,
                               kwargs, key=f"ti_spinorbit-chunk-{k}-of-{len(bounds)}-{run_id}",
                               retries=retries, pure=False)
        futures[future] = k
    parts = [None] * len(bounds)
    done = 0
    try:
        for future in as_completed(list(futures)):
            k = futures[future]
            if future.status != "finished":
                exc = future.exception()
                lo, hi = bounds[k]
                raise ChunkError(
                    f"chunk {k} of {len(bounds)} (members {lo}..{hi - 1}) failed after "
                    f"{retries + 1} attempt{'s' if retries else ''}: {type(exc).__name__}: "
                    f"{exc}", k, slice(lo, hi)) \
                    from exc
            parts[k] = future.result()
            done += bounds[k][1] - bounds[k][0]
            if progress is not None:
                progress(done / n)
    finally:
        client.cancel([f for f in futures if not f.done()])
    result = concatenate(parts)
    return dataclasses.replace(result, systems=members, seconds=time.perf_counter() - started)


def _run_chunk(systems, theta_p, thetadot_p, orbits, init, kwargs):
    """Worker side: one chunk through surface_of_section on this process's Taichi thread.
    ``systems`` are left out of the reply (the client has them)."""
    result = _taichi_thread().submit(_integrate, systems, theta_p, thetadot_p, orbits, init,
                                     kwargs).result()
    return dataclasses.replace(result, systems=[])


def _taichi_thread():
    """The one thread of this process that initialises Taichi and launches its kernels.

    Taichi's LLVM backends (CPU, CUDA) only compile in the thread that called ``ti.init``,
    while Dask runs tasks in whichever pool thread is free: so every chunk is handed to this
    single thread, which also serialises chunks sharing the process-global runtime."""
    with _THREAD_LOCK:
        if _THREAD["executor"] is None:
            _THREAD["executor"] = ThreadPoolExecutor(1, thread_name_prefix="ti_spinorbit-taichi")
        return _THREAD["executor"]


def _integrate(systems, theta_p, thetadot_p, orbits, init, kwargs):
    if runtime.current_arch() is not None and runtime.generation() != _THREAD["generation"]:
        raise RuntimeError(
            "Taichi was initialised in this worker process outside ti_spinorbit.distributed "
            "(its LLVM backends then refuse to compile in the worker's Taichi thread): do not "
            "call ti_spinorbit.init on the workers; pass arch= / cpu_max_num_threads= to "
            "run_sections, set TI_SPINORBIT_ARCH in the workers' environment, and use "
            "process-based workers (LocalCluster(processes=True))")
    if init["arch"] is not None or init["cpu_max_num_threads"] is not None:
        runtime.init(init["arch"], cpu_max_num_threads=init["cpu_max_num_threads"])
    else:
        runtime.ensure_init()
    _THREAD["generation"] = runtime.generation()
    # no bar in a worker (the client reports chunks); its stderr may well be a terminal
    return section.surface_of_section(systems, theta_p, thetadot_p, orbits,
                                      **dict(kwargs, progress=False))


def concatenate(parts) -> section.SectionResult:
    """SectionResults of consecutive member chunks as one: per-member arrays (first axis the
    chunk's member count) are joined, and the crossing axis is NaN-padded to the longest
    chunk; scalar fields come from the first chunk; ``systems`` lists are joined; ``seconds``
    is summed (callers that know the wall time replace it)."""
    if not parts:
        raise ValueError("concatenate needs at least one SectionResult")
    sizes = [len(p.count) for p in parts]
    joined = {}
    for f in dataclasses.fields(section.SectionResult):
        values = [getattr(p, f.name) for p in parts]
        first = values[0]
        if f.name == "systems":
            joined[f.name] = [s for v in values for s in v]
        elif f.name == "seconds":
            joined[f.name] = float(sum(values))
        elif isinstance(first, np.ndarray) and first.ndim >= 1 and all(
                isinstance(v, np.ndarray) and len(v) == m for v, m in zip(values, sizes)):
            joined[f.name] = _join(values)
        else:
            joined[f.name] = first
    return section.SectionResult(**joined)


def _join(arrays):
    """Concatenate along axis 0, NaN-padding axis 1 (crossings) to the widest array."""
    if arrays[0].ndim >= 2:
        width = max(a.shape[1] for a in arrays)
        padded = []
        for a in arrays:
            if a.shape[1] < width:
                pad = np.full((a.shape[0], width - a.shape[1]) + a.shape[2:], np.nan)
                a = np.concatenate([a, pad], axis=1)
            padded.append(a)
        arrays = padded
    return np.concatenate(arrays, axis=0)


__all__ = ["run_sections", "sections", "check_client", "concatenate", "ChunkError", "CHUNKS_PER_WORKER",
           "DEFAULT_RETRIES"]
