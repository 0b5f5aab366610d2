"""Photometry of a pass cube: its own range, Sun distance and airmass; lengths as Quantities."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import photometry as P
from sbrdf_xr.errors import RenamedWarning, UnitError, ValidationError
from sbrdf_xr.observing import observe
from sbrdf_xr.observing.orbits import Orbit, Site
from sbrdf_xr.observing.timescales import times

#: Per-time coordinates a simulated pass cube carries from its observation.
PER_TIME = ("range", "elevation", "phase_angle", "sun_distance", "sunlit_fraction", "airmass")


@pytest.fixture(scope="module")
def pass_cube():
    """A pass cube: the real geometry of a sunlit CanX-1 pass, a grey signal per time.

    A grey signal ``c_t`` has band signal ``c_t`` in every band exactly, so the expected
    magnitude is closed form: ``m_sun(1 au) - 2.5 log10(c_t (1 au / r_t)^2 / d_t^2)``.
    """
    obs = observe.Observation(
        Orbit.from_catalog("canx1-example"),
        Site.from_catalog("mont-megantic"),
        times("2024-03-17T01:21:20", "2024-03-17T01:24:00", 20.0),
        observe.canx1_attitude(),
        name="short-pass",
    )
    g = obs.geometry()
    wl = np.arange(300.0, 1101.0, 10.0)
    c = np.linspace(0.01, 0.03, g.sizes["time"])
    signal = np.repeat(c[:, None], wl.size, axis=1)
    return xr.Dataset(
        {"signal": (("time", "wavelength"), signal, {"units": "m2 sr-1"})},
        coords={
            "time": g.time,
            "wavelength": ("wavelength", wl, {"units": "nm"}),
            **{k: g[k] for k in PER_TIME},
        },
        attrs=g.attrs,
    ), c


def _closed_form(c, range_km, sun_au, bands):
    msun = P.sun_magnitudes(bands).values
    flux = (
        c[:, None] * (1.0 / np.asarray(sun_au)[..., None]) ** 2 / (range_km * 1e3)[..., None] ** 2
    )
    return msun[None, :] - 2.5 * np.log10(flux)


def test_magnitudes_use_the_cubes_range_and_sun_distance_per_time(pass_cube):
    cube, c = pass_cube
    d = cube["range"].values  # km, per time
    r = cube["sun_distance"].values  # au, per time
    assert np.ptp(d) > 200.0 and np.all(r < 0.996)  # a moving range; March, not 1 au
    m = P.magnitudes(cube, ["V", "R"])
    # float64 logarithms of the same numbers in another order: a few ulp of ~10 mag.
    np.testing.assert_allclose(m.values, _closed_form(c, d, r, ["V", "R"]), rtol=0, atol=1e-12)
    assert m.dims == ("time", "band")
    assert "the cube's 'range'" in m.attrs["range_source"]
    assert "the cube's 'sun_distance'" in m.attrs["sun_distance_source"]
    assert "range_override" not in m.attrs
    xr.testing.assert_identical(cube.sbrdf.magnitudes(["V", "R"]), m)
    ph = cube.sbrdf.photometry(["V", "R"])
    xr.testing.assert_identical(ph.magnitude, m)
    assert "the cube's 'range'" in ph.attrs["range_source"]


def test_an_explicit_value_overrides_and_says_so(pass_cube):
    cube, c = pass_cube
    m = P.magnitudes(cube, ["V"], range=1300.0, sun_distance=1.0)
    np.testing.assert_allclose(
        m.values, _closed_form(c, np.full(c.size, 1300.0), np.ones(c.size), ["V"]), atol=1e-12
    )
    lo, hi = cube["range"].values.min(), cube["range"].values.max()
    note = m.attrs["range_override"]
    assert "1300 km" in note and f"{lo:.6g} to {hi:.6g} km over time" in note
    assert "overrides the cube's 'sun_distance'" in m.attrs["sun_distance_override"]
    assert m.attrs["range_source"] == "argument range (1300 km)"


def test_a_length_quantity_is_converted_and_other_quantities_refused(pass_cube):
    cube, _ = pass_cube
    a = P.magnitudes(cube, ["V"], range=1e6 * u.m, sun_distance=1.0 * u.au)
    b = P.magnitudes(cube, ["V"], range=1000.0, sun_distance=1.0)
    np.testing.assert_allclose(a.values, b.values, rtol=0, atol=1e-12)
    column = cube["range"].values[:, None] * 1e3 * u.m  # (time, 1) against (time, band)
    per_time = P.magnitudes(cube, ["V"], range=column)
    np.testing.assert_allclose(per_time.values, P.magnitudes(cube, ["V"]).values, atol=1e-12)
    au_km = (1.0 * u.au).to_value(u.km)
    c = P.magnitudes(cube, ["V"], range=1000.0, sun_distance=au_km * u.km)
    np.testing.assert_allclose(c.values, b.values, atol=1e-12)
    with pytest.raises(
        UnitError, match=r"range: got 3.0 s \(time\), which is not in km \(length\)"
    ):
        P.magnitudes(cube, ["V"], range=3.0 * u.s)
    with pytest.raises(UnitError, match=r"sun_distance: got 1.0 kg \(mass\)"):
        P.magnitudes(cube, ["V"], sun_distance=1.0 * u.kg)
    with pytest.raises(ValidationError, match="range: must be finite and > 0"):
        P.magnitudes(cube, ["V"], range=-1.0 * u.km)


@pytest.mark.parametrize("call", ["magnitudes", "photometry"])
def test_the_old_distance_keywords_answer_one_release_with_a_warning(pass_cube, call):
    cube, _ = pass_cube
    new = getattr(P, call)(cube, ["V"], range=1000.0, sun_distance=1.0)
    with pytest.warns(RenamedWarning, match="range_km"):
        old = getattr(P, call)(cube, ["V"], range_km=1000.0, sun_distance=1.0)
    xr.testing.assert_identical(old, new)
    with pytest.warns(RenamedWarning, match="sun_distance_au"):
        old = getattr(P, call)(cube, ["V"], range=1000.0, sun_distance_au=1.0)
    xr.testing.assert_identical(old, new)
    with pytest.warns(RenamedWarning, match=f"SbrdfDatasetAccessor.{call}.*range_km"):
        old = getattr(cube.sbrdf, call)(["V"], range_km=1000.0, sun_distance=1.0)
    xr.testing.assert_identical(old, new)
    with pytest.raises(ValidationError, match="received both 'range_km' and 'range'"):
        getattr(P, call)(cube, ["V"], range=1000.0, range_km=1000.0)


def test_extinction_adds_k_times_the_cubes_airmass(pass_cube):
    cube, _ = pass_cube
    m = P.magnitudes(cube, ["V", "R"])
    k = {"V": 0.2, "R": 0.1}
    seen = P.magnitudes(cube, ["V", "R"], extinction=k)
    x = cube["airmass"].values
    assert np.all(x > 1.0)
    np.testing.assert_allclose(
        (seen - m).values, x[:, None] * np.array([0.2, 0.1])[None, :], rtol=0, atol=1e-12
    )
    assert seen.attrs["extinction_coefficients"] == "V: 0.2, R: 0.1"
    # Filter names match as well as labels; the bundle applies it before the colours.
    by_filter = P.magnitudes(cube, ["V", "R"], extinction={"bessell-V": 0.2, "bessell-R": 0.1})
    xr.testing.assert_identical(by_filter.drop_attrs(), seen.drop_attrs())
    ph = P.photometry(cube, ["V", "R"], extinction=k)
    np.testing.assert_allclose(
        ph.colour_index.sel(colour="V-R").values,
        (seen.sel(band="V") - seen.sel(band="R")).values,
        atol=1e-12,
    )
    with pytest.raises(ValidationError, match="no coefficient for band 'R'"):
        P.magnitudes(cube, ["V", "R"], extinction={"V": 0.2})
    with pytest.raises(ValidationError, match="must be finite and >= 0"):
        P.magnitudes(cube, ["V"], extinction={"V": -0.2})


def test_a_rotation_cube_still_needs_a_range_and_has_no_airmass():
    wl = np.arange(300.0, 1101.0, 10.0)
    cube = xr.Dataset(
        {"signal": (("attitude", "wavelength"), np.full((2, wl.size), 0.1), {"units": "m2 sr-1"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    )
    with pytest.raises(ValidationError, match=r"range: the observer range .* no 'range'"):
        P.magnitudes(cube, ["V"])
    m = P.magnitudes(cube, ["V"], 1000.0)
    assert m.attrs["sun_distance_source"].startswith("default 1 au")
    assert "range_override" not in m.attrs and m.attrs["range_km"] == 1000.0
    with pytest.raises(ValidationError, match="extinction: the cube records no 'airmass'"):
        P.magnitudes(cube, ["V"], 1000.0, extinction={"V": 0.2})


def test_a_cube_range_in_metres_is_read_as_metres(pass_cube):
    cube, _ = pass_cube
    in_m = cube.assign_coords(range=("time", cube["range"].values * 1e3, {"units": "m"}))
    np.testing.assert_allclose(
        P.magnitudes(in_m, ["V"]).values, P.magnitudes(cube, ["V"]).values, atol=1e-12
    )
    bad = cube.assign_coords(range=("time", cube["range"].values, {"units": "s"}))
    with pytest.raises(ValidationError, match="'range' has units 's'"):
        P.magnitudes(bad, ["V"])
