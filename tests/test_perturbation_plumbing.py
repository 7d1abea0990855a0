"""Tides, YORP and BYORP on every entry point: recorded
in every result and its saved file, in xarray, with indicators, checkpoints and the Dask
path. Tiny runs: a few members, a few orbits, tolerances where the drift limits hold."""

import dataclasses
import json
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.model import perturbations as tsp
from test_checkpoint import killed_run   # the same kill-and-resume harness

#: A tide 1e6 times its real strength and YORP 1e6 times on the secondary of 1991 VH, BYORP:
#: effects visible in a few orbits (1991 VH's heliocentric orbit is catalogued).
TIDE = tso.Tides(k2=1e-5, time_lag=600.0, strength=1e6)
#: and the Sun's tide ×300 in the orbit plane (the planar model carries it), 1e-5 of the
#: mutual gravity
ALL = (TIDE, tso.YORP(coefficient=1e-3, strength=1e6), tso.BYORP(coefficient=1e-3, strength=1e6),
       tso.SolarTide(inclination_deg=0.0, strength=300.0))
STARTS = [0.83, 1.63]
ARGS = dict(orbits=6, rtol=1e-10)


@pytest.fixture(scope="module")
def section(vh):
    return tso.surface_of_section(vh, 0.0, STARTS, indicators=True, perturbations=ALL, **ARGS)


@pytest.fixture(scope="module")
def series(vh):
    return tso.time_series(vh, 0.0, STARTS, samples_per_orbit=8, perturbations=ALL, **ARGS)


@pytest.fixture(scope="module")
def cmap(vh):
    return tso.chaos_map(vh, [0.0, 90.0], [0.8, 1.6], orbits=4, fraction_orbits=(),
                         perturbations=[TIDE])


