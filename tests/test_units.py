"""Units (ti_spinorbit.units): astropy Quantities wherever a length, mass, density, angle,
time or rate is taken, bit for bit the plain numbers they stand for; wrong dimensions
refused in one line; the degree hint for angles that look like radians; result.quantity();
and the plain path without astropy."""

import dataclasses
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import units as tsu
from ti_spinorbit.units import DegreesExpectedWarning, UnitMismatchError

u = pytest.importorskip("astropy.units")


def _system(**kw):
    args = dict(a=1.2 * u.km, e=0.05, primary_spin_period=2.26 * u.h)
    args.update(kw)
    return tso.BinarySystem(tso.Sphere(0.4 * u.km, 2.17 * u.g / u.cm**3),
                            tso.Ellipsoid(0.085 * u.km, 65 * u.m, 0.06 * u.km,
                                          2.17 * u.g / u.cm**3), name="u", **args)


@pytest.fixture(scope="module")
def plain():
    return tso.BinarySystem(tso.Sphere(400.0, 2170.0), tso.Ellipsoid(85.0, 65.0, 60.0, 2170.0),
                            a=1200.0, e=0.05, primary_spin_period=2.26 * 3600.0, name="u")


def _hints(caught):
    return [w for w in caught if issubclass(w.category, DegreesExpectedWarning)]


# ---- Quantity inputs: the same numbers, bit for bit ----------------------------------------
def test_bodies_km_and_g_cm3_are_m_and_kg_m3():
    q = tso.Ellipsoid(0.245 * u.km, 190 * u.m, 16300 * u.cm, 2.618 * u.g / u.cm**3)
    p = tso.Ellipsoid(245.0, 190.0, 163.0, 2618.0)
    assert q.semi_axes == p.semi_axes and q.mass == p.mass and q.integrals == p.integrals
    assert np.array_equal(q.as_row(), p.as_row())
    s = tso.Sphere(radius=0.6 * u.km, mass=5e8 * u.t)
    assert (s.mass, s.bounding_radius) == (5e11, 600.0)
    body = tso.Body(2.0 * u.kg, {(2, 0, 0): 1.0, (0, 2, 0): 1.0, (0, 0, 2): 1.0}, 200 * u.cm)
    assert (body.mass, body.bounding_radius) == (2.0, 2.0)


def test_point_masses_and_polyhedra_take_quantities():
    pts = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 0.5, 0], [0, -0.5, 0], [0, 0, 0.2],
                    [0, 0, -0.2]])
    a, _ = tso.Body.from_point_masses(pts * u.km, np.ones(6) * u.t)
    b, _ = tso.Body.from_point_masses(pts * 1000.0, np.ones(6) * 1000.0)
    assert np.array_equal(a.as_row(), b.as_row()) and a.bounding_radius == b.bounding_radius
    from ti_spinorbit.system.shapes import packaged_shape
    q = packaged_shape("didymos_radar", density=2.17 * u.g / u.cm**3, order=4)
    p = packaged_shape("didymos_radar", density=2170.0, order=4)
    assert q.integrals == p.integrals and q.source == p.source
    verts = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1]])
    faces = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    assert np.array_equal(tso.Polyhedron(verts * u.km, faces, mass=1e9 * u.kg, order=4).as_row(),
                          tso.Polyhedron(verts * 1e3, faces, mass=1e9, order=4).as_row())


def test_binary_system_takes_quantities(plain):
    q = _system()
    assert q == plain and q.a == 1200.0 and q.primary_spin_period == 2.26 * 3600.0
    assert np.array_equal(q.parameter_row(), plain.parameter_row())
    assert np.array_equal(q.initial_state(0.3, 1.1), plain.initial_state(0.3, 1.1))
    assert _system(e=0.05 * u.one) == plain
    # the observed period, hours or seconds
    hours = _system(orbital_period=12.0 * u.h)
    seconds = tso.BinarySystem(plain.primary, plain.secondary, 1200.0, 0.05, 2.26 * 3600.0,
                               name="u", orbital_period=43200.0)
    assert hours == seconds and hours.density_scale == seconds.density_scale


