"""Wall time of the polyhedron inertia integrals (ti_spinorbit.system.integrals).

Builds closed UV-ellipsoid meshes (semi-axes 1.5, 1.0, 0.7 m: pole fans and rings of quads
split in two) and times ``polyhedron_integrals`` at order 8 over mesh sizes up to about 3
million facets, and at orders 0 ... 16 on a smaller mesh (orders 4, 8 and 12 printed).
Each time is the best of a few repetitions (one at the largest size). The integrals are
checked against the homogeneous ellipsoid's closed form (``ellipsoid_integrals``): the
difference is the mesh's O(h²) discretisation, about 2e-5 at 3 million facets.

    python experiments/integrals_speed.py            # 30k ... 3M facets, orders 0-16 at 100k
    python experiments/integrals_speed.py --quick    # small meshes (CI)

Writes <out>/integrals_speed.png (time against facets and against order) and .npz.
"""

import os
import resource
import time

import numpy as np

import _common

AXES = (1.5, 1.0, 0.7)


def uv_ellipsoid(nlon, nlat, a, b, c):
    """Closed, outward-wound UV mesh: 2 nlon (nlat - 1) triangles."""
    th = np.pi * np.arange(1, nlat) / nlat
    ph = 2 * np.pi * np.arange(nlon) / nlon
    T, P = np.meshgrid(th, ph, indexing="ij")
    ring = np.stack([a * np.sin(T) * np.cos(P), b * np.sin(T) * np.sin(P), c * np.cos(T)],
                    -1).reshape(-1, 3)
    V = np.vstack([[0.0, 0.0, c], ring, [0.0, 0.0, -c]])
    j = np.arange(nlon)
    idx = lambda i, k: 1 + i * nlon + (k % nlon)        # noqa: E731
    faces = [np.stack([np.zeros(nlon, dtype=np.intp), idx(0, j), idx(0, j + 1)], -1)]
    i = np.arange(nlat - 2)[:, None]
    faces.append(np.stack([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)], -1).reshape(-1, 3))
    faces.append(np.stack([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)], -1).reshape(-1, 3))
    faces.append(np.stack([idx(nlat - 2, j), np.full(nlon, len(V) - 1), idx(nlat - 2, j + 1)],
                          -1))
    return V, np.concatenate(faces)


def mesh_with(facets):
    """UV ellipsoid with about ``facets`` triangles (nlon = 2 nlat)."""
    nlat = max(3, int(round((facets / 4) ** 0.5)))
    return uv_ellipsoid(2 * nlat, nlat, *AXES)


def best_time(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def deviation(T, order):
    """Largest |T − T_ellipsoid| of the even integrals, relative to T_ellipsoid."""
    from ti_spinorbit.system.integrals import ellipsoid_integrals

    E = ellipsoid_integrals(*AXES, T[(0, 0, 0)], order)  # same mass: compare the shapes
    return max(abs(T[k] / E[k] - 1) for k in E if E[k] != 0 and k != (0, 0, 0))


def main():
    args, started = _common.parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    from ti_spinorbit.system import integrals

    sizes = [2_000, 8_000, 32_000] if args.quick else [30_000, 100_000, 300_000, 1_000_000,
                                                       3_000_000]
    orders = [0, 2, 4, 8, 12] if args.quick else list(range(0, 17, 2))
    small = 8_000 if args.quick else 100_000
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()

    facets, seconds_8 = [], []
    for target in sizes:
        V, F = mesh_with(target)
        t, T = best_time(lambda: integrals.polyhedron_integrals(V, F, 8, 1.0),
                         1 if target >= 1_000_000 else 3)
        facets.append(len(F))
        seconds_8.append(t)
        print(f"order 8, {len(F):>9} facets: {t:8.3f} s ({t / len(F) * 1e6:.2f} µs per facet), "
              f"largest deviation from the ellipsoid {deviation(T, 8):.2e}")
    V, F = mesh_with(small)
    seconds_n = []
    for order in orders:
        t, T = best_time(lambda: integrals.polyhedron_integrals(V, F, order, 1.0), 3)
        seconds_n.append(t)
        print(f"order {order:>2}, {len(F):>9} facets: {t:8.3f} s")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024     # KiB on Linux
    print(f"peak RSS {peak:.0f} MiB, {cores} cores")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 4))
    ax1.loglog(facets, seconds_8, "o-")
    ax1.set_xlabel("facets")
    ax1.set_ylabel("wall time (s)")
    ax1.set_title("order 8")
    ax2.semilogy(orders, seconds_n, "o-")
    ax2.set_xlabel("order N")
    ax2.set_ylabel("wall time (s)")
    ax2.set_title(f"{len(F)} facets")
    fig.suptitle(f"Polyhedron inertia integrals, {cores} cores", fontsize=10)
    numbers = {"largest_facets": facets[-1], "order8_seconds_largest": seconds_8[-1],
               "order8_us_per_facet_largest": seconds_8[-1] / facets[-1] * 1e6,
               "small_facets": len(F), "peak_rss_mib": peak, "cores": cores}
    for order, t in zip(orders, seconds_n):
        if order in (4, 8, 12):
            numbers[f"order{order}_seconds_small"] = t
    _common.save(args, "integrals_speed", fig,
                 {"facets": np.array(facets), "order8_seconds": np.array(seconds_8),
                  "orders": np.array(orders), "seconds_by_order": np.array(seconds_n)},
                 {"axes_m": list(AXES), "sizes": sizes, "orders": orders, "small": small},
                 numbers, started)


if __name__ == "__main__":
    main()
