"""Plain NumPy reference for the mutual potential, force, torques and equations of motion.

This module is the slow, readable yardstick the Taichi kernels are checked against. It takes
a deliberately different route from the kernels, so the two cannot share a mistake:

* the kernels evaluate the explicit scalar formulas of docs/physics.md §3.2–3.5;
* this module uses the general Cartesian Taylor (multipole) form of docs/physics.md §3.1 and docs/physics.md §3,

      U = −G Σ_{n ≤ N} Σ_{k=0..n} (−1)^{n−k} / (k! (n−k)!) ⟨M′_B^(k) ⊗ M_A^(n−k), ∂^n(1/R)⟩,
      ∂^n_{i1..in}(1/R) = (−1)^n (2n−1)!! STF(e_{i1} … e_{in}) / R^{n+1},   e = R/|R|,

  with the symmetric trace-free (STF) derivative tensors built once from Kronecker deltas and
  contracted with einsum/tensordot. The expansion is that of Ashenberg 2007 (CeMDA 99:149) and
  Hou, Scheeres & Xin 2017 (CeMDA 127:369) truncated at total order N ≤ 4.

The force is −∂U/∂R from ∂^{n+1}(1/R). The torques come from the derivative of U with respect to
each body's moment tensors (the general tensor rule of docs/physics.md §3.4): if U holds
⟨W, M^(k)⟩ then rotating that body alone by δθ changes U by −μ·δθ with

      μ_a = k ε_aij W_{i i2..ik} M^(k)_{j i2..ik}.

The equations of motion are Maciejewski's (1995) form in the primary's body frame
(docs/physics.md §4; docs/physics.md §4.1–4.2), integrated with scipy's DOP853.

Conventions (docs/physics.md §1.3–1.4): every vector is in the primary (A) body frame;
R points from A's centre of mass to B's; C (Naidu & Margot's S) takes B-frame vectors to the
A frame; moment tensors are M^(k)_{i..} = ∫ x_i … dm about each body's centre of mass in its
own frame (so first moments vanish); G is always an argument, so any unit system works.
"""

import itertools
import math
from functools import lru_cache

import numpy as np

#: Truncation orders the reference accepts (order 1 would add nothing: first moments vanish).
ORDERS = (0, 2, 3, 4)


def _levi_civita():
    eps = np.zeros((3, 3, 3))
    for i, j, k in itertools.permutations(range(3)):
        eps[i, j, k] = (j - i) * (k - i) * (k - j) / 2  # sign of the permutation (i, j, k)
    return eps


#: Levi-Civita symbol ε_ijk.
LEVI_CIVITA = _levi_civita()


def _double_factorial(n):
    return 1 if n <= 0 else n * _double_factorial(n - 2)


