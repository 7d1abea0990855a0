"""Scale-out over Dask (ti_spinorbit.studies.distributed): chunked runs on worker processes give the
single-process result bit for bit, in member order; failed chunks are retried, and a chunk
that keeps failing raises an error naming it.

One two-worker LocalCluster for the module (processes, one thread each, CPU Taichi). The
workers keep Taichi's default settings so that they share offline-cache entries with the test
process (a different cpu_max_num_threads would compile everything again)."""

import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.studies import distributed as tsd
from ti_spinorbit.studies.chaosmap import chaos_map, parameter_map
from ti_spinorbit.studies.overlap import overlap_threshold, overlap_vs_eccentricity
from ti_spinorbit.studies.section import SectionResult

from conftest import lumpy_body, run_options

pytest.importorskip("distributed")

# the slow part of the suite: deselect with -m "not slow" (README, its first lines)
pytestmark = pytest.mark.slow

THETA_P = np.array([0.0, 45.0, 90.0])
THETADOT_P = np.array([0.5, 0.9, 1.3, 2.5])
ORBITS = 4
RTOL = 1e-9


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    env = {"TI_SPINORBIT_ARCH": "cpu"}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None, env=env) as cluster, Client(cluster) as c:
        yield c


@pytest.fixture(scope="module")
def vh_local(vh):
    return chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=RTOL)


def sections(client, *args, **kw):
    """surface_of_section on the cluster, its run options (chunk_size, retries, ...) given as
    keywords."""
    return tso.surface_of_section(*args, **run_options(client=client, **kw))


def assert_sections_equal(got, want):
    """Every SectionResult field equal (bit for bit, NaN padding included), but wall time."""
    for f in dataclasses.fields(SectionResult):
        a, b = getattr(got, f.name), getattr(want, f.name)
        if f.name == "seconds":
            assert a > 0
        elif f.name == "systems":
            assert [s.name for s in a] == [s.name for s in b]
            assert all(x.e == y.e and x.a == y.a for x, y in zip(a, b))
        elif isinstance(b, np.ndarray):
            assert isinstance(a, np.ndarray) and a.dtype == b.dtype, f.name
            np.testing.assert_array_equal(a, b, err_msg=f.name)
        else:
            assert a == b, f.name


def test_importing_the_package_does_not_import_dask():
    code = ("import sys, ti_spinorbit, ti_spinorbit.studies.chaosmap, ti_spinorbit.studies.overlap, "
            "ti_spinorbit.studies.distributed; "
            "assert not {'dask', 'distributed'} & set(sys.modules), 'dask imported'")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)


def test_chaos_map_with_client_equals_local(client, vh, vh_local):
    fractions = []
    cmap = chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=RTOL,
                     run=tso.Run(client=client, progress=fractions.append))
    for name in ("theta_p", "thetadot_p", "megno", "lyapunov", "classification", "mean_thetadot",
                 "status"):
        np.testing.assert_array_equal(getattr(cmap, name), getattr(vh_local, name),
                                      err_msg=name)
    assert cmap.chaotic_fraction == vh_local.chaotic_fraction or \
        np.isnan(cmap.chaotic_fraction) and np.isnan(vh_local.chaotic_fraction)
    assert_sections_equal(cmap.section, vh_local.section)
    # default chunking: 12 members, 2 workers -> 3 chunks per worker of 2 members, for each
    # of the three lengths (orbits/4, orbits/2 for the fraction against length, then orbits)
    assert len(fractions) == 18 and np.all(np.diff(fractions) > 0) and fractions[-1] == 1.0
    assert fractions[5] == pytest.approx(1 / 7) and fractions[11] == pytest.approx(3 / 7)


@pytest.mark.parametrize("chunk_size", [1, 5, 12, 100])
def test_uneven_chunks_come_back_in_order(client, vh, vh_local, chunk_size):
    cmap = chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=RTOL,
                     run=tso.Run(client=client, chunk_size=chunk_size))
    np.testing.assert_array_equal(cmap.section.initial_theta_p,
                                  vh_local.section.initial_theta_p)
    np.testing.assert_array_equal(cmap.section.initial_thetadot_p,
                                  vh_local.section.initial_thetadot_p)
    assert_sections_equal(cmap.section, vh_local.section)


def test_chunks_with_different_crossing_counts_are_nan_padded(client):
    """Members that escape early (e = 0.3 beyond 1.1 a) have no crossings, e = 0 members
    have 10: a chunk of escapers is one column wide, and joining pads it with NaN."""
    eccentric = tso.catalog.system("1991 VH", eccentricity=0.3)
    circular = tso.catalog.system("1991 VH", eccentricity=0.0)
    systems = [eccentric] * 3 + [circular] * 3
    kwargs = dict(rtol=RTOL, integrator=tso.Integrator(escape_distance=1.1), indicators=True)
    local = tso.surface_of_section(systems, 0.0, np.linspace(0.5, 2.0, 6), ORBITS, **kwargs)
    assert local.count[:3].max() == 0 and local.count[3:].min() > 1
    got = sections(client, systems, 0.0, np.linspace(0.5, 2.0, 6), ORBITS,
                           chunk_size=3, **kwargs)
    assert_sections_equal(got, local)


