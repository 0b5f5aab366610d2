"""Tests of sbrdf_xr.brdf.robertson_sandford_angular: G (Eq. 10) and H (Eq. 18)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from sbrdf_xr.brdf import robertson_sandford_angular as rs

#: Closed forms (Eqs. 10, 18) vs adaptive quadrature: 1e-10; quad is asked for 1e-13
#: so its own error is negligible.
TOL_CLOSED_FORM = 1e-10


def _s(theta_i: float) -> np.ndarray:
    t = np.radians(theta_i)
    return np.array([np.sin(t), 0.0, np.cos(t)])


# --- Eq. 10: G(b) -------------------------------------------------------------


def _g_quad(b: float) -> float:
    # Eq. 10 as written: (1/pi) int sin cos / (1 + b^2 tan^2) dtheta dphi
    f = lambda t: 2 * np.sin(t) * np.cos(t) ** 3 / (np.cos(t) ** 2 + b * b * np.sin(t) ** 2)  # noqa: E731
    return integrate.quad(f, 0, np.pi / 2, epsabs=0, epsrel=1e-13, limit=500)[0]


@pytest.mark.parametrize(
    "b",
    [
        0.0,
        1e-9,
        1e-3,
        0.08,
        0.12,
        0.5,
        0.7,
        0.71,
        1 - 1e-3,
        1 - 1e-9,
        1.0,
        1 + 1e-9,
        1 + 1e-3,
        1.2,
        1.3,
        2.0,
        5.0,
        30.0,
    ],
)
def test_G_closed_form_equals_quadrature(b):
    assert rs.normalisation_G(b) == pytest.approx(_g_quad(b), rel=TOL_CLOSED_FORM, abs=0)


def test_G_special_values_and_continuity():
    assert rs.normalisation_G(0.0) == 1.0
    assert rs.normalisation_G(1.0) == pytest.approx(0.5, rel=1e-15)
    # across the series/closed-form switch (|1 - b^2| = 0.5) and across b = 1
    for b0 in (np.sqrt(0.5), np.sqrt(1.5), 1.0):
        lo, hi = rs.normalisation_G(b0 * (1 - 1e-12)), rs.normalisation_G(b0 * (1 + 1e-12))
        assert abs(lo - hi) < 1e-11
    bs = np.linspace(0, 5, 2001)
    g = rs.normalisation_G(bs)
    assert np.all(np.diff(g) < 0) and np.all(g > 0)


# --- Eq. 18: H(theta_i) -------------------------------------------------------


def _h_quad(theta_i: float, e: float) -> float:
    """e^2 H by quadrature of (1/4 pi) int h dOmega_r in glint coordinates.

    With tan(alpha) = e tan(x) the inner integral is elementary:
    e^2 H = (1/pi) int_0^2pi [cos ti sin^2(xm)/2 + e cos(phi) sin ti (xm/2 - sin(2 xm)/4)] dphi
    where xm(phi) is the horizon limit; the azimuth integral is done by quad.
    """
    ti = np.radians(theta_i)

    def f(phi):
        beta = np.arctan2(np.cos(phi) * np.sin(ti), np.cos(ti))
        xm = np.arctan2(np.tan(0.5 * (beta + 0.5 * np.pi)), e)
        return np.cos(ti) * np.sin(xm) ** 2 / 2 + e * np.cos(phi) * np.sin(ti) * (
            xm / 2 - np.sin(2 * xm) / 4
        )

    v = integrate.quad(f, 0, np.pi, points=[np.pi / 2], epsabs=0, epsrel=1e-13, limit=500)[0]
    return 2 * v / np.pi


@pytest.mark.parametrize("e", [1e-6, 1e-3, 0.012, 0.12, 0.5, 1 - 1e-9, 1.0, 1 + 1e-9, 2.5])
@pytest.mark.parametrize("theta_i", [0.0, 1e-7, 20.0, 45.0, 70.0, 89.0, 90 - 1e-7, 90.0])
def test_H_closed_form_equals_quadrature(theta_i, e):
    expected = _h_quad(theta_i, e) / e**2
    assert rs.normalisation_H(theta_i, e) == pytest.approx(expected, rel=TOL_CLOSED_FORM)


def _eq18_as_printed(theta_i, e):
    c = np.cos(np.radians(theta_i))
    return (1 / (2 * e**2)) * (
        (1 - e**2) * c
        + (2 * e**2 + (1 - e**2) ** 2 * c**2) / np.sqrt((1 - e**2) ** 2 * c**2 + 4 * e**2)
    )


@pytest.mark.parametrize(("theta_i", "e"), [(0, 0.5), (40, 0.3), (75, 1.0), (30, 0.7)])
def test_H_definition_by_direct_quadrature(theta_i, e):
    """Eq. 18's integral in plain (theta_r, phi_r): the printed closed form equals it."""
    s = _s(theta_i)

    def f(phr, thr):
        o = np.array([np.sin(thr) * np.cos(phr), np.sin(thr) * np.sin(phr), np.cos(thr)])
        g = (o + s) / np.linalg.norm(o + s)
        return np.sin(thr) / (e**2 * g[2] ** 2 + g[0] ** 2 + g[1] ** 2) ** 2

    v = integrate.dblquad(f, 0, np.pi / 2, 0, 2 * np.pi, epsabs=0, epsrel=1e-11)[0] / (4 * np.pi)
    assert _eq18_as_printed(theta_i, e) == pytest.approx(v, rel=TOL_CLOSED_FORM)
    assert rs.normalisation_H(theta_i, e) == pytest.approx(v, rel=TOL_CLOSED_FORM)


def test_H_limits():
    assert rs.normalisation_H(0.0, 0.3) == pytest.approx(1 / (0.09 * 1.09), rel=1e-14)
    assert rs.normalisation_H(33.0, 1.0) == pytest.approx(0.5, rel=1e-14)
    assert rs.normalisation_H(90.0, 1e-6) == pytest.approx(1 / 2e-6, rel=1e-9)
    h = rs.normalisation_H(np.linspace(0, 90, 91), 1e-6)
    assert np.all(np.isfinite(h)) and np.all(np.diff(h) < 0)
