"""The table-driven order-N mutual potential of the kernels (kernels/multipole_gravity.py with
the tables of ti_spinorbit/engine/multipole_tables.py) against the independent host reference
(ti_spinorbit/multipole.py), against the hand-written order-4 kernels, inside the planar
and 3-D equations of motion, and in runs (conservation, checkpoints, refusals)."""

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit import layout
from ti_spinorbit.engine import accuracy, evaluation, multipole_tables as MT
from ti_spinorbit.engine.checkpoint import CheckpointError
from ti_spinorbit.engine.ensemble import Ensemble
from ti_spinorbit.engine.members import Members
from ti_spinorbit import multipole as M
from ti_spinorbit.model import planar as PL
from ti_spinorbit.system import integrals as I

from conftest import degenerate_geometries, random_rotation

TOL = 1e-13          # relative, each of U, F, torque on A, torque on B
KERNEL_ORDER = layout.multipole.KERNEL_ORDER


def vector(T, degree):
    """An integral dict as the kernels' row (multi_indices order, degrees 0..degree)."""
    return np.array([float(T.get(tuple(int(x) for x in e), 0.0)) for e in M.multi_indices(degree)])


def centred(T):
    """The integrals with the (rounding-level) first moments set to zero: the kernels never
    read degree 1 (zero about the centre of mass), so the reference must not either."""
    return {k: (0.0 if sum(k) == 1 else v) for k, v in T.items()}


def kernel(TA, TB, R, S, order, degrees=None, G=1.0, form="harmonic"):
    """(U, dU/dR, torque on A, torque on B) of the order-N kernel for configurations R (n, 3)
    and S (n, 3, 3): the kernels' harmonic one (``form="harmonic"``, what the integrators
    call) or the Cartesian one (``"cartesian"``, kept as their independent check)."""
    from ti_spinorbit.kernels import harmonic_gravity, multipole_gravity

    dA, dB = MT.check_degrees(order, degrees)
    row = np.concatenate([vector(TA, dA), vector(TB, dB)])[None]
    tab = MT.tables(order, dA, dB, MT.odd_present(row, (dA, dB)))
    R = np.ascontiguousarray(np.atleast_2d(R), dtype=np.float64)
    S = np.ascontiguousarray(np.reshape(S, (-1, 3, 3)), dtype=np.float64)
    mp = MT.Multipole(tab, np.repeat(row, len(R), 0))
    if form == "harmonic":
        K, args = harmonic_gravity, mp.arguments(len(R))
    else:
        K, args = multipole_gravity, mp.cartesian_arguments(len(R))
    rows, scr, ints, floats = args
    out = np.zeros((len(R), 10))
    K.evaluate_multipole(rows, R, S, scr, ints, floats, out, G)
    return out[:, 0], out[:, 1:4], out[:, 4:7], out[:, 7:10]


def reference(TA, TB, R, S, order, degrees=None, G=1.0):
    U, F, tB, tA = M.mutual_force_torque(centred(TA), centred(TB), R, S, order,
                                         degrees=degrees, G=G)
    return U, -F, tA, tB


def relative(a, b):
    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)) / np.linalg.norm(b))


def ellipsoid_pair(order):
    """Triaxial ellipsoids, bounding radii 1 and 0.5 (contact at |R| = 1.5)."""
    return (I.ellipsoid_integrals(1.0, 0.8, 0.6, 1.0, order),
            I.ellipsoid_integrals(0.5, 0.35, 0.3, 0.2, order), 1.5)


