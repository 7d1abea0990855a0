"""The binary's heliocentric orbit (``tso.HeliocentricOrbit``, docs/physics.md §13.12): the
ecliptic-to-binary rotation against spherical geometry, the catalogue's orbits, the system
file round trip, and YORP/BYORP at the Sun's distance of the moment against a quadrature of
the torque on an independent Kepler solution."""

import math

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.constants import AU
from ti_spinorbit.engine import accuracy
from ti_spinorbit.system.bodies import Sphere
from ti_spinorbit.system.heliocentric import ecliptic_to_binary


def unit(lon, lat):
    lon, lat = math.radians(lon), math.radians(lat)
    return np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])


@pytest.mark.parametrize("pole, w_b", [((310.0, -84.0), 0.0), ((326.0, -62.0), 40.0),
                                       ((10.0, 90.0), 0.0), ((200.0, 5.0), -120.0)])
def test_ecliptic_to_binary_is_the_rotation_spherical_geometry_gives(pole, w_b):
    """The rows are orthonormal and right-handed, z is the pole, x lies w_b from the ascending
    node of the mutual orbit on the ecliptic (w_b = 0: in the ecliptic, ahead of the pole's
    longitude by 90°), and the heliocentric orbit's tilt to the mutual orbit is the angle
    between the two normals."""
    R = ecliptic_to_binary(pole, w_b)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-15)
    z = unit(*pole)
    np.testing.assert_allclose(R[2], z, atol=1e-15)
    if abs(pole[1]) < 90.0:
        node = unit(pole[0] + 90.0, 0.0)          # ẑ_ecl × z points 90° ahead of the pole
        assert R[0] @ node == pytest.approx(math.cos(math.radians(w_b)), abs=1e-14)
    orbit = tso.HeliocentricOrbit(1.2, 0.1, inclination_deg=25.0, node_deg=70.0,
                                  periapsis_deg=10.0, frame="ecliptic", pole=pole,
                                  binary_periapsis_deg=w_b)
    P, Q = orbit.directions()
    h_ecl = np.cross(*tso.HeliocentricOrbit(1.2, 0.1, inclination_deg=25.0, node_deg=70.0,
                                            periapsis_deg=10.0).directions())
    assert np.cross(P, Q)[2] == pytest.approx(h_ecl @ z, abs=1e-14)


def test_catalogue_orbits_and_a_system_file_round_trip(tmp_path):
    kw4 = tso.catalog.system("1999 KW4")
    orbit = kw4.heliocentric_orbit
    assert (orbit.a_au, orbit.e, orbit.pole) == (0.642, 0.689, (326.0, -62.0))
    # 1999 KW4's heliocentric orbit is 38.9° from the ecliptic, its mutual orbit's pole 28°
    # from the ecliptic's south pole: the Sun's orbit is far out of the mutual plane
    tilt = math.degrees(math.acos(np.cross(*orbit.directions())[2]))
    h = np.cross(*tso.HeliocentricOrbit(0.642, 0.689, inclination_deg=38.88, node_deg=244.91,
                                        periapsis_deg=192.62).directions())
    assert tilt == pytest.approx(math.degrees(math.acos(h @ unit(326.0, -62.0))), abs=1e-9)
    path = tmp_path / "kw4.json"
    path.write_text(__import__("json").dumps(kw4.describe()))
    back = tso.BinarySystem.from_file(path)
    assert back.heliocentric_orbit == orbit
    legacy = dict(kw4.describe())
    legacy.pop("heliocentric_orbit")
    legacy.update(heliocentric_a_au=1.1, heliocentric_e=0.2)    # as earlier versions wrote
    assert tso.BinarySystem.from_description(legacy).heliocentric_orbit == \
        tso.HeliocentricOrbit(1.1, 0.2)
    with pytest.raises(ValueError, match="not both"):
        tso.BinarySystem.from_description({**kw4.describe(), "heliocentric_a_au": 1.0})


@pytest.mark.parametrize("kwargs, match", [
    (dict(a_au=0.01, e=0.1), r"heliocentric_orbit a must lie in \[0.05, 10000"),
    (dict(a_au=1.0, e=1.0), r"heliocentric_orbit e must lie in \[0"),
    (dict(a_au=1.0, e=0.1, frame="galactic"), r"frame must be one of binary, ecliptic"),
    (dict(a_au=1.0, e=0.1, pole=(0.0, 10.0)), r"belong to frame='ecliptic'"),
    (dict(a_au=1.0, e=0.1, frame="ecliptic", pole=(0.0, 95.0)), r"latitude must lie in"),
    (dict(a_au=1.0, e=0.1, inclination_deg=200.0), r"inclination_deg must lie in \[0"),
])
def test_bad_orbits_are_refused_in_one_line(kwargs, match):
    with pytest.raises(ValueError, match=match) as info:
        tso.HeliocentricOrbit(**kwargs)
    assert "\n" not in str(info.value)


