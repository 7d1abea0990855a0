"""Memory a run will need, estimated from its sizes alone, before any work.

One model serves the early checks of every entry point (``surface_of_section``,
``time_series``, ``chaos_map``, ``parameter_map``, ``overlap_threshold``,
``relaxed_libration``, the command line) and :meth:`Ensemble.run`, so a run that is admitted
early is admitted again by the ensemble, and an absurd request (a 4000 x 4000 map, 10^7
orbits) is refused in milliseconds instead of after minutes of building members.

The peak is not the integration: it comes after it, when the records are turned into
observables. At that moment these are alive together, per recorded row (a crossing or a
sample; 8-byte floats):

* the run's 3-D records (31) and their flat concatenation (31), the per-row parameter rows
  of ``observables.derive`` (``par[member]``, NPAR = 73) or, for a time series, the
  contiguous state copy handed to the diagnostics kernel (30) and its output (14);
* the padded (N, max count) observables (5-17 columns) and ``derive``'s temporaries;
* the kernels' own record chunks (11 or 31 per row), freed just before but kept by the
  allocator (RSS does not shrink).

Counting those arrays gives about 150 floats per row; measured peak RSS growth
(``experiments/memory_estimate.py``) is 1 200-1 300 bytes per row for both sections and time
series, planar and 3-D, which is what :data:`ROW_BYTES` uses. A member costs
:data:`MEMBER_BYTES` on top (its parameter row, result arrays, Python lists and one small
array per window with records). With many members and few orbits the integration itself can
be the peak (window buffers of ``window_orbits + 4`` rows per member): the estimate is the
larger of the two phases.

A time series with ``states=True`` keeps 30 SI numbers per sample more. They are made after
the observables, when ``derive``'s temporaries are gone: alive then are the records (31), the
derived and result columns (about 35) and the state rows, per member and stacked (2 x 30),
which is :data:`STATES_ROW_BYTES` (measured 1 010 bytes per row), plus the scaled copy and
temporaries of the member being converted (:data:`STATES_MEMBER_ROW_BYTES` per row of the
largest member). That third phase stays below the observables' peak (measured: the peak RSS
of a states=True series is that of the same series without states), so the states are not
counted as a second set of rows of ``ROW_BYTES`` each (that was 2.1 x the measured peak).

The memory available is read by :func:`ti_spinorbit._validate.available_memory`, the one
place every check asks. Decision: psutil (``psutil.virtual_memory().available``) when it is
installed, since it is the well-kept standard helper and says it right on every platform
(on macOS free pages alone understate what can be had; on Windows neither /proc nor
``sysconf`` exists, so no check would be made); without psutil the package's own reading
stays (``MemAvailable`` of /proc/meminfo on Linux, where it is the same number psutil gives,
else free pages × page size, else no check). psutil is not a dependency: the fallback covers
Linux, where long runs are made, exactly, and one compiled package fewer keeps installs light;
the test extra carries it, and a test checks the two readings agree.
"""

import math

import numpy as np

from .. import layout as _layout
from ..model import planar
from .._validate import GIB, require_memory
from ..model.perturbations import NACC
from ..system.systems import BinarySystem

#: Peak bytes per recorded row (crossing or sample), measured: see the module docstring.
ROW_BYTES = 1300.0
#: Pericentre crossings per initial orbit (coupling changes the mean motion a little: 1.013
#: measured for 1991 VH).
CROSSINGS_PER_ORBIT = 1.0
#: Bytes per member besides its records at the peak: parameter rows, states, result
#: arrays, labels and Python objects (measured: a 128 x 128 map of 10 orbits).
MEMBER_BYTES = 2500.0
#: Bytes per member alive only during the integration: kernel states, RHS, shadow, errors
#: (about ten NSTATE-wide rows).
RUN_MEMBER_BYTES = 2500.0
#: Bytes per member and window that produced records (one small array and a list slot).
CHUNK_BYTES = 160.0
#: Window buffer rows per member besides the window's own records (ensemble.Ensemble.run).
BUFFER_SLACK = 4
#: Bytes per sample row alive while a time series' ``states`` are built (module docstring;
#: measured 1 010 with tracemalloc for planar and 3-D runs).
STATES_ROW_BYTES = 1010.0
#: Bytes per row of the member whose state rows are being converted, on top (measured 170).
STATES_MEMBER_ROW_BYTES = 170.0


def record_rows(orbits, samples_per_orbit=None):
    """Rows one member records over ``orbits`` orbits: crossings, plus samples (the initial
    state is the first) when ``samples_per_orbit`` is given. Scalars or arrays."""
    orbits = np.asarray(orbits, dtype=np.float64)
    rows = np.ceil(CROSSINGS_PER_ORBIT * orbits)       # the start is not a crossing
    if samples_per_orbit is not None:
        rows = rows + np.ceil(orbits * samples_per_orbit) + 1
    return rows


