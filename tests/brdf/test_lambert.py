"""Tests of the Lambertian model."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr.brdf import lambert
from sbrdf_xr.errors import ValidationError

#: Gauss-Legendre quadrature of a constant times cos(theta) sin(theta) over the
#: hemisphere is exact to rounding: 1e-13 leaves room for summation error only.
TOL_QUAD = 1e-13

WL = np.array([450.0, 550.0, 650.0])
RHO = np.array([0.2, 0.5, 0.9])
Z = np.array([0.0, 0.0, 1.0])


def test_value_is_rho_over_pi():
    f = lambert.brdf(Z, [0.3, 0.1, 1.0], [-0.5, 0.2, 0.7], WL, rho=RHO)
    np.testing.assert_array_equal(f, RHO / np.pi)


def test_zero_when_unlit_or_unseen():
    lit_seen = lambert.brdf(Z, [0, 0, 1], [1, 0, 1e-12], WL, rho=RHO)
    assert np.all(lit_seen > 0)
    for s, o in (([1, 0, 0], [0, 0, 1]), ([0, 0, 1], [1, 0, -1e-12]), ([0, 0, -1], [0, 0, 1])):
        assert np.all(lambert.brdf(Z, s, o, WL, rho=RHO) == 0)


def test_hemispherical_quadrature_equals_rho():
    t, wt = np.polynomial.legendre.leggauss(40)
    th = 0.25 * np.pi * (t + 1)
    ph = np.pi * (t + 1)
    th, ph = np.meshgrid(th, ph, indexing="ij")
    w = (0.25 * np.pi * wt)[:, None] * (np.pi * wt)[None, :] * np.sin(th) * np.cos(th)
    o = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    f = lambert.brdf(Z, [0.4, 0.0, 0.9], o, WL, rho=RHO)
    np.testing.assert_allclose(np.einsum("ij,ijk->k", w, f), RHO, rtol=TOL_QUAD)
    np.testing.assert_array_equal(
        lambert.directional_hemispherical_reflectance([0.0, 45.0, 90.0], WL, rho=RHO),
        np.broadcast_to(RHO, (3, 3)),
    )


def test_shapes_dtype_and_grid():
    s = np.tile([0.1, 0.0, 1.0], (4, 1)).astype(np.float32)
    o = np.tile([0.0, 0.3, 1.0], (2, 1, 1)).astype(np.float32)
    f = lambert.brdf(np.float32([0, 0, 1]), s, o, WL, rho=RHO)
    assert f.shape == (2, 4, 3) and f.dtype == np.float32
    g = lambert.render_grid([0.0, 30.0, 95.0], [-10.0, 0.0], [0.0, 45.0], WL, rho=0.3)
    assert g.shape == (3, 2, 2, 3)
    assert np.all(g[:2] == pytest.approx(0.3 / np.pi)) and np.all(g[2] == 0)


@settings(max_examples=examples(100), deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=6, max_size=6).filter(
        lambda v: sum(x * x for x in v[:3]) > 1e-6 and sum(x * x for x in v[3:]) > 1e-6
    )
)
def test_property_finite_nonnegative(v):
    f = lambert.brdf(Z, v[:3], v[3:], WL, rho=RHO)
    assert np.all(np.isfinite(f)) and np.all(f >= 0)
    assert np.all((f > 0) == (v[2] > 0 and v[5] > 0))


@pytest.mark.parametrize(
    ("rho", "match"),
    [(-0.1, "rho"), (1.5, "rho"), ([0.1, np.nan, 0.2], "NaN"), ([0.1, 0.2], "shape")],
)
def test_validation(rho, match):
    with pytest.raises(ValidationError, match=match):
        lambert.check_params(WL, rho=rho)


def test_validation_wavelength_and_theta():
    with pytest.raises(ValidationError, match="wavelength"):
        lambert.check_params([-1.0, 500.0], rho=0.2)
    with pytest.raises(ValidationError, match="theta_i"):
        lambert.directional_hemispherical_reflectance(95.0, WL, rho=0.2)
