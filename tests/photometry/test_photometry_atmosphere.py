"""Air mass, extinction, standard magnitudes, the Sun's distance and spectral resolution."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import photometry as P
from sbrdf_xr.errors import ValidationError


def _mags(values=(10.0, 11.0, 12.0)):
    return xr.DataArray(
        np.array(values),
        dims="band",
        coords={"band": ["B", "V", "R"][: len(values)]},
        name="magnitude",
        attrs={"units": "1", "long_name": "m", "magnitude_system": "Vega"},
    )


def test_airmass_wraps_pvlib_models_and_is_nan_below_the_horizon():
    from pvlib.atmosphere import get_relative_airmass

    el = np.array([90.0, 60.0, 30.0, 10.0])
    for model in P.AIRMASS_MODELS:
        np.testing.assert_array_equal(
            P.airmass(el, model=model), get_relative_airmass(90.0 - el, model=model)
        )
    assert P.airmass(30.0, model="simple") == pytest.approx(2.0, rel=1e-12)  # sec 60 deg
    da = xr.DataArray([45.0, 60.0], dims="obs", name="elevation")
    x = P.airmass(da)
    assert (
        x.dims == ("obs",)
        and x.attrs["units"] == "1"
        and x.attrs["airmass_model"] == "kastenyoung1989"
    )
    below = P.airmass([10.0, -5.0])  # below the horizon: not defined, NaN
    assert np.isfinite(below[0]) and np.isnan(below[1])
    with pytest.raises(ValidationError, match=r"elevation: must be in \[-90, 90\].*first is 95"):
        P.airmass([10.0, 95.0])
    with pytest.raises(ValidationError, match="airmass model: unknown 'bogus'; allowed: 'simple'"):
        P.airmass(10.0, model="bogus")


@settings(max_examples=examples(50), deadline=None)
@given(st.floats(1.0, 10.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_extinction_law_is_exact(x, kb, kv, kr):
    k = {"B": kb, "V": kv, "R": kr}
    m1 = P.apply_extinction(_mags(), 1.0, k)
    mx = P.apply_extinction(_mags(), x, k)
    # m(X) - m(1) = k (X - 1): one multiply-add per value, so to a few ulps of m ~ 10
    np.testing.assert_allclose(
        mx.values - m1.values, np.array([kb, kv, kr]) * (x - 1.0), rtol=0, atol=1e-12
    )
    assert mx.attrs["airmass"] == x and mx.attrs["magnitude_system"] == "Vega"


def test_extinction_refuses_missing_bands_and_bad_airmass():
    with pytest.raises(ValidationError, match=r"no extinction coefficient for band\(s\) \['R'\]"):
        P.apply_extinction(_mags(), 1.2, {"B": 0.3, "V": 0.2})
    with pytest.raises(ValidationError, match="airmass: must be finite and >= 1"):
        P.apply_extinction(_mags(), 0.5, {"B": 0.3, "V": 0.2, "R": 0.1})
    # per-observation air masses broadcast
    x = xr.DataArray([1.0, 2.0], dims="obs")
    out = P.apply_extinction(_mags(), x, {"B": 0.3, "V": 0.2, "R": 0.1})
    assert out.dims == ("band", "obs")
    assert float(out.sel(band="V", obs=1) - out.sel(band="V", obs=0)) == pytest.approx(0.2)


def test_spectral_transmission_through_the_band_weights():
    wl = P.solar_spectrum().wavelength.values
    # Transmission 1 changes nothing (the same integrals)
    one = xr.DataArray(np.ones(wl.size), dims="wavelength", coords={"wavelength": wl})
    np.testing.assert_allclose(
        P.sun_magnitudes(["B", "V"], transmission=one).values,
        P.sun_magnitudes(["B", "V"]).values,
        rtol=0,
        atol=1e-12,
    )
    # A grey transmission a dims every band by -2.5 log10 a exactly
    grey = one * 0.5
    d = P.sun_magnitudes(["B", "V"], transmission=grey) - P.sun_magnitudes(["B", "V"])
    np.testing.assert_allclose(d.values, -2.5 * np.log10(0.5), rtol=1e-12)
    # Rayleigh + aerosols: blue is dimmed more; V coefficient of a clear sea-level site
    # (0.1-0.2 mag per air mass; e.g. Sterken & Manfroid 1992, Table 9.1)
    k = P.extinction_coefficients(["B", "V", "R", "I"])
    assert list(np.diff(k.values) < 0) == [True, True, True]
    assert 0.1 < float(k.sel(band="V")) < 0.2
    # The band weights with transmission: m through X = 2 equals m_sun + k-like offset, and
    # a spectrally flat spectrum's band mean stays 1 (the normalisation includes it).
    t2 = P.transmission(wl, 2.0)
    w = P.band_weights(["V"], np.arange(400.0, 800.0, 1.0), normalize=True, transmission=t2)
    assert float(w.sum()) == pytest.approx(1.0, rel=1e-12)
    assert w.attrs["airmass"] == 2.0 and "Rayleigh" in w.attrs["atmosphere"]
    with pytest.raises(
        ValidationError, match=r"transmission: values must be finite and in \[0, 1\]"
    ):
        P.sun_magnitudes(["V"], transmission=one * 2.0)


def test_rayleigh_optical_depth_closed_form():
    # Hansen & Travis 1974: tau_R(550 nm) = 0.0975 at sea level; scales with pressure
    assert float(P.rayleigh_optical_depth([550.0])[0]) == pytest.approx(0.0975, abs=0.0005)
    assert float(P.rayleigh_optical_depth([550.0], 506.625)[0]) == pytest.approx(
        0.5 * float(P.rayleigh_optical_depth([550.0])[0]), rel=1e-14
    )


def test_standard_magnitude_to_range_and_phase():
    m = _mags()
    s = P.standard_magnitude(m, 2000.0)
    np.testing.assert_allclose(s.values, m.values - 5 * np.log10(2.0), rtol=0, atol=1e-12)
    assert s.attrs["standard_range_km"] == 1000.0 and s.attrs["magnitude_system"] == "Vega"
    # Lambert sphere: Phi(90) = 1/pi exactly; at 90 deg normalised to 0 deg: -2.5 log10 pi brighter
    s0 = P.standard_magnitude(m, 1000.0, phase_angle=90.0, to_phase_angle=0.0)
    np.testing.assert_allclose(
        s0.values, m.values + 2.5 * np.log10(1.0 / np.pi), rtol=0, atol=1e-12
    )
    assert s0.attrs["phase_function"] == "lambert_sphere"
    sp = P.standard_magnitude(
        m, 1000.0, phase_angle=90.0, to_phase_angle=0.0, phase_function="specular_sphere"
    )
    np.testing.assert_allclose(sp.values, m.values, atol=1e-12)
    s1 = P.standard_magnitude(m, 1000.0, sun_distance=1.1)
    np.testing.assert_allclose(s1.values, m.values - 5 * np.log10(1.1), atol=1e-12)
    with pytest.raises(ValidationError, match="phase_angle: give the phase angle"):
        P.standard_magnitude(m, 1000.0, to_phase_angle=0.0)
    with pytest.raises(ValidationError, match="dark at 180 degree"):
        P.standard_magnitude(m, 1000.0, phase_angle=180.0, to_phase_angle=0.0)
    with pytest.raises(ValidationError, match="range: must be finite and > 0"):
        P.standard_magnitude(m, 0.0)


def test_lambert_sphere_phase_function_is_the_quadrature_of_lambert_discs():
    # Brightness of a Lambert sphere: integral of cos(i) cos(e) over the lit and visible
    # surface, by a 400 x 400 trapezoid rule (independent of the closed form); the kink
    # at the terminator limits it to ~1e-4.
    lon = np.linspace(-np.pi / 2, np.pi / 2, 400)  # visible longitudes (observer at lon 0)
    lat = np.linspace(-np.pi / 2, np.pi / 2, 400)
    lo, la = np.meshgrid(lon, lat)

    def brightness(alpha):
        cos_e = np.cos(la) * np.cos(lo)
        cos_i = np.cos(la) * np.cos(lo - np.radians(alpha))
        f = np.where(cos_i > 0, cos_i * cos_e * np.cos(la), 0.0)
        return np.trapezoid(np.trapezoid(f, lon, axis=1), lat)

    for alpha in (30.0, 90.0, 150.0):
        assert brightness(alpha) / brightness(0.0) == pytest.approx(
            float(P.lambert_sphere_phase(alpha)), abs=2e-4
        )


def test_sun_distance_at_perihelion_and_aphelion():
    # 2024 perihelion (Jan 3 00:39 UTC) 0.983307 AU; aphelion (Jul 5 05:06 UTC) 1.016725 AU
    # (USNO/IMCCE ephemerides); the low-precision formula is good to ~2e-5 AU.
    t = np.array(["2024-01-03T00:39", "2024-07-05T05:06"], dtype="datetime64[ns]")
    np.testing.assert_allclose(P.sun_distance_au(t), [0.983307, 1.016725], atol=5e-5)
    with pytest.raises(ValidationError, match="time"):
        P.sun_distance_au(np.array(["2024-01-03", "NaT"], dtype="datetime64[ns]"))


def _emission(wl, centre=600.0, sigma=0.5):
    return xr.DataArray(
        np.exp(-0.5 * ((wl - centre) / sigma) ** 2),
        dims="wavelength",
        coords={"wavelength": wl},
        name="x",
        attrs={"units": "1", "long_name": "test"},
    )


def test_at_resolution_conserves_flux_and_widens_lines_in_quadrature():
    wl = np.arange(500.0, 700.0, 0.05)
    x = _emission(wl)
    y = P.at_resolution(x, fwhm=2.0)
    # flux conservation: the trapezoid integrals agree up to the flux spread past the ends
    # (a line 100 nm = 100 sigma from the ends: none), so to rounding
    assert np.trapezoid(y.values, wl) == pytest.approx(np.trapezoid(x.values, wl), rel=1e-12)
    # Gaussian line of sigma s0 through a Gaussian LSF of sigma s: the variances add
    # (the 0.05 nm sampling adds h^2/12 to both sides' discrete moments: 1e-3 relative)
    s = 2.0 / (2 * np.sqrt(2 * np.log(2)))
    w = y.values / y.values.sum()
    mean = (w * wl).sum()
    assert np.sqrt((w * (wl - mean) ** 2).sum()) == pytest.approx(np.hypot(0.5, s), rel=1e-3)
    assert mean == pytest.approx(600.0, abs=1e-6)
    # a continuum that reaches the ends loses the half-kernel past each end (documented)
    flat = x * 0.0 + 1.0
    lost = np.trapezoid(flat.values, wl) - np.trapezoid(P.at_resolution(flat, fwhm=2.0).values, wl)
    assert lost == pytest.approx(2 * s / np.sqrt(2 * np.pi), rel=1e-2)
    # resolving power R: FWHM lambda/R; R = 600/2 gives the same line as FWHM 2 nm near 600 nm
    z = P.at_resolution(x, resolving_power=300.0)
    assert float(z.sel(wavelength=600.0, method="nearest")) == pytest.approx(
        float(y.sel(wavelength=600.0, method="nearest")), abs=2e-3
    )
    # onto a coarser grid, still flux-conserving
    coarse = np.arange(500.0, 700.01, 1.0)
    c = P.at_resolution(x, fwhm=2.0, wavelength=coarse)
    assert np.trapezoid(c.values, coarse) == pytest.approx(np.trapezoid(x.values, wl), rel=1e-12)
    assert "flux-conserving" in c.attrs["spectral_resolution"] and c.attrs["units"] == "1"
    with pytest.raises(ValidationError, match="exactly one of resolving_power"):
        P.at_resolution(x)
