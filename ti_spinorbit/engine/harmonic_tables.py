"""Tables of the order-N mutual potential in real solid harmonics along the line of centres,
built once per (order, degree caps, masks) on the host, and the members' coefficient rows
(NumPy).

The kernels (``kernels/harmonic_gravity.py``) walk these tables; the formulation is that of
``ti_spinorbit.harmonics`` (its module docstring; docs/physics.md §3.8.2), whose functions give
every number here: the fixed matrices J_l = M_l(Rx(90°)) and their transposes, the axial
couplings K_{l1 l2} (diagonal in m) and the rotation generators about x and y.

What the kernels need from the host:

* **coefficient rows** (:func:`coefficient_rows`): each member's Cartesian integral row
  (``multipole_tables.integral_rows``: the primary's integrals of degrees 0..dA, then the
  secondary's of 0..dB, scaled) turned into harmonic coefficients, degree l at columns
  l² .. l² + 2l of each body in class order (``layout.harmonic``: cos even, cos odd, sin
  even, sin odd), the secondary after (dA + 1)² columns;
* **integer table**: the header of ``ti_spinorbit.layout.harmonic`` and, per body, a
  program of flat lists that the kernel walks in order:

  - the pairs (p, q, m) that load the member's coefficients turned by the first z-rotation,
    each degree's orders in steps of one (of two: STEP2) from its first entry (RESTART), so
    that the kernel steps the multiple angles by the addition formula;
  - the plain chunks of J: :data:`CHUNK` columns of a row ((destination, source, add), one
    int): each output class of J_l reads one input class as a dense block, about a quarter
    of the degree's (2l+1)² entries, all others zero (checked when the tables are built); a
    chunk reads consecutive entries of its own degree only, and its weights are the list's
    e-th group of CHUNK floats (from the program's P_FJ). Plain are the m = 0 rows and the
    leading chunks of rows longer than CHUNK;
  - the fused entries of J and the second z-rotation: for each pair (m, −m) the last chunk
    of both rows (two ints; 2 CHUNK weights from P_FJX), added to the rows' partial sums
    (ADD_P, ADD_Q), then rotated by mψ (m = 1, 2, ... from RESTART);
  - the same two lists for Jᵀ and the last z-rotation (P_JT, P_JTX; the secondary has no
    last rotation, so all its Jᵀ chunks are plain);
  - the rows of ∂U/∂C that the torque reads, each with its generators' two columns about x
    and about y (packed) and their four values (from P_FROW);

  then the interaction terms (ia, ib, l1 + l2 and flags) for l1 ≤ dA, l2 ≤ dB,
  l1 + l2 ≤ N, neither 1 (first moments vanish about the centres of mass) nor a masked
  degree, |m| ≤ min(l1, l2), in the order (l1, m, l2), so that each of the primary's ∂U/∂C
  rows is a run of consecutive terms (summed in a register, stored by the last: LAST_A) and
  each of the secondary's is stored by its first term (FIRST_B): nothing is zeroed first;
  then the secondary's z-torque pairs. Entries of three small fields are packed into one
  int32 (:func:`pack`);
* **float table**: the chunk weights of each J and Jᵀ list (plain and fused) and the
  generators' values of each program's torque rows, each in its list's order, and the
  couplings K_{l1 l2}[m, m] of the terms.

What the programs leave out (docs/physics.md §3.8.2): a degree's terms reach only
|m| ≤ m_l (:func:`top_orders`), so its Jᵀ rows and last pairs stop at |m| ≤ m_l + 1 (the
torques read the generators' neighbours) and its rows of ∂U/∂C at |m| ≤ m_l; a body's degrees
that are zero in every member (:func:`degree_mask`: an ellipsoid's odd degrees) are skipped;
for a body whose coefficients are cos-even only at an even degree (:func:`even_mask`: three
mirror planes, an ellipsoid) the load reads no sines, the first J computes only the two cos
classes (the others would read zeros), and the second z-rotation's pairs are flagged
(ZERO_SIN) not to read their zero sines.

Every member walks the same tables in the same order, so threads never diverge; one compiled
kernel serves every order, cap and mask (``layout.multipole.KERNEL_ORDER``).
"""

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import harmonics as _hm
from ..layout import harmonic as _K, multipole as _MP
from ..multipole import _count as count    # a Cartesian integral row's columns, degree <= d

