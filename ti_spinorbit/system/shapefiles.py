"""Polyhedral shape models: read them from the common small-body file formats, and check
that a triangle mesh is a closed, consistently and outward wound surface.

Everything returned is in SI units: vertex coordinates in **metres** (float64, shape (V, 3))
and facets as **0-based** vertex indices (int64, shape (F, 3)), each facet wound so that
its normal ``(v1 - v0) x (v2 - v1)`` points out of the body. Only NumPy is needed; the
optional ``trimesh`` package, imported only when a file's extension is none of ours, adds
the formats it reads (STL, PLY, OFF, ...).

Formats (``read_mesh(..., format=...)``; when ``format`` is None the extension decides and,
for the extensions the vertex-facet tables and ICQ share, the content):

``"obj"`` (``.obj``), Wavefront OBJ
    ``v x y z`` lines (further columns, a w or a colour, are ignored) and ``f`` lines of
    three or more 1-based vertex references, each ``i``, ``i/t``, ``i//n`` or ``i/t/n``
    (only ``i`` is used); a negative ``i`` counts back from the last vertex defined before
    that line (``-1`` is the latest). Polygons are fan-triangulated (``i0 i1 i2``,
    ``i0 i2 i3``, ...). Comments (``#``) and every other statement (``vn``, ``vt``, ``o``,
    ``g``, ``usemtl``, ...) are ignored.

``"tab"`` (``.tab``, ``.txt``, ``.plt``, ``.ver``), the vertex-facet tables of the PDS Small
Bodies Node and of Gaskell's shape models, in the layouts NAIF's MKDSK reads:

    - vertex-facet table: ``v x y z`` and ``f i j k`` lines (1-based; the order of the
      ``v`` lines numbers the vertices);
    - plate-vertex table (Gaskell ``ver``/``plt`` files): a line with the vertex count
      NV, NV lines ``id x y z``, a line with the facet count NF, NF lines
      ``id i j k``; the facets refer to the vertex ids (normally 1..NV);
    - the same with both counts on the first line (``NV NF``), and vertex and facet lines
      with or without their leading id;
    - the Rosetta/OSIRIS ``.ver`` layout: ``NV NF``, NV lines ``x y z``, then each facet as
      a line ``3`` followed by a line ``i j k``.

``"icq"`` (``.icq``; also recognised by content in ``.tab``/``.txt`` files), Gaskell's
implicitly connected quadrilateral format (``SHAPE.TXT`` of stereophotoclinometry): a line
with the resolution Q, then 6(Q+1)^2 lines ``x y z``: the vertices v(I, J, F) of the six
faces F = 1..6 of a cube, each a (Q+1) x (Q+1) grid (F outermost, then J, then I, each
from 0 to Q). Neighbouring faces repeat the vertices of their common cube edges; these are
merged with the edge and corner identities of the format's definition (v(I,0,2) =
v(I,Q,1), ..., v(Q,Q,6) = v(0,Q,4) = v(Q,Q,5)), leaving 6Q^2 + 2 distinct vertices. Each
quadrilateral v(I,J), v(I+1,J), v(I+1,J+1), v(I,J+1) is split into two triangles along the
diagonal whose position vectors have the smaller cross product, as NAIF's MKDSK does, which
gives 12 Q^2 outward-wound facets. Repeated vertices that disagree by more than 1e-3 of the
model's extent mean the file is not an ICQ model (or is corrupt): that is an error.

``"gubas"`` (``.csv``), the CSV pair of the GUBAS full two-body simulator: a vertex file of
rows ``0,x,y,z`` (the first column unused) and a facet file of rows ``i,j,k,,`` (1-based;
trailing empty columns allowed). Pass both: ``read_mesh((vertices_csv, facets_csv))`` or
``read_mesh(vertices_csv, facets=facets_csv)``. The two files are told apart by their
content (four columns of coordinates, three integer columns), so either order works.

Units: ``unit="km"`` (the default, as in PDS and Gaskell models) or ``unit="m"`` (GUBAS
files are in metres) says what the file's numbers are; the result is always metres. A
:class:`ShapeUnitWarning` (a ``UserWarning``) flags a model whose largest extent is above
1000 km or below 1 m after scaling: probably the wrong unit.

Errors are one-line ``ValueError``\\ s: unreadable content names the file and line; an
unknown extension lists the supported formats; a mesh that fails :func:`check_mesh` (run by
``read_mesh`` unless ``check=False``) says what is wrong and where, after the file name.
"""

from __future__ import annotations

import itertools
import os
import re
import warnings
from importlib import resources
from pathlib import Path

import numpy as np

