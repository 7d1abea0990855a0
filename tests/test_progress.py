"""No silent waits: ``progress=None | True | False | callable`` on
every entry point, a tqdm bar in a terminal, plain lines in a log, nothing by default where no
bar can be drawn; compile time announced once and kept out of elapsed time, ETA and rates.

The bar is tested with a fake clock and an in-memory stream; the compile step is stood in for
(``compiling._launch``), never compiled cold."""

import contextlib
import io
import math
import sys
import time
import types

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine import compiling, progress
from ti_spinorbit.engine.progress import Progress, eta_seconds, format_duration

STARTS = [0.83, 1.63]


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def make(tty, **kwargs):
    clock, stream = FakeClock(), io.StringIO()
    return Progress("map", stream=stream, tty=tty, clock=clock, **kwargs), clock, stream


# ---- arithmetic and plain lines ---------------------------------------------------------

def test_eta_and_durations():
    assert eta_seconds(0.25, 30.0) == 90.0         # a quarter in 30 s: 90 s to go
    assert eta_seconds(0.0, 30.0) is None and eta_seconds(1.0, 30.0) == 0.0
    assert [format_duration(s) for s in (0, 59.4, 59.6, 61, 3599, 3600, 3725, None, math.inf)] \
        == ["0:00", "0:59", "1:00", "1:01", "59:59", "1:00:00", "1:02:05", "--:--", "--:--"]


def test_plain_lines_every_ten_percent_with_the_right_eta():
    bar, clock, stream = make(tty=False)
    with bar:
        for k in range(1, 101):
            clock.now += 1.0
            bar(k / 100)
        bar(1.0)                      # a repeated 100 % is not written twice
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue() and len(lines) == 10
    assert lines[0] == "map:  10%  elapsed 0:10, ETA 1:30"
    assert lines[-1] == "map: 100%  elapsed 1:40, ETA 0:00"


def test_plain_lines_wait_for_the_delay():
    # a run shorter than the delay writes nothing; a longer one writes its first line as
    # soon as the delay has passed, then one per step (the CLI uses progress.DELAY_S)
    bar, clock, stream = make(tty=False, delay=25.0)
    for k in range(1, 101):
        clock.now += 1.0
        bar(k / 100)
    lines = stream.getvalue().splitlines()
    assert lines[0] == "map:  25%  elapsed 0:25, ETA 1:15" and len(lines) == 9
    assert lines[1].startswith("map:  30%")
    short, clock, stream = make(tty=False, delay=25.0)
    for k in range(1, 11):
        clock.now += 1.0
        short(k / 10)
    assert stream.getvalue() == ""


def test_plain_lines_jumps_and_odd_fractions():
    bar, clock, stream = make(tty=False)
    bar(float("nan"))                 # ignored
    bar(0.35)                         # one line for the 10-30 % crossed at once
    bar(0.36)
    bar(2.0)                          # clipped to 100 %
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2 and " 35%" in lines[0] and "100%" in lines[1]


@pytest.mark.parametrize("tty", [True, False])
def test_disabled_progress_writes_nothing(tty):
    bar, clock, stream = make(tty=tty, enabled=False)
    with bar:
        bar.compiling("compiling kernels for the planar model (first use only, about 8 s)")
        bar(0.5)
        bar.compiled(8.0)
        bar(1.0)
    assert stream.getvalue() == ""


# ---- the tqdm bar (terminal mode) ------------------------------------------------------

def test_terminal_bar_is_tqdm_with_the_right_eta():
    bar, clock, stream = make(tty=True)
    clock.now += 30.0
    bar(0.25)                         # a quarter in 30 s: 1:30 to go
    text = stream.getvalue()
    assert "\r" in text and "map:  25%|" in text
    assert text.rstrip().endswith("elapsed 00:30, ETA 01:30")
    clock.now += 90.0
    bar(1.0)
    bar.close()
    assert "map: 100%|" in stream.getvalue() and stream.getvalue().endswith("\n")


