"""Every stage of a multi-stage entry point is checkpointed: a chaos or
parameter map's evidence lengths (orbits/4, orbits/2) and the map itself, overlap_threshold's
doublings and relaxed_libration's search and convergence runs each checkpoint into
``DIR/launch-kkk``. A run interrupted at any window of any stage resumes to a result equal
bit for bit to an uninterrupted one, and a resume never integrates a finished stage again
(no window of it is saved again).

An interruption is a KeyboardInterrupt raised from the progress callback, which runs after
every window's checkpoint is written (the state a kill -9 right after that write leaves);
one test kills a CLI map with SIGKILL in its evidence phase. Tiny runs: 1991 VH, 2 × 3
starts, 8 orbits, rtol 1e-8."""

import dataclasses
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine import checkpoint as C

from conftest import run_cli, run_options
from test_checkpoint import Interrupt

THETA, RATES = [0.0, 90.0], [0.8, 1.2, 1.6]
MAP = dict(orbits=8, rtol=1e-8)


@pytest.fixture
def saves(monkeypatch):
    """The launch directory of every window checkpoint written (checkpoint.save calls)."""
    written = []
    real = C.save

    def spy(path, *args, **kwargs):
        written.append(os.path.basename(os.fspath(path)))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(C, "save", spy)
    return written


def arrays(result):
    """Every array field of a result (nested results' arrays too), by name."""
    out = {}
    for f in dataclasses.fields(result):
        x = getattr(result, f.name)
        if isinstance(x, np.ndarray):
            out[f.name] = x
        elif dataclasses.is_dataclass(x):
            out.update({f"{f.name}.{k}": v for k, v in arrays(x).items()})
    return out


def assert_same(a, b):
    a, b = arrays(a), arrays(b)
    assert a.keys() == b.keys()
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def chaos(vh, **kw):
    return tso.chaos_map(vh, THETA, RATES, **run_options(**MAP, **kw))


@pytest.fixture(scope="module")
def whole(vh):
    return chaos(vh, progress=False)


@pytest.fixture(scope="module")
def windows(vh, tmp_path_factory):
    """Windows per stage of the map (counted from a checkpointed run's records files)."""
    path = tmp_path_factory.mktemp("count") / "ck"
    chaos(vh, checkpoint=path, progress=False, keep_checkpoint=True)
    return [len(list((path / f"launch-{k:03d}").glob("records-*.npz"))) for k in range(3)]


def test_map_stages_each_have_their_checkpoint(vh, whole, windows, tmp_path):
    again = chaos(vh, checkpoint=tmp_path / "ck", progress=False, keep_checkpoint=True)
    assert sorted(p.name for p in (tmp_path / "ck").iterdir() if p.is_dir()) == \
        ["launch-000", "launch-001", "launch-002"]
    assert all(w >= 1 for w in windows), windows
    assert_same(again, whole)      # checkpointing changes nothing


def test_a_finished_map_removes_its_folder_only_after_its_last_stage(vh, whole, tmp_path,
                                                                     monkeypatch):
    """Each stage keeps its launch-kkk while the map goes on (a resume reuses it); the map's
    folder goes once the last stage has succeeded."""
    ckpt = tmp_path / "ck"
    seen = []
    real = C.finish

    def spy(path, *args, **kwargs):
        seen.append((os.path.basename(os.fspath(path)),
                     sorted(p.name for p in ckpt.iterdir() if p.is_dir())))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(C, "finish", spy)
    done = chaos(vh, checkpoint=ckpt, progress=False)
    assert not ckpt.exists() and os.listdir(tmp_path) == []
    # one removal, of the map's folder, when all three stages were there
    assert seen == [("ck", ["launch-000", "launch-001", "launch-002"])], seen
    assert_same(done, whole)


@pytest.mark.parametrize("where", ["first evidence length", "second evidence length",
                                   "the map itself"])
def test_map_interrupted_in_any_stage_resumes_bit_identical(vh, whole, windows, tmp_path,
                                                            saves, where):
    stage = ["first evidence length", "second evidence length", "the map itself"].index(where)
    at = sum(windows[:stage]) + 1          # the first window of that stage
    ckpt = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        chaos(vh, checkpoint=ckpt, progress=Interrupt(at))
    assert saves[-1] == f"launch-{stage:03d}"
    done = {f"launch-{k:03d}": (ckpt / f"launch-{k:03d}" / C.STATE).read_bytes()
            for k in range(stage)}
    saves.clear()
    resumed = chaos(vh, checkpoint=ckpt, resume=True, progress=False, keep_checkpoint=True)
    assert_same(resumed, whole)
    # no finished stage was integrated again: none of its windows was saved, its state is
    # byte for byte the one written before the interruption
    assert not set(saves) & set(done), saves
    for name, state in done.items():
        assert (ckpt / name / C.STATE).read_bytes() == state
    assert saves.count(f"launch-{stage:03d}") == windows[stage] - 1


