"""The two models of the equations of motion, host side: one object each instead of
``if model == "planar"`` branches.

* ``SPATIAL`` ("3d"): the general 30-number state (``kernels/eom.py``);
* ``PLANAR`` ("planar"): the reduced 10-number state (``kernels/planar.py``), exact when both
  bodies are mirror-symmetric about their equators and the start is planar
  (:func:`ti_spinorbit.planar.qualifies`).

Each model knows its kernels (per method), whether members qualify for it, how to convert
parameter rows and states between the public 3-D layout and its kernel layout, and the
direction of the shadow trajectory's initial separation. :func:`choose` is the one decision
"auto" makes, used by ``Ensemble`` and by the Dask path alike. Importing this module does
not import Taichi.
"""

import numpy as np

from . import planar as _planar

#: Number of state components of the public (3-D) layout.
SPATIAL_NSTATE = 30


class Model:
    """Host side of one model of the equations of motion."""

    name = ""
    nstate = 0

    @property
    def record_width(self):
        """Columns of the kernels' event and sample records: time, then the state."""
        return 1 + self.nstate

    def kernels(self, method="cash-karp"):
        """The Taichi kernel set (``kernels.ensemble.kernels_for``); imports Taichi."""
        from .kernels import ensemble as K
        return K.kernels_for(self.name, method)

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
        # state offsets of kernels/eom.py (Y_R = 0, Y_V = 3, Y_W2 = 9), kept here so that
        # this module does not import Taichi
        u = np.zeros(SPATIAL_NSTATE)
        u[[0, 1, 3, 4, 9 + 2]] = 1.0
        return u / np.linalg.norm(u)


class Planar(Model):
    name = "planar"
    nstate = 10

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


def choose(model, par, y0):
    """The model object for ``model`` in {"auto", "planar", "3d"}: "auto" takes the planar
    model when every member qualifies (decided over the whole ensemble, never per chunk)."""
    if model not in ("auto", "planar", "3d"):
        raise ValueError(f"model must be 'auto', 'planar' or '3d' (got {model!r})")
    if model == "3d":
        return SPATIAL
    ok = PLANAR.qualifies(par, y0)
    if model == "planar" and not np.all(ok):
        bad = np.nonzero(~ok)[0]
        raise ValueError(f"model='planar' needs planar starts and bodies symmetric about their "
                         f"equators; members {bad[:10].tolist()} do not qualify (use "
                         "model='3d' or 'auto')")
    return PLANAR if np.all(ok) else SPATIAL