def test_terminal_bar_waits_for_its_delay():
    bar, clock, stream = make(tty=True, delay=2.0)
    clock.now += 1.0
    bar(0.5)                          # quick: nothing shown yet
    assert stream.getvalue() == ""
    clock.now += 1.5
    bar(0.9)
    assert "map:  90%|" in stream.getvalue()
    bar.close()


def test_a_short_run_with_announcements_draws_no_bar_and_ends_every_line():
    """The CLI's case (delay 2 s): compile announcements, then a sub-second run. tqdm redraws
    every existing bar at each write, its delay or not, and then never ends that line (the
    next print ran on: ``ETA 00:001991 VH: ...``): here no bar is drawn at all."""
    bar, clock, stream = make(tty=True, delay=progress.DELAY_S)
    with bar:
        bar.compiling("compiling kernels for the planar model (first use only, about 1 s)")
        clock.now += 1.4
        bar.compiled(1.4)
        for k in range(1, 5):
            clock.now += 0.2
            bar(k / 4)
    assert stream.getvalue() == (
        "map: compiling kernels for the planar model (first use only, about 1 s)\n"
        "map: kernels ready after 1.4 s (not counted in elapsed time, ETA or rates)\n")
    assert "%" not in stream.getvalue() and "\r" not in stream.getvalue()


@pytest.mark.parametrize("fail", [False, True])
def test_a_long_run_shows_the_bar_and_ends_its_line(fail):
    """Past the delay the bar shows (announcements before it are plain lines, those during
    it are written above it), and closing ends the bar's line, also when the run fails."""
    bar, clock, stream = make(tty=True, delay=progress.DELAY_S)
    with pytest.raises(RuntimeError) if fail else contextlib.nullcontext():
        with bar:
            bar.compiling("compiling kernels for the planar model (first use only, about 1 s)")
            for k in range(1, 11):
                clock.now += 1.0
                bar(k / 10)
                if k == 5:
                    bar.compiling("compiling kernels for the 3-D model (first use only)")
                if fail and k == 7:
                    raise RuntimeError("a failing run")
    text = stream.getvalue()
    assert text.startswith("map: compiling kernels for the planar model (first use only, "
                           "about 1 s)\n")
    assert "map:  20%|" in text and "map:  10%|" not in text   # shown once 2 s had passed
    assert "\nmap: compiling kernels for the 3-D model (first use only)\n" in text \
        or "\rmap: compiling kernels for the 3-D model (first use only)\n" in text
    assert ("map:  70%|" if fail else "map: 100%|") in text.rsplit("\r", 1)[-1]
    assert text.endswith("\n")                   # the next print starts on its own line


@pytest.mark.parametrize("tty", [True, False])
def test_compile_time_is_announced_and_left_out_of_elapsed_and_eta(tty):
    bar, clock, stream = make(tty=tty)
    bar.compiling("compiling kernels for the 3-D model (first use only, about 50 s)")
    clock.now += 48.0                 # the compile
    bar.compiled(48.0)
    clock.now += 30.0
    bar(0.25)                         # 30 s of integration for a quarter
    bar(1.0) if not tty else None
    text = stream.getvalue()
    assert text.count("map: compiling kernels for the 3-D model (first use only, about 50 s)") == 1
    assert "map: kernels ready after 48.0 s (not counted in elapsed time, ETA or rates)" in text
    if tty:
        assert text.rstrip().endswith("elapsed 00:30, ETA 01:30")
    else:
        assert "map:  25%  elapsed 0:30, ETA 1:30" in text
    assert bar.compile_seconds == 48.0 and bar.elapsed() == 30.0
    bar.close()


# ---- what each value of progress= means ------------------------------------------------

