"""Taichi runtime: one idempotent ``init`` for the whole package.

Nothing calls ``ti.init`` at import time. Every entry point that launches a kernel calls
:func:`ensure_init`, which initialises Taichi once with the package defaults (CPU, f64,
offline kernel cache). Call :func:`init` yourself first to pick another arch.

Decisions (docs/design.md, "Kernel design"):
* ``default_fp = f64`` and ``default_ip = i32`` always: tolerances down to 1e-15 must work.
* ``fast_math=False``: on CUDA fast math degrades f64 sqrt/division.
* ``unrolling_limit=0``: the kernels unroll loops over state components on purpose (34 for
  the perturbed 3-D state); Taichi's warning above 32 iterations would only alarm users.
* The environment variable ``TI_SPINORBIT_ARCH`` (``cpu``, ``cuda``, ``vulkan``, ...)
  overrides the arch of the lazy default and of ``init()`` called without an arch.
* ``cfg_optimization=False, opt_level=0``: Taichi's own control-flow-graph pass (store
  forwarding and dead-store elimination over the whole kernel) and its whole-kernel common
  subexpression elimination (``opt_level`` 0 turns off only that and the CFG pass; LLVM's
  optimisation level is not affected) were most of the cold compile of our large kernels
  (3-D DOP853 with indicators: 26 s -> 3.1 s; planar Cash-Karp 6.0 s -> 0.9 s). LLVM does
  the same work afterwards: run time is unchanged and results are bit for bit the same
  (docs/design.md "Taichi's CFG pass").
* Taichi 1.7's front end formats a source-position string for every AST node it visits,
  cached kernel or not; ``_taichi_frontend`` memoises it (a third of the warm start).
* ``TI_SKIP_VERSION_CHECK=ON`` is set before Taichi is imported (no network in CI).
* **Quiet console, library and command alike** (docs/design.md "Console"): Taichi prints
  nothing unless asked. Three sources, three remedies:

  - the "[Taichi] version ..." banner that ``import taichi`` prints on stdout:
    ``ENABLE_TAICHI_HEADER_PRINT=0`` is set when this module is imported, with the package
    and so before anything in it imports taichi (the kernels and :func:`init` import taichi
    on first use; a process that imported taichi itself first has seen its banner already);
  - the "[Taichi] Starting on arch=..." line: a plain ``print`` in ``ti.init`` (not the
    logger), so :func:`init` runs ``ti.init`` with stdout redirected (after ``import
    taichi``: Taichi decides at import whether stdout is "a graphical shell") and passes
    ``log_level=WARN``; what ti.init printed is replayed on stderr if it fails;
  - the "[shell.py:_shell_pop_print@23] Graphical python shell detected" line in Jupyter,
    IDLE or any process whose ``sys.stdout`` is not ``sys.__stdout__``: an *info* log line
    that ``taichi.lang.shell`` emits at import (Taichi then wraps printing so that ``print``
    inside kernels reaches the notebook; that behaviour is kept). Taichi's log level before
    ``ti.init`` can only be set by ``TI_LOG_LEVEL``, read at import, so ``TI_LOG_LEVEL=warn``
    is set with the banner's variable. :func:`init` removes both once Taichi is imported
    (child processes do not inherit them, and ``ti.init`` would otherwise warn that its
    ``log_level`` argument overrides ``TI_LOG_LEVEL``).

  All are defaults: a value already in the environment wins (``ENABLE_TAICHI_HEADER_PRINT``
  or ``TI_LOG_LEVEL`` set by the user are left alone, and a user's ``TI_LOG_LEVEL`` is then
  Taichi's log level: ``log_level`` is not passed). **Opt in** to Taichi's messages with
  ``TI_SPINORBIT_VERBOSE=1`` in the environment (banner, start line and info logs, library
  and command), or ``init(verbose=True)`` (the start line and info logs; the banner too if
  Taichi is not imported yet). Tests use the variable to see whether Taichi started
  (tests/test_robustness_accuracy.py).
"""

import atexit
import contextlib
import io
import os
import shutil
import sys
import tempfile

import platformdirs

from . import _taichi_frontend


#: Environment variable: a true value (1, true, yes, on) lets Taichi print its banner, its
#: "Starting on arch" line and its info logs.
VERBOSE_ENV = "TI_SPINORBIT_VERBOSE"
#: The environment variables this module set for the import of Taichi (removed later).
_QUIET_ENV = {"ENABLE_TAICHI_HEADER_PRINT": "0", "TI_LOG_LEVEL": "warn"}


def verbose_requested():
    """True when ``TI_SPINORBIT_VERBOSE`` asks for Taichi's own messages."""
    return os.environ.get(VERBOSE_ENV, "").strip().lower() in ("1", "true", "yes", "on")