def test_starts_take_angles_and_rates(plain):
    n = plain.mean_motion
    deg = plain.tilted_start(np.degrees(0.5), 1.1, roll=10.0, inclination=5.0, spin_x=0.01)
    rad = plain.tilted_start(0.5 * u.rad, 1.1 * n * u.rad / u.s, roll=10 * u.deg,
                             inclination=5.0 * u.deg, spin_x=0.01 * tsu.n)
    assert np.allclose(rad.to_row(), deg.to_row(), rtol=1e-15, atol=0)
    same = plain.tilted_start(30.0 * u.deg, 1.1 * u.one)
    assert same == plain.tilted_start(30.0, 1.1)
    state = tso.InitialState(R=deg.R / 1e3 * u.km, V=deg.V * u.m / u.s,
                             primary_attitude=deg.primary_attitude,
                             primary_omega=deg.primary_omega * u.rad / u.s,
                             secondary_attitude=deg.secondary_attitude,
                             secondary_omega=np.degrees(deg.secondary_omega) * u.deg / u.s)
    assert np.allclose(state.to_row(), deg.to_row(), rtol=1e-15, atol=0)


def test_perturbations_take_quantities():
    assert tso.Tides(time_lag=2 * u.min, radius=0.08 * u.km) == tso.Tides(time_lag=120.0,
                                                                          radius=80.0)
    assert tso.YORP(heliocentric_a_au=1.6 * u.AU, heliocentric_e=0.38, radius=80 * u.m) == \
        tso.YORP(heliocentric_a_au=1.6, heliocentric_e=0.38, radius=80.0)
    assert tso.BYORP(heliocentric_a_au=239354250000.0 * u.m, heliocentric_e=0.38) == \
        tso.BYORP(heliocentric_a_au=239354250000.0 / 149597870700.0, heliocentric_e=0.38)
    tide = tso.SolarTide(heliocentric_a_au=1.6, heliocentric_e=0.1,
                         inclination_deg=np.pi / 2 * u.rad)
    assert tide.inclination_deg == np.degrees(np.pi / 2)


def test_entry_points_take_quantities_bit_for_bit(plain):
    q = tso.surface_of_section(plain, [0.0, 30.0] * u.deg, np.array([1.0, 1.1]) * u.one,
                               2 * tsu.orbit)
    p = tso.surface_of_section(plain, [0.0, 30.0], [1.0, 1.1], 2)
    for name in ("theta_p", "thetadot_p", "t", "r"):
        assert np.array_equal(getattr(q, name), getattr(p, name), equal_nan=True), name
    # a rate in rad/s and a time in s through the system's n and period
    n, period = plain.mean_motion, plain.orbital_period
    r = tso.time_series(plain, 0.5 * u.rad, 1.05 * n * u.rad / u.s, 2 * period * u.s,
                        samples_per_orbit=8)
    s = tso.time_series(plain, np.degrees(0.5), 1.05, 2.0, samples_per_orbit=8)
    assert np.array_equal(r.thetadot, s.thetadot) and r.orbits == s.orbits
    m = tso.chaos_map(plain, [0.0, 90.0] * u.deg, [1.0] * u.one, 2 * tsu.orbit)
    assert np.array_equal(m.theta_p, [0.0, 90.0]) and m.orbits == 2.0
    from ti_spinorbit.studies.chaosmap import _check_tilt
    assert _check_tilt((10 * u.deg, 0.5 * u.deg), "inertial").tolist() == [10.0, 0.5]