def test_parameter_map_with_client_equals_local(client):
    kwargs = dict(elongations=[1.1, 1.4], eccentricities=[0.05], orbits=ORBITS,
                  thetadot_p=[0.7, 1.5], theta_p=[0.0], rtol=RTOL)
    local = parameter_map("1991 VH", **kwargs)
    got = parameter_map("1991 VH", **kwargs, run=tso.Run(client=client, chunk_size=3))
    for name in ("chaotic_fraction", "megno", "classification", "status", "theta_p", "thetadot_p"):
        np.testing.assert_array_equal(getattr(got, name), getattr(local, name), err_msg=name)


def test_overlap_scans_with_client_equal_local(client):
    kwargs = dict(elongations=[1.01, 1.08], orbits=8, rtol=RTOL, centre_starts=6,
                  separatrix_starts=4)
    local = overlap_threshold("1991 VH", **kwargs)
    got = overlap_threshold("1991 VH", **kwargs, run=tso.Run(client=client))
    np.testing.assert_array_equal(got.overlaps, local.overlaps)
    assert got.decisions == local.decisions or all(  # NaN != NaN in the evidence
        str(dataclasses.astuple(a)) == str(dataclasses.astuple(b))   # every field, as text
        for a, b in zip(got.decisions, local.decisions))
    assert_sections_equal(got.sections, local.sections)
    # overlap_vs_eccentricity passes run=Run(client=...) on to every scan
    _, _, _, scans = overlap_vs_eccentricity("1991 VH", [local.eccentricity], **kwargs,
                                             run=tso.Run(client=client))
    assert_sections_equal(scans[0].sections, local.sections)


# --- failures: a fault installed in the workers' section.surface_of_section ---------------

BAD_MEMBER = (45.0, 0.9)   # member 5 of the 3 x 4 grid: chunk 1 of 3 with chunk_size=5


def _install_fault(mode, marker=None):
    """Replace the worker's runner, section_of. ``mode`` "once": chunks holding BAD_MEMBER
    fail while the file ``marker`` exists (the first attempt removes it); "always": they fail
    every time; "report": every chunk fails, naming the model its member table carries."""
    from ti_spinorbit.studies import section

    original = getattr(section, "_unfaulted", section.section_of)

    def faulty(members, *args, **kwargs):
        if mode == "report":
            raise ValueError(f"chunk got model={members.model!r}")
        if np.any((np.asarray(members.theta_p) == BAD_MEMBER[0]) &
                  (np.asarray(members.thetadot_p) == BAD_MEMBER[1])):
            if mode == "always":
                raise ValueError("injected failure, every attempt")
            try:
                os.remove(marker)
            except FileNotFoundError:
                pass
            else:
                raise ValueError("injected failure, first attempt only")
        return original(members, *args, **kwargs)

    section._unfaulted = original
    section.section_of = faulty


def _remove_fault():
    from ti_spinorbit.studies import section

    if hasattr(section, "_unfaulted"):
        section.section_of = section._unfaulted
        del section._unfaulted


@pytest.fixture
def faulty_workers(client):
    yield lambda mode, marker=None: client.run(_install_fault, mode, marker)
    client.run(_remove_fault)


def test_failed_chunk_is_retried(client, vh, vh_local, faulty_workers, tmp_path):
    marker = tmp_path / "fail-once"
    marker.touch()
    faulty_workers("once", str(marker))
    cmap = chaos_map(vh, THETA_P, THETADOT_P, ORBITS, rtol=RTOL,
                     run=tso.Run(client=client, chunk_size=5))
    assert not marker.exists()   # the fault did fire
    assert_sections_equal(cmap.section, vh_local.section)


def test_chunk_failing_every_retry_raises_naming_it(client, vh, faulty_workers):
    faulty_workers("always")
    with pytest.raises(tsd.ChunkError, match=r"chunk 1 of 3 \(members 5\.\.9\) failed after "
                                             r"2 attempts: ValueError: injected") as info:
        sections(client, vh, THETA_P[:, None], THETADOT_P[None, :], ORBITS,
                         chunk_size=5, retries=1, rtol=RTOL, indicators=True)
    assert info.value.chunk == 1 and info.value.members == slice(5, 10)
    assert isinstance(info.value.__cause__, ValueError)


