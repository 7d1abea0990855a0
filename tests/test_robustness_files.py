"""Files and checkpoints lose nothing: a checkpoint directory has one
writer (a second is refused at once, naming the holder; a killed holder never blocks), a
checkpoint is never overwritten by accident, any damage to a checkpoint is one
"checkpoint damaged: ..." line (exit status 2 on the CLI), ``tso.load`` raises one
``ArchiveError`` line for every malformed archive without allocating what a hostile header
claims, and ``tso.save`` works for every valid system.

Tiny runs: 1991 VH, 2 members, 20 orbits in windows of 4 (5 records files)."""

import dataclasses
import hashlib
import io as _io
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import tracemalloc
import zipfile

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine import checkpoint as C
from ti_spinorbit.output import io
from ti_spinorbit.output.io import ArchiveError

from conftest import run_cli, run_options

STARTS = [0.83, 1.63]
ARGS = dict(orbits=20, rtol=1e-10, window_orbits=4)
#: Windows are adaptive (1, 2, 4, 4, ... orbits, shortened when slow): count the files.
MAX_WINDOWS = 64


def windows(ckpt):
    """Windows a checkpoint holds records of (one records file each)."""
    return len(list(ckpt.glob("records-*.npz")))


def run(vh, ckpt=None, starts=STARTS, **kw):
    return tso.surface_of_section(vh, 0.0, starts, **run_options(**{**ARGS, **kw}, checkpoint=ckpt))


def assert_same(a, b):
    for f in dataclasses.fields(a):
        x = getattr(a, f.name)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, getattr(b, f.name), err_msg=f.name)


@pytest.fixture(scope="module")
def whole(vh):
    """The uninterrupted run without a checkpoint."""
    return run(vh)


@pytest.fixture(scope="module")
def finished(vh, tmp_path_factory):
    """A finished checkpoint directory (copy it before changing it)."""
    path = tmp_path_factory.mktemp("template") / "run.ckpt"
    run(vh, path, keep_checkpoint=True)
    return path


@pytest.fixture
def ckpt(finished, tmp_path):
    path = tmp_path / "run.ckpt"
    shutil.copytree(finished, path)
    return path


def snapshot(path):
    """name -> bytes of every checkpoint file (the lock file aside)."""
    return {f: (path / f).read_bytes() for f in sorted(os.listdir(path)) if f != C.LOCK}


def env():
    return dict(os.environ, MPLBACKEND="Agg")


CLI_SECTION = ["section", "--system", "1991 VH", "--orbits", "20", "--thetadot", "0.83",
               "1.63", "--rtol", "1e-10", "--out", "s.png", "--quiet"]


def error_line(p):
    """The one stderr line of a failed CLI run."""
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1, p.stderr
    return lines[0]


# ---- 1. locking ---------------------------------------------------------------------------
def test_held_lock_refuses_a_second_writer_at_once_and_names_the_holder(vh, ckpt):
    before = snapshot(ckpt)
    with C.claim(ckpt, resume=True):
        owner = json.loads((ckpt / C.OWNER).read_text())
        assert (owner["pid"], owner["host"]) == (os.getpid(), socket.gethostname())
        assert owner["started_utc"] and "command" in owner
        started = time.perf_counter()
        with pytest.raises(C.CheckpointLocked,
                           match=rf"is locked by another run: pid {os.getpid()} on "
                                 rf"{socket.gethostname()}, started .*; wait for it to end"):
            run(vh, ckpt, resume=True)
        assert time.perf_counter() - started < 2.0               # refused, not queued
    assert snapshot(ckpt) == before                              # nothing written
    assert not (ckpt / C.OWNER).exists()                         # identity removed on release
    run(vh, ckpt, resume=True)                                   # free again


HOLD = """
import sys
from ti_spinorbit.engine import checkpoint as C
with C.claim(sys.argv[1], resume=True):
    print("held", flush=True)
    sys.stdin.read()
"""