__all__ = ["read_mesh", "check_mesh", "didymos_radar_mesh", "ShapeUnitWarning", "FORMATS"]

#: The formats ``read_mesh`` reads itself (``format=``).
FORMATS = ("obj", "tab", "icq", "gubas")

#: Extension -> format; "tab*" extensions are ICQ when their content says so.
_EXTENSIONS = {".obj": "obj", ".tab": "tab*", ".txt": "tab*", ".plt": "tab*", ".ver": "tab",
               ".icq": "icq", ".csv": "gubas"}

_UNITS = {"km": 1000.0, "m": 1.0}

#: Largest plausible extent of a small body, m (Ceres spans ~960 km), and the smallest.
_MAX_EXTENT_M = 1.0e6
_MIN_EXTENT_M = 1.0

#: Relative tolerances: the zero-area test of check_mesh (|2 x area| <= _DEGENERATE * L^2)
#: and the agreement required of the vertices an ICQ file repeats (fraction of the extent).
_DEGENERATE = 1e-12
_ICQ_MISMATCH = 1e-3

_SLASH = re.compile(r"/\S*")

# the packaged radar model of (65803) Didymos (ti_spinorbit/data/shapes/README.md)
_DIDYMOS_FILES = ("didymos_radar_vertices_m.csv", "didymos_radar_facets.csv")


class ShapeUnitWarning(UserWarning):
    """A shape model whose size after unit scaling is implausible for a small body (larger
    than 1000 km or smaller than 1 m across): probably read with the wrong ``unit``."""


# ---------------------------------------------------------------------------------- text --

class _Lines:
    """The data lines of a text file: stripped, without blank lines or ``#`` comments,
    each with its 1-based line number in the file."""

    def __init__(self, text: str, name: str):
        self.name = name
        lines = text.splitlines()
        if "#" in text:
            lines = [ln.split("#", 1)[0] for ln in lines]
        lines = [ln.strip() for ln in lines]
        keep = np.fromiter((bool(ln) for ln in lines), dtype=bool, count=len(lines))
        self.rows = list(itertools.compress(lines, keep))
        self.lineno = np.flatnonzero(keep) + 1

    def error(self, k: int, message: str) -> ValueError:
        """A one-line error at data line ``k`` (an index into rows; len(rows) = end of file)."""
        if k >= len(self.rows):
            return ValueError(f"{self.name}: {message} (file ends at line "
                              f"{int(self.lineno[-1]) if len(self.rows) else 0})")
        row = self.rows[k]
        shown = row if len(row) <= 72 else row[:69] + "..."
        return ValueError(f"{self.name}, line {int(self.lineno[k])}: {message}; got {shown!r}")


def _table(lines: _Lines, ks, ncols: int, dtype, what: str, *, delimiter=None,
           extra_ok=False, rows=None) -> np.ndarray:
    """Parse the data lines ``ks`` (indices into lines.rows; ``rows`` replaces their text,
    e.g. without a prefix) as an (n, ncols) table of ``dtype``; with ``extra_ok`` further
    columns are ignored. A bad line raises a ValueError naming it."""
    ks = np.asarray(ks, dtype=np.int64)
    if rows is None:
        rows = [lines.rows[k] for k in ks]
    if not rows:
        return np.empty((0, ncols), dtype)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            arr = np.loadtxt(rows, dtype=dtype, delimiter=delimiter, ndmin=2, comments=None,
                             usecols=range(ncols) if extra_ok else None)
        if arr.shape == (len(rows), ncols):
            return arr
    except ValueError:
        pass
    convert = float if np.dtype(dtype).kind == "f" else int
    for k, row in zip(ks, rows):
        toks = [t.strip() for t in row.split(delimiter)]
        ok = len(toks) >= ncols if extra_ok else len(toks) == ncols
        if ok:
            try:
                for t in toks[:ncols]:
                    convert(t)
            except ValueError:
                ok = False
        if not ok:
            raise lines.error(int(k), f"expected {what}")
    raise lines.error(int(ks[0]), f"expected {what}")       # not reached: loadtxt and we agree


def _read_text(path) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{path}: not a text shape file (byte {e.start} is not UTF-8)") from None


def _int_tokens(row: str):
    """The integers of a whitespace-separated row, or None if it is anything else."""
    try:
        return [int(t) for t in row.split()]
    except ValueError:
        return None


# ---------------------------------------------------------------------------------- OBJ --

