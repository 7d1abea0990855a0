"""The secondary's attitude in three dimensions: Euler angles in the orbit frame, pole tilt,
non-principal-axis rotation, and a per-member classification (docs/physics.md §6.9).

Every function takes scaled 3-D states (``(..., 30)``, the kernels' layout of docs/physics.md
§4.3; time series samples, section crossings or final states) and works on any leading shape.
Only directions and ratios of moments enter, so the scaled units do not matter.

The reference is the *orbit frame* of each state: radial x̂ = R/|R|, orbit normal
ẑ = R × V/|R × V| (V the relative velocity seen from the inertial frame), along-track
ŷ = ẑ × x̂. In a planar run the yaw angle is the paper's θ, the secondary's long axis from
the line of centres (docs/physics.md §6.2), and roll and pitch stay zero.

Classification (decision; thresholds are parameters with these defaults):

* ``tumbling``: at some sample the secondary's spin angular momentum is more than
  ``npa_angle`` (30°) from its short body axis, or its rotation is in the long-axis mode
  (dynamic moment of inertia below the intermediate moment): it no longer spins about its
  short axis;
* ``circulation``: not tumbling, and the yaw angle (unwrapped) sweeps 180° or more: the long
  axis turns past the along-track direction, so the secondary circulates relative to the line
  of centres;
* ``3-D libration``: neither, and the pole tilts more than ``tilt_angle`` (1°) from the orbit
  normal at some sample;
* ``planar libration``: neither, and the pole stays within ``tilt_angle`` of the normal.
"""

import numpy as np

from .._validate import require_scalar
from ..system.initial import ROW_SLICES, orbit_frame as _orbit_frame

#: Class labels, in the order of the integer codes :func:`classify` returns.
CLASSES = ("planar libration", "3-D libration", "circulation", "tumbling")
PLANAR_LIBRATION, LIBRATION_3D, CIRCULATION, TUMBLING = range(4)
#: Unit text of stored class codes (results' ``attitude_class``).
CLASS_UNIT = "code: " + ", ".join(f"{k} {c}" for k, c in enumerate(CLASSES)) + ", -1 none"
#: Default thresholds, degrees (module docstring).
TILT_ANGLE, NPA_ANGLE = 1.0, 30.0

_R, _V, _W2, _S = slice(0, 3), slice(3, 6), slice(9, 12), slice(12, 21)


def _unit(v):
    """v / |v|; NaN, silently, for a zero vector (a non-spinning body has no spin axis)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _split(y):
    y = np.asarray(y, dtype=np.float64)
    if y.shape[-1] != 30:
        raise ValueError(f"states must have 30 columns (the scaled 3-D state; got shape {y.shape})")
    S = y[..., _S].reshape(y.shape[:-1] + (3, 3))
    return y[..., _R], y[..., _V], y[..., _W2], S


def orbit_frame(y):
    """Orbit frame of each state in the primary's frame: matrix (..., 3, 3) whose columns
    are the radial, along-track and normal unit vectors (:func:`ti_spinorbit.system.initial.orbit_frame`)."""
    R, V, _, _ = _split(y)
    return _orbit_frame(R, V)


def relative_attitude(y):
    """Rotation (..., 3, 3) taking the secondary's body frame to the orbit frame."""
    _, _, _, S = _split(y)
    O = orbit_frame(y)
    return np.swapaxes(O, -1, -2) @ S


def euler_angles(y):
    """Roll, pitch, yaw (degrees, last axis) of the secondary relative to the orbit frame,
    with relative attitude = Rz(yaw) Ry(pitch) Rx(roll) (the order of
    :func:`ti_spinorbit.system.initial.tilted_start`). Yaw and roll in (−180°, 180°], pitch in
    [−90°, 90°]."""
    return _euler(relative_attitude(y))


def euler_angles_of_rows(rows):
    """:func:`euler_angles` of SI state rows (``initial.ROW_SLICES``: inertial R, V and the
    secondary's body -> inertial attitude), e.g. a time series' ``states``."""
    rows = np.asarray(rows, dtype=np.float64)
    A2 = rows[..., ROW_SLICES["secondary_attitude"]].reshape(rows.shape[:-1] + (3, 3))
    O = _orbit_frame(rows[..., ROW_SLICES["R"]], rows[..., ROW_SLICES["V"]])
    return _euler(np.swapaxes(O, -1, -2) @ A2)


def _euler(M):
    yaw = np.arctan2(M[..., 1, 0], M[..., 0, 0])
    pitch = -np.arcsin(np.clip(M[..., 2, 0], -1.0, 1.0))
    roll = np.arctan2(M[..., 2, 1], M[..., 2, 2])
    return np.degrees(np.stack([roll, pitch, yaw], axis=-1))


def _angle(sine, cosine):
    """Angle (degrees) from |a × b| and a · b: atan2 keeps full relative precision at every
    angle, where arccos of the dot product loses all digits below ~1e-8 rad (cos θ = 1 − θ²/2
    rounds to 1) and arcsin those near 90°."""
    return np.degrees(np.arctan2(sine, cosine))


def pole_tilt(y):
    """Angle (degrees) between the secondary's short body axis (its pole) and the orbit
    normal: atan2(|n × p|, n · p) with p the pole in the orbit frame (accurate near 0)."""
    p = relative_attitude(y)[..., :, 2]               # the pole's orbit-frame components
    return _angle(np.hypot(p[..., 0], p[..., 1]), p[..., 2])


