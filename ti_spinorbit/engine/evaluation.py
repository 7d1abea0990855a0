"""Host-side evaluations through the kernels, in one place: every launch of a Taichi kernel
that is not an integration.

* :func:`mutual_potential`: the truncated mutual potential, the force and both torques of
  two bodies at given configurations (SI, the primary's frame), by the same Taichi code
  path as the integrator (docs/physics.md §3);
* :func:`true_acceleration` and :func:`apsidal_rates`: the relative acceleration seen from
  the inertial frame and the rate ϖ̇ of the osculating line of apsides it gives, for the
  apsidal coordinates of docs/physics.md §6.7;
* :func:`diagnostics`: energies, angular momenta and orthonormality errors of recorded
  states (``layout.DIAG_FIELDS``), for time series and the accuracy verdict;
* :func:`truncation_estimates`: the size of the next orders of the mutual potential at
  recorded states, for the truncation verdict (``engine.accuracy``).

Results are built from these functions and the member table's rows; they never call an
:class:`~ti_spinorbit.engine.ensemble.Ensemble` back. Each call initialises Taichi when it is
not yet (``runtime.ensure_init``); the kernels are imported on first use, so importing this
module stays quiet.
"""

import numpy as np

from .. import layout, runtime
from .._validate import require_finite, require_order
from ..layout import ROW_LENGTH, spatial as _S
from ..system.bodies import Body, odd_columns
from ..system.systems import G
from ..model.coordinates import apsidal_rate
from . import multipole_tables as _mp

#: States per launch of an order-N evaluation: each takes a scratch row of its own
#: (``multipole_tables.Tables.scratch``), so long record lists go in blocks of this many.
ORDER_N_BLOCK = 4096


#: Parameter-row columns of integrals with an odd exponent, both bodies.
_ODD_COLUMNS = np.array(odd_columns(ROW_LENGTH))


def has_odd(par) -> bool:
    """Whether any member row holds an integral with an odd exponent (the kernels' odd
    terms are then compiled in), as ``Ensemble`` decides it."""
    par = np.asarray(par)
    return bool(par.size and np.any(par[:, _ODD_COLUMNS] != 0.0))


