"""The package's own quaternion, rotation-matrix and Euler-angle conversions against scipy's
``Rotation`` (an oracle here; the package keeps its three short conversions so that scipy
stays a test dependency, and because its scalar-first (w, x, y, z) quaternions are those of the
kernels: ``ti_spinorbit.system.initial``, "Rotations")."""

import numpy as np
import pytest

from ti_spinorbit.model.attitude import _euler
from ti_spinorbit.system.initial import matrix_to_quaternion, quaternion_to_matrix, rotation

Rotation = pytest.importorskip("scipy.spatial.transform").Rotation


def random_rotations(n=200, seed=5):
    return Rotation.random(n, random_state=seed)


def test_quaternion_to_matrix_and_back_agree_with_scipy():
    for r in random_rotations():
        x, y, z, w = r.as_quat()                       # scipy: scalar last
        M = quaternion_to_matrix([w, x, y, z])
        np.testing.assert_allclose(M, r.as_matrix(), atol=2e-15)
        q = matrix_to_quaternion(r.as_matrix())
        ref = np.array([w, x, y, z]) * (1.0 if w >= 0 else -1.0)
        np.testing.assert_allclose(q, ref, atol=3e-15)


def test_matrix_to_quaternion_near_half_turns():
    """Shepperd's method stays accurate at 180° turns, where the trace form loses w."""
    for axis in np.eye(3):
        r = Rotation.from_rotvec((np.pi - 1e-9) * axis)
        q = matrix_to_quaternion(r.as_matrix())
        np.testing.assert_allclose(quaternion_to_matrix(q), r.as_matrix(), atol=2e-15)


def test_axis_rotations_and_euler_angles_agree_with_scipy():
    """rotation(axis, angle) is scipy's right-handed rotation about that axis; the
    (roll, pitch, yaw) of Rz(yaw) Ry(pitch) Rx(roll) are scipy's intrinsic "ZYX" angles."""
    for k, name in enumerate("xyz"):
        np.testing.assert_allclose(rotation(k, 0.7), Rotation.from_euler(name, 0.7).as_matrix(),
                                   atol=1e-15)
    rots = random_rotations()
    ours = _euler(rots.as_matrix())
    yaw, pitch, roll = rots.as_euler("ZYX", degrees=True).T
    np.testing.assert_allclose(ours, np.stack([roll, pitch, yaw], axis=-1), atol=1e-10)