@pytest.mark.parametrize("value", [5, "bar", 1.0, [1]])
def test_bad_progress_is_a_type_error_naming_the_argument(vh, value):
    with pytest.raises(TypeError, match=r"^progress must be True, False, None or a callable "):
        tso.surface_of_section(vh, 0.0, STARTS, orbits=2, run=tso.Run(progress=value))


def test_results_are_identical_whatever_progress_is(vh, capsys):
    fractions = []
    runs = [tso.surface_of_section(vh, 0.0, STARTS, orbits=4, rtol=1e-10, run=tso.Run(progress=p))
            for p in (None, False, True, fractions.append)]
    for r in runs[1:]:
        np.testing.assert_array_equal(r.theta_p, runs[0].theta_p)
        np.testing.assert_array_equal(r.thetadot_p, runs[0].thetadot_p)
    assert fractions[-1] == 1.0 and fractions == sorted(fractions)
    err = capsys.readouterr().err     # pytest's capture is no terminal
    lines = err.strip().splitlines()
    # True: plain lines, the last at 100 %; None and False: nothing
    assert lines and all(line.startswith("surface_of_section: ") for line in lines)
    assert lines[-1].startswith("surface_of_section: 100%")


def test_default_progress_writes_nothing_when_no_bar_can_be_drawn(vh, capsys):
    assert not progress.interactive()
    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10)
    assert capsys.readouterr().err == ""


def test_default_progress_is_on_in_jupyter(monkeypatch):
    class ZMQInteractiveShell:
        pass

    shell = ZMQInteractiveShell()
    monkeypatch.setitem(sys.modules, "ipykernel", types.ModuleType("ipykernel"))
    fake = types.ModuleType("IPython")
    fake.get_ipython = lambda: shell
    monkeypatch.setitem(sys.modules, "IPython", fake)
    assert progress.in_jupyter() and progress.interactive(io.StringIO())
    fake.get_ipython = lambda: None            # IPython imported but no kernel
    assert not progress.in_jupyter()


ENTRY_POINTS = {
    "time_series": lambda vh, p: tso.time_series(vh, 0.0, STARTS, 2, samples_per_orbit=8,
                                                 rtol=1e-10, run=tso.Run(progress=p)),
    "chaos_map": lambda vh, p: tso.chaos_map(vh, [0.0, 90.0], [1.0], orbits=8,
                                             run=tso.Run(progress=p)),
    "parameter_map": lambda vh, p: tso.parameter_map("1991 VH", [1.2], [0.05], orbits=8,
                                                     theta_p=[0.0], thetadot_p=[1.0],
                                                     run=tso.Run(progress=p)),
    "libration_amplitude": lambda vh, p: tso.libration_amplitude(vh, [0.8, 0.9], 2,
                                                                 samples_per_orbit=16, rtol=1e-10,
                                                                 run=tso.Run(progress=p)),
    "overlap_threshold": lambda vh, p: tso.overlap_threshold("1991 VH", elongations=[1.05],
                                                             orbits=4, max_orbits=8,
                                                             centre_starts=2, separatrix_starts=2,
                                                             run=tso.Run(progress=p)),
}


@pytest.mark.parametrize("name", sorted(ENTRY_POINTS))
def test_every_entry_point_takes_true_and_a_callable(vh, capsys, name):
    ENTRY_POINTS[name](vh, True)                     # was: TypeError 'bool' not callable
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[-1].startswith(f"{name}: 100%"), lines
    fractions = []
    ENTRY_POINTS[name](vh, fractions.append)
    assert fractions and fractions[-1] == pytest.approx(1.0)
    assert all(0.0 <= f <= 1.0 for f in fractions) and fractions == sorted(fractions)
    ENTRY_POINTS[name](vh, False)
    assert capsys.readouterr().err == ""


