"""Mutual potential, force and torques of two rigid bodies at any truncation order (Taichi), in
real solid harmonics along the line of centres.

The formulation is that of ``ti_spinorbit.harmonics`` (its module docstring; docs/physics.md
§3.8a) and the tables those of ``ti_spinorbit.engine.harmonic_tables``: both bodies' harmonic
coefficients are turned into the frame whose z axis is the line of centres, by z-rotations (4
products per pair ±m) and the fixed sparse matrices J_l and J_lᵀ,

    primary:   C_A ← X(−α) Jᵀ X(−θ) J X(−φ) C_A,      secondary:  C_B ← Jᵀ X(β) J X(γ) C_B,

where there the interaction of degrees l1 and l2 is diagonal in m (2 min(l1, l2) + 1 terms,
against C(l1+2, 2) C(l2+2, 2) in Cartesian form). Torques follow from the generators, the
transverse force from R × ∂U/∂R = τ_A + τ_B (angular momentum conserved by construction), and
everything is turned back into the primary's frame.

Why this form and not the Cartesian one (``multipole_gravity.py``, kept as the kernels'
independent check): the same numbers at 1e-13 for a fraction of the work at every order
above 4 (experiments/README.md, "bench_harmonics.py"). Cost-saving details:

* each z-rotation is fused into the pass before it or after it (the copy from the member's
  row, or the output of a J product), so a body's degree costs three passes;
* degrees above the mixed terms' (l > min(d, N − 2)) enter only through m = 0 (the other
  body's monopole) and the generators' neighbours m = ±1, so their last pass computes those
  three rows only;
* r^−(L+1) is tabulated once per evaluation; the angles come from matrix entries, never from
  trigonometric calls (multiple angles by the addition recurrence);
* the secondary's z-torque is the primary's with the opposite sign: along the line of
  centres (R × ∂U/∂R)_z = 0.

Per-member data, passed as arguments of the kernels beside the parameter rows (the same four
arrays as the Cartesian kernels'): ``rows`` (members × width) the coefficient rows
(``harmonic_tables.coefficient_rows``), ``scr`` (slots × scratch) per-slot scratch, ``tab_i``
(int32, the header of ``ti_spinorbit.layout.harmonic`` first) and ``tab_f`` (float64).
Conventions as in ``mutual_gravity.py`` (primary frame A; R from A's centre of mass to B's; S
maps B-frame vectors into A; ``dUdR`` = ∂U/∂R; mu2 the torque on B, mu1 on A).
"""

import taichi as ti

from ti_spinorbit.layout import harmonic as _K

from .mutual_gravity import vec3


@ti.func
def _sizes(l):
    """Class sizes of degree l: cos even, cos odd, sin even, sin odd (``layout.harmonic``)."""
    return l // 2 + 1, (l + 1) // 2, l // 2, (l + 1) // 2


@ti.func
def _size(l, a):
    n = l // 2 + 1
    if a == 1 or a == 3:
        n = (l + 1) // 2
    elif a == 2:
        n = l // 2
    return n


@ti.func
def _offset(l, a):
    """Position of class a's first coefficient within degree l."""
    n0, n1, n2, _ = _sizes(l)
    o = 0
    if a >= 1:
        o += n0
    if a >= 2:
        o += n1
    if a >= 3:
        o += n2
    return o


@ti.func
def _angles(scr: ti.template(), k, o, top, c, s):
    """cos mψ at scr[k, o + m] and sin mψ at scr[k, o + top + 1 + m], m = 1..top."""
    cm, sm = 1.0, 0.0
    for m in range(1, top + 1):
        cm, sm = cm * c - sm * s, sm * c + cm * s
        scr[k, o + m] = cm
        scr[k, o + top + 1 + m] = sm


