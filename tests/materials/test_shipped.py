"""Tests of sbrdf_xr.materials.shipped: the model reflectances shipped beside the catalog's fits."""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr.errors import NonPhysicalWarning, ValidationError
from sbrdf_xr.materials import models, shipped
from sbrdf_xr.materials import tables as M


def _build_catalog():
    """``tools/build_catalog.py`` (not part of the package), imported by path."""
    path = Path(__file__).resolve().parents[2] / "tools" / "build_catalog.py"
    spec = importlib.util.spec_from_file_location("tools_build_catalog", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: (model file, rows, wavelengths) of every catalog table built with its fit's reflectance
SHIPPED = _build_catalog().shipped_reflectances()


def test_every_renormalised_catalog_table_has_a_shipped_reflectance():
    fits = sorted(f.name for f, _, _ in SHIPPED)
    assert fits == [
        "aluminium-6061-t6-microfacet-fit.nc",
        "tjpv-cell-coated-fit.nc",
        "white-paint-a276-fit.nc",
    ]


@pytest.mark.parametrize("fit, ti, wl", SHIPPED, ids=[f.stem for f, _, _ in SHIPPED])
def test_shipped_reflectance_is_current_and_is_the_quadrature(fit, ti, wl):
    rho = shipped.read_reflectance(fit, ti, wl)
    assert rho is not None, (
        f"{shipped.reflectance_file(fit).name} is missing or stale (its model, rows or the "
        "code that computes it changed): run python tools/build_catalog.py reflectances"
    )
    assert rho.dims == ("theta_i", "wavelength") and rho.attrs["units"] == "1"
    np.testing.assert_array_equal(rho.theta_i, ti)
    np.testing.assert_array_equal(rho.wavelength, wl)
    # Three rows recomputed by the model's own quadrature: the same arithmetic on the
    # same nodes, so equal to the last bits but for the summation blocking of the
    # matrix product (a few units of 1e-16); 1e-13 leaves room for that only.
    mod, _, kw = models.model_parameters(models.open_model(fit))
    rows = [0, 47, ti.size - 1]
    direct = mod.directional_hemispherical_reflectance(np.minimum(ti[rows], 90.0), wl, **kw)
    np.testing.assert_allclose(rho.values[rows], direct, rtol=1e-13, atol=0)


def test_a_changed_model_file_or_other_rows_find_no_shipped_reflectance(tmp_path):
    fit, ti, wl = SHIPPED[-1]
    copy = tmp_path / fit.name
    shutil.copy(fit, copy)
    shutil.copy(shipped.reflectance_file(fit), shipped.reflectance_file(copy))
    assert shipped.read_reflectance(copy, ti, wl) is not None  # the same bytes
    assert shipped.read_reflectance(copy, ti[:-1], wl) is None
    assert shipped.read_reflectance(copy, ti, wl + 1e-9) is None
    with open(copy, "ab") as f:  # the model file changed
        f.write(b"\0")
    assert shipped.read_reflectance(copy, ti, wl) is None
    assert shipped.read_reflectance(tmp_path / "none.nc", ti, wl) is None


def _gloss():
    wl = np.linspace(450.0, 1000.0, 4)
    spec = models.model_material(
        "microfacet", wl, material="gloss", provenance="test", roughness=0.1, n=1.5, k=0.0,
        rho_d=0.05,
    )  # fmt: skip
    return spec, models.measure(spec, (10.0, 25.0, 40.0, 55.0, 70.0)), wl


def test_build_lut_with_the_model_reflectance_given_is_the_same_table():
    spec, meas, wl = _gloss()
    kw = dict(below_noise="model", model=spec, extrapolation="model", n_phi=11, n_delta_theta=11)
    built = M.build_lut(meas, **kw)
    mod, _, p = models.model_parameters(spec)
    ti = built.theta_i.values
    rho = xr.DataArray(
        mod.directional_hemispherical_reflectance(np.minimum(ti, 90.0), wl, **p),
        dims=("theta_i", "wavelength"),
        coords={"theta_i": ti, "wavelength": wl},
    )
    given = M.build_lut(meas, model_reflectance=rho, **kw)
    xr.testing.assert_identical(given, built)
    # the reflectance steers the table: twice the model's reflectance, twice the table
    with pytest.warns(NonPhysicalWarning, match="misses its own samples"):  # the self-check
        doubled = M.build_lut(meas, model_reflectance=2.0 * rho, **kw)
    np.testing.assert_allclose(doubled.values, 2.0 * built.values, rtol=1e-12)
    with pytest.raises(ValidationError, match="model_reflectance: its theta_i"):
        M.build_lut(meas, model_reflectance=rho.isel(theta_i=slice(1, None)), **kw)
    with pytest.raises(ValidationError, match=r"expected an xarray\.DataArray with dims"):
        M.build_lut(meas, model_reflectance=rho.values, **kw)
