"""Bodies of any shape: uniform polyhedra (shape models, from arrays or files) and composites.

Each constructor returns a :class:`~ti_spinorbit.system.bodies.Body`: its inertia integrals,
at every order up to ``order`` (default :data:`~ti_spinorbit.system.bodies.DATA_ORDER`, 8),
about its centre of mass in its principal axes (docs/physics.md §2.6-§2.8).

Frames (decisions)
------------------
A shape is given in a frame of its own (the *shape frame*: that of the shape model's file,
or of the composite's parts). The body is moved to its centre of mass and turned to its
principal axes, ordered as :func:`~ti_spinorbit.system.integrals.principal_frame` orders
them (x the long axis: T^200 >= T^020 >= T^002; z the short one, the spin axis of a
principal-axis rotator; right-handed, each of the first two axes with its largest component
positive). The map stays on the body:

* ``body.offset``: the centre of mass in the shape frame, m, shape (3,);
* ``body.rotation``: the rotation from the shape frame to the body frame, shape (3, 3), whose
  rows are the body axes written in the shape frame;

so that a point or direction of the shape model maps as

    x_body = body.rotation @ (x_shape - body.offset),      v_body = body.rotation @ v_shape,

and back as x_shape = body.rotation.T @ x_body + body.offset. For instance the shape
model's own z axis (often its spin pole) is ``body.rotation[:, 2]`` in the body frame, and
a surface point of the model in the body frame is ``body.rotation @ (vertex - body.offset)``.

Round-off
---------
The integrals odd in x_i that a mirror plane x_i -> -x_i makes zero come out as round-off.
When every integral odd in x_i is below :data:`ROUND_OFF` (1e-12) of mass ×
bounding_radius^(l+m+n), a bound of every integral of that degree, the body has that mirror
plane and they are all set to exactly 0, so that a symmetric shape does not switch on the
kernels' odd terms (and may use the planar model); otherwise all of them are kept as
computed, however small. The first moments and the off-diagonal second moments, zero by
construction, are dropped.

Composites
----------
A :class:`Part` is a body placed in the composite's frame: ``x_composite = rotation @ x_part
+ offset`` (``rotation`` None: the identity), with a ``weight`` that multiplies its mass and
every integral (default 1). The parts' integrals are rotated and shifted exactly
(:func:`~ti_spinorbit.system.integrals.rotate_integrals`,
:func:`~ti_spinorbit.system.integrals.shift_integrals`), summed, and the sum moved to its
centre of mass and principal axes as above. Parts may overlap: their densities add. So a
denser core inside a mantle is the mantle's full shape at the mantle's density plus the core's
shape at the density *excess* ρ_core − ρ_mantle; a lighter core (or a void) is the core's
shape at the density deficit ρ_mantle − ρ_core with ``weight=-1``. :meth:`Part.in_shape_frame`
places a body where its shape model put it (several shape files in one frame).
"""

import math
import os
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Optional

import numpy as np

from .._validate import MAX_LENGTH, require_real, show, _as_floats
from . import integrals as _integrals
from . import shapefiles as _shapefiles
from .bodies import DATA_ORDER, Body, _mass_from, check_order
from ..units import plain_fields, to_plain

__all__ = ["Polyhedron", "read_shape", "Part", "Composite", "PACKAGED", "packaged_shape",
           "ROUND_OFF", "Source"]

#: A mirror plane is recognised when every integral odd in its axis is below this fraction of
#: mass × bounding_radius^(l+m+n) (module docstring, "Round-off"). The integrals of a closed
#: mesh carry a rounding error of about 1e-15 of that bound (tests/test_polyhedron.py), so
#: this keeps three orders of magnitude of margin, while no physical asymmetry this small
#: would change a trajectory.
ROUND_OFF = 1e-12

#: The shape models packaged with ti_spinorbit (``ti_spinorbit/data/shapes/README.md``), by
#: the name a system file gives as ``"packaged"``: a function returning (vertices m, faces).
PACKAGED = MappingProxyType({"didymos_radar": _shapefiles.didymos_radar_mesh})


def _check_name(name):
    if not isinstance(name, str):
        raise TypeError(f"name must be a string (got {show(name)})")
    return name


