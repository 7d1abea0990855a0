"""Memory estimate against measured peak RSS growth, for every entry point at a few sizes.

Each case runs in a fresh subprocess: it initialises Taichi and runs a tiny case of the same
entry point (kernels compiled, allocator warm), resets the peak RSS to the current one (Linux
``/proc/self/clear_refs``; compiling can leave a high-water mark above what the case needs),
reads the RSS, runs the case and reads the peak RSS (``VmHWM``; ``ru_maxrss`` where there is
no /proc: on Linux ru_maxrss inherits the parent's peak, see :func:`peak_rss`). The growth is compared with the estimate the entry point itself computed
before any work (``ti_spinorbit.engine.resources.check_memory``, captured here). The estimate must be
within a factor 1.5 of the growth; the ratio column shows it.

    python experiments/memory_estimate.py            # full sizes (a few GiB at most, ~2 min)
    python experiments/memory_estimate.py --quick    # small sizes (CI)
"""

import ti_spinorbit
import json
import os
import subprocess
import sys

import numpy as np

import _common

HERE = os.path.dirname(os.path.abspath(__file__))

#: (label, entry point, keyword arguments); "scale" cases only in full mode.
QUICK = [
    ("section 4x3000", "surface_of_section", dict(members=4, orbits=3000)),
    ("time_series 2x200x256", "time_series", dict(members=2, orbits=200, samples_per_orbit=256)),
    ("time_series 3d 2x300x256", "time_series", dict(members=2, orbits=300, samples_per_orbit=256,
                                                    model="3d")),
    ("time_series states 2x200x256", "time_series", dict(members=2, orbits=200,
                                                         samples_per_orbit=256, states=True)),
    ("energy (CLI) 300x256", "energy", dict(orbits=300, samples_per_orbit=256)),
    ("chaos_map 16x16x100", "chaos_map", dict(grid=16, orbits=100)),
    ("parameter_map 2x2x24x300", "parameter_map", dict(grid=2, orbits=300)),
    ("overlap 2x80x200", "overlap_threshold", dict(elongations=2, orbits=200)),
    ("relaxed_libration 30", "relaxed_libration", dict(orbits=30)),
]
FULL = [
    ("section 8x20000", "surface_of_section", dict(members=8, orbits=20000)),
    ("section 256x300", "surface_of_section", dict(members=256, orbits=300)),
    ("section 3d 16384x2", "surface_of_section", dict(members=16384, orbits=2, model="3d")),
    ("section 65536x1", "surface_of_section", dict(members=65536, orbits=1)),
    ("time_series 4x500x64", "time_series", dict(members=4, orbits=500, samples_per_orbit=64)),
    ("time_series 16x4000x40", "time_series",
     dict(members=16, orbits=4000, samples_per_orbit=40)),
    ("time_series 3d 4x500x64", "time_series", dict(members=4, orbits=500, samples_per_orbit=64,
                                                   model="3d")),
    ("time_series states 4x2000x64", "time_series", dict(members=4, orbits=2000,
                                                         samples_per_orbit=64, states=True)),
    ("time_series 3d states 4x1000x64", "time_series",
     dict(members=4, orbits=1000, samples_per_orbit=64, model="3d", states=True)),
    ("energy (CLI) 2000x256", "energy", dict(orbits=2000, samples_per_orbit=256)),
    ("chaos_map 32x32x200", "chaos_map", dict(grid=32, orbits=200)),
    ("chaos_map 128x128x10", "chaos_map", dict(grid=128, orbits=10)),
    ("parameter_map 4x4x24x200", "parameter_map", dict(grid=4, orbits=200)),
    ("overlap 4x80x500", "overlap_threshold", dict(elongations=4, orbits=500)),
    ("relaxed_libration 100", "relaxed_libration", dict(orbits=100)),
]


