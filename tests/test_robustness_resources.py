"""Resources and environment: the memory estimate is right (within a factor 1.5 of
the measured peak RSS growth), absurd sizes are refused from the sizes alone before any member
is built, progress comes every few seconds even inside a long window without changing a bit
of the results, and a read-only HOME (unwritable kernel cache) no longer crashes at exit."""

import dataclasses
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine.members import Members
from ti_spinorbit import _validate, cli, runtime
from ti_spinorbit.engine import ensemble, resources
from ti_spinorbit.studies import overlap

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXPERIMENT = os.path.join(ROOT, "experiments", "memory_estimate.py")
GIB = 2.0**30


# ---- 1. the estimate is right --------------------------------------------------------------

@pytest.mark.parametrize("entry, kw", [
    # records dominate: few members, many rows (a crossing or a sample each)
    ("time_series", dict(members=2, orbits=200, samples_per_orbit=256)),
    ("surface_of_section", dict(members=4, orbits=6000)),
])
def test_estimate_within_factor_1_5_of_measured_peak_rss(entry, kw):
    """The estimate the entry point computes before any work against the peak RSS growth of
    the run, in a fresh process that has initialised Taichi and run a tiny case first
    (experiments/memory_estimate.py, measure)."""
    sys.path.insert(0, os.path.dirname(EXPERIMENT))
    try:
        import memory_estimate
    finally:
        sys.path.pop(0)
    r = memory_estimate.measure(entry, kw)
    assert r["growth"] > 10 * 2**20, r          # the case is large against allocator noise
    assert 1 / 1.5 <= r["estimate"] / r["growth"] <= 1.5, r


def test_estimate_of_the_reported_case_matches_its_measured_peak():
    """16 members x 4000 orbits x 40 samples per orbit: measured peak RSS growth 2.92 GiB
    (an earlier estimate said 0.42 GiB)."""
    estimate = resources.estimate_bytes(16, 4000, 40) / GIB
    assert 2.92 / 1.5 <= estimate <= 2.92 * 1.5, estimate


def test_ensemble_run_checks_the_same_model_as_the_entry_points():
    t_stop = np.full(3, 2 * np.pi * 500)
    got = ensemble._record_bytes(t_stop, 2 * np.pi / 64, 31, ensemble.DEFAULT_WINDOW_ORBITS + 4)
    assert got == pytest.approx(resources.estimate_bytes(3, 500, 64.0,
                                                         ensemble.DEFAULT_WINDOW_ORBITS), rel=1e-3)


@pytest.mark.parametrize("bigger", [dict(members=8), dict(orbits=2000), dict(samples_per_orbit=128)])
def test_estimate_grows_with_every_size(bigger):
    base = dict(members=4, orbits=1000, samples_per_orbit=64)
    assert resources.estimate_bytes(**dict(base, **bigger)) > resources.estimate_bytes(**base)


def test_many_members_few_orbits_count_the_window_buffers():
    """One orbit per member: the integration's window buffers (window_orbits + 4 rows of the
    record width per member) outweigh the records, and the estimate says so."""
    n = 10**6
    buffers = n * (ensemble.DEFAULT_WINDOW_ORBITS + 4 + 1) * 31 * 8
    assert resources.estimate_bytes(n, 1.0) >= buffers


@pytest.mark.parametrize("model, systems, width", [
    ("auto", "one", 11), ("planar", "one", 11), ("3d", "one", 31), ("auto", "list", 31)])
def test_record_width_of_the_model_a_run_will_use(vh, model, systems, width):
    """The early check sizes the kernels' buffers with the model's record width (planar
    11, 3-D 31); a list of systems is not inspected (3-D, the larger)."""
    assert resources.record_width(vh if systems == "one" else [vh, vh], model) == width