def _clean(T, mass, radius):
    """The principal-frame integral set T as Body integrals: degrees 0 and 1 and the
    off-diagonal second moments dropped; for each axis i, when every integral odd in x_i is
    below ROUND_OFF of mass radius^(l+m+n) (a mirror plane x_i -> -x_i), those integrals are
    zeroed. An integral is never zeroed alone: a small but real one of an asymmetric body
    stays as computed."""
    bound = {n: ROUND_OFF * mass * radius ** n for n in range(max(map(sum, T)) + 1)}
    mirror = [all(abs(float(v)) <= bound[sum(k)] for k, v in T.items() if k[i] % 2)
              for i in range(3)]
    out = {}
    for key, value in T.items():
        degree = sum(key)
        if degree < 2 or (degree == 2 and max(key) < 2):
            continue
        if any(key[i] % 2 and mirror[i] for i in range(3)):
            continue
        if float(value) != 0.0:
            out[key] = float(value)
    return out


def _frozen(array):
    array = np.array(array, dtype=np.float64)
    array.setflags(write=False)
    return array


def _principal_body(T, mass, radius_about, name, order, origin):
    """A Body from an integral set about the point ``origin`` (m, shape frame) with the
    shape frame's axes: its centre of mass and principal axes (integrals.principal_frame),
    ``radius_about(offset)`` its bounding radius (``offset`` from ``origin``); offset (from
    the shape frame's origin) and rotation set on the body, read-only."""
    Tp, offset, rotation = _integrals.principal_frame(T)
    radius = float(radius_about(offset))
    body = Body(float(mass), _clean(Tp, float(mass), radius), radius, name, order)
    object.__setattr__(body, "offset", _frozen(offset + origin))
    object.__setattr__(body, "rotation", _frozen(rotation))
    return body


def _mesh_arrays(vertices, faces, name):
    v = _as_floats("vertices", vertices)
    if v.ndim != 2 or v.shape[-1:] != (3,):
        raise ValueError(f"vertices must be an array of shape (V, 3), m (got shape {v.shape})")
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1:] != (3,) or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be an integer array of shape (F, 3) of 0-based vertex "
                         f"indices (got shape {f.shape}, dtype {f.dtype})")
    try:
        _shapefiles.check_mesh(v, f)
    except ValueError as exc:
        raise ValueError(f"polyhedron {name!r}: {exc}") from None
    if np.abs(v).max() > MAX_LENGTH:
        raise ValueError(f"vertices must lie within {MAX_LENGTH:g} m of the origin (got a "
                         f"coordinate of {np.abs(v).max():g} m)")
    return v, f.astype(np.int64, copy=False)


def _centroid(v, f):
    """Volume (m³) and centre of volume (m) of a closed mesh: the moments of orders 0 and 1
    about the facet corners' mean."""
    counts = np.bincount(f.ravel(), minlength=len(v)).astype(np.float64)
    mean = counts @ v / counts.sum()
    T1 = _integrals.polyhedron_integrals(v - mean, f, 1, 1.0)
    volume = float(T1[(0, 0, 0)])
    return volume, mean + np.array([T1[(1, 0, 0)], T1[(0, 1, 0)], T1[(0, 0, 1)]]) / volume


