"""``method=``: Cash-Karp 4(5) (default), DOP853 8(5,3) and Verner 9(8) in the ensemble
kernels (the high-order pairs through the same tests, parametrised).

* accuracy at equal rtol: the error of DOP853 and of Verner's pair against a tight reference
  (Cash-Karp at 1e-15) is no larger than Cash-Karp's, with fewer right-hand-side evaluations;
* pericentre events, samples and chaos indicators agree between the methods;
* conservation; the planar and 3-D models agree with each high-order pair;
* the choice is validated, recorded in results, saved files and checkpoints (a checkpoint
  refuses to resume with another method), and reachable from the command line.
"""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.engine.checkpoint import CheckpointError
from ti_spinorbit.engine.ensemble import Ensemble

from conftest import run_cli

ORBITS = 5
T_STOP = 2.0 * np.pi * ORBITS
SPINS = (0.9, 1.3, 2.1, 0.5)
HIGH_ORDER = ("dop853", "vern9")


@pytest.fixture(scope="module")
def members(vh):
    par = np.stack([vh.parameter_row()] * len(SPINS))
    y0 = np.stack([vh.initial_state(0.0, w) for w in SPINS])
    return par, y0


def _run(members, method, rtol, model="planar", **kw):
    return Ensemble(*members, rtol=rtol, model=model, method=method).run(T_STOP, **kw)


@pytest.fixture(scope="module")
def reference(members):
    return _run(members, "cash-karp", 1e-15)


@pytest.mark.parametrize("method, rtol, call_ratio", [("dop853", 1e-9, 0.9),
                                                      ("dop853", 1e-12, 0.6),
                                                      ("vern9", 1e-9, 0.8),
                                                      ("vern9", 1e-12, 0.4)])
def test_high_order_is_at_least_as_accurate_with_fewer_evaluations(members, reference, method,
                                                                   rtol, call_ratio):
    """Measured (5 orbits, 4 members): at 1e-9 errors 7.4e-7 (CK), 1.5e-7 (DOP853), 1.0e-7
    (Verner) with 0.83x and 0.71x CK's RHS calls; at 1e-12 7.4e-10, 1.8e-10, 9.7e-11 with
    0.41x and 0.30x."""
    runs = {m: _run(members, m, rtol) for m in ("cash-karp", method)}
    err = {m: np.max(np.abs(r.y - reference.y)) for m, r in runs.items()}
    calls = {m: r.counters[:, 2].sum() for m, r in runs.items()}
    assert all((r.status == 1).all() for r in runs.values())
    assert err[method] <= err["cash-karp"], err
    assert err[method] < 1e3 * rtol, err
    assert calls[method] < call_ratio * calls["cash-karp"], calls


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_events_agree_between_methods(members, reference, method):
    """Pericentre times and states at rtol 1e-12 match the tight reference to 1e-8 (the
    state error grows along the run as above), with the same number of crossings."""
    dop = _run(members, method, 1e-12)
    for ev, ref in zip(dop.events, reference.events):
        assert ev.shape == ref.shape and len(ev) >= ORBITS - 1
        assert np.max(np.abs(ev - ref)) < 1e-8


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_samples_and_indicators_work_with_high_order(members, method):
    """Sample times land exactly on the grid; MEGNO agrees with Cash-Karp's; the shadow does
    not change the main trajectory."""
    dt = 2.0 * np.pi / 8
    ck = _run(members, "cash-karp", 1e-11, sample_dt=dt, indicators=True)
    dop = _run(members, method, 1e-11, sample_dt=dt, indicators=True)
    plain = _run(members, method, 1e-11, sample_dt=dt)
    for s, s_ck in zip(dop.samples, ck.samples):
        assert np.array_equal(s[:, 0], s_ck[:, 0])              # the grid, exactly
        assert np.max(np.abs(s[:, 1:] - s_ck[:, 1:])) < 1e-7
    assert np.array_equal(dop.y, plain.y)
    assert np.all(np.isfinite(dop.megno))
    assert np.allclose(dop.megno, ck.megno, atol=0.05), (dop.megno, ck.megno)


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_energy_is_conserved_with_high_order(members, method):
    out = Ensemble(*members, rtol=1e-12, model="planar", method=method)
    run = out.run(T_STOP)
    e0 = run.diag_start[:, :3].sum(axis=1)
    e1 = run.diag_end[:, :3].sum(axis=1)
    assert np.max(np.abs((e1 - e0) / e0)) < 1e-10


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_planar_and_3d_agree_with_high_order(members, method):
    """The 3-D kernel with each high-order pair (one variant compiled: no sampling, no
    indicators; about 20 s cold for Verner's)."""
    planar = _run(tuple(a[:2] for a in members), method, 1e-12)
    spatial = _run(tuple(a[:2] for a in members), method, 1e-12, model="3d")
    assert (spatial.status == 1).all()
    assert np.max(np.abs(spatial.y - planar.y)) < 1e-8
    for a, b in zip(spatial.events, planar.events):
        assert a.shape == b.shape and np.max(np.abs(a - b)) < 1e-8