def test_argument_errors(client, vh):
    with pytest.raises(ValueError, match="chunk_size"):
        sections(client, vh, 0.0, 1.0, ORBITS, chunk_size=0)
    with pytest.raises(ValueError, match="retries"):
        sections(client, vh, 0.0, 1.0, ORBITS, retries=-1)
    with pytest.raises(TypeError):
        sections(client, [], 0.0, 1.0, ORBITS)
    # raised on the client, before any chunk is sent (not retried as a ChunkError)
    with pytest.raises(ValueError, match="orbits"):
        sections(client, vh, 0.0, 1.0, 0.0)
    with pytest.raises(ValueError, match="rtol"):
        sections(client, vh, 0.0, 1.0, ORBITS, rtol=0.5)
    with pytest.raises(TypeError, match="rtool"):
        sections(client, vh, 0.0, 1.0, ORBITS, rtool=1e-9)
    with pytest.raises(ValueError, match="checkpoint"):       # chunks would share one file
        sections(client, vh, 0.0, 1.0, ORBITS, checkpoint="run.ckpt")


def test_ensemble_wide_model_choice_is_made_over_all_members(client, rng, faulty_workers):
    """One launch picks its equations for the whole ensemble (the planar model only when
    every member qualifies; planar and 3-D runs differ in the last bits and more). So every
    chunk of an ensemble holding one lumpy, not equator-symmetric, system must be told to use
    the 3-D model, even a chunk of plain ellipsoids that would qualify on its own. (Checked
    on what the chunks receive: integrating the lumpy 3-D kernels costs minutes of compile.)"""
    lumpy = tso.BinarySystem(lumpy_body(rng, scale=300.0, mass=2e12),
                             lumpy_body(rng, scale=100.0, mass=1e11), 3000.0, 0.1, name="lumpy")
    plain = tso.catalog.system("test")
    faulty_workers("report")
    for systems, model in (([lumpy, plain, plain, plain], "3d"), ([plain] * 4, "planar")):
        with pytest.raises(tsd.ChunkError, match=f"chunk got model='{model}'"):
            sections(client, systems, 30.0, [1.0, 0.8, 1.2, 1.6], ORBITS,
                             chunk_size=2, retries=0, rtol=RTOL)


def test_full_space_chaos_map_with_client_equals_local(client, vh):
    """indicator_space="full" makes every chunk use the 3-D model (as one launch would), so
    the map equals the single-process one bit for bit (docs/physics.md §10.4)."""
    kw = dict(rtol=RTOL, indicator_space="full", fraction_orbits=())
    local = chaos_map(vh, THETA_P[:2], THETADOT_P[:2], 2, **kw, run=tso.Run(progress=False))
    remote = chaos_map(vh, THETA_P[:2], THETADOT_P[:2], 2, **kw,
                       run=tso.Run(client=client, chunk_size=2, progress=False))
    assert remote.indicator_space == local.indicator_space == "full"
    assert_sections_equal(remote.section, local.section)


def test_tilted_and_explicit_starts_go_to_the_cluster(client, vh):
    """The Dask runner takes the member table, so every kind of start goes to a cluster:
    a tilted chaos map and explicit 3-D states equal their single-process runs bit for bit
    (they were refused with a client before)."""
    kw = dict(rtol=RTOL, tilt=(5.0, 2.0), fraction_orbits=())
    local = chaos_map(vh, THETA_P[:2], THETADOT_P[:3], 2, **kw, run=tso.Run(progress=False))
    remote = chaos_map(vh, THETA_P[:2], THETADOT_P[:3], 2, **kw,
                       run=tso.Run(client=client, chunk_size=2, progress=False))
    assert remote.section.max_tilt.max() > 1.0           # really out of the plane
    assert_sections_equal(remote.section, local.section)
    starts = [vh.tilted_start(30.0, 1.2, roll=3.0, pitch=0.0),
              vh.tilted_start(60.0, 0.9, roll=0.0, pitch=4.0)]
    alone = tso.surface_of_section(vh, initial_states=starts, orbits=2, rtol=RTOL)
    split = sections(client, vh, None, None, 2, chunk_size=1, rtol=RTOL,
                             initial_states=starts)
    assert_sections_equal(split, alone)


def test_third_bodies_go_to_the_cluster_one_flyby_per_member(client, vh):
    """The Sun (inclined: the 3-D model) and a flyby whose closest distance differs per
    member: chunks of the member table carry each member's own flyby, so the cluster's
    section equals the single-process one bit for bit (work and indicators included)."""
    q = np.linspace(2e5, 6e5, 6)
    perturbations = [tso.SolarTide(inclination_deg=20.0, strength=300.0),
                     tso.Flyby("Earth", v_inf_km_s=5.0, q_km=q, inclination_deg=30.0,
                               t_closest_h=10.0)]
    kw = dict(rtol=RTOL, perturbations=perturbations, indicators=True)
    alone = tso.surface_of_section(vh, 0.0, np.linspace(0.6, 1.6, 6), 2, **kw)
    split = sections(client, vh, 0.0, np.linspace(0.6, 1.6, 6), 2, chunk_size=4, **kw)
    assert_sections_equal(split, alone)
    assert split.perturbations == tuple(perturbations)