def cloud(rng, n, scale, mass, order):
    """A lumpy point cloud about its centre of mass, with odd integrals; and its radius."""
    pts = rng.normal(size=(n, 3)) * np.array([1.0, 0.7, 0.5]) * scale
    pts[: n // 3] += np.array([0.4, 0.2, -0.1]) * scale
    m = rng.uniform(0.5, 1.5, n)
    m *= mass / m.sum()
    pts -= (m[:, None] * pts).sum(0) / mass
    return I.point_mass_integrals(pts, m, order), float(np.linalg.norm(pts, axis=1).max())


def cloud_pair(rng, order):
    TA, rA = cloud(rng, 40, 0.4, 1.0, order)
    TB, rB = cloud(rng, 30, 0.2, 0.1, order)
    return TA, TB, rA + rB


def configurations(rng, contact, n=4):
    """Tilted configurations: random directions and rotations, one just outside contact
    (1.03 x), the others at 1.2 to 3 x contact."""
    R = rng.normal(size=(n, 3))
    R /= np.linalg.norm(R, axis=1, keepdims=True)
    R *= contact * np.array([1.03, 1.2, 1.8, 3.0])[:n, None]
    return R, np.stack([random_rotation(rng) for _ in range(n)])


CASES = [(2, None), (3, None), (4, None), (5, None), (6, None), (7, None), (8, None),
         (10, None), (12, None), (8, (8, 4)), (12, (12, 6)), (6, (2, 6)), (9, (5, 9))]


@pytest.mark.parametrize("form", ["harmonic", "cartesian"])
@pytest.mark.parametrize("bodies", ["ellipsoids", "clouds"])
@pytest.mark.parametrize("order,degrees", CASES)
def test_kernel_equals_the_host_reference(rng, bodies, order, degrees, form):
    """U, the gradient and both torques of both kernel forms equal ti_spinorbit/multipole.py
    (the Cartesian host reference) to 1e-13 relative (2e-12 at orders above 8 in harmonics,
    whose tables carry the round-off of their projections), at orders 2..12 with and without
    degree caps, tilted and near contact; and the reference at the order below differs by far
    more, so the comparison sees the top order's terms."""
    if bodies == "ellipsoids":
        TA, TB, contact = ellipsoid_pair(order)
    else:
        TA, TB, contact = cloud_pair(rng, order)
    R, S = configurations(rng, contact)
    got = kernel(TA, TB, R, S, order, degrees, form=form)
    tol = TOL if form == "cartesian" or order <= 8 else 2e-12
    step = 2 if bodies == "ellipsoids" else 1          # odd orders add nothing to ellipsoids
    lower = max(order - step, 0)
    lower_degrees = None if degrees is None else tuple(min(d, lower) for d in degrees)
    for k in range(len(R)):
        ref = reference(TA, TB, R[k], S[k], order, degrees)
        for name, g, r in zip(("U", "dU/dR", "torque on B"), got[:2] + got[3:],
                              ref[:2] + ref[3:]):
            assert relative(g[k], r) <= tol, (name, k, relative(g[k], r))
        # the torque on A comes from the identity R × ∂U/∂R = τ_A + τ_B: its round-off is
        # that of the terms it is the difference of
        scale = np.linalg.norm(R[k]) * np.linalg.norm(ref[1]) + np.linalg.norm(ref[3])
        assert np.linalg.norm(got[2][k] - ref[2]) <= tol * scale, k
        if k <= 1 and order >= 3 and (degrees is None or min(degrees) >= 2):   # near contact
            below = reference(TA, TB, R[k], S[k], lower, lower_degrees)
            assert relative(below[1], ref[1]) > 1e3 * TOL, k


@pytest.mark.parametrize("order", [6, 9])
def test_kernel_at_degenerate_angles(rng, order):
    """Where the kernel's line-of-centres angles degenerate (R along ±z, the secondary's z
    axis along or against R, the planar geometry) it still equals the Cartesian host
    reference to 1e-13."""
    TA, TB, contact = cloud_pair(rng, order)
    geoms = degenerate_geometries(rng, contact / 1.5)
    R = np.stack([g[0] for g in geoms])
    S = np.stack([g[1] for g in geoms])
    got = kernel(TA, TB, R, S, order)
    for k in range(len(R)):
        ref = reference(TA, TB, R[k], S[k], order)
        for g, r in zip(got, ref):
            assert np.linalg.norm(g[k] - r) <= TOL * (np.linalg.norm(r) + np.linalg.norm(R[k])
                                                      * np.linalg.norm(ref[1])), k


@pytest.mark.parametrize("pair", ["cloud-ellipsoid", "ellipsoid-cloud"])
def test_kernel_with_one_mirror_symmetric_body(rng, pair):
    """A lumpy body beside an ellipsoid: the ellipsoid's program skips its odd degrees and
    orders (the tables' masks), the other's does not, and the two share the kernel's
    buffers; the result still equals the reference to 1e-13."""
    TA, TB, contact = cloud_pair(rng, 8)
    EA, EB, _ = ellipsoid_pair(8)
    if pair == "cloud-ellipsoid":
        TB = {k: v * 0.1 / EB[(0, 0, 0)] for k, v in EB.items()}
    else:
        TA = EA
    R, S = configurations(rng, 1.6)
    got = kernel(TA, TB, R, S, 8)
    for k in range(len(R)):
        ref = reference(TA, TB, R[k], S[k], 8)
        for g, r in zip(got[:2] + got[3:], ref[:2] + ref[3:]):
            assert relative(g[k], r) <= TOL, k


@pytest.mark.parametrize("order", [6, 8, 12])
def test_the_real_function_equals_the_inlined_body_bit_for_bit(rng, order):
    """On the CPU the integrators call the harmonic potential as one Taichi real function
    (compiled once, outside the integrator's state machine); the other backends inline the
    same body. Both must give the same bits."""
    from ti_spinorbit.kernels import harmonic_gravity as K

    TA, TB, contact = cloud_pair(rng, order)
    R, S = configurations(rng, contact)
    row = np.concatenate([vector(TA, order), vector(TB, order)])[None]
    mp = MT.Multipole(MT.tables(order, order, order, True), np.repeat(row, len(R), 0))
    rows, scr, ints, floats = mp.arguments(len(R))
    real, inline = np.zeros((len(R), 10)), np.zeros((len(R), 10))
    K.evaluate_multipole(rows, R, S, scr.copy(), ints, floats, real, 1.0)
    K.evaluate_multipole_inline(rows, R, S, scr.copy(), ints, floats, inline, 1.0)
    assert np.all(np.isfinite(real)) and np.any(real[:, 4:] != 0.0)
    np.testing.assert_array_equal(real, inline)


@pytest.mark.parametrize("symmetric", ["primary", "secondary"])
def test_a_failed_state_leaves_nothing_in_the_scratch(rng, symmetric):
    """A non-finite state evaluated in a slot does not change what the next state evaluated
    in that slot gives (every scratch entry the kernel reads was written by the same
    evaluation or never written at all; the chunks of the J rows read only their own
    degree; each body has its own first buffer, so the lumpy body's entries never reach the
    ellipsoid's skipped ones)."""
    from ti_spinorbit.kernels import harmonic_gravity as K

    TA, TB, contact = cloud_pair(rng, 8)
    EA, EB, _ = ellipsoid_pair(8)
    if symmetric == "secondary":
        TB = {k: v * 0.1 / EB[(0, 0, 0)] for k, v in EB.items()}  # masked classes too
    else:
        TA = EA
    R, S = configurations(rng, contact, n=1)
    row = np.concatenate([vector(TA, 8), vector(TB, 8)])[None]
    mp = MT.Multipole(MT.tables(8, 8, 8, True), row)
    rows, scr, ints, floats = mp.arguments(1)
    fresh = np.zeros((1, 10))
    K.evaluate_multipole(rows, R, S, scr.copy(), ints, floats, fresh, 1.0)
    used = scr.copy()
    bad = np.zeros((1, 10))
    K.evaluate_multipole(rows, np.full((1, 3), np.nan), S, used, ints, floats, bad, 1.0)
    assert np.all(np.isnan(bad))
    after = np.zeros((1, 10))
    K.evaluate_multipole(rows, R, S, used, ints, floats, after, 1.0)
    np.testing.assert_array_equal(after, fresh)


def test_conservation_identity_of_the_torques(rng):
    """R × F + τ_A + τ_B = 0 to round-off: the kernel takes τ_A from the identity, the
    reference computes it on its own, and the two agree (above), so the identity holds."""
    TA, TB, contact = cloud_pair(rng, 8)
    R, S = configurations(rng, contact)
    U, dUdR, tA, tB = kernel(TA, TB, R, S, 8)
    total = np.cross(R, -dUdR) + tA + tB
    assert np.abs(total).max() <= 1e-13 * np.abs(np.cross(R, dUdR)).max()


def _hand_written_row(T):
    """A body's row of the hand-written kernels (Body.as_row order) from an integral dict."""
    return np.array([T[(0, 0, 0)]] + [T[k] for k in layout.EXPONENTS_2]
                    + [T[k] for k in layout.EXPONENTS_3] + [T[k] for k in layout.EXPONENTS_4])


@pytest.mark.parametrize("order", [0, 2, 3, 4])
@pytest.mark.parametrize("bodies", ["ellipsoids", "clouds"])
def test_order_4_through_the_tables_equals_the_hand_written_kernels(rng, order, bodies):
    """At orders 0..4 the table path equals kernels/mutual_gravity.py to 1e-13 relative: a
    check of both (bodies in their principal frames, which the hand-written kernels assume)."""
    from ti_spinorbit.kernels import advance as K

    if bodies == "ellipsoids":
        TA, TB, contact = ellipsoid_pair(4)
    else:
        TA, TB, contact = cloud_pair(rng, 4)
        TA, TB = (centred(I.principal_frame(T)[0]) for T in (TA, TB))
        for T in (TA, TB):
            for k in ((1, 1, 0), (1, 0, 1), (0, 1, 1)):
                T[k] = 0.0                       # rounding-level: the row has no such column
    R, S = configurations(rng, contact)
    L = layout.spatial
    par = np.zeros((len(R), L.NPAR))
    par[:, L.BODY_A:L.BODY_A + layout.ROW_LENGTH] = _hand_written_row(TA)
    par[:, L.BODY_B:L.BODY_B + layout.ROW_LENGTH] = _hand_written_row(TB)
    out = np.zeros((len(R), 10))
    K.evaluate_mutual(par, R, np.ascontiguousarray(S), out, 1.0, order, bodies == "clouds")
    got = kernel(TA, TB, R, S, order)
    for name, c, g in (("U", 0, got[0][:, None]), ("dU/dR", 1, got[1]), ("torque on A", 4, got[2]),
                       ("torque on B", 7, got[3])):
        hand = out[:, c:c + g.shape[1]]
        for k in range(len(R)):
            # torques on A from the identity R × ∂U/∂R − τ_B in both: round-off of |R| |F|
            scale = np.linalg.norm(hand[k]) + (np.linalg.norm(R[k]) * np.linalg.norm(out[k, 1:4])
                                               if c == 4 else 0.0)
            if scale == 0.0:                              # order 0: no torque on B
                assert np.linalg.norm(g[k]) == 0.0
            else:
                assert np.linalg.norm(g[k] - hand[k]) <= TOL * scale, (name, k)


def test_tables_are_shared_and_read_only():
    a = MT.tables(8, 8, 4, False)
    assert MT.tables(8, 8, 4, False) is a
    with pytest.raises(ValueError):
        a.ints[0] = 1
    assert a.pairs > 0 and a.scratch > 0
    # ellipsoids (no odd terms) need fewer pairs than lumpy bodies
    assert MT.tables(8, 8, 8, False).pairs < MT.tables(8, 8, 8, True).pairs


# ---- in the equations of motion ----------------------------------------------------------

def _ellipsoid_system():
    A = tso.Ellipsoid(330.0, 300.0, 280.0, 2000.0, name="A")
    B = tso.Ellipsoid(150.0, 100.0, 90.0, 2000.0, name="B")
    return tso.BinarySystem(A, B, 1200.0, 0.1, name="ellipsoids")


def _rows(system, order, degrees=None):
    """Scaled order-N rows of an ellipsoid system from the closed form (not from the bodies,
    so that these tests hold whatever order the bodies store)."""
    dA, dB = MT.check_degrees(order, degrees)
    M_, a = system.total_mass, float(system.a)
    out = []
    for body, d in ((system.primary, dA), (system.secondary, dB)):
        ax = [330.0, 300.0, 280.0] if body.name == "A" else [150.0, 100.0, 90.0]
        T = I.ellipsoid_integrals(*(x / a for x in ax), body.mass / M_, d)
        out.append(vector(T, d))
    return np.concatenate(out)[None]


def _planar_states(rng, y0, n):
    """Planar 3-D states near y0: r, v, both attitudes about z and both spins about z moved."""
    L = layout.spatial
    y = np.repeat(y0[:1], n, 0)
    for k in range(n):
        c, s = np.cos(rng.uniform(0, 2 * np.pi)), np.sin(rng.uniform(0, 2 * np.pi))
        y[k, L.Y_R:L.Y_R + 2] = 0.9 * np.array([c, s])
        y[k, L.Y_V:L.Y_V + 2] = np.array([-s, c]) * 1.05 + 0.1 * rng.normal(size=2)
        th = rng.uniform(0, 2 * np.pi)
        y[k, L.Y_S:L.Y_S + 9] = [np.cos(th), -np.sin(th), 0, np.sin(th), np.cos(th), 0, 0, 0, 1]
        y[k, L.Y_W1 + 2] = rng.uniform(0.5, 3)
        y[k, L.Y_W2 + 2] = rng.uniform(0.5, 2)
    return y


def test_planar_order_n_rhs_equals_the_3d_one(rng):
    """The planar model's order-6 right-hand side equals d/dt to_planar(y) of the 3-D one
    (Richardson-extrapolated central differences, as tests/test_planar.py does at order 4)."""
    from ti_spinorbit.kernels import advance as K

    system = _ellipsoid_system()
    table = Members.from_starts(system, [0.0], [1.0], 1000.0)
    par = np.repeat(table.par, 4, 0)
    y = _planar_states(rng, table.y0, 4)
    mp = MT.Multipole(MT.tables(6, 6, 6, False), np.repeat(_rows(system, 6), 4, 0))
    f3 = np.zeros_like(y)
    K.SPATIAL.evaluate_rhs_mp(par, y, f3, *mp.arguments(4), KERNEL_ORDER, False)
    q = PL.to_planar(y)
    fp = np.zeros_like(q)
    K.PLANAR.evaluate_rhs_mp(PL.parameter_rows(par), q, fp, *mp.arguments(4), KERNEL_ORDER, False)

    def central(eps):
        return (PL.to_planar(y + eps * f3) - PL.to_planar(y - eps * f3)) / (2 * eps)

    expected = (4 * central(5e-4) - central(1e-3)) / 3
    np.testing.assert_allclose(fp, expected, rtol=0, atol=1e-10 * np.abs(fp).max())
    # the order-6 terms are there: the order-4 planar RHS differs by far more than that
    f4 = np.zeros_like(q)
    K.PLANAR.evaluate_rhs(PL.parameter_rows(par), q, f4, 4, False)
    assert np.abs(f4 - fp).max() > 1e3 * 1e-10 * np.abs(fp).max()


@pytest.mark.parametrize("order", [6, 8])
def test_3d_run_conserves_energy_and_angular_momentum(order):
    """A tilted 3-D start at orders 6 and 8 (every torque component at work): relative energy
    and angular-momentum drift at the tolerance level over 10 orbits (the healthy band is
    4-18 × rtol per orbit, docs/design.md "Accuracy of the integration")."""
    system = _ellipsoid_system()
    start = system.tilted_start(20.0, 1.3, roll=10.0, pitch=5.0, spin_x=0.1)
    table = Members.from_states(system, [start], 1000.0)
    rtol, orbits = 1e-11, 10.0
    ens = Ensemble(table.par, table.y0, order=order, rtol=rtol, model="3d",
                   multipole_rows=_rows(system, order))
    out = ens.run(2.0 * np.pi * orbits)
    assert out.status[0] == layout.DONE
    energy, angmom = accuracy.drifts(out.diag_start, out.diag_end, None)
    assert energy[0] <= 50 * rtol * orbits, energy
    assert angmom[0] <= 50 * rtol * orbits, angmom
    # the run is one of this order: its energy is not the order-4 energy
    four = evaluation.diagnostics(table.par, table.y0, [0], 4)
    assert abs(four[0, 0] - out.diag_start[0, 0]) > 1e3 * rtol * abs(four[0, 0])


def _holds(system, degree):
    return min(MT.degrees_provided(b) for b in (system.primary, system.secondary)) >= degree


@pytest.mark.parametrize("order", [6, 8])
def test_time_series_at_order_n_conserves(order):
    """The whole entry point at orders 6 and 8 (3-D): energy_drift and angmom_drift at the
    tolerance level, the order recorded in the result."""
    system = _ellipsoid_system()
    if not _holds(system, order):
        pytest.skip("these bodies hold their integrals only to degree 4")
    start = system.tilted_start(20.0, 1.3, roll=10.0, pitch=5.0)
    ts = tso.time_series(system, initial_states=[start], orbits=5, samples_per_orbit=4,
                         rtol=1e-11, integrator=tso.Integrator(order=order, model="3d"))
    assert np.max(ts.energy_drift) <= 50 * 1e-11 * 5
    assert np.max(ts.angmom_drift) <= 50 * 1e-11 * 5


def test_planar_and_3d_runs_agree_at_order_6():
    """The same planar start through both models at order 6: the crossings agree in
    proportion to the tolerance."""
    system = _ellipsoid_system()
    table = Members.from_starts(system, [0.0, 40.0], [1.0, 1.4], 1000.0)
    rows = np.repeat(_rows(system, 6), 2, 0)
    runs = {}
    for model in ("planar", "3d"):
        ens = Ensemble(table.par, table.y0, order=6, rtol=1e-12, model=model,
                       multipole_rows=rows)
        runs[model] = ens.run(2.0 * np.pi * 5)
        assert ens.model == model
    for k in range(2):
        a, b = runs["planar"].events[k], runs["3d"].events[k]
        assert len(a) == len(b) >= 4
        assert np.abs(a - b).max() < 1e-8


# ---- checkpoints and refusals -------------------------------------------------------------

def test_resume_with_another_order_or_degrees_is_refused(tmp_path):
    system = _ellipsoid_system()
    table = Members.from_starts(system, [0.0], [1.0], 1000.0)
    path = tmp_path / "ckpt"
    Ensemble(table.par, table.y0, order=6, model="3d",
             multipole_rows=_rows(system, 6)).run(2.0 * np.pi * 0.5, checkpoint=path,
                                                  keep_checkpoint=True)
    with pytest.raises(CheckpointError, match=r"order \(checkpoint 6, now 8\)"):
        Ensemble(table.par, table.y0, order=8, model="3d",
                 multipole_rows=_rows(system, 8)).run(2.0 * np.pi, checkpoint=path,
                                                      resume=True)
    with pytest.raises(CheckpointError, match=r"order \(checkpoint 6, now 4\)"):
        Ensemble(table.par, table.y0, order=4, model="3d").run(2.0 * np.pi, checkpoint=path,
                                                               resume=True)
    with pytest.raises(CheckpointError, match=r"degrees \(checkpoint \[6, 6\], now \[6, 4\]\)"):
        Ensemble(table.par, table.y0, order=6, model="3d", degrees=(6, 4),
                 multipole_rows=_rows(system, 6, (6, 4))).run(2.0 * np.pi, checkpoint=path,
                                                              resume=True)
    # other order-N integrals (the same order-4 rows) are other inputs
    rows = _rows(system, 6)
    rows[0, -1] *= 1.5
    with pytest.raises(CheckpointError, match="order-N integrals"):
        Ensemble(table.par, table.y0, order=6, model="3d",
                 multipole_rows=rows).run(2.0 * np.pi, checkpoint=path, resume=True)


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(order=1), ValueError, r"^order must be 0 or an integer in \[2, 16\] \(got 1\)$"),
    (dict(order=17), ValueError, r"^order must be 0 or an integer in \[2, 16\] \(got 17\)$"),
    (dict(order=6.5), ValueError, r"^order must be 0 or an integer in \[2, 16\] \(got 6.5\)$"),
    (dict(order=-2), ValueError, r"^order must be 0 or an integer in \[2, 16\]"),
    (dict(order="8"), TypeError, r"^order must be an integer, 0 or in \[2, 16\] \(got '8'\)$"),
    (dict(order=None), TypeError, r"^order must be an integer, 0 or in \[2, 16\]"),
    (dict(order=8, degrees=(9, 2)), ValueError,
     r"^degrees must be None or a pair \(primary, secondary\) of integers in \[0, order=8\]"),
    (dict(order=8, degrees=(8,)), ValueError, r"^degrees must be None or a pair"),
    (dict(order=4, degrees=(4, 2)), ValueError, r"^degrees is for orders above 4"),
])
def test_bad_orders_and_degrees_are_refused_in_one_line(kwargs, error, message):
    with pytest.raises(error, match=message) as info:
        tso.Integrator(**kwargs)
    assert "\n" not in str(info.value)


