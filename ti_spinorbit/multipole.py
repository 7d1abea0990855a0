"""Mutual potential, force and torques of two rigid bodies at any truncation order (NumPy only).

This is the host-side reference for the full two-body problem at orders beyond the fixed
order-4 formulas of the Taichi kernels. It depends on NumPy alone (no Taichi, nothing else from
the package) so that it can be imported, tested and reused anywhere.

Formulation (Cartesian multipole–multipole expansion)
-----------------------------------------------------
Every vector is in body A's frame. R (m) points from A's centre of mass to B's; C takes B-frame
vectors to the A frame. A body is described by its inertia integrals

    T^α = ∫ x^α dm = ∫ x^l y^m z^n dm,   α = (l, m, n), |α| = l + m + n,

about its centre of mass in its own frame (SI: kg m^|α|). B's integrals are first carried into
A's frame,

    T'_B^β = ∫_B (C x)^β dm,

exactly: (C x)^β = Π_i (Σ_j C_ij x_j)^{β_i} is expanded as a polynomial of degree |β| in x (a
linear map on the integrals of each degree, built degree by degree from the one below).

With ρ = C x_B − x_A the separation of two mass elements minus R, Taylor's theorem gives
1/|R + ρ| = Σ_γ a_γ(R) ρ^γ, where a_γ(R) = ∂^γ(1/|R|)/γ! (multi-index factorial
γ! = γ_1! γ_2! γ_3!), and the multinomial expansion of ρ^γ = (x'_B − x_A)^γ splits each term
between the two bodies. Keeping every term of total degree |α| + |β| ≤ N:

    U_N = −G Σ_{|α|+|β| ≤ N} (−1)^{|α|} (α+β)!/(α! β!) T_A^α T'_B^β a_{α+β}(R).

The degree-n part of this double sum is exactly the degree-n Legendre term
|ρ|^n P_n(−R̂·ρ̂)/|R|^{n+1} integrated over both bodies, so U_N is the classical truncated
mutual potential (Hou, Scheeres & Xin 2017, Celest. Mech. Dyn. Astron. 127:369, in its
inertia-integral form; Tricarico 2008, Celest. Mech. Dyn. Astron. 100:319, for the same
Cartesian multipole–multipole structure; Boué & Laskar 2009, Icarus 201:750, for the
expansion of the full two-body problem in the bodies' multipoles). It converges when every
|C x_B − x_A| < |R|, i.e. whenever the bodies' bounding spheres about their centres of mass
are disjoint (|R| > ρ_A + ρ_B); this module does not check that (it does not know the radii).

The coefficients a_γ follow from the recurrence (n = |γ| ≥ 1, terms with a negative index
are zero, a_0 = 1/|R|)

    n |R|² a_γ = −(2n − 1) Σ_i R_i a_{γ−e_i} − (n − 1) Σ_i a_{γ−2e_i},

obtained from |R|² ∂(1/|R|) = −R/|R| by Leibniz' rule. They are evaluated at the unit vector
R/|R| and the integrals are scaled by |R|^{−|α|}, so no power of a length overflows.

Force and torques
-----------------
* Force on B (N, A frame): F = −∂U/∂R with ∂a_γ/∂R_i = (γ_i + 1) a_{γ+e_i} (a is needed up to
  degree N + 1). A feels −F.
* Torque on B about its centre of mass (N m, A frame): rotating B alone by a small angle vector
  ε changes its points x' = C x_B by ε × x', hence

      ∂T'_B^β/∂ε_d = Σ_{c,e} ε_{cde} β_c T'_B^{β−e_c+e_e}     (ε_{cde}: Levi-Civita),

  and τ_B = −∂U/∂ε = G Σ_β V_B^β ∂T'_B^β/∂ε, V_B^β = Σ_α (−1)^{|α|} (α+β)!/(α!β!) T_A^α a_{α+β}.
  The same generator acting on T_A gives the torque on A (about A's centre of mass) for a
  rotation of A alone, computed independently of B's; R × F + τ_A + τ_B = 0 (conservation of
  angular momentum, the truncated U being rotation invariant) then holds to round-off and is
  a check, not an input. Sign convention: δU = −τ·ε for an infinitesimal rotation ε of that
  body alone (as in ``ti_spinorbit.mutual_potential``).

Degree caps and integral sets
-----------------------------
``degrees=(dA, dB)`` keeps only |α| ≤ dA and |β| ≤ dB (e.g. a secondary described to degree 2
only); the default is no cap beyond ``order``.

An integral set is a mapping {(l, m, n): T^lmn}. It must hold the mass (key (0, 0, 0), > 0).
The degree a set PROVIDES is the largest l + m + n among its keys (a key with value 0 counts:
it states that the integral is zero). Within the provided degree a missing key is zero (e.g.
the vanishing first moments about the centre of mass, or the odd integrals of a symmetric
body). A set whose provided degree is below the degree needed, min(order, cap), is refused
(ValueError naming the body and the degree it lacks), so that a truncated description never
silently drops terms; pass a cap in ``degrees`` or ``allow_lower_degree=True`` to accept it
(all higher integrals then taken as zero). Keys above the needed degree are ignored. Non-zero
first moments are accepted: the expansion is then about each frame's origin, R joins the
origins and the torques are about them.

Cost: index tables are built once per (order, degrees) and cached; an evaluation is a few
vectorised gathers over the ~C(N+6, 6) pairs (α, β) (18 564 at N = 12, 74 613 at N = 16),
about a millisecond at N = 12. Everything is float64.
"""

