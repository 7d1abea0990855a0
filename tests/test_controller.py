"""The step-size controller (kernels/controller.py), in the style of scipy's controller tests
(scipy/integrate/_ivp/tests: factors clipped to [min, max], no growth after a rejection, the
exponent of the error order), plus the project's own rules (non-finite estimate, shortened
steps, Newton's stopping test). The compiled Taichi funcs must give the host mirror's
results bit for bit, since the mirror is what these tests read."""

import math

import numpy as np
import pytest
import taichi as ti

from ti_spinorbit import runtime
from ti_spinorbit.kernels.controller import DEFAULT_CONTROLLER, NONFINITE_ERROR, Controller
from ti_spinorbit.kernels.tableau import CASH_KARP, DOP853

C = DEFAULT_CONTROLLER


def test_defaults_are_the_documented_constants():
    assert (C.safety, C.min_factor, C.max_factor, C.nonfinite_factor) == (0.9, 0.2, 5.0, 0.2)
    assert (C.event_rtol, C.event_max_iter) == (4e-16, 8)
    assert CASH_KARP.error_exponent == 1.0 / 5 and DOP853.error_exponent == 1.0 / 8


@pytest.mark.parametrize("exponent", [1.0 / 5, 1.0 / 8])
def test_factor_follows_the_power_law_between_the_limits(exponent):
    """fac = safety err^(-exponent) where that lies in [min, max]; err = 1 gives safety."""
    assert C.factor(1.0, False, exponent) == 0.9
    for err in (0.05, 0.3, 2.0, 10.0):
        expected = 0.9 * err ** -exponent
        if C.min_factor < expected < C.max_factor:
            assert C.factor(err, False, exponent) == pytest.approx(expected, rel=1e-15)
    # halving the error grows the step by 2^exponent (the error order sets the exponent)
    assert C.factor(0.25, False, exponent) / C.factor(0.5, False, exponent) == \
        pytest.approx(2.0 ** exponent, rel=1e-14)


@pytest.mark.parametrize("err, expected", [(0.0, 5.0), (1e-30, 5.0), (1e12, 0.2), (1e300, 0.2)])
def test_factor_is_clipped(err, expected):
    assert C.factor(err, False, 0.2) == expected


@pytest.mark.parametrize("err", [0.0, 1e-8, 0.5, 0.55])
def test_no_growth_right_after_a_rejection(err):
    assert C.factor(err, False, 0.2) > 1.0
    assert C.factor(err, True, 0.2) == 1.0


def test_rejected_step_shrinks():
    """A rejected step (err > 1) is retried smaller, never below min_factor; a non-finite
    estimate retries at nonfinite_factor whatever its value."""
    for err in (1.0001, 3.0, 1e6):
        h = C.rejected(0.1, err, 0.2)
        assert 0.1 * C.min_factor <= h < 0.1
    assert C.rejected(0.1, NONFINITE_ERROR, 0.2) == 0.1 * 0.2


def test_shortened_step_keeps_its_proposal():
    """A step cut to land on a sample time and accepted with a factor >= 1 leaves the
    proposal alone; an uncut one, or one that did badly, takes hs * factor."""
    h, hs = 0.1, 0.03
    assert C.accepted(h, hs, 0.01, False, True, 0.2) == h
    assert C.accepted(h, hs, 0.01, False, False, 0.2) == hs * C.factor(0.01, False, 0.2)
    assert C.accepted(h, hs, 0.99, False, True, 0.2) == hs * C.factor(0.99, False, 0.2) < h


def test_event_stopping_test():
    assert C.event_converged(1.0, 1.0 + 1e-16, 1.0, 1)
    assert not C.event_converged(1.0, 1.0 + 1e-12, 1.0, 1)
    assert C.event_converged(1.0, 1.0 + 1e-12, 1.0, C.event_max_iter)


@pytest.mark.parametrize("kwargs, name", [
    (dict(safety=0.0), "safety"), (dict(safety=1.5), "safety"),
    (dict(min_factor=0.95), "min_factor"), (dict(max_factor=0.5), "max_factor"),
    (dict(nonfinite_factor=1.0), "nonfinite_factor")])
def test_invalid_constants_are_refused(kwargs, name):
    with pytest.raises(ValueError, match=name):
        Controller(**kwargs)


def test_scalar_problem_meets_the_tolerance():
    """scipy-style end-to-end check with the host mirror: a 5th-order error model
    err = (h/h*)^5 on y' = -y; the accepted steps converge to the size that gives err ≈
    safety^(-5) < 1 and no step is accepted with err > 1."""
    h_star, h, accepted, after_reject = 0.01, 1.0, 0, False
    for _ in range(200):
        err = (h / h_star) ** 5
        if err > 1.0:
            h, after_reject = C.rejected(h, err, 0.2), True
            continue
        accepted += 1
        h, after_reject = C.accepted(h, h, err, after_reject, False, 0.2), False
    assert accepted > 150
    assert h == pytest.approx(0.9 * h_star, rel=1e-6)


# ---- the compiled funcs equal the host mirror bit for bit ------------------------------------
nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)


@pytest.fixture(scope="module")
def compiled():
    runtime.ensure_init()
    f = C.funcs()

    @ti.kernel
    def run(err: nd1f, flag: nd1i, out: nd1f, exponent: ti.template()):
        for k in range(err.shape[0]):
            out[4 * k] = f.factor(err[k], flag[k], exponent)
            out[4 * k + 1] = f.rejected(0.1, err[k], exponent)
            out[4 * k + 2] = f.accepted(0.1, 0.03, err[k], flag[k], flag[k], exponent)
            out[4 * k + 3] = ti.select(f.event_converged(err[k], 0.5, 1.0, flag[k] * 8), 1.0, 0.0)

    return run


ERRS = np.array([0.0, 1e-30, 1e-6, 0.3, 0.99, 1.0, 1.5, 40.0, 1e12, NONFINITE_ERROR,
                 0.5 + 1e-16, 0.5 + 1e-10])


@pytest.mark.parametrize("exponent", [1.0 / 5, 1.0 / 8])
def test_taichi_funcs_equal_the_host_mirror(compiled, exponent):
    for flag in (0, 1):
        flags = np.full(len(ERRS), flag, dtype=np.int32)
        out = np.zeros(4 * len(ERRS))
        compiled(ERRS, flags, out, exponent)
        expected = []
        for e in ERRS:
            expected += [C.factor(e, flag, exponent), C.rejected(0.1, e, exponent),
                         C.accepted(0.1, 0.03, e, flag, flag, exponent),
                         float(C.event_converged(e, 0.5, 1.0, flag * 8))]
        assert out.tolist() == expected
    assert math.isfinite(out.sum())
