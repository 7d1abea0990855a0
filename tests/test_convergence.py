"""Converged, not finite-time, answers: the overlap threshold against integration length
(doubling, the MEGNO connection criterion, the cap's "not converged" verdict), the relaxed
libration centre and amplitude in orbits and tolerance, and the chaotic fraction of a map
against orbits; the evidence saved and loaded back, and printed by the CLI."""

import json
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.output import io
from ti_spinorbit.studies import libration
from ti_spinorbit.studies.chaosmap import chaos_map, fraction_evidence
from ti_spinorbit.studies.libration import relaxed_libration
from ti_spinorbit.studies.overlap import OverlapScan, _lengths, megno_connects, overlap_threshold

from conftest import run_cli

STARTS = dict(centre_starts=24, separatrix_starts=16)


@pytest.fixture(scope="module")
def doubling():
    """1991 VH at a/b = 1.03 (separate) and 1.05 (connects between 150 and 300 orbits)."""
    return overlap_threshold("1991 VH", elongations=[1.03, 1.05], orbits=150, max_orbits=1200,
                             **STARTS)


def test_converges_at_the_second_doubling(doubling):
    """1.05 connects at 300 orbits, nothing changes at 600: converged at the second doubling,
    the per-length decisions say so, and only the still-separate 1.03 ran at 600."""
    s = doubling
    assert s.lengths.tolist() == [150.0, 300.0, 600.0]
    assert s.overlaps_by_length.tolist() == [[False, False], [False, True], [False, True]]
    assert s.converged and not s.upper_bound and s.converged_orbits == 600.0
    assert s.first_overlap == 1.05 and s.max_orbits == 1200.0
    assert s.message.startswith("converged: decisions at 300 and 600 orbits agree")
    assert [d.orbits for d in s.decisions] == [600.0, 300.0]
    # cost: both elongations at 150 and 300 orbits, then 1.03 alone at 600 (40 starts each)
    assert s.member_orbits == 80 * 150 + 80 * 300 + 40 * 600


def test_megno_criterion_sees_the_layer_first(doubling):
    """At 150 orbits no trajectory has crossed at 1.05, but its chaotic layer already spans
    both islands; at 1.03 neither criterion connects at any length."""
    assert doubling.megno_overlaps_by_length[:, 1].tolist() == [1, 1, 1]
    assert doubling.megno_overlaps_by_length[:, 0].tolist() == [0, 0, 0]
    assert doubling.megno_first_overlap == 1.05


def test_cap_reports_not_converged_and_an_upper_bound(tmp_path):
    """1991 VH at 1.04 has not connected by 200 orbits while MEGNO already connects: the scan
    stops at the cap, says so, labels the (absent) threshold an upper bound, and the plot
    title says it too."""
    s = overlap_threshold("1991 VH", elongations=[1.04], orbits=100, max_orbits=200, **STARTS)
    assert s.lengths.tolist() == [100.0, 200.0]
    assert not s.converged and s.upper_bound and np.isnan(s.converged_orbits)
    assert s.message.startswith("not converged by 200 orbits: first overlap none in the scan "
                                "is an upper bound")
    assert s.message.endswith("the MEGNO criterion already connects at a/b = 1.04")
    ax = s.plot()
    assert "not converged by 200 orbits (upper bound)" in ax.get_title()
    assert s.evidence()[-1] == s.message


def test_megno_criterion_agrees_with_a_long_geometric_run():
    """1991 VH at a/b = 1.04: at 150 orbits the geometric rule sees no connection yet, the
    MEGNO criterion does; 2400 orbits later a trajectory has crossed both island levels."""
    kw = dict(elongations=[1.04], centre_starts=16, separatrix_starts=16)
    short = overlap_threshold("1991 VH", orbits=150, max_orbits=150, **kw).decisions[0]
    long = overlap_threshold("1991 VH", orbits=2400, max_orbits=2400, **kw).decisions[0]
    assert (short.overlap, short.megno_overlap) == (False, True)
    assert long.overlap is True and long.connecting_megno > 4


@pytest.mark.parametrize("lo, hi, megno, expected", [
    ([0.6, 1.3], [1.4, 1.7], [20.0, 15.0], True),       # two chaotic ranges chain c1 .. c3/2
    ([0.6, 1.45], [1.4, 1.7], [20.0, 15.0], False),     # a gap between them
    ([0.6, 1.3], [1.4, 1.7], [20.0, 2.0], False),       # the upper one is regular
    ([0.5], [1.8], [3.0], False),                       # wide but not chaotic
    ([0.6, 1.3], [1.4, 1.7], [np.nan, np.nan], None),   # indicators off
])
def test_megno_connects(lo, hi, megno, expected):
    assert megno_connects(np.array(lo), np.array(hi), np.array(megno), 0.97, 1.55) is expected


