"""Benchmark: where the ensemble integrator's time goes on 1991 VH (a/b = 1.5), and how it scales.

Measure first: methods as an axis, a compiled DOP853 baseline in the same run, accuracy at
equal rtol, and the speed targets with their ratios.
Every run is deterministic: member k starts at
θ_p = 180° frac(½ + k/g), θ̇_p/n = 0.5 + 2 frac(½ + k/g²) with g the plastic number (an
R2 low-discrepancy sequence over θ_p ∈ [0, 180), θ̇_p/n ∈ [0.5, 2.5]), so the first N
members of a larger table are the N-member table and every N samples the same mix of regular
and chaotic starts. Integration uses ``Ensemble`` directly (order 4, atol = rtol, escape
distance 1000 a so no member stops early). Sections (``--sections``, default all):

throughput
    member-orbits per second for N × rtol × model × method (``--members``, ``--rtols``,
    ``--models``, ``--methods``; default N = 1, 16, 256, 1024, 4096, 16384, rtol 1e-10,
    1e-12, 1e-15, models planar and 3d, methods cash-karp, dop853 and vern9) on the arch of
    ``--arch`` (cpu by default; ``--arch cuda --members ... 65536`` for a GPU). The
    orbits of each point are chosen so that it takes about ``--seconds`` (default 2 s): a
    short pilot run measures the rate, then the timed run integrates ``seconds × rate / N``
    orbits (rounded up to two significant figures, at least one orbit). The time is
    ``RunOutput.seconds`` (the window loop: kernel launches and draining); accepted and
    rejected steps and RHS calls are per member-orbit.
    Per-core CPU-time throughput (member-orbits per process CPU-second) is printed beside
    the wall-clock rate: it is what to compare on a loaded machine.
split
    the time of one integrator pass, split into the right-hand side, the rest of
    ``advance`` (stage points and combination, error norm, step control, pericentre events,
    loads and stores) and the drain (Python between launches: buffer copies, status
    updates). RHS cost: a kernel defined here evaluates each model's ``rhs`` R times in a
    loop on the N benchmark states (R large, so launch overhead vanishes); each call's
    argument is y0 + 1e-12 f(previous), a dependent chain like the stages of a step, which
    stops the compiler from hoisting any of the RHS out of the loop. That chain adds one
    multiply-add per state component (20 flops beside the planar RHS's 141, 60 beside the
    3-D's 835), so the RHS share is, if anything, overstated. A store inside the loop, which
    keeps the parameter loads from being hoisted as the record stores in ``advance`` do,
    changed nothing (measured once; not in the script). Kernel time: ``advance`` of the
    model's kernel namespace is wrapped by a timer for the duration of each run (wall and
    process CPU time per launch), and ``progress`` marks each window's end. On the CPU the
    ns figures are per core (process CPU time / count), on a GPU wall time / count.
flops
    a hand count of floating-point operations per RHS (:data:`FLOPS_PER_RHS`, derivation
    beside it), the achieved flop rate of the RHS-only kernel and of the whole integrator
    (RHS flops only), and the fraction of the CPU's f64 peak: cores × GHz (``cpu MHz`` of
    /proc/cpuinfo) × ``--flops-per-cycle`` (default 16: AVX2 + FMA, 2 FMA units × 4 lanes ×
    2). The kernels compile to scalar code (one member per thread, no SIMD across members),
    which uses one of the four lanes: about 1/4 of that peak is its ceiling (a little more
    where the core has separate add ports or the clock boosts above ``cpu MHz``).
threads
    N = 4096 at rtol 1e-12, both models, in fresh processes with
    ``tso.init(cpu_max_num_threads=k)`` for k = 1, 2 (and all cores when there are more),
    alternating; speed-up, parallel efficiency and per-core CPU-time throughput (CPU only).
window
    throughput for ``window_orbits`` = 4, 16, 64 at N = 4096, planar, rtol 1e-12, over 128
    orbits (two launches of the longest window), with launches and drain fraction.
baseline
    the plain NumPy reference (``reference.integrate``, scipy DOP853) on the first 2 members
    over 2 orbits per rtol, and the same members through the kernels to the same end time
    (max |Δy| of the final states, scaled units, so both sides integrate the same problem).
    Tolerances: the kernels control the error of the scaled state (every component O(1))
    with atol = rtol; the reference integrates the SI state, whose components span 1
    (rotation matrices) to 1e13 (Γ1), so the baseline uses the per-component
    atol = rtol · to_physical(ones), the kernels' own error control carried to SI (scipy's
    RMS norm is, if anything, looser than the kernels' max norm, which favours the
    baseline). Pure relative control (atol ~ 1e-30) does not work: components that are zero
    in this planar problem pick up round-off and DOP853's step collapses. scipy raises any
    rtol below 100 eps to 2.2e-14, so its "1e-15" runs at 2.2e-14 (shown in the table),
    again in the baseline's favour. One-off costs (importing scipy.integrate, the
    reference's cached multipole bases) are paid before timing. The speed-up printed is the
    kernel rate at the split N over the baseline rate, per model and rtol.
numba
    a compiled single-trajectory DOP853 integrator of the planar model written for this
    benchmark with numba (experiments/_numba_dop853.py: its own RHS, Hairer's error norm and
    controller; the ``bench`` extra), at rtol 1e-12 and 1e-15 (those of ``--rtols``),
    atol = rtol, on the first 64 members (quick: 4) one after the other on ONE core: orbits
    per CPU-second is its rate per core. Checked in the same run: its RHS against the
    package's planar RHS on 256 random states (relative difference, round-off), and its
    final states against the kernels at rtol 1e-14 over ``accuracy_orbits``. With the
    accuracy section it is also timed at 1e-11, 1e-13 and 1e-14 (quick: 1e-13): its rate
    against its error, for the equal-accuracy comparison.
accuracy
    final-state error at equal rtol: each (model, method, rtol) of the run and the numba
    baseline on the first 32 members (quick: 4) over 4 orbits (quick: 0.5), against a tight
    reference, numba DOP853 at rtol 1e-16 (the kernels' Cash-Karp at 1e-16 without numba);
    error = max |Δy| over the scaled 3-D state (planar states through ``to_spatial``, so
    both models meet the same reference), median and max over members. One line per model
    and rtol gives every method's median error and its ratio to Cash-Karp's, so that a
    faster method is not bought with accuracy. Then, informational (not a
    target), "equal accuracy": each planar method's per-core rate over the numba baseline's
    rate at the SAME median error (log-log interpolation between the baseline's measured
    tolerances): the kernels' max-norm error control is more accurate at a given rtol than
    the baseline's RMS norm, so equal rtol is not equal work.
latency
    first result from a fresh process: ``sys.executable -c`` imports ti_spinorbit and
    computes a 1-member, 1-orbit section; with a new, empty offline kernel cache (cold:
    compiles) and then ``--repeat`` times with it warm. Wall time includes interpreter
    start-up. ``--quick`` skips the cold run and uses the default cache folder.

``--quick``: N = 1, 16, split/threads/window at N = 16, 0.05 s per point, 1 baseline member
over 0.5 orbit, no cold-cache run: every section in about 12 s (CI, not figures).
``--repeat k`` times every run k times and keeps the best (do that on a shared machine; the
load average at start and end is recorded, and other processes' load lowers every
wall-clock figure).

Methods: ``--methods cash-karp dop853 vern9 ...`` (``Ensemble(method=...)``; the default
"cash-karp" is never passed by keyword, so the script runs on a package without the keyword;
a method ``Ensemble`` does not accept yet is skipped with a one-line note). The split, flops,
threads and window sections use Cash-Karp.

Targets (planar unless said, 1991 VH a/b = 1.5, N = the split N, "fastest" = the
fastest method measured): >= 60 000 member-orbits/s on 2 cores at rtol 1e-12; >= 2x per core
the numba DOP853 baseline (ensemble member-orbits per CPU-second over the baseline's orbits
per CPU-second; on a GPU the wall rate against one CPU core); at 1e-15 >= 4x the Cash-Karp
rate of the same run; 3-D >= 15 000 at 1e-12; and the accuracy at equal rtol of each method
no worse than Cash-Karp's (median error ratio <= 1). Each prints MET/MISS, its value and
value/target.

Targets (2-core machine): >= 20 000 member-orbits/s for the planar model and
>= 2 000 for the 3-D model at N = 4096, rtol 1e-12; >= 300x the
baseline; <= 3 s to the first result from a fresh process with a warm cache. (The 64 x 64 x
500-orbit MEGNO map target is measured by experiments/chaos_maps.py.)

Writes ``<out>/bench_throughput.json`` (every row of every section, machine information and
the settings), ``bench_throughput.png`` (throughput against N; time split) and
``bench_throughput.npz``; prints one table per section.

    python experiments/bench_throughput.py                      # full: ~3 min on 2 cores
    python experiments/bench_throughput.py --quick              # CI
    python experiments/bench_throughput.py --sections throughput --members 4096
    python experiments/bench_throughput.py --arch cuda --members 1024 4096 16384 65536 262144
"""

import datetime
import importlib
import inspect
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

from _common import parse, save