def body_angular_momentum(y):
    """Unit vector (..., 3) of the secondary's spin angular momentum in its own body frame;
    (0, 0, ±1) for rotation about the short axis."""
    _, _, w2, S = _split(y)
    return _unit(np.einsum("...ji,...j->...i", S, w2))


def spin_axis_angle(y, system):
    """Angle (degrees) between the secondary's angular-velocity vector and the orbit normal:
    its spin axis obliquity to the mutual orbit (0° for the paper's planar states spinning
    forward)."""
    _, _, w2, S = _split(y)
    moments = system.secondary.moments
    body = np.einsum("...ji,...j->...i", S, w2) * (moments.max() / moments)   # ∝ body ω
    omega = np.einsum("...ij,...j->...i", S, body)
    normal = orbit_frame(y)[..., :, 2]
    u = _unit(omega)
    return _angle(np.linalg.norm(np.cross(u, normal), axis=-1), np.sum(u * normal, axis=-1))


def dynamic_inertia(y, system):
    """Dynamic moment of inertia L²/(2 E_rot) of the secondary's spin over its intermediate
    moment B: > 1 short-axis mode, < 1 long-axis mode (free-rotation classification, e.g.
    Kaasalainen 2001); C/B for rotation about the short axis."""
    A, B, C = system.secondary.moments
    l = body_angular_momentum(y)
    return 1.0 / (l[..., 0] ** 2 / A + l[..., 1] ** 2 / B + l[..., 2] ** 2 / C) / B


def _unwrapped_span(angles_deg, axis=-1):
    """Largest minus smallest of the unwrapped angle along ``axis`` (degrees)."""
    u = np.degrees(np.unwrap(np.radians(angles_deg), axis=axis))
    return np.nanmax(u, axis=axis) - np.nanmin(u, axis=axis)


def classify(samples, system, *, tilt_angle=TILT_ANGLE, npa_angle=NPA_ANGLE):
    """Per-member class codes (indices into :data:`CLASSES`) from time series.

    ``samples`` is (members, times, 30) scaled states (NaN rows, e.g. padding after a member
    stopped, are ignored), or a list of (times_k, 30) arrays. Thresholds in degrees (module
    docstring). Samples must resolve the yaw angle's changes (well under 180° apart: the
    spin is at most a few n, so 16 samples per orbit are plenty)."""
    tilt_angle = require_scalar("tilt_angle", tilt_angle, 0.0, 90.0, low_open=True, unit="degrees")
    npa_angle = require_scalar("npa_angle", npa_angle, 0.0, 90.0, low_open=True, unit="degrees")
    members = [np.asarray(s, dtype=np.float64) for s in samples]
    A, B, C = system.secondary.moments
    modes = C > B * (1.0 + 1e-9)     # a body with B = C has no long-axis mode to switch to
    out = np.empty(len(members), dtype=np.int8)
    for k, s in enumerate(members):
        s = s[np.all(np.isfinite(s), axis=-1)]
        if len(s) < 2:
            raise ValueError(f"samples of member {k} hold {len(s)} finite states; classify "
                             "needs at least 2")
        l = body_angular_momentum(s)
        off_axis = _angle(np.hypot(l[:, 0], l[:, 1]), np.abs(l[:, 2]))  # npa_angle (shadowed)
        long_axis_mode = modes and np.min(dynamic_inertia(s, system)) < 1.0
        if np.max(off_axis) > npa_angle or long_axis_mode:
            out[k] = TUMBLING
        elif _unwrapped_span(euler_angles(s)[:, 2]) >= 180.0:
            out[k] = CIRCULATION
        elif np.max(pole_tilt(s)) > tilt_angle:
            out[k] = LIBRATION_3D
        else:
            out[k] = PLANAR_LIBRATION
    return out


def npa_angle(y):
    """Angle (degrees) between the secondary's spin angular momentum and its short body axis
    (either direction): 0 for rotation about the short axis."""
    l = body_angular_momentum(y)
    return _angle(np.hypot(l[..., 0], l[..., 1]), np.abs(l[..., 2]))


def classify_crossings(synchronous, max_tilt, max_npa, *, tilt_angle=TILT_ANGLE,
                       npa_angle=NPA_ANGLE):
    """Class codes (:data:`CLASSES`) of section members, from once-per-orbit records.

    A section cannot follow the yaw angle between crossings, so the libration/circulation
    decision is taken from the spin classification instead: a member librates when its
    section is resonant in the synchronous (1:1) resonance (``synchronous``, boolean), else
    it circulates. Tumbling (``max_npa`` > ``npa_angle``, the largest angle of the spin
    angular momentum from the short axis over the records) comes first; a librating member
    is "3-D" when its pole tilts more than ``tilt_angle`` (``max_tilt``). Arrays broadcast;
    NaN inputs give −1 ("none")."""
    synchronous = np.asarray(synchronous, dtype=bool)
    max_tilt, max_npa = np.asarray(max_tilt, dtype=float), np.asarray(max_npa, dtype=float)
    out = np.where(max_npa > npa_angle, TUMBLING,
                   np.where(~synchronous, CIRCULATION,
                            np.where(max_tilt > tilt_angle, LIBRATION_3D, PLANAR_LIBRATION)))
    out = np.where(np.isfinite(max_tilt) & np.isfinite(max_npa), out, -1)
    return out.astype(np.int8)


def class_names(codes):
    """Labels of class codes (:data:`CLASSES`)."""
    return [CLASSES[int(c)] if c >= 0 else "" for c in np.ravel(codes)]
