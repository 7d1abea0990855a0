"""InitialState: any 3-D start in SI units and an inertial frame, checked against the paper's
start, against the kernels' own diagnostics (an independent formula for the angular
momentum), against a rotation of the whole problem, and through a 3-D integration."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.system import initial as I
from ti_spinorbit.system.initial import InitialState
from ti_spinorbit.engine import accuracy, ensemble
from ti_spinorbit.model import planar


def random_rotation(rng):
    q = rng.normal(size=4)
    return I.quaternion_to_matrix(q / np.linalg.norm(q))


def random_state(system, rng, tilt=True):
    base = I.tilted_start(system, rng.uniform(0, 180), rng.uniform(0.5, 2.5),
                          roll=rng.uniform(-30, 30) * tilt, pitch=rng.uniform(-30, 30) * tilt,
                          spin_x=0.1 * tilt, spin_y=-0.05 * tilt,
                          inclination=rng.uniform(-20, 20) * tilt)
    return base


@pytest.fixture(scope="module")
def spun_vh():
    """1991 VH with a spinning primary (exercises the primary's spin term of the state)."""
    vh = tso.catalog.system("1991 VH")
    return tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=0.2, primary_spin_period=2.6 * 3600)


@pytest.mark.parametrize("theta, thetadot", [(0.0, 1.0), (30.0, 1.2), (135.0, -0.4), (89.0, 2.5)])
def test_untilted_start_is_the_papers_start(vh, spun_vh, theta, thetadot):
    for system in (vh, spun_vh):
        y = I.tilted_start(system, theta, thetadot).to_scaled(system)
        np.testing.assert_allclose(y, system.initial_state(np.radians(theta), thetadot),
                                   rtol=1e-15, atol=4e-16)     # round-off only


def test_untilted_start_qualifies_for_the_planar_model_and_a_tilted_one_does_not(vh):
    par = vh.parameter_row()
    flat = I.tilted_start(vh, 20.0, 1.1).to_scaled(vh)
    tilted = I.tilted_start(vh, 20.0, 1.1, roll=1e-3).to_scaled(vh)
    assert planar.qualifies(par, flat)[0] and not tso.model.planar.qualifies(par, tilted)[0]


def test_scaled_round_trip(spun_vh):
    rng = np.random.default_rng(1)
    for _ in range(5):
        s = InitialState(R=spun_vh.a * rng.normal(size=3) + [spun_vh.a, 0, 0],
                         V=0.05 * rng.normal(size=3), primary_attitude=random_rotation(rng),
                         primary_omega=1e-4 * rng.normal(size=3),
                         secondary_attitude=random_rotation(rng),
                         secondary_omega=1e-4 * rng.normal(size=3))
        back = InitialState.from_scaled(spun_vh, s.to_scaled(spun_vh))
        for name in ("R", "V", "primary_attitude", "primary_omega", "secondary_attitude",
                     "secondary_omega"):
            a, b = getattr(s, name), getattr(back, name)
            np.testing.assert_allclose(b, a, rtol=1e-13, atol=1e-13 * np.max(np.abs(a)), err_msg=name)


def test_rotating_the_whole_problem_changes_only_the_primary_attitude(spun_vh):
    # the kernels' state is in the primary's frame: a rigid rotation Q of the inertial frame
    # must leave everything but S1 unchanged (and S1 -> Q S1)
    rng = np.random.default_rng(2)
    s = random_state(spun_vh, rng)
    Q = random_rotation(rng)
    turned = InitialState(R=Q @ s.R, V=Q @ s.V, primary_attitude=Q @ s.primary_attitude,
                          primary_omega=s.primary_omega,
                          secondary_attitude=Q @ s.secondary_attitude,
                          secondary_omega=s.secondary_omega)
    y, yq = s.to_scaled(spun_vh), turned.to_scaled(spun_vh)
    np.testing.assert_allclose(yq[:21], y[:21], rtol=0, atol=2e-15)
    np.testing.assert_allclose(yq[21:].reshape(3, 3), Q @ y[21:].reshape(3, 3), atol=2e-15)


def test_angular_momentum_matches_the_kernels_diagnostics(spun_vh):
    # independent route: K = m R×V + A1 I1 ω1 + A2 I2 ω2 in SI and the inertial frame, from
    # the InitialState alone, against the kernels' scaled diagnostics of the converted state
    rng = np.random.default_rng(3)
    states = [random_state(spun_vh, rng) for _ in range(4)]
    y = I.as_scaled_states(spun_vh, states)
    ens = ensemble.Ensemble(np.tile(spun_vh.parameter_row(), (len(y), 1)), y, model="3d")
    _, L = accuracy.totals(ens.diagnostics())
    unit = spun_vh.total_mass * spun_vh.a**2 * spun_vh.mean_motion
    for s, l in zip(states, L):
        K = s.angular_momentum(spun_vh)
        np.testing.assert_allclose(l * unit, K, rtol=0, atol=1e-13 * np.linalg.norm(K))


