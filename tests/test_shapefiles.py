"""Shape-model files (ti_spinorbit.system.shapefiles): every format read back from files
written here from known meshes, the ICQ connectivity on synthetic cube and sphere models,
the packaged Didymos radar model, and the one-line error of every failure."""

import re
import sys
import types
from importlib import resources

import numpy as np
import pytest

from ti_spinorbit.system.shapefiles import (FORMATS, ShapeUnitWarning, check_mesh,
                                            didymos_radar_mesh, read_mesh)


# ------------------------------------------------------------------------ known meshes --

def signed_volume(v, f):
    """Sum of v1 . (v2 x v3) / 6 over the facets (independent of the module)."""
    v1, v2, v3 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.sum(v1 * np.cross(v2, v3))) / 6.0


def icosphere(subdivisions=1, radius=1.0):
    """An outward-wound icosahedron, subdivided, on a sphere of ``radius``."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    v = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(subdivisions):
        mid, nf = {}, []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[k] = len(v) - 1
            return mid[k]
        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return np.array(v) * radius, np.array(f, dtype=np.int64)


CUBE_V = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
# outward quads of the cube above (vertex index = 4*(x>0) + 2*(y>0) + (z>0))
CUBE_QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
              (1, 5, 7, 3)]


@pytest.fixture(scope="module")
def sphere():
    return icosphere(2, radius=1.5)        # 162 vertices, 320 facets, unit km in the files


def assert_same_mesh(got, want, scale=1000.0):
    gv, gf = got
    wv, wf = want
    assert gv.dtype == np.float64 and gf.dtype == np.int64
    assert gv.shape == wv.shape and gf.shape == wf.shape
    np.testing.assert_allclose(gv, wv * scale, rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(gf, wf)


def fmt(x):
    return f"{x:.17g}"


# ---------------------------------------------------------------------------- formats --

def test_obj_round_trip_with_slashes_negative_indices_and_comments(tmp_path, sphere):
    v, f = sphere
    lines = ["# an icosphere", "o body", "mtllib none.mtl"]
    lines += [f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
    lines += ["vn 0 0 1", "vt 0.5 0.5", "s off"]
    nv = len(v)
    for k, (a, b, c) in enumerate(f):
        if k % 3 == 0:
            lines.append(f"f {a + 1} {b + 1} {c + 1}")
        elif k % 3 == 1:
            lines.append(f"f {a + 1}/1/1 {b + 1}//1 {c + 1}/1")
        else:                                 # relative: -1 is the last vertex so far
            lines.append(f"f {a - nv} {b - nv} {c - nv}  # relative")
    p = tmp_path / "ico.obj"
    p.write_text("\n".join(lines) + "\n")
    assert_same_mesh(read_mesh(p), sphere)
    assert_same_mesh(read_mesh(str(p), unit="m"), sphere, scale=1.0)


def test_obj_relative_indices_count_from_the_vertices_defined_so_far(tmp_path):
    # each face written right after its own three vertices, referenced as -3 -2 -1
    v, f = icosphere(0, radius=2.0)
    lines = []
    for a, b, c in f:
        lines += [f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v[[a, b, c]]]
        lines.append("f -3 -2 -1")
    p = tmp_path / "soup.obj"
    p.write_text("\n".join(lines))
    gv, gf = read_mesh(p, check=False)         # a triangle soup: not closed, by design
    assert gv.shape == (3 * len(f), 3)
    np.testing.assert_array_equal(gf, np.arange(3 * len(f)).reshape(-1, 3))
    np.testing.assert_allclose(gv[gf], v[f] * 1000)


def test_obj_polygons_are_fan_triangulated(tmp_path):
    lines = [f"v {x:g} {y:g} {z:g}" for x, y, z in CUBE_V]
    lines += ["f " + " ".join(str(i + 1) for i in q) for q in CUBE_QUADS[:5]]
    a, b, c, d = CUBE_QUADS[5]                 # the last face as two triangles
    lines += [f"f {a + 1} {b + 1} {c + 1}", f"f {a + 1} {c + 1} {d + 1}"]
    p = tmp_path / "cube.obj"
    p.write_text("\n".join(lines))
    v, f = read_mesh(p, unit="m")
    assert f.shape == (12, 3)
    np.testing.assert_array_equal(f[:2], [[0, 1, 3], [0, 3, 2]])   # fan of the first quad
    assert signed_volume(v, f) == pytest.approx(8.0, rel=1e-14)


def test_tab_vertex_facet_v_f_form(tmp_path, sphere):
    v, f = sphere
    text = "\n".join([f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                     + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f])
    for name in ("m.tab", "m.txt", "m.plt"):
        (tmp_path / name).write_text(text)
        assert_same_mesh(read_mesh(tmp_path / name), sphere)


def test_tab_plate_vertex_table_counts_on_their_own_lines(tmp_path, sphere):
    # Gaskell / MKDSK plate type 1: NV, "id x y z" lines, NF, "id i j k" lines
    v, f = sphere
    text = "\n".join([str(len(v))]
                     + [f"{k + 1} {fmt(x)} {fmt(y)} {fmt(z)}" for k, (x, y, z) in enumerate(v)]
                     + [str(len(f))]
                     + [f"{k + 1} {a + 1} {b + 1} {c + 1}" for k, (a, b, c) in enumerate(f)])
    (tmp_path / "ver.tab").write_text(text)
    assert_same_mesh(read_mesh(tmp_path / "ver.tab"), sphere)
    bare = "\n".join([str(len(v))] + [f"{fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                     + [str(len(f))] + [f"{a + 1} {b + 1} {c + 1}" for a, b, c in f])
    (tmp_path / "ver.txt").write_text(bare)            # not mistaken for ICQ
    assert_same_mesh(read_mesh(tmp_path / "ver.txt"), sphere)


def test_tab_counts_on_the_first_line_with_and_without_ids(tmp_path, sphere):
    v, f = sphere
    head = f"{len(v)} {len(f)}"
    indexed = "\n".join([head]
                        + [f"{k + 1} {fmt(x)} {fmt(y)} {fmt(z)}" for k, (x, y, z) in enumerate(v)]
                        + [f"{k + 1} {a + 1} {b + 1} {c + 1}" for k, (a, b, c) in enumerate(f)])
    bare = "\n".join([head] + [f"{fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                     + [f"{a + 1} {b + 1} {c + 1}" for a, b, c in f])
    rosetta = "\n".join([head] + [f"{fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                        + [s for a, b, c in f for s in ("3", f"{a + 1} {b + 1} {c + 1}")])
    for name, text in [("a.tab", indexed), ("b.txt", bare), ("c.ver", rosetta)]:
        (tmp_path / name).write_text(text)
        assert_same_mesh(read_mesh(tmp_path / name), sphere)
        assert_same_mesh(read_mesh(tmp_path / name, format="tab"), sphere)


def test_tab_facets_refer_to_the_vertex_ids(tmp_path, sphere):
    v, f = sphere
    for ids in (np.arange(len(v)), 10 * np.arange(len(v))[::-1] + 7):   # 0-based; arbitrary
        text = "\n".join([str(len(v))]
                         + [f"{i} {fmt(x)} {fmt(y)} {fmt(z)}" for i, (x, y, z) in zip(ids, v)]
                         + [str(len(f))]
                         + [f"{k + 1} {ids[a]} {ids[b]} {ids[c]}" for k, (a, b, c) in enumerate(f)])
        (tmp_path / "ids.tab").write_text(text)
        assert_same_mesh(read_mesh(tmp_path / "ids.tab"), sphere)


def test_gubas_pair_in_both_calling_forms_and_either_order(tmp_path, sphere):
    v, f = sphere
    vp, fp = tmp_path / "verts.csv", tmp_path / "facets.csv"
    vp.write_text("\n".join(f"0,{fmt(x)},{fmt(y)},{fmt(z)}" for x, y, z in v) + "\n")
    fp.write_text("\n".join(f"{a + 1},{b + 1},{c + 1},," for a, b, c in f) + "\n")
    want = (v, f)
    assert_same_mesh(read_mesh((vp, fp), unit="m"), want, scale=1.0)
    assert_same_mesh(read_mesh(vp, facets=fp, unit="m"), want, scale=1.0)
    assert_same_mesh(read_mesh((fp, vp), unit="m"), want, scale=1.0)
    assert_same_mesh(read_mesh(str(vp), facets=str(fp), unit="km", format="gubas"), want)


# -------------------------------------------------------------------------------- ICQ --

def icq_points(q):
    """The 6 (q+1)^2 grid points of an ICQ model on the cube [-1, 1]^3, in file order
    (face F = 1..6, then J, then I). Face 1 is +z with I along +x and J along -y, as in
    Gaskell's models; the other faces follow from the format's shared-edge identities."""
    u = -1 + 2 * np.arange(q + 1) / q
    I, J = np.meshgrid(u, u, indexing="xy")      # I varies fastest (rows of constant J)
    one = np.ones_like(I)
    faces = [(I, -J, one), (I, -one, -J), (-one, -I, -J), (-I, one, -J), (one, I, -J),
             (I, J, -one)]
    return np.concatenate([np.stack(c, axis=-1).reshape(-1, 3) for c in faces])


def write_icq(path, points, q):
    path.write_text(f"{q:10d}\n" + "\n".join(f"{fmt(x)} {fmt(y)} {fmt(z)}"
                                             for x, y, z in points) + "\n")


def test_icq_cube_is_closed_with_the_exact_volume_and_counts(tmp_path):
    q = 6
    p = tmp_path / "cube.icq"
    write_icq(p, 2.0 * icq_points(q), q)          # side 4 km
    v, f = read_mesh(p)
    assert v.shape == (6 * q * q + 2, 3) and f.shape == (12 * q * q, 3)
    check_mesh(v, f)                              # closed, consistently and outward wound
    edges = {tuple(sorted(e)) for t in f for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert len(v) - len(edges) + len(f) == 2      # Euler: a closed genus-0 surface
    assert signed_volume(v, f) == pytest.approx(4000.0 ** 3, rel=1e-12)
    # the grid points are all there, once each
    np.testing.assert_allclose(np.sort(np.abs(v).max(axis=1)), 2000.0)


def test_icq_sphere_volume_and_detection_by_content(tmp_path):
    q, r = 16, 3.0
    pts = icq_points(q)
    pts = r * pts / np.linalg.norm(pts, axis=1, keepdims=True)
    p = tmp_path / "SHAPE.TXT"
    write_icq(p, pts, q)
    v, f = read_mesh(p)                           # .txt: ICQ recognised from the content
    check_mesh(v, f)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), r * 1000)
    vol, sphere = signed_volume(v, f), 4 / 3 * np.pi * (r * 1000) ** 3
    assert 0.99 * sphere < vol < sphere          # inscribed polyhedron: slightly smaller
    v2, f2 = read_mesh(p, format="icq")
    np.testing.assert_array_equal(f2, f)
    # the diagonal choice: each quad is split along its shorter cross product, and both
    # choices give the same closed surface
    assert signed_volume(v2, f2) == pytest.approx(vol, rel=1e-15)


def test_icq_repeated_vertices_must_agree(tmp_path):
    q = 4
    pts = icq_points(q)
    m = q + 1
    pts[1 * m * m + 0 * m + 2] += [0.0, 0.0, 0.5]   # v(2, 0, 2) repeats v(2, Q, 1)
    p = tmp_path / "bad.icq"
    write_icq(p, pts, q)
    line = 1 + 1 * m * m + 2 + 1                    # its line in the file
    with pytest.raises(ValueError, match=rf"bad\.icq, line {line}: this ICQ vertex should "
                                         rf"repeat the one on line {1 + q * m + 2 + 1}"):
        read_mesh(p)


def test_icq_wrong_number_of_lines(tmp_path):
    q = 3
    p = tmp_path / "short.icq"
    write_icq(p, icq_points(q)[:-2], q)
    with pytest.raises(ValueError, match=r"short\.icq: an ICQ model of Q = 3 has 6\(Q\+1\)\^2 "
                                         r"= 96 vertex lines, found 94 \(file ends at line 95\)"):
        read_mesh(p)
    txt = tmp_path / "SHAPE.TXT"                       # recognised as ICQ by content
    write_icq(txt, icq_points(q)[:-2], q)
    with pytest.raises(ValueError, match=r"SHAPE\.TXT: an ICQ model of Q = 3 has"):
        read_mesh(txt)
    write_icq(p, np.vstack([icq_points(q), [[1, 2, 3]]]), q)
    with pytest.raises(ValueError, match=r"short\.icq, line 98: unexpected line after the 96"):
        read_mesh(p)
    p.write_text("3.5\n1 2 3\n")
    with pytest.raises(ValueError, match=r"short\.icq, line 1: expected the ICQ resolution Q"):
        read_mesh(p)


# ------------------------------------------------------------------ packaged Didymos --

def test_packaged_didymos_radar_model():
    v, f = didymos_radar_mesh()
    assert v.shape == (1000, 3) and f.shape == (1996, 3)
    assert v.dtype == np.float64 and f.dtype == np.int64 and f.min() == 0 and f.max() == 999
    check_mesh(v, f)
    assert signed_volume(v, f) == pytest.approx(2.4855e8, rel=1e-4)
    np.testing.assert_allclose(np.ptp(v, axis=0), [832.4, 837.5, 786.2], atol=0.5)
    # the packaged files read the same through read_mesh, with provenance and licence
    base = resources.files("ti_spinorbit.data").joinpath("shapes")
    with resources.as_file(base) as d:
        v2, f2 = read_mesh((d / "didymos_radar_vertices_m.csv", d / "didymos_radar_facets.csv"),
                           unit="m")
        np.testing.assert_array_equal(v2, v)
        np.testing.assert_array_equal(f2, f)
        assert "Copyright 2019 Alex B. Davis" in (d / "GUBAS-LICENSE.txt").read_text()
        readme = (d / "README.md").read_text()
        assert "Naidu" in readme and "GUBAS-LICENSE.txt" in readme and "shared" not in readme


# -------------------------------------------------------------------- units, warnings --

def test_km_to_m_scaling_and_the_unit_warning(tmp_path, sphere):
    v, f = sphere
    p = tmp_path / "s.obj"
    p.write_text("\n".join([f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                           + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]))
    vk, _ = read_mesh(p, unit="km")
    vm, _ = read_mesh(p, unit="m")
    np.testing.assert_allclose(vk, 1000 * vm, rtol=1e-15)
    big = tmp_path / "big.obj"                        # 3000 km across, read as km
    scaled = "\n".join([f"v {fmt(1000 * x)} {fmt(1000 * y)} {fmt(1000 * z)}" for x, y, z in v]
                       + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f])
    big.write_text(scaled)
    with pytest.warns(ShapeUnitWarning, match=r"big\.obj: the model spans 3000 km with "
                                              r"unit='km', more than any asteroid \(1000 km\); "
                                              r"is the file in m\?"):
        read_mesh(big)
    small = tmp_path / "small.obj"
    small.write_text("\n".join([f"v {fmt(x / 10)} {fmt(y / 10)} {fmt(z / 10)}" for x, y, z in v]
                               + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]))
    with pytest.warns(ShapeUnitWarning, match=r"small\.obj: the model spans only 0\.3 m with "
                                              r"unit='m' \(less than 1 m\); is the file in km\?"):
        read_mesh(small, unit="m")
    assert issubclass(ShapeUnitWarning, UserWarning)


def test_no_unit_warning_for_plausible_sizes(tmp_path, sphere, recwarn):
    p = _write_obj(tmp_path / "ok.obj", *sphere)      # 3 km across in km, 3 m in m
    read_mesh(p)
    read_mesh(p, unit="m")
    assert not [w for w in recwarn if issubclass(w.category, ShapeUnitWarning)]


def _write_obj(p, v, f):
    p.write_text("\n".join([f"v {fmt(x)} {fmt(y)} {fmt(z)}" for x, y, z in v]
                           + [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f]))
    return p


# ------------------------------------------------------------------ check_mesh errors --

def one_line(excinfo):
    assert "\n" not in str(excinfo.value)


@pytest.mark.parametrize("break_it, message", [
    (lambda v, f: (v, f[1:]), r"the mesh is not closed: 3 open edges \(each on one facet only\); "
                              r"the first is edge \(\d+, \d+\) of facet \d+"),
    (lambda v, f: (v, np.vstack([f, f[:1, ::-1]])),
     r"the mesh is not manifold: 3 edges are on more than two facets; the first is edge "
     r"\(\d+, \d+\), on facets 0, \d+, 320"),
    (lambda v, f: (v, np.vstack([f[:7], f[7:8, ::-1], f[8:]])),
     r"the facets are inconsistently wound: facet \d+ runs edge \(\d+, \d+\) the same way as "
     r"its neighbour facet \d+ \(3 such edges\)"),
    (lambda v, f: (v, f[:, ::-1]), r"the facets are wound inward: signed volume -\S+ \(vertex "
                                   r"units cubed\) is not positive; reverse them"),
    (lambda v, f: (v, np.where(f == 5, 162, f)), r"facets have vertex indices outside 0\.\.161; "
                                                 r"the first is facet \d+ = \[.*162.*\]"),
    (lambda v, f: (v, np.vstack([f[:3], [[4, 4, 9]], f[3:]])), r"1 facets repeat a vertex index; "
                                                               r"the first is facet 3 = \[4, 4, 9\]"),
    (lambda v, f: (np.vstack([v[:40], [[np.nan, 0, 0]], v[41:]]), f),
     r"1 vertices are not finite \(NaN or inf\); the first is vertex 40 = \[nan, 0\.0, 0\.0\]"),
    (lambda v, f: (v[:, :2], f), r"vertices must be a numeric \(V, 3\) array, got shape \(162, 2\)"),
    (lambda v, f: (v, f.astype(float)), r"faces must be an integer \(F, 3\) array of vertex "
                                        r"indices, got shape \(320, 3\) dtype float64"),
    (lambda v, f: (v, f[:3]), r"a closed polyhedron needs at least 4 vertices and 4 facets"),
])
def test_check_mesh_errors(sphere, break_it, message):
    v, f = sphere
    check_mesh(v, f)
    bv, bf = break_it(v.copy(), f.copy())
    with pytest.raises(ValueError, match=message) as e:
        check_mesh(bv, bf)
    one_line(e)


def test_check_mesh_degenerate_facet_names_it(sphere):
    v, f = sphere
    v = v.copy()
    a, b, c = f[17]
    v[c] = (v[a] + v[b]) / 2                      # facet 17 collapses onto its edge a-b
    with pytest.raises(ValueError, match=rf"facets are degenerate \(zero area\); the first is "
                                         rf"facet 17 = \[{a}, {b}, {c}\]") as e:
        check_mesh(v, f)
    one_line(e)


def test_check_mesh_first_open_edge_is_in_the_lowest_facet(sphere):
    v, f = sphere
    holey = np.delete(f, [30, 200], axis=0)           # two holes
    uses = {}
    for k, t in enumerate(holey):
        for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            uses.setdefault(tuple(sorted(e)), []).append(k)
    open_edges = [e for e, on in uses.items() if len(on) == 1]
    lowest = min(uses[e][0] for e in open_edges)
    with pytest.raises(ValueError, match=rf"{len(open_edges)} open edges .* of facet {lowest}$"):
        check_mesh(v, holey)
    assert len(open_edges) == 6


# ------------------------------------------------------------------- read_mesh errors --

def test_read_mesh_argument_errors(tmp_path, sphere):
    p = _write_obj(tmp_path / "s.obj", *sphere)
    with pytest.raises(ValueError, match=r"unit must be 'km' or 'm' \(the unit of the file's "
                                         r"coordinates\), got 'cm'"):
        read_mesh(p, unit="cm")
    with pytest.raises(ValueError, match=r"format must be one of 'obj', 'tab', 'icq', 'gubas' "
                                         r"\(or None to detect it\), got 'stl'"):
        read_mesh(p, format="stl")
    assert FORMATS == ("obj", "tab", "icq", "gubas")
    with pytest.raises(ValueError, match=r"s\.obj: a GUBAS model is two files: read_mesh\("
                                         r"\(vertices_csv, facets_csv\)\)"):
        read_mesh(p, format="gubas")
    with pytest.raises(ValueError, match=r"facets= is for the GUBAS CSV pair only"):
        read_mesh(p, format="obj", facets=p)


def test_unknown_extension_names_the_supported_formats(tmp_path, monkeypatch):
    p = tmp_path / "body.stl"
    p.write_text("solid x\nendsolid x\n")
    monkeypatch.setitem(sys.modules, "trimesh", None)      # as if trimesh were not installed
    with pytest.raises(ValueError, match=r"cannot tell the shape format of .*body\.stl from its "
                                         r"extension '\.stl'; supported: obj \(\.obj\), tab "
                                         r"\(.*\), icq \(.*\), gubas \(.*\); pass format=, or "
                                         r"install trimesh") as e:
        read_mesh(p)
    one_line(e)


def test_other_extensions_go_through_trimesh_when_installed(tmp_path, monkeypatch, sphere):
    v, f = sphere
    fake = types.ModuleType("trimesh")
    fake.load = lambda path, force, process: types.SimpleNamespace(vertices=v, faces=f)
    monkeypatch.setitem(sys.modules, "trimesh", fake)
    p = tmp_path / "body.ply"
    p.write_text("ply\n")
    assert_same_mesh(read_mesh(p), sphere)


@pytest.mark.parametrize("name, text, message", [
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n",
     r"a\.obj, line 3: expected 'v x y z' \(three numbers\); got 'v 0 x 0'"),
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# c\nf 1 2 0\n",
     r"a\.obj, line 6: OBJ vertex references start at 1 .*; got 'f 1 2 0'"),
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
     r"a\.obj, line 4: face refers to a vertex the file does not define \(it has 3\)"),
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
     r"a\.obj, line 4: a face needs at least three vertices; got 'f 1 2'"),
    ("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 q\n",
     r"a\.obj, line 4: expected 'f' and 4 vertex references; got 'f 1 2 3 q'"),
    ("a.obj", "o nothing\n", r"a\.obj: no vertex \(v\) lines: not an OBJ shape model"),
    ("a.tab", "v 0 0 0\nv 1 0 0\nv 0 1 0\nx 1 2 3\n",
     r"a\.tab, line 4: expected a 'v x y z' or 'f i j k' line; got 'x 1 2 3'"),
    ("a.tab", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n",
     r"a\.tab, line 4: expected 'f i j k' \(three integers\)"),
    ("a.tab", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
     r"a\.tab, line 4: facet refers to a vertex outside 1\.\.3"),
    ("a.tab", "4 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 2 3\n",
     r"a\.tab: expected 4 facet lines after the 4 vertices \(counts on line 1\), found 1 lines "
     r"\(file ends at line 6\)"),
    ("a.tab", "3\n1 0 0 0\n2 1 0 0\n",
     r"a\.tab: expected 3 vertex lines after line 1 \(file ends at line 3\)"),
    ("a.tab", "3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n1 1 2 3\n",
     r"a\.tab, line 5: expected the facet count \(one integer\) after the 3 vertices"),
    ("a.tab", "3\n1 0 0 0\n2 1 0 0\n3 0 1.5\n",
     r"a\.tab, line 4: expected a vertex line 'id x y z'; got '3 0 1\.5'"),
    ("a.tab", "3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n1\n1 1 2 9\n",
     r"a\.tab, line 6: facet refers to a vertex outside 1\.\.3"),
    ("a.tab", "hello world\n", r"a\.tab, line 1: expected 'v'/'f' lines, or a first line with "
                               r"the vertex count"),
    ("a.tab", "\n\n", r"a\.tab: empty shape file"),
])
def test_unreadable_content_names_file_and_line(tmp_path, name, text, message):
    p = tmp_path / name
    p.write_text(text)
    with pytest.raises(ValueError, match=message) as e:
        read_mesh(p, unit="m", check=False)
    one_line(e)


def test_gubas_content_errors(tmp_path):
    vp, fp = tmp_path / "v.csv", tmp_path / "f.csv"
    vp.write_text("0,0,0,0\n0,1,0,0\n0,0,1,oops\n0,0,0,1\n")
    fp.write_text("1,2,3,,\n1,3,4,,\n")
    with pytest.raises(ValueError, match=r"v\.csv, line 3: expected a GUBAS vertex row "
                                         r"'0,x,y,z'; got '0,0,1,oops'"):
        read_mesh((vp, fp), unit="m", check=False)
    vp.write_text("0,0,0\n")
    with pytest.raises(ValueError, match=r"cannot tell the GUBAS vertex file .* among .*v\.csv "
                                         r"and .*f\.csv"):
        read_mesh((vp, fp), unit="m")


def test_a_broken_mesh_in_a_file_is_named_with_the_file(tmp_path, sphere):
    v, f = sphere
    p = _write_obj(tmp_path / "holey.obj", v, f[1:])
    with pytest.raises(ValueError, match=r"holey\.obj: the mesh is not closed: 3 open edges"):
        read_mesh(p)
    read_mesh(p, check=False)


def test_binary_file_is_refused(tmp_path):
    p = tmp_path / "b.obj"
    p.write_bytes(b"\x80\x81\xfe\xff" * 10)
    with pytest.raises(ValueError, match=r"b\.obj: not a text shape file \(byte 0 is not UTF-8\)"):
        read_mesh(p)


def test_error_messages_are_one_line(sphere):
    # the module's messages never span lines (the parametrised cases check each); here the
    # regex of the inward case must also match the whole message
    v, f = sphere
    with pytest.raises(ValueError) as e:
        check_mesh(v, f[:, ::-1])
    assert re.fullmatch(r"the facets are wound inward: .*\(faces\[:, ::-1\]\)", str(e.value))