def _quiet_import_of_taichi():
    """Set the variables that silence ``import taichi`` unless the user set them, asked for
    Taichi's messages, or Taichi is already imported; remember which ones were set here."""
    set_here = {}
    if not verbose_requested() and "taichi" not in sys.modules:
        for key, value in _QUIET_ENV.items():
            if key not in os.environ:
                os.environ[key] = set_here[key] = value
    return set_here


def _unset_quiet_env(*keys):
    """Remove variables set by :func:`_quiet_import_of_taichi` (if nobody changed them)."""
    for key in keys:
        value = _SET_HERE.pop(key, None)
        if value is not None and os.environ.get(key) == value:
            del os.environ[key]


os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
_SET_HERE = _quiet_import_of_taichi()

_STATE = {"arch": None}
ARCH_ENV = "TI_SPINORBIT_ARCH"
#: Offline-cache folder under the user cache folder's taichi/ (bump when kernel settings
#: change); see :func:`cache_folder`.
CACHE_SUBDIR = "ti_spinorbit-2"
CACHE_ENV = "TI_OFFLINE_CACHE_FILE_PATH"
_KNOWN_ARCHS = ("cpu", "x64", "arm64", "cuda", "vulkan", "metal", "opengl", "gpu")


def init(arch=None, *, offline_cache=True, debug=False, cpu_max_num_threads=None,
         verbose=None):
    """Initialise Taichi for ti_spinorbit (idempotent).

    Parameters
    ----------
    arch : str, optional
        ``"cpu"`` (default), ``"cuda"``, ``"vulkan"``, ... ; ``TI_SPINORBIT_ARCH`` overrides
        the default. Asking for a GPU arch that is not available raises RuntimeError instead
        of silently falling back to the CPU.
    offline_cache : bool
        Keep compiled kernels on disk (:func:`cache_folder`: the user cache folder's
        ``taichi/ti_spinorbit-2``, ``~/.cache/taichi/ti_spinorbit-2`` on Linux, unless
        ``TI_OFFLINE_CACHE_FILE_PATH`` is set), so a fresh process starts in seconds. When
        that folder cannot be created or written (a read-only HOME), kernels are compiled
        in memory instead, with a one-line notice on stderr.
    cpu_max_num_threads : int, optional
        Threads for the CPU backend (default: all cores).
    verbose : bool, optional
        True shows Taichi's own "[Taichi] Starting on arch=..." line and info logs (and its
        banner if Taichi is not imported yet); default: ``TI_SPINORBIT_VERBOSE`` in the
        environment, else quiet. Taichi's warnings and errors are shown either way.

    Returns the arch name in use. Calling again with the same arch is a no-op; calling with
    a different arch re-initialises Taichi, which invalidates existing ensembles.

    Examples
    --------
    >>> tso.init()               # the CPU, the default; a no-op when already started there
    'cpu'
    """
    name = arch if arch is not None else (os.environ.get(ARCH_ENV) or "cpu")
    if not isinstance(name, str) or name.lower() not in _KNOWN_ARCHS:
        label = "arch" if arch is not None else f"the environment variable {ARCH_ENV}"
        raise ValueError(f"{label} must be one of {', '.join(_KNOWN_ARCHS)} (got {name!r})")
    name = name.lower()
    verbose = verbose_requested() if verbose is None else bool(verbose)
    if verbose and "taichi" not in sys.modules:
        _unset_quiet_env("ENABLE_TAICHI_HEADER_PRINT", "TI_LOG_LEVEL")   # the banner too

    import taichi as ti      # Taichi: imported on first use, the package import stays quiet

    # Taichi has read both at import: not inherited by child processes, and ti.init would
    # warn that its log_level argument overrides TI_LOG_LEVEL
    _unset_quiet_env("ENABLE_TAICHI_HEADER_PRINT", "TI_LOG_LEVEL")

    if _STATE["arch"] == name:
        return name
    _taichi_frontend.install()   # warm start: Taichi re-traces every kernel, even cached ones
    ti_arch = {"cpu": ti.cpu, "x64": ti.x64, "arm64": ti.arm64, "cuda": ti.cuda,
               "vulkan": ti.vulkan, "metal": ti.metal, "opengl": ti.opengl, "gpu": ti.gpu}[name]
    kwargs = dict(arch=ti_arch, default_fp=ti.f64, default_ip=ti.i32, offline_cache=offline_cache,
                  fast_math=False, debug=debug, log_level=ti.INFO if verbose else ti.WARN,
                  enable_fallback=False, unrolling_limit=0, cfg_optimization=False, opt_level=0)
    if os.environ.get("TI_LOG_LEVEL"):
        del kwargs["log_level"]          # the user's own Taichi log level (set before import)
    if cpu_max_num_threads:
        kwargs["cpu_max_num_threads"] = int(cpu_max_num_threads)
    if name in ("cpu", "x64", "arm64"):
        # One member per scheduler task: Taichi's default CPU loop lowering ran ensembles of
        # up to ~512 members on ONE thread (N = 16 or 256: 14 600 member-orbits/s on 2 cores,
        # 26 800-28 100 with this setting; N = 4096 unchanged). Members cost milliseconds, so
        # per-member scheduling costs nothing.
        kwargs.update(make_cpu_multithreading_loop=False, cpu_block_dim_adaptive=False,
                      default_cpu_block_dim=1)
    # Taichi's cache key ignores the loop settings above, so kernels compiled with other
    # settings (another program, an older version of this package) must not be reused: our
    # own folder unless TI_OFFLINE_CACHE_FILE_PATH names one (Taichi reads it). Checked even
    # with offline_cache=False: Taichi touches its cache path at exit either way.
    folder = cache_folder()
    problem = _unwritable(folder)
    if problem is None:
        if offline_cache and not os.environ.get(CACHE_ENV):
            kwargs["offline_cache_file_path"] = folder
    else:
        # Taichi crashes at exit (SIGSEGV, status 139) when its cache folder cannot be
        # written, even with offline_cache=False: compile in memory, with a temporary
        # folder (removed at exit) as the path Taichi touches
        kwargs["offline_cache"] = False
        kwargs["offline_cache_file_path"] = _temporary_cache()
        print(f"ti_spinorbit: kernel cache folder {folder} is not writable ({problem}); "
              f"compiling without a disk cache (set {CACHE_ENV} to a writable folder)",
              file=sys.stderr)
    if _STATE["arch"] is not None:
        ti.reset()
    saved = None
    if kwargs.get("offline_cache_file_path") and \
            kwargs["offline_cache_file_path"] == _STATE.get("temporary_cache"):
        saved = os.environ.pop(CACHE_ENV, None)   # unwritable; Taichi would warn about it
    printed = io.StringIO()
    try:
        # ti.init prints "[Taichi] Starting on arch=..." with a plain print: hidden unless
        # verbose (Taichi's warnings go through its logger, to the process's stderr)
        with contextlib.nullcontext() if verbose else contextlib.redirect_stdout(printed):
            ti.init(**kwargs)
    except Exception as exc:  # Taichi raises a bare RuntimeError with little context
        _STATE["arch"] = None
        sys.stderr.write(printed.getvalue())
        raise RuntimeError(f"Taichi could not start on arch {name!r}: {exc}") from exc
    finally:
        if saved is not None:
            os.environ[CACHE_ENV] = saved
    _STATE["arch"] = name
    _STATE["generation"] = _STATE.get("generation", 0) + 1
    _STATE["disk_cache"] = bool(kwargs["offline_cache"])
    return name


