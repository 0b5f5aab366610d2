"""``build_lut(check_energy="clamp")``: every row's directional-hemispherical reflectance
bounded by 1, the measured plane of an in-plane scan kept."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from sbrdf_xr import catalog
from sbrdf_xr.errors import NonPhysicalWarning
from sbrdf_xr.kernels.lut import hemispherical_reflectance_kernel
from sbrdf_xr.materials import build_lut, hemispherical_reflectance, models
from sbrdf_xr.materials.energy import _clamp_energy
from sbrdf_xr.materials.readers import measurement_set


def _grid():
    return np.array([0.0, 20.0, 40.0]), np.linspace(-180.0, 90.0, 55), np.linspace(0.0, 90.0, 19)


def test_an_over_bright_row_reflects_one_and_keeps_its_plane():
    """A row at 3x the reflectance of 1 (a constant 3 / pi sr-1): scaled to exactly 1 by
    the quadrature of its own interpolant (linear in the values: exact to rounding), its
    phi = 0 nodes untouched; a row within the bound is left as it is."""
    g = _grid()
    lut = np.empty((3, 55, 19, 2))
    lut[..., 0] = 3.0 / np.pi
    lut[..., 1] = 0.5 / np.pi
    before = lut.copy()
    out = _clamp_energy(lut, g, (True, True, True), 0.0)
    rho = hemispherical_reflectance_kernel(lut, *g, None, zero_edges=(True,) * 3)
    np.testing.assert_allclose(rho[:, 0], 1.0, rtol=1e-12)
    np.testing.assert_array_equal(lut[:, :, 0, :], before[:, :, 0, :])
    np.testing.assert_array_equal(lut[..., 1], before[..., 1])
    assert out["energy_clamp_theta_i"] == [0.0, 20.0, 40.0]
    assert 0.0 < out["energy_clamp_min_scale"] < 1.0 / 2.0


def test_a_table_within_the_bound_is_not_touched():
    g = _grid()
    lut = np.full((3, 55, 19, 1), 0.2)
    assert _clamp_energy(lut, g, (True, True, True), 5.0) == {}
    assert np.all(lut == 0.2)


def _bright_scan():
    """An in-plane scan that reflects more than it receives: a lobe reflecting about
    0.7, its values three times too large (a calibration error of the scan)."""
    spec = models.model_material(
        "robertson_sandford", [550.0], material="bright", provenance="test",
        rho_D=0.4, epsilon=0.4, b=0.1, e=0.3,
    )  # fmt: skip
    t, s = (a.ravel() for a in np.meshgrid([10.0, 35.0, 60.0], np.arange(-85.0, 86.0, 1.0),
                                            indexing="ij"))  # fmt: skip
    d = s - t
    vals = 3.0 * models.spectra(spec, t, d, 0.0)
    return measurement_set(t, d, np.zeros_like(t), [550.0], vals, material="bright",
                           provenance="test")  # fmt: skip


@pytest.mark.slow
def test_an_in_plane_build_is_clamped_and_still_reproduces_its_samples():
    ds = _bright_scan()
    with pytest.warns(NonPhysicalWarning, match="does not conserve energy"):
        plain = build_lut(ds, holdout=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonPhysicalWarning)  # the check passes after it
        table = build_lut(ds, holdout=0, check_energy="clamp")
    rows = np.arange(0.0, 91.0, 5.0)
    assert hemispherical_reflectance(plain, rows, warn=False).max() > 1.05
    assert float(hemispherical_reflectance(table, rows, warn=False).max()) <= 1.0 + 1e-9
    assert table.attrs["self_check_worst"] < 1e-9  # the measured plane is kept
    assert len(table.attrs["energy_clamp_theta_i"]) > 0


@pytest.mark.slow
def test_the_shipped_chassis_reflects_at_most_one():
    """Its energy check is on again (no skip in the catalog) and passes: 1.1-1.4 before."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonPhysicalWarning)
        table = catalog.load("starlink-v1.5-chassis")
    rho = hemispherical_reflectance(table, np.arange(0.0, 91.0, 5.0), warn=False)
    assert float(rho.max()) <= 1.0 + 1e-9
    assert table.attrs["self_check_worst"] < 1e-9
    assert 0.1 < table.attrs["energy_clamp_min_scale"] < 1.0