def wait_held(p):
    """Wait for the subprocess ``p`` to print "held" (Taichi prints a banner first)."""
    for line in p.stdout:
        if line.strip() == "held":
            return p
    p.wait()
    raise AssertionError(f"the lock holder exited with status {p.returncode}")


def holder(path):
    p = subprocess.Popen([sys.executable, "-c", HOLD, str(path)], stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True, env=env())
    try:
        return wait_held(p)
    except BaseException:
        p.kill()
        p.wait()
        raise


def test_lock_held_by_another_process_then_killed(vh, ckpt, whole):
    p = holder(ckpt)
    try:
        with pytest.raises(C.CheckpointLocked, match=rf"pid {p.pid} on {socket.gethostname()}"):
            run(vh, ckpt, resume=True)
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    assert (ckpt / C.OWNER).exists()               # the killed holder's identity is left ...
    assert_same(run(vh, ckpt, resume=True), whole)    # ... and its lock does not block


def test_cli_second_writer_is_refused_with_one_line(ckpt, tmp_path):
    p = holder(ckpt)
    try:
        r = run_cli(*CLI_SECTION, "--checkpoint", str(ckpt), "--resume", cwd=tmp_path)
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    assert r.returncode == 2
    assert error_line(r).startswith(f"ti-spinorbit section: error: checkpoint '{ckpt}' is "
                                     f"locked by another run: pid {p.pid} on ")


RUNNING = """
import sys
import ti_spinorbit as tso
def progress(fraction):
    if fraction < 1:
        print("held", flush=True)
        sys.stdin.readline()
args = {args}
window_orbits = args.pop("window_orbits")
tso.surface_of_section(tso.catalog.system("1991 VH"), 0.0, {starts}, **args,
                       run=tso.Run(checkpoint=sys.argv[1], progress=progress,
                                   window_orbits=window_orbits))
"""


def test_a_running_integration_holds_the_lock_between_windows(vh, tmp_path, whole):
    """Two real runs on one directory: the second is refused while the first is between
    windows, and the first then finishes to the uninterrupted result."""
    ckpt = tmp_path / "two.ckpt"
    code = RUNNING.format(starts=STARTS, args=ARGS)
    p = subprocess.Popen([sys.executable, "-c", code, str(ckpt)], stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, text=True, env=env())
    try:
        wait_held(p)
        owner = json.loads((ckpt / C.OWNER).read_text())
        assert owner["pid"] == p.pid and owner["command"].startswith("-c")
        for resume in (True, False):
            with pytest.raises(C.CheckpointLocked, match=rf"locked by another run: pid {p.pid} "):
                run(vh, ckpt, resume=resume, overwrite=True)
        p.stdin.write("\n" * MAX_WINDOWS)
        p.stdin.close()
        assert p.wait(timeout=300) == 0
    finally:
        p.kill()
        p.wait()
    assert not (ckpt / C.OWNER).exists()
    assert_same(run(vh, ckpt, resume=True), whole)


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_lock_released_when_the_run_raises(vh, tmp_path, whole, exc):
    ckpt = tmp_path / "r.ckpt"
    calls = []

    def progress(fraction):
        calls.append(fraction)
        if len(calls) == 2:
            raise exc("stop here")

    with pytest.raises(exc, match="stop here"):
        run(vh, ckpt, progress=progress)
    assert not (ckpt / C.OWNER).exists()
    with C.claim(ckpt, resume=True):                 # the lock is free: taken at once
        pass
    assert_same(run(vh, ckpt, resume=True), whole)