def test_order_8_is_accepted_and_one_variant_serves_every_order_above_4():
    from ti_spinorbit.engine.compiling import KernelVariant

    assert tso.Integrator(order=8, degrees=(8, 4)).degrees == (8, 4)
    assert tso.Integrator(order=12).order == 12
    names = {KernelVariant("3d", order=k, odd=k % 2 == 0).name for k in (5, 6, 8, 12, 16)}
    assert names == {"3d/plain/sections/orderN/cash-karp"}
    assert KernelVariant("3d", order=4).name == "3d/plain/sections/order4/cash-karp"


def test_ensemble_needs_the_rows_above_order_4_and_refuses_them_below():
    system = _ellipsoid_system()
    table = Members.from_starts(system, [0.0], [1.0], 1000.0)
    with pytest.raises(ValueError, match=r"^order 6 needs multipole_rows"):
        Ensemble(table.par, table.y0, order=6)
    with pytest.raises(ValueError, match=r"^multipole_rows and degrees are for orders above 4"):
        Ensemble(table.par, table.y0, order=4, multipole_rows=_rows(system, 6))
    with pytest.raises(ValueError, match=r"^multipole_rows must be \(1, 168\)"):
        Ensemble(table.par, table.y0, order=6, multipole_rows=_rows(system, 6)[:, :-1])


