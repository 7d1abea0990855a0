"""The host-side model objects (ti_spinorbit/model/models.py): one decision for "auto", the
conversions and the shadow direction of each model, and that Ensemble uses them."""

import numpy as np
import pytest

from ti_spinorbit.model import models
from ti_spinorbit.engine.ensemble import Ensemble


@pytest.fixture(scope="module")
def rows(vh):
    par = np.stack([vh.parameter_row()] * 2)
    y0 = np.stack([vh.initial_state(0.0, w) for w in (0.9, 1.3)])
    return par, y0


def test_auto_takes_planar_only_when_every_member_qualifies(rows):
    par, y0 = rows
    assert models.choose("auto", par, y0) is models.PLANAR
    assert models.choose("3d", par, y0) is models.SPATIAL
    tilted = y0.copy()
    tilted[1, 2] = 1e-3                       # R_z: out of the plane
    assert models.choose("auto", par, tilted) is models.SPATIAL
    with pytest.raises(ValueError, match=r"model='planar' needs planar starts .* members \[1\]"):
        models.choose("planar", par, tilted)
    with pytest.raises(ValueError, match=r"^model must be 'auto', 'planar' or '3d' \(got 'xy'\)"):
        models.choose("xy", par, y0)


@pytest.mark.parametrize("model", [models.PLANAR, models.SPATIAL], ids=lambda m: m.name)
def test_state_round_trip_and_record_width(rows, model):
    par, y0 = rows
    q = model.to_kernel_state(y0)
    assert q.shape == (2, model.nstate) and model.record_width == model.nstate + 1
    assert np.allclose(model.to_spatial(q), y0, rtol=0, atol=1e-15)
    u = model.shadow_direction()
    assert u.shape == (model.nstate,) and np.linalg.norm(u) == pytest.approx(1.0, abs=1e-15)


def test_spatial_shadow_direction_matches_the_kernel_layout():
    from ti_spinorbit.kernels import eom

    u = np.zeros(eom.NSTATE)
    u[[eom.Y_R, eom.Y_R + 1, eom.Y_V, eom.Y_V + 1, eom.Y_W2 + 2]] = 1.0
    assert np.array_equal(models.SPATIAL.shadow_direction(), u / np.linalg.norm(u))


def test_ensemble_uses_the_model_object(rows):
    par, y0 = rows
    ens = Ensemble(par, y0)
    assert ens.equations is models.PLANAR and ens.model == "planar"
    assert ens.y.shape == (2, 10)
    assert Ensemble(par, y0, model="3d").equations is models.SPATIAL