import math
import numbers
from collections.abc import Mapping
from functools import lru_cache

import numpy as np

__all__ = [
    "MAX_ORDER", "G_SI", "multi_indices", "rotate_integrals", "inverse_distance_coefficients",
    "mutual_potential_order_n", "mutual_force_torque",
]

#: Largest truncation order accepted (index tables grow as C(N+6, 6)).
MAX_ORDER = 16

#: Default gravitational constant, m^3 kg^-1 s^-2 (CODATA 2018, the package's ``G``).
G_SI = 6.67430e-11

#: Levi-Civita symbol as (d, c, e, sign) with ε_{cde} = sign ≠ 0.
_LEVI = tuple((d, c, e, s) for d in range(3)
              for (c, e, s) in (((d + 1) % 3, (d + 2) % 3, -1.0), ((d + 2) % 3, (d + 1) % 3, 1.0)))
# ε_{c d e} with (c, d, e) = (d+1, d, d+2) is an odd permutation of (d, d+1, d+2): −1.


# ---- index tables -----------------------------------------------------------------------------
def _count(degree):
    """Number of monomials x^l y^m z^n with l + m + n ≤ degree."""
    return (degree + 1) * (degree + 2) * (degree + 3) // 6


@lru_cache(maxsize=None)
def _table(degree):
    """(exponents (n, 3) int array, lookup (degree+3,)*3 -> flat index or −1, degree offsets).

    Order: by total degree, then l descending, then m descending."""
    exps = [(l, m, d - l - m) for d in range(degree + 1)
            for l in range(d, -1, -1) for m in range(d - l, -1, -1)]
    E = np.array(exps, dtype=np.int64).reshape(-1, 3)
    lookup = np.full((degree + 3,) * 3, -1, dtype=np.int64)
    lookup[E[:, 0], E[:, 1], E[:, 2]] = np.arange(len(E))
    offsets = np.array([_count(d - 1) if d else 0 for d in range(degree + 2)])
    E.setflags(write=False)
    lookup.setflags(write=False)
    return E, lookup, offsets


def _index(E, degree, sentinel):
    """Flat index (in _table(degree)) of each exponent row of E; ``sentinel`` where a component
    is negative or the degree exceeds ``degree``."""
    _, lookup, _ = _table(degree)
    E = np.asarray(E)
    ok = (E >= 0).all(-1) & (E.sum(-1) <= degree)
    safe = np.where(ok[..., None], E, 0)
    return np.where(ok, lookup[safe[..., 0], safe[..., 1], safe[..., 2]], sentinel)