def Polyhedron(vertices, faces, *, density=None, mass=None, name="polyhedron",
               order=DATA_ORDER) -> Body:
    """A uniform polyhedron bounded by a closed triangle mesh (a shape model), as a Body.

    Parameters
    ----------
    vertices : array_like or Quantity, shape (V, 3)
        Vertex coordinates in the shape frame, m (:func:`read_shape` reads a file in km or m).
    faces : array_like of int, shape (F, 3)
        0-based vertex indices of the triangles, each wound counter-clockwise seen from
        outside. The mesh must be closed, consistently wound, outward and without
        degenerate facets (:func:`~ti_spinorbit.system.shapefiles.check_mesh`: a one-line
        ValueError says what is wrong and where, facet and vertex indices).
    density : float or Quantity, optional
        kg m^-3, in [1, 1e5]; give exactly one of ``density`` and ``mass``.
    mass : float or Quantity, optional
        kg, in [1e-9, 1e35]; the density is then mass / volume.
    name : str
        Label.
    order : int
        Highest degree of the integrals, in [4, 16] (default 8; module docstring of
        :mod:`ti_spinorbit.system.bodies`, "Orders").

    Returns
    -------
    Body
        In its principal frame about its centre of mass, with ``offset`` (m) and ``rotation``
        (shape frame -> body frame; module docstring, "Frames"), ``volume`` (m³) and
        ``density`` (kg m^-3). Its bounding radius is the largest distance of a vertex from
        the centre of mass; its integrals are those of
        :func:`~ti_spinorbit.system.integrals.polyhedron_integrals` (signed tetrahedra:
        exact for any closed mesh, star-shaped or not; docs/physics.md §2.7).

    Examples
    --------
    A tetrahedron with 100 m edges along the axes, its facets wound outwards:

    >>> vertices = 100.0 * np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    >>> faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    >>> rock = tso.Polyhedron(vertices, faces, density=2000)
    >>> round(rock.volume)                                 # m³, 100³/6
    166667
    >>> rock.offset                                        # its centre of mass, m
    array([25., 25., 25.])
    """
    _check_name(name)
    order = check_order(order)
    density, mass = to_plain("density", density, "kg/m^3"), to_plain("mass", mass, "kg")
    v, f = _mesh_arrays(to_plain("vertices", vertices, "m"), faces, name)
    # integrate about the centre of mass itself (found at order 1 first): moving integrals
    # of degree n by a distance d costs up to ((d + size) / size)^n of their precision, so
    # neither the model's origin nor the shift to the centre of mass may come after them
    volume, centre = _centroid(v, f)
    mass = _mass_from(volume, density, mass)
    rho = float(density) if density is not None else mass / volume
    T = _integrals.polyhedron_integrals(v - centre, f, order, rho)
    used = v[np.unique(f)] - centre

    def radius(offset):
        return np.sqrt(np.einsum("ij,ij->i", used - offset, used - offset)).max()

    body = _principal_body(T, mass, radius, name, order, centre)
    object.__setattr__(body, "volume", float(volume))
    object.__setattr__(body, "density", rho)
    return body


