"""Tests of the pure-numpy table kernels in sbrdf_xr.kernels.lut."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples
from scipy.interpolate import RegularGridInterpolator, make_smoothing_spline

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.kernels import lut as _lut

# Interpolation weights are computed in float64 from O(1) ratios; agreement with an
# independent implementation to 1e-12 relative is a few hundred ulps.
RTOL = 1e-12

TI = np.array([0.0, 10.0, 25.0, 40.0, 60.0, 90.0])
DT = np.array([-40.0, -20.0, -8.0, 0.0, 5.0, 15.0, 30.0])  # non-uniform, asymmetric
PH = np.array([0.0, 1.0, 3.0, 6.0])


def table(n_wl=3, seed=0):
    return np.random.default_rng(seed).uniform(0.1, 2.0, (TI.size, DT.size, PH.size, n_wl))


def queries(n=500, seed=1):
    rng = np.random.default_rng(seed)
    return (rng.uniform(0, 90, n), rng.uniform(-40, 30, n), rng.uniform(0, 6, n))


def test_linear_matches_scipy_regular_grid_interpolator():
    v = table()
    ti, dt, ph = queries()
    ours = _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, "linear")
    ref = RegularGridInterpolator((TI, DT, PH), v, method="linear")(np.stack([ti, dt, ph], -1))
    np.testing.assert_allclose(ours, ref, rtol=RTOL)


def test_nearest_matches_scipy_nearest_away_from_ties():
    v = table()
    ti, dt, ph = queries()
    ours = _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, "nearest")
    ref = RegularGridInterpolator((TI, DT, PH), v, method="nearest")(np.stack([ti, dt, ph], -1))
    np.testing.assert_array_equal(ours, ref)


@pytest.mark.parametrize("method", ["nearest", "linear", "cubic"])
def test_nodes_are_reproduced_exactly(method):
    v = table()
    g = np.meshgrid(TI, DT, PH, indexing="ij")
    out = _lut.lookup_kernel(v, TI, DT, PH, *g, method)
    np.testing.assert_allclose(out, v, rtol=RTOL, atol=0)


def test_cubic_is_exact_for_cubic_polynomials_on_nonuniform_grids():
    def poly(t, d, p):
        return 5 + 1e-6 * (t**3) + 1e-5 * (d**3 + 40**3) + 0.01 * p**3 + 1e-4 * t * d * p

    g = np.meshgrid(TI, DT, PH, indexing="ij")
    v = poly(*g)[..., None]
    ti, dt, ph = queries()
    out = _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, "cubic")[..., 0]
    np.testing.assert_allclose(out, poly(ti, dt, ph), rtol=1e-10)
    # ... whereas linear is not (the test can fail).
    lin = _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, "linear")[..., 0]
    assert np.max(np.abs(lin / poly(ti, dt, ph) - 1)) > 1e-3


def test_out_of_range_policy():
    v = table()
    # Beyond the delta_theta extent or above phi_max: zero.
    out = _lut.lookup_kernel(v, TI, DT, PH, [30, 30, 30], [-40.5, 30.5, 0.0], [0, 0, 6.5], "linear")
    np.testing.assert_array_equal(out, 0.0)
    # theta_i beyond 90 (or below 0) clamps to the edge rows.
    a = _lut.lookup_kernel(v, TI, DT, PH, [95.0, -3.0], [5.0, 5.0], [1.0, 1.0], "linear")
    np.testing.assert_allclose(a, v[[-1, 0], 4, 1], rtol=RTOL)
    # Rounding just past an edge still counts as on it.
    e = _lut.lookup_kernel(v, TI, DT, PH, [40.0], [30.0 + 1e-12], [0.0], "linear")
    np.testing.assert_allclose(e, v[3:4, -1, 0], rtol=RTOL)


def test_unknown_method_is_rejected():
    with pytest.raises(ValidationError, match="allowed: nearest, linear, cubic"):
        _lut.lookup_kernel(table(), TI, DT, PH, 1.0, 0.0, 0.0, "spline")


def test_float32_table_gives_float32_spectra():
    v = table().astype(np.float32)
    out = _lut.lookup_kernel(v, TI, DT, PH, *queries(10), "linear")
    assert out.dtype == np.float32


def test_weighted_lookup_matrix_sums_weighted_spectra():
    v = table()
    ti, dt, ph = queries(50)
    w = np.random.default_rng(3).uniform(0, 1, 50)
    m = _lut.lookup_matrix(TI, DT, PH, ti, dt, ph, "linear", weights=w)
    total = np.asarray(m.sum(axis=0)) @ v.reshape(-1, v.shape[-1])
    direct = (w[:, None] * _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, "linear")).sum(0)
    np.testing.assert_allclose(total.ravel(), direct, rtol=1e-12)


@settings(max_examples=examples(200), deadline=None)
@given(
    ti=st.floats(-10, 100),
    dt=st.floats(-60, 50),
    ph=st.floats(0, 10),
    method=st.sampled_from(["nearest", "linear", "cubic"]),
)
def test_lookup_is_finite_nonnegative_and_bounded(ti, dt, ph, method):
    v = table()
    out = _lut.lookup_kernel(v, TI, DT, PH, ti, dt, ph, method)
    assert np.all(np.isfinite(out)) and np.all(out >= 0)
    if method != "cubic":  # convex combinations stay within the table's range
        assert np.all(out <= v.max() * (1 + 1e-12))


# --------------------------------------------------------------- splines


def test_smoothing_spline_matches_scipy_make_smoothing_spline():
    rng = np.random.default_rng(0)
    x = np.array([10.0, 25.0, 40.0, 55.0, 70.0, 80.0])
    y = rng.uniform(0, 1, (x.size, 4))
    xo = np.linspace(x[0], x[-1], 37)
    for lam in (0.0, 3.0, 500.0):
        e = _lut.smoothing_spline_matrix(x, xo, lam)
        ref = make_smoothing_spline(x, y, lam=lam, axis=0)(xo)
        np.testing.assert_allclose(e @ y, ref, rtol=1e-9, atol=1e-12)


def test_smoothing_spline_extrapolation_modes():
    x = np.array([10.0, 30.0, 50.0, 70.0])
    y = np.array([1.0, 2.0, 2.5, 2.2])
    xo = np.array([0.0, 5.0, 80.0, 90.0])
    cubic = _lut.smoothing_spline_matrix(x, xo, 10.0, "cubic") @ y
    lin = _lut.smoothing_spline_matrix(x, xo, 10.0, "linear") @ y
    const = _lut.smoothing_spline_matrix(x, xo, 10.0, "constant") @ y
    inside = _lut.smoothing_spline_matrix(x, x, 10.0) @ y
    np.testing.assert_allclose(const, inside[[0, 0, -1, -1]])
    # Linear extension: equal spacing gives equal steps.
    np.testing.assert_allclose(lin[1] - lin[0], (inside[0] - lin[0]) / 2)
    # The natural spline has zero curvature at the ends: cubic and linear
    # continuations agree to first order next to the end.
    near = _lut.smoothing_spline_matrix(x, [9.999], 10.0, "cubic") @ y
    near_lin = _lut.smoothing_spline_matrix(x, [9.999], 10.0, "linear") @ y
    assert near == pytest.approx(near_lin, abs=1e-8)
    assert not np.allclose(cubic, lin)


def test_two_sites_give_the_line_and_infinite_smoothing_gives_least_squares_line():
    e = _lut.smoothing_spline_matrix([10.0, 30.0], [0.0, 20.0, 40.0], 5.0, "linear")
    np.testing.assert_allclose(e @ np.array([1.0, 3.0]), [0.0, 2.0, 4.0])
    x = np.array([0.0, 10.0, 20.0, 30.0, 40.0])
    y = np.array([1.0, 3.0, 2.0, 5.0, 4.0])
    fit = _lut.smoothing_spline_matrix(x, x, 1e12) @ y
    np.testing.assert_allclose(fit, np.polyval(np.polyfit(x, y, 1), x), rtol=1e-6)


def test_csaps_default_lambda():
    assert _lut.csaps_default_lambda([10.0, 30.0, 50.0]) == pytest.approx(20.0**3 / 6)


@pytest.mark.parametrize("x", [[1.0], [2.0, 1.0], [1.0, 1.0, 2.0]])
def test_spline_sites_validated(x):
    with pytest.raises(ValidationError, match="strictly increasing"):
        _lut.smoothing_spline_matrix(x, [0.0], 1.0)


# ------------------------------------------------------------- quadrature


def test_hemispherical_reflectance_of_lambertian_table_is_albedo():
    """A table equal to rho/pi over the whole visible hemisphere integrates to rho."""
    rho = np.array([0.2, 0.9])
    ti = np.array([0.0, 30.0, 60.0, 89.0, 90.0])
    dt = np.array([-180.0, -100.0, -30.0, 0.0, 30.0, 90.0])
    ph = np.array([0.0, 30.0, 60.0, 90.0])
    v = np.broadcast_to(rho / np.pi, (ti.size, dt.size, ph.size, 2)).copy()
    out = _lut.hemispherical_reflectance_kernel(v, ti, dt, ph, ti)
    # The integrand is smooth on each <= 5 deg Gauss-Legendre interval: ~1e-13.
    np.testing.assert_allclose(out, np.broadcast_to(rho, out.shape), rtol=1e-11)


def test_hemispherical_reflectance_of_narrow_band_matches_closed_form():
    """f = c for |phi| <= phi0 and the full in-plane range: 2 c phi-integral closed form."""
    c, phi0 = 3.0, 2.0
    ti = np.array([20.0])
    dt = np.array([-110.0, 70.0])
    ph = np.array([0.0, phi0, phi0 + 1e-6])
    v = np.zeros((1, 2, 3, 1))
    v[:, :, :2] = c
    out = _lut.hemispherical_reflectance_kernel(v, ti, dt, ph, ti)[0, 0]
    p = np.radians(phi0)
    expected = 2 * c * (p / 2 + np.sin(2 * p) / 4) * 2.0  # int cos^2 phi * int cos t
    # The last, 1e-6-degree-wide interval ramps down linearly: its share is ~1e-8.
    assert out == pytest.approx(expected, rel=1e-6)


def test_empty_query_gives_empty_results():
    m = _lut.lookup_matrix(TI, DT, PH, np.array([]), np.array([]), np.array([]))
    assert m.shape == (0, TI.size * DT.size * PH.size)
    assert _lut.lookup_kernel(
        table(), TI, DT, PH, np.array([]), np.array([]), np.array([])
    ).shape == (0, 3)