def _parse_obj(text: str, name: str):
    lines = _Lines(text, name)
    heads = [r[:2] for r in lines.rows]
    is_v = np.fromiter((h in ("v ", "v\t") for h in heads), bool, len(heads))
    is_f = np.fromiter((h in ("f ", "f\t") for h in heads), bool, len(heads))
    vk = np.flatnonzero(is_v)
    fk = np.flatnonzero(is_f)
    if not vk.size or not fk.size:
        raise ValueError(f"{name}: no {'vertex (v)' if not vk.size else 'face (f)'} lines: "
                         f"not an OBJ shape model")
    verts = _table(lines, vk, 3, np.float64, "'v x y z' (three numbers)", extra_ok=True,
                   rows=[lines.rows[k][2:] for k in vk])
    nv = len(verts)
    # vertices defined before each f line (for negative, relative references)
    nv_before = np.cumsum(is_v)[fk]
    frows = [lines.rows[k][2:] for k in fk]
    if "/" in text:
        frows = [_SLASH.sub("", r) for r in frows]
    try:                                                  # fast path: all triangles
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            raw = np.loadtxt(frows, dtype=np.int64, ndmin=2, comments=None)
        if raw.shape[1] != 3:
            raise ValueError
        groups = [(np.arange(len(fk)), raw)]
        ntri = np.ones(len(fk), np.int64)
    except ValueError:
        ntok = np.fromiter((len(r.split()) for r in frows), np.int64, len(frows))
        short = np.flatnonzero(ntok < 3)
        if short.size:
            raise lines.error(int(fk[short[0]]), "a face needs at least three vertices")
        groups = []
        for n in np.unique(ntok):
            sel = np.flatnonzero(ntok == n)
            groups.append((sel, _table(lines, fk[sel], int(n), np.int64,
                                       f"'f' and {n} vertex references",
                                       rows=[frows[s] for s in sel])))
        ntri = ntok - 2
    start = np.concatenate([[0], np.cumsum(ntri)[:-1]])
    faces = np.empty((int(ntri.sum()), 3), np.int64)
    for sel, raw in groups:
        zero = np.flatnonzero((raw == 0).any(axis=1))
        if zero.size:
            raise lines.error(int(fk[sel[zero[0]]]), "OBJ vertex references start at 1 (or "
                                                     "count back from -1), not 0")
        idx = np.where(raw > 0, raw - 1, nv_before[sel][:, None] + raw)
        bad = np.flatnonzero(((idx < 0) | (idx >= nv)).any(axis=1))
        if bad.size:
            raise lines.error(int(fk[sel[bad[0]]]), f"face refers to a vertex the file does "
                                                    f"not define (it has {nv})")
        n = raw.shape[1]
        for j in range(n - 2):                            # fan: (0, j+1, j+2)
            faces[start[sel] + j] = np.stack([idx[:, 0], idx[:, j + 1], idx[:, j + 2]], axis=1)
    return verts, faces


# ---------------------------------------------------------------------- vertex-facet tab --

def _resolve_ids(lines: _Lines, plates, plate_ks, vids, nv: int):
    """0-based facets from the vertex references of a table: 1-based positions when the
    vertex lines carry no id, else the ids they carry (normally 1..NV, or 0..NV-1)."""
    if vids is not None:
        frac = np.flatnonzero(vids != np.round(vids))
        if frac.size:                                     # vertex lines start at data line 1
            raise lines.error(1 + int(frac[0]), "vertex ids must be integers")
        vids = vids.astype(np.int64)
        if np.array_equal(vids, np.arange(1, nv + 1)):
            vids = None
        elif np.array_equal(vids, np.arange(nv)):
            plates = plates + 1
            vids = None
    if vids is None:
        idx = plates - 1
        bad = np.flatnonzero(((idx < 0) | (idx >= nv)).any(axis=1))
        if bad.size:
            raise lines.error(int(plate_ks[bad[0]]), f"facet refers to a vertex outside "
                                                     f"1..{nv}")
        return idx
    order = np.argsort(vids, kind="stable")
    sv = vids[order]
    dup = np.flatnonzero(sv[1:] == sv[:-1])
    if dup.size:
        raise ValueError(f"{lines.name}: vertex id {int(sv[dup[0]])} is used twice")
    pos = np.clip(np.searchsorted(sv, plates), 0, nv - 1)
    bad = np.flatnonzero((sv[pos] != plates).any(axis=1))
    if bad.size:
        raise lines.error(int(plate_ks[bad[0]]), "facet refers to a vertex id no vertex "
                                                 "line has")
    return order[pos]


def _vertex_block(lines: _Lines, ks):
    """Vertex lines ``x y z`` or ``id x y z`` (as the first of them): coordinates and ids."""
    ncol = len(lines.rows[ks[0]].split()) if len(ks) else 3
    if ncol == 4:
        a = _table(lines, ks, 4, np.float64, "a vertex line 'id x y z'")
        return a[:, 1:], a[:, 0]
    return _table(lines, ks, 3, np.float64, "a vertex line 'x y z' (or 'id x y z')"), None


