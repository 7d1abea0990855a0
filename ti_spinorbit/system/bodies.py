"""Rigid bodies described by their mass and inertia integrals, at any order.

A body lives in its own principal-axis frame with the origin at its centre of mass
(docs/physics.md §2). What the mutual potential needs of it is

    T^{lmn} = ∫_B x^l y^m z^n dm      (kg m^{l+m+n}),   2 <= l + m + n <= order,

computed once here, never per step. Order 1 vanishes (centre of mass) and order 2 must be
diagonal (principal axes); every higher integral may be anything, so a lumpy body with odd
integrals plugs into the same kernels as an ellipsoid.

Orders (decisions)
------------------
* Every :class:`Body` has an ``order``, 4 <= order <= :data:`MAX_ORDER` (16), and answers
  :meth:`Body.integral` for every l + m + n <= order (a key it does not store is zero); beyond
  its order it refuses in one line, never a silent zero. The fixed order-4 row of the
  kernels (:meth:`Body.as_row`) is the same for every order, so raising the order of a body
  changes nothing at order <= 4.
* :func:`Ellipsoid` and :func:`Sphere` hold their closed form up to ``MAX_ORDER`` by default
  (164 non-zero integrals, a fraction of a millisecond), so a kernel of any order takes them
  without anyone asking; ``order=`` lowers it.
* Bodies computed from data (:meth:`Body.from_point_masses` here, and the polyhedra and
  composites of :mod:`ti_spinorbit.system.shapes`) default to :data:`DATA_ORDER` (8): their
  cost grows as C(order + 3, 3) integrals per point or facet (165 at order 8, 455 at 12,
  969 at 16: on two cores the integrals of a 3-million-facet shape model take about 3 s at
  order 8 and 19 s at order 12, the mesh checks about 5 s more, while the 2000 facets of the
  Didymos radar model take 0.02 s at order 12), and ``order=`` raises it.
* A hand-given integrals dict has the order of its highest key, at least 4, unless
  ``order=`` says more (or refuses keys beyond a smaller one).

Sources: uniform ellipsoid integrals, Tricarico 2008 eq. 19 / Hou et al. 2017 eq. 26
(docs/physics.md §2.2):
    T^{lmn} = 3 M a^l b^m c^n (l-1)!!(m-1)!!(n-1)!! / (l+m+n+3)!!   (all indices even), else 0.
"""

import math
import numbers
from dataclasses import dataclass, field
from typing import Dict, Optional, Tuple

import numpy as np

from .._validate import (MAX_DENSITY, MAX_LENGTH, MAX_MASS, MIN_DENSITY, MIN_LENGTH, MIN_MASS,
                         MIN_MOMENT_RATIO, require_count, require_finite, require_positive_scalar,
                         require_real, show, _as_floats)
from .. import display as _display
from ..units import plain_fields, to_plain
from . import integrals as _integrals
# the monomial orders of a body's row (Body.as_row), shared with the kernels
from ..layout import EXPONENTS_2, EXPONENTS_3, EXPONENTS_4, ROW_LENGTH

#: Highest order of a body's integrals: that of :mod:`ti_spinorbit.system.integrals` (969
#: integrals; the factorials in the polyhedron coefficients, up to 19!, are exact), which is
#: also the highest truncation order of the mutual potential the package evaluates.
MAX_ORDER = _integrals.MAX_ORDER
#: Order of the kernels' fixed parameter row (:meth:`Body.as_row`), and the lowest order a
#: body may have: the row needs every integral up to it.
ROW_ORDER = 4
#: Default order of bodies computed from data (point clouds, polyhedra, composites): module
#: docstring, "Orders".
DATA_ORDER = 8


def row_columns(select):
    """Offsets in :meth:`Body.as_row` of the integrals whose exponents (l, m, n) satisfy
    ``select`` (the mass at offset 0 is never included)."""
    cols, off = [], 1
    for group in (EXPONENTS_2, EXPONENTS_3, EXPONENTS_4):
        cols += [off + k for k, e in enumerate(group) if select(e)]
        off += len(group)
    return cols


