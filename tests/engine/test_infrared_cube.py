"""Wavelengths past 4 um through the plan and the cube: an LWIR cube end to end (issue 46)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
import xarray as xr
from scipy import integrate

from sbrdf_xr import Scene, load_spacecraft, simulate
from sbrdf_xr.engine.spectral import solar_for
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.photometry import solar_spectrum
from sbrdf_xr.photometry.inband import in_band
from sbrdf_xr.sources import planck

WL = np.arange(2500.0, 25001.0, 250.0)  # [nm]
TO_SUN = [[1.0, 0.0, 0.0]]
TO_OBS = [[np.cos(0.3), np.sin(0.3), 0.0]]


def _scene(**kw):
    box = load_spacecraft(trimesh.creation.box(), material="grey")
    return Scene(
        box, {"grey": lambertian(0.3, WL, material="grey")}, to_sun=TO_SUN, to_observer=TO_OBS, **kw
    )


def test_thermal_only_past_4_um_is_planned():
    """The issue's refusal (3000-15000 nm with effects=('thermal',)) is gone."""
    plan = _scene(effects=("thermal",)).plan()
    assert "thermal" in plan.effects and plan.wavelength[-1] == 25000.0


def test_lwir_cube_emission_is_kirchhoff_times_planck():
    """A grey Lambertian box (albedo 0.3) at 290 K: emissivity 0.7 (Kirchhoff), projected
    area cos(0.3) + sin(0.3) of the two faces seen; float64 rounding only (1e-12)."""
    cube = simulate(
        _scene(
            effects=("sunlight", "thermal"),
            temperature=290.0,
            bands=("MWIR", "LWIR", "N", "W2"),
            outputs=("signal", "band_signal"),
        )
    ).compute()
    seen = np.cos(0.3) + np.sin(0.3)  # [m2] of the unit cube
    expected = 0.7 * seen * planck(WL, 290.0)
    assert cube["thermal_intensity"].isel(geometry=0).values == pytest.approx(expected, rel=1e-12)
    assert cube["band_signal"].sizes["band"] == 4
    assert cube["thermal_intensity"].attrs["units"] == "W sr-1 nm-1"
    # in-band LWIR intensity [W sr-1]: reflected sunlight plus emission
    sun = solar_spectrum(WL, solar="astm_g173_extended")
    reflected = cube["signal"].isel(geometry=0) * sun
    reflected.attrs["units"] = "W sr-1 nm-1"
    total = in_band(reflected + cube["thermal_intensity"].isel(geometry=0), ["LWIR"])
    emitted = in_band(cube["thermal_intensity"].isel(geometry=0), ["LWIR"])
    # against quadrature of Planck over 8-12 um less the two 1-nm ramps (half each);
    # the trapezoid rule on the 0.25-um grid is good to ~1e-4 for this smooth curve
    box = integrate.quad(lambda x: float(planck(x, 290.0)), 8000.0, 12000.0)[0]
    box -= 0.5 * float(planck(8000.0, 290.0) + planck(12000.0, 290.0))
    assert float(emitted[0]) == pytest.approx(0.7 * seen * box, rel=1e-3)
    assert 0 < float(total[0] - emitted[0]) < 0.01 * float(emitted[0])  # sunlight is small


def test_solar_spectrum_of_the_engine():
    assert solar_for(np.array([400.0, 700.0]), ["V"]) == "astm_g173"
    assert solar_for(np.array([2500.0, 25000.0])) == "astm_g173_extended"


def test_in_band_refuses_a_band_past_the_spectrum():
    s = xr.DataArray(
        np.ones(3),
        dims="wavelength",
        coords={"wavelength": [8000.0, 9000.0, 10000.0]},
        attrs={"units": "W m-2 nm-1"},
    )
    from sbrdf_xr.errors import ValidationError

    with pytest.raises(ValidationError, match="LWIR"):
        in_band(s, ["LWIR"])
    assert float(in_band(s, ["N"][:0] or [("box", ([8000.0, 10000.0], [1.0, 1.0]))])[0]) == 2000.0


def test_kirchhoff_emissivity_of_a_rendered_paint_is_the_models():
    """The thermal effect's emissivity (1 - the table's hemispherical reflectance) against
    the model's own 1 - rho(theta_i) for paper 001's AFGL-01: a 1-degree table integrates
    the glint lobe (FWHM 19 deg) to ~4e-5 (measured), hence 1e-4."""
    from sbrdf_xr.brdf import robertson_sandford as rs
    from sbrdf_xr.materials.energy import hemispherical_reflectance
    from sbrdf_xr.materials.model_schema import model_material
    from sbrdf_xr.materials.models import render
    from sbrdf_xr.sources import kirchhoff_emissivity

    p = dict(rs.TABLE4["AFGL-01"])
    wl = [4000.0, 10000.0]
    spec = model_material("robertson_sandford", wl, material="afgl01", provenance="Table 4", **p)
    ti = np.array([0.0, 20.0, 40.0, 60.0, 80.0])
    grid = (np.arange(-180.0, 90.1, 1.0), np.arange(0.0, 90.1, 1.0))
    lut = render(spec, ti, *grid, progress=False)
    eps_table = kirchhoff_emissivity(hemispherical_reflectance(lut, ti, warn=False).values)
    eps_model = 1.0 - rs.directional_hemispherical_reflectance(ti, wl, **p)
    assert eps_table == pytest.approx(eps_model, abs=1e-4)