def _plate_block(lines: _Lines, ks):
    ncol = len(lines.rows[ks[0]].split()) if len(ks) else 3
    if ncol == 4:
        return _table(lines, ks, 4, np.int64, "a facet line 'id i j k'")[:, 1:]
    return _table(lines, ks, 3, np.int64, "a facet line 'i j k' (or 'id i j k')")


def _parse_tab(text: str, name: str, lines: _Lines | None = None):
    lines = lines or _Lines(text, name)
    rows = lines.rows
    if not rows:
        raise ValueError(f"{name}: empty shape file")
    head = rows[0].split(None, 1)[0].lower()
    if head in ("v", "f"):                                # vertex-facet table: v/f lines
        kinds = [r[:1].lower() if r[1:2] in (" ", "\t") else "" for r in rows]
        odd = next((k for k, c in enumerate(kinds) if c not in ("v", "f")), None)
        if odd is not None:
            raise lines.error(odd, "expected a 'v x y z' or 'f i j k' line")
        vk = np.flatnonzero(np.fromiter((c == "v" for c in kinds), bool, len(kinds)))
        fk = np.flatnonzero(np.fromiter((c == "f" for c in kinds), bool, len(kinds)))
        if not vk.size or not fk.size:
            raise ValueError(f"{name}: a vertex-facet table needs both 'v' and 'f' lines")
        verts = _table(lines, vk, 3, np.float64, "'v x y z'", rows=[rows[k][2:] for k in vk])
        plates = _table(lines, fk, 3, np.int64, "'f i j k' (three integers)",
                        rows=[rows[k][2:] for k in fk])
        return verts, _resolve_ids(lines, plates, fk, None, len(verts))
    counts = _int_tokens(rows[0])
    if counts is None or len(counts) not in (1, 2) or min(counts) < 1:
        raise lines.error(0, "expected 'v'/'f' lines, or a first line with the vertex count "
                             "(and facet count) of a vertex-facet table")
    nv = counts[0]
    if len(rows) < 1 + nv:
        raise lines.error(len(rows), f"expected {nv} vertex lines after line "
                                     f"{int(lines.lineno[0])}")
    verts, vids = _vertex_block(lines, np.arange(1, 1 + nv))
    k = 1 + nv
    if len(counts) == 1:                                  # NV / vertices / NF / facets
        nf = _int_tokens(rows[k]) if k < len(rows) else None
        if not nf or len(nf) != 1 or nf[0] < 1:
            raise lines.error(k, f"expected the facet count (one integer) after the {nv} "
                                 f"vertices")
        nf = nf[0]
        k += 1
        if len(rows) < k + nf:
            raise lines.error(len(rows), f"expected {nf} facet lines")
        if len(rows) > k + nf:
            raise lines.error(k + nf, f"unexpected line after the {nf} facets")
        pk = np.arange(k, k + nf)
    else:                                                 # NV NF / vertices / facets
        nf = counts[1]
        rest = len(rows) - k
        if rest == 2 * nf and all(rows[j] == "3" for j in range(k, len(rows), 2)):
            pk = np.arange(k + 1, len(rows), 2)           # Rosetta/OSIRIS: "3" / "i j k"
        elif rest == nf:
            pk = np.arange(k, len(rows))
        else:
            raise lines.error(min(k + nf, len(rows)) if rest > nf else len(rows),
                              f"expected {nf} facet lines after the {nv} vertices "
                              f"(counts on line {int(lines.lineno[0])}), found {rest} lines")
    plates = _plate_block(lines, pk)
    return verts, _resolve_ids(lines, plates, pk, vids, nv)


# ---------------------------------------------------------------------------------- ICQ --

def _looks_icq(lines: _Lines) -> bool:
    """A first line with one integer and 'x y z' lines after it, without the facet-count
    line a plate-vertex table has after its vertices: ICQ (so that a truncated ICQ file
    gets the ICQ reader's message)."""
    rows = lines.rows
    n = _int_tokens(rows[0]) if rows else None
    if not n or len(n) != 1 or n[0] < 1 or len(rows) < 2 or len(rows[1].split()) != 3:
        return False
    after = _int_tokens(rows[1 + n[0]]) if len(rows) > 1 + n[0] else None
    return not (after is not None and len(after) == 1)


