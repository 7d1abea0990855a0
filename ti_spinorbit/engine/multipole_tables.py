"""Tables of the order-N mutual potential, built once on the host per (order, degree caps,
odd terms), and the per-member integral rows that go with them (NumPy only).

The integral rows are what every order-N run carries (member tables, checkpoints, results);
:class:`Multipole` turns them into the harmonic coefficient rows and tables the integrators
use (``harmonic_tables``, ``kernels/harmonic_gravity.py``, docs/physics.md §3.8.2). The
Cartesian tables below serve the kernels' independent check, ``kernels/multipole_gravity.py``
(:meth:`Multipole.cartesian_arguments`), which evaluates the mutual potential, the force and
both torques of two rigid bodies at any truncation order N by walking these tables at run
time: every member walks the same entries in the same order, so no thread diverges, and no
term is unrolled at compile time, so one compiled kernel serves every order above 4
(``layout.multipole.KERNEL_ORDER``). What the tables encode (docs/physics.md §3.8.1 derives
it; ``ti_spinorbit.multipole`` is the independent host reference):

Normalised quantities. With D_γ(R) = ∂^γ(1/|R|) (γ a multi-index, |γ| its degree),
t̂_A^α = (−1)^{|α|} T_A^α / α! and t̂_B'^β = T'_B^β / β! (T'_B: the secondary's integrals
carried into the primary's frame), the truncated potential is

    U_N = −G Σ_{|α|+|β| ≤ N} t̂_A^α t̂_B'^β D_{α+β}(R),

the Cartesian multipole–multipole expansion of ``ti_spinorbit/multipole.py`` with its coefficient
(−1)^{|α|} (α+β)!/(α!β!) a_{α+β} absorbed: every pair costs one product, no coefficient.

Three kinds of terms, so that the secondary is rotated only as far as the mixed terms need:

* **monopole and primary-only terms** (β = 0): t̂_A^α m_B, added to the combined moments
  W_γ = Σ_{α+β=γ} t̂_A^α t̂_B'^β;
* **secondary-only terms** (α = 0): Σ_β T'^β_B a_β(R) is invariant under a common rotation of
  the integrals and R, so they are evaluated in the secondary's own frame with D at
  R_B = Sᵀ R (a second, cheap recurrence), never rotated. Their torque on the secondary is
  R × ∂U/∂R of the same terms;
* **mixed terms** (|α|, |β| ≥ 2, |α| + |β| ≤ N): the secondary's integrals rotated up to
  degree min(dB, N − 2) only, by the exact recurrence
  P_{p+1}[β' + e_i][δ] = Σ_j S_ij P_p[β'][δ + e_j] (P_p[β'][δ] = ∫ (S x)^{β'} x^δ dm,
  |β'| + |δ| = k, β' + e_i peeled along its first non-zero axis), which needs two buffers
  of at most C(p+3, 2) C(k−p+1, 2) numbers, not a rotation matrix of every degree; every
  stage of every degree is one flat list of entries (output, three inputs, axis), walked in
  one loop (measured faster than the loop nest over rows and columns, whose loops are a
  few iterations long). The pairs are stored by β with the α of each β after it (a CSR
  table): per pair, acc_β += t̂_A^α D_γ and W_γ += t̂_A^α t̂_B'^β. The torque on the
  secondary is G Σ_β acc_β ∂t̂_B'^β/∂ε, with the rotation generator
  ∂t̂'^β/∂ε_d = Σ_{c,e} ε_{cde} (β_e + 1) t̂'^{β − e_c + e_e} (β_c > 0).

Energy and force from W: U = −G (Σ_γ W_γ D_γ + m_A Σ_δ t̂_B^δ D_δ(R_B)),
∂U/∂R_i = −G (Σ_γ W_γ D_{γ+e_i} + m_A [S ∇_B]_i) (∂D_γ/∂R_i = D_{γ+e_i}); the torque on
the primary is R × ∂U/∂R − μ_B, the identity of the order-4 kernels (total angular momentum
conserved to round-off by construction).

D_γ from the two-term recurrence (n = |γ| ≥ 1, D_0 = 1/r)

    n r² D_γ = −(2n − 1) Σ_i γ_i R_i D_{γ−e_i} − (n − 1) Σ_i γ_i (γ_i − 1) D_{γ−2e_i},

the recurrence of ``ti_spinorbit/multipole.py`` with a_γ = D_γ / γ!, for the 2d + 1 entries of each
degree d whose z exponent is at most 1 (five terms: the z second-order one vanishes; an
index with a negative component gets weight 0 and index 0, so every entry has five); the
other entries, (d − 1) d / 2 of them, follow from ∇²(1/r) = 0,
D_(l,m,n) = −D_(l+2,m,n−2) − D_(l,m+2,n−2), in order of increasing n (two loads each).

Degree caps ``(degree_a, degree_b)`` keep |α| ≤ dA and |β| ≤ dB; with ``odd`` False (every
odd-exponent integral of both bodies zero in its own frame, e.g. ellipsoids) the primary's
and the secondary-only terms with an odd exponent are left out of the tables (the rotated
secondary integrals are general and stay). First moments (degree 1) are zero about the
centre of mass and are never read.

Layout: the integer table starts with the header of ``ti_spinorbit.layout.multipole``; the
positions of every section (integer and float) and of the per-member scratch are read from
it. A member's integral row (:func:`integral_rows`) is the primary's integrals of degrees
0..dA and then the secondary's of degrees 0..dB, each in its own frame in
``model.multipole.multi_indices`` order, in the units of the parameter rows
(T / ((m1 + m2) a^{l+m+n}), :meth:`ti_spinorbit.system.systems.BinarySystem.scaled_body_row`).
"""

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..layout import multipole as _H
from ..multipole import multi_indices