SYSTEM = "1991 VH"
ELONGATION = 1.5                  # secondary a/b
THETA_P_RANGE = (0.0, 180.0)      # degrees
THETADOT_RANGE = (0.5, 2.5)       # θ̇_p/n
ESCAPE_DISTANCE = 1000.0          # units of a: nobody escapes within a benchmark
PLASTIC = 1.32471795724474602596  # g of the R2 sequence (g³ = g + 1)
RTOLS = (1e-10, 1e-12, 1e-15)
MODELS = ("planar", "3d")
WINDOWS = (4, 16, 64)
SECTIONS = ("throughput", "split", "flops", "threads", "window", "baseline", "numba",
            "accuracy", "latency", "compile")
#: Integration methods (``Ensemble(method=...)``); the default one is never passed by keyword.
DEFAULT_METHOD = "cash-karp"
METHODS = ("cash-karp", "dop853", "vern9")
TARGET_RATE = {"planar": 20000.0, "3d": 2000.0}   # member-orbits/s, N = 4096, rtol 1e-12
# (planar, 1991 VH a/b = 1.5, N >= 1024; "fastest" = the fastest method measured)
TARGET_PLANAR = 60000.0         # member-orbits/s on 2 cores, rtol 1e-12
TARGET_3D = 15000.0             # member-orbits/s, 3-D, rtol 1e-12
TARGET_PER_CORE = 2.0           # x the numba DOP853 baseline, per core, same run
TARGET_TIGHT = 4.0              # x today's Cash-Karp rate at rtol 1e-15
NUMBA_RTOLS = (1e-12, 1e-15)      # the baseline's tolerances
ACCURACY_REFERENCE_RTOL = 1e-16   # numba DOP853, the tight reference of the accuracy section
TARGET_SPEEDUP = 300.0            # over the scipy baseline
# cold compile of every variant (model x method x indicators, each in a fresh
# process with an empty kernel cache: the integrator and diagnostics kernels)
# <= 25 s and <= 2x "the planar one" (the planar default: Cash-Karp without indicators, what
# the README's first command compiles); warm start (fresh process, warm cache, import to the
# first result of a one-orbit section) <= 1 s for each model.
TARGET_COMPILE_S = 25.0
TARGET_COMPILE_RATIO = 2.0
TARGET_WARM_S = 1.0
TARGET_FIRST_RESULT_S = 3.0       # fresh process, warm offline cache
SCIPY_MIN_RTOL = 100 * np.finfo(float).eps   # scipy's RK solvers raise smaller rtol to this
FLOPS_PER_CYCLE = 16              # f64, AVX2 + FMA: 2 FMA units × 4 lanes × 2 flops
RHS_PERTURBATION = 1e-12          # RHS-only loop: next argument y0 + this · f(previous)

# Floating-point operations per right-hand side, order 4, bodies symmetric about their
# principal planes (odd=False: every catalogued system). Counted by hand from the kernels,
# after removing what the compiler removes (dead code: the potential's value, which dy/dt
# does not use; the cos/sin 3ψ and order-3 terms; common subexpressions). One add, subtract,
# multiply, divide or square root = 1 flop; negations free. Check: the optimised LLVM IR of
# each model's evaluate_rhs (Taichi 1.7.4, x64, fast_math off) holds 140 (planar) and 768
# (3-D) scalar fadd/fsub/fmul/fdiv/sqrt, no vector operations (the 3-D count 4 % under the
# hand count: LLVM shares a few products the count repeats).
#
# planar, kernels/planar_eom.py                                                                     141
#   1/r 1 (the only division), start of V_r 2                                                     3
#   per body (_series): cos, sin of 2ψ and 4ψ 10, P2 4, dP2/dψ 4, P4 8, dP4/dψ 9 = 35; ×2        70
#   1/r², 1/r³ 2; order-2 terms into V_r 5, V_A 2, V_B 2                                         11
#   order 4: cos, sin (2ψ_A − 2ψ_B) 6, X 9, X_A 6, X_B 5, 1/r⁵ 1, P4 + Q4 + X 2,
#     V_r 4, V_A 3, V_B 3                                                                        39
#   rhs_member: dλ/dt 2, dψ_A/dt and dψ_B/dt 4, dv_r/dt 4, dℓ/dt 2, cos/sin rates 4,
#     spins 2                                                                                    18
# 3-D, kernels/eom.py + kernels/mutual_gravity.py (G = 1 folds away)                                 799
#   eom.rhs around the potential: Ω1 3, Ω2 = S I2⁻¹ Sᵀ w2 33, dR/dt 12, dV/dt 15,
#     dw1/dt 15, dw2/dt 15 (3 divisions each), Ω2 − Ω1 3, dS/dt 27, dS1/dt 27                   150
#   mutual: R·R 5, sqrt 1, 1/r 1, e 3, ∇(mA mB/r) 6                                              16
#     e_B = Sᵀ e 15; single_body_terms per body 118 (L2 13, ∇L2 3, powers of u 9,
#       the 6 even 4th-order monomials and their gradient 51, the K diagonal 6,
#       K u 15 (a full 3×3 product: 0·x does not fold), L4 12, ∇L4 9); two bodies 236           251
#     order 2: 1/r², 1/r³ 2, S ∇L2_B 15, U2 3, ∇U2 9, ∂U/∂R 27, torque on B 9                    65
#     order 4: J'_B = S J_B Sᵀ 54 (S_rk j_k 9, 9 entries of 5), traces 4, J_A e 3, J'_B e 15, a, b 10, X 24,
#       J_A J'_B e 3, J'_B J_A e 15, ∇X 36, S ∇L4_B 15, U4 4, ∇U4 12, 1/r⁵ 1,
#       ∂U/∂R 27, torque on B 9, ε_AB 6, quadrupole-quadrupole torque 55                        293
#     μ2 += e × τ 12, μ1 = R × ∂U/∂R − μ2 12                                                     24
FLOPS_PER_RHS = {"planar": 141, "3d": 799}

FULL = dict(sizes=(1, 16, 256, 1024, 4096, 16384), seconds=2.0, min_orbits=1.0,
            split_members=4096, rhs_seconds=1.0, window_orbits=2.0 * max(WINDOWS),
            baseline_members=2, baseline_orbits=2.0, cold_latency=True,
            numba_members=64, accuracy_members=32, accuracy_orbits=4.0,
            numba_curve=(1e-11, 1e-13, 1e-14))
QUICK = dict(sizes=(1, 16), seconds=0.05, min_orbits=0.1,
             split_members=16, rhs_seconds=0.05, window_orbits=2.0 * max(WINDOWS),
             baseline_members=1, baseline_orbits=0.5, cold_latency=False,
             numba_members=4, accuracy_members=4, accuracy_orbits=0.5, numba_curve=(1e-13,))
FIRST_RATE_GUESS = 1000.0         # member-orbits/s, for sizing the very first pilot run
PILOT_FRACTION = 0.125            # pilot run length, fraction of --seconds
MIN_PILOT_ORBITS = 0.05

EXPERIMENTS = os.path.dirname(os.path.abspath(__file__))
# Child processes print one JSON line last; sys.argv[1:] carries their inputs.
CHILD_THREADS = (f"import sys; sys.path.insert(0, {EXPERIMENTS!r}); import bench_throughput; "
                 "bench_throughput.child_threads(*sys.argv[1:])")
CHILD_FIRST_RESULT = """
import json, time
t0 = time.perf_counter()
import ti_spinorbit as tso
imported = time.perf_counter() - t0
r = tso.surface_of_section(tso.catalog.system({system!r}, elongation={elongation!r}), 90.0,
                           [1.5], orbits=1, model={model!r})
print(json.dumps({{"import_s": imported, "in_process_s": time.perf_counter() - t0,
                  "integrate_s": r.seconds, "crossings": int(r.count[0])}}))
"""
# One kernel variant compiled (or loaded) in a fresh process: tso.warmup's own bookkeeping.
CHILD_COMPILE = """
import json, sys
import ti_spinorbit as tso
model, method, indicators = sys.argv[1], sys.argv[2], sys.argv[3] == "on"
done = tso.warmup(models=[model], indicators=[indicators], sampling=[False], methods=[method],
                  verbose=False)
print(json.dumps(done[0]))
"""


# ---- inputs ------------------------------------------------------------------------------

def starts(n):
    """(θ_p in degrees, θ̇_p/n) of the first n benchmark members (R2 sequence)."""
    k = np.arange(n)
    u = np.mod(0.5 + k / PLASTIC, 1.0)
    v = np.mod(0.5 + k / PLASTIC**2, 1.0)
    return (THETA_P_RANGE[0] + (THETA_P_RANGE[1] - THETA_P_RANGE[0]) * u,
            THETADOT_RANGE[0] + (THETADOT_RANGE[1] - THETADOT_RANGE[0]) * v)


def benchmark_system():
    import ti_spinorbit as tso
    return tso.catalog.system(SYSTEM, elongation=ELONGATION)


def member_table(n):
    """Member parameter rows and initial 3-D states (scaled) of the first n members."""
    from ti_spinorbit.engine.members import Members

    theta_p, thetadot_p = starts(n)
    start = Members.from_starts(benchmark_system(), theta_p, thetadot_p, ESCAPE_DISTANCE)
    par, y0 = start.par, start.y0
    return par, y0


def nice_ceil(x):
    """x rounded up to two significant figures."""
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.ceil(x / scale - 1e-9) * scale


def on_cpu():
    import ti_spinorbit as tso
    return tso.runtime.current_arch() in ("cpu", "x64", "arm64")


# ---- timing one run ----------------------------------------------------------------------

