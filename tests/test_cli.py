"""The console script end to end, in subprocesses (tiny runs), and the saved files.

Every subcommand that computes runs once in a fresh process (the installed entry point, the
offline kernel cache, files on disk); variants that only change what is printed or the exit
status run in-process through ``cli.main`` (kernels already compiled: fast). Bad flags are
covered by tests/test_validation.py."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import cli
from ti_spinorbit.output.io import read_metadata

from conftest import run_cli

PNG = b"\x89PNG\r\n\x1a\n"
TAICHI_BANNER = "[Taichi] version"      # `import taichi`'s banner: hidden, see test below


def test_section_writes_png_and_self_describing_data(tmp_path):
    p = run_cli("section", "--system", "1991 VH", "--thetadot", "0.83", "1.63", "--orbits", "5",
                "--rtol", "1e-10", "--out", "s.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    png = (tmp_path / "s.png").read_bytes()
    assert png[:8] == PNG and len(png) > 10000
    with np.load(tmp_path / "s.npz") as d:
        assert d["theta_p"].shape[0] == 2 and np.all(d["count"] >= 4)
        assert np.nanmax(d["theta_p"]) < 180 and np.nanmin(d["theta_p"]) >= 0
        np.testing.assert_array_equal(d["initial_thetadot_p"], [0.83, 1.63])
    meta = read_metadata(tmp_path / "s.npz")
    assert meta["rtol"] == 1e-10 and meta["systems"][0]["name"] == "1991 VH"
    assert meta["units"]["thetadot_p"] == "mean motion n"
    assert meta["command"].startswith("ti-spinorbit section")
    assert "1991 VH" in p.stdout and "wrote" in p.stdout
    # not a terminal and shorter than progress.DELAY_S: no progress lines at all (a log of a
    # short run stays quiet; tests/test_progress.py covers the lines of a long one)
    assert "%" not in p.stderr


def test_systems_lists_the_catalogue(tmp_path):
    p = run_cli("systems", cwd=tmp_path)
    assert p.returncode == 0
    for name in ("1991 VH", "2003 YT1", "2004 DC", "1999 KW4"):
        assert name in p.stdout


def test_systems_writes_json(tmp_path, capsys):
    assert cli.main(["systems", "--quiet", "--out", str(tmp_path / "c.json")]) == 0
    assert capsys.readouterr().out == ""
    listed = json.loads((tmp_path / "c.json").read_text())
    assert [d["name"] for d in listed] == tso.catalog.names()


@pytest.mark.parametrize("args, message", [
    (("section", "--system", "1991 XX"), "unknown system"),
    (("section", "--orbits", "-3"), r"--orbits must lie in \(0, 1e\+07\] \(got -3\)"),
    (("map", "--grid", "0", "4"), r"--grid must lie in \[1, 1024\]"),
])
def test_bad_input_prints_one_line_and_exits_2(tmp_path, args, message):
    p = run_cli(*args, cwd=tmp_path)
    assert p.returncode == 2
    assert "Traceback" not in p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"ti-spinorbit {args[0]}: error: ")
    assert __import__("re").search(message, lines[0]), lines[0]


def test_overlap_scan_command(tmp_path):
    p = run_cli("overlap", "--system", "2004 DC", "--elongations", "1.01", "1.03", "0.02",
                "--orbits", "120", "--out", "ov.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "ov.png").read_bytes()[:8] == PNG
    scan = tso.output.io.load(tmp_path / "ov.npz")
    assert scan.name == "2004 DC" and len(scan.decisions) == 2
    assert "first overlap" in p.stdout


def test_map_command(tmp_path):
    p = run_cli("map", "--system", "1991 VH", "--grid", "3", "4", "--orbits", "40",
                "--out", "m.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    with np.load(tmp_path / "m.npz") as d:
        assert d["megno"].shape == (3, 4) and np.all(np.isfinite(d["megno"]))
    cmap = tso.output.io.load(tmp_path / "m.npz")
    assert 0.0 <= cmap.chaotic_fraction <= 1.0


def test_libration_command(tmp_path):
    p = run_cli("libration", "--system", "Didymos", "--orbits", "5", "--rtol", "1e-9",
                "--out", "lib.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "lib.png").read_bytes()[:8] == PNG
    result = tso.output.io.load(tmp_path / "lib.npz")
    assert 0.0 < result.amplitude < 90.0 and result.converged
    # the printed numbers are the saved ones
    assert f"amplitude {result.amplitude:.4f} deg" in p.stdout
    # ψ_A as an amplitude with its phase in words, never a negative angle
    assert f"|ψ_A| = {abs(result.psi_A):.4f} deg" in p.stdout
    assert result.psi_A < 0 and f"{result.psi_A:.4f}" not in p.stdout
    assert "(phase: ψ = −|ψ_A| sin M, in antiphase with M" in p.stdout


def test_energy_command_reports_drift_and_exchange(tmp_path):
    p = run_cli("energy", "--orbits", "2", "--rtol", "1e-11", "--max-drift", "1e-6",
                "--out", "e.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "e.png").read_bytes()[:8] == PNG
    meta = read_metadata(tmp_path / "e.npz")
    check = meta["energy_check"]
    assert meta["systems"][0]["name"] == "test" and meta["member_status"] == "done"
    # the totals are conserved to the tolerance while the parts trade far more energy
    assert check["energy_drift"] < 1e-8 and check["angmom_drift"] < 1e-8
    for part in ("orbit", "primary", "secondary"):
        assert check[f"exchange_{part}"] > 1e3 * check["energy_drift"]
    assert "max relative energy drift" in p.stdout and "angular-momentum drift" in p.stdout
    with np.load(tmp_path / "e.npz") as d:
        assert d["energy"].shape[1] == check["samples"]


def test_energy_exit_status_1_above_max_drift(tmp_path, capsys):
    out = str(tmp_path / "e.png")
    code = cli.main(["energy", "--orbits", "1", "--rtol", "1e-9", "--max-drift", "1e-15",
                     "--out", out, "--quiet"])
    captured = capsys.readouterr()
    assert code == 1
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and "exceeds --max-drift 1e-15" in lines[0]
    assert os.path.exists(out)
    assert read_metadata(tmp_path / "e.npz")["command"] == \
        f"ti-spinorbit energy --orbits 1 --rtol 1e-9 --max-drift 1e-15 --out {out} --quiet"


def test_benchmark_command(tmp_path):
    p = run_cli("benchmark", "--members", "3", "--orbits", "2", "--rtol", "1e-9",
                "--out", "b.json", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    report = json.loads((tmp_path / "b.json").read_text())
    assert report["members"] == 3 and report["orbits"] == 2.0 and report["arch"] == "cpu"
    assert report["member_orbits_per_second"] == pytest.approx(6.0 / report["best_seconds"])
    assert report["status_counts"] == {"done": 3}
    assert "member-orbits/s" in p.stdout


def test_quiet_prints_nothing_of_its_own(tmp_path):
    p = run_cli("energy", "--orbits", "1", "--rtol", "1e-9", "--max-drift", "1e-3", "--quiet",
                "--out", "q.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert p.stdout == "" and p.stderr == ""      # no summary, no progress bar, no Taichi
    assert (tmp_path / "q.npz").exists()


def test_quiet_hides_the_taichi_banner(tmp_path):
    p = run_cli("systems", "--quiet", cwd=tmp_path)
    assert p.returncode == 0 and p.stdout == ""


def test_taichi_prints_nothing_in_the_command_or_the_library(tmp_path):
    """No Taichi banner nor "Starting on arch" line, in the command (console script or
    python -m, --quiet or not) and in the library (ti_spinorbit/runtime.py); with
    TI_SPINORBIT_VERBOSE=1 the same commands show both (so the checks can fail)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("ENABLE_TAICHI_HEADER_PRINT", "TI_LOG_LEVEL", "TI_SPINORBIT_VERBOSE")}
    script = os.path.join(os.path.dirname(sys.executable), "ti-spinorbit")
    energy = ["energy", "--orbits", "1", "--rtol", "1e-9", "--max-drift", "1e-3", "--out", "e.png"]
    runs = [[sys.executable, "-m", "ti_spinorbit", *energy, "--overwrite"],
            [sys.executable, "-c", "import ti_spinorbit as t; t.init()"]]
    if os.path.exists(script):
        runs.append([script, *energy, "--overwrite"])
    for verbose in (False, True):
        for command in runs:
            p = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True,
                               timeout=600, env={**env, "MPLBACKEND": "Agg",
                                                 **({"TI_SPINORBIT_VERBOSE": "1"} if verbose else {})})
            assert p.returncode == 0, p.stdout + p.stderr
            out = p.stdout + p.stderr
            if verbose:
                assert TAICHI_BANNER in out and "Starting on arch" in out, (command, out)
            else:
                assert "[Taichi]" not in out and "Starting on arch" not in out, (command, out)