def test_tilted_integration_conserves_energy_and_leaves_the_plane(vh):
    y = I.as_scaled_states(vh, [I.tilted_start(vh, 10.0, 1.0, roll=20.0, spin_x=0.2),
                                I.tilted_start(vh, 10.0, 1.0, inclination=15.0)])
    ens = ensemble.Ensemble(np.tile(vh.parameter_row(), (2, 1)), y, rtol=1e-11, model="auto")
    assert ens.model == "3d"
    d0 = ens.diagnostics()
    out = ens.run(2 * 2 * np.pi)
    assert np.all(out.status == 1)
    energy, angmom = accuracy.drifts(d0, out.diag_end)
    assert np.all(energy < 1e-9) and np.all(angmom < 1e-9)
    # the tilted secondary's spin axis precesses: its angle to the orbit normal changes
    end = InitialState.from_scaled(vh, out.y[0])
    start = InitialState.from_scaled(vh, y[0])
    normal = I.orbit_frame(start.R, start.V)[:, 2]
    tilt0 = np.degrees(np.arccos(start.secondary_attitude[:, 2] @ normal))
    tilt1 = np.degrees(np.arccos(end.secondary_attitude[:, 2] @ normal))
    assert tilt0 == pytest.approx(20.0, abs=1e-12) and abs(tilt1 - tilt0) > 0.1


@pytest.mark.parametrize("kw, axis, angle", [
    (dict(roll=90.0), [0.0, -1.0, 0.0], 90.0),       # Rx(90°) takes body z to −along-track
    (dict(pitch=90.0), [1.0, 0.0, 0.0], 90.0),       # Ry(90°) takes body z to radial
    (dict(roll=25.0), None, 25.0), (dict(pitch=-40.0), None, 40.0),
    (dict(yaw=70.0), [0.0, 0.0, 1.0], 0.0),          # yaw keeps the pole on the normal
])
def test_tilt_conventions(vh, kw, axis, angle):
    s = I.tilted_start(vh, 0.0, 1.0, **kw)
    pole = s.secondary_attitude[:, 2]
    frame = I.orbit_frame(s.R, s.V)
    assert np.degrees(np.arccos(np.clip(pole @ frame[:, 2], -1, 1))) == pytest.approx(angle, abs=1e-12)
    if axis is not None:
        np.testing.assert_allclose(frame.T @ pole, axis, atol=1e-15)


def test_inclination_turns_the_orbit_about_the_line_of_centres(vh):
    s = I.tilted_start(vh, 0.0, 1.0, inclination=30.0)
    h = np.cross(s.R, s.V)
    assert np.degrees(np.arccos(h[2] / np.linalg.norm(h))) == pytest.approx(30.0, abs=1e-12)
    assert s.R[1] == s.R[2] == 0.0                       # the pericentre is the node
    np.testing.assert_array_equal(s.primary_attitude, np.eye(3))