def mutual_potential(primary: Body, secondary: Body, R, S, order: int = 4, degrees=None):
    """Mutual potential energy, force on the secondary and torques, SI, primary frame.

    Parameters
    ----------
    primary, secondary : Body
    R : array (..., 3)
        Secondary's centre of mass relative to the primary's, m, primary frame.
    S : array (..., 3, 3)
        Rotation taking secondary-frame vectors to the primary frame: orthonormal
        (|S^T S − 1| <= 1e-9) and proper (det S = +1; a reflection is no rigid motion).
    order : int
        Truncation order, 0 or 2..16 (docs/physics.md §3; Ashenberg 2007; Hou et al. 2017):
        up to 4 the hand-written kernels, above 4 the table-driven ones (§3.8.2), which need
        each body's integrals to the degree used (``body.integral``).
    degrees : (int, int), optional
        Order > 4 only: degree caps (primary, secondary) of the integrals, in [0, order];
        default (order, order).

    Returns
    -------
    (V, F, torque_primary, torque_secondary)
        V in J; F = −∂V/∂R the force on the secondary, N; torques about each body's centre of
        mass, N m (δV = −torque·δθ for an infinitesimal rotation of that body alone).

    Examples
    --------
    The energy, force and torques of 1991 VH's bodies 3 km apart, the secondary's axes along
    the primary's (``S`` the identity):

    >>> vh = tso.catalog.system("1991 VH")
    >>> V, F, torque_p, torque_s = tso.mutual_potential(
    ...     vh.primary, vh.secondary, R=[3000.0, 500.0, 0.0], S=np.eye(3))
    >>> f"{V:.4g} J"
    '-3.771e+09 J'
    >>> F.shape, torque_s.shape                            # N and N m, primary frame
    ((3,), (3,))
    """
    from ..kernels import advance as K      # Taichi: imported on first use

    for label, body in (("primary", primary), ("secondary", secondary)):
        if not isinstance(body, Body):
            raise TypeError(f"{label} must be a ti_spinorbit Body (Sphere, Ellipsoid, Body) "
                            f"(got {type(body).__name__})")
    order = require_order(order)
    # checked before the conversion, so text is a TypeError naming R or S
    R = np.asarray(require_finite("R", R), dtype=np.float64)
    S = np.asarray(require_finite("S", S), dtype=np.float64)
    if R.shape[-1:] != (3,) or S.shape[-2:] != (3, 3) or R.shape[:-1] != S.shape[:-2]:
        raise ValueError(f"R must be (..., 3) and S (..., 3, 3) with matching batch shapes "
                         f"(got {R.shape} and {S.shape})")
    if not np.allclose(np.einsum("...ji,...jk->...ik", S, S), np.eye(3), atol=1e-9):
        raise ValueError("S must be a rotation matrix (S^T S = 1)")
    det = np.linalg.det(S) if S.size else np.ones(0)
    if np.any(det < 0):
        raise ValueError(f"S must be a proper rotation matrix, det S = +1 (got det S = "
                         f"{float(np.min(det)):.6g}: a reflection)")
    # the expansion converges only outside the bodies' bounding spheres (R = 0 gave NaN)
    contact = primary.bounding_radius + secondary.bounding_radius
    closest = float(np.min(np.linalg.norm(R, axis=-1))) if R.size else np.inf
    if closest <= contact:
        raise ValueError(f"bodies overlap: |R| = {closest:.6g} m must exceed the sum of "
                         f"bounding radii ({contact:.6g} m)")
    batch = R.shape[:-1]
    Rf = np.ascontiguousarray(R.reshape(-1, 3))
    Sf = np.ascontiguousarray(S.reshape(-1, 3, 3))
    if order > layout.multipole.HAND_WRITTEN_MAX:
        return _mutual_potential_n(primary, secondary, Rf, Sf, order, degrees, batch)
    if degrees is not None:
        raise ValueError(f"degrees is for orders above {layout.multipole.HAND_WRITTEN_MAX} "
                         f"(got order {order})")
    par = np.zeros((len(Rf), _S.NPAR))
    par[:, _S.BODY_A:_S.BODY_A + ROW_LENGTH] = primary.as_row()
    par[:, _S.BODY_B:_S.BODY_B + ROW_LENGTH] = secondary.as_row()
    runtime.ensure_init()
    out = np.zeros((len(Rf), 10))
    K.evaluate_mutual(par, Rf, Sf, out, G, int(order), has_odd(par))
    V = out[:, 0].reshape(batch)
    F = -out[:, 1:4].reshape(batch + (3,))
    return V, F, out[:, 4:7].reshape(batch + (3,)), out[:, 7:10].reshape(batch + (3,))


def _mutual_potential_n(primary, secondary, Rf, Sf, order, degrees, batch):
    """:func:`mutual_potential` above order 4: the kernels' order-N potential in units of the
    contact distance L = ρ_A + ρ_B and the total mass M (G = 1), so that no power of a length
    in metres comes near the float range, then back to SI."""
    from ..kernels import harmonic_gravity as K      # Taichi: imported on first use

    dA, dB = _mp.check_degrees(order, degrees)
    _check_degree(primary, "primary", dA, order)
    _check_degree(secondary, "secondary", dB, order)
    M = primary.mass + secondary.mass
    L = primary.bounding_radius + secondary.bounding_radius
    row = np.concatenate([_mp.body_integrals(primary, dA, M, L),
                          _mp.body_integrals(secondary, dB, M, L)])
    rows = np.repeat(row[None], max(len(Rf), 1), axis=0)
    tab = _mp.tables(order, dA, dB, _mp.odd_present(row[None], (dA, dB)))
    out = np.zeros((len(Rf), 10))
    if len(Rf):
        runtime.ensure_init()
        for lo in range(0, len(Rf), ORDER_N_BLOCK):
            hi = min(lo + ORDER_N_BLOCK, len(Rf))
            rows_, scr, ints, floats = _mp.Multipole(tab, rows[lo:hi]).arguments(hi - lo)
            part = np.zeros((hi - lo, 10))
            K.evaluate_multipole(rows_, np.ascontiguousarray(Rf[lo:hi] / L),
                                 np.ascontiguousarray(Sf[lo:hi]), scr, ints, floats, part, 1.0)
            out[lo:hi] = part
    energy = G * M * M / L
    V = out[:, 0].reshape(batch) * energy
    F = -out[:, 1:4].reshape(batch + (3,)) * (energy / L)
    return (V, F, out[:, 4:7].reshape(batch + (3,)) * energy,
            out[:, 7:10].reshape(batch + (3,)) * energy)


