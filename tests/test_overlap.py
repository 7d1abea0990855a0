"""Resonance-overlap scans: decisions at clearly separated and clearly overlapping
elongations, monotonic in a/b, and the analytic threshold."""

import numpy as np
import pytest

from ti_spinorbit.model import analytic
from ti_spinorbit.studies.overlap import overlap_threshold


@pytest.fixture(scope="module")
def vh_scan():
    return overlap_threshold("1991 VH", elongations=[1.01, 1.03, 1.08], orbits=300,
                             centre_starts=32, separatrix_starts=16)


def test_overlap_decision_and_monotonic(vh_scan):
    """At a/b = 1.01 (ω0 = 0.17, far below ω0^RO = 0.35) the resonances are separate; at 1.08
    (ω0 = 0.48) they overlap; the decision switches once."""
    assert vh_scan.overlaps.tolist()[0] is False and vh_scan.overlaps.tolist()[-1] is True
    assert vh_scan.monotonic
    d = vh_scan.decisions[-1]
    lo, hi = d.connecting_range
    assert lo <= d.centre_1 and hi >= d.centre_3_2          # the evidence says what it claims
    assert d.connecting_megno > 4 and d.connecting_lyapunov > 0.05   # and it is chaotic
    assert 0.9 < d.centre_1 < 1.1 and 1.4 < d.centre_3_2 < 1.7
    sep = vh_scan.decisions[0]
    assert sep.connecting_start is None and sep.widest_range[1] < sep.centre_3_2


def test_analytic_threshold_reported(vh_scan):
    assert vh_scan.omega0_ro == pytest.approx(1 / (2 + np.sqrt(14 * 0.05)))
    assert analytic.omega0(vh_scan.elongation_ro) == pytest.approx(vh_scan.omega0_ro)
    # the numerical threshold lies between the separated and overlapping samples
    assert 1.01 < vh_scan.first_overlap <= 1.08


def test_bad_inputs():
    with pytest.raises(ValueError, match="unknown system"):
        overlap_threshold("1991 XX", elongations=[1.1])
    with pytest.raises(ValueError, match="elongations"):
        overlap_threshold("1991 VH", elongations=[0.9])


def test_eccentricity_with_a_factory_is_refused_not_ignored():
    """A factory sets its systems' e: eccentricity= beside it was silently ignored."""
    from ti_spinorbit.system import catalog

    factory = lambda q: catalog.system("1991 VH", elongation=q)  # noqa: E731
    with pytest.raises(TypeError, match=r"eccentricity=0\.3 applies to a catalogue name"):
        overlap_threshold(factory, elongations=[1.1], eccentricity=0.3, orbits=2)
    mixed = lambda q: catalog.system("1991 VH", elongation=q, eccentricity=q - 1.0)  # noqa: E731
    with pytest.raises(ValueError, match="the same eccentricity"):
        overlap_threshold(mixed, elongations=[1.1, 1.2], orbits=2)
    with pytest.raises(TypeError, match="must return a BinarySystem"):
        overlap_threshold(lambda q: "1991 VH", elongations=[1.1], orbits=2)


def test_eccentricity_reaches_a_named_scan():
    scan = overlap_threshold("1991 VH", elongations=[1.1], eccentricity=0.2, orbits=2,
                             max_orbits=2, centre_starts=2, separatrix_starts=2)
    assert scan.eccentricity == 0.2
    assert scan.omega0_ro == pytest.approx(analytic.omega0_overlap(0.2), rel=1e-15)


def test_overlap_vs_eccentricity_reports_per_e():
    from ti_spinorbit.studies.overlap import overlap_vs_eccentricity
    ecc, first, analytic_ab, scans = overlap_vs_eccentricity(
        "2004 DC", [0.1, 0.3], elongations=[1.01, 1.06], orbits=150, centre_starts=24,
        separatrix_starts=12)
    assert len(scans) == 2 and ecc.tolist() == [0.1, 0.3]
    assert analytic_ab[1] < analytic_ab[0]                   # overlap comes earlier at higher e
    assert all(s.monotonic for s in scans)
    assert scans[1].overlaps[-1]                             # a/b = 1.06 at e = 0.3: overlap
