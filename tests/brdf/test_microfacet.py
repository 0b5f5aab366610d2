"""Tests of the GGX microfacet model (sbrdf_xr.brdf.microfacet)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr.brdf import microfacet as mf
from sbrdf_xr.brdf import optics
from sbrdf_xr.errors import ValidationError

#: Test quadrature (glint-centred Gauss-Legendre, smooth integrand) vs the module's
#: quadrature: both converge to ~1e-8 away from grazing; 1e-6 leaves margin.
TOL_QUAD = 1e-6
#: Reciprocity is exact in the formula, and f(s, o), f(o, s) are computed with the same
#: operations on swapped (commuting) operands: bit identical, measured; 1e-13 is ~500 ulp.
TOL_RECIPROCITY = 1e-13
#: Energy conservation: the F = 1 albedo may exceed 1 only by quadrature error.
TOL_ALBEDO = 1e-6

WL = np.array([450.0, 650.0, 900.0])
Z = np.array([0.0, 0.0, 1.0])
GLASS = {"roughness": 0.2, "n": 1.5, "k": 0.0, "rho_d": 0.0}


def _gl(n, a, b):
    t, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * t + 0.5 * (b + a), 0.5 * (b - a) * w


def glint_nodes(theta_i, alpha, n_phi=128, n_x=128):
    """Directions o and weights w: sum w f(o) ~ int f cos(theta_r) dOmega_r (GGX-centred).

    Half-vector polar angle theta_h up to the horizon limit for each azimuth, split in
    a core (variable x, tan theta_h = alpha tan x: resolves needle lobes) and a tail
    (variable theta_h: resolves the masking near the horizon).
    """
    ti = np.radians(theta_i)
    s = np.array([np.sin(ti), 0.0, np.cos(ti)])
    p1, w1 = _gl(n_phi, 0, np.pi / 2)
    p2, w2 = _gl(n_phi, np.pi / 2, np.pi)
    phi, wphi = np.concatenate([p1, p2]), 2 * np.concatenate([w1, w2])
    beta = np.arctan2(np.cos(phi) * np.sin(ti), np.cos(ti))
    th_max = 0.5 * (beta + 0.5 * np.pi)
    t, wt = _gl(n_x, 0, 1)
    x_s = np.arctan2(np.tan(th_max / 2), alpha)
    x = x_s[:, None] * t
    tx = np.tan(x)
    core_th = np.arctan(alpha * tx)
    core_w = x_s[:, None] * wt * alpha * (1 + tx**2) / (1 + (alpha * tx) ** 2)
    tail_th = th_max[:, None] * (0.5 + 0.5 * t)
    tail_w = 0.5 * th_max[:, None] * wt
    th = np.concatenate([core_th, tail_th], axis=1)
    wth = np.concatenate([core_w, tail_w], axis=1)
    h = np.stack(
        [np.sin(th) * np.cos(phi)[:, None], np.sin(th) * np.sin(phi)[:, None], np.cos(th)], axis=-1
    )
    hs = h @ s
    o = 2 * hs[..., None] * h - s
    return s, o, wphi[:, None] * wth * 4 * hs * np.sin(th) * o[..., 2]


@pytest.mark.parametrize("alpha", [1e-3, 0.05, 0.1, 0.3, 0.6, 1.0])
@pytest.mark.parametrize("theta_i", [0.0, 30.0, 60.0, 80.0])
def test_white_furnace_albedo(alpha, theta_i):
    """F = 1, no diffuse term: albedo <= 1, close to 1 for smooth surfaces."""
    s, o, w = glint_nodes(theta_i, alpha)
    albedo = np.einsum("ij,ijk->k", w, mf.specular_factor(Z, s, o, alpha))[0]
    assert albedo <= 1 + TOL_ALBEDO
    if alpha <= 0.05 and theta_i <= 60:
        assert albedo > 0.98
    assert albedo > 0.25


def test_white_furnace_closed_form_rough_normal_incidence():
    """alpha = 1, normal incidence: D = 1/pi, G2 = 2 c/(1 + c), albedo = 1 - ln 2."""
    s, o, w = glint_nodes(0.0, 1.0)
    albedo = np.einsum("ij,ijk->k", w, mf.specular_factor(Z, s, o, 1.0))[0]
    assert albedo == pytest.approx(1 - np.log(2), rel=1e-10)


@pytest.mark.parametrize("theta_i", [0.0, 40.0, 75.0])
@pytest.mark.parametrize(
    "params",
    [
        GLASS,
        {"roughness": [0.02, 0.1, 0.5], "n": 1.2, "k": 7.0, "rho_d": 0.05},
        {"roughness": 0.3, "n": 3.5, "k": 0.2, "rho_d": [0.0, 0.05, 0.2]},
    ],
)
def test_hemispherical_reflectance_equals_brdf_quadrature(theta_i, params):
    alphas = np.broadcast_to(params["roughness"], WL.shape)
    for j, a in enumerate(alphas):
        s, o, w = glint_nodes(theta_i, a)
        spec = {**params, "rho_d": 0.0}
        quad = np.einsum("ij,ijk->k", w, mf.brdf(Z, s, o, WL, **spec))[j]
        dhr = mf.directional_hemispherical_reflectance(theta_i, WL, **spec)[j]
        assert dhr == pytest.approx(quad, rel=TOL_QUAD)
    full = mf.directional_hemispherical_reflectance(theta_i, WL, **params)
    np.testing.assert_allclose(
        full - mf.directional_hemispherical_reflectance(theta_i, WL, **{**params, "rho_d": 0.0}),
        np.broadcast_to(params["rho_d"], WL.shape),
        rtol=1e-12,
        atol=1e-15,
    )
    assert np.all(full <= 1.0)


def test_index_one_has_no_specular_reflection():
    r = mf.directional_hemispherical_reflectance(
        [0.0, 45.0], WL, roughness=0.2, n=1.0, k=0.0, rho_d=0.3
    )
    np.testing.assert_allclose(r, 0.3, atol=1e-12)


def test_smooth_peak_value():
    a, ti = 1e-3, 35.0
    f = mf.brdf_angles(ti, 0.0, 0.0, WL, roughness=a, n=1.5, k=0.0, rho_d=0.0)
    c = np.cos(np.radians(ti))
    s_ = np.sqrt(a**2 + (1 - a**2) * c**2)
    expected = optics.fresnel_conductor(c, 1.5) / (np.pi * a**2) / (4 * c * s_)
    np.testing.assert_allclose(f, expected, rtol=1e-8)


def test_coating_with_zero_thickness_equals_bare_and_coating_changes_colour():
    p = {"roughness": 0.1, "n": 3.5, "k": 0.1, "rho_d": 0.0}
    s, o = [0.5, 0.0, 1.0], [-0.45, 0.05, 1.0]
    bare = mf.brdf(Z, s, o, WL, **p)
    np.testing.assert_allclose(mf.brdf(Z, s, o, WL, layers=[(2.4, 0.0)], **p), bare, rtol=1e-12)
    coated = mf.brdf(Z, s, o, WL, layers=[(1.87, 600 / (4 * 1.87))], **p)
    assert np.all(coated < bare)


@st.composite
def directions(draw):
    special = [
        (0.0, 0.0, 1.0),
        (1.0, 0.0, 1e-9),
        (0.0, 1.0, 1e-300),
        (1e-12, 0.0, 1.0),
        (-1.0, 1e-12, 1e-8),
        (0.0, 0.0, -1.0),
    ]
    return draw(
        st.one_of(
            st.tuples(*[st.floats(-1, 1, allow_subnormal=False)] * 3).filter(
                lambda v: v[0] ** 2 + v[1] ** 2 + v[2] ** 2 > 1e-6
            ),
            st.sampled_from(special),
        )
    )


@settings(max_examples=examples(300), deadline=None)
@given(
    s=directions(),
    o=directions(),
    log_a=st.floats(-4, 0),
    dtype=st.sampled_from([np.float32, np.float64]),
    k=st.floats(0, 10),
    coated=st.booleans(),
)
def test_property_finite_nonnegative(s, o, log_a, dtype, k, coated):
    s = np.array(s, dtype=dtype)
    o = np.array(o, dtype=dtype)
    n = np.array([0, 0, 1], dtype=dtype)
    layers = [(2.0, 75.0)] if coated else None
    f = mf.brdf(n, s, o, WL, layers=layers, roughness=10**log_a, n=1.4, k=k, rho_d=0.1)
    assert f.dtype == dtype and f.shape == (3,)
    assert np.all(np.isfinite(f)) and np.all(f >= 0)
    if not (s[2] > 0 and o[2] > 0):
        assert np.all(f == 0)


@settings(max_examples=examples(200), deadline=None)
@given(s=directions(), o=directions(), log_a=st.floats(-4, 0))
@example(  # doubly grazing forward scatter: f(s, o) / f(o, s) was 1e4
    s=(0.0, 1.0, 1e-300), o=(2.220446049250313e-16, -1.0, 2.076445471370354e-178), log_a=-1.0
)
def test_property_reciprocity(s, o, log_a):
    # uniform over the whole domain, forward scatter included (tests/brdf/test_grazing.py
    # draws the grazing and forward-scatter pairs for every reciprocal model)
    p = {"roughness": 10**log_a, "n": 1.3, "k": 6.0, "rho_d": 0.05}
    a = mf.brdf(Z, s, o, WL, **p)
    b = mf.brdf(Z, o, s, WL, **p)
    np.testing.assert_allclose(a, b, rtol=TOL_RECIPROCITY, atol=0)


def test_normal_and_grazing_incidence_are_finite():
    for a in (1e-4, 0.3):
        f = mf.brdf_angles(
            [0.0, 0.0, 89.999, 90.0 - 1e-9],
            [0.0, 60.0, 0.0, 0.0],
            0.0,
            WL,
            roughness=a,
            n=1.5,
            k=0.0,
            rho_d=0.0,
        )
        assert np.all(np.isfinite(f)) and np.all(f >= 0)
    r = mf.directional_hemispherical_reflectance([0.0, 89.99, 90.0], WL, **GLASS)
    assert np.all(np.isfinite(r)) and np.all((r >= 0) & (r <= 1))


@pytest.mark.parametrize(
    ("update", "name"),
    [
        ({"roughness": 0.0}, "roughness"),
        ({"n": -1.0}, "n"),
        ({"k": -0.1}, "k"),
        ({"rho_d": 1.5}, "rho_d"),
        ({"n": [1.5, 1.5]}, "n"),
    ],
)
def test_validation(update, name):
    with pytest.raises(ValidationError, match=name):
        mf.check_params(WL, **{**GLASS, **update})
