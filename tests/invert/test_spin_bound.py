"""Branch-and-bound spin search: the lower bound holds, and the best states are the exact
search's.

The bound search must return the ``direct`` (brute-force, every candidate through the
kernel) search's best state and chi-square: same argmin, chi-square to 1e-9 relative (the
exact evaluations are the same kernel calls in other blocks; only the summation order of
the chi-square may differ, at 1e-15).
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from sbrdf_xr import invert
from sbrdf_xr.errors import FitQualityWarning, InversionError
from sbrdf_xr.invert._spin import bound as _bound
from sbrdf_xr.invert._spin import data as _spin_data
from sbrdf_xr.invert._spin import search as _spin_search

BANDS = ("V", "R", "I")
AXIS_BODY = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)


@functools.cache
def _kernel():
    from sbrdf_xr.body.spacecraft import canx1

    return _spin_search.Kernel(canx1(), BANDS)


def _problem(axis, period, phase, seed, offset="band", n=40, rel=0.02):
    """CanX-1 spinning about ``AXIS_BODY``, ``n`` times over 90 s, the observer moving
    through 40 degrees, noise ``rel`` of the mean signal."""
    t = np.linspace(0.0, 90.0, n)
    lc = xr.Dataset(
        {"flux": ("obs", np.ones(3 * n)), "flux_uncertainty": ("obs", np.ones(3 * n))},
        coords={"time": ("obs", np.repeat(t, 3)), "band": ("obs", np.tile(BANDS, n))},
    )
    d = invert.light_curve_fluxes(lc)
    az = np.radians(np.linspace(10.0, 50.0, n))
    o = np.stack([np.cos(az), np.sin(az), 0.2 * np.ones(n)], axis=-1)
    o /= np.linalg.norm(o, axis=1)[:, None]
    geo = _spin_data.spin_geometry(d["time"], None, [1.0, 0.2, 0.1], o)
    prob = _spin_search.Problem(d, geo, _kernel(), AXIS_BODY, offset)
    m = prob.model(np.asarray(axis)[None, :], np.array([period]), np.array([phase]))[0]
    sigma = rel * float(m.mean())
    d["flux"] = m + sigma * np.random.default_rng(seed).normal(size=m.size)
    d["sigma"] = np.full(m.size, sigma)
    return _spin_search.Problem(d, geo, _kernel(), AXIS_BODY, offset)


GRID = (invert.fibonacci_sphere(12), np.linspace(24.0, 36.0, 9), np.arange(8) * 45.0)


def _same_best(exact, found):
    assert int(np.argmin(found.grid)) == int(np.argmin(exact))
    # 1e-9: the same kernel values, summed in other blocks (rounding at 1e-15)
    np.testing.assert_allclose(found.grid.min(), exact.min(), rtol=1e-9)
    # every exactly evaluated cell is the exact chi-square, every bound below it
    np.testing.assert_allclose(found.grid[found.exact], exact[found.exact], rtol=1e-9)
    assert np.all(found.lower <= exact * (1 + 1e-9))


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    lon=st.floats(0.0, 360.0),
    lat=st.floats(-80.0, 80.0),
    period=st.floats(25.0, 35.0),
    phase=st.floats(0.0, 360.0),
    seed=st.integers(0, 2**16),
    offset=st.sampled_from(["band", "common"]),
    stride=st.sampled_from([1, 4]),
)
def test_bound_search_finds_the_exact_best_of_random_truths(
    lon, lat, period, phase, seed, offset, stride
):
    """Random truths, both offsets, with and without the first pass on every 4th time."""
    prob = _problem(invert.axis_vector(lon, lat), period, phase, seed, offset)
    exact = _spin_search.run_search("direct", prob, *GRID, 1, 360)
    found = _bound.search_bound(prob, *GRID, 1, 720, stride=stride)
    _same_best(exact, found)
    assert found.n_exact < exact.size  # it pruned


def test_bound_search_top_axes_are_exact():
    """With ``n_best`` axes, the best state of each of the best axes is the exact one."""
    prob = _problem(invert.axis_vector(40.0, 25.0), 30.0, 50.0, 3)
    exact = _spin_search.run_search("direct", prob, *GRID, 1, 360)
    found = _bound.search_bound(prob, *GRID, 1, 720, n_best=4)
    flat_e, flat_f = exact.reshape(exact.shape[0], -1), found.grid.reshape(exact.shape[0], -1)
    top = np.argsort(flat_e.min(axis=1))[:4]
    assert set(np.argsort(flat_f.min(axis=1))[:4]) == set(top)
    for a in top:
        assert int(np.argmin(flat_f[a])) == int(np.argmin(flat_e[a]))
        assert found.exact.reshape(flat_f.shape)[a, np.argmin(flat_f[a])]
    _same_best(exact, found)


def test_table_error_estimate_holds_against_the_kernel():
    """The stated error estimate of the tables, checked against the kernel at random
    candidates: no value beyond it (the estimate is not a proof: this measures it)."""
    prob = _problem(invert.axis_vector(200.0, -30.0), 28.0, 10.0, 5)
    bad, seen, worst = _bound.bound_violations(prob, *GRID, 720, n_samples=40, seed=1)
    assert seen == 40 * prob.y.size
    assert bad == 0 and worst < 1.0


@settings(max_examples=200, deadline=None)
@given(
    n=st.integers(2, 12),
    seed=st.integers(0, 2**32 - 1),
    scale=st.floats(1e-3, 1e3),
    rel_eps=st.floats(0.0, 0.5),
)
def test_lower_bound_lies_below_every_model_within_the_errors(n, seed, scale, rel_eps):
    """Models anywhere in the box ``|m - m~| <= eps`` (corners and inside): their
    chi-square with the best scale is never below the bound."""
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.5, 2.0, n)
    y = scale * rng.normal(1.0, 0.5, n)
    mt = rng.uniform(0.1, 1.0, n)
    eps = rel_eps * rng.uniform(0.0, 1.0, n) * mt
    c, lb = _bound.lower_bound(w @ (y * y), w @ (y * mt), w @ (mt * mt), w @ (eps * eps))
    for _ in range(20):
        corner = rng.integers(0, 2, n) * 2 - 1.0
        for m in (mt + corner * eps, mt + rng.uniform(-1, 1, n) * eps):
            k = (w @ (y * m)) / (w @ (m * m))
            assert w @ (y - k * m) ** 2 >= lb - 1e-12 * (w @ (y * y))
    assert lb <= c


def test_table_errors_refuses_odd_tables():
    with pytest.raises(InversionError, match="7 angles; allowed an even number >= 8"):
        _bound.table_errors(np.ones((7, 1)))


def test_fit_spin_bound_method_matches_direct():
    """``fit_spin(method="bound")``: the grid's best states and the fit are the direct
    search's."""
    from sbrdf_xr.body.spacecraft import canx1

    prob = _problem(invert.axis_vector(40.0, 25.0), 30.0, 50.0, 11)
    lc = xr.Dataset(
        {"flux": ("obs", prob.y), "flux_uncertainty": ("obs", prob.sigma)},
        coords={
            "time": ("obs", prob.times[prob.t_index] - prob.times[0]),
            "band": ("obs", np.array(BANDS)[prob.band]),
        },
    )
    kw = dict(
        to_sun=[1.0, 0.2, 0.1],
        to_observer=prob.o,
        periods=np.linspace(27.0, 33.0, 13),
        axis_body=AXIS_BODY,
        n_axes=30,
        n_starts=2,
        n_threads=1,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitQualityWarning)  # the twins of a cube-like body
        fb = invert.fit_spin(lc, canx1(), method="bound", **kw)
        fd = invert.fit_spin(lc, canx1(), method="direct", **kw)
    assert fb.attrs["search_method"] == "bound"
    assert "evaluated exactly" in fb.attrs["search_check"]
    np.testing.assert_allclose(float(fb["chi2"]), float(fd["chi2"]), rtol=1e-9)
    np.testing.assert_allclose(float(fb["period"]), float(fd["period"]), rtol=1e-9)
    np.testing.assert_allclose(fb["axis_vector"].values, fd["axis_vector"].values, atol=1e-9)
