"""Kernel compile time: done before the clock starts, announced, measured, and ahead of time.

Taichi compiles a kernel variant (model × indicators × sampling × potential order × odd
terms × method: template arguments) on its first launch in a process, and keeps it in its
offline cache on disk (``runtime.cache_folder()``), so a later process only loads it. A cold
compile takes seconds (planar) to a minute (3-D) on 2 cores; a load well under a second.

What happens at the first use of a variant in a process (:class:`FirstUse`, wrapped
around ``advance`` and the run's first right-hand-side and diagnostics calls by
``Ensemble.run``):

1. The variant is compiled by a **compile-only launch**: the same kernel with one-member
   copies of every per-member array and that member's status "done", so nothing is
   integrated and nothing of the run is touched; the results are bit-identical with or
   without it (the real first window then runs on the compiled kernel).
2. If the disk cache does not hold it (see below), the active progress reporter
   (:mod:`ti_spinorbit.engine.progress`) announces ``compiling kernels for <variant> (first use
   only, about N s)`` before it starts. N is the last cold compile of this variant measured on
   this machine (stored in ``compile_seconds.json`` in the cache folder), else
   ``DEFAULT_COMPILE_SECONDS`` (documented 2-core figures).
3. The whole first use (the other kernels' compile included) is kept out of ``RunOutput.seconds`` (so out of every result's ``seconds``
   and member-orbits/s), out of the window-length adaptation, and out of the bar's elapsed
   time and ETA (``Progress.compiled`` shifts the bar's clock).

Whether the disk cache holds a variant: ``compile_seconds.json`` records, per variant, a
fingerprint (the kernel sources, Taichi version, arch) of the last compile made with the disk
cache on. Same fingerprint: it is a load, not announced (Taichi may still evict old entries:
then a compile happens unannounced, and is measured and recorded as usual).

:func:`ti_spinorbit.studies.warmup.warmup` (CLI ``ti-spinorbit warmup``) compiles chosen variants ahead of time by
running each on one member for a hundredth of an orbit.
"""

import contextlib
import hashlib
import json
import logging
import os
import time
from dataclasses import dataclass

import numpy as np

from ..model import models as _models
from . import progress
from .. import runtime
from ..kernels import tableau as _tableau
from ..layout import DONE, multipole as _multipole_layout

_HAND_WRITTEN_MAX = _multipole_layout.HAND_WRITTEN_MAX

_LOG = logging.getLogger("ti_spinorbit")

#: Seconds a cold compile of a variant takes when nothing was measured on this machine yet
#: (2-core CPU, Taichi 1.7.4 with the settings of runtime.py, fresh process, integrator and
#: diagnostics kernels: planar 0.65-0.82 s, 3-D 1.0-1.16 s); the shadow trajectory
#: (indicators) adds about 10-25 %, dense sampling little. Estimates under ANNOUNCE_MIN_S are
#: not announced (the planar default, rounded up to 1 s, just is).
DEFAULT_COMPILE_SECONDS = {"planar": 1.0, "3d": 1.2}
INDICATORS_FACTOR = 1.2
SAMPLING_FACTOR = 1.0
#: Announce only compiles expected to take at least this long (seconds).
ANNOUNCE_MIN_S = 1.0
#: The measurements, in the kernel cache folder (runtime.cache_folder()).
RECORD_FILE = "compile_seconds.json"
#: The methods and models, from their one registry each (kernels.tableau.METHODS, pure
#: Python: importing it loads no Taichi; models.MODELS).
METHODS = tuple(_tableau.METHODS)
MODELS = tuple(_models.MODELS)

_SEEN = set()              # (runtime generation, arch, variant) compiled in this process
_TOTAL = [0.0]             # compile seconds spent in this process
_HOW = {}                  # variant -> how its last first use went ("compiled", "loaded")


