"""Files lose nothing and say what is wrong in one line:

* every result file, figure and report is written atomically (a temporary file beside it,
  fsync, os.replace): a write that fails or is killed with SIGKILL never harms an existing
  file and never leaves a partial one under the final name;
* two CLI runs with the same output names cannot both go on: the second is refused (exit 2);
* a dangling symlink as --data, names longer than the folder allows, control characters and
  system names with folder separators are refused or made safe before any integration;
* the same --resume command finishes a run killed between its data file and its figure, and
  a finished checkpoint in a read-only folder resumes;
* every one-bit flip of a small archive or checkpoint state is the documented error, edited
  arrays (codes, shapes, dtypes) are refused on load, to_xarray carries every array field,
  and ``checkpoint=123`` / ``save(extra=['a'])`` are one-line TypeErrors.

Tiny runs: 1991 VH, one or two members, a few orbits."""

import builtins
import contextlib
import dataclasses
import errno
import glob
import json
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine import checkpoint as C
from ti_spinorbit import cli, files
from ti_spinorbit.output import io, plotting
from ti_spinorbit.cli import common
from ti_spinorbit.output.io import ArchiveError
from ti_spinorbit.studies.libration import RelaxedLibration

from conftest import run_cli, run_options

SECTION = ["section", "--system", "1991 VH", "--orbits", "3", "--thetadot", "0.83", "1.63",
           "--rtol", "1e-9", "--quiet"]


def error_line(text):
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    return lines[0]


