"""Checkpoint and resume: a run killed between windows resumes to exactly the
results of an uninterrupted run; damaged or mismatched checkpoints raise clear errors."""

import dataclasses
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import ti_spinorbit as tso

from conftest import run_options
from ti_spinorbit.engine import checkpoint

STARTS = [0.83, 1.63, 2.2]
ARGS = dict(orbits=40, rtol=1e-10, window_orbits=4)


def assert_same_section(a, b):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "seconds":
            continue
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=f.name)


def killed_run(tmp_path, ckpt, kill_after, kind="section", extra="", starts=STARTS, args=ARGS):
    """Run in a subprocess that SIGKILLs itself from the progress callback after
    ``kill_after`` windows (the checkpoint of that window is already written): a section or
    (``kind`` "series") a time series of 1991 VH from ``starts`` with ``args``, and the
    keyword text ``extra``."""
    script = textwrap.dedent(f"""
        import os, signal
        import ti_spinorbit as tso
        calls = [0]
        def progress(fraction):
            calls[0] += 1
            if calls[0] == {kill_after}:
                os.kill(os.getpid(), signal.SIGKILL)
        vh = tso.catalog.system("1991 VH")
        args = {dict(args)!r}
        run = tso.Run(progress=progress, checkpoint={str(ckpt)!r},
                      window_orbits=args.pop("window_orbits", 4))
        tso.{"surface_of_section" if kind == "section" else "time_series"}(
            vh, 0.0, {list(starts)!r}, {extra} **args, run=run)
        raise SystemExit("not killed")
    """)
    p = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == -9, p.stderr
    assert os.path.exists(ckpt)
    assert not [f for f in os.listdir(ckpt) if ".tmp-" in f]       # no half-written file left


@pytest.mark.parametrize("indicators", [False, True])
def test_resume_after_kill_equals_uninterrupted_run(tmp_path, indicators):
    ckpt = tmp_path / "run.ckpt"
    killed_run(tmp_path, ckpt, kill_after=3, extra=f"indicators={indicators},")
    vh = tso.catalog.system("1991 VH")
    resumed = tso.surface_of_section(vh, 0.0, STARTS, indicators=indicators, **run_options(**ARGS, checkpoint=ckpt, resume=True))
    whole = tso.surface_of_section(vh, 0.0, STARTS, indicators=indicators, **run_options(**ARGS))
    assert_same_section(resumed, whole)
    assert np.all(resumed.count >= 38)


def test_time_series_resume_equals_uninterrupted(tmp_path):
    ckpt = tmp_path / "ts.ckpt"
    killed_run(tmp_path, ckpt, kill_after=2, kind="time_series")
    vh = tso.catalog.system("1991 VH")
    resumed = tso.time_series(vh, 0.0, STARTS, **run_options(**ARGS, checkpoint=ckpt, resume=True))
    whole = tso.time_series(vh, 0.0, STARTS, **run_options(**ARGS))
    for f in dataclasses.fields(whole):
        if isinstance(getattr(whole, f.name), np.ndarray):
            np.testing.assert_array_equal(getattr(resumed, f.name), getattr(whole, f.name))


def test_resume_from_a_finished_checkpoint_and_without_one(tmp_path):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "done.ckpt"
    first = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(**ARGS, checkpoint=ckpt,
                                                                      keep_checkpoint=True))
    again = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(**ARGS, checkpoint=ckpt, resume=True))
    assert_same_section(first, again)
    assert not ckpt.exists()                   # the resumed run finished: removed
    fresh = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(**ARGS, checkpoint=tmp_path / "none.ckpt", resume=True))           # no file yet: starts afresh
    assert_same_section(first, fresh)


