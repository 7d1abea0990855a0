"""Scale-out over a Dask cluster: one ensemble split into chunks, one chunk per task.

The integrator is per-member deterministic: a member's result does not depend on how many
members share its launch or on its slot (tests/test_kernels.py, ensemble invariance). So a
flat member list can be cut into contiguous chunks, each chunk integrated by
:func:`~ti_spinorbit.studies.section.section_of` in a Dask worker process with its own Taichi
runtime, and the chunks' :class:`~ti_spinorbit.studies.section.SectionResult` s concatenated in
member order: the result is bit-for-bit the single-process one.

Decisions:
* Dask is an optional extra (``pip install ti-spinorbit[dask]``), imported only when a
  ``client`` is given (``run=Run(client=...)`` of any entry point): the front door is
  :func:`~ti_spinorbit.studies.section.surface_of_section`, which calls :func:`run_members`.
* A failed chunk is retried ``Run.retries`` times by the scheduler (possibly on another worker);
  when the retries are spent, :class:`ChunkError` names the chunk, its members and the
  original exception, and the other chunks are cancelled. No chunk is ever dropped.
* The member table (:class:`ti_spinorbit.engine.members.Members`) is built once, on the client, by
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
* Workers initialise Taichi with ``Run.worker_arch``/``Run.worker_threads`` when given, else
  lazily with the package defaults (which honour ``TI_SPINORBIT_ARCH`` in the worker's environment).
* ``progress(fraction)`` is called on the client, with the share of members in finished
  chunks, each time a chunk comes back.
"""

import dataclasses
import threading
import uuid
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import runtime

#: Default number of chunks per worker process: enough to balance members of unequal cost
#: (chaotic members, early escapes) without paying Taichi's per-launch overhead too often.
#: Per process, not per thread: a worker runs its chunks one at a time (see _taichi_thread).
CHUNKS_PER_WORKER = 3

_THREAD = {"executor": None, "generation": None}  # see _taichi_thread
_THREAD_LOCK = threading.Lock()


class ChunkError(RuntimeError):
    """A chunk kept failing after all its retries; ``chunk`` is its index, ``members`` the
    slice of the flat member list it held; the original exception is ``__cause__``."""

    def __init__(self, message, chunk, members):
        super().__init__(message)
        self.chunk = chunk
        self.members = members


def run_members(run, runner, members, orbits, options, progress=None):
    """The Dask runner: a member table (:class:`ti_spinorbit.engine.members.Members`) cut into
    chunks of ``run.chunk_size`` members, each integrated by ``runner(chunk, orbits,
    **options)`` (the local runner, :func:`ti_spinorbit.studies.section.section_of`, which
    passes itself: this module imports no study) on a worker of ``run.client``, the results
    joined in member order (``options``: the runner's keywords, checked;
    ``progress(fraction)`` after every chunk). Starts of every kind go to the cluster: the
    paper's (θ_p, θ̇_p), apsidal ones, explicit 3-D states (tilted), with perturbations."""
    from distributed import as_completed

    client, chunk_size, retries = run.client, run.chunk_size, run.retries
    n = len(members)
    if chunk_size is None:
        workers = max(len(client.nthreads()), 1)
        chunk_size = -(-n // (CHUNKS_PER_WORKER * workers))
    chunks = members.chunks(chunk_size)
    init = {"arch": run.worker_arch, "cpu_max_num_threads": run.worker_threads}
    options = dict(options, run=run.on_worker())
    run_id = uuid.uuid4().hex[:8]
    futures = {}
    for k, (lo, hi, chunk) in enumerate(chunks):
        future = client.submit(_run_chunk, runner, chunk, orbits, init, options,
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


def _run_chunk(runner, members, orbits, init, options):
    """Worker side: one chunk through the runner on this process's Taichi thread.
    ``systems`` are left out of the reply (the client has them)."""
    result = _taichi_thread().submit(_integrate, runner, members, orbits, init,
                                     options).result()
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


def _integrate(runner, members, orbits, init, options):
    if runtime.current_arch() is not None and runtime.generation() != _THREAD["generation"]:
        raise RuntimeError(
            "Taichi was initialised in this worker process outside ti_spinorbit.studies.distributed "
            "(its LLVM backends then refuse to compile in the worker's Taichi thread): do not "
            "call ti_spinorbit.init on the workers; give run=Run(worker_arch=..., "
            "worker_threads=...), set TI_SPINORBIT_ARCH in the workers' environment, and use "
            "process-based workers (LocalCluster(processes=True))")
    if init["arch"] is not None or init["cpu_max_num_threads"] is not None:
        runtime.init(init["arch"], cpu_max_num_threads=init["cpu_max_num_threads"])
    else:
        runtime.ensure_init()
    _THREAD["generation"] = runtime.generation()
    return runner(members, orbits, **options)


def concatenate(parts):
    """Results of consecutive member chunks (SectionResults: dataclasses with per-member
    arrays, a ``count`` per member and a ``systems`` list) as one: per-member arrays (first axis the
    chunk's member count) are joined, and the crossing axis is NaN-padded to the longest
    chunk; scalar fields come from the first chunk; ``systems`` lists are joined; ``seconds``
    is summed (callers that know the wall time replace it)."""
    if not parts:
        raise ValueError("concatenate needs at least one SectionResult")
    sizes = [len(p.count) for p in parts]
    kind = type(parts[0])
    joined = {}
    for f in dataclasses.fields(kind):
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
    return kind(**joined)


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


__all__ = ["run_members", "concatenate", "ChunkError", "CHUNKS_PER_WORKER"]
