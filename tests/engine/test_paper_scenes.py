"""The paper's two CanX-1 experiments (paper 000 §4) as built-in scenes: what they must show."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import geometry
from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate


@pytest.fixture(scope="module")
def rotation():
    return simulate("canx1-rotation").compute()


@pytest.fixture(scope="module")
def plusx():
    return simulate("canx1-plusx-specular").compute()


def test_rotation_has_four_glints_90_deg_apart_in_the_paper_order(rotation):
    """Fig. 18: peaks +X -> +Y -> -X -> -Y, 90 deg apart; +-X brighter than +-Y."""
    brdf = rotation.brdf.isel(phase_angle=0)
    angle = rotation.attitude_angle.values
    peaks = []
    for start in range(0, 360, 90):  # one peak per quarter turn (the sweep starts 25 deg before +X)
        window = (angle >= start) & (angle < start + 90)
        peaks.append(angle[window][np.argmax(brdf.values[window])])
    # Body +X faces the bisector after 25 deg of rotation about -z, then +Y, -X, -Y; the
    # +-Y cells, tilted +-1 deg, glint 1 deg either side of their face's glint.
    np.testing.assert_allclose(peaks, [25.0, 115.0, 205.0, 295.0], atol=1.0)
    values = np.array([brdf.values[int(p)] for p in peaks])
    assert values[0] > 1.2 * values[1] and values[2] > 1.2 * values[3]  # cells glint in unison on X
    # Each glint stands far above the directional-diffuse base between the peaks.
    assert values.min() > 20 * np.median(brdf.values)


def test_rotation_cube_is_labelled_and_finite(rotation):
    for name in ("spacecraft_sbrdf", "signal", "brdf", "area", "signal_material"):
        assert np.all(np.isfinite(rotation[name].values)), name
        assert rotation[name].attrs["units"] and rotation[name].attrs["long_name"]
    assert rotation.sizes["attitude"] == 360
    np.testing.assert_allclose(
        geometry.phase_angle(rotation.to_sun.values, rotation.to_observer.values), 10.0
    )


def test_plusx_cell_features_move_to_shorter_wavelengths_as_beta_grows(plusx):
    """Fig. 14: the cell's interference features in 600-800 nm shift shorter with beta."""
    wl = plusx.wavelength.values
    band = (wl >= 620) & (wl <= 780)
    minima = {}
    for beta in plusx.phase_angle.values:
        spec = plusx.spacecraft_sbrdf.sel(phase_angle=beta).isel(attitude=0).values
        minima[float(beta)] = wl[band][np.argmin(spec[band])]
    # beta = 5 deg is theta_i = 2.5 deg, below the smallest measured 10 deg, where the
    # table is extrapolated; from there on the minimum moves monotonically.
    assert minima[90.0] < minima[60.0] <= minima[30.0]
    assert minima[90.0] <= minima[5.0] - 20.0
    # The cells dominate the +X side at specular.
    share = plusx.signal_material.sel(material="tjpv-cell") / plusx.signal_material.sum("material")
    assert float(share.mean()) > 0.5


def test_aluminium_feature_appears_off_specular():
    """Fig. 16: off specular the aluminium's ~800 nm absorption shows in the sBRDF."""
    scene = builtin_scene("canx1-plusx-specular").with_options(
        attitudes=geometry.axis_rotation([0, 0, 1], [0.0, 6.0, 10.0]), phase_angles=[30.0]
    )
    cube = simulate(scene).compute()
    wl = cube.wavelength.values
    band = (wl >= 700) & (wl <= 950)
    alu = cube.signal_material.sel(material="aluminium-6061-t6") / cube.signal_material.sum(
        "material"
    )
    at_specular, off = alu.isel(attitude=0, phase_angle=0), alu.isel(attitude=[1, 2], phase_angle=0)
    assert float(at_specular.mean()) < 0.3 < float(off.mean("wavelength").min())
    lo, hi = (wl >= 700) & (wl <= 720), (wl >= 930) & (wl <= 950)
    for k in (1, 2):
        spec = cube.spacecraft_sbrdf.isel(attitude=k, phase_angle=0).values
        # An absorption feature is located after continuum removal (the spectrum over the
        # straight line through its 700-720 and 930-950 nm means), not by the plain
        # minimum: the solar cells' coating has its reflectance minimum near 710-745 nm,
        # which tilts the total there (the generating models show the same).
        x0, x1 = wl[lo].mean(), wl[hi].mean()
        y0, y1 = spec[lo].mean(), spec[hi].mean()
        removed = spec / (y0 + (wl - x0) * (y1 - y0) / (x1 - x0))
        assert 790.0 <= wl[band][np.argmin(removed[band])] <= 880.0
        # the aluminium's own term has its minimum there too
        own = cube.signal_material.sel(material="aluminium-6061-t6").isel(attitude=k, phase_angle=0)
        assert 790.0 <= wl[band][np.argmin(own.values[band])] <= 880.0