def odd_columns(row_length=ROW_LENGTH):
    """Parameter-row columns of the integrals with an odd exponent, for both body rows (the
    primary's from 0, the secondary's from ``row_length``): any non-zero one makes a member
    need the kernels' odd terms."""
    cols = row_columns(lambda e: any(x % 2 for x in e))
    return cols + [row_length + c for c in cols]


def tensor_from_integrals(order, integral):
    """Full symmetric rank-``order`` moment tensor whose entry i..k is ``integral(l, m, n)``,
    (l, m, n) counting the indices equal to x, y and z."""
    tensor = np.zeros((3,) * order)
    for idx in np.ndindex(*tensor.shape):
        tensor[idx] = integral(idx.count(0), idx.count(1), idx.count(2))
    return tensor


def _double_factorial(n: int) -> int:
    return 1 if n <= 0 else n * _double_factorial(n - 2)


#: n!! for n = -1 .. 2 MAX_ORDER + 3 (the same integers, looked up: _DF[n + 1]).
_DF = [_double_factorial(n) for n in range(-1, 2 * 16 + 4)]


def _multi_index(exponents):
    """Indices (i, j, k, ...) into a symmetric tensor for a monomial x^l y^m z^n."""
    l, m, n = exponents
    return (0,) * l + (1,) * m + (2,) * n


def _degree_keys(degree):
    """The (l, m, n) with l + m + n == degree, in multi_indices order."""
    return _integrals.multi_indices(degree)[len(_integrals.multi_indices(degree - 1)):]


def _is_int(x):
    return isinstance(x, numbers.Integral) and not isinstance(x, (bool, np.bool_))


def check_order(order, what="order"):
    """A body's order as an int in [ROW_ORDER, MAX_ORDER] (4..16), or a one-line ValueError."""
    return require_count(what, order, ROW_ORDER, MAX_ORDER)


def _integral_key(key):
    """(l, m, n) as plain ints, or None when ``key`` is not three non-negative integers."""
    if type(key) is tuple and len(key) == 3 and all(type(i) is int and i >= 0 for i in key):
        return key
    if not isinstance(key, tuple) or len(key) != 3 or not all(_is_int(i) for i in key):
        return None
    key = tuple(int(i) for i in key)
    return key if min(key) >= 0 else None