MAX_ORDER = _MP.MAX_ORDER


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


#: Columns per chunk of a J row: a row of a dense class block (at most 7 columns, at degree
#: 12) is one or two chunks of fixed width, a loop-free 4-term product in the kernel
#: (measured faster than a loop over the row's columns, whose length is 1 to 7).
CHUNK = 4
#: Flags in the third field of packed entries: a pair (p, q, m) whose q entry is known to be
#: zero (not read); the last term of a ∂U/∂C row of the primary (stores the row's sum), the
#: first of one of the secondary (stores instead of adding). The third field of a J row is 1
#: when the chunk adds to its row.
ZERO_SIN = 1 << 5
LAST_A, FIRST_B = 1 << 6, 1 << 7
#: Flags of a fused entry (J rows p and q, then their z-rotation): row p (q) adds its last
#: chunk to the partial sum its earlier chunks left (a row longer than CHUNK).
ADD_P, ADD_Q = 1 << 6, 1 << 7
#: Flags of a pair list's entries: the first entry of its degree (the multiple angle restarts
#: from m = 0), and an entry two orders after the one before (only the even orders of a
#: mirror-symmetric body are loaded); the kernel walks the multiples by the addition formula.
RESTART, STEP2 = 1 << 8, 1 << 9


#: Bits of a position in a packed table entry: positions within a body's region are below
#: (MAX_ORDER + 1)² = 289 < 2⁹. Entries of three small fields are one int32 (a | b << 9 |
#: c << 18), one load in the kernel instead of three.
BITS = 9


def pack(a, b, c=0):
    """One int32 holding a, b (< 2⁹) and c (< 2¹³)."""
    if not (0 <= a < 1 << BITS and 0 <= b < 1 << BITS and 0 <= c < 1 << 13):
        raise AssertionError(f"table entry ({a}, {b}, {c}) does not pack")
    return a | (b << BITS) | (c << 2 * BITS)