def test_quaternions():
    np.testing.assert_allclose(I.quaternion_to_matrix([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]),
                               [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    rng = np.random.default_rng(4)
    for _ in range(20):
        A = random_rotation(rng)
        q = I.matrix_to_quaternion(A)
        assert q[0] >= 0 and abs(np.linalg.norm(q) - 1) < 1e-15
        np.testing.assert_allclose(I.quaternion_to_matrix(q), A, atol=1e-15)
        np.testing.assert_allclose(I.quaternion_to_matrix(-q), A, atol=1e-15)   # q and −q agree
    s = InitialState(R=[1e4, 0, 0], V=[0, 0.1, 0], primary_attitude=[1, 0, 0, 0],
                     primary_omega=[0, 0, 0], secondary_attitude=I.matrix_to_quaternion(A),
                     secondary_omega=[0, 0, 1e-4])
    np.testing.assert_allclose(s.secondary_attitude, A, atol=1e-15)


GOOD = dict(R=[3000.0, 0, 0], V=[0, 0.18, 0], primary_attitude=np.eye(3), primary_omega=[0, 0, 0],
            secondary_attitude=np.eye(3), secondary_omega=[0, 0, 5e-5])


@pytest.mark.parametrize("change, error, text", [
    (dict(R=[0.0, 0, 0]), ValueError, "R must be a non-zero separation"),
    (dict(R=[1.0, 2.0]), ValueError, "R must have shape (3,)"),
    (dict(V=[0, np.nan, 0]), ValueError, "V must be finite"),
    (dict(V="fast"), TypeError, "V must be an array of real numbers"),
    (dict(primary_attitude=2 * np.eye(3)), ValueError, "primary_attitude must be orthonormal"),
    (dict(secondary_attitude=np.diag([1.0, 1.0, -1.0])), ValueError,
     "secondary_attitude must be a proper rotation with det +1"),
    (dict(secondary_attitude=[1.0, 0.1, 0, 0]), ValueError,
     "secondary_attitude must be a unit quaternion"),
    (dict(primary_omega=[0, 0, np.inf]), ValueError, "primary_omega must be finite"),
])
def test_bad_states_name_the_field(change, error, text):
    with pytest.raises(error) as info:
        InitialState(**(GOOD | change))
    assert text in str(info.value) and "\n" not in str(info.value)


def test_contact_and_unbound_orbits_are_refused(vh):
    touching = InitialState(**(GOOD | dict(R=[500.0, 0, 0])))
    with pytest.raises(ValueError, match=r"initial_states\[1\]: the bodies overlap at the start"):
        I.as_scaled_states(vh, [InitialState(**GOOD), touching])
    escape = np.sqrt(2 * tso.G * vh.total_mass / 3000.0)
    with pytest.raises(ValueError, match="not bound"):
        InitialState(**(GOOD | dict(V=[0, 1.001 * escape, 0]))).to_scaled(vh)
    InitialState(**(GOOD | dict(V=[0, 0.999 * escape, 0]))).to_scaled(vh)   # bound: accepted
    with pytest.raises(TypeError, match=r"initial_states\[0\] must be an InitialState"):
        I.as_scaled_states(vh, [GOOD])


def test_description_round_trip(vh):
    s = I.tilted_start(vh, 40.0, 1.3, roll=5.0, pitch=-3.0, spin_y=0.02, inclination=2.0)
    back = InitialState.from_description(s.describe())
    for name in ("R", "V", "primary_attitude", "secondary_attitude", "secondary_omega"):
        np.testing.assert_array_equal(getattr(back, name), getattr(s, name))
    assert "secondary z axis 5.83° from the orbit normal" in repr(s)


def test_kick_changes_only_the_velocity_along_the_orbit_frame(vh):
    s = I.tilted_start(vh, 10.0, 1.0, inclination=20.0)
    k = s.kicked([0.0, -2.7e-3, 1e-3])
    frame = I.orbit_frame(s.R, s.V)
    np.testing.assert_allclose(frame.T @ (k.V - s.V), [0.0, -2.7e-3, 1e-3], atol=1e-18)
    for name in ("R", "primary_attitude", "secondary_attitude", "secondary_omega"):
        np.testing.assert_array_equal(getattr(k, name), getattr(s, name))
    # a circular orbit's Keplerian period changes by 3 Δv/v to first order (exact: vis-viva)
    circ = tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=0.0)
    c = circ.tilted_start(0.0, 1.0)
    v = np.linalg.norm(c.V)
    dv = -1e-3 * v
    kv = c.kicked([0.0, dv, 0.0])
    mu = tso.G * circ.total_mass
    a_new = 1.0 / (2.0 / np.linalg.norm(kv.R) - kv.V @ kv.V / mu)
    assert (a_new / circ.a) ** 1.5 - 1.0 == pytest.approx(3 * dv / v, rel=3e-3)


def test_rows_round_trip_and_vectorised_rows_match_from_scaled(spun_vh):
    rng = np.random.default_rng(6)
    states = [random_state(spun_vh, rng) for _ in range(3)]
    for s in states:
        back = InitialState.from_row(s.to_row())
        np.testing.assert_array_equal(back.to_row(), s.to_row())
    y = np.stack([s.to_scaled(spun_vh) for s in states])
    rows = I.physical_rows(spun_vh, y.reshape(3, 1, 30))          # any leading shape
    for k, s in enumerate(states):
        expect = InitialState.from_scaled(spun_vh, y[k]).to_row()
        scale = np.abs(expect).max()
        np.testing.assert_allclose(rows[k, 0], expect, rtol=1e-13, atol=1e-14 * scale)
        np.testing.assert_allclose(rows[k, 0], s.to_row(), rtol=1e-12, atol=1e-13 * scale)