def test_a_body_that_stops_below_the_degree_is_refused():
    """A body holding integrals to degree 4 only cannot serve order 6 (its degree-5 and 6
    integrals would read as zero): refused in one line, unless capped."""
    body = tso.Body(1e9, {(2, 0, 0): 1e13, (0, 2, 0): 8e12, (0, 0, 2): 6e12}, 200.0)
    if MT.degrees_provided(body) > 4:
        pytest.skip("this body holds more than degree 4")
    system = tso.BinarySystem(body, tso.Ellipsoid(80.0, 60.0, 50.0, 2000.0), 1500.0, 0.1)
    with pytest.raises(ValueError, match=r"the primary holds integrals up to degree 4, but "
                                         r"order 6 needs degree 6"):
        Members.from_starts(system, 0.0, 1.0, order=6)
    capped = Members.from_starts(system, 0.0, 1.0, order=6, degrees=(4, 6))
    assert capped.degrees == (4, 6) and capped.multipole_rows.shape == (1, 35 + 84)


def test_mutual_potential_at_order_n_equals_the_reference():
    """tso.mutual_potential(order=N) in SI against ti_spinorbit/multipole.py with the bodies' own
    integrals (bodies that hold them)."""
    system = _ellipsoid_system()
    if not _holds(system, 10):
        pytest.skip("these bodies hold their integrals only to degree 4")
    A, B = system.primary, system.secondary
    rng = np.random.default_rng(5)
    R = rng.normal(size=(3, 3))
    R *= 700.0 / np.linalg.norm(R, axis=1, keepdims=True)
    S = np.stack([random_rotation(rng) for _ in range(3)])
    for order in (6, 10):
        V, F, tA, tB = evaluation.mutual_potential(A, B, R, S, order=order)
        for k in range(3):
            U, Fr, tBr, tAr = M.mutual_force_torque(A.integral_set(order), B.integral_set(order),
                                                    R[k], S[k], order)
            assert abs(V[k] - U) <= TOL * abs(U)
            assert relative(F[k], Fr) <= TOL
            assert relative(tA[k], tAr) <= TOL and relative(tB[k], tBr) <= TOL