@dataclass(frozen=True, repr=False)
class Body(_display.Readable):
    """A rigid body given by its mass and inertia integrals in its principal-axis frame.

    Parameters
    ----------
    mass : float or Quantity
        Mass in kg, in [1e-9, 1e35];
        a Quantity is converted (:mod:`ti_spinorbit.units`).
    integrals : dict
        ``{(l, m, n): T^{lmn}}`` for 2 <= l + m + n <= ``order``, SI units (kg m^{l+m+n}).
        Missing entries are zero (the body keeps a copy without the zero entries). Second-order
        off-diagonal terms must vanish: the frame is the principal-axis frame. The second
        moments T^200, T^020, T^002 must be >= 0. (A body collapsed onto a line has a zero
        principal moment: its potential is fine, but
        :class:`~ti_spinorbit.system.systems.BinarySystem` refuses it, since the spin equations
        divide by the moments.)
    bounding_radius : float or Quantity
        Radius (m) of a sphere about the centre of mass that contains the body; used for the
        collision test and the overlap check at start. In [1e-3, 1e10] m (``MIN_LENGTH``,
        ``MAX_LENGTH``) and no smaller than the integrals allow: a body inside a sphere of
        radius ρ has (T^200 + T^020 + T^002) <= mass ρ² and |T^lmn| <= mass ρ^(l+m+n).
    name : str
        Free text used in plots and saved files.
    order : int, optional
        Highest degree l + m + n the body holds, in [4, 16] (``ROW_ORDER``, ``MAX_ORDER``).
        Default: the highest degree among the keys of ``integrals``, at least 4. Keys beyond
        a given order are refused. After construction ``body.order`` is an int.

    Notes
    -----
    :meth:`integral` answers every l + m + n <= ``order`` and refuses beyond it;
    :meth:`integral_set` gives the whole set (mass and zeros included) in the form of
    :mod:`ti_spinorbit.system.integrals`. Constructors that move a shape into its principal
    frame (:meth:`from_point_masses`, :func:`~ti_spinorbit.system.shapes.Polyhedron`,
    :func:`~ti_spinorbit.system.shapes.Composite`) leave the map on the body: ``offset``
    (m, the centre of mass in the input frame) and ``rotation`` (input frame -> body frame),
    so that ``x_body = rotation @ (x_input - offset)``.

    See Also
    --------
    Sphere, Ellipsoid, Polyhedron, Composite : bodies with their integrals computed

    Examples
    --------
    A body given by its mass and second-order inertia integrals T^{lmn} (kg m^(l+m+n)):

    >>> body = tso.Body(1e12, {(2, 0, 0): 1e17, (0, 2, 0): 0.9e17, (0, 0, 2): 0.8e17},
    ...                 bounding_radius=600.0)
    >>> body.integral(2, 0, 0), body.integral(1, 1, 0)     # a key not stored is zero
    (1e+17, 0.0)
    """

    mass: float
    integrals: Dict[Tuple[int, int, int], float]
    bounding_radius: float
    name: str = "body"
    order: Optional[int] = None
    _row: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        plain_fields(self, mass="kg", bounding_radius="m")
        require_positive_scalar("mass", self.mass, MIN_MASS, MAX_MASS, "kg")
        require_positive_scalar("bounding_radius", self.bounding_radius, MIN_LENGTH, MAX_LENGTH, "m")
        if not isinstance(self.integrals, dict):
            raise TypeError(f"integrals must be a dict {{(l, m, n): T^lmn}} (got "
                            f"{type(self.integrals).__name__} {show(self.integrals)})")
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a string (got {show(self.name)})")
        order = None if self.order is None else check_order(self.order)
        top = order if order is not None else MAX_ORDER
        table = {}
        for key, value in self.integrals.items():
            lmn = _integral_key(key)
            if lmn is None or not 2 <= sum(lmn) <= MAX_ORDER:
                raise ValueError(f"integrals: key {key!r} is not (l, m, n) with l + m + n in "
                                 f"2..{top}")
            if sum(lmn) > top:
                raise ValueError(f"integrals: key {key!r} has degree {sum(lmn)}, above "
                                 f"order={order} (raise order or drop the key)")
            if type(value) is not float:
                require_real(f"integrals[{key}]", value)
            value = float(value)
            if not math.isfinite(value):
                require_finite(f"integrals[{key}]", value)
            if value != 0.0:
                table[lmn] = value
        if order is None:
            order = max([ROW_ORDER] + [sum(k) for k in table])
        object.__setattr__(self, "integrals", table)
        object.__setattr__(self, "order", order)
        trace = sum(self.integrals.get(k, 0.0) for k in EXPONENTS_2)
        if not trace > 0.0:
            raise ValueError(f"integrals: second-order trace must be > 0 (got {trace!r})")
        for k in ((1, 1, 0), (1, 0, 1), (0, 1, 1)):
            if abs(self.integrals.get(k, 0.0)) > 1e-12 * trace:
                raise ValueError(
                    f"integrals[{k}] = {self.integrals[k]!r}: the body frame must be its "
                    "principal-axis frame (off-diagonal second-order integrals must be 0); "
                    "Body.from_point_masses rotates a mass distribution into it")
        for k in EXPONENTS_2:
            if self.integrals.get(k, 0.0) < 0:
                raise ValueError(f"integrals[{k}] must be >= 0: a second moment ∫ x_i² dm "
                                 f"(got {self.integrals[k]!r})")
        # a body inside a sphere of radius ρ has ∫ r² dm <= M ρ² and |T^lmn| <= M ρ^(l+m+n)
        mass = float(self.mass)
        rms = math.sqrt(trace / mass)
        smallest = max([rms] + [(abs(v) / mass) ** (1.0 / sum(k))
                                for k, v in self.integrals.items() if v])
        if float(self.bounding_radius) < smallest * (1.0 - 1e-12):
            raise ValueError(
                f"bounding_radius must be >= {smallest:.6g} m, the smallest sphere the integrals "
                f"allow (RMS radius sqrt((T^200 + T^020 + T^002)/mass) = {rms:.6g} m, and "
                f"|T^lmn| <= mass radius^(l+m+n)) (got {float(self.bounding_radius):.6g})")
        row = [self.mass]
        for group in (EXPONENTS_2, EXPONENTS_3, EXPONENTS_4):
            row += [float(self.integrals.get(k, 0.0)) for k in group]
        object.__setattr__(self, "_row", np.array(row, dtype=np.float64))

    # ---- derived quantities -------------------------------------------------------------
    def integral(self, l: int, m: int, n: int) -> float:
        """T^{lmn} in SI units (kg m^{l+m+n}) for any l + m + n <= ``order``: the mass
        for (0, 0, 0), 0 for the first moments (the origin is the centre of mass) and for
        every entry not stored. Beyond the body's order: ValueError (one line, naming the
        body, the degree asked and the order), never a silent zero."""
        key = _integral_key((l, m, n))
        if key is None:
            raise ValueError(f"body {self.name!r}: T^lmn needs three non-negative integers "
                             f"(l, m, n) (got {show((l, m, n))})")
        degree = key[0] + key[1] + key[2]
        if degree > self.order:
            raise ValueError(f"body {self.name!r} holds its integrals up to order {self.order}: "
                             f"T^({key[0]}, {key[1]}, {key[2]}) of degree {degree} is beyond it "
                             f"(build the body with order >= {degree})")
        if degree == 0:
            return self.mass
        return float(self.integrals.get(key, 0.0))

    def integral_set(self, order=None) -> dict:
        """Every integral up to ``order`` (default: the body's order) as an integral set of
        :mod:`ti_spinorbit.system.integrals`: ``{(l, m, n): T}`` for every l + m + n <= order
        in :func:`~ti_spinorbit.system.integrals.multi_indices` order, the mass (0, 0, 0), the
        zero first moments and every zero included, floats in SI units. An order above the
        body's is refused as :meth:`integral` refuses it."""
        order = self.order if order is None else order
        if not _is_int(order) or not 0 <= order <= MAX_ORDER:
            raise ValueError(f"order must be an integer in [0, {MAX_ORDER}] (got {show(order)})")
        if order > self.order:
            self.integral(order, 0, 0)                     # the one-line refusal
        get = self.integrals.get
        out = {key: float(get(key, 0.0)) for key in _integrals.multi_indices(order)}
        out[(0, 0, 0)] = float(self.mass)
        return out

    @property
    def moments(self) -> np.ndarray:
        """Principal moments of inertia (A, B, C) about x, y, z, kg m^2."""
        t200, t020, t002 = (self.integral(*k) for k in EXPONENTS_2)
        return np.array([t020 + t002, t200 + t002, t200 + t020])

    @property
    def has_odd_integrals(self) -> bool:
        """True when any integral with an odd index is non-zero (no mirror symmetry), at any
        order the body holds."""
        return any(v != 0.0 and any(i % 2 for i in k) for k, v in self.integrals.items())

    def moment_tensor(self, order: int) -> np.ndarray:
        """Full symmetric moment tensor M^(k)_{i..} = ∫ x_i ... dm in the body frame (SI),
        k = 0 .. the body's order (3^k entries)."""
        if not _is_int(order) or not 0 <= order <= MAX_ORDER:
            raise ValueError(f"order must be an integer in 0..{self.order} (got {order!r})")
        if order == 0:
            return np.array(self.mass)
        if order == 1:
            return np.zeros(3)
        self.integral(order, 0, 0)                         # refuses beyond the body's order
        return tensor_from_integrals(order, self.integral)

    def as_row(self) -> np.ndarray:
        """Mass and integrals in the fixed order the kernels read (copy, SI units): orders 2
        to 4 whatever the body's order."""
        return self._row.copy()

    # ---- constructors for general bodies ------------------------------------------------
    @classmethod
    def from_point_masses(cls, points, masses, name="point cloud", bounding_radius=None,
                          order=DATA_ORDER):
        """A body made of point masses (m, kg; arrays or Quantities), shifted to its centre of mass and rotated into
        its principal axes (x = smallest moment, i.e. the long axis), with every integral up
        to ``order`` (4..16, default ``DATA_ORDER`` = 8). Integrals below 1e-13 of
        Σ m_i |r_i|^(l+m+n) (round-off of a symmetry) are set to exactly 0.

        Returns ``(body, rotation)``: ``rotation`` takes the input frame to the body frame;
        the body also carries it as ``body.rotation`` and the centre of mass in the input
        frame as ``body.offset`` (m): ``x_body = rotation @ (x_input - offset)``."""
        order = check_order(order)
        points = _as_floats("points", to_plain("points", points, "m"))
        masses = _as_floats("masses", to_plain("masses", masses, "kg"))
        if points.ndim != 2 or points.shape[1] != 3 or masses.shape != points.shape[:1]:
            raise ValueError("points must have shape (n, 3) and masses shape (n,)")
        require_finite("points", points)
        if points.size and np.abs(points).max() > MAX_LENGTH:
            raise ValueError(f"points must lie within {MAX_LENGTH:g} m of the origin (got a "
                             f"coordinate of {np.abs(points).max():g} m)")
        if np.any(masses <= 0) or not np.all(np.isfinite(masses)):
            raise ValueError("masses must all be finite and > 0")
        total = masses.sum()
        centre = (masses[:, None] * points).sum(0) / total
        p = points - centre
        second = np.einsum("n,ni,nj->ij", masses, p, p)
        inertia = np.trace(second) * np.eye(3) - second
        w, vecs = np.linalg.eigh(inertia)  # ascending moments: x long axis
        if np.linalg.det(vecs) < 0:
            vecs[:, 2] *= -1
        rotation = vecs.T
        q = p @ rotation.T
        integrals = {}
        for degree, group in ((2, EXPONENTS_2), (3, EXPONENTS_3), (4, EXPONENTS_4)):
            # integrals that vanish by symmetry come out as round-off: zero them so that a
            # symmetric cloud does not switch on the kernels' odd-order terms
            floor = 1e-13 * float(np.sum(masses * np.linalg.norm(q, axis=1) ** degree))
            for l, m, n in group:
                value = float(np.sum(masses * q[:, 0] ** l * q[:, 1] ** m * q[:, 2] ** n))
                integrals[(l, m, n)] = value if abs(value) > floor else 0.0
        if order > ROW_ORDER:
            more = _integrals.point_mass_integrals(q, masses, order)
            radii = np.linalg.norm(q, axis=1)
            for degree in range(ROW_ORDER + 1, order + 1):
                floor = 1e-13 * float(np.sum(masses * radii ** degree))
                for key in _degree_keys(degree):
                    value = float(more[key])
                    integrals[key] = value if abs(value) > floor else 0.0
        radius = float(np.max(np.linalg.norm(q, axis=1))) if bounding_radius is None else bounding_radius
        body = cls(float(total), integrals, radius, name, order)
        for attribute, value in (("offset", centre), ("rotation", rotation)):
            value = np.array(value, dtype=np.float64)
            value.setflags(write=False)                    # a copy the caller cannot change
            object.__setattr__(body, attribute, value)
        return body, rotation


