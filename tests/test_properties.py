"""Property tests (hypothesis): validators accept exactly their documented ranges, unit
conversions round-trip, and closed-form invariants of bodies and systems hold for any valid
input. Pure NumPy: no kernel launches, so each property runs its 50 examples in milliseconds."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import ti_spinorbit as tso
from ti_spinorbit import _validate
from ti_spinorbit.model import analytic
from ti_spinorbit.studies.classify import wrap_half_turn
from ti_spinorbit.studies.section import TimeSeriesResult
from ti_spinorbit.model.observables import derive
from ti_spinorbit.engine.progress import eta_seconds, format_duration

FAST = settings(max_examples=50, deadline=None)

any_float = st.floats(allow_nan=True, allow_infinity=True)
finite = st.floats(allow_nan=False, allow_infinity=False, min_value=-1e12, max_value=1e12)
unit = st.floats(0.5, 1.0)          # ratio of consecutive semi-axes (b/a, c/b)
density = st.floats(500.0, 5000.0)  # kg m^-3


def accepts(check, *args, **kwargs):
    try:
        check(*args, **kwargs)
    except ValueError:
        return False
    return True


# ---- validators: exactly the documented ranges ------------------------------------------

@FAST
@given(value=any_float, low=finite, width=st.floats(1e-6, 1e6), low_open=st.booleans(),
       high_open=st.booleans())
def test_require_range_accepts_exactly_its_interval(value, low, width, low_open, high_open):
    high = low + width
    inside = math.isfinite(value) and (value > low if low_open else value >= low) \
        and (value < high if high_open else value <= high)
    assert accepts(_validate.require_range, "x", value, low, high,
                   low_open=low_open, high_open=high_open) == inside


@FAST
@given(st.one_of(any_float, st.lists(any_float, min_size=1, max_size=5)))
def test_require_positive_and_finite(value):
    arr = np.asarray(value, dtype=np.float64)
    assert accepts(_validate.require_finite, "x", value) == bool(np.all(np.isfinite(arr)))
    assert accepts(_validate.require_positive, "x", value) == \
        bool(np.all(np.isfinite(arr)) and np.all(arr > 0))


@FAST
@given(value=st.one_of(st.integers(-10**6, 10**6), any_float), minimum=st.integers(-100, 100),
       span=st.integers(0, 1000))
def test_require_count_accepts_integers_in_range(value, minimum, span):
    maximum = minimum + span
    ok = math.isfinite(value) and float(value).is_integer() and minimum <= value <= maximum
    assert accepts(_validate.require_count, "n", value, minimum, maximum) == ok
    if ok:
        got = _validate.require_count("n", value, minimum, maximum)
        assert type(got) is int and got == value


@FAST
@given(nbytes=st.floats(0, 1e15), available=st.integers(1, 10**15))
def test_require_memory_threshold(nbytes, available):
    assert accepts(_validate.require_memory, "x", nbytes, "advice", available=available) == \
        (nbytes <= _validate.MEMORY_FRACTION * available)


# ---- bodies: closed forms ----------------------------------------------------------------

@FAST
@given(a=st.floats(1.0, 1e4), u=unit, v=unit, rho=density)
def test_ellipsoid_mass_moments_and_integrals(a, u, v, rho):
    b, c = a * u, a * u * v
    body = tso.Ellipsoid(a, b, c, rho)
    m = 4.0 / 3.0 * math.pi * a * b * c * rho
    assert body.mass == pytest.approx(m, rel=1e-14)
    A, B, C = body.moments
    np.testing.assert_allclose([A, B, C], [m * (b * b + c * c) / 5, m * (a * a + c * c) / 5,
                                           m * (a * a + b * b) / 5], rtol=1e-13)
    assert A <= B * (1 + 1e-14) and B <= C * (1 + 1e-14)
    assert body.integral(2, 0, 0) == pytest.approx(m * a * a / 5, rel=1e-13)
    assert body.integral(4, 0, 0) == pytest.approx(3 * m * a**4 / 35, rel=1e-13)
    assert body.integral(2, 2, 0) == pytest.approx(m * a * a * b * b / 35, rel=1e-13)
    assert body.integral(3, 0, 0) == 0.0 and not body.has_odd_integrals
    # the same body given by its mass instead of its density
    same = tso.Ellipsoid(a, b, c, mass=m)
    np.testing.assert_allclose(same.as_row(), body.as_row(), rtol=1e-13)


@FAST
@given(r=st.floats(1.0, 1e4), rho=density)
def test_sphere_moments(r, rho):
    s = tso.Sphere(r, rho)
    np.testing.assert_allclose(s.moments, [0.4 * s.mass * r * r] * 3, rtol=1e-13)
    assert s.bounding_radius == r


# ---- systems -----------------------------------------------------------------------------

@st.composite
def systems(draw):
    """A valid binary: spherical or ellipsoidal primary, ellipsoidal secondary, bodies clear
    of each other at pericentre."""
    radius = draw(st.floats(100.0, 2000.0))
    if draw(st.booleans()):
        primary = tso.Sphere(radius, draw(density))
    else:
        b1 = radius * draw(unit)
        primary = tso.Ellipsoid(radius, b1, b1 * draw(unit), draw(density))
    a2 = draw(st.floats(5.0, 0.5 * radius))
    b2 = a2 * draw(unit)
    secondary = tso.Ellipsoid(a2, b2, b2 * draw(unit), draw(density))
    e = draw(st.floats(0.0, 0.8))
    contact = primary.bounding_radius + secondary.bounding_radius
    a = contact / (1.0 - e) * draw(st.floats(1.2, 20.0))
    period = draw(st.one_of(st.none(), st.floats(3600.0, 1e6)))
    return tso.BinarySystem(primary, secondary, a, e, primary_spin_period=period)


@FAST
@given(systems())
def test_kepler_units(system):
    n = system.mean_motion
    assert n * n * system.a**3 == pytest.approx(tso.G * system.total_mass, rel=1e-13)
    assert system.orbital_period * n == pytest.approx(2 * math.pi, rel=1e-15)
    assert system.mass_ratio == pytest.approx(system.primary.mass / system.secondary.mass)


@FAST
@given(systems())
def test_omega0_depends_on_elongation_only(system):
    # compared as ω0² = 3 (B − A)/C: B − A cancels for a nearly round body, so allow round-off
    # of the moments themselves (~1e-16 · 3 (A + B)/C ≈ 1e-15 absolute)
    a, b, c = system.secondary.semi_axes
    assert system.omega0**2 == pytest.approx(analytic.omega0(a / b) ** 2, rel=1e-12, abs=1e-14)
    assert analytic.elongation_from_omega0(system.omega0) == pytest.approx(a / b, rel=1e-10)
    fraction = system.primary.mass / system.total_mass
    assert analytic.omega0_effective(system) ** 2 == \
        pytest.approx(system.omega0**2 * fraction, rel=1e-12, abs=1e-14)


@FAST
@given(system=systems(), seed=st.integers(0, 2**32 - 1))
def test_scaled_and_si_states_round_trip(system, seed):
    y = np.random.default_rng(seed).normal(size=(3, 30))
    x = system.to_physical(y)
    np.testing.assert_allclose(system.from_physical(x), y, rtol=1e-13, atol=0)
    # lengths scale with a, rotation matrices are untouched
    from ti_spinorbit.kernels import eom
    np.testing.assert_allclose(x[:, eom.Y_R:eom.Y_R + 3], y[:, eom.Y_R:eom.Y_R + 3] * system.a,
                               rtol=1e-15)
    np.testing.assert_array_equal(x[:, eom.Y_S:eom.Y_S + 9], y[:, eom.Y_S:eom.Y_S + 9])


@FAST
@given(systems())
def test_scaled_body_rows_undo_to_si(system):
    from ti_spinorbit.system.bodies import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4

    M, a = system.total_mass, system.a
    scale = np.array([M] + [M * a**2] * len(EXPONENTS_2) + [M * a**3] * len(EXPONENTS_3)
                     + [M * a**4] * len(EXPONENTS_4))
    for body in (system.primary, system.secondary):
        np.testing.assert_allclose(system.scaled_body_row(body) * scale, body.as_row(), rtol=1e-14)


@FAST
@given(system=systems(), theta_p=st.floats(-360.0, 360.0), thetadot_p=st.floats(-5.0, 5.0))
def test_initial_state_observables_round_trip(system, theta_p, thetadot_p):
    """Start at pericentre with (θ_p, θ̇_p/n); the observables read back θ_p (deg, modulo
    360°), θ̇_p/n, r = 1 − e and the osculating a = 1, e (scaled units)."""
    par = system.parameter_row()
    y = system.initial_state(math.radians(theta_p), thetadot_p)
    d = {k: float(v[0]) for k, v in derive(par[None], y[None]).items()}
    diff = (math.degrees(d["alpha"]) - theta_p + 180.0) % 360.0 - 180.0
    assert abs(diff) < 1e-9
    assert d["thetadot"] == pytest.approx(thetadot_p, rel=1e-12, abs=1e-12)
    assert d["r"] == pytest.approx(1.0 - system.e, rel=1e-14)
    assert d["a"] == pytest.approx(1.0, rel=1e-12)
    assert d["e"] == pytest.approx(system.e, abs=1e-7)


@FAST
@given(systems())
def test_describe_round_trip(system):
    back = tso.BinarySystem.from_description(system.describe())
    np.testing.assert_array_equal(back.parameter_row(), system.parameter_row())
    np.testing.assert_array_equal(back.initial_state(0.3, 1.1), system.initial_state(0.3, 1.1))


@FAST
@given(name=st.sampled_from([n for n in tso.catalog.names() if n != "test"]),
       stretch=st.floats(0.0, 1.0), rho=density)
def test_catalogue_prescription(name, stretch, rho):
    """docs/physics.md §7: a = sqrt(ab · q), b = sqrt(ab / q), c fixed, mass ρ (4/3) π ab c."""
    entry = tso.catalog.entry(name)
    q = 1.0 + stretch * (entry["ab"] / entry["c"] ** 2 - 1.0)     # up to b = c
    system = tso.catalog.system(name, elongation=q, secondary_density=rho)
    a, b, c = system.secondary.semi_axes
    assert a / b == pytest.approx(q, rel=1e-13)
    assert a * b == pytest.approx(entry["ab"], rel=1e-13) and c == entry["c"]
    assert system.secondary.mass == pytest.approx(rho * 4 / 3 * math.pi * entry["ab"] * c, rel=1e-13)
    assert system.omega0**2 == pytest.approx(analytic.omega0(q) ** 2, rel=1e-12, abs=1e-14)


# ---- angles and progress arithmetic ----------------------------------------------------------

@FAST
@given(st.floats(-1e6, 1e6))
def test_wrap_half_turn(angle):
    w = wrap_half_turn(angle)
    assert -90.0 < w <= 90.0
    k = (angle - w) / 180.0
    assert abs(k - round(k)) < 1e-9
    assert wrap_half_turn(w) == pytest.approx(w, abs=1e-12)


@FAST
@given(total=st.floats(1e-3, 1e6), fraction=st.floats(1e-6, 1.0))
def test_eta_at_constant_rate_is_the_time_left(total, fraction):
    elapsed = fraction * total
    assert eta_seconds(fraction, elapsed) == pytest.approx((1.0 - fraction) * total, rel=1e-9,
                                                           abs=1e-9)
    assert eta_seconds(0.0, elapsed) is None


@FAST
@given(st.floats(0.0, 1e6))
def test_format_duration_reads_back(seconds):
    parts = [int(p) for p in format_duration(seconds).split(":")]
    assert all(0 <= p < 60 for p in parts[1:])
    value = sum(p * 60**k for k, p in enumerate(reversed(parts)))
    assert value == int(round(seconds))


@FAST
@given(scale=st.floats(1e-10, 1e10), seed=st.integers(0, 2**32 - 1))
def test_energy_check_is_relative(scale, seed):
    """The energy check's drifts and exchanges are ratios: scaling every energy and every
    angular momentum by the same factor changes none of them."""
    from types import SimpleNamespace

    rng = np.random.default_rng(seed)
    k = 20
    parts = {f"energy_{p}": rng.normal(size=(1, k)) for p in ("orbit", "primary", "secondary")}
    parts["energy_orbit"] -= 10.0                          # a bound orbit dominates
    mom = {f"angmom_{p}": rng.normal(size=(1, k, 3)) + 5.0 for p in ("orbit", "primary", "secondary")}

    def series(f):
        fields = {**{n: v * f for n, v in parts.items()}, **{n: v * f for n, v in mom.items()}}
        fields["energy"] = sum(fields[f"energy_{p}"] for p in ("orbit", "primary", "secondary"))
        return SimpleNamespace(t=np.arange(k, dtype=float)[None], **fields)

    base = TimeSeriesResult.conservation(series(1.0))[0]
    scaled = TimeSeriesResult.conservation(series(scale))[0]
    assume(base["energy_drift"] > 0)
    for key, value in base.items():
        assert scaled[key] == pytest.approx(value, rel=1e-9)