@ti.func
def _load(rows: ti.template(), j, src, scr: ti.template(), k, dst, l, trig, top):
    """scr[dst..] ← X(ψ) of the member's degree-l coefficients (row columns src..), class
    order: m = 2i pairs cos-even position i with sin-even i − 1, m = 2i + 1 cos-odd i with
    sin-odd i."""
    n0, n1, n2, n3 = _sizes(l)
    scr[k, dst] = rows[j, src]
    for i in range(1, n0):
        c = scr[k, trig + 2 * i]
        s = scr[k, trig + top + 1 + 2 * i]
        p = rows[j, src + i]
        q = rows[j, src + n0 + n1 + i - 1]
        scr[k, dst + i] = c * p - s * q
        scr[k, dst + n0 + n1 + i - 1] = s * p + c * q
    for i in range(n1):
        c = scr[k, trig + 2 * i + 1]
        s = scr[k, trig + top + 2 + 2 * i]
        p = rows[j, src + n0 + i]
        q = rows[j, src + n0 + n1 + n2 + i]
        scr[k, dst + n0 + i] = c * p - s * q
        scr[k, dst + n0 + n1 + n2 + i] = s * p + c * q


@ti.func
def _zrot(scr: ti.template(), k, v, l, mtop, trig, top):
    """X(ψ) in place on the degree-l vector at v, orders |m| <= mtop."""
    n0, n1, n2, n3 = _sizes(l)
    for i in range(1, ti.min(n0, mtop // 2 + 1)):
        c = scr[k, trig + 2 * i]
        s = scr[k, trig + top + 1 + 2 * i]
        p = scr[k, v + i]
        q = scr[k, v + n0 + n1 + i - 1]
        scr[k, v + i] = c * p - s * q
        scr[k, v + n0 + n1 + i - 1] = s * p + c * q
    for i in range(ti.min(n1, (mtop + 1) // 2)):
        c = scr[k, trig + 2 * i + 1]
        s = scr[k, trig + top + 2 + 2 * i]
        p = scr[k, v + n0 + i]
        q = scr[k, v + n0 + n1 + n2 + i]
        scr[k, v + n0 + i] = c * p - s * q
        scr[k, v + n0 + n1 + n2 + i] = s * p + c * q


@ti.func
def _product(scr: ti.template(), k, src, dst, l, full, tab_i: ti.template(),
             tab_f: ti.template(), which):
    """scr[dst..] ← M scr[src..] for degree l, M = J (which 0) or Jᵀ (1): per output class a
    dense block from one input class (the degree's table entry); with ``full`` False only
    the rows m = 0, ±1 (first rows of the cos-even, cos-odd and sin-odd classes)."""
    d = tab_i[_K.K_I_DEG] + _K.DEG_WIDTH * l
    f = tab_i[d + which]
    for a in range(4):
        b = tab_i[d + 2 + 4 * which + a]
        na = _size(l, a)
        nb = _size(l, b)
        rows_ = na
        if not full:
            rows_ = 0 if a == 2 else ti.min(na, 1)
        ia = dst + _offset(l, a)
        ib = src + _offset(l, b)
        for i in range(rows_):
            s = 0.0
            fr = f + i * nb
            for c in range(nb):
                s += tab_f[fr + c] * scr[k, ib + c]
            scr[k, ia + i] = s
        f += na * nb


@ti.func
def _torque_xy(scr: ti.template(), k, base, gbase, deg, kmix, mask, tab_i: ti.template(),
               tab_f: ti.template()):
    """(τ_x, τ_y) of one body in the line-of-centres frame: −Σ ∂U/∂C_lm (G_k C)_lm over the
    rows where ∂U/∂C can be non-zero (all m up to degree kmix, m = 0 above)."""
    oc = tab_i[_K.K_I_GC]
    of = tab_i[_K.K_F_G]
    tx, ty = 0.0, 0.0
    for l in range(2, deg + 1):
        if (mask >> l) & 1:
            nrow = 2 * l + 1 if l <= kmix else 1
            b = base + l * l
            for i in range(nrow):
                g = l * l + i
                acc = scr[k, gbase + g]
                t = oc + 4 * g
                f = of + 4 * g
                tx += acc * (tab_f[f] * scr[k, b + tab_i[t]] + tab_f[f + 1] * scr[k, b + tab_i[t + 1]])
                ty += acc * (tab_f[f + 2] * scr[k, b + tab_i[t + 2]]
                             + tab_f[f + 3] * scr[k, b + tab_i[t + 3]])
    return -tx, -ty


@ti.func
def mutual_h(rows: ti.template(), j, scr: ti.template(), k, tab_i: ti.template(),
             tab_f: ti.template(), G, R, S):
    """Mutual potential U, gradient dU/dR, torque on A (mu1) and on B (mu2), frame A, at the
    order and degree caps the tables were built for; member j's coefficient row
    (``rows[j]``), slot k's scratch (``scr[k]``)."""
    N = tab_i[_K.K_N]
    dA = tab_i[_K.K_DA]
    dB = tab_i[_K.K_DB]
    KA = tab_i[_K.K_KA]
    KB = tab_i[_K.K_KB]
    top = tab_i[_K.K_TOP]
    rowB = tab_i[_K.K_ROW_B]
    mA = tab_i[_K.K_MASK_A]
    mB = tab_i[_K.K_MASK_B]
    sA = tab_i[_K.K_S_A]
    sB = tab_i[_K.K_S_B]
    sGA = tab_i[_K.K_S_GA]
    sGB = tab_i[_K.K_S_GB]
    t1 = tab_i[_K.K_S_T1]
    t2 = tab_i[_K.K_S_T2]
    trig = tab_i[_K.K_S_TRIG]
    sw = tab_i[_K.K_S_W]
    # the line-of-centres frame L = Rz(−α) Ry(−θ) Rz(−φ) and the secondary's Ry(β) Rz(γ)
    x, y, z = R[0], R[1], R[2]
    rho = ti.sqrt(x * x + y * y)
    r = ti.sqrt(rho * rho + z * z)
    cf, sf = 1.0, 0.0
    if rho > 0.0:
        cf, sf = x / rho, y / rho
    ct, st = z / r, rho / r
    P = ti.Matrix([[ct * cf, ct * sf, -st], [-sf, cf, 0.0], [st * cf, st * sf, ct]], ti.f64)
    Q = P @ S
    h = ti.sqrt(Q[0, 2] * Q[0, 2] + Q[1, 2] * Q[1, 2])
    ca, sa = 1.0, 0.0
    if h > 0.0:
        ca, sa = Q[0, 2] / h, Q[1, 2] / h
    cb, sb = Q[2, 2], ca * Q[0, 2] + sa * Q[1, 2]
    cg, sg = ca * Q[1, 1] - sa * Q[0, 1], ca * Q[1, 0] - sa * Q[0, 0]
    L = ti.Matrix([[ca, sa, 0.0], [-sa, ca, 0.0], [0.0, 0.0, 1.0]], ti.f64) @ P
    n2 = 2 * (top + 1)
    _angles(scr, k, trig, top, cf, -sf)
    _angles(scr, k, trig + n2, top, ct, -st)
    _angles(scr, k, trig + 2 * n2, top, ca, -sa)
    _angles(scr, k, trig + 3 * n2, top, cg, sg)
    _angles(scr, k, trig + 4 * n2, top, cb, sb)
    # both bodies into the frame L, degree by degree (degree 0 is the mass; 1 is zero):
    # one loop over the bodies and the two J products, so each helper has one call site
    # (every call of a ti.func is inlined; compile time grows with the copies)
    scr[k, sA] = rows[j, 0]
    scr[k, sB] = rows[j, rowB]
    for body in range(2):
        src0, dst0, deg, kmix, mask, z0, z1, z2 = 0, sA, dA, KA, mA, 0, 1, 2
        if body == 1:
            src0, dst0, deg, kmix, mask, z0, z1, z2 = rowB, sB, dB, KB, mB, 3, 4, -1
        for l in range(2, deg + 1):
            if (mask >> l) & 1:
                _load(rows, j, src0 + l * l, scr, k, t1, l, trig + z0 * n2, top)
                for which in range(2):                    # J, then Jᵀ
                    full = which == 0 or l <= kmix
                    src, dst, zs = t1, t2, z1
                    if which == 1:
                        src, dst, zs = t2, dst0 + l * l, z2
                    _product(scr, k, src, dst, l, full, tab_i, tab_f, which)
                    if zs >= 0:
                        _zrot(scr, k, dst, l, l if full else 1, trig + zs * n2, top)
    # the interaction along ẑ: U, ∂U/∂r and each body's ∂U/∂C
    inv_r = 1.0 / r
    w = -G * inv_r
    for q in range(N + 1):
        scr[k, sw + q] = w                       # −G r^−(q+1)
        w *= inv_r
    for q in range((dA + 1) * (dA + 1)):
        scr[k, sGA + q] = 0.0
    for q in range((dB + 1) * (dB + 1)):
        scr[k, sGB + q] = 0.0
    op = tab_i[_K.K_I_PAIR]
    U = 0.0
    dUdr = 0.0
    for pi in range(tab_i[_K.K_NPAIR]):
        l1 = tab_i[op + 3 * pi]
        l2 = tab_i[op + 3 * pi + 1]
        fo = tab_i[op + 3 * pi + 2]
        mn = ti.min(l1, l2)
        wl = scr[k, sw + l1 + l2]
        e = 0.0
        for a in range(4):
            ia = l1 * l1 + _offset(l1, a)
            ib = l2 * l2 + _offset(l2, a)
            for i in range(_size(mn, a)):
                kv = wl * tab_f[fo + i]
                ca_ = scr[k, sA + ia + i]
                cb_ = scr[k, sB + ib + i]
                e += ca_ * kv * cb_
                scr[k, sGA + ia + i] += kv * cb_
                scr[k, sGB + ib + i] += kv * ca_
            fo += _size(mn, a)
        U += e
        dUdr -= (l1 + l2 + 1) * e * inv_r
    # torques in the frame L: x, y from the generators, z analytically (G_z C: m ↔ −m, × m)
    ax, ay, bx, by = 0.0, 0.0, 0.0, 0.0
    for body in range(2):
        if body == 0:
            ax, ay = _torque_xy(scr, k, sA, sGA, dA, KA, mA, tab_i, tab_f)
        else:
            bx, by = _torque_xy(scr, k, sB, sGB, dB, KB, mB, tab_i, tab_f)
    bz = 0.0
    for l in range(2, KB + 1):
        if (mB >> l) & 1:
            n0, n1, n2_, _ = _sizes(l)
            g = sGB + l * l
            c = sB + l * l
            for i in range(1, n0):             # m = 2i: cos-even i, sin-even i − 1
                bz += 2 * i * (scr[k, g + i] * scr[k, c + n0 + n1 + i - 1]
                               - scr[k, g + n0 + n1 + i - 1] * scr[k, c + i])
            for i in range(n1):                # m = 2i + 1: cos-odd i, sin-odd i
                bz += (2 * i + 1) * (scr[k, g + n0 + i] * scr[k, c + n0 + n1 + n2_ + i]
                                     - scr[k, g + n0 + n1 + n2_ + i] * scr[k, c + n0 + i])
    tauA = vec3(ax, ay, -bz)
    tauB = vec3(bx, by, bz)
    s = tauA + tauB
    dU = vec3(s[1] * inv_r, -s[0] * inv_r, dUdr)
    LT = L.transpose()
    return U, LT @ dU, LT @ tauA, LT @ tauB


nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
nd3f = ti.types.ndarray(dtype=ti.f64, ndim=3)
nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)


@ti.kernel
def evaluate_multipole(rows: nd2f, R_nd: nd2f, S_nd: nd3f, scr: nd2f, tab_i: nd1i,
                       tab_f: nd1f, out: nd2f, G: ti.f64):
    """The order-N potential for each row i (member i's coefficients, R_nd[i], S_nd[i]):
    out = [U, dU/dR (3), mu1 (3), mu2 (3)], scratch row i."""
    for i in range(R_nd.shape[0]):
        R = vec3(R_nd[i, 0], R_nd[i, 1], R_nd[i, 2])
        S = ti.Matrix([[S_nd[i, r, c] for c in ti.static(range(3))] for r in ti.static(range(3))])
        U, dUdR, mu1, mu2 = mutual_h(rows, i, scr, i, tab_i, tab_f, G, R, S)
        out[i, 0] = U
        for c in ti.static(range(3)):
            out[i, 1 + c] = dUdR[c]
            out[i, 4 + c] = mu1[c]
            out[i, 7 + c] = mu2[c]