def same_arrays(a, b):
    """Every array field of two results equal (dtype, shape, values, NaN where NaN)."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert isinstance(y, np.ndarray) and x.dtype == y.dtype and x.shape == y.shape, f.name
            np.testing.assert_array_equal(x, y, err_msg=f.name)


def stray(folder):
    """Hidden temporary or lock files left in ``folder``."""
    return sorted(n for n in os.listdir(folder) if n.endswith((".tmp", ".lock")))


@pytest.fixture(scope="module")
def small(vh):
    return tso.surface_of_section(vh, 0.0, [0.83, 1.63], orbits=3, rtol=1e-9,
                                  run=tso.Run(progress=False))


@pytest.fixture
def no_integration(monkeypatch):
    """Entry points that fail the test if the CLI gets as far as integrating."""
    def refuse(*args, **kwargs):
        raise AssertionError("integrated before refusing")
    for name in ("surface_of_section", "time_series", "chaos_map"):
        monkeypatch.setattr(tso, name, refuse)


# ---- 1. atomic writes -----------------------------------------------------------------------
KILL_DURING_SAVE = """
import dataclasses, sys
import numpy as np
import ti_spinorbit as tso
small = tso.load(sys.argv[1])
big = dataclasses.replace(small, theta_p=np.random.default_rng(1).random((2, 2_500_000)))
print("saving", flush=True)
tso.save(big, sys.argv[2], overwrite=True)
print("saved", flush=True)
"""


def test_save_killed_mid_write_leaves_the_old_file_byte_identical(small, tmp_path):
    """tso.save of 40 MB over a good file, SIGKILL-ed while its bytes go out: the old file is
    untouched, nothing partial has the final name, only a hidden temporary file is left."""
    good = io.save(small, tmp_path / "good.npz")
    target = tmp_path / "result.npz"
    shutil.copy(good, target)
    before = target.read_bytes()
    script = tmp_path / "kill.py"
    script.write_text(KILL_DURING_SAVE)
    p = subprocess.Popen([sys.executable, str(script), str(good), str(target)],
                         stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "saving"
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            temps = glob.glob(str(tmp_path / ".result.npz.*.tmp"))
            if temps and os.path.getsize(temps[0]) > 0:
                break
            time.sleep(0.002)
        else:
            pytest.fail("the save never started writing its temporary file")
        os.kill(p.pid, signal.SIGKILL)
    finally:
        p.wait(timeout=60)
    assert p.returncode == -signal.SIGKILL
    assert "saved" not in p.stdout.read()
    assert target.read_bytes() == before                # byte-identical, still loadable
    same_arrays(small, tso.load(target))
    left = [n for n in os.listdir(tmp_path) if n not in ("good.npz", "result.npz", "kill.py")]
    assert len(left) == 1 and left[0].startswith(".result.npz.") and left[0].endswith(".tmp")
    io.save(small, target, overwrite=True)           # a later save over it works
    same_arrays(small, tso.load(target))


def _fail_in_savez(monkeypatch, exc):
    real = np.savez_compressed

    def partial(fh, **arrays):
        real(fh, **arrays)
        fh.write(b"half")
        raise exc

    monkeypatch.setattr(np, "savez_compressed", partial)


def _fail_in_savefig(monkeypatch, exc):
    import matplotlib.figure

    def partial(self, fh, **kwargs):
        fh.write(b"\x89PNG half a figure")
        raise exc

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", partial)


WRITERS = {
    "tso.save": ("r.npz", _fail_in_savez,
                 lambda small, path: io.save(small, path, overwrite=True)),
    "save_figure": ("r.png", _fail_in_savefig,
                    lambda small, path: plotting.save_figure(small.plot(), path)),
    "report (JSON)": ("r.json", None,
                      lambda small, path: files.write_json(path, {"a": 1, "b": object()})),
}


@pytest.mark.parametrize("exc", [OSError(errno.ENOSPC, "No space left on device"),
                                 KeyboardInterrupt()], ids=["disk full", "Ctrl-C"])
@pytest.mark.parametrize("writer", list(WRITERS))
def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(small, tmp_path, monkeypatch,
                                                                  writer, exc):
    name, fail, write = WRITERS[writer]
    path = tmp_path / name
    path.write_bytes(b"the earlier, good file")
    if fail is not None:
        fail(monkeypatch, exc)
        expected = type(exc)
    else:
        expected = TypeError              # json.dump fails half-way through (object())
    with pytest.raises(expected):
        write(small, path)
    assert path.read_bytes() == b"the earlier, good file"
    assert os.listdir(tmp_path) == [name]           # no temporary file left behind


def test_atomic_writes_keep_modes_and_symlinks(small, tmp_path):
    old = os.umask(0o027)
    try:
        fresh = io.save(small, tmp_path / "fresh.npz")
    finally:
        os.umask(old)
    assert os.stat(fresh).st_mode & 0o777 == 0o640   # as open() would: 0o666 & ~umask
    kept = tmp_path / "kept.npz"
    kept.write_bytes(b"x")
    os.chmod(kept, 0o604)
    io.save(small, kept, overwrite=True)
    assert os.stat(kept).st_mode & 0o777 == 0o604    # the mode of the file it replaced
    real = tmp_path / "real.npz"
    real.write_bytes(b"x")
    link = tmp_path / "link.npz"
    link.symlink_to(real)
    io.save(small, link, overwrite=True)
    assert link.is_symlink() and os.readlink(link) == str(real)
    same_arrays(small, tso.load(real))


def test_save_into_a_missing_folder_names_the_file_not_the_temporary(small, tmp_path):
    with pytest.raises(FileNotFoundError) as info:
        io.save(small, tmp_path / "absent" / "r.npz")
    assert str(info.value) == (f"[Errno 2] cannot write '{tmp_path / 'absent' / 'r.npz'}' in "
                               f"folder '{tmp_path / 'absent'}' (No such file or directory)")


def test_cli_outputs_are_complete_and_no_helper_files_stay(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main([*SECTION, "--out", "s.png"]) == 0
    assert sorted(os.listdir(tmp_path)) == ["s.npz", "s.png"]     # no lock, no temporary
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert tso.load("s.npz").status.tolist() == [1, 1]


# ---- 2. exclusive outputs -------------------------------------------------------------------
def test_output_claimed_by_another_run_is_refused_before_any_work(tmp_path, monkeypatch, capsys,
                                                                    no_integration):
    monkeypatch.chdir(tmp_path)
    with files.claim([("--out", "s.png")], command="ti-spinorbit section (the first run)"):
        assert cli.main([*SECTION, "--out", "s.png", "--overwrite"]) == cli.EXIT_ERROR
    line = error_line(capsys.readouterr().err)
    assert line.startswith("ti-spinorbit section: error: --out: 's.png' is being written by "
                           f"another run (pid {os.getpid()} on ")
    assert "ti-spinorbit section (the first run)" in line
    assert os.listdir(tmp_path) == []                  # nothing written, lock file gone


def test_two_cli_runs_with_the_same_out_started_together(tmp_path):
    """The reproducer: the second run is refused in one line while the first goes on; a
    killed first run leaves its lock file, which blocks nothing."""
    slow = ["section", "--system", "1991 VH", "--orbits", "100000", "--thetadot", "0.83",
            "1.0", "1.2", "1.63", "--rtol", "1e-9", "--out", "s.png", "--quiet"]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    first = subprocess.Popen([sys.executable, "-m", "ti_spinorbit", *slow], cwd=tmp_path,
                             env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 120
        while not (tmp_path / ".s.png.lock").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert (tmp_path / ".s.npz.lock").exists()
        second = run_cli(*SECTION, "--out", "s.png", "--overwrite", cwd=tmp_path)
        assert first.poll() is None, "the first run ended too soon for the test"
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait(timeout=60)
    assert second.returncode == 2
    line = error_line(second.stderr)
    assert f"--out: 's.png' is being written by another run (pid {first.pid} on " in line
    assert not (tmp_path / "s.png").exists() and not (tmp_path / "s.npz").exists()
    again = run_cli(*SECTION, "--out", "s.png", cwd=tmp_path)      # stale locks: no block
    assert again.returncode == 0, again.stderr
    assert sorted(os.listdir(tmp_path)) == ["s.npz", "s.png"]


# ---- 3. checked before work -----------------------------------------------------------------
def _system_file(tmp_path, vh, name):
    d = vh.describe()
    d["name"] = name
    path = tmp_path / "own.json"
    path.write_text(json.dumps(d))
    return str(path)


@pytest.mark.parametrize("case", ["dangling --data", "long --out", "control character",
                                  "long system name"])
def test_unwritable_names_are_refused_before_any_work(vh, tmp_path, monkeypatch, capsys,
                                                      no_integration, case):
    monkeypatch.chdir(tmp_path)
    args, message = {
        "dangling --data": (["--out", "s.png", "--data", "gone.npz"],
                            "--data: 'gone.npz' is a symbolic link to 'missing/x.npz', which "
                            "does not exist"),
        "long --out": (["--out", "x" * 300 + ".png"],
                       f"--out: the file name '{'x' * 40}'... is 304 bytes long, more than the "
                       "255 bytes a name may have here"),
        "control character": (["--out", "a\nb.png"], "holds control characters ('\\n')"),
        "long system name": (["--system", _system_file(tmp_path, vh, "V" * 260)],
                             "the figure (default --out): the file name 'sos_VVVVVVVV"),
    }[case]
    if case == "dangling --data":
        os.symlink("missing/x.npz", "gone.npz")
    argv = [a for a in SECTION if a not in ("--system", "1991 VH")] if "--system" in args \
        else SECTION
    assert cli.main([*argv, *args]) == cli.EXIT_ERROR
    line = error_line(capsys.readouterr().err)
    assert message in line, line
    assert set(os.listdir(tmp_path)) <= {"gone.npz", "own.json"}   # nothing written


@pytest.mark.parametrize("name, stem", [
    ("sub/evil", "sos_sub-evil"), ("a\nb", "sos_a-b"), ("../up", "sos_up"),
    ("tab\there", "sos_tab-here"),
    # shell-safe: [A-Za-z0-9._-] only, whatever the name holds
    ("Didymos (radar shape)", "sos_Didymos-radarshape"), ("$(rm -rf ~)", "sos_rm-rf"),
    ("a;b&c|d>e", "sos_a-b-c-d-e"), ("O'Brien \"x\"", "sos_O-Brien-x"), ("`id`", "sos_id"),
    ("Šteins", "sos_Steins"), ("Didymos–Dimorphos", "sos_Didymos-Dimorphos"),
    ("(65803) Didymos", "sos_65803-Didymos"), ("-rf", "sos_rf"), ("*?[]", "sos_unnamed"),
    ("α Cen + β", "sos_Cen"), ("x=1,y@2+3", "sos_x-1-y-2-3"), ("v1.2_b", "sos_v1.2_b"),
])
def test_system_names_are_made_safe_in_default_file_names(vh, tmp_path, monkeypatch, name,
                                                          stem):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    args = cli._parser().parse_args(["section", "--system", _system_file(tmp_path, vh, name)])
    assert cli.default_stem(args, "sos", name) == stem
    assert re.fullmatch(r"[A-Za-z0-9._-]+", stem) and shlex.quote(stem) == stem
    out, data = common.output_paths(args, "sos", name)
    common.release_outputs()
    assert (out, data) == (stem + ".png", stem + ".npz")
    assert os.listdir(tmp_path / "sub") == [] and "\n" not in out


@pytest.mark.parametrize("value, power, text", [
    (9.999999999999999e-12, True, "1e-11"), (1e-4, True, "1e-4"), (2.5e-11, True, "2.5e-11"),
    (3e-10, False, "3e-10"), (1e6, False, "1e6"), (1e-5, False, "1e-5"), (5e-4, False, "0.0005"),
    (1000.0, False, "1000"), (-30.0, False, "-30"), (0.1 + 0.2, False, "0.3"),
    (1.0000001, False, "1.0000001"), (1234567.0, False, "1234567"), (2.5e-7, False, "2.5e-7"),
    (1.06, False, "1.06"), (64, False, "64"), (1e22, False, "1e22"),
])
def test_numbers_in_default_names_are_g_style(value, power, text):
    """%g, with more digits (up to 12) only where %g's 6 would change the value; never a
    double's binary noise; exponents short and without "+"."""
    assert common.name_number(value, power=power) == text