class AdvanceTimer:
    """Times every launch of ``kern.advance`` while active (wall and process CPU time, after
    a device sync), and the end of every window through :meth:`window_done`, which is
    ``Ensemble.run``'s ``progress`` callback. The window loop of a run then lasts from the
    first launch to the last window end; what is not inside a launch is the drain."""

    def __init__(self, kern):
        import taichi as ti

        self.kern, self._sync = kern, ti.sync
        self.launches, self.kernel_wall, self.kernel_cpu = 0, 0.0, 0.0
        self.first = self.last = None

    def __enter__(self):
        self._advance = self.kern.advance
        self.kern.advance = self._timed
        return self

    def __exit__(self, *exc):
        self.kern.advance = self._advance

    def _timed(self, *args):
        wall, cpu = time.perf_counter(), time.process_time()
        if self.first is None:
            self.first = (wall, cpu)
        self._advance(*args)
        self._sync()
        self.kernel_wall += time.perf_counter() - wall
        self.kernel_cpu += time.process_time() - cpu
        self.launches += 1

    def window_done(self, fraction):
        self.last = (time.perf_counter(), time.process_time())


def make_ensemble(par, y0, model, rtol, method=DEFAULT_METHOD):
    """``Ensemble`` of the members with ``model`` and ``method``; ``method=`` is passed only
    when it is not the default, so the script runs on a package without the keyword."""
    from ti_spinorbit.engine.ensemble import Ensemble

    extra = {} if method == DEFAULT_METHOD else {"method": method}
    return Ensemble(par, y0, rtol=rtol, model=model, **extra)


def method_unavailable(method):
    """None if ``Ensemble`` runs ``method``, else a one-line reason (the keyword or the
    value not accepted yet): such a method is skipped, not an error."""
    from ti_spinorbit.engine.ensemble import Ensemble

    if method == DEFAULT_METHOD:
        return None
    if "method" not in inspect.signature(Ensemble).parameters:
        return "Ensemble() has no method= keyword yet"
    par, y0 = member_table(1)
    try:
        make_ensemble(par, y0, "planar", 1e-12, method)
    except (TypeError, ValueError) as exc:
        return f"Ensemble(method={method!r}) refused: {str(exc).splitlines()[0]}"
    return None


def run_point(par, y0, model, rtol, orbits, window=16, method=DEFAULT_METHOD):
    """Integrate the members (par, y0) for ``orbits`` with ``model`` and ``method``; one
    result row."""
    from ti_spinorbit.kernels.advance import DONE

    ens = make_ensemble(par, y0, model, rtol, method)
    n = len(par)
    t_stop = 2.0 * np.pi * orbits
    with AdvanceTimer(ens.kernels) as timer:
        out = ens.run(t_stop, window_orbits=window, progress=timer.window_done)
    loop_wall = timer.last[0] - timer.first[0]
    loop_cpu = timer.last[1] - timer.first[1]
    member_orbits = float(np.sum(np.minimum(out.t, t_stop)) / (2.0 * np.pi))
    accepted, rejected, calls = out.counters.sum(axis=0)
    calls -= n                                   # the first-stage evaluation before the loop
    return {"model": model, "method": method, "rtol": rtol, "members": n, "orbits": orbits,
            "window_orbits": window, "seconds": out.seconds, "loop_wall_s": loop_wall,
            "loop_cpu_s": loop_cpu,
            "kernel_wall_s": timer.kernel_wall, "kernel_cpu_s": timer.kernel_cpu,
            "launches": timer.launches, "member_orbits": member_orbits,
            "member_orbits_per_s": member_orbits / out.seconds,
            "member_orbits_per_cpu_s": member_orbits / loop_cpu,
            "accepted_per_orbit": accepted / member_orbits,
            "rejected_per_orbit": rejected / member_orbits,
            "rhs_per_orbit": calls / member_orbits, "rhs_calls": int(calls),
            "steps": int(accepted + rejected),
            "drain_fraction": max(0.0, loop_wall - timer.kernel_wall) / loop_wall,
            "not_done": int(np.sum(out.status != DONE))}


class Points:
    """Throughput points measured so far, keyed by (model, rtol, N, window, orbits, method);
    a point asked for without orbits is sized by pilot runs so that it lasts about
    ``seconds``."""

    def __init__(self, settings, repeat):
        self.settings, self.repeat = settings, repeat
        self.rows, self._rate, self.warmup_s = {}, {}, {}
        self.par = self.y0 = None

    def table(self, n):
        """Parameter rows and initial states of the first n members (built once, for the
        largest N of the settings or n if larger)."""
        if self.par is None or n > len(self.par):
            self.par, self.y0 = member_table(max(n, *self.settings["sizes"]))
        return self.par[:n], self.y0[:n]

    def warm_up(self, model, method=DEFAULT_METHOD):
        """Compile or load the kernels of (model, method) (timed once, not part of any
        point)."""
        name = model if method == DEFAULT_METHOD else f"{model} {method}"
        if name not in self.warmup_s:
            par, y0 = self.table(1)
            t0 = time.perf_counter()
            run_point(par, y0, model, RTOLS[0], MIN_PILOT_ORBITS, method=method)
            self.warmup_s[name] = time.perf_counter() - t0
        return self.warmup_s[name]

    def get(self, model, rtol, n, window=16, orbits=None, method=DEFAULT_METHOD):
        """The row of (model, rtol, N, window, method) over ``orbits`` (None: sized by pilot
        runs)."""
        key = (model, rtol, n, window, orbits, method)
        if key in self.rows:
            return self.rows[key]
        self.warm_up(model, method)
        par, y0 = self.table(n)
        if orbits is None:
            orbits = self._orbits(par, y0, model, rtol, window, method)
        runs = [run_point(par, y0, model, rtol, orbits, window, method)
                for _ in range(self.repeat)]
        row = dict(min(runs, key=lambda r: r["seconds"]),
                   all_seconds=[r["seconds"] for r in runs])
        self._rate[(model, rtol, method)] = row["member_orbits_per_s"]
        self.rows[key] = row
        print(f"  {model:6} {method:9} rtol {rtol:.0e} N {n:6d} window {window:3d}: "
              f"{orbits:9.4g} orbits {row['seconds']:7.2f} s  "
              f"{row['member_orbits_per_s']:10.1f} member-orbits/s", flush=True)
        return row

    def measured(self, model, rtol, n, method=DEFAULT_METHOD):
        """The sized, default-window row of (model, rtol, N, method), or None if not
        measured."""
        return self.rows.get((model, rtol, n, 16, None, method))

    def _orbits(self, par, y0, model, rtol, window, method):
        """Orbits for a run of about ``seconds``: a pilot run of PILOT_FRACTION of that,
        sized by the last rate of this model and rtol, measures the rate (a pilot shorter than
        half its plan is repeated with the rate it measured, at most twice)."""
        n, s = len(par), self.settings
        plan = PILOT_FRACTION * s["seconds"]
        rate = self._rate.get((model, rtol, method),
                              self._rate.get((model, rtol, DEFAULT_METHOD), FIRST_RATE_GUESS))
        for _ in range(3):
            pilot = run_point(par, y0, model, rtol, max(MIN_PILOT_ORBITS, plan * rate / n),
                              window, method)
            rate = pilot["member_orbits_per_s"]
            if pilot["seconds"] >= 0.5 * plan:
                break
        return max(s["min_orbits"], nice_ceil(s["seconds"] * rate / n))


# ---- sections ----------------------------------------------------------------------------

def bench_throughput(points, models, rtols, sizes, methods=(DEFAULT_METHOD,)):
    return [points.get(model, rtol, n, method=method) for model in models for rtol in rtols
            for method in methods for n in sorted(sizes)]


_RHS_LOOPS = {}


def rhs_loop_kernel(model):
    """Kernel: for each member, R dependent evaluations of ``model.rhs`` (see ``split``)."""
    if model.__name__ in _RHS_LOOPS:
        return _RHS_LOOPS[model.__name__]
    import taichi as ti

    nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
    nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)

    @ti.kernel
    def rhs_loop(par: nd2f, y_nd: nd2f, out: nd1f, repeats: ti.i32, order: ti.template(),
                 odd: ti.template()):
        for i in range(y_nd.shape[0]):
            y0 = model.state(0.0)
            for k in ti.static(range(model.NSTATE)):
                y0[k] = y_nd[i, k]
            z = y0
            for _ in range(repeats):
                z = y0 + RHS_PERTURBATION * model.rhs(par, i, z, order, odd)
            out[i] = z.sum()

    _RHS_LOOPS[model.__name__] = rhs_loop
    return rhs_loop


