"""Dask scaling: a MEGNO chaos map of 1991 VH through the package's Dask path on a
``dask.distributed.LocalCluster`` of 1, 2, ... worker processes, and the cost of one chunk.

Each worker is a process with one Dask thread and one Taichi CPU thread
(``tso.Run(worker_threads=1)``, passed through ``chaos_map`` to every chunk), so k workers use
k cores; the worker counts are 1, 2, 4, ... up to the usable cores. The cluster starts with
the largest count, every worker loads its kernels (a warm-up map in one-member chunks), and
the cluster is then scaled down count by count. Timed: ``tso.chaos_map(..., run=tso.Run(client=client))``
(grid, orbits, ``fraction_orbits=()``: one pass), rtol 1e-10, the default chunking (3 chunks
per worker); the maps must be identical at every worker count;
member-orbits per second (wall), per worker CPU-second (summed process CPU time of the
workers, read with ``client.run``: the figure to compare on a loaded machine), speed-up over
one worker, parallel efficiency. For comparison the
same map in this process without Dask (Taichi on every core).

Per-chunk overhead, on one worker: (a) the same smaller map at several ``chunk_size``
(time per chunk against members per chunk; the intercept of time = a + b·members over the
chunks is the fixed cost of a chunk), and (b) ``surface_of_section`` with one-member, 0.01-orbit
chunks, one after the other (scheduling, pickling, result concatenation, launch set-up).

    python experiments/dask_scaling.py             # 48 x 48 x 50 orbits; ~2 min on 2 cores
    python experiments/dask_scaling.py --quick     # 8 x 8 x 2 orbits (CI)
"""

import logging
import os
import time

import numpy as np

from _common import parse, save

SYSTEM = "1991 VH"
ELONGATION = 1.5
RTOL = 1e-10
FULL = dict(grid=48, orbits=50.0, sweep_grid=32, sweep_orbits=20.0,
            chunk_sizes=(16, 64, 256, 1024), tiny_chunks=16, rounds=2)
QUICK = dict(grid=8, orbits=2.0, sweep_grid=8, sweep_orbits=2.0, chunk_sizes=(8, 64),
             tiny_chunks=4, rounds=1)


def worker_counts():
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    counts, k = [1], 2
    while k <= max(2, cores or 1):
        counts.append(k)
        k *= 2
    return counts, cores


def cpu_seconds(client=None):
    """Process CPU seconds of this process, or summed over the cluster's worker processes
    (read with ``client.run``, which only reads a clock there)."""
    if client is None:
        return time.process_time()
    return sum(client.run(time.process_time).values())


def chaos(system, grid, orbits, client=None, chunk_size=None):
    """One timed chaos map (wall s, ChaosMap, CPU s of this process or of all workers)."""
    import ti_spinorbit as tso

    theta_p = np.linspace(0.0, 180.0, grid, endpoint=False)
    thetadot_p = np.linspace(0.5, 2.5, grid)
    run = None if client is None else tso.Run(client=client, chunk_size=chunk_size,
                                              worker_arch="cpu", worker_threads=1)
    cpu = cpu_seconds(client)
    t0 = time.perf_counter()
    cmap = tso.chaos_map(system, theta_p, thetadot_p, orbits, rtol=RTOL, fraction_orbits=(),
                         run=run)
    wall = time.perf_counter() - t0
    return wall, cmap, cpu_seconds(client) - cpu


def _one_member_chunks(client):
    """Run options of the overhead measurements: one member per chunk, one CPU thread each."""
    import ti_spinorbit as tso

    return tso.Run(client=client, chunk_size=1, worker_arch="cpu", worker_threads=1,
                   progress=False)


def warm_up(client, system, workers):
    """Every worker loads its kernels: one-member chunks, several per worker, map and section."""
    import ti_spinorbit as tso

    tso.surface_of_section(system, 0.0, np.linspace(0.5, 2.5, 4 * workers), 0.05,
                           indicators=True, rtol=RTOL, run=_one_member_chunks(client))


def tiny_chunks(client, system, count):
    """Seconds per one-member, 0.01-orbit chunk, ``count`` chunks on the cluster."""
    import ti_spinorbit as tso

    t0 = time.perf_counter()
    tso.surface_of_section(system, 0.0, np.full(count, 1.3), 0.01, indicators=True, rtol=RTOL,
                           run=_one_member_chunks(client))
    return (time.perf_counter() - t0) / count


