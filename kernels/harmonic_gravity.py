"""Mutual potential, force and torques of two rigid bodies at any truncation order (Taichi), in
real solid harmonics along the line of centres.

The formulation is that of ``ti_spinorbit.harmonics`` (its module docstring; docs/physics.md
§3.8.2) and the tables those of ``ti_spinorbit.engine.harmonic_tables``: both bodies' harmonic
coefficients are turned into the frame whose z axis is the line of centres, by z-rotations (4
products per pair ±m) and the fixed sparse matrices J_l and J_lᵀ,

    primary:   C_A ← X(−α) Jᵀ X(−θ) J X(−φ) C_A,      secondary:  C_B ← Jᵀ X(β) J X(γ) C_B,

where there the interaction of degrees l1 and l2 is diagonal in m (2 min(l1, l2) + 1 terms,
against C(l1+2, 2) C(l2+2, 2) in Cartesian form). Torques follow from the generators, the
transverse force from R × ∂U/∂R = τ_A + τ_B (angular momentum conserved by construction), and
everything is turned back into the primary's frame.

Why this form and not the Cartesian one (``multipole_gravity.py``, kept as the kernels'
independent check): the same numbers to 1e-13 for a fraction of the work at every order
above 4 (experiments/README.md, "bench_harmonics.py"). Cost-saving details:

* the host turns each body's rotation into a program of flat lists (``harmonic_tables``):
  z-rotation pairs and dense J-block rows, so the kernel runs a few flat loops with no
  per-degree logic, each written once (compile time grows with every copy);
* a degree's terms reach only |m| <= m_l (m_l = 0 above N − 2: the other body's
  monopole), so its last product computes |m| <= m_l + 1 only (the generators'
  neighbours); a body's degrees that are zero in every member are left out, and a
  mirror-symmetric body's zero classes are neither computed nor read (the tables' flags);
* the rows of ∂U/∂C are stored by the terms (a run of terms per primary row summed in a
  register, the secondary's first term storing), never zeroed first;
* r^−(L+1) is tabulated once per evaluation; the angles come from matrix entries, never from
  trigonometric calls (multiple angles by the addition recurrence);
* the primary's z-torque is the secondary's with the opposite sign: along the line of
  centres (R × ∂U/∂R)_z = 0;
* its loops are counted and stepped by numbers read from the table, so that LLVM neither
  copies nor unrolls them (compile time, and faster inside the integrator);
* on the CPU the body is one Taichi real function (``ti.real_func``),
  compiled once per kernel and called, not inlined: inlined in the integrator's state
  machine, its short loops ran 1.5 × slower than the same code in a small kernel (the
  register pressure of the stage matrix around them), and the call also compiles faster
  (experiments/README.md, "bench_orders.py"). The body is written as one function, with no
  nested ``ti.func`` call: inside a real function such calls crash at launch in Taichi 1.7.

Per-member data, passed as arguments of the kernels beside the parameter rows (the four
arrays of ``Multipole.arguments``): ``rows`` the coefficient rows
(``harmonic_tables.coefficient_rows``) as one flat array, member j's at j · K_WIDTH, ``scr``
the per-slot scratch as one flat array, slot k's at k · K_SCRATCH (flat because Taichi
reloads a 2-D array's stride from memory after every store: 15-20 % of the order-6
potential), ``tab_i`` (int32, the header of ``ti_spinorbit.layout.harmonic`` first) and
``tab_f`` (float64).
Conventions as in ``mutual_gravity.py`` (primary frame A; R from A's centre of mass to B's; S
maps B-frame vectors into A; ``dUdR`` = ∂U/∂R; mu2 the torque on B, mu1 on A).
"""

import taichi as ti

from ti_spinorbit.layout import harmonic as _K

from .mutual_gravity import make_evaluate, vec3