# ---- wrong dimensions: one line, the parameter, the unit given and the one expected -------
@pytest.mark.parametrize("make, message", [
    (lambda: tso.Sphere(600 * u.s, 1000), r"^radius must be in m \(a length\) or a unit "
                                           r"convertible to it \(got a Quantity in s\)$"),
    (lambda: tso.Sphere(600, 1000 * u.kg), r"^density must be in kg / m3 \(a mass density\).*"
                                           r"got a Quantity in kg\)$"),
    (lambda: tso.Ellipsoid(3, 2, 1 * u.kg, mass=1e9), r"^c must be in m .*got a Quantity in kg"),
    (lambda: _system(a=1.2 * u.kg), r"^a must be in m \(a length\).*got a Quantity in kg\)$"),
    (lambda: _system(e=0.05 * u.m), r"^e must be dimensionless .*got a Quantity in m\)$"),
    (lambda: _system(primary_spin_period=2 * u.m), r"^primary_spin_period must be in s \(a time\)"),
    (lambda: tso.Tides(time_lag=3 * u.m), r"^time_lag must be in s \(a time\)"),
    (lambda: tso.SolarTide(inclination_deg=1.0 * u.one), r"^inclination_deg must be an angle, "
                                                         r"u\.deg or u\.rad"),
    (lambda: tso.surface_of_section("didymos", 1.0 * u.m, 1.0, 2), r"^theta_p must be in "
                                                                   r"degrees \(deg\).* in m\)$"),
    (lambda: tso.surface_of_section("didymos", 1.0, 1.0 * u.Hz, 2), r"^thetadot_p must be in "
                                                                    r"units of the mean motion n"),
    (lambda: tso.surface_of_section("didymos", 1.0, 1.0, 2 * u.m), r"^orbits must be in orbital "
                                                                   r"periods .*in m\)$"),
    (lambda: tso.overlap_threshold("didymos", orbits=3 * u.day),
     r"^orbits in d needs one system's mean motion to become orbital periods"),
    (lambda: tso.parameter_map("didymos", [1.3], [0.0], 2, thetadot_p=[1e-4] * u.rad / u.s),
     r"^thetadot_p in rad / s needs one system's mean motion"),
])
def test_wrong_dimension_is_refused_in_one_line(make, message):
    with pytest.raises(UnitMismatchError, match=message) as err:
        make()
    assert "\n" not in str(err.value) and isinstance(err.value, ValueError)


def test_a_quantity_where_no_unit_is_taken_must_be_dimensionless():
    with pytest.raises(UnitMismatchError, match=r"^rtol must be dimensionless"):
        tso.Integrator(rtol=1e-10 * u.s)


# ---- the degree hint ------------------------------------------------------------------------
@pytest.mark.parametrize("value", [np.pi / 2, 1.5708, np.pi, 2 * np.pi, -np.pi / 4,
                                   np.linspace(0, 2 * np.pi, 9),
                                   np.linspace(0, 2 * np.pi, 16, endpoint=False),
                                   np.linspace(-np.pi, np.pi, 5)])
def test_radians_given_as_degrees_get_a_hint(value, plain):
    assert tsu.looks_like_radians(value)
    with pytest.warns(DegreesExpectedWarning, match=r"^theta_p = .* looks like radians, but "
                      r"theta_p is in degrees .*np\.degrees\(theta_p\).*theta_p \* u\.rad\)$"):
        with pytest.raises(ValueError, match="orbits"):      # the hint comes before any run
            tso.surface_of_section(plain, value, 1.0, -1)


@pytest.mark.parametrize("value", [0, 0.0, 1, 1.0, 2, 3, 5, 5.5, 10, 30, 45, 60, 90, 120, 180,
                                   270, 360, -90, [0, 0], np.zeros(4), np.linspace(0, 180, 7),
                                   np.linspace(0, 5, 11), np.arange(0, 360, 30), [0.0, 90.0],
                                   float("nan")])
def test_degree_inputs_get_no_hint(value):
    assert not tsu.looks_like_radians(value)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tsu.degrees("theta_p", value)
    assert not _hints(caught)


def test_no_decimal_degree_is_taken_for_radians():
    typed = [k / 100 for k in range(1, 36001)]
    assert not [x for x in typed if tsu.looks_like_radians(x)]


def test_the_hint_is_everywhere_an_angle_in_degrees_is_taken(plain):
    cases = [lambda: plain.tilted_start(np.pi / 2, 1.0),
             lambda: plain.tilted_start(0.0, 1.0, roll=np.pi / 6),
             lambda: plain.tilted_start(0.0, 1.0, inclination=np.pi / 4),
             lambda: tso.SolarTide(heliocentric_a_au=1.6, heliocentric_e=0.1,
                                   inclination_deg=np.pi / 2),
             lambda: tso.chaos_map(plain, np.linspace(0, np.pi, 4), [1.0], -1)]
    for make in cases:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                make()
            except ValueError:
                pass
        hints = _hints(caught)
        assert hints and all(h.filename == __file__ for h in hints), [str(h.message) for h in caught]


def test_quantities_never_get_the_hint(plain):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plain.tilted_start(np.pi / 2 * u.rad, 1.0, roll=np.pi / 6 * u.rad)
    assert not _hints(caught)


