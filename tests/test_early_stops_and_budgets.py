"""Results that look fine and are not, and runs that never end.

* A member that stopped early (collision, escape, step underflow, step budget) is judged by
  its drift up to the stop: past the limit it is "inaccurate", with what it stopped for kept
  in ``stop_status``, and the command line exits 3 (the loose-tolerance "escapes" and
  "collisions" that were reported as physics).
* Every accepted input finishes in bounded time: spins of an ``InitialState`` are held to the
  bounds of the θ̇ path, a perturbation too strong to be one is refused before any work (with
  the largest strength that is), and a per-member step budget stops a member the integrator
  cannot carry ("step budget") while the rest of the ensemble goes on; the step estimate
  behind the budget and the long-run warning is checked against measured step counts.
"""

import dataclasses
import math
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import cli
from ti_spinorbit.engine import accuracy, cost
from ti_spinorbit.model import perturbations
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.system.initial import tilted_start
from ti_spinorbit.engine.results import STATUS_NAMES, Status

VH = tso.catalog.system("1991 VH")


# ---- the verdict -----------------------------------------------------------------------------

def test_verdict_judges_early_stops_by_their_drift():
    codes = [Status.DONE, Status.COLLISION, Status.ESCAPE, Status.STEP_UNDERFLOW,
             Status.STEP_BUDGET, Status.NONFINITE]
    over = accuracy.verdict(codes, [1e-3] * 6, [1e-9] * 6, 1e-4)
    assert list(over) == [Status.INACCURATE] * 5 + [Status.NONFINITE]
    # the angular momentum alone past the limit is enough
    assert list(accuracy.verdict(codes, [1e-9] * 6, [1e-3] * 6, 1e-4))[:5] == [Status.INACCURATE] * 5
    within = accuracy.verdict(codes, [1e-6] * 6, [1e-6] * 6, 1e-4)
    assert list(within) == codes                      # physical outcomes within the limit kept
    # a NaN drift: "done" cannot pass, an early stop keeps its own status
    nan = accuracy.verdict(codes, [np.nan] * 6, [0.0] * 6, 1e-4)
    assert list(nan) == [Status.NONFINITE] + codes[1:]


def test_loose_tolerance_escapes_are_inaccurate_and_exit_3(tmp_path, capsys):
    argv = ["section", "--eccentricity", "0.6", "--orbits", "200", "--thetadot", "0.3", "0.48",
            "0.66", "0.84", "--quiet"]
    code = cli.main([*argv, "--rtol", "1e-3", "--out", str(tmp_path / "loose.png")])
    err = capsys.readouterr().err
    assert code == cli.EXIT_INACCURATE
    assert "4 of 4 members inaccurate" in err and "4 escape" in err
    r = tso.load(tmp_path / "loose.npz")
    assert r.status_names == ["inaccurate"] * 4
    assert [STATUS_NAMES[s] for s in r.stop_status] == ["escape"] * 4
    assert np.all(r.energy_drift > r.max_drift)
    # the same starts at a tolerance that resolves them stay bound and pass
    assert cli.main([*argv, "--rtol", "1e-10", "--out", str(tmp_path / "tight.png")]) == 0
    tight = tso.load(tmp_path / "tight.npz")
    assert tight.status_names == ["done"] * 4 and list(tight.stop_status) == [Status.DONE] * 4


def test_loose_tolerance_collision_is_inaccurate(tmp_path, capsys):
    code = cli.main(["section", "--system", "2004 DC", "--rtol", "1e-2", "--quiet",
                     "--out", str(tmp_path / "dc.png")])
    err = capsys.readouterr().err
    r = tso.load(tmp_path / "dc.npz")
    collided = r.stop_status == Status.COLLISION
    assert code == cli.EXIT_INACCURATE and "collision" in err
    assert collided.any() and np.all(r.status[collided] == Status.INACCURATE)
    assert np.all(r.energy_drift[collided] > r.max_drift)


def test_time_series_keeps_stop_status():
    ts = tso.time_series(VH, [30.0], [0.8], orbits=2, samples_per_orbit=16, rtol=1e-10)
    assert ts.status_names == ["done"] and list(ts.stop_status) == [Status.DONE]


# ---- spins and strengths a run can carry ---------------------------------------------------