def test_a_sun_of_unknown_direction_is_refused_where_its_direction_is_needed():
    vh = tso.catalog.system("1991 VH")          # SBDB elements, no published pole
    assert tso.YORP().torque(vh) != 0.0          # the distance is known
    with pytest.raises(ValueError, match="without the binary's pole"):
        tso.SolarTide().block(vh)
    assert tso.SolarTide(inclination_deg=10.0).block(vh)[9] > 0    # angles of one's own


def test_radiation_at_the_suns_distance():
    """YORP on the secondary with distance="orbit", a binary on a 0.3 AU, e = 0.5 orbit near
    perihelion: the external angular momentum the run integrates equals the torque × a⊙²
    sqrt(1 − e⊙²)/d(t)² integrated by quadrature on scipy's bracketing Kepler solution, to
    1e-9; it differs from the mean-distance run by tens of percent; and the factor averages to
    1 over a heliocentric orbit (quadrature, 1e-12)."""
    from scipy.integrate import quad
    from scipy.optimize import brentq

    orbit = tso.HeliocentricOrbit(0.3, 0.5, mean_anomaly_deg=-10.0)
    system = tso.BinarySystem(Sphere(600.0, 1581.0), Sphere(230.0, 2618.0), a=3300.0, e=0.05,
                              name="near the Sun", heliocentric_orbit=orbit)
    kw = dict(orbits=4, samples_per_orbit=8, rtol=1e-12)
    at_d = tso.YORP(coefficient=1e-3, strength=1e4)
    mean = tso.YORP(coefficient=1e-3, strength=1e4, distance="mean")
    ts = tso.time_series(system, 0.0, [1.0], perturbations=[at_d], **kw)
    ref = tso.time_series(system, 0.0, [1.0], perturbations=[mean], **kw)
    assert accuracy.usable(ts.status).all() and accuracy.usable(ref.status).all()
    a, e = orbit.a_au * AU, orbit.e
    n = tso.SolarTide().mean_motion(system)

    def factor(t):
        M = math.radians(orbit.mean_anomaly_deg) + n * t
        M = math.remainder(M, 2 * math.pi)
        E = brentq(lambda E: E - e * math.sin(E) - M, -math.pi, math.pi, xtol=1e-15)
        return math.sqrt(1 - e * e) / (1 - e * math.cos(E)) ** 2

    T = at_d.torque(system)
    t = ts.t[0]
    expected = np.array([quad(factor, 0.0, tk, epsabs=0, epsrel=1e-13)[0] for tk in t]) * T
    ours = ts.external_angmom[0, :, 2]
    assert np.abs(ours - expected).max() < 1e-9 * np.abs(expected).max()
    np.testing.assert_allclose(ref.external_angmom[0, :, 2], T * t, rtol=1e-9, atol=0)
    assert ours[-1] / ref.external_angmom[0, -1, 2] > 1.2      # near perihelion: stronger
    P = 2 * math.pi / n
    assert quad(factor, 0.0, P, limit=200, epsabs=0, epsrel=1e-13)[0] / P == \
        pytest.approx(1.0, abs=1e-12)


def test_yorp_and_a_sun_on_different_orbits_are_refused():
    vh = tso.catalog.system("1991 VH")
    with pytest.raises(ValueError, match="on different heliocentric orbits"):
        tso.model.perturbations.perturbation_rows(
            [vh], [tso.YORP(), tso.SolarTide(heliocentric_a_au=2.0, heliocentric_e=0.1)])


def test_quantities_are_taken_and_converted():
    u = pytest.importorskip("astropy.units")
    given = tso.HeliocentricOrbit(1.644 * u.AU, 0.384, inclination_deg=3.41 * u.deg,
                                  node_deg=(73.2 * u.deg).to(u.rad), frame="ecliptic",
                                  pole=(310.0 * u.deg, -84.0 * u.deg))
    plain = tso.HeliocentricOrbit(1.644, 0.384, inclination_deg=3.41, node_deg=73.2,
                                  frame="ecliptic", pole=(310.0, -84.0))
    assert given.a_au == plain.a_au and given.pole == plain.pole
    assert given.node_deg == pytest.approx(73.2, rel=1e-14)
    with pytest.raises(ValueError, match="inclination_deg must be in"):
        tso.HeliocentricOrbit(1.0, 0.1, inclination_deg=3.0 * u.m)