@dataclass(frozen=True)
class KernelVariant:
    """One compiled variant of the window kernel: its Taichi template arguments. ``name``
    is its text (the key of the measurements file), ``describe()`` its words in the
    compile announcement, ``default_seconds`` the cold-compile estimate before anything was
    measured on this machine."""

    model: str                       # "planar" or "3d" (MODELS)
    indicators: bool = False         # the shadow trajectory (MEGNO, Lyapunov)
    sampling: bool = False           # dense samples (time series) besides the crossings
    order: int = 4                   # truncation order of the mutual potential
    odd: bool = False                # odd-degree inertia integrals present
    method: str = "cash-karp"        # Runge-Kutta pair (METHODS)
    perturbed: bool = False          # tides, YORP or BYORP in the equations
    controller: object = None        # a step-size policy other than the default, or None

    @property
    def name(self) -> str:
        """``planar/indicators/sections/order4/cash-karp`` (``.../perturbed/cash-karp`` with
        tides, YORP or BYORP; ``.../orderN/...`` for every order above 4)."""
        # every order above 4 is one compiled variant (the table-driven potential: the
        # tables, which are data, carry the order and the odd terms)
        order_n = int(self.order) > _HAND_WRITTEN_MAX
        parts = [self.model, "indicators" if self.indicators else "plain",
                 "sampling" if self.sampling else "sections",
                 "orderN" if order_n else f"order{int(self.order)}"]
        if self.odd and not order_n:
            parts.append("odd")
        if self.perturbed:
            parts.append("perturbed")
        if self.controller is not None:     # its own kernels: its own compile record
            parts.append("controller-" + hashlib.sha256(repr(self.controller).encode())
                         .hexdigest()[:8])
        return "/".join(parts + [self.method])

    def describe(self) -> str:
        """"the planar model with chaos indicators (dop853)", ..."""
        what = [f"the {'3-D' if self.model == '3d' else self.model} model"]
        if self.indicators:
            what.append("with chaos indicators")
        if self.sampling:
            what.append("with dense sampling")
        if self.perturbed:
            what.append("with perturbations")
        if self.method != "cash-karp":
            what.append(f"({self.method})")
        return " ".join(what)

    @property
    def default_seconds(self) -> float:
        """``DEFAULT_COMPILE_SECONDS`` of the model, scaled for indicators and sampling."""
        seconds = DEFAULT_COMPILE_SECONDS.get(self.model, max(DEFAULT_COMPILE_SECONDS.values()))
        if self.indicators:
            seconds *= INDICATORS_FACTOR
        if self.sampling:
            seconds *= SAMPLING_FACTOR
        return seconds


def record_path():
    """The measurements file in the kernel cache folder."""
    return os.path.join(runtime.cache_folder(), RECORD_FILE)


def read_records():
    """{variant: {"seconds": last cold compile, "fingerprint": ..., "loaded_seconds": ...}};
    empty when missing or unreadable (a damaged file is only a lost estimate)."""
    try:
        with open(record_path()) as f:
            data = json.load(f)
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def _write_records(records):
    """Atomic replace; failures are ignored (a read-only cache only loses the estimate)."""
    path = record_path()
    tmp = f"{path}.tmp-{os.getpid()}"
    try:
        with open(tmp, "w") as f:
            json.dump(records, f, indent=1, sort_keys=True)
        os.replace(tmp, path)
    except OSError:
        try:
            os.remove(tmp)
        except OSError:
            pass


def fingerprint(variant: KernelVariant):
    """Digest of what Taichi's cache key depends on for us: the kernel sources, the Taichi
    version, the arch and the variant."""
    from .. import kernels    # kernels/: on first use (the quiet import loads no kernel module)

    h = hashlib.sha256(variant.name.encode())
    folder = list(kernels.__path__)[0]
    for name in sorted(os.listdir(folder)):
        if name.endswith(".py"):
            with open(os.path.join(folder, name), "rb") as f:
                h.update(name.encode() + f.read())
    try:
        import taichi         # Taichi: imported on first use, the package import stays quiet

        h.update(str(taichi.__version__).encode())
    except ImportError:  # pragma: no cover - taichi is a dependency
        pass
    h.update(str(runtime.current_arch()).encode())
    return h.hexdigest()


def compiled_seconds():
    """Compile seconds spent in this process so far (for callers that time whole studies)."""
    return _TOTAL[0]


class Stopwatch:
    """Wall time since creation minus the compile time spent meanwhile (seconds of a study
    that runs several integrations: chaos maps, scans, the libration search)."""

    def __init__(self, already=0.0):
        self.start = time.perf_counter() - float(already)
        self._compiled = _TOTAL[0]

    def seconds(self):
        return time.perf_counter() - self.start - (_TOTAL[0] - self._compiled)