@pytest.mark.parametrize("method", ["rk45", "DOP853", None, 8])
def test_unknown_method_is_refused(members, method):
    with pytest.raises(ValueError,
                       match=r"^method must be one of 'cash-karp', 'dop853', 'vern9' \(got"):
        Ensemble(*members, method=method)


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_results_and_files_record_the_method(vh, tmp_path, method):
    res = tso.surface_of_section(vh, 0.0, [1.3], orbits=2, rtol=1e-10, method=method)
    assert res.method == method
    path = tso.output.io.save(res, tmp_path / "s.npz")
    assert tso.output.io.load(path).method == method
    assert tso.output.io.read_metadata(path)["method"] == method
    default = tso.surface_of_section(vh, 0.0, [1.3], orbits=2, rtol=1e-10)
    assert default.method == "cash-karp"


@pytest.mark.parametrize("written, resumed", [("cash-karp", "dop853"), ("cash-karp", "vern9"),
                                              ("vern9", "dop853")])
def test_checkpoint_refuses_another_method(members, tmp_path, written, resumed):
    ck = tmp_path / "ck"
    Ensemble(*members, rtol=1e-10, model="planar", method=written).run(T_STOP, checkpoint=ck,
                                                                       keep_checkpoint=True)
    with pytest.raises(CheckpointError,
                       match=rf"method \(checkpoint '{written}', now '{resumed}'\)"):
        Ensemble(*members, rtol=1e-10, model="planar", method=resumed).run(
            T_STOP, checkpoint=ck, resume=True)


class _Stop(Exception):
    pass


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_high_order_resume_equals_uninterrupted(members, tmp_path, method):
    """Interrupted after two windows (the checkpoint is written before progress is called),
    resumed: the same bits as an uninterrupted run."""
    whole = _run(members, method, 1e-10, window_orbits=1)
    calls = []

    def stop_after_two(fraction):
        calls.append(fraction)
        if len(calls) == 2:
            raise _Stop

    ck = tmp_path / "ck"
    with pytest.raises(_Stop):
        _run(members, method, 1e-10, window_orbits=1, checkpoint=ck, progress=stop_after_two)
    resumed = _run(members, method, 1e-10, window_orbits=1, checkpoint=ck, resume=True)
    assert 0.0 < calls[-1] < 1.0
    for name in ("y", "t", "counters"):
        assert np.array_equal(getattr(resumed, name), getattr(whole, name)), name
    for a, b in zip(resumed.events, whole.events):
        assert np.array_equal(a, b)


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_entry_points_forward_the_method(vh, method):
    """chaos_map and libration_amplitude pass method= down to every launch."""
    cmap = tso.chaos_map(vh, [0.0, 90.0], [1.3], orbits=2, method=method, fraction_orbits=())
    assert cmap.method == method and cmap.section.method == method
    amp = {m: tso.libration_amplitude(vh, [0.95], orbits=2, samples_per_orbit=32, rtol=1e-11,
                                      method=m) for m in ("cash-karp", method)}
    assert np.all(np.isfinite(amp[method]))
    assert np.allclose(amp[method], amp["cash-karp"], atol=1e-5), amp


@pytest.mark.parametrize("method", HIGH_ORDER)
def test_cli_method_flag(tmp_path, method):
    p = run_cli("section", "--system", "1991 VH", "--thetadot", "1.3", "--orbits", "2",
                "--method", method, "--quiet", "--out", str(tmp_path / "s.png"), cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert tso.output.io.read_metadata(tmp_path / "s.npz")["method"] == method
    bad = run_cli("section", "--method", "rk4", cwd=tmp_path)
    assert bad.returncode == 2 and "--method: invalid choice: 'rk4'" in bad.stderr


def test_warmup_knows_every_method():
    # compiling keeps its own copy of the names so that importing the package stays free of
    # the kernel modules: it must list the same methods
    from ti_spinorbit.engine.compiling import METHODS
    from ti_spinorbit.kernels.tableau import METHODS as kernel_methods
    assert tuple(METHODS) == tuple(kernel_methods)


@pytest.mark.parametrize("method, stages", [("cash-karp", 6), ("dop853", 12), ("vern9", 16)])
@pytest.mark.parametrize("indicators", [False, True])
def test_first_stage_is_evaluated_inside_the_integrator(members, monkeypatch, method, stages,
                                                        indicators):
    """A fresh run's first stage comes from the integrator's own first pass (no separate
    right-hand-side kernel), and is counted once, as before: one step that lands on a tiny
    end time costs 1 (start) + (stages - 1) + 1 (the derivative at the end) evaluations, and
    the shadow adds its stages and end point but not its start."""
    from ti_spinorbit.kernels import advance as K

    ens = Ensemble(*members, rtol=1e-10, model="planar", method=method)

    def refuse(*args):
        raise AssertionError("a fresh run launched evaluate_rhs")

    monkeypatch.setattr(ens.kernels, "evaluate_rhs", refuse)
    out = ens.run(1e-6, indicators=indicators)
    assert (out.status == 1).all()
    np.testing.assert_array_equal(out.counters[:, K.C_ACCEPTED], 1)
    np.testing.assert_array_equal(out.counters[:, K.C_REJECTED], 0)
    shadow = stages if indicators else 0
    np.testing.assert_array_equal(out.counters[:, K.C_RHS], 1 + stages + shadow)
