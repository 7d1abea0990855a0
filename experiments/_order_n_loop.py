"""The benchmark loop of the order-N potential alone (``bench_harmonics.py`` and
``bench_orders.py``'s ``split``): one member per loop iteration, a dependent chain of
evaluations so that nothing is hoisted, one core under ``tso.init(cpu_max_num_threads=1)``.
Import after Taichi is initialised."""

import taichi as ti


def tilted_rotation():
    """A member's attitude: a rotation about a tilted axis (every Euler angle non-zero)."""
    @ti.func
    def rotation(i):
        a, b = 0.3 * i + 0.2, 0.7 + 0.05 * i
        ca, sa, cb, sb = ti.cos(a), ti.sin(a), ti.cos(b), ti.sin(b)
        Rz = ti.Matrix([[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]], ti.f64)
        Rx = ti.Matrix([[1.0, 0.0, 0.0], [0.0, cb, -sb], [0.0, sb, cb]], ti.f64)
        return Rz @ Rx @ Rz.transpose() @ Rx
    return rotation


def loop_kernel(potential, rotation):
    """The loop over an order-N ``potential`` func (the kernels' signature: rows, j, scr, k,
    tab_i, tab_f, G, R, S): per member i, ``rotation(i)`` as its attitude and a dependent
    chain of ``repeats`` evaluations; out[i] = the last [U, dU/dR, mu1, mu2] and the chain's
    sum (11 columns)."""
    from ti_spinorbit.kernels.mutual_gravity import vec3

    nd2f = ti.types.ndarray(dtype=ti.f64, ndim=2)
    nd1f = ti.types.ndarray(dtype=ti.f64, ndim=1)
    nd1i = ti.types.ndarray(dtype=ti.i32, ndim=1)
    ndf = ti.types.ndarray(dtype=ti.f64)          # rows and scratch: 2-D or flat (harmonic)

    @ti.kernel
    def loop(rows: ndf, R_nd: nd2f, scr: ndf, ints: nd1i, floats: nd1f, out: nd2f,
             repeats: ti.i32):
        for i in range(R_nd.shape[0]):
            R = vec3(R_nd[i, 0], R_nd[i, 1], R_nd[i, 2])
            S = rotation(i)
            acc = 0.0
            U, dU, m1, m2 = potential(rows, i, scr, i, ints, floats, 1.0, R, S)
            for _ in range(repeats):
                U, dU, m1, m2 = potential(rows, i, scr, i, ints, floats, 1.0, R, S)
                acc += U + m2[2]
                R[0] += 1e-14 * dU[0]            # a dependent chain: nothing hoisted
            out[i, 0] = U
            for c in ti.static(range(3)):
                out[i, 1 + c] = dU[c]
                out[i, 4 + c] = m1[c]
                out[i, 7 + c] = m2[c]
            out[i, 10] = acc

    return loop
