"""One-line messages and sensible limits: a Dask ``client`` that is
not one, a kick of a state whose V is parallel to R, the memory estimate of a time series with
``states=True``, the pole tilt near 0, ``InitialState ==``, the range of ``atol``, a
``parameter_map`` factory returning something else, and ``libration --quiet`` when not
converged."""

import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import cli, layout
from ti_spinorbit.model import attitude
from ti_spinorbit.studies import section
from ti_spinorbit.engine import options
from ti_spinorbit.engine import resources
from ti_spinorbit.engine.ensemble import check_tolerances
from ti_spinorbit.system.initial import InitialState, orbit_frame, quaternion_to_matrix, rotation

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# ---- 1. client= that is not a dask.distributed.Client ---------------------------------------

CLIENT_MESSAGE = r"^client must be a dask\.distributed\.Client or None, not object$"


@pytest.fixture
def no_integration(monkeypatch):
    """Any integration fails the test: the argument must be refused before any work."""
    def forbidden(*args, **kwargs):
        raise AssertionError("integrated although client is not a Client")
    monkeypatch.setattr(section, "surface_of_section", forbidden)
    monkeypatch.setattr(section, "section_of", forbidden)


def test_client_that_is_not_a_client_is_a_one_line_type_error(no_integration):
    """Every entry point takes its client in a Run, which refuses a non-client when made."""
    with pytest.raises(TypeError, match=CLIENT_MESSAGE) as info:
        tso.Run(client=object())
    assert "\n" not in str(info.value)


def test_check_client_names_the_type_given():
    class FakeClient:
        def nthreads(self):
            return {}

    assert options.check_client(None) is None
    with pytest.raises(TypeError, match=r"^client must be a dask\.distributed\.Client or "
                                        r"None, not FakeClient$"):
        options.check_client(FakeClient())
    with pytest.raises(TypeError, match=r", not str$"):
        options.check_client("tcp://127.0.0.1:8786")


# ---- 2. kicked() when V is parallel to R ----------------------------------------------------

def _radial_state(vh, speed, general=True):
    """A state whose V is along R (falling in or moving out along the line of centres), in a
    general direction or along x (R x V then exactly 0), with the paper's attitudes."""
    direction = np.array([1.0, 0.0, 0.0])
    if general:
        direction = rotation(2, 0.7) @ rotation(1, 0.3) @ direction
    start = vh.tilted_start(0.0, 1.0)
    return InitialState(R=vh.a * direction, V=speed * direction,
                        primary_attitude=start.primary_attitude, primary_omega=start.primary_omega,
                        secondary_attitude=start.secondary_attitude,
                        secondary_omega=start.secondary_omega)


@pytest.mark.parametrize("general", [False, True], ids=["along-x", "general"])
@pytest.mark.parametrize("speed", [-0.05, 0.0, 0.02])      # in units of a n
@pytest.mark.parametrize("dv", [0.01, -0.003])             # m/s
def test_radial_kick_of_a_radial_state_is_applied(vh, speed, dv, general):
    v = speed * vh.a * vh.mean_motion
    state = _radial_state(vh, v, general)
    kicked = state.kicked([dv, 0.0, 0.0])
    r_hat = state.R / np.linalg.norm(state.R)
    delta = kicked.V - state.V
    # the velocity changes by exactly dv along R
    np.testing.assert_allclose(delta, dv * r_hat, rtol=0, atol=1e-15 * (abs(v) + abs(dv)))
    assert np.linalg.norm(delta) == pytest.approx(abs(dv), rel=1e-12, abs=0)
    # the kick is radial: the angular momentum is unchanged, the linear momentum of the
    # relative motion changes by m_red dv, the kinetic energy by m_red (v dv + dv^2/2)
    m_red = vh.primary.mass * vh.secondary.mass / vh.total_mass
    spin = np.linalg.norm(state.angular_momentum(vh))
    np.testing.assert_allclose(kicked.angular_momentum(vh), state.angular_momentum(vh),
                               rtol=0, atol=1e-14 * spin)
    assert np.linalg.norm(m_red * (kicked.V - state.V)) == pytest.approx(m_red * abs(dv),
                                                                         rel=1e-12, abs=0)
    kinetic = 0.5 * m_red * (kicked.V @ kicked.V - state.V @ state.V)
    assert kinetic == pytest.approx(m_red * (v * dv + 0.5 * dv * dv), rel=1e-9, abs=1e-30)
    # everything else is untouched
    assert np.array_equal(kicked.R, state.R)
    assert np.array_equal(kicked.secondary_attitude, state.secondary_attitude)
    assert np.all(np.isfinite(kicked.to_row()))


