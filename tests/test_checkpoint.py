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
from ti_spinorbit import checkpoint

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
        tso.{"surface_of_section" if kind == "section" else "time_series"}(
            vh, 0.0, {list(starts)!r}, progress=progress, checkpoint={str(ckpt)!r}, {extra}
            **{dict(args)!r})
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
    resumed = tso.surface_of_section(vh, 0.0, STARTS, checkpoint=ckpt, resume=True,
                                     indicators=indicators, **ARGS)
    whole = tso.surface_of_section(vh, 0.0, STARTS, indicators=indicators, **ARGS)
    assert_same_section(resumed, whole)
    assert np.all(resumed.count >= 38)


def test_time_series_resume_equals_uninterrupted(tmp_path):
    ckpt = tmp_path / "ts.ckpt"
    killed_run(tmp_path, ckpt, kill_after=2, kind="time_series")
    vh = tso.catalog.system("1991 VH")
    resumed = tso.time_series(vh, 0.0, STARTS, checkpoint=ckpt, resume=True, **ARGS)
    whole = tso.time_series(vh, 0.0, STARTS, **ARGS)
    for f in dataclasses.fields(whole):
        if isinstance(getattr(whole, f.name), np.ndarray):
            np.testing.assert_array_equal(getattr(resumed, f.name), getattr(whole, f.name))


def test_resume_from_a_finished_checkpoint_and_without_one(tmp_path):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "done.ckpt"
    first = tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, **ARGS)
    again = tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, **ARGS)
    assert_same_section(first, again)
    fresh = tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=tmp_path / "none.ckpt",
                                   resume=True, **ARGS)           # no file yet: starts afresh
    assert_same_section(first, fresh)


def test_mismatched_and_damaged_checkpoints_are_refused(tmp_path):
    vh = tso.catalog.system("1991 VH")
    ckpt = tmp_path / "a.ckpt"
    tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, orbits=4, rtol=1e-10)
    with pytest.raises(ValueError, match=r"other settings: rtol \(checkpoint 1e-10, now 1e-11\)"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, orbits=4,
                               rtol=1e-11)
    with pytest.raises(ValueError, match="other inputs"):
        tso.surface_of_section(vh, 0.0, [0.9, 1.63], checkpoint=ckpt, resume=True, orbits=4,
                               rtol=1e-10)
    with pytest.raises(ValueError, match="other inputs"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, orbits=5,
                               rtol=1e-10)
    with pytest.raises(ValueError, match="model"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, orbits=4,
                               rtol=1e-10, model="3d")
    state = (ckpt / checkpoint.STATE).read_bytes()
    (ckpt / checkpoint.STATE).write_bytes(state[:300])
    with pytest.raises(ValueError, match="state.npz is damaged or not a checkpoint"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, orbits=4,
                               rtol=1e-10)
    (ckpt / checkpoint.STATE).write_bytes(state)
    (ckpt / "records-000000.npz").unlink()
    with pytest.raises(ValueError, match="records-000000.npz is missing"):
        tso.surface_of_section(vh, 0.0, STARTS[:2], checkpoint=ckpt, resume=True, orbits=4,
                               rtol=1e-10)
    (tmp_path / "a_file").write_text("not a checkpoint")
    with pytest.raises(ValueError, match="is not a ti_spinorbit checkpoint directory"):
        checkpoint.load(tmp_path / "a_file", {}, "")
