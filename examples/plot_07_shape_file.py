"""
A real shape: Didymos from its radar shape model
================================================

A shape model is a closed triangle mesh; :func:`~ti_spinorbit.read_shape` reads it (OBJ,
PDS/Gaskell tables, ICQ, or the GUBAS CSV pair used here) and returns a uniform
:func:`~ti_spinorbit.Polyhedron`: its inertia integrals up to ``order``, from signed
tetrahedra, about its centre of mass in its principal axes (docs/physics.md §2.7).

The file here is the radar model of (65803) Didymos (Naidu et al. 2020) packaged with
ti_spinorbit, in metres; the density is the catalogue's 1955 kg/m³. The body keeps the map
from the file's frame to its own: ``x_body = rotation @ (x_file - offset)``. (This copy of
the model is already centred and in its principal axes, so the map is the identity to
round-off; for another file it need not be.)
"""

from importlib import resources

import matplotlib.pyplot as plt
import numpy as np

import ti_spinorbit as tso
from ti_spinorbit.system.integrals import multi_indices
from ti_spinorbit.system.shapefiles import read_mesh

folder = resources.files("ti_spinorbit.data") / "shapes"
files = (folder / "didymos_radar_vertices_m.csv", folder / "didymos_radar_facets.csv")
didymos = tso.read_shape(files, unit="m", density=1955, name="Didymos", order=12)
print(didymos)
print(f"volume {didymos.volume:.4e} m³, volume-equivalent radius "
      f"{(3 * didymos.volume / (4 * np.pi)) ** (1 / 3):.1f} m, bounding radius "
      f"{didymos.bounding_radius:.1f} m")
print("principal moments A, B, C / C:", np.round(didymos.moments / didymos.moments.max(), 4))
print("centre of mass in the file's frame (m):", np.round(didymos.offset, 9))
print("file axes -> body axes (rows: body x, y, z in the file's frame):")
print(np.round(didymos.rotation, 6))

# %%
# The shape in its body frame, and how much of its mass distribution lies beyond an
# ellipsoid: for each degree n, the largest magnitude of T^lmn in units of M ρ^n (ρ the
# bounding radius, so every value is at most 1), for the polyhedron, for its integrals with
# an odd index alone (no mirror symmetry: an ellipsoid has none), and for the uniform
# ellipsoid with the same second moments.

vertices, faces = read_mesh(files, unit="m")
body_frame = (vertices - didymos.offset) @ didymos.rotation.T
axes = [np.sqrt(5 * didymos.integral(*k) / didymos.mass) for k in ((2, 0, 0), (0, 2, 0),
                                                                      (0, 0, 2))]
twin = tso.Ellipsoid(*axes, mass=didymos.mass, order=12)
M, rho = didymos.mass, didymos.bounding_radius


def largest(body, odd_only=False):
    out = []
    for n in range(2, 13):
        keys = [k for k in multi_indices(n) if sum(k) == n and (not odd_only or
                                                                 any(i % 2 for i in k))]
        out.append(max(abs(body.integral(*k)) for k in keys) / (M * rho ** n))
    return out


fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
near = np.abs(body_frame[:, 1]) < 40.0                   # vertices near the plane y = 0
left.plot(body_frame[near, 0], body_frame[near, 2], ".", ms=3, color="0.3",
          label="shape model, |y| < 40 m")
t = np.linspace(0, 2 * np.pi, 200)
left.plot(axes[0] * np.cos(t), axes[2] * np.sin(t), color="C1", label="equal-moment ellipsoid")
left.set(xlabel="body x (m)", ylabel="body z (m): spin axis", aspect="equal",
         title="the body frame: section y = 0")
left.legend(loc="lower right", fontsize=8)
degrees = np.arange(2, 13)
right.semilogy(degrees, largest(didymos), "o-", label="polyhedron")
right.semilogy(degrees[1:], largest(didymos, odd_only=True)[1:], "s--",   # none at degree 2
               label="polyhedron, odd index")
even = degrees % 2 == 0                                  # an ellipsoid's odd degrees are 0
right.semilogy(degrees[even], np.array(largest(twin))[even], "^:",
               label="equal-moment ellipsoid")
right.set(xlabel="degree l + m + n", ylabel="max |T^lmn| / (M ρ^n)",
          title="integrals by degree")
right.legend(fontsize=8)
plt.show()

# %%
# In a binary: the catalogue's "Didymos (radar shape)" puts this primary (integrals to
# order 12) with Dimorphos as an ellipsoid on the orbit of the "Didymos" entry. The
# truncation error of the mutual force and torques at pericentre shows what order the
# shape needs: order 4 (the paper's) leaves a few per cent in the torque on the primary.

from ti_spinorbit.model.truncation import truncation

system = tso.catalog.system("Didymos (radar shape)")
print(system)
print(truncation(system, orders=(2, 4, 6, 8)))