def bench_rhs(points, model_name, n, seconds, repeat):
    """ns per RHS evaluation of one model on the first n benchmark states."""
    import taichi as ti

    from ti_spinorbit.engine.ensemble import Ensemble

    ens = Ensemble(*points.table(n), model=model_name)    # kernel-layout parameters, states
    kernel = rhs_loop_kernel(ens.kernels.model)
    out = np.zeros(n)

    def timed(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        kernel(ens.kpar, ens.y, out, repeats, ens.order, ens.odd)
        ti.sync()
        return time.perf_counter() - wall, time.process_time() - cpu

    timed(1)                                      # compile or load
    calibration = 16
    wall, _ = timed(calibration)
    repeats = max(calibration, int(seconds / max(wall, 1e-6) * calibration))
    wall, cpu = min((timed(repeats) for _ in range(repeat)), key=lambda t: t[0])
    evaluations = n * repeats
    row = {"model": model_name, "members": n, "repeats": repeats, "wall_s": wall, "cpu_s": cpu,
           "ns_per_rhs_wall": 1e9 * wall / evaluations, "ns_per_rhs_cpu": 1e9 * cpu / evaluations}
    print(f"  RHS only {model_name:6} N {n}: {repeats} repeats, {wall:.2f} s", flush=True)
    return row


def time_split(points, rhs_rows, models, rtols, n):
    """Per model and rtol at N = n: ns per RHS, per pass, and the RHS / rest / drain split."""
    basis = "cpu" if on_cpu() else "wall"
    rows = []
    for model in models:
        ns_rhs = rhs_rows[model][f"ns_per_rhs_{basis}"]
        for rtol in rtols:
            p = points.get(model, rtol, n)
            kernel, loop = p[f"kernel_{basis}_s"], p[f"loop_{basis}_s"]
            ns_pass = 1e9 * kernel / p["rhs_calls"]
            rhs_share = min(1.0, ns_rhs / ns_pass)
            inside = 1.0 - p["drain_fraction"]
            rows.append({"model": model, "rtol": rtol, "members": n, "basis": basis,
                         "ns_per_rhs": ns_rhs, "ns_per_pass": ns_pass,
                         "ns_per_pass_with_drain": 1e9 * loop / p["rhs_calls"],
                         "us_per_step": 1e6 * loop / p["steps"],
                         "passes_per_step": p["rhs_calls"] / p["steps"],
                         "overhead_fraction": 1.0 - rhs_share,
                         "drain_fraction": p["drain_fraction"],
                         "rhs_share_of_total": rhs_share * inside,
                         "rest_share_of_total": (1.0 - rhs_share) * inside,
                         "launches": p["launches"]})
    return rows


def cpu_info():
    """(model name, mean clock in GHz, flags) from /proc/cpuinfo; Nones where unreadable."""
    name, mhz, flags = platform.processor() or None, [], set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key = key.strip()
                if key == "model name":
                    name = value.strip()
                elif key == "cpu MHz":
                    mhz.append(float(value))
                elif key == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    return name, (sum(mhz) / len(mhz) / 1000.0 if mhz else None), flags


def flop_rates(points, rhs_rows, models, rtols, n, machine, flops_per_cycle):
    """Achieved flop rates (RHS flops only) and the fraction of the f64 peak."""
    cores, ghz = machine["cpus_usable"], machine["cpu_ghz"]
    cpu = on_cpu() and ghz is not None
    core_peak = ghz * flops_per_cycle if cpu else None           # Gflop/s per core
    rows = []
    for model in models:
        flops = FLOPS_PER_RHS[model]
        r = rhs_rows[model]
        evaluations = r["members"] * r["repeats"]
        measured = [("RHS only", None, flops * evaluations / r["wall_s"] / 1e9,
                     flops / r["ns_per_rhs_cpu"] if cpu else None)]
        for rtol in rtols:
            p = points.get(model, rtol, n)
            measured.append(("integrator", rtol, flops * p["rhs_calls"] / p["loop_wall_s"] / 1e9,
                             flops * p["rhs_calls"] / p["loop_cpu_s"] / 1e9 if cpu else None))
        for what, rtol, total, per_core in measured:
            rows.append({"model": model, "what": what, "rtol": rtol, "members": n,
                         "flops_per_rhs": flops, "gflops_wall": total,
                         "gflops_per_core_cpu": per_core,
                         "peak_gflops": core_peak * cores if cpu else None,
                         "fraction_of_peak": per_core / core_peak if cpu else None})
    return rows


def child_threads(threads, members, rtol, window, orbits_json):
    """Child process of the threads section: both models at ``threads`` CPU threads; prints
    the result rows as one JSON line."""
    import ti_spinorbit as tso

    tso.init(arch="cpu", cpu_max_num_threads=int(threads))
    par, y0 = member_table(int(members))
    rows = []
    for model, orbits in json.loads(orbits_json).items():
        run_point(par[:1], y0[:1], model, float(rtol), MIN_PILOT_ORBITS)   # compile or load
        rows.append(run_point(par, y0, model, float(rtol), orbits, int(window)))
    print(json.dumps(rows))


def run_child(code, args=(), env=None):
    """Run ``sys.executable -c code *args``; returns (wall seconds, its last-line JSON)."""
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", code, *map(str, args)], capture_output=True,
                          text=True, env=env, cwd=EXPERIMENTS)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"child process failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    return wall, json.loads(proc.stdout.strip().splitlines()[-1])


def child_env(arch, **extra):
    env = dict(os.environ, **extra)
    if arch:
        env["TI_SPINORBIT_ARCH"] = arch
    return env


def bench_threads(points, models, n, repeat, rtol=1e-12, window=16):
    """Each model with k = 1, 2 (, all) threads in fresh processes, alternating; best of
    ``repeat``. Orbits: the in-process rate at N = n sized for ``seconds`` on all cores."""
    seconds = points.settings["seconds"]
    orbits = {m: max(points.settings["min_orbits"],
                     nice_ceil(seconds * points.get(m, rtol, n)["member_orbits_per_s"] / n))
              for m in models}
    counts = sorted({1, 2, os.cpu_count() or 1})
    runs = {(k, m): [] for k in counts for m in models}
    for _ in range(repeat):
        for k in counts:
            _, rows = run_child(CHILD_THREADS, (k, n, rtol, window, json.dumps(orbits)),
                                env=child_env(None))
            for r in rows:
                runs[(k, r["model"])].append(r)
    out = []
    for m in models:
        one = None
        for k in counts:
            best = min(runs[(k, m)], key=lambda r: r["seconds"])
            one = one or best
            speedup = best["member_orbits_per_s"] / one["member_orbits_per_s"]
            out.append({"threads": k, **best, "all_seconds": [r["seconds"] for r in runs[(k, m)]],
                        "speedup": speedup, "efficiency": speedup / k})
            print(f"  threads {k} {m:6}: {best['seconds']:7.2f} s  "
                  f"{best['member_orbits_per_s']:10.1f} member-orbits/s", flush=True)
    return out


def bench_window(points, n):
    return [points.get("planar", 1e-12, n, window=w, orbits=points.settings["window_orbits"])
            for w in WINDOWS]


def bench_baseline(members, orbits, rtols):
    """scipy DOP853 on the NumPy reference, and the same members through the kernels."""
    import ti_spinorbit as tso
    from ti_spinorbit.model import reference
    from ti_spinorbit.engine.ensemble import Ensemble

    system = benchmark_system()
    unit = system.to_physical(np.ones(30))  # SI size of one scaled unit, per component
    t_end = orbits * system.orbital_period
    par, y0_scaled = member_table(members)
    importlib.import_module("scipy.integrate")  # one-off import cost before timing
    reference.rhs(tso.G, system.primary, system.secondary, system.to_physical(y0_scaled[0]))
    rows = []
    for rtol in rtols:
        seconds, steps, rhs, final = 0.0, 0, 0, []
        for y0 in y0_scaled:
            t0 = time.perf_counter()
            with warnings.catch_warnings():  # "rtol too small": recorded as scipy_rtol below
                warnings.simplefilter("ignore", UserWarning)
                sol = reference.integrate(tso.G, system.primary, system.secondary,
                                          system.to_physical(y0), (0.0, t_end), rtol=rtol,
                                          atol=rtol * unit)
            seconds += time.perf_counter() - t0
            if sol.status != 0:
                raise RuntimeError(f"reference integration failed at rtol {rtol}: {sol.message}")
            steps += len(sol.t) - 1
            rhs += sol.nfev
            final.append(sol.y[:, -1])
        kernel = Ensemble(par, y0_scaled, rtol=rtol).run(2.0 * np.pi * orbits)
        mismatch = np.max(np.abs(np.array(final) - system.to_physical(kernel.y)) / unit)
        rows.append({"rtol": rtol, "scipy_rtol": max(rtol, SCIPY_MIN_RTOL),
                     "atol": "rtol * to_physical(ones)", "members": members,
                     "orbits": orbits, "seconds": seconds,
                     "member_orbits_per_s": members * orbits / seconds,
                     "steps_per_orbit": steps / (members * orbits),
                     "rhs_per_orbit": rhs / (members * orbits),
                     "kernel_reference_max_diff_scaled": float(mismatch)})
        print(f"  scipy  rtol {rtol:.0e}: {seconds:8.3f} s", flush=True)
    return rows


def numba_baseline():
    """The numba DOP853 module (experiments/_numba_dop853.py), or None when numba is not
    installed (``pip install ti-spinorbit[bench]``)."""
    try:
        return importlib.import_module("_numba_dop853")
    except ImportError as exc:
        print(f"  numba baseline skipped: {exc} (pip install 'ti-spinorbit[bench]')", flush=True)
        return None


def random_planar_states(n, seed=1):
    """n random planar states (r 0.8-1.3, any angles and spins): RHS comparisons only."""
    rng = np.random.default_rng(seed)
    q = np.zeros((n, 10))
    q[:, 0] = rng.uniform(0.8, 1.3, n)
    q[:, 1] = 0.1 * rng.normal(size=n)
    q[:, 2] = rng.uniform(0.8, 1.2, n)
    q[:, 3] = rng.uniform(0.0, 2.0 * np.pi, n)
    for c, angle in ((4, rng.uniform(0, 2 * np.pi, n)), (7, rng.uniform(0, 2 * np.pi, n))):
        q[:, c], q[:, c + 1] = np.cos(angle), np.sin(angle)
    q[:, 6], q[:, 9] = rng.normal(size=n), rng.normal(size=n)
    return q


