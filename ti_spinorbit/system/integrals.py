r"""Inertia integrals of rigid bodies at any order: the foundation of an order-N mutual potential.

Representation
--------------
An *integral set* of order ``N`` is a dict ``{(l, m, n): T}`` holding, for every multi-index
with ``l + m + n <= N`` (zeros included),

.. math::  T^{lmn} = \int_B x^l\, y^m\, z^n \; dm  \qquad [\mathrm{kg\,m}^{l+m+n}],

as float64 numbers (``numpy.float64``), in SI units. Its keys are ordered as
:func:`multi_indices` lists them (by degree, then ``l`` descending, then ``m`` descending), so
the first ``C(N + 3, 3)`` entries of any higher-order set are the lower-order set. Orders run
from 0 to :data:`MAX_ORDER` (16: 969 integrals). Expansions of the mutual potential of two
bodies in these integrals are given by Tricarico (2008, Celest. Mech. Dyn. Astron. 100:319)
and Hou, Scheeres & Xin (2017, Celest. Mech. Dyn. Astron. 127:369).

Sources of integral sets
------------------------
* Homogeneous ellipsoid with semi-axes a, b, c along x, y, z and mass M
  (:func:`ellipsoid_integrals`): with u = x/a etc. the ellipsoid is the unit ball, and the
  ball's monomial moments are products of Gamma functions; for l, m, n all even

  .. math:: T^{lmn} = 3 M a^l b^m c^n \frac{(l-1)!!\,(m-1)!!\,(n-1)!!}{(l+m+n+3)!!},
            \qquad (-1)!! = 1,

  and zero when any exponent is odd. The rational coefficient is exact (Python integers).

* Point masses m_i at r_i (:func:`point_mass_integrals`): T^{lmn} = Σ_i m_i x_i^l y_i^m z_i^n.

* Homogeneous polyhedron of density ρ bounded by a closed, consistently outward-wound
  triangle mesh (:func:`polyhedron_integrals`). Every facet (v1, v2, v3) spans a tetrahedron
  with the origin, of SIGNED six-fold volume D = v1 · (v2 × v3). The signed tetrahedra of a
  closed surface add up to its interior whatever the origin (each point of space is covered
  by as many positive as negative tetrahedra, plus one if it is inside), so the sum is exact
  for any closed mesh, convex, star-shaped or not (a torus included: with |D| its volume would
  come out about 60 % too large). With x = u1 v1 + u2 v2 + u3 v3 over the standard simplex
  (u_k ≥ 0, u1 + u2 + u3 ≤ 1) the volume element is D du, and expanding the monomial
  multinomially over the three vertices and using the Dirichlet integral

  .. math:: \int_{\rm simplex} u_1^{p} u_2^{q} u_3^{r}\, du = \frac{p!\,q!\,r!}{(p+q+r+3)!}

  gives, for |α| = l + m + n,

  .. math:: \int_{\rm tet} x^\alpha\, dV = D\,\frac{\alpha!}{(|\alpha|+3)!}\, S_\alpha,\qquad
            S_\alpha = \sum_{\beta_1+\beta_2+\beta_3=\alpha}\ \prod_{k=1}^{3}
            \frac{|\beta_k|!}{\beta_k!}\, v_k^{\beta_k},

  with α! = l! m! n!. S_α is the coefficient of t^α in the complete homogeneous symmetric
  polynomial h_{|α|}(t·v1, t·v2, t·v3) (Lasserre & Avrachenkov 2001, Amer. Math. Monthly
  108:151; Baldoni et al. 2011, Math. Comp. 80:297); it is evaluated for all facets at once
  by the recursion h_n(a1) = a1 h_{n-1}(a1), h_n(a1, a2) = h_n(a1) + a2 h_{n-1}(a1, a2),
  h_n(a1, a2, a3) = h_n(a1, a2) + a3 h_{n-1}(a1, a2, a3) on polynomials in t (each step a
  product with a linear form, about 10 multiply-adds per facet and integral). The same
  signed-tetrahedron (or divergence-theorem) decomposition underlies Mirtich (1996,
  J. Graphics Tools 1(2):31) and Dobrovolskis (1996, Icarus 124:698) at order 2.

Transformations
---------------
* :func:`shift_integrals` (translation by +d): ∫(x + d)^α dm = Σ_{β ≤ α} C(α, β) d^{α-β} T^β,
  with C(α, β) = C(l, l') C(m, m') C(n, n') (a binomial per axis); exact, same order.
* :func:`rotate_integrals` (rotation x' = R x): (R x)^α = Π_i (R_i · x)^{α_i} is a homogeneous
  polynomial of the same degree in x; its coefficients (the symmetric powers of R) are built
  degree by degree, row α from row α − e_i times the linear form R_i · x, so the map is exact
  at every order.
* :func:`principal_frame`: the centre of mass and the principal axes of the second moments;
  ``x_principal = rotation @ (x_input - offset)`` (conventions in its docstring).

Everything is float64 NumPy; no Taichi and no other module of the package is imported.
"""