@pytest.mark.parametrize("general", [False, True], ids=["along-x", "general"])
@pytest.mark.parametrize("dv", [[0.0, 0.01, 0.0], [0.01, 0.0, -0.002]])
def test_non_radial_kick_of_a_radial_state_names_dv(vh, dv, general):
    state = _radial_state(vh, -0.05 * vh.a * vh.mean_motion, general)
    with pytest.raises(ValueError, match=r"^dv = \[.*\] m/s has along-track/normal components, "
                                         r"but V is parallel to R \(\|R x V\| = 0: no orbit "
                                         r"plane\), so only a radial kick dv = \(dv_r, 0, 0\) is "
                                         r"defined for this state$"):
        state.kicked(dv)


def test_kick_of_an_ordinary_state_uses_the_orbit_frame(vh):
    state = vh.tilted_start(30.0, 1.2, roll=5.0)
    dv = np.array([0.003, -0.01, 0.002])
    np.testing.assert_allclose(state.kicked(dv).V - state.V,
                               orbit_frame(state.R, state.V) @ dv, rtol=0, atol=1e-15)


# ---- 3. memory estimate with states=True ----------------------------------------------------

def _expected_peak_bytes(members, orbits, samples_per_orbit):
    """The arrays alive together at the peak of a time series with states=True, from their
    shapes (float64): while ``derive`` runs, the records (RECORD_WIDTH columns), their flat
    concatenation and one parameter row per record (NPAR); while the states are built, the
    records, the derived columns (t, alpha, theta, thetadot, r, e, 3 energies, 3 x 3 angular
    momenta: 18), the result columns made before them (t, alpha, theta, r, energy, 3 x 3
    angular momenta: 14), the state rows per member and stacked (2 x 30). The larger phase."""
    rows = members * (math.ceil(orbits) + math.ceil(orbits * samples_per_orbit) + 1)
    w, npar = layout.RECORD_WIDTH, layout.spatial.NPAR
    derive_phase = rows * 8 * (w + w + npar)
    states_phase = rows * 8 * (w + 18 + 14 + 30 + 30)
    return max(derive_phase, states_phase)


@pytest.mark.parametrize("members, orbits, samples_per_orbit",
                         [(4, 500, 64), (1, 2000, 256), (16, 100, 40)])
def test_states_estimate_matches_the_array_shapes(members, orbits, samples_per_orbit):
    expected = _expected_peak_bytes(members, orbits, samples_per_orbit)
    got = resources.estimate_bytes(members, orbits, samples_per_orbit, states=True)
    assert 0.9 * expected <= got <= 1.5 * expected, got / expected
    # the old count (states as a second set of sampled rows) was over twice that
    doubled = resources.estimate_bytes(members, orbits, 2 * samples_per_orbit)
    assert doubled > 2 * expected


def test_time_series_with_states_checks_that_estimate(vh, monkeypatch):
    """time_series(states=True) checks memory with the states counted once (captured before
    any work: the check raises here, so nothing is integrated)."""
    seen = []

    def capture(*args, **kwargs):
        seen.append(resources.estimate_bytes(*args[1:4], width=kwargs["width"],
                                             states=kwargs.get("states", False)))
        raise RuntimeError("captured")

    monkeypatch.setattr(resources, "check_memory", capture)
    with pytest.raises(RuntimeError, match="captured"):
        tso.time_series(vh, 0.0, np.linspace(0.9, 1.3, 4), 500, samples_per_orbit=64,
                        states=True)
    expected = _expected_peak_bytes(4, 500, 64)
    assert len(seen) == 1 and 0.9 * expected <= seen[0] <= 1.5 * expected, seen[0] / expected


def test_states_estimate_within_1_3_of_the_measured_peak():
    """Measured as experiments/memory_estimate.py does (a fresh process, peak RSS growth):
    the estimate was 2.1 x the peak before."""
    sys.path.insert(0, os.path.join(ROOT, "experiments"))
    try:
        import memory_estimate
    finally:
        sys.path.pop(0)
    r = memory_estimate.measure("time_series", dict(members=2, orbits=200,
                                                    samples_per_orbit=256, states=True))
    assert r["growth"] > 50 * 2**20, r
    assert 1.0 / 1.3 <= r["estimate"] / r["growth"] <= 1.3, r


# ---- 4. pole tilt near 0 --------------------------------------------------------------------