def numba_rhs_mismatch(nb, kpar, q):
    """max over states and components of |f_numba − f_package| / max |f_package| of that
    component: the baseline's RHS against the planar kernels' (round-off: ~1e-16)."""
    from ti_spinorbit.kernels import advance as K

    f_pkg, f_nb = np.zeros_like(q), np.zeros_like(q)
    K.PLANAR.evaluate_rhs(kpar, q, f_pkg, 4, False)
    nb.rhs_many(kpar, q, f_nb)
    scale = np.maximum(np.abs(f_pkg).max(axis=0), np.finfo(float).tiny)
    return float(np.max(np.abs(f_nb - f_pkg) / scale))


def numba_run(nb, kpar, q0, orbits, rtol):
    """The members one after the other on this thread: (final planar states, counters, wall
    s, this thread's CPU s)."""
    y, counters = np.zeros_like(q0), np.zeros((len(q0), 3), dtype=np.int64)
    wall, cpu = time.perf_counter(), time.thread_time()
    nb.integrate_many(kpar, q0, 2.0 * np.pi * orbits, rtol, rtol, y, counters)
    return y, counters, time.perf_counter() - wall, time.thread_time() - cpu


def bench_numba(points, rtols, members, seconds, repeat, check_orbits, curve=()):
    """numba DOP853, planar, one member at a time on one core; orbits per CPU-second at
    ``rtols`` and, marked ``curve``, at the extra tolerances ``curve`` (the rate-against-
    error curve of the equal-accuracy comparison)."""
    from ti_spinorbit.model import planar

    nb = numba_baseline()
    if nb is None:
        return []
    par, y0 = points.table(members)
    kpar, q0 = planar.parameter_rows(par), planar.to_planar(y0)
    nb.check_even(kpar)
    t0 = time.perf_counter()
    numba_run(nb, kpar[:1], q0[:1], 0.01, 1e-10)             # compile (or load numba's cache)
    compile_s = time.perf_counter() - t0
    rhs_mismatch = numba_rhs_mismatch(nb, kpar[:1].repeat(256, axis=0), random_planar_states(256))
    # whole trajectories against the kernels at a tight tolerance
    tight = 1e-14
    y_nb = numba_run(nb, kpar, q0, check_orbits, tight)[0]
    kernel = make_ensemble(par, y0, "planar", tight).run(2.0 * np.pi * check_orbits)
    trajectory_mismatch = float(np.max(np.abs(planar.to_spatial(y_nb) - kernel.y)))
    print(f"  numba DOP853: compile/load {compile_s:.2f} s; RHS vs package max rel diff "
          f"{rhs_mismatch:.1e}; final states vs kernels (rtol {tight:g}, {check_orbits:g} "
          f"orbits) max |dy| {trajectory_mismatch:.1e}", flush=True)
    rows = []
    for rtol in sorted(set(rtols) | set(curve), reverse=True):
        _, c, _, cpu = numba_run(nb, kpar, q0, 1.0, rtol)    # pilot: one orbit each
        rate = members / max(cpu, 1e-6)
        orbits = max(points.settings["min_orbits"], nice_ceil(seconds * rate / members))
        runs = [numba_run(nb, kpar, q0, orbits, rtol) for _ in range(repeat)]
        _, counters, wall, cpu = min(runs, key=lambda r: r[3])
        mo = members * orbits
        accepted, rejected, calls = counters.sum(axis=0)
        rows.append({"method": "numba DOP853", "model": "planar", "rtol": rtol,
                     "curve": rtol not in rtols,
                     "members": members, "orbits": orbits, "threads": 1, "wall_s": wall,
                     "cpu_s": cpu, "orbits_per_s": mo / wall, "orbits_per_cpu_s": mo / cpu,
                     "accepted_per_orbit": accepted / mo, "rejected_per_orbit": rejected / mo,
                     "rhs_per_orbit": calls / mo, "ns_per_rhs": 1e9 * cpu / calls,
                     "all_cpu_s": [r[3] for r in runs], "compile_s": compile_s,
                     "rhs_max_rel_diff_vs_package": rhs_mismatch,
                     "final_state_max_diff_vs_kernels": trajectory_mismatch,
                     "check_rtol": tight, "check_orbits": check_orbits})
        print(f"  numba DOP853 rtol {rtol:.0e}: {mo:g} member-orbits {cpu:7.2f} CPU-s "
              f"{mo / cpu:10.1f} orbits/CPU-s", flush=True)
    return rows


def bench_accuracy(models, methods, rtols, members, orbits, numba_rtols=()):
    """Final-state error of every (model, method, rtol) and of the numba baseline against a
    tight reference: numba DOP853 at ACCURACY_REFERENCE_RTOL (else the kernels' Cash-Karp at
    that rtol). Error of a member: max over the 30 scaled 3-D state components (the planar
    states are compared after ``to_spatial``, so both models meet the same reference)."""
    from ti_spinorbit.model import planar

    par, y0 = member_table(members)
    t_end = 2.0 * np.pi * orbits
    nb = numba_baseline()
    tight = ACCURACY_REFERENCE_RTOL
    if nb is not None:
        kpar, q0 = planar.parameter_rows(par), planar.to_planar(y0)
        reference = planar.to_spatial(numba_run(nb, kpar, q0, orbits, tight)[0])
        reference_name = f"numba DOP853, rtol {tight:g}"
    else:
        reference = make_ensemble(par, y0, "planar", tight).run(t_end).y
        reference_name = f"kernels, Cash-Karp, planar, rtol {tight:g}"
    rows = []

    def add(model, method, rtol, y):
        err = np.max(np.abs(y - reference), axis=1)
        rows.append({"model": model, "method": method, "rtol": rtol, "members": members,
                     "orbits": orbits, "reference": reference_name,
                     "median_error": float(np.median(err)), "max_error": float(err.max())})

    for rtol in rtols:
        for model in models:
            for method in methods:
                add(model, method, rtol, make_ensemble(par, y0, model, rtol, method).run(t_end).y)
    if nb is not None:
        for rtol in sorted(set(rtols) | set(numba_rtols), reverse=True):
            add("planar", "numba DOP853", rtol, planar.to_spatial(numba_run(nb, kpar, q0, orbits,
                                                                          rtol)[0]))
    print(f"  accuracy: {len(rows)} runs against {reference_name}", flush=True)
    return rows


def bench_first_result(arch, repeat, cold, models=("planar",)):
    """Fresh processes, per model: with ``cold``, a run with a new empty kernel cache and
    then max(``repeat``, 3) runs with it warm (the best is the warm-start figure); else those
    warm runs with the default cache folder."""
    runs = []
    for model in models:
        code = CHILD_FIRST_RESULT.format(system=SYSTEM, elongation=ELONGATION, model=model)
        with tempfile.TemporaryDirectory(prefix="ti_spinorbit_cache_") as cache:
            env = child_env(arch, TI_OFFLINE_CACHE_FILE_PATH=cache) if cold else child_env(arch)
            labels = (["cold cache"] if cold else []) + ["warm cache"] * max(repeat, 3)
            for label in labels:
                wall, inside = run_child(code, env=env)
                runs.append({"model": model, "run": label, "new_cache_folder": cold,
                             "wall_s": wall, **inside})
                print(f"  fresh process, {model}, {label}: {wall:8.3f} s", flush=True)
    return runs


def bench_compile(arch, models, methods, repeat):
    """Cold compile of every variant (model x method x indicators, sampling off): each in a
    fresh process with a new empty kernel cache (``repeat`` times, the fastest kept), then
    its load from that cache in another fresh process. Kernel seconds are tso.warmup's
    (the integrator and diagnostics kernels; imports and ti.init excluded)."""
    rows = []
    for model in models:
        for method in methods:
            for indicators in ("off", "on"):
                cold, warm = [], []
                for _ in range(repeat):
                    with tempfile.TemporaryDirectory(prefix="ti_spinorbit_cache_") as cache:
                        env = child_env(arch, TI_OFFLINE_CACHE_FILE_PATH=cache)
                        cold.append(run_child(CHILD_COMPILE, (model, method, indicators), env))
                        warm.append(run_child(CHILD_COMPILE, (model, method, indicators), env))
                c = min(cold, key=lambda wi: wi[1]["kernel_seconds"])
                w = min(warm, key=lambda wi: wi[1]["kernel_seconds"])
                rows.append({"model": model, "method": method, "indicators": indicators,
                             "variant": c[1]["variant"], "compile_s": c[1]["kernel_seconds"],
                             "cold_process_s": c[0], "load_s": w[1]["kernel_seconds"],
                             "warm_process_s": w[0], "how_warm": w[1]["how"]})
                print(f"  compile {c[1]['variant']}: {c[1]['kernel_seconds']:.2f} s cold, "
                      f"{w[1]['kernel_seconds']:.2f} s from the cache", flush=True)
    return rows


def fastest(points, model, rtol, n, methods, key="member_orbits_per_s"):
    """(method, row) of the measured method with the highest ``key`` at (model, rtol, N)."""
    rows = [(m, points.measured(model, rtol, n, m)) for m in methods]
    rows = [(m, r) for m, r in rows if r]
    return max(rows, key=lambda mr: mr[1][key]) if rows else (None, None)