def current_rss():
    """Resident set size of this process now, bytes (Linux /proc; else the peak so far)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except OSError:
        import resource
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def peak_rss():
    """Peak resident set size of this process, bytes: VmHWM of /proc/self/status (Linux), else
    ``ru_maxrss``. On Linux ``ru_maxrss`` also carries the parent's peak across fork + exec
    (the kernel's signal->maxrss), so a child of a large process (a test runner) reads the
    parent's size, and clear_refs cannot reset it; VmHWM is this process's own."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    import resource
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def run_case(entry, kw):
    """One case in this process; returns (estimate bytes, peak RSS growth bytes, warm-up
    seconds)."""
    import ti_spinorbit as tso
    from ti_spinorbit import cli
    from ti_spinorbit.engine import resources

    estimates = []
    check = resources.check_memory

    def capture(*args, **kwargs):
        nbytes = check(*args, **kwargs)
        estimates.append(nbytes)
        return nbytes

    resources.check_memory = capture
    vh = tso.catalog.system("1991 VH")

    def call(scale):
        orbits = max(kw["orbits"] * scale, 2) if scale < 1 else kw["orbits"]
        members = kw.get("members", 1) if scale == 1 else min(kw.get("members", 1), 4)
        if entry == "surface_of_section":
            tso.surface_of_section(vh, 0.0, np.linspace(0.9, 1.3, members), orbits,
                                   integrator=ti_spinorbit.Integrator(model=kw.get("model", "auto")))
        elif entry == "time_series":
            tso.time_series(vh, 0.0, np.linspace(0.9, 1.3, members), orbits,
                            samples_per_orbit=kw["samples_per_orbit"],
                            states=kw.get("states", False),
                            integrator=ti_spinorbit.Integrator(model=kw.get("model", "auto")))
        elif entry == "energy":
            out = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"memory_estimate_{os.getpid()}")
            status = cli.main(["energy", "--quiet", "--orbits", f"{orbits:g}", "--samples-per-orbit",
                               str(kw["samples_per_orbit"]), "--max-drift", "1",
                               "--out", out + ".png"])
            for ext in (".png", ".npz"):
                if os.path.exists(out + ext):
                    os.remove(out + ext)
            assert status == 0, status
        elif entry == "chaos_map":
            g = kw["grid"] if scale == 1 else 2
            tso.chaos_map(vh, np.linspace(0, 180, g), np.linspace(0.5, 2.0, g), orbits)
        elif entry == "parameter_map":
            g = kw["grid"] if scale == 1 else 1
            tso.parameter_map("1991 VH", np.linspace(1.1, 1.4, g), np.linspace(0.05, 0.2, g),
                              orbits)
        elif entry == "overlap_threshold":
            g = kw["elongations"] if scale == 1 else 1
            tso.overlap_threshold("1991 VH", elongations=np.linspace(1.02, 1.1, g), orbits=orbits)
        elif entry == "relaxed_libration":
            import warnings
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                tso.relaxed_libration(tso.catalog.system("Didymos"), orbits=orbits,
                                      xtol=1e-3 if scale < 1 else 1e-6)
        else:
            raise ValueError(entry)

    import time

    started = time.perf_counter()
    call(0.001)                                  # compile, warm the allocator
    warmup = time.perf_counter() - started
    # the high-water mark may sit above the resident set (compiling): reset it to the
    # current RSS (Linux: clear_refs 5) so that the peak measures this case alone
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
    except OSError:
        pass
    before = current_rss()
    estimates.clear()
    call(1)
    after = peak_rss()
    return max(estimates), after - before, warmup


def measure(entry, kw, env=None):
    """Run one case in a fresh process: dict with "estimate" and "growth" (bytes). A process
    that had to compile kernels (cold cache: a slow warm-up) leaves freed compiler memory that
    the case then reuses without growing, so such a case is measured again (the cache is warm
    by then)."""
    for attempt in range(2):
        p = subprocess.run([sys.executable, os.path.abspath(__file__), "--case",
                            json.dumps({"entry": entry, "kw": kw})], capture_output=True,
                           text=True, env=dict(env or os.environ, MPLBACKEND="Agg"), cwd=HERE)
        if p.returncode != 0:
            raise RuntimeError(f"{entry} {kw}: {p.stderr[-2000:]}")
        r = json.loads(p.stdout.strip().splitlines()[-1])
        if r["warmup"] < WARM_SECONDS:
            break
    return r


#: A warm-up slower than this compiled kernels (a warm cache loads them in about a second).
WARM_SECONDS = 4.0


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--case":
        case = json.loads(sys.argv[2])
        estimate, growth, warmup = run_case(case["entry"], case["kw"])
        print(json.dumps({"estimate": estimate, "growth": growth, "warmup": warmup}))
        return
    args, started = _common.parse(__doc__.splitlines()[0])
    cases = QUICK if args.quick else FULL
    rows = []
    print(f"{'case':36s} {'estimate MiB':>12s} {'measured MiB':>12s} {'ratio':>6s}")
    for label, entry, kw in cases:
        r = measure(entry, kw)
        ratio = r["estimate"] / r["growth"]
        rows.append((label, r["estimate"], r["growth"], ratio))
        print(f"{label:36s} {r['estimate'] / 2**20:12.1f} {r['growth'] / 2**20:12.1f} {ratio:6.2f}",
              flush=True)
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    est = np.array([r[1] for r in rows]) / 2**20
    got = np.array([r[2] for r in rows]) / 2**20
    ax.loglog(got, est, "o")
    lim = np.array([min(est.min(), got.min()) * 0.7, max(est.max(), got.max()) * 1.4])
    ax.plot(lim, lim, "k-", lw=0.8, label="estimate = measured")
    ax.fill_between(lim, lim / 1.5, lim * 1.5, color="0.9", label="factor 1.5")
    for (label, *_), x, y in zip(rows, got, est):
        ax.annotate(label.replace("_", " "), (x, y), fontsize=5)   # no raw "_" in figures
    ax.set_xlabel("measured peak RSS growth (MiB)")
    ax.set_ylabel("estimate before the run (MiB)")
    ax.legend(fontsize=7)
    ratios = [r[3] for r in rows]
    _common.save(args, "memory_estimate", fig,
                 {"estimate_bytes": np.array([r[1] for r in rows]),
                  "measured_bytes": np.array([r[2] for r in rows]),
                  "ratio": np.array(ratios)},
                 {"cases": [[label, entry, kw] for label, entry, kw in cases]},
                 {"cases": len(rows), "min_ratio": min(ratios), "max_ratio": max(ratios),
                  "within_1.5": bool(all(1 / 1.5 <= x <= 1.5 for x in ratios))}, started)


if __name__ == "__main__":
    main()