def position(l, m):
    """Position of order m within degree l in class storage order."""
    n0, n1, n2 = l // 2 + 1, (l + 1) // 2, l // 2
    if m >= 0:
        return m // 2 if m % 2 == 0 else n0 + (m - 1) // 2
    return n0 + n1 + (-m // 2 - 1) if m % 2 == 0 else n0 + n1 + n2 + (-m - 1) // 2


def top_orders(order, degree_a, degree_b, masks=(ALL_DEGREES, ALL_DEGREES)):
    """For each body, {degree l: the largest |m| its interaction terms reach}: min(l, the
    largest partner degree l2 of the other body, l2 = 0 or 2 <= l2 <= min(d_other, N − l),
    not masked out). Degrees above N − 2 meet only the monopole (0)."""
    N = int(order)
    degs = (int(degree_a), int(degree_b))
    out = ({}, {})
    for body in (0, 1):
        other = 1 - body
        for l in range(2, degs[body] + 1):
            partners = [l2 for l2 in range(2, min(degs[other], N - l) + 1)
                        if (masks[other] >> l2) & 1]
            out[body][l] = min(l, max(partners, default=0))
    return out


@lru_cache(maxsize=32)
def tables(order, degree_a, degree_b, mask_a=ALL_DEGREES, mask_b=ALL_DEGREES, even_a=0,
           even_b=0) -> HarmonicTables:
    """The harmonic tables of the order-``order`` potential with degree caps
    (``degree_a``, ``degree_b``), built once per process (module docstring). ``mask_a``,
    ``mask_b``: bit l clear when that body's degree-l coefficients are zero for every member
    (:func:`degree_mask`; e.g. the odd degrees of ellipsoids), so its rotation and its terms
    are left out. ``even_a``, ``even_b``: bit l set when only the cos-even class of that
    degree is non-zero in every member (:func:`even_mask`: a body with three mirror planes in
    its frame, e.g. an ellipsoid), so at even degrees the load reads no sines, the first J
    product computes only the cos classes and the second z-rotation reads no sines."""
    N, dA, dB = int(order), int(degree_a), int(degree_b)
    if not 0 <= N <= MAX_ORDER or not 0 <= dA <= N or not 0 <= dB <= N:
        raise ValueError(f"tables need 0 <= degrees <= order <= {MAX_ORDER} (got order {N}, "
                         f"degrees ({dA}, {dB}))")
    top = max(dA, dB, 1)
    masks = (int(mask_a), int(mask_b))
    evens = (int(even_a), int(even_b))
    ints, floats = [0] * _K.KHEAD, []
    head = ints

    def put(values):
        start = len(ints)
        ints.extend(int(v) for v in values)
        return start

    # the dense class blocks of J_l and J_lᵀ, once for every degree the bodies use; the
    # programs' rows read them again as padded chunks (after the program is built)
    block_at, dense = {}, []
    for l in range(2, top + 1):
        for which, M in ((0, _hm.j_matrix(l)), (1, _hm.j_matrix(l).T)):
            entry = []
            for b, blk in _blocks(M, l):
                entry.append((b, len(dense), blk.shape[1]))
                dense += [float(v) for v in blk.ravel()]
            block_at[(l, which)] = entry
    # the generators about x and y: two (column, value) pairs per global row l² + position,
    # copied into each torque row of the programs
    gcols, gvals = [], []
    for l in range(top + 1):
        G = _hm.generators(l)
        pos = np.argsort(permutation(l))          # natural index -> class position
        for i in permutation(l):
            for k in (0, 1):
                nz = [int(c) for c in np.nonzero(G[k][i])[0]]
                if len(nz) > 2:
                    raise AssertionError(f"generator {k} of degree {l} has {len(nz)} entries "
                                         f"in row {i}")
                gvals += [float(G[k][i, c]) for c in nz] + [0.0] * (2 - len(nz))
                cols = [l * l + int(pos[c]) for c in nz] + [l * l + int(pos[i])] * (2 - len(nz))
                gcols.append(pack(*cols))

    offset = 0
    regions = {}
    for key, size in ((_K.K_S_A, (dA + 1) ** 2), (_K.K_S_B, (dB + 1) ** 2),
                      (_K.K_S_GA, (dA + 1) ** 2), (_K.K_S_GB, (dB + 1) ** 2),
                      (_K.K_S_T1, 2 * (top + 1) ** 2), (_K.K_S_T2, (top + 1) ** 2),
                      (_K.K_S_W, N + 2)):
        head[key] = regions[key] = offset
        offset += size
    head[_K.K_SCRATCH] = offset
    head[_K.K_WIDTH] = (dA + 1) ** 2 + (dB + 1) ** 2
    head[_K.K_TWO] = 2

    # each body's program: its degrees 2..d that are not masked out. Only the orders a degree
    # needs are computed: its terms reach |m| <= top_m (:func:`top_orders`), the torques read
    # its coefficients one order further (the generators' neighbours), so the Jᵀ rows and
    # last pairs stop at |m| <= top_m + 1 and the rows of ∂U/∂C at |m| <= top_m
    tops = top_orders(N, dA, dB, masks)
    for body, (d, src, dst, acc, t1, slots) in enumerate((
            (dA, 0, regions[_K.K_S_A], regions[_K.K_S_GA], regions[_K.K_S_T1], (0, 1, 2)),
            (dB, (dA + 1) ** 2, regions[_K.K_S_B], regions[_K.K_S_GB],
             regions[_K.K_S_T1] + (top + 1) ** 2, (3, 4, -1)))):
        lists = {name: [] for name in ("load", "j", "jx", "jt", "jtx", "row")}
        weights = {"j": [], "jx": [], "jt": [], "jtx": []}
        for l in range(2, d + 1):
            if not (masks[body] >> l) & 1:
                continue
            mt = tops[body][l]
            reach = min(l, mt + 1)
            # (an even degree: at an odd one J sends the cos-even class elsewhere)
            even = bool((evens[body] >> l) & 1) and l % 2 == 0
            base = l * l
            pairs = [(base + position(l, m), base + position(l, -m), m) if m else
                     (base, base, 0) for m in range(l + 1)]
            if even:
                # only cos-even coefficients: the first z-rotation reads the cos-even ones
                # (their sin partners are zero: not read), the first J computes only the
                # classes it fills from them (cos even, cos odd; the others would read
                # zeros), and every pair of the second z-rotation then has a zero sin
                # partner (not read; both written)
                lists["load"] += [(p_, q_, (m | ZERO_SIN | STEP2) if m else RESTART)
                                  for p_, q_, m in pairs if m % 2 == 0]
                x1 = [(p_, q_, m | ZERO_SIN | (RESTART if m == 1 else 0))
                      for p_, q_, m in pairs[1:]]
            else:
                lists["load"] += [(p_, q_, m | (RESTART if m == 0 else 0))
                                  for p_, q_, m in pairs]
                x1 = [(p_, q_, m | (RESTART if m == 1 else 0)) for p_, q_, m in pairs[1:]]
            # the pairs of the last z-rotation: the primary's only
            x2 = ([(p_, q_, m | (RESTART if m == 1 else 0)) for p_, q_, m in pairs[1:reach + 1]]
                  if slots[2] >= 0 else [])
            sizes = [len(c) for c in classes(l)]
            off = np.concatenate([[0], np.cumsum(sizes)])
            for which, name, xname, xpairs in ((0, "j", "jx", x1), (1, "jt", "jtx", x2)):
                chunks = {}                        # destination row -> [(source, weights, add)]
                for a, (b, fo, nb) in enumerate(block_at[(l, which)]):
                    if which == 0 and even and b in (1, 3):
                        continue                   # reads the cos-odd or sin-odd class
                    for i in range(sizes[a]):
                        if which == 1 and abs(classes(l)[a][i]) > reach:
                            continue
                        # a row in chunks of CHUNK columns: (destination, source, add). A
                        # chunk reads CHUNK consecutive entries of this degree only
                        # (2l + 1 >= 5), shifted back at the degree's end, with zero weights
                        # where it overlaps other columns: it reads only entries this
                        # evaluation has written
                        row = dense[fo + i * nb:fo + (i + 1) * nb]
                        for c0 in range(0, max(nb, 1), CHUNK):
                            st = min(off[b] + c0, 2 * l + 1 - CHUNK)
                            chunks.setdefault(base + off[a] + i, []).append((base + st, [
                                row[st + q - off[b]] if c0 <= st + q - off[b] < min(c0 + CHUNK, nb)
                                else 0.0 for q in range(CHUNK)], int(c0 > 0)))
                # the rows of a z-rotation pair end in one fused entry: the last chunk of
                # each row, then the rotation (ADD_P, ADD_Q: the row's earlier chunks are
                # in the plain list, which runs first); every other chunk is plain
                fused = {r for p_, q_, _ in xpairs for r in (p_, q_)}
                for row_, ch in chunks.items():
                    for s_, w, add in (ch[:-1] if row_ in fused else ch):
                        lists[name].append((row_, s_, add))
                        weights[name].append(w)
                for p_, q_, mf in xpairs:
                    cp = chunks[p_][-1]
                    cq = None if mf & ZERO_SIN else chunks[q_][-1]
                    flags = mf | (ADD_P if cp[2] else 0) | (ADD_Q if cq and cq[2] else 0)
                    lists[xname].append((pack(p_, cp[0], flags),
                                         pack(q_, cq[0] if cq else cp[0])))
                    weights[xname].append(cp[1] + (cq[1] if cq else [0.0] * CHUNK))
            lists["row"] += [base + position(l, m) for m in range(-mt, mt + 1)]
        prog = [0] * _K.PROGRAM_WIDTH
        for nkey, okey, name in ((_K.P_NLOAD, _K.P_LOAD, "load"), (_K.P_NJ, _K.P_J, "j"),
                                 (_K.P_NJX, _K.P_JX, "jx"), (_K.P_NJT, _K.P_JT, "jt"),
                                 (_K.P_NJTX, _K.P_JTX, "jtx"), (_K.P_NROW, _K.P_ROW, "row")):
            items = lists[name]
            prog[nkey] = len(items)
            if name == "row":                 # (g, its generator columns about x, about y)
                prog[okey] = put([v for g in items for v in (g, gcols[2 * g], gcols[2 * g + 1])])
            elif name in ("jx", "jtx"):       # two packed ints per fused entry
                prog[okey] = put([v for it in items for v in it])
            else:
                prog[okey] = put([pack(*it) for it in items])
        # the weights in each list's own order: plain chunk e's CHUNK at P_FJ (P_FJT) +
        # CHUNK e, fused entry e's 2 CHUNK (row p's, row q's) at P_FJX (P_FJTX) + 2 CHUNK e,
        # torque row e's generator values (x, x, y, y) at P_FROW + 4 e
        weights["row"] = [gvals[4 * g:4 * g + 4] for g in lists["row"]]
        for fkey, name in ((_K.P_FJ, "j"), (_K.P_FJX, "jx"), (_K.P_FJT, "jt"),
                           (_K.P_FJTX, "jtx"), (_K.P_FROW, "row")):
            prog[fkey] = len(floats)
            for w in weights[name]:
                floats += w
        prog[_K.P_SRC], prog[_K.P_DST], prog[_K.P_ACC], prog[_K.P_T1] = src, dst, acc, t1
        prog[_K.P_Z0], prog[_K.P_Z1], prog[_K.P_Z2] = slots
        at = _K.K_PROG_A if body == 0 else _K.K_PROG_B
        head[at:at + _K.PROGRAM_WIDTH] = prog

    # the interaction terms (ia, ib, L) with their couplings, and the z-torque pairs
    # in the order (l1, m, l2), so that each of the primary's ∂U/∂C rows is one run of
    # consecutive terms, summed in a register and stored by its last term (LAST_A); the
    # first term of each of the secondary's rows stores instead of adding (FIRST_B): no row
    # is zeroed first, and every row the torques read is one some term wrote
    terms, kvals = [], []
    touched = set()
    for l1 in range(dA + 1):
        if l1 == 1 or not (masks[0] >> l1) & 1:
            continue
        partners = [l2 for l2 in range(min(dB, N - l1) + 1)
                    if l2 != 1 and (masks[1] >> l2) & 1]
        for m in range(-l1, l1 + 1):
            mine = [l2 for l2 in partners if abs(m) <= l2]
            for n_, l2 in enumerate(mine):
                ia, ib = l1 * l1 + position(l1, m), l2 * l2 + position(l2, m)
                flags = (LAST_A if n_ == len(mine) - 1 else 0) | \
                    (FIRST_B if ib not in touched else 0)
                touched.add(ib)
                terms.append(pack(ia, ib, (l1 + l2) | flags))
                kvals.append(float(_hm.coupling(l1, l2)[l1 + m, l2 + m]))
    head[_K.K_NTERM] = len(kvals)
    head[_K.K_I_TERM] = put(terms)
    head[_K.K_F_TERM] = len(floats)
    floats += kvals
    bz = []
    for l in range(2, min(dB, N - 2) + 1):
        if (masks[1] >> l) & 1:
            bz += [pack(l * l + position(l, m), l * l + position(l, -m), m)
                   for m in range(1, tops[1][l] + 1)]
    head[_K.K_NBZ] = len(bz)
    head[_K.K_I_BZ] = put(bz)
    head[_K.K_NPOW] = N + 1
    head[_K.K_TOP] = top
    floats_arr = np.array(floats + [0.0], dtype=np.float64)     # never empty
    ints_arr = np.array(ints, dtype=np.int32)
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


def even_mask(coefficient_rows_, degree, first=0):
    """Bit l set when a body's degree-l coefficients are zero outside the cos-even class (the
    first l // 2 + 1 of the degree in class order) in every row: a body with three mirror
    planes in its frame (an ellipsoid; the projection keeps those zeros exact)."""
    rows = np.asarray(coefficient_rows_)
    mask = 0
    for l in range(2, degree + 1):
        if not np.any(rows[:, first + l * l + l // 2 + 1:first + (l + 1) ** 2] != 0.0):
            mask |= 1 << l
    return mask


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


__all__ = ["HarmonicTables", "tables", "top_orders", "coefficient_rows", "degree_mask", "even_mask",
           "classes", "permutation", "ALL_DEGREES"]
