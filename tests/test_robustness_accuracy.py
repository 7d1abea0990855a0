"""Accuracy is checked, not assumed, and the command line's
outputs: paths checked before any work, data written before the figure, exit statuses.

A healthy Cash-Karp run drifts linearly in rtol and in the run length (≈ 13 rtol per orbit in
energy for 1991 VH, experiments/drift_calibration.py); at rtol 1e-2 … 1e-6 the drift of a
few orbits is already far above the default limit, so loose tolerances give members that
must be flagged "inaccurate" while their data are kept."""

import os
import time

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import cli
from ti_spinorbit.engine import accuracy
from ti_spinorbit.cli import common
from ti_spinorbit.kernels.advance import (COLLISION, DONE, ESCAPE, INACCURATE, NONFINITE,
                                           STATUS_NAMES, STEP_UNDERFLOW)

from conftest import run_cli

VH = tso.catalog.system("1991 VH")
#: Taichi prints its "Starting on arch" line only when asked (ti_spinorbit/runtime.py): the
#: runs below ask, so the line's absence means Taichi never started (that it shows when
#: Taichi does start: tests/test_cli.py::test_taichi_prints_nothing_in_the_command_or_the_library)
TAICHI_VERBOSE = {"TI_SPINORBIT_VERBOSE": "1"}
STARTS = [0.83, 1.63]


# ---- the limit and the verdict ------------------------------------------------------------

@pytest.mark.parametrize("rtol, orbits, expected", [
    (1e-12, 500, 5e-7), (1e-10, 300, 3e-5), (1e-12, 0.5, 1e-9),   # short runs count as 1
    (1e-2, 50, accuracy.DRIFT_CAP), (1e-8, 1e6, accuracy.DRIFT_CAP)])
def test_default_limit_scales_with_tolerance_and_length(rtol, orbits, expected):
    assert accuracy.drift_limit(rtol, orbits) == pytest.approx(expected, rel=1e-12)


def test_explicit_limit_wins():
    assert accuracy.drift_limit(1e-12, 100, 0.5) == 0.5
    assert accuracy.drift_limit(1e-2, 100, 1.0) == 1.0


@pytest.mark.parametrize("bad", [0.0, -1e-3, 1.5, float("nan"), float("inf"), "1e-3", [1e-3],
                                 True, 1e-3j])
def test_bad_max_drift_is_refused_naming_it(bad):
    with pytest.raises((TypeError, ValueError), match="max_drift"):
        accuracy.drift_limit(1e-12, 10, bad)


@pytest.mark.parametrize("status, e, l, expected", [
    (DONE, 1e-9, 1e-9, DONE),                      # within the limit
    (DONE, 1e-3, 1e-9, INACCURATE),                # energy above
    (DONE, 1e-9, 1e-3, INACCURATE),                # angular momentum above
    (DONE, np.nan, 1e-9, NONFINITE),               # never "done" with a NaN
    (DONE, 1e-9, np.inf, NONFINITE),
    (COLLISION, 1e-3, 1e-3, INACCURATE),           # stopped early past the limit: not trusted
    (COLLISION, 1e-9, 1e-9, COLLISION),            # stopped early within it: its own status
    (ESCAPE, np.nan, np.nan, ESCAPE),
    (STEP_UNDERFLOW, 1e-9, 1e-9, STEP_UNDERFLOW),
    (NONFINITE, np.nan, np.nan, NONFINITE)])
def test_verdict_per_member(status, e, l, expected):
    out = accuracy.verdict([status], [e], [l], 1e-6)
    assert out.tolist() == [expected]


def test_verdict_does_not_modify_its_input():
    status = np.array([DONE, DONE], dtype=np.int32)
    accuracy.verdict(status, [1.0, 0.0], [0.0, 0.0], 1e-6)
    assert status.tolist() == [DONE, DONE]


def test_status_table_names_the_new_status():
    assert STATUS_NAMES[INACCURATE] == "inaccurate"
    assert tso.output.io.status_codes()[INACCURATE] == "inaccurate"
    assert accuracy.counts([DONE, INACCURATE, INACCURATE]) == {"done": 1, "inaccurate": 2}


# ---- sections and time series -----------------------------------------------------------

@pytest.fixture(scope="module")
def loose():
    return tso.surface_of_section(VH, 0.0, STARTS, orbits=20, rtol=1e-4)


