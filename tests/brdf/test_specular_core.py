"""The Robertson-Sandford model with a Beckmann specular core (brdf.specular_core)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from sbrdf_xr.brdf import robertson_sandford as rs
from sbrdf_xr.brdf import specular_core as sc
from sbrdf_xr.geometry import facet_vectors

Z = np.array([0.0, 0.0, 1.0])
BODY = dict(rs.TABLE4["AFGL-01"])


def _unit(theta):
    t = np.radians(theta)
    return np.array([np.sin(t), 0.0, np.cos(t)])


@pytest.mark.parametrize(
    ("theta_i", "m"),
    [
        (40.0, 0.2),
        pytest.param(0.0, 0.2, marks=pytest.mark.slow),
        pytest.param(70.0, 0.3, marks=pytest.mark.slow),
        pytest.param(30.0, 0.05, marks=pytest.mark.slow),
    ],
)
def test_the_core_reflectance_quadrature_matches_an_outgoing_hemisphere_quadrature(theta_i, m):
    """core_loss (over the half vector, u = tan(theta_h) / m) against a product
    Gauss-Legendre rule of the core's f cos(theta_r) over the outgoing hemisphere in
    (theta_r, phi_r): two independent parameterisations of one integral; 400 x 400
    points resolve a lobe of rms slope >= 0.05 (about 6 deg of theta_r) to < 1e-4."""
    s = _unit(theta_i)
    x, w = np.polynomial.legendre.leggauss(400)
    tr, wt = np.pi / 4 * (x + 1), np.pi / 4 * w
    ph, wp = np.pi * (x + 1), np.pi * w
    t, p = np.meshgrid(tr, ph, indexing="ij")
    o = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    f = sc.core_brdf(Z, s, o, [1.0], [m])[..., 0] * np.cos(t) * np.sin(t)
    want = float(np.einsum("ij,i,j->", f, wt, wp))
    assert sc.core_loss([theta_i], m)[0] == pytest.approx(want, abs=1e-4)


def test_a_narrow_core_reflects_its_reflectance_and_peaks_as_beckmann_says():
    # Away from grazing a narrow lobe lies whole above the horizon and its Smith
    # masking is 1: L = int D cos(theta_h) d omega_h = 1 (Beckmann's normalisation).
    assert np.allclose(sc.core_loss([0.0, 30.0, 60.0], 0.005), 1.0, atol=1e-6)
    # At the mirror direction: D = 1 / (pi m^2), G = 1, f = rho D / (4 cos^2 theta_i).
    ti, m, rho = 30.0, 0.01, 0.4
    s, o = _unit(ti), _unit(-ti)
    want = rho / (np.pi * m**2) / (4 * np.cos(np.radians(ti)) ** 2)
    assert sc.core_brdf(Z, s, o, [rho], [m])[0] == pytest.approx(want, rel=1e-12)
    # In the plane, delta_theta from specular turns the half vector by delta_theta / 2:
    # D falls as exp(-tan^2(delta_theta / 2) / m^2).
    off = sc.core_brdf(Z, s, _unit(-ti - 1.0), [rho], [m])[0]
    th = np.radians(0.5)
    want_off = rho * np.exp(-(np.tan(th) ** 2) / m**2) / (np.pi * m**2 * np.cos(th) ** 4)
    cos_r = np.cos(np.radians(ti + 1.0))
    assert off == pytest.approx(want_off / (4 * np.cos(np.radians(ti)) * cos_r), rel=1e-9)


def _law(rho, directions):
    """``core_rho cos theta_i`` at the facet ``Z`` lit from ``directions``."""
    cos_i = directions[..., 2] / np.linalg.norm(directions, axis=-1)
    return np.asarray(rho)[None, :] * cos_i[:, None]


def test_the_core_is_reciprocal_and_the_model_is_body_plus_core_scaled():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(200, 3))
    b = rng.normal(size=(200, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]), np.abs(b[:, 2])
    f_ab = sc.core_brdf(Z, a, b, [0.3], [0.2])
    f_ba = sc.core_brdf(Z, b, a, [0.3], [0.2])
    assert np.allclose(f_ab, f_ba, rtol=1e-12, atol=0)
    wl = [500.0, 600.0]
    core = dict(core_rho=[0.3, 0.1], core_roughness=0.2)
    total = sc.brdf(Z, a, b, wl, **core, **BODY)
    ti = np.degrees(np.arccos(a[:, 2] / np.linalg.norm(a, axis=-1)))
    scale = sc.energy_scale(ti, wl, **core, **BODY)
    parts = rs.brdf(Z, a, b, wl, **BODY) + sc.core_brdf(Z, a, b, _law([0.3, 0.1], a), [0.2, 0.2])
    assert np.allclose(total, parts * scale, rtol=1e-12, atol=0)
    rho = sc.directional_hemispherical_reflectance([20.0], wl, **core, **BODY)
    body = rs.directional_hemispherical_reflectance([20.0], wl, **BODY)
    c = np.array([0.3, 0.1]) * np.cos(np.radians(20.0)) * sc.core_loss([20.0], 0.2)
    assert np.allclose(rho, (body + c) * sc.energy_scale([20.0], wl, **core, **BODY))


#: A body like the Starlink chassis' fit (a paint-like lobe on a near-mirror's
#: emissivity) under a core that alone would reflect 0.95 at normal incidence.
CHASSIS = dict(rho_D=0.035, epsilon=0.77, b=0.06, e=0.086, core_rho=0.95, core_roughness=0.0066)


def test_the_model_reflects_at_most_one_at_every_incidence_angle():
    """Without the energy scale the chassis-like model reflects 1.2 near normal
    incidence; with it, at most one at every incidence angle 0-90 deg (the half-vector
    quadrature of the core, the body's own quadrature of its cut-off, each good to
    ~1e-12: 1e-9 is their rounding)."""
    ti = np.linspace(0.0, 90.0, 181)
    rho = sc.directional_hemispherical_reflectance(ti, [532.0], **CHASSIS)[:, 0]
    assert rho.max() <= 1.0 + 1e-9
    unscaled = rho / sc.energy_scale(ti, [532.0], **CHASSIS)[:, 0]
    assert unscaled.max() > 1.15  # the bound is at work
    # b = 0 (no cut-off) and a narrow core away from grazing (L = 1 to 1e-6): the body
    # reflects 1 - epsilon(theta_i) exactly (Eq. 11), and the scaled model exactly 1 where
    # it is scaled (to 30 deg here).
    exact = dict(CHASSIS, b=0.0)
    rho0 = sc.directional_hemispherical_reflectance([0.0, 10.0, 20.0], [532.0], **exact)
    np.testing.assert_allclose(rho0, 1.0, atol=1e-6)


@pytest.mark.parametrize("theta_i", [10.0, pytest.param(50.0, marks=pytest.mark.slow), 75.0])
def test_the_model_reflectance_matches_a_cubature_over_the_outgoing_hemisphere(theta_i):
    """The scaled model's reflectance against an independent cubature of ``f cos
    theta_r`` over the outgoing hemisphere: Gauss-Legendre in the angle ``alpha`` from
    the mirror direction on panels graded about the core (0-3, 3-12 core widths, the
    rest) times 256 points in azimuth about it, the points below the horizon dropped.
    The horizon cuts that grid along a curve, not a panel edge: a 1e-3 share of the
    integral there (the body's grazing tail); 2e-3 holds it."""
    p = dict(CHASSIS, core_roughness=0.02)
    t = np.radians(theta_i)
    s = np.array([np.sin(t), 0.0, np.cos(t)])
    r = np.array([-np.sin(t), 0.0, np.cos(t)])  # the mirror direction
    u = np.array([np.cos(t), 0.0, np.sin(t)])  # in the plane, perpendicular to r
    v = np.array([0.0, 1.0, 0.0])
    width = 2.0 * p["core_roughness"]  # 1/e half width of the core in angle [rad]
    edges = [0.0, 3.0 * width, 12.0 * width, np.pi]
    x, w = np.polynomial.legendre.leggauss(200)
    alpha = np.concatenate([0.5 * (b - a) * (x + 1) + a for a, b in itertools.pairwise(edges)])
    w_a = np.concatenate([0.5 * (b - a) * w for a, b in itertools.pairwise(edges)])
    beta = np.arange(256) * (2 * np.pi / 256)
    al, be = np.meshgrid(alpha, beta, indexing="ij")
    o = (np.cos(al)[..., None] * r + np.sin(al)[..., None]
         * (np.cos(be)[..., None] * u + np.sin(be)[..., None] * v))  # fmt: skip
    f = sc.brdf(Z, s, o, [532.0], **p)[..., 0] * np.maximum(o[..., 2], 0.0)
    got = float(np.einsum("ab,a->", f * np.sin(al), w_a) * (2 * np.pi / 256))
    want = float(sc.directional_hemispherical_reflectance([theta_i], [532.0], **p)[0, 0])
    assert got == pytest.approx(want, abs=2e-3)


def test_fit_core_recovers_a_core_beside_a_known_body_at_several_incidence_angles():
    t, d = np.meshgrid([5.0, 40.0, 60.0], np.arange(-10.0, 10.5, 1.0), indexing="ij")
    t, d, p = t.ravel(), d.ravel(), np.zeros(t.size)
    n, s, o = facet_vectors(t, d, p)
    body = rs.brdf(n, s, o, [500.0, 700.0], **BODY)
    rho = np.array([0.5, 0.2])[None, :] * np.cos(np.radians(t))[:, None]
    y = body + sc.core_brdf(n, s, o, rho, [0.006, 0.006])
    fit = sc.fit_core(t, d, p, y, body)
    assert fit["core_roughness"] == pytest.approx(0.006, rel=1e-6)
    assert np.allclose(fit["core_rho"], [0.5, 0.2], rtol=1e-6)
    assert np.allclose(fit["core_offset"], 0.0, atol=1e-6)
    assert fit["rms_log"] < 1e-8


def test_fit_core_takes_a_core_off_specular_as_an_offset_not_as_width():
    """A core measured 0.2 deg beyond specular (a goniometer's zero): its width and
    reflectance are recovered and the offset returned, where a core held at specular
    would widen to reach both flanks."""
    t, d = np.meshgrid([5.0, 40.0, 60.0], np.arange(-10.0, 10.5, 1.0), indexing="ij")
    t, d, p = t.ravel(), d.ravel(), np.zeros(t.size)
    body = rs.brdf(*facet_vectors(t, d, p), [500.0], **BODY)
    rho = 0.5 * np.cos(np.radians(t))[:, None]
    y = body + sc.core_brdf(*facet_vectors(t, d - 0.2, p), rho, [0.006])
    fit = sc.fit_core(t, d, p, y, body)
    assert fit["core_roughness"] == pytest.approx(0.006, rel=1e-6)
    assert fit["core_rho"][0] == pytest.approx(0.5, rel=1e-6)
    np.testing.assert_allclose(fit["core_offset"], 0.2, atol=1e-6)