def _icq_ids(q: int) -> np.ndarray:
    """ICQ vertex merging: n[F-1, I, J] is the raw (file-order) index of vertex v(I, J, F)
    after the cube-edge and corner identities of the format (the first occurrence wins)."""
    m = q + 1
    f, i, j = np.meshgrid(np.arange(6), np.arange(m), np.arange(m), indexing="ij")
    n = f * m * m + j * m + i                              # file order: F, then J, then I
    t = np.arange(1, q)                                    # cube edges (without corners)
    N = lambda F: n[F - 1]                                 # noqa: E731 (1-based face view)
    N(6)[t, q] = N(4)[q - t, q]
    N(6)[t, 0] = N(2)[t, q]
    N(5)[t, 0] = N(1)[q, q - t]
    N(4)[t, 0] = N(1)[q - t, 0]
    N(3)[t, 0] = N(1)[0, t]
    N(2)[t, 0] = N(1)[t, q]
    N(6)[q, t] = N(5)[t, q]
    N(5)[q, t] = N(4)[0, t]
    N(4)[q, t] = N(3)[0, t]
    N(3)[q, t] = N(2)[0, t]
    N(6)[0, t] = N(3)[q - t, q]
    N(5)[0, t] = N(2)[q, t]
    for (a, b, F), (c, d, G) in [((0, 0, 3), (0, 0, 1)), ((q, 0, 4), (0, 0, 1)),
                                 ((0, 0, 2), (0, q, 1)), ((q, 0, 3), (0, q, 1)),
                                 ((0, 0, 4), (q, 0, 1)), ((q, 0, 5), (q, 0, 1)),
                                 ((0, 0, 5), (q, q, 1)), ((q, 0, 2), (q, q, 1)),
                                 ((0, 0, 6), (0, q, 2)), ((q, q, 3), (0, q, 2)),
                                 ((0, q, 5), (q, q, 2)), ((q, 0, 6), (q, q, 2)),
                                 ((q, q, 4), (0, q, 3)), ((0, q, 6), (0, q, 3)),
                                 ((q, q, 5), (0, q, 4)), ((q, q, 6), (0, q, 4))]:
        N(F)[a, b] = N(G)[c, d]
    return n


def _parse_icq(text: str, name: str, lines: _Lines | None = None):
    lines = lines or _Lines(text, name)
    rows = lines.rows
    q = _int_tokens(rows[0]) if rows else None
    if not q or len(q) != 1 or q[0] < 1:
        raise lines.error(0, "expected the ICQ resolution Q (one positive integer)")
    q = q[0]
    m = q + 1
    nraw = 6 * m * m
    if len(rows) < 1 + nraw:
        raise lines.error(len(rows), f"an ICQ model of Q = {q} has 6(Q+1)^2 = {nraw} vertex "
                                     f"lines, found {len(rows) - 1}")
    if len(rows) > 1 + nraw:
        raise lines.error(1 + nraw, f"unexpected line after the {nraw} ICQ vertices")
    raw = _table(lines, np.arange(1, 1 + nraw), 3, np.float64, "an ICQ vertex line 'x y z'")
    n = _icq_ids(q)                                       # (6, m, m): [face, I, J]
    flat = n.reshape(-1)
    own = (np.arange(6)[:, None, None] * m * m + np.arange(m)[None, None, :] * m
           + np.arange(m)[None, :, None]).reshape(-1)     # raw index of each (F, I, J) slot
    extent = float(np.ptp(raw, axis=0).max()) or 1.0
    dev = np.linalg.norm(raw[own] - raw[flat], axis=1)
    bad = np.flatnonzero(dev > _ICQ_MISMATCH * extent)
    if bad.size:
        k = int(bad[0])
        raise lines.error(1 + int(own[k]), f"this ICQ vertex should repeat the one on line "
                                           f"{int(lines.lineno[1 + flat[k]])} (a shared cube "
                                           f"edge) but lies {dev[k]:.4g} from it: not an ICQ "
                                           f"model, or a corrupt one")
    # quadrilaterals (F, I, J), in MKDSK's order: face, then I, then J
    fi, ii, jj = (a.reshape(-1) for a in np.meshgrid(np.arange(6), np.arange(q), np.arange(q),
                                                     indexing="ij"))
    r00 = fi * m * m + jj * m + ii                        # raw indices of the four corners
    r10, r01, r11 = r00 + 1, r00 + m, r00 + m + 1
    w1 = np.linalg.norm(np.cross(raw[r00], raw[r11]), axis=1)
    w2 = np.linalg.norm(np.cross(raw[r10], raw[r01]), axis=1)
    c00, c10, c01, c11 = n[fi, ii, jj], n[fi, ii + 1, jj], n[fi, ii, jj + 1], n[fi, ii + 1, jj + 1]
    d1 = (w1 <= w2)[:, None]
    t1 = np.where(d1, np.stack([c00, c11, c10], 1), np.stack([c00, c01, c10], 1))
    t2 = np.where(d1, np.stack([c00, c01, c11], 1), np.stack([c10, c01, c11], 1))
    faces = np.stack([t1, t2], axis=1).reshape(-1, 3)
    used, faces = np.unique(faces, return_inverse=True)   # drop the repeated vertices
    return raw[used], faces.reshape(-1, 3).astype(np.int64)


