"""Tests of optical constants and exact Fresnel reflectances (sbrdf_xr.brdf.optics)."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.brdf import optics
from sbrdf_xr.errors import ValidationError

#: Closed-form Fresnel identities hold to rounding (a few ulp of complex arithmetic).
TOL_EXACT = 1e-12
#: Independent literature values of optical constants: the simple GaAs model is
#: documented as ~2 % below Skauli et al. (2003) in the transparent range.
TOL_GAAS = 0.03


@pytest.mark.parametrize("index", [1.5, 2.4 + 0j, 3.5 + 0.2j, 1.2 + 7.3j, 0.3 + 3.0j])
def test_normal_incidence_formula(index):
    n, k = index.real if isinstance(index, complex) else index, np.imag(index)
    expected = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
    assert optics.fresnel_conductor(1.0, index) == pytest.approx(expected, rel=TOL_EXACT)
    assert optics.normal_incidence_reflectance(index) == pytest.approx(expected, rel=TOL_EXACT)


@pytest.mark.parametrize("index", [1.5, 3.5 + 0.2j, 1.2 + 7.3j, 0.5 + 0.0j])
def test_grazing_incidence_tends_to_one(index):
    assert optics.fresnel_conductor(0.0, index) == pytest.approx(1.0, abs=TOL_EXACT)
    r = optics.fresnel_conductor(np.array([1e-6, 1e-4, 1e-2]), index)
    assert r[0] > 0.999 and np.all(np.diff(r) <= 1e-15)


def test_dielectric_against_textbook_real_snell():
    n = 1.5
    ti = np.radians(np.linspace(0, 89.9, 50))
    tt = np.arcsin(np.sin(ti) / n)
    rs = (np.cos(ti) - n * np.cos(tt)) / (np.cos(ti) + n * np.cos(tt))
    rp = (n * np.cos(ti) - np.cos(tt)) / (n * np.cos(ti) + np.cos(tt))
    np.testing.assert_allclose(
        optics.fresnel_conductor(np.cos(ti), n), 0.5 * (rs**2 + rp**2), rtol=1e-10, atol=1e-15
    )
    # Brewster angle: p vanishes, R = R_s / 2
    tb = np.arctan(n)
    tt = np.arcsin(np.sin(tb) / n)
    rs_b = ((np.cos(tb) - n * np.cos(tt)) / (np.cos(tb) + n * np.cos(tt))) ** 2
    assert optics.fresnel_conductor(np.cos(tb), n) == pytest.approx(rs_b / 2, rel=1e-12)


WL = np.linspace(400.0, 1000.0, 61)


def test_stack_without_layers_or_with_zero_thickness_equals_bare_substrate():
    c = np.array([1.0, 0.8, 0.3, 1e-3, 0.0])
    sub = optics.aluminium_index(WL)
    bare = optics.fresnel_conductor(c[:, None], sub)
    np.testing.assert_allclose(
        optics.fresnel_thin_film_stack(c, WL, [], sub), bare, rtol=TOL_EXACT, atol=1e-15
    )
    layers = [(2.4, 0.0), (optics.gaas_index(WL), 0.0), (1.46 + 0.1j, 0.0)]
    np.testing.assert_allclose(
        optics.fresnel_thin_film_stack(c, WL, layers, sub), bare, rtol=TOL_EXACT, atol=1e-15
    )


def _airy(cos_t, wl, n1, d, n2):
    """Single layer by the Airy summation (independent of the matrix method)."""
    s2 = 1 - cos_t**2
    q0, q1, q2 = (np.sqrt(n**2 - s2 + 0j) for n in (1.0, n1, n2))
    q1 = np.where(q1.imag < 0, -q1, q1)
    q2 = np.where(q2.imag < 0, -q2, q2)
    ph = np.exp(2j * 2 * np.pi * d * q1 / wl)
    out = 0.0
    for pol in ("s", "p"):
        if pol == "s":
            r01, r12 = (q0 - q1) / (q0 + q1), (q1 - q2) / (q1 + q2)
        else:
            r01 = (n1**2 * q0 - q1) / (n1**2 * q0 + q1)
            r12 = (n2**2 * q1 - n1**2 * q2) / (n2**2 * q1 + n1**2 * q2)
        out = out + 0.5 * np.abs((r01 + r12 * ph) / (1 + r01 * r12 * ph)) ** 2
    return out


@pytest.mark.parametrize("cos_t", [1.0, 0.7, 0.2, 0.01])
def test_single_layer_matches_airy_formula(cos_t):
    sub = optics.gaas_index(WL)
    for n1, d in ((2.4, 70.0), (1.65 + 0.05j, 300.0), (optics.aluminium_index(WL), 12.0)):
        stack = optics.fresnel_thin_film_stack(cos_t, WL, [(n1, d)], sub)
        np.testing.assert_allclose(
            stack, _airy(cos_t, WL, np.asarray(n1), d, sub), rtol=1e-10, atol=1e-14
        )


def test_quarter_wave_layer_cancels_reflection():
    n_sub, wl0 = 3.5, 600.0
    n1 = np.sqrt(n_sub)
    r = optics.fresnel_thin_film_stack(1.0, [wl0], [(n1, wl0 / (4 * n1))], n_sub)
    assert r[0] < 1e-15
    assert optics.fresnel_conductor(1.0, n_sub) > 0.3


def test_interference_minimum_moves_blue_with_angle():
    """AR-coated cell: the minimum shifts to shorter wavelengths as the angle grows."""
    wl = np.linspace(400.0, 800.0, 4001)
    sub = optics.gaas_index(wl)
    n1 = 2.0
    layers = [(n1, 600.0 / (4 * n1))]
    mins = [
        wl[np.argmin(optics.fresnel_thin_film_stack(np.cos(np.radians(t)), wl, layers, sub))]
        for t in (0.0, 30.0, 50.0, 65.0)
    ]
    assert np.all(np.diff(mins) < 0)
    # phase-thickness scaling: lambda_min ~ cos(theta_1) (+ dispersion of GaAs)
    cos1 = np.sqrt(1 - (np.sin(np.radians(50.0)) / n1) ** 2)
    assert mins[2] / mins[0] == pytest.approx(cos1, rel=0.03)


def test_thick_absorbing_layer_no_overflow():
    sub = 1.46
    r = optics.fresnel_thin_film_stack(
        np.array([1.0, 0.5, 0.0]), WL, [(optics.aluminium_index(WL), 1e5)], sub
    )
    bare = optics.fresnel_conductor(np.array([1.0, 0.5, 0.0])[:, None], optics.aluminium_index(WL))
    assert np.all(np.isfinite(r))
    np.testing.assert_allclose(r, bare, rtol=1e-12)


def test_aluminium_reflectance_visible_and_800nm_dip():
    wl = np.arange(400.0, 1201.0, 5.0)
    n = optics.aluminium_index(wl)
    assert np.all(n.imag > 0)
    r = optics.normal_incidence_reflectance(n)
    vis = (wl >= 400) & (wl <= 650)
    assert np.all((r[vis] > 0.89) & (r[vis] < 0.94))
    near_ir = (wl >= 700) & (wl <= 1000)
    wl_min = wl[near_ir][np.argmin(r[near_ir])]
    assert 750 <= wl_min <= 900
    assert r[wl == wl_min][0] < r[wl == 600][0] - 0.03
    assert r[wl == 1100][0] > r[wl == wl_min][0] + 0.05


def test_gaas_model_against_skauli_2003():
    wl_um = np.array([1.0, 1.3, 1.5, 2.0])
    # Skauli et al., J. Appl. Phys. 94, 6447 (2003), 22 C (valid 0.97-17 um)
    eps = (
        5.372514
        + 5.466742 * wl_um**2 / (wl_um**2 - 0.4431307**2)
        + 0.02429960 * wl_um**2 / (wl_um**2 - 0.8746453**2)
        + 1.957522 * wl_um**2 / (wl_um**2 - 36.9166**2)
    )
    n = optics.gaas_index(wl_um * 1000)
    np.testing.assert_allclose(n.real, np.sqrt(eps), rtol=TOL_GAAS)
    assert np.all(n.imag == 0)  # transparent below the gap (871 nm)
    vis = optics.gaas_index(np.array([450.0, 550.0, 650.0, 800.0]))
    assert np.all(vis.imag > 0) and np.all((vis.real > 3.5) & (vis.real < 5.0))
    assert np.all(np.diff(vis.real) < 0)  # normal dispersion


def test_dielectric_sellmeier_values():
    assert optics.silica_index(587.6) == pytest.approx(1.4585, abs=2e-4)  # Malitson
    assert optics.sapphire_index(589.3) == pytest.approx(1.768, abs=2e-3)  # n_o
    assert 2.55 < optics.titania_index(550.0) < 2.75  # rutile n_o
    assert 2.3 <= optics.FILM_INDEX["TiO2"] <= 2.5 and optics.FILM_INDEX["SiO2"] == 1.46


def test_validation():
    with pytest.raises(ValidationError, match="cos_theta"):
        optics.fresnel_conductor(1.2, 1.5)
    with pytest.raises(ValidationError, match="n_complex"):
        optics.fresnel_conductor(0.5, 1.5 - 0.1j)
    with pytest.raises(ValidationError, match="thickness"):
        optics.fresnel_thin_film_stack(1.0, WL, [(1.5, -1.0)], 3.5)
    with pytest.raises(ValidationError, match="shape"):
        optics.fresnel_thin_film_stack(1.0, WL, [(np.ones(3) * 1.5, 10.0)], 3.5)
    with pytest.raises(ValidationError, match="wavelength"):
        optics.aluminium_index([0.0, 500.0])