def test_chunks_of_an_order_n_table_integrate_as_the_whole():
    """A member's order-N result depends on its own row only: chunks of the table (what the
    Dask runner sends) give the whole table's crossings bit for bit."""
    from ti_spinorbit.studies.section import section_of

    system = _ellipsoid_system()
    if not _holds(system, 6):
        pytest.skip("these bodies hold their integrals only to degree 4")
    table = Members.from_starts(system, [0.0, 30.0, 60.0, 90.0], [1.0, 1.2, 1.4, 1.6], order=6,
                                degrees=(6, 4))
    integrator = tso.Integrator(order=6, degrees=(6, 4), rtol=1e-10)
    run = tso.Run(progress=False)
    whole = section_of(table, 2, integrator=integrator, run=run)
    parts = [section_of(part, 2, integrator=integrator, run=run) for _, _, part in table.chunks(3)]
    rows = [(p, k) for p in parts for k in range(len(p.count))]
    assert len(rows) == len(whole.count)
    for i, (p, k) in enumerate(rows):
        n = whole.count[i]
        assert p.count[k] == n >= 1
        np.testing.assert_array_equal(p.t[k, :n], whole.t[i, :n])
        np.testing.assert_array_equal(p.thetadot_p[k, :n], whole.thetadot_p[i, :n])


@pytest.mark.parametrize("text, ok", [("0", True), ("2", True), ("16", True), ("1", False),
                                      ("17", False), ("-1", False)])
def test_command_line_order_flag(text, ok):
    import argparse

    from ti_spinorbit.cli.options import ORDER

    if ok:
        assert ORDER(text) == int(text)
    else:
        with pytest.raises(argparse.ArgumentTypeError,
                           match=rf"^must lie in \{{0\}} ∪ \[2, 16\] \(got {text}\)$"):
            ORDER(text)
