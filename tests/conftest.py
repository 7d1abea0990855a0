"""Shared fixtures: one Taichi runtime per test session (arch from TI_SPINORBIT_ARCH, CPU by
default), and small systems used across the suite."""

import numpy as np
import pytest

import ti_spinorbit as tso


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


def lumpy_body(rng, n=40, scale=1.0, mass=1.0):
    """A point-cloud body with non-zero odd integrals, in its principal frame."""
    pts = rng.normal(size=(n, 3)) * np.array([1.0, 0.7, 0.5]) * scale
    pts[: n // 3] += np.array([0.4, 0.2, -0.1]) * scale  # break mirror symmetry
    m = rng.uniform(0.5, 1.5, n)
    body, _ = tso.Body.from_point_masses(pts, m * mass / m.sum())
    return body