def assert_same(a, b):
    """Every field of two results equal (arrays bit for bit, NaN included), but wall time."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if f.name == "seconds" or dataclasses.is_dataclass(x) or f.name == "systems":
            continue
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        elif isinstance(x, float) and np.isnan(x):
            assert np.isnan(y), f.name
        else:
            assert x == y, f.name


def test_section_with_indicators_and_perturbations(section, vh):
    assert section.perturbations == ALL
    assert list(section.status_names) == ["done", "done"]
    assert np.all(np.isfinite(section.megno)) and np.all(section.megno > 0)
    assert np.all(np.isfinite(section.lyapunov))
    plain = tso.surface_of_section(vh, 0.0, STARTS, indicators=True, **ARGS)
    assert plain.perturbations == ()
    assert not np.array_equal(section.megno, plain.megno)       # the equations changed


@pytest.mark.parametrize("kw", [dict(integrator=tso.Integrator(model="3d")),
                                dict(indicator_space="full")])
def test_indicators_with_perturbations_in_3d(vh, kw):
    got = tso.surface_of_section(vh, 0.0, STARTS, indicators=True, perturbations=ALL,
                                 orbits=3, rtol=1e-10, **kw)
    assert got.perturbations == ALL and list(got.status_names) == ["done", "done"]
    assert np.all(np.isfinite(got.megno)) and np.all(np.isfinite(got.lyapunov))


@pytest.mark.parametrize("fixture", ["section", "series", "cmap"])
def test_saved_and_loaded_with_the_perturbations(fixture, request, tmp_path):
    result = request.getfixturevalue(fixture)
    path = tso.save(result, tmp_path / "r.npz")
    back = tso.load(path)
    assert type(back) is type(result)
    assert back.perturbations == result.perturbations and back.perturbations
    assert all(type(p) in (tso.Tides, tso.YORP, tso.BYORP, tso.SolarTide)
               for p in back.perturbations)
    assert_same(back, result)
    meta = tso.output.io.read_metadata(path)
    assert meta["units"]["perturbations"] == tsp.UNIT
    if fixture == "cmap":       # the nested section keeps them too
        assert back.section.perturbations == (TIDE,)
        assert_same(back.section, result.section)


def test_results_show_their_perturbations(section, cmap):
    assert repr(section).splitlines()[-1] == ("  perturbations tides on the secondary ×1e+06, "
                                              "yorp on the secondary ×1e+06, byorp ×1e+06, "
                                              "solar_tide ×300")
    assert "perturbations" in cmap._repr_html_()
    assert "perturbations" not in repr(cmap.section.__class__(**{
        **{f.name: getattr(cmap.section, f.name) for f in dataclasses.fields(cmap.section)},
        "perturbations": ()}))


def test_time_series_work_and_external_angular_momentum(series, tmp_path):
    n, width = series.t.shape
    assert series.work.shape == (n, width) and series.external_angmom.shape == (n, width, 3)
    assert series.units()["work"] == "J"
    assert series.units()["external_angmom"] == "kg m^2 s^-1"
    assert np.all(series.work[:, 0] == 0.0)
    assert np.all(np.abs(series.work[:, -1] / series.energy[:, 0]) > 1e-3)   # work was done
    assert np.all(np.linalg.norm(series.external_angmom[:, -1], axis=-1) > 0)   # YORP, BYORP
    back = tso.load(tso.save(series, tmp_path / "ts.npz"))
    np.testing.assert_array_equal(back.work, series.work)
    np.testing.assert_array_equal(back.external_angmom, series.external_angmom)
    # conservation() accounts for them: E − W and L − L_ext, as the accuracy verdict
    numbers, _ = series.conservation(0)
    assert numbers["energy_drift"] <= series.energy_drift[0] * (1 + 1e-9) < 1e-6
    assert numbers["angmom_drift"] <= series.angmom_drift[0] * (1 + 1e-9) < 1e-6


def test_xarray_carries_the_perturbations(series, cmap, tmp_path):
    pytest.importorskip("xarray")
    ds = tso.to_xarray(series)
    assert tsp.from_description(json.loads(ds.attrs["perturbations"])) == ALL
    assert ds["work"].dims == ("member", "sample") and ds["work"].attrs["units"] == "J"
    assert ds["external_angmom"].dims == ("member", "sample", "component")
    assert ds["external_angmom"].attrs["units"] == "kg m^2 s^-1"
    np.testing.assert_array_equal(ds["work"].values, series.work)
    ds2 = tso.to_xarray(tso.save(cmap, tmp_path / "m.npz"))        # from the file
    assert tsp.from_description(json.loads(ds2.attrs["perturbations"])) == (TIDE,)
    if all(isinstance(v, (str, int, float)) for v in ds.attrs.values()):   # netCDF-ready
        ds.attrs["perturbations"].encode("ascii", "strict")


def test_xarray_without_perturbations_says_so(vh):
    pytest.importorskip("xarray")
    ts = tso.time_series(vh, 0.0, [0.83], orbits=1, samples_per_orbit=4, rtol=1e-9)
    ds = tso.to_xarray(ts)
    assert ds.attrs["perturbations"] == "[]" and "work" not in ds


def test_chaos_map_records_them(cmap):
    assert cmap.perturbations == (TIDE,) and cmap.section.perturbations == (TIDE,)
    assert np.all(np.isfinite(cmap.megno))


def test_parameter_map_builds_them_per_system():
    pm = tso.parameter_map("1991 VH", [1.2, 1.5], [0.05], orbits=3, theta_p=[0.0],
                           thetadot_p=[1.0], fraction_orbits=(), perturbations=[TIDE])
    assert pm.perturbations == (TIDE,)
    # the same SI object gives each grid system its own scaled block (radius, masses, a, n)
    systems = [tso.catalog.system("1991 VH", elongation=q, eccentricity=0.05) for q in (1.2, 1.5)]
    rows = tsp.perturbation_rows(systems, [TIDE])
    assert rows[0, tsp.Q_TIDE2] != rows[1, tsp.Q_TIDE2]
    np.testing.assert_array_equal(rows[1], TIDE.block(systems[1]))


def test_overlap_threshold_records_them():
    scan = tso.overlap_threshold("2004 DC", elongations=[1.03], orbits=3, max_orbits=3,
                                 centre_starts=2, separatrix_starts=2, indicators=False,
                                 perturbations=[TIDE])
    assert scan.perturbations == (TIDE,) and scan.sections.perturbations == (TIDE,)


def test_libration_with_perturbations(vh):
    P = [tso.Tides(k2=1e-5, time_lag=600.0, strength=1e7)]
    kw = dict(samples_per_orbit=32, rtol=1e-10)
    amp = tso.libration_amplitude(vh, [0.45, 0.5], 4, perturbations=P, **kw)
    ts = tso.time_series(vh, 0.0, [0.45, 0.5], 4, perturbations=P, **kw)
    from ti_spinorbit.studies.libration import _amplitudes
    np.testing.assert_array_equal(amp, _amplitudes(ts))
    assert not np.array_equal(amp, tso.libration_amplitude(vh, [0.45, 0.5], 4, **kw))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        lib = tso.relaxed_libration(vh, orbits=3, candidates=np.linspace(0.2, 1.3, 9),
                                    zoom_candidates=5, max_iterations=1, samples_per_orbit=16,
                                    converge=False, perturbations=P)
    assert lib.perturbations == tuple(P) and lib.series.perturbations == tuple(P)
    assert lib.series.work is not None


def test_bad_perturbations_are_named_before_any_work(vh):
    with pytest.raises(TypeError, match=r"perturbations\[1\] must be a Tides, YORP, BYORP, SolarTide or Flyby"):
        tso.chaos_map(vh, [0.0], [1.0], orbits=2, perturbations=[TIDE, "tides"])
    with pytest.raises(ValueError, match=r"a second tides on the secondary"):
        tso.overlap_threshold("1991 VH", elongations=[1.05], orbits=2,
                              perturbations=[TIDE, tso.Tides()])


def test_yorp_on_a_system_of_your_own_asks_for_the_heliocentric_orbit(vh):
    mine = tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e, name="mine")
    with pytest.raises(ValueError, match="'mine' has no heliocentric orbit"):
        tso.YORP().block(mine)
    given = tso.YORP(heliocentric_a_au=1.14, heliocentric_e=0.14).block(mine)
    assert given[tsp.Q_YORP2] > 0


def test_the_heliocentric_orbit_belongs_to_the_system_not_to_its_name(vh):
    """A system of your own named like a catalogue entry gets no catalogued orbit; the
    orbit is a field of the system, saved and read back with it."""
    assert vh.heliocentric_orbit == tso.catalog.heliocentric_orbit("1991 VH")
    namesake = tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e, name="1991 VH")
    assert namesake.heliocentric_orbit is None
    with pytest.raises(ValueError, match="'1991 VH' has no heliocentric orbit"):
        tso.YORP().block(namesake)
    # the same torque as the catalogue's when given the same orbit, by field or by keyword
    mine = tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e, name="mine",
                            heliocentric_orbit=vh.heliocentric_orbit)
    a_au, e_sun = vh.heliocentric_orbit.a_au, vh.heliocentric_orbit.e
    by_keyword = tso.YORP(heliocentric_a_au=a_au, heliocentric_e=e_sun).block(namesake)
    np.testing.assert_array_equal(tso.YORP().block(mine), tso.YORP().block(vh))
    np.testing.assert_array_equal(by_keyword, tso.YORP().block(vh))
    # a farther orbit gives the 1/(d² sqrt(1 - e²)) weaker torque
    far = tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e,
                           heliocentric_orbit=(2.0 * a_au, 0.0))
    ratio = tso.YORP().block(far)[tsp.Q_YORP2] / tso.YORP().block(vh)[tsp.Q_YORP2]
    assert ratio == pytest.approx(np.sqrt(1.0 - e_sun ** 2) / 4.0, rel=1e-12)
    back = tso.BinarySystem.from_description(mine.describe())
    assert back == mine and back.heliocentric_orbit == mine.heliocentric_orbit
    with pytest.raises(ValueError, match=r"heliocentric_orbit a must lie in \[0.05, 10000\]"):
        tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e,
                         heliocentric_orbit=(0.01, 0.1))
    with pytest.raises(TypeError,
                       match=r"heliocentric_orbit must be a HeliocentricOrbit, \(a in AU, e\)"):
        tso.BinarySystem(vh.primary, vh.secondary, a=vh.a, e=vh.e, heliocentric_orbit=1.1)


def test_warmup_compiles_the_perturbed_variant():
    done = tso.warmup(models=["planar"], indicators=[False], sampling=[False],
                      perturbed=[True], verbose=False)
    assert [d["variant"] for d in done] == ["planar/plain/sections/order4/perturbed/cash-karp"]
    with pytest.raises(ValueError, match="perturbed must be a non-empty selection"):
        tso.warmup(perturbed=["yes"])


# ---- checkpoints -------------------------------------------------------------------------

def test_resumed_perturbed_run_equals_an_uninterrupted_one(tmp_path, vh):
    ckpt = tmp_path / "ts.ckpt"
    kw = dict(orbits=12, rtol=1e-10, samples_per_orbit=8)
    killed_run(tmp_path, ckpt, kill_after=2, kind="series", starts=STARTS, args=kw,
               extra="perturbations=[tso.Tides(k2=1e-5, time_lag=600.0, strength=1e6), "
                     "tso.BYORP(coefficient=1e-3, strength=1e6)],")
    kw["perturbations"] = [TIDE, tso.BYORP(coefficient=1e-3, strength=1e6)]
    resumed = tso.time_series(vh, 0.0, STARTS, **kw,
                              run=tso.Run(checkpoint=ckpt, resume=True, window_orbits=4))
    whole = tso.time_series(vh, 0.0, STARTS, **kw, run=tso.Run(window_orbits=4))
    assert_same(resumed, whole)
    assert np.all(np.isfinite(whole.work[:, -1])) and np.all(whole.work[:, -1] != 0)


def test_checkpoint_of_other_perturbations_is_refused(tmp_path, vh):
    ckpt = tmp_path / "a.ckpt"
    kw = dict(orbits=2, rtol=1e-10)
    tso.surface_of_section(vh, 0.0, STARTS, **kw, run=tso.Run(checkpoint=ckpt, keep_checkpoint=True))
    with pytest.raises(ValueError, match=r"other settings: perturbed \(checkpoint False, now "
                                         r"True\)"):
        tso.surface_of_section(vh, 0.0, STARTS, perturbations=[TIDE], **kw,
                               run=tso.Run(checkpoint=ckpt, resume=True))
    tso.surface_of_section(vh, 0.0, STARTS, perturbations=[TIDE], **kw,
                           run=tso.Run(checkpoint=ckpt, overwrite=True, keep_checkpoint=True))
    with pytest.raises(ValueError, match=r"other settings: perturbed \(checkpoint True, now "
                                         r"False\)"):
        tso.surface_of_section(vh, 0.0, STARTS, **kw, run=tso.Run(checkpoint=ckpt, resume=True))
    stronger = dataclasses.replace(TIDE, strength=2e6)       # the fingerprint hashes the rows
    with pytest.raises(ValueError, match="other inputs"):
        tso.surface_of_section(vh, 0.0, STARTS, perturbations=[stronger], **kw,
                               run=tso.Run(checkpoint=ckpt, resume=True))


# ---- Dask --------------------------------------------------------------------------------

def test_dask_path_passes_them_and_equals_one_process(vh):
    pytest.importorskip("distributed")
    from distributed import Client, LocalCluster

    kw = dict(rtol=1e-10, indicators=True, perturbations=[TIDE])
    local = tso.surface_of_section(vh, 0.0, STARTS, 3, **kw)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      env={"TI_SPINORBIT_ARCH": "cpu"}) as cluster, Client(cluster) as client:
        with pytest.raises(TypeError, match=r"perturbations\[0\] must be"):   # on the client
            tso.surface_of_section(vh, 0.0, STARTS, 3, perturbations=[1.0],
                                   run=tso.Run(client=client))
        got = tso.surface_of_section(vh, 0.0, STARTS, 3, **kw,
                                     run=tso.Run(client=client, chunk_size=1))
    assert got.perturbations == (TIDE,)
    assert_same(got, local)
