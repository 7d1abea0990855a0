"""
Earth flybys: 32 close encounters of 1991 VH in one launch
==========================================================

A planet passing a binary asteroid raises a tide on the mutual orbit and torques on both
bodies (``tso.Flyby``, docs/physics.md §13.12). Every orbit field of a ``Flyby`` may be a
sequence with one value per member, so an ensemble over the closest distance q is a single
launch, one flyby per member.

Here Earth passes 1991 VH at 32 distances from 2 to 40 Earth radii, at v∞ = 8 km/s (about
1991 VH's own encounter speed with Earth), 60° out of the mutual orbit's plane, 12 mutual
orbits after the start (the planet then starts 45 q or more away). The secondary starts
synchronous (θ_p = 0, θ̇_p/n = 1) and librates in the plane; what it does after the pass is
the encounter's doing. ``experiments/study16_flybys.py`` runs thousands of such encounters
with isotropic orientations and random phases.
"""

import matplotlib.pyplot as plt
from matplotlib.ticker import NullFormatter
import numpy as np

import ti_spinorbit as tso
from ti_spinorbit.model.attitude import CLASSES

vh = tso.catalog.system("1991 VH")
R_EARTH_KM = 6371.0
q_re = np.geomspace(2.0, 40.0, 32)
flyby = tso.Flyby("Earth", v_inf_km_s=8.0, q_km=list(q_re * R_EARTH_KM), inclination_deg=60.0,
                  node_deg=20.0, periapsis_deg=30.0,
                  t_closest_h=12 * vh.orbital_period / 3600.0)
ts = tso.time_series(vh, theta_p=0.0, thetadot_p=[1.0] * len(q_re), orbits=30,
                     samples_per_orbit=16, rtol=1e-10, perturbations=[flyby],
                     integrator=tso.Integrator(model="3d"))
print(ts)

# %%
# The secondary's spin rate (one-orbit mean) against time for four of the encounters. Before
# the pass at 12 orbits every member librates about synchronous rotation (θ̇/n = 1). Passes
# within about 8 Earth radii split the binary (the member stops as ``escape`` when the
# bodies are 50 a apart); out to about 22 Earth radii the secondary is knocked out of
# synchronous rotation, into another spin (circulation; here a slower one) or tumbling;
# farther passes leave it librating, its pole tilted by a few degrees.

t_orbits = ts.t / vh.orbital_period
fig, ax = plt.subplots(figsize=(6.4, 4), layout="constrained")
for q in (3.0, 9.4, 15.0, 35.0):
    k = int(np.argmin(np.abs(q_re - q)))
    mean = np.convolve(ts.thetadot[k], np.ones(16) / 16, mode="valid")
    ax.plot(t_orbits[k, :len(mean)], mean,
            label=f"q = {q_re[k]:.1f} $R_\\oplus$ ({ts.status_names[k]})")
ax.axvline(12.0, color="0.5", lw=0.8, ls=":")
ax.set_xlabel("time (mutual orbits)")
ax.set_ylabel(r"$\dot\theta/n$, one-orbit mean")
ax.set_title("1991 VH meeting Earth 12 orbits after the start")
ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
plt.show()

# %%
# The end state against q: the largest angle of the secondary's spin angular momentum from
# its short axis (``max_npa_angle``: above 30° it tumbles) coloured by the package's attitude
# class over the whole run (docs/physics.md §6.9), and the split binaries (status
# ``escape``) marked on top.

split = np.asarray(ts.status_names) == "escape"
classes = np.asarray(ts.attitude_class)
colours = ["#9ecae1", "#3182bd", "#969696", "#fb6a4a"]
fig, ax = plt.subplots(figsize=(6.4, 4), layout="constrained")
for c, name in enumerate(CLASSES):
    sel = (classes == c) & ~split
    ax.scatter(q_re[sel], np.maximum(ts.max_npa_angle[sel], 1e-3), color=colours[c], label=name)
ax.scatter(q_re[split], np.full(split.sum(), 100.0), marker="v", color="k", label="split (escape)")
ax.axhline(30.0, color="0.5", lw=0.8, ls="--")
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xticks([2, 5, 10, 20, 40], ["2", "5", "10", "20", "40"])
ax.xaxis.set_minor_formatter(NullFormatter())
ax.set_xlabel(r"closest approach $q/R_\oplus$")
ax.set_ylabel("largest non-principal-axis angle (deg)")
ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
plt.show()
names, counts = np.unique(np.asarray(ts.attitude_class_names)[~split], return_counts=True)
print(f"split: {int(split.sum())} of {len(q_re)}, out to q = {q_re[split].max():.1f} Earth radii;",
      "the rest:", ", ".join(f"{c} {n}" for n, c in zip(names, counts)))