class Source(dict):
    """A body's ``source`` (how a system file names its shape file): a dict that cannot be
    changed (the body would no longer be what it says), and that pickles (Dask sends
    systems to its workers)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("a body's source cannot be changed: read the shape again instead")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse
    __ior__ = _refuse

    def __reduce__(self):
        return (Source, (dict(self),))


def _set_source(body, source):
    object.__setattr__(body, "source", Source(source))
    return body


def read_shape(path, *, unit="km", density=None, mass=None, format=None, facets=None,
               name=None, order=DATA_ORDER) -> Body:
    """A uniform polyhedron read from a shape-model file (:func:`Polyhedron` of
    :func:`~ti_spinorbit.system.shapefiles.read_mesh`).

    Parameters
    ----------
    path : str or os.PathLike, or (vertices_path, facets_path)
        The file: OBJ, PDS/Gaskell vertex-facet or plate tables, Gaskell ICQ, or the GUBAS
        CSV pair (give both files as a tuple, or the vertex file with ``facets=``); other
        extensions through ``trimesh`` when it is installed.
    unit : {"km", "m"} or astropy unit
        Unit of the file's coordinates (default km, as in PDS and Gaskell models; GUBAS
        files are in m); ``u.km`` and ``u.m`` are accepted too.
    density, mass : float or Quantity
        Exactly one: kg m^-3 or kg.
    format : {"obj", "tab", "icq", "gubas"}, optional
        The format, when the extension does not tell it.
    facets : str or os.PathLike, optional
        The GUBAS facet file.
    name : str, optional
        Label; default the file's stem.
    order : int
        Highest degree of the integrals, 4..16 (default 8).

    Returns
    -------
    Body
        As :func:`Polyhedron` returns it, with ``source``: what a system file needs to read
        it again (``shape``, ``file`` and ``facets`` as absolute paths, ``unit``, ``format``
        and ``density`` or ``mass_kg``); :meth:`BinarySystem.describe` writes it.

    Raises
    ------
    ValueError
        One line: the file and line of unreadable content, the file and what is wrong with
        its mesh, or a bad parameter.

    Examples
    --------
    A shape-model file (here a tetrahedron written as OBJ, in km):

    >>> with open("tetra.obj", "w") as f:
    ...     _ = f.write("v 0 0 0\\nv 0.1 0 0\\nv 0 0.1 0\\nv 0 0 0.1\\n"
    ...                 "f 1 3 2\\nf 1 2 4\\nf 1 4 3\\nf 2 3 4\\n")
    >>> rock = tso.read_shape("tetra.obj", unit="km", density=2000)
    >>> round(rock.volume)                                 # m³
    166667
    """
    if isinstance(path, (tuple, list)):
        if len(path) != 2 or facets is not None:
            raise ValueError("a tuple path is the GUBAS pair (vertices_csv, facets_csv); give "
                             "facets= only with a single vertex file")
        path, facets = path
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file path (str or os.PathLike) or a pair of them (got "
                        f"{show(path)})")
    name = Path(path).stem if name is None else _check_name(name)
    order = check_order(order)
    density, mass = to_plain("density", density, "kg/m^3"), to_plain("mass", mass, "kg")
    unit = unit.to_string() if hasattr(unit, "to_string") else unit    # an astropy unit
    vertices, faces = _shapefiles.read_mesh(path, unit=unit, format=format, facets=facets)
    body = Polyhedron(vertices, faces, density=density, mass=mass, name=name, order=order)
    source = {"shape": "polyhedron", "file": os.path.abspath(os.fspath(path))}
    if facets is not None:
        source["facets"] = os.path.abspath(os.fspath(facets))
    source["unit"] = unit
    if format is not None:
        source["format"] = format
    source.update({"density": float(density)} if density is not None else
                  {"mass_kg": float(body.mass)})
    return _set_source(body, source)


def packaged_shape(model, *, density=None, mass=None, name=None, order=DATA_ORDER) -> Body:
    """One of the shape models packaged with ti_spinorbit (:data:`PACKAGED`: so far
    ``"didymos_radar"``, the radar model of (65803) Didymos, Naidu et al. 2020) as a
    :func:`Polyhedron`, with the ``source`` a system file names it by (``"packaged"``)."""
    if model not in PACKAGED:
        raise ValueError(f"unknown packaged shape {show(model)}; the packaged shapes are "
                         f"{', '.join(map(repr, PACKAGED))}")
    density, mass = to_plain("density", density, "kg/m^3"), to_plain("mass", mass, "kg")
    vertices, faces = PACKAGED[model]()
    body = Polyhedron(vertices, faces, density=density, mass=mass,
                      name=model if name is None else name, order=order)
    source = {"shape": "polyhedron", "packaged": model}
    source.update({"density": float(density)} if density is not None else
                  {"mass_kg": float(body.mass)})
    return _set_source(body, source)


# ---- composites -------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class Part:
    """A body placed in a composite's frame (:func:`Composite`).

    Parameters
    ----------
    body : Body
        The part, with its own density or mass (any constructor of the package).
    offset : array_like or Quantity, shape (3,)
        Where the part's origin (its centre of mass) sits in the composite frame, m.
    rotation : array_like, shape (3, 3), optional
        Rotation from the part's body frame to the composite frame (orthonormal, det +1):
        ``x_composite = rotation @ x_part + offset``. None: the identity.
    weight : float
        Multiplies the part's mass and every integral (default 1; -1 removes the part's
        shape: a void, or a core lighter than its mantle given by its density deficit).

    Examples
    --------
    >>> core = tso.Part(tso.Sphere(150, density=1500), offset=(50, 0, 0))   # m
    >>> core.weight
    1.0
    >>> void = tso.Part(tso.Sphere(50, density=2000), weight=-1.0)         # a hole
    """

    body: Body
    offset: tuple = (0.0, 0.0, 0.0)
    rotation: Optional[np.ndarray] = None
    weight: float = 1.0

    def __post_init__(self):
        if not isinstance(self.body, Body):
            raise TypeError(f"Part body must be a ti_spinorbit Body (got {show(self.body)})")
        plain_fields(self, offset="m")
        offset = _as_floats("Part offset", self.offset)
        if offset.shape != (3,) or not np.all(np.isfinite(offset)):
            raise ValueError(f"Part offset must be a finite vector of 3 lengths in m (got "
                             f"{show(self.offset)})")
        object.__setattr__(self, "offset", tuple(float(x) for x in offset))
        if self.rotation is not None:
            try:
                R = _integrals._check_rotation(self.rotation)
            except ValueError as exc:
                raise ValueError(f"Part rotation: {exc}") from None
            R = R.copy()
            R.setflags(write=False)
            object.__setattr__(self, "rotation", R)
        weight = require_real("Part weight", self.weight)
        if not math.isfinite(weight) or weight == 0.0:
            raise ValueError(f"Part weight must be a finite non-zero number (got "
                             f"{show(self.weight)})")
        object.__setattr__(self, "weight", weight)

    @classmethod
    def in_shape_frame(cls, body, weight=1.0):
        """The part placed where its shape frame puts it: ``offset = body.offset``,
        ``rotation = body.rotation.T`` (a :func:`Polyhedron`, :func:`read_shape` or
        :func:`Composite` body), so parts read from shape files in one frame keep their
        places."""
        if not hasattr(body, "rotation") or not hasattr(body, "offset"):
            raise ValueError(f"body {getattr(body, 'name', body)!r} has no shape frame "
                             "(offset and rotation): place it with Part(body, offset, rotation)")
        return cls(body, tuple(body.offset), np.asarray(body.rotation).T, weight)


def Composite(parts, *, name="composite", order=None) -> Body:
    """A body made of parts (module docstring, "Composites"), each a :class:`Part` (or a
    Body, placed at the origin unrotated).

    The parts' integrals up to ``order`` are rotated and shifted into the composite frame
    exactly, weighted and summed; the sum is moved to its centre of mass and principal axes,
    with ``offset`` and ``rotation`` (composite frame -> body frame) kept on the body, and
    ``parts`` (the tuple of Parts). The bounding radius is the largest distance from the
    centre of mass to a part's centre plus that part's bounding radius (over the parts of
    positive weight).

    Parameters
    ----------
    parts : sequence of Part or Body
        At least one; the total mass must be positive.
    name : str
    order : int, optional
        4..16; default the lowest order among the parts (the composite can hold no more);
        an order above a part's is refused naming the part.

    Returns
    -------
    Body

    Examples
    --------
    A mantle with a denser core off its centre (the core's excess density, 1500 kg/m³ above the
    mantle's):

    >>> cored = tso.Composite([tso.Ellipsoid(400, 390, 380, density=2000),
    ...                        tso.Part(tso.Sphere(150, density=1500), offset=(50, 0, 0))])
    >>> f"{cored.mass:.4g} kg"
    '5.178e+11 kg'
    """
    _check_name(name)
    if isinstance(parts, (Part, Body, str, bytes)) or not hasattr(parts, "__iter__"):
        raise TypeError(f"parts must be a sequence of Part or Body (got {show(parts)})")
    given = list(parts)
    if not given:
        raise ValueError("parts must hold at least one Part")
    for k, p in enumerate(given):
        if not isinstance(p, (Part, Body)):
            raise TypeError(f"parts[{k}] must be a Part or a Body (got {show(p)})")
    placed = tuple(p if isinstance(p, Part) else Part(p) for p in given)
    lowest = min(p.body.order for p in placed)
    order = lowest if order is None else check_order(order)
    for k, p in enumerate(placed):
        if p.body.order < order:
            raise ValueError(f"order={order} is above the order {p.body.order} of parts[{k}] "
                             f"({p.body.name!r}): build that part with order >= {order}, or "
                             f"give a lower order")
    mass = sum(p.weight * float(p.body.mass) for p in placed)
    if not mass > 0:
        raise ValueError(f"the parts' total mass (weights included) must be > 0 (got "
                         f"{mass:.6g} kg)")
    # each part is about its own centre of mass, so the composite's is the weighted mean of
    # the offsets; the parts are moved to it directly (a detour through the composite
    # frame's origin would cost precision: see Polyhedron)
    centre = sum(p.weight * float(p.body.mass) * np.asarray(p.offset) for p in placed) / mass
    total = None
    for p in placed:
        T = p.body.integral_set(order)
        if p.rotation is not None:
            T = _integrals.rotate_integrals(T, p.rotation)
        d = np.asarray(p.offset) - centre
        if np.any(d != 0.0):
            T = _integrals.shift_integrals(T, d)
        vec = np.array(list(T.values())) * p.weight
        total = vec if total is None else total + vec
    T = dict(zip(_integrals.multi_indices(order), total))

    def radius(offset):
        return max(np.linalg.norm(np.asarray(p.offset) - centre - offset) + p.body.bounding_radius
                   for p in placed if p.weight > 0)

    body = _principal_body(T, mass, radius, name, order, centre)
    object.__setattr__(body, "parts", placed)
    return body
