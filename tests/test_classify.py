"""Classification of section traces (docs/physics.md §6, §8, §10): synthetic curves, islands and
area-filling sets; standard-map orbits; the MEGNO override; the decoupled island centres
against an independent solver; and the paper's 1991 VH starts (Naidu & Margot 2015, Fig. 7)."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import ti_spinorbit as tso
from ti_spinorbit.model.analytic import omega0_effective
from ti_spinorbit.studies.classify import (COLORS, ORDER_RATIO_CHAOTIC, SectionClassification,
                                   classify_points, classify_section, horizontal_extent,
                                   island_centres, libration_arc, order_ratio)

N = 512
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def standard_map(K, x0, p0, n=N):
    """Chirikov's area-preserving twist map p' = p + K sin x, x' = x + p' (mod 2π)."""
    x, p = np.empty(n), np.empty(n)
    x[0], p[0] = x0, p0
    for k in range(n - 1):
        p[k + 1] = p[k] + K * math.sin(x[k])
        x[k + 1] = (x[k] + p[k + 1]) % (2.0 * math.pi)
    return x, p


def synthetic_traces(rng):
    """(name, θ_p deg, θ̇_p/n, expected label, expected p) of one member each."""
    k = np.arange(N)
    phase = 2.0 * np.pi * k * GOLDEN
    angle = phase + 0.6 * np.sin(phase)        # non-uniform speed along the curve
    psi = 2.0 * np.pi * k * 0.1234567
    traces = [
        ("smooth curve", np.degrees(angle) / 2.0, 2.2 + 0.3 * np.cos(angle), "quasi-periodic",
         None),
        # ellipse about θ_p = 0: half the points lie near 180° (the wrap)
        ("island at 0", 25.0 * np.cos(psi), 1.5 + 0.1 * np.sin(psi), "resonant", 1.5),
        ("island at 90", 90.0 + 20.0 * np.cos(psi), 0.52 + 0.05 * np.sin(psi), "resonant", 0.5),
        ("random fill", rng.uniform(0.0, 180.0, N), rng.uniform(0.5, 2.0, N), "chaotic", None),
    ]
    x, p = standard_map(0.5, 0.0, 2.0 * np.pi * GOLDEN)        # KAM curve
    traces.append(("standard map, torus", np.degrees(x) / 2.0, p / (2 * np.pi),
                   "quasi-periodic", None))
    x, p = standard_map(0.9, np.pi + 0.6, 0.0)                 # island about (π, 0)
    traces.append(("standard map, island", np.degrees(x - np.pi) / 2.0, 1.0 + p / (2 * np.pi),
                   "resonant", 1.0))
    x, p = standard_map(4.0, 1.0, 0.5)                         # global chaos
    traces.append(("standard map, chaos", np.degrees(x) / 2.0, (p % (2 * np.pi)) / (2 * np.pi),
                   "chaotic", None))
    return traces


@pytest.mark.parametrize("subsample", [slice(None), slice(0, N // 2), slice(None, None, 2)],
                         ids=["all points", "first half", "every second point"])
def test_synthetic_traces_are_labelled_and_stable_under_subsampling(rng, subsample):
    traces = synthetic_traces(rng)
    theta = np.array([t[1] for t in traces])[:, subsample]
    thetadot = np.array([t[2] for t in traces])[:, subsample]
    cls = classify_points(np.mod(theta, 180.0), thetadot)
    for i, (name, _, _, label, p) in enumerate(traces):
        assert cls.classification[i] == label, (name, cls.order_ratio[i], cls.largest_gap_deg[i])
        if p is None:
            assert np.isnan(cls.resonance_p[i]), name
        else:
            assert cls.resonance_p[i] == p, name
    regular = cls.classification != "chaotic"
    assert np.all(cls.order_ratio[regular] < 0.5 * ORDER_RATIO_CHAOTIC)
    assert np.all(cls.order_ratio[~regular] > 2.0 * ORDER_RATIO_CHAOTIC)
    # the island about 0 wraps through 180°: centre 0, half extent the ellipse's 25°
    assert abs(cls.libration_centre_deg[1]) < 0.5
    assert cls.libration_half_extent_deg[1] == pytest.approx(25.0, abs=0.5)
    assert cls.libration_centre_thetadot[1] == pytest.approx(1.5, abs=0.01)
    assert abs(cls.libration_centre_deg[2]) == pytest.approx(90.0, abs=0.5)
    assert cls.libration_half_extent_deg[2] == pytest.approx(20.0, abs=0.5)
    assert np.all(np.isnan(cls.libration_centre_deg[cls.classification != "resonant"]))


def test_chain_round_the_circle_librates_but_gets_no_p():
    """Two islands alternately visited at θ_p = 0 and 90° (a 2-island chain): θ_p never covers
    the circle, so resonant, but the two equal gaps say it is no p:1 island."""
    k = np.arange(N)
    psi = 2.0 * np.pi * k * 0.1234567
    theta = np.mod(np.where(k % 2 == 0, 0.0, 90.0) + 15.0 * np.cos(psi), 180.0)
    thetadot = 1.75 + np.where(k % 2 == 0, 0.05, -0.05) + 0.02 * np.sin(psi)
    for sub in (slice(None), slice(0, N // 2)):
        cls = classify_points(theta[sub], thetadot[sub])
        assert cls.classification[0] == "resonant" and np.isnan(cls.resonance_p[0])
        assert cls.largest_gap_deg[0] == pytest.approx(60.0, abs=0.5)


def test_megno_overrides_only_beyond_its_thresholds(rng):
    traces = synthetic_traces(rng)
    theta = np.mod(np.array([t[1] for t in traces]), 180.0)
    thetadot = np.array([t[2] for t in traces])
    geometric = classify_points(theta, thetadot).classification
    names = [t[0] for t in traces]
    curve, island, fill = (names.index(s) for s in ("smooth curve", "island at 0", "random fill"))
    megno = np.full(len(traces), np.nan)
    megno[curve] = 12.0     # chaotic whatever the points say
    megno[fill] = 2.0       # regular: it circulates, so quasi-periodic
    megno[island] = 3.0     # grey zone: the points decide
    cls = classify_points(theta, thetadot, megno=megno)
    assert cls.classification[curve] == "chaotic"
    assert cls.classification[fill] == "quasi-periodic"
    assert cls.classification[island] == "resonant" and cls.resonance_p[island] == 1.5
    others = np.isnan(megno)
    assert list(cls.classification[others]) == list(geometric[others])
    assert list(cls.classification_geometric) == list(geometric)
    np.testing.assert_array_equal(cls.megno, megno)


def test_too_few_points_or_failed_members_are_undetermined(rng):
    traces = synthetic_traces(rng)
    theta = np.mod(np.array([t[1] for t in traces[:2]]), 180.0)
    thetadot = np.array([t[2] for t in traces[:2]])
    theta[0, 40:] = np.nan                               # 40 points: too few
    thetadot[0, 40:] = np.nan
    cls = classify_points(theta, thetadot)
    assert list(cls.classification) == ["undetermined", "resonant"]
    assert cls.count[0] == 40 and np.isfinite(cls.mean_thetadot[0])
    cls = classify_points(theta, thetadot, failed=[False, True])
    assert list(cls.classification) == ["undetermined", "undetermined"]
    assert isinstance(cls, SectionClassification)
    assert cls.counts()["undetermined"] == 2


def test_horizontal_extent_and_arc_handle_the_wrap():
    theta = np.array([[178.0, 179.5, 1.0, 3.0, np.nan], [88.0, 91.0, 95.0, np.nan, np.nan],
                      [np.nan] * 5])
    extent = horizontal_extent(theta)
    assert extent[0] == pytest.approx(3.0) and extent[1] == pytest.approx(89.0)
    assert np.isnan(extent[2])
    assert horizontal_extent(theta, center_deg=[0.0, 90.0, 0.0])[1] == pytest.approx(5.0)
    gap, center, half, second = libration_arc(theta[0])
    assert gap == pytest.approx(175.0) and center == pytest.approx(0.5)
    assert half == pytest.approx(2.5) and second == pytest.approx(2.0)
    assert np.isnan(order_ratio([1.0, 2.0], [0.5, 0.6]))


def test_bad_thresholds_are_rejected():
    theta, thetadot = np.zeros((1, 100)), np.ones((1, 100))
    with pytest.raises(ValueError, match="libration_gap_deg"):
        classify_points(theta, thetadot, libration_gap_deg=0.0)
    with pytest.raises(ValueError, match="megno_regular"):
        classify_points(theta, thetadot, megno_regular=5.0, megno_chaotic=4.0)
    with pytest.raises(ValueError, match="same shape"):
        classify_points(theta, thetadot[:, :50])


def decoupled_center(omega0, e, p, theta0):
    """Pericentre spin rate of the symmetric p:1 periodic orbit of θ̈ = −(ω0²/2)(a/r)³ sin 2(θ−f)
    (docs/physics.md §8.1), with DOP853 and Brent: θ(π) − θ0 = pπ at apocentre."""
    def rhs(t, y):
        theta, thetadot, f = y
        one_plus = 1.0 + e * math.cos(f)
        a_over_r = one_plus / (1.0 - e * e)
        return [thetadot, -0.5 * omega0**2 * a_over_r**3 * math.sin(2.0 * (theta - f)),
                one_plus**2 / (1.0 - e * e) ** 1.5]

    def miss(w):
        sol = solve_ivp(rhs, (0.0, math.pi), [theta0, w, 0.0], method="DOP853", rtol=1e-11,
                        atol=1e-12)
        return sol.y[0, -1] - theta0 - p * math.pi

    grid = np.arange(p - 1.0, p + 1.0, 0.01)
    values = [miss(w) for w in grid]
    i = next(j for j in range(len(grid) - 1) if values[j] < 0 <= values[j + 1])
    return brentq(miss, grid[i], grid[i + 1], xtol=1e-12)


def test_island_centres_match_an_independent_solver():
    """The 1:1 island of 1991 VH (a/b = 1.5, ω0,eff ≈ 1.03) is pushed far below 1 by the
    near-resonant forced libration; the 2:1 island sits above 2."""
    vh = tso.catalog.system("1991 VH")
    centers = island_centres(vh, p_max=3.0)
    omega0 = omega0_effective(vh)
    for p, theta0 in ((1.0, 0.0), (2.0, 0.0), (2.5, 0.0), (0.5, math.pi / 2)):
        assert centers[p] == pytest.approx(decoupled_center(omega0, vh.e, p, theta0), abs=2e-3), p
    assert centers[1.0] < 0.5 and 2.3 < centers[2.0] < 2.4


def test_island_shift_decides_between_neighbouring_resonances():
    """A small island at θ̇_p/n = 2.35 is the 2:1 island of 1991 VH (its forced libration lifts
    the 2:1 centre to 2.355), not the 5:2 one that the nominal centres would suggest."""
    psi = 2.0 * np.pi * np.arange(N) * 0.1234567
    theta, thetadot = np.mod(3.0 * np.cos(psi), 180.0), 2.35 + 0.01 * np.sin(psi)
    vh = tso.catalog.system("1991 VH")
    assert classify_points(theta, thetadot, systems=vh).resonance_p[0] == 2.0
    assert classify_points(theta, thetadot).resonance_p[0] == 2.5


@pytest.fixture(scope="module")
def vh_section():
    """The paper's five starts (θ_p = 0) plus the decoupled 1:2 island centre (θ_p = 90°),
    one launch."""
    vh = tso.catalog.system("1991 VH")
    theta_p = [0.0, 0.0, 0.0, 0.0, 0.0, 90.0]
    thetadot_p = [0.43, 0.83, 1.63, 2.31, 2.53, round(island_centres(vh)[0.5], 3)]
    return tso.surface_of_section(vh, theta_p, thetadot_p, orbits=400, rtol=1e-10)


def test_paper_starts_of_1991VH(vh_section):
    """Naidu & Margot 2015 Fig. 7 (1991 VH, a/b = 1.5): 0.43 and 0.83 librate in the
    synchronous island (small and large amplitude), 1.63 is chaotic, 2.31 librates in the
    2:1 island, 2.53 circulates; and a small 1:2 island survives at θ_p = 90°."""
    r = vh_section
    assert np.all(r.count >= 390)
    cls = classify_section(r)
    assert list(cls.classification) == ["resonant", "resonant", "chaotic", "resonant", "quasi-periodic",
                               "resonant"]
    np.testing.assert_array_equal(cls.resonance_p, [1.0, 1.0, np.nan, 2.0, np.nan, 0.5])
    assert cls.order_ratio[2] > 2 * ORDER_RATIO_CHAOTIC
    assert np.all(np.delete(cls.order_ratio, 2) < 0.2 * ORDER_RATIO_CHAOTIC)
    # same island, centred on θ_p = 0; the excited-mode amplitude grows with the distance of
    # the start from the island centre (≈ 0.45)
    assert np.all(np.abs(cls.libration_centre_deg[[0, 1, 3]]) < 1.0)
    assert cls.libration_half_extent_deg[0] < 5.0 < 20.0 < cls.libration_half_extent_deg[1]
    assert cls.libration_half_extent_deg[5] < 5.0
    # the 2:1 island centre is where the decoupled problem puts it, far from 2 and 2.5
    centers = island_centres(r.systems[0])
    assert abs(cls.libration_centre_thetadot[3] - centers[2.0]) < 0.05
    assert abs(cls.libration_centre_thetadot[5] - centers[0.5]) < 0.02
    assert cls.colors[:5] == [COLORS[k] for k in cls.classification[:5]]


def test_paper_starts_are_stable_under_subsampling(vh_section):
    r = vh_section
    full = classify_section(r)
    for sub in (slice(0, 200), slice(None, None, 2)):
        half = classify_points(r.theta_p[:, sub], r.thetadot_p[:, sub], systems=r.systems)
        assert list(half.classification) == list(full.classification)
        np.testing.assert_array_equal(half.resonance_p, full.resonance_p)