@pytest.mark.parametrize("command", sorted(cli.EXAMPLES_BY_COMMAND))
def test_help_has_examples(command, capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main([command, "--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert "examples:" in text and f"ti-spinorbit {command}" in text
    if command not in ("systems", "figures", "warmup"):
        assert "--arch" in text and "--quiet" in text and "--out" in text


def test_top_level_help_lists_every_subcommand(capsys):
    with pytest.raises(SystemExit):
        cli.main(["--help"])
    text = capsys.readouterr().out
    for command in cli.HANDLERS:
        assert command in text and f"ti-spinorbit {command}" in text


def read_checkpoint_launches(path):
    import json
    with np.load(path / "state.npz") as d:
        return json.loads(str(d["header"]))["launches"]


def test_map_resume_after_interrupt_equals_the_full_run(tmp_path):
    """The map is interrupted by SIGKILL after two windows of its first stage (the evidence
    length orbits/4, checkpointed in launch-000), `--resume` finishes it, and the saved
    arrays equal those of an uninterrupted run."""
    import signal
    import time

    env = dict(os.environ, MPLBACKEND="Agg")
    args = ["map", "--system", "1991 VH", "--grid", "3", "3", "--orbits", "1600", "--rtol", "1e-9",
            "--quiet"]
    ckpt = tmp_path / "m.ckpt"
    proc = subprocess.Popen([sys.executable, "-m", "ti_spinorbit", *args, "--out", "m.png",
                             "--checkpoint", str(ckpt)], cwd=tmp_path, env=env)
    deadline = time.time() + 300
    first = ckpt / "launch-000"
    # a window writes its records file, then the state: once the third records file is
    # there, the state holds at least two windows (waiting for the second raced the state)
    while time.time() < deadline and not (first / "records-000002.npz").exists():
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL                    # killed, not finished
    done = read_checkpoint_launches(first)
    assert 2 <= done < 25                  # 25 windows of 16 orbits in the first 400 orbits
    assert not (ckpt / "launch-001").exists()
    p = run_cli(*args, "--out", "m.png", "--checkpoint", str(ckpt), "--resume", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    p = run_cli(*args, "--out", "full.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    with np.load(tmp_path / "m.npz") as a, np.load(tmp_path / "full.npz") as b:
        for key in ("megno", "lyapunov", "status", "section/theta_p", "section/thetadot_p"):
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)


# ---- output hygiene ------------------------------------------------------

@pytest.mark.parametrize("argv, stem", [
    (["section"], "sos_1991VH"),
    (["section", "--elongation", "1.06"], "sos_1991VH_ab1.06"),
    (["section", "--system", "2004 DC", "--density", "2500", "--eccentricity", "0.1",
      "--theta-p", "30"], "sos_2004DC_rho2500_e0.1_tp30"),
    (["section", "--thetadot", "1.13", "1.63"], "sos_1991VH_td1.13-1.63"),
    (["section", "--thetadot", "1", "1.5", "2", "2.5"], "sos_1991VH_td1-2.5n4"),
    (["section", "--thetadot", "1", "2.5", "4"], "sos_1991VH_td1-2.5-4"),
    (["section", "--orbits", "1000", "--rtol", "1e-13", "--model", "3d",
      "--coordinates", "apsidal"], "sos_1991VH_o1000_rtol1e-13_3d_apsidal"),
    (["section", "--orbits", "1e6", "--rtol", "1e-9"], "sos_1991VH_o1e6_rtol1e-9"),
    (["map", "--rtol", "1e-4", "--model", "planar"], "map_1991VH_rtol1e-4_planar"),
    (["map", "--rtol", "2.5e-11"], "map_1991VH_rtol2.5e-11"),
    (["section", "--rtol", "1e-11"], "sos_1991VH_rtol1e-11"),     # 9.999...e-12 in binary
    # defaults given explicitly and flags that change no physics are not named
    (["section", "--orbits", "500", "--max-drift", "1e-6", "--arch", "cpu", "--quiet"],
     "sos_1991VH"),
    (["map", "--grid", "64", "64", "--thetadot-range", "0.5", "2"], "map_1991VH_g64x64_tdr0.5-2"),
    (["overlap", "--elongations", "1.01", "1.1", "0.01", "--max-orbits", "4000"],
     "overlap_1991VH_ab1.01-1.1-0.01_maxo4000"),
    (["libration", "--xtol", "1e-8", "--candidates", "0.2", "1.3", "45"],
     "libration_Didymos_cand0.2-1.3-45_xtol1e-8"),
    (["energy", "--samples-per-orbit", "128", "--thetadot", "1.0"], "energy_test_td1_spo128"),
])
def test_default_names_carry_the_overridden_physics(argv, stem):
    args = cli._parser().parse_args(argv)
    prefix = {"section": "sos"}.get(argv[0], argv[0])
    assert cli.default_stem(args, prefix, args.system) == stem


SMALL_SECTION = ["section", "--elongation", "1.06", "--thetadot", "1.13", "--orbits", "2",
                 "--rtol", "1e-9"]


def test_default_names_in_a_run_and_no_silent_overwrite(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    stem = "sos_1991VH_ab1.06_td1.13_o2_rtol1e-9"
    assert cli.main(SMALL_SECTION + ["--quiet"]) == 0
    png = (tmp_path / f"{stem}.png").read_bytes()
    data = (tmp_path / f"{stem}.npz").read_bytes()
    capsys.readouterr()
    assert cli.main(SMALL_SECTION + ["--quiet"]) == cli.EXIT_ERROR       # refused, not redone
    err = capsys.readouterr().err
    assert err == (f"ti-spinorbit section: error: the figure (default --out): '{stem}.png' "
                   "already exists (an earlier run's output?); pass --overwrite to replace it, "
                   "or choose another --out\n")
    assert (tmp_path / f"{stem}.png").read_bytes() == png
    assert (tmp_path / f"{stem}.npz").read_bytes() == data
    assert cli.main(SMALL_SECTION + ["--quiet", "--overwrite"]) == 0


@pytest.mark.parametrize("existing, flags, named", [
    ("s.png", ["--out", "s.png"], "--out: 's.png'"),
    ("s.npz", ["--out", "s.png"], "the data file (default --data): 's.npz'"),
    ("d.npz", ["--out", "s.png", "--data", "d.npz"], "--data: 'd.npz'"),
])
def test_an_existing_output_is_refused_before_any_work(tmp_path, monkeypatch, capsys, existing,
                                                       flags, named):
    monkeypatch.chdir(tmp_path)
    (tmp_path / existing).write_bytes(b"an earlier run")
    assert cli.main(SMALL_SECTION + flags) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert err.startswith(f"ti-spinorbit section: error: {named} already exists") and \
        "--overwrite" in err and err.count("\n") == 1
    assert (tmp_path / existing).read_bytes() == b"an earlier run"
    assert sorted(p.name for p in tmp_path.iterdir()) == [existing]


def test_benchmark_report_is_not_overwritten(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "benchmark.json").write_text("{}")
    assert cli.main(["benchmark", "--members", "2", "--orbits", "1"]) == cli.EXIT_ERROR
    assert "'benchmark.json' already exists" in capsys.readouterr().err
    assert (tmp_path / "benchmark.json").read_text() == "{}"


@pytest.mark.parametrize("keep", [False, True])
def test_checkpoint_is_removed_after_success_unless_kept(tmp_path, monkeypatch, capsys, keep):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    argv = SMALL_SECTION + ["--out", "s.png", "--resume"] + (["--keep-checkpoint"] if keep else [])
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    assert (tmp_path / "s.ckpt").is_dir() == keep
    assert (tmp_path / "s.npz").is_file()
    if keep:
        assert "kept checkpoint s.ckpt (--keep-checkpoint)" in out
        assert (tmp_path / "s.ckpt" / "state.npz").is_file()
    else:
        assert "removed checkpoint s.ckpt (the run is complete; --keep-checkpoint keeps it)" in out


def test_no_progress_hides_the_bar_but_not_the_summary(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    assert cli.main(SMALL_SECTION + ["--out", "s.png", "--no-progress"]) == 0
    captured = capsys.readouterr()
    assert "%" not in captured.err and "wrote s.png and s.npz" in captured.out
    monkeypatch.setattr("ti_spinorbit.engine.progress.DELAY_S", 0.0)    # as if the run were long
    assert cli.main(SMALL_SECTION + ["--out", "t.png"]) == 0
    assert capsys.readouterr().err.strip().splitlines()[-1].startswith("section: 100%")


@pytest.mark.parametrize("psi, text", [
    (-19.9, "(phase: ψ = −|ψ_A| sin M, in antiphase with M, as for omega0 < 1; ψ is the long "
            "axis's angle from the line of centres, M the mean anomaly)"),
    (5.0, "(phase: ψ = +|ψ_A| sin M, in phase with M, as for omega0 > 1;"),
    (0.0, "(no forced libration: e = 0)"),
    (math.inf, "(phase undefined: omega0 = 1 is the forced resonance)"),
])
def test_psi_a_phase_in_words(psi, text):
    assert cli.psi_phase(psi).startswith(text)
    assert "19.9" not in cli.psi_phase(psi)


def test_warmup_command(capsys):
    assert cli.main(["warmup", "--models", "planar", "--indicators", "off",
                     "--sampling", "off"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("planar/plain/sections/order4/cash-karp: ")
    assert lines[-1].startswith("1 kernel variants ready (")


def test_warmup_refuses_an_unknown_method(capsys):
    assert cli.main(["warmup", "--methods", "rk4"]) == cli.EXIT_ERROR
    assert capsys.readouterr().err == ("ti-spinorbit warmup: error: --methods must be among "
                                       "cash-karp, dop853, vern9 (got 'rk4')\n")


# ---- tides, YORP and BYORP ------------------------------------------------------------------

@pytest.mark.parametrize("argv, stem", [
    (["section", "--tide", "secondary", "--k2", "1e-5", "--time-lag", "600", "--strength",
      "1e6"], "sos_1991VH_tide-secondary_k21e-5_dt600_str1e6"),
    (["energy", "--tide", "primary", "--Q", "100"], "energy_test_tide-primary_Q100"),
    (["map", "--yorp", "5e-4", "--yorp-body", "primary", "--byorp", "1e-3", "--heliocentric",
      "1.1", "0.2"], "map_1991VH_yorp0.0005_yorp-primary_byorp0.001_helio1.1-0.2"),
    (["libration", "--tide", "secondary", "--strength", "1"], "libration_Didymos_tide-secondary"),
    (["section", "--tide", "secondary", "--tide-radius", "150"],
     "sos_1991VH_tide-secondary_Rtide150"),
    (["section", "--sun", "--sun-inclination", "30", "--sun-mean-anomaly", "90"],
     "sos_1991VH_sun_suni30_sunM90"),
    (["section", "--flyby", "Earth", "--flyby-q", "2e5", "--flyby-time", "10"],
     "sos_1991VH_flyby-Earth_q200000_tq10"),
    (["section", "--yorp", "1e-3", "--radiation-distance", "mean"],
     "sos_1991VH_yorp0.001_rad-mean"),
])
def test_default_names_carry_the_perturbations(argv, stem):
    args = cli._parser().parse_args(argv)
    prefix = {"section": "sos"}.get(argv[0], argv[0])
    assert cli.default_stem(args, prefix, args.system) == stem


@pytest.mark.parametrize("flags, message", [
    (["--k2", "1e-5"], "--k2 needs --tide primary|secondary (the body that deforms)"),
    (["--time-lag", "600"], "--time-lag needs --tide primary|secondary"),
    (["--tide", "secondary", "--time-lag", "600", "--Q", "10"],
     "--time-lag and --Q exclude each other"),
    (["--tide", "secondary", "--k2", "0"], "--k2 must lie in [1e-12, 10] (got 0)"),
    (["--tide", "secondary", "--time-lag", "-1"], "--time-lag must lie in [1e-09, 1e+09] (got -1)"),
    (["--tide", "secondary", "--Q", "0"], "--Q must lie in [0.001, 1e+12] (got 0)"),
    (["--yorp", "2"], "--yorp must lie in [-1, 1] (got 2)"),
    (["--byorp", "-1.5"], "--byorp must lie in [-1, 1] (got -1.5)"),
    (["--tide", "secondary", "--strength", "0"], "--strength must lie in [1e-12, 1e+15] (got 0)"),
    (["--strength", "10"], "--strength needs --tide, --yorp, --byorp, --sun or --flyby"),
    (["--yorp-body", "primary"], "--yorp-body needs --yorp F_Y"),
    (["--heliocentric", "1", "0.1"], "--heliocentric needs --yorp or --byorp"),
    (["--yorp", "1e-3", "--heliocentric", "0.01", "0.1"],
     "--heliocentric A_AU must lie in [0.05, 10000] (got 0.01)"),
    (["--byorp", "1e-3", "--heliocentric", "1", "1"],
     "--heliocentric E must lie in [0, 1) (got 1)"),
    (["--system", "test", "--yorp", "1e-3"],
     "--yorp: 'test' has no heliocentric orbit: pass --heliocentric A_AU E, or give the "
     "system file a heliocentric_orbit"),
    (["--tide", "both"], "argument --tide: invalid choice: 'both'"),
    (["--tide-radius", "150"], "--tide-radius needs --tide primary|secondary"),
    (["--yorp-radius", "150"], "--yorp-radius needs --yorp (the YORP coefficient)"),
    (["--byorp", "1e-3", "--byorp-radius", "0"], "--byorp-radius must lie in [0.001, 1e+10]"),
    (["--sun-inclination", "10"], "--sun-inclination needs --sun (the Sun's tide)"),
    (["--sun-node", "10"], "--sun-node needs --sun"),
    (["--sun", "--sun-inclination", "181"], "--sun-inclination must lie in [0, 180] (got 181)"),
    (["--sun", "--sun-periapsis", "400"], "--sun-periapsis must lie in [-360, 360] (got 400)"),
    (["--system", "test", "--sun"],
     "--sun: 'test' has no heliocentric orbit: pass --heliocentric A_AU E"),
    (["--sun"], "--sun: this heliocentric orbit is given in the ecliptic without the binary's "
                "pole, so the Sun's direction is unknown: give --sun-inclination DEG"),
    (["--flyby", "Earth"], "--flyby needs --flyby-q KM, the closest distance (at least 6371 km"),
    (["--flyby-q", "1e5"], "--flyby-q needs --flyby PLANET"),
    (["--flyby", "Earth", "--flyby-q", "1000"],
     "--flyby needs --flyby-q KM, the closest distance (at least 6371 km for Earth: closer, "
     "the binary hits it); got 1000"),
    (["--flyby", "Earth", "--flyby-q", "1e5", "--flyby-vinf", "0"],
     "--flyby-vinf must lie in [0.01, 100] (got 0)"),
    (["--radiation-distance", "mean"], "--radiation-distance needs --yorp or --byorp"),
])
def test_bad_perturbation_flags_one_line_exit_2(flags, message, tmp_path, capsys):
    out = str(tmp_path / "x.png")
    assert cli.main(["section", *flags, "--out", out]) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not os.path.exists(out)


def test_tide_radius_flag_for_a_body_given_by_its_integrals(tmp_path, capsys):
    """A --system file whose secondary has inertia integrals but no semi-axes has no radius
    to default to: --tide asks for --tide-radius in one line, and with it the run saves it."""
    import json

    vh = tso.catalog.system("1991 VH")
    d = vh.describe()
    del d["secondary"]["semi_axes_m"]
    d["secondary"]["integrals"] = {",".join(map(str, k)): v
                                   for k, v in vh.secondary.integrals.items()}
    path = tmp_path / "vh_integrals.json"
    path.write_text(json.dumps(d))
    run = ["section", "--system", str(path), "--thetadot", "0.83", "--orbits", "1", "--rtol",
           "1e-9", "--tide", "secondary", "--k2", "1e-5", "--time-lag", "600"]
    assert cli.main(run + ["--out", str(tmp_path / "a.png")]) == cli.EXIT_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and ("--tide: the secondary is not an ellipsoid or sphere, so "
                                      "its radius is undefined: give --tide-radius M") in err
    assert cli.main(run + ["--tide-radius", "150", "--out", str(tmp_path / "b.png")]) == 0
    saved = tso.load(tmp_path / "b.npz")
    assert saved.perturbations == (tso.Tides(k2=1e-5, time_lag=600.0, radius=150.0),)


def test_section_with_a_tide_prints_and_saves_it(tmp_path, capsys):
    out = str(tmp_path / "s.png")
    assert cli.main(["section", "--thetadot", "0.83", "--orbits", "3", "--rtol", "1e-10",
                     "--tide", "secondary", "--k2", "1e-5", "--time-lag", "600", "--strength",
                     "1e6", "--byorp", "1e-3", "--out", out]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == ("perturbations: tide on the secondary (k2 1e-05, time lag 600 s); BYORP "
                        "(B 0.001); strength 1e+06 (docs/physics.md §13; drifts are those of "
                        "E - W and L - L_ext)")
    saved = tso.load(tmp_path / "s.npz")
    assert saved.perturbations == (tso.Tides(k2=1e-5, time_lag=600.0, strength=1e6),
                                   tso.BYORP(coefficient=1e-3, strength=1e6))


def test_section_with_the_sun_prints_and_saves_it(tmp_path, capsys):
    out = str(tmp_path / "s.png")
    assert cli.main(["section", "--thetadot", "0.83", "--orbits", "2", "--rtol", "1e-10",
                     "--sun", "--heliocentric", "1.1", "0.2", "--sun-inclination", "20",
                     "--strength", "100", "--out", out]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == ("perturbations: the Sun's tide (i 20°, node 0°, perihelion 0°, M0 0°); "
                        "strength 100 (docs/physics.md §13; drifts are those of E - W and "
                        "L - L_ext)")
    assert tso.load(tmp_path / "s.npz").perturbations == (tso.SolarTide(
        heliocentric_a_au=1.1, heliocentric_e=0.2, inclination_deg=20.0, strength=100.0),)


def test_section_with_a_flyby_prints_and_saves_it(tmp_path, capsys):
    out = str(tmp_path / "f.png")
    assert cli.main(["section", "--thetadot", "0.83", "--orbits", "1", "--rtol", "1e-10",
                     "--flyby", "Earth", "--flyby-q", "2e5", "--flyby-vinf", "5",
                     "--flyby-time", "10", "--flyby-inclination", "30", "--out", out]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == ("perturbations: Earth flyby (q 200000 km, v_inf 5 km/s, closest at "
                        "10 h, i 30°); strength 1 (docs/physics.md §13; drifts are those of "
                        "E - W and L - L_ext)")
    assert tso.load(tmp_path / "f.npz").perturbations == (tso.Flyby(
        "Earth", q_km=2e5, v_inf_km_s=5.0, t_closest_h=10.0, inclination_deg=30.0),)


def test_energy_with_a_tide_prints_the_work(tmp_path, capsys):
    out = str(tmp_path / "e.png")
    assert cli.main(["energy", "--system", "1991 VH", "--thetadot", "0.8", "--orbits", "2",
                     "--rtol", "1e-11", "--max-drift", "1e-6", "--tide", "secondary",
                     "--time-lag", "600", "--strength", "1e6", "--out", out]) == 0
    text = capsys.readouterr().out
    assert "perturbations: tide on the secondary (k2 " in text and "(rubble pile)" in text
    work = [line for line in text.splitlines() if "work done by the perturbations" in line]
    ts = tso.load(tmp_path / "e.npz")
    assert ts.work[0, -1] < 0                                  # the tide dissipates
    assert work == [f"  work done by the perturbations W = {ts.work[0, -1]:.6e} J by the end "
                    "(< 0: dissipated); external angular momentum |L_ext| = 0.000e+00 kg m^2/s"]


def test_warmup_perturbed(capsys):
    assert cli.main(["warmup", "--models", "planar", "--indicators", "off", "--sampling", "off",
                     "--perturbed"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("planar/plain/sections/order4/cash-karp: ")
    assert lines[1].startswith("planar/plain/sections/order4/perturbed/cash-karp: ")
    assert lines[-1].startswith("2 kernel variants ready (")


@pytest.mark.parametrize("argv", [
    ["map", "--grid", "2", "2", "--orbits", "3", "--rtol", "1e-10"],
    ["overlap", "--system", "2004 DC", "--elongations", "1.03", "1.03", "0.01", "--orbits", "3",
     "--max-orbits", "3"],
    ["libration", "--orbits", "3", "--candidates", "0.2", "1.3", "9", "--max-orbits", "3"],
])
def test_every_integrating_command_saves_its_perturbations(argv, tmp_path, capsys):
    out = str(tmp_path / "r.png")
    assert cli.main([*argv, "--tide", "secondary", "--Q", "50", "--strength", "1e5",
                     "--allow-inaccurate", "--out", out]) == 0
    assert capsys.readouterr().out.startswith("perturbations: tide on the secondary (k2 ")
    assert tso.load(tmp_path / "r.npz").perturbations == (tso.Tides(Q=50.0, strength=1e5),)