def multi_indices(degree):
    """All exponent triples (l, m, n) with l + m + n ≤ ``degree``, in this module's order, as a
    read-only (count, 3) int array."""
    return _table(int(degree))[0]


@lru_cache(maxsize=None)
def _recurrence_tables(degree):
    """Per degree n = 1..degree: (flat indices of degree n, indices of γ − e_i (n_n, 3), of
    γ − 2e_i (n_n, 3)), with the sentinel _count(degree) pointing at an appended zero."""
    E, _, off = _table(degree)
    sentinel = len(E)
    eye = np.eye(3, dtype=np.int64)
    steps = []
    for n in range(1, degree + 1):
        g = E[off[n]:off[n + 1]]
        down1 = np.stack([_index(g - eye[i], degree, sentinel) for i in range(3)], axis=1)
        down2 = np.stack([_index(g - 2 * eye[i], degree, sentinel) for i in range(3)], axis=1)
        steps.append((off[n], off[n + 1], down1, down2))
    return steps


def _a_unit(u, degree):
    """a_γ(u) for |u| = 1 and |γ| ≤ degree (flat, with one trailing zero slot)."""
    a = np.zeros(_count(degree) + 1)
    a[0] = 1.0
    for n, (lo, hi, down1, down2) in enumerate(_recurrence_tables(degree), start=1):
        a[lo:hi] = (-(2 * n - 1) * (a[down1] @ u) - (n - 1) * a[down2].sum(1)) / n
    return a


@lru_cache(maxsize=None)
def _rotation_tables(degree):
    """Per degree k = 1..degree: (axis i(β) used to peel β, parent index of β − e_i in degree
    k − 1 (local), child indices δ − e_j in degree k − 1 (local, sentinel n_{k−1}) (n_k, 3))."""
    E, _, off = _table(degree)
    eye = np.eye(3, dtype=np.int64)
    tables = []
    for k in range(1, degree + 1):
        g = E[off[k]:off[k + 1]]
        axis = np.argmax(g > 0, axis=1)
        parent = _index(g - eye[axis], degree, -1) - off[k - 1]
        n_prev = off[k] - off[k - 1]
        child = np.stack([_index(g - eye[j], degree, -1) for j in range(3)], axis=1)
        child = np.where(child >= 0, child - off[k - 1], n_prev)
        tables.append((axis, parent, child))
    return tables


def _rotation_blocks(C, degree):
    """Matrices M_k (k = 0..degree) with (C x)^β = Σ_δ M_k[β, δ] x^δ for |β| = |δ| = k."""
    blocks = [np.ones((1, 1))]
    for axis, parent, child in _rotation_tables(degree):
        prev = np.concatenate([blocks[-1], np.zeros((blocks[-1].shape[0], 1))], axis=1)
        rows = prev[parent]                     # coefficients of (C x)^{β − e_i}
        Ci = C[axis]                            # (n_k, 3): row i(β) of C
        blocks.append(sum(Ci[:, j:j + 1] * rows[:, child[:, j]] for j in range(3)))
    return blocks


def _rotate_vector(t, C, degree):
    """Rotate a flat integral vector (degrees 0..degree) by C, exactly."""
    _, _, off = _table(degree)
    out = np.empty_like(t)
    for k, M in enumerate(_rotation_blocks(C, degree)):
        out[off[k]:off[k + 1]] = M @ t[off[k]:off[k + 1]]
    return out


@lru_cache(maxsize=None)
def _generator_tables(degree):
    """For each axis d: two (coefficient array, index array) terms with
    (∂T^β/∂ε_d) = Σ coefficient * T[index]  (index sentinel _count(degree) -> zero)."""
    E, _, _ = _table(degree)
    sentinel = len(E)
    eye = np.eye(3, dtype=np.int64)
    terms = []
    for d in range(3):
        row = []
        for dd, c, e, s in _LEVI:
            if dd != d:
                continue
            coef = s * E[:, c].astype(np.float64)
            idx = _index(E - eye[c] + eye[e], degree, sentinel)
            row.append((coef, idx))
        terms.append(tuple(row))
    return tuple(terms)


