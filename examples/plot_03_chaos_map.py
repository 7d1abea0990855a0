"""
A small chaos map
=================

:func:`~ti_spinorbit.chaos_map` integrates a grid of starts (θ_p, θ̇_p/n) in one launch,
each with a shadow trajectory for the chaos indicators: MEGNO ⟨Y⟩ tends to 2 for regular
motion and grows without bound for chaotic motion, so the map separates resonant islands
from the chaotic sea (docs/physics.md §10.2). The chaotic fraction counts only members whose
integration passed the accuracy check.

A 16 × 16 grid over 100 orbits is coarse but shows 1991 VH's synchronous island and the
chaotic sea around it; the figures of the README use 64 × 64 starts and 500 orbits.
"""

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso

vh = tso.catalog.system("1991 VH")
cmap = tso.chaos_map(vh, theta_p=np.linspace(0, 180, 16), thetadot_p=np.linspace(0.2, 2.6, 16),
                     orbits=100, rtol=1e-10)
print(cmap)
print(f"chaotic fraction: {cmap.chaotic_fraction:.2f}")
print("MEGNO <Y> from", round(float(np.nanmin(cmap.megno)), 2),
      "to", round(float(np.nanmax(cmap.megno)), 1))

fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
cmap.plot(ax=ax)
plt.show()
