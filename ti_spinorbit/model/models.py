"""The two models of the equations of motion, host side: one object each instead of
``if model == "planar"`` branches.

* ``SPATIAL`` ("3d"): the general 30-number state (``kernels/eom.py``);
* ``PLANAR`` ("planar"): the reduced 10-number state (``kernels/planar_eom.py``), exact when both
  bodies are mirror-symmetric about their equators and the start is planar
  (:func:`ti_spinorbit.model.planar.qualifies`).

Each model knows its kernels (per method), whether members qualify for it, how to convert
parameter rows and states between the public 3-D layout and its kernel layout, and the
direction of the shadow trajectory's initial separation. :func:`choose` is the one decision
"auto" makes, used by ``Ensemble`` and by the Dask path alike. Importing this module does
not import Taichi.
"""

import numpy as np

from . import planar as _planar
from ..layout import planar as _planar_layout, spatial as _spatial_layout

#: Number of state components of the public (3-D) layout.
SPATIAL_NSTATE = _spatial_layout.NSTATE
#: Seed of the full-space shadow direction (``indicator_space="full"``): fixed, so that runs
#: are reproducible and every member gets the same random components.
FULL_DIRECTION_SEED = 20151030
#: The two values of ``indicator_space`` (docs/physics.md §10.4).
INDICATOR_SPACES = ("planar", "full")


def check_indicator_space(value):
    """``value`` if it is "planar" or "full", else a one-line ValueError."""
    if not isinstance(value, str) or value not in INDICATOR_SPACES:
        raise ValueError(f"indicator_space must be 'planar' or 'full' (got {value!r})")
    return value


def hat(v):
    """Antisymmetric matrices hat(v) (..., 3, 3) with hat(v) @ x = v × x."""
    v = np.asarray(v, dtype=np.float64)
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1),
                     np.stack([-y, x, z], -1)], -2)


def full_components(seed=FULL_DIRECTION_SEED):
    """The random components of the full-space direction, one draw for all members: a dict
    of 3-vectors "R", "V", "w1", "w2" (state components) and "dS", "dS1" (the small-rotation
    vectors δ of the secondary's and the primary's attitude, body frames)."""
    draw = np.random.default_rng(seed).standard_normal((6, 3))
    return dict(zip(("R", "V", "w1", "w2", "dS", "dS1"), draw))


class Model:
    """Host side of one model of the equations of motion."""

    name = ""
    nstate = 0

    @property
    def record_width(self):
        """Columns of the kernels' event and sample records: time, then the state."""
        return 1 + self.nstate

    def kernels(self, method="cash-karp", perturbed=False, controller=None):
        """The Taichi kernel set (``kernels.advance.kernels_for``); imports Taichi."""
        from ..kernels import advance as K      # Taichi: imported on first use
        return K.kernels_for(self.name, method, perturbed, controller)

    def qualifies(self, par, y0):
        """Per member: can this model integrate it exactly?"""
        raise NotImplementedError

    def kernel_parameters(self, par):
        """Public parameter rows (``BinarySystem.parameter_row``) -> the kernels' rows."""
        raise NotImplementedError

    def to_kernel_state(self, y):
        """3-D scaled states (N, 30) -> this model's kernel states (a copy)."""
        raise NotImplementedError

    def to_spatial(self, y):
        """This model's kernel states -> 3-D scaled states (N, 30) (a copy)."""
        raise NotImplementedError

    def shadow_direction(self):
        """Unit direction (kernel layout) of the shadow trajectory's initial separation."""
        raise NotImplementedError

    def full_direction(self, y):
        """Per-member unit directions (N, nstate) spanning the whole state
        (``indicator_space="full"``); only the 3-D model has them."""
        raise ValueError(f"indicator_space='full' needs the 3-D model (the {self.name} model "
                         "cannot carry out-of-plane deviations): use model='auto' or '3d'")

    def __repr__(self):
        return f"<model {self.name!r}>"


