"""Saved results (ti_spinorbit.output.io, ti_spinorbit.output.xarray_io): every result kind survives
save -> load unchanged (arrays bit-identical, NaN padding included; scalars equal; systems with
identical parameter rows and initial states), files describe themselves (units, provenance,
status), bad files fail with a message that says why, and results convert to labelled xarray.

Tiny ensembles (2-4 members, a few orbits) keep the module to seconds once kernels are cached."""

import dataclasses
import datetime
import json
import math
import subprocess
import sys

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import files
from ti_spinorbit.output import io
from ti_spinorbit.studies.chaosmap import ChaosMap, ParameterMap
from ti_spinorbit.studies.libration import RelaxedLibration
from ti_spinorbit.studies.overlap import OverlapScan
from ti_spinorbit.studies.section import SectionResult, TimeSeriesResult

from conftest import lumpy_body


# ---- results of every kind (the fixtures are conftest.py's) ------------------------------------
KINDS = {"section": SectionResult, "time_series": TimeSeriesResult, "chaos_map": ChaosMap,
         "parameter_map": ParameterMap, "overlap_scan": OverlapScan,
         "relaxed_libration": RelaxedLibration}


def assert_same(expected, actual, where="result"):
    """Recursive equality: arrays identical in dtype, shape and values (NaN == NaN), systems
    with identical parameter rows and initial states, scalars equal and of the same type."""
    if isinstance(expected, tso.BinarySystem):
        assert isinstance(actual, tso.BinarySystem), where
        assert (actual.name, actual.a, actual.e, actual.primary_spin_period) == \
            (expected.name, expected.a, expected.e, expected.primary_spin_period), where
        np.testing.assert_array_equal(actual.parameter_row(), expected.parameter_row(), where)
        np.testing.assert_array_equal(actual.initial_state(0.3, 1.2),
                                      expected.initial_state(0.3, 1.2), where)
    elif isinstance(expected, np.ndarray):
        assert isinstance(actual, np.ndarray), where
        assert (actual.dtype, actual.shape) == (expected.dtype, expected.shape), where
        np.testing.assert_array_equal(actual, expected, err_msg=where)
    elif dataclasses.is_dataclass(expected):
        assert type(actual) is type(expected), where
        for f in dataclasses.fields(expected):
            assert_same(getattr(expected, f.name), getattr(actual, f.name), f"{where}.{f.name}")
    elif isinstance(expected, (list, tuple)):
        assert type(actual) is type(expected) and len(actual) == len(expected), where
        for k, (e, a) in enumerate(zip(expected, actual)):
            assert_same(e, a, f"{where}[{k}]")
    else:
        if isinstance(expected, np.generic):
            expected = expected.item()
        if isinstance(expected, float) and math.isnan(expected):
            assert isinstance(actual, float) and math.isnan(actual), where
        else:
            assert actual == expected and type(actual) is type(expected), (where, expected, actual)


# ---- round trips ------------------------------------------------------------------------
@pytest.mark.parametrize("kind", list(KINDS))
def test_every_kind_round_trips_unchanged(kind, request, tmp_path):
    result = request.getfixturevalue(kind)
    path = tso.save(result, tmp_path / f"{kind}.npz")
    loaded = tso.load(path)
    assert type(loaded) is KINDS[kind]
    assert_same(result, loaded)
    assert io.read_metadata(path)["kind"] == kind


def test_section_padding_and_shared_systems_survive(section, tmp_path):
    """Two members of one system: NaN padding kept bit for bit, one description saved, and
    the loaded members share one rebuilt system as the originals did."""
    loaded = tso.load(io.save(section, tmp_path / "s.npz"))
    assert np.isnan(section.theta_p).any()               # the fixture has padding to keep
    assert loaded.systems[0] is loaded.systems[1]
    assert loaded.status_names == ["done", "done"]
    assert loaded.member_orbits_per_second == section.member_orbits_per_second
    meta = io.read_metadata(tmp_path / "s.npz")
    assert len(meta["systems"]) == 1 and meta["systems"][0]["name"] == "1991 VH"
    with np.load(tmp_path / "s.npz") as d:
        np.testing.assert_array_equal(d["system_index"], [0, 0])


def test_nested_section_is_saved_with_prefix_or_dropped(chaos_map, tmp_path):
    with np.load(io.save(chaos_map, tmp_path / "m.npz")) as d:
        assert d["section/theta_p"].shape == chaos_map.section.theta_p.shape
        assert d["megno"].shape == (2, 2)
    loaded = tso.load(tmp_path / "m.npz")
    assert loaded.section.systems[0].name == "1991 VH"
    assert loaded.classification.dtype == object           # labels back as Python str
    path = io.save(chaos_map, tmp_path / "small.npz", include_sections=False)
    with np.load(path) as d:
        assert not [k for k in d.files if k.startswith("section/")]
    assert tso.load(path).section is None
    meta = io.read_metadata(path)
    assert meta["dropped"] == ["section"] and meta["systems"] == []


