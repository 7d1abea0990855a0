"""Tables of the order-N mutual potential in real solid harmonics along the line of centres,
built once per (order, degree caps) on the host, and the members' coefficient rows (NumPy).

The kernels (``kernels/harmonic_gravity.py``) walk these tables; the formulation is that of
``ti_spinorbit.harmonics`` (its module docstring; docs/physics.md §3.8a), whose functions give
every number here: the fixed matrices J_l = M_l(Rx(90°)) and their transposes, the axial
couplings K_{l1 l2} (diagonal in m) and the rotation generators about x and y.

What the kernels need from the host:

* **coefficient rows** (:func:`coefficient_rows`): each member's Cartesian integral row
  (``multipole_tables.integral_rows``: the primary's integrals of degrees 0..dA, then the
  secondary's of 0..dB, scaled) turned into harmonic coefficients, degree l at columns
  l² .. l² + 2l of each body in class order (``layout.harmonic``: cos even, cos odd, sin
  even, sin odd), the secondary after (dA + 1)² columns;
* **integer table**: the header of ``ti_spinorbit.layout.harmonic``, then per degree the
  offsets of J_l and J_lᵀ in the float table and, for each output class, the one input class
  its dense block reads (about a quarter of each degree's (2l+1)² entries is non-zero, all
  inside these blocks: checked when the tables are built), the generators about x and y as
  exactly two (column, value) pairs per row (padded with a zero), and the interaction blocks
  (l1, l2, offset of the couplings) with l1 ≤ dA, l2 ≤ dB, l1 + l2 ≤ N, neither 1 (first
  moments vanish about the centres of mass) nor a degree the masks leave out;
* **float table**: the dense blocks of J and Jᵀ (row-major, output classes in order), the
  generators' values and the couplings K_{l1 l2}[m, m] for |m| ≤ min(l1, l2), in class order.

Every member walks the same tables in the same order, so threads never diverge; one compiled
kernel serves every order and degree cap (``layout.multipole.KERNEL_ORDER``).
"""

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import harmonics as _hm
from ..layout import harmonic as _K, multipole as _MP

MAX_ORDER = _MP.MAX_ORDER


def count(degree):
    """Multi-indices of degree <= ``degree`` (a Cartesian integral row's columns)."""
    return (degree + 1) * (degree + 2) * (degree + 3) // 6


def classes(l):
    """The orders m of degree l by storage class (``layout.harmonic``): cos even, cos odd,
    sin even, sin odd."""
    return ([m for m in range(0, l + 1, 2)], [m for m in range(1, l + 1, 2)],
            [-m for m in range(2, l + 1, 2)], [-m for m in range(1, l + 1, 2)])


@lru_cache(maxsize=None)
def permutation(l):
    """Positions of the class storage order in the natural order m = −l..l (index m + l)."""
    return np.array([m + l for cls in classes(l) for m in cls], dtype=np.int64)


def _blocks(M, l):
    """For each output class: (input class, dense block) of the degree-l matrix M in class
    order; every other block must be zero (checked)."""
    perm = permutation(l)
    Mp = M[np.ix_(perm, perm)]
    sizes = [len(c) for c in classes(l)]
    off = np.concatenate([[0], np.cumsum(sizes)])
    out = []
    for a in range(4):
        rows = Mp[off[a]:off[a + 1]]
        used = [b for b in range(4) if sizes[b] and np.any(rows[:, off[b]:off[b + 1]] != 0.0)]
        if len(used) > 1:
            raise AssertionError(f"degree {l}: output class {a} reads classes {used}")
        b = used[0] if used else a        # an empty class: any block of its size
        out.append((b, rows[:, off[b]:off[b + 1]]))
    return out


@dataclass(frozen=True, eq=False)
class HarmonicTables:
    """``ints`` (int32), ``floats`` (float64), read-only, for one (order, dA, dB, masks)."""

    order: int
    degree_a: int
    degree_b: int
    ints: np.ndarray
    floats: np.ndarray

    @property
    def width(self):
        """Columns of a coefficient row: (dA + 1)² + (dB + 1)²."""
        return (self.degree_a + 1) ** 2 + (self.degree_b + 1) ** 2

    @property
    def scratch(self):
        """Per-member scratch columns (float64)."""
        return int(self.ints[_K.K_SCRATCH])


ALL_DEGREES = (1 << (MAX_ORDER + 1)) - 1


