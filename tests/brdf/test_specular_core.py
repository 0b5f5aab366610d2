"""The Robertson-Sandford model with a Beckmann specular core (brdf.specular_core)."""

from __future__ import annotations

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


def test_the_core_is_reciprocal_and_the_sum_is_body_plus_core():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(200, 3))
    b = rng.normal(size=(200, 3))
    a[:, 2], b[:, 2] = np.abs(a[:, 2]), np.abs(b[:, 2])
    f_ab = sc.core_brdf(Z, a, b, [0.3], [0.2])
    f_ba = sc.core_brdf(Z, b, a, [0.3], [0.2])
    assert np.allclose(f_ab, f_ba, rtol=1e-12, atol=0)
    wl = [500.0, 600.0]
    total = sc.brdf(Z, a, b, wl, core_rho=[0.3, 0.1], core_roughness=0.2, **BODY)
    parts = rs.brdf(Z, a, b, wl, **BODY) + sc.core_brdf(Z, a, b, [0.3, 0.1], [0.2, 0.2])
    assert np.allclose(total, parts, rtol=1e-12, atol=0)
    rho = sc.directional_hemispherical_reflectance([20.0], wl, core_rho=[0.3, 0.1],
                                                   core_roughness=0.2, **BODY)  # fmt: skip
    body = rs.directional_hemispherical_reflectance([20.0], wl, **BODY)
    assert np.allclose(rho - body, np.array([0.3, 0.1]) * sc.core_loss([20.0], 0.2))


def test_fit_core_recovers_a_core_beside_a_known_body_at_several_incidence_angles():
    t, d = np.meshgrid([5.0, 40.0, 60.0], np.arange(-10.0, 10.5, 1.0), indexing="ij")
    t, d, p = t.ravel(), d.ravel(), np.zeros(t.size)
    n, s, o = facet_vectors(t, d, p)
    body = rs.brdf(n, s, o, [500.0, 700.0], **BODY)
    y = body + sc.core_brdf(n, s, o, [0.5, 0.2], [0.006, 0.006])
    fit = sc.fit_core(t, d, p, y, body)
    assert fit["core_roughness"] == pytest.approx(0.006, rel=1e-6)
    assert np.allclose(fit["core_rho"], [0.5, 0.2], rtol=1e-6)
    assert fit["rms_log"] < 1e-8