# ------------------------------------------------------------------------------- GUBAS --

def _gubas_rows(lines: _Lines):
    return [r.rstrip(", \t") for r in lines.rows]


def _gubas_kind(lines: _Lines):
    """'vertices' (rows of four numbers), 'facets' (rows of three integers) or None."""
    if not lines.rows:
        return None
    toks = [t.strip() for t in lines.rows[0].rstrip(", \t").split(",")]
    if len(toks) == 3:
        try:
            [int(t) for t in toks]
            return "facets"
        except ValueError:
            return None
    return "vertices" if len(toks) == 4 else None


def _parse_gubas(vtext: str, vname: str, ftext: str, fname: str):
    vl, fl = _Lines(vtext, vname), _Lines(ftext, fname)
    kinds = (_gubas_kind(vl), _gubas_kind(fl))
    if kinds == ("facets", "vertices"):
        vl, fl = fl, vl
    elif kinds != ("vertices", "facets"):
        raise ValueError(f"cannot tell the GUBAS vertex file (rows '0,x,y,z') from the facet "
                         f"file (rows 'i,j,k,,') among {vname} and {fname}")
    a = _table(vl, np.arange(len(vl.rows)), 4, np.float64, "a GUBAS vertex row '0,x,y,z'",
               delimiter=",", rows=_gubas_rows(vl))
    plates = _table(fl, np.arange(len(fl.rows)), 3, np.int64, "a GUBAS facet row 'i,j,k,,' "
                    "(three integers)", delimiter=",", rows=_gubas_rows(fl))
    verts = a[:, 1:]
    return verts, _resolve_ids(fl, plates, np.arange(len(fl.rows)), None, len(verts))


# --------------------------------------------------------------------------- read_mesh --

def _supported() -> str:
    return ("supported: obj (.obj), tab (.tab .txt .plt .ver: PDS/Gaskell vertex-facet "
            "tables), icq (.icq, or Gaskell ICQ content in .tab/.txt), gubas (a .csv vertex "
            "and facet pair)")


def _read_with_trimesh(path):
    try:
        import trimesh                                    # optional, only for other formats
    except ImportError:
        raise ValueError(f"cannot tell the shape format of {path} from its extension "
                         f"{Path(path).suffix!r}; {_supported()}; pass format=, or install "
                         f"trimesh for STL/PLY/OFF/...") from None
    mesh = trimesh.load(str(path), force="mesh", process=False)
    return (np.asarray(mesh.vertices, dtype=np.float64),
            np.asarray(mesh.faces, dtype=np.int64))