@pytest.mark.parametrize("model, width", [("planar", 15), ("3d", 35)])
def test_perturbed_runs_count_their_accumulator_columns(vh, monkeypatch, model, width):
    """With tides, YORP or BYORP the records carry the work and external-angular-momentum
    accumulators (4 more columns), and the entry points' early check counts them: the width
    it sizes with equals the kernels' own record width of the perturbed variant."""
    from ti_spinorbit.kernels import advance as K

    kernels = K.kernels_for(model, perturbed=True)
    assert resources.record_width(vh, model, perturbed=True) == width == kernels.RECORD_WIDTH
    widths = []
    checked = resources.check_memory

    def spy(*args, **kwargs):
        widths.append(kwargs.get("width"))
        return checked(*args, **kwargs)

    monkeypatch.setattr(resources, "check_memory", spy)
    tide = tso.Tides(k2=1e-5, time_lag=600.0)
    tso.surface_of_section(vh, 0.0, [1.0], orbits=0.1, perturbations=[tide],
                           integrator=tso.Integrator(model=model))
    tso.chaos_map(vh, [0.0], [1.0], orbits=0.1, perturbations=[tide],
                  integrator=tso.Integrator(model=model))
    assert len(widths) >= 2 and set(widths) == {width}   # the map checks its nested runs too


# ---- 2. absurd sizes are refused before any member is built ---------------------------------

def _no_members(*args, **kwargs):
    raise AssertionError("members were built before the size check")


@pytest.mark.parametrize("what, call", [
    ("chaos_map", lambda vh: tso.chaos_map(vh, np.linspace(0, 180, 4000), np.linspace(.2, 3, 4000),
                                           orbits=1e4)),
    ("surface_of_section", lambda vh: tso.surface_of_section(vh, 0.0, np.linspace(0.5, 2, 10**5),
                                                             orbits=1e7)),
    ("time_series", lambda vh: tso.time_series(vh, 0.0, 1.0, 1e6, samples_per_orbit=1000)),
    ("parameter_map", lambda vh: tso.parameter_map("1991 VH", np.linspace(1, 2, 1000),
                                                   np.linspace(0, 0.5, 1000), 1e4)),
    ("overlap_threshold", lambda vh: tso.overlap_threshold(
        "1991 VH", elongations=np.linspace(1.01, 2, 1000), orbits=1e6)),
    ("relaxed_libration", lambda vh: tso.relaxed_libration(
        tso.catalog.system("Didymos"), orbits=1e7, samples_per_orbit=100000)),
])
def test_absurd_sizes_are_refused_within_seconds(vh, monkeypatch, what, call):
    monkeypatch.setattr(Members, "from_starts", classmethod(_no_members))
    monkeypatch.setattr(tso.catalog, "system", _no_catalog(tso.catalog.system))
    started = time.perf_counter()
    with pytest.raises(_validate.InsufficientMemoryError) as err:
        call(vh)
    assert time.perf_counter() - started < 5.0
    message = str(err.value)
    assert message.startswith(what) and " GiB available; " in message and "\n" not in message


def _no_catalog(system):
    """catalog.system that refuses to build the many systems of a scan (one is fine)."""
    calls = [0]

    def guarded(*args, **kwargs):
        calls[0] += 1
        if calls[0] > 2:
            raise AssertionError("systems were built before the size check")
        return system(*args, **kwargs)
    return guarded


def test_cli_map_refused_within_a_second(capsys, tmp_path):
    started = time.perf_counter()
    status = cli.main(["map", "--grid", "1024", "1024", "--orbits", "1e7", "--quiet",
                       "--out", str(tmp_path / "map.png")])
    seconds = time.perf_counter() - started
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and seconds < 5.0
    assert len(err) == 1 and err[0].startswith("ti-spinorbit map: error: chaos_map needs "), err
    assert not os.listdir(tmp_path)


def test_refusal_follows_the_available_memory(vh, monkeypatch):
    """A run that fits is admitted; the same run with 1 MiB available is refused."""
    monkeypatch.setattr(_validate, "available_memory", lambda: 2**20)
    with pytest.raises(_validate.InsufficientMemoryError, match=r"^time_series needs .* GiB, "
                       r"0\.000977 GiB available; "):
        tso.time_series(vh, 0.0, 1.0, 50, samples_per_orbit=64)
    monkeypatch.setattr(_validate, "available_memory", lambda: 64 * GIB)
    from ti_spinorbit.kernels.advance import DONE
    assert tso.time_series(vh, 0.0, 1.0, 2, samples_per_orbit=4).status.tolist() == [DONE]


def test_overlap_scans_at_several_eccentricities_are_sized_together(monkeypatch):
    """Each scan keeps its sections: three that fit one by one (~0.47 GiB each at 300 orbits)
    are refused together with 1 GiB available, before the first scan starts."""
    one = resources.estimate_bytes(15 * 80, 300)
    assert one < 0.8 * GIB < 3 * one
    monkeypatch.setattr(_validate, "available_memory", lambda: GIB)
    monkeypatch.setattr(Members, "from_starts", classmethod(_no_members))
    with pytest.raises(_validate.InsufficientMemoryError, match=r"^overlap_vs_eccentricity needs "):
        overlap.overlap_vs_eccentricity("1991 VH", [0.05, 0.1, 0.15], orbits=300)