def targets13(points, numba_rows, accuracy_rows, models, methods, n, cores, cpu):
    """Targets with their values and ratios to the target."""
    out = []

    def add(text, value, goal):
        out.append({"target": text, "value": value, "ratio": value / goal,
                    "met": value >= goal})

    if "planar" in models:
        method, row = fastest(points, "planar", 1e-12, n, methods)
        if row:
            add(f">= {TARGET_PLANAR:.0f} member-orbits/s on {cores} cores, planar, fastest "
                f"method ({method}), N = {n}, rtol 1e-12", row["member_orbits_per_s"],
                TARGET_PLANAR)
        for b in (b for b in numba_rows if not b.get("curve")):
            key = "member_orbits_per_cpu_s" if cpu else "member_orbits_per_s"
            method, row = fastest(points, "planar", b["rtol"], n, methods, key)
            if row:
                add(f">= {TARGET_PER_CORE:g}x the numba DOP853 baseline "
                    f"({b['orbits_per_cpu_s']:.0f} orbits/CPU-s, one core) "
                    + ("per core" if cpu else "(device wall rate against one CPU core)")
                    + f", planar, fastest method ({method}, {row[key]:.0f}), N = {n}, "
                    f"rtol {b['rtol']:.0e}", row[key] / b["orbits_per_cpu_s"],
                    TARGET_PER_CORE)
        today = points.measured("planar", 1e-15, n, DEFAULT_METHOD)
        method, row = fastest(points, "planar", 1e-15, n, methods)
        if today and row:
            add(f">= {TARGET_TIGHT:g}x today's Cash-Karp rate ({today['member_orbits_per_s']:.0f}"
                f"), planar, fastest method ({method}), N = {n}, rtol 1e-15",
                row["member_orbits_per_s"] / today["member_orbits_per_s"], TARGET_TIGHT)
    if "3d" in models:
        method, row = fastest(points, "3d", 1e-12, n, methods)
        if row:
            add(f">= {TARGET_3D:.0f} member-orbits/s, 3-D, fastest method ({method}), N = {n}, "
                "rtol 1e-12", row["member_orbits_per_s"], TARGET_3D)
    return out + _accuracy_targets(accuracy_rows, methods)


def targets13_compile(compile_rows, first_runs):
    """Targets: cold compile per variant and warm start per model."""
    out = []
    ref = [r for r in compile_rows if (r["model"], r["method"], r["indicators"])
           == ("planar", DEFAULT_METHOD, "off")]
    for r in compile_rows:
        what = f"{r['model']}, {r['method']}, indicators {r['indicators']}"
        out.append({"target": f"cold compile <= {TARGET_COMPILE_S:.0f} s, {what}",
                    "value": r["compile_s"], "ratio": r["compile_s"] / TARGET_COMPILE_S,
                    "met": r["compile_s"] <= TARGET_COMPILE_S})
        if ref:
            ratio = r["compile_s"] / ref[0]["compile_s"]
            out.append({"target": f"cold compile <= {TARGET_COMPILE_RATIO:g}x the "
                                  f"planar default's ({ref[0]['compile_s']:.2f} s), {what}",
                        "value": ratio, "ratio": ratio / TARGET_COMPILE_RATIO,
                        "met": ratio <= TARGET_COMPILE_RATIO})
    for model in dict.fromkeys(f["model"] for f in first_runs):
        warm = [f["wall_s"] for f in first_runs if f["model"] == model and f["run"] == "warm cache"]
        if warm:
            best = min(warm)
            out.append({"target": f"warm start <= {TARGET_WARM_S:g} s, fresh process "
                                  f"to the first result of a one-orbit {model} section (best "
                                  f"of {len(warm)})", "value": best,
                        "ratio": best / TARGET_WARM_S, "met": best <= TARGET_WARM_S})
    return out


def _accuracy_targets(accuracy_rows, methods):
    """Accuracy at equal rtol: each method's median final-state error over Cash-Karp's."""
    out = []
    for a in accuracy_rows:
        if a["method"] == DEFAULT_METHOD or a["method"] not in methods:
            continue
        ck = [c for c in accuracy_rows if (c["model"], c["rtol"], c["method"])
              == (a["model"], a["rtol"], DEFAULT_METHOD)]
        if ck:
            ratio = a["median_error"] / max(ck[0]["median_error"], 1e-300)
            out.append({"target": f"accuracy at equal rtol, {a['method']} error <= "
                                  f"Cash-Karp's, {a['model']}, rtol {a['rtol']:.0e} (median "
                                  f"{a['median_error']:.2e} vs {ck[0]['median_error']:.2e})",
                        "value": ratio, "met": ratio <= 1.0})
    return out


def equal_accuracy(points, numba_rows, accuracy_rows, methods, n, cpu):
    """Informational (not a target): each planar method at each baseline rtol
    against the numba baseline at the SAME median final-state error, its rate read off the
    baseline's rate-against-error curve (log-log interpolation between the measured
    tolerances; None outside the curve)."""
    def error(method, rtol):
        rows = [a for a in accuracy_rows
                if (a["model"], a["method"], a["rtol"]) == ("planar", method, rtol)]
        return rows[0]["median_error"] if rows else None

    curve = sorted((error(b["method"], b["rtol"]), b["orbits_per_cpu_s"], b["rtol"])
                   for b in numba_rows if error(b["method"], b["rtol"]))
    out = []
    if len(curve) < 2:
        return out
    log_err = np.log([c[0] for c in curve])
    key = "member_orbits_per_cpu_s" if cpu else "member_orbits_per_s"
    for b in (b for b in numba_rows if not b.get("curve")):
        for method in methods:
            row, err = points.measured("planar", b["rtol"], n, method), error(method, b["rtol"])
            if not row or not err:
                continue
            inside = log_err[0] <= np.log(err) <= log_err[-1]
            rate = float(np.exp(np.interp(np.log(err), log_err, np.log([c[1] for c in curve])))) \
                if inside else None
            numba_rtol = float(np.exp(np.interp(np.log(err), log_err,
                                                np.log([c[2] for c in curve])))) \
                if inside else None
            out.append({"method": method, "rtol": b["rtol"], "members": n, "median_error": err,
                        "rate": row[key], "numba_rate_at_equal_error": rate,
                        "numba_rtol_at_equal_error": numba_rtol,
                        "ratio": row[key] / rate if rate else None})
    return out


def targets(points, baseline_rows, first_runs, models, n):
    """Each target with its measured value (kernel figures at N = n)."""
    out = []
    for m in models:
        row = points.measured(m, 1e-12, n)
        if row:
            rate = row["member_orbits_per_s"]
            out.append({"target": f">= {TARGET_RATE[m]:.0f} member-orbits/s, {m}, N = {n}, "
                                  "rtol 1e-12", "value": rate, "met": rate >= TARGET_RATE[m]})
        for b in baseline_rows:
            row = points.measured(m, b["rtol"], n)
            if row:
                ratio = row["member_orbits_per_s"] / b["member_orbits_per_s"]
                out.append({"target": f">= {TARGET_SPEEDUP:.0f}x scipy DOP853, {m}, N = {n}, "
                                      f"rtol {b['rtol']:.0e}",
                            "value": ratio, "met": ratio >= TARGET_SPEEDUP})
    warm = [f["wall_s"] for f in first_runs if f["run"] == "warm cache"]
    if warm:
        out.append({"target": f"<= {TARGET_FIRST_RESULT_S:.0f} s first result, fresh process, "
                              "warm cache", "value": min(warm),
                    "met": min(warm) <= TARGET_FIRST_RESULT_S})
    return out


# ---- report ------------------------------------------------------------------------------