@pytest.fixture(scope="module")
def tight():
    return tso.surface_of_section(VH, 0.0, STARTS, orbits=20, rtol=1e-12)


def test_loose_tolerance_is_flagged_and_its_data_kept(loose):
    assert loose.status_names == ["inaccurate", "inaccurate"]
    assert loose.n_inaccurate == 2 and loose.status_counts == {"inaccurate": 2}
    assert np.all(loose.energy_drift > loose.max_drift) and loose.max_drift == 1e-4
    assert np.all(loose.count >= 15)                       # every crossing is still there
    assert np.all(np.isfinite(loose.theta_p[:, :15]))


def test_healthy_drift_sits_on_the_calibrated_line(tight):
    """The drift is measured, not zero: 1 … 100 × rtol per orbit (13 measured), far below
    the limit of 1000 × rtol per orbit."""
    scale = tight.rtol * tight.orbits
    assert tight.status_names == ["done", "done"]
    assert np.all((tight.energy_drift > scale) & (tight.energy_drift < 100 * scale))
    assert np.all((tight.angmom_drift > 0.3 * scale) & (tight.angmom_drift < 100 * scale))
    assert tight.max_drift == pytest.approx(1000 * scale)


def test_verdict_changes_the_status_only():
    a = tso.surface_of_section(VH, 0.0, STARTS, orbits=10, rtol=1e-4)
    b = tso.surface_of_section(VH, 0.0, STARTS, orbits=10, rtol=1e-4, max_drift=1.0)
    assert a.status_names == ["inaccurate"] * 2 and b.status_names == ["done"] * 2
    for name in ("theta_p", "thetadot_p", "t", "energy_drift", "angmom_drift", "count"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_time_series_drift_is_the_largest_over_its_samples():
    """Checked against the SI energies and angular momenta of the samples themselves; the
    end of the run (1/16 orbit past the last sample) may add its linear share, ~2 %."""
    ts = tso.time_series(VH, 0.0, STARTS, orbits=3, samples_per_orbit=16, rtol=1e-6)
    for i in range(2):
        ok = np.isfinite(ts.t[i])
        e = ts.energy[i][ok]
        lvec = (ts.angmom_orbit + ts.angmom_primary + ts.angmom_secondary)[i][ok]
        de = np.max(np.abs(e - e[0])) / abs(e[0])
        dl = np.max(np.linalg.norm(lvec - lvec[0], axis=1)) / np.linalg.norm(lvec[0])
        assert de * (1 - 1e-9) <= ts.energy_drift[i] <= de * 1.1
        assert dl * (1 - 1e-9) <= ts.angmom_drift[i] <= dl * 1.1
    assert ts.status_names == ["done", "done"] and ts.max_drift == 1e-4
    strict = tso.time_series(VH, 0.0, STARTS, orbits=3, samples_per_orbit=16, rtol=1e-6,
                             max_drift=1e-9)
    assert strict.status_names == ["inaccurate", "inaccurate"]
    np.testing.assert_array_equal(strict.energy, ts.energy)


def test_a_nan_in_any_sample_makes_the_member_non_finite():
    from ti_spinorbit.engine.ensemble import RunOutput
    from ti_spinorbit.studies.section import _sampled_drifts

    diag = np.zeros((2, 14))
    diag[:, 0] = -1.0
    diag[:, 5] = 1.0                                      # L_z of the orbit
    nan_sample = np.array([[-1.0, -1.0, np.nan, np.nan], [-1.0, -1.0, -1.0, np.nan]])
    cols = {"t": np.array([[0, 1, 2, np.nan], [0, 1, 2, np.nan]], float),
            "energy_orbit": nan_sample, "energy_primary": np.zeros((2, 4)),
            "energy_secondary": np.zeros((2, 4))}
    for k in ("orbit", "primary", "secondary"):
        cols[f"angmom_{k}"] = np.zeros((2, 4, 3))
    cols["angmom_orbit"][..., 2] = 1.0
    out = RunOutput(events=[], samples=[], diag_start=diag, diag_end=diag, t=np.zeros(2),
                    y=np.zeros((2, 30)), status=np.full(2, DONE), counters=np.zeros((2, 3)))
    e, l = _sampled_drifts(cols, out)
    assert np.isnan(e[0]) and e[1] == 0.0               # padding (t NaN) is not a sample
    assert accuracy.verdict(out.status, e, l, 1e-6).tolist() == [NONFINITE, DONE]


def test_classification_leaves_inaccurate_members_undetermined(loose):
    assert list(tso.classify_section(loose).classification) == ["undetermined"] * 2
    labels = tso.classify_section(loose, include_inaccurate=True, min_points=8).classification
    assert "undetermined" not in list(labels)


# ---- maps, scans, libration -------------------------------------------------------------

@pytest.fixture(scope="module")
def loose_map():
    return tso.chaos_map(VH, [0.0, 90.0], [0.8, 1.6], orbits=20, rtol=1e-4)


def test_chaos_map_counts_inaccurate_members_apart(loose_map):
    assert loose_map.n_inaccurate == 4 and loose_map.status_counts == {"inaccurate": 4}
    assert np.isnan(loose_map.chaotic_fraction)            # nothing trustworthy to count
    assert loose_map.energy_drift.shape == (2, 2) and np.all(loose_map.energy_drift > 1e-4)
    assert np.all(np.isfinite(loose_map.megno))            # data kept
    assert set(loose_map.classification.ravel()) <= {"resonant", "quasi-periodic", "chaotic"}


def test_chaos_map_includes_them_when_asked():
    m = tso.chaos_map(VH, [0.0, 90.0], [0.8, 1.6], orbits=20, rtol=1e-4,
                      include_inaccurate=True)
    labels = m.classification.ravel()
    assert m.chaotic_fraction == pytest.approx(np.mean(labels == "chaotic"))
    assert m.include_inaccurate and m.n_inaccurate == 4


def test_chaos_map_at_a_sound_tolerance_is_all_done():
    m = tso.chaos_map(VH, [0.0, 90.0], [0.8, 1.6], orbits=20, rtol=1e-10)
    assert m.n_inaccurate == 0 and m.status_counts == {"done": 4}
    assert np.all(m.energy_drift < m.max_drift) and np.isfinite(m.chaotic_fraction)


def test_chaos_map_verdict_survives_save_and_load(loose_map, tmp_path):
    back = tso.load(tso.save(loose_map, tmp_path / "m.npz"))
    assert back.n_inaccurate == 4 and back.max_drift == loose_map.max_drift
    np.testing.assert_array_equal(back.status, loose_map.status)
    np.testing.assert_array_equal(back.energy_drift, loose_map.energy_drift)
    meta = tso.output.io.read_metadata(tmp_path / "m.npz")
    assert meta["units"]["energy_drift"] == "1 (relative)"
    assert meta["status_counts"]["inaccurate"] == 4


def test_parameter_map_counts_inaccurate_starts_per_cell():
    pm = tso.parameter_map("1991 VH", [1.3], [0.05], orbits=10, thetadot_p=[0.9, 1.5],
                           theta_p=[0.0], rtol=1e-4)
    assert pm.inaccurate.tolist() == [[2]] and pm.n_inaccurate == 2
    assert np.isnan(pm.chaotic_fraction[0, 0]) and pm.energy_drift.shape == (1, 1, 2)


def test_overlap_decisions_leave_inaccurate_trajectories_out():
    kw = dict(elongations=[1.3], orbits=10, centre_starts=6, separatrix_starts=4,
              indicators=False)
    scan = tso.overlap_threshold("1991 VH", rtol=1e-4, **kw)
    d = scan.decisions[0]
    assert d.inaccurate == 10 and scan.n_inaccurate == 10
    assert not d.overlap and scan.first_overlap is None    # no evidence from bad runs
    assert d.max_energy_drift > scan.max_drift


def test_libration_amplitude_is_nan_for_an_inaccurate_member():
    from ti_spinorbit.studies.libration import libration_amplitude

    # dense samples cap the step, so even rtol 1e-4 drifts only ~4e-6 here: ask for less
    bad = libration_amplitude(VH, 0.6, orbits=3, samples_per_orbit=32, rtol=1e-4,
                              max_drift=1e-9)
    kept = libration_amplitude(VH, 0.6, orbits=3, samples_per_orbit=32, rtol=1e-4,
                               max_drift=1e-9, include_inaccurate=True)
    assert np.isnan(bad) and np.isfinite(kept) and 0 < kept < 90


def test_relaxed_libration_refuses_when_every_candidate_is_inaccurate():
    with pytest.raises(RuntimeError, match="every candidate's conservation drift exceeds"):
        tso.relaxed_libration(tso.catalog.system("Didymos"), orbits=3, rtol=1e-10,
                              max_drift=1e-15)


# ---- command line: accuracy and exit statuses -------------------------------------------

def test_cli_map_with_a_loose_tolerance_exits_3_and_keeps_the_data(tmp_path):
    p = run_cli("map", "--grid", "2", "2", "--orbits", "10", "--rtol", "1e-4", "--quiet",
                cwd=tmp_path)
    assert p.returncode == cli.EXIT_INACCURATE == 3, p.stderr
    assert "4 of 4 members inaccurate" in p.stderr and "--allow-inaccurate" in p.stderr
    m = tso.load(tmp_path / "map_1991VH_g2x2_o10_rtol1e-4.npz")      # the default name
    assert m.n_inaccurate == 4 and (tmp_path / "map_1991VH_g2x2_o10_rtol1e-4.png").exists()


def test_cli_allow_inaccurate_exits_0_and_counts_them(tmp_path):
    p = run_cli("section", "--thetadot", "0.83", "--orbits", "5", "--rtol", "1e-4",
                "--allow-inaccurate", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "status inaccurate" in p.stdout and "1 of 1 members inaccurate" in p.stderr


def test_cli_max_drift_override_passes_the_same_run(tmp_path):
    p = run_cli("section", "--thetadot", "0.83", "--orbits", "5", "--rtol", "1e-4",
                "--max-drift", "1", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "status done" in p.stdout and "inaccurate" not in p.stderr


def test_cli_energy_fails_its_check_and_saves_the_verdict(tmp_path):
    p = run_cli("energy", "--orbits", "1", "--rtol", "1e-8", "--max-drift", "1e-12",
                "--quiet", cwd=tmp_path)
    assert p.returncode == 1 and "exceeds --max-drift" in p.stderr
    ts = tso.load(tmp_path / "energy_test_o1_rtol1e-8.npz")     # the default name
    assert ts.status_names == ["inaccurate"] and ts.max_drift == 1e-12


@pytest.mark.parametrize("value", ["0", "2", "nan", "-1e-3"])
def test_cli_bad_max_drift_names_the_flag(value, tmp_path):
    p = run_cli("map", f"--max-drift={value}", "--grid", "2", "2", cwd=tmp_path)
    assert p.returncode == 2 and "--max-drift must lie in (0, 1]" in p.stderr
    assert "Traceback" not in p.stderr


# ---- command line: outputs checked before any work --------------------------------------

def _bad_output_cases(tmp):
    (tmp / "folder.png").mkdir()
    (tmp / "folder.npz").mkdir()
    (tmp / "folder.json").mkdir()
    return {
        "out is a folder": (["section", "--out", "folder.png"], "'folder.png' is a folder"),
        "data is a folder": (["map", "--data", "folder.npz"], "'folder.npz' is a folder"),
        "missing folder": (["overlap", "--out", "no/such/o.png"], "does not exist"),
        "unwritable folder": (["section", "--out", "/proc/x.png"], "not writable"),
        "benchmark out is a folder": (["benchmark", "--out", "folder.json"], "is a folder"),
        "wrong extension": (["libration", "--out", "l.txt"], "--out must end in"),
        "default figure is a folder": (["section", "--data", "ok.npz", "--out", "x.png",
                                        "--system", "1991 VH"], None),
    }


@pytest.mark.parametrize("case", ["out is a folder", "data is a folder", "missing folder",
                                  "unwritable folder", "benchmark out is a folder",
                                  "wrong extension"])
def test_cli_output_problems_fail_before_any_work(case, tmp_path):
    args, message = _bad_output_cases(tmp_path)[case]
    started = time.perf_counter()
    p = run_cli(*args, "--orbits", "1e6", cwd=tmp_path,      # a run that would take hours
                env=TAICHI_VERBOSE)
    assert p.returncode == 2 and message in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
    assert "Starting on arch" not in p.stdout + p.stderr     # Taichi never started
    assert time.perf_counter() - started < 60


def test_cli_default_data_path_is_checked_too(tmp_path):
    (tmp_path / "sos_1991VH_o1e6.npz").mkdir()        # the default name carries --orbits
    p = run_cli("section", "--orbits", "1e6", cwd=tmp_path)
    assert p.returncode == 2 and "the data file (default --data)" in p.stderr


def test_cli_invalid_matplotlib_backend_fails_before_work(tmp_path):
    p = run_cli("section", "--orbits", "1e6", cwd=tmp_path,
                env={"MPLBACKEND": "nosuch", **TAICHI_VERBOSE})
    assert p.returncode == 2 and "MPLBACKEND='nosuch'" in p.stderr
    assert "Starting on arch" not in p.stdout + p.stderr and not list(tmp_path.iterdir())


def test_cli_data_name_in_upper_case_is_written_as_given(tmp_path):
    p = run_cli("section", "--thetadot", "0.83", "--orbits", "2", "--data", "r.NPZ",
                "--out", "r.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert sorted(os.listdir(tmp_path)) == ["r.NPZ", "r.png"]
    assert "wrote r.png and r.NPZ" in p.stdout
    assert tso.load(tmp_path / "r.NPZ").count[0] >= 1


def test_io_save_keeps_an_upper_case_extension(tight, tmp_path):
    assert tso.save(tight, tmp_path / "a.NPZ") == tmp_path / "a.NPZ"
    assert tso.save(tight, tmp_path / "b") == str(tmp_path / "b.npz")
    assert sorted(os.listdir(tmp_path)) == ["a.NPZ", "b.npz"]


def test_cli_plotting_failure_keeps_the_data(tmp_path, monkeypatch, capsys):
    from ti_spinorbit.output import plotting

    def broken(ax, path):
        raise RuntimeError("disk full")

    monkeypatch.setattr(plotting, "save_figure", broken)
    monkeypatch.chdir(tmp_path)
    status = cli.main(["section", "--thetadot", "0.83", "--orbits", "2", "--quiet"])
    err = capsys.readouterr().err
    assert status == 2 and "could not be written (disk full)" in err
    assert "the data are saved in sos_1991VH_td0.83_o2.npz" in err      # the default name
    assert tso.load(tmp_path / "sos_1991VH_td0.83_o2.npz").count[0] >= 1


# ---- --debug ----------------------------------------------------------------------------

def _raise_type_error(args):
    raise TypeError("a bug in user code")


@pytest.mark.parametrize("argv", [["--debug", "systems"], ["systems", "--debug"]])
def test_debug_keeps_the_traceback(argv, monkeypatch):
    monkeypatch.setitem(cli.HANDLERS, "systems", _raise_type_error)
    with pytest.raises(TypeError, match="a bug in user code"):
        cli.main(argv)


def test_without_debug_the_error_is_one_line(monkeypatch, capsys):
    monkeypatch.setitem(cli.HANDLERS, "systems", _raise_type_error)
    assert cli.main(["systems"]) == 2
    assert capsys.readouterr().err.strip() == "ti-spinorbit systems: error: a bug in user code"


def test_debug_shows_the_traceback_in_a_subprocess(tmp_path):
    p = run_cli("--debug", "systems", "--show", "nowhere", cwd=tmp_path)
    assert p.returncode == 1 and "Traceback" in p.stderr and "unknown system" in p.stderr


@pytest.mark.parametrize("status, allow, expected, message", [
    ([DONE, NONFINITE], False, 3, "1 of 2 members non-finite"),
    ([DONE, NONFINITE], True, 0, "1 of 2 members non-finite"),
    ([INACCURATE, NONFINITE], False, 3, "1 of 2 members inaccurate"),
    ([DONE, COLLISION, ESCAPE, STEP_UNDERFLOW], False, 0, ""),   # outcomes, not failures
    ([DONE, DONE], False, 0, "")])
def test_exit_status_counts_untrustworthy_members(status, allow, expected, message, capsys):
    import argparse

    args = argparse.Namespace(command="map", allow_inaccurate=allow)
    drift = np.where(np.array(status) == INACCURATE, 0.5, 1e-9)
    assert common.accuracy_status(args, np.array(status), drift, 1e-4) == expected
    err = capsys.readouterr().err
    assert (message in err) if message else err == ""


def test_xarray_views_carry_the_drifts(loose_map):
    pytest.importorskip("xarray")
    ds = tso.to_xarray(loose_map)
    np.testing.assert_array_equal(ds.energy_drift.values, loose_map.energy_drift)
    assert ds.energy_drift.attrs["units"] == "1 (relative)"
    assert ds.attrs["n_inaccurate"] == 4 and ds.attrs["max_drift"] == loose_map.max_drift
    assert list(np.unique(ds.status_name.values)) == ["inaccurate"]