def _clock():
    return time.perf_counter()


def _launch(kernel, args):
    """The compile-only launch (a function of its own so that tests can stand in for it)."""
    kernel(*args)


def _one_member(args, n, status):
    """Arguments of a compile-only launch: one-member copies of every per-member array (first
    dimension ``n``), the status "done" (the kernel skips the member); the rest as given."""
    out = []
    for a in args:
        if a is status:
            out.append(np.full(1, DONE, dtype=status.dtype))
        elif isinstance(a, np.ndarray) and a.ndim >= 1 and a.shape[0] == n:
            out.append(np.ascontiguousarray(a[:1]).copy())
        else:
            out.append(a)
    return out


class FirstUse:
    """``kernel`` (the integrator kernel, ``advance``) wrapped so that the first use of
    ``variant`` in this process is announced, compiled by a compile-only launch before the
    real one, and timed. ``other_kernels()`` wraps the run's first calls of the other kernels
    (diagnostics), whose first use also compiles (or loads) them: their time
    counts as compile time too. ``status`` is the members' status array, or a function
    returning it (the array the launch will be given). ``take_seconds()`` returns (and resets) the integrator
    kernel's compile time, which the caller keeps out of its own clock."""

    def __init__(self, kernel, variant, status):
        self.kernel = kernel
        self.variant = variant
        self.status = status
        self.key = (runtime.generation(), runtime.current_arch(), variant.name)
        self.first = self.key not in _SEEN
        self.seconds = 0.0          # integrator kernel compile, not yet taken
        self.how = "ready"          # "compiled", "loaded" (disk cache) or "ready" (in process)
        self._other = 0.0           # the other kernels' first use
        self._begun = False
        self._cached = False
        self._report = None

    def _begin(self):
        """Announce the compile (once) unless the disk cache holds the variant."""
        if self._begun:
            return
        self._begun = True
        rec = read_records().get(self.variant.name) or {}
        self._fp = fingerprint(self.variant)
        self._cached = runtime.disk_cache() and rec.get("fingerprint") == self._fp
        self._report = progress.active()
        if self._cached:
            return
        estimate = rec.get("seconds") or self.variant.default_seconds
        if estimate >= ANNOUNCE_MIN_S:
            text = (f"compiling kernels for {self.variant.describe()} (first use only, about "
                    f"{estimate:.0f} s)")
            _LOG.info(text)
            if self._report is not None:
                self._report.compiling(text)

    @contextlib.contextmanager
    def other_kernels(self):
        if not self.first or self.key in _SEEN:
            yield
            return
        self._begin()
        started = _clock()
        try:
            yield
        finally:
            seconds = _clock() - started
            self._other += seconds
            _TOTAL[0] += seconds

    def __call__(self, *args):
        status = self.status() if callable(self.status) else self.status
        if self.first and self.key not in _SEEN and len(status):
            self._begin()
            started = _clock()
            _launch(self.kernel, _one_member(args, len(status), status))
            seconds = _clock() - started
            _SEEN.add(self.key)
            _TOTAL[0] += seconds
            self.seconds += seconds
            self.how = "loaded" if self._cached else "compiled"
            _HOW[self.variant.name] = self.how
            total = seconds + self._other
            self._record(total)
            _LOG.info("kernels for %s %s in %.2f s", self.variant.describe(), self.how, total)
            if self._report is not None:
                self._report.compiled(total)
        return self.kernel(*args)

    def _record(self, total):
        """Store the measurement (the whole first use: what a user waits for)."""
        records = read_records()
        rec = dict(records.get(self.variant.name) or {})
        rec["loaded_seconds" if self._cached else "seconds"] = round(total, 3)
        if runtime.disk_cache():
            rec["fingerprint"] = self._fp
        else:
            rec.pop("fingerprint", None)
        if rec != records.get(self.variant.name):
            records[self.variant.name] = rec
            _write_records(records)

    def take_seconds(self):
        seconds, self.seconds = self.seconds, 0.0
        return seconds


# ---- ahead of time ----------------------------------------------------------------------
