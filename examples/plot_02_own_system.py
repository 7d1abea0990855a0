"""
Your own system, from an observed orbital period
================================================

Observers measure a binary's orbital period far better than its densities. Give
:class:`~ti_spinorbit.BinarySystem` the bodies' sizes (a sphere's radius and an ellipsoid's
semi-axes a ≥ b ≥ c, in metres, not diameters), any densities, the semimajor axis and the
eccentricity, plus ``orbital_period`` in seconds: both densities are scaled by one factor so
that the Keplerian period matches it. The mass ratio, the shapes and ω0 stay as given.

Here Didymos–Dimorphos with its observed period of 11.92 h: the catalogue's sizes and orbit
typed in by hand, with a guessed density of 2000 kg/m³ for both bodies.
"""

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso

didymos = tso.BinarySystem(tso.Sphere(400, density=2000),             # radius, m
                           tso.Ellipsoid(85.51, 65.78, 65, density=2000),  # semi-axes, m
                           a=1180, e=0.04, orbital_period=11.92 * 3600,
                           name="Didymos")
print(didymos)
print(f"both densities scaled by {didymos.density_scale:.4f}: "
      f"{2000 * didymos.density_scale:.0f} kg/m³")
print(f"orbital period: {didymos.orbital_period / 3600:.3f} h, mass ratio {didymos.mass_ratio:.1f}")

# %%
# A short surface of section of this system: a handful of starts around synchronous
# rotation (θ̇_p/n = 1), 100 orbits.

sos = tso.surface_of_section(didymos, theta_p=0.0, thetadot_p=np.linspace(0.6, 1.6, 8),
                             orbits=100, rtol=1e-10)
print("statuses:", sos.status_counts)

fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
sos.plot(ax=ax)
plt.show()
