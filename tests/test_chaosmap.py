"""Chaos maps and parameter maps (ti_spinorbit.studies.chaosmap): shapes, physics, robustness.

Tiny grids and short runs keep the module well under a minute on two CPU cores."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.studies.chaosmap import ChaosMap, ParameterMap, chaos_map, parameter_map

#: 4 θ_p × 6 θ̇_p/n starts of 1991 VH (a/b = 1.5): the 1:1 island (~0.45), the chaotic sea of
#: the merged 1:1-3:2 zone (0.9-1.7), and circulating tori above the 2:1 island (2.55).
THETA_P = np.array([0.0, 45.0, 90.0, 135.0])
THETADOT_P = np.array([0.45, 0.9, 1.3, 1.7, 2.1, 2.55])
ORBITS = 150


@pytest.fixture(scope="module")
def vh_map(vh):
    return chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=1e-10)


def test_shapes_and_axes(vh):
    cmap = chaos_map(vh, [10.0, 100.0], [0.5, 1.5, 2.5], 12)
    assert isinstance(cmap, ChaosMap)
    np.testing.assert_array_equal(cmap.theta_p, [10.0, 100.0])
    np.testing.assert_array_equal(cmap.thetadot_p, [0.5, 1.5, 2.5])
    for arr in (cmap.megno, cmap.lyapunov, cmap.classification, cmap.mean_thetadot, cmap.status):
        assert arr.shape == (2, 3)
    # indexing="ij": member [i, j] started at (theta_p[i], thetadot_p[j])
    np.testing.assert_allclose(cmap.section.initial_theta_p.reshape(2, 3)[:, 0], [10.0, 100.0])
    np.testing.assert_allclose(cmap.section.initial_thetadot_p.reshape(2, 3)[0], [0.5, 1.5, 2.5])
    assert cmap.orbits == 12 and cmap.seconds > 0 and cmap.member_orbits_per_second > 0
    assert 0.0 <= cmap.chaotic_fraction <= 1.0


def test_vh_map_mixes_regular_and_chaotic(vh_map):
    assert 0.0 < vh_map.chaotic_fraction < 1.0
    assert np.all(vh_map.status == vh_map.status[0, 0])  # all finished alike ("done")
    # circulating quasi-periodic row: ⟨Y⟩ → 2, slowly next to the 2:1 and 5:2 islands (measured
    # 1.98-2.41 after 150 orbits, 1.99-2.25 after 300), so: inside the regular band (≤ 2.5)
    y = vh_map.megno[:, -1]
    assert np.all((y > 1.8) & (y <= 2.5)), y
    assert abs(np.median(y) - 2.0) < 0.3, y
    assert np.all(vh_map.classification[:, -1] != "chaotic")
    chaotic = vh_map.classification == "chaotic"
    assert np.all(vh_map.megno[chaotic] >= 4.0)
    # the regular row's section mean spin stays between the 3:2 and 3:1 zones (forced
    # libration moves it by up to ~0.35 n from the start: measured 2.21-2.73)
    assert np.all((vh_map.mean_thetadot[:, -1] > 2.0) & (vh_map.mean_thetadot[:, -1] < 3.0))


def test_classification_stable_under_halved_tolerance(vh, vh_map):
    """rtol 1e-10 vs 5e-11: the same labels, but for at most one of 24 members. Chaotic orbits
    diverge after ~ln(1/rtol)/λ ≈ 40 orbits whatever the tolerance, yet they stay in the sea
    and keep ⟨Y⟩ ≫ 4; regular ones keep ⟨Y⟩ ≈ 2. Only a start on the edge of a sticky island
    (⟨Y⟩ near the 4 threshold) may flip, hence the allowance of one."""
    finer = chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=5e-11)
    changed = np.sum(finer.classification != vh_map.classification)
    assert changed <= 1, (vh_map.classification, finer.classification)
    assert abs(finer.chaotic_fraction - vh_map.chaotic_fraction) <= 1 / 24 + 1e-12


def test_plot_runs(vh_map):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3)
    for ax, quantity in zip(axes, ("megno", "lyapunov", "classification")):
        assert vh_map.plot(ax=ax, quantity=quantity, overlay=True) is ax
    with pytest.raises(ValueError, match="quantity"):
        vh_map.plot(quantity="entropy")
    plt.close("all")


def test_parameter_map_chaos_grows_with_elongation():
    pmap = parameter_map("1991 VH", [1.01, 1.3], [0.05], 100)
    assert isinstance(pmap, ParameterMap)
    assert pmap.chaotic_fraction.shape == (2, 1)
    assert pmap.megno.shape == (2, 1, 24)
    np.testing.assert_allclose(pmap.omega0, tso.analytic.omega0(np.array([1.01, 1.3])))
    # a/b = 1.01 (ω0 ≈ 0.12) is far below overlap (ω0^RO(0.05) ≈ 0.85... in a/b ≈ 1.05);
    # 1.3 is well above it
    assert pmap.chaotic_fraction[1, 0] > pmap.chaotic_fraction[0, 0]
    assert pmap.chaotic_fraction[1, 0] > 0.2


@pytest.mark.parametrize("kwargs, name", [
    (dict(theta_p=[]), "theta_p"),
    (dict(theta_p=[[0.0, 1.0]]), "theta_p"),
    (dict(thetadot_p=[1.0, np.nan]), "thetadot_p"),
    (dict(orbits=0), "orbits"),
    (dict(orbits=-5), "orbits"),
    (dict(rtol=0.0), "rtol"),
])
def test_chaos_map_bad_inputs(vh, kwargs, name):
    args = dict(theta_p=[0.0], thetadot_p=[1.0], orbits=10) | kwargs
    with pytest.raises(ValueError, match=name):
        chaos_map(vh, **args)


@pytest.mark.parametrize("kwargs, name", [
    (dict(elongations=[]), "elongations"),
    (dict(elongations=[0.9]), "elongations"),
    (dict(eccentricities=[1.2]), "eccentricities"),
    (dict(orbits=float("inf")), "orbits"),
    (dict(thetadot_p=[np.inf]), "thetadot_p"),
])
def test_parameter_map_bad_inputs(kwargs, name):
    args = dict(elongations=[1.2], eccentricities=[0.05], orbits=10) | kwargs
    with pytest.raises(ValueError, match=name):
        parameter_map("1991 VH", **args)