def test_inputs_that_do_not_broadcast_are_left_to_the_member_table(vh):
    with pytest.raises(ValueError, match="cannot broadcast"):
        tso.surface_of_section(vh, [0.0, 1.0], [1.0, 1.1, 1.2], orbits=1)


# ---- 3. progress inside long windows, results unchanged -------------------------------------

@pytest.mark.parametrize("span, seconds, expected", [
    (2 * np.pi * 16, 8.0, 2 * np.pi * 16 / 8),       # slow: shortened in proportion
    (2 * np.pi * 2, 0.1, 2 * np.pi * 4),              # fast: doubled
    (2 * np.pi * 16, 0.1, 2 * np.pi * 16),            # never beyond window_orbits
    (2 * np.pi * 16, 1e6, 2 * np.pi / 64),            # never below MIN_WINDOW_ORBITS
    (2 * np.pi, 1.0, 2 * np.pi),                      # on target: kept
])
def test_next_window_span(span, seconds, expected):
    assert ensemble._next_span(span, seconds, 2 * np.pi * 16) == pytest.approx(expected)


def _fields_equal(a, b):
    for f in dataclasses.fields(a):
        x = getattr(a, f.name)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, getattr(b, f.name), err_msg=f.name)


@pytest.mark.parametrize("kind", ["section", "section+indicators", "time_series"])
def test_forced_short_windows_are_bit_identical(vh, monkeypatch, kind):
    def run():
        calls = []
        if kind == "time_series":
            r = tso.time_series(vh, 0.0, [0.83, 1.63], 12, samples_per_orbit=16,
                                run=tso.Run(progress=calls.append))
        else:
            r = tso.surface_of_section(vh, 0.0, [0.83, 1.63], 12, rtol=1e-10,
                                       indicators=kind.endswith("indicators"),
                                       run=tso.Run(progress=calls.append))
        return r, calls

    default, default_calls = run()
    monkeypatch.setattr(ensemble, "PROGRESS_SECONDS", 0.0)   # every window "too slow"
    short, short_calls = run()
    assert len(short_calls) > max(100, 20 * len(default_calls))   # windows of ~1/64 orbit
    _fields_equal(short, default)


def test_short_windows_checkpoint_resume_with_default_windows(vh, monkeypatch, tmp_path):
    """Interrupted under forced-short windows, resumed with adaptive ones: the same bits as
    an uninterrupted default run (window ends are soft; window_orbits, which the checkpoint
    records, is unchanged)."""
    ckpt = tmp_path / "run.ckpt"
    args = dict(orbits=10, rtol=1e-10)
    calls = []

    def stop_after_some(fraction):
        calls.append(fraction)
        if len(calls) == 40:
            raise KeyboardInterrupt

    monkeypatch.setattr(ensemble, "PROGRESS_SECONDS", 0.0)
    with pytest.raises(KeyboardInterrupt):
        tso.surface_of_section(vh, 0.0, [0.83, 1.63], **args,
                               run=tso.Run(checkpoint=ckpt, progress=stop_after_some,
                                           window_orbits=4))
    assert 0 < calls[-1] < 1
    monkeypatch.setattr(ensemble, "PROGRESS_SECONDS", 1.0)
    resumed = tso.surface_of_section(vh, 0.0, [0.83, 1.63], **args,
                                     run=tso.Run(checkpoint=ckpt, resume=True, window_orbits=4))
    whole = tso.surface_of_section(vh, 0.0, [0.83, 1.63], **args, run=tso.Run(window_orbits=4))
    _fields_equal(resumed, whole)


# ---- 4. read-only HOME ----------------------------------------------------------------------

