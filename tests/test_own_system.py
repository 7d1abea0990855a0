"""Your own system everywhere: ``--system path.json`` (round trip with ``systems --show --out``),
``BinarySystem(..., orbital_period=)``, the systems table (P_orb, sizes), and the input
warnings (tiny bodies, sections at e ~ 0). The CLI runs in-process (``cli.main``): tiny runs."""

import json
import math
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import cli
from ti_spinorbit.system import catalog
from ti_spinorbit.cli import common
from ti_spinorbit.system.systems import G, ImplausibleInputWarning, NearCircularWarning

HOUR = 3600.0
DIDYMOS_PERIOD_H = 11.92        # observed mutual orbit period of Didymos-Dimorphos


def _arrays(path):
    """Every numeric array of a saved .npz (the text metadata holds the command line)."""
    with np.load(path, allow_pickle=False) as d:
        return {k: d[k] for k in d.files if d[k].dtype.kind in "fiub"}


@pytest.fixture
def vh_json(tmp_path, capsys):
    path = tmp_path / "vh.json"
    assert cli.main(["systems", "--show", "1991 VH", "--out", str(path), "--quiet"]) == 0
    assert capsys.readouterr().out == ""
    return path


# ---- --system path.json ------------------------------------------------------------------

def test_section_from_json_is_bit_identical_to_the_catalogue_name(tmp_path, vh_json, capsys):
    common = ["--thetadot", "1.1", "1.6", "--orbits", "3", "--rtol", "1e-9", "--quiet"]
    assert cli.main(["section", "--system", str(vh_json), *common,
                     "--out", str(tmp_path / "file.png")]) == 0
    assert cli.main(["section", "--system", "1991 VH", *common,
                     "--out", str(tmp_path / "name.png")]) == 0
    from_file, from_name = _arrays(tmp_path / "file.npz"), _arrays(tmp_path / "name.npz")
    assert sorted(from_file) == sorted(from_name) and "theta_p" in from_file
    for key in from_name:
        np.testing.assert_array_equal(from_file[key], from_name[key], err_msg=key)
    assert capsys.readouterr().err == ""


def test_json_rebuilds_the_catalogue_system_exactly(vh_json):
    loaded = tso.BinarySystem.from_description(json.loads(vh_json.read_text()))
    vh = catalog.system("1991 VH")
    np.testing.assert_array_equal(loaded.parameter_row(), vh.parameter_row())
    np.testing.assert_array_equal(loaded.initial_state(0.3, 1.2), vh.initial_state(0.3, 1.2))
    assert loaded.describe() == vh.describe()


def test_eccentricity_flag_applies_to_a_json_system(vh_json):
    d = json.loads(vh_json.read_text())
    vh_json.write_text(json.dumps([d]))      # the one-item list 'systems --out' writes
    args = cli._parser().parse_args(["section", "--system", str(vh_json), "--eccentricity", "0.2"])
    system = common.build_system(args)
    assert system.e == 0.2 and system.density_scale == 1.0
    np.testing.assert_array_equal(system.parameter_row(),
                                  catalog.system("1991 VH", eccentricity=0.2).parameter_row())


