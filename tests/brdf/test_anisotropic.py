"""Tests of the anisotropic GGX microfacet model and its psi-axis tables."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import geometry
from sbrdf_xr.brdf import anisotropic as A
from sbrdf_xr.brdf import get_model
from sbrdf_xr.brdf import microfacet as M
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials import models
from sbrdf_xr.materials import tables as material

WL = np.array([450.0, 650.0, 900.0])
METAL = {"n": [1.2, 1.4, 2.0], "k": [6.0, 7.5, 8.5], "rho_d": 0.01}
Z = np.array([0.0, 0.0, 1.0])


def upper(draw_vec):
    v = np.array(draw_vec, dtype=float)
    v[2] = abs(v[2]) + 1e-3
    return v


vectors = st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: v[0] ** 2 + v[1] ** 2 > 1e-6)
rough = st.floats(-2.5, 0.3).map(lambda x: 10**x)


@settings(max_examples=examples(80), deadline=None)
@given(s=vectors, o=vectors, t=vectors, a=rough)
def test_equal_roughnesses_reproduce_the_isotropic_model(s, o, t, a):
    # Same arithmetic up to the order of operations: 1e-12 relative.
    s, o, t = upper(s), upper(o), np.array(t)
    t[2] = 0.0
    got = A.brdf(Z, s, o, WL, tangent=t, alpha_x=a, alpha_y=a, **METAL)
    want = M.brdf(Z, s, o, WL, roughness=a, **METAL)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)


@settings(max_examples=examples(80), deadline=None)
@given(s=vectors, o=vectors, t=vectors, ax=rough, ay=rough)
def test_reciprocity(s, o, t, ax, ay):
    s, o, t = upper(s), upper(o), np.array(t)
    t[2] = 0.0
    f1 = A.brdf(Z, s, o, WL, tangent=t, alpha_x=ax, alpha_y=ay, **METAL)
    f2 = A.brdf(Z, o, s, WL, tangent=t, alpha_x=ax, alpha_y=ay, **METAL)
    assert np.all(np.isfinite(f1)) and np.all(f1 >= 0)
    np.testing.assert_allclose(f1, f2, rtol=1e-12)


def test_reflectance_quadrature_matches_the_isotropic_one():
    # Equal roughnesses: the isotropic 1e-6 quadrature is the reference; this one cuts
    # the horizon on 128 x 128 nodes without aligning them: 1e-3.
    ti = np.array([0.0, 30.0, 60.0, 80.0])
    for a in (0.05, 0.2, 0.5):
        got = A.directional_hemispherical_reflectance(ti, WL, alpha_x=a, alpha_y=a, **METAL)
        want = M.directional_hemispherical_reflectance(ti, WL, roughness=a, **METAL)
        np.testing.assert_allclose(got, want, rtol=1e-3)


@settings(max_examples=examples(15), deadline=None)
@given(
    ax=st.floats(0.02, 1.0),
    ay=st.floats(0.02, 1.0),
    ti=st.floats(0.0, 85.0),
    psi=st.floats(0.0, 180.0),
)
def test_energy_is_bounded_by_one(ax, ay, ti, psi):
    # A near-perfect conductor (k = 1e3: F = 1 - 4e-6) and no diffuse term: the
    # "white furnace" albedo, <= 1 (masking loses energy), quadrature to 1e-3.
    p = {"n": 1.0, "k": 1e3, "rho_d": 0.0}
    r = A.directional_hemispherical_reflectance(ti, WL[:1], psi=psi, alpha_x=ax, alpha_y=ay, **p)
    assert 0.0 < float(r[0]) <= 1.0 + 1e-3


def test_angles_psi_and_vectors_agree():
    rng = np.random.default_rng(5)
    s = rng.standard_normal((400, 3))
    o = rng.standard_normal((400, 3))
    t = np.array([0.8, -0.6, 0.0])
    kw = {"alpha_x": 0.05, "alpha_y": 0.4, **METAL}
    direct = A.brdf(Z, s, o, WL, tangent=t, **kw)
    ang = geometry.facet_angles(Z, s, o)
    psi = A.illumination_azimuth(Z, t, s, o)
    assert np.all((psi >= 0) & (psi < 180))
    via = A.brdf_angles(ang.theta_i, ang.delta_theta, ang.phi, WL, psi=psi, **kw)
    ok = ang.lit & ang.visible
    np.testing.assert_allclose(via[ok], direct[ok], rtol=1e-9)
    # Rotating the tangent by 180 deg changes nothing.
    np.testing.assert_allclose(A.brdf(Z, s, o, WL, tangent=-t, **kw), direct, rtol=1e-13)


def test_tangent_along_the_normal_is_an_error():
    with pytest.raises(ValidationError, match="tangent"):
        A.brdf(
            Z, [0.3, 0, 1], [-0.3, 0, 1], WL, tangent=[0, 0, 2.0], alpha_x=0.1, alpha_y=0.2, **METAL
        )


def brushed():
    return models.model_material(
        "anisotropic_microfacet",
        WL,
        material="brushed",
        provenance="test",
        alpha_x=0.05,
        alpha_y=0.3,
        **METAL,
    )


def test_psi_table_layout_and_lookup():
    spec = brushed()
    ti, dt, ph, ps = (
        np.arange(0.0, 91.0, 10.0),
        np.arange(-180.0, 91.0, 5.0),
        np.arange(0.0, 91.0, 5.0),
        np.arange(0.0, 181.0, 15.0),
    )
    tab = models.render_anisotropic(spec, ti, dt, ph, ps)
    assert tab.dims == ("theta_i", "delta_theta", "phi", "psi", "wavelength")
    assert tab.psi.attrs["units"] == "degree" and tab.attrs["units"] == "sr-1"
    # At nodes the look-up is the model; psi = 180 wraps onto 0.
    q = (
        np.array([30.0, 50.0, 60.0]),
        np.array([-5.0, 10.0, 0.0]),
        np.array([5.0, 0.0, 20.0]),
        np.array([45.0, 90.0, 180.0]),
    )
    np.testing.assert_allclose(
        material.lookup_anisotropic(tab, *q), models.spectra(spec, *q), rtol=1e-12
    )
    np.testing.assert_allclose(
        material.lookup_anisotropic(tab, 30.0, -5.0, 5.0, 195.0),
        material.lookup_anisotropic(tab, 30.0, -5.0, 5.0, 15.0),
        rtol=1e-13,
    )
    # Brushed: off the plane the glint depends on the tangent's azimuth.
    off = material.lookup_anisotropic(tab, 40.0, 0.0, 10.0, np.array([0.0, 90.0]))
    assert off[0, 0] > 3 * off[1, 0] or off[1, 0] > 3 * off[0, 0]
    with pytest.raises(ValidationError, match="anisotropic"):
        models.render(spec)
    with pytest.raises(ValidationError, match="isotropic"):
        models.render_anisotropic(
            models.model_material("lambert", WL, material="l", provenance="t", rho=0.5),
            ti,
            dt,
            ph,
            ps,
        )


def test_equal_roughness_psi_table_is_the_isotropic_table():
    a = models.model_material(
        "anisotropic_microfacet",
        WL,
        material="iso",
        provenance="test",
        alpha_x=0.2,
        alpha_y=0.2,
        **METAL,
    )
    i = models.model_material(
        "microfacet", WL, material="iso", provenance="test", roughness=0.2, **METAL
    )
    ti, dt, ph = (
        np.arange(0.0, 91.0, 15.0),
        np.arange(-180.0, 91.0, 15.0),
        np.arange(0.0, 91.0, 15.0),
    )
    tab = models.render_anisotropic(a, ti, dt, ph, [0.0, 60.0, 120.0])
    iso = models.render(i, ti, dt, ph)
    for k in range(3):
        np.testing.assert_allclose(tab.isel(psi=k).values, iso.values, rtol=1e-12)


def test_registry_lists_the_anisotropic_model():
    assert get_model("anisotropic_microfacet") is A.MODEL
    with pytest.raises(ValidationError, match="anisotropic_microfacet"):
        get_model("nope")


def test_brushed_aluminium_example_glints_along_the_brushing():
    from sbrdf_xr import catalog

    spec = catalog.load("brushed-aluminium-model")
    ti, dt, ph, ps = (
        np.array([30.0, 40.0, 50.0]),
        np.arange(-30.0, 31.0, 2.0),
        np.arange(0.0, 31.0, 2.0),
        np.array([0.0, 45.0, 90.0, 135.0, 180.0]),
    )
    tab = models.render_anisotropic(spec, ti, dt, ph, ps)
    # Brushing along the illumination plane (psi = 0): smooth along the plane, rough
    # across it, so the glint is narrow in delta_theta and spread in phi; brushing
    # across the plane (psi = 90): the opposite.
    row = tab.sel(theta_i=40.0, wavelength=tab.wavelength[0])
    peak = row.sel(delta_theta=0.0, phi=0.0)
    spread_phi = row.sel(delta_theta=0.0, phi=10.0) / peak
    spread_dt = row.sel(delta_theta=10.0, phi=0.0) / peak
    assert float(spread_phi.sel(psi=0.0)) > 5 * float(spread_phi.sel(psi=90.0))
    assert float(spread_dt.sel(psi=90.0)) > 5 * float(spread_dt.sel(psi=0.0))
    np.testing.assert_allclose(tab.sel(psi=0.0), tab.sel(psi=180.0), rtol=1e-12)
    rho = A.directional_hemispherical_reflectance(
        [0.0, 45.0, 80.0],
        spec.wavelength.values,
        psi=[0.0, 45.0, 90.0],
        **{k: spec[k].values for k in A.PARAMS},
    )
    assert np.all((rho > 0.5) & (rho <= 1.0))
