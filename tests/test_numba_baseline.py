"""The benchmark's compiled DOP853 baseline (experiments/_numba_dop853.py, numba) integrates the
same equations as the planar kernels: its independently written right-hand side equals the
package's to round-off, and its trajectories meet the kernels' at a tight tolerance."""

import os
import sys

import numpy as np
import pytest

pytest.importorskip("numba")

from ti_spinorbit.model import planar as PL  # noqa: E402
from ti_spinorbit.engine.ensemble import Ensemble  # noqa: E402
from ti_spinorbit.kernels import advance as K  # noqa: E402
from ti_spinorbit.engine.members import Members  # noqa: E402

EXPERIMENTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                           "experiments")
sys.path.insert(0, EXPERIMENTS)
import _numba_dop853 as nb  # noqa: E402
import bench_throughput as bt  # noqa: E402

sys.path.remove(EXPERIMENTS)

# the slow part of the suite: deselect with -m "not slow" (README, its first lines)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def members(taichi_runtime):
    import ti_spinorbit as tso
    system = tso.catalog.system("1991 VH", elongation=1.5)
    table = Members.from_starts(system, [0.0, 45.0, 120.0], [0.8, 1.3, 2.1], 1000.0)
    par, y0 = table.par, table.y0
    return par, y0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_rhs_equals_the_package_planar_rhs(members, seed):
    par, _ = members
    kpar = PL.parameter_rows(par)[[0]].repeat(64, axis=0)
    q = bt.random_planar_states(64, seed)
    expected, got = np.zeros_like(q), np.zeros_like(q)
    K.PLANAR.evaluate_rhs(kpar, q, expected, 4, False)
    nb.rhs_many(kpar, q, got)
    scale = np.abs(expected).max(axis=0)
    assert np.all(scale > 0)
    assert np.max(np.abs(got - expected) / scale) < 1e-14


def test_trajectories_meet_the_kernels_at_tight_tolerance(members):
    par, y0 = members
    kpar, q0 = PL.parameter_rows(par), PL.to_planar(y0)
    y, counters = np.zeros_like(q0), np.zeros((len(q0), 3), dtype=np.int64)
    nb.integrate_many(kpar, q0, 2 * np.pi, 1e-14, 1e-14, y, counters)
    kernel = Ensemble(par, y0, rtol=1e-14, model="planar").run(2 * np.pi)
    assert np.max(np.abs(PL.to_spatial(y) - kernel.y)) < 1e-10
    # 12 RHS calls per step (FSAL) plus the two of the first-step choice
    np.testing.assert_array_equal(counters[:, 2], 12 * counters[:, :2].sum(axis=1) + 2)


def test_refuses_odd_rows():
    row = np.zeros((1, 37))
    row[0, 12] = 1e-3                                    # an order-3 coefficient
    with pytest.raises(ValueError, match="odd inertia integrals"):
        nb.check_even(row)


def test_benchmark_skips_a_method_the_package_refuses(members):
    assert bt.method_unavailable("cash-karp") is None       # the default: never passed by keyword
    why = bt.method_unavailable("no-such-method")
    assert isinstance(why, str) and "\n" not in why
    assert "Ensemble(method='no-such-method') refused" in why


@pytest.mark.parametrize("method,passed", [("cash-karp", {}), ("dop853", {"method": "dop853"})])
def test_benchmark_passes_method_only_when_not_the_default(monkeypatch, members, method, passed):
    """``method=`` reaches Ensemble only for a non-default method, so the benchmark runs on a
    package with and without the keyword."""
    import ti_spinorbit.engine.ensemble as E

    seen = []

    class Recorder:
        def __init__(self, par, y0, **kwargs):
            seen.append(kwargs)

    monkeypatch.setattr(E, "Ensemble", Recorder)
    par, y0 = members
    bt.make_ensemble(par, y0, "planar", 1e-12, method)
    assert seen == [dict(rtol=1e-12, model="planar", **passed)]
