"""The step-size controller: the whole accept/reject and next-step policy in one place.

After a trial step of size ``hs`` whose error estimate is ``err`` (tolerance units, see
``integrator.make_error_norm``; ``err <= 1`` means accepted), the next proposal is

    h = hs * clip(safety * err^(-exponent), min_factor, max_factor)

with ``exponent = 1 / (q + 1)`` for an error estimate of order q (``Tableau.error_exponent``:
1/5 for Cash-Karp, 1/8 for DOP853, 1/9 for Verner 9(8)), as in scipy ``integrate/_ivp/rk.py``
and Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.4 (eq. 4.13), and these refinements:

* no growth (factor <= 1) on the step right after a rejection (scipy's ``step_rejected``);
* a trial step whose error estimate is NaN or infinite (``NONFINITE_ERROR``) is retried at
  ``nonfinite_factor`` times its size: the estimate carries no information on the size;
* a step shortened to land on a sample time or on ``t_stop`` that was accepted with a factor
  >= 1 keeps the proposal it had before shortening (shortening is not evidence that a
  smaller step is needed; without this rule every sample would shrink the step);
* event location (Newton on the pericentre function inside an accepted step) stops when the
  update is below ``event_rtol`` times the step, or after ``event_max_iter`` iterations.

``Controller`` is plain data; :meth:`Controller.funcs` builds its Taichi functions, which the
kernel factory (``ensemble.make_kernels``) receives with the controller. The pure-Python
methods mirror the Taichi ones operation for operation (same IEEE results), so the policy
can be unit-tested without a kernel (tests/test_controller.py).
"""

import math
from dataclasses import dataclass
from types import SimpleNamespace

#: Error-norm value standing for "NaN or inf somewhere in the trial step".
NONFINITE_ERROR = 1e301


@dataclass(frozen=True)
class Controller:
    """Step-size controller constants (scipy naming; NR §16.2 / HNW §II.4 behaviour).

    safety, min_factor, max_factor : the next-step factor is
        clip(safety * err^(-exponent), min_factor, max_factor).
    nonfinite_factor : step factor after a trial step with a NaN or infinite error estimate.
    event_rtol : Newton's stopping test for an event time, relative to the step length
        (4e-16: two ulps of a time O(1) scaled unit, where further iterates only round).
    event_max_iter : at most this many Newton iterates per event.
    """

    safety: float = 0.9
    min_factor: float = 0.2
    max_factor: float = 5.0
    nonfinite_factor: float = 0.2
    event_rtol: float = 4e-16
    event_max_iter: int = 8

    def __post_init__(self):
        if not 0.0 < self.safety <= 1.0:
            raise ValueError(f"safety must be in (0, 1] (got {self.safety!r})")
        if not 0.0 < self.min_factor <= self.safety <= self.max_factor:
            raise ValueError("controller factors must satisfy 0 < min_factor <= safety <= "
                             f"max_factor (got {self.min_factor!r}, {self.safety!r}, "
                             f"{self.max_factor!r})")
        if not 0.0 < self.nonfinite_factor < 1.0:
            raise ValueError(f"nonfinite_factor must be in (0, 1) (got {self.nonfinite_factor!r})")

    # ---- host mirror (same operations as the Taichi functions) ------------------------------
    def factor(self, err, after_reject, exponent):
        """Next-step factor for an error norm ``err`` (no growth when ``after_reject``)."""
        fac = self.max_factor
        if err > 0.0:
            fac = self.safety * math.pow(err, -exponent)
        fac = min(self.max_factor, max(self.min_factor, fac))
        if after_reject:
            fac = min(1.0, fac)
        return fac

    def rejected(self, hs, err, exponent):
        """Retry size after the trial step ``hs`` was rejected (err > 1)."""
        if err >= NONFINITE_ERROR:
            return hs * self.nonfinite_factor
        return hs * self.factor(err, True, exponent)

    def accepted(self, h, hs, err, after_reject, shortened, exponent):
        """Next proposal after the step ``hs`` (proposal ``h``) was accepted; ``shortened``
        when hs was cut to land on a sample time or on the end."""
        fac = self.factor(err, after_reject, exponent)
        if not (shortened and hs < h and fac >= 1.0):
            h = hs * fac
        return h

    def event_converged(self, new_tau, tau, h_step, iterations):
        return abs(new_tau - tau) <= self.event_rtol * h_step or \
            iterations >= self.event_max_iter

    # ---- Taichi functions ---------------------------------------------------------------------
    def funcs(self):
        """Taichi funcs ``factor``, ``rejected``, ``accepted``, ``event_converged`` with this
        controller's constants compiled in (the exponent is a template argument)."""
        import taichi as ti      # Taichi: the controller's data is read without it (tableau)

        safety, lo, hi = self.safety, self.min_factor, self.max_factor
        nonfinite, ev_rtol, ev_iter = self.nonfinite_factor, self.event_rtol, self.event_max_iter

        @ti.func
        def factor(err_norm, after_reject, exponent: ti.template()):
            fac = hi
            if err_norm > 0.0:
                fac = safety * ti.pow(err_norm, -exponent)
            fac = ti.min(hi, ti.max(lo, fac))
            if after_reject:
                fac = ti.min(1.0, fac)
            return fac

        @ti.func
        def rejected(hs, err_norm, exponent: ti.template()):
            h = 0.0
            if err_norm >= NONFINITE_ERROR:
                h = hs * nonfinite
            else:
                h = hs * factor(err_norm, 1, exponent)
            return h

        @ti.func
        def accepted(h, hs, err_norm, after_reject, shortened, exponent: ti.template()):
            h_next = h
            fac = factor(err_norm, after_reject, exponent)
            if not (shortened and hs < h and fac >= 1.0):
                h_next = hs * fac
            return h_next

        @ti.func
        def event_converged(new_tau, tau, h_step, iterations):
            return ti.abs(new_tau - tau) <= ev_rtol * h_step or iterations >= ev_iter

        return SimpleNamespace(factor=factor, rejected=rejected, accepted=accepted,
                               event_converged=event_converged)


DEFAULT_CONTROLLER = Controller()