def _generator(t, degree):
    """(3, n) array: ∂T^β/∂ε_d for a rotation x → x + ε × x of the body (t flat, with a trailing
    zero slot appended here)."""
    tz = np.append(t, 0.0)
    return np.stack([sum(coef * tz[idx] for coef, idx in _generator_tables(degree)[d])
                     for d in range(3)])


@lru_cache(maxsize=64)
def _pair_tables(order, dA, dB):
    """Index tables of the pairs (α, β), |α| ≤ dA, |β| ≤ dB, |α| + |β| ≤ order:
    ia, ib (flat indices into A's and B's integral vectors), ig (index of γ = α + β in the
    a-table of degree order + 1), coefficient (−1)^{|α|} (α+β)!/(α!β!), and up (P, 3): the index
    of γ + e_i, (3, P), with the factor (γ_i + 1) in gp1 (3, P)."""
    EA = _table(dA)[0]
    EB = _table(dB)[0]
    total = EA.sum(1)[:, None] + EB.sum(1)[None, :]
    ia, ib = np.nonzero(total <= order)
    alpha, beta = EA[ia], EB[ib]
    gamma = alpha + beta
    top = order + 1
    ig = _index(gamma, top, -1)
    binom = np.array([[math.comb(n, k) for k in range(top + 1)] for n in range(top + 1)],
                     dtype=np.float64)
    coef = np.prod(binom[gamma, alpha], axis=1) * (-1.0) ** alpha.sum(1)
    eye = np.eye(3, dtype=np.int64)
    up = np.ascontiguousarray(np.stack([_index(gamma + eye[i], top, -1) for i in range(3)]))
    gp1 = np.ascontiguousarray((gamma + 1).T.astype(np.float64))
    out = (ia, ib, ig, coef, up, gp1)
    for arr in out:
        arr.setflags(write=False)
    return out


# ---- validation ---------------------------------------------------------------------------------
def _check_order(order):
    if isinstance(order, bool) or not isinstance(order, numbers.Integral) \
            or not 0 <= int(order) <= MAX_ORDER:
        raise ValueError(f"order must be an integer in [0, {MAX_ORDER}] (got {order!r})")
    return int(order)


def _check_degrees(degrees, order):
    if degrees is None:
        return order, order
    try:
        caps = tuple(degrees)
    except TypeError:
        caps = None
    if caps is None or len(caps) != 2 or any(
            isinstance(d, bool) or not isinstance(d, numbers.Integral) or not 0 <= int(d) <= order
            for d in caps):
        raise ValueError(f"degrees must be None or a pair (dA, dB) of integers in [0, order={order}]"
                         f" (got {degrees!r})")
    return int(caps[0]), int(caps[1])


def _check_R(R):
    try:
        R = np.asarray(R, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"R must be a finite non-zero 3-vector in m (got {R!r})") from None
    if R.shape != (3,) or not np.all(np.isfinite(R)) or not np.any(R != 0.0):
        raise ValueError(f"R must be a finite non-zero 3-vector in m (got {np.array2string(R)})")
    return R


def _check_C(C):
    try:
        C = np.asarray(C, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"C must be a 3x3 rotation matrix (got {C!r})") from None
    if C.shape != (3, 3) or not np.all(np.isfinite(C)):
        raise ValueError(f"C must be a finite 3x3 rotation matrix (got shape {C.shape})")
    err = float(np.max(np.abs(C.T @ C - np.eye(3))))
    if err > 1e-9:
        raise ValueError(f"C must be orthonormal, |C^T C - 1| <= 1e-9 (got {err:.3g})")
    det = float(np.linalg.det(C))
    if det < 0:
        raise ValueError(f"C must be a proper rotation, det C = +1 (got det C = {det:.6g}: a "
                         "reflection)")
    return C


