"""initial_states= on the public entry points: explicit 3-D starts through
surface_of_section and time_series, the full physical state of time series, the attitude
class and largest tilt of every member, and what saved files keep."""

import numpy as np
import pytest

import ti_spinorbit as tso


@pytest.fixture(scope="module")
def didymos():
    return tso.catalog.system("Didymos")


def test_planar_state_through_initial_states_matches_the_papers_start(vh):
    # the same start two ways: the conversion through SI units differs from the paper's
    # start by round-off only (V: m_red v / (m_red a n)), so a regular trajectory agrees to
    # about the tolerance, and both run the planar model
    kw = dict(orbits=5, rtol=1e-12)
    a = tso.surface_of_section(vh, 20.0, 0.43, **kw)
    b = tso.surface_of_section(vh, orbits=5, rtol=1e-12,
                               initial_states=[vh.tilted_start(20.0, 0.43)])
    assert b.count[0] == a.count[0] == 5
    np.testing.assert_allclose(b.thetadot_p, a.thetadot_p, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.theta_p, a.theta_p, rtol=0, atol=1e-7)
    assert b.initial_theta_p[0] == pytest.approx(20.0, abs=1e-12)
    assert b.initial_thetadot_p[0] == pytest.approx(0.43, abs=1e-12)
    np.testing.assert_allclose(b.initial_states, a.initial_states, rtol=1e-14, atol=1e-18)
    assert b.max_tilt[0] == a.max_tilt[0] == 0.0


def test_tilted_time_series_keeps_states_classes_and_conserves(didymos):
    starts = [didymos.tilted_start(0.0, 1.0), didymos.tilted_start(0.0, 1.0, roll=10.0),
              didymos.tilted_start(0.0, 2.5), didymos.tilted_start(0.0, 0.0, spin_x=3.0)]
    ts = tso.time_series(didymos, orbits=20, samples_per_orbit=32, rtol=1e-10,
                         initial_states=starts, states=True)
    assert ts.attitude_class_names == ["planar libration", "3-D libration", "circulation",
                                       "tumbling"]
    assert np.all(ts.status == tso.Status.DONE)
    assert np.all(ts.energy_drift < 1e-7) and np.all(ts.angmom_drift < 1e-7)
    # the stored physical state: its first sample is the start, the pole tilt follows it
    np.testing.assert_allclose(ts.states[:, 0], ts.initial_states, rtol=1e-12,
                               atol=1e-12 * np.abs(ts.initial_states).max())
    np.testing.assert_allclose(ts.R[1, 0], starts[1].R, rtol=1e-12)
    np.testing.assert_allclose(ts.secondary_attitude[1, 0], starts[1].secondary_attitude, atol=1e-12)
    np.testing.assert_allclose(ts.euler_angles[1, 0], [10.0, 0.0, 0.0], atol=1e-9)
    assert ts.max_tilt[1] == pytest.approx(np.nanmax(np.abs(ts.euler_angles[1, :, 0])), rel=0.2)
    # |R| of the states is the recorded separation
    np.testing.assert_allclose(np.linalg.norm(ts.R, axis=-1), ts.r, rtol=1e-12)
    # the yaw in a planar member is the recorded α
    np.testing.assert_allclose(ts.euler_angles[0, :, 2], ts.alpha[0], atol=1e-9)


def test_states_off_by_default_and_the_message_says_how(didymos):
    ts = tso.time_series(didymos, 0.0, 1.0, orbits=1, samples_per_orbit=8, rtol=1e-9)
    assert ts.states is None and ts.attitude_class_names == ["planar libration"]
    with pytest.raises(ValueError, match=r"states=True"):
        ts.R


