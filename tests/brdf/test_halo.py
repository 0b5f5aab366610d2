"""Robertson-Sandford body, Beckmann core and ABg halo (brdf.halo)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from sbrdf_xr.brdf import halo
from sbrdf_xr.brdf import robertson_sandford as rs
from sbrdf_xr.brdf import specular_core as sc
from sbrdf_xr.geometry import facet_vectors

Z = np.array([0.0, 0.0, 1.0])
#: A bright glint: body, core and halo together reflect more than one before scaling.
BRIGHT = dict(
    rho_D=0.05, epsilon=0.2, b=0.05, e=0.1, core_rho=0.6, core_roughness=0.01,
    halo_a=3e-3, halo_b=1e-6, halo_g=2.4,
)  # fmt: skip


def _unit(theta):
    t = np.radians(theta)
    return np.array([np.sin(t), 0.0, np.cos(t)])


def _hemisphere(f, n=400, cut=np.pi / 2):
    """``int f(o) cos(theta_o) d omega_o`` by a product Gauss-Legendre rule in
    ``(theta_o, phi_o)``, ``theta_o`` in ``[0, cut]``."""
    x, w = np.polynomial.legendre.leggauss(n)
    tr, wt = cut / 2 * (x + 1), cut / 2 * w
    ph, wp = np.pi * (x + 1), np.pi * w
    t, p = np.meshgrid(tr, ph, indexing="ij")
    o = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    vals = f(o)
    return np.einsum("ij...,i,j->...", vals * (np.cos(t) * np.sin(t))[..., None], wt, wp)


@pytest.mark.parametrize(("b", "g", "r"), [(1e-6, 2.4, 1.0), (1e-4, 1.5, 1.7), (1e-9, 3.5, 1.3)])
def test_the_radial_integral_matches_adaptive_quadrature(b, g, r):
    """The closed form (a hypergeometric function) against scipy's adaptive quadrature
    in ``ln r``, where the integrand is smooth; both to rounding (1e-12)."""
    want = quad(lambda u: np.exp(2 * u) / (b + np.exp(g * u)), np.log(1e-12 * b ** (1 / g)),
                np.log(r), limit=400, epsabs=0, epsrel=1e-13)[0]  # fmt: skip
    assert float(halo._radial(r, b, g)) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("theta_i", [0.0, 40.0, pytest.param(75.0, marks=pytest.mark.slow)])
def test_the_halo_reflectance_matches_a_hemisphere_quadrature(theta_i):
    """halo_reflectance (over the disc of direction cosines, polar about the mirror
    direction) against the halo's f cos(theta_o) over the outgoing hemisphere in
    (theta_o, phi_o): two parameterisations of one integral.  A broad halo (turning
    over at 0.1 in direction cosines) which 1000 x 1000 points resolve to < 1e-6 (at
    75 deg 400 points are off by 3e-6, converging on halo_reflectance's value)."""
    a, b, g = [2e-3], [0.1**2.5], [2.5]
    s = _unit(theta_i)
    want = _hemisphere(lambda o: halo.halo_brdf(Z, s, o, a, b, g), n=1000)
    assert halo.halo_reflectance([theta_i], a, b, g)[0] == pytest.approx(want, rel=1e-6)


def test_the_halo_is_reciprocal_shift_invariant_and_peaks_at_a_over_b():
    rng = np.random.default_rng(3)
    u, v = rng.normal(size=(300, 3)), rng.normal(size=(300, 3))
    u[:, 2], v[:, 2] = np.abs(u[:, 2]), np.abs(v[:, 2])
    p = ([2e-3], [1e-6], [2.5])
    np.testing.assert_allclose(halo.halo_brdf(Z, u, v, *p), halo.halo_brdf(Z, v, u, *p),
                               rtol=1e-12)  # fmt: skip
    # The same distance in direction cosines from the mirror direction gives the same
    # value at every incidence angle (Harvey's shift invariance): sin(theta_o) moved
    # by 0.02 from sin(theta_i).
    vals = []
    for ti in (5.0, 40.0, 70.0):
        to = np.degrees(np.arcsin(np.sin(np.radians(ti)) + 0.02))
        vals.append(halo.halo_brdf(Z, _unit(ti), _unit(-to), *p)[0])
    np.testing.assert_allclose(vals, 2e-3 / (1e-6 + 0.02**2.5), rtol=1e-9)
    assert halo.halo_brdf(Z, _unit(30.0), _unit(-30.0), *p)[0] == pytest.approx(2000.0)


@pytest.mark.parametrize("theta_i", [0.0, 30.0, 60.0, pytest.param(80.0, marks=pytest.mark.slow)])
def test_a_bright_glint_reflects_at_most_one_by_quadrature(theta_i):
    """The model's directional-hemispherical reflectance (body, core and halo) is at
    most one, both as the model states it and by quadrature of the BRDF itself: the
    body by a 1000 x 1000 product rule over the hemisphere (400 points miss by 1.3e-3
    at 80 deg), the halo by adaptive quadrature about the mirror direction
    (_halo_quadrature, independent of halo_reflectance's disc of direction cosines;
    both agree to 1e-8), the core (0.6 degree wide) by its own half-vector quadrature,
    core_loss, checked against a hemisphere rule in test_specular_core.  Together
    within 1e-5 of the stated reflectance."""
    wl = [532.0]
    p = halo.MODEL.check_params(wl, **BRIGHT)
    scale = halo.energy_scale([theta_i], wl, **BRIGHT)[0, 0]
    assert scale < 1.0  # the bright glint needs scaling
    stated = halo.directional_hemispherical_reflectance([theta_i], wl, **BRIGHT)[0, 0]
    assert stated <= 1.0 + 1e-12
    s = _unit(theta_i)
    body_p = {k: BRIGHT[k] for k in rs.PARAMS}
    body = _hemisphere(lambda o: rs.brdf(Z, s, o, wl, **body_p), n=1000)[0]
    halo_q = _halo_quadrature(theta_i, p)
    core = BRIGHT["core_rho"] * np.cos(np.radians(theta_i)) * sc.core_loss([theta_i], 0.01)[0]
    total = scale * (body + core + halo_q)
    assert total <= 1.0 + 1e-5
    assert total == pytest.approx(stated, abs=1e-5)


def _halo_quadrature(theta_i, p):
    """The halo's reflectance on the sphere, in polar coordinates ``(alpha, q)`` about the
    mirror direction: scipy's adaptive quadrature in ``ln alpha`` from the mirror
    direction to the horizon (``alpha_max(q)``, where ``o_z = 0``), the trapezoid rule
    in ``q`` (periodic)."""
    a, b, g = (float(p[k][0]) for k in ("halo_a", "halo_b", "halo_g"))
    s = _unit(theta_i)
    mirror = np.array([-s[0], 0.0, s[2]])
    e1 = np.cross(mirror, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(mirror, e1)
    qs = np.arange(256) * (2 * np.pi / 256)
    total = 0.0
    for q in qs:
        side = np.cos(q) * e1 + np.sin(q) * e2
        top = np.arctan2(side[2], mirror[2]) + np.pi / 2  # o_z = 0 beyond

        def f(u, side=side):
            al = np.exp(u)
            o = np.cos(al) * mirror + np.sin(al) * side
            val = halo.halo_brdf(Z, s, o, [a], [b], [g])[0]
            return val * max(o[2], 0.0) * np.sin(al) * al

        total += quad(f, np.log(1e-9), np.log(top), limit=200, epsrel=1e-10)[0]
    return total * 2 * np.pi / qs.size


@settings(max_examples=25, deadline=None)
@given(
    theta_i=st.floats(0.0, 90.0),
    a=st.floats(1e-5, 1e-1),
    b=st.floats(1e-9, 1e-2),
    g=st.floats(1.0, 4.0),
)
def test_the_energy_bound_holds_for_any_halo(theta_i, a, b, g):
    """The bound H (the halo over the disc of radius 1 + sin theta_i) is at least the
    halo's reflectance (over the unit disc it holds), and the scaled model reflects at
    most one."""
    exact = halo.halo_reflectance([theta_i], [a], [b], [g])[0, 0]
    assert np.isfinite(exact)
    p = dict(BRIGHT, halo_a=a, halo_b=b, halo_g=g)
    bound = halo._halo_bound(np.array([theta_i]), halo.MODEL.check_params([532.0], **p))
    assert exact <= bound[0, 0] * (1 + 1e-9)
    assert halo.directional_hemispherical_reflectance([theta_i], [532.0], **p)[0, 0] <= 1 + 1e-12


def test_the_halo_fit_recovers_a_known_halo_beside_a_core():
    """A scan of core and halo on a flat body (0.25-degree steps to 8 degrees from
    specular at two incidence angles): the joint log fit returns the halo's power to
    1e-4 and its level to 1e-3 (the optimiser's tolerance on noiseless data)."""
    t = np.repeat([20.0, 60.0], 65)
    d = np.tile(np.linspace(-8.0, 8.0, 65), 2)
    n, s, o = facet_vectors(t, d, np.zeros_like(t))
    core = sc.core_brdf(n, s, o, 0.5 * np.cos(np.radians(t))[:, None], [0.006])
    y = 0.2 + core + halo.halo_brdf(n, s, o, [1e-4], [1e-7], [2.8])
    start = sc.fit_core(t, d, np.zeros_like(t), y, np.full_like(y, 0.2))
    fit = halo.fit_halo(t, d, np.zeros_like(t), y, np.full_like(y, 0.2), start)
    assert fit["halo_g"] == pytest.approx(2.8, rel=1e-4)
    assert fit["halo_a"][0] == pytest.approx(1e-4, rel=1e-3)
    assert fit["core_roughness"] == pytest.approx(0.006, rel=1e-3)
    assert fit["rms_log"] < 1e-4