def read_mesh(path, *, unit: str = "km", format: str | None = None, facets=None,
              check: bool = True):
    """Read a polyhedral shape model.

    Parameters
    ----------
    path : str or os.PathLike, or (vertices_path, facets_path)
        The shape file; for the GUBAS CSV pair, a tuple of the two files (either order),
        or the vertex file with ``facets=``.
    unit : {"km", "m"}
        The length unit of the file's coordinates (default "km", as in PDS and Gaskell
        models; GUBAS files are in metres). The result is in metres either way.
    format : {"obj", "tab", "icq", "gubas"} or None
        The file format (module docstring); None detects it from the extension (and, for
        ``.tab``/``.txt``/``.plt``, the content: ICQ or a vertex-facet table). Other
        extensions are read with ``trimesh`` if it is installed.
    facets : str or os.PathLike, optional
        The GUBAS facet file, when ``path`` is the vertex file.
    check : bool
        Run :func:`check_mesh` on the result (default): a mesh that is not a closed,
        consistently and outward wound surface raises ValueError.

    Returns
    -------
    vertices : ndarray of float64, shape (V, 3)
        Vertex coordinates, m, in the model's own body frame (not re-centred).
    faces : ndarray of int64, shape (F, 3)
        0-based vertex indices of the triangular facets, as wound in the file (outward for
        a valid model).

    Raises
    ------
    ValueError
        One line: an unknown ``unit`` or ``format``, an extension of no known format, the
        file and line of unreadable content, or what :func:`check_mesh` found wrong.

    Warns
    -----
    ShapeUnitWarning
        The model spans more than 1000 km or less than 1 m: probably the wrong ``unit``.
    """
    if unit not in _UNITS:
        raise ValueError(f"unit must be 'km' or 'm' (the unit of the file's coordinates), "
                         f"got {unit!r}")
    if format is not None and format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(map(repr, FORMATS))} (or None to "
                         f"detect it), got {format!r}")
    if isinstance(path, (tuple, list)):
        if len(path) != 2 or facets is not None:
            raise ValueError("a tuple path is the GUBAS pair (vertices_csv, facets_csv); "
                             "give facets= only with a single vertex file")
        path, facets = path
        if format not in (None, "gubas"):
            raise ValueError(f"a pair of files is the GUBAS format, not {format!r}")
        format = "gubas"
    name = os.fspath(path)
    if facets is not None and format not in (None, "gubas"):
        raise ValueError(f"facets= is for the GUBAS CSV pair only, not format={format!r}")
    if format is None:
        format = "gubas" if facets is not None else _EXTENSIONS.get(Path(name).suffix.lower())
    if format == "gubas":
        if facets is None:
            raise ValueError(f"{name}: a GUBAS model is two files: read_mesh((vertices_csv, "
                             f"facets_csv)) or read_mesh(vertices_csv, facets=facets_csv)")
        fname = os.fspath(facets)
        verts, faces = _parse_gubas(_read_text(name), name, _read_text(fname), fname)
        name = f"{name} + {fname}"
    elif format == "obj":
        verts, faces = _parse_obj(_read_text(name), name)
    elif format in ("tab", "tab*", "icq"):
        lines = _Lines(_read_text(name), name)
        if format == "icq" or (format == "tab*" and _looks_icq(lines)):
            verts, faces = _parse_icq("", name, lines)
        else:
            verts, faces = _parse_tab("", name, lines)
    else:
        verts, faces = _read_with_trimesh(name)
    verts = np.ascontiguousarray(verts, dtype=np.float64) * _UNITS[unit]
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    _warn_unit(verts, unit, name)
    if check:
        try:
            check_mesh(verts, faces)
        except ValueError as e:
            raise ValueError(f"{name}: {e}") from None
    return verts, faces


def _warn_unit(verts, unit, name):
    fin = verts[np.isfinite(verts).all(axis=1)]
    if not len(fin):
        return
    extent = float(np.ptp(fin, axis=0).max())
    other = "m" if unit == "km" else "km"
    if extent > _MAX_EXTENT_M:
        warnings.warn(f"{name}: the model spans {extent / 1e3:.4g} km with unit={unit!r}, more "
                      f"than any asteroid (1000 km); is the file in {other}?",
                      ShapeUnitWarning, stacklevel=3)
    elif extent < _MIN_EXTENT_M:
        warnings.warn(f"{name}: the model spans only {extent:.4g} m with unit={unit!r} (less "
                      f"than 1 m); is the file in {other}?", ShapeUnitWarning, stacklevel=3)


# -------------------------------------------------------------------------- check_mesh --

def _edge(a, b):
    return f"({int(a)}, {int(b)})"


