"""Tests of sbrdf_xr.materials.models: analytic materials as labelled parameter sets."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import catalog
from sbrdf_xr.materials import energy, models
from sbrdf_xr.materials import tables as material

WL = np.linspace(400.0, 1100.0, 15)


def paint(**kw):
    p = {"rho_D": 0.8, "epsilon": 0.12, "b": 0.1, "e": 0.35} | kw
    return models.model_material("robertson_sandford", WL, material="p", provenance="test", **p)


def test_render_equals_direct_evaluation_and_conserves_energy():
    spec = paint()
    lut = models.render(spec, theta_i=[0.0, 30.0, 60.0])
    assert lut.attrs["source"] == "model:robertson_sandford"
    n = 50
    rng = np.random.default_rng(0)
    ti = rng.choice([0.0, 30.0, 60.0], n)
    dt = rng.choice(
        lut.delta_theta.values[(lut.delta_theta.values >= -90) & (lut.delta_theta.values <= 30)], n
    )
    ph = rng.choice(lut.phi.values[lut.phi.values <= 60], n)  # table nodes: exact
    got, want = material.lookup(lut, ti, dt, ph).values, models.spectra(spec, ti, dt, ph)
    np.testing.assert_allclose(got[ti > 0], want[ti > 0], rtol=1e-12)
    # At theta_i = 0 the look-up is the row's in-plane profile at the observer's polar
    # angle (plane-independent normal incidence): linear in theta_r between 3-degree
    # nodes of a smooth lobe, ~3e-3.
    np.testing.assert_allclose(got[ti == 0], want[ti == 0], rtol=5e-3)
    # The whole-hemisphere table integrates to the model's directional reflectance
    # (1 - epsilon(theta_i) less the grazing cut-off): quadrature of a 1-degree
    # piecewise-linear interpolant of a smooth lobe (e = 0.35) is good to ~1e-3.
    from sbrdf_xr.brdf import robertson_sandford as rs

    rho = energy.hemispherical_reflectance(lut, warn=False).values
    p = {k: spec[k].values for k in ("rho_D", "epsilon", "b", "e")}
    expected = rs.directional_hemispherical_reflectance(np.array([0.0, 30.0, 60.0]), WL, **p)
    np.testing.assert_allclose(rho, expected, rtol=5e-3)


def test_measure_then_build_reproduces_measured_geometries():
    spec = paint()
    meas = models.measure(spec, (10.0, 30.0, 50.0, 70.0))
    assert meas.attrs["source"] == "synthetic" and "robertson_sandford" in meas.attrs["provenance"]
    lut = material.build_lut(meas, smoothing=0.0)
    spec0 = (meas.delta_theta == 0) & (meas.phi == 0)
    sel = meas.isel(sample=np.flatnonzero(spec0.values))
    got = material.lookup(lut, sel.theta_i.values, sel.delta_theta.values, sel.phi.values).values
    np.testing.assert_allclose(got, sel.measured_sbrdf.values, rtol=1e-10)


def test_canx1_catalog_models_show_their_spectral_features():
    al = catalog.load("aluminium-6061-t6-model")
    wl = al.wavelength.values
    s = models.spectra(al, 40.0, 0.0, 0.0)
    assert 780 <= wl[np.argmin(s)] <= 880  # aluminium's interband absorption near 800 nm
    cell = catalog.load("tjpv-cell-model")
    wl = cell.wavelength.values
    band = (wl >= 620) & (wl <= 780)
    minima = [
        wl[band][np.argmin(models.spectra(cell, t, 0.0, 0.0)[band])]
        for t in (2.5, 15.0, 30.0, 45.0)
    ]
    # the anti-reflection minimum moves to shorter wavelengths with angle: 715, 710, 695, 675 nm
    assert minima == sorted(minima, reverse=True) and minima[-1] <= minima[0] - 30
    paint_ = catalog.load("white-paint-a276-model")
    rho = paint_.rho_D.sel(wavelength=slice(500, 1100)).values
    assert np.ptp(rho) < 0.005  # flat above the titania edge (400-450 nm)


@pytest.mark.parametrize("method", ["nearest", "linear", "cubic"])
@pytest.mark.parametrize(
    "grid",
    [
        {},  # the default, whole hemisphere in 3-degree steps
        {
            "theta_i": [0.0, 45.0, 90.0],
            "delta_theta": [-180.0, -100.0, 0.0, 90.0],
            "phi": [0.0, 80.0, 90.0],
        },
        {"theta_i": [0.0, 30.0, 60.0, 90.0], "delta_theta": [-20.0, 0.0, 25.0], "phi": [0.0, 10.0]},
        {
            "theta_i": [10.0, 70.0],
            "delta_theta": [-50.0, -7.0, 3.0, 40.0],
            "phi": [0.0, 33.0, 89.0],
        },
    ],
)
def test_lambert_renders_exactly_on_any_grid(grid, method):
    # Below-horizon nodes carry the limit from the hemisphere (rho / pi), grid edges
    # inside the hemisphere are held: every look-up weight sums to one, so the table is
    # rho / pi at every lit and visible geometry to rounding (1e-9 asked).
    from sbrdf_xr import geometry

    wl = np.array([450.0, 700.0])
    rho = np.array([0.25, 0.8])
    spec = models.model_material("lambert", wl, material="l", provenance="test", rho=rho)
    lut = models.render(spec, **grid)
    rng = np.random.default_rng(11)
    s, o = rng.standard_normal((3000, 3)), rng.standard_normal((3000, 3))
    s[:, 2], o[:, 2] = np.abs(s[:, 2]) + 1e-12, np.abs(o[:, 2]) + 1e-12
    s[:5] = [[0, 0, 1], [1, 0, 1e-9], [0.3, 0.1, 1], [1, 1, 1e-6], [1e-9, 0, 1]]  # hard cases
    o[:5] = [[0.2, 0.3, 1], [-1, 0, 1e-9], [0, 1, 1e-9], [0, 0, 1], [0.5, 0, 1]]
    a = geometry.facet_angles(np.array([0.0, 0.0, 1.0]), s, o)
    ok = a.lit & a.visible
    got = material.lookup(lut, a.theta_i[ok], a.delta_theta[ok], a.phi[ok], method=method).values
    np.testing.assert_allclose(got, np.broadcast_to(rho / np.pi, got.shape), rtol=1e-9)
