"""Attitude observables of the secondary (Euler angles in the orbit frame, pole tilt,
non-principal rotation) and the per-member classification: inverses of the tilted start,
agreement with the planar observable α, free-rotation limits, and four integrated cases."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import attitude as att
from ti_spinorbit.system import initial as I
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.model.observables import derive


@pytest.fixture(scope="module")
def didymos():
    return tso.catalog.system("Didymos")


def test_euler_angles_invert_the_tilted_start(vh):
    rng = np.random.default_rng(5)
    for _ in range(25):
        roll, pitch = rng.uniform(-80, 80, size=2)
        theta, yaw = rng.uniform(-90, 90, size=2)
        s = I.tilted_start(vh, theta, 1.3, roll=roll, pitch=pitch, yaw=yaw,
                           inclination=rng.uniform(-40, 40), primary_tilt=rng.uniform(-40, 40))
        got = att.euler_angles(s.to_scaled(vh))
        np.testing.assert_allclose(got, [roll, pitch, theta + yaw], atol=1e-10)
        cos_tilt = np.cos(np.radians(roll)) * np.cos(np.radians(pitch))
        assert att.pole_tilt(s.to_scaled(vh)) == pytest.approx(np.degrees(np.arccos(cos_tilt)), abs=1e-9)


def test_planar_states(vh):
    y = np.stack([vh.initial_state(np.radians(t), td) for t, td in ((25.0, 1.2), (-60.0, -0.7))])
    np.testing.assert_allclose(att.euler_angles(y), [[0, 0, 25.0], [0, 0, -60.0]], atol=1e-12)
    np.testing.assert_allclose(att.pole_tilt(y), 0.0, atol=1e-6)
    np.testing.assert_allclose(att.body_angular_momentum(y), [[0, 0, 1], [0, 0, -1]], atol=1e-15)
    np.testing.assert_allclose(att.spin_axis_angle(y, vh), [0.0, 180.0], atol=1e-6)
    A, B, C = vh.secondary.moments
    np.testing.assert_allclose(att.dynamic_inertia(y, vh), C / B, rtol=1e-14)


def test_long_axis_spin_has_the_long_axis_dynamic_inertia(vh):
    y = I.tilted_start(vh, 0.0, 0.0, spin_x=2.0).to_scaled(vh)
    A, B, C = vh.secondary.moments
    assert att.dynamic_inertia(y, vh) == pytest.approx(A / B, rel=1e-14)
    np.testing.assert_allclose(att.body_angular_momentum(y), [1, 0, 0], atol=1e-15)
    assert att.spin_axis_angle(y, vh) == pytest.approx(90.0, abs=1e-9)


@pytest.fixture(scope="module")
def integrated(didymos):
    """Didymos (synchronous, a/b = 1.3), 20 orbits, 32 samples per orbit, 3-D model."""
    starts = {"planar libration": didymos.tilted_start(0.0, 1.0),
              "3-D libration": didymos.tilted_start(0.0, 1.0, roll=10.0),
              "circulation": didymos.tilted_start(0.0, 2.5),
              "tumbling": didymos.tilted_start(0.0, 0.0, spin_x=3.0)}
    y = I.as_scaled_states(didymos, list(starts.values()))
    ens = Ensemble(np.tile(didymos.parameter_row(), (len(y), 1)), y, rtol=1e-10, model="3d")
    out = ens.run(2 * np.pi * 20, sample_dt=2 * np.pi / 32)
    assert np.all(out.status == 1)
    return list(starts), out, ens


def test_classification_of_four_canonical_starts(integrated, didymos):
    names, out, _ = integrated
    codes = att.classify([s[:, 1:] for s in out.samples], didymos)
    assert att.class_names(codes) == names


def test_yaw_is_the_planar_alpha_along_a_planar_run(integrated):
    # independent formula: observables.derive's α (cross and dot products with the line of
    # centres) against the Euler decomposition of the relative attitude matrix
    _, out, ens = integrated
    for k in (0, 2):                                      # the two planar members
        s = out.samples[k][:, 1:]
        alpha = np.degrees(derive(ens.par[k], s)["alpha"])
        np.testing.assert_allclose(att.euler_angles(s)[:, 2], alpha, atol=1e-9)
        assert np.max(np.abs(att.euler_angles(s)[:, :2])) < 1e-9


def test_thresholds_move_the_3d_libration_between_classes(integrated, didymos):
    _, out, _ = integrated
    s = [out.samples[1][:, 1:]]
    tilt = att.pole_tilt(s[0]).max()
    assert 10.0 <= tilt < 30.0
    assert att.class_names(att.classify(s, didymos, tilt_angle=tilt + 1.0)) == ["planar libration"]
    assert att.class_names(att.classify(s, didymos, npa_angle=1.0)) == ["tumbling"]


@pytest.mark.parametrize("kw, text", [(dict(tilt_angle=0.0), "tilt_angle must lie in (0, 90]"),
                                      (dict(npa_angle=120.0), "npa_angle must lie in (0, 90]")])
def test_bad_thresholds(vh, kw, text):
    y = np.stack([vh.initial_state(0.0, 1.0)] * 3)
    with pytest.raises(ValueError, match=text.replace("(", r"\(").replace("]", r"\]")):
        att.classify([y], vh, **kw)


def test_too_few_samples_and_wrong_width(vh):
    with pytest.raises(ValueError, match="member 0 hold 1 finite states"):
        att.classify([np.stack([vh.initial_state(0.0, 1.0), np.full(30, np.nan)])], vh)
    with pytest.raises(ValueError, match="30 columns"):
        att.euler_angles(np.zeros((4, 31)))


def test_hyperion_like_synchronous_state_is_attitude_unstable(didymos):
    # Wisdom, Peale & Mignard (1984): for Hyperion (ω0 ≈ 0.89, e = 0.1, decoupled) the
    # synchronous state is attitude-unstable, the tilt e-folding in a few orbits; the
    # synchronous Didymos secondary is stable out of the plane. A 1e-4° roll, 14 orbits.
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "experiments"))
    try:
        from attitude_hyperion import e_folding, hyperion_system
    finally:
        sys.path.pop(0)
    hyp = hyperion_system()
    centre = 0.544395            # its synchronous island centre (relaxed_libration, 50 orbits)
    ts = tso.time_series([hyp, didymos], orbits=14, samples_per_orbit=16, rtol=1e-12, states=True,
                         initial_states=[hyp.tilted_start(0.0, centre, roll=1e-4),                                          didymos.tilted_start(0.0, 1.0, roll=1e-4)],
                         integrator=tso.Integrator(model="3d"), run=tso.Run(progress=False))
    assert np.all(ts.status == tso.Status.DONE)
    tilt = ts.pole_tilt
    assert np.nanmax(tilt[0]) > 0.1 and np.nanmax(tilt[1]) < 1e-3       # grew 1000x / did not
    fold = e_folding(ts.t[0] / hyp.orbital_period, tilt[0], 1e-4)
    assert 0.8 < fold < 2.5                     # orbits ("a few orbital periods"; 1.4 at 40)


def test_classify_crossings_rule():
    codes = att.classify_crossings(
        synchronous=[True, True, False, True, False, True],
        max_tilt=[0.5, 5.0, 0.2, 0.5, 80.0, np.nan],
        max_npa=[0.1, 3.0, 0.1, 45.0, 2.0, 0.1])
    assert att.class_names(codes) == ["planar libration", "3-D libration", "circulation",
                                           "tumbling", "circulation", ""]


def test_chaos_maps_carry_attitude_classes(tmp_path):
    grid = dict(theta_p=[0.0, 90.0], thetadot_p=[0.43, 1.63], orbits=40, rtol=1e-10,
                run=tso.Run(progress=False))
    flat = tso.chaos_map("1991 VH", **grid)
    tilted = tso.chaos_map("1991 VH", **grid, tilt=(5.0, 0.0))
    # planar: synchronous-island starts librate in the plane, the others circulate
    sync = (flat.classification == "resonant")
    assert flat.attitude_class_names[0, 0] == "planar libration"      # θ_p 0, 0.43: the island
    assert set(flat.attitude_class_names[~sync]) <= {"circulation"}
    assert np.all(flat.max_tilt == 0.0)
    # tilted by 5°: the island start librates in 3-D, the chaotic start (1.63) tumbles
    assert tilted.attitude_class_names[0, 0] == "3-D libration"
    assert tilted.attitude_class_names[1, 0] == "tumbling"
    back = tso.load(tso.save(tilted, tmp_path / "m.npz"))
    np.testing.assert_array_equal(back.attitude_class, tilted.attitude_class)
