"""Tests of sbrdf_xr.brdf.robertson_sandford_fit: the least-squares fit of the R-S model."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.brdf import robertson_sandford as rs
from sbrdf_xr.brdf.robertson_sandford_fit import fit_robertson_sandford
from sbrdf_xr.errors import ValidationError

#: Parameter recovery: estimates must lie within this many standard uncertainties.
N_SIGMA = 4.0

WL = np.array([500.0, 1000.0, 4000.0])  # [nm]


def _synthetic(noise: float, seed: int = 7):
    truth = {
        "rho_D": np.array([0.05, 0.07, 0.10]),
        "epsilon": np.array([0.85, 0.80, 0.70]),
        "b": 0.12,
        "e": 0.12,
    }
    ti, dt, ph = np.meshgrid(
        [10.0, 25.0, 40.0, 55.0, 70.0], np.linspace(-30, 30, 10), [0.0, 10.0, 40.0], indexing="ij"
    )
    ti, dt, ph = ti.ravel(), dt.ravel(), ph.ravel()
    f = rs.brdf_angles(ti, dt, ph, WL, **truth)
    rng = np.random.default_rng(seed)
    y = f * np.exp(noise * rng.standard_normal(f.shape))
    return truth, ti, dt, ph, y


def test_fit_recovers_parameters_from_noisy_data():
    truth, ti, dt, ph, y = _synthetic(0.02)
    fit = fit_robertson_sandford(ti, dt, ph, WL, y, sigma=0.02)
    assert fit["success"]
    for name in ("rho_D", "epsilon", "b", "e"):
        err = np.abs(np.asarray(fit[name]) - truth[name])
        assert np.all(err <= N_SIGMA * np.asarray(fit["u_" + name])), name
    # stated tolerance: 2 % multiplicative noise on 150 geometries
    np.testing.assert_allclose(fit["rho_D"], truth["rho_D"], atol=0.005)
    np.testing.assert_allclose(fit["epsilon"], truth["epsilon"], atol=0.02)
    assert fit["b"] == pytest.approx(truth["b"], rel=0.1)
    assert fit["e"] == pytest.approx(truth["e"], rel=0.05)
    assert 0.7 < fit["chi2_reduced"] < 1.4


def test_fit_excludes_reference_points_and_scales_without_sigma():
    truth, ti, dt, ph, y = _synthetic(0.02, seed=3)
    ref = np.zeros(y.shape[0], dtype=bool)
    ref[::7] = True
    y = y.copy()
    y[ref] = 0.0  # reference points: measured as zero
    fit = fit_robertson_sandford(ti, dt, ph, WL, y, reference=ref)
    assert fit["e"] == pytest.approx(truth["e"], rel=0.05)
    np.testing.assert_allclose(fit["rho_D"], truth["rho_D"], atol=0.005)
    assert fit["chi2_reduced"] == pytest.approx(0.02**2, rel=0.3)  # estimates the noise


def test_fit_rejects_too_few_samples():
    _truth, ti, dt, ph, y = _synthetic(0.0)
    ref = np.ones(y.shape[0], dtype=bool)
    ref[:3] = False
    with pytest.raises(ValidationError, match="usable"):
        fit_robertson_sandford(ti, dt, ph, WL, y, reference=ref)
    with pytest.raises(ValidationError, match="sbrdf"):
        fit_robertson_sandford(ti, dt, ph, WL, y[:, :2])