@pytest.mark.parametrize("argv, stem", [
    (["--rtol", "1e-11", "--elongation", "1.0000001"], "sos_1991VH_ab1.0000001_rtol1e-11"),
    (["--orbits", "1234567", "--eccentricity", "0.30000000000000004"], "sos_1991VH_e0.3_o1234567"),
    (["--thetadot", "1e-5", "2.5e-7", "1e2"], "sos_1991VH_td1e-5-2.5e-7-100"),
    (["--orbits", "1e6", "--strength", "1e12", "--tide", "secondary"],
     "sos_1991VH_o1e6_tide-secondary_str1e12"),
])
def test_default_names_write_numbers_g_style(argv, stem):
    args = cli._parser().parse_args(["section", *argv])
    assert cli.default_stem(args, "sos", "1991 VH") == stem


def test_default_names_of_catalogued_systems_are_unchanged():
    args = cli._parser().parse_args(["section", "--elongation", "1.06", "--theta-p", "-30",
                                     "--thetadot", "-1", "-2"])
    assert cli.default_stem(args, "sos", "1991 VH") == "sos_1991VH_ab1.06_tp-30_td-1--2"


# ---- 4. the same command again finishes a run ----------------------------------------------
KILL_BEFORE_FIGURE = """
import os, signal, sys
import ti_spinorbit.output.plotting as plotting
plotting.save_figure = lambda ax, path: os.kill(os.getpid(), signal.SIGKILL)
from ti_spinorbit.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_resume_finishes_a_run_killed_between_its_data_file_and_figure(tmp_path, monkeypatch):
    command = [*SECTION, "--out", "s.png", "--resume"]
    script = tmp_path / "kill.py"
    script.write_text(KILL_BEFORE_FIGURE)
    p = subprocess.run([sys.executable, str(script), *command], cwd=tmp_path,
                       env={**os.environ, "MPLBACKEND": "Agg"}, capture_output=True, timeout=600)
    assert p.returncode == -signal.SIGKILL
    assert (tmp_path / "s.npz").exists() and not (tmp_path / "s.png").exists()
    assert C.holds_checkpoint(tmp_path / "s.ckpt")
    first = tso.load(tmp_path / "s.npz")
    monkeypatch.chdir(tmp_path)
    script.unlink()
    assert cli.main(command) == 0                           # the same command again
    assert sorted(os.listdir(tmp_path)) == ["s.npz", "s.png"]
    again = tso.load("s.npz")
    same_arrays(first, again)
    assert again.seconds == first.seconds      # resumed from the finished checkpoint


def test_without_its_checkpoint_an_existing_data_file_is_still_refused(tmp_path, monkeypatch,
                                                                      capsys, no_integration):
    monkeypatch.chdir(tmp_path)
    command = [*SECTION, "--out", "s.png", "--resume"]
    (tmp_path / "s.npz").write_bytes(b"someone else's file")
    assert cli.main(command) == cli.EXIT_ERROR
    assert "'s.npz' already exists" in error_line(capsys.readouterr().err)
    assert (tmp_path / "s.npz").read_bytes() == b"someone else's file"


# ---- 5. read-only checkpoints ---------------------------------------------------------------
@contextlib.contextmanager
def read_only(monkeypatch, folder):
    """Make ``folder`` read-only for this process, whoever runs the tests (root ignores
    chmod): every call that would create, change or delete something inside it raises
    PermissionError, as on a read-only folder or mount."""
    folder = os.path.realpath(folder)

    def inside(p):
        if isinstance(p, int):
            return False
        p = os.path.realpath(os.fsdecode(os.fspath(p)))
        return p == folder or p.startswith(folder + os.sep)

    def deny(p):
        raise PermissionError(errno.EACCES, "Permission denied", os.fspath(p))

    real_open, real_os_open, real_mkdir = builtins.open, os.open, os.mkdir
    writing = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND

    def fake_open(file, mode="r", *a, **k):
        if inside(file) and any(c in mode for c in "wax+"):
            deny(file)
        return real_open(file, mode, *a, **k)

    def fake_os_open(path, flags, *a, **k):
        if inside(path) and flags & writing:
            deny(path)
        return real_os_open(path, flags, *a, **k)

    def fake_mkdir(path, *a, **k):
        if inside(path):
            if os.path.exists(path):
                raise FileExistsError(errno.EEXIST, "File exists", os.fspath(path))
            deny(path)
        return real_mkdir(path, *a, **k)

    def guard(real):
        def fake(*paths, **k):
            for p in paths[:2]:
                if inside(p):
                    deny(p)
            return real(*paths, **k)
        return fake

    with monkeypatch.context() as m:
        m.setattr(builtins, "open", fake_open)
        m.setattr(os, "open", fake_os_open)
        m.setattr(os, "mkdir", fake_mkdir)
        for name in ("replace", "rename", "remove", "unlink", "rmdir"):
            m.setattr(os, name, guard(getattr(os, name)))
        yield


def snapshot(path):
    return {f: (path / f).read_bytes() for f in sorted(os.listdir(path))}


ARGS = dict(orbits=6, rtol=1e-10, window_orbits=2, progress=False)


@pytest.fixture(scope="module")
def whole(vh):
    return tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**ARGS))


@pytest.fixture(scope="module")
def finished(vh, tmp_path_factory):
    path = tmp_path_factory.mktemp("ro") / "run.ckpt"
    tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**ARGS, checkpoint=path,
                                                                 keep_checkpoint=True))
    return path


def test_the_simulated_read_only_folder_refuses_writes(tmp_path, monkeypatch):
    with read_only(monkeypatch, tmp_path):
        for attempt in (lambda: open(tmp_path / "x", "w"),
                        lambda: os.open(tmp_path / "x", os.O_RDWR | os.O_CREAT),
                        lambda: C.claim(tmp_path / "new.ckpt").__enter__()):
            with pytest.raises((PermissionError, C.CheckpointError)):
                attempt()


def test_finished_checkpoint_in_a_read_only_folder_resumes(vh, finished, tmp_path, whole,
                                                           monkeypatch):
    ckpt = tmp_path / "run.ckpt"
    shutil.copytree(finished, ckpt)
    before = snapshot(ckpt)
    with read_only(monkeypatch, ckpt):
        resumed = tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**ARGS, checkpoint=ckpt, resume=True))
    same_arrays(whole, resumed)
    assert snapshot(ckpt) == before                     # nothing written, nothing removed


def test_unfinished_checkpoint_in_a_read_only_folder_is_refused_in_one_line(vh, tmp_path,
                                                                            monkeypatch):
    ckpt = tmp_path / "run.ckpt"

    def stop(fraction):               # after the first window's state is written
        if 0 < fraction < 1:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**{**ARGS, "progress": stop}, checkpoint=ckpt))
    assert C.holds_checkpoint(ckpt)
    before = snapshot(ckpt)
    with read_only(monkeypatch, ckpt), pytest.raises(C.CheckpointError) as info:
        tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**ARGS, checkpoint=ckpt, resume=True))
    text = str(info.value)
    assert "cannot be written and its run is not finished (2 of 2 members still running)" \
        in text and "copy the directory elsewhere" in text and "\n" not in text
    assert snapshot(ckpt) == before


@pytest.mark.skipif(hasattr(os, "geteuid") and os.geteuid() == 0,
                    reason="running as root: chmod does not stop root from writing (the "
                           "simulated read-only folder tests above cover it)")
def test_finished_checkpoint_in_a_chmod_read_only_folder_resumes(vh, finished, tmp_path,
                                                                 whole):
    ckpt = tmp_path / "run.ckpt"
    shutil.copytree(finished, ckpt)
    before = snapshot(ckpt)
    os.chmod(ckpt, 0o555)
    try:
        resumed = tso.surface_of_section(vh, 0.0, [0.83, 1.63], **run_options(**ARGS, checkpoint=ckpt, resume=True))
    finally:
        os.chmod(ckpt, 0o755)
    same_arrays(whole, resumed)
    assert snapshot(ckpt) == before


def test_cli_resume_from_a_read_only_checkpoint_writes_the_outputs(tmp_path, monkeypatch,
                                                                   capsys):
    monkeypatch.chdir(tmp_path)
    command = [*SECTION, "--out", "s.png", "--checkpoint", "ro.ckpt"]
    assert cli.main([*command, "--keep-checkpoint"]) == 0
    first = tso.load("s.npz")
    os.remove("s.npz")
    os.remove("s.png")
    capsys.readouterr()
    loud = [a for a in command if a != "--quiet"]
    with read_only(monkeypatch, tmp_path / "ro.ckpt"):
        assert cli.main([*loud, "--resume"]) == 0
    out = capsys.readouterr().out
    assert "kept checkpoint ro.ckpt (it cannot be removed: Permission denied)" in out
    same_arrays(first, tso.load("s.npz"))


# ---- 6. every one-bit flip ------------------------------------------------------------------
def tiny_archive(path):
    """A 2.7 kB archive (a relaxed libration without its system) that tso.load reads."""
    r = RelaxedLibration(centre_thetadot_p=1.0, amplitude=0.1, extent=0.01, psi_A=-0.2,
                         psi_A_effective=-0.21, omega0=0.8, omega0_effective=0.79, iterations=1,
                         converged=True, candidates=[np.array([0.9, 1.0, 1.1])],
                         extents=[np.array([0.3, 0.01, 0.2])], lengths=np.array([10.0, 20.0]),
                         centres_by_length=np.array([1.0, 1.0]),
                         amplitudes_by_length=np.array([0.1, 0.1]))
    return r, io.save(r, path)


def test_every_bit_flip_of_a_small_archive_is_one_archive_error(tmp_path):
    """All 8 x 2.7 k flips (about 12 s): each one raises ArchiveError (one line naming the
    file) or loads the same result (a flip in a field zip readers ignore); no other error
    type, no changed number."""
    result, path = tiny_archive(tmp_path / "tiny.npz")
    data = open(path, "rb").read()
    assert len(data) < 3000
    bad = tmp_path / "flipped.npz"
    outcomes = {"refused": 0, "identical": 0}
    for bit in range(8 * len(data)):
        flipped = bytearray(data)
        flipped[bit // 8] ^= 1 << (bit % 8)
        bad.write_bytes(flipped)
        try:
            loaded = tso.load(bad)
        except ArchiveError as exc:
            assert str(exc).startswith(f"'{bad}'") and "\n" not in str(exc), (bit, exc)
            outcomes["refused"] += 1
        except Exception as exc:   # noqa: BLE001 - the point: nothing else may come out
            pytest.fail(f"bit {bit}: {type(exc).__module__}.{type(exc).__name__}: {exc}")
        else:
            same_arrays(result, loaded)
            assert loaded.amplitude == result.amplitude
            outcomes["identical"] += 1
    assert outcomes["refused"] > 0.8 * 8 * len(data)


def _state_flips(data):
    """(byte, bit) of a stored .npz, every byte flipped at least once: every bit of the end
    record and, for the first, a middle and the last entry, of its local header, directory
    record and .npy magic, header length and header dict (where the readers interpret what
    they read; the other entries have the same layout); one rotating bit of every other byte
    (their structures, header padding, the numbers and the JSON text, whose flips end in the
    same CRC-32 check)."""
    import io as _io
    import struct

    every = np.zeros(len(data), dtype=bool)
    every[data.rindex(b"PK\x05\x06"):] = True                     # end of central directory
    with zipfile.ZipFile(_io.BytesIO(bytes(data))) as zf:
        infos, record = zf.infolist(), zf.start_dir
    chosen = {0, len(infos) // 2, len(infos) - 1}
    for k, info in enumerate(infos):           # directory records are in the entries' order
        size = 46 + sum(struct.unpack("<HHH", data[record + 28:record + 34]))
        if k in chosen:
            off = info.header_offset
            n, m = struct.unpack("<HH", data[off + 26:off + 30])
            start = off + 30 + n + m
            every[off:data.index(b"}", start, start + info.compress_size) + 1] = True
            every[record:record + size] = True
        record += size
    return [(j, b) for j in range(len(data)) for b in (range(8) if every[j] else [j % 8])]


def test_bit_flips_of_a_checkpoint_state_are_checkpoint_damaged(vh, tmp_path):
    """Flips of a one-member checkpoint's state.npz (about 10 k): each is
    CheckpointDamaged (one line) or loads the same state; never RuntimeError, TokenError,
    a changed number."""
    ckpt = tmp_path / "one.ckpt"
    tso.surface_of_section(vh, 0.0, [1.0], orbits=1, rtol=1e-8, indicators=False,
                           run=tso.Run(window_orbits=1, checkpoint=ckpt, progress=False,
                                       keep_checkpoint=True))
    with np.load(ckpt / C.STATE) as f:
        header = json.loads(str(f["header"]))
    settings, fingerprint = header["settings"], header["fingerprint"]
    good = C.load(ckpt, settings, fingerprint)
    data = (ckpt / C.STATE).read_bytes()
    assert len(data) < 8000
    flips = _state_flips(data)
    assert len({j for j, _ in flips}) == len(data)         # every byte flipped at least once
    damaged = 0
    for j, b in flips:
        flipped = bytearray(data)
        flipped[j] ^= 1 << b
        (ckpt / C.STATE).write_bytes(flipped)
        try:
            state = C.load(ckpt, settings, fingerprint)
        except C.CheckpointDamaged as exc:
            assert str(exc).startswith("checkpoint damaged: ") and "\n" not in str(exc)
            damaged += 1
        except Exception as exc:   # noqa: BLE001
            pytest.fail(f"byte {j} bit {b}: {type(exc).__module__}.{type(exc).__name__}: {exc}")
        else:
            for k in C._ARRAYS:
                assert state[k].dtype == good[k].dtype, k
                np.testing.assert_array_equal(state[k], good[k], err_msg=k)
    assert damaged > 0.7 * len(flips)


def _set_encrypted_flag(path):
    """Set the zip 'encrypted' bit of the first entry, in the local header and directory."""
    data = bytearray(open(path, "rb").read())
    data[6] |= 1                                          # local header, flag bits
    central = data.index(b"PK\x01\x02")
    data[central + 8] |= 1
    open(path, "wb").write(data)


def _unbalanced_header(path, entry):
    """Rewrite ``entry`` with a .npy header whose brackets do not close (tokenize.TokenError
    inside numpy's parser)."""
    text = b"{'descr': '<f8', 'fortran_order': False, 'shape': (2, "
    text += b" " * (118 - len(text)) + b"\n"
    blob = b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text + bytes(16)
    with zipfile.ZipFile(path) as zf:
        items = [(i, zf.read(i)) for i in zf.infolist()]
    with zipfile.ZipFile(path, "w") as zf:
        for info, payload in items:
            zf.writestr(info, blob if info.filename == entry else payload)


def test_the_two_leaks_found_by_fuzzing_are_archive_errors(tmp_path, vh):
    _, path = tiny_archive(tmp_path / "a.npz")
    _set_encrypted_flag(path)
    with pytest.raises(ArchiveError, match="'metadata.npy' is flagged as encrypted"):
        tso.load(path)
    _, path = tiny_archive(tmp_path / "b.npz")
    _unbalanced_header(path, "lengths.npy")
    with pytest.raises(ArchiveError, match=r"'lengths.npy' has a bad .npy header \(TokenError\)"):
        tso.load(path)
    ckpt = tmp_path / "c.ckpt"
    tso.surface_of_section(vh, 0.0, [1.0], orbits=1, rtol=1e-8, indicators=False,
                           run=tso.Run(checkpoint=ckpt, progress=False, keep_checkpoint=True))
    with np.load(ckpt / C.STATE) as f:
        header = json.loads(str(f["header"]))
    _set_encrypted_flag(ckpt / C.STATE)
    with pytest.raises(C.CheckpointDamaged, match="flagged as encrypted"):
        C.load(ckpt, header["settings"], header["fingerprint"])


# ---- 7. edited files ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def saved(vh, chaos_map, parameter_map, overlap_scan, relaxed_libration, tmp_path_factory):
    folder = tmp_path_factory.mktemp("edited")
    perturbed = tso.time_series(vh, 0.0, [0.8], orbits=1, samples_per_orbit=8, rtol=1e-9,
                                states=True,
                                perturbations=[tso.Tides(body="secondary", time_lag=600,                                                          strength=1e6)],
                                run=tso.Run(progress=False))
    kinds = {"time_series": perturbed, "chaos_map": chaos_map, "parameter_map": parameter_map,
             "overlap_scan": overlap_scan, "relaxed_libration": relaxed_libration}
    return {k: io.save(r, folder / f"{k}.npz") for k, r in kinds.items()}


EDITS = {
    "status code 9": ("time_series", {"status": np.array([9], np.int32)},
                      "field 'status' holds code 9, outside 0.."),
    "status code -1": ("chaos_map", {"status": -np.ones((2, 2), np.int32)},
                       "field 'status' holds code -1, outside 0.."),
    "status as float": ("chaos_map", {"status": np.ones((2, 2))},
                        "field 'status' holds float64, not integer"),
    "nested section status": ("chaos_map", {"section/status": np.full(4, 42, np.int32)},
                              "section field 'status' holds code 42"),
    "attitude class 7": ("time_series", {"attitude_class": np.array([7], np.int8)},
                         "field 'attitude_class' holds code 7, outside -1..3"),
    "map attitude class": ("chaos_map", {"attitude_class": np.full((2, 2), 5, np.int8)},
                           "field 'attitude_class' holds code 5"),
    "work array short": ("time_series", {"work": np.zeros((1, 3))},
                         "field 'work' has shape (1, 3), but its axis 1 must have"),
    "work array text": ("time_series", {"work": np.full((1, 9), "x")},
                        "field 'work' holds <U1, not float"),
    "states of 29 columns": ("time_series", {"states": np.zeros((1, 9, 29))},
                             "field 'states' has shape (1, 9, 29), but its axis 2 must have 30"),
    "initial_states 1-D": ("time_series", {"initial_states": np.zeros(30)},
                           "field 'initial_states' has shape (30,), not 2-dimensional"),
    "megno of another grid": ("chaos_map", {"megno": np.zeros((3, 2))},
                              "field 'megno' has shape (3, 2), but its axis 0 must have 2"),
    "classification numbers": ("parameter_map", {"classification": np.zeros((2, 2, 2))},
                               "field 'classification' holds float 0.0, not text"),
    "classification of another grid": ("chaos_map", {"classification": np.full((2, 3), "x")},
                                       "field 'classification' has shape (2, 3)"),
    "fraction_by_length 2-D": ("parameter_map", {"fraction_by_length": np.zeros((3, 2))},
                               "field 'fraction_by_length' has shape (3, 2), not 3-dimensional"),
    "overlaps as int": ("overlap_scan", {"overlaps": np.array([1, 0])},
                        "field 'overlaps' holds int64, not bool"),
    "overlap evidence short": ("overlap_scan", {"overlaps_by_length": np.zeros((2, 1), bool)},
                               "field 'overlaps_by_length' has shape (2, 1)"),
    "libration extents short": ("relaxed_libration", {"extents/1": np.zeros(2)},
                                "fields 'candidates' and 'extents' do not pair up"),
}


@pytest.mark.parametrize("case", list(EDITS))
def test_edited_arrays_are_refused_on_load_in_one_line(saved, tmp_path, case):
    kind, arrays, message = EDITS[case]
    meta = io.read_metadata(saved[kind])
    with np.load(saved[kind]) as f:
        entries = {k: f[k] for k in f.files if k != "metadata"}
    assert set(arrays) <= set(entries), sorted(entries)
    edited = io.write_archive(tmp_path / "edited.npz", {**entries, **arrays}, meta)
    with pytest.raises(ArchiveError) as info:
        tso.load(edited)
    text = str(info.value)
    assert text.startswith(f"'{edited}' is damaged or edited: ") and message in text, text
    assert "\n" not in text and len(text) < 400
    tso.load(saved[kind])                                    # the unedited file loads


# ---- 8. to_xarray carries every array field --------------------------------------------------
#: Fields that become coordinates under another name, or are flattened (relaxed libration).
COORDINATE_OF = {"elongations": "elongation", "eccentricities": "eccentricity",
                 "fraction_lengths": "length", "lengths": "length"}
FLATTENED = {"candidates": "thetadot_p", "extents": "extent"}


@pytest.fixture(scope="module")
def with_states(vh):
    return tso.time_series(vh, 0.0, [0.83, 1.63], orbits=1, samples_per_orbit=8, rtol=1e-9,
                           states=True, run=tso.Run(progress=False))


@pytest.fixture(scope="module")
def tilted(vh):
    return tso.surface_of_section(vh, initial_states=[vh.tilted_start(0.0, 1.0, roll=5.0)],
                                  orbits=2, rtol=1e-9, run=tso.Run(progress=False))


@pytest.mark.parametrize("kind", ["with_states", "tilted", "chaos_map", "parameter_map",
                                  "overlap_scan", "relaxed_libration"])
def test_to_xarray_round_trips_every_array_field_with_its_unit(kind, request, tmp_path):
    pytest.importorskip("xarray")
    result = request.getfixturevalue(kind)
    for ds in (tso.to_xarray(result), tso.to_xarray(io.save(result, tmp_path / "r.npz"))):
        for f in dataclasses.fields(result):
            value = getattr(result, f.name)
            if isinstance(value, list) and f.name in FLATTENED:
                value, name = np.concatenate(value), FLATTENED[f.name]
            elif isinstance(value, np.ndarray):
                name = COORDINATE_OF.get(f.name, f.name)
            else:
                continue
            assert name in ds.variables, f"{f.name} missing from to_xarray"
            expected = value.astype(str) if value.dtype == object else value
            np.testing.assert_array_equal(ds[name].values, expected, err_msg=f.name)
            assert ds[name].attrs.get("units") == f.metadata["unit"], f.name


def test_to_xarray_labels_state_columns_and_attitude_classes(with_states, chaos_map):
    pytest.importorskip("xarray")
    ds = tso.to_xarray(with_states)
    assert ds["states"].dims == ("member", "sample", "element")
    assert ds["initial_states"].dims == ("member", "element")
    assert list(ds["element"].values[:4]) == ["R_x", "R_y", "R_z", "V_x"]
    assert ds["element"].values[7] == "primary_attitude_01"
    assert ds["element_unit"].sel(element="secondary_omega_z").item() == \
        "rad/s (secondary body frame)"
    np.testing.assert_array_equal(ds["states"].sel(member=1, element="V_y"),
                                  with_states.states[1, :, 4])
    assert list(ds["attitude_class_name"].values) == with_states.attitude_class_names
    ds = tso.to_xarray(chaos_map)
    assert ds["fraction_by_length"].dims == ("length",)
    assert ds["length"].values.tolist() == chaos_map.fraction_lengths.tolist()
    assert ds["max_tilt"].dims == ("theta_p", "thetadot_p")


# ---- 9. one-line type errors ----------------------------------------------------------------
@pytest.mark.parametrize("bad", [123, 1.5, ["dir"], b"bytes"], ids=repr)
def test_checkpoint_that_is_not_a_path_is_a_type_error(vh, bad):
    with pytest.raises(TypeError) as info:
        tso.surface_of_section(vh, 0.0, [1.0], orbits=1,
                               run=tso.Run(checkpoint=bad, progress=False))
    text = str(info.value)
    assert text.startswith("checkpoint must be a directory path (str or os.PathLike) or None "
                           f"(got {type(bad).__name__} ") and "\n" not in text
    with pytest.raises(TypeError, match="^checkpoint must be a directory path"):
        C.Launches(bad)
    with pytest.raises(TypeError, match="^checkpoint must be a directory path"):
        C.check_path(bad)
    assert C.check_path(None) is None


@pytest.mark.parametrize("extra, message", [
    (["a"], "extra must be a dict of JSON-able metadata, {name: value} (got list ['a'])"),
    ("note", "extra must be a dict of JSON-able metadata, {name: value} (got str 'note')"),
    ({1: "x"}, "extra: metadata keys must be str (got int 1)")])
def test_save_extra_that_is_not_a_dict_is_a_type_error(small, tmp_path, extra, message):
    with pytest.raises(TypeError) as info:
        io.save(small, tmp_path / "x.npz", extra=extra)
    assert str(info.value) == message
    assert os.listdir(tmp_path) == []


def test_save_path_that_is_not_a_path_is_a_type_error(small):
    with pytest.raises(TypeError, match=r"^path must be a file name \(str or os.PathLike\) or "
                                        r"a binary file object \(got int 123\)$"):
        io.save(small, 123)