@pytest.mark.parametrize("content, flags, message", [
    (None, [], "--system: no such file"),
    ("not json", [], "--system: cannot read"),
    ('{"a_m": 3300}', [], "mine.json': system description lacks 'primary', 'secondary', 'e'"),
    ("VH", ["--elongation", "1.2"], "--elongation applies only to a catalogued --system"),
    ("VH", ["--density", "2000"], "--density applies only to a catalogued --system"),
    ("VH", ["--eccentricity", "0.99"], "--eccentricity must lie in [0, 0.7291) for 1991 VH"),
])
def test_bad_json_system_is_one_line_naming_the_flag(tmp_path, vh_json, capsys, content, flags,
                                                     message):
    path = vh_json if content == "VH" else tmp_path / "mine.json"
    if content not in (None, "VH"):
        path.write_text(content)
    status = cli.main(["section", "--system", str(path), *flags, "--out", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert status == cli.EXIT_ERROR
    assert err.startswith("ti-spinorbit section: error: ") and message in err
    assert err.count("\n") == 1
    assert not (tmp_path / "x.png").exists()


def test_overlap_refuses_a_json_system(vh_json, tmp_path, capsys):
    assert cli.main(["overlap", "--system", str(vh_json), "--out", str(tmp_path / "o.png")]) == 2
    assert "overlap scans the catalogue's elongation prescription" in capsys.readouterr().err


# ---- orbital_period ----------------------------------------------------------------------

def test_orbital_period_scales_both_densities_to_match_kepler():
    primary, secondary = tso.Sphere(1000.0, 2000.0), tso.Ellipsoid(200.0, 150.0, 120.0, 2000.0)
    a, period = 5000.0, 20.0 * HOUR
    s = tso.BinarySystem(primary, secondary, a, 0.1, orbital_period=period)
    kepler = 2.0 * math.pi * math.sqrt(a**3 / (G * (s.primary.mass + s.secondary.mass)))
    assert kepler == pytest.approx(period, rel=1e-13)
    assert s.orbital_period == pytest.approx(period, rel=1e-13)
    plain = tso.BinarySystem(primary, secondary, a, 0.1)
    assert s.density_scale == pytest.approx((plain.orbital_period / period) ** 2, rel=1e-14)
    assert s.primary.mass == pytest.approx(primary.mass * s.density_scale, rel=1e-15)
    assert s.secondary.mass == pytest.approx(secondary.mass * s.density_scale, rel=1e-15)
    assert s.mass_ratio == pytest.approx(plain.mass_ratio, rel=1e-14)
    assert s.omega0 == pytest.approx(plain.omega0, rel=1e-14)
    assert s.secondary.semi_axes == secondary.semi_axes and plain.density_scale == 1.0
    assert "density_scale" not in s.describe()      # the masses written carry it already
    assert s.describe()["orbital_period_h"] == pytest.approx(20.0, rel=1e-13)


def test_orbital_period_scales_a_general_body_integral_by_integral():
    ellipsoid = tso.Ellipsoid(300.0, 200.0, 150.0, 2000.0)
    lumpy = tso.Body(ellipsoid.mass, dict(ellipsoid.integrals), ellipsoid.bounding_radius, "lumpy")
    s = tso.BinarySystem(tso.Sphere(1000.0, 2000.0), lumpy, 6000.0, 0.05, orbital_period=30 * HOUR)
    assert not hasattr(s.secondary, "semi_axes") and s.secondary.name == "lumpy"
    np.testing.assert_array_equal(s.secondary.as_row(), lumpy.as_row() * s.density_scale)
    assert s.secondary.bounding_radius == lumpy.bounding_radius
    assert s.orbital_period == pytest.approx(30 * HOUR, rel=1e-13)


def test_didymos_with_its_observed_period():
    didymos = catalog.system("Didymos")
    s = tso.BinarySystem(didymos.primary, didymos.secondary, didymos.a, didymos.e,
                         name="Didymos", orbital_period=DIDYMOS_PERIOD_H * HOUR)
    assert s.orbital_period / HOUR == pytest.approx(DIDYMOS_PERIOD_H, rel=1e-13)
    # the catalogue's densities already give 11.92 h to its rounding: the scale is ~1
    assert s.density_scale == pytest.approx((didymos.orbital_period / HOUR / DIDYMOS_PERIOD_H) ** 2,
                                            rel=1e-13)
    assert abs(s.density_scale - 1.0) < 0.01
    again = tso.BinarySystem.from_description(json.loads(json.dumps(s.describe())))
    assert again.density_scale == 1.0 and again == s      # a record, not part of the system
    np.testing.assert_array_equal(again.parameter_row(), s.parameter_row())


@pytest.mark.parametrize("value, error, message", [
    (-1.0, ValueError, "orbital_period must be a finite number > 0 (got -1"),
    (0.0, ValueError, "orbital_period must be a finite number > 0 (got 0"),
    (math.nan, ValueError, "orbital_period must be a finite number > 0 (got nan"),
    (math.inf, ValueError, "orbital_period must be a finite number > 0 (got inf"),
    ("11.92 h", TypeError, "orbital_period"),
])
def test_orbital_period_is_validated(value, error, message):
    vh = catalog.system("1991 VH")
    with pytest.raises(error) as info:
        tso.BinarySystem(vh.primary, vh.secondary, vh.a, vh.e, orbital_period=value)
    assert message in str(info.value) and "\n" not in str(info.value)


# ---- systems table and docstrings ----------------------------------------------------------

def test_systems_table_shows_orbital_period_and_sizes(capsys):
    assert cli.main(["systems"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "P_orb (h)" in lines[0] and "primary (m)" in lines[0]
    didymos = next(line for line in lines if line.startswith("Didymos"))
    assert "11.92" in didymos and "R 400" in didymos and "86 x 66 x 65" in didymos


def test_docstrings_say_semi_axes_in_metres():
    assert "semi-axes a ≥ b ≥ c (m)" in tso.Ellipsoid.__doc__
    assert "semi-axes a >= b >= c in m, not diameters" in tso.BinarySystem.__doc__
    assert "orbital_period" in tso.BinarySystem.__doc__ and "density_scale" in tso.BinarySystem.__doc__


# ---- warnings ------------------------------------------------------------------------------

@pytest.mark.parametrize("primary, secondary, a, what", [
    (tso.Sphere(0.6, 2000.0), tso.Sphere(0.2, 2000.0), 50.0, "primary size 0.6 m, secondary size 0.2 m"),
    (tso.Sphere(2.0, 2000.0), tso.Ellipsoid(1.0, 0.8, 0.5, 2000.0), 30.0, "secondary size 0.5 m"),
    (tso.Sphere(2.0, 2000.0), tso.Sphere(1.0, 2000.0), 8.0, "a = 8 m"),
])
def test_implausibly_small_bodies_warn(primary, secondary, a, what):
    with pytest.warns(ImplausibleInputWarning, match="kilometres typed as metres") as record:
        tso.BinarySystem(primary, secondary, a, 0.1)
    assert what in str(record[0].message)
    assert record[0].filename == __file__          # points at the caller's line


def test_catalogue_systems_do_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in catalog.names():
            catalog.system(name)


def test_section_near_circular_warns_once_and_circular_enough_does_not():
    vh = catalog.system("1991 VH")
    with pytest.warns(NearCircularWarning, match=r"e = 0.0005 < 0.001: the pericentre"):
        tso.surface_of_section(catalog.system("1991 VH", eccentricity=5e-4), 0.0, [1.0], orbits=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tso.surface_of_section(vh, 0.0, [1.0], orbits=1)


def test_cli_prints_input_warnings_as_one_line(tmp_path, capsys):
    d = catalog.system("1991 VH").describe()
    d["secondary"]["semi_axes_m"] = [0.3, 0.2, 0.19]       # kilometres typed as metres
    d["secondary"]["mass_kg"] = 100.0
    d["secondary"]["bounding_radius_m"] = 0.3
    d["e"] = 0.0
    for derived in ("mean_motion_rad_s", "mass_ratio", "omega0", "orbital_period_h"):
        del d[derived]               # they no longer match the edited secondary: optional
    path = tmp_path / "pebbles.json"
    path.write_text(json.dumps(d))
    status = cli.main(["section", "--system", str(path), "--thetadot", "1.0", "--orbits", "1",
                       "--rtol", "1e-8", "--out", str(tmp_path / "p.png")])
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert status in (0, cli.EXIT_INACCURATE)
    assert len(err) == 2, err
    assert err[0].startswith("ti-spinorbit section: warning: 1991 VH: secondary size 0.19 m")
    assert "kilometres typed as metres" in err[0]
    assert err[1].startswith("ti-spinorbit section: warning: surface_of_section: e = 0 < 0.001")
    assert cli.main(["section", "--system", str(path), "--thetadot", "1.0", "--orbits", "1",
                     "--rtol", "1e-8", "--out", str(tmp_path / "q.png"), "--quiet"]) in (0, 3)
    assert "warning" not in capsys.readouterr().err