def machine_info():
    """Versions, CPU, git state and the load average at the start (the machine may be
    shared: other processes' load lowers every wall-clock figure)."""
    import scipy
    import taichi as ti

    import ti_spinorbit as tso

    name, ghz, flags = cpu_info()
    try:
        commit = subprocess.run(["git", "describe", "--always", "--dirty"], capture_output=True,
                                text=True, cwd=EXPERIMENTS, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = None
    return {"date_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
            "cpu_count": os.cpu_count(),
            "cpus_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
            else os.cpu_count(),
            "cpu_model": name, "cpu_ghz": ghz,
            "simd": sorted(f for f in flags if f in ("avx2", "fma", "avx512f")),
            "machine": platform.machine(), "platform": platform.platform(),
            "python": platform.python_version(), "taichi": ".".join(map(str, ti.__version__)),
            "numpy": np.__version__, "scipy": scipy.__version__, "numba": _version("numba"),
            "ti_spinorbit": tso.__version__, "arch": tso.runtime.current_arch(), "git": commit,
            "load_average_1min_start": os.getloadavg()[0]}


def _version(module):
    try:
        return importlib.import_module(module).__version__
    except ImportError:
        return None


def _opt(x, fmt):
    return "-" if x is None else format(x, fmt)


def _table(rows, columns):
    """Print ``rows`` (dicts) under ``columns`` = (header, key, format spec); None prints as
    "-", the spec "%" as a percentage; every column is right-aligned to its widest entry."""
    def cell(value, spec):
        return f"{100.0 * value:.1f}%" if spec == "%" and value is not None else _opt(value, spec)

    body = [[cell(r[key], spec) for _, key, spec in columns] for r in rows]
    lines = [[header for header, _, _ in columns]] + body
    widths = [max(len(line[k]) for line in lines) for k in range(len(columns))]
    for line in lines:
        print(" ".join(text.rjust(width) for text, width in zip(line, widths)))


MODEL, RTOL, N = ("model", "model", "s"), ("rtol", "rtol", ".0e"), ("N", "members", "d")
METHOD = ("method", "method", "s")
RATE = ("mo/s", "member_orbits_per_s", ".1f")
CPU_RATE = ("mo/CPU-s", "member_orbits_per_cpu_s", ".1f")
ORBITS, SECONDS = ("orbits", "orbits", ".4g"), ("seconds", "seconds", ".2f")
LAUNCHES, DRAIN = ("launches", "launches", "d"), ("drain", "drain_fraction", "%")
TABLES = {
    "throughput": [MODEL, METHOD, RTOL, N, ORBITS, SECONDS, RATE, CPU_RATE,
                   ("acc/orb", "accepted_per_orbit", ".1f"),
                   ("rej/orb", "rejected_per_orbit", ".2f"), ("RHS/orb", "rhs_per_orbit", ".1f"),
                   LAUNCHES, DRAIN, ("not done", "not_done", "d")],
    "split": [MODEL, RTOL, N, ("basis", "basis", "s"), ("ns/RHS", "ns_per_rhs", ".1f"),
              ("ns/pass", "ns_per_pass", ".1f"), ("+drain", "ns_per_pass_with_drain", ".1f"),
              ("us/step", "us_per_step", ".2f"), ("pass/step", "passes_per_step", ".2f"),
              ("overhead", "overhead_fraction", "%"), ("RHS", "rhs_share_of_total", "%"),
              ("rest", "rest_share_of_total", "%"), DRAIN],
    "flops": [MODEL, ("what", "what", "s"), RTOL, ("Gflop/s", "gflops_wall", ".2f"),
              ("per core", "gflops_per_core_cpu", ".2f"), ("of peak", "fraction_of_peak", "%")],
    "threads": [MODEL, ("k", "threads", "d"), N, ORBITS, SECONDS, RATE, CPU_RATE,
                ("speed-up", "speedup", ".2f"), ("efficiency", "efficiency", "%")],
    "window": [("window", "window_orbits", "d"), N, ORBITS, SECONDS, RATE, CPU_RATE, LAUNCHES,
               DRAIN],
    "baseline": [RTOL, ("scipy rtol", "scipy_rtol", ".2g"), ("members", "members", "d"),
                 ORBITS, ("seconds", "seconds", ".3f"), ("mo/s", "member_orbits_per_s", ".3f"),
                 ("steps/orb", "steps_per_orbit", ".1f"), ("RHS/orb", "rhs_per_orbit", ".1f"),
                 ("max|dy| vs kernel", "kernel_reference_max_diff_scaled", ".2e")],
    "numba": [RTOL, ("members", "members", "d"), ORBITS, ("CPU s", "cpu_s", ".2f"),
              ("orbits/CPU-s", "orbits_per_cpu_s", ".1f"), ("orbits/s", "orbits_per_s", ".1f"),
              ("acc/orb", "accepted_per_orbit", ".1f"), ("rej/orb", "rejected_per_orbit", ".2f"),
              ("RHS/orb", "rhs_per_orbit", ".1f"), ("ns/RHS", "ns_per_rhs", ".1f")],
    "accuracy": [MODEL, METHOD, RTOL, ("members", "members", "d"), ORBITS,
                 ("median err", "median_error", ".2e"), ("max err", "max_error", ".2e")],
    "compile": [MODEL, METHOD, ("indicators", "indicators", "s"),
                ("cold compile s", "compile_s", ".2f"), ("process s", "cold_process_s", ".2f"),
                ("cache load s", "load_s", ".2f"), ("process s ", "warm_process_s", ".2f")],
}


def print_report(result):
    m, s, p = result["machine"], result["sections"], result["parameters"]
    print()
    print(f"ti_spinorbit throughput benchmark  {m['date_utc']}  "
          f"{'quick' if result['quick'] else 'full'}, {result['total_seconds']:.0f} s")
    print(f"machine: {m['cpu_model']} at {_opt(m['cpu_ghz'], '.2f')} GHz, {m['cpus_usable']} "
          f"usable CPUs ({m['machine']}, {', '.join(m['simd']) or 'no AVX2'}), Taichi "
          f"{m['taichi']}, arch {m['arch']}, git {m['git']}")
    print(f"load average (1 min) at start {m['load_average_1min_start']:.2f}, at end "
          f"{m['load_average_1min_end']:.2f} (other processes share the CPUs if > 0)")
    print(f"system {SYSTEM}, a/b = {ELONGATION}; starts: R2 sequence over theta_p in "
          f"[{THETA_P_RANGE[0]:g}, {THETA_P_RANGE[1]:g}) deg, thetadot_p/n in "
          f"[{THETADOT_RANGE[0]}, {THETADOT_RANGE[1]}]; kernel warm-up (compile or load) "
          + ", ".join(f"{k} {v:.2f} s" for k, v in result["warmup_s"].items()))
    captions = {
        "throughput": "member-orbits per second (wall) and per process CPU-second; steps and "
                      "RHS calls per member-orbit",
        "split": "ns per pass = advance time / RHS calls; overhead = 1 - RHS/pass (stage "
                 "points and combination, error norm, step control, events, loads/stores); "
                 "drain = Python between launches; RHS, rest, drain: shares of the wall time",
        "flops": "hand-counted flops per RHS: "
                 + ", ".join(f"{k} {v}" for k, v in FLOPS_PER_RHS.items())
                 + f"; peak assumed {m['cpus_usable']} cores x {_opt(m['cpu_ghz'], '.2f')} GHz "
                 f"x {p['flops_per_cycle']:g} f64 flops/cycle (AVX2+FMA: 2 FMA units x 4 lanes "
                 "x 2); scalar code reaches about 1/4 of it",
        "threads": "fresh processes, cpu_max_num_threads = k; speed-up over 1 thread (wall), "
                   "efficiency = speed-up / k",
        "window": "planar, rtol 1e-12: orbits per launch",
        "baseline": "scipy DOP853 + NumPy reference RHS, atol = rtol * to_physical(ones)",
        "numba": "compiled single-trajectory DOP853 (numba, experiments/_numba_dop853.py), "
                 "planar, members one after the other on ONE core, atol = rtol, Hairer's "
                 "RMS error norm; orbits per CPU-second = per core",
        "accuracy": "final-state error at equal rtol: max |dy| over the scaled 3-D state "
                    "against a tight reference, median and max over members",
        "compile": "each kernel variant in a fresh process with a new empty kernel cache "
                   "(cold), then loaded from it in another fresh process; kernel seconds "
                   "(integrator and diagnostics) and the whole process"}
    for name, columns in TABLES.items():
        if s.get(name):
            print(f"\n[{name}] {captions[name]}")
            if name == "split":
                print("RHS-only kernel, per RHS: " + "; ".join(
                    f"{k} {v['ns_per_rhs_cpu']:.1f} ns CPU time, {v['ns_per_rhs_wall']:.1f} ns "
                    f"wall (N = {v['members']}, {v['repeats']} repeats)"
                    for k, v in s["rhs_only"].items()))
            if name == "numba":
                b = s[name][0]
                print(f"checks: RHS vs the package's planar RHS, max relative difference "
                      f"{b['rhs_max_rel_diff_vs_package']:.1e} (256 random states); final "
                      f"states vs the kernels at rtol {b['check_rtol']:g} over "
                      f"{b['check_orbits']:g} orbits, max |dy| "
                      f"{b['final_state_max_diff_vs_kernels']:.1e}; compile/load "
                      f"{b['compile_s']:.2f} s")
            if name == "accuracy":
                print(f"reference: {s[name][0]['reference']}")
            _table(s[name], columns)
            if name == "accuracy":
                print_accuracy_lines(s[name])
    if "latency" in s:
        print("\n[latency] first result from a fresh process (1 member, 1 orbit)")
        for f in s["latency"]:
            where = "new cache folder" if f["new_cache_folder"] else "default cache folder"
            print(f"  {f['model']:<6} {f['run']:<10} ({where}): wall {f['wall_s']:6.2f} s  (import "
                  f"{f['import_s']:.2f} s, in process {f['in_process_s']:.2f} s)")
    if s.get("equal_accuracy"):
        print("\n[equal accuracy] informational: each method against the numba baseline at the "
              "same median final-state error (its rate interpolated between the measured "
              "tolerances); " + ("per core" if s["equal_accuracy"][0]["rate"] is not None
                                 and result["machine"]["arch"] in ("cpu", "x64", "arm64")
                                 else "wall rate against one core"))
        for e in s["equal_accuracy"]:
            if e["ratio"] is None:
                print(f"  planar {e['method']}, rtol {e['rtol']:.0e}: error "
                      f"{e['median_error']:.2e} outside the baseline's measured curve")
            else:
                print(f"  planar {e['method']}, rtol {e['rtol']:.0e}: error "
                      f"{e['median_error']:.2e}, {e['rate']:.0f} member-orbits/CPU-s; numba "
                      f"DOP853 at that error (rtol ~{e['numba_rtol_at_equal_error']:.1e}) "
                      f"{e['numba_rate_at_equal_error']:.0f} orbits/CPU-s: ratio "
                      f"{e['ratio']:.2f}")
    if result.get("skipped_methods"):
        print()
        for method, why in result["skipped_methods"].items():
            print(f"method {method} skipped: {why}")
    if result["targets"]:
        print("\n[targets]")
        for t in result["targets"]:
            ratio = f"  ({t['ratio']:.2f}x the target)" if "ratio" in t else ""
            print(f"  {'MET ' if t['met'] else 'MISS'}  {t['target']}: {t['value']:.4g}{ratio}")


def print_accuracy_lines(rows):
    """One "accuracy at equal rtol" line per (model, rtol): every method's median error and
    its ratio to Cash-Karp's."""
    for model in dict.fromkeys(r["model"] for r in rows):
        for rtol in dict.fromkeys(r["rtol"] for r in rows):
            group = [r for r in rows if (r["model"], r["rtol"]) == (model, rtol)]
            ck = [r["median_error"] for r in group if r["method"] == DEFAULT_METHOD]
            if not ck:
                continue                       # a tolerance of the baseline's curve only
            parts = []
            for r in group:
                ratio = f" ({r['median_error'] / ck[0]:.2g}x Cash-Karp)" if ck and ck[0] > 0 \
                    and r["method"] != DEFAULT_METHOD else ""
                parts.append(f"{r['method']} {r['median_error']:.2e}{ratio}")
            print(f"accuracy at equal rtol, {model}, rtol {rtol:.0e} (median final-state error): "
                  + "; ".join(parts))


def figure(result):
    import matplotlib.pyplot as plt

    s = result["sections"]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = {"planar": "-", "3d": "--"}
    for k, rtol in enumerate(result["parameters"]["rtols"]):
        color = f"C{k}"
        for model in result["parameters"]["models"]:
            for j, method in enumerate(result["parameters"]["methods"]):
                rows = [r for r in s.get("throughput", []) if r["rtol"] == rtol
                        and r["model"] == model and r["method"] == method]
                if rows:
                    ax.loglog([r["members"] for r in rows],
                              [r["member_orbits_per_s"] for r in rows], "os^v"[j % 4]
                              + styles[model], color=color,
                              label=f"{model}, {method}, rtol {rtol:.0e}")
        for b in s.get("numba", []):
            if b["rtol"] == rtol:
                ax.axhline(b["orbits_per_cpu_s"], color=color, ls=(0, (5, 2, 1, 2)), lw=1,
                           label=f"numba DOP853, 1 core, rtol {rtol:.0e}")
        for b in s.get("baseline", []):
            if b["rtol"] == rtol:
                ax.axhline(b["member_orbits_per_s"], color=color, ls=":", lw=1,
                           label=f"scipy DOP853, rtol {b['scipy_rtol']:.2g}")
    for model, ls in (("planar", "-."), ("3d", "--")):
        ax.axhline(TARGET_RATE[model], color="k", ls=ls, lw=0.8,
                   label=f"{model} target (N = 4096, rtol 1e-12)")
    ax.set_xlabel("members N")
    ax.set_ylabel("member-orbits per second")
    m = result["machine"]
    ax.set_title(f"{SYSTEM}, a/b = {ELONGATION}; {m['cpus_usable']}-CPU {m['arch']}, "
                 f"Taichi {m['taichi']}", fontsize=9)
    ax.legend(fontsize=6, ncol=2, loc="lower center", bbox_to_anchor=(0.5, 0.1), handlelength=3)
    split = s.get("split", [])
    labels = [f"{r['model']}\n{r['rtol']:.0e}" for r in split]
    bottom = np.zeros(len(split))
    for key, name in (("rhs_share_of_total", "RHS"), ("rest_share_of_total", "rest of advance"),
                      ("drain_fraction", "drain")):
        values = np.array([r[key] for r in split])
        bx.bar(labels, values, bottom=bottom, label=name)
        bottom += values
    bx.set_ylabel("share of wall time")
    bx.set_title(f"time split, N = {split[0]['members']}" if split else "time split (not run)",
                 fontsize=9)
    bx.legend(fontsize=7)
    return fig


def _extra(p):
    p.add_argument("--repeat", type=lambda text: max(1, int(text)), default=1,
                   help="time every run this many times, keep the best (default 1; raise it "
                        "on a shared or noisy machine)")
    p.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS),
                   help="sections to run (default: all)")
    p.add_argument("--members", type=int, nargs="+", default=None,
                   help="ensemble sizes N of the throughput section (default 1 16 256 1024 "
                        "4096 16384; e.g. add 65536 262144 on a GPU)")
    p.add_argument("--rtols", type=float, nargs="+", default=list(RTOLS),
                   help="tolerances (default 1e-10 1e-12 1e-15)")
    p.add_argument("--models", nargs="+", choices=MODELS, default=list(MODELS),
                   help="equations of motion (default: planar 3d)")
    p.add_argument("--methods", nargs="+", default=list(METHODS),
                   help="integration methods, Ensemble(method=...) (default: cash-karp dop853 "
                        "vern9; a method the installed package does not accept is skipped "
                        "with a note)")
    p.add_argument("--seconds", type=float, default=None,
                   help="target duration of each throughput point (default 2; --quick 0.05)")
    p.add_argument("--flops-per-cycle", type=float, default=FLOPS_PER_CYCLE,
                   help="f64 flops per cycle per core for the peak (default 16: AVX2 + FMA)")