@pytest.mark.parametrize("angles", [dict(roll=1.0), dict(pitch=1.0), dict(roll=0.6, pitch=0.8)])
@pytest.mark.parametrize("tilt", [1e-10, 1e-13, 1e-6])
def test_tiny_pole_tilt_is_resolved(vh, angles, tilt):
    # roll r and pitch p (small) tilt the pole by sqrt(r^2 + p^2)
    scale = math.degrees(tilt) / math.hypot(angles.get("roll", 0.0), angles.get("pitch", 0.0))
    state = vh.tilted_start(20.0, 1.0, **{k: v * scale for k, v in angles.items()})
    got = math.radians(float(attitude.pole_tilt(state.to_scaled(vh))))
    assert got == pytest.approx(tilt, rel=1e-3, abs=0)


@pytest.mark.parametrize("deg", [0.0, 30.0, 89.0, 90.0, 135.0, 180.0])
def test_pole_tilt_at_large_angles(vh, deg):
    state = vh.tilted_start(0.0, 1.0, roll=deg)
    assert float(attitude.pole_tilt(state.to_scaled(vh))) == pytest.approx(deg, abs=1e-12)


def test_time_series_max_tilt_keeps_a_tiny_start_tilt(vh):
    start = vh.tilted_start(0.0, 1.0, roll=math.degrees(1e-10))
    ts = tso.time_series(vh, initial_states=[start], orbits=0.5, samples_per_orbit=4, rtol=1e-9)
    tilt = math.radians(float(ts.max_tilt[0]))
    assert 0.999e-10 <= tilt < 1e-7, tilt


# ---- 5. InitialState == ---------------------------------------------------------------------

def test_initial_state_equality(vh):
    a = vh.tilted_start(30.0, 1.2, roll=5.0, pitch=-3.0)
    same = InitialState.from_row(a.to_row())
    assert a == same and not (a != same)
    assert hash(a) == hash(same) and len({a, same}) == 1
    # a quaternion and its matrix are the same attitude
    q = np.array([np.cos(0.2), 0.0, 0.0, np.sin(0.2)])
    b = InitialState(R=a.R, V=a.V, primary_attitude=a.primary_attitude,
                     primary_omega=a.primary_omega, secondary_attitude=q,
                     secondary_omega=a.secondary_omega)
    c = InitialState(R=a.R, V=a.V, primary_attitude=a.primary_attitude,
                     primary_omega=a.primary_omega, secondary_attitude=quaternion_to_matrix(q),
                     secondary_omega=a.secondary_omega)
    assert b == c and hash(b) == hash(c)
    # -0.0 == 0.0 element by element, and the hashes agree
    row = a.to_row()
    zero = int(np.flatnonzero(row == 0.0)[0])
    flipped = row.copy()
    flipped[zero] = -0.0
    assert InitialState.from_row(flipped) == a and hash(InitialState.from_row(flipped)) == hash(a)


@pytest.mark.parametrize("field", ["R", "V", "primary_omega", "secondary_omega",
                                   "secondary_attitude", "primary_attitude"])
def test_initial_state_inequality_in_every_field(vh, field):
    a = vh.tilted_start(30.0, 1.2)
    value = getattr(a, field).copy()
    if field.endswith("attitude"):
        value = rotation(0, 1e-6) @ value
    else:
        value[0] += 1e-9 * max(1.0, abs(value[0]))
    b = InitialState(**{f: getattr(a, f) for f in ("R", "V", "primary_attitude",
                                                     "primary_omega", "secondary_attitude",
                                                     "secondary_omega")} | {field: value})
    assert a != b and not (a == b)


@pytest.mark.parametrize("other", [3, "state", None, (1, 2), [0.0] * 30])
def test_initial_state_compared_with_other_types(vh, other):
    a = vh.tilted_start(0.0, 1.0)
    assert a.__eq__(other) is NotImplemented
    assert not (a == other) and a != other
    assert a != a.to_row().tolist()
    # an array compares element by element (NumPy's rule): no element equals a state
    assert not np.any(np.zeros(30) == a)


# ---- 6. atol range --------------------------------------------------------------------------

ATOL = r"^atol must lie in \(0, 0\.01\] \(absolute tolerance on the scaled state, whose " \
       r"components are O\(1\); got {}\)$"


@pytest.mark.parametrize("atol, shown", [(1e10, "10000000000"), (0.05, "0.05"), (0.0, "0"),
                                         (-1e-12, "-1e-12"), (float("nan"), "nan"),
                                         (float("inf"), "inf")])