def check_mesh(vertices, faces) -> None:
    """Check that a triangle mesh is a closed, consistently wound, outward-facing surface
    (what the volume and inertia integrals of a polyhedron assume).

    Parameters
    ----------
    vertices : array_like, shape (V, 3)
        Vertex coordinates (any length unit; m from :func:`read_mesh`).
    faces : array_like of int, shape (F, 3)
        0-based vertex indices of the triangles.

    Raises
    ------
    ValueError
        One line saying what is wrong and where (0-based vertex and facet indices), from
        the first failing check in this order: array shapes and integer facets; non-finite
        vertices; out-of-range indices; a facet repeating a vertex; degenerate (zero-area:
        twice the area <= 1e-12 L^2, L the largest extent) facets; open edges (on one facet
        only: the surface has a hole); non-manifold edges (on three or more facets);
        inconsistently wound neighbours (a shared edge running the same way in both);
        inward winding (negative signed volume). Vertices no facet uses are allowed.

    Notes
    -----
    Vectorised: each undirected edge is a key ``min * V + max``, sorted once; 3 million
    facets take about a second.
    """
    v = np.asarray(vertices)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3 or not np.issubdtype(v.dtype, np.number):
        raise ValueError(f"vertices must be a numeric (V, 3) array, got shape {v.shape} "
                         f"dtype {v.dtype}")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be an integer (F, 3) array of vertex indices, got shape "
                         f"{f.shape} dtype {f.dtype}")
    nv, nf = len(v), len(f)
    if nf < 4 or nv < 4:
        raise ValueError(f"a closed polyhedron needs at least 4 vertices and 4 facets, got "
                         f"{nv} vertices and {nf} facets")
    v = v.astype(np.float64, copy=False)
    f = f.astype(np.int64, copy=False)
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        raise ValueError(f"{bad.size} vertices are not finite (NaN or inf); the first is "
                         f"vertex {bad[0]} = {v[bad[0]].tolist()}")
    bad = np.flatnonzero(((f < 0) | (f >= nv)).any(axis=1))
    if bad.size:
        raise ValueError(f"{bad.size} facets have vertex indices outside 0..{nv - 1}; the "
                         f"first is facet {bad[0]} = {f[bad[0]].tolist()}")
    bad = np.flatnonzero((f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0]))
    if bad.size:
        raise ValueError(f"{bad.size} facets repeat a vertex index; the first is facet "
                         f"{bad[0]} = {f[bad[0]].tolist()}")
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    cross = np.cross(p1 - p0, p2 - p0)
    used = np.zeros(nv, dtype=bool)
    used[f.reshape(-1)] = True
    scale = float(np.ptp(v[used], axis=0).max()) ** 2
    bad = np.flatnonzero(np.sqrt(np.einsum("ij,ij->i", cross, cross)) <= _DEGENERATE * scale)
    if bad.size:
        raise ValueError(f"{bad.size} facets are degenerate (zero area); the first is facet "
                         f"{bad[0]} = {f[bad[0]].tolist()}")
    # edges: directed a -> b for each facet's three sides, keyed undirected
    a = f.reshape(-1)
    b = f[:, [1, 2, 0]].reshape(-1)
    key = np.minimum(a, b) * nv + np.maximum(a, b)
    order = np.argsort(key)
    ks = key[order]
    first = np.flatnonzero(np.concatenate([[True], ks[1:] != ks[:-1]]))
    count = np.diff(np.concatenate([first, [ks.size]]))
    facet_of = order // 3                                 # facet of each sorted directed edge
    g = np.flatnonzero(count == 1)
    if g.size:
        e = order[first[g]]
        k = int(np.argmin(e))                             # the open edge of the lowest facet
        raise ValueError(f"the mesh is not closed: {g.size} open edges (each on one facet "
                         f"only); the first is edge {_edge(a[e[k]], b[e[k]])} of facet "
                         f"{e[k] // 3}")
    g = np.flatnonzero(count > 2)
    if g.size:
        lowest = np.minimum.reduceat(facet_of, first)[g]
        k = int(np.argmin(lowest))
        s = first[g[k]]
        on = sorted(int(x) for x in facet_of[s:s + count[g[k]]])
        shown = ", ".join(map(str, on[:6])) + (", ..." if len(on) > 6 else "")
        e = order[s]
        raise ValueError(f"the mesh is not manifold: {g.size} edges are on more than two "
                         f"facets; the first is edge {_edge(a[e], b[e])}, on facets {shown}")
    e1, e2 = order[first], order[first + 1]               # every edge now on exactly two
    same = (a[e1] < b[e1]) == (a[e2] < b[e2])
    g = np.flatnonzero(same)
    if g.size:
        later = np.maximum(e1[g], e2[g])
        k = int(np.argmin(later))
        lo, hi = sorted((int(e1[g[k]] // 3), int(e2[g[k]] // 3)))
        e = e1[g[k]]
        raise ValueError(f"the facets are inconsistently wound: facet {hi} runs edge "
                         f"{_edge(a[e], b[e])} the same way as its neighbour facet {lo} "
                         f"({g.size} such edges)")
    vol = float(np.einsum("ij,ij->", p0, np.cross(p1, p2))) / 6.0
    if not vol > 0:
        raise ValueError(f"the facets are wound inward: signed volume {vol:.6g} (vertex units "
                         f"cubed) is not positive; reverse them (faces[:, ::-1])")


# ---------------------------------------------------------------------- packaged model --

def didymos_radar_mesh():
    """The radar shape model of (65803) Didymos (Naidu et al. 2020, Icarus 348, 113777),
    packaged with ti_spinorbit from the GUBAS distribution (provenance and licence in
    ``ti_spinorbit/data/shapes/``).

    Returns
    -------
    vertices : ndarray of float64, shape (1000, 3)
        m, body frame of the model, centre of volume at the origin.
    faces : ndarray of int64, shape (1996, 3)
        0-based, outward wound; signed volume 2.4855e8 m^3.
    """
    base = resources.files("ti_spinorbit.data").joinpath("shapes")
    (vname, vfile), (fname, ffile) = ((n, base.joinpath(n)) for n in _DIDYMOS_FILES)
    verts, faces = _parse_gubas(vfile.read_text(encoding="utf-8"), vname,
                                ffile.read_text(encoding="utf-8"), fname)
    verts = np.ascontiguousarray(verts, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    check_mesh(verts, faces)
    return verts, faces