def Ellipsoid(a, b, c, density=None, *, mass=None, name="ellipsoid", order=MAX_ORDER) -> Body:
    """Uniform triaxial ellipsoid with semi-axes a ≥ b ≥ c (m) along x, y, z.

    Give exactly one of ``density`` (kg m^-3, in [1, 1e5]: ``MIN_DENSITY``, ``MAX_DENSITY``)
    or ``mass`` (kg, in [1e-9, 1e35]). Each is a float or Quantity (semi-axes, density and
    mass alike: ``Ellipsoid(0.245 * u.km, ..., 2.6 * u.g / u.cm**3)``,
    :mod:`ti_spinorbit.units`). Semi-axes lie in [1e-3, 1e10] m (``MIN_LENGTH``,
    ``MAX_LENGTH``) and the body may not be a needle: (b² + c²)/(a² + b²) >= 1e-6 (its
    smallest principal moment over its largest). x is the long axis and z the short one (the
    spin axis of a principal-axis rotator). Every integral up to ``order`` (4..16, default
    ``MAX_ORDER`` = 16) is the closed form of the module docstring, the odd ones exactly 0.

    Examples
    --------
    Semi-axes a >= b >= c in metres (not diameters):

    >>> moon = tso.Ellipsoid(294, 196, 190, density=2618)
    >>> f"{moon.mass:.4g} kg"
    '1.201e+11 kg'
    >>> f"{moon.integral(2, 0, 0) / moon.mass:.1f} m²"     # a²/5
    '17287.2 m²'
    """
    a, b, c = (to_plain(label, value, "m") for label, value in (("a", a), ("b", b), ("c", c)))
    for label, value in (("a", a), ("b", b), ("c", c)):
        require_positive_scalar(label, value, MIN_LENGTH, MAX_LENGTH, "m")
    if not isinstance(name, str):
        raise TypeError(f"name must be a string (got {show(name)})")
    order = check_order(order)
    if not a >= b >= c:
        raise ValueError(f"semi-axes must satisfy a >= b >= c (got a={a}, b={b}, c={c})")
    a, b, c = float(a), float(b), float(c)
    if (b * b + c * c) < MIN_MOMENT_RATIO * (a * a + b * b):
        raise ValueError(f"semi-axes a={a:g}, b={b:g}, c={c:g} make a needle: (b² + c²)/(a² + b²) "
                         f"must be >= {MIN_MOMENT_RATIO:g} (its smallest principal moment over "
                         f"its largest)")
    volume = 4.0 / 3.0 * math.pi * a * b * c
    mass = _mass_from(volume, density, mass)
    integrals = {}
    for degree in range(2, order + 1, 2):
        for l in range(0, degree + 1, 2):
            for m in range(0, degree - l + 1, 2):
                n = degree - l - m
                integrals[(l, m, n)] = (
                    3.0 * mass * a**l * b**m * c**n
                    * _DF[l] * _DF[m] * _DF[n] / _DF[l + m + n + 4])   # (l-1)!! ... (l+m+n+3)!!
    body = Body(mass, integrals, float(a), name, order)
    object.__setattr__(body, "semi_axes", (float(a), float(b), float(c)))
    return body


