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
* In the ``ti-spinorbit`` command only, ``ENABLE_TAICHI_HEADER_PRINT=0`` is set too: ``import
  taichi`` prints a "[Taichi] version ..." line on stdout, and the command's stdout is its
  own (``--quiet`` prints nothing). Library users still see the banner. Both are defaults
  (``setdefault``): a value already in the environment wins. This module is imported before
  anything in the package imports taichi (``ti_spinorbit/__init__.py``).
"""

import atexit
import os
import shutil
import sys
import tempfile

import platformdirs

from . import _taichi_frontend


def _is_command_line():
    """True when this process is the ti-spinorbit command: the console script, or
    ``python -m ti_spinorbit`` (while runpy imports the package, sys.argv[0] is "-m" and the
    module name is in sys.orig_argv)."""
    argv0 = sys.argv[0] if sys.argv else ""
    if os.path.splitext(os.path.basename(argv0))[0] in ("ti-spinorbit", "ti-spinorbit-script"):
        return True
    if argv0 != "-m":
        return False
    orig = getattr(sys, "orig_argv", [])
    for k, token in enumerate(orig[1:], 1):
        if token == "-m":
            return orig[k + 1:k + 2] == ["ti_spinorbit"]
        if token.startswith("-m"):
            return token[2:] == "ti_spinorbit"
    return False


os.environ.setdefault("TI_SKIP_VERSION_CHECK", "ON")
if _is_command_line():
    os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "0")

_STATE = {"arch": None}
ARCH_ENV = "TI_SPINORBIT_ARCH"
#: Offline-cache folder under the user cache folder's taichi/ (bump when kernel settings
#: change); see :func:`cache_folder`.
CACHE_SUBDIR = "ti_spinorbit-2"
CACHE_ENV = "TI_OFFLINE_CACHE_FILE_PATH"
_KNOWN_ARCHS = ("cpu", "x64", "arm64", "cuda", "vulkan", "metal", "opengl", "gpu")


def init(arch=None, *, offline_cache=True, debug=False, cpu_max_num_threads=None):
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

    Returns the arch name in use. Calling again with the same arch is a no-op; calling with
    a different arch re-initialises Taichi, which invalidates existing ensembles.
    """
    name = arch if arch is not None else (os.environ.get(ARCH_ENV) or "cpu")
    if not isinstance(name, str) or name.lower() not in _KNOWN_ARCHS:
        label = "arch" if arch is not None else f"the environment variable {ARCH_ENV}"
        raise ValueError(f"{label} must be one of {', '.join(_KNOWN_ARCHS)} (got {name!r})")
    name = name.lower()

    import taichi as ti      # Taichi: imported on first use, the package import stays quiet

    if _STATE["arch"] == name:
        return name
    _taichi_frontend.install()   # warm start: Taichi re-traces every kernel, even cached ones
    ti_arch = {"cpu": ti.cpu, "x64": ti.x64, "arm64": ti.arm64, "cuda": ti.cuda,
               "vulkan": ti.vulkan, "metal": ti.metal, "opengl": ti.opengl, "gpu": ti.gpu}[name]
    kwargs = dict(arch=ti_arch, default_fp=ti.f64, default_ip=ti.i32, offline_cache=offline_cache,
                  fast_math=False, debug=debug, log_level=ti.WARN, enable_fallback=False,
                  unrolling_limit=0, cfg_optimization=False, opt_level=0)
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
    try:
        ti.init(**kwargs)
    except Exception as exc:  # Taichi raises a bare RuntimeError with little context
        _STATE["arch"] = None
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
