"""Profile-likelihood intervals of the joint fit's spin parameters
(:mod:`sbrdf_xr.invert._joint.profile`), against closed forms.

The profile of a parameter is the chi-square minimised over the others; for the small
models here it is known in closed form, and its crossings are found by an independent
root finder (scipy's brentq) to compare with.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from sbrdf_xr.invert._joint.profile import (
    QUADRATIC_TOL,
    profile_crossing,
    quadratic_check,
)


def _linear():
    rng = np.random.default_rng(5)
    a = rng.normal(size=(20, 3))
    y = rng.normal(size=20)
    q = np.linalg.lstsq(a, y, rcond=None)[0]

    def res(p):
        return a @ p - y

    return res, q, np.linalg.inv(a.T @ a)


def test_linear_model_profile_is_the_jacobians():
    """A model linear in its parameters: the chi-square is quadratic, the check's roots
    are -2 and 2 (to rounding) and the profile's crossings the Jacobian's 1 and 2 sigma
    (to the refit's tolerance, 1e-6 of a sigma)."""
    res, q, cov = _linear()
    c0 = float(res(q) @ res(q))
    for j in range(3):
        lo, hi = quadratic_check(lambda x: float(res(x) @ res(x)), q, cov, c0, j)
        assert lo == pytest.approx(-2.0, abs=1e-6) and hi == pytest.approx(2.0, abs=1e-6)
        out = profile_crossing(res, q, cov, c0, j)
        sd = np.sqrt(cov[j, j])
        np.testing.assert_allclose((np.array(out["high"]) - q[j]) / sd, [1, 2], atol=1e-6)
        np.testing.assert_allclose((q[j] - np.array(out["low"])) / sd, [1, 2], atol=1e-6)
        assert out["converged"] and out["dip"] > -1e-9


def _nonlinear():
    """r(t, b) = (t^3 - 1, b - t, b + t - 2) / 0.3: at fixed t the best b is 1, so the
    profile is chi2(t) = ((t^3 - 1)^2 + 2 (t - 1)^2) / 0.09, minimum 0 at t = 1."""

    def res(p):
        t, b = p
        return np.array([t**3 - 1.0, b - t, b + t - 2.0]) / 0.3

    def profile(t):
        return ((t**3 - 1.0) ** 2 + 2 * (t - 1.0) ** 2) / 0.09

    q = np.array([1.0, 1.0])
    h = 1e-6
    jac = np.column_stack([(res(q + d) - res(q - d)) / (2 * h) for d in np.eye(2) * h])
    return res, profile, q, np.linalg.inv(jac.T @ jac)


def test_nonlinear_profile_against_brentq():
    """A model cubic in t: its profile's Delta chi2 = 1 and 4 crossings (brentq on the
    closed form, to 1e-12) are asymmetric, their
    sides 7-8 % (Delta chi2 = 1) and 12-19 % (4) off the quadratic's; the search finds them to
    2 % of a sigma (linear interpolation of sqrt(Delta chi2) between grid points half a
    sigma apart, then one regula-falsi step: its error is the square of the bracket's
    curvature, below 1e-2 here), and the check flags the quadratic approximation."""
    res, profile, q, cov = _nonlinear()
    sd = np.sqrt(cov[0, 0])
    lo, hi = quadratic_check(lambda x: float(res(x) @ res(x)), q, cov, 0.0, 0)
    assert max(abs(lo + 2), abs(hi - 2)) > QUADRATIC_TOL
    out = profile_crossing(res, q, cov, 0.0, 0)
    for level, k in ((1.0, 0), (4.0, 1)):
        hi_true = brentq(lambda t, lv=level: profile(t) - lv, 1.0, 1.0 + 10 * sd, xtol=1e-12)
        lo_true = brentq(lambda t, lv=level: profile(t) - lv, 1.0 - 10 * sd, 1.0, xtol=1e-12)
        assert out["high"][k] == pytest.approx(hi_true, abs=0.02 * sd)
        assert out["low"][k] == pytest.approx(lo_true, abs=0.02 * sd)
        quad = np.sqrt(level) * sd
        sides = np.array([hi_true - 1.0, 1.0 - lo_true]) / quad
        assert np.abs(sides - 1).max() > 0.05  # not the quadratic's
    assert out["converged"]


def test_rippled_profile_takes_the_outermost_crossing():
    """A rippled profile, chi2(t) = t^2 (1 + 0.9 cos 2 pi t), which crosses 1 going up
    near 0.84, down near 1.32 and up again near 1.63: the outermost crossings of 1 and 4
    are reported (brentq on the closed form; 0.02 allowed, the interpolation's error
    after one regula-falsi step in a bracket of half a unit)."""

    def f(t):
        return t * t * (1.0 + 0.9 * np.cos(2 * np.pi * t))

    def res(p):
        return np.array([np.sign(p[0]) * np.sqrt(f(p[0])), p[1]])

    out = profile_crossing(res, np.zeros(2), np.eye(2), 0.0, 0, grid=(0.5, 1.0, 1.5, 2.0))
    for k, level in enumerate((1.0, 4.0)):
        outer = brentq(lambda t, lv=level: f(t) - lv, 1.5, 2.0)
        assert out["high"][k] == pytest.approx(outer, abs=0.02)
        assert out["low"][k] == pytest.approx(-outer, abs=0.02)
    assert out["converged"]
