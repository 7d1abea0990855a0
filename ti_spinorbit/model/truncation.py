"""How large the truncation error of the mutual potential is: choosing the order N before a run.

The mutual potential is a double series in the two bodies' inertia integrals, truncated at
total order N (docs/physics.md §3). Its error falls geometrically with N at a rate set by the
separation and the bodies' sizes, torques about two decades more slowly than forces (the
torque on a body involves one more power of its own size). :func:`truncation` tabulates, for a
system at a given separation, the relative error of the order-N force on the secondary and of
the torques on both bodies against a higher-order reference, so that a user can pick N: the
smallest N whose errors sit below what the study needs.

Decisions:

* **Reference.** The exact mutual potential of two arbitrary bodies has no closed form, so the
  error of order N is measured against order ``reference`` (default: the largest order asked
  for plus 4, at most the bodies' own order): e_N = |X_N − X_ref| / |X_ref|. This is the
  relative size of the orders N+1 … ref together, the "next orders", and it is what the error
  is when the series has converged by ``reference`` (the geometric fall makes the orders beyond
  it smaller still). For an order close to the reference the estimate is a lower bound; the
  table says which orders are within 2 of it.
* **Configurations.** The error depends on the attitudes: an aligned symmetric pair has no
  torque at all along an axis. The table takes the largest error over a fixed set of generic
  configurations at the given separation: the line of centres along the primary's x, y and z
  axes and along a diagonal, each with the secondary turned by four fixed generic rotations
  (fixed, so the table is reproducible). Force errors are relative to each configuration's
  force; torque errors are relative to the largest reference torque on that body over the
  configurations (a torque can vanish by symmetry in one attitude and not in the next, and
  its error relative to a vanishing torque says nothing). A body that feels no torque (a
  sphere) has torque errors of 0.
* **Separation.** Default: the pericentre distance a(1 − e) of the initial mutual orbit, the
  closest approach of the unperturbed orbit. The series converges only while the bodies'
  bounding spheres are apart, so a separation at or below the sum of the bounding radii is
  refused.
* **Formulation.** The host-side order-N expansion of :mod:`ti_spinorbit.multipole`
  (NumPy only), with the bodies' integrals from ``Body.integral``; it agrees with the kernels'
  order-4 terms to round-off (tests/test_multipole.py), so the table describes the kernels'
  truncation.
"""

from dataclasses import dataclass

import numpy as np

from .._validate import require_count, require_positive_scalar, show
from ..system.systems import G
from .. import multipole

#: Default orders of the table (the paper's is 4).
DEFAULT_ORDERS = (2, 4, 6, 8, 12)
#: Reference order beyond the largest order asked for, by default.
REFERENCE_MARGIN = 4
def _rotation(axis, angle_deg):
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.eye(3)
    m[i, i] = m[j, j] = c
    m[i, j], m[j, i] = -s, s
    return m


#: Directions of the line of centres (primary frame) and attitudes of the secondary
#: (secondary frame -> primary frame) the table takes its largest error over.
DIRECTIONS = tuple(d / np.linalg.norm(d) for d in
                   (np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]),
                    np.array([1.0, 1.0, 1.0])))
ATTITUDES = (np.eye(3), _rotation(2, 25.0) @ _rotation(0, 10.0),
             _rotation(2, 65.0) @ _rotation(1, 40.0), _rotation(0, 90.0) @ _rotation(2, 120.0))


@dataclass(frozen=True, repr=False)
class TruncationTable:
    """Relative truncation errors of the mutual potential against order (see the module).

    Attributes
    ----------
    orders : ndarray of int
        The truncation orders N.
    separation : float
        Distance between the centres of mass, m.
    reference : int
        Order the errors are measured against.
    force : ndarray
        Largest relative error of the force on the secondary, per order.
    torque_secondary, torque_primary : ndarray
        Largest error of the torque on each body about its centre of mass, relative to the
        largest reference torque on that body (0 for a body that feels none).
    system : str
        The system's name.

    Examples
    --------
    >>> table = tso.truncation(tso.catalog.system("1991 VH"), orders=(2, 4))
    >>> print(table)                                       # doctest: +ELLIPSIS
    truncation error of the mutual potential, 1991 VH at 3135 m (against order 8):
        N   force      torque (secondary)   torque (primary)
        2   ...
    """

    orders: np.ndarray
    separation: float
    reference: int
    force: np.ndarray
    torque_secondary: np.ndarray
    torque_primary: np.ndarray
    system: str = ""

    def order_for(self, force=None, torque=None) -> int:
        """The smallest tabulated order whose force error is below ``force`` and whose
        secondary-torque error is below ``torque`` (relative; None: no condition); None when no
        order of the table reaches them."""
        ok = np.ones(len(self.orders), bool)
        if force is not None:
            ok &= self.force <= force
        if torque is not None:
            ok &= self.torque_secondary <= torque
        return int(self.orders[ok][0]) if ok.any() else None

    def __repr__(self):
        lines = [f"truncation error of the mutual potential, {self.system or 'system'} at "
                 f"{self.separation:.6g} m (against order {self.reference}):",
                 "    N   force      torque (secondary)   torque (primary)"]
        for k, n in enumerate(self.orders):
            bound = "  (lower bound: near the reference)" \
                if self.reference - n <= 2 else ""
            lines.append(f"  {n:3d}   {self.force[k]:.2e}   {self.torque_secondary[k]:.2e}"
                         f"             {self.torque_primary[k]:.2e}{bound}")
        return "\n".join(lines)