def test_soft_lock_of_a_dead_process_does_not_block(vh, ckpt, whole, monkeypatch):
    """Where the file system has no OS locks filelock uses a marker file; one left by a killed
    process on this host is broken, not waited on."""
    import filelock

    (ckpt / C.LOCK).unlink(missing_ok=True)     # the OS lock's (unlocked) file
    script = ("import filelock, sys; l = filelock.SoftFileLock(sys.argv[1]); "
              "l.acquire(timeout=60); print('held', flush=True); sys.stdin.read()")
    p = subprocess.Popen([sys.executable, "-c", script, str(ckpt / C.LOCK)],
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        wait_held(p)
        monkeypatch.setattr(C, "_lock_class", lambda: filelock.SoftFileLock)
        with pytest.raises(C.CheckpointLocked, match="is locked by another run: holder unknown "
                                                     rf"\({C.OWNER} missing or unreadable\)"):
            run(vh, ckpt, resume=True)
    finally:
        p.send_signal(signal.SIGKILL)
        p.wait()
    assert_same(run(vh, ckpt, resume=True), whole)


# ---- 2. no overwrite ------------------------------------------------------------------------
def entry_points(vh, ckpt, **kw):
    return {
        "section": lambda: run(vh, ckpt, **kw),
        "time_series": lambda: tso.time_series(vh, 0.0, STARTS, samples_per_orbit=4,
                                               **run_options(**ARGS, **kw, checkpoint=ckpt)),
        "chaos_map": lambda: tso.chaos_map(vh, [0.0, 90.0], [1.0], orbits=8,
                                           **run_options(**kw, checkpoint=ckpt)),
        "parameter_map": lambda: tso.parameter_map("1991 VH", [1.2], [0.05], orbits=8,
                                                   theta_p=[0.0], thetadot_p=[1.0],
                                                   **run_options(**kw, checkpoint=ckpt)),
    }


@pytest.mark.parametrize("entry", ["section", "time_series", "chaos_map", "parameter_map"])
def test_checkpoint_of_another_run_is_not_overwritten(vh, ckpt, entry):
    before = snapshot(ckpt)
    with pytest.raises(C.CheckpointExists,
                       match=r"already holds a checkpoint of an earlier run; pass "
                             r"Run\(resume=True\) to continue it or Run\(overwrite=True\) "
                             r"to replace it"):
        entry_points(vh, ckpt)[entry]()
    assert snapshot(ckpt) == before
    assert isinstance(C.CheckpointExists("x"), ValueError)


@pytest.mark.parametrize("entry", ["section", "chaos_map"])
def test_overwrite_checkpoint_replaces_it(vh, ckpt, entry):
    result = entry_points(vh, ckpt, overwrite=True)[entry]()
    again = entry_points(vh, ckpt, resume=True, keep_checkpoint=True)[entry]()   # finished
    if entry == "section":
        assert_same(result, again)
    else:
        np.testing.assert_array_equal(result.megno, again.megno)
    # a map checkpoints each of its lengths in launch-kkk: the old run's files in the
    # directory itself go, and each launch holds only its own records
    folders = [ckpt] if entry == "section" else sorted(ckpt.glob("launch-*"))
    if entry != "section":
        assert len(folders) == 3 and not (ckpt / C.STATE).exists()
        assert not [f for f in os.listdir(ckpt) if f.startswith("records-")]
    for folder in folders:
        with np.load(folder / C.STATE) as d:
            launches = json.loads(str(d["header"]))["launches"]
        assert sorted(f for f in os.listdir(folder) if f.startswith("records-")) == \
            [f"records-{k:06d}.npz" for k in range(launches)]    # no records of the old run


def test_cli_refuses_overwrite_and_overwrites_on_request(ckpt, tmp_path):
    before = snapshot(ckpt)
    r = run_cli(*CLI_SECTION, "--checkpoint", str(ckpt), cwd=tmp_path)
    assert r.returncode == 2
    assert error_line(r) == (f"ti-spinorbit section: error: checkpoint '{ckpt}' already holds a "
                             "checkpoint of an earlier run; pass --resume to continue it or "
                             "--overwrite-checkpoint to replace it (refused: a run would "
                             "destroy it)")
    assert snapshot(ckpt) == before
    assert not (tmp_path / "s.npz").exists()
    r = run_cli(*CLI_SECTION, "--checkpoint", str(ckpt), "--overwrite-checkpoint",
                "--keep-checkpoint", cwd=tmp_path)          # kept: removed after success else
    assert r.returncode == 0, r.stderr
    assert snapshot(ckpt) != before and (tmp_path / "s.npz").exists()


@pytest.mark.parametrize("leftovers", [["records-000000.npz"], ["state.npz.tmp-4242"],
                                       ["records-000000.npz", "records-000001.npz.tmp-99"]])
@pytest.mark.parametrize("resume", [True, False])
def test_directory_killed_before_its_first_state_starts_afresh(vh, tmp_path, whole, leftovers,
                                                               resume):
    ckpt = tmp_path / "k.ckpt"
    ckpt.mkdir()
    for name in leftovers:
        (ckpt / name).write_bytes(b"half-written by a killed run")
    assert_same(run(vh, ckpt, resume=resume, keep_checkpoint=True), whole)
    assert not [f for f in os.listdir(ckpt) if ".tmp-" in f]        # stray temp files cleaned
    assert_same(run(vh, ckpt, resume=True), whole)                   # and a real checkpoint now


def test_stray_temp_files_are_cleaned_on_resume(vh, ckpt, whole):
    (ckpt / "state.npz.tmp-31337").write_bytes(b"x")
    assert_same(run(vh, ckpt, resume=True), whole)
    assert not (ckpt / "state.npz.tmp-31337").exists()


def test_checkpoint_path_that_is_a_file_is_refused_untouched(vh, tmp_path):
    f = tmp_path / "notes.txt"
    f.write_text("mine")
    for resume in (False, True):
        with pytest.raises(C.CheckpointError, match="is a file, not a ti_spinorbit checkpoint "
                                                    "directory"):
            run(vh, f, resume=resume)
    assert f.read_text() == "mine"


def test_resume_in_a_directory_of_other_files_is_refused(vh, tmp_path):
    d = tmp_path / "papers"
    d.mkdir()
    (d / "draft.tex").write_text("x")
    with pytest.raises(C.CheckpointError, match=r"is not a ti_spinorbit checkpoint directory "
                                                r"\(no state.npz; holds draft.tex\)"):
        run(vh, d, resume=True)
    assert (d / "draft.tex").read_text() == "x"


# ---- 3. damaged checkpoints -----------------------------------------------------------------
def rewrite_zip(path, rename=None, drop=None, replace=None):
    """Rewrite a zip with one entry renamed, dropped or replaced (a valid zip again)."""
    with zipfile.ZipFile(path) as zf:
        items = [(i.filename, zf.read(i)) for i in zf.infolist()]
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in items:
            if name == drop:
                continue
            if replace and name in replace:
                data = replace[name]
            zf.writestr((rename or {}).get(name, name), data)


def rewrite_state(ckpt, meta=None, **arrays):
    """Rewrite state.npz with header keys ``meta`` and ``arrays`` changed."""
    with np.load(ckpt / C.STATE) as d:
        content = {k: d[k] for k in d.files}
    if meta is not None:
        content["header"] = np.array(json.dumps({**json.loads(str(content["header"])), **meta}))
    content.update(arrays)
    np.savez(ckpt / C.STATE, **content)


def rehash(ckpt):
    """Record the digests of the records files as they are now (as a forger would), so the
    damage below is met by the structural checks."""
    digests = [hashlib.sha256((ckpt / f"records-{k:06d}.npz").read_bytes()).digest()
               for k in range(windows(ckpt))]
    rewrite_state(ckpt, records_sha256=np.array(digests, dtype="S32"))


def fake_npy(shape, descr="<f8", payload=b""):
    """An .npy entry whose header claims ``shape`` (valid syntax) followed by ``payload``."""
    buf = _io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False,
                                               "shape": shape})
    return buf.getvalue() + payload