def test_chaos_map_progress_covers_the_shorter_lengths(vh):
    """The fraction-against-length runs (orbits/4, orbits/2 first) are 3/7 of the work: the
    bar moves during them instead of waiting at 0 %."""
    fractions = []
    tso.chaos_map(vh, [0.0, 90.0], [1.0], orbits=8, run=tso.Run(progress=fractions.append))
    assert min(fractions) < 3.0 / 7.0 + 1e-12
    assert any(abs(f - 3.0 / 7.0) < 1e-12 for f in fractions)   # end of the shorter runs


# ---- compile announcement and rates (the compile step stood in for) --------------------

@pytest.fixture
def cold(monkeypatch, tmp_path):
    """A process in which no variant was used yet, measurements in tmp_path, and a compile
    that takes 1.5 s more than the real (cached) first launch."""
    monkeypatch.setattr(compiling, "_SEEN", set())
    monkeypatch.setattr(compiling, "record_path", lambda: str(tmp_path / "compile.json"))
    real = compiling._launch
    launches = []

    def slow(kernel, args):
        launches.append(len(args))
        real(kernel, args)
        time.sleep(1.5)

    monkeypatch.setattr(compiling, "_launch", slow)
    return launches


def test_compile_is_announced_once_and_left_out_of_seconds_and_rates(vh, cold, tmp_path):
    stream = io.StringIO()
    bar = Progress("section", stream=stream, tty=False)
    first = tso.surface_of_section(vh, 0.0, STARTS, orbits=4, rtol=1e-10,
                                   run=tso.Run(progress=bar))
    again = tso.surface_of_section(vh, 0.0, STARTS, orbits=4, rtol=1e-10,
                                   run=tso.Run(progress=bar))
    bar.close()
    text = stream.getvalue()
    assert text.count("compiling kernels") == 1 and len(cold) == 1
    assert ("section: compiling kernels for the planar model (first use only, about 1 s)"
            in text)                            # DEFAULT_COMPILE_SECONDS: nothing measured
    assert bar.compile_seconds >= 1.5
    # the 1.5 s compile is in neither the run's seconds nor its rate
    assert first.seconds < 1.0 and again.seconds < 1.0
    assert first.member_orbits_per_second > len(STARTS) * 4 / 1.0
    np.testing.assert_array_equal(first.theta_p, again.theta_p)
    record = compiling.read_records()["planar/plain/sections/order4/cash-karp"]
    assert record["seconds"] >= 1.5 and record["fingerprint"]


def test_a_variant_in_the_disk_cache_is_not_announced(vh, cold, monkeypatch):
    stream = io.StringIO()
    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10,
                           run=tso.Run(progress=Progress("s", stream=stream, tty=False)))
    assert stream.getvalue().count("compiling kernels") == 1
    monkeypatch.setattr(compiling, "_SEEN", set())     # a new process, same disk cache
    stream = io.StringIO()
    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10,
                           run=tso.Run(progress=Progress("s", stream=stream, tty=False)))
    assert "compiling" not in stream.getvalue() and len(cold) == 2
    assert compiling._HOW["planar/plain/sections/order4/cash-karp"] == "loaded"


def test_the_estimate_is_the_last_measurement(vh, cold, monkeypatch):
    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10, run=tso.Run(progress=False))
    records = compiling.read_records()
    records["planar/plain/sections/order4/cash-karp"].update(seconds=37.0, fingerprint="old")
    compiling._write_records(records)                   # kernels changed since: a compile
    monkeypatch.setattr(compiling, "_SEEN", set())
    stream = io.StringIO()
    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10,
                           run=tso.Run(progress=Progress("s", stream=stream, tty=False)))
    assert "(first use only, about 37 s)" in stream.getvalue()


def test_nested_calls_announce_to_the_outer_bar(vh, cold):
    """libration_amplitude runs time_series inside: one bar, the announcement on it."""
    stream = io.StringIO()
    bar = Progress("lib", stream=stream, tty=False)
    with progress.reporting(bar, "outer"):
        tso.time_series(vh, 0.0, STARTS, 2, samples_per_orbit=8, rtol=1e-10)
    assert stream.getvalue().count("lib: compiling kernels for the planar model with dense "
                                   "sampling") == 1
    assert "%" not in stream.getvalue()       # the inner call's fractions are not the outer's