def test_map_interrupted_at_every_window_then_resumed_each_time(vh, whole, windows, tmp_path):
    """Interrupted again at the first window of every resume: the run still ends as the
    uninterrupted one (each resume makes one window of progress)."""
    ckpt = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        chaos(vh, checkpoint=ckpt, progress=Interrupt(1))
    for _ in range(sum(windows) - 1):
        try:
            result = chaos(vh, checkpoint=ckpt, resume=True, progress=Interrupt(1))
        except KeyboardInterrupt:
            continue
        break
    else:
        result = chaos(vh, checkpoint=ckpt, resume=True, progress=False)
    assert_same(result, whole)
    assert not ckpt.exists()     # every interrupted resume kept it; the one that finished not


def test_parameter_map_interrupted_in_its_evidence_resumes_bit_identical(tmp_path, saves):
    kw = dict(elongations=[1.2], eccentricities=[0.05], orbits=6, thetadot_p=[0.9, 1.5],
              theta_p=[0.0], rtol=1e-8)
    whole = tso.parameter_map("1991 VH", **kw, run=tso.Run(progress=False))
    ckpt = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        tso.parameter_map("1991 VH", **kw, run=tso.Run(checkpoint=ckpt, progress=Interrupt(2)))
    assert saves[-1] in ("launch-000", "launch-001")
    resumed = tso.parameter_map("1991 VH", **kw,
                                run=tso.Run(checkpoint=ckpt, resume=True, progress=False))
    assert_same(resumed, whole)
    assert not ckpt.exists()                 # finished after its last stage: removed


def test_overlap_doubling_interrupted_in_a_longer_length_resumes(tmp_path, saves):
    kw = dict(elongations=[1.05, 1.3], orbits=4, max_orbits=8, rtol=1e-8, centre_starts=3,
              separatrix_starts=3)
    whole = tso.overlap_threshold("1991 VH", **kw, run=tso.Run(progress=False))
    ckpt = tmp_path / "ck"
    full = []
    tso.overlap_threshold("1991 VH", **kw, run=tso.Run(checkpoint=tmp_path / "count",
                                                       progress=False, keep_checkpoint=True))
    full = sorted(p.name for p in (tmp_path / "count").iterdir() if p.is_dir())
    assert len(full) >= 2, full          # the doubling ran a second length
    first = len(list((tmp_path / "count" / "launch-000").glob("records-*.npz")))
    with pytest.raises(KeyboardInterrupt):
        tso.overlap_threshold("1991 VH", **kw,
                              run=tso.Run(checkpoint=ckpt, progress=Interrupt(first + 1)))
    assert saves[-1] == "launch-001"
    saves.clear()
    resumed = tso.overlap_threshold("1991 VH", **kw,
                                    run=tso.Run(checkpoint=ckpt, resume=True, progress=False))
    assert "launch-000" not in saves
    assert_same(resumed, whole)
    assert not ckpt.exists()                 # finished after its last doubling: removed
    np.testing.assert_array_equal(resumed.overlaps_by_length, whole.overlaps_by_length)


def test_a_second_run_on_a_staged_checkpoint_is_refused_at_once(vh, tmp_path):
    ckpt = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        chaos(vh, checkpoint=ckpt, progress=Interrupt(1))
    # not resuming: refused before any work, nothing touched
    before = {p: p.read_bytes() for p in ckpt.rglob("*") if p.is_file()}
    with pytest.raises(C.CheckpointExists, match="already holds a checkpoint"):
        chaos(vh, checkpoint=ckpt, progress=False)
    assert {p: p.read_bytes() for p in ckpt.rglob("*") if p.is_file()} == before
    # while a computation holds the directory, a second one is refused at once
    with C.Launches(ckpt, resume=True).owned():
        t = time.perf_counter()
        with pytest.raises(C.CheckpointLocked, match="locked by another run"):
            chaos(vh, checkpoint=ckpt, resume=True, progress=False)
        assert time.perf_counter() - t < 5.0


def test_overwrite_replaces_every_stage_and_remove_deletes_them(vh, whole, tmp_path):
    ckpt = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        chaos(vh, checkpoint=ckpt, progress=Interrupt(1))
    (ckpt / "launch-007").mkdir()      # a stale launch of some longer computation
    assert C.holds_checkpoint(ckpt)
    fresh = chaos(vh, checkpoint=ckpt, overwrite=True, progress=False, keep_checkpoint=True)
    assert_same(fresh, whole)
    assert not (ckpt / "launch-007").exists()
    C.remove(ckpt)
    assert not ckpt.exists()