def flip_entry(path, name):
    """Flip a byte inside the compressed data of one zip entry."""
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo(name)
    data = bytearray(path.read_bytes())
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
    data[start + info.compress_size // 2] ^= 0xFF
    path.write_bytes(bytes(data))


def npy(array):
    buf = _io.BytesIO()
    np.save(buf, array)
    return buf.getvalue()


def flip(path, where=0.5):
    data = bytearray(path.read_bytes())
    data[int(len(data) * where)] ^= 0x40
    path.write_bytes(bytes(data))


def swap(a, b):
    a_bytes = a.read_bytes()
    a.write_bytes(b.read_bytes())
    b.write_bytes(a_bytes)


R1, R2 = "records-000001.npz", "records-000002.npz"
DAMAGE = {
    "renamed entry": (lambda c: rewrite_zip(c / R1, rename={"events_data.npy": "evts.npy"}),
                      f"{R1} is not the file this run wrote"),
    "renamed entry, digest forged": (
        lambda c: (rewrite_zip(c / R1, rename={"events_data.npy": "evts.npy"}), rehash(c)),
        f"{R1} lacks events_data"),
    "dropped entry, digest forged": (
        lambda c: (rewrite_zip(c / R2, drop="samples_counts.npy"), rehash(c)),
        f"{R2} lacks samples_counts"),
    "flipped byte": (lambda c: flip(c / R2), f"{R2} is not the file this run wrote"),
    "flipped data byte, digest forged": (
        lambda c: (flip_entry(c / R2, "events_data.npy"), rehash(c)),
        f"{R2} is damaged or not a checkpoint (BadZipFile: Bad CRC-32"),
    "truncated records": (lambda c: (c / R1).write_bytes((c / R1).read_bytes()[:200]),
                          f"{R1} is not the file this run wrote"),
    "swapped records files": (lambda c: swap(c / R1, c / R2),
                              f"{R1} is not the file this run wrote"),
    "missing records file": (lambda c: (c / "records-000004.npz").unlink(),
                             "records-000004.npz is missing"),
    "member out of range, digest forged": (
        lambda c: (rewrite_zip(c / R1, replace={"events_members.npy": npy(np.array([0, 7]))}),
                   rehash(c)),
        f"{R1}: events members, counts and data disagree"),
    "huge npy header, digest forged": (
        lambda c: (rewrite_zip(c / R1, replace={"events_data.npy": fake_npy((2**40, 31))}),
                   rehash(c)),
        f"{R1} is damaged or not a checkpoint (ArchiveError: "),
    "truncated state": (lambda c: (c / C.STATE).write_bytes((c / C.STATE).read_bytes()[:300]),
                        "state.npz is damaged or not a checkpoint"),
    # a byte of an entry's data (a fixed fraction of the file can land on a local-header
    # field the reader never uses, e.g. the extra-field length: nothing damaged then)
    "flipped byte in state": (lambda c: flip_entry(c / C.STATE, "y.npy"),
                              "state.npz is damaged or not a checkpoint"),
    "renamed state entry": (lambda c: rewrite_zip(c / C.STATE, rename={"y.npy": "z.npy"}),
                            "state.npz lacks y"),
    "state header not JSON": (lambda c: rewrite_state(c, header=np.array("{oops")),
                              "state.npz is damaged or not a checkpoint (JSONDecodeError"),
    "state header nested": (lambda c: rewrite_state(c, **{"header": np.array("[" * 50000)}),
                            "state.npz is damaged or not a checkpoint (RecursionError"),
    "digest table shortened": (
        lambda c: rewrite_state(c, records_sha256=np.zeros(2, dtype="S32")),
        "records_sha256 do not fit 2 members and "),
    "state rows edited": (lambda c: rewrite_state(c, y=np.zeros((3, 30))),
                          "y do not fit 2 members"),
    "state launches edited": (lambda c: rewrite_state(c, meta={"launches": "five"}),
                              "state.npz header is incomplete"),
}


@pytest.mark.parametrize("damage", list(DAMAGE))
def test_damaged_checkpoint_is_one_line(vh, ckpt, damage):
    make, message = DAMAGE[damage]
    make(ckpt)
    with pytest.raises(C.CheckpointDamaged) as info:
        run(vh, ckpt, resume=True)
    text = str(info.value)
    assert text.startswith(f"checkpoint damaged: '{ckpt}': ")
    assert message in text
    assert text.endswith("delete the directory to start the run afresh")
    assert "\n" not in text and isinstance(info.value, ValueError)


def test_huge_header_claim_is_refused_before_allocating(ckpt):
    """A records entry whose header claims 2**40 x 31 doubles (250 TiB) is refused from its
    sizes, before anything is allocated."""
    rewrite_zip(ckpt / R1, replace={"events_data.npy": fake_npy((2**40, 31), payload=bytes(64))})
    rehash(ckpt)
    tracemalloc.start()
    with pytest.raises(C.CheckpointDamaged, match="has a header for shape"):
        C.load(ckpt, _settings(ckpt), _fingerprint(ckpt))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 64 * 2**20


def _header(ckpt):
    with np.load(ckpt / C.STATE) as d:
        return json.loads(str(d["header"]))


def _settings(ckpt):
    return _header(ckpt)["settings"]


def _fingerprint(ckpt):
    return _header(ckpt)["fingerprint"]


def test_checkpoint_of_another_package_version_is_refused(vh, ckpt):
    rewrite_state(ckpt, meta={"version": "0.0.1"})
    with pytest.raises(C.CheckpointError,
                       match=rf"was written by ti_spinorbit '0.0.1', this is {tso.__version__}: "
                             "a resumed run would not equal an uninterrupted one"):
        run(vh, ckpt, resume=True)


def test_intact_checkpoint_loads_with_its_digests(ckpt):
    state = C.load(ckpt, _settings(ckpt), _fingerprint(ckpt))
    assert state["launches"] == windows(ckpt) >= 5
    assert state["records_sha256"] == [hashlib.sha256((ckpt / f"records-{k:06d}.npz")
                                                      .read_bytes()).hexdigest()
                                       for k in range(windows(ckpt))]


def test_cli_damaged_checkpoint_exits_2_with_one_line(ckpt, tmp_path):
    # the CLI's default window (16 orbits) differs from the fixture's: a CLI checkpoint
    r = run_cli(*CLI_SECTION, "--checkpoint", str(tmp_path / "c.ckpt"), "--keep-checkpoint",
                cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rewrite_zip(tmp_path / "c.ckpt" / "records-000000.npz",
                rename={"events_data.npy": "x.npy"})
    r = run_cli(*CLI_SECTION, "--checkpoint", str(tmp_path / "c.ckpt"), "--resume",
                "--overwrite", cwd=tmp_path)
    assert r.returncode == 2
    assert error_line(r).startswith("ti-spinorbit section: error: checkpoint damaged: ")
    assert "records-000000.npz is not the file this run wrote" in r.stderr


# ---- 4. tso.load on malformed archives ------------------------------------------------------
@pytest.fixture(scope="module")
def archive(vh, tmp_path_factory):
    result = tso.surface_of_section(vh, 0.0, STARTS, orbits=3, rtol=1e-9)
    return result, io.save(result, tmp_path_factory.mktemp("arch") / "good.npz")


def with_meta(path, out, **changes):
    meta = {**io.read_metadata(path), **changes}
    with np.load(path) as d:
        arrays = {k: d[k] for k in d.files if k != "metadata"}
    return io.write_archive(out, arrays, meta)


def meta_text(path, out, text):
    shutil.copy(path, out)
    rewrite_zip(out, replace={"metadata.npy": npy(np.array(text))})
    return out


def huge_claim(path, out):
    shutil.copy(path, out)
    rewrite_zip(out, replace={"theta_p.npy": fake_npy((9999999999999,), payload=bytes(24))})
    return out


MALFORMED = {
    "renamed entry": (lambda p, o: (shutil.copy(p, o), rewrite_zip(o, rename={"theta_p.npy":
                                                                             "theta.npy"})),
                      "names the array 'theta_p', which is not in the file"),
    "missing entry": (lambda p, o: (shutil.copy(p, o), rewrite_zip(o, drop="status.npy")),
                      "names the array 'status', which is not in the file"),
    "list-valued kind": (lambda p, o: with_meta(p, o, kind=["section"]),
                         "holds unknown kind ['section']"),
    "numeric kind": (lambda p, o: with_meta(p, o, kind=3), "holds unknown kind 3"),
    "nested JSON": (lambda p, o: meta_text(p, o, "[" * 100000 + "]" * 100000),
                    "its 'metadata' is not JSON (RecursionError"),
    "nested JSON in a field": (lambda p, o: meta_text(p, o, '{"kind": "section", "fields": '
                                                      + "[" * 100000 + "]" * 100000 + "}"),
                               "its 'metadata' is not JSON (RecursionError"),
    "metadata not text": (lambda p, o: (shutil.copy(p, o), rewrite_zip(
        o, replace={"metadata.npy": npy(np.arange(3.0))})),
                          "its 'metadata' is not JSON text"),
    "bad npy header": (lambda p, o: (shutil.copy(p, o),
                                     rewrite_zip(o, replace={"theta_p.npy": b"\x93NUMPY\x01\x00"
                                                             b"\x10\x00{'descr': zzz}   \n"})),
                       "is damaged: entry 'theta_p.npy' has a bad .npy header (ValueError)"),
    "object dtype": (lambda p, o: (shutil.copy(p, o), rewrite_zip(
        o, replace={"theta_p.npy": fake_npy((2,), descr="|O", payload=bytes(16))})),
        "holds Python objects"),
    "corrupt compressed data": (lambda p, o: (shutil.copy(p, o), flip_entry(o, "r.npy")),
                                "is damaged or malformed: "),
    "corrupt compressed metadata": (lambda p, o: (shutil.copy(p, o),
                                                  flip_entry(o, "metadata.npy")),
                                    "its 'metadata' entry cannot be read"),
    "TiB header claim": (huge_claim, "has a header for shape (9999999999999,) of float64"),
    "truncated file": (lambda p, o: o.write_bytes(p.read_bytes()[:1000]),
                       "not a NumPy .npz file"),
    "format_version -1": (lambda p, o: with_meta(p, o, format_version=-1),
                          "format_version -1, which no ti_spinorbit writes"),
    "format_version 1.0": (lambda p, o: with_meta(p, o, format_version=1.0),
                           "format_version 1.0, which no ti_spinorbit writes"),
    "format_version true": (lambda p, o: with_meta(p, o, format_version=True),
                            "format_version True, which no ti_spinorbit writes"),
    "fields a list": (lambda p, o: with_meta(p, o, fields=[1, 2]), "is damaged or malformed"),
    "systems a dict": (lambda p, o: with_meta(p, o, systems={"a": 1}),
                       "metadata 'systems' is a dict, not a list"),
    "system index out of range": (
        lambda p, o: (shutil.copy(p, o),
                      rewrite_zip(o, replace={"system_index.npy": npy(np.array([0, -1]))})),
        "system index -1 is not in 0..0"),
    "system description broken": (lambda p, o: with_meta(p, o, systems=[{"e": 0.1}]),
                                  "system description lacks 'primary'"),
    "single npy": (lambda p, o: np.save(o, np.zeros(3)) or os.replace(str(o) + ".npy", o),
                   "a single .npy array, not an .npz"),
    "nested block garbage": (lambda p, o: with_meta(p, o, nested={"section": [1]}),
                             "is damaged or malformed"),
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_malformed_archive_is_one_archive_error(archive, tmp_path, case):
    _, good = archive
    make, message = MALFORMED[case]
    bad = tmp_path / "bad.npz"
    make(good, bad)
    with pytest.raises(ArchiveError) as info:
        tso.load(bad)
    text = str(info.value)
    assert text.startswith(f"'{bad}'") and message in text
    assert "\n" not in text and len(text) < 600
    assert isinstance(info.value, ValueError)
    if "format_version" in case:
        assert "newer" not in text


def test_huge_header_claim_allocates_nothing(archive, tmp_path):
    _, good = archive
    bad = huge_claim(good, tmp_path / "huge.npz")
    tracemalloc.start()
    with pytest.raises(ArchiveError, match="bytes of data"):
        tso.load(bad)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 32 * 2**20


def test_unreferenced_huge_entry_is_never_read(archive, tmp_path):
    """A small file with an extra 512 MiB (compressed to < 1 MiB) entry loads in little
    memory: only the entries the metadata names are read."""
    result, good = archive
    bad = tmp_path / "bomb.npz"
    shutil.copy(good, bad)
    header = npy(np.zeros(0, dtype=np.uint8)).replace(b"(0,)", b"(536870912,)"[:4])
    size = 512 * 2**20
    with zipfile.ZipFile(bad, "a", compression=zipfile.ZIP_DEFLATED) as zf:
        with zf.open("junk.npy", "w", force_zip64=True) as fh:
            fh.write(header)
            block = bytes(16 * 2**20)
            for _ in range(size // len(block)):
                fh.write(block)
    assert bad.stat().st_size < 2 * 2**20
    tracemalloc.start()
    loaded = tso.load(bad)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 64 * 2**20
    assert_same(result, loaded)


def test_format_99_is_still_called_newer_and_valid_files_load(archive, tmp_path):
    result, good = archive
    with pytest.raises(ArchiveError, match="a newer package wrote it"):
        tso.load(with_meta(good, tmp_path / "f.npz", format_version=99))
    assert_same(result, tso.load(good))
    assert io.ArchiveError is tso.output.io.ArchiveError and "ArchiveError" in io.__all__


def test_missing_path_is_still_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="no saved result at"):
        tso.load(tmp_path / "absent.npz")


# ---- 5. save works for every valid system ---------------------------------------------------
BODIES = {
    "long axis y": {(2, 0, 0): 1e14, (0, 2, 0): 2e14, (0, 0, 2): 5e13},
    "long axis x": {(2, 0, 0): 2e14, (0, 2, 0): 1e14, (0, 0, 2): 5e13},
    "round in the xy plane": {(2, 0, 0): 1e14, (0, 2, 0): 1e14, (0, 0, 2): 5e13},
}


@pytest.mark.parametrize("shape", list(BODIES))
def test_every_valid_secondary_saves_and_loads(vh, tmp_path, shape):
    secondary = tso.Body(1e10, BODIES[shape], 300)
    system = tso.BinarySystem(vh.primary, secondary, vh.a, vh.e,
                              primary_spin_period=vh.primary_spin_period, name=shape)
    expected = {"long axis y": 1.0, "long axis x": 1.0, "round in the xy plane": 0.0}[shape]
    assert system.omega0 == pytest.approx(expected, rel=1e-15)
    result = tso.surface_of_section(system, 0.0, [1.0], orbits=2, rtol=1e-9)
    loaded = tso.load(io.save(result, tmp_path / "y.npz"))
    assert_same(result, loaded)
    np.testing.assert_array_equal(loaded.systems[0].parameter_row(), system.parameter_row())
    assert loaded.systems[0].omega0 == system.omega0
    assert io.read_metadata(tmp_path / "y.npz")["systems"][0]["omega0"] == system.omega0
