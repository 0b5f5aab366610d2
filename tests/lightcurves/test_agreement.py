"""compare_magnitudes and binned_residuals against scipy and numpy, closed forms, bad input."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.stats import pearsonr

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.lightcurves import binned_residuals, compare_magnitudes

# Sums of a few hundred magnitudes of order 10 in float64: 1e-12 is rounding, not method.
TOL = 1e-12


def _series(seed: int = 0, n: int = 300) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    pred = rng.uniform(3.0, 10.0, n)
    return pred, 0.7 * pred + 4.0 + rng.normal(0.0, 0.8, n)


def test_statistics_match_scipy_and_numpy():
    pred, obs = _series()
    out = compare_magnitudes(pred, obs)
    res = obs - pred - np.mean(obs - pred)
    assert float(out.pearson_r) == pytest.approx(pearsonr(pred, obs)[0], abs=TOL)
    assert float(out.zero_point) == pytest.approx(np.mean(obs - pred), abs=TOL)
    assert float(out.rms_residual) == pytest.approx(np.std(obs - pred), abs=TOL)
    assert float(out.median_abs_residual) == pytest.approx(np.median(np.abs(res)), abs=TOL)
    np.testing.assert_allclose(out.residual.values, res, atol=TOL)
    for k in ("residual", "pearson_r", "zero_point", "rms_residual", "median_abs_residual"):
        assert out[k].attrs["units"] == "1" and out[k].attrs["long_name"]


def test_the_zero_point_is_the_rms_minimum():
    pred, obs = _series(1)
    out = compare_magnitudes(pred, obs)
    for dz in (-0.01, 0.01):
        shifted = obs - pred - float(out.zero_point) - dz
        assert np.sqrt(np.mean(shifted**2)) > float(out.rms_residual)


@settings(max_examples=40, deadline=None)
@given(st.floats(-20.0, 20.0), st.integers(0, 1000))
def test_a_constant_offset_changes_only_the_zero_point(offset, seed):
    pred, obs = _series(seed, 50)
    a, b = compare_magnitudes(pred, obs), compare_magnitudes(pred + offset, obs)
    assert float(b.zero_point) == pytest.approx(float(a.zero_point) - offset, abs=1e-9)
    for k in ("pearson_r", "rms_residual", "median_abs_residual"):
        assert float(b[k]) == pytest.approx(float(a[k]), abs=1e-9)


def test_rows_without_light_are_counted_not_dropped_silently():
    pred, obs = _series(2, 20)
    pred[[3, 7]] = np.inf
    out = compare_magnitudes(pred, obs)
    assert out.attrs == {"n_rows": 20, "n_compared": 18, "n_unpredicted": 2}
    assert np.isnan(out.residual.values[[3, 7]]).all()
    keep = np.isfinite(pred)
    assert float(out.pearson_r) == pytest.approx(pearsonr(pred[keep], obs[keep])[0], abs=TOL)


def test_dataarray_coordinates_are_kept():
    pred, obs = _series(3, 10)
    t = np.arange(10)
    da = xr.DataArray(
        obs, dims="time", coords={"phase_angle": ("time", t * 10.0, {"units": "degree"})}
    )
    out = compare_magnitudes(pred, da)
    assert out.phase_angle.attrs["units"] == "degree"
    assert out.residual.dims == ("time",)


@pytest.mark.parametrize(
    "pred, obs, match",
    [
        ([1.0, 2.0], [1.0, 2.0, 3.0], "predicted has 2 rows, observed 3"),
        ([1.0, 2.0, 3.0], [1.0, np.nan, 3.0], "observed magnitude of row 1 is nan"),
        ([1.0, np.inf, np.inf], [1.0, 2.0, 3.0], "1 rows with a finite prediction"),
        ([[1.0, 2.0, 3.0]], [[1.0, 2.0, 3.0]], "1-D series"),
    ],
)
def test_bad_input_is_named(pred, obs, match):
    with pytest.raises(ValidationError, match=match):
        compare_magnitudes(pred, obs)


def test_binned_residuals_match_numpy_percentiles():
    rng = np.random.default_rng(4)
    x = rng.uniform(0.0, 180.0, 500)
    r = rng.normal(0.0, 1.0, 500)
    r[::50] = np.nan
    edges = np.array([0.0, 60.0, 120.0, 180.0])
    out = binned_residuals(r, x, edges)
    for b in range(3):
        sel = r[(x >= edges[b]) & (x < edges[b + 1]) & np.isfinite(r)]
        assert int(out["count"][b]) == sel.size
        np.testing.assert_allclose(
            [float(out[k][b]) for k in ("median", "p16", "p84")],
            np.percentile(sel, [50, 16, 84]),
            atol=TOL,
        )
    np.testing.assert_allclose(out.bin.values, [30.0, 90.0, 150.0])
    with pytest.raises(ValidationError, match="increasing"):
        binned_residuals(r, x, [0.0, 0.0])