@lru_cache(maxsize=32)
def tables(order, degree_a, degree_b, mask_a=ALL_DEGREES, mask_b=ALL_DEGREES) -> HarmonicTables:
    """The harmonic tables of the order-``order`` potential with degree caps
    (``degree_a``, ``degree_b``), built once per process (module docstring). ``mask_a``,
    ``mask_b``: bit l clear when that body's degree-l coefficients are zero for every member
    (:func:`degree_mask`; e.g. the odd degrees of ellipsoids), so its rotation and its terms
    are skipped."""
    N, dA, dB = int(order), int(degree_a), int(degree_b)
    if not 0 <= N <= MAX_ORDER or not 0 <= dA <= N or not 0 <= dB <= N:
        raise ValueError(f"tables need 0 <= degrees <= order <= {MAX_ORDER} (got order {N}, "
                         f"degrees ({dA}, {dB}))")
    top = max(dA, dB, 1)
    ints, floats = [0] * _K.KHEAD, []
    head = ints
    deg = []
    for l in range(top + 1):
        entry = []
        ins = []
        for M in (_hm.j_matrix(l), _hm.j_matrix(l).T):
            entry.append(len(floats))
            for b, block in _blocks(M, l):
                ins.append(b)
                floats += [float(v) for v in block.ravel()]
        deg += entry + ins
    head[_K.K_I_DEG] = len(ints)
    ints += deg
    gcols, gvals = [], []
    for l in range(top + 1):
        G = _hm.generators(l)
        perm = permutation(l)
        pos = np.argsort(perm)                    # natural index -> class position
        for i in perm:
            for k in (0, 1):
                nz = [int(c) for c in np.nonzero(G[k][i])[0]]
                if len(nz) > 2:
                    raise AssertionError(f"generator {k} of degree {l} has {len(nz)} entries "
                                         f"in row {i}")
                gvals += [float(G[k][i, c]) for c in nz] + [0.0] * (2 - len(nz))
                gcols += [int(pos[c]) for c in nz] + [int(pos[i])] * (2 - len(nz))
    head[_K.K_I_GC] = len(ints)
    ints += gcols
    head[_K.K_F_G] = len(floats)
    floats += gvals
    pairs = []
    for l1 in range(dA + 1):
        for l2 in range(min(dB, N - l1) + 1):
            if l1 == 1 or l2 == 1 or not (mask_a >> l1) & 1 or not (mask_b >> l2) & 1:
                continue
            K = _hm.coupling(l1, l2)
            mn = min(l1, l2)
            pairs += [l1, l2, len(floats)]
            # the couplings of |m| <= mn in class order of the smaller degree's classes
            floats += [float(K[l1 + m, l2 + m]) for cls in classes(mn) for m in cls]
    head[_K.K_I_PAIR] = len(ints)
    ints += pairs
    head[_K.K_N], head[_K.K_DA], head[_K.K_DB] = N, dA, dB
    head[_K.K_KA], head[_K.K_KB] = min(dA, N - 2), min(dB, N - 2)
    head[_K.K_TOP] = top
    head[_K.K_ROW_B] = (dA + 1) ** 2
    head[_K.K_MASK_A], head[_K.K_MASK_B] = int(mask_a) & ALL_DEGREES, int(mask_b) & ALL_DEGREES
    head[_K.K_NPAIR] = len(pairs) // 3
    offset = 0
    for key, size in ((_K.K_S_A, (dA + 1) ** 2), (_K.K_S_B, (dB + 1) ** 2),
                      (_K.K_S_GA, (dA + 1) ** 2), (_K.K_S_GB, (dB + 1) ** 2),
                      (_K.K_S_T1, 2 * top + 1), (_K.K_S_T2, 2 * top + 1),
                      (_K.K_S_TRIG, 10 * (top + 1)), (_K.K_S_W, N + 2)):
        head[key] = offset
        offset += size
    head[_K.K_SCRATCH] = offset
    ints_arr = np.array(ints, dtype=np.int32)
    floats_arr = np.array(floats + [0.0], dtype=np.float64)     # never empty
    ints_arr.setflags(write=False)
    floats_arr.setflags(write=False)
    return HarmonicTables(N, dA, dB, ints_arr, floats_arr)


def coefficient_rows(rows, degree_a, degree_b):
    """Coefficient rows (N, (dA+1)² + (dB+1)²) of Cartesian integral rows (N, width), degree
    block by degree block. Each output is the same sum in the same order whatever N is
    (``einsum`` without BLAS: a matrix product may block differently for other row counts),
    so a member's coefficients, and its run, do not depend on the other members."""
    rows = np.asarray(rows, dtype=np.float64)
    dA, dB = int(degree_a), int(degree_b)
    out = np.zeros((len(rows), (dA + 1) ** 2 + (dB + 1) ** 2))
    for r0, c0, d in ((0, 0, dA), (count(dA), (dA + 1) ** 2, dB)):
        for l in range(d + 1):
            P = _hm.projector(l)[permutation(l)]
            block = rows[:, r0 + count(l - 1):r0 + count(l)]
            out[:, c0 + l * l:c0 + (l + 1) ** 2] = np.einsum("ij,kj->ik", block, P,
                                                              optimize=False)
    return out


def degree_mask(coefficient_rows_, degree, first=0):
    """Bit l set when a body's degree-l coefficients (columns first + l² .. first + (l+1)² of
    the rows) are not all exactly zero for some row (an ellipsoid's odd degrees are: its odd
    integrals are exact zeros, and so is their projection)."""
    rows = np.asarray(coefficient_rows_)
    mask = 1
    for l in range(2, degree + 1):
        if np.any(rows[:, first + l * l:first + (l + 1) ** 2] != 0.0):
            mask |= 1 << l
    return mask


__all__ = ["HarmonicTables", "tables", "coefficient_rows", "degree_mask",
           "classes", "permutation", "ALL_DEGREES"]