@pytest.mark.parametrize("orbits, cap, expected", [
    (100, 400, [100.0, 200.0, 400.0]), (100, 100, [100.0]), (100, 300, [100.0, 200.0, 300.0])])
def test_doubling_lengths(orbits, cap, expected):
    assert _lengths(orbits, cap) == expected


@pytest.mark.parametrize("cap", [50, "400", float("nan"), 2e7])
def test_max_orbits_out_of_range_is_named(cap):
    with pytest.raises(ValueError, match=r"max_orbits must be a number in \[orbits, 1e7\]"):
        overlap_threshold("1991 VH", elongations=[1.04], orbits=100, max_orbits=cap)


def test_overlap_evidence_saved_and_loaded(doubling, tmp_path):
    path = io.save(doubling, tmp_path / "scan.npz")
    back = io.load(path)
    assert back.lengths.tolist() == doubling.lengths.tolist()
    assert np.array_equal(back.overlaps_by_length, doubling.overlaps_by_length)
    assert np.array_equal(back.megno_overlaps_by_length, doubling.megno_overlaps_by_length)
    assert (back.converged, back.converged_orbits, back.message, back.member_orbits) == \
        (True, 600.0, doubling.message, doubling.member_orbits)
    assert [d.megno_overlap for d in back.decisions] == [False, True]
    units = io.read_metadata(path)["units"]
    assert units["lengths"] == "orbital periods" and units["overlaps_by_length"].startswith("bool")


def test_scan_without_evidence_loads_with_defaults(doubling, tmp_path):
    """A scan saved before the evidence existed (no such fields) loads: not converged."""
    old = OverlapScan(name="x", eccentricity=0.05, elongations=np.array([1.03]),
                      overlaps=np.array([False]), decisions=doubling.decisions[:1],
                      first_overlap=None, omega0_ro=0.35, elongation_ro=1.04, orbits=600.0)
    back = io.load(io.save(old, tmp_path / "old.npz"))
    assert back.lengths is None and back.converged is False and back.message == ""
    assert back.evidence() == ["x: one length (600 orbits), convergence not checked"]


@pytest.fixture(scope="module")
def decoupled():
    return tso.BinarySystem(tso.Sphere(1000, 2000), tso.Ellipsoid(26, 20, 15, 2000), a=50000.0,
                            e=0.01)


@pytest.fixture(scope="module")
def checked(decoupled):
    return relaxed_libration(decoupled, orbits=30, max_orbits=60, rtol=1e-9, xtol=1e-5)


def test_libration_converged_in_orbits_and_tolerance(checked):
    r = checked
    assert r.converged and r.search_converged and r.convergence_checked
    assert r.converged_in_orbits and r.converged_in_tolerance
    assert r.lengths.tolist() == [30.0, 60.0] and r.rtol_check == pytest.approx(1e-10)
    assert abs(r.centres_by_length[1] - r.centres_by_length[0]) <= r.centre_tol == 1e-4
    assert abs(r.amplitude_rtol_check - r.amplitudes_by_length[-1]) <= r.amplitude_tol
    assert r.message == ("converged: centre and amplitude agree at 30 and 60 orbits and at "
                         "rtol 1e-09 and 1e-10")


def test_libration_tolerance_check_can_fail(decoupled, monkeypatch):
    """A centre that moves when rtol is divided by 10 makes the result not converged, and
    the message says it is the tolerance."""
    real = libration._search

    def shifted(system, orbits, rtol, *args, **kwargs):
        out = real(system, orbits, rtol, *args, **kwargs)
        if rtol < 1e-9:
            out.centre_thetadot_p += 1e-3
        return out

    monkeypatch.setattr(libration, "_search", shifted)
    r = relaxed_libration(decoupled, orbits=30, max_orbits=60, rtol=1e-9, xtol=1e-5)
    assert r.converged_in_orbits and not r.converged_in_tolerance and not r.converged
    assert "not converged in tolerance: rtol 1e-10 moves the centre by 0.001 n" in r.message


def test_libration_cap_without_doubling_is_not_converged(decoupled):
    with warnings.catch_warnings():
        warnings.simplefilter("error")        # the verdict is in the result, not a warning
        r = relaxed_libration(decoupled, orbits=30, max_orbits=30, rtol=1e-9, xtol=1e-5)
    assert not r.converged and r.search_converged
    assert r.message.startswith("not converged by 30 orbits")