_BITS = 9                       # harmonic_tables.BITS: a packed entry is a | b << 9 | c << 18
_MASK = (1 << _BITS) - 1
_M_FIELD = 31                   # c of a pair: m | ZERO_SIN; of a term: L | LAST_A | FIRST_B
_L_FIELD = 63
_ZERO_SIN = 1 << (2 * _BITS + 5)          # harmonic_tables.ZERO_SIN, LAST_A, FIRST_B in place
_LAST_A = 1 << (2 * _BITS + 6)
_FIRST_B = 1 << (2 * _BITS + 7)
_ADD_P = 1 << (2 * _BITS + 6)             # harmonic_tables.ADD_P, ADD_Q in place
_ADD_Q = 1 << (2 * _BITS + 7)
_RESTART = 1 << (2 * _BITS + 8)           # harmonic_tables.RESTART, STEP2 in place
_STEP2 = 1 << (2 * _BITS + 9)

_nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
_nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)
_mat3 = ti.types.matrix(3, 3, ti.f64)
_Result = ti.types.struct(U=ti.f64, dU=vec3, mu1=vec3, mu2=vec3)


def _potential(rows: _nd1f, j: ti.i32, scr: _nd1f, k: ti.i32, tab_i: _nd1i, tab_f: _nd1f,
               G: ti.f64, R: vec3, S: _mat3) -> _Result:
    """The body of :func:`mutual_h`, compiled as a real function (module docstring) or
    inlined. Written as one function with no nested ``ti.func`` call: inside a Taichi 1.7
    real function such calls crashed at launch (seen with one taking an array and with one
    taking only vectors)."""
    # member j's coefficient row and slot k's scratch row in the flat arrays
    j0 = j * tab_i[_K.K_WIDTH]
    k0 = k * tab_i[_K.K_SCRATCH]
    # 2 and 1 read at run time, for the loop counts and steps: LLVM would otherwise copy the
    # loops over the bodies and the passes and unroll every table loop eight times over,
    # which cost 0.4-0.5 s of compile and, in the integrator, more time than it saved (the
    # smaller code ran 5-10 % faster there, though 5 % slower in a small benchmark kernel)
    two = tab_i[_K.K_TWO]
    one = two - 1
    t2 = tab_i[_K.K_S_T2]
    sw = tab_i[_K.K_S_W]
    sA = tab_i[_K.K_S_A]
    sB = tab_i[_K.K_S_B]
    sGA = tab_i[_K.K_S_GA]
    sGB = tab_i[_K.K_S_GB]
    # the line-of-centres frame L = Rz(−α) Ry(−θ) Rz(−φ) and the secondary's Ry(β) Rz(γ)
    x, y, z = R[0], R[1], R[2]
    rho = ti.sqrt(x * x + y * y)
    r = ti.sqrt(rho * rho + z * z)
    inv_r = 1.0 / r
    cf, sf = 1.0, 0.0
    if rho > 0.0:
        inv_rho = 1.0 / rho
        cf, sf = x * inv_rho, y * inv_rho
    ct, st = z * inv_r, rho * inv_r
    P = ti.Matrix([[ct * cf, ct * sf, -st], [-sf, cf, 0.0], [st * cf, st * sf, ct]], ti.f64)
    Q = P @ S
    h = ti.sqrt(Q[0, 2] * Q[0, 2] + Q[1, 2] * Q[1, 2])
    ca, sa = 1.0, 0.0
    if h > 0.0:
        inv_h = 1.0 / h
        ca, sa = Q[0, 2] * inv_h, Q[1, 2] * inv_h
    cb, sb = Q[2, 2], ca * Q[0, 2] + sa * Q[1, 2]
    cg, sg = ca * Q[1, 1] - sa * Q[0, 1], ca * Q[1, 0] - sa * Q[0, 0]
    L = ti.Matrix([[ca, sa, 0.0], [-sa, ca, 0.0], [0.0, 0.0, 1.0]], ti.f64) @ P
    # the five angles (slots 0..4: −φ, −θ, −α for the primary, γ, β for the secondary); the
    # pair lists run through each degree's orders in steps of one (of two: STEP2), so their
    # multiples follow by the addition recurrence as the lists are walked (RESTART: a
    # degree's first entry, from m = 0), and no table of multiple angles is stored
    c1 = ti.Vector([cf, ct, ca, cg, cb], ti.f64)
    s1 = ti.Vector([-sf, -st, -sa, sg, sb], ti.f64)
    # both bodies into the frame L by their programs: the member's coefficients read with
    # the first z-rotation, then two passes (J then X; Jᵀ then X), in one loop over the
    # bodies and one over the passes, so that each table loop is written once
    for body in range(two):
        pg = _K.K_PROG_A + body * _K.PROGRAM_WIDTH
        src = tab_i[pg + _K.P_SRC]
        dst = tab_i[pg + _K.P_DST]
        t1 = tab_i[pg + _K.P_T1]
        scr[k0 + dst] = rows[j0 + src]                     # degree 0: the mass
        # the member's coefficients, turned by the first z-rotation as they are read
        o = tab_i[pg + _K.P_LOAD]
        z0 = tab_i[pg + _K.P_Z0]
        zc, zs = c1[0], s1[0]
        for a in ti.static(range(1, 5)):                 # (no nested ti.func: see above)
            if z0 == a:
                zc, zs = c1[a], s1[a]
        zc2, zs2 = zc * zc - zs * zs, 2.0 * zc * zs
        c, s_ = 1.0, 0.0
        e, ne = 0, tab_i[pg + _K.P_NLOAD]
        while e < ne:
            w = tab_i[o + e]
            p = w & _MASK
            q = (w >> _BITS) & _MASK
            if w & _RESTART != 0:
                c, s_ = 1.0, 0.0
            if (w >> (2 * _BITS)) & _M_FIELD != 0:      # the next multiple of the angle
                if w & _STEP2 != 0:
                    c, s_ = c * zc2 - s_ * zs2, s_ * zc2 + c * zs2
                else:
                    c, s_ = c * zc - s_ * zs, s_ * zc + c * zs
            a = rows[j0 + src + p]
            b = 0.0
            if w & _ZERO_SIN == 0:                       # (a sin partner known zero: not read)
                b = rows[j0 + src + q]
            scr[k0 + t1 + p] = c * a - s_ * b
            scr[k0 + t1 + q] = s_ * a + c * b
            e += one
        for step in range(1, 1 + two):                   # J then X; Jᵀ then X
            nkey_j, orow, frow, nkey_x, ofx, ffx, slot, vec, src_ = (
                _K.P_NJ, tab_i[pg + _K.P_J], tab_i[pg + _K.P_FJ],
                _K.P_NJX, tab_i[pg + _K.P_JX], tab_i[pg + _K.P_FJX],
                tab_i[pg + _K.P_Z1], t2, t1)
            if step == 2:
                nkey_j, orow, frow, nkey_x, ofx, ffx, slot, vec, src_ = (
                    _K.P_NJT, tab_i[pg + _K.P_JT], tab_i[pg + _K.P_FJT],
                    _K.P_NJTX, tab_i[pg + _K.P_JTX], tab_i[pg + _K.P_FJTX],
                    tab_i[pg + _K.P_Z2], dst, t2)
            # the J (or Jᵀ) rows in chunks ((destination, source, add) packed; the list's
            # weights in its order, four per chunk, zero past a row's end:
            # ``harmonic_tables.CHUNK``); a chunk stores its sum or adds it to its row's
            e, ne = 0, tab_i[pg + nkey_j]
            while e < ne:
                w = tab_i[orow + e]
                d = vec + (w & _MASK)
                s0 = src_ + ((w >> _BITS) & _MASK)
                f = frow + 4 * e
                acc = (tab_f[f] * scr[k0 + s0] + tab_f[f + 1] * scr[k0 + s0 + 1]
                       + tab_f[f + 2] * scr[k0 + s0 + 2] + tab_f[f + 3] * scr[k0 + s0 + 3])
                if w >> (2 * _BITS) != 0:
                    acc += scr[k0 + d]
                scr[k0 + d] = acc
                e += one
            # then each z-rotation pair (p, q, m): the last chunk of J row p and of row q
            # (added to the rows' partial sums when they are longer: ADD_P, ADD_Q; row q not
            # computed when its class is known to be zero: ZERO_SIN), then rotated by mψ
            zc, zs = c1[0], s1[0]                        # (slot −1: a pass with no pairs)
            for a in ti.static(range(1, 5)):
                if slot == a:
                    zc, zs = c1[a], s1[a]
            c, s_ = 1.0, 0.0
            e, ne = 0, tab_i[pg + nkey_x]
            while e < ne:
                w = tab_i[ofx + 2 * e]
                w2 = tab_i[ofx + 2 * e + 1]
                p = vec + (w & _MASK)
                sp = src_ + ((w >> _BITS) & _MASK)
                f = ffx + 8 * e
                rp = (tab_f[f] * scr[k0 + sp] + tab_f[f + 1] * scr[k0 + sp + 1]
                      + tab_f[f + 2] * scr[k0 + sp + 2] + tab_f[f + 3] * scr[k0 + sp + 3])
                if w & _ADD_P != 0:
                    rp += scr[k0 + p]
                q = vec + (w2 & _MASK)
                rq = 0.0
                if w & _ZERO_SIN == 0:
                    sq = src_ + ((w2 >> _BITS) & _MASK)
                    rq = (tab_f[f + 4] * scr[k0 + sq] + tab_f[f + 5] * scr[k0 + sq + 1]
                          + tab_f[f + 6] * scr[k0 + sq + 2] + tab_f[f + 7] * scr[k0 + sq + 3])
                    if w & _ADD_Q != 0:
                        rq += scr[k0 + q]
                if w & _RESTART != 0:                    # m = 1: a degree's first pair
                    c, s_ = 1.0, 0.0
                c, s_ = c * zc - s_ * zs, s_ * zc + c * zs
                scr[k0 + p] = c * rp - s_ * rq
                scr[k0 + q] = s_ * rp + c * rq
                e += one
    # the interaction along ẑ: U, ∂U/∂r and each body's ∂U/∂C (no row zeroed first: the
    # primary's rows are runs of consecutive terms, of the secondary's the first stores)
    wr = -G * inv_r
    for q in range(tab_i[_K.K_NPOW]):
        scr[k0 + sw + q] = wr                              # −G r^−(q+1)
        wr *= inv_r
    ot = tab_i[_K.K_I_TERM]
    ok = tab_i[_K.K_F_TERM]
    U = 0.0
    dUdr = 0.0
    ga = 0.0
    e, ne = 0, tab_i[_K.K_NTERM]
    while e < ne:
        w = tab_i[ot + e]
        ia = w & _MASK
        ib = (w >> _BITS) & _MASK
        Lt = (w >> (2 * _BITS)) & _L_FIELD
        kv = scr[k0 + sw + Lt] * tab_f[ok + e]
        a = scr[k0 + sA + ia]
        b = scr[k0 + sB + ib]
        u = a * kv * b
        U += u
        dUdr -= (Lt + 1) * u
        ga += kv * b                                     # the primary's row: a run of terms
        if w & _LAST_A != 0:
            scr[k0 + sGA + ia] = ga
            ga = 0.0
        gb = kv * a                                      # the secondary's: its first stores
        if w & _FIRST_B == 0:
            gb += scr[k0 + sGB + ib]
        scr[k0 + sGB + ib] = gb
        e += one
    dUdr *= inv_r
    # torques in the frame L: x, y from the generators (4 entries per row), z of the
    # secondary analytically ((G_z C)_±m = ∓m C_∓m), the primary's z opposite (along the
    # line of centres (R × ∂U/∂R)_z = 0)
    ax, ay, bx, by = 0.0, 0.0, 0.0, 0.0
    for body in range(two):
        pg = _K.K_PROG_A + body * _K.PROGRAM_WIDTH
        base = tab_i[pg + _K.P_DST]
        acc0 = tab_i[pg + _K.P_ACC]
        o = tab_i[pg + _K.P_ROW]
        fo = tab_i[pg + _K.P_FROW]
        tx, ty = 0.0, 0.0
        e, ne = 0, tab_i[pg + _K.P_NROW]
        while e < ne:          # (row, columns x, columns y)
            g = tab_i[o + 3 * e]
            av = scr[k0 + acc0 + g]
            wx = tab_i[o + 3 * e + 1]
            wy = tab_i[o + 3 * e + 2]
            f = fo + 4 * e
            tx += av * (tab_f[f] * scr[k0 + base + (wx & _MASK)]
                        + tab_f[f + 1] * scr[k0 + base + ((wx >> _BITS) & _MASK)])
            ty += av * (tab_f[f + 2] * scr[k0 + base + (wy & _MASK)]
                        + tab_f[f + 3] * scr[k0 + base + ((wy >> _BITS) & _MASK)])
            e += one
        if body == 0:
            ax, ay = -tx, -ty
        else:
            bx, by = -tx, -ty
    bz = 0.0
    ob = tab_i[_K.K_I_BZ]
    e, ne = 0, tab_i[_K.K_NBZ]
    while e < ne:
        w = tab_i[ob + e]
        gp = w & _MASK
        gm = (w >> _BITS) & _MASK
        bz += (w >> (2 * _BITS)) * (scr[k0 + sGB + gp] * scr[k0 + sB + gm]
                                    - scr[k0 + sGB + gm] * scr[k0 + sB + gp])
        e += one
    tauA = vec3(ax, ay, -bz)
    tauB = vec3(bx, by, bz)
    s = tauA + tauB
    dU = vec3(s[1] * inv_r, -s[0] * inv_r, dUdr)
    LT = L.transpose()
    return _Result(U=U, dU=LT @ dU, mu1=LT @ tauA, mu2=LT @ tauB)