#: Orders beyond a run's that its truncation estimate takes (the next two: N+1 and N+2,
#: since symmetric bodies have no odd orders).
TRUNCATION_STEP = 2


def truncation_estimates(groups, states, order):
    """The relative size of the orders above ``order`` in the mutual force and in the torque
    on the secondary, at scaled 3-D states (M, 30) (docs/physics.md §3.9).

    ``groups`` lists (system, indices into ``states``) for the distinct systems
    (``engine.members.member_groups``). At each state the force F and the secondary's torque
    τ are evaluated at ``order`` and at ``order + TRUNCATION_STEP`` (no degree caps: what the
    run's caps drop counts too) through the kernels (:func:`mutual_potential`), in the
    recorded attitude and with the secondary turned by 45° about z (the larger counts); returns
    (|ΔF|/|F|, |Δτ|/(|F| ρ_B)) per state, ρ_B the secondary's bounding radius (a torque
    itself can vanish by symmetry; |F| ρ_B is the torque scale of the force). NaN where not
    estimated: a non-finite state, a state at or inside contact (the series diverges there),
    or bodies that hold no integrals beyond the run's order (``Body.order``), or an order
    beyond the kernels' highest."""
    states = np.asarray(states, dtype=np.float64).reshape(-1, _S.NSTATE)
    force = np.full(len(states), np.nan)
    torque = np.full(len(states), np.nan)
    higher = int(order) + TRUNCATION_STEP
    if higher > layout.multipole.MAX_ORDER:
        return force, torque
    for system, idx in groups:
        primary, secondary = system.primary, system.secondary
        if min(_mp.degrees_provided(primary), _mp.degrees_provided(secondary)) < higher:
            continue
        y = states[idx]
        R = y[:, _S.Y_R:_S.Y_R + 3] * system.a
        S = y[:, _S.Y_S:_S.Y_S + 9].reshape(-1, 3, 3)
        contact = primary.bounding_radius + secondary.bounding_radius
        with np.errstate(invalid="ignore"):
            ok = np.isfinite(y).all(axis=1) & (np.linalg.norm(R, axis=1) > contact * (1 + 1e-9))
        if not ok.any():
            continue
        R, k = R[ok], int(ok.sum())
        # the nearest rotation (a loose-tolerance run drifts off orthonormality; the estimate
        # needs the attitude, not its drift)
        u, _, vt = np.linalg.svd(S[ok])
        S = u @ vt
        # the recorded attitude, and the same turned by 45° about z: an aligned body feels no
        # torque at any order, and its estimate would say nothing of the attitudes to come
        R2, S2 = np.concatenate([R, R]), np.concatenate([S, np.einsum("ij,mjk->mik", _TURN, S)])
        _, F0, _, t0 = mutual_potential(primary, secondary, R2, S2, int(order))
        _, F1, _, t1 = mutual_potential(primary, secondary, R2, S2, higher)
        scale = np.linalg.norm(F1, axis=1)
        f = np.linalg.norm(F1 - F0, axis=1) / scale
        t = np.linalg.norm(t1 - t0, axis=1) / (scale * secondary.bounding_radius)
        sel = np.asarray(idx)[ok]
        force[sel] = np.fmax(f[:k], f[k:])
        torque[sel] = np.fmax(t[:k], t[k:])
    return force, torque


#: A turn of 45° about the primary's z axis (the orbit normal of a planar start).
_TURN = np.array([[np.sqrt(0.5), -np.sqrt(0.5), 0.0], [np.sqrt(0.5), np.sqrt(0.5), 0.0],
                  [0.0, 0.0, 1.0]])


def _check_degree(body, label, degree, order):
    """Refuse a body whose integrals stop below ``degree``: its missing ones would be taken
    as zero and the order-``order`` potential silently be a lower one."""
    provided = _mp.degrees_provided(body)
    if provided < degree:
        raise ValueError(f"the {label} holds integrals up to degree {provided}, but order "
                         f"{order} needs degree {degree}: give it integrals of degree "
                         f"{degree} or cap it with degrees=")