def test_libration_evidence_saved_and_loaded(checked, tmp_path):
    back = io.load(io.save(checked, tmp_path / "lib.npz"))
    assert np.array_equal(back.centres_by_length, checked.centres_by_length)
    assert np.array_equal(back.amplitudes_by_length, checked.amplitudes_by_length)
    assert (back.converged, back.message, back.rtol_check) == \
        (True, checked.message, checked.rtol_check)


def test_chaotic_fraction_against_orbits(tmp_path):
    vh = tso.catalog.system("1991 VH")
    cmap = chaos_map(vh, [10.0, 90.0], [0.9, 1.2, 1.5, 2.0], 40)
    assert cmap.fraction_lengths.tolist() == [10.0, 20.0, 40.0]
    assert cmap.fraction_by_length[-1] == cmap.chaotic_fraction
    diffs = np.diff(cmap.fraction_by_length)
    assert cmap.fraction_monotone == bool(np.all(diffs >= 0))
    assert ("never decreases" if cmap.fraction_monotone else "NOT monotone") in \
        cmap.fraction_message
    back = io.load(io.save(cmap, tmp_path / "m.npz"))
    assert np.array_equal(back.fraction_by_length, cmap.fraction_by_length)
    assert back.fraction_message == cmap.fraction_message


@pytest.mark.parametrize("fractions, monotone, words", [
    ([0.1, 0.2, 0.25], True, "never decreases; the last step adds +0.050"),
    ([0.1, 0.3, 0.2], False, "NOT monotone"),
])
def test_fraction_evidence(fractions, monotone, words):
    out = fraction_evidence([10.0, 20.0, 40.0], fractions)
    assert out["fraction_monotone"] is monotone and words in out["fraction_message"]


def test_fraction_orbits_out_of_range_is_named():
    with pytest.raises(ValueError, match=r"fraction_orbits must hold lengths in \(0, orbits\)"):
        chaos_map(tso.catalog.system("1991 VH"), [10.0], [1.0], 40, fraction_orbits=[50.0])


def test_cli_overlap_prints_the_verdict(tmp_path):
    """Not converged is not an error: exit 0, the message on stdout and in the metadata."""
    p = run_cli("overlap", "--system", "1991 VH", "--elongations", "1.04", "1.04", "0.01",
                "--orbits", "100", "--max-orbits", "200", "--out", "o.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert "not converged by 200 orbits" in p.stdout and "is an upper bound" in p.stdout
    assert "     100     .m" in p.stdout and "     200     .m" in p.stdout
    meta = io.read_metadata(tmp_path / "o.npz")
    assert meta["converged"] is False and meta["convergence"].startswith("not converged by 200")
    assert json.dumps(meta)          # plain JSON


def test_cli_libration_prints_the_evidence(tmp_path):
    p = run_cli("libration", "--system", "1991 VH", "--orbits", "20", "--max-orbits", "40",
                "--xtol", "1e-4", "--out", "l.png", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    assert [line.split()[:2] for line in lines if line.strip().startswith(("20 ", "40 "))] == \
        [["20", "1e-12"], ["40", "1e-12"], ["40", "1e-13"]]
    assert "  converged: centre and amplitude agree at 20 and 40 orbits and at rtol 1e-12 " \
           "and 1e-13" in lines
    meta = io.read_metadata(tmp_path / "l.npz")
    assert meta["converged"] is True and meta["convergence"].startswith("converged: centre")


@pytest.mark.parametrize("flag, value", [("--max-orbits", "50"), ("--max-orbits", "-1")])
def test_cli_max_orbits_range_is_named(tmp_path, flag, value):
    p = run_cli("overlap", "--system", "1991 VH", "--orbits", "100", flag, value,
                "--out", "o.png", cwd=tmp_path)
    assert p.returncode == 2 and "--max-orbits" in p.stderr and not (tmp_path / "o.npz").exists()


def test_parameter_map_fraction_against_orbits(tmp_path):
    pmap = tso.parameter_map("1991 VH", [1.05, 1.3], [0.05], 24, thetadot_p=[0.9, 1.4],
                             theta_p=[90.0])
    assert pmap.fraction_lengths.tolist() == [6.0, 12.0, 24.0]
    assert pmap.fraction_by_length.shape == (3, 2, 1)
    assert np.array_equal(pmap.fraction_by_length[-1], pmap.chaotic_fraction, equal_nan=True)
    drops = np.diff(pmap.fraction_by_length, axis=0) < 0
    assert np.array_equal(pmap.fraction_monotone, ~drops.any(axis=0))
    assert pmap.fraction_message.startswith("chaotic fraction at 6, 12, 24 orbits: ")
    back = io.load(io.save(pmap, tmp_path / "p.npz"))
    assert np.array_equal(back.fraction_by_length, pmap.fraction_by_length, equal_nan=True)
