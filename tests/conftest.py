"""Shared fixtures: one Taichi runtime per test session (arch from TI_SPINORBIT_ARCH, CPU by
default), small systems used across the suite, and 1991 VH with one cheap result of every
kind (module scope, like the per-file fixtures they replace)."""

import dataclasses
import math
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import ti_spinorbit as tso


#: The keywords an entry point takes inside its ``run=tso.Run(...)``.
RUN_FIELDS = frozenset(f.name for f in dataclasses.fields(tso.Run))


def run_options(**kw):
    """Keywords of an entry point with the run options among them (progress, checkpoint,
    resume, overwrite, window_orbits, ...) gathered into ``run=tso.Run(...)``: tests that
    vary one run option per case write it as a keyword."""
    run = {k: kw.pop(k) for k in list(kw) if k in RUN_FIELDS}
    return {**kw, "run": tso.Run(**run)}


def run_cli(*args, cwd, env=None, timeout=600):
    """``python -m ti_spinorbit ARGS`` in a fresh process (Agg backend; ``env`` adds to or
    overrides the environment); the CompletedProcess with text stdout and stderr."""
    env = {**os.environ, "MPLBACKEND": "Agg", **(env or {})}
    return subprocess.run([sys.executable, "-m", "ti_spinorbit", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="session", autouse=True)
def taichi_runtime():
    """Initialise once; a GPU arch that is not there fails loudly (no silent CPU fallback)."""
    return tso.init()


@pytest.fixture
def rng():
    return np.random.default_rng(20150080)


def random_rotation(rng):
    """A uniformly random proper rotation matrix (QR of a Gaussian matrix)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


def cloud(rng, n, scale, mass, order):
    """Integrals (a dict, degrees 0..order) of n point masses of total ``mass`` about their
    centre of mass, spread ``scale`` × (1, 0.7, 0.5): a body with odd integrals and no
    symmetry (first moments set to exact zeros)."""
    from ti_spinorbit.system import integrals as I
    pts = rng.normal(size=(n, 3)) * np.array([1.0, 0.7, 0.5]) * scale
    m = rng.uniform(0.5, 1.5, n)
    m *= mass / m.sum()
    pts -= (m[:, None] * pts).sum(0) / mass
    T = I.point_mass_integrals(pts, m, order)
    return {k: (0.0 if sum(k) == 1 else v) for k, v in T.items()}


def axis_rotation(axis, angle):
    """The rotation by ``angle`` (rad) about coordinate axis 0, 1 or 2."""
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    Q = np.eye(3)
    Q[i, i] = Q[j, j] = c
    Q[j, i], Q[i, j] = s, -s
    return Q


def degenerate_geometries(rng, scale=1.0):
    """(R, C) pairs (R in units of ``scale``) where the line-of-centres angles of the
    order-N potential degenerate: R along ±z (no azimuth), the secondary's z axis along the
    line of centres (β = 0) or against it (β = π), the planar model's geometry (R in the
    plane, C a z-rotation or the identity), and generic ones."""
    out = [((0.0, 0.0, 1.7), np.eye(3)), ((0.0, 0.0, -1.7), random_rotation(rng)),
           ((1.3, 0.8, 0.0), axis_rotation(2, 0.7)), ((1.3, 0.8, 0.0), np.eye(3)),
           ((0.0, 1.6, 0.0), axis_rotation(0, math.pi)), ((0.9, 1.2, -0.4), random_rotation(rng))]
    for R, flip in (((1.1, -0.6, 0.9), 1.0), ((-0.5, 0.7, 1.3), -1.0)):   # β = 0 and β = π
        z = flip * np.asarray(R) / np.linalg.norm(R)
        x = np.cross(z, [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        out.append((R, np.column_stack([x, np.cross(z, x), z])))
    return [(scale * np.asarray(R, dtype=float), C) for R, C in out]


def lumpy_body(rng, n=40, scale=1.0, mass=1.0):
    """A point-cloud body with non-zero odd integrals, in its principal frame."""
    pts = rng.normal(size=(n, 3)) * np.array([1.0, 0.7, 0.5]) * scale
    pts[: n // 3] += np.array([0.4, 0.2, -0.1]) * scale  # break mirror symmetry
    m = rng.uniform(0.5, 1.5, n)
    body, _ = tso.Body.from_point_masses(pts, m * mass / m.sum())
    return body


# ---- 1991 VH and one cheap result of every kind (tests of io, display, ...) -----------------
@pytest.fixture(scope="module")
def vh():
    return tso.catalog.system("1991 VH")


@pytest.fixture(scope="module")
def section(vh):
    return tso.surface_of_section(vh, 0.0, [0.83, 1.63], orbits=3, rtol=1e-9)


@pytest.fixture(scope="module")
def many(vh):
    """A section of 12 members (above plotting.MAX_LEGEND): a colourbar of the start, not a
    legend."""
    return tso.surface_of_section(vh, 0.0, np.linspace(0.8, 1.9, 12), orbits=2, rtol=1e-9)


@pytest.fixture(scope="module")
def time_series(vh):
    return tso.time_series(vh, 0.0, [0.83, 1.63], orbits=2, samples_per_orbit=8, rtol=1e-9)


@pytest.fixture(scope="module")
def chaos_map(vh):
    return tso.chaos_map(vh, [30.0, 120.0], [0.8, 1.6], orbits=3)


@pytest.fixture(scope="module")
def parameter_map():
    return tso.parameter_map("1991 VH", [1.2, 1.4], [0.05, 0.1], orbits=3, theta_p=[0.0],
                             thetadot_p=[1.0, 1.5])


@pytest.fixture(scope="module")
def overlap_scan():
    return tso.overlap_threshold("2004 DC", elongations=[1.01, 1.03], orbits=5, centre_starts=6,
                                 separatrix_starts=4)


@pytest.fixture(scope="module")
def relaxed_libration(vh):
    with warnings.catch_warnings():      # 3 orbits and one zoom: not converged, on purpose
        warnings.simplefilter("ignore", RuntimeWarning)
        return tso.relaxed_libration(vh, orbits=3, candidates=np.linspace(0.2, 1.3, 9),
                                     zoom_candidates=5, max_iterations=1, samples_per_orbit=16)
