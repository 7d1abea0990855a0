"""
Where do the 1:1 and 3:2 resonances overlap?
============================================

Near a/b = 1 the synchronous (1:1) and 3:2 spin-orbit resonances are separated by invariant
curves; as the secondary gets more elongated a chaotic layer grows between them until one
trajectory connects both: the resonances overlap (docs/physics.md §8.5, §9.2).
:func:`~ti_spinorbit.overlap_threshold` scans a/b, integrates starts near both island
centres and across the separatrix, and decides for each a/b whether they connect; it doubles
the run length until the decisions stop changing (or reports an upper bound).

This scan of 1991 VH is deliberately small: four elongations, few starts and short runs, so
the verdict may be "not converged". The analytic estimate of the overlap,
ω0 = 1/(2 + √(14 e)), is printed for comparison.
"""

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso

scan = tso.overlap_threshold("1991 VH", elongations=np.array([1.02, 1.04, 1.06, 1.08]),
                             orbits=100, max_orbits=200, centre_starts=8, separatrix_starts=8,
                             rtol=1e-10)
print(scan)
print("first overlap at a/b =", scan.first_overlap)
print("analytic estimate   a/b =", round(float(scan.elongation_ro), 3))
print(scan.message)

fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
scan.plot(ax=ax)
plt.show()
