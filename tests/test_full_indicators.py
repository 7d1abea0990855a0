"""Full-space chaos indicators (docs/physics.md §10.4): a shadow direction that
spans the whole state sees out-of-plane instability that the planar-restricted one cannot;
the attitude parts of the direction are first-order rotations; choices are checked, recorded,
saved and part of a checkpoint's settings."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import models
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.system.initial import rotation

#: The Hyperion-like system's synchronous island centre θ̇_p/n at θ_p = 0 (relaxed_libration;
#: planar-regular, attitude-unstable with an e-folding of the tilt of ≈ 1.4 orbits).
HYPERION_CENTRE = 0.544395


def hyperion():
    """Saturn as a uniform sphere and Hyperion as a uniform 180 × 137 × 103 km ellipsoid, a =
    1.4811e6 km, e = 0.1: the decoupled limit (mass ratio ~1e8, ω0 ≈ 0.89)."""
    radius = 5.8232e7
    saturn = tso.Sphere(radius, density=5.68e26 / (4.0 / 3.0 * np.pi * radius**3), name="Saturn")
    moon = tso.Ellipsoid(180e3, 137e3, 103e3, density=544.0, name="Hyperion")
    return tso.BinarySystem(saturn, moon, a=1.4811e9, e=0.1, name="Saturn-Hyperion")


@pytest.fixture(scope="module")
def runs():
    """[Hyperion synchronous centre, Didymos synchronous] over 40 orbits, planar start, for
    each (indicator_space, model)."""
    systems = [hyperion(), tso.catalog.system("Didymos")]
    out = {}
    for space, model in (("planar", "auto"), ("planar", "3d"), ("full", "auto")):
        out[space, model] = tso.surface_of_section(systems, 0.0, [HYPERION_CENTRE, 1.0], orbits=40,
                                                   rtol=1e-11, indicators=True,
                                                   indicator_space=space,
                                                   integrator=tso.Integrator(model=model),
                                                   run=tso.Run(progress=False))
    return out


def test_hyperion_centre_is_planar_regular_and_full_chaotic(runs):
    planar, full = runs["planar", "auto"], runs["full", "auto"]
    assert planar.megno[0] == pytest.approx(2.0, abs=0.5)
    assert full.megno[0] > 8.0                       # λ ≈ 0.7/orbit: ⟨Y⟩ ≈ λt/2 grows
    assert full.lyapunov[0] > 3 * planar.lyapunov[0]
    assert planar.indicator_space == "planar" and full.indicator_space == "full"
    assert list(full.status_names) == ["done", "done"]


def test_didymos_synchronous_is_regular_in_both_spaces(runs):
    for key in (("planar", "auto"), ("full", "auto")):
        assert runs[key].megno[1] == pytest.approx(2.0, abs=0.5), key


def test_planar_space_same_megno_in_either_model(runs):
    """The two models start their shadows along different planar directions (r, v_r, ℓ, ω2
    against R_x, R_y, V_x, V_y, ω2_z), so ⟨Y⟩ agrees only as both tend to 2: within 0.15
    after 40 orbits (measured: 0.06 and 0.07)."""
    np.testing.assert_allclose(runs["planar", "auto"].megno, runs["planar", "3d"].megno,
                               atol=0.15)


def _rotations(n, seed=3):
    rng = np.random.default_rng(seed)
    return [rotation(2, a) @ rotation(1, b) @ rotation(0, c)
            for a, b, c in rng.uniform(-np.pi, np.pi, (n, 3))]


def _states(n):
    rng = np.random.default_rng(7)
    y = rng.standard_normal((n, 30))
    for k, (S, S1) in enumerate(zip(_rotations(n, 1), _rotations(n, 2))):
        y[k, 12:21], y[k, 21:30] = S.ravel(), S1.ravel()
    return y


@pytest.mark.parametrize("lo", [12, 21], ids=["secondary S", "primary S1"])
def test_full_direction_attitude_parts_are_first_order_rotations(lo):
    y = _states(5)
    d = models.SPATIAL.full_direction(y)
    eps = 1e-7
    for k in range(len(y)):
        A = y[k, lo:lo + 9].reshape(3, 3)
        Ap = A + eps * d[k, lo:lo + 9].reshape(3, 3)
        M = A.T @ Ap - np.eye(3)                       # = eps · hat(δ) to first order
        assert np.abs(M + M.T).max() < 1e-13           # antisymmetric (round-off)
        assert np.abs(M).max() > 1e-9                  # and not zero: the attitude moves
        # the same small rotation δ for every member, in its body frame
        delta = np.array([M[2, 1], M[0, 2], M[1, 0]]) / eps / np.linalg.norm(d[k, :3])
        key = "dS" if lo == 12 else "dS1"
        np.testing.assert_allclose(delta, models.full_components()[key] /
                                   np.linalg.norm(models.full_components()["R"]), rtol=1e-6)


def test_full_direction_is_unit_seeded_and_slot_invariant():
    y = _states(4)
    d = models.SPATIAL.full_direction(y)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-14)
    for k in range(4):                                 # a member alone gets the same row
        np.testing.assert_array_equal(models.SPATIAL.full_direction(y[k:k + 1])[0], d[k])
    np.testing.assert_array_equal(d, models.SPATIAL.full_direction(y))   # deterministic
    assert np.all(d[:, 24:30] != 0) and np.all(d[:, 0:12] != 0)       # every part moves
    # same R, V, spin components (up to each member's normalisation)
    ratio = d[:, 0:12] / d[0, 0:12]
    np.testing.assert_allclose(ratio, ratio[:, :1] * np.ones((1, 12)), rtol=1e-12)


@pytest.mark.parametrize("call", ["section", "ensemble", "chaos_map"])
def test_full_space_with_planar_model_refused(call):
    vh = tso.catalog.system("1991 VH")
    msg = r"^indicator_space='full' needs the 3-D model .*use model='auto' or '3d'$"
    with pytest.raises(ValueError, match=msg):
        if call == "section":
            tso.surface_of_section(vh, 0.0, 1.0, orbits=1, indicators=True, indicator_space="full",
                                   integrator=tso.Integrator(model="planar"))
        elif call == "chaos_map":
            tso.chaos_map(vh, [0.0], [1.0], orbits=1, indicator_space="full",
                          integrator=tso.Integrator(model="planar"))
        else:
            Ensemble(vh.parameter_row()[None], vh.initial_state(0.0, 1.0)[None],
                     model="planar").run(1.0, indicators=True, indicator_space="full")


@pytest.mark.parametrize("value", ["Full", "3d", None, 1])
def test_bad_indicator_space_refused(value):
    with pytest.raises(ValueError, match=r"^indicator_space must be 'planar' or 'full' \(got "):
        tso.surface_of_section("1991 VH", 0.0, 1.0, orbits=1, indicators=True,
                               indicator_space=value)


def test_auto_ensemble_turns_3d_for_full_space_only_with_indicators():
    vh = tso.catalog.system("1991 VH")
    par, y0 = vh.parameter_row()[None], vh.initial_state(0.0, 1.0)[None]
    plain = Ensemble(par, y0)
    plain.run(2 * np.pi, indicator_space="full")            # no indicators: stays planar
    assert plain.model == "planar"
    full = Ensemble(par, y0)
    out = full.run(2 * np.pi, indicators=True, indicator_space="full")
    assert full.model == "3d" and np.isfinite(out.megno[0])


def test_full_space_recorded_saved_and_in_checkpoint_settings(tmp_path):
    vh = tso.catalog.system("1991 VH")
    r = tso.surface_of_section(vh, 0.0, 1.0, orbits=2, rtol=1e-10, indicators=True,
                               indicator_space="full",
                               run=tso.Run(checkpoint=tmp_path / "ck", progress=False,
                                           keep_checkpoint=True))
    loaded = tso.load(tso.save(r, tmp_path / "r.npz"))
    assert loaded.indicator_space == "full"
    assert "planar" in type(r).units()["indicator_space"]
    np.testing.assert_array_equal(loaded.megno, r.megno)
    with pytest.raises(ValueError, match=r"other settings: .*indicator_space \(checkpoint "
                                         r"'full', now 'planar'\)"):
        tso.surface_of_section(vh, 0.0, 1.0, orbits=2, rtol=1e-10, indicators=True,
                               integrator=tso.Integrator(model="3d"),
                               run=tso.Run(checkpoint=tmp_path / "ck", resume=True, progress=False))


def test_chaos_map_tilt_and_max_tilt(tmp_path):
    """A small start tilt (0.01° roll) on the Hyperion-like island centre grows past 10° in
    40 orbits; the planar map records zero tilt; both are saved with the map."""
    hyp = hyperion()
    common = dict(orbits=40, rtol=1e-10, fraction_orbits=(), run=tso.Run(progress=False))
    tilted = tso.chaos_map(hyp, [0.0], [HYPERION_CENTRE, 2.5], tilt=(0.01, 0.0), **common)
    assert tilted.max_tilt.shape == (1, 2) and tilted.tilt.tolist() == [0.01, 0.0]
    assert tilted.max_tilt[0, 0] > 10.0                # the synchronous centre tumbles
    assert tilted.max_tilt[0, 1] < 1.0                 # fast rotation stays upright
    planar = tso.chaos_map(hyp, [0.0], [HYPERION_CENTRE], **common)
    assert planar.tilt is None and planar.max_tilt.tolist() == [[0.0]]
    loaded = tso.load(tso.save(tilted, tmp_path / "m.npz"))
    np.testing.assert_array_equal(loaded.max_tilt, tilted.max_tilt)
    ax = tilted.plot(quantity="max_tilt")
    assert "tilt" in ax.figure.axes[-1].get_ylabel()


@pytest.mark.parametrize("tilt", [(1.0,), (0.0, 95.0), (np.nan, 0.0), "x"])
def test_chaos_map_bad_tilt_refused(tilt):
    with pytest.raises((ValueError, TypeError), match=r"tilt"):
        tso.chaos_map("1991 VH", [0.0], [1.0], orbits=1, tilt=tilt)


def test_parameter_map_records_full_space():
    pm = tso.parameter_map("1991 VH", [1.5], [0.05], orbits=2, theta_p=[0.0], thetadot_p=[1.0],
                           fraction_orbits=(), indicator_space="full", run=tso.Run(progress=False))
    assert pm.indicator_space == "full" and np.isfinite(pm.megno).all()