def _check_G(G):
    if isinstance(G, bool) or not isinstance(G, numbers.Real) or not math.isfinite(G) or G <= 0:
        raise ValueError(f"G must be a finite positive number (got {G!r})")
    return float(G)


def _integral_vector(T, label, needed, cap, order, allow_lower_degree):
    """Flat vector of the integrals of degree ≤ ``needed`` (module order) from a mapping."""
    if not isinstance(T, Mapping):
        raise ValueError(f"{label} must be a mapping {{(l, m, n): T^lmn}} (got "
                         f"{type(T).__name__})")
    provided = -1
    for key, value in T.items():
        # fast path for plain int triples and float/int values; the generic checks otherwise
        if not (type(key) is tuple and len(key) == 3 and type(key[0]) is int
                and type(key[1]) is int and type(key[2]) is int and min(key) >= 0):
            if (not isinstance(key, tuple) or len(key) != 3
                    or any(isinstance(i, bool) or not isinstance(i, numbers.Integral) or i < 0
                           for i in key)):
                raise ValueError(f"{label}: key {key!r} is not a triple (l, m, n) of integers "
                                 ">= 0")
        if not ((type(value) is float or type(value) is int) and math.isfinite(value)):
            if isinstance(value, bool) or not isinstance(value, numbers.Real) \
                    or not math.isfinite(value):
                raise ValueError(f"{label}[{key}] must be a finite real number (got {value!r})")
        degree = key[0] + key[1] + key[2]
        if degree > provided:
            provided = int(degree)
    mass = T.get((0, 0, 0))
    if mass is None or not mass > 0:
        raise ValueError(f"{label} lacks degree 0: the mass T^000 (key (0, 0, 0)) must be > 0 "
                         f"(got {mass!r})")
    if provided < needed and not allow_lower_degree:
        raise ValueError(
            f"{label} lacks degree-{provided + 1} integrals: its keys reach degree {provided} but "
            f"order={order} with degree cap {cap} needs degree {needed} (cap it with degrees=, or "
            "pass allow_lower_degree=True to take the missing integrals as zero)")
    E = _table(needed)[0]
    get = T.get
    return np.array([float(get((int(l), int(m), int(n)), 0.0)) for l, m, n in E.tolist()])


# ---- public API ----------------------------------------------------------------------------------
def rotate_integrals(T, C, degree=None):
    """Integrals of a body rotated by C: returns {(l, m, n): ∫ (C x)^(l,m,n) dm} (SI) for every
    l + m + n ≤ ``degree`` (default: the largest key degree of T; missing keys are zero).

    Exact polynomial expansion of (C x)^β, degree by degree (no truncation)."""
    C = _check_C(C)
    if not isinstance(T, Mapping) or not T:
        raise ValueError("T must be a non-empty mapping {(l, m, n): T^lmn}")
    if degree is None:
        degree = max(int(sum(k)) for k in T)
    if isinstance(degree, bool) or not isinstance(degree, numbers.Integral) \
            or not 0 <= degree <= 4 * MAX_ORDER:
        raise ValueError(f"degree must be an integer in [0, {4 * MAX_ORDER}] (got {degree!r})")
    E = _table(int(degree))[0]
    t = np.array([float(T.get(k, 0.0)) for k in map(tuple, E.tolist())])
    out = _rotate_vector(t, C, int(degree))
    return {tuple(k): float(v) for k, v in zip(E.tolist(), out)}


def inverse_distance_coefficients(R, degree):
    """{γ: a_γ(R)} with a_γ = ∂^γ(1/|R|)/γ! for |γ| ≤ ``degree`` (R in m; a_γ in m^-(|γ|+1))."""
    R = _check_R(R)
    if isinstance(degree, bool) or not isinstance(degree, numbers.Integral) \
            or not 0 <= degree <= MAX_ORDER + 1:
        raise ValueError(f"degree must be an integer in [0, {MAX_ORDER + 1}] (got {degree!r})")
    L = float(np.linalg.norm(R))
    E = _table(int(degree))[0]
    a = _a_unit(R / L, int(degree))[:-1] / L ** (E.sum(1) + 1.0)
    return {tuple(k): float(v) for k, v in zip(E.tolist(), a)}


