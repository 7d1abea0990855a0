"""What a run will cost before it starts, and the step budget that bounds every member.

An adaptive integrator takes as many steps as the motion needs, so an input inside every
documented range can still ask for an unbounded number of them (a perturbation scaled far
past a perturbation, a spin of 10⁷ n). Two guards keep every accepted input finite in time:

1. **An estimate before the run.** The steps per orbit of a member follow from its time
   scales: the orbit (pericentre passage), the two spins, and the method's order,

       steps/orbit ≈ A_m · (rtol / 1e-12)^(−e_m) · max(1, |ω₁|/n, |ω₂|/n + 1) · (1 − e)^(−3/2),

   with e_m the method's error exponent (1/5 Cash-Karp, 1/8 DOP853, 1/9 Verner 9(8): a step
   of length h makes an error ∝ h^(1/e_m)) and A_m the steps per orbit of a slowly spinning
   member at rtol 1e-12, set above what the eleven catalogued systems take (two starts
   each, 3 orbits, rtol 1e-8, 1e-12 and 1e-15; ``python experiments/step_cost.py`` prints
   the table): Cash-Karp 300-420, DOP853 53-89, Verner 27-45 steps per orbit at 1e-12. The
   measured rtol slopes are −0.200, −0.112 and −0.095 against −e_m = −0.200, −0.125 and
   −0.111, and the estimate is 2.1 to 5.6 times the measured steps of every member: an
   upper bound, by design. ω₁ and ω₂ are read off the start (scaled units:
   n = 1) through the largest principal-moment ratio, so they bound the fastest component
   of the spin; the factor (1 − e)^(−3/2) is the pericentre's angular rate over n's, up to
   the (1 + e)^(1/2) that the fit does not need. The run's estimate is the sum over members.
   Above :data:`LONG_RUN_STEPS` a :class:`LongRunWarning` says so before any work (like the
   memory check, ``ti_spinorbit.engine.resources``), with the estimate in steps.

2. **A per-member step budget.** Every member may take at most

       max_steps = BUDGET_FACTOR · max(estimate over members) · max(orbits, 1) + BUDGET_FLOOR

   accepted plus rejected steps (the kernels count both across launches and resumes); a
   member that reaches it stops at its last accepted state with the status
   ``"step budget"`` (:class:`ti_spinorbit.engine.results.Status`), keeping everything recorded, and
   the rest of the ensemble goes on. ``BUDGET_FACTOR = 100`` is far above the estimate's
   scatter (healthy members take 0.18-0.48 × the estimate), so only a member whose motion
   is hundreds of times stiffer than its time scales say (a near-contact, a runaway
   perturbation) meets it.
   One budget serves the whole launch (a kernel scalar): it is set by the member estimated
   to be the most expensive.

Importing this module does not import Taichi.
"""

import warnings

import numpy as np

from ..layout import spatial as _L

#: Steps per orbit of a slowly spinning, near-circular member at rtol 1e-12, and the
#: method's error exponent (kernels/tableau.py ``error_exponent``; a test checks they agree).
METHOD_COST = {"cash-karp": (420.0, 1.0 / 5.0), "dop853": (90.0, 1.0 / 8.0),
               "vern9": (45.0, 1.0 / 9.0)}
#: A member may take this many times the most expensive member's estimate.
BUDGET_FACTOR = 100.0
#: Steps every member may take whatever the estimate (short runs, event location).
BUDGET_FLOOR = 100_000
#: Estimated steps (all members together) above which a run warns before it starts: about
#: 1e10 steps is 20-60 minutes of two CPU cores with the 3-D model.
LONG_RUN_STEPS = 1e10



class LongRunWarning(UserWarning):
    """A run whose estimated cost (steps) is above :data:`LONG_RUN_STEPS`."""


def _spin_bound(w, ratios):
    """|ω| bound (units of n) from the scaled spin w = Γ/C and the body's C/(A, B, C)."""
    return np.linalg.norm(w, axis=1) * np.max(ratios, axis=1)


def steps_per_orbit(par, y0, rtol, method="cash-karp"):
    """Estimated integration steps per orbit of each member, (N,) floats (see the module
    docstring). ``par`` the members' scaled parameter rows, ``y0`` their 30-number scaled
    starts (``BinarySystem.initial_state``), ``rtol`` the relative tolerance."""
    amplitude, exponent = METHOD_COST[method]
    par = np.asarray(par, dtype=np.float64)
    y0 = np.asarray(y0, dtype=np.float64)
    w1 = _spin_bound(y0[:, _L.Y_W1:_L.Y_W1 + 3], par[:, _L.P_IA:_L.P_IA + 3])
    w2 = _spin_bound(y0[:, _L.Y_W2:_L.Y_W2 + 3], par[:, _L.P_IB:_L.P_IB + 3])
    R, V = y0[:, _L.Y_R:_L.Y_R + 3], y0[:, _L.Y_V:_L.Y_V + 3]
    r = np.linalg.norm(R, axis=1)
    # eccentricity vector with G(m1 + m2) = 1 (scaled units)
    ev = (np.sum(V * V, axis=1) - 1.0 / r)[:, None] * R - np.sum(R * V, axis=1)[:, None] * V
    e = np.minimum(np.linalg.norm(ev, axis=1), 0.999)
    spins = np.maximum.reduce([np.ones_like(w1), w1, w2 + 1.0])
    return amplitude * (rtol / 1e-12) ** (-exponent) * spins * (1.0 - e) ** -1.5


def step_budget(estimate, orbits):
    """The per-member step budget (an int) of a run whose members' estimates (steps per
    orbit) are ``estimate`` over ``orbits`` orbits (scalar or per member)."""
    # a member whose start is not finite has no estimate (it stops as "non-finite" at once)
    per_member = np.asarray(estimate, float) * np.maximum(np.asarray(orbits, float), 1.0)
    worst = float(np.max(np.where(np.isfinite(per_member), per_member, 0.0), initial=0.0))
    budget = BUDGET_FACTOR * worst + BUDGET_FLOOR
    return int(min(budget, 2.0 ** 62))


def check_cost(what, estimate, orbits):
    """Warn (:class:`LongRunWarning`) when the run's estimated steps, the sum over members of
    ``estimate`` × ``orbits``, exceed :data:`LONG_RUN_STEPS`; returns that total."""
    per_member = np.asarray(estimate, float) * np.maximum(np.asarray(orbits, float), 0.0)
    total = float(np.sum(np.where(np.isfinite(per_member), per_member, 0.0)))
    if total > LONG_RUN_STEPS:
        warnings.warn(f"{what}: an estimated {total:.2g} integration steps (above "
                      f"{LONG_RUN_STEPS:.0e}, roughly an hour of two CPU cores): fewer members "
                      "or orbits, a looser rtol or a higher-order method (DOP853, Verner) "
                      "shorten it", LongRunWarning, stacklevel=3)
    return total


__all__ = ["steps_per_orbit", "step_budget", "check_cost", "LongRunWarning", "METHOD_COST",
           "BUDGET_FACTOR", "BUDGET_FLOOR", "LONG_RUN_STEPS"]