import math
import numbers
import os
from concurrent.futures import ThreadPoolExecutor
from fractions import Fraction

import numpy as np

__all__ = ["MAX_ORDER", "multi_indices", "ellipsoid_integrals", "point_mass_integrals",
           "polyhedron_integrals", "shift_integrals", "rotate_integrals", "principal_frame",
           "volume_of"]

#: Highest order accepted (969 integrals; factorials up to 19! stay exact in the coefficients).
MAX_ORDER = 16
#: A mesh is accepted as closed when the length of its vector area, |Σ_f A_f n_f| (zero for
#: every closed surface), is at most this fraction of its total area Σ_f A_f. Moving the
#: origin by d changes a polyhedral volume by d · (Σ_f A_f n_f) / 3, so below this bound the
#: result depends on the origin by less than about this fraction.
CLOSURE_TOLERANCE = 1e-6
#: Facets per block of the vectorised polyhedron sum (bounds the memory: about
#: 6 × C(N + 2, 2) × 8 bytes per facet, 17 MB per block at order 8, 59 MB at order 16).
_CHUNK = 8192
#: Tolerance of the orthonormality and determinant tests of a rotation matrix.
_ROTATION_TOL = 1e-10


# ---- multi-indices ----------------------------------------------------------------------
def _degree_indices(n):
    """The multi-indices of degree n: l descending, then m descending."""
    return tuple((l, m, n - l - m) for l in range(n, -1, -1) for m in range(n - l, -1, -1))


_ALL = tuple(alpha for n in range(MAX_ORDER + 1) for alpha in _degree_indices(n))
_POS = {alpha: i for i, alpha in enumerate(_ALL)}


def _count(order):
    """Number of multi-indices with l + m + n <= order: C(order + 3, 3)."""
    return (order + 1) * (order + 2) * (order + 3) // 6


def _start(n):
    """Index of the first multi-index of degree n: C(n + 2, 3)."""
    return n * (n + 1) * (n + 2) // 6


def _check_order(order):
    if (isinstance(order, bool) or not isinstance(order, numbers.Integral)
            or not 0 <= int(order) <= MAX_ORDER):
        raise ValueError(f"order must be an integer in [0, {MAX_ORDER}], got {order!r}")
    return int(order)


def multi_indices(order):
    """Every (l, m, n) with l + m + n <= ``order``, sorted by degree l + m + n, then l
    descending, then m descending: (0,0,0), (1,0,0), (0,1,0), (0,0,1), (2,0,0), (1,1,0),
    (1,0,1), (0,2,0), (0,1,1), (0,0,2), ... (``C(order + 3, 3)`` tuples).

    Parameters
    ----------
    order : int
        In [0, 16].

    Returns
    -------
    tuple of tuple of int
    """
    return _ALL[:_count(_check_order(order))]


