"""Scale-out over a Dask cluster: one ensemble split into chunks, one chunk per task.

The integrator is per-member deterministic: a member's result does not depend on how many
members share its launch or on its slot (tests/test_kernels.py, ensemble invariance). So a
flat member list can be cut into contiguous chunks, each chunk integrated by
:func:`~ti_spinorbit.section.section_of` in a Dask worker process with its own Taichi
runtime, and the chunks' :class:`~ti_spinorbit.section.SectionResult` s concatenated in
member order: the result is bit-for-bit the single-process one.

Decisions:
* Dask is an optional extra (``pip install ti-spinorbit[dask]``) and is imported only inside
  :func:`run_sections`, i.e. only when a ``client`` is given.
* A failed chunk is retried ``retries`` times by the scheduler (possibly on another worker);
  when the retries are spent, :class:`ChunkError` names the chunk, its members and the
  original exception, and the other chunks are cancelled. No chunk is ever dropped.
* The member table (:class:`ti_spinorbit.members.Members`) is built once, on the client, by
  the same checks as a local run (``section.section_inputs``): what one launch decides for
  all its members (``model="auto"``: the planar model only when every member qualifies) is
  decided there over the whole table, and each chunk is a slice of it, so a chunk
  integrates its members exactly as the full launch would. Every kind of start goes to the
  cluster: the paper's (θ_p, θ̇_p), apsidal ones and explicit 3-D states (tilted starts).
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
import threading
import time
import uuid
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import runtime, section
from .runners import check_client
from ._validate import require_count

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


def run_sections(client, system, theta_p, thetadot_p, orbits, chunk_size=None,
                 retries=DEFAULT_RETRIES, arch=None, cpu_max_num_threads=None, progress=None,
                 **kwargs) -> section.SectionResult:
    """:func:`~ti_spinorbit.section.surface_of_section` split over the workers of a Dask
    cluster; the result equals the single-process one bit for bit (``seconds`` aside).

    Parameters
    ----------
    client : dask.distributed.Client
    system, theta_p, thetadot_p, orbits
        As for ``surface_of_section`` (broadcast to a flat list of N members); explicit
        starts go as ``initial_states=`` among the keywords.
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
    started = time.perf_counter()
    retries = require_count("retries", retries, 0, 1000)
    if kwargs.get("checkpoint") is not None or kwargs.get("resume"):
        raise ValueError("checkpoint/resume do not combine with a Dask client (every chunk "
                         "would share one file); failed chunks are retried instead")
    # argument errors are raised here, by the same checks as a local run, not on the workers;
    # the member table (and what "auto" decides for it) is built once, here
    members, options = section.section_inputs(system, theta_p, thetadot_p, orbits, **kwargs)
    result = run_members(client, members, orbits, options, chunk_size=chunk_size,
                         retries=retries, arch=arch, cpu_max_num_threads=cpu_max_num_threads,
                         progress=progress)
    return dataclasses.replace(result, seconds=time.perf_counter() - started)


def run_members(client, members, orbits, options, chunk_size=None, retries=DEFAULT_RETRIES,
                arch=None, cpu_max_num_threads=None, progress=None) -> section.SectionResult:
    """The Dask runner: a member table (:class:`ti_spinorbit.members.Members`) cut into
    chunks, each integrated by :func:`ti_spinorbit.section.section_of` on a worker, the
    SectionResults joined in member order (``options``: section_of's keywords, checked).
    Starts of every kind go to the cluster: the paper's (θ_p, θ̇_p), apsidal ones, explicit
    3-D states (tilted), with perturbations."""
    from distributed import as_completed

    n = len(members)
    if chunk_size is None:
        workers = max(len(client.nthreads()), 1)
        chunk_size = -(-n // (CHUNKS_PER_WORKER * workers))
    chunks = members.chunks(chunk_size)
    init = {"arch": arch, "cpu_max_num_threads": cpu_max_num_threads}
    options = dict(options, progress=False)   # no bar in a worker: the client reports chunks
    run_id = uuid.uuid4().hex[:8]
    futures = {}
    for k, (lo, hi, chunk) in enumerate(chunks):
        future = client.submit(_run_chunk, chunk, orbits, init, options,
                               key=f"ti_spinorbit-chunk-{k}-of-{len(chunks)}-{run_id}",
                               retries=retries, pure=False)
        futures[future] = k
    parts = [None] * len(chunks)
    done = 0
    try:
        for future in as_completed(list(futures)):
            k = futures[future]
            lo, hi, _ = chunks[k]
            if future.status != "finished":
                exc = future.exception()
                raise ChunkError(
                    f"chunk {k} of {len(chunks)} (members {lo}..{hi - 1}) failed after "
                    f"{retries + 1} attempt{'s' if retries else ''}: {type(exc).__name__}: "
                    f"{exc}", k, slice(lo, hi)) \
                    from exc
            parts[k] = future.result()
            done += hi - lo
            if progress is not None:
                progress(done / n)
    finally:
        client.cancel([f for f in futures if not f.done()])
    return dataclasses.replace(concatenate(parts), systems=members.systems)


def _run_chunk(members, orbits, init, options):
    """Worker side: one chunk through section_of on this process's Taichi thread.
    ``systems`` are left out of the reply (the client has them)."""
    result = _taichi_thread().submit(_integrate, members, orbits, init, options).result()
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


def _integrate(members, orbits, init, options):
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
    return section.section_of(members, orbits, **options)


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


__all__ = ["run_sections", "run_members", "concatenate", "ChunkError", "CHUNKS_PER_WORKER",
           "DEFAULT_RETRIES"]