def _integrals(body, order, label):
    body_order = body.order
    if body_order < order:
        raise ValueError(f"truncation: the {label} ({body.name!r}) holds integrals up to order "
                         f"{body_order}, and the reference order {order} needs them up to "
                         f"{order}; pass a smaller reference= or build the body with "
                         f"order={order}")
    return {tuple(int(x) for x in k): body.integral(*(int(x) for x in k))
            for k in multipole.multi_indices(order)}


def truncation(system, orders=DEFAULT_ORDERS, separation=None, *, reference=None):
    """Relative error of the truncated mutual force and torques against order, at one
    separation (module docstring: reference, configurations, separation).

    Parameters
    ----------
    system : BinarySystem
    orders : sequence of int
        Truncation orders N to tabulate, each in [0, 16].
    separation : float, optional
        Distance between the centres of mass, m (default: the pericentre a(1 − e)); must
        exceed the sum of the bounding radii, where the series stops converging.
    reference : int, optional
        Order the errors are measured against (default: max(orders) + 4, at most the bodies'
        own order, and above every order of the table).

    Returns
    -------
    TruncationTable

    Examples
    --------
    >>> table = tso.truncation(tso.catalog.system("1991 VH"), orders=(2, 4))
    >>> table.orders
    array([2, 4])
    >>> bool(table.force[1] < 1e-5)             # order 4 is well inside the force limit
    True
    """
    if isinstance(orders, (str, bytes)) or not hasattr(orders, "__iter__"):
        raise TypeError(f"orders must be a sequence of whole numbers (got {show(orders)})")
    orders = np.array(sorted({require_count("orders", n, 0, multipole.MAX_ORDER)
                              for n in orders}), dtype=int)
    if not len(orders):
        raise ValueError("orders must hold at least one order")
    primary, secondary = system.primary, system.secondary
    contact = primary.bounding_radius + secondary.bounding_radius
    if separation is None:
        separation = system.a * (1.0 - system.e)
    separation = require_positive_scalar("separation", separation, 0.0, 1e12, "m")
    if separation <= contact:
        raise ValueError(f"separation must exceed the sum of the bounding radii ({contact:.6g} m), "
                         f"where the series converges (got {separation:.6g} m)")
    available = min(primary.order, secondary.order,
                    multipole.MAX_ORDER)
    if reference is None:
        reference = min(int(orders[-1]) + REFERENCE_MARGIN, available)
    reference = require_count("reference", reference, 1, multipole.MAX_ORDER)
    if reference <= orders[-1]:
        raise ValueError(f"reference must exceed every order of the table (largest "
                         f"{orders[-1]}; got {reference}; the bodies hold integrals up to "
                         f"order {available})")
    TA = _integrals(primary, reference, "primary")
    TB = _integrals(secondary, reference, "secondary")
    force = np.zeros(len(orders))
    torque_b, torque_a = np.zeros(len(orders)), np.zeros(len(orders))
    refs = []
    for d in DIRECTIONS:
        for C in ATTITUDES:
            _, F, tb, ta = multipole.mutual_force_torque(TA, TB, separation * d, C, reference, G=G)
            refs.append((d, C, F, tb, ta))
    # a body that feels no torque (a sphere) has round-off torques only: 0 error, not noise
    orbital = separation * max(np.linalg.norm(r[2]) for r in refs)     # |R × F| scale, N m
    scale_b = max(np.linalg.norm(r[3]) for r in refs)
    scale_a = max(np.linalg.norm(r[4]) for r in refs)
    scale_b = scale_b if scale_b > 1e-12 * orbital else np.inf
    scale_a = scale_a if scale_a > 1e-12 * orbital else np.inf
    for d, C, F, tb, ta in refs:
        for k, n in enumerate(orders):
            _, Fn, tbn, tan = multipole.mutual_force_torque(TA, TB, separation * d, C, int(n), G=G)
            force[k] = max(force[k], np.linalg.norm(Fn - F) / np.linalg.norm(F))
            torque_b[k] = max(torque_b[k], np.linalg.norm(tbn - tb) / scale_b)
            torque_a[k] = max(torque_a[k], np.linalg.norm(tan - ta) / scale_a)
    return TruncationTable(orders, float(separation), int(reference), force, torque_b, torque_a,
                           getattr(system, "name", ""))


__all__ = ["truncation", "TruncationTable", "DEFAULT_ORDERS"]