def test_a_callable_gets_the_announcements_when_it_wants_them(vh, cold):
    seen = []

    class Callback:
        def __call__(self, fraction):
            seen.append(fraction)

        def compiling(self, text):
            seen.append(text)

        def compiled(self, seconds):
            seen.append(("compiled", seconds))

    tso.surface_of_section(vh, 0.0, STARTS, orbits=2, rtol=1e-10, run=tso.Run(progress=Callback()))
    assert isinstance(seen[0], str) and seen[0].startswith("compiling kernels for the planar")
    assert seen[1][0] == "compiled" and seen[1][1] >= 1.5 and seen[-1] == 1.0


# ---- warm-up -----------------------------------------------------------------------------

def test_warmup_compiles_each_variant_and_says_how(cold):
    out = io.StringIO()
    done = tso.warmup(models=["planar"], indicators=[False], sampling=[False, True], stream=out)
    assert [d["variant"] for d in done] == ["planar/plain/sections/order4/cash-karp",
                                            "planar/plain/sampling/order4/cash-karp"]
    assert all(d["how"] == "compiled" and d["kernel_seconds"] >= 1.5 for d in done)
    again = tso.warmup(models=["planar"], indicators=[False], sampling=[False], stream=out)
    assert again[0]["how"] == "ready" and again[0]["kernel_seconds"] == 0.0
    lines = out.getvalue().splitlines()
    assert lines[0].startswith("planar/plain/sections/order4/cash-karp: compiled in ")
    assert lines[-1].startswith("planar/plain/sections/order4/cash-karp: already compiled in "
                                "this process")


@pytest.mark.parametrize("kwargs, message", [
    ({"models": ["2d"]}, r"^models must be a non-empty selection of 'planar', '3d' \(got \['2d'\]\)"),
    ({"methods": ["rk4"]},
     r"^methods must be a non-empty selection of 'cash-karp', 'dop853', 'vern9' \(got"),
    ({"indicators": []}, r"^indicators must be a non-empty selection of False, True"),
])
def test_warmup_refuses_unknown_variants(kwargs, message):
    with pytest.raises(ValueError, match=message):
        tso.warmup(**kwargs)


@pytest.mark.parametrize("delay", [120.0, 0.0])
def test_the_command_in_a_terminal_ends_the_bars_line(tmp_path, delay):
    """End to end in a pseudo-terminal (stderr a tty, so a bar can be drawn), the command's
    delay set so that the outcome does not depend on the machine's speed: a run shorter than
    the delay draws no bar at all; one past it draws the bar and ends its line, so the
    summary starts a line of its own (it ran on after the bar: ``ETA 00:001991 VH: ...``)."""
    import os
    import pty
    import subprocess

    code = ("import sys; from ti_spinorbit.engine import progress; "
            f"progress.DELAY_S = {delay}; from ti_spinorbit import cli; "
            "sys.exit(cli.main(['section', '--orbits', '2', '--thetadot', '0.83', "
            "'--out', 's.png']))")
    import fcntl
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))   # 100 columns
    env = {**os.environ, "MPLBACKEND": "Agg"}
    p = subprocess.Popen([sys.executable, "-c", code], cwd=tmp_path, env=env,
                         stdin=slave, stdout=slave, stderr=slave)
    os.close(slave)
    chunks = []
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:            # the child closed the terminal
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(master)
    text = b"".join(chunks).decode(errors="replace")
    assert p.wait(timeout=600) == 0, text
    assert "wrote s.png" in text, text
    if delay:
        assert "%|" not in text and "ETA" not in text, text          # no bar at all
    else:
        assert "section: 100%|" in text, text
    summary = text.index("1991 VH: mass ratio")
    assert summary == 0 or text[summary - 1] == "\n", text          # on a line of its own