def test_general_body_with_odd_integrals_is_rebuilt_exactly(section, rng, tmp_path):
    """describe() alone cannot hold a lumpy body; the saved integrals can, bit for bit."""
    lumpy = tso.BinarySystem(lumpy_body(rng, scale=300.0, mass=2e12),
                             lumpy_body(rng, scale=100.0, mass=1e11), 3000.0, 0.1,
                             primary_spin_period=9000.0, name="lumpy")
    assert lumpy.secondary.has_odd_integrals
    with pytest.raises(ValueError, match="general Body"):
        tso.BinarySystem.from_description(lumpy.describe())
    rebuilt = tso.BinarySystem.from_description(io.describe_system(lumpy))
    assert_same(lumpy, rebuilt)
    # and through a file (systems swapped in: saving needs no kernel run)
    result = dataclasses.replace(section, systems=[lumpy, tso.catalog.system("test")])
    loaded = tso.load(io.save(result, tmp_path / "lumpy.npz"))
    assert_same(result, loaded)
    assert loaded.systems[1].secondary.semi_axes == tso.catalog.system("test").secondary.semi_axes


def test_ellipsoids_rebuild_from_plain_describe_output():
    for name in tso.catalog.names():
        system = tso.catalog.system(name)
        assert_same(system, tso.BinarySystem.from_description(system.describe()))


def test_save_appends_npz_and_returns_the_path(section, tmp_path):
    path = io.save(section, tmp_path / "noext")
    assert path.endswith("noext.npz") and isinstance(tso.load(path), SectionResult)
    with pytest.raises(FileNotFoundError, match="did you mean"):
        tso.load(tmp_path / "noext")


def test_save_result_alias_and_format_0_files(section, tmp_path):
    """save_result still works (the CLI calls it), and files it wrote before format_version
    existed (one describe() per member, no scalar fields block) still load."""
    io.save_result(section, tmp_path / "new.npz", kind="section")
    assert_same(section, tso.load(tmp_path / "new.npz"))
    # the layout of ti_spinorbit 0.1's save_result, written here as it did
    arrays = {k: v for k, v in vars(section).items() if isinstance(v, np.ndarray)}
    arrays["status_names"] = np.array(section.status_names)
    meta = {"kind": "section", **io.provenance(), "rtol": section.rtol, "atol": section.atol,
            "order": section.order, "orbits": section.orbits,
            "systems": [s.describe() for s in section.systems],
            "units": {"theta_p": "deg", "thetadot_p": "mean motion n"}}
    io.write_archive(tmp_path / "old.npz", arrays, meta)
    old = tso.load(tmp_path / "old.npz")
    assert old.seconds == 0.0                       # format 0 did not record the wall time
    assert math.isnan(old.max_drift)                # nor an accuracy limit: unknown
    assert_same(dataclasses.replace(section, seconds=0.0, max_drift=float("nan")), old)


# ---- self-description -------------------------------------------------------------------
@pytest.mark.parametrize("kind", list(KINDS))
def test_metadata_has_units_provenance_and_status(kind, request, tmp_path):
    result = request.getfixturevalue(kind)
    path = io.save(result, tmp_path / f"{kind}.npz", extra={"note": "test run"})
    meta = io.read_metadata(path)
    assert meta["format_version"] == io.FORMAT_VERSION
    assert (meta["package"], meta["version"]) == ("ti_spinorbit", tso.__version__)
    assert meta["arch"] and meta["arch"] == tso.runtime.current_arch()
    age = datetime.datetime.now(datetime.timezone.utc) - datetime.datetime.fromisoformat(meta["created_utc"])
    assert datetime.timedelta(0) <= age < datetime.timedelta(minutes=10)
    assert meta["note"] == "test run"
    assert meta["status_codes"]["1"] == "done"
    with np.load(path) as d:
        missing = [k for k in d.files if k != "metadata" and k not in meta["units"]]
        if "status" in d.files:
            assert meta["status_counts"] == {"done": int(d["status"].size)}
            assert set(d["status_names"].ravel()) == {"done"}
    assert not missing, f"arrays without units: {missing}"
    numeric = [k for k, v in meta["fields"].items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)]
    assert not [k for k in numeric if k not in meta["units"]]
    json.dumps(meta)                                  # plain JSON all the way down


