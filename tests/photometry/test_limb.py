"""Sunlight through the Earth's limb (photometry.limb): the ray, the atmosphere, the disc."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.photometry import limb as limb_module
from sbrdf_xr.photometry import limb_ray, limb_transmission

A, B = 6378.137, 6356.752314245  # WGS84 [km]


def geodetic_height(x: np.ndarray) -> float:
    """Exact height above the WGS84 ellipsoid (Bowring's iteration to convergence)."""
    e2 = 1 - (B / A) ** 2
    p, z = np.hypot(x[0], x[1]), x[2]
    lat = np.arctan2(z, p * (1 - e2))
    for _ in range(20):
        n = A / np.sqrt(1 - e2 * np.sin(lat) ** 2)
        h = p / np.cos(lat) - n
        lat = np.arctan2(z, p * (1 - e2 * n / (n + h)))
    return float(h)


@settings(max_examples=30, deadline=None)
@given(
    st.floats(90.5, 125.0),  # the Sun's angle from the zenith [degree]
    st.floats(6700.0, 7200.0),  # distance from the centre [km]
)
def test_the_ray_over_the_equator_is_a_circle(zenith, r):
    """In the equatorial plane the ellipsoid is a circle of radius a: the ray's least
    height is |p x s| - a at -p.s from the spacecraft (to the search's 0.1 m, 1e-7 km
    of height at the minimum)."""
    a = np.radians(zenith)
    p = np.array([[r, 0.0, 0.0]])
    s = np.array([[np.cos(a), np.sin(a), 0.0]])
    h, d = limb_ray(p, s)
    assert h[0] == pytest.approx(r * np.sin(a) - A, abs=1e-6)
    assert d[0] == pytest.approx(-r * np.cos(a), abs=0.1)


@pytest.mark.parametrize("lat", [0.0, 35.0, 60.0, 89.0])
@pytest.mark.parametrize("zenith", [95.0, 105.0, 112.0])
def test_the_ray_against_the_exact_geodetic_height(lat, zenith):
    """A ray in the meridian plane over any latitude, against the exact geodetic height
    minimised by scipy: the height along the radius differs from the geodetic one by
    about h (e^2 sin 2phi / 2)^2 / 2 <= 1.2e-5 h (0.3 m at 25 km, 6 m at 525 km)."""
    phi = np.radians(lat)
    p = 6921.0 * np.array([np.cos(phi), 0.0, np.sin(phi)])
    up = p / np.linalg.norm(p)
    north = np.array([-np.sin(phi), 0.0, np.cos(phi)])
    a = np.radians(zenith)
    s = np.cos(a) * up + np.sin(a) * north
    h, d = limb_ray(p[None], s[None])
    best = minimize_scalar(
        lambda lam: geodetic_height(p + lam * s), bounds=(0.0, 5000.0), method="bounded",
        options={"xatol": 1e-6},
    )  # fmt: skip
    assert h[0] == pytest.approx(best.fun, abs=1.5e-5 * best.fun + 1e-3)
    assert d[0] == pytest.approx(best.x, abs=5.0)  # a flat minimum: 5 km moves h by ~2 m


def test_a_ray_that_climbs_has_its_lowest_point_at_the_spacecraft():
    h, d = limb_ray([[0.0, 0.0, 7000.0]], [[0.0, 0.0, 1.0]])
    assert d[0] == 0.0 and h[0] == pytest.approx(7000.0 - B, abs=1e-9)


def test_the_slant_path_is_chapmans_grazing_limit():
    """For an exponential atmosphere of scale height H the limb path lowest at h holds
    sqrt(2 pi r / H) exp(-h / H) vertical columns from the ground (Chapman's function at
    90 deg, to O(H/r): 0.1 %)."""
    for hscale in (6.0, 8.0):
        ratio = limb_module._slant(np.array([0.0, 20.0]), lambda z, s=hscale: np.exp(-z / s))
        h = np.array([0.0, 20.0])
        exact = np.sqrt(2 * np.pi * (6371.0 + h) / hscale) * np.exp(-h / hscale)
        np.testing.assert_allclose(ratio, exact, rtol=3e-3)


def test_the_bending_is_the_exponential_atmospheres_closed_form(monkeypatch):
    """delta(h) = N0 sqrt(2 pi r / H) exp(-h / H) for refractivity N0 exp(-z / H) (the
    integral of the module docstring in closed form, to O(H/r)); and the US Standard
    Atmosphere's bending at the surface is twice the horizontal refraction, 2 x 34.5'
    (Bennett 1982), to 15 % (the profile is log-linear between 5 km nodes, which misses
    the lowest kilometres' gradient)."""
    n0, hs = 2.78e-4, 8.0
    monkeypatch.setattr(limb_module, "_density", lambda z: np.exp(-z / hs))
    h = np.array([0.0, 10.0, 30.0])
    exact = n0 * np.sqrt(2 * np.pi * (6371.0 + h) / hs) * np.exp(-h / hs)
    np.testing.assert_allclose(limb_module._bending(h, n0), exact, rtol=5e-3)
    monkeypatch.undo()
    surface = np.degrees(limb_module._bending(np.array([0.0]), n0))[0] * 60
    assert surface == pytest.approx(69.0, rel=0.15)


def test_the_transmission_far_above_and_deep_below():
    assert np.all(limb_transmission([100.0, 200.0, 500.0], 2700.0) > 1 - 1e-4)
    assert limb_transmission(30.0, 0.0) == 1.0  # no atmosphere crossed
    # refraction reaches ~50 km into the geometric shadow at 2700 km; beyond: dark
    assert limb_transmission(-100.0, 2700.0) == 0.0
    assert 0.0 < limb_transmission(-20.0, 2700.0) < 0.01


@settings(max_examples=25, deadline=None)
@given(st.floats(-40.0, 120.0), st.floats(500.0, 3500.0))
def test_the_transmission_rises_with_the_ray(h, d):
    """Higher rays cross less air and are bent less: the transmission grows with height
    (each strip of the disc does), and stays in [0, 1]."""
    t = limb_transmission([h, h + 2.0], d)
    assert 0.0 <= t[0] <= t[1] <= 1.0 + 1e-9


def test_ozone_and_wavelength_act_as_they_should():
    t = limb_transmission(25.0, 2700.0)
    assert limb_transmission(25.0, 2700.0, ozone_optical_depth=0.0) > t
    assert limb_transmission(25.0, 2700.0, wavelength=800.0) > t  # less Rayleigh


def test_bad_input_is_refused():
    with pytest.raises(ValidationError, match="distance finite and >= 0"):
        limb_transmission(30.0, -1.0)
    with pytest.raises(ValidationError, match=r"ozone_optical_depth 2\.0"):
        limb_transmission(30.0, 100.0, ozone_optical_depth=2.0)
    with pytest.raises(ValidationError, match=r"same shape; got \(1, 3\) and \(2, 3\)"):
        limb_ray([[7000.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]] * 2)
