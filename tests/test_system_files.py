"""System files (``--system path.json``, ``systems --show path.json``,
``BinarySystem.from_file``): nothing in them is ignored. Unknown keys are refused with the
nearest valid key, derived entries are checked against the inputs, ``density_scale`` can no
longer be set by hand, deeply nested or non-object JSON gives one line naming the flag (or
parameter) and the file, and ``orbital_period`` must imply a physical bulk density. The
CLI runs in-process (``cli.main``) and fails before any integration: every test takes
well under a second."""

import json
import math
import re

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import _validate, cli
from ti_spinorbit.system import catalog
from ti_spinorbit.output import io
from ti_spinorbit.system.systems import DERIVED_RTOL, G, read_system_file

DERIVED = ("mean_motion_rad_s", "mass_ratio", "omega0", "orbital_period_h")


@pytest.fixture
def vh():
    return catalog.system("1991 VH")


@pytest.fixture
def vh_file(tmp_path, capsys):
    """1991 VH as 'ti-spinorbit systems --show --out' writes it."""
    path = tmp_path / "vh.json"
    assert cli.main(["systems", "--show", "1991 VH", "--out", str(path), "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
    return path


def edited(tmp_path, vh_file, edit, name="mine.json"):
    """A copy of ``vh_file`` with ``edit(d)`` applied to its description."""
    d = json.loads(vh_file.read_text())
    edit(d)
    path = tmp_path / name
    path.write_text(json.dumps(d))
    return path


def cli_error(capsys, tmp_path, path, command="section"):
    """Run ``command --system path`` (or ``systems --show path``): exit status 2, one line on
    stderr, no output written; returns the message after the command's prefix."""
    out = tmp_path / "x.png"
    argv = (["systems", "--show", str(path)] if command == "systems" else
            [command, "--system", str(path), "--thetadot", "1.0", "--orbits", "1",
             "--out", str(out)])
    assert cli.main(argv) == cli.EXIT_ERROR
    captured = capsys.readouterr()
    prefix = f"ti-spinorbit {command}: error: "
    assert captured.err.startswith(prefix) and captured.err.count("\n") == 1, captured.err
    assert captured.out == "" and not out.exists()
    return captured.err[len(prefix):].rstrip("\n")


def python_error(path, error=ValueError):
    with pytest.raises(error) as info:
        tso.BinarySystem.from_file(path)
    message = str(info.value)
    assert "\n" not in message
    return message


# ---- 1. unknown keys ---------------------------------------------------------------------

@pytest.mark.parametrize("edit, key, where, hint", [
    (lambda d: d.update(primary_spin_period=9000.0), "primary_spin_period",
     "the system description", "did you mean 'primary_spin_period_s'?"),
    (lambda d: d.update(eccentricity=0.1), "eccentricity", "the system description",
     "did you mean 'e'?"),
    (lambda d: d.update(zzz=0.1), "zzz", "the system description",
     "the keys are 'name', 'primary', 'secondary', 'a_m', 'e', 'primary_spin_period_s', "
     "'observed_orbital_period_h', 'period_match', 'heliocentric_orbit', 'heliocentric_a_au', "
     "'heliocentric_e', 'mean_motion_rad_s', 'mass_ratio', 'omega0', 'orbital_period_h', "
     "'density_scale'"),
    (lambda d: d["secondary"].update(mass=1e11), "mass", "'secondary'", "did you mean 'mass_kg'?"),
    (lambda d: d["primary"].update(semi_axes=[600, 600, 600]), "semi_axes", "'primary'",
     "did you mean 'semi_axes_m'?"),
])
def test_unknown_keys_are_refused_naming_the_key_the_file_and_the_nearest_key(
        tmp_path, capsys, vh_file, edit, key, where, hint):
    path = edited(tmp_path, vh_file, edit)
    expected = (f"{path}': unknown key {key!r} in {where}: {hint} (unknown keys are refused, "
                "not ignored)")
    assert cli_error(capsys, tmp_path, path) == f"--system: '{expected}"
    assert cli_error(capsys, tmp_path, path, "systems") == f"--show: '{expected}"
    assert python_error(path) == f"path: '{expected}"
    with pytest.raises(ValueError, match=f"unknown key {key!r} in {where}"):
        tso.BinarySystem.from_description(json.loads(path.read_text()))


def test_a_key_given_twice_is_refused(tmp_path, capsys, vh_file):
    text = vh_file.read_text().replace('"e": 0.05', '"e": 0.05, "e": 0.3')
    path = tmp_path / "twice.json"
    path.write_text(text)
    expected = f"'{path}': key 'e' is given twice in one object (JSON would keep the last silently)"
    assert cli_error(capsys, tmp_path, path) == f"--system: {expected}"
    assert python_error(path) == f"path: {expected}"


# ---- 2. derived entries ------------------------------------------------------------------

def test_files_the_package_writes_round_trip(tmp_path, capsys):
    for name in catalog.names():
        path = tmp_path / "one.json"
        assert cli.main(["systems", "--show", name, "--out", str(path), "--quiet"]) == 0
        system, loaded = catalog.system(name), tso.BinarySystem.from_file(path)
        assert loaded == system and loaded.describe() == system.describe(), name
        np.testing.assert_array_equal(loaded.parameter_row(), system.parameter_row())
        np.testing.assert_array_equal(loaded.initial_state(0.3, 1.2),
                                      system.initial_state(0.3, 1.2))
        assert cli.main(["systems", "--show", str(path)]) == 0     # a file shows as a name
        from_file = capsys.readouterr().out.splitlines()
        assert cli.main(["systems", "--show", name]) == 0
        from_name = capsys.readouterr().out.splitlines()
        assert [line.split()[0] for line in from_file] == [line.split()[0] for line in from_name]
        assert from_file[0] == from_name[0] == f"{'name':24s} {system.name}"
    assert capsys.readouterr().err == ""


def test_archive_descriptions_round_trip_general_bodies_and_scaled_densities():
    """io.save writes describe() plus integrals: a general body, and a system whose densities
    orbital_period scaled, come back equal (density_scale is a record, not written)."""
    dd = catalog.system("Didymos")
    scaled = tso.BinarySystem(dd.primary, dd.secondary, dd.a, dd.e, orbital_period=11.0 * 3600)
    ellipsoid = tso.Ellipsoid(300.0, 200.0, 150.0, 2000.0)
    lumpy = tso.Body(ellipsoid.mass, {**ellipsoid.integrals, (3, 0, 0): 1e15}, 400.0, "lumpy")
    general = tso.BinarySystem(tso.Sphere(1000.0, 2000.0), lumpy, 6000.0, 0.05)
    for system in (scaled, general):
        back = tso.BinarySystem.from_description(json.loads(json.dumps(io.describe_system(system))))
        assert back == system and back.density_scale == 1.0
        np.testing.assert_array_equal(back.parameter_row(), system.parameter_row())
    assert scaled.density_scale != 1.0 and "density_scale" not in scaled.describe()


@pytest.mark.parametrize("key, factor, inputs", [
    ("orbital_period_h", 20.0 / 32.52473479610836, "a_m and the bodies' mass_kg"),
    ("mean_motion_rad_s", 1.5, "a_m and the bodies' mass_kg"),
    ("mass_ratio", 2.0, "the bodies' mass_kg"),
    ("omega0", 0.5, "the secondary's semi_axes_m or integrals"),
])
def test_an_edited_derived_entry_is_refused_naming_both_values_and_the_inputs(
        tmp_path, capsys, vh, vh_file, key, factor, inputs):
    written = json.loads(vh_file.read_text())[key]
    path = edited(tmp_path, vh_file, lambda d: d.update({key: written * factor}))
    derived = {"orbital_period_h": vh.orbital_period / 3600.0, "mean_motion_rad_s": vh.mean_motion,
               "mass_ratio": vh.mass_ratio, "omega0": vh.omega0}[key]
    expected = (f"'{path}': {key} is {written * factor:.12g} in the description, but {inputs} "
                f"give {derived:.12g}: it is derived from the inputs, never read: edit those "
                "inputs instead (derived entries are optional: delete those that no longer match)")
    assert cli_error(capsys, tmp_path, path) == f"--system: {expected}"
    assert python_error(path) == f"path: {expected}"


def test_orbital_period_h_edited_to_20_h_is_refused_not_ignored(tmp_path, capsys, vh_file):
    path = edited(tmp_path, vh_file, lambda d: d.update(orbital_period_h=20))
    message = cli_error(capsys, tmp_path, path)
    assert message.startswith(f"--system: '{path}': orbital_period_h is 20 in the description, "
                              "but a_m and the bodies' mass_kg give 32.5247347961: ")


def test_an_ellipsoids_bounding_radius_is_derived_and_all_mismatches_are_named_at_once(
        tmp_path, capsys, vh, vh_file):
    def edit(d):                       # a longer secondary, its derived entries left stale
        d["secondary"]["semi_axes_m"][0] = 320.0
    path = edited(tmp_path, vh_file, edit)
    longer = tso.BinarySystem(vh.primary, tso.Ellipsoid(320.0, *vh.secondary.semi_axes[1:],
                                                        mass=vh.secondary.mass,
                                                        name=vh.secondary.name), vh.a, vh.e,
                              name=vh.name, heliocentric_orbit=vh.heliocentric_orbit)
    expected = (f"--system: '{path}': secondary bounding_radius_m is "
                f"{vh.secondary.bounding_radius:.12g} in the description, but its semi_axes_m "
                "give 320 (an ellipsoid's is its largest semi-axis); omega0 is "
                f"{vh.omega0:.12g} in the description, but the secondary's semi_axes_m or "
                f"integrals give {longer.omega0:.12g}: they are derived from the inputs, never "
                "read: edit those inputs instead (derived entries are optional: delete those "
                "that no longer match)")
    assert cli_error(capsys, tmp_path, path) == expected

    def edit_and_drop(d):              # as the message says: the derived entries may go
        edit(d)
        for key in ("omega0", "mass_ratio"):
            del d[key]
        del d["secondary"]["bounding_radius_m"]
    loaded = tso.BinarySystem.from_file(edited(tmp_path, vh_file, edit_and_drop, "ok.json"))
    assert loaded == longer and loaded.secondary.bounding_radius == 320.0


def test_derived_entries_agree_to_a_relative_1e_9_and_may_be_left_out(tmp_path, vh, vh_file):
    def nudge(d):
        for key in DERIVED:
            d[key] *= 1.0 + 0.1 * DERIVED_RTOL
    assert tso.BinarySystem.from_file(edited(tmp_path, vh_file, nudge)) == vh

    def drop(d):
        for key in DERIVED:
            del d[key]
        for body in ("primary", "secondary"):
            del d[body]["bounding_radius_m"]
    assert tso.BinarySystem.from_file(edited(tmp_path, vh_file, drop, "bare.json")) == vh


def test_an_edited_density_scale_is_refused_and_1_from_earlier_versions_is_read(tmp_path, capsys,
                                                                               vh, vh_file):
    path = edited(tmp_path, vh_file, lambda d: d.update(density_scale=2.5))
    expected = (f"'{path}': density_scale is 2.5, but a description's masses are used as they "
                "are and nothing scales them (it recorded a factor BinarySystem(orbital_period=) "
                "had already applied to mass_kg, and cannot be checked): delete density_scale, "
                "and edit the bodies' mass_kg to change the densities")
    assert cli_error(capsys, tmp_path, path) == f"--system: {expected}"
    assert python_error(path) == f"path: {expected}"
    older = edited(tmp_path, vh_file, lambda d: d.update(density_scale=1.0), "older.json")
    assert tso.BinarySystem.from_file(older) == vh


def test_semi_axes_that_disagree_with_the_integrals_are_refused(vh):
    d = io.describe_system(vh)
    d["secondary"]["semi_axes_m"] = [250.0, 195.95917942265424, 190.0]
    with pytest.raises(ValueError, match=r"^secondary semi_axes_m \[250.0, 195.95917942265424, "
                                         r"190.0\] and mass_kg make T\^200 = .* for a uniform "
                                         r"ellipsoid, but its integrals give .*: the integrals "
                                         r"are read and semi_axes_m only checked"):
        tso.BinarySystem.from_description(d)


# ---- 3. nested and non-object JSON -------------------------------------------------------

@pytest.mark.parametrize("text, what", [
    ("[" * 100000 + "]" * 100000, "deep"),
    ('{"a": ' * 100000 + "1" + "}" * 100000, "deep"),
    ("3", "a JSON number"),
    ('"1991 VH"', "a JSON string"),
    ("null", "a JSON null"),
    ("[]", "a JSON array"),
    ("[[1]]", "a JSON array"),
])
def test_deep_or_non_object_json_is_one_line_naming_the_flag_and_the_file(tmp_path, capsys, text,
                                                                         what):
    path = tmp_path / "odd.json"
    path.write_text(text)
    tail = ("holds JSON nested too deeply to read" if what == "deep" else
            f"holds {what}, not an object") + "; a system file is one JSON object " \
        "(BinarySystem.describe() output, as 'ti-spinorbit systems --show NAME --out PATH' writes)"
    assert cli_error(capsys, tmp_path, path) == f"--system: '{path}' {tail}"
    assert cli_error(capsys, tmp_path, path, "systems") == f"--show: '{path}' {tail}"
    assert python_error(path) == f"path: '{path}' {tail}"
    with pytest.raises(ValueError, match=r"^--system: "):       # the prefix the caller names
        read_system_file(str(path), "--system")


def test_a_list_of_several_systems_names_its_length(tmp_path, capsys):
    path = tmp_path / "catalogue.json"
    assert cli.main(["systems", "--out", str(path), "--quiet"]) == 0
    n = len(catalog.names())
    expected = (f"'{path}' holds a list of {n} system descriptions; give a file of one "
                "('ti-spinorbit systems --show NAME --out PATH' writes one)")
    assert cli_error(capsys, tmp_path, path) == f"--system: {expected}"
    assert python_error(path) == f"path: {expected}"


def test_a_deeply_nested_value_inside_the_object_is_one_line(tmp_path, vh_file):
    path = edited(tmp_path, vh_file, lambda d: d.update(name=json.loads("[" * 200 + "]" * 200)))
    message = python_error(path)
    assert message.startswith(f"path: '{path}': name must be a string (got [[[[")


def test_show_bounds_a_value_too_deep_to_repr():
    deep = []
    for _ in range(100000):
        deep = [deep]
    assert _validate.show(deep) == "a list nested too deeply to show"


def test_missing_file_and_non_path(tmp_path, capsys):
    path = tmp_path / "absent.json"
    assert python_error(path, FileNotFoundError) == f"path: no such file '{path}'"
    assert cli_error(capsys, tmp_path, path) == (
        f"--system: no such file '{path}' (a catalogued name, or a .json written by "
        "'ti-spinorbit systems --show NAME --out PATH')")
    with pytest.raises(TypeError, match=r"^path must be a file path \(str or os.PathLike\), "
                                        r"got 3$"):
        tso.BinarySystem.from_file(3)


# ---- 4. orbital_period ---------------------------------------------------------------------

def _period_range(vh):
    volume = 4.0 / 3.0 * math.pi * (600.0**3 + math.prod(vh.secondary.semi_axes))
    return [2.0 * math.pi * math.sqrt(vh.a**3 / (G * rho * volume)) for rho in (25000.0, 100.0)]


@pytest.mark.parametrize("period, density", [(1e20, "2.24e-27"), (1.0, "2.24e+13"),
                                             (1e-300, "inf")])
def test_orbital_period_implying_an_unphysical_bulk_density_is_one_sentence(vh, period, density):
    shortest, longest = _period_range(vh)
    with pytest.raises(ValueError) as info:
        tso.BinarySystem(vh.primary, vh.secondary, vh.a, vh.e, orbital_period=period)
    assert str(info.value) == (
        f"orbital_period must lie in [{shortest:.6g}, {longest:.6g}] s for these bodies at "
        "a = 3300 m, the periods of a bulk density (m1 + m2)/(V1 + V2) in [100, 25000] kg/m^3 "
        f"(got {period:.6g} s, which implies {density} kg/m^3)")
    assert f"{shortest:.6g}" == "29907.1" and f"{longest:.6g}" == "472873"


def test_orbital_period_range_ends_are_accepted_and_the_density_follows(vh):
    shortest, longest = _period_range(vh)
    volume = 4.0 / 3.0 * math.pi * (600.0**3 + math.prod(vh.secondary.semi_axes))
    for period, density in ((shortest * (1 + 1e-9), 25000.0), (longest * (1 - 1e-9), 100.0)):
        s = tso.BinarySystem(vh.primary, vh.secondary, vh.a, vh.e, orbital_period=period)
        assert s.total_mass / volume == pytest.approx(density, rel=1e-8)
    for period in (shortest * 0.99, longest * 1.01):
        with pytest.raises(ValueError, match="which implies"):
            tso.BinarySystem(vh.primary, vh.secondary, vh.a, vh.e, orbital_period=period)


def test_orbital_period_of_a_general_body_uses_its_equivalent_ellipsoid(vh):
    ellipsoid = vh.secondary
    general = tso.Body(ellipsoid.mass, dict(ellipsoid.integrals), ellipsoid.bounding_radius, "g")
    with pytest.raises(ValueError) as as_ellipsoid:
        tso.BinarySystem(vh.primary, ellipsoid, vh.a, vh.e, orbital_period=1.0)
    with pytest.raises(ValueError) as as_general:
        tso.BinarySystem(vh.primary, general, vh.a, vh.e, orbital_period=1.0)
    assert str(as_general.value) == str(as_ellipsoid.value)


def test_orbital_period_that_pushes_a_mass_past_its_bound_is_one_sentence():
    big = tso.Sphere(1e10, 2e4)                 # ten solar radii: the largest body allowed
    volume = 2 * 4.0 / 3.0 * math.pi * 1e30
    period = 2.0 * math.pi * math.sqrt(1e33 / (G * 24000.0 * volume))
    with pytest.raises(ValueError) as info:
        tso.BinarySystem(big, big, 1e11, 0.0, orbital_period=period)
    assert re.fullmatch(r"orbital_period \S+ s scales both masses by 1\.2\d*, which makes the "
                        r"primary's 1\.0\d*e\+35 kg, outside \[1e-09, 1e\+35\] kg",
                        str(info.value)), str(info.value)


def test_the_bulk_density_range_is_documented():
    assert (_validate.MIN_BULK_DENSITY, _validate.MAX_BULK_DENSITY) == (100.0, 25000.0)
    assert "[100, 25000] kg/m³" in tso.BinarySystem.__doc__