def test_read_only_home_runs_and_exits_true(tmp_path):
    """HOME and XDG_CACHE_HOME under a regular file: no folder can be created there, even as
    root. Taichi used to crash at exit (139); now a one-line notice and the true status."""
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    env = dict(os.environ, HOME=str(blocker / "home"), XDG_CACHE_HOME=str(blocker / "cache"),
               MPLBACKEND="Agg", MPLCONFIGDIR=str(tmp_path / "mpl"), TMPDIR=str(tmp_path))
    env.pop(runtime.CACHE_ENV, None)
    p = subprocess.run([sys.executable, "-m", "ti_spinorbit", "energy", "--orbits", "1",
                        "--quiet", "--out", str(tmp_path / "e.png")], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    notices = [line for line in p.stderr.splitlines() if "kernel cache folder" in line]
    assert notices == [f"ti_spinorbit: kernel cache folder {blocker}/cache/taichi/ti_spinorbit-2 "
                       f"is not writable (Not a directory); compiling without a disk cache "
                       f"(set TI_OFFLINE_CACHE_FILE_PATH to a writable folder)"], p.stderr
    assert (tmp_path / "e.npz").exists()
    assert not [f for f in os.listdir(tmp_path) if f.startswith("ti_spinorbit-cache-")]


def test_read_only_home_with_the_disk_cache_off_exits_true(tmp_path):
    """init(offline_cache=False) used to crash at exit too: Taichi touches its default cache
    path (~/.cache/taichi/ticache) either way."""
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    env = dict(os.environ, HOME=str(blocker / "home"), XDG_CACHE_HOME=str(blocker / "cache"),
               TMPDIR=str(tmp_path))
    env.pop(runtime.CACHE_ENV, None)
    script = ("import ti_spinorbit as tso; tso.init(offline_cache=False); "
              "r = tso.surface_of_section(tso.catalog.system('1991 VH'), 0.0, 1.0, 1); "
              "print(r.status_names[0])")
    p = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    assert p.stdout.strip().splitlines()[-1] == "done"
    assert sum("is not writable (Not a directory)" in line for line in p.stderr.splitlines()) == 1


def test_cache_folder_from_platformdirs_and_the_variable(monkeypatch, tmp_path):
    monkeypatch.delenv(runtime.CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if sys.platform.startswith("linux"):
        assert runtime.cache_folder() == str(tmp_path / "xdg" / "taichi" / "ti_spinorbit-2")
    monkeypatch.setenv(runtime.CACHE_ENV, str(tmp_path / "mine"))
    assert runtime.cache_folder() == str(tmp_path / "mine")


def test_unwritable_probe_writes_for_real(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert runtime._unwritable(str(tmp_path / "new" / "cache")) is None
    assert os.path.isdir(tmp_path / "new" / "cache") and not os.listdir(tmp_path / "new" / "cache")
    assert runtime._unwritable(str(blocker / "cache")) == "Not a directory"


def test_platformdirs_is_a_dependency():
    with open(os.path.join(ROOT, "pyproject.toml")) as f:
        text = f.read()
    deps = text.split("dependencies = [", 1)[1].split("]", 1)[0]
    assert '"platformdirs' in deps


# ---- available memory: psutil when installed, the package's own reading otherwise ----------
def test_psutil_and_the_fallback_agree_on_the_available_memory():
    psutil = pytest.importorskip("psutil")
    own = _validate._os_available_memory()
    via_psutil = psutil.virtual_memory().available
    assert own is not None and via_psutil > 0
    # two reads of a moving number (other processes allocate meanwhile): roughly equal
    assert own == pytest.approx(via_psutil, rel=0.1)
    assert _validate.available_memory() == pytest.approx(via_psutil, rel=0.1)


def test_available_memory_uses_psutil_when_installed_and_falls_back_without(monkeypatch):
    psutil = pytest.importorskip("psutil")

    class Memory:
        available = 123 * 2**20

    monkeypatch.setattr(psutil, "virtual_memory", lambda: Memory())
    assert _validate.available_memory() == 123 * 2**20          # psutil's answer is taken
    monkeypatch.setitem(sys.modules, "psutil", None)             # as if not installed
    assert _validate._psutil_available_memory() is None
    got = _validate.available_memory()
    assert got != 123 * 2**20
    assert got == pytest.approx(_validate._os_available_memory(), rel=0.1)   # /proc moves

    def broken():
        raise RuntimeError("cannot read memory here")

    monkeypatch.setitem(sys.modules, "psutil", psutil)
    monkeypatch.setattr(psutil, "virtual_memory", broken)       # psutil fails: fallback
    assert _validate.available_memory() == pytest.approx(_validate._os_available_memory(),
                                                         rel=0.1)