def test_initial_state_spins_are_bounded_as_on_the_thetadot_path():
    start = tilted_start(VH, 30.0, 1.0)
    n = VH.mean_motion
    fast = dataclasses.replace(start, primary_omega=np.array([0.0, 0.0, 1e3]))
    with pytest.raises(ValueError, match=r"primary_omega is 1\.86e\+07 n .* at most 100000 n"):
        tso.surface_of_section(VH, initial_states=[fast], orbits=0.01)
    spinning = dataclasses.replace(start, secondary_omega=np.array([0.0, 0.0, 101.0 * n]))
    with pytest.raises(ValueError, match=r"secondary_omega is 101 n .* at most 100 n"):
        spinning.to_scaled(VH)
    # at the bounds themselves the starts are accepted
    dataclasses.replace(start, primary_omega=np.array([0.0, 0.0, 0.999e5 * n])).to_scaled(VH)
    dataclasses.replace(start, secondary_omega=np.array([0.0, 0.0, 99.9 * n])).to_scaled(VH)


@pytest.mark.parametrize("make", [
    lambda s: tso.YORP(strength=s),
    lambda s: tso.Tides(k2=1e-5, time_lag=600.0, strength=s),
    lambda s: tso.Tides(Q=20.0, strength=s),
    lambda s: tso.BYORP(strength=s),
])
def test_too_strong_a_perturbation_is_refused_with_the_largest_strength(make):
    with pytest.raises(ValueError, match=r"perturbations\[0\] .* no longer be a perturbation; "
                                         r"use a strength of at most") as info:
        perturbations.perturbation_rows([VH], [make(1e15)])
    largest = float(str(info.value).rsplit(" ", 1)[1])
    perturbations.perturbation_rows([VH], [make(largest * 0.99)])   # just inside: accepted
    with pytest.raises(ValueError):
        perturbations.perturbation_rows([VH], [make(largest * 1.02)])


def test_the_documented_examples_stay_inside_the_strength_limits():
    # the README's tide and the strengths the perturbation studies use
    for p in (tso.Tides(k2=1e-5, time_lag=600.0, strength=1e6), tso.YORP(strength=1e6),
              tso.BYORP(strength=1e6), tso.Tides(strength=1e7)):
        for system in (VH, tso.catalog.system("2004 DC")):
            perturbations.perturbation_rows([system], [p])


def test_yorp_spin_change_per_orbit_is_the_torque_the_run_delivers():
    """change_per_orbit's YORP figure against the external angular momentum the kernels
    integrate over one orbit: ΔL = T P, so ΔL / (C n) = 2π T / (C n²)."""
    yorp = tso.YORP(strength=1e6, distance="mean")     # change_per_orbit's mean distance
    (_, predicted, _, _), = perturbations.change_per_orbit(yorp, VH)
    ts = tso.time_series(VH, [30.0], [0.8], orbits=1, samples_per_orbit=8, rtol=1e-12,
                         perturbations=[yorp])
    delivered = np.linalg.norm(ts.external_angmom[0, -1])
    C = float(np.max(VH.secondary.moments))
    assert delivered / (C * VH.mean_motion) == pytest.approx(predicted, rel=1e-9)


# ---- the step budget -----------------------------------------------------------------------

def _members(thetadots):
    from ti_spinorbit.engine.members import Members
    table = Members.from_starts(VH, [30.0] * len(thetadots), thetadots, 50.0)
    return table.par, table.y0


def test_step_budget_stops_one_member_and_the_rest_goes_on():
    par, y0 = _members([0.8, 0.8])
    t_stop = 2.0 * np.pi * np.array([2.0, 20.0])
    free = Ensemble(par, y0, rtol=1e-10).run(t_stop)
    assert list(free.status) == [Status.DONE, Status.DONE]
    budget = int(free.counters[0, :2].sum()) + 50     # member 0 fits, member 1 does not
    capped = Ensemble(par, y0, rtol=1e-10).run(t_stop, max_steps=budget)
    assert list(capped.status) == [Status.DONE, Status.STEP_BUDGET]
    assert capped.counters[1, :2].sum() == budget and capped.t[1] < t_stop[1]
    # nothing lost, nothing changed: member 0 as without a budget, member 1's crossings the
    # first ones of its free run, bit for bit
    assert np.array_equal(capped.events[0], free.events[0])
    k = len(capped.events[1])
    assert 0 < k < len(free.events[1])
    assert np.array_equal(capped.events[1], free.events[1][:k])