# ---- result.quantity() ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def section(plain):
    return tso.surface_of_section(plain, [0.0, 30.0], [1.0, 1.1], 2)


def test_quantity_round_trip(section, plain):
    theta = section.quantity("theta_p")
    assert theta.unit == u.deg and np.array_equal(theta.to_value(u.deg), section.theta_p,
                                                  equal_nan=True)
    assert section.quantity("t").unit == u.s and section.quantity("r").unit == u.m
    spin = section.quantity("thetadot_p")
    assert spin.unit == tsu.n and np.array_equal(spin.value, section.thetadot_p, equal_nan=True)
    rad_s = spin.to(u.rad / u.s, equivalencies=tsu.equivalencies(plain))
    assert np.allclose(rad_s.value, section.thetadot_p * plain.mean_motion, equal_nan=True)
    orbits = section.quantity("orbits")
    assert orbits.unit == tsu.orbit and orbits.to_value(u.s, equivalencies=tsu.equivalencies(
        plain)) == pytest.approx(2 * plain.orbital_period, rel=1e-15)
    assert section.quantity("energy_drift").unit == u.dimensionless_unscaled
    # a Quantity taken from a result goes back in as the same number
    assert tsu.to_plain("theta_p", section.quantity("initial_theta_p"), "deg").tolist() == \
        section.initial_theta_p.tolist()


def test_quantity_refuses_names_listing_the_valid_ones(section):
    with pytest.raises(ValueError, match=r"^SectionResult: no field 'nope' with a unit; the "
                                         r"fields with a unit are theta_p, thetadot_p, t, r"):
        section.quantity("nope")
    with pytest.raises(ValueError, match=r"'status' holds 'status code.*not a physical "
                                         r"quantity.*the fields with a unit are theta_p"):
        section.quantity("status")


def test_unit_texts_map_to_astropy_units():
    assert tsu.astropy_unit("deg (roll, pitch)") == u.deg
    assert tsu.astropy_unit("kg m^2 s^-1") == u.kg * u.m**2 / u.s
    assert tsu.astropy_unit("1/orbit") == tsu.orbit ** -1
    assert tsu.astropy_unit("mean motion n") == tsu.n
    assert tsu.astropy_unit("orbital periods") == tsu.orbit
    assert tsu.astropy_unit("1 (relative)") == u.dimensionless_unscaled
    assert tsu.astropy_unit("steps") == u.dimensionless_unscaled
    assert tsu.astropy_unit("bool") is None and tsu.astropy_unit("name: x") is None


# ---- without astropy ------------------------------------------------------------------------
def _python(code):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=300, env=env, cwd=os.path.dirname(__file__))


def test_plain_numbers_never_import_astropy():
    out = _python("""
        import sys, warnings
        import numpy as np
        import ti_spinorbit as tso
        s = tso.BinarySystem(tso.Sphere(400.0, 2170.0), tso.Ellipsoid(85, 65, 60, 2170), 1200.0,
                             0.05, primary_spin_period=8000.0, orbital_period=43000.0)
        s.tilted_start(30.0, 1.1, roll=5.0)
        tso.Tides(time_lag=100.0); tso.SolarTide(inclination_deg=10.0)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            s.tilted_start(np.pi / 2, 1.0)
        assert [str(w.message) for w in caught], "no hint without astropy"
        print("astropy" in sys.modules)
    """)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


def test_everything_plain_works_without_astropy():
    out = _python("""
        import dataclasses, sys
        sys.modules["astropy"] = None          # as if astropy were not installed
        import numpy as np
        import ti_spinorbit as tso
        from ti_spinorbit.engine.results import Result, unit
        s = tso.BinarySystem(tso.Sphere(400.0, 2170.0), tso.Ellipsoid(85, 65, 60, 2170), 1200.0,
                             0.05, primary_spin_period=8000.0)
        s.tilted_start(30.0, 1.1, roll=5.0)
        tso.YORP(heliocentric_a_au=1.6, heliocentric_e=0.3)

        @dataclasses.dataclass
        class Little(Result):
            r: float = unit("m", default=1.0)

        try:
            Little().quantity("r")
        except ImportError as exc:
            print(exc)
    """)
    assert out.returncode == 0, out.stderr
    assert "pip install ti-spinorbit[units]" in out.stdout