def test_saved_files_keep_the_states(tmp_path, didymos):
    ts = tso.time_series(didymos, orbits=1, samples_per_orbit=8, rtol=1e-9, states=True,
                         initial_states=[didymos.tilted_start(0.0, 1.0, pitch=5.0)])
    back = tso.load(tso.save(ts, tmp_path / "ts.npz"))
    np.testing.assert_array_equal(back.states, ts.states)
    np.testing.assert_array_equal(back.initial_states, ts.initial_states)
    np.testing.assert_array_equal(back.attitude_class, ts.attitude_class)
    restored = tso.InitialState.from_row(back.initial_states[0])
    np.testing.assert_allclose(restored.secondary_attitude,
                               didymos.tilted_start(0.0, 1.0, pitch=5.0).secondary_attitude, atol=1e-12)


@pytest.mark.parametrize("kw, error, text", [
    (dict(theta_p=0.0, thetadot_p=1.0), ValueError, "not both"),
    (dict(coordinates="apsidal"), ValueError, "coordinates='inertial'"),
    (dict(initial_states=[]), ValueError, "at least one InitialState"),
    (dict(initial_states=["start"]), TypeError, r"initial_states\[0\] must be an InitialState"),
])
def test_bad_initial_states(vh, kw, error, text):
    args = dict(orbits=1, initial_states=[vh.tilted_start(0.0, 1.0)]) | kw
    with pytest.raises(error, match=text):
        tso.surface_of_section(vh, **args)


def test_no_starts_at_all(vh):
    with pytest.raises(TypeError, match="give the starts as theta_p and thetadot_p"):
        tso.surface_of_section(vh, orbits=1)


def test_one_system_per_state(vh, didymos):
    sec = tso.surface_of_section([vh, didymos], orbits=2, rtol=1e-9,
                                 initial_states=[vh.tilted_start(0.0, 1.0, roll=1.0),
                                                 didymos.tilted_start(0.0, 1.0)])
    assert [s.name for s in sec.systems] == ["1991 VH", "Didymos"]
    assert sec.max_tilt[0] >= 1.0 - 1e-9 and sec.max_tilt[1] == 0.0
    with pytest.raises(ValueError, match="one system or one per state"):
        tso.surface_of_section([vh, didymos], orbits=1, initial_states=[vh.tilted_start(0, 1)] * 3)


def test_cli_section_with_a_tilt(tmp_path):
    from conftest import run_cli

    p = run_cli("section", "--system", "1991 VH", "--orbits", "10", "--rtol", "1e-10",
                "--thetadot", "0.43", "--tilt", "5", "0", "0", "--no-progress", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "largest pole tilt 5 deg" in p.stdout
    npz, = tmp_path.glob("sos_1991VH_td0.43_o10_rtol1e-10_tilt5-0-0.npz")
    back = tso.load(npz)
    start = tso.InitialState.from_row(back.initial_states[0])
    assert np.degrees(np.arccos(start.secondary_attitude[2, 2])) == pytest.approx(5.0, abs=1e-9)


@pytest.mark.parametrize("flags, text", [
    (["--tilt", "5", "0", "0", "--coordinates", "apsidal"], "need --coordinates inertial"),
    (["--tilt", "400", "0", "0"], "--tilt must lie in [-360, 360]"),
    (["--spin-xy", "0", "1e3"], "--spin-xy must lie in [-100, 100]"),
])
def test_cli_tilt_errors(tmp_path, flags, text):
    from conftest import run_cli

    p = run_cli("section", "--orbits", "1", *flags, cwd=tmp_path)
    assert p.returncode == 2 and text in p.stderr and not list(tmp_path.iterdir())


def test_one_system_per_state_errors_name_the_member(vh, didymos):
    # each state is checked against its own system, and the message names its index
    touching = tso.InitialState(R=[300.0, 0, 0], V=[0, 0.1, 0], primary_attitude=np.eye(3),
                                primary_omega=[0, 0, 0], secondary_attitude=np.eye(3),
                                secondary_omega=[0, 0, 1e-4])
    with pytest.raises(ValueError, match=r"^initial_states\[1\]: the bodies overlap at the start"):
        tso.surface_of_section([vh, didymos], orbits=1,
                               initial_states=[vh.tilted_start(0.0, 1.0), touching])