def test_units_of_the_main_quantities(section, time_series, chaos_map, tmp_path):
    s = io.read_metadata(io.save(section, tmp_path / "s.npz"))["units"]
    assert (s["theta_p"], s["thetadot_p"], s["t"], s["r"]) == ("deg", "mean motion n", "s", "m")
    t = io.read_metadata(io.save(time_series, tmp_path / "t.npz"))["units"]
    assert (t["energy"], t["angmom_orbit"], t["alpha"]) == ("J", "kg m^2 s^-1", "deg")
    m = io.read_metadata(io.save(chaos_map, tmp_path / "m.npz"))["units"]
    assert (m["lyapunov"], m["section/t"], m["rtol"]) == ("1/orbit", "s", "1")


# ---- clear errors -----------------------------------------------------------------------
def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="no saved result at .*nothing.npz"):
        tso.load(tmp_path / "nothing.npz")


def _rewrite(path, out, **changes):
    """Copy an archive with metadata keys changed."""
    meta = {**io.read_metadata(path), **changes}
    with np.load(path) as d:
        arrays = {k: d[k] for k in d.files if k != "metadata"}
    return io.write_archive(out, arrays, meta)


@pytest.mark.parametrize("make, error, message", [
    (lambda p: p.write_text("hello"), ValueError, "not a ti_spinorbit archive: not a NumPy"),
    (lambda p: np.savez(p, theta_p=np.zeros(3)), ValueError, "no 'metadata' entry"),
    (lambda p: np.savez(p, metadata=np.array("{not json")), ValueError, "not JSON"),
    (lambda p: io.write_archive(p, {"x": np.zeros(2)}, {"study": "s"}), ValueError,
     "metadata has no 'kind'"),
    (lambda p: io.write_archive(p, {}, {"kind": "banana", "format_version": 1}), ValueError,
     "unknown kind 'banana'; known kinds: section"),
])
def test_not_a_result_archive(tmp_path, make, error, message):
    path = tmp_path / "bad.npz"
    make(path)
    with pytest.raises(error, match=message):
        tso.load(path)


def test_newer_format_version_is_refused(section, tmp_path):
    good = io.save(section, tmp_path / "good.npz")
    bad = _rewrite(good, tmp_path / "future.npz", format_version=99)
    with pytest.raises(ValueError, match="format_version 99.*reads format versions 0, 1, 2"):
        tso.load(bad)
    with pytest.raises(ValueError, match="format_version 'one'"):
        tso.load(_rewrite(good, tmp_path / "text.npz", format_version="one"))


def test_saving_bad_input(section, tmp_path):
    with pytest.raises(TypeError, match="cannot save a dict"):
        io.save({"theta_p": 1}, tmp_path / "x.npz")
    with pytest.raises(ValueError, match="kind 'chaos_map' does not match.*'section'"):
        io.save_result(section, tmp_path / "x.npz", kind="chaos_map")
    with pytest.raises(ValueError, match=r"extra metadata keys \['kind'\] clash"):
        io.save(section, tmp_path / "x.npz", extra={"kind": "mine"})
    with pytest.raises(ValueError, match=r"\['nested'\] clash"):   # absent here, still reserved
        io.save(section, tmp_path / "x.npz", extra={"nested": 1})
    with pytest.raises(ValueError, match="lacks 'a_m'"):
        tso.BinarySystem.from_description({"primary": {}, "secondary": {}, "e": 0.1})


# ---- xarray -------------------------------------------------------------------------------
def test_section_to_xarray(section):
    xr = pytest.importorskip("xarray")
    ds = tso.to_xarray(section)
    assert isinstance(ds, xr.Dataset)
    assert ds["theta_p"].dims == ("member", "crossing") and ds.sizes["member"] == 2
    np.testing.assert_array_equal(ds["initial_thetadot_p"], [0.83, 1.63])
    np.testing.assert_array_equal(ds["thetadot_p"].sel(member=1), section.thetadot_p[1])
    assert ds["thetadot_p"].attrs["units"] == "mean motion n" and ds["t"].attrs["units"] == "s"
    assert ds["initial_theta_p"].attrs["units"] == "deg"
    assert list(ds["status_name"].values) == ["done", "done"]
    assert ds.attrs["kind"] == "section" and ds.attrs["rtol"] == 1e-9
    assert json.loads(ds.attrs["systems"])[0]["name"] == "1991 VH"


def test_maps_to_xarray(chaos_map, parameter_map):
    pytest.importorskip("xarray")
    ds = tso.to_xarray(chaos_map)
    assert ds["megno"].dims == ("theta_p", "thetadot_p")
    assert ds["megno"].sel(theta_p=120.0, thetadot_p=1.6).item() == chaos_map.megno[1, 1]
    assert ds["theta_p"].attrs["units"] == "deg" and ds["lyapunov"].attrs["units"] == "1/orbit"
    assert ds.attrs["chaotic_fraction"] == chaos_map.chaotic_fraction
    ds = tso.to_xarray(parameter_map)
    assert ds["chaotic_fraction"].dims == ("elongation", "eccentricity")
    assert ds["megno"].dims == ("elongation", "eccentricity", "start")
    assert ds["megno"].sel(elongation=1.4, eccentricity=0.05).values.tolist() == \
        parameter_map.megno[1, 0].tolist()
    np.testing.assert_array_equal(ds["thetadot_p"], [1.0, 1.5])
    assert ds["omega0"].attrs["units"] == "mean motion n"
    assert ds["elongation"].attrs["units"] == "1 (a/b)"