def test_step_budget_resumes_bit_for_bit(tmp_path):
    par, y0 = _members([0.8])
    t_stop = 2.0 * np.pi * 40.0
    whole = Ensemble(par, y0, rtol=1e-10).run(t_stop, max_steps=2500)

    class Stop(Exception):
        pass

    calls = []

    def interrupt(fraction):
        calls.append(fraction)
        if len(calls) == 2:
            raise Stop

    with pytest.raises(Stop):
        Ensemble(par, y0, rtol=1e-10).run(t_stop, max_steps=2500, window_orbits=1,
                                          progress=interrupt, checkpoint=tmp_path / "c")
    resumed = Ensemble(par, y0, rtol=1e-10).run(t_stop, max_steps=2500, window_orbits=1,
                                                checkpoint=tmp_path / "c", resume=True)
    assert list(resumed.status) == [Status.STEP_BUDGET] == list(whole.status)
    assert np.array_equal(resumed.y, whole.y) and np.array_equal(resumed.t, whole.t)
    assert np.array_equal(resumed.events[0], whole.events[0])
    assert np.array_equal(resumed.counters, whole.counters)


def test_budget_stops_are_judged_and_the_cli_exits_3(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(cost, "BUDGET_FACTOR", 0.0)
    monkeypatch.setattr(cost, "BUDGET_FLOOR", 400)
    code = cli.main(["section", "--orbits", "5", "--thetadot", "0.8", "--quiet",
                     "--out", str(tmp_path / "b.png")])
    err = capsys.readouterr().err
    r = tso.load(tmp_path / "b.npz")
    assert r.status_names == ["step budget"] and code == cli.EXIT_INACCURATE
    assert "1 of 1 members stopped by the step budget" in err
    assert r.accepted[0] + r.rejected[0] == 400 and r.count[0] >= 1


# ---- the estimate behind them ----------------------------------------------------------------

@pytest.mark.parametrize("method", ["cash-karp", "dop853", "vern9"])
def test_step_estimate_bounds_the_measured_steps(method):
    """The estimate is an upper bound within a factor of eight of the steps a run takes, for a
    slow and a fast (15 n) primary, e = 0.05 and 0.3, two tolerances: far inside the budget's
    factor of 100, and a wrong exponent or spin term would leave the band."""
    from ti_spinorbit.engine.members import Members
    for name in ("1991 VH", "2004 DC", "test"):
        system = tso.catalog.system(name)
        for rtol in (1e-8, 1e-12):
            table = Members.from_starts(system, [30.0, 60.0], [0.5, 1.2], 50.0)
            par, y0 = table.par, table.y0
            r = tso.surface_of_section(system, [30.0, 60.0], [0.5, 1.2], orbits=2, rtol=rtol,
                                       method=method)
            measured = (r.accepted + r.rejected) / 2.0
            ratio = cost.steps_per_orbit(par, y0, rtol, method) / measured
            assert np.all((ratio >= 1.0) & (ratio <= 8.0)), (name, rtol, ratio)


def test_cost_exponents_are_the_methods_error_exponents():
    from ti_spinorbit.kernels.tableau import METHODS
    assert set(cost.METHOD_COST) == set(METHODS)
    for name, (_, exponent) in cost.METHOD_COST.items():
        assert exponent == pytest.approx(METHODS[name].error_exponent, rel=1e-15)


def test_a_long_run_warns_before_it_starts(monkeypatch):
    with pytest.warns(cost.LongRunWarning, match=r"estimated 1\.3e\+10 integration steps"):
        cost.check_cost("a map", np.full(1000, 1.3e3), 1e4)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cost.check_cost("a map", np.full(1000, 1.3e3), 1e3)
    monkeypatch.setattr(cost, "LONG_RUN_STEPS", 10.0)
    with pytest.warns(cost.LongRunWarning):
        tso.surface_of_section(VH, [30.0], [0.8], orbits=0.1)


def test_step_budget_is_bounded_for_every_accepted_run():
    est = np.array([300.0, 1e4])
    assert cost.step_budget(est, 10.0) == int(cost.BUDGET_FACTOR * 1e5 + cost.BUDGET_FLOOR)
    assert cost.step_budget(est, 0.01) == int(cost.BUDGET_FACTOR * 1e4 + cost.BUDGET_FLOOR)
    assert math.isfinite(cost.step_budget(np.array([1e300]), 1e7))
    # a member without an estimate (a NaN start, stopped at once) leaves the others' budget
    assert cost.step_budget(np.array([300.0, np.nan]), 10.0) == cost.step_budget(est[:1], 10.0)
    assert cost.check_cost("x", np.array([300.0, np.nan]), 10.0) == 3000.0