def estimate_bytes(members, orbits, samples_per_orbit=None, window_orbits=16, width=31,
                   states=False):
    """Peak memory, bytes, of an entry point integrating ``members`` members for ``orbits``
    initial orbits each (a scalar, or an array with one value per member), with
    ``samples_per_orbit`` dense samples per orbit (a time series) or none (a section): its
    records, the observables derived from them and the per-member state; ``states``: a time
    series that also keeps the SI state at every sample (``time_series(states=True)``).

    Counts only, no arrays of that size are made, so absurd requests cost nothing."""
    members = float(members)
    orbits = np.broadcast_to(np.asarray(orbits, dtype=np.float64), (int(members),)) \
        if np.ndim(orbits) else np.asarray(float(orbits))
    rows = record_rows(orbits, samples_per_orbit)
    total_rows = float(np.sum(rows)) if np.ndim(rows) else float(rows) * members
    mean_orbits = float(np.mean(orbits))
    windows = math.ceil(mean_orbits / max(window_orbits, 1))
    per_window = 1 + (samples_per_orbit is not None)        # chunk arrays per window
    chunks = CHUNK_BYTES * windows * per_window * members
    # after the integration: the observables (the usual peak, ROW_BYTES per row); during it:
    # the window buffers (events, samples) of the kernels' record width, the kernel states
    # and the records so far (the peak of many members with few orbits)
    derived = ROW_BYTES * total_rows + MEMBER_BYTES * members
    buffer_rows = window_orbits + BUFFER_SLACK + \
        (math.ceil(window_orbits * samples_per_orbit) + BUFFER_SLACK if samples_per_orbit else 1)
    running = (buffer_rows * width * 8 + RUN_MEMBER_BYTES) * members + total_rows * width * 8
    # with states: after the observables, the state rows of every sample (module docstring)
    kept = 0.0
    if states and samples_per_orbit is not None:
        largest = float(np.max(rows)) if np.ndim(rows) else float(rows)
        kept = STATES_ROW_BYTES * total_rows + STATES_MEMBER_ROW_BYTES * largest \
            + MEMBER_BYTES * members
    return max(derived, running, kept) + chunks


def check_memory(what, members, orbits, samples_per_orbit=None, window_orbits=16,
                 advice="use fewer members or orbits, or sample less densely", available=None,
                 width=31, states=False):
    """:func:`~ti_spinorbit._validate.require_memory` for :func:`estimate_bytes`: raises
    InsufficientMemoryError (a ValueError and a MemoryError) with "<what> needs X GiB, Y GiB
    available; <advice>". Returns the estimate in bytes."""
    nbytes = estimate_bytes(members, orbits, samples_per_orbit, window_orbits, width, states)
    return require_memory(what, nbytes, advice, available=available)


def record_width(system, model="auto", perturbed=False):
    """Width of the kernels' record rows for members of ``system`` under ``model``: the
    planar model's (11) when "auto" will choose it (a BinarySystem whose start is planar and
    bodies equatorially symmetric) or "planar" is asked, else the 3-D one (31; also when
    ``system`` is a list, not yet known); with ``perturbed`` (tides, YORP or BYORP) the
    records also carry the NACC work and external-angular-momentum accumulators (15, 35)."""
    # the kernels' rows: the time and the model's own state (layout), converted on the host
    width = 1 + _layout.spatial.NSTATE
    if model == "planar":
        width = 1 + _layout.planar.NSTATE
    elif model == "auto" and isinstance(system, BinarySystem):
        try:
            if np.all(planar.qualifies(system.parameter_row(), system.initial_state(0.0, 1.0))):
                width = 1 + _layout.planar.NSTATE
        except (ValueError, TypeError, ArithmeticError):
            pass                            # left to the entry point's own checks: 3-D
    return width + (NACC if perturbed else 0)


def member_count(shape, *arrays):
    """Members an entry point broadcasts ``shape`` (a tuple) and ``arrays`` to (product of the
    broadcast shape), or None when they do not broadcast (the entry point's own checks then
    name the problem)."""
    try:
        shape = np.broadcast_shapes(tuple(shape), *(np.shape(x) for x in arrays))
    except (ValueError, TypeError):
        return None
    return int(np.prod(shape, dtype=np.float64)) if shape else 1


def describe(nbytes):
    """'1.23 GiB' for reports."""
    return f"{nbytes / GIB:.3g} GiB"


__all__ = ["estimate_bytes", "check_memory", "member_count", "record_rows", "ROW_BYTES",
           "MEMBER_BYTES", "STATES_ROW_BYTES"]
