"""Python access to the kernels' mutual potential (same Taichi code path as the integrator).

``mutual_potential(primary, secondary, R, S, order=4)`` evaluates, in SI units and in the
primary's frame, the truncated mutual potential of docs/physics.md §3 (Ashenberg 2007; Hou et al.
2017) for one configuration or a batch (R of shape (..., 3), S of shape (..., 3, 3)).
"""

import numpy as np

from . import runtime
from ._validate import require_finite, require_order
from .bodies import Body, odd_columns
from .layout import ROW_LENGTH
from .systems import G


def mutual_potential(primary: Body, secondary: Body, R, S, order: int = 4):
    """Mutual potential energy, force on the secondary and torques, SI, primary frame.

    Parameters
    ----------
    primary, secondary : Body
    R : array (..., 3)
        Secondary's centre of mass relative to the primary's, m, primary frame.
    S : array (..., 3, 3)
        Rotation taking secondary-frame vectors to the primary frame: orthonormal
        (|S^T S − 1| <= 1e-9) and proper (det S = +1; a reflection is no rigid motion).
    order : {0, 2, 3, 4}
        Truncation order.

    Returns
    -------
    (V, F, torque_primary, torque_secondary)
        V in J; F = −∂V/∂R the force on the secondary, N; torques about each body's centre of
        mass, N m (δV = −torque·δθ for an infinitesimal rotation of that body alone).
    """
    from .kernels import eom          # Taichi: imported on first use
    from .kernels import advance as K

    for label, body in (("primary", primary), ("secondary", secondary)):
        if not isinstance(body, Body):
            raise TypeError(f"{label} must be a ti_spinorbit Body (Sphere, Ellipsoid, Body) "
                            f"(got {type(body).__name__})")
    order = require_order(order)
    # checked before the conversion, so text is a TypeError naming R or S
    R = np.asarray(require_finite("R", R), dtype=np.float64)
    S = np.asarray(require_finite("S", S), dtype=np.float64)
    if R.shape[-1:] != (3,) or S.shape[-2:] != (3, 3) or R.shape[:-1] != S.shape[:-2]:
        raise ValueError(f"R must be (..., 3) and S (..., 3, 3) with matching batch shapes "
                         f"(got {R.shape} and {S.shape})")
    if not np.allclose(np.einsum("...ji,...jk->...ik", S, S), np.eye(3), atol=1e-9):
        raise ValueError("S must be a rotation matrix (S^T S = 1)")
    det = np.linalg.det(S) if S.size else np.ones(0)
    if np.any(det < 0):
        raise ValueError(f"S must be a proper rotation matrix, det S = +1 (got det S = "
                         f"{float(np.min(det)):.6g}: a reflection)")
    # the expansion converges only outside the bodies' bounding spheres (R = 0 gave NaN)
    contact = primary.bounding_radius + secondary.bounding_radius
    closest = float(np.min(np.linalg.norm(R, axis=-1))) if R.size else np.inf
    if closest <= contact:
        raise ValueError(f"bodies overlap: |R| = {closest:.6g} m must exceed the sum of "
                         f"bounding radii ({contact:.6g} m)")
    batch = R.shape[:-1]
    Rf = np.ascontiguousarray(R.reshape(-1, 3))
    Sf = np.ascontiguousarray(S.reshape(-1, 3, 3))
    par = np.zeros((len(Rf), eom.NPAR))
    par[:, eom.BODY_A:eom.BODY_A + ROW_LENGTH] = primary.as_row()
    par[:, eom.BODY_B:eom.BODY_B + ROW_LENGTH] = secondary.as_row()
    odd = bool(np.any(par[:, odd_columns(ROW_LENGTH)] != 0.0))
    runtime.ensure_init()
    out = np.zeros((len(Rf), 10))
    K.evaluate_mutual(par, Rf, Sf, out, G, int(order), odd)
    V = out[:, 0].reshape(batch)
    F = -out[:, 1:4].reshape(batch + (3,))
    return V, F, out[:, 4:7].reshape(batch + (3,)), out[:, 7:10].reshape(batch + (3,))