def cache_folder():
    """Folder of the offline kernel cache: ``TI_OFFLINE_CACHE_FILE_PATH`` when set, else
    ``<user cache dir>/taichi/ti_spinorbit-2`` (``platformdirs.user_cache_dir``:
    ``~/.cache/taichi/ti_spinorbit-2`` on Linux, honouring ``XDG_CACHE_HOME``)."""
    path = os.environ.get(CACHE_ENV)
    if path:
        return path
    return os.path.join(platformdirs.user_cache_dir("taichi", appauthor=False), CACHE_SUBDIR)


def _unwritable(folder):
    """None when ``folder`` exists or can be created and a file can be written in it, else
    the reason (a real write probe: permission bits say nothing to root or on read-only
    mounts)."""
    try:
        os.makedirs(folder, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder) as f:
            f.write(b"probe")
    except OSError as exc:
        return exc.strerror or type(exc).__name__
    return None


def _temporary_cache():
    """A private temporary folder for Taichi's cache path, created once per process and
    removed at exit after Taichi has shut down (``ti.reset`` first: Taichi's own exit hook
    would otherwise recreate it)."""
    if _STATE.get("temporary_cache") is None:
        try:
            folder = tempfile.mkdtemp(prefix="ti_spinorbit-cache-")
        except OSError:
            return None

        def cleanup():
            if _STATE["arch"] is not None:
                import taichi as ti      # Taichi: already imported (an arch is set)
                ti.reset()
                _STATE["arch"] = None
            shutil.rmtree(folder, ignore_errors=True)

        atexit.register(cleanup)
        _STATE["temporary_cache"] = folder
    return _STATE["temporary_cache"]


def ensure_init():
    """Initialise with the defaults if nobody has called :func:`init` yet."""
    if _STATE["arch"] is None:
        init()
    return _STATE["arch"]


def current_arch():
    """The arch Taichi was initialised with, or None."""
    return _STATE["arch"]


def disk_cache():
    """True when compiled kernels are kept in the offline cache on disk (so a variant compiled
    by an earlier process is only loaded; ``ti_spinorbit.engine.compiling``)."""
    return bool(_STATE.get("disk_cache"))


def generation():
    """Increments at every (re-)initialisation; owners of fields use it to notice a reset."""
    return _STATE.get("generation", 0)
