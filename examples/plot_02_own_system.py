"""
Your own system, from an observed orbital period
================================================

Observers measure a binary's orbital period far better than its densities. Give
:class:`~ti_spinorbit.BinarySystem` the bodies' sizes (a sphere's radius and an ellipsoid's
semi-axes a ≥ b ≥ c, in metres, not diameters), the semimajor axis and the eccentricity,
plus ``orbital_period`` in seconds: both densities are scaled by one factor so that the
Keplerian period matches it. The mass ratio, the shapes and ω0 stay as given.

Here Didymos–Dimorphos with its observed period of 11.92 h, starting from the catalogue's
shapes and orbit.
"""

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso

dd = tso.catalog.system("Didymos")
didymos = tso.BinarySystem(dd.primary, dd.secondary, a=dd.a, e=dd.e,
                           orbital_period=11.92 * 3600, name="Didymos (P = 11.92 h)")
print(didymos)
print(f"density scale factor: {didymos.density_scale:.4f}")
print(f"orbital period: {didymos.orbital_period / 3600:.3f} h")

# %%
# The same bodies written out by hand work just as well (SI units throughout):
# ``tso.BinarySystem(tso.Sphere(radius, density=...), tso.Ellipsoid(a, b, c, density=...),
# a=..., e=..., orbital_period=...)``.
#
# A short surface of section of this system: a handful of starts around synchronous
# rotation (θ̇_p/n = 1), 100 orbits.

sos = tso.surface_of_section(didymos, theta_p=0.0, thetadot_p=np.linspace(0.6, 1.6, 8),
                             orbits=100, rtol=1e-10)
print("statuses:", sos.status_counts)

fig, ax = plt.subplots(figsize=(6, 4.5))
sos.plot(ax=ax)
plt.show()