class Spatial(Model):
    name = "3d"
    nstate = SPATIAL_NSTATE

    def qualifies(self, par, y0):
        return np.ones(len(np.atleast_2d(par)), dtype=bool)

    def kernel_parameters(self, par):
        return par

    def to_kernel_state(self, y):
        return np.array(y, dtype=np.float64)

    def to_spatial(self, y):
        return np.array(y, dtype=np.float64)

    def shadow_direction(self):
        """R_x, R_y, V_x, V_y and the secondary's spin w2_z, so a planar start stays planar
        (the same for every member: slot-invariant)."""
        L = _spatial_layout
        u = np.zeros(SPATIAL_NSTATE)
        u[[L.Y_R, L.Y_R + 1, L.Y_V, L.Y_V + 1, L.Y_W2 + 2]] = 1.0
        return u / np.linalg.norm(u)

    def full_direction(self, y):
        """Unit directions (N, 30) of the full-space shadow (docs/physics.md §10.4): the
        same seeded random components (:func:`full_components`) in R, V and both spins for
        every member, and each attitude A (S, S1) moved along the tangent A·hat(δ) of the
        small rotation A' = A·exp(hat(δ)) (to first order; AᵀA' − 1 = hat(δ) is
        antisymmetric), each row normalised in the scaled-state Euclidean norm. A member's
        direction depends on its own state only (slot-invariant)."""
        y = np.atleast_2d(np.asarray(y, dtype=np.float64))
        c = full_components()
        # state offsets of kernels/eom.py: Y_R 0, Y_V 3, Y_W1 6, Y_W2 9, Y_S 12, Y_S1 21
        d = np.zeros_like(y)
        d[:, 0:3], d[:, 3:6], d[:, 6:9], d[:, 9:12] = c["R"], c["V"], c["w1"], c["w2"]
        for lo, key in ((12, "dS"), (21, "dS1")):
            A = y[:, lo:lo + 9].reshape(-1, 3, 3)
            d[:, lo:lo + 9] = (A @ hat(c[key])).reshape(-1, 9)
        return d / np.linalg.norm(d, axis=1, keepdims=True)


class Planar(Model):
    name = "planar"
    nstate = _planar_layout.NSTATE

    def qualifies(self, par, y0):
        return _planar.qualifies(par, y0)

    def kernel_parameters(self, par):
        return _planar.parameter_rows(par)

    def to_kernel_state(self, y):
        return _planar.to_planar(y)

    def to_spatial(self, y):
        return _planar.to_spatial(y)

    def shadow_direction(self):
        return _planar.shadow_direction()


SPATIAL = Spatial()
PLANAR = Planar()
MODELS = {"planar": PLANAR, "3d": SPATIAL}
#: What an entry point's ``model=`` may ask for: "auto" (decided by :func:`choose`) or a model.
REQUESTS = ("auto", *MODELS)


def choose(model, par, y0, symmetric=None, spatial_forces=False):
    """The model object for ``model`` in {"auto", "planar", "3d"}: "auto" takes the planar
    model when every member qualifies (decided over the whole ensemble, never per chunk).
    ``symmetric`` (per member, optional) must hold too: at orders above 4 it says that no
    integral of a member's order-N row is odd in z (the parameter rows hold degrees 2..4
    only). ``spatial_forces`` (a perturbation the planar model does not carry: the Sun's
    tide out of the orbit plane) sends "auto" to the 3-D model and refuses "planar"."""
    if model not in REQUESTS:
        raise ValueError(f"model must be 'auto', 'planar' or '3d' (got {model!r})")
    if model == "3d":
        return SPATIAL
    if spatial_forces:
        if model == "planar":
            raise ValueError("model='planar' does not carry the Sun's tide out of the orbit "
                             "plane (SolarTide with inclination_deg not 0 or 180): use "
                             "model='auto' or '3d'")
        return SPATIAL
    ok = PLANAR.qualifies(par, y0)
    if symmetric is not None:
        ok = ok & np.asarray(symmetric, dtype=bool)
    if model == "planar" and not np.all(ok):
        bad = np.nonzero(~ok)[0]
        raise ValueError(f"model='planar' needs planar starts and bodies symmetric about their "
                         f"equators; members {bad[:10].tolist()} do not qualify (use "
                         "model='3d' or 'auto')")
    return PLANAR if np.all(ok) else SPATIAL