def test_resume_refused_after_a_perturbation_changed_names_it(vh, tmp_path):
    tide = tso.Tides(k2=1e-5, time_lag=600.0, strength=1e6)
    ckpt = tmp_path / "ck"
    tso.surface_of_section(vh, 0.0, [1.0], orbits=2, rtol=1e-8, perturbations=[tide],
                           run=tso.Run(checkpoint=ckpt, progress=False, keep_checkpoint=True))
    stronger = dataclasses.replace(tide, strength=2e6)
    with pytest.raises(C.CheckpointError, match=r"other inputs \(perturbations \(tides, YORP, "
                                                r"BYORP or their parameters\) differ\)"):
        tso.surface_of_section(vh, 0.0, [1.0], orbits=2, rtol=1e-8, perturbations=[stronger],
                               run=tso.Run(checkpoint=ckpt, resume=True, progress=False))
    with pytest.raises(C.CheckpointError, match=r"other inputs \(initial states differ\)"):
        tso.surface_of_section(vh, 0.0, [1.1], orbits=2, rtol=1e-8, perturbations=[tide],
                               run=tso.Run(checkpoint=ckpt, resume=True, progress=False))


def test_map_inputs_that_are_refused_before_any_work(vh, tmp_path):
    with pytest.raises(ValueError, match="fraction_orbits must hold distinct lengths"):
        chaos(vh, fraction_orbits=[5, 5])
    with pytest.raises(TypeError, match="unexpected keyword argument 'initial_states'"):
        chaos(vh, initial_states=[vh.tilted_start(0.0, 1.0, roll=1.0, pitch=0.0)])
    with pytest.raises(TypeError, match="checkpoint must be a directory path"):
        chaos(vh, checkpoint=123)
    with pytest.raises(TypeError, match=r"converge must be True or False \(got 'yes'\)"):
        tso.relaxed_libration(vh, converge="yes")
    (tmp_path / "file").write_text("x")
    with pytest.raises(C.CheckpointError, match="is a file"):
        chaos(vh, checkpoint=tmp_path / "file")


CLI_MAP = ["map", "--system", "1991 VH", "--grid", "3", "3", "--orbits", "40", "--rtol",
           "1e-9", "--out", "m.png", "--quiet"]


def test_cli_map_killed_in_its_evidence_resumes_to_the_same_data(tmp_path):
    """kill -9 while the map integrates its first evidence length; the same command with
    --resume keeps that stage's windows and ends with the uninterrupted run's numbers."""
    ref = tmp_path / "ref"
    ref.mkdir()
    assert run_cli(*CLI_MAP, cwd=ref).returncode == 0
    run = tmp_path / "run"
    run.mkdir()
    cmd = [sys.executable, "-m", "ti_spinorbit", *CLI_MAP, "--checkpoint", "ck"]
    p = subprocess.Popen(cmd, cwd=run, env=dict(os.environ, MPLBACKEND="Agg"),
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    first = run / "ck" / "launch-000"
    deadline = time.time() + 240
    while time.time() < deadline and len(list(first.glob("records-*.npz"))) < 2:
        time.sleep(0.02)
    p.send_signal(signal.SIGKILL)
    p.wait()
    kept = len(list(first.glob("records-*.npz")))
    assert kept >= 2 and not (run / "ck" / "launch-002").exists()
    done = run_cli(*CLI_MAP, "--checkpoint", "ck", "--resume", cwd=run)
    assert done.returncode == 0, done.stderr
    a, b = tso.load(ref / "m.npz"), tso.load(run / "m.npz")
    for name in ("megno", "lyapunov", "fraction_by_length", "status"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert not (run / "ck").exists()         # removed once the outputs are written


def test_a_single_run_and_a_staged_checkpoint_are_not_confused(vh, tmp_path):
    single, staged = tmp_path / "single", tmp_path / "staged"
    tso.surface_of_section(vh, 0.0, [1.0], orbits=2, rtol=1e-8,
                           run=tso.Run(checkpoint=single, progress=False, keep_checkpoint=True))
    with pytest.raises(C.CheckpointError, match="holds a single run's checkpoint"):
        chaos(vh, checkpoint=single, resume=True, progress=False)
    chaos(vh, checkpoint=staged, progress=False, keep_checkpoint=True)
    with pytest.raises(C.CheckpointError, match=r"holds the launches \(launch-kkk\)"):
        tso.surface_of_section(vh, 0.0, [1.0], orbits=2, rtol=1e-8,
                               run=tso.Run(checkpoint=staged, resume=True, progress=False))


def test_a_finished_libration_search_removes_its_folder_and_an_interrupted_one_keeps_it(
        vh, tmp_path):
    kw = dict(orbits=2, candidates=np.linspace(0.2, 1.3, 7), zoom_candidates=5,
              max_iterations=1, samples_per_orbit=8, converge=False)
    ckpt = tmp_path / "ck"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        with pytest.raises(KeyboardInterrupt):
            tso.relaxed_libration(vh, **kw, run=tso.Run(checkpoint=ckpt, progress=Interrupt(2)))
        assert C.holds_checkpoint(ckpt)                  # interrupted: kept for the resume
        resumed = tso.relaxed_libration(vh, **kw, run=tso.Run(checkpoint=ckpt, resume=True,
                                                              progress=False))
        assert not ckpt.exists()                         # finished: removed
        whole = tso.relaxed_libration(vh, **kw, run=tso.Run(progress=False))
    assert resumed.centre_thetadot_p == whole.centre_thetadot_p
    assert resumed.amplitude == whole.amplitude
