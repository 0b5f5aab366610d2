"""Tests of sbrdf_xr.engine.spectral: band-only plans pre-integrate the tables.

The claim is exactness: a band-only plan looks up tables integrated over filter x Sun
once per plan, and its ``band_signal`` equals the full-spectrum signal of the same scene
integrated over the same band weights afterwards, to 1e-12 relative.  The facet sum
and the nearest and linear look-ups are linear in f_r, and every term (f_r, weights,
areas) is non-negative, so the two orders of summation differ by rounding only: about
n eps for n = 11-141 wavelengths (< 2e-14), far below the 1e-12 asserted.  Cubic
look-up clips each material's sums at 0 and is not linear: it is not claimed.
"""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import catalog
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene, simulate
from sbrdf_xr.materials import models

BANDS = ("V", "R", "I")
MAT = T.TEST_SPACECRAFT_MATERIAL


def _pairs(n, seed):
    rng = np.random.default_rng(seed)
    s, o = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    o[: n // 5] = s[: n // 5]  # back-scatter among them
    return s / np.linalg.norm(s, axis=1)[:, None], o / np.linalg.norm(o, axis=1)[:, None]


def _anisotropic_table():
    wl = np.linspace(400.0, 1100.0, 8)
    spec = models.model_material(
        "anisotropic_microfacet",
        wl,
        material=MAT,
        provenance="test",
        alpha_x=0.2,
        alpha_y=0.5,
        n=np.linspace(1.2, 1.5, 8),
        k=np.linspace(6.0, 7.0, 8),
        rho_d=0.01,
    )
    grids = (np.arange(0, 91, 10.0), np.arange(-180, 91, 10.0), np.arange(0, 91, 10.0))
    return models.render_anisotropic(spec, *grids, np.arange(0.0, 181.0, 20.0))


def _scene(name):
    s, o = _pairs(300, 5)
    lobe = {MAT: T.make_material(n_wavelength=11)}
    pairs = dict(to_sun=s, to_observer=o, bands=BANDS)
    if name == "cube, linear":
        return Scene(T.cube_spacecraft(1.0, subdivisions=2), materials=lobe, **pairs)
    if name == "cube, nearest, unmerged":
        return Scene(T.cube_spacecraft(1.0), materials=lobe, method="nearest", merge=False, **pairs)
    if name == "L, exact shadowing":
        return Scene(
            T.l_shaped_spacecraft(), materials=lobe, effects=("sunlight", "shadowing"), **pairs
        )
    if name == "cube, anisotropic table":
        sc = T.cube_spacecraft(1.0, subdivisions=1).with_tangent((1.0, 0.3, 0.2))
        return Scene(sc, materials={MAT: _anisotropic_table()}, **pairs)
    raise KeyError(name)


def _assert_band_exact(scene):
    pre = scene.with_options(outputs=("band_signal", "area")).plan()
    full = scene.with_options(outputs=("signal", "area")).plan()
    assert pre.pre_integrated and pre.tables.n_spectral == len(BANDS)
    assert not full.pre_integrated and full.tables.n_spectral == full.wavelength.size > 3
    assert np.array_equal(pre.band_weights, full.band_weights)
    band = simulate(pre).band_signal.values
    signal = simulate(full).signal.values
    after = np.einsum("...l,bl->...b", signal, full.band_weights)
    assert (after > 0).mean() > 0.3  # most geometries light and show something
    # n eps for n summands of one sign (module docstring); zeros are exact
    np.testing.assert_allclose(band, after, rtol=1e-12, atol=0.0)
    np.testing.assert_array_equal(simulate(pre).area.values, simulate(full).area.values)


@pytest.mark.parametrize(
    "name",
    ["cube, linear", "cube, nearest, unmerged", "L, exact shadowing", "cube, anisotropic table"],
)
def test_band_only_equals_the_full_spectrum_integrated_afterwards(name):
    _assert_band_exact(_scene(name))


@pytest.mark.slow
def test_canx1_band_only_equals_the_full_spectrum_integrated_afterwards():
    """The measured CanX-1 tables (141 wavelengths, three materials) on random attitudes."""
    from sbrdf_xr import geometry
    from sbrdf_xr.engine import builtin_scene

    scene = builtin_scene("canx1-rotation").with_options(
        attitudes=geometry.uniform_attitudes(500, seed=2), attitude_angle=None, bands=BANDS
    )
    _assert_band_exact(scene)


def test_lambertian_band_signal_is_the_albedo_over_pi():
    """A grey Lambertian 1 x 2 m plate lit and seen along its normal: each band's signal
    is its f_r (0.5 / pi sr-1 as the catalog stores it) times its 2 m2, whatever the
    band's weights (they sum to one)."""
    sc = T.plate_spacecraft(front="grey", back=None)
    z = [[0.0, 0.0, 1.0]]
    grey = {"grey": catalog.load("lambertian-grey-50")}
    scene = Scene(
        sc, materials=grey, to_sun=z, to_observer=z, bands=BANDS, outputs=("band_signal",)
    )
    assert scene.plan().pre_integrated
    band = simulate(scene).band_signal.values[0]
    f_r = np.unique(np.asarray(grey["grey"].values, dtype=np.float64))
    assert f_r.size == 1 and abs(f_r[0] - 0.5 / np.pi) < 1e-7  # 0.5 / pi as stored (float32)
    np.testing.assert_allclose(band, f_r[0] * 2.0, rtol=1e-12)