# ---- checks -----------------------------------------------------------------------------
def _positive(value, name):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}") from None
    if isinstance(value, bool) or not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def _real_array(value, name, shape_text):
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite real array of shape {shape_text}") from None
    return arr


def _check_points(points, name="points"):
    arr = _real_array(points, name, "(N, 3)")
    if arr.ndim != 2 or arr.shape[1] != 3 or arr.shape[0] < 1:
        raise ValueError(f"{name} must be a finite real array of shape (N, 3) with N >= 1, "
                         f"got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite (shape (N, 3)): "
                         f"{int(np.sum(~np.isfinite(arr)))} entries are NaN or infinite")
    return arr


def _check_mesh(vertices, faces):
    v = _check_points(vertices, "vertices")
    try:
        f = np.asarray(faces)
    except (TypeError, ValueError):
        raise ValueError("faces must be an integer array of shape (F, 3)") from None
    if f.ndim != 2 or f.shape[1] != 3 or f.shape[0] < 1:
        raise ValueError(f"faces must be an integer array of shape (F, 3) with F >= 1, "
                         f"got shape {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be an integer array of shape (F, 3) (vertex indices), "
                         f"got dtype {f.dtype}")
    lo, hi = int(f.min()), int(f.max())
    if lo < 0 or hi >= len(v):
        raise ValueError(f"faces must hold vertex indices in [0, {len(v) - 1}] (0-based), "
                         f"got indices in [{lo}, {hi}]")
    return v, f.astype(np.intp, copy=False)