def test_mismatched_and_damaged_checkpoints_are_refused(tmp_path):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "a.ckpt"
    tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=4, rtol=1e-10,
                           run=tso.Run(checkpoint=ckpt, keep_checkpoint=True))
    with pytest.raises(ValueError, match=r"other settings: rtol \(checkpoint 1e-10, now 1e-11\)"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=4, rtol=1e-11,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    with pytest.raises(ValueError, match="other inputs"):
        tso.surface_of_section(vh, 0.0, [0.9, 1.63], orbits=4, rtol=1e-10,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    with pytest.raises(ValueError, match="other inputs"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=5, rtol=1e-10,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    with pytest.raises(ValueError, match="model"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=4, rtol=1e-10,
                               integrator=tso.Integrator(model="3d"),
                               run=tso.Run(checkpoint=ckpt, resume=True))
    state = (ckpt / checkpoint.STATE).read_bytes()
    (ckpt / checkpoint.STATE).write_bytes(state[:300])
    with pytest.raises(ValueError, match="state.npz is damaged or not a checkpoint"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=4, rtol=1e-10,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    (ckpt / checkpoint.STATE).write_bytes(state)
    (ckpt / "records-000000.npz").unlink()
    with pytest.raises(ValueError, match="records-000000.npz is missing"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], orbits=4, rtol=1e-10,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    (tmp_path / "a_file").write_text("not a checkpoint")
    with pytest.raises(ValueError, match="is not a ti_spinorbit checkpoint directory"):
        checkpoint.load(tmp_path / "a_file", {}, "")


# ---- a finished run's checkpoint is removed (Run(keep_checkpoint=True) keeps it) -----------
class Interrupt:
    """A progress callback that raises KeyboardInterrupt at its ``at``-th call (after that
    window's checkpoint is written)."""

    def __init__(self, at):
        self.at, self.calls = at, 0

    def __call__(self, fraction):
        self.calls += 1
        if self.calls == self.at:
            raise KeyboardInterrupt


@pytest.fixture
def saves(monkeypatch):
    """Every window checkpoint written (checkpoint.save calls)."""
    written = []
    real = checkpoint.save

    def spy(path, *args, **kwargs):
        written.append(os.fspath(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(checkpoint, "save", spy)
    return written


def test_a_finished_run_removes_its_checkpoint(tmp_path, saves):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "run.ckpt"
    with_ckpt = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(**ARGS, checkpoint=ckpt))
    assert saves                               # it was checkpointed ...
    assert not ckpt.exists()                   # ... and the folder is gone once it returned
    assert os.listdir(tmp_path) == []
    assert_same_section(with_ckpt, tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(**ARGS)))
    # a time series likewise (the same Ensemble.run path)
    tso.time_series(vh, 0.0, STARTS[:1], **run_options(**ARGS, checkpoint=ckpt))
    assert not ckpt.exists()


def test_keep_checkpoint_keeps_it_and_a_resume_from_it_integrates_nothing(tmp_path, saves):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "kept.ckpt"
    first = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(
        **ARGS, checkpoint=ckpt, keep_checkpoint=True))
    assert checkpoint.holds_checkpoint(ckpt)
    state = (ckpt / checkpoint.STATE).read_bytes()
    saves.clear()
    again = tso.surface_of_section(vh, 0.0, STARTS[:2], **run_options(
        **ARGS, checkpoint=ckpt, resume=True, keep_checkpoint=True))
    assert_same_section(first, again)
    assert saves == []                         # the finished checkpoint gave its result back
    assert (ckpt / checkpoint.STATE).read_bytes() == state
    assert np.all(again.count > 0)              # a result with crossings, not an empty one
    with pytest.raises(TypeError, match="keep_checkpoint must be True or False"):
        tso.Run(checkpoint=ckpt, keep_checkpoint="yes")


def test_an_interrupted_run_keeps_its_checkpoint_and_the_resume_removes_it(tmp_path):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "stopped.ckpt"
    with pytest.raises(KeyboardInterrupt):
        tso.surface_of_section(vh, 0.0, STARTS, **run_options(
            **{**ARGS, "progress": Interrupt(3)}, checkpoint=ckpt))
    assert checkpoint.holds_checkpoint(ckpt)   # kept for the resume
    assert len(list(ckpt.glob("records-*.npz"))) == 3
    resumed = tso.surface_of_section(vh, 0.0, STARTS, **run_options(**ARGS, checkpoint=ckpt,
                                                                    resume=True))
    assert not ckpt.exists()                   # finished now: removed
    assert_same_section(resumed, tso.surface_of_section(vh, 0.0, STARTS, **run_options(**ARGS)))


def test_a_run_that_fails_keeps_its_checkpoint(tmp_path):
    """Any exception, not only an interruption, keeps the checkpoint."""
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "failed.ckpt"

    def fail(fraction):
        raise RuntimeError("the disk is full")

    with pytest.raises(RuntimeError, match="the disk is full"):
        tso.surface_of_section(vh, 0.0, STARTS[:1], **run_options(
            **{**ARGS, "progress": fail}, checkpoint=ckpt))
    assert checkpoint.holds_checkpoint(ckpt)


def test_finish_is_the_one_rule(tmp_path):
    """checkpoint.finish: kept when asked (naming the caller's flag), removed otherwise; a
    missing folder is nothing to do; files that are not a checkpoint's stay."""
    ckpt = tmp_path / "c"
    ckpt.mkdir()
    (ckpt / checkpoint.STATE).write_bytes(b"x")
    (ckpt / "records-000000.npz").write_bytes(b"x")
    assert checkpoint.finish(ckpt, keep=True, flag="--keep-checkpoint") == \
        f"kept checkpoint {ckpt} (--keep-checkpoint)"
    assert sorted(os.listdir(ckpt)) == ["records-000000.npz", checkpoint.STATE]
    (ckpt / "notes.txt").write_text("mine")
    assert checkpoint.finish(ckpt) == \
        f"removed checkpoint {ckpt} (the run is complete; keep_checkpoint=True keeps it)"
    assert os.listdir(ckpt) == ["notes.txt"]  # not a checkpoint file: left, with its folder
    assert checkpoint.finish(tmp_path / "none") is None