_REAL = ti.real_func(_potential)
_INLINE = ti.func(_potential)
#: where the real function is used: the CPU backends, where it was measured and tested (Taichi
#: has real functions on CUDA too, but no GPU has run this code yet, so it inlines there)
_REAL_ARCHS = (ti.x64, ti.arm64)


@ti.func
def mutual_h(rows: ti.template(), j, scr: ti.template(), k, tab_i: ti.template(),
             tab_f: ti.template(), G, R, S):
    """Mutual potential U, gradient dU/dR, torque on A (mu1) and on B (mu2), frame A, at the
    order and degree caps the tables were built for; member j's coefficient row
    (``rows[j]``), slot k's scratch (``scr[k]``). A call to one real function on the CPU,
    inlined on the other backends."""
    r = _Result(U=0.0, dU=vec3(0.0, 0.0, 0.0), mu1=vec3(0.0, 0.0, 0.0), mu2=vec3(0.0, 0.0, 0.0))
    if ti.static(ti.lang.impl.current_cfg().arch in _REAL_ARCHS):
        r = _REAL(rows, j, scr, k, tab_i, tab_f, G, R, S)
    else:
        r = _INLINE(rows, j, scr, k, tab_i, tab_f, G, R, S)
    return r.U, r.dU, r.mu1, r.mu2


@ti.func
def mutual_h_inline(rows: ti.template(), j, scr: ti.template(), k, tab_i: ti.template(),
                    tab_f: ti.template(), G, R, S):
    """:func:`mutual_h` always inlined (what the GPU backends run; the tests hold the
    real function to it bit for bit)."""
    r = _INLINE(rows, j, scr, k, tab_i, tab_f, G, R, S)
    return r.U, r.dU, r.mu1, r.mu2


#: The order-N potential for each row i (member i's coefficients, R_nd[i], S_nd[i]):
#: out = [U, dU/dR (3), mu1 (3), mu2 (3)], scratch row i (``mutual_gravity.make_evaluate``).
evaluate_multipole = make_evaluate(mutual_h, flat=True)
#: The same with :func:`mutual_h_inline`.
evaluate_multipole_inline = make_evaluate(mutual_h_inline, flat=True)