def _check_integrals(T, name="T"):
    """The order and the values (a float64 vector in multi_indices order) of an integral
    set; one-line ValueError when it is not one."""
    if not isinstance(T, dict):
        raise ValueError(f"{name} must be a dict {{(l, m, n): value}} of inertia integrals, "
                         f"got {type(T).__name__}")
    k, order = len(T), 0
    while order < MAX_ORDER and _count(order) < k:
        order += 1
    if _count(order) != k or set(T) != set(_ALL[:k]):
        raise ValueError(f"{name} must hold exactly the multi-indices (l, m, n) with "
                         f"l + m + n <= N for one order N in [0, {MAX_ORDER}] "
                         f"(multi_indices(N)); got {k} entries")
    try:
        vec = np.array([T[alpha] for alpha in _ALL[:k]], dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must map each (l, m, n) to a finite real number") from None
    if not np.all(np.isfinite(vec)):
        raise ValueError(f"{name} must map each (l, m, n) to a finite real number: "
                         f"{int(np.sum(~np.isfinite(vec)))} values are NaN or infinite")
    return order, vec


def _as_dict(vec, order):
    return {alpha: np.float64(x) for alpha, x in zip(_ALL[:_count(order)], vec)}


def _check_rotation(R):
    arr = _real_array(R, "R", "(3, 3)")
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise ValueError(f"R must be a finite 3x3 rotation matrix, got shape {arr.shape}")
    err = float(np.max(np.abs(arr @ arr.T - np.eye(3))))
    det = float(np.linalg.det(arr))
    if err > _ROTATION_TOL or abs(det - 1.0) > _ROTATION_TOL:
        raise ValueError(f"R must be a rotation matrix (orthonormal, det +1, within "
                         f"{_ROTATION_TOL:g}): max|R R^T - I| = {err:.3g}, det = {det:.12g}")
    return arr


# ---- ellipsoid ----------------------------------------------------------------------------
def _double_factorial(k):
    """k!! for k >= -1, an exact integer ((-1)!! = 0!! = 1)."""
    out = 1
    while k > 1:
        out *= k
        k -= 2
    return out


def ellipsoid_integrals(a, b, c, mass, order):
    r"""Inertia integrals of a homogeneous triaxial ellipsoid centred at the origin.

    The body is x²/a² + y²/b² + z²/c² <= 1 with its semi-axes along x, y, z. For l, m, n all
    even

    .. math:: T^{lmn} = 3 M a^l b^m c^n \frac{(l-1)!!\,(m-1)!!\,(n-1)!!}{(l+m+n+3)!!}

    ((−1)!! = 1), otherwise 0 (mirror symmetry). For instance T^000 = M, T^200 = M a²/5,
    T^400 = 3 M a⁴/35, T^220 = M a² b²/35. The coefficient is an exact fraction, turned into a
    float once and multiplied by M a^l b^m c^n (Tricarico 2008, Celest. Mech. Dyn. Astron.
    100:319; Hou, Scheeres & Xin 2017, Celest. Mech. Dyn. Astron. 127:369).

    Parameters
    ----------
    a, b, c : float
        Semi-axes along x, y, z, m; finite, > 0 (any order among them).
    mass : float
        kg, finite, > 0.
    order : int
        Highest degree l + m + n, in [0, 16].

    Returns
    -------
    dict
        ``{(l, m, n): T}``, kg m^(l+m+n), every l + m + n <= order.
    """
    a, b, c = _positive(a, "a"), _positive(b, "b"), _positive(c, "c")
    mass = _positive(mass, "mass")
    order = _check_order(order)
    out = {}
    for l, m, n in _ALL[:_count(order)]:
        if l % 2 or m % 2 or n % 2:
            out[(l, m, n)] = np.float64(0.0)
            continue
        coef = Fraction(3 * _double_factorial(l - 1) * _double_factorial(m - 1)
                        * _double_factorial(n - 1), _double_factorial(l + m + n + 3))
        out[(l, m, n)] = np.float64(float(coef) * (mass * a**l * b**m * c**n))
    return out


# ---- point masses -------------------------------------------------------------------------
def _powers(x, order):
    """(len(x), order + 1) array of x**k."""
    p = np.empty((len(x), order + 1))
    p[:, 0] = 1.0
    for k in range(1, order + 1):
        np.multiply(p[:, k - 1], x, out=p[:, k])
    return p


def point_mass_integrals(points, masses, order):
    """Inertia integrals of point masses: T^{lmn} = Σ_i m_i x_i^l y_i^m z_i^n.

    Vectorised: per block of points, the x-powers weighted by the masses are contracted
    with every product y^m z^n (m + n <= order) in one matrix product.

    Parameters
    ----------
    points : array_like, shape (N, 3)
        Positions, m, finite.
    masses : array_like, shape (N,)
        kg, finite, each > 0.
    order : int
        In [0, 16].

    Returns
    -------
    dict
        ``{(l, m, n): T}``, kg m^(l+m+n).
    """
    pts = _check_points(points)
    m = _real_array(masses, "masses", f"({len(pts)},)")
    if m.shape != (len(pts),):
        raise ValueError(f"masses must be a finite array of shape ({len(pts)},) (one per "
                         f"point), each > 0, got shape {m.shape}")
    if not np.all(np.isfinite(m)) or not np.all(m > 0):
        bad = int(np.sum(~(m > 0) | ~np.isfinite(m)))
        raise ValueError(f"masses must be finite and > 0: {bad} of {len(m)} are not")
    order = _check_order(order)
    yz = [(j, k) for j in range(order + 1) for k in range(order + 1 - j)]
    jj = np.array([j for j, _ in yz])
    kk = np.array([k for _, k in yz])
    acc = np.zeros((order + 1, len(yz)))
    for s in range(0, len(pts), 65536):
        blk, mb = pts[s:s + 65536], m[s:s + 65536]
        wx = _powers(blk[:, 0], order) * mb[:, None]
        py, pz = _powers(blk[:, 1], order), _powers(blk[:, 2], order)
        acc += wx.T @ (py[:, jj] * pz[:, kk])
    col = {jk: i for i, jk in enumerate(yz)}
    vec = np.array([acc[l, col[(j, k)]] for l, j, k in _ALL[:_count(order)]])
    return _as_dict(vec, order)


# ---- polyhedra ----------------------------------------------------------------------------
def _linear_blocks(n):
    """Row ranges for multiplying a degree-(n-1) polynomial by a linear form (rows in
    multi_indices order within a degree): multiplication by t_x maps degree-(n-1) row i to
    degree-n row i (all of them at once); by t_y and t_z, block l of degree n-1 (its n - l
    rows, from its start s) goes to block l of degree n at its start (t_y) or one row later
    (t_z). Returns (m_prev, [(dst_y, dst_z, src, length), ...])."""
    blocks = []
    for l in range(n):
        src = (n - 1 - l) * (n - l) // 2
        dst = (n - l) * (n - l + 1) // 2
        blocks.append((dst, dst + 1, src, n - l))
    return n * (n + 1) // 2, blocks


_BLOCKS = [None] + [_linear_blocks(n) for n in range(1, MAX_ORDER + 1)]


def _times_linear(P, v, n, out):
    """out = (v_x t_x + v_y t_y + v_z t_z) P for P homogeneous of degree n - 1 (rows of
    coefficients, one column per facet); out has the rows of degree n."""
    m_prev, blocks = _BLOCKS[n]
    np.multiply(P, v[0], out=out[:m_prev])
    out[m_prev:] = 0.0
    for dy, dz, s, ln in blocks:
        src = P[s:s + ln]
        out[dy:dy + ln] += src * v[1]
        out[dz:dz + ln] += src * v[2]
    return out


def _facet_sums(vs, faces, order):
    """Σ_f D_f S_α(f) for one block of facets, per degree (a list of vectors): S_α is the
    coefficient of t^α in h_n(t·v1, t·v2, t·v3) (module docstring)."""
    v1 = vs[faces[:, 0]].T.copy()
    v2 = vs[faces[:, 1]].T.copy()
    v3 = vs[faces[:, 2]].T.copy()
    D = (v1[0] * (v2[1] * v3[2] - v2[2] * v3[1]) + v1[1] * (v2[2] * v3[0] - v2[0] * v3[2])
         + v1[2] * (v2[0] * v3[1] - v2[1] * v3[0]))
    sums = [np.array([D.sum()])]
    cols = len(D)
    h1 = h2 = h3 = np.ones((1, cols))
    for n in range(1, order + 1):
        rows = (n + 1) * (n + 2) // 2
        n1 = _times_linear(h1, v1, n, np.empty((rows, cols)))
        n2 = _times_linear(h2, v2, n, np.empty((rows, cols)))
        n2 += n1
        n3 = _times_linear(h3, v3, n, np.empty((rows, cols)))
        n3 += n2
        sums.append(n3 @ D)
        h1, h2, h3 = n1, n2, n3
    return sums


def _workers():
    try:
        return max(1, min(8, len(os.sched_getaffinity(0))))
    except AttributeError:            # not Linux
        return max(1, min(8, os.cpu_count() or 1))


def _mesh_geometry(vertices, faces):
    """Checked vertices shifted to the mean of the facet corners, the faces, that centre,
    and the signed volume; raises when the mesh is not closed."""
    v, f = _check_mesh(vertices, faces)
    counts = np.bincount(f.ravel(), minlength=len(v)).astype(np.float64)
    centre = counts @ v / counts.sum()
    vs = v - centre
    vec_area = np.zeros(3)
    area = vol6 = 0.0
    for s in range(0, len(f), 1 << 20):
        blk = f[s:s + (1 << 20)]
        a, b, c = vs[blk[:, 0]], vs[blk[:, 1]], vs[blk[:, 2]]
        cr = np.cross(b - a, c - a)                  # 2 A n per facet
        vec_area += cr.sum(axis=0)
        area += np.sqrt(np.einsum("ij,ij->i", cr, cr)).sum()
        vol6 += np.einsum("ij,ij->i", a, np.cross(b, c)).sum()
    gap = float(np.linalg.norm(vec_area) / area) if area > 0 else np.inf
    if not gap <= CLOSURE_TOLERANCE:
        raise ValueError(f"faces must form a closed surface: the vector area |Σ A n| is "
                         f"{gap:.3g} of the total area (allowed <= {CLOSURE_TOLERANCE:g}); "
                         f"the mesh has holes or inconsistent winding")
    return vs, f, centre, vol6 / 6.0


def volume_of(vertices, faces):
    """Signed volume of a closed triangle mesh, m³: Σ_f v1·(v2×v3)/6 over facets.

    Positive when the faces are wound counter-clockwise seen from outside (outward normals
    by the right-hand rule), negative when they are all wound the other way. Computed about
    the mean of the facet corners (exactly the same volume for a closed mesh, with less
    rounding).

    Parameters
    ----------
    vertices : array_like, shape (V, 3)
        m, finite.
    faces : array_like of int, shape (F, 3)
        0-based vertex indices; the surface must be closed (module constant
        CLOSURE_TOLERANCE).

    Returns
    -------
    float
    """
    return float(_mesh_geometry(vertices, faces)[3])


def polyhedron_integrals(vertices, faces, order, density):
    r"""Inertia integrals of a homogeneous polyhedron bounded by a closed triangle mesh.

    Each facet (v1, v2, v3) and the origin span a tetrahedron of signed six-fold volume
    D = v1·(v2×v3); over it

    .. math:: \int x^\alpha\, dV = D\,\frac{\alpha!}{(|\alpha|+3)!}
              \sum_{\beta_1+\beta_2+\beta_3=\alpha}\ \prod_k \frac{|\beta_k|!}{\beta_k!}\,
              v_k^{\beta_k}

    (multinomial expansion of x = Σ u_k v_k over the standard simplex and the Dirichlet
    integral ∫ u1^p u2^q u3^r du = p! q! r!/(p+q+r+3)!), and the signed sum over the facets
    is the exact integral over the interior of any closed mesh, star-shaped or not. The
    inner sum is evaluated for all facets of a block at once (NumPy arrays, blocks of
    8192 facets over a few threads; no Python loop over facets) by the complete-homogeneous
    recursion of the module docstring. Cost: about 10 multiply-adds per facet and integral,
    10 C(N+3, 3) per facet at order N; order 8 of 3 million facets took 2.8 s on 2 cores
    (experiments/integrals_speed.py), order 16 of 100 000 facets 0.9 s.

    Accuracy: the mesh is first moved so that the mean of its facet corners is the origin,
    integrated there (the tetrahedra are then small and the signed sum cancels little), and
    the result is moved back exactly with :func:`shift_integrals`. The result does not depend
    on that choice beyond rounding.

    Parameters
    ----------
    vertices : array_like, shape (V, 3)
        m, finite.
    faces : array_like of int, shape (F, 3)
        0-based vertex indices, every facet wound counter-clockwise seen from outside. The
        surface must be closed: its vector area may be at most CLOSURE_TOLERANCE (1e-6) of its
        area, otherwise ValueError; a mesh wound inward (negative volume) is a ValueError too.
    order : int
        In [0, 16].
    density : float
        kg/m³, finite, > 0.

    Returns
    -------
    dict
        ``{(l, m, n): T}``, kg m^(l+m+n), every l + m + n <= order: density times the volume
        integrals about the input frame's origin.
    """
    order = _check_order(order)
    rho = _positive(density, "density")
    vs, f, centre, volume = _mesh_geometry(vertices, faces)
    if not volume > 0:
        raise ValueError(f"faces must be wound outward (counter-clockwise seen from outside): "
                         f"the signed volume is {volume:.6g} m^3; reverse each face's order")
    starts = range(0, len(f), _CHUNK)
    work = lambda s: _facet_sums(vs, f[s:s + _CHUNK], order)   # noqa: E731
    workers = min(_workers(), len(starts))
    if workers > 1:
        with ThreadPoolExecutor(workers) as pool:
            parts = list(pool.map(work, starts))     # summed in block order: deterministic
    else:
        parts = [work(s) for s in starts]
    vec = np.empty(_count(order))
    for n in range(order + 1):
        total = np.sum([p[n] for p in parts], axis=0)
        coef = np.array([float(Fraction(math.factorial(l) * math.factorial(m) * math.factorial(k),
                                        math.factorial(n + 3)))
                         for l, m, k in _degree_indices(n)])
        vec[_start(n):_start(n + 1)] = rho * coef * total
    out = _as_dict(vec, order)
    if np.any(centre != 0.0):
        out = shift_integrals(out, centre)
    return out


# ---- translations and rotations -------------------------------------------------------------
def shift_integrals(T, d):
    r"""Integrals of the same body translated by +d (equivalently: about a point at −d).

    .. math:: T'^{\alpha} = \int (x + d)^\alpha dm
              = \sum_{\beta \le \alpha} \binom{l}{l'}\binom{m}{m'}\binom{n}{n'}
                d_x^{l-l'} d_y^{m-m'} d_z^{n-n'}\, T^{\beta},

    β = (l', m', n') ≤ α componentwise: exact, and of the same order (only integrals of
    lower or equal degree enter). To refer the integrals to a point p instead of the origin,
    use d = −p.

    Parameters
    ----------
    T : dict
        An integral set ``{(l, m, n): value}`` (every l + m + n <= N), kg m^(l+m+n).
    d : array_like, shape (3,)
        Displacement, m, finite.

    Returns
    -------
    dict
        Same order and units.
    """
    order, vec = _check_integrals(T)
    dd = _real_array(d, "d", "(3,)")
    if dd.shape != (3,) or not np.all(np.isfinite(dd)):
        raise ValueError(f"d must be a finite displacement of shape (3,), m, got "
                         f"{np.asarray(d).tolist() if np.size(d) < 10 else np.shape(d)}")
    k = np.arange(order + 1)
    binom = np.array([[math.comb(i, j) for j in range(order + 1)] for i in range(order + 1)],
                     dtype=np.float64)
    diff = k[:, None] - k[None, :]
    axis = []
    for x in dd:
        pw = np.where(diff >= 0, x ** np.maximum(diff, 0).astype(np.float64), 0.0)  # 0**0 = 1
        axis.append(binom * pw)
    idx = np.array(_ALL[:_count(order)])
    L, M, N = idx[:, 0], idx[:, 1], idx[:, 2]
    mat = (axis[0][L[:, None], L[None, :]] * axis[1][M[:, None], M[None, :]]
           * axis[2][N[:, None], N[None, :]])
    return _as_dict(mat @ vec, order)


def _symmetric_powers(R, order):
    """Per degree n, the matrix A_n with (R x)^α = Σ_β A_n[α, β] x^β (|α| = |β| = n)."""
    mats = [np.ones((1, 1))]
    for n in range(1, order + 1):
        alphas = _degree_indices(n)
        prev = {beta: i for i, beta in enumerate(_degree_indices(n - 1))}
        axis = np.array([next(i for i in range(3) if a[i] > 0) for a in alphas])
        parent = np.array([prev[tuple(a[j] - (j == i) for j in range(3))]
                           for a, i in zip(alphas, axis)])
        cur = {beta: i for i, beta in enumerate(alphas)}
        up = [np.array([cur[tuple(b[j] + (j == i) for j in range(3))] for b in prev])
              for i in range(3)]
        base = mats[-1][parent]                         # rows (R x)^(α - e_i)
        A = np.zeros((len(alphas), len(alphas)))
        for j in range(3):
            A[:, up[j]] += R[axis, j][:, None] * base   # times R_ij x_j
        mats.append(A)
    return mats


def rotate_integrals(T, R):
    r"""Integrals of the body rotated by R: T'^α = ∫ (R x)^α dm, exact at every order.

    (R x)^α = Π_i (Σ_j R_ij x_j)^{α_i} is a homogeneous polynomial of degree |α| in x; its
    coefficient matrix for degree n (the n-th symmetric power of R) is built from that of
    degree n − 1: row α is row α − e_i (i the first axis with α_i > 0) multiplied by the
    linear form R_i · x. Then T'_n = A_n T_n per degree. To express a body's integrals in a
    frame whose axes are the rows of Q (coordinates x' = Q x), pass R = Q.

    Parameters
    ----------
    T : dict
        An integral set ``{(l, m, n): value}``, kg m^(l+m+n).
    R : array_like, shape (3, 3)
        Proper rotation: orthonormal and det +1 within 1e-10.

    Returns
    -------
    dict
        Same order and units.
    """
    order, vec = _check_integrals(T)
    Rm = _check_rotation(R)
    out = np.empty_like(vec)
    for n, A in enumerate(_symmetric_powers(Rm, order)):
        out[_start(n):_start(n + 1)] = A @ vec[_start(n):_start(n + 1)]
    return _as_dict(out, order)


def principal_frame(T):
    """Integrals about the centre of mass in the principal axes of the second moments.

    Conventions (deterministic):

    * offset = (T^100, T^010, T^001) / T^000, the centre of mass in the input frame, m;
    * the rows of ``rotation`` are the unit eigenvectors of the second-moment matrix
      S_ij = ∫ (x − offset)_i (x − offset)_j dm, ordered so that in the result
      T^200 >= T^020 >= T^002: x is the longest axis (smallest moment of inertia A), z the
      shortest (largest moment C);
    * each of the first two rows has its largest-magnitude component positive (the first
      such component where two are equal), and the third row is row 1 × row 2, so the frame
      is right-handed and det(rotation) = +1;
    * principal coordinates are ``x_principal = rotation @ (x_input - offset)``, and
      ``T_principal = rotate_integrals(shift_integrals(T, -offset), rotation)``.

    In the result the first-order and off-diagonal second-order integrals vanish to rounding
    (about 1e-16 of T^000 times the size, and of T^200); they are kept as computed, not set to
    zero. When two second moments are equal (a body of revolution, a sphere) the axes inside
    the degenerate plane are whatever numpy.linalg.eigh returns: still a valid principal
    frame, the same for the same input, but not unique.

    Parameters
    ----------
    T : dict
        An integral set of order >= 2 about any origin, T^000 > 0.

    Returns
    -------
    T_principal : dict
        Same order, kg m^(l+m+n).
    offset : ndarray, shape (3,)
        m.
    rotation : ndarray, shape (3, 3)
        Proper rotation.
    """
    order, vec = _check_integrals(T)
    if order < 2:
        raise ValueError(f"T must be of order >= 2 for a principal frame (second moments), "
                         f"got order {order}")
    mass = vec[0]
    if not mass > 0:
        raise ValueError(f"T must have a positive mass T[(0, 0, 0)], got {mass!r}")
    offset = vec[1:4] / mass
    Tc = shift_integrals(T, -offset)
    S = np.array([[Tc[(2, 0, 0)], Tc[(1, 1, 0)], Tc[(1, 0, 1)]],
                  [Tc[(1, 1, 0)], Tc[(0, 2, 0)], Tc[(0, 1, 1)]],
                  [Tc[(1, 0, 1)], Tc[(0, 1, 1)], Tc[(0, 0, 2)]]])
    _, vecs = np.linalg.eigh(S)
    e1, e2 = vecs[:, 2].copy(), vecs[:, 1].copy()      # largest, middle second moment
    for e in (e1, e2):
        if e[np.argmax(np.abs(e))] < 0:
            e *= -1.0
    e3 = np.cross(e1, e2)
    rotation = np.array([e1, e2, e3 / np.linalg.norm(e3)])
    return rotate_integrals(Tc, rotation), offset, rotation