MAX_ORDER = _H.MAX_ORDER


def count(degree):
    """Multi-indices with l + m + n <= degree: C(degree + 3, 3) (0 for degree < 0)."""
    return 0 if degree < 0 else (degree + 1) * (degree + 2) * (degree + 3) // 6


def per_degree(degree):
    """Multi-indices of one degree: C(degree + 2, 2)."""
    return (degree + 1) * (degree + 2) // 2


@lru_cache(maxsize=None)
def _lookup(top):
    """{exponent triple: flat index} of multi_indices(top)."""
    return {tuple(int(x) for x in e): k for k, e in enumerate(multi_indices(top))}


def _fact(e):
    return math.factorial(e[0]) * math.factorial(e[1]) * math.factorial(e[2])


def _even(e):
    return not (e[0] % 2 or e[1] % 2 or e[2] % 2)


@dataclass(frozen=True, eq=False)
class Tables:
    """The tables of one (order, degree_a, degree_b, odd): ``ints`` (int32) and ``floats``
    (float64), read-only, and the sizes the host needs (``width_a``, ``width_b`` the
    columns of each body in an integral row, ``scratch`` the per-member scratch columns)."""

    order: int
    degree_a: int
    degree_b: int
    odd: bool
    ints: np.ndarray
    floats: np.ndarray

    @property
    def width_a(self):
        return count(self.degree_a)

    @property
    def width_b(self):
        return count(self.degree_b)

    @property
    def width(self):
        """Columns of an integral row: both bodies."""
        return self.width_a + self.width_b

    @property
    def scratch(self):
        """Per-member scratch columns (float64)."""
        return int(self.ints[_H.H_SCRATCH])

    @property
    def pairs(self):
        """Mixed (α, β) pairs the tables hold."""
        h = self.ints
        return int((h[_H.H_I_GAM] - h[_H.H_I_PAIR]) // 2)

    def bytes_per_member(self):
        """Bytes of a member's integral row and scratch (float64)."""
        return 8 * (self.width + self.scratch)


def check_degrees(order, degrees):
    """(degree_a, degree_b) for ``order``: None gives (order, order); a pair must hold two
    integers in [0, order]."""
    if degrees is None:
        return int(order), int(order)
    try:
        caps = tuple(degrees)
    except TypeError:
        caps = None
    if caps is None or len(caps) != 2 or any(
            isinstance(d, (bool, np.bool_)) or not isinstance(d, (int, np.integer))
            or not 0 <= int(d) <= order for d in caps):
        raise ValueError(f"degrees must be None or a pair (primary, secondary) of integers in "
                         f"[0, order={order}] (got {degrees!r})")
    return int(caps[0]), int(caps[1])


@lru_cache(maxsize=32)
def tables(order, degree_a, degree_b, odd=True) -> Tables:
    """The tables of the order-``order`` potential with degree caps (``degree_a``,
    ``degree_b``) and odd terms on or off (see the module docstring), built once per
    process."""
    N, dA, dB = int(order), int(degree_a), int(degree_b)
    if not 0 <= N <= MAX_ORDER or not 0 <= dA <= N or not 0 <= dB <= N:
        raise ValueError(f"tables need 0 <= degrees <= order <= {MAX_ORDER} (got order {N}, "
                         f"degrees ({dA}, {dB}))")
    odd = bool(odd)
    top = N + 1
    look = _lookup(top)
    E = [tuple(int(x) for x in e) for e in multi_indices(top)]
    eye = ((1, 0, 0), (0, 1, 0), (0, 0, 1))

    def idx(e):
        return look[e]

    def add(e, f, s=1):
        return (e[0] + s * f[0], e[1] + s * f[1], e[2] + s * f[2])

    def keep(e):
        return odd or _even(e)

    ints = {name: [] for name in ("D", "DH", "A", "B", "BETA", "PAIR", "GAM")}
    floats = {name: [] for name in ("D", "A", "B", "ROT", "BETA")}
    nD = count(N + 1)
    eB = min(dB, N)                     # the secondary-only terms' top degree
    nDB = count(eB + 1) if eB >= 2 else 1
    nW = count(N)
    KR = min(dB, N - 2)                 # rotated secondary integrals (mixed terms)
    KA = min(dA, N - 2)                 # primary degree of the mixed terms

    # D, degree by degree: first the 2d + 1 entries with z exponent <= 1 from the recurrence
    # (target; γ − e_x, γ − e_y, γ − e_z, γ − 2e_x, γ − 2e_y and their weights), then the
    # others by increasing z exponent from harmonicity (target; (l+2, m, n−2), (l, m+2, n−2))
    for d in range(1, top + 1):
        block = [e for e in E[count(d - 1):count(d)]]
        for g in (e for e in block if e[2] <= 1):
            ints["D"].append(idx(g))
            for i in range(3):
                ok = g[i] >= 1
                ints["D"].append(idx(add(g, eye[i], -1)) if ok else 0)
                floats["D"].append((2 * d - 1) * g[i] / d if ok else 0.0)
            for i in range(2):
                ok = g[i] >= 2
                ints["D"].append(idx(add(g, add(eye[i], eye[i]), -1)) if ok else 0)
                floats["D"].append((d - 1) * g[i] * (g[i] - 1) / d if ok else 0.0)
        for g in sorted((e for e in block if e[2] >= 2), key=lambda e: e[2]):
            ints["DH"] += [idx(g), idx((g[0] + 2, g[1], g[2] - 2)), idx((g[0], g[1] + 2, g[2] - 2))]

    # primary terms: normalisation (−1)^|α|/α! of 2 <= |α| <= min(dA, N)
    a_set = [e for e in E[:count(min(dA, N))] if sum(e) >= 2 and keep(e)]
    for e in a_set:
        ints["A"].append(idx(e))
        floats["A"].append((-1.0) ** sum(e) / _fact(e))

    # secondary-only terms, own frame: δ, δ + e_j, 1/δ!
    b_set = [e for e in E[:count(eB)] if sum(e) >= 2 and keep(e)]
    for e in b_set:
        ints["B"] += [idx(e)] + [idx(add(e, eye[j])) for j in range(3)]
        floats["B"].append(1.0 / _fact(e))

    # rotation: one flat list of entries (dst, src0, src1, src2, 3·axis), stage after stage
    # (degree k = 2..KR, step p = 0..k−1), scratch offsets within the slot; the copy of the
    # secondary's integrals at the start of the P region, then two buffers the stages write
    # in turn, the last stage of each degree writing into TB (unnormalised; 1/β! after)
    P0 = count(max(KR, 0))                       # P region: the copy, then two buffers
    maxP = max([per_degree(p + 1) * per_degree(k - p - 1) for k in range(2, KR + 1)
                for p in range(k - 1)], default=0)
    p_size = P0 + 2 * maxP
    rot_entries = []
    for k in range(2, KR + 1):
        in_base, in_rel = None, count(k - 1)     # p = 0 reads the copy of degree k
        for p in range(k):
            cols_out, cols_in = per_degree(k - p - 1), per_degree(k - p)
            last = p == k - 1
            block = P0 + (p % 2) * maxP          # stage p writes one buffer, reads the other
            out_base = ("TB", count(k - 1)) if last else ("P", block)
            for b, beta in enumerate(E[count(p):count(p + 1)]):     # degree p + 1
                axis = next(i for i in range(3) if beta[i] > 0)
                parent = idx(add(beta, eye[axis], -1)) - count(p - 1)
                for c, delta in enumerate(E[count(k - p - 2):count(k - p - 1)]):
                    up = [idx(add(delta, eye[jj])) - count(k - p - 1) for jj in range(3)]
                    src = [("P", (in_rel if in_base is None else in_base)
                            + parent * cols_in + u) for u in up]
                    rot_entries.append((out_base[0], out_base[1] + b * cols_out + c, src, axis))
            if not last:
                in_base = block
    floats["ROT"] = [1.0 / _fact(e) for e in E[:count(max(KR, 0))]]

    # mixed terms: β with 2 <= |β| <= KR, then its α (2 <= |α| <= min(KA, N − |β|))
    levi = {0: ((1, 2, -1.0), (2, 1, 1.0)), 1: ((2, 0, -1.0), (0, 2, 1.0)),
            2: ((0, 1, -1.0), (1, 0, 1.0))}   # (c, e, ε_cde) with ε_cde ≠ 0, for each d
    pairs = 0
    for b in (E[:count(KR)] if KR >= 2 else ()):
        if sum(b) < 2:
            continue
        alphas = [a for a in a_set if sum(a) <= min(KA, N - sum(b))]
        if not alphas:
            continue
        gen_i, gen_f = [], []
        for d in range(3):
            for c, e_, s in levi[d]:
                if b[c] > 0:
                    gen_i.append(idx(add(add(b, eye[c], -1), eye[e_])))
                    gen_f.append(s * (b[e_] + 1))
                else:
                    gen_i.append(idx(b))
                    gen_f.append(0.0)
        ints["BETA"] += [idx(b), pairs, pairs + len(alphas)] + gen_i
        floats["BETA"] += gen_f
        for a in alphas:
            ints["PAIR"] += [idx(a), idx(add(a, b))]
        pairs += len(alphas)

    # energy and force over W: γ of degree 0 and 2..N, with the indices of γ + e_i in D
    for g in E[:nW]:
        if sum(g) == 1:
            continue
        ints["GAM"] += [idx(g)] + [idx(add(g, eye[i])) for i in range(3)]

    head = [0] * _H.NHEAD
    head[_H.H_WIDTH_A] = count(dA)
    head[_H.H_TOP_D] = N + 1
    head[_H.H_TOP_DB] = eB + 1 if b_set else 0
    head[_H.H_NW] = nW
    head[_H.H_KR] = KR
    head[_H.H_NA] = len(a_set)
    head[_H.H_NB] = len(b_set)
    head[_H.H_NBETA] = len(ints["BETA"]) // 9
    head[_H.H_NGAM] = len(ints["GAM"]) // 4
    flat_i, flat_f = list(head), []
    for name, key in (("D", _H.H_I_D), ("DH", _H.H_I_DH), ("A", _H.H_I_A), ("B", _H.H_I_B),
                      ("BETA", _H.H_I_BETA), ("PAIR", _H.H_I_PAIR), ("GAM", _H.H_I_GAM)):
        flat_i[key] = len(flat_i)
        flat_i += ints[name]
    for name, key in (("D", _H.H_F_D), ("A", _H.H_F_A), ("B", _H.H_F_B), ("ROT", _H.H_F_ROT),
                      ("BETA", _H.H_F_BETA)):
        flat_i[key] = len(flat_f)
        flat_f += floats[name]
    offset = 0
    for key, size in ((_H.H_S_D, nD), (_H.H_S_DB, nDB), (_H.H_S_W, nW),
                      (_H.H_S_TA, count(min(dA, N))), (_H.H_S_TB, count(max(KR, 0))),
                      (_H.H_S_P, p_size), (_H.H_S_S, 9)):
        flat_i[key] = offset
        offset += size
    flat_i[_H.H_SCRATCH] = offset
    # the rotation entries, now that the regions have their offsets
    region = {"P": flat_i[_H.H_S_P], "TB": flat_i[_H.H_S_TB]}
    rot = []
    for where, dst, src, axis in rot_entries:
        rot += [region[where] + dst] + [region[w] + o for w, o in src] + [3 * axis]
    flat_i[_H.H_NROT] = len(rot_entries)
    flat_i[_H.H_I_ROT] = len(flat_i)
    flat_i += rot
    ints_arr = np.array(flat_i, dtype=np.int32)
    floats_arr = np.array(flat_f + [0.0], dtype=np.float64)   # never empty
    ints_arr.setflags(write=False)
    floats_arr.setflags(write=False)
    return Tables(N, dA, dB, odd, ints_arr, floats_arr)


@dataclass(frozen=True, eq=False)
class Multipole:
    """An ensemble's order-N data: the ``tables`` and the members' integral ``rows``
    (N, tables.width). :meth:`arguments` gives the four arrays the kernels take."""

    tables: Tables
    rows: np.ndarray

    def __post_init__(self):
        rows = np.ascontiguousarray(self.rows, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != self.tables.width or not np.all(np.isfinite(rows)):
            raise ValueError(f"multipole rows must be a finite (N, {self.tables.width}) array "
                             f"(degrees {self.tables.degree_a}, {self.tables.degree_b}; got "
                             f"shape {np.shape(self.rows)})")
        if len(rows) and not (np.all(rows[:, 0] > 0) and np.all(rows[:, self.tables.width_a] > 0)):
            raise ValueError("multipole rows must start each body with its mass (> 0)")
        object.__setattr__(self, "rows", rows)

    @property
    def order(self):
        return self.tables.order

    @property
    def degrees(self):
        return self.tables.degree_a, self.tables.degree_b

    def take(self, index) -> "Multipole":
        """The rows ``index`` (one per state, e.g. the member of each record). The taken rows
        keep this ensemble's harmonic tables (their masks hold for any subset), so a block
        of states neither recomputes the projection nor builds tables of its own."""
        index = np.asarray(index)
        out = Multipole(self.tables, self.rows[index])
        rows, tab = self.harmonic
        object.__setattr__(out, "_harmonic", (rows[index], tab))
        return out

    @property
    def harmonic(self):
        """(coefficient rows, harmonic tables) of the kernels (``harmonic_tables``): the rows
        in real solid harmonics, and tables that skip each body's degrees that are zero in
        every row (an ellipsoid's odd degrees) and its classes that are (an ellipsoid's odd
        orders). Built on first use and kept."""
        cached = self.__dict__.get("_harmonic")
        if cached is None:
            from . import harmonic_tables as _ht
            dA, dB = self.degrees
            rows = _ht.coefficient_rows(self.rows, dA, dB)
            rB = (dA + 1) ** 2
            tab = _ht.tables(self.order, dA, dB, _ht.degree_mask(rows, dA),
                             _ht.degree_mask(rows, dB, first=rB), _ht.even_mask(rows, dA),
                             _ht.even_mask(rows, dB, first=rB))
            cached = (rows, tab)
            object.__setattr__(self, "_harmonic", cached)
        return cached

    def arguments(self, slots):
        """(rows, scratch, ints, floats) of the kernels' order-N potential
        (``kernels/harmonic_gravity.py``) for a launch with ``slots`` scratch rows (one per
        thread's slot: the member in the integrator, the state in the diagnostics). Rows
        and scratch are flat arrays, member j's row at j · ``tables.width``, slot k's at
        k · ``tables.scratch``: the kernel reloads a 2-D array's stride from memory after
        every store (flat, the order-6 potential measured 15-20 % faster)."""
        rows, tab = self.harmonic
        return rows.ravel(), np.zeros(max(int(slots), 1) * tab.scratch), tab.ints, tab.floats

    def cartesian_arguments(self, slots):
        """The same four arrays for the Cartesian kernel (``kernels/multipole_gravity.py``,
        the kernels' independent check): integral rows and these tables."""
        return (self.rows, np.zeros((max(int(slots), 1), self.tables.scratch)),
                self.tables.ints, self.tables.floats)

    def bytes(self, slots):
        """Bytes of the kernels' rows and of ``slots`` scratch rows."""
        rows, tab = self.harmonic
        return 8 * (rows.size + max(int(slots), 1) * tab.scratch)


def no_arguments():
    """Stand-ins for the four order-N arrays of a launch at order <= 4 (never read)."""
    return (np.zeros(1), np.zeros(1), np.zeros(1, dtype=np.int32), np.zeros(1))


def body_integrals(body, degree, mass_unit=1.0, length_unit=1.0):
    """A body's integrals of degrees 0..``degree`` (``body.integral(l, m, n)``, its own
    frame) in ``multi_indices`` order, divided by mass_unit · length_unit^(l+m+n)."""
    mass_unit, length_unit = float(mass_unit), float(length_unit)   # never integer powers
    return np.array([body.integral(l, m, n) / (mass_unit * length_unit ** (l + m + n))
                     for l, m, n in multi_indices(degree).tolist()], dtype=np.float64)


def integral_rows(systems, degrees):
    """(N, width) integral rows of ``systems`` (one BinarySystem per member) for degree caps
    ``degrees`` = (dA, dB): the primary's integrals of degrees 0..dA, then the secondary's of
    0..dB, in the parameter rows' scaled units (mass m1 + m2, length a), one row per distinct
    system, spread over its members."""
    dA, dB = degrees
    rows = {}
    for s in systems:
        if id(s) not in rows:
            M, a = s.total_mass, s.a
            rows[id(s)] = np.concatenate([body_integrals(s.primary, dA, M, a),
                                          body_integrals(s.secondary, dB, M, a)])
    width = count(dA) + count(dB)
    if not systems:
        return np.zeros((0, width))
    return np.stack([rows[id(s)] for s in systems])


def odd_present(rows, degrees):
    """Whether any integral row holds a non-zero integral with an odd exponent (either
    body, its own frame): then the tables keep the odd terms."""
    mask = odd_mask(degrees)
    rows = np.asarray(rows)
    return bool(rows.size and np.any(rows[:, mask] != 0.0))


def odd_mask(degrees, axis=None):
    """Boolean mask over an integral row's columns: the integrals with an odd exponent (of
    ``axis`` 0, 1, 2 only when given; e.g. 2: odd in z, which tilts a planar motion)."""
    out = []
    for d in degrees:
        for e in multi_indices(d):
            out.append(bool(e[axis] % 2) if axis is not None else bool(any(x % 2 for x in e)))
    return np.array(out, dtype=bool)


def degrees_provided(body):
    """The highest degree of integrals ``body`` holds: its ``order`` (a Body answers
    ``integral`` up to it), 4 for a body that does not say (the order-4 row's)."""
    return int(getattr(body, "order", None) or 4)


__all__ = ["Tables", "Multipole", "no_arguments", "tables", "check_degrees", "count", "per_degree", "integral_rows",
           "body_integrals", "odd_present", "odd_mask", "degrees_provided", "MAX_ORDER"]
