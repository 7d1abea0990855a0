"""The console script end to end, in subprocesses (tiny runs), and the saved files."""

import os
import subprocess
import sys

import numpy as np
import pytest

from ti_spinorbit.io import read_metadata


def run_cli(*args, cwd):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "ti_spinorbit", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


def test_section_writes_png_and_self_describing_data(tmp_path):
    p = run_cli("section", "--system", "1991 VH", "--thetadot", "0.83", "1.63", "--orbits", "5",
                "--rtol", "1e-10", "--out", "s.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    png = (tmp_path / "s.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10000
    with np.load(tmp_path / "s.npz") as d:
        assert d["theta_p"].shape[0] == 2 and np.all(d["count"] >= 4)
        assert np.nanmax(d["theta_p"]) < 180 and np.nanmin(d["theta_p"]) >= 0
        np.testing.assert_array_equal(d["initial_thetadot_p"], [0.83, 1.63])
    meta = read_metadata(tmp_path / "s.npz")
    assert meta["rtol"] == 1e-10 and meta["systems"][0]["name"] == "1991 VH"
    assert meta["units"]["thetadot_p"] == "mean motion n"
    assert "1991 VH" in p.stdout and "wrote" in p.stdout


def test_systems_lists_the_catalogue(tmp_path):
    p = run_cli("systems", cwd=tmp_path)
    assert p.returncode == 0
    for name in ("1991 VH", "2003 YT1", "2004 DC", "1999 KW4"):
        assert name in p.stdout


@pytest.mark.parametrize("args, message", [
    (("section", "--system", "1991 XX"), "unknown system"),
    (("section", "--elongation", "0.5"), "elongation"),
    (("section", "--rtol", "0"), "rtol"),
    (("section", "--orbits", "-3"), "orbits"),
])
def test_bad_input_prints_one_line_and_exits_nonzero(tmp_path, args, message):
    p = run_cli(*args, cwd=tmp_path)
    assert p.returncode == 2
    assert message in p.stderr and "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1


def test_overlap_scan_command(tmp_path):
    p = run_cli("overlap", "--system", "2004 DC", "--elongations", "1.01", "1.03", "0.02",
                "--orbits", "120", "--out", "ov.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "ov.png").read_bytes()[:4] == b"\x89PNG"
    meta = read_metadata(tmp_path / "ov.npz")
    assert meta["system"]["name"] == "2004 DC" and len(meta["decisions"]) == 2
    assert "first overlap" in p.stdout


def test_map_command(tmp_path):
    p = run_cli("map", "--system", "1991 VH", "--grid", "3", "4", "--orbits", "40",
                "--out", "m.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    with np.load(tmp_path / "m.npz") as d:
        assert d["megno"].shape == (3, 4) and np.all(np.isfinite(d["megno"]))
    assert 0.0 <= read_metadata(tmp_path / "m.npz")["chaotic_fraction"] <= 1.0


@pytest.mark.parametrize("args, message", [
    (("map", "--grid", "0", "4"), "--grid"),
    (("map", "--thetadot-range", "2", "1"), "thetadot-range"),
    (("overlap", "--elongations", "0.9", "1.1", "0.01"), "elongations"),
])
def test_bad_map_and_overlap_flags(tmp_path, args, message):
    p = run_cli(*args, cwd=tmp_path)
    assert p.returncode == 2 and message in p.stderr and "Traceback" not in p.stderr
