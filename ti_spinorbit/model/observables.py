"""Observables derived from recorded scaled states (NumPy; docs/physics.md §6, §9.1).

The kernels record the raw 30-element state at events and samples; everything a scientist
reads is derived here, vectorised over records:

* α: angle from the line of centres to the secondary's long axis, measured about the orbit
  normal (R × V), in (−π, π]: α = θ − f, so at pericentre α is the section angle θ_p.
  (Naidu & Margot's diagram, docs/physics.md §6.2, writes θ + α = f, i.e. the opposite sign;
  amplitudes are the same.)
* θ̇: the secondary's inertial spin rate about the orbit normal, units of n.
* θ: the long axis's angle from the inertial x axis (the initial pericentre direction) in the
  inertial xy plane (the initial orbit plane).
* r, osculating a and e of the relative Kepler orbit with μ = G(m1 + m2) (scaled units).
"""

import numpy as np

from ..layout import spatial as _S   # state offsets and columns (no Taichi)


def _vec(states, offset):
    return states[:, offset:offset + 3]


def _mat(states, offset):
    return states[:, offset:offset + 9].reshape(-1, 3, 3)


def secondary_angular_velocity(par, states):
    """Ω2 in primary-frame components (scaled), for states (M, 30) with rows par (M, NPAR)."""
    S = _mat(states, _S.Y_S)
    w2 = _vec(states, _S.Y_W2)
    w2b = np.einsum("mji,mj->mi", S, w2) * par[:, _S.P_IB:_S.P_IB + 3]
    return np.einsum("mij,mj->mi", S, w2b)


def derive(par, states):
    """Dict of arrays (M,): alpha (rad), thetadot (n), theta (rad), r, a, e (scaled)."""
    states = np.atleast_2d(states)
    par = np.broadcast_to(par, (len(states), par.shape[-1]))
    R = _vec(states, _S.Y_R)
    V = _vec(states, _S.Y_V)
    S = _mat(states, _S.Y_S)
    S1 = _mat(states, _S.Y_S1)
    h = np.cross(R, V)
    normal = h / np.linalg.norm(h, axis=1)[:, None]
    r = np.linalg.norm(R, axis=1)
    rhat = R / r[:, None]
    xb = S[:, :, 0]
    alpha = np.arctan2(np.einsum("mi,mi->m", normal, np.cross(rhat, xb)),
                       np.einsum("mi,mi->m", rhat, xb))
    thetadot = np.einsum("mi,mi->m", secondary_angular_velocity(par, states), normal)
    x_inertial = np.einsum("mij,mj->mi", S1, xb)
    theta = np.arctan2(x_inertial[:, 1], x_inertial[:, 0])
    eps = 0.5 * np.einsum("mi,mi->m", V, V) - 1.0 / r
    with np.errstate(divide="ignore"):
        a = -0.5 / eps
    e = np.sqrt(np.maximum(0.0, 1.0 + 2.0 * eps * np.einsum("mi,mi->m", h, h)))
    return {"alpha": alpha, "thetadot": thetadot, "theta": theta, "r": r, "a": a, "e": e}