def true_acceleration(par, states, order=4, odd=None, multipole=None):
    """Relative acceleration d²R/dt² seen from the inertial frame, in primary-frame
    components, scaled units (G = 1, a = 1, n = 1), for 3-D states (M, 30) with parameter
    rows par (M, NPAR). It is −(∂U/∂R)/m: the kernels' dV/dt = V × Ω1 − (∂U/∂R)/m with the
    frame term V × Ω1 removed (docs/physics.md §4.3). ``odd``: whether the odd terms are
    needed (default: decided from ``par``; pass it when ``par`` repeats the rows of fewer
    members, one per record, and the decision is known from those). Above order 4
    ``multipole`` (``multipole_tables.Multipole``) holds the order-N rows, one per state."""
    from ..kernels import advance as K      # Taichi: imported on first use

    runtime.ensure_init()
    par = np.ascontiguousarray(par, dtype=np.float64)
    y = np.ascontiguousarray(np.atleast_2d(states), dtype=np.float64)
    if len(y) == 0:
        return np.zeros((0, 3))
    f = np.zeros_like(y)
    if _order_n(order, multipole):
        for lo, hi in _blocks(len(y)):
            part = np.zeros_like(y[lo:hi])
            K.SPATIAL.evaluate_rhs_mp(par[lo:hi], y[lo:hi], part,
                                      *multipole.take(np.arange(lo, hi)).arguments(hi - lo),
                                      layout.multipole.KERNEL_ORDER, False)
            f[lo:hi] = part
    else:
        K.SPATIAL.evaluate_rhs(par, y, f, int(order), has_odd(par) if odd is None else bool(odd))
    V = y[:, _S.Y_V:_S.Y_V + 3]
    om1 = par[:, _S.P_IA:_S.P_IA + 3] * y[:, _S.Y_W1:_S.Y_W1 + 3]
    return f[:, _S.Y_V:_S.Y_V + 3] + np.cross(om1, V)


def apsidal_rates(par, states, order=4, odd=None, multipole=None):
    """ϖ̇ (units of n) of scaled 3-D states (M, 30) with parameter rows par (M, NPAR): the
    exact rate of the osculating line of apsides under the true acceleration
    (:func:`ti_spinorbit.model.coordinates.apsidal_rate`; ``multipole`` above order 4: the
    order-N rows, one per state)."""
    states = np.atleast_2d(states)
    acc = true_acceleration(par, states, order, odd, multipole)
    return apsidal_rate(states[:, _S.Y_R:_S.Y_R + 3], states[:, _S.Y_V:_S.Y_V + 3], acc)


def diagnostics(par, states, member, order=4, odd=None, multipole=None):
    """``layout.DIAG_FIELDS`` (three energies, three angular-momentum vectors, two
    orthonormality errors; scaled units) of 3-D states (M, 30) of the members ``member``
    (M,) whose rows are ``par`` (N, NPAR); ``odd`` as ``Ensemble`` decides it (default: from
    the rows); above order 4 ``multipole`` holds the members' order-N rows (N of them)."""
    from ..kernels import advance as K      # Taichi: imported on first use

    par = np.ascontiguousarray(par, dtype=np.float64)
    y = np.ascontiguousarray(states, dtype=np.float64).reshape(-1, _S.NSTATE)
    member = np.ascontiguousarray(member, dtype=np.int32)
    out = np.zeros((len(y), len(layout.DIAG_FIELDS)))
    if len(y):
        runtime.ensure_init()
        if _order_n(order, multipole):
            for lo, hi in _blocks(len(y)):
                part = np.zeros((hi - lo, out.shape[1]))
                rows, scr, ints, floats = multipole.arguments(hi - lo)
                K.diagnostics_mp(par, y[lo:hi], member[lo:hi], part, rows, scr, ints, floats,
                                 layout.multipole.KERNEL_ORDER, False)
                out[lo:hi] = part
        else:
            K.diagnostics(par, y, member, out, int(order), has_odd(par) if odd is None else odd)
    return out


def _order_n(order, multipole):
    """Whether ``order`` needs the order-N kernels; then ``multipole`` must be given."""
    if int(order) <= layout.multipole.HAND_WRITTEN_MAX:
        return False
    if multipole is None or multipole.order != int(order):
        raise ValueError(f"order {order} needs the members' order-N integral rows "
                         "(multipole=, a multipole_tables.Multipole of that order)")
    return True


def _blocks(n):
    """[(lo, hi)] blocks of at most ORDER_N_BLOCK states."""
    return [(lo, min(lo + ORDER_N_BLOCK, n)) for lo in range(0, n, ORDER_N_BLOCK)]


__all__ = ["mutual_potential", "true_acceleration", "apsidal_rates", "diagnostics", "has_odd",
           "truncation_estimates"]