def test_atol_out_of_range_is_refused(atol, shown):
    with pytest.raises(ValueError, match=ATOL.format(re.escape(shown))):
        check_tolerances(1e-10, atol)


def test_atol_out_of_range_is_refused_before_any_work(vh, no_integration):
    with pytest.raises(ValueError, match=ATOL.format("10000000000")):
        tso.surface_of_section(vh, 0.0, 1.0, 2, integrator=tso.Integrator(atol=1e10))
    with pytest.raises(ValueError, match=ATOL.format("10000000000")):
        tso.time_series(vh, 0.0, 1.0, 2, integrator=tso.Integrator(atol=1e10))


@pytest.mark.parametrize("atol", [1e-2, 1e-10, 1e-15, 1e-20, 1e-300, None])
def test_atol_in_range_is_accepted(atol):
    assert check_tolerances(1e-10, atol) == (1e-10, 1e-10 if atol is None else atol)


def test_atol_defaults_to_rtol_at_both_ends():
    assert check_tolerances(1e-16, None) == (1e-16, 1e-16)
    assert check_tolerances(1e-2, None) == (1e-2, 1e-2)


# ---- 7. parameter_map factory returning something else --------------------------------------

@pytest.mark.parametrize("made, name", [("1991 VH", "str"), (None, "NoneType"), (3.0, "float")])
def test_parameter_map_factory_must_return_a_system(no_integration, made, name):
    with pytest.raises(TypeError, match=rf"^factory system\(a/b, e\) must return a BinarySystem; "
                                        rf"at the grid point \(a/b, e\) = \(1\.2, 0\.1\) it "
                                        rf"returned {name}$"):
        tso.parameter_map(lambda q, e: made, [1.2, 1.3], [0.1], 2)


def test_parameter_map_factory_names_the_first_bad_grid_point(no_integration):
    vh = tso.catalog.system("1991 VH")
    calls = []

    def factory(q, e):
        calls.append((q, e))
        return vh if q < 1.25 else "oops"

    with pytest.raises(TypeError, match=r"\(a/b, e\) = \(1\.3, 0\.05\) it returned str$"):
        tso.parameter_map(factory, [1.2, 1.3, 1.4], [0.05, 0.1], 2)
    assert calls[-1] == (1.3, 0.05)        # refused at once, the rest never built


# ---- 8. libration --quiet when not converged ------------------------------------------------

LIBRATION = ["libration", "--orbits", "3", "--candidates", "0.2", "1.3", "9", "--max-orbits",
             "3", "--rtol", "1e-10", "--quiet"]


def test_libration_not_converged_exits_3_with_a_note_even_quiet(tmp_path, capsys):
    out = str(tmp_path / "l.png")
    assert cli.main([*LIBRATION, "--out", out]) == cli.EXIT_INACCURATE == 3
    captured = capsys.readouterr()
    assert captured.out == ""
    notes = [line for line in captured.err.splitlines() if "not converged" in line]
    assert len(notes) == 1, captured.err
    assert notes[0].startswith("ti-spinorbit libration: not converged (")
    assert "max_orbits leaves no doubling to compare" in notes[0]
    assert notes[0].endswith("--allow-inaccurate to accept (exit status 3)")
    result = tso.load(tmp_path / "l.npz")          # written all the same
    assert not result.converged


def test_libration_not_converged_accepted_with_allow_inaccurate(tmp_path, capsys):
    out = str(tmp_path / "l.png")
    assert cli.main([*LIBRATION, "--allow-inaccurate", "--out", out]) == 0
    err = capsys.readouterr().err
    assert "ti-spinorbit libration: not converged (" in err and "exit status 3" not in err


def test_a_local_map_never_imports_the_dask_module():
    """The runner is chosen by client: without one, the maps and scans never import
    ti_spinorbit.studies.distributed (nor dask)."""
    code = ("import sys, ti_spinorbit as tso\n"
            "tso.chaos_map('1991 VH', [0.0], [1.0], 1, fraction_orbits=(), run=tso.Run(progress=False))\n"
            "tso.overlap_threshold('1991 VH', elongations=[1.05], orbits=1, max_orbits=1,\n"
            "                      centre_starts=2, separatrix_starts=2, run=tso.Run(progress=False))\n"
            "print(sorted(m for m in sys.modules if m in ('ti_spinorbit.studies.distributed', 'dask',\n"
            "             'distributed')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, MPLBACKEND="Agg"), timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"