def main():
    args, started = parse(__doc__.splitlines()[0])
    from dask.distributed import Client, LocalCluster

    import ti_spinorbit as tso

    s = dict(QUICK if args.quick else FULL)
    system = tso.catalog.system(SYSTEM, elongation=ELONGATION)
    counts, cores = worker_counts()
    mo = s["grid"] ** 2 * s["orbits"]
    chaos(system, 2, 0.05)                                   # this process: compile or load
    local, _, local_cpu = min((chaos(system, s["grid"], s["orbits"])
                               for _ in range(s["rounds"])), key=lambda r: r[0])
    print(f"[dask_scaling] no Dask, one process, all cores: {local:.2f} s, "
          f"{mo / local:.0f} member-orbits/s, {mo / local_cpu:.0f} per CPU-s", flush=True)
    scaling, sweep, tiny = [], [], None
    reference_map = None
    # retiring a worker that holds finished chunks logs a warning: expected here
    logging.getLogger("distributed.scheduler").setLevel(logging.ERROR)
    with LocalCluster(n_workers=counts[-1], threads_per_worker=1, processes=True,
                      dashboard_address=None, env={"TI_SPINORBIT_ARCH": "cpu"}) as cluster, \
            Client(cluster) as client:
        client.wait_for_workers(counts[-1])
        warm_up(client, system, counts[-1])
        for k in reversed(counts):                         # all workers warm; retire down to k
            cluster.scale(k)
            while len(client.nthreads()) != k:
                time.sleep(0.05)
            runs = [chaos(system, s["grid"], s["orbits"], client) for _ in range(s["rounds"])]
            wall, cmap, cpu = min(runs, key=lambda r: r[0])
            if reference_map is None:
                reference_map = cmap
            identical = bool(np.array_equal(cmap.megno, reference_map.megno, equal_nan=True)
                             and np.array_equal(cmap.status, reference_map.status))
            scaling.append({"workers": k, "seconds": wall, "all_seconds": [r[0] for r in runs],
                            "member_orbits_per_s": mo / wall, "worker_cpu_s": cpu,
                            "member_orbits_per_worker_cpu_s": mo / cpu,
                            "identical_map": identical})
            print(f"[dask_scaling] {k} worker(s): {wall:.2f} s, {mo / wall:.0f} member-orbits/s"
                  f", {mo / cpu:.0f} per worker CPU-s"
                  f", map identical to {counts[-1]} workers': {identical}", flush=True)
            if k == 1:
                n_sweep = s["sweep_grid"] ** 2
                for size in s["chunk_sizes"]:
                    chunks = -(-n_sweep // size)
                    w, _, _ = chaos(system, s["sweep_grid"], s["sweep_orbits"], client, size)
                    sweep.append({"chunk_size": size, "chunks": chunks, "seconds": w,
                                  "seconds_per_chunk": w / chunks,
                                  "member_orbits_per_s": n_sweep * s["sweep_orbits"] / w})
                    print(f"[dask_scaling] 1 worker, chunk_size {size}: {chunks} chunks, "
                          f"{w:.2f} s, {w / chunks:.3f} s per chunk", flush=True)
                tiny = tiny_chunks(client, system, s["tiny_chunks"])
                print(f"[dask_scaling] 1 worker, one-member 0.01-orbit chunks: "
                      f"{1e3 * tiny:.1f} ms per chunk", flush=True)
    scaling.sort(key=lambda r: r["workers"])
    one = scaling[0]["member_orbits_per_s"]
    for r in scaling:
        r["speedup"] = r["member_orbits_per_s"] / one
        r["efficiency"] = r["speedup"] / r["workers"]
    # the same map in more chunks: time = a·chunks + c, a the fixed cost of a chunk
    chunks = np.array([r["chunks"] for r in sweep], dtype=float)
    t = np.array([r["seconds"] for r in sweep])
    per_chunk = float(np.polyfit(chunks, t, 1)[0]) if len(set(chunks)) >= 2 else float("nan")

    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 3.8))
    w = [r["workers"] for r in scaling]
    ax.plot(w, [r["member_orbits_per_s"] for r in scaling], "o-", label="chaos map on a Dask cluster")
    ax.plot(w, [one * k for k in w], "k:", lw=1, label="ideal (k x 1 worker)")
    ax.plot(w, [r["workers"] * r["member_orbits_per_worker_cpu_s"] for r in scaling], "s--",
            label="k x per worker CPU-s (k unshared cores)")
    ax.axhline(mo / local, color="C2", ls="--", lw=1, label="one process, no Dask, all cores")
    ax.set_xlabel("worker processes (1 thread each)")
    ax.set_ylabel("member-orbits per second")
    ax.set_xticks(w)
    ax.set_title(f"{SYSTEM} a/b = {ELONGATION}: {s['grid']}x{s['grid']} map, "
                 f"{s['orbits']:g} orbits, rtol {RTOL:g}", fontsize=9)
    ax.legend(fontsize=7)
    bx.loglog([r["chunk_size"] for r in sweep], [r["seconds_per_chunk"] for r in sweep], "o-",
              label=f"{s['sweep_grid']}x{s['sweep_grid']} map, {s['sweep_orbits']:g} orbits")
    bx.axhline(tiny, color="C3", ls="--", lw=1,
               label=f"one-member 0.01-orbit chunk: {1e3 * tiny:.0f} ms")
    bx.set_xlabel("members per chunk")
    bx.set_ylabel("seconds per chunk, 1 worker")
    bx.set_title(f"per-chunk cost; fit: {1e3 * per_chunk:.0f} ms fixed per chunk", fontsize=9)
    bx.legend(fontsize=7)
    numbers = {f"{r['workers']} workers member-orbits/s": r["member_orbits_per_s"]
               for r in scaling}
    numbers.update({f"{r['workers']} workers speed-up": r["speedup"] for r in scaling[1:]})
    numbers.update({f"{r['workers']} workers member-orbits per worker CPU-s":
                    r["member_orbits_per_worker_cpu_s"] for r in scaling})
    numbers["no Dask member-orbits/s"] = mo / local
    numbers["no Dask member-orbits per CPU-s"] = mo / local_cpu
    numbers["tiny chunk ms"] = 1e3 * tiny
    numbers["fitted fixed cost per chunk ms"] = 1e3 * per_chunk
    numbers["identical maps"] = all(r["identical_map"] for r in scaling)
    save(args, "dask_scaling", fig,
         {"workers": w, "member_orbits_per_s": [r["member_orbits_per_s"] for r in scaling],
          "chunk_size": [r["chunk_size"] for r in sweep],
          "seconds_per_chunk": [r["seconds_per_chunk"] for r in sweep]},
         {**s, "system": SYSTEM, "elongation": ELONGATION, "rtol": RTOL, "cores": cores,
          "scaling": scaling, "sweep": sweep, "tiny_chunk_s": tiny, "no_dask_s": local,
          "no_dask_cpu_s": local_cpu, "load_average_end": os.getloadavg()[0]},
         numbers, started)


if __name__ == "__main__":
    main()
