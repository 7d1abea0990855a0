"""Ahead-of-time compilation: :func:`warmup` compiles the kernel variants a session will use,
so that later runs (in any process, through Taichi's disk cache) start without the compile
wait. It sits above the ensemble and the entry points it runs; the first-use bookkeeping it
reports on lives in :mod:`ti_spinorbit.engine.compiling`, below them.
"""

import itertools
import sys
import time

import numpy as np

from .. import runtime
from .._validate import require_order
from ..engine import compiling
from ..engine.compiling import KernelVariant, METHODS, MODELS
from ..engine.ensemble import Ensemble
from ..engine.members import Members
from ..model.perturbations import Tides
from ..system import catalog


def _choices(name, values, allowed):
    values = [values] if isinstance(values, (str, bool)) else list(values)
    bad = [v for v in values if v not in allowed]
    if bad or not values:
        raise ValueError(f"{name} must be a non-empty selection of {', '.join(map(repr, allowed))} "
                         f"(got {values!r})")
    return list(dict.fromkeys(values))


def warmup(models=MODELS, indicators=(False, True), sampling=(False, True), methods=("cash-karp",),
           order=4, verbose=True, stream=None, perturbed=(False,)):
    """Compile kernel variants ahead of time, so that later runs (in this process, and in
    later processes through the disk cache) start without waiting.

    Each variant is run once on one member of 1991 VH for 0.01 orbit (which also compiles
    the diagnostics kernel it uses; the integrator evaluates its own first stage).

    Parameters
    ----------
    models : sequence of {"planar", "3d"}
        Equations of motion (default both).
    indicators : sequence of bool
        Without and/or with the chaos-indicator shadow (``chaos_map``, ``overlap_threshold``).
    sampling : sequence of bool
        Without (sections) and/or with dense sampling (``time_series``, libration).
    methods : sequence of str
        Integration methods among ``METHODS`` ("cash-karp", "dop853", "vern9"); default the default
        method only (each method is a separate set of compiles).
    perturbed : sequence of bool
        Without and/or with tides, YORP and BYORP in the equations (``perturbations=``,
        docs/physics.md §13; a separate kernel set). Default without only; ``(False, True)``
        compiles both (``ti-spinorbit warmup --perturbed``).
    order : int
        Potential order of the variants (default 4, every entry point's default): 0 or
        2..16; every order above 4 is one variant (the table-driven potential).
    verbose : bool
        Print one line per variant (what, how, seconds) on ``stream`` (default stdout).

    Returns
    -------
    list of dict
        One per variant: ``variant``, ``how`` ("compiled", "loaded" from the disk cache, or
        "ready" already in this process), ``kernel_seconds`` (the compile or load of the
        kernels this variant uses first: integrator, and diagnostics when not used before) and ``seconds`` (the whole first run).

    Examples
    --------
    Compile (or load from the cache) the planar kernel without indicators or sampling:

    >>> _ = tso.warmup(models=("planar",), indicators=(False,), sampling=(False,), verbose=False)
    """

    models = _choices("models", models, MODELS)
    indicators = _choices("indicators", indicators, (False, True))
    sampling = _choices("sampling", sampling, (False, True))
    methods = _choices("methods", methods, METHODS)
    perturbed = _choices("perturbed", perturbed, (False, True))
    order = require_order(order)
    out = sys.stdout if stream is None else stream
    runtime.ensure_init()
    system = catalog.system("1991 VH")
    table = Members.from_starts(system, 0.0, 1.0, order=order,
                                perturbations=[Tides(k2=1e-5, time_lag=600.0)])  # any block
    par, y0, rows = table.par, table.y0, table.perturbation_rows
    done = []
    for method, model, ind, samp, pert in itertools.product(methods, models, indicators,
                                                            sampling, perturbed):
        started = time.perf_counter()
        kw = {} if method == "cash-karp" else {"method": method}
        if pert:
            kw["perturbation_rows"] = rows
        ens = Ensemble(par, y0, order=order, model=model, multipole_rows=table.multipole_rows,
                       degrees=table.degrees, **kw)
        before = len(compiling._SEEN), compiling._TOTAL[0]
        ens.run(2.0 * np.pi * 0.01, sample_dt=2.0 * np.pi / 64 if samp else None,
                indicators=ind)
        variant = KernelVariant(model, ind, samp, order, ens.odd, method, pert).name
        seconds = time.perf_counter() - started
        kernel = compiling._TOTAL[0] - before[1]
        how = "ready" if len(compiling._SEEN) == before[0] else compiling._HOW.get(variant, "compiled")
        done.append({"variant": variant, "how": how, "kernel_seconds": kernel,
                     "seconds": seconds})
        if verbose:
            word = {"compiled": "compiled", "loaded": "loaded from the disk cache",
                    "ready": "already compiled in this process"}[how]
            print(f"{variant}: {word} in {kernel:.2f} s (first run {seconds:.2f} s in all)",
                  file=out)
    return done