def main():
    args, started = parse(__doc__.splitlines()[0], _extra)
    settings = dict(QUICK if args.quick else FULL)
    if args.members:
        settings["sizes"] = tuple(sorted(set(args.members)))
    if args.seconds:
        settings["seconds"] = args.seconds
    n_split = settings["split_members"]
    machine = machine_info()
    sections = [name for name in SECTIONS if name in args.sections]
    cpu = on_cpu()
    print(f"bench_throughput ({'quick' if args.quick else 'full'}; "
          f"{', '.join(sections)}): running ...", flush=True)
    points = Points(settings, args.repeat)
    skipped = {m: why for m in dict.fromkeys(args.methods) if (why := method_unavailable(m))}
    for method, why in skipped.items():
        print(f"  method {method} skipped: {why}", flush=True)
    methods = [m for m in dict.fromkeys(args.methods) if m not in skipped]
    s = {}
    if "throughput" in sections:
        s["throughput"] = bench_throughput(points, args.models, args.rtols, settings["sizes"],
                                           methods)
    if "split" in sections or "flops" in sections:
        s["rhs_only"] = {m: bench_rhs(points, m, n_split, settings["rhs_seconds"], args.repeat)
                         for m in args.models}
    if "split" in sections:
        s["split"] = time_split(points, s["rhs_only"], args.models, args.rtols, n_split)
    if "flops" in sections:
        s["flops"] = flop_rates(points, s["rhs_only"], args.models, args.rtols, n_split,
                                machine, args.flops_per_cycle)
    if "threads" in sections and cpu:
        s["threads"] = bench_threads(points, args.models, n_split, args.repeat)
    if "window" in sections:
        s["window"] = bench_window(points, n_split)
    if "baseline" in sections:
        s["baseline"] = bench_baseline(settings["baseline_members"], settings["baseline_orbits"],
                                       args.rtols)
    if "numba" in sections:
        curve = settings["numba_curve"] if "accuracy" in sections else ()
        s["numba"] = bench_numba(points, [r for r in args.rtols if r in NUMBA_RTOLS] or args.rtols,
                                 settings["numba_members"], settings["seconds"], args.repeat,
                                 settings["accuracy_orbits"], curve)
    if "accuracy" in sections:
        s["accuracy"] = bench_accuracy(args.models, methods, args.rtols,
                                       settings["accuracy_members"], settings["accuracy_orbits"],
                                       [b["rtol"] for b in s.get("numba", [])])
        s["equal_accuracy"] = equal_accuracy(points, s.get("numba", []), s["accuracy"], methods,
                                             n_split, cpu)
    if "latency" in sections:
        s["latency"] = bench_first_result(args.arch, args.repeat, settings["cold_latency"],
                                          args.models)
    if "compile" in sections:
        s["compile"] = bench_compile(args.arch, args.models, methods, args.repeat)
    parameters = {"system": SYSTEM, "elongation": ELONGATION, "theta_p_range": THETA_P_RANGE,
                  "thetadot_range": THETADOT_RANGE, "escape_distance": ESCAPE_DISTANCE,
                  "starts": "R2 sequence, plastic number", "rtols": args.rtols,
                  "models": args.models, "methods": methods, "sections": sections,
                  "repeat": args.repeat,
                  "flops_per_cycle": args.flops_per_cycle, "flops_per_rhs": FLOPS_PER_RHS,
                  "windows": WINDOWS, **settings}
    result = {"benchmark": "bench_throughput", "quick": bool(args.quick),
              "machine": {**machine, "load_average_1min_end": os.getloadavg()[0]},
              "parameters": parameters, "warmup_s": points.warmup_s, "sections": s,
              "skipped_methods": skipped,
              "targets": targets(points, s.get("baseline", []), s.get("latency", []),
                                 args.models, n_split)
              + targets13(points, s.get("numba", []), s.get("accuracy", []), args.models,
                          methods, n_split, machine["cpus_usable"], cpu)
              + targets13_compile(s.get("compile", []), s.get("latency", [])),
              "total_seconds": time.perf_counter() - started}
    print_report(result)
    path = os.path.join(args.out, "bench_throughput.json")
    with open(path, "w") as f:
        json.dump(result, f, indent=1)
    print(f"[bench_throughput] wrote {path}")
    rows = s.get("throughput", [])
    save(args, "bench_throughput", figure(result),
         {key: [r[key] for r in rows] for key in ("model", "method", "rtol", "members",
                                                  "member_orbits_per_s",
                                                  "member_orbits_per_cpu_s")},
         {"machine": result["machine"], **parameters},
         {t["target"]: t["value"] for t in result["targets"]}, started)


if __name__ == "__main__":
    main()
