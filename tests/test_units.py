"""Units never silently wrong: Quantities converted or refused by name, implausible bare
numbers warned about with the likely unit, length units read case-sensitively."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
import trimesh
from astropy.coordinates import Angle
from astropy.time import Time

from sbrdf_xr import photometry as P
from sbrdf_xr import units
from sbrdf_xr.body.spacecraft import load_spacecraft
from sbrdf_xr.errors import UnitError, UnitWarning, ValidationError
from sbrdf_xr.geometry.rotations import axis_rotation
from sbrdf_xr.materials.schema import constant_material, lambertian
from sbrdf_xr.observing.attitude import Nadir, Spin
from sbrdf_xr.observing.orbits import Site, airmass
from sbrdf_xr.observing.timescales import times
from sbrdf_xr.sources import earthshine_irradiance_ratio, planck


def test_quantities_convert_and_other_kinds_are_refused_by_name():
    assert units.to_unit(1e6 * u.m, "km", "range_km") == 1000.0
    assert units.to_unit(2.0, "km", "range_km") == 2.0  # a bare number: the documented unit
    np.testing.assert_allclose(units.to_unit([0.4, 1.1] * u.um, "nm", "wavelength"), [400, 1100])
    # frequencies are wavelengths only where asked (a wavelength argument)
    assert units.to_unit(299792458.0 * u.GHz, "nm", "w", spectral=True) == pytest.approx(1.0)
    with pytest.raises(
        UnitError, match=r"range_km: got 1\.0 GHz \(frequency\), which is not in km"
    ):
        units.to_unit(1.0 * u.GHz, "km", "range_km")
    with pytest.raises(
        UnitError, match=r"step_s: got 3\.0 m \(length\), which is not in s \(time\)"
    ):
        units.to_unit(3.0 * u.m, "s", "step_s")


def test_observing_arguments_take_quantities():
    a = Site(Angle("20d42m30s"), -156.2575 * u.deg, 3.058 * u.km)
    assert a.latitude == pytest.approx(20.708333, abs=1e-6) and a.height == 3058.0
    with pytest.raises(UnitError, match=r"site height: got 3\.0 s"):
        Site(0.0, 0.0, 3.0 * u.s)
    spin = Spin(rate=np.pi / 90 * u.rad / u.s, phase=0.5 * u.rad)
    assert spin.rate == pytest.approx(2.0) and spin.phase == pytest.approx(28.64789, 1e-6)
    assert Nadir(yaw=0.25 * u.cycle).yaw == pytest.approx(90.0)
    t = times(Time("2024-03-17T01:20:37", scale="tai"), "2024-03-17T01:21:00", 0.5 * u.min)
    assert [str(x)[11:19] for x in t] == ["01:20:00", "01:20:30", "01:21:00"]  # TAI - UTC = 37 s
    np.testing.assert_allclose(airmass(np.pi / 2 * u.rad), airmass(90.0))
    np.testing.assert_allclose(
        axis_rotation([0, 0, 1], np.pi * u.rad), axis_rotation([0, 0, 1], 180)
    )


def test_wavelength_axes_in_micrometres_are_converted_or_warned_about():
    w_um = np.array([0.4, 0.55, 0.7, 0.9, 1.1])
    a = lambertian(0.5, w_um * u.um)
    np.testing.assert_allclose(a.wavelength.values, w_um * 1e3)
    with pytest.warns(
        UnitWarning,
        match=r"wavelengths 0\.4-1\.1: micrometres\? the axis is in nm "
        r"\(400-1100 nm if they were micrometres\)",
    ):
        lambertian(0.5, w_um)
    with pytest.warns(UnitWarning, match="metres?"):
        constant_material(0.1, w_um * 1e-6, material="grey")
    # the warning says why the error that follows (no overlap with V) happens
    with (
        pytest.warns(UnitWarning, match="micrometres"),
        pytest.raises(ValidationError, match=r"the spectrum covers only 0\.4-1\.1 nm"),
    ):
        P.band_weights(["V"], w_um)
    a, b = P.band_weights(["V"], w_um * u.um).values, P.band_weights(["V"], w_um * 1e3).values
    # 0.7 um is 700.0000000000001 nm, where the V curve ends: a weight 1e-16 of the largest
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * b.max())
    # Planck's law holds at any wavelength (the axes are checked where they are made)
    assert planck(10.0 * u.um, 300.0 * u.K) == pytest.approx(planck(10_000.0, 300.0))


def test_ranges_and_distances_outside_their_plausible_span_warn():
    with pytest.warns(
        UnitWarning,
        match=r"range: 1\.2e\+09 km is above the plausible 1e\+07 km: "
        r"metres\? the value is read in km \(1\.2e\+06 km if it were metres\)",
    ):
        earthshine_irradiance_ratio(0.3, 1.2e9, 0.0)
    assert earthshine_irradiance_ratio(0.3, 42164.0 * u.km, 0.0) == pytest.approx(
        earthshine_irradiance_ratio(0.3, 4.2164e7 * u.m, 0.0)
    )
    wl = np.arange(300.0, 1101.0, 10.0)
    import xarray as xr

    cube = xr.Dataset(
        {"signal": (("geometry", "wavelength"), np.full((1, wl.size), 0.1), {"units": "m2 sr-1"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    )
    with pytest.warns(UnitWarning, match="sun_distance: 1.496e\\+08 au is above"):
        P.magnitudes(cube, ["V"], range=1000.0, sun_distance=1.496e8)
    m = P.standard_magnitude(P.magnitudes(cube, ["V"], range=2000.0), 2e6 * u.m)
    np.testing.assert_allclose(
        m.values, P.standard_magnitude(P.magnitudes(cube, ["V"], range=2000.0), 2000.0).values
    )


def test_mesh_length_units_are_case_sensitive_where_si_prefixes_are():
    assert units.metres_per("mm") == 1e-3 and units.metres_per("MM") == 1e-3
    assert units.metres_per("Millimetre") == 1e-3
    assert units.metres_per(u.imperial.inch) == pytest.approx(0.0254, rel=1e-12)
    assert units.metres_per(25.4 * u.mm) == pytest.approx(0.0254)
    with pytest.raises(UnitError, match="'Mm' is the megametre"):
        units.metres_per("Mm")
    with pytest.raises(UnitError, match="got 'furlong', which is not a length unit"):
        units.metres_per("furlong")
    with pytest.raises(UnitError, match=r"got 1\.0 s \(time\)"):
        units.metres_per(u.s)
    box = trimesh.creation.box(extents=(100.0, 100.0, 100.0))
    sc = load_spacecraft(box, material="paint", length_unit="Millimeter")
    np.testing.assert_allclose(sc.mesh.extents, 0.1)


def test_a_mesh_unit_contradicting_the_file_or_an_implausible_size_warns(tmp_path):
    box = trimesh.creation.box(extents=(100.0, 100.0, 100.0))  # a 10 cm cube, in mm
    box.units = "mm"
    box.export(tmp_path / "cube.3mf")  # 3MF states its unit
    sc = load_spacecraft(tmp_path / "cube.3mf", material="paint")  # follows the file
    np.testing.assert_allclose(sc.mesh.extents, 0.1, rtol=1e-6)
    with pytest.warns(
        UnitWarning,
        match=r"length_unit='m' reads the coordinates in 1 m units, "
        r"but the file states they are in 'millimeter' \(0\.001 m\)",
    ):
        load_spacecraft(tmp_path / "cube.3mf", material="paint", length_unit="m")
    big = trimesh.creation.box(extents=(2000.0, 2000.0, 2000.0))  # 2 m in mm, read as metres
    with pytest.warns(
        UnitWarning,
        match=r"largest side: 2000 m is above the plausible 500 m: "
        r"millimetres\? .*\(2 m if it were millimetres\); give the file's unit",
    ):
        load_spacecraft(big, material="paint")