def test_other_kinds_to_xarray(time_series, overlap_scan, relaxed_libration):
    pytest.importorskip("xarray")
    ds = tso.to_xarray(time_series)
    assert ds["energy"].dims == ("member", "sample") and ds["energy"].attrs["units"] == "J"
    assert ds["angmom_orbit"].dims == ("member", "sample", "component")
    ds = tso.to_xarray(overlap_scan)
    assert ds["overlaps"].dims == ("elongation",)
    np.testing.assert_array_equal(ds["elongation"], [1.01, 1.03])
    assert ds["widest_range"].sel(elongation=1.03, bound="high").item() == \
        overlap_scan.decisions[1].widest_range[1]
    assert ds["centre_1"].attrs["units"] == "mean motion n"
    ds = tso.to_xarray(relaxed_libration)
    assert ds.sizes["candidate"] == sum(len(c) for c in relaxed_libration.candidates)
    assert ds["extent"].attrs["units"] == "deg"
    assert ds.attrs["centre_thetadot_p"] == relaxed_libration.centre_thetadot_p


def test_to_xarray_of_a_file_keeps_its_provenance(chaos_map, tmp_path):
    pytest.importorskip("xarray")
    path = io.save(chaos_map, tmp_path / "m.npz")
    ds = tso.to_xarray(path)
    assert ds.attrs["created_utc"] == io.read_metadata(path)["created_utc"]
    np.testing.assert_array_equal(ds["megno"], chaos_map.megno)


def test_to_xarray_without_xarray_says_how_to_install(section, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)       # import xarray -> ImportError
    with pytest.raises(ImportError, match=r'pip install "ti-spinorbit\[xarray\]"'):
        tso.to_xarray(section)


def test_package_import_does_not_import_xarray():
    code = "import sys, ti_spinorbit; print('xarray' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "False"


# ---- one overwrite rule: refused unless overwrite=True (as the CLI's --overwrite) -----------
def test_save_refuses_an_existing_file_in_one_line_and_touches_nothing(section, tmp_path):
    path = tmp_path / "s.npz"
    path.write_bytes(b"an earlier result")
    for save in (lambda: io.save(section, path), lambda: tso.save(section, path),
                 lambda: section.save(path), lambda: io.save_result(section, path)):
        with pytest.raises(FileExistsError) as info:
            save()
        text = str(info.value)
        assert text == (f"{str(path)!r} already exists; pass overwrite=True to replace it, "
                        "or choose another name"), text
        assert isinstance(info.value, files.OutputExists)
    assert path.read_bytes() == b"an earlier result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.npz"]      # no temporary left
    # the name actually written counts: "b" is written as "b.npz"
    (tmp_path / "b.npz").write_bytes(b"x")
    with pytest.raises(FileExistsError, match=r"b\.npz' already exists"):
        io.save(section, tmp_path / "b")
    # a symbolic link by that name is an existing name too
    (tmp_path / "link.npz").symlink_to(tmp_path / "s.npz")
    with pytest.raises(FileExistsError, match=r"link\.npz' already exists"):
        section.save(tmp_path / "link.npz")
    assert path.read_bytes() == b"an earlier result"
    with pytest.raises(TypeError, match="overwrite must be True or False"):
        io.save(section, tmp_path / "new.npz", overwrite="yes")


def test_save_with_overwrite_replaces_and_a_new_name_needs_nothing(section, tmp_path):
    path = tmp_path / "s.npz"
    assert io.save(section, path) == path                 # a new name: written
    path.write_bytes(b"an earlier result")
    assert section.save(path, overwrite=True) == path
    assert_same(section, tso.load(path))
    assert tso.save(section, path, overwrite=True) == path


def test_a_file_that_appears_during_the_save_is_not_replaced(section, tmp_path, monkeypatch):
    """The name is checked before the work and again when the file is put in place (a hard
    link, which fails on an existing name): another writer's file that appeared meanwhile
    stays, and no temporary file is left."""
    path = tmp_path / "s.npz"
    real = np.savez_compressed

    def racing(fh, **arrays):
        real(fh, **arrays)
        path.write_bytes(b"written meanwhile by someone else")

    monkeypatch.setattr(np, "savez_compressed", racing)
    with pytest.raises(FileExistsError, match="already exists; pass overwrite=True"):
        io.save(section, path)
    assert path.read_bytes() == b"written meanwhile by someone else"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.npz"]