def Sphere(radius, density=None, *, mass=None, name="sphere", order=MAX_ORDER) -> Body:
    """Uniform sphere of ``radius`` (m); give ``density`` (kg m^-3) or ``mass`` (kg); each a
    float or Quantity.

    Its exterior field is exactly that of a point mass; the integrals are kept anyway so the
    same kernels serve every body. ``radius`` in [1e-3, 1e10] m; density and mass bounds, and
    ``order``, as for :func:`Ellipsoid`.

    Examples
    --------
    >>> primary = tso.Sphere(600, density=1581)          # radius in m, density in kg/m³
    >>> f"{primary.mass:.4g} kg"
    '1.43e+12 kg'
    >>> primary.integral(2, 0, 0) == primary.integral(0, 0, 2)
    True
    """
    radius = to_plain("radius", radius, "m")
    require_positive_scalar("radius", radius, MIN_LENGTH, MAX_LENGTH, "m")
    return Ellipsoid(radius, radius, radius, density, mass=mass, name=name, order=order)


def _mass_from(volume, density, mass):
    if (density is None) == (mass is None):
        raise ValueError("give exactly one of density (kg/m^3) or mass (kg)")
    if mass is not None:
        return require_positive_scalar("mass", mass, MIN_MASS, MAX_MASS, "kg")
    density = require_positive_scalar("density", density, MIN_DENSITY, MAX_DENSITY, "kg/m^3")
    return require_positive_scalar("mass (density × volume)", density * volume, MIN_MASS, MAX_MASS,
                                   "kg")
