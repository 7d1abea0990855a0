"""How a system moves: the models (3-D and planar), their host-side parameter rows and state
conversions, the perturbations (tides, YORP, BYORP), coordinates (apsidal, inertial), attitude
and observables, and the analytic and reference formulas the tests and studies compare
against. Imports ``system`` and the base modules; never the engine, the studies or the output.
"""