@lru_cache(maxsize=None)
def _stf_derivative_basis(rank):
    """Matrices P_m, m = rank, rank−2, …, with ∂^rank(1/R) = R^{−(rank+1)} Σ_m P_m · e^{⊗m}.

    ∂^l(1/R) = (−1)^l (2l−1)!! STF(e^{⊗l}) / R^{l+1}, and for a unit vector
    (2l−1)!! STF(e^{⊗l}) = Σ_k (−1)^k (2l−2k−1)!! {δ^k e^{l−2k}}, where {…} sums the
    l!/(2^k k! (l−2k)!) distinct index placements. Each placement sum is built as that count
    times the full symmetrisation of δ_{i1 i2}…δ_{i(2k−1) i2k} δ_{i(2k+1) j1}…δ_{il jm}; the
    j indices are then contracted with e^{⊗m} at run time. Returns ((m, P_m), …) with P_m of
    shape (3**rank, 3**m)."""
    basis = []
    for k in range(rank // 2 + 1):
        m = rank - 2 * k
        pairs = np.ones(())
        for _ in range(k + m):
            pairs = np.multiply.outer(pairs, np.eye(3))
        # axes: delta pair p < k -> (2p, 2p+1) both free; link pair p >= k -> (2p free, 2p+1 = j)
        free_axes = list(range(2 * k)) + [2 * p for p in range(k, k + m)]
        link_axes = [2 * p + 1 for p in range(k, k + m)]
        base = np.transpose(pairs, free_axes + link_axes)
        sym = np.zeros_like(base)
        for perm in itertools.permutations(range(rank)):
            sym += np.transpose(base, list(perm) + list(range(rank, rank + m)))
        sym /= math.factorial(rank)
        placements = math.factorial(rank) // (2**k * math.factorial(k) * math.factorial(m))
        coefficient = (-1) ** (rank + k) * _double_factorial(2 * rank - 2 * k - 1) * placements
        basis.append((m, (coefficient * sym).reshape(3**rank, 3**m)))
    return tuple(basis)


def inverse_distance_derivatives(R, max_rank):
    """The derivative tensors ∂^l(1/|R|), l = 0..max_rank, as full symmetric arrays (3,)*l.

    They are trace-free (1/R is harmonic away from 0); the tests check that and that each is
    the gradient of the one before."""
    R = np.asarray(R, dtype=np.float64)
    r = float(np.linalg.norm(R))
    e = R / r
    powers = [np.ones(1)]  # e^{⊗m}, flattened
    for _ in range(max_rank):
        powers.append(np.multiply.outer(powers[-1], e).ravel())
    tensors = []
    for rank in range(max_rank + 1):
        flat = sum(P @ powers[m] for m, P in _stf_derivative_basis(rank))
        tensors.append(flat.reshape((3,) * rank) / r ** (rank + 1))
    return tensors


def rotate_tensor(T, C):
    """Rotate a rank-k Cartesian tensor: T′_{i1..ik} = C_{i1 a1} … C_{ik ak} T_{a1..ak}."""
    T = np.asarray(T, dtype=np.float64)
    for _ in range(T.ndim):
        # contracts the leading axis with C's second index and appends the result as last axis
        T = np.tensordot(T, C, axes=(0, 1))
    return T


def _contract_leading(D, T):
    """Contract the leading T.ndim axes of the symmetric tensor D with T."""
    k = T.ndim
    return (T.ravel() @ D.reshape(3**k, -1)).reshape(D.shape[k:])


def _moment_list(mass, tensors):
    J, S3, S4 = (np.asarray(t, dtype=np.float64) for t in tensors)
    if J.shape != (3, 3) or S3.shape != (3, 3, 3) or S4.shape != (3, 3, 3, 3):
        raise ValueError("tensors must be (J, S3, S4) with shapes (3,3), (3,3,3), (3,3,3,3); "
                         f"got {J.shape}, {S3.shape}, {S4.shape}")
    return [np.array(float(mass)), np.zeros(3), J, S3, S4]


def _torque(W, M):
    """μ_a = k ε_aij W_{i..} M_{j..} for a rank-k moment M and its coefficient tensor W."""
    k = M.ndim
    if k == 0:
        return np.zeros(3)
    X = W.reshape(3, -1) @ M.reshape(3, -1).T
    return k * np.einsum("aij,ij->a", LEVI_CIVITA, X)


def mutual_potential(G, mass_a, tensors_a, mass_b, tensors_b, R, C, order=4):
    """Truncated mutual potential energy of two rigid bodies, with force and torques.

    Parameters
    ----------
    G : float
        Gravitational constant in the caller's units.
    mass_a, mass_b : float
        Masses of the primary A and the secondary B.
    tensors_a, tensors_b : tuple of arrays
        ``(J, S3, S4)``: full second, third and fourth moment tensors ∫x⊗x dm, ∫x⊗x⊗x dm,
        ∫x⊗x⊗x⊗x dm of each body about its centre of mass, in that body's own frame (they need
        not be principal).
    R : (3,) array
        Position of B's centre of mass relative to A's, A frame.
    C : (3, 3) array
        Rotation taking B-frame vectors to the A frame.
    order : {0, 2, 3, 4}
        Keep every term of total order n ≤ order (order 4 includes the J_A ⊗ J_B term).

    Returns
    -------
    U : float
        Potential energy (negative), −G ∫∫ dm_A dm_B / |R + C r_B − r_A| truncated.
    force_on_b : (3,) array
        −∂U/∂R, the force on B (A gets the opposite).
    torque_a, torque_b : (3,) arrays
        Torques on A and B about their centres of mass, A frame, defined by δU = −μ·δθ for an
        infinitesimal rotation δθ of that body alone. R × force_on_b + torque_a + torque_b = 0.
    """
    if order not in ORDERS:
        raise ValueError(f"order must be one of {ORDERS} (got {order!r})")
    R = np.asarray(R, dtype=np.float64)
    C = np.asarray(C, dtype=np.float64)
    if R.shape != (3,) or C.shape != (3, 3):
        raise ValueError(f"R must have shape (3,) and C shape (3, 3); got {R.shape}, {C.shape}")
    moments_a = _moment_list(mass_a, tensors_a)
    moments_b = [rotate_tensor(M, C) for M in _moment_list(mass_b, tensors_b)]
    D = inverse_distance_derivatives(R, order + 1)

    U = 0.0
    dU_dR = np.zeros(3)
    W_a = [np.zeros((3,) * k) for k in range(order + 1)]  # ∂U/∂M_A^(k)
    W_b = [np.zeros((3,) * k) for k in range(order + 1)]  # ∂U/∂M′_B^(k)
    for n in range(order + 1):
        for k in range(n + 1):           # k: rank of B's moment, n − k: rank of A's
            if k == 1 or n - k == 1:     # first moments about the centre of mass vanish
                continue
            weight = -G * (-1) ** (n - k) / (math.factorial(k) * math.factorial(n - k))
            Mb, Ma = moments_b[k], moments_a[n - k]
            both = np.multiply.outer(Mb, Ma)
            U += weight * float(both.ravel() @ D[n].ravel())
            dU_dR += weight * _contract_leading(D[n + 1], both)
            # D[n] is symmetric, so either body's slots may be contracted first
            W_b[k] = W_b[k] + weight * _contract_leading(D[n], Ma)
            W_a[n - k] = W_a[n - k] + weight * _contract_leading(D[n], Mb)
    torque_a = sum(_torque(W_a[k], moments_a[k]) for k in range(order + 1))
    torque_b = sum(_torque(W_b[k], moments_b[k]) for k in range(order + 1))
    return U, -dU_dR, torque_a, torque_b


def body_tensors(body):
    """``(J, S3, S4)`` of a :class:`ti_spinorbit.system.bodies.Body`, in its own frame."""
    return tuple(body.moment_tensor(k) for k in (2, 3, 4))


def inertia_tensor(J):
    """Inertia tensor I = tr(J)·1 − J from the second moment tensor J."""
    J = np.asarray(J, dtype=np.float64)
    return np.trace(J) * np.eye(3) - J


def _hat(v):
    """Cross-product matrix: _hat(v) @ w = v × w."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def unpack_state(y):
    """Split the 30-element state into R, P, Γ1, Γ2, S (3×3), S1 (3×3)."""
    y = np.asarray(y, dtype=np.float64)
    if y.shape != (30,):
        raise ValueError(f"state must have 30 elements (got shape {y.shape})")
    return y[0:3], y[3:6], y[6:9], y[9:12], y[12:21].reshape(3, 3), y[21:30].reshape(3, 3)


class _Pair:
    """Everything about two bodies the right-hand side needs, computed once."""

    def __init__(self, body_a, body_b):
        self.mass_a, self.mass_b = float(body_a.mass), float(body_b.mass)
        self.tensors_a, self.tensors_b = body_tensors(body_a), body_tensors(body_b)
        self.reduced_mass = self.mass_a * self.mass_b / (self.mass_a + self.mass_b)
        self.inertia_a = inertia_tensor(self.tensors_a[0])
        self.inertia_b = inertia_tensor(self.tensors_b[0])

    def potential(self, G, R, S, order):
        return mutual_potential(G, self.mass_a, self.tensors_a, self.mass_b, self.tensors_b,
                                R, S, order)

    def angular_velocities(self, S, gamma1, gamma2):
        """Ω1 (A frame) and Ω2′ (B frame)."""
        return (np.linalg.solve(self.inertia_a, gamma1),
                np.linalg.solve(self.inertia_b, S.T @ gamma2))

    def rhs(self, G, y, order):
        R, P, gamma1, gamma2, S, S1 = unpack_state(y)
        omega1, omega2_b = self.angular_velocities(S, gamma1, gamma2)
        _, force, torque_a, torque_b = self.potential(G, R, S, order)
        return np.concatenate([
            np.cross(R, omega1) + P / self.reduced_mass,
            np.cross(P, omega1) + force,
            np.cross(gamma1, omega1) + torque_a,
            np.cross(gamma2, omega1) + torque_b,
            (S @ _hat(omega2_b) - _hat(omega1) @ S).ravel(),
            (S1 @ _hat(omega1)).ravel(),
        ])

    def energy(self, G, y, order):
        R, P, gamma1, gamma2, S, _ = unpack_state(y)
        omega1, omega2_b = self.angular_velocities(S, gamma1, gamma2)
        U = self.potential(G, R, S, order)[0]
        parts = {
            "orbit": float(P @ P) / (2.0 * self.reduced_mass) + U,
            "primary_spin": 0.5 * float(gamma1 @ omega1),
            "secondary_spin": 0.5 * float((S.T @ gamma2) @ omega2_b),
        }
        parts["total"] = parts["orbit"] + parts["primary_spin"] + parts["secondary_spin"]
        return parts


def rhs(G, body_a, body_b, y, order=4):
    """Time derivative of the 30-element state (Maciejewski 1995; docs/physics.md §4).

    y = [R (3), P (3), Γ1 (3), Γ2 (3), S (3×3 row-major), S1 (3×3 row-major)], all vectors in
    the primary frame: R the relative position, P = m·(relative velocity) with reduced mass
    m = m_A m_B/(m_A + m_B), Γ1 and Γ2 the spin angular momenta, S the secondary-to-primary
    rotation, S1 the primary-to-inertial rotation.

        Ṙ = R × Ω1 + P/m        Ṗ = P × Ω1 − ∂U/∂R
        Γ̇1 = Γ1 × Ω1 + μ1       Γ̇2 = Γ2 × Ω1 + μ2
        Ṡ = S Ω̂2′ − Ω̂1 S        Ṡ1 = S1 Ω̂1,     Ω1 = I_A⁻¹ Γ1,  Ω2′ = I_B⁻¹ Sᵀ Γ2.
    """
    return _Pair(body_a, body_b).rhs(G, y, order)


def energy(G, body_a, body_b, y, order=4):
    """Energy split ``{'orbit', 'primary_spin', 'secondary_spin', 'total'}`` of a state.

    orbit = |P|²/2m + U, primary_spin = ½ Γ1·Ω1, secondary_spin = ½ (SᵀΓ2)·Ω2′."""
    return _Pair(body_a, body_b).energy(G, y, order)


def angular_momentum(body_a, body_b, y):
    """Inertial-frame angular momenta ``{'orbit', 'primary_spin', 'secondary_spin', 'total'}``.

    orbit = S1 (R × P) (the relative orbit about the barycentre), primary_spin = S1 Γ1,
    secondary_spin = S1 Γ2. The bodies are not needed; they are kept in the signature so it
    matches :func:`energy`."""
    R, P, gamma1, gamma2, _, S1 = unpack_state(y)
    parts = {"orbit": S1 @ np.cross(R, P), "primary_spin": S1 @ gamma1,
             "secondary_spin": S1 @ gamma2}
    parts["total"] = parts["orbit"] + parts["primary_spin"] + parts["secondary_spin"]
    return parts


def integrate(G, body_a, body_b, y0, t_span, rtol, atol, order=4, t_eval=None):
    """Integrate :func:`rhs` with scipy's DOP853; returns scipy's ``OdeResult``.

    scipy is imported here only: it is a test-time dependency of the package."""
    from scipy.integrate import solve_ivp      # scipy: optional (tests only), imported here

    pair = _Pair(body_a, body_b)
    return solve_ivp(lambda t, y: pair.rhs(G, y, order), t_span, np.asarray(y0, dtype=np.float64),
                     method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval)