def _evaluate(TA, TB, R, C, order, degrees, G, allow_lower_degree, want_forces):
    order = _check_order(order)
    dA, dB = _check_degrees(degrees, order)
    R = _check_R(R)
    C = _check_C(C)
    G = _check_G(G)
    tA = _integral_vector(TA, "TA", dA, dA, order, allow_lower_degree)
    tB = _integral_vector(TB, "TB", dB, dB, order, allow_lower_degree)
    L = float(np.linalg.norm(R))
    # dimensionless: lengths in units of |R| (masses kept)
    tA = tA / L ** _table(dA)[0].sum(1)
    tB = _rotate_vector(tB / L ** _table(dB)[0].sum(1), C, dB)
    top = order + 1 if want_forces else order
    a = _a_unit(R / L, top)
    ia, ib, ig, coef, up, gp1 = _pair_tables(order, dA, dB)
    g = a[ig]
    cA = coef * tA[ia]
    prod = cA * tB[ib]
    # long dot products by einsum: a BLAS ddot of this length may go multi-threaded, which costs
    # far more than it saves here
    U = -G / L * float(np.einsum("i,i->", prod, g))
    if not want_forces:
        return U
    F = G / L**2 * np.array([np.einsum("i,i->", prod, gp1[i] * a[up[i]]) for i in range(3)])
    VB = np.bincount(ib, weights=cA * g, minlength=len(tB))
    VA = np.bincount(ia, weights=coef * tB[ib] * g, minlength=len(tA))
    torque_B = G / L * (_generator(tB, dB) @ VB)
    torque_A = G / L * (_generator(tA, dA) @ VA)
    return U, F, torque_B, torque_A


def mutual_potential_order_n(TA, TB, R, C, order, *, degrees=None, G=G_SI,
                             allow_lower_degree=False):
    """Mutual potential energy U_N (J) of two rigid bodies truncated at total order N.

    Parameters
    ----------
    TA, TB : mapping {(l, m, n): T^lmn}
        Inertia integrals ∫ x^l y^m z^n dm (kg m^(l+m+n)) of A and B about their centres of mass
        in their own frames; (0, 0, 0) is the mass (kg). See the module notes for missing keys.
    R : (3,) array_like
        B's centre of mass minus A's, m, A frame (finite, non-zero).
    C : (3, 3) array_like
        Rotation taking B-frame vectors to the A frame (orthonormal to 1e-9, det +1).
    order : int in [0, 16]
        Keep the terms with |α| + |β| ≤ order.
    degrees : (int, int), optional
        Caps (dA, dB) on the degree of each body's integrals, each in [0, order].
    G : float
        Gravitational constant (default 6.67430e-11 m^3 kg^-1 s^-2).
    allow_lower_degree : bool
        Accept an integral set whose keys stop below the needed degree (higher ones = 0).
    """
    return _evaluate(TA, TB, R, C, order, degrees, G, allow_lower_degree, False)


def mutual_force_torque(TA, TB, R, C, order, *, degrees=None, G=G_SI, allow_lower_degree=False):
    """U_N with its force and torques; arguments as :func:`mutual_potential_order_n`.

    Returns
    -------
    U : float
        Potential energy, J.
    force_on_B : (3,) ndarray
        −∂U/∂R, N, A frame (A feels the opposite).
    torque_on_B : (3,) ndarray
        Torque on B about its centre of mass, N m, A frame: δU = −torque_on_B·ε for a rotation
        ε of B alone (C → exp([ε]×) C).
    torque_on_A : (3,) ndarray
        Torque on A about its centre of mass, N m, A frame, computed independently from A's
        integrals (rotation of A alone); R × F + torque_on_A + torque_on_B = 0 to round-off.

    (Note the order: ``ti_spinorbit.mutual_potential`` returns the primary's torque first.)
    """
    return _evaluate(TA, TB, R, C, order, degrees, G, allow_lower_degree, True)
