"""
Reading a saved result with plain NumPy
=======================================

:func:`ti_spinorbit.save` writes any result to a compressed ``.npz`` archive: every array
under its own name, plus one entry ``metadata`` holding JSON with all inputs, units, the
statuses, the package version and the time of the run. :func:`ti_spinorbit.load` gives the
result object back, but the file needs nothing but NumPy to read, in any language that reads
``.npz``.
"""

import json
import os
import tempfile

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso

vh = tso.catalog.system("1991 VH")
sos = tso.surface_of_section(vh, theta_p=0.0, thetadot_p=[0.45, 1.0, 1.7], orbits=50,
                             rtol=1e-10)
path = tso.save(sos, os.path.join(tempfile.mkdtemp(), "sos_1991VH.npz"))

# %%
# From here on, only NumPy and the standard library.

with np.load(path) as archive:
    print("arrays:", sorted(archive.files))
    meta = json.loads(str(archive["metadata"]))
    theta_p, thetadot_p = archive["theta_p"], archive["thetadot_p"]

print("kind:", meta["kind"], "| rtol:", meta["rtol"], "| orbits:", meta["orbits"])
print("statuses:", meta["status_counts"])
print("units of thetadot_p:", meta["units"]["thetadot_p"])
system = meta["systems"][0]
print("system:", system["name"], "| a =", system["a_m"], "m | e =", system["e"],
      "| secondary semi-axes (m):", system["secondary"]["semi_axes_m"])

# %%
# The section arrays are (members, crossings), padded with NaN after each member's last
# crossing.

fig, ax = plt.subplots(figsize=(6, 4.5), layout="constrained")
for k in range(theta_p.shape[0]):
    ax.plot(theta_p[k], thetadot_p[k], ".", ms=3, label=f"member {k}")
ax.set_xlabel(r"$\theta_p$ (deg)")
ax.set_ylabel(r"$\dot\theta_p / n$")
ax.legend()
plt.show()
